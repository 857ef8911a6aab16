"""Linearization of a :class:`~impstab.model.Model` at a thrust (THEORY 4).

``linearize(model, thrust)`` returns one :class:`LinearSystem`; :class:`ModelFamily` evaluates
stacks of systems for arrays of thrusts in one compiled loop (used by the locus, the critical
thrust search and design studies).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError, NumericalError
from ..model.model import LINEARIZATIONS, Model
from ..model.mount_law import LAW_AXIS, LAW_CLEARANCE, LAW_K3_AXIAL, LAW_K3_SHEAR, N_LAW
from .system import LinearSystem
from .tangent import classical_forms, linearize_batch

__all__ = ["linearize", "ModelFamily", "PackedModel", "pack_model", "affine_forms"]

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class PackedModel:
    """A model flattened to arrays for the compiled kernels."""

    mass6: Array
    damp6: Array
    positions: Array
    stiffness: Array
    damping: Array
    e_dir: Array
    r_thrust: Array
    tangency: float
    preload: bool
    polar_inertia: float
    speed: float
    speed_law: str
    operating: float | None
    length_scale: float
    #: ``(n_mounts, N_LAW)`` nonlinear mount laws (:mod:`impstab.model.mount_law`); zeros: linear
    laws: Array | None = None

    @property
    def nonlinear(self) -> bool:
        """True when a mount carries a nonlinear law."""
        return self.laws is not None and bool(np.any(self.laws[:, LAW_K3_AXIAL:] != 0.0))

    def spins(self, thrusts: Array) -> Array:
        """Propeller speed Omega (rad/s) at each thrust."""
        thrusts = np.asarray(thrusts, dtype=float)
        if self.speed_law == "sqrt-thrust":
            return self.speed * np.sqrt(np.maximum(thrusts, 0.0) / self.operating)
        return np.full(thrusts.shape, self.speed)


def pack_model(model: Model, damped: bool = True, fluid_frequency: float = 0.0) -> PackedModel:
    """Flatten ``model`` for the kernels.

    ``damped=False`` drops every damper (mounts and fluid radiation); ``fluid_frequency`` (Hz)
    selects the frequency of compressible fluid coefficients (added mass and radiation damping).
    """
    added, radiation = model.fluid.coefficients_at(fluid_frequency)
    if not damped:
        radiation = np.zeros((6, 6))
    positions = np.array([m.position for m in model.mounts], dtype=float).reshape(-1, 3)
    stiffness = np.array([m.stiffness for m in model.mounts], dtype=float).reshape(-1, 6, 6)
    damping = np.array([m.damping for m in model.mounts], dtype=float).reshape(-1, 6, 6)
    if not damped:
        damping = np.zeros_like(damping)
    point = np.asarray(model.thrust.point, dtype=float)
    arm = float(np.sqrt(max((positions * positions).sum(axis=1).max(initial=0.0), point @ point)))  # the longest arm (m)
    laws = np.zeros((len(model.mounts), N_LAW))
    for i, mount in enumerate(model.mounts):
        if mount.is_nonlinear:
            laws[i] = mount.nonlinear.packed()
    return PackedModel(
        mass6=np.ascontiguousarray(model.body.mass_matrix() + added),
        damp6=np.ascontiguousarray(radiation),
        positions=np.ascontiguousarray(positions),
        stiffness=np.ascontiguousarray(stiffness),
        damping=np.ascontiguousarray(damping),
        e_dir=np.ascontiguousarray(model.thrust.direction),
        r_thrust=np.ascontiguousarray(point),
        tangency=float(model.thrust.tangency),
        preload=bool(model.thrust.preload_stiffness),
        polar_inertia=float(model.propeller.polar_inertia),
        speed=float(model.propeller.speed),
        speed_law=model.propeller.speed_law,
        operating=model.thrust.operating,
        length_scale=max(arm, 1e-3),
        laws=laws,
    )


def affine_forms(
    mass6: Array, damp6: Array, positions: Array, stiffness: Array, damping: Array, e_dir: Array,
    r_thrust: Array, tangency: Array, preload: bool, length_scale: Array, equilibrium: bool,
    laws: Array | None = None,
):
    """The affine form ``K = K0 + T K1`` of many designs at once (leading design axis ``n``).

    Inputs are :class:`PackedModel` fields stacked over designs (``positions (n, nm, 3)``, ...,
    ``tangency`` and ``length_scale`` of shape ``(n,)``, ``laws (n, nm, N_LAW)`` or None for
    linear mounts). Returns ``M, D, K0, K1, G1`` (each ``(n, 6, 6)``; ``G1`` per unit
    ``I_p Omega``) and ``affine (n,)``: whether K is exactly linear in T for that design.

    The classical form is linear by construction; its two parts are formed directly by
    :func:`~impstab.linear.tangent.classical_forms` (the matrices of :func:`linearize_batch` to
    rounding). The classical form sees only the linear springs: a nonlinear mount law's tangent
    at zero deflection is the linear one. The equilibrium form is linear too when linear statics
    leaves the body unrotated (symmetric layouts, thrust through the elastic centre): then
    ``R0 = I`` solves the nonlinear statics exactly, the mount forces are the linear ones and the
    tangent equals the classical matrices. ``length_scale`` (m) converts that rotation to a
    displacement for the test. With nonlinear mount laws that is exact only where the law adds
    nothing along the whole path: every mount deflects by ``d = T u1`` (``u1`` the translation
    per newton), so a cubic axial term needs ``a . u1 = 0``, a cubic shear term
    ``u1 - (a . u1) a = 0``, and a snubber (which engages at some thrust) is never affine.
    """
    m, d, g, k0, k1, q0 = classical_forms(
        mass6, damp6, positions, stiffness, damping, e_dir, r_thrust, np.asarray(tangency, dtype=float), preload
    )
    affine = np.ones(len(m), dtype=bool)
    if equilibrium:
        aq = np.abs(q0)
        size = np.maximum(aq[:, :3].max(axis=-1), 1e-300)
        affine = aq[:, 3:].max(axis=-1) * length_scale <= 1e-13 * size
        if laws is not None and laws[..., LAW_K3_AXIAL:].any():
            u1 = q0[:, None, :3]
            axis = laws[..., LAW_AXIS:LAW_AXIS + 3]
            along = (axis * u1).sum(axis=-1)
            across = np.linalg.norm(u1 - along[..., None] * axis, axis=-1)
            tol = 1e-13 * size[:, None]
            active = (((laws[..., LAW_K3_AXIAL] != 0.0) & (np.abs(along) > tol))
                      | ((laws[..., LAW_K3_SHEAR] != 0.0) & (across > tol)) | (laws[..., LAW_CLEARANCE] > 0.0))
            affine &= ~active.any(axis=-1)
    return m, d, k0, k1, g, affine


def lost_equilibrium_reason(model: Model, thrust: float, length_scale: float) -> str:
    """Why the static equilibrium could not be followed to ``thrust`` (N), in words.

    Linear statics ``K_c q = (T e, T r x e)`` tells the two cases apart: a deflection of many
    times the model's size (very soft mounts under a large thrust; the continuation's load steps
    stop at :data:`~impstab.linear.tangent.MAX_PREDICTOR` of the length scale, 1024 of them) or
    a limit point of the nonlinear path (the mounts do not carry the thrust).
    """
    e = np.asarray(model.thrust.direction, dtype=float)
    load = thrust * np.concatenate([e, np.cross(np.asarray(model.thrust.point, dtype=float), e)])
    try:
        q = np.linalg.solve(model.elastic_stiffness, load)
    except np.linalg.LinAlgError:
        return "the mounts give no stiffness against this thrust"
    size = float(np.abs(q[:3]).max() + length_scale * np.abs(q[3:]).max())
    if np.isfinite(size) and size > length_scale:
        return (f"linear statics deflects the mounts by {size:.3g} m under it, {size / length_scale:.3g} times the "
                f"model's size ({length_scale:.3g} m), beyond what the equilibrium path is followed to")
    return "the mounts cannot carry this thrust (a limit point of the static path)"


@dataclass(frozen=True, eq=False)
class ModelFamily:
    """The model's linearized systems as a function of thrust, evaluated in batches.

    Parameters
    ----------
    model : Model
    linearization : {"equilibrium", "classical"}, optional
        Defaults to the model's ``analysis.linearization``.
    damped : bool
        False removes every damper (the undamped companion of a damped model).
    fluid_frequency : float
        Frequency (Hz) at which compressible fluid coefficients are taken (0: incompressible).
    mount_dofs : bool
        Append the internal finite-element dofs of massive beam mounts
        (:mod:`impstab.linear.mount_dofs`): ``n = 6 + n_internal`` and :meth:`matrices`,
        :meth:`affine_parts` return the grown system (:meth:`evaluate` stays the 6-dof body
        system with each mount as its static stiffness). False, or a model without massive beam
        mounts: ``n = 6``.
    cutoff : float
        With ``mount_dofs``: keep the beams' fixed-interface modes below ``cutoff`` times the body's
        highest frequency (:func:`~impstab.linear.mount_dofs.mount_dofs`; default
        :data:`~impstab.linear.mount_dofs.CUTOFF`, the time histories use
        :data:`~impstab.dynamics.beam_mounts.SIM_CUTOFF`).
    """

    model: Model
    linearization: str | None = None
    damped: bool = True
    fluid_frequency: float = 0.0
    mount_dofs: bool = True
    cutoff: float | None = None

    def __post_init__(self) -> None:
        lin = self.linearization or self.model.analysis.linearization
        if lin not in LINEARIZATIONS:
            raise ModelError("analysis.linearization", lin, f"must be one of {list(LINEARIZATIONS)}")
        object.__setattr__(self, "linearization", lin)
        pk = pack_model(self.model, damped=self.damped, fluid_frequency=self.fluid_frequency)
        object.__setattr__(self, "_packed", pk)
        object.__setattr__(self, "_affine", self._affine_form(pk, lin))
        # -- massive beam mounts: internal dofs (impstab.linear.mount_dofs) --
        from .mount_dofs import CUTOFF, mount_dofs

        cutoff = CUTOFF if self.cutoff is None else float(self.cutoff)
        object.__setattr__(self, "_internal", mount_dofs(self.model, cutoff=cutoff) if self.mount_dofs else None)

    @staticmethod
    def _affine_form(pk: PackedModel, lin: str):
        """``(M, D, K0, K1, G1)`` when K is exactly linear in T, else None (see :func:`affine_forms`)."""
        # writable copies (np.array): the packed fields may be read-only, another argument type
        # for numba; the studies and the static mount loads pass writable arrays to the same kernel
        stack = lambda a: np.array(a, dtype=float)[None]  # noqa: E731
        m, d, k0, k1, g1, affine = affine_forms(
            stack(pk.mass6), stack(pk.damp6), stack(pk.positions), stack(pk.stiffness), stack(pk.damping),
            stack(pk.e_dir), stack(pk.r_thrust), stack(pk.tangency), pk.preload, stack(pk.length_scale),
            lin == "equilibrium", None if pk.laws is None else stack(pk.laws),
        )
        return (m[0], d[0], k0[0], k1[0], g1[0]) if affine[0] else None

    def _affine_matrices(self, p: Array):
        m, d, k0, k1, g1 = self._affine  # type: ignore[attr-defined]
        pk = self.packed
        n = p.size
        shape = (n, 6, 6)
        g = g1[None] * (pk.polar_inertia * pk.spins(p))[:, None, None]
        return (np.broadcast_to(m, shape), np.broadcast_to(d, shape), g, k0[None] + p[:, None, None] * k1[None])

    @property
    def n(self) -> int:
        """Number of dofs: 6, plus the internal dofs of massive beam mounts (``mount_dofs``)."""
        internal = self._internal  # type: ignore[attr-defined]
        return 6 if internal is None else 6 + internal.n

    @property
    def internal(self):
        """The :class:`~impstab.linear.mount_dofs.MountDofs` appended to the body's, or None."""
        return self._internal  # type: ignore[attr-defined]

    @property
    def packed(self) -> PackedModel:
        return self._packed  # type: ignore[attr-defined]

    @property
    def undamped_nongyroscopic(self) -> bool:
        """True when D and G vanish at every thrust by construction: no mount damper, no fluid
        radiation damping, no spinning propeller inertia, no internal mount dofs. The engine then
        takes the undamped form without sampling D and G (which needs static equilibria at the
        far end of the search range, the costliest poses to reach)."""
        pk = self.packed
        return (self._internal is None and not np.any(pk.damp6) and not np.any(pk.damping)  # type: ignore[attr-defined]
                and pk.polar_inertia * pk.speed == 0.0)

    def evaluate(self, thrusts: Array, strict: bool = True):
        """``M, D, G, K`` stacks and the static poses ``u0, R0`` at each thrust.

        Where no static equilibrium is found (a limit point: the mounts cannot carry the thrust)
        ``strict`` raises :class:`~impstab.errors.NumericalError`; otherwise those entries are NaN.
        """
        pk = self.packed
        thrusts = np.ascontiguousarray(np.atleast_1d(np.asarray(thrusts, dtype=float)))
        t_start, u_start, r_start = self._start(float(np.abs(thrusts).min()))
        m, d, g, k, u0, r0, ok = linearize_batch(
            thrusts, pk.spins(thrusts), pk.mass6, pk.damp6, pk.positions, pk.stiffness, pk.damping,
            pk.e_dir, pk.r_thrust, pk.tangency, pk.preload, pk.polar_inertia,
            self.linearization == "equilibrium", pk.length_scale, t_start, u_start, r_start, pk.laws,
        )
        self._remember(thrusts[ok], u0[ok], r0[ok])
        if not ok.all():
            if strict:
                bad = float(thrusts[~ok][0])
                reason = lost_equilibrium_reason(self.model, bad, pk.length_scale)
                err = NumericalError(
                    f"no static equilibrium found at thrust {bad:.6g} N (Newton with load stepping "
                    f"did not converge): {reason}"
                )
                err.reason = reason  # type: ignore[attr-defined]
                raise err
            for a in (m, d, g, k):
                a[~ok] = np.nan
        return m, d, g, k, u0, r0

    # -- continuation: every evaluation starts from the equilibrium at the nearest lower thrust
    # already solved, so that past a bifurcation all evaluations follow one branch
    def _start(self, thrust: float):
        known = self.__dict__.get("_path")
        if not known or self.linearization != "equilibrium":
            return 0.0, np.zeros(3), np.eye(3)
        below = [t for t in known if t <= thrust]
        if not below:
            return 0.0, np.zeros(3), np.eye(3)
        t = max(below)
        u, r = known[t]
        return t, u.copy(), r.copy()

    def _remember(self, thrusts: Array, u0: Array, r0: Array) -> None:
        if self.linearization != "equilibrium" or not len(thrusts):
            return
        known = self.__dict__.setdefault("_path", {})
        if len(known) > 4096:
            known.clear()
        for t, u, r in zip(thrusts, u0, r0):
            known[float(abs(t))] = (u, r)

    @property
    def is_affine(self) -> bool:
        """True when ``K = K0 + T K1`` exactly (classical, or an equilibrium without rotation)."""
        return self._affine is not None  # type: ignore[attr-defined]

    def affine_parts(self):
        """``(M, D, G, K0, K1)`` when the family is exactly affine with constant G, else None."""
        if self._affine is None or self._speed_follows_thrust:  # type: ignore[attr-defined]
            return None
        return self._affine_grown(self.packed.speed)

    def gyroscopic_law_parts(self):
        """``(M, D, G1, K0, K1, speed)`` when K is exactly affine in T and the propeller's speed
        follows the thrust (``sqrt-thrust``): ``G(T) = speed(T) G1``, ``G1`` per unit speed and
        ``speed`` the model's own law (:meth:`PackedModel.spins`, rad/s, vectorized); else None (a
        constant speed is affine: :meth:`affine_parts`)."""
        if self._affine is None or not self._speed_follows_thrust:  # type: ignore[attr-defined]
            return None
        return (*self._affine_grown(1.0), self.packed.spins)

    @property
    def _speed_follows_thrust(self) -> bool:
        pk = self.packed
        return pk.speed_law == "sqrt-thrust" and pk.polar_inertia * pk.speed != 0.0

    def _affine_grown(self, speed: float):
        """``(M, D, G, K0, K1)`` of the affine form with G at propeller speed ``speed`` (rad/s), on
        the grown dofs where the model has massive beam mounts."""
        m, d, k0, k1, g1 = self._affine  # type: ignore[attr-defined]
        g = g1 * self.packed.polar_inertia * speed
        if self.internal is not None:
            (m, d, g, k0), k1 = self._grow(m, d, g, k0), self._grow_load(k1)
        return m, d, g, k0, k1

    def _grow(self, m, d, g, k, rotations=None):
        stack = lambda a: np.asarray(a, dtype=float)[None]  # noqa: E731
        return tuple(a[0] for a in self.internal.augment(stack(m), stack(d), stack(g), stack(k), rotations))

    def _grow_load(self, k1):
        """The load part of an affine K on the grown dofs: the beams carry no thrust terms."""
        out = np.zeros((self.n, self.n))
        out[:6, :6] = k1
        return out

    def matrices(self, p: Array):
        p = np.atleast_1d(np.asarray(p, dtype=float))
        if self._affine is not None:  # type: ignore[attr-defined]
            m, d, g, k = self._affine_matrices(p)
            r0 = None
        else:
            m, d, g, k, _, r0 = self.evaluate(p, strict=False)
        if self.internal is not None:
            return self.internal.augment(np.asarray(m), np.asarray(d), np.asarray(g), np.asarray(k), r0)
        return m, d, g, k


def linearize(model: Model, thrust: float, linearization: str | None = None) -> LinearSystem:
    """Linearized equations of motion of ``model`` at thrust ``thrust`` (N).

    Parameters
    ----------
    model : Model
    thrust : float
        Thrust magnitude T (N).
    linearization : {"equilibrium", "classical"}, optional
        Override the model's setting. ``"equilibrium"`` solves the nonlinear statics (Newton) and
        returns the exact tangent there, with M, D and G at the deflected pose; ``"classical"``
        evaluates at the undeformed configuration with mount forces from linear statics, so that
        ``K = K_c - T K_G`` is exactly linear in T.

    Returns
    -------
    LinearSystem
    """
    if not np.isfinite(thrust):
        raise ModelError("thrust", thrust, "must be a finite number")
    fam = ModelFamily(model, linearization)
    m, d, g, k, u0, r0 = fam.evaluate(np.array([float(thrust)]))
    return LinearSystem(m[0], d[0], g[0], k[0], float(thrust), fam.linearization, u0[0], r0[0])
