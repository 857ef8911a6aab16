"""Command line end to end: outputs, JSON, exit codes, no partial files."""

import json
import os
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


# -- bad input: one line naming the option, exit 2, nothing written ---------------------------------

def one_line_error(capsys, *args, field):
    code, out, err = run(capsys, *args)
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("impstab: error: ") and field in err, err
    assert "Traceback" not in err and "Warning" not in err and "np.float64" not in err
    return err


LIMITS = [
    (("critical", "EX", "--thrust-max", "1e308"), "--thrust-max"),
    (("locus", "EX", "--thrust-max", "1e308", "-o", "OUT/l.nc"), "--thrust-max"),
    (("locus", "EX", "--steps", "100000000000000000000", "-o", "OUT/l.nc"), "--steps"),
    (("modes", "EX", "--thrust", "1e308"), "--thrust"),
    (("modes", "EX", "--thrust", "1e9"), "--thrust"),           # beyond what the mounts carry
    (("simulate", "EX", "--thrust", "1000", "--duration", "1", "--dt", "1e-300", "-o", "OUT/s.nc"), "--dt"),
    (("simulate", "EX", "--thrust", "1000", "--duration", "1e9", "-o", "OUT/s.nc"), "--duration"),
    (("simulate", "EX", "--thrust", "1000", "--duration", "1e6", "-o", "OUT/s.nc"), "--duration"),
    (("simulate", "EX", "--thrust", "1000", "--duration", "100", "--sample", "1e-9", "-o", "OUT/s.nc"), "--sample"),
    (("simulate", "EX", "--thrust", "1000", "--duration", "1", "--kick", "sway=1e300", "-o", "OUT/s.nc"), "--kick"),
    (("simulate", "EX", "--thrusts", ",".join(["1000"] * 101), "--duration", "1", "-o", "OUT/s.nc"), "--thrusts"),
    (("added-mass", "--radius", "0.15", "--length", "2e7"), "--length"),
    (("added-mass", "--radius", "1e-300", "--length", "1"), "--radius"),
    (("added-mass", "--radius", "1e-4", "--length", "1000"), "--length"),
    (("added-mass", "--radius", "0.15", "--length", "0.8", "--sound-speed", "1500", "--frequency", "1e10"), "--frequency"),
    (("added-mass", "--radius", "5", "--length", "1000", "--sound-speed", "1", "--frequency", "1e6"), "--frequency"),
    (("added-mass", "--radius", "0.15", "--length", "0.8", "--frequencies", "0:1:1e9"), "--frequencies"),
    (("added-mass", "--radius", "1", "--length", "100", "--sound-speed", "100", "--frequencies", "0:1e5:10000"),
     "--frequencies"),
    (("check", "/dev/zero"), "model file"),
    (("critical", "x\x00y"), "NUL"),
]


@pytest.mark.parametrize("args,field", LIMITS)
def test_work_and_ranges_are_checked_before_anything_runs(capsys, examples, tmp_path, args, field):
    (tmp_path / "OUT").mkdir()
    args = [str(examples / "imp_symmetric.toml") if a == "EX" else a.replace("OUT", str(tmp_path / "OUT")) for a in args]
    one_line_error(capsys, *args, field=field)
    assert list((tmp_path / "OUT").iterdir()) == []


def test_a_fifo_as_the_model_does_not_hang(capsys, tmp_path):
    fifo = tmp_path / "m.toml"
    os.mkfifo(fifo)
    one_line_error(capsys, "check", str(fifo), field="not a regular file")


def test_limits_name_the_way_out(capsys, examples, tmp_path):
    err = one_line_error(capsys, "simulate", str(examples / "imp_symmetric.toml"), "--thrust", "1000", "--duration",
                         "1e6", "-o", str(tmp_path / "s.nc"), field="--duration")
    assert "time steps" in err and "--allow-long" in err
    err = one_line_error(capsys, "added-mass", "--radius", "0.15", "--length", "0.8", "--frequencies",
                         "0:100:20000", field="--frequencies")
    assert "--allow-long" in err


# -- hygiene: user strings never reach the terminal raw ---------------------------------------------

HOSTILE_NAME = "\x1b[2J\x1b]0;pwned\x07[/bold][red]x\u202e"


def test_escape_sequences_in_names_are_shown_escaped(capsys, examples, tmp_path):
    text = (examples / "imp_symmetric.toml").read_text()
    model = tmp_path / "m\x1b[1m.toml"
    model.write_text(text.replace('name = "symmetric three-mount IMP"', f"name = {json.dumps(HOSTILE_NAME)}"))
    for args in (("check",), ("critical",), ("modes", "--thrust", "19000"), ("critical", "--all-crossings")):
        code, out, err = run(capsys, args[0], str(model), *args[1:])
        assert code == 0, err
        for ch in ("\x1b", "\x07", "\u202e"):
            assert ch not in out and ch not in err
        assert "\\x1b[2J" in out and "[/bold][red]x" in out   # shown, escaped, rich markup not applied
    code, out, err = run(capsys, "critical", str(model), "--json")
    assert code == 0 and json.loads(out)["model"] == HOSTILE_NAME      # JSON: the exact name, escaped by json
    assert "\x1b" not in out


def test_unknown_key_with_escape_sequences_on_stderr(capsys, examples, tmp_path):
    text = (examples / "imp_symmetric.toml").read_text()
    model = tmp_path / "m.toml"
    model.write_text(text.replace("count = 3", 'count = 3\n"\\u001b[2Jevil" = 1'))
    err = one_line_error(capsys, "critical", str(model), field="unknown key")
    assert "\\x1b[2Jevil" in err


def test_warnings_and_interrupts_are_one_line(capsys):
    import warnings

    import click

    from impstab.cli._common import run_guarded

    @click.command()
    def noisy():
        import numpy as np

        with np.errstate(over="warn"):
            np.float64(1e308) * 10
        warnings.warn("something to say\nover two lines", UserWarning)
        click.echo("result")

    assert run_guarded(noisy, []) == 0
    out, err = capsys.readouterr()
    assert out == "result\n"
    assert err.splitlines() == ["impstab: warning: RuntimeWarning: overflow encountered in scalar multiply",
                                "impstab: warning: something to say\\x0aover two lines"]

    @click.command()
    def stopped():
        raise KeyboardInterrupt

    assert run_guarded(stopped, []) == 130
    assert capsys.readouterr().err == "impstab: error: interrupted\n"

    @click.command()
    def bad():
        import numpy as np

        np.float64(1e308) * 10 if np.seterr(over="warn") else None
        from impstab.errors import ModelError

        raise ModelError("--x", np.float64(2.5), "must be small")

    assert run_guarded(bad, []) == 2
    assert capsys.readouterr().err == "impstab: error: --x = 2.5: must be small\n"   # the warning is not spilled


# -- no silent wrong answer ------------------------------------------------------------------------

def _model(tmp_path, examples, **replace):
    text = (examples / "imp_symmetric.toml").read_text()
    for old, new in replace.items():
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / "m.toml"
    path.write_text(text)
    return str(path)


def test_operating_thrust_above_the_search_range(capsys, examples, tmp_path):
    # the case: thrust_max 15000 N below the operating thrust 20000 N
    path = _model(tmp_path, examples, **{"operating = 2000.0": "operating = 20000.0", "thrust_max = 20000.0": "thrust_max = 15000.0"})
    for args in ((path,), (str(examples / "imp_symmetric.toml"), "--thrust-max", "1500")):
        code, out, err = run(capsys, "critical", *args, "--json")
        d = json.loads(out)
        assert code == 0 and d["critical_thrust"] is None and d["margin"] is None
        assert any("below the operating thrust" in w and "not established" in w for w in d["warnings"])
        code, out, err = run(capsys, "critical", *args)
        assert code == 0 and "not established" in out and "stability at the operating point" in " ".join(out.split())
    code, out, err = run(capsys, "check", path)
    assert code == 0 and "not established" in out


def test_unstable_at_the_operating_thrust_is_said(capsys, examples, tmp_path):
    path = _model(tmp_path, examples, **{"operating = 2000.0": "operating = 19000.0", "thrust_max = 20000.0": "thrust_max = 30000.0"})
    code, out, err = run(capsys, "critical", path, "--json")
    d = json.loads(out)
    assert code == 0 and d["margin"] < 1
    assert any("unstable at its operating thrust" in w for w in d["warnings"])
    code, out, err = run(capsys, "critical", path)
    assert "UNSTABLE at the operating thrust" in out and "unstable at its operating thrust" in out


def test_check_and_modes_agree_with_critical(capsys, examples):
    ex = str(examples / "imp_symmetric.toml")
    code, out, _ = run(capsys, "critical", ex, "--json")
    crit = json.loads(out)
    code, out, err = run(capsys, "check", ex)
    assert code == 0 and f"{crit['critical_thrust']:.10g} N (flutter)" in out and f"{crit['margin']:.4g}" in out
    above = crit["critical_thrust"] * 1.01
    code, out, err = run(capsys, "modes", ex, "--thrust", str(above), "--json")
    d = json.loads(out)
    assert code == 0 and d["stable"] is False and d["critical_thrust"] == crit["critical_thrust"] and d["warnings"] == []
    assert max(m["growth_rate"] for m in d["modes"]) > 0
    code, out, err = run(capsys, "modes", ex, "--thrust", str(above))
    assert "UNSTABLE" in out and f"first lost at {crit['critical_thrust']:.8g} N" in out
    code, out, err = run(capsys, "modes", ex, "--thrust", str(0.99 * crit["critical_thrust"]), "--json")
    assert json.loads(out)["stable"] is True


def test_a_closed_pipe_is_quiet(examples):
    import subprocess
    import sys

    proc = subprocess.run(f"{sys.executable} -m impstab critical {examples / 'imp_symmetric.toml'} | head -c 1",
                          shell=True, capture_output=True, text=True, timeout=120)
    assert proc.stderr == ""


def test_outputs_never_replace_a_pipe_or_a_device(capsys, examples, tmp_path):
    import stat

    ex = str(examples / "imp_symmetric.toml")
    for name in ("l.nc", "s.nc", "a.png", "s.png"):
        os.mkfifo(tmp_path / name)
    one_line_error(capsys, "locus", ex, "--steps", "4", "-o", str(tmp_path / "l.nc"), field="--output")
    one_line_error(capsys, "simulate", ex, "--thrust", "100", "--duration", "0.1", "-o", str(tmp_path / "s.nc"),
                   field="--output")
    one_line_error(capsys, "added-mass", "--radius", "0.1", "--length", "1", "--frequencies", "0:1:2", "-o",
                   str(tmp_path / "a.png"), field="--output")
    assert all(stat.S_ISFIFO((tmp_path / n).stat().st_mode) for n in ("l.nc", "s.nc", "a.png", "s.png"))
