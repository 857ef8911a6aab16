"""Building blocks of the fluid model: quadrature rule, windows, modal impedance."""

import numpy as np
import pytest
from scipy import special

import impstab.fluid as fl
from impstab.fluid.integrals import window_integrals
from impstab.fluid.impedance import evanescent_ratio, incompressible_kernel, modal_impedance, radiating_ratio
from impstab.fluid.quadrature import PanelRule, graded_edges, split_long
from impstab.fluid.windows import window_parts, window_squared


def test_kronrod_and_gauss_degrees():
    rule = PanelRule.from_edges(np.array([-1.0, 0.5, 2.0]))
    for degree in range(32):
        exact = (2.0 ** (degree + 1) - (-1.0) ** (degree + 1)) / (degree + 1)
        k = np.sum(rule.x**degree * rule.wk)
        g = np.sum(rule.x**degree * rule.wg)
        assert k == pytest.approx(exact, rel=1e-13, abs=1e-13)
        if degree < 20:
            assert g == pytest.approx(exact, rel=1e-13, abs=1e-13)
    total, err_re, err_im = rule.integrate(np.exp(rule.x) * (1 + 1j))
    assert total == pytest.approx((np.e**2 - np.exp(-1)) * (1 + 1j), rel=1e-14)
    assert err_re < 1e-12 and err_im < 1e-12


def test_panel_layouts():
    e = graded_edges(2.0, 0.3, 1e-6)
    assert e[0] == 0.0 and e[-1] == 2.0 and e[1] <= 1e-6 and np.all(np.diff(e) > 0)
    assert np.allclose(e[2:] / e[1:-1], 1 / 0.3)
    s = split_long(np.array([0.0, 0.1, 1.0]), 0.25)
    assert np.all(np.diff(s) <= 0.25 + 1e-15) and s[-1] == 1.0 and 0.1 in s


def test_windows_match_spherical_bessel_and_g_formula():
    x = np.concatenate([np.geomspace(1e-6, 1, 50), np.linspace(1, 60, 300)])
    for order in (0, 1):
        ref = special.spherical_jn(order, x) ** 2
        assert np.allclose(window_squared(x, order), ref, rtol=1e-13, atol=1e-300)
        big = x[x > 1.5]
        n, c = window_parts(big.astype(complex), order)
        recon = (n + 2 * (c * np.exp(2j * big)).real).real
        assert np.allclose(recon, special.spherical_jn(order, big) ** 2, rtol=1e-10, atol=1e-15)
    # |G|^2 of THEORY 9 equals (L^4 / 4) j1(kL/2)^2, and (L^3/12)^2 k^2 for small k
    L = 0.8
    k = np.linspace(0.5, 40, 7)
    g2 = 4 * (np.sin(k * L / 2) / k**2 - (L / 2) * np.cos(k * L / 2) / k) ** 2
    assert np.allclose(L**4 / 4 * window_squared(k * L / 2, 1), g2, rtol=1e-12)
    k = 1e-5
    assert L**4 / 4 * window_squared(np.array([k * L / 2]), 1)[0] == pytest.approx((L**3 / 12) ** 2 * k**2, rel=1e-9)


def test_incompressible_kernel_limits():
    a = 0.15
    assert incompressible_kernel(0.0, a) == pytest.approx(a, rel=1e-15)
    # small ka: g/a = 1 + s^2 (log(s/2) + Euler gamma) + O(s^4 log^2 s)
    s = 1e-4
    assert incompressible_kernel(s / a, a) / a == pytest.approx(1 + s**2 * (np.log(s / 2) + np.euler_gamma), abs=1e-13)
    # large ka, from the Hankel expansions of K0 and K1: g = 1/k - 1/(2 a k^2) - 1/(8 a^2 k^3) + O(k^-4)
    k = np.array([200.0, 400.0]) / a
    asym = 1 / k - 1 / (2 * a * k**2) - 1 / (8 * a**2 * k**3)
    assert np.allclose(incompressible_kernel(k, a), asym, rtol=5e-8)
    # the definition with unscaled Bessel functions
    k = np.linspace(0.1, 30, 40)
    s = k * a
    direct = special.k1(s) / (k * (special.k0(s) + special.k1(s) / s))
    assert np.allclose(incompressible_kernel(k, a), direct, rtol=1e-13)


def test_radiating_ratio_against_hankel_definition_and_wronskian():
    x = np.geomspace(1e-2, 50, 200)
    direct = -special.hankel2(1, x) / (x * special.h2vp(1, x))
    r = radiating_ratio(x)
    assert np.allclose(r, direct, rtol=1e-12)
    # Im r = -(2/pi) / (x^2 (J1'^2 + Y1'^2)) exactly (Wronskian); accurate even where Re r dominates
    im = -(2 / np.pi) / (x**2 * (special.jvp(1, x) ** 2 + special.yvp(1, x) ** 2))
    assert np.allclose(r.imag, im, rtol=1e-13)
    assert np.all(r.imag < 0) and np.all(r.real > 0)
    tiny = radiating_ratio(np.array([1e-8, 1e-150]))
    assert np.allclose(tiny.real, 1.0) and np.allclose(tiny.imag, -np.pi / 2 * np.array([1e-16, 1e-300]), rtol=1e-6)


def test_analytic_continuation_below_the_branch_point():
    # gamma = +i k_r below k0 (outgoing waves, e^{i omega t}): K1(i x) = -(pi/2) H1(2)(x)
    x = np.linspace(0.05, 20, 60)
    assert np.allclose(evanescent_ratio(1j * x), radiating_ratio(x), rtol=1e-11)


@pytest.mark.parametrize("k0a", [0.01, 0.7, 5.0])
def test_modal_impedance_continuous_at_k0(k0a):
    a, rho, c = 0.15, 1025.0, 1500.0
    omega = k0a * c / a
    k0 = omega / c
    at = 1j * omega * rho * a  # r = 1 at gamma = 0 from both sides
    for delta in (1e-6, 1e-9, 1e-12):
        below, above = modal_impedance(k0 * np.array([1 - delta, 1 + delta]), a, rho, c, omega)
        bound = 10 * (k0a**2 + 1) * delta * abs(np.log(delta)) * abs(at)
        assert abs(below - at) < bound and abs(above - at) < bound
    z = modal_impedance(np.linspace(0, 3 * k0, 301), a, rho, c, omega)
    assert np.all(z.real >= 0) and np.all(z.imag > 0)
    assert np.all(z[np.linspace(0, 3 * k0, 301) > k0].real == 0)


@pytest.mark.parametrize("ell,s0", [(1e-7, 0.0), (1e-3, 0.5), (2.67, 0.0), (2.67, 1.0), (100.0, 0.0), (2.67, 300.0),
                                    (1e3, 0.0), (10.0, 10.0)])
@pytest.mark.parametrize("refine", [1, 2, 4])
def test_node_estimate_bounds_the_layout(ell, s0, refine):
    """The O(1) estimate used to refuse work is an upper bound of the nodes the layout really has,
    and a tight one (within 20 %)."""
    from impstab.fluid.integrals import estimate_nodes

    actual = window_integrals(ell, s0, refine).nodes
    assert actual <= estimate_nodes(ell, s0, refine) <= 1.2 * actual


def test_too_much_quadrature_is_refused_before_it_starts():
    from impstab.errors import ModelError

    with pytest.raises(ModelError, match="^length = 1000.0: .*quadrature nodes"):
        fl.baffled_cylinder(radius=1e-4, length=1000.0)
    with pytest.raises(ModelError, match="^frequency = 1000000.0: the segment is .* wavelengths long"):
        fl.baffled_cylinder(radius=1.0, length=1000.0, sound_speed=1.0, frequency=1e6)
    # just inside the limit it runs
    assert fl.quadrature_nodes(0.15, 0.8, 1500.0, 1e6) <= 1_000_000
    assert fl.baffled_cylinder(radius=0.15, length=0.8, sound_speed=1500.0, frequency=1e6).added_mass > 0
