"""Practical stability: the first load at which the least-damped mode's damping falls to a threshold.

The exact onset (:mod:`impstab.linear.critical`) is where the least-damped eigenvalue reaches the
imaginary axis. Rotordynamic practice asks for more: every mode keeps at least a damping ratio
``zeta_min`` (``zeta = -Re lambda / |lambda|``), or a logarithmic decrement ``delta_min``
(``delta = -2 pi Re lambda / Im lambda = 2 pi zeta / sqrt(1 - zeta^2)``; API 617 and API 684 ask
for ``delta >= 0.1``, ``zeta >= 0.0159``). The *practical critical load* is the first load from
``p_min`` at which ``min zeta(p) = zeta_min``.

The sector as a stability problem
---------------------------------
``zeta >= zeta_min`` for every eigenvalue is the statement that every eigenvalue lies in the
sector ``|arg lambda| >= pi/2 + theta`` with ``sin theta = zeta_min``. Turning the spectrum by
``+theta`` and by ``-theta`` maps that sector's edges onto the imaginary axis: ``Re(lambda
e^(+-i theta)) < 0`` for both signs exactly when ``zeta > sin theta``. The turned spectrum is the
spectrum of the real operator ``[[c A, s A], [-s A, c A]]`` (``c = cos theta``, ``s = sin theta``; the real
form of ``e^(-i theta) A``, which holds ``lambda e^(-i theta)`` and, with the conjugates,
``lambda e^(+i theta)``). So the practical critical load is the critical load of the turned
family, found by the one stability engine (:mod:`impstab.linear.engine`: its scan, bubble
searches and exact refinement), with no scan of its own. An affine family stays affine; a family
given by a provider (the equilibrium linearization) is turned point by point.

A real eigenvalue crossing zero (divergence) has ``zeta`` jump from 1 to -1; the turned pair
``|lambda| e^(i (pi +- theta))`` then reaches the imaginary axis at 0 with it, and the practical
onset is the divergence itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..limits import check_number
from ..model.criteria import damping_ratio_of_log_decrement, damping_threshold, log_decrement_of_damping_ratio
from .engine import Problem, second_order_problem, first_order_problem, solve

__all__ = ["PracticalOnset", "damping_ratio_of_log_decrement", "log_decrement_of_damping_ratio",
           "damping_threshold", "practical_load_family", "sector_problem", "damping_ratios"]

Array = NDArray[np.float64]

#: |Im lambda| / |lambda| below which the least-damped eigenvalue at the practical onset is real
REAL_EIGENVALUE = 1e-8


def damping_ratios(vals: NDArray[np.complex128]) -> Array:
    """``zeta = -Re lambda / |lambda|`` of each eigenvalue (NaN for ``lambda = 0``)."""
    vals = np.asarray(vals)
    mag = np.abs(vals)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(mag > 0, -vals.real / np.where(mag > 0, mag, 1.0), np.nan)


class _TurnedProvider:
    """Operators ``[[c A, s A], [-s A, c A]]`` of a provider's operators ``A(p)``."""

    def __init__(self, provider, turn: Array) -> None:
        self.provider, self.turn = provider, turn

    @property
    def error(self):
        return getattr(self.provider, "error", None)

    def operators(self, loads: Array) -> Array:
        a = self.provider.operators(loads)
        return np.einsum("ij,mkl->mikjl", self.turn, a).reshape(a.shape[0], 2 * a.shape[1], 2 * a.shape[2])

    def weights(self, p: float) -> Array:
        return self.provider.weights(p)

    def fold_indicator(self, p: float) -> float:
        return self.provider.fold_indicator(p)


def sector_problem(problem: Problem, zeta: float) -> Problem:
    """The turned problem of a first-order ``problem``: stable exactly where every ``zeta > zeta``.

    Parameters
    ----------
    problem : Problem
        A first-order problem (``undamped`` False) of order N.
    zeta : float
        Damping-ratio threshold, ``0 <= zeta < 1``.

    Returns
    -------
    Problem
        Order 2N, the same range, dofs and weights.
    """
    if problem.undamped:
        raise ValueError("the sector problem needs the first-order form (eigenvalues lambda)")
    theta = math.asin(zeta)
    turn = np.array([[math.cos(theta), math.sin(theta)], [-math.sin(theta), math.cos(theta)]])
    n = problem.order
    if problem.affine:
        a0, a1 = problem.operators()
        return Problem(False, problem.p_min, problem.p_max, problem.n_scan, 2 * n, problem.n_dof,
                       np.kron(turn, a0), np.kron(turn, a1), problem.weights.copy())
    return Problem(False, problem.p_min, problem.p_max, problem.n_scan, 2 * n, problem.n_dof,
                   provider=_TurnedProvider(problem.provider, turn))


def _operator(problem: Problem, p: float) -> Array:
    if problem.affine:
        a0, a1 = problem.operators()
        return a0 + p * a1
    return problem.provider.operators(np.array([p]))[0]


@dataclass(frozen=True, eq=False)
class PracticalOnset:
    """The first load at which the least damping ratio falls to the threshold.

    Attributes
    ----------
    load : float or None
        Practical critical load (``p_min`` when the damping is below the threshold already
        there); None when every mode keeps the threshold up to ``p_max``.
    damping_ratio : float
        The threshold ``zeta_min`` (1).
    log_decrement : float
        The same threshold as a logarithmic decrement ``delta_min`` (1).
    kind : {"flutter", "divergence", "none"}
        ``"divergence"`` when the least-damped eigenvalue at the onset is real (a static loss).
    omega : float or None
        ``|Im lambda|`` of the least-damped eigenvalue at the onset (rad/s).
    at_start : bool
        The damping is below the threshold at ``p_min`` already.
    evaluations : int
        Eigenproblems solved by the engine.
    warnings : tuple of str
    """

    load: float | None
    damping_ratio: float
    log_decrement: float
    kind: str
    omega: float | None
    at_start: bool = False
    evaluations: int = 0
    warnings: tuple[str, ...] = ()

    @property
    def frequency_hz(self) -> float | None:
        return None if self.omega is None else self.omega / (2 * math.pi)


def first_order_of(family, p_max: float, *, p_min: float = 0.0, n_scan: int = 64) -> Problem:
    """The first-order problem of a second- or first-order family (the form the sector needs)."""
    if getattr(family, "first_order", False):
        return first_order_problem(family, p_max, p_min=p_min, n_scan=n_scan)
    return second_order_problem(family, p_max, p_min=p_min, n_scan=n_scan, undamped=False)


def practical_problem(family, p_max: float, zeta: float, *, p_min: float = 0.0, n_scan: int = 64) -> tuple[Problem, Problem]:
    """``(first-order problem, its sector problem)`` of a family, for :func:`practical_onset`."""
    base = first_order_of(family, p_max, p_min=p_min, n_scan=n_scan)
    return base, sector_problem(base, zeta)


def practical_onset(base: Problem, outcome, zeta: float) -> PracticalOnset:
    """The :class:`PracticalOnset` of the engine's ``outcome`` on the sector problem of ``base``."""
    if outcome.error is not None:
        raise outcome.error
    delta = log_decrement_of_damping_ratio(zeta)
    if outcome.load is None:
        return PracticalOnset(None, zeta, delta, "none", None, False, outcome.evaluations, tuple(outcome.warnings))
    p = float(outcome.load)
    op = _operator(base, p)
    kind, omega = outcome.kind, outcome.omega
    if np.isfinite(op).all():
        vals = np.linalg.eigvals(op)
        j = int(np.argmax(vals.real + zeta * np.abs(vals)))  # the eigenvalue on the sector's edge
        lam = vals[j]
        omega = float(abs(lam.imag))
        kind = "divergence" if omega <= REAL_EIGENVALUE * max(float(np.abs(vals).max()), 1e-300) else "flutter"
    return PracticalOnset(p, zeta, delta, kind, omega, bool(outcome.unstable_at_start), outcome.evaluations,
                          tuple(outcome.warnings))


def practical_load_family(family, p_max: float, min_damping_ratio: float, *, p_min: float = 0.0,
                          n_scan: int = 64) -> PracticalOnset:
    """First load from ``p_min`` at which the least damping ratio of ``family`` falls to ``min_damping_ratio``.

    Parameters
    ----------
    family : SystemFamily or FirstOrderFamily
        ``p -> (M, D, G, K)`` or ``p -> (E, A)`` (:mod:`impstab.linear.families`).
    p_max, p_min : float
        The load range searched.
    min_damping_ratio : float
        Threshold ``zeta_min`` in ``[0, 0.9]`` (use :func:`damping_ratio_of_log_decrement` for a
        logarithmic decrement). 0 gives the exact critical load (of the first-order form).
    n_scan : int
        Scan intervals.

    Returns
    -------
    PracticalOnset

    Examples
    --------
    One dof ``q'' + 0.2 q' + (1 + p) q = 0``: ``zeta(p) = 0.1 / sqrt(1 + p)`` is 0.05 at ``p = 3``.

    >>> from impstab.linear.families import LinearFamily
    >>> f = LinearFamily.build([[1.0]], [[1.0]], [[1.0]], D=[[0.2]])
    >>> round(practical_load_family(f, 10.0, 0.05).load, 10)
    3.0
    """
    zeta = check_number("min_damping_ratio", min_damping_ratio, "damping_ratio")
    base, turned = practical_problem(family, p_max, zeta, p_min=p_min, n_scan=n_scan)
    return practical_onset(base, solve([turned])[0], zeta)
