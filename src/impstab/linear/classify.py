"""Stability classification of eigenvalues, compiled (the engine's rule, one implementation).

Each eigenvalue is judged against its own magnitude, so that a stiff mode cannot hide the flutter
of a soft one, with a rounding floor relative to the largest eigenvalue of its problem:

* undamped problems (eigenvalues ``s = omega^2`` of ``M^-1 K``): flutter-type where
  ``|Im s| > max(TOL_UNSTABLE |s|, floor)``, divergence-type where ``Re s < -floor`` (and real);
* damped problems (eigenvalues ``lambda`` of the state matrix): unstable where
  ``Re lambda > max(TOL_UNSTABLE |lambda|, floor)``; divergence-type if it is also real
  (``|Im lambda| <= max(TOL_CLUSTER |lambda|, floor)``), flutter-type otherwise.

The scan indicator of a problem (two columns, both negative once unstable): for undamped
problems the closest approach of two distinct frequencies and the smallest ``s`` (each relative
to the largest ``|s|``; duplicates closer than ``TOL_DUPLICATE`` are one frequency); for
first-order ones minus the largest relative growth rate, and the closest approach of two
distinct frequencies ``|Im lambda|`` (relative to the largest ``|lambda|``), which is what can
announce a flutter bubble where every growth rate is zero to rounding (an undamped system
written in first-order form).
"""

from __future__ import annotations

import numpy as np
from .._jit import njit
from numpy.typing import NDArray

__all__ = ["unstable_masks", "classify_eigenvalues"]


@njit(cache=True, error_model="numpy", _nrt=False)
def _masks(vals, undamped, tol_unstable, tol_cluster, floor_rel, cplx, neg):
    count, n = vals.shape
    for s in range(count):
        big = 0.0
        for i in range(n):
            big = max(big, abs(vals[s, i]))
        floor = floor_rel * big
        for i in range(n):
            v = vals[s, i]
            mag = abs(v)
            if undamped:
                c = abs(v.imag) > max(tol_unstable * mag, floor)
                cplx[s, i] = c
                neg[s, i] = (v.real < -floor) and not c
            else:
                grow = v.real > max(tol_unstable * mag, floor)
                real = abs(v.imag) <= max(tol_cluster * mag, floor)
                cplx[s, i] = grow and not real
                neg[s, i] = grow and real


@njit(cache=True, inline="always", error_model="numpy")
def _insert(sorted_, i, x):
    """Insert ``x`` into the ascending ``sorted_[:i]`` (insertion sort: ``n`` is small)."""
    j = i
    while j > 0 and sorted_[j - 1] > x:
        sorted_[j] = sorted_[j - 1]
        j -= 1
    sorted_[j] = x


@njit(cache=True, inline="always", error_model="numpy")
def _least_gap(sorted_, n, tol_duplicate):
    """The smallest difference of neighbours of the ascending ``sorted_[:n]`` that is at least
    ``tol_duplicate`` (closer ones are duplicates of one value); ``inf`` if none."""
    gap = np.inf
    for i in range(n - 1):
        d = sorted_[i + 1] - sorted_[i]
        if d >= tol_duplicate and d < gap:
            gap = d
    return gap


@njit(cache=True, error_model="numpy", _nrt=False)
def _indicators(vals, undamped, cplx, neg, tol_duplicate, unstable, indicator, re):
    """Whether each row of ``vals`` is unstable, and its scan indicators; ``re (n,)`` is work space."""
    count, n = vals.shape
    for s in range(count):
        any_c = False
        bad = False
        for i in range(n):
            any_c = any_c or cplx[s, i]
            bad = bad or cplx[s, i] or neg[s, i]
        unstable[s] = bad
        if undamped:
            scale = 0.0
            worst = 0.0
            for i in range(n):
                mag = max(abs(vals[s, i]), 1e-300)
                scale = max(scale, mag)
                worst = max(worst, abs(vals[s, i].imag) / mag)
            for i in range(n):  # the scaled real parts, sorted
                _insert(re, i, vals[s, i].real / scale)
            gap = _least_gap(re, n, tol_duplicate)
            indicator[s, 0] = -worst if any_c else gap
            indicator[s, 1] = -worst if any_c else re[0]
        else:
            growth = -np.inf
            scale = 0.0
            for i in range(n):
                growth = max(growth, vals[s, i].real / max(abs(vals[s, i]), 1e-300))
                scale = max(scale, abs(vals[s, i]), 1e-300)
            for i in range(n):  # the scaled frequencies, sorted
                _insert(re, i, abs(vals[s, i].imag) / scale)
            gap = _least_gap(re, n, tol_duplicate)
            indicator[s, 0] = -growth
            indicator[s, 1] = -growth if bad else gap


def unstable_masks(vals: NDArray[np.complex128], undamped: bool, tol_unstable: float, tol_cluster: float,
                   floor: float) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Masks of the unstable eigenvalues ``(flutter-type, divergence-type)``, same shape as ``vals``.

    ``vals (..., n)``: the eigenvalues of each problem along the last axis. ``floor`` is relative
    to the largest magnitude of the problem.
    """
    vals = np.asarray(vals, dtype=np.complex128)
    flat = np.ascontiguousarray(vals.reshape(-1, vals.shape[-1]))
    cplx = np.empty(flat.shape, dtype=np.bool_)
    neg = np.empty(flat.shape, dtype=np.bool_)
    _masks(flat, bool(undamped), float(tol_unstable), float(tol_cluster), float(floor), cplx, neg)
    return cplx.reshape(vals.shape), neg.reshape(vals.shape)


def classify_eigenvalues(vals: NDArray[np.complex128], undamped: bool, tol_unstable: float, tol_cluster: float,
                         floor: float, tol_duplicate: float) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
    """Whether each problem is unstable, and its scan indicator ``(N, 2)``; ``vals (N, n)``."""
    vals = np.ascontiguousarray(vals, dtype=np.complex128)
    cplx, neg = unstable_masks(vals, undamped, tol_unstable, tol_cluster, floor)
    unstable = np.empty(len(vals), dtype=np.bool_)
    indicator = np.empty((len(vals), 2))
    _indicators(vals, bool(undamped), cplx, neg, float(tol_duplicate), unstable, indicator, np.empty(vals.shape[-1]))
    return unstable, indicator
