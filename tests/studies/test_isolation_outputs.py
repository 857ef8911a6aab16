"""Isolation outputs of a study against single-model frequency responses; the Pareto front
against a brute-force dominance check."""

from __future__ import annotations

import numpy as np
import pytest

from impstab.errors import ModelError
from impstab.response import frequency_response, static_mount_loads
from impstab.studies import load_study, run_study
from impstab.studies.pareto import pareto_mask

from _study_helpers import write_study

BODY = """
outputs = ["margin", "kind", "peak_transmissibility", "peak_frequency_hz", "static_deflection", "peak_mount_load"]
[[parameters]]
path = "mount_rings[0].k_shear"
values = { start = 8e3, stop = 6e4, num = 3, scale = "log" }
[[parameters]]
path = "mount_rings[0].x"
values = [0.1, 0.3]
[[parameters]]
path = "thrust.operating"
values = [1500.0, 2000.0]
[isolation]
input = "heave"
range_hz = [0.5, 200.0]
points = 90
[[isolation.at]]
name = "t_blade"
frequency_hz = 167.0
[[isolation.at]]
name = "t_band"
band_hz = [20.0, 30.0]
"""


def test_isolation_outputs_equal_single_model_responses(tmp_path):
    study = load_study(write_study(tmp_path, BODY, model="imp_isolation.toml", chunk_size=5))
    assert study.outputs[-2:] == ("t_blade", "t_band")
    res = run_study(study)
    ds = res.dataset
    assert res.counts()["ok"] == 12
    grid = np.geomspace(0.5, 200.0, 90)
    band = np.geomspace(20.0, 30.0, 64)
    for k in ds["mount_rings[0].k_shear"].values:
        for x in ds["mount_rings[0].x"].values:
            for t in ds["thrust.operating"].values:
                params = {"mount_rings[0].k_shear": float(k), "mount_rings[0].x": float(x), "thrust.operating": float(t)}
                model = res.model(params)
                point = ds.sel(params)
                full = frequency_response(model, grid, input="heave").transmissibility
                j = int(np.argmax(full))
                assert point["peak_transmissibility"].item() == pytest.approx(full[j], rel=1e-10, abs=0)
                assert point["peak_frequency_hz"].item() == grid[j]
                at = frequency_response(model, [167.0], input="heave").transmissibility[0]
                assert point["t_blade"].item() == pytest.approx(at, rel=1e-10, abs=0)
                inb = frequency_response(model, band, input="heave").transmissibility.max()
                assert point["t_band"].item() == pytest.approx(inb, rel=1e-10, abs=0)
                st = static_mount_loads(model)
                assert st.thrust == t
                assert point["static_deflection"].item() == pytest.approx(st.deflection_magnitude.max(), rel=1e-10)
                assert point["peak_mount_load"].item() == pytest.approx(st.force_magnitude.max(), rel=1e-10)
                # independent check of the static load: three equal mounts on a symmetric ring share the thrust
                assert point["peak_mount_load"].item() == pytest.approx(t / 3.0, rel=1e-6)


def test_isolation_outputs_on_the_bulk_path(tmp_path):
    """An undamped study (bulk-assembled stability) still gets the single-model isolation values."""
    body = """
outputs = ["margin", "static_deflection", "peak_mount_load", "t_low"]
[[parameters]]
path = "mount_rings[0].k_shear"
values = [1e4, 2e4]
[isolation]
range_hz = [1.0, 50.0]
[[isolation.at]]
name = "t_low"
frequency_hz = 0.7
"""
    with pytest.raises(ModelError, match="t_low"):   # named outputs are not listed in outputs
        load_study(write_study(tmp_path, body))
    body = body.replace(', "t_low"]', "]")
    res = run_study(load_study(write_study(tmp_path, body)))
    for k in (1e4, 2e4):
        model = res.model({"mount_rings[0].k_shear": k})
        got = res.dataset.sel({"mount_rings[0].k_shear": k})
        want = frequency_response(model, [0.7]).transmissibility[0]
        assert got["t_low"].item() == pytest.approx(want, rel=1e-10, abs=0)
        assert got["peak_mount_load"].item() == pytest.approx(static_mount_loads(model).force_magnitude.max(), rel=1e-10)


@pytest.mark.parametrize("isolation, field", [
    ("", "isolation.range_hz"),
    ("[isolation]\nrange_hz = [0.0, 10.0]", "isolation.range_hz"),
    ("[isolation]\nrange_hz = [1.0, 10.0]\npoints = 1", "isolation.points"),
    ("[isolation]\nrange_hz = [1.0, 10.0]\nrang_hz = 3", "isolation.rang_hz"),
    ("[isolation]\nrange_hz = [1.0, true]", "isolation.range_hz[1]"),
    ("[isolation]\nrange_hz = [1.0, 10.0]\n[[isolation.at]]\nname = \"a\"", "isolation.at[0]"),
    ("[isolation]\nrange_hz = [1.0, 10.0]\n[[isolation.at]]\nname = \"margin\"\nfrequency_hz = 3.0", "isolation.at[0].name"),
    ("[isolation]\nrange_hz = [1.0, 10.0]\n[[isolation.at]]\nname = \"Bad name\"\nfrequency_hz = 3.0", "isolation.at[0].name"),
    ("[isolation]\nrange_hz = [1.0, 10.0]\ninput = \"twist\"", "isolation.input"),
])
def test_bad_isolation_table_names_the_field(tmp_path, isolation, field):
    body = f'outputs = ["margin", "peak_transmissibility"]\n[[parameters]]\npath = "mount_rings[0].x"\nvalues = [0.1]\n{isolation}\n'
    with pytest.raises(ModelError) as err:
        load_study(write_study(tmp_path, body))
    assert err.value.field == field


def _dominated_brute(f: np.ndarray) -> np.ndarray:
    n = f.shape[0]
    out = np.zeros(n, dtype=bool)
    for i in range(n):
        for j in range(n):
            if i != j and np.all(f[j] <= f[i]) and np.any(f[j] < f[i]):
                out[i] = True
    return out


@pytest.mark.parametrize("seed", range(6))
def test_pareto_mask_against_brute_force(seed):
    rng = np.random.default_rng(seed)
    f = rng.integers(0, 12, size=(80, 2)).astype(float)   # integers: ties and shared coordinates
    f[rng.integers(0, 80, 3), rng.integers(0, 2, 3)] = np.nan
    mask = pareto_mask(f)
    finite = np.isfinite(f).all(axis=1)
    want = np.zeros(len(f), dtype=bool)
    want[finite] = ~_dominated_brute(f[finite])
    np.testing.assert_array_equal(mask, want)


def test_tradeoff_front_and_figure(tmp_path):
    res = run_study(load_study(write_study(tmp_path, BODY, model="imp_isolation.toml", chunk_size=12)))
    t = res.tradeoff("t_band", required_margin=2.0, load_limit=600.0)
    feasible = t["feasible"]
    assert np.array_equal(feasible, res.dataset["peak_mount_load"].values.ravel() <= 600.0)
    pts = np.column_stack([t["isolation"], -t["stability"]])[feasible]
    assert np.array_equal(t["pareto"][feasible], ~_dominated_brute(pts))
    assert not t["pareto"][~feasible].any()
    c = t["chosen"]
    ok = t["acceptable"]
    assert t["stability"][c] >= 2.0 and t["isolation"][c] == t["isolation"][ok].min()
    ax = res.plot_tradeoff("t_band", required_margin=2.0, load_limit=600.0, isolation_limit=0.05)
    labels = [h.get_label() for h in ax.get_legend().legend_handles]
    assert any(s.startswith("Pareto front") for s in labels) and any("required margin 2" in s for s in labels)
    assert "N/N" in ax.get_ylabel() and "margin" in ax.get_xlabel()
    import matplotlib.pyplot as plt

    plt.close(ax.figure)
