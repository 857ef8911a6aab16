"""Orthogonal collocation of periodic orbits: piecewise polynomials on a mesh of [0, 1].

The orbit of period ``T`` is written in the scaled time ``tau = t / T`` on a mesh
``0 = tau_0 < ... < tau_N = 1``. On interval ``i`` (length ``h_i``) the state is the polynomial of
degree ``m`` through its values at ``m + 1`` equally spaced nodes (AUTO's representation); the
last node of an interval is the first of the next, and the node at ``tau = 1`` is the node at
``tau = 0`` (periodicity is built in). The collocation equations hold at the ``m`` Gauss-Legendre
points ``c_k`` of every interval::

    B x'(tau_ik) - T h_i f(x(tau_ik), p) = 0        (x' = d/ds, s the local coordinate in [0, 1])

which gives ``N m n`` equations for the ``N m n`` nodal values (plus the period and the parameter,
fixed by the phase condition and the continuation constraint). Collocation at Gauss points is
superconvergent: ``O(h^2m)`` at the mesh points and in the period, ``O(h^(m+1))`` in between.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

__all__ = ["Scheme", "scheme", "Profile", "interval_nodes", "node_weights"]

Array = NDArray[np.float64]

#: Newton polish of an extremum of a piecewise polynomial
EXTREMUM_ITERATIONS = 8


@dataclass(frozen=True, eq=False)
class Scheme:
    """Local matrices of the degree-``m`` collocation on the unit interval.

    ``value[k, j] = L_j(c_k)``, ``derivative[k, j] = L_j'(c_k)`` at the Gauss points ``c_k``;
    ``node_derivative[i, j] = L_j'(s_i)`` at the nodes; ``weights[j] = int_0^1 L_j``;
    ``top[j]`` the (constant) ``m``-th derivative of ``L_j``; ``power[k, j]`` the coefficient of
    ``s^k`` in ``L_j``.
    """

    degree: int
    nodes: Array
    points: Array
    value: Array
    derivative: Array
    node_derivative: Array
    weights: Array
    top: Array
    power: Array
    error_constant: float

    def basis(self, s: Array) -> Array:
        """``L_j(s)`` for local coordinates ``s`` (any shape) -> ``s.shape + (m + 1,)``."""
        return _lagrange(self.nodes, np.asarray(s, dtype=float), 0)

    def basis_derivative(self, s: Array, order: int = 1) -> Array:
        s = np.asarray(s, dtype=float)
        k = np.arange(self.degree + 1)
        coef = np.ones(self.degree + 1)
        for j in range(order):
            coef = coef * np.clip(k - j, 0, None)
        pw = np.where(k >= order, s[..., None] ** np.clip(k - order, 0, None), 0.0) * coef
        return pw @ self.power


@lru_cache(maxsize=None)
def scheme(degree: int) -> Scheme:
    """The collocation scheme of ``degree`` (2 to 7; AUTO's NCOL)."""
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or not 2 <= degree <= 7:
        raise ValueError(f"degree = {degree!r}: must be an integer from 2 to 7")
    m = int(degree)
    nodes = np.linspace(0.0, 1.0, m + 1)
    # L_j(s) = sum_k power[k, j] s^k: the inverse of the nodes' Vandermonde matrix in exact rational
    # arithmetic (its condition number reaches 1e5 at degree 7, and a float inverse loses that much)
    exact = [Fraction(j, m) for j in range(m + 1)]
    power = np.array(_rational_inverse([[x ** k for k in range(m + 1)] for x in exact]), dtype=float)
    g, gw = np.polynomial.legendre.leggauss(m)
    points = 0.5 * (g + 1.0)
    # the local matrices from the product form of the Lagrange polynomials (a few eps; the power
    # form sums coefficients of size 1e3 with alternating signs)
    value = _lagrange(nodes, points, 0)
    derivative = _lagrange(nodes, points, 1)
    node_derivative = _lagrange(nodes, nodes, 1)
    weights = 0.5 * gw @ value                     # Gauss-Legendre with m points: exact to degree 2m - 1
    top = np.array([float(np.prod(np.arange(1, m + 1)) / np.prod([xj - xi for xi in exact if xi != xj]))
                    for xj in exact])
    fine = np.linspace(0.0, 1.0, 2001)
    err = float(np.max(np.abs(np.prod(fine[:, None] - points[None, :], axis=1)))) / float(np.prod(np.arange(1, m + 2)))
    return Scheme(m, nodes, points, value, derivative, node_derivative, weights, top, power, err)


def _lagrange(nodes: Array, s: Array, order: int) -> Array:
    """``L_j(s)`` (``order = 0``) or ``L_j'(s)`` (1) of the nodes, ``s.shape + (m + 1,)``, from the
    product form: ``L_j = prod_{i != j} (s - x_i) / (x_j - x_i)`` and
    ``L_j' = sum_{k != j} 1 / (x_j - x_k) prod_{i != j, k} (s - x_i) / (x_j - x_i)``."""
    n = nodes.size
    diff = s[..., None] - nodes                                        # (..., n)
    out = np.zeros(s.shape + (n,))
    for j in range(n):
        others = [i for i in range(n) if i != j]
        scale = nodes[j] - nodes[others]
        if order == 0:
            out[..., j] = np.prod(diff[..., others] / scale, axis=-1)
            continue
        for k in others:
            rest = [i for i in others if i != k]
            out[..., j] += np.prod(diff[..., rest] / (nodes[j] - nodes[rest]), axis=-1) / (nodes[j] - nodes[k])
    return out


def _rational_inverse(rows: list[list[Fraction]]) -> list[list[Fraction]]:
    """The inverse of a square matrix of fractions (Gauss-Jordan, exact)."""
    n = len(rows)
    a = [list(r) + [Fraction(int(i == j)) for j in range(n)] for i, r in enumerate(rows)]
    for c in range(n):
        piv = next(r for r in range(c, n) if a[r][c] != 0)
        a[c], a[piv] = a[piv], a[c]
        inv = 1 / a[c][c]
        a[c] = [v * inv for v in a[c]]
        for r in range(n):
            if r != c and a[r][c] != 0:
                f = a[r][c]
                a[r] = [v - f * w for v, w in zip(a[r], a[c])]
    return [r[n:] for r in a]


def interval_nodes(intervals: int, degree: int) -> NDArray[np.intp]:
    """Global node index of local node ``j`` of interval ``i``, ``(N, m + 1)``, periodic."""
    idx = np.arange(intervals)[:, None] * degree + np.arange(degree + 1)[None, :]
    return idx % (intervals * degree)


def node_weights(mesh: Array, sch: Scheme) -> Array:
    """Quadrature weights of the nodal values for ``int_0^1 (.) dtau``, ``(N m,)``."""
    h = np.diff(mesh)
    n_int = h.size
    w = np.zeros(n_int * sch.degree)
    np.add.at(w, interval_nodes(n_int, sch.degree), h[:, None] * sch.weights[None, :])
    return w


@dataclass(frozen=True, eq=False)
class Profile:
    """A periodic piecewise polynomial on a mesh: the shape of one cycle over ``tau in [0, 1)``.

    Attributes
    ----------
    mesh : (N + 1,) array
        ``0 = tau_0 < ... < tau_N = 1``.
    nodes : (N m, n) array
        Nodal values (the node at ``tau = 1`` is node 0).
    degree : int
    """

    mesh: Array
    nodes: Array
    degree: int

    @property
    def intervals(self) -> int:
        return self.mesh.size - 1

    @property
    def scheme(self) -> Scheme:
        return scheme(self.degree)

    @property
    def widths(self) -> Array:
        return np.diff(self.mesh)

    def local(self) -> Array:
        """Nodal values per interval, ``(N, m + 1, n)``."""
        return self.nodes[interval_nodes(self.intervals, self.degree)]

    def node_times(self) -> Array:
        """``tau`` of the nodes, ``(N m,)``."""
        h = self.widths
        return (self.mesh[:-1, None] + h[:, None] * self.scheme.nodes[None, :-1]).reshape(-1)

    def _locate(self, tau: Array) -> tuple[NDArray[np.intp], Array]:
        t = np.mod(np.asarray(tau, dtype=float), 1.0)
        i = np.clip(np.searchsorted(self.mesh, t, side="right") - 1, 0, self.intervals - 1)
        s = (t - self.mesh[i]) / self.widths[i]
        return i, s

    def __call__(self, tau: Array) -> Array:
        """States at scaled times ``tau`` (periodic), ``tau.shape + (n,)``."""
        i, s = self._locate(tau)
        return np.einsum("...j,...jn->...n", self.scheme.basis(s), self.local()[i])

    def derivative(self, tau: Array) -> Array:
        """``dx/dtau`` at ``tau``."""
        i, s = self._locate(tau)
        d = np.einsum("...j,...jn->...n", self.scheme.basis_derivative(s), self.local()[i])
        return d / self.widths[i][..., None]

    def node_derivatives(self) -> Array:
        """``dx/dtau`` at the nodes of each interval, from that interval's polynomial, ``(N, m + 1, n)``."""
        loc = self.local()
        return np.einsum("ij,kjn->kin", self.scheme.node_derivative, loc) / self.widths[:, None, None]

    def collocation_states(self) -> tuple[Array, Array]:
        """States and local derivatives ``dx/ds`` at the Gauss points, each ``(N, m, n)``."""
        loc = self.local()
        sch = self.scheme
        return np.einsum("kj,ijn->ikn", sch.value, loc), np.einsum("kj,ijn->ikn", sch.derivative, loc)

    def top_derivative(self) -> Array:
        """The ``m``-th derivative ``d^m x / dtau^m`` on each interval (constant), ``(N, n)``."""
        return np.einsum("j,ijn->in", self.scheme.top, self.local()) / self.widths[:, None] ** self.degree

    def extrema(self) -> tuple[Array, Array]:
        """Minimum and maximum of each state over the period, ``(n,)`` each, exact to rounding.

        Dense sampling brackets each extremum; Newton's method on the polynomial's derivative
        polishes it (the piecewise polynomial itself, not the samples, is measured).
        """
        sch = self.scheme
        m = self.degree
        coef = np.einsum("kj,ijn->ikn", sch.power, self.local())            # (N, m+1, n): coefficient of s^k
        k = 4 * m + 1
        s = np.linspace(0.0, 1.0, k)
        vals = np.einsum("sk,ikn->isn", s[:, None] ** np.arange(m + 1), coef)  # (N, k, n)
        n = vals.shape[-1]
        flat = vals.reshape(-1, n)
        sign = np.concatenate([np.ones(n), -np.ones(n)])                     # maxima, then minima
        cols = np.concatenate([np.arange(n), np.arange(n)])
        j = np.argmax(sign[None, :] * flat[:, cols], axis=0)
        iv, sv = j // k, s[j % k]
        # a sample on a mesh point: the extremum may lie in the neighbouring interval; polish both
        n_int = coef.shape[0]
        iv2 = np.where(sv == 0.0, (iv - 1) % n_int, np.where(sv == 1.0, (iv + 1) % n_int, iv))
        sv2 = np.where(sv == 0.0, 1.0, np.where(sv == 1.0, 0.0, sv))
        iv, sv = np.concatenate([iv, iv2]), np.concatenate([sv, sv2])
        sign, cols = np.concatenate([sign, sign]), np.concatenate([cols, cols])
        c = coef[iv, :, cols]                                                # (4n, m+1)
        best = sign * np.sum(c * sv[:, None] ** np.arange(m + 1), axis=1)
        powers = np.arange(m + 1)
        for _ in range(EXTREMUM_ITERATIONS):
            d1 = np.sum(c[:, 1:] * powers[1:] * sv[:, None] ** (powers[1:] - 1), axis=1)
            d2 = np.sum(c[:, 2:] * powers[2:] * (powers[2:] - 1) * sv[:, None] ** (powers[2:] - 2), axis=1)
            ok = sign * d2 < 0
            s_new = np.where(ok, sv - d1 / np.where(ok, d2, 1.0), sv)
            s_new = np.clip(s_new, 0.0, 1.0)
            val = sign * np.sum(c * s_new[:, None] ** powers, axis=1)
            better = val >= best
            sv = np.where(better, s_new, sv)
            best = np.where(better, val, best)
        best = np.maximum(best[: 2 * n], best[2 * n:])
        return -best[n:], best[:n]

    def amplitude(self) -> Array:
        """Half the peak-to-peak of each state over the period, ``(n,)``."""
        lo, hi = self.extrema()
        return 0.5 * (hi - lo)

    def mean(self) -> Array:
        """Time average of each state over the period, ``(n,)``."""
        return node_weights(self.mesh, self.scheme) @ self.nodes

    def resample(self, mesh: Array) -> "Profile":
        """The same function on another mesh (interpolated at the new nodes)."""
        mesh = np.asarray(mesh, dtype=float)
        h = np.diff(mesh)
        tau = (mesh[:-1, None] + h[:, None] * self.scheme.nodes[None, :-1]).reshape(-1)
        return Profile(mesh, self(tau), self.degree)

    @staticmethod
    def uniform(states, intervals: int, degree: int) -> "Profile":
        """A profile on a uniform mesh from a callable ``states(tau) -> (k, n)``."""
        mesh = np.linspace(0.0, 1.0, intervals + 1)
        tau = (mesh[:-1, None] + np.diff(mesh)[:, None] * scheme(degree).nodes[None, :-1]).reshape(-1)
        return Profile(mesh, np.asarray(states(tau), dtype=float), degree)
