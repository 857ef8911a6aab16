"""Population search and local polish over bounded design variables, one batched call per generation.

The search is pymoo's (NSGA-II for two objectives, its genetic algorithm for one), on the unit
cube: each variable is mapped to ``[0, 1]`` linearly, or logarithmically for a ``log`` variable,
so that the operators see stiffnesses spanning decades evenly. Every generation is one call of
``evaluate`` with the whole population (a design study's batched evaluation, in impstab).
Constraints are ``g <= 0``; pymoo ranks feasible designs first and infeasible ones by their
total violation. A design whose evaluation fails (NaN) is infeasible with a violation larger
than any computed one.

The polish is scipy's COBYLA (constrained, derivative-free: the objectives are grid maxima and
bisection-refined critical loads, whose finite-difference gradients are unreliable) from the
chosen design of the population, on objective 0, inside the unit cube; it is kept only when it
is feasible and better.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["SearchResult", "search", "polish", "joined", "Variables"]

Array = NDArray[np.float64]
#: objective and violation given to pymoo for a design whose evaluation failed
_FAILED = 1e300


@dataclass(frozen=True)
class Variables:
    """Bounds of the design variables (``log``: geometric scale, bounds > 0)."""

    lower: Array
    upper: Array
    log: NDArray[np.bool_]

    def to_x(self, u: Array) -> Array:
        """Unit-cube points ``u (n, d)`` to design values."""
        u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
        lin = self.lower + u * (self.upper - self.lower)
        with np.errstate(divide="ignore", invalid="ignore"):
            geo = self.lower * (self.upper / self.lower) ** u
        return np.where(self.log, geo, lin)

    def to_u(self, x: Array) -> Array:
        x = np.asarray(x, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            geo = np.log(x / self.lower) / np.log(self.upper / self.lower)
        return np.where(self.log, geo, (x - self.lower) / (self.upper - self.lower))


@dataclass(frozen=True, eq=False)
class SearchResult:
    """Every evaluated design of a search, in order, and the final population.

    Attributes
    ----------
    x : (n, d) design values;  f : (n, k) objectives (minimised; NaN: failed);  g : (n, m) constraints (<= 0)
    generation : (n,) int, 0-based (the polish is ``-1``)
    final : (n,) bool, the designs of the final population
    evaluations : int, calls of ``evaluate``
    """

    x: Array
    f: Array
    g: Array
    generation: NDArray[np.int64]
    final: NDArray[np.bool_]
    evaluations: int

    @property
    def feasible(self) -> NDArray[np.bool_]:
        return np.isfinite(self.f).all(axis=1) & np.all(self.g <= 0.0, axis=1)


class _Recorder:
    """``evaluate`` wrapped for pymoo: records every call, turns failures into infeasibility."""

    def __init__(self, evaluate: Callable, variables: Variables):
        self.evaluate, self.variables = evaluate, variables
        self.x: list[Array] = []
        self.f: list[Array] = []
        self.g: list[Array] = []
        self.gen: list[Array] = []
        self.calls = 0

    def __call__(self, u: Array, generation: int) -> tuple[Array, Array]:
        x = self.variables.to_x(u)
        f, g = self.evaluate(x)
        f = np.asarray(f, dtype=float).reshape(len(x), -1)
        g = np.asarray(g, dtype=float).reshape(len(x), -1)
        self.calls += 1
        self.x.append(x)
        self.f.append(f)
        self.g.append(g)
        self.gen.append(np.full(len(x), generation))
        bad = ~(np.isfinite(f).all(axis=1) & np.isfinite(g).all(axis=1))
        f = np.where(bad[:, None], _FAILED, f)
        g = np.where(bad[:, None], _FAILED, g)
        return f, g


def search(evaluate: Callable[[Array], tuple[Array, Array]], variables: Variables, n_objectives: int,
           n_constraints: int, *, population: int = 24, generations: int = 20, seed: int = 0) -> SearchResult:
    """Population search (NSGA-II for two objectives, a genetic algorithm for one).

    Parameters
    ----------
    evaluate : callable
        ``x (n, d) -> (f (n, k), g (n, m))``: objectives to minimise and constraints ``g <= 0``;
        called once per generation with the whole population.
    variables : Variables
    n_objectives : {1, 2}
    n_constraints : int
    population, generations, seed : int

    Returns
    -------
    SearchResult
    """
    from pymoo.core.problem import Problem
    from pymoo.optimize import minimize

    rec = _Recorder(evaluate, variables)
    d = len(variables.lower)

    class _P(Problem):
        def __init__(self):
            super().__init__(n_var=d, n_obj=n_objectives, n_ieq_constr=n_constraints, xl=0.0, xu=1.0)
            self.generation = 0

        def _evaluate(self, u, out, *args, **kwargs):
            f, g = rec(u, self.generation)
            self.generation += 1
            out["F"] = f
            if n_constraints:
                out["G"] = g

    if n_objectives == 2:
        from pymoo.algorithms.moo.nsga2 import NSGA2

        algorithm = NSGA2(pop_size=population)
    elif n_objectives == 1:
        from pymoo.algorithms.soo.nonconvex.ga import GA

        algorithm = GA(pop_size=population, eliminate_duplicates=True)
    else:
        raise ValueError("one or two objectives")
    res = minimize(_P(), algorithm, ("n_gen", generations), seed=seed, verbose=False)
    x = np.concatenate(rec.x)
    final = np.zeros(len(x), dtype=bool)
    pop_u = res.pop.get("X")
    xf = variables.to_x(pop_u)
    for row in xf:  # the final population among the evaluated designs (last occurrence)
        hit = np.flatnonzero(np.all(x == row, axis=1))
        if hit.size:
            final[hit[-1]] = True
    return SearchResult(x, np.concatenate(rec.f), np.concatenate(rec.g), np.concatenate(rec.gen), final, rec.calls)


def polish(evaluate: Callable[[Array], tuple[Array, Array]], variables: Variables, x0: Array, *,
           max_evaluations: int = 200, tolerance: float = 1e-6) -> tuple[Array, Array, Array, SearchResult]:
    """COBYLA on objective 0 from ``x0`` with the constraints ``g <= 0``, inside the bounds.

    Returns ``(x, f, g, evaluated)``: the best feasible design met (``x0`` itself if none is
    better) and every design the polish evaluated (generation -1).
    """
    from scipy.optimize import minimize

    cache: dict[bytes, tuple[Array, Array]] = {}

    def at(u):
        key = np.asarray(u, dtype=float).tobytes()
        if key not in cache:
            f, g = evaluate(variables.to_x(np.asarray(u, dtype=float)[None]))
            cache[key] = (np.asarray(f, dtype=float).ravel(), np.asarray(g, dtype=float).ravel())
        return cache[key]

    def fun(u):
        f = at(u)[0][0]
        return f if np.isfinite(f) else _FAILED

    u0 = variables.to_u(np.asarray(x0, dtype=float))
    f0, g0 = at(u0)
    cons = []
    if g0.size:
        cons.append({"type": "ineq", "fun": lambda u: np.where(np.isfinite(at(u)[1]), -at(u)[1], -_FAILED)})
    d = len(u0)
    minimize(fun, u0, method="COBYLA", constraints=cons, bounds=[(0.0, 1.0)] * d,
             options={"maxiter": max_evaluations, "rhobeg": 0.05, "tol": tolerance})
    best_u, best_f, best_g = u0, f0, g0
    for key, (f, g) in cache.items():
        ok = np.isfinite(f).all() and np.all(g <= 0.0)
        if ok and (not (np.isfinite(best_f).all() and np.all(best_g <= 0.0)) or f[0] < best_f[0]):
            best_u, best_f, best_g = np.frombuffer(key, dtype=float), f, g
    us = np.array([np.frombuffer(k, dtype=float) for k in cache])
    done = SearchResult(variables.to_x(us), np.array([v[0] for v in cache.values()]),
                        np.array([v[1] for v in cache.values()]).reshape(len(cache), -1),
                        np.full(len(cache), -1), np.zeros(len(cache), dtype=bool), len(cache))
    return variables.to_x(best_u[None])[0], best_f, best_g, done


def joined(a: SearchResult, b: SearchResult) -> SearchResult:
    """The designs of two searches as one (``b`` after ``a``)."""
    return SearchResult(np.vstack([a.x, b.x]), np.vstack([a.f, b.f]), np.vstack([a.g, b.g]),
                        np.concatenate([a.generation, b.generation]), np.concatenate([a.final, b.final]),
                        a.evaluations + b.evaluations)
