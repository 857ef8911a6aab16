"""Fluid loading of the model: the added-mass matrix about A (THEORY 9).

``model = "none"`` adds nothing, ``"matrix"`` takes a user 6 x 6 matrix about A, and the
hull-based models (``"baffled-cylinder"``, ``"strip"``) compute the transverse added mass and
added rotary inertia of the wetted cylinder segment and move them from the segment centre c to A
with ``M_A = T(c)^T diag(0, m_a, m_a, 0, I_a, I_a) T(c)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..kinematics import rigid_map6

__all__ = ["Hull", "FluidLoading", "segment_added_mass_matrix", "FLUID_MODELS"]

Array = NDArray[np.float64]

FLUID_MODELS = ("none", "baffled-cylinder", "strip", "matrix")


@dataclass(frozen=True, eq=False)
class Hull:
    """Wetted cylinder of radius ``radius`` and length ``length`` (m), centred at ``center`` (body frame)."""

    radius: float
    length: float
    center: Array

    def __repr__(self) -> str:
        from ..display import hull_text

        return hull_text(self)

    def __post_init__(self) -> None:
        c = np.array(self.center, dtype=float)
        c.setflags(write=False)
        object.__setattr__(self, "center", c)


def segment_added_mass_matrix(added_mass: float, added_inertia: float, center: Array) -> Array:
    """6 x 6 added mass about A of a segment with transverse ``m_a`` (kg) and ``I_a`` (kg m^2)
    about its centre ``c``: ``T(c)^T diag(0, m_a, m_a, 0, I_a, I_a) T(c)``."""
    t = rigid_map6(np.asarray(center, float))
    core = np.diag([0.0, added_mass, added_mass, 0.0, added_inertia, added_inertia])
    return t.T @ core @ t


@dataclass(frozen=True, eq=False)
class FluidLoading:
    """Fluid loading settings and the resulting added-mass matrix about A.

    Parameters
    ----------
    model : str
        One of ``"none"``, ``"baffled-cylinder"``, ``"strip"``, ``"matrix"``.
    density : float or None
        Fluid density rho (kg/m^3).
    sound_speed : float or None
        Speed of sound c (m/s); None means incompressible.
    added_mass : (6, 6) array
        Added-mass matrix about A in the body frame (kg, kg m, kg m^2), at zero frequency for
        the hull-based models.
    """

    model: str = "none"
    density: float | None = None
    sound_speed: float | None = None
    added_mass: Array = None  # type: ignore[assignment]
    hull: Hull | None = None

    def __repr__(self) -> str:
        from ..display import fluid_loading_text

        return fluid_loading_text(self)

    def __post_init__(self) -> None:
        a = np.zeros((6, 6)) if self.added_mass is None else np.array(self.added_mass, dtype=float)
        a.setflags(write=False)
        object.__setattr__(self, "added_mass", a)

    @classmethod
    def from_hull(
        cls, model: str, hull: Hull, density: float, sound_speed: float | None = None
    ) -> "FluidLoading":
        """Build the hull-based added mass (``"baffled-cylinder"`` or ``"strip"``)."""
        from .. import fluid as _fluid

        if model == "strip":
            coeffs = _fluid.strip_theory(radius=hull.radius, length=hull.length, density=density)
        elif model == "baffled-cylinder":
            coeffs = _fluid.baffled_cylinder(
                radius=hull.radius, length=hull.length, density=density, sound_speed=None, frequency=0.0
            )
        else:  # pragma: no cover - guarded by the schema
            raise ValueError(f"fluid.model {model!r} is not hull-based")
        mat = segment_added_mass_matrix(coeffs.added_mass, coeffs.added_inertia, hull.center)
        return cls(model=model, density=density, sound_speed=sound_speed, added_mass=mat, hull=hull)

    @property
    def compressible(self) -> bool:
        """True when the coefficients depend on frequency (baffled cylinder with a sound speed)."""
        return self.model == "baffled-cylinder" and self.sound_speed is not None

    def coefficients_at(self, frequency_hz: float = 0.0) -> tuple[Array, Array]:
        """Added mass and radiation damping about A (body frame, 6 x 6) at ``frequency_hz``.

        Frequency-independent models return the zero-frequency added mass and no damping.
        """
        if not self.compressible or frequency_hz <= 0.0 or self.hull is None:
            return self.added_mass, np.zeros((6, 6))
        from .. import fluid as _fluid

        h = self.hull
        c = _fluid.baffled_cylinder(
            radius=h.radius, length=h.length, density=self.density, sound_speed=self.sound_speed,
            frequency=float(frequency_hz),
        )
        mass = segment_added_mass_matrix(c.added_mass, c.added_inertia, h.center)
        damp = segment_added_mass_matrix(c.radiation_resistance or 0.0, c.rotational_radiation_resistance or 0.0, h.center)
        return mass, damp
