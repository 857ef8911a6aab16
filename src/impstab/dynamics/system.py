"""Packing a model (or a linear test system) for the compiled kernels, and Python entry points
to the right-hand side and the mount loads.

:class:`NonlinearSystem` is the entry point for analyses built on the equations of motion (the
Hopf coefficient, periodic orbits): the compiled right-hand side of :func:`simulate` (the one
implementation, :func:`~impstab.dynamics.rhs.model_rhs`) on a batch of real or complex states,
its exact Jacobian by complex step, and the static equilibrium state at a thrust.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..model.mount_law import N_LAW
from .rhs import (FLAG_LAW, FLAG_ROTATION, KIND_LINEAR, KIND_MODEL, N_BODY, N_PAR, P_CG, P_E, P_IA, P_JP, P_MASS, P_PITCH,
                  P_RADIATION, P_ROTATION, P_RT, P_TANG, PITCH_LIMIT, mount_loads_series, rhs_batch)

__all__ = ["DynamicSystem", "NonlinearSystem", "pack_dynamics", "linear_dynamics", "evaluate_rhs", "mount_loads",
           "equilibrium_state", "STATE_NAMES", "COMPLEX_STEP"]

#: the 12 states of the nonlinear model: position of A (hull frame, m), z-y-x Euler angles (rad),
#: body-frame velocity of A (m/s) and angular velocity (rad/s)
STATE_NAMES = ("X_A", "Y_A", "Z_A", "phi", "theta", "psi", "u", "v", "w", "p", "q", "r")
#: imaginary step of the complex-step Jacobian (absolute, in each state's unit)
COMPLEX_STEP = 1e-30


@dataclass(frozen=True, eq=False)
class DynamicSystem:
    """A system packed for the compiled kernels.

    ``kind = 0``: the propulsor model (12 states, then 3 per Prony term of its viscoelastic
    mounts, then the kept modal coordinates ``eta`` of its massive beam mounts and their rates
    ``eta'``, :mod:`impstab.dynamics.beam_mounts`); ``kind = 1``: a linear system ``z' = A z``
    (used to test the integrators on oscillators). ``arrays`` is the tuple handed to the kernels;
    ``length_scale`` (m) is the model's largest mount or thrust arm.
    """

    kind: int
    arrays: tuple
    n_states: int
    n_mounts: int
    length_scale: float = 1.0

    @property
    def n_terms(self) -> int:
        """Number of Prony terms (internal 3-vectors, states ``12 + 3 j : 15 + 3 j``)."""
        return int(self.arrays[10].shape[0])

    @property
    def term_mounts(self) -> NDArray[np.int64]:
        """The mount of each Prony term (index into the model's mounts)."""
        start = np.asarray(self.arrays[9])
        return np.repeat(np.arange(start.size - 1), np.diff(start))

    @property
    def n_modes(self) -> int:
        """Number of kept modes of massive beam mounts (states ``eta`` then ``eta'``, ``2 n_modes``)."""
        return int(self.arrays[14].shape[0])

    @property
    def mode_start(self) -> int:
        """First state of the beams' modal coordinates: ``12 + 3 n_terms``."""
        return N_BODY + 3 * self.n_terms

    @property
    def mode_mounts(self) -> NDArray[np.int64]:
        """The mount of each kept beam mode (index into the model's mounts)."""
        flags = np.asarray(self.arrays[16], dtype=np.int64)
        return np.repeat(flags, np.diff(np.asarray(self.arrays[13])))

    def internal_equilibrium(self, displacement, rotation) -> NDArray[np.float64]:
        """The internal states at rest for the body at ``displacement`` (m) and ``rotation``
        (3 x 3, body -> hull): the Prony terms' ``w_ij = d_i`` (``3 n_terms``, m, hull frame),
        then ``eta = eta' = 0`` of the beams' modes (``2 n_modes``)."""
        pos = np.asarray(self.arrays[0])[self.term_mounts]
        d = np.asarray(displacement, float)[None] + pos @ np.asarray(rotation, float).T - pos
        return np.concatenate([d.reshape(-1), np.zeros(2 * self.n_modes)])


def pack_dynamics(model, pitch_limit: float = PITCH_LIMIT) -> DynamicSystem:
    """Pack ``model`` for the kernels: mounts, mass properties, thrust line, propeller, the
    Prony terms of viscoelastic mounts (:attr:`~impstab.model.mounts.Mount.viscoelastic`) and the
    kept modes of massive beam mounts (:mod:`impstab.dynamics.beam_mounts`)."""
    from ..linear.linearize import pack_model
    from .beam_mounts import beam_dofs, pack_beams

    pk = pack_model(model)
    nm = pk.positions.shape[0]
    rotational = [bool(np.any(k[3:, :] != 0) or np.any(k[:, 3:] != 0) or np.any(c[3:, :] != 0) or np.any(c[:, 3:] != 0))
                  for k, c in zip(pk.stiffness, pk.damping)]
    nonlinear = np.any(pk.laws[:, 3:] != 0.0, axis=1)
    flags = np.array([FLAG_ROTATION * r + FLAG_LAW * int(nl) for r, nl in zip(rotational, nonlinear)], dtype=np.int64)
    par = np.zeros(N_PAR)
    body = model.body
    par[P_MASS] = body.mass
    par[P_CG:P_CG + 3] = body.cg
    par[P_IA:P_IA + 9] = np.asarray(body.inertia_a).ravel()
    par[P_E:P_E + 3] = pk.e_dir
    par[P_RT:P_RT + 3] = pk.r_thrust
    par[P_TANG] = pk.tangency
    par[P_JP] = pk.polar_inertia
    par[P_PITCH] = float(pitch_limit)
    par[P_ROTATION] = float(any(rotational))
    par[P_RADIATION] = float(np.any(pk.damp6 != 0.0))
    vstart = np.zeros(nm + 1, dtype=np.int64)
    vpar = []
    for i, m in enumerate(model.mounts):
        law = m.viscoelastic
        if law is not None:
            vpar += list(zip(law.weights, law.relaxation_times))
        vstart[i + 1] = len(vpar)
    arrays = (
        np.ascontiguousarray(pk.positions), np.ascontiguousarray(pk.stiffness),
        np.ascontiguousarray(pk.damping), flags, np.ascontiguousarray(pk.laws), par,
        np.ascontiguousarray(np.linalg.inv(pk.mass6)), np.ascontiguousarray(pk.damp6), np.zeros((1, 1)),
        vstart, np.ascontiguousarray(np.array(vpar, dtype=float).reshape(-1, 2)),
    )
    dofs = beam_dofs(model)
    beams = np.array([i for i, m in enumerate(model.mounts) if m.is_massive_beam], dtype=np.int64)
    arrays = arrays + pack_beams(dofs, pk.mass6) + (beams,)
    n_modes = 0 if dofs is None else dofs.n
    return DynamicSystem(KIND_MODEL, arrays, N_BODY + 3 * len(vpar) + 2 * n_modes, nm, float(pk.length_scale))


def linear_dynamics(amat) -> DynamicSystem:
    """A linear system ``z' = A z`` for the same kernels (oscillator tests of the integrators)."""
    from .beam_mounts import no_beams

    amat = np.ascontiguousarray(amat, dtype=float)
    n = amat.shape[0]
    arrays = (np.zeros((0, 3)), np.zeros((0, 6, 6)), np.zeros((0, 6, 6)), np.zeros(0, dtype=np.int64),
              np.zeros((0, N_LAW)), np.zeros(N_PAR), np.zeros((6, 6)), np.zeros((6, 6)), amat,
              np.zeros(1, dtype=np.int64), np.zeros((0, 2))) + no_beams(np.eye(6)) + (np.zeros(0, dtype=np.int64),)
    return DynamicSystem(KIND_LINEAR, arrays, n, 0)


def evaluate_rhs(system: DynamicSystem, yeq, z, thrust: float, spin: float = 0.0):
    """Python entry to the right-hand side: returns ``(z', status)``."""
    out = np.empty((1, system.n_states))
    status = np.zeros(1, dtype=np.int64)
    rhs_batch(system.kind, system.arrays, np.ascontiguousarray(yeq, dtype=float),
              np.ascontiguousarray(z, dtype=float).reshape(1, -1), float(thrust), float(spin), out, status)
    return out[0], int(status[0])


def equilibrium_state(model, thrust: float):
    """The static equilibrium at thrust ``thrust`` (N) as a state ``(eta, nu)`` (12,), with
    ``nu = 0``, and the equilibrium linearization there (a
    :class:`~impstab.linear.system.LinearSystem`). Raises NumericalError where there is none."""
    from ..kinematics import matrix_to_euler_zyx
    from ..linear.linearize import linearize

    lin = linearize(model, float(thrust), "equilibrium")
    y = np.zeros(12)
    y[:3] = lin.displacement
    y[3:6] = matrix_to_euler_zyx(lin.rotation)
    return y, lin


@dataclass(frozen=True, eq=False)
class NonlinearSystem:
    """The nonlinear equations of motion ``y' = f(y; T)`` of a model, as :func:`simulate` integrates them.

    The state is ``y = (X_A, Y_A, Z_A, phi, theta, psi, u, v, w, p, q, r)`` (:data:`STATE_NAMES`):
    position of the reference point A from its unloaded place (hull frame, m), z-y-x Euler angles
    of the body (rad), body-frame velocity of A (m/s) and angular velocity (rad/s). The thrust
    ``T`` (N) is the parameter; the propeller spin follows the model's speed law unless given.

    With viscoelastic mounts the state goes on with the internal variables ``w_ij`` of their
    Prony terms (3 each, hull frame, m; :mod:`impstab.dynamics.viscoelastic`), then with massive
    beam mounts the kept modal coordinates ``eta`` (kg^0.5 m) and their rates ``eta'``
    (:mod:`impstab.dynamics.beam_mounts`): ``n_states`` is ``12 + 3 n_terms + 2 n_modes``; at an
    equilibrium ``w_ij = d_i`` and ``eta = eta' = 0``.

    Every evaluation runs the compiled right-hand side of the simulation (one implementation),
    on real or complex128 states: the code is analytic in the state, so ``f`` of a complex state
    is the analytic continuation of ``f``, and complex-step or Cauchy-integral derivatives of it
    are exact to rounding. Guards compare real parts only: the pitch guard (``|Re theta|`` at
    ``pitch_limit``; the result is still computed, NaN only where ``cos theta`` vanishes) and the
    snubber's contact test ``Re(d . d) > c^2`` (its force uses ``|d| = sqrt(d . d)``, analytic
    away from ``d = 0``). A derivative taken exactly at the snubber's contact or at an end of its
    smoothing interval is one-sided (the law is C2 there, not analytic).

    Examples
    --------
    >>> ns = NonlinearSystem.from_model(model)
    >>> y0 = ns.equilibrium(9000.0)                  # (12,)
    >>> ns.rhs(y0, 9000.0)                           # ~0
    >>> ns.jacobian(y0, 9000.0)                      # (12, 12), exact
    >>> ns.rhs(y0 + 1e-3j * v, 9000.0)               # complex state
    """

    model: object
    pitch_limit: float = PITCH_LIMIT
    system: DynamicSystem = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "system", pack_dynamics(self.model, self.pitch_limit))

    @classmethod
    def from_model(cls, model, pitch_limit: float = PITCH_LIMIT) -> "NonlinearSystem":
        return cls(model, pitch_limit)

    @property
    def n_states(self) -> int:
        """12, 3 per Prony term of the viscoelastic mounts and 2 per kept beam mode."""
        return self.system.n_states

    def spin(self, thrust: float) -> float:
        """Propeller speed Omega (rad/s) at thrust ``thrust`` (N), by the model's speed law."""
        return float(self.model.propeller.spin(float(thrust), self.model.thrust.operating))

    def equilibrium(self, thrust: float) -> NDArray[np.float64]:
        """The static equilibrium state at thrust ``thrust`` (N): ``(X_A, Xi, 0)`` (12,), then the
        internal states at rest (``w_ij = d_i``, ``eta = eta' = 0``); the continuation and Newton method of the
        linear analyses (:func:`equilibrium_state`)."""
        y, lin = equilibrium_state(self.model, thrust)
        return np.concatenate([y, self.system.internal_equilibrium(lin.displacement, lin.rotation)])

    def rhs(self, states, thrust: float, spin: float | None = None, deviation_from=None):
        """``f(y; T)`` at each state.

        Parameters
        ----------
        states : (n_states,) or (n, n_states) array, float or complex
            Absolute states ``y``, or deviations from ``deviation_from`` when it is given.
        thrust : float
            Thrust T (N).
        spin : float, optional
            Propeller speed (rad/s); default the model's speed law at ``thrust``.
        deviation_from : (n_states,) real array, optional
            A base state ``y0``: ``states`` are then ``y - y0`` (the integrators' form).

        Returns
        -------
        ndarray of the states' shape and dtype (complex128 for complex states): ``y'``.
        """
        states = np.asarray(states)
        cplx = np.iscomplexobj(states)
        zs = np.ascontiguousarray(np.atleast_2d(states), dtype=complex if cplx else float)
        ns = self.n_states
        if zs.shape[-1] != ns or zs.ndim != 2:
            raise ValueError(f"states must have shape ({ns},) or (n, {ns}), not {states.shape}")
        base = np.zeros(ns) if deviation_from is None else np.ascontiguousarray(deviation_from, dtype=float)
        out = np.empty_like(zs)
        status = np.zeros(zs.shape[0], dtype=np.int64)
        spin = self.spin(thrust) if spin is None else float(spin)
        rhs_batch(self.system.kind, self.system.arrays, base, zs, float(thrust), spin, out, status)
        return out.reshape(states.shape)

    def jacobian(self, states, thrust: float, spin: float | None = None, deviation_from=None):
        """``df/dy`` at each state by complex step (exact to rounding): (m, m) or (n, m, m),
        ``m = n_states``."""
        states = np.asarray(states, dtype=float)
        ys = np.atleast_2d(states)
        n, m = ys.shape[0], self.n_states
        probe = np.repeat(ys[:, None, :], m, axis=1).astype(complex)
        probe[:, np.arange(m), np.arange(m)] += 1j * COMPLEX_STEP
        f = self.rhs(probe.reshape(n * m, m), thrust, spin, deviation_from).reshape(n, m, m)
        jac = np.swapaxes(f.imag, 1, 2) / COMPLEX_STEP
        return jac[0] if states.ndim == 1 else jac


def mount_loads(system: DynamicSystem, yeq, zs):
    """Mount loads ``(n_samples, n_mounts, 6)``: force (N, hull frame) then moment (N m)."""
    zs = np.ascontiguousarray(np.atleast_2d(zs), dtype=float)
    out = np.zeros((zs.shape[0], system.n_mounts, 6))
    if system.kind == KIND_MODEL and zs.shape[0]:
        mount_loads_series(system.arrays, np.ascontiguousarray(yeq, dtype=float), zs, out)
    return out
