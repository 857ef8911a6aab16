"""The isolation-versus-stability trade-off of a design study: every design, the Pareto front,
the operating requirements.

x: the stability margin (critical / operating thrust; designs stable over their whole search
at their search limit, hollow: the true margin is larger); y: the isolation output (log scale:
transmissibility, N/N). Designs beyond a static limit are grey crosses, left out of the front.
The front is the line of filled markers; the required margin is a vertical line with the
region below it shaded; an isolation limit is a horizontal line; the chosen design (smallest
isolation value on the acceptable part of the front) is a star, annotated.
"""

from __future__ import annotations

import numpy as np

from .style import ONSET_COLOR, PALETTE, figure_style

__all__ = ["plot_tradeoff", "plot_optimization"]


_SHORT = {
    "peak_transmissibility": "peak transmissibility |F_hull| / |F_in| (N/N)",
    "static_deflection": "largest static mount deflection (m)",
    "peak_mount_load": "largest static mount force (N)",
}


def _axis_label(result, name: str) -> str:
    from .stability_map import value_label

    if name in _SHORT:
        return _SHORT[name]
    text = result.dataset[name].attrs.get("long_name", "") if name in result.dataset else ""
    if "transmissibility" in text:
        what = text.replace("force transmissibility |F_hull| / |F_in| ", "transmissibility ").replace(
            "largest force transmissibility |F_hull| / |F_in| ", "largest transmissibility ")
        return f"{name}: {what} (N/N)"
    return value_label(name)


def _minor_label(v: float, _pos) -> str:
    """Label the minor ticks 2, 3 and 5 of a decade (plain numbers)."""
    if v <= 0:
        return ""
    lead = round(v / 10 ** np.floor(np.log10(v)), 6)
    return f"{v:g}" if lead in (2.0, 3.0, 5.0) else ""


def plot_tradeoff(result, isolation: str = "peak_transmissibility", stability: str = "margin", *, ax=None,
                  required_margin: float | None = None, isolation_limit: float | None = None,
                  deflection_limit: float | None = None, load_limit: float | None = None, title: str | None = None):
    """Draw isolation against stability for every design of ``result``; returns the Axes.

    Parameters as :func:`impstab.studies.pareto.tradeoff_table`; ``isolation_limit`` draws the
    highest acceptable isolation value as a line.
    """
    from ..studies.pareto import tradeoff_table

    t = tradeoff_table(result, isolation, stability, required_margin=required_margin,
                       deflection_limit=deflection_limit, load_limit=load_limit)
    computed = np.isfinite(t["stability"]) & np.isfinite(t["isolation"]) & (result.dataset["status"].values.ravel() == 0)
    return _draw(ax, t["stability"], t["isolation"], t["censored"], t["feasible"], computed & ~t["feasible"],
                 t["pareto"], t["chosen"], required_margin, isolation_limit, _axis_label(result, stability),
                 _axis_label(result, isolation), title or f"{result.dataset.attrs.get('study_name', 'study')}: trade-off",
                 "beyond a static limit")


def plot_optimization(res, ax=None):
    """Every design an optimisation evaluated: isolation against margin, the Pareto set, the
    constraints and the chosen (polished) design; returns the Axes."""
    opt = res.optimization
    h = res.history
    x, y = -h.f[:, 1], h.f[:, 0]
    computed = np.isfinite(x) & np.isfinite(y)
    feasible = h.feasible
    pareto = np.zeros(len(x), dtype=bool)
    from ..optimize.run import _pareto_rows

    pareto[_pareto_rows(h.f, feasible)] = True
    ds = res.pareto.dataset
    y_label = _axis_label(res.pareto, opt.objective) if opt.objective in ds else opt.objective
    ax = _draw(ax, x, y, np.zeros(len(x), dtype=bool), feasible, computed & ~feasible, pareto, None,
               opt.margin_min, None, "margin = critical / operating thrust (stable to thrust_max: its bound)",
               y_label, f"{opt.name}: {int((h.generation >= 0).sum())} designs in {opt.generations} generations, "
               f"{int((h.generation < 0).sum())} in the polish", "violates a constraint")
    c = res.chosen
    with figure_style():
        ax.plot([c["margin"]], [c["isolation"]], "*", ms=13, color=PALETTE[3], mec="k", mew=0.5,
                label=f"chosen{' (polished)' if c['polished'] else ''}: {c['isolation']:.4g} at margin {c['margin']:.3g}")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return ax


def _draw(ax, x, y, censored, feasible, violating, pareto, chosen, required_margin, isolation_limit,
          x_label, y_label, title, violating_label):
    with figure_style():
        import matplotlib.pyplot as plt
        from matplotlib.ticker import FuncFormatter

        if ax is None:
            _, ax = plt.subplots(figsize=(8.4, 4.4))
        ok = feasible
        limits = violating
        found = ok & ~censored
        cens = ok & censored
        ax.scatter(x[found], y[found], s=14, color=PALETTE[0], alpha=0.55, lw=0, label=f"design ({found.sum()})")
        if cens.any():
            ax.scatter(x[cens], y[cens], s=16, facecolor="none", edgecolor=PALETTE[0], lw=0.8,
                       label=f"stable to thrust_max ({cens.sum()}): margin larger")
        if limits.any():
            ax.scatter(x[limits], y[limits], s=14, marker="x", color="#9A9A9A", lw=0.8,
                       label=f"{violating_label} ({limits.sum()})")
        front = np.flatnonzero(pareto)
        front = front[np.argsort(x[front])]
        ax.plot(x[front], y[front], "-o", color=PALETTE[1], ms=4.5, lw=1.3, label=f"Pareto front ({front.size})")
        ax.set_yscale("log")
        pos = x[(ok | limits) & (x > 0)]
        if pos.size and pos.max() > 8 * pos.min():  # margins over a decade or more: log axis
            ax.set_xscale("log")
            ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            ax.xaxis.set_minor_formatter(FuncFormatter(_minor_label))
        if required_margin is not None:
            ax.axvline(required_margin, color=ONSET_COLOR, lw=1.2, ls="--", label=f"required margin {required_margin:g}")
            lo, hi = ax.get_xlim()
            lo = min(lo, required_margin)
            ax.axvspan(lo, required_margin, color=ONSET_COLOR, alpha=0.07, lw=0)
            ax.set_xlim(lo, max(hi, required_margin))
        if isolation_limit is not None:
            ax.axhline(isolation_limit, color=PALETTE[2], lw=1.2, ls=":", label=f"isolation limit {isolation_limit:g}")
        if chosen is not None:
            c = chosen
            ax.plot([x[c]], [y[c]], "*", ms=13, color=PALETTE[3], mec="k", mew=0.5,
                    label=f"chosen: {y[c]:.3g} at margin {x[c]:.3g}")
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(FuncFormatter(_minor_label))
        ax.set_xlabel(x_label)
        ax.set_ylabel(y_label)
        ax.set_title(title)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return ax
