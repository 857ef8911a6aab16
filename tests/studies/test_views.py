"""Stability maps (`impstab map`, `.plot()`) and the best design."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from _study_helpers import GRID_6x5, write_study  # noqa: E402

from impstab.cli import main  # noqa: E402
from impstab.errors import ModelError  # noqa: E402
from impstab.studies import load_study, run_study  # noqa: E402

MAP = """
[[parameters]]
path = "mount_rings[0].x"
values = [-0.05, 0.0, 0.025, 0.05, 0.1, 0.2, 0.3, 0.45]
[[parameters]]
path = "mount_rings[0].k_shear"
values = [3e3, 1e4, 1.85e4, 3e4, 5e4, 1e5]
"""


@pytest.fixture(scope="module")
def map_store(tmp_path_factory):
    folder = tmp_path_factory.mktemp("map")
    path = write_study(folder, MAP, chunk_size=40)
    res = run_study(load_study(path), folder / "m.zarr")
    return folder, res


def test_map_command_writes_png(map_store, capsys):
    folder, _ = map_store
    out = folder / "map.png"
    code = main(["map", str(folder / "m.zarr"), "--x", "mount_rings[0].x", "--y", "mount_rings[0].k_shear",
                 "--value", "margin", "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    assert out.stat().st_size > 10_000 and out.read_bytes()[:4] == b"\x89PNG"
    assert main(["map", str(folder / "m.zarr")]) == 0  # defaults: the first two parameters
    assert (folder / "m-map.png").exists()


@pytest.mark.parametrize(
    "args,field",
    [(["--x", "mount_rings[0].radius"], "--x"), (["--value", "kind"], "--value"), (["--y", "mount_rings[0].x"], "--y")],
)
def test_map_bad_options(map_store, capsys, args, field):
    folder, _ = map_store
    out = folder / "bad.png"
    assert main(["map", str(folder / "m.zarr"), "-o", str(out), *args]) == 2
    assert field in capsys.readouterr().err
    assert not out.exists()


def test_map_of_a_folder_that_is_no_store(tmp_path, capsys):
    assert main(["map", str(tmp_path)]) == 2
    assert "STORE" in capsys.readouterr().err


def test_plot_draws_on_given_axes(map_store):
    _, res = map_store
    fig, ax = plt.subplots()
    assert res.plot(ax=ax) is ax
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(t.startswith("stable up to thrust_max = 20000 N") for t in labels)
    assert any(t.startswith("margin < 1") for t in labels)  # this range crosses the operating thrust
    assert ax.get_ylabel() == "mount shear stiffness k_shear (N/m)"
    plt.close(fig)


def test_best_design(map_store):
    _, res = map_store
    ds = res.dataset
    best = res.best("margin")
    # some layouts do not flutter up to thrust_max: their margin is only bounded below
    assert best["lower_bound"] and best["tied"] > 1
    assert best["value"] == pytest.approx(20000.0 / 2000.0)  # thrust_max / operating
    worst = res.best("margin", minimum=True)
    assert not worst["lower_bound"]
    assert worst["value"] == pytest.approx(np.nanmin(ds["margin"].values))
    sel = worst["index"]
    assert ds["margin"].isel(sel).item() == worst["value"]
    assert worst["values"]["kind"] == "flutter"
    with pytest.raises(ModelError):
        res.best("kind")
    # the largest margin among the designs that flutter within the search range, and its model
    fl = res.best("margin", where=ds["kind"] == 1)
    assert not fl["lower_bound"] and fl["value"] == pytest.approx(np.nanmax(ds["margin"].values))
    import impstab

    crit = impstab.critical_thrust(res.model(fl["parameters"]))
    assert crit.margin == pytest.approx(fl["value"], rel=1e-10)
    assert res.model_dict(fl["parameters"])["mount_rings"][0]["x"] == fl["parameters"]["mount_rings[0].x"]
    with pytest.raises(ModelError):
        res.model({"mount_rings[0].radius": 0.2})


def test_three_parameters_one_parameter_and_samples(tmp_path):
    three = write_study(tmp_path, GRID_6x5 + '\n[[parameters]]\npath = "mount_rings[0].count"\nvalues = [3, 4]\n',
                        name="three.toml")
    res = run_study(load_study(three), None)
    ax = res.plot(x="mount_rings[0].k_shear", y="mount_rings[0].x", at={"mount_rings[0].count": 4})
    assert "mounts per ring = 4" in ax.get_title() and ax.get_xscale() == "log"
    plt.close(ax.figure)
    one = write_study(tmp_path, '[[parameters]]\npath = "mount_rings[0].x"\nvalues = { start = 0.1, stop = 0.4, num = 7 }',
                      name="one.toml")
    ax = run_study(load_study(one), None).plot(value="margin")
    assert ax.get_ylabel().startswith("margin")
    plt.close(ax.figure)
    sob = write_study(tmp_path, GRID_6x5.replace(", num = 6", "").replace(", num = 5", "") +
                      '\n[sampling]\nmethod = "sobol"\nn = 32\n', name="sobol.toml", chunk_size=None)
    ax = run_study(load_study(sob), None).plot()
    assert ax.collections  # coloured points
    plt.close(ax.figure)
