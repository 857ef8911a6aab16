"""A propeller whose speed grows as sqrt(T): the engine's operators ``A0 + p A1 + Omega(p) A2``.

With ``speed_law = "sqrt-thrust"`` the gyroscopic matrix is ``G(T) = Omega(T) G_1`` (the speed
``Omega(T) = Omega_op sqrt(T / T_op)``, ``G_1`` per unit speed) and the family is not affine; its stiffness still is, so the engine forms the three operators once
(``problems._GyroscopicLawProvider``) instead of linearizing the model at every load. Independent
answers:

* the operators equal the state matrix ``[[0, I], [-M^-1 K, -M^-1 (D + G)]]`` of the model's
  linearization (``ModelFamily.matrices``) at loads across the range, to rounding;
* the undamped companion of examples/imp_isolation.toml (gyroscopic and conservative) loses
  stability by a coalescence on the imaginary axis, past which ``Re(lambda)^2`` grows linearly in
  the thrust: extrapolated to zero from LAPACK's eigenvalues at 15000.20 N and 15000.25 N, that
  gives the onset independently of the engine (15000.16178 N; the curvature of the branch leaves
  about 4e-9 N).
  The engine's exact indicator lands on it to 3e-13 with compiled kernels (whose inverse
  iteration returns another basis of the pair doubled at 15000 N than LAPACK: before the
  selection turned that basis toward the cluster, bisection on the stability tolerance left the
  onset 1e-5 high, with a warning);
* the damped critical thrusts equal those through the linearization at every load to 1e-12.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import impstab
from impstab._jit import require_compiled
from impstab.linear import critical_load_family
from impstab.linear.eigen import state_matrices
from impstab.linear.engine import problems
from impstab.linear.linearize import ModelFamily

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize("name,damped", [("imp_isolation", True), ("imp_isolation", False), ("imp_damped", True)])
def test_operators_equal_the_state_matrix_of_the_linearization(name, damped):
    model = impstab.load_model(EXAMPLES / f"{name}.toml")
    fam = ModelFamily(model, damped=damped)
    problem = problems.second_order_problem(fam, model.analysis.thrust_max)
    assert isinstance(problem.provider, problems._GyroscopicLawProvider)
    loads = np.array([0.0, 1.0, 0.37 * model.thrust.operating, model.thrust.operating, model.analysis.thrust_max])
    m, d, g, k = fam.matrices(loads)
    expected = state_matrices(m, d + g, k)
    got = problem.provider.operators(loads)
    scale = np.abs(expected).max(axis=(1, 2))
    assert np.all(np.abs(got - expected).max(axis=(1, 2)) <= 1e-14 * scale)
    assert np.any(g[1:] != 0.0) and not np.any(g[0])  # the gyroscopic part follows the load, zero at rest


def _eigenvalues(fam, thrust):
    m, d, g, k = (x[0] for x in fam.matrices(np.array([thrust])))
    return np.linalg.eigvals(state_matrices(m, d + g, k))


def test_the_conservative_companion_loses_stability_where_the_frequencies_coalesce():
    require_compiled()  # the compiled kernels (run as Python, they take LAPACK's decompositions)
    model = impstab.load_model(EXAMPLES / "imp_isolation.toml")
    fam = ModelFamily(model, damped=False)
    res = critical_load_family(fam, model.analysis.thrust_max)
    assert res.kind == "flutter" and res.warnings == ()
    # independent onset: Re(lambda)^2 is linear in the thrust past a coalescence
    p1, p2 = 15000.20, 15000.25  # 0.04 and 0.09 N past it
    g1, g2 = _eigenvalues(fam, p1).real.max() ** 2, _eigenvalues(fam, p2).real.max() ** 2
    onset = p1 - g1 * (p2 - p1) / (g2 - g1)
    assert abs(onset - 15000.16178) < 1e-4
    assert abs(res.load / onset - 1) < 1e-12  # measured 2.7e-13 (by bisection on the tolerance: 9.6e-6)
    below = _eigenvalues(fam, onset * (1 - 1e-9))
    assert below.real.max() < 1e-9 * np.abs(below).max()  # marginally stable just below


@pytest.mark.parametrize("name", ["imp_isolation", "imp_damped"])
def test_damped_critical_thrust_equals_the_linearization_at_every_load(name, monkeypatch):
    model = impstab.load_model(EXAMPLES / f"{name}.toml")
    res = impstab.critical_thrust(model)
    monkeypatch.setattr(ModelFamily, "gyroscopic_law_parts", lambda self: None)
    general = impstab.critical_thrust(model)
    assert res.kind == general.kind == "flutter"
    assert abs(res.thrust / general.thrust - 1) < 1e-12 and abs(res.omega / general.omega - 1) < 1e-12
    np.testing.assert_allclose(res.participation, general.participation, atol=1e-12)


def test_the_command_line_and_a_compiled_process_give_the_same_undamped_onset():
    """A fresh ``impstab critical`` runs its kernels as Python (LAPACK's decompositions); a study
    or any long work compiles them: both must reach the same onset (with the compiled
    decompositions of a repeated eigenvalue, before the selection turned their basis toward the
    cluster, they were 9.6e-6 apart)."""
    import json
    import os
    import subprocess
    import sys

    path = EXAMPLES / "imp_isolation.toml"
    out = subprocess.run([sys.executable, "-m", "impstab", "critical", str(path), "--json"], capture_output=True,
                         text=True, env=dict(os.environ, IMPSTAB_JIT="auto", MPLBACKEND="Agg"), timeout=120)
    assert out.returncode == 0, out.stderr
    line = json.loads(out.stdout)
    require_compiled()
    res = impstab.critical_thrust(impstab.load_model(path))
    assert line["warnings"] == [] and res.warnings == ()
    assert abs(res.undamped_thrust / line["undamped_critical_thrust"] - 1) < 1e-12
    assert abs(res.thrust / line["critical_thrust"] - 1) < 1e-12
