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

(c) the floor: an allocation-free hand-written compiled kernel of the same equations (written
    out below for this model's class: translation mounts with 3 x 3 springs and dashpots,
    follower thrust, rigid body with cg offset), Hamming's method with the Gill start, the step
    loop and the right-hand side in one compiled function. It is what the same arithmetic
    costs without any generality (6 x 6 mounts, nonlinear mount laws, fluid damping, propeller,
    thrust histories, step-size control, chunking, error estimates). ``floor_ratio`` is
    impstab's compiled loop time over the floor's (goal: at most 1.5); it is checked to give
    the same trajectory.

Accuracy per right-hand-side evaluation: Hamming at 1/2, 1, 2 and 4 times the default step
count against ``solve_ivp``'s DOP853 (on the same compiled right-hand side) at rtol 1e-4 to
1e-10, each as (evaluations, error, seconds); ``dop853_evals_at_hamming_error`` is the number of
evaluations DOP853 needs for Hamming's error at the default step (log-log interpolation).

Error: the largest weighted deviation (rotations x the length scale, velocities / omega_max)
from a DOP853 reference at rtol 1e-12 on the compiled right-hand side, relative to the largest
motion. Prints a table of medians and ends with one JSON line.
"""

from __future__ import annotations

from impstab._blas import prefer_single_thread

prefer_single_thread()  # before numpy loads: impstab and the baseline with one BLAS thread, as the CLI runs

import json
import math
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from numba import njit
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
REPEATS = 7
SQ2 = math.sqrt(2.0)
GILL = ((SQ2 - 1) / 2, 1 - 1 / SQ2, -1 / SQ2, 1 + 1 / SQ2, 2 - SQ2, 2 + SQ2)


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


# ---------------------------------------------------------------------------------------------
# The floor: an allocation-free hand-written kernel of the same equations (translation mounts
# with 3 x 3 springs and dashpots, follower thrust, rigid body with cg offset, M^-1), Hamming's
# method with three Gill steps to start, one compiled function with the loop inside.


@njit(inline="always", error_model="numpy")
def _floor_rhs(y, out, thrust, pos, kmat, cmat, minv, mass, cg, ia, e, rt):
    phi, theta, psi = y[3], y[4], y[5]
    cf, sf, ct, st, cp, sp = math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta), math.cos(psi), math.sin(psi)
    r00, r01, r02 = cp * ct, -sp * cf + cp * st * sf, sp * sf + cp * cf * st
    r10, r11, r12 = sp * ct, cp * cf + sp * st * sf, -cp * sf + sp * st * cf
    r20, r21, r22 = -st, ct * sf, ct * cf
    u, v, w, p, q, r = y[6], y[7], y[8], y[9], y[10], y[11]
    vh0, vh1, vh2 = r00 * u + r01 * v + r02 * w, r10 * u + r11 * v + r12 * w, r20 * u + r21 * v + r22 * w
    wh0, wh1, wh2 = r00 * p + r01 * q + r02 * r, r10 * p + r11 * q + r12 * r, r20 * p + r21 * q + r22 * r
    out[0], out[1], out[2] = vh0, vh1, vh2
    tt = st / ct
    out[3] = p + sf * tt * q + cf * tt * r
    out[4] = cf * q - sf * r
    out[5] = (sf * q + cf * r) / ct
    f0 = f1 = f2 = m0 = m1 = m2 = 0.0
    for i in range(pos.shape[0]):
        a0, a1, a2 = pos[i, 0], pos[i, 1], pos[i, 2]
        h0, h1, h2 = r00 * a0 + r01 * a1 + r02 * a2, r10 * a0 + r11 * a1 + r12 * a2, r20 * a0 + r21 * a1 + r22 * a2
        d0, d1, d2 = y[0] + h0 - a0, y[1] + h1 - a1, y[2] + h2 - a2
        s0 = vh0 + wh1 * h2 - wh2 * h1
        s1 = vh1 + wh2 * h0 - wh0 * h2
        s2 = vh2 + wh0 * h1 - wh1 * h0
        g0 = -(kmat[i, 0, 0] * d0 + kmat[i, 0, 1] * d1 + kmat[i, 0, 2] * d2 + cmat[i, 0, 0] * s0 + cmat[i, 0, 1] * s1 + cmat[i, 0, 2] * s2)
        g1 = -(kmat[i, 1, 0] * d0 + kmat[i, 1, 1] * d1 + kmat[i, 1, 2] * d2 + cmat[i, 1, 0] * s0 + cmat[i, 1, 1] * s1 + cmat[i, 1, 2] * s2)
        g2 = -(kmat[i, 2, 0] * d0 + kmat[i, 2, 1] * d1 + kmat[i, 2, 2] * d2 + cmat[i, 2, 0] * s0 + cmat[i, 2, 1] * s1 + cmat[i, 2, 2] * s2)
        f0 += g0
        f1 += g1
        f2 += g2
        m0 += h1 * g2 - h2 * g1
        m1 += h2 * g0 - h0 * g2
        m2 += h0 * g1 - h1 * g0
    re0, re1, re2 = r00 * e[0] + r01 * e[1] + r02 * e[2], r10 * e[0] + r11 * e[1] + r12 * e[2], r20 * e[0] + r21 * e[1] + r22 * e[2]
    t0, t1, t2 = thrust * re0, thrust * re1, thrust * re2
    q0, q1, q2 = r00 * rt[0] + r01 * rt[1] + r02 * rt[2], r10 * rt[0] + r11 * rt[1] + r12 * rt[2], r20 * rt[0] + r21 * rt[1] + r22 * rt[2]
    f0 += t0
    f1 += t1
    f2 += t2
    m0 += q1 * t2 - q2 * t1
    m1 += q2 * t0 - q0 * t2
    m2 += q0 * t1 - q1 * t0
    # to the body frame, Coriolis-centripetal terms in Newton-Euler form
    x0 = r00 * f0 + r10 * f1 + r20 * f2
    x1 = r01 * f0 + r11 * f1 + r21 * f2
    x2 = r02 * f0 + r12 * f1 + r22 * f2
    x3 = r00 * m0 + r10 * m1 + r20 * m2
    x4 = r01 * m0 + r11 * m1 + r21 * m2
    x5 = r02 * m0 + r12 * m1 + r22 * m2
    wv0, wv1, wv2 = q * w - r * v, r * u - p * w, p * v - q * u
    wg0, wg1, wg2 = q * cg[2] - r * cg[1], r * cg[0] - p * cg[2], p * cg[1] - q * cg[0]
    x0 -= mass * (wv0 + q * wg2 - r * wg1)
    x1 -= mass * (wv1 + r * wg0 - p * wg2)
    x2 -= mass * (wv2 + p * wg1 - q * wg0)
    i0 = ia[0, 0] * p + ia[0, 1] * q + ia[0, 2] * r
    i1 = ia[1, 0] * p + ia[1, 1] * q + ia[1, 2] * r
    i2 = ia[2, 0] * p + ia[2, 1] * q + ia[2, 2] * r
    x3 -= q * i2 - r * i1 + mass * (cg[1] * wv2 - cg[2] * wv1)
    x4 -= r * i0 - p * i2 + mass * (cg[2] * wv0 - cg[0] * wv2)
    x5 -= p * i1 - q * i0 + mass * (cg[0] * wv1 - cg[1] * wv0)
    for a in range(6):
        out[6 + a] = minv[a, 0] * x0 + minv[a, 1] * x1 + minv[a, 2] * x2 + minv[a, 3] * x3 + minv[a, 4] * x4 + minv[a, 5] * x5


@njit(error_model="numpy")
def floor_run(y0, h, n_steps, stride, thrust, pos, kmat, cmat, minv, mass, cg, ia, e, rt, out):
    """Hamming's method (three Gill steps to start) on the absolute state; samples every
    ``stride`` steps into ``out``; returns the number of right-hand side evaluations."""
    n = 12
    ys = np.zeros((4, n))  # y_n, y_n-1, y_n-2, y_n-3
    fs = np.zeros((3, n))  # f_n, f_n-1, f_n-2
    work = np.zeros((9, n))
    k1, k2, k3, k4, tmp, ynew, f, pmc, mod = work[0], work[1], work[2], work[3], work[4], work[5], work[6], work[7], work[8]
    for i in range(n):
        ys[0, i] = y0[i]
        out[0, i] = y0[i]
        tmp[i] = y0[i]
    _floor_rhs(tmp, f, thrust, pos, kmat, cmat, minv, mass, cg, ia, e, rt)
    for i in range(n):
        fs[0, i] = f[i]
    evals = 1
    for step in range(n_steps):
        if step < 3:  # Gill's RK4
            for i in range(n):
                k1[i] = h * fs[0, i]
                tmp[i] = ys[0, i] + 0.5 * k1[i]
            _floor_rhs(tmp, k2, thrust, pos, kmat, cmat, minv, mass, cg, ia, e, rt)
            for i in range(n):
                k2[i] = h * k2[i]
                tmp[i] = ys[0, i] + GILL[0] * k1[i] + GILL[1] * k2[i]
            _floor_rhs(tmp, k3, thrust, pos, kmat, cmat, minv, mass, cg, ia, e, rt)
            for i in range(n):
                k3[i] = h * k3[i]
                tmp[i] = ys[0, i] + GILL[2] * k2[i] + GILL[3] * k3[i]
            _floor_rhs(tmp, k4, thrust, pos, kmat, cmat, minv, mass, cg, ia, e, rt)
            evals += 3
            for i in range(n):
                ynew[i] = ys[0, i] + (k1[i] + GILL[4] * k2[i] + GILL[5] * k3[i] + h * k4[i]) / 6.0
                pmc[i] = 0.0
        else:  # Hamming: predictor, modifier, corrector, final value
            for i in range(n):
                p = ys[3, i] + (4.0 * h / 3.0) * (2.0 * fs[0, i] - fs[1, i] + 2.0 * fs[2, i])
                tmp[i] = p - 112.0 / 121.0 * pmc[i]
                pmc[i] = p
            _floor_rhs(tmp, mod, thrust, pos, kmat, cmat, minv, mass, cg, ia, e, rt)
            evals += 1
            for i in range(n):
                c = (9.0 * ys[0, i] - ys[2, i] + 3.0 * h * (mod[i] + 2.0 * fs[0, i] - fs[1, i])) / 8.0
                pmc[i] = pmc[i] - c
                ynew[i] = c + 9.0 / 121.0 * pmc[i]
        _floor_rhs(ynew, f, thrust, pos, kmat, cmat, minv, mass, cg, ia, e, rt)
        evals += 1
        for i in range(n):
            ys[3, i], ys[2, i], ys[1, i], ys[0, i] = ys[2, i], ys[1, i], ys[0, i], ynew[i]
            fs[2, i], fs[1, i], fs[0, i] = fs[1, i], fs[0, i], f[i]
        if (step + 1) % stride == 0:
            for i in range(n):
                out[(step + 1) // stride, i] = ys[0, i]
    return evals


def floor_kernel(model, res, h):
    """The floor on ``model``'s arrays: ``(run, check)``, ``run()`` timing one run of the floor over
    the same steps (s), ``check()`` the largest deviation of the last run's samples from impstab's
    ``res`` relative to the motion (the same equations, so rounding only) and its number of
    right-hand side evaluations."""
    body, th = model.body, model.thrust
    assert all(not m.has_rotational_stiffness and not m.is_nonlinear for m in model.mounts) and th.tangency == 1.0
    pos = np.array([m.position for m in model.mounts])
    kmat = np.ascontiguousarray([m.stiffness[:3, :3] for m in model.mounts])
    cmat = np.ascontiguousarray([m.damping[:3, :3] for m in model.mounts])
    args = (THRUST, pos, kmat, cmat, np.linalg.inv(model.mass_matrix), float(body.mass), np.asarray(body.cg, float),
            np.asarray(body.inertia_a, float), np.asarray(th.direction, float), np.asarray(th.point, float))
    y0 = res.equilibrium + res.deviation[0]
    out = np.zeros((STEPS // STRIDE + 1, 12))
    floor_run(y0, h, 10 * STRIDE, STRIDE, *args, out[:11])  # compile

    evals = [0]

    def run():
        t0 = time.perf_counter()
        evals[0] = floor_run(y0, h, STEPS, STRIDE, *args, out)
        return time.perf_counter() - t0

    def check():
        dev = out - res.equilibrium
        return float(np.abs(dev - res.deviation).max() / np.abs(res.deviation).max()), evals[0]

    return run, check


def per_evaluation(model, kw, ref, w, h):
    """Hamming at several step counts and DOP853 at several tolerances: (evals, error, seconds)."""
    import warnings as _w

    from impstab.dynamics.simulate import StepSizeWarning

    ham, dop = [], []
    for factor in (0.5, 1.0, 2.0, 4.0):
        with _w.catch_warnings():
            _w.simplefilter("ignore", StepSizeWarning)
            r = impstab.simulate(model, dt=h / factor, **kw)
        ham.append((r.rhs_evaluations, weighted_error(r.deviation, ref.deviation, w), round(r.wall_time, 4)))
    for rtol in (1e-4, 1e-6, 1e-8, 1e-10):
        r = impstab.simulate(model, integrator="dop853", rtol=rtol, **kw)
        dop.append((r.rhs_evaluations, weighted_error(r.deviation, ref.deviation, w), round(r.wall_time, 4)))
    return ham, dop


def evals_for_error(runs, target):
    """Evaluations needed for ``target`` error, log-log interpolated along ``runs``."""
    pts = sorted((math.log(e), math.log(n)) for n, e, _ in runs if e > 0)
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    if not xs[0] <= math.log(target) <= xs[-1]:
        return None
    return round(math.exp(float(np.interp(math.log(target), xs, ys))))


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
    floor, floor_check = floor_kernel(model, impstab.simulate(model, dt=h, **kw), h)
    # impstab and the floor in turns, so that both see the machine's speed of the moment (it
    # drifts by tens of percent on a shared machine): the ratio is the median over the pairs
    times, kernel, floors, ratios = [], [], [], []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        res = impstab.simulate(model, dt=h, **kw)
        times.append(time.perf_counter() - t0)
        kernel.append(res.wall_time)
        floors.append(floor())
        ratios.append(kernel[-1] / floors[-1])
    t_imp, t_kernel, t_floor = statistics.median(times), statistics.median(kernel), statistics.median(floors)
    same, floor_evals = floor_check()
    assert res.steps == STEPS and res.completed
    ref = impstab.simulate(model, integrator="dop853", rtol=1e-12, **kw)
    omega, length = res.fastest_omega, res.length_scale
    w = np.array([1, 1, 1, length, length, length] + [1 / omega] * 3 + [length / omega] * 3)
    err_imp = weighted_error(res.deviation, ref.deviation, w)
    ham, dop = per_evaluation(model, kw, ref, w, h)

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
            ("impstab hamming, compiled loop only", t_kernel, err_imp, f"{STEPS / t_kernel / 1e6:.2f} M steps/s"),
            ("floor: hand-written allocation-free kernel", t_floor, None,
             f"{floor_evals} f-evals, {STEPS / t_floor / 1e6:.2f} M steps/s, same samples to {same:.1e}"),
            (f"plain Python + solve_ivp {py_method} rtol {py_rtol:.0e}", t_py, err_py, f"{nfev} f-evals"),
            ("Exudyn RK44", t_mb, err_mb, f"{STEPS} steps" if t_mb else "exudyn not installed")]
    print(f"{model.name}: T = {THRUST:g} N, {STEPS} steps of {h:.4g} s = {duration:.4g} s simulated")
    print(f"plain-Python right-hand side equals the compiled one to {check:.1e}")
    print(f"{'run':48s} {'time (s)':>10s} {'error':>10s}  notes")
    for name, t, err, note in rows:
        ts = "-" if t is None else f"{t:.4f}"
        es = "-" if err is None else f"{err:.2e}"
        print(f"{name:48s} {ts:>10s} {es:>10s}  {note}")
    print("accuracy per right-hand-side evaluation (evaluations, weighted error, compiled-loop or solve_ivp seconds):")
    for name, runs in (("hamming at 1/2, 1, 2, 4 x the default step count", ham),
                       ("dop853 (solve_ivp) at rtol 1e-4, 1e-6, 1e-8, 1e-10", dop)):
        print(f"  {name}:")
        for n, e, t in runs:
            print(f"    {n:>9d} evals  error {e:.2e}  {t:.3f} s  ({1e9 * t / n:.0f} ns per evaluation)")
    dop_evals = evals_for_error(dop, err_imp)
    out = {
        "steps_per_s": round(STEPS / t_imp, 1),
        "speedup_vs_python_solve_ivp": round(t_py / t_imp, 2),
        "speedup_vs_multibody": None if t_mb is None else round(t_mb / t_imp, 2),
        "impstab_s": round(t_imp, 4), "kernel_s": round(t_kernel, 4), "error": err_imp,
        "python_solve_ivp_s": round(t_py, 3), "python_method": py_method, "python_rtol": py_rtol, "python_error": err_py,
        "multibody_s": None if t_mb is None else round(t_mb, 4), "multibody": "exudyn RK44" if t_mb else None,
        "multibody_error": err_mb,
        "floor_ratio": round(statistics.median(ratios), 3), "floor_ratios": [round(r, 3) for r in ratios],
        "speedup_vs_floor": round(1.0 / statistics.median(ratios), 3),
        "kernel_steps_per_s": round(STEPS / t_kernel, 1), "floor_s": round(t_floor, 4),
        "floor_steps_per_s": round(STEPS / t_floor, 1), "floor_same_samples": same,
        "hamming_runs": [list(r) for r in ham], "dop853_runs": [list(r) for r in dop],
        "dop853_evals_at_hamming_error": dop_evals,
        "hamming_evals_per_dop853_evals": None if dop_evals is None else round(res.rhs_evaluations / dop_evals, 3),
    }
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
