"""Sobol sensitivity indices of a sampled study: which scattered parameter drives the margin.

Two estimators, both from SALib (nothing hand-rolled), chosen by the study's sampling:

* ``saltelli`` sampling (Saltelli's cross-sampled design, :func:`impstab.studies.sampling.unit_samples`):
  first-order and total indices by ``SALib.analyze.sobol.analyze`` (Saltelli et al. 2010 for the
  first-order, Jansen's estimator for the total index), with bootstrap confidence intervals
  (``S +- conf``, ``conf`` = z times the bootstrap standard deviation over the base samples).
* ``random`` and ``sobol`` sampling (given data, no special design): first-order indices only,
  by RBD-FAST in Plischke's given-data form with the bias correction of Tissot and Prieur
  (``SALib.analyze.rbd_fast.analyze``, 10 harmonics). Why this one: it takes any sample, its
  point estimate is the whole sample's (deterministic), and it costs one FFT per parameter.
  SALib's other given-data estimator, ``delta`` (Borgonovo's moment-independent index with a
  binned first-order index), takes its first-order point estimate from a random resample of the
  data (so two calls differ) and its kernel density estimates took minutes for 1024 samples of
  three parameters on a shared two-core machine, against under a second for RBD-FAST. Its
  bootstrap resamples half the data, so its interval is that of ``n / 2`` samples: wide, not
  narrow. Total indices need the Saltelli design; they are not available from given data.

**Censored designs.** A design stable up to its search limit has no critical thrust. The
indices are computed for ``min(margin, thrust_max / operating)`` (or ``min(critical thrust,
thrust_max)``): the censored designs enter at their limit. When any design is censored the
result says so (``capped``; :attr:`SensitivityIndices.of` reads ``min(margin, 3.53)``): these are
the indices of the capped quantity, which tell how much each parameter moves the margin *below
the search limit*, not the indices of the uncensored margin (a parameter that matters only
above the limit is invisible to them). With a small censored fraction the two are close; with a
large one, raise ``analysis.thrust_max``.

**Failed designs** have no value. A given-data estimate leaves them out; for a Saltelli design
the whole base sample (its ``d + 2`` rows) of a failed design is left out. The number left out
is reported (``dropped``): the indices are then those of the computable designs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError

__all__ = ["SensitivityIndices", "sensitivity_indices"]

#: bootstrap resamples of the confidence intervals
RESAMPLES = 200
#: harmonics of the RBD-FAST estimator (SALib's default)
HARMONICS = 10


@dataclass(frozen=True, eq=False)
class SensitivityIndices:
    """Sobol sensitivity indices of one quantity of a study.

    Attributes
    ----------
    method : str
        ``"saltelli"`` (SALib ``sobol.analyze``, first-order and total) or ``"rbd-fast"``
        (SALib ``rbd_fast.analyze``, given data, first-order only).
    quantity : str
        ``"margin"`` or ``"critical_thrust"``.
    cap : float or None
        The search limit at which censored designs enter (``thrust_max / operating`` or
        ``thrust_max``, the smallest when it varies); None when no design is censored.
    censored : int
        Designs stable up to their search limit among those used.
    parameters : tuple of str
    first_order, first_order_conf : (d,) arrays
        First-order indices and the half-widths of their confidence intervals.
    total_order, total_order_conf : (d,) arrays or None
        Total indices (Saltelli design only).
    evaluations : int
        Designs used.
    dropped : int
        Designs (given data) or base samples (Saltelli) left out because a design failed or was
        not computed.
    confidence : float
    """

    method: str
    quantity: str
    cap: float | None
    censored: int
    parameters: tuple[str, ...]
    first_order: NDArray[np.float64]
    first_order_conf: NDArray[np.float64]
    total_order: NDArray[np.float64] | None
    total_order_conf: NDArray[np.float64] | None
    evaluations: int
    dropped: int = 0
    confidence: float = 0.95

    @property
    def capped(self) -> bool:
        """Whether censored designs entered at their search limit (indices of a capped quantity)."""
        return self.censored > 0

    @property
    def of(self) -> str:
        """What the indices are of: ``"margin"`` or ``"min(margin, 3.53)"``."""
        name = "margin" if self.quantity == "margin" else "critical thrust"
        if not self.capped:
            return name
        unit = "" if self.quantity == "margin" else " N"
        return f"min({name}, {self.cap:.4g}{unit})"

    @property
    def estimator(self) -> str:
        return ("Saltelli design, SALib sobol.analyze" if self.method == "saltelli"
                else "given data, RBD-FAST by SALib rbd_fast.analyze")

    @property
    def note(self) -> str:
        text = f"Sobol indices of {self.of} ({self.estimator}; {self.evaluations} designs"
        text += f", {self.dropped} {'base samples' if self.method == 'saltelli' else 'designs'} left out for failures)" if self.dropped else ")"
        if self.capped:
            text += (f": {self.censored} designs stable up to the search limit enter at it; these are the indices "
                     "of the capped quantity, not of the uncensored one")
        if self.total_order is None:
            text += "; total indices need sampling.method = 'saltelli'"
        return text

    def summary(self) -> str:
        """One line: the indices per parameter."""
        from ..display.format import number

        parts = []
        for i, p in enumerate(self.parameters):
            s = f"{p} S1 {number(self.first_order[i], 2, fmt='f')}"
            if self.total_order is not None:
                s += f" ST {number(self.total_order[i], 2, fmt='f')}"
            parts.append(s)
        return f"Sobol indices of {self.of}: " + ", ".join(parts)

    def to_dict(self) -> dict[str, Any]:
        def arr(a):
            return None if a is None else [float(v) for v in a]

        return {"method": self.method, "quantity": self.quantity, "of": self.of, "capped": self.capped,
                "cap": self.cap, "censored": self.censored, "parameters": list(self.parameters),
                "first_order": arr(self.first_order), "first_order_conf": arr(self.first_order_conf),
                "total_order": arr(self.total_order), "total_order_conf": arr(self.total_order_conf),
                "evaluations": self.evaluations, "dropped": self.dropped, "confidence": self.confidence}

    def to_xarray(self):
        """A Dataset over ``parameter``: ``first_order``, ``total_order`` and their half-widths."""
        import xarray as xr

        nan = np.full(len(self.parameters), np.nan)
        attrs = {"units": "1"}
        data = {
            "first_order": ("parameter", self.first_order, {**attrs, "long_name": f"first-order Sobol index of {self.of}"}),
            "first_order_conf": ("parameter", self.first_order_conf, {**attrs, "long_name": f"{self.confidence:g} interval half-width"}),
            "total_order": ("parameter", nan if self.total_order is None else self.total_order,
                            {**attrs, "long_name": f"total Sobol index of {self.of}"}),
            "total_order_conf": ("parameter", nan if self.total_order_conf is None else self.total_order_conf,
                                 {**attrs, "long_name": f"{self.confidence:g} interval half-width"}),
        }
        return xr.Dataset(data, coords={"parameter": list(self.parameters)},
                          attrs={"sensitivity_method": self.method, "sensitivity_of": self.of,
                                 "sensitivity_note": self.note})

    def plot(self, ax=None):
        """Bar chart of the indices with their intervals; returns the Axes."""
        from ..plot.statistics import plot_sensitivity

        return plot_sensitivity(self, ax=ax)

    def __repr__(self) -> str:
        return f"SensitivityIndices({self.method}, {self.summary()})"

    def cells(self, i: int) -> list[str]:
        """``["0.980 +- 0.006", ...]``: the indices of parameter ``i`` with their half-widths."""
        from ..display.format import number

        def cell(v, c):
            return f"{number(v, 3, fmt='f')} +- {number(c, 3, fmt='f')}"

        out = [cell(self.first_order[i], self.first_order_conf[i])]
        if self.total_order is not None:
            out.append(cell(self.total_order[i], self.total_order_conf[i]))
        return out

    def _repr_html_(self) -> str:
        from ..display.html import html_table

        conf = f"+- {100 * self.confidence:g} %"
        header = ["parameter", f"first order {conf}"] + ([f"total {conf}"] if self.total_order is not None else [])
        rows = [[p, *self.cells(i)] for i, p in enumerate(self.parameters)]
        return html_table(self.note, rows, header=header)


def _inputs(result) -> NDArray[np.float64]:
    """``(n, d)`` parameter values as numbers (a list of words becomes its codes, in order of
    first appearance: the estimators need only the order of the values, or none)."""
    ds = result.dataset
    cols = []
    for p in result.parameters:
        v = np.asarray(ds[p].values).ravel()
        if v.dtype.kind in "fiub":
            cols.append(v.astype(float))
        else:
            _, first, codes = np.unique(v.astype(str), return_index=True, return_inverse=True)
            rank = np.argsort(np.argsort(first))
            cols.append(rank[codes].astype(float))
    return np.column_stack(cols)


def sensitivity_indices(result, quantity: str | None = None, *, confidence: float = 0.95,
                        resamples: int = RESAMPLES, seed: int = 1) -> SensitivityIndices:
    """Sobol sensitivity indices of a random, Sobol or Saltelli study.

    Parameters
    ----------
    result : StudyResult
    quantity : {"margin", "critical_thrust"}, optional
        Default the margin when the operating thrust is known, else the critical thrust.
    confidence : float
        Level of the bootstrap intervals.
    resamples : int
        Bootstrap resamples.
    seed : int
        Seed of the bootstrap (> 0), so that the intervals are reproducible.

    Raises
    ------
    ModelError
        A grid study; too few computable designs; a quantity that is the same for every design.
    """
    from .sampling import saltelli_rows
    from .statistics import SAMPLED, censored_values

    ds = result.dataset
    sampling = str(ds.attrs.get("sampling", ""))
    if sampling not in SAMPLED:
        raise ModelError("STORE", sampling, "sensitivity indices need a random, sobol or saltelli study")
    if quantity is None:
        quantity = "margin" if censored_values(result, "margin")[0] is not None else "critical_thrust"
    if quantity not in ("margin", "critical_thrust"):
        raise ModelError("quantity", quantity, "must be 'margin' or 'critical_thrust'")
    value, limit, censored, ok = censored_values(result, quantity)
    if value is None:
        raise ModelError("quantity", quantity, "is not stored and cannot be derived (no operating thrust)")
    y = np.where(censored, np.nan if limit is None else limit, value)
    y = np.where(ok, y, np.nan)
    usable = np.isfinite(y)
    names = tuple(result.parameters)
    d = len(names)
    problem = {"num_vars": d, "names": list(names), "bounds": [[0.0, 1.0]] * d}
    if sampling == "saltelli":
        r = saltelli_rows(y.size, d)
        groups = np.column_stack([r["A"], r["AB"], r["B"]])       # (n, d + 2) rows of each base sample
        keep = usable[groups].all(axis=1)
        rows = np.sort(groups[keep].ravel())
        dropped = int(np.count_nonzero(~keep))
        if keep.sum() < 4:
            raise ModelError("STORE", f"{int(keep.sum())} complete base samples", "too few for Sobol indices (at least 4)")
    else:
        rows = np.flatnonzero(usable)
        dropped = int(np.count_nonzero(~usable))
        if rows.size < 4 * HARMONICS:
            raise ModelError("STORE", f"{rows.size} computed designs", f"too few for RBD-FAST indices (at least {4 * HARMONICS})")
    yy = y[rows]
    if np.ptp(yy) <= 1e-12 * max(1.0, float(np.abs(yy).max())):
        raise ModelError("quantity", quantity, "is the same for every design: no sensitivity to compute")
    cens = censored[rows]
    cap = float(np.min(limit[rows][cens])) if cens.any() else None
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # SALib divides by a zero variance of a constant column
        if sampling == "saltelli":
            from SALib.analyze import sobol

            out = sobol.analyze(problem, yy, calc_second_order=False, num_resamples=resamples,
                                conf_level=confidence, seed=seed)
            first, first_conf = out["S1"], out["S1_conf"]
            total, total_conf = np.asarray(out["ST"], dtype=float), np.asarray(out["ST_conf"], dtype=float)
        else:
            from SALib.analyze import rbd_fast

            out = rbd_fast.analyze(problem, _inputs(result)[rows], yy, M=HARMONICS, num_resamples=resamples,
                                   conf_level=confidence, seed=seed)
            first, first_conf = out["S1"], out["S1_conf"]
            total = total_conf = None
    return SensitivityIndices(
        method="saltelli" if sampling == "saltelli" else "rbd-fast",
        quantity=quantity,
        cap=cap,
        censored=int(cens.sum()),
        parameters=names,
        first_order=np.asarray(first, dtype=float),
        first_order_conf=np.asarray(first_conf, dtype=float),
        total_order=total,
        total_order_conf=total_conf,
        evaluations=int(rows.size),
        dropped=dropped,
        confidence=confidence,
    )
