"""Time histories below, at and above the critical thrust (the paper's Figures 5-6).

Three nonlinear runs from the static equilibrium with the default sway and pitch kick, at
:data:`THRUST_FACTORS` times the critical thrust, on one time grid. Unless a duration is given,
each run lasts long enough for the supercritical one to grow by ``e^GROWTH_FOLDS`` (about 20
times) at the largest growth rate of its linearization, but at least :data:`MIN_PERIODS` and at
most :data:`MAX_PERIODS` periods of the onset frequency (13 s to 130 s for a 3 Hz onset): the
envelopes then show decay, a steady amplitude and growth, for well under a second of computing
per run once compiled. A run that grows past the range of small motions is drawn only that far
(see :mod:`impstab.plot.simulation`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np

from ...display.format import growth, number
from ..result import NOT_COMPUTED, Figure, Note, Section
from ..svg import draw_svg, mathtext_safe
from ..tables import table
from .titles import TITLES
from .context import ModelContext

__all__ = ["simulation_section", "THRUST_FACTORS", "GROWTH_FOLDS", "MIN_PERIODS", "MAX_PERIODS", "run_settings"]

#: thrusts of the three runs, as multiples of the critical thrust: sub-, at- and supercritical
THRUST_FACTORS = (0.9, 1.0, 1.05)
#: e-foldings of the supercritical run's linear growth that set the default length
GROWTH_FOLDS = 3.0
#: shortest and longest default length, in periods of the onset frequency
MIN_PERIODS, MAX_PERIODS = 40, 400
#: growth over a run (e-foldings of the supercritical linear rate) below which it is invisible and said so
WEAK_GROWTH = 0.1
_KINDS = ("subcritical", "at the critical thrust", "supercritical")


def run_settings(ctx: ModelContext) -> tuple[list[float], float] | str:
    """``(thrusts (N), duration (s))`` of the three runs, or the reason there are none."""
    crit = ctx.critical
    if crit.thrust is None:
        return (f"no critical thrust up to thrust_max = {number(crit.thrust_max)} N: there is no sub-, at- and "
                "supercritical triple to show")
    if crit.kind == "divergence":
        return (f"the onset is a divergence (a static instability at {number(crit.thrust)} N): the equilibrium the "
                "runs start from is singular there and unstable beyond, the motion a static collapse, not an "
                "oscillation; the sub-, at- and supercritical time histories are shown for a flutter onset")
    thrusts = [factor * crit.thrust for factor in THRUST_FACTORS]
    duration = ctx.options.duration
    if duration is None:
        from ...linear.modes import modes

        f = crit.frequency_hz                     # a flutter onset: a frequency > 0
        rate = float(np.max(modes(ctx.model, thrusts[-1]).growth_rate))
        grow = GROWTH_FOLDS / rate if rate > 0 else math.inf
        duration = min(max(grow, MIN_PERIODS / f), MAX_PERIODS / f)
    return thrusts, float(duration)


def _draw(runs):
    """One row per run, sway left and pitch right, on a page-wide figure."""
    import matplotlib.pyplot as plt

    from ...plot.simulation import plot_simulations

    n = len(runs)
    fig, axes = plt.subplots(n, 2, figsize=(8.6, 2.55 * n + 0.5), layout="constrained", squeeze=False)
    handle = plot_simulations(runs, ax=np.array([axes[:, 0], axes[:, 1]]))
    fig.suptitle(f"time histories of {runs[0].model_name}: sway (left) and pitch (right)")
    for a in axes[:-1].ravel():
        a.set_xlabel("")
    axes[-1, 0].set_xlabel("time t (s)")
    return handle


def simulation_section(ctx: ModelContext) -> Section:
    from ...dynamics.simulate import default_step, simulate

    title = TITLES["simulation"]
    if not ctx.options.simulation:
        return Section("simulation", title, NOT_COMPUTED, "left out of this report: no time histories asked for "
                                                          "(--no-simulation; simulation=False in Python)")
    settings = run_settings(ctx)
    if isinstance(settings, str):
        return Section("simulation", title, NOT_COMPUTED, settings)
    thrusts, duration = settings
    crit = ctx.critical.thrust
    dt = min(default_step(ctx.model, t) for t in thrusts)
    sample = dt * max(1, math.ceil(duration / dt / 4000))       # at most about 4000 points drawn per run
    runs = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for t in thrusts:
            runs.append(simulate(ctx.model, thrust=t, duration=duration, dt=dt, sample=sample, critical_thrust=crit))
    drawn = [replace(r, model_name=mathtext_safe(r.model_name)) for r in runs]
    svg = draw_svg(lambda: _draw(drawn), "simulation")
    rows = []
    for kind, r in zip(_KINDS, runs):
        g = r.growth
        exponential = g is not None and g.envelope in ("exponential growth", "decaying") and math.isfinite(g.rate)
        rows.append([f"{number(r.thrust[0])} ({kind})", r.classification, g.envelope if g else "no fit",
                     number(g.rate, 5) if exponential else "n/a (not exponential)",
                     growth(g.linear_rate, r.fastest_omega) if g and g.linear_rate is not None else "not computed",
                     "completed" if r.completed else f"stopped at {number(r.stop_time, 4)} s: {r.stop_reason}"])
    factors = ", ".join(f"{f:g}" for f in THRUST_FACTORS)
    blocks = [
        Figure(svg, f"Nonlinear time histories from the static equilibrium, kicked in sway (1e-5 m/s) and pitch "
                    f"(1e-5 rad/s), at {factors} x the critical thrust {number(crit)} N; Hamming's "
                    f"predictor-corrector, step {number(dt, 4)} s, {number(duration, 4)} s each"
                    + ("" if ctx.options.duration is not None else
                       f" ({number(duration * ctx.critical.frequency_hz, 3)} periods of the onset frequency; "
                       f"the supercritical run grows by e^{GROWTH_FOLDS:g} at its linear rate)"
                       if ctx.critical.frequency_hz else "")
                    + "."),
        table("runs", rows, ["thrust (N)", "class", "envelope", "fitted growth (1/s)", "max Re λ (1/s)", "outcome"],
              ["left", "left", "left", "right", "right", "left"]),
    ]
    last = runs[-1]
    super_rate = last.growth.linear_rate if last.growth is not None else None
    if super_rate is not None and abs(super_rate) <= 1e-10 * last.fastest_omega:
        text = (f"At {number(last.thrust[0])} N the simulated system has max Re λ = 0 to rounding: the run above the "
                "critical thrust does not grow.")
        if ctx.model.fluid.compressible:
            own = (f"the undamped critical thrust {number(ctx.critical.undamped_thrust)} N" if not ctx.model.is_damped
                   else "that of the model with its mount dampers but without radiation damping")
            text += (" The time simulation takes the fluid coefficients at 0 Hz, without the radiation damping that "
                     f"sets this model's critical thrust through the onset frequency; its own onset is {own}.")
        blocks.append(Note(text))
    elif super_rate is not None and 0 < super_rate * duration < WEAK_GROWTH:
        blocks.append(Note(f"The supercritical growth rate {number(super_rate, 3)} 1/s doubles the amplitude only "
                           f"every {number(math.log(2) / super_rate, 3)} s: the instability is too weak to be seen in "
                           f"a run of {number(duration, 4)} s (it is real, but slow)."))
    blocks += [Note(w, "warning") for w in sorted({str(w.message) for w in caught})]
    return Section("simulation", title, blocks=tuple(blocks), data={"runs": tuple(runs)})
