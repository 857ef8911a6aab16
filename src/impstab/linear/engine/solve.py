"""The engine's entry point: solve a list of problems in one compiled loop and collect the outcomes."""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..blocks import decoupled_blocks
from ..eigen import kinetic_shares
from .layout import (AFFINE, BISECTIONS, BRACKETS, CHUNK, DECOMPOSITIONS, DIRECTION, EVALUATIONS, FIRST, HI, KIND, LARGEST, LO,
                     LOAD, N_SCAN, OMEGA, PAIRS, START_UNSTABLE, STATUS, WARNED, Jobs)
from .refine import LIMIT, refine_stack
from .scan import scan_stack
from . import large
from .problems import Problem
from .spectra import register, unregister
from .tolerances import TOL_UNSTABLE
from ..._jit import require_compiled

__all__ = ["Outcome", "Crossing", "StackOutcome", "solve", "solve_affine", "PROVIDER_CHUNK"]

Array = NDArray[np.float64]

#: scan points classified per call of a provider
PROVIDER_CHUNK = 16
#: scan points classified per call for affine problems whose blocks are closed forms (order <= 2),
#: where the call costs more than the eigenvalues; coupled affine problems go one point at a time
BLOCK_CHUNK = 8


def _affine_chunk(largest):
    return np.where(largest <= 2, BLOCK_CHUNK, 1)

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


@functools.lru_cache(maxsize=256)
def _grid(p_min: float, p_max: float, n_scan: int) -> Array:
    grid = np.linspace(p_min, p_max, n_scan + 1)
    grid.setflags(write=False)
    return grid


def _jobs(problems: list[Problem], chunk: int) -> tuple[Jobs, list[int]]:
    """The stack's arrays (:mod:`~impstab.linear.engine.layout`) and the providers' keys."""
    count = len(problems)
    if count == 1 and problems[0].affine:  # a single model: the fewest calls
        p = problems[0]
        a0, a1 = p.operators()
        a0, a1 = a0[None], a1[None]
        bs = decoupled_blocks(a0, a1, np.array([max(abs(p.p_min), abs(p.p_max))]))
        largest = int(bs.largest[0])
        ints = np.array([[0 if p.undamped else 1, 1, -1, p.n_scan, BLOCK_CHUNK if largest <= 2 else 1, largest]],
                        dtype=np.int64)
        grids = _grid(p.p_min, p.p_max, p.n_scan)[None].copy()
        return Jobs(ints, np.array([[p.p_min, p.p_max]]), grids, a0, a1, bs.order, bs.starts, bs.nblocks,
                    bs.mirror, bs.fixed, p.weights[None]), []
    n, n_dof = problems[0].order, problems[0].n_dof
    keys = [-1 if p.affine else register(p.provider) for p in problems]
    ints = np.array([(0 if p.undamped else 1, p.affine, k, p.n_scan, 1 if p.affine else chunk, n)
                     for p, k in zip(problems, keys)], dtype=np.int64)
    span = np.array([(p.p_min, p.p_max) for p in problems])
    grids = np.zeros((count, max(p.n_scan for p in problems) + 1))
    for i, p in enumerate(problems):
        grids[i, : p.n_scan + 1] = _grid(p.p_min, p.p_max, p.n_scan)
    if max(keys) < 0:  # the usual stack: affine problems only
        if count == 1:
            a0, a1 = problems[0].operators()
            a0, a1, weights = a0[None], a1[None], problems[0].weights[None]
        else:
            ops = [p.operators() for p in problems]
            a0 = np.stack([o[0] for o in ops])
            a1 = np.stack([o[1] for o in ops])
            weights = np.stack([p.weights for p in problems])
        bs = decoupled_blocks(a0, a1, np.array([max(abs(p.p_min), abs(p.p_max)) for p in problems]))
        ints[:, LARGEST] = bs.largest
        ints[:, CHUNK] = _affine_chunk(bs.largest)
        return Jobs(ints, span, grids, a0, a1, bs.order, bs.starts, bs.nblocks, bs.mirror, bs.fixed,
                    weights), []
    a0 = np.zeros((count, n, n))
    a1 = np.zeros((count, n, n))
    weights = np.ones((count, n_dof))
    for i, p in enumerate(problems):
        if p.affine:
            (a0[i], a1[i]), weights[i] = p.operators(), p.weights
    order = np.empty((count, n), dtype=np.int64)
    order[:] = np.arange(n)
    starts = np.full((count, n + 1), n, dtype=np.int64)
    starts[:, 0] = 0
    nblocks = np.ones(count, dtype=np.int64)
    mirror = np.zeros((count, n), dtype=np.int64)
    fixed = np.full((count, n), np.nan + 0j)
    rows = np.flatnonzero(ints[:, AFFINE])
    if rows.size:
        bs = decoupled_blocks(a0[rows], a1[rows], np.abs(span[rows]).max(axis=1))
        order[rows], starts[rows], nblocks[rows], ints[rows, LARGEST] = bs.order, bs.starts, bs.nblocks, bs.largest
        mirror[rows], fixed[rows] = bs.mirror, bs.fixed
        ints[rows, CHUNK] = _affine_chunk(bs.largest)
    return Jobs(ints, span, grids, a0, a1, order, starts, nblocks, mirror, fixed, weights), [k for k in keys if k >= 0]


def _run(jobs: Jobs, n_dof: int, all_crossings: bool):
    """The two compiled loops over a stack: ``(onsets, counts, mode, part)`` (see ``layout``)."""
    count = len(jobs.ints)
    if count > 2:
        require_compiled()  # a stack of designs: compiled from its first problem
    # rows for the brackets: every crossing (at most two per grid interval: a bubble's loss and
    # regain), or for the first loss alone the one bracket the scan stops at (and a spare); a
    # study's stack of 1e4 designs would otherwise allocate 18 MB here for 2 rows used
    rows = 2 * jobs.grids.shape[1] if all_crossings else 2
    onsets = np.full((count, rows, 7), np.nan)
    counts = np.zeros((count, 8), dtype=np.int64)
    mode = np.zeros((count, n_dof), dtype=np.complex128)
    part = np.zeros((count, n_dof))
    scan_stack(jobs, bool(all_crossings), onsets, counts)
    refine_stack(jobs, onsets, mode, part, counts)
    return onsets, counts, mode, part


@dataclass(frozen=True, eq=False)
class StackOutcome:
    """The first loss of stability of every problem of an affine stack, as arrays.

    ``load``, ``omega`` (NaN: stable up to ``p_max``), ``kind`` (0 none, 1 flutter,
    2 divergence), ``participation (J, n_dof)``, ``evaluations (J,)`` eigenproblems, and
    ``warnings``: the warnings of each problem (mostly empty). ``decompositions`` and ``pairs``
    count the eigenproblems with eigenvectors, and those with the vectors of two eigenvalues only.
    """

    load: Array
    kind: NDArray[np.int8]
    omega: Array
    participation: Array
    evaluations: NDArray[np.int64]
    warnings: list[tuple[str, ...]]
    decompositions: NDArray[np.int64] | None = None
    pairs: NDArray[np.int64] | None = None


def solve_affine(a0: Array, a1: Array, weights: Array, p_max: Array, *, undamped: bool = True,
                 n_scan: int = 64) -> StackOutcome:
    """The engine on a stack of affine problems given as arrays (a design study's designs).

    ``a0, a1 (J, N, N)``: the operators ``A = a0 + p a1`` (undamped: ``M^-1 K``); ``weights
    (J, n_dof)``; ``p_max (J,)``: each range ``[0, p_max]``. The same loops as :func:`solve`,
    without a Python object per problem.
    """
    count, n = a0.shape[0], a0.shape[-1]
    p_max = np.asarray(p_max, dtype=float)
    ints = np.empty((count, 6), dtype=np.int64)
    ints[:] = (0 if undamped else 1, 1, -1, n_scan, 1, n)
    span = np.zeros((count, 2))
    span[:, 1] = p_max
    grids = np.empty((count, n_scan + 1))
    for value in np.unique(p_max):
        grids[p_max == value] = _grid(0.0, float(value), n_scan)
    a0, a1 = np.ascontiguousarray(a0, dtype=float), np.ascontiguousarray(a1, dtype=float)
    bs = decoupled_blocks(a0, a1, np.abs(p_max))
    ints[:, LARGEST] = bs.largest
    ints[:, CHUNK] = _affine_chunk(bs.largest)
    jobs = Jobs(ints, span, grids, a0, a1, bs.order, bs.starts, bs.nblocks, bs.mirror, bs.fixed,
                np.ascontiguousarray(weights, dtype=float))
    onsets, counts, mode, part = _run(jobs, weights.shape[-1], False)
    rows = np.arange(count)
    start = counts[:, START_UNSTABLE] == 1
    first = np.where(start, 0, counts[:, FIRST])
    found = first >= 0
    pick = onsets[rows, np.maximum(first, 0)]
    load = np.where(found, pick[:, LOAD], np.nan)
    omega = np.where(found, pick[:, OMEGA], np.nan)
    kind = np.where(found, pick[:, KIND], 0).astype(np.int8)
    warned = np.flatnonzero((onsets[:, :, WARNED] == 1).any(axis=1))
    warnings: list[tuple[str, ...]] = [()] * count
    for r in warned:
        warnings[r] = tuple(_warning(float(row[LOAD])) for row in onsets[r, : counts[r, BRACKETS]] if row[WARNED])
    return StackOutcome(load, kind, omega, part, counts[:, EVALUATIONS].copy(), warnings,
                        counts[:, DECOMPOSITIONS].copy(), counts[:, PAIRS].copy())


def solve(problems: list[Problem], *, all_crossings: bool = False, chunk: int = PROVIDER_CHUNK) -> list[Outcome]:
    """The first loss of stability of every problem (and every crossing, if asked).

    Problems with operators of the same order are solved in one compiled loop; a problem whose
    provider raises gets an :class:`Outcome` with that ``error`` and the others go on.
    """
    if len(problems) == 1 and problems[0].order <= large.LARGE_ORDER:  # one model: the fewest calls
        p = problems[0]
        jobs, keys = _jobs(problems, int(chunk))
        try:
            onsets, counts, mode, part = _run(jobs, p.n_dof, all_crossings)
        finally:
            for k in keys:
                unregister(k)
        return [_outcome(p, onsets[0], mode[0], part[0], counts[0], all_crossings)]
    outcomes: list[Outcome | None] = [None] * len(problems)
    groups: dict[tuple[int, int], list[int]] = {}
    notes: dict[int, tuple[str, ...]] = {}
    for i, p in enumerate(problems):
        if not all_crossings and large.reducible(p):
            outcomes[i], reason = _solve_large(p, chunk)
            if outcomes[i] is not None:
                continue
            notes[i] = (f"modal reduction not used: {reason}; solved dense",)
        groups.setdefault((p.order, p.n_dof), []).append(i)
    for (n, n_dof), members in groups.items():
        group = [problems[i] for i in members]
        jobs, keys = _jobs(group, int(chunk))
        try:
            onsets, counts, mode, part = _run(jobs, n_dof, all_crossings)
        finally:
            for k in keys:
                unregister(k)
        for r, i in enumerate(members):
            outcomes[i] = _outcome(group[r], onsets[r], mode[r], part[r], counts[r], all_crossings, notes.get(i, ()))
    return outcomes  # type: ignore[return-value]


def _solve_large(problem: Problem, chunk: int) -> tuple[Outcome | None, str]:
    """A large second-order problem by modal reduction with error checks
    (:mod:`~impstab.linear.engine.large`).

    Returns the outcome, or None and the reason where the problem must be solved dense.
    """
    n = problem.second_order[0].shape[0]
    method = "coalescence" if problem.undamped else "hopf"
    m = large.BASIS
    evaluations = 0
    while True:
        m2 = min(2 * m, n - 1)
        w, phi = large.modal_basis(problem, m2)
        small, big = solve([large.reduced_problem(problem, w[:m], phi[:, :m]), large.reduced_problem(problem, w, phi)],
                           chunk=chunk)
        evaluations += small.evaluations + big.evaluations
        if small.load is None and big.load is None:
            if not large.stable_at(problem, problem.p_max):
                return None, "the full model is unstable at p_max although the reduced models are not"
            return Outcome(None, "none", None, None, None, (), evaluations + 1, big.warnings, method=method), ""
        if small.load is not None and big.load is not None and small.kind == big.kind \
                and abs(small.load - big.load) <= large.TRUNCATION_TOLERANCE * abs(big.load):
            break
        if 2 * m2 > n:
            return None, f"the onsets with {m} and {m2} modes disagree"
        m = m2
    try:
        if problem.undamped:
            width = max(10 * abs(small.load - big.load) / abs(big.load), 1e-8)
            onset, reason = large.full_onset(problem, big.load, big.kind, big.omega, w, phi, width)
        else:
            onset, reason = large.damped_full_onset(problem, big.load, big.kind, big.omega, big.mode, phi)
    except np.linalg.LinAlgError as exc:  # a singular matrix in the subspace or Newton iteration
        return None, f"the iteration on the full model failed ({exc})"
    if onset is None:
        return None, reason
    p, kind, omega, mode, part = onset
    return Outcome(p, kind, omega, mode, part, (), evaluations + 1, big.warnings, method=method), ""


def _warning(load: float) -> str:
    return (f"onset near {load:.10g} located by bisection on the stability tolerance "
            f"(growth above {TOL_UNSTABLE:g} of |lambda|), not by the exact indicator: expect a "
            "relative accuracy near that tolerance (very light damping?)")


def _outcome(problem: Problem, onsets, mode, part, counts, all_crossings: bool, notes: tuple = ()) -> Outcome:
    method = "coalescence" if problem.undamped else "hopf"
    counts = counts.tolist()  # Python numbers: reading numpy scalars one by one costs more than the rest
    evaluations, bisections = counts[EVALUATIONS], counts[BISECTIONS]
    if counts[STATUS] != 0:
        err = getattr(problem.provider, "error", None) or RuntimeError("the stability engine stopped")
        return Outcome(None, "none", None, None, None, (), evaluations, (), err, method=method)
    rows = onsets[: max(counts[BRACKETS], counts[FIRST] + 1, 1)].tolist()
    if counts[START_UNSTABLE]:
        row = rows[0]
        return Outcome(row[LOAD], _KINDS[int(row[KIND])], row[OMEGA], mode.copy(), part.copy(), (),
                       evaluations, unstable_at_start=True, method=method)
    found: list[Crossing] = []
    warnings: list[str] = list(notes)
    first = int(counts[FIRST])
    best = None
    if first >= 0:
        row = rows[first]
        best = (row[LOAD], _KINDS[int(row[KIND])], row[OMEGA], mode.copy(), part.copy())
    for row in rows[: counts[BRACKETS]]:
        direction = "loss" if row[DIRECTION] > 0 else "gain"
        if row[KIND] == LIMIT:
            p, kind, omega, m, pa = limit_point(problem, float(row[LO]), float(row[HI]))
            if direction == "loss" and (best is None or p < best[0]):
                best = (p, kind, omega, m, pa)
        else:
            p, kind, omega = row[LOAD], _KINDS[int(row[KIND])], row[OMEGA]
        if row[WARNED]:
            warnings.append(_warning(p))
        if all_crossings or best is None:
            found.append(Crossing(p, direction, kind, omega))
    if len(found) > 1:
        found.sort(key=lambda c: c.load)
    if best is None:
        return Outcome(None, "none", None, None, None, tuple(found), evaluations, tuple(warnings),
                       bisections=bisections, method=method)
    p, kind, omega, m, pa = best
    return Outcome(p, kind, omega, m, pa, tuple(found) if all_crossings else (), evaluations, tuple(warnings),
                   bisections=bisections, method=method)


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
