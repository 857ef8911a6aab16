"""Property-based tests: generated command lines (hostile numbers, paths and option values).

Asserted only: exit code 0 or 2, one line on stderr for 2, no traceback, no raw control
character on the terminal, and nothing left in the output folder after bad input. A few runs go
through a real subprocess (``python -m impstab``) to cover what an in-process run cannot: the
interpreter's own exit, a FIFO and a device as the model.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
from _fuzz import check_run, fuzz, run_cli
from conftest import EXAMPLES
from hypothesis import given
from hypothesis import strategies as st

NUMBERS = ["0", "-0", "1", "-1", "1e308", "-1e308", "1e-300", "nan", "inf", "-inf", "abc", "", "1e9", "1e10", "5000",
           "20000", "0x10", "1_000", " 5", "1e-12", "3.5", "100000", "100001", "99999999999999999999999"]
numbers = st.one_of(st.sampled_from(NUMBERS), st.floats(allow_nan=True, allow_infinity=True).map(repr),
                    st.integers(-(10**30), 10**30).map(str))
MODELS = ["EX", "FLUID", "/dev/zero", "FIFO", "DIR", "MISSING", "WEIRD", "BINARY", "EMPTY", "", "-", "LONG", "x\x00y", "STUDY"]


def _options(command: str):
    common = {
        "check": [],
        "critical": [("--json",), ("--all-crossings",), ("--thrust-max", numbers), ("--linearization", st.sampled_from(["classical", "x"]))],
        "modes": [("--json",), ("--thrust", numbers), ("--linearization", st.sampled_from(["equilibrium", "exact"]))],
        "locus": [("--thrust-max", numbers), ("--steps", st.sampled_from(["0", "1", "4", "100001", "-3", "1e3"])), ("-o", "OUT")],
        "simulate": [("--dt", numbers), ("--sample", numbers), ("--tol", numbers), ("--json",),
                     ("--integrator", st.sampled_from(["hamming", "gill", "dop853", "euler"])),
                     ("--displace", st.sampled_from(["sway=0.01", "pitch=1e300", "sway", "x=1", "yaw=nan"])),
                     ("--kick", st.sampled_from(["sway=0.01", "heave=1e9", "roll="])),
                     ("--thrusts", st.sampled_from(["1,2", "1e9,1", ",", "nan", "1," * 120, "5000,1e308"])), ("-o", "OUT")],
        "added-mass": [("--density", numbers), ("--sound-speed", numbers), ("--frequency", numbers), ("--json",),
                       ("--frequencies", st.sampled_from(["0:100:5", "0:1:1e9", "100:0:5", "0:1e6:3", "a:b:c", "0:10",
                                                          "0:10:0", "0:1e5:10000", "5:5:1", "0:1e7:2"])), ("-o", "OUT")],
        "sweep": [("-o", "OUT"), ("--workers", st.sampled_from(["0", "-1", "100000", "x"])), ("--export", "OUT")],
        "map": [("--x", st.sampled_from(["mount_rings[0].x", "nope", "\x1b[2J"])), ("-o", "OUT")],
        "response": [("--thrust", numbers), ("--input", st.sampled_from(["sway", "twist", "\x1b[2J"])), ("--json",),
                     ("--excitation",), ("-o", "OUT")],
    }
    return common[command]


@st.composite
def command_lines(draw):
    command = draw(st.sampled_from(["check", "critical", "modes", "locus", "simulate", "added-mass", "sweep", "map",
                                    "response"]))
    argv = [command]
    if command in ("check", "critical", "modes", "locus", "simulate", "response"):
        argv.append(draw(st.sampled_from(MODELS)))
    if command == "response":
        argv += ["--frequencies", draw(st.sampled_from(["0:20:5", "0:1:1e9", "0:1e7:3", "5:1:2", "x", "0:100:100001"]))]
    if command == "simulate":
        argv += ["--thrust", draw(st.sampled_from(["1000", "0", "-1", "nan", "1e308", "1e9"])),
                 "--duration", draw(st.sampled_from(["0.05", "1e9", "1e6", "0", "-1", "nan", "1e-300", "abc"]))]
    if command == "added-mass":
        argv += ["--radius", draw(numbers), "--length", draw(numbers)]
    if command == "sweep":
        argv.append(draw(st.sampled_from(["STUDY", "EX", "/dev/zero", "MISSING", "DIR"])))
    if command == "map":
        argv.append(draw(st.sampled_from(["DIR", "MISSING", "EX", "/dev/zero"])))
    for option in draw(st.lists(st.sampled_from(_options(command)), max_size=3)) if _options(command) else []:
        argv.append(option[0])
        if len(option) > 1:
            value = option[1]
            argv.append(value if isinstance(value, str) else draw(value))
    return argv


def _files(folder: Path) -> dict[str, str]:
    for name in ("imp_symmetric.toml", "imp_fluid.toml", "study_mounts.toml"):
        shutil.copy(EXAMPLES / name, folder / name)
    os.mkfifo(folder / "fifo.toml")
    (folder / "dir").mkdir()
    weird = folder / "we\x1b[2Jird\u202e.toml"
    shutil.copy(EXAMPLES / "imp_symmetric.toml", weird)
    (folder / "binary.toml").write_bytes(b"\xff\xfe\x00garbage")
    (folder / "empty.toml").write_text("")
    study = folder / "study.toml"
    study.write_text((folder / "study_mounts.toml").read_text().replace("num = 46", "num = 3").replace("num = 41", "num = 2"))
    return {"EX": str(folder / "imp_symmetric.toml"), "FLUID": str(folder / "imp_fluid.toml"), "FIFO": str(folder / "fifo.toml"),
            "DIR": str(folder / "dir"), "MISSING": str(folder / "missing.toml"), "WEIRD": str(weird),
            "BINARY": str(folder / "binary.toml"), "EMPTY": str(folder / "empty.toml"), "LONG": "a" * 5000,
            "STUDY": str(study)}


OUTPUTS = {"locus": "l.nc", "simulate": "s.nc", "added-mass": "a.png", "sweep": "s.zarr", "map": "m.png", "response": "r.nc"}


@fuzz(60)
@given(argv=command_lines())
def test_command_lines(argv):
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        names = _files(folder)
        out = folder / "out"
        out.mkdir()
        target = OUTPUTS.get(argv[0], "x.out")
        args = [names.get(a, a) for a in argv]
        args = [str(out / ("e.csv" if args[i - 1] == "--export" else target)) if a == "OUT" else a for i, a in enumerate(args)]
        if argv[0] in ("simulate",) and "-o" not in args:
            args += ["-o", str(out / "s.nc")]
        if argv[0] == "sweep" and "-o" not in args:
            args += ["-o", str(out / "s.zarr")]
        if argv[0] == "map" and "-o" not in args:
            args += ["-o", str(out / "m.png")]
        cwd = os.getcwd()
        os.chdir(out)        # default output names land in the output folder too
        try:
            code, stdout, stderr = run_cli(*args)
        finally:
            os.chdir(cwd)
        base = Path(target).stem
        model = Path(args[1]).stem if len(args) > 1 else ""
        defaults = tuple(f"{model}-{kind}.{ext}" for kind in ("locus", "simulation") for ext in ("nc", "png"))
        check_run(code, stdout, stderr, out, as_json="--json" in args and "--frequencies" not in args,
                  expected=(target, base + ".png", base + ".nc", "e.csv") + defaults)


@pytest.mark.parametrize("kind", ["device", "fifo", "hostile name"])
def test_real_process(kind, tmp_path):
    if kind == "device":
        args = ["check", "/dev/zero"]
    elif kind == "fifo":
        os.mkfifo(tmp_path / "m.toml")
        args = ["critical", str(tmp_path / "m.toml"), "--json"]
    else:
        text = (EXAMPLES / "imp_symmetric.toml").read_text().replace('name = "symmetric three-mount IMP"',
                                                                        'name = "\\u001b[2J\\u001b]0;x\\u0007"')
        (tmp_path / "m.toml").write_text(text)
        args = ["critical", str(tmp_path / "m.toml")]
    env = dict(os.environ, PYTHONWARNINGS="default")
    proc = subprocess.run([sys.executable, "-m", "impstab", *args], capture_output=True, text=True, timeout=120, env=env)
    assert "Traceback" not in proc.stderr and "\x1b" not in proc.stdout + proc.stderr
    if kind == "hostile name":
        assert proc.returncode == 0 and proc.stderr == "" and "\\x1b[2J" in proc.stdout
    else:
        assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "not a regular file" in proc.stderr
