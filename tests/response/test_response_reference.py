"""The forced response against independent answers: a per-frequency solve, Newton's law for the
body, the power balance, the single-dof transmissibility, the static limit, the resonance peaks."""

import numpy as np
import pytest
from _resp_models import DOFS, asym_full, body_end_maps, model, reference_response, ring_damped, skew
from scipy.spatial.transform import Rotation

import impstab
from impstab.model.foundation import Foundation
from impstab.response import frequency_response

FREQS = np.concatenate([[0.0], np.geomspace(0.2, 60.0, 57)])


@pytest.mark.parametrize("linearization", ["equilibrium", "classical"])
@pytest.mark.parametrize("dof", ["sway", "heave", "surge", "roll", "pitch", "yaw"])
def test_matches_per_frequency_solve(linearization, dof):
    """Asymmetric, tilted, damped, gyroscopic (sqrt-thrust speed law), both linearizations, force
    and moment inputs: response and mount forces equal an independent solve to 1e-10."""
    mdl = model(asym_full())
    thrust = 9000.0
    res = frequency_response(mdl, FREQS, thrust=thrust, input=dof, linearization=linearization)
    load = np.zeros(6)
    load[DOFS.index(dof)] = 1.0
    q, forces, _ = reference_response(mdl, FREQS, load, thrust, linearization)
    assert np.abs(res.response - q).max() <= 1e-10 * np.abs(q).max()
    assert np.abs(res.mount_force - forces).max() <= 1e-10 * np.abs(forces).max()
    hull = forces.sum(axis=1)
    assert np.abs(res.hull_force - hull).max() <= 1e-10 * np.abs(hull).max()
    t_ref = np.sqrt((np.abs(hull) ** 2).sum(axis=1))         # |F_hull| / |F_in|, |F_in| = 1
    assert np.allclose(res.transmissibility, t_ref, rtol=1e-10, atol=0)


def test_body_end_maps_are_the_derivative_of_the_deflection():
    """The reference's B_i (closed-form J_l^-1) is the Jacobian of the exact body-end deflection
    (u + R r - r, log R) for the spatial increment R <- exp(S(dphi)) R (central differences)."""
    mdl = model(asym_full())
    lin = impstab.linearize(mdl, 30000.0)
    r0 = lin.rotation
    assert Rotation.from_matrix(r0).magnitude() > 1e-3           # a rotated equilibrium
    for m, b in zip(mdl.mounts, body_end_maps(mdl, r0)):
        def e(q):
            rot = Rotation.from_rotvec(q[3:]).as_matrix() @ r0
            return np.concatenate([lin.displacement + q[:3] + rot @ m.position - m.position,
                                   Rotation.from_matrix(rot).as_rotvec()])
        h = 1e-6
        jac = np.column_stack([(e(h * np.eye(6)[j]) - e(-h * np.eye(6)[j])) / (2 * h) for j in range(6)])
        assert np.abs(jac - b).max() < 1e-8


@pytest.mark.parametrize("linearization", ["equilibrium", "classical"])
def test_newtons_law_for_the_body(linearization):
    """Hull force = applied force + inertial force + load-stiffness force of the thrust, at every
    frequency: F_hull = F_t + w^2 (M q)_t - (K_L q)_t with K_L,ut = S(f_F), f_F = eta T R0 e."""
    d = asym_full()
    mdl = model(d)
    thrust = 12000.0
    lin = impstab.linearize(mdl, thrust, linearization)
    f_follower = d["thrust"]["tangency"] * thrust * lin.rotation @ mdl.thrust.direction
    for dof in ("sway", "yaw", "surge"):
        res = frequency_response(mdl, FREQS, thrust=thrust, input=dof, linearization=linearization)
        w = 2 * np.pi * FREQS
        q = res.response
        inertial = (w[:, None] ** 2) * (q @ lin.M.T)[:, :3]
        load_stiffness = q[:, 3:] @ skew(f_follower).T
        expected = res.load[:, :3] + inertial - load_stiffness
        assert np.abs(res.hull_force - expected).max() <= 1e-10 * np.abs(expected).max()


def test_hull_force_equals_applied_force_at_zero_frequency():
    """At 0 Hz a force input reaches the hull whole when the thrust cannot turn with the body
    (T = 0, or a dead load): F_hull = F_in exactly. Under a follower thrust the turned thrust
    vector adds theta x f_F: F_hull = F_in + theta x f_F (theta the static rotation response)."""
    d = asym_full(tangency=1.0)
    mdl = model(d)
    for dof in ("surge", "sway", "heave"):
        unit = np.eye(3)[DOFS.index(dof)]
        r0 = frequency_response(mdl, [0.0], thrust=0.0, input=dof)
        assert np.abs(r0.hull_force[0] - unit).max() <= 1e-12
        dead = frequency_response(model(asym_full(tangency=0.0)), [0.0], thrust=20000.0, input=dof)
        assert np.abs(dead.hull_force[0] - unit).max() <= 1e-12
        fol = frequency_response(mdl, [0.0], thrust=20000.0, input=dof)
        lin = impstab.linearize(mdl, 20000.0)
        f_f = 20000.0 * lin.rotation @ mdl.thrust.direction
        expected = unit + np.cross(fol.response[0, 3:], f_f)
        assert np.abs(fol.hull_force[0] - expected).max() <= 1e-12
        assert np.abs(fol.hull_force[0] - unit).max() > 1e-4      # the effect is real
    # a moment input at T = 0 puts no net force on the hull at 0 Hz
    mom = frequency_response(mdl, [0.0], thrust=0.0, input="yaw")
    assert np.abs(mom.hull_force[0]).max() <= 1e-12


@pytest.mark.parametrize("thrust", [0.0, 2000.0, 15000.0])
@pytest.mark.parametrize("linearization", ["equilibrium", "classical"])
def test_single_dof_transmissibility_of_the_decoupled_surge_mode(thrust, linearization):
    """Surge of the symmetric damped ring is one degree of freedom at every thrust:
    T = sqrt(1 + (2 zeta r)^2) / sqrt((1 - r^2)^2 + (2 zeta r)^2)."""
    mdl = model(ring_damped())
    k, c, m = 3 * 1.0e5, 3 * 150.0, 100.0
    wn, zeta = np.sqrt(k / m), c / (2 * np.sqrt(k * m))
    f = np.geomspace(0.05, 200.0, 400)
    res = frequency_response(mdl, f, thrust=thrust, input="surge", linearization=linearization)
    r = 2 * np.pi * f / wn
    exact = np.sqrt(1 + (2 * zeta * r) ** 2) / np.sqrt((1 - r**2) ** 2 + (2 * zeta * r) ** 2)
    assert np.allclose(res.transmissibility, exact, rtol=1e-11, atol=0)


def _lumped(f):
    w = 2 * np.pi * f
    return 4.0e5 - w**2 * 30.0 + 1j * w * 900.0


@pytest.mark.parametrize("thrust", [0.0, 9000.0])
def test_power_balance_with_a_compliant_hull(thrust):
    """Input power + thrust work = dissipated in the mount dampers + transmitted into the hull,
    every term formed here from its definition; and the coupled response against an independent
    solve with the hull-end displacements as unknowns."""
    d = asym_full()
    mdl = model(d)
    hull = Foundation("lumped", mass=30.0, stiffness=4.0e5, damping=900.0)
    f = np.geomspace(0.3, 80.0, 61)
    res = frequency_response(mdl, f, thrust=thrust, input="heave", foundation=hull)
    load = np.eye(6)[2]
    q, forces, x = reference_response(mdl, f, load, thrust, hull_stiffness=_lumped)
    assert np.abs(res.response - q).max() <= 1e-10 * np.abs(q).max()
    assert np.abs(res.mount_force - forces).max() <= 1e-10 * np.abs(forces).max()
    w = 2 * np.pi * f
    lin = impstab.linearize(mdl, thrust)
    maps = body_end_maps(mdl, lin.rotation)
    p_in = 0.5 * np.real(np.conj(load) @ (1j * w[:, None] * q).T)
    p_damp = np.zeros_like(w)
    p_hull = np.zeros_like(w)
    for i, (mnt, b) in enumerate(zip(mdl.mounts, maps)):
        e = q @ b.T
        e[:, :3] -= x[:, i]
        p_damp += 0.5 * w**2 * np.einsum("fi,ij,fj->f", e.conj(), mnt.damping, e).real
        p_hull += 0.5 * np.real((forces[:, i].conj() * (1j * w[:, None] * x[:, i])).sum(axis=1))
    # the thrust's work: generalized force -(K - sum B^T k B) q on the velocity i w q
    k_load = lin.K - sum(b.T @ mnt.stiffness @ b for mnt, b in zip(mdl.mounts, maps))
    p_thrust = 0.5 * np.real(np.einsum("fi,fi->f", (-(q @ k_load.T)).conj(), 1j * w[:, None] * q))
    assert np.allclose(res.power_input, p_in, rtol=1e-9, atol=1e-12 * np.abs(p_in).max())
    assert np.allclose(res.power_damper.sum(axis=1), p_damp, rtol=1e-9, atol=1e-12 * p_damp.max())
    assert np.allclose(res.power_transmitted.sum(axis=1), p_hull, rtol=1e-9, atol=1e-12 * p_hull.max())
    assert np.abs(p_in + p_thrust - p_damp - p_hull).max() <= 1e-9 * np.abs(p_in).max()
    assert p_hull.min() > 0 and p_damp.min() > 0
    if thrust == 0.0:
        assert np.abs(p_thrust).max() <= 1e-12 * np.abs(p_in).max()


def test_compliant_table_foundation_against_the_reference():
    """A measured impedance table: linear interpolation of Z, S = i w Z, same coupled solve."""
    mdl = model(asym_full())
    tf = np.array([0.1, 5.0, 20.0, 100.0])
    z = np.array([2.0e3 + 1.0e5j, 1.5e3 - 2.0e4j, 4.0e3 + 3.0e3j, 8.0e3 + 2.0e4j])
    hull = Foundation("impedance-table", frequency_hz=tf, values=z)
    f = np.linspace(0.5, 90.0, 40)
    res = frequency_response(mdl, f, thrust=5000.0, input="sway", foundation=hull)

    def s(fr):
        zz = np.interp(fr, tf, z.real) + 1j * np.interp(fr, tf, z.imag)
        return 1j * 2 * np.pi * fr * zz

    q, forces, _ = reference_response(mdl, f, np.eye(6)[1], 5000.0, hull_stiffness=s)
    assert np.abs(res.response - q).max() <= 1e-10 * np.abs(q).max()
    assert np.abs(res.mount_force - forces).max() <= 1e-10 * np.abs(forces).max()
    assert np.abs(res.power_balance_error).max() <= 1e-9 * np.abs(res.power_input).max()


def test_a_very_stiff_foundation_is_the_rigid_hull():
    mdl = model(asym_full())
    f = np.geomspace(0.5, 50.0, 20)
    rigid = frequency_response(mdl, f, thrust=3000.0)
    stiff = frequency_response(mdl, f, thrust=3000.0, foundation=Foundation("lumped", stiffness=1e15))
    assert np.abs(stiff.hull_force - rigid.hull_force).max() <= 1e-8 * np.abs(rigid.hull_force).max()


def test_peaks_at_the_damped_natural_frequencies():
    """Light damping (zeta ~ 1e-3): the displacement peaks of each mode lie at its damped
    natural frequency to O(zeta^2) (an isolated mode peaks at w_n sqrt(1 - 2 zeta^2), the damped
    frequency is w_n sqrt(1 - zeta^2))."""
    from scipy.optimize import minimize_scalar

    d = asym_full(spin=0.0, law="constant")
    for m in d["mounts"][:3]:
        m.update(c_axial=2.0, c_shear=0.5)
    d["mounts"][3]["damping"] = (np.diag([1.0, 0.4, 0.4, 0.02, 0.02, 0.02])).tolist()
    mdl = model(d)
    thrust = 6000.0
    md = impstab.modes(mdl, thrust)
    assert md.damping_ratio.max() < 5e-3
    for j, fd in enumerate(md.frequency_hz):
        dof = md.dominant()[j][0]
        k = DOFS.index(dof)
        amp = lambda f: -abs(frequency_response(mdl, [f], thrust=thrust, input=dof).response[0, k])  # noqa: E731
        peak = minimize_scalar(amp, bounds=(fd * (1 - 2e-3), fd * (1 + 2e-3)), method="bounded",
                               options={"xatol": 1e-9 * fd}).x
        assert abs(peak - fd) <= 2e-5 * fd, (j, dof, peak, fd)
