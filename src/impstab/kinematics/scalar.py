"""Elementary functions for compiled code that runs on real and on complex numbers alike.

``sqrt``, ``sin``, ``cos`` and ``acos`` are ``math``'s functions for a real argument and
``cmath``'s (their analytic continuations) for a complex one. Compiled code written with them,
with comparisons on ``x.real`` only, gets a complex128 specialisation from numba, so that
complex-step and Cauchy-integral derivatives of it are exact (THEORY 7; used by the nonlinear
right-hand side and the mount laws). For a real argument the compiled and the plain-Python
(:mod:`impstab._jit`'s interpreted) paths call the same C library function, so both give identical bits.
"""

from __future__ import annotations

import cmath
import math

from .._jit import on_compile

__all__ = ["sqrt", "sin", "cos", "acos"]


def sqrt(x):
    """Square root; complex argument: principal branch (analytic off the negative real axis)."""
    return cmath.sqrt(x) if isinstance(x, complex) else math.sqrt(x)


def sin(x):
    """Sine of a real or complex argument."""
    return cmath.sin(x) if isinstance(x, complex) else math.sin(x)


def cos(x):
    """Cosine of a real or complex argument."""
    return cmath.cos(x) if isinstance(x, complex) else math.cos(x)


def acos(x):
    """Arc cosine; complex argument: principal branch (analytic off ``|Re x| > 1``)."""
    return cmath.acos(x) if isinstance(x, complex) else math.acos(x)


@on_compile
def _register() -> None:
    """Give numba the real and complex specialisations (when the process compiles its kernels)."""
    from numba import types
    from numba.extending import overload

    def pair(real, cplx):
        def typer(x):
            if isinstance(x, types.Complex):
                return lambda x: cplx(x)
            if isinstance(x, (types.Float, types.Integer)):
                return lambda x: real(x)
            return None
        return typer

    overload(sqrt)(pair(math.sqrt, cmath.sqrt))
    overload(sin)(pair(math.sin, cmath.sin))
    overload(cos)(pair(math.cos, cmath.cos))
    overload(acos)(pair(math.acos, cmath.acos))
