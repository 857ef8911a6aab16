"""Entry point: critical thrust of many models at once."""

from __future__ import annotations

from typing import Sequence

import numpy as np
from numpy.typing import NDArray

from ...model.model import Model
from ..critical_thrust import _modes
from ..linearize import ModelFamily
from .jobs import KINDS, STATUSES, AffineDesign, BatchCriticalThrust, _Job
from .refine import _solve_jobs
from .scan import _operators, _prime

Array = NDArray[np.float64]



def _single(model: Model) -> tuple:
    """One design through :func:`critical_thrust` itself (compressible fluid: frequency iteration)."""
    from ..critical_thrust import critical_thrust

    r = critical_thrust(model)
    return (r.thrust, r.kind, r.omega, r.participation, r.warnings), (r.undamped_thrust, r.undamped_kind)


def critical_thrust_batch(
    models: Sequence[Model | AffineDesign | None], *, n_scan: int = 64, chunk: int = 16, vectorized: bool = True
) -> BatchCriticalThrust:
    """Critical thrust of every model, as :func:`impstab.critical_thrust` gives it for one.

    Parameters
    ----------
    models : sequence of Model, AffineDesign or None
        The designs; None marks a design to skip (status ``"invalid"``, empty message, for the
        caller to fill in). An :class:`AffineDesign` (matrices of an undamped affine design,
        assembled in bulk by a design study) is searched exactly as its model would be.
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
        if isinstance(model, AffineDesign):
            out["t_max"][i], out["operating"][i] = model.thrust_max, model.operating
            job = _Job.affine(model, n_scan)
            jobs.append(job)
            owner[id(job)] = (i, True)
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
    from ...errors import ModelError, NumericalError

    if isinstance(exc, ModelError):
        return STATUSES.index("invalid"), str(exc)
    text = " ".join(str(exc).split()) or type(exc).__name__
    if isinstance(exc, (NumericalError, np.linalg.LinAlgError, FloatingPointError, ArithmeticError)):
        return STATUSES.index("numerical_failure"), f"{type(exc).__name__}: {text}"
    return STATUSES.index("error"), f"{type(exc).__name__}: {text}"
