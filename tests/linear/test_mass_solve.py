"""mass_solve: E^-1 A of stacks, solved on the band of rows of E that differ from the identity.

The reference is LAPACK (numpy.linalg.solve) on the whole matrix.
"""

import numpy as np
import pytest

from impstab.linear.engine.problems import mass_solve


def _augmented_e(rng, nq: int, nz: int, couple: bool) -> np.ndarray:
    """diag(I, M, I) with a random mass block; ``couple``: the band's rows also reach the identity
    blocks' columns (E = [[I, 0, 0], [E_b0, M, E_b2], [0, 0, I]])."""
    n = 2 * nq + nz
    e = np.eye(n)
    r = rng.normal(size=(nq, nq))
    e[nq:2 * nq, nq:2 * nq] = r @ r.T + nq * np.eye(nq)
    if couple:
        e[nq:2 * nq, :nq] = rng.normal(size=(nq, nq))
        e[nq:2 * nq, 2 * nq:] = rng.normal(size=(nq, nz))
    return e


@pytest.mark.parametrize("couple", [False, True])
def test_band_solve_equals_the_whole_solve(couple):
    rng = np.random.default_rng(7)
    for nq, nz in [(6, 12), (2, 0), (3, 5), (1, 1)]:
        e = np.stack([_augmented_e(rng, nq, nz, couple) for _ in range(3)])
        a = rng.normal(size=(3, 2) + e.shape[1:])
        x = mass_solve(e, a)
        ref = np.linalg.solve(e[:, None], a)
        np.testing.assert_allclose(x, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
        # rows outside the band are A's own, exactly
        np.testing.assert_array_equal(x[:, :, :nq], a[:, :, :nq])


def test_a_row_of_the_identity_inside_the_band():
    """A mass matrix with an uncoupled unit inertia (roll 1 kg m^2) has a row equal to the
    identity's inside the band: still solved exactly."""
    rng = np.random.default_rng(3)
    e = _augmented_e(rng, 6, 6, False)
    e[9, 6:12] = 0.0
    e[6:12, 9] = 0.0
    e[9, 9] = 1.0
    a = rng.normal(size=(1, 2, 18, 18))
    np.testing.assert_allclose(mass_solve(e[None], a)[0], np.linalg.solve(e, a[0]), rtol=0, atol=1e-12)


def test_identity_whole_and_general_matrices():
    rng = np.random.default_rng(5)
    a = rng.normal(size=(2, 1, 5, 5))
    np.testing.assert_array_equal(mass_solve(np.broadcast_to(np.eye(5), (2, 5, 5)), a), a)
    e = rng.normal(size=(2, 5, 5)) + 5 * np.eye(5)
    np.testing.assert_allclose(mass_solve(e, a), np.linalg.solve(e[:, None], a), rtol=1e-12, atol=1e-12)


def test_singular_band_raises():
    e = np.eye(6)
    e[2:4, 2:4] = [[1.0, 2.0], [2.0, 4.0]]
    with pytest.raises(np.linalg.LinAlgError):
        mass_solve(e[None], np.ones((1, 1, 6, 6)))
