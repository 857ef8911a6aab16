"""Eigenvalues of stacks of small real matrices, compiled.

LAPACK's ``geev`` spends most of its time on a 6 x 6 or 12 x 12 matrix in call overhead and
blocking logic meant for large ones (about 2.6 us for a 6 x 6 scan operator, against 0.9 us
here). The stability engine classifies thousands of such matrices, so it uses this routine
(eigenvectors come from :mod:`impstab.linear.small_eigvec`, built on it).

Algorithm (the classical eigenvalue-only path of EISPACK / LAPACK ``dlahqr``):

1. balancing by powers of two (exact in floating point: the spectrum is unchanged, the
   matrix norm is reduced for badly scaled operators such as ``M^-1 K`` with mixed units);
2. reduction to upper Hessenberg form by Householder reflections (orthogonal similarity);
3. the Francis implicit double-shift QR iteration with deflation on small subdiagonal entries
   (``|h_{l,l-1}| <= eps (|h_{l-1,l-1}| + |h_{l,l}|)``) and exceptional shifts after 10 and
   20 iterations without deflation.

All three steps are backward stable: the eigenvalues are exact for a matrix within a few eps
of the input (relative to its norm), as LAPACK's. A simple eigenvalue is then accurate to
``eps |A| / s_i`` (``s_i`` its condition number); a double one of a defective matrix to
``sqrt(eps |A|)`` -- the same sensitivity as any backward-stable method.
"""

from __future__ import annotations

from math import copysign, sqrt

import numpy as np
from .._jit import njit
from numpy.typing import NDArray

__all__ = ["eigvals_small", "eigvals_affine", "MAX_ORDER"]

#: largest order solved here; larger matrices go to LAPACK
MAX_ORDER = 24
_EPS = float(np.finfo(float).eps)
_MAX_ITERATIONS = 60  # per eigenvalue, as EISPACK hqr (30 per eigenvalue in dlahqr, x n in total)


@njit(cache=True, error_model="numpy", _nrt=False)
def _balance(a, n, f):
    """Scale rows and columns by powers of two until their off-diagonal norms are comparable.

    The result is ``D^-1 a D`` with ``D = diag(f)``; ``f`` (length ``n``) receives the scaling.
    """
    for i in range(n):
        f[i] = 1.0
    done = False
    while not done:
        done = True
        for i in range(n):
            c = 0.0
            r = 0.0
            for j in range(n):
                if j != i:
                    c += abs(a[j, i])
                    r += abs(a[i, j])
            if c == 0.0 or r == 0.0:
                continue
            total = c + r
            step = 1.0
            g = r / 2.0
            while c < g:
                step *= 2.0
                c *= 4.0
            g = r * 2.0
            while c > g:
                step /= 2.0
                c /= 4.0
            if (c + r) / step < 0.95 * total:
                done = False
                f[i] *= step
                g = 1.0 / step
                for j in range(n):
                    a[i, j] *= g
                for j in range(n):
                    a[j, i] *= step


@njit(cache=True, error_model="numpy", _nrt=False)
def _hessenberg(a, n, v):
    """Householder reduction of ``a`` (in place) to upper Hessenberg form."""
    for k in range(n - 2):
        alpha = 0.0
        for i in range(k + 1, n):
            alpha += a[i, k] * a[i, k]
        alpha = sqrt(alpha)
        if alpha == 0.0:
            continue
        if a[k + 1, k] > 0.0:
            alpha = -alpha
        for i in range(k + 1, n):
            v[i] = a[i, k]
        v[k + 1] -= alpha
        vv = 0.0
        for i in range(k + 1, n):
            vv += v[i] * v[i]
        if vv == 0.0:
            continue
        beta = 2.0 / vv
        for j in range(k, n):  # H a
            s = 0.0
            for i in range(k + 1, n):
                s += v[i] * a[i, j]
            s *= beta
            for i in range(k + 1, n):
                a[i, j] -= s * v[i]
        for i in range(n):  # (H a) H
            s = 0.0
            for j in range(k + 1, n):
                s += a[i, j] * v[j]
            s *= beta
            for j in range(k + 1, n):
                a[i, j] -= s * v[j]
        for i in range(k + 2, n):
            a[i, k] = 0.0


@njit(cache=True, error_model="numpy", _nrt=False)
def _hessenberg_norm(a, n):
    s = 0.0
    for i in range(n):
        for j in range(max(i - 1, 0), n):
            s += abs(a[i, j])
    return s


@njit(cache=True, error_model="numpy", _nrt=False)
def _francis(a, n, wr, wi):  # noqa: C901 - one algorithm, kept in one piece
    """Eigenvalues of the upper Hessenberg ``a`` (destroyed) into ``wr + i wi``; False: no convergence."""
    hi = n - 1
    shift = 0.0  # accumulated exceptional shifts
    x = y = w = 0.0
    while hi >= 0:
        its = 0
        while True:
            lo = hi  # look for a negligible subdiagonal entry
            while lo >= 1:
                s = abs(a[lo - 1, lo - 1]) + abs(a[lo, lo])
                if s == 0.0:
                    s = _hessenberg_norm(a, n)
                if abs(a[lo, lo - 1]) <= _EPS * s:
                    a[lo, lo - 1] = 0.0
                    break
                lo -= 1
            x = a[hi, hi]
            if lo == hi:  # a 1 x 1 block has split off
                wr[hi] = x + shift
                wi[hi] = 0.0
                hi -= 1
                break
            y = a[hi - 1, hi - 1]
            w = a[hi, hi - 1] * a[hi - 1, hi]
            if lo == hi - 1:  # a 2 x 2 block: its two roots, real or a conjugate pair
                p = 0.5 * (y - x)
                q = p * p + w
                z = sqrt(abs(q))
                x += shift
                if q >= 0.0:
                    z = p + copysign(z, p)
                    wr[hi - 1] = x + z
                    wr[hi] = x - w / z if z != 0.0 else x + z
                    wi[hi - 1] = 0.0
                    wi[hi] = 0.0
                else:
                    wr[hi - 1] = x + p
                    wr[hi] = x + p
                    wi[hi - 1] = z
                    wi[hi] = -z
                hi -= 2
                break
            if its == _MAX_ITERATIONS:
                return False
            if its == 10 or its == 20:  # exceptional shift
                shift += x
                for i in range(hi + 1):
                    a[i, i] -= x
                s = abs(a[hi, hi - 1]) + abs(a[hi - 1, hi - 2])
                x = 0.75 * s
                y = x
                w = -0.4375 * s * s
            its += 1
            # the double shift's first column; start where two consecutive subdiagonals are small
            m = hi - 2
            p = q = r = 0.0
            while m >= lo:
                z = a[m, m]
                r = x - z
                s = y - z
                p = (r * s - w) / a[m + 1, m] + a[m, m + 1]
                q = a[m + 1, m + 1] - z - r - s
                r = a[m + 2, m + 1]
                s = abs(p) + abs(q) + abs(r)
                p /= s
                q /= s
                r /= s
                if m == lo:
                    break
                u = abs(a[m, m - 1]) * (abs(q) + abs(r))
                v = abs(p) * (abs(a[m - 1, m - 1]) + abs(z) + abs(a[m + 1, m + 1]))
                if u <= _EPS * v:
                    break
                m -= 1
            for i in range(m + 2, hi + 1):
                a[i, i - 2] = 0.0
                if i != m + 2:
                    a[i, i - 3] = 0.0
            # chase the bulge with 3 x 3 Householder reflections
            for k in range(m, hi):
                if k != m:
                    p = a[k, k - 1]
                    q = a[k + 1, k - 1]
                    r = a[k + 2, k - 1] if k != hi - 1 else 0.0
                    x = abs(p) + abs(q) + abs(r)
                    if x != 0.0:
                        p /= x
                        q /= x
                        r /= x
                s = copysign(sqrt(p * p + q * q + r * r), p)
                if s == 0.0:
                    continue
                if k == m:
                    if lo != m:
                        a[k, k - 1] = -a[k, k - 1]
                else:
                    a[k, k - 1] = -s * x
                p += s
                x = p / s
                y = q / s
                z = r / s
                q /= p
                r /= p
                for j in range(k, hi + 1):
                    p = a[k, j] + q * a[k + 1, j]
                    if k != hi - 1:
                        p += r * a[k + 2, j]
                        a[k + 2, j] -= p * z
                    a[k + 1, j] -= p * y
                    a[k, j] -= p * x
                top = hi if hi < k + 3 else k + 3
                for i in range(lo, top + 1):
                    p = x * a[i, k] + y * a[i, k + 1]
                    if k != hi - 1:
                        p += z * a[i, k + 2]
                        a[i, k + 2] -= p * r
                    a[i, k + 1] -= p * q
                    a[i, k] -= p
    return True


def _solve_one_lapack(a, n, v, wr, wi, out_row):
    """:func:`_solve_one` while kernels run interpreted: LAPACK ``geev`` through NumPy.

    The same contract (eigenvalues of ``a[:n, :n]`` into ``out_row``, complex pairs adjacent with
    the positive imaginary part first and exactly conjugate, real ones with a zero imaginary part;
    False when not finite) and the same backward-stable algorithm, which in plain Python is far
    faster than interpreting the QR iteration below.
    """
    m = a[:n, :n]
    if not np.isfinite(m).all():
        return False
    out_row[:n] = np.linalg.eigvals(m)
    return True


@njit(cache=True, error_model="numpy", _nrt=False, interpreted=_solve_one_lapack)
def _solve_one(a, n, v, wr, wi, out_row):
    """Eigenvalues of the matrix in ``a`` (destroyed) into ``out_row``.

    False when it is not finite or the iteration does not converge (the caller asks LAPACK).
    """
    for i in range(n):
        for j in range(n):
            if not np.isfinite(a[i, j]):
                return False
    _balance(a, n, v)  # v: scratch for the scaling, then for the reflections
    _hessenberg(a, n, v)
    ok = _francis(a, n, wr, wi)
    for i in range(n):
        out_row[i] = complex(wr[i], wi[i])
    return ok


@njit(cache=True, error_model="numpy")
def _eigvals_stack(ops, out, ok):
    n = ops.shape[1]
    a, v, wr, wi = np.empty((n, n)), np.empty(n), np.empty(n), np.empty(n)
    for s in range(ops.shape[0]):
        a[:, :] = ops[s]
        ok[s] = _solve_one(a, n, v, wr, wi, out[s])


@njit(cache=True, error_model="numpy")
def _eigvals_affine(a0, a1, loads, out, ok):
    n = a0.shape[1]
    a, v, wr, wi = np.empty((n, n)), np.empty(n), np.empty(n), np.empty(n)
    for s in range(a0.shape[0]):
        for k in range(loads.shape[1]):
            p = loads[s, k]
            for i in range(n):
                for j in range(n):
                    a[i, j] = a0[s, i, j] + p * a1[s, i, j]
            ok[s, k] = _solve_one(a, n, v, wr, wi, out[s, k])


def eigvals_affine(a0: NDArray[np.float64], a1: NDArray[np.float64], loads: NDArray[np.float64]) -> NDArray[np.complex128]:
    """Eigenvalues of ``a0[i] + loads[i, k] a1[i]`` for every ``i`` and ``k``, shape ``(N, K, n)``.

    The same as :func:`eigvals_small` on the formed stack (the matrices are formed with the same
    arithmetic, one at a time, so that the stack is never held in memory).
    """
    a0 = np.ascontiguousarray(a0, dtype=float)
    a1 = np.ascontiguousarray(a1, dtype=float)
    loads = np.ascontiguousarray(loads, dtype=float)
    n = a0.shape[-1]
    if n > MAX_ORDER or n == 0:
        return np.linalg.eigvals(a0[:, None] + loads[..., None, None] * a1[:, None])
    out = np.empty(loads.shape + (n,), dtype=np.complex128)
    ok = np.ones(loads.shape, dtype=np.bool_)
    _eigvals_affine(a0, a1, loads, out, ok)
    if not ok.all():
        s, k = np.nonzero(~ok)
        out[s, k] = np.linalg.eigvals(a0[s] + loads[s, k][:, None, None] * a1[s])
    return out


def eigvals_small(ops: NDArray[np.float64]) -> NDArray[np.complex128]:
    """Eigenvalues of each real matrix of a stack, like ``np.linalg.eigvals``.

    Parameters
    ----------
    ops : (..., n, n) float array

    Returns
    -------
    (..., n) complex array
        The eigenvalues of each matrix, in no particular order (complex pairs adjacent, the
        positive imaginary part first). Orders above :data:`MAX_ORDER`, and any matrix that is
        not finite or whose iteration does not converge, go to ``np.linalg.eigvals`` (which
        raises ``LinAlgError`` for the non-finite ones, as before).
    """
    ops = np.asarray(ops, dtype=float)
    n = ops.shape[-1]
    if ops.ndim < 2 or ops.shape[-2] != n:
        raise ValueError(f"eigvals_small needs square matrices, got shape {ops.shape}")
    if n > MAX_ORDER or n == 0:
        return np.linalg.eigvals(ops)
    flat = np.ascontiguousarray(ops.reshape(-1, n, n))
    out = np.empty(flat.shape[:2], dtype=np.complex128)
    ok = np.ones(len(flat), dtype=np.bool_)
    _eigvals_stack(flat, out, ok)
    if not ok.all():
        out[~ok] = np.linalg.eigvals(flat[~ok])
    return out.reshape(ops.shape[:-1])
