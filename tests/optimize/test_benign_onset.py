"""The optimiser's benign-onset constraint: a design must have a supercritical Hopf point.

On imp_hardening.toml the cubic shear stiffness changes neither the critical thrust nor the
forced response (the shear springs are straight at equilibrium, tests/postcritical), only the
direction of the Hopf bifurcation: l1 is affine in k3_shear (hardening: l1 < 0, benign; strongly
softening: l1 > 0, dangerous). Every design the search calls feasible must be supercritical,
every one it calls infeasible must not be, and the chosen design is confirmed by the analysis
of the written model file.
"""

from __future__ import annotations

import shutil

import numpy as np

import impstab
from impstab.model import model_from_dict
from impstab.model.assemble import read_toml
from impstab.optimize.problem import load_optimization
from impstab.optimize.run import benign, run_optimization
from impstab.postcritical import propulsor_postcritical

OPT = """schema_version = 1
model = "imp_hardening.toml"

[[variables]]
path = "mounts[0].k3_shear"
low = -1.0e8
high = 2.0e7

[[variables]]
path = "mounts[1].k3_shear"
low = -1.0e8
high = 2.0e7

[objective]
isolation = "t_sway_20"

[constraints]
benign_onset = true

[isolation]
input = "sway"

[[isolation.at]]
name = "t_sway_20"
frequency_hz = 20.0

[optimizer]
population = 6
generations = 2
seed = 3
polish = false
"""


def test_benign_onset_keeps_only_supercritical_designs(tmp_path, examples):
    shutil.copy(examples / "imp_hardening.toml", tmp_path / "imp_hardening.toml")
    path = tmp_path / "opt.toml"
    path.write_text(OPT, encoding="utf-8")
    opt = load_optimization(path)
    assert opt.benign_onset and "bifurcation" in opt.outputs
    res = run_optimization(opt, store=str(tmp_path / "p.zarr"), model_out=str(tmp_path / "chosen.toml"))
    h = res.history
    assert h.feasible.any() and not h.feasible.all()  # the bounds straddle the sign change of l1
    # the label of each evaluated design, by the analysis of its own variant model
    raw = read_toml(tmp_path / "imp_hardening.toml")
    for x, ok in zip(h.x, h.feasible):
        raw["mounts"][0]["k3_shear"], raw["mounts"][1]["k3_shear"] = float(x[0]), float(x[1])
        one = propulsor_postcritical(model_from_dict(raw), branch=False)
        assert (one.bifurcation == "supercritical") == bool(ok), (x, one.bifurcation, ok)
    chosen = impstab.load_model(tmp_path / "chosen.toml")
    pc = propulsor_postcritical(chosen, branch=False)
    assert pc.bifurcation == "supercritical" and pc.lyapunov_coefficient < 0
    assert res.chosen["bifurcation"] == "supercritical"
    assert res.to_dict()["constraints"]["benign_onset"] is True


def test_benign_mask():
    data = {"bifurcation": np.array(["supercritical", "subcritical", "degenerate", "", "none"]),
            "status": np.array([0, 0, 0, 2, 0]), "kind": np.array([1, 1, 2, -1, 0])}
    assert benign(data).tolist() == [True, False, False, False, True]
