"""The batched thrust scan: stacked classification, brackets, bubble searches."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..critical import TOL_DUPLICATE, TOL_UNSTABLE
from ..blocks import decoupled_blocks, eig_affine, eigvals_affine_blocks
from .jobs import _Job, _ScanTable, _Stack, gather

Array = NDArray[np.float64]



def _operators(jobs: list[_Job]) -> None:
    """``a0 = M^-1 K0`` and ``a1 = M^-1 K1`` of the affine undamped jobs, as the engine forms them.

    Also their decoupled blocks (:mod:`impstab.linear.blocks`) on each job's thrust range; the
    stacks are shared by the jobs (:func:`gather`), each job keeping its row.
    """
    fast = [j for j in jobs if j.fast]
    if not fast:
        return
    m = np.stack([j.mass for j in fast])
    a = np.linalg.solve(np.concatenate([m, m]), np.concatenate([np.stack([j.k0 for j in fast]), np.stack([j.k1 for j in fast])]))
    a0, a1 = a[: len(fast)], a[len(fast):]
    pack = (a0, a1, decoupled_blocks(a0, a1, np.array([j.p_max for j in fast])))
    for i, j in enumerate(fast):
        j.a0, j.a1, j.pack, j.pack_row = a0[i], a1[i], pack, i


def _classify_group(jobs: list[_Job], start: int, stop: int) -> tuple | list:
    """Flags ``(J, m)`` and indicators ``(J, m, 2)`` of the jobs' grid points ``start:stop``.

    Where the stacked call fails, a list with each job's own ``(flags, ind)`` or exception.
    """
    try:
        if jobs[0].fast:  # the operators a0 + p a1 are formed one at a time in the kernel, block by block
            a0, a1, blocks = gather(jobs)
            p = np.stack([j.grid[start:stop] for j in jobs])
            vals = eigvals_affine_blocks(a0, a1, p, blocks)
            flags, ind = _Stack(None, True).classify_values(vals.reshape(-1, vals.shape[-1]))
        else:
            ops = np.stack([j.engine().operators(j.grid[start:stop])[0] for j in jobs])
            flat = ops.reshape((-1,) + ops.shape[2:])
            flags, ind = _Stack(flat, jobs[0].undamped).classify(np.zeros(len(flat)))
    except np.linalg.LinAlgError:
        out = []
        for j in jobs:
            try:
                out.append(_Stack(j.engine().operators(j.grid[start:stop])[0], j.undamped).classify(j.grid[start:stop]))
            except Exception as exc:  # noqa: BLE001 - reported per design
                out.append(exc)
        return out
    n = stop - start
    return flags.reshape(len(jobs), n), ind.reshape(len(jobs), n, 2)


def _prime(jobs: list[_Job], chunk: int, errors: dict) -> None:
    """Classify each job's scan grid chunk by chunk, batched; a job stops where its scan would.

    The classifications go to one :class:`_ScanTable` shared by the jobs (``job.table``,
    ``job.row``), where the vectorized steps and each job's own engine find them.
    """
    n_pts = len(jobs[0].grid) if jobs else 0
    table = _ScanTable(np.zeros((len(jobs), n_pts), dtype=bool), np.full((len(jobs), n_pts, 2), np.nan),
                       np.zeros(len(jobs), dtype=np.int64), chunk)
    for r, j in enumerate(jobs):
        j.table, j.row = table, r
    first = np.full(len(jobs), n_pts)
    active, start = np.arange(len(jobs)), 0
    while active.size and start < n_pts:
        stop = min(start + chunk, n_pts)
        keys = [(jobs[r].fast, jobs[r].undamped) for r in active]
        for key in set(keys):
            rows = active[np.array([k == key for k in keys])]
            group = [jobs[r] for r in rows]
            res = _classify_group(group, start, stop)
            if isinstance(res, list):  # the stacked call failed: each job's own result
                ok = np.array([not isinstance(x, Exception) for x in res])
                for j, x in zip(group, res):
                    if isinstance(x, Exception):
                        errors[id(j)] = x
                rows, res = rows[ok], (np.array([x[0] for x, o in zip(res, ok) if o]).reshape(-1, stop - start),
                                       np.array([x[1] for x, o in zip(res, ok) if o]).reshape(-1, stop - start, 2))
            table.flags[rows, start:stop], table.ind[rows, start:stop] = res
            table.length[rows] = stop
            for r in rows.tolist():
                jobs[r].evaluations += stop - start
        hit = table.flags[active, start:stop]
        pos = np.where(hit.any(axis=1), start + np.argmax(hit, axis=1), n_pts)
        first[active] = np.where(first[active] == n_pts, pos, first[active])
        live = np.array([id(jobs[r]) not in errors for r in active], dtype=bool)
        active = active[live & (first[active] >= stop - 1)]
        start = stop


# -- vectorized engine steps -----------------------------------------------------------------
def _brackets(jobs: list[_Job], errors: dict) -> list:
    """First bracket of each job's scan as the engine's ``scan`` finds it (None: no crossing).

    The bubble searches of all jobs run in lockstep; the ``attracting`` test is vectorized for
    affine undamped jobs and the engine's own for the others (always true when damped).
    """
    n_pts = len(jobs[0].grid)
    table = jobs[0].table
    rows = np.array([j.row for j in jobs])
    flags, ind, length = table.flags[rows], table.ind[rows], table.length[rows]
    js = np.arange(n_pts)[None, :]
    upper = np.where(length < n_pts, length - 1, n_pts)[:, None]
    valid = (js >= 1) & (js < upper)
    prev = np.roll(flags, 1, axis=1)
    nxt_i = np.minimum(js + 1, length[:, None] - 1)
    nxt_f = np.take_along_axis(flags, nxt_i, axis=1)
    inner = ~flags & (js + 1 < length[:, None]) & ~nxt_f
    prev_ind, nxt_ind = np.roll(ind, 1, axis=1), np.take_along_axis(ind, nxt_i[..., None].repeat(2, -1), axis=1)
    with np.errstate(invalid="ignore"):
        dips = inner[..., None] & (ind < prev_ind) & (ind <= nxt_ind)
    change = flags != prev
    cand = valid & (change | dips[..., 0] | dips[..., 1])
    hit_change = cand & change
    first_change = np.where(hit_change.any(axis=1), np.argmax(hit_change, axis=1), n_pts)
    before = cand & ~change & (js < first_change[:, None])
    # the dips a bubble search starts from: a dip of the smallest s (undamped), or a close
    # approach of two frequencies that attract; the attraction test of every dip before the
    # first change at once (each test depends on its own grid point only)
    undamped = np.array([j.undamped for j in jobs])
    smin_dips = before & dips[..., 1] & undamped[:, None]
    attract = np.zeros_like(before)
    where = list(zip(*(a.tolist() for a in np.nonzero(before & dips[..., 0]))))
    if where:
        attract[tuple(np.array(where).T)] = _attract_any(jobs, where, errors)
    searched = smin_dips | attract
    out: list = [None] * len(jobs)
    pos: dict[int, int] = {}
    for r in range(len(jobs)):
        if id(jobs[r]) in errors:
            continue
        if searched[r].any():
            pos[r] = 0
        elif first_change[r] < n_pts:
            out[r] = (jobs[r].grid[first_change[r] - 1], jobs[r].grid[first_change[r]])
    while pos:  # rows with a bubble search to run: in order, all rows in lockstep
        dip: list[tuple[int, int]] = []
        for r in list(pos):
            hits = np.flatnonzero(searched[r, pos[r]:])
            if not hits.size:
                del pos[r]
                if first_change[r] < n_pts:
                    out[r] = (jobs[r].grid[first_change[r] - 1], jobs[r].grid[first_change[r]])
                continue
            j = pos[r] + int(hits[0])
            pos[r] = j + 1
            dip.append((r, j))
        first = _bubbles(jobs, [(r, j) for r, j in dip if smin_dips[r, j]], 1, errors)
        rest = [(r, j) for r, j in dip if first.get(r) is None and attract[r, j] and id(jobs[r]) not in errors]
        second = _bubbles(jobs, rest, 0, errors)
        for r, j in dip:
            if id(jobs[r]) in errors:
                del pos[r]
                continue
            hit = first.get(r) if first.get(r) is not None else second.get(r)
            if hit is not None:
                out[r] = (jobs[r].grid[j - 1], hit)
                del pos[r]
    return out


def _attract_any(jobs: list[_Job], where: list[tuple[int, int]], errors: dict) -> NDArray[np.bool_]:
    """The engine's ``attracting`` test for each (job, grid index); False where it raised."""
    out = np.zeros(len(where), dtype=bool)
    fast = [k for k, (r, _) in enumerate(where) if jobs[r].fast]
    if fast:
        out[fast], fine = _attracting([jobs[where[k][0]] for k in fast], [where[k][1] for k in fast])
        for k in np.asarray(fast)[~fine]:  # as the engine's own test raises there
            errors[id(jobs[where[k][0]])] = np.linalg.LinAlgError("Singular matrix")
    for k, (r, j) in enumerate(where):
        if jobs[r].fast or id(jobs[r]) in errors:
            continue
        g = jobs[r].grid
        try:
            out[k] = jobs[r].engine().attracting(g[j - 1], g[j], g[j + 1])
        except Exception as exc:  # noqa: BLE001 - reported per design
            errors[id(jobs[r])] = exc
    return out


def _bubbles(jobs: list[_Job], where: list[tuple[int, int]], column: int, errors: dict) -> dict:
    """The engine's ``bubble(grid[j-1], grid[j+1], column)`` for many jobs, in lockstep.

    Each search is scipy's bounded Brent minimisation (the engine's), ported step for step to a
    generator, so that all searches share one batched classification per step.
    """
    found: dict[int, float | None] = {}
    runs = {}
    for r, j in where:
        lo, hi = jobs[r].grid[j - 1], jobs[r].grid[j + 1]
        gen = _bounded_minimum(lo, hi, (hi - lo) * 1e-9)
        runs[r] = (gen, next(gen))
        found[r] = None
    while runs:
        rows = list(runs)
        unstable, ind = classify_points([jobs[r] for r in rows], [runs[r][1] for r in rows], errors)
        for k, r in enumerate(rows):
            gen, x = runs.pop(r)
            if id(jobs[r]) in errors:
                continue
            if unstable[k]:
                found[r] = float(x)
                continue
            try:
                runs[r] = (gen, gen.send(float(ind[k, column])))
            except StopIteration:
                pass
    return found


def classify_points(jobs: list[_Job], loads: list[float], errors: dict) -> tuple[NDArray[np.bool_], Array]:
    """The engine's classification of each job at its own load, batched (``engine.classify``).

    Returns the unstable flags and the indicators ``(len(jobs), 2)``; a job whose operator
    cannot be formed is recorded in ``errors`` (its row is stable, NaN).
    """
    unstable = np.zeros(len(jobs), dtype=bool)
    ind = np.full((len(jobs), 2), np.nan)
    step: dict[bool, list] = {}
    for k, (job, x) in enumerate(zip(jobs, loads)):
        try:
            step.setdefault(job.undamped, []).append((k, job.point_op(x)))
        except Exception as exc:  # noqa: BLE001 - reported per design
            errors[id(job)] = exc
    for undamped, items in step.items():
        rows = [k for k, _ in items]
        unstable[rows], ind[rows] = _Stack(np.concatenate([op for _, op in items]), undamped).classify(np.zeros(len(items)))
        for k in rows:
            jobs[k].evaluations += 1
    return unstable, ind


def _bounded_minimum(x1: float, x2: float, xatol: float, maxfun: int = 500):
    """scipy's ``_minimize_scalar_bounded`` as a generator: yields x, receives f(x)."""
    sqrt_eps = np.sqrt(2.2e-16)
    golden_mean = 0.5 * (3.0 - np.sqrt(5.0))
    a, b = x1, x2
    fulc = a + golden_mean * (b - a)
    nfc, xf = fulc, fulc
    rat = e = 0.0
    fx = yield xf
    num = 1
    ffulc = fnfc = fx
    xm = 0.5 * (a + b)
    tol1 = sqrt_eps * np.abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    while np.abs(xf - xm) > (tol2 - 0.5 * (b - a)):
        golden = 1
        if np.abs(e) > tol1:  # parabolic fit
            golden = 0
            r = (xf - nfc) * (fx - ffulc)
            q = (xf - fulc) * (fx - fnfc)
            p = (xf - fulc) * q - (xf - nfc) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = np.abs(q)
            r = e
            e = rat
            if (np.abs(p) < np.abs(0.5 * q * r)) and (p > q * (a - xf)) and (p < q * (b - xf)):
                rat = (p + 0.0) / q
                x = xf + rat
                if ((x - a) < tol2) or ((b - x) < tol2):
                    rat = tol1 * (np.sign(xm - xf) + ((xm - xf) == 0))
            else:
                golden = 1
        if golden:
            e = a - xf if xf >= xm else b - xf
            rat = golden_mean * e
        si = np.sign(rat) + (rat == 0)
        x = xf + si * np.maximum(np.abs(rat), tol1)
        fu = yield x
        num += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                b = xf
            fulc, ffulc = nfc, fnfc
            nfc, fnfc = xf, fx
            xf, fx = x, fu
        else:
            if x < xf:
                a = x
            else:
                b = x
            if (fu <= fnfc) or (nfc == xf):
                fulc, ffulc = nfc, fnfc
                nfc, fnfc = x, fu
            elif (fu <= ffulc) or (fulc == xf) or (fulc == nfc):
                fulc, ffulc = x, fu
        xm = 0.5 * (a + b)
        tol1 = sqrt_eps * np.abs(xf) + xatol / 3.0
        tol2 = 2.0 * tol1
        if num >= maxfun:
            return


def _attracting(jobs: list[_Job], js: list[int]) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """The engine's ``attracting(grid[j-1], grid[j], grid[j+1])`` for many jobs at once.

    Also returns where the test could be made (False: singular eigenvectors, where the engine's
    own test raises).
    """
    lo = np.array([jb.grid[j - 1] for jb, j in zip(jobs, js)])
    mid = np.array([jb.grid[j] for jb, j in zip(jobs, js)])
    hi = np.array([jb.grid[j + 1] for jb, j in zip(jobs, js)])
    a0, a1, blocks = gather(jobs)
    for jb in jobs:
        jb.evaluations += 3
    op = lambda p: a0 + p[:, None, None] * a1  # noqa: E731
    vals, vecs, inv, fine = eig_affine(a0, a1, mid, blocks)
    vals, vecs, inv = (np.where(fine.reshape((-1,) + (1,) * (x.ndim - 1)), x, 0) for x in (vals, vecs, inv))
    result = np.abs(vals.imag).max(-1) > TOL_UNSTABLE * np.abs(vals).max(-1)
    order = np.argsort(vals.real, axis=-1)
    re = np.take_along_axis(vals.real, order, -1)
    scale = np.abs(re).max(-1, keepdims=True)
    diffs = np.diff(re, axis=-1)
    distinct = diffs >= TOL_DUPLICATE * scale
    j = np.argmin(np.where(distinct, diffs, np.inf), axis=-1)
    pick = lambda c: np.take_along_axis(re, c[:, None], -1)  # noqa: E731
    lower_s, upper_s = np.abs(re - pick(j)) < TOL_DUPLICATE * scale, np.abs(re - pick(j + 1)) < TOL_DUPLICATE * scale
    lower, upper = np.zeros_like(lower_s), np.zeros_like(upper_s)
    np.put_along_axis(lower, order, lower_s, -1)
    np.put_along_axis(upper, order, upper_s, -1)
    rate = (op(hi) - op(lo)) / (hi - lo)[:, None, None]
    b = inv @ (rate @ vecs)
    norm = np.maximum(np.abs(rate).max(axis=(-2, -1)), 1e-300)
    # the interaction B_lu B_ul of the two clusters, a k_l x k_l block (the engine's product),
    # for all rows with the same cluster sizes at once
    pulled = np.zeros(len(b), dtype=bool)
    n_lower, n_upper = lower.sum(-1), upper.sum(-1)
    for kl, ku in set(zip(n_lower.tolist(), n_upper.tolist())):
        rows = np.flatnonzero((n_lower == kl) & (n_upper == ku))
        li = np.nonzero(lower[rows])[1].reshape(len(rows), kl)
        ui = np.nonzero(upper[rows])[1].reshape(len(rows), ku)
        br = b[rows]
        b_lu = np.take_along_axis(np.take_along_axis(br, li[:, :, None], 1), ui[:, None, :], 2)
        b_ul = np.take_along_axis(np.take_along_axis(br, ui[:, :, None], 1), li[:, None, :], 2)
        prod = b_lu @ b_ul
        inter = prod[:, 0, :] if kl == 1 else np.linalg.eigvals(prod)
        pulled[rows] = np.any(inter.real < -1e-8 * norm[rows, None] ** 2, axis=-1)
    return np.where(result, True, distinct.any(-1) & pulled) & fine, fine
