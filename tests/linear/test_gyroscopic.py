"""Gyroscopic systems ``M q'' + (D + G) q' + K(p) q = 0``: the engine against independent routes.

Expected values come from closed forms, from the Routh-Hurwitz boundary of the characteristic
quartic ``det(lambda^2 M + lambda (D + G) + K)`` built here with ``numpy.poly1d``, or from a
brute-force scan of ``max Re(lambda)`` of a state matrix built here (``scipy.linalg.eigvals``).

Closed forms used below (M = I, G = g J with J = [[0, -1], [1, 0]], K = diag(k1, k2)):
``det = lambda^4 + (k1 + k2 + g^2) lambda^2 + k1 k2``, a quadratic in ``mu = lambda^2``. The
system is (marginally) stable iff ``k1 k2 > 0``, ``k1 + k2 + g^2 > 0`` and
``(k1 + k2 + g^2)^2 - 4 k1 k2 >= 0``; two negative stiffnesses can be gyroscopically stabilised,
and the stabilisation ends by a coalescence (flutter) of the two frequencies.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from numpy import poly1d
from scipy.optimize import brentq

from impstab.linear import CallableFamily, critical_load, critical_load_family

J = np.array([[0.0, -1.0], [1.0, 0.0]])
RTOL = 1e-10


def charpoly2(M, C, K) -> poly1d:
    """``det(lambda^2 M + lambda C + K)`` of a 2 x 2 system."""
    e = [[poly1d([M[i][j], C[i][j], K[i][j]]) for j in range(2)] for i in range(2)]
    return e[0][0] * e[1][1] - e[0][1] * e[1][0]


def hurwitz3(coeffs) -> float:
    a4, a3, a2, a1, a0 = coeffs
    return a3 * a2 * a1 - a4 * a1**2 - a0 * a3**2


def first_root(f, lo, hi, n=400):
    grid = np.linspace(lo, hi, n + 1)
    vals = np.array([f(p) for p in grid])
    j = np.flatnonzero(np.sign(vals[1:]) != np.sign(vals[:-1]))[0]
    return brentq(f, grid[j], grid[j + 1], xtol=1e-300, rtol=8.9e-16, maxiter=500)


def max_growth(M, C, K) -> float:
    n = len(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-sla.solve(M, K), -sla.solve(M, C)]])
    return float(sla.eigvals(A).real.max())


# -- damped, gyroscopic, circulatory: a transversal Hopf crossing --------------------------------
M_A = np.array([[2.0, 0.3], [0.3, 1.0]])
D_A = np.array([[1.0, 0.2], [0.2, 0.5]])
K0_A = np.array([[3.0, 0.5], [0.5, 1.5]])
K1_A = np.array([[0.0, 1.0], [-1.0, 0.0]])     # circulatory: det K = det K0 + p^2 > 0, no divergence


@pytest.mark.parametrize("d, g", [(0.01, 0.0), (0.01, 0.5), (0.05, 1.0), (0.2, 2.0), (0.002, 0.3)])
def test_damped_gyroscopic_routh_hurwitz(d, g):
    C = d * D_A + g * J

    def h(p):
        return hurwitz3(charpoly2(M_A, C, K0_A + p * K1_A).coeffs)

    p_rh = first_root(h, 0.0, 1.0)
    a4, a3, a2, a1, a0 = charpoly2(M_A, C, K0_A + p_rh * K1_A).coeffs
    assert min(a4, a3, a2, a1, a0) > 0
    res = critical_load(M_A, K0_A, K1_A, D=d * D_A, G=g * J, p_max=1.0)
    assert res.kind == "flutter"
    assert res.method == "hopf"
    assert res.load == pytest.approx(p_rh, rel=RTOL)
    assert res.omega == pytest.approx(np.sqrt(a1 / a3), rel=1e-9)
    # and by brute force on a state matrix built here
    p_bf = first_root(lambda p: max_growth(M_A, C, K0_A + p * K1_A), 0.0, 1.0, n=100)
    assert res.load == pytest.approx(p_bf, rel=1e-9)


def test_load_dependent_gyroscopic_callable():
    """Propeller law: G = g0 sqrt(p) J (spin ~ sqrt(thrust)); D constant; K affine."""
    g0, d = 0.8, 0.03

    def system(p):
        return M_A, d * D_A, g0 * np.sqrt(p) * J, K0_A + p * K1_A

    def h(p):
        return hurwitz3(charpoly2(M_A, d * D_A + g0 * np.sqrt(p) * J, K0_A + p * K1_A).coeffs)

    p_rh = first_root(h, 0.0, 10.0)
    a4, a3, a2, a1, a0 = charpoly2(M_A, d * D_A + g0 * np.sqrt(p_rh) * J, K0_A + p_rh * K1_A).coeffs
    for res in (
        critical_load_family(CallableFamily(system, 2), 10.0),
        critical_load(system, p_max=10.0),
    ):
        assert res.kind == "flutter"
        assert res.load == pytest.approx(p_rh, rel=RTOL)
        assert res.omega == pytest.approx(np.sqrt(a1 / a3), rel=1e-9)


@pytest.mark.parametrize("seed", [0, 1])
def test_damped_gyroscopic_invariant_under_orthogonal_duplicates(seed):
    """Two copies of the damped gyroscopic system, mixed by an orthogonal Q: same onset."""
    d, g = 0.05, 1.0
    C = d * D_A + g * J
    p_rh = first_root(lambda p: hurwitz3(charpoly2(M_A, C, K0_A + p * K1_A).coeffs), 0.0, 10.0)
    q, r = np.linalg.qr(np.random.default_rng(seed).standard_normal((4, 4)))
    Q = q * np.sign(np.diag(r))
    mats = [sla.block_diag(a, a) for a in (M_A, d * D_A, g * J, K0_A, K1_A)]
    M, D, G, K0, K1 = (Q.T @ a @ Q for a in mats)
    res = critical_load(M, K0, K1, D=D, G=G, p_max=10.0)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(p_rh, rel=RTOL)


# -- Jeffcott rotor with internal damping: closed form ---------------------------------------
def jeffcott_fixed(m, k, ce, ci):
    """Fixed frame, z = x + i y: ``m z'' + (ce + ci) z' + k z - i Omega ci z = 0``.

    Affine in the spin ``Omega``: ``K1 = ci [[0, 1], [-1, 0]]`` (circulatory). With
    ``lambda = i w`` on the boundary: ``w^2 = k / m`` and ``(ce + ci) w = Omega ci``.
    """
    return m * np.eye(2), (ce + ci) * np.eye(2), k * np.eye(2), ci * np.array([[0.0, 1.0], [-1.0, 0.0]])


def jeffcott_rotating(m, k, ce, ci):
    """Rotating frame: ``m (xi'' + 2 i Omega xi' - Omega^2 xi) + ce (xi' + i Omega xi) + ci xi'
    + k xi = 0`` -> G = 2 m Omega J, K = (k - m Omega^2) I + ce Omega J (not affine in Omega).
    Same real parts as in the fixed frame, frequencies shifted by Omega."""

    def system(W):
        return m * np.eye(2), (ce + ci) * np.eye(2), 2 * m * W * J, (k - m * W**2) * np.eye(2) + ce * W * J

    return system


@pytest.mark.parametrize("m, k, ce, ci", [(1.0, 1.0, 0.02, 0.05), (2.5, 40.0, 0.3, 0.1), (0.1, 7.0, 1e-3, 2e-3)])
def test_jeffcott_rotor_fixed_and_rotating_frames(m, k, ce, ci):
    wn = np.sqrt(k / m)
    w_cr = wn * (1 + ce / ci)
    p_max = 3 * w_cr
    M, D, K0, K1 = jeffcott_fixed(m, k, ce, ci)
    fixed = critical_load(M, K0, K1, D=D, p_max=p_max)
    assert fixed.kind == "flutter"
    assert fixed.load == pytest.approx(w_cr, rel=RTOL)
    assert fixed.omega == pytest.approx(wn, rel=1e-9)              # forward whirl at wn
    system = jeffcott_rotating(m, k, ce, ci)
    rot = critical_load_family(CallableFamily(system, 2), p_max)
    assert rot.kind == "flutter"
    assert rot.load == pytest.approx(w_cr, rel=RTOL)
    assert rot.omega == pytest.approx(w_cr - wn, rel=1e-9)         # seen from the rotor
    # Routh-Hurwitz on the rotating-frame quartic agrees
    def h(W):
        m_, d_, g_, k_ = system(W)
        return hurwitz3(charpoly2(m_, d_ + g_, k_).coeffs)

    p_rh = first_root(h, 0.0, p_max)
    assert p_rh == pytest.approx(w_cr, rel=1e-12)


# -- gyroscopic stabilisation and destabilisation by damping ------------------------------------
K_EQ, G_EQ = 1.0, 1.2


def test_gyroscopic_stabilisation_then_coalescence_undamped():
    """K = (k - p) I, G = g J: stable past p = k (gyroscopic stabilisation) until
    ``(2 (k - p) + g^2)^2 - 4 (k - p)^2 = g^2 (4 (k - p) + g^2)`` turns negative:
    flutter at ``p = k + g^2 / 4`` with the double root ``lambda = +- i g / 2``."""
    res = critical_load(np.eye(2), K_EQ * np.eye(2), -np.eye(2), G=G_EQ * J, p_max=3.0)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(K_EQ + G_EQ**2 / 4, rel=RTOL)
    assert res.omega == pytest.approx(G_EQ / 2, rel=1e-6)


@pytest.mark.parametrize("d", [1e-3, 1e-2, 0.1])
def test_destabilisation_of_gyroscopic_stabilisation_by_damping(d):
    """With D = d I the negative stiffness cannot be held (Kelvin-Tait-Chetaev): p_cr = k.

    In z = x + i y: ``lambda^2 + (d + i g) lambda + (k - p) = 0``; for small ``k - p``,
    ``lambda = -(k - p)(d - i g) / (d^2 + g^2)`` crosses into Re > 0 through the origin at
    ``p = k`` (zero frequency), far below the undamped ``k + g^2 / 4``.
    """
    res = critical_load(np.eye(2), K_EQ * np.eye(2), -np.eye(2), D=d * np.eye(2), G=G_EQ * J, p_max=3.0)
    assert res.load == pytest.approx(K_EQ, rel=RTOL)
    # onset at zero frequency; the unstable root beyond it is complex, so "divergence" and
    # "flutter" are both defensible names and the kind is not asserted
    assert res.omega == pytest.approx(0.0, abs=1e-8)
    undamped = critical_load(np.eye(2), K_EQ * np.eye(2), -np.eye(2), G=G_EQ * J, p_max=3.0)
    assert res.load < undamped.load - 0.3


def test_undamped_gyroscopic_all_crossings():
    """K = diag(k1 - p, k2 - p), G = g J: divergence at k1, restabilised at k2 (two negative
    stiffnesses held by the gyroscopic coupling), flutter at
    ``p_f = (k1 + k2)/2 + ((k1 - k2)^2 + g^4) / (4 g^2)`` where ``mu = lambda^2`` is double."""
    k1, k2, g = 1.0, 1.5, 2.0
    p_f = (k1 + k2) / 2 + ((k1 - k2) ** 2 + g**4) / (4 * g**2)
    # the discriminant in mu vanishes at p_f (independent check of the closed form)
    a, b = k1 - p_f, k2 - p_f
    assert (a + b + g**2) ** 2 - 4 * a * b == pytest.approx(0.0, abs=1e-12)
    res = critical_load(np.eye(2), np.diag([k1, k2]), -np.eye(2), G=g * J, p_max=3.0, all_crossings=True)
    assert res.load == pytest.approx(k1, rel=RTOL)
    assert res.kind == "divergence"
    assert [c.direction for c in res.crossings] == ["loss", "gain", "loss"]
    assert [c.load for c in res.crossings] == pytest.approx([k1, k2, p_f], rel=1e-9)
    assert [c.kind for c in res.crossings] == ["divergence", "divergence", "flutter"]
    assert res.crossings[2].omega == pytest.approx(np.sqrt((k1 + k2 - 2 * p_f + g**2) / 2), rel=1e-6)
