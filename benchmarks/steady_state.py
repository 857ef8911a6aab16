"""Limit-cycle amplitudes by time integration to steady state: the route without a cycle solver.

:func:`settle_sweep` integrates the model at each thrust of an increasing list with impstab's
compiled Hamming integrator (:class:`impstab.dynamics.integrators.Hamming`, the integrator of
``impstab simulate``, called directly so that no time is spent on the envelope fit and the mount
loads ``simulate`` adds to every run), each thrust starting from the state the previous one
settled on (a quasi-static thrust ramp: the quickest way onto each cycle), the first from a
pitch displacement. It integrates in chunks of a few periods, samples every step, and measures
each cycle's amplitude (:func:`cycle_amplitudes`): cycles run from one upward crossing of the
pitch's mid-range to the next; the maximum and the minimum of each coordinate in each cycle
(windows centred on them, so that a coordinate moving at twice the frequency, like the surge,
is measured on the same extremum every cycle) are refined by the quartic through the five
samples around them (error ~ (omega h)^6, far below the tolerances here).

Settling criterion. Past the transients of the fast modes, the amplitudes approach their limit
as ``a_k = a + c r^k``, ``r`` the Floquet multiplier of the cycle's slowest transverse mode
(close to 1 next to the onset, where settling is slowest); on this model a complex pair of
almost the same modulus (0.981 against 0.985 at T_c + 900 N) superposes an oscillation of some
8 cycles, so successive ratios of changes scatter and are useless. The test works on windows of
``window`` cycles instead: ``E`` the largest change ``|a_k - a_{k-1}|`` in a window, the decay
per cycle ``r = q^(1/window)`` with ``q`` the larger of the ratios of the last three windows'
``E`` (measured from the data, never from the Floquet multipliers), and the remaining error of
the last cycle bounded by the geometric tail ``E r / (1 - r)``. A thrust is settled when, for
every coordinate, that bound is below ``tolerance`` times the amplitude, or the changes are
below the measurement floor (``FLOOR`` of the amplitude). The last measured cycle's amplitude
is reported (no extrapolation).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["settle_sweep", "SweepResult", "cycle_amplitudes"]

# quartic through the samples at -2..2: coefficients c = P @ samples (c0 + c1 x + ... + c4 x^4)
_P = np.linalg.inv(np.vander(np.arange(-2.0, 3.0), 5, increasing=True))


def _refine(v: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Extreme values of ``v`` (1-D) near the sample indices ``idx`` (quartic fit, Newton)."""
    windows = v[idx[:, None] + np.arange(-2, 3)[None, :]]                 # (k, 5)
    c = windows @ _P.T                                                     # (k, 5)
    x = np.zeros(idx.size)
    for _ in range(6):
        d1 = c[:, 1] + 2 * c[:, 2] * x + 3 * c[:, 3] * x ** 2 + 4 * c[:, 4] * x ** 3
        d2 = 2 * c[:, 2] + 6 * c[:, 3] * x + 12 * c[:, 4] * x ** 2
        x = np.clip(x - d1 / np.where(d2 != 0, d2, 1.0), -1.0, 1.0)
    return c[:, 0] + c[:, 1] * x + c[:, 2] * x ** 2 + c[:, 3] * x ** 3 + c[:, 4] * x ** 4


def _centred_extremes(v: np.ndarray, starts: np.ndarray, sign: float) -> np.ndarray:
    """``sign * max(sign * v)`` over each cycle, the windows shifted so that the extremum of the
    first cycle sits in the middle of its window (every window then holds the same extremum, even
    for a coordinate that oscillates at twice the frequency); refined by :func:`_refine`."""
    length = int(np.median(np.diff(starts)))
    first = starts[0] + int(np.argmax(sign * v[starts[0]:starts[1]]))
    offset = first - starts[0] - length // 2
    idx = []
    for a in starts[:-1] + offset:
        b = a + length
        if a < 2 or b > v.size - 2:
            idx.append(-1)
            continue
        idx.append(a + int(np.argmax(sign * v[a:b])))
    idx = np.array(idx)
    out = np.full(idx.size, np.nan)
    ok = (idx >= 2) & (idx <= v.size - 3)
    out[ok] = sign * _refine(sign * v, idx[ok])
    return out


def cycle_amplitudes(z: np.ndarray, dominant: int = 4) -> np.ndarray:
    """Half peak-to-peak of each column of the samples ``z`` over each cycle, ``(k, n)``.

    Cycles are delimited by the upward crossings of the mid-range of column ``dominant`` (the
    pitch); cycles whose window leaves the samples are dropped.
    """
    v = z[:, dominant]
    mid = 0.5 * (v.max() + v.min())
    starts = np.flatnonzero((v[:-1] < mid) & (v[1:] >= mid)) + 1
    if starts.size < 3:
        return np.zeros((0, z.shape[1]))
    cols = [0.5 * (_centred_extremes(z[:, j], starts, 1.0) - _centred_extremes(z[:, j], starts, -1.0))
            for j in range(z.shape[1])]
    amp = np.array(cols).T
    return amp[np.all(np.isfinite(amp), axis=1)]


@dataclass(frozen=True)
class SweepResult:
    amplitude: np.ndarray         # (k, 6) settled amplitudes of X_A, Y_A, Z_A (m), phi, theta, psi (rad)
    simulated: float              # simulated time, all thrusts (s)
    steps: int                    # time steps, all thrusts
    cycles: np.ndarray            # (k,) cycles integrated at each thrust
    multiplier: np.ndarray        # (k,) the settling ratio r measured at each thrust
    unsettled: tuple[float, ...]  # thrusts not settled within the cycle cap (N)


#: relative change per cycle below which the cycle amplitudes cannot be told apart (their
#: measurement scatter on a converged cycle is 1e-12 to 3e-11 of the amplitude, measured)
FLOOR = 2e-11


class _Tracker:
    """The settling test of one coordinate (see the module docstring)."""

    def __init__(self, tolerance: float, window: int) -> None:
        self.tol = tolerance
        self.window = window
        self.amps: list[float] = []
        self.r_reliable: float | None = None

    def settled(self) -> bool:
        a, w = self.amps, self.window
        if len(a) < 3 * w + 1:
            return False
        d = np.abs(np.diff(np.asarray(a[-3 * w - 1:])))
        e3, e2, e1 = d[:w].max(), d[w:2 * w].max(), d[2 * w:].max()
        scale = abs(a[-1])
        if e1 < FLOOR * scale:
            return True
        if e2 > FLOOR * scale and e3 > FLOOR * scale:
            q = max(e1 / e2, e2 / e3)
            if q < 1.0:
                self.r_reliable = q ** (1.0 / w)
        if self.r_reliable is None:
            return False
        r = self.r_reliable
        return e1 * r / (1.0 - r) < self.tol * scale


def settle_sweep(model, thrusts, *, tolerance: float, period: float, step: float,
                 chunk_periods: int = 8, window: int = 24, max_cycles: int = 30000,
                 first_pitch: float = 0.01) -> SweepResult:
    """Settled amplitudes at each thrust of the increasing ``thrusts`` (N).

    Parameters
    ----------
    tolerance : float
        Relative amplitude accuracy to settle to (every coordinate).
    period : float
        A period estimate (s; the onset period): the chunk length unit.
    step : float
        Fixed step of the Hamming integrator (s).
    chunk_periods : int
        Periods per integrator call between settling tests.
    window : int
        Cycles per window of the settling test (longer than the beat of an oscillating transient).
    max_cycles : int
        Cycles at most per thrust; beyond it the thrust is listed in ``unsettled``.
    """
    from impstab._jit import require_compiled
    from impstab.dynamics.integrators import Problem, get_integrator
    from impstab.dynamics.system import equilibrium_state, pack_dynamics

    require_compiled()  # a long time integration: the compiled kernels from the start
    system = pack_dynamics(model)
    length = system.length_scale
    hamming = get_integrator("hamming")
    stride = 1
    per_chunk = int(math.ceil(chunk_periods * period / step))
    amps, cycles, ratios, unsettled = [], [], [], []
    simulated, steps = 0.0, 0
    y_last = None
    for thrust in np.asarray(thrusts, dtype=float):
        yeq = equilibrium_state(model, float(thrust))[0]
        spin = float(model.propeller.spin(float(thrust), model.thrust.operating))
        if y_last is None:
            z0 = np.zeros(12)
            z0[4] = first_pitch
        else:
            z0 = y_last - yeq
        omega = 2 * math.pi / period
        weights = np.array([1, 1, 1, length, length, length] + [1 / omega] * 3 + [length / omega] * 3)
        trackers = [_Tracker(tolerance, window) for _ in range(6)]
        n_cycles = 0
        done = False
        while not done:
            problem = Problem(system=system, yeq=yeq, z0=z0, t0=0.0, h=step, stride=stride, n_samples=per_chunk,
                              loads=lambda t, T=float(thrust), s=spin: np.vstack(
                                  [np.full(np.shape(t), T), np.full(np.shape(t), s)]),
                              weights=weights, amp_limit=10 * length, pitch_limit=math.radians(85.0), h_max=step,
                              constant_load=(float(thrust), spin))
            raw = hamming.run(problem)
            if not raw.completed:
                raise RuntimeError(f"time integration stopped at {thrust:.2f} N: {raw.reason}")
            simulated += per_chunk * step
            steps += raw.steps
            z0 = raw.z[-1]
            amp = cycle_amplitudes(raw.z[:, :6])
            for j, tr in enumerate(trackers):
                tr.amps.extend(amp[:, j].tolist())
            n_cycles = min(len(tr.amps) for tr in trackers)
            done = all([tr.settled() for tr in trackers])
            if not done and n_cycles > max_cycles:
                unsettled.append(float(thrust))
                break
        y_last = yeq + z0
        amps.append([tr.amps[-1] for tr in trackers])
        cycles.append(n_cycles)
        ratios.append(trackers[4].r_reliable if trackers[4].r_reliable is not None else math.nan)
    return SweepResult(np.array(amps), simulated, steps, np.array(cycles), np.array(ratios), tuple(unsettled))
