"""The scan of each problem (compiled): classification of grid points, brackets, bubble searches.

The load range is sampled on the problem's grid (``n_scan`` intervals), a chunk of points at a
time (one point at a time for affine problems, whose operators cost nothing to form), and each
point is classified by its eigenvalues alone (:mod:`impstab.linear.classify`, the engine's
stability rule). The points are examined in order:

* a change of stability between neighbours is a bracket ``(stable, unstable)``;
* between stable points, where the bubble indicator has a local minimum -- the closest gap
  between two frequencies, or the smallest ``s`` (undamped); minus the largest growth rate
  (first-order problems), or where that is zero to rounding (a conservative system in first-order
  form) the closest gap between two frequencies -- an instability may hide between the grid points: the minimum is
  located by bounded minimisation (scipy's ``fminbound``, ported step for step) and the first
  unstable point it meets closes a bracket. For a frequency gap of an undamped problem, only
  when the two modes can merge: their first-order interaction ``B_lu B_ul`` in the biorthogonal
  eigenbasis of ``dA/dp`` is negative (modes decoupled by symmetry have none and simply cross).

Without ``all_crossings`` the scan of a problem stops at its first bracket; with it, it runs to
the end of the range and also closes each bubble from its far side (a regain of stability).
"""

from __future__ import annotations

import numpy as np
from ..._jit import njit, objmode

from ..classify import _indicators, _insert, _masks
from ..small_eigvec import _eigvector
from .layout import BRACKETS, CHUNK, DECOMPOSITIONS, EVALUATIONS, FORM, HI, LO, N_SCAN, PAIRS, START_UNSTABLE, STATUS
from .spectra import DECOMPOSITION, OK, PROVIDER_ERROR, VALUES, cache_new, operators_at, spectrum, workspace
from .tolerances import FLOOR, TOL_CLUSTER, TOL_DUPLICATE, TOL_MARGINAL, TOL_UNSTABLE

__all__ = ["scan_stack"]

_SQRT_EPS = float(np.sqrt(2.2e-16))
_GOLDEN = 0.5 * (3.0 - float(np.sqrt(5.0)))
_MAXFUN = 500


@njit(cache=True, error_model="numpy", _nrt=False)
def _classify(vals, lost, undamped, flags, ind, cplx, neg, work):
    """Stability flags and the bubble indicators ``(m, 2)`` from the eigenvalues ``vals (m, N)``.

    A load without a finite operator (``lost``: no static equilibrium) is unstable, indicators -inf.
    ``work (N,)`` is work space.
    """
    _masks(vals, undamped, TOL_UNSTABLE, TOL_CLUSTER, FLOOR, cplx, neg)
    _indicators(vals, undamped, cplx, neg, TOL_DUPLICATE, flags, ind, work)
    for i in range(len(lost)):
        if lost[i]:
            flags[i] = True
            ind[i, 0] = -np.inf
            ind[i, 1] = -np.inf


# -- scipy's bounded Brent minimisation, as steps (reverse communication) ------------------------
# state: a, b, fulc, nfc, xf, rat, e, fx, ffulc, fnfc, num, xatol, x, phase, xm, tol1, tol2
@njit(cache=True, error_model="numpy", _nrt=False)
def fmin_start(st, x1, x2, xatol):
    """Start ``_minimize_scalar_bounded`` on ``(x1, x2)``; returns the first point to evaluate."""
    st[0], st[1] = x1, x2
    st[2] = x1 + _GOLDEN * (x2 - x1)
    st[3] = st[4] = st[2]
    st[5] = st[6] = 0.0
    st[11] = xatol
    st[13] = 0.0
    st[12] = st[4]
    return st[12]


@njit(cache=True, error_model="numpy", _nrt=False)
def fmin_next(st, f):
    """Give ``f`` at the last point; returns ``(next point, more)`` (``more`` False: done)."""
    a, b, fulc, nfc, xf, rat, e, fx, ffulc, fnfc, num, xatol = st[0], st[1], st[2], st[3], st[4], st[5], st[6], \
        st[7], st[8], st[9], st[10], st[11]
    if st[13] == 0.0:
        fx = f
        num = 1.0
        ffulc = fnfc = fx
    else:
        fu, x = f, st[12]
        num += 1.0
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
    tol1 = _SQRT_EPS * abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    more = not (st[13] != 0.0 and num >= _MAXFUN) and abs(xf - xm) > (tol2 - 0.5 * (b - a))
    x = np.nan
    if more:
        golden = True
        if abs(e) > tol1:  # parabolic fit
            golden = False
            r = (xf - nfc) * (fx - ffulc)
            q = (xf - fulc) * (fx - fnfc)
            p = (xf - fulc) * q - (xf - nfc) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            r = e
            e = rat
            if (abs(p) < abs(0.5 * q * r)) and (p > q * (a - xf)) and (p < q * (b - xf)):
                rat = (p + 0.0) / q
                x = xf + rat
                if ((x - a) < tol2) or ((b - x) < tol2):
                    rat = tol1 * (np.sign(xm - xf) + ((xm - xf) == 0))
            else:
                golden = True
        if golden:
            e = a - xf if xf >= xm else b - xf
            rat = _GOLDEN * e
        si = np.sign(rat) + (rat == 0)
        x = xf + si * max(abs(rat), tol1)
    st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7], st[8], st[9], st[10] = \
        a, b, fulc, nfc, xf, rat, e, fx, ffulc, fnfc, num
    st[12], st[13] = x, 1.0
    return x, more


# -- attraction of two close frequencies ------------------------------------------------------------
def _lapack_complex_eigvals(a, out):
    out[...] = np.linalg.eigvals(a)


@njit(cache=True, error_model="numpy")
def _complex_eigvals(a, out):
    """Eigenvalues of a small complex matrix: closed forms up to order 2, else LAPACK."""
    k = a.shape[0]
    if k == 1:
        out[0] = a[0, 0]
    elif k == 2:
        tr = a[0, 0] + a[1, 1]
        det = a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]
        root = np.sqrt(tr * tr - 4.0 * det + 0j)
        out[0] = 0.5 * (tr + root)
        out[1] = 0.5 * (tr - root)
    else:
        with objmode():
            _lapack_complex_eigvals(a, out)


@njit(cache=True, error_model="numpy")
def closest_pair(vals, lower, upper):
    """The closest pair of distinct real ``s`` as masks ``lower``, ``upper`` (their duplicates in).

    Returns 1 (found), 0 (no distinct pair: nothing to merge) or -1 (already complex).
    """
    n = vals.shape[0]
    big = 0.0
    worst = 0.0
    for v in vals:
        big = max(big, abs(v))
        worst = max(worst, abs(v.imag))
    if worst > TOL_UNSTABLE * big:
        return -1
    re = np.empty(n)  # the real parts, sorted (an insertion sort: n is small, and numba's
    for i in range(n):  # np.sort is a quicksort compiled for this one call)
        _insert(re, i, vals[i].real)
    scale = 0.0
    for x in re:
        scale = max(scale, abs(x))
    jj = -1
    gap = np.inf
    for i in range(n - 1):
        d = re[i + 1] - re[i]
        if d >= TOL_DUPLICATE * scale and d < gap:
            gap = d
            jj = i
    if jj < 0:
        return 0
    for i in range(n):
        lower[i] = abs(vals[i].real - re[jj]) < TOL_DUPLICATE * scale
        upper[i] = abs(vals[i].real - re[jj + 1]) < TOL_DUPLICATE * scale
    return 1


@njit(cache=True, error_model="numpy")
def _pulled(inter, rate):
    """Whether an interaction eigenvalue pulls the pair together (below -1e-8 |rate|^2)."""
    norm = 1e-300
    for x in rate.flat:
        norm = max(norm, abs(x))
    for v in inter:
        if v.real < -1e-8 * norm * norm:
            return True
    return False


@njit(cache=True, error_model="numpy")
def attraction(vals, vecs, inv, lower, upper, rate):
    """Whether the pair ``lower``, ``upper`` can merge, from a full decomposition ``vals, vecs, inv``.

    Two nearby eigenvalues interact, to first order in the load, through the entries ``B_lu``,
    ``B_ul`` of ``rate = dA/dp`` in the biorthogonal eigenbasis; ``B_lu B_ul < 0`` pulls them
    together (a possible bubble), ``> 0`` makes them veer apart, zero (to rounding) means they do
    not interact. With repeated eigenvalues the interaction is the eigenvalues of the block
    product ``B_lu B_ul``.
    """
    n = vals.shape[0]
    low = np.flatnonzero(lower)
    up = np.flatnonzero(upper)
    kl, ku = len(low), len(up)
    b_lu = np.empty((kl, ku), dtype=np.complex128)
    b_ul = np.empty((ku, kl), dtype=np.complex128)
    for x in range(kl):
        for y in range(ku):
            s1 = 0j
            s2 = 0j
            for r in range(n):
                row1 = 0j
                row2 = 0j
                for c in range(n):
                    row1 += rate[r, c] * vecs[c, up[y]]
                    row2 += rate[r, c] * vecs[c, low[x]]
                s1 += inv[low[x], r] * row1
                s2 += inv[up[y], r] * row2
            b_lu[x, y] = s1
            b_ul[y, x] = s2
    inter = np.empty(kl, dtype=np.complex128)
    _complex_eigvals(b_lu @ b_ul, inter)
    return _pulled(inter, rate)


@njit(cache=True, error_model="numpy")
def simple_attraction(op, s_low, s_up, rate, w):
    """:func:`attraction` for two simple eigenvalues, from four inverse iterations (no decomposition).

    ``B_lu B_ul = (y_l^T R x_u)(y_u^T R x_l) / ((y_l^T x_l)(y_u^T x_u))`` with the right and left
    eigenvectors ``x``, ``y`` of ``op`` for the two real eigenvalues. Returns 1 or 0, and -1 where
    an inverse iteration fails (the caller decomposes instead). ``w`` is a work tuple.
    """
    n = op.shape[0]
    opt, b, piv, xl, xu, yl, yu = w
    norm = 0.0
    for i in range(n):
        row = 0.0
        for j in range(n):
            row += abs(op[i, j])
            opt[i, j] = op[j, i]
        norm = max(norm, row)
    if not (_eigvector(op, n, s_low, norm, b, piv, xl) and _eigvector(op, n, s_up, norm, b, piv, xu)
            and _eigvector(opt, n, s_low, norm, b, piv, yl) and _eigvector(opt, n, s_up, norm, b, piv, yu)):
        return -1
    lu = ul = ll = uu = 0.0
    for r in range(n):
        ru = 0.0
        rl = 0.0
        for c in range(n):
            ru += rate[r, c] * xu[c]
            rl += rate[r, c] * xl[c]
        lu += yl[r] * ru
        ul += yu[r] * rl
        ll += yl[r] * xl[r]
        uu += yu[r] * xu[r]
    inter = np.empty(1, dtype=np.complex128)
    inter[0] = lu * ul / (ll * uu)
    return 1 if _pulled(inter, rate) else 0


# -- the scan of every problem --------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def scan_stack(jobs, all_crossings, onsets, counts):
    """The brackets of every problem into ``onsets[j, :, LO:HI + 1]`` (stable load, unstable load).

    ``counts[j]``: the number of brackets, whether already unstable at the first grid point (then
    no brackets), the status (1: the provider failed) and the eigenproblems solved
    (:mod:`impstab.linear.engine.layout`).
    """
    n = jobs.a0.shape[1]
    count = len(jobs.ints)
    big_chunk = np.int64(1)  # an int64 from the start: workspace compiled for one type (see refine_stack)
    for j in range(count):
        big_chunk = max(big_chunk, jobs.ints[j, CHUNK])
    ws = workspace(n, big_chunk)
    cache = cache_new(n)
    npts_max = jobs.grids.shape[1]
    flags = np.zeros(npts_max, dtype=np.bool_)
    ind = np.zeros((npts_max, 2))
    one_flag = np.zeros(1, dtype=np.bool_)
    one_ind = np.zeros((1, 2))
    cplx = np.empty((big_chunk, n), dtype=np.bool_)
    neg = np.empty((big_chunk, n), dtype=np.bool_)
    st = np.zeros(17)
    probe = np.zeros(1)
    trio = np.zeros(3)
    ops3 = np.empty((3, n, n))
    vals_grid = np.empty((npts_max, n), dtype=np.complex128)
    lower = np.empty(n, dtype=np.bool_)
    upper = np.empty(n, dtype=np.bool_)
    pair_ws = (np.empty((n, n)), np.empty((n, n)), np.empty(n, dtype=np.int64), np.empty(n), np.empty(n),
               np.empty(n), np.empty(n))
    counter = np.zeros(3, dtype=np.int64)
    # the one-point views made once, not in the loops (each view made costs two atomic reference counts)
    vals1, lost1, cplx1, neg1, scratch = ws[10][:1], ws[11][:1], cplx[:1], neg[:1], ws[13]
    for j in range(count):
        cache[0][:] = np.nan  # a new problem: nothing cached
        counter[:] = 0
        npts = jobs.ints[j, N_SCAN] + 1
        grid = jobs.grids[j, :npts]
        chunk = max(jobs.ints[j, CHUNK], 1)
        undamped = jobs.ints[j, FORM] == 0
        known = 0
        found = 0
        failed = False
        jj = 1
        while jj < npts and not failed:
            for need in (jj + 1, min(jj + 2, npts)):
                if need == jj + 2 and (flags[jj] != flags[jj - 1] or flags[jj]):
                    break  # a change, or unstable at jj: the next point is not needed
                while known < need:  # classify the next chunk
                    stop = min(known + chunk, npts)
                    code, _ = spectrum(jobs, j, grid[known:stop], VALUES, cache, ws, counter)
                    if code == PROVIDER_ERROR:
                        failed = True
                        break
                    m = stop - known
                    _classify(ws[10][:m], ws[11][:m], undamped, flags[known:stop], ind[known:stop], cplx[:m], neg[:m], scratch)
                    for i in range(m):  # loops, not slice assignments: numba compiles a
                        for c in range(n):  # broadcast check (and its error message) for those
                            vals_grid[known + i, c] = ws[10][i, c]
                    known = stop
                if failed or flags[0]:
                    break
            if failed or flags[0]:
                break
            if flags[jj] != flags[jj - 1]:
                if flags[jj - 1]:
                    onsets[j, found, LO], onsets[j, found, HI] = grid[jj], grid[jj - 1]
                else:
                    onsets[j, found, LO], onsets[j, found, HI] = grid[jj - 1], grid[jj]
                found += 1
            elif jj + 1 < npts and not flags[jj] and not flags[jj + 1]:
                dips = (ind[jj, 0] < ind[jj - 1, 0] and ind[jj, 0] <= ind[jj + 1, 0],
                        ind[jj, 1] < ind[jj - 1, 1] and ind[jj, 1] <= ind[jj + 1, 1])
                # first order: where every growth rate is zero to rounding at the three points
                # (a conservative system), the growth rate's dips are noise and a bubble shows as
                # a close approach of two frequencies instead (column 1)
                marginal = not undamped and max(abs(ind[jj - 1, 0]), abs(ind[jj, 0]), abs(ind[jj + 1, 0])) <= TOL_MARGINAL
                hit = np.nan
                for column in (1, 0):
                    if not dips[column] or not np.isnan(hit):
                        continue
                    if not undamped and (column == 1) != marginal:
                        continue
                    if column == 0 and undamped:
                        # search only where the two closest frequencies attract
                        found_pair = closest_pair(vals_grid[jj], lower, upper)
                        if found_pair == 0:
                            continue
                        pull = 1
                        if found_pair == 1:
                            trio[0], trio[1], trio[2] = grid[jj - 1], grid[jj], grid[jj + 1]
                            if operators_at(jobs, j, trio, ops3) != 0:
                                failed = True
                                break
                            rate = (ops3[2] - ops3[0]) / (trio[2] - trio[0])
                            pull = -1
                            if lower.sum() == 1 and upper.sum() == 1:
                                s_low = vals_grid[jj, np.argmax(lower)].real
                                s_up = vals_grid[jj, np.argmax(upper)].real
                                pull = simple_attraction(ops3[1], s_low, s_up, rate, pair_ws)
                                counter[0] += 1
                                counter[2] += 1
                            if pull < 0:  # repeated eigenvalues, or no inverse iteration: decompose
                                code, s = spectrum(jobs, j, grid[jj:jj + 1], DECOMPOSITION, cache, ws, counter)
                                if code == PROVIDER_ERROR:
                                    failed = True
                                    break
                                pull = 1
                                if code == OK:
                                    rows = closest_pair(cache[2][s], lower, upper)
                                    pull = 0 if rows == 0 else (1 if rows < 0 else
                                                                (1 if attraction(cache[2][s], cache[3][s], cache[4][s],
                                                                                 lower, upper, rate) else 0))
                        if pull == 0:
                            continue
                    # the closest approach in (grid[jj-1], grid[jj+1]): the first unstable load met
                    probe[0] = fmin_start(st, grid[jj - 1], grid[jj + 1], (grid[jj + 1] - grid[jj - 1]) * 1e-9)
                    more = True
                    while more:
                        code, _ = spectrum(jobs, j, probe, VALUES, cache, ws, counter)
                        if code == PROVIDER_ERROR:
                            failed = True
                            break
                        _classify(vals1, lost1, undamped, one_flag, one_ind, cplx1, neg1, scratch)
                        if one_flag[0]:
                            hit = probe[0]
                            break
                        probe[0], more = fmin_next(st, one_ind[0, column])
                    if failed:
                        break
                if not np.isnan(hit):
                    # stable at grid[jj-1]; unstable at hit; stable again by grid[jj+1]
                    onsets[j, found, LO], onsets[j, found, HI] = grid[jj - 1], hit
                    found += 1
                    if all_crossings:
                        onsets[j, found, LO], onsets[j, found, HI] = grid[jj + 1], hit
                        found += 1
            if found and not all_crossings:
                break
            jj += 1
        counts[j, EVALUATIONS] += counter[0]
        counts[j, DECOMPOSITIONS] += counter[1]
        counts[j, PAIRS] += counter[2]
        counts[j, STATUS] = 1 if failed else 0
        counts[j, START_UNSTABLE] = 1 if (flags[0] and not failed) else 0
        counts[j, BRACKETS] = 0 if (failed or flags[0]) else found
        flags[:npts] = False
