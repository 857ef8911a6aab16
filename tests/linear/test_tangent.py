"""The linearized stiffness against independent routes (THEORY 4).

* equilibrium: the tangent equals a central-difference Jacobian of the exact nonlinear forces at
  the static equilibrium, on asymmetric layouts (tilted axes, a full 6x6 mount, cg offset,
  off-axis thrust, partial follower);
* classical: the explicit list of THEORY 4 (K_c + K_sigma + K_L), exactly linear in T;
* symmetric rings: the preload term -T x_m diag(0, 1, 1) and the follower entries -T, +T.
"""

import numpy as np
import pytest
from conftest import asymmetric_model_dict, ring_model_dict

from impstab import linearize
from impstab.kinematics import rigid_map, rotation_from_vector, skew
from impstab.linear.linearize import pack_model
from impstab.linear.tangent import pose_forces
from impstab.model import model_from_dict


def forces(pk, thrust, u, rot):
    return pose_forces(u, rot, thrust, pk.positions, pk.stiffness, pk.damping, pk.e_dir, pk.r_thrust, pk.tangency, pk.laws)[0]


def fd_jacobian(pk, thrust, u0, r0, h=1e-6):
    """-dQ/dq by central differences (Richardson-extrapolated) in (du, spatial dphi)."""
    def one(step):
        jac = np.zeros((6, 6))
        for j in range(6):
            dq = np.zeros(6)
            dq[j] = step
            qp = forces(pk, thrust, u0 + dq[:3], rotation_from_vector(dq[3:]) @ r0)
            qm = forces(pk, thrust, u0 - dq[:3], rotation_from_vector(-dq[3:]) @ r0)
            jac[:, j] = -(qp - qm) / (2 * step)
        return jac
    return (4 * one(h / 2) - one(h)) / 3


@pytest.mark.parametrize("thrust", [2000.0, 9000.0, 25000.0])
@pytest.mark.parametrize("tangency", [1.0, 0.8, 0.0])
def test_equilibrium_tangent_equals_fd_jacobian(thrust, tangency):
    d = asymmetric_model_dict()
    d["thrust"]["tangency"] = tangency
    model = model_from_dict(d)
    lin = linearize(model, thrust, "equilibrium")
    pk = pack_model(model)
    # the pose is a static equilibrium: no residual force
    q = forces(pk, thrust, lin.displacement, lin.rotation)
    assert np.abs(q).max() < 1e-9 * thrust
    # and the body did rotate (otherwise this would not test the equilibrium form)
    assert np.abs(lin.rotation - np.eye(3)).max() > 1e-4
    jac = fd_jacobian(pk, thrust, lin.displacement, lin.rotation)
    assert np.abs(lin.K - jac).max() < 1e-8 * np.abs(lin.K).max()


def test_preload_switch_drops_only_mount_preload_term():
    d = asymmetric_model_dict()
    model = model_from_dict(d)
    d["thrust"]["preload_stiffness"] = False
    off = model_from_dict(d)
    t = 12000.0
    on_lin, off_lin = linearize(model, t), linearize(off, t)
    pk = pack_model(model)
    _, _, k_pre, _, _ = pose_forces(on_lin.displacement, on_lin.rotation, t, pk.positions, pk.stiffness,
                                    pk.damping, pk.e_dir, pk.r_thrust, pk.tangency, pk.laws)
    assert np.allclose(on_lin.K - off_lin.K, k_pre, rtol=1e-12, atol=1e-9)
    assert np.abs(k_pre[:3]).max() == 0 and np.abs(k_pre[:, :3]).max() == 0


@pytest.mark.parametrize("tangency", [1.0, 0.5, 0.0])
def test_classical_equals_theory_list(tangency):
    d = asymmetric_model_dict()
    d["mounts"] = d["mounts"][:3] + [
        {"position": [-0.2, 0.0, -0.14], "axis": [0.0, 0.0, 1.0], "k_axial": 3e4, "k_shear": 1e4}
    ]
    d["thrust"]["tangency"] = tangency
    model = model_from_dict(d)
    t = 7000.0
    lin = linearize(model, t, "classical")
    e, r_t, eta = model.thrust.direction, model.thrust.point, tangency
    kc = model.elastic_stiffness
    q0 = np.linalg.solve(kc, np.concatenate([t * e, np.cross(r_t, t * e)]))
    k_sigma = np.zeros((3, 3))
    for m in model.mounts:
        f = -m.stiffness[:3, :3] @ rigid_map(m.position) @ q0
        r = m.position
        k_sigma += (r @ f) * np.eye(3) - np.outer(r, f)
    expected = kc.copy()
    expected[3:, 3:] += k_sigma
    expected[:3, 3:] += eta * t * skew(e)
    expected[3:, 3:] += eta * skew(np.cross(r_t, t * e))
    expected[3:, 3:] += (1 - eta) * t * ((r_t @ e) * np.eye(3) - np.outer(r_t, e))
    assert np.allclose(lin.K, expected, rtol=1e-12, atol=1e-9 * np.abs(kc).max())
    # exactly linear in T
    k0, k1, k2 = (linearize(model, x, "classical").K for x in (0.0, t, 2 * t))
    assert np.allclose(k2 - k1, k1 - k0, atol=1e-9 * np.abs(kc).max())
    if tangency == 0.0:
        assert np.allclose(lin.K, lin.K.T, atol=1e-9 * np.abs(kc).max())


def test_symmetric_ring_terms():
    model = model_from_dict(ring_model_dict())
    t, x_m = 4000.0, 0.3
    k0 = linearize(model, 0.0).K
    k = linearize(model, t).K
    dk = k - k0
    assert dk[1, 5] == pytest.approx(-t, rel=1e-12)   # K[sway, yaw] = -T (follower)
    assert dk[2, 4] == pytest.approx(t, rel=1e-12)    # K[heave, pitch] = +T
    # preload: -T x_m diag(0, 1, 1) in the rotation block, destabilising for mounts ahead of A
    assert np.allclose(np.diag(dk)[3:], [0.0, -t * x_m, -t * x_m], atol=1e-9 * t)
    skew_part = 0.5 * (dk - dk.T)
    assert skew_part[1, 5] == pytest.approx(-t / 2) and skew_part[2, 4] == pytest.approx(t / 2)
    # equilibrium and classical agree on a symmetric layout
    assert np.allclose(k, linearize(model, t, "classical").K, rtol=0, atol=1e-9 * np.abs(k).max())


def test_equilibrium_and_classical_differ_on_asymmetric_layout():
    model = model_from_dict(asymmetric_model_dict())
    a = linearize(model, 20000.0, "equilibrium").K
    b = linearize(model, 20000.0, "classical").K
    assert np.abs(a - b).max() > 1e-4 * np.abs(a).max()


def test_mass_and_gyroscopic_matrices_at_the_deflected_pose():
    d = asymmetric_model_dict()
    d["propeller"] = {"polar_inertia": 0.05, "speed": 200.0, "speed_law": "sqrt-thrust"}
    model = model_from_dict(d)
    t = 12000.0
    lin = linearize(model, t)
    big = np.zeros((6, 6))
    big[:3, :3] = big[3:, 3:] = lin.rotation
    assert np.allclose(lin.M, big @ model.mass_matrix @ big.T, rtol=1e-13, atol=1e-12)
    spin = 200.0 * np.sqrt(t / 3000.0)
    h = 0.05 * spin * lin.rotation @ model.thrust.direction
    assert np.allclose(lin.G[3:, 3:], -skew(h), rtol=1e-13, atol=1e-12)
    assert np.allclose(lin.G, -lin.G.T)


def test_soft_shear_mounts_keep_the_straight_equilibrium_and_the_commands_agree(capsys, tmp_path, examples):
    """A shear stiffness of 1 N/m under 8 kN: rounding alone moves the pose by more than the old
    fixed Newton tolerance, and `modes` lost the exact straight equilibrium that `critical` and
    `locus` (affine, no Newton) use. Now the Newton path at every thrust equals the affine
    matrices, and `modes`, `critical` and `locus` agree on where the model turns unstable."""
    import json

    from impstab import critical_thrust, locus, modes
    from impstab.cli import main
    from impstab.linear.linearize import ModelFamily

    d = ring_model_dict()
    d["mount_rings"][0]["k_shear"] = 1.0
    model = model_from_dict(d)
    fam = ModelFamily(model)
    assert fam.is_affine
    thrusts = np.linspace(0.0, 20000.0, 81)
    m, dd, g, k, u0, r0 = fam.evaluate(thrusts)  # Newton continuation at every thrust
    _, _, _, k_affine = fam.matrices(thrusts)
    assert np.abs(k - k_affine).max() <= 1e-9 * np.abs(k_affine).max()
    np.testing.assert_allclose(r0, np.broadcast_to(np.eye(3), r0.shape), atol=1e-12)
    np.testing.assert_allclose(u0[:, 0], thrusts / 3e5, rtol=1e-12)
    crit = critical_thrust(model)
    assert crit.kind == "flutter"
    loc = locus(model, thrusts)
    unstable_locus = loc.growth_rate.max(axis=1) > 1e-9
    unstable_modes = np.array([modes(model, t).growth_rate.max() > 1e-9 for t in thrusts])
    np.testing.assert_array_equal(unstable_locus, unstable_modes)
    np.testing.assert_array_equal(unstable_modes, thrusts > crit.thrust)
    # and on the command line: modes at 8 kN has an equilibrium and is stable
    text = (examples / "imp_symmetric.toml").read_text()
    assert "k_shear = 2.0e4" in text
    path = tmp_path / "soft.toml"
    path.write_text(text.replace("k_shear = 2.0e4", "k_shear = 1.0"))
    assert main(["modes", str(path), "--thrust", "8000"]) == 0
    out = capsys.readouterr().out
    assert "stable" in out and "UNSTABLE" not in out
    assert main(["critical", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["critical_thrust"] == pytest.approx(crit.thrust, rel=1e-12)
