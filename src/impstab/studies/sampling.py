"""Design points of a study: grid axes, or random / Sobol samples drawn from distributions.

Grid: each parameter has its own axis of values and the designs are their Cartesian product.
Random and Sobol: ``n`` points of the unit hypercube (``numpy.random.default_rng(seed)`` or
``scipy.stats.qmc.Sobol(scramble=True, seed=seed)``) mapped through each parameter's inverse
distribution function, so that the samples are reproducible from the study file alone.

Saltelli: the cross-sampled design of Saltelli (2002) for first-order and total Sobol indices,
drawn by SALib (``SALib.sample.sobol.sample`` on the unit hypercube, scrambled, without the
second-order rows) and mapped like the others. ``n`` base samples give ``n * (d + 2)`` designs
for ``d`` parameters, in SALib's order: for each base sample ``j`` the row of matrix A, the ``d``
rows ``AB_i`` (A with column ``i`` taken from B), then the row of B. The design's order is the
order of the ``sample`` dimension of the study, so that the indices can be computed from the
store alone (:mod:`impstab.studies.sensitivity`). The rows of A and of B are each ``n`` scrambled
Sobol points of the input distribution.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .schema import DistributionSpec, ParameterSpec, RangeSpec

__all__ = ["axis_values", "unit_samples", "map_samples", "check_distribution", "design_count", "saltelli_rows"]

#: unit-cube coordinates are kept this far from 0 and 1 (inverse CDFs are infinite there)
_EDGE = 1e-12


def axis_values(spec: ParameterSpec) -> NDArray | list:
    """Grid values of one parameter (a float array for a range, the list as given otherwise)."""
    vals = spec.values
    if isinstance(vals, RangeSpec):
        if vals.num is None:
            raise ValueError("num: is required for grid sampling (the number of grid values)")
        if vals.scale == "log":
            if vals.start <= 0 or vals.stop <= 0:
                raise ValueError("start and stop must be > 0 with scale = 'log'")
            return np.geomspace(vals.start, vals.stop, vals.num)
        return np.linspace(vals.start, vals.stop, vals.num)
    return list(vals)


def check_distribution(spec: ParameterSpec) -> None:
    """ValueError naming the key when a random/sobol parameter is ill-defined."""
    if (spec.values is None) == (spec.distribution is None):
        raise ValueError("give either values (a range or a list) or a distribution, not both or neither")
    if isinstance(spec.values, RangeSpec):
        if spec.values.num is not None:
            raise ValueError("num: is only used with grid sampling (random, sobol and saltelli draw their own values)")
        if spec.values.stop <= spec.values.start:
            raise ValueError("stop must be greater than start")
        if spec.values.scale == "log" and spec.values.start <= 0:
            raise ValueError("start and stop must be > 0 with scale = 'log'")
    dist = spec.distribution
    if dist is None:
        return
    need = {
        "uniform": ("low", "high"), "loguniform": ("low", "high"), "normal": ("mean", "std"),
        "lognormal": ("median", "sigma"), "truncnormal": ("mean", "std", "low", "high"),
    }[dist.kind]
    given = {k for k, v in dist.model_dump().items() if v is not None and k != "kind"}
    missing = [k for k in need if k not in given]
    extra = sorted(given - set(need))
    if missing:
        raise ValueError(f"a {dist.kind} distribution needs {', '.join(need)} (missing {', '.join(missing)})")
    if extra:
        raise ValueError(f"a {dist.kind} distribution takes {', '.join(need)}, not {', '.join(extra)}")
    if "high" in need and dist.high <= dist.low:
        raise ValueError("high must be greater than low")
    if dist.kind == "loguniform" and dist.low <= 0:
        raise ValueError("low must be > 0 for a loguniform distribution")


def design_count(method: str, n: int, dim: int) -> int:
    """Number of designs of ``n`` samples of ``dim`` parameters: ``n``, or ``n * (dim + 2)`` for
    Saltelli's design (``n`` base samples)."""
    return n * (dim + 2) if method == "saltelli" else n


def saltelli_rows(size: int, dim: int) -> dict[str, NDArray[np.int64]]:
    """Positions of the rows of Saltelli's design of ``size`` designs and ``dim`` parameters:
    ``"A"`` and ``"B"`` (``(n,)`` each) and ``"AB"`` (``(n, dim)``: column ``i`` holds the rows
    of A with parameter ``i`` taken from B)."""
    step = dim + 2
    if size % step:
        raise ValueError(f"{size} designs are not a Saltelli design of {dim} parameters (a multiple of {step})")
    base = np.arange(0, size, step, dtype=np.int64)
    return {"A": base, "B": base + dim + 1, "AB": base[:, None] + np.arange(1, dim + 1, dtype=np.int64)}


def unit_samples(method: str, n: int, dim: int, seed: int) -> NDArray[np.float64]:
    """``(n, dim)`` points in the open unit hypercube (``n`` designs: for ``"saltelli"`` a
    multiple of ``dim + 2``, see :func:`design_count`)."""
    if method == "saltelli":
        from SALib.sample import sobol as saltelli

        problem = {"num_vars": dim, "names": [f"x{i}" for i in range(dim)], "bounds": [[0.0, 1.0]] * dim}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # a base size that is not a power of two
            u = saltelli.sample(problem, n // (dim + 2), calc_second_order=False, scramble=True, seed=seed)
    elif method == "sobol":
        from scipy.stats import qmc

        with warnings.catch_warnings():
            # a sample size that is not a power of two loses some balance; allowed, documented
            warnings.simplefilter("ignore", UserWarning)
            u = qmc.Sobol(d=dim, scramble=True, seed=seed).random(n)
    else:
        u = np.random.default_rng(seed).random((n, dim))
    return np.clip(u, _EDGE, 1.0 - _EDGE)


def _inverse(dist: DistributionSpec, u: NDArray) -> NDArray:
    from scipy import stats

    if dist.kind == "uniform":
        return dist.low + u * (dist.high - dist.low)
    if dist.kind == "loguniform":
        return np.exp(np.log(dist.low) + u * (np.log(dist.high) - np.log(dist.low)))
    if dist.kind == "normal":
        return stats.norm.ppf(u, loc=dist.mean, scale=dist.std)
    if dist.kind == "lognormal":
        return dist.median * np.exp(dist.sigma * stats.norm.ppf(u))
    a, b = (dist.low - dist.mean) / dist.std, (dist.high - dist.mean) / dist.std
    return stats.truncnorm.ppf(u, a, b, loc=dist.mean, scale=dist.std)


def map_samples(spec: ParameterSpec, u: NDArray[np.float64]) -> NDArray | list[Any]:
    """Values of one parameter at the unit-cube coordinates ``u`` (inverse distribution)."""
    vals = spec.values
    if isinstance(vals, RangeSpec):
        if vals.scale == "log":
            lo, hi = np.log(vals.start), np.log(vals.stop)
            return np.exp(lo + u * (hi - lo))
        return vals.start + u * (vals.stop - vals.start)
    if vals is not None:
        idx = np.minimum((u * len(vals)).astype(np.int64), len(vals) - 1)
        return [vals[i] for i in idx]
    return _inverse(spec.distribution, u)
