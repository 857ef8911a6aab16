"""Entry point: critical thrust of many models at once, in one call of the stability engine."""

from __future__ import annotations

from typing import Sequence

import numpy as np
from numpy.typing import NDArray

from ...model.model import DOF_NAMES, Model
from ..critical_thrust import PARTICIPATION_THRESHOLD, _body_part, _modes
from ..engine import Problem, StackOutcome, second_order_problem, solve, solve_affine
from ..engine.problems import mass_solve
from ..linearize import ModelFamily
from ..practical import practical_onset, practical_problem
from .results import KINDS, STATUSES, AffineDesign, AffineStack, BatchCriticalThrust

Array = NDArray[np.float64]


def _single(model: Model) -> tuple:
    """One design through :func:`critical_thrust` itself (compressible fluid: frequency iteration)."""
    from ..critical_thrust import critical_thrust

    r = critical_thrust(model)
    return (r.thrust, r.kind, r.omega, r.participation, r.warnings), (r.undamped_thrust, r.undamped_kind), r.practical_thrust


def _affine_stack(stack: AffineStack, n_scan: int, vectorized: bool):
    """The undamped problems ``M^-1 K0 + T M^-1 K1`` of designs given by their matrices, solved at once."""
    a0, a1 = np.moveaxis(mass_solve(stack.mass, np.stack([stack.k0, stack.k1], axis=1)), 1, 0)
    weights = np.diagonal(stack.mass, axis1=1, axis2=2)
    t_max = np.asarray(stack.thrust_max, dtype=float)
    if vectorized:
        return solve_affine(a0, a1, weights, t_max, n_scan=n_scan)
    parts = [solve_affine(a0[i:i + 1], a1[i:i + 1], weights[i:i + 1], t_max[i:i + 1], n_scan=n_scan)
             for i in range(len(stack))]
    return _joined(parts)


def _affine_designs(models: Sequence, given: AffineStack | None) -> AffineStack | None:
    """One stack of every design given by its matrices: ``given`` and the :class:`AffineDesign` entries."""
    listed = [i for i, m in enumerate(models) if isinstance(m, AffineDesign)]
    if not listed:
        return given
    own = AffineStack.of(listed, [models[i] for i in listed])
    return own if given is None else AffineStack.joined([given, own])


def _joined(parts: list[StackOutcome]) -> StackOutcome:
    """Stack outcomes of consecutive parts as one."""
    arrays = {f: np.concatenate([getattr(r, f) for r in parts])
              for f in ("load", "kind", "omega", "participation", "evaluations", "decompositions", "pairs")}
    return StackOutcome(warnings=[w for r in parts for w in r.warnings], **arrays)


def _mode_names(participation: Array) -> list[str]:
    """The dofs with at least 5 % of the kinetic energy, comma-separated, for each row."""
    bits = (participation >= PARTICIPATION_THRESHOLD) @ (1 << np.arange(participation.shape[-1]))
    names = {b: ",".join(n for i, n in enumerate(DOF_NAMES) if b >> i & 1) for b in np.unique(bits).tolist()}
    return [names[b] for b in bits.tolist()]


def critical_thrust_batch(
    models: Sequence[Model | AffineDesign | None], *, affine: AffineStack | None = None, n_scan: int = 64,
    chunk: int = 16, vectorized: bool = True,
) -> BatchCriticalThrust:
    """Critical thrust of every model, as :func:`impstab.critical_thrust` gives it for one.

    Parameters
    ----------
    models : sequence of Model, AffineDesign or None
        The designs; None marks a design to skip (status ``"invalid"``, empty message, for the
        caller to fill in). An :class:`AffineDesign` (matrices of an undamped affine design,
        assembled in bulk by a design study) is searched exactly as its model would be.
    affine : AffineStack, optional
        More designs given by their matrices, stacked, at positions ``affine.rows`` of the batch
        (the entries of ``models`` there are None): a chunk of a design study assembled in bulk,
        with no object per design.
    n_scan : int
        Scan intervals.
    chunk : int
        Scan points per evaluation of a design whose linearization is not affine in the thrust.
    vectorized : bool
        Solve all designs in one call of the engine (default), or each in a call of its own (the
        same engine, a stack of one: for checks).

    Returns
    -------
    BatchCriticalThrust
        A design with compressible fluid loading goes through :func:`impstab.critical_thrust`
        itself (its coefficients follow the onset frequency), and so does one with viscoelastic
        mounts (the augmented first-order system, and its onset checked on the exact laws). A value located only to the
        classification tolerance has status ``"ok"`` and the warning as its message.
    """
    n = len(models)
    out = {k: np.full(n, np.nan) for k in ("thrust", "omega", "undamped", "t_max", "operating", "practical")}
    kind, ukind = np.full(n, -1, dtype=np.int8), np.full(n, -1, dtype=np.int8)
    status = np.full(n, STATUSES.index("invalid"), dtype=np.int8)
    message, modes = [""] * n, [""] * n
    problems: list[Problem] = []
    owner: list[tuple[int, bool | str]] = []
    bases: dict[int, Problem] = {}
    done: dict[int, tuple] = {}
    affine_evaluations = decompositions = pairs = 0
    given = _affine_designs(models, affine)
    if given is not None and len(given):
        out["t_max"][given.rows], out["operating"][given.rows] = given.thrust_max, given.operating
        rows, stack = given.rows, None
        try:
            stack = _affine_stack(given, n_scan, vectorized)
        except np.linalg.LinAlgError:  # a singular mass somewhere: design by design
            kept, parts = [], []
            for k, i in enumerate(given.rows.tolist()):
                try:
                    parts.append(_affine_stack(given.take(slice(k, k + 1)), n_scan, True))
                    kept.append(i)
                except Exception as exc:  # noqa: BLE001 - reported per design
                    status[i], message[i] = _failure(exc)
            rows = np.array(kept, dtype=np.intp)
            if parts:
                stack = _joined(parts)
        if stack is not None:
            out["thrust"][rows], out["omega"][rows], kind[rows] = stack.load, stack.omega, stack.kind
            out["undamped"][rows], ukind[rows] = stack.load, stack.kind
            status[rows] = 0
            for i, names, warn in zip(rows.tolist(), _mode_names(stack.participation), stack.warnings):
                modes[i], message[i] = names, "; ".join(warn)
            affine_evaluations = int(stack.evaluations.sum())
            decompositions, pairs = int(stack.decompositions.sum()), int(stack.pairs.sum())
    for i, model in enumerate(models):
        if model is None or isinstance(model, AffineDesign):
            continue
        out["t_max"][i] = t_max = float(model.analysis.thrust_max)
        out["operating"][i] = np.nan if model.thrust.operating is None else float(model.thrust.operating)
        try:
            if model.fluid.compressible or model.is_viscoelastic:
                # frequency iteration / the augmented system and its check on the exact law
                done[i] = _single(model)
                continue
            built = [(second_order_problem(ModelFamily(model, None, damped=True), t_max, n_scan=n_scan), True)]
            if model.is_damped:
                built.append((second_order_problem(ModelFamily(model, None, damped=False), t_max, n_scan=n_scan), False))
            zeta = model.analysis.min_damping_ratio
            if zeta is not None:
                bases[i], turned = practical_problem(ModelFamily(model, None, damped=True), t_max, zeta, n_scan=n_scan)
                built.append((turned, "practical"))
        except Exception as exc:  # noqa: BLE001 - reported per design
            status[i], message[i] = _failure(exc)
            continue
        for problem, damped in built:
            problems.append(problem)
            owner.append((i, damped))
    if vectorized:
        outcomes = solve(problems, chunk=chunk) if problems else []
    else:
        outcomes = [solve([p], chunk=chunk)[0] for p in problems]
    by_design: dict[int, dict[bool | str, object]] = {}
    for (i, damped), res in zip(owner, outcomes):
        by_design.setdefault(i, {})[damped] = res
    practical: dict[int, float | None] = {}
    for i, pair in by_design.items():
        err = next((r.error for r in pair.values() if r.error is not None), None)
        if err is not None:
            status[i], message[i] = _failure(err)
            continue
        if "practical" in pair:
            zeta = models[i].analysis.min_damping_ratio
            try:
                practical[i] = practical_onset(bases[i], pair["practical"], zeta).load
            except Exception as exc:  # noqa: BLE001 - reported per design
                status[i], message[i] = _failure(exc)
                continue
        r = pair[True]
        res = (r.load, r.kind, r.omega, r.participation, r.warnings)
        und = None
        if False in pair:
            u = pair[False]
            und = (u.load, u.kind)
            res = (*res[:4], res[4] + tuple(f"undamped companion: {w}" for w in u.warnings))
        done[i] = (res, und, practical.get(i))
    for i, (res, und, prac) in done.items():
        p, k, omega, part, warn = res
        status[i], message[i] = 0, "; ".join(warn)
        out["thrust"][i] = np.nan if p is None else p
        out["omega"][i] = np.nan if omega is None else omega
        kind[i], modes[i] = KINDS.index(k), ",".join(_modes(_body_part(None, part)[1]))
        up, uk = (p, k) if und is None else und
        out["undamped"][i], ukind[i] = (np.nan if up is None else up), KINDS.index(uk)
        out["practical"][i] = np.nan if prac is None else prac
    evaluations = sum(r.evaluations for r in outcomes) + affine_evaluations
    return BatchCriticalThrust(
        out["thrust"], kind, out["omega"], out["undamped"], ukind, out["t_max"], out["operating"],
        modes, status, message, out["practical"], evaluations, decompositions, pairs,
    )


def _failure(exc: BaseException) -> tuple[int, str]:
    """Status code and one-line message of a design whose analysis raised."""
    from ...errors import ModelError, NumericalError

    if isinstance(exc, ModelError):
        return STATUSES.index("invalid"), str(exc)
    text = " ".join(str(exc).split()) or type(exc).__name__
    if isinstance(exc, (NumericalError, np.linalg.LinAlgError, FloatingPointError, ArithmeticError)):
        return STATUSES.index("numerical_failure"), f"{type(exc).__name__}: {text}"
    return STATUSES.index("error"), f"{type(exc).__name__}: {text}"
