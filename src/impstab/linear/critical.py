"""Critical load of ``M q'' + (D + G) q' + K(p) q = 0``: the first loss of stability from p = 0.

Method (THEORY 5)
-----------------
1. Scan ``p`` on a uniform grid in batches (stacks of eigenproblems), stopping at the first
   unstable point. Between stable grid points, wherever the closest pair of frequencies has a
   local minimum (undamped) or the growth rate a local maximum (damped), the closest approach is
   located by bounded minimisation and tested, so that narrow flutter bubbles are not stepped over.
2. Refine the bracket with an *exact*, smooth indicator that crosses zero linearly, solved by
   Brent's method to machine precision:

   * undamped, non-gyroscopic: eigenvalues ``s = omega^2`` of ``M^-1 K``. The merging cluster
     (two eigenvalues, or four for symmetric layouts where two planes merge at once) is followed
     by its invariant subspace, and ``Delta(p) = k sum s_i^2 - (sum s_i)^2`` over the cluster is a
     symmetric function of the cluster: analytic in ``p`` although the double root is defective
     (its individual eigenvalues carry sqrt(eps) noise, ``Delta`` only eps). ``Delta > 0`` while
     the cluster is real, ``< 0`` once it is a complex pair. Divergence: the cluster mean of the
     real ``s`` crossing zero.
   * damped or gyroscopic: the largest real part of the eigenvalues of the state matrix in the
     cluster that goes unstable (a Hopf crossing, smooth). Where that branch was marginal before
     (undamped gyroscopic systems), the onset is where it leaves the axis by the classification
     tolerance; the branch leaves like ``sqrt(p - p_c)``, so the error is of order tolerance squared.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy import optimize

from .eigen import cluster_participation, kinetic_shares, state_matrices
from .families import CallableFamily, LinearFamily, SystemFamily
from .classify import classify_eigenvalues, unstable_masks
from .small_eig import eigvals_small

__all__ = ["CriticalLoad", "Crossing", "critical_load", "critical_load_family"]

Array = NDArray[np.float64]

#: relative size of an imaginary part (of s) or a real part (of lambda) that counts as unstable
TOL_UNSTABLE = 1e-7
#: real part (relative to the eigenvalue) below which a branch counts as marginal (on the axis)
TOL_MARGINAL = 1e-11
#: rounding floor, relative to the spectral radius
FLOOR = 1e3 * np.finfo(float).eps
#: relative distance within which eigenvalues belong to one cluster
TOL_CLUSTER = 1e-6
#: relative gap below which two real s are symmetric duplicates, not an approach
TOL_DUPLICATE = 1e-9


@dataclass(frozen=True)
class Crossing:
    """A change of stability at load ``load``: ``"loss"`` (stable -> unstable) or ``"gain"``."""

    load: float
    direction: str
    kind: str
    omega: float


@dataclass(frozen=True, eq=False)
class CriticalLoad:
    """Result of a critical-load search.

    Attributes
    ----------
    load : float or None
        Critical load ``p_c`` (first loss of stability from p = 0), None when stable up to ``p_max``.
    kind : {"flutter", "divergence", "none"}
    omega : float or None
        Angular frequency at onset (rad/s); 0 for divergence.
    frequency_hz : float or None
        ``omega / 2 pi`` (Hz).
    mode : (n,) complex array or None
        Displacement shape of the critical mode at onset.
    participation : (n,) array or None
        Kinetic-energy share of each dof in the critical cluster's subspace.
    p_max : float
        Upper end of the search.
    method : str
        ``"coalescence"`` (undamped discriminant) or ``"hopf"`` (state-matrix real part).
    crossings : tuple of Crossing
        Every stability change up to ``p_max`` (only when requested with ``all_crossings``).
    evaluations : int
        Number of eigenproblems solved.
    warnings : tuple of str
        Numerical trouble met on the way (e.g. an onset located only to the classification
        tolerance), never hidden.
    """

    load: float | None
    kind: str
    omega: float | None
    p_max: float
    method: str
    mode: Array | None = None
    participation: Array | None = None
    crossings: tuple[Crossing, ...] = field(default_factory=tuple)
    evaluations: int = 0
    warnings: tuple[str, ...] = field(default_factory=tuple)

    def __repr__(self) -> str:
        from ..display import critical_load_text

        return critical_load_text(self)

    @property
    def frequency_hz(self) -> float | None:
        return None if self.omega is None else self.omega / (2.0 * np.pi)


def _pair_growth(v: Array) -> float:
    """Largest real part of a cluster (upper half plane), from its symmetric functions.

    For the upper-half members (a pair lambda_1, lambda_2, possibly each doubled by symmetry)
    ``c = mean`` and ``d = mean((lambda - c)^2) = ((lambda_1 - lambda_2) / 2)^2`` are analytic in
    the load even where the pair is defective, so ``Re c + |Re sqrt(d)|`` keeps its accuracy
    there; for a single eigenvalue it is just ``Re lambda``.
    """
    up = v[v.imag >= 0] if np.any(v.imag > 0) else v
    c = up.mean()
    d = ((up - c) ** 2).mean()
    return float(c.real + abs(np.sqrt(d + 0j).real))


def _relative_real(v: Array) -> Array:
    """``Re(v) / |v|``, and 0 for an eigenvalue at the origin."""
    mag = np.abs(v)
    return np.where(mag > 0, v.real / np.where(mag > 0, mag, 1.0), 0.0)


class _Unstable(Exception):
    def __init__(self, p: float) -> None:
        self.p = p


class _Engine:
    def __init__(self, family: SystemFamily, p_max: float, undamped: bool | None = None) -> None:
        self.family = family
        self.n = family.n
        self.p_range = (0.0, float(p_max))
        self.evaluations = 0
        self.warnings: list[str] = []
        self._cache: dict[float, tuple] = {}
        # affine families (constant M, D, G; K = K0 + p K1): the operator is op0 + p op1
        parts = family.affine_parts() if hasattr(family, "affine_parts") else None
        if parts is not None:
            d, g = parts[1], parts[2]
        else:
            # damping and gyroscopic terms may depend on the load (a propeller speed following it)
            _, d, g, _ = family.matrices(np.array([0.0, 0.5 * p_max, p_max]))
        self.damped = bool(np.any(d != 0))
        if undamped is None:
            undamped = not (self.damped or np.any(g != 0))
        self.undamped = undamped
        self.ops = None
        if parts is not None:
            m, d, g, k0, k1 = parts
            self.mass = np.array(m)
            if undamped:
                a0 = np.linalg.solve(m, k0)
                a1 = np.linalg.solve(m, k1)
            else:
                a0 = state_matrices(m, d + g, k0)
                a1 = np.zeros_like(a0)
                a1[self.n:, : self.n] = -np.linalg.solve(m, k1)
            self.ops = (a0, a1)

    def operators(self, p: Array) -> tuple[Array, Array]:
        """The eigen-operator (``M^-1 K`` or the state matrix) at each load, and the mass."""
        if self.ops is not None:
            a0, a1 = self.ops
            return a0[None] + p[:, None, None] * a1[None], np.broadcast_to(self.mass, (len(p),) + self.mass.shape)
        m, d, g, k = self.family.matrices(p)
        if self.undamped:
            return np.linalg.solve(m, k), m
        return state_matrices(m, d + g, k), m

    # -- batched classification of grid points --------------------------------------------
    def classify(self, p: Array) -> tuple[Array, Array]:
        """Stability flags and the bubble indicator (closest gap / growth) at each load."""
        ops, _ = self.operators(p)
        self.evaluations += len(p)
        lost = ~np.isfinite(ops).all(axis=(-2, -1))
        if lost.any():
            # no static equilibrium there: a static loss of stability (limit point)
            ops = np.where(lost[:, None, None], np.eye(ops.shape[-1]), ops)
            unstable, indicator = self._classify_ops(ops)
            return unstable | lost, np.where(lost[:, None], -np.inf, indicator)
        return self._classify_ops(ops)

    def unstable_parts(self, vals: Array) -> tuple[Array, Array]:
        """Masks of unstable eigenvalues: (flutter-type, divergence-type), per eigenvalue.

        Each eigenvalue is judged against its own magnitude (a stiff mode must not hide the
        flutter of a soft one), with a rounding floor relative to the spectral radius
        (:mod:`impstab.linear.classify`).
        """
        return unstable_masks(vals, self.undamped, TOL_UNSTABLE, TOL_CLUSTER, FLOOR)

    def _classify_ops(self, ops: Array) -> tuple[Array, Array]:
        return self.classify_values(eigvals_small(ops))

    def classify_values(self, vals: Array) -> tuple[Array, Array]:
        """Stability flags and indicators of problems with eigenvalues ``vals (N, n)``.

        Indicator column 0: closest approach of two frequencies; column 1: smallest s (distance
        to divergence); both negative once unstable (damped: minus the largest growth rate).
        """
        return classify_eigenvalues(vals, self.undamped, TOL_UNSTABLE, TOL_CLUSTER, FLOOR, TOL_DUPLICATE)

    def unstable_at(self, p: float) -> bool:
        return bool(self.classify(np.array([p]))[0][0])

    # -- eigen-decomposition at one load ------------------------------------------------------
    def decompose(self, p: float):
        """Eigenvalues, eigenvectors and mass at one load (cached for the engine's lifetime)."""
        hit = self._cache.get(p)
        if hit is None:
            if self.ops is not None:
                op, m = self.ops[0] + p * self.ops[1], self.mass
            else:
                ops, ms = self.operators(np.array([p]))
                op, m = ops[0], ms[0]
            self.evaluations += 1
            if np.isfinite(op).all():
                vals, vecs = np.linalg.eig(op)
            else:  # no static equilibrium at this load
                vals = np.full(op.shape[0], np.nan + 0j)
                vecs = np.full(op.shape, np.nan + 0j)
            hit = self._cache[p] = (vals, vecs, m, op)
        return hit[:3]

    def unstable_cluster(self, vals: Array) -> tuple[Array, bool, bool]:
        """Indices of the cluster that is unstable, whether it is unique, and if divergent."""
        cplx, neg = self.unstable_parts(vals)
        bad = np.flatnonzero(cplx | neg)
        if self.undamped:
            if cplx.any():
                j0 = np.flatnonzero(cplx)[np.argmin(vals.real[cplx])]
                divergence = False
            else:
                j0 = bad[np.argmin(vals.real[bad])]
                divergence = True
        else:
            j0 = bad[np.argmax(_relative_real(vals[bad]))]
            divergence = bool(neg[j0])
        ref = vals[j0]
        tol = max(TOL_CLUSTER * abs(ref), FLOOR * np.abs(vals).max())
        close = (np.abs(vals - ref) <= tol) | (np.abs(vals - np.conj(ref)) <= tol)
        if not self.undamped and not divergence:
            # the decaying partner of a merged pair has the same frequency: keep it in the
            # cluster (before the merge the two modes span both branches)
            close |= np.abs(np.abs(vals.imag) - abs(ref.imag)) <= tol
        members = np.flatnonzero(close)
        unique = set(bad.tolist()) <= set(members.tolist())
        return members, unique, divergence

    @staticmethod
    def projector(vecs: Array, members: Array) -> tuple[Array, Array]:
        """Spectral projector onto the cluster's invariant subspace, as ``(V_C, W_C^H)``.

        The projector is oblique (``V_C W_C^H`` with left eigenvectors ``W^H = V^-1``): for a
        non-normal problem the right eigenvectors of other clusters are not orthogonal to it.
        """
        try:
            inv = np.linalg.inv(vecs)
        except np.linalg.LinAlgError:  # an exactly defective point: use the pseudo-inverse
            inv = np.linalg.pinv(vecs)
        return vecs[:, members], inv[members, :]

    @staticmethod
    def select(vecs: Array, proj: tuple[Array, Array], k: int) -> tuple[Array, bool]:
        """The ``k`` eigenvectors lying most in the cluster subspace, and whether that is clear.

        ``vecs`` are unit columns (as LAPACK returns them); the share of each is the norm of its
        oblique projection onto the cluster subspace.
        """
        v_c, w_c = proj
        y = v_c @ (w_c @ vecs)
        share = (y.real**2 + y.imag**2).sum(axis=0)
        order = np.argsort(-share)
        ok = share[order[k - 1]] > 0.25 and (len(order) == k or share[order[k]] < 0.25)
        return order[:k], bool(ok)

    # -- refinement of one bracket -----------------------------------------------------------
    def refine(self, a: float, b: float) -> tuple[float, str, float, Array, Array]:
        """Root of the exact indicator between stable ``a`` and unstable ``b``.

        The classification thresholds only bracket: if the exact indicator shows that ``a`` is
        already past the onset (a point inside the threshold window), ``a`` steps back, away
        from ``b``, until it is truly stable.
        """
        lo_lim, hi_lim = self.p_range
        for _ in range(200):
            vals_b, vecs_b, _ = self.decompose(b)
            if not np.all(np.isfinite(vals_b)):
                # no static equilibrium at b: close in on the limit point
                mid = 0.5 * (a + b)
                if mid in (a, b):
                    return self._limit_point(a, b)
                if self.unstable_at(mid):
                    b = mid
                else:
                    a = mid
                continue
            members, unique, divergence = self.unstable_cluster(vals_b)
            basis = self.projector(vecs_b, members)
            k = len(members)
            vals_a, vecs_a, _ = self.decompose(a)
            _, ok_a = self.select(vecs_a, basis, k)
            if unique and ok_a:
                try:
                    return self._solve(a, b, basis, k, divergence)
                except _NoSignChange:
                    step = a - b
                    new_a = min(max(a + step, lo_lim), hi_lim)
                    if new_a == a:
                        break
                    a = new_a
                    continue
                except _Ambiguous:
                    pass
            mid = 0.5 * (a + b)
            if mid in (a, b):
                break
            if self.unstable_at(mid):
                b = mid
            else:
                a = mid
        # the exact indicator could not be used: the bracket was narrowed on the stability
        # classification only, which resolves the onset to its tolerance, not to rounding
        self.warnings.append(
            f"onset near {b:.10g} located by bisection on the stability tolerance "
            f"(growth above {TOL_UNSTABLE:g} of |lambda|), not by the exact indicator: expect a "
            "relative accuracy near that tolerance (very light damping?)"
        )
        vals, vecs, m = self.decompose(b)
        members, _, divergence = self.unstable_cluster(vals)
        return self._finish(b, vals, vecs, m, members, divergence)

    def _limit_point(self, a: float, b: float):
        """The static equilibrium path folds between ``a`` (reached) and ``b`` (not reached).

        At a fold the smallest stiffness eigenvalue vanishes like ``sqrt(T_f - T)``, so its
        square is linear in T there: secant steps on ``s_min^2`` from the reached side locate
        ``T_f`` (a static loss of stability, reported as divergence).
        """

        def s2(p: float) -> float:
            m, _, _, k = self.family.matrices(np.array([p]))
            if not np.isfinite(k).all():
                return np.nan
            s = np.linalg.eigvals(np.linalg.solve(m[0], k[0]))
            return float(np.min(np.abs(s)) ** 2)

        x0, x1 = a - 0.5 * (b - a), a
        f0, f1 = s2(x0), s2(x1)
        for _ in range(40):
            if not (np.isfinite(f0) and np.isfinite(f1)) or f1 == f0:
                break
            x2 = x1 - f1 * (x1 - x0) / (f1 - f0)
            if not x1 < x2 < b:
                break
            f2 = s2(x2)
            if not np.isfinite(f2):  # past the fold: pull back
                b = x2
                x2 = 0.5 * (x1 + x2)
                f2 = s2(x2)
                if not np.isfinite(f2):
                    break
            x0, f0, x1, f1 = x1, f1, x2, f2
            if abs(x1 - x0) <= 1e-12 * abs(x1):
                break
        vals, vecs, m = self.decompose(x1)
        if not np.isfinite(vals).all():
            x1 = b  # the path could not be followed close to the fold: report where it ended
            return float(x1), "divergence", 0.0, np.zeros(self.n, complex), np.full(self.n, np.nan)
        j = int(np.argmin(np.abs(vals)))
        mode = vecs[: self.n, j]
        mode = mode * np.conj(mode[np.argmax(np.abs(mode))])
        mode = mode / max(np.abs(mode).max(), 1e-300)
        return float(x1), "divergence", 0.0, mode, kinetic_shares(vecs[: self.n, [j]], m)

    def _indicator(self, basis: Array, k: int, divergence: bool, target: float):
        """The exact indicator and, for affine families, its derivative (THEORY 5).

        For the cluster ``C`` with eigenvalues ``v_j`` and eigenvalue derivatives
        ``b_j = (W_C A1 V_C)_jj``: ``Delta = k sum v^2 - (sum v)^2`` with
        ``Delta' = 2 k sum v_j b_j - 2 (sum v)(sum b_j)`` (symmetric functions of the cluster,
        smooth through the defective double root); ``mean(v)`` for divergence; ``max Re v`` for
        a Hopf crossing.
        """

        def fun(p: float, derivative: bool = False):
            vals, vecs, _ = self.decompose(p)
            sel, ok = self.select(vecs, basis, k)
            if not ok:
                raise _Ambiguous
            v = vals[sel]
            if self.undamped:
                f = v.real.mean() if divergence else (k * (v * v).sum() - v.sum() ** 2).real
            else:
                j = int(np.argmax(_relative_real(v)))
                f = _pair_growth(v) - target * abs(v[j])
            if not derivative:
                return float(f)
            try:
                w = np.linalg.inv(vecs)[sel, :]
            except np.linalg.LinAlgError:  # eigenvectors exactly dependent: no derivative here
                raise _Ambiguous from None
            b = np.einsum("ij,jk,ki->i", w, self.ops[1], vecs[:, sel])
            if self.undamped:
                df = b.real.mean() if divergence else (2 * k * (v * b).sum() - 2 * v.sum() * b.sum()).real
            else:
                df = b.real[j]
            return float(f), float(df)

        return fun

    def _marginal(self, a: float, b: float, basis, k: int) -> bool:
        """Whether the crossing branch lay on the imaginary axis before ``a`` (two points)."""
        lo_lim, hi_lim = self.p_range
        for p in (a, min(max(a + (a - b), lo_lim), hi_lim)):
            vals, vecs, _ = self.decompose(p)
            sel, ok = self.select(vecs, basis, k)
            if not ok:
                return False
            v = vals[sel]
            if np.max(np.abs(_relative_real(v))) > TOL_MARGINAL:
                return False
        return True

    def _root(self, fun, a: float, b: float, fa: float, fb: float) -> float:
        """Bracketed Newton iteration (secant start, bisection guard) to machine precision."""
        lo, hi, flo = a, b, fa
        p = a - fa * (b - a) / (fb - fa)
        for _ in range(100):
            f, df = fun(p, True)
            if f == 0.0:
                return p
            if np.sign(f) == np.sign(flo):
                lo, flo = p, f
            else:
                hi = p
            new = p - f / df if df != 0.0 else np.inf
            if not (min(lo, hi) < new < max(lo, hi)):
                new = 0.5 * (lo + hi)
            if abs(new - p) <= 4 * np.finfo(float).eps * abs(p) or new in (lo, hi):
                return new
            p = new
        raise _Ambiguous

    def _solve(self, a: float, b: float, basis: Array, k: int, divergence: bool):
        target = 0.0
        if not self.undamped and self._marginal(a, b, basis, k):
            # the branch was on the imaginary axis (to rounding) before it left it: it leaves
            # like sqrt(p - p_c), and the onset is where it is off the axis by TOL_UNSTABLE
            target = TOL_UNSTABLE
        fun = self._indicator(basis, k, divergence, target)
        fa, fb = fun(a), fun(b)
        if fa == 0.0:
            root = a
        elif np.sign(fa) == np.sign(fb):
            raise _NoSignChange
        elif self.ops is not None and target == 0.0 and (self.undamped or k <= 2):
            root = self._root(fun, a, b, fa, fb)
        else:
            root = optimize.brentq(fun, a, b, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=200)
        vals, vecs, m = self.decompose(root)
        sel, _ = self.select(vecs, basis, k)
        return self._finish(root, vals, vecs, m, sel, divergence, basis, a)

    def _finish(self, p, vals, vecs, m, members, divergence, proj=None, before=None):
        """Onset values at ``p``; participation from the distinct modes at ``before`` (stable side)."""
        n = self.n
        v = vals[members]
        if self.undamped:
            omega = 0.0 if divergence else float(np.sqrt(max(v.real.mean(), 0.0)))
            lead = members[np.argmax(np.abs(v.imag))] if not divergence else members[0]
            mode = vecs[:, lead]
        else:
            j = members[np.argmax(v.real)]
            omega = 0.0 if divergence else float(abs(vals[j].imag))
            mode = vecs[:n, j]
        shapes, values = vecs[:n, members], vals[members]
        if proj is not None and before is not None:
            vals_b, vecs_b, _ = self.decompose(before)
            sel, ok = self.select(vecs_b, proj, len(members))
            if ok:
                shapes, values = vecs_b[:n, sel], vals_b[sel]
        # each distinct mode of the cluster weighs equally in the participation
        part = cluster_participation(shapes, values, np.ones(len(values), dtype=bool), np.diag(m), TOL_DUPLICATE)
        kind = "divergence" if divergence else "flutter"
        big = np.argmax(np.abs(mode))
        mode = mode * np.conj(mode[big]) / np.abs(mode[big]) ** 2
        return float(p), kind, omega, mode, part

    # -- scan ---------------------------------------------------------------------------------
    def attracting(self, lo: float, mid: float, hi: float) -> bool:
        """Whether the closest pair of real ``s`` at ``mid`` can merge (undamped only).

        Two nearby eigenvalues interact, to first order in the load, through the off-diagonal
        entries ``B_lu``, ``B_ul`` of ``dA/dp`` in the biorthogonal eigenbasis (``A = M^-1 K``).
        A product ``B_lu B_ul < 0`` pulls them together (they may merge: a possible bubble);
        ``> 0`` makes them veer apart; zero (to rounding) means they do not interact, as for modes
        decoupled by symmetry, which simply cross.
        """
        if not self.undamped:
            return True
        a, _ = self.operators(np.array([lo, mid, hi]))
        self.evaluations += 3
        vals, vecs = np.linalg.eig(a[1])
        if np.abs(vals.imag).max() > TOL_UNSTABLE * np.abs(vals).max():
            return True
        order = np.argsort(vals.real)
        re = vals.real[order]
        scale = np.abs(re).max()
        diffs = np.diff(re)
        distinct = np.flatnonzero(diffs >= TOL_DUPLICATE * scale)
        if distinct.size == 0:
            return False
        j = distinct[np.argmin(diffs[distinct])]
        lower = order[np.abs(re - re[j]) < TOL_DUPLICATE * scale]
        upper = order[np.abs(re - re[j + 1]) < TOL_DUPLICATE * scale]
        rate = (a[2] - a[0]) / (hi - lo)
        b = np.linalg.solve(vecs, rate @ vecs)
        prod = b[np.ix_(lower, upper)] @ b[np.ix_(upper, lower)]
        inter = prod.ravel() if prod.size == 1 else np.linalg.eigvals(prod)
        norm = max(np.abs(rate).max(), 1e-300)
        return bool(np.any(inter.real < -1e-8 * norm**2))

    def bubble(self, lo: float, hi: float, column: int = 0) -> float | None:
        """Closest approach in ``(lo, hi)``; the load of an instability found there, else None.

        ``column`` 0 minimises the closest gap between frequencies (a flutter bubble), 1 the
        smallest ``s`` (a divergence interval).
        """

        def fun(p: float) -> float:
            unstable, ind = self.classify(np.array([p]))
            if unstable[0]:
                raise _Unstable(p)
            return float(ind[0, column])

        try:
            optimize.minimize_scalar(
                fun, bounds=(lo, hi), method="bounded", options={"xatol": (hi - lo) * 1e-9}
            )
        except _Unstable as hit:
            return hit.p
        return None

    def scan(self, p_min: float, p_max: float, n_scan: int, chunk: int, all_crossings: bool):
        grid = np.linspace(p_min, p_max, n_scan + 1)
        flags = np.zeros(0, dtype=bool)
        ind = np.zeros((0, 2))
        brackets: list[tuple[float, float]] = []
        checked = 0  # grid index up to which bubbles were examined
        start = 0
        while start < len(grid):
            stop = min(start + chunk, len(grid))
            f, i = self.classify(grid[start:stop])
            if start == 0 and f[0]:
                return grid, f, brackets  # unstable already at p_min
            flags = np.concatenate([flags, f])
            ind = np.concatenate([ind, i])
            # examine transitions and bubbles up to the last point with both neighbours known
            limit = len(flags) - 1 if stop < len(grid) else len(flags)
            lo_j = max(checked, 1)
            if limit > lo_j:
                js = np.arange(lo_j, limit)
                change = flags[js] != flags[js - 1]
                nxt = np.minimum(js + 1, len(flags) - 1)
                inner = ~flags[js] & (js + 1 < len(flags)) & ~flags[nxt]
                dips = [
                    inner & (ind[js, c] < ind[js - 1, c]) & (ind[js, c] <= ind[nxt, c]) for c in (0, 1)
                ]
                for j in js[change | dips[0] | dips[1]]:
                    if flags[j] != flags[j - 1]:
                        lo, hi = grid[j - 1], grid[j]
                        brackets.append((lo, hi) if not flags[j - 1] else (hi, lo))
                    else:
                        hit = None
                        if dips[1][j - lo_j] and self.undamped:
                            hit = self.bubble(grid[j - 1], grid[j + 1], column=1)
                        if hit is None and dips[0][j - lo_j] and self.attracting(grid[j - 1], grid[j], grid[j + 1]):
                            hit = self.bubble(grid[j - 1], grid[j + 1], column=0)
                        if hit is not None:
                            # stable at grid[j-1]; unstable at hit; stable again by grid[j+1]
                            brackets.append((grid[j - 1], hit))
                            if all_crossings:
                                brackets.append((grid[j + 1], hit))
                    if brackets and not all_crossings:
                        return grid, flags, brackets
            checked = limit
            start = stop
        return grid, flags, brackets


class _Ambiguous(Exception):
    pass


class _NoSignChange(Exception):
    pass


def critical_load_family(
    family: SystemFamily,
    p_max: float,
    *,
    p_min: float = 0.0,
    n_scan: int = 64,
    chunk: int = 65,
    all_crossings: bool = False,
    undamped: bool | None = None,
) -> CriticalLoad:
    """Critical load of a family ``p -> (M, D, G, K)`` (see :func:`critical_load`)."""
    if not (np.isfinite(p_max) and p_max > p_min):
        raise ValueError(f"p_max = {p_max!r}: must be finite and above p_min = {p_min!r}")
    eng = _Engine(family, p_max, undamped=undamped)
    eng.p_range = (float(p_min), float(p_max))
    method = "coalescence" if eng.undamped else "hopf"
    grid, flags, brackets = eng.scan(p_min, p_max, n_scan, chunk, all_crossings)
    if flags[0]:
        vals, vecs, m = eng.decompose(p_min)
        members, _, divergence = eng.unstable_cluster(vals)
        p, kind, omega, mode, part = eng._finish(p_min, vals, vecs, m, members, divergence)
        return CriticalLoad(p, kind, omega, p_max, method, mode, part, (), eng.evaluations)
    crossings = []
    first = None
    for a, b in brackets:
        p, kind, omega, mode, part = eng.refine(a, b)
        direction = "loss" if a < b else "gain"
        crossings.append(Crossing(p, direction, kind, omega))
        if direction == "loss" and (first is None or p < first[0]):
            first = (p, kind, omega, mode, part)
    crossings.sort(key=lambda c: c.load)
    if first is None:
        return CriticalLoad(
            None, "none", None, p_max, method, None, None, tuple(crossings), eng.evaluations, tuple(eng.warnings)
        )
    p, kind, omega, mode, part = first
    return CriticalLoad(
        p, kind, omega, p_max, method, mode, part,
        tuple(crossings) if all_crossings else (), eng.evaluations, tuple(eng.warnings),
    )


def critical_load(
    M,
    K0=None,
    K1=None,
    D=None,
    G=None,
    p_max: float = 1.0,
    *,
    n_scan: int = 64,
    all_crossings: bool = False,
) -> CriticalLoad:
    """Critical load of ``M q'' + (D + G) q' + (K0 + p K1) q = 0``, or of a callable system.

    Parameters
    ----------
    M, K0, K1 : (n, n) array_like
        Mass, stiffness at p = 0, and stiffness per unit load (non-symmetric for follower loads).
        Alternatively ``M`` may be a callable ``p -> (M, D, G, K)`` (D or G may be None) for a
        system that is not affine in the load; then K0 and K1 are not given.
    D, G : (n, n) array_like, optional
        Damping (symmetric) and gyroscopic (skew) matrices.
    p_max : float
        Upper end of the search.
    n_scan : int
        Number of scan intervals on ``[0, p_max]``.
    all_crossings : bool
        Also list every later loss and gain of stability up to ``p_max``.

    Returns
    -------
    CriticalLoad
        ``.load`` is the first critical value from p = 0 (None if stable up to ``p_max``).

    Examples
    --------
    Ziegler's pendulum (m = l = c = 1): flutter at ``7/2 - sqrt(2)``.

    >>> import numpy as np
    >>> r = critical_load([[3, 1], [1, 1]], [[2, -1], [-1, 1]], [[-1, 1], [0, 0]], p_max=5)
    >>> round(r.load, 10), r.kind
    (2.0857864376, 'flutter')
    """
    if callable(M):
        if K0 is not None or K1 is not None:
            raise ValueError("give either a callable system or the matrices M, K0, K1, not both")
        first = M(0.0)
        n = np.asarray(first[0]).shape[0]
        fam = CallableFamily(M, n)
    else:
        if K0 is None or K1 is None:
            raise ValueError("K0 and K1 are required with a mass matrix")
        fam = LinearFamily.build(M, K0, K1, D, G)
    return critical_load_family(fam, p_max, n_scan=n_scan, all_crossings=all_crossings)
