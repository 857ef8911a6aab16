"""The compiled small-matrix eigenvalue routine against matrices of known spectrum and LAPACK."""

import numpy as np
import pytest

from impstab.linear.small_eig import MAX_ORDER, eigvals_affine, eigvals_small

EPS = np.finfo(float).eps


def _match(got: np.ndarray, want: np.ndarray) -> float:
    """Largest distance between the two multisets of eigenvalues (greedy nearest matching)."""
    rest = list(want)
    worst = 0.0
    for g in sorted(got, key=lambda z: (z.real, z.imag)):
        k = int(np.argmin([abs(g - w) for w in rest]))
        worst = max(worst, abs(g - rest.pop(k)))
    return worst


def _known(rng, n, complex_pairs):
    """A real matrix ``S B S^-1`` whose eigenvalues are known exactly (B block diagonal)."""
    b = np.zeros((n, n))
    vals = []
    i = 0
    for _ in range(complex_pairs):
        re, im = rng.uniform(-2, 2), rng.uniform(0.1, 3)
        b[i : i + 2, i : i + 2] = [[re, im], [-im, re]]
        vals += [re + 1j * im, re - 1j * im]
        i += 2
    while i < n:
        b[i, i] = rng.uniform(-5, 5)
        vals.append(complex(b[i, i]))
        i += 1
    s = rng.standard_normal((n, n)) + 3 * np.eye(n)
    return s @ b @ np.linalg.inv(s), np.array(vals), np.linalg.cond(s)


@pytest.mark.parametrize("n", [1, 2, 3, 5, 6, 8, 12])
def test_known_spectra(n):
    rng = np.random.default_rng(n)
    for trial in range(40):
        a, vals, cond = _known(rng, n, trial % (n // 2 + 1))
        got = eigvals_small(a[None])[0]
        # backward stable: each eigenvalue within cond(S) * eps * |A| of the exact one
        assert _match(got, vals) <= 50 * cond * EPS * np.abs(a).max() * n


def test_agrees_with_lapack_on_random_stacks():
    rng = np.random.default_rng(7)
    for n in range(1, 13):
        a = rng.standard_normal((300, n, n)) * rng.uniform(0.01, 100, (300, 1, 1))
        got = eigvals_small(a)
        want = np.linalg.eigvals(a)
        for g, w, m in zip(got, want, a):
            assert _match(g, w) <= 1e-9 * np.abs(m).max()
        # trace and determinant: sum and product of the eigenvalues
        np.testing.assert_allclose(got.sum(axis=-1).real, np.trace(a, axis1=1, axis2=2), atol=1e-10 * np.abs(a).max() * n)
        assert np.abs(got.sum(axis=-1).imag).max() <= 1e-10 * np.abs(a).max() * n


def test_complex_pairs_are_exact_conjugates():
    rng = np.random.default_rng(3)
    a = rng.standard_normal((500, 6, 6))
    got = eigvals_small(a)
    for g in got:
        cplx = g[g.imag != 0]
        np.testing.assert_array_equal(np.sort_complex(cplx), np.sort_complex(np.conj(cplx)))


def test_companion_matrix_roots():
    roots = np.array([1.0, 2.0, 3.0, -4.0, 0.5 + 2j, 0.5 - 2j])
    c = np.poly(roots).real
    comp = np.zeros((6, 6))
    comp[0, :] = -c[1:]
    comp[1:, :-1] = np.eye(5)
    assert _match(eigvals_small(comp[None])[0], roots) < 1e-11


def test_defective_double_root_has_sqrt_eps_sensitivity():
    # a Jordan block hidden by a similarity: the double root 2 splits by O(sqrt(eps))
    rng = np.random.default_rng(5)
    s = rng.standard_normal((2, 2)) + 2 * np.eye(2)
    a = s @ np.array([[2.0, 1.0], [0.0, 2.0]]) @ np.linalg.inv(s)
    got = eigvals_small(a[None])[0]
    assert np.abs(got - 2.0).max() < 30 * np.sqrt(EPS)
    assert abs(got.sum() - 4.0) < 1e-13  # the mean is well conditioned


def test_badly_scaled_matrix_is_balanced():
    # D A D^-1 has A's spectrum; entries spanning 24 orders of magnitude
    rng = np.random.default_rng(11)
    a, vals, cond = _known(rng, 6, 1)
    d = np.diag(10.0 ** np.array([-6, -3, 0, 2, 4, 6]))
    scaled = d @ a @ np.linalg.inv(d)
    assert _match(eigvals_small(scaled[None])[0], vals) <= 1e3 * cond * EPS * np.abs(a).max()


def test_special_matrices():
    assert np.all(eigvals_small(np.zeros((1, 4, 4))) == 0)
    tri = np.triu(np.arange(1.0, 26.0).reshape(5, 5))
    np.testing.assert_allclose(np.sort(eigvals_small(tri[None])[0].real), np.sort(np.diag(tri)))
    rot = np.array([[0.0, -1.0], [1.0, 0.0]])
    np.testing.assert_allclose(np.sort_complex(eigvals_small(rot[None])[0]), [-1j, 1j], atol=1e-15)
    # stacks keep their leading shape
    assert eigvals_small(np.ones((2, 3, 4, 4))).shape == (2, 3, 4)


def test_non_finite_and_large_orders_go_to_lapack():
    bad = np.eye(3)[None].copy()
    bad[0, 0, 1] = np.nan
    with pytest.raises(np.linalg.LinAlgError):
        eigvals_small(bad)
    big = np.random.default_rng(1).standard_normal((2, MAX_ORDER + 1, MAX_ORDER + 1))
    assert _match(eigvals_small(big)[0], np.linalg.eigvals(big)[0]) < 1e-10
    with pytest.raises(ValueError, match="square"):
        eigvals_small(np.ones((2, 3)))


def test_affine_family_equals_the_formed_stack():
    rng = np.random.default_rng(8)
    a0, a1 = rng.standard_normal((2, 30, 6, 6))
    loads = rng.uniform(0, 5, (30, 9))
    got = eigvals_affine(a0, a1, loads)
    formed = a0[:, None] + loads[..., None, None] * a1[:, None]
    np.testing.assert_array_equal(got, eigvals_small(formed))
    assert _match(got[3, 4], np.linalg.eigvals(formed[3, 4])) < 1e-12 * np.abs(formed[3, 4]).max()
    loads[2, 1] = np.nan  # a non-finite matrix goes to LAPACK, which refuses it
    with pytest.raises(np.linalg.LinAlgError):
        eigvals_affine(a0, a1, loads)
