"""Faults of the machine for every command that writes: a full disk, a read-only folder.

Each must end with exit code 2 and one line naming the option and the path, and leave no file
(and no temporary) behind; a study store keeps the chunks it finished and resumes to what an
uninterrupted run writes. Tested on a real tiny tmpfs where this process may mount one (root),
and everywhere with injected write errors (ENOSPC, EACCES) at the lowest write calls.
"""

import errno
import os
import shutil
import subprocess
from pathlib import Path

import pytest
import zarr
from _fault_helpers import FAULT_STUDY, assert_same_store, one_line
from _study_helpers import EXAMPLES, write_study

from impstab.cli import main
from impstab.studies import load_study, run_study

MODEL = str(EXAMPLES / "imp_symmetric.toml")


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    folder = tmp_path_factory.mktemp("reference")
    study = write_study(folder, FAULT_STUDY, chunk_size=8)
    run_study(load_study(study), folder / "ref.zarr")
    return study, folder / "ref.zarr"


def _mount(folder: Path, options: str) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(folder)], capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.decode().strip()}")


@pytest.fixture
def tmpfs(tmp_path):
    """A mounter of tiny tmpfs file systems under tmp_path (unmounted afterwards)."""
    mounted: list[Path] = []

    def mount(name: str, options: str) -> Path:
        folder = tmp_path / name
        _mount(folder, options)
        mounted.append(folder)
        return folder

    yield mount
    for folder in reversed(mounted):
        subprocess.run(["umount", "-l", str(folder)], capture_output=True)


def _fill(folder: Path) -> None:
    """Fill the file system of ``folder`` up."""
    with open(folder / "filler", "wb", buffering=0) as f:
        try:
            while True:
                f.write(b"\0" * 4096)
        except OSError as exc:
            assert exc.errno == errno.ENOSPC


#: every command that writes, with its output in FOLDER
WRITERS = {
    "locus -o nc": ["locus", MODEL, "-o", "{f}/l.nc"],
    "simulate -o nc": ["simulate", MODEL, "--thrust", "1000", "--duration", "0.5", "-o", "{f}/s.nc"],
    "simulate -o csv": ["simulate", MODEL, "--thrust", "1000", "--duration", "0.5", "-o", "{f}/s.csv"],
    "added-mass -o png": ["added-mass", "--radius", "0.1", "--length", "1", "--frequencies", "0:50:3", "-o", "{f}/a.png"],
    "added-mass -o nc": ["added-mass", "--radius", "0.1", "--length", "1", "--frequencies", "0:50:3", "-o", "{f}/a.nc"],
    "response -o nc": ["response", MODEL, "--frequencies", "0.5:5:20", "-o", "{f}/r.nc"],
    "schema -o": ["schema", "-o", "{f}/schema.json"],
    "locus -o svg": ["locus", MODEL, "-o", "{f}/l.svg"],
    "map -o png": ["map", "{store}", "-o", "{f}/m.png"],
    "sweep --export nc": ["sweep", "{study}", "-o", "{store}", "--no-progress", "--export", "{f}/e.nc"],
    "sweep --export csv": ["sweep", "{study}", "-o", "{store}", "--no-progress", "--export", "{f}/e.csv"],
    "sweep -o store": ["sweep", "{study}", "-o", "{f}/new.zarr", "--no-progress"],
}
OPTION = {"sweep --export nc": "--export", "sweep --export csv": "--export"}


def _argv(name: str, folder: Path, reference) -> list[str]:
    """The command line of writer ``name`` into ``folder`` (on a copy of the reference store)."""
    study, ref = reference
    store = folder.parent / "copy.zarr"
    if not store.exists():
        shutil.copytree(ref, store)
    return [a.format(f=folder, store=store, study=study) for a in WRITERS[name]]


def _check_refused(capsys, name: str, folder: Path, reference, reason: str) -> str:
    """The command ``name`` writing into ``folder`` exits 2 with one line naming the option, the path, the reason."""
    capsys.readouterr()
    assert main(_argv(name, folder, reference)) == 2
    line = one_line(capsys.readouterr().err)
    target = next(a for a in WRITERS[name] if "{f}" in a).format(f=folder)
    assert f"{OPTION.get(name, '--output')} = '{target}'" in line and reason in line, line
    return line


@pytest.mark.parametrize("name", list(WRITERS))
def test_every_writer_on_a_full_disk(tmpfs, reference, capsys, name):
    folder = tmpfs("full", "size=64k")
    _fill(folder)
    _check_refused(capsys, name, folder, reference, "no space left on the device")
    assert sorted(p.name for p in folder.iterdir()) == ["filler"]  # no file, no temporary


@pytest.mark.parametrize("name", list(WRITERS))
def test_every_writer_in_a_read_only_folder(tmpfs, reference, capsys, name):
    folder = tmpfs("ro", "size=64k,ro")
    _check_refused(capsys, name, folder, reference, "read-only")
    assert not list(folder.iterdir())


def test_a_store_filling_the_disk_keeps_its_chunks_and_resumes(tmpfs, reference, capsys):
    study, ref = reference
    folder = tmpfs("full", "size=160k")
    store = folder / "s.zarr"
    capsys.readouterr()
    assert main(["sweep", str(study), "-o", str(store), "--no-progress"]) == 2
    line = one_line(capsys.readouterr().err)
    assert "no space left" in line and "chunks are done and kept" in line and "run the same command again" in line
    assert not list(store.rglob("*.partial"))
    subprocess.run(["mount", "-o", "remount,size=2m", str(folder)], check=True)
    assert main(["sweep", str(study), "-o", str(store), "--no-progress"]) == 0
    assert_same_store(store, ref)


def test_a_complete_store_on_a_read_only_file_system_can_still_be_exported(tmp_path, reference, capsys):
    study, ref = reference
    if os.geteuid() != 0:
        pytest.skip("a read-only bind mount needs root")
    store = tmp_path / "s.zarr"
    shutil.copytree(ref, store)
    for options in (None, "remount,bind,ro"):
        cmd = ["mount", "--bind", str(store), str(store)] if options is None else ["mount", "-o", options, str(store)]
        if subprocess.run(cmd, capture_output=True).returncode != 0:
            subprocess.run(["umount", "-l", str(store)], capture_output=True)
            pytest.skip("cannot bind-mount here")
    try:
        capsys.readouterr()
        assert main(["sweep", str(study), "-o", str(store), "--no-progress", "--export", str(tmp_path / "e.csv")]) == 0
        assert "read-only" in capsys.readouterr().err and (tmp_path / "e.csv").exists()
    finally:
        subprocess.run(["umount", "-l", str(store)], capture_output=True)


# -- injected errors (no root needed) ------------------------------------------------------------
class _OsWith:
    """The os module with one function replaced (for the module under test only)."""

    def __init__(self, **replaced) -> None:
        self.__dict__.update(replaced)

    def __getattr__(self, name):
        return getattr(os, name)


def _enospc(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")


def _eacces(path, *args, **kwargs):
    raise PermissionError(errno.EACCES, "Permission denied", str(path))


@pytest.mark.parametrize("name", [n for n in WRITERS if n != "sweep -o store"])
@pytest.mark.parametrize("fault", ["ENOSPC", "EACCES"])
def test_every_file_writer_with_an_injected_write_error(tmp_path, reference, capsys, monkeypatch, name, fault):
    import impstab.io

    if fault == "ENOSPC":
        monkeypatch.setattr(impstab.io, "_write_all", _enospc)
        reason = "no space left on the device"
    else:
        monkeypatch.setattr(impstab.io, "os", _OsWith(open=_eacces))
        reason = "permission denied"
    folder = tmp_path / "out"
    folder.mkdir()
    _argv(name, folder, reference)  # the store copy, before the fault
    _check_refused(capsys, name, folder, reference, reason)
    assert not list(folder.iterdir())


def test_a_store_write_failing_mid_run_keeps_what_is_done_and_resumes(tmp_path, reference, capsys, monkeypatch):
    study, ref = reference
    real, calls = zarr.storage.LocalStore.set, [0]

    async def failing(self, key, value):
        calls[0] += 1
        if calls[0] > 15:  # two chunks (6 arrays each) and half of the third
            raise OSError(errno.ENOSPC, "No space left on device")
        return await real(self, key, value)

    monkeypatch.setattr(zarr.storage.LocalStore, "set", failing)
    store = tmp_path / "s.zarr"
    capsys.readouterr()
    assert main(["sweep", str(study), "-o", str(store), "--no-progress"]) == 2
    line = one_line(capsys.readouterr().err)
    assert f"--output = '{store}'" in line and "no space left" in line and "2 of 6 chunks are done and kept" in line
    monkeypatch.undo()
    assert main(["sweep", str(study), "-o", str(store), "--no-progress"]) == 0
    assert_same_store(store, ref)


def test_store_creation_without_permission_leaves_nothing(tmp_path, reference, capsys, monkeypatch):
    import impstab.studies.store_files as store_files

    study, _ = reference
    monkeypatch.setattr(store_files, "open", _eacces, raising=False)
    capsys.readouterr()
    assert main(["sweep", str(study), "-o", str(tmp_path / "n.zarr"), "--no-progress"]) == 2
    line = one_line(capsys.readouterr().err)
    assert "permission denied" in line and "n.zarr" in line
    assert not list(tmp_path.iterdir())


def test_a_store_that_cannot_be_locked_is_refused_in_one_line(tmp_path, reference, capsys, monkeypatch):
    import impstab.studies.lock as lock

    study, ref = reference
    store = tmp_path / "s.zarr"
    shutil.copytree(ref, store)
    shutil.rmtree(store / "status" / "c" / "3")  # something to compute: a read-only store cannot be resumed
    monkeypatch.setattr(lock, "os", _OsWith(open=_eacces))
    capsys.readouterr()
    assert main(["sweep", str(study), "-o", str(store), "--no-progress"]) == 2
    assert "permission denied" in one_line(capsys.readouterr().err)
