"""Provenance of a report: the input's SHA-256, versions, the date and time (UTC), the command.

A model file or a study export is hashed as it is on disk (``hashlib.sha256`` of its bytes). A
study store is a folder (zarr): :func:`tree_sha256` hashes its files in a fixed order, each as
its path relative to the store, a NUL byte, its SHA-256 in hex and a newline, so that the same
store gives the same digest on any machine and any change of a file, a name or the set of
files changes it.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import os
import platform
import sys
from pathlib import Path

from .result import Provenance

__all__ = ["file_sha256", "tree_sha256", "make_provenance", "versions"]

_CHUNK = 1 << 20


def file_sha256(path: str | os.PathLike[str]) -> str:
    """SHA-256 (hex) of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(_CHUNK), b""):
            h.update(block)
    return h.hexdigest()


def tree_sha256(folder: str | os.PathLike[str]) -> str:
    """SHA-256 (hex) of a folder's files: ``path NUL sha256(file) LF`` for each file, sorted by
    its path relative to ``folder`` (``/`` separators); links are not followed."""
    root = Path(folder)
    files = sorted(p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file() and not p.is_symlink())
    h = hashlib.sha256()
    for rel in files:
        h.update(rel.encode("utf-8") + b"\0" + file_sha256(root / rel).encode("ascii") + b"\n")
    return h.hexdigest()


def versions() -> dict[str, str]:
    """Versions of impstab and of what the numbers and the page depend on."""
    import jinja2
    import matplotlib
    import numpy
    import scipy

    from .. import __version__

    return {"impstab": __version__, "Python": platform.python_version(), "numpy": numpy.__version__,
            "scipy": scipy.__version__, "matplotlib": matplotlib.__version__, "jinja2": jinja2.__version__}


def make_provenance(source: str | os.PathLike[str] | None, kind: str, command: str | None,
                    described: str | None = None) -> Provenance:
    """Provenance of a report on ``source`` (a file or folder; None: an object in memory)."""
    digest = None
    if source is not None:
        p = Path(source)
        digest = tree_sha256(p) if p.is_dir() else file_sha256(p)
    now = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0)
    return Provenance(
        input=str(source) if source is not None else (described or "an object in memory"),
        input_kind=kind,
        sha256=digest,
        generated_utc=now.strftime("%Y-%m-%d %H:%M:%S UTC"),
        command=command or "Python: impstab.report(...)",
        versions=versions(),
        platform=f"{platform.system()} {platform.machine()} ({sys.implementation.name})",
    )
