"""Compliant mounts between the hull and the propulsor (THEORY 3).

Every mount is stored in one general form: a 6 x 6 stiffness and a 6 x 6 damping acting on the
deflection of its body end (translation of the attachment point, then rotation), in the hull
frame. The paper's mount (axial and shear springs and dashpots along a unit axis ``a``) is the
special case ``k = k_ax a a^T + k_sh (I - a a^T)`` in the translation block and zero rotation
block; a beam or measured mount gives the full 6 x 6 matrix at its body end.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..linear.kinematics import rigid_map6

__all__ = ["Mount", "axial_shear_matrix", "ring_positions", "elastic_stiffness", "mount_damping"]

Array = NDArray[np.float64]


def _frozen(a: Array) -> Array:
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


def axial_shear_matrix(axis: Array, axial: float, shear: float) -> Array:
    """``axial a a^T + shear (I - a a^T)`` for a unit axis ``a`` (3 x 3)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    aa = np.outer(a, a)
    return axial * aa + shear * (np.eye(3) - aa)


@dataclass(frozen=True, eq=False)
class Mount:
    """One massless mount.

    Parameters
    ----------
    position : (3,) array
        Attachment point on the body, body frame, from A (m). At rest the hull end is at the
        same point.
    stiffness : (6, 6) array
        Stiffness of the body end, hull frame: ``[f; m] = -stiffness @ [d; phi]`` (N/m, N, N m/rad).
    damping : (6, 6) array
        Viscous damping of the body end, same layout (N s/m, ...).
    """

    position: Array
    stiffness: Array
    damping: Array

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", _frozen(self.position))
        object.__setattr__(self, "stiffness", _frozen(self.stiffness))
        object.__setattr__(self, "damping", _frozen(self.damping))

    @classmethod
    def axial_shear(
        cls,
        position: Array,
        axis: Array = (1.0, 0.0, 0.0),
        k_axial: float = 0.0,
        k_shear: float = 0.0,
        c_axial: float = 0.0,
        c_shear: float = 0.0,
    ) -> "Mount":
        """The paper's mount: uncoupled axial and shear spring and dashpot along ``axis``."""
        k = np.zeros((6, 6))
        c = np.zeros((6, 6))
        k[:3, :3] = axial_shear_matrix(axis, k_axial, k_shear)
        c[:3, :3] = axial_shear_matrix(axis, c_axial, c_shear)
        return cls(np.asarray(position, float), k, c)

    @property
    def has_rotational_stiffness(self) -> bool:
        """True when the mount resists rotation or couples it (a full 6 x 6 mount)."""
        return bool(np.any(self.stiffness[3:, :] != 0) or np.any(self.stiffness[:, 3:] != 0))


def ring_positions(count: int, radius: float, x: float, start_angle_deg: float) -> Array:
    """Attachment points of ``count`` mounts equally spaced on a ring (angle from +y toward +z)."""
    ang = np.deg2rad(start_angle_deg) + 2.0 * np.pi * np.arange(count) / count
    return np.column_stack([np.full(count, float(x)), radius * np.cos(ang), radius * np.sin(ang)])


def _condense(mounts, which: str) -> Array:
    out = np.zeros((6, 6))
    for mt in mounts:
        t = rigid_map6(mt.position)
        out += t.T @ getattr(mt, which) @ t
    return out


def elastic_stiffness(mounts: tuple[Mount, ...] | list[Mount]) -> Array:
    """Condensed elastic stiffness about A, ``K_c = sum T6_i^T k_i T6_i`` (THEORY 3)."""
    return _condense(mounts, "stiffness")


def mount_damping(mounts: tuple[Mount, ...] | list[Mount]) -> Array:
    """Condensed damping about A, ``D = sum T6_i^T c_i T6_i``."""
    return _condense(mounts, "damping")
