"""Equilibria of ``B x' = f(x, p)`` and the spectrum of the pencil ``(J, B)`` there."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.typing import NDArray

from ..errors import NumericalError
from .derivatives import jacobians
from .system import DynamicalSystem

__all__ = ["solve_equilibrium", "Spectrum", "spectrum"]

Array = NDArray[np.float64]
CArray = NDArray[np.complex128]

EQUILIBRIUM_TOLERANCE = 1e-13
EQUILIBRIUM_ITERATIONS = 50


def solve_equilibrium(system: DynamicalSystem, x0: Array, p: float, *, tol: float = EQUILIBRIUM_TOLERANCE,
                      max_iter: int = EQUILIBRIUM_ITERATIONS) -> Array:
    """Newton's method for ``f(x, p) = 0`` from ``x0`` (exact complex-step Jacobian).

    Converged when the scaled step is below ``tol`` (relative to ``max(1, |x|)``).

    Raises
    ------
    NumericalError
        No convergence, or a singular Jacobian (a fold of equilibria at ``p``).
    """
    x = np.array(x0, dtype=float)
    scale = system.state_scale
    for _ in range(max_iter):
        fx = system.evaluate(x[None], p)[0].real
        jac = jacobians(system, x[None], p)[0]
        try:
            step = np.linalg.solve(jac, fx)
        except np.linalg.LinAlgError as exc:
            raise NumericalError(f"equilibrium at p = {p:.12g}: singular Jacobian (a fold of equilibria?)") from exc
        x = x - step
        if np.max(np.abs(step) / scale) <= tol * max(1.0, float(np.max(np.abs(x) / scale))):
            return x
    raise NumericalError(f"equilibrium at p = {p:.12g}: Newton's method did not converge in {max_iter} iterations")


@dataclass(frozen=True, eq=False)
class Spectrum:
    """Eigenvalues of ``J v = lambda B v`` with right vectors ``v`` and left vectors ``w``
    (``w^H J = lambda w^H B``), columns matching the eigenvalues."""

    eigenvalues: CArray
    right: CArray
    left: CArray

    def nearest(self, target: complex, upper: bool = True) -> int:
        """Index of the eigenvalue closest to ``target`` (among ``Im >= 0`` when ``upper``)."""
        lam = self.eigenvalues
        d = np.abs(lam - target)
        if upper:
            d = np.where(lam.imag >= -1e-300, d, np.inf)
        return int(np.argmin(d))


def spectrum(jac: Array, mass: Array) -> Spectrum:
    """The generalized eigenproblem of the pencil ``(J, B)`` (QZ; B invertible)."""
    lam, left, right = sla.eig(jac, mass, left=True, right=True)
    if not np.all(np.isfinite(lam)):
        raise NumericalError("infinite eigenvalues of the pencil (J, B): is the mass matrix invertible?")
    return Spectrum(lam, right, left)
