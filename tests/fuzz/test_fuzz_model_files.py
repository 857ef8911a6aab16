"""Property-based tests: generated model files, valid and broken, through the real command line.

Asserted only: exit code 0 or 2, exactly one line on stderr for 2, no traceback, no raw control
character on the terminal, valid JSON for --json, and no file left in the output folder.
"""

from __future__ import annotations

import tempfile
import tomllib
from pathlib import Path

from _fuzz import check_run, fuzz, mutated, run_cli
from _toml import dumps
from conftest import EXAMPLES, asymmetric_model_dict, ring_model_dict
from hypothesis import given
from hypothesis import strategies as st

BASES = [ring_model_dict(), asymmetric_model_dict()] + [
    tomllib.loads((EXAMPLES / name).read_text())
    for name in ("imp_damped.toml", "imp_fluid.toml", "imp_asymmetric.toml", "imp_isolation.toml")
]


def _write(doc: dict, folder: Path) -> Path | None:
    try:
        text = dumps(doc)
    except TypeError:
        return None
    path = folder / "model.toml"
    path.write_text(text, encoding="utf-8")
    return path


@fuzz(80)
@given(doc=mutated(BASES))
def test_broken_model_files(doc):
    with tempfile.TemporaryDirectory() as tmp:
        path = _write(doc, Path(tmp))
        if path is None:
            return
        out = Path(tmp) / "out"
        out.mkdir()
        for args, as_json in ((("check", str(path)), False), (("critical", str(path), "--json"), True)):
            code, stdout, stderr = run_cli(*args)
            check_run(code, stdout, stderr, out, as_json)


@fuzz(15)
@given(doc=mutated(BASES, gentle=True), command=st.sampled_from(["modes", "locus", "critical-text", "response"]))
def test_valid_model_files(doc, command):
    with tempfile.TemporaryDirectory() as tmp:
        path = _write(doc, Path(tmp))
        out = Path(tmp) / "out"
        out.mkdir()
        code, stdout, stderr = run_cli("critical", str(path), "--json")
        check_run(code, stdout, stderr, out, as_json=True)
        if code != 0:
            return
        if command == "modes":
            thrust = doc.get("thrust", {}).get("operating", 1000.0)
            args = ("modes", str(path), "--thrust", repr(float(thrust)), "--json")
            code, stdout, stderr = run_cli(*args)
            check_run(code, stdout, stderr, out, as_json=True)
        elif command == "locus":
            code, stdout, stderr = run_cli("locus", str(path), "--steps", "6", "-o", str(out / "l.nc"))
            check_run(code, stdout, stderr, out, expected=("l.nc", "l.png"))
        elif command == "response":
            code, stdout, stderr = run_cli("response", str(path), "--frequencies", "0:30:7", "--json")
            check_run(code, stdout, stderr, out, as_json=True)
        else:
            code, stdout, stderr = run_cli("critical", str(path), "--all-crossings")
            check_run(code, stdout, stderr, out)
