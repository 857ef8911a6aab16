"""Nonlinear time simulation of the symmetric example: impstab against two baselines, same run.

Model: ``examples/imp_symmetric.toml`` at T = 5000 N from its static equilibrium, kicked in sway
(1e-3 m/s), heave (5e-4 m/s) and yaw (2e-3 rad/s). impstab runs 1e5 steps of Hamming's method at
its default step (40 steps per period of the fastest mode), end to end through
``impstab.simulate`` (equilibrium, linearization, compiled loop, mount forces, growth fit).

Baselines, timed in the same process:

(a) a plain-Python right-hand side of the same equations (NumPy, written out below, C_RB nu in
    its Newton-Euler form, cross products without ``np.cross``) integrated by
    ``scipy.integrate.solve_ivp`` over the same simulated time at matched accuracy: the loosest
    ``rtol`` in 1e-4, 1e-5, ... whose global error is no larger than Hamming's; RK45 and DOP853
    are both tried and the faster counts;
(b) Exudyn, a compiled multibody code (C++ core driven from Python), on the same body, springs
    and follower force, with the same number of steps of its explicit RK4 (``RK44``), when the
    optional ``exudyn`` package is installed (``pip install exudyn``); otherwise null.

Error: the largest weighted deviation (rotations x the length scale, velocities / omega_max)
from a DOP853 reference at rtol 1e-12 on the compiled right-hand side, relative to the largest
motion. Prints a table of medians and ends with one JSON line.
"""

from __future__ import annotations

import json
import math
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import impstab
from impstab.dynamics.simulate import default_step
from impstab.kinematics import euler_zyx_to_matrix

# the Exudyn model is the peer test's own, one implementation for both
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "dynamics"))
from exudyn_peer import exudyn_system  # noqa: E402

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "imp_symmetric.toml"
THRUST = 5000.0
STEPS = 100_000
STRIDE = 10
KICK = {"velocity": {"sway": 1e-3, "heave": 5e-4, "yaw": 2e-3}}
REPEATS = 3


def cross(a, b):
    """``a x b`` without ``np.cross`` (which costs ~10 us per call on 3-vectors)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def python_rhs(model, yeq, thrust):
    """The equations of motion in plain NumPy (THEORY 2, 7): the baseline's right-hand side."""
    minv = np.linalg.inv(model.mass_matrix)
    body, th = model.body, model.thrust
    mounts = [(mt.position, mt.stiffness[:3, :3], mt.damping[:3, :3]) for mt in model.mounts]
    e, r_t, eta_t = th.direction, th.point, th.tangency
    mass, r_g, i_a = body.mass, body.cg, body.inertia_a

    def rhs(t, z):
        y = yeq + z
        x, (phi, theta, psi), nu = y[:3], y[3:6], y[6:]
        rot = euler_zyx_to_matrix(phi, theta, psi)
        j2 = np.array([[1.0, math.sin(phi) * math.tan(theta), math.cos(phi) * math.tan(theta)],
                       [0.0, math.cos(phi), -math.sin(phi)],
                       [0.0, math.sin(phi) / math.cos(theta), math.cos(phi) / math.cos(theta)]])
        vh, wh = rot @ nu[:3], rot @ nu[3:]
        force, moment = np.zeros(3), np.zeros(3)
        for r, k, c in mounts:
            rho = rot @ r
            f = -k @ (x + rho - r) - c @ (vh + cross(wh, rho))
            force += f
            moment += cross(rho, f)
        ft = thrust * (eta_t * (rot @ e) + (1 - eta_t) * e)
        force += ft
        moment += cross(rot @ r_t, ft)
        tau = np.concatenate([rot.T @ force, rot.T @ moment])
        v, w = nu[:3], nu[3:]
        wv = cross(w, v)
        tau[:3] -= mass * (wv + cross(w, cross(w, r_g)))
        tau[3:] -= cross(w, i_a @ w) + mass * cross(r_g, wv)
        return np.concatenate([vh, j2 @ nu[3:], minv @ tau])

    return rhs


def weighted_error(z, ref, w):
    n = min(len(z), len(ref))
    return float(np.abs((z[:n] - ref[:n]) * w).max() / np.abs(ref[:n] * w).max())


def exudyn_seconds(model, res, duration):
    """Wall time of Exudyn's RK44 over the same steps, and its final weighted state; None without it."""
    try:
        import exudyn as exu
    except ImportError:
        return None, None
    warnings.simplefilter("ignore", DeprecationWarning)
    y0 = res.equilibrium + res.deviation[0]
    times, final = [], None
    for _ in range(REPEATS):
        _, mbs, settings, node = exudyn_system(model, THRUST, y0[:6], y0[6:], duration, STEPS)
        t0 = time.perf_counter()
        mbs.SolveDynamic(settings, solverType=exu.DynamicSolverType.RK44)
        times.append(time.perf_counter() - t0)
        final = np.array(mbs.GetNodeOutput(node, exu.OutputVariableType.Position)) - res.equilibrium[:3]
    return statistics.median(times), final


def main() -> int:
    model = impstab.load_model(EXAMPLE)
    h = default_step(model, THRUST)
    duration = STEPS * h
    kw = dict(thrust=THRUST, duration=duration, perturbation=KICK, critical_thrust=False, sample=STRIDE * h)
    impstab.simulate(model, **{**kw, "duration": 50 * h})  # compile / load the cache
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        res = impstab.simulate(model, dt=h, **kw)
        times.append(time.perf_counter() - t0)
    t_imp = statistics.median(times)
    assert res.steps == STEPS and res.completed
    ref = impstab.simulate(model, integrator="dop853", rtol=1e-12, **kw)
    omega, length = res.fastest_omega, res.length_scale
    w = np.array([1, 1, 1, length, length, length] + [1 / omega] * 3 + [length / omega] * 3)
    err_imp = weighted_error(res.deviation, ref.deviation, w)

    # (a) plain Python + solve_ivp at matched accuracy
    rhs = python_rhs(model, res.equilibrium, THRUST)
    rng = np.random.default_rng(0)
    from impstab.dynamics.system import evaluate_rhs, pack_dynamics

    system = pack_dynamics(model)
    check = max(np.abs(rhs(0, z) - evaluate_rhs(system, res.equilibrium, z, THRUST)[0]).max()
                for z in rng.normal(scale=1e-3, size=(5, 12)))
    t_eval = res.time
    scale = float(np.abs(w * res.deviation[0]).max())
    best = None
    for method in ("RK45", "DOP853"):
        for rtol in 10.0 ** -np.arange(4, 12):
            print(f"  baseline {method} rtol {rtol:.0e} ...", file=sys.stderr, flush=True)
            t0 = time.perf_counter()
            sol = solve_ivp(rhs, (0.0, duration), res.deviation[0], method=method, t_eval=t_eval, rtol=rtol,
                            atol=rtol * scale / w)
            wall = time.perf_counter() - t0
            err = weighted_error(sol.y.T, ref.deviation, w)
            if sol.success and err <= err_imp:
                if best is None or wall < best[0]:
                    best = (wall, method, rtol, err, sol.nfev)
                break
    t_py, py_method, py_rtol, err_py, nfev = best

    # (b) a compiled multibody code
    t_mb, mb_final = exudyn_seconds(model, res, duration)
    err_mb = None if mb_final is None else float(np.abs(mb_final - ref.deviation[-1, :3]).max() / np.abs(ref.deviation[:, :3]).max())

    rows = [("impstab hamming (simulate, end to end)", t_imp, err_imp, f"{STEPS} steps, {res.rhs_evaluations} f-evals"),
            (f"plain Python + solve_ivp {py_method} rtol {py_rtol:.0e}", t_py, err_py, f"{nfev} f-evals"),
            ("Exudyn RK44", t_mb, err_mb, f"{STEPS} steps" if t_mb else "exudyn not installed")]
    print(f"{model.name}: T = {THRUST:g} N, {STEPS} steps of {h:.4g} s = {duration:.4g} s simulated")
    print(f"plain-Python right-hand side equals the compiled one to {check:.1e}")
    print(f"{'run':48s} {'time (s)':>10s} {'error':>10s}  notes")
    for name, t, err, note in rows:
        ts = "-" if t is None else f"{t:.4f}"
        es = "-" if err is None else f"{err:.2e}"
        print(f"{name:48s} {ts:>10s} {es:>10s}  {note}")
    out = {
        "steps_per_s": round(STEPS / t_imp, 1),
        "speedup_vs_python_solve_ivp": round(t_py / t_imp, 2),
        "speedup_vs_multibody": None if t_mb is None else round(t_mb / t_imp, 2),
        "impstab_s": round(t_imp, 4), "kernel_s": round(res.wall_time, 4), "error": err_imp,
        "python_solve_ivp_s": round(t_py, 3), "python_method": py_method, "python_rtol": py_rtol, "python_error": err_py,
        "multibody_s": None if t_mb is None else round(t_mb, 4), "multibody": "exudyn RK44" if t_mb else None,
        "multibody_error": err_mb,
    }
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
