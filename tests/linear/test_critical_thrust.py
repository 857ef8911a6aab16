"""Critical thrust of propulsor models against closed forms and independent routes."""

import numpy as np
import pytest
import scipy.linalg as sla
from conftest import asymmetric_model_dict, ring_model_dict
from scipy.optimize import brentq

import impstab
from impstab import critical_thrust, linearize
from impstab.model import model_from_dict

M, I_T, I_X, K_SH, K_AX, X_M, R_M = 100.0, 6.0, 1.0, 2.0e4, 1.0e5, 0.3, 0.15


def planar_discriminant(t, preload=True):
    """Discriminant of m I s^2 - (k_y I + m k_t') s + (k_y k_t' - k_yt^2 + T k_yt) (THEORY 4)."""
    k_y, k_yt = 3 * K_SH, 3 * K_SH * X_M
    k_t = 3 * K_SH * X_M**2 + 1.5 * K_AX * R_M**2 - (t * X_M if preload else 0.0)
    return (k_y * I_T + M * k_t) ** 2 - 4 * M * I_T * (k_y * k_t - k_yt**2 + t * k_yt)


@pytest.mark.parametrize("linearization", ["equilibrium", "classical"])
def test_planar_closed_form_with_preload(linearization):
    model = model_from_dict(ring_model_dict())
    res = critical_thrust(model, linearization=linearization)
    exact = brentq(planar_discriminant, 0.0, 30000.0, xtol=1e-13)
    assert res.kind == "flutter"
    assert res.thrust == pytest.approx(exact, rel=1e-12)
    assert res.margin == pytest.approx(exact / 2000.0, rel=1e-12)


def test_planar_closed_form_without_preload():
    d = ring_model_dict()
    d["thrust"]["preload_stiffness"] = False
    res = critical_thrust(model_from_dict(d))
    k_y, k_yt = 3 * K_SH, 3 * K_SH * X_M
    k_t = 3 * K_SH * X_M**2 + 1.5 * K_AX * R_M**2
    t_c = ((k_y * I_T - M * k_t) ** 2 + 4 * M * I_T * k_yt**2) / (4 * M * I_T * k_yt)
    w_c = np.sqrt((k_y * I_T + M * k_t) / (2 * M * I_T))
    assert res.thrust == pytest.approx(t_c, rel=1e-12)
    assert res.omega == pytest.approx(w_c, rel=1e-7)   # at a defective root: sqrt(eps) in omega
    assert res.frequency_hz == pytest.approx(w_c / (2 * np.pi), rel=1e-7)


def test_figure4_structure_of_the_symmetric_example(examples):
    model = impstab.load_model(examples / "imp_symmetric.toml")
    res = critical_thrust(model)
    lam0 = linearize(model, 0.0).eigenvalues()
    assert np.abs(lam0.real).max() < 1e-10 * np.abs(lam0).max()      # all imaginary at T = 0
    w0 = np.sort(np.abs(lam0.imag))[::2]
    # sway = heave and pitch = yaw pairs: two double frequencies
    assert np.sum(np.isclose(w0[:, None], w0[None, :], rtol=1e-9)) == 6 + 2 * 2
    # at T_c the two pairs merge: a quadruple root (up to sqrt(eps) splitting)
    lam_c = linearize(model, res.thrust).eigenvalues()
    near = np.abs(np.abs(lam_c.imag) - res.omega) < 1e-5 * res.omega
    assert near.sum() == 8          # 4 roots and their conjugates
    # roll and surge stay put: their frequencies sqrt(K_ii / M_ii) are untouched by the thrust
    for dof in (0, 3):
        w = np.sqrt(model.elastic_stiffness[dof, dof] / model.mass_matrix[dof, dof])
        assert np.any(np.isclose(np.abs(lam0.imag), w, rtol=1e-9))
        assert np.any(np.isclose(np.abs(lam_c.imag), w, rtol=1e-9))
    assert set(res.modes) >= {"pitch", "yaw"}


def test_fixed_direction_thrust_is_conservative_and_diverges():
    d = ring_model_dict()
    d["thrust"]["tangency"] = 0.0
    d["thrust"]["point"] = [-0.4, 0.0, 0.0]     # a dead load behind A tips the body over
    d["analysis"]["thrust_max"] = 1e6
    model = model_from_dict(d)
    for t in (1000.0, 5000.0):
        k = linearize(model, t).K
        assert np.allclose(k, k.T, atol=1e-10 * np.abs(k).max())
    res = critical_thrust(model, linearization="classical")
    assert res.kind == "divergence" and res.omega == 0.0
    # independent: det K(T) = 0, from the generalized eigenvalues of (K0, -K1)
    k0 = linearize(model, 0.0, "classical").K
    k1 = linearize(model, 1e5, "classical").K - k0
    mu = sla.eigvals(k0, -k1 / 1e5)
    mu = np.sort(mu.real[(np.abs(mu.imag) < 1e-9) & (mu.real > 0)])
    assert res.thrust == pytest.approx(mu[0], rel=1e-10)


def test_damping_can_lower_the_critical_thrust(examples):
    model = impstab.load_model(examples / "imp_damped.toml")
    res = critical_thrust(model)
    assert res.kind == "flutter"
    assert res.undamped_thrust is not None and res.thrust < 0.95 * res.undamped_thrust
    # independent check of the damped value: brute-force eigenvalues just below and above
    below = linearize(model, res.thrust * (1 - 1e-7)).eigenvalues().real.max()
    above = linearize(model, res.thrust * (1 + 1e-7)).eigenvalues().real.max()
    assert below < 0 < above


def test_stable_up_to_thrust_max_reports_none():
    model = model_from_dict(ring_model_dict())
    res = critical_thrust(model, thrust_max=5000.0)
    assert res.thrust is None and res.kind == "none" and res.margin is None
    assert res.to_dict()["critical_thrust"] is None


@pytest.mark.parametrize("linearization", ["equilibrium", "classical"])
def test_asymmetric_onset_is_a_true_stability_boundary(linearization):
    model = model_from_dict(asymmetric_model_dict())
    res = critical_thrust(model, linearization=linearization)
    assert res.kind in ("flutter", "divergence")
    # independent: scipy eigenvalues of the state matrix on a fine grid below T_c are stable
    for t in np.linspace(0.0, res.thrust * (1 - 1e-6), 400):
        lam = sla.eigvals(linearize(model, t, linearization).state_matrix())
        assert lam.real.max() < 1e-9 * np.abs(lam).max()
    lam = sla.eigvals(linearize(model, res.thrust * (1 + 1e-6), linearization).state_matrix())
    assert lam.real.max() > 0


def test_json_keys_are_the_fixed_interface():
    res = critical_thrust(model_from_dict(ring_model_dict()))
    d = res.to_dict()
    for key in ("critical_thrust", "kind", "frequency_hz", "omega", "modes", "thrust_max", "operating_thrust",
                "margin", "undamped_critical_thrust", "linearization"):
        assert key in d
    assert d["kind"] in ("flutter", "divergence", "none")
