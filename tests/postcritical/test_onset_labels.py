"""The label of a propulsor's onset where l1 is small or a neighbouring pair is near, against
independent answers.

* ``imp_damped.toml`` (linear mounts: the only nonlinearity is the rigid-body kinematics and the
  follower-thrust geometry): l1 is small, 7.29e-7, and positive. The same value from Cauchy
  circles of 3, 10 and 30 state scales and 16 or 32 points (a different rounding and truncation
  each time) to within the stated bound; and the normal-form relation
  ``T - T_c = -(omega l1 / sigma') rho^2`` against the collocation branch, with ``rho`` the
  adjoint projection ``|p^H x_1|`` of each computed cycle's first harmonic (p^H q = 1): a fit of
  ``T - T_c = a + b rho^2 + c rho^4`` to the first branch points gives ``b``;
* a lightly damped asymmetric model (c_axial = 4, c_shear = 1 N s/m on every mount): the crossing
  pair is simple (its neighbour 5e-3 |lambda| away, far above the coalescence resolution), so it
  is labelled with l1 and warned about the small range of the normal form; a long Hamming run
  just past T_c settles on the small stable cycle of the computed branch (supercritical);
* the softening example with dampers ten times lighter: l1 < 0 (the critical mode changes), and a
  run from a small displacement past T_c settles on the small cycle, not on the snubber cycle of
  the same branch (with its own dampers l1 > 0 and the run jumps to the snubber cycle:
  test_propulsor.py);
* snubbers engaged at the equilibrium: the same l1 on circles of 1 to 30 state scales;
* a model whose mounts have rotational (6 x 6) stiffness, rotated at equilibrium: l1 does not
  depend on the circle (the logarithm of the rotation is continued analytically, not clamped).
"""

import tomllib
from pathlib import Path

import numpy as np
import pytest

import impstab
from _settled import settled_amplitude
from impstab.model import model_from_dict
from impstab.postcritical import hopf_analysis, propulsor_postcritical
from impstab.postcritical.propulsor import propulsor_system

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _toml(name: str) -> dict:
    with open(EXAMPLES / name, "rb") as fh:
        return tomllib.load(fh)


@pytest.fixture(scope="module")
def damped():
    model = impstab.load_model(EXAMPLES / "imp_damped.toml")
    return model, propulsor_postcritical(model, max_points=24)


def test_imp_damped_is_subcritical_with_a_small_l1(damped):
    _, res = damped
    assert res.bifurcation == "subcritical" and res.reason is None
    assert res.lyapunov_coefficient == pytest.approx(7.2931e-7, rel=1e-4)
    assert res.lyapunov_error < 1e-4 * res.lyapunov_coefficient
    assert res.reading.startswith("dangerous")


def test_imp_damped_l1_does_not_depend_on_the_circle(damped):
    model, res = damped
    crit = impstab.critical_thrust(model)
    system, ns = propulsor_system(model, crit.omega)
    x0 = ns.equilibrium(crit.thrust)
    values = []
    for radius in (3.0, 10.0, 30.0):
        for points in (16, 32):
            h = hopf_analysis(system, x0, crit.thrust, omega=crit.omega, radius=radius, points=points, check=False)
            assert h.bifurcation == "subcritical"
            assert abs(h.lyapunov_coefficient - res.lyapunov_coefficient) <= h.lyapunov_error + res.lyapunov_error
            values.append(h.lyapunov_coefficient)
    assert np.ptp(values) < 1e-5 * res.lyapunov_coefficient


def _rho(cycle, adjoint, samples=256):
    """``|p^H x_1|``: the adjoint projection of the first harmonic of a cycle (``x ~ 2 Re(rho q e^{i theta})``)."""
    t = np.arange(samples) / samples * cycle.period
    x = np.asarray(cycle.states(t))
    x1 = np.exp(-2j * np.pi * np.arange(samples) / samples) @ x / samples
    return abs(np.vdot(adjoint, x1))


def test_imp_damped_branch_bends_back_as_the_normal_form_says(damped):
    _, res = damped
    h = res.hopf
    predicted = -h.omega * h.lyapunov_coefficient / h.crossing_speed          # N per unit rho^2 (about -0.4168)
    cycles = res.cycles.cycles
    rho = np.array([_rho(c, h.adjoint) for c in cycles])
    dt = np.array([c.parameter for c in cycles]) - h.parameter
    use = (rho > 5e-3) & (rho < 0.5)
    assert use.sum() >= 6
    design = np.stack([np.ones(use.sum()), rho[use] ** 2, rho[use] ** 4], axis=1)
    (_, slope, _), *_ = np.linalg.lstsq(design, dt[use], rcond=None)
    assert predicted < 0 and slope == pytest.approx(predicted, rel=1e-5)
    assert np.all(dt[rho > 5e-3] < 0) and not np.any(res.branch_stable)     # unstable cycles below T_c


@pytest.fixture(scope="module")
def lightly_damped():
    d = _toml("imp_asymmetric.toml")
    for mount in d["mounts"]:
        mount["c_axial"], mount["c_shear"] = 4.0, 1.0
    model = model_from_dict(d)
    tc = impstab.critical_thrust(model).thrust
    return model, tc, propulsor_postcritical(model, thrusts=[tc + 20.0], max_points=24)


def test_a_lightly_damped_onset_is_a_plain_hopf_point_with_a_warning(lightly_damped):
    _, tc, res = lightly_damped
    h = res.hopf
    lam = h.spectrum
    others = np.delete(lam, int(np.argmin(np.abs(lam - h.eigenvalue))))
    gap = np.min(np.abs(others - h.eigenvalue)) / np.abs(h.eigenvalue)
    assert 1e-3 < gap < 0.05                                               # a near but distinct neighbour
    assert res.bifurcation == "supercritical" and res.lyapunov_coefficient < 0
    assert abs(res.lyapunov_coefficient) > 1e3 * res.lyapunov_error
    assert any("near neighbour" in w for w in res.warnings)
    assert any("near neighbour" in w for w in res.to_dict()["warnings"])


def test_a_long_run_past_the_lightly_damped_onset_lands_on_the_small_cycle(lightly_damped):
    model, tc, res = lightly_damped
    thrust = tc + 20.0
    (i,) = [k for k, t in enumerate(res.branch_thrust) if t == thrust]
    assert res.branch_stable[i] and res.branch_amplitude[i, 4] < 0.05       # small: 0.044 rad of pitch
    settle = impstab.simulate(model, thrust=thrust, duration=1200.0, dt=2e-3, integrator="hamming",
                              critical_thrust=tc, sample=0.5, perturbation={"displacement": {"pitch": 0.03}})
    z = settle.deviation[-1]
    run = impstab.simulate(model, thrust=thrust, duration=0.5, dt=1e-3, integrator="hamming", critical_thrust=tc,
                           sample=1e-4, perturbation={"displacement": z[:6], "velocity": z[6:]})
    y = run.deviation + run.equilibrium
    amplitude = 0.5 * (y[:, :6].max(axis=0) - y[:, :6].min(axis=0))
    np.testing.assert_allclose(amplitude, res.branch_amplitude[i], rtol=5e-5)


def test_rotational_mount_stiffness_l1_does_not_depend_on_the_circle():
    d = _toml("imp_beam_mounts.toml")
    for mount in d["mounts"]:
        mount["beam"]["density"] = 0.0                                      # massless beams: a 6 x 6 stiffness
        mount["c_axial"], mount["c_shear"] = 40.0, 8.0
    d["mounts"][0]["position"] = [0.3, 0.13, 0.08]                          # asymmetric: rotated at equilibrium
    model = model_from_dict(d)
    crit = impstab.critical_thrust(model)
    system, ns = propulsor_system(model, crit.omega)
    x0 = ns.equilibrium(crit.thrust)
    assert np.max(np.abs(x0[3:6])) > 0.01
    hs = [hopf_analysis(system, x0, crit.thrust, omega=crit.omega, radius=r, points=32, check=False)
          for r in (3.0, 10.0, 30.0)]
    l1 = np.array([h.lyapunov_coefficient for h in hs])
    assert all(h.bifurcation == "supercritical" for h in hs)
    assert np.ptp(l1) < 1e-6 * abs(l1[0]) and max(h.lyapunov_error for h in hs) < 1e-4 * abs(l1[0])


def _softening(c_axial, c_shear):
    d = _toml("imp_softening.toml")
    for mount in d["mounts"]:
        mount["c_axial"], mount["c_shear"] = c_axial, c_shear
    model = model_from_dict(d)
    tc = impstab.critical_thrust(model).thrust
    return model, tc, propulsor_postcritical(model, thrusts=[tc + 50.0], max_points=60)


def test_light_damping_makes_the_softening_onset_supercritical_and_a_run_stays_on_the_small_cycle():
    # softening shear springs, but with dampers 10 times lighter the critical mode changes and
    # l1 < 0: a small stable cycle past T_c, which the branch later folds away from. The run from a
    # small displacement settles on it, 12 times smaller than the snubber cycle on the same branch
    model, tc, res = _softening(4.0, 1.0)
    assert res.bifurcation == "supercritical" and any("near neighbour" in w for w in res.warnings)
    idx = [k for k, t in enumerate(res.branch_thrust) if t == tc + 50.0]
    small = min(idx, key=lambda k: res.branch_amplitude[k, 4])
    assert res.branch_stable[small] and not res.snubber_contact[small] and len(idx) >= 2
    amplitude = settled_amplitude(model, tc + 50.0, tc, 1500.0, 8e-4)
    np.testing.assert_allclose(amplitude, res.branch_amplitude[small], rtol=1e-4)


def test_snubbers_engaged_at_equilibrium_give_the_same_l1_on_every_circle():
    # clearance 30 mm, the static deflection at the onset 0.10 m: every snubber is beyond its
    # smoothing ramp at the equilibrium; the circles must stay there (region codes), and where a
    # large one meets the singularity of |d| the radius is shrunk until the bound is small
    d = _toml("imp_softening.toml")
    for mount in d["mounts"]:
        mount["snubber_clearance"] = 0.03
    d["analysis"]["thrust_max"] = 2.0e5
    model = model_from_dict(d)
    crit = impstab.critical_thrust(model)
    system, ns = propulsor_system(model, crit.omega)
    x0 = ns.equilibrium(crit.thrust)
    assert np.all(system.region(x0[None].astype(complex))[0, 1:] == 2)      # beyond the ramp on every mount
    hs = [hopf_analysis(system, x0, crit.thrust, omega=crit.omega, radius=r, points=n, check=False)
          for r in (1.0, 10.0, 30.0) for n in (16, 32)]
    l1 = np.array([h.lyapunov_coefficient for h in hs])
    err = np.array([h.lyapunov_error for h in hs])
    assert all(h.bifurcation == "subcritical" for h in hs) and np.all(err < 1e-3 * l1)
    assert np.ptp(l1) <= 2 * err.max()
