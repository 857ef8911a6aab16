"""``impstab.simulate``: nonlinear time histories of the propulsor under follower thrust."""

from __future__ import annotations

import math
import warnings
from dataclasses import replace
from typing import Callable

import numpy as np

from ..errors import ModelError
from ..kinematics import matrix_to_euler_zyx
from ..linear.linearize import linearize
from ..model.model import DOF_NAMES, Model
from .growth import classify, fit_run
from .integrators import Problem, get_integrator
from .loading import Perturbation, as_thrust_history
from .rhs import N_BODY, PITCH_LIMIT
from .system import pack_dynamics
from .result import SimulationResult
from .beam_mounts import beam_dofs, check_beam_step, fastest_root, modal_length_factors
from .viscoelastic import augmented_roots, check_explicit_step, step_limit

__all__ = ["simulate", "check_work", "check_step", "StepSizeWarning", "STEPS_PER_PERIOD", "fastest_mode", "default_step", "MAX_SAMPLES"]

#: fixed steps per period of the fastest mode of the linearized system (Hamming's method is
#: stable on the imaginary axis only for |h omega| below about 0.3; 40 steps give 0.157)
STEPS_PER_PERIOD = 40
#: default largest number of stored samples (the sampling interval grows beyond it)
MAX_SAMPLES = 100_000
#: floor of the SciPy methods' absolute tolerance, relative to the model's length scale
ATOL_FLOOR = 1e-15


class StepSizeWarning(UserWarning):
    """A fixed step larger than the stability and accuracy limit of the fastest mode."""


def _finite(field: str, value, positive: bool = True) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ModelError(field, value, "must be a number") from None
    if not math.isfinite(v) or (positive and v <= 0):
        raise ModelError(field, value, "must be a finite number > 0")
    return v


def _snubber_contact(model: Model, lin) -> np.ndarray | None:
    """The stiffness every snubber adds in full contact, ``sum T(rho_i)^T (k_snub I) T(rho_i)``
    at the arms of ``lin``'s pose (an upper bound of its tangent ``k_snub [ramp' n n^T +
    ramp / |d| (I - n n^T)]``); None without snubbers."""
    from ..kinematics import rigid_map

    extra = np.zeros((6, 6))
    found = False
    for m in model.mounts:
        law = m.nonlinear
        if law is not None and law.has_snubber:
            t = rigid_map(lin.rotation @ m.position)
            extra += law.snubber_stiffness * (t.T @ t)
            found = True
    return extra if found else None


def fastest_mode(lin, model: Model | None = None) -> tuple[float, str]:
    """``(|lambda|_max (rad/s), dominant dof)`` of the linearized system ``lin``; with ``model``,
    also of ``lin`` with every snubber of the model in full contact (a run that engages a stiff
    snubber vibrates faster than the equilibrium's modes)."""
    vals, vecs = np.linalg.eig(lin.state_matrix())
    j = int(np.argmax(np.abs(vals)))
    shape = np.abs(vecs[:6, j]) * np.sqrt(np.diag(lin.M))
    omega, mode = float(np.abs(vals[j])), DOF_NAMES[int(np.argmax(shape))]
    extra = None if model is None else _snubber_contact(model, lin)
    if extra is not None:
        om, md = fastest_mode(replace(lin, K=lin.K + extra))
        if om > omega:
            omega, mode = om, f"{md} in snubber contact"
    return omega, mode


def _fastest(model: Model, lin) -> tuple[float, str, float]:
    """``(omega (rad/s), dominant dof, rate (1/s))``: the fastest mode of ``lin`` (snubbers in
    contact included, :func:`fastest_mode`), with massive beam mounts of the body with the
    beams' kept modes (:func:`~impstab.dynamics.beam_mounts.fastest_root`), and, with
    viscoelastic mounts, of the augmented system with their internal variables, and its fastest
    real relaxation root (0 without)."""
    omega, mode = fastest_mode(lin, model)
    if model.has_massive_beams:
        beam = fastest_root(model, lin.thrust)
        if beam.omega > omega:
            omega, mode = beam.omega, beam.mode
    if not model.is_viscoelastic:
        return omega, mode, 0.0
    roots = augmented_roots(model, lin.thrust)
    if roots.omega > omega:
        omega, mode = roots.omega, roots.mode
    return omega, mode, roots.rate


def default_step(model: Model, thrust: float) -> float:
    """Default fixed step (s) at constant thrust ``thrust`` (N): ``STEPS_PER_PERIOD`` per period of
    the fastest mode of the system linearized at the static equilibrium (with its snubbers in
    full contact, when it has any; with the kept modes of massive beam mounts,
    :mod:`impstab.dynamics.beam_mounts`) and per ``2 pi / rate`` of the fastest relaxation of the
    viscoelastic internal variables (:mod:`impstab.dynamics.viscoelastic`)."""
    omega, _, rate = _fastest(model, linearize(model, float(thrust), "equilibrium"))
    return step_limit(omega, rate, STEPS_PER_PERIOD)


def _spin_law(model: Model) -> Callable:
    prop, op = model.propeller, model.thrust.operating
    if prop.speed_law == "sqrt-thrust":
        return lambda t: prop.speed * np.sqrt(np.maximum(t, 0.0) / op)
    return lambda t: np.full(np.shape(t), prop.speed)


def check_step(model: Model, thrust: float, integrator: str, dt: float | None, names: dict[str, str] | None = None) -> None:
    """Refuse a fixed step ``dt`` (s) of ``hamming`` or ``gill`` beyond its stability limit on the
    relaxation of viscoelastic internal variables or on the fastest kept mode of massive beam
    mounts at constant thrust ``thrust`` (N), before a run
    (:func:`~impstab.dynamics.viscoelastic.check_explicit_step`,
    :func:`~impstab.dynamics.beam_mounts.check_beam_step`); ``names`` as :func:`check_work`."""
    beams = model.has_massive_beams
    if dt is None or not (model.is_viscoelastic or beams) or not get_integrator(integrator).fixed_step:
        return
    omega, _, rate = _fastest(model, linearize(model, float(thrust), "equilibrium"))
    _refuse_unstable_step(model, get_integrator(integrator).name, float(dt), omega, rate, beams,
                          (names or PYTHON_NAMES)["dt"])


def _refuse_unstable_step(model: Model, integrator: str, dt: float, omega: float, rate: float, beams: bool,
                          field: str = "dt") -> None:
    """The explicit step ``dt`` against its stability limits: the fastest viscoelastic relaxation
    ``rate`` (1/s) and, with massive beam mounts, the fastest root ``omega`` (rad/s)."""
    check_explicit_step(model, integrator, dt, rate, field)
    if beams:
        check_beam_step(model, integrator, dt, omega, field)


#: the argument names of :func:`simulate` in the messages of :func:`check_work`
PYTHON_NAMES = {"dt": "dt", "duration": "duration", "sample": "sample", "allow_long": "allow_long=True"}
#: the option names of ``impstab simulate``
CLI_NAMES = {"dt": "--dt", "duration": "--duration", "sample": "--sample", "allow_long": "--allow-long"}


def check_work(model: Model, step_sizes: list[float], duration: float, dt: float | None, sample: float | None,
               allow_long: bool, names: dict[str, str] = PYTHON_NAMES) -> None:
    """Refuse runs whose time steps or stored samples exceed the limits, before they start.

    ``step_sizes`` holds each run's step (s). The steps of all runs together may be at most
    :data:`~impstab.limits.MAX_STEPS` (``allow_long``: :data:`~impstab.limits.LONG_FACTOR` times
    more). The samples of a run are every step, at most :data:`MAX_SAMPLES` of them, unless
    ``sample`` is given; each takes 8 bytes for the time, the 12 states, the thrust, the error
    estimate, the 6 loads of every mount, the viscoelastic internal variables and the beam mounts' modal
    states, twice (the run and a file written from it); they may
    take at most :data:`~impstab.limits.MAX_OUTPUT_BYTES`. ``names`` gives the argument names the
    messages use (``dt``, ``duration``, ``sample``, ``allow_long``).
    """
    from ..limits import LONG_FACTOR, MAX_OUTPUT_BYTES, MAX_STEPS, describe_count

    limit = MAX_STEPS * (LONG_FACTOR if allow_long else 1)
    total = sum(duration / h for h in step_sizes)
    field = names["dt"] if dt is not None else names["duration"]
    if total > limit:
        hint = "" if allow_long else f"; {names['allow_long']} runs up to {describe_count(limit * LONG_FACTOR)}" + (
            " with a progress bar" if names is CLI_NAMES else "")
        raise ModelError(field, dt if dt is not None else duration,
                         f"would need {describe_count(total)} time steps (limit {describe_count(limit)}){hint}")
    internal = 3 * sum(m.viscoelastic.n_terms for m in model.mounts if m.viscoelastic is not None)
    if model.has_massive_beams:
        internal += 2 * beam_dofs(model).n
    per_sample = 8 * 2 * (15 + 6 * len(model.mounts) + internal)
    samples = sum(math.ceil(duration / sample) if sample is not None else min(math.ceil(duration / h), MAX_SAMPLES)
                  for h in step_sizes)
    if samples * per_sample > MAX_OUTPUT_BYTES:
        raise ModelError(names["sample"] if sample is not None else field, sample if sample is not None else duration,
                         f"{describe_count(samples)} stored samples would take {samples * per_sample / 1024**3:.3g} GiB "
                         f"(limit {MAX_OUTPUT_BYTES / 1024**3:g} GiB): use a longer {names['sample']} interval")


def simulate(model: Model, thrust, duration: float, integrator: str = "hamming",
             dt: float | None = None, perturbation=None, sample: float | None = None, *,
             tol: float | None = None, rtol: float = 1e-8, atol=None, pitch_limit: float = PITCH_LIMIT,
             max_displacement: float | None = None, fit_window: tuple[float, float] | None = None,
             critical_thrust: float | None | bool = True,
             progress: Callable[[float], None] | None = None, allow_long: bool = False) -> SimulationResult:
    """Integrate the nonlinear equations of motion from the static equilibrium under thrust.

    Parameters
    ----------
    model : Model
    thrust : float, ThrustHistory or callable
        Thrust T (N): a constant, :class:`~impstab.dynamics.Ramp`, :class:`~impstab.dynamics.Step`
        or any function ``f(t)`` of time (s). The run starts at the static equilibrium at ``T(0)``.
    duration : float
        Simulated time (s).
    integrator : {"hamming", "gill", "dop853", "rk45", "radau", "lsoda"}
    dt : float, optional
        Fixed step (s) of ``hamming`` and ``gill``; default: ``STEPS_PER_PERIOD`` steps per period of
        the fastest mode of the linearized system (the kept modes of massive beam mounts included).
        A larger step warns (:class:`StepSizeWarning`); one beyond the method's stability limit on
        a viscoelastic relaxation or a kept beam mode is refused (:class:`~impstab.errors.ModelError`).
        For the SciPy methods it is the largest step (default unlimited). The step is shortened
        slightly so that samples and the end of the run fall on steps.
    perturbation : Perturbation, dict or None
        Initial displacement (m, rad) and velocity (m/s, rad/s) per dof from the equilibrium;
        default :meth:`Perturbation.default` (a small sway and pitch kick).
    sample : float, optional
        Sampling interval of the output (s); default every step (at most ``MAX_SAMPLES`` samples).
    tol : float, optional
        ``hamming`` only: step-size control on the relative local error per step (halve and
        restart above ``tol``, double below ``tol / 64``, never above the default step).
    rtol, atol : SciPy methods' tolerances (``atol`` default: ``rtol`` x the initial deviation, in
        each state's units, but not below ``ATOL_FLOOR`` x the length scale).
    pitch_limit : float
        Stop when ``|theta|`` reaches it (rad); the Euler angles are singular at 90 degrees.
    max_displacement : float, optional
        Stop when a displacement of A from the equilibrium exceeds it (m); default 10 x the
        model's length scale (the largest mount or thrust arm).
    fit_window : (t0, t1), optional
        Window of the envelope growth-rate fit (s); see :func:`~impstab.dynamics.growth.fit_run`.
    critical_thrust : True, float, None or False
        True computes the critical thrust for the classification; a number uses it; None means
        stable up to ``thrust_max``; False skips the classification.
    progress : callable, optional
        Called with the fraction done between compiled chunks.
    allow_long : bool
        Allow a run beyond :data:`~impstab.limits.MAX_STEPS` time steps (up to
        :data:`~impstab.limits.LONG_FACTOR` times more; ``impstab simulate --allow-long``). The
        steps (``duration / dt``, the default step when ``dt`` is not given) and the memory of the
        stored samples are estimated before the run and refused beyond the limits with a
        :class:`~impstab.errors.ModelError` naming the argument.

    Returns
    -------
    SimulationResult
    """
    duration = _finite("duration", duration)
    history = as_thrust_history(thrust)
    solver = get_integrator(integrator)
    if dt is not None:
        dt = _finite("dt", dt)
    if sample is not None:
        sample = _finite("sample", sample)
    pitch_limit = _finite("pitch_limit", pitch_limit)
    if pitch_limit >= math.pi / 2:
        raise ModelError("pitch_limit", pitch_limit, "must be below pi/2 rad (the Euler-angle singularity)")
    pert = Perturbation.coerce(perturbation)
    t0_thrust = float(history(0.0))
    if not math.isfinite(t0_thrust):
        raise ModelError("thrust", t0_thrust, "T(0) must be finite")
    lin = linearize(model, t0_thrust, "equilibrium")
    system = pack_dynamics(model, pitch_limit)
    length = system.length_scale
    yeq = np.zeros(system.n_states)
    yeq[:3] = lin.displacement
    yeq[3:6] = matrix_to_euler_zyx(lin.rotation)
    # internal states at rest: viscoelastic w_ij = d_i (the static deflection carries the load),
    # beam modes eta = eta' = 0 (the constraint modes carry the statics)
    yeq[N_BODY:] = system.internal_equilibrium(lin.displacement, lin.rotation)
    z0 = np.zeros(system.n_states)
    z0[:N_BODY] = pert.vector
    if abs(yeq[4] + z0[4]) >= pitch_limit:
        raise ModelError("perturbation.displacement.pitch", z0[4], "initial pitch must stay below pitch_limit")
    # step from the fastest mode and relaxation (at T(0), and at the extreme thrusts of a history)
    omega, mode, rate = _fastest(model, lin)
    t_probe = history(np.linspace(0.0, duration, 257))
    for t_other in (float(np.max(t_probe)), float(np.min(t_probe))):
        if abs(t_other - t0_thrust) > 1e-6 * max(abs(t0_thrust), 1.0):
            try:
                om, md, rt = _fastest(model, linearize(model, t_other, "equilibrium"))
            except Exception:  # noqa: BLE001 - no equilibrium there: keep the value at T(0)
                continue
            if om > omega:
                omega, mode = om, md
            rate = max(rate, rt)
    h_limit = step_limit(omega, rate, STEPS_PER_PERIOD)
    if solver.fixed_step and dt is not None:
        _refuse_unstable_step(model, solver.name, dt, omega, rate, bool(system.n_modes))
        if dt > h_limit * (1 + 1e-9):
            what = (f"the fastest mode ({mode}, {omega / (2 * math.pi):.4g} Hz)" if omega >= rate else
                    f"the fastest relaxation of the viscoelastic internal variables ({rate:.4g} 1/s)")
            warnings.warn(
                f"dt = {dt:.4g} s is larger than the limit {h_limit:.4g} s for {what}: use at least "
                f"{STEPS_PER_PERIOD} steps per period, or the integrator's own growth can look like flutter",
                StepSizeWarning, stacklevel=2)
    h = dt if dt is not None else h_limit
    check_work(model, [h], duration, dt, sample, allow_long)
    if sample is None:
        steps = math.ceil(duration / h)
        sample = h * max(1, math.ceil(steps / MAX_SAMPLES))
    n_samples = max(1, math.ceil(duration / sample - 1e-9))
    sample = duration / n_samples
    stride = max(1, math.ceil(sample / h - 1e-9))
    h = sample / stride
    spin = _spin_law(model)

    def loads(t):
        tt = np.asarray(history(t), dtype=float)
        return np.vstack([tt, spin(tt)])

    # error weights make every state a length; the internal variables are lengths (m), a beam's
    # modal coordinate (kg^0.5 m) over the square root of the beam's mass is one
    root_mass = modal_length_factors(model, system)
    weights = np.concatenate([[1, 1, 1, length, length, length], [1 / omega] * 3, [length / omega] * 3,
                              np.ones(3 * system.n_terms), 1 / root_mass, 1 / (root_mass * omega)])
    # absolute tolerance (in metres after weighting): rtol x the initial deviation, floored at
    # 1e-15 x the length scale, where the rounding of the absolute state (eps x |y_eq|) takes over
    scale = max(float(np.max(np.abs(weights * z0))), 1e-9 * length)
    atol_m = max(rtol * scale, ATOL_FLOOR * length)
    problem = Problem(
        system=system, yeq=yeq, z0=z0, t0=0.0, h=h, stride=stride, n_samples=n_samples, loads=loads,
        weights=weights,
        amp_limit=10 * length if max_displacement is None else _finite("max_displacement", max_displacement),
        pitch_limit=pitch_limit, h_max=h_limit if solver.fixed_step else (dt or 0.0),
        tol=0.0 if tol is None else _finite("tol", tol), rtol=_finite("rtol", rtol),
        atol=np.asarray(atol, float) if atol is not None else atol_m / weights,
        constant_load=(t0_thrust, float(spin(t0_thrust))) if history.is_constant else None,
    )
    raw = solver.run(problem, progress)
    return _assemble(model, history, solver, problem, raw, lin, yeq, length, omega, mode, h_limit, pert,
                     fit_window, critical_thrust, duration)


def _assemble(model, history, solver, problem, raw, lin, yeq, length, omega, mode, h_limit, pert, fit_window,
              critical_thrust, duration) -> SimulationResult:
    from .system import mount_loads

    thrust_t = np.asarray(history(raw.time), dtype=float).reshape(raw.time.shape)
    loads6 = mount_loads(problem.system, yeq, raw.z)
    t_end = float(thrust_t[-1]) if thrust_t.size else float(history(0.0))
    lin_end = lin
    if abs(t_end - lin.thrust) > 1e-9 * max(abs(lin.thrust), 1.0):
        try:
            lin_end = linearize(model, t_end, "equilibrium")
        except Exception:  # noqa: BLE001 - no equilibrium at the final thrust
            lin_end = None
    linear_rate = None if lin_end is None else float(np.max(lin_end.eigenvalues().real))
    offset = None
    if lin_end is not None and lin_end is not lin:
        # a history that ends at another thrust: the motion about the final equilibrium
        offset = np.zeros(12)
        offset[:3] = lin_end.displacement - yeq[:3]
        offset[3:6] = np.asarray(matrix_to_euler_zyx(lin_end.rotation)) - yeq[3:6]
    if lin_end is not None and model.is_viscoelastic:
        linear_rate = augmented_roots(model, lin_end.thrust).max_real
    elif lin_end is not None and problem.system.n_modes:
        linear_rate = fastest_root(model, lin_end.thrust).max_real
    body = raw.z[:, :N_BODY]
    growth = fit_run(raw.time, body, length, fit_window, linear_rate, t_end, omega_max=omega, offset=offset,
                     thrusts=thrust_t)
    internal = None
    sysm = problem.system
    start, n_modes = sysm.mode_start, sysm.n_modes
    if sysm.n_terms:
        internal = (yeq[None, N_BODY:start] + raw.z[:, N_BODY:start]).reshape(raw.z.shape[0], -1, 3)
    modal = None if not n_modes else raw.z[:, start:start + 2 * n_modes]
    crit = None
    classification = "not computed"
    if critical_thrust is not False:
        if critical_thrust is True:
            from ..errors import NumericalError
            from ..linear.critical_thrust import critical_thrust as _ct

            try:
                crit = _ct(model, linearization="equilibrium").thrust
                classification = classify(t_end, crit, model.analysis.thrust_max)
            except NumericalError:
                classification = "unknown"
        else:
            crit = None if critical_thrust is None else float(critical_thrust)
            classification = classify(t_end, crit, model.analysis.thrust_max)
    return SimulationResult(
        time=raw.time, deviation=np.ascontiguousarray(body), equilibrium=yeq[:N_BODY].copy(), thrust=thrust_t, mount_loads=loads6,
        error_estimate=raw.error, model_name=model.name, integrator=solver.name, dt=problem.h,
        final_dt=raw.final_step, sample=problem.sample, duration=duration, thrust_history=history.describe(),
        perturbation=pert.to_dict(), completed=raw.completed, stop_reason=raw.reason, stop_time=raw.stop_time,
        steps=raw.steps, rhs_evaluations=raw.rhs_evals, restarts=raw.restarts, wall_time=raw.wall_time,
        fastest_omega=omega, fastest_mode=mode, step_limit=h_limit, length_scale=length, growth=growth,
        critical_thrust=crit, classification=classification,
        tolerances={"tol": problem.tol, "rtol": problem.rtol} if not solver.fixed_step or problem.tol else {},
        internal_variables=internal,
        internal_mounts=None if internal is None else problem.system.term_mounts.copy(),
        beam_modes=None if modal is None else np.ascontiguousarray(modal[:, :n_modes]),
        beam_mode_rates=None if modal is None else np.ascontiguousarray(modal[:, n_modes:]),
        beam_mode_mounts=None if modal is None else sysm.mode_mounts.copy(),
        beam_mode_omega=None if modal is None else np.sqrt(np.asarray(sysm.arrays[14])[:, 0]),
    )
