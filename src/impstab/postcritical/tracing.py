"""The working state of a continuation run: points on the branch and how they are corrected."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import NumericalError
from .collocation import Profile
from .floquet import FloquetMultipliers
from .mesh import equidistribute, error_indicator
from .periodic import OrbitProblem, Solution, Weights
from .result import Cycle
from .system import DynamicalSystem

__all__ = ["BranchPoint", "Tracer", "to_cycle", "STABILITY_FLOOR"]

Array = NDArray[np.float64]

#: stability margin floor (see Cycle.stability_tolerance)
STABILITY_FLOOR = 1e-9


@dataclass
class BranchPoint:
    """A converged cycle on the branch with its unit tangent, multipliers and arclength."""

    sol: Solution
    problem: OrbitProblem
    tangent: Array
    floquet: FloquetMultipliers
    arclength: float
    label: str = ""

    @property
    def u(self) -> Array:
        return self.sol.vector

    @property
    def p(self) -> float:
        return self.sol.parameter


class Tracer:
    """The working state of one continuation run: the problems per mesh, corrections, re-meshing."""

    def __init__(self, system: DynamicalSystem, weights: Weights, degree: int, mesh_tolerance: float | None,
                 max_intervals: int) -> None:
        self.system = system
        self.weights = weights
        self.degree = degree
        self.mesh_tolerance = mesh_tolerance
        self.max_intervals = max_intervals
        self.problems: dict[bytes, OrbitProblem] = {}
        self.failures = 0

    def problem(self, mesh: Array) -> OrbitProblem:
        key = mesh.tobytes()
        if key not in self.problems:
            if len(self.problems) > 8:
                self.problems.clear()
            self.problems[key] = OrbitProblem(self.system, mesh, self.degree, self.weights)
        return self.problems[key]

    def finish(self, prob: OrbitProblem, sol: Solution | None, ref: Profile, orient: Array, s: float,
               label: str = "") -> BranchPoint | None:
        if sol is None:
            self.failures += 1
            return None
        try:
            tangent = prob.tangent(sol, ref, orient)
            floq = prob.floquet(sol)
        except (RuntimeError, NumericalError, np.linalg.LinAlgError):
            self.failures += 1
            return None
        if not np.all(np.isfinite(tangent)):
            return None
        return BranchPoint(sol, prob, tangent, floq, s, label)

    def correct(self, base: BranchPoint, ds: float, label: str = "") -> BranchPoint | None:
        prob = base.problem
        guess = base.u + ds * base.tangent
        sol = prob.solve(guess, base.sol.profile, ("arclength", base.u, ds, base.tangent))
        return self.finish(prob, sol, base.sol.profile, base.tangent, base.arclength + ds, label)

    def at_parameter(self, a: BranchPoint, b: BranchPoint, p_star: float, label: str) -> BranchPoint | None:
        prob = a.problem
        theta = (p_star - a.p) / (b.p - a.p) if b.p != a.p else 0.5
        guess = a.u + theta * (b.u - a.u)
        guess[-1] = p_star
        sol = prob.solve(guess, a.sol.profile, ("parameter", None, p_star, None))
        return self.finish(prob, sol, a.sol.profile, a.tangent, a.arclength + theta * (b.arclength - a.arclength),
                           label)

    def remesh(self, pt: BranchPoint) -> BranchPoint:
        """The point on an equidistributed mesh (more intervals while the error is too large)."""
        scale = self.weights.state
        prof = pt.sol.profile
        intervals = prof.intervals
        err = self.relative_error(prof)
        if self.mesh_tolerance is not None and err > self.mesh_tolerance:
            intervals = min(2 * intervals, self.max_intervals)
        new_mesh = equidistribute(prof, scale, intervals)
        prob = self.problem(new_mesh)
        new_prof = prof.resample(new_mesh)
        tan_prof = Profile(prof.mesh, pt.tangent[:-2].reshape(prof.nodes.shape), prof.degree).resample(new_mesh)
        orient = prob.pack(tan_prof, pt.tangent[-2], pt.tangent[-1])
        guess = prob.pack(new_prof, pt.sol.period, pt.p)
        sol = prob.solve(guess, new_prof, ("parameter", None, pt.p, None))
        new = self.finish(prob, sol, new_prof, orient / max(prob.norm(orient), 1e-300), pt.arclength, pt.label)
        return pt if new is None else new

    def relative_error(self, prof: Profile) -> float:
        err, _ = error_indicator(prof, self.weights.state)
        amp = float(np.max(prof.amplitude() / self.weights.state))
        return err / max(amp, 1e-300)


def to_cycle(pt: BranchPoint, label: str | None = None) -> Cycle:
    prof = pt.sol.profile
    lo, hi = prof.extrema()
    fl = pt.floquet
    tol = max(STABILITY_FLOOR, 10.0 * fl.trivial_error)
    stable = fl.largest < 1.0
    err, _ = error_indicator(prof, pt.problem.weights.state)
    return Cycle(parameter=pt.p, period=pt.sol.period, profile=prof, multipliers=fl.values, trivial=fl.trivial,
                 trivial_error=fl.trivial_error, stable=bool(stable), stability_tolerance=tol,
                 amplitude=0.5 * (hi - lo), minimum=lo, maximum=hi, mean=prof.mean(), mesh_error=err,
                 arclength=pt.arclength, label=pt.label if label is None else label,
                 newton_iterations=pt.sol.iterations)


