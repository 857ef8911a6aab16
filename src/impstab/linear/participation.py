"""Kinetic-energy participation of a cluster of modes, compiled (one cluster at a time).

The stability engine calls it at every onset it reports, inside its compiled loop;
:func:`impstab.linear.eigen.cluster_participation` is the same routine over stacks.

A mode of a simple eigenvalue contributes ``|x_i|^2 M_ii / sum_k |x_k|^2 M_kk``. The modes of one
repeated eigenvalue (``|v_i - v_j| <= tol max |v|``) span an eigenspace in which any basis is as
good as another: they contribute the diagonal of the kinetic-energy-orthogonal projector onto it,
``diag(Y G^-1 Y^H)`` with ``Y = M^1/2 X`` and the Gram matrix ``G = Y^H Y`` taken within each
repeated eigenvalue, which does not depend on the basis an eigensolver returned. Where that
projector cannot be formed (a defective repeated eigenvalue: dependent vectors) the modes
contribute one by one. Each distinct mode weighs equally; the shares sum to 1.
"""

from __future__ import annotations

from math import sqrt

import numpy as np
from .._jit import njit

from .small_eigvec import _lu, _lu_solve

__all__ = ["participation_into"]


@njit(cache=True, error_model="numpy")
def participation_into(shapes, values, members, weights, tol, out):
    """Shares of each dof in the cluster ``members`` of ``shapes (n, k)`` into ``out (n,)``.

    ``values (k,)`` are the eigenvalues of the columns, ``weights (n,)`` the mass diagonal (kg,
    kg m^2), ``tol`` the relative distance of one repeated eigenvalue.
    """
    n, k = shapes.shape
    y = np.zeros((n, k), dtype=np.complex128)
    count = 0
    scale = 0.0
    for c in range(k):
        if members[c]:
            count += 1
            scale = max(scale, abs(values[c]))
            for r in range(n):
                y[r, c] = shapes[r, c] * sqrt(weights[r])
    gram = np.zeros((k, k), dtype=np.complex128)
    for a in range(k):
        if not members[a]:
            gram[a, a] = 1.0
            continue
        for b in range(k):
            if members[b] and abs(values[a] - values[b]) <= tol * scale:
                s = 0j
                for r in range(n):
                    s += y[r, a].conjugate() * y[r, b]
                gram[a, b] = s
    piv = np.empty(k, dtype=np.int64)
    good = not _lu(gram, k, piv, 0.0)
    if good:
        x = np.empty(k, dtype=np.complex128)
        worst = 0.0
        for r in range(n):
            for c in range(k):
                x[c] = y[r, c].conjugate()
            _lu_solve(gram, k, piv, x)
            s = 0.0
            for c in range(k):
                s += (y[r, c] * x[c]).real
            out[r] = s
            good = good and np.isfinite(s)
            worst = min(worst, s)
        good = good and worst > -1e-12
    if not good:  # mode by mode
        for r in range(n):
            out[r] = 0.0
        for c in range(k):
            total = 0.0
            for r in range(n):
                total += y[r, c].real ** 2 + y[r, c].imag ** 2
            if total > 0.0:
                for r in range(n):
                    out[r] += (y[r, c].real ** 2 + y[r, c].imag ** 2) / total
    for r in range(n):
        out[r] = max(out[r], 0.0) / max(count, 1)
