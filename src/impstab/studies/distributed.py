"""Studies on ``dask.distributed``: the workers compute and write their own chunks; this process schedules.

**Write path.** Each task computes a few consecutive chunks (:func:`task_groups`) and, on its
worker, writes each of them into the store as soon as it is computed: the chunk's arrays
(region writes: a chunk is exactly one zarr chunk of every array, so no two tasks ever write the
same file), then the chunk's completion record, with the same
:class:`~impstab.studies.store.ChunkWriter` an in-process run uses. The task returns only the
records (a few hundred bytes each), which this process notes; it reads the store once,
verified, at the end. A worker killed while it writes leaves a chunk without a record: Dask
gives the task to another worker, which writes its chunks whole, and a rerun after a killed
client computes what has no record. Before the first task, every worker shows that it sees this
run's store (its study and the run's id in the history); where one does not (a cluster without
a shared file system), the workers send the chunks' data back and this process writes them.

**Hygiene.** Local worker processes ignore SIGINT, so a Ctrl-C in the terminal reaches only this
process, which cancels the tasks and shuts the cluster down without Dask's log lines; a
scheduler address that does not answer is refused before anything is written.
"""

from __future__ import annotations

import contextlib
import logging
import signal
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import ModelError
from .evaluate import ChunkTask, evaluate_chunk
from .interrupts import interrupt_held
from .plan import ChunkPlan

__all__ = ["local_cluster", "connect", "start_local", "run_on_dask", "Session", "StoreTarget", "run_chunks",
           "task_groups", "ClusterStart", "CONNECT_TIMEOUT", "TASKS_PER_WORKER"]

#: seconds to wait for a scheduler to answer
CONNECT_TIMEOUT = 10
#: Dask tasks per worker (each a group of consecutive chunks; see :func:`task_groups`)
TASKS_PER_WORKER = 16

#: Dask settings of the clusters started here (see :func:`local_cluster`)
_QUIET_CLUSTER = {
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.scheduler.worker-saturation": "inf",
}
_LOGGERS = ("distributed", "tornado", "asyncio", "bokeh")


@contextlib.contextmanager
def _silent(interrupt_after: bool = False):
    """Dask's loggers off while a cluster starts or is torn down, and Ctrl-C held back.

    A SIGINT in the block is noted instead of breaking Dask's start or shutdown half-way
    (which prints tracebacks from its threads); with ``interrupt_after`` it is raised as
    KeyboardInterrupt when the block has ended, else it is dropped (a run that ends anyway).
    """
    levels = {n: logging.getLogger(n).level for n in _LOGGERS}
    for n in _LOGGERS:
        logging.getLogger(n).setLevel(logging.CRITICAL + 1)
    try:
        with interrupt_held(interrupt_after):
            yield
    finally:
        for n, level in levels.items():
            logging.getLogger(n).setLevel(level)


def _ignore_interrupt() -> None:
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


def _interrupt_plugin():
    from distributed import WorkerPlugin

    class IgnoreInterrupt(WorkerPlugin):
        """Worker processes of a local cluster leave Ctrl-C to their client."""

        name = "impstab-ignore-sigint"

        def setup(self, worker) -> None:
            _ignore_interrupt()

    return IgnoreInterrupt()


def local_cluster(n_workers: int, **kwargs):
    """A ``dask.distributed.LocalCluster`` of single-threaded worker processes for studies.

    Dask's nannies start workers with ``MALLOC_TRIM_THRESHOLD_=65536``; setting it turns off
    glibc's adaptive mmap threshold, so that every temporary array above 128 kB is mapped and
    unmapped anew and its pages faulted in again: a chunk of designs then takes 1.5x as long.
    The workers started here go without it (the batched engine's temporaries are freed at the
    end of each chunk). They also go without Dask's background work that a study does not
    use: the statistical profiler that samples each worker's thread every 10 ms (some 4 % of
    a worker's time), the 20 ms event-loop tick (it only warns of a blocked loop) and the
    0.5 s system monitor (the dashboard's CPU and memory plots, every 2 s here). On two cores
    that background took a tenth of a core. The workers are forked from a server process that
    has loaded and run the study code once (:mod:`impstab.studies.worker_preload`), and they
    ignore SIGINT (:func:`_start_fork_server`): Ctrl-C is the client's to handle. Their log
    lines are off below CRITICAL (a failed task reaches the client as its exception; the
    shutdown races of heartbeats are noise). Other keyword arguments go to ``LocalCluster``.
    """
    import dask
    from distributed import LocalCluster

    kw = dict(threads_per_worker=1, processes=True, silence_logs=logging.CRITICAL)
    kw.update(kwargs)
    if kw.get("dashboard_address", ":8787") is None:  # no dashboard: Dask's HTTP routes on a free port, not 8787
        kw["scheduler_kwargs"] = {"dashboard": False, "dashboard_address": ":0", **kw.get("scheduler_kwargs", {})}
    with dask.config.set({**_QUIET_CLUSTER, **_fork_server()}):
        return LocalCluster(n_workers=n_workers, **kw)


_PRELOAD = ["distributed", "impstab.studies.distributed", "impstab.studies.worker_preload"]


def _fork_server() -> dict:
    """Dask settings that fork the workers from a server with the study code loaded and run once.

    See :mod:`impstab.studies.worker_preload`; where the platform has no ``forkserver``,
    nothing (the workers are spawned as Dask does by default).
    """
    import multiprocessing

    if "forkserver" not in multiprocessing.get_all_start_methods():
        return {}
    settings = {"distributed.worker.multiprocessing-method": "forkserver"}
    import dask
    from distributed.utils import get_mp_context

    with dask.config.set(settings):
        ctx = get_mp_context()  # Dask names its own modules to preload on first use ...
    ctx.set_forkserver_preload(_PRELOAD)  # ... and these take their place
    _start_fork_server()
    return settings


def _start_fork_server() -> None:
    """Start the fork server now, ignoring SIGINT: it passes that on to every worker it forks.

    A Ctrl-C in a terminal goes to every process of the foreground group: each worker would
    stop with a traceback of its own. Ignored SIGINT survives the start of a new program, and
    the server gives its workers the disposition it had after its preloads. The window in
    which this process ignores SIGINT itself is the start of one process (milliseconds).
    """
    from multiprocessing import forkserver

    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        forkserver.ensure_running()
    finally:
        if main:
            signal.signal(signal.SIGINT, previous)


class Session:
    """A Dask client and what was started for it (closed quietly by :meth:`close`)."""

    def __init__(self, client, owned: list) -> None:
        self.client = client
        self.owned = owned

    def close(self) -> None:
        with _silent():
            for obj in self.owned:
                with contextlib.suppress(Exception):
                    obj.close()
        self.owned = []


def connect(address: str) -> Session:
    """A client of the scheduler at ``address``; a one-line ModelError if none answers there."""
    from distributed import Client

    text = str(address).strip()
    if not text or any(c.isspace() for c in text):
        raise ModelError("--scheduler", address, "must be a Dask scheduler address such as tcp://10.0.0.5:8786")
    try:
        with _silent():
            client = Client(text, timeout=f"{CONNECT_TIMEOUT}s")
    except Exception as exc:  # noqa: BLE001 - any failure to connect is reported in one line
        reason = (str(exc).splitlines() or [type(exc).__name__])[0][:160]
        if isinstance(exc, (OSError, TimeoutError)) and "unknown address scheme" not in reason:
            raise ModelError("--scheduler", address, f"no Dask scheduler answered there within {CONNECT_TIMEOUT} s "
                                                     f"({reason})") from None
        raise ModelError("--scheduler", address, f"is not the address of a Dask scheduler ({reason})") from None
    return Session(client, [client])


def start_local(workers: int) -> Session:
    """A local cluster of ``workers`` processes and its client."""
    from distributed import Client

    dashboard = ":0"  # a free port: the dashboard with bokeh, else Dask's HTTP routes (never the busy 8787)
    owned: list = []
    try:
        with _silent(interrupt_after=True):
            owned.append(local_cluster(workers, dashboard_address=dashboard))
            owned.insert(0, Client(owned[0]))
            with contextlib.suppress(Exception):
                owned[0].register_plugin(_interrupt_plugin())  # workers spawned, not forked, ignore Ctrl-C too
    except BaseException:
        Session(None, owned).close()
        raise
    return Session(owned[0], owned)


class ClusterStart:
    """A local cluster started in a background thread, so that this process computes meanwhile.

    Starting ``workers`` processes takes seconds (the fork server imports and warms up the study
    code first); a run computes its first chunks in process in that time and hands the rest to
    the workers once :meth:`ready`. The fork server itself is started here, in the calling
    (main) thread, so that its workers ignore SIGINT.
    """

    def __init__(self, workers: int) -> None:
        _fork_server()
        self.session: Session | None = None
        self.error: BaseException | None = None
        self._thread = threading.Thread(target=self._start, args=(workers,), name="impstab-cluster-start",
                                        daemon=True)
        self._thread.start()

    def _start(self, workers: int) -> None:
        try:
            self.session = start_local(workers)
        except BaseException as exc:  # noqa: BLE001 - reported by the run, which then goes on in process
            self.error = exc

    def ready(self) -> bool:
        """Whether the start has ended (with a cluster, or with :attr:`error`)."""
        return not self._thread.is_alive()

    def wait(self) -> "Session | None":
        """The started session (None if the start failed), once the start has ended."""
        with _silent():
            self._thread.join()
        return self.session

    def close(self) -> None:
        """Wait for the start to end, then shut the cluster down."""
        if self.wait() is not None:
            self.session.close()


# -- the tasks ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class StoreTarget:
    """Where the workers write: the store folder, its study, this run, the chunk layout."""

    path: str
    fingerprint: str
    run_id: str
    plan: ChunkPlan
    arrays: tuple[str, ...]


@dataclass(frozen=True)
class ChunkDone:
    """A chunk a worker wrote: its number and its completion record."""

    index: int
    record: np.ndarray


_WRITERS: dict = {}


def _store_is_this_run(target: StoreTarget) -> bool:
    import json

    from .store_files import FolderFiles
    from .store_layout import attributes, json_doc

    attrs = attributes(json_doc(FolderFiles(Path(target.path)).read("zarr.json")))
    try:
        history = json.loads(attrs.get("history", "[]"))
    except ValueError:
        return False
    return attrs.get("fingerprint") == target.fingerprint and bool(history) and history[-1].get("run") == target.run_id


def sees_store(target: StoreTarget) -> bool:
    """Whether this worker sees the store of this run (run on every worker before the first task)."""
    try:
        return _store_is_this_run(target)
    except Exception:  # noqa: BLE001 - cannot see it
        return False


def _writer(target: StoreTarget):
    from .store import ChunkWriter
    from .store_files import FolderFiles

    key = (target.path, target.run_id)
    writer = _WRITERS.get(key)
    if writer is None:
        if not _store_is_this_run(target):
            raise ModelError("--output", target.path, "is not the store of this run on this worker "
                                                      "(the workers need the store on a shared file system)")
        _WRITERS.clear()
        writer = _WRITERS[key] = ChunkWriter(FolderFiles(Path(target.path)), target.path, target.plan, target.arrays)
    return writer


def run_chunks(tasks: list[ChunkTask], target: StoreTarget | None, runs: list[int]) -> list:
    """One Dask task: compute some consecutive chunks, one after the other.

    With a ``target`` each chunk is written there (data, then its record) as soon as it is
    computed, and the records are returned; without, the chunks' results are returned.
    """
    out = []
    for task, n in zip(tasks, runs):
        result = evaluate_chunk(task)
        out.append(result if target is None else ChunkDone(task.index, _writer(target).write(result, n)))
    return out


def task_groups(todo: list[int], n_workers: int) -> list[list[int]]:
    """The chunks ``todo`` in consecutive groups, one Dask task each, :data:`TASKS_PER_WORKER` per worker.

    Each task costs this process some 15 ms of scheduling (two cores, a loaded machine): with
    chunks of 1024 designs (about 0.1 s of work) that was a seventh of the workers' time. Groups
    of several chunks make it small, and 16 tasks per worker still leave the last ones short
    enough that no worker waits long for another at the end.
    """
    size = max(1, len(todo) // (TASKS_PER_WORKER * max(1, n_workers)))
    return [todo[i:i + size] for i in range(0, len(todo), size)]


def _worker_version() -> str:
    try:
        from impstab import __version__

        return __version__
    except Exception as exc:  # noqa: BLE001 - reported to the user
        return f"cannot import impstab ({type(exc).__name__}: {exc})"


def run_on_dask(client, st, study, plan: ChunkPlan, todo: list[int], done: Callable[[int], None],
                progress: bool) -> str:
    """Compute the chunks ``todo`` of the open store ``st`` on ``client``'s cluster; say who wrote them."""
    from distributed import as_completed

    from .. import __version__
    from .execute import chunk_task

    for worker, version in client.run(_worker_version).items():
        if version != __version__:
            raise ModelError("--scheduler", worker, f"this worker has impstab {version}, the client {__version__}: "
                                                    "install the same version everywhere")
    target = None
    how = "this process keeps the results in memory"
    if st.path is not None:
        target = StoreTarget(str(Path(st.path).resolve()), study.fingerprint, st.run_id, plan, st.arrays)
        seen = client.run(sees_store, target)
        if seen and all(seen.values()):
            how = "the workers write the chunks"
        else:
            target = None
            how = "this process writes the chunks: the workers cannot see the store folder"
    prefix = f"impstab-chunk-{study.fingerprint[:12]}-{st.run_id}"
    groups = task_groups(todo, len(client.scheduler_info().get("workers", {})))
    futures = [client.submit(run_chunks, [chunk_task(study, plan, i) for i in group], target,
                             [st.previous_runs(i) + 1 for i in group], key=f"{prefix}-{group[0]}-{group[-1]}",
                             pure=False, retries=2) for group in groups]
    bar = _dask_progress(client, futures) if progress else None
    pending = as_completed(futures)
    held: list = []
    try:
        for fut in pending:
            for out in fut.result():
                if isinstance(out, ChunkDone):
                    st.mark_done(out.index, out.record)
                else:
                    st.write(out)
                done(int(out.index))
            # results are released once noted, after Dask's bar has seen every task
            held.append(fut)
            if bar is None or hasattr(bar, "_last_response"):
                for f in held:
                    f.release()
                held.clear()
    except BaseException:
        with _silent(), contextlib.suppress(Exception):
            client.cancel(futures)
        raise
    return how


def _dask_progress(client, futures: list):
    """Dask's own progress bar: a text bar in a terminal, a widget in a notebook."""
    from distributed.diagnostics.progressbar import TextProgressBar
    from distributed.utils import is_kernel

    if is_kernel():
        from distributed import progress
        from IPython.display import display

        widget = progress(futures, notebook=True)
        display(widget)
        return widget
    bar = TextProgressBar(futures, scheduler=client.scheduler.address, start=False)
    threading.Thread(target=bar._loop_runner.run_sync, args=(bar.listen,), daemon=True).start()
    return bar
