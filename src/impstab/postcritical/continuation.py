"""Pseudo-arclength continuation of periodic orbits in the parameter, with bifurcation detection.

From a Hopf point the first cycle solves the collocation equations with the constraint
``<U - U_H, V_H> = ds``: ``U_H`` is the equilibrium as a constant "cycle" of period ``2 pi / omega``
and ``V_H = (2 Re(q e^{2 pi i tau}), 0, 0)`` the direction in which the cycles leave it; the
normal form (radius, parameter and period at that amplitude, second-order shape) is the initial
guess. Each later step predicts along the unit tangent ``V_k`` and corrects with Newton's method
under ``<U - U_k, V_k> = ds`` (Keller's pseudo-arclength), so folds are passed without special
treatment. The step grows after quick convergence, shrinks after slow convergence, a failure or a
sharp turn of the tangent, and is scaled so that the tangent turns by about 0.1 rad per step (a
smooth diagram: more points where the branch bends). The mesh is re-equidistributed every ``adapt_every`` steps (AUTO's IAD)
and the number of intervals doubled while the estimated profile error exceeds ``mesh_tolerance``.

On every accepted step the test functions are compared with the previous point's and each sign
change is located by Brent's method in the arclength (each trial point a corrected cycle):

* fold (limit point of cycles): ``dp/ds``, the parameter component of the tangent;
* period doubling: ``mu + 1`` for the real multiplier closest to -1 (an odd change of the number
  of real multipliers below -1);
* torus (Neimark-Sacker): ``|mu| - 1`` for the complex multiplier closest to the unit circle (a
  change of the number of complex multipliers outside it, the pair staying complex).

Requested parameter values crossed by a step are solved exactly (Newton's method at fixed ``p``
from the interpolated cycle), and so is the end point at ``p_min`` / ``p_max``.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError, NumericalError
from .collocation import Profile
from .events import TESTS, critical_multiplier, events, locate
from .hopf import HopfPoint
from .periodic import Weights
from .result import Cycle, CycleBranch, SpecialPoint
from .system import as_system
from .tracing import BranchPoint, Tracer, to_cycle

__all__ = ["continue_cycles", "find_cycle", "cycle_at", "cycles_at"]

Array = NDArray[np.float64]

#: a step is rejected when the tangent turns by more than this (cosine of the angle)
MIN_TANGENT_COSINE = 0.9
#: the step is scaled so that the tangent turns by about this much per step (rad)
TARGET_TURN = 0.1


# ----------------------------------------------------------------------- starting points
def _settings_weights(system, period_scale, parameter_scale) -> Weights:
    return Weights(np.asarray(system.state_scale, dtype=float), float(period_scale), float(parameter_scale))


def _hopf_start(tracer: Tracer, hopf: HopfPoint, intervals: int, ds: float) -> BranchPoint:
    if hopf.onset != "hopf" or hopf.eigenvector is None or not hopf.omega:
        raise ModelError("hopf", hopf.bifurcation, "cycles start from a Hopf point (a complex pair at onset); "
                         f"this onset is a {hopf.onset}")
    if hopf.bifurcation == "degenerate" and hopf.reason and not hopf.reason.startswith("l1 = 0"):
        raise ModelError("hopf", hopf.reason, "the branch of a single pair does not describe this onset; give a "
                         "start cycle (find_cycle) for a chosen branch")
    mesh = np.linspace(0.0, 1.0, intervals + 1)
    prob = tracer.problem(mesh)
    q = hopf.eigenvector
    period0 = 2 * math.pi / hopf.omega
    direction = Profile.uniform(lambda t: 2 * np.real(np.exp(2j * np.pi * t)[:, None] * q[None, :]),
                                intervals, tracer.degree)
    base = Profile(mesh, np.tile(hopf.state, (direction.nodes.shape[0], 1)), tracer.degree)
    u_h = prob.pack(base, period0, hopf.parameter)
    v_raw = prob.pack(direction, 0.0, 0.0)
    v_h = v_raw / prob.norm(v_raw)
    rho = ds / prob.norm(v_raw)
    if hopf.bifurcation != "degenerate":
        c1 = hopf.normal_form_coefficient
        p1 = hopf.parameter - c1.real * rho ** 2 / hopf.crossing_speed
        z = lambda t: rho * np.exp(2j * np.pi * t)                                   # noqa: E731
        guess_prof = Profile.uniform(
            lambda t: (hopf.state + hopf.equilibrium_slope * (p1 - hopf.parameter))[None, :]
            + 2 * np.real(z(t)[:, None] * q[None, :]) + np.real(z(t)[:, None] ** 2 * hopf.h20[None, :])
            + rho ** 2 * hopf.h11[None, :], intervals, tracer.degree)
        guess = prob.pack(guess_prof, float(hopf.predicted_period(p1)), p1)
    else:
        guess = u_h + ds * v_h
    ref = prob.profile(u_h + ds * v_h)
    sol = prob.solve(guess, ref, ("arclength", u_h, ds, v_h))
    pt = tracer.finish(prob, sol, ref, v_h, ds, "start")
    if pt is None:
        raise NumericalError(f"no cycle converged at the first step from the Hopf point (ds = {ds:g}); try a smaller ds")
    return pt


def _normal_form_point(tracer: Tracer, hopf: HopfPoint, first: BranchPoint, p: float) -> BranchPoint | None:
    """The cycle at ``p`` between the Hopf point and the first cycle, from the normal-form guess."""
    prob = first.problem
    mesh = prob.mesh
    try:
        rho = float(hopf.normal_form_radius(p))
    except ModelError:
        return None
    if not math.isfinite(rho):
        return None
    tau = Profile(mesh, first.sol.profile.nodes, first.sol.profile.degree).node_times()
    z = rho * np.exp(2j * np.pi * tau)
    q = hopf.eigenvector
    nodes = ((hopf.state + hopf.equilibrium_slope * (p - hopf.parameter))[None, :] + 2 * np.real(z[:, None] * q[None, :])
             + np.real(z[:, None] ** 2 * hopf.h20[None, :]) + rho ** 2 * hopf.h11[None, :])
    guess_prof = Profile(mesh, nodes, first.sol.profile.degree)
    guess = prob.pack(guess_prof, float(hopf.predicted_period(p)), p)
    sol = prob.solve(guess, guess_prof, ("parameter", None, p, None))
    rho_first = float(hopf.normal_form_radius(first.p))
    share = rho / rho_first if math.isfinite(rho_first) and rho_first > rho else 0.5
    return tracer.finish(prob, sol, guess_prof, first.tangent, share * first.arclength, "requested")


def _cycle_start(tracer: Tracer, cycle: Cycle, direction: int) -> BranchPoint:
    prof = cycle.profile
    prob = tracer.problem(prof.mesh)
    guess = prob.pack(prof, cycle.period, cycle.parameter)
    sol = prob.solve(guess, prof, ("parameter", None, cycle.parameter, None))
    orient = np.zeros(prob.size)
    orient[-1] = float(direction)
    pt = tracer.finish(prob, sol, prof, orient / prob.norm(orient), 0.0, "start")
    if pt is None:
        raise NumericalError("the start cycle did not converge at its parameter value")
    return pt


# ----------------------------------------------------------------------- public API
def continue_cycles(
    f,
    start: HopfPoint | Cycle,
    p_max: float,
    *,
    p_min: float = -math.inf,
    parameters: tuple[float, ...] | list[float] = (),
    amplitude_max: float = math.inf,
    period_max: float = math.inf,
    max_points: int = 200,
    ds: float = 0.01,
    ds_min: float = 1e-7,
    ds_max: float = 0.2,
    intervals: int = 40,
    degree: int = 4,
    adapt_every: int = 3,
    mesh_tolerance: float | None = 1e-7,
    max_intervals: int = 320,
    period_scale: float | None = None,
    parameter_scale: float = 1.0,
    direction: int = 1,
    progress: Callable[[int, float], None] | None = None,
) -> CycleBranch:
    """Continue the periodic orbits of ``B x' = f(x, p)`` from a Hopf point (or a cycle).

    Parameters
    ----------
    f : DynamicalSystem or callable
        The same system as given to :func:`hopf_analysis`.
    start : HopfPoint or Cycle
        The Hopf point the cycles are born at (not a degenerate one, except ``l1 = 0``), or a
        converged cycle (:func:`find_cycle`) to continue from.
    p_max, p_min : float
        The branch ends where it leaves ``[p_min, p_max]``, with a cycle exactly at the bound.
    parameters : sequence of float
        Parameter values at which the branch must hold a cycle: every crossing of each value is
        solved exactly (label "requested"); values never crossed are listed in ``unreached``.
    amplitude_max, period_max : float
        Stop when the largest scaled amplitude ``max_j amplitude_j / state_scale_j`` or the period
        exceeds these (the approach to a homoclinic orbit shows as a growing period).
    max_points : int
        Regular continuation steps at most.
    ds, ds_min, ds_max : float
        Initial, smallest and largest pseudo-arclength step, in the weighted norm
        ``|U|^2 = int |x / state_scale|^2 dtau + (T / period_scale)^2 + (p / parameter_scale)^2``.
        From a Hopf point ``ds`` is also the size of the first cycle in that norm.
    intervals, degree : int
        Mesh intervals (AUTO's NTST) and collocation degree (NCOL, Gauss points per interval).
    adapt_every : int
        Re-equidistribute the mesh every so many steps (0: fixed mesh).
    mesh_tolerance : float or None
        Largest estimated profile error, relative to the largest scaled amplitude, before the
        number of intervals is doubled (up to ``max_intervals``); None keeps ``intervals``.
    period_scale : float, optional
        Period scale of the norm (default: the period at the start).
    parameter_scale : float
        Parameter scale of the norm (parameter units).
    direction : {1, -1}
        From a start cycle: continue toward increasing (1) or decreasing (-1) ``p``.
    progress : callable, optional
        Called as ``progress(points_done, p)`` after every accepted step.

    Returns
    -------
    CycleBranch
    """
    if isinstance(start, HopfPoint):
        n = start.state.size
    elif isinstance(start, Cycle):
        n = start.profile.nodes.shape[1]
    else:
        raise ModelError("start", type(start).__name__, "must be a HopfPoint or a Cycle")
    system = as_system(f, n)
    _check_positive("ds", ds)
    _check_positive("ds_min", ds_min)
    _check_positive("ds_max", ds_max)
    _check_positive("parameter_scale", parameter_scale)
    if not ds_min <= ds <= ds_max:
        raise ModelError("ds", ds, f"must lie between ds_min = {ds_min:g} and ds_max = {ds_max:g}")
    if not (p_min < p_max) or math.isnan(p_max):
        raise ModelError("p_max", p_max, f"must exceed p_min = {p_min:g}")
    if isinstance(intervals, bool) or int(intervals) != intervals or intervals < 4:
        raise ModelError("intervals", intervals, "must be an integer of at least 4")
    if max_intervals < intervals:
        raise ModelError("max_intervals", max_intervals, f"must be at least intervals = {intervals}")
    if direction not in (1, -1):
        raise ModelError("direction", direction, "must be 1 or -1")
    requested = sorted({float(v) for v in parameters})
    for v in requested:
        if not math.isfinite(v):
            raise ModelError("parameters", v, "must be finite numbers")
    t0 = (2 * math.pi / start.omega) if isinstance(start, HopfPoint) and start.omega else getattr(start, "period", 1.0)
    weights = _settings_weights(system, period_scale or t0, parameter_scale)
    tracer = Tracer(system, weights, degree, mesh_tolerance, int(max_intervals))
    if isinstance(start, HopfPoint):
        first = _hopf_start(tracer, start, int(intervals), ds)
        hopf = start
    else:
        first = _cycle_start(tracer, start, direction)
        hopf = None
    if adapt_every:
        first = tracer.remesh(first)
    points: list[BranchPoint] = [first]
    extra: list[BranchPoint] = []
    special: list[tuple[str, BranchPoint]] = []
    crossed: set[float] = set()
    warnings: list[str] = []
    amp0 = _scaled_amplitude(first)
    if hopf is not None and hopf.bifurcation != "degenerate":
        # requested values between the Hopf point and the first cycle: from the normal form
        for v in requested:
            if (hopf.parameter - v) * (first.p - v) < 0 or first.p == v:
                pt = first if first.p == v else _normal_form_point(tracer, hopf, first, v)
                if pt is None:
                    warnings.append(f"no cycle converged at the requested p = {v:.10g} next to the Hopf point")
                    continue
                if pt is first:
                    first.label = "requested"
                else:
                    extra.append(pt)
                crossed.add(v)
    step = ds
    steps = 0
    stop = "maximum number of points reached"
    current = first
    if not p_min <= current.p <= p_max:
        stop = "the start lies outside [p_min, p_max]"
        steps = max_points
    while steps < max_points:
        new = tracer.correct(current, step)
        if new is not None:
            cos = current.problem.inner(new.tangent, current.tangent)
            if cos < MIN_TANGENT_COSINE and step > ds_min * 1.0001:
                new = None
        if new is None:
            step *= 0.5
            if step < ds_min:
                stop = f"no convergence at the smallest step ds_min = {ds_min:g}"
                break
            continue
        steps += 1
        # events between current and new
        for kind in events(current, new):
            loc = locate(tracer, current, new, kind)
            if loc is None:
                warnings.append(f"a {kind} between p = {current.p:.10g} and {new.p:.10g} could not be located")
                continue
            special.append((kind, loc))
            extra.append(loc)
        for v in requested:
            if (current.p - v) * (new.p - v) < 0 or new.p == v:
                pt = new if new.p == v else tracer.at_parameter(current, new, v, "requested")
                if pt is None:
                    warnings.append(f"no cycle converged at the requested p = {v:.10g}")
                    continue
                if pt is new:
                    new.label = "requested"
                else:
                    extra.append(pt)
                crossed.add(v)
        leaving = new.p > p_max or new.p < p_min
        if leaving:
            bound = p_max if new.p > p_max else p_min
            end = tracer.at_parameter(current, new, bound, "end")
            if end is not None:
                extra.append(end)
                stop = f"reached {'p_max' if bound == p_max else 'p_min'} = {bound:.10g}"
            else:
                points.append(new)
                stop = f"left [p_min, p_max] (no cycle converged exactly at {bound:.10g})"
            break
        points.append(new)
        if progress is not None:
            progress(len(points), new.p)
        amp = _scaled_amplitude(new)
        if amp > amplitude_max:
            stop = f"amplitude limit {amplitude_max:g} exceeded (largest scaled amplitude {amp:.6g})"
            break
        if new.sol.period > period_max:
            stop = f"period limit {period_max:g} exceeded (period {new.sol.period:.6g})"
            break
        if len(points) > 4 and amp < 0.25 * amp0 and hopf is not None:
            stop = "the cycles shrank back to an equilibrium (another Hopf point)"
            break
        # step control
        it = new.sol.iterations
        factor = 1.5 if it <= 3 else (1.0 if it <= 5 else 0.6)
        angle = math.acos(min(1.0, max(-1.0, current.problem.inner(new.tangent, current.tangent))))
        if angle > 0:
            factor = min(factor, max(0.5, TARGET_TURN / angle))
        step = min(max(step * factor, ds_min), ds_max)
        current = new
        if adapt_every and steps % adapt_every == 0:
            current = tracer.remesh(current)
            points[-1] = current
    if points and stop.startswith(("maximum", "amplitude", "period", "no convergence", "the cycles")):
        points[-1].label = points[-1].label or "end"
    allpts = sorted(points + extra, key=lambda p: p.arclength)
    cycles = tuple(to_cycle(p) for p in allpts)
    sp_points = tuple(SpecialPoint(kind, to_cycle(pt), TESTS[kind](pt), critical_multiplier(kind, pt))
                      for kind, pt in sorted(special, key=lambda kp: kp[1].arclength))
    unreached = tuple(v for v in requested if v not in crossed)
    settings = {"degree": degree, "intervals": int(intervals), "max_intervals": int(max_intervals),
                "adapt_every": adapt_every, "mesh_tolerance": mesh_tolerance, "ds": ds, "ds_min": ds_min,
                "ds_max": ds_max, "p_min": p_min, "p_max": p_max, "amplitude_max": amplitude_max,
                "period_max": period_max, "max_points": max_points, "state_scale": list(map(float, weights.state)),
                "period_scale": weights.period, "parameter_scale": weights.parameter,
                "failed_corrections": tracer.failures}
    return CycleBranch(cycles=cycles, hopf=hopf, special_points=sp_points, stop_reason=stop, unreached=unreached,
                       settings=settings, state_names=system.state_names, state_units=system.state_units,
                       parameter_name=system.parameter_name, parameter_units=system.parameter_units,
                       time_units=system.time_units, warnings=tuple(warnings))


def _scaled_amplitude(pt: BranchPoint) -> float:
    return float(np.max(pt.sol.profile.amplitude() / pt.problem.weights.state))


def _check_positive(name: str, value: float) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) \
            or not math.isfinite(value) or value <= 0:
        raise ModelError(name, value, "must be a positive finite number")


def find_cycle(
    f,
    guess,
    period: float,
    p: float,
    *,
    n: int | None = None,
    intervals: int = 40,
    degree: int = 4,
    mesh_tolerance: float | None = 1e-7,
    max_intervals: int = 320,
    period_scale: float | None = None,
    parameter_scale: float = 1.0,
) -> Cycle:
    """A periodic orbit at fixed ``p`` by Newton's method on the collocation equations.

    Parameters
    ----------
    f : DynamicalSystem or callable
    guess : callable or (k, n) array
        ``guess(tau) -> (len(tau), n)`` over the scaled time ``tau = t / T in [0, 1)``, or ``k``
        states equally spaced in time over one period (e.g. from a time integration), which are
        interpolated trigonometrically.
    period : float
        Period guess (time units).
    p : float
    n : int, optional
        Number of states (taken from ``guess`` when it is an array).
    intervals, degree, mesh_tolerance, max_intervals
        As in :func:`continue_cycles`: the mesh is equidistributed after the first solve and the
        intervals doubled until the estimated relative profile error is below ``mesh_tolerance``.

    Returns
    -------
    Cycle
        With its Floquet multipliers; raises NumericalError when Newton's method fails.
    """
    if callable(guess):
        if n is None:
            n = int(np.asarray(guess(np.array([0.0]))).shape[-1])
        fn = guess
    else:
        arr = np.asarray(guess, dtype=float)
        if arr.ndim != 2 or arr.shape[0] < 4:
            raise ModelError("guess", arr.shape, "must be a callable or an array (k >= 4 samples, n states)")
        n = arr.shape[1]
        fn = _trigonometric(arr)
    system = as_system(f, n)
    _check_positive("period", period)
    weights = _settings_weights(system, period_scale or period, parameter_scale)
    tracer = Tracer(system, weights, degree, mesh_tolerance, max(int(max_intervals), int(intervals)))
    prof = Profile.uniform(fn, intervals, degree)
    prob = tracer.problem(prof.mesh)
    sol = prob.solve(prob.pack(prof, period, p), prof, ("parameter", None, float(p), None), max_iter=40)
    orient = np.zeros(prob.size)
    orient[-1] = 1.0
    pt = tracer.finish(prob, sol, prof, orient / prob.norm(orient), 0.0, "")
    if pt is None:
        raise NumericalError(f"no periodic orbit converged from the guess at p = {p:.10g}")
    for _ in range(8):
        pt = tracer.remesh(pt)
        if mesh_tolerance is None or tracer.relative_error(pt.sol.profile) <= mesh_tolerance \
                or pt.sol.profile.intervals >= tracer.max_intervals:
            break
    return to_cycle(pt)


def _trigonometric(samples: Array):
    k = samples.shape[0]
    coef = np.fft.rfft(samples, axis=0) / k
    freqs = np.arange(coef.shape[0])

    def fn(tau):
        tau = np.asarray(tau, dtype=float)
        e = np.exp(2j * np.pi * tau[:, None] * freqs[None, :])
        w = np.full(freqs.size, 2.0)
        w[0] = 1.0
        if k % 2 == 0:
            w[-1] = 1.0
        return np.real((e * w[None, :]) @ coef)

    return fn


def cycles_at(f, branch: CycleBranch, p: float) -> tuple[Cycle, ...]:
    """Every cycle of ``branch`` at exactly ``p`` (Newton's method from each bracketing pair)."""
    cyc = branch.cycles
    if not cyc:
        return ()
    system = as_system(f, cyc[0].profile.nodes.shape[1])
    st = branch.settings
    weights = Weights(np.asarray(st.get("state_scale", system.state_scale), dtype=float),
                      float(st.get("period_scale", cyc[0].period)), float(st.get("parameter_scale", 1.0)))
    tracer = Tracer(system, weights, cyc[0].profile.degree, None, 10 ** 6)
    out = []
    for a, b in zip(cyc[:-1], cyc[1:]):
        if a.parameter == p:
            out.append(a)
            continue
        if (a.parameter - p) * (b.parameter - p) < 0:
            prob = tracer.problem(a.profile.mesh)
            theta = (p - a.parameter) / (b.parameter - a.parameter)
            nodes_b = b.profile.resample(a.profile.mesh).nodes
            prof = Profile(a.profile.mesh, a.profile.nodes + theta * (nodes_b - a.profile.nodes), a.profile.degree)
            guess = prob.pack(prof, a.period + theta * (b.period - a.period), p)
            sol = prob.solve(guess, a.profile, ("parameter", None, float(p), None))
            orient = np.zeros(prob.size)
            orient[-1] = 1.0
            pt = tracer.finish(prob, sol, a.profile, orient / prob.norm(orient),
                               a.arclength + theta * (b.arclength - a.arclength), "requested")
            if pt is None:
                raise NumericalError(f"no cycle converged at p = {p:.10g} between branch points")
            out.append(to_cycle(pt))
    if cyc[-1].parameter == p:
        out.append(cyc[-1])
    return tuple(out)


def cycle_at(f, branch: CycleBranch, p: float, which: int = 0) -> Cycle:
    """The ``which``-th cycle (in branch order) of ``branch`` at exactly ``p``.

    Raises ModelError when the branch does not pass ``p`` (that often).
    """
    found = cycles_at(f, branch, p)
    if not found or not -len(found) <= which < len(found):
        lo, hi = float(branch.parameter.min()), float(branch.parameter.max())
        raise ModelError("p", p, f"the branch passes it {len(found)} time(s) (it spans {lo:.10g} .. {hi:.10g})")
    return found[which]
