"""Thrust (a follower force) and the spinning propeller (THEORY 4)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Thrust", "Propeller"]

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class Thrust:
    """Thrust load of magnitude T (the load parameter) acting on the body.

    Parameters
    ----------
    point : (3,) array
        Point of application, body frame, from A (m).
    direction : (3,) array
        Unit direction, body frame.
    tangency : float
        Follower fraction eta in [0, 1]: the force is ``T (eta R e + (1 - eta) e)``;
        1 is a pure follower force, 0 a force of fixed direction (conservative).
    operating : float or None
        Design thrust (N); margins are reported against it.
    preload_stiffness : bool
        Include the mount-preload geometric stiffness ``-sum S(f_i) S(rho_i)``.
    """

    point: Array
    direction: Array
    tangency: float = 1.0
    operating: float | None = None
    preload_stiffness: bool = True

    def __repr__(self) -> str:
        from ..display import thrust_text

        return thrust_text(self)

    def __post_init__(self) -> None:
        p = np.array(self.point, dtype=float)
        d = np.array(self.direction, dtype=float)
        d = d / np.linalg.norm(d)
        p.setflags(write=False)
        d.setflags(write=False)
        object.__setattr__(self, "point", p)
        object.__setattr__(self, "direction", d)


@dataclass(frozen=True)
class Propeller:
    """Spinning propeller: polar inertia J_p (kg m^2) and spin speed Omega (rad/s).

    ``speed_law = "constant"`` keeps Omega fixed; ``"sqrt-thrust"`` scales it as
    ``speed * sqrt(T / operating)`` (propeller law T ~ n^2). The angular momentum
    ``h = J_p Omega e`` lies along the thrust direction ``e``.
    """

    polar_inertia: float = 0.0
    speed: float = 0.0
    speed_law: str = "constant"

    def spin(self, thrust: float, operating: float | None) -> float:
        """Spin speed Omega (rad/s) at thrust T (N)."""
        if self.speed_law == "sqrt-thrust":
            if not operating:
                raise ValueError("propeller.speed_law 'sqrt-thrust' needs thrust.operating > 0")
            return self.speed * math.sqrt(max(thrust, 0.0) / operating)
        return self.speed

    def angular_momentum(self, thrust: float, operating: float | None) -> float:
        """Magnitude J_p Omega (kg m^2/s) of the rotor angular momentum at thrust T."""
        return self.polar_inertia * self.spin(thrust, operating)
