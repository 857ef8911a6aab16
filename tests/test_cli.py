"""Command line end to end: outputs, JSON, exit codes, no partial files."""

import json
import shutil

import numpy as np
import pytest
import xarray as xr

from impstab.cli import main


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_critical_json(capsys, examples):
    code, out, err = run(capsys, "critical", str(examples / "imp_symmetric.toml"), "--json")
    assert code == 0 and err == ""
    d = json.loads(out)
    assert out.count("\n") == 1
    assert d["kind"] == "flutter"
    assert d["critical_thrust"] == pytest.approx(18012.0999227555, rel=1e-12)
    assert d["margin"] == pytest.approx(d["critical_thrust"] / d["operating_thrust"])
    assert d["linearization"] == "equilibrium"
    for key in ("frequency_hz", "omega", "modes", "thrust_max", "undamped_critical_thrust"):
        assert key in d


def test_check_modes_and_critical_tables(capsys, examples):
    for args in (("check",), ("modes", "--thrust", "5000"), ("critical",), ("critical", "--all-crossings")):
        code, out, err = run(capsys, *args, str(examples / "imp_asymmetric.toml"))
        assert code == 0, err
        assert out.strip()
    code, out, _ = run(capsys, "modes", str(examples / "imp_symmetric.toml"), "--json")
    assert len(json.loads(out)["modes"]) == 6


def test_locus_writes_netcdf_and_png(capsys, examples, tmp_path):
    out = tmp_path / "loc.nc"
    code, _, err = run(capsys, "locus", str(examples / "imp_symmetric.toml"), "--steps", "40", "-o", str(out))
    assert code == 0, err
    assert out.exists() and out.with_suffix(".png").stat().st_size > 1000
    ds = xr.load_dataset(out)
    assert ds.sizes["thrust"] == 41 and ds.sizes["branch"] == 12
    assert ds.attrs["linearization"] == "equilibrium"
    assert np.isfinite(ds.attrs["critical_thrust"])
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


@pytest.mark.parametrize(
    "args,field",
    [
        (("critical", "MISSING"), "model file"),
        (("modes", "EX", "--thrust", "nan"), "--thrust"),
        (("locus", "EX", "--steps", "0"), "--steps"),
        (("locus", "EX", "-o", "out.txt"), "--output"),
        (("critical", "EX", "--thrust-max", "-1"), "--thrust-max"),
    ],
)
def test_bad_input_exit_2(capsys, examples, tmp_path, args, field):
    args = [str(examples / "imp_symmetric.toml") if a == "EX" else str(tmp_path / a) if a in ("MISSING", "out.txt") else a for a in args]
    code, out, err = run(capsys, *args)
    assert code == 2
    assert err.count("\n") == 1 and field in err
    assert list(tmp_path.iterdir()) == []


def test_bad_model_file_exit_2(capsys, examples, tmp_path):
    bad = tmp_path / "bad.toml"
    text = (examples / "imp_symmetric.toml").read_text().replace("k_shear = 2.0e4", "k_shear = -2.0e4")
    bad.write_text(text)
    code, out, err = run(capsys, "critical", str(bad), "--json")
    assert code == 2 and out == ""
    assert err.strip().startswith("impstab: error: mount_rings[0].k_shear = -20000.0")


def test_console_script_installed():
    # the install declares the console script beside the interpreter (make test installs it)
    import subprocess
    import sys
    from pathlib import Path

    script = Path(sys.executable).parent / "impstab"
    assert script.exists() or shutil.which("impstab")
    out = subprocess.run([str(script) if script.exists() else "impstab", "--version"], capture_output=True, text=True)
    assert out.returncode == 0 and "version" in out.stdout
