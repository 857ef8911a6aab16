"""Static deflection and load of each mount at a thrust, and their utilisation against ratings.

At the static equilibrium of the linearization (THEORY 4; gravity and buoyancy neglected, so the
loads come from the thrust alone) each mount's body end has moved by
``e_i = (u0 + R0 r_i - r_i, log R0)`` (equilibrium; classically ``T6(r_i) q0`` from linear
statics ``K_c q0 = [T e; r_T x T e]``). The mount pushes the hull with the force
``F_i = (k_i e_i)_t`` and, with rotational stiffness, the moment ``M_i = J_l^{-T} (k_i e_i)_r``
(hull axes); the forces sum to the thrust vector. Deflection and force split along the mount axis ``a`` (axial, signed) and normal
to it (shear, magnitude). With the optional ratings of a mount (``rated_force`` N,
``max_deflection`` m) the utilisations are ``|F_i| / rated_force`` and ``|d_i| / max_deflection``;
above 1 a warning names the mount.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError
from ..kinematics import inverse_left_jacobian, rigid_map6, rotation_from_vector, rotation_vector
from ..linear.linearize import linearize, pack_model
from ..linear.tangent import classical_forms
from ..model.model import LINEARIZATIONS, Model

__all__ = ["StaticMountLoads", "static_mount_loads", "static_loads_batch"]

Array = NDArray[np.float64]


def static_loads_batch(positions: Array, stiffness: Array, translation: Array, rotation: Array, exact: bool = True):
    """Body-end deflections ``e (nd, nm, 6)`` and mount loads ``(nd, nm, 6)`` of many designs.

    The load of a mount on the hull is ``[F; M] = [(k e)_t; J_l^{-T}(phi) (k e)_r]``: the force
    ``(k e)_t`` and, for a mount with rotational stiffness, the moment conjugate to the spatial
    rotation (THEORY 4: the elastic potential ``1/2 e^T k e`` in ``phi = log R``; ``J_l = I``
    for classical statics).

    Parameters
    ----------
    positions : (nd, nm, 3) array
        Mount attachment points, body frame (m).
    stiffness : (nd, nm, 6, 6) array
        Mount stiffness at the body end.
    translation : (nd, 3) array
        Static displacement of A (m).
    rotation : (nd, 3) array
        Static rotation vector (rad).
    exact : bool
        True: the finite pose ``(u, exp(S(rotation)))`` of the equilibrium linearization;
        False: the linear map ``T6(r) q0`` of classical statics.
    """
    pos = np.asarray(positions, dtype=float)
    u = np.asarray(translation, dtype=float)
    phi = np.asarray(rotation, dtype=float)
    nd, nm = pos.shape[:2]
    e = np.zeros((nd, nm, 6))
    if exact:
        for d in range(nd):
            rot = rotation_from_vector(phi[d])
            e[d, :, :3] = u[d] + pos[d] @ rot.T - pos[d]
    else:
        q0 = np.concatenate([u, phi], axis=-1)
        e[..., :3] = (rigid_map6(pos) @ q0[:, None, :, None])[..., :3, 0]
    e[..., 3:] = phi[:, None, :]
    load = (np.asarray(stiffness, dtype=float) @ e[..., None])[..., 0]
    if exact:
        for d in range(nd):
            load[d, :, 3:] = load[d, :, 3:] @ inverse_left_jacobian(phi[d])   # rows: J^-T g
    return e, load


@dataclass(frozen=True, eq=False)
class StaticMountLoads:
    """Static deflection and load of every mount at one thrust (hull axes).

    Attributes
    ----------
    thrust : float (N);  linearization : str
    axis : (nm, 3) unit mount axes
    deflection : (nm, 3) m, body-end displacement of each attachment point
    rotation : (nm, 3) rad, body-end rotation (the body's)
    force : (nm, 3) N, force of each mount on the hull;  moment : (nm, 3) N m (6 x 6 mounts)
    rated_force, max_deflection : (nm,) ratings (NaN where not given)
    """

    thrust: float
    linearization: str
    axis: Array
    deflection: Array
    rotation: Array
    force: Array
    moment: Array
    rated_force: Array
    max_deflection: Array

    @property
    def axial_deflection(self) -> Array:
        """Deflection along the mount axis (m, signed)."""
        return (self.deflection * self.axis).sum(axis=-1)

    @property
    def shear_deflection(self) -> Array:
        """Deflection normal to the mount axis (m, magnitude)."""
        return np.linalg.norm(self.deflection - self.axial_deflection[:, None] * self.axis, axis=-1)

    @property
    def deflection_magnitude(self) -> Array:
        return np.linalg.norm(self.deflection, axis=-1)

    @property
    def axial_force(self) -> Array:
        """Force along the mount axis (N, signed)."""
        return (self.force * self.axis).sum(axis=-1)

    @property
    def shear_force(self) -> Array:
        return np.linalg.norm(self.force - self.axial_force[:, None] * self.axis, axis=-1)

    @property
    def force_magnitude(self) -> Array:
        return np.linalg.norm(self.force, axis=-1)

    @property
    def force_utilisation(self) -> Array:
        """``|F| / rated_force`` (NaN without a rating)."""
        return self.force_magnitude / self.rated_force

    @property
    def deflection_utilisation(self) -> Array:
        """``|d| / max_deflection`` (NaN without a limit)."""
        return self.deflection_magnitude / self.max_deflection

    @property
    def utilisation(self) -> Array:
        """The larger of the two utilisations (NaN where the mount has no rating)."""
        return np.fmax(self.force_utilisation, self.deflection_utilisation)

    @property
    def warnings(self) -> tuple[str, ...]:
        out = []
        for i in range(self.force.shape[0]):
            if self.force_utilisation[i] > 1:
                out.append(f"mount {i}: static force {self.force_magnitude[i]:.4g} N exceeds its rated_force "
                           f"{self.rated_force[i]:.4g} N ({100 * self.force_utilisation[i]:.0f} %)")
            if self.deflection_utilisation[i] > 1:
                out.append(f"mount {i}: static deflection {1e3 * self.deflection_magnitude[i]:.4g} mm exceeds its "
                           f"max_deflection {1e3 * self.max_deflection[i]:.4g} mm ({100 * self.deflection_utilisation[i]:.0f} %)")
        return tuple(out)

    def to_dict(self) -> dict:
        nan = lambda a: [None if not np.isfinite(v) else float(v) for v in a]  # noqa: E731
        return {
            "thrust": self.thrust, "linearization": self.linearization,
            "deflection": self.deflection.tolist(), "axial_deflection": self.axial_deflection.tolist(),
            "shear_deflection": self.shear_deflection.tolist(), "force": self.force.tolist(),
            "axial_force": self.axial_force.tolist(), "shear_force": self.shear_force.tolist(),
            "moment": self.moment.tolist(), "rated_force": nan(self.rated_force), "max_deflection": nan(self.max_deflection),
            "utilisation": nan(self.utilisation), "warnings": list(self.warnings),
        }


def static_mount_loads(model: Model, thrust: float | None = None, linearization: str | None = None) -> StaticMountLoads:
    """Static deflection and load of each mount at ``thrust`` (N; default the operating thrust, else 0).

    The equilibrium is that of :func:`impstab.linearize` (same Newton solve and continuation).
    """
    from .api import default_thrust

    t = default_thrust(model, thrust)
    lin_kind = linearization or model.analysis.linearization
    if lin_kind not in LINEARIZATIONS:
        raise ModelError("linearization", lin_kind, f"must be one of {list(LINEARIZATIONS)}")
    pos = np.array([m.position for m in model.mounts], dtype=float)[None]
    k = np.array([m.stiffness for m in model.mounts], dtype=float)[None]
    if lin_kind == "equilibrium":
        lin = linearize(model, t, "equilibrium")
        e, load = static_loads_batch(pos, k, lin.displacement[None], rotation_vector(lin.rotation)[None], exact=True)
        for i, m in enumerate(model.mounts):  # a nonlinear mount law adds grad V_nl(d) to the force
            if m.is_nonlinear:
                from ..model.mount_law import law_gradient

                load[0, i, :3] += law_gradient(np.ascontiguousarray(m.nonlinear.packed()[None]), 0, *e[0, i, :3])
    else:
        pk = pack_model(model)
        # writable copies, as ModelFamily passes them (a read-only field is another type for numba)
        stack = lambda a: np.array(a, dtype=float)[None]  # noqa: E731
        q1 = classical_forms(stack(pk.mass6), stack(pk.damp6), stack(pk.positions), stack(pk.stiffness),
                             stack(pk.damping), stack(pk.e_dir), stack(pk.r_thrust), stack(pk.tangency), pk.preload)[5]
        q0 = t * q1
        e, load = static_loads_batch(pos, k, q0[:, :3], q0[:, 3:], exact=False)
    rating = lambda name: np.array([np.nan if getattr(m, name) is None else getattr(m, name) for m in model.mounts])  # noqa: E731
    return StaticMountLoads(
        thrust=t, linearization=lin_kind, axis=np.array([m.axis for m in model.mounts]),
        deflection=e[0, :, :3], rotation=e[0, :, 3:], force=load[0, :, :3], moment=load[0, :, 3:],
        rated_force=rating("rated_force"), max_deflection=rating("max_deflection"),
    )
