"""The zarr store: written chunk by chunk, resumed after a kill, equal to an uninterrupted run."""

import json
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import xarray as xr
import zarr
from _study_helpers import GRID_6x5, write_study

from impstab.cli import main
from impstab.studies import load_study, open_study, run_study
from impstab.studies.plan import plan_chunks

BIG = """
[[parameters]]
path = "mount_rings[0].x"
values = { start = 0.1, stop = 0.4, num = 40 }
[[parameters]]
path = "mount_rings[0].k_shear"
values = { start = 5e3, stop = 5e4, num = 40, scale = "log" }
"""


def _records(store) -> np.ndarray:
    return zarr.open_group(str(store), mode="r")["progress/chunks"][...]


def _results(store) -> xr.Dataset:
    return open_study(store).dataset.drop_attrs()


def test_kill_and_resume_equals_uninterrupted(tmp_path):
    study = write_study(tmp_path, BIG, chunk_size=40)
    store = tmp_path / "k.zarr"
    cmd = [sys.executable, "-m", "impstab", "sweep", str(study), "-o", str(store), "--no-progress"]
    done_before = None
    with subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) as proc:
        deadline = time.time() + 60
        while time.time() < deadline and proc.poll() is None:
            time.sleep(0.02)
            if (store / "progress").exists():
                try:
                    rec = _records(store)
                except Exception:  # noqa: BLE001 - the store may be mid-write
                    continue
                if np.isfinite(rec[:, 0]).sum() >= 4:
                    proc.send_signal(signal.SIGKILL)
                    done_before = rec
                    break
        proc.wait()
    assert done_before is not None, "the study finished (or failed) before it could be killed"
    rec_killed = _records(store)
    finished = np.isfinite(rec_killed[:, 0])
    assert 4 <= finished.sum() < len(finished)
    # the rerun, with the same command, computes only the missing chunks
    rerun = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert rerun.returncode == 0, rerun.stderr
    rec = _records(store)
    assert np.isfinite(rec[:, 0]).all()
    assert np.all(rec[:, 1] == 1), "a chunk was computed twice"
    np.testing.assert_array_equal(rec[finished, 0], rec_killed[finished, 0])
    history = json.loads(zarr.open_group(str(store), mode="r").attrs["history"])
    assert len(history) == 2 and history[0]["ended"] is None
    assert history[1]["chunks_computed"] == len(finished) - finished.sum()
    # and the store equals the one an uninterrupted run writes
    run_study(load_study(study), tmp_path / "u.zarr")
    assert _results(store).identical(_results(tmp_path / "u.zarr"))


def test_half_written_chunk_is_computed_again(tmp_path):
    path = write_study(tmp_path, GRID_6x5)
    store = tmp_path / "h.zarr"
    first = run_study(load_study(path), store).dataset.drop_attrs()
    group = zarr.open_group(str(store), mode="r+")
    sl = plan_chunks(load_study(path)).slices(1)
    group["critical_thrust"][sl] = -1.0  # data of a chunk half-written by a process that died ...
    group["status"][sl] = -1
    group["progress/chunks"][1, :] = np.nan  # ... before it could mark the chunk done
    (store / "critical_thrust" / "c" / "junk.partial").write_bytes(b"x")
    res = run_study(load_study(path), store)
    assert res.dataset.drop_attrs().identical(first)
    history = json.loads(res.dataset.attrs["history"])
    assert history[-1]["chunks_computed"] == 1
    assert not list(store.rglob("*.partial"))


def test_rerun_of_a_complete_study_computes_nothing(tmp_path, capsys):
    path = write_study(tmp_path, GRID_6x5)
    store = tmp_path / "c.zarr"
    assert main(["sweep", str(path), "-o", str(store), "--no-progress"]) == 0
    assert main(["sweep", str(path), "-o", str(store), "--no-progress"]) == 0
    capsys.readouterr()
    ds = open_study(store).dataset
    history = json.loads(ds.attrs["history"])
    assert [h["chunks_computed"] for h in history] == [plan_chunks(load_study(path)).n_chunks, 0]
    assert ds.attrs["complete"] == 1 and ds.attrs["completed"]
    for key in ("study_file", "model_file", "impstab_version", "created", "updated"):
        assert ds.attrs[key]
    assert "mount_rings[0].k_shear" in ds.attrs["study_file"] and "k_axial" in ds.attrs["model_file"]


def test_a_store_of_another_study_is_refused(tmp_path, capsys):
    path = write_study(tmp_path, GRID_6x5)
    store = tmp_path / "o.zarr"
    assert main(["sweep", str(path), "-o", str(store), "--no-progress"]) == 0
    path.write_text(path.read_text().replace("num = 6", "num = 7"))
    capsys.readouterr()
    assert main(["sweep", str(path), "-o", str(store), "--no-progress"]) == 2
    _, err = capsys.readouterr()
    assert "different study" in err and err.count("\n") == 1
    (tmp_path / "notastore").mkdir()
    assert main(["sweep", str(path), "-o", str(tmp_path / "notastore")]) == 2
    assert "not an impstab study store" in capsys.readouterr().err


def test_exports_netcdf_and_csv(tmp_path, capsys):
    path = write_study(tmp_path, GRID_6x5)
    nc, csv = tmp_path / "r.nc", tmp_path / "r.csv"
    code = main(["sweep", str(path), "-o", str(tmp_path / "e.zarr"), "--export", str(nc), "--export", str(csv)])
    assert code == 0, capsys.readouterr().err
    ds = xr.load_dataset(nc)
    ref = open_study(tmp_path / "e.zarr").dataset
    np.testing.assert_array_equal(ds["critical_thrust"].values, ref["critical_thrust"].values)
    assert ds["kind"].attrs["flag_meanings"] == "none flutter divergence"
    assert ds.attrs["impstab_version"] == ref.attrs["impstab_version"]
    import pandas as pd

    table = pd.read_csv(csv)
    assert len(table) == 30
    assert {"mount_rings[0].x", "mount_rings[0].k_shear", "critical_thrust", "kind", "status"} <= set(table.columns)
    assert set(table["kind"]) <= {"none", "flutter", "divergence"} and set(table["status"]) == {"ok"}
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
    again = open_study(nc)  # an export opens like the store
    assert again.best("margin")["parameters"] == open_study(tmp_path / "e.zarr").best("margin")["parameters"]


@pytest.mark.parametrize("method", ["random", "sobol"])
def test_sampled_study_in_memory(tmp_path, method):
    body = f"""
[[parameters]]
path = "mount_rings[0].k_shear"
distribution = {{ kind = "lognormal", median = 2e4, sigma = 0.3 }}
[[parameters]]
path = "mount_rings[0].x"
values = {{ start = 0.2, stop = 0.4 }}
[sampling]
method = "{method}"
n = 40
"""
    res = run_study(load_study(write_study(tmp_path, body, chunk_size=None)), None)
    ds = res.dataset
    assert ds["critical_thrust"].dims == ("sample",) and ds.sizes["sample"] == 40
    assert "mount_rings[0].k_shear" in ds.coords and res.store is None
    assert res.complete and res.counts()["ok"] == 40


def test_ctrl_c_keeps_finished_chunks(tmp_path, capsys, monkeypatch):
    from impstab.studies import execute

    path = write_study(tmp_path, GRID_6x5)
    store = tmp_path / "i.zarr"
    real, calls = execute.evaluate_chunk, []

    def interrupted_after_two(task):
        calls.append(task.index)
        if len(calls) > 2:
            raise KeyboardInterrupt
        return real(task)

    monkeypatch.setattr(execute, "evaluate_chunk", interrupted_after_two)
    assert main(["sweep", str(path), "-o", str(store), "--no-progress"]) == 130
    assert "run the same command again to resume" in capsys.readouterr().err
    assert np.isfinite(_records(store)[:, 0]).sum() == 2
    monkeypatch.setattr(execute, "evaluate_chunk", real)
    assert main(["sweep", str(path), "-o", str(store), "--no-progress"]) == 0
    history = json.loads(open_study(store).dataset.attrs["history"])
    assert history[0]["interrupted"] and history[1]["chunks_computed"] == len(_records(store)) - 2
    assert open_study(store).complete


def test_a_failed_data_write_leaves_the_chunk_not_done(tmp_path, monkeypatch):
    """If one of a chunk's data writes fails, its completion record is not written (the chunk
    is recomputed on the next run), and writing it again completes it."""
    from impstab.studies.evaluate import evaluate_chunk
    from impstab.studies.execute import chunk_task
    from impstab.studies.store import StudyStore

    study = load_study(write_study(tmp_path, GRID_6x5))
    plan = plan_chunks(study)
    store = tmp_path / "f.zarr"
    st = StudyStore.create_or_resume(study, plan, store)
    res = evaluate_chunk(chunk_task(study, plan, 1))
    real = zarr.Array.__setitem__

    def failing(self, selection, value):
        if self.basename == "status":
            raise OSError("disk full")
        return real(self, selection, value)

    monkeypatch.setattr(zarr.Array, "__setitem__", failing)
    with pytest.raises(OSError, match="disk full"):
        st.write(res)
    monkeypatch.undo()
    assert not np.isfinite(_records(store)[:, 0]).any()
    group = zarr.open_group(str(store), mode="r")
    sl = plan.slices(1)
    np.testing.assert_array_equal(group["critical_thrust"][sl], res.data["critical_thrust"])  # written before
    assert (group["status"][sl] == -1).all()
    st.write(res)
    assert np.isfinite(_records(store)[:, 0]).sum() == 1 and _records(store)[1, 1] == 1.0


def test_chunk_pauses_the_collector_and_restores_it(tmp_path, monkeypatch):
    """evaluate_chunk runs with the cyclic collector off and leaves it as it found it, also
    when the chunk fails."""
    import gc

    from impstab.studies import evaluate
    from impstab.studies.execute import chunk_task

    study = load_study(write_study(tmp_path, GRID_6x5))
    task = chunk_task(study, plan_chunks(study), 0)
    seen = []
    real = evaluate._evaluate

    def spy(t):
        seen.append(gc.isenabled())
        return real(t)

    monkeypatch.setattr(evaluate, "_evaluate", spy)
    assert gc.isenabled()
    evaluate.evaluate_chunk(task)
    assert seen == [False] and gc.isenabled()
    gc.disable()
    try:
        evaluate.evaluate_chunk(task)
        assert not gc.isenabled()  # left off, as the caller had it
    finally:
        gc.enable()

    def boom(t):
        raise RuntimeError("boom")

    monkeypatch.setattr(evaluate, "_evaluate", boom)
    with pytest.raises(RuntimeError):
        evaluate.evaluate_chunk(task)
    assert gc.isenabled()


_MIXED = """
outputs = ["critical_thrust", "kind", "frequency_hz", "margin", "modes"]
[[parameters]]
path = "mount_rings[0].k_shear"
values = [0.0, 1e4, 2e4, 3e4]
[[parameters]]
path = "mount_rings[0].count"
values = [1, 3, 4]
"""

_SAMPLED = """
outputs = ["critical_thrust", "kind", "undamped_critical_thrust", "modes"]
[[parameters]]
path = "mount_rings[0].k_shear"
distribution = { kind = "lognormal", median = 2e4, sigma = 0.3 }
[sampling]
method = "random"
n = 11
"""


@pytest.mark.parametrize("body", [_MIXED, _SAMPLED], ids=["grid-with-failures", "sampled"])
def test_returned_results_equal_the_store_read_back(tmp_path, body):
    # run_study assembles its result from the chunks it wrote (every chunk of a fresh run);
    # the independent route is the store read back from disk: identical values, dtypes, attrs
    res = run_study(load_study(write_study(tmp_path, body, chunk_size=3)), tmp_path / "s.zarr")
    back = open_study(tmp_path / "s.zarr").dataset
    xr.testing.assert_identical(res.dataset, back)
    for name, var in back.variables.items():
        assert res.dataset[name].dtype == var.dtype, name
    if body is _MIXED:  # failed designs and their messages are among the assembled values
        assert 0 < res.counts()["ok"] < res.dataset["status"].size
        assert any(str(m) for m in res.dataset["message"].values.ravel())


def test_results_of_a_fresh_run_come_from_the_written_chunks(tmp_path):
    # the assembled values are the chunk results themselves: remove a variable's chunks from
    # disk after the writes, and the loaded dataset still holds them, while a reader of the
    # store refuses it, naming the missing chunks
    from impstab.errors import ModelError
    from impstab.studies.evaluate import evaluate_chunk
    from impstab.studies.execute import chunk_task
    from impstab.studies.store import StudyStore

    study = load_study(write_study(tmp_path, GRID_6x5, chunk_size=8))
    plan = plan_chunks(study)
    with StudyStore.create_or_resume(study, plan, tmp_path / "s.zarr") as st:
        results = [evaluate_chunk(chunk_task(study, plan, i)) for i in range(plan.n_chunks)]
        for r in results:
            st.write(r)
        for chunk in (tmp_path / "s.zarr" / "critical_thrust" / "c").rglob("*"):
            if chunk.is_file():
                chunk.unlink()
        ds = st.load_dataset()
    for r in results:
        np.testing.assert_array_equal(ds["critical_thrust"].values[plan.slices(r.index)], r.data["critical_thrust"])
    with pytest.raises(ModelError, match=r"chunk 0 \(critical_thrust/c/0/0 missing\)"):
        open_study(tmp_path / "s.zarr")
