"""Post-critical analysis with viscoelastic mounts: the internal variables in the state.

* the Jacobian of the nonlinear equations (complex step through the compiled right-hand side,
  internal variables at rest equal to the deflection) has the eigenvalues of the augmented
  first-order family of the stability analysis (:class:`ViscoelasticFamily`, built from the
  tangent matrices), relaxation roots included;
* the Hopf point, refined by Newton on the nonlinear system from a thrust 2 % off, is the linear
  critical thrust of the viscoelastic family, at its frequency;
* a short branch of cycles carries the extended state (multipliers of every state, profiles of
  the body's 12);
* a supercritical cycle (hardening cubic shear on the same mounts) 1 % past the onset equals the
  one a long time integration settles on: period to 8e-12, amplitudes of every dof to 1.4e-8.
"""

import sys
from pathlib import Path

import numpy as np
import pytest

import impstab
from impstab.dynamics.system import NonlinearSystem
from impstab.linear.viscoelastic import ViscoelasticFamily
from impstab.model import model_from_dict
from impstab.postcritical import hopf_analysis, propulsor_postcritical
from impstab.postcritical.propulsor import propulsor_system

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "dynamics"))
from _dyn_models import asymmetric  # noqa: E402


@pytest.fixture(scope="module")
def model():
    d = asymmetric()
    for m in d["mounts"][:3]:
        m["viscoelastic"] = {"law": "standard-linear-solid", "stiffening": 1.5, "relaxation_time": 4e-3}
        m["k3_axial"] = 1e9
    return model_from_dict(d)


def test_jacobian_spectrum_equals_the_augmented_family(model):
    ns = NonlinearSystem(model)
    assert ns.n_states == 12 + 3 * 3
    thrust = 9000.0
    y0 = ns.equilibrium(thrust)
    assert np.max(np.abs(ns.rhs(y0, thrust))) < 1e-9
    mine = np.linalg.eigvals(ns.jacobian(y0, thrust))
    e, a = ViscoelasticFamily(model, "equilibrium").matrices(np.array([thrust]))
    ref = np.linalg.eigvals(np.linalg.solve(e[0], a[0]))
    assert mine.size == ref.size
    scale = np.abs(ref).max()
    for lam in ref:  # every root of the family, relaxation roots included, is a root of the Jacobian
        assert np.min(np.abs(mine - lam)) < 1e-8 * scale


def test_hopf_onset_equals_the_linear_critical_thrust(model):
    crit = impstab.critical_thrust(model)
    assert crit.kind == "flutter"
    system, ns = propulsor_system(model, crit.omega)
    start = 1.02 * crit.thrust
    hopf = hopf_analysis(system, ns.equilibrium(start), start, omega=crit.omega)
    assert hopf.refined and hopf.iterations > 0
    assert hopf.parameter == pytest.approx(crit.thrust, rel=1e-8)
    assert hopf.omega == pytest.approx(crit.omega, rel=1e-8)
    assert hopf.bifurcation in ("supercritical", "subcritical")


def test_branch_carries_the_internal_variables(model):
    res = propulsor_postcritical(model, max_points=3)
    assert res.critical_thrust == pytest.approx(impstab.critical_thrust(model).thrust, rel=1e-8)
    assert res.branch_multipliers.shape[1] == 21
    ds = res.to_xarray()
    assert ds["profile"].shape[2] == 12 and ds.sizes["multiplier"] == 21
    # the trivial Floquet multiplier: the accuracy check of the extended collocation
    assert np.nanmax(res.trivial_multiplier_error) < 1e-6


def test_a_long_run_lands_on_the_viscoelastic_cycle():
    """Supercritical onset on standard-linear-solid mounts (hardening cubic shear): the branch's
    cycle 1 % past the onset against a long time integration. 1000 s of impstab's Hamming
    integrator from a pitch displacement settle on the cycle (|mu| = 0.992 per period, 4000
    periods); from the state reached, internal variables included, SciPy's DOP853 on the same
    equations samples two periods densely."""
    from scipy.integrate import solve_ivp

    d = asymmetric()
    for m in d["mounts"][:3]:
        m["viscoelastic"] = {"law": "standard-linear-solid", "stiffening": 1.5, "relaxation_time": 4e-3}
        m["k3_shear"] = 1e7
    model = model_from_dict(d)
    tc = impstab.critical_thrust(model).thrust
    thrust = 1.01 * tc
    res = propulsor_postcritical(model, thrusts=[thrust], max_points=40)
    assert res.bifurcation == "supercritical" and res.lyapunov_coefficient < 0
    (i,) = [j for j, t in enumerate(res.branch_thrust) if t == thrust]
    assert res.branch_stable[i]
    settle = impstab.simulate(model, thrust=thrust, duration=1000.0, dt=5e-4, integrator="hamming",
                              critical_thrust=tc, sample=0.5, perturbation={"displacement": {"pitch": 0.02}})
    assert settle.completed and settle.internal_variables is not None
    y0 = np.concatenate([settle.deviation[-1] + settle.equilibrium, settle.internal_variables[-1].ravel()])
    ns = NonlinearSystem(model)
    period = res.branch_period[i]
    t = np.arange(0.0, 2.6 * period, 1e-5)
    sol = solve_ivp(lambda _, y: ns.rhs(y, thrust), (0.0, t[-1]), y0, method="DOP853", t_eval=t,
                    rtol=1e-12, atol=1e-14)
    y = sol.y.T
    amplitude = 0.5 * (y[:, :6].max(axis=0) - y[:, :6].min(axis=0))
    x = y[:, 4] - 0.5 * (y[:, 4].max() + y[:, 4].min())
    k = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    crossings = t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])
    assert crossings.size >= 2
    assert np.diff(crossings).mean() == pytest.approx(period, rel=1e-9)       # measured 8e-12
    np.testing.assert_allclose(amplitude, res.branch_amplitude[i], rtol=1e-6)  # measured 5e-9 to 1.4e-8
    assert res.branch_amplitude[i, 4] > 0.01                             # a real oscillation of the pitch
