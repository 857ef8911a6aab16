"""``impstab added-mass`` end to end: JSON, tables, sweeps, plots, exit codes."""

import json

import pytest

import impstab.fluid as fl
from impstab.cli import main


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_json_incompressible(capsys):
    code, out, err = run(capsys, "added-mass", "--radius", "0.15", "--length", "0.8", "--json")
    assert code == 0 and err == ""
    assert out.count("\n") == 1
    d = json.loads(out)
    ref = fl.baffled_cylinder(0.15, 0.8, 1025.0)
    assert d["added_mass"] == ref.added_mass and d["added_inertia"] == ref.added_inertia
    assert d["radiation_resistance"] is None and d["sound_speed"] is None
    assert (d["radius"], d["length"], d["density"], d["frequency"]) == (0.15, 0.8, 1025.0, 0.0)


def test_json_compressible(capsys):
    args = ("added-mass", "--radius", "0.15", "--length", "0.8", "--density", "1000",
            "--sound-speed", "1480", "--frequency", "250", "--json")
    code, out, err = run(capsys, *args)
    assert code == 0 and err == ""
    d = json.loads(out)
    ref = fl.baffled_cylinder(0.15, 0.8, 1000.0, 1480.0, 250.0)
    assert d["radiation_resistance"] == ref.radiation_resistance > 0
    assert d["rotational_radiation_resistance"] == ref.rotational_radiation_resistance
    assert d["omega"] == pytest.approx(2 * 3.141592653589793 * 250)


def test_table(capsys):
    code, out, err = run(capsys, "added-mass", "--radius", "0.15", "--length", "0.8", "--sound-speed", "1500",
                         "--frequency", "100")
    assert code == 0 and err == ""
    assert "added mass" in out and "radiation resistance" in out and "kg m^2" in out


def test_sweep_json_table_and_png(capsys, tmp_path):
    base = ("added-mass", "--radius", "0.15", "--length", "0.8", "--sound-speed", "1500", "--frequencies", "0:2000:5")
    code, out, err = run(capsys, *base, "--json")
    assert code == 0 and err == ""
    d = json.loads(out)
    assert d["frequency"] == [0.0, 500.0, 1000.0, 1500.0, 2000.0]
    assert len(d["added_mass"]) == 5 and d["radiation_resistance"][0] == 0.0
    code, out, err = run(capsys, *base)
    assert code == 0 and "1500" in out
    png = tmp_path / "sub" / "coefficients.png"
    code, out, err = run(capsys, *base, "-o", str(png))
    assert code == 0, err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 1000
    assert [p.name for p in png.parent.iterdir()] == ["coefficients.png"]


@pytest.mark.parametrize(
    "extra,flag",
    [
        (("--radius", "-1", "--length", "0.8"), "--radius"),
        (("--radius", "0.15", "--length", "nan"), "--length"),
        (("--radius", "0.15", "--length", "0.8", "--density", "0"), "--density"),
        (("--radius", "0.15", "--length", "0.8", "--sound-speed", "0"), "--sound-speed"),
        (("--radius", "0.15", "--length", "0.8", "--frequency", "-5"), "--frequency"),
        (("--radius", "0.15", "--length", "0.8", "--frequencies", "10:1:5"), "--frequencies"),
        (("--radius", "0.15", "--length", "0.8", "--frequencies", "a:b:c"), "--frequencies"),
        (("--radius", "0.15", "--length", "0.8", "--frequencies", "0:10:2", "--frequency", "3"), "--frequencies"),
        (("--radius", "0.15", "--length", "0.8", "-o", "OUT.png"), "--output"),
        (("--radius", "0.15", "--length", "0.8", "--frequencies", "0:10:2", "-o", "OUT.txt"), "--output"),
        (("--radius", "-1", "--length", "0.8", "--frequencies", "0:10:2", "-o", "OUT.png"), "--radius"),
        (("--length", "0.8"), "--radius"),
    ],
)
def test_bad_input_exit_2(capsys, tmp_path, extra, flag):
    args = [str(tmp_path / a) if a.startswith("OUT") else a for a in extra]
    code, out, err = run(capsys, "added-mass", *args)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and flag in err
    assert list(tmp_path.iterdir()) == []
