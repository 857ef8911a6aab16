"""The layout of a study store: its static part, and root metadata that prove themselves.

The static part -- every ``zarr.json``, the coordinate arrays, the progress group -- follows
from the study alone: :func:`reference_files` builds it in memory with zarr, exactly as a store
must hold it, so that a new store is written from it and a resumed one compared with it file by
file (:mod:`impstab.studies.store`). The root ``zarr.json`` holds the attributes (fixed ones, and
the run-to-run ones in :data:`DYNAMIC`) and zarr's consolidated metadata; its attribute
``integrity`` is the CRC-32 of the fixed attributes and the consolidated metadata, so that a
reader without the study can still tell intact metadata from damaged ones (:func:`root_intact`).
"""

from __future__ import annotations

import datetime as _dt
import json
import zlib
from typing import Any

import numpy as np

from ..linear.batch import KINDS, STATUSES
from .evaluate import CODE_OUTPUTS
from .plan import ChunkPlan
from .records import columns, file_checksum
from .schema import OUTPUTS
from .study import Study, describe

__all__ = ["FORMAT", "DYNAMIC", "INTEGRITY", "now_iso", "chunk_arrays", "data_key", "reference_files", "static_attrs",
           "fresh_dynamic", "root_bytes", "root_intact", "json_doc", "attributes", "same_file", "history_list", "names",
           "count", "tidy"]

FORMAT = "impstab-study-store/2"
#: root attributes that change from run to run (all others are fixed when the store is made)
DYNAMIC = ("updated", "completed", "complete", "history")
INTEGRITY = "integrity"


def now_iso() -> str:
    """The current UTC time, ISO 8601 to the second."""
    return _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat()


def chunk_arrays(outputs) -> tuple[str, ...]:
    """The arrays each chunk of the store holds: the outputs, ``status`` and ``message``."""
    return (*outputs, "status", "message")


def data_key(name: str, plan: ChunkPlan, index: int) -> str:
    """The key of chunk ``index``'s file of array ``name``."""
    pos = np.unravel_index(index, plan.grid)
    return f"{name}/c/" + "/".join(str(int(p)) for p in pos)


def _variable_attrs(name: str, study: Study | None = None) -> dict[str, Any]:
    if name == "status":
        return {
            "long_name": "status of the design",
            "flag_values": list(range(len(STATUSES))),
            "flag_meanings": " ".join(STATUSES),
            "comment": "-1: not computed yet; see 'message' for the reason of a failure",
        }
    if name == "message":
        return {"long_name": "why the design failed (empty when status is ok)"}
    units, text = OUTPUTS[name] if study is None else study.output_info(name)
    attrs: dict[str, Any] = {"long_name": text}
    if units:
        attrs["units"] = units
    if name in CODE_OUTPUTS:
        attrs.update(flag_values=list(range(len(KINDS))), flag_meanings=" ".join(KINDS),
                     comment="-1: not available (the design failed or is not computed)")
    return attrs


def _kind(name: str) -> tuple[Any, Any]:
    if name in ("message", "modes", "bifurcation"):
        return str, ""
    if name == "status" or name in CODE_OUTPUTS:
        return "i1", -1
    return "f8", np.nan


def static_attrs(study: Study, plan: ChunkPlan, created: str) -> dict[str, Any]:
    from .. import __version__

    attrs = {
        "title": f"design study {study.name}",
        "format": FORMAT,
        "study_name": study.name,
        "study_file": study.study_text,
        "study_path": study.source or "",
        "model_file": study.model_text,
        "model_path": study.model_source or "",
        "model_name": study.model_name,
        "impstab_version": __version__,
        "fingerprint": study.fingerprint,
        "created": created,
        "chunk_shape": list(plan.chunks),
        "n_chunks": plan.n_chunks,
        "kind_legend": json.dumps(dict(enumerate(KINDS))),
        "status_legend": json.dumps(dict(enumerate(STATUSES))),
    }
    attrs.update({k: (json.dumps(v) if isinstance(v, list) else v) for k, v in describe(study).items()})
    return attrs


def fresh_dynamic() -> dict[str, Any]:
    return {"updated": now_iso(), "completed": "", "complete": 0, "history": "[]"}


def _canonical(obj) -> bytes:
    return json.dumps(obj, sort_keys=True, separators=(",", ":")).encode()


def _integrity(static: dict, consolidated) -> int:
    return zlib.crc32(_canonical({"attributes": {k: v for k, v in static.items() if k != INTEGRITY},
                                  "consolidated_metadata": consolidated}))


def root_bytes(reference_root: dict, static: dict, dynamic: dict) -> bytes:
    doc = dict(reference_root)
    attrs = {k: v for k, v in static.items() if k != INTEGRITY}
    attrs[INTEGRITY] = _integrity(attrs, doc.get("consolidated_metadata"))
    attrs.update(dynamic)
    doc["attributes"] = attrs
    return json.dumps(doc, indent=2).encode()


def reference_files(study: Study, plan: ChunkPlan) -> tuple[dict[str, bytes], dict]:
    """Every file of the static part as the store must hold it, and the root document.

    The root ``zarr.json`` is not among the files: its attributes are composed per run
    (:func:`_root_bytes`).
    """
    import zarr

    store_dict: dict = {}
    group = zarr.open_group(zarr.storage.MemoryStore(store_dict=store_dict), mode="w", zarr_format=3)
    dims = list(study.dims)
    coords = [p.name for p in study.parameters]
    for p in study.parameters:
        vals = p.values
        dtype = str if vals.dtype.kind == "U" else vals.dtype
        grid = study.method == "grid"
        arr = group.create_array(p.name, shape=vals.shape, dtype=dtype, chunks=vals.shape if grid else plan.chunks,
                                 dimension_names=[p.name] if grid else dims,
                                 attributes={"long_name": f"model-file value {p.name}"})
        arr[...] = vals
    if study.method != "grid":
        coords.append("sample")
        arr = group.create_array("sample", shape=study.shape, dtype="i8", chunks=plan.chunks, dimension_names=dims)
        arr[...] = np.arange(study.size)
    arrays = chunk_arrays(study.outputs)
    for name in arrays:
        dtype, fill = _kind(name)
        group.create_array(name, shape=study.shape, dtype=dtype, chunks=plan.chunks, fill_value=fill,
                           dimension_names=dims, attributes=_variable_attrs(name, study))
    coordinate_files = {k: list(file_checksum(v.to_bytes())) for k, v in store_dict.items()
                        if k.split("/")[0] in coords and not k.endswith("zarr.json")}
    cols = columns(arrays)
    prog = group.create_group("progress", attributes={"fingerprint": study.fingerprint, "arrays": list(arrays),
                                                      "coordinate_files": coordinate_files})
    prog.create_array("chunks", shape=(plan.n_chunks, len(cols)), dtype="f8", chunks=(1, len(cols)),
                      fill_value=np.nan, compressors=None, dimension_names=["chunk", "record"],
                      attributes={"columns": list(cols),
                                  "comment": "one completion record per chunk: see impstab.studies.records"})
    _consolidate(group.store)
    files = {k: v.to_bytes() for k, v in store_dict.items()}
    root = json.loads(files.pop("zarr.json"))
    return files, root


def _consolidate(store) -> None:
    """Consolidated metadata (fixed once the arrays exist), so that readers open the store fast."""
    import warnings

    import zarr

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "not part of the Zarr format 3 specification (yet)"
        zarr.consolidate_metadata(store)


def json_doc(data: bytes | None):
    if data is None:
        return None
    try:
        doc = json.loads(data)
    except (ValueError, UnicodeDecodeError):
        return None
    return doc if isinstance(doc, dict) else None


def attributes(doc) -> dict:
    attrs = doc.get("attributes") if isinstance(doc, dict) else None
    return attrs if isinstance(attrs, dict) else {}


def root_intact(doc) -> bool:
    attrs = attributes(doc)
    static = {k: v for k, v in attrs.items() if k not in DYNAMIC}
    return INTEGRITY in attrs and attrs[INTEGRITY] == _integrity(static, doc.get("consolidated_metadata"))


def same_file(key: str, disk: bytes | None, ref: bytes) -> bool:
    if disk is None:
        return False
    if key.endswith("zarr.json"):
        return json_doc(disk) is not None and json_doc(disk) == json_doc(ref)
    return disk == ref


def history_list(text) -> list | None:
    try:
        history = json.loads(text) if isinstance(text, str) else None
    except ValueError:
        return None
    return history if isinstance(history, list) and all(isinstance(h, dict) for h in history) else None


def names(items: list[str], limit: int = 6) -> str:
    shown = ", ".join(items[:limit])
    return shown + (f" and {len(items) - limit} more" if len(items) > limit else "")


def count(n: int, what: str) -> str:
    return f"{n} {what}" + ("" if n == 1 else "s")


def tidy(ds):
    """Parameters as coordinates; outputs in the study file's order, then status and message."""
    params = json.loads(ds.attrs.get("parameters", "[]"))
    ds = ds.set_coords([p for p in params if p in ds.data_vars])
    ds.attrs.pop(INTEGRITY, None)
    order = [*json.loads(ds.attrs.get("outputs", "[]")), "status", "message"]
    return ds[[v for v in order if v in ds.data_vars] + [v for v in ds.data_vars if v not in order]]
