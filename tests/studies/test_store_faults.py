"""Fault injection into study stores: every kind of file deleted, truncated, corrupted or replaced
by a symbolic link; stale locks and temporaries; two runs on one store.

The independent answer is always an uninterrupted run of the same study: after the fault and a
resume, the store must read back identical to it (values, dtypes, attributes but the run-to-run
ones), readers must refuse damaged data naming the part (or read intact data), and nothing
outside the store may be written.
"""

import json
import os
import shutil
import socket
import subprocess
import sys
import time

import numpy as np
import pytest
from _fault_helpers import FAULT_STUDY, SRC, assert_same_store, damage, one_line, tree
from _study_helpers import write_study

from impstab.cli import main
from impstab.errors import ModelError
from impstab.studies import load_study, open_study, run_study
from impstab.studies.lock import LOCK_NAME

#: one file (or folder) of every kind in a store; chunk 2 is the block mount_rings[0].x = 0.22
KINDS = {
    "float data": "critical_thrust/c/2/0",
    "int8 data": "kind/c/2/0",
    "string data": "modes/c/2/0",
    "status": "status/c/2/0",
    "message": "message/c/2/0",
    "completion record": "progress/chunks/c/2/0",
    "coordinate": "mount_rings[0].x/c/0",
    "array metadata": "critical_thrust/zarr.json",
    "root metadata": "zarr.json",
    "progress metadata": "progress/zarr.json",
    "record metadata": "progress/chunks/zarr.json",
    "chunk folder": "critical_thrust/c/2",
}
CHUNK_KINDS = ("float data", "int8 data", "string data", "status", "message", "completion record", "chunk folder")
FAULTS = ("delete", "truncate", "corrupt", "symlink")


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The study file and the store of an uninterrupted run."""
    folder = tmp_path_factory.mktemp("reference")
    study = write_study(folder, FAULT_STUDY, chunk_size=8)
    run_study(load_study(study), folder / "ref.zarr")
    return study, folder / "ref.zarr"


def _cases():
    for kind in KINDS:
        for how in FAULTS:
            if kind == "chunk folder" and how in ("truncate", "corrupt"):
                continue
            yield pytest.param(kind, how, id=f"{how}-{kind.replace(' ', '_')}")


def _named(message: str, kind: str) -> bool:
    key = KINDS[kind]
    return key in message or (kind in CHUNK_KINDS and "chunk 2" in message) or "zarr.json" in message


@pytest.mark.parametrize("kind,how", list(_cases()))
def test_damaged_store_is_flagged_then_resumed_to_the_uninterrupted_run(reference, tmp_path, kind, how, capsys):
    study_file, ref = reference
    store = tmp_path / "s.zarr"
    shutil.copytree(ref, store)
    outside = tmp_path / "outside"
    moved = damage(store, KINDS[kind], how, outside)
    before = tree(tmp_path)

    # the reader: damaged data refused with the part named, or intact data read
    try:
        res = open_study(store)
    except ModelError as exc:
        assert _named(str(exc), kind), str(exc)
        capsys.readouterr()  # and the command line says so in one line (drawing intact stores is tested elsewhere)
        assert main(["map", str(store), "-o", str(tmp_path / "map.png")]) == 2
        assert _named(one_line(capsys.readouterr().err), kind)
    else:
        ref_ds = open_study(ref).dataset
        assert set(res.pending_chunks) <= {2}
        keep = np.ones(ref_ds["status"].shape, dtype=bool)
        keep[2] = not res.pending_chunks
        for var in ref_ds.data_vars:
            np.testing.assert_array_equal(res.dataset[var].values[keep], ref_ds[var].values[keep])
    assert tree(tmp_path) == before, "a reader wrote something"

    lines: list[str] = []
    if how == "symlink":  # refused, and nothing written through the link or anywhere else
        with pytest.raises(ModelError, match="symbolic link") as info:
            run_study(load_study(study_file), store, report=lines.append)
        assert str(store.joinpath(*KINDS[kind].split("/"))) in str(info.value)
        assert tree(tmp_path) == before
        store.joinpath(*KINDS[kind].split("/")).unlink()  # the user removes the link
        assert moved.exists()
    res = run_study(load_study(study_file), store, report=lines.append)
    assert_same_store(store, ref)
    assert res.complete
    if how == "symlink":
        assert {k: v for k, v in tree(outside).items()} == {k[len("outside/"):]: v for k, v in before.items()
                                                            if k.startswith("outside/")}
    else:
        assert not (tmp_path / "outside").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["s.zarr"] + (["outside"] if how == "symlink" else []))
    history = json.loads(open_study(store).dataset.attrs["history"])
    if kind in CHUNK_KINDS and not (kind == "completion record" and how in ("delete", "symlink")):
        assert any("chunk 2" in line for line in lines), lines
        if how != "symlink" or kind == "chunk folder":
            assert history[-1].get("recomputed") == [2] or history[-1]["chunks_computed"] == 1
    if kind not in CHUNK_KINDS and how != "symlink":
        assert any("repaired" in line and KINDS[kind] in line for line in lines), lines
    assert history[-1]["ended"] is not None


def test_a_damaged_chunk_in_the_cli_is_one_line_then_resumed(reference, tmp_path, capsys):
    study_file, ref = reference
    store = tmp_path / "s.zarr"
    shutil.copytree(ref, store)
    damage(store, "critical_thrust/c/4/0", "truncate", tmp_path)
    capsys.readouterr()
    assert main(["map", str(store), "-o", str(tmp_path / "m.png")]) == 2
    line = one_line(capsys.readouterr().err)
    assert "chunk 4" in line and "critical_thrust/c/4/0 truncated" in line and "impstab sweep" in line
    assert main(["sweep", str(study_file), "-o", str(store), "--no-progress", "--export", str(tmp_path / "e.nc")]) == 0
    err = capsys.readouterr().err
    assert "computing 1 chunk again" in one_line(err) and "chunk 4" in err
    assert_same_store(store, ref)
    assert main(["map", str(store), "-o", str(tmp_path / "m.png")]) == 0


def test_an_interrupted_store_is_drawn_with_a_warning_naming_the_missing_chunks(reference, tmp_path, capsys):
    study_file, ref = reference
    store = tmp_path / "s.zarr"
    shutil.copytree(ref, store)
    for i in (1, 3):
        (store / "progress" / "chunks" / "c" / str(i) / "0").unlink()  # as if killed before these records
    res = open_study(store)
    assert res.pending_chunks == (1, 3) and not res.complete
    assert (res.dataset["status"].values[[1, 3]] == -1).all()  # not computed, whatever the files hold
    assert np.isnan(res.dataset["critical_thrust"].values[[1, 3]]).all()
    capsys.readouterr()
    assert main(["map", str(store), "-o", str(tmp_path / "m.png")]) == 0
    err = capsys.readouterr().err
    assert "2 of 6 chunks" in one_line(err) and "chunks 1, 3" in err


def test_a_copied_record_does_not_vouch_for_another_chunk(reference, tmp_path):
    study_file, ref = reference
    store = tmp_path / "s.zarr"
    shutil.copytree(ref, store)
    rec = store / "progress" / "chunks" / "c"
    shutil.copy(rec / "1" / "0", rec / "3" / "0")
    with pytest.raises(ModelError, match="that of chunk 1"):
        open_study(store)
    lines: list[str] = []
    run_study(load_study(study_file), store, report=lines.append)
    assert "chunk 3" in " ".join(lines)
    assert_same_store(store, ref)


def test_stale_lock_of_a_killed_run_does_not_block(reference, tmp_path):
    study_file, ref = reference
    store = tmp_path / "s.zarr"
    shutil.copytree(ref, store)
    (store / LOCK_NAME).write_text(json.dumps({"pid": 2**22 + 12345, "host": socket.gethostname(),
                                               "started": "2020-01-01T00:00:00+00:00"}))
    shutil.rmtree(store / "margin" / "c" / "5")
    run_study(load_study(study_file), store)
    assert_same_store(store, ref)


def test_stale_temporaries_of_killed_runs_are_removed(reference, tmp_path, capsys):
    study_file, ref = reference
    host = socket.gethostname()
    dead = 2**22 + 4321
    creating = tmp_path / f".n.zarr.creating-{host}~{dead}"
    legacy = tmp_path / f".n.zarr.creating-{dead}"
    other_host = tmp_path / f".n.zarr.creating-elsewhere~{dead}"
    for folder in (creating, legacy, other_host):
        folder.mkdir()
        (folder / "zarr.json").write_text("{")
    part = tmp_path / f".e.nc.{host}~{dead}~abcd1234.part.nc"
    old_part = tmp_path / ".e.nc.k2j3h4g5.part.nc"  # an earlier version's name
    mine = tmp_path / f".e.nc.{host}~{os.getpid()}~abcd1234.part.nc"  # a live writer's
    for f in (part, old_part, mine):
        f.write_bytes(b"half")
    stale_partial = ref.parent / "unused"
    del stale_partial
    code = main(["sweep", str(study_file), "-o", str(tmp_path / "n.zarr"), "--no-progress",
                 "--export", str(tmp_path / "e.nc")])
    assert code == 0, capsys.readouterr().err
    assert "killed while it made the store" in capsys.readouterr().err
    assert not creating.exists() and not legacy.exists() and not part.exists() and not old_part.exists()
    assert other_host.exists() and mine.exists()  # another host's and a running writer's are left alone
    assert_same_store(tmp_path / "n.zarr", ref)
    (tmp_path / "n.zarr" / "status" / "c" / "0" / "0.0123abcd.partial").write_bytes(b"x")  # a zarr write cut short
    lines: list[str] = []
    run_study(load_study(study_file), tmp_path / "n.zarr", report=lines.append)
    assert "removed 1 temporary file" in " ".join(lines)
    assert not list((tmp_path / "n.zarr").rglob("*.partial"))


_HOLD = """
import sys, time
from impstab.studies import load_study
from impstab.studies.plan import plan_chunks
from impstab.studies.store import StudyStore
study = load_study(sys.argv[1])
st = StudyStore.create_or_resume(study, plan_chunks(study), sys.argv[2])
print("locked", flush=True)
time.sleep(float(sys.argv[3]))
st.close()
"""


def test_a_second_run_on_a_store_in_use_is_refused_in_one_line(reference, tmp_path, capsys):
    study_file, ref = reference
    store = tmp_path / "s.zarr"
    shutil.copytree(ref, store)
    shutil.rmtree(store / "status" / "c" / "1")
    env = dict(os.environ, PYTHONPATH=str(SRC))
    with subprocess.Popen([sys.executable, "-c", _HOLD, str(study_file), str(store), "30"], env=env,
                          stdout=subprocess.PIPE, text=True) as holder:
        assert holder.stdout.readline().strip() == "locked"
        capsys.readouterr()
        assert main(["sweep", str(study_file), "-o", str(store), "--no-progress"]) == 2
        line = one_line(capsys.readouterr().err)
        assert "being written by another impstab run" in line and f"process {holder.pid}" in line
        with pytest.raises(ModelError, match="another impstab run"):
            run_study(load_study(study_file), store)
        holder.kill()  # kill -9: its lock goes with it
        holder.wait()
    before = json.loads(json.loads((store / "zarr.json").read_text())["attributes"]["history"])
    run_study(load_study(study_file), store)
    assert_same_store(store, ref)
    after = json.loads(open_study(store).dataset.attrs["history"])
    assert after[: len(before)] == before and len(after) == len(before) + 1  # no entry lost, none made up


_RESUME = """
import sys
from impstab.studies import load_study, run_study
from impstab.errors import ModelError
try:
    run_study(load_study(sys.argv[1]), sys.argv[2], report=lambda line: None)
    print("ran")
except ModelError as exc:
    print("refused" if "another impstab run" in str(exc) else f"error {exc}")
"""


def test_concurrent_resumes_one_runs_the_other_is_refused_and_no_history_is_lost(reference, tmp_path):
    study_file, ref = reference
    store = tmp_path / "s.zarr"
    shutil.copytree(ref, store)
    for i in range(6):  # every chunk to compute again
        (store / "progress" / "chunks" / "c" / str(i) / "0").unlink()
    start = json.loads(open_study(ref).dataset.attrs["history"])
    env = dict(os.environ, PYTHONPATH=str(SRC))
    procs = [subprocess.Popen([sys.executable, "-c", _RESUME, str(study_file), str(store)], env=env,
                              stdout=subprocess.PIPE, text=True) for _ in range(2)]
    outcomes = sorted(p.communicate(timeout=120)[0].strip() for p in procs)
    assert outcomes in (["ran", "refused"], ["ran", "ran"]), outcomes  # the second may start after the first ended
    history = json.loads(open_study(store).dataset.attrs["history"])
    assert history[: len(start)] == start
    assert len(history) == len(start) + outcomes.count("ran")
    assert sum(h["chunks_computed"] for h in history[len(start):]) == 6
    assert_same_store(store, ref)


def test_a_fresh_store_made_at_the_same_time_by_two_runs(reference, tmp_path):
    study_file, ref = reference
    store = tmp_path / "new.zarr"
    env = dict(os.environ, PYTHONPATH=str(SRC))
    procs = [subprocess.Popen([sys.executable, "-c", _RESUME, str(study_file), str(store)], env=env,
                              stdout=subprocess.PIPE, text=True) for _ in range(2)]
    outcomes = sorted(p.communicate(timeout=120)[0].strip() for p in procs)
    assert outcomes in (["ran", "refused"], ["ran", "ran"]), outcomes
    assert_same_store(store, ref)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["new.zarr"]  # no temporary folder left


def test_older_store_format_is_refused_with_its_reason(reference, tmp_path, capsys):
    study_file, ref = reference
    store = tmp_path / "s.zarr"
    shutil.copytree(ref, store)
    doc = json.loads((store / "zarr.json").read_text())
    doc["attributes"]["format"] = "impstab-study-store/1"
    del doc["attributes"]["integrity"]
    (store / "zarr.json").write_text(json.dumps(doc))
    with pytest.raises(ModelError, match="older store format"):
        open_study(store)
    capsys.readouterr()
    assert main(["sweep", str(study_file), "-o", str(store), "--no-progress"]) == 2
    assert "older store format" in one_line(capsys.readouterr().err)


def test_a_store_with_nothing_finished_is_not_left_behind(reference, tmp_path, monkeypatch, capsys):
    from impstab.studies import execute

    study_file, _ = reference

    def fails(task):
        raise RuntimeError("boom")

    monkeypatch.setattr(execute, "evaluate_chunk", fails)
    with pytest.raises(RuntimeError):
        run_study(load_study(study_file), tmp_path / "x.zarr")
    assert not list(tmp_path.iterdir())

    def interrupted(task):
        raise KeyboardInterrupt

    monkeypatch.setattr(execute, "evaluate_chunk", interrupted)
    capsys.readouterr()
    assert main(["sweep", str(study_file), "-o", str(tmp_path / "x.zarr"), "--no-progress"]) == 130
    assert "nothing was kept" in one_line(capsys.readouterr().err)
    assert not list(tmp_path.iterdir())
    time.sleep(0)


@pytest.mark.parametrize("after", ["rename", "hand-over"])
def test_ctrl_c_as_a_new_store_is_made_leaves_nothing(tmp_path, monkeypatch, after):
    """A SIGINT that arrives right after the new store is renamed into place, or between its
    creation and the run holding it, is raised once the run holds the store, which it removes (no
    chunk was computed): no store without a run in its history, no temporary folder."""
    import signal

    from impstab.studies.store import StudyStore

    study = load_study(write_study(tmp_path, FAULT_STUDY, chunk_size=5))
    made = StudyStore._create.__func__

    def interrupted(cls, *args, **kw):
        if after == "rename":
            real = os.rename

            def rename_then_interrupt(src, dst):
                real(src, dst)
                signal.raise_signal(signal.SIGINT)

            monkeypatch.setattr(os, "rename", rename_then_interrupt)
        store = made(cls, *args, **kw)
        monkeypatch.undo()
        if after == "hand-over":
            signal.raise_signal(signal.SIGINT)
        return store

    monkeypatch.setattr(StudyStore, "_create", classmethod(interrupted))
    with pytest.raises(KeyboardInterrupt):
        run_study(study, tmp_path / "s.zarr", report=lambda line: None)
    assert not (tmp_path / "s.zarr").exists()
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".s.zarr")]
    res = run_study(study, tmp_path / "s.zarr", report=lambda line: None)  # and a new run makes it afresh
    assert res.complete
    assert [e["interrupted"] for e in json.loads(open_study(tmp_path / "s.zarr").dataset.attrs["history"])] == [False]


def test_ctrl_c_while_a_chunk_is_written_finishes_that_chunk(tmp_path, monkeypatch):
    """A SIGINT during a chunk's write (zarr's writes are asynchronous: cut half-way, they are left
    never awaited, a warning each at exit) is raised once the chunk and its completion record are
    written: the chunk is kept as done, and the resumed run equals an uninterrupted one."""
    import signal
    import warnings

    from impstab.studies.store import ChunkWriter

    study = load_study(write_study(tmp_path, FAULT_STUDY, chunk_size=5))
    ref = run_study(study, tmp_path / "ref.zarr", report=lambda line: None)
    real = ChunkWriter.write

    def interrupted(self, result, runs):
        monkeypatch.undo()  # the first chunk only
        signal.raise_signal(signal.SIGINT)
        return real(self, result, runs)

    monkeypatch.setattr(ChunkWriter, "write", interrupted)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a coroutine never awaited is a RuntimeWarning
        with pytest.raises(KeyboardInterrupt):
            run_study(study, tmp_path / "s.zarr", report=lambda line: None)
    store = open_study(tmp_path / "s.zarr")
    history = json.loads(store.dataset.attrs["history"])
    assert [(e["interrupted"], e["chunks_computed"]) for e in history] == [(True, 1)]
    res = run_study(study, tmp_path / "s.zarr", report=lambda line: None)
    assert res.complete
    assert_same_store(tmp_path / "s.zarr", tmp_path / "ref.zarr")
    assert ref.complete
