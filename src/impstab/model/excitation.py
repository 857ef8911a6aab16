"""Harmonic loads on the propulsor for the forced response (``[excitation]`` of the model file).

The loads act on the body and move with it: each is given in body axes at a body point, and at a
static equilibrium that rotates the body by ``R0`` it is applied as ``R0 F`` at the arm ``R0 r``
(like the thrust). A harmonic component is ``F(t) = Re(F e^{i phi} e^{i omega t})``: amplitude
``F`` and phase ``phi``. The loads and their frequencies at a thrust are formed by
:func:`impstab.response.excitation_lines` (docs/isolation.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Unbalance", "BladeRate", "SpectrumLines", "Excitation"]

Array = NDArray[np.float64]


def _frozen(a, shape: tuple[int, ...] | None = None) -> Array:
    a = np.array(a, dtype=float)
    if shape is not None:
        a = a.reshape(shape)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class Unbalance:
    """A rotating unbalance on the shaft: force ``m e Omega^2`` at shaft rate.

    Parameters
    ----------
    mass : float
        Unbalance mass m (kg).
    eccentricity : float
        Its radius e (m).
    point : (3,) array or None
        Body point of the unbalance plane (m, from A); None is the thrust point (the propeller).
    phase_deg : float
        Angle of the unbalance at t = 0 (deg), from the first in-plane axis toward the second
        (:func:`impstab.response.excitation.plane_axes`).
    """

    mass: float
    eccentricity: float
    point: Array | None = None
    phase_deg: float = 0.0

    def __post_init__(self) -> None:
        if self.point is not None:
            object.__setattr__(self, "point", _frozen(self.point, (3,)))


@dataclass(frozen=True, eq=False)
class BladeRate:
    """Blade-rate force and moment: frequency ``harmonic * blades * |Omega| / 2 pi`` (Hz).

    Parameters
    ----------
    blades : int
        Blade count Z.
    amplitude : (6,) array
        Force (N) and moment (N m) amplitudes at ``point``, body axes, dof order.
    phase_deg : (6,) array
        Phase of each component (deg).
    harmonic : int
        Multiple of the blade-pass frequency (1 = blade rate).
    point : (3,) array or None
        Body point where the load acts (m, from A); None is the thrust point.
    """

    blades: int
    amplitude: Array
    phase_deg: Array = None  # type: ignore[assignment]
    harmonic: int = 1
    point: Array | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "amplitude", _frozen(self.amplitude, (6,)))
        phase = np.zeros(6) if self.phase_deg is None else self.phase_deg
        object.__setattr__(self, "phase_deg", _frozen(phase, (6,)))
        if self.point is not None:
            object.__setattr__(self, "point", _frozen(self.point, (3,)))


@dataclass(frozen=True, eq=False)
class SpectrumLines:
    """A user table of harmonic loads: one line per row.

    Parameters
    ----------
    frequency_hz : (n,) array
        Line frequencies (Hz).
    amplitude : (n, 6) array
        Force (N) and moment (N m) amplitudes at ``point``, body axes, dof order.
    phase_deg : (n, 6) array
        Phases (deg).
    point : (3,) array
        Body point where the loads act (m, from A).
    """

    frequency_hz: Array
    amplitude: Array
    phase_deg: Array = None  # type: ignore[assignment]
    point: Array = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        f = _frozen(self.frequency_hz).reshape(-1)
        object.__setattr__(self, "frequency_hz", f)
        object.__setattr__(self, "amplitude", _frozen(self.amplitude, (f.size, 6)))
        phase = np.zeros((f.size, 6)) if self.phase_deg is None else self.phase_deg
        object.__setattr__(self, "phase_deg", _frozen(phase, (f.size, 6)))
        object.__setattr__(self, "point", _frozen(np.zeros(3) if self.point is None else self.point, (3,)))


@dataclass(frozen=True, eq=False)
class Excitation:
    """The model's harmonic loads.

    Parameters
    ----------
    input : str
        Dof of the unit load of a transfer-function response (``impstab response`` without
        ``--input``); DESIGN's default is sway.
    unbalance, blade_rate : tuples
        Rotating unbalances and blade-rate loads (they follow the propeller speed law).
    spectrum : SpectrumLines or None
        A user table of lines.
    """

    input: str = "sway"
    unbalance: tuple[Unbalance, ...] = ()
    blade_rate: tuple[BladeRate, ...] = ()
    spectrum: SpectrumLines | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "unbalance", tuple(self.unbalance))
        object.__setattr__(self, "blade_rate", tuple(self.blade_rate))

    @property
    def has_loads(self) -> bool:
        """True when any unbalance, blade-rate load or spectrum line is given."""
        return bool(self.unbalance or self.blade_rate or self.spectrum is not None)

    @property
    def needs_shaft_rate(self) -> bool:
        """True when a load follows the shaft rate (unbalance or blade rate)."""
        return bool(self.unbalance or self.blade_rate)
