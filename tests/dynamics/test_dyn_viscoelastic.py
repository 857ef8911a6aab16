"""Time histories with viscoelastic mounts against independent answers.

* surge of the symmetric ring on standard-linear-solid mounts is one dof with one internal
  variable: ``m x'' + k0 x + g k0 (x - w) = 0``, ``tau w' = x - w``; its free vibration from a
  jump of the displacement is the residue sum of ``X(s) = m s x0 (1 + s tau) / P(s)``,
  ``P(s) = m tau s^3 + m s^2 + k0 tau (1 + g) s + k0`` (roots of the exact characteristic cubic,
  ``numpy.roots``); the mount forces equal ``m x'' - T``;
* small-amplitude runs of examples/imp_viscoelastic.toml below and above the critical thrust grow
  or decay at the least-stable eigenvalue of the augmented first-order family (rate and frequency);
* hamming and radau agree on the same run;
* a relaxation time far below the step: refused for the explicit steps with one line naming the
  stiff methods; radau carries it exactly (the closed form again).
"""

from pathlib import Path

import numpy as np
import pytest
from _dyn_models import symmetric

import impstab
from impstab.errors import ModelError
from impstab.linear.viscoelastic import ViscoelasticFamily
from impstab.model import load_model, model_from_dict

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
MASS, K0 = 100.0, 3.0e5  # the ring: three mounts of k_axial = 1e5 N/m along x


def sls_ring(stiffening: float, tau: float):
    d = symmetric()
    d["mount_rings"][0]["viscoelastic"] = {"law": "standard-linear-solid", "stiffening": stiffening,
                                           "relaxation_time": tau}
    return model_from_dict(d)


def surge_closed_form(t, x0, stiffening, tau):
    """Surge deviation and acceleration after a jump ``x0`` of the displacement (w at rest)."""
    g = stiffening - 1.0
    p = np.array([MASS * tau, MASS, K0 * tau * (1 + g), K0])
    lam = np.roots(p)
    dp = np.polyval(np.polyder(p), lam)
    coef = MASS * lam * x0 * (1 + lam * tau) / dp
    e = np.exp(np.outer(t, lam))
    return (e @ coef).real, (e @ (coef * lam**2)).real


@pytest.mark.parametrize("integrator", ["hamming", "gill", "radau"])
def test_surge_free_vibration_equals_standard_linear_solid_closed_form(integrator):
    s, tau, x0, thrust = 2.0, 5e-3, 1e-3, 2000.0
    model = sls_ring(s, tau)
    res = impstab.simulate(model, thrust, 0.4, integrator, perturbation={"displacement": {"surge": x0}},
                           rtol=1e-10, critical_thrust=False)
    assert res.completed
    x, acc = surge_closed_form(res.time, x0, s, tau)
    assert np.max(np.abs(res.deviation[:, 0] - x)) < 1e-6 * x0  # measured 1.1e-7 (gill), 5e-11 (radau)
    assert np.max(np.abs(res.deviation[:, 1:6])) < 1e-12  # pure surge by symmetry
    # the mounts (static and Prony parts) carry the body's inertia and the thrust
    force = res.mount_loads[:, :, 0].sum(axis=1)
    assert np.max(np.abs(force - (MASS * acc - thrust))) < 5e-6 * K0 * x0
    # internal variables: at rest equal to the static deflection T / k0, one 3-vector per mount
    assert res.internal_variables.shape == (res.time.size, 3, 3)
    assert np.allclose(res.internal_variables[0, :, 0], thrust / K0, rtol=1e-12)


def test_stiff_relaxation_refused_for_explicit_steps_and_exact_with_radau():
    s, tau, x0 = 2.0, 1e-5, 1e-3
    model = sls_ring(s, tau)
    for integrator in ("hamming", "gill"):
        with pytest.raises(ModelError) as err:
            impstab.simulate(model, 0.0, 0.1, integrator, dt=1e-3, critical_thrust=False)
        text = str(err.value)
        assert err.value.field == "dt" and "\n" not in text and "radau" in text and "lsoda" in text
    for integrator, rtol in (("radau", 1e-9), ("lsoda", 1e-10)):  # measured 6e-10, 2e-8
        res = impstab.simulate(model, 0.0, 0.2, integrator, perturbation={"displacement": {"surge": x0}}, rtol=rtol,
                               critical_thrust=False)
        x, _ = surge_closed_form(res.time, x0, s, tau)
        assert res.completed and np.max(np.abs(res.deviation[:, 0] - x)) < 1e-7 * x0, integrator
    # the default explicit step resolves the relaxation: stable, and the same answer
    res = impstab.simulate(model, 0.0, 0.02, "hamming", perturbation={"displacement": {"surge": x0}},
                           critical_thrust=False)
    x, _ = surge_closed_form(res.time, x0, s, tau)
    assert res.completed and res.dt * 1e5 < 0.7 and np.max(np.abs(res.deviation[:, 0] - x)) < 1e-6 * x0


def _least_stable(model, thrust):
    e, a = ViscoelasticFamily(model, "equilibrium").matrices(np.array([thrust]))
    vals = np.linalg.eigvals(np.linalg.solve(e[0], a[0]))
    osc = vals[vals.imag > 1e-6]
    return osc[np.argmax(osc.real)]


@pytest.fixture(scope="module")
def example():
    model = load_model(EXAMPLES / "imp_viscoelastic.toml")
    return model, impstab.critical_thrust(model, linearization="equilibrium").thrust


@pytest.mark.parametrize("factor", [0.9, 1.1])
def test_small_amplitude_growth_equals_least_stable_eigenvalue(example, factor):
    model, crit = example
    thrust = factor * crit
    lam = _least_stable(model, thrust)
    res = impstab.simulate(model, thrust, 12.0, "hamming", critical_thrust=crit)
    assert res.completed
    fit = res.growth
    assert (lam.real > 0) == (factor > 1) and res.classification == ("supercritical" if factor > 1 else "subcritical")
    assert abs(fit.rate - lam.real) < 1e-6 * abs(lam.real)  # measured 2e-8
    assert abs(fit.frequency_hz - lam.imag / (2 * np.pi)) < 1e-7 * lam.imag / (2 * np.pi)


def test_hamming_agrees_with_radau(example):
    model, crit = example
    kw = dict(perturbation={"velocity": {"sway": 1e-4, "pitch": 1e-4}}, critical_thrust=False, sample=1e-2)
    ham = impstab.simulate(model, 1.1 * crit, 3.0, "hamming", **kw)
    rad = impstab.simulate(model, 1.1 * crit, 3.0, "radau", rtol=1e-10, **kw)
    scale = np.max(np.abs(rad.deviation[:, :6]), axis=0)
    assert np.allclose(ham.time, rad.time)
    assert np.max(np.abs(ham.deviation[:, :6] - rad.deviation[:, :6]) / scale) < 2e-6  # measured 2e-7
    assert np.max(np.abs(ham.internal_variables - rad.internal_variables)) < 5e-7 * np.max(scale[:3])


def test_cli_refuses_a_stiff_explicit_step_in_one_line_and_writes_nothing(capsys, tmp_path):
    from impstab.cli import main

    out = tmp_path / "s.nc"
    code = main(["simulate", str(EXAMPLES / "imp_viscoelastic.toml"), "--thrust", "1000", "--duration", "0.1",
                 "--dt", "0.004", "-o", str(out)])
    _, err = capsys.readouterr()
    assert code == 2 and err.count("\n") == 1 and err.startswith("impstab: error: --dt = 0.004")
    assert "radau" in err and "Traceback" not in err
    assert not list(tmp_path.iterdir())
    # the same step is fine for the implicit method (its largest step)
    code = main(["simulate", str(EXAMPLES / "imp_viscoelastic.toml"), "--thrust", "1000", "--duration", "0.1",
                 "--dt", "0.004", "--integrator", "radau", "--no-plot", "-o", str(out), "--json"])
    assert code == 0 and out.exists()


def test_step_between_accuracy_and_stability_limit_warns_and_runs():
    from impstab.dynamics.simulate import StepSizeWarning
    from impstab.dynamics.viscoelastic import augmented_roots

    model = sls_ring(2.0, 1e-3)
    rate = augmented_roots(model, 0.0).rate
    assert 1e3 <= rate <= 2e3  # the relaxation root lies between 1 / tau and s / tau
    with pytest.warns(StepSizeWarning, match="relaxation"):
        res = impstab.simulate(model, 0.0, 0.05, "hamming", dt=0.5 / rate, critical_thrust=False,
                               perturbation={"displacement": {"surge": 1e-3}})
    x, _ = surge_closed_form(res.time, 1e-3, 2.0, 1e-3)
    assert res.completed and np.max(np.abs(res.deviation[:, 0] - x)) < 1e-2 * 1e-3
