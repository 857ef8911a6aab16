"""Running an optimisation: the population search over batched design evaluations, the polish,
the Pareto set stored like a study, the chosen design as a model file.

Each generation is one chunk of a design study (:func:`impstab.studies.evaluate.evaluate_chunk`:
the batched critical-thrust engine and the batched isolation outputs), so a design is evaluated
by exactly the code a study uses. Objectives: the isolation output (minimised) and the margin
(maximised; a design stable over its whole search counts with its search limit
``thrust_max / operating``, a lower bound). Constraints, each scaled by its limit: ``margin >=
margin_min``, ``static_deflection <= static_deflection_max``, ``peak_mount_load <=
peak_mount_load_max``. The chosen design is the feasible one with the smallest isolation value;
the polish (COBYLA on the isolation value under the same constraints) starts from it.

The Pareto set (the feasible non-dominated designs of every generation, with the polished
design) is then a study of its own (sampling ``"pareto"``, one ``sample`` per design), run into
a zarr store by :func:`impstab.studies.run_study`: verified, resumable and read like any study
(:func:`impstab.studies.open_study`). The search itself is deterministic for a seed; rerun, it
finds the same set and the store is reused.
"""

from __future__ import annotations

import hashlib
import json
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError
from .engine import SearchResult, joined, polish, search
from .problem import Optimization, bounds

__all__ = ["OptimizationResult", "run_optimization", "evaluate_designs"]


def evaluate_designs(opt: Optimization, x: NDArray) -> dict[str, NDArray]:
    """Every study output of ``opt.outputs`` (and the named isolation outputs) at designs ``x (n, d)``."""
    from ..studies.evaluate import ChunkTask, evaluate_chunk

    outputs = opt.outputs + (() if opt.isolation is None else tuple(p.name for p in opt.isolation.at))
    task = ChunkTask(index=0, block=(len(x),), base_model=opt.base_model,
                     segments=tuple(v.path.segments for v in opt.variables),
                     columns=tuple(np.asarray(x[:, i], dtype=float) for i in range(x.shape[1])),
                     outputs=outputs, model_name=opt.model_name, isolation=opt.isolation)
    return evaluate_chunk(task).data


def objectives(opt: Optimization, data: dict[str, NDArray]) -> tuple[NDArray, NDArray]:
    """``f = (isolation, -margin)`` and the scaled constraints ``g <= 0`` of evaluated designs."""
    margin = np.where(data["kind"] == 0, data["thrust_max"] / data["operating_thrust"], data["margin"])
    margin = np.where(data["status"] == 0, margin, np.nan)
    f = np.column_stack([data[opt.objective], -margin])
    g = []
    if opt.margin_min is not None:
        g.append((opt.margin_min - margin) / opt.margin_min)
    if opt.static_deflection_max is not None:
        g.append((data["static_deflection"] - opt.static_deflection_max) / opt.static_deflection_max)
    if opt.peak_mount_load_max is not None:
        g.append((data["peak_mount_load"] - opt.peak_mount_load_max) / opt.peak_mount_load_max)
    if opt.benign_onset:
        g.append(np.where(benign(data), -1.0, 1.0))
    return f, (np.column_stack(g) if g else np.zeros((len(margin), 0)))


def benign(data: dict[str, NDArray]) -> NDArray:
    """Designs whose onset is benign: a supercritical Hopf point, or no onset up to thrust_max.

    A subcritical onset (a jump to a large cycle, with a fold below the critical thrust) is not,
    nor is a degenerate one (undamped, symmetric, divergence: no proof of a benign cycle), nor a
    design whose post-critical analysis failed (its label is empty)."""
    label = np.asarray(data["bifurcation"]).astype(str)
    return (np.asarray(data["status"]) == 0) & ((label == "supercritical") | (np.asarray(data["kind"]) == 0))


@dataclass(frozen=True, eq=False)
class OptimizationResult:
    """The outcome of :func:`run_optimization`.

    Attributes
    ----------
    optimization : Optimization
    history : SearchResult
        Every evaluated design of the search and the polish (generation -1), objectives
        ``(isolation, -margin)``.
    pareto : StudyResult
        The Pareto set (and the polished design), stored like a study.
    chosen : dict
        ``parameters`` (path -> value), ``isolation``, ``margin``, ``static_deflection``,
        ``peak_mount_load``, ``polished`` (whether the polish improved it), ``feasible``.
    model_file : str or None
        Where the chosen design was written as a model file.
    seconds : float
    """

    optimization: Optimization
    history: SearchResult
    pareto: Any
    chosen: dict
    model_file: str | None = None
    seconds: float = 0.0
    polish_evaluations: int = 0
    notes: tuple[str, ...] = field(default_factory=tuple)

    def to_dict(self) -> dict:
        opt = self.optimization
        h = self.history
        return {
            "name": opt.name, "objective": opt.objective,
            "variables": [{"path": v.name, "low": v.low, "high": v.high, "scale": "log" if v.log else "linear"}
                          for v in opt.variables],
            "constraints": {"margin_min": opt.margin_min, "static_deflection_max": opt.static_deflection_max,
                            "peak_mount_load_max": opt.peak_mount_load_max, "benign_onset": opt.benign_onset},
            "evaluations": int(np.count_nonzero(h.generation >= 0)), "generations": opt.generations, "population": opt.population,
            "batched_calls": int((h.generation >= 0).any() and h.generation.max() + 1), "polish_evaluations": self.polish_evaluations,
            "feasible_designs": int(h.feasible.sum()), "pareto_designs": int(self.pareto.dataset.sizes["sample"]),
            "chosen": self.chosen, "store": self.pareto.store, "model_file": self.model_file,
            "seconds": self.seconds, "notes": list(self.notes),
        }

    def plot(self, ax=None):
        """Isolation against margin of every evaluated design, the Pareto front, the limits and the
        chosen design; returns the Axes (:func:`impstab.plot.tradeoff.plot_optimization`)."""
        from ..plot.tradeoff import plot_optimization

        return plot_optimization(self, ax=ax)


def _pareto_rows(f: NDArray, feasible: NDArray) -> NDArray:
    from ..studies.pareto import pareto_mask

    rows = np.flatnonzero(feasible)
    keep = pareto_mask(f[rows])
    # one row per distinct design
    picked = rows[keep]
    _, first = np.unique(f[picked], axis=0, return_index=True)
    return np.sort(picked[first])


def _pareto_study(opt: Optimization, x: NDArray):
    from ..studies.study import Parameter, Study

    digest = hashlib.sha256((opt.fingerprint + x.tobytes().hex()).encode()).hexdigest()
    return Study(
        name=f"{opt.name}: Pareto set", method="pareto",
        parameters=tuple(Parameter(v.path, np.ascontiguousarray(x[:, i])) for i, v in enumerate(opt.variables)),
        outputs=opt.outputs + (() if opt.isolation is None else tuple(p.name for p in opt.isolation.at)),
        chunk_size=max(len(x), 1), base_model=opt.base_model, model_name=opt.model_name,
        study_text=opt.text, model_text=opt.model_text, fingerprint=digest, source=opt.source,
        model_source=opt.model_source, seed=opt.seed, isolation=opt.isolation,
    )


def run_optimization(opt: Optimization, store: str | None = None, model_out: str | None = None) -> OptimizationResult:
    """Search, polish, store the Pareto set (``store``: a zarr folder, None: in memory) and write
    the chosen design to ``model_out`` (TOML), if given."""
    from ..io import write_output
    from ..studies import run_study
    from .toml_out import dumps

    t0 = time.perf_counter()
    var = bounds(opt)

    def evaluate(x: NDArray):
        return objectives(opt, evaluate_designs(opt, x))

    n_con = sum(v is not None for v in (opt.margin_min, opt.static_deflection_max, opt.peak_mount_load_max))
    n_con += int(opt.benign_onset)
    hist = search(evaluate, var, 2, n_con, population=opt.population, generations=opt.generations, seed=opt.seed)
    feasible = hist.feasible
    notes: list[str] = []
    if not feasible.any():
        raise ModelError("constraints", None, f"no design of the {len(hist.x)} evaluated met every constraint: relax "
                         "the limits, widen the bounds or raise optimizer.generations")
    rows = np.flatnonzero(feasible)
    best = int(rows[np.argmin(hist.f[rows, 0])])
    x_best, f_best = hist.x[best], hist.f[best]
    polished, n_polish = False, 0
    if opt.polish:
        x_p, f_p, g_p, done = polish(evaluate, var, x_best, max_evaluations=opt.polish_evaluations)
        n_polish = len(done.x)
        hist = joined(hist, done)
        if np.all(g_p <= 0) and f_p[0] < f_best[0]:
            polished = True
            x_best, f_best = x_p, f_p
    x_set = hist.x[_pareto_rows(hist.f, hist.feasible)]
    study = _pareto_study(opt, x_set)
    pareto = run_study(study, store)
    params = {v.name: float(x_best[i]) for i, v in enumerate(opt.variables)}
    data = evaluate_designs(opt, x_best[None])
    chosen = {
        "parameters": params, "isolation": float(f_best[0]), "margin": float(-f_best[1]),
        "margin_is_lower_bound": bool(data["kind"][0] == 0),
        "static_deflection": float(data["static_deflection"][0]), "peak_mount_load": float(data["peak_mount_load"][0]),
        "critical_thrust": float(data["critical_thrust"][0]), "polished": polished, "feasible": True,
    }
    if opt.benign_onset:
        chosen["bifurcation"] = str(data["bifurcation"][0]) or None
        chosen["lyapunov_coefficient"] = float(data["lyapunov_coefficient"][0])
    written = None
    if model_out is not None:
        d = pareto.model_dict(params)
        header = (f"The chosen design of the optimisation {opt.name!r} ({opt.source or 'in memory'}):\n"
                  + "\n".join(f"  {k} = {v!r}" for k, v in params.items())
                  + f"\n  {opt.objective} = {chosen['isolation']:.6g}, margin = {chosen['margin']:.6g}")
        text = dumps({k: v for k, v in d.items()}, header=header)
        written = str(write_output(model_out, text.encode(), option="--model"))
    return OptimizationResult(opt, hist, pareto, chosen, written, time.perf_counter() - t0, n_polish, tuple(notes))
