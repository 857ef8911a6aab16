"""``impstab response`` and the isolation additions of ``check`` and ``modes`` end to end."""

import json
import re

import numpy as np
import pytest
import xarray as xr

import impstab
from impstab.cli import main
from impstab.response import ForcedResponse, frequency_response

DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_json_has_design_keys_and_values(capsys, examples):
    path = examples / "imp_isolation.toml"
    code, out, err = run(capsys, "response", path, "--frequencies", "0:50:11", "--json")
    assert code == 0 and err == "" and out.count("\n") == 1
    d = json.loads(out)
    assert d["thrust"] == 2000.0 and d["input"] == "sway"
    assert d["frequency_hz"] == pytest.approx(np.linspace(0, 50, 11).tolist(), abs=0)
    assert set(d["response"]) == set(DOFS)
    for dof in DOFS:
        assert set(d["response"][dof]) >= {"abs", "phase_deg"} and len(d["response"][dof]["abs"]) == 11
    ref = frequency_response(impstab.load_model(path), np.linspace(0, 50, 11))
    assert d["transmissibility"] == pytest.approx(ref.transmissibility.tolist(), rel=1e-14)
    assert d["response"]["yaw"]["phase_deg"] == pytest.approx(np.degrees(np.angle(ref.response[:, 5])).tolist(), abs=1e-9)


def test_thrust_input_and_linearization_flags(capsys, examples):
    path = examples / "imp_asymmetric.toml"
    code, out, _ = run(capsys, "response", path, "--frequencies", "1:10:4", "--thrust", "0", "--input", "yaw",
                       "--linearization", "classical", "--json")
    d = json.loads(out)
    assert code == 0 and d["thrust"] == 0.0 and d["input"] == "yaw" and d["linearization"] == "classical"
    # DESIGN: the default input is sway, the default thrust the operating one
    code, out, _ = run(capsys, "response", examples / "imp_symmetric.toml", "--frequencies", "1:2:2", "--json")
    d = json.loads(out)
    assert d["input"] == "sway" and d["thrust"] == 2000.0


def test_netcdf_and_png_written_atomically(capsys, examples, tmp_path):
    out = tmp_path / "iso.nc"
    code, stdout, err = run(capsys, "response", examples / "imp_isolation.toml", "--frequencies", "0.5:300:400",
                            "--excitation", "-o", out)
    assert code == 0, err
    assert out.exists() and out.with_suffix(".png").stat().st_size > 10000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["iso.nc", "iso.png"]
    ds = xr.load_dataset(out)
    back = ForcedResponse.from_xarray(ds)
    assert back.transmissibility.shape == (400,) and ds["transmissibility"].attrs["units"] == "N/N"
    for name in ds.data_vars:
        assert "units" in ds[name].attrs, name
    ex = xr.load_dataset(out, group="excitation")
    assert list(ex["source"].values[:2]) == ["unbalance[0]", "blade_rate[0]"]
    assert "one-third-octave" in stdout and "excitation lines" in stdout
    code, _, _ = run(capsys, "response", examples / "imp_isolation.toml", "--frequencies", "1:2:3", "-o",
                     tmp_path / "b.nc", "--no-plot")
    assert code == 0 and (tmp_path / "b.nc").exists() and not (tmp_path / "b.png").exists()


def test_excitation_json_has_lines_and_bands(capsys, examples):
    code, out, _ = run(capsys, "response", examples / "imp_isolation.toml", "--frequencies", "1:100:5", "--excitation", "--json")
    ex = json.loads(out)["excitation"]
    assert code == 0 and ex["input"] == "excitation" and "transmissibility" not in ex
    assert ex["source"][0] == "unbalance[0]" and ex["bands"]["nominal_hz"][0] == 25.0
    assert ex["frequency_hz"][1] == pytest.approx(7 * 150.0 / (2 * np.pi), rel=1e-12)


@pytest.mark.parametrize(
    "args,field",
    [
        (("--frequencies", "0:10:100001"), "--frequencies"),
        (("--frequencies", "-1:10:5"), "--frequencies"),
        (("--frequencies", "nan:10:5"), "--frequencies"),
        (("--frequencies", "0:10"), "--frequencies"),
        (("--frequencies", "0:10:5", "--input", "twist"), "--input"),
        (("--frequencies", "0:10:5", "--thrust", "-5"), "--thrust"),
        (("--frequencies", "0:10:5", "-o", "out.txt"), "--output"),
        (("--frequencies", "0:10:5", "--excitation", "-o", "x.nc"), "excitation"),
    ],
)
def test_bad_input_exits_2_with_one_line_and_no_files(capsys, examples, tmp_path, args, field):
    args = [str(tmp_path / a) if a in ("out.txt", "x.nc") else a for a in args]
    code, out, err = run(capsys, "response", examples / "imp_symmetric.toml", *args)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and field in err
    assert list(tmp_path.iterdir()) == []


def test_modes_prints_the_decoupling_table_and_the_axes(capsys, examples):
    code, out, err = run(capsys, "modes", examples / "imp_isolation.toml", "--thrust", "2000")
    assert code == 0, err
    assert "kinetic-energy shares" in out and "torque roll axis" in out and "elastic centre" in out
    code, out, _ = run(capsys, "modes", examples / "imp_asymmetric.toml", "--json")
    d = json.loads(out)
    for mode in d["modes"]:
        shares = mode["energy_share"]
        assert sum(shares.values()) == pytest.approx(1.0, abs=1e-12)
        assert mode["dominant"][0] == max(shares, key=shares.get)
    assert 0 <= d["decoupling"]["roll_share"] <= 1


def test_check_reports_static_mount_loads_and_overloads(capsys, examples, tmp_path):
    code, out, _ = run(capsys, "check", examples / "imp_isolation.toml")
    assert code == 0 and "static mount deflection and load" in out and re.search(r" 83 *$", out, re.M)
    text = (examples / "imp_isolation.toml").read_text().replace("rated_force = 1000.0", "rated_force = 500.0")
    p = tmp_path / "over.toml"
    p.write_text(text)
    code, out, _ = run(capsys, "check", p)
    assert code == 0 and "exceeds its rated_force" in out
