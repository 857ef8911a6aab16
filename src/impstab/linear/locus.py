"""Eigenvalue loci against thrust (the paper's Figure 4), computed in one batch and tracked.

Each mode of the propulsor is a *branch* of the locus: a conjugate pair of eigenvalues
``sigma +- i omega`` of the state matrix, followed from thrust to thrust. The branches are named
by the dofs that carry their kinetic energy at the first thrust (``"sway, yaw"``), so that a
figure can say which motion goes unstable.

Where the dofs fall apart into independent groups over the whole sweep (a symmetric layout:
surge, roll, the sway-yaw and the heave-pitch planes, see :mod:`impstab.linear.blocks`), every
group is solved and tracked on its own. The two planes of a symmetric layout have identical
eigenvalues; solved together, an eigensolver returns arbitrary mixtures of the two planes and a
branch could not be named; solved apart, each plane keeps its own modes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError
from ..limits import check_number
from ..model.model import DOF_NAMES, Model
from .eigen import state_matrices
from .linearize import ModelFamily
from .mount_dofs import mount_dofs
from .tracking import track_modes

__all__ = ["LocusResult", "locus", "DOMINANT_SHARE", "SAME_TOL", "matching_order"]

#: kinetic-energy share above which a dof names a branch
DOMINANT_SHARE = 0.2
#: relative distance within which two eigenvalues are one conjugate pair or one repeated value
_PAIR_TOL = 1e-8
#: two groups of dofs with eigenvalues this close (relative) at every thrust are identical planes
#: (near a double root rounding moves eigenvalues by sqrt(eps), about 1e-8)
SAME_TOL = 1e-6
#: coupling between two dofs, relative to the largest entry, below which they are independent
COUPLING_TOL = 1e-12
#: massive beam mounts: the locus carries the beams' fixed-interface modes below this multiple of the
#: body's highest natural frequency (the critical thrust and the modes keep those below
#: :data:`impstab.linear.mount_dofs.CUTOFF`); the static constraint modes keep the statics exact and the
#: body's eigenvalues move by about ``LOCUS_CUTOFF^-2`` of the dropped modes' effective mass share
LOCUS_CUTOFF = 100.0


@dataclass(frozen=True, eq=False)
class LocusResult:
    """Eigenvalues of the state matrix along a thrust sweep, one column per tracked eigenvalue.

    Attributes
    ----------
    thrust : (N,) thrusts (N)
    eigenvalues : (N, 12) complex, ``lambda = sigma + i omega`` (1/s), tracked by MAC (with
        viscoelastic mounts: (N, 12 + 3 x Prony terms), the relaxation roots of the internal
        variables included)
    linearization : str
    model_name : str
    critical_thrust : float or None
        The critical thrust when it was computed alongside (drawn as a marker line).
    operating_thrust : float or None
        Design thrust (N).
    mode : (12,) int array or None
        The branch (mode) each column belongs to: the two eigenvalues of a conjugate pair share
        it. Branches are numbered by their frequency at the first thrust.
    participation : (N, 12, 6) array or None
        Kinetic-energy share of each dof (surge ... yaw) in each column's mode.
    critical_kind : str or None
        ``"flutter"``, ``"divergence"`` or ``"none"`` when the critical thrust was computed.
    critical_frequency_hz : float or None
        Frequency at the onset (Hz).
    undamped_critical_thrust : float or None
        Critical thrust of the same model without dampers (N), when computed.
    fluid_frequency_hz : float or None
        Frequency (Hz) at which compressible fluid coefficients were taken (None: none or
        incompressible).
    """

    thrust: NDArray[np.float64]
    eigenvalues: NDArray[np.complex128]
    linearization: str
    model_name: str = ""
    critical_thrust: float | None = None
    operating_thrust: float | None = None
    mode: NDArray[np.int64] | None = None
    participation: NDArray[np.float64] | None = None
    critical_kind: str | None = None
    critical_frequency_hz: float | None = None
    undamped_critical_thrust: float | None = None
    fluid_frequency_hz: float | None = None
    internal_share: NDArray[np.float64] | None = None
    mount_elements: tuple[int, ...] = ()

    @property
    def is_mount_branch(self) -> NDArray[np.bool_]:
        """Per column: True for an internal mode of massive beam mounts (most of its kinetic energy
        in the mounts' internal dofs at the first thrust); all False without such mounts."""
        if self.internal_share is None:
            return np.zeros(self.eigenvalues.shape[1], dtype=bool)
        first = np.nan_to_num(self.internal_share[0], nan=0.0)
        return first > 0.5

    @property
    def growth_rate(self) -> NDArray[np.float64]:
        """``sigma = Re(lambda)`` (1/s), shape (N, 12)."""
        return self.eigenvalues.real

    @property
    def omega(self) -> NDArray[np.float64]:
        """``Im(lambda)`` (rad/s), shape (N, 12)."""
        return self.eigenvalues.imag

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        """``Im(lambda) / 2 pi`` (Hz), shape (N, 12)."""
        return self.eigenvalues.imag / (2 * np.pi)

    @property
    def modes(self) -> NDArray[np.int64]:
        """The branch of every column (each column its own when not computed)."""
        return np.arange(self.eigenvalues.shape[1]) if self.mode is None else self.mode

    def branch_labels(self, threshold: float = DOMINANT_SHARE) -> list[str]:
        """Name of each branch: its dominant dofs at the first thrust, e.g. ``"sway, yaw"``.

        A dof is named when it carries at least ``threshold`` of the kinetic energy of the mode
        (at the first thrust where the branch's eigenvalue is not repeated).
        """
        modes = self.modes
        out = []
        for b in range(int(modes.max()) + 1):
            cols = np.flatnonzero(modes == b)
            if self.participation is None:
                out.append(f"branch {b + 1}")
                continue
            share = self.participation[self._naming_row(cols), cols[0]]
            names = [DOF_NAMES[i] for i in np.argsort(-share) if share[i] >= threshold]
            label = ", ".join(names) if names else DOF_NAMES[int(np.argmax(share))]
            if self.is_mount_branch[cols[0]]:
                label = f"mount internal ({label})"
            out.append(label)
        return out

    def _naming_row(self, cols) -> int:
        """The first thrust at which the branch's eigenvalue is simple: at a repeated eigenvalue
        (two planes that only a gyroscope couples, at zero spin) its mode is any mixture."""
        lam = self.eigenvalues
        others = np.setdiff1d(np.arange(lam.shape[1]), cols)
        finite = np.all(np.isfinite(self.participation[:, cols[0]]), axis=-1)
        for i in np.flatnonzero(finite):
            v = lam[i, cols[0]]
            if not others.size or np.nanmin(np.abs(lam[i, others] - v)) > 1e-6 * max(abs(v), 1e-300):
                return int(i)
        return int(np.flatnonzero(finite)[0]) if finite.any() else 0

    def to_xarray(self):
        """Dataset with coordinates ``thrust`` and ``branch``; settings in ``attrs``."""
        import xarray as xr

        from .. import __version__

        attrs = {
            "title": f"eigenvalue loci of {self.model_name}",
            "linearization": self.linearization,
            "model": self.model_name,
            "impstab_version": __version__,
            "convention": "lambda = sigma + i omega, x(t) = Re(X exp(lambda t)); frequency_hz = omega / 2 pi; "
                          "one branch per eigenvalue, 'mode' groups a conjugate pair",
        }
        for name in ("critical_thrust", "operating_thrust", "critical_kind", "critical_frequency_hz",
                     "undamped_critical_thrust", "fluid_frequency_hz"):
            if getattr(self, name) is not None:
                attrs[name] = getattr(self, name)
        data = {
            "growth_rate": (("thrust", "branch"), self.growth_rate, {"units": "1/s", "long_name": "Re(lambda)"}),
            "omega": (("thrust", "branch"), self.omega, {"units": "rad/s", "long_name": "Im(lambda)"}),
            "frequency_hz": (("thrust", "branch"), self.frequency_hz, {"units": "Hz", "long_name": "Im(lambda) / 2 pi"}),
        }
        coords = {
            "thrust": ("thrust", self.thrust, {"units": "N", "long_name": "thrust"}),
            "branch": ("branch", np.arange(self.eigenvalues.shape[1]), {"units": "1", "long_name": "eigenvalue track"}),
        }
        if self.mode is not None:
            labels = self.branch_labels()
            coords["mode"] = ("branch", self.mode, {"units": "1", "long_name": "mode (conjugate pair) of the track"})
            data["mode_label"] = ("branch", [labels[b] for b in self.mode],
                                  {"long_name": "dominant dofs of the mode at the first thrust"})
        if self.participation is not None:
            coords["dof"] = ("dof", list(DOF_NAMES))
            data["participation"] = (("thrust", "branch", "dof"), self.participation,
                                     {"units": "1", "long_name": "kinetic-energy share of each dof in the mode"})
        if self.internal_share is not None:
            data["internal_share"] = (("thrust", "branch"), self.internal_share, {
                "units": "1", "long_name": "kinetic-energy share of the beam mounts' internal dofs in the mode"})
            attrs["mount_elements"] = list(self.mount_elements)
        return xr.Dataset(data, coords=coords, attrs=attrs)

    @classmethod
    def from_xarray(cls, ds) -> "LocusResult":
        """Rebuild a result from :meth:`to_xarray` output (e.g. read back from netCDF)."""
        lam = ds["growth_rate"].values + 1j * ds["omega"].values
        a = ds.attrs
        return cls(
            ds["thrust"].values, lam, a.get("linearization", ""), a.get("model", ""),
            _attr(a, "critical_thrust"), _attr(a, "operating_thrust"),
            ds["mode"].values.astype(np.int64) if "mode" in ds.coords else None,
            ds["participation"].values if "participation" in ds else None,
            a.get("critical_kind"), _attr(a, "critical_frequency_hz"), _attr(a, "undamped_critical_thrust"),
            _attr(a, "fluid_frequency_hz"),
            ds["internal_share"].values if "internal_share" in ds else None,
            tuple(int(e) for e in np.atleast_1d(a.get("mount_elements", []))),
        )

    def plot(self, ax=None, *, growth_scale: str = "auto", mount_branches: bool = False):
        """Frequency (Hz) and growth rate (1/s) of every branch against thrust; returns the axes.

        See :func:`impstab.plot.locus.plot_locus`: ``ax`` may be None (a new figure), one Axes
        (frequency only) or a pair; the result is a :class:`~impstab.plot.LocusAxes`
        ``(frequency, growth)``, or the one Axes given. With massive beam mounts the internal
        mount branches (:attr:`is_mount_branch`, hundreds of Hz above the body modes) are left
        out unless ``mount_branches``.
        """
        from ..plot.locus import plot_locus

        shown = self if mount_branches or not self.is_mount_branch.any() else self.body_branches()
        return plot_locus(shown, ax=ax, growth_scale=growth_scale)

    def body_branches(self) -> "LocusResult":
        """The result without the internal mount branches (the same object without such mounts)."""
        keep = ~self.is_mount_branch
        if keep.all():
            return self
        from dataclasses import replace

        mode = None if self.mode is None else np.unique(self.mode[keep], return_inverse=True)[1].astype(np.int64)
        return replace(self, eigenvalues=self.eigenvalues[:, keep], mode=mode,
                       participation=None if self.participation is None else self.participation[:, keep],
                       internal_share=None if self.internal_share is None else self.internal_share[:, keep])

    def __repr__(self) -> str:
        from ..display import locus_text

        return locus_text(self)

    def _repr_html_(self) -> str:
        from ..display import locus_html

        return locus_html(self)


def _attr(attrs, name):
    v = attrs.get(name)
    return None if v is None else float(v)


def locus(
    model: Model,
    thrusts: NDArray[np.float64] | None = None,
    *,
    linearization: str | None = None,
    steps: int = 200,
    thrust_max: float | None = None,
    fluid_frequency: float | None = None,
    critical: bool = False,
) -> LocusResult:
    """Eigenvalue loci of ``model`` over ``thrusts`` (N), evaluated in one batch and tracked.

    Parameters
    ----------
    model : Model
    thrusts : array_like, optional
        Thrust values; default ``steps + 1`` values from 0 to ``thrust_max``.
    linearization : {"equilibrium", "classical"}, optional
    steps : int
        Number of intervals when ``thrusts`` is not given.
    thrust_max : float, optional
        Default ``model.analysis.thrust_max``.
    fluid_frequency : float, optional
        Frequency (Hz) of compressible fluid coefficients (radiation damping); default 0, or with
        ``critical=True`` the onset frequency the critical thrust was found at.
    critical : bool
        Also compute the critical thrust (damped and undamped) over the same range and store
        it in the result (the figure marks it).
    """
    if thrusts is None:
        if steps < 1:
            raise ModelError("steps", steps, "must be at least 1")
        t_max = check_number("thrust_max", thrust_max if thrust_max is not None else model.analysis.thrust_max, "thrust")
        thrusts = np.linspace(0.0, t_max, steps + 1)
    thrusts = np.asarray(thrusts, dtype=float)
    if thrusts.ndim != 1 or thrusts.size == 0 or not np.all(np.isfinite(thrusts)):
        raise ModelError("thrusts", thrusts.tolist(), "must be a 1-D list of finite numbers")
    crit = None
    if critical:
        from .critical_thrust import critical_thrust

        crit = critical_thrust(model, thrust_max=float(thrusts.max()), linearization=linearization)
        if fluid_frequency is None and crit.fluid_frequency_hz is not None:
            fluid_frequency = crit.fluid_frequency_hz
    f_fluid = float(fluid_frequency or 0.0)
    if model.is_viscoelastic:  # internal variables: the augmented first-order system
        from .viscoelastic import ViscoelasticFamily, augmented_matrices

        fam = ViscoelasticFamily(model, linearization, fluid_frequency=f_fluid, cutoff=LOCUS_CUTOFF)
        m, c, k, rho = fam.system(thrusts)
        e, a = augmented_matrices(m, c, k, rho, fam.terms)  # type: ignore[attr-defined]
        good = np.isfinite(a).all(axis=(1, 2))
        ops = np.full(a.shape, np.nan)
        ops[good] = np.linalg.solve(e[good], a[good])
        vals, shares, mode = _tracked_branches(m, c, k, operators=ops)
    else:
        fam = ModelFamily(model, linearization, fluid_frequency=f_fluid, mount_dofs=False)
        internal_dofs = mount_dofs(model, cutoff=LOCUS_CUTOFF)
        if internal_dofs is None:
            m, d, g, k = fam.matrices(thrusts)
        else:  # massive beam mounts: the internal dofs in the locus's frequency range
            if fam.is_affine:
                m, d, g, k = fam.matrices(thrusts)
                r0 = None
            else:
                m, d, g, k, _, r0 = fam.evaluate(thrusts, strict=False)
            m, d, g, k = internal_dofs.augment(np.asarray(m), np.asarray(d), np.asarray(g), np.asarray(k), r0)
        vals, shares, mode = _tracked_branches(np.asarray(m), np.asarray(d + g), np.asarray(k))
    internal = None
    if shares.shape[-1] > 6:  # massive beam mounts: body shares, and the internal dofs' share beside
        internal = shares[..., 6:].sum(axis=-1)
        body = shares[..., :6]
        tot = body.sum(axis=-1, keepdims=True)
        shares = body / np.where(tot > 0, tot, 1.0)
    return LocusResult(
        thrusts, vals, fam.linearization, model.name,  # type: ignore[arg-type]
        None if crit is None else crit.thrust, model.thrust.operating, mode, shares,
        None if crit is None else crit.kind, None if crit is None else crit.frequency_hz,
        None if crit is None else crit.undamped_thrust,
        f_fluid if model.fluid.compressible else None,
        internal, tuple(int(mt.beam.elements) for mt in model.mounts if mt.is_massive_beam),
    )


def _dof_groups(m, c, k) -> list[NDArray[np.int64]]:
    """Groups of dofs coupled anywhere on the sweep (rows with finite matrices only).

    Judged in mass-normalised coordinates ``S X S``, ``S = diag(M)^-1/2`` (dimensionless mass,
    stiffness in 1/s^2, damping in 1/s), where an entry below ``COUPLING_TOL`` of the largest
    is a rounding residue of a coupling that vanishes by symmetry (1e-17 relative in the bundled
    ring). :func:`impstab.linear.blocks.decoupled_blocks` balances the operator ``M^-1 K``
    instead, which is right for one operator but fails at a thrust where a coupling vanishes on
    one side only (``K`` is not symmetric under a follower force): the balancing factor runs away
    there and rounding residues look like couplings.
    """
    from scipy.sparse.csgraph import connected_components

    ok = np.all(np.isfinite(m), axis=(1, 2)) & np.all(np.isfinite(c), axis=(1, 2)) & np.all(np.isfinite(k), axis=(1, 2))
    n = m.shape[-1]
    if not ok.any():
        return [np.arange(n)]
    s = 1.0 / np.sqrt(np.abs(np.diagonal(m[ok], axis1=1, axis2=2)))
    norm = s[:, :, None] * s[:, None, :]
    mm, cc, kk = (np.abs(x[ok]) * norm for x in (m, c, k))
    w_scale = np.sqrt(kk.max())
    coupled = ((mm > COUPLING_TOL * mm.max()) | (kk > COUPLING_TOL * kk.max())
               | (cc > COUPLING_TOL * max(cc.max(), w_scale))).any(axis=0)
    coupled = coupled | coupled.T
    _, labels = connected_components(coupled, directed=False)
    return [np.flatnonzero(labels == lab) for lab in np.unique(labels)]


def _tracked_branches(m, c, k, operators=None):
    """Eigenvalues (N, 2n), kinetic-energy shares (N, 2n, n) and the mode of each column.

    ``operators (N, S, S)``: the first-order operators ``E^-1 A`` of an augmented system (internal
    variables after the ``2 n`` displacement and velocity states), solved as one group; then
    the columns are its ``S`` eigenvalues and the shares those of the displacement states.
    """
    big, n = m.shape[0], m.shape[-1]
    size = 2 * n if operators is None else operators.shape[-1]
    vals = np.full((big, size), np.nan + 0j)
    shares = np.full((big, size, n), np.nan)
    mode = np.zeros(size, dtype=np.int64)
    ok = np.all(np.isfinite(m), axis=(1, 2)) & np.all(np.isfinite(c), axis=(1, 2)) & np.all(np.isfinite(k), axis=(1, 2))
    rows = np.flatnonzero(ok)
    col = 0
    first_freq = []
    done: list[NDArray] = []
    groups_of_dofs = _dof_groups(m, c, k) if operators is None else [np.arange(n)]
    for dofs in groups_of_dofs:
        nb = dofs.size
        ix = np.ix_(dofs, dofs)
        width = 2 * nb if operators is None else size
        if rows.size:
            sub = (slice(None),) + ix
            ops = state_matrices(m[rows][sub], c[rows][sub], k[rows][sub]) if operators is None else operators[rows]
            lam, vec = np.linalg.eig(ops)
            if operators is None and n > 6:  # massive beam mounts: body and internal modes apart
                lam, vec = _track_body_and_internal(lam, vec, np.diagonal(m[rows][sub], axis1=1, axis2=2))
            else:
                lam, vec = track_modes(lam, vec)
            for other in done:
                perm = matching_order(other, lam)
                if perm is not None:  # identical planes: continue through coalescences alike
                    lam = np.take_along_axis(lam, perm, axis=1)
                    vec = np.take_along_axis(vec, perm[:, None, :], axis=2)
                    break
            done.append(lam)
            disp = vec[:, :nb, :]
            w = np.abs(disp) ** 2 * np.diagonal(m[rows][sub], axis1=1, axis2=2)[:, :, None]
            tot = w.sum(axis=1, keepdims=True)
            w = w / np.where(tot > 0, tot, 1.0)
            cols = np.arange(col, col + width)
            vals[np.ix_(rows, cols)] = lam
            full = np.zeros((rows.size, width, n))
            full[:, :, dofs] = np.transpose(w, (0, 2, 1))
            shares[rows[:, None], cols[None, :], :] = full
            groups = _conjugate_groups(lam, vec if operators is None and n > 6 else None)
            for gcols in groups:
                mode[col + gcols] = len(first_freq)
                first_freq.append(float(np.abs(lam[0, gcols].imag).max()))
        col += width
    # number the branches by frequency at the first thrust (then by growth)
    order = np.argsort(np.asarray(first_freq), kind="stable")
    renumber = np.empty_like(order)
    renumber[order] = np.arange(order.size)
    mode = renumber[mode]
    # columns listed branch by branch, the upper member of a pair first
    key = np.lexsort((-np.nan_to_num(vals[rows[0]].imag if rows.size else np.zeros(size)), mode))
    return vals[:, key], shares[:, key, :], mode[key]


def _track_body_and_internal(lam, vec, m_diag):
    """Tracking of a system grown by the internal dofs of massive beam mounts.

    The body's eigenvalues (most kinetic energy in the first six dofs) and the mounts' internal
    ones are tracked apart: tracked together, the distance scale of the assignment is the internal
    modes' (hundreds of Hz) and the body's branches would be matched by their eigenvectors alone.
    Each repeated body eigenvalue (two identical planes of a symmetric layout, which the internal
    dofs join into one group of dofs) gets a solver-independent basis first
    (:func:`impstab.linear.modes._canonical_repeated`). Rows whose body count differs from the
    first row's are tracked as one set.
    """
    from .modes import _canonical_repeated

    n = m_diag.shape[1]
    w = np.abs(vec[:, :n, :]) ** 2 * m_diag[:, :, None]
    body = w[:, :6, :].sum(axis=1) > 0.5 * w.sum(axis=1)             # (rows, 2n)
    count = body.sum(axis=1)
    if not np.all(count == count[0]) or count[0] == 0:
        return track_modes(lam, vec)
    k = int(count[0])
    order = np.argsort(~body, axis=1, kind="stable")                  # body columns first
    lam = np.take_along_axis(lam, order, axis=1)
    vec = np.take_along_axis(vec, order[:, None, :], axis=2)
    weight = np.concatenate([m_diag, m_diag], axis=1)
    for r in range(lam.shape[0]):
        sort = np.lexsort((lam[r, :k].real, lam[r, :k].imag))
        lam[r, :k] = lam[r, :k][sort]
        vec[r, :, :k] = _canonical_repeated(lam[r, :k], vec[r, :, :k][:, sort], weight[r])
    lb, vb = track_modes(lam[:, :k], vec[:, :, :k])
    li, vi = track_modes(lam[:, k:], vec[:, :, k:])
    return np.concatenate([lb, li], axis=1), np.concatenate([vb, vi], axis=2)


def matching_order(ref: NDArray[np.complex128], lam: NDArray[np.complex128]) -> NDArray[np.int64] | None:
    """Per-row column order of ``lam`` (N, k) that follows ``ref`` when both hold the same
    eigenvalues (to :data:`SAME_TOL` relative) at every row, e.g. two identical planes; None
    otherwise. Rows are matched by the assignment of least total distance."""
    from scipy.optimize import linear_sum_assignment

    if ref.shape != lam.shape:
        return None
    scale = max(float(np.nanmax(np.abs(ref), initial=0.0)), 1e-300)
    perm = np.empty(lam.shape, dtype=np.int64)
    for i in range(lam.shape[0]):
        if not (np.all(np.isfinite(ref[i])) and np.all(np.isfinite(lam[i]))):
            if np.isfinite(ref[i]).any() or np.isfinite(lam[i]).any():
                return None
            perm[i] = np.arange(lam.shape[1])
            continue
        dist = np.abs(ref[i][:, None] - lam[i][None, :])
        _, perm[i] = linear_sum_assignment(dist)
        if dist[np.arange(lam.shape[1]), perm[i]].max(initial=0.0) > SAME_TOL * scale:
            return None
    return perm


def _conjugate_groups(lam: NDArray[np.complex128], vectors: NDArray | None = None) -> list[NDArray[np.int64]]:
    """Columns of a tracked set that form one mode: each upper-half column and its conjugate partner.

    A column's partner is the column holding its conjugate value, decided once for the whole
    locus: the partner it has most often at the thrusts where that partner is unambiguous (one
    column within the pairing tolerance), else most often over all thrusts, and never a column
    another one already took. ``vectors (rows, S, k)``: where several columns hold the conjugate
    value (identical planes that one group of dofs carries, or two pairs about to merge), the
    partner at that thrust is the one whose eigenvector is the conjugate of the column's own
    (one-to-one assignment of largest MAC), not the first of them.
    """
    k = lam.shape[1]
    scale = max(float(np.nanmax(np.abs(lam))) if lam.size else 1.0, 1e-300)
    with np.errstate(invalid="ignore"):
        dist = np.abs(lam[:, :, None] - np.conj(lam)[:, None, :])  # (rows, a, b)
        cand = dist <= _PAIR_TOL * scale
        partner = np.argmin(np.where(np.isnan(dist), np.inf, dist), axis=-1)
        unique = cand.sum(axis=-1) == 1
        if vectors is not None:
            from scipy.optimize import linear_sum_assignment

            from .tracking import mac_of_pairs

            for r in range(lam.shape[0]):
                multi = ~unique[r] & cand[r].any(axis=1)
                if multi.any():
                    a, b = np.nonzero(cand[r] & multi[:, None])
                    fit = np.full((k, k), -1.0)
                    fit[a, b] = mac_of_pairs(np.conj(vectors[r][:, a]), vectors[r][:, b])
                    rows = np.flatnonzero(multi)
                    _, cols = linear_sum_assignment(fit[rows], maximize=True)
                    partner[r, rows] = cols
        upper = lam.imag > _PAIR_TOL * scale
    first = np.broadcast_to(np.arange(k), partner.shape)
    linked = upper & cand.any(axis=-1) & (partner != first)
    label = np.arange(k)
    taken = np.zeros(k, dtype=bool)
    for a in range(k):
        rows = linked[:, a]
        if taken[a] or not rows.any():
            continue
        sure = rows & unique[:, a]
        votes = np.bincount(partner[sure if sure.any() else rows, a], minlength=k)
        votes[taken] = 0
        votes[a] = 0
        if votes.max() == 0:
            continue
        b = int(np.argmax(votes))
        taken[a] = taken[b] = True
        label[max(a, b)] = min(a, b)
    return [np.flatnonzero(label == r) for r in np.unique(label)]
