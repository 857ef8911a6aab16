"""Stability with viscoelastic mounts: the augmented first-order system against independent answers."""

import numpy as np
import pytest
import scipy.linalg
from conftest import ring_model_dict
from scipy.optimize import brentq, fsolve

import impstab
from impstab.model import model_from_dict
from impstab.linear.viscoelastic import ViscoelasticFamily, exact_onset

SLS = {"law": "standard-linear-solid", "stiffening": 1.5, "relaxation_time": 2e-3}


def _unmatched(e, a, er, ar) -> list:
    """The eigenvalues of the full pencil ``(A, E)`` left after each of the reduced one's took its
    nearest (each to 1e-8 relative)."""
    lam = list(np.linalg.eigvals(np.linalg.solve(e, a)))
    for r in np.linalg.eigvals(np.linalg.solve(er, ar)):
        j = int(np.argmin(np.abs(np.array(lam) - r)))
        assert abs(lam[j] - r) <= 1e-8 * max(abs(r), 1.0)
        lam.pop(j)
    return lam


def _model(visco=SLS, **analysis):
    d = ring_model_dict()
    d["mount_rings"][0]["viscoelastic"] = dict(visco)
    d["analysis"].update(analysis)
    return model_from_dict(d)


def _hurwitz_minors(coeffs_high_first):
    """Leading principal minors of the Hurwitz matrix of sum c_i lambda^(n-i) (c_0 leading)."""
    c = np.asarray(coeffs_high_first, dtype=float)
    n = c.size - 1
    h = np.zeros((n, n))
    for i in range(n):
        for j in range(n):
            k = 2 * j - i + 1
            if 0 <= k <= n:
                h[i, j] = c[k]
    return np.array([np.linalg.det(h[:m, :m]) for m in range(1, n + 1)])


def _ziegler_sls_polynomial(p, g, tau):
    """det Y(lambda), Y = (1 + lambda tau) lambda^2 M + (1 + s lambda tau) Kc + (1 + lambda tau) p K1,
    Ziegler's pendulum (m = l = c = 1) with standard-linear-solid springs; coefficients, highest first.

    Y = (1 + lambda tau) F(lambda) with F = lambda^2 M + r(lambda) Kc + p K1, r = (1 + s lambda tau)/(1 + lambda tau),
    so det Y = (1 + lambda tau)^2 det F, and det Y(-1/tau) = (1 - s)^2 det Kc != 0: the zeros are those of det F.
    """
    P = np.polynomial.polynomial
    s = 1.0 + g
    M = np.array([[3.0, 1.0], [1.0, 1.0]])
    Kc = np.array([[2.0, -1.0], [-1.0, 1.0]])
    K1 = np.array([[-1.0, 1.0], [0.0, 0.0]])
    y = [[P.polyadd(P.polyadd(P.polymul([1.0, tau], [0.0, 0.0, M[i, j]]), [Kc[i, j], s * tau * Kc[i, j]]),
                    P.polymul([1.0, tau], [p * K1[i, j]])) for j in range(2)] for i in range(2)]
    det = P.polysub(P.polymul(y[0][0], y[1][1]), P.polymul(y[0][1], y[1][0]))
    return det[::-1]


def test_ziegler_pendulum_with_sls_springs_against_routh_hurwitz():
    """Ziegler's double pendulum (m1 = 2m, m2 = m, l, joint springs c, follower load p; m = l = c = 1)
    with standard-linear-solid springs (weight g, relaxation time tau). Closed form: the
    characteristic polynomial det Y(lambda) (degree 6, see _ziegler_sls_polynomial) is Hurwitz
    (all Hurwitz minors Delta_1..Delta_6 > 0) below the critical load, and flutter sets in where
    Delta_5(p) = 0 (Routh-Hurwitz: a pair crosses the imaginary axis). The engine solves the
    augmented first-order system x = (theta, theta', z): M theta'' + (1 + g) Kc theta + p K1 theta
    - g B^T z = 0, tau z' = B theta - z, B = [[1, 0], [-1, 1]] (relative joint angles)."""
    g, tau = 0.5, 0.1
    minors = lambda p: _hurwitz_minors(_ziegler_sls_polynomial(p, g, tau))  # noqa: E731
    stable = lambda p: bool(np.all(minors(p) > 0) and np.all(_ziegler_sls_polynomial(p, g, tau) > 0))  # noqa: E731
    grid = np.linspace(0.0, 5.0, 501)
    first = next(i for i, p in enumerate(grid) if not stable(p))
    p_rh = brentq(lambda p: minors(p)[4], grid[first - 1], grid[first], xtol=1e-14, rtol=1e-15)

    M = np.array([[3.0, 1.0], [1.0, 1.0]])
    Kc = np.array([[2.0, -1.0], [-1.0, 1.0]])
    K1 = np.array([[-1.0, 1.0], [0.0, 0.0]])
    B = np.array([[1.0, 0.0], [-1.0, 1.0]])
    E = np.eye(6)
    E[2:4, 2:4] = M
    A0 = np.zeros((6, 6))
    A0[:2, 2:4] = np.eye(2)
    A0[2:4, :2] = -(1 + g) * Kc
    A0[2:4, 4:] = g * B.T
    A0[4:, :2] = B / tau
    A0[4:, 4:] = -np.eye(2) / tau
    A1 = np.zeros((6, 6))
    A1[2:4, :2] = -K1
    res = impstab.critical_load(A0=A0, A1=A1, E=E, p_max=5.0)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(p_rh, rel=1e-9)
    # the viscoelastic springs move the load away from the elastic 7/2 - sqrt(2)
    assert abs(p_rh - (3.5 - np.sqrt(2))) > 1e-3


def _poly_roots(lin, kv, g, tau):
    """Roots of det((lambda^2 M + lambda C + K)(1 + lambda tau) + g lambda tau Kv) = 0, a cubic matrix
    polynomial (every mount the same standard linear solid), by a companion pencil."""
    n = 6
    c = lin.D + lin.G
    a3, a2, a1, a0 = tau * lin.M, lin.M + tau * c, c + tau * lin.K + g * tau * kv, lin.K
    big = np.zeros((3 * n, 3 * n))
    big[:n, n:2 * n] = np.eye(n)
    big[n:2 * n, 2 * n:] = np.eye(n)
    big[2 * n:, :n], big[2 * n:, n:2 * n], big[2 * n:, 2 * n:] = -a0, -a1, -a2
    lhs = np.eye(3 * n)
    lhs[2 * n:, 2 * n:] = a3
    return scipy.linalg.eigvals(big, lhs)


def test_augmented_eigenvalues_are_the_roots_of_the_exact_characteristic_equation():
    model = _model()
    g, tau = 0.5, 2e-3
    thrust = 9000.0
    lin = impstab.linearize(model, thrust, "classical")
    kv = model.elastic_stiffness  # every mount viscoelastic: sum B^T k B
    roots = _poly_roots(lin, kv, g, tau)
    fam = ViscoelasticFamily(model, "classical")
    e, a = fam.matrices(np.array([thrust]))
    assert fam.n == 12 + 3 * 1 * 3
    aug = np.linalg.eigvals(np.linalg.solve(e[0], a[0]))
    left = list(aug)
    for r in roots:
        j = int(np.argmin(np.abs(np.array(left) - r)))
        assert abs(left[j] - r) <= 1e-7 * max(abs(r), 1.0), (r, left[j])
        left.pop(j)
    # the three internal combinations no body motion reaches relax at -1/tau
    np.testing.assert_allclose(np.sort_complex(np.array(left)), [-1 / tau] * 3, rtol=1e-7)


def _max_growth(model, thrust, g, tau):
    lin = impstab.linearize(model, thrust, "classical")
    return _poly_roots(lin, model.elastic_stiffness, g, tau).real.max()


def test_critical_thrust_equals_a_scan_of_the_exact_characteristic_equation():
    model = _model(linearization="classical")
    g, tau = 0.5, 2e-3
    res = impstab.critical_thrust(model)
    grid = np.linspace(0.0, 30000.0, 61)
    growth = [_max_growth(model, t, g, tau) for t in grid]
    i = next(i for i, v in enumerate(growth) if v > 0)
    t_ref = brentq(lambda t: _max_growth(model, t, g, tau), grid[i - 1], grid[i], xtol=1e-9, rtol=1e-14)
    assert res.kind == "flutter"
    assert res.thrust == pytest.approx(t_ref, rel=1e-8)
    # undamped = the same mounts elastic at their static stiffness
    assert res.undamped_thrust == pytest.approx(impstab.critical_thrust(model.undamped()).thrust, rel=1e-12)
    # an exact series: no fit to check, and Newton on the exact eigenproblem from the onset only polishes
    assert res.exact_onset is None
    check = exact_onset(model, res.thrust, res.omega, "classical")
    assert check.exact_thrust is not None and abs(check.thrust_difference) < 1e-10
    d = res.to_dict()
    assert d["viscoelastic"]["undamped_stiffness"] == "static"
    assert d["undamped_critical_thrust"] == res.undamped_thrust


def test_fractional_zener_onset_solves_the_exact_law():
    """The reported onset is a root of det F(i omega, T) = 0 with the fractional ratio written out
    here, found by scipy's fsolve from the Prony onset (independent of impstab's Newton)."""
    s, tau, alpha = 2.0, 2e-3, 0.4
    model = _model({"law": "fractional-zener", "stiffening": s, "relaxation_time": tau, "alpha": alpha},
                   linearization="classical")
    res = impstab.critical_thrust(model)
    check = res.exact_onset
    assert res.kind == "flutter" and check is not None and check.exact_thrust is not None
    kv = model.elastic_stiffness

    def residual(x):
        t, w = x
        lin = impstab.linearize(model, t, "classical")
        z = (1j * w * tau) ** alpha
        r = (1 + s * z) / (1 + z)
        f = -w * w * lin.M + 1j * w * (lin.D + lin.G) + lin.K + kv * (r - 1)
        d = np.linalg.det(f / np.abs(lin.K).max())
        return [d.real, d.imag]

    t_ref, w_ref = fsolve(residual, [check.thrust, check.omega], xtol=1e-13)
    assert res.thrust == pytest.approx(t_ref, rel=1e-8)
    assert res.omega == pytest.approx(w_ref, rel=1e-8)
    law = model.mounts[0].viscoelastic
    assert 0 < law.fit_error < 0.05
    assert abs(check.thrust_difference) < 0.02 and check.thrust == pytest.approx(check.thrust * (1.0), rel=0)


def test_hysteretic_table_is_fitted_over_its_band_and_said_so():
    table = {"law": "table", "frequency_hz": [0.5, 2.0, 5.0, 20.0, 100.0], "storage_ratio": [1.0, 1.05, 1.1, 1.2, 1.3],
             "loss_factor": [0.05, 0.05, 0.05, 0.05, 0.05]}
    res = impstab.critical_thrust(_model(table))
    assert res.thrust is not None
    assert any("hysteretic" in w for w in res.warnings)
    d = res.to_dict()["viscoelastic"]
    assert d["fits"][0]["hysteretic"] and d["fits"][0]["fit_error"] > 0


def test_rotated_equilibrium_onset_is_a_root_of_the_exact_equation():
    """Asymmetric layout (tilted axes, a 6x6 mount, off-axis thrust), equilibrium linearization (the
    body rotates under thrust, the family is not affine): at the reported onset the exact dynamic
    stiffness, written out here with the arms R0 r_i of the equilibrium, is singular, and the
    rightmost characteristic root changes sign across it."""
    from conftest import asymmetric_model_dict

    d = asymmetric_model_dict()
    tau, s = 3e-3, 1.6
    for m in d["mounts"][:3]:
        m["viscoelastic"] = {"law": "standard-linear-solid", "stiffening": s, "relaxation_time": tau}
    model = model_from_dict(d)
    res = impstab.critical_thrust(model)
    assert res.thrust is not None and res.kind == "flutter"

    def exact_f(t, lam):
        lin = impstab.linearize(model, t)
        f = lam * lam * lin.M + lam * (lin.D + lin.G) + lin.K + 0j
        r = (1 + lam * s * tau) / (1 + lam * tau)
        for mt in model.mounts[:3]:
            arm = lin.rotation @ mt.position
            b = np.hstack([np.eye(3), -np.array([[0, -arm[2], arm[1]], [arm[2], 0, -arm[0]], [-arm[1], arm[0], 0]])])
            f += b.T @ mt.stiffness[:3, :3] @ b * (r - 1)
        return f

    sv = np.linalg.svd(exact_f(res.thrust, 1j * res.omega), compute_uv=False)
    assert sv[-1] / sv[0] < 1e-10

    def growth(t):
        lin = impstab.linearize(model, t)
        # the same F times (1 + lambda tau): a cubic matrix polynomial, rightmost root by a companion pencil
        kv = np.zeros((6, 6))
        for mt in model.mounts[:3]:
            arm = lin.rotation @ mt.position
            b = np.hstack([np.eye(3), -np.array([[0, -arm[2], arm[1]], [arm[2], 0, -arm[0]], [-arm[1], arm[0], 0]])])
            kv += b.T @ mt.stiffness[:3, :3] @ b
        return _poly_roots(lin, kv, s - 1, tau).real.max()

    assert growth(res.thrust * (1 - 1e-6)) < 0 < growth(res.thrust * (1 + 1e-6))


def test_locus_and_modes_are_those_of_the_augmented_system():
    model = _model(linearization="classical")
    g, tau = 0.5, 2e-3
    crit = impstab.critical_thrust(model)
    thrusts = np.array([0.0, 0.5, 0.999, 1.001]) * crit.thrust
    loc = impstab.locus(model, thrusts)
    assert loc.eigenvalues.shape == (4, 21)
    for i, t in enumerate(thrusts):
        roots = _poly_roots(impstab.linearize(model, t, "classical"), model.elastic_stiffness, g, tau)
        lam = loc.eigenvalues[i]
        for r in roots:
            assert np.min(np.abs(lam - r)) <= 1e-7 * max(abs(r), 1.0)
    assert loc.eigenvalues[2].real.max() < 0 < loc.eigenvalues[3].real.max()
    md = impstab.modes(model, thrusts[3])
    assert md.eigenvalues.real.max() > 0
    upper = [r for r in _poly_roots(impstab.linearize(model, thrusts[3], "classical"), model.elastic_stiffness, g, tau)
             if r.imag > 1e-9]
    for r in upper:
        assert np.min(np.abs(md.eigenvalues - r)) <= 1e-7 * abs(r)


def test_reduced_family_drops_only_the_unreached_relaxation_roots():
    """Two Prony terms on each of 3 mounts: 30 states, of which 2 x (9 - 6) internal combinations no
    motion reaches (eigenvalues -1/tau_j, stable); the reduced family keeps every other eigenvalue
    and gives the same critical thrust through the engine."""
    model = _model({"law": "prony", "terms": [[0.3, 1e-3], [0.5, 2e-2]]}, linearization="classical")
    full, small = ViscoelasticFamily(model), ViscoelasticFamily(model, reduced=True)
    assert (full.n, small.n) == (30, 24)
    e, a = full.matrices(np.array([8000.0]))
    er, ar = small.matrices(np.array([8000.0]))
    lam = _unmatched(e[0], a[0], er[0], ar[0])
    np.testing.assert_allclose(np.sort(np.real(lam)), [-1e3] * 3 + [-50.0] * 3, rtol=1e-8)
    from impstab.linear.critical import critical_load_family

    t_full = critical_load_family(full, 30000.0).load
    assert impstab.critical_thrust(model).thrust == pytest.approx(t_full, rel=1e-10)


def test_reduced_states_in_dof_coordinates_are_the_exact_roots_and_keep_the_planes_apart():
    """Three standard-linear-solid mounts (B of rank 6): the reduced family keeps one internal
    6-vector in the body's dof coordinates, 18 states whose eigenvalues are the 18 roots of the exact
    characteristic polynomial (companion pencil, _poly_roots), at a thrust with flutter and one
    without; and its operator splits into the blocks of the symmetric layout (surge and roll with
    their internal states, 3 each; the sway-yaw and heave-pitch planes, 6 each)."""
    from impstab.linear.blocks import decoupled_blocks

    model = _model(linearization="classical")
    g, tau = 0.5, 2e-3
    fam = ViscoelasticFamily(model, reduced=True)
    assert fam.n == 18
    for thrust in (4000.0, 29000.0):
        lin = impstab.linearize(model, thrust, "classical")
        roots = list(_poly_roots(lin, model.elastic_stiffness, g, tau))
        e, a = fam.matrices(np.array([thrust]))
        for lam in np.linalg.eigvals(np.linalg.solve(e[0], a[0])):
            j = int(np.argmin(np.abs(np.array(roots) - lam)))
            assert abs(roots[j] - lam) <= 1e-8 * max(abs(lam), 1.0), (lam, roots[j])
            roots.pop(j)
        assert not roots
    e, a0, a1 = fam.affine_parts()
    blocks = decoupled_blocks(np.linalg.solve(e, a0)[None], np.linalg.solve(e, a1)[None], np.array([30000.0]))
    sizes = np.diff(blocks.starts[0, : blocks.nblocks[0] + 1])
    assert sorted(sizes.tolist()) == [3, 3, 6, 6]


def test_reduced_states_below_full_rank_drop_only_the_unreached_root():
    """Two viscoelastic mounts of the asymmetric layout: their stacked maps have rank 5 (a rotation
    about the line through them moves neither), so of the 6 internal states one combination is never
    reached: the reduced family (an orthonormal basis of range B) has 17 states, every eigenvalue
    of the full 18-state system but one, and that one is -1/tau."""
    from conftest import asymmetric_model_dict

    d = asymmetric_model_dict()
    tau = 3e-3
    for m in d["mounts"][:2]:
        m["viscoelastic"] = {"law": "standard-linear-solid", "stiffening": 1.6, "relaxation_time": tau}
    d["analysis"]["linearization"] = "classical"
    model = model_from_dict(d)
    full, small = ViscoelasticFamily(model), ViscoelasticFamily(model, reduced=True)
    assert (full.n, small.n) == (18, 17)
    e, a = full.matrices(np.array([3000.0]))
    er, ar = small.matrices(np.array([3000.0]))
    lam = _unmatched(e[0], a[0], er[0], ar[0])
    assert len(lam) == 1 and lam[0] == pytest.approx(-1 / tau, rel=1e-8)


@pytest.mark.parametrize("dampers", [False, True])
def test_undamped_companion_is_the_model_without_dampers_and_with_static_stiffness(dampers):
    """The undamped critical thrust of a viscoelastic model, with or without viscous dampers beside
    the laws, is that of model.undamped() (dampers removed, the mounts elastic at their static
    stiffness), solved as an elastic model of its own."""
    d = ring_model_dict()
    d["mount_rings"][0]["viscoelastic"] = dict(SLS)
    if dampers:
        d["mount_rings"][0].update(c_axial=60.0, c_shear=15.0)
    model = model_from_dict(d)
    res = impstab.critical_thrust(model)
    plain = impstab.critical_thrust(model.undamped())
    assert not model.undamped().is_damped
    assert res.undamped_thrust == pytest.approx(plain.thrust, rel=1e-12)
    assert res.undamped_kind == plain.kind


def test_onset_of_identical_planes_by_newton_equals_a_plain_dense_scan():
    """Three mounts with two Prony terms each: the flutter pair appears twice (the sway-yaw and the
    heave-pitch plane), a cluster of copies that the engine refines by Newton on their mean growth.
    The onset equals a plain scan of the full 30-state matrix (numpy eigvals on the same grid, then
    bisection on max Re lambda > 0 to 1e-14 relative), the rightmost pair is doubled there, and the
    refinement takes a handful of eigen-decompositions (not a bisection tail at the rounding
    floor): 35 scan points up to the bracket, at most 6 more."""
    from impstab.linear.critical import critical_load_family

    model = _model({"law": "prony", "terms": [[0.3, 1e-3], [0.5, 2e-2]]}, linearization="classical")
    res = critical_load_family(ViscoelasticFamily(model, reduced=True), 30000.0)
    e, a0, a1 = ViscoelasticFamily(model).affine_parts()
    a0, a1 = np.linalg.solve(e, a0), np.linalg.solve(e, a1)
    growth = lambda t: np.linalg.eigvals(a0 + t * a1).real.max()  # noqa: E731
    grid = np.linspace(0.0, 30000.0, 65)
    i = next(i for i, t in enumerate(grid) if growth(t) > 0)
    lo, hi = grid[i - 1], grid[i]
    while hi - lo > 1e-14 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if growth(mid) > 0 else (mid, hi)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(hi, rel=1e-11)
    lam = np.linalg.eigvals(a0 + res.load * a1)
    top = lam[np.argsort(-lam.real)[:4]]
    assert np.abs(top.real).max() <= 1e-9 * np.abs(top).max()
    assert np.sort(np.abs(top.imag)) == pytest.approx([res.omega] * 4, rel=1e-8)
    assert res.evaluations <= 35 + 6
