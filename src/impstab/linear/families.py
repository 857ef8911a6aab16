"""Load-dependent linear systems evaluated in batches: second order and first order.

A second-order family (:class:`SystemFamily`) is anything with ``n`` (number of dofs) and
``matrices(p)`` returning stacks ``M, D, G, K`` of shape ``(N, n, n)`` for an array of load values
``p``. :class:`LinearFamily` is the classical ``K = K0 + p K1``; :class:`CallableFamily` wraps a
user function of one load value.

A first-order family (:class:`FirstOrderFamily`) describes ``E x' = A(p) x`` with ``n`` states:
``matrices(p)`` returns stacks ``E, A``. Its first ``n_dof`` states are the displacements that
mode shapes and participation are reported for (all of them by default), with the
participation ``weights`` (a mass diagonal; ones by default). :class:`LinearFirstOrderFamily` is
``A = A0 + p A1``; :class:`CallableFirstOrderFamily` wraps a user function. A model with internal
states (viscoelastic mounts, the finite-element dofs of a massive mount) hands the engine such a
family of its augmented state, ``n_dof = 6`` and the rigid-body mass diagonal as weights.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np
from numpy.typing import NDArray

__all__ = ["SystemFamily", "LinearFamily", "CallableFamily", "FirstOrderFamily", "LinearFirstOrderFamily",
           "CallableFirstOrderFamily"]

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
    if not np.isfinite(arr).all():
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


class FirstOrderFamily(Protocol):
    """Protocol of a one-parameter family ``E x' = A(p) x`` (E invertible)."""

    n: int
    n_dof: int

    def matrices(self, p: Array) -> tuple[Array, Array]:  # pragma: no cover - protocol
        """Stacks ``E, A`` of shape ``(len(p), n, n)``."""
        ...


def _dofs(n: int, n_dof: int | None, weights) -> tuple[int, Array]:
    n_dof = n if n_dof is None else int(n_dof)
    if not 1 <= n_dof <= n:
        raise ValueError(f"n_dof = {n_dof!r}: must be between 1 and the number of states {n}")
    w = np.ones(n_dof) if weights is None else np.asarray(weights, dtype=float).reshape(-1)
    if w.shape != (n_dof,) or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ValueError(f"weights must be {n_dof} finite numbers >= 0, got {np.asarray(weights).tolist()}")
    return n_dof, w


@dataclass(frozen=True, eq=False)
class LinearFirstOrderFamily:
    """``E x' = (A0 + p A1) x``.

    Attributes
    ----------
    E, A0, A1 : (n, n) arrays
        ``E`` invertible (the identity when not given).
    n_dof : int
        Leading states reported in the mode and the participation.
    weights : (n_dof,) array
        Participation weights of those states (e.g. their masses).
    """

    E: Array
    A0: Array
    A1: Array
    n_dof: int
    weights: Array
    first_order = True

    @classmethod
    def build(cls, A0, A1, E=None, n_dof: int | None = None, weights=None) -> "LinearFirstOrderFamily":
        a0 = _square("A0", A0)
        n = a0.shape[0]
        a1 = _square("A1", A1, n)
        e = np.eye(n) if E is None else _square("E", E, n)
        if np.linalg.cond(e) > 1e14:
            raise ValueError("E must be invertible (its condition number exceeds 1e14)")
        n_dof, w = _dofs(n, n_dof, weights)
        return cls(e, a0, a1, n_dof, w)

    @property
    def n(self) -> int:
        return self.A0.shape[0]

    def affine_parts(self) -> tuple[Array, Array, Array]:
        """``(E, A0, A1)``: the family is exactly affine in the load."""
        return self.E, self.A0, self.A1

    def matrices(self, p: Array) -> tuple[Array, Array]:
        p = np.atleast_1d(np.asarray(p, dtype=float))
        shape = (p.size, self.n, self.n)
        return np.broadcast_to(self.E, shape), self.A0[None] + p[:, None, None] * self.A1[None]


@dataclass(frozen=True, eq=False)
class CallableFirstOrderFamily:
    """Wrap ``func(p) -> A`` or ``func(p) -> (E, A)`` (one load value, ``n x n`` arrays).

    ``E`` (constant) is used where ``func`` returns ``A`` alone; the identity when not given.
    """

    func: Callable[[float], object]
    n: int
    E: Array | None = None
    n_dof: int = 0
    weights: Array | None = None
    first_order = True

    @classmethod
    def build(cls, func, E=None, n_dof: int | None = None, weights=None) -> "CallableFirstOrderFamily":
        first = func(0.0)
        a = first[1] if isinstance(first, tuple) else first
        n = np.asarray(a).shape[0]
        e = None if E is None else _square("E", E, n)
        n_dof, w = _dofs(n, n_dof, weights)
        return cls(func, n, e, n_dof, w)

    def matrices(self, p: Array) -> tuple[Array, Array]:
        p = np.atleast_1d(np.asarray(p, dtype=float))
        e = np.empty((p.size, self.n, self.n))
        a = np.empty((p.size, self.n, self.n))
        for j, pj in enumerate(p):
            out = self.func(float(pj))
            if isinstance(out, tuple):
                e[j], a[j] = out
            else:
                e[j] = np.eye(self.n) if self.E is None else self.E
                a[j] = out
        return e, a
