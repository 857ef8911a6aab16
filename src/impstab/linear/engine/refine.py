"""Exact refinement of every bracket (compiled), and the onset values there (THEORY 5).

A bracket ``(a, b)`` has ``a`` stable and ``b`` unstable by the classification, whose thresholds
only bracket. The onset itself is the root of a smooth indicator that crosses zero linearly: the
cluster going unstable at ``b`` is followed across the bracket by its spectral projector, and its
indicator (:mod:`.cluster`) is solved by the steps of :mod:`.roots`. A branch leaving the
imaginary axis through zero leaves like ``sqrt(p - p_c)``; its onset is where it is off the axis
by the classification tolerance (an error of order 1e-14).

Affine problems use the exact derivative of the indicator (eigenvalue derivatives
``W_C A1 V_C``) in a bracketed Newton iteration from the root of the Hermite cubic through the
indicator and its slope at both ends (for a first-order cluster of more than one pair, where
its upper half is copies of one eigenvalue, as the identical planes of a symmetric layout give:
the trace of that half's block, the derivative of their mean); the others scipy's Brent method
(``brentq``, ported as steps). Where the cluster at ``b`` is not clearly one at ``a``, the bracket is halved
on the classification and tried again; where the indicator shows ``a`` already past the onset,
``a`` steps back by the bracket width. Where the exact route cannot be used at all, the bracket
is narrowed on the classification alone and the result carries a warning.
"""

from __future__ import annotations

from math import sqrt

import numpy as np
from ..._jit import njit

from ..participation import participation_into
from .cluster import _relative_real, indicator, projector, select, unstable_cluster
from .layout import (AFFINE, BISECTIONS, BRACKETS, DECOMPOSITIONS, DIRECTION, EVALUATIONS, FIRST, FORM, HI, KEY, KIND, LO, LOAD,
                     OMEGA, START_UNSTABLE, STATUS, WARNED)
from .roots import brent_step, hermite_root, newton_step
from .scan import _classify
from .spectra import (DECOMPOSITION, NOT_FINITE, OK, PROVIDER_ERROR, VALUES, cache_new, provided_weights,
                      spectrum, workspace)
from .tolerances import TOL_DUPLICATE, TOL_MARGINAL, TOL_UNSTABLE

__all__ = ["refine_stack"]

#: onset kinds; a limit point still to be located by the caller (its bracket is returned)
FLUTTER, DIVERGENCE, LIMIT = 1, 2, 3


# -- onset values -------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def onset_values(vals, vecs, members, k, undamped, divergence, shapes, values, weights, mode, part, coalesce=False):
    """Kind and omega of the onset, its mode (largest component 1) and participation.

    ``vals, vecs``: the decomposition at the onset, ``members[:k]`` the cluster's columns;
    ``shapes (n, k), values (k,)``: the distinct modes the participation is taken from. Where two
    frequencies merge (undamped, or ``coalesce``: first order on the imaginary axis) omega comes
    from the cluster's mean, a symmetric function: the individual eigenvalues of the defective
    double root carry sqrt(eps) noise, their mean only eps.
    """
    n = mode.shape[0]
    lead = members[0]
    if undamped:
        omega = 0.0
        if not divergence:
            mean = 0.0
            for i in range(k):
                mean += vals[members[i]].real
                if abs(vals[members[i]].imag) > abs(vals[lead].imag):
                    lead = members[i]
            omega = sqrt(max(mean / k, 0.0))
    else:
        for i in range(k):
            if vals[members[i]].real > vals[lead].real:
                lead = members[i]
        omega = 0.0 if divergence else abs(vals[lead].imag)
        if coalesce:
            mean = 0.0
            m = 0
            for i in range(k):
                if vals[members[i]].imag >= 0:
                    mean += vals[members[i]].imag
                    m += 1
            omega = mean / max(m, 1)
    big = 0
    for r in range(n):
        mode[r] = vecs[r, lead]
        if abs(mode[r]) > abs(mode[big]):
            big = r
    scale = mode[big].conjugate() / (abs(mode[big]) ** 2)
    for r in range(n):
        mode[r] *= scale
    # each distinct mode of the cluster weighs equally in the participation
    participation_into(shapes, values, np.ones(k, dtype=np.bool_), weights, TOL_DUPLICATE, part)
    return (DIVERGENCE if divergence else FLUTTER), omega


@njit(cache=True, error_model="numpy")
def _take(vals, vecs, cols, k, n):
    """``(vecs[:n, cols[:k]], vals[cols[:k]])``, new arrays."""
    shapes = np.empty((n, k), dtype=np.complex128)
    values = np.empty(k, dtype=np.complex128)
    for i in range(k):
        values[i] = vals[cols[i]]
        for r in range(n):
            shapes[r, i] = vecs[r, cols[i]]
    return shapes, values


# -- every bracket of every problem ---------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def refine_stack(jobs, onsets, mode_out, part_out, counts):
    """Refine every bracket of every problem: the onsets into ``onsets``, the first loss's mode
    and participation into ``mode_out``, ``part_out`` (:mod:`impstab.linear.engine.layout`).

    A limit point gets kind :data:`LIMIT` and its final bracket in ``LO, HI``, for the caller to
    locate. A problem unstable at the start gets its onset values there in row 0.
    """
    n = jobs.a0.shape[1]
    n_dof = mode_out.shape[1]
    # counts and flags passed to compiled callees are int64 / bool variables, not literals: numba
    # compiles a callee once per argument type, and ``Literal[int](0)`` or ``Literal[bool](True)``
    # (a constant, or a variable's first value while its type is being inferred) is one of its own.
    # Except ``spectrum``'s ``vectors``: one specialisation per value, each without the other branch,
    # is what its every-eigenproblem calls want
    ws = workspace(n, np.int64(1))
    with_slope, without_slope = np.bool_(True), np.bool_(False)
    cache = cache_new(n)
    vc = np.empty((n, n), dtype=np.complex128)
    wc = np.empty((n, n), dtype=np.complex128)
    sel = np.empty(n, dtype=np.int64)
    cols = np.empty(n, dtype=np.int64)
    share = np.empty(n)
    work = np.empty((3, n), dtype=np.complex128)
    members = np.empty(n, dtype=np.bool_)
    cplx = np.empty((1, n), dtype=np.bool_)
    neg = np.empty((1, n), dtype=np.bool_)
    one_flag = np.zeros(1, dtype=np.bool_)
    one_ind = np.zeros((1, 2))
    weights = np.empty(n_dof)
    mode = np.empty(n_dof, dtype=np.complex128)
    part = np.empty(n_dof)
    point = np.zeros(1)
    st = np.zeros(8)
    ev = np.zeros(3, dtype=np.int64)
    # the cache's arrays and the one-point views taken once, not in the loops (each taken costs two
    # atomic reference counts)
    c_vals, c_vecs, c_inv = cache[2], cache[3], cache[4]
    vals1, lost1, scratch = ws[10][:1], ws[11][:1], ws[13]
    for j in range(len(jobs.ints)):
        if counts[j, STATUS] != 0:
            continue
        cache[0][:] = np.nan
        ev[:] = 0
        undamped = jobs.ints[j, FORM] == 0
        affine = jobs.ints[j, AFFINE] == 1
        start_unstable = counts[j, START_UNSTABLE] == 1
        lo_lim, hi_lim = jobs.span[j, 0], jobs.span[j, 1]
        a1 = jobs.a1[j]
        failed = False
        first = -1
        tasks = 1 if start_unstable else counts[j, BRACKETS]
        for t in range(tasks):
            if start_unstable:
                a, b = np.nan, jobs.grids[j, 0]
            else:
                a, b = onsets[j, t, LO], onsets[j, t, HI]
            onsets[j, t, DIRECTION] = 1.0 if not a > b else -1.0
            root = np.nan
            warned = False
            limit = False
            divergence = False
            k = np.int64(0)
            shapes = np.empty((n_dof, 1), dtype=np.complex128)
            values = np.empty(1, dtype=np.complex128)
            vals_r = np.empty(n, dtype=np.complex128)
            vecs_r = np.empty((n, n), dtype=np.complex128)
            last = np.nan
            coalesce = False
            steps = 0 if start_unstable else 200
            for _ in range(steps):
                point[0] = b
                code_b, sb = spectrum(jobs, j, point, DECOMPOSITION, cache, ws, ev)
                if code_b == PROVIDER_ERROR:
                    failed = True
                    break
                if code_b == NOT_FINITE:
                    # no static equilibrium at b: close in on the limit point
                    mid = 0.5 * (a + b)
                    if mid == a or mid == b:
                        limit = True
                        break
                    point[0] = mid
                    if spectrum(jobs, j, point, VALUES, cache, ws, ev)[0] == PROVIDER_ERROR:
                        failed = True
                        break
                    _classify(vals1, lost1, undamped, one_flag, one_ind, cplx, neg, scratch)
                    if one_flag[0]:
                        b = mid
                    else:
                        a = mid
                    continue
                found, unique, divergence = unstable_cluster(c_vals[sb], undamped, members, cplx, neg)
                step_back = False
                if found and code_b == OK:
                    k = projector(c_vecs[sb], c_inv[sb], members, vc, wc)
                    point[0] = a
                    code_a, sa = spectrum(jobs, j, point, DECOMPOSITION, cache, ws, ev)
                    if code_a == PROVIDER_ERROR:
                        failed = True
                        break
                    ok_a = code_a != NOT_FINITE and select(c_vals[sa], c_vecs[sa], c_inv[sa], vc, wc, k, sel, share, work)
                    while unique and ok_a:  # the exact route (a loop only to leave it early)
                        target = 0.0
                        coalesce = False
                        if not undamped:
                            # on the imaginary axis (to rounding) at a and a step before it? Then two
                            # frequencies merge there (the discriminant of the cluster's upper half
                            # crosses zero linearly), or a branch leaves through zero
                            marginal = True
                            for p in (a, min(max(a + (a - b), lo_lim), hi_lim)):
                                point[0] = p
                                code, s = spectrum(jobs, j, point, DECOMPOSITION, cache, ws, ev)
                                if code == PROVIDER_ERROR:
                                    failed = True
                                    break
                                if code == NOT_FINITE or not select(c_vals[s], c_vecs[s], c_inv[s], vc, wc, k, sel, share, work):
                                    marginal = False
                                    break
                                for i in range(k):
                                    if abs(_relative_real(c_vals[s][sel[i]])) > TOL_MARGINAL:
                                        marginal = False
                                if not marginal:
                                    break
                            if failed:
                                break
                            if marginal and divergence:
                                # the branch leaves the axis through zero like sqrt(p - p_c): the onset
                                # is where it is off the axis by TOL_UNSTABLE
                                target = TOL_UNSTABLE
                            coalesce = marginal and not divergence
                        # Newton where the indicator's derivative is exact: a pair, the undamped and
                        # the coalescence forms, and (decided at both ends) copies of one pair
                        newton = affine and target == 0.0 and (undamped or k <= 2 or coalesce)
                        copies = affine and target == 0.0 and not newton
                        fab = np.zeros(2)
                        dfab = np.full(2, np.nan)
                        clear = True
                        for e in range(2):
                            point[0] = a if e == 0 else b
                            code, s = spectrum(jobs, j, point, DECOMPOSITION, cache, ws, ev)
                            if code == PROVIDER_ERROR:
                                failed = True
                                break
                            slope = (newton or copies) and code == OK
                            f, df, ok = indicator(c_vals[s], c_vecs[s], c_inv[s], a1, undamped, vc, wc, k,
                                                  divergence, target, slope, sel, share, work, coalesce)
                            clear = clear and code != NOT_FINITE and ok
                            fab[e] = f
                            if slope:
                                dfab[e] = df
                        if failed or not clear:
                            break
                        fa, fb = fab[0], fab[1]
                        if copies and not (np.isnan(dfab[0]) or np.isnan(dfab[1])):
                            newton = True
                        if fa == 0.0:
                            root = a
                        elif np.sign(fa) == np.sign(fb):
                            step_back = True
                            break
                        elif newton:
                            st[0], st[1], st[2], st[3] = a, b, fa, np.nan
                            p = hermite_root(a, b, fa, fb, dfab[0], dfab[1])
                            for _ in range(100):
                                point[0] = last = p
                                code, s = spectrum(jobs, j, point, DECOMPOSITION, cache, ws, ev)
                                if code == PROVIDER_ERROR:
                                    failed = True
                                    break
                                if code != OK:
                                    break
                                f, df, ok = indicator(c_vals[s], c_vecs[s], c_inv[s], a1, undamped, vc, wc,
                                                      k, divergence, 0.0, with_slope, sel, share, work, coalesce)
                                if not ok:
                                    break
                                p, done = newton_step(st, p, f, df)
                                if done:
                                    root = p
                                    break
                        else:
                            st[0], st[1], st[3], st[4] = a, b, fa, fb
                            st[2] = st[5] = st[6] = st[7] = 0.0
                            f = np.nan
                            for _ in range(200):
                                x, done = brent_step(st, f)
                                if done:
                                    root = x
                                    break
                                point[0] = last = x
                                code, s = spectrum(jobs, j, point, DECOMPOSITION, cache, ws, ev)
                                if code == PROVIDER_ERROR:
                                    failed = True
                                    break
                                f, _, ok = indicator(c_vals[s], c_vecs[s], c_inv[s], a1, undamped, vc, wc, k,
                                                     divergence, target, without_slope, sel, share, work, coalesce)
                                if code == NOT_FINITE or not ok:
                                    break
                        break
                    if failed:
                        break
                    if not np.isnan(root):
                        # the onset values: cluster at the root (or at the last point evaluated, where
                        # that is within 1e-12 of it); where frequencies merge (undamped, or on the
                        # imaginary axis) the distinct modes come from a (stable side): at the root
                        # they are one defective mode
                        point[0] = last if abs(root - last) <= 1e-12 * abs(root) else root
                        code, s = spectrum(jobs, j, point, DECOMPOSITION, cache, ws, ev)
                        if code == PROVIDER_ERROR:
                            failed = True
                            break
                        select(c_vals[s], c_vecs[s], c_inv[s], vc, wc, k, sel, share, work)
                        for i in range(k):  # loops, not slice assignments (see scan_stack)
                            cols[i] = sel[i]
                        shapes, values = _take(c_vals[s], c_vecs[s], cols, k, n_dof)
                        vals_r, vecs_r = c_vals[s].copy(), c_vecs[s].copy()
                        if undamped or coalesce:
                            point[0] = a
                            code, s = spectrum(jobs, j, point, DECOMPOSITION, cache, ws, ev)
                            if code == PROVIDER_ERROR:
                                failed = True
                                break
                            if code != NOT_FINITE and select(c_vals[s], c_vecs[s], c_inv[s], vc, wc, k, sel, share, work):
                                shapes, values = _take(c_vals[s], c_vecs[s], sel, k, n_dof)
                        break
                    if step_back:
                        new_a = min(max(a + (a - b), lo_lim), hi_lim)
                        if new_a == a:
                            break
                        a = new_a
                        continue
                mid = 0.5 * (a + b)
                if mid == a or mid == b:
                    break
                point[0] = mid
                if spectrum(jobs, j, point, VALUES, cache, ws, ev)[0] == PROVIDER_ERROR:
                    failed = True
                    break
                _classify(vals1, lost1, undamped, one_flag, one_ind, cplx, neg, scratch)
                counts[j, BISECTIONS] += 1
                if one_flag[0]:
                    b = mid
                else:
                    a = mid
            if failed:
                break
            if limit:
                onsets[j, t, KIND], onsets[j, t, LOAD] = LIMIT, b
                onsets[j, t, LO], onsets[j, t, HI] = a, b
                continue
            if np.isnan(root):
                # the exact indicator could not be used (or the problem is unstable at the start):
                # the onset values at b, from its unstable cluster
                warned = not start_unstable
                coalesce = False
                root = b
                point[0] = b
                code, s = spectrum(jobs, j, point, DECOMPOSITION, cache, ws, ev)
                if code == PROVIDER_ERROR:
                    failed = True
                    break
                found, _, divergence = unstable_cluster(c_vals[s], undamped, members, cplx, neg)
                k = np.int64(0)
                for i in range(n):
                    if members[i]:
                        cols[k] = i
                        k += 1
                shapes, values = _take(c_vals[s], c_vecs[s], cols, k, n_dof)
                vals_r, vecs_r = c_vals[s].copy(), c_vecs[s].copy()
            if affine or jobs.ints[j, KEY] < 0:
                for i in range(len(weights)):
                    weights[i] = jobs.weights[j, i]
            elif provided_weights(jobs.ints[j, KEY], root, weights) != 0:
                failed = True
                break
            kind, omega = onset_values(vals_r, vecs_r, cols, k, undamped, divergence, shapes, values, weights, mode,
                                       part, coalesce)
            onsets[j, t, LOAD], onsets[j, t, KIND], onsets[j, t, OMEGA] = root, kind, omega
            onsets[j, t, WARNED] = 1.0 if warned else 0.0
            if start_unstable or (a < b and (first < 0 or root < onsets[j, first, LOAD])):
                first = t
                for i in range(mode_out.shape[1]):
                    mode_out[j, i] = mode[i]
                for i in range(part_out.shape[1]):
                    part_out[j, i] = part[i]
        counts[j, EVALUATIONS] += ev[0]
        counts[j, DECOMPOSITIONS] += ev[1]
        counts[j, FIRST] = first
        if failed:
            counts[j, STATUS] = 1
