"""Hamming's predictor-corrector and Gill's RK4 against their formulas and analytic answers.

* one Gill step equals the textbook Butcher tableau (nonlinear, time-dependent thrust);
* Hamming's run equals a plain transcription of THEORY 8's formulas (predictor, modifier,
  corrector, final value, three Gill steps to start);
* order of convergence on x'' + w^2 x = 0 against cos(w t); the error estimate scales as h^5;
* stability on the imaginary axis: the limit from the amplification matrix of the formulas, and
  the measured growth per step equals its spectral radius on both sides of the limit;
* step-size control with restart; chunked runs equal one run; the plain-Python path
  (NUMBA_DISABLE_JIT=1) gives bit-identical results.
"""

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from _dyn_models import asymmetric

from impstab.dynamics import Ramp
from impstab.dynamics.integrators import integrate_linear
from impstab.dynamics.kernels import CARRY_ROWS, run_fixed
from impstab.dynamics.system import evaluate_rhs, pack_dynamics
from impstab.model import model_from_dict

SQ2 = math.sqrt(2.0)
GILL_A = np.array([[0, 0, 0, 0], [0.5, 0, 0, 0], [(SQ2 - 1) / 2, 1 - 1 / SQ2, 0, 0], [0, -1 / SQ2, 1 + 1 / SQ2, 0]])
GILL_B = np.array([1, 2 - SQ2, 2 + SQ2, 1]) / 6
GILL_C = np.array([0, 0.5, 0.5, 1])


@pytest.fixture(scope="module")
def ramp_problem():
    model = model_from_dict(asymmetric(damped=True, gyro=True, tangency=0.8))
    system = pack_dynamics(model)
    ramp = Ramp(3000.0, 9000.0, 0.05)
    op = model.thrust.operating

    def f(t, z):
        thrust = ramp(t)
        spin = 200.0 * math.sqrt(thrust / op)
        return evaluate_rhs(system, np.zeros(12), z, thrust, spin)[0]

    def loads(t):
        thrust = ramp(np.asarray(t))
        return np.ascontiguousarray(np.vstack([thrust, 200.0 * np.sqrt(thrust / op)]))

    z0 = np.array([1e-3, -2e-3, 1e-3, 0.01, -0.02, 0.015, 0.05, 0.02, -0.03, 0.3, -0.2, 0.4])
    return system, f, loads, z0


def kernel(system, loads, z0, h, n, method, stride=1):
    carry = np.zeros((CARRY_ROWS, 12))
    carry[0] = z0
    out = np.zeros((n // stride + 2, 12))
    err = np.zeros(n // stride + 2)
    out[0] = z0
    st, done, _, written = run_fixed(method, 0, system.arrays, np.zeros(12), h, n, stride,
                                     loads(0.5 * h * np.arange(2 * n + 1)), carry, 0, out, err, 0,
                                     np.ones(12), 0.0, 1e9, False)
    assert st == 0 and done == n
    return out[: written + 1], err[: written + 1]


def gill_tableau(f, t, y, h):
    k = []
    for i in range(4):
        k.append(f(t + GILL_C[i] * h, y + h * sum(GILL_A[i, j] * k[j] for j in range(i))))
    return y + h * sum(GILL_B[i] * k[i] for i in range(4))


def test_gill_step_equals_textbook_tableau(ramp_problem):
    system, f, loads, z0 = ramp_problem
    h = 2e-3
    out, _ = kernel(system, loads, z0, h, 5, 0)
    y = z0.copy()
    for n in range(5):
        y = gill_tableau(f, n * h, y, h)
        np.testing.assert_allclose(out[n + 1], y, rtol=1e-13, atol=1e-16)


def test_hamming_equals_its_formulas(ramp_problem):
    system, f, loads, z0 = ramp_problem
    h, n = 1.5e-3, 120
    out, err = kernel(system, loads, z0, h, n, 1)
    ys = [z0.copy()]
    for k in range(3):
        ys.append(gill_tableau(f, k * h, ys[-1], h))
    fs = [f(k * h, y) for k, y in enumerate(ys)]
    pc = np.zeros(12)
    est = [np.nan] * 4
    for k in range(3, n):
        p = ys[k - 3] + (4 * h / 3) * (2 * fs[k] - fs[k - 1] + 2 * fs[k - 2])
        m = p - 112 / 121 * pc
        c = (9 * ys[k] - ys[k - 2] + 3 * h * (f((k + 1) * h, m) + 2 * fs[k] - fs[k - 1])) / 8
        y = c + 9 / 121 * (p - c)
        pc = p - c
        ys.append(y)
        fs.append(f((k + 1) * h, y))
        est.append(9 / 121 * np.abs(p - c).max() / np.abs(y).max())
    ys = np.array(ys)
    np.testing.assert_allclose(out, ys, rtol=1e-11, atol=1e-15 * np.abs(ys).max())
    np.testing.assert_allclose(err[4:], est[4:], rtol=1e-6)


def oscillator_error(integrator, w, t_end, n):
    a = np.array([[0.0, 1.0], [-w * w, 0.0]])
    run = integrate_linear(a, [1.0, 0.0], t_end / n, n, integrator)
    return abs(run.z[-1, 0] - math.cos(w * t_end)), run


@pytest.mark.parametrize("integrator, low, high", [("hamming", 3.8, 5.7), ("gill", 3.9, 4.1)])
def test_order_of_convergence_on_harmonic_oscillator(integrator, low, high):
    errors = np.array([oscillator_error(integrator, 2.0, 10.0, n)[0] for n in (200, 400, 800, 1600)])
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all((orders > low) & (orders < high)), orders


def test_hamming_error_estimate_scales_as_h5():
    est = [np.nanmedian(oscillator_error("hamming", 2.0, 10.0, n)[1].error) for n in (200, 400, 800)]
    orders = np.log2(np.array(est[:-1]) / np.array(est[1:]))
    assert np.all(np.abs(orders - 5.0) < 0.2), orders


def amplification_matrix(z):
    """One Hamming step on y' = lambda y (z = h lambda) in the state (y_n, y_n-1, y_n-2, y_n-3, p_n - c_n)."""
    e = np.eye(5, dtype=complex)
    y0, y1, y2, y3, pc = e
    p = y3 + 4 / 3 * z * (2 * y0 - y1 + 2 * y2)
    m = p - 112 / 121 * pc
    c = (9 * y0 - y2 + 3 * z * (m + 2 * y0 - y1)) / 8
    return np.array([c + 9 / 121 * (p - c), y0, y1, y2, p - c])


def spectral_radius(x):
    return max(abs(np.linalg.eigvals(amplification_matrix(1j * x))))


def test_zero_stability_roots_of_the_corrector():
    roots = np.sort(np.roots([8, -9, 0, 1]).real)  # 8 rho^3 - 9 rho^2 + 1 = 0
    np.testing.assert_allclose(roots, np.sort([1.0, (1 + math.sqrt(33)) / 16, (1 - math.sqrt(33)) / 16]), atol=1e-12)
    assert spectral_radius(1e-9) == pytest.approx(1.0, abs=1e-12)


def test_stability_limit_on_the_imaginary_axis():
    lo, hi = 0.1, 0.5
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if spectral_radius(mid) <= 1 + 1e-13 else (lo, mid)
    limit = lo
    assert 0.27 < limit < 0.28  # THEORY 8: |h omega| < ~0.27
    assert 2 * math.pi / 40 < limit  # the default 40 steps per period is inside it
    rot = np.array([[0.0, 1.0], [-1.0, 0.0]])
    for x in (0.9 * limit, 1.1 * limit, 0.5):
        n = 40000
        run = integrate_linear(rot, [1.0, 0.0], x, n, "hamming")
        amp = np.log(np.hypot(run.z[:, 0], run.z[:, 1]))
        slope = np.polyfit(np.arange(1000, n + 1), amp[1000:], 1)[0]
        assert slope == pytest.approx(math.log(spectral_radius(x)), rel=0.02, abs=2e-9)
        assert (slope > 0) == (x > limit)


def test_step_size_control_halves_and_recovers_accuracy():
    import warnings

    import impstab
    from impstab.dynamics.simulate import StepSizeWarning, default_step

    model = impstab.load_model(Path(__file__).resolve().parents[2] / "examples" / "imp_asymmetric.toml")
    h0 = default_step(model, 5000.0)
    kw = dict(thrust=5000.0, duration=2.0, perturbation={"velocity": {"sway": 1e-3, "pitch": 1e-3}},
              critical_thrust=False, sample=8 * h0)
    ref = impstab.simulate(model, integrator="dop853", rtol=1e-12, **kw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StepSizeWarning)
        coarse = impstab.simulate(model, dt=4 * h0, **kw)
        ctrl = impstab.simulate(model, dt=4 * h0, tol=1e-8, **kw)
    scale = np.abs(ref.deviation).max(axis=0)
    err_coarse = (np.abs(coarse.deviation - ref.deviation) / scale).max()
    err_ctrl = (np.abs(ctrl.deviation - ref.deviation) / scale).max()
    assert ctrl.restarts >= 2 and ctrl.final_dt < h0
    assert err_ctrl < 1e-6 < 1e-2 < err_coarse
    assert np.nanmax(ctrl.error_estimate) <= 1e-8
    # doubling: from a tiny step the control grows the step back towards the default
    fine = impstab.simulate(model, dt=h0 / 8, tol=1e-6, **kw)
    assert fine.final_dt > 4 * fine.dt and fine.completed


def test_chunked_run_equals_one_run(ramp_problem):
    system, f, loads, z0 = ramp_problem
    whole, _ = kernel(system, loads, z0, 1e-3, 400, 1)
    carry = np.zeros((CARRY_ROWS, 12))
    carry[0] = z0
    out = np.zeros((402, 12))
    err = np.zeros(402)
    out[0] = z0
    nhist, k = 0, 0
    for chunk in (7, 93, 300):
        t0 = k * 1e-3
        _, _, nhist, written = run_fixed(1, 0, system.arrays, np.zeros(12), 1e-3, chunk, 1,
                                         loads(t0 + 0.5e-3 * np.arange(2 * chunk + 1)), carry, nhist, out, err,
                                         k, np.ones(12), 0.0, 1e9, False)
        k += written
    np.testing.assert_array_equal(out[:401], whole)


@pytest.mark.parametrize("integrator", ["hamming", "gill"])
def test_a_constant_thrust_as_one_column_equals_its_value_at_every_half_step(integrator):
    """A constant thrust reaches the step loop as one (thrust, spin) column; the same thrust as a
    function of time reaches it as its value at every half step. The two runs are the same run."""
    import impstab

    model = model_from_dict(asymmetric(damped=True, gyro=True, tangency=0.8))
    pert = {"velocity": [0.01, 0.02, 0.03, 0.1, 0.2, 0.3]}
    kw = dict(duration=0.5, integrator=integrator, perturbation=pert, critical_thrust=False)
    one = impstab.simulate(model, thrust=7000.0, **kw)
    every = impstab.simulate(model, thrust=lambda t: 7000.0 + 0.0 * np.asarray(t), **kw)
    assert "user function" in every.thrust_history and "user function" not in one.thrust_history
    assert one.steps == every.steps > 100
    np.testing.assert_array_equal(one.deviation, every.deviation)
    assert np.abs(one.deviation).max() > 1e-4


SCRIPT = """
import sys, numpy as np
sys.path.insert(0, {here!r})
from _dyn_models import asymmetric
import impstab
from impstab.dynamics import Ramp
from impstab.model import model_from_dict
model = model_from_dict(asymmetric(damped=True, gyro=True, tangency=0.8))
pert = {{"velocity": [0.01, 0.02, 0.03, 0.1, 0.2, 0.3], "displacement": {{"yaw": 0.02}}}}
a = impstab.simulate(model, thrust=Ramp(3000.0, 9000.0, 0.1), duration=0.15, perturbation=pert, critical_thrust=False)
b = impstab.simulate(model, thrust=9000.0, duration=0.1, integrator="gill", perturbation=pert, critical_thrust=False)
np.savez({out!r}, a=a.deviation, e=a.error_estimate, m=a.mount_loads, b=b.deviation)
"""


def test_plain_python_path_is_bit_identical(tmp_path):
    here = str(Path(__file__).resolve().parent)
    results = []
    for jit in ("0", "1"):
        out = str(tmp_path / f"run{jit}.npz")
        env = dict(os.environ, NUMBA_DISABLE_JIT=jit)
        subprocess.run([sys.executable, "-c", SCRIPT.format(here=here, out=out)], check=True, env=env,
                       capture_output=True, timeout=300)
        results.append(np.load(out))
    for key in ("a", "e", "m", "b"):
        np.testing.assert_array_equal(results[0][key], results[1][key])
    assert np.abs(results[0]["a"]).max() > 1e-3  # a real (nonlinear, time-dependent) run
