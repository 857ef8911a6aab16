"""The files of a study store: read and written by key, never outside the store.

A key is a path inside the store with ``/`` separators (``zarr.json``,
``critical_thrust/c/1/0``). :class:`FolderFiles` keeps them in a folder, :class:`MemoryFiles`
in the dict of a zarr ``MemoryStore``. A folder store holds its own files: a symbolic link
anywhere inside it (a chunk file, a chunk folder, an array folder) is refused with
:class:`StoreLinkError` before anything is written through it, so a link can never make a
write land outside the store. Writes go to a temporary name beside the file and are renamed
onto it (a reader sees the old file or the new one, never half of one); zarr writes its own
chunk files the same way (``*.partial``).
"""

from __future__ import annotations

import contextlib
import os
import secrets
import stat
from pathlib import Path

from ..io import PathError

__all__ = ["StoreFiles", "FolderFiles", "MemoryFiles", "StoreLinkError", "scan"]


class StoreLinkError(PathError):
    """A symbolic link inside a study store (refused: nothing is written through it)."""

    def __init__(self, field: str, store: str, link: str) -> None:
        super().__init__(field, store, f"holds a symbolic link, {link}: a study store must hold its own files, "
                                       "so nothing is written through it (replace the link by what it points "
                                       "to, or remove it to have that part computed again)")
        self.link = link

    def __reduce__(self):
        return (type(self), (self.field, self.value, self.link))


class StoreFiles:
    """Files by key (see the module docstring)."""

    def read(self, key: str) -> bytes | None:  # pragma: no cover - interface
        raise NotImplementedError

    def write(self, key: str, data: bytes) -> None:  # pragma: no cover - interface
        raise NotImplementedError

    def remove(self, key: str) -> None:  # pragma: no cover - interface
        raise NotImplementedError

    def check(self, key: str) -> None:
        """Raise :class:`StoreLinkError` if writing ``key`` would pass through a symbolic link."""


class MemoryFiles(StoreFiles):
    """The files of an in-memory zarr store (its ``store_dict`` of zarr buffers)."""

    def __init__(self, store_dict: dict) -> None:
        self.store_dict = store_dict

    def read(self, key: str) -> bytes | None:
        buf = self.store_dict.get(key)
        return None if buf is None else buf.to_bytes()

    def write(self, key: str, data: bytes) -> None:
        from zarr.buffer import default_buffer_prototype

        self.store_dict[key] = default_buffer_prototype().buffer.from_bytes(data)

    def remove(self, key: str) -> None:
        self.store_dict.pop(key, None)


class FolderFiles(StoreFiles):
    """The files of a store folder ``root`` (see the module docstring).

    Parameters
    ----------
    root : Path
        The store folder (a link to a folder is followed: the store is where it points).
    field : str
        How the store was named (``--output``, ``STORE``), for the error messages.
    """

    def __init__(self, root: Path, field: str = "--output") -> None:
        self.root = Path(root)
        self.field = field

    def path(self, key: str) -> Path:
        return self.root.joinpath(*key.split("/"))

    def read(self, key: str) -> bytes | None:
        try:
            with open(self.path(key), "rb") as f:
                return f.read()
        except (FileNotFoundError, NotADirectoryError, IsADirectoryError):
            return None

    def check(self, key: str) -> None:
        """Refuse a key whose file or any folder on the way is a symbolic link."""
        here = self.root
        for part in key.split("/"):
            here = here / part
            try:
                mode = os.lstat(here).st_mode
            except (FileNotFoundError, NotADirectoryError):
                return  # the rest does not exist yet: it is made here, as a folder or file
            if stat.S_ISLNK(mode):
                raise StoreLinkError(self.field, str(self.root), str(here))

    def write(self, key: str, data: bytes) -> None:
        """Write ``data`` under ``key`` (temporary name, then rename); OSErrors propagate."""
        self.check(key)
        final = self.path(key)
        final.parent.mkdir(parents=True, exist_ok=True)
        tmp = final.with_name(f"{final.name}.{secrets.token_hex(8)}.partial")
        try:
            with open(tmp, "xb") as f:
                f.write(data)
            os.replace(tmp, final)
        except BaseException:
            with contextlib.suppress(OSError):
                tmp.unlink()
            raise

    def remove(self, key: str) -> None:
        self.check(key)
        with contextlib.suppress(FileNotFoundError, NotADirectoryError):
            self.path(key).unlink()


def scan(root: Path) -> tuple[list[Path], list[Path]]:
    """The symbolic links and the ``*.partial`` files inside the store folder ``root``.

    Walks the folder without following any link.
    """
    links: list[Path] = []
    partial: list[Path] = []
    stack = [root]
    while stack:
        folder = stack.pop()
        try:
            entries = list(os.scandir(folder))
        except OSError:
            continue
        for entry in entries:
            if entry.is_symlink():
                links.append(Path(entry.path))
            elif entry.is_dir(follow_symlinks=False):
                stack.append(Path(entry.path))
            elif entry.name.endswith(".partial"):
                partial.append(Path(entry.path))
    return sorted(links), partial
