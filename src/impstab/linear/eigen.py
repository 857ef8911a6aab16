"""Batched eigenvalue problems of ``M q'' + (D + G) q' + K q = 0`` (stacks of small matrices).

Eigenvalues ``lambda = sigma + i omega`` with ``q(t) = Re(X exp(lambda t))``: ``sigma`` is the
growth rate (1/s), ``omega`` the damped angular frequency (rad/s).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["state_matrices", "stiffness_eigenvalues", "state_eigenvalues", "kinetic_shares", "cluster_participation"]

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


def cluster_participation(shapes: NDArray, values: NDArray, members: NDArray, m_diag: Array, tol: float) -> Array:
    """Kinetic-energy share of each dof in a cluster of modes, each distinct mode weighing equally.

    A mode of a simple eigenvalue contributes its :func:`kinetic_shares`. Modes of one repeated
    eigenvalue (``|v_i - v_j| <= tol max |v|``: a symmetric layout's sway-yaw and heave-pitch
    planes, say) span an eigenspace in which any basis is as good as another; they contribute
    the diagonal of the kinetic-energy-orthogonal projector onto that space, which does not
    depend on the basis an eigensolver happened to return. Batched over leading axes.

    Parameters
    ----------
    shapes : (..., n, k) complex array
        Displacement parts of the eigenvectors (columns).
    values : (..., k) complex array
        Their eigenvalues.
    members : (..., k) bool array
        The columns in the cluster.
    m_diag : (..., n) array
        Mass diagonal (kg, kg m^2).
    tol : float
        Relative distance within which eigenvalues are one repeated eigenvalue.

    Returns
    -------
    (..., n) array
        Sums to 1 over the dofs.
    """
    shapes = np.asarray(shapes, dtype=complex)
    members = np.asarray(members, dtype=bool)
    y = shapes * np.sqrt(np.asarray(m_diag, dtype=float))[..., :, None] * members[..., None, :]
    scale = np.abs(np.where(members, values, 0)).max(axis=-1)[..., None, None]
    same = (np.abs(values[..., :, None] - values[..., None, :]) <= tol * scale) & members[..., :, None] & members[..., None, :]
    eye = np.eye(members.shape[-1], dtype=bool)
    gram = np.where(same, np.conj(np.swapaxes(y, -1, -2)) @ y, 0) + (eye & ~members[..., :, None])
    # diag(Y G^-1 Y^H) with the Gram matrix G taken within each repeated eigenvalue only: the sum
    # of the projectors onto each eigenspace (for a simple eigenvalue |y|^2 / y^H y)
    try:
        sol = np.linalg.solve(gram, np.conj(np.swapaxes(y, -1, -2)))
        share = (y * np.swapaxes(sol, -1, -2)).sum(axis=-1).real
        good = np.isfinite(share).all(axis=-1) & (share.min(axis=-1, initial=0.0) > -1e-12)
    except np.linalg.LinAlgError:  # a defective repeated eigenvalue somewhere: mode by mode
        share, good = np.zeros(y.shape[:-1]), np.zeros(y.shape[:-2], dtype=bool)
    if not np.all(good):
        w = np.abs(y) ** 2
        total = w.sum(axis=-2, keepdims=True)
        each = (w / np.where(total > 0, total, 1.0)).sum(axis=-1)
        share = np.where(good[..., None], share, each)
    share = np.maximum(share, 0.0)
    return share / np.maximum(members.sum(axis=-1), 1)[..., None]
