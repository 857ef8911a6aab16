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

from ..errors import ModelError
from ..limits import MAX_QUADRATURE_NODES
from .integrals import estimate_nodes, window_integrals
from .result import FluidCoefficients, check_nonnegative, check_optional_positive, check_positive

__all__ = ["baffled_cylinder", "TARGET_ERROR", "quadrature_nodes", "check_work"]

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
    a = check_positive("radius", radius, "size")
    L = check_positive("length", length, "size")
    rho = check_positive("density", density, "density")
    c = check_optional_positive("sound_speed", sound_speed, "sound_speed")
    f = check_nonnegative("frequency", frequency, "frequency")
    check_work(a, L, c, f)
    return _baffled_cylinder(a, L, rho, c, f)


def quadrature_nodes(radius: float, length: float, sound_speed: float | None, frequency: float) -> int:
    """Impedance evaluations of :func:`baffled_cylinder` on its production panel layout.

    An upper estimate computed from the layout rules without building it (the panels grow with
    ``L / a`` and with the number of wavelengths ``k0 L / 2 pi`` along the segment); the error
    control may refine the layout up to 4 times (:data:`_MAX_REFINE`).
    """
    s0 = 0.0 if sound_speed is None else 2.0 * math.pi * frequency * radius / sound_speed
    return estimate_nodes(0.5 * length / radius, s0)


def check_work(radius: float, length: float, sound_speed: float | None, frequency: float) -> None:
    """ModelError (naming ``length`` or ``frequency``) when the quadrature would need more than
    :data:`impstab.limits.MAX_QUADRATURE_NODES` nodes."""
    nodes = quadrature_nodes(radius, length, sound_speed, frequency)
    if nodes <= MAX_QUADRATURE_NODES:
        return
    if sound_speed is not None and frequency > 0 and 2.0 * math.pi * frequency * radius / sound_speed > 1.5:
        waves = frequency * length / sound_speed
        raise ModelError(
            "frequency", frequency,
            f"the segment is {waves:.3g} wavelengths long at this frequency: the quadrature would need "
            f"{nodes:.3g} nodes (limit {MAX_QUADRATURE_NODES:.0e}); lower the frequency or the length",
        )
    raise ModelError(
        "length", length,
        f"a segment {length / radius:.3g} radii long would need {nodes:.3g} quadrature nodes "
        f"(limit {MAX_QUADRATURE_NODES:.0e}); for so slender a segment strip theory is within 1.2 a / L of the baffled value",
    )


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
