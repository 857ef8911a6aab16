"""Spectral windows of the rigid segment motions (THEORY 9).

The segment ``|x| < L/2`` translating with velocity ``V`` has the wavenumber transform
``U~(k) = V L sinc(kL/2)``; rotating with angular velocity ``Omega`` about a transverse axis
through its centre (``U = Omega x``) it has ``|U~(k)|^2 = Omega^2 |G(k)|^2`` with
``|G|^2 = 4 [sin(kL/2)/k^2 - (L/2) cos(kL/2)/k]^2 = (L^4 / 4) j1(kL/2)^2``.
With ``X = kL/2``, the translation window is ``L^2 j0(X)^2`` and the rotation window
``(L^4/4) j1(X)^2``, where ``j0, j1`` are spherical Bessel functions. Small ``X``:
``|G|^2 ~ (L^3/12)^2 k^2`` (a series is used there: the closed form cancels).

For the tail of the wavenumber integrals the squares are split into a non-oscillating part and
``e^{+-2iX}`` parts, ``j_n(X)^2 = n_n(X) + c_n(X) e^{2iX} + conj(c_n)(X) e^{-2iX}`` (real X):

* ``n_0 = 1/(2X^2)``, ``c_0 = -1/(4X^2)``;
* ``n_1 = (1 + X^2)/(2X^4)``, ``c_1 = (X + i)^2/(4X^4)``.

The parts are analytic away from ``X = 0`` and are evaluated on complex ``X`` as well.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["window_squared", "window_parts", "ORDERS"]

ORDERS = (0, 1)  # 0: translation, 1: rotation about the segment centre

_SERIES_BELOW = 1.0


def _j1_series(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``j1(x) = x sum_k (-x^2/2)^k / (k! (2k+3)!!)``; 9 terms give full precision for x < 1."""
    term = x / 3.0
    total = term.copy()
    for k in range(1, 9):
        term = term * (-0.5 * x * x) / (k * (2 * k + 3))
        total += term
    return total


def window_squared(x: NDArray[np.float64], order: int) -> NDArray[np.float64]:
    """``j0(x)^2`` (order 0) or ``j1(x)^2`` (order 1) for real ``x > 0``."""
    x = np.asarray(x, dtype=float)
    if order == 0:
        return (np.sin(x) / x) ** 2
    small = x < _SERIES_BELOW
    j1 = np.empty_like(x)
    xs = x[small]
    j1[small] = _j1_series(xs)
    xl = x[~small]
    j1[~small] = (np.sin(xl) - xl * np.cos(xl)) / (xl * xl)
    return j1 * j1


def window_parts(x: NDArray, order: int) -> tuple[NDArray, NDArray]:
    """Non-oscillating part ``n(x)`` and ``e^{2ix}`` coefficient ``c(x)`` of ``j_order(x)^2``.

    Valid for complex ``x`` away from 0; used where ``|x|`` is at least of order 1 (the split
    cancels badly for small ``|x|``).
    """
    x2 = x * x
    if order == 0:
        return 0.5 / x2, -0.25 / x2
    x4 = x2 * x2
    return (1.0 + x2) / (2.0 * x4), (x + 1j) ** 2 / (4.0 * x4)
