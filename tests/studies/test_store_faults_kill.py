"""kill -9 at every kind of moment, in process and on a local Dask cluster, then resume.

A run is killed at its k-th file commit (a rename of a finished temporary onto its name, the
only way the store changes), just before or just after it, for k spread over the whole run:
store creation, chunk data, completion records, the run history. A Dask run loses one of its
workers mid-run, or its client. The independent answer is an uninterrupted in-process run of
the same study: the resumed store must read back identical to it, with nothing left behind.
"""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from _fault_helpers import FAULT_STUDY, SRC, assert_same_store, run_child
from _study_helpers import write_study

from impstab.studies import load_study, open_study, run_study

#: forks one run per (k, moment) from a single interpreter; each child dies at its k-th commit
_KILLER = r"""
import json, os, signal, sys
from impstab.studies import load_study, run_study

study_file, folder, plan = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
study = load_study(study_file)
run_study(study, None)  # imports and compiled code loaded before the forks

def child(k, when, store):
    count = [0]
    def wrap(real):
        def commit(src, dst, *a, **kw):
            mine = store.name in str(dst)
            if mine:
                count[0] += 1
            if mine and count[0] == k and when == "before":
                os.kill(os.getpid(), signal.SIGKILL)
            out = real(src, dst, *a, **kw)
            if mine and count[0] == k and when == "after":
                os.kill(os.getpid(), signal.SIGKILL)
            return out
        return commit
    os.replace, os.rename = wrap(os.replace), wrap(os.rename)
    run_study(study, store, report=lambda line: None)
    print(json.dumps({"commits": count[0]}), flush=True)

from pathlib import Path
for k, when in plan:
    store = Path(folder) / f"k{k}-{when}" / "s.zarr"
    store.parent.mkdir()
    pid = os.fork()
    if pid == 0:
        try:
            child(k, when, store)
        finally:
            os._exit(0)
    _, status = os.waitpid(pid, 0)
    print(json.dumps({"k": k, "when": when, "killed": os.WIFSIGNALED(status)}), flush=True)
"""


def _kills(study: Path, folder: Path, plan: list) -> list[dict]:
    out = run_child(_KILLER, str(study), str(folder), json.dumps(plan), timeout=300)
    assert out.returncode == 0, out.stderr
    return [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]


def test_kill_at_every_kind_of_moment_in_process_then_resume(tmp_path):
    study = write_study(tmp_path, FAULT_STUDY, chunk_size=8)
    run_study(load_study(study), tmp_path / "ref.zarr")
    total = [r for r in _kills(study, tmp_path, [[0, "never"]]) if "commits" in r][0]["commits"]
    assert total > 6 * 8  # creation, 6 chunks of 5 arrays and a record, the history
    rng = np.random.default_rng(13)
    moments = sorted({1, 2, total - 1, total, *rng.choice(np.arange(3, total - 1), size=8, replace=False).tolist()})
    plan = [[int(k), "before" if i % 2 else "after"] for i, k in enumerate(moments)]
    results = [r for r in _kills(study, tmp_path, plan) if "k" in r]
    assert len(results) == len(plan) and all(r["killed"] for r in results), results
    for r in results:
        folder = tmp_path / f"k{r['k']}-{r['when']}"
        store = folder / "s.zarr"
        res = run_study(load_study(study), store, report=lambda line: None)
        assert res.complete, r
        assert_same_store(store, tmp_path / "ref.zarr")
        assert sorted(p.name for p in folder.iterdir()) == ["s.zarr"], r  # no temporary folder left
        assert not list(store.rglob("*.partial")), r
        records = np.array(open_study(store).dataset["status"].shape)  # the grid
        assert records.prod() == 30
    history = json.loads(open_study(tmp_path / f"k{total}-{plan[-1][1]}" / "s.zarr").dataset.attrs["history"])
    assert len(history) == 2  # the killed run's entry is kept, with the resume after it


distributed = pytest.importorskip("distributed")

#: the per-variant path (a mount count is not assembled in bulk): tens of ms a chunk
_SLOW_STUDY = """
[[parameters]]
path = "mount_rings[0].count"
values = [3, 4, 5, 6]
[[parameters]]
path = "mount_rings[0].k_shear"
values = { start = 5e3, stop = 5e4, num = 60, scale = "log" }
"""


def _records_done(store: Path) -> int:
    return len(list((store / "progress" / "chunks" / "c").glob("*/0")))


@pytest.fixture(scope="module")
def slow(tmp_path_factory):
    """A study of 40 chunks on the per-variant path, and its uninterrupted in-process store."""
    folder = tmp_path_factory.mktemp("slow")
    study = write_study(folder, _SLOW_STUDY, chunk_size=6)
    run_study(load_study(study), folder / "ref.zarr")
    return study, folder / "ref.zarr"


def test_a_worker_killed_mid_run_loses_nothing(tmp_path, slow):
    from impstab.studies.distributed import local_cluster

    study, ref = slow
    n_chunks = 40
    store = tmp_path / "s.zarr"
    with local_cluster(2, dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        pids = sorted(client.run(os.getpid).values())
        killed = []

        def killer():
            deadline = time.time() + 60
            while time.time() < deadline:
                if store.exists() and _records_done(store) >= 3:
                    killed.append(_records_done(store))
                    os.kill(pids[0], signal.SIGKILL)
                    return
                time.sleep(0.002)

        thread = threading.Thread(target=killer)
        thread.start()
        res = run_study(load_study(study), store, client=client, in_process_below=0)
        thread.join()
    assert killed and killed[0] < n_chunks, "the run ended before a worker could be killed"
    assert res.complete
    assert_same_store(store, ref)
    history = json.loads(open_study(store).dataset.attrs["history"])
    assert "the workers write the chunks" in history[-1]["executor"]


_CLIENT = r"""
import json, os, signal, sys
from impstab.studies import distributed, load_study, run_study
from impstab.studies.store import StudyStore

after = int(sys.argv[3])
real_mark, real_run = StudyStore.mark_done, distributed.run_on_dask
seen = [0]
on_dask = []

def mark_done(self, index, record):  # the chunks the workers wrote, as the client notes them
    real_mark(self, index, record)
    seen[0] += bool(on_dask)
    if seen[0] == after:
        os.kill(os.getpid(), signal.SIGKILL)

def run_on_dask(client, *args, **kw):
    print(json.dumps(sorted(client.run(os.getpid).values())), flush=True)
    on_dask.append(True)
    return real_run(client, *args, **kw)

StudyStore.mark_done, distributed.run_on_dask = mark_done, run_on_dask
distributed.ClusterStart.ready = lambda self: self.wait() or True  # every chunk to the workers
run_study(load_study(sys.argv[1]), sys.argv[2], workers=2, in_process_below=0)
"""


def _gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


@pytest.mark.parametrize("after", [1, 17])
def test_the_client_killed_mid_run_then_resumed(tmp_path, slow, after):
    study, ref = slow
    store = tmp_path / "s.zarr"
    env = dict(os.environ, PYTHONPATH=str(SRC), MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, "-c", _CLIENT, str(study), str(store), str(after)], env=env,
                          capture_output=True, text=True, timeout=180)
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    workers = json.loads(proc.stdout.splitlines()[0])
    deadline = time.time() + 30
    while time.time() < deadline and not all(_gone(p) for p in workers):
        time.sleep(0.1)
    assert all(_gone(p) for p in workers), "the workers outlived their client"
    done_before = _records_done(store)
    assert done_before < 40
    res = run_study(load_study(study), store, report=lambda line: None)
    assert res.complete
    assert_same_store(store, ref)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.zarr"]


#: 1200 designs on the per-variant path in 200 chunks: a second or two of work
_INTERRUPTED_STUDY = """
[[parameters]]
path = "mount_rings[0].count"
values = [3, 4, 5, 6]
[[parameters]]
path = "mount_rings[0].k_shear"
values = { start = 5e3, stop = 5e4, num = 300, scale = "log" }
"""


_CLI = "import sys; from impstab.cli import main; sys.exit(main(sys.argv[1:]))"
#: the command line, with every chunk left to the workers once the cluster has started
_CLI_DASK_ONLY = ("import sys; from impstab.studies import distributed; "
                  "distributed.ClusterStart.ready = lambda self: self.wait() or True; " + _CLI.split("; ", 1)[1])


@pytest.fixture(scope="module")
def interrupted(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sigint")
    study = write_study(folder, _INTERRUPTED_STUDY, chunk_size=6)
    run_study(load_study(study), folder / "ref.zarr")
    return study, folder / "ref.zarr"


def _as_a_terminal_starts_it() -> None:
    """Ctrl-C's default disposition, as a shell gives a foreground program: a test runner started
    in the background of a non-interactive shell ignores SIGINT, and an ignored signal stays
    ignored across ``exec``, so the command would run to its end and exit 0."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.parametrize("where,after", [("in-process", 3), ("dask", 3), ("dask", 0)],
                         ids=["in-process", "dask-mid-run", "dask-while-the-cluster-starts"])
def test_ctrl_c_in_a_terminal_ends_in_one_line_and_resumes(tmp_path, interrupted, where, after):
    """SIGINT to the whole foreground process group, as a terminal's Ctrl-C sends it (to the
    local workers too): exit 130, one line on stderr, and a store that resumes to the
    uninterrupted run's (or none, if no chunk was finished)."""
    study, ref = interrupted
    store = tmp_path / "s.zarr"
    args = ["sweep", str(study), "-o", str(store), "--no-progress"]
    if where == "dask":
        args += ["--workers", "2", "--min-dask-designs", "0"]
    cmd = [sys.executable, "-c", _CLI_DASK_ONLY if after else _CLI, *args]
    env = dict(os.environ, PYTHONPATH=str(SRC), MPLBACKEND="Agg")
    with subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env,
                          start_new_session=True, preexec_fn=_as_a_terminal_starts_it) as proc:
        deadline = time.time() + 120
        while time.time() < deadline and proc.poll() is None and not (store.exists() and _records_done(store) >= after):
            time.sleep(0.005)  # after=0: the store is made, the cluster is starting
        assert proc.poll() is None, "the run ended before it could be interrupted"
        os.killpg(proc.pid, signal.SIGINT)
        err = proc.communicate(timeout=120)[1]
    assert proc.returncode == 130, err
    assert len(err.strip().splitlines()) == 1 and "interrupted" in err, err
    if store.exists():
        run_study(load_study(study), store, report=lambda line: None)
        assert_same_store(store, ref)
        history = json.loads(open_study(store).dataset.attrs["history"])
        assert history[0]["interrupted"] is True
    else:
        assert "nothing was" in err
    assert sorted(p.name for p in tmp_path.iterdir()) in ([], ["s.zarr"])
