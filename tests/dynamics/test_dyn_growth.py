"""What `simulate` says a run shows, against the linear theory and an independent orbit.

* the envelope label and the fitted rate do not depend on the run length (5 to 40 s), on damped
  (decaying at max Re lambda), undamped beating (bounded), critical (linear growth, no relative
  difference against a neutral linear rate), Hopf-critical damped (bounded) and supercritical
  (exponential growth at Re lambda) runs of symmetric and asymmetric layouts;
* the fitted rate equals max Re(lambda) of the linearization to 1e-4 wherever it is not neutral;
* a run past a supercritical onset of a lightly damped asymmetric layout with hardening cubic
  shear springs settles on a limit cycle: label, period and amplitudes (half the peak-to-peak of
  each coordinate over one period) equal those of the periodic orbit recomputed independently
  with SciPy's DOP853 from the last state (it closes after one period), and the growth rate
  towards it equals Re(lambda);
* a run that has not settled, and one without motion, are "undetermined" with the reason;
* a thrust step is judged about the equilibrium at the final thrust.
"""

import math

import numpy as np
import pytest
from _dyn_models import asymmetric, symmetric
from scipy.integrate import solve_ivp

import impstab
from impstab.dynamics import Step
from impstab.dynamics.growth import ENVELOPES, GrowthFit
from impstab.dynamics.system import NonlinearSystem
from impstab.model import load_model, model_from_dict
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
DURATIONS = (5.0, 10.0, 20.0, 40.0)


def _model(name):
    if name == "damped-ring":
        return load_model(EXAMPLES / "imp_damped.toml")
    if name == "ring":
        return model_from_dict(symmetric())
    if name == "asymmetric":
        return model_from_dict(asymmetric())
    return model_from_dict(asymmetric(damped=True, gyro=True))


CASES = [
    # model, thrust / T_c, envelope
    ("damped-ring", 0.5, "decaying"),
    ("damped-ring", 0.86, "decaying"),
    ("asymmetric-damped", 0.5, "decaying"),
    ("asymmetric-damped", 1.0, "bounded"),      # a simple pair on the imaginary axis
    ("asymmetric-damped", 1.03, "exponential growth"),
    ("ring", 0.8, "bounded"),                   # beating of neutral modes
    ("ring", 0.99, "bounded"),                  # slow beating of two close modes
    ("ring", 1.0, "linear growth"),             # the double root at T_c
    ("ring", 1.02, "exponential growth"),
    ("asymmetric", 0.5, "bounded"),
    ("asymmetric", 1.0, "linear growth"),
]


@pytest.fixture(scope="module")
def critical():
    return {name: impstab.critical_thrust(_model(name), linearization="equilibrium").thrust
            for name in ("damped-ring", "ring", "asymmetric", "asymmetric-damped")}


@pytest.mark.parametrize("name, factor, envelope", CASES)
def test_label_and_rate_do_not_depend_on_the_run_length(critical, name, factor, envelope):
    model = _model(name)
    tc = critical[name]
    thrust = factor * tc
    sigma = float(np.max(impstab.linearize(model, thrust, "equilibrium").eigenvalues().real))
    rates = []
    for duration in DURATIONS:
        g = impstab.simulate(model, thrust=thrust, duration=duration, critical_thrust=tc).growth
        assert g.envelope == envelope, (duration, g)
        assert g.envelope in ENVELOPES and g.linear_rate == pytest.approx(sigma, rel=1e-12, abs=1e-12)
        rates.append(g.rate)
        if envelope in ("decaying", "exponential growth"):
            # to 1e-4, or to the integrator's own damping ratio at the default step (~1e-7)
            tol = 1e-4 * abs(sigma) + 1e-7 * 2 * math.pi * g.frequency_hz
            assert abs(g.rate - sigma) <= tol
            assert abs(g.relative_difference) <= tol / abs(sigma)
        else:
            # neutral: the rate is within the neutral band and no relative difference is made up
            assert abs(g.rate) <= g.rate_tolerance and g.relative_difference is None
    if envelope == "decaying":
        assert max(rates) - min(rates) <= 1e-5 * abs(sigma)


def test_the_old_failure_cases():
    """A decaying run is not "bounded", a run at T_c has no 1e7 % difference."""
    model = load_model(EXAMPLES / "imp_damped.toml")
    g = impstab.simulate(model, thrust=8000.0, duration=20.0, critical_thrust=False).growth
    assert g.envelope == "decaying" and g.rate == pytest.approx(g.linear_rate, rel=1e-4)
    ring = model_from_dict(symmetric())
    tc = impstab.critical_thrust(ring).thrust
    g = impstab.simulate(ring, thrust=tc, duration=20.0, critical_thrust=tc).growth
    assert g.envelope == "linear growth" and g.relative_difference is None


def hopf_model():
    """The asymmetric example layout with light dampers and hardening cubic shear springs."""
    import tomllib

    with open(EXAMPLES / "imp_asymmetric.toml", "rb") as fh:
        d = tomllib.load(fh)
    for m in d["mounts"]:
        m.update(c_axial=4.0, c_shear=1.0, k3_shear=1e7)
    return model_from_dict(d)


@pytest.fixture(scope="module")
def cycle_run():
    model = hopf_model()
    crit = impstab.critical_thrust(model)
    assert crit.kind == "flutter" and crit.method == "hopf"
    thrust = crit.thrust + 20.0
    res = impstab.simulate(model, thrust=thrust, duration=400.0, critical_thrust=crit.thrust, sample=0.01)
    return model, thrust, res


def test_supercritical_run_settles_on_the_limit_cycle(cycle_run):
    model, thrust, res = cycle_run
    g = res.growth
    assert res.classification == "supercritical" and res.completed
    assert g.envelope == "limit cycle" and g.reason is None
    assert g.rate == pytest.approx(g.linear_rate, rel=1e-3)  # the growth towards the cycle
    # the orbit, recomputed from the last state over the reported period with DOP853
    ns = NonlinearSystem(model)
    y0 = res.deviation[-1] + res.equilibrium
    ts = np.linspace(0.0, g.period, 2001)
    sol = solve_ivp(lambda t, y: ns.rhs(y, thrust), (0.0, g.period), y0, method="DOP853", rtol=1e-11, atol=1e-14,
                    t_eval=ts)
    orbit = sol.y.T
    scale = np.ptp(orbit[:, :6], axis=0)
    assert np.abs(orbit[-1, :6] - orbit[0, :6]).max() <= 2e-3 * scale.max()  # it closes: periodic
    for j, name in enumerate(("surge", "sway", "heave", "roll", "pitch", "yaw")):
        assert g.amplitude[name] == pytest.approx(0.5 * scale[j], rel=2e-3), name
    assert g.amplitude["pitch"] > 1e-3  # a real oscillation, far beyond the 1e-5 kick
    assert g.frequency_hz == pytest.approx(1.0 / g.period)
    # round trip through the result's dictionary and netCDF attributes
    assert GrowthFit.from_dict(g.to_dict()) == g and GrowthFit.from_dict(g.to_dict()).amplitude == g.amplitude


def test_a_run_still_on_its_way_is_undetermined_with_the_reason(cycle_run):
    model, thrust, res = cycle_run
    short = impstab.simulate(model, thrust=thrust, duration=150.0, critical_thrust=False, sample=0.01)
    g = short.growth
    assert g.envelope == "undetermined" and "not yet periodic" in g.reason and "run longer" in g.reason
    still = impstab.simulate(model, thrust=thrust, duration=2.0, critical_thrust=False, perturbation={})
    assert still.growth.envelope == "undetermined" and "no motion" in still.growth.reason


def test_thrust_step_is_judged_about_the_final_equilibrium():
    model = load_model(EXAMPLES / "imp_damped.toml")
    res = impstab.simulate(model, thrust=Step(3000.0, 5000.0, 1.0), duration=12.0, critical_thrust=False)
    g = res.growth
    assert g.window[0] >= 1.0 and g.envelope == "decaying"
    # the step excites the axial (surge) mode: its rate -3 c_axial / (2 m)
    assert g.dof == "surge" and g.rate == pytest.approx(-3 * 60.0 / (2 * 100.0), rel=1e-3)
    assert math.isclose(g.thrust, 5000.0)
