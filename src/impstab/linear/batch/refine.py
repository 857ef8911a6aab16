"""The batched exact refinement, and the per-design engine for everything else."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..blocks import eig_affine
from ..critical import FLOOR, TOL_CLUSTER, TOL_DUPLICATE
from ..eigen import cluster_participation
from .jobs import _EPS4, _Job, _Stack, gather
from .scan import _brackets, classify_points

Array = NDArray[np.float64]



def _select(vecs: Array, proj: Array, k: NDArray) -> tuple[NDArray, NDArray]:
    """The engine's ``select``: mask of the ``k`` vectors most in the cluster, and whether clear."""
    y = proj @ vecs
    share = (y.real**2 + y.imag**2).sum(axis=-2)
    srt = -np.sort(-share, axis=-1)
    rank = np.argsort(np.argsort(-share, axis=-1, kind="stable"), axis=-1, kind="stable")
    kth = np.take_along_axis(srt, (k - 1)[:, None], -1)[:, 0]
    nxt = np.take_along_axis(srt, np.minimum(k, srt.shape[-1] - 1)[:, None], -1)[:, 0]
    ok = (kth > 0.25) & ((k == srt.shape[-1]) | (nxt < 0.25))
    return rank < k[:, None], ok


#: what a bracket needs next (``_refine_once``): done (or its own engine), bisection, step back
_DONE, _BISECT, _STEP_BACK = 0, 1, 2


def _refine(jobs: list[_Job], brackets: list[tuple[float, float]]) -> list:
    """The engine's ``refine`` on each bracket, vectorized; None where a job must use its engine.

    As the engine does: where the cluster going unstable at ``b`` is not clearly a cluster at
    ``a`` (a wide bracket over which the modes rotate, or a third mode nearby), the bracket is
    halved on the stability classification and the exact refinement tried again; where the
    exact indicator shows ``a`` already past the onset, ``a`` steps back by the bracket width.
    """
    n = len(jobs)
    a = np.array([br[0] for br in brackets])
    b = np.array([br[1] for br in brackets])
    p_max = np.array([j.p_max for j in jobs])
    out: list = [None] * n
    rows = np.arange(n)
    for _ in range(200):  # the engine's limit
        res, retry = _refine_once([jobs[r] for r in rows], a[rows], b[rows])
        for i in np.flatnonzero(retry == _DONE):
            out[rows[i]] = res[i]
        back = rows[retry == _STEP_BACK]
        new_a = np.clip(2 * a[back] - b[back], 0.0, p_max[back])
        moved = new_a != a[back]  # one that cannot step back is left to its engine (None)
        back = back[moved]
        a[back] = new_a[moved]
        half = rows[retry == _BISECT]
        mid = 0.5 * (a[half] + b[half])
        keep = (mid != a[half]) & (mid != b[half])
        half, mid = half[keep], mid[keep]
        if half.size:  # the engine's unstable_at(mid)
            unstable, _ = classify_points([jobs[r] for r in half], mid.tolist(), {})
            b[half[unstable]], a[half[~unstable]] = mid[unstable], mid[~unstable]
        rows = np.sort(np.concatenate([back, half]))
        if not rows.size:
            break
    return out


def _refine_once(jobs: list[_Job], a: Array, b: Array) -> tuple[list, NDArray[np.int8]]:
    """One attempt of the exact refinement of each bracket ``(a, b)``, vectorized.

    Returns each result (None where there is none) and what the bracket needs next: ``_DONE``
    (a result, or None for the job's own engine), ``_BISECT`` or ``_STEP_BACK``.
    """
    n = len(jobs)
    a0, a1, blocks = gather(jobs)

    def eig(p, rows):
        """Eigenvalues, unit eigenvectors, their inverse and where these exist (else NaN)."""
        if rows is None:
            return eig_affine(a0, a1, p, blocks)
        return eig_affine(a0[rows], a1[rows], p, blocks.take(rows))

    evals = np.full(n, 2)
    vals_b, vecs_b, inv_b, good = eig(b, None)
    cplx, neg = _Stack(None, True).unstable_parts(vals_b)
    bad = cplx | neg
    has_c = cplx.any(-1)
    key = np.where(np.where(has_c[:, None], cplx, bad), vals_b.real, np.inf)
    ref = np.take_along_axis(vals_b, np.argmin(key, -1)[:, None], -1)
    tol = np.maximum(TOL_CLUSTER * np.abs(ref), FLOOR * np.abs(vals_b).max(-1, keepdims=True))
    members = (np.abs(vals_b - ref) <= tol) | (np.abs(vals_b - np.conj(ref)) <= tol)
    divergence = ~has_c
    k = members.sum(-1)
    proj = (vecs_b * members[:, None, :]) @ inv_b
    vals_a, vecs_a, _, fine_a = eig(a, None)
    _, ok_a = _select(vecs_a, proj, k)
    good &= bad.any(-1) & fine_a
    # the engine's "unique and ok_a": every unstable eigenvalue in the cluster, found again at a
    clear = ~(bad & ~members).any(-1) & ok_a
    retry = np.where(good & ~clear, _BISECT, _DONE).astype(np.int8)
    good &= clear

    def indicator(vals, vecs, inv, fine, rows, derivative):
        sel, ok = _select(vecs, proj[rows], k[rows])
        kk, dv = k[rows], divergence[rows]
        v = np.where(sel, vals, 0)
        s1, s2 = v.sum(-1), (v * v).sum(-1)
        f = np.where(dv, s1.real / kk, (kk * s2 - s1**2).real)
        if not derivative:
            return f, ok
        bd = np.einsum("dij,djk,dki->di", inv, a1[rows], vecs)
        bd = np.where(sel, bd, 0)
        df = np.where(dv, bd.real.sum(-1) / kk, (2 * kk * (v * bd).sum(-1) - 2 * s1 * bd.sum(-1)).real)
        return f, df, ok & fine

    fa, oka = indicator(vals_a, vecs_a, None, fine_a, slice(None), False)
    fb, okb = indicator(vals_b, vecs_b, inv_b, good, slice(None), False)
    retry[good & ~(oka & okb)] = _BISECT  # the engine's _Ambiguous
    retry[good & oka & okb & (fa != 0) & (np.sign(fa) == np.sign(fb))] = _STEP_BACK  # _NoSignChange
    good &= oka & okb & ((fa == 0) | (np.sign(fa) != np.sign(fb)))
    root = np.where(fa == 0, a, np.nan)
    live = np.flatnonzero(good & (fa != 0))
    lo, hi, flo = a.copy(), b.copy(), fa.copy()
    with np.errstate(divide="ignore", invalid="ignore"):
        p = a - fa * (b - a) / (fb - fa)
    for _ in range(100):
        if not live.size:
            break
        vals, vecs, inv, fine = eig(p[live], live)
        evals[live] += 1
        f, df, ok = indicator(vals, vecs, inv, fine, live, True)
        good[live[~ok]] = False
        retry[live[~ok]] = _BISECT
        done = ok & (f == 0)
        root[live[done]] = p[live[done]]
        same = np.sign(f) == np.sign(flo[live])
        lo[live] = np.where(same, p[live], lo[live])
        flo[live] = np.where(same, f, flo[live])
        hi[live] = np.where(same, hi[live], p[live])
        with np.errstate(divide="ignore", invalid="ignore"):
            new = np.where(df != 0, p[live] - f / df, np.inf)
        inside = (np.minimum(lo[live], hi[live]) < new) & (new < np.maximum(lo[live], hi[live]))
        new = np.where(inside, new, 0.5 * (lo[live] + hi[live]))
        conv = ok & ~done & ((np.abs(new - p[live]) <= _EPS4 * np.abs(p[live])) | (new == lo[live]) | (new == hi[live]))
        root[live[conv]] = new[conv]
        p[live] = new
        live = live[ok & ~done & ~conv]
    retry[live] = _BISECT  # no convergence in 100 steps: the engine's _Ambiguous
    good &= np.isfinite(root)
    rows = np.flatnonzero(good)
    out: list = [None] * n
    for j, e in zip(jobs, evals + good):
        j.evaluations += int(e)
    if not rows.size:
        return out, retry
    vals, vecs, _, _ = eig(root[rows], rows)
    sel, _ = _select(vecs, proj[rows], k[rows])
    sel_a, ok_sa = _select(vecs_a[rows], proj[rows], k[rows])
    shapes, cols = np.where(ok_sa[:, None, None], vecs_a[rows], vecs), np.where(ok_sa[:, None], sel_a, sel)
    values = np.where(ok_sa[:, None], vals_a[rows], vals)
    mass = np.stack([np.diag(jobs[r].mass) for r in rows])
    part = cluster_participation(shapes, values, cols, mass, TOL_DUPLICATE)
    mean = np.where(sel, vals.real, 0).sum(-1) / k[rows]
    for i, r in enumerate(rows):
        div = bool(divergence[r])
        omega = 0.0 if div else float(np.sqrt(max(mean[i], 0.0)))
        out[r] = (float(root[r]), "divergence" if div else "flutter", omega, part[i])
    return out, retry


# -- per-design engine path and the driver ----------------------------------------------------
def _engine_first_loss(job: _Job, chunk: int, bracket=False):
    """``(load, kind, omega, participation, warnings)`` as ``critical_load_family`` finds it.

    ``bracket`` False: scan (primed) and refine; a tuple: refine that bracket only.
    """
    eng = job.engine()
    if bracket is False:
        _, flags, brackets = eng.scan(0.0, job.p_max, len(job.grid) - 1, chunk, False)
        if flags[0]:
            vals, vecs, m = eng.decompose(0.0)
            members, _, divergence = eng.unstable_cluster(vals)
            p, kind, omega, _, part = eng._finish(0.0, vals, vecs, m, members, divergence)
            return p, kind, omega, part, ()
    else:
        brackets = [bracket]
    first = (None, "none", None, None)
    for a, b in brackets:
        p, kind, omega, _, part = eng.refine(a, b)
        if a < b and (first[0] is None or p < first[0]):
            first = (p, kind, omega, part)
    return (*first, tuple(getattr(eng, "warnings", ())))


def _solve_jobs(jobs: list[_Job], chunk: int, vectorized: bool, errors: dict) -> dict:
    """First loss of stability of every job that has not failed."""
    results: dict[int, tuple] = {}
    live = [j for j in jobs if id(j) not in errors]
    engine_only: list = [j for j in live if not vectorized or j.table.flags[j.row, 0]]
    scanned = [j for j in live if j not in engine_only]
    brackets = _brackets(scanned, errors) if scanned else []
    fast = [(j, br) for j, br in zip(scanned, brackets) if j.fast and br is not None and id(j) not in errors]
    refined = _refine([j for j, _ in fast], [br for _, br in fast]) if fast else []
    done = {id(j): r for (j, _), r in zip(fast, refined) if r is not None}
    for job, br in zip(scanned, brackets):
        if id(job) in errors:
            continue
        if br is None:
            results[id(job)] = (None, "none", None, None, ())
        elif id(job) in done:
            results[id(job)] = (*done[id(job)], ())
        else:
            engine_only.append((job, br))
    for item in engine_only:
        job, br = item if isinstance(item, tuple) else (item, False)
        try:
            results[id(job)] = _engine_first_loss(job, chunk, br)
        except Exception as exc:  # noqa: BLE001 - reported per design
            errors[id(job)] = exc
    return results
