"""Compiled kernels that run as plain Python until compiling pays for itself.

impstab's hot loops are numba kernels. Importing numba (about 0.35 s of CPU) and loading the
kernels' machine code from the cache (0.2 s for the first kernel, which initialises numba's
code generator, then 10-60 ms each) costs far more than a single-model analysis, which is a
few milliseconds of arithmetic. So a kernel decorated with :func:`njit` here is the same
function run two ways:

* **interpreted** (the start of every process): the function's own Python source, called
  directly. numba is not imported. A kernel may name a faster plain-Python equivalent with
  ``interpreted=`` (e.g. the small-matrix QR iteration, which is fast compiled but slow
  interpreted, names LAPACK's ``geev`` through ``numpy.linalg.eigvals``, the same
  backward-stable algorithm);
* **compiled**: from the moment the process has spent :data:`BUDGET_S` seconds in interpreted
  kernels, or a caller announces a large piece of work with :func:`require_compiled` (a time
  integration, a study, a stack of many designs), numba is imported, every kernel becomes its
  numba dispatcher (loaded from impstab's cache, :mod:`impstab._numba_cache`) and every
  module's global name for it is rebound to the dispatcher, so that compiled kernels call
  compiled kernels. This happens once per process and is never undone.

Both ways run one implementation, so they give the same results up to the rounding of the
named equivalents (LAPACK against the compiled QR: a few eps of the matrix norm). Plain
Python raises ``ZeroDivisionError`` or ``OverflowError`` where the compiled kernels
(``error_model="numpy"``) produce ``inf`` or ``nan`` and go on; such a call is repeated
compiled, so the answers do not depend on which way ran.

``IMPSTAB_JIT`` chooses the policy: ``auto`` (the default, as above), ``compiled`` (compile
from the first call, e.g. for benchmarks of the kernels) or ``interpreted`` (never compile;
for debugging: very slow on time integrations).

Parameters of :func:`njit` are numba's (``cache``, ``error_model``, ``inline``, ``nogil``,
``_nrt``), passed on unchanged when the kernel is compiled.
"""

from __future__ import annotations

import functools
import os
import sys
import threading
from collections.abc import Callable
from contextlib import nullcontext
from time import thread_time
from typing import Any

__all__ = ["njit", "objmode", "on_compile", "require_compiled", "compiled", "announce_compiling", "COMPILING",
           "BUDGET_S", "Kernel"]

#: seconds of interpreted kernel time after which the process compiles (CPU time of the calling
#: thread, so that a loaded machine does not make the same analysis compile): numba's import, its code
#: generator's start and the cache loads of the linear kernels cost about 0.8 s of CPU once, so
#: an analysis that interprets for less than that is done sooner interpreted (a single model's
#: critical thrust takes 0.02-0.65 s interpreted); past it, compiling is cheaper than going on)
BUDGET_S = 0.75

_POLICIES = ("auto", "compiled", "interpreted")
_kernels: list["Kernel"] = []
_hooks: list[Callable[[], None]] = []
_lock = threading.RLock()
_local = threading.local()
_spent = 0.0
_compiled = False
#: called once with a line when the process next compiles (see :func:`announce_compiling`)
_announce: Callable[[str], None] | None = None
_listening = False
#: the line
COMPILING = ("impstab: compiling numba kernels for their first use on this machine, once (later runs load them "
             "from the cache; `python -m impstab.precompile` compiles them all ahead)")


def _policy() -> str:
    value = os.environ.get("IMPSTAB_JIT", "auto").strip().lower() or "auto"
    if value not in _POLICIES:
        from .errors import ModelError

        raise ModelError("environment variable IMPSTAB_JIT", value, f"must be one of {', '.join(_POLICIES)}")
    return value


class _ObjectMode:
    """``numba.objmode`` for interpreted kernels: the block simply runs (rebound when compiled)."""

    def __call__(self, *args: Any, **types: Any) -> nullcontext:
        return nullcontext()

    def __enter__(self) -> None:
        return None

    def __exit__(self, *exc: Any) -> None:
        return None


#: stands for ``numba.objmode`` in kernels' modules (``with objmode(status="int64"): ...``)
_SHIM = _ObjectMode()
objmode = _SHIM  # rebound to numba's own when the process compiles (for modules imported later)


class Kernel:
    """A kernel: its Python function until the process compiles, then its numba dispatcher."""

    def __init__(self, func: Callable, options: dict[str, Any], interpreted: Callable | None,
                 compile_first: bool = False) -> None:
        self.py_func = func
        self.compile_first = compile_first
        self.options = options
        self.interpreted = interpreted if interpreted is not None else func
        self.dispatcher: Any = None
        functools.update_wrapper(self, func)

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        dispatcher = self.dispatcher
        if dispatcher is not None:
            return dispatcher(*args, **kwargs)
        if getattr(_local, "depth", 0):
            return self.interpreted(*args, **kwargs)
        return _interpret(self, args, kwargs)

    def __getattr__(self, name: str) -> Any:
        # numba's dispatcher attributes (signatures, stats, inspect_types, ...) compile first
        if name.startswith("__"):
            raise AttributeError(name)
        require_compiled()
        return getattr(self.__dict__["dispatcher"], name)

    def __repr__(self) -> str:
        state = "compiled" if self.dispatcher is not None else "interpreted"
        return f"<impstab kernel {self.py_func.__module__}.{self.py_func.__qualname__} ({state})>"


def _interpret(kernel: Kernel, args: tuple, kwargs: dict) -> Any:
    global _spent
    if kernel.compile_first or _policy() == "compiled":
        require_compiled()
        if kernel.dispatcher is not None:
            return kernel.dispatcher(*args, **kwargs)
    _local.depth = 1
    start = thread_time()
    retry = False
    try:
        return kernel.interpreted(*args, **kwargs)
    except (ZeroDivisionError, OverflowError):
        retry = True  # IEEE arithmetic where Python raises: the compiled kernel's answer
    finally:
        _local.depth = 0
        _spent += thread_time() - start
        if retry or (_spent > BUDGET_S and _policy() == "auto"):
            require_compiled(force=retry)
    return kernel.dispatcher(*args, **kwargs)


def njit(func: Callable | None = None, *, interpreted: Callable | None = None, compile_first: bool = False,
         **options: Any) -> Any:
    """Declare a compiled kernel (``@njit(cache=True, ...)`` as numba's decorator).

    ``interpreted`` names a plain-Python function with the same arguments and effects, run
    instead of ``func``'s source while the process has not compiled. ``compile_first``: one
    call can be long (a time integration, a sweep over frequencies), so the process compiles
    before the first one (unless ``IMPSTAB_JIT=interpreted``).
    """
    def decorate(f: Callable) -> Any:
        with _lock:
            kernel = Kernel(f, options, interpreted, compile_first)
            if _compiled:
                import numba

                kernel.dispatcher = numba.njit(**options)(f)
                return kernel.dispatcher
            _kernels.append(kernel)
            return kernel

    return decorate(func) if func is not None else decorate


def on_compile(hook: Callable[[], None]) -> Callable[[], None]:
    """Run ``hook`` (e.g. numba ``overload`` registrations) when the process compiles."""
    with _lock:
        if _compiled:
            hook()
        else:
            _hooks.append(hook)
    return hook


def announce_compiling(write: Callable[[str], None] | None) -> None:
    """Call ``write`` with :data:`COMPILING` when this process next starts compiling a kernel (not
    when it loads one from the cache), once; ``None`` takes a writer back. The command line passes
    a writer to standard error, so that its user knows why the first run on a machine takes longer."""
    global _announce
    with _lock:
        _announce = write
        if _compiled and write is not None:
            _listen()


def _listen() -> None:
    """Register the listener of numba's compile events behind :func:`announce_compiling` (once)."""
    global _listening
    if _listening:
        return
    from numba.core import event
    from numba.core.dispatcher import LiftedCode

    class FirstCompile(event.Listener):
        def on_start(self, ev: Any) -> None:
            global _announce
            # an object-mode block (a lifted ``with objmode``) is made again in every process, even
            # of a kernel loaded from the cache: Python calls, milliseconds, no machine code
            if isinstance(ev.data.get("dispatcher"), LiftedCode):
                return
            write, _announce = _announce, None
            if write is not None:
                write(COMPILING)

        def on_end(self, ev: Any) -> None:
            return None

    event.register("numba:compile", FirstCompile())
    _listening = True


def compiled() -> bool:
    """Whether this process runs the compiled kernels."""
    return _compiled


def require_compiled(force: bool = False) -> None:
    """Compile from now on (a long piece of work follows); no effect under ``IMPSTAB_JIT=interpreted``.

    ``force`` compiles even then (a kernel's plain-Python arithmetic failed where IEEE
    arithmetic does not).
    """
    global _compiled
    if _compiled or (_policy() == "interpreted" and not force):
        return
    with _lock:
        if _compiled:
            return
        import numba

        from ._numba_cache import locate_by_package, lock_cache_files

        lock_cache_files()  # processes compiling into one cache at once (make compile, test workers)
        locate_by_package()  # kernels cached by their place in the package: shared by every clone
        for hook in _hooks:
            hook()
        for kernel in _kernels:
            kernel.dispatcher = numba.njit(**kernel.options)(kernel.py_func)
        _rebind(numba.objmode)
        globals()["objmode"] = numba.objmode
        if _announce is not None:
            _listen()
        _compiled = True


def _rebind(numba_objmode: Any) -> None:
    """Point every impstab module's names for kernels (and ``objmode``) at numba's objects."""
    for name, module in list(sys.modules.items()):
        if module is None or name == __name__ or not (name == "impstab" or name.startswith("impstab.")):
            continue
        namespace = vars(module)
        for attr, value in list(namespace.items()):
            if isinstance(value, Kernel):
                namespace[attr] = value.dispatcher
            elif value is _SHIM:
                namespace[attr] = numba_objmode

