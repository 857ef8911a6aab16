"""Strip theory: the two-dimensional added mass of a circle applied along the segment.

Every section of the segment is loaded as an infinitely long cylinder would be,
``rho pi a^2`` per unit length, so ``m_a = rho pi a^2 L`` and ``I_a = rho pi a^2 L^3 / 12``
about the centre. It ignores the end relief of a finite segment, which the baffled-cylinder model
captures (``m_a ~ rho pi a^2 (L - 1.18 a)`` for long segments), and it has no radiation.
"""

from __future__ import annotations

import math

from .result import FluidCoefficients, check_positive

__all__ = ["strip_theory"]


def strip_theory(radius: float, length: float, density: float = 1025.0) -> FluidCoefficients:
    """Strip-theory coefficients of a cylinder segment (upper bounds of the baffled values).

    Parameters
    ----------
    radius : float
        Cylinder radius ``a`` (m), finite and > 0.
    length : float
        Segment length ``L`` (m), finite and > 0.
    density : float, default 1025.0
        Fluid density ``rho`` (kg/m^3), finite and > 0.

    Returns
    -------
    FluidCoefficients
        ``added_mass = rho pi a^2 L`` (kg), ``added_inertia = rho pi a^2 L^3 / 12`` (kg m^2),
        no radiation resistance (None), frequency 0, ``error_estimate`` 0.
    """
    a = check_positive("radius", radius, "size")
    L = check_positive("length", length, "size")
    rho = check_positive("density", density, "density")
    mass = rho * math.pi * a * a * L
    return FluidCoefficients(
        model="strip",
        radius=a,
        length=L,
        density=rho,
        sound_speed=None,
        frequency=0.0,
        added_mass=mass,
        added_inertia=mass * L * L / 12.0,
        radiation_resistance=None,
        rotational_radiation_resistance=None,
        error_estimate=0.0,
    )
