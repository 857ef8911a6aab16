"""Load-dependent linear systems ``p -> (M, D, G, K)`` evaluated in batches.

A family is anything with ``n`` (number of dofs) and ``matrices(p)`` returning stacks
``(N, n, n)`` for an array of load values ``p``. :class:`LinearFamily` is the classical
``K = K0 + p K1``; :class:`CallableFamily` wraps a user function of one load value.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np
from numpy.typing import NDArray

__all__ = ["SystemFamily", "LinearFamily", "CallableFamily"]

Array = NDArray[np.float64]
Matrices = tuple[Array, Array, Array, Array]


class SystemFamily(Protocol):
    """Protocol of a one-parameter family of linear systems."""

    n: int

    def matrices(self, p: Array) -> Matrices:  # pragma: no cover - protocol
        """Stacks ``M, D, G, K`` of shape ``(len(p), n, n)``."""
        ...


def _square(name: str, a: object, n: int | None = None) -> Array:
    arr = np.asarray(a, dtype=float)
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1] or (n is not None and arr.shape[0] != n):
        raise ValueError(f"{name} must be a square {n or 'n'} x {n or 'n'} matrix, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} has non-finite entries")
    return arr


@dataclass(frozen=True, eq=False)
class LinearFamily:
    """``M q'' + (D + G) q' + (K0 + p K1) q = 0``."""

    M: Array
    K0: Array
    K1: Array
    D: Array
    G: Array

    @classmethod
    def build(cls, M, K0, K1, D=None, G=None) -> "LinearFamily":
        m = _square("M", M)
        n = m.shape[0]
        zero = np.zeros((n, n))
        return cls(
            m,
            _square("K0", K0, n),
            _square("K1", K1, n),
            zero if D is None else _square("D", D, n),
            zero if G is None else _square("G", G, n),
        )

    @property
    def n(self) -> int:
        return self.M.shape[0]

    def affine_parts(self) -> tuple[Array, Array, Array, Array, Array]:
        """``(M, D, G, K0, K1)``: the family is exactly affine in the load."""
        return self.M, self.D, self.G, self.K0, self.K1

    def matrices(self, p: Array) -> Matrices:
        p = np.atleast_1d(np.asarray(p, dtype=float))
        shape = (p.size, self.n, self.n)
        k = self.K0[None] + p[:, None, None] * self.K1[None]
        return (
            np.broadcast_to(self.M, shape),
            np.broadcast_to(self.D, shape),
            np.broadcast_to(self.G, shape),
            k,
        )


@dataclass(frozen=True, eq=False)
class CallableFamily:
    """Wrap ``func(p) -> (M, D, G, K)`` (one load value, ``n x n`` arrays, D or G may be None)."""

    func: Callable[[float], tuple]
    n: int

    def matrices(self, p: Array) -> Matrices:
        p = np.atleast_1d(np.asarray(p, dtype=float))
        out = np.zeros((4, p.size, self.n, self.n))
        for j, pj in enumerate(p):
            mats = self.func(float(pj))
            for i, a in enumerate(mats):
                if a is not None:
                    out[i, j] = a
        return out[0], out[1], out[2], out[3]
