"""Property-based tests: generated study files, valid and broken, through ``impstab sweep``.

Asserted only: exit code 0 or 2, one line on stderr for 2, no traceback, and no store or export
left in the output folder after bad input. Studies larger than a few thousand designs are
checked by loading them (they must load or be refused in one line) without running them.
"""

from __future__ import annotations

import shutil
import tempfile
import tomllib
from pathlib import Path

from _fuzz import check_run, fuzz, mutated, run_cli
from _toml import dumps
from conftest import EXAMPLES
from hypothesis import given

from impstab.errors import ModelError
from impstab.studies import load_study

SMALL = 2000

BASES = [tomllib.loads((EXAMPLES / n).read_text()) for n in ("study_mounts.toml", "study_uncertainty.toml", "study_damping.toml")]
BASES += [
    {"schema_version": 1, "model": "imp_symmetric.toml", "outputs": ["critical_thrust", "kind", "margin"],
     "parameters": [{"path": "thrust.preload_stiffness", "values": [True, False]},
                    {"path": "mount_rings[0].count", "values": {"start": 3, "stop": 5, "num": 3}}]},
    {"schema_version": 1, "model": "imp_symmetric.toml", "name": "mass and linearization",
     "parameters": [{"path": "body.mass", "values": [50.0, 100.0]},
                    {"path": "analysis.linearization", "values": ["classical", "equilibrium"]}]},
    {"schema_version": 1, "model": "imp_symmetric.toml", "sampling": {"method": "random", "n": 16, "seed": 3},
     "parameters": [{"path": "body.cg[0]", "distribution": {"kind": "normal", "mean": 0.0, "std": 0.01}},
                    {"path": "mount_rings[0].k_shear", "values": {"start": 1e4, "stop": 3e4, "scale": "log"}}]},
]
for base in BASES:  # small grids and samples, so that valid studies run in a moment
    for par in base["parameters"]:
        if isinstance(par.get("values"), dict) and par["values"].get("num", 0) > 5:
            par["values"]["num"] = 5
    if base.get("sampling", {}).get("n", 0) > 16:
        base["sampling"]["n"] = 16


@fuzz(20)
@given(doc=mutated(BASES))
def test_study_files(doc):
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name in ("imp_symmetric.toml", "imp_damped.toml"):
            shutil.copy(EXAMPLES / name, folder / name)
        try:
            text = dumps(doc)
        except TypeError:
            return
        study = folder / "study.toml"
        study.write_text(text, encoding="utf-8")
        try:
            size = load_study(study).size
        except ModelError:
            size = 0
        if size > SMALL:
            return
        out = folder / "out"
        out.mkdir()
        code, stdout, stderr = run_cli("sweep", str(study), "-o", str(out / "s.zarr"), "--export", str(out / "s.csv"))
        check_run(code, stdout, stderr, out, expected=("s.zarr", "s.csv"))
