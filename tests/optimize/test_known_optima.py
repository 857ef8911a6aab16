"""The optimiser on problems whose optimum is known in closed form."""

from __future__ import annotations

import numpy as np
import pytest

import impstab
from impstab.optimize.engine import Variables, polish, search


def ziegler_flutter_load(r: float, k: float = 1.0, l: float = 1.0, m2: float = 1.0) -> float:
    """Flutter load of Ziegler's pendulum (absolute angles, THEORY), masses m1 = r m2 (middle
    hinge) and m2 (tip), equal rotational springs k, by the generic stability engine."""
    m1 = r * m2
    M = l**2 * np.array([[m1 + m2, m2], [m2, m2]])
    K0 = k * np.array([[2.0, -1.0], [-1.0, 1.0]])
    K1 = -l * np.array([[1.0, -1.0], [0.0, 0.0]])
    res = impstab.critical_load(M, K0, K1, p_max=10.0 * k / l)
    assert res.kind == "flutter"
    return res.load


def test_ziegler_flutter_load_formula():
    """The engine reproduces P_f(r) = (r/2 + 5/2 - sqrt r) k/l (and 7/2 - sqrt 2 at r = 2)."""
    for r in (0.3, 1.0, 2.0, 4.0):
        assert ziegler_flutter_load(r) == pytest.approx(r / 2 + 2.5 - np.sqrt(r), rel=1e-9)


def test_optimiser_finds_the_smallest_ziegler_flutter_load():
    calls = []

    def evaluate(x):
        calls.append(len(x))
        f = np.array([[ziegler_flutter_load(r)] for r in x[:, 0]])
        return f, np.zeros((len(x), 0))

    v = Variables(np.array([0.1]), np.array([10.0]), np.array([True]))
    res = search(evaluate, v, 1, 0, population=12, generations=10, seed=3)
    assert res.evaluations == len(calls) == 10           # one batched call per generation
    best = int(np.argmin(res.f[:, 0]))
    x, f, _, n = polish(evaluate, v, res.x[best])
    assert x[0] == pytest.approx(1.0, abs=2e-3)
    assert f[0] == pytest.approx(2.0, abs=1e-6)           # P_f(1 + e) = 2 + e^2 / 8


def test_single_dof_isolator_optimum_on_its_deflection_bound():
    """Minimise the transmissibility of m, k, c at 20 Hz subject to F / k <= d_max: the optimum
    is the softest allowed spring, k = F / d_max (transmissibility falls with k above sqrt 2 f_n)."""
    m, c, force, d_max, f0 = 50.0, 200.0, 1000.0, 0.004, 20.0
    w = 2 * np.pi * f0

    def evaluate(x):
        k = x[:, 0]
        t = np.abs(k + 1j * w * c) / np.abs(k - m * w**2 + 1j * w * c)
        return t[:, None], (force / k - d_max)[:, None] / d_max

    v = Variables(np.array([1e4]), np.array([1e7]), np.array([True]))
    res = search(evaluate, v, 1, 1, population=16, generations=12, seed=1)
    ok = res.feasible
    best = np.flatnonzero(ok)[np.argmin(res.f[ok, 0])]
    x, f, g, _ = polish(evaluate, v, res.x[best])
    assert g[0] <= 0.0
    assert x[0] == pytest.approx(force / d_max, rel=1e-4)
