"""Time histories of sway and pitch (the paper's Figures 5-6)."""

from __future__ import annotations

import numpy as np

__all__ = ["plot_simulation", "plot_simulations"]


def _label(result) -> str:
    text = f"T = {result.thrust[0]:.6g} N" if result.thrust.size else "T = ?"
    if result.classification not in ("not computed", ""):
        text += f" ({result.classification})"
    return text


def _growth_note(result) -> str:
    g = result.growth
    if g is None:
        return ""
    note = f"envelope: {g.envelope}"
    if g.envelope == "limit cycle" and g.amplitude:
        note += f"\nperiod {g.period:.4g} s, {g.dof} ±{g.amplitude[g.dof]:.3g}"
    if np.isfinite(g.rate):
        note += f"\nfitted growth {g.rate:.4g} 1/s"
    if g.linear_rate is not None:
        note += f"\nmax Re(λ) {g.linear_rate:.4g} 1/s"
    return note


def _draw(result, ax_s, ax_p, color=None, label=None):
    t = result.time
    ax_s.plot(t, result.displacement[:, 1], color=color, lw=1.0, label=label)
    if ax_p is not None:
        ax_p.plot(t, result.displacement[:, 4], color=color, lw=1.0, label="pitch")
        ax_p.plot(t, result.displacement[:, 5], color=color, lw=0.8, ls="--", alpha=0.6, label="yaw")
    for a in (ax_s,) if ax_p is None else (ax_s, ax_p):
        if not result.completed and result.stop_time is not None:
            a.axvline(result.stop_time, color="C3", ls=":", lw=0.9)
        a.grid(True, alpha=0.3)


def plot_simulation(result, ax=None):
    """Draw sway (m), pitch and yaw (rad, yaw dashed) of ``result`` against time; returns the axes.

    ``ax`` may be None (a new figure with two stacked axes), one Axes (sway only) or a pair.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, (ax_s, ax_p) = plt.subplots(2, 1, sharex=True, figsize=(7.0, 5.5), layout="constrained")
    elif isinstance(ax, (list, tuple, np.ndarray)):
        ax_s, ax_p = ax
    else:
        ax_s, ax_p = ax, None
    _draw(result, ax_s, ax_p, color="C0")
    ax_s.set_ylabel("sway (m)")
    ax_s.set_title(f"{result.model_name}: {_label(result)}", fontsize="medium")
    note = _growth_note(result)
    if not result.completed:
        import textwrap

        note = (note + "\n" if note else "") + textwrap.fill(f"stopped: {result.stop_reason}", 48)
    if note:
        ax_s.text(0.01, 0.98, note, transform=ax_s.transAxes, va="top", fontsize="x-small",
                  bbox={"facecolor": "white", "alpha": 0.7, "edgecolor": "none"})
    if ax_p is not None:
        ax_p.set_ylabel("pitch, yaw (rad)")
        ax_p.legend(loc="lower left", fontsize="small")
        ax_p.set_xlabel("time (s)")
        return ax_s, ax_p
    ax_s.set_xlabel("time (s)")
    return ax_s


def plot_simulations(results, ax=None):
    """Several runs side by side (one column per run: sway above, pitch below); returns a
    ``(2, n)`` array of axes. ``ax`` may be such an array."""
    import matplotlib.pyplot as plt

    n = len(results)
    if ax is None:
        _, axes = plt.subplots(2, n, sharex="col", figsize=(4.0 * n + 1.0, 5.5), layout="constrained", squeeze=False)
    else:
        axes = np.asarray(ax, dtype=object).reshape(2, n)
    for j, res in enumerate(results):
        plot_simulation(res, ax=(axes[0, j], axes[1, j]))
        axes[0, j].set_title(_label(res), fontsize="medium")
        if j:
            axes[0, j].set_ylabel("")
            axes[1, j].set_ylabel("")
    if n:
        axes[0, 0].figure.suptitle(f"time histories of {results[0].model_name}")
    return axes
