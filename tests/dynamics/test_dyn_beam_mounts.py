"""Time histories with massive beam mounts against independent answers.

* the complex-step Jacobian of the right-hand side at the static equilibrium (at rest, and at a
  thrust whose equilibrium is rotated) has the eigenvalues of the grown linear system of
  ``MountDofs.augment`` with the same kept modes (the stability analysis's family);
* small-amplitude runs of a damped variant of examples/imp_beam_mounts.toml below and above the
  critical thrust grow or decay at the least-stable eigenvalue of that family;
* a body of mass M on one axial rod (density rho, area A, modulus E, length L, clamped at the
  hull): the exact frequency equation of the longitudinal rod with a tip mass,
  ``EA u'(L) = -M u''(L)`` with ``u = sin(beta x)``: ``beta L tan(beta L) = rho A L / M``,
  against the simulated free vibration, converging with the elements;
* an explicit step beyond the stability limit of the fastest kept mode is refused in one line;
  radau and lsoda (exact complex-step Jacobian) agree with hamming.
"""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import impstab
from impstab.dynamics.beam_mounts import OSCILLATION_LIMIT, SIM_CUTOFF
from impstab.dynamics.system import NonlinearSystem
from impstab.errors import ModelError
from impstab.linear.eigen import state_matrices
from impstab.linear.linearize import ModelFamily
from impstab.model import model_from_dict

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
L, D, E, G, RHO = 0.05, 0.04, 5.0e6, 1.7e6, 1100.0
ROD_MASS = RHO * np.pi * D * D / 4 * L
BODY_MASS = 2.0 * ROD_MASS


def _example(damped: bool = False, asymmetric: bool = False):
    import tomllib

    d = tomllib.loads((EXAMPLES / "imp_beam_mounts.toml").read_text())
    for mount in d["mounts"]:
        if damped:
            mount["c_axial"], mount["c_shear"] = 40.0, 8.0
    if asymmetric:
        d["mounts"][0]["position"] = [0.3, 0.13, 0.08]  # the equilibrium under thrust is rotated
    return model_from_dict(d)


def _grown_eigenvalues(model, thrust):
    """Eigenvalues of the first-order form of the grown system (the kept modes of the time
    histories) at the static equilibrium at ``thrust``."""
    fam = ModelFamily(model, "equilibrium", cutoff=SIM_CUTOFF)
    m, d, g, k = (a[0] for a in fam.matrices(np.array([float(thrust)])))
    return np.linalg.eigvals(state_matrices(m, d + g, k))


def _sorted(v):
    return v[np.lexsort((np.round(v.real, 6), np.round(v.imag, 6)))]


@pytest.mark.parametrize("asymmetric,thrust", [(False, 0.0), (True, 20000.0)])
def test_jacobian_has_the_eigenvalues_of_the_grown_linear_system(asymmetric, thrust):
    model = _example(damped=True, asymmetric=asymmetric)
    ns = NonlinearSystem(model)
    n_modes = ns.system.n_modes
    assert n_modes == 12 and ns.n_states == 12 + 2 * n_modes  # three kept modes per beam
    y0 = ns.equilibrium(thrust)
    assert np.all(y0[12:] == 0.0) and np.max(np.abs(ns.rhs(y0, thrust))) < 1e-9
    if asymmetric:
        assert np.max(np.abs(y0[3:6])) > 1e-3  # a rotated equilibrium: the arms are R0 r
    got = _sorted(np.linalg.eigvals(ns.jacobian(y0, thrust)))
    want = _sorted(_grown_eigenvalues(model, thrust))
    assert np.max(np.abs(got - want) / np.abs(want)) < 1e-9  # measured 1e-14


@pytest.fixture(scope="module")
def damped_example():
    model = _example(damped=True)
    return model, impstab.critical_thrust(model, linearization="equilibrium")


@pytest.mark.parametrize("factor", [0.9, 1.1])
def test_small_amplitude_growth_equals_least_stable_eigenvalue(damped_example, factor):
    model, crit = damped_example
    thrust = factor * crit.thrust
    vals = _grown_eigenvalues(model, thrust)
    body = vals[(vals.imag > 1e-6) & (vals.imag < 3 * crit.omega)]  # the undamped beam modes lie far above
    lam = body[np.argmax(body.real)]
    res = impstab.simulate(model, thrust, 12.0, "hamming", critical_thrust=crit.thrust, sample=2e-3)
    assert res.completed and res.beam_modes.shape[1] == 12
    fit = res.growth
    assert (lam.real > 0) == (factor > 1) and res.classification == ("supercritical" if factor > 1 else "subcritical")
    if factor > 1:
        assert abs(fit.linear_rate - lam.real) < 1e-9 * abs(lam.real)
    assert abs(fit.rate - lam.real) < 1e-6 * abs(lam.real)  # measured 6e-8 (0.9), 3e-8 (1.1)
    assert abs(fit.frequency_hz - lam.imag / (2 * np.pi)) < 1e-9 * lam.imag / (2 * np.pi)  # measured 2e-11


def _rod(elements: int):
    model = model_from_dict({
        "schema_version": 1, "name": "body on one axial rod",
        "body": {"mass": BODY_MASS, "cg": [0.0, 0.0, 0.0], "inertia": [1e-4, 1e-4, 1e-4]},
        "mounts": [{"position": [0.0, 0.0, 0.0], "axis": [1.0, 0.0, 0.0],
                    "beam": {"length": L, "outer_diameter": D, "youngs_modulus": E, "shear_modulus": G,
                             "density": RHO}}],
        "thrust": {"point": [0.0, 0.0, 0.0], "direction": [1.0, 0.0, 0.0], "tangency": 1.0, "operating": 1.0},
        "analysis": {"thrust_max": 10.0}})
    mount = model.mounts[0]
    return replace(model, mounts=(replace(mount, beam=replace(mount.beam, elements=elements)),))


def _rod_frequency() -> float:
    """The exact surge frequency (rad/s): ``beta L tan(beta L) = m_rod / M``, ``omega = beta sqrt(E / rho)``."""
    bl = brentq(lambda x: x * np.tan(x) - ROD_MASS / BODY_MASS, 1e-9, np.pi / 2 - 1e-9)
    return bl / L * np.sqrt(E / RHO)


def _crossing_frequency(t, x):
    """Mean frequency (rad/s) from the downward zero crossings of ``x`` (linear interpolation)."""
    s = np.flatnonzero((x[:-1] > 0) & (x[1:] <= 0))
    tc = t[s] + (t[s + 1] - t[s]) * x[s] / (x[s] - x[s + 1])
    return 2 * np.pi * (tc.size - 1) / (tc[-1] - tc[0])


def test_body_on_an_axial_rod_vibrates_at_the_exact_rod_frequency():
    exact = _rod_frequency()
    rayleigh = np.sqrt(E * np.pi * D * D / 4 / L / (BODY_MASS + ROD_MASS / 3))
    assert abs(rayleigh / exact - 1) > 1e-3  # the rod's distributed inertia matters beyond Rayleigh's m/3
    errors = []
    for n in (2, 4, 8):
        x0 = 1e-4
        res = impstab.simulate(_rod(n), 0.0, 30 * 2 * np.pi / exact, "hamming",
                               perturbation={"displacement": {"surge": x0}}, critical_thrust=False)
        assert res.completed and np.max(np.abs(res.deviation[:, 1:6])) < 1e-15  # pure surge
        errors.append(abs(_crossing_frequency(res.time, res.deviation[:, 0]) / exact - 1))
        # the reported mount load: the static tip stiffness EA / L at the body-end deflection
        force = res.mount_loads[:, 0, 0]
        np.testing.assert_allclose(force, -E * np.pi * D * D / 4 / L * res.deviation[:, 0], rtol=1e-9, atol=1e-12)
    # measured 6.1e-4, 1.5e-4, 5.0e-5: second order in the element length
    assert errors[0] < 1e-3 and errors[1] < errors[0] / 3 and errors[2] < errors[1] / 2.5 and errors[2] < 6e-5


def test_explicit_step_beyond_the_fastest_kept_mode_is_refused_in_one_line():
    model = _rod(4)
    omega = impstab.simulate(model, 0.0, 1e-3, "radau", critical_thrust=False).fastest_omega
    dt = 1.2 * OSCILLATION_LIMIT["hamming"] / omega
    with pytest.raises(ModelError) as info:
        impstab.simulate(model, 0.0, 0.01, "hamming", dt=dt, critical_thrust=False)
    text = str(info.value)
    assert info.value.field == "dt" and "\n" not in text and "radau" in text and "lsoda" in text
    gill = 1.2 * OSCILLATION_LIMIT["gill"] / omega
    with pytest.raises(ModelError):
        impstab.simulate(model, 0.0, 0.01, "gill", dt=gill, critical_thrust=False)
    res = impstab.simulate(model, 0.0, 0.01, "radau", dt=gill, critical_thrust=False)  # its largest step
    assert res.completed


def test_cli_refuses_a_stiff_explicit_step_in_one_line(capsys, tmp_path):
    from impstab.cli import main

    out = tmp_path / "s.nc"
    code = main(["simulate", str(EXAMPLES / "imp_beam_mounts.toml"), "--thrust", "1000", "--duration", "0.1",
                 "--dt", "1e-3", "-o", str(out)])
    _, err = capsys.readouterr()
    assert code == 2 and err.count("\n") == 1 and err.startswith("impstab: error: --dt = 0.001")
    assert "internal mode" in err and "radau" in err and not list(tmp_path.iterdir())
    # the default step runs and the file carries the modal coordinates
    code = main(["simulate", str(EXAMPLES / "imp_beam_mounts.toml"), "--thrust", "1000", "--duration", "0.02",
                 "--no-plot", "-o", str(out)])
    assert code == 0 and out.exists()
    import xarray as xr

    with xr.open_dataset(out) as ds:
        assert ds.sizes["beam_mode"] == 12 and list(np.unique(ds["beam_mode_mount"].values)) == [0, 1, 2, 3]


def test_radau_agrees_with_hamming_and_the_modes_round_trip(tmp_path):
    model = _rod(4)
    kw = dict(perturbation={"displacement": {"surge": 1e-4}, "velocity": {"sway": 1e-3, "pitch": 1e-2}},
              critical_thrust=False, sample=2e-4)
    ham = impstab.simulate(model, 0.0, 0.05, "hamming", **kw)
    rad = impstab.simulate(model, 0.0, 0.05, "radau", rtol=1e-10, **kw)
    scale = np.max(np.abs(rad.deviation), axis=0)
    assert np.allclose(ham.time, rad.time)
    err = np.max(np.abs(ham.deviation - rad.deviation) / scale)
    assert err < 1e-5  # measured 6.9e-7
    # the fastest kept modes (40 steps a period, some hundred periods) carry Hamming's phase error
    err = np.max(np.abs(ham.beam_modes - rad.beam_modes)) / np.max(np.abs(rad.beam_modes))
    assert err < 1e-4  # measured 1.6e-5
    assert np.max(np.abs(rad.beam_modes)) > 0 and np.all(rad.beam_mode_mounts == 0)
    lsoda = impstab.simulate(model, 0.0, 0.05, "lsoda", rtol=1e-10, **kw)
    assert np.max(np.abs(lsoda.deviation - rad.deviation) / scale) < 1e-6  # measured 6e-8
    path = tmp_path / "r.nc"
    rad.to_xarray().to_netcdf(path)
    import xarray as xr

    with xr.open_dataset(path) as ds:
        back = type(rad).from_xarray(ds.load())
    np.testing.assert_array_equal(back.beam_modes, rad.beam_modes)
    np.testing.assert_array_equal(back.beam_mode_rates, rad.beam_mode_rates)
    np.testing.assert_array_equal(back.beam_mode_omega, rad.beam_mode_omega)
