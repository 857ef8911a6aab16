"""Where numba keeps impstab's compiled kernels: outside the source tree, shared by every clone.

numba's ``cache=True`` writes beside the sources (``__pycache__``) by default, so every clone, copy
and read-only install compiled again, for minutes. impstab points numba at a cache of its own
instead (``NUMBA_CACHE_DIR``, set before numba is imported):

* ``$XDG_CACHE_HOME/impstab/numba/<key>`` (``~/.cache/impstab/...``; ``%LOCALAPPDATA%\\impstab\\...``
  on Windows), shared by every clone, virtual environment and install of the same kernel sources
  on the machine, as uv and pip share their caches; where that folder cannot be written,
  ``<venv>/var/cache/impstab/numba/<key>`` in a writable virtual environment;
* a ``NUMBA_CACHE_DIR`` of the user's own is left as it is (and then the caveats below are theirs).

Keying. numba checks a cached function against the file that defines it (a hash of its
contents), but not against the files it imports: a kernel that calls a compiled function or reads
a constant of another module keeps the old machine code when only that other module changes.
The ``<key>`` above closes that gap: it hashes the contents of every impstab module that defines
numba kernels and of every impstab module those import, directly or not (:func:`kernel_sources`).
An edit of any of them moves the whole package to a fresh cache folder (compiled again on first
use, or by ``python -m impstab.precompile``); edits elsewhere (commands, drawing, docs) keep it.
Inside it, :func:`versions_tag` (Python, numba, llvmlite, NumPy) separates environments whose
compiled code differs; numba's own index separates processors.

Shared by clones. numba's default layout names a source file's cache folder after the file's
absolute path, so a second clone of the same commit would compile again. impstab's kernels are
placed instead by their path inside the package (:func:`locate_by_package`, a cache locator put
in front of numba's own when the process compiles), so any clone or environment with the same
sources, at any path, loads the machine code the first one compiled. ``python -m
impstab.precompile`` keeps the :data:`KEEP` most recently compiled key folders and removes older
ones, and the virtual environment's folder where earlier versions kept the kernels (:func:`prune`);
``make clean-cache`` removes them all.

The hook costs nothing until numba is imported: :func:`install` puts a finder in front of
``sys.meta_path`` that computes the folder (a few milliseconds) when the first ``import numba``
happens and then steps aside.

Processes sharing a cache. numba adds a compiled signature to a kernel's cache by reading its
index, choosing the next free data file and writing both back, with no lock between processes
(``make compile`` runs its cases in parallel processes, the test suite in several workers; two
clones may compile at once). Two processes saving different signatures of one kernel at once can
then both choose the same data file: one index entry is lost, or, worse, an entry names the other
signature's machine code. :func:`lock_cache_files` (called when a process compiles) makes each
kernel's index and data update one step under an exclusive ``flock`` on a lock file beside the
index, and each load read them under a shared one (POSIX; elsewhere numba's own behaviour stays).
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
import sys
from pathlib import Path

__all__ = ["install", "cache_dir", "cache_root", "kernel_sources", "source_key", "is_kernel_module", "user_setting",
           "lock_cache_files", "locate_by_package", "versions_tag", "kernel_folder", "prune", "KEEP", "MARKER", "ENV"]

#: numba's own setting (read once, when numba is imported)
ENV = "NUMBA_CACHE_DIR"
#: the value impstab gave ``NUMBA_CACHE_DIR`` (so that a worker process inheriting it, or
#: ``precompile --clean``, can tell it from a setting of the user's own)
SET_BY_IMPSTAB = "IMPSTAB_NUMBA_CACHE_DIR"
PACKAGE = Path(__file__).resolve().parent
#: key folders (kernel sources) kept by :func:`prune`: the most recently compiled
KEEP = 8
#: written by ``python -m impstab.precompile`` into :func:`kernel_folder` when every case ran
MARKER = "precompiled.txt"

_FROM = re.compile(rb"^[ \t]*from[ \t]+(\.+)([\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^#\n]*)", re.M)
#: imports numba, or impstab's deferred numba decorator (impstab._jit: kernels compiled on demand)
_USES_NUMBA = re.compile(rb"^[ \t]*(?:(?:from|import)[ \t]+numba\b|from[ \t]+(?:\.+|impstab\.)_jit[ \t]+import\b)", re.M)
#: a compiled function defined here: a numba decorator, or one called on a function
_DEFINES_KERNEL = re.compile(
    rb"(?:^[ \t]*@[ \t]*(?:numba\.|nb\.)?|\b)(?:njit|jit|vectorize|guvectorize|cfunc|stencil|overload|intrinsic)\b[ \t]*[(\n]",
    re.M)
_ABSOLUTE = re.compile(rb"^[ \t]*(?:from|import)[ \t]+impstab((?:\.\w+)*)", re.M)


def _user_cache() -> Path:
    if os.name == "nt":  # pragma: no cover - not run on this platform
        base = os.environ.get("LOCALAPPDATA") or str(Path.home() / "AppData" / "Local")
        return Path(base) / "impstab" / "Cache"
    xdg = os.environ.get("XDG_CACHE_HOME", "")  # a relative one is ignored, as the specification says
    return Path(xdg if os.path.isabs(xdg) else Path.home() / ".cache") / "impstab"


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return False
    return os.access(folder, os.W_OK | os.X_OK)


def cache_root() -> Path:
    """The folder for impstab's caches (without the ``numba/<key>`` part): the user's cache folder,
    else (not writable) a writable virtual environment's ``var/cache/impstab``."""
    user = _user_cache()
    if _writable(user):
        return user
    environment = _environment_cache()
    if environment is not None and os.access(sys.prefix, os.W_OK):
        return environment.parent
    return user


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


def versions_tag() -> str:
    """The environment's part of a kernel's cache path: Python, numba, llvmlite and NumPy versions.

    Read from the installed distributions (about 40 ms), not by importing numba (0.25 s): the
    precompile step's check of a complete cache, at every ``make test`` and ``make demo``, needs
    no numba otherwise. numba's own index still refuses entries of another numba version.
    """
    from importlib.metadata import version

    return (f"py{sys.version_info[0]}{sys.version_info[1]}{getattr(sys, 'abiflags', '')}-numba{version('numba')}"
            f"-llvmlite{version('llvmlite')}-numpy{version('numpy')}")


def kernel_folder() -> Path:
    """The folder that holds this environment's compiled kernels (and precompile's marker):
    :func:`cache_dir` / :func:`versions_tag`."""
    return cache_dir() / versions_tag()


@functools.lru_cache(maxsize=None)
def _content_hash(path: str, mtime_ns: int, size: int) -> bytes:
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).digest()


def _inside_package(py_file: str) -> Path | None:
    try:
        return Path(py_file).resolve().parent.relative_to(PACKAGE.parent)
    except (OSError, ValueError):
        return None


def locate_by_package() -> None:
    """Put impstab's kernels in the cache by their path inside the package (once per process).

    numba chooses a function's cache folder with the first of its "locator" classes that accepts
    the function; the one added here in front accepts impstab's own source files while numba's
    cache folder is the one impstab set, and places them at :func:`kernel_folder` / ``impstab/<sub
    package>`` instead of a folder named after the clone's absolute path. Everything else (the
    index and data files, the check of the source file's contents) is numba's. Where numba has no
    such class list, or the user named locators (``NUMBA_CACHE_LOCATOR_CLASSES``), numba's layout
    stays: a second clone then compiles again, nothing worse.
    """
    try:
        from numba.core import caching, config
    except ImportError:  # pragma: no cover - a numba without that module
        return
    impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)  # older numba: "_" names
    base = getattr(caching, "UserProvidedCacheLocator", None) or getattr(caching, "_UserProvidedCacheLocator", None)
    if impl is None or base is None or not isinstance(getattr(impl, "_locator_classes", None), list):
        return
    if any(getattr(cls, "_impstab", False) for cls in impl._locator_classes):
        return
    tag = versions_tag()

    class PackageCacheLocator(base):  # type: ignore[misc, valid-type]
        """impstab's kernels under ``<NUMBA_CACHE_DIR>/<versions>/impstab/<subpackage>``."""

        _impstab = True

        def __init__(self, py_func, py_file):
            super().__init__(py_func, py_file)
            self._cache_path = os.path.join(config.CACHE_DIR, tag, *_inside_package(py_file).parts)

        def get_source_stamp(self):
            """The source file's contents (as recent numba versions do; older ones took its time stamp,
            which differs between clones)."""
            st = os.stat(self._py_file)
            return _content_hash(self._py_file, st.st_mtime_ns, st.st_size)

        @classmethod
        def from_function(cls, py_func, py_file):
            if (_inside_package(py_file) is None or not config.CACHE_DIR
                    or config.CACHE_DIR != os.environ.get(SET_BY_IMPSTAB)):
                return None
            return super().from_function(py_func, py_file)

    impl._locator_classes.insert(0, PackageCacheLocator)


def _environment_cache() -> Path | None:
    """The virtual environment's cache folder (the fallback of :func:`cache_root`; every kernel's
    home before the cache was shared), or ``None`` outside one."""
    return Path(sys.prefix) / "var" / "cache" / "impstab" / "numba" if sys.prefix != sys.base_prefix else None


def prune(keep: int = KEEP, environment: Path | None = None) -> list[Path]:
    """Remove the key folders of impstab's shared cache but the ``keep`` most recently compiled
    (and the current one), and the environment's own cache folder (``environment``, default that
    of the running virtual environment) when the shared one is in use; returns the folders
    removed. A process still loading from a removed folder compiles what it cannot find (numba
    treats a missing cache file as a miss)."""
    import shutil

    if user_setting():
        return []
    current = cache_dir()
    folders = [p for p in current.parent.glob("*") if p.is_dir() and p != current]

    def last_compiled(folder: Path) -> float:
        stamps = [m.stat().st_mtime for m in folder.glob(f"*/{MARKER}")]
        return max(stamps, default=folder.stat().st_mtime)

    folders.sort(key=last_compiled, reverse=True)
    removed = folders[max(0, keep - 1):]
    environment = environment if environment is not None else _environment_cache()
    if environment is not None and environment.is_dir() and environment != current.parent:
        removed.append(environment)
    for folder in removed:
        shutil.rmtree(folder, ignore_errors=True)
    return removed


def remove() -> None:
    """Take the finder of :func:`install` out of ``sys.meta_path`` (if there)."""
    while _BeforeNumba in sys.meta_path:
        sys.meta_path.remove(_BeforeNumba)  # type: ignore[arg-type]
