"""Eigenvalue loci: frequency and growth rate of every mode against thrust (the paper's Figure 4).

One colour per branch (a conjugate pair of eigenvalues, one mode) in both panels, named in the
legend by its dominant dofs and its frequency at the first thrust; branches with identical loci
(the two planes of a symmetric layout) share one line and one entry. The onset is a vertical
line with a marker at the onset frequency and at zero growth, the undamped onset beside it, the
operating thrust dotted. The growth-rate axis turns symmetric-logarithmic when the growth just
past the onset is small against the largest growth (radiation damping: 1e-9 1/s beside 5 1/s),
so that the onset is seen; legends sit beside the panels, never over the data.
"""

from __future__ import annotations

import math

import numpy as np

from ..linear.locus import matching_order
from .handles import LocusAxes
from .style import ONSET_COLOR, PALETTE, figure_style

__all__ = ["plot_locus", "growth_axis_scale"]

#: eigenvalue rounding: growth rates below this fraction of the largest |lambda| are zero
_NOISE = 1e-12


def _groups(result) -> list[tuple[list[int], list[int]]]:
    """``(branches, columns)`` of each drawn line: branches with identical loci merged."""
    lam = result.eigenvalues
    modes = result.modes
    out: list[tuple[list[int], list[int]]] = []
    for b in range(int(modes.max()) + 1):
        cols = list(np.flatnonzero(modes == b))
        for group in out:
            if matching_order(lam[:, group[1]], lam[:, cols]) is not None:
                group[0].append(b)
                break
        else:
            out.append(([b], cols))
    return out


def growth_axis_scale(result) -> tuple[str, float | None]:
    """``("linear", None)`` or ``("symlog", linthresh)`` for the growth-rate axis.

    The growth that must be seen is the largest growth in the first 2 % of the thrust range past
    the onset (or, without an onset, the smallest positive growth above the rounding level). When
    it is below 1/30 of the largest growth on the plot a linear axis would flatten it onto zero:
    the axis is then symmetric-logarithmic, linear within a decade below that growth.
    """
    g = result.growth_rate
    finite = np.isfinite(g)
    if not finite.any():
        return "linear", None
    gmax = float(np.abs(g[finite]).max())
    floor = _NOISE * max(float(np.nanmax(np.abs(result.eigenvalues))), 1e-300)
    if gmax <= floor:
        return "linear", None
    t = result.thrust
    visible = None
    if result.critical_thrust is not None:
        span = 0.02 * max(float(t.max() - t.min()), 1e-300)
        band = (t >= result.critical_thrust) & (t <= result.critical_thrust + span)
        if not band.any():
            band = t >= result.critical_thrust
        vals = g[band][np.isfinite(g[band])]
        vals = vals[vals > floor]
        visible = float(vals.max()) if vals.size else None
    if visible is None:
        pos = g[finite & (g > 1e3 * floor)]
        visible = float(pos.min()) if pos.size else None
    if visible is None or visible * 30 >= gmax:
        return "linear", None
    return "symlog", 10.0 ** (math.floor(math.log10(visible)) - 1)


def _hz(x: float) -> str:
    return f"{x:.3g} Hz"


def _n(x: float) -> str:
    return f"{x:.6g} N"


def plot_locus(result, ax=None, *, growth_scale: str = "auto"):
    """Draw ``result`` (a :class:`~impstab.linear.locus.LocusResult`).

    Parameters
    ----------
    result : LocusResult
    ax : None, one Axes or a pair of Axes
        None: a new figure with the frequency panel above the growth-rate panel. One Axes: the
        frequency panel only. A pair: (frequency, growth).
    growth_scale : {"auto", "linear", "symlog"}
        ``"auto"`` chooses by :func:`growth_axis_scale`.

    Returns
    -------
    LocusAxes or Axes
        ``LocusAxes(frequency, growth)``, or the one Axes given.
    """
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    with figure_style():
        if ax is None:
            _, (ax_f, ax_g) = plt.subplots(2, 1, sharex=True, figsize=(8.8, 6.6), layout="constrained")
        elif isinstance(ax, (list, tuple, np.ndarray)):
            ax_f, ax_g = ax
        else:
            ax_f, ax_g = ax, None
        t = result.thrust
        lam = result.eigenvalues
        scale = max(float(np.nanmax(np.abs(lam))) if np.isfinite(lam).any() else 1.0, 1e-300)
        labels = result.branch_labels()
        handles = []
        groups = _groups(result)
        # the branches that grow most are drawn on top of those that stay on the axis
        peak = [float(np.nanmax(lam[:, cols].real, initial=-np.inf)) for _, cols in groups]
        rank = np.argsort(np.argsort(peak))
        for j, (branches, cols) in enumerate(groups):
            color = PALETTE[j % len(PALETTE)]
            z = 2.0 + 0.01 * rank[j]
            for c in cols:
                f = np.where(lam[:, c].imag > 1e-9 * scale, lam[:, c].imag / (2 * np.pi), np.nan)
                ax_f.plot(t, f, color=color, lw=1.5, zorder=z)
                if ax_g is not None:
                    ax_g.plot(t, lam[:, c].real, color=color, lw=1.5, zorder=z)
            f0 = float(np.nanmax(np.abs(lam[0, cols].imag))) / (2 * np.pi) if np.isfinite(lam[0, cols]).any() else np.nan
            name = " | ".join(labels[b] for b in branches)
            if len(branches) > 1:
                name += f" ({len(branches)} identical)"
            handles.append(Line2D([], [], color=color, lw=2.0, label=f"{f0:.3g} Hz: {name}" if f0 > 0 else f"real: {name}"))
        title = f"eigenvalue loci of {result.model_name}" if result.model_name else "eigenvalue loci"
        title += f" ({result.linearization} linearization"
        if result.fluid_frequency_hz:
            title += f"; fluid coefficients at {_hz(result.fluid_frequency_hz)}"
        ax_f.set_title(title + ")")
        ax_f.set_ylabel("frequency ω/2π (Hz)")
        ax_f.set_ylim(bottom=0.0)
        targets = [ax_f] if ax_g is None else [ax_f, ax_g]
        marks = _marks(result, targets, ax_f, ax_g)
        t0 = float(t[0]) if t.size else 0.0
        ax_f.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                    title=f"branches (frequency at {t0:.6g} N: dominant dofs)", alignment="left")
        last = ax_g if ax_g is not None else ax_f
        if ax_g is not None:
            _growth_axis(result, ax_g, growth_scale)
        if marks:
            last.legend(handles=marks, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                        title="thrusts", alignment="left")
        last.set_xlabel("thrust T (N)")
        for a in targets:
            a.set_xlim(float(t.min()), float(t.max()))
    return LocusAxes(ax_f, ax_g) if ax_g is not None else ax_f


def _marks(result, targets, ax_f, ax_g) -> list:
    from matplotlib.lines import Line2D

    marks = []
    tc = result.critical_thrust
    if tc is not None:
        kind = result.critical_kind or "onset"
        text = f"onset ({kind}): {_n(tc)}"
        if result.critical_frequency_hz:
            text += f", {_hz(result.critical_frequency_hz)}"
        for a in targets:
            a.axvline(tc, color=ONSET_COLOR, ls="--", lw=1.1)
        if result.critical_frequency_hz is not None:
            ax_f.plot([tc], [result.critical_frequency_hz], "o", color=ONSET_COLOR, ms=5, zorder=5)
        if ax_g is not None:
            ax_g.plot([tc], [0.0], "o", color=ONSET_COLOR, ms=5, zorder=5)
        marks.append(Line2D([], [], color=ONSET_COLOR, ls="--", marker="o", ms=5, label=text))
    tu = result.undamped_critical_thrust
    if tc is not None and tu is not None and abs(tu - tc) > 1e-9 * max(abs(tc), 1.0):
        for a in targets:
            a.axvline(tu, color="0.35", ls="-.", lw=1.1)
        marks.append(Line2D([], [], color="0.35", ls="-.", label=f"undamped onset: {_n(tu)}"))
    elif tc is not None and tu is not None:
        marks.append(Line2D([], [], color="none", label="undamped onset: the same (no damping)"))
    elif tc is not None and result.critical_kind is not None:
        marks.append(Line2D([], [], color="none", label="undamped: stable over the range"))
    op = result.operating_thrust
    if op is not None and result.thrust.min() <= op <= result.thrust.max():
        for a in targets:
            a.axvline(op, color="0.15", ls=":", lw=1.1)
        marks.append(Line2D([], [], color="0.15", ls=":", label=f"operating: {_n(op)}"))
    return marks


def _growth_axis(result, ax_g, growth_scale: str) -> None:
    ax_g.axhline(0.0, color="0.4", lw=0.8)
    kind, linthresh = growth_axis_scale(result) if growth_scale == "auto" else (growth_scale, None)
    label = "growth rate σ = Re λ (1/s)"
    if kind == "symlog":
        if linthresh is None:
            kind, linthresh = growth_axis_scale(result)
            linthresh = linthresh or 1e-6
        from matplotlib.ticker import FixedLocator, NullLocator

        ax_g.set_yscale("symlog", linthresh=linthresh, linscale=0.5)
        g = result.growth_rate[np.isfinite(result.growth_rate)]
        ax_g.yaxis.set_major_locator(FixedLocator(_symlog_ticks(linthresh, float(g.min()), float(g.max()))))
        ax_g.yaxis.set_minor_locator(NullLocator())
        label += f"\nsymmetric log scale, linear within ±{linthresh:.0e}"
    ax_g.set_ylabel(label)


def _symlog_ticks(linthresh: float, lo: float, hi: float, per_side: int = 4) -> list[float]:
    """Zero and a few decades on each side, starting a decade above the linear range."""
    ticks = [0.0]
    for sign, end in ((1.0, hi), (-1.0, -lo)):
        if end <= linthresh * 10:
            continue
        first, last = math.log10(linthresh) + 1, math.floor(math.log10(end))
        decades = np.arange(first, last + 1)
        stride = max(1, math.ceil(decades.size / per_side))
        ticks += [sign * 10.0**d for d in decades[::-1][::stride]]
    return sorted(ticks)
