"""The compiled classification rule against hand-made spectra and a plain NumPy statement of it."""

import numpy as np
import pytest

from impstab.linear.classify import classify_eigenvalues, unstable_masks
from impstab.linear.critical import FLOOR, TOL_CLUSTER, TOL_DUPLICATE, TOL_UNSTABLE

ARGS = (TOL_UNSTABLE, TOL_CLUSTER, FLOOR)


def _reference(vals, undamped):
    """The rule written out with NumPy array operations (sort, diff, masks)."""
    mag = np.abs(vals)
    floor = FLOOR * mag.max(axis=-1, keepdims=True)
    if undamped:
        cplx = np.abs(vals.imag) > np.maximum(TOL_UNSTABLE * mag, floor)
        neg = (vals.real < -floor) & ~cplx
    else:
        grow = vals.real > np.maximum(TOL_UNSTABLE * mag, floor)
        real = np.abs(vals.imag) <= np.maximum(TOL_CLUSTER * mag, floor)
        cplx, neg = grow & ~real, grow & real
    unstable = (cplx | neg).any(axis=-1)
    mag = np.maximum(mag, 1e-300)
    if undamped:
        srt = np.sort(vals.real / mag.max(axis=-1, keepdims=True), axis=-1)
        diffs = np.diff(srt, axis=-1)
        diffs[diffs < TOL_DUPLICATE] = np.inf
        gap = diffs.min(axis=-1)
        worst = -(np.abs(vals.imag) / mag).max(axis=-1)
        c = cplx.any(axis=-1)
        ind = np.stack([np.where(c, worst, gap), np.where(c, worst, srt[:, 0])], axis=-1)
    else:
        growth = (vals.real / mag).max(axis=-1)
        freq = np.sort(np.abs(vals.imag) / mag.max(axis=-1, keepdims=True), axis=-1)
        diffs = np.diff(freq, axis=-1)
        diffs[diffs < TOL_DUPLICATE] = np.inf
        ind = np.stack([-growth, np.where(unstable, -growth, diffs.min(axis=-1))], axis=-1)
    return cplx, neg, unstable, ind


def test_hand_made_undamped_spectra():
    s = np.array([
        [100.0, 400.0, 900.0],                 # stable, gap (400-100)/900
        [100.0, 400.0 + 1e-3j, 400.0 - 1e-3j],  # flutter: |Im| 1e-3 > 1e-7 * 400
        [100.0, 400.0 + 1e-6j, 400.0 - 1e-6j],  # within tolerance: stable
        [-5.0, 400.0, 900.0],                  # divergence
        [100.0, 100.0, 900.0],                 # duplicate frequency: not a gap
    ], dtype=complex)
    unstable, ind = classify_eigenvalues(s, True, *ARGS, TOL_DUPLICATE)
    assert unstable.tolist() == [False, True, False, True, False]
    assert ind[0, 0] == pytest.approx(300.0 / 900.0) and ind[0, 1] == pytest.approx(100.0 / 900.0)
    assert ind[1, 0] < 0 and ind[3, 1] < 0
    assert ind[4, 0] == pytest.approx(800.0 / 900.0)
    cplx, neg = unstable_masks(s, True, *ARGS)
    assert cplx[1].tolist() == [False, True, True] and neg[3].tolist() == [True, False, False]


def test_hand_made_damped_spectra():
    lam = np.array([
        [-0.1 + 10j, -0.1 - 10j, -2.0],  # decaying
        [0.01 + 10j, 0.01 - 10j, -2.0],  # flutter: growing oscillation
        [-0.1 + 10j, -0.1 - 10j, 0.5],   # divergence: growing real root
    ])
    unstable, ind = classify_eigenvalues(lam, False, *ARGS, TOL_DUPLICATE)
    assert unstable.tolist() == [False, True, True]
    cplx, neg = unstable_masks(lam, False, *ARGS)
    assert cplx[1].tolist() == [True, True, False] and neg[2].tolist() == [False, False, True]
    assert ind[0, 0] == pytest.approx(0.1 / abs(-0.1 + 10j))
    # the closest gap between distinct frequencies |Im lambda| (10 and 0), relative to max |lambda|
    assert ind[0, 1] == pytest.approx(10 / abs(-0.1 + 10j)) and ind[1, 1] == ind[1, 0]


@pytest.mark.parametrize("undamped", [True, False])
def test_equals_the_numpy_statement_on_random_spectra(undamped):
    rng = np.random.default_rng(4)
    re = rng.uniform(-1, 10, (4000, 6)) * 10.0 ** rng.integers(-3, 4, (4000, 1))
    im = np.where(rng.random((4000, 6)) < 0.3, rng.normal(0, 1, (4000, 6)) * 10.0 ** rng.integers(-9, 1, (4000, 6)), 0)
    vals = re * np.where(rng.random((4000, 1)) < 0.2, -1, 1) + 1j * im * np.abs(re)
    vals[::7, 1] = vals[::7, 0]  # exact duplicates
    cplx, neg = unstable_masks(vals, undamped, *ARGS)
    unstable, ind = classify_eigenvalues(vals, undamped, *ARGS, TOL_DUPLICATE)
    r_cplx, r_neg, r_unstable, r_ind = _reference(vals, undamped)
    np.testing.assert_array_equal(cplx, r_cplx)
    np.testing.assert_array_equal(neg, r_neg)
    np.testing.assert_array_equal(unstable, r_unstable)
    # |z| is a hypot in both, which may round differently in the last bit
    np.testing.assert_allclose(ind, r_ind, rtol=0, atol=4 * np.finfo(float).eps)  # indicators are relative
    assert unstable.any() and not unstable.all()
