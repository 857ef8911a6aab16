"""Figures of the uncertainty statistics of a study: histogram, ECDF with its band, Sobol indices."""

from __future__ import annotations

import numpy as np

from .handles import StatisticsAxes
from .style import ONSET_COLOR, PALETTE, figure_style

__all__ = ["StatisticsAxes", "plot_statistics", "plot_histogram", "plot_ecdf", "plot_sensitivity"]

_LABELS = {"critical_thrust": "critical thrust (N)", "margin": "margin (critical / operating thrust)"}
_BAR = PALETTE[0]
_TOTAL = PALETTE[1]
_CENSORED = "0.55"
_TARGET = ONSET_COLOR


def _fmt(v: float) -> str:
    return f"{v:.4g}"


def _parameter_label(path: str) -> str:
    """The parameter's name from the model-file reference, over its path."""
    from ..model.reference import label

    name = label(path)
    return f"{name}\n{path}" if name and name != path else path


def _limit_name(dist) -> str:
    return "thrust_max" if dist.quantity == "critical_thrust" else "thrust_max / operating"


def _plot_statistics(stats, ax=None):
    """:func:`plot_statistics` inside the figure style."""
    import matplotlib.pyplot as plt

    dist = stats.main
    target = stats.probability
    if ax is not None and not isinstance(ax, (list, tuple, np.ndarray)):  # one Axes: the first panel
        return _plot_histogram(dist, ax=ax, target=None if target is None else target.target,
                               operating=stats.operating_thrust)
    if ax is None:
        n = 3 if stats.sensitivity is not None else 2
        fig, axes = plt.subplots(1, n, figsize=(4.6 * n, 4.4), layout="constrained",
                                 gridspec_kw={"width_ratios": [1.0, 1.0, 0.9][:n]})
        how = (f"rows A and B of a Saltelli design of {stats.designs}" if stats.rows != stats.designs
               else f"{stats.sampling} sampling")
        fig.suptitle(f"{stats.study_name}: {stats.computed} computed designs ({how})", fontsize="medium")
    else:
        axes = list(ax)
    h = _plot_histogram(dist, ax=axes[0], target=None if target is None else target.target,
                       operating=stats.operating_thrust)
    e = _plot_ecdf(dist, ax=axes[1], probability=target, operating=stats.operating_thrust)
    s = None
    if stats.sensitivity is not None and len(axes) > 2:
        s = _plot_sensitivity(stats.sensitivity, ax=axes[2])
    return StatisticsAxes(h, e, s)


def _thrust_axis(ax, dist, operating):
    """A second x axis in newtons above a margin axis (when the operating thrust is one value)."""
    if dist.quantity != "margin" or not operating:
        return
    sec = ax.secondary_xaxis("top", functions=(lambda m: m * operating, lambda t: t / operating))
    from matplotlib.ticker import MaxNLocator

    sec.xaxis.set_major_locator(MaxNLocator(5))
    sec.set_xlabel(f"critical thrust (N), operating thrust {operating:.5g} N", fontsize="small")
    sec.tick_params(labelsize="small")


def _plot_histogram(dist, ax=None, *, target: float | None = None, operating: float | None = None):
    """:func:`plot_histogram` inside the figure style."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5.5, 4.2), layout="constrained")
    edges, counts = dist.histogram()
    if counts.size:
        ax.stairs(counts, edges, fill=True, color=_BAR, alpha=0.85,
                  label=f"lose stability within the search: {dist.observed.size}")
        width = float(np.median(np.diff(edges)))
    else:
        width = 0.05 * dist.exact_up_to
    if dist.censored:
        c = dist.exact_up_to
        ax.bar(c + 0.6 * width, dist.censored, width=width, color="white", edgecolor=_CENSORED, hatch="///",
               label=f"stable up to {_limit_name(dist)} (> {_fmt(c)}): {dist.censored}")
        ax.axvline(c, color=_CENSORED, lw=1.0, ls=":")
    if target is not None:
        ax.axvline(target, color=_TARGET, lw=1.5, ls="--", label=f"required margin {target:g}")
    ax.set_xlabel(_LABELS.get(dist.quantity, dist.quantity))
    ax.set_ylabel("designs per bin")
    ax.set_title(f"distribution of the {dist.quantity.replace('_', ' ')} (n = {dist.n})", fontsize="medium")
    ax.legend(loc="upper left", fontsize="small", framealpha=0.9)
    ax.set_ylim(0, ax.get_ylim()[1] * 1.25)  # room for the legend above the bars
    _thrust_axis(ax, dist, operating)
    return ax


def _percent_ticks(ax, n: int) -> None:
    """Ticks of a logit probability axis in percent, within the range a sample of ``n`` shows."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

    ticks = [p for p in (0.001, 0.01, 0.05, 0.2, 0.5, 0.8, 0.95, 0.99, 0.999) if 0.5 / n < p < 1 - 0.5 / n]
    ax.yaxis.set_major_locator(FixedLocator(ticks))
    ax.yaxis.set_minor_locator(NullLocator())
    ax.yaxis.set_major_formatter(FuncFormatter(lambda p, _: f"{100 * p:.3g} %"))


def _plot_ecdf(dist, ax=None, *, probability=None, operating: float | None = None):
    """:func:`plot_ecdf` inside the figure style."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5.5, 4.2), layout="constrained")
    n = dist.n
    obs = dist.observed
    floor, ceil = 0.3 / n, 1 - 0.3 / n
    approx = "" if dist.exact else ", approximate"
    conf = f"{100 * dist.confidence:g} %"
    if obs.size:
        right = dist.exact_up_to if dist.censored else obs[-1]
        x = np.concatenate([obs, [right]])

        def ext(a):
            return np.clip(np.concatenate([a, [a[-1]]]), floor, ceil)

        lo, hi = dist.band(obs)
        ax.fill_between(x, ext(lo), ext(hi), step="post", color=_BAR, alpha=0.12, lw=0,
                        label=f"{conf} DKW band (simultaneous{approx})")
        lo, hi = dist.pointwise_band(obs)
        ax.fill_between(x, ext(lo), ext(hi), step="post", color=_BAR, alpha=0.3, lw=0,
                        label=f"{conf} Clopper-Pearson (pointwise{approx})")
        ax.step(x, ext(dist.ecdf(obs)), where="post", color=_BAR, lw=1.4, label=f"ECDF of {n} designs")
    if dist.censored:
        c = dist.exact_up_to
        ax.axvline(c, color=_CENSORED, lw=1.0, ls=":")
        ax.annotate(f"not known above {_fmt(c)}:\n{dist.censored} designs stable\nup to {_limit_name(dist)}",
                    xy=(c, 0.03), xytext=(-6, 0), textcoords="offset points", ha="right", va="center",
                    fontsize="small", color="0.35")
    if probability is not None:
        p = probability
        shown = max(p.estimate, floor)
        ax.axvline(p.target, color=_TARGET, lw=1.2, ls="--")
        ax.errorbar([p.target], [shown], yerr=[[shown - max(p.low, floor)], [max(p.high, floor) - shown]], fmt="o",
                    color=_TARGET, ms=5, capsize=4,
                    label=(f"P({'margin' if dist.quantity == 'margin' else 'value'} < {p.target:g}) = "
                           f"{100 * p.estimate:.3g} %, interval [{100 * p.low:.2g}, {100 * p.high:.2g}] %"))
    ax.set_yscale("logit")
    ax.set_ylim(floor, ceil)
    _percent_ticks(ax, n)
    ax.set_xlabel(_LABELS.get(dist.quantity, dist.quantity))
    ax.set_ylabel("designs at or below (logit scale)")
    ax.set_title("empirical distribution function", fontsize="medium")
    ax.legend(loc="upper left", fontsize="small", framealpha=0.9)
    _thrust_axis(ax, dist, operating)
    return ax


def _plot_sensitivity(ind, ax=None):
    """:func:`plot_sensitivity` inside the figure style."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5.0, 0.8 + 0.7 * len(ind.parameters)), layout="constrained")
    k = len(ind.parameters)
    y = np.arange(k)[::-1].astype(float)
    both = ind.total_order is not None
    h = 0.38 if both else 0.6
    ax.barh(y + (h / 2 if both else 0), ind.first_order, height=h, xerr=ind.first_order_conf, color=_BAR,
            error_kw={"capsize": 3, "lw": 1},
            label=f"first order $S_1$, {100 * ind.confidence:g} % interval")
    if both:
        ax.barh(y - h / 2, ind.total_order, height=h, xerr=ind.total_order_conf, color=_TOTAL,
                error_kw={"capsize": 3, "lw": 1},
                label=f"total $S_T$, {100 * ind.confidence:g} % interval")
    ax.set_yticks(y, [_parameter_label(p) for p in ind.parameters])
    top = [ind.first_order + ind.first_order_conf]
    if both:
        top.append(ind.total_order + ind.total_order_conf)
    hi = max(1.05, float(np.nanmax(np.concatenate(top))) + 0.05)
    lo = min(0.0, float(np.nanmin(ind.first_order - ind.first_order_conf)) - 0.02)
    ax.set_xlim(lo, hi)
    ax.axvline(0.0, color="0.3", lw=0.8)
    label = f"Sobol index of {ind.of}"
    if ind.capped:
        label += f"\n({ind.censored} censored designs enter at their limit)"
    ax.set_xlabel(label)
    method = "Sobol indices, Saltelli design" if ind.method == "saltelli" else "first-order indices, RBD-FAST"
    ax.set_title(method, fontsize="medium")
    ax.legend(loc="lower right", fontsize="small", framealpha=0.9)
    ax.tick_params(axis="y", labelsize="small")
    return ax


def plot_statistics(stats, ax=None):
    """Draw the distribution of the margin (or critical thrust) and the sensitivity indices.

    Parameters
    ----------
    stats : UncertaintyStatistics
    ax : matplotlib Axes or sequence of Axes, optional
        None: a new figure of three panels (two without indices). One Axes: the first panel
        (the histogram) only.
        A sequence: the panels in order (histogram, ECDF, indices).

    Returns
    -------
    StatisticsAxes or Axes
        The panels (the Axes when one was given).
    """
    with figure_style():
        return _plot_statistics(stats, ax)


def plot_histogram(dist, ax=None, *, target: float | None = None, operating: float | None = None):
    """Histogram of the observed values of a :class:`~impstab.studies.statistics.CensoredDistribution`,
    the censored designs as a separate hatched bar beyond the search limit, the target margin as
    a line; returns the Axes."""
    with figure_style():
        return _plot_histogram(dist, ax, target=target, operating=operating)


def plot_ecdf(dist, ax=None, *, probability=None, operating: float | None = None):
    """The empirical distribution function with its pointwise Clopper-Pearson band and the
    simultaneous DKW band, on a logit axis (both tails readable), drawn only where it is known
    (up to the smallest search limit of a censored design); the probability of a margin below
    the target with its interval. Returns the Axes."""
    with figure_style():
        return _plot_ecdf(dist, ax, probability=probability, operating=operating)


def plot_sensitivity(ind, ax=None):
    """Horizontal bars of the first-order (and total) Sobol indices with their intervals;
    returns the Axes."""
    with figure_style():
        return _plot_sensitivity(ind, ax)
