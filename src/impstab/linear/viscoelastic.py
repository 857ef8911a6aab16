"""Linear analyses of a model with viscoelastic mounts: the augmented first-order system.

Each Prony term j of mount i adds an internal 3-vector ``z_ij`` (hull frame, m). Linearized at
the static equilibrium (where ``z_ij = d_i``, so the static stiffness carries the load), with
``B_i = [I, -S(rho_i)]`` (3 x 6, ``rho_i = R0 r_i`` the arm at equilibrium) and ``k_i`` the
mount's static 3 x 3 translation stiffness:

    M q'' + (D + G) q' + (K + sum_ij g_ij B_i^T k_i B_i) q - sum_ij g_ij B_i^T k_i z_ij = 0
    tau_ij z_ij' = B_i q - z_ij

(K, D, G, M the elastic model's tangent matrices at that equilibrium). As ``E x' = A(T) x`` with
``x = (q, q', z)``: ``E = diag(I, M, I)`` and 12 + 3 x (terms) x (mounts) states. Eliminating
``z = B q / (1 + lambda tau)`` gives the exact nonlinear eigenproblem

    det(lambda^2 M + lambda (D + G) + K + sum_i B_i^T k_i B_i (r_i(lambda) - 1)) = 0

with the mount's ratio ``r_i = k*/k0`` (:mod:`impstab.model.viscoelastic`). The engine
(:mod:`impstab.linear.engine`) solves the augmented family (for the critical thrust the reduced
one, :func:`augmented_matrices`: the internal states the motion reaches, in the body's dof
coordinates where the mounts' maps have full rank, so a symmetric layout keeps its decoupled
planes and each eigenproblem of the scan is a few small blocks); :func:`exact_onset` then solves the
nonlinear eigenproblem with the law itself (not its Prony fit) at the onset by Newton on
``(T, omega)`` with ``lambda = i omega``, which checks (and for a fitted law, corrects) it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from ..kinematics import rigid_map
from ..model.model import Model
from ..model.viscoelastic import prony_ratio
from .linearize import ModelFamily

__all__ = ["ViscoelasticFamily", "ExactOnset", "exact_onset", "augmented_matrices", "dynamic_stiffness"]

Array = NDArray[np.float64]

#: Newton on the exact eigenproblem stops when the step is below this (relative)
NEWTON_TOL = 1e-12
NEWTON_MAX = 40
#: eigenvalues of F this close (relative to max |F|) are one cluster (identical planes)
CLUSTER = 1e-8
#: a last step below this (relative) after NEWTON_MAX steps is converged to rounding
NEWTON_FLOOR = 1e-9


@dataclass(frozen=True, eq=False)
class _Terms:
    """The Prony terms of a model's viscoelastic mounts and what the assembly derives from them once.

    Iterating gives ``(mount index, static 3x3 k, g (n,), tau (n,))`` per viscoelastic mount.
    ``groups``: ``(tau, positions in the mounts' order, g of each)`` of the terms that share a
    relaxation time; ``weights``: each mount's ``sum g``; ``group_weights (groups, v)``: the g of
    every mount in each group (zero where a mount has no term at that tau).
    """

    entries: tuple
    mounts: list[int]
    k: Array
    weights: Array
    groups: tuple
    group_weights: Array

    @classmethod
    def of(cls, model: Model) -> "_Terms":
        found = [(i, m.viscoelastic) for i, m in enumerate(model.mounts) if m.viscoelastic is not None]
        k = np.array([model.mounts[i].stiffness[:3, :3] for i, _ in found]).reshape(-1, 3, 3)
        entries = tuple((i, k[j], law.weights, law.relaxation_times) for j, (i, law) in enumerate(found))
        by_tau: dict[float, dict[int, float]] = {}  # tau -> {position of the mount: its g at tau}
        sums = []
        for j, (_, law) in enumerate(found):
            g = law.weights.tolist()
            sums.append(sum(g))
            for gj, tj in zip(g, law.relaxation_times.tolist()):
                members = by_tau.setdefault(tj, {})
                members[j] = members.get(j, 0.0) + gj
        groups = tuple((tj, tuple(members), np.array(list(members.values()))) for tj, members in by_tau.items())
        group_weights = np.array([[members.get(j, 0.0) for j in range(len(found))] for members in by_tau.values()])
        return cls(entries, [i for i, _ in found], k, np.array(sums), groups,
                   group_weights.reshape(len(groups), len(found)))

    def __iter__(self):
        return iter(self.entries)

    def __len__(self) -> int:
        return len(self.entries)

    def __getitem__(self, j):
        return self.entries[j]


def _terms(model: Model) -> _Terms:
    """The Prony terms of every viscoelastic mount (:class:`_Terms`)."""
    return _Terms.of(model)


def _mount_maps(rho: Array, terms: _Terms) -> tuple[Array, Array, Array]:
    """For the viscoelastic mounts (in the order of ``terms``) at arms ``rho (..., nm, 3)``: their maps
    ``B_i (..., v, 3, 6)``, ``B_i^T k_i (..., v, 6, 3)`` and ``B_i^T k_i B_i (..., v, 6, 6)``."""
    maps = rigid_map(rho if len(terms.mounts) == rho.shape[-2] else rho[..., terms.mounts, :])  # every mount: no gather
    btk = np.swapaxes(maps, -1, -2) @ terms.k
    return maps, btk, btk @ maps


def _reduced_ranks(maps: Array, terms: _Terms) -> dict[float, int]:
    """Rank of the stacked maps ``B`` of each relaxation time's mounts (at most 6; the same at every
    thrust: the equilibrium only rotates the arms), from the maps ``(v, 3, 6)`` of :func:`_mount_maps`."""
    ranks: dict[float, int] = {}
    by_mounts: dict[tuple, int] = {}  # relaxation times of the same mounts share the rank
    every = tuple(range(len(terms)))
    for tj, js, _ in terms.groups:
        if js not in by_mounts:
            sv = np.linalg.svd((maps if js == every else maps[list(js)]).reshape(-1, 6), compute_uv=False)
            by_mounts[js] = int(np.count_nonzero(sv > 1e-12 * sv[0]))
        ranks[tj] = by_mounts[js]
    return ranks


def augmented_matrices(m: Array, c: Array, k: Array, rho: Array, terms, reduced: bool = False,
                       ranks: dict[float, int] | None = None, maps=None) -> tuple[Array, Array]:
    """``E, A`` of the augmented state for stacks ``m, c = D + G, k (S, nq, nq)`` and arms ``rho (S, nm, 3)``.

    ``terms`` as :func:`_terms` returns. Returns ``E, A (S, N, N)``, ``N = 2 nq + 3 sum n_i``. The
    dofs are the body's 6 (``nq = 6``), or the body's followed by the internal dofs of massive beam
    mounts (:mod:`impstab.linear.mount_dofs`): the mounts' maps act on the body's dofs only.

    ``reduced``: the internal variables that share a relaxation time ``tau`` obey one equation
    ``tau z' = B q - z`` (``B`` the mounts' maps stacked): only ``z`` in the range of ``B`` (rank
    at most 6) is reached from the motion, the rest decays at ``-1/tau`` whatever the body does
    (block-triangular form). Those are dropped, every other eigenvalue is kept exactly, and the
    stability; the dropped roots ``-1/tau`` are stable. Where ``B`` has full rank 6 (three mounts
    or more, not on one line) the states kept are ``z = B zeta`` in the body's own dof coordinates:
    ``tau zeta' = q - zeta``, with the force ``K_tau zeta``, ``K_tau = sum g B_i^T k_i B_i``. They
    couple only the dofs the mounts' stiffness couples, so the operator keeps the decoupled blocks
    of a symmetric layout (:mod:`impstab.linear.blocks`: the sway-yaw and heave-pitch planes apart,
    each with its own internal states). Below rank 6 they are ``w = U^T z`` (``U`` an orthonormal
    basis of range B, from an SVD). ``ranks``: those ranks by relaxation time
    (:func:`_reduced_ranks`), where known; otherwise from the first stack with finite arms.
    ``maps``: :func:`_mount_maps` of ``rho`` where already known.
    """
    s, nq = m.shape[0], m.shape[-1]  # nq: 6, or 6 + the internal dofs of massive beam mounts (the body's first)
    maps, btk, stiff = _mount_maps(rho, terms) if maps is None else maps  # (S, v, 3, 6), (S, v, 6, 3), (S, v, 6, 6)
    flat = stiff.reshape(s, len(terms), 36)
    blocks = []   # (rows from q (S, r, 6), or None for q itself; force columns (S, 6, r); tau)
    if reduced:
        if ranks is None:  # invariant under the rotation of the arms: from the first finite stack
            ranks = _reduced_ranks(maps[int(np.argmax(np.isfinite(maps).all(axis=(1, 2, 3))))], terms)
        forces = (terms.group_weights @ flat).reshape(s, -1, 6, 6)  # K_tau of each group
        for g, (tj, js, gs) in enumerate(terms.groups):
            if ranks[tj] == 6:
                blocks.append((None, forces[:, g], tj))
                continue
            b = maps[:, list(js)].reshape(s, -1, 6)                                        # (S, 3m, 6)
            cols = np.concatenate(list(gs[:, None, None, None] * np.swapaxes(btk[:, list(js)], 0, 1)), axis=2)  # (S, 6, 3m)
            u = np.linalg.svd(np.where(np.isfinite(b), b, 0.0))[0][:, :, :ranks[tj]]
            blocks.append((np.swapaxes(u, -1, -2) @ b, cols @ u, tj))
    else:
        for j, (_, _, g, tau) in enumerate(terms):
            for gj, tj in zip(g, tau):
                blocks.append((maps[:, j], gj * btk[:, j], float(tj)))
    n = 2 * nq + sum(force.shape[-1] for _, force, _ in blocks)
    e = np.zeros((s, n, n))
    a = np.zeros((s, n, n))
    _diagonal(e, 0, 0, n)[...] = 1.0
    e[:, nq:2 * nq, nq:2 * nq] = m
    _diagonal(a, 0, nq, nq)[...] = 1.0
    a[:, nq:2 * nq, nq:2 * nq] = -c
    a[:, nq:2 * nq, :nq] = -np.asarray(k, dtype=float)
    a[:, nq:nq + 6, :6] -= (terms.weights @ flat).reshape(s, 6, 6)  # the static stiffness of the mounts
    row = 2 * nq
    for from_q, force, tj in blocks:
        r = force.shape[-1]
        a[:, nq:nq + 6, row:row + r] = force
        if from_q is None:
            _diagonal(a, row, 0, 6)[...] = 1.0 / tj
        else:
            a[:, row:row + r, :6] = from_q / tj
        _diagonal(a, row, row, r)[...] = -1.0 / tj
        row += r
    return e, a


def _diagonal(x: Array, row: int, col: int, r: int) -> Array:
    """A view of the entries ``x[:, row + i, col + i]``, ``i < r``, of a C-contiguous stack ``x (S, n, n)``."""
    n = x.shape[-1]
    return x.reshape(x.shape[0], n * n)[:, row * n + col:: n + 1][:, :r]


def dynamic_stiffness(lam: complex, m, c, k, rho, model: Model, exact: bool = True) -> Array:
    """``lambda^2 M + lambda (D + G) + K + sum_i B_i^T k_i B_i (r_i(lambda) - 1)`` (6 x 6, complex).

    ``exact`` uses each mount's law; otherwise its Prony series.
    """
    terms = _terms(model)
    return _dynamic(lam, m, c, k, _mount_maps(np.asarray(rho, dtype=float), terms)[2], model, terms, exact)


def _dynamic(lam: complex, m, c, k, stiff: Array, model: Model, terms, exact: bool = True) -> Array:
    """:func:`dynamic_stiffness` with the mounts' ``B_i^T k_i B_i`` given (``stiff (v, 6, 6)``)."""
    f = lam * lam * m + lam * c + k + 0j
    for j, (i, _, g, tau) in enumerate(terms):
        r = model.mounts[i].viscoelastic.ratio_at(lam) if exact else prony_ratio(lam, g, tau)
        f[:6, :6] += stiff[j] * (complex(r) - 1.0)   # the body's dofs (internal beam dofs after them)
    return f


def _d_dynamic_stiffness(lam: complex, m, c, stiff: Array, model: Model, terms) -> Array:
    """``dF / d lambda`` with the exact laws (``stiff`` as :func:`_dynamic`)."""
    f = 2.0 * lam * m + c + 0j
    for j, (i, _, _, _) in enumerate(terms):
        f[:6, :6] += stiff[j] * model.mounts[i].viscoelastic.dratio_at(lam)
    return f


@dataclass(frozen=True, eq=False)
class ViscoelasticFamily:
    """The model's augmented first-order family ``E x' = A(T) x`` (a :class:`FirstOrderFamily`).

    Parameters
    ----------
    model : Model
        With at least one viscoelastic mount.
    linearization : {"equilibrium", "classical"}, optional
    fluid_frequency : float
        Frequency (Hz) of compressible fluid coefficients.
    reduced : bool
        Drop the internal variables no motion reaches (see :func:`augmented_matrices`): the same
        stability and every other eigenvalue, fewer states (the critical-thrust search uses it).
    cutoff : float, optional
        With massive beam mounts, whose internal dofs follow the body's: keep their fixed-interface
        modes below ``cutoff`` times the body's highest frequency (default that of
        :class:`~impstab.linear.linearize.ModelFamily`).
    """

    model: Model
    linearization: str | None = None
    fluid_frequency: float = 0.0
    reduced: bool = False
    cutoff: float | None = None
    first_order = True
    n_dof = 6

    def __post_init__(self) -> None:
        base = ModelFamily(self.model, self.linearization, damped=True, fluid_frequency=self.fluid_frequency,
                           cutoff=self.cutoff)
        object.__setattr__(self, "base", base)
        object.__setattr__(self, "linearization", base.linearization)
        object.__setattr__(self, "terms", _terms(self.model))
        object.__setattr__(self, "positions", np.array([mt.position for mt in self.model.mounts], dtype=float))

    @property
    def rest_maps(self) -> tuple[Array, Array, Array]:
        """:func:`_mount_maps` at the mounts' positions (the arms of an affine family at every thrust)."""
        hit = self.__dict__.get("_rest_maps")
        if hit is None:
            hit = _mount_maps(self.positions, self.terms)  # type: ignore[attr-defined]
            object.__setattr__(self, "_rest_maps", hit)
        return hit

    @property
    def ranks(self) -> dict[float, int] | None:
        """Reduced families: the internal states kept per relaxation time (the rank of its mounts'
        stacked maps; the same at every thrust, the equilibrium only rotates the arms)."""
        if not self.reduced:
            return None
        hit = self.__dict__.get("_ranks")
        if hit is None:
            hit = _reduced_ranks(self.rest_maps[0], self.terms)  # type: ignore[attr-defined]
            object.__setattr__(self, "_ranks", hit)
        return hit

    @property
    def n(self) -> int:
        nq = 2 * self.base.n  # type: ignore[attr-defined]
        if self.reduced:
            return nq + sum(self.ranks.values())  # type: ignore[union-attr]
        return nq + 3 * sum(len(g) for _, _, g, _ in self.terms)  # type: ignore[attr-defined]

    @property
    def weights(self) -> Array:
        """Participation weights: the mass diagonal at rest."""
        return np.diag(self.model.mass_matrix).copy()

    def system(self, thrusts: Array):
        """``M, D + G, K`` stacks (the body's dofs, then those of massive beam mounts) and the arms at
        equilibrium ``rho (S, nm, 3)`` at each thrust."""
        p = np.atleast_1d(np.asarray(thrusts, dtype=float))
        base: ModelFamily = self.base  # type: ignore[attr-defined]
        if base.is_affine:
            m, d, g, k = base.matrices(p)
            rho = np.broadcast_to(self.positions, (p.size,) + self.positions.shape)  # type: ignore[attr-defined]
        else:
            m, d, g, k, _, r0 = base.evaluate(p, strict=False)
            if base.internal is not None:  # massive beam mounts: their internal dofs after the body's
                m, d, g, k = base.internal.augment(np.asarray(m), np.asarray(d), np.asarray(g), np.asarray(k), r0)
            rho = np.einsum("sab,mb->sma", r0, self.positions)  # type: ignore[attr-defined]
        return np.asarray(m), np.asarray(d + g), np.asarray(k), rho

    def matrices(self, p: Array) -> tuple[Array, Array]:
        m, c, k, rho = self.system(p)
        return augmented_matrices(m, c, k, rho, self.terms, self.reduced, self.ranks)  # type: ignore[attr-defined]

    def affine_parts(self):
        """``(E, A0, A1)`` when the elastic family is exactly affine with constant G, else None."""
        parts = self.base.affine_parts()  # type: ignore[attr-defined]
        if parts is None:
            return None
        m, d, g, k0, k1 = parts
        rho = self.positions[None]  # type: ignore[attr-defined]
        e, a0 = augmented_matrices(m[None], (d + g)[None], k0[None], rho, self.terms, self.reduced,  # type: ignore[attr-defined]
                                   self.ranks, tuple(x[None] for x in self.rest_maps))
        nq = m.shape[-1]
        a1 = np.zeros_like(a0[0])
        a1[nq:2 * nq, :nq] = -k1
        return e[0], a0[0], a1


@dataclass(frozen=True)
class ExactOnset:
    """An onset of the Prony realisation checked on the exact law.

    Attributes
    ----------
    thrust, omega : float
        The onset of the augmented (Prony) system: thrust (N), frequency (rad/s).
    exact_thrust, exact_omega : float or None
        The root of the exact eigenproblem ``det F(i omega, T) = 0`` Newton converged to from it
        (None when Newton did not converge).
    thrust_difference, omega_difference : float or None
        ``exact - Prony``, relative to the Prony values (the frequency relative to ``max(omega, 1)``).
    iterations : int
    """

    thrust: float
    omega: float
    exact_thrust: float | None
    exact_omega: float | None
    thrust_difference: float | None
    omega_difference: float | None
    iterations: int

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def _cluster(f: Array):
    """Right and left bases ``X, Y`` of the eigenvalues of ``f`` nearest zero (a cluster of equal
    ones: identical planes of a symmetric layout give each root twice) and their mean."""
    vals, left, right = scipy.linalg.eig(f, left=True, right=True)
    scale = max(float(np.abs(f).max()), 1e-300)
    j = int(np.argmin(np.abs(vals)))
    members = np.flatnonzero(np.abs(vals - vals[j]) <= CLUSTER * scale)
    return right[:, members], left[:, members], complex(vals[members].mean())


def _mean_derivative(x: Array, y: Array, df: Array) -> complex:
    """Derivative of the cluster's mean eigenvalue: ``trace((Y^H X)^-1 Y^H dF X) / m``."""
    yx = y.conj().T @ x
    return complex(np.trace(np.linalg.solve(yx, y.conj().T @ df @ x)) / x.shape[1])


def exact_onset(model: Model, thrust: float, omega: float, linearization: str | None = None,
                fluid_frequency: float = 0.0, family: "ViscoelasticFamily | None" = None) -> ExactOnset:
    """Newton on the exact eigenproblem ``F(i omega, T) v = 0`` (the mounts' laws, not their Prony
    fits) from an onset ``(thrust, omega)``.

    The unknowns are ``T`` and ``omega`` (for divergence, ``omega = 0``, where every law has its
    static stiffness: ``T`` alone), the equation the eigenvalue ``mu(i omega, T)`` of ``F`` nearest
    zero (the mean of a cluster of equal ones, so that the identical planes of a symmetric layout
    keep the convergence quadratic), with its exact derivative ``y^H dF x / y^H x``;
    ``dF/d omega = i dF/d lambda`` exactly, ``dF/dT`` exactly ``K1`` where the family is affine in
    the thrust (else by central differences of the linearization).
    ``family``: the model's :class:`ViscoelasticFamily` when one exists already (same settings).
    """
    fam = family if family is not None else ViscoelasticFamily(model, linearization, fluid_frequency)
    terms = fam.terms  # type: ignore[attr-defined]
    parts = fam.base.affine_parts()  # type: ignore[attr-defined]
    if parts is not None:  # K = K0 + T K1 with constant M, D + G and arms: dF/dT = K1 exactly
        m0, d0, g0, k0, k1 = parts
        c0 = d0 + g0
        stiff0 = fam.rest_maps[2]

        def dyn(t: float, lam: complex):
            return _dynamic(lam, m0, c0, k0 + t * k1, stiff0, model, terms), (m0, c0, stiff0)

        def dyn_t(t: float, lam: complex):
            return k1 + 0j
    else:
        def dyn(t: float, lam: complex):
            m, c, k, rho = fam.system(np.array([t]))
            stiff = _mount_maps(rho[0], terms)[2]
            return _dynamic(lam, m[0], c[0], k[0], stiff, model, terms), (m[0], c[0], stiff)

        def dyn_t(t: float, lam: complex):
            h = 1e-6 * max(abs(t), 1.0)
            return (dyn(t + h, lam)[0] - dyn(t - h, lam)[0]) / (2 * h)

    t, w = float(thrust), float(abs(omega))
    flutter = w > 0.0
    it = 0
    converged = False
    dt = dw = np.inf
    for it in range(1, NEWTON_MAX + 1):
        lam = 1j * w
        f, (m, c, stiff) = dyn(t, lam)
        if not np.isfinite(f).all():
            break
        f_t = dyn_t(t, lam)
        try:
            x, y, mu = _cluster(f)
            b = _mean_derivative(x, y, f_t)
            if flutter:
                a = 1j * _mean_derivative(x, y, _d_dynamic_stiffness(lam, m, c, stiff, model, terms))
                dw, dt = np.linalg.solve(np.array([[a.real, b.real], [a.imag, b.imag]]), [-mu.real, -mu.imag])
            else:
                dw, dt = 0.0, -mu.real / b.real
        except (np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
            break
        if not (np.isfinite(dw) and np.isfinite(dt)):
            break
        t, w = t + float(dt), w + float(dw)
        if abs(dt) <= NEWTON_TOL * max(abs(t), 1.0) and abs(dw) <= NEWTON_TOL * max(abs(w), 1.0):
            converged = True
            break
    if not converged and np.isfinite(dt) and abs(dt) <= NEWTON_FLOOR * max(abs(t), 1.0) \
            and abs(dw) <= NEWTON_FLOOR * max(abs(w), 1.0):
        converged = True
    if not converged:
        return ExactOnset(float(thrust), float(omega), None, None, None, None, it)
    return ExactOnset(float(thrust), float(omega), t, w, (t - thrust) / thrust if thrust else t - thrust,
                      (w - abs(omega)) / max(abs(omega), 1.0), it)


def viscoelastic_modes(model: Model, thrust: float = 0.0, linearization: str | None = None):
    """Modes of the augmented system at ``thrust`` (a :class:`~impstab.linear.modes.ModalResult`).

    Every eigenvalue of ``E^-1 A`` with ``omega >= 0`` is a mode, the real relaxation roots of
    the internal variables included (``omega = 0``, ``sigma < 0``); shapes and the decoupling
    table are those of the displacement states ``q``. Roots whose displacement part vanishes
    (an internal variable that no motion of the body excites) are left out.
    """
    from .modes import _canonical_repeated, body_modes

    fam = ViscoelasticFamily(model, linearization)
    m, c, k, rho = fam.system(np.array([float(thrust)]))
    if not np.isfinite(k).all():
        from ..errors import NumericalError

        raise NumericalError(f"no static equilibrium found at thrust {thrust:.6g} N: the mounts cannot carry this thrust")
    e, a = augmented_matrices(m, c, k, rho, fam.terms)  # type: ignore[attr-defined]
    vals, vecs = np.linalg.eig(np.linalg.solve(e[0], a[0]))
    scale = max(np.abs(vals).max(), 1e-300)
    nq = m.shape[-1]                     # the body's 6 dofs, then those of massive beam mounts
    q = vecs[:nq]
    size = np.linalg.norm(q, axis=0) / np.maximum(np.linalg.norm(vecs, axis=0), 1e-300)
    keep = ((vals.imag > 1e-12 * scale) | (np.abs(vals.imag) <= 1e-12 * scale)) & (size > 1e-10)
    vals, vecs = vals[keep], q[:, keep]
    vals = np.where(np.abs(vals.imag) <= 1e-12 * scale, vals.real + 0j, vals)
    order = np.lexsort((vals.real, np.abs(vals.imag)))
    vals, vecs = vals[order], vecs[:, order]
    vecs = _canonical_repeated(vals, vecs, np.diag(m[0]))
    return body_modes(model, float(thrust), fam.linearization, vals, vecs, m[0])  # type: ignore[arg-type]
