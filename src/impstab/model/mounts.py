"""Compliant mounts between the hull and the propulsor (THEORY 3).

Every mount is stored in one general form: a 6 x 6 stiffness and a 6 x 6 damping acting on the
deflection of its body end (translation of the attachment point, then rotation), in the hull
frame. The paper's mount (axial and shear springs and dashpots along a unit axis ``a``) is the
special case ``k = k_ax a a^T + k_sh (I - a a^T)`` in the translation block and zero rotation
block; a beam or measured mount gives the full 6 x 6 matrix at its body end.

A mount may also carry a :class:`NonlinearLaw` (cubic axial and shear springs, a snubber) that
adds to the forces of its linear springs on the translation deflection of its body end; see
:mod:`impstab.model.mount_law` for the force law.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..kinematics import rigid_map6
from .beam import BeamMount

__all__ = ["Mount", "NonlinearLaw", "axial_shear_matrix", "ring_positions", "condense", "elastic_stiffness", "mount_damping"]

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
class NonlinearLaw:
    """Nonlinear part of a mount's force law (DESIGN "Model file, round 2 additions").

    Parameters
    ----------
    axis : (3,) array
        Mount axis ``a`` (hull frame; normalised here).
    k3_axial : float
        Cubic axial stiffness (N/m^3): axial force ``-k3_axial d_a^3`` (negative: softening).
    k3_shear : float
        Cubic shear stiffness (N/m^3): shear force ``-k3_shear |d_s|^2 d_s``.
    snubber_clearance : float
        Clearance ``c`` (m) beyond which the motion limiter engages on ``|d|``; 0: no snubber.
    snubber_stiffness : float
        Snubber stiffness (N/m): force ``-k_snub ramp(|d| - c) d / |d|``, ramp smoothed (C2)
        over ``0.05 c``. Required > 0 with a clearance, and 0 without one.
    """

    axis: Array
    k3_axial: float = 0.0
    k3_shear: float = 0.0
    snubber_clearance: float = 0.0
    snubber_stiffness: float = 0.0

    def __post_init__(self) -> None:
        axis = np.asarray(self.axis, dtype=float).reshape(3)
        norm = float(np.linalg.norm(axis))
        if not norm > 0.0 or not np.isfinite(norm):
            raise ValueError(f"NonlinearLaw.axis must be a finite non-zero vector, not {axis.tolist()}")
        object.__setattr__(self, "axis", _frozen(axis / norm))
        for name in ("k3_axial", "k3_shear", "snubber_clearance", "snubber_stiffness"):
            value = float(getattr(self, name))
            if not np.isfinite(value):
                raise ValueError(f"NonlinearLaw.{name} must be finite, not {value}")
            object.__setattr__(self, name, value)
        if self.snubber_clearance < 0.0 or self.snubber_stiffness < 0.0:
            raise ValueError("NonlinearLaw: snubber clearance and stiffness must be >= 0")
        if (self.snubber_clearance > 0.0) != (self.snubber_stiffness > 0.0):
            raise ValueError("NonlinearLaw: a snubber needs both a clearance > 0 and a stiffness > 0")

    @property
    def has_snubber(self) -> bool:
        return self.snubber_clearance > 0.0

    @property
    def is_linear(self) -> bool:
        """True when the law adds nothing (no cubic term, no snubber)."""
        return self.k3_axial == 0.0 and self.k3_shear == 0.0 and not self.has_snubber

    def packed(self) -> Array:
        """The law as a row of :data:`impstab.model.mount_law.N_LAW` numbers for the kernels."""
        from .mount_law import LAW_AXIS, LAW_CLEARANCE, LAW_K3_AXIAL, LAW_K3_SHEAR, LAW_SNUBBER, N_LAW

        row = np.zeros(N_LAW)
        row[LAW_AXIS:LAW_AXIS + 3] = self.axis
        row[LAW_K3_AXIAL], row[LAW_K3_SHEAR] = self.k3_axial, self.k3_shear
        row[LAW_CLEARANCE], row[LAW_SNUBBER] = self.snubber_clearance, self.snubber_stiffness
        return row


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
    nonlinear : NonlinearLaw or None
        Cubic springs and snubber acting on the translation deflection, in addition to
        ``stiffness``; None (or a linear law): the mount is linear.
    beam : BeamMount or None
        The Timoshenko beam the mount is (:mod:`impstab.model.beam`), along ``axis``; then
        ``stiffness`` is its clamped-free tip stiffness ``K_tip``, and a beam with mass brings
        internal finite-element dofs to the stability analysis.
    """

    position: Array
    stiffness: Array
    damping: Array
    axis: Array = (1.0, 0.0, 0.0)  # type: ignore[assignment]
    rated_force: float | None = None
    max_deflection: float | None = None
    nonlinear: NonlinearLaw | None = None
    beam: BeamMount | None = None

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
        k3_axial: float = 0.0,
        k3_shear: float = 0.0,
        snubber_clearance: float = 0.0,
        snubber_stiffness: float = 0.0,
    ) -> "Mount":
        """The paper's mount: uncoupled axial and shear spring and dashpot along ``axis``, with
        an optional nonlinear law (cubic springs, snubber; see :class:`NonlinearLaw`)."""
        k = np.zeros((6, 6))
        c = np.zeros((6, 6))
        k[:3, :3] = axial_shear_matrix(axis, k_axial, k_shear)
        c[:3, :3] = axial_shear_matrix(axis, c_axial, c_shear)
        law = NonlinearLaw(np.asarray(axis, float), k3_axial, k3_shear, snubber_clearance, snubber_stiffness)
        return cls(np.asarray(position, float), k, c, axis, nonlinear=None if law.is_linear else law)

    # -- beam mounts -----------------------------------------------------------------------------
    @classmethod
    def beam_mount(cls, position: Array, axis: Array, beam: BeamMount, damping: Array | None = None) -> "Mount":
        """A Timoshenko beam mount along ``axis`` with its body end at ``position``: ``stiffness`` is
        its tip stiffness :func:`~impstab.model.beam.tip_stiffness` (hull frame)."""
        from .beam import tip_stiffness

        c = np.zeros((6, 6)) if damping is None else np.asarray(damping, float)
        return cls(np.asarray(position, float), tip_stiffness(beam, axis), c, axis, beam=beam)

    @property
    def is_massive_beam(self) -> bool:
        """True when the mount is a beam with mass (internal dofs in the dynamics)."""
        return self.beam is not None and self.beam.is_massive
    # -- end of beam mounts ------------------------------------------------------------------------

    @property
    def is_nonlinear(self) -> bool:
        """True when the mount carries a nonlinear law (cubic springs or a snubber)."""
        return self.nonlinear is not None and not self.nonlinear.is_linear

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
