"""Rigid body of the propulsor: mass, centre of gravity and inertia (THEORY 2).

All quantities are in the body frame, about the reference point A unless said otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..kinematics import skew

__all__ = ["RigidBody", "rigid_body_mass_matrix", "rigid_body_coriolis_matrix"]

Array = NDArray[np.float64]


def _frozen(a: Array) -> Array:
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class RigidBody:
    """Mass properties of the propulsor.

    Parameters
    ----------
    mass : float
        Mass m (kg).
    cg : (3,) array
        Centre of gravity G from the reference point A, body frame (m).
    inertia_cg : (3, 3) array
        Inertia tensor about G, body axes (kg m^2), symmetric positive definite.
    """

    mass: float
    cg: Array
    inertia_cg: Array

    def __repr__(self) -> str:
        from ..display import body_text

        return body_text(self)

    def __post_init__(self) -> None:
        object.__setattr__(self, "cg", _frozen(self.cg))
        object.__setattr__(self, "inertia_cg", _frozen(self.inertia_cg))

    @property
    def inertia_a(self) -> Array:
        """Inertia tensor about A: ``I_A = I_G - m S(r_G) S(r_G)`` (parallel axes, paper eq. 13)."""
        s = skew(self.cg)
        return self.inertia_cg - self.mass * (s @ s)

    def mass_matrix(self) -> Array:
        """The 6 x 6 rigid-body mass matrix ``M_RB`` about A (paper eq. 17); a new array each call."""
        hit = self.__dict__.get("_mass_matrix")
        if hit is None:  # the body is immutable: formed once
            hit = _frozen(rigid_body_mass_matrix(self.mass, self.cg, self.inertia_a))
            object.__setattr__(self, "_mass_matrix", hit)
        return hit.copy()


def rigid_body_mass_matrix(mass: float, cg: Array, inertia_a: Array) -> Array:
    """``M_RB = [[m I, -m S(r_G)], [m S(r_G), I_A]]`` (kg, kg m, kg m^2)."""
    s = skew(cg)
    m = np.zeros((6, 6))
    m[:3, :3] = mass * np.eye(3)
    m[:3, 3:] = -mass * s
    m[3:, :3] = mass * s
    m[3:, 3:] = inertia_a
    return m


def rigid_body_coriolis_matrix(mass: float, cg: Array, inertia_a: Array, nu: Array) -> Array:
    """Skew-symmetric Coriolis-centripetal matrix ``C_RB(nu)`` (THEORY 2).

    ``C_RB(nu) @ nu`` equals the Newton-Euler terms ``m (w x v + w x (w x r_G))`` (force) and
    ``w x I_A w + m r_G x (w x v)`` (moment about A), with ``nu = (v, w)`` in the body frame.
    """
    v, w = np.asarray(nu[:3], float), np.asarray(nu[3:], float)
    sg = skew(cg)
    c = np.zeros((6, 6))
    c[:3, 3:] = -mass * skew(v) - mass * skew(w) @ sg
    c[3:, :3] = -mass * skew(v) + mass * sg @ skew(w)
    c[3:, 3:] = -skew(inertia_a @ w)
    return c
