"""Result type of the fluid-loading models and validation of their inputs."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

from ..errors import ModelError

__all__ = ["FluidCoefficients", "check_positive", "check_nonnegative", "check_optional_positive"]


def _as_float(name: str, value: object) -> float:
    if isinstance(value, bool):
        raise ModelError(name, value, "must be a number")
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ModelError(name, value, "must be a number") from None


def check_positive(name: str, value: object) -> float:
    """``value`` as a float, or :class:`~impstab.errors.ModelError` unless finite and > 0."""
    x = _as_float(name, value)
    if not (math.isfinite(x) and x > 0.0):
        raise ModelError(name, value, "must be a finite number > 0")
    return x


def check_nonnegative(name: str, value: object) -> float:
    """``value`` as a float, or :class:`~impstab.errors.ModelError` unless finite and >= 0."""
    x = _as_float(name, value)
    if not (math.isfinite(x) and x >= 0.0):
        raise ModelError(name, value, "must be a finite number >= 0")
    return x + 0.0  # -0.0 -> 0.0


def check_optional_positive(name: str, value: object) -> float | None:
    """None, or ``value`` as a float checked by :func:`check_positive`."""
    if value is None:
        return None
    x = _as_float(name, value)
    if not (math.isfinite(x) and x > 0.0):
        raise ModelError(name, value, "must be a finite number > 0 (omit it for an incompressible fluid)")
    return x


@dataclass(frozen=True)
class FluidCoefficients:
    """Fluid loading of a rigid cylinder segment moving transversely (THEORY 9).

    Coefficients are about the segment centre for motion normal to the axis (sway/heave
    translation, pitch/yaw rotation); there is none in surge or roll (inviscid fluid) and no
    coupling between translation and rotation about the centre. With the time factor
    ``e^{i omega t}`` the fluid force on the segment is ``-(R + i omega m_a) V`` for a transverse
    velocity ``V``, and likewise the moment ``-(R_rot + i omega I_a) Omega``.

    Attributes
    ----------
    model : str
        ``"baffled-cylinder"`` or ``"strip"``.
    radius, length : float
        Cylinder radius ``a`` and segment length ``L`` (m).
    density : float
        Fluid density ``rho`` (kg/m^3).
    sound_speed : float or None
        Speed of sound ``c`` (m/s); None for an incompressible fluid.
    frequency : float
        Frequency ``f`` (Hz) at which the coefficients hold; ``omega = 2 pi f``.
    added_mass : float
        Transverse added mass ``m_a = Im Z_T / omega`` (kg).
    added_inertia : float
        Added rotary inertia ``I_a = Im Z_R / omega`` about a transverse axis through the segment
        centre (kg m^2).
    radiation_resistance : float or None
        ``R = Re Z_T >= 0`` (N s/m); None when the fluid is incompressible (no radiation), 0.0 at
        zero frequency.
    rotational_radiation_resistance : float or None
        ``R_rot = Re Z_R >= 0`` (N m s), same convention.
    error_estimate : float
        Conservative relative error estimate of the coefficients (the largest over the four);
        0 for the closed-form strip model.
    """

    model: str
    radius: float
    length: float
    density: float
    sound_speed: float | None
    frequency: float
    added_mass: float
    added_inertia: float
    radiation_resistance: float | None
    rotational_radiation_resistance: float | None
    error_estimate: float

    def __repr__(self) -> str:
        from ..display import fluid_coefficients_text

        return fluid_coefficients_text(self)

    @property
    def omega(self) -> float:
        """Angular frequency ``2 pi f`` (rad/s)."""
        return 2.0 * math.pi * self.frequency

    @property
    def wavenumber(self) -> float | None:
        """Acoustic wavenumber ``k0 = omega / c`` (rad/m); None when incompressible."""
        return None if self.sound_speed is None else self.omega / self.sound_speed

    @property
    def strip_added_mass(self) -> float:
        """Strip-theory added mass ``rho pi a^2 L`` (kg)."""
        return self.density * math.pi * self.radius**2 * self.length

    @property
    def strip_added_inertia(self) -> float:
        """Strip-theory added inertia ``rho pi a^2 L^3 / 12`` (kg m^2)."""
        return self.strip_added_mass * self.length**2 / 12.0

    @property
    def strip_ratio(self) -> float:
        """``added_mass / (rho pi a^2 L)``: 1 for strip theory, below 1 for a finite segment."""
        return self.added_mass / self.strip_added_mass

    @property
    def inertia_strip_ratio(self) -> float:
        """``added_inertia / (rho pi a^2 L^3 / 12)``."""
        return self.added_inertia / self.strip_added_inertia

    @property
    def loss_factor(self) -> float | None:
        """``R / (omega m_a)``: radiation resistance over added-mass reactance (None if no c)."""
        if self.radiation_resistance is None:
            return None
        if self.frequency == 0.0:
            return 0.0
        return self.radiation_resistance / (self.omega * self.added_mass)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-able dict: the coefficients, the settings and the derived ratios.

        Keys: ``added_mass`` (kg), ``added_inertia`` (kg m^2), ``radiation_resistance``
        (N s/m or None), ``rotational_radiation_resistance`` (N m s or None), ``model``,
        ``radius``, ``length`` (m), ``density`` (kg/m^3), ``sound_speed`` (m/s or None),
        ``frequency`` (Hz), ``omega`` (rad/s), ``strip_ratio``, ``inertia_strip_ratio``,
        ``loss_factor``, ``error_estimate``.
        """
        out = asdict(self)
        out.update(
            omega=self.omega,
            strip_ratio=self.strip_ratio,
            inertia_strip_ratio=self.inertia_strip_ratio,
            loss_factor=self.loss_factor,
        )
        keys = (
            "added_mass", "added_inertia", "radiation_resistance", "rotational_radiation_resistance",
            "model", "radius", "length", "density", "sound_speed", "frequency", "omega",
            "strip_ratio", "inertia_strip_ratio", "loss_factor", "error_estimate",
        )
        return {k: out[k] for k in keys}
