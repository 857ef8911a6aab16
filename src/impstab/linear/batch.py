"""Critical thrust of many models at once (design studies).

The steps of the engine in :mod:`impstab.linear.critical` are run for all designs together:

1. the thrust scan: the grid operators of all designs (``M^-1 K`` or the state matrix,
   THEORY 5) are classified in a few stacked LAPACK calls, with the engine's own classification
   (same tolerances, same bubble indicators), chunk by chunk, each design stopping where its
   scan would;
2. the bracket logic of the scan, vectorized across designs; the bubble searches (scipy's
   bounded Brent minimisation, which the engine uses, ported step for step) run in lockstep so
   that each step is one stacked classification; the ``attracting`` test is vectorized for
   affine undamped designs;
3. the exact refinement, vectorized for affine undamped designs (the common case: symmetric
   layouts, or the classical linearization): the root of the cluster discriminant by bracketed
   Newton steps to machine precision. Any design that leaves this path (an ambiguous cluster, no
   sign change of the indicator, unstable at zero thrust), and every damped, gyroscopic or
   rotating-equilibrium design, is refined by its own engine, exactly as in
   :func:`impstab.critical_thrust`.

The values agree with :func:`impstab.critical_thrust` to rounding. A design with compressible
fluid loading goes through :func:`impstab.critical_thrust` itself. Failures are per design: a
model whose analysis raises gets a status and a message.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numpy.typing import NDArray

from ..model.model import Model
from .critical import FLOOR, TOL_CLUSTER, TOL_DUPLICATE, TOL_UNSTABLE, _Engine
from .critical_thrust import _modes
from .linearize import ModelFamily

__all__ = ["BatchCriticalThrust", "critical_thrust_batch", "KINDS", "STATUSES"]

Array = NDArray[np.float64]

#: kind codes: index in this tuple (-1: not available)
KINDS = ("none", "flutter", "divergence")
#: status codes: index in this tuple (-1: not computed)
STATUSES = ("ok", "invalid", "numerical_failure", "error")
_EPS4 = 4 * np.finfo(float).eps


@dataclass(frozen=True, eq=False)
class BatchCriticalThrust:
    """Critical thrusts of a batch of designs, one entry per design.

    Attributes
    ----------
    thrust, omega : (N,) float arrays
        Critical thrust (N) and angular frequency at onset (rad/s); NaN when the design has none
        up to its ``thrust_max`` or failed.
    kind, undamped_kind : (N,) int8 arrays
        Codes into :data:`KINDS`; -1 for a failed design.
    undamped_thrust : (N,) float array
        Critical thrust with every damper removed (N).
    thrust_max, operating : (N,) float arrays
        Search range end and operating thrust (N; NaN without one).
    modes : list of str
        Dofs with at least 5 % of the kinetic energy of the critical mode, comma-separated.
    status : (N,) int8 array
        Codes into :data:`STATUSES`.
    message : list of str
        Empty when ``status`` is 0, else a one-line reason.
    evaluations : int
        Eigenproblems solved in total.
    """

    thrust: Array
    kind: NDArray[np.int8]
    omega: Array
    undamped_thrust: Array
    undamped_kind: NDArray[np.int8]
    thrust_max: Array
    operating: Array
    modes: list[str]
    status: NDArray[np.int8]
    message: list[str]
    evaluations: int = 0

    @property
    def frequency_hz(self) -> Array:
        """Onset frequency ``omega / 2 pi`` (Hz)."""
        return self.omega / (2.0 * np.pi)

    @property
    def margin(self) -> Array:
        """``critical / operating`` (NaN without either)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.thrust / self.operating


class _PrimedEngine(_Engine):
    """An engine whose scan chunks were classified beforehand, in a batch with other designs."""

    def __init__(self, family: ModelFamily, p_max: float, primed: dict) -> None:
        super().__init__(family, p_max)
        self.primed = primed

    def classify(self, p: Array):
        hit = self.primed.get((float(p[0]), len(p))) if len(p) else None
        if hit is not None:  # counted by the job that classified it
            return hit
        return super().classify(p)


class _Stack(_Engine):
    """The engine's classification applied to a ready stack of operators (no engine set-up)."""

    def __init__(self, ops: Array | None, undamped: bool) -> None:  # noqa: D107
        self._ops = ops
        self.undamped = undamped
        self.evaluations = 0

    def operators(self, p: Array):
        return self._ops, None


class _Job:
    """One critical-load search: a design, or the undamped companion of a damped design."""

    def __init__(self, family: ModelFamily, p_max: float, n_scan: int) -> None:
        self.family, self.p_max = family, p_max
        self.grid = np.linspace(0.0, p_max, n_scan + 1)
        self.primed: dict = {}
        self.flags: list = []
        self.ind: list = []
        self.evaluations = 0
        self._engine: _PrimedEngine | None = None
        parts = family.affine_parts()
        self.fast = parts is not None and not (np.any(parts[1] != 0) or np.any(parts[2] != 0))
        if self.fast:  # M^-1 K0 and M^-1 K1 are formed for all jobs at once (_operators)
            self.mass, self.k0, self.k1 = np.array(parts[0]), parts[3], parts[4]
        self.undamped = True if self.fast else self.engine().undamped

    def engine(self) -> _PrimedEngine:
        if self._engine is None:
            self._engine = _PrimedEngine(self.family, self.p_max, self.primed)
        return self._engine

    def point_op(self, x: float) -> Array:
        """The eigen-operator at one load, as the engine forms it."""
        if self.fast:
            return self.a0[None] + np.array([x])[:, None, None] * self.a1[None]
        return self.engine().operators(np.array([x]))[0]


# -- batched scan -----------------------------------------------------------------------------
def _operators(jobs: list[_Job]) -> None:
    """``a0 = M^-1 K0`` and ``a1 = M^-1 K1`` of the affine undamped jobs, as the engine forms them."""
    fast = [j for j in jobs if j.fast]
    if not fast:
        return
    m = np.stack([j.mass for j in fast])
    a = np.linalg.solve(np.concatenate([m, m]), np.concatenate([np.stack([j.k0 for j in fast]), np.stack([j.k1 for j in fast])]))
    for i, j in enumerate(fast):
        j.a0, j.a1 = a[i], a[len(fast) + i]


def _classify_group(jobs: list[_Job], start: int, stop: int) -> list:
    if jobs[0].fast:
        a0 = np.stack([j.a0 for j in jobs])
        a1 = np.stack([j.a1 for j in jobs])
        p = np.stack([j.grid[start:stop] for j in jobs])
        ops = a0[:, None] + p[:, :, None, None] * a1[:, None]
    else:
        ops = np.stack([j.engine().operators(j.grid[start:stop])[0] for j in jobs])
    flat = ops.reshape((-1,) + ops.shape[2:])
    try:
        flags, ind = _Stack(flat, jobs[0].undamped).classify(np.zeros(len(flat)))
    except np.linalg.LinAlgError:
        out = []
        for j in jobs:
            try:
                out.append(_Stack(j.engine().operators(j.grid[start:stop])[0], j.undamped).classify(j.grid[start:stop]))
            except Exception as exc:  # noqa: BLE001 - reported per design
                out.append(exc)
        return out
    n = stop - start
    return [(flags[i * n:(i + 1) * n], ind[i * n:(i + 1) * n]) for i in range(len(jobs))]


def _prime(jobs: list[_Job], chunk: int, errors: dict) -> None:
    """Classify each job's scan grid chunk by chunk, batched; a job stops where its scan would."""
    n_pts = len(jobs[0].grid) if jobs else 0
    first = {id(j): n_pts for j in jobs}
    active, start = list(jobs), 0
    while active and start < n_pts:
        stop = min(start + chunk, n_pts)
        for key in {(j.fast, j.undamped) for j in active}:
            group = [j for j in active if (j.fast, j.undamped) == key]
            for j, r in zip(group, _classify_group(group, start, stop)):
                if isinstance(r, Exception):
                    errors[id(j)] = r
                    continue
                j.primed[(float(j.grid[start]), stop - start)] = r
                j.flags.append(r[0])
                j.ind.append(r[1])
                j.evaluations += stop - start
                bad = np.flatnonzero(r[0])
                if bad.size and first[id(j)] == n_pts:
                    first[id(j)] = start + int(bad[0])
        active = [j for j in active if id(j) not in errors and first[id(j)] >= stop - 1]
        start = stop


# -- vectorized engine steps -----------------------------------------------------------------
def _brackets(jobs: list[_Job], errors: dict) -> list:
    """First bracket of each job's scan as the engine's ``scan`` finds it (None: no crossing).

    The bubble searches of all jobs run in lockstep; the ``attracting`` test is vectorized for
    affine undamped jobs and the engine's own for the others (always true when damped).
    """
    n_pts = len(jobs[0].grid)
    flags = np.zeros((len(jobs), n_pts), dtype=bool)
    ind = np.full((len(jobs), n_pts, 2), np.nan)
    length = np.array([sum(len(f) for f in j.flags) for j in jobs])
    for r, j in enumerate(jobs):
        flags[r, : length[r]] = np.concatenate(j.flags)
        ind[r, : length[r]] = np.concatenate(j.ind)
    js = np.arange(n_pts)[None, :]
    upper = np.where(length < n_pts, length - 1, n_pts)[:, None]
    valid = (js >= 1) & (js < upper)
    prev = np.roll(flags, 1, axis=1)
    nxt_i = np.minimum(js + 1, length[:, None] - 1)
    nxt_f = np.take_along_axis(flags, nxt_i, axis=1)
    inner = ~flags & (js + 1 < length[:, None]) & ~nxt_f
    prev_ind, nxt_ind = np.roll(ind, 1, axis=1), np.take_along_axis(ind, nxt_i[..., None].repeat(2, -1), axis=1)
    with np.errstate(invalid="ignore"):
        dips = inner[..., None] & (ind < prev_ind) & (ind <= nxt_ind)
    change = flags != prev
    cand = valid & (change | dips[..., 0] | dips[..., 1])
    out: list = [None] * len(jobs)
    pos = {r: 0 for r in range(len(jobs))}
    while pos:
        dip: list[tuple[int, int]] = []
        for r in list(pos):
            hits = np.flatnonzero(cand[r, pos[r]:])
            if not hits.size:
                del pos[r]
                continue
            j = pos[r] + int(hits[0])
            pos[r] = j + 1
            if change[r, j]:
                out[r] = (jobs[r].grid[j - 1], jobs[r].grid[j])
                del pos[r]
            else:
                dip.append((r, j))
        # a dip of the smallest s first, then a close approach of two frequencies that attract
        first = _bubbles(jobs, [(r, j) for r, j in dip if dips[r, j, 1] and jobs[r].undamped], 1, errors)
        rest = [(r, j) for r, j in dip if first.get(r) is None and dips[r, j, 0] and id(jobs[r]) not in errors]
        attract = _attract_any(jobs, rest, errors)
        second = _bubbles(jobs, [rj for rj in rest if attract.get(rj[0])], 0, errors)
        for r, j in dip:
            if id(jobs[r]) in errors:
                del pos[r]
                continue
            hit = first.get(r) if first.get(r) is not None else second.get(r)
            if hit is not None:
                out[r] = (jobs[r].grid[j - 1], hit)
                del pos[r]
    return out


def _attract_any(jobs: list[_Job], where: list[tuple[int, int]], errors: dict) -> dict[int, bool]:
    """The engine's ``attracting`` test for each (job, grid index)."""
    out: dict[int, bool] = {}
    fast = [(r, j) for r, j in where if jobs[r].fast]
    if fast:
        out.update(zip([r for r, _ in fast], _attracting([jobs[r] for r, _ in fast], [j for _, j in fast])))
    for r, j in where:
        if jobs[r].fast:
            continue
        g = jobs[r].grid
        try:
            out[r] = jobs[r].engine().attracting(g[j - 1], g[j], g[j + 1])
        except Exception as exc:  # noqa: BLE001 - reported per design
            errors[id(jobs[r])] = exc
    return out


def _bubbles(jobs: list[_Job], where: list[tuple[int, int]], column: int, errors: dict) -> dict:
    """The engine's ``bubble(grid[j-1], grid[j+1], column)`` for many jobs, in lockstep.

    Each search is scipy's bounded Brent minimisation (the engine's), ported step for step to a
    generator, so that all searches share one batched classification per step.
    """
    found: dict[int, float | None] = {}
    runs = {}
    for r, j in where:
        lo, hi = jobs[r].grid[j - 1], jobs[r].grid[j + 1]
        gen = _bounded_minimum(lo, hi, (hi - lo) * 1e-9)
        runs[r] = (gen, next(gen))
        found[r] = None
    while runs:
        step: dict[bool, list] = {}
        for r in list(runs):
            try:
                step.setdefault(jobs[r].undamped, []).append((r, jobs[r].point_op(runs[r][1])))
            except Exception as exc:  # noqa: BLE001 - reported per design
                errors[id(jobs[r])] = exc
                del runs[r]
        for undamped, items in step.items():
            ops = np.concatenate([op for _, op in items])
            unstable, ind = _Stack(ops, undamped).classify(np.zeros(len(ops)))
            for k, (r, _) in enumerate(items):
                jobs[r].evaluations += 1
                gen, x = runs.pop(r)
                if unstable[k]:
                    found[r] = float(x)
                    continue
                try:
                    runs[r] = (gen, gen.send(float(ind[k, column])))
                except StopIteration:
                    pass
    return found


def _bounded_minimum(x1: float, x2: float, xatol: float, maxfun: int = 500):
    """scipy's ``_minimize_scalar_bounded`` as a generator: yields x, receives f(x)."""
    sqrt_eps = np.sqrt(2.2e-16)
    golden_mean = 0.5 * (3.0 - np.sqrt(5.0))
    a, b = x1, x2
    fulc = a + golden_mean * (b - a)
    nfc, xf = fulc, fulc
    rat = e = 0.0
    fx = yield xf
    num = 1
    ffulc = fnfc = fx
    xm = 0.5 * (a + b)
    tol1 = sqrt_eps * np.abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    while np.abs(xf - xm) > (tol2 - 0.5 * (b - a)):
        golden = 1
        if np.abs(e) > tol1:  # parabolic fit
            golden = 0
            r = (xf - nfc) * (fx - ffulc)
            q = (xf - fulc) * (fx - fnfc)
            p = (xf - fulc) * q - (xf - nfc) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = np.abs(q)
            r = e
            e = rat
            if (np.abs(p) < np.abs(0.5 * q * r)) and (p > q * (a - xf)) and (p < q * (b - xf)):
                rat = (p + 0.0) / q
                x = xf + rat
                if ((x - a) < tol2) or ((b - x) < tol2):
                    rat = tol1 * (np.sign(xm - xf) + ((xm - xf) == 0))
            else:
                golden = 1
        if golden:
            e = a - xf if xf >= xm else b - xf
            rat = golden_mean * e
        si = np.sign(rat) + (rat == 0)
        x = xf + si * np.maximum(np.abs(rat), tol1)
        fu = yield x
        num += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                b = xf
            fulc, ffulc = nfc, fnfc
            nfc, fnfc = xf, fx
            xf, fx = x, fu
        else:
            if x < xf:
                a = x
            else:
                b = x
            if (fu <= fnfc) or (nfc == xf):
                fulc, ffulc = nfc, fnfc
                nfc, fnfc = x, fu
            elif (fu <= ffulc) or (fulc == xf) or (fulc == nfc):
                fulc, ffulc = x, fu
        xm = 0.5 * (a + b)
        tol1 = sqrt_eps * np.abs(xf) + xatol / 3.0
        tol2 = 2.0 * tol1
        if num >= maxfun:
            return


def _attracting(jobs: list[_Job], js: list[int]) -> NDArray[np.bool_]:
    """The engine's ``attracting(grid[j-1], grid[j], grid[j+1])`` for many jobs at once."""
    lo = np.array([jb.grid[j - 1] for jb, j in zip(jobs, js)])
    mid = np.array([jb.grid[j] for jb, j in zip(jobs, js)])
    hi = np.array([jb.grid[j + 1] for jb, j in zip(jobs, js)])
    a0, a1 = np.stack([jb.a0 for jb in jobs]), np.stack([jb.a1 for jb in jobs])
    for jb in jobs:
        jb.evaluations += 3
    op = lambda p: a0 + p[:, None, None] * a1  # noqa: E731
    vals, vecs = np.linalg.eig(op(mid))
    vals, vecs = vals.astype(complex), vecs.astype(complex)
    result = np.abs(vals.imag).max(-1) > TOL_UNSTABLE * np.abs(vals).max(-1)
    order = np.argsort(vals.real, axis=-1)
    re = np.take_along_axis(vals.real, order, -1)
    scale = np.abs(re).max(-1, keepdims=True)
    diffs = np.diff(re, axis=-1)
    distinct = diffs >= TOL_DUPLICATE * scale
    j = np.argmin(np.where(distinct, diffs, np.inf), axis=-1)
    pick = lambda c: np.take_along_axis(re, c[:, None], -1)  # noqa: E731
    lower_s, upper_s = np.abs(re - pick(j)) < TOL_DUPLICATE * scale, np.abs(re - pick(j + 1)) < TOL_DUPLICATE * scale
    lower, upper = np.zeros_like(lower_s), np.zeros_like(upper_s)
    np.put_along_axis(lower, order, lower_s, -1)
    np.put_along_axis(upper, order, upper_s, -1)
    rate = (op(hi) - op(lo)) / (hi - lo)[:, None, None]
    b = np.linalg.solve(vecs, rate.astype(complex) @ vecs)
    blu = b * (lower[:, :, None] & upper[:, None, :])
    bul = b * (upper[:, :, None] & lower[:, None, :])
    inter = np.linalg.eigvals(blu @ bul)
    norm = np.maximum(np.abs(rate).max(axis=(-2, -1)), 1e-300)
    pulled = np.any(inter.real < -1e-8 * norm[:, None] ** 2, axis=-1)
    return np.where(result, True, distinct.any(-1) & pulled)


def _inv(m: Array) -> tuple[Array, NDArray[np.bool_]]:
    """Inverses of a stack, and which exist (a singular one is NaN, left to its engine)."""
    try:
        return np.linalg.inv(m), np.ones(len(m), dtype=bool)
    except np.linalg.LinAlgError:
        out, ok = np.full(m.shape, np.nan, dtype=m.dtype), np.ones(len(m), dtype=bool)
        for i, mi in enumerate(m):
            try:
                out[i] = np.linalg.inv(mi)
            except np.linalg.LinAlgError:
                ok[i] = False
        return out, ok


def _select(vecs: Array, proj: Array, k: NDArray) -> tuple[NDArray, NDArray]:
    """The engine's ``select``: mask of the ``k`` vectors most in the cluster, and whether clear."""
    y = proj @ vecs
    share = (y.real**2 + y.imag**2).sum(axis=-2)
    srt = -np.sort(-share, axis=-1)
    rank = np.argsort(np.argsort(-share, axis=-1, kind="stable"), axis=-1, kind="stable")
    kth = np.take_along_axis(srt, (k - 1)[:, None], -1)[:, 0]
    nxt = np.take_along_axis(srt, np.minimum(k, srt.shape[-1] - 1)[:, None], -1)[:, 0]
    ok = (kth > 0.25) & ((k == srt.shape[-1]) | (nxt < 0.25))
    return rank < k[:, None], ok


def _refine(jobs: list[_Job], brackets: list[tuple[float, float]]) -> list:
    """The engine's ``refine`` on each bracket, vectorized; None where a job must use its engine."""
    n = len(jobs)
    a = np.array([br[0] for br in brackets])
    b = np.array([br[1] for br in brackets])
    a0, a1 = np.stack([j.a0 for j in jobs]), np.stack([j.a1 for j in jobs])
    op = lambda p: a0 + p[:, None, None] * a1  # noqa: E731

    def eig(p, rows):
        ops = op(p) if rows is None else a0[rows] + p[:, None, None] * a1[rows]
        vals, vecs = np.linalg.eig(ops)
        return vals.astype(complex), vecs.astype(complex)

    evals = np.full(n, 2)
    vals_b, vecs_b = eig(b, None)
    cplx, neg = _Stack(None, True).unstable_parts(vals_b)
    bad = cplx | neg
    has_c = cplx.any(-1)
    key = np.where(np.where(has_c[:, None], cplx, bad), vals_b.real, np.inf)
    ref = np.take_along_axis(vals_b, np.argmin(key, -1)[:, None], -1)
    tol = np.maximum(TOL_CLUSTER * np.abs(ref), FLOOR * np.abs(vals_b).max(-1, keepdims=True))
    members = (np.abs(vals_b - ref) <= tol) | (np.abs(vals_b - np.conj(ref)) <= tol)
    divergence = ~has_c
    k = members.sum(-1)
    inv_b, good = _inv(vecs_b)
    proj = (vecs_b * members[:, None, :]) @ inv_b
    vals_a, vecs_a = eig(a, None)
    _, ok_a = _select(vecs_a, proj, k)
    good &= bad.any(-1) & ~(bad & ~members).any(-1) & ok_a

    def indicator(vals, vecs, rows, derivative):
        sel, ok = _select(vecs, proj[rows], k[rows])
        kk, dv = k[rows], divergence[rows]
        v = np.where(sel, vals, 0)
        s1, s2 = v.sum(-1), (v * v).sum(-1)
        f = np.where(dv, s1.real / kk, (kk * s2 - s1**2).real)
        if not derivative:
            return f, ok
        inv, fine = _inv(vecs)
        bd = np.einsum("dij,djk,dki->di", inv, a1[rows], vecs)
        bd = np.where(sel, bd, 0)
        df = np.where(dv, bd.real.sum(-1) / kk, (2 * kk * (v * bd).sum(-1) - 2 * s1 * bd.sum(-1)).real)
        return f, df, ok & fine

    fa, oka = indicator(vals_a, vecs_a, slice(None), False)
    fb, okb = indicator(vals_b, vecs_b, slice(None), False)
    good &= oka & okb & ((fa == 0) | (np.sign(fa) != np.sign(fb)))
    root = np.where(fa == 0, a, np.nan)
    live = np.flatnonzero(good & (fa != 0))
    lo, hi, flo = a.copy(), b.copy(), fa.copy()
    with np.errstate(divide="ignore", invalid="ignore"):
        p = a - fa * (b - a) / (fb - fa)
    for _ in range(100):
        if not live.size:
            break
        vals, vecs = eig(p[live], live)
        evals[live] += 1
        f, df, ok = indicator(vals, vecs, live, True)
        good[live[~ok]] = False
        done = ok & (f == 0)
        root[live[done]] = p[live[done]]
        same = np.sign(f) == np.sign(flo[live])
        lo[live] = np.where(same, p[live], lo[live])
        flo[live] = np.where(same, f, flo[live])
        hi[live] = np.where(same, hi[live], p[live])
        with np.errstate(divide="ignore", invalid="ignore"):
            new = np.where(df != 0, p[live] - f / df, np.inf)
        inside = (np.minimum(lo[live], hi[live]) < new) & (new < np.maximum(lo[live], hi[live]))
        new = np.where(inside, new, 0.5 * (lo[live] + hi[live]))
        conv = ok & ~done & ((np.abs(new - p[live]) <= _EPS4 * np.abs(p[live])) | (new == lo[live]) | (new == hi[live]))
        root[live[conv]] = new[conv]
        p[live] = new
        live = live[ok & ~done & ~conv]
    good &= np.isfinite(root)
    rows = np.flatnonzero(good)
    out: list = [None] * n
    for j, e in zip(jobs, evals + good):
        j.evaluations += int(e)
    if not rows.size:
        return out
    vals, vecs = eig(root[rows], rows)
    sel, _ = _select(vecs, proj[rows], k[rows])
    sel_a, ok_sa = _select(vecs_a[rows], proj[rows], k[rows])
    shapes, cols = np.where(ok_sa[:, None, None], vecs_a[rows], vecs), np.where(ok_sa[:, None], sel_a, sel)
    w = (np.abs(shapes) ** 2) * np.stack([np.diag(jobs[r].mass) for r in rows])[:, :, None]
    w = w / np.where(w.sum(-2, keepdims=True) > 0, w.sum(-2, keepdims=True), 1.0)
    part = (w * cols[:, None, :]).sum(-1) / k[rows][:, None]
    mean = np.where(sel, vals.real, 0).sum(-1) / k[rows]
    for i, r in enumerate(rows):
        div = bool(divergence[r])
        omega = 0.0 if div else float(np.sqrt(max(mean[i], 0.0)))
        out[r] = (float(root[r]), "divergence" if div else "flutter", omega, part[i])
    return out


# -- per-design engine path and the driver ----------------------------------------------------
def _engine_first_loss(job: _Job, chunk: int, bracket=False):
    """``(load, kind, omega, participation, warnings)`` as ``critical_load_family`` finds it.

    ``bracket`` False: scan (primed) and refine; a tuple: refine that bracket only.
    """
    eng = job.engine()
    if bracket is False:
        _, flags, brackets = eng.scan(0.0, job.p_max, len(job.grid) - 1, chunk, False)
        if flags[0]:
            vals, vecs, m = eng.decompose(0.0)
            members, _, divergence = eng.unstable_cluster(vals)
            p, kind, omega, _, part = eng._finish(0.0, vals, vecs, m, members, divergence)
            return p, kind, omega, part, ()
    else:
        brackets = [bracket]
    first = (None, "none", None, None)
    for a, b in brackets:
        p, kind, omega, _, part = eng.refine(a, b)
        if a < b and (first[0] is None or p < first[0]):
            first = (p, kind, omega, part)
    return (*first, tuple(getattr(eng, "warnings", ())))


def _solve_jobs(jobs: list[_Job], chunk: int, vectorized: bool, errors: dict) -> dict:
    """First loss of stability of every job that has not failed."""
    results: dict[int, tuple] = {}
    live = [j for j in jobs if id(j) not in errors]
    engine_only: list = [j for j in live if not vectorized or j.flags[0][0]]
    scanned = [j for j in live if j not in engine_only]
    brackets = _brackets(scanned, errors) if scanned else []
    fast = [(j, br) for j, br in zip(scanned, brackets) if j.fast and br is not None and id(j) not in errors]
    refined = _refine([j for j, _ in fast], [br for _, br in fast]) if fast else []
    done = {id(j): r for (j, _), r in zip(fast, refined) if r is not None}
    for job, br in zip(scanned, brackets):
        if id(job) in errors:
            continue
        if br is None:
            results[id(job)] = (None, "none", None, None, ())
        elif id(job) in done:
            results[id(job)] = (*done[id(job)], ())
        else:
            engine_only.append((job, br))
    for item in engine_only:
        job, br = item if isinstance(item, tuple) else (item, False)
        try:
            results[id(job)] = _engine_first_loss(job, chunk, br)
        except Exception as exc:  # noqa: BLE001 - reported per design
            errors[id(job)] = exc
    return results


def _single(model: Model) -> tuple:
    """One design through :func:`critical_thrust` itself (compressible fluid: frequency iteration)."""
    from .critical_thrust import critical_thrust

    r = critical_thrust(model)
    return (r.thrust, r.kind, r.omega, r.participation, r.warnings), (r.undamped_thrust, r.undamped_kind)


def critical_thrust_batch(
    models: Sequence[Model | None], *, n_scan: int = 64, chunk: int = 32, vectorized: bool = True
) -> BatchCriticalThrust:
    """Critical thrust of every model, as :func:`impstab.critical_thrust` gives it for one.

    Parameters
    ----------
    models : sequence of Model or None
        The designs; None marks a design to skip (status ``"invalid"``, empty message, for the
        caller to fill in).
    n_scan, chunk : int
        Scan intervals, and scan points classified per batch (a design whose scan has gone
        unstable takes no further chunks).
    vectorized : bool
        Vectorize the engine's steps across affine undamped designs (default); False runs every
        design's own engine after the batched scan.

    Returns
    -------
    BatchCriticalThrust
        A design with compressible fluid loading goes through :func:`impstab.critical_thrust`
        itself (its coefficients follow the onset frequency). A value located only to the
        classification tolerance has status ``"ok"`` and the warning as its message.
    """
    n = len(models)
    out = {k: np.full(n, np.nan) for k in ("thrust", "omega", "undamped", "t_max", "operating")}
    kind, ukind = np.full(n, -1, dtype=np.int8), np.full(n, -1, dtype=np.int8)
    status = np.full(n, STATUSES.index("invalid"), dtype=np.int8)
    message, modes = [""] * n, [""] * n
    jobs: list[_Job] = []
    owner: dict[int, tuple[int, bool]] = {}
    done: dict[int, tuple] = {}
    for i, model in enumerate(models):
        if model is None:
            continue
        out["t_max"][i] = t_max = float(model.analysis.thrust_max)
        out["operating"][i] = np.nan if model.thrust.operating is None else float(model.thrust.operating)
        try:
            if model.fluid.compressible:
                done[i] = _single(model)
                continue
            built = [(_Job(ModelFamily(model, None, damped=True), t_max, n_scan), True)]
            if model.is_damped:
                built.append((_Job(ModelFamily(model, None, damped=False), t_max, n_scan), False))
        except Exception as exc:  # noqa: BLE001 - reported per design
            status[i], message[i] = _failure(exc)
            continue
        for job, damped in built:
            jobs.append(job)
            owner[id(job)] = (i, damped)
    errors: dict[int, Exception] = {}
    _operators(jobs)
    _prime(jobs, chunk, errors)
    results = _solve_jobs(jobs, chunk, vectorized, errors)
    pairs: dict[int, dict[bool, _Job]] = {}
    for job in jobs:
        i, damped = owner[id(job)]
        pairs.setdefault(i, {})[damped] = job
    for i, pair in pairs.items():
        err = next((errors[id(j)] for j in pair.values() if id(j) in errors), None)
        if err is not None:
            status[i], message[i] = _failure(err)
            continue
        res, und = results[id(pair[True])], None
        if False in pair:
            u = results[id(pair[False])]
            und = u[:2]
            res = (*res[:4], res[4] + tuple(f"undamped companion: {w}" for w in u[4]))
        done[i] = (res, und)
    for i, (res, und) in done.items():
        p, k, omega, part, warn = res
        status[i], message[i] = 0, "; ".join(warn)
        out["thrust"][i] = np.nan if p is None else p
        out["omega"][i] = np.nan if omega is None else omega
        kind[i], modes[i] = KINDS.index(k), ",".join(_modes(part))
        up, uk = (p, k) if und is None else und
        out["undamped"][i], ukind[i] = (np.nan if up is None else up), KINDS.index(uk)
    evaluations = sum(j.evaluations + (j._engine.evaluations if j._engine is not None else 0) for j in jobs)
    return BatchCriticalThrust(
        out["thrust"], kind, out["omega"], out["undamped"], ukind, out["t_max"], out["operating"],
        modes, status, message, evaluations,
    )


def _failure(exc: Exception) -> tuple[int, str]:
    """Status code and one-line message of a design whose analysis raised."""
    from ..errors import ModelError, NumericalError

    if isinstance(exc, ModelError):
        return STATUSES.index("invalid"), str(exc)
    text = " ".join(str(exc).split()) or type(exc).__name__
    if isinstance(exc, (NumericalError, np.linalg.LinAlgError, FloatingPointError, ArithmeticError)):
        return STATUSES.index("numerical_failure"), f"{type(exc).__name__}: {text}"
    return STATUSES.index("error"), f"{type(exc).__name__}: {text}"
