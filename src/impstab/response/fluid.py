"""Compressible fluid loading at every frequency of a forced response (THEORY 9).

With a sound speed the baffled-cylinder added mass ``m_a``, added inertia ``I_a`` and radiation
resistances ``R``, ``R_rot`` depend on frequency. One evaluation of
:func:`impstab.fluid.baffled_cylinder` takes milliseconds (its wavenumber integrals are accurate
to about 1e-12), so a sweep of 1e4 frequencies would spend tens of seconds there. Instead:

* up to :data:`DIRECT_LIMIT` distinct frequencies: each is evaluated directly;
* more (unless the panels below would need more evaluations than that): the four coefficients (as ``m_a``, ``R / omega``, ``I_a``, ``R_rot / omega``, all smooth
  in frequency and finite at 0) are interpolated on Chebyshev panels of degree :data:`DEGREE`
  over the analysed range, each panel halved until its last three Chebyshev coefficients are
  below :data:`TOLERANCE` times the panel's ``|Z_T| / omega`` (``|Z_R| / omega`` for rotation).
  The accepted tail bounds the interpolation error; it is reported as ``interpolation_error``
  and checked against direct evaluations in tests/response/test_fluid_response.py.

The coefficients enter the dynamic stiffness as ``i omega D_f - omega^2 M_f`` with
``M_f = T(c)^T diag(0, m_a, m_a, 0, I_a, I_a) T(c)`` and ``D_f`` likewise with the resistances,
rotated with the body (``blockdiag(R0, R0)``), in place of the zero-frequency added mass that the
linearization holds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev as cheb
from numpy.typing import NDArray

from ..kinematics import block_rotate
from ..model.fluid import segment_added_mass_matrix
from ..model.model import Model

__all__ = ["FluidSpectrum", "fluid_spectrum", "fluid_dynamic_stiffness", "DIRECT_LIMIT", "TOLERANCE", "DEGREE"]

Array = NDArray[np.float64]

DIRECT_LIMIT = 48
TOLERANCE = 1e-10
DEGREE = 16
_MAX_DEPTH = 40


@dataclass(frozen=True, eq=False)
class FluidSpectrum:
    """Segment coefficients at each analysed frequency.

    Attributes
    ----------
    frequency_hz : (nf,) Hz
    added_mass : (nf,) kg;  added_inertia : (nf,) kg m^2 (about the segment centre)
    radiation_resistance : (nf,) N s/m;  rotational_radiation_resistance : (nf,) N m s
    method : {"direct", "chebyshev"}
    evaluations : int
        Calls of the wavenumber integrals.
    interpolation_error : float
        Bound of the relative interpolation error (0 for direct evaluation).
    quadrature_error : float
        Largest error estimate of the wavenumber integrals used.
    """

    frequency_hz: Array
    added_mass: Array
    added_inertia: Array
    radiation_resistance: Array
    rotational_radiation_resistance: Array
    method: str
    evaluations: int
    interpolation_error: float
    quadrature_error: float


def _direct(model: Model, f: Array) -> tuple[Array, float]:
    """``(len(f), 4)`` values ``m_a, R / omega, I_a, R_rot / omega`` and the quadrature error."""
    from .. import fluid as _fluid

    h, fl = model.hull, model.fluid
    out = np.empty((f.size, 4))
    err = 0.0
    for i, fi in enumerate(f):
        c = _fluid.baffled_cylinder(h.radius, h.length, fl.density, fl.sound_speed, float(fi))
        w = 2.0 * np.pi * fi
        out[i] = (
            c.added_mass, c.radiation_resistance / w if w > 0 else 0.0,
            c.added_inertia, c.rotational_radiation_resistance / w if w > 0 else 0.0,
        )
        err = max(err, c.error_estimate)
    return out, err


def _chebyshev(model: Model, f: Array) -> tuple[Array, int, float, float] | None:
    """Adaptive Chebyshev panels over ``[f.min(), f.max()]`` evaluated at ``f``; None when the
    panels would need more evaluations than ``f`` has frequencies (then direct evaluation is cheaper).

    A panel is accepted when its Chebyshev tail is below :data:`TOLERANCE`, or below 100 times
    the quadrature error of its nodes where that is larger (the values carry that error anyway).
    """
    x = np.cos(np.pi * np.arange(DEGREE + 1) / DEGREE)  # Chebyshev-Lobatto points on [-1, 1]
    out = np.empty((f.size, 4))
    evaluations = 0
    tail_max = 0.0
    quad = 0.0
    stack = [(float(f.min()), float(f.max()), 0)]
    while stack:
        lo, hi, depth = stack.pop()
        nodes = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x
        vals, err = _direct(model, nodes)
        evaluations += nodes.size
        if evaluations > f.size:
            return None
        quad = max(quad, err)
        coef = cheb.chebfit(x, vals, DEGREE)              # (DEGREE + 1, 4), exact interpolation
        scale_t = np.hypot(vals[:, 0], vals[:, 1]).max()
        scale_r = np.hypot(vals[:, 2], vals[:, 3]).max()
        scale = np.array([scale_t, scale_t, scale_r, scale_r])
        tail = (np.abs(coef[-3:]).max(axis=0) / np.where(scale > 0, scale, 1.0)).max()
        if tail > max(TOLERANCE, 100.0 * err) and depth < _MAX_DEPTH and hi > lo:
            mid = 0.5 * (lo + hi)
            stack += [(lo, mid, depth + 1), (mid, hi, depth + 1)]
            continue
        tail_max = max(tail_max, tail)
        inside = (f >= lo) & (f <= hi)
        t = (2.0 * f[inside] - lo - hi) / (hi - lo) if hi > lo else np.zeros(inside.sum())
        out[inside] = cheb.chebval(t, coef).T
    return out, evaluations, tail_max, quad


def fluid_spectrum(model: Model, frequency_hz: Array) -> FluidSpectrum | None:
    """Baffled-cylinder coefficients at each frequency (Hz); None unless the fluid is compressible."""
    if not model.fluid.compressible or model.hull is None:
        return None
    f = np.asarray(frequency_hz, dtype=float).reshape(-1)
    uniq, inverse = np.unique(f, return_inverse=True)
    panels = _chebyshev(model, uniq) if uniq.size > DIRECT_LIMIT else None
    if panels is None:
        vals, quad = _direct(model, uniq)
        method, evaluations, interp = "direct", uniq.size, 0.0
    else:
        vals, evaluations, interp, quad = panels
        method = "chebyshev"
    vals = vals[inverse]
    w = 2.0 * np.pi * f
    return FluidSpectrum(
        frequency_hz=f, added_mass=vals[:, 0], radiation_resistance=vals[:, 1] * w,
        added_inertia=vals[:, 2], rotational_radiation_resistance=vals[:, 3] * w,
        method=method, evaluations=int(evaluations), interpolation_error=float(interp), quadrature_error=float(quad),
    )


def fluid_dynamic_stiffness(model: Model, spectrum: FluidSpectrum, rotation: Array) -> tuple[NDArray, NDArray, NDArray]:
    """The fluid's change of the dynamic stiffness at each frequency, hull axes at the pose.

    Returns ``X (nf, 6, 6)`` complex, ``i omega D_f - omega^2 (M_f - M_f(0))``, to add to
    ``K + i omega (D + G) - omega^2 M`` of the linearization (which holds the zero-frequency added
    mass ``M_f(0)``), and the rotated unit patterns ``P_T``, ``P_R`` (``M_f = m_a P_T + I_a P_R``).
    """
    c = model.hull.center  # type: ignore[union-attr]
    p_t = block_rotate(segment_added_mass_matrix(1.0, 0.0, c), rotation)
    p_r = block_rotate(segment_added_mass_matrix(0.0, 1.0, c), rotation)
    m0 = block_rotate(np.asarray(model.fluid.added_mass, float), rotation)
    w = 2.0 * np.pi * spectrum.frequency_hz
    w_ = w[:, None, None]
    mass = spectrum.added_mass[:, None, None] * p_t + spectrum.added_inertia[:, None, None] * p_r
    damp = spectrum.radiation_resistance[:, None, None] * p_t + spectrum.rotational_radiation_resistance[:, None, None] * p_r
    extra = 1j * w_ * damp - w_**2 * (mass - m0)
    return extra, p_t, p_r
