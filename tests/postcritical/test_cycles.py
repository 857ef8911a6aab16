"""Single periodic orbits: collocation, published cycles, Floquet multipliers in closed form."""

from __future__ import annotations

import numpy as np
import pytest

from impstab.postcritical import Profile, continue_cycles, find_cycle
from impstab.postcritical.collocation import node_weights, scheme
from impstab.postcritical.mesh import equidistribute

from _pc_systems import (VDP_MAX_X, VDP_PERIOD, bautin, bautin_multiplier, bautin_radius, clock_guess,
                         clock_twist, van_der_pol)


@pytest.mark.parametrize("m", [2, 3, 4, 5, 7])
def test_scheme_integrates_and_interpolates_polynomials_exactly(m):
    sch = scheme(m)
    for k in range(m + 1):
        assert sch.weights @ sch.nodes ** k == pytest.approx(1 / (k + 1), rel=1e-12)
        assert sch.value @ sch.nodes ** k == pytest.approx(sch.points ** k, abs=1e-12)
        assert sch.derivative @ sch.nodes ** k == pytest.approx(k * sch.points ** max(k - 1, 0) if k else 0 * sch.points,
                                                               abs=1e-11)
    # Gauss-Legendre points of degree m: the Legendre polynomial P_m vanishes there
    assert np.allclose(np.polynomial.legendre.legval(2 * sch.points - 1, [0] * m + [1]), 0, atol=1e-12)


def test_profile_extrema_mean_and_quadrature():
    prof = Profile.uniform(lambda t: np.stack([np.cos(2 * np.pi * t + 0.3), 2 + np.sin(4 * np.pi * t) ** 2], -1), 40, 4)
    lo, hi = prof.extrema()
    assert lo == pytest.approx([-1.0, 2.0], abs=1e-8)
    assert hi == pytest.approx([1.0, 3.0], abs=1e-8)
    assert prof.mean() == pytest.approx([0.0, 2.5], abs=1e-9)
    assert node_weights(prof.mesh, prof.scheme).sum() == pytest.approx(1.0, abs=1e-14)
    # the extrema are those of the piecewise polynomial itself: no sample exceeds them
    x = prof(np.linspace(0, 1, 200001))
    assert np.all(x.max(axis=0) <= hi + 1e-14) and np.all(x.min(axis=0) >= lo - 1e-14)


def test_equidistribution_puts_intervals_where_the_profile_is_steep():
    prof = Profile.uniform(lambda t: np.tanh(30 * np.sin(2 * np.pi * t))[:, None], 40, 4)
    mesh = equidistribute(prof, np.ones(1))
    h = np.diff(mesh)
    steep = (np.abs(mesh[:-1] - 0.5) < 0.05) | (mesh[:-1] < 0.05) | (mesh[:-1] > 0.95)
    assert mesh[0] == 0.0 and mesh[-1] == 1.0 and np.all(h > 0)
    assert h[steep].mean() < 0.5 * h[~steep].mean()


@pytest.fixture(scope="module")
def vdp_cycle():
    guess = lambda t: np.stack([2 * np.cos(2 * np.pi * t), -2 * np.sin(2 * np.pi * t)], -1)  # noqa: E731
    return find_cycle(van_der_pol(), guess, 2 * np.pi, 1.0, intervals=40)


def test_van_der_pol_period_and_amplitude(vdp_cycle):
    c = vdp_cycle
    assert c.period == pytest.approx(VDP_PERIOD, abs=1e-8)
    assert c.maximum[0] == pytest.approx(VDP_MAX_X, abs=1e-8)
    assert c.amplitude[0] == pytest.approx(VDP_MAX_X, abs=1e-8)      # symmetric cycle
    assert c.mesh_error < 1e-6
    assert c.stable


def test_van_der_pol_multipliers_against_liouville(vdp_cycle):
    """Product of the multipliers = exp(int_0^T trace J dt) = exp(int mu (1 - x^2) dt)."""
    c = vdp_cycle
    nodes = c.profile.nodes
    integral = c.period * node_weights(c.profile.mesh, c.profile.scheme) @ (1.0 - nodes[:, 0] ** 2)
    mu = c.nontrivial_multipliers
    assert mu.size == 1 and abs(mu[0].imag) == 0
    assert mu[0].real == pytest.approx(np.exp(integral), rel=1e-7)
    assert c.trivial_error < 1e-9


def test_single_state_callable_finds_the_same_cycle(vdp_cycle):
    guess = lambda t: np.stack([2 * np.cos(2 * np.pi * t), -2 * np.sin(2 * np.pi * t)], -1)  # noqa: E731
    c = find_cycle(van_der_pol(vectorized=False), guess, 2 * np.pi, 1.0, intervals=40)
    assert c.period == pytest.approx(vdp_cycle.period, rel=1e-12)


def test_cycle_from_time_samples(vdp_cycle):
    """A guess given as samples equally spaced in time (as from a simulation)."""
    t, x = vdp_cycle.sample(65)
    shifted = np.roll(x[:-1], 17, axis=0) * 1.02
    c = find_cycle(van_der_pol(), shifted, 6.6, 1.0, intervals=40)
    assert c.period == pytest.approx(VDP_PERIOD, abs=1e-8)


def test_planar_multipliers_in_closed_form_with_a_strongly_damped_extra_direction():
    """Cycle r = (p2 + sqrt(p2^2 + 4 p1))/2 of x' = x g - y ..., and x3' = -k x3 decoupled:
    multipliers exp(2 pi 2 r (p2 - 2 r)) and exp(-2 pi k) (1.2e-11 here: relative accuracy kept)."""
    p1, p2, k = 0.2, -0.5, 4.0
    system = bautin(p2, extra=k)
    rad = np.sqrt(bautin_radius(p1, p2, 1))
    guess = lambda t: np.stack([rad * np.cos(2 * np.pi * t), rad * np.sin(2 * np.pi * t), 0 * t], -1)  # noqa: E731
    c = find_cycle(system, guess, 6.0, p1, intervals=20)
    nt = np.sort(c.nontrivial_multipliers.real)
    assert nt[0] == pytest.approx(np.exp(-2 * np.pi * k), rel=1e-6)
    assert nt[1] == pytest.approx(bautin_multiplier(p1, p2, 1), rel=1e-9)
    assert c.trivial_error < 1e-10
    assert c.period == pytest.approx(2 * np.pi, rel=1e-10)


@pytest.mark.parametrize("kind", ["period-doubling", "torus"])
def test_period_doubling_and_torus_at_their_exact_location(kind):
    system = clock_twist(kind)
    start = find_cycle(system, clock_guess, 2 * np.pi, -0.3, intervals=20)
    # multipliers at a = -0.3 in closed form
    t = 2 * np.pi
    expect = {"period-doubling": [-np.exp(-0.3 * t), -np.exp(-t)],
              "torus": [np.exp(-0.3 * t + 0.37j * t), np.exp(-0.3 * t - 0.37j * t)]}[kind]
    got = start.nontrivial_multipliers
    for e in expect + [np.exp(-2 * t)]:
        assert np.min(np.abs(got - e)) <= 1e-9 * max(abs(e), 1e-3)
    br = continue_cycles(system, start, 0.3, ds=0.05, ds_max=0.2, intervals=20)
    found = [s for s in br.special_points if s.kind == kind]
    assert len(found) == 1 and len(br.special_points) == 1
    sp = found[0]
    assert abs(sp.parameter) < 1e-10
    if kind == "period-doubling":
        assert abs(sp.multiplier + 1) < 1e-9
    else:
        assert abs(abs(sp.multiplier) - 1) < 1e-9
        assert abs(np.angle(sp.multiplier)) == pytest.approx(0.37 * t, rel=1e-9)
    # stable before, unstable after
    assert all(c.stable for c in br.cycles if c.parameter < -1e-6)
    assert not any(c.stable for c in br.cycles if c.parameter > 1e-6)
    assert max(br.trivial_error) < 1e-10


def test_condensed_newton_step_equals_the_full_sparse_solve(vdp_cycle):
    """Condensation of parameters against SuperLU on the whole bordered Jacobian (random right side)."""
    import scipy.sparse.linalg as spla

    from impstab.postcritical.condensed import Condensation
    from impstab.postcritical.periodic import OrbitProblem, Weights

    prof = vdp_cycle.profile
    prob = OrbitProblem(van_der_pol(), prof.mesh, prof.degree, Weights(np.ones(2), 6.0, 1.0))
    u = prob.pack(prof, vdp_cycle.period * 1.01, 1.05)
    res, blocks, col_t, col_p = prob.evaluate(u)
    rng = np.random.default_rng(3)
    phase = prob.phase_row(prof)
    last = rng.standard_normal(prob.size)
    rhs = rng.standard_normal(prob.size)
    full = spla.spsolve(prob.matrix(blocks, col_t, col_p, phase, last), rhs)
    cond = Condensation(blocks, col_t, col_p).solve(rhs[:-2], np.stack([np.concatenate([phase, [0, 0]]), last]), rhs[-2:])
    assert np.max(np.abs(cond - full)) <= 1e-10 * np.max(np.abs(full))
