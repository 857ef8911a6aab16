"""Natural frequencies, damping, growth rates, mode shapes and the mode decoupling table at one thrust.

The decoupling table (``ModalResult.participation``) is the kinetic-energy distribution an NVH
engineer uses to judge a mount layout: for mode ``x`` (shape at A) and dof ``j``,

    share_j = Re(conj(y_j) (M_c y)_j) / Re(y^H M_c y),     y = T6(c) x,  M_c = T6(c)^-T M T6(c)^-1,

in the coordinates of the mass centre ``c`` (translation of ``c`` and rotation, hull axes), so that
a rotation about the cg counts as rotation and not as translation of an arbitrary datum. Each row
sums to 1 exactly (Jeong and Singh's energy distribution, J. Sound Vib. 234 (2000) 85-114). The
mass centre is the point where the translation-rotation coupling of ``M`` is symmetric
(:func:`coupling_centre`): the cg for a dry body, where the rigid-body coupling vanishes; with
added mass the inertial centre of body and entrained water. A share can be slightly negative or
above 1 where ``M_c`` keeps off-diagonal terms (products of inertia, added mass off the cg); the
row still sums to 1. The dominant dof of a mode is its largest share.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ..model.model import DOF_NAMES, Model
from .critical import TOL_DUPLICATE
from .linearize import linearize
from .system import LinearSystem

__all__ = ["ModalResult", "modes", "modes_of_system", "coupling_centre", "energy_shares", "body_modes"]


@dataclass(frozen=True, eq=False)
class ModalResult:
    """Modes of the linearized system at thrust ``thrust``, sorted by frequency.

    One entry per mode: a complex pair counts once (``omega >= 0``); a real eigenvalue (an
    overdamped or divergent motion) is its own entry with ``omega = 0``.

    Attributes
    ----------
    eigenvalues : (k,) complex
        ``lambda = sigma + i omega`` (1/s).
    shapes : (6, k) complex
        Displacement shapes at A (m, rad), largest component 1.
    participation : (k, 6)
        The mode decoupling table: kinetic-energy share of each dof in each mode, in the
        coordinates of the mass centre (rows sum to 1; see the module notes). With massive beam
        mounts: the body's part of the energy split over its dofs (rows sum to 1).
    internal_share : (k,) array or None
        With massive beam mounts (:mod:`impstab.linear.mount_dofs`): the share of each mode's
        kinetic energy in the mounts' internal (fixed-interface) dofs; above 1/2 the mode is an
        internal mount mode (:attr:`kind`). None without such mounts.
    mount_elements : tuple of int
        Finite elements of each massive beam mount (empty without them).
    internal_dofs : int
        Internal dofs carried (Craig-Bampton modes kept below the cutoff).
    """

    thrust: float
    linearization: str
    eigenvalues: NDArray[np.complex128]
    shapes: NDArray[np.complex128]
    participation: NDArray[np.float64]
    internal_share: NDArray[np.float64] | None = None
    mount_elements: tuple[int, ...] = ()
    internal_dofs: int = 0

    @property
    def kind(self) -> list[str]:
        """``"body"`` or ``"mount"`` (an internal mount mode: most kinetic energy in the mounts'
        internal dofs) for each mode."""
        if self.internal_share is None:
            return ["body"] * len(self.eigenvalues)
        return ["mount" if s > 0.5 else "body" for s in self.internal_share]

    def __repr__(self) -> str:
        from ..display import modal_text

        return modal_text(self)

    def _repr_html_(self) -> str:
        from ..display import modal_html

        return modal_html(self)

    @property
    def omega(self) -> NDArray[np.float64]:
        """Damped angular frequency (rad/s)."""
        return np.abs(self.eigenvalues.imag)

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        return self.omega / (2 * np.pi)

    @property
    def growth_rate(self) -> NDArray[np.float64]:
        """``sigma = Re(lambda)`` (1/s); positive means growing."""
        return self.eigenvalues.real

    @property
    def damping_ratio(self) -> NDArray[np.float64]:
        """``zeta = -sigma / |lambda|`` (negative for a growing mode)."""
        mag = np.abs(self.eigenvalues)
        return np.where(mag > 0, -self.eigenvalues.real / np.where(mag > 0, mag, 1), 0.0)

    @property
    def stable(self) -> bool:
        scale = max(np.abs(self.eigenvalues).max(), 1e-300)
        return bool(np.all(self.growth_rate <= 1e-9 * scale))

    def dominant(self, tie: float = 0.01) -> list[tuple[str, ...]]:
        """The dof with the largest kinetic-energy share in each mode (the decoupling table's
        maximum), with any other dof within ``tie`` of it (a whirl mode of a symmetric, spinning
        layout shares its energy equally between two planes), largest first."""
        out = []
        for row in self.participation:
            order = np.argsort(-row, kind="stable")
            out.append(tuple(DOF_NAMES[j] for j in order if row[j] >= row[order[0]] - tie))
        return out

    def decoupling_table(self) -> dict[str, list[float]]:
        """Kinetic-energy shares in percent, ``{dof: [share of mode 1, ...]}`` (rows sum to 100)."""
        return {n: (100.0 * self.participation[:, j]).tolist() for j, n in enumerate(DOF_NAMES)}

    def to_dict(self) -> dict:
        out = self._to_dict()
        if self.internal_share is not None:
            out["mount_elements"] = list(self.mount_elements)
            out["internal_dofs"] = self.internal_dofs
            for j, row in enumerate(out["modes"]):
                row["kind"] = self.kind[j]
                row["internal_energy_share"] = float(self.internal_share[j])
        return out

    def _to_dict(self) -> dict:
        return {
            "thrust": self.thrust,
            "linearization": self.linearization,
            "modes": [
                {
                    "omega": float(self.omega[j]),
                    "frequency_hz": float(self.frequency_hz[j]),
                    "growth_rate": float(self.growth_rate[j]),
                    "damping_ratio": float(self.damping_ratio[j]),
                    "dominant": list(self.dominant()[j]),
                    "energy_share": dict(zip(DOF_NAMES, map(float, self.participation[j]))),
                    "shape_real": self.shapes[:, j].real.tolist(),
                    "shape_imag": self.shapes[:, j].imag.tolist(),
                }
                for j in range(len(self.eigenvalues))
            ],
        }

    def to_xarray(self):
        import xarray as xr

        from .. import __version__

        extra = {}
        if self.internal_share is not None:
            extra = {"internal_share": ("mode", self.internal_share, {
                         "units": "1", "long_name": "kinetic-energy share of the beam mounts' internal dofs"}),
                     "kind": ("mode", self.kind, {"long_name": "body or mount (internal mount mode)"})}
        return xr.Dataset(
            {
                **extra,
                "omega": ("mode", self.omega, {"units": "rad/s"}),
                "frequency_hz": ("mode", self.frequency_hz, {"units": "Hz"}),
                "growth_rate": ("mode", self.growth_rate, {"units": "1/s"}),
                "damping_ratio": ("mode", self.damping_ratio, {"units": "1"}),
                "shape_real": (("dof", "mode"), self.shapes.real),
                "shape_imag": (("dof", "mode"), self.shapes.imag),
                "participation": (("mode", "dof"), self.participation, {
                    "units": "1", "long_name": "kinetic-energy share of each dof (mass-centre coordinates)"}),
            },
            coords={"mode": np.arange(len(self.eigenvalues)), "dof": list(DOF_NAMES)},
            attrs={"thrust": self.thrust, "linearization": self.linearization, "impstab_version": __version__},
        )


def coupling_centre(matrix6: NDArray) -> NDArray:
    """The point ``p`` (m, from A) about which the translation-rotation coupling block is symmetric.

    Moving the reference point of a symmetric 6 x 6 matrix ``[[A, C], [C^T, B]]`` (mass or
    stiffness about A) to ``p`` turns its coupling block into ``A S(p) + C``; its skew part
    vanishes at ``p = -2 (tr(A) I - A)^-1 axial(C - C^T) / 2``, unique for ``A`` positive definite.
    For a rigid body's mass matrix this is the cg (the coupling vanishes there); for a mount
    system's stiffness it is the elastic centre (centre of stiffness).
    """
    m = np.asarray(matrix6, dtype=float)
    a, c = m[:3, :3], m[:3, 3:]
    skew_c = 0.5 * (c - c.T)
    axial = np.array([skew_c[2, 1], skew_c[0, 2], skew_c[1, 0]])
    return -2.0 * np.linalg.solve(np.trace(a) * np.eye(3) - a, axial)


def energy_shares(shapes: NDArray, mass: NDArray) -> NDArray:
    """Decoupling table ``(k, 6)`` of the shapes ``(6, k)`` (at A) in mass-centre coordinates."""
    from ..kinematics import rigid_map6

    centre = coupling_centre(mass)
    t = rigid_map6(centre)
    w = np.linalg.inv(t)
    m_c = w.T @ mass @ w
    y = t @ np.asarray(shapes, dtype=complex)
    parts = (y.conj() * (m_c @ y)).real            # (6, k)
    total = parts.sum(axis=0)
    return (parts / np.where(total > 0, total, 1.0)).T


def _undamped_eigenpairs(system: LinearSystem):
    """``lambda = i sqrt(s)`` from ``K x = s M x``: exact zero growth for real positive s.

    A complex pair ``s, conj(s)`` (flutter) gives one growing and one decaying root at the same
    frequency; a negative real s (divergence) gives ``lambda = +sqrt(-s)``.
    """
    s, x = np.linalg.eig(np.linalg.solve(system.M, system.K))
    scale = max(np.abs(s).max(), 1e-300)
    real = np.abs(s.imag) <= 1e-12 * scale
    root = np.where(real, np.sqrt(np.abs(s.real)) + 0j, np.sqrt(s.astype(complex)))
    lam = np.where(real & (s.real >= 0), 1j * root, np.where(real, root, 1j * root))
    lam = np.where(~real & (lam.imag < 0), -lam, lam)
    return lam, x


def _canonical_repeated(vals: NDArray, vecs: NDArray, m_diag: NDArray) -> NDArray:
    """A basis of each repeated eigenvalue's eigenspace that does not depend on the eigensolver.

    Any basis of the eigenspace of a repeated eigenvalue is as good as another, and LAPACK
    returns an arbitrary one: on a symmetric layout it mixes the sway-yaw and heave-pitch
    planes. Here ``g`` pivot dofs are chosen by QR with column pivoting of the mass-weighted
    vectors, and the basis is the one whose vectors are 1 at their own pivot and 0 at the
    others: on a symmetric layout exactly the two planes' modes. An exactly defective group
    (dependent vectors) is left as it is.
    """
    from scipy.linalg import qr

    scale = max(float(np.abs(vals).max(initial=0.0)), 1e-300)
    out = vecs.copy()
    start = 0
    while start < len(vals):
        stop = start + 1
        while stop < len(vals) and abs(vals[stop] - vals[start]) <= TOL_DUPLICATE * scale:
            stop += 1
        if stop - start > 1:
            v = vecs[:, start:stop]
            _, _, piv = qr((v * np.sqrt(m_diag)[:, None]).T, pivoting=True)
            piv = np.sort(piv[: stop - start])
            block = v[piv, :]
            if np.linalg.cond(block) < 1e8:
                basis = v @ np.linalg.inv(block)
                # listed by their first dof (sway before heave), for a stable order
                w = np.abs(basis) * np.sqrt(m_diag)[:, None]
                first = np.argmax(w > 1e-8 * w.max(axis=0, keepdims=True), axis=0)
                out[:, start:stop] = basis[:, np.argsort(first, kind="stable")]
        start = stop
    return out


def modes_of_system(system: LinearSystem) -> ModalResult:
    """Modes of a :class:`LinearSystem`."""
    if not (np.any(system.D) or np.any(system.G)):
        vals, vecs = _undamped_eigenpairs(system)
    else:
        vals, vecs = np.linalg.eig(system.state_matrix())
        scale = max(np.abs(vals).max(), 1e-300)
        keep = (vals.imag > 1e-12 * scale) | (np.abs(vals.imag) <= 1e-12 * scale)
        vals, vecs = vals[keep], vecs[:6, keep]
    vals, vecs = np.asarray(vals, dtype=complex), np.asarray(vecs, dtype=complex)
    order = np.lexsort((vals.real, np.abs(vals.imag)))
    vals, vecs = vals[order], vecs[:, order]
    vecs = _canonical_repeated(vals, vecs, np.diag(system.M))
    big = np.argmax(np.abs(vecs), axis=0)
    piv = vecs[big, np.arange(vecs.shape[1])]
    shapes = vecs / piv
    part = energy_shares(shapes, system.M)
    return ModalResult(system.thrust, system.linearization, vals, shapes, part)


def modes(model: Model, thrust: float = 0.0, linearization: str | None = None) -> ModalResult:
    """Natural frequencies, damping ratios, growth rates and mode shapes at thrust ``thrust`` (N).

    With compressible fluid loading each mode is computed with the added mass and radiation
    damping at its own frequency, iterated to consistency (fixed point on the frequency).
    """
    if model.is_viscoelastic:  # internal variables (and any massive beams' dofs): the augmented system
        from .viscoelastic import viscoelastic_modes

        return viscoelastic_modes(model, thrust, linearization)
    if model.has_massive_beams:  # internal mount dofs: the grown system
        grown = _grown_modes(model, thrust, linearization)
        if not model.fluid.compressible:
            return grown
        return _fluid_consistent(model, thrust, linearization, grown,
                                 lambda f: _grown_modes(model, thrust, linearization, f))
    base = modes_of_system(linearize(model, thrust, linearization))
    if not model.fluid.compressible:
        return base
    return _fluid_consistent(model, thrust, linearization, base)


def _fluid_consistent(model: Model, thrust: float, linearization: str | None, base: ModalResult,
                      solve: Callable[[float], ModalResult] | None = None) -> ModalResult:
    """Each mode with the fluid coefficients at its own frequency (fixed point on the frequency).

    ``base``: the modes with the coefficients at 0 Hz; ``solve(f)``: every mode with the
    coefficients at ``f`` Hz (default: the body's 6 dofs; the grown system of massive beam mounts
    passes its own). Modes that converge to one frequency share one eigenproblem there: each takes
    a different eigenvalue of it (the nearest not taken yet), so a repeated eigenvalue is listed as
    often as its multiplicity, with independent shapes, never one mode twice.
    """
    from .linearize import ModelFamily

    def body_modes(f: float) -> ModalResult:
        fam = ModelFamily(model, linearization, fluid_frequency=f)
        m, d, g, k, u0, r0 = fam.evaluate(np.array([thrust]))
        return modes_of_system(LinearSystem(m[0], d[0], g[0], k[0], thrust, fam.linearization, u0[0], r0[0]))

    solve = body_modes if solve is None else solve
    solved: dict[float, ModalResult] = {}

    def at(f: float) -> ModalResult:
        if f not in solved:
            solved[f] = solve(f)
        return solved[f]

    taken: dict[float, set[int]] = {}
    n = len(base.eigenvalues)
    vals, shapes, part = base.eigenvalues.copy(), base.shapes.copy(), base.participation.copy()
    internal = None if base.internal_share is None else base.internal_share.copy()
    for j in range(n):
        target, f = vals[j], abs(vals[j].imag) / (2 * np.pi)
        for _ in range(50):
            f = next((h for h in taken if abs(h - f) <= FREQUENCY_TOLERANCE * max(h, 1e-300)), f)
            res = at(f)
            dist = np.abs(res.eigenvalues - target)
            dist[list(taken.get(f, ()))] = np.inf
            i = int(np.argmin(dist))
            target = res.eigenvalues[i]
            f_new = abs(target.imag) / (2 * np.pi)
            if abs(f_new - f) <= FREQUENCY_TOLERANCE * max(f_new, 1e-300):
                break
            f = f_new
        taken.setdefault(f, set()).add(i)
        vals[j], shapes[:, j], part[j] = res.eigenvalues[i], res.shapes[:, i], res.participation[i]
        if internal is not None:
            internal[j] = res.internal_share[i]
    order = np.lexsort((vals.real, np.abs(vals.imag)))
    return replace(base, eigenvalues=vals[order], shapes=shapes[:, order], participation=part[order],
                   internal_share=None if internal is None else internal[order])


#: relative change of a mode's frequency that ends the fluid fixed point; modes whose frequencies
#: agree to it share one eigenproblem
FREQUENCY_TOLERANCE = 1e-12


def _grown_modes(model: Model, thrust: float, linearization: str | None, fluid_frequency: float = 0.0) -> ModalResult:
    """Modes of the body with the internal dofs of its massive beam mounts
    (:mod:`impstab.linear.mount_dofs`): every eigenvalue of the grown system with ``omega >= 0``;
    shapes and the decoupling table of the body dofs, the internal share of each mode's kinetic
    energy beside them. ``fluid_frequency`` (Hz): where compressible fluid coefficients are taken
    (they act on the body's dofs only)."""
    from ..errors import NumericalError
    from .linearize import ModelFamily

    fam = ModelFamily(model, linearization, fluid_frequency=fluid_frequency)
    m, d, g, k = (np.asarray(a[0], dtype=float) for a in fam.matrices(np.array([float(thrust)])))
    if not np.isfinite(k).all():
        raise NumericalError(f"no static equilibrium found at thrust {thrust:.6g} N: the mounts cannot carry this thrust")
    n = m.shape[0]
    if not (np.any(d) or np.any(g)):
        vals, vecs = _undamped_eigenpairs(LinearSystem(m, d, g, k, float(thrust), fam.linearization, np.zeros(3), np.eye(3)))
    else:
        mk = np.linalg.solve(m, np.hstack([k, d + g]))
        a = np.block([[np.zeros((n, n)), np.eye(n)], [-mk[:, :n], -mk[:, n:]]])
        vals, vecs = np.linalg.eig(a)
        scale = max(np.abs(vals).max(), 1e-300)
        keep = (vals.imag > 1e-12 * scale) | (np.abs(vals.imag) <= 1e-12 * scale)
        vals, vecs = vals[keep], vecs[:n, keep]
    vals, vecs = np.asarray(vals, dtype=complex), np.asarray(vecs, dtype=complex)
    order = np.lexsort((vals.real, np.abs(vals.imag)))
    vals, vecs = vals[order], vecs[:, order]
    vecs = _canonical_repeated(vals, vecs, np.diag(m))
    return body_modes(model, float(thrust), fam.linearization, vals, vecs, m)  # type: ignore[arg-type]


def body_modes(model: Model, thrust: float, linearization: str, vals, vecs, m) -> ModalResult:
    """The :class:`ModalResult` of eigenvalues ``vals (k,)`` with displacement vectors ``vecs (nq, k)``
    of mass ``m (nq, nq)``: shapes and decoupling table of the body's 6 dofs; with massive beam
    mounts (their internal dofs after the body's, ``nq - 6`` of them) each mode's internal share of
    kinetic energy."""
    extra = {}
    nq = m.shape[0]
    if model.has_massive_beams:
        energy = (vecs.conj() * (m @ vecs)).real                 # (nq, k)
        total = energy.sum(axis=0)
        internal = np.clip(energy[6:].sum(axis=0) / np.where(total > 0, total, 1.0), 0.0, 1.0)  # rounding: no -0.0
        extra = dict(internal_share=internal, internal_dofs=nq - 6,
                     mount_elements=tuple(int(mt.beam.elements) for mt in model.mounts if mt.is_massive_beam))
    body = vecs[:6]
    big = np.argmax(np.abs(body), axis=0)
    piv = body[big, np.arange(body.shape[1])]
    shapes = body / np.where(piv != 0, piv, 1.0)
    return ModalResult(thrust, linearization, vals, shapes, energy_shares(shapes, m[:6, :6]), **extra)  # type: ignore[arg-type]
