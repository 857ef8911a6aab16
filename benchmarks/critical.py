"""Critical thrust: impstab against a naive scan and against a competent vectorized method, same run.

References and baselines, each on the same matrices and timed in the same run:

* **naive scan** (the reference of the first benchmark, kept): scan the thrust from 0 to
  thrust_max in 1000 steps with ``scipy.linalg.eig`` of the 12 x 12 state matrix (K = K0 + T K1
  precomputed, so it pays for eigenvalues only), take the first step whose largest real part
  exceeds 1e-9 of the spectral radius, bisect that step to 1e-9 relative. ``"speedup"`` is its
  time over ``impstab.critical_thrust(model)`` end to end on the symmetric example.
* **vectorized method** (the baseline the goal is measured against): what a competent engineer
  writes with NumPy and SciPy: batched ``numpy.linalg.eigvals`` of the 6 x 6 ``M^-1 K(T)`` on the
  65-point grid in chunks of 17 and then 16 points (17 to 65 thrusts, stopping at the first
  unstable chunk), then ``scipy.optimize.brentq`` (rtol 4 eps) on the discriminant
  ``k sum s^2 - (sum s)^2`` of the merging cluster (its ranks among the real parts of ``s``), which
  crosses zero linearly and reaches the 1e-16 level: its accuracy is checked here against the
  planar closed form of THEORY 4. ``"speedup_vs_vectorized"`` is its time over
  ``impstab.critical_load(M, K0, K1, p_max=thrust_max)`` on the same matrices (the generic engine
  with its bubble detection, exact refinement, mode and participation), on the symmetric and the
  asymmetric example; ``"speedup_vs_vectorized_end_to_end"`` over ``impstab.critical_thrust(model)``,
  which also builds the linearization from the model file's data (about 50 us of set-up).
  The asymmetric example is taken with the classical linearization (K exactly affine in T, as
  the vectorized method needs); its default equilibrium linearization re-solves the rotated
  statics at every thrust.
* **massive beam mounts** (``examples/imp_beam_mounts.toml``: four Timoshenko beam mounts with mass,
  8 elements each, 174 dofs): ``impstab.critical_thrust(model)`` against a plain scan of the
  augmented first-order state matrix ``[[0, I], [-M^-1 K(T), 0]]`` (348 states) with batched
  ``numpy.linalg.eigvals`` on the 65-point grid (chunks of 17 and 16), the first point whose largest
  real part exceeds 1e-12 of the spectral radius, then bisection of that step to 1e-9 relative.
  ``"beam_speedup"``.
* **Beck's column** (160 Hermite elements, 320 dofs, the large generic system): impstab's
  ``critical_load`` against the dense method: ``scipy.linalg.eigvals(K(p), M)`` on the same
  65-point grid in chunks of 17 and 16, then ``brentq`` on ``(s_1 - s_2)^2`` of the two lowest
  ``s``. ``"beck_speedup"``.
* **viscoelastic mounts** (the symmetric ring with a two-term Prony law on each of its 3 mounts:
  the augmented first-order system of 12 + 3 x 2 x 3 = 30 states): the plain method on the same
  affine augmented matrices ``E^-1 A0``, ``E^-1 A1``: batched ``numpy.linalg.eigvals`` on the
  65-point grid, then bisection of the first unstable interval on ``max Re lambda > 0`` to 1e-9
  relative. ``"viscoelastic_speedup"`` is its time over ``impstab.critical_thrust(model)`` end to
  end (which also builds the augmented matrices from the model and finds the undamped companion; the
  Newton check on the exact law runs only for fitted laws, and this one is a Prony series);
  ``"viscoelastic_speedup_engine"`` over the engine alone on the matrices critical_thrust hands it
  (the internal variables no motion reaches dropped: 24 states, in the body's dof coordinates, so
  that the engine sees the planes' blocks of 4, 8, 8 and 4 states).

* **damped massive beam mounts** (the same with dashpots ``c_axial = 40``, ``c_shear = 8`` N s/m at
  every mount: a first-order problem of 348 states): ``impstab.critical_thrust(model)`` (which also
  finds the undamped companion) against the plain first-order scan above on the same affine
  matrices, unstable where the largest real part exceeds 1e-12 of the spectral radius.
  ``"damped_beam_speedup"``.

``--only PART`` (repeatable: ``examples``, ``beam``, ``damped_beam``, ``beck``, ``viscoelastic``) runs only those
parts; the JSON line then has their keys only.

Timings are the best of interleaved rounds of CPU time (the timeit convention: the other
rounds were slowed by something else; on a shared machine wall time varies by 2x from second
to second). Also printed: eigenproblems and Python calls per solve. Ends with one JSON line.
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
import scipy.linalg as sla
from scipy.optimize import brentq

import impstab
from impstab._jit import require_compiled

require_compiled()  # the kernels are what is timed here (a lone call in a fresh process runs them interpreted)
from impstab.linear.linearize import ModelFamily

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SYMMETRIC, ASYMMETRIC = EXAMPLES / "imp_symmetric.toml", EXAMPLES / "imp_asymmetric.toml"
TOL_COMPLEX = 1e-7  # |Im s| / |s| above which the vectorized method calls a point unstable


def closed_form(model) -> float:
    """Planar closed form of THEORY 4 (symmetric ring, mount preload term)."""
    ring_x = float(model.mounts[0].position[0])
    radius = float(np.hypot(*model.mounts[0].position[1:]))
    k = model.mounts[0].stiffness[:3, :3]
    k_ax, k_sh = float(k[0, 0]), float(k[1, 1])
    m, inertia = model.body.mass, float(model.body.inertia_cg[2, 2])
    k_y, k_yt = 3 * k_sh, 3 * k_sh * ring_x
    c0 = 3 * k_sh * ring_x**2 + 1.5 * k_ax * radius**2
    p = k_y * inertia + m * c0
    return (p - 2 * math.sqrt(m * inertia * (k_y * c0 - k_yt**2))) / (m * ring_x)


def naive_scan(m: np.ndarray, k0: np.ndarray, k1: np.ndarray, t_max: float) -> float:
    n = m.shape[0]
    minv = np.linalg.inv(m)

    def unstable(t: float) -> bool:
        a = np.zeros((2 * n, 2 * n))
        a[:n, n:] = np.eye(n)
        a[n:, :n] = -minv @ (k0 + t * k1)
        lam = sla.eig(a, right=False)
        return lam.real.max() > 1e-9 * np.abs(lam).max()

    grid = np.linspace(0.0, t_max, 1001)
    flags = [unstable(t) for t in grid]
    first = flags.index(True)
    lo, hi = grid[first - 1], grid[first]
    while hi - lo > 1e-9 * hi:
        mid = 0.5 * (lo + hi)
        if unstable(mid):
            hi = mid
        else:
            lo = mid
    return hi


def _first_unstable(values_of, grid) -> int | None:
    """Index of the first unstable grid point, classifying chunks of 17 then 16 points."""
    start = 0
    while start < len(grid):
        stop = min(start + (17 if start == 0 else 16), len(grid))
        s = values_of(grid[start:stop])
        bad = (np.abs(s.imag) > TOL_COMPLEX * np.abs(s)).any(axis=1) | (s.real < 0).any(axis=1)
        if bad.any():
            return start + int(np.argmax(bad))
        start = stop
    return None


def _cluster_discriminant(values_at, ranks):
    def disc(t: float) -> float:
        s = values_at(t)
        c = s[np.argsort(s.real)][ranks]
        return float((len(c) * (c * c).sum() - c.sum() ** 2).real)

    return disc


def vectorized_method(m: np.ndarray, k0: np.ndarray, k1: np.ndarray, t_max: float) -> float | None:
    """Batched eigvals of M^-1 K on the grid, then brentq on the merging cluster's discriminant."""
    a0, a1 = np.linalg.solve(m, k0), np.linalg.solve(m, k1)
    grid = np.linspace(0.0, t_max, 65)
    j = _first_unstable(lambda t: np.linalg.eigvals(a0[None] + t[:, None, None] * a1[None]), grid)
    if j is None:
        return None
    s = np.linalg.eigvals(a0 + grid[j] * a1)
    cplx = np.abs(s.imag) > TOL_COMPLEX * np.abs(s)
    ref = s[cplx][np.argmin(s[cplx].real)]
    ranks = np.flatnonzero((np.abs(s.real - ref.real) <= 1e-6 * abs(ref))[np.argsort(s.real)])
    disc = _cluster_discriminant(lambda t: np.linalg.eigvals(a0 + t * a1), ranks)
    return brentq(disc, grid[j - 1], grid[j], xtol=1e-300, rtol=4 * np.finfo(float).eps)


def dense_method(m: np.ndarray, k0: np.ndarray, k1: np.ndarray, p_max: float) -> float | None:
    """Dense generalized eigenvalues on the grid, then brentq on (s_1 - s_2)^2 of the two lowest s."""
    grid = np.linspace(0.0, p_max, 65)
    j = _first_unstable(lambda t: np.array([sla.eigvals(k0 + p * k1, m) for p in t]), grid)
    if j is None:
        return None
    disc = _cluster_discriminant(lambda t: sla.eigvals(k0 + t * k1, m), np.arange(2))
    return brentq(disc, grid[j - 1], grid[j], xtol=1e-300, rtol=4 * np.finfo(float).eps)


VISCOELASTIC = """schema_version = 1
name = "three mounts, two Prony terms"
[body]
mass = 100.0
inertia = [1.0, 6.0, 6.0]
[[mount_rings]]
count = 3
radius = 0.15
x = 0.3
start_angle = 90.0
k_axial = 1.0e5
k_shear = 2.0e4
[mount_rings.viscoelastic]
law = "prony"
terms = [[0.3, 1.0e-3], [0.5, 2.0e-2]]
[thrust]
operating = 2000.0
[analysis]
thrust_max = 30000.0
"""


def plain_scan_first_order(a0: np.ndarray, a1: np.ndarray, t_max: float, relative: float = 0.0) -> float | None:
    """Batched eigvals of A0 + T A1 on 65 points, then bisection on max Re > 0 to 1e-9 relative
    (``relative``: unstable above that share of the spectral radius, for spectra whose undamped
    modes carry rounding)."""
    grid = np.linspace(0.0, t_max, 65)

    def unstable(lam):
        return lam.real.max(axis=-1) > relative * np.abs(lam).max(axis=-1)

    bad = np.flatnonzero(unstable(np.linalg.eigvals(a0[None] + grid[:, None, None] * a1[None])))
    if not bad.size:
        return None
    lo, hi = grid[bad[0] - 1], grid[bad[0]]
    while hi - lo > 1e-9 * hi:
        mid = 0.5 * (lo + hi)
        if unstable(np.linalg.eigvals(a0 + mid * a1)):
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def viscoelastic_benchmark(line: dict) -> None:
    from impstab.linear.viscoelastic import ViscoelasticFamily
    from impstab.model import model_from_dict
    import tomllib

    model = model_from_dict(tomllib.loads(VISCOELASTIC))
    fam = ViscoelasticFamily(model)
    e, a0, a1 = fam.affine_parts()
    a0, a1 = np.linalg.solve(e, a0), np.linalg.solve(e, a1)
    small = ViscoelasticFamily(model, reduced=True)  # what critical_thrust hands the engine
    er, r0, r1 = small.affine_parts()
    r0, r1 = np.linalg.solve(er, r0), np.linalg.solve(er, r1)
    t_max = float(model.analysis.thrust_max)
    whole = impstab.critical_thrust(model)
    engine = impstab.critical_load(A0=r0, A1=r1, p_max=t_max)
    plain = plain_scan_first_order(a0, a1, t_max)
    t_plain, t_engine, t_whole = best_times(
        [lambda: plain_scan_first_order(a0, a1, t_max), lambda: impstab.critical_load(A0=r0, A1=r1, p_max=t_max),
         lambda: impstab.critical_thrust(model)], rounds=10, per_round=[3, 10, 5])
    print(f"viscoelastic mounts, 3 mounts x 2 Prony terms ({fam.n} states; {small.n} reached by the motion)")
    print(f"  impstab critical_thrust T_c = {whole.thrust:.12f} N  {t_whole * 1e3:8.2f} ms (model -> result, "
          f"augmented matrices and undamped companion included)")
    print(f"  impstab critical_load  T_c = {engine.load:.12f} N  {t_engine * 1e3:8.2f} ms  "
          f"{engine.evaluations} eigenproblems")
    print(f"  plain eigvals scan     T_c = {plain:.12f} N  {t_plain * 1e3:8.2f} ms  "
          f"(differs from impstab by {abs(plain - whole.thrust) / whole.thrust:.1e})")
    print(f"  speedup                {t_plain / t_whole:.1f}x end to end, {t_plain / t_engine:.1f}x engine")
    line.update(viscoelastic_speedup=t_plain / t_whole, viscoelastic_speedup_engine=t_plain / t_engine,
                viscoelastic_critical_thrust=whole.thrust, viscoelastic_plain=plain)


BEAMS = EXAMPLES / "imp_beam_mounts.toml"


def beam_scan(m: np.ndarray, k0: np.ndarray, k1: np.ndarray, t_max: float) -> float | None:
    """Plain scan of the augmented state matrix with numpy.linalg.eigvals, bisection to 1e-9."""
    n = m.shape[0]
    a0, a1 = np.linalg.solve(m, k0), np.linalg.solve(m, k1)

    def states(t):
        t = np.atleast_1d(t)
        a = np.zeros((t.size, 2 * n, 2 * n))
        a[:, :n, n:] = np.eye(n)
        a[:, n:, :n] = -(a0[None] + t[:, None, None] * a1[None])
        return a

    def unstable(t) -> np.ndarray:
        lam = np.linalg.eigvals(states(t))
        return lam.real.max(axis=1) > 1e-12 * np.abs(lam).max(axis=1)

    grid = np.linspace(0.0, t_max, 65)
    start, first = 0, None
    while start < len(grid) and first is None:
        stop = min(start + (17 if start == 0 else 16), len(grid))
        bad = unstable(grid[start:stop])
        if bad.any():
            first = start + int(np.argmax(bad))
        start = stop
    if first is None:
        return None
    lo, hi = grid[first - 1], grid[first]
    while hi - lo > 1e-9 * hi:
        mid = 0.5 * (lo + hi)
        if unstable(mid)[0]:
            hi = mid
        else:
            lo = mid
    return hi


def best_times(functions, rounds: int, per_round: list[int]) -> list[float]:
    """Best CPU time per call of each function over interleaved rounds (seconds)."""
    best = [np.inf] * len(functions)
    for f in functions:
        f()
    for _ in range(rounds):
        for i, (f, n) in enumerate(zip(functions, per_round)):
            t0 = time.process_time()
            for _ in range(n):
                f()
            best[i] = min(best[i], (time.process_time() - t0) / n)
    return best


def python_calls(fn) -> int:
    """Python-level and C-level function calls made by one call of ``fn``."""
    calls = [0]

    def prof(frame, event, arg):
        if event in ("call", "c_call"):
            calls[0] += 1

    sys.setprofile(prof)
    try:
        fn()
    finally:
        sys.setprofile(None)
    return calls[0]


def beck_matrices(n_el: int):
    """Clamped-free Hermite Beck column (L = EI = m = 1): M, K0, K1 (tests/linear/test_beck_column.py)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "linear"))
    from test_beck_column import beck_matrices as build

    return build(n_el)


PARTS = ("examples", "beam", "damped_beam", "beck", "viscoelastic")


def main(argv: list[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", action="append", choices=PARTS,
                        help="run only this part (repeatable); the JSON line then has its keys only")
    parts = set(parser.parse_args(argv).only or PARTS)
    line: dict = {}
    if "examples" in parts:
        examples_benchmark(line)
    if "beam" in parts:
        beam_benchmark(line)
    if "damped_beam" in parts:
        damped_beam_benchmark(line)
    if "beck" in parts:
        beck_benchmark(line)
    if "viscoelastic" in parts:
        viscoelastic_benchmark(line)
    print(json.dumps(line))
    return 0


def examples_benchmark(line: dict) -> None:
    by_example: dict = {}
    end_to_end: dict = {}
    for path, linearization in ((SYMMETRIC, None), (ASYMMETRIC, "classical")):
        model = impstab.load_model(path)
        m, _, _, k0, k1 = ModelFamily(model, linearization).affine_parts()
        t_max = float(model.analysis.thrust_max)
        res = impstab.critical_load(m, k0, k1, p_max=t_max)
        whole = impstab.critical_thrust(model, linearization=linearization)
        base = vectorized_method(m, k0, k1, t_max)
        t_base, t_engine, t_whole = best_times(
            [lambda: vectorized_method(m, k0, k1, t_max), lambda: impstab.critical_load(m, k0, k1, p_max=t_max),
             lambda: impstab.critical_thrust(model, linearization=linearization)], rounds=30, per_round=[20, 40, 20])
        calls = python_calls(lambda: impstab.critical_load(m, k0, k1, p_max=t_max))
        name = path.name
        by_example[name], end_to_end[name] = t_base / t_engine, t_base / t_whole
        print(f"{name} ({linearization or model.analysis.linearization})")
        print(f"  impstab critical_load  T_c = {res.load:.12f} N  {t_engine * 1e6:7.1f} us  "
              f"{res.evaluations} eigenproblems, {calls} Python calls")
        print(f"  impstab critical_thrust T_c = {whole.thrust:.12f} N  {t_whole * 1e6:7.1f} us (model -> result)")
        print(f"  vectorized method      T_c = {base:.12f} N  {t_base * 1e6:7.1f} us  "
              f"(differs from impstab by {abs(base - res.load) / res.load:.1e})")
        print(f"  speedup vs vectorized  {t_base / t_engine:.2f}x  (end to end {t_base / t_whole:.2f}x)")
        if path == SYMMETRIC:
            exact = closed_form(model)
            line.update(rel_err=abs(res.load - exact) / exact, critical_thrust=res.load, closed_form=exact,
                        vectorized_rel_err=abs(base - exact) / exact, evaluations=res.evaluations, python_calls=calls)
            print(f"  closed form            T_c = {exact:.12f} N  impstab rel_err {line['rel_err']:.1e}, "
                  f"vectorized {line['vectorized_rel_err']:.1e}")
            lin0 = impstab.linearize(model, 0.0, "classical")
            k1_fd = (impstab.linearize(model, 1e6, "classical").K - lin0.K) / 1e6
            naive_scan(lin0.M, lin0.K, k1_fd, t_max)
            t_naive, t_imp = best_times([lambda: naive_scan(lin0.M, lin0.K, k1_fd, t_max),
                                         lambda: impstab.critical_thrust(model)], rounds=5, per_round=[1, 100])
            naive = naive_scan(lin0.M, lin0.K, k1_fd, t_max)
            line.update(speedup=t_naive / t_imp, impstab_ms=t_imp * 1e3, baseline_ms=t_naive * 1e3,
                        baseline_rel_err=abs(naive - exact) / exact)
            print(f"  naive 1000-step scan   T_c = {naive:.12f} N  {t_naive * 1e3:7.2f} ms: "
                  f"{t_naive / t_imp:.1f}x impstab end to end")
    line["speedup_vs_vectorized"] = by_example
    line["speedup_vs_vectorized_end_to_end"] = end_to_end


def beam_benchmark(line: dict) -> None:
    # massive beam mounts: the grown system (body + internal finite-element dofs)
    beams = impstab.load_model(BEAMS)
    mbm, _, _, k0m, k1m = ModelFamily(beams).affine_parts()
    t_max_b = float(beams.analysis.thrust_max)
    crit_b = impstab.critical_thrust(beams)
    (t_crit_b,) = best_times([lambda: impstab.critical_thrust(beams)], rounds=3, per_round=[1])
    t0 = time.process_time()  # the scan takes minutes: timed once
    scan_b = beam_scan(mbm, k0m, k1m, t_max_b)
    t_scan_b = time.process_time() - t0
    print(f"{BEAMS.name} ({mbm.shape[0]} dofs, {2 * mbm.shape[0]} states)")
    print(f"  impstab critical_thrust T_c = {crit_b.thrust:.12f} N  {t_crit_b * 1e3:8.1f} ms  ({crit_b.method})")
    print(f"  eigvals scan + bisection T_c = {scan_b:.12f} N  {t_scan_b * 1e3:8.1f} ms  "
          f"(differs by {abs(scan_b - crit_b.thrust) / crit_b.thrust:.1e})")
    print(f"  speedup                {t_scan_b / t_crit_b:.1f}x")
    line.update(beam_speedup=t_scan_b / t_crit_b, beam_critical_thrust=crit_b.thrust, beam_scan=scan_b,
                beam_dofs=int(mbm.shape[0]))


def damped_beam_benchmark(line: dict) -> None:
    # the same with dashpots at every mount: a first-order problem of 348 states
    import tomllib

    from impstab.linear.eigen import state_matrices
    from impstab.model import model_from_dict

    d = tomllib.loads(BEAMS.read_text(encoding="utf-8"))
    for mount in d["mounts"]:
        mount["c_axial"], mount["c_shear"] = 40.0, 8.0
    damped = model_from_dict(d)
    m, dd, g, k0, k1 = ModelFamily(damped, damped=True).affine_parts()
    n = m.shape[0]
    a0 = state_matrices(m, dd + g, k0)
    a1 = np.zeros_like(a0)
    a1[n:, :n] = -np.linalg.solve(m, k1)
    t_max = float(damped.analysis.thrust_max)
    crit = impstab.critical_thrust(damped)
    (t_crit,) = best_times([lambda: impstab.critical_thrust(damped)], rounds=3, per_round=[1])
    t0 = time.process_time()  # seconds: timed once
    scan = plain_scan_first_order(a0, a1, t_max, relative=1e-12)
    t_scan = time.process_time() - t0
    print(f"{BEAMS.name} with dashpots c_axial 40, c_shear 8 N s/m ({n} dofs, {2 * n} states)")
    print(f"  impstab critical_thrust T_c = {crit.thrust:.12f} N  {t_crit * 1e3:8.1f} ms  ({crit.method}; with the "
          "undamped companion)")
    print(f"  eigvals scan + bisection T_c = {scan:.12f} N  {t_scan * 1e3:8.1f} ms  "
          f"(differs by {abs(scan - crit.thrust) / crit.thrust:.1e})")
    print(f"  speedup                {t_scan / t_crit:.1f}x")
    line.update(damped_beam_speedup=t_scan / t_crit, damped_beam_critical_thrust=crit.thrust, damped_beam_scan=scan)


def beck_benchmark(line: dict) -> None:
    # a large generic system: Beck's column with 160 elements
    mb, k0b, k1b = beck_matrices(160)
    beck = impstab.critical_load(mb, k0b, k1b, p_max=22.0)
    dense = dense_method(mb, k0b, k1b, 22.0)
    t_dense, t_beck = best_times([lambda: dense_method(mb, k0b, k1b, 22.0),
                                  lambda: impstab.critical_load(mb, k0b, k1b, p_max=22.0)], rounds=3, per_round=[1, 1])
    print(f"Beck's column, 160 elements ({mb.shape[0]} dofs)")
    print(f"  impstab critical_load  p_c = {beck.load:.12f}  {t_beck * 1e3:8.1f} ms  ({beck.method})")
    print(f"  dense method           p_c = {dense:.12f}  {t_dense * 1e3:8.1f} ms  "
          f"(differs by {abs(dense - beck.load) / beck.load:.1e})")
    print(f"  speedup                {t_dense / t_beck:.1f}x")
    line.update(beck_speedup=t_dense / t_beck, beck_critical_load=beck.load, beck_dense=dense)


if __name__ == "__main__":
    sys.exit(main())
