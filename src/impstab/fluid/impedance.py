"""Modal specific impedance of the n = 1 motion of an infinite cylinder (THEORY 9).

Time factor ``e^{i omega t}``. A radial surface velocity ``U cos(theta) e^{i k x}`` on the
cylinder ``r = a`` radiates a pressure ``p = z(k) U cos(theta) e^{i k x}`` at the surface with

* ``|k| > k0`` (evanescent, ``gamma = sqrt(k^2 - k0^2)``):
  ``z = i omega rho K1(gamma a) / [gamma (K0(gamma a) + K1(gamma a) / (gamma a))]``,
* ``|k| < k0`` (radiating, ``k_r = sqrt(k0^2 - k^2)``):
  ``z = -i omega rho H1(2)(k_r a) / [k_r H1(2)'(k_r a)]``,

where ``k0 = omega / c``. Both are written ``z = i omega rho a r`` with the dimensionless ratio
``r``: real for ``|k| > k0`` (a pure mass), complex with ``Im r < 0`` below (radiation, so that
``Re z > 0``). ``r`` depends on ``gamma`` only through ``gamma^2`` and ``gamma^2 log gamma``, so it
is continuous at ``k0`` with a logarithmic (not square-root) singularity there; ``r -> 1`` as
``gamma -> 0`` and ``r ~ 1 / (gamma a)`` for large ``gamma``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import special

__all__ = ["evanescent_ratio", "radiating_ratio", "modal_impedance", "incompressible_kernel"]

_TINY = 1e-300  # keeps 0 * inf out of the small-argument limits (the ratios tend to 1 there)


def evanescent_ratio(w: ArrayLike) -> NDArray:
    """``r(w) = K1(w) / (w K0(w) + K1(w))`` for ``Re w > 0`` (``w = gamma a``).

    Written as ``1 / (1 + w K0/K1)`` with exponentially scaled Bessel functions (the scaling
    cancels in the ratio), which is accurate from ``w -> 0`` (``r -> 1``, no series needed:
    ``w K0/K1 ~ -w^2 log w``) to large ``|w|`` (``r ~ 1/w - 1/(2 w^2)``). Real input uses the
    fast real routines, complex input the complex ones.
    """
    w = np.asarray(w)
    if np.iscomplexobj(w):
        return 1.0 / (1.0 + w * special.kve(0, w) / special.kve(1, w))
    w = np.maximum(w.astype(float), _TINY)
    return 1.0 / (1.0 + w * special.k0e(w) / special.k1e(w))


def radiating_ratio(x: ArrayLike) -> NDArray[np.complex128]:
    """``r(x) = -H1(2)(x) / (x H1(2)'(x))`` for real ``x = k_r a > 0``.

    With ``H = J1 - i Y1`` and ``D = x H' = (x J0 - J1) - i (x Y0 - Y1) = Dr - i Di`` the Wronskian
    ``J1 Y1' - Y1 J1' = 2 / (pi x)`` gives, without cancellation,
    ``r = -[(J1 Dr + Y1 Di) + 2 i / pi] / (Dr^2 + Di^2)``. Numerator and denominator are
    multiplied by ``x^2`` so that nothing overflows as ``x -> 0`` (``r -> 1 - i pi x^2 / 2``).
    """
    x = np.maximum(np.asarray(x, dtype=float), _TINY)
    xj1 = x * special.j1(x)
    xy1 = x * special.y1(x)
    xdr = x * x * special.j0(x) - xj1
    xdi = x * x * special.y0(x) - xy1
    den = xdr * xdr + xdi * xdi
    return (-(xj1 * xdr + xy1 * xdi) - 2j / np.pi * x * x) / den


def _check_k(k: ArrayLike) -> NDArray[np.float64]:
    k = np.abs(np.asarray(k, dtype=float))
    if not np.all(np.isfinite(k)):
        raise ValueError("wavenumbers must be finite")
    return k


def incompressible_kernel(k: ArrayLike, radius: float) -> NDArray[np.float64]:
    """``g(k) = K1(ka) / [k (K0(ka) + K1(ka)/(ka))]`` in metres (``z = i omega rho g``).

    ``g(0) = a`` and ``g ~ 1/k`` for large ``k``; ``k`` in rad/m (sign ignored, ``g`` is even).
    """
    k = _check_k(k)
    return radius * evanescent_ratio(k * radius)


def modal_impedance(
    k: ArrayLike, radius: float, density: float, sound_speed: float | None, omega: float
) -> NDArray[np.complex128]:
    """Modal specific impedance ``z(k)`` in Pa s/m (pressure per radial velocity amplitude).

    Parameters
    ----------
    k : array_like
        Axial wavenumber (rad/m); ``z`` is even in ``k``.
    radius : float
        Cylinder radius ``a`` (m).
    density : float
        Fluid density ``rho`` (kg/m^3).
    sound_speed : float or None
        Speed of sound ``c`` (m/s); None for an incompressible fluid (``k0 = 0``).
    omega : float
        Angular frequency (rad/s), time factor ``e^{i omega t}``.

    Returns
    -------
    ndarray of complex
        ``z(k) = i omega rho a r``; ``Re z >= 0`` (radiation) only for ``|k| < k0``.
    """
    k = _check_k(k)
    k0 = 0.0 if sound_speed is None else omega / sound_speed
    r = np.empty(k.shape, dtype=complex)
    above = k >= k0
    r[above] = evanescent_ratio(radius * np.sqrt((k[above] - k0) * (k[above] + k0)))
    below = ~above
    r[below] = radiating_ratio(radius * np.sqrt((k0 - k[below]) * (k0 + k[below])))
    return 1j * omega * density * radius * r
