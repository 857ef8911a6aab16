"""The run lock of a study store: one run at a time writes a store.

A run holds an exclusive ``flock`` on the file ``.impstab-lock`` inside the store for as long as
it writes (the workers of a Dask run write under their client's lock). The operating system
drops the lock when its process ends in any way, kill -9 included, so a lock file left behind
never blocks: the next run takes it over. The file names its holder (host, process id, start
time) for the message a second run gets. Where the file system cannot lock (some network file
systems), the holder written in the file decides instead: a holder on this host that no longer
runs is stale (:func:`impstab.io.pid_alive`).
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import errno
import json
import os
import socket
from pathlib import Path

from ..io import PathError, output_error, pid_alive

__all__ = ["RunLock", "LOCK_NAME", "StoreLockedError"]

LOCK_NAME = ".impstab-lock"


class StoreLockedError(PathError):
    """Another run writes the store."""


def _holder_text(path: Path) -> str:
    try:
        holder = json.loads(path.read_text())
        return f"process {holder['pid']} on {holder['host']}, since {holder['started']}"
    except (OSError, ValueError, KeyError, TypeError):
        return "another process"


class RunLock:
    """The exclusive lock of the store folder ``root`` (a context manager; see the module docstring)."""

    def __init__(self, root: Path, field: str = "--output") -> None:
        self.root = Path(root)
        self.field = field
        self.fd: int | None = None

    @property
    def path(self) -> Path:
        return self.root / LOCK_NAME

    def acquire(self) -> "RunLock":
        import fcntl

        path = self.path
        if path.is_symlink():
            raise PathError(self.field, self.root, f"holds a symbolic link, {path}: remove it")
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            error = output_error(self.field, self.root, exc, "nothing was changed")
            error.errno = exc.errno
            raise error from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                os.close(fd)
                raise StoreLockedError(
                    self.field, self.root,
                    f"is being written by another impstab run ({_holder_text(path)}): wait for it to end, "
                    "or stop it and run again",
                ) from None
            if not self._holder_gone(path):  # no flock on this file system: judge the holder named in the file
                os.close(fd)
                raise StoreLockedError(self.field, self.root,
                                       f"is locked by {_holder_text(path)}: wait for it to end, or stop it") from None
        holder = {"pid": os.getpid(), "host": socket.gethostname(),
                  "started": _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat()}
        try:
            os.ftruncate(fd, 0)
            os.pwrite(fd, json.dumps(holder).encode(), 0)
        except OSError:
            pass  # a full disk: the lock still holds, only the holder's name is missing
        self.fd = fd
        return self

    @staticmethod
    def _holder_gone(path: Path) -> bool:
        try:
            holder = json.loads(path.read_text() or "{}")
        except (OSError, ValueError):
            return True
        if not holder:
            return True
        return holder.get("host") == socket.gethostname() and not pid_alive(int(holder.get("pid", 0)))

    def release(self) -> None:
        if self.fd is None:
            return
        with contextlib.suppress(OSError):
            os.ftruncate(self.fd, 0)
        with contextlib.suppress(OSError):
            os.close(self.fd)
        self.fd = None

    def __enter__(self) -> "RunLock":
        return self.acquire()

    def __exit__(self, *exc) -> None:
        self.release()
