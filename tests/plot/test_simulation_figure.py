"""Time-history figures: the default kick shows the flutter mode in sway and pitch, amplitudes
in readable units without offsets, nothing over the data, a blow-up drawn only while the
motion is small."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import impstab  # noqa: E402
from impstab.model import model_from_dict  # noqa: E402
from impstab.plot import SimulationAxes  # noqa: E402
from impstab.plot.simulation import ROTATION_RANGE, amplitude_unit, plot_simulations  # noqa: E402

T_C = 18012.0999227555


@pytest.fixture(scope="module")
def ring():
    from conftest import ring_model_dict

    return model_from_dict(ring_model_dict())


@pytest.fixture(scope="module")
def runs(ring):
    return [impstab.simulate(ring, thrust=t, duration=d, critical_thrust=T_C)
            for t, d in ((15000.0, 3.0), (T_C, 3.0), (19000.0, 12.0))]


def test_default_kick_moves_sway_and_pitch_like_the_linear_solution(runs):
    sub = runs[0]
    t = sub.time
    early = (t > 0) & (t < 2e-3)
    # a velocity kick v0 of a system at rest: x(t) = v0 t + O(t^3) (independent of the model)
    np.testing.assert_allclose(sub.displacement[early, 1], 1e-5 * t[early], rtol=1e-3)
    np.testing.assert_allclose(sub.displacement[early, 4], 1e-5 * t[early], rtol=1e-3)
    for r in runs:  # both planes move at every thrust: pitch is never a flat line
        assert np.abs(r.displacement[:, 4]).max() > 1e-3 * np.abs(r.displacement[:, 1]).max() / r.length_scale


@pytest.mark.parametrize("peak,unit", [(4e-7, "nm"), (3.3e-6, "µm"), (0.036, "mm"), (2.0, "m"), (0.0, "m")])
def test_amplitude_unit_keeps_at_most_three_digits(peak, unit):
    scale, u = amplitude_unit([0.0, -peak, peak / 2])
    assert u == unit
    if peak:
        assert 1.0 <= peak / scale < 1000.0


def test_figure_in_readable_units_without_offsets_or_text_over_the_data(runs):
    axes = plot_simulations(runs)
    assert isinstance(axes, SimulationAxes) and len(axes.sway) == 3
    fig = axes.figure
    fig.canvas.draw()
    for ax in [*axes.sway, *axes.pitch]:
        y = np.concatenate([ln.get_ydata() for ln in ax.lines if len(ln.get_ydata()) > 2])
        assert 1.0 <= np.abs(y).max() < 1000.0, ax.get_ylabel()
        assert ax.yaxis.get_offset_text().get_text() == ""
        assert not ax.texts and ax.get_legend() is None
    assert [a.get_ylabel().split(" ")[0] for a in axes.sway] == ["sway"] * 3
    title = axes.sway[2].get_title(loc="left")
    assert "supercritical" in title and "exponential growth" in title
    plt.close(fig)


def test_a_blow_up_is_drawn_while_the_motion_is_small(runs):
    sup = runs[2]
    assert np.abs(sup.displacement[:, 3:]).max() > ROTATION_RANGE  # the run itself went far
    ax_s, ax_p = sup.plot()
    n = ax_s.lines[0].get_xdata().size
    assert n < sup.time.size
    assert np.abs(sup.displacement[: n - 1, 3:]).max() <= ROTATION_RANGE
    assert "drawn to t =" in ax_s.get_title()
    plt.close("all")
