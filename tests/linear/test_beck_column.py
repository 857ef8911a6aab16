"""Beck's column: a cantilever under a tangential follower force, built here with Hermite elements.

Model (x along the undeformed axis, 0 <= x <= L, transverse deflection w, rotation theta = w')
-------------------------------------------------------------------------------------------
Each element of length h has the dofs ``(w1, theta1, w2, theta2)`` and the cubic Hermite shape
functions ``N``; then

* consistent mass ``m h / 420 [[156, 22h, 54, -13h], [22h, 4h^2, 13h, -3h^2], ...]`` (= ∫ m N^T N),
* elastic stiffness ``EI / h^3 [[12, 6h, -12, 6h], [6h, 4h^2, -6h, 2h^2], ...]`` (= ∫ EI N''^T N''),
* geometric stiffness ``K_G = 1 / (30 h) [[36, 3h, -36, 3h], [3h, 4h^2, -3h, -h^2], ...]``
  (= ∫ N'^T N').

Follower load at the tip. The force has magnitude P and stays tangent to the deformed axis,
pointing to the root: ``F = -P (cos theta_L, sin theta_L) ~ -P (1, theta_L)``. Its virtual work,
to second order in the displacements, has two parts:

* the axial part ``-P`` works through the shortening of the tip, ``u_L = -1/2 ∫ w'^2 dx``:
  ``delta W = P ∫ w' delta w' dx = delta q^T (P K_G) q`` (the same as for a dead load);
* the transverse part ``-P theta_L`` works through ``delta w_L``:
  ``delta W = -P theta_L delta w_L = -delta q^T (P e_w e_theta^T) q``, where ``e_w`` and
  ``e_theta`` pick the tip deflection and the tip rotation.

So ``M q'' + (K_e - P K_G + P e_w e_theta^T) q = 0``: ``K(P) = K0 + P K1`` with ``K0 = K_e`` and
``K1 = -K_G + e_w e_theta^T``, i.e. the load stiffness per unit P is the (negative) geometric
stiffness plus one non-symmetric entry ``+1`` in the row of the tip deflection and the column of
the tip rotation. (In the continuum this term turns the dead-load shear condition
``EI w''' + P w' = 0`` into Beck's ``w'''(L) = 0``.) Without it (a dead load) the column buckles
at Euler's ``pi^2 / 4``.

Nondimensional units L = EI = m = 1, so ``p = P L^2 / EI`` and ``Omega = omega L^2 sqrt(m / EI)``.
Published (THEORY 10): p_cr = 20.051, Omega = 11.016. Independent reference here: the exact
continuum value from the characteristic determinant of ``W'''' + p W'' - Omega^2 W = 0`` with
``W(0) = W'(0) = W''(1) = W'''(1) = 0`` (the largest p on the curve det = 0 in the (Omega, p)
plane, where the two lowest frequencies coalesce).
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.optimize import brentq, minimize_scalar

from impstab.linear import critical_load

P_PUBLISHED, OMEGA_PUBLISHED = 20.051, 11.016
P_MAX = 22.0          # "a bit above" 20.051


def beck_matrices(n_el: int, L: float = 1.0, EI: float = 1.0, m: float = 1.0, follower: bool = True):
    """Clamped-free Hermite model: ``(M, K0, K1)`` with ``K(P) = K0 + P K1`` (see module doc)."""
    h = L / n_el
    me = m * h / 420.0 * np.array(
        [[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
         [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]]
    )
    ke = EI / h**3 * np.array(
        [[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
         [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]]
    )
    kg = 1.0 / (30.0 * h) * np.array(
        [[36, 3 * h, -36, 3 * h], [3 * h, 4 * h * h, -3 * h, -h * h],
         [-36, -3 * h, 36, -3 * h], [3 * h, -h * h, -3 * h, 4 * h * h]]
    )
    n = 2 * (n_el + 1)
    M, K, G = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    for e in range(n_el):
        s = slice(2 * e, 2 * e + 4)
        M[s, s] += me
        K[s, s] += ke
        G[s, s] += kg
    K1 = -G
    if follower:
        K1[n - 2, n - 1] += 1.0        # + P theta_L in the equation of the tip deflection
    free = slice(2, n)                 # clamp w and theta at the root
    return M[free, free], K[free, free], K1[free, free]


# -- independent references --------------------------------------------------------------------
def _continuum_det(p: float, Omega: float) -> float:
    r = np.sqrt(p * p + 4 * Omega * Omega)
    a, b = np.sqrt((p + r) / 2), np.sqrt((r - p) / 2)     # W = {cos, sin}(a x), {cosh, sinh}(b x)
    ca, sa, cb, sb = np.cos(a), np.sin(a), np.cosh(b), np.sinh(b)
    rows = [
        [1.0, 0.0, 1.0, 0.0],                                        # W(0)
        [0.0, a, 0.0, b],                                            # W'(0)
        [-a**2 * ca, -a**2 * sa, b**2 * cb, b**2 * sb],              # W''(1)
        [a**3 * sa, -a**3 * ca, b**3 * sb, b**3 * cb],               # W'''(1)
    ]
    return float(np.linalg.det(np.array(rows)))


@functools.lru_cache(maxsize=None)
def continuum_reference() -> tuple[float, float]:
    """Exact (p_cr, Omega_cr) of the continuous Beck column: max of p(Omega) on det = 0."""

    def p_of(Omega: float) -> float:
        return brentq(lambda p: _continuum_det(p, Omega), 15.0, 20.06, xtol=1e-14, rtol=8.9e-16)

    res = minimize_scalar(lambda W: -p_of(W), bounds=(10.5, 11.5), method="bounded",
                          options={"xatol": 1e-9})
    return -res.fun, res.x


@functools.lru_cache(maxsize=None)
def fe_coalescence(n_el: int) -> tuple[float, float]:
    """Flutter load of the FE model by brentq on the discriminant of the two lowest ``s``.

    ``Delta(p) = (s_1 - s_2)^2`` is real (both real, or a conjugate pair) and crosses zero
    linearly at the coalescence; ``s`` from ``scipy.linalg.eigvals(K, M)``.
    """
    M, K0, K1 = beck_matrices(n_el)

    def pair(p):
        s = sla.eigvals(K0 + p * K1, M)
        return s[np.argsort(s.real)][:2]

    def delta(p):
        s = pair(p)
        return float(((s[0] - s[1]) ** 2).real)

    p = brentq(delta, 15.0, 25.0, xtol=1e-300, rtol=8.9e-16)
    return p, float(np.sqrt(pair(p).real.mean()))


def engine(n_el: int, **kw):
    M, K0, K1 = beck_matrices(n_el, **kw)
    return critical_load(M, K0, K1, p_max=P_MAX)


# -- the references themselves -----------------------------------------------------------------
def test_continuum_reference_reproduces_published_values():
    p, W = continuum_reference()
    assert round(p, 3) == P_PUBLISHED
    assert round(W, 3) == OMEGA_PUBLISHED
    # at p = 0 the same determinant gives the cantilever's first frequency 1.8751^2
    w1 = brentq(lambda W: _continuum_det(0.0, W), 2.0, 5.0)
    assert w1 == pytest.approx(1.875104068711961**2, rel=1e-12)


# -- engine against the FE model, mesh by mesh --------------------------------------------------


@pytest.mark.parametrize(
    "n_el, n_scan",
    [(2, 64), (3, 64), (4, 64), (6, 64), (8, 64), (12, 64), (8, 200),
     (16, 64),
     (32, 64),
     # scans whose grid points once fell inside the classification window (fixed)
     (12, 80),
     (8, 147)],
)
def test_engine_matches_fe_coalescence(n_el, n_scan):
    p_fe, w_fe = fe_coalescence(n_el)
    M, K0, K1 = beck_matrices(n_el)
    res = critical_load(M, K0, K1, p_max=P_MAX, n_scan=n_scan)
    assert res.kind == "flutter"
    # the coalescence indicator is exact to eps |A| / |s_c|^2; with 32 elements the stiffest
    # element modes make |A| / |s_c| ~ 1e8, so the attainable accuracy there is ~1e-9
    assert res.load == pytest.approx(p_fe, rel=1e-10 if n_el <= 16 else 1e-9)
    assert res.omega == pytest.approx(w_fe, rel=1e-7)   # sqrt(eps) noise at the defective pair


def test_published_values_12_elements():
    res = engine(12)
    assert res.kind == "flutter"
    assert abs(res.load / P_PUBLISHED - 1) < 1e-4          # 20.0516 (4 digits)
    assert abs(res.omega / OMEGA_PUBLISHED - 1) < 1e-5     # 11.0159
    p_ref, w_ref = continuum_reference()
    assert 0 < res.load - p_ref < 1e-3
    assert abs(res.omega - w_ref) < 1e-3


def test_published_values_richardson():
    """Order-4 Richardson extrapolation of the engine's 8- and 12-element values: 5 digits."""
    r8, r12 = engine(8), engine(12)
    k = (12 / 8) ** 4
    p = (k * r12.load - r8.load) / (k - 1)
    W = (k * r12.omega - r8.omega) / (k - 1)
    assert round(p, 3) == P_PUBLISHED
    assert round(W, 3) == OMEGA_PUBLISHED
    p_ref, w_ref = continuum_reference()
    assert abs(p - p_ref) < 5e-5 and abs(W - w_ref) < 5e-5


def test_convergence_with_mesh_refinement():
    p_ref, w_ref = continuum_reference()
    meshes = [2, 4, 8, 12]
    res = [engine(n) for n in meshes]
    err_p = np.array([r.load - p_ref for r in res])
    err_w = np.array([r.omega - w_ref for r in res])
    assert np.all(err_p > 0) and np.all(np.diff(err_p) < 0)     # monotone, from above
    assert np.all(err_w > 0) and np.all(np.diff(err_w) < 0)
    order = np.log(err_p[1:] / err_p[:-1]) / np.log(np.array(meshes[:-1]) / np.array(meshes[1:]))
    # 2 -> 4 is pre-asymptotic (~1.6); cubic Hermite elements converge like h^4 after that
    assert order[1] == pytest.approx(4.0, abs=0.3)
    assert order[2] == pytest.approx(4.0, abs=0.3)
    assert err_p[-1] < 1e-3


@pytest.mark.parametrize("L, EI, m", [(2.5, 3.0e4, 7.0), (0.3, 12.0, 0.02)])
def test_dimensional_scaling(L, EI, m):
    """P_cr = p_cr EI / L^2, omega = Omega sqrt(EI / m) / L^2."""
    p_fe, w_fe = fe_coalescence(8)
    M, K0, K1 = beck_matrices(8, L=L, EI=EI, m=m)
    res = critical_load(M, K0, K1, p_max=P_MAX * EI / L**2)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(p_fe * EI / L**2, rel=1e-10)
    assert res.omega == pytest.approx(w_fe * np.sqrt(EI / m) / L**2, rel=1e-7)


@pytest.mark.parametrize("n_el", [2, 4, 8])
def test_dead_load_buckles_at_euler(n_el):
    """Without the follower term the load is conservative: divergence at ~ pi^2/4."""
    M, K0, K1 = beck_matrices(n_el, follower=False)
    s = sla.eigvals(K0, -K1)
    p_fe = s.real[s.real > 0].min()
    res = critical_load(M, K0, K1, p_max=5.0)
    assert res.kind == "divergence"
    assert res.omega == 0.0
    assert res.load == pytest.approx(p_fe, rel=1e-10)
    assert res.load == pytest.approx(np.pi**2 / 4, rel=1e-3)


# -- Kelvin-Voigt internal damping: destabilisation by damping ----------------------------------
def _max_growth(M, D, K):
    n = len(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-sla.solve(M, K), -sla.solve(M, D)]])
    return float(sla.eigvals(A).real.max())


def damped_reference(n_el: int, eta: float) -> float:
    """Brute force: scan max Re(lambda) of the state matrix built here, brentq its first zero."""
    M, K0, K1 = beck_matrices(n_el)
    D = eta * K0

    def f(p):
        return _max_growth(M, D, K0 + p * K1)

    grid = np.linspace(0.0, P_MAX, 111)
    j = next(i for i, p in enumerate(grid) if f(p) > 0)
    return brentq(f, grid[j - 1], grid[j], xtol=1e-300, rtol=8.9e-16)




@pytest.mark.parametrize(
    "n_el, eta",
    [
        (4, 1e-3),
        (4, 1e-2),
        (8, 1e-3),
        (8, 1e-2),
    ],
)
def test_kelvin_voigt_damping(n_el, eta):
    """D = eta K_e: the critical load drops to about 10.94, far below the undamped 20.05."""
    p_ref = damped_reference(n_el, eta)
    assert 10.9 < p_ref < 11.0
    M, K0, K1 = beck_matrices(n_el)
    res = critical_load(M, K0, K1, D=eta * K0, p_max=P_MAX)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(p_ref, rel=1e-10)


# -- large models: modal reduction with error checks, exact onset of the full model -------------
@pytest.mark.parametrize("n_el", [50, 80])
def test_large_column_matches_the_fe_models_own_coalescence(n_el):
    """100 and 160 dofs (above the engine's LARGE_ORDER: reduced, then refined on the full model).

    The dense reference is accurate only to ~eps |M^-1 K| / s_c (stiff element modes): 1e-9 at 50
    elements, a few 1e-9 at 80; the engine's onset is conditioned at ~2e-10 per ulp of K there."""
    p_fe, w_fe = fe_coalescence(n_el)
    M, K0, K1 = beck_matrices(n_el)
    res = critical_load(M, K0, K1, p_max=P_MAX)
    assert res.kind == "flutter" and res.warnings == ()
    assert res.load == pytest.approx(p_fe, rel=1e-9 if n_el == 50 else 1e-8)
    assert res.omega == pytest.approx(w_fe, rel=1e-7)


def test_large_columns_converge_to_the_continuum_like_h4():
    """40, 80 and 160 elements (80, 160 and 320 dofs; the last two reduced and refined on the
    full model). The errors against the exact continuum value fall by 2^4 from 40 to 80, and
    their Richardson extrapolation reproduces it to 1e-9. The 160-element model's onset is
    itself determined only to ~1e-9 (2e-8 absolute) by its rounded stiffness entries (a random
    ulp in each moves it by that much), the size of its remaining discretization error: it lies
    within that of the h^4 prediction from 80 elements."""
    p_ref, w_ref = continuum_reference()
    r40, r80, r160 = engine(40), engine(80), engine(160)
    assert r40.warnings == () and r80.warnings == () and r160.warnings == ()
    err40, err80 = r40.load - p_ref, r80.load - p_ref
    assert 0 < err80 < err40 and err40 / err80 == pytest.approx(16.0, rel=0.02)
    assert (16 * r80.load - r40.load) / 15 == pytest.approx(p_ref, rel=1e-9)
    assert (16 * r80.omega - r40.omega) / 15 == pytest.approx(w_ref, rel=1e-8)
    assert abs(r160.load - (p_ref + err80 / 16)) <= 3e-8
    assert r160.omega == pytest.approx(w_ref, rel=1e-8)


def test_a_reduction_that_misses_an_earlier_instability_is_not_used():
    """100 dofs, M = I, K0 = diag(s_i): the pairs (s_0, s_1) and (s_60, s_61) each coalesce under a
    circulatory coupling [[0, p], [-p, 0]] at p = (s_j+1 - s_j) / 2: 0.5 for the low pair, 0.25
    for the high one, which the modal bases of 12 and 24 modes do not contain. The full model's
    check below the reduced onset finds it unstable, and the problem is solved dense."""
    n = 100
    s = np.linspace(1.0, 100.0, n)
    s[61] = s[60] + 0.5
    K1 = np.zeros((n, n))
    K1[0, 1], K1[1, 0] = 1.0, -1.0
    K1[60, 61], K1[61, 60] = 1.0, -1.0
    res = critical_load(np.eye(n), np.diag(s), K1, p_max=2.0)
    assert res.load == pytest.approx(0.25, rel=1e-12) and res.kind == "flutter"
    assert len(res.warnings) == 1 and "solved dense" in res.warnings[0]
