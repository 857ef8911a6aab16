"""Batched eigenvalue problems of ``M q'' + (D + G) q' + K q = 0`` (stacks of small matrices).

Eigenvalues ``lambda = sigma + i omega`` with ``q(t) = Re(X exp(lambda t))``: ``sigma`` is the
growth rate (1/s), ``omega`` the damped angular frequency (rad/s).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["state_matrices", "stiffness_eigenvalues", "state_eigenvalues", "kinetic_shares"]

Array = NDArray[np.float64]


def state_matrices(m: Array, c: Array, k: Array) -> Array:
    """First-order state matrices ``A = [[0, I], [-M^-1 K, -M^-1 C]]`` for stacks ``(..., n, n)``."""
    m, c, k = np.broadcast_arrays(np.asarray(m, float), np.asarray(c, float), np.asarray(k, float))
    n = m.shape[-1]
    a = np.zeros(m.shape[:-2] + (2 * n, 2 * n))
    a[..., :n, n:] = np.eye(n)
    rhs = np.concatenate([k, c], axis=-1)
    a[..., n:, :] = -np.linalg.solve(m, rhs)
    return a


def stiffness_eigenvalues(m: Array, k: Array, vectors: bool = False):
    """Eigenvalues ``s = omega^2`` of ``K x = s M x`` (undamped, non-gyroscopic), batched.

    Stable when every ``s`` is real and positive; ``lambda = +- i sqrt(s)``.
    """
    a = np.linalg.solve(m, k)
    if vectors:
        return np.linalg.eig(a)
    return np.linalg.eigvals(a)


def state_eigenvalues(m: Array, c: Array, k: Array, vectors: bool = False):
    """Eigenvalues (and optionally eigenvectors) of the state matrix, batched."""
    a = state_matrices(m, c, k)
    if vectors:
        return np.linalg.eig(a)
    return np.linalg.eigvals(a)


def kinetic_shares(vectors: Array, m: Array) -> Array:
    """Share of each dof in the kinetic-energy diagonal, ``|x_i|^2 M_ii / sum_k |x_k|^2 M_kk``.

    ``vectors`` is ``(n, k)`` (columns spanning a mode or an invariant subspace); the result is
    ``(n,)`` and sums to 1. It is unit-consistent (kg m^2/s^2 for every dof).
    """
    w = (np.abs(vectors) ** 2).sum(axis=-1) * np.diag(m)
    total = w.sum()
    return w / total if total > 0 else w
