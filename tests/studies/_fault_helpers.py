"""Helpers for the store fault tests: a reference store, damage, comparisons, child processes."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import xarray as xr

from impstab.studies import open_study

SRC = Path(__file__).resolve().parents[2] / "src"

#: the run-to-run attributes; everything else must equal an uninterrupted run's
RUN_ATTRS = ("created", "updated", "completed", "history")

#: a 6 x 5 grid in 6 chunks, with a string and an integer output among the arrays
FAULT_STUDY = """
outputs = ["critical_thrust", "kind", "margin", "modes"]
[[parameters]]
path = "mount_rings[0].x"
values = { start = 0.1, stop = 0.4, num = 6 }
[[parameters]]
path = "mount_rings[0].k_shear"
values = { start = 5e3, stop = 5e4, num = 5, scale = "log" }
"""


def assert_same_store(store: Path, reference: Path) -> None:
    """``store`` reads back exactly as ``reference``: values, dtypes, coordinates, variable
    attributes and the store attributes except the run-to-run ones."""
    a, b = open_study(store).dataset, open_study(reference).dataset
    assert not open_study(store).pending_chunks
    for ds in (a, b):
        ds.attrs = {k: v for k, v in ds.attrs.items() if k not in RUN_ATTRS}
    xr.testing.assert_identical(a, b)
    for name, var in b.variables.items():
        assert a[name].dtype == var.dtype, name
    assert int(a.attrs["complete"]) == 1


def tree(folder: Path) -> dict[str, tuple[int, bytes]]:
    """Every file below ``folder`` (links not followed) with its modification time and contents
    (the run lock, which every run takes, left out)."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(folder):
        for name in dirnames + filenames:
            if name == ".impstab-lock":
                continue
            p = Path(dirpath) / name
            if p.is_symlink():
                out[str(p.relative_to(folder))] = (0, os.readlink(p).encode())
            elif p.is_file():
                out[str(p.relative_to(folder))] = (p.stat().st_mtime_ns, p.read_bytes())
    return out


def damage(store: Path, key: str, how: str, outside: Path) -> Path:
    """Damage the file (or folder) ``key`` of ``store``: delete, truncate, corrupt or symlink it.

    ``symlink`` moves it to ``outside`` and leaves a link to it in its place; returns its path.
    """
    path = store.joinpath(*key.split("/"))
    if how == "delete":
        if path.is_dir():
            shutil.rmtree(path)
        else:
            path.unlink()
    elif how == "truncate":
        data = path.read_bytes()
        path.write_bytes(data[: len(data) // 2])
    elif how == "corrupt":
        data = bytearray(path.read_bytes())
        rng = np.random.default_rng(len(data))
        for i in rng.choice(len(data), size=min(3, len(data)), replace=False):
            data[i] ^= 0xA5
        path.write_bytes(bytes(data))
    elif how == "symlink":
        outside.mkdir(parents=True, exist_ok=True)
        target = outside / path.name
        shutil.move(str(path), str(target))
        path.symlink_to(target, target_is_directory=target.is_dir())
        return target
    else:
        raise ValueError(how)
    return path


def run_child(script: str, *args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """Run a Python snippet in a fresh interpreter (this source tree first on its path)."""
    env = dict(os.environ, PYTHONPATH=f"{SRC}{os.pathsep}{os.environ.get('PYTHONPATH', '')}", MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-c", script, *args], capture_output=True, text=True, timeout=timeout,
                          env=env)


def one_line(text: str) -> str:
    """The only line of ``text`` (asserts there is exactly one)."""
    lines = [ln for ln in text.splitlines() if ln.strip()]
    assert len(lines) == 1, text
    return lines[0]
