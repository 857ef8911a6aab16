"""Independent tests of the critical-load engine ``impstab.linear.critical``.

Every expected value comes from a route that does not use the engine: closed forms, the
Routh-Hurwitz boundary of the characteristic polynomial (built here with ``numpy.poly1d`` and
solved with ``brentq``), generalized eigenvalues from ``scipy.linalg``, or a brute-force scan of
the state matrix built here.

Ziegler's pendulum (THEORY 10), absolute angles, m = l = c = 1:
``M = [[3, 1], [1, 1]]``, ``K(p) = [[2 - p, p - 1], [-1, 1]]``. With ``s = omega^2``,
``det(K - s M) = 2 s^2 + (2 p - 7) s + 1``: its discriminant ``(2 p - 7)^2 - 8`` is negative
for ``p`` in ``(7/2 - sqrt 2, 7/2 + sqrt 2)``, where the double root is ``s = 1/sqrt 2``.
Beyond ``7/2 + sqrt 2`` both ``s`` are real and negative: still unstable (no restabilisation).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from numpy import poly1d
from scipy.optimize import brentq

from impstab.linear import CallableFamily, critical_load, critical_load_family

M_Z = np.array([[3.0, 1.0], [1.0, 1.0]])
K0_Z = np.array([[2.0, -1.0], [-1.0, 1.0]])
K1_Z = -np.array([[1.0, -1.0], [0.0, 0.0]])
P_FLUTTER = 3.5 - np.sqrt(2.0)          # 2.0857864376269...
OMEGA_FLUTTER = 2.0 ** -0.25
RTOL = 1e-10                            # the engine is meant to be exact to machine precision


# -- independent helpers ----------------------------------------------------------------------
def charpoly2(M, C, K) -> poly1d:
    """``det(lambda^2 M + lambda C + K)`` of a 2 x 2 system, as a polynomial in lambda."""
    e = [[poly1d([M[i][j], C[i][j], K[i][j]]) for j in range(2)] for i in range(2)]
    return e[0][0] * e[1][1] - e[0][1] * e[1][0]


def hurwitz3(coeffs) -> float:
    """Third Hurwitz determinant of a quartic ``a4 l^4 + a3 l^3 + a2 l^2 + a1 l + a0``.

    With all coefficients positive, the quartic is Hurwitz stable iff this is positive; it
    vanishes where a pair of roots crosses the imaginary axis at ``omega^2 = a1 / a3``.
    """
    a4, a3, a2, a1, a0 = coeffs
    return a3 * a2 * a1 - a4 * a1**2 - a0 * a3**2


def rh_boundary(M, C, K0, K1, lo, hi):
    """First Routh-Hurwitz boundary in ``(lo, hi)`` (fine sign scan + brentq) and omega there."""

    def h(p):
        return hurwitz3(charpoly2(M, C, K0 + p * K1).coeffs)

    grid = np.linspace(lo, hi, 401)
    vals = np.array([h(p) for p in grid])
    assert vals[0] > 0
    j = np.flatnonzero(np.sign(vals[1:]) != np.sign(vals[:-1]))[0]
    p = brentq(h, grid[j], grid[j + 1], xtol=1e-300, rtol=8.9e-16, maxiter=500)
    a4, a3, a2, a1, a0 = charpoly2(M, C, K0 + p * K1).coeffs
    assert min(a4, a3, a2, a1, a0) > 0     # a Hopf crossing, not a real root through zero
    return p, np.sqrt(a1 / a3)


def hinge_dashpots(b1: float, b2: float) -> np.ndarray:
    """Dashpot b1 at the root hinge (angle q1) and b2 at the middle hinge (angle q2 - q1)."""
    return np.array([[b1 + b2, -b2], [-b2, b2]])


def ziegler(m=1.0, l=1.0, c=1.0):
    return m * l**2 * M_Z, c * K0_Z, l * K1_Z


# -- 1. Ziegler's pendulum -------------------------------------------------------------------
def test_ziegler_undamped_closed_form():
    res = critical_load(M_Z, K0_Z, K1_Z, p_max=5.0)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(P_FLUTTER, rel=RTOL)
    assert res.omega == pytest.approx(OMEGA_FLUTTER, rel=RTOL)
    assert res.frequency_hz == pytest.approx(OMEGA_FLUTTER / (2 * np.pi), rel=RTOL)
    # independent: the quadratic in s has a double root exactly there
    disc = (2 * res.load - 7) ** 2 - 8
    assert abs(disc) < 1e-12


def test_ziegler_onset_mode_is_the_double_root_eigenvector():
    res = critical_load(M_Z, K0_Z, K1_Z, p_max=5.0)
    k = K0_Z + res.load * K1_Z
    # exact double-root eigenvector: (K - s M) x = 0 with s = 1/sqrt 2
    s = 1.0 / np.sqrt(2.0)
    null = sla.null_space(k - s * M_Z, rcond=1e-6)
    assert null.shape[1] == 1
    x = np.asarray(res.mode)
    cos = abs(np.vdot(null[:, 0], x)) / np.linalg.norm(x)
    assert cos == pytest.approx(1.0, abs=1e-6)     # eigenvector of a defective root: sqrt(eps)


def test_ziegler_no_restabilisation_after_flutter():
    """Past 7/2 + sqrt 2 the pair becomes real negative: unstable on both sides, no 'gain'."""
    res = critical_load(M_Z, K0_Z, K1_Z, p_max=6.5, all_crossings=True)
    assert res.load == pytest.approx(P_FLUTTER, rel=RTOL)
    assert [c.direction for c in res.crossings] == ["loss"]
    assert res.crossings[0].load == pytest.approx(P_FLUTTER, rel=RTOL)
    assert res.crossings[0].kind == "flutter"




@pytest.mark.parametrize(
    "b",
    [
        1e-4, 1e-3, 3e-3, 1e-2, 0.05, 0.1, 0.3, 0.5, 1e-5, 1e-6,
    ],
)
def test_ziegler_equal_dashpots(b):
    """p_cr = 41/28 + b^2/2 (THEORY 10), and the Routh-Hurwitz boundary of the quartic."""
    d = b * K0_Z
    p_rh, w_rh = rh_boundary(M_Z, d, K0_Z, K1_Z, 0.0, 4.0)
    assert p_rh == pytest.approx(41 / 28 + b**2 / 2, rel=1e-13)   # the two routes agree
    res = critical_load(M_Z, K0_Z, K1_Z, D=d, p_max=4.0)
    assert res.kind == "flutter"
    # the Hopf slope d(Re lambda)/dp is proportional to b, so rounding in Re(lambda) moves the
    # root by ~ eps / b: the attainable accuracy degrades gracefully for very light damping
    rtol = max(RTOL, 1e-15 / b)
    assert res.load == pytest.approx(41 / 28 + b**2 / 2, rel=rtol)
    assert res.load == pytest.approx(p_rh, rel=rtol)
    assert res.omega == pytest.approx(w_rh, rel=1e-9)




@pytest.mark.parametrize(
    "b1, b2, p_max",
    [
        (0.01, 0.001, 4.0), (0.001, 0.01, 4.0), (0.0, 0.1, 4.0), (0.05, 0.2, 4.0),
        (0.1, 0.0, 3.0),
        # boundary exactly 2 = grid point 32 of linspace(0, 4, 65)
        (0.1, 0.0, 4.0),
    ],
)
def test_ziegler_unequal_dashpots_routh_hurwitz(b1, b2, p_max):
    """The vanishing-damping limit depends on how the damping is distributed (THEORY 5).

    Dashpot only at the root hinge (b2 = 0): the boundary is p = 2 exactly, independent of b1
    (Routh-Hurwitz: H3 is proportional to (2 - p)).
    """
    d = hinge_dashpots(b1, b2)
    p_rh, w_rh = rh_boundary(M_Z, d, K0_Z, K1_Z, 0.0, p_max)
    if b2 == 0.0:
        assert p_rh == pytest.approx(2.0, rel=1e-14)
    res = critical_load(M_Z, K0_Z, K1_Z, D=d, p_max=p_max)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(p_rh, rel=RTOL)
    assert res.omega == pytest.approx(w_rh, rel=1e-9)


def test_destabilisation_by_damping_ziegler():
    """A tiny damping lowers the critical load by a finite amount; the undamped one stays exact."""
    undamped = critical_load(M_Z, K0_Z, K1_Z, p_max=4.0)
    damped = critical_load(M_Z, K0_Z, K1_Z, D=1e-3 * K0_Z, p_max=4.0)
    assert undamped.method == "coalescence" and damped.method == "hopf"
    assert undamped.load == pytest.approx(P_FLUTTER, rel=RTOL)
    assert damped.load == pytest.approx(41 / 28 + 0.5e-6, rel=RTOL)
    assert damped.load < 0.71 * undamped.load


@pytest.mark.parametrize("m, l, c", [(2.5, 0.7, 40.0), (0.01, 3.0, 1.0e3), (1.0e3, 0.1, 2.0), (7.0, 1.0, 1.0)])
def test_ziegler_dimensional_undamped(m, l, c):
    """P_cr = (7/2 - sqrt 2) c / l, omega = 2^(-1/4) sqrt(c / (m l^2))."""
    M, K0, K1 = ziegler(m, l, c)
    p_exact = P_FLUTTER * c / l
    res = critical_load(M, K0, K1, p_max=2.0 * p_exact)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(p_exact, rel=RTOL)
    assert res.omega == pytest.approx(OMEGA_FLUTTER * np.sqrt(c / (m * l**2)), rel=RTOL)


@pytest.mark.parametrize("m, l, c", [(2.5, 0.7, 40.0), (0.01, 3.0, 1.0e3), (1.0e3, 0.1, 2.0)])
@pytest.mark.parametrize("b", [1e-3, 0.2])
def test_ziegler_dimensional_damped(m, l, c, b):
    """Dashpots b sqrt(m c) l: P_cr = (41/28 + b^2/2) c / l; omega from Routh-Hurwitz."""
    M, K0, K1 = ziegler(m, l, c)
    d = b * np.sqrt(m * c) * l * K0_Z
    p_exact = (41 / 28 + b**2 / 2) * c / l
    _, w_rh = rh_boundary(M, d, K0, K1, 0.0, 3.0 * c / l)
    res = critical_load(M, K0, K1, D=d, p_max=3.0 * c / l)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(p_exact, rel=RTOL)
    assert res.omega == pytest.approx(w_rh, rel=1e-9)
    # nondimensional frequency: omega^2 = a1/a3 on the boundary, independent of b for equal dashpots
    assert res.omega * np.sqrt(m * l**2 / c) == pytest.approx(np.sqrt(2.0 / 7.0), rel=1e-9)




def test_ziegler_with_a_stiff_decoupled_dof_undamped():
    """Adding a decoupled stiff dof (k = 1e8) changes nothing physically."""
    M = sla.block_diag(M_Z, 1.0)
    K0 = sla.block_diag(K0_Z, 1.0e8)
    K1 = sla.block_diag(K1_Z, 0.0)
    res = critical_load(M, K0, K1, p_max=5.0)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(P_FLUTTER, rel=RTOL)


def test_ziegler_with_a_stiff_decoupled_dof_damped():
    M = sla.block_diag(M_Z, 1.0)
    K0 = sla.block_diag(K0_Z, 1.0e6)
    K1 = sla.block_diag(K1_Z, 0.0)
    D = sla.block_diag(0.01 * K0_Z, 0.0)
    res = critical_load(M, K0, K1, D=D, p_max=5.0)
    assert res.load == pytest.approx(41 / 28 + 0.5e-4, rel=RTOL)


# -- 3. conservative load: divergence only ---------------------------------------------------
def _spd(rng, n, shift=0.5):
    a = rng.standard_normal((n, n))
    return a @ a.T + shift * n * np.eye(n)


def _first_positive(values):
    values = np.asarray(values)
    real = values[np.abs(values.imag) < 1e-12 * np.abs(values).max()].real
    return real[real > 0].min()


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("damped", [False, True])
def test_conservative_dead_load_diverges(seed, damped):
    rng = np.random.default_rng(seed)
    n = 4
    M, K0 = _spd(rng, n), _spd(rng, n)
    k1 = rng.standard_normal((n, n))
    K1 = -(k1 @ k1.T) + 0.3 * np.diag(rng.standard_normal(n))     # symmetric, mostly softening
    # independent: det(K0 + p K1) = 0  <=>  K0 x = p (-K1) x
    p_exact = _first_positive(sla.eigvals(K0, -K1))
    D = 0.05 * _spd(rng, n) if damped else None
    res = critical_load(M, K0, K1, D=D, p_max=1.5 * p_exact)
    assert res.kind == "divergence"
    assert res.omega == 0.0
    assert res.frequency_hz == 0.0
    assert res.load == pytest.approx(p_exact, rel=RTOL)
    assert abs(np.linalg.det(K0 + res.load * K1)) < 1e-9 * np.abs(np.linalg.eigvals(K0)).prod()


def test_conservative_never_flutters_all_crossings():
    """Symmetric K: s stays real; only divergence crossings (no flutter) up to p_max."""
    rng = np.random.default_rng(7)
    n = 3
    M, K0 = _spd(rng, n), _spd(rng, n)
    K1 = -np.eye(n)
    roots = np.sort(sla.eigvals(K0).real)             # det(K0 - p I) = 0
    res = critical_load(M, K0, K1, p_max=roots[-1] + 1.0, all_crossings=True)
    assert res.load == pytest.approx(roots[0], rel=RTOL)
    assert all(c.kind == "divergence" for c in res.crossings)
    assert all(c.direction == "loss" for c in res.crossings)   # more and more negative s


# -- 4. symmetric duplicates -----------------------------------------------------------------
def _two_copies(damping=None):
    M = sla.block_diag(M_Z, M_Z)
    K0 = sla.block_diag(K0_Z, K0_Z)
    K1 = sla.block_diag(K1_Z, K1_Z)
    D = None if damping is None else sla.block_diag(damping, damping)
    return M, K0, K1, D


def _orthogonal(n, seed):
    q, r = np.linalg.qr(np.random.default_rng(seed).standard_normal((n, n)))
    return q * np.sign(np.diag(r))


def test_duplicate_copies_quadruple_root():
    M, K0, K1, _ = _two_copies()
    res = critical_load(M, K0, K1, p_max=5.0)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(P_FLUTTER, rel=RTOL)
    assert res.omega == pytest.approx(OMEGA_FLUTTER, rel=RTOL)
    # independent: det(K - s M) of the 4x4 is (2 s^2 + (2p-7) s + 1)^2 -> a quadruple root
    s = np.linalg.eigvals(np.linalg.solve(M, K0 + res.load * K1))
    assert np.abs(s - 1 / np.sqrt(2)).max() < 1e-6


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_duplicate_copies_mixed_by_orthogonal_basis(seed):
    M, K0, K1, _ = _two_copies()
    Q = _orthogonal(4, seed)
    res = critical_load(Q.T @ M @ Q, Q.T @ K0 @ Q, Q.T @ K1 @ Q, p_max=5.0)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(P_FLUTTER, rel=RTOL)
    assert res.omega == pytest.approx(OMEGA_FLUTTER, rel=RTOL)


@pytest.mark.parametrize("seed", [4, 5])
def test_duplicate_copies_mixed_by_general_congruence(seed):
    T = np.eye(4) + 0.4 * np.random.default_rng(seed).standard_normal((4, 4))
    M, K0, K1, _ = _two_copies()
    res = critical_load(T.T @ M @ T, T.T @ K0 @ T, T.T @ K1 @ T, p_max=5.0)
    assert res.load == pytest.approx(P_FLUTTER, rel=RTOL)


@pytest.mark.parametrize("seed", [None, 0, 1])
@pytest.mark.parametrize("b", [1e-3, 0.1])
def test_duplicate_damped_copies(seed, b):
    M, K0, K1, D = _two_copies(b * K0_Z)
    if seed is not None:
        Q = _orthogonal(4, seed)
        M, K0, K1, D = (Q.T @ a @ Q for a in (M, K0, K1, D))
    res = critical_load(M, K0, K1, D=D, p_max=4.0)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(41 / 28 + b**2 / 2, rel=RTOL)
    assert res.omega == pytest.approx(np.sqrt(2 / 7), rel=1e-9)


def test_two_different_pendulums_take_the_lower():
    """Decoupled copies with different springs (c and 1.3 c), mixed: the softer one flutters first."""
    M = sla.block_diag(M_Z, M_Z)
    K0 = sla.block_diag(K0_Z, 1.3 * K0_Z)
    K1 = sla.block_diag(K1_Z, K1_Z)
    Q = _orthogonal(4, 11)
    res = critical_load(Q.T @ M @ Q, Q.T @ K0 @ Q, Q.T @ K1 @ Q, p_max=5.0, all_crossings=True)
    assert res.load == pytest.approx(P_FLUTTER, rel=RTOL)
    # crossings are changes of the system's stability: the stiffer copy going unstable at
    # 1.3 P_FLUTTER (inside the first copy's flutter interval) is not one
    assert [c.direction for c in res.crossings] == ["loss"]
    assert res.crossings[0].load == pytest.approx(P_FLUTTER, rel=RTOL)


# -- 6. flutter bubble narrower than the scan spacing -----------------------------------------
P0, HALF = 0.3712, 1.0e-4     # bubble (P0 - HALF, P0 + HALF), width 2e-4 << p_max / n_scan


def test_flutter_bubble_affine():
    """M = I, K(p) = [[2 + (p - P0), w], [-w, 2 - (p - P0)]].

    Eigenvalues of K: s = 2 +- sqrt((p - P0)^2 - w^2): complex exactly for |p - P0| < w,
    with Re s = 2 there (omega = sqrt 2 at both ends).
    """
    K0 = np.array([[2.0 - P0, HALF], [-HALF, 2.0 + P0]])
    K1 = np.diag([1.0, -1.0])
    res = critical_load(np.eye(2), K0, K1, p_max=1.0, n_scan=64, all_crossings=True)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(P0 - HALF, rel=RTOL)
    assert res.omega == pytest.approx(np.sqrt(2.0), rel=RTOL)
    assert [c.direction for c in res.crossings] == ["loss", "gain"]
    assert res.crossings[0].load == pytest.approx(P0 - HALF, rel=RTOL)
    assert res.crossings[1].load == pytest.approx(P0 + HALF, rel=RTOL)
    assert res.crossings[1].kind == "flutter"
    # without all_crossings the first loss is still found and no crossings are listed
    first = critical_load(np.eye(2), K0, K1, p_max=1.0, n_scan=64)
    assert first.load == pytest.approx(P0 - HALF, rel=RTOL)
    assert first.crossings == ()


P1, P2, WB = 0.42, 1.37, 2.0e-5


def _bubble_family(p):
    """K = [[2 + g, WB], [-WB, 2 - g]], g(p) = (p - P1)(p - P2): s = 2 +- sqrt(g^2 - WB^2),
    complex iff |g(p)| < WB (two bubbles, around P1 and P2)."""
    g = (p - P1) * (p - P2)
    K = np.array([[2.0 + g, WB], [-WB, 2.0 - g]])
    M = np.array([[1.0, 0.0], [0.0, 1.0]])
    return M, None, None, K


def _bubble_edges():
    """Roots of (p - P1)(p - P2) = +-WB, sorted: two bubbles around P1 and P2."""
    edges = []
    for sign in (1.0, -1.0):
        edges += list(np.roots([1.0, -(P1 + P2), P1 * P2 - sign * WB]).real)
    return np.sort(edges)


def test_flutter_bubbles_callable_family():
    edges = _bubble_edges()
    assert edges[1] - edges[0] < 1e-4 and edges[3] - edges[2] < 1e-4
    fam = CallableFamily(_bubble_family, 2)
    res = critical_load_family(fam, 2.0, n_scan=50, all_crossings=True)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(edges[0], rel=RTOL)
    assert [c.direction for c in res.crossings] == ["loss", "gain", "loss", "gain"]
    assert [c.load for c in res.crossings] == pytest.approx(list(edges), rel=RTOL)
    assert all(c.omega == pytest.approx(np.sqrt(2.0), rel=1e-9) for c in res.crossings)


def test_flutter_bubble_callable_through_critical_load():
    edges = _bubble_edges()
    res = critical_load(_bubble_family, p_max=2.0)
    assert res.load == pytest.approx(edges[0], rel=RTOL)


# -- 7. nothing up to p_max -----------------------------------------------------------------
def test_stable_up_to_p_max():
    res = critical_load(M_Z, K0_Z, K1_Z, p_max=2.0, all_crossings=True)
    assert res.kind == "none"
    assert res.load is None
    assert res.omega is None
    assert res.frequency_hz is None
    assert res.crossings == ()
    assert res.p_max == 2.0


def test_stable_damped_up_to_p_max():
    res = critical_load(M_Z, K0_Z, K1_Z, D=0.1 * K0_Z, p_max=1.4)
    assert res.kind == "none" and res.load is None


def test_bubble_just_past_p_max_is_not_reported():
    K0 = np.array([[2.0 - P0, HALF], [-HALF, 2.0 + P0]])
    res = critical_load(np.eye(2), K0, np.diag([1.0, -1.0]), p_max=P0 - 2 * HALF)
    assert res.kind == "none" and res.load is None


# -- 8. input validation --------------------------------------------------------------------
@pytest.mark.parametrize(
    "kwargs",
    [
        dict(M=np.ones((2, 3)), K0=K0_Z, K1=K1_Z),
        dict(M=np.ones(2), K0=K0_Z, K1=K1_Z),
        dict(M=M_Z, K0=np.eye(3), K1=K1_Z),
        dict(M=M_Z, K0=K0_Z, K1=np.ones((2, 3))),
        dict(M=M_Z, K0=K0_Z, K1=np.eye(3)),
        dict(M=M_Z, K0=K0_Z, K1=K1_Z, D=np.eye(3)),
        dict(M=M_Z, K0=K0_Z, K1=K1_Z, G=np.ones((3, 2))),
        dict(M=M_Z, K0=np.array([[np.nan, 0.0], [0.0, 1.0]]), K1=K1_Z),
        dict(M=M_Z, K0=K0_Z, K1=None),
    ],
)
def test_bad_matrices_raise(kwargs):
    with pytest.raises(ValueError):
        critical_load(p_max=5.0, **kwargs)


@pytest.mark.parametrize("p_max", [0.0, -1.0, np.nan, np.inf, -np.inf])
def test_bad_p_max_raises(p_max):
    with pytest.raises(ValueError):
        critical_load(M_Z, K0_Z, K1_Z, p_max=p_max)


@pytest.mark.parametrize("p_max", [0.0, -2.0, np.nan, np.inf])
def test_bad_p_max_raises_for_families(p_max):
    with pytest.raises(ValueError):
        critical_load_family(CallableFamily(_bubble_family, 2), p_max)


def test_callable_with_matrices_raises():
    with pytest.raises(ValueError):
        critical_load(_bubble_family, K0_Z, K1_Z, p_max=1.0)
