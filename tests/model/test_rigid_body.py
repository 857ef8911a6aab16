"""Rigid-body mass and Coriolis matrices (THEORY 2) against their defining identities."""

import numpy as np
import pytest

from impstab.kinematics import skew
from impstab.model.body import RigidBody, rigid_body_coriolis_matrix, rigid_body_mass_matrix


@pytest.fixture
def rng():
    return np.random.default_rng(7)


def random_body(rng):
    a = rng.normal(size=(3, 3))
    inertia = a @ a.T + 3 * np.eye(3)
    return RigidBody(rng.uniform(10, 200), rng.normal(scale=0.1, size=3), inertia)


def test_parallel_axis_and_mass_matrix(rng):
    body = random_body(rng)
    m, r = body.mass, body.cg
    # parallel axes: I_A = I_G + m (|r|^2 I - r r^T), the paper's eq. 13 with pi = -r_G
    expected = body.inertia_cg + m * (r @ r * np.eye(3) - np.outer(r, r))
    assert np.allclose(body.inertia_a, expected, rtol=1e-14, atol=1e-12)
    mm = body.mass_matrix()
    assert np.allclose(mm, mm.T)
    # kinetic energy of a rigid motion (v of A, w) equals 1/2 m |v_G|^2 + 1/2 w I_G w
    for _ in range(5):
        v, w = rng.normal(size=3), rng.normal(size=3)
        nu = np.concatenate([v, w])
        v_g = v + np.cross(w, r)
        assert 0.5 * nu @ mm @ nu == pytest.approx(0.5 * m * v_g @ v_g + 0.5 * w @ body.inertia_cg @ w, rel=1e-13)


def test_paper_eq17_layout(rng):
    body = random_body(rng)
    m, (xg, yg, zg) = body.mass, body.cg
    mm = body.mass_matrix()
    top_right = np.array([[0, m * zg, -m * yg], [-m * zg, 0, m * xg], [m * yg, -m * xg, 0]])
    assert np.allclose(mm[:3, 3:], top_right)


def test_coriolis_is_skew_and_equals_newton_euler(rng):
    for _ in range(10):
        body = random_body(rng)
        nu = rng.normal(size=6)
        v, w = nu[:3], nu[3:]
        c = rigid_body_coriolis_matrix(body.mass, body.cg, body.inertia_a, nu)
        assert np.allclose(c, -c.T, atol=1e-12)
        force = body.mass * (np.cross(w, v) + np.cross(w, np.cross(w, body.cg)))
        moment = np.cross(w, body.inertia_a @ w) + body.mass * np.cross(body.cg, np.cross(w, v))
        assert np.allclose(c @ nu, np.concatenate([force, moment]), rtol=1e-12, atol=1e-10)


def test_mass_matrix_helper_matches_skew_form(rng):
    body = random_body(rng)
    s = skew(body.cg)
    mm = rigid_body_mass_matrix(body.mass, body.cg, body.inertia_a)
    assert np.allclose(mm[3:, :3], body.mass * s)
