"""What a run shows: the envelope of the motion, its growth rate and the sub/at/supercritical
classification.

A small-amplitude run from the static equilibrium is a sum of the linear modes, ``z(t) = sum_j
c_j e^{lambda_j t}``: beating of two modes, several damped modes and a growing one all at once.
Fitting a line through the logarithm of the peaks of one coordinate (what the paper's Figures
5-6 suggest) mixes them: the label then depends on where the beats fall in the window, so on
the run length. Instead the modes are identified from the run itself:

1. **Modal fit** (the eigensystem realization algorithm of Juang and Pappa, 1985, on all twelve
   weighted state histories at once): a block Hankel matrix of the samples, its truncated SVD,
   the shift-invariant realization ``A``; the poles ``lambda_j = log(eig A) / dt``; the amplitude
   of each pole by linear least squares on the samples; the misfit of that sum of modes. The
   fit window is the longest stretch of the run in the linear range (every displacement within
   :data:`LINEAR_LIMIT` x the length scale, every angle within that many rad), cut to a dynamic
   range of :data:`DYNAMIC_RANGE` of its envelope. Beating modes come out as separate poles, so the fit
   does not depend on the run length once the run holds a few periods.
2. **Labels** from the significant poles (those carrying at least :data:`SIGNIFICANT` of the
   largest contribution in the window), leaving out the static offset and the combination tones
   of the nonlinear terms (a weaker pole at the sum of two or three stronger ones, e.g. at
   ``2 lambda`` near the end of a growing run); the growth rate is the largest real part among them:
   ``"exponential growth"`` above ``+tau``, ``"decaying"`` below ``-tau``, ``"bounded"``
   between, with ``tau = ZETA_NEUTRAL |lambda|`` of that pole (a damping ratio of 1e-5); a
   neutral pole that coalesces with another (relative distance below :data:`COALESCE`: the
   double root at a critical thrust, ``(A + B t) e^{i omega t}``) is ``"linear growth"``.
3. **Limit cycle**: the motion at the end of the run is periodic (in the last third of the run,
   the last half of its periods, at least three, agree to :data:`CYCLE_RTOL` in period and
   amplitude), it got there by growing or decaying (its
   envelope changed by a factor of 2 or more) and no sum of linear modes explains the whole run.
   The amplitude of each coordinate is half its peak-to-peak over the last period (X_A, Y_A, Z_A
   in m, the Euler angles in rad, named surge ... yaw; peaks refined by a parabola).
4. Otherwise ``"undetermined"``, always with the reason (too few samples or periods, a nonlinear
   transient not yet periodic, no motion).

The fitted rate is compared with ``max Re(lambda)`` of the linearized system at the same
thrust; the relative difference is given only where the linear rate is not neutral (beyond
``tau``).

Written here rather than taken from a library: SciPy has no eigensystem realization or
matrix-pencil routine; the algorithm is twenty lines of NumPy (one SVD, one eigenproblem, one
least-squares solve).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..model.model import DOF_NAMES

__all__ = ["GrowthFit", "ModalFit", "modal_fit", "envelope_peaks", "fit_run", "classify", "LINEAR_LIMIT",
           "CRITICAL_RTOL", "ENVELOPES"]

Array = NDArray[np.float64]

#: amplitude (fraction of the model's length scale, or rad) where the modal fit window ends
LINEAR_LIMIT = 1e-2
#: largest ratio of the envelope within the modal fit window
DYNAMIC_RANGE = 1e4
#: a pole counts when its contribution in the window is at least this fraction of the largest
SIGNIFICANT = 1e-3
#: a growth rate below this fraction of |lambda| (a damping ratio) is neutral
ZETA_NEUTRAL = 1e-5
#: two neutral poles closer than this (relative to |lambda|) are one double root
COALESCE = 1e-3
#: a pole (at most a tenth of the size of the poles it combines) at the frequency of a sum of two
#: or three stronger poles (within this fraction of the largest |lambda|) and at its growth rate
#: is a combination tone of the nonlinear terms, not a mode
COMBINATION = 1e-2
#: a modal fit whose relative misfit exceeds this does not explain the run
MISFIT_TOL = 1e-2
#: relative agreement of the last periods (period and amplitude) of a settled limit cycle
CYCLE_RTOL = 1e-3
#: samples per period of the fastest mode used by the modal fit, and its largest sample count
FIT_SAMPLES_PER_PERIOD = 8
FIT_MAX_SAMPLES = 3000
#: columns (state snapshots) of the block Hankel matrix of the modal fit
HANKEL_COLUMNS = 600
#: motion below this fraction of the length scale is rounding, not motion
NO_MOTION = 1e-10
#: thrusts within this relative distance of the critical thrust are classified "critical"
CRITICAL_RTOL = 1e-3
#: the envelope labels
ENVELOPES = ("decaying", "bounded", "linear growth", "exponential growth", "limit cycle", "undetermined")


@dataclass(frozen=True)
class GrowthFit:
    """What a run shows: envelope label, fitted growth rate and, for a limit cycle, its amplitude.

    Attributes
    ----------
    rate : float
        Fitted growth rate (1/s): the largest real part of the significant poles of the modal
        fit (for a limit cycle: of its growth or decay phase); NaN when there is no fit.
    dof : str
        The coordinate with the largest motion in the window (rotations scaled by the length
        scale).
    window : (float, float)
        Time window (s) of the modal fit (of the whole analysis when there is no fit).
    n_peaks : int
        Peaks of ``|dof|`` in that window.
    envelope : str
        One of :data:`ENVELOPES`.
    linear_rate : float or None
        ``max Re(lambda)`` of the linearized system at the same thrust (1/s).
    thrust : float
        Thrust at the end of the window (N).
    reason : str or None
        Why the envelope is ``"undetermined"``, or a note on the label.
    frequency_hz : float or None
        Frequency of the pole that sets the rate (Hz); for a limit cycle 1 / period.
    period : float or None
        Period of the limit cycle (s).
    amplitude : dict or None
        Limit cycle: half the peak-to-peak of each coordinate over the last period,
        ``{"surge": m, "sway": m, "heave": m, "roll": rad, "pitch": rad, "yaw": rad}``.
    rate_tolerance : float or None
        The neutral band ``tau`` (1/s): rates within it are "bounded".
    fit_misfit : float or None
        Relative misfit of the modal fit.
    """

    rate: float
    dof: str
    window: tuple[float, float]
    n_peaks: int
    envelope: str
    linear_rate: float | None = None
    thrust: float = math.nan
    reason: str | None = None
    frequency_hz: float | None = None
    period: float | None = None
    amplitude: dict | None = field(default=None, compare=False)
    rate_tolerance: float | None = None
    fit_misfit: float | None = None

    @property
    def relative_difference(self) -> float | None:
        """``(rate - linear_rate) / |linear_rate|``; None without a linear rate, without a fitted
        rate, or where the linear rate is neutral (within ``rate_tolerance``, or below 1e-8 1/s)."""
        if self.linear_rate is None or not math.isfinite(self.rate):
            return None
        neutral = max(1e-8, self.rate_tolerance or 0.0)
        if abs(self.linear_rate) <= neutral:
            return None
        return (self.rate - self.linear_rate) / abs(self.linear_rate)

    def to_dict(self) -> dict:
        return {"rate": self.rate, "dof": self.dof, "window": list(self.window), "n_peaks": self.n_peaks,
                "envelope": self.envelope, "linear_rate": self.linear_rate, "thrust": self.thrust,
                "relative_difference": self.relative_difference, "reason": self.reason,
                "frequency_hz": self.frequency_hz, "period": self.period, "amplitude": self.amplitude,
                "rate_tolerance": self.rate_tolerance, "fit_misfit": self.fit_misfit}

    @classmethod
    def from_dict(cls, d: dict) -> "GrowthFit":
        keys = ("reason", "frequency_hz", "period", "amplitude", "rate_tolerance", "fit_misfit")
        return cls(d["rate"], d["dof"], tuple(d["window"]), d["n_peaks"], d["envelope"], d.get("linear_rate"),
                   d.get("thrust", math.nan), **{k: d.get(k) for k in keys})


@dataclass(frozen=True)
class ModalFit:
    """A sum of modes fitted to sampled histories: poles ``lambda`` (1/s), the norm of each
    pole's amplitude vector at the window start, its largest contribution within the window,
    and the relative misfit of the sum."""

    poles: NDArray[np.complex128]
    amplitude: Array
    contribution: Array
    misfit: float
    order: int

    def significant(self) -> NDArray[np.bool_]:
        return self.contribution >= SIGNIFICANT * self.contribution.max()


def modal_fit(y: Array, dt: float, sv_tol: float = 1e-7) -> ModalFit | None:
    """Eigensystem realization of the samples ``y`` (``(N, p)``, step ``dt`` s); None when there
    are too few samples."""
    n_samples, p = y.shape
    rows = max(4, min(n_samples // 3, int(math.ceil(48 / p))))
    cols = n_samples - rows
    if cols < 2 * rows or not np.any(y):
        return None
    # the columns are state snapshots: a spread of HANKEL_COLUMNS of them over the window spans
    # the same column space as all of them
    snap = np.arange(0, cols, max(1, cols // HANKEL_COLUMNS))
    hankel = np.empty((rows * p, snap.size))
    for i in range(rows):
        hankel[i * p:(i + 1) * p] = y[i + snap].T
    # left singular vectors and values of the wide Hankel matrix from its R factor (H^T = Q R,
    # so H = R^T Q^T): the same numbers, at a fraction of the cost of a direct SVD
    u, s, _ = np.linalg.svd(np.linalg.qr(hankel.T, mode="r").T)
    order = int(min(np.sum(s > sv_tol * s[0]), (rows - 1) * p))
    obs = u[:, :order] * np.sqrt(s[:order])
    amat = np.linalg.lstsq(obs[:-p], obs[p:], rcond=None)[0]
    mu = np.linalg.eigvals(amat).astype(complex)
    mu = mu[np.abs(mu) > 0]
    # amplitudes by least squares on all samples, powers counted from the middle of the window
    k = np.arange(n_samples) - 0.5 * (n_samples - 1)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        vander = np.exp(np.outer(k, np.log(mu)))
    keep = np.all(np.isfinite(vander), axis=0)
    mu, vander = mu[keep], vander[:, keep]
    if not mu.size:
        return None
    # columns scaled to unit peak (a fast-decaying pole spans many decades over the window)
    peak = np.abs(vander).max(axis=0)
    coef, *_ = np.linalg.lstsq(vander / peak, y.astype(complex), rcond=None)
    fit = ((vander / peak) @ coef).real
    misfit = float(np.linalg.norm(y - fit) / np.linalg.norm(y))
    contribution = np.linalg.norm(coef, axis=1)  # largest size of each pole's term in the window
    half = 0.5 * (n_samples - 1)
    start = contribution * np.abs(mu) ** (-half) / peak
    return ModalFit(np.log(mu) / dt, start, contribution, misfit, order)


def _refined_extrema(t: Array, x: Array, sign: float) -> tuple[Array, Array]:
    """Times and values of the local maxima (``sign = 1``) or minima (``-1``) of the samples
    ``x``, each refined by the parabola through it and its neighbours."""
    y = sign * x
    i = np.nonzero((y[1:-1] >= y[:-2]) & (y[1:-1] > y[2:]))[0] + 1
    ym, y0, yp = y[i - 1], y[i], y[i + 1]
    curv = yp - 2.0 * y0 + ym
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.clip(np.where(curv < 0, 0.5 * (ym - yp) / curv, 0.0), -1.0, 1.0)
        peak = np.where(curv < 0, y0 - 0.125 * (yp - ym) ** 2 / curv, y0)
    return t[i] + shift * (t[i + 1] - t[i]), sign * peak


def envelope_peaks(t: Array, x: Array) -> tuple[Array, Array]:
    """Times (s) and values of the local maxima of ``|x|``, refined by a parabola."""
    return _refined_extrema(np.asarray(t, dtype=float), np.abs(np.asarray(x, dtype=float)), 1.0)


def _half_range(t: Array, x: Array) -> float:
    """Half the peak-to-peak of ``x`` over the samples, extremes refined by a parabola (the
    sampled extreme where it lies at an end)."""
    hi = _refined_extrema(t, x, 1.0)[1]
    lo = _refined_extrema(t, x, -1.0)[1]
    return 0.5 * (max(hi.max(initial=-np.inf), x.max()) - min(lo.min(initial=np.inf), x.min()))


def _upward_crossings(t: Array, x: Array) -> Array:
    """Times where ``x`` crosses zero upwards (linear interpolation)."""
    i = np.nonzero((x[:-1] < 0.0) & (x[1:] >= 0.0))[0]
    return t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])


@dataclass(frozen=True)
class _Cycle:
    settled: bool
    period: float
    amplitude: dict
    change: float  # largest relative change of the amplitude over the compared periods
    periods: int  # periods compared


def _tail_cycle(t: Array, disp: Array, j: int) -> _Cycle | None:
    """The last periods of the motion, judged on coordinate ``j`` of the displacement ``disp``
    (``(N, 6)``); None with fewer than five periods in the last third of the window."""
    tail = t >= t[0] + (2.0 / 3.0) * (t[-1] - t[0])
    tt, xx = t[tail], disp[tail]
    x = xx[:, j]
    mid = 0.5 * (x.max() + x.min())
    cross = _upward_crossings(tt, x - mid)
    if cross.size < 6:
        return None
    periods = np.diff(cross)
    # half peak-to-peak of each period: the largest refined maximum and the smallest refined
    # minimum between its two crossings
    tmax, vmax = _refined_extrema(tt, x, 1.0)
    tmin, vmin = _refined_extrema(tt, x, -1.0)
    if tmax.size < cross.size - 1 or tmin.size < cross.size - 1:
        return None
    hi = np.maximum.reduceat(vmax, np.minimum(np.searchsorted(tmax, cross[:-1]), tmax.size - 1))
    lo = np.minimum.reduceat(vmin, np.minimum(np.searchsorted(tmin, cross[:-1]), tmin.size - 1))
    amps = 0.5 * (hi - lo)
    last_p, last_a = periods[-1], amps[-1]
    # compared over the last half of these periods (at least three): an approach that slows
    # geometrically is judged by how far it still went over many periods, not over the last one
    m = max(3, periods.size // 2)
    change = float(np.max(np.abs(amps[-m:] - last_a)) / last_a) if last_a > 0 else math.inf
    settled = bool(np.max(np.abs(periods[-m:] - last_p)) <= CYCLE_RTOL * last_p and change <= CYCLE_RTOL)
    sel = (tt >= cross[-2]) & (tt <= cross[-1])
    amplitude = {name: _half_range(tt[sel], xx[sel, d]) for d, name in enumerate(DOF_NAMES)}
    return _Cycle(settled, float(last_p), amplitude, change, m)


def _longest_run(mask: NDArray[np.bool_]) -> tuple[int, int]:
    """First and last index of the longest stretch of True in ``mask`` (the later of equals);
    ``(0, -1)`` when there is none."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0] - 1
    if not starts.size:
        return 0, -1
    lengths = ends - starts
    k = int(np.flatnonzero(lengths == lengths.max())[-1])
    return int(starts[k]), int(ends[k])


def _running_max(a: Array, width: int) -> Array:
    from scipy.ndimage import maximum_filter1d

    return maximum_filter1d(a, size=max(1, width), mode="nearest")


def fit_run(time: Array, z: Array, length_scale: float, window: tuple[float, float] | None = None,
            linear_rate: float | None = None, thrust: float = math.nan, *, omega_max: float | None = None,
            offset: Array | None = None, thrusts: Array | None = None) -> GrowthFit:
    """What the run ``z`` (deviations of the state, ``(k, 12)``, at ``time``) shows.

    Parameters
    ----------
    length_scale : float
        The model's length scale (m): rotations are scaled by it to compare with translations.
    window : (t0, t1), optional
        Analyse only this time window (s). Default: the whole run, from the last change of the
        thrust on (``thrusts``, the thrust at each sample).
    linear_rate : float, optional
        ``max Re(lambda)`` at the same thrust (1/s), for the comparison.
    omega_max : float, optional
        Largest ``|lambda|`` of the linearized system (rad/s): velocities are scaled by it, and
        the modal fit takes :data:`FIT_SAMPLES_PER_PERIOD` samples per its period.
    offset : (12,) array, optional
        Subtracted from ``z`` first: the static equilibrium at the final thrust relative to the
        one the run started from, for a thrust history that ends at another thrust.
    """
    time = np.asarray(time, dtype=float)
    z = np.asarray(z, dtype=float)
    if offset is not None:
        z = z - np.asarray(offset, dtype=float)[None, :]
    sample = float(np.median(np.diff(time))) if time.size > 1 else math.nan
    # samples on the regular grid (a stopped run ends with an extra, off-grid sample)
    regular = np.ones(time.size, dtype=bool)
    if time.size > 2 and abs((time[-1] - time[-2]) - sample) > 1e-6 * sample:
        regular[-1] = False
    if window is None:
        t0 = float(time[0]) if time.size else 0.0
        if thrusts is not None and len(thrusts) == time.size:
            thrusts = np.asarray(thrusts, dtype=float)
            changed = np.nonzero(np.abs(thrusts - thrusts[-1]) > 1e-12 * max(abs(thrusts[-1]), 1.0))[0]
            if changed.size:
                t0 = float(time[min(changed[-1] + 1, time.size - 1)])
        t1 = float(time[regular][-1]) if time.size else 0.0
    else:
        t0, t1 = float(window[0]), float(window[1])
    inside = regular & (time >= t0 - 1e-12) & (time <= t1 + 1e-12)
    t, zz = time[inside], z[inside]
    omega = omega_max if omega_max and math.isfinite(omega_max) and omega_max > 0 else 1.0
    weights = np.array([1, 1, 1, length_scale, length_scale, length_scale] + [1 / omega] * 3
                       + [length_scale / omega] * 3)
    y = zz * weights
    disp = y[:, :6]
    big = np.abs(disp).max(axis=1) if len(t) else np.zeros(0)
    j = int(np.argmax(np.ptp(disp, axis=0))) if len(t) else 0

    def result(envelope, rate=math.nan, reason=None, win=(t0, t1), fit=None, pole=None, cycle=None, tau=None):
        sel = (t >= win[0]) & (t <= win[1])
        n_peaks = int(envelope_peaks(t[sel], disp[sel, j])[0].size) if sel.sum() >= 3 else 0
        freq = None if pole is None else abs(pole.imag) / (2 * math.pi)
        period = amplitude = None
        if cycle is not None:
            period, amplitude, freq = cycle.period, {k: float(v) for k, v in cycle.amplitude.items()}, 1.0 / cycle.period
        return GrowthFit(float(rate), DOF_NAMES[j], (float(win[0]), float(win[1])), n_peaks, envelope, linear_rate,
                         float(thrust), reason, freq, period, amplitude, tau,
                         None if fit is None else fit.misfit)

    if len(t) < 8:
        return result("undetermined", reason=f"only {len(t)} samples in the window")
    if not np.abs(disp).max() > NO_MOTION * length_scale:
        return result("undetermined", reason=f"no motion beyond rounding in the window (largest {np.abs(disp).max():.3g} m): "
                      "give a perturbation")
    # the analysis windows: envelope over about two periods of the slowest oscillation seen
    cross = _upward_crossings(t, disp[:, j] - 0.5 * (disp[:, j].max() + disp[:, j].min()))
    per = float(np.median(np.diff(cross))) if cross.size >= 3 else (t[-1] - t[0]) / 4
    env = _running_max(big, int(round(2 * per / sample)))
    # the linear range: the longest stretch of samples with every motion within LINEAR_LIMIT
    i0, i1 = _longest_run(big <= LINEAR_LIMIT * length_scale)
    linear_to_end = i1 == len(t) - 1
    if i1 > i0:
        # keep the envelope within DYNAMIC_RANGE of its largest value there
        part = env[i0:i1 + 1]
        strong = np.nonzero(part >= part.max() / DYNAMIC_RANGE)[0]
        i0, i1 = i0 + int(strong[0]), i0 + int(strong[-1])
    cycle = _tail_cycle(t, zz[:, :6], j)
    approach = bool(env[0] > 0 and (env[-1] / env[0] >= 2.0 or env[-1] / env[0] <= 0.5))
    settled = cycle is not None and cycle.settled and approach and cycle.amplitude[DOF_NAMES[j]] > 0
    fit = _fit(y, i0, i1, sample, omega_max)
    good = fit is not None and fit.misfit <= MISFIT_TOL
    win = (float(t[i0]), float(t[i1]))
    if good:
        label, rate, pole, tau = _label(fit)
        # the modal fit says the amplitude still changes per period, yet the motion has settled
        stopped = settled and abs(rate) * cycle.period > 2 * CYCLE_RTOL
        if linear_to_end and not stopped:
            return result(label, rate, None, win, fit, pole, tau=tau)
    if settled:
        # the rate of the growth (or decay) towards the cycle, while it is small
        growth = _growth_phase_fit(y, env, sample, omega_max)
        gwin = (t0, t1)
        if growth is None and good:
            growth, gwin = fit, win
        rate, pole, tau = _label(growth)[1:] if growth is not None else (math.nan, None, None)
        return result("limit cycle", rate, None, gwin, growth, pole, cycle, tau)
    if good:
        return result(label, rate, f"the motion is beyond the linear range after t = {t[i1]:.4g} s: the label "
                      "describes the motion before it", win, fit, pole, tau=tau)
    if fit is None:
        return result("undetermined", reason=f"too few samples ({i1 - i0 + 1}) in the linear-range window "
                      f"{win[0]:.4g}-{win[1]:.4g} s for a modal fit: run longer or sample finer", win=win)
    if cycle is None:
        why = (f"the motion is not a sum of linear modes (misfit {fit.misfit:.2g}) and the run ends before five "
               "periods of a cycle could be compared: run longer")
    else:
        why = (f"the motion is not a sum of linear modes (misfit {fit.misfit:.2g}) and not yet periodic: its "
               f"amplitude changed by {100 * cycle.change:.2g} % over its last {cycle.periods} periods: run longer")
    return result("undetermined", reason=why, win=win, fit=fit)


def _fit(y: Array, i0: int, i1: int, sample: float, omega_max: float | None) -> ModalFit | None:
    """Modal fit of the samples ``i0..i1``, thinned to about FIT_SAMPLES_PER_PERIOD samples per
    period of the fastest mode and at most FIT_MAX_SAMPLES samples."""
    count = i1 - i0 + 1
    stride = 1
    if omega_max:
        stride = max(1, int(2 * math.pi / (FIT_SAMPLES_PER_PERIOD * omega_max) / sample))
    stride = max(stride, int(math.ceil(count / FIT_MAX_SAMPLES)))
    ys = y[i0:i1 + 1:stride]
    if len(ys) < 24:
        return None
    return modal_fit(ys, sample * stride)


def _growth_phase_fit(y, env, sample, omega_max) -> ModalFit | None:
    """Modal fit where the envelope is below a hundredth of its final value (the small-amplitude
    growth towards a limit cycle, where the nonlinear terms are 1e-4 of the motion)."""
    small = np.nonzero(env >= env[-1] / 100.0)[0]
    end = int(small[0]) if small.size else len(y) - 1
    if end < 24:
        return None
    strong = np.nonzero(env[: end + 1] >= env[: end + 1].max() / DYNAMIC_RANGE)[0]
    fit = _fit(y, int(strong[0]), end, sample, omega_max)
    return fit if fit is not None and fit.misfit <= MISFIT_TOL else None


def _linear_poles(fit: ModalFit) -> NDArray[np.complex128]:
    """The significant poles of a modal fit that are modes of the motion: without the static
    offset (a pole at zero) and without combination tones (:func:`_is_combination`)."""
    sig = fit.significant()
    order = np.argsort(-fit.contribution[sig])
    poles, size = fit.poles[sig][order], fit.contribution[sig][order]
    scale = np.abs(poles).max()
    keep = []
    for k, p in enumerate(poles):
        if abs(p) <= ZETA_NEUTRAL * scale:
            continue  # a static offset
        if _is_combination(p, poles[:k][size[:k] >= 10.0 * size[k]]):
            continue
        keep.append(p)
    return np.asarray(keep if keep else poles[:1], dtype=complex)


def _is_combination(p: complex, stronger: NDArray[np.complex128]) -> bool:
    """True when ``p`` is a combination tone of the ``stronger`` poles (each at least ten times
    its size): the quadratic and cubic terms of the equations acting on the modes give poles at
    sums of two or three of them (``2 lambda``, ``lambda + conj(lambda) = 2 sigma``,
    ``2 lambda + conj(lambda)`` ...). ``p`` must match such a sum in frequency (within
    COMBINATION of the largest ``|lambda|``) and in growth rate (within a fifth of the sum's, a
    combination of decaying modes cannot grow), and the sum must be distinct from each of the
    poles (by more than COALESCE of the largest ``|lambda|``: ``a + b + conj(b) = a + 2 Re b``
    with a neutral ``b`` falls on ``a`` itself and says nothing)."""
    if not stronger.size:
        return False
    scale = float(np.abs(stronger).max())
    sums = (stronger[:, None] + stronger[None, :]).ravel()
    sums = np.concatenate([sums, (sums[:, None] + stronger[None, :]).ravel()])
    near = ((np.abs(sums.imag - p.imag) <= COMBINATION * scale)
            & (np.abs(sums.real - p.real) <= 0.2 * np.abs(sums.real) + ZETA_NEUTRAL * scale))
    if not near.any():
        return False
    distinct = np.min(np.abs(sums[near][:, None] - stronger[None, :]), axis=1) > COALESCE * scale
    return bool(distinct.any())


def _label(fit: ModalFit) -> tuple[str, float, complex, float]:
    """``(label, rate, pole, tau)`` from the modes of a modal fit (:func:`_linear_poles`).

    A double root (the coalescence at a critical thrust) is fitted as two poles a small
    distance apart, split about its true place (the realization of a defective pole is
    ill-conditioned); the pair, with its mean growth rate, is taken as one root.
    """
    poles = _linear_poles(fit)
    pairs = [(a, b) for a in range(poles.size) for b in range(a + 1, poles.size)
             if abs(poles[a] - poles[b]) <= COALESCE * abs(poles[a]) and poles[a].imag * poles[b].imag >= 0]
    merged = np.ones(poles.size, dtype=bool)
    double = []
    for a, b in pairs:
        if merged[a] and merged[b]:
            merged[b] = False
            double.append(a)
            poles[a] = 0.5 * (poles[a] + poles[b])
    k = int(np.argmax(np.where(merged, poles.real, -np.inf)))
    pole = complex(poles[k])
    rate = float(pole.real)
    tau = ZETA_NEUTRAL * abs(pole)
    if rate > tau:
        return "exponential growth", rate, pole, tau
    if rate < -tau:
        return "decaying", rate, pole, tau
    # neutral: a neutral double root grows linearly in time
    if any(abs(poles[a].real) <= tau for a in double):
        return "linear growth", rate, pole, tau
    return "bounded", rate, pole, tau


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
