"""A branch of limit cycles with Floquet multipliers against time integration to steady state.

Model: ``examples/imp_hardening.toml`` (supercritical onset at T_c = 12672.9 N). Fifty thrusts
equally spaced from T_c + 50 N to T_c + 1000 N.

* impstab: ``propulsor_postcritical(model, thrusts=...)``, end to end: the linear onset, the Hopf
  analysis, the collocation branch from the Hopf point with Floquet multipliers of every cycle
  (stability decided), each requested thrust solved exactly.
* baseline, the route a user has without this feature, made competent: impstab's own compiled
  Hamming integrator (``impstab.simulate``, default step) at each thrust in increasing order,
  each run starting from the state the previous thrust settled on (a slow thrust ramp, the
  quickest way onto each cycle); the first from a pitch displacement of 0.01 rad. Each thrust
  is integrated in windows of 20 onset periods until the amplitude of every coordinate (half the
  peak-to-peak over the window's last period, sampled at every step, each extreme refined by the
  parabola through its neighbours) is settled to ``SETTLE``
  relative: the change between windows, and the remaining error it implies under geometric
  convergence (``change r / (1 - r)``, ``r`` the ratio of successive changes), below it. This gives no stability information beyond "it
  attracts"; unstable cycles it cannot find at all.

``amplitude_rel_err`` is the largest relative difference in the pitch amplitude between the two
over the fifty thrusts (the settled integration carries its own step error, about 2e-5 at the
default step, and the settling tolerance). AUTO-07p (Debian ``auto-07p``) needs the equations of
motion transcribed to Fortran; that is not done here, so its column is null.

Run: ``python benchmarks/postcritical.py``; ends with one JSON line. Timings on a shared machine
are noisy: compare ratios of one run.
"""

from __future__ import annotations

import json
import math
import shutil
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import impstab  # noqa: E402
from impstab.postcritical import propulsor_postcritical  # noqa: E402

POINTS = 50
#: target accuracy of the settled amplitude (relative)
SETTLE = 1e-4
WINDOW_PERIODS = 20
MAX_WINDOWS = 500


def _extreme(y, sign):
    """``sign * max(sign * y)`` of each column, refined by the parabola through the largest sample
    and its neighbours (the sampled peak alone is off by (pi dt / T)^2 / 2, some 5e-4 here)."""
    v = sign * y
    k = np.clip(np.argmax(v, axis=0), 1, v.shape[0] - 2)
    c = np.arange(v.shape[1])
    a, b, d = v[k - 1, c], v[k, c], v[k + 1, c]
    den = a - 2 * b + d
    shift = np.where(den != 0, 0.5 * (a - d) / np.where(den != 0, den, 1.0), 0.0)
    return sign * (b - 0.25 * (a - d) * shift)


def brute_force(model, thrusts, tc, period):
    """Amplitudes (pitch) at each thrust by integrating to steady state; returns (amplitudes, sim seconds)."""
    amps = []
    unsettled: list[float] = []
    simulated = 0.0
    state = None
    for t in thrusts:
        pert = {"displacement": {"pitch": 0.01}} if state is None else {"displacement": state[:6], "velocity": state[6:]}
        last, prev = None, None
        for _ in range(MAX_WINDOWS):
            run = impstab.simulate(model, thrust=float(t), duration=WINDOW_PERIODS * period, critical_thrust=tc,
                                   perturbation=pert)
            simulated += WINDOW_PERIODS * period
            y = run.deviation + run.equilibrium
            tail = run.time >= run.time[-1] - 1.05 * period
            amp = 0.5 * (_extreme(y[tail, :6], 1.0) - _extreme(y[tail, :6], -1.0))
            z = run.deviation[-1]
            pert = {"displacement": z[:6], "velocity": z[6:]}
            if last is not None:
                change = float(np.max(np.abs(amp - last) / np.maximum(np.abs(amp), 1e-300)))
                # geometric convergence: the remaining error is change * r / (1 - r), r the ratio of
                # successive changes
                r = min(change / prev, 0.999) if prev else 0.5
                # (or a change at the sampling noise floor, a tenth of the target)
                if change < 0.1 * SETTLE or (change * r / (1.0 - r) < SETTLE and change < SETTLE):
                    break
                prev = change
            last = amp
        else:
            unsettled.append(float(t))          # counted and reported, its last window kept
        state = run.deviation[-1]        # deviation from this thrust's equilibrium, close to the next one's
        amps.append(amp[4])
    return np.array(amps), simulated, unsettled


def main() -> None:
    model = impstab.load_model(ROOT / "examples" / "imp_hardening.toml")
    crit = impstab.critical_thrust(model)
    tc = crit.thrust
    thrusts = np.linspace(tc + 50.0, tc + 1000.0, POINTS)
    # warm the compiled kernels of both routes (the cache may be cold)
    propulsor_postcritical(model, thrust_max=tc * 1.01, max_points=3)
    impstab.simulate(model, thrust=float(thrusts[0]), duration=0.1, critical_thrust=tc)

    t0 = time.perf_counter()
    res = propulsor_postcritical(model, thrust_max=float(thrusts[-1]), thrusts=thrusts.tolist(), max_points=200)
    t_branch = time.perf_counter() - t0
    pc_amp = np.array([res.branch_amplitude[list(res.branch_thrust).index(t), 4] for t in thrusts])
    cycles = res.branch_thrust.size
    period = float(2 * math.pi / res.omega)
    trivial = float(np.nanmax(res.trivial_multiplier_error))
    print(f"impstab branch: {cycles} cycles ({POINTS} requested), Floquet multipliers of each, {t_branch:.2f} s; "
          f"stop: {res.stop_reason}; max |mu_trivial - 1| = {trivial:.1e}; all stable: {bool(res.branch_stable.all())}")

    t0 = time.perf_counter()
    bf_amp, simulated, unsettled = brute_force(model, thrusts, tc, period)
    t_brute = time.perf_counter() - t0
    err = np.abs(bf_amp / pc_amp - 1.0)
    print(f"time integration to steady state: {POINTS} thrusts, {simulated:.0f} s simulated, {t_brute:.2f} s; "
          f"settled to {SETTLE:g} relative in {WINDOW_PERIODS}-period windows")
    if unsettled:
        print(f"not settled within {MAX_WINDOWS} windows at {len(unsettled)} thrusts: "
              + ", ".join(f"{t:.1f}" for t in unsettled) + " N (their last window is compared)")
    print(f"{'thrust (N)':>12} {'pitch amp (rad)':>16} {'brute force':>14} {'rel. diff':>10}")
    for k in range(0, POINTS, 7):
        print(f"{thrusts[k]:12.2f} {pc_amp[k]:16.8g} {bf_amp[k]:14.8g} {err[k]:10.2e}")
    auto = shutil.which("auto-07p") or shutil.which("auto")
    print("AUTO-07p:", "installed at " + auto + "; the propulsor equations are not transcribed to Fortran, no timing"
          if auto else "not installed, skipped")
    print("note: timings measured on a shared machine; compare the ratios of one run")
    print(json.dumps({"speedup_vs_time_integration": t_brute / t_branch, "amplitude_rel_err": float(err.max()),
                      "branch_seconds": t_branch, "time_integration_seconds": t_brute, "points": POINTS,
                      "cycles_computed": int(cycles), "simulated_seconds": simulated,
                      "max_trivial_multiplier_error": trivial, "unsettled_thrusts": len(unsettled),
                      "speedup_vs_auto07p": None}))


if __name__ == "__main__":
    main()
