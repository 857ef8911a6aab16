"""How well the mount layout decouples the rigid-body modes: roll mode, torque roll axis, elastic axis.

At the thrust of the linearization (hull axes, points from A at the static pose):

* **Roll decoupling**: the roll mode is the mode with the largest roll share in the decoupling
  table (:attr:`impstab.linear.modes.ModalResult.participation`); it counts as decoupled when
  that share is at least ``threshold`` (90 % by default).
* **Torque roll axis (TRA)**: the axis about which the free body turns under a torque about the
  thrust axis ``e`` (the propeller's torque fluctuation): the screw axis of the acceleration
  ``M^-1 [0; e]`` (direction ``alpha = (M^-1 [0; e])_rot``, through ``p = alpha x a_A / |alpha|^2``);
  for a dry body it passes through the cg (with added mass, through the wet inertial centre only
  approximately). A roll mode whose rotation axis lies on the TRA is excited by
  that torque alone (Jeong and Singh, J. Sound Vib. 234 (2000) 85-114).
* **Roll-mode axis**: the rotation axis of the roll mode's shape (its phase turned so the roll
  component is real): direction ``theta / |theta|``, through ``theta x u_A / |theta|^2``.
* **Elastic centre**: the point about which the translation-rotation coupling of the mount
  stiffness ``K_e = sum B_i^T k_i B_i`` is symmetric (:func:`impstab.linear.modes.coupling_centre`);
  ``elastic_coupling`` is the remaining coupling there, ``|K_ur(E)|_2 / sqrt(|K_uu|_2 |K_rr(E)|_2)``
  (0: translation and rotation fully decoupled at E). The elastic roll axis is the principal axis
  of ``K_rr(E)`` closest to the thrust axis, through E. The load stiffness of the thrust is left
  out (it is not a property of the mounts).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..kinematics import rigid_map6
from ..linear.linearize import linearize
from ..linear.modes import coupling_centre, modes
from ..model.model import DOF_NAMES, Model
from .core import attachment_maps

__all__ = ["DecouplingCheck", "decoupling_check", "ROLL_DECOUPLED"]

Array = NDArray[np.float64]

#: roll share of the roll mode from which it counts as decoupled
ROLL_DECOUPLED = 0.9


def _angle_deg(a: Array, b: Array) -> float:
    c = abs(float(a @ b)) / (np.linalg.norm(a) * np.linalg.norm(b))
    return float(np.degrees(np.arccos(min(c, 1.0))))


def _line_distance(point: Array, line_point: Array, direction: Array) -> float:
    d = direction / np.linalg.norm(direction)
    return float(np.linalg.norm(np.cross(point - line_point, d)))


@dataclass(frozen=True, eq=False)
class DecouplingCheck:
    """Roll decoupling, torque roll axis and elastic axis at one thrust (hull axes, m from A).

    Attributes
    ----------
    thrust : float (N);  linearization : str;  threshold : float
    roll_mode : int
        Index of the roll mode in ``impstab.modes(model, thrust)`` (sorted by frequency).
    roll_share : float
        Its roll share (kinetic energy, 0..1).
    roll_frequency_hz : float
    roll_axis, roll_axis_point : (3,) arrays
        Rotation axis of the roll mode and its point closest to A.
    torque_roll_axis, torque_roll_point : (3,) arrays
    mass_centre, elastic_centre : (3,) arrays
    elastic_coupling : float
    elastic_roll_axis : (3,) array
    thrust_axis, thrust_point : (3,) arrays
    """

    thrust: float
    linearization: str
    threshold: float
    roll_mode: int
    roll_share: float
    roll_frequency_hz: float
    roll_axis: Array
    roll_axis_point: Array
    torque_roll_axis: Array
    torque_roll_point: Array
    mass_centre: Array
    elastic_centre: Array
    elastic_coupling: float
    elastic_roll_axis: Array
    thrust_axis: Array
    thrust_point: Array

    @property
    def roll_decoupled(self) -> bool:
        return self.roll_share >= self.threshold

    @property
    def tra_angle_deg(self) -> float:
        """Angle between the torque roll axis and the thrust axis (deg)."""
        return _angle_deg(self.torque_roll_axis, self.thrust_axis)

    @property
    def tra_offset(self) -> float:
        """Distance of the mass centre from the torque roll axis (m; 0 for a dry body)."""
        return _line_distance(self.mass_centre, self.torque_roll_point, self.torque_roll_axis)

    @property
    def roll_axis_angle_deg(self) -> float:
        """Angle between the roll mode's axis and the torque roll axis (deg)."""
        return _angle_deg(self.roll_axis, self.torque_roll_axis)

    @property
    def roll_axis_offset(self) -> float:
        """Distance of the roll mode's axis from the mass centre, where the TRA passes (m)."""
        return _line_distance(self.mass_centre, self.roll_axis_point, self.roll_axis)

    @property
    def centre_offset(self) -> float:
        """Distance between the elastic centre and the mass centre (m)."""
        return float(np.linalg.norm(self.elastic_centre - self.mass_centre))

    @property
    def thrust_line_offset(self) -> float:
        """Distance of the elastic centre from the thrust line (m)."""
        return _line_distance(self.elastic_centre, self.thrust_point, self.thrust_axis)

    @property
    def elastic_axis_angle_deg(self) -> float:
        """Angle between the elastic roll axis and the thrust axis (deg)."""
        return _angle_deg(self.elastic_roll_axis, self.thrust_axis)

    def lines(self) -> list[str]:
        """The check in words, one finding a line (for ``impstab modes``)."""
        verdict = "decoupled" if self.roll_decoupled else "coupled"

        def fmt(v):  # rounding noise below 1e-12 of the vector's size shown as 0
            tiny = 1e-12 * max(float(np.abs(v).max()), 1e-3)
            return "[" + ", ".join(f"{(x if abs(x) > tiny else 0.0):.4g}" for x in v) + "]"

        num = lambda x, unit=1.0: f"{(x * unit if abs(x) > 1e-12 else 0.0):.3g}"  # noqa: E731
        return [
            f"roll mode {self.roll_mode + 1} ({self.roll_frequency_hz:.4g} Hz): roll share {100 * self.roll_share:.1f} % "
            f"({verdict}; decoupled from {100 * self.threshold:.0f} %)",
            f"torque roll axis (free body under a torque about the thrust axis): direction {fmt(self.torque_roll_axis)}, "
            f"{num(self.tra_angle_deg)} deg from the thrust axis, {num(self.tra_offset, 1e3)} mm from the mass centre "
            f"{fmt(self.mass_centre)} m",
            f"roll-mode axis: {num(self.roll_axis_angle_deg)} deg from the torque roll axis, "
            f"{num(self.roll_axis_offset, 1e3)} mm from the mass centre",
            f"elastic centre {fmt(self.elastic_centre)} m: {num(self.centre_offset, 1e3)} mm from the mass centre, "
            f"{num(self.thrust_line_offset, 1e3)} mm from the thrust line; coupling left there {num(self.elastic_coupling, 100)} %",
            f"elastic roll axis: {num(self.elastic_axis_angle_deg)} deg from the thrust axis",
        ]

    def to_dict(self) -> dict:
        out = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in self.__dict__.items()}
        out.update(roll_decoupled=self.roll_decoupled, tra_angle_deg=self.tra_angle_deg, tra_offset=self.tra_offset,
                   roll_axis_angle_deg=self.roll_axis_angle_deg, roll_axis_offset=self.roll_axis_offset,
                   centre_offset=self.centre_offset, thrust_line_offset=self.thrust_line_offset,
                   elastic_axis_angle_deg=self.elastic_axis_angle_deg)
        return out


def decoupling_check(model: Model, thrust: float | None = None, linearization: str | None = None,
                     threshold: float = ROLL_DECOUPLED, modal=None) -> DecouplingCheck:
    """Roll decoupling, torque roll axis and elastic axis at ``thrust`` (default operating, else 0).

    ``modal`` may pass the :func:`impstab.modes` result at that thrust to avoid recomputing it.
    """
    from .api import default_thrust

    t = default_thrust(model, thrust)
    lin = linearize(model, t, linearization)
    md = modal if modal is not None else modes(model, t, linearization)
    rot = lin.rotation
    e = rot @ model.thrust.direction
    r_t = rot @ model.thrust.point
    # torque roll axis: screw axis of the acceleration under a unit torque about e
    acc = np.linalg.solve(lin.M, np.concatenate([np.zeros(3), e]))
    alpha, a_a = acc[3:], acc[:3]
    tra = alpha / np.linalg.norm(alpha)
    tra = tra if tra @ e >= 0 else -tra
    tra_point = np.cross(alpha, a_a) / (alpha @ alpha)
    # roll mode and its rotation axis
    roll = DOF_NAMES.index("roll")
    body = np.array([kind == "body" for kind in md.kind])  # massive beam mounts: not an internal mode
    j = int(np.argmax(np.where(body, md.participation[:, roll], -np.inf)))
    x = md.shapes[:, j]
    x = (x * np.conj(x[roll]) / abs(x[roll])).real if abs(x[roll]) > 0 else x.real
    theta, u = x[3:], x[:3]
    axis = theta / np.linalg.norm(theta)
    axis = axis if axis @ e >= 0 else -axis
    axis_point = np.cross(theta, u) / (theta @ theta)
    # elastic centre and elastic roll axis of the mount stiffness at the pose
    pos = np.array([m.position for m in model.mounts], dtype=float)[None]
    b = attachment_maps(pos, rot[None])[0]
    km = np.array([m.stiffness for m in model.mounts], dtype=float)
    k_e = (np.swapaxes(b, -1, -2) @ km @ b).sum(axis=0)
    centre = coupling_centre(k_e)
    w = np.linalg.inv(rigid_map6(centre))
    k_c = w.T @ k_e @ w
    norm = lambda a: float(np.linalg.norm(a, 2))  # noqa: E731
    coupling = norm(k_c[:3, 3:]) / np.sqrt(norm(k_c[:3, :3]) * norm(k_c[3:, 3:]))
    vals, vecs = np.linalg.eigh(0.5 * (k_c[3:, 3:] + k_c[3:, 3:].T))
    elastic_axis = vecs[:, int(np.argmax(np.abs(vecs.T @ e)))]
    elastic_axis = elastic_axis if elastic_axis @ e >= 0 else -elastic_axis
    return DecouplingCheck(
        thrust=t, linearization=lin.linearization, threshold=float(threshold), roll_mode=j,
        roll_share=float(md.participation[j, roll]), roll_frequency_hz=float(md.frequency_hz[j]),
        roll_axis=axis, roll_axis_point=axis_point, torque_roll_axis=tra, torque_roll_point=tra_point,
        mass_centre=coupling_centre(lin.M), elastic_centre=centre, elastic_coupling=float(coupling),
        elastic_roll_axis=elastic_axis, thrust_axis=e, thrust_point=r_t,
    )
