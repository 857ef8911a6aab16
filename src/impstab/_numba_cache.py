"""Where numba keeps impstab's compiled kernels: outside the source tree, keyed by the sources.

numba's ``cache=True`` writes beside the sources (``__pycache__``) by default, so every clone, copy
and read-only install compiled again, for minutes. impstab points numba at a cache of its own
instead (``NUMBA_CACHE_DIR``, set before numba is imported):

* ``<venv>/var/cache/impstab/numba/<key>`` when Python runs in a writable virtual environment
  (``make clean`` removes it with the environment), else ``$XDG_CACHE_HOME/impstab/numba/<key>``
  (``~/.cache/impstab/...``; ``%LOCALAPPDATA%\\impstab\\...`` on Windows);
* a ``NUMBA_CACHE_DIR`` of the user's own is left as it is (and then the caveat below is theirs).

Keying. numba checks a cached function against the file that defines it (its time stamp, or a
hash of its contents in recent versions), but not against the files it imports: a kernel that
calls a compiled function or reads a constant of another module keeps the old machine code when
only that other module changes. The ``<key>`` above closes that gap: it hashes the contents of
every impstab module that defines numba kernels and of every impstab module those import,
directly or not (:func:`kernel_sources`). An edit of any of them moves the whole package to a
fresh cache folder (compiled again on first use, or by ``python -m impstab.precompile``); edits
elsewhere (commands, drawing, docs) keep it. ``make clean-cache`` removes every cache folder.

The hook costs nothing until numba is imported: :func:`install` puts a finder in front of
``sys.meta_path`` that computes the folder (a few milliseconds) when the first ``import numba``
happens and then steps aside.

Processes sharing a cache. numba adds a compiled signature to a kernel's cache by reading its
index, choosing the next free data file and writing both back, with no lock between processes
(``make compile`` runs its cases in parallel processes, the test suite in several workers). Two
processes saving different signatures of one kernel at once can then both choose the same data
file: one index entry is lost, or, worse, an entry names the other signature's machine code.
:func:`lock_cache_files` (called when a process compiles) makes each kernel's index and data
update one step under an exclusive ``flock`` on a lock file beside the index, and each load
read them under a shared one (POSIX; elsewhere numba's own behaviour stays).
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
import sys
from pathlib import Path

__all__ = ["install", "cache_dir", "cache_root", "kernel_sources", "source_key", "is_kernel_module", "user_setting",
           "lock_cache_files", "ENV"]

#: numba's own setting (read once, when numba is imported)
ENV = "NUMBA_CACHE_DIR"
#: the value impstab gave ``NUMBA_CACHE_DIR`` (so that a worker process inheriting it, or
#: ``precompile --clean``, can tell it from a setting of the user's own)
SET_BY_IMPSTAB = "IMPSTAB_NUMBA_CACHE_DIR"
PACKAGE = Path(__file__).resolve().parent

_FROM = re.compile(rb"^[ \t]*from[ \t]+(\.+)([\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^#\n]*)", re.M)
#: imports numba, or impstab's deferred numba decorator (impstab._jit: kernels compiled on demand)
_USES_NUMBA = re.compile(rb"^[ \t]*(?:(?:from|import)[ \t]+numba\b|from[ \t]+(?:\.+|impstab\.)_jit[ \t]+import\b)", re.M)
#: a compiled function defined here: a numba decorator, or one called on a function
_DEFINES_KERNEL = re.compile(
    rb"(?:^[ \t]*@[ \t]*(?:numba\.|nb\.)?|\b)(?:njit|jit|vectorize|guvectorize|cfunc|stencil|overload|intrinsic)\b[ \t]*[(\n]",
    re.M)
_ABSOLUTE = re.compile(rb"^[ \t]*(?:from|import)[ \t]+impstab((?:\.\w+)*)", re.M)


def cache_root() -> Path:
    """The folder for impstab's caches (without the ``numba/<key>`` part)."""
    if sys.prefix != sys.base_prefix and os.access(sys.prefix, os.W_OK):
        return Path(sys.prefix) / "var" / "cache" / "impstab"
    if os.name == "nt":  # pragma: no cover - not run on this platform
        base = os.environ.get("LOCALAPPDATA") or str(Path.home() / "AppData" / "Local")
        return Path(base) / "impstab" / "Cache"
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "impstab"


def _module_file(parts: list[str], package: Path) -> Path | None:
    path = package.joinpath(*parts)
    if (path / "__init__.py").is_file():
        return path / "__init__.py"
    if path.with_suffix(".py").is_file():
        return path.with_suffix(".py")
    return None


def _imports(path: Path, text: bytes, package: Path) -> set[Path]:
    """The impstab source files that the module at ``path`` imports (anywhere in it)."""
    here = path.relative_to(package).parent.parts
    found: set[Path] = set()
    for dots, name, names in _FROM.findall(text):
        base = list(here[: len(here) - (len(dots) - 1)]) if len(dots) - 1 <= len(here) else None
        if base is None:
            continue
        parts = base + [p for p in name.decode().split(".") if p]
        for target in [parts] + [parts + [n.split()[0]] for n in names.decode().strip("()").split(",") if n.split()]:
            file = _module_file(target, package)
            if file is not None:
                found.add(file)
    for name in _ABSOLUTE.findall(text):
        parts = [p for p in name.decode().split(".") if p]
        for k in range(len(parts), -1, -1):
            file = _module_file(parts[:k], package)
            if file is not None:
                found.add(file)
                break
    return found


def is_kernel_module(text: bytes) -> bool:
    """Whether a module's source imports numba and defines compiled code."""
    return bool(_USES_NUMBA.search(text) and _DEFINES_KERNEL.search(text))


def kernel_sources(package: Path = PACKAGE) -> dict[Path, bytes]:
    """Contents of the source files that can reach compiled code: every module of ``package``
    that defines numba kernels, and every module of ``package`` they import (transitively)."""
    texts = {p: p.read_bytes() for p in package.rglob("*.py") if "__pycache__" not in p.parts}
    todo = [p for p, text in texts.items() if (b"numba" in text or b"_jit" in text) and is_kernel_module(text)]
    seen: set[Path] = set(todo)
    while todo:
        path = todo.pop()
        for dep in _imports(path, texts[path], package):
            if dep not in seen and dep in texts:
                seen.add(dep)
                todo.append(dep)
    return {p: texts[p] for p in sorted(seen)}


def source_key(package: Path = PACKAGE) -> str:
    """A short hash of :func:`kernel_sources` (paths relative to the package, and contents)."""
    h = hashlib.blake2b(digest_size=8)
    for path, text in kernel_sources(package).items():
        h.update(path.relative_to(package).as_posix().encode() + b"\0")
        h.update(hashlib.blake2b(text, digest_size=16).digest())
    return h.hexdigest()


def user_setting() -> str | None:
    """``NUMBA_CACHE_DIR`` if the user set it (not impstab, in this process or a parent)."""
    value = os.environ.get(ENV)
    return value if value and value != os.environ.get(SET_BY_IMPSTAB) else None


def cache_dir() -> Path:
    """The folder numba uses for impstab's kernels: the user's ``NUMBA_CACHE_DIR`` if set, else
    ``cache_root()/numba/<source_key()>``."""
    own = user_setting()
    if own:
        return Path(own)
    return cache_root() / "numba" / source_key()


def _configure() -> None:
    if user_setting():
        return
    folder = str(cache_dir())
    os.environ[ENV] = os.environ[SET_BY_IMPSTAB] = folder  # worker processes inherit both
    config = sys.modules.get("numba.core.config")
    if config is not None:  # numba came first: kernels decorated from now on use the folder
        config.CACHE_DIR = folder


class _BeforeNumba:
    """A ``sys.meta_path`` finder that sets ``NUMBA_CACHE_DIR`` at the first ``import numba``."""

    @classmethod
    def find_spec(cls, name, path=None, target=None):
        if name == "numba" or name.startswith("numba."):
            remove()
            _configure()
        return None  # the normal finders load numba


def install() -> None:
    """Make numba cache impstab's kernels in :func:`cache_dir` (once per process)."""
    if user_setting():
        return
    if "numba" in sys.modules:
        _configure()
    elif _BeforeNumba not in sys.meta_path:
        sys.meta_path.insert(0, _BeforeNumba)  # type: ignore[arg-type]


def lock_cache_files() -> None:
    """Serialise numba's cache updates of each kernel across processes (see the module notes).

    Wraps ``numba.core.caching.IndexDataCacheFile.save`` (exclusive lock) and ``load`` (shared
    lock) once per process; where ``fcntl`` or that class is missing, or the lock file cannot be
    opened (a read-only cache, which numba does not write either), numba runs unchanged.
    """
    try:
        import fcntl
        from numba.core import caching
    except ImportError:  # pragma: no cover - not POSIX, or a numba without that module
        return
    cls = getattr(caching, "IndexDataCacheFile", None)
    if cls is None or getattr(cls, "_impstab_locked", False) or not hasattr(cls, "save"):
        return

    def locked(method, mode):
        @functools.wraps(method)
        def run(self, *args, **kwargs):
            try:
                fd = os.open(str(self._index_path) + ".lock", os.O_RDWR | os.O_CREAT, 0o644)
            except (OSError, AttributeError):
                return method(self, *args, **kwargs)
            try:
                fcntl.flock(fd, mode)
                return method(self, *args, **kwargs)
            finally:
                os.close(fd)  # releases the lock
        return run

    cls.save = locked(cls.save, fcntl.LOCK_EX)
    cls.load = locked(cls.load, fcntl.LOCK_SH)
    cls._impstab_locked = True


def remove() -> None:
    """Take the finder of :func:`install` out of ``sys.meta_path`` (if there)."""
    while _BeforeNumba in sys.meta_path:
        sys.meta_path.remove(_BeforeNumba)  # type: ignore[arg-type]
