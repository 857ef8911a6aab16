"""Exact refinement of every bracket (compiled), and the onset values there (THEORY 5).

A bracket ``(a, b)`` has ``a`` stable and ``b`` unstable by the classification, whose thresholds
only bracket. The onset itself is the root of a smooth indicator that crosses zero linearly:

* the cluster going unstable at ``b`` (two eigenvalues, or four where two symmetric planes merge
  at once) is followed across the bracket by its oblique spectral projector ``V_C W_C^H``
  (``W^H = V^-1``), which picks the ``k`` eigenvectors at a load lying most in it;
* undamped second-order problems (``s = omega^2``): ``Delta = k sum s_i^2 - (sum s_i)^2`` of the
  cluster, a symmetric function analytic in the load although the double root is defective
  (its eigenvalues carry sqrt(eps) noise, ``Delta`` only eps): positive while the cluster is real,
  negative once it is a complex pair; divergence: the cluster mean of ``s``;
* first-order problems (``lambda``): the largest real part of the cluster from its symmetric
  functions (``Re c + |Re sqrt(d)|`` with the mean ``c`` and variance ``d`` of the upper half, a
  Hopf crossing). Where the merging branches lay on the imaginary axis before (an undamped
  system in first-order form, an undamped gyroscopic one), the discriminant of the cluster's
  upper half, ``Re(m sum lambda^2 - (sum lambda)^2)``, which crosses zero linearly like
  ``Delta``; a branch leaving the axis through zero leaves like ``sqrt(p - p_c)``, and its onset
  is where it is off the axis by the classification tolerance (an error of order 1e-14).

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

from ..classify import _masks
from ..participation import participation_into
from .layout import (AFFINE, BISECTIONS, BRACKETS, DECOMPOSITIONS, DIRECTION, EVALUATIONS, FIRST, FORM, HI, KEY, KIND, LO, LOAD,
                     OMEGA, START_UNSTABLE, STATUS, WARNED)
from .scan import _classify
from .spectra import (DECOMPOSITION, FAILED, NOT_FINITE, OK, PROVIDER_ERROR, VALUES, cache_new, provided_weights,
                      spectrum, workspace)
from .tolerances import EPS, FLOOR, TOL_CLUSTER, TOL_COPIES, TOL_DUPLICATE, TOL_MARGINAL, TOL_REPEATED, TOL_UNSTABLE

__all__ = ["refine_stack"]

#: onset kinds; a limit point still to be located by the caller (its bracket is returned)
FLUTTER, DIVERGENCE, LIMIT = 1, 2, 3
_EPS4 = 4.0 * EPS


# -- the cluster ------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def _relative_real(v):
    mag = abs(v)
    return v.real / mag if mag > 0 else 0.0


@njit(cache=True, error_model="numpy", _nrt=False)
def unstable_cluster(vals, undamped, members, cplx, neg):
    """The cluster that is unstable into the mask ``members``; returns ``(found, unique, divergence)``.

    ``unique``: every unstable eigenvalue is in the cluster. ``cplx, neg`` are ``(1, n)`` work arrays.
    """
    n = vals.shape[0]
    _masks(vals.reshape(1, n), undamped, TOL_UNSTABLE, TOL_CLUSTER, FLOOR, cplx, neg)
    j0 = -1
    divergence = False
    if undamped:
        for i in range(n):
            if cplx[0, i] and (j0 < 0 or vals[i].real < vals[j0].real):
                j0 = i
        if j0 < 0:
            divergence = True
            for i in range(n):
                if neg[0, i] and (j0 < 0 or vals[i].real < vals[j0].real):
                    j0 = i
    else:
        best = -np.inf
        for i in range(n):
            if cplx[0, i] or neg[0, i]:
                r = _relative_real(vals[i])
                if j0 < 0 or r > best:
                    j0, best = i, r
        if j0 >= 0:
            divergence = neg[0, j0]
    if j0 < 0:
        members[:] = True
        return False, False, False
    ref = vals[j0]
    big = 0.0
    for v in vals:
        big = max(big, abs(v))
    tol = max(TOL_CLUSTER * abs(ref), FLOOR * big)
    unique = True
    for i in range(n):
        v = vals[i]
        close = abs(v - ref) <= tol or abs(v - ref.conjugate()) <= tol
        if not undamped and not divergence:
            # the decaying partner of a merged pair has the same frequency: keep it in the
            # cluster (before the merge the two modes span both branches)
            close = close or abs(abs(v.imag) - abs(ref.imag)) <= tol
        members[i] = close
        if (cplx[0, i] or neg[0, i]) and not close:
            unique = False
    return True, unique, divergence


@njit(cache=True, error_model="numpy", _nrt=False)
def projector(vecs, inv, members, vc, wc):
    """The cluster's oblique projector ``V_C W_C^H`` as ``vc (n, k)``, ``wc (k, n)``; returns ``k``."""
    n = vecs.shape[0]
    k = 0
    for c in range(n):
        if members[c]:
            for r in range(n):
                vc[r, k] = vecs[r, c]
                wc[k, r] = inv[c, r]
            k += 1
    return k


def _select_numpy(vals, vecs, inv, vc, wc, k, sel, share, work):
    """:func:`select` for interpreted runs: the same shares as two matrix products."""
    n = vecs.shape[0]
    proj = vc[:, :k] @ (wc[:k] @ vecs)
    share[:n] = (proj.real * proj.real + proj.imag * proj.imag).sum(axis=0)
    align_repeated(vals, vecs, inv, vc, wc, k, share, work)
    order = np.argsort(-share[:n], kind="mergesort")
    sel[:k] = order[:k]
    return share[order[k - 1]] > 0.25 and (n == k or share[order[k]] < 0.25)


@njit(cache=True, error_model="numpy", _nrt=False)
def _next_largest(share, n, sel, i):
    """The column with the largest share that is not in ``sel[:i]``, the lowest on ties (the order of
    a stable sort by decreasing share; NaN last)."""
    best = -1
    for c in range(n):
        taken = False
        for x in range(i):
            taken = taken or sel[x] == c
        if not taken and (best < 0 or share[c] > share[best] or (np.isnan(share[best]) and not np.isnan(share[c]))):
            best = c
    return best


@njit(cache=True, error_model="numpy", _nrt=False)
def _projected(vc, wc, k, v, t):
    """``t[:k] = W_C^H v`` (the cluster coordinates of the column ``v``)."""
    n = v.shape[0]
    for i in range(k):
        s = 0j
        for r in range(n):
            s += wc[i, r] * v[r]
        t[i] = s


@njit(cache=True, error_model="numpy", _nrt=False)
def _share(vc, k, t):
    """``|V_C t|^2`` (the share of a unit column whose cluster coordinates are ``t``)."""
    total = 0.0
    for r in range(vc.shape[0]):
        y = 0j
        for i in range(k):
            y += vc[r, i] * t[i]
        total += y.real * y.real + y.imag * y.imag
    return total


@njit(cache=True, error_model="numpy", _nrt=False)
def _coordinate(inv, row, vc, k, t):
    """``w_row^H V_C t``: the component along column ``row`` of the decomposition of ``V_C t``."""
    acc = 0j
    for r in range(vc.shape[0]):
        y = 0j
        for i in range(k):
            y += vc[r, i] * t[i]
        acc += inv[row, r] * y
    return acc


@njit(cache=True, error_model="numpy", _nrt=False)
def align_repeated(vals, vecs, inv, vc, wc, k, share, work):
    """Turn the basis of each repeated eigenvalue's eigenspace toward the cluster, in place.

    A repeated eigenvalue (two of ``vals`` within :data:`TOL_REPEATED` of the largest magnitude)
    has no preferred eigenvectors: any basis of its eigenspace is one, and where the cluster holds
    only one combination of them (a mode merging with one plane of a symmetric layout's doubled
    pair) the shares of the two columns depend on the basis the decomposition returned. The
    cluster's projector ``P = V_C W_C^H`` maps the eigenspace ``E`` (nearly) into itself; in the
    columns' coordinates it is the 2 x 2 matrix ``M = W_E^H P V_E``, whose eigenvalues (near 1
    and 0 where the cluster holds one combination) and eigenvectors ``x`` do not depend on the
    basis: ``V_E -> V_E T`` takes ``M`` to ``T^-1 M T``. The two columns are replaced by the unit
    vectors along ``V_E x`` (the one nearer the cluster first) and the two rows of ``inv`` by the
    matching rows of the inverse, so that ``vecs`` and ``inv`` stay one decomposition, and their
    shares are computed again. Left as they are: a pair that ``P`` does not split (eigenvalues
    of ``M`` within 1e-3: all of ``E`` in the cluster, or none of it), a pair whose columns are
    nearly parallel (cosine above 0.99995: a defective pair, not a semisimple one), and groups
    of more than two. ``work (3, n)`` complex is work space.
    """
    n = vecs.shape[0]
    scale = 0.0
    for i in range(n):
        scale = max(scale, abs(vals[i]))
    t1, t2 = work[0], work[1]
    for c1 in range(n):
        c2 = -1
        skip = False
        for c in range(n):
            if c != c1 and abs(vals[c] - vals[c1]) <= TOL_REPEATED * scale:
                skip = skip or c2 >= 0 or c < c1
                c2 = c
        if c2 < 0 or skip:  # not repeated, a group of more than two, or a pair already turned
            continue
        beta = 0j
        for r in range(n):
            beta += vecs[r, c1].conjugate() * vecs[r, c2]
        if not abs(beta) < 0.99995:
            continue
        _projected(vc, wc, k, vecs[:, c1], t1)
        _projected(vc, wc, k, vecs[:, c2], t2)
        m11, m12 = _coordinate(inv, c1, vc, k, t1), _coordinate(inv, c1, vc, k, t2)
        m21, m22 = _coordinate(inv, c2, vc, k, t1), _coordinate(inv, c2, vc, k, t2)
        half = 0.5 * (m11 + m22)
        root = np.sqrt(half * half - (m11 * m22 - m12 * m21))
        if root.real < 0.0:
            root = -root
        if not abs(root) > 0.5e-3:
            continue
        # eigenvectors of M for mu = half +- root: (m12, mu - m11) or (mu - m22, m21), the larger
        mu1, mu2 = half + root, half - root
        p1, q1 = m12, mu1 - m11
        if abs(mu1 - m22) + abs(m21) > abs(p1) + abs(q1):
            p1, q1 = mu1 - m22, m21
        p2, q2 = m12, mu2 - m11
        if abs(mu2 - m22) + abs(m21) > abs(p2) + abs(q2):
            p2, q2 = mu2 - m22, m21
        # the new columns y_i = p_i v1 + q_i v2, normalized
        n1 = 0.0
        n2 = 0.0
        for r in range(n):
            y1 = p1 * vecs[r, c1] + q1 * vecs[r, c2]
            y2 = p2 * vecs[r, c1] + q2 * vecs[r, c2]
            n1 += y1.real * y1.real + y1.imag * y1.imag
            n2 += y2.real * y2.real + y2.imag * y2.imag
        n1, n2 = sqrt(n1), sqrt(n2)
        det = (p1 * q2 - p2 * q1) / (n1 * n2)
        if not abs(det) > 1e-2:
            continue
        for r in range(n):
            v1, v2 = vecs[r, c1], vecs[r, c2]
            vecs[r, c1] = (p1 * v1 + q1 * v2) / n1
            vecs[r, c2] = (p2 * v1 + q2 * v2) / n2
        # rows: D X^-1 W_E^H with X = [[p1, p2], [q1, q2]], D = diag(n1, n2)
        det = p1 * q2 - p2 * q1
        for col in range(n):
            w1, w2 = inv[c1, col], inv[c2, col]
            inv[c1, col] = n1 * (q2 * w1 - p2 * w2) / det
            inv[c2, col] = n2 * (-q1 * w1 + p1 * w2) / det
        _projected(vc, wc, k, vecs[:, c1], t1)
        share[c1] = _share(vc, k, t1)
        _projected(vc, wc, k, vecs[:, c2], t2)
        share[c2] = _share(vc, k, t2)


@njit(cache=True, error_model="numpy", interpreted=_select_numpy, _nrt=False)
def select(vals, vecs, inv, vc, wc, k, sel, share, work):
    """The ``k`` eigenvectors lying most in the cluster subspace into ``sel[:k]``; whether clear.

    ``vecs`` are unit columns; the share of each is the squared norm of its oblique projection
    onto the cluster subspace; clear when the ``k``-th share exceeds 1/4 and the next is below.
    The basis of a repeated eigenvalue's eigenspace is first turned toward the cluster
    (:func:`align_repeated`, which rewrites those columns of ``vecs`` and rows of ``inv``), so
    that the choice does not depend on the basis the decomposition returned. ``share (n,)``
    receives the shares, ``work (3, n)`` complex is work space. The ``k`` columns are picked one
    by one (the cluster is small), in the order of a stable sort by decreasing share.
    """
    n = vecs.shape[0]
    t = work[0]
    for c in range(n):
        _projected(vc, wc, k, vecs[:, c], t)
        share[c] = _share(vc, k, t)
    align_repeated(vals, vecs, inv, vc, wc, k, share, work)
    for i in range(k):
        sel[i] = _next_largest(share, n, sel, i)
    if not share[sel[k - 1]] > 0.25:
        return False
    if n == k:
        return True
    return share[_next_largest(share, n, sel, k)] < 0.25


@njit(cache=True, error_model="numpy", _nrt=False)
def _pair_growth(v, k):
    """Largest real part of a cluster (upper half plane), from its symmetric functions.

    For the upper-half members (a pair, possibly each doubled by symmetry) ``c = mean`` and
    ``d = mean((lambda - c)^2)`` are analytic in the load even where the pair is defective, so
    ``Re c + |Re sqrt(d)|`` keeps its accuracy there; for a single eigenvalue it is ``Re lambda``.
    """
    upper = False
    for i in range(k):
        upper = upper or v[i].imag > 0
    c = 0j
    m = 0
    for i in range(k):
        if not upper or v[i].imag >= 0:
            c += v[i]
            m += 1
    c /= m
    d = 0j
    for i in range(k):
        if not upper or v[i].imag >= 0:
            d += (v[i] - c) ** 2
    d /= m
    return c.real + abs(np.sqrt(d).real)


@njit(cache=True, error_model="numpy", _nrt=False)
def indicator(vals, vecs, inv, a1, undamped, vc, wc, k, divergence, target, derivative, sel, share, work,
              coalesce=False):
    """``(f, df, clear)``: the exact indicator of the cluster in the decomposition, its derivative.

    ``df`` (affine problems, ``derivative``) from the eigenvalue derivatives ``W_C A1 V_C``;
    ``clear`` False where the cluster is not found clearly (then the values mean nothing).
    ``coalesce`` (first-order problems whose crossing branch lay on the imaginary axis): the
    discriminant of the cluster's upper half, ``Re(m sum lambda^2 - (sum lambda)^2)``, negative
    while two frequencies ``i w_1, i w_2`` are distinct, positive once they have split into
    ``+-a + i b``, and like the undamped ``Delta`` analytic through the defective double root.
    ``work (3, n)`` complex is work space.
    """
    if not select(vals, vecs, inv, vc, wc, k, sel, share, work):
        return 0.0, 0.0, False
    v, b = work[1], work[2]
    for i in range(k):
        v[i] = vals[sel[i]]
    jj = 0
    # the members counted: all, or with ``coalesce`` the upper half (where there is one)
    upper = False
    if coalesce:
        for i in range(k):
            upper = upper or v[i].imag > 0
    if undamped or coalesce:
        s1 = 0j
        s2 = 0j
        m = 0
        for i in range(k):
            if not upper or v[i].imag >= 0:
                s1 += v[i]
                s2 += v[i] * v[i]
                m += 1
        f = s1.real / k if divergence else (m * s2 - s1 * s1).real
    else:
        best = -np.inf
        for i in range(k):
            r = _relative_real(v[i])
            if r > best:
                jj, best = i, r
        f = _pair_growth(v, k) - target * abs(v[jj])
    if not derivative:
        return f, 0.0, True
    n = vecs.shape[0]
    for i in range(k):
        c0 = sel[i]
        acc = 0j
        for r in range(n):
            w = inv[c0, r]
            if w == 0:
                continue
            row = 0j
            for c in range(n):
                row += a1[r, c] * vecs[c, c0]
            acc += w * row
        b[i] = acc
    if not (undamped or coalesce):
        if k <= 2:
            return f, b[jj].real, True
        # a larger cluster: copies of one pair (identical planes of a symmetric layout) have the
        # derivative of their mean, the trace of the upper half's block of W_C A1 V_C (invariant
        # under the choice of basis in the repeated eigenspace); anything else: none (NaN)
        upper = False
        for i in range(k):
            upper = upper or v[i].imag > 0
        c = 0j
        cb = 0j
        m = 0
        for i in range(k):
            if not upper or v[i].imag >= 0:
                c += v[i]
                cb += b[i]
                m += 1
        c /= m
        for i in range(k):
            if (not upper or v[i].imag >= 0) and abs(v[i] - c) > TOL_COPIES * abs(c):
                return f, np.nan, True
        return f, cb.real / m, True
    if divergence:
        df = 0.0
        for i in range(k):
            df += b[i].real
        return f, df / k, True
    s1 = 0j
    sb = 0j
    svb = 0j
    m = 0
    for i in range(k):
        if not upper or v[i].imag >= 0:
            s1 += v[i]
            sb += b[i]
            svb += v[i] * b[i]
            m += 1
    return f, (2 * m * svb - 2 * s1 * sb).real, True


# -- roots, as steps (reverse communication) ------------------------------------------------------
@njit(cache=True, error_model="numpy")
def hermite_root(a, b, fa, fb, da, db):
    """A first point for Newton: the root in ``(a, b)`` of the cubic with ``f`` and ``f'`` at both ends.

    Its error is of order ``h^4`` against the secant's ``h^2``; the secant point where the slopes
    are not known or the cubic has no root inside.
    """
    secant = a - fa * (b - a) / (fb - fa)
    if np.isnan(da) or np.isnan(db):
        return secant
    h = b - a
    # the cubic in t = (x - a) / h with value and slope (times h) at t = 0 and 1
    c0, c1 = fa, da * h
    c2 = 3 * (fb - fa) - (2 * da + db) * h
    c3 = 2 * (fa - fb) + (da + db) * h
    t = (secant - a) / h
    lo, hi = 0.0, 1.0
    for _ in range(30):  # safeguarded Newton on the cubic (a few scalar steps)
        f = c0 + t * (c1 + t * (c2 + t * c3))
        if f == 0.0:
            break
        if (f > 0) == (fa > 0):
            lo = t
        else:
            hi = t
        d = c1 + t * (2 * c2 + 3 * t * c3)
        step = f / d if d != 0.0 else np.inf
        new = t - step
        if not (lo < new < hi):
            new = 0.5 * (lo + hi)
        if abs(new - t) <= 1e-15:
            t = new
            break
        t = new
    x = a + t * h
    return x if min(a, b) < x < max(a, b) else secant


@njit(cache=True, error_model="numpy", _nrt=False)
def newton_step(st, p, f, df):
    """Bracketed Newton (bisection guard) after ``f, df`` at ``p``; returns ``(next, done)``.

    ``st = (lo, hi, f_lo, last Newton step or NaN)``: the bracket, updated here. Done when the
    step is below 4 eps, or lands on an end of the bracket, or when the convergence seen so far
    is clearly quadratic (the step shrank by 1e4 at least) and predicts the error of the next
    point below eps: the error after a step ``d`` is ``C d^2``, ``C`` measured as
    ``|d| / d_prev^2`` from the last two steps. (The indicators cross zero linearly: simple roots.)
    """
    if f == 0.0:
        return p, True
    if np.sign(f) == np.sign(st[2]):
        st[0], st[2] = p, f
    else:
        st[1] = p
    lo, hi = st[0], st[1]
    new = p - f / df if df != 0.0 else np.inf
    prev = st[3]
    st[3] = new - p
    if not (min(lo, hi) < new < max(lo, hi)):
        new = 0.5 * (lo + hi)
        st[3] = np.nan
    step = abs(new - p)
    if step <= _EPS4 * abs(p) or new == lo or new == hi:
        return new, True
    quadratic = not np.isnan(prev) and not np.isnan(st[3]) and step <= 1e-3 * abs(prev)
    return new, quadratic and (step / (prev * prev)) * step * step <= EPS * abs(new)


@njit(cache=True, error_model="numpy", _nrt=False)
def brent_step(st, f):
    """scipy's ``brentq`` (xtol 1e-300, rtol 4 eps) as steps; returns ``(x, done)``.

    ``st = (xpre, xcur, xblk, fpre, fcur, fblk, spre, scur)``; ``f`` is the value at the last
    point returned (NaN on the first call, which starts from ``xpre, xcur, fpre, fcur``).
    """
    xtol, rtol = 1e-300, _EPS4
    xpre, xcur, xblk, fpre, fcur, fblk, spre, scur = st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7]
    if not np.isnan(f):
        fcur = f
    if fpre != 0 and fcur != 0 and (np.signbit(fpre) != np.signbit(fcur)):
        xblk, fblk = xpre, fpre
        spre = scur = xcur - xpre
    if abs(fblk) < abs(fcur):
        xpre, xcur, xblk = xcur, xblk, xcur
        fpre, fcur, fblk = fcur, fblk, fcur
    delta = (xtol + rtol * abs(xcur)) / 2
    sbis = (xblk - xcur) / 2
    done = fcur == 0 or abs(sbis) < delta
    if not done:
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # interpolate
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # extrapolate
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):
                spre, scur = scur, stry
            else:
                spre, scur = sbis, sbis
        else:
            spre, scur = sbis, sbis
        xpre, fpre = xcur, fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0 else -delta
    st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7] = xpre, xcur, xblk, fpre, fcur, fblk, spre, scur
    return xcur, done


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
