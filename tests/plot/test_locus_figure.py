"""Locus results and figures: eigenvalues equal the full state matrix's, branches are conjugate
pairs named by the modes' kinetic energy, one colour per branch in both panels, the onset
marked and visible."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import impstab  # noqa: E402
from impstab.linear.eigen import state_matrices  # noqa: E402
from impstab.linear.linearize import ModelFamily  # noqa: E402
from impstab.plot import LocusAxes  # noqa: E402
from impstab.plot.locus import growth_axis_scale  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def loci():
    out = {}
    for name in ("symmetric", "asymmetric", "damped", "fluid"):
        model = impstab.load_model(EXAMPLES / f"imp_{name}.toml")
        out[name] = (model, impstab.locus(model, steps=80, critical=True))
    return out


def _sorted(v):
    return v[np.lexsort((np.round(v.imag, 6), np.round(v.real, 6)))]


@pytest.mark.parametrize("name", ["symmetric", "asymmetric", "damped", "fluid"])
def test_eigenvalues_equal_those_of_the_whole_state_matrix(loci, name):
    model, loc = loci[name]
    fam = ModelFamily(model, fluid_frequency=loc.fluid_frequency_hz or 0.0)
    m, d, g, k = fam.matrices(loc.thrust)
    full = np.linalg.eigvals(state_matrices(m, d + g, k))
    scale = np.abs(full).max()
    for i in range(0, loc.thrust.size, 7):
        a, b = np.sort_complex(full[i]), np.sort_complex(loc.eigenvalues[i])
        # as sets: every eigenvalue of one has a partner in the other (sqrt(eps) at a double root)
        dist = np.abs(a[:, None] - b[None, :]).min(axis=1)
        assert dist.max() < 1e-7 * scale, (name, loc.thrust[i], dist.max())


@pytest.mark.parametrize("name", ["symmetric", "asymmetric"])
def test_branches_are_conjugate_pairs_named_like_the_modes(loci, name):
    model, loc = loci[name]
    modes = loc.modes
    assert sorted(np.bincount(modes)) == [2] * 6
    lam0 = loc.eigenvalues[0]
    for b in range(6):
        a, c = lam0[modes == b]
        assert abs(a - np.conj(c)) <= 1e-9 * abs(a)
    # the names are the dofs holding at least DOMINANT_SHARE of the kinetic-energy diagonal
    # |x_i|^2 M_ii of the modes at T = 0, from the modal analysis's own solver and shapes
    from impstab.linear.locus import DOMINANT_SHARE

    md = impstab.modes(model, 0.0)
    w = np.abs(md.shapes) ** 2 * np.diag(impstab.linearize(model, 0.0).M)[:, None]
    w = w / w.sum(axis=0)
    dofs = impstab.DOF_NAMES
    expected = sorted(tuple(sorted(dofs[i] for i in np.flatnonzero(col >= DOMINANT_SHARE))) for col in w.T)
    got = sorted(tuple(sorted(label.split(", "))) for label in loc.branch_labels())
    assert got == expected


def test_symmetric_planes_share_one_line_and_one_colour_per_branch(loci):
    _, loc = loci["symmetric"]
    axes = loc.plot()
    assert isinstance(axes, LocusAxes)
    labels = [t.get_text() for t in axes.frequency.get_legend().get_texts()]
    assert labels == ["2.13 Hz: sway, yaw | heave, pitch (2 identical)", "5.85 Hz: roll",
                      "6.91 Hz: yaw, sway | pitch, heave (2 identical)", "8.72 Hz: surge"]
    handles = axes.frequency.get_legend().legend_handles
    legend_colours = {h.get_color() for h in handles}
    for ax in axes:
        drawn = {ln.get_color() for ln in ax.lines if ln.get_linestyle() == "-" and len(ln.get_xdata()) > 2}
        assert drawn == legend_colours  # the same colour per branch in both panels, and no other
    plt.close("all")


def test_onset_marked_at_the_critical_thrust_and_the_undamped_beside_it(loci):
    model, loc = loci["damped"]
    crit = impstab.critical_thrust(model)
    assert loc.critical_thrust == pytest.approx(crit.thrust, rel=1e-12)
    assert loc.undamped_critical_thrust == pytest.approx(crit.undamped_thrust, rel=1e-12)
    axes = loc.plot()
    vlines = {round(float(ln.get_xdata()[0]), 6) for ln in axes.growth.lines
              if len(set(np.atleast_1d(ln.get_xdata()))) == 1 and len(ln.get_xdata()) == 2}
    assert round(crit.thrust, 6) in vlines and round(crit.undamped_thrust, 6) in vlines
    marks = [t.get_text() for t in axes.growth.get_legend().get_texts()]
    assert any(t.startswith("onset (flutter): 16291.3 N") for t in marks)
    assert any(t.startswith("undamped onset: 18000 N") for t in marks)
    plt.close("all")


def test_growth_of_order_1e9_past_the_onset_is_visible(loci):
    model, loc = loci["fluid"]
    kind, linthresh = growth_axis_scale(loc)
    assert kind == "symlog"
    past = (loc.thrust > loc.critical_thrust) & (loc.thrust < 16000.0)
    g = loc.growth_rate[past].max(axis=1)
    assert np.all((g > 0) & (g < 1e-6))          # radiation damping: a tiny growth ...
    assert np.all(g > 3 * linthresh)              # ... drawn above the linear band, not on zero
    axes = loc.plot()
    assert axes.growth.get_yscale() == "symlog"
    plt.close("all")
    _, sym = loci["symmetric"]
    assert growth_axis_scale(sym) == ("linear", None)  # growth of order 1 at once: a plain axis


def test_plot_on_given_axes_and_legends_outside_the_data(loci):
    _, loc = loci["asymmetric"]
    fig, (a, b) = plt.subplots(2, 1, layout="constrained")
    out = loc.plot(ax=(a, b))
    assert out == (a, b) and out.figure is fig
    fig.canvas.draw()
    for ax in out:
        leg = ax.get_legend().get_window_extent()
        assert leg.x0 >= ax.get_window_extent().x1 - 1  # beside the panel, not over it
    _, one = plt.subplots()
    assert loc.plot(ax=one) is one
    plt.close("all")


def test_netcdf_round_trip_keeps_the_branches(loci, tmp_path):
    import xarray as xr

    _, loc = loci["symmetric"]
    path = tmp_path / "l.nc"
    loc.to_xarray().to_netcdf(path, engine="h5netcdf")
    back = impstab.linear.locus.LocusResult.from_xarray(xr.load_dataset(path, engine="h5netcdf"))
    np.testing.assert_array_equal(back.eigenvalues, loc.eigenvalues)
    np.testing.assert_array_equal(back.modes, loc.modes)
    assert back.branch_labels() == loc.branch_labels() and back.critical_thrust == loc.critical_thrust
