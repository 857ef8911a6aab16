"""One style applied while drawing (the user's rcParams untouched), figures as PNG, SVG or PDF
with a resolution, --no-plot, and units on every netCDF variable the commands write."""

import json
import struct
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import xarray as xr  # noqa: E402

import impstab  # noqa: E402
from impstab.cli import main  # noqa: E402
from impstab.errors import ModelError  # noqa: E402
from impstab.plot.save import save_figure  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SYM = str(EXAMPLES / "imp_symmetric.toml")


def _png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def test_importing_and_drawing_leave_the_users_rcparams_alone():
    before = dict(matplotlib.rcParams)
    import impstab.plot  # noqa: F401

    loc = impstab.locus(impstab.load_model(SYM), steps=10)
    axes = loc.plot()
    after = dict(matplotlib.rcParams)
    assert after == before
    assert axes.frequency.yaxis.get_major_formatter().get_useOffset() is False  # the style was applied
    plt.close("all")


def test_figure_formats_by_suffix_and_dpi(tmp_path):
    fig, ax = plt.subplots(figsize=(2.0, 1.0))
    ax.plot([0, 1], [0, 1])
    low, high = save_figure(fig, tmp_path / "a.png", dpi=50), save_figure(fig, tmp_path / "b.png", dpi=100)
    (w1, h1), (w2, h2) = _png_size(low), _png_size(high)
    assert abs(w2 / w1 - 2.0) < 0.1 and abs(h2 / h1 - 2.0) < 0.15
    assert save_figure(fig, tmp_path / "c.svg").read_text().lstrip().startswith("<?xml")
    assert save_figure(fig, tmp_path / "d.pdf").read_bytes()[:5] == b"%PDF-"
    with pytest.raises(ModelError, match=r"must end in \.png, \.svg or \.pdf"):
        save_figure(fig, tmp_path / "e.jpg")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png", "c.svg", "d.pdf"]
    plt.close(fig)


def _units_everywhere(ds) -> list[str]:
    """Numeric variables without units (flag variables carry flag_meanings instead)."""
    return [n for n, v in ds.variables.items()
            if v.dtype.kind in "fiu" and "units" not in v.attrs and "flag_meanings" not in v.attrs]


def test_locus_command_outputs(tmp_path, capsys):
    assert main(["locus", SYM, "--steps", "20", "-o", str(tmp_path / "l.pdf")]) == 0
    assert (tmp_path / "l.pdf").read_bytes()[:5] == b"%PDF-" and not (tmp_path / "l.png").exists()
    assert main(["locus", SYM, "--steps", "20", "-o", str(tmp_path / "l.nc"), "--no-plot"]) == 0
    assert not (tmp_path / "l.png").exists()
    assert _units_everywhere(xr.load_dataset(tmp_path / "l.nc")) == []
    assert main(["locus", SYM, "--steps", "20", "-o", str(tmp_path / "m.nc"), "--figure", str(tmp_path / "m.svg"),
                 "--dpi", "80"]) == 0
    assert (tmp_path / "m.svg").exists() and not (tmp_path / "m.png").exists()
    capsys.readouterr()
    for bad, flag in ((["-o", str(tmp_path / "x.pdf"), "--no-plot"], "--no-plot"),
                      (["-o", str(tmp_path / "x.nc"), "--figure", str(tmp_path / "x.gif")], "--figure"),
                      (["-o", str(tmp_path / "x.nc"), "--dpi", "-3"], "--dpi")):
        assert main(["locus", SYM, "--steps", "5", *bad]) == 2
        assert flag in capsys.readouterr().err
    assert not list(tmp_path.glob("x*"))


def test_simulate_several_thrusts_netcdf_has_units_and_a_thrust_index(tmp_path, capsys):
    out = tmp_path / "three.nc"
    assert main(["simulate", SYM, "--thrusts", "12000,18012.1,19000", "--duration", "1", "-o", str(out),
                 "--figure", str(tmp_path / "three.svg")]) == 0
    assert (tmp_path / "three.svg").exists()
    ds = xr.load_dataset(out, engine="h5netcdf")
    assert _units_everywhere(ds) == []
    assert ds["thrust"].dims == ("case",) and ds["thrust"].attrs["units"] == "N"
    one = ds.set_xindex("thrust").sel(thrust=19000.0)
    assert one["classification"].item() == "supercritical" and one["sway"].dims == ("time",)
    assert main(["simulate", SYM, "--thrust", "5000", "--duration", "0.2", "-o", str(tmp_path / "one.pdf")]) == 0
    assert (tmp_path / "one.pdf").exists() and not list(tmp_path.glob("one.nc"))
    capsys.readouterr()
    assert main(["simulate", SYM, "--thrust", "5000", "--duration", "0.2", "-o", str(tmp_path / "d.nc"), "--no-plot",
                 "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["figure"] is None and not (tmp_path / "d.png").exists()
    assert _units_everywhere(xr.load_dataset(tmp_path / "d.nc", engine="h5netcdf")) == []


def test_in_memory_multi_run_dataset_selects_by_thrust():
    from impstab.dynamics.result import combine_results

    model = impstab.load_model(SYM)
    runs = [impstab.simulate(model, thrust=t, duration=0.1, dt=2e-3, critical_thrust=False) for t in (1000.0, 2000.0)]
    ds = combine_results(runs)
    np.testing.assert_array_equal(ds.sel(thrust=2000.0)["sway"].values, runs[1].displacement[:, 1])
    np.testing.assert_array_equal(ds.sel(thrust=1000.0)["applied_thrust"].values, runs[0].thrust)


def test_map_and_added_mass_outputs(tmp_path, capsys):
    study = tmp_path / "s.toml"
    (tmp_path / "m.toml").write_text(Path(SYM).read_text())
    study.write_text('schema_version = 1\nmodel = "m.toml"\n[[parameters]]\npath = "mount_rings[0].x"\n'
                     'values = [0.1, 0.2, 0.3]\n[[parameters]]\npath = "mount_rings[0].k_shear"\nvalues = [1e4, 2e4]\n')
    assert main(["sweep", str(study), "-o", str(tmp_path / "s.zarr"), "--export", str(tmp_path / "s.nc")]) == 0
    assert _units_everywhere(xr.load_dataset(tmp_path / "s.nc", engine="h5netcdf")) == []
    assert main(["map", str(tmp_path / "s.zarr"), "-o", str(tmp_path / "map.pdf")]) == 0
    assert (tmp_path / "map.pdf").read_bytes()[:5] == b"%PDF-"
    assert main(["map", str(tmp_path / "s.zarr"), "-o", str(tmp_path / "map.png"), "--dpi", "60"]) == 0
    assert main(["added-mass", "--radius", "0.15", "--length", "0.8", "--sound-speed", "1500",
                 "--frequencies", "0:100:3", "-o", str(tmp_path / "am.nc")]) == 0
    ds = xr.load_dataset(tmp_path / "am.nc", engine="h5netcdf")
    assert _units_everywhere(ds) == [] and ds["added_mass"].attrs["units"] == "kg"
    assert main(["added-mass", "--radius", "0.15", "--length", "0.8", "--frequencies", "0:100:3",
                 "-o", str(tmp_path / "am.svg")]) == 0
