"""Static mount loads and the mode decoupling table against independent answers."""

import copy

import numpy as np
import pytest
from _resp_models import DOFS, asym_full, model, ring_damped, skew

import impstab
from impstab.linear.modes import coupling_centre
from impstab.response import decoupling_check, static_mount_loads


@pytest.mark.parametrize("tangency", [1.0, 0.4])
def test_static_mount_forces_carry_the_thrust(tangency):
    """Equilibrium: the mount forces on the hull sum to the thrust vector eta T R0 e + (1 - eta) T e,
    and the moments of the body-end forces at the moved attachment points plus the mounts' own
    moments equal the thrust's moment at its moved arm."""
    mdl = model(asym_full(tangency=tangency))
    t = 20000.0
    st = static_mount_loads(mdl, t)
    lin = impstab.linearize(mdl, t)
    thrust = t * (tangency * lin.rotation @ mdl.thrust.direction + (1 - tangency) * mdl.thrust.direction)
    assert np.allclose(st.force.sum(axis=0), thrust, rtol=0, atol=1e-9 * t)
    arm = lin.displacement + lin.rotation @ mdl.thrust.point
    m_body = sum(np.cross(lin.displacement + lin.rotation @ m.position, f) for m, f in zip(mdl.mounts, st.force))
    assert np.allclose(m_body + st.moment.sum(axis=0), np.cross(arm, thrust), rtol=0, atol=1e-8 * t)


def test_classical_static_loads_are_linear_statics():
    mdl = model(asym_full())
    t = 7000.0
    st = static_mount_loads(mdl, t, "classical")
    e = mdl.thrust.direction
    q0 = np.linalg.solve(mdl.elastic_stiffness, np.concatenate([t * e, np.cross(mdl.thrust.point, t * e)]))
    for i, m in enumerate(mdl.mounts):
        d = q0[:3] - skew(m.position) @ q0[3:]
        assert np.allclose(st.deflection[i], d, rtol=1e-12, atol=1e-15)
        assert np.allclose(st.force[i], (m.stiffness @ np.concatenate([d, q0[3:]]))[:3], rtol=1e-11, atol=1e-9)
    assert np.allclose(st.force.sum(axis=0), t * e, atol=1e-8 * t)


def test_ratings_give_utilisation_and_warnings():
    d = ring_damped()
    d["mount_rings"][0].update(rated_force=500.0, max_deflection=0.01)
    mdl = model(d)
    st = static_mount_loads(mdl, 2000.0)                 # 2000 N over three mounts: 666.7 N, 6.67 mm
    assert np.allclose(st.force_utilisation, (2000.0 / 3) / 500.0, rtol=1e-12)
    assert np.allclose(st.deflection_utilisation, (2000.0 / 3 / 1e5) / 0.01, rtol=1e-12)
    assert np.allclose(st.utilisation, st.force_utilisation)
    assert len(st.warnings) == 3 and "rated_force" in st.warnings[0]
    assert np.allclose(st.axial_deflection, 2000.0 / 3 / 1e5, rtol=1e-12) and st.shear_force.max() < 1e-9
    unrated = static_mount_loads(model(ring_damped()), 2000.0)
    assert np.all(np.isnan(unrated.utilisation)) and unrated.warnings == ()


def test_coupling_centre_of_a_rigid_body_is_its_cg():
    from impstab.model.body import rigid_body_mass_matrix

    rng = np.random.default_rng(3)
    for _ in range(5):
        cg = rng.normal(size=3) * 0.2
        a = rng.normal(size=(3, 3))
        m = rigid_body_mass_matrix(50.0, cg, a @ a.T + 3 * np.eye(3))
        assert np.allclose(coupling_centre(m), cg, atol=1e-13)


def test_elastic_centre_of_a_ring_lies_in_its_plane_on_the_axis():
    mdl = model(ring_damped())
    chk = decoupling_check(mdl, 0.0)
    assert np.allclose(chk.elastic_centre, [0.3, 0.0, 0.0], atol=1e-13)
    assert chk.elastic_coupling < 1e-12 and chk.roll_decoupled and chk.roll_share == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("thrust", [0.0, 9000.0])
def test_decoupling_table_rows_sum_to_one_and_name_the_dominant_dof(thrust):
    mdl = model(asym_full())
    md = impstab.modes(mdl, thrust)
    assert np.allclose(md.participation.sum(axis=1), 1.0, atol=1e-12)
    for row, dom in zip(md.participation, md.dominant()):
        assert dom[0] == DOFS[int(np.argmax(row))]
        assert all(row[DOFS.index(n)] >= row.max() - 0.01 for n in dom)


def test_energy_shares_in_cg_coordinates_of_a_free_rotation():
    """A body whose cg is off A, on one soft mount system: a pure rotation about the cg must show
    as rotation only (at A it would look like translation too)."""
    d = copy.deepcopy(ring_damped())
    d["body"]["cg"] = [0.3, 0.0, 0.0]                     # cg in the mount plane: roll is about the cg
    mdl = model(d)
    md = impstab.modes(mdl, 0.0)
    j = [i for i, dom in enumerate(md.dominant()) if dom[0] == "roll"][0]
    assert md.participation[j, DOFS.index("roll")] == pytest.approx(1.0, abs=1e-12)


def test_torque_roll_axis_is_the_inertia_image_of_the_thrust_axis():
    """Free body under a torque about e: the rotation axis is I_G^-1 e, through the cg."""
    d = asym_full()
    mdl = model(d)
    chk = decoupling_check(mdl, 0.0)
    i_g = np.array(d["body"]["inertia"])
    tra = np.linalg.solve(i_g, mdl.thrust.direction)
    tra /= np.linalg.norm(tra)
    assert np.allclose(chk.torque_roll_axis, tra, atol=1e-12)
    cg = np.array(d["body"]["cg"])
    assert np.linalg.norm(np.cross(cg - chk.torque_roll_point, tra)) < 1e-12
    assert np.allclose(chk.mass_centre, cg, atol=1e-13)
