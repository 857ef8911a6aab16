"""Time histories of sway and pitch (the paper's Figures 5-6).

Sway (the displacement of A along y) above pitch (rotation about y), each in a unit chosen
from the data (m, mm, um, nm; rad, mrad, urad) so that tick labels are plain numbers without an
offset. The outcome of a run (classification, fitted and linear growth rates, why it stopped)
is written in the panel titles, never over the data. A run that grows past the range of
small motions is drawn up to where it leaves that range (a rotation of :data:`ROTATION_RANGE`
or a displacement of A of one model length scale): beyond it the motion says nothing about a
real propulsor on its mounts, and the title says where the run itself ended.
"""

from __future__ import annotations

import math

import numpy as np

from ..display.format import growth, number
from .handles import SimulationAxes
from .style import ONSET_COLOR, PALETTE, figure_style

__all__ = ["plot_simulation", "plot_simulations", "ROTATION_RANGE", "amplitude_unit"]

#: largest rotation (rad) drawn: about 29 degrees, far beyond any mount's working range
ROTATION_RANGE = 0.5

_LENGTH_UNITS = ((1.0, "m"), (1e-3, "mm"), (1e-6, "µm"), (1e-9, "nm"))
_ANGLE_UNITS = ((1.0, "rad"), (1e-3, "mrad"), (1e-6, "µrad"), (1e-9, "nrad"))
_SWAY, _PITCH = 1, 4


def amplitude_unit(values, angle: bool = False) -> tuple[float, str]:
    """``(scale, unit)`` with ``values / scale`` of at most three digits before the point."""
    units = _ANGLE_UNITS if angle else _LENGTH_UNITS
    v = np.asarray(values, dtype=float)
    peak = float(np.nanmax(np.abs(v), initial=0.0)) if v.size else 0.0
    for scale, unit in units:
        if peak >= scale * 0.999:
            return scale, unit
    return (units[-1] if peak > 0 else units[0])


def drawn_range(result) -> tuple[int, str | None]:
    """Number of samples drawn and, when the run left the range of small motions, why."""
    disp = result.displacement
    n = disp.shape[0]
    rot = np.abs(disp[:, 3:]).max(axis=1) if n else np.zeros(0)
    trans = np.abs(disp[:, :3]).max(axis=1) if n else np.zeros(0)
    out = np.flatnonzero((rot > ROTATION_RANGE) | (trans > result.length_scale))
    if not out.size:
        return n, None
    k = int(out[0])
    what = (f"a rotation exceeds {ROTATION_RANGE:g} rad" if rot[k] > ROTATION_RANGE
            else f"A moves more than {result.length_scale:.3g} m")
    return max(k, 2), f"drawn to t = {result.time[k]:.4g} s, where {what}"


def _title(result) -> str:
    lines = [f"T = {result.thrust[0]:.6g} N" + (f": {result.classification}"
                                                  if result.classification not in ("", "not computed") else "")]
    g = result.growth
    if g is not None:
        text = f"envelope: {g.envelope}"
        if g.envelope in ("exponential growth", "decaying") and math.isfinite(g.rate):
            text += f" at {number(g.rate, 4)} 1/s"
        if g.envelope == "limit cycle" and g.amplitude:
            unit = "m" if g.dof in ("surge", "sway", "heave") else "rad"
            text += f", period {number(g.period, 4)} s, {g.dof} ±{number(g.amplitude[g.dof], 3)} {unit}"
        if g.linear_rate is not None:
            text += f"; max Re λ {growth(g.linear_rate, result.fastest_omega)} 1/s"
        lines.append(text)
    _, note = drawn_range(result)
    if not result.completed and result.stop_time is not None:
        reason = (result.stop_reason or "").split(" at t =")[0].split(" (")[0]
        lines.append(f"run stopped at t = {result.stop_time:.4g} s: {reason}")
    if note:
        lines.append(note)
    return "\n".join(lines)


def _draw(result, ax_s, ax_p, color_s: str, color_p: str) -> None:
    n, _ = drawn_range(result)
    t = result.time[:n]
    for a, j, color, name, angle in ((ax_s, _SWAY, color_s, "sway", False), (ax_p, _PITCH, color_p, "pitch", True)):
        if a is None:
            continue
        y = result.displacement[:n, j]
        scale, unit = amplitude_unit(y, angle)
        a.plot(t, y / scale, color=color, lw=1.0)
        a.set_ylabel(f"{name} ({unit})")
        a.axhline(0.0, color="0.6", lw=0.6, zorder=0)
        if not result.completed and result.stop_time is not None and n == result.time.size:
            a.axvline(result.stop_time, color=ONSET_COLOR, ls=":", lw=1.0)
        a.set_xlim(float(result.time[0]), float(t[-1]) if t.size else float(result.time[-1]))


def plot_simulation(result, ax=None):
    """Sway above pitch of ``result`` against time.

    Parameters
    ----------
    result : SimulationResult
    ax : None, one Axes or a pair of Axes
        None: a new figure with two stacked panels; one Axes: sway only; a pair: (sway, pitch).

    Returns
    -------
    SimulationAxes or Axes
        ``SimulationAxes(sway, pitch)``, or the one Axes given.
    """
    import matplotlib.pyplot as plt

    with figure_style():
        if ax is None:
            _, (ax_s, ax_p) = plt.subplots(2, 1, sharex=True, figsize=(7.2, 5.6), layout="constrained")
        elif isinstance(ax, (list, tuple, np.ndarray)):
            ax_s, ax_p = ax
        else:
            ax_s, ax_p = ax, None
        _draw(result, ax_s, ax_p, PALETTE[0], PALETTE[1])
        ax_s.set_title(f"{result.model_name}\n{_title(result)}" if result.model_name else _title(result))
        (ax_p if ax_p is not None else ax_s).set_xlabel("time t (s)")
    return SimulationAxes(ax_s, ax_p) if ax_p is not None else ax_s


def plot_simulations(results, ax=None):
    """Several runs side by side (one column per run: sway above, pitch below), like the paper's
    sub-, at- and supercritical Figures 5-6.

    Returns
    -------
    SimulationAxes
        ``sway`` and ``pitch`` are arrays of Axes, one per run. ``ax`` may be a ``(2, n)``
        array of Axes to draw on.
    """
    import matplotlib.pyplot as plt

    n = len(results)
    with figure_style():
        if ax is None:
            _, axes = plt.subplots(2, n, sharex="col", figsize=(3.9 * n + 0.8, 6.2), layout="constrained", squeeze=False)
        else:
            axes = np.asarray(ax, dtype=object).reshape(2, n)
        for j, res in enumerate(results):
            _draw(res, axes[0, j], axes[1, j], PALETTE[0], PALETTE[1])
            axes[0, j].set_title(_title(res), fontsize="small", loc="left")
            axes[1, j].set_xlabel("time t (s)")
        if n:
            axes[0, 0].figure.suptitle(f"time histories of {results[0].model_name}: sway (above) and pitch (below)")
    return SimulationAxes(axes[0], axes[1])
