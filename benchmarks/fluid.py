"""Baffled-cylinder coefficients: time per evaluation and accuracy against refined computations.

Timed (median of repeats, ``time.perf_counter``, the result cache cleared before every call):

* the incompressible pair ``added_mass`` + ``added_inertia`` (one call returns both) of a
  segment with radius 0.15 m and length 0.8 m in sea water;
* the same segment at one compressible frequency point (c = 1500 m/s, f = 500 Hz).

Baseline: the plain method, adaptive QUADPACK (``scipy.integrate.quad``, epsrel 1e-13) on the real
axis cut into half-periods of the window, with the tail beyond a few radii by QUADPACK's
Fourier-integral routine (QAWF); four integrals per point (translation and rotation, real and
imaginary parts): ``tests/fluid/fluid_reference.py``, the test suite's independent route. It
also serves as the first refined computation; the second is impstab's own
panel layout with four times as many panels and a much deeper grading.

``rel_err_vs_refined`` is the largest relative difference of the four coefficients (added mass,
added inertia, the two radiation resistances), over both points, from either refined
computation. Prints a table and ends with one JSON line.
"""

from __future__ import annotations

from impstab._blas import prefer_single_thread

prefer_single_thread()  # before numpy loads: impstab and the baseline with one BLAS thread, as the CLI runs

import json
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import impstab.fluid as fl
from impstab.fluid.baffled_cylinder import _baffled_cylinder
from impstab.fluid.integrals import window_integrals

# the plain method is the test suite's independent reference, one implementation for both
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "fluid"))
from fluid_reference import window_integral  # noqa: E402

A, L, RHO, C, F = 0.15, 0.8, 1025.0, 1500.0, 500.0


def coefficients(j0: complex, j1: complex, omega: float) -> np.ndarray:
    """(m_a, I_a, R, R_rot) from the window integrals (THEORY 9 scalings)."""
    st, sr = RHO * A * L**2, RHO * A * L**4 / 4
    return np.array([st * j0.real, sr * j1.real, -omega * st * j0.imag, -omega * sr * j1.imag])


def median_ms(fn, repeats: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        _baffled_cylinder.cache_clear()
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(times), out


def main() -> int:
    ell = L / (2 * A)
    rows, worst = [], 0.0
    for label, c, f in (("incompressible", None, 0.0), ("compressible", C, F)):
        omega = 2 * math.pi * f
        s0 = 0.0 if c is None else omega * A / c
        ms, r = median_ms(lambda: fl.baffled_cylinder(A, L, RHO, c, f), repeats=200)
        got = np.array([r.added_mass, r.added_inertia, r.radiation_resistance or 0.0,
                        r.rotational_radiation_resistance or 0.0])
        t0 = time.perf_counter()
        plain = coefficients(window_integral(ell, s0, 0), window_integral(ell, s0, 1), omega)
        plain_ms = 1e3 * (time.perf_counter() - t0)
        fine = window_integrals(ell, s0, refine=4)
        refined = coefficients(*fine.values, omega)
        err = 0.0
        for ref in (plain, refined):
            nz = ref != 0.0
            err = max(err, float(np.max(np.abs(got[nz] / ref[nz] - 1.0))))
        worst = max(worst, err)
        rows.append((label, ms, plain_ms, err, r.error_estimate))
    print(f"{'case':16s} {'impstab ms':>11s} {'quad ms':>9s} {'speed-up':>9s} {'rel err':>9s} {'estimate':>9s}")
    for label, ms, plain_ms, err, est in rows:
        print(f"{label:16s} {ms:11.3f} {plain_ms:9.1f} {plain_ms / ms:9.0f} {err:9.1e} {est:9.1e}")
    print(json.dumps({"incompressible_ms": round(rows[0][1], 4), "compressible_ms": round(rows[1][1], 4),
                      "rel_err_vs_refined": worst}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
