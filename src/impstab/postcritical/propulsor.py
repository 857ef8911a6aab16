"""Post-critical analysis of a propulsor model: the Hopf point at the flutter onset and its cycles.

:func:`propulsor_postcritical` puts the model's nonlinear equations of motion (the compiled
right-hand side of :func:`impstab.simulate`, through
:class:`~impstab.dynamics.system.NonlinearSystem`) into the generic machinery of this package:

1. the linear onset from :func:`impstab.critical_thrust` (the one stability engine);
2. :func:`~impstab.postcritical.hopf_analysis` on the 12-state system ``y' = f(y; T)`` with the
   thrust as the parameter: the onset refined, the first Lyapunov coefficient ``l1`` from exact
   (complex-step and Cauchy-circle) derivatives, the crossing speed, the label, or "degenerate"
   with the reason (an undamped model's 1:1 resonance, a symmetric ring's double pair, a
   divergence);
3. :func:`~impstab.postcritical.continue_cycles` from the Hopf point: orthogonal collocation,
   pseudo-arclength continuation through folds, Floquet multipliers, cycles at the requested
   thrusts;
4. per cycle the mechanical quantities an engineer checks: amplitude of each coordinate, peak
   mount deflection and force, snubber contact.

State scales (the unit of "small" of each state, which weighs the arclength and the derivative
circles): ``0.01 L`` for the position of A, ``0.01`` rad for the angles, and those times the
onset frequency for the velocities, ``L`` the model's largest mount or thrust arm. Viscoelastic
mounts add their internal variables to the state (:mod:`impstab.dynamics.viscoelastic`,
``w{j}_x, w{j}_y, w{j}_z`` for Prony term j, scaled like the position of A); massive beam
mounts add their kept modal coordinates and rates (:mod:`impstab.dynamics.beam_mounts`,
``eta{j}`` and ``eta{j}_rate``, kg^0.5 m, scaled like the position of A times the square root of
the beam's mass; 0 at the equilibrium); the cycles' amplitudes, profiles and mount peaks are those
of the body's 12 states, the Floquet multipliers those of the whole state.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError
from .continuation import continue_cycles
from .hopf import hopf_analysis
from .propulsor_result import DOFS, PostcriticalResult
from .system import DynamicalSystem

__all__ = ["propulsor_postcritical", "propulsor_system", "mount_peaks", "DEFAULTS"]

#: the 12 states as the continuation names them: the six coordinates of THEORY 7 (X_A, Y_A, Z_A,
#: Euler angles phi, theta, psi) under their dof names, then the body-frame velocities
STATE_NAMES = DOFS + ("u", "v", "w", "p", "q", "r")
STATE_UNITS = ("m",) * 3 + ("rad",) * 3 + ("m/s",) * 3 + ("rad/s",) * 3

#: default continuation settings (see :func:`propulsor_postcritical`)
DEFAULTS = {
    "max_points": 60,
    "amplitude_max": 25.0,       # in state scales: 0.25 rad of angle or 0.25 L of displacement
    "relative_position_scale": 0.01,
    "angle_scale": 0.01,
    "parameter_share": 0.01,     # parameter scale of the arclength: 1 % of the critical thrust
    "ds": 0.01,
    "ds_max": 0.5,
    "intervals": 40,
    "degree": 4,
    # Cauchy circles of the second and third derivatives, in state scales (see propulsor_system)
    "circle_radius": 10.0,
    "circle_points": 32,
}
#: phases per period at which mount deflections and forces are sampled
MOUNT_SAMPLES = 128


def propulsor_system(model, omega: float | None = None) -> tuple[DynamicalSystem, object]:
    """The model's equations of motion as a :class:`DynamicalSystem` in the thrust (N), and the
    :class:`~impstab.dynamics.system.NonlinearSystem` that evaluates them."""
    from ..dynamics.beam_mounts import modal_length_factors
    from ..dynamics.system import NonlinearSystem

    ns = NonlinearSystem(model)
    length = float(ns.system.length_scale)
    w = float(omega) if omega else 1.0
    xs = DEFAULTS["relative_position_scale"] * length
    an = DEFAULTS["angle_scale"]
    n_internal = 3 * ns.system.n_terms  # viscoelastic internal variables (m): scaled like the position of A
    n_modes = ns.system.n_modes         # beam modal coordinates (kg^0.5 m): the position scale x sqrt(beam mass)
    root_mass = modal_length_factors(model, ns.system)
    scale = np.concatenate([[xs] * 3 + [an] * 3 + [w * xs] * 3 + [w * an] * 3 + [xs] * n_internal,
                            xs * root_mass, w * xs * root_mass])
    names = (STATE_NAMES + tuple(f"w{j}_{a}" for j in range(n_internal // 3) for a in "xyz")
             + tuple(f"eta{j}" for j in range(n_modes)) + tuple(f"eta{j}_rate" for j in range(n_modes)))
    units = STATE_UNITS + ("m",) * n_internal + ("kg^0.5 m",) * n_modes + ("kg^0.5 m/s",) * n_modes

    def rhs(states, thrust):
        return ns.rhs(states, float(np.real(thrust)))

    system = DynamicalSystem(rhs, ns.n_states, vectorized=True, complex_parameter=False, state_names=names,
                             state_units=units, parameter_name="thrust", parameter_units="N",
                             time_units="s", state_scale=scale, region=_regions(ns))
    return system, ns


def _regions(ns) -> Callable[[NDArray], NDArray]:
    """The pieces of the right-hand side a (complex) state lies in: the pitch guard
    (``|Re theta|`` at the limit) and, for each mount with a snubber, free / smoothing ramp /
    beyond the ramp, by the same real-part tests as the compiled law (:mod:`impstab.model.mount_law`)."""
    from ..model.mount_law import LAW_CLEARANCE, SNUBBER_SMOOTHING

    pos = np.asarray(ns.system.arrays[0])
    laws = np.asarray(ns.system.arrays[4])
    clearance = laws[:, LAW_CLEARANCE] if laws.size else np.zeros(pos.shape[0])
    snub = np.flatnonzero(clearance > 0.0)
    arms, clear = pos[snub], clearance[snub]
    pitch = float(ns.pitch_limit)

    def region(states):
        y = np.atleast_2d(np.asarray(states, dtype=complex))
        codes = [(np.abs(y[:, 4].real) >= pitch).astype(np.int64)[:, None]]
        if snub.size:
            d = _deflections(y, arms)
            r2 = np.sum(d * d, axis=-1)                                          # analytic, no conjugate
            contact = r2.real > clear ** 2
            t = (np.sqrt(r2) - clear) / (SNUBBER_SMOOTHING * clear)
            codes.append(contact.astype(np.int64) + (contact & (t.real >= 1.0)))
        return np.concatenate(codes, axis=1)

    return region


def _deflections(states: NDArray, arms: NDArray) -> NDArray:
    """Mount deflections ``d = X_A + R r_i - r_i`` (hull frame, m; THEORY 7) of a batch of (real or
    complex) states ``(N, >= 6)`` at arms ``r_i (mounts, 3)``: ``(N, mounts, 3)``."""
    from ..kinematics import euler_zyx_to_matrix

    rot = np.moveaxis(np.asarray(euler_zyx_to_matrix(states[:, 3], states[:, 4], states[:, 5])), -1, 0)  # (N, 3, 3)
    return states[:, None, :3] + np.einsum("kab,ib->kia", rot, arms) - arms[None]


def mount_peaks(ns, states: NDArray) -> tuple[float, float, bool]:
    """Peak mount deflection ``max |d|`` (m), peak mount force (N) and snubber contact over ``states``.

    ``d = X_A + R r_i - r_i`` (hull frame, THEORY 7) of each mount's body end; the force is the
    magnitude of the total force the mount applies (springs, nonlinear law, snubber, dampers);
    contact: ``|d|`` beyond a mount's snubber clearance somewhere on the samples.
    """
    from ..dynamics.system import mount_loads
    from ..model.mount_law import LAW_CLEARANCE

    states = np.atleast_2d(np.asarray(states, dtype=float))
    pos = np.asarray(ns.system.arrays[0])
    laws = np.asarray(ns.system.arrays[4])
    d = _deflections(states, pos)
    dn = np.linalg.norm(d, axis=-1)                                              # (k, mounts)
    loads = mount_loads(ns.system, np.zeros(ns.n_states), states)
    force = np.linalg.norm(loads[:, :, :3], axis=-1)
    clearance = laws[:, LAW_CLEARANCE] if laws.size else np.zeros(pos.shape[0])
    contact = bool(np.any((clearance[None, :] > 0) & (dn > clearance[None, :])))
    return float(dn.max(initial=0.0)), float(force.max(initial=0.0)), contact


def _check_thrusts(thrusts, thrust_max: float) -> tuple[float, ...]:
    if thrusts is None:
        return ()
    values = []
    for t in np.atleast_1d(np.asarray(thrusts, dtype=object)).tolist():
        if isinstance(t, bool) or not isinstance(t, (int, float, np.integer, np.floating)):
            raise ModelError("thrusts", t, "must be numbers (N)")
        t = float(t)
        if not math.isfinite(t) or t < 0.0:
            raise ModelError("thrusts", t, "must be finite and non-negative (N)")
        if t > thrust_max:
            raise ModelError("thrusts", t, f"must not exceed thrust_max = {thrust_max:g} N")
        values.append(t)
    return tuple(sorted(set(values)))


def propulsor_postcritical(
    model,
    thrust_max: float | None = None,
    thrusts=None,
    *,
    max_points: int = DEFAULTS["max_points"],
    amplitude_max: float = DEFAULTS["amplitude_max"],
    intervals: int = DEFAULTS["intervals"],
    degree: int = DEFAULTS["degree"],
    progress: Callable[[int, float], None] | None = None,
    branch: bool = True,
    critical=None,
) -> PostcriticalResult:
    """Hopf analysis at the flutter onset of ``model`` and its branch of limit cycles.

    Parameters
    ----------
    model : Model
        An assembled model (:func:`impstab.load_model`); nonlinear mount laws (``k3_axial``,
        ``k3_shear``, snubbers) decide the post-critical behaviour.
    thrust_max : float, optional
        Upper end of the onset search and of the branch (N); default ``model.analysis.thrust_max``.
    thrusts : sequence of float, optional
        Thrusts (N) at which cycles are wanted: each appears exactly in ``branch_thrust``, with
        every cycle the branch has there (two between the fold and the onset of a subcritical
        branch); where the computed branch has none, an entry labelled "no cycle" (the
        equilibrium's amplitude 0 where it is stable, NaN where it is not).
    max_points : int
        Continuation steps at most.
    amplitude_max : float
        Stop the branch when a coordinate's amplitude exceeds this many state scales (0.01 L
        for displacements, 0.01 rad for angles, L the largest mount or thrust arm).
    intervals, degree : int
        Initial collocation mesh intervals and polynomial degree.
    progress : callable, optional
        ``progress(points_done, thrust)`` after each continuation step.
    branch : bool
        Continue the branch of cycles (``False``: the Hopf analysis only; ``fold_thrust`` is then
        None and ``stop_reason`` says the branch was not computed).
    critical : CriticalThrust, optional
        The linear onset when already known (anything with ``thrust``, ``kind``, ``omega`` and
        ``linearization``, computed with the same ``thrust_max``); default :func:`impstab.critical_thrust`.

    Returns
    -------
    PostcriticalResult
    """
    from .._jit import require_compiled
    from ..limits import check_number
    from ..linear.critical_thrust import critical_thrust

    require_compiled()  # a Hopf analysis and a branch of cycles: seconds of kernel time
    t_max = check_number("thrust_max", thrust_max if thrust_max is not None else model.analysis.thrust_max, "thrust")
    requested = _check_thrusts(thrusts, t_max)
    crit = critical if critical is not None else critical_thrust(model, thrust_max=t_max)
    settings = {"thrust_max": t_max, "max_points": int(max_points), "amplitude_max": float(amplitude_max),
                "intervals": int(intervals), "degree": int(degree), "linearization": crit.linearization,
                "requested_thrusts": list(requested)}
    base = dict(model_name=model.name, thrust_max=t_max, operating_thrust=model.thrust.operating,
                linear_kind=crit.kind, linear_critical_thrust=crit.thrust, settings=settings)
    if crit.kind == "none" or crit.thrust is None:
        return PostcriticalResult.without_branch(
            critical_thrust=None, kind="none", omega=None, bifurcation=None,
            reason=f"no loss of stability up to thrust_max = {t_max:g} N: there is no onset to analyse",
            requested=requested, stable_below=math.inf, **base)
    if crit.kind == "divergence":
        # a real eigenvalue through zero: a fold (limit point) or pitchfork of equilibria, where the
        # static equilibrium itself may cease to exist; no cycle is born
        return PostcriticalResult.without_branch(
            critical_thrust=crit.thrust, kind="divergence", omega=None, bifurcation="degenerate",
            reason="divergence: a real eigenvalue crosses zero (a static instability: a fold or pitchfork of "
                   "equilibria), so no limit cycle is born and there is no Lyapunov coefficient",
            requested=requested, stable_below=crit.thrust, **base)
    system, ns = propulsor_system(model, crit.omega)
    x0 = ns.equilibrium(crit.thrust)
    hopf = hopf_analysis(system, x0, crit.thrust, omega=crit.omega if crit.kind == "flutter" else None,
                         radius=DEFAULTS["circle_radius"], points=DEFAULTS["circle_points"])
    settings["state_scale"] = np.asarray(system.state_scale).tolist()
    kind = "divergence" if hopf.onset == "divergence" else "flutter"
    if hopf.bifurcation == "degenerate" and not (hopf.reason or "").startswith("l1 = 0"):
        return PostcriticalResult.without_branch(
            critical_thrust=hopf.parameter, kind=kind, omega=hopf.omega, bifurcation="degenerate",
            reason=hopf.reason, requested=requested, stable_below=hopf.parameter, hopf=hopf, **base)
    if not branch:
        return PostcriticalResult.from_hopf(hopf=hopf, kind=kind, requested=requested, **base)
    parameter_scale = DEFAULTS["parameter_share"] * hopf.parameter
    branch = continue_cycles(system, hopf, p_max=t_max, p_min=0.0, parameters=requested,
                             amplitude_max=float(amplitude_max), max_points=int(max_points), ds=DEFAULTS["ds"],
                             ds_max=DEFAULTS["ds_max"], intervals=int(intervals), degree=int(degree),
                             parameter_scale=parameter_scale, progress=progress)
    peaks = [mount_peaks(ns, c.sample(MOUNT_SAMPLES)[1]) for c in branch.cycles]
    return PostcriticalResult.from_branch(hopf=hopf, kind=kind, branch=branch, peaks=peaks, requested=requested,
                                          **base)
