"""Studies over viscoelastic keys equal the single-model critical thrust of each variant."""

import numpy as np
import pytest
from _study_helpers import write_study

import impstab
from impstab.model import model_from_dict
from impstab.studies import load_study, run_study
from impstab.studies.evaluate import variant_dict

MODEL = """schema_version = 1
name = "viscoelastic ring"
[body]
mass = 100.0
inertia = [1.0, 6.0, 6.0]
[[mount_rings]]
count = 3
radius = 0.15
x = 0.3
start_angle = 90.0
k_axial = 1.0e5
k_shear = 2.0e4
[mount_rings.viscoelastic]
law = "standard-linear-solid"
stiffening = 1.5
relaxation_time = 2.0e-3
[thrust]
operating = 2000.0
[analysis]
thrust_max = 30000.0
"""

GRID = """
[[parameters]]
path = "mount_rings[0].viscoelastic.stiffening"
values = [1.2, 2.0, 4.0]
[[parameters]]
path = "mount_rings[0].viscoelastic.relaxation_time"
values = [1.0e-3, 1.0e-2]
"""


def test_study_over_viscoelastic_keys_equals_single_models(tmp_path):
    (tmp_path / "visco.toml").write_text(MODEL)
    study = load_study(write_study(tmp_path, GRID, model="visco.toml"))
    res = run_study(study, tmp_path / "s.zarr")
    assert res.counts()["ok"] == 6
    ds = res.dataset
    segs = [p.path.segments for p in study.parameters]
    for i, s in enumerate(study.parameters[0].values):
        for j, tau in enumerate(study.parameters[1].values):
            one = impstab.critical_thrust(model_from_dict(variant_dict(study.base_model, segs, [s, tau])))
            sel = {ds["critical_thrust"].dims[0]: i, ds["critical_thrust"].dims[1]: j}
            assert float(ds["critical_thrust"][sel]) == pytest.approx(one.thrust, rel=1e-10)
            assert float(ds["undamped_critical_thrust"][sel]) == pytest.approx(one.undamped_thrust, rel=1e-10)
    # the values differ from one variant to the next (the keys are read)
    assert np.unique(np.round(ds["critical_thrust"].values, 3)).size == 6
