"""The settling test and the cycle amplitudes of the time-integration baseline
(benchmarks/steady_state.py), on signals whose answers are known in closed form."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from steady_state import _Tracker, cycle_amplitudes  # noqa: E402


def test_cycle_amplitudes_of_harmonics():
    """Half peak-to-peak per cycle: a pure first harmonic, a pure second harmonic (measured on the
    same extremum every cycle) and a mixture whose extremes are found by dense evaluation."""
    w, h = 2 * np.pi / 0.29, 0.29 / 397.3
    t = np.arange(0.0, 12 * 0.29, h)
    mix = lambda s: 0.02 * np.sin(w * s) + 0.005 * np.cos(2 * w * s + 0.4)  # noqa: E731
    z = np.column_stack([0.05 * np.cos(w * t), 1e-3 * np.cos(2 * w * t + 0.3), mix(t)])
    amp = cycle_amplitudes(z, dominant=0)
    dense = mix(np.linspace(0.0, 0.29, 2_000_001))
    exact = np.array([0.05, 1e-3, 0.5 * (dense.max() - dense.min())])
    assert amp.shape[0] >= 9
    np.testing.assert_allclose(amp, np.broadcast_to(exact, amp.shape), rtol=1e-9)


def test_settling_stops_within_tolerance_of_a_geometric_limit():
    """a_k = a + slow geometric mode + an oscillating pair almost as slow (as on the propulsor):
    the test says settled only once the true error is below the tolerance, and not much later."""
    tol, a = 1e-8, 0.06
    k = np.arange(20000)
    seq = a * (1 + 0.2 * 0.99 ** k + 0.1 * 0.985 ** k * np.cos(0.75 * k))
    tr = _Tracker(tol, 24)
    stop = None
    for n, v in enumerate(seq):
        tr.amps.append(float(v))
        if n % 8 == 0 and tr.settled():
            stop = n
            break
    assert stop is not None
    true = np.abs(seq / a - 1)
    assert true[stop] < tol
    first_ok = int(np.flatnonzero(true >= tol)[-1]) + 1
    assert stop < first_ok + 400          # the tail bound is conservative, but not wildly
    assert abs(tr.r_reliable - 0.99) < 2e-3
