"""An independent route to the window integrals, for tests: adaptive QUADPACK on the real axis.

``J_n = integral_0^inf r(s) j_n(ell s)^2 ds`` with the impedance ratio written directly from
the Bessel and Hankel functions (``kve``, ``hankel2``, ``h2vp``; none of the package's
rearrangements), ``j_n`` from ``scipy.special.spherical_jn``, the real axis cut into
half-periods, and the tail beyond ``s_cut`` done by QUADPACK's Fourier-integral routine (QAWF).
Slow (about a second), deliberately simple, no contour deformation.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy import integrate, special


def ratio(s: float, s0: float) -> complex:
    """``z / (i omega rho a)`` at ``s = k a`` for ``s0 = k0 a``."""
    if s > s0:
        w = np.sqrt(s * s - s0 * s0)
        return special.kve(1, w) / (w * special.kve(0, w) + special.kve(1, w))
    x = np.sqrt(s0 * s0 - s * s)
    return -special.hankel2(1, x) / (x * special.h2vp(1, x))


def _quad(f, a, b, **kw):
    # QAWF (a Fourier weight on an infinite range) controls the absolute error only
    tol = {"epsabs": 1e-17} if "weight" in kw else {"epsabs": 0.0, "epsrel": 1e-13}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", integrate.IntegrationWarning)
        return integrate.quad(f, a, b, limit=400, **tol, **kw)[0]


def window_integral(ell: float, s0: float, order: int) -> complex:
    """``J_order`` for ``ell = L / 2a`` and ``s0 = k0 a`` by adaptive quadrature."""
    s_cut = s0 + max(8.0, 8.0 / ell)
    period = np.pi / (2.0 * ell)
    marks = {0.0, s0, s_cut}
    marks.update(np.arange(period, s_cut, period).tolist())
    edges = sorted(m for m in marks if 0.0 <= m <= s_cut)
    total = 0.0 + 0.0j

    def window(s):
        return special.spherical_jn(order, ell * s) ** 2

    for a, b in zip(edges[:-1], edges[1:]):
        if b <= a:
            continue
        total += _quad(lambda s: ratio(s, s0).real * window(s), a, b)
        if b <= s0:
            total += 1j * _quad(lambda s: ratio(s, s0).imag * window(s), a, b)
    # tail: j^2 = n(X) + p(X) cos 2X + q(X) sin 2X with X = ell s; the ratio is real there
    if order == 0:
        parts = (lambda x: 0.5 / x**2, lambda x: -0.5 / x**2, lambda x: 0.0 * x)
    else:
        parts = (lambda x: (1 + x**2) / (2 * x**4), lambda x: (x**2 - 1) / (2 * x**4), lambda x: -1.0 / x**3)
    n, p, q = parts
    total += _quad(lambda s: ratio(s, s0).real * n(ell * s), s_cut, np.inf)
    total += _quad(lambda s: ratio(s, s0).real * p(ell * s), s_cut, np.inf, weight="cos", wvar=2 * ell)
    total += _quad(lambda s: ratio(s, s0).real * q(ell * s), s_cut, np.inf, weight="sin", wvar=2 * ell)
    return total
