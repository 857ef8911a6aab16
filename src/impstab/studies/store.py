"""The result store: a zarr group that xarray opens as the study's Dataset, that proves itself complete.

Layout (zarr format 3, ``impstab-study-store/2``): one array per output plus ``status`` and
``message``, chunked exactly like the study's chunk plan, with one dimension per grid parameter
(or ``sample``); coordinate arrays for the parameter values; attributes with the study file,
the base model, the package version, timestamps and the run history; consolidated metadata in
the root ``zarr.json``; the sub-group ``progress`` with one completion record per chunk
(:mod:`impstab.studies.records`) and the size and CRC-32 of every coordinate file; the run lock
``.impstab-lock`` (:mod:`impstab.studies.lock`).

What proves what:

* **The chunks' data**: a chunk is done when its record exists, and it is trusted only while
  every file of the chunk has the size and CRC-32 its record gives. The record is written after
  the data, by the process that wrote them, so a chunk cut short by a kill has no record.
* **The static part** -- every ``zarr.json`` and the coordinate arrays -- follows from the study
  alone: a run builds it in memory (:func:`~impstab.studies.store_layout.reference_files`), and a
  resume compares the store with it file by file and rewrites what differs. The root
  ``zarr.json`` also carries the CRC-32 of its own fixed attributes and consolidated metadata
  (``integrity``), for readers that have no study.

A resume (:meth:`StudyStore.create_or_resume`) takes the lock, refuses a store with a symbolic
link inside (nothing is ever written outside the store), removes the temporary files of writes
cut short, repairs the static part, and verifies every chunk: a damaged one (a file missing,
truncated or corrupt, or its record damaged) is said and computed again. A reader
(:func:`~impstab.studies.store_read.read_store`) decodes only what it verified: damaged data are refused with the chunks
named, chunks not computed yet are left at their fill values and named.
"""

from __future__ import annotations

import errno
import json
import os
import secrets
import shutil
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ModelError
from ..io import PathError, output_error, owner_tag, remove_stale
from .evaluate import ChunkResult
from .lock import RunLock
from .plan import ChunkPlan
from .records import check_chunk, columns, decode, encode, file_checksum, record_key
from .store_files import FolderFiles, MemoryFiles, StoreFiles, StoreLinkError, scan
from .store_layout import (DYNAMIC, FORMAT, INTEGRITY, attributes, chunk_arrays, count, data_key, fresh_dynamic,
                           history_list, json_doc, names, now_iso, reference_files, root_bytes, root_intact, same_file,
                           static_attrs, tidy)
from .store_read import StoreView, read_store
from .study import Study

__all__ = ["StudyStore", "ChunkWriter", "StoreView", "read_store", "now_iso", "tidy", "chunk_arrays", "data_key",
           "FORMAT"]


def _stale_note(p: Path) -> str:
    return f"removed {p.name}, left by a run that was killed while it made the store"


# -- writing chunks -------------------------------------------------------------------------------
class ChunkWriter:
    """Writes a chunk's data, then its completion record (in the client or on a Dask worker).

    Parameters
    ----------
    files : StoreFiles
        The store's files (symbolic links are refused before each write).
    zarr_store : zarr store
        The same store for zarr (a folder path or the in-memory store).
    plan : ChunkPlan
    arrays : tuple of str
        The arrays of a chunk (:func:`chunk_arrays`).
    """

    def __init__(self, files: StoreFiles, zarr_store, plan: ChunkPlan, arrays: tuple[str, ...]) -> None:
        import zarr

        self.files = files
        self.plan = plan
        self.arrays = arrays
        group = zarr.open_group(zarr_store, mode="r+", zarr_format=3)
        # every chunk file is written, also one of fill values only: a file that is not there is missing
        self._zarr = {n: group[n].with_config({"write_empty_chunks": True}) for n in arrays}

    def write(self, result: ChunkResult, runs: int) -> np.ndarray:
        """Write ``result`` (computed for the ``runs``-th time); return its record (all columns)."""
        index = result.index
        keys = [data_key(n, self.plan, index) for n in self.arrays]
        for key in (*keys, record_key(index)):
            self.files.check(key)
        self.files.remove(record_key(index))  # a chunk computed again is not done until its new record
        sl = self.plan.slices(index)
        for name in self.arrays:
            self._zarr[name][sl] = result.data[name]
        sums = [v for key in keys for v in file_checksum(self.files.read(key))]
        fields = np.array([time.time(), float(runs), result.seconds, float(result.evaluations), float(index), *sums],
                          dtype=np.float64)
        self.files.write(record_key(index), encode(fields))
        return np.append(fields, np.nan)


# -- the store ------------------------------------------------------------------------------------
class StudyStore:
    """A study's zarr store, open for a run (from :meth:`create_or_resume`; :meth:`close` when done).

    Attributes
    ----------
    path : Path or None
        The store folder (None: in memory).
    findings : list of str
        What opening it found and did, one line each (repairs, chunks to compute again, stale
        temporaries removed).
    created : bool
        Whether this run made the store.
    recomputed : list of int
        The chunks found damaged (computed again by this run).
    repaired : list of str
        The metadata and coordinate files rewritten from the study.
    """

    def __init__(self, study: Study, plan: ChunkPlan, files: StoreFiles, zarr_store, path: Path | None,
                 root: dict, static: dict, dynamic: dict, lock: RunLock | None, created: bool) -> None:
        self.study = study
        self.plan = plan
        self.files = files
        self.zarr_store = zarr_store
        self.path = path
        self.arrays = chunk_arrays(study.outputs)
        self._root = root
        self._static = static
        self._dynamic = dynamic
        self.lock = lock
        self.created = created
        self.findings: list[str] = []
        self.recomputed: list[int] = []
        self.repaired: list[str] = []
        self._records = np.full((plan.n_chunks, len(columns(self.arrays))), np.nan)
        self._done = np.zeros(plan.n_chunks, dtype=bool)
        self._runs = np.zeros(plan.n_chunks, dtype=int)
        self._writer: ChunkWriter | None = None
        self._written: dict[int, dict[str, np.ndarray]] = {}
        self.run_id = ""
        self.read_only = False

    # -- opening --------------------------------------------------------------------------------
    @classmethod
    def create_or_resume(cls, study: Study, plan: ChunkPlan, path: str | os.PathLike[str] | None,
                         field: str = "--output") -> "StudyStore":
        """Open the store at ``path`` for ``study`` (creating it if it does not exist) and lock it.

        ``path`` None keeps the store in memory. An existing store must hold the same study
        (same study file contents and base model), made by the same impstab version; it is
        verified and repaired (module docstring) before anything is computed.

        Raises
        ------
        ModelError
            Not a store of this study, another run writes it, a symbolic link inside it, or it
            cannot be written (:class:`impstab.io.OutputError`).
        """
        files_ref, root = reference_files(study, plan)
        if path is None:
            import zarr

            store_dict: dict = {}
            files = MemoryFiles(store_dict)
            for key, data in files_ref.items():
                files.write(key, data)
            static, dynamic = static_attrs(study, plan, now_iso()), fresh_dynamic()
            files.write("zarr.json", root_bytes(root, static, dynamic))
            return cls(study, plan, files, zarr.storage.MemoryStore(store_dict=store_dict), None, root, static,
                       dynamic, None, True)
        path = Path(path)
        if not path.exists() and not path.is_symlink():
            made = cls._create(study, plan, path, field, files_ref, root)
            if made is not None:
                return made
        return cls._resume(study, plan, path, field, files_ref, root)

    @classmethod
    def _create(cls, study, plan, path: Path, field: str, files_ref: dict, root: dict) -> "StudyStore | None":
        """Make the store in a temporary folder beside ``path`` and rename it; None if another run made it first."""
        parent = path.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise output_error(field, path, exc) from None
        found = [_stale_note(p) for p in remove_stale(parent, f".{path.name}.creating-")]
        tmp = parent / f".{path.name}.creating-{owner_tag()}"
        lock = None
        try:
            tmp.mkdir()
            lock = RunLock(tmp, field).acquire()
            files = FolderFiles(tmp, field)
            for key, data in files_ref.items():
                files.write(key, data)
            static, dynamic = static_attrs(study, plan, now_iso()), fresh_dynamic()
            files.write("zarr.json", root_bytes(root, static, dynamic))
            try:
                os.rename(tmp, path)
            except OSError:
                if not path.exists():
                    raise
                lock.release()
                shutil.rmtree(tmp, ignore_errors=True)
                return None  # made by another run in the meantime: resume it
        except BaseException as exc:
            if lock is not None:
                lock.release()
            shutil.rmtree(tmp, ignore_errors=True)
            if isinstance(exc, OSError):
                raise output_error(field, path, exc) from None
            raise
        lock.root = path
        store = cls(study, plan, FolderFiles(path, field), str(path), path, root, static, dynamic, lock, True)
        store.findings = found
        return store

    @classmethod
    def _resume(cls, study, plan, path: Path, field: str, files_ref: dict, root: dict) -> "StudyStore":
        if not path.is_dir():
            raise PathError(field, path, "exists and is not an impstab study store (give a new path)")
        files = FolderFiles(path, field)
        findings = [_stale_note(p) for p in remove_stale(path.parent, f".{path.name}.creating-")]
        try:
            disk_root = json_doc(files.read("zarr.json"))
            progress = json_doc(files.read("progress/zarr.json"))
        except OSError as exc:
            raise PathError(field, path, f"cannot be read: {exc.strerror or exc}") from None
        intact = disk_root is not None and root_intact(disk_root)
        _identify(study, path, field, disk_root, intact, progress)
        try:
            lock = RunLock(path, field).acquire()
        except ModelError as exc:
            if getattr(exc, "errno", None) not in (errno.EROFS, errno.EACCES, errno.EPERM):
                raise
            return cls._read_only(study, plan, path, field, files_ref, root, disk_root, exc)
        try:
            links, partial = scan(path)
            if links:
                raise StoreLinkError(field, str(path), str(links[0]))
            for p in partial:
                try:
                    p.unlink()
                except OSError:
                    pass
            repaired = [key for key, data in files_ref.items() if not same_file(key, files.read(key), data)]
            for key in repaired:
                files.write(key, files_ref[key])
            attrs = attributes(disk_root)
            created = attrs.get("created") if isinstance(attrs.get("created"), str) else now_iso()
            static = ({k: v for k, v in attrs.items() if k not in DYNAMIC} if intact
                      else static_attrs(study, plan, created))
            dynamic = fresh_dynamic()
            history = history_list(attrs.get("history"))
            if history is not None:
                dynamic.update({k: attrs[k] for k in DYNAMIC if k in attrs and k != "history"})
                dynamic["history"] = json.dumps(history)
            root_now = root_bytes(root, static, dynamic)
            if not intact or json_doc(root_now) != disk_root:
                repaired.insert(0, "zarr.json" + ("" if history is not None else " (its run history was lost)"))
                files.write("zarr.json", root_now)
            store = cls(study, plan, files, str(path), path, root, static, dynamic, lock, False)
            store._verify()
        except OSError as exc:
            lock.release()
            raise output_error(field, path, exc, "nothing was computed") from None
        except BaseException:
            lock.release()
            raise
        if partial:
            findings.append(f"removed {count(len(partial), 'temporary file')} of writes cut short")
        if repaired:
            findings.append(f"repaired {count(len(repaired), 'metadata or coordinate file')} from the study: "
                            f"{names(repaired)}")
        store.findings = findings + store.findings
        store.repaired = repaired
        return store

    @classmethod
    def _read_only(cls, study, plan, path: Path, field: str, files_ref: dict, root: dict, disk_root,
                   error: ModelError) -> "StudyStore":
        """A store this process cannot write: usable only if it is complete and intact (a rerun to export)."""
        files = FolderFiles(path, field)
        intact = disk_root is not None and root_intact(disk_root)
        if not intact or any(not same_file(key, files.read(key), data) for key, data in files_ref.items()):
            raise error
        attrs = attributes(disk_root)
        store = cls(study, plan, files, str(path), path, root, {k: v for k, v in attrs.items() if k not in DYNAMIC},
                    {k: attrs[k] for k in DYNAMIC if k in attrs}, None, False)
        store.read_only = True
        store._verify(remove_damaged=False)
        if not store._done.all():
            raise error
        store.findings.append("the store cannot be written (read-only), but it is complete and verified: "
                              "nothing is computed or recorded")
        return store

    def _verify(self, remove_damaged: bool = True) -> None:
        """Check every chunk against its record; a damaged chunk loses its record (computed again)."""
        damaged = []
        n_columns = len(columns(self.arrays))
        for i in range(self.plan.n_chunks):
            record = self.files.read(record_key(i))
            check = check_chunk(i, record, self.arrays, [data_key(n, self.plan, i) for n in self.arrays],
                                self.files.read)
            row = decode(record, n_columns)
            self._runs[i] = int(row[1]) if row is not None else (1 if record is not None else 0)
            self._done[i] = check.state == "done"
            if check.state == "damaged":
                damaged.append(check)
                if remove_damaged:
                    self.files.remove(record_key(i))
        self.recomputed = [c.index for c in damaged]
        if damaged:
            self.findings.append(f"computing {count(len(damaged), 'chunk')} again, whose stored data do not match "
                                 "the completion record: " + names([c.describe() for c in damaged]))

    # -- progress ---------------------------------------------------------------------------------
    def todo(self) -> list[int]:
        """The chunks to compute: those not done (never computed, cut short, or damaged)."""
        return [int(i) for i in np.flatnonzero(~self._done)]

    def done(self) -> np.ndarray:
        """Which chunks are complete (verified when opened, or written by this run)."""
        return self._done.copy()

    def previous_runs(self, index: int) -> int:
        """How often chunk ``index`` had been computed when the store was opened (at least 1 if damaged)."""
        return int(self._runs[index])

    @property
    def writer(self) -> ChunkWriter:
        if self._writer is None:
            self._writer = ChunkWriter(self.files, self.zarr_store, self.plan, self.arrays)
        return self._writer

    def write(self, result: ChunkResult) -> None:
        """Write one chunk's data, then its completion record (in this process)."""
        self.mark_done(result.index, self.writer.write(result, self.previous_runs(result.index) + 1))
        self._written[result.index] = result.data

    def mark_done(self, index: int, record: np.ndarray) -> None:
        """Note a chunk written (here, or by a worker, which sends its record)."""
        self._records[index] = record
        self._done[index] = True

    def records(self) -> np.ndarray:
        """The records written by this run (NaN rows for the others)."""
        return self._records.copy()

    # -- the run history --------------------------------------------------------------------------
    def _write_root(self) -> None:
        if not self.read_only:
            self.files.write("zarr.json", root_bytes(self._root, self._static, self._dynamic))

    def begin_run(self, executor: str) -> int:
        """Record the start of a run in the store's history; returns its position."""
        history = json.loads(self._dynamic["history"])
        self.run_id = secrets.token_hex(8)
        entry: dict[str, Any] = {"started": now_iso(), "ended": None, "executor": executor, "chunks_computed": 0,
                                 "run": self.run_id}
        if self.recomputed:
            entry["recomputed"] = self.recomputed
        if self.repaired:
            entry["repaired"] = self.repaired
        history.append(entry)
        self._dynamic.update(history=json.dumps(history), updated=now_iso())
        self._write_root()
        return len(history) - 1

    def set_executor(self, run: int, executor: str) -> None:
        """Describe where run ``run`` computed (written with the run's end)."""
        history = json.loads(self._dynamic["history"])
        history[run]["executor"] = executor
        self._dynamic["history"] = json.dumps(history)

    def end_run(self, run: int, computed: int, interrupted: bool = False, error: str | None = None) -> None:
        """Close the run's history entry; update the timestamps and the completion flag."""
        history = json.loads(self._dynamic["history"])
        history[run].update(ended=now_iso(), chunks_computed=computed, interrupted=interrupted)
        if error:
            history[run]["error"] = error
        done = bool(self._done.all())
        self._dynamic.update(history=json.dumps(history), updated=now_iso(), complete=int(done))
        if done and not self._dynamic.get("completed"):
            self._dynamic["completed"] = now_iso()
        self._write_root()

    # -- reading ----------------------------------------------------------------------------------
    def open_dataset(self):
        """The verified results as an xarray Dataset in memory (see :func:`read_store`)."""
        return read_store(self.files, str(self.path or "memory"), field="--output").dataset

    def load_dataset(self):
        """The results as an xarray Dataset in memory.

        When this object wrote every chunk of the study (a run from the start), the result
        variables are assembled from the chunks it wrote instead of being read back: the same
        values, without decoding every chunk again. The attributes, coordinates and dtypes come
        from the store either way.
        """
        if len(self._written) != self.plan.n_chunks:
            return self.open_dataset()
        ds = read_store(self.files, str(self.path or "memory"), field="--output", data=False).dataset
        full = {}
        for name in ds.data_vars:
            arr = np.empty(ds[name].shape, dtype=ds[name].dtype)
            for index, data in self._written.items():
                arr[self.plan.slices(index)] = data[name]
            full[name] = ds[name].copy(data=arr)
        return ds.assign(full)

    # -- closing ----------------------------------------------------------------------------------
    def close(self) -> None:
        """Release the run lock."""
        if self.lock is not None:
            self.lock.release()

    def discard(self) -> bool:
        """Remove the store if this run made it and finished no chunk in it (nothing to resume)."""
        self.close()
        if not (self.created and self.path is not None) or self._done.any():
            return False
        if any(self.files.read(record_key(i)) is not None for i in range(self.plan.n_chunks)):
            return False  # a chunk finished by a worker that this process had not heard of yet
        shutil.rmtree(self.path, ignore_errors=True)
        return True

    def __enter__(self) -> "StudyStore":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _identify(study: Study, path: Path, field: str, root, intact: bool, progress) -> None:
    """Refuse anything but a store of this study made by this version (damaged metadata of one is fine)."""
    from .. import __version__

    attrs = attributes(root)
    fmt = attrs.get("format")
    if intact:
        if fmt != FORMAT:
            raise PathError(field, path, "exists and is not an impstab study store (give a new path)")
        if attrs.get("fingerprint") != study.fingerprint:
            raise PathError(field, path,
                             "holds a different study (the study file or its base model changed since it was "
                             "started): give a new path or remove it")
        if attrs.get("impstab_version") != __version__:
            raise PathError(field, path,
                             f"was started with impstab {attrs.get('impstab_version')}, this is {__version__}: "
                             "finish it with that version or start a new store")
        return
    if isinstance(fmt, str) and fmt.startswith("impstab-study-store/") and fmt != FORMAT and INTEGRITY not in attrs:
        raise PathError(field, path, f"was written in an older store format ({fmt}, without checksums): "
                                           "finish it with the impstab version that started it, or start a new store")
    if attrs.get("fingerprint") == study.fingerprint or attributes(progress).get("fingerprint") == study.fingerprint:
        return  # ours, with damaged metadata: repaired from the study
    if root is None and progress is None:
        raise PathError(field, path, "exists and is not an impstab study store (give a new path)")
    raise PathError(field, path, "exists, but its metadata are damaged and do not name this study: "
                                       "give a new path, or remove it to start again")
