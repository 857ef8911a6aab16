"""Mode tracking along a load sweep: pair eigenvectors step to step by MAC, not by sorting."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

__all__ = ["mac", "mac_of_pairs", "track_modes"]

#: weight of the relative eigenvalue distance against the MAC (which lies in [0, 1])
DISTANCE_WEIGHT = 20.0


def mac(a: NDArray, b: NDArray) -> NDArray[np.float64]:
    """Modal assurance criterion ``|a_i^H b_j|^2 / (|a_i|^2 |b_j|^2)`` between columns."""
    num = np.abs(a.conj().T @ b) ** 2
    den = np.outer((np.abs(a) ** 2).sum(0), (np.abs(b) ** 2).sum(0))
    return num / np.where(den > 0, den, 1.0)


def mac_of_pairs(a: NDArray, b: NDArray) -> NDArray[np.float64]:
    """The MAC of each column of ``a`` with the same column of ``b`` (the diagonal of
    :func:`mac` without the rest of the matrix)."""
    num = np.abs((a.conj() * b).sum(0)) ** 2
    den = (np.abs(a) ** 2).sum(0) * (np.abs(b) ** 2).sum(0)
    return num / np.where(den > 0, den, 1.0)


def track_modes(values: NDArray, vectors: NDArray) -> tuple[NDArray, NDArray]:
    """Reorder eigenpairs ``(N, k)`` / ``(N, n, k)`` so each column follows one branch.

    Consecutive steps are matched by the assignment that minimises ``w |dlambda| / scale - MAC``:
    far from a crossing the eigenvalue distance decides (eigenvectors of a non-normal problem are
    not orthogonal, and the basis of a symmetric double root is arbitrary); where two branches
    come close, the MAC decides which way they go on.
    """
    values = values.copy()
    vectors = vectors.copy()
    for i in range(1, len(values)):
        m = mac(vectors[i - 1], vectors[i])
        scale = max(np.abs(values[i - 1]).max(), 1e-300)
        dist = np.abs(values[i - 1][:, None] - values[i][None, :]) / scale
        _, col = linear_sum_assignment(DISTANCE_WEIGHT * dist - m)
        values[i] = values[i][col]
        vectors[i] = vectors[i][:, col]
    return values, vectors
