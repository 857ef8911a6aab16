"""Participation of the dofs in the critical cluster: independent of the eigensolver's basis."""

import copy
from pathlib import Path

import numpy as np

import impstab
from impstab.model.assemble import read_toml
from impstab.linear.eigen import cluster_participation, kinetic_shares
from impstab.model import model_from_dict

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
M_DIAG = np.array([100.0, 100.0, 100.0, 1.0, 6.0, 6.0])


def test_simple_eigenvalues_weigh_each_mode_equally():
    rng = np.random.default_rng(1)
    v = rng.standard_normal((6, 2)) + 1j * rng.standard_normal((6, 2))
    got = cluster_participation(v, np.array([3.0, 5.0]), np.ones(2, bool), M_DIAG, 1e-9)
    by_hand = sum(np.abs(v[:, j]) ** 2 * M_DIAG / np.sum(np.abs(v[:, j]) ** 2 * M_DIAG) for j in range(2)) / 2
    assert np.allclose(got, by_hand, rtol=1e-14, atol=1e-16)
    assert np.allclose(got, 0.5 * (kinetic_shares(v[:, [0]], np.diag(M_DIAG)) + kinetic_shares(v[:, [1]], np.diag(M_DIAG))))


def test_repeated_eigenvalue_does_not_depend_on_the_basis():
    """Sway-yaw and heave-pitch modes of one frequency: any basis of their plane pair is as good."""
    sway_yaw = np.array([0, 1.0, 0, 0, 0, 0.4])
    heave_pitch = np.array([0, 0, 1.0, 0, -0.4, 0])
    plane = np.stack([sway_yaw, heave_pitch], axis=1)
    # the two modes carry the same energy shape, so sway = heave and pitch = yaw, exactly
    want = (np.abs(sway_yaw) ** 2 * M_DIAG / np.sum(np.abs(sway_yaw) ** 2 * M_DIAG)
            + np.abs(heave_pitch) ** 2 * M_DIAG / np.sum(np.abs(heave_pitch) ** 2 * M_DIAG)) / 2
    vals = np.array([2.0, 2.0 * (1 + 1e-12)])
    for mix in ([[1, 0], [0, 1]], [[1, 1], [1, -2]], [[0.3, 2.0], [1.0, 0.1]], [[1, 1j], [1j, 3]]):
        shapes = (plane @ np.array(mix, dtype=complex)) * np.array([0.7, -2.5])
        got = cluster_participation(shapes, vals, np.ones(2, bool), M_DIAG, 1e-9)
        assert np.allclose(got, want, rtol=1e-12, atol=1e-15)
        assert got[1] == np.float64(got[1]) and abs(got[1] - got[2]) < 1e-14 and abs(got[4] - got[5]) < 1e-14
    # the mode-by-mode mean of a mixed basis is not the answer: the test can tell them apart
    mixed = plane @ np.array([[1.0, 1.0], [1.0, -2.0]])
    naive = np.mean([kinetic_shares(mixed[:, [j]], np.diag(M_DIAG)) for j in range(2)], axis=0)
    assert np.abs(naive - want).max() > 1e-2


def test_batched_with_masks_equals_one_at_a_time():
    rng = np.random.default_rng(4)
    shapes = rng.standard_normal((5, 6, 6)) + 1j * rng.standard_normal((5, 6, 6))
    vals = rng.uniform(1, 2, (5, 6)).astype(complex)
    vals[:, 1] = vals[:, 0]  # a repeated pair in each row
    members = rng.random((5, 6)) < 0.6
    members[:, :2] = True
    got = cluster_participation(shapes, vals, members, np.broadcast_to(M_DIAG, (5, 6)), 1e-9)
    for r in range(5):
        one = cluster_participation(shapes[r][:, members[r]], vals[r][members[r]], np.ones(members[r].sum(), bool), M_DIAG, 1e-9)
        assert np.allclose(got[r], one, rtol=1e-13, atol=1e-15)
        assert abs(got[r].sum() - 1) < 1e-13


def test_symmetric_rings_give_symmetric_participation():
    """Symmetric layouts: sway = heave and pitch = yaw in the critical cluster (by symmetry).

    The five-mount ring with tangency 0.66 is a case where LAPACK's basis of the repeated
    eigenvalues used to give 'sway, pitch, yaw' without heave.
    """
    base = read_toml(EXAMPLES / "imp_symmetric.toml")
    for count, x, tangency, k_axial, k_shear in [(5, 0.1975, 0.6628, 33325.76, 8458.40), (3, 0.3, 1.0, 1e5, 2e4),
                                                 (4, -0.2, 0.5, 5e4, 1e4), (6, 0.05, 0.9, 2e5, 3e4)]:
        d = copy.deepcopy(base)
        d["mount_rings"][0].update(count=count, x=x, k_axial=k_axial, k_shear=k_shear)
        d["thrust"]["tangency"] = tangency
        res = impstab.critical_thrust(model_from_dict(d))
        if res.participation is None:
            continue
        p = res.participation
        assert abs(p[1] - p[2]) <= 1e-9 and abs(p[4] - p[5]) <= 1e-9, (count, p)
        assert ("sway" in res.modes) == ("heave" in res.modes) and ("pitch" in res.modes) == ("yaw" in res.modes)
