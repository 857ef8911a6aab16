"""Forced response: 1e4 frequencies of ``impstab.response.frequency_response`` against loops.

Model: the asymmetric four-mount layout of ``examples/imp_asymmetric.toml`` (tilted axes, a cg and
a thrust line off the axis) with dampers on every mount and a spinning propeller (sqrt-thrust
speed law), at the operating thrust with the equilibrium linearization; a unit sway force.
Frequencies: 1e4 from 0.1 to 200 Hz.

Timed (best of repeats, ``time.perf_counter``, warm: the compiled kernels loaded first):

* ``impstab``: the whole call ``frequency_response(model, f)`` -- linearization, the stacked
  solve, the mount forces, hull force, transmissibility, mount deflections and powers, the modes
  at that thrust for the plot markers, the result object;
* ``loop``: the competent baseline, the same linearization once and then a Python loop with one
  ``numpy.linalg.solve`` per frequency computing the same outputs (response, each mount's force
  on the hull from precomputed ``(k_i B_i)_t`` and ``(c_i B_i)_t``, hull force, transmissibility,
  mount deflections ``B_i q``, input and damper powers);
* ``minimal_loop``: the same loop computing only the response and the transmissibility;
* ``stacked_numpy``: the vectorized NumPy route, one ``numpy.linalg.solve`` on the stack of all
  dynamic stiffness matrices, then the same outputs with ``einsum``.

A second part times the compressible-fluid case (added mass and radiation damping at every
frequency) on 1e3 frequencies against a loop that evaluates the baffled-cylinder coefficients at
each frequency (``FluidLoading.coefficients_at``) before its solve.

``max_rel_diff`` is the largest difference of the response and of the hull force from the loop,
relative to their largest magnitudes. Ends with one JSON line.
"""

from __future__ import annotations

from impstab._blas import prefer_single_thread

prefer_single_thread()  # before numpy loads: impstab and the baseline with one BLAS thread, as the CLI runs

import json
import time
import tomllib
from pathlib import Path

import numpy as np

import impstab
from impstab.model import model_from_dict
from impstab.response import attachment_maps, frequency_response

ROOT = Path(__file__).resolve().parents[1]
N_FREQ = 10_000
N_FLUID = 1_000
REPEATS = 5


def bench_model(fluid: bool = False):
    d = tomllib.loads((ROOT / "examples" / "imp_asymmetric.toml").read_text())
    for m in d["mounts"]:
        m.update(c_axial=60.0, c_shear=15.0)
    d["propeller"] = {"polar_inertia": 0.05, "speed": 300.0, "speed_law": "sqrt-thrust"}
    if fluid:
        d["hull"] = {"radius": 0.15, "length": 0.8, "center": [0.05, 0.0, 0.0]}
        d["fluid"] = {"model": "baffled-cylinder", "density": 1025.0, "sound_speed": 1500.0}
    return model_from_dict(d)


def best(fn, repeats: int = REPEATS) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def mount_maps(model, lin):
    b = attachment_maps(np.array([[m.position for m in model.mounts]]), lin.rotation[None])[0]
    hk = np.concatenate([(m.stiffness @ bi)[:3] for m, bi in zip(model.mounts, b)])   # (3 nm, 6)
    hc = np.concatenate([(m.damping @ bi)[:3] for m, bi in zip(model.mounts, b)])
    bb = np.concatenate(list(b))                                                      # (6 nm, 6)
    dm = np.array([bi.T @ m.damping @ bi for m, bi in zip(model.mounts, b)])          # (nm, 6, 6)
    return hk, hc, bb, dm


def loop(model, f, thrust, fluid=False, minimal=False):
    """One numpy.linalg.solve per frequency, the outputs formed per frequency."""
    lin = impstab.linearize(model, thrust)
    hk, hc, bb, dm = mount_maps(model, lin)
    nm = len(model.mounts)
    load = np.zeros(6)
    load[1] = 1.0
    c = lin.D + lin.G
    big = np.zeros((6, 6))
    big[:3, :3] = big[3:, 3:] = lin.rotation
    m0 = big @ model.fluid.added_mass @ big.T
    q_all = np.empty((f.size, 6), complex)
    hull_all = np.empty((f.size, 3), complex)
    trans = np.empty(f.size)
    for n, fn in enumerate(f):
        w = 2 * np.pi * fn
        if fluid:
            added, radiation = model.fluid.coefficients_at(fn)
            z = lin.K + 1j * w * (c + big @ radiation @ big.T) - w * w * (lin.M - m0 + big @ added @ big.T)
        else:
            z = lin.K + 1j * w * c - w * w * lin.M
        q = np.linalg.solve(z, load)
        q_all[n] = q
        if minimal:
            hull = (hk @ q + 1j * w * (hc @ q)).reshape(nm, 3).sum(axis=0)
            trans[n] = np.linalg.norm(hull)
            continue
        forces = (hk @ q + 1j * w * (hc @ q)).reshape(nm, 3)
        hull = forces.sum(axis=0)
        hull_all[n] = hull
        trans[n] = np.linalg.norm(hull)
        _deflection = (bb @ q).reshape(nm, 6)
        _p_in = 0.5 * w * np.vdot(q, load).imag
        _p_damp = 0.5 * w * w * np.einsum("i,mij,j->m", q.conj(), dm, q).real
    return q_all, hull_all, trans


def stacked_numpy(model, f, thrust):
    lin = impstab.linearize(model, thrust)
    hk, hc, bb, dm = mount_maps(model, lin)
    nm = len(model.mounts)
    w = 2 * np.pi * f
    load = np.zeros((f.size, 6, 1), complex)
    load[:, 1] = 1.0
    z = lin.K[None] + 1j * w[:, None, None] * (lin.D + lin.G)[None] - (w**2)[:, None, None] * lin.M[None]
    q = np.linalg.solve(z, load)[..., 0]
    forces = (q @ hk.T + 1j * w[:, None] * (q @ hc.T)).reshape(f.size, nm, 3)
    hull = forces.sum(axis=1)
    trans = np.linalg.norm(hull, axis=1)
    _deflection = (q @ bb.T).reshape(f.size, nm, 6)
    _p_in = 0.5 * w * (q.conj() * load[..., 0]).sum(axis=1).imag
    _p_damp = 0.5 * w[:, None] ** 2 * np.einsum("fi,mij,fj->fm", q.conj(), dm, q).real
    return q, hull, trans


def main() -> int:
    model = bench_model()
    thrust = float(model.thrust.operating)
    f = np.linspace(0.1, 200.0, N_FREQ)
    frequency_response(model, f[:3])                                      # load the compiled kernels
    t_imp, res = best(lambda: frequency_response(model, f))
    t_loop, (q_ref, hull_ref, _) = best(lambda: loop(model, f, thrust), 3)
    t_min, _ = best(lambda: loop(model, f, thrust, minimal=True), 3)
    t_stack, (q_st, hull_st, _) = best(lambda: stacked_numpy(model, f, thrust), 3)
    diff = max(np.abs(res.response - q_ref).max() / np.abs(q_ref).max(),
               np.abs(res.hull_force - hull_ref).max() / np.abs(hull_ref).max())
    diff_stack = max(np.abs(q_st - q_ref).max() / np.abs(q_ref).max(), np.abs(hull_st - hull_ref).max() / np.abs(hull_ref).max())

    wet = bench_model(fluid=True)
    fw = np.linspace(0.1, 2000.0, N_FLUID)
    frequency_response(wet, fw[:3])
    t_wet, res_w = best(lambda: frequency_response(wet, fw), 3)
    t_wet_loop, (qw_ref, hw_ref, _) = best(lambda: loop(wet, fw, thrust, fluid=True), 1)
    diff_wet = max(np.abs(res_w.response - qw_ref).max() / np.abs(qw_ref).max(),
                   np.abs(res_w.hull_force - hw_ref).max() / np.abs(hw_ref).max())

    print(f"forced response, {N_FREQ} frequencies, asymmetric damped gyroscopic model, unit sway force")
    print(f"  impstab frequency_response (whole call)  {1e3 * t_imp:9.2f} ms")
    print(f"  loop of numpy.linalg.solve, same outputs {1e3 * t_loop:9.2f} ms   {t_loop / t_imp:6.1f} x")
    print(f"  loop, response and transmissibility only {1e3 * t_min:9.2f} ms   {t_min / t_imp:6.1f} x")
    print(f"  stacked numpy.linalg.solve + einsum      {1e3 * t_stack:9.2f} ms   {t_stack / t_imp:6.1f} x")
    print(f"  max relative difference from the loop    {diff:.2e} (stacked numpy {diff_stack:.2e})")
    print(f"compressible fluid at every frequency, {N_FLUID} frequencies to 2 kHz "
          f"({res_w.settings['fluid']})")
    print(f"  impstab {1e3 * t_wet:9.2f} ms, loop with coefficients at each frequency {1e3 * t_wet_loop:9.2f} ms "
          f"({t_wet_loop / t_wet:.1f} x), max relative difference {diff_wet:.2e}")
    out = {
        "frequencies": N_FREQ,
        "impstab_s": t_imp,
        "loop_s": t_loop,
        "speedup_vs_loop": t_loop / t_imp,
        "minimal_loop_s": t_min,
        "speedup_vs_minimal_loop": t_min / t_imp,
        "stacked_numpy_s": t_stack,
        "speedup_vs_stacked_numpy": t_stack / t_imp,
        "max_rel_diff": diff,
        "fluid_frequencies": N_FLUID,
        "fluid_speedup_vs_loop": t_wet_loop / t_wet,
        "fluid_max_rel_diff": diff_wet,
    }
    out.update(pareto_benchmark())
    print(json.dumps(out))
    return 0


def pareto_benchmark() -> dict:
    """A 2-variable Pareto front: ``impstab optimize examples/optimize_isolation.toml`` in memory
    (24 designs x 12 generations, each generation one batched study chunk, then the polish and the
    stored Pareto set), wall time; and one generation evaluated batched against the same designs
    evaluated one call each (the same code, a chunk of one)."""
    from impstab.optimize.problem import load_optimization
    from impstab.optimize.run import evaluate_designs, run_optimization

    opt = load_optimization(Path(__file__).resolve().parents[1] / "examples" / "optimize_isolation.toml")
    rng = np.random.default_rng(0)
    lo = np.array([v.low for v in opt.variables])
    hi = np.array([v.high for v in opt.variables])
    x = lo + rng.random((opt.population, len(lo))) * (hi - lo)
    evaluate_designs(opt, x[:2])                                          # load the compiled kernels
    t_gen, _ = best(lambda: evaluate_designs(opt, x), 3)
    t_gen_loop, _ = best(lambda: [evaluate_designs(opt, row[None]) for row in x], 3)
    t0 = time.perf_counter()
    res = run_optimization(opt)
    t_pareto = time.perf_counter() - t0
    c = res.chosen
    print(f"2-variable Pareto front, {opt.population} designs x {opt.generations} generations + polish "
          f"({len(res.history.x)} evaluations)")
    print(f"  impstab optimize (search, polish, stored set)  {t_pareto:7.2f} s; chosen "
          f"{opt.objective} = {c['isolation']:.5g} at margin {c['margin']:.4g}")
    print(f"  one generation batched {1e3 * t_gen:8.1f} ms, one design per call {1e3 * t_gen_loop:8.1f} ms "
          f"({t_gen_loop / t_gen:.2f} x)")
    return {"pareto_s": t_pareto, "pareto_evaluations": int(len(res.history.x)),
            "generation_batched_s": t_gen, "generation_loop_s": t_gen_loop,
            "generation_speedup_vs_loop": t_gen_loop / t_gen}


if __name__ == "__main__":
    raise SystemExit(main())
