"""The refinement's choice of the cluster's eigenvectors (``impstab.linear.engine.cluster.select``).

The compiled routine picks the ``k`` columns with the largest share one by one; the reference here
is NumPy's stable sort of the same shares, computed here as two matrix products. Ties (identical
planes of a symmetric layout give equal shares) must come out in column order, NaN shares last.
"""

from __future__ import annotations

import numpy as np
import pytest

from impstab._jit import require_compiled


def _reference(vecs, vc, wc, k):
    proj = vc[:, :k] @ (wc[:k] @ vecs)
    share = (np.abs(proj) ** 2).sum(axis=0)
    order = np.argsort(-share, kind="stable")
    clear = share[order[k - 1]] > 0.25 and (len(share) == k or share[order[k]] < 0.25)
    return share, order[:k], clear


def _case(rng, n, k, ties):
    vecs = rng.normal(size=(n, n)) + 1j * rng.normal(size=(n, n))
    vecs /= np.linalg.norm(vecs, axis=0)
    if ties:  # repeated columns: equal shares
        vecs[:, 1::2] = vecs[:, 0:1]
    vc = rng.normal(size=(n, n)) + 1j * rng.normal(size=(n, n))
    wc = np.linalg.pinv(vc).astype(complex)
    return vecs, np.ascontiguousarray(vc), np.ascontiguousarray(wc)


@pytest.mark.parametrize("ties", [False, True])
@pytest.mark.parametrize("n,k", [(2, 1), (2, 2), (4, 2), (6, 2), (6, 4), (12, 4), (12, 12)])
def test_select_matches_a_stable_sort_of_the_shares(n, k, ties):
    require_compiled()
    from impstab.linear.engine.cluster import select

    rng = np.random.default_rng(10 * n + k + ties)
    for _ in range(20):
        vecs, vc, wc = _case(rng, n, k, ties)
        share, order, clear = _reference(vecs, vc, wc, k)
        sel = np.full(n, -1, dtype=np.int64)
        got_share = np.empty(n)
        # distinct eigenvalues: no repeated eigenspace to turn (tests/linear/test_repeated_eigenspace.py)
        vals = (1.0 + 1.0j) * np.arange(1, n + 1)
        got = select(vals, vecs, np.zeros((n, n), complex), vc, wc, np.int64(k), sel, got_share,
                     np.empty((3, n), dtype=complex))
        np.testing.assert_allclose(got_share, share, rtol=1e-12, atol=1e-14)
        picked = share[sel[:k]]
        # the same shares as the sort's first k, in decreasing order; the same columns where the
        # shares are apart by more than rounding (equal ones, such as all of them when k = n, may
        # differ in the last bit and so come in either order)
        np.testing.assert_allclose(picked, share[order], rtol=1e-12, atol=1e-14)
        if np.all(np.abs(np.diff(np.sort(share))) > 1e-9):
            assert list(sel[:k]) == list(order)
        assert bool(got) == bool(clear)


def test_select_takes_exact_ties_in_column_order_and_nan_last():
    require_compiled()
    from impstab.linear.engine.cluster import _next_largest

    share = np.array([0.5, np.nan, 0.9, 0.5, 0.9, np.nan, 0.1])
    sel = np.full(len(share), -1, dtype=np.int64)
    for i in range(len(share)):
        sel[i] = _next_largest(share, len(share), sel, i)
    assert list(sel) == list(np.argsort(-share, kind="stable"))  # [2, 4, 0, 3, 6, 1, 5]
