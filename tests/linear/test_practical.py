"""Practical critical load: the least damping ratio falls to a threshold (impstab.linear.practical).

Independent answers: closed forms of the damping ratio of one and two decoupled dofs; a dense
scan of numpy eigenvalues of the damped Ziegler pendulum with bisection; the exact critical load
for a vanishing threshold; the unit conversion of the logarithmic decrement.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import impstab
from impstab.errors import ModelError
from impstab.linear.critical import critical_load_family
from impstab.linear.families import LinearFamily
from impstab.linear.practical import practical_load_family
from impstab.model.criteria import damping_ratio_of_log_decrement, damping_threshold, log_decrement_of_damping_ratio

ZIEGLER_M = np.array([[3.0, 1.0], [1.0, 1.0]])
ZIEGLER_K0 = np.array([[2.0, -1.0], [-1.0, 1.0]])
ZIEGLER_K1 = np.array([[-1.0, 1.0], [0.0, 0.0]])


def test_single_dof_closed_form():
    # m q'' + c q' + (k0 + k1 p) q = 0: zeta = c / (2 sqrt(m (k0 + k1 p)))
    m, c, k0, k1 = 2.0, 0.6, 3.0, 1.5
    fam = LinearFamily.build([[m]], [[k0]], [[k1]], D=[[c]])
    for zeta in (0.02, 0.05, 0.1):
        exact = (c * c / (4 * m * zeta * zeta) - k0) / k1
        r = practical_load_family(fam, 2 * exact, zeta)
        assert r.load == pytest.approx(exact, rel=1e-12)
        assert r.kind == "flutter" and not r.at_start
        assert r.omega == pytest.approx(math.sqrt((k0 + k1 * exact) / m) * math.sqrt(1 - zeta**2), rel=1e-10)
    # the threshold never reached: zeta(p_max) is still above it
    assert practical_load_family(fam, 1.0, 0.02).load is None
    # below it already at p = 0: zeta(0) = 0.1225 < 0.2
    r = practical_load_family(fam, 1.0, 0.2)
    assert r.at_start and r.load == 0.0


def test_two_decoupled_dofs_least_damped_wins():
    # dof 1: zeta1 = 0.4 / (2 sqrt(1 + p)); dof 2: zeta2 = 1 / (2 sqrt(4 (9 + 0.5 p)))
    fam = LinearFamily.build(np.diag([1.0, 4.0]), np.diag([1.0, 9.0]), np.diag([1.0, 0.5]), D=np.diag([0.4, 1.0]))
    zeta = 0.05
    p1 = (0.4**2 / (4 * zeta**2)) - 1.0
    p2 = ((1.0**2 / (4 * 4.0 * zeta**2)) - 9.0) / 0.5
    assert p1 < p2  # dof 1 reaches the threshold first (p1 = 15, p2 = 32)
    r = practical_load_family(fam, 100.0, zeta)
    assert r.load == pytest.approx(p1, rel=1e-12)
    assert r.omega == pytest.approx(math.sqrt(1 + p1) * math.sqrt(1 - zeta**2), rel=1e-10)
    # with dof 1 damped more, dof 2 decides
    fam = LinearFamily.build(np.diag([1.0, 4.0]), np.diag([1.0, 9.0]), np.diag([1.0, 0.5]), D=np.diag([0.8, 1.0]))
    assert practical_load_family(fam, 100.0, zeta).load == pytest.approx(p2, rel=1e-12)


def _min_zeta(p: float, d: np.ndarray) -> float:
    n = 2
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    a[n:, :n] = -np.linalg.solve(ZIEGLER_M, ZIEGLER_K0 + p * ZIEGLER_K1)
    a[n:, n:] = -np.linalg.solve(ZIEGLER_M, d)
    lam = np.linalg.eigvals(a)
    return float(np.min(-lam.real / np.abs(lam)))


def _brute_force(d: np.ndarray, zeta: float, p_max: float) -> float:
    grid = np.linspace(0.0, p_max, 4001)
    g = np.array([_min_zeta(p, d) - zeta for p in grid])
    i = int(np.flatnonzero(g <= 0)[0])
    assert i > 0
    lo, hi = grid[i - 1], grid[i]
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _min_zeta(mid, d) - zeta > 0 else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("zeta", [0.002, 0.01])
def test_damped_ziegler_against_dense_scan(zeta):
    d = 0.1 * np.array([[2.0, -1.0], [-1.0, 1.0]])
    fam = LinearFamily.build(ZIEGLER_M, ZIEGLER_K0, ZIEGLER_K1, D=d)
    r = practical_load_family(fam, 5.0, zeta)
    expected = _brute_force(d, zeta, 5.0)
    assert r.load == pytest.approx(expected, rel=1e-9)
    assert _min_zeta(r.load, d) == pytest.approx(zeta, abs=1e-10)


def test_threshold_zero_is_the_exact_onset_and_small_thresholds_approach_it():
    d = 0.1 * np.array([[2.0, -1.0], [-1.0, 1.0]])
    fam = LinearFamily.build(ZIEGLER_M, ZIEGLER_K0, ZIEGLER_K1, D=d)
    exact = critical_load_family(fam, 5.0).load
    assert practical_load_family(fam, 5.0, 0.0).load == pytest.approx(exact, rel=1e-12)
    gaps = [exact - practical_load_family(fam, 5.0, z).load for z in (1e-4, 1e-5)]
    assert gaps[0] > gaps[1] > 0
    assert gaps[0] / gaps[1] == pytest.approx(10.0, rel=0.01)  # linear in the threshold near the onset


def test_log_decrement_conversion():
    # API 617: delta = 0.1 is zeta = 0.1 / sqrt(4 pi^2 + 0.01) = 0.015913...
    assert damping_ratio_of_log_decrement(0.1) == pytest.approx(0.1 / math.sqrt(4 * math.pi**2 + 0.01), rel=1e-15)
    for zeta in (0.0, 0.01, 0.3, 0.8):
        assert damping_ratio_of_log_decrement(log_decrement_of_damping_ratio(zeta)) == pytest.approx(zeta, abs=1e-15)
    with pytest.raises(ModelError, match="not both"):
        damping_threshold(0.1, 0.1)
    with pytest.raises(ModelError, match="min_damping_ratio"):
        damping_threshold(True)
    with pytest.raises(ModelError, match="between 0 and 0.9"):
        damping_threshold(1.0)


def _model(tmp_path, analysis: str):
    text = open("examples/imp_damped.toml").read().replace(
        "[analysis]\nthrust_max = 20000.0", "[analysis]\nthrust_max = 20000.0\n" + analysis)
    path = tmp_path / "m.toml"
    path.write_text(text)
    return path


def test_model_key_and_api_and_log_decrement_agree(tmp_path):
    zeta = 0.001
    delta = log_decrement_of_damping_ratio(zeta)
    a = impstab.critical_thrust(impstab.load_model(_model(tmp_path, f"min_damping_ratio = {zeta}")))
    b = impstab.critical_thrust(impstab.load_model("examples/imp_damped.toml"), min_log_decrement=delta)
    assert a.practical_thrust == pytest.approx(b.practical_thrust, rel=1e-10)
    assert 0 < a.practical_thrust < a.thrust
    assert a.practical_margin == pytest.approx(a.practical_thrust / 2000.0, rel=1e-15)
    # independent check at the reported thrust: the least damping ratio of the model's eigenvalues
    md = impstab.modes(impstab.load_model("examples/imp_damped.toml"), thrust=a.practical_thrust)
    lam = np.asarray(md.eigenvalues)
    assert float(np.min(-lam.real / np.abs(lam))) == pytest.approx(zeta, abs=1e-8)
    d = a.to_dict()
    assert d["practical_critical_thrust"] == a.practical_thrust and d["min_damping_ratio"] == zeta
    assert d["critical_thrust"] == a.thrust  # the fixed key is unchanged
    # without a threshold: no practical values
    c = impstab.critical_thrust(impstab.load_model("examples/imp_damped.toml"))
    assert c.practical is None and c.to_dict()["practical_critical_thrust"] is None


def test_model_file_rules(tmp_path):
    for text, field in (("min_damping_ratio = true", "analysis.min_damping_ratio"),
                        ("min_log_decrement = -0.1", "analysis.min_log_decrement"),
                        ("min_damping_ratio = 0.1\nmin_log_decrement = 0.1", "analysis.min_log_decrement")):
        with pytest.raises(ModelError, match=field.replace(".", r"\.")):
            impstab.load_model(_model(tmp_path, text))


def test_cli_option_and_json(tmp_path):
    out = subprocess.run([sys.executable, "-m", "impstab", "critical", "examples/imp_damped.toml",
                          "--min-log-decrement", "0.1", "--json"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["min_log_decrement"] == pytest.approx(0.1, rel=1e-14)
    # the example's shear damping is very light: the least damping ratio is below 0.0159 at T = 0
    assert d["practical_critical_thrust"] == 0.0
    bad = subprocess.run([sys.executable, "-m", "impstab", "critical", "examples/imp_damped.toml",
                          "--min-damping-ratio", "0.95"], capture_output=True, text=True)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1 and "--min-damping-ratio" in bad.stderr
