"""Running a study: the chunks that are not done yet, in process or on a Dask cluster.

In process (the default) the chunks run one after the other in this process, each one a batch
of designs through the batched engine, with a rich progress bar (rate and ETA). ``workers=N``
starts a local Dask cluster of N single-threaded worker processes; ``scheduler=ADDRESS`` uses an
existing ``dask.distributed`` cluster. Either way the workers receive one chunk's parameter
values at a time and send back that chunk's results; this process writes them to the store, so
the workers need no access to it. Rerunning an interrupted study computes only the chunks that
are not marked done.
"""

from __future__ import annotations

import logging
import os
import threading
from typing import Callable, Iterator

from ..errors import ModelError
from .evaluate import ChunkResult, ChunkTask, evaluate_chunk
from .plan import ChunkPlan, plan_chunks
from .result import StudyResult
from .store import StudyStore
from .study import Study

__all__ = ["run_study", "chunk_task", "local_cluster"]


def chunk_task(study: Study, plan: ChunkPlan, index: int) -> ChunkTask:
    """The work description of chunk ``index`` (only its own parameter values)."""
    return ChunkTask(
        index=index,
        block=plan.block_shape(index),
        base_model=study.base_model,
        segments=tuple(p.path.segments for p in study.parameters),
        columns=tuple(plan.design_columns(study, index)),
        outputs=study.outputs,
        model_name=study.model_name,
    )


def run_study(
    study: Study,
    store: str | os.PathLike[str] | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    client=None,
    progress: bool = False,
) -> StudyResult:
    """Run (or resume) ``study`` and return its results.

    Parameters
    ----------
    study : Study
        From :func:`impstab.studies.load_study`.
    store : path, optional
        zarr store (a folder). Created if missing; if it exists it must hold the same study,
        and only the chunks not yet done are computed. None keeps the results in memory.
    workers : int, optional
        Start a local Dask cluster with this many worker processes (one thread each).
    scheduler : str, optional
        Address of an existing Dask scheduler, e.g. ``"tcp://10.0.0.5:8786"``.
    client : distributed.Client, optional
        An already connected Dask client (takes precedence over ``workers`` and ``scheduler``).
    progress : bool
        Show a progress bar (rich in process, Dask's own on a cluster).

    Returns
    -------
    StudyResult
    """
    if workers is not None and scheduler is not None:
        raise ModelError("--workers", workers, "give either --workers or --scheduler, not both")
    if workers is not None and not (isinstance(workers, int) and workers >= 1):
        raise ModelError("--workers", workers, "must be a whole number >= 1")
    plan = plan_chunks(study)
    st = StudyStore.create_or_resume(study, plan, store)
    todo = [i for i, d in enumerate(st.done()) if not d]
    computed = [0]

    def write(res: ChunkResult) -> None:
        st.write(res)
        computed[0] += 1

    tasks = (chunk_task(study, plan, i) for i in todo)
    sizes = {i: _prod(plan.block_shape(i)) for i in todo}
    on_dask = client is not None or workers is not None or scheduler is not None
    where = "in-process"
    if on_dask:
        where = "dask: " + (scheduler or ("a connected client" if client is not None else f"local cluster of {workers} workers"))
    run = st.begin_run(where)
    interrupted = True
    try:
        if todo and on_dask:
            _run_dask(tasks, write, workers, scheduler, client, progress, study.fingerprint)
        elif todo:
            _run_local(tasks, sizes, write, progress)
        interrupted = False
    finally:
        st.end_run(run, computed[0], interrupted)
    return StudyResult.from_store(st)


def _prod(shape) -> int:
    out = 1
    for s in shape:
        out *= int(s)
    return out


def _run_local(tasks: Iterator[ChunkTask], sizes: dict[int, int], write: Callable, progress: bool) -> None:
    if not progress:
        for task in tasks:
            write(evaluate_chunk(task))
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, ProgressColumn, TextColumn, TimeElapsedColumn, TimeRemainingColumn
    from rich.text import Text

    class Rate(ProgressColumn):
        def render(self, task) -> Text:
            speed = task.finished_speed or task.speed
            return Text("-- designs/s" if speed is None else f"{speed:,.0f} designs/s")

    columns = (TextColumn("designs"), BarColumn(), MofNCompleteColumn(), Rate(), TimeElapsedColumn(),
               TextColumn("ETA"), TimeRemainingColumn())
    with Progress(*columns, console=Console(stderr=True)) as bar:
        job = bar.add_task("designs", total=sum(sizes.values()))
        for task in tasks:
            res = evaluate_chunk(task)
            write(res)
            bar.advance(job, sizes[task.index])


def _worker_version() -> str:
    try:
        from impstab import __version__

        return __version__
    except Exception as exc:  # noqa: BLE001 - reported to the user
        return f"cannot import impstab ({type(exc).__name__}: {exc})"


#: Dask settings of the clusters started here (see :func:`local_cluster`)
_QUIET_CLUSTER = {
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
}


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
    that background took a tenth of a core. Other keyword arguments go to ``LocalCluster``.
    """
    import dask
    from distributed import LocalCluster

    kw = dict(threads_per_worker=1, processes=True, silence_logs=logging.ERROR)
    kw.update(kwargs)
    with dask.config.set(_QUIET_CLUSTER):
        return LocalCluster(n_workers=n_workers, **kw)


def _connect(workers: int | None, scheduler: str | None):
    """A client, and the objects to close afterwards."""
    from distributed import Client

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="20s")
        except (OSError, TimeoutError) as exc:
            raise ModelError("--scheduler", scheduler, f"no Dask scheduler answered there ({exc})") from None
        return client, [client]
    try:
        import bokeh  # noqa: F401

        dashboard = ":0"
    except ImportError:
        dashboard = None
    cluster = local_cluster(workers, dashboard_address=dashboard)
    client = Client(cluster)
    return client, [client, cluster]


def _run_dask(tasks, write: Callable, workers, scheduler, client, progress: bool, token: str) -> None:
    from distributed import as_completed

    from .. import __version__

    owned: list = []
    if client is None:
        client, owned = _connect(workers, scheduler)
    try:
        for worker, version in client.run(_worker_version).items():
            if version != __version__:
                raise ModelError("--scheduler", worker, f"this worker has impstab {version}, the client {__version__}: install the same version everywhere")
        futures = [
            client.submit(evaluate_chunk, t, key=f"impstab-chunk-{token[:12]}-{t.index}", pure=False, retries=2)
            for t in tasks
        ]
        keys = [f.key for f in futures]
        bar = _dask_progress(client, futures) if progress else None
        pending = as_completed(futures)
        del futures
        held: list = []
        try:
            for fut in pending:
                write(fut.result())
                # results are released once written, after Dask's bar has seen every task
                held.append(fut)
                if bar is None or hasattr(bar, "_last_response"):
                    for f in held:
                        f.release()
                    held.clear()
        except BaseException:
            client.cancel(keys)
            raise
    finally:
        for obj in owned:
            obj.close()


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
