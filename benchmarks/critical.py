"""Critical thrust of the symmetric example: impstab against the plain method, same run.

Baseline (the plain method): scan the thrust from 0 to thrust_max in 1000 steps with
``scipy.linalg.eig`` of the 12 x 12 state matrix (K = K0 + T K1 precomputed, so the baseline pays
for eigenvalues only), take the first step whose largest real part exceeds 1e-9 of the spectral
radius, then bisect that step to 1e-9 relative.

impstab: ``impstab.critical_thrust(model)`` end to end (linearization set-up, batched scan,
exact refinement, the result object), nothing cached between repeats.

Reference: the planar closed form of THEORY 4 (with the mount preload term), which for the
symmetric ring reduces to ``T_c = (P - 2 sqrt(m I (k_y c0 - k_yt^2))) / (m x_m)`` with
``P = k_y I + m c0`` and ``c0 = 3 k_sh x_m^2 + 1.5 k_ax R^2``.

Prints a table of medians and ends with one JSON line.
"""

from __future__ import annotations

import json
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import scipy.linalg as sla

import impstab

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "imp_symmetric.toml"


def closed_form(model) -> float:
    ring_x = float(model.mounts[0].position[0])
    radius = float(np.hypot(*model.mounts[0].position[1:]))
    k = model.mounts[0].stiffness[:3, :3]
    k_ax, k_sh = float(k[0, 0]), float(k[1, 1])
    m, inertia = model.body.mass, float(model.body.inertia_cg[2, 2])
    k_y, k_yt = 3 * k_sh, 3 * k_sh * ring_x
    c0 = 3 * k_sh * ring_x**2 + 1.5 * k_ax * radius**2
    p = k_y * inertia + m * c0
    return (p - 2 * math.sqrt(m * inertia * (k_y * c0 - k_yt**2))) / (m * ring_x)


def plain_method(m: np.ndarray, k0: np.ndarray, k1: np.ndarray, t_max: float) -> float:
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


def median_time(fn, repeats: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def main() -> int:
    model = impstab.load_model(EXAMPLE)
    exact = closed_form(model)
    impstab.critical_thrust(model)  # compile and warm up (numba caches to disk)
    t_imp, res = median_time(lambda: impstab.critical_thrust(model), 200)
    lin0 = impstab.linearize(model, 0.0, "classical")
    big = 1e6
    k1 = (impstab.linearize(model, big, "classical").K - lin0.K) / big
    t_max = model.analysis.thrust_max
    plain_method(lin0.M, lin0.K, k1, t_max)
    t_base, base = median_time(lambda: plain_method(lin0.M, lin0.K, k1, t_max), 7)
    rel_err = abs(res.thrust - exact) / exact
    base_err = abs(base - exact) / exact
    print(f"model            {model.name} ({EXAMPLE.name})")
    print(f"closed form      T_c = {exact:.12f} N")
    print(f"impstab          T_c = {res.thrust:.12f} N  rel_err {rel_err:.2e}  median {t_imp * 1e3:.3f} ms")
    print(f"plain method     T_c = {base:.12f} N  rel_err {base_err:.2e}  median {t_base * 1e3:.3f} ms")
    print(f"speedup          {t_base / t_imp:.1f}x")
    line = {
        "speedup": t_base / t_imp,
        "rel_err": rel_err,
        "impstab_ms": t_imp * 1e3,
        "baseline_ms": t_base * 1e3,
        "baseline_rel_err": base_err,
        "critical_thrust": res.thrust,
        "closed_form": exact,
    }
    print(json.dumps(line))
    return 0


if __name__ == "__main__":
    sys.exit(main())
