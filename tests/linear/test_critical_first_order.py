"""The engine on first-order systems ``E x' = A(p) x`` against independent answers.

* Ziegler's pendulum (THEORY 10) written in first-order form: undamped flutter at
  ``7/2 - sqrt 2`` (on the state matrix, where the frequencies merge on the imaginary axis),
  damped ``41/28 + b^2/2`` and the Routh-Hurwitz boundary of the characteristic quartic.
* A first-order system equal to a second-order one (the same onset to rounding), affine and not.
* Springs that are standard linear solids (an internal state per spring):
  ``k*(w) = k (1 + i w s tau) / (1 + i w tau)``, realised by ``tau z' = d - z`` and the force
  ``k (s d + (1 - s) z)``. One dof under a dead load: divergence at the static stiffness ``k``
  (not ``s k``). Ziegler's pendulum with such springs at both hinges: the Routh-Hurwitz boundary
  of its degree-6 characteristic polynomial ``det(lambda^2 M + k*(lambda)/c K0 + p K1) (1 + lambda tau)^2``,
  built here with ``numpy.poly1d``, the first sign change of the Hurwitz determinant by brentq.
* A flutter bubble narrower than the scan spacing in an undamped first-order system.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy import poly1d
from scipy.optimize import brentq

import impstab
from impstab.linear import LinearFirstOrderFamily, critical_load, critical_load_family
from impstab.model import model_from_dict
from impstab.model.assemble import read_toml

M_Z = np.array([[3.0, 1.0], [1.0, 1.0]])
K0_Z = np.array([[2.0, -1.0], [-1.0, 1.0]])
K1_Z = -np.array([[1.0, -1.0], [0.0, 0.0]])
C_Z = np.array([[1.0, 0.0], [-1.0, 1.0]])  # hinge rotations d = C q; K0_Z = C^T C
P_FLUTTER = 3.5 - np.sqrt(2.0)


def state_space(M, D, K0, K1):
    """``E = [[I, 0], [0, M]]``, ``A0 = [[0, I], [-K0, -D]]``, ``A1 = [[0, 0], [-K1, 0]]``."""
    n = len(M)
    z, i = np.zeros((n, n)), np.eye(n)
    return np.block([[z, i], [-K0, -D]]), np.block([[z, z], [-K1, z]]), np.block([[i, z], [z, M]])


def hurwitz(coeffs) -> np.ndarray:
    """The Hurwitz matrix of ``a0 l^n + a1 l^(n-1) + ... + an`` (a0 > 0), order n."""
    a = np.asarray(coeffs, dtype=float)
    n = len(a) - 1
    h = np.zeros((n, n))
    for r in range(n):
        for c in range(n):
            k = 2 * c - r + 1
            if 0 <= k <= n:
                h[r, c] = a[k]
    return h


def first_hurwitz_boundary(poly_of, lo, hi, steps=400):
    """First p where the Hurwitz determinant of order n-1 changes sign (a pair crosses the axis)."""
    def det(p):
        h = hurwitz(poly_of(p).coeffs)
        return np.linalg.det(h[:-1, :-1])

    grid = np.linspace(lo, hi, steps + 1)
    vals = np.array([det(p) for p in grid])
    assert vals[0] > 0 and np.all(poly_of(lo).coeffs > 0)
    j = np.flatnonzero(np.sign(vals[1:]) != np.sign(vals[:-1]))[0]
    return brentq(det, grid[j], grid[j + 1], xtol=1e-300, rtol=8.9e-16, maxiter=500)


# -- Ziegler's pendulum in first-order form ------------------------------------------------------------
def test_ziegler_undamped_first_order_is_exact():
    """The frequencies merge on the imaginary axis: the cluster's upper-half discriminant is exact."""
    A0, A1, E = state_space(M_Z, np.zeros((2, 2)), K0_Z, K1_Z)
    res = critical_load(A0=A0, A1=A1, E=E, p_max=5.0)
    assert res.kind == "flutter" and res.method == "hopf"
    assert res.load == pytest.approx(P_FLUTTER, rel=1e-14)
    assert res.omega == pytest.approx(2.0**-0.25, rel=1e-9)
    # the state matrix itself (E = I) gives the same
    same = critical_load(A0=np.linalg.solve(E, A0), A1=np.linalg.solve(E, A1), p_max=5.0)
    assert same.load == pytest.approx(P_FLUTTER, rel=1e-14)


@pytest.mark.parametrize("b", [1e-4, 1e-3, 1e-2, 0.1, 0.5])
def test_ziegler_damped_first_order(b):
    A0, A1, E = state_space(M_Z, b * K0_Z, K0_Z, K1_Z)
    res = critical_load(A0=A0, A1=A1, E=E, p_max=4.0)
    quartic = lambda p: (poly1d([3, 2 * b, 2 - p]) * poly1d([1, b, 1]) - poly1d([1, -b, p - 1]) * poly1d([1, -b, -1]))  # noqa: E731
    p_rh = first_hurwitz_boundary(quartic, 0.0, 4.0)
    assert p_rh == pytest.approx(41 / 28 + b**2 / 2, rel=1e-13)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(41 / 28 + b**2 / 2, rel=max(1e-12, 1e-15 / b))
    a = quartic(p_rh).coeffs
    assert res.omega == pytest.approx(np.sqrt(a[3] / a[1]), rel=1e-9)


def test_first_order_family_names_the_displacements():
    """With ``n_dof`` and the masses as weights, the mode and participation are those of q."""
    A0, A1, E = state_space(M_Z, 0.1 * K0_Z, K0_Z, K1_Z)
    first = critical_load_family(LinearFirstOrderFamily.build(A0, A1, E, n_dof=2, weights=np.diag(M_Z)), 4.0)
    second = critical_load(M_Z, K0_Z, K1_Z, D=0.1 * K0_Z, p_max=4.0)
    assert first.load == pytest.approx(second.load, rel=1e-13)
    assert first.mode.shape == (2,) and first.participation == pytest.approx(second.participation, abs=1e-9)


# -- a first-order system equal to a second-order one ------------------------------------------------
def _damped_asymmetric():
    d = read_toml("examples/imp_asymmetric.toml")
    d["analysis"]["linearization"] = "classical"
    model = model_from_dict(d)
    lin0, lin1 = impstab.linearize(model, 0.0), impstab.linearize(model, 1.0)
    return model, lin0.M, lin0.K, lin1.K - lin0.K


def test_affine_first_order_equals_second_order():
    model, M, K0, K1 = _damped_asymmetric()
    D = 2e-4 * K0  # stiffness-proportional damping: the onset moves, still a Hopf crossing
    second = critical_load(M, K0, K1, D=D, p_max=model.analysis.thrust_max)
    A0, A1, E = state_space(M, D, K0, K1)
    first = critical_load(A0=A0, A1=A1, E=E, p_max=model.analysis.thrust_max)
    assert second.kind == first.kind == "flutter"
    assert first.load == pytest.approx(second.load, rel=1e-12)
    assert first.omega == pytest.approx(second.omega, rel=1e-10)


def test_callable_first_order_equals_second_order_of_a_spinning_model():
    """The damped example with a propeller whose speed follows sqrt(thrust): not affine; the
    first-order form from LinearSystem.first_order() at each thrust gives critical_thrust's onset."""
    model = impstab.load_model("examples/imp_damped.toml")
    ref = impstab.critical_thrust(model)
    res = critical_load(A=lambda t: impstab.linearize(model, t).first_order(), p_max=model.analysis.thrust_max)
    assert res.kind == ref.kind
    assert res.load == pytest.approx(ref.thrust, rel=1e-10)
    e, a = impstab.linearize(model, 3000.0).first_order()
    np.testing.assert_allclose(np.linalg.solve(e, a), impstab.linearize(model, 3000.0).state_matrix(), rtol=0,
                               atol=1e-12 * np.abs(a).max())


# -- standard-linear-solid springs: an internal state per spring ---------------------------------------
def sls_system(M, C, c, s, tau, K1):
    """``M q'' + c C^T (s C q + (1 - s) z) + p K1 q = 0``, ``tau z' = C q - z``; x = (q, q', z)."""
    n, h = len(M), len(C)
    z_nn, z_nh, z_hn = np.zeros((n, n)), np.zeros((n, h)), np.zeros((h, n))
    A0 = np.block([[z_nn, np.eye(n), z_nh], [-c * s * C.T @ C, z_nn, -c * (1 - s) * C.T], [C, z_hn, -np.eye(h)]])
    A1 = np.zeros_like(A0)
    A1[n:2 * n, :n] = -K1
    E = np.eye(2 * n + h)
    E[n:2 * n, n:2 * n] = M
    E[2 * n:, 2 * n:] = tau * np.eye(h)
    return A0, A1, E


@pytest.mark.parametrize("s, tau", [(2.0, 0.5), (5.0, 0.05), (1.5, 3.0)])
def test_single_dof_sls_diverges_at_its_static_stiffness(s, tau):
    """m x'' + k (s x + (1 - s) z) - p x = 0: the static (relaxed) stiffness k decides, p_c = k."""
    m, k = 2.0, 30.0
    A0, A1, E = sls_system(np.array([[m]]), np.eye(1), k, s, tau, -np.eye(1))
    res = critical_load(A0=A0, A1=A1, E=E, p_max=2 * s * k)
    assert res.kind == "divergence" and res.omega == 0.0
    assert res.load == pytest.approx(k, rel=1e-12)


@pytest.mark.parametrize("s, tau", [(2.0, 0.3), (1.2, 1.0), (3.0, 0.05), (1.05, 5.0)])
def test_ziegler_with_sls_springs_routh_hurwitz(s, tau):
    """k*(lambda) = c (1 + lambda tau s) / (1 + lambda tau) at both hinges (m = l = c = 1)."""

    def poly(p):
        one = poly1d([tau, 1.0])
        kst = poly1d([tau * s, 1.0])
        e = [[poly1d([M_Z[i][j], 0, 0]) * one + kst * K0_Z[i][j] + one * (p * K1_Z[i][j]) for j in range(2)]
             for i in range(2)]
        return e[0][0] * e[1][1] - e[0][1] * e[1][0]

    p_rh = first_hurwitz_boundary(poly, 0.0, 4.0)
    A0, A1, E = sls_system(M_Z, C_Z, 1.0, s, tau, K1_Z)
    res = critical_load(A0=A0, A1=A1, E=E, p_max=4.0)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(p_rh, rel=1e-10)
    # the state-space eigenvalues are the roots of the characteristic polynomial
    lam = np.linalg.eigvals(np.linalg.solve(E, A0 + 1.0 * A1))
    roots = poly(1.0).roots
    assert np.abs(np.sort_complex(lam) - np.sort_complex(roots)).max() < 1e-8 * np.abs(roots).max()


# -- bubbles ---------------------------------------------------------------------------------------
P0, HALF = 0.3712, 1.0e-4


def test_flutter_bubble_of_an_undamped_first_order_system():
    """M = I, K(p) = [[2 + (p - P0), w], [-w, 2 - (p - P0)]]: the frequencies touch in
    (P0 - w, P0 + w), narrower than the scan spacing; written in first-order form."""
    K0 = np.array([[2.0 - P0, HALF], [-HALF, 2.0 + P0]])
    A0, A1, E = state_space(np.eye(2), np.zeros((2, 2)), K0, np.diag([1.0, -1.0]))
    res = critical_load(A0=A0, A1=A1, E=E, p_max=1.0, all_crossings=True)
    assert res.kind == "flutter"
    assert res.load == pytest.approx(P0 - HALF, rel=1e-10)
    assert [c.direction for c in res.crossings] == ["loss", "gain"]
    assert res.crossings[1].load == pytest.approx(P0 + HALF, rel=1e-10)


# -- input validation ------------------------------------------------------------------------------
@pytest.mark.parametrize("kwargs", [
    dict(A0=np.eye(2)),
    dict(A0=np.eye(2), A1=np.eye(3)),
    dict(A0=np.eye(2), A1=np.eye(2), E=np.zeros((2, 2))),
    dict(A0=np.eye(2), A1=np.eye(2), M=np.eye(2)),
    dict(A=np.eye(2)),
    dict(A=lambda p: np.eye(2), A0=np.eye(2)),
    dict(M=np.eye(2), K0=np.eye(2), K1=np.eye(2), E=np.eye(2)),
])
def test_bad_first_order_input_raises(kwargs):
    with pytest.raises(ValueError):
        critical_load(p_max=1.0, **kwargs)
