"""Massive beam mounts in the time histories: their kept internal modes as states, and the step.

A beam mount with ``density > 0`` carries its own mass in Craig-Bampton form
(:mod:`impstab.linear.mount_dofs`, one construction for the stability analysis and the time
histories): the mount acts on the body by its static tip stiffness ``K_tip`` (the 6 x 6 mount of
the kernels), and its inertia by the constraint-mode body-end mass ``m_tt`` and the kept
fixed-interface modes ``eta`` (unit modal mass, stiffness ``Omega^2``, undamped), coupled to the
body through the mass only (``m_te``). The right-hand side (:mod:`impstab.dynamics.rhs`) carries
``eta`` and ``eta'`` as states after the body's 12 and the viscoelastic internal variables; at
rest ``eta = 0`` (the constraint modes carry the statics exactly).

Which modes: the stability analysis keeps every mode below
:data:`~impstab.linear.mount_dofs.CUTOFF` (1000) times the body's highest frequency; that is far
too stiff for an explicit step. The time histories keep the modes below :data:`SIM_CUTOFF` times
the body's highest frequency (at rest, each mount as its static stiffness, the beams' constraint
mass included). The dropped modes stay in the constraint modes as their static (mass) part, so the
statics and the low-frequency inertia are exact and only the dynamic amplification of modes far
above the body's is lost. On ``examples/imp_beam_mounts.toml`` (first internal modes at 31 times
the body's highest frequency) the time histories keep three modes per beam, and the critical
thrust of the body with them is within 1.2e-8 (relative) of the stability analysis's with 168
modes (1.2e-7 with none; docs/mounts.md gives the table).

Mount loads: a massive beam's reported load (:func:`~impstab.dynamics.rhs.mount_loads_series`)
is that of its static tip stiffness and dampers at the body-end deflection, the quasi-static load
both of its ends carry; the beam's inertia force on the body
``f = -(m_tt - m_te m_te^T) a + m_te Omega^2 eta`` is not in it, and the hull-end reaction differs
from the body-end force by the beam's own inertia (the forced response reports the exact hull-end
force).

The step: the default fixed step takes :data:`~impstab.dynamics.simulate.STEPS_PER_PERIOD` steps
per period of the fastest root of the grown linear system (:func:`fastest_root`), which is the
fastest kept beam mode; a given ``dt`` beyond :data:`OSCILLATION_LIMIT` ``/ omega`` (80 % of the
measured bound of the method's stability interval on the imaginary axis, Hamming 0.274, Gill
2.83 = ``2 sqrt 2``; measured on ``z'' = -z`` with
:func:`~impstab.dynamics.integrators.integrate_linear`) is refused in one line naming ``radau``
and ``lsoda`` (:func:`check_beam_step`), which integrate the undamped stiff modes with their exact
complex-step Jacobian.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..model.model import DOF_NAMES, Model

__all__ = ["SIM_CUTOFF", "OSCILLATION_LIMIT", "BeamRoots", "beam_dofs", "pack_beams", "no_beams", "fastest_root",
           "check_beam_step", "modal_length_factors"]

#: the time histories keep the beams' fixed-interface modes below this multiple of the body's
#: highest natural frequency (the stability analysis: :data:`~impstab.linear.mount_dofs.CUTOFF`)
SIM_CUTOFF = 40.0
#: largest ``h x omega`` a fixed-step method is run at on an undamped mode: 80 % of the measured
#: bound of its stability interval on the imaginary axis (Hamming 0.274, Gill 2.83)
OSCILLATION_LIMIT = {"hamming": 0.22, "gill": 2.26}


def beam_dofs(model: Model):
    """The model's massive beam mounts as the time histories carry them
    (:func:`~impstab.linear.mount_dofs.mount_dofs` at :data:`SIM_CUTOFF`), or None."""
    from ..linear.mount_dofs import mount_dofs

    return mount_dofs(model, cutoff=SIM_CUTOFF)


def modal_length_factors(model: Model, system) -> np.ndarray:
    """``sqrt(m_b)`` (kg^0.5) of the beam of each kept mode of a packed
    :class:`~impstab.dynamics.system.DynamicSystem`: a modal coordinate (unit modal mass, kg^0.5 m)
    divided by it is a length, the unit the error weights and state scales use."""
    return np.sqrt([model.mounts[i].beam.mass for i in system.mode_mounts])


def no_beams(mass6) -> tuple:
    """The kernel arrays of a model without massive beam mounts."""
    return (np.zeros((0, 3)), np.zeros((0, 6, 6)), np.zeros(1, dtype=np.int64), np.zeros((0, 7)),
            np.ascontiguousarray(mass6, dtype=float))


def pack_beams(dofs, mass6) -> tuple:
    """``(bpos, bmat, bstart, bmode, mass6)`` for the kernels (:func:`~impstab.dynamics.rhs.beam_body`)
    from a :class:`~impstab.linear.mount_dofs.MountDofs` (None: :func:`no_beams`)."""
    if dofs is None:
        return no_beams(mass6)
    nb = dofs.positions.shape[0]
    bmat = np.array([dofs.m_tt[b] - dofs.m_te[b] @ dofs.m_te[b].T for b in range(nb)]).reshape(nb, 6, 6)
    counts = [t.shape[1] for t in dofs.m_te]
    bstart = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    bmode = np.zeros((dofs.n, 7))
    bmode[:, 0] = dofs.omega2
    if dofs.n:
        bmode[:, 1:] = np.concatenate([t.T for t in dofs.m_te], axis=0)
    return (np.ascontiguousarray(dofs.positions, dtype=float), np.ascontiguousarray(bmat),
            bstart, np.ascontiguousarray(bmode), np.ascontiguousarray(mass6, dtype=float))


@dataclass(frozen=True)
class BeamRoots:
    """The fastest root of the grown linear system at one thrust.

    Attributes
    ----------
    omega : float
        Largest ``|lambda|`` (rad/s).
    mode : str
        Its dominant dof, or ``"mounts[i] internal mode"`` when most of its kinetic energy is in
        the kept modes of beam mount i.
    max_real : float
        ``max Re(lambda)`` (1/s): the linear growth rate of the kept modes at that thrust.
    """

    omega: float
    mode: str
    max_real: float


def fastest_root(model: Model, thrust: float) -> BeamRoots:
    """Eigenvalues of the body with its beams' kept modes (:data:`SIM_CUTOFF`), linearized at the
    static equilibrium at ``thrust`` (N): the grown system of
    :meth:`~impstab.linear.mount_dofs.MountDofs.augment`."""
    from ..linear.linearize import ModelFamily
    from ..linear.eigen import state_matrices

    fam = ModelFamily(model, "equilibrium", cutoff=SIM_CUTOFF)
    m, d, g, k = (a[0] for a in fam.matrices(np.array([float(thrust)])))
    vals, vecs = np.linalg.eig(state_matrices(m, d + g, k))
    j = int(np.argmax(np.abs(vals)))
    n = m.shape[0]
    v = vecs[n:, j]
    energy = np.real(np.conj(v) * (m @ v))                   # kinetic energy per dof (diagonal share)
    mode = DOF_NAMES[int(np.argmax(energy[:6]))]
    internal = fam.internal
    if n > 6 and energy[6:].sum() > energy[:6].sum():
        beams = [i for i, mt in enumerate(model.mounts) if mt.is_massive_beam]
        dof = 6 + int(np.argmax(energy[6:]))
        b = int(np.searchsorted(np.asarray(internal.offsets), dof - 6, side="right")) - 1
        mode = f"mounts[{beams[b]}] internal mode"
    return BeamRoots(float(np.abs(vals[j])), mode, float(vals.real.max()))


def check_beam_step(model: Model, integrator: str, dt: float, omega: float, field: str = "dt") -> None:
    """Refuse a fixed step ``dt`` (s) of ``integrator`` beyond its stability limit on the fastest
    kept beam mode ``omega`` (rad/s) (one line, naming the stiff alternatives)."""
    limit = OSCILLATION_LIMIT.get(integrator)
    if limit is None or omega <= 0.0 or dt * omega <= limit:
        return
    raise ModelError(field, dt, (
        f"the explicit {integrator} step is unstable on the fastest kept internal mode of the massive beam mounts "
        f"({omega / (2 * math.pi):.4g} Hz) for dt x omega above {limit:g}: use dt <= {limit / omega:.4g} s, "
        f"or integrator radau or lsoda (implicit, for stiff undamped modes)"))
