"""The refinement's choice of the merging modes does not depend on the basis of a repeated eigenvalue.

A symmetric layout doubles some eigenvalues; where a mode merges with one combination of such a
pair, the cluster the refinement follows holds that combination and not the other, and the share
of each column of a decomposition in the cluster's subspace depends on the basis the
decomposition returned for the doubled eigenspace (the compiled routines and LAPACK return
different ones). Independent answer, built here: an operator ``A = V diag(lambda) V^-1`` with a
semisimple doubled eigenvalue, and a cluster subspace spanned by a chosen combination ``g`` of the
doubled pair and one other eigenvector. Given any basis of the doubled eigenspace, the selection
must pick ``g`` (share 1, to rounding) and that other column, leave the orthogonal combination out
(share 0), and leave a valid decomposition behind.
"""

from __future__ import annotations

import numpy as np
import pytest

from impstab._jit import require_compiled
from impstab.linear.engine import cluster

N = 8
THETA = 0.7  # the cluster's combination of the doubled pair: cos(THETA) v0 + sin(THETA) v1


def _problem(seed: int = 3):
    rng = np.random.default_rng(seed)
    v = rng.standard_normal((N, N)) + 1j * rng.standard_normal((N, N))
    v /= np.linalg.norm(v, axis=0)
    lam = np.array([2.0 + 5.0j, 2.0 + 5.0j, 2.1 + 5.3j, -1.0, 3.0j, -3.0j, 0.5 + 1.0j, 7.0])
    a = v @ np.diag(lam) @ np.linalg.inv(v)
    # the cluster subspace: g (in the doubled eigenspace) and v2; its complement: h (the other
    # combination of the doubled pair) and v3...
    c, s = np.cos(THETA), np.sin(THETA)
    g, h = c * v[:, 0] + s * v[:, 1], -s * v[:, 0] + c * v[:, 1]
    basis = np.column_stack([g, v[:, 2], h, v[:, 3:]])
    inv = np.linalg.inv(basis)
    vc, wc = np.ascontiguousarray(basis[:, :2]), np.ascontiguousarray(inv[:2])
    return a, lam, v, g / np.linalg.norm(g), vc, wc


def _decomposition(lam, v, mixing):
    """``(vals, vecs, inv)`` with the doubled eigenspace's basis ``v[:, :2] @ mixing``, unit columns."""
    vecs = v.copy()
    vecs[:, :2] = v[:, :2] @ mixing
    vecs /= np.linalg.norm(vecs, axis=0)
    return lam.astype(complex).copy(), np.ascontiguousarray(vecs), np.ascontiguousarray(np.linalg.inv(vecs))


def _mixings():
    rng = np.random.default_rng(11)
    out = [np.eye(2), np.array([[1.0, 1.0], [1.0, -1.0]]), np.array([[1.0, 0.9], [0.0, 0.4]])]
    out += [rng.standard_normal((2, 2)) + 1j * rng.standard_normal((2, 2)) for _ in range(5)]
    return out


def _raw_shares(vecs, vc, wc):
    proj = vc @ (wc @ vecs)
    return (np.abs(proj) ** 2).sum(axis=0)


@pytest.mark.parametrize("way", ["interpreted", "compiled"])
def test_the_selection_does_not_depend_on_the_basis_of_a_doubled_eigenspace(way):
    if way == "compiled":
        require_compiled()
    select = cluster._select_numpy if way == "interpreted" else cluster.select
    a, lam, v, g, vc, wc = _problem()
    ambiguous = 0
    for mixing in _mixings():
        vals, vecs, inv = _decomposition(lam, v, mixing)
        raw = _raw_shares(vecs, vc, wc)
        ambiguous += bool(min(raw[0], raw[1]) > 0.25)  # both columns would count as in the cluster
        sel, share, work = np.zeros(2, np.int64), np.zeros(N), np.zeros((3, N), complex)
        assert select(vals, vecs, inv, vc, wc, 2, sel, share, work)
        assert sorted(sel) == [0, 2]
        assert abs(share[0] - 1.0) < 1e-12 and abs(share[1]) < 1e-12 and abs(share[2] - 1.0) < 1e-12
        assert abs(abs(np.vdot(g, vecs[:, 0])) - 1.0) < 1e-12  # the first column is g (to its phase)
        # still one decomposition: unit columns, inv = vecs^-1, A vecs = vecs diag(vals)
        np.testing.assert_allclose(np.linalg.norm(vecs, axis=0), 1.0, atol=1e-13)
        np.testing.assert_allclose(inv @ vecs, np.eye(N), atol=1e-12)
        np.testing.assert_allclose(a @ vecs, vecs * vals, atol=1e-12 * np.abs(a).max())
    assert ambiguous >= 2  # the bases given include ones that the plain shares cannot decide


def test_nearly_parallel_or_distinct_columns_are_left_alone():
    a, lam, v, g, vc, wc = _problem()
    # distinct eigenvalues: nothing turned
    lam2 = lam.copy()
    lam2[1] += 1e-6
    vals, vecs, inv = _decomposition(lam2, v, np.array([[1.0, 1.0], [1.0, -1.0]]))
    before = vecs.copy()
    cluster.align_repeated(vals, vecs, inv, vc, wc, 2, np.zeros(N), np.zeros((3, N), complex))
    np.testing.assert_array_equal(vecs, before)
    # a defective-looking pair (columns at a cosine of 1 - 1e-10): nothing turned either
    vals, vecs, inv = _decomposition(lam, v, np.eye(2))
    vecs[:, 1] = vecs[:, 0] + 1e-5 * vecs[:, 1]
    vecs[:, 1] /= np.linalg.norm(vecs[:, 1])
    before = vecs.copy()
    cluster.align_repeated(vals, vecs, inv, vc, wc, 2, np.zeros(N), np.zeros((3, N), complex))
    np.testing.assert_array_equal(vecs, before)
