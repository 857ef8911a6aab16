"""Adaptive mesh for collocation: equidistribution of the leading error term (AUTO, COLSYS).

The error of degree-``m`` collocation on interval ``i`` behaves like ``h_i^(m+1) |x^(m+1)|``. The
``m``-th derivative of the piecewise polynomial is constant on each interval; differencing it
across the mesh points estimates ``x^(m+1)``. The new mesh equidistributes
``int theta(tau) dtau`` with ``theta = |x^(m+1)|^(1/(m+1))`` (the monitor of AUTO's ``ADAPT`` and of
de Boor's and COLSYS's mesh selection), so every interval carries the same error.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .collocation import Profile

__all__ = ["monitor", "equidistribute", "error_indicator"]

Array = NDArray[np.float64]

#: the monitor is bounded below by this share of its mean (no interval grows without bound)
MONITOR_FLOOR = 0.02


def _higher_derivative(profile: Profile, scale: Array) -> Array:
    """Estimate of ``|x^(m+1)| / scale`` per interval (max over states), ``(N,)``."""
    d = profile.top_derivative() / scale[None, :]                     # (N, n)
    h = profile.widths
    jump = (d - np.roll(d, 1, axis=0)) / (0.5 * (h + np.roll(h, 1)))[:, None]   # at mesh point i (periodic)
    at_mesh = np.max(np.abs(jump), axis=1)
    return 0.5 * (at_mesh + np.roll(at_mesh, -1))


def monitor(profile: Profile, scale: Array) -> Array:
    """``theta_i = |x^(m+1)|^(1/(m+1))`` per interval, floored at ``MONITOR_FLOOR`` of its mean."""
    theta = _higher_derivative(profile, scale) ** (1.0 / (profile.degree + 1))
    mean = float(np.sum(theta * profile.widths))
    if not np.isfinite(mean) or mean <= 0:
        return np.ones_like(theta)
    return np.maximum(theta, MONITOR_FLOOR * mean)


def equidistribute(profile: Profile, scale: Array, intervals: int | None = None) -> Array:
    """A new mesh of ``intervals`` (default: as many as now) with equal ``h_i theta_i``."""
    n_new = profile.intervals if intervals is None else int(intervals)
    theta = monitor(profile, scale)
    cum = np.concatenate([[0.0], np.cumsum(theta * profile.widths)])
    targets = np.linspace(0.0, cum[-1], n_new + 1)
    mesh = np.interp(targets, cum, profile.mesh)
    mesh[0], mesh[-1] = 0.0, 1.0
    return mesh


def error_indicator(profile: Profile, scale: Array) -> tuple[float, float]:
    """Estimated largest error of the profile between mesh points (scaled states) and the
    equidistribution ratio ``max(h theta) / mean(h theta)`` (1 for a perfectly adapted mesh)."""
    m = profile.degree
    h = profile.widths
    d = _higher_derivative(profile, scale)
    err = float(np.max(profile.scheme.error_constant * h ** (m + 1) * d))
    theta = d ** (1.0 / (m + 1))
    ht = h * theta
    ratio = float(np.max(ht) / np.mean(ht)) if np.mean(ht) > 0 else 1.0
    return err, ratio
