"""Decoupled blocks and their closed-form eigenproblems against LAPACK and exact spectra."""

import numpy as np
import pytest

import impstab
from impstab.linear.blocks import TOL_DECOUPLE, _eig_blocks, decoupled_blocks, eig_affine, eigvals_affine_blocks
from impstab.linear.linearize import ModelFamily
from impstab.linear.small_eig import eigvals_affine
from test_small_eig import _match  # greedy matching of two eigenvalue multisets

EPS = np.finfo(float).eps


def _hidden_blocks(rng, sizes, scale_units=True):
    """``A0, A1`` block diagonal with the given block sizes, dofs shuffled, units mixed."""
    n = sum(sizes)
    a0, a1 = np.zeros((n, n)), np.zeros((n, n))
    i = 0
    for s in sizes:
        a0[i : i + s, i : i + s] = rng.standard_normal((s, s)) + 4 * np.eye(s)
        a1[i : i + s, i : i + s] = rng.standard_normal((s, s)) * 0.1
        i += s
    perm = rng.permutation(n)
    a0, a1 = a0[np.ix_(perm, perm)], a1[np.ix_(perm, perm)]
    if scale_units:  # a diagonal similarity (translations in m, rotations in rad): same spectrum
        d = 10.0 ** rng.uniform(-2, 2, n)
        a0, a1 = a0 * d[:, None] / d[None, :], a1 * d[:, None] / d[None, :]
    return a0, a1, perm


def _block_sets(bs, row=0):
    return sorted(
        tuple(sorted(bs.order[row, bs.starts[row, b] : bs.starts[row, b + 1]].tolist())) for b in range(bs.nblocks[row])
    )


@pytest.mark.parametrize("sizes", [(1, 1, 2, 2), (2, 2, 2), (3, 1, 2), (6,), (1,) * 6, (4, 2)])
def test_structure_finds_the_hidden_blocks(sizes):
    rng = np.random.default_rng(sum(sizes) * 7 + len(sizes))
    a0, a1, perm = _hidden_blocks(rng, sizes)
    bs = decoupled_blocks(a0[None], a1[None], np.array([10.0]))
    want, i = [], 0
    for s in sizes:
        want.append(tuple(sorted(int(np.flatnonzero(perm == k)[0]) for k in range(i, i + s))))
        i += s
    assert _block_sets(bs) == sorted(want)
    assert bs.largest[0] == max(sizes)


def test_rounding_couplings_are_dropped_and_real_ones_kept():
    rng = np.random.default_rng(3)
    a0, a1, _ = _hidden_blocks(rng, (2, 2, 1, 1), scale_units=False)
    norm = np.abs(a0).max()
    # residues of symmetric sums, far below the threshold: still four blocks
    noise = rng.standard_normal(a0.shape) * norm * 1e-17 * (np.abs(a0) == 0)
    bs = decoupled_blocks((a0 + noise)[None], a1[None], np.array([1.0]))
    assert bs.nblocks[0] == 4
    # a real coupling (1e-12 of the norm, above TOL_DECOUPLE) joins two blocks, in either direction
    i, j = np.nonzero((np.abs(a0) == 0))
    a0c = a0.copy()
    a0c[i[0], j[0]] = 1e-12 * norm
    assert 1e-12 > 8 * TOL_DECOUPLE
    bs = decoupled_blocks(a0c[None], a1[None], np.array([1.0]))
    assert bs.nblocks[0] == 3
    # a coupling through the load term only counts over the load range
    a1c = a1.copy()
    a1c[i[0], j[0]] = 1e-3 * norm
    assert decoupled_blocks(a0[None], a1c[None], np.array([1e-20])).nblocks[0] == 4
    assert decoupled_blocks(a0[None], a1c[None], np.array([1.0])).nblocks[0] == 3
    # an operator that is not finite is one block
    a0n = a0.copy()
    a0n[0, 0] = np.nan
    assert decoupled_blocks(a0n[None], a1[None], np.array([1.0])).nblocks[0] == 1


@pytest.mark.parametrize("sizes", [(1, 1, 2, 2), (3, 1, 2), (6,), (2, 2, 2)])
def test_block_eigenvalues_equal_lapack(sizes):
    rng = np.random.default_rng(len(sizes) * 31 + sizes[0])
    a0s, a1s = [], []
    for _ in range(40):
        a0, a1, _ = _hidden_blocks(rng, sizes)
        a0s.append(a0)
        a1s.append(a1)
    a0, a1 = np.array(a0s), np.array(a1s)
    loads = rng.uniform(0, 40, (40, 7))  # large enough that many blocks have complex pairs
    bs = decoupled_blocks(a0, a1, loads.max(axis=1))
    got = eigvals_affine_blocks(a0, a1, loads, bs)
    n_complex = 0
    for s in range(40):
        for k in range(7):
            a = a0[s] + loads[s, k] * a1[s]
            want = np.linalg.eigvals(a)
            n_complex += np.sum(np.abs(want.imag) > 1e-8)
            # a well-separated spectrum: eigenvalues to a modest multiple of cond * eps |A|
            _, vecs = np.linalg.eig(a)
            cond = np.linalg.cond(vecs)
            assert _match(got[s, k], want) <= 100 * cond * EPS * np.abs(a).max()
    assert n_complex > 0


def test_two_by_two_closed_form_exact_cases():
    """Closed form on matrices with exactly known eigenvalues (no rounding in the answer)."""
    cases = [
        ([[2.0, 0.0], [0.0, 5.0]], [2.0, 5.0]),
        ([[3.0, 1.0], [0.0, 3.0]], [3.0, 3.0]),  # a Jordan block
        ([[0.0, 1.0], [-4.0, 0.0]], [2j, -2j]),
        ([[1.0, 2.0], [2.0, 1.0]], [3.0, -1.0]),
        ([[5.0, 0.0], [0.0, 5.0]], [5.0, 5.0]),
        ([[1.0, -8.0], [2.0, 1.0]], [1 + 4j, 1 - 4j]),
    ]
    for m, want in cases:
        a0 = np.array(m)[None]
        bs = decoupled_blocks(a0, np.zeros_like(a0), np.array([1.0]))
        got = eigvals_affine_blocks(a0, np.zeros_like(a0), np.zeros((1, 1)), bs)[0, 0]
        assert _match(got, np.array(want, dtype=complex)) == 0.0


def test_eigenvectors_and_inverse():
    rng = np.random.default_rng(5)
    a0, a1 = [], []
    for sizes in [(1, 1, 2, 2)] * 20 + [(3, 3)] * 5 + [(6,)] * 5:
        x, y, _ = _hidden_blocks(rng, sizes)
        a0.append(x)
        a1.append(y)
    a0, a1 = np.array(a0), np.array(a1)
    loads = rng.uniform(0, 40, len(a0))
    bs = decoupled_blocks(a0, a1, loads + 1)
    vals, vecs, inv, ok = eig_affine(a0, a1, loads, bs)
    assert ok.all()
    for s in range(len(a0)):
        a = a0[s] + loads[s] * a1[s]
        cond = np.linalg.cond(vecs[s])
        assert np.abs(a @ vecs[s] - vecs[s] * vals[s]).max() <= 50 * EPS * np.abs(a).max() * cond
        assert np.allclose(np.linalg.norm(vecs[s], axis=0), 1.0, rtol=0, atol=4 * EPS)
        assert np.abs(inv[s] @ vecs[s] - np.eye(6)).max() <= 50 * EPS * cond
        assert _match(vals[s], np.linalg.eigvals(a)) <= 100 * cond * EPS * np.abs(a).max()


def test_defective_block_goes_to_lapack_and_reports():
    """A 2 x 2 Jordan block: parallel eigenvectors, no inverse -> LAPACK, then not ok."""
    a0 = np.zeros((1, 4, 4))
    a0[0, :2, :2] = [[3.0, 1.0], [0.0, 3.0]]
    a0[0, 2, 2], a0[0, 3, 3] = 1.0, 2.0
    a1 = np.zeros_like(a0)
    bs = decoupled_blocks(a0, a1, np.array([1.0]))
    assert bs.largest[0] == 2
    vals, vecs, inv, ok = eig_affine(a0, a1, np.zeros(1), bs)
    # LAPACK's vectors of a Jordan block are parallel to rounding, not exactly: whichever route,
    # either the inverse is refused or it is huge (the defect is visible, never hidden)
    assert (not ok[0]) or np.abs(inv[0]).max() > 1e12


def test_symmetric_propulsor_splits_into_its_planes():
    """The paper's symmetric layout: surge, roll, sway-yaw and heave-pitch (Figure 4)."""
    model = impstab.load_model("examples/imp_symmetric.toml")
    m, _, _, k0, k1 = ModelFamily(model).affine_parts()
    a0, a1 = np.linalg.solve(m, k0)[None], np.linalg.solve(m, k1)[None]
    assert np.count_nonzero(np.abs(a0[0]) < 1e-10 * np.abs(a0).max() * (a0[0] != 0)) > 0  # rounding residues exist
    bs = decoupled_blocks(a0, a1, np.array([2e4]))
    assert _block_sets(bs) == [(0,), (1, 5), (2, 4), (3,)]
    loads = np.linspace(0, 2e4, 65)[None]
    got = eigvals_affine_blocks(a0, a1, loads, bs)
    want = eigvals_affine(a0, a1, loads)
    for k in range(65):
        assert _match(got[0, k], want[0, k]) <= 1e-11 * np.abs(want[0, k]).max()


def test_asymmetric_propulsor_stays_coupled():
    model = impstab.load_model("examples/imp_asymmetric.toml")
    fam = ModelFamily(model, "classical")
    m, _, _, k0, k1 = fam.affine_parts()
    bs = decoupled_blocks(np.linalg.solve(m, k0)[None], np.linalg.solve(m, k1)[None], np.array([1e4]))
    assert bs.largest[0] >= 3


def test_defective_larger_block_falls_back_without_raising():
    """A 3 x 3 Jordan block: inverse iteration finds one vector three times, the eigenvector
    matrix is singular, and LAPACK's route takes over (which reports it or returns a huge
    inverse); nothing raises, and a regular design in the same batch is solved."""
    a0 = np.zeros((2, 5, 5))
    a0[0, :3, :3] = [[2.0, 1.0, 0.0], [0.0, 2.0, 1.0], [0.0, 0.0, 2.0]]
    a0[0, 3, 3], a0[0, 4, 4] = 5.0, 7.0
    rng = np.random.default_rng(9)
    a0[1] = rng.standard_normal((5, 5)) + 5 * np.eye(5)
    a1 = np.zeros_like(a0)
    bs = decoupled_blocks(a0, a1, np.ones(2))
    assert bs.largest[0] == 3 and bs.largest[1] == 5
    vals, vecs, inv, ok = eig_affine(a0, a1, np.zeros(2), bs)
    assert (not ok[0]) or np.abs(inv[0]).max() > 1e4
    assert ok[1] and np.abs(a0[1] @ vecs[1] - vecs[1] * vals[1]).max() < 1e-12 * np.abs(a0[1]).max() * np.linalg.cond(vecs[1])
    # a nilpotent block: zero pivots in every shifted factorisation, no division by zero
    z = np.zeros((1, 3, 3))
    z[0, 0, 1] = z[0, 1, 2] = 1.0
    bs = decoupled_blocks(z, np.zeros_like(z), np.ones(1))
    assert bs.largest[0] == 3
    vals, vecs, inv, ok = eig_affine(z, np.zeros_like(z), np.zeros(1), bs)
    assert np.abs(vals).max() < 1e-5 and ((not ok[0]) or np.abs(inv[0]).max() > 1e4)


def test_coupled_blocks_match_lapack_on_the_asymmetric_propulsor():
    """The compiled route for a coupled 6 x 6 (QR + inverse iteration) against LAPACK's eig."""
    from impstab.model import model_from_dict
    from impstab.model.assemble import read_toml

    d = read_toml("examples/imp_asymmetric.toml")
    d["analysis"]["linearization"] = "classical"
    m, _, _, k0, k1 = ModelFamily(model_from_dict(d)).affine_parts()
    loads = np.linspace(0.0, 6e4, 301)  # stable, near the flutter onset, and far past it
    a0 = np.repeat(np.linalg.solve(m, k0)[None], len(loads), 0)
    a1 = np.repeat(np.linalg.solve(m, k1)[None], len(loads), 0)
    bs = decoupled_blocks(a0, a1, np.full(len(loads), 6e4))
    assert (bs.largest == 6).all()
    # the compiled route itself (eig_affine would hide its failures behind LAPACK)
    vals, vecs, inv = np.empty((len(loads), 6), complex), np.empty((len(loads), 6, 6), complex), np.empty((len(loads), 6, 6), complex)
    ok = np.zeros(len(loads), dtype=bool)
    _eig_blocks(a0, a1, loads, bs.order, bs.starts, bs.nblocks, bs.mirror, vals, vecs, inv, ok)
    ref_vals, ref_vecs, ref_inv, ref_ok = eig_affine(a0, a1, loads, None)
    assert ok.all() and ref_ok.all()
    for s in range(len(loads)):
        a = a0[s] + loads[s] * a1[s]
        cond = np.linalg.cond(vecs[s])
        assert np.abs(a @ vecs[s] - vecs[s] * vals[s]).max() <= 400 * EPS * np.abs(a).sum(axis=1).max()
        assert np.abs(inv[s] @ vecs[s] - np.eye(6)).max() <= 100 * EPS * cond
        # each unit eigenvector equals LAPACK's up to a phase (simple eigenvalues here)
        for k in range(6):
            j = int(np.argmin(np.abs(ref_vals[s] - vals[s, k])))
            overlap = abs(np.vdot(ref_vecs[s][:, j], vecs[s][:, k]))
            assert abs(overlap - 1) <= 1e3 * EPS * cond


def _signed_copies(rng, m, copies, noise=0.0):
    """Block diagonal ``A0, A1``: one random block of order ``m``, ``copies`` signed copies of it
    (``S B S``, ``S`` random signs, entries perturbed by ``noise`` relative), a different block of
    the same order, dofs shuffled."""
    b0, b1 = rng.standard_normal((m, m)) + 3 * np.eye(m), 0.2 * rng.standard_normal((m, m))
    other0, other1 = rng.standard_normal((m, m)) + 3 * np.eye(m), 0.2 * rng.standard_normal((m, m))
    parts = [(b0, b1)]
    for _ in range(copies):
        s = rng.choice([-1.0, 1.0], m)
        d = np.outer(s, s)
        parts.append((d * b0 * (1 + noise * rng.standard_normal((m, m))), d * b1))
    parts.append((other0, other1))
    n = m * len(parts)
    a0, a1 = np.zeros((n, n)), np.zeros((n, n))
    for i, (x0, x1) in enumerate(parts):
        a0[i * m:(i + 1) * m, i * m:(i + 1) * m] = x0
        a1[i * m:(i + 1) * m, i * m:(i + 1) * m] = x1
    perm = np.argsort(np.tile(np.arange(m), len(parts)) * 10 + np.repeat(np.arange(len(parts)), m))
    return a0[np.ix_(perm, perm)], a1[np.ix_(perm, perm)]


@pytest.mark.parametrize("m", [3, 4, 8])
def test_signed_copies_of_a_block_are_solved_once_and_match_lapack(m):
    """Identical planes: a block that is ``S B S`` of an earlier one copies its eigenvalues and
    takes ``S`` times its eigenvectors; checked against LAPACK on the whole matrix (residual,
    inverse, values), and a different block of the same order is not taken for a copy."""
    rng = np.random.default_rng(m)
    a0, a1 = _signed_copies(rng, m, copies=2)
    bs = decoupled_blocks(a0[None], a1[None], np.array([2.0]))
    assert bs.nblocks[0] == 4
    copied = [b for b in range(4) if bs.mirror[0, bs.starts[0, b]] != 0]
    assert len(copied) == 2  # the two copies; the source and the different block are solved
    loads = np.array([[0.0, 0.7, 2.0]])
    vals = eigvals_affine_blocks(a0[None], a1[None], loads, bs)
    for k, p in enumerate(loads[0]):
        ref = np.linalg.eigvals(a0 + p * a1)
        assert _match(vals[0, k], ref) <= 1e-12 * np.abs(ref).max()
    v, w, u, ok = eig_affine(a0[None], a1[None], np.array([0.7]), bs)
    a = a0 + 0.7 * a1
    assert ok[0]
    assert np.abs(a @ w[0] - w[0] * v[0]).max() <= 1e-12 * np.abs(a).max()
    assert np.abs(u[0] @ w[0] - np.eye(len(a))).max() <= 1e-11


def test_a_copy_beyond_rounding_is_solved_on_its_own():
    """A block that differs from a signed copy by more than the decoupling tolerance (1e-10 of its
    entries) is not taken for one: its own eigenvalues, not those of the other."""
    rng = np.random.default_rng(11)
    a0, a1 = _signed_copies(rng, 4, copies=1, noise=1e-10)
    bs = decoupled_blocks(a0[None], a1[None], np.array([2.0]))
    assert not bs.mirror.any()
    a0r, a1r = _signed_copies(np.random.default_rng(11), 4, copies=1, noise=1e-17)
    assert decoupled_blocks(a0r[None], a1r[None], np.array([2.0])).mirror.any()  # rounding: a copy


def test_a_block_the_load_does_not_change_is_solved_once():
    """A block with ``A1 = 0`` (surge and roll under an axial thrust) keeps the eigenvalues it has at
    ``p = 0``; they equal LAPACK's at every load, and a block the load does change (even by 1e-9 of
    its entries) is solved at each load."""
    rng = np.random.default_rng(5)
    a0, a1 = np.zeros((11, 11)), np.zeros((11, 11))
    a0[:4, :4] = rng.standard_normal((4, 4)) + 3 * np.eye(4)          # constant
    a0[4:7, 4:7] = rng.standard_normal((3, 3)) + 3 * np.eye(3)        # changes with the load
    a1[4:7, 4:7] = 0.3 * rng.standard_normal((3, 3))
    a0[7:, 7:] = rng.standard_normal((4, 4)) + 3 * np.eye(4)          # changes by 1e-9 of its entries
    a1[7:, 7:] = 1e-9 * rng.standard_normal((4, 4))
    bs = decoupled_blocks(a0[None], a1[None], np.array([2.0]))
    fixed = {tuple(sorted(bs.order[0, bs.starts[0, b]:bs.starts[0, b + 1]])): bs.fixed[0, bs.starts[0, b]]
             for b in range(bs.nblocks[0])}
    assert not np.isnan(fixed[(0, 1, 2, 3)]) and np.isnan(fixed[(4, 5, 6)]) and np.isnan(fixed[(7, 8, 9, 10)])
    loads = np.array([[0.0, 1.3, 2.0]])
    vals = eigvals_affine_blocks(a0[None], a1[None], loads, bs)
    for k, p in enumerate(loads[0]):
        ref = np.linalg.eigvals(a0 + p * a1)
        assert _match(vals[0, k], ref) <= 1e-12 * np.abs(ref).max()
