"""Envelope growth rate of a time history and the sub/at/supercritical classification.

The growth rate of a run is fitted to the envelope of one response: the peaks of ``|x(t)|``
(each refined by a parabola through three samples), and a least-squares line through
``log(peak)`` against time. It is compared with ``max Re(lambda)`` of the linearized system at
the same thrust (paper Figures 5-6: bounded below the critical thrust, growing linearly in time
at it, exponentially at the rate ``Re(lambda)`` above it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..model.model import DOF_NAMES

__all__ = ["GrowthFit", "envelope_peaks", "fit_growth_rate", "fit_run", "classify", "LINEAR_LIMIT", "CRITICAL_RTOL"]

Array = NDArray[np.float64]

#: amplitude (fraction of the model's length scale, or rad) where the default fit window ends
LINEAR_LIMIT = 1e-2
#: a growing envelope is fitted where it rises through this factor below its final value
GROWTH_SPAN = 100.0
#: thrusts within this relative distance of the critical thrust are classified "critical"
CRITICAL_RTOL = 1e-3


@dataclass(frozen=True)
class GrowthFit:
    """Envelope growth rate fitted from a run.

    Attributes
    ----------
    rate : float
        Fitted growth rate of the envelope (1/s); NaN when fewer than 4 peaks were found.
    dof : str
        The response fitted (the dof with the largest motion, rotations scaled by the length scale).
    window : (float, float)
        Time window of the fit (s).
    n_peaks : int
    envelope : {"exponential growth", "linear growth", "bounded", "decaying", "undetermined"}
        Shape of the envelope in the window (a heuristic on the fitted peaks).
    linear_rate : float or None
        ``max Re(lambda)`` of the linearized system at the same thrust (1/s).
    thrust : float
        Thrust at the end of the window (N).
    """

    rate: float
    dof: str
    window: tuple[float, float]
    n_peaks: int
    envelope: str
    linear_rate: float | None = None
    thrust: float = math.nan

    @property
    def relative_difference(self) -> float | None:
        """``(rate - linear_rate) / |linear_rate|``; None without a linear rate or when it is zero to
        round-off (below ``1e-8`` 1/s: a neutral or critical system)."""
        if self.linear_rate is None or abs(self.linear_rate) < 1e-8 or not math.isfinite(self.rate):
            return None
        return (self.rate - self.linear_rate) / abs(self.linear_rate)

    def to_dict(self) -> dict:
        return {"rate": self.rate, "dof": self.dof, "window": list(self.window), "n_peaks": self.n_peaks,
                "envelope": self.envelope, "linear_rate": self.linear_rate, "thrust": self.thrust,
                "relative_difference": self.relative_difference}


def envelope_peaks(t: Array, x: Array) -> tuple[Array, Array]:
    """Times (s) and values of the local maxima of ``|x|``, refined by a parabola in ``x``."""
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if x.size < 3:
        return np.empty(0), np.empty(0)
    a = np.abs(x)
    i = np.nonzero((a[1:-1] >= a[:-2]) & (a[1:-1] > a[2:]))[0] + 1
    xm, x0, xp = x[i - 1], x[i], x[i + 1]
    curv = xp - 2.0 * x0 + xm
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.where(curv != 0, 0.5 * (xm - xp) / curv, 0.0)
    shift = np.clip(shift, -1.0, 1.0)
    peak = np.abs(x0 - 0.25 * (xm - xp) * shift)
    dt = np.where(shift >= 0, t[np.minimum(i + 1, t.size - 1)] - t[i], t[i] - t[i - 1])
    return t[i] + shift * dt, peak


def fit_growth_rate(tp: Array, ap: Array) -> tuple[float, float]:
    """Least-squares ``log(ap) = c + rate t``; returns ``(rate, c)`` (NaN with fewer than 4 peaks)."""
    keep = ap > 0
    if keep.sum() < 4:
        return math.nan, math.nan
    rate, c = np.polyfit(tp[keep], np.log(ap[keep]), 1)
    return float(rate), float(c)


def _r2(y: Array, fit: Array) -> float:
    var = float(np.var(y))
    return 1.0 - float(np.var(y - fit)) / var if var > 0 else 0.0


def _envelope_kind(tp: Array, ap: Array, rate: float) -> str:
    """Heuristic shape of the envelope: a trend counts when it changes the amplitude by more than
    a factor 1.5 over the window and explains 90 % of the variance of the peaks; beating of
    neutral modes is "bounded"."""
    if tp.size < 4 or not math.isfinite(rate):
        return "undetermined"
    logs = np.log(ap)
    r2_exp = _r2(logs, np.polyval(np.polyfit(tp, logs, 1), tp))
    lin_coef = np.polyfit(tp, ap, 1)
    r2_lin = _r2(ap, np.polyval(lin_coef, tp))
    change = rate * (tp[-1] - tp[0])
    if change < -math.log(1.5) and r2_exp > 0.9:
        return "decaying"
    if change > math.log(1.5) and max(r2_exp, r2_lin) > 0.9:
        return "linear growth" if r2_lin > r2_exp else "exponential growth"
    return "bounded"


def fit_run(time: Array, z: Array, length_scale: float, window: tuple[float, float] | None = None,
            linear_rate: float | None = None, thrust: float = math.nan) -> GrowthFit:
    """Fit the envelope growth rate of a run (deviations ``z`` of the state, ``(k, 12)``).

    Default window: up to the first time the motion leaves the linear range (a translation of
    ``LINEAR_LIMIT`` x the length scale, or ``LINEAR_LIMIT`` rad) or the end of the run; from
    the last time the envelope is below ``1 / GROWTH_SPAN`` of its final value when it grows
    strongly (the first half stays below a tenth of the final amplitude), else the second half.
    """
    time = np.asarray(time, dtype=float)
    sig = np.asarray(z, dtype=float)[:, :6].copy()
    sig[:, 3:] *= length_scale
    big = np.abs(sig).max(axis=1)
    if window is None:
        over = np.nonzero(big > LINEAR_LIMIT * length_scale)[0]
        end = int(over[0]) if over.size else time.size - 1
        end = max(end, min(2, time.size - 1))
        j = int(np.argmax(np.abs(sig[: end + 1]).max(axis=0)))
        tp, ap = envelope_peaks(time[: end + 1], sig[: end + 1, j])
        t1 = float(time[end])
        t0 = 0.5 * (float(time[0]) + t1)
        early = ap[tp < t0]
        if ap.size >= 8 and early.size and early.max() * 10.0 < ap[-1]:
            # strong growth: start where the envelope is 1/GROWTH_SPAN of its final value
            below = np.nonzero(ap < ap[-1] / GROWTH_SPAN)[0]
            t0 = float(tp[below[-1]]) if below.size else float(time[0])
    else:
        t0, t1 = float(window[0]), float(window[1])
        inside = (time >= t0) & (time <= t1)
        j = int(np.argmax(np.abs(sig[inside]).max(axis=0))) if inside.any() else 0
        tp, ap = envelope_peaks(time, sig[:, j])
    sel = (tp >= t0) & (tp <= t1)
    tp, ap = tp[sel], ap[sel]
    rate, _ = fit_growth_rate(tp, ap)
    return GrowthFit(rate, DOF_NAMES[j], (t0, t1), int(tp.size), _envelope_kind(tp, ap, rate), linear_rate, thrust)


def classify(thrust: float, critical: float | None, thrust_max: float | None = None,
             rtol: float = CRITICAL_RTOL) -> str:
    """``"subcritical"``, ``"critical"`` (within ``rtol`` of T_c) or ``"supercritical"``.

    ``critical = None`` means no loss of stability up to ``thrust_max``: subcritical below it,
    ``"unknown"`` above it.
    """
    if critical is None:
        return "subcritical" if thrust_max is None or thrust <= thrust_max else "unknown"
    if abs(thrust - critical) <= rtol * critical:
        return "critical"
    return "subcritical" if thrust < critical else "supercritical"
