"""A first-order system ``B x' = f(x, p)`` and the calling convention of its right-hand side.

Calling convention
------------------
``f(x, p)`` takes a state and a scalar parameter and returns ``x'`` (or ``B x'``):

* ``vectorized=False`` (default): ``x`` has shape ``(n,)`` and ``f`` returns ``(n,)``; the
  machinery loops over states.
* ``vectorized=True``: ``x`` is a batch ``X`` of shape ``(N, n)`` (one state per row) and ``f``
  returns ``(N, n)``. This is the fast path: the collocation Jacobians, the complex-step and
  Cauchy-circle derivatives evaluate ``f`` on thousands of states in a handful of calls.

In both cases ``p`` is one scalar per call (a Python or NumPy ``float``, or a ``complex`` for the
parameter derivatives), never an array. Exact derivatives need ``f`` to be written with analytic
operations that accept complex states (``+ - * /``, powers, ``exp``, ``sin`` ...; not ``abs``,
``max``, comparisons or ``.real``) and to return real values for real input. Where ``f`` does not
accept a complex parameter, say so with ``complex_parameter=False``: the parameter derivatives
then use a fourth-order central difference, and the results say so.

Optional analytic derivatives replace the complex-step / Cauchy-circle ones; they follow the
same batch convention (shown here for ``vectorized=True``; drop the leading ``N`` otherwise):
``jacobian(X, p) -> (N, n, n)``, ``second_derivative(X, p, U, V) -> (N, n)`` (the bilinear form
``B(u, v) = sum_jk d2f/dx_j dx_k u_j v_k``) and ``third_derivative(X, p, U, V, W) -> (N, n)``;
``U``, ``V``, ``W`` may be complex.

Piecewise right-hand sides (a contact law, a guard) are analytic only inside each piece. The
optional ``region(X) -> (N,) or (N, k)`` integer codes say which piece each (complex) state of a
batch lies in, decided on real parts of analytic functions of the state (``Re(d . d) > c^2``).
The Cauchy circles of the second and third derivatives are shrunk until every point of a circle
(sampled four times finer than the circle itself, at 1.5 times its radius) has the centre's
codes: a real part of an analytic function is harmonic, so it takes its extremes on the boundary
of the disc, and the whole disc then lies in the centre's piece, where ``f`` is analytic.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError

__all__ = ["DynamicalSystem", "as_system"]

Array = NDArray[np.float64]

#: largest condition number accepted for a mass matrix
MASS_MATRIX_CONDITION_LIMIT = 1e12


@dataclass(frozen=True, eq=False)
class DynamicalSystem:
    """``B x' = f(x, p)``: the right-hand side, its dimension and optional extras.

    Parameters
    ----------
    rhs : callable
        ``f(x, p)`` as described in the module notes (batch ``(N, n)`` when ``vectorized``).
    dimension : int
        Number of states ``n``.
    vectorized : bool
        Whether ``rhs`` (and the derivative callables) take a batch of states.
    mass_matrix : (n, n) array, optional
        Constant invertible ``B``; ``None`` means the identity.
    jacobian, second_derivative, third_derivative : callable, optional
        Analytic derivatives (see the module notes); absent ones are computed exactly to
        rounding by complex step (Jacobian) and Cauchy-circle Taylor coefficients (forms).
    complex_parameter : bool
        Whether ``rhs`` accepts a complex parameter (complex-step parameter derivatives).
    state_names, state_units : tuple of str
        One name and one unit per state (used in result tables, datasets and plots).
    parameter_name, parameter_units, time_units : str
    state_scale : (n,) array, optional
        Typical size of each state (its unit of "small"); it weighs the arclength and the
        derivative circles. Default ones.
    region : callable, optional
        ``region(X)``: integer codes of the piece of a piecewise ``f`` each state of the batch
        ``X`` (complex, ``(N, n)``) lies in (see the module notes); None: ``f`` is analytic.
    """

    rhs: Callable[..., Any]
    dimension: int
    vectorized: bool = False
    mass_matrix: Array | None = None
    jacobian: Callable[..., Any] | None = None
    second_derivative: Callable[..., Any] | None = None
    third_derivative: Callable[..., Any] | None = None
    complex_parameter: bool = True
    state_names: tuple[str, ...] = ()
    state_units: tuple[str, ...] = ()
    parameter_name: str = "p"
    parameter_units: str = ""
    time_units: str = "s"
    state_scale: Array | None = None
    region: Callable[..., Any] | None = None

    def __post_init__(self) -> None:
        n = self.dimension
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ModelError("dimension", n, "must be a positive integer")
        object.__setattr__(self, "dimension", int(n))
        if not callable(self.rhs):
            raise ModelError("rhs", self.rhs, "must be callable as f(x, p)")
        if self.mass_matrix is not None:
            b = np.array(self.mass_matrix, dtype=float)
            if b.shape != (n, n):
                raise ModelError("mass_matrix", b.shape, f"must have shape ({n}, {n})")
            if not np.all(np.isfinite(b)):
                raise ModelError("mass_matrix", "non-finite entries", "must be finite")
            cond = np.linalg.cond(b)
            if not np.isfinite(cond) or cond > MASS_MATRIX_CONDITION_LIMIT:
                raise ModelError("mass_matrix", f"condition number {cond:.3g}",
                                 f"must be invertible (condition number below {MASS_MATRIX_CONDITION_LIMIT:.0e})")
            b.setflags(write=False)
            object.__setattr__(self, "mass_matrix", b)
        names = tuple(self.state_names) or tuple(f"x{j + 1}" for j in range(n))
        if len(names) != n:
            raise ModelError("state_names", names, f"must name all {n} states")
        object.__setattr__(self, "state_names", names)
        units = tuple(self.state_units) or ("",) * n
        if len(units) != n:
            raise ModelError("state_units", units, f"must give one unit for each of the {n} states")
        object.__setattr__(self, "state_units", units)
        scale = np.ones(n) if self.state_scale is None else np.array(self.state_scale, dtype=float).reshape(-1)
        if scale.shape != (n,) or not np.all(np.isfinite(scale)) or np.any(scale <= 0):
            raise ModelError("state_scale", self.state_scale, f"must be {n} positive finite numbers")
        scale.setflags(write=False)
        object.__setattr__(self, "state_scale", scale)

    # ------------------------------------------------------------------ evaluation
    @property
    def mass(self) -> Array:
        """The mass matrix ``B`` (identity when none was given)."""
        return np.eye(self.dimension) if self.mass_matrix is None else self.mass_matrix

    def evaluate(self, states: NDArray, p: complex) -> NDArray:
        """``f`` on a batch ``(N, n)`` of (possibly complex) states at one parameter value."""
        x = np.asarray(states)
        if x.ndim != 2 or x.shape[1] != self.dimension:
            raise ValueError(f"states must have shape (N, {self.dimension}), got {x.shape}")
        if self.vectorized:
            out = np.asarray(self.rhs(x, p))
            if out.shape != x.shape:
                raise ModelError("rhs", f"output shape {out.shape}",
                                 f"a vectorized right-hand side must return (N, n) = {x.shape}")
            return out
        rows = [np.asarray(self.rhs(xi, p)) for xi in x]
        out = np.array(rows) if rows else np.zeros((0, self.dimension))
        if out.shape != x.shape:
            raise ModelError("rhs", f"output shape {out.shape[1:]}",
                             f"must return one value per state, shape ({self.dimension},)")
        return out

    def evaluate_rows(self, states: NDArray, params: NDArray) -> NDArray:
        """``f`` on states whose rows have their own parameter values (one call per value)."""
        x = np.asarray(states)
        pv = np.asarray(params)
        out = np.empty(x.shape, dtype=np.result_type(x.dtype, pv.dtype, np.float64))
        values, inverse = np.unique(pv, return_inverse=True)
        for k, value in enumerate(values):
            rows = np.flatnonzero(inverse == k)
            out[rows] = self.evaluate(x[rows], value.item())
        return out

    def call_jacobian(self, states: Array, p: float) -> Array:
        """The analytic Jacobian hook on a batch, ``(N, n, n)``."""
        assert self.jacobian is not None
        return _batched(self.jacobian, self.vectorized, (states,), p, (self.dimension, self.dimension))

    def call_second(self, states: Array, p: float, u: NDArray, v: NDArray) -> NDArray:
        assert self.second_derivative is not None
        return _batched(self.second_derivative, self.vectorized, (states, u, v), p, (self.dimension,), form=True)

    def call_third(self, states: Array, p: float, u: NDArray, v: NDArray, w: NDArray) -> NDArray:
        assert self.third_derivative is not None
        return _batched(self.third_derivative, self.vectorized, (states, u, v, w), p, (self.dimension,), form=True)


def _batched(fn, vectorized: bool, arrays: tuple, p, shape: tuple[int, ...], form: bool = False) -> NDArray:
    states = arrays[0]
    if vectorized:
        out = np.asarray(fn(states, p, *arrays[1:]) if form else fn(states, p))
    else:
        rows = []
        for k in range(states.shape[0]):
            args = [a[k] for a in arrays[1:]]
            rows.append(np.asarray(fn(states[k], p, *args) if form else fn(states[k], p)))
        out = np.array(rows)
    if out.shape != (states.shape[0],) + shape:
        raise ModelError(getattr(fn, "__name__", "derivative"), f"output shape {out.shape}",
                         f"must return shape {(states.shape[0],) + shape}")
    return out


def as_system(f: DynamicalSystem | Callable[..., Any], dimension: int) -> DynamicalSystem:
    """``f`` itself when it is a :class:`DynamicalSystem`, else a plain single-state system."""
    if isinstance(f, DynamicalSystem):
        if f.dimension != dimension:
            raise ModelError("x0", f"{dimension} states", f"the system has {f.dimension} states")
        return f
    return DynamicalSystem(rhs=f, dimension=dimension)
