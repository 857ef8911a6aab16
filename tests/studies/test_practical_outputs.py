"""Practical critical thrust as a study output: each design equals its own model's value."""

from __future__ import annotations

import numpy as np
import pytest

import impstab
from impstab.studies import load_study, run_study

from _study_helpers import EXAMPLES, write_study


def test_practical_outputs_equal_single_models(tmp_path):
    text = (EXAMPLES / "imp_damped.toml").read_text().replace(
        "[analysis]\nthrust_max = 20000.0", "[analysis]\nthrust_max = 20000.0\nmin_damping_ratio = 0.002")
    (tmp_path / "damped.toml").write_text(text)
    body = ('outputs = ["critical_thrust", "practical_critical_thrust", "practical_margin"]\n'
            '[[parameters]]\npath = "mount_rings[0].c_shear"\nvalues = [5.0, 20.0, 60.0]\n')
    study = load_study(write_study(tmp_path, body, model="damped.toml", chunk_size=None))
    res = run_study(study, tmp_path / "s.zarr")
    ds = res.dataset
    got = np.asarray(ds["practical_critical_thrust"]).ravel()
    margin = np.asarray(ds["practical_margin"]).ravel()
    crit = np.asarray(ds["critical_thrust"]).ravel()
    assert np.isfinite(got).all()
    for j, c in enumerate((5.0, 20.0, 60.0)):
        single = impstab.critical_thrust(_variant(tmp_path, c))
        assert got[j] == pytest.approx(single.practical_thrust, rel=1e-10)
        assert margin[j] == pytest.approx(single.practical_margin, rel=1e-10)
        assert 0 < got[j] < crit[j]


def _variant(folder, c_shear: float):
    text = (folder / "damped.toml").read_text().replace("c_shear = 5.0", f"c_shear = {c_shear}")
    path = folder / f"v{c_shear}.toml"
    path.write_text(text)
    return impstab.load_model(path)
