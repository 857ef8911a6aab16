"""Hopf analysis: l1 in Kuznetsov's normalisation against closed forms; the degenerate onsets."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from impstab.errors import ModelError
from impstab.postcritical import DynamicalSystem, hopf_analysis
from impstab.postcritical.derivatives import jacobians

from _pc_systems import bautin, rossler, rossler_equilibrium, with_mass_matrix


@pytest.mark.parametrize("p2", [0.7, -0.5, 1.3, -2.0])
def test_bautin_l1_is_2_p2_and_the_eigenvectors_are_normalised(p2):
    h = hopf_analysis(bautin(p2), [1e-3, 0.0], 0.05)
    assert abs(h.parameter) <= 1e-14
    assert h.omega == pytest.approx(1.0, abs=1e-14)
    assert h.lyapunov_coefficient == pytest.approx(2 * p2, rel=1e-11)
    assert h.lyapunov_error < 1e-9
    assert h.bifurcation == ("subcritical" if p2 > 0 else "supercritical")
    assert h.crossing_speed == pytest.approx(1.0, rel=1e-12)
    assert h.frequency_slope == pytest.approx(0.0, abs=1e-12)
    q, p = h.eigenvector, h.adjoint
    a = jacobians(bautin(p2), h.state[None], h.parameter)[0]
    assert np.vdot(q, q).real == pytest.approx(1.0, abs=1e-14)
    assert abs(np.vdot(p, q) - 1.0) <= 1e-14
    assert np.allclose(a @ q, 1j * h.omega * q, atol=1e-14)
    assert np.allclose(a.T @ p, -1j * h.omega * p, atol=1e-14)     # A^H p = -i omega p (A real)
    assert h.cycle_side == (-1 if p2 > 0 else 1)


def test_bautin_p2_zero_is_degenerate_not_a_number():
    h = hopf_analysis(bautin(0.0), [1e-3, 0.0], 0.05)
    assert h.bifurcation == "degenerate"
    assert h.lyapunov_coefficient is None
    assert h.reason.startswith("l1 = 0 to its accuracy")
    with pytest.raises(ModelError):
        h.normal_form_radius(0.01)


def test_frequency_does_not_enter_l1_but_enters_the_radius():
    """x' = w g(x): same cycles, l1 = 2 p2 for every w, rho^2 = -sigma' dp / Re(c1) with Re c1 = w l1."""
    p2, w = -0.5, 2.0
    h = hopf_analysis(bautin(p2, omega=w), [1e-3, 0.0], 0.05)
    assert h.omega == pytest.approx(w, rel=1e-14)
    assert h.lyapunov_coefficient == pytest.approx(2 * p2, rel=1e-11)
    assert h.crossing_speed == pytest.approx(w, rel=1e-12)
    for dp in (1e-3, 1e-4):
        r_exact = (p2 + np.sqrt(p2 ** 2 + 4 * dp)) / 2          # |x|^2 = 2 rho^2
        rho2 = float(h.normal_form_radius(dp)) ** 2
        assert 2 * rho2 == pytest.approx(r_exact, rel=10 * dp)
        assert h.predicted_period(dp) == pytest.approx(2 * np.pi / w, rel=1e-12)


def _gh_system(c):
    a1, a2, a3, a4, a5, b1, b2, b3, b4, b5 = c

    def f(x, p):
        x1, x2 = x[:, 0], x[:, 1]
        fx = a1 * x1 ** 2 + a2 * x1 * x2 + a3 * x2 ** 2 + a4 * x1 ** 3 + a5 * x1 * x2 ** 2
        gx = b1 * x1 ** 2 + b2 * x1 * x2 + b3 * x2 ** 2 + b4 * x1 ** 2 * x2 + b5 * x2 ** 3
        return np.stack([p * x1 - x2 + fx, x1 + p * x2 + gx], axis=-1)

    return DynamicalSystem(f, 2, vectorized=True)


def test_l1_against_the_guckenheimer_holmes_planar_formula():
    """x' = -y + f, y' = x + g: a = [f_xxx + f_xyy + g_xxy + g_yyy] / 16
    + [f_xy (f_xx + f_yy) - g_xy (g_xx + g_yy) - f_xx g_xx + f_yy g_yy] / 16; with |x| = |z| in GH's
    complex coordinate and q^H q = 1 in Kuznetsov's, l1 = 2 a / omega."""
    c = (0.7, -1.1, 0.4, -0.3, 0.25, -0.6, 0.9, 0.35, -0.45, 0.2)
    a1, a2, a3, a4, a5, b1, b2, b3, b4, b5 = c
    fxx, fxy, fyy, fxxx, fxyy = 2 * a1, a2, 2 * a3, 6 * a4, 2 * a5
    gxx, gxy, gyy, gxxy, gyyy = 2 * b1, b2, 2 * b3, 2 * b4, 6 * b5
    a = (fxxx + fxyy + gxxy + gyyy) / 16 + (fxy * (fxx + fyy) - gxy * (gxx + gyy) - fxx * gxx + fyy * gyy) / 16
    h = hopf_analysis(_gh_system(c), [0.0, 0.0], 0.02)
    assert abs(h.parameter) < 1e-14
    assert h.lyapunov_coefficient == pytest.approx(2 * a, rel=1e-10)
    assert h.lyapunov_error < 1e-10


def test_mass_matrix_gives_the_same_hopf_point():
    rng = np.random.default_rng(1)
    mass = np.eye(2) + 0.4 * rng.standard_normal((2, 2))
    plain = hopf_analysis(bautin(0.7), [1e-3, 0.0], 0.05)
    massed = hopf_analysis(with_mass_matrix(bautin(0.7), mass), [1e-3, 0.0], 0.05)
    assert massed.lyapunov_coefficient == pytest.approx(plain.lyapunov_coefficient, rel=1e-11)
    assert massed.crossing_speed == pytest.approx(plain.crossing_speed, rel=1e-12)
    assert massed.omega == pytest.approx(plain.omega, rel=1e-14)
    assert np.allclose(massed.eigenvector, plain.eigenvector, atol=1e-13)
    assert np.allclose(massed.adjoint, plain.adjoint, atol=1e-13)


def test_rossler_onset_against_routh_hurwitz():
    """Hopf of a cubic characteristic polynomial l^3 + c2 l^2 + c1 l + c0: c2 c1 = c0."""
    system = rossler()

    def hurwitz(a):
        c = np.poly(jacobians(system, rossler_equilibrium(a)[None], a)[0])
        return c[1] * c[2] - c[3]

    a_c = brentq(hurwitz, 0.1, 0.15, xtol=1e-15)
    h = hopf_analysis(system, rossler_equilibrium(0.12), 0.12)
    assert h.parameter == pytest.approx(a_c, abs=1e-13)
    hb = hopf_analysis(system, rossler_equilibrium(0.12), 0.12, bracket=(0.1, 0.15))
    assert hb.parameter == pytest.approx(a_c, abs=1e-13)
    assert hb.lyapunov_coefficient == pytest.approx(h.lyapunov_coefficient, rel=1e-9)
    assert h.bifurcation == "supercritical" and h.derivative_check["jacobian"] < 1e-8
    # the crossing speed against a central difference of the real part along the equilibria
    d = 1e-5

    def sigma(a):
        return np.max(np.linalg.eigvals(jacobians(system, rossler_equilibrium(a)[None], a)[0]).real)

    assert h.crossing_speed == pytest.approx((sigma(a_c + d) - sigma(a_c - d)) / (2 * d), rel=1e-8)


def test_divergence_onset_is_degenerate():
    def f(x, p):
        return np.stack([p * x[:, 0] - x[:, 0] ** 3 + 0.1 * x[:, 1], -x[:, 1]], axis=-1)

    h = hopf_analysis(DynamicalSystem(f, 2, vectorized=True), [0.0, 0.0], 0.05)
    assert h.onset == "divergence" and h.bifurcation == "degenerate"
    assert h.omega is None and h.lyapunov_coefficient is None
    assert h.reason.startswith("divergence")


def test_symmetric_double_pair_is_degenerate():
    """Two identical oscillators, coupled only through the cubic terms: i is a double, semisimple eigenvalue."""
    def f(x, p):
        z1 = x[:, 0] + 1j * x[:, 1]
        z2 = x[:, 2] + 1j * x[:, 3]
        s1 = x[:, 0] ** 2 + x[:, 1] ** 2
        s2 = x[:, 2] ** 2 + x[:, 3] ** 2
        # written without conj: the states stay complex-analytic
        d1 = (p * x[:, 0] - x[:, 1]) - (s1 + 2 * s2) * x[:, 0], (p * x[:, 1] + x[:, 0]) - (s1 + 2 * s2) * x[:, 1]
        d2 = (p * x[:, 2] - x[:, 3]) - (s2 + 2 * s1) * x[:, 2], (p * x[:, 3] + x[:, 2]) - (s2 + 2 * s1) * x[:, 3]
        del z1, z2
        return np.stack([d1[0], d1[1], d2[0], d2[1]], axis=-1)

    h = hopf_analysis(DynamicalSystem(f, 4, vectorized=True), np.zeros(4), 0.02)
    assert abs(h.parameter) < 1e-13
    assert h.bifurcation == "degenerate" and h.multiplicity == 2
    assert h.reason.startswith("double Hopf / symmetric")
    assert h.lyapunov_coefficient is None


def _ziegler(damping: float):
    """Ziegler's pendulum (m = l = c = 1) with a hardening spring at the lower hinge; parameter P.
    Undamped flutter at P = 7/2 - sqrt(2) (THEORY 10)."""
    mass = np.array([[3.0, 1.0], [1.0, 1.0]])
    minv = np.linalg.inv(mass)

    def f(x, p):
        q, v = x[:, :2], x[:, 2:]
        k = np.array([[2.0, -1.0], [-1.0, 1.0]]) - p * np.array([[1.0, -1.0], [0.0, 0.0]])
        force = -(q @ k.T) - damping * (v @ np.array([[2.0, -1.0], [-1.0, 1.0]]).T)
        force = force - np.stack([0.5 * q[:, 0] ** 3, 0 * q[:, 0]], axis=-1)
        return np.concatenate([v, force @ minv.T], axis=-1)

    return DynamicalSystem(f, 4, vectorized=True, parameter_name="P")


def test_undamped_collision_is_a_reversible_1_to_1_resonance():
    p_c = 3.5 - np.sqrt(2.0)
    h = hopf_analysis(_ziegler(0.0), np.zeros(4), p_c, refine=False)
    assert h.bifurcation == "degenerate" and h.lyapunov_coefficient is None
    assert h.reason.startswith("collision on the imaginary axis (undamped")
    assert h.omega == pytest.approx(2 ** -0.25, rel=1e-6)


def test_undamped_pair_below_the_collision_stays_on_the_axis():
    h = hopf_analysis(_ziegler(0.0), np.zeros(4), 1.0)
    assert h.bifurcation == "degenerate"
    assert h.reason.startswith("reversible / undamped")


def test_damped_follower_system_is_a_plain_hopf_point():
    """With equal dashpots the onset is a simple crossing at Ziegler's p_cr = 41/28 + b^2/2 (THEORY 10)."""
    b = 0.02
    h = hopf_analysis(_ziegler(b), np.zeros(4), 1.47)
    assert h.parameter == pytest.approx(41 / 28 + b ** 2 / 2, rel=1e-12)
    assert h.bifurcation in ("supercritical", "subcritical") and h.reason is None
    assert h.lyapunov_error < 1e-6 * abs(h.lyapunov_coefficient)


def test_bad_inputs():
    with pytest.raises(ModelError, match="p0"):
        hopf_analysis(bautin(0.5), [0.0, 0.0], float("nan"))
    with pytest.raises(ModelError, match="bracket"):
        hopf_analysis(bautin(0.5), [0.0, 0.0], 0.1, bracket=(0.1, 0.2))
    with pytest.raises(ModelError, match="bracket"):
        hopf_analysis(bautin(0.5), [0.0, 0.0], 0.1, bracket=(0.2, -0.1))


def test_real_parameter_only_falls_back_to_central_differences():
    base = bautin(0.7)

    def f(x, p):
        if isinstance(p, complex) or np.iscomplexobj(p):
            raise TypeError("real parameter only")
        return base.rhs(x, p)

    system = DynamicalSystem(f, 2, vectorized=True, complex_parameter=False)
    h = hopf_analysis(system, [1e-3, 0.0], 0.05)
    assert h.parameter_derivative_method == "central-difference-4"
    assert h.crossing_speed == pytest.approx(1.0, rel=1e-9)
    assert h.lyapunov_coefficient == pytest.approx(1.4, rel=1e-11)


def test_analytic_derivatives_give_the_same_coefficient():
    """The Bautin system's derivatives at the origin by hand: B = 0 and, from the cubic p2 x (x.x),
    C(u, v, w) = 2 p2 [u (v.w) + v (w.u) + w (u.v)] (the terms r^2 x are of fifth order)."""
    p2 = -0.5
    base = bautin(p2)

    def third(x, p, u, v, w):
        def sym(a, b, c):
            return a * (b[0] * c[0] + b[1] * c[1])
        return 2 * p2 * (sym(u, v, w) + sym(v, w, u) + sym(w, u, v))

    system = DynamicalSystem(lambda x, p: base.rhs(x[None], p)[0], 2,
                             second_derivative=lambda x, p, u, v: np.zeros(2, dtype=complex),
                             third_derivative=third)
    h = hopf_analysis(system, [0.0, 0.0], 0.05)
    assert h.derivative_method == "analytic"
    assert h.lyapunov_coefficient == pytest.approx(2 * p2, rel=1e-12)


def test_nearly_symmetric_pair_is_a_hopf_point_with_a_warning():
    """Two oscillators 1e-5 apart in frequency: a simple crossing, but the neighbour is named."""
    def f(x, p):
        s1 = x[:, 0] ** 2 + x[:, 1] ** 2
        s2 = x[:, 2] ** 2 + x[:, 3] ** 2
        w2 = 1.0 + 1e-5
        return np.stack([p * x[:, 0] - x[:, 1] - (s1 + 2 * s2) * x[:, 0], p * x[:, 1] + x[:, 0] - (s1 + 2 * s2) * x[:, 1],
                         (p - 1e-5) * x[:, 2] - w2 * x[:, 3] - (s2 + 2 * s1) * x[:, 2],
                         (p - 1e-5) * x[:, 3] + w2 * x[:, 2] - (s2 + 2 * s1) * x[:, 3]], axis=-1)

    h = hopf_analysis(DynamicalSystem(f, 4, vectorized=True), np.zeros(4), 0.001)
    assert h.bifurcation == "supercritical" and h.lyapunov_coefficient == pytest.approx(-2.0, rel=1e-10)
    assert any("near neighbour" in w for w in h.warnings)
