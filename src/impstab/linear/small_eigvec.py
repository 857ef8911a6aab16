"""Eigenvectors of small dense real matrices, compiled: inverse iteration on computed eigenvalues.

For a 6 x 6 operator LAPACK's ``geev`` plus an inverse of its eigenvectors, called through
numpy on a stack, costs about 9 us a matrix, mostly call overhead. Here, for one block:

1. eigenvalues by the compiled QR of :mod:`impstab.linear.small_eig`;
2. each eigenvector by inverse iteration, ``(A - lambda I) x_new = x`` with the computed
   eigenvalue as the shift (accurate to ``eps |A|``, so one step usually suffices), in real
   arithmetic for a real eigenvalue and once for a complex-conjugate pair (the partner's vector
   is its exact conjugate), accepted only once the residual ``|A x - lambda x|`` is below
   ``64 m eps |A|``: then ``x`` is an exact eigenvector of a matrix that close to ``A``, the
   backward stability of LAPACK's vectors;
3. the left eigenvectors ``V^-1`` by LU with partial pivoting.

Any failure (a defective block, whose eigenvectors are dependent; no acceptable residual in
three steps) is reported, and the caller solves that matrix with LAPACK. About 3.5 us for the
asymmetric example's 6 x 6 operator.
"""

from __future__ import annotations

from math import sqrt

import numpy as np
from .._jit import njit

from .small_eig import _solve_one

_EPS = float(np.finfo(float).eps)


@njit(cache=True, error_model="numpy", _nrt=False)
def _lu(b, m, piv, tiny):
    """LU factorisation with partial pivoting of the complex ``b[:m, :m]`` in place.

    A zero pivot becomes ``tiny`` (inverse iteration: the shifted matrix is singular to working
    precision by design); returns whether that happened (with ``tiny`` 0 the factorisation
    stops there: singular).
    """
    hit = False
    for k in range(m):
        p = k
        big = abs(b[k, k].real) + abs(b[k, k].imag)  # LAPACK's cabs1: as good a pivot, no hypot
        for i in range(k + 1, m):
            size = abs(b[i, k].real) + abs(b[i, k].imag)
            if size > big:
                big = size
                p = i
        piv[k] = p
        if p != k:
            for j in range(m):
                t = b[k, j]
                b[k, j] = b[p, j]
                b[p, j] = t
        if b[k, k] == 0.0:
            hit = True
            if tiny == 0.0:  # singular, and no substitute wanted
                return hit
            b[k, k] = tiny
        rec = 1.0 / b[k, k]
        for i in range(k + 1, m):
            f = b[i, k] * rec
            b[i, k] = f
            for j in range(k + 1, m):
                b[i, j] -= f * b[k, j]
    return hit


@njit(cache=True, error_model="numpy", _nrt=False)
def _lu_solve(b, m, piv, x):
    """Solve ``B y = x`` in place with the factors of :func:`_lu`."""
    for k in range(m):
        p = piv[k]
        if p != k:
            t = x[k]
            x[k] = x[p]
            x[p] = t
    for i in range(m):
        for j in range(i):
            x[i] -= b[i, j] * x[j]
    for i in range(m - 1, -1, -1):
        for j in range(i + 1, m):
            x[i] -= b[i, j] * x[j]
        x[i] /= b[i, i]


@njit(cache=True, error_model="numpy", _nrt=False)
def _eigvector(w0, m, lam, norm, b, piv, x):
    """Unit eigenvector of ``w0[:m, :m]`` for the computed eigenvalue ``lam``, by inverse iteration.

    Steps of ``(A - lam I) x_new = x`` from a fixed start with unequal entries until the residual
    ``|A x - lam x|`` is below ``64 m eps |A|`` (``norm``: the infinity norm of ``A``): then ``x``
    is an exact eigenvector of a matrix within that distance of ``A``, the backward stability
    LAPACK's vectors have. The shift is accurate to ``eps |A|``, so one step is usually enough;
    False after three (then LAPACK takes over).
    """
    for i in range(m):
        for j in range(m):
            b[i, j] = w0[i, j]
        b[i, i] -= lam
    _lu(b, m, piv, max(_EPS * norm, 1e-300))
    for i in range(m):
        x[i] = 1.0 + 0.1 * sqrt(i + 2.0)
    for _ in range(3):
        _lu_solve(b, m, piv, x)
        size = 0.0
        for i in range(m):
            size += x[i].real ** 2 + x[i].imag ** 2
        if not (size > 0.0 and np.isfinite(size)):
            return False
        size = 1.0 / sqrt(size)
        for i in range(m):
            x[i] *= size
        worst = 0.0
        for i in range(m):
            r = -lam * x[i]
            for j in range(m):
                r += w0[i, j] * x[j]
            worst = max(worst, abs(r.real) + abs(r.imag))
        if worst <= 64.0 * m * _EPS * norm:
            return True
    return False


def _eig_block_lapack(w, w0, m, v, wr, wi, vals, vecs, inv, b, piv, x, b_real, x_real):
    """:func:`_eig_block` while kernels run interpreted: LAPACK ``geev`` and an LU inverse through NumPy.

    The same contract (unit eigenvectors, a real eigenvalue's vector real, a complex pair's
    exactly conjugate, False when a step fails) and LAPACK's vectors, which the engine already
    takes wherever the compiled inverse iteration gives up.
    """
    a = w0[:m, :m]
    if not np.isfinite(a).all():
        return False
    return lapack_eig(a, vals[:m], vecs[:m, :m], inv[:m, :m]) == 1


def lapack_eig(op, vals, vecs, inv):
    """LAPACK's eigen-decomposition and the inverse of the eigenvectors; 0 where that is singular.

    Results go to ``vals``, ``vecs``, ``inv`` (views are fine); 1 on success. The engine calls it
    from compiled code (object mode) wherever the compiled inverse iteration gives up.
    """
    v, w = np.linalg.eig(op)
    vals[...] = v
    vecs[...] = w
    try:
        inv[...] = np.linalg.inv(w)
    except np.linalg.LinAlgError:
        return 0
    return 1 if np.isfinite(inv).all() else 0


@njit(cache=True, error_model="numpy", _nrt=False, interpreted=_eig_block_lapack)
def _eig_block(w, w0, m, v, wr, wi, vals, vecs, inv, b, piv, x, b_real, x_real):
    """Eigenvalues (compiled QR), unit eigenvectors and their inverse of the block ``w0[:m, :m]``.

    ``w`` holds a copy (destroyed). Results go to ``vals[:m]``, ``vecs[:m, :m]``, ``inv[:m, :m]``;
    False if any step fails. A real eigenvalue's vector is found in real arithmetic (``b_real``,
    ``x_real``: the same routines, compiled for real arrays), a complex pair's once.
    """
    if not _solve_one(w, m, v, wr, wi, vals):
        return False
    norm = 0.0
    for i in range(m):
        row = 0.0
        for j in range(m):
            row += abs(w0[i, j])
        norm = max(norm, row)
    t = 0
    while t < m:
        if vals[t].imag == 0.0:
            if not _eigvector(w0, m, vals[t].real, norm, b_real, piv, x_real):
                return False
            for i in range(m):
                vecs[i, t] = x_real[i]
            t += 1
            continue
        if not _eigvector(w0, m, vals[t], norm, b, piv, x):
            return False
        for i in range(m):
            vecs[i, t] = x[i]
        if vals[t].imag > 0.0 and t + 1 < m and vals[t + 1] == vals[t].conjugate():
            for i in range(m):  # the conjugate pair's vector, exactly conjugate
                vecs[i, t + 1] = x[i].conjugate()
            t += 2
        else:
            t += 1
    # inverse of the eigenvectors: LU, then the columns of the identity
    for i in range(m):
        for j in range(m):
            b[i, j] = vecs[i, j]
    if _lu(b, m, piv, 0.0):
        return False
    for c in range(m):
        for i in range(m):
            x[i] = 1.0 if i == c else 0.0
        _lu_solve(b, m, piv, x)
        for i in range(m):
            if not (np.isfinite(x[i].real) and np.isfinite(x[i].imag)):
                return False
            inv[i, c] = x[i]
    return True
