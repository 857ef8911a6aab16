"""The result store: a zarr group that xarray opens as the study's Dataset, written chunk by chunk.

Layout (zarr format 3): one array per output plus ``status`` and ``message``, chunked exactly like
the study's chunk plan, with one dimension per grid parameter (or ``sample``); coordinate arrays
for the parameter values; attributes with the study file, the base model, the package version
and timestamps. A sub-group ``progress`` holds one record per chunk (finish time, number of
times computed, seconds), written *after* the chunk's data: a chunk is done only when its record
exists, so a chunk half-written when the process died is simply computed again. zarr writes each
stored chunk to a temporary file and renames it, so a record is never half-written.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import shutil
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ModelError
from ..linear.batch import KINDS, STATUSES
from .evaluate import CODE_OUTPUTS, ChunkResult
from .plan import ChunkPlan
from .schema import OUTPUTS
from .study import Study, describe

__all__ = ["StudyStore", "now_iso", "tidy"]

_FORMAT = "impstab-study-store/1"
_RECORD = ("finished_at", "runs", "seconds", "evaluations")


def now_iso() -> str:
    """The current UTC time, ISO 8601 to the second."""
    return _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat()


def _variable_attrs(name: str) -> dict[str, Any]:
    if name == "status":
        return {
            "long_name": "status of the design",
            "flag_values": list(range(len(STATUSES))),
            "flag_meanings": " ".join(STATUSES),
            "comment": "-1: not computed yet; see 'message' for the reason of a failure",
        }
    if name == "message":
        return {"long_name": "why the design failed (empty when status is ok)"}
    units, text = OUTPUTS[name]
    attrs: dict[str, Any] = {"long_name": text}
    if units:
        attrs["units"] = units
    if name in CODE_OUTPUTS:
        attrs.update(flag_values=list(range(len(KINDS))), flag_meanings=" ".join(KINDS),
                     comment="-1: not available (the design failed or is not computed)")
    return attrs


def _kind(name: str) -> tuple[Any, Any]:
    if name in ("message", "modes"):
        return str, ""
    if name == "status" or name in CODE_OUTPUTS:
        return "i1", -1
    return "f8", np.nan


class StudyStore:
    """A study's zarr store (open with :meth:`create_or_resume`)."""

    def __init__(self, group, plan: ChunkPlan, path: Path | None) -> None:
        self.group = group
        self.plan = plan
        self.path = path
        self._arrays: dict = {}  # the result arrays, opened once
        self._records: np.ndarray | None = None  # the progress records as last read or written
        self._written: dict[int, dict[str, np.ndarray]] = {}  # chunk data written by this object

    # -- creation and resumption -------------------------------------------------------------
    @classmethod
    def create_or_resume(cls, study: Study, plan: ChunkPlan, path: str | os.PathLike[str] | None) -> "StudyStore":
        """Open the store at ``path`` for ``study``, creating it if it does not exist.

        ``path`` None keeps the store in memory. An existing store must hold the same study
        (same study file contents and base model) made by the same impstab version.
        """
        import zarr

        if path is None:
            mem = zarr.storage.MemoryStore()
            _initialise(zarr.open_group(mem, mode="w", zarr_format=3), study, plan)
            _consolidate(mem)
            return cls(zarr.open_group(mem, mode="r+", zarr_format=3), plan, None)
        path = Path(path)
        if path.exists():
            group = _open_existing(path, study)
            _remove_partial_files(path)
            return cls(group, plan, path)
        tmp = path.with_name(f".{path.name}.creating-{os.getpid()}")
        shutil.rmtree(tmp, ignore_errors=True)
        try:
            _initialise(zarr.open_group(str(tmp), mode="w-", zarr_format=3), study, plan)
            _consolidate(str(tmp))
            os.rename(tmp, path)
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)
            raise
        return cls(zarr.open_group(str(path), mode="r+", zarr_format=3), plan, path)

    # -- progress ----------------------------------------------------------------------------
    def records(self) -> np.ndarray:
        """``(n_chunks, 4)`` records: finish time (epoch s, NaN if not done), runs, seconds, evaluations."""
        self._records = self.group["progress/chunks"][...]
        return self._records.copy()

    def done(self) -> np.ndarray:
        """Which chunks are complete."""
        return np.isfinite(self.records()[:, 0])

    def write(self, result: ChunkResult) -> None:
        """Write one chunk's data, then its completion record.

        The number of runs of the chunk comes from the records as read at the start (this
        process is the store's only writer) and kept up to date here.
        """
        for name in (*result.data, "progress/chunks"):
            if name not in self._arrays:
                self._arrays[name] = self.group[name]
        sl = self.plan.slices(result.index)
        for name, arr in result.data.items():
            self._arrays[name][sl] = arr
        if self._records is None:
            self.records()
        runs = self._records[result.index, 1]
        runs = 0.0 if not np.isfinite(runs) else float(runs)
        row = np.array([time.time(), runs + 1.0, result.seconds, float(result.evaluations)])
        self._arrays["progress/chunks"][result.index, :] = row
        self._records[result.index] = row
        self._written[result.index] = result.data

    def begin_run(self, executor: str) -> int:
        """Record the start of a run in the store's history; returns its position."""
        history = json.loads(self.group.attrs.get("history", "[]"))
        history.append({"started": now_iso(), "ended": None, "executor": executor, "chunks_computed": 0})
        self.group.update_attributes({"history": json.dumps(history), "updated": now_iso()})  # one metadata write
        return len(history) - 1

    def end_run(self, run: int, computed: int, interrupted: bool = False) -> None:
        """Close the run's history entry and update the timestamps and the completion flag."""
        attrs = self.group.attrs
        history = json.loads(attrs.get("history", "[]"))
        history[run].update(ended=now_iso(), chunks_computed=computed, interrupted=interrupted)
        records = self.records() if self._records is None else self._records
        done = bool(np.isfinite(records[:, 0]).all())
        new = {"history": json.dumps(history), "updated": now_iso(), "complete": int(done)}
        if done and not attrs.get("completed"):
            new["completed"] = now_iso()
        self.group.update_attributes(new)  # one metadata write

    def open_dataset(self):
        """The results as an xarray Dataset (lazy, backed by the store)."""
        import xarray as xr

        store = self.group.store if self.path is None else str(self.path)
        return tidy(xr.open_zarr(store, consolidated=True, chunks=None))

    def load_dataset(self):
        """The results as an xarray Dataset in memory.

        When this object wrote every chunk of the study (a run from the start), the result
        variables are assembled from the chunks it wrote instead of being read back: the same
        values, without reading every chunk of every variable again (some 0.3 ms each). The
        attributes, coordinates and dtypes come from the store either way.
        """
        ds = self.open_dataset()
        if len(self._written) == self.plan.n_chunks and all(v in self._written[0] for v in ds.data_vars):
            full = {}
            for name in ds.data_vars:
                arr = np.empty(ds[name].shape, dtype=ds[name].dtype)
                for index, data in self._written.items():
                    arr[self.plan.slices(index)] = data[name]
                full[name] = ds[name].copy(data=arr)
            ds = ds.assign(full)
        return ds.load()


def tidy(ds):
    """Parameters as coordinates; outputs in the study file's order, then status and message."""
    params = json.loads(ds.attrs.get("parameters", "[]"))
    ds = ds.set_coords([p for p in params if p in ds.data_vars])
    order = [*json.loads(ds.attrs.get("outputs", "[]")), "status", "message"]
    return ds[[v for v in order if v in ds.data_vars] + [v for v in ds.data_vars if v not in order]]


def _initialise(group, study: Study, plan: ChunkPlan) -> None:
    from .. import __version__

    dims = list(study.dims)
    attrs = {
        "title": f"design study {study.name}",
        "format": _FORMAT,
        "study_name": study.name,
        "study_file": study.study_text,
        "study_path": study.source or "",
        "model_file": study.model_text,
        "model_path": study.model_source or "",
        "model_name": study.model_name,
        "impstab_version": __version__,
        "fingerprint": study.fingerprint,
        "created": now_iso(),
        "updated": now_iso(),
        "completed": "",
        "complete": 0,
        "history": "[]",
        "chunk_shape": list(plan.chunks),
        "n_chunks": plan.n_chunks,
        "kind_legend": json.dumps(dict(enumerate(KINDS))),
        "status_legend": json.dumps(dict(enumerate(STATUSES))),
    }
    attrs.update({k: (json.dumps(v) if isinstance(v, list) else v) for k, v in describe(study).items()})
    group.update_attributes(attrs)  # one metadata write (attrs.update writes once per key)
    for p in study.parameters:
        vals = p.values
        dtype = str if vals.dtype.kind == "U" else vals.dtype
        if study.method == "grid":
            arr = group.create_array(p.name, shape=vals.shape, dtype=dtype, dimension_names=[p.name],
                                     attributes={"long_name": f"model-file value {p.name}"})
        else:
            arr = group.create_array(p.name, shape=vals.shape, dtype=dtype, chunks=plan.chunks,
                                     dimension_names=dims, attributes={"long_name": f"model-file value {p.name}"})
        arr[...] = vals
    if study.method != "grid":
        arr = group.create_array("sample", shape=study.shape, dtype="i8", chunks=plan.chunks, dimension_names=dims)
        arr[...] = np.arange(study.size)
    for name in (*study.outputs, "status", "message"):
        dtype, fill = _kind(name)
        group.create_array(name, shape=study.shape, dtype=dtype, chunks=plan.chunks, fill_value=fill,
                           dimension_names=dims, attributes=_variable_attrs(name))
    prog = group.create_group("progress")
    prog.create_array("chunks", shape=(plan.n_chunks, len(_RECORD)), dtype="f8", chunks=(1, len(_RECORD)),
                      fill_value=np.nan, dimension_names=["chunk", "record"],
                      attributes={"columns": json.dumps(_RECORD), "units": json.dumps(["s since epoch", "1", "s", "1"])})


def _consolidate(store) -> None:
    """Consolidated metadata (fixed once the arrays exist), so that readers open the store fast."""
    import warnings

    import zarr

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "not part of the Zarr format 3 specification (yet)"
        zarr.consolidate_metadata(store)


def _open_existing(path: Path, study: Study):
    import zarr

    from .. import __version__

    try:
        group = zarr.open_group(str(path), mode="r+", zarr_format=3)
        attrs = dict(group.attrs)
    except Exception:  # noqa: BLE001 - any unreadable folder is "not a store"
        attrs = {}
    if attrs.get("format") != _FORMAT:
        raise ModelError("--output", str(path), "exists and is not an impstab study store (give a new path)")
    if attrs.get("fingerprint") != study.fingerprint:
        raise ModelError(
            "--output", str(path),
            "holds a different study (the study file or its base model changed since it was started): "
            "give a new path or remove it",
        )
    if attrs.get("impstab_version") != __version__:
        raise ModelError(
            "--output", str(path),
            f"was started with impstab {attrs.get('impstab_version')}, this is {__version__}: "
            "finish it with that version or start a new store",
        )
    return group


def _remove_partial_files(path: Path) -> None:
    """Temporary files of writes cut short by a killed process (zarr writes then renames)."""
    for p in path.rglob("*.partial"):
        try:
            p.unlink()
        except OSError:
            pass
