"""Nonlinear time histories against independent answers (THEORY 7).

* small amplitude: the run equals the linear solution exp(A t) x0 of the linearized system;
* the envelope growth rate fitted from a run equals max Re(lambda) within 1 % above T_c, on the
  symmetric ring and on asymmetric layouts (undamped, and damped with a 6 x 6 mount);
* energy (kinetic plus the exact mount potential, written here with SciPy's rotation vector) is
  conserved at T = 0 without damping, to the order of the integrator, in large motions with a
  spinning propeller;
* all integrators agree on the same run; blow-up stops with the time and the reason.
"""

from pathlib import Path

import numpy as np
import pytest
from _dyn_models import asymmetric, symmetric
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

import impstab
from impstab.dynamics.simulate import default_step
from impstab.kinematics import euler_zyx_to_matrix
from impstab.model import load_model, model_from_dict

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def to_linear_coordinates(res, rot0):
    """(du, dphi, q') of each sample: dphi = log(R R0^T) exactly, q' = (R v, R w)."""
    out = np.empty((res.time.size, 12))
    for k in range(res.time.size):
        eta = res.deviation[k, :6] + res.equilibrium[:6]
        rot = euler_zyx_to_matrix(*eta[3:])
        out[k, :3] = res.deviation[k, :3]
        out[k, 3:6] = Rotation.from_matrix(rot @ rot0.T).as_rotvec()
        out[k, 6:9] = rot @ res.deviation[k, 6:9]
        out[k, 9:] = rot @ res.deviation[k, 9:]
    return out


@pytest.mark.parametrize("integrator, dt_factor, bound", [("hamming", 1.0, 2e-4), ("hamming", 0.25, 2e-6),
                                                           ("dop853", None, 2e-6)])
def test_small_amplitude_run_equals_matrix_exponential(integrator, dt_factor, bound):
    model = model_from_dict(asymmetric(damped=True, gyro=True, tangency=0.8))
    thrust, length = 8000.0, 0.35
    lin = impstab.linearize(model, thrust, "equilibrium")
    amp = 1e-8  # nonlinear terms are ~1e-7 of the motion here
    pert = {"displacement": amp * np.array([1, 2, -1, 0.5 / length, 1 / length, -1 / length]),
            "velocity": amp * np.array([10, -20, 5, 30 / length, 10 / length, 20 / length])}
    dt = None if dt_factor is None else dt_factor * default_step(model, thrust)
    res = impstab.simulate(model, thrust=thrust, duration=3.0, integrator=integrator, dt=dt, perturbation=pert,
                           rtol=1e-12, critical_thrust=False, sample=0.01)
    q = to_linear_coordinates(res, lin.rotation)
    step = expm(lin.state_matrix() * 0.01)
    exact = [q[0]]
    for _ in range(res.time.size - 1):
        exact.append(step @ exact[-1])
    exact = np.array(exact)
    w = np.array([1, 1, 1, length, length, length] * 2)
    assert np.abs((q - exact) * w).max() / np.abs(exact * w).max() < bound


GROWTH_CASES = {
    "symmetric": (symmetric(), 1.02, 8.0),
    "asymmetric": (asymmetric(), 1.05, 30.0),
    "asymmetric-damped-6x6": (asymmetric(damped=True), 1.05, 40.0),
    "asymmetric-example": ("imp_asymmetric.toml", 1.05, 25.0),
}


@pytest.mark.parametrize("case", sorted(GROWTH_CASES))
def test_fitted_growth_rate_equals_re_lambda_above_critical(case):
    spec, factor, duration = GROWTH_CASES[case]
    model = load_model(EXAMPLES / spec) if isinstance(spec, str) else model_from_dict(spec)
    crit = impstab.critical_thrust(model, linearization="equilibrium").thrust
    thrust = factor * crit
    res = impstab.simulate(model, thrust=thrust, duration=duration, critical_thrust=crit)
    sigma = float(np.max(impstab.linearize(model, thrust, "equilibrium").eigenvalues().real))
    g = res.growth
    assert sigma > 0 and g.linear_rate == pytest.approx(sigma, rel=1e-12)
    assert g.rate == pytest.approx(sigma, rel=0.01)
    assert g.n_peaks >= 8 and g.envelope == "exponential growth"
    assert res.classification == "supercritical"


def test_subcritical_bounded_and_critical_linear_growth():
    model = model_from_dict(symmetric())
    crit = impstab.critical_thrust(model, linearization="equilibrium").thrust
    below = impstab.simulate(model, thrust=0.8 * crit, duration=10.0, critical_thrust=crit)
    at = impstab.simulate(model, thrust=crit, duration=20.0, critical_thrust=crit)
    assert below.classification == "subcritical" and below.growth.envelope == "bounded"
    assert at.classification == "critical" and at.growth.envelope == "linear growth"
    # (A + B t): the peaks rise linearly, so the second half's amplitude exceeds the first's
    sway = np.abs(at.displacement[:, 1])
    half = sway.size // 2
    assert sway[half:].max() > 1.5 * sway[:half].max()


def mount_energy(model, res):
    mass = model.mass_matrix
    energy = np.empty(res.time.size)
    for k in range(res.time.size):
        y = res.deviation[k] + res.equilibrium
        rot = euler_zyx_to_matrix(*y[3:6])
        phi = Rotation.from_matrix(rot).as_rotvec()
        pot = 0.0
        for mt in model.mounts:
            e = np.concatenate([y[:3] + rot @ mt.position - mt.position, phi])
            pot += 0.5 * e @ mt.stiffness @ e
        energy[k] = 0.5 * y[6:] @ mass @ y[6:] + pot
    return energy


def test_energy_conserved_at_zero_thrust_to_integrator_order():
    d = asymmetric()
    d["propeller"] = {"polar_inertia": 0.05, "speed": 300.0}  # gyroscopic moments do no work
    model = model_from_dict(d)
    pert = {"displacement": {"sway": 0.01, "yaw": 0.05, "roll": 0.1, "pitch": -0.04},
            "velocity": {"heave": 0.2, "pitch": 0.5, "surge": 0.1}}
    h0 = default_step(model, 0.0)
    drift = {}
    for integrator, dt in (("hamming", h0), ("hamming", h0 / 2), ("gill", h0), ("gill", h0 / 2), ("dop853", None)):
        res = impstab.simulate(model, thrust=0.0, duration=5.0, integrator=integrator, dt=dt, perturbation=pert,
                               rtol=1e-12, critical_thrust=False, sample=h0 * 10)
        assert res.completed and np.abs(res.displacement[:, 3:]).max() > 0.05  # large rotations
        energy = mount_energy(model, res)
        drift[integrator, dt] = np.abs(energy - energy[0]).max() / energy[0]
    for integrator in ("hamming", "gill"):
        assert drift[integrator, h0] < 5e-4
        ratio = drift[integrator, h0] / drift[integrator, h0 / 2]
        assert ratio > 2**3.5, (integrator, ratio)  # fourth order or better
    assert drift["dop853", None] < 1e-9


def test_all_integrators_agree():
    model = model_from_dict(asymmetric(damped=True, gyro=True, tangency=0.8))
    h0 = default_step(model, 6000.0)
    kw = dict(thrust=6000.0, duration=1.0, critical_thrust=False, sample=10 * h0,
              perturbation={"displacement": {"yaw": 0.02, "sway": 0.003}, "velocity": {"pitch": 0.1}})
    runs = {name: impstab.simulate(model, integrator=name, rtol=1e-10, **kw)
            for name in ("hamming", "gill", "dop853", "rk45", "radau", "lsoda")}
    ref = runs["dop853"]
    scale = np.abs(ref.deviation).max(axis=0)
    for name, res in runs.items():
        assert res.time.shape == ref.time.shape and res.completed
        np.testing.assert_allclose(res.time, ref.time, rtol=1e-12)
        err = (np.abs(res.deviation - ref.deviation) / scale).max()
        assert err < (1e-4 if name in ("hamming", "gill") else 1e-6), (name, err)


def test_blow_up_stops_with_time_and_reason_keeping_the_data():
    model = model_from_dict(symmetric())
    res = impstab.simulate(model, thrust=25000.0, duration=30.0, critical_thrust=False)
    assert not res.completed and 0 < res.stop_time < 30.0
    assert "pitch" in res.stop_reason and f"{res.stop_time:.6g}" in res.stop_reason
    assert res.time[-1] == pytest.approx(res.stop_time) and res.time.size > 100
    assert np.all(np.isfinite(res.deviation))
    # a displacement limit stops earlier, for the same reason class (blow-up)
    lim = impstab.simulate(model, thrust=25000.0, duration=30.0, critical_thrust=False, max_displacement=0.01)
    assert not lim.completed and lim.stop_time < res.stop_time and "exceeded 0.01 m" in lim.stop_reason
    assert np.abs(lim.displacement[:, :3]).max() <= 0.01
    # the SciPy methods stop on the same guards
    ivp = impstab.simulate(model, thrust=25000.0, duration=30.0, integrator="dop853", critical_thrust=False,
                           max_displacement=0.01)
    assert not ivp.completed and ivp.stop_time == pytest.approx(lim.stop_time, rel=0.02)


def test_pitch_guard_stops_a_run_before_the_singularity():
    model = model_from_dict(symmetric())
    res = impstab.simulate(model, thrust=0.0, duration=2.0, critical_thrust=False, pitch_limit=np.radians(30),
                           perturbation={"velocity": {"pitch": 30.0}})
    assert not res.completed and "pitch angle reached the guard |theta| = 30 deg" in res.stop_reason
    assert np.abs(res.displacement[:, 4]).max() < np.radians(30)
    with pytest.raises(impstab.ModelError, match="pitch"):
        impstab.simulate(model, thrust=0.0, duration=1.0, pitch_limit=np.radians(30),
                         perturbation={"displacement": {"pitch": 0.6}})
