"""The simulate API and command line: result objects, netCDF and CSV, figures, thrust histories,
input errors (exit code 2), the step-size warning."""

import json
import warnings
from pathlib import Path

import matplotlib
import numpy as np
import pytest
import xarray as xr
from _dyn_models import symmetric

import impstab
from impstab.cli import main
from impstab.dynamics import Perturbation, Ramp, SimulationResult, Step, StepSizeWarning
from impstab.model import load_model, model_from_dict
from impstab.model.model import DOF_NAMES

matplotlib.use("Agg")
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def ring():
    return model_from_dict(symmetric())


@pytest.fixture(scope="module")
def run(ring):
    return impstab.simulate(ring, thrust=19000.0, duration=2.0, critical_thrust=18012.0999227555)


def test_result_to_xarray_and_netcdf_round_trip(run, tmp_path):
    ds = run.to_xarray()
    assert list(ds["time"].dims) == ["time"] and ds["time"].attrs["units"] == "s"
    for name in DOF_NAMES:
        for var in (name, f"{name}_absolute", f"{name}_velocity"):
            assert ds[var].dims == ("time",)
    assert ds["mount_force"].dims == ("time", "mount", "axis") and ds.sizes["mount"] == 3
    assert ds.attrs["integrator"] == "hamming" and ds.attrs["classification"] == "supercritical"
    assert ds.attrs["growth_rate_fit"] == pytest.approx(ds.attrs["growth_rate_linear"], rel=0.01)
    # relative and absolute: the absolute surge adds the static deflection under 19 kN
    np.testing.assert_allclose(ds["surge_absolute"] - ds["surge"], run.equilibrium[0])
    assert run.equilibrium[0] == pytest.approx(19000.0 / 3e5, rel=1e-9)  # three axial springs
    path = tmp_path / "run.nc"
    ds.to_netcdf(path, engine="h5netcdf")
    back = SimulationResult.from_xarray(xr.open_dataset(path, engine="h5netcdf"))
    np.testing.assert_array_equal(back.deviation, run.deviation)
    np.testing.assert_array_equal(back.mount_loads, run.mount_loads)
    assert back.growth == run.growth and back.classification == run.classification
    assert back.completed == run.completed and back.perturbation == run.perturbation


def test_mount_forces_balance_the_thrust_at_equilibrium(ring):
    res = impstab.simulate(ring, thrust=5000.0, duration=0.05, critical_thrust=False, perturbation={})
    total = res.mount_loads[:, :, :3].sum(axis=1)
    np.testing.assert_allclose(total, np.tile([-5000.0, 0, 0], (res.time.size, 1)), atol=1e-9)
    np.testing.assert_allclose(res.thrust, 5000.0)


def test_plot_returns_axes(run):
    import matplotlib.pyplot as plt

    from impstab.plot.simulation import plot_simulations

    ax_s, ax_p = run.plot()
    assert ax_s.get_ylabel() == "sway (µm)" and ax_p.get_ylabel() == "pitch (µrad)"  # 1e-5 kick
    n = ax_s.lines[0].get_ydata().size
    np.testing.assert_allclose(ax_s.lines[0].get_ydata() * 1e-6, run.displacement[:n, 1], rtol=1e-15)
    _, one = plt.subplots()
    assert run.plot(ax=one) is one
    axes = plot_simulations([run, run, run])
    assert len(axes.sway) == 3 and len(axes.pitch) == 3
    plt.close("all")


def test_thrust_histories(ring):
    step = impstab.simulate(ring, thrust=Step(3000.0, 4000.0, 0.1), duration=0.2, critical_thrust=False)
    user = impstab.simulate(ring, thrust=lambda t: 3000.0 if t < 0.1 else 4000.0, duration=0.2, critical_thrust=False)
    np.testing.assert_array_equal(step.deviation, user.deviation)  # a scalar-only callable
    vec = impstab.simulate(ring, thrust=lambda t: 3000.0 + 1000.0 * (np.asarray(t) >= 0.1), duration=0.2,
                           critical_thrust=False)
    np.testing.assert_array_equal(step.deviation, vec.deviation)  # a vectorised callable
    assert step.thrust[0] == 3000.0 and step.thrust[-1] == 4000.0
    assert "user function" in user.thrust_history


def test_slow_ramp_ends_at_the_static_equilibrium():
    model = load_model(EXAMPLES / "imp_damped.toml")
    res = impstab.simulate(model, thrust=Ramp(0.0, 5000.0, 4.0), duration=12.0, critical_thrust=False,
                           perturbation={})
    target = impstab.linearize(model, 5000.0).displacement
    assert res.absolute[-1, 0] == pytest.approx(target[0], rel=1e-3)
    assert res.equilibrium[0] == 0.0  # started unloaded


def test_default_perturbation_and_validation(ring):
    p = Perturbation.coerce(None)
    assert dict(zip(DOF_NAMES, p.velocity)) == {"surge": 0, "sway": 1e-5, "heave": 0, "roll": 0, "pitch": 1e-5, "yaw": 0}
    assert not any(p.displacement)
    for bad in ({"velocity": {"swya": 1.0}}, {"displacment": {}}, [1.0, 2.0], {"velocity": [np.nan] * 6}):
        with pytest.raises(impstab.ModelError):
            impstab.simulate(ring, thrust=1000.0, duration=0.1, perturbation=bad)
    for kwargs in ({"integrator": "euler"}, {"duration": -1.0}, {"dt": 0.0}, {"thrust": -5.0}, {"thrust": "x"}):
        with pytest.raises(impstab.ModelError):
            impstab.simulate(ring, **{"thrust": 1000.0, "duration": 0.1, **kwargs})


def test_step_too_large_warns_with_mode_and_limit(ring):
    with pytest.warns(StepSizeWarning, match=r"limit 0\.00286\d* s for the fastest mode \(surge, 8\.717 Hz\)"):
        impstab.simulate(ring, thrust=1000.0, duration=0.1, dt=0.01, critical_thrust=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", StepSizeWarning)
        res = impstab.simulate(ring, thrust=1000.0, duration=0.1, critical_thrust=False)
        assert res.dt <= res.step_limit and res.step_limit == pytest.approx(2 * np.pi / (40 * np.sqrt(3e5 / 100)))
        impstab.simulate(ring, thrust=1000.0, duration=0.1, dt=0.01, integrator="dop853", critical_thrust=False)


def cli(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_netcdf_csv_png_and_json(capsys, tmp_path):
    model = str(EXAMPLES / "imp_symmetric.toml")
    out = tmp_path / "run.nc"
    code, text, err = cli(capsys, "simulate", model, "--thrust", "19000", "--duration", "2", "-o", str(out))
    assert code == 0, err
    assert out.is_file() and out.with_suffix(".png").is_file()
    assert "supercritical" in text and "exponential growth" in text
    ds = xr.open_dataset(out, engine="h5netcdf")
    assert ds.attrs["classification"] == "supercritical" and "sway" in ds
    csv = tmp_path / "run.csv"
    code, text, err = cli(capsys, "simulate", model, "--thrust", "5000", "--duration", "0.3", "--integrator", "dop853",
                          "--kick", "heave=1e-4", "--displace", "pitch=1e-4", "-o", str(csv), "--json")
    assert code == 0, err
    d = json.loads(text)
    assert d["runs"][0]["integrator"] == "dop853" and d["runs"][0]["perturbation"]["velocity"]["heave"] == 1e-4
    header = csv.read_text().splitlines()[0].split(",")
    assert header[:3] == ["case_thrust", "time", "surge"] and "mount2_fz" in header


def test_cli_several_thrusts_in_one_figure(capsys, tmp_path):
    out = tmp_path / "three.nc"
    code, text, err = cli(capsys, "simulate", str(EXAMPLES / "imp_symmetric.toml"), "--thrusts", "12000,18012.0999,19000",
                          "--duration", "3", "-o", str(out))
    assert code == 0, err
    ds = xr.open_dataset(out, engine="h5netcdf")
    assert ds.sizes["case"] == 3 and ds["sway"].dims == ("case", "time")
    assert list(ds["classification"].values) == ["subcritical", "critical", "supercritical"]
    assert out.with_suffix(".png").is_file()


@pytest.mark.parametrize("args, field", [
    (("--thrusts", "1000,x"), "--thrusts"),
    (("--thrust", "1000", "--thrusts", "1,2"), "--thrusts"),
    ((), "--thrust"),
    (("--thrust", "1000", "--dt", "-1"), "--dt"),
    (("--thrust", "1000", "--kick", "spin=1"), "--kick"),
    (("--thrust", "1000", "-o", "out.txt"), "--output"),
])
def test_cli_bad_input_exit_2_without_files(capsys, tmp_path, monkeypatch, args, field):
    monkeypatch.chdir(tmp_path)
    code, text, err = cli(capsys, "simulate", str(EXAMPLES / "imp_symmetric.toml"), "--duration", "0.1", *args)
    assert code == 2 and field in err and text == ""
    assert list(tmp_path.iterdir()) == []


def test_cli_warns_on_large_step(capsys, tmp_path):
    code, _, err = cli(capsys, "simulate", str(EXAMPLES / "imp_symmetric.toml"), "--thrust", "1000", "--duration", "0.2",
                       "--dt", "0.01", "-o", str(tmp_path / "w.nc"))
    assert code == 0 and "warning: dt = 0.01 s is larger than the limit" in err
