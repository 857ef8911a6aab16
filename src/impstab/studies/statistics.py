"""Uncertainty statistics of a sampled study: how the critical thrust and the margin are spread,
and how likely a design is to miss a required margin.

For a ``random``, ``sobol`` or ``saltelli`` study (:func:`study_statistics`), over the designs
that were computed:

* the distribution of the critical thrust (N) and of the margin (critical / operating thrust):
  histogram, empirical distribution function (ECDF) with a confidence band, percentiles with
  confidence intervals;
* the probability that the margin is below a required value, with its confidence interval;
* Sobol sensitivity indices (:mod:`impstab.studies.sensitivity`).

**Censoring.** A design that stays stable over its whole search, ``0 .. analysis.thrust_max``,
has no critical thrust: it is only known to exceed ``thrust_max`` (its margin to exceed
``thrust_max / operating``). Such a design is a right-censored observation. It is counted
(``censored``, ``censored_fraction``) and stays in the sample: with ``n`` computed designs, the
ECDF ``F_n(t) = #{T_i <= t} / n`` is exact (every design is known to be below ``t`` or not) for
``t`` up to the smallest search limit ``c`` of a censored design, and unknown above it; nothing is
reported or drawn there. A percentile ``q`` is the inverse of the ECDF (the smallest value with
``F_n >= q``, numpy's ``"inverted_cdf"``): it is a number when ``q <= F_n(c)``, and otherwise
only known to exceed ``c``, which is how it is reported (``above``, ``"> 30000 N"``), never as a
number. The probability of a margin below a target needs the target at or below ``c /
operating``: a censored design is then known not to miss it.

**Failed designs** (status invalid, numerical_failure, error) have no value at all; they are
counted by status and left out of ``n``: the statistics describe the designs that could be
computed. Designs not computed yet (an interrupted study) are counted too and left out.

**Intervals.** With ``random`` sampling the designs are independent draws, and the intervals are
exact ones: the probability's interval is Clopper-Pearson's (the exact binomial interval, the
beta quantiles of ``scipy.stats.binomtest(...).proportion_ci(method="exact")``); the ECDF has
two bands, the Dvoretzky-Kiefer-Wolfowitz band (simultaneous: the whole true distribution
function lies inside with at least the confidence level; half-width ``sqrt(ln(2 / alpha) /
(2 n))``, Massart's constant) and the pointwise Clopper-Pearson interval of ``F(t)`` at each
``t`` (:meth:`CensoredDistribution.pointwise_band`: much narrower in the tails, where a
probability of missing a margin is read, but valid for one ``t`` at a time); a percentile's
interval lies between two order statistics (``scipy.stats.quantile_test``, distribution-free).

Scrambled Sobol points (``sobol``; for ``saltelli`` the ``2 n`` rows of its matrices A and B,
the only rows that are a sample of the input distribution on their own) are not independent.
Each point is uniformly distributed, so the estimates are unbiased, but one scrambled sequence
carries no estimate of its own error. The same intervals are given for them as an
approximation (``intervals = "approximate"``). For ``examples/study_uncertainty.toml`` they are
conservative: over 40 independent scramblings the standard deviation of the probability of a
margin below 1.4, 1.5 and 1.7 was 0.23 to 0.34 times the binomial one (``docs/studies.md``);
that is measured for one study, not guaranteed for every study.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError

__all__ = [
    "CensoredDistribution",
    "Percentile",
    "MarginProbability",
    "UncertaintyStatistics",
    "study_statistics",
    "clopper_pearson",
    "PERCENTS",
    "SAMPLED",
]

#: percentiles reported by default (percent of the computed designs)
PERCENTS = (1.0, 5.0, 10.0, 50.0, 90.0, 95.0, 99.0)
#: sampling methods whose designs are a sample of the input distribution
SAMPLED = ("random", "sobol", "saltelli")
_UNITS = {"critical_thrust": "N", "margin": "1"}
_NAMES = {"critical_thrust": "critical thrust", "margin": "margin"}


def _plain(v: float, units: str = "") -> str:
    """5 significant digits for a force (N), 4 for a margin or a ratio (never ``-0``), no unit."""
    from ..display.format import number

    return number(v, 5 if units == "N" else 4)


def _number(v: float, units: str = "") -> str:
    """:func:`_plain` with its unit (none for a ratio)."""
    text = _plain(v, units)
    return f"{text} {units}" if units not in ("", "1") else text


@dataclass(frozen=True)
class Percentile:
    """One percentile of a right-censored sample.

    Attributes
    ----------
    percent : float
        ``q`` in percent of the computed designs.
    value : float or None
        The percentile (units of the quantity); None when it is censored.
    above : float or None
        When censored: the percentile is only known to exceed this search limit.
    low, high : float or None
        Confidence interval between two order statistics; ``high`` None when it lies above the
        search limit (then ``high_above`` is that limit) or beyond the sample (too few designs).
    low_above, high_above : float or None
        The search limit an end of the interval is only known to exceed.
    units : str
    """

    percent: float
    value: float | None
    above: float | None
    low: float | None
    high: float | None
    low_above: float | None
    high_above: float | None
    units: str = ""

    @property
    def censored(self) -> bool:
        """Whether the percentile lies above the search limit (not known as a number)."""
        return self.value is None

    def text(self, units: bool = True) -> str:
        """``"12345 N"`` or ``"> 30000 N"`` (without the unit if ``units`` is False)."""
        num = _number if units else _plain
        return num(self.value, self.units) if self.value is not None else f"> {num(self.above, self.units)}"

    def interval_text(self) -> str:
        """``"[lo, hi]"`` (without the unit); an end above the search limit shows as ``> limit``,
        one beyond the sample as ``?``."""
        def end(v, above):
            if v is not None:
                return _plain(v, self.units)
            return "?" if above is None else f"> {_plain(above, self.units)}"

        return f"[{end(self.low, self.low_above)}, {end(self.high, self.high_above)}]"

    def __repr__(self) -> str:
        return f"Percentile({self.percent:g} %: {self.text()}, interval {self.interval_text()})"

    def to_dict(self) -> dict[str, Any]:
        return {"percent": self.percent, "value": self.value, "above": self.above, "low": self.low,
                "high": self.high, "low_above": self.low_above, "high_above": self.high_above}


@dataclass(frozen=True, eq=False)
class CensoredDistribution:
    """The distribution of one quantity over the computed designs, right-censored at the search
    limit.

    Attributes
    ----------
    quantity : str
        ``"critical_thrust"`` (N) or ``"margin"`` (1).
    observed : (m,) array
        Sorted values of the designs that lose stability within their search.
    censoring : (k,) array
        Sorted search limits of the designs stable up to them (their values exceed these).
    confidence : float
        Level of the band and of the percentile intervals.
    exact : bool
        Whether the intervals are exact (independent samples) or approximate (Sobol points).
    """

    quantity: str
    observed: NDArray[np.float64]
    censoring: NDArray[np.float64]
    confidence: float = 0.95
    exact: bool = True

    @property
    def units(self) -> str:
        return _UNITS.get(self.quantity, "")

    @property
    def n(self) -> int:
        """Number of computed designs (observed and censored)."""
        return int(self.observed.size + self.censoring.size)

    @property
    def censored(self) -> int:
        return int(self.censoring.size)

    @property
    def censored_fraction(self) -> float:
        return self.censored / self.n if self.n else math.nan

    @property
    def exact_up_to(self) -> float:
        """The ECDF is known exactly up to this value: the smallest search limit of a censored
        design (``inf`` when none is censored)."""
        return float(self.censoring[0]) if self.censoring.size else math.inf

    @property
    def band_halfwidth(self) -> float:
        """Half-width of the Dvoretzky-Kiefer-Wolfowitz band, ``sqrt(ln(2 / alpha) / (2 n))``."""
        return math.sqrt(math.log(2.0 / (1.0 - self.confidence)) / (2.0 * self.n)) if self.n else math.nan

    def ecdf(self, t) -> NDArray[np.float64]:
        """``F_n(t)``, the fraction of the computed designs with a value ``<= t``; NaN above
        :attr:`exact_up_to`, where it is not known."""
        t = np.asarray(t, dtype=float)
        f = np.searchsorted(self.observed, t, side="right") / self.n
        return np.where(t <= self.exact_up_to, f, np.nan)

    def band(self, t) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Lower and upper edge of the DKW band at ``t`` (simultaneous; NaN where the ECDF is
        not known)."""
        f = self.ecdf(t)
        eps = self.band_halfwidth
        return np.clip(f - eps, 0.0, 1.0), np.clip(f + eps, 0.0, 1.0)

    def pointwise_band(self, t) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Clopper-Pearson interval of ``F(t)`` at each ``t`` on its own (pointwise, not
        simultaneous; NaN where the ECDF is not known)."""
        f = self.ecdf(t)
        k = np.round(np.nan_to_num(f) * self.n)
        lo, hi = clopper_pearson(k, self.n, self.confidence)
        known = np.isfinite(f)
        return np.where(known, lo, np.nan), np.where(known, hi, np.nan)

    def _sample(self) -> NDArray[np.float64]:
        """All computed designs, the censored ones as ``+inf`` (only their rank above every
        value below their limit matters to the ECDF and its order statistics)."""
        return np.concatenate([self.observed, np.full(self.censoring.size, np.inf)])

    def _known(self, v: float) -> bool:
        return math.isfinite(v) and v <= self.exact_up_to

    def percentile(self, percent: float) -> Percentile:
        """The ``percent`` percentile (0 < percent < 100), censoring flagged, with its interval."""
        from scipy import stats

        if not 0.0 < percent < 100.0:
            raise ModelError("percentile", percent, "must be between 0 and 100 (exclusive)")
        if self.n == 0:
            raise ModelError("percentile", percent, "no computed design to take it from")
        x = self._sample()
        q = percent / 100.0
        value = float(np.quantile(x, q, method="inverted_cdf"))
        ci = stats.quantile_test(x, q=0.0, p=q).confidence_interval(self.confidence)
        ends = []
        for v in (float(ci.low), float(ci.high)):
            if self._known(v):
                ends += [v, None]
            elif math.isnan(v):
                ends += [None, None]  # the sample is too small for this end
            else:
                ends += [None, self.exact_up_to]
        known = self._known(value)
        return Percentile(percent, value if known else None, None if known else self.exact_up_to,
                          ends[0], ends[2], ends[1], ends[3], self.units)

    def histogram(self, bins: int | str = "auto") -> tuple[NDArray[np.float64], NDArray[np.int64]]:
        """Bin edges and counts of the observed values (the censored designs are
        :attr:`censored`, beyond the last edge)."""
        if self.observed.size == 0:
            return np.array([]), np.array([], dtype=np.int64)
        edges = np.histogram_bin_edges(self.observed, bins=bins)
        counts, edges = np.histogram(self.observed, bins=edges)
        return edges, counts

    def probability_below(self, target: float) -> tuple[int, int]:
        """``(count, n)``: designs with a value strictly below ``target``, out of ``n``."""
        if target > self.exact_up_to:
            raise ModelError(
                "target", target,
                f"is above the search limit {_number(self.exact_up_to, self.units)} of a design stable up to "
                f"it: whether that design is below the target is not known (raise analysis.thrust_max)",
            )
        return int(np.searchsorted(self.observed, target, side="left")), self.n

    def plot(self, ax=None, **kw):
        """The ECDF with its confidence band; returns the Axes (:func:`impstab.plot.statistics.plot_ecdf`)."""
        from ..plot.statistics import plot_ecdf

        return plot_ecdf(self, ax=ax, **kw)

    def __repr__(self) -> str:
        cens = f", {self.censored} censored above {_number(self.exact_up_to, self.units)}" if self.censored else ""
        return f"CensoredDistribution({self.quantity}, n={self.n}{cens})"


@dataclass(frozen=True)
class MarginProbability:
    """The probability that a design misses a required margin.

    Attributes
    ----------
    target : float
        Required margin (critical / operating thrust).
    below : int
        Designs with a margin strictly below it (a design stable up to its search limit, at or
        above the target, counts as meeting it).
    n : int
        Computed designs.
    estimate, low, high : float
        ``below / n`` and its confidence interval (Clopper-Pearson).
    confidence : float
    exact : bool
        Whether the interval's coverage is exact (independent samples) or approximate (Sobol).
    """

    target: float
    below: int
    n: int
    estimate: float
    low: float
    high: float
    confidence: float
    exact: bool

    @property
    def method(self) -> str:
        text = "Clopper-Pearson exact binomial interval"
        return text if self.exact else text + ", approximate for scrambled Sobol points"

    def to_dict(self) -> dict[str, Any]:
        return {"target_margin": self.target, "below": self.below, "n": self.n, "estimate": self.estimate,
                "low": self.low, "high": self.high, "confidence": self.confidence, "exact": self.exact,
                "method": self.method}

    def __repr__(self) -> str:
        return (f"MarginProbability(P(margin < {self.target:g}) = {100 * self.estimate:.3g} %, "
                f"{100 * self.confidence:g} % interval [{100 * self.low:.3g}, {100 * self.high:.3g}] %, "
                f"{self.below} of {self.n})")


@dataclass(frozen=True, eq=False)
class UncertaintyStatistics:
    """The statistics of a sampled study (:func:`study_statistics`).

    Attributes
    ----------
    study_name, sampling : str
    parameters : tuple of str
        Parameter paths.
    designs : int
        Designs of the study (for ``saltelli`` the whole cross-sampled design).
    rows : int
        Designs that are a sample of the input distribution: all of them, or the ``2 n`` rows of
        A and B of a Saltelli design.
    computed : int
        Of these, the designs computed without failure (the ``n`` of the statistics).
    failed : dict
        Designs per failure status (``invalid``, ``numerical_failure``, ``error``), among ``rows``.
    not_computed : int
        Designs among ``rows`` not computed yet.
    critical_thrust, margin : CensoredDistribution or None
        Distributions (N, 1); ``margin`` None when the operating thrust is unknown.
    probability : MarginProbability or None
        Of a margin below ``target_margin``.
    percents : tuple of float
        Percentiles reported.
    sensitivity : SensitivityIndices or None
    confidence : float
    thrust_max, operating_thrust : float or None
        When the same for every design (N).
    notes : tuple of str
        What the numbers mean where it is not obvious (censoring, intervals, indices).
    """

    study_name: str
    sampling: str
    parameters: tuple[str, ...]
    designs: int
    rows: int
    computed: int
    failed: dict
    not_computed: int
    critical_thrust: CensoredDistribution | None
    margin: CensoredDistribution | None
    probability: MarginProbability | None
    percents: tuple[float, ...] = PERCENTS
    sensitivity: Any = None
    confidence: float = 0.95
    thrust_max: float | None = None
    operating_thrust: float | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)

    # -- views --------------------------------------------------------------------------------
    @property
    def main(self) -> CensoredDistribution:
        """The margin's distribution when known, else the critical thrust's."""
        return self.margin if self.margin is not None else self.critical_thrust

    @property
    def censored(self) -> int:
        """Designs stable up to their search limit (right-censored)."""
        return self.main.censored

    @property
    def censored_fraction(self) -> float:
        return self.main.censored_fraction

    @property
    def exact(self) -> bool:
        """Whether the intervals are exact (random sampling) or approximate (Sobol points)."""
        return self.sampling == "random"

    @property
    def intervals(self) -> str:
        return "exact" if self.exact else "approximate"

    def percentiles(self, quantity: str | None = None) -> list[Percentile]:
        """The reported percentiles of ``quantity`` (default :attr:`main`)."""
        dist = self.main if quantity is None else getattr(self, quantity)
        return [dist.percentile(p) for p in self.percents] if dist is not None else []

    # -- exports ------------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """A JSON-able dict (the object ``impstab stats --json`` prints; units in ``docs/studies.md``)."""
        def dist(d: CensoredDistribution | None):
            if d is None:
                return None
            return {
                "units": d.units, "n": d.n, "censored": d.censored, "censored_fraction": d.censored_fraction,
                "exact_up_to": d.exact_up_to if d.censored else None,
                "ecdf_band": "dkw", "ecdf_band_halfwidth": d.band_halfwidth, "ecdf_pointwise": "clopper-pearson",
                "percentiles": [p.to_dict() for p in (d.percentile(q) for q in self.percents)],
            }

        return {
            "study": self.study_name,
            "sampling": self.sampling,
            "parameters": list(self.parameters),
            "designs": self.designs,
            "rows": self.rows,
            "computed": self.computed,
            "failed": dict(self.failed),
            "not_computed": self.not_computed,
            "censored": self.censored,
            "censored_fraction": self.censored_fraction,
            "thrust_max": self.thrust_max,
            "operating_thrust": self.operating_thrust,
            "confidence": self.confidence,
            "intervals": self.intervals,
            "critical_thrust": dist(self.critical_thrust),
            "margin": dist(self.margin),
            "probability": None if self.probability is None else self.probability.to_dict(),
            "sensitivity": None if self.sensitivity is None else self.sensitivity.to_dict(),
            "notes": list(self.notes),
        }

    def to_xarray(self):
        """The statistics as an xarray Dataset: the ECDF of each quantity over its sorted observed
        values (with the DKW band), the percentiles (NaN where censored, with ``*_above``), the
        probability and the sensitivity indices; counts and notes in ``attrs``."""
        import xarray as xr

        data: dict[str, Any] = {}
        coords: dict[str, Any] = {"percent": ("percent", np.asarray(self.percents), {"units": "%"})}
        for name in ("critical_thrust", "margin"):
            d = getattr(self, name)
            if d is None:
                continue
            units = {"units": d.units}
            dim = f"{name}_value"
            coords[dim] = (dim, d.observed, {**units, "long_name": f"observed {_NAMES[name]} (sorted)"})
            lo, hi = d.band(d.observed)
            data[f"{name}_ecdf"] = (dim, d.ecdf(d.observed), {"units": "1", "long_name": f"empirical distribution function of the {_NAMES[name]}"})
            data[f"{name}_ecdf_low"] = (dim, lo, {"units": "1", "long_name": f"{self.confidence:g} DKW band, lower edge"})
            data[f"{name}_ecdf_high"] = (dim, hi, {"units": "1", "long_name": f"{self.confidence:g} DKW band, upper edge"})
            ps = [d.percentile(q) for q in self.percents]
            for key in ("value", "above", "low", "high"):
                vals = [getattr(p, key) for p in ps]
                data[f"{name}_percentile" + ("" if key == "value" else f"_{key}")] = (
                    "percent", np.array([np.nan if v is None else v for v in vals], dtype=float),
                    {**units, "long_name": f"{_NAMES[name]} percentile" + ("" if key == "value" else f" ({key})")})
            data[f"{name}_censored"] = ((), d.censored, {"long_name": "designs stable up to their search limit"})
        if self.probability is not None:
            p = self.probability
            for key in ("estimate", "low", "high"):
                data[f"probability_{key}"] = ((), getattr(p, key), {"units": "1", "long_name": f"P(margin < {p.target:g}), {key}"})
        ds = xr.Dataset(data, coords=coords)
        if self.sensitivity is not None:
            ds = ds.merge(self.sensitivity.to_xarray(), combine_attrs="drop_conflicts")
        ds.attrs.update({
            "study_name": self.study_name, "sampling": self.sampling, "designs": self.designs, "rows": self.rows,
            "computed": self.computed, "not_computed": self.not_computed, "confidence": self.confidence,
            "intervals": self.intervals, "notes": "\n".join(self.notes),
            **{f"failed_{k}": v for k, v in self.failed.items()},
            **({"target_margin": self.probability.target} if self.probability is not None else {}),
        })
        return ds

    def plot(self, ax=None):
        """Histogram, ECDF with its band, and the sensitivity indices; returns the axes
        (:func:`impstab.plot.statistics.plot_statistics`)."""
        from ..plot.statistics import plot_statistics

        return plot_statistics(self, ax=ax)

    # -- display ------------------------------------------------------------------------------
    def summary_rows(self) -> list[tuple[str, str]]:
        """``(quantity, value)`` rows of the headline numbers (for the repr and the CLI)."""
        rows = [("designs", self._design_text())]
        d = self.main
        if d.censored:
            text = f"{d.censored} of {d.n} ({100 * d.censored_fraction:.3g} %) stable up to "
            c = self.critical_thrust
            if c is not None and c.censored:
                text += f"thrust_max = {_number(c.exact_up_to, 'N')}"
                text += f" (margin {_number(d.exact_up_to)})" if d is not c else ""
            else:
                text += f"thrust_max / operating = {_number(d.exact_up_to)}"
            rows.append(("censored", text))
        else:
            rows.append(("censored", "none (every design loses stability within its search)"))
        p = self.probability
        if p is not None:
            rows.append((f"P(margin < {p.target:g})",
                         f"{100 * p.estimate:.3g} % ({p.below} of {p.n}), {100 * p.confidence:g} % interval "
                         f"[{100 * p.low:.3g}, {100 * p.high:.3g}] %"))
        for q in (5.0, 50.0):
            if q in self.percents:
                parts = [f"{_NAMES[x.quantity]} {x.percentile(q).text()}"
                         for x in (self.critical_thrust, self.margin) if x is not None]
                rows.append((f"{q:g} % percentile", ", ".join(parts)))
        return rows

    def _design_text(self) -> str:
        text = f"{self.computed} computed"
        fails = sum(self.failed.values())
        text += f", {fails} failed" if fails else ""
        text += f", {self.not_computed} not computed" if self.not_computed else ""
        if self.rows != self.designs:
            text += f" (rows A and B of {self.designs})"
        return text

    def __repr__(self) -> str:
        lines = [f"UncertaintyStatistics({self.study_name!r}, {self.sampling}, intervals {self.intervals})"]
        lines += [f"  {k}: {v}" for k, v in self.summary_rows()]
        if self.sensitivity is not None:
            lines.append(f"  {self.sensitivity.summary()}")
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        from ..display.html import html_table

        html = html_table(f"statistics of {self.study_name} ({self.sampling}, {self.computed} designs)",
                          self.summary_rows())
        if self.sensitivity is not None:
            html += self.sensitivity._repr_html_()
        return f"<div>{html}</div>"


def _status_counts(status: NDArray) -> tuple[dict[str, int], int]:
    from ..linear.batch import STATUSES

    failed = {name: int(np.count_nonzero(status == k)) for k, name in enumerate(STATUSES) if name != "ok"}
    return failed, int(np.count_nonzero(status < 0))


def censored_values(result, quantity: str):
    """Per-design values of ``quantity`` with the designs stable up to their search limit.

    Returns
    -------
    value : array
        The stored (or derived) value; NaN for a censored or failed design.
    limit : array or None
        Search limit of each design (``thrust_max``, or ``thrust_max / operating``).
    censored : bool array
        Computed designs stable up to their limit.
    ok : bool array
        Designs computed without failure.
    """
    ds = result.dataset
    status = ds["status"].values.ravel()
    ok = status == 0
    if quantity in ds:
        value = np.asarray(ds[quantity].values, dtype=float).ravel()
    else:
        op = result.operating_thrust()
        other = "margin" if quantity == "critical_thrust" else "critical_thrust"
        if other not in ds or op is None:
            return None, None, None, ok
        with np.errstate(invalid="ignore", divide="ignore"):
            raw = np.asarray(ds[other].values, dtype=float).ravel()
            value = raw * op.ravel() if quantity == "critical_thrust" else raw / op.ravel()
    if "kind" in ds:
        censored = ok & (ds["kind"].values.ravel() == 0)
    else:
        censored = ok & ~np.isfinite(value)
    limit = result.search_limit(quantity)
    limit = None if limit is None else np.asarray(limit, dtype=float).ravel()
    return value, limit, censored, ok


def _distribution(result, quantity: str, rows: NDArray, confidence: float, exact: bool):
    value, limit, censored, ok = censored_values(result, quantity)
    if value is None:
        return None
    value, censored, ok = value[rows], censored[rows], ok[rows]
    observed = ok & ~censored
    bad = observed & ~np.isfinite(value)
    if bad.any():
        raise ModelError(quantity, f"{int(bad.sum())} designs", "computed designs that are not stable to their limit have no value")
    if censored.any() and (limit is None or not np.isfinite(limit[rows][censored]).all()):
        raise ModelError(quantity, "thrust_max", "the search limit of the designs stable up to it is not known")
    cens = np.sort(limit[rows][censored]) if censored.any() else np.array([])
    return CensoredDistribution(quantity, np.sort(value[observed]), cens, confidence, exact)


def _constant(arr) -> float | None:
    if arr is None:
        return None
    a = np.asarray(arr, dtype=float).ravel()
    a = a[np.isfinite(a)]
    return float(a[0]) if a.size and np.all(a == a[0]) else None


def study_statistics(result, target_margin: float | None = 1.0, *, confidence: float = 0.95,
                     percents: tuple[float, ...] = PERCENTS, sensitivity: bool = True) -> UncertaintyStatistics:
    """The uncertainty statistics of a random, Sobol or Saltelli study.

    Parameters
    ----------
    result : StudyResult
        A study with ``sampling`` ``"random"``, ``"sobol"`` or ``"saltelli"``.
    target_margin : float or None
        Required margin (critical / operating thrust): the probability of a margin below it is
        reported. Default 1: the probability of an instability at the operating thrust. None:
        no probability.
    confidence : float
        Level of every interval and band (0.5 to 0.9999).
    percents : tuple of float
        Percentiles to report (percent).
    sensitivity : bool
        Also compute Sobol sensitivity indices (:func:`impstab.studies.sensitivity.sensitivity_indices`).

    Raises
    ------
    ModelError
        A grid study, no computed design, a target above the search limit of a censored design.
    """
    from .sampling import saltelli_rows

    ds = result.dataset
    sampling = str(ds.attrs.get("sampling", ""))
    if sampling not in SAMPLED:
        raise ModelError("STORE", sampling or "(unknown)",
                         "statistics need a random, sobol or saltelli study (a grid is not a sample of a distribution)")
    if not 0.5 <= confidence <= 0.9999:
        raise ModelError("--confidence", confidence, "must be between 0.5 and 0.9999")
    if target_margin is not None and not (math.isfinite(target_margin) and target_margin > 0):
        raise ModelError("--target-margin", target_margin, "must be a finite number > 0")
    status = ds["status"].values.ravel()
    size = status.size
    if sampling == "saltelli":
        r = saltelli_rows(size, len(result.parameters))
        rows = np.sort(np.concatenate([r["A"], r["B"]]))
    else:
        rows = np.arange(size)
    failed, not_computed = _status_counts(status[rows])
    computed = int(np.count_nonzero(status[rows] == 0))
    if computed == 0:
        raise ModelError("STORE", result.store or result.dataset.attrs.get("study_name", ""),
                         "has no computed design yet (run or resume the study with impstab sweep)")
    exact = sampling == "random"
    crit = _distribution(result, "critical_thrust", rows, confidence, exact)
    marg = _distribution(result, "margin", rows, confidence, exact)
    prob = None
    if target_margin is not None and marg is not None:
        try:
            below, n = marg.probability_below(target_margin)
        except ModelError as err:
            raise ModelError("--target-margin", target_margin, err.rule) from None
        prob = _clopper_pearson(target_margin, below, n, confidence, exact)
    notes = [_censoring_note(marg or crit)]
    if sum(failed.values()) or not_computed:
        notes.append(f"{sum(failed.values())} failed and {not_computed} not computed designs are left out: "
                     "the statistics are those of the computed designs")
    notes.append(_interval_note(sampling))
    indices = None
    if sensitivity:
        from .sensitivity import sensitivity_indices

        indices = sensitivity_indices(result, confidence=confidence)
        notes.append(indices.note)
    return UncertaintyStatistics(
        study_name=str(ds.attrs.get("study_name", "")),
        sampling=sampling,
        parameters=tuple(result.parameters),
        designs=size,
        rows=int(rows.size),
        computed=computed,
        failed=failed,
        not_computed=not_computed,
        critical_thrust=crit,
        margin=marg,
        probability=prob,
        percents=tuple(float(p) for p in percents),
        sensitivity=indices,
        confidence=confidence,
        thrust_max=_constant(result.thrust_max()),
        operating_thrust=_constant(result.operating_thrust()),
        notes=tuple(notes),
    )


def clopper_pearson(k, n: int, confidence: float = 0.95) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Clopper-Pearson (exact binomial) interval of a proportion ``k / n``, elementwise in ``k``.

    The ends are the beta quantiles ``B(alpha/2; k, n - k + 1)`` and ``B(1 - alpha/2; k + 1,
    n - k)``, 0 for ``k = 0`` and 1 for ``k = n``: the interval of
    ``scipy.stats.binomtest(k, n).proportion_ci(method="exact")``, vectorized.
    """
    from scipy import stats

    k = np.asarray(k, dtype=float)
    alpha = 1.0 - confidence
    with np.errstate(invalid="ignore"):
        lo = np.where(k > 0, stats.beta.ppf(alpha / 2, np.maximum(k, 1e-300), n - k + 1), 0.0)
        hi = np.where(k < n, stats.beta.ppf(1 - alpha / 2, k + 1, np.maximum(n - k, 1e-300)), 1.0)
    return lo, hi


def _clopper_pearson(target: float, below: int, n: int, confidence: float, exact: bool) -> MarginProbability:
    lo, hi = clopper_pearson(below, n, confidence)
    return MarginProbability(target, below, n, below / n, float(lo), float(hi), confidence, exact)


def _censoring_note(d: CensoredDistribution) -> str:
    if not d.censored:
        return "no design is censored: every design loses stability within its search"
    return (f"{d.censored} of {d.n} designs ({100 * d.censored_fraction:.3g} %) are stable up to their search limit "
            f"(right-censored at {_number(d.exact_up_to, d.units)}): the ECDF is exact up to it, percentiles above it "
            f"are reported as '> {_number(d.exact_up_to, d.units)}'")


def _interval_note(sampling: str) -> str:
    if sampling == "random":
        return ("intervals are exact: Clopper-Pearson for the probability, the DKW band (simultaneous) for the ECDF, "
                "order statistics for the percentiles")
    rows = "the A and B rows of the Saltelli design" if sampling == "saltelli" else "scrambled Sobol points"
    return (f"intervals are approximate: the intervals of independent sampling applied to {rows} "
            "(unbiased estimates; the Sobol error is not estimated by one sequence)")
