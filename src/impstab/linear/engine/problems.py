"""Problems of the engine: one-parameter operator families, built from second- and first-order systems.

A :class:`Problem` is what the engine solves: the operator ``A(p)`` whose spectrum decides
stability on ``[p_min, p_max]``, given as ``A0 + p A1`` (affine) or by a provider (any other
family), and what the onset values need (the dofs of the mode, the participation weights).

* a second-order family ``M q'' + (D + G) q' + K(p) q = 0`` without damping and gyroscopic terms
  is an *undamped* problem: ``A = M^-1 K`` with eigenvalues ``s = omega^2`` (stable: all real and
  positive), ``n`` states;
* with damping or gyroscopic terms it is a first-order problem on ``x = (q, q')``:
  ``A = [[0, I], [-M^-1 K, -M^-1 (D + G)]]``, ``2 n`` states, eigenvalues ``lambda`` (stable: all
  ``Re lambda < 0``); the mode and the participation are those of ``q``;
* a first-order family ``E x' = A(p) x`` is a first-order problem with ``A = E^-1 A(p)``; its
  first ``n_dof`` states are the ones the mode and participation are reported for.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..._jit import njit

from ..eigen import state_matrices
from ..small_eigvec import _lu, _lu_solve
from .large import LARGE_ORDER

__all__ = ["Problem", "second_order_problem", "first_order_problem", "mass_solve"]

Array = NDArray[np.float64]


@dataclass(eq=False)
class Problem:
    """One critical-load search.

    Attributes
    ----------
    undamped : bool
        Eigenvalues are ``s = omega^2`` of ``M^-1 K`` (True) or ``lambda`` of a first-order
        operator (False).
    p_min, p_max : float
        Load range.
    n_scan : int
        Scan intervals on it.
    order : int
        Order ``N`` of the operator.
    n_dof : int
        Leading states in the reported mode and participation.
    a0, a1 : (N, N) arrays or None
        ``A = a0 + p a1`` for affine problems.
    weights : (n_dof,) array
        Participation weights (mass diagonal), for affine problems.
    second_order : tuple of arrays or None
        ``(M, K0, K1)`` of an affine second-order problem (for the reduction of large ones,
        :mod:`impstab.linear.engine.large`).
    damping : array or None
        ``D + G`` of an affine damped second-order problem (with ``second_order``).
    provider : object or None
        For the others: ``operators(loads) -> (m, N, N)`` (NaN where no operator exists),
        ``weights(p) -> (n_dof,)``, and ``fold_indicator(p) -> float`` (the square of the
        smallest eigenvalue magnitude of the static problem, for limit points).
    """

    undamped: bool
    p_min: float
    p_max: float
    n_scan: int
    order: int
    n_dof: int
    a0: Array | None = None
    a1: Array | None = None
    weights: Array | None = None
    provider: object | None = None
    second_order: tuple | None = None
    damping: Array | None = None

    @property
    def affine(self) -> bool:
        return self.a0 is not None or self.second_order is not None

    def operators(self) -> tuple[Array, Array]:
        """``(a0, a1)`` of an affine problem (formed from ``second_order`` when first needed)."""
        if self.a0 is None:
            m, k0, k1 = self.second_order
            self.a0, self.a1 = mass_solve(m[None], np.array([[k0, k1]]))[0]
        return self.a0, self.a1


@njit(cache=True, error_model="numpy")
def _solve_into(m, rhs, out):
    """``out[s, r] = m[s]^-1 rhs[s, r]`` by LU with partial pivoting; False where an ``m[s]`` is singular.

    Only the band of rows from the first to the last that differ from the identity's is solved:
    with those rows ``b``, ``m = [[I, 0, 0], [m_b0, m_bb, m_b2], [0, 0, I]]`` and the solution keeps
    ``rhs``'s other rows, with ``m_bb^-1 (rhs_b - m_b0 rhs_0 - m_b2 rhs_2)`` on the band, exactly
    (an augmented state's ``E = diag(I, M, I)``: a system of the order of ``M``; a mass matrix is one
    band, all of it).
    """
    count, n = m.shape[0], m.shape[1]
    b = np.empty((n, n))
    piv = np.empty(n, dtype=np.int64)
    x = np.empty(n)
    for s in range(count):
        r0, r1 = n, 0
        for i in range(n):
            for j in range(n):
                if m[s, i, j] != (1.0 if i == j else 0.0):
                    r0 = min(r0, i)
                    r1 = i + 1
                    break
        k = max(r1 - r0, 0)
        for i in range(k):
            for j in range(k):
                b[i, j] = m[s, r0 + i, r0 + j]
        if _lu(b, k, piv, 0.0):
            return False
        for r in range(rhs.shape[1]):
            for c in range(n):
                for i in range(n):
                    out[s, r, i, c] = rhs[s, r, i, c]
                for i in range(k):
                    acc = rhs[s, r, r0 + i, c]
                    for j in range(r0):
                        acc -= m[s, r0 + i, j] * rhs[s, r, j, c]
                    for j in range(r1, n):
                        acc -= m[s, r0 + i, j] * rhs[s, r, j, c]
                    x[i] = acc
                _lu_solve(b, k, piv, x)
                for i in range(k):
                    out[s, r, r0 + i, c] = x[i]
    return True


def mass_solve(m: Array, rhs: Array) -> Array:
    """``m^-1 rhs`` for stacks ``m (J, n, n)``, ``rhs (J, r, n, n)``: compiled, one call for a batch.

    The operators of affine problems (``M^-1 K0``, ``M^-1 K1``; ``E^-1 A0``, ``E^-1 A1``) come from
    here, for one model and for a design study alike. Raises ``numpy.linalg.LinAlgError`` for a
    singular matrix.
    """
    out = np.empty(rhs.shape)
    if not _solve_into(np.ascontiguousarray(m, dtype=float), np.ascontiguousarray(rhs, dtype=float), out):
        raise np.linalg.LinAlgError("Singular matrix")
    return out


def _static_fold_indicator(m: Array, k: Array) -> float:
    """The square of the smallest eigenvalue magnitude of ``M^-1 K`` (NaN where ``K`` is not finite:
    no static equilibrium): linear in the load at a fold of the static path."""
    if not np.isfinite(k).all():
        return np.nan
    s = np.linalg.eigvals(np.linalg.solve(m, k))
    return float(np.min(np.abs(s)) ** 2)


class _SecondOrderProvider:
    """Operators of a second-order family that is not affine (``family.matrices`` per load)."""

    def __init__(self, family, undamped: bool) -> None:
        self.family = family
        self.undamped = undamped
        self.error: BaseException | None = None
        self._mass: dict[float, Array] = {}

    def operators(self, loads: Array) -> Array:
        m, d, g, k = self.family.matrices(np.asarray(loads, dtype=float))
        n = m.shape[-1]
        size = n if self.undamped else 2 * n
        out = np.full((len(loads), size, size), np.nan)
        good = np.isfinite(m).all(axis=(1, 2)) & np.isfinite(k).all(axis=(1, 2)) & np.isfinite(d + g).all(axis=(1, 2))
        if good.any():
            if self.undamped:
                out[good] = np.linalg.solve(m[good], k[good])
            else:
                out[good] = state_matrices(m[good], (d + g)[good], k[good])
        for p, mm in zip(loads, m):
            self._mass[float(p)] = np.diag(mm).copy()
        if len(self._mass) > 4096:
            self._mass.clear()
        return out

    def weights(self, p: float) -> Array:
        hit = self._mass.get(float(p))
        if hit is None:
            hit = np.diag(self.family.matrices(np.array([p]))[0][0]).copy()
        return hit

    def fold_indicator(self, p: float) -> float:
        m, _, _, k = self.family.matrices(np.array([p]))
        return _static_fold_indicator(m[0], k[0])


class _GyroscopicLawProvider:
    """Operators of an affine second-order family whose gyroscopic matrix follows a scalar law of
    the load, ``G(p) = law(p) G1`` (a propeller whose speed grows as the square root of the thrust:
    ``law`` its speed, ``G1`` per unit speed).

    ``A(p) = A0 + p A1 + law(p) A2`` with ``A0 = [[0, I], [-M^-1 K0, -M^-1 D]]``,
    ``A1 = [[0, 0], [-M^-1 K1, 0]]`` and ``A2 = [[0, 0], [0, -M^-1 G1]]``, formed once: a load then
    costs two scaled sums (about 10 us) where :class:`_SecondOrderProvider` linearizes the model and
    solves with ``M`` (about 200 us), and the engine asks a provider for one load at a time in its
    refinement and bubble searches (about 100 loads per critical thrust).
    """

    def __init__(self, m: Array, d: Array, g1: Array, k0: Array, k1: Array, law) -> None:
        n = m.shape[0]
        self.error: BaseException | None = None
        self.law = law
        self.a0 = state_matrices(m, d, k0)
        solved = np.linalg.solve(m, np.concatenate([k1, g1], axis=1))
        self.a1 = np.zeros_like(self.a0)
        self.a1[n:, :n] = -solved[:, :n]
        self.a2 = np.zeros_like(self.a0)
        self.a2[n:, n:] = -solved[:, n:]
        self._mass, self._k = m, (k0, k1)
        self._weights = np.diag(m).copy()

    def operators(self, loads: Array) -> Array:
        loads = np.asarray(loads, dtype=float)
        return self.a0 + loads[:, None, None] * self.a1 + self.law(loads)[:, None, None] * self.a2

    def weights(self, p: float) -> Array:
        return self._weights

    def fold_indicator(self, p: float) -> float:
        k0, k1 = self._k
        return _static_fold_indicator(self._mass, k0 + p * k1)


class _FirstOrderProvider:
    """Operators ``E^-1 A(p)`` of a first-order family that is not affine."""

    def __init__(self, family) -> None:
        self.family = family
        self.error: BaseException | None = None
        self._weights = np.asarray(getattr(family, "weights", None) if getattr(family, "weights", None) is not None
                                   else np.ones(family.n_dof), dtype=float)

    def operators(self, loads: Array) -> Array:
        e, a = self.family.matrices(np.asarray(loads, dtype=float))
        out = np.full(a.shape, np.nan)
        good = np.isfinite(e).all(axis=(1, 2)) & np.isfinite(a).all(axis=(1, 2))
        if good.any():
            out[good] = np.linalg.solve(e[good], a[good])
        return out

    def weights(self, p: float) -> Array:
        return self._weights

    def fold_indicator(self, p: float) -> float:
        op = self.operators(np.array([p]))[0]
        if not np.isfinite(op).all():
            return np.nan
        return float(np.min(np.abs(np.linalg.eigvals(op))) ** 2)


def _range(family, p_min: float, p_max: float, n_scan: int):
    if not (math.isfinite(p_max) and math.isfinite(p_min) and p_max > p_min):
        raise ValueError(f"p_max = {p_max!r}: must be finite and above p_min = {p_min!r}")
    if int(n_scan) < 1:
        raise ValueError(f"n_scan = {n_scan!r}: must be at least 1")
    return float(p_min), float(p_max), int(n_scan)


def second_order_problem(family, p_max: float, *, p_min: float = 0.0, n_scan: int = 64,
                         undamped: bool | None = None) -> Problem:
    """The problem of a second-order family ``p -> (M, D, G, K)`` (:class:`~impstab.linear.SystemFamily`).

    ``undamped`` forces the undamped (``s``) or the first-order form; by default the undamped form
    is used where D and G vanish (affine families: exactly; families that say so by
    ``undamped_nongyroscopic = True``: by their structure; others: at ``p_min``, the middle and
    ``p_max``, since damping and gyroscopic terms may follow the load).
    """
    p_min, p_max, n_scan = _range(family, p_min, p_max, n_scan)
    parts = family.affine_parts() if hasattr(family, "affine_parts") else None
    if parts is not None:
        parts = [np.asarray(x, dtype=float) for x in parts]
        d, g = parts[1], parts[2]
    elif getattr(family, "undamped_nongyroscopic", False):
        d = g = np.zeros((1, 1))  # the family's structure: no damper and no gyroscopic term at any load
    else:
        _, d, g, _ = family.matrices(np.array([p_min, 0.5 * (p_min + p_max), p_max]))
        # a load without a static equilibrium gives NaN matrices: they say nothing about damping
        finite = np.isfinite(d).all(axis=(-2, -1)) & np.isfinite(g).all(axis=(-2, -1))
        if finite.any():
            d, g = d[finite], g[finite]
    if undamped is None:
        undamped = not (d.any() or g.any())
    n = int(family.n)
    if parts is None:
        law_parts = None if undamped or not hasattr(family, "gyroscopic_law_parts") else family.gyroscopic_law_parts()
        provider = (_GyroscopicLawProvider(*(np.asarray(x, dtype=float) for x in law_parts[:5]), law_parts[5])
                    if law_parts is not None else _SecondOrderProvider(family, bool(undamped)))
        return Problem(bool(undamped), p_min, p_max, n_scan, n if undamped else 2 * n, n, provider=provider)
    m, d, g, k0, k1 = parts
    if undamped:
        problem = Problem(True, p_min, p_max, n_scan, n, n, weights=m.diagonal().copy(), second_order=(m, k0, k1))
        if n <= LARGE_ORDER:  # a large one may be reduced: its operators are formed only if needed
            problem.operators()
        return problem
    a0 = state_matrices(m, d + g, k0)
    a1 = np.zeros_like(a0)
    a1[n:, :n] = -np.linalg.solve(m, k1)
    return Problem(False, p_min, p_max, n_scan, a0.shape[0], n, a0, a1, np.diag(m).copy(), second_order=(m, k0, k1),
                   damping=d + g)


def first_order_problem(family, p_max: float, *, p_min: float = 0.0, n_scan: int = 64) -> Problem:
    """The problem of a first-order family ``E x' = A(p) x`` (:class:`~impstab.linear.FirstOrderFamily`)."""
    p_min, p_max, n_scan = _range(family, p_min, p_max, n_scan)
    n = int(family.n)
    n_dof = int(getattr(family, "n_dof", n) or n)
    parts = family.affine_parts() if hasattr(family, "affine_parts") else None
    if parts is None:
        return Problem(False, p_min, p_max, n_scan, n, n_dof, provider=_FirstOrderProvider(family))
    e, a0, a1 = (np.asarray(x, dtype=float) for x in parts)
    a0, a1 = mass_solve(e[None], np.array([[a0, a1]]))[0]
    weights = getattr(family, "weights", None)
    weights = np.ones(n_dof) if weights is None else np.asarray(weights, dtype=float)
    return Problem(False, p_min, p_max, n_scan, n, n_dof, a0, a1, weights.copy())
