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

from ..kinematics import rigid_map6

__all__ = ["Mount", "axial_shear_matrix", "ring_positions", "condense", "elastic_stiffness", "mount_damping"]

Array = NDArray[np.float64]


def _frozen(a: Array) -> Array:
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


def axial_shear_matrix(axis: Array, axial: float | Array, shear: float | Array) -> Array:
    """``axial a a^T + shear (I - a a^T)`` for a unit axis ``a`` (3 x 3).

    Broadcasts: ``axis (..., 3)`` and ``axial``, ``shear`` of shape ``(...)`` give ``(..., 3, 3)``
    (a design study assembles all its variants' mounts in one call).
    """
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    aa = a[..., :, None] * a[..., None, :]
    axial = np.asarray(axial, dtype=float)[..., None, None]
    shear = np.asarray(shear, dtype=float)[..., None, None]
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
    axis : (3,) array
        Unit mount axis, hull frame (default x): splits deflections and forces into axial and
        shear parts.
    rated_force, max_deflection : float or None
        Static force rating (N) and static deflection limit (m) of the mount, for the static
        load check (:func:`impstab.response.static_mount_loads`).
    """

    position: Array
    stiffness: Array
    damping: Array
    axis: Array = (1.0, 0.0, 0.0)  # type: ignore[assignment]
    rated_force: float | None = None
    max_deflection: float | None = None

    def __repr__(self) -> str:
        from ..display import mount_text

        return mount_text(self)

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", _frozen(self.position))
        object.__setattr__(self, "stiffness", _frozen(self.stiffness))
        object.__setattr__(self, "damping", _frozen(self.damping))
        axis = np.asarray(self.axis, dtype=float)
        object.__setattr__(self, "axis", _frozen(axis / np.linalg.norm(axis)))

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
        return cls(np.asarray(position, float), k, c, axis)

    @property
    def has_rotational_stiffness(self) -> bool:
        """True when the mount resists rotation or couples it (a full 6 x 6 mount)."""
        return bool(np.any(self.stiffness[3:, :] != 0) or np.any(self.stiffness[:, 3:] != 0))


def ring_positions(count: int, radius: float | Array, x: float | Array, start_angle_deg: float | Array) -> Array:
    """Attachment points of ``count`` mounts equally spaced on a ring (angle from +y toward +z).

    Returns ``(count, 3)``; array ``radius``, ``x``, ``start_angle_deg`` of a common shape
    ``(...)`` give ``(..., count, 3)``.
    """
    radius, x, start = (np.asarray(v, dtype=float)[..., None] for v in (radius, x, start_angle_deg))
    ang = np.deg2rad(start) + 2.0 * np.pi * np.arange(count) / count
    radius, x, ang = np.broadcast_arrays(radius, x, ang)
    return np.stack([x, radius * np.cos(ang), radius * np.sin(ang)], axis=-1)


def condense(positions: Array, matrices: Array) -> Array:
    """``sum_i T6_i^T k_i T6_i``: mount matrices at their body ends condensed about A.

    ``positions (..., nm, 3)`` and ``matrices (..., nm, 6, 6)`` give ``(..., 6, 6)`` (leading
    axes: designs of a study).
    """
    t = rigid_map6(np.asarray(positions, dtype=float))
    return (np.swapaxes(t, -1, -2) @ np.asarray(matrices, dtype=float) @ t).sum(axis=-3)


def _condense(mounts, which: str) -> Array:
    if not mounts:
        return np.zeros((6, 6))
    return condense(np.array([m.position for m in mounts]), np.array([getattr(m, which) for m in mounts]))


def elastic_stiffness(mounts: tuple[Mount, ...] | list[Mount]) -> Array:
    """Condensed elastic stiffness about A, ``K_c = sum T6_i^T k_i T6_i`` (THEORY 3)."""
    return _condense(mounts, "stiffness")


def mount_damping(mounts: tuple[Mount, ...] | list[Mount]) -> Array:
    """Condensed damping about A, ``D = sum T6_i^T c_i T6_i``."""
    return _condense(mounts, "damping")
