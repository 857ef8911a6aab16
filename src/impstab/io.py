"""Output files: written whole or not at all, and a one-line error naming the option and the path.

Every file a command writes goes through :func:`write_output`. Its content is produced in memory
first (a netCDF file by h5py into a byte buffer, a PNG by matplotlib, a CSV by pandas), then
written with plain ``os.write`` calls to a temporary name beside the target, flushed to the disk
and renamed onto the target. So a library that crashes on a full disk (h5py can segfault on
ENOSPC) never writes to the disk at all, and a failing write (full disk, read-only or missing
folder, no permission) becomes one :class:`OutputError` line: exit code 2 on the command line,
no file under the target name, the temporary removed.

A temporary name carries the host and process id of its writer
(``.NAME.HOST~PID~RANDOM.partSUFFIX``). A process killed while writing (kill -9, power loss of
the process) leaves it behind; the next write to the same target removes the temporaries whose
writer is no longer running on this host (:func:`remove_stale`), and so do the study stores for
their own temporary folders.
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
import re
import secrets
import shutil
import socket
import stat
from pathlib import Path
from typing import Any, BinaryIO, Callable, Iterator

from .errors import ModelError

__all__ = [
    "PathError", "OutputError", "write_output", "write_netcdf", "save_figure", "write_csv", "check_output",
    "atomic_path", "owner_tag", "is_stale", "remove_stale", "describe_os_error", "pid_alive",
]


class PathError(ModelError):
    """A ModelError about a file or folder: ``option = 'path': rule``, with the whole path."""

    def __init__(self, option: str, path: str | os.PathLike[str], rule: str) -> None:
        super().__init__(option, str(path), rule)
        self.args = (f"{option} = {str(path)!r}: {rule}",)  # the whole path, however long

    def __reduce__(self):  # picklable (raised on Dask workers, re-raised by the client)
        return (type(self), (self.field, self.value, self.rule))


class OutputError(PathError):
    """An output that cannot be written: ``option = 'path': cannot be written: reason``."""


_REASONS = {
    errno.ENOSPC: "no space left on the device (the file system is full)",
    errno.EDQUOT: "the disk quota is exceeded",
    errno.EROFS: "the file system is read-only",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.ENOTDIR: "a part of the path is not a folder",
    errno.EISDIR: "it is a folder",
    errno.ENOENT: "the folder does not exist",
    errno.ENAMETOOLONG: "the name is too long",
    errno.EIO: "input/output error of the device",
    errno.ELOOP: "too many symbolic links",
}


def describe_os_error(exc: OSError) -> str:
    """The reason of an OSError in words (no exception class names, no errno numbers).

    The file it names is added unless it is a hidden file (one of the temporaries and lock
    files written here, whose names mean nothing to the reader).
    """
    text = _REASONS.get(exc.errno or -1) or (exc.strerror or str(exc) or type(exc).__name__).lower()
    name = getattr(exc, "filename", None)
    if name and not Path(str(name)).name.startswith(".") and exc.errno not in (errno.ENOSPC, errno.EDQUOT):
        return f"{text} ({name})"
    return text


def output_error(option: str, path: str | os.PathLike[str], exc: OSError, after: str = "nothing was written") -> OutputError:
    """The :class:`OutputError` of an OSError raised while writing ``path``."""
    return OutputError(option, path, f"cannot be written: {describe_os_error(exc)}; {after}")


# -- owners of temporary files ------------------------------------------------------------------
def _host() -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", socket.gethostname() or "localhost")


def owner_tag() -> str:
    """``HOST~PID`` of this process: put into the names of its temporary files and folders."""
    return f"{_host()}~{os.getpid()}"


def pid_alive(pid: int) -> bool:
    """Whether a process ``pid`` runs on this host (a process of another user counts)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except OSError:
        return False
    return True


_TAG = re.compile(r"(?P<host>[A-Za-z0-9_.-]+)~(?P<pid>\d+)")


def is_stale(name: str) -> bool:
    """Whether a temporary file or folder ``name`` was left by a process that no longer runs.

    Names with an owner tag (:func:`owner_tag`) of this host are stale when that process is
    gone; a tag of another host is never judged (its process may run there). A name without a
    tag comes from a writer that did not record itself (older impstab versions), and counts as
    stale.
    """
    tags = list(_TAG.finditer(name))
    if not tags:
        return True
    tag = tags[-1]
    if tag["host"] != _host():
        return False
    return not pid_alive(int(tag["pid"]))


def remove_stale(folder: Path, prefix: str, suffix: str = "") -> list[Path]:
    """Remove the stale temporaries ``prefix*suffix`` in ``folder`` (files or folders); return them.

    Symbolic links among them are unlinked, never followed.
    """
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        name = entry.name
        if not (name.startswith(prefix) and name.endswith(suffix)) or not is_stale(name[len(prefix):]):
            continue
        path = Path(entry.path)
        try:
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(path)
            else:
                path.unlink()
            removed.append(path)
        except OSError:
            pass
    return removed


def _temporaries(final: Path) -> tuple[str, str]:
    return f".{final.name}.", f".part{final.suffix}"


# -- writing ------------------------------------------------------------------------------------
def _parent(final: Path, option: str) -> None:
    if final.is_dir():
        raise OutputError(option, final, "cannot be written: it is a folder")
    try:
        final.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise output_error(option, final, exc) from None


def _write_all(fd: int, data: memoryview) -> None:
    while data:
        n = os.write(fd, data)
        data = data[n:]


def write_output(path: str | os.PathLike[str], content: bytes | bytearray | memoryview | Callable[[BinaryIO], Any],
                 *, option: str) -> Path:
    """Write ``content`` to ``path`` whole or not at all.

    Parameters
    ----------
    path : path
        The target file; missing parent folders are created.
    content : bytes or callable
        The bytes, or a function that writes them into the binary buffer it is given.
    option : str
        The command-line option (or argument name) that gave ``path``, for the error message.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    OutputError
        If it cannot be written (full disk, read-only or missing folder, no permission); no file
        is left under ``path`` or under a temporary name.
    """
    final = Path(path)
    if callable(content):
        buf = io.BytesIO()
        content(buf)
        data = buf.getbuffer()
    else:
        data = memoryview(content)
    _parent(final, option)
    prefix, suffix = _temporaries(final)
    remove_stale(final.parent, prefix, suffix)
    tmp = final.parent / f"{prefix}{owner_tag()}~{secrets.token_hex(4)}{suffix}"
    fd = -1
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # the umask applies, as for open()
        _write_all(fd, data.cast("B"))
        os.fsync(fd)  # a delayed ENOSPC (network file systems) is reported here, not lost
        os.close(fd)
        fd = -1
        os.replace(tmp, final)
    except BaseException as exc:
        if fd >= 0:
            with contextlib.suppress(OSError):
                os.close(fd)
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, OSError):
            raise output_error(option, final, exc) from None
        raise
    return final


def check_output(path: str | os.PathLike[str], *, option: str) -> None:
    """Fail early (before a long computation) if ``path`` cannot be written.

    Creates and removes a temporary file in the nearest existing folder on the way to ``path``;
    creates nothing else. A full disk can only be noticed when the data are written.
    """
    final = Path(path)
    if final.is_dir():
        raise OutputError(option, final, "cannot be written: it is a folder")
    try:
        mode = os.stat(final).st_mode  # follows a link: its target is what the rename would replace
    except (OSError, ValueError):
        mode = None
    if mode is not None and not stat.S_ISREG(mode):
        raise OutputError(option, final, "exists and is not a regular file (a pipe, a device or a socket): "
                                         "give the name of a file to write")
    folder = final.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise OutputError(option, final, f"cannot be written: {folder} is not a folder")
    probe = folder / f".{final.name}.{owner_tag()}~{secrets.token_hex(4)}.probe"
    try:
        fd = os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        with contextlib.suppress(OSError):
            probe.unlink()
        raise output_error(option, final, exc) from None


def write_netcdf(dataset, path: str | os.PathLike[str], *, option: str) -> Path:
    """Write an xarray Dataset to a netCDF-4 file (h5netcdf, built in memory first)."""
    return write_output(path, lambda buf: dataset.to_netcdf(buf, engine="h5netcdf"), option=option)


def save_figure(figure, path: str | os.PathLike[str], *, option: str, **savefig: Any) -> Path:
    """Save a matplotlib figure (format from the suffix unless given), rendered in memory first."""
    savefig.setdefault("format", Path(path).suffix.lstrip(".").lower() or "png")
    return write_output(path, lambda buf: figure.savefig(buf, **savefig), option=option)


def write_csv(frame, path: str | os.PathLike[str], *, option: str, **to_csv: Any) -> Path:
    """Write a pandas DataFrame as CSV (UTF-8)."""
    return write_output(path, frame.to_csv(**to_csv).encode("utf-8"), option=option)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str], option: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it onto ``path`` only if the block succeeds.

    For writers that need a file name. Prefer :func:`write_output`, which keeps a crashing
    library away from the disk. With ``option``, an OSError becomes an :class:`OutputError`.
    """
    final = Path(path)
    try:
        final.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        if option is None:
            raise
        raise output_error(option, final, exc) from None
    prefix, suffix = _temporaries(final)
    remove_stale(final.parent, prefix, suffix)
    tmp_path = final.parent / f"{prefix}{owner_tag()}~{secrets.token_hex(4)}{suffix}"
    try:
        yield tmp_path
        os.replace(tmp_path, final)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp_path.unlink()
        if isinstance(exc, OSError) and option is not None:
            raise output_error(option, final, exc) from None
        raise
