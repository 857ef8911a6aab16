"""The nonlinear right-hand side against independent answers.

* C_RB(nu) nu equals the Newton-Euler terms (random data), and the right-hand side at rest with
  a velocity reproduces them;
* the central-difference Jacobian of the right-hand side at the static equilibrium, mapped to
  the linear coordinates q = (du, dphi), equals the linear state matrix (and so do the
  eigenvalues), on symmetric and asymmetric layouts with dampers, a full 6 x 6 mount, partial
  follower thrust and a spinning propeller;
* the mount force is THEORY 7's f = -k d - c d' for the paper's mounts;
* the pitch-singularity guard.
"""

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment
from _dyn_models import asymmetric, symmetric

from impstab import linearize
from impstab.kinematics import euler_zyx_to_matrix, matrix_to_euler_zyx, skew
from impstab.model import model_from_dict
from impstab.model.body import rigid_body_coriolis_matrix
from impstab.dynamics.system import evaluate_rhs, mount_loads, pack_dynamics


def random_body(rng):
    a = rng.normal(size=(3, 3))
    inertia_a = a @ a.T + 3 * np.eye(3)
    return float(rng.uniform(50, 200)), rng.normal(scale=0.1, size=3), inertia_a


def test_coriolis_matrix_equals_newton_euler_terms():
    rng = np.random.default_rng(1)
    for _ in range(20):
        m, rg, ia = random_body(rng)
        nu = rng.normal(size=6)
        v, w = nu[:3], nu[3:]
        c = rigid_body_coriolis_matrix(m, rg, ia, nu)
        force = m * (np.cross(w, v) + np.cross(w, np.cross(w, rg)))
        moment = np.cross(w, ia @ w) + m * np.cross(rg, np.cross(w, v))
        np.testing.assert_allclose(c @ nu, np.concatenate([force, moment]), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(c, -c.T, atol=1e-12)


@pytest.mark.parametrize("spin", [0.0, 250.0])
def test_rhs_at_rest_reproduces_coriolis_and_gyroscopic_terms(spin):
    """At the unloaded rest pose without thrust the mounts carry nothing: M nu' = -C_RB nu - [0; w x h]."""
    d = asymmetric()
    d["propeller"] = {"polar_inertia": 0.04, "speed": spin}
    model = model_from_dict(d)
    system = pack_dynamics(model)
    rng = np.random.default_rng(2)
    body = model.body
    for _ in range(5):
        nu = rng.normal(size=6)
        z = np.concatenate([np.zeros(6), nu])
        f, status = evaluate_rhs(system, np.zeros(12), z, 0.0, spin)
        assert status == 0
        h = 0.04 * spin * model.thrust.direction
        expect = -rigid_body_coriolis_matrix(body.mass, body.cg, body.inertia_a, nu) @ nu
        expect[3:] -= np.cross(nu[3:], h)
        # the mount dampers are zero; the mount springs see no deflection at the rest pose
        np.testing.assert_allclose(model.mass_matrix @ f[6:], expect, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(f[:3], nu[:3], atol=1e-15)  # R = I: X' = v


def test_rhs_at_rest_under_thrust_is_the_thrust():
    model = model_from_dict(asymmetric(tangency=0.8))
    f, _ = evaluate_rhs(pack_dynamics(model), np.zeros(12), np.zeros(12), 1234.0, 0.0)
    e, r = model.thrust.direction, model.thrust.point
    np.testing.assert_allclose(model.mass_matrix @ f[6:], np.concatenate([1234.0 * e, np.cross(r, 1234.0 * e)]),
                               rtol=1e-12)


def equilibrium_state(model, thrust):
    lin = linearize(model, thrust, "equilibrium")
    yeq = np.zeros(12)
    yeq[:3] = lin.displacement
    yeq[3:6] = matrix_to_euler_zyx(lin.rotation)
    return lin, yeq


def euler_rate_matrix(phi, theta):
    """J2 with Xi' = J2 w (w in the body frame), z-y-x Euler angles (paper eq. 7)."""
    return np.array([
        [1.0, np.sin(phi) * np.tan(theta), np.cos(phi) * np.tan(theta)],
        [0.0, np.cos(phi), -np.sin(phi)],
        [0.0, np.sin(phi) / np.cos(theta), np.cos(phi) / np.cos(theta)],
    ])


def linear_coordinates_map(yeq, rot):
    """d(q, q')/d(eta, nu) at the equilibrium: du = dX, dphi = R0 J2^-1 dXi, q' = (R0 v, R0 w)."""
    p = np.zeros((12, 12))
    p[:3, :3] = np.eye(3)
    p[3:6, 3:6] = rot @ np.linalg.inv(euler_rate_matrix(yeq[3], yeq[4]))
    p[6:9, 6:9] = rot
    p[9:, 9:] = rot
    return p


CASES = {
    "symmetric": (symmetric(), 12000.0),
    "asymmetric": (asymmetric(), 9000.0),
    "asym-damped-gyro-partial": (asymmetric(damped=True, gyro=True, tangency=0.8), 9000.0),
    "asym-supercritical": (asymmetric(damped=True, gyro=True), 14000.0),
    "asym-fluid": ({**asymmetric(damped=True), "hull": {"radius": 0.15, "length": 0.8, "center": [0.1, 0.01, 0.0]},
                    "fluid": {"model": "baffled-cylinder", "density": 1025.0}}, 9000.0),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_jacobian_at_equilibrium_equals_linear_state_matrix(case):
    d, thrust = CASES[case]
    model = model_from_dict(d)
    lin, yeq = equilibrium_state(model, thrust)
    system = pack_dynamics(model)
    spin = model.propeller.spin(thrust, model.thrust.operating)
    f0, _ = evaluate_rhs(system, yeq, np.zeros(12), thrust, spin)
    assert np.abs(f0).max() < 1e-9  # the static equilibrium is an equilibrium of the dynamics

    def jac(h):
        out = np.zeros((12, 12))
        for j in range(12):
            dz = np.zeros(12)
            dz[j] = h
            out[:, j] = (evaluate_rhs(system, yeq, dz, thrust, spin)[0] - evaluate_rhs(system, yeq, -dz, thrust, spin)[0]) / (2 * h)
        return out

    jacobian = (4 * jac(5e-7) - jac(1e-6)) / 3
    p = linear_coordinates_map(yeq, lin.rotation)
    a = lin.state_matrix()
    mapped = p @ jacobian @ np.linalg.inv(p)
    assert np.abs(mapped - a).max() < 1e-8 * np.abs(a).max()
    ev_nl, ev_lin = np.linalg.eigvals(jacobian), np.linalg.eigvals(a)
    rows, cols = linear_sum_assignment(np.abs(ev_nl[:, None] - ev_lin[None, :]))
    # double roots at T_c would split like sqrt(eps); these thrusts are away from them
    assert np.abs(ev_nl[rows] - ev_lin[cols]).max() < 1e-6 * np.abs(ev_lin).max()
    if case != "symmetric":
        assert np.abs(yeq[3:6]).max() > 1e-3  # the equilibrium is rotated: the map matters


def test_mount_force_is_minus_k_d_minus_c_ddot():
    """THEORY 7: d = X + R r - r, d' = R (v + w x r), f = -k d - c d' (hull frame)."""
    d = asymmetric(damped=True)
    model = model_from_dict(d)
    system = pack_dynamics(model)
    rng = np.random.default_rng(3)
    yeq = np.concatenate([rng.normal(scale=0.01, size=3), rng.normal(scale=0.05, size=3), np.zeros(6)])
    z = np.concatenate([np.zeros(6), rng.normal(scale=0.1, size=6)])
    loads = mount_loads(system, yeq, z[None])[0]
    rot = euler_zyx_to_matrix(*yeq[3:6])
    v, w = z[6:9], z[9:]
    for i, mt in enumerate(model.mounts[:3]):  # the paper's mounts (translation block only)
        r = mt.position
        dd = yeq[:3] + rot @ r - r
        ddot = rot @ (v + np.cross(w, r))
        f = -mt.stiffness[:3, :3] @ dd - mt.damping[:3, :3] @ ddot
        np.testing.assert_allclose(loads[i, :3], f, rtol=1e-12, atol=1e-12)
        assert np.all(loads[i, 3:] == 0)
    assert np.abs(loads[3, 3:]).max() > 0  # the full 6 x 6 mount also carries a moment


def test_pitch_guard_in_the_right_hand_side():
    system = pack_dynamics(model_from_dict(symmetric()), pitch_limit=np.radians(80))
    y = np.zeros(12)
    y[4] = np.radians(79)
    assert evaluate_rhs(system, y, np.zeros(12), 0.0)[1] == 0
    y[4] = np.radians(81)
    f, status = evaluate_rhs(system, y, np.zeros(12), 0.0)
    assert status == 2 and np.all(np.isfinite(f))
    y[4] = np.pi / 2
    f, status = evaluate_rhs(system, y, np.zeros(12), 0.0)
    assert status == 2 and np.all(np.isnan(f))


def test_skew_convention_used_by_the_oracles():
    a, b = np.array([1.0, 2.0, 3.0]), np.array([-0.5, 0.3, 2.0])
    np.testing.assert_allclose(skew(a) @ b, np.cross(a, b))


def nonlinear_case():
    """The asymmetric layout with cubic springs and a snubber engaged at 4500 N."""
    d = asymmetric(damped=True, gyro=True, tangency=0.8)
    for i, m in enumerate(d["mounts"][:3]):
        m["k3_axial"] = [2e8, -1e8, 1e8][i]
        m["k3_shear"] = [5e8, 2e8, -1e8][i]
    d["mounts"][0].update(snubber_clearance=0.004, snubber_stiffness=3e6)
    return d, 4500.0


COMPLEX_CASES = {**CASES, "nonlinear-laws": nonlinear_case()}


@pytest.mark.parametrize("case", sorted(COMPLEX_CASES))
def test_complex_step_jacobian_equals_the_state_matrix(case):
    """The compiled right-hand side on complex states: its complex-step Jacobian at the static
    equilibrium, mapped to q = (du, dphi), is the exact tangent to rounding."""
    from impstab.dynamics.system import NonlinearSystem

    d, thrust = COMPLEX_CASES[case]
    model = model_from_dict(d)
    ns = NonlinearSystem(model)
    y0 = ns.equilibrium(thrust)
    lin = linearize(model, thrust, "equilibrium")
    jac = ns.jacobian(y0, thrust)
    p = linear_coordinates_map(y0, lin.rotation)
    a = lin.state_matrix()
    mapped = p @ jac @ np.linalg.inv(p)
    # measured 6e-16 to 3e-13 (the stiff engaged snubber); central differences give 5e-11
    assert np.abs(mapped - a).max() < 5e-13 * np.abs(a).max(), np.abs(mapped - a).max() / np.abs(a).max()
    # the real part of a complex evaluation is the real evaluation, to rounding
    rng = np.random.default_rng(7)
    ys = y0 + rng.normal(scale=1e-3, size=(5, 12))
    real = ns.rhs(ys, thrust)
    cplx = ns.rhs(ys + 1e-40j * rng.normal(size=(5, 12)), thrust)
    assert cplx.dtype == complex and real.dtype == float and real.shape == (5, 12)
    assert np.abs(cplx.real - real).max() <= 1e-15 * np.abs(real).max()


def test_cauchy_taylor_coefficients_of_the_complex_rhs_are_exact():
    """Second and third derivatives along a direction from evaluations on a complex circle
    (f(y0 + r e^{i theta} v), FFT) equal finite differences of the complex-step Jacobian and of
    the second coefficient; the circle is far from the snubber's contact radius."""
    from impstab.dynamics.system import NonlinearSystem

    d, thrust = nonlinear_case()
    ns = NonlinearSystem(model_from_dict(d))
    y0 = ns.equilibrium(thrust)
    rng = np.random.default_rng(11)
    v = rng.normal(size=12) * np.array([1e-3] * 3 + [1e-2] * 3 + [1e-2] * 6)
    k, r = 32, 0.5
    theta = 2 * np.pi * np.arange(k) / k
    f = ns.rhs(y0[None, :] + r * np.exp(1j * theta)[:, None] * v[None, :], thrust)
    coef = np.fft.fft(f, axis=0) / k / r ** np.arange(k)[:, None]  # c_m = D^m f [v]^m / m!
    jv = ns.jacobian(y0, thrust) @ v
    np.testing.assert_allclose(coef[1].real, jv, rtol=1e-10, atol=1e-10 * np.abs(jv).max())
    h = 1e-4
    d2 = (ns.jacobian(y0 + h * v, thrust) @ v - ns.jacobian(y0 - h * v, thrust) @ v) / (2 * h)
    np.testing.assert_allclose(2 * coef[2].real, d2, rtol=1e-6, atol=1e-6 * np.abs(d2).max())
    d3 = (ns.jacobian(y0 + h * v, thrust) @ v - 2 * jv + ns.jacobian(y0 - h * v, thrust) @ v) / h**2
    np.testing.assert_allclose(6 * coef[3].real, d3, rtol=1e-4, atol=1e-4 * np.abs(d3).max())
    assert np.abs(coef[:5].imag).max() <= 1e-9 * np.abs(coef[:5]).max()  # a real function on the real axis
