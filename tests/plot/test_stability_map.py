"""Stability maps: one cell per design with its own value, censored designs counted and kept
out of the colour scale, labels with names and units from the model-file reference."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import LineCollection, QuadMesh  # noqa: E402

from impstab.studies import load_study, run_study  # noqa: E402

GRID = """
[[parameters]]
path = "mount_rings[0].x"
values = [-0.05, 0.0, 0.025, 0.05, 0.1, 0.2, 0.3, 0.45]
[[parameters]]
path = "mount_rings[0].k_shear"
values = { start = 3e3, stop = 1e5, num = 7, scale = "log" }
"""


def _study(tmp_path, body, name="s.toml"):
    import shutil
    from pathlib import Path

    shutil.copy(Path(__file__).resolve().parents[2] / "examples" / "imp_symmetric.toml", tmp_path / "m.toml")
    path = tmp_path / name
    path.write_text('schema_version = 1\nmodel = "m.toml"\nname = "map test"\n'
                    'outputs = ["critical_thrust", "kind", "margin"]\n' + body)
    return run_study(load_study(path), None)


@pytest.fixture(scope="module")
def grid(tmp_path_factory):
    return _study(tmp_path_factory.mktemp("grid"), GRID)


def _meshes(ax):
    return [c for c in ax.collections if isinstance(c, QuadMesh)]


def test_cells_carry_each_designs_own_value(grid):
    ds = grid.dataset.transpose("mount_rings[0].k_shear", "mount_rings[0].x")
    ax = grid.plot(value="margin")
    mesh = _meshes(ax)[0]
    shown = (ds["kind"].values != 0) & (ds["status"].values == 0)
    values = np.ma.masked_array(mesh.get_array()).reshape(shown.shape)
    np.testing.assert_array_equal(values.mask, ~shown)
    np.testing.assert_array_equal(values.data[shown], ds["margin"].values[shown])  # no interpolation
    # the colour scale spans the values found, not the censored lower bounds
    assert mesh.norm.vmin == ds["margin"].values[shown].min() and mesh.norm.vmax == ds["margin"].values[shown].max()
    assert mesh.norm.vmax < 20000.0 / 2000.0
    assert ax.get_yscale() == "log"
    plt.close("all")


def test_legend_counts_censored_and_unsafe_designs(grid):
    ds = grid.dataset
    censored = int(((ds["kind"] == 0) & (ds["status"] == 0)).sum())
    unsafe = int((ds["margin"] < 1.0).sum())
    assert censored > 0 and unsafe > 0
    ax = grid.plot(value="critical_thrust")
    labels = [t.get_text() for t in ax.figure.legends[0].get_texts()]
    assert f"stable up to thrust_max = 20000 N, censored: {censored} of {ds['status'].size}" in labels
    assert f"margin < 1 (unstable at the operating thrust): {unsafe} of {ds['status'].size}" in labels
    assert not any("no hatching" in t for t in labels)
    outline = [c for c in ax.collections if isinstance(c, LineCollection)]
    assert len(outline) == 1 and len(outline[0].get_segments()) >= 4  # the cells' own edges
    assert ax.get_xlabel() == "ring axial position x (m)"
    assert ax.get_ylabel() == "mount shear stiffness k_shear (N/m)"
    plt.close("all")


def test_sampled_study_points_and_censored_samples(tmp_path):
    res = _study(tmp_path, GRID.replace(", num = 7", "").replace("values = [-0.05, 0.0, 0.025, 0.05, 0.1, 0.2, 0.3, 0.45]",
                                                                  "values = { start = 0.0, stop = 0.45 }")
                 + '\n[sampling]\nmethod = "sobol"\nn = 64\n')
    ds = res.dataset
    ax = res.plot()
    shown = ((ds["kind"] != 0) & (ds["status"] == 0)).values
    assert ax.collections[0].get_offsets().shape[0] == int(shown.sum())
    censored = int(((ds["kind"] == 0) & (ds["status"] == 0)).sum())
    labels = [t.get_text() for t in ax.figure.legends[0].get_texts()]
    assert any(t.endswith(f"censored: {censored} of 64") for t in labels)
    plt.close("all")
