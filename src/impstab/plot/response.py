"""Forced response: transmissibility against frequency with the modes marked; excitation band levels."""

from __future__ import annotations

import numpy as np

__all__ = ["plot_transmissibility", "plot_excitation"]


def _axes(ax, figsize=(9.0, 4.6)):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    _, ax = plt.subplots(figsize=figsize, layout="constrained")
    return ax


def _label_rows(freqs: list[float], labels: list[str], lo: float, hi: float, width_pt: float) -> list[int]:
    """Row of each tick label on the top axis so that none overlaps its neighbours (labels about
    4.5 pt a character, centred on their frequency, on an axis ``width_pt`` points wide)."""
    span = np.log10(hi / lo) if hi > lo else 1.0
    right: list[float] = []
    rows = []
    for f, text in zip(freqs, labels):
        x = np.log10(f / lo) * width_pt / span
        half = 0.5 * 4.5 * len(text) + 2.0
        row = next((r for r, edge in enumerate(right) if edge < x - half), len(right))
        if row == len(right):
            right.append(0.0)
        right[row] = x + half
        rows.append(row)
    return rows


def _mark_modes(ax, result, lo: float, hi: float) -> None:
    """Dotted lines at the damped natural frequencies, numbered on a top axis (labels of close
    modes staggered); the legend lists each mode's dominant dof and frequency."""
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FixedLocator, NullLocator

    f = result.mode_frequency_hz
    order = [int(j) for j in np.argsort(f, kind="stable") if f[j] > 0 and lo <= f[j] <= hi]
    if not order:
        return
    freqs = [float(f[j]) for j in order]
    numbers = [str(j + 1) for j in order]
    width_pt = 0.8 * ax.get_position().width * ax.figure.get_figwidth() * 72.0  # the legend takes room
    rows = _label_rows(freqs, numbers, lo, hi, width_pt)
    names = result.mode_dominant
    for fj, j in zip(freqs, order):
        ax.axvline(fj, color="0.45", ls=":", lw=0.9, zorder=1)
        ax.add_artist(Line2D([], [], lw=0, label=f"mode {j + 1}: {names[j] if j < len(names) else ''}, {fj:.4g} Hz"))
    top = ax.secondary_xaxis("top")
    top.xaxis.set_major_locator(FixedLocator(freqs))
    top.xaxis.set_minor_locator(NullLocator())
    top.set_xticklabels([n + "\n" * r for n, r in zip(numbers, rows)], fontsize="x-small", linespacing=1.0)
    rigid = not str(result.settings.get("foundation", "rigid")).startswith("compliant")
    top.set_xlabel("mode (damped natural frequencies at this thrust" + ("" if rigid else ", on a rigid hull") + ")",
                   fontsize="x-small")


def _hz_axis(ax, lo: float, hi: float) -> None:
    """Log frequency axis with plain numbers (1, 10, 100 Hz); minor ticks labelled on a short span."""
    from matplotlib.ticker import FuncFormatter, NullFormatter

    plain = FuncFormatter(lambda x, _: f"{x:g}")
    some = FuncFormatter(lambda x, _: f"{x:g}" if x > 0 and round(x / 10 ** np.floor(np.log10(x))) in (2, 3, 5) else "")
    ax.xaxis.set_major_formatter(plain)
    ax.xaxis.set_minor_formatter(some if hi / lo < 15.0 else NullFormatter())
    ax.tick_params(axis="x", which="minor", labelsize="x-small")


def _legend(ax) -> None:
    """Legend outside the axes on the right: the curves first, then the mode list."""
    pairs = list(zip(*ax.get_legend_handles_labels()))
    pairs = [p for p in pairs if not p[1].startswith("mode ")] + [p for p in pairs if p[1].startswith("mode ")]
    ax.legend([h for h, _ in pairs], [lab for _, lab in pairs], loc="upper left",
              bbox_to_anchor=(1.01, 1.0), fontsize="x-small", frameon=False, handlelength=1.5)


def plot_transmissibility(result, ax=None):
    """Transmissibility ``20 log10 |F_hull| / |F_in|`` (dB) against log frequency, modes marked.

    Frequencies at 0 Hz are left out (log axis). Returns the Axes.
    """
    ax = _axes(ax)
    f = result.frequency_hz
    keep = f > 0
    db = result.transmissibility_db
    unit = "N/(N m)" if result.input_unit == "N m" else "N/N"
    ax.semilogx(f[keep], db[keep], color="C0", lw=1.6, label=f"{result.input} input")
    ax.axhline(0.0, color="0.6", lw=0.8, zorder=0)
    if np.any(keep):
        lo, hi = float(f[keep].min()), float(f[keep].max())
        _mark_modes(ax, result, lo, hi)
        ax.set_xlim(lo, hi)
        _hz_axis(ax, lo, hi)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel(f"transmissibility |F_hull| / |F_in| (dB re 1 {unit})")
    ax.set_title(f"force transmissibility to the hull at T = {result.thrust:g} N ({result.linearization}), "
                 f"unit {result.input} {'moment' if result.input_unit == 'N m' else 'force'} at A",
                 fontsize="medium")
    ax.grid(True, which="both", alpha=0.25)
    _legend(ax)
    return ax


def plot_excitation(result, ax=None):
    """Hull force of each excitation line and the one-third-octave band levels (dB re 1 N, rms)."""
    ax = _axes(ax)
    f = result.frequency_hz
    keep = f > 0
    rms = result.hull_force_magnitude / np.sqrt(2.0)
    with np.errstate(divide="ignore"):
        line_db = 20.0 * np.log10(rms)
    bands = result.bands()
    if bands.index.size:
        level = bands.level_db
        has = np.isfinite(level)
        ax.bar(bands.lower_hz[has], level[has] - np.nanmin(level[has]) + 10.0,
               width=bands.upper_hz[has] - bands.lower_hz[has], bottom=np.nanmin(level[has]) - 10.0, align="edge",
               color="C1", alpha=0.35, edgecolor="C1", label="one-third-octave band level")
    sources = sorted({s.split("[")[0] for s in result.source}) or ["lines"]
    for k, src in enumerate(sources):
        sel = keep & np.array([s.startswith(src) for s in result.source]) if result.source else keep
        if np.any(sel):
            ax.vlines(f[sel], np.nanmin(line_db[keep]) - 10.0, line_db[sel], color=f"C{k + 2}", lw=1.2)
            ax.plot(f[sel], line_db[sel], "o", ms=3.5, color=f"C{k + 2}", label=f"{src.replace('_', ' ')} lines")
    ax.set_xscale("log")
    if np.any(keep):
        lo, hi = float(f[keep].min()) / 1.2, float(f[keep].max()) * 1.2
        _mark_modes(ax, result, lo, hi)
        ax.set_xlim(lo, hi)
        _hz_axis(ax, lo, hi)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("hull force, rms (dB re 1 N)")
    ax.set_title(f"hull force of the excitation at T = {result.thrust:g} N (shaft {result.shaft_rate:.4g} rad/s)",
                 fontsize="medium")
    ax.grid(True, which="both", alpha=0.25)
    _legend(ax)
    return ax
