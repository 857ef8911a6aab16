"""The cluster of eigenvalues going unstable, followed across a bracket (compiled; THEORY 5).

At the unstable end ``b`` of a bracket the cluster is the eigenvalue going unstable and those
within :data:`~.tolerances.TOL_CLUSTER` of it (two, or four where two symmetric planes merge at
once): :func:`unstable_cluster`. Its oblique spectral projector ``P = V_C W_C^H`` (``W^H =
V^-1``, :func:`projector`) follows it to any other load, where :func:`select` picks the ``k``
eigenvectors lying most in it (the squared norm of each unit column's projection), after turning
the basis of every repeated eigenvalue toward it (:func:`align_repeated`: the choice must not
depend on the basis a decomposition returned for a doubled eigenspace).

:func:`indicator` is the smooth function of the load whose root is the onset:

* undamped second-order problems (``s = omega^2``): ``Delta = k sum s_i^2 - (sum s_i)^2`` of the
  cluster, a symmetric function analytic in the load although the double root is defective
  (its eigenvalues carry sqrt(eps) noise, ``Delta`` only eps): positive while the cluster is real,
  negative once it is a complex pair; divergence: the cluster mean of ``s``;
* first-order problems (``lambda``): the largest real part of the cluster from its symmetric
  functions (``Re c + |Re sqrt(d)|`` with the mean ``c`` and variance ``d`` of the upper half, a
  Hopf crossing). Where the merging branches lay on the imaginary axis before (an undamped
  system in first-order form, an undamped gyroscopic one), the discriminant of the cluster's
  upper half, ``Re(m sum lambda^2 - (sum lambda)^2)``, which crosses zero linearly like
  ``Delta``.

Affine problems get its exact derivative from the eigenvalue derivatives ``W_C A1 V_C``.
"""

from __future__ import annotations

from math import sqrt

import numpy as np
from ..._jit import njit

from ..classify import _masks
from .tolerances import FLOOR, TOL_CLUSTER, TOL_COPIES, TOL_REPEATED, TOL_UNSTABLE

__all__ = ["unstable_cluster", "projector", "select", "align_repeated", "indicator"]


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
def _upper_half(v, k):
    """Whether some of ``v[:k]`` lie in the upper half plane (the cluster's sums then count those)."""
    upper = False
    for i in range(k):
        upper = upper or v[i].imag > 0
    return upper


@njit(cache=True, error_model="numpy", _nrt=False)
def _sums(v, b, k, upper):
    """``(sum v, sum b, sum v b, m)`` over the ``m`` members of ``v[:k]`` counted: all of them, or
    with ``upper`` those with ``Im v >= 0``."""
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
    return s1, sb, svb, m


@njit(cache=True, error_model="numpy", _nrt=False)
def _pair_growth(v, k):
    """Largest real part of a cluster (upper half plane), from its symmetric functions.

    For the upper-half members (a pair, possibly each doubled by symmetry) ``c = mean`` and
    ``d = mean((lambda - c)^2)`` are analytic in the load even where the pair is defective, so
    ``Re c + |Re sqrt(d)|`` keeps its accuracy there; for a single eigenvalue it is ``Re lambda``.
    """
    upper = _upper_half(v, k)
    c, _, _, m = _sums(v, v, k, upper)
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
    upper = coalesce and _upper_half(v, k)
    if undamped or coalesce:
        s1, _, s2, m = _sums(v, v, k, upper)
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
        upper = _upper_half(v, k)
        c, cb, _, m = _sums(v, b, k, upper)
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
    s1, sb, svb, m = _sums(v, b, k, upper)
    return f, (2 * m * svb - 2 * s1 * sb).real, True
