"""Added mass, added rotary inertia and radiation resistance of a cylinder segment in a baffle.

The wetted hull is idealised as the segment ``|x| < L/2`` of an infinite cylinder of radius
``a`` whose remainder is rigid and at rest (a cylindrical baffle), moving as a rigid body
transversely (THEORY 9). With the time factor ``e^{i omega t}`` and ``k0 = omega / c``:

    Z_T = a L^2 integral_0^inf z(k) sinc^2(kL/2) dk,     Z_R = a integral_0^inf z(k) |G(k)|^2 dk,

``m_a = Im Z_T / omega``, ``I_a = Im Z_R / omega``, ``R = Re Z_T``, ``R_rot = Re Z_R``, with
``z(k)`` the modal specific impedance of :mod:`impstab.fluid.impedance`. In the incompressible
limit ``z = i omega rho g(k)`` and
``m_a = rho a L^2 integral g sinc^2 dk``, ``I_a = rho a integral g |G|^2 dk``.

The integrals are evaluated by :func:`impstab.fluid.integrals.window_integrals` to about 1e-12
relative (an estimate is returned); results are cached per set of arguments.
"""

from __future__ import annotations

import math
from functools import lru_cache

from .integrals import window_integrals
from .result import FluidCoefficients, check_nonnegative, check_optional_positive, check_positive

__all__ = ["baffled_cylinder", "TARGET_ERROR"]

TARGET_ERROR = 1e-9  # the panel layout is refined until the (conservative) estimate is below
_MAX_REFINE = 4


def baffled_cylinder(
    radius: float,
    length: float,
    density: float = 1025.0,
    sound_speed: float | None = None,
    frequency: float = 0.0,
) -> FluidCoefficients:
    """Fluid coefficients of a rigid cylinder segment in a rigid cylindrical baffle.

    Parameters
    ----------
    radius : float
        Cylinder radius ``a`` (m), finite and > 0.
    length : float
        Segment (wetted hull) length ``L`` (m), finite and > 0.
    density : float, default 1025.0
        Fluid density ``rho`` (kg/m^3), finite and > 0 (sea water by default).
    sound_speed : float or None, default None
        Speed of sound ``c`` (m/s), finite and > 0; None for an incompressible fluid, whose
        coefficients do not depend on frequency and have no radiation resistance.
    frequency : float, default 0.0
        Frequency ``f`` in Hz (not rad/s), finite and >= 0; ``omega = 2 pi f``. At 0 the
        compressible coefficients equal the incompressible ones and the resistances are 0.

    Returns
    -------
    FluidCoefficients
        ``added_mass`` (kg), ``added_inertia`` (kg m^2, about the segment centre),
        ``radiation_resistance`` (N s/m) and ``rotational_radiation_resistance`` (N m s), the
        latter two None when ``sound_speed`` is None.

    Raises
    ------
    impstab.errors.ModelError
        An input that breaks its rule; the message names the field.

    Examples
    --------
    >>> r = baffled_cylinder(radius=0.15, length=0.8)
    >>> round(r.strip_ratio, 4)
    0.8142
    """
    a = check_positive("radius", radius)
    L = check_positive("length", length)
    rho = check_positive("density", density)
    c = check_optional_positive("sound_speed", sound_speed)
    f = check_nonnegative("frequency", frequency)
    return _baffled_cylinder(a, L, rho, c, f)


@lru_cache(maxsize=4096)
def _baffled_cylinder(a: float, L: float, rho: float, c: float | None, f: float) -> FluidCoefficients:
    omega = 2.0 * math.pi * f
    s0 = 0.0 if c is None else omega * a / c
    ell = 0.5 * L / a
    refine = 1
    while True:
        result = window_integrals(ell, s0, refine=refine)
        error = max(result.errors)
        if error <= TARGET_ERROR or refine >= _MAX_REFINE:
            break
        refine *= 2
    j_translation, j_rotation = result.values
    scale_t = rho * a * L**2        # Z_T = i omega scale_t J_0
    scale_r = rho * a * L**4 / 4.0  # Z_R = i omega scale_r J_1
    if c is None:
        resistance = rotational = None
    else:
        resistance = -omega * scale_t * j_translation.imag + 0.0
        rotational = -omega * scale_r * j_rotation.imag + 0.0
    return FluidCoefficients(
        model="baffled-cylinder",
        radius=a,
        length=L,
        density=rho,
        sound_speed=c,
        frequency=f,
        added_mass=scale_t * j_translation.real,
        added_inertia=scale_r * j_rotation.real,
        radiation_resistance=resistance,
        rotational_radiation_resistance=rotational,
        error_estimate=error,
    )
