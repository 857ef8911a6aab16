"""A branch of limit cycles with Floquet multipliers against time integration to steady state and AUTO-07p.

Model: ``examples/imp_hardening.toml`` (supercritical onset at T_c = 12672.9 N). Fifty thrusts
equally spaced from T_c + 50 N to T_c + 1000 N; the amplitude of a cycle is the half
peak-to-peak of each of the six coordinates (X_A, Y_A, Z_A, phi, theta, psi), as the branch
reports it; errors are relative, per coordinate, the largest over the six and the fifty thrusts.

* impstab: ``propulsor_postcritical(model, thrusts=...)`` with its default settings, end to end:
  the linear onset, the Hopf analysis, the collocation branch from the Hopf point with the
  Floquet multipliers of every cycle (stability decided), each requested thrust solved exactly.
* reference (not timed): the same branch on a mesh four times finer (160 intervals). It is an
  independent check of nothing by itself; what makes it a reference is that the two other
  methods below, which share no code with it (AUTO-07p's own collocation of a transcription of
  the equations to Fortran; time integration), agree with it at every thrust to the errors
  printed. The branch's own accuracy, the largest error against it, sets the tolerance
  ``tol`` to which the baseline is settled ("the same amplitude accuracy").
* baseline, the route a user has without this feature (``benchmarks/steady_state.py``): time
  integration to steady state at each thrust with impstab's compiled Hamming integrator (called
  directly, without the post-processing ``simulate`` adds to every run), thrusts in increasing
  order, each starting from the state the previous one settled on (the first from a pitch of
  0.01 rad). Step: an eighth of ``simulate``'s default (40 steps per period of the fastest
  mode): the integrator's own error in the amplitudes is 3e-7 (pitch) to 4e-6 (surge) at the
  default step at T_c + 500 N; it shifts the numerical onset, so the relative error grows as
  1 / (T - T_c): settled at T_c + 50 N it is 7e-8 with a quarter of the default step and 7e-9
  with an eighth (measured). Every cycle's amplitude is
  measured (extrema refined by a quartic through five samples); a thrust is settled when the
  geometric tail of its amplitude changes, with the decay per cycle measured from the data over
  24-cycle windows (it matches the slowest Floquet multiplier, e.g. 0.9984 at T_c + 50 N), is
  below ``tol`` for every coordinate (see ``steady_state.py``). It gives no stability
  information beyond "it attracts"; unstable cycles it cannot find at all.
* AUTO-07p (Debian ``auto-07p``, when installed; ``benchmarks/auto07p/``): the same equations
  transcribed to a Fortran equations file written at run time into a temporary folder, compiled
  with gfortran against AUTO's library; equilibria from T = 0 to its Hopf point (HB), then its
  periodic orbits from HB over the same thrusts (orthogonal collocation NCOL = 4 like impstab's
  degree 4, adaptive mesh IAD = 3, Floquet multipliers ISP = 2, the fifty thrusts located as
  user points UZR, Newton tolerances EPSL = EPSU = 1e-10, EPSS = 1e-9, finite-difference Jacobian
  JAC = 0, one OpenMP thread). NTST is the smallest of 10, 20, 30, 40, 50, 60, 80 whose
  amplitude error reaches the impstab branch's; its time includes the compilation of the
  equations file (reported also without).

The two quick methods are timed as the best of two runs, the baseline once (it runs minutes).

Run: ``python benchmarks/postcritical.py``; ends with one JSON line. Timings on a shared machine
are noisy: compare ratios of one run.
"""

from __future__ import annotations

from impstab._blas import prefer_single_thread

prefer_single_thread()  # before numpy loads: impstab and the baseline with one BLAS thread, as the CLI runs

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "benchmarks"))

import impstab  # noqa: E402
from impstab._jit import require_compiled  # noqa: E402
from impstab.dynamics.simulate import default_step  # noqa: E402
from impstab.postcritical import propulsor_postcritical  # noqa: E402

import auto07p  # noqa: E402
from steady_state import settle_sweep  # noqa: E402

POINTS = 50
#: the reference branch's mesh, relative to the default
REFERENCE_REFINEMENT = 4
#: the baseline's step, as a fraction of simulate's default
STEP_DIVISOR = 8
#: floor of the baseline's tolerance (the integrator's own error at that step)
TOL_FLOOR = 5e-9
AUTO_NTST = (10, 20, 30, 40, 50, 60, 80)
#: timed runs of the two quick methods (the best is kept: the machine is shared)
REPEATS = 2


def _at(res, thrusts):
    bt = list(res.branch_thrust)
    k = [bt.index(t) for t in thrusts]
    return res.branch_amplitude[k], res.branch_period[k], res


def rel_err(amp, ref):
    return np.abs(amp / ref - 1.0)


def main() -> None:
    require_compiled()  # the kernels are what is timed here (a fresh process starts them interpreted)
    model = impstab.load_model(ROOT / "examples" / "imp_hardening.toml")
    crit = impstab.critical_thrust(model)
    tc = crit.thrust
    thrusts = np.linspace(tc + 50.0, tc + 1000.0, POINTS)
    t_top = float(thrusts[-1])
    # warm the compiled kernels of both routes (the cache may be cold)
    propulsor_postcritical(model, thrust_max=tc * 1.01, max_points=3)
    settle_sweep(model, thrusts[-1:], tolerance=1e-3, period=2 * math.pi / crit.omega,
                 step=default_step(model, t_top), max_cycles=50)

    t_branch = math.inf
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        res = propulsor_postcritical(model, thrust_max=t_top, thrusts=thrusts.tolist(), max_points=200)
        t_branch = min(t_branch, time.perf_counter() - t0)
    pc_amp, pc_per, _ = _at(res, thrusts)
    trivial = float(np.nanmax(res.trivial_multiplier_error))
    print(f"impstab branch: {res.branch_thrust.size} cycles ({POINTS} requested), Floquet multipliers of each, "
          f"{t_branch:.2f} s; stop: {res.stop_reason}; max |mu_trivial - 1| = {trivial:.1e}; "
          f"all stable: {bool(res.branch_stable.all())}")

    intervals = REFERENCE_REFINEMENT * 40
    ref_amp, ref_per, _ = _at(propulsor_postcritical(model, thrust_max=t_top, thrusts=thrusts.tolist(),
                                                     max_points=200, intervals=intervals), thrusts)
    pc_err = rel_err(pc_amp, ref_amp)
    tol = max(float(pc_err.max()), TOL_FLOOR)
    print(f"reference: the branch on {intervals} mesh intervals; impstab branch error {pc_err.max():.2e} "
          f"(per coordinate X_A..psi: " + ", ".join(f"{v:.1e}" for v in pc_err.max(axis=0)) + ")")
    print(f"baseline tolerance: {tol:.2e} relative on every coordinate")

    period = float(2 * math.pi / res.omega)
    step = default_step(model, float(thrusts[0])) / STEP_DIVISOR
    t0 = time.perf_counter()
    bf = settle_sweep(model, thrusts, tolerance=tol, period=period, step=step)
    t_brute = time.perf_counter() - t0
    bf_err = rel_err(bf.amplitude, ref_amp)
    print(f"time integration to steady state: {POINTS} thrusts, step {step:.3g} s, {bf.steps} steps, "
          f"{bf.simulated:.0f} s simulated ({int(bf.cycles.sum())} cycles, {int(bf.cycles[0])} at the first "
          f"thrust), {t_brute:.2f} s; error {bf_err.max():.2e}")
    if bf.unsettled:
        print(f"not settled within the cycle cap at {len(bf.unsettled)} thrusts: "
              + ", ".join(f"{t:.1f}" for t in bf.unsettled) + " N (their last cycle is compared)")

    why = auto07p.available()
    auto = None
    auto_rows = []
    if why is None:
        for ntst in AUTO_NTST:
            try:
                b = auto07p.run_branch(model, thrusts, t_top, ntst=ntst, ncol=4)
            except (RuntimeError, OSError) as exc:
                print(f"AUTO-07p NTST = {ntst}: failed: {str(exc).splitlines()[0]}")
                continue
            err = rel_err(b.amplitude[:, :6], ref_amp)
            auto_rows.append((b, err))
            print(f"AUTO-07p NTST = {ntst:3d}, NCOL = 4: {b.points} points, {b.seconds:.2f} s "
                  f"({b.compile_seconds:.2f} s compiling, {b.run_seconds:.2f} s running); error {err.max():.2e}")
            if err.max() <= pc_err.max():
                auto = (b, err)
                break
        if auto is None and auto_rows:
            auto = min(auto_rows, key=lambda r: r[1].max())
            print("AUTO-07p did not reach the impstab branch's accuracy; its most accurate run is compared")
    else:
        print(f"AUTO-07p: skipped: {why}")
    if auto is not None:
        for _ in range(REPEATS - 1):
            again = auto07p.run_branch(model, thrusts, t_top, ntst=auto[0].ntst, ncol=4)
            if again.seconds < auto[0].seconds:
                auto = (again, rel_err(again.amplitude[:, :6], ref_amp))
        print(f"AUTO-07p timed: NTST = {auto[0].ntst}, best of {REPEATS} runs {auto[0].seconds:.2f} s "
              f"({auto[0].run_seconds:.2f} s without compiling)")

    print(f"{'thrust (N)':>12} {'pitch amp (rad)':>16} {'period (s)':>12} {'impstab err':>12} "
          f"{'time int. err':>14} {'AUTO err':>10}")
    for k in sorted(set(range(0, POINTS, 7)) | {POINTS - 1}):
        a_err = f"{auto[1][k].max():10.1e}" if auto else f"{'-':>10}"
        print(f"{thrusts[k]:12.2f} {ref_amp[k, 4]:16.10g} {ref_per[k]:12.9f} {pc_err[k].max():12.1e} "
              f"{bf_err[k].max():14.1e} {a_err}")
    out = {"speedup_vs_time_integration": t_brute / t_branch, "amplitude_rel_err": max(float(pc_err.max()),
                                                                                       float(bf_err.max())),
           "branch_amplitude_rel_err": float(pc_err.max()),
           "time_integration_amplitude_rel_err": float(bf_err.max()), "settling_tolerance": tol,
           "branch_seconds": t_branch, "time_integration_seconds": t_brute, "points": POINTS,
           "cycles_computed": int(res.branch_thrust.size), "simulated_seconds": bf.simulated,
           "time_steps": int(bf.steps), "max_trivial_multiplier_error": trivial,
           "unsettled_thrusts": len(bf.unsettled), "speedup_vs_auto07p": None, "auto07p_seconds": None,
           "auto07p_amplitude_rel_err": None}
    if auto:
        b, err = auto
        per_err = float(np.max(np.abs(b.period / ref_per - 1.0)))
        print(f"AUTO-07p against impstab: Hopf thrust {b.hopf_thrust:.6f} N vs {res.critical_thrust:.6f} N "
              f"(rel. {abs(b.hopf_thrust / res.critical_thrust - 1):.1e}), onset omega {b.hopf_omega:.9f} vs "
              f"{res.omega:.9f} rad/s (rel. {abs(b.hopf_omega / res.omega - 1):.1e}); periods agree to "
              f"{per_err:.1e}, amplitudes to {err.max():.1e} at all {POINTS} thrusts (NTST = {b.ntst})")
        out.update({"speedup_vs_auto07p": b.seconds / t_branch, "auto07p_seconds": b.seconds,
                    "auto07p_run_seconds": b.run_seconds, "speedup_vs_auto07p_run_only": b.run_seconds / t_branch,
                    "auto07p_amplitude_rel_err": float(err.max()), "auto07p_ntst": b.ntst,
                    "auto07p_period_rel_err": per_err})
    else:
        print("AUTO-07p: no comparison" + (f" ({why})" if why else ""))
    print("note: timings measured on a shared machine; compare the ratios of one run")
    print(json.dumps(out))


if __name__ == "__main__":
    main()
