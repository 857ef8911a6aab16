"""Ctrl-C held back while a step must not be cut half-way.

Python raises ``KeyboardInterrupt`` between any two bytecodes of the main thread. A step that
makes something another step must clean up (a store this run created, a Dask cluster starting)
is not safe against that: an interrupt after the thing exists but before the code that would
clean it up holds it leaves it behind. :func:`interrupt_held` notes a SIGINT instead, and raises
it once the block has ended.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

__all__ = ["interrupt_held"]


@contextlib.contextmanager
def interrupt_held(raise_after: bool = True) -> Iterator[None]:
    """A SIGINT in the block is noted instead of raised.

    With ``raise_after`` it is raised as ``KeyboardInterrupt`` when the block has ended (also when
    the block failed meanwhile: the interrupt is what the user asked for); without, it is dropped
    (for a block that ends the run anyway). Outside the main thread, where Python delivers no
    SIGINT, the block simply runs.
    """
    main = threading.current_thread() is threading.main_thread()
    caught: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda sig, frame: caught.append(sig)) if main else None
    try:
        yield
    except BaseException:
        if caught and raise_after:
            raise KeyboardInterrupt from None
        raise
    finally:
        if main:
            signal.signal(signal.SIGINT, previous)
    if caught and raise_after:
        raise KeyboardInterrupt
