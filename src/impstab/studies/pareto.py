"""Pareto front of designs over an isolation output and the stability margin.

A design is on the front when no other design is at least as good in both objectives and
strictly better in one. The non-dominated sort is pymoo's
(:class:`pymoo.util.nds.non_dominated_sorting.NonDominatedSorting`, the one the optimiser
uses), on objectives to minimise: ``(isolation, -margin)``. Ties (two designs with the same
pair) are both on the front.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["pareto_mask", "tradeoff_table"]


def pareto_mask(objectives: ArrayLike) -> NDArray[np.bool_]:
    """The non-dominated rows of ``objectives (n, k)``, every column minimised.

    Rows with a NaN are never on the front (and dominate nothing).

    Returns
    -------
    (n,) bool array
    """
    from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

    f = np.asarray(objectives, dtype=float)
    if f.ndim != 2:
        raise ValueError("objectives must be an (n, k) array")
    mask = np.zeros(f.shape[0], dtype=bool)
    rows = np.flatnonzero(np.isfinite(f).all(axis=1))
    if rows.size:
        front = NonDominatedSorting().do(f[rows], only_non_dominated_front=True)
        mask[rows[np.asarray(front, dtype=int)]] = True
    return mask


def tradeoff_table(result, isolation: str = "peak_transmissibility", stability: str = "margin", *,
                   required_margin: float | None = None, deflection_limit: float | None = None,
                   load_limit: float | None = None) -> dict:
    """Isolation against stability for every design of a study, with the Pareto front.

    Parameters
    ----------
    result : StudyResult
    isolation : str
        A stored isolation output to minimise (``peak_transmissibility``, a named ``at`` output, ...).
    stability : str
        ``"margin"`` or ``"critical_thrust"`` (maximised). A design stable over its whole search
        counts with its search limit (a lower bound; ``censored``).
    required_margin : float, optional
        Designs below it are not ``acceptable``; ``chosen`` is the acceptable front design with
        the smallest isolation value.
    deflection_limit, load_limit : float, optional
        Static limits (m, N) on the stored ``static_deflection`` and ``peak_mount_load``: a design
        beyond them is not ``feasible`` and left out of the front.

    Returns
    -------
    dict of flat arrays over the designs (C order of the study's design array): ``isolation``,
    ``stability``, ``censored``, ``feasible`` (computed, within the static limits), ``pareto``
    (the front of the feasible designs), ``acceptable`` (feasible and margin >= required), and
    ``chosen`` (flat index or None).
    """
    from ..errors import ModelError

    ds = result.dataset
    for name, what in ((isolation, "isolation"), (stability, "stability")):
        if name not in ds.data_vars or ds[name].dtype.kind != "f":
            known = [v for v in ds.data_vars if ds[v].dtype.kind == "f"]
            raise ModelError(what, name, f"must be one of the stored real outputs {known}")
    iso = ds[isolation].values.astype(float).ravel()
    stab = ds[stability].values.astype(float).ravel()
    status = ds["status"].values.ravel()
    censored = np.zeros(iso.shape, dtype=bool)
    if stability in ("margin", "critical_thrust") and "kind" in ds:
        limit = result.search_limit(stability)
        if limit is not None:
            censored = (ds["kind"].values.ravel() == 0) & (status == 0)
            stab = np.where(censored, np.asarray(limit, dtype=float).ravel(), stab)
    feasible = (status == 0) & np.isfinite(iso) & np.isfinite(stab)
    for limit, name in ((deflection_limit, "static_deflection"), (load_limit, "peak_mount_load")):
        if limit is None:
            continue
        if name not in ds:
            raise ModelError(name, None, f"is not stored by the study: add it to its outputs to apply the limit {limit:g}")
        with np.errstate(invalid="ignore"):
            feasible &= ds[name].values.ravel() <= limit
    pareto = np.zeros(iso.shape, dtype=bool)
    rows = np.flatnonzero(feasible)
    pareto[rows] = pareto_mask(np.column_stack([iso[rows], -stab[rows]]))
    acceptable = feasible.copy()
    if required_margin is not None:
        acceptable &= stab >= required_margin
    chosen = None
    if acceptable.any():
        cand = np.flatnonzero(acceptable)
        chosen = int(cand[np.argmin(iso[cand])])
    return {"isolation": iso, "stability": stab, "censored": censored, "feasible": feasible, "pareto": pareto,
            "acceptable": acceptable, "chosen": chosen, "isolation_name": isolation, "stability_name": stability}
