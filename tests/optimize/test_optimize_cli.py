"""impstab optimize end to end: the known optimum of a decoupled isolator on its deflection bound,
the chosen design as a model file, the Pareto store, JSON, exit 2 on bad OPT files."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

import impstab
from impstab.cli import main
from impstab.response import frequency_response, static_mount_loads
from impstab.studies import open_study

SURGE = """schema_version = 1
model = "imp_isolation.toml"

[[variables]]
path = "mount_rings[0].k_axial"
low = 5.0e4
high = 1.0e6
scale = "log"

[objective]
isolation = "t_surge_60"

[constraints]
margin_min = 1.5
static_deflection_max = 0.005

[isolation]
input = "surge"

[[isolation.at]]
name = "t_surge_60"
frequency_hz = 60.0

[optimizer]
population = 10
generations = 5
seed = 0
"""


def _run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture()
def folder(tmp_path, examples):
    shutil.copy(examples / "imp_isolation.toml", tmp_path / "imp_isolation.toml")
    return tmp_path


def test_isolator_stiffness_sits_on_its_deflection_bound(folder, capsys):
    """Surge is decoupled (a symmetric ring along the thrust axis): the three mounts carry the
    2000 N thrust axially, d = T / (3 k_axial), and above the surge mode the transmissibility
    falls with k_axial, so the best design is the softest with d = 5 mm: k_axial = T / (3 * 0.005)."""
    opt = folder / "opt.toml"
    opt.write_text(SURGE)
    code, out, err = _run(capsys, "optimize", str(opt), "-o", str(folder / "p.zarr"), "--model",
                          str(folder / "best.toml"), "--figure", str(folder / "opt.png"), "--json")
    assert code == 0, err
    d = json.loads(out)
    assert out.count("\n") == 1
    k_best = 2000.0 / (3 * 0.005)
    k = d["chosen"]["parameters"]["mount_rings[0].k_axial"]
    assert k == pytest.approx(k_best, rel=1e-4) and k >= k_best * (1 - 1e-12)
    assert d["batched_calls"] == 5 and d["evaluations"] == 50
    # the chosen model file round-trips through load_model and gives the stated values
    best = impstab.load_model(folder / "best.toml")
    assert best.mounts[0].stiffness[0, 0] == pytest.approx(k, rel=1e-15)   # axial along x
    t = frequency_response(best, [60.0], input="surge").transmissibility[0]
    assert d["chosen"]["isolation"] == pytest.approx(t, rel=1e-10)
    assert static_mount_loads(best).deflection_magnitude.max() == pytest.approx(d["chosen"]["static_deflection"], rel=1e-10)
    assert impstab.critical_thrust(best).margin == pytest.approx(d["chosen"]["margin"], rel=1e-9)
    # the Pareto set is a study store: opened, verified; a rerun reuses it
    res = open_study(folder / "p.zarr")
    assert res.complete and res.dataset.sizes["sample"] == d["pareto_designs"]
    assert (folder / "opt.png").stat().st_size > 10_000
    code2, out2, _ = _run(capsys, "optimize", str(opt), "-o", str(folder / "p.zarr"), "--model",
                          str(folder / "best2.toml"), "--no-plot", "--json")
    assert code2 == 0 and json.loads(out2)["chosen"] == d["chosen"]


@pytest.mark.parametrize("change, field", [
    (("scale = \"log\"", "scale = \"cubic\""), "variables[0].scale"),
    (("low = 5.0e4", "low = true"), "variables[0].low"),
    (("low = 5.0e4", "low = -5.0"), "variables[0].low"),
    (("high = 1.0e6", "high = 1.0e3"), "variables[0].high"),
    (("path = \"mount_rings[0].k_axial\"", "path = \"mount_rings[0].count\""), "variables[0].path"),
    (("path = \"mount_rings[0].k_axial\"", "path = \"mount_rings[3].k_axial\""), "variables[0].path"),
    (("isolation = \"t_surge_60\"", "isolation = \"t_other\""), "objective.isolation"),
    (("margin_min = 1.5", "margin_min = 0.0"), "constraints.margin_min"),
    (("margin_min = 1.5", "margin_min = 1.5\nbenign_onset = 1"), "constraints.benign_onset"),  # a flag, not a number
    (("population = 10", "population = 2"), "optimizer.population"),
    (("seed = 0", "sed = 0"), "optimizer.sed"),
])
def test_bad_opt_file_is_one_line_exit_2(folder, capsys, change, field):
    opt = folder / "opt.toml"
    opt.write_text(SURGE.replace(*change))
    code, out, err = _run(capsys, "optimize", str(opt), "-o", str(folder / "p.zarr"), "--no-plot")
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and field in err, err
    assert not (folder / "p.zarr").exists() and not (folder / "opt-chosen.toml").exists()


def test_toml_writer_round_trips_every_example(examples, tmp_path):
    from impstab.model.assemble import read_toml
    from impstab.optimize.toml_out import dumps

    for path in sorted(examples.glob("imp_*.toml")):
        d = read_toml(path)
        out = tmp_path / path.name
        out.write_text(dumps(d, header="copy"))
        assert read_toml(out) == d
        a, b = impstab.load_model(path), impstab.load_model(out)
        np.testing.assert_array_equal(a.body.mass_matrix(), b.body.mass_matrix())
