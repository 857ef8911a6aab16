"""The damping-destabilisation table of docs/mounts.md is what impstab computes."""

from pathlib import Path

import pytest
from conftest import ring_model_dict

import impstab
from impstab.model import model_from_dict

DOC = Path(__file__).resolve().parents[2] / "docs" / "mounts.md"
TABLE = [{"law": "table", "frequency_hz": [1.0, 3.0, 10.0, 30.0, 100.0], "storage_ratio": [1.0, 1.03, 1.08, 1.15, 1.25],
          "loss_factor": [0.04, 0.06, 0.08, 0.10, 0.12]}]
VARIANTS = {
    "elastic": ({}, None),
    "viscous, `c_axial = 60`": ({"c_axial": 60.0, "c_shear": 5.0}, None),
    "viscous, stiffness-proportional": ({"c_axial": 100.0, "c_shear": 20.0}, None),
    "standard linear solid, s = 2": ({}, {"law": "standard-linear-solid", "stiffening": 2.0, "relaxation_time": 5e-3}),
    "fractional Zener, s = 2": ({}, {"law": "fractional-zener", "stiffening": 2.0, "relaxation_time": 2e-3, "alpha": 0.4}),
    "data-sheet table above": ({}, TABLE[0]),
}


@pytest.mark.parametrize("label", list(VARIANTS))
def test_docs_table_row(label):
    extra, visco = VARIANTS[label]
    d = ring_model_dict()
    d["analysis"]["thrust_max"] = 30000.0
    d["mount_rings"][0].update(extra)
    if visco:
        d["mount_rings"][0]["viscoelastic"] = visco
    res = impstab.critical_thrust(model_from_dict(d))
    row = next(line for line in DOC.read_text().splitlines() if line.startswith(f"| {label}"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert float(cells[1]) == pytest.approx(res.thrust, abs=0.06)
    assert float(cells[2]) == pytest.approx(res.frequency_hz, abs=6e-4)
    assert float(cells[3]) == pytest.approx(res.undamped_thrust, abs=0.06)
