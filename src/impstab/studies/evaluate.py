"""Evaluation of one chunk of designs: variant model files -> models -> batched critical thrust.

:func:`evaluate_chunk` is the unit of work, in process or on a Dask worker. Its input
(:class:`ChunkTask`) holds only the base model, the parameter paths and this chunk's parameter
values; its output (:class:`ChunkResult`) only this chunk's results. Every variant is validated
like a model file (:func:`impstab.model.model_from_dict`); a variant that breaks a rule, or whose
analysis fails, gets a status and a message and the others go on.
"""

from __future__ import annotations

import gc
import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from .._jit import require_compiled
from ..errors import ModelError
from ..linear.batch import STATUSES, critical_thrust_batch
from .bulk import assemble_bulk, variant_model
from .isolation import IsolationSettings, isolation_outputs
from .paths import variant_dict
from .schema import ISOLATION_OUTPUTS, POSTCRITICAL_OUTPUTS

__all__ = ["ChunkTask", "ChunkResult", "evaluate_chunk", "variant_dict", "CODE_OUTPUTS"]

#: outputs stored as int8 codes into :data:`impstab.linear.batch.KINDS`
CODE_OUTPUTS = ("kind", "undamped_kind")


@dataclass(frozen=True, eq=False)
class ChunkTask:
    """Everything a worker needs for one chunk (small: no other chunk's data).

    Attributes
    ----------
    index : int
        Chunk number in the plan.
    block : tuple of int
        Shape of the chunk's block of the design array.
    base_model : dict
        The parsed base model file.
    segments : tuple
        Each parameter's path as keys and indices.
    columns : tuple of arrays
        Each parameter's value at each design of the chunk (flattened, C order).
    outputs : tuple of str
    model_name : str
    """

    index: int
    block: tuple[int, ...]
    base_model: dict
    segments: tuple[tuple[str | int, ...], ...]
    columns: tuple[NDArray, ...]
    outputs: tuple[str, ...]
    model_name: str = "model"
    isolation: IsolationSettings | None = None


@dataclass(frozen=True, eq=False)
class ChunkResult:
    """Results of one chunk: each output, the status codes and messages, as block-shaped arrays."""

    index: int
    data: dict[str, NDArray] = field(default_factory=dict)
    seconds: float = 0.0
    evaluations: int = 0

    @property
    def size(self) -> int:
        return int(self.data["status"].size)


def evaluate_chunk(task: ChunkTask) -> ChunkResult:
    """Critical thrust (and the other outputs) of every design in the chunk.

    The cyclic garbage collector is paused while the chunk is computed: a chunk makes some
    10^4 short-lived objects (freed by reference counting as usual), which would otherwise set
    off full collections over every object of the process -- on a Dask worker a quarter of the
    chunk's time. It is switched back on (if it was on) when the chunk ends or fails.

    Parameters
    ----------
    task : ChunkTask

    Returns
    -------
    ChunkResult
        Arrays of shape ``task.block``; ``status`` codes index :data:`impstab.linear.batch.STATUSES`.
    """
    require_compiled()  # a chunk is many designs: the compiled kernels from its first one
    enabled = gc.isenabled()
    gc.disable()
    try:
        return _evaluate(task)
    finally:
        if enabled:
            gc.enable()


def _evaluate(task: ChunkTask) -> ChunkResult:
    """The body of :func:`evaluate_chunk`."""
    t0 = time.perf_counter()
    n = len(task.columns[0]) if task.columns else 1
    bulk = assemble_bulk(task.base_model, task.segments, task.columns, task.model_name)
    in_bulk = np.zeros(n, dtype=bool)
    if bulk is not None:
        in_bulk[bulk.stack.rows] = True
    models: list = [None] * n
    errors: dict[int, str] = {}
    for j in np.flatnonzero(~in_bulk).tolist():
        try:
            models[j] = _variant(task, j)
        except ModelError as exc:
            errors[j] = str(exc)
        except Exception as exc:  # noqa: BLE001 - a variant never stops the study
            errors[j] = f"{type(exc).__name__}: {exc}"
    res = critical_thrust_batch(models, affine=None if bulk is None else bulk.stack)
    status = res.status.copy()
    message = list(res.message)
    for j, text in errors.items():
        status[j] = STATUSES.index("invalid")
        message[j] = text
    failed = status != 0
    values = {
        "critical_thrust": res.thrust,
        "frequency_hz": res.frequency_hz,
        "omega": res.omega,
        "margin": res.margin,
        "undamped_critical_thrust": res.undamped_thrust,
        "practical_critical_thrust": res.practical_thrust,
        "practical_margin": res.practical_margin,
        "thrust_max": res.thrust_max,
        "operating_thrust": res.operating,
        "kind": res.kind,
        "undamped_kind": res.undamped_kind,
    }
    iso_names = tuple(n for n in task.outputs if n in ISOLATION_OUTPUTS
                      or (task.isolation is not None and any(p.name == n for p in task.isolation.at)))
    postcritical = any(name in POSTCRITICAL_OUTPUTS for name in task.outputs)
    if iso_names or postcritical:
        # the designs assembled in bulk as models too: these outputs need the model's view
        models = [_variant(task, j) if in_bulk[j] else m for j, m in enumerate(models)]
    if iso_names:
        iso, iso_messages = isolation_outputs(models, task.isolation, iso_names)
        values.update(iso)
        for j, text in iso_messages.items():
            if status[j] == 0:
                status[j] = STATUSES.index("numerical_failure")
                message[j] = text
        failed = status != 0
    if postcritical:
        values.update(_postcritical(models, res, failed, message, "fold_thrust" in task.outputs))
    data: dict[str, NDArray] = {}
    for name in task.outputs:
        if name == "bifurcation":
            arr = np.array(["" if failed[j] else values[name][j] for j in range(n)], dtype=np.str_)
        elif name == "modes":
            arr = np.array(["" if failed[j] else res.modes[j] for j in range(n)], dtype=np.str_)
        elif name in CODE_OUTPUTS:
            arr = np.where(failed, -1, values[name]).astype(np.int8)
        else:
            arr = np.where(failed, np.nan, values[name]).astype(np.float64)
        data[name] = arr.reshape(task.block)
    data["status"] = status.astype(np.int8).reshape(task.block)
    data["message"] = np.array(message, dtype=np.str_).reshape(task.block)
    return ChunkResult(task.index, data, time.perf_counter() - t0, res.evaluations)


def _variant(task: ChunkTask, j: int):
    """The model of design ``j`` of the chunk, from its variant model file (raises ``ModelError``)."""
    return variant_model(task.base_model, task.segments, task.columns, j, name=task.model_name)


def _postcritical(models, res, failed, message, branch: bool) -> dict[str, object]:
    """``lyapunov_coefficient``, ``bifurcation`` and ``fold_thrust`` of each design, by the
    post-critical analysis (:func:`impstab.postcritical.propulsor_postcritical`) from the onset the
    batch found: the Hopf analysis (a fraction of a second per design), and with ``branch`` the
    branch of cycles for the fold (seconds per design). A design whose analysis fails keeps its
    linear results; the message says why."""
    from types import SimpleNamespace

    from ..errors import NumericalError
    from ..linear.batch import KINDS
    from ..postcritical import propulsor_postcritical

    n = len(models)
    l1 = np.full(n, np.nan)
    fold = np.full(n, np.nan)
    label = [""] * n
    for j, model in enumerate(models):
        if failed[j] or model is None:
            continue
        kind = KINDS[int(res.kind[j])]
        if kind == "none":
            label[j] = "none"
            continue
        onset = SimpleNamespace(thrust=float(res.thrust[j]), kind=kind, omega=float(res.omega[j]),
                                linearization=model.analysis.linearization)
        try:
            pc = propulsor_postcritical(model, thrust_max=float(res.thrust_max[j]), critical=onset, branch=branch,
                                        max_points=40)
        except (NumericalError, ModelError, np.linalg.LinAlgError) as exc:
            message[j] = f"postcritical: {exc}"
            continue
        label[j] = pc.bifurcation or "none"
        l1[j] = np.nan if pc.lyapunov_coefficient is None else pc.lyapunov_coefficient
        fold[j] = np.nan if pc.fold_thrust is None else pc.fold_thrust
    return {"lyapunov_coefficient": l1, "bifurcation": label, "fold_thrust": fold}

