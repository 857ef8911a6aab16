"""The linearized system ``M q'' + (D + G) q' + K q = 0`` at one thrust, and its first-order form."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .eigen import state_matrices

__all__ = ["LinearSystem"]

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class LinearSystem:
    """Linearized equations of motion about the static equilibrium at thrust ``thrust``.

    Coordinates ``q = (u_x, u_y, u_z, r_x, r_y, r_z)`` of the reference point A (hull frame,
    small rotation vector); SI units.

    Attributes
    ----------
    M : (6, 6) mass, rigid body plus added mass (kg, kg m, kg m^2)
    D : (6, 6) mount damping, symmetric
    G : (6, 6) propeller gyroscopic matrix, skew
    K : (6, 6) tangent stiffness, non-symmetric under follower thrust
    thrust : float
        Thrust T (N).
    linearization : {"equilibrium", "classical"}
    displacement : (3,) static displacement of A (m)
    rotation : (3, 3) static rotation matrix body -> hull
    """

    M: Array
    D: Array
    G: Array
    K: Array
    thrust: float
    linearization: str
    displacement: Array
    rotation: Array

    def __repr__(self) -> str:
        from ..display import linear_system_text

        return linear_system_text(self)

    def state_matrix(self) -> Array:
        """``A = [[0, I], [-M^-1 K, -M^-1 (D + G)]]`` for ``x = (q, q')``."""
        return state_matrices(self.M, self.D + self.G, self.K)

    def first_order(self) -> tuple[Array, Array]:
        """The first-order form ``E x' = A x`` for ``x = (q, q')``, without inverting M.

        Returns
        -------
        E : (12, 12) array
            ``[[I, 0], [0, M]]``.
        A : (12, 12) array
            ``[[0, I], [-K, -(D + G)]]``; ``E^-1 A`` is :meth:`state_matrix`.
        """
        n = self.M.shape[0]
        e = np.eye(2 * n)
        e[n:, n:] = self.M
        a = np.zeros((2 * n, 2 * n))
        a[:n, n:] = np.eye(n)
        a[n:, :n] = -self.K
        a[n:, n:] = -(self.D + self.G)
        return e, a

    @property
    def stiffness_symmetric(self) -> Array:
        """Symmetric (conservative) part of K."""
        return 0.5 * (self.K + self.K.T)

    @property
    def stiffness_circulatory(self) -> Array:
        """Skew (circulatory, non-conservative) part of K."""
        return 0.5 * (self.K - self.K.T)

    def eigenvalues(self) -> NDArray[np.complex128]:
        """Eigenvalues ``lambda = sigma + i omega`` of the state matrix (1/s)."""
        return np.linalg.eigvals(self.state_matrix())
