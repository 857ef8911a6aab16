"""Exact derivatives: complex-step Jacobians and Cauchy-circle forms against analytic ones."""

from __future__ import annotations

import numpy as np
import pytest

from impstab.errors import ModelError
from impstab.postcritical import DynamicalSystem, Forms, check_derivatives, jacobians


def _f(x, p):
    x0, x1, x2 = x[:, 0], x[:, 1], x[:, 2]
    return np.stack([np.sin(x0) * x1 ** 2 + p * x2, np.exp(x0 * x2) - p ** 2 * x1, x1 ** 3 + x0 * x1 * x2], axis=-1)


def _jac(x, p):
    x0, x1, x2 = x
    e = np.exp(x0 * x2)
    return np.array([[np.cos(x0) * x1 ** 2, 2 * np.sin(x0) * x1, p],
                     [x2 * e, -p ** 2, x0 * e],
                     [x1 * x2, 3 * x1 ** 2 + x0 * x2, x0 * x1]])


def _hessians(x):
    """H[i] = d2 f_i / dx dx (3 x 3)."""
    x0, x1, x2 = x
    e = np.exp(x0 * x2)
    h0 = np.array([[-np.sin(x0) * x1 ** 2, 2 * np.cos(x0) * x1, 0], [2 * np.cos(x0) * x1, 2 * np.sin(x0), 0], [0, 0, 0]])
    h1 = np.array([[x2 ** 2 * e, 0, e + x0 * x2 * e], [0, 0, 0], [e + x0 * x2 * e, 0, x0 ** 2 * e]])
    h2 = np.array([[0, x2, x1], [x2, 6 * x1, x0], [x1, x0, 0]])
    return np.array([h0, h1, h2])


def _third(x, u, v, w):
    """Analytic C(u, v, w) of _f."""
    x0, x1, x2 = x
    e = np.exp(x0 * x2)
    t = np.zeros((3, 3, 3, 3))
    # f0 = sin(x0) x1^2
    t[0, 0, 0, 0] = -np.cos(x0) * x1 ** 2
    for idx in ((0, 0, 1), (0, 1, 0), (1, 0, 0)):
        t[(0,) + idx] = -2 * np.sin(x0) * x1
    for idx in ((0, 1, 1), (1, 0, 1), (1, 1, 0)):
        t[(0,) + idx] = 2 * np.cos(x0)
    # f1 = exp(x0 x2)
    t[1, 0, 0, 0] = x2 ** 3 * e
    t[1, 2, 2, 2] = x0 ** 3 * e
    for idx in ((0, 0, 2), (0, 2, 0), (2, 0, 0)):
        t[(1,) + idx] = 2 * x2 * e + x0 * x2 ** 2 * e
    for idx in ((0, 2, 2), (2, 0, 2), (2, 2, 0)):
        t[(1,) + idx] = 2 * x0 * e + x0 ** 2 * x2 * e
    # f2 = x1^3 + x0 x1 x2
    t[2, 1, 1, 1] = 6.0
    for idx in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
        t[(2,) + idx] = 1.0
    return np.einsum("iabc,a,b,c->i", t, u, v, w)


SYSTEM = DynamicalSystem(_f, 3, vectorized=True)
X0 = np.array([0.3, -0.7, 0.45])
P0 = 1.3
RNG = np.random.default_rng(4)
U, V, W = (RNG.standard_normal(3) + 1j * RNG.standard_normal(3) for _ in range(3))


def test_complex_step_jacobian_is_exact_to_rounding():
    pts = np.array([X0, -X0, 2 * X0])
    jac = jacobians(SYSTEM, pts, P0)
    for k in range(3):
        ref = _jac(pts[k], P0)
        assert np.max(np.abs(jac[k] - ref)) <= 4e-16 * np.max(np.abs(ref))


def test_cauchy_second_form_against_hessians_with_its_error_bound():
    forms = Forms(SYSTEM, X0, P0)
    val = forms.second(U, V)
    ref = np.einsum("iab,a,b->i", _hessians(X0), U, V)
    err = np.max(np.abs(val.value - ref))
    assert err <= 1e-12 * np.max(np.abs(ref))
    assert err <= val.error          # the stated bound holds
    assert val.error <= 1e-10 * np.max(np.abs(ref))   # and is not vacuous


def test_cauchy_third_form_against_analytic_with_its_error_bound():
    forms = Forms(SYSTEM, X0, P0)
    val = forms.third(U, V, W)
    ref = _third(X0, U, V, W)
    err = np.max(np.abs(val.value - ref))
    assert err <= 1e-10 * np.max(np.abs(ref))
    assert err <= val.error
    assert val.error <= 1e-8 * np.max(np.abs(ref))


def test_forms_are_symmetric_and_multilinear():
    forms = Forms(SYSTEM, X0, P0)
    b1 = forms.second(U, V).value
    b2 = forms.second(V, U).value
    b3 = forms.second(2j * U, V).value
    assert np.allclose(b1, b2, rtol=1e-12, atol=1e-14)
    assert np.allclose(b3, 2j * b1, rtol=1e-12, atol=1e-14)
    c1 = forms.third(U, V, W).value
    c2 = forms.third(W, U, V).value
    assert np.allclose(c1, c2, rtol=1e-10, atol=1e-12)


def test_total_parameter_derivative_of_the_jacobian():
    """d/dp [J(x(p), p) u] = B(u, x_p) + dJ/dp u, here dJ/dp = [[0, 0, 1], [0, -2p, 0], [0, 0, 0]]."""
    forms = Forms(SYSTEM, X0, P0)
    x_p = np.array([0.2, -0.1, 0.4])
    val, method = forms.jacobian_total_derivative(U, x_p)
    dj = np.array([[0, 0, 1.0], [0, -2 * P0, 0], [0, 0, 0]])
    ref = np.einsum("iab,a,b->i", _hessians(X0), U, x_p) + dj @ U
    assert method == "Cauchy circle"
    assert np.max(np.abs(val - ref)) <= 1e-11 * np.max(np.abs(ref))


def test_single_state_callable_gives_the_same_derivatives():
    single = DynamicalSystem(lambda x, p: _f(x[None, :], p)[0], 3)
    a = Forms(single, X0, P0).third(U, V, W).value
    b = Forms(SYSTEM, X0, P0).third(U, V, W).value
    assert np.array_equal(a, b)
    assert np.array_equal(jacobians(single, X0[None], P0), jacobians(SYSTEM, X0[None], P0))


def test_analytic_hooks_replace_the_numerical_derivatives():
    calls = []

    def second(x, p, u, v):
        calls.append("B")
        return np.einsum("iab,a,b->i", _hessians(x), u, v)

    sys_a = DynamicalSystem(lambda x, p: _f(x[None, :], p)[0], 3, jacobian=_jac, second_derivative=second,
                            third_derivative=lambda x, p, u, v, w: _third(x, u, v, w))
    forms = Forms(sys_a, X0, P0)
    assert forms.method == "analytic"
    assert np.allclose(forms.second(U, V).value, Forms(SYSTEM, X0, P0).second(U, V).value, rtol=1e-12)
    assert calls == ["B"]
    assert np.array_equal(jacobians(sys_a, X0[None], P0)[0], _jac(X0, P0))


def test_derivative_check_passes_for_analytic_and_flags_abs():
    good = check_derivatives(SYSTEM, X0, P0)
    assert good["jacobian"] < 1e-8 and good["second"] < 1e-9 and good["third"] < 1e-8
    bad = DynamicalSystem(lambda x, p: np.stack([np.abs(x[:, 0]) * x[:, 1], x[:, 0]], axis=-1), 2, vectorized=True)
    # |x| has no complex extension: the complex step sees d|x0|/dx0 = 0 instead of sign(x0)
    assert check_derivatives(bad, np.array([0.5, 1.0]), 0.0)["jacobian"] > 0.1


def test_bad_systems_are_rejected_with_one_line():
    with pytest.raises(ModelError, match="dimension"):
        DynamicalSystem(_f, 0)
    with pytest.raises(ModelError, match="mass_matrix"):
        DynamicalSystem(_f, 3, mass_matrix=np.zeros((3, 3)))
    with pytest.raises(ModelError, match="mass_matrix"):
        DynamicalSystem(_f, 3, mass_matrix=np.eye(2))
    with pytest.raises(ModelError, match="state_scale"):
        DynamicalSystem(_f, 3, state_scale=[1.0, -1.0, 1.0])
    wrong = DynamicalSystem(lambda x, p: x[:, :2], 3, vectorized=True)
    with pytest.raises(ModelError, match="rhs"):
        jacobians(wrong, X0[None], P0)


def _contact(x, p):
    """A smooth law plus a cubic contact force engaging at x0 = 0.5 (a seam: C2, not analytic)."""
    gap = x[:, 0] - 0.5
    contact = np.where(gap.real > 0.0, 1e3 * gap ** 3, 0.0 * gap)
    return np.stack([np.sin(x[:, 0]) * x[:, 1] - contact, x[:, 0] ** 2 * x[:, 1]], axis=-1)


def test_circles_stay_inside_the_piece_of_a_piecewise_law():
    # at x0 = 0.45, 0.05 from the seam, a circle of radius 1 crosses it: the forms it gives are not
    # the derivatives of the free piece; the region codes shrink it until the disc stays free
    x = np.array([0.45, 0.8])
    u, v, w = np.array([1.0, 0.3]), np.array([0.2, -1.0]), np.array([0.7, 0.5])
    # free piece: f0 = sin(x0) x1, f1 = x0^2 x1; C(u, v, w) by hand
    x0, x1 = x
    c0 = -np.cos(x0) * x1 * u[0] * v[0] * w[0] - np.sin(x0) * (u[0] * v[0] * w[1] + u[0] * v[1] * w[0] + u[1] * v[0] * w[0])
    c1 = 2 * (u[0] * v[0] * w[1] + u[0] * v[1] * w[0] + u[1] * v[0] * w[0])
    exact = np.array([c0, c1])
    blind = Forms(DynamicalSystem(_contact, 2, vectorized=True), x, 0.0, radius=1.0, points=32)
    assert np.max(np.abs(blind.third(u, v, w).value - exact)) > 1.0          # wrong: the circle crossed the seam
    aware = Forms(DynamicalSystem(_contact, 2, vectorized=True,
                                  region=lambda s: (np.asarray(s)[:, 0].real > 0.5).astype(int)), x, 0.0,
                  radius=1.0, points=32)
    got = aware.third(u, v, w)
    assert np.max(np.abs(got.value - exact)) <= got.error < 1e-8
    assert aware.smallest_radius < 0.05 / 1.5                                 # the disc ends before the seam


def test_a_point_on_a_seam_is_reported():
    on_seam = DynamicalSystem(_contact, 2, vectorized=True, region=lambda s: (np.asarray(s)[:, 0].real > 0.5).astype(int))
    from impstab.errors import NumericalError

    with pytest.raises(NumericalError, match="seam"):
        Forms(on_seam, np.array([0.5, 0.8]), 0.0).third(np.array([1.0, 0.0]), np.array([1.0, 0.0]), np.array([1.0, 0.0]))
