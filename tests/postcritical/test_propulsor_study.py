"""Study outputs of the post-critical analysis: l1, the label and the fold thrust per design.

Each design's values equal those of :func:`impstab.postcritical.propulsor_postcritical` on the
same variant model, and the stability map separates benign (hardening) from dangerous
(softening) mount designs: the sign of l1 follows the sign of k3_shear (tests/postcritical/
test_propulsor.py gives the hand argument).
"""

import shutil
from pathlib import Path

import pytest

from impstab.postcritical import propulsor_postcritical
from impstab.studies import load_study, run_study

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

STUDY = """schema_version = 1
name = "benign or dangerous"
model = "imp_hardening.toml"
outputs = ["critical_thrust", "kind", "lyapunov_coefficient", "bifurcation"{fold}]

[[parameters]]
path = "mounts[0].k3_shear"
values = [-1.0e8, 2.0e7]

[[parameters]]
path = "mounts[1].k3_shear"
values = [-1.0e8, 2.0e7]
"""


def _run(folder, fold=False):
    shutil.copy(EXAMPLES / "imp_hardening.toml", folder / "imp_hardening.toml")
    path = folder / "study.toml"
    path.write_text(STUDY.format(fold=', "fold_thrust"' if fold else ""), encoding="utf-8")
    return run_study(load_study(path), folder / "s.zarr")


def test_lyapunov_coefficient_and_label_per_design(tmp_path):
    res = _run(tmp_path)
    ds = res.dataset
    l1 = ds["lyapunov_coefficient"].values
    label = ds["bifurcation"].values
    assert ds["lyapunov_coefficient"].attrs["units"] == "1/s"
    # two strongly softening mounts: subcritical; all hardening: supercritical
    assert label[0, 0] == "subcritical" and l1[0, 0] > 0
    assert label[1, 1] == "supercritical" and l1[1, 1] < 0
    # the same numbers as the analysis of the variant model
    import tomllib

    from impstab.model import model_from_dict

    with open(EXAMPLES / "imp_hardening.toml", "rb") as fh:
        d = tomllib.load(fh)
    d["mounts"][0]["k3_shear"] = d["mounts"][1]["k3_shear"] = -1.0e8
    variant = model_from_dict(d)
    one = propulsor_postcritical(variant, branch=False)
    assert one.lyapunov_coefficient == pytest.approx(l1[0, 0], rel=1e-9)
    assert one.critical_thrust == pytest.approx(ds["critical_thrust"].values[0, 0], rel=1e-7)
