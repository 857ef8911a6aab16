"""Batched eigenvalue problems of ``M q'' + (D + G) q' + K q = 0`` (stacks of small matrices).

Eigenvalues ``lambda = sigma + i omega`` with ``q(t) = Re(X exp(lambda t))``: ``sigma`` is the
growth rate (1/s), ``omega`` the damped angular frequency (rad/s).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .participation import participation_into

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
    values = np.asarray(values, dtype=complex)
    members = np.asarray(members, dtype=bool)
    m_diag = np.asarray(m_diag, dtype=float)
    n, k = shapes.shape[-2:]
    lead = np.broadcast_shapes(shapes.shape[:-2], values.shape[:-1], members.shape[:-1], m_diag.shape[:-1])
    # writable C copies (np.array), as the compiled callers pass: a read-only view of a broadcast
    # is another argument type, for which numba would compile participation_into again
    flat_s = np.array(np.broadcast_to(shapes, lead + (n, k)).reshape(-1, n, k), order="C")
    flat_v = np.array(np.broadcast_to(values, lead + (k,)).reshape(-1, k), order="C")
    flat_m = np.array(np.broadcast_to(members, lead + (k,)).reshape(-1, k), order="C")
    flat_w = np.array(np.broadcast_to(m_diag, lead + (n,)).reshape(-1, n), order="C")
    out = np.empty((len(flat_s), n))
    for r in range(len(flat_s)):
        participation_into(flat_s[r], flat_v[r], flat_m[r], flat_w[r], float(tol), out[r])
    return out.reshape(lead + (n,))
