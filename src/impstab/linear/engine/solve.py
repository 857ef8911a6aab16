"""The engine's entry point: solve a list of problems in one compiled loop and collect the outcomes."""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..blocks import decoupled_blocks
from ..eigen import kinetic_shares
from .refine import LIMIT, refine_stack
from .scan import scan_stack
from .problems import Problem
from .spectra import register, unregister
from .tolerances import TOL_UNSTABLE

__all__ = ["Outcome", "Crossing", "solve", "PROVIDER_CHUNK"]

Array = NDArray[np.float64]

#: scan points classified per call of a provider (affine problems: one at a time)
PROVIDER_CHUNK = 16

#: the compiled loop's view of a stack of problems of one operator order
Jobs = namedtuple("Jobs", "form affine key a0 a1 order starts nblocks largest grids n_scan chunk weights p_lo p_hi")
#: its results: per bracket, and per problem
Results = namedtuple("Results", "first load kind omega direction warned limit mode part evaluations bisections")

_KINDS = {1: "flutter", 2: "divergence"}


@dataclass(frozen=True)
class Crossing:
    """A change of stability at load ``load``: ``"loss"`` (stable -> unstable) or ``"gain"``."""

    load: float
    direction: str
    kind: str
    omega: float


@dataclass(frozen=True, eq=False)
class Outcome:
    """What the engine found for one problem.

    ``load`` is the first loss of stability from ``p_min`` (None if stable up to ``p_max``),
    ``crossings`` every change found (all of them with ``all_crossings``), ``error`` the exception
    that stopped the problem (its provider raised), ``bisections`` the refinement steps taken on
    the classification (a diagnostic).
    """

    load: float | None
    kind: str
    omega: float | None
    mode: NDArray[np.complex128] | None
    participation: Array | None
    crossings: tuple[Crossing, ...] = ()
    evaluations: int = 0
    warnings: tuple[str, ...] = ()
    error: BaseException | None = None
    unstable_at_start: bool = False
    bisections: int = 0
    method: str = field(default="")


def _stack(problems: list[Problem], all_crossings: bool, chunk: int):
    count = len(problems)
    n = problems[0].order
    n_dof = problems[0].n_dof
    g = max(p.n_scan for p in problems) + 1
    a0 = np.zeros((count, n, n))
    a1 = np.zeros((count, n, n))
    affine = np.array([p.affine for p in problems], dtype=np.bool_)
    weights = np.ones((count, n_dof))
    grids = np.zeros((count, g))
    for i, p in enumerate(problems):
        if p.affine:
            a0[i], a1[i] = p.a0, p.a1
            weights[i] = p.weights
        grids[i, : p.n_scan + 1] = np.linspace(p.p_min, p.p_max, p.n_scan + 1)
    order = np.tile(np.arange(n), (count, 1))
    starts = np.full((count, n + 1), n, dtype=np.int64)
    starts[:, 0] = 0
    nblocks = np.ones(count, dtype=np.int64)
    largest = np.full(count, n, dtype=np.int64)
    rows = np.flatnonzero(affine)
    if rows.size:
        reach = np.array([max(abs(problems[r].p_min), abs(problems[r].p_max)) for r in rows])
        bs = decoupled_blocks(a0[rows], a1[rows], reach)
        order[rows], starts[rows], nblocks[rows], largest[rows] = bs.order, bs.starts, bs.nblocks, bs.largest
    keys = np.array([-1 if p.affine else register(p.provider) for p in problems], dtype=np.int64)
    jobs = Jobs(
        np.array([0 if p.undamped else 1 for p in problems], dtype=np.int64), affine, keys, a0, a1,
        order, starts, nblocks, largest, grids, np.array([p.n_scan for p in problems], dtype=np.int64),
        np.where(affine, 1, chunk).astype(np.int64), weights,
        np.array([p.p_min for p in problems]), np.array([p.p_max for p in problems]),
    )
    cap = 2 * g
    res = Results(
        np.full(count, -1, dtype=np.int64), np.full((count, cap), np.nan), np.zeros((count, cap), dtype=np.int64),
        np.full((count, cap), np.nan), np.zeros((count, cap), dtype=np.int64), np.zeros((count, cap), dtype=np.bool_),
        np.full((count, cap, 2), np.nan), np.zeros((count, n_dof), dtype=np.complex128), np.zeros((count, n_dof)),
        np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64),
    )
    return jobs, res, keys, cap


def solve(problems: list[Problem], *, all_crossings: bool = False, chunk: int = PROVIDER_CHUNK) -> list[Outcome]:
    """The first loss of stability of every problem (and every crossing, if asked).

    Problems with operators of the same order are solved in one compiled loop; a problem whose
    provider raises gets an :class:`Outcome` with that ``error`` and the others go on.
    """
    outcomes: list[Outcome | None] = [None] * len(problems)
    groups: dict[tuple[int, int], list[int]] = {}
    for i, p in enumerate(problems):
        groups.setdefault((p.order, p.n_dof), []).append(i)
    for members in groups.values():
        group = [problems[i] for i in members]
        jobs, res, keys, cap = _stack(group, bool(all_crossings), int(chunk))
        count = len(group)
        brk = np.zeros((count, cap, 2))
        n_brk = np.zeros(count, dtype=np.int64)
        start = np.zeros(count, dtype=np.bool_)
        status = np.zeros(count, dtype=np.int64)
        try:
            scan_stack(jobs, bool(all_crossings), brk, n_brk, start, status, res.evaluations)
            refine_stack(jobs, brk, n_brk, start, status, res)
        finally:
            for k in keys:
                if k >= 0:
                    unregister(int(k))
        for r, i in enumerate(members):
            outcomes[i] = _outcome(group[r], res, r, int(n_brk[r]), bool(start[r]), int(status[r]), all_crossings)
    return outcomes  # type: ignore[return-value]


def _warning(load: float) -> str:
    return (f"onset near {load:.10g} located by bisection on the stability tolerance "
            f"(growth above {TOL_UNSTABLE:g} of |lambda|), not by the exact indicator: expect a "
            "relative accuracy near that tolerance (very light damping?)")


def _outcome(problem: Problem, res: Results, r: int, n_brk: int, start: bool, status: int,
             all_crossings: bool) -> Outcome:
    method = "coalescence" if problem.undamped else "hopf"
    evaluations = int(res.evaluations[r])
    if status != 0:
        err = getattr(problem.provider, "error", None) or RuntimeError("the stability engine stopped")
        return Outcome(None, "none", None, None, None, (), evaluations, (), err, method=method)
    if start:
        return Outcome(float(res.load[r, 0]), _KINDS[int(res.kind[r, 0])], float(res.omega[r, 0]),
                       res.mode[r].copy(), res.part[r].copy(), (), evaluations, unstable_at_start=True,
                       method=method)
    found: list[tuple] = []
    warnings: list[str] = []
    first = int(res.first[r])
    first_values = None
    if first >= 0:
        first_values = (float(res.load[r, first]), _KINDS[int(res.kind[r, first])], float(res.omega[r, first]),
                        res.mode[r].copy(), res.part[r].copy())
    for i in range(n_brk):
        direction = "loss" if res.direction[r, i] > 0 else "gain"
        if res.kind[r, i] == LIMIT:
            p, kind, omega, mode, part = limit_point(problem, float(res.limit[r, i, 0]), float(res.limit[r, i, 1]))
            if direction == "loss" and (first_values is None or p < first_values[0]):
                first_values = (p, kind, omega, mode, part)
        else:
            p, kind, omega = float(res.load[r, i]), _KINDS[int(res.kind[r, i])], float(res.omega[r, i])
        if res.warned[r, i]:
            warnings.append(_warning(p))
        found.append(Crossing(p, direction, kind, omega))
    found.sort(key=lambda c: c.load)
    if first_values is None:
        return Outcome(None, "none", None, None, None, tuple(found), evaluations, tuple(warnings),
                       bisections=int(res.bisections[r]), method=method)
    p, kind, omega, mode, part = first_values
    return Outcome(p, kind, omega, mode, part, tuple(found) if all_crossings else (), evaluations, tuple(warnings),
                   bisections=int(res.bisections[r]), method=method)


def limit_point(problem: Problem, a: float, b: float):
    """The static equilibrium path folds between ``a`` (reached) and ``b`` (not reached).

    At a fold the smallest stiffness eigenvalue vanishes like ``sqrt(p_f - p)``, so its square is
    linear in ``p`` there: secant steps on it from the reached side locate ``p_f`` (a static loss of
    stability, reported as divergence).
    """
    provider = problem.provider
    s2 = provider.fold_indicator
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
    n = problem.n_dof
    op = provider.operators(np.array([x1]))[0]
    if not np.isfinite(op).all():
        # the path could not be followed close to the fold: report where it ended
        return float(b), "divergence", 0.0, np.zeros(n, complex), np.full(n, np.nan)
    vals, vecs = np.linalg.eig(op)
    j = int(np.argmin(np.abs(vals)))
    mode = vecs[:n, j]
    mode = mode * np.conj(mode[np.argmax(np.abs(mode))])
    mode = mode / max(np.abs(mode).max(), 1e-300)
    return float(x1), "divergence", 0.0, mode, kinetic_shares(vecs[:n, [j]], np.diag(provider.weights(x1)))
