"""Running a study: the chunks that are not done yet, in process or on a Dask cluster.

In process (the default) the chunks run one after the other in this process, each one a batch
of designs through the batched engine, with a rich progress bar (rate and ETA). ``workers=N``
starts a local Dask cluster of N single-threaded worker processes; ``scheduler=ADDRESS`` uses an
existing ``dask.distributed`` cluster (:mod:`impstab.studies.distributed`): each worker writes
the chunks it computes into the store itself, and this process only schedules. While a local
cluster starts (seconds: its workers' imports and first compiled calls), this process computes
the first chunks itself, so that the start costs the run little.

**Small studies stay in process.** Starting a local cluster costs some 2 s of CPU on two cores
and each task some milliseconds of scheduling, so a run on Dask pays only when there is enough
to share: fewer than
:data:`IN_PROCESS_BELOW` designs to compute, or fewer than two chunks per worker, run in this
process, and the run's history and output say so.

Rerunning an interrupted study computes only the chunks that are not verified done
(:mod:`impstab.studies.store`).
"""

from __future__ import annotations

import contextlib
import logging
import os
from typing import Callable

from ..errors import ModelError
from ..io import output_error
from .evaluate import ChunkResult, ChunkTask, evaluate_chunk
from .interrupts import interrupt_held
from .plan import ChunkPlan, plan_chunks
from .result import StudyResult
from .store import StudyStore
from .study import Study

__all__ = ["run_study", "chunk_task", "local_cluster", "IN_PROCESS_BELOW", "MAX_WORKERS"]

#: designs to compute below which a run asked to use Dask stays in this process
IN_PROCESS_BELOW = 20_000
#: most local worker processes for ``workers=N`` (per CPU core, and at least)
MAX_WORKERS = max(8, 4 * (os.cpu_count() or 1))

_log = logging.getLogger("impstab.studies")


def local_cluster(n_workers: int, **kwargs):
    """A local Dask cluster for studies (see :func:`impstab.studies.distributed.local_cluster`)."""
    from .distributed import local_cluster as _local

    return _local(n_workers, **kwargs)


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
        isolation=study.isolation,
    )


def run_study(
    study: Study,
    store: str | os.PathLike[str] | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    client=None,
    progress: bool = False,
    report: Callable[[str], None] | None = None,
    in_process_below: int = IN_PROCESS_BELOW,
) -> StudyResult:
    """Run (or resume) ``study`` and return its results.

    Parameters
    ----------
    study : Study
        From :func:`impstab.studies.load_study`.
    store : path, optional
        zarr store (a folder). Created if missing; if it exists it must hold the same study: it
        is verified, and only the chunks not done (or found damaged) are computed. None keeps
        the results in memory.
    workers : int, optional
        Start a local Dask cluster with this many worker processes (one thread each).
    scheduler : str, optional
        Address of an existing Dask scheduler, e.g. ``"tcp://10.0.0.5:8786"``.
    client : distributed.Client, optional
        An already connected Dask client (takes precedence over ``workers`` and ``scheduler``).
    progress : bool
        Show a progress bar (rich in process, Dask's own on a cluster).
    report : callable, optional
        Receives one line for each thing the run found and did besides computing (a damaged
        chunk computed again, a repaired file, the choice to stay in process); default: the
        ``impstab.studies`` logger, level WARNING.
    in_process_below : int
        A run on Dask with fewer designs to compute (or fewer than two chunks per worker)
        stays in this process; 0 never does.

    Returns
    -------
    StudyResult

    Raises
    ------
    ModelError
        Bad arguments, a store of another study or written by another run, a scheduler that
        does not answer (before anything is written), a store that cannot be written
        (:class:`impstab.io.OutputError`: the chunks finished so far are kept).
    KeyboardInterrupt
        Ctrl-C: the chunks finished so far are kept, the run is marked interrupted.
    """
    if workers is not None and scheduler is not None:
        raise ModelError("--workers", workers, "give either --workers or --scheduler, not both")
    if workers is not None and not (isinstance(workers, int) and not isinstance(workers, bool)
                                    and 1 <= workers <= MAX_WORKERS):
        raise ModelError("--workers", workers, f"must be a whole number from 1 to {MAX_WORKERS}")
    say = report or _log.warning
    plan = plan_chunks(study)
    session = None
    if client is None and scheduler is not None:
        from .distributed import connect

        session = connect(scheduler)  # before anything is written: a wrong address leaves nothing behind
    owned = [session] if session is not None else []
    st = None
    # a new store is made with Ctrl-C held back: an interrupt is raised once this run holds the
    # store (and removes it below), not between its creation and the hand-over, which would leave
    # behind a store without a run in its history ("chunks kept" where none was computed)
    creating = store is not None and not os.path.lexists(store)
    try:
        with interrupt_held() if creating else contextlib.nullcontext():
            st = StudyStore.create_or_resume(study, plan, store)
        for line in st.findings:
            say(line)
        return _run(study, plan, st, workers, scheduler, client, owned, progress, say, in_process_below)
    except BaseException:
        _close(owned)  # the workers stopped first: nothing writes into the store any more
        if st is not None:
            st.discard()  # a store made by this run with no chunk finished: nothing to resume, nothing left
        raise
    finally:
        if st is not None:
            st.close()
        _close(owned)


def _close(owned: list) -> None:
    while owned:
        owned.pop().close()


def _run(study, plan, st: StudyStore, workers, scheduler, client, owned: list, progress: bool, say,
         in_process_below: int) -> StudyResult:
    session = owned[0] if owned else None
    todo = st.todo()
    designs = sum(_prod(plan.block_shape(i)) for i in todo)
    asked = client is not None or workers is not None or scheduler is not None
    where = "in-process"
    if asked and todo:
        n_workers = workers if workers is not None else _worker_count(client or session.client)
        if in_process_below and (designs < in_process_below or len(todo) < 2 * n_workers):
            where = (f"in-process: {designs} designs in {len(todo)} chunks to compute, too few to share among "
                     f"{n_workers} workers (Dask is used from {in_process_below} designs and 2 chunks per worker)")
            say(where)
            asked = False
    computed = [0]

    def done(index: int) -> None:
        computed[0] += 1

    dask = asked and bool(todo)
    label = ""
    if dask:
        label = scheduler or ("a connected client" if client is not None else f"local cluster of {workers} workers")
    run = None
    try:
        run = st.begin_run(f"dask: {label}" if dask else where)
        if dask:
            from .distributed import ClusterStart, run_on_dask

            early = 0
            if client is None and session is None:  # compute here while the local cluster starts
                start = ClusterStart(workers)
                owned.append(start)
                rest = _run_local(study, plan, st, todo, done, progress, until=start.ready)
                early, todo = len(todo) - len(rest), rest
                session = start.wait()
                if session is None:
                    say(f"the local Dask cluster did not start ({type(start.error).__name__}: {start.error}); "
                        "the study goes on in this process")
                    _run_local(study, plan, st, todo, done, progress)
                    todo = []
            how = "this process computed every chunk"
            if todo:
                how = run_on_dask(client if client is not None else session.client, st, study, plan, todo, done,
                                  progress)
            if early:
                how += f"; this process computed {early} chunks while the cluster started"
            st.set_executor(run, f"dask: {label} ({how})")
        elif todo:
            _run_local(study, plan, st, todo, done, progress)
    except KeyboardInterrupt:
        _end(st, run, computed[0], interrupted=True)
        raise
    except OSError as exc:
        _end(st, run, computed[0], error=str(exc))
        kept = int(st.done().sum())
        raise output_error("--output", st.path or "memory", exc,
                           f"{kept} of {plan.n_chunks} chunks are done and kept: make room, then run the same "
                           "command again to resume" if kept else "no chunk was finished") from None
    except BaseException as exc:
        _end(st, run, computed[0], error=f"{type(exc).__name__}: {exc}")
        raise
    _end(st, run, computed[0])
    return StudyResult.from_store(st)


def _end(st: StudyStore, run, computed: int, interrupted: bool = False, error: str | None = None) -> None:
    if run is None:
        return
    with contextlib.suppress(OSError):  # a full disk: the history entry stays open, the chunks are kept
        st.end_run(run, computed, interrupted, error)


def _worker_count(client) -> int:
    try:
        return max(1, len(client.scheduler_info().get("workers", {})))
    except Exception:  # noqa: BLE001 - a count for the small-study rule only
        return 1


def _prod(shape) -> int:
    out = 1
    for s in shape:
        out *= int(s)
    return out


def _run_local(study: Study, plan: ChunkPlan, st: StudyStore, todo: list[int], done: Callable, progress: bool,
               until: Callable[[], bool] | None = None) -> list[int]:
    """Compute and write the chunks ``todo`` here, in order, until ``until()`` is true; return the rest."""
    stop = until or (lambda: False)
    rest = list(todo)
    if not progress:
        while rest and not stop():
            _keep(st, evaluate_chunk(chunk_task(study, plan, rest[0])), done)
            rest.pop(0)
        return rest
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, ProgressColumn, TextColumn, TimeElapsedColumn, TimeRemainingColumn
    from rich.text import Text

    class Rate(ProgressColumn):
        def render(self, task) -> Text:
            speed = task.finished_speed or task.speed
            return Text("-- designs/s" if speed is None else f"{speed:,.0f} designs/s")

    columns = (TextColumn("designs"), BarColumn(), MofNCompleteColumn(), Rate(), TimeElapsedColumn(),
               TextColumn("ETA"), TimeRemainingColumn())
    with Progress(*columns, console=Console(stderr=True), transient=until is not None) as bar:
        job = bar.add_task("designs", total=sum(_prod(plan.block_shape(i)) for i in todo))
        while rest and not stop():
            index = rest.pop(0)
            _keep(st, evaluate_chunk(chunk_task(study, plan, index)), done)
            bar.advance(job, _prod(plan.block_shape(index)))
    return rest


def _keep(st: StudyStore, result: ChunkResult, done: Callable[[int], None]) -> None:
    """Write a computed chunk (its data, then its completion record) and count it, Ctrl-C held back.

    The write takes milliseconds. Cut half-way by an interrupt, zarr's asynchronous writes were left
    never awaited, a warning each when the process ended (the interrupted run's one line on
    stderr became five), and a chunk written but not counted was missing from the run's history.
    """
    with interrupt_held():
        st.write(result)
        done(result.index)
