"""Branches of cycles from Hopf points: closed-form branches, folds, normal form, time integration."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest
import xarray as xr
from scipy.integrate import solve_ivp

from impstab.errors import ModelError
from impstab.postcritical import continue_cycles, cycle_at, cycles_at, hopf_analysis

from _pc_systems import bautin, bautin_multiplier, bautin_radius, rossler, rossler_equilibrium, with_mass_matrix

matplotlib.use("Agg")

P2 = 0.7
FOLD = -P2 ** 2 / 4


@pytest.fixture(scope="module")
def subcritical():
    system = bautin(P2)
    h = hopf_analysis(system, [1e-3, 0.0], 0.05)
    calls = []
    br = continue_cycles(system, h, 0.5, p_min=-1.0, parameters=[-0.1, 0.3, 2.0], ds_max=0.3,
                         progress=lambda k, p: calls.append((k, p)))
    return system, h, br, calls


def test_subcritical_branch_matches_the_closed_form(subcritical):
    _, h, br, _ = subcritical
    assert h.bifurcation == "subcritical"
    assert br.stop_reason == "reached p_max = 0.5"
    assert br.cycles[-1].parameter == 0.5
    for c in br.cycles:
        r = c.amplitude[0] ** 2
        # on a cycle r solves p1 + p2 r - r^2 = 0 (robust at the fold, where the root formula is not)
        assert abs(c.parameter + P2 * r - r * r) < 1e-10
        assert c.period == pytest.approx(2 * np.pi, rel=1e-10)
        assert c.trivial_error < 1e-10
        if abs(c.parameter - FOLD) > 1e-3:
            sign = 1 if r > P2 / 2 else -1
            assert c.stable == (sign == 1)                 # the outer cycle is the stable one
            mu = np.real(c.nontrivial_multipliers[0])
            assert mu == pytest.approx(bautin_multiplier(c.parameter, P2, sign), rel=1e-8)


def test_fold_of_cycles_located(subcritical):
    _, _, br, _ = subcritical
    assert [s.kind for s in br.special_points] == ["fold"]
    fold = br.special_points[0]
    assert fold.parameter == pytest.approx(FOLD, abs=1e-10)
    assert br.fold_parameter == fold.parameter
    assert fold.cycle.amplitude[0] ** 2 == pytest.approx(P2 / 2, rel=1e-6)   # r = p2/2 at the fold
    assert abs(fold.multiplier - 1) < 1e-5
    # stability changes at the fold and nowhere else
    s = br.stable
    assert s[0] == False and s[-1] == True  # noqa: E712
    assert np.count_nonzero(s[1:] != s[:-1]) == 1


def test_requested_parameters_are_on_the_branch_exactly(subcritical):
    _, _, br, _ = subcritical
    two = br.requested(-0.1)
    assert len(two) == 2 and all(c.parameter == -0.1 for c in two)
    assert sorted(c.amplitude[0] ** 2 for c in two) == pytest.approx(
        [bautin_radius(-0.1, P2, -1), bautin_radius(-0.1, P2, 1)], rel=1e-9)
    assert [c.stable for c in two] == [False, True]
    assert len(br.requested(0.3)) == 1
    assert br.unreached == (2.0,)


def test_progress_callback(subcritical):
    _, _, br, calls = subcritical
    assert len(calls) >= 10 and calls[-1][0] >= calls[0][0]


def test_cycles_at_solves_exactly_between_branch_points(subcritical):
    system, _, br, _ = subcritical
    found = cycles_at(system, br, -0.05)
    assert len(found) == 2
    assert sorted(c.amplitude[0] ** 2 for c in found) == pytest.approx(
        [bautin_radius(-0.05, P2, -1), bautin_radius(-0.05, P2, 1)], rel=1e-9)
    assert cycle_at(system, br, -0.05, which=1).parameter == -0.05
    with pytest.raises(ModelError, match="passes it 0 time"):
        cycle_at(system, br, -0.5)


def test_supercritical_branch_is_stable():
    system = bautin(-0.5)
    h = hopf_analysis(system, [1e-3, 0.0], 0.05)
    br = continue_cycles(system, h, 0.4, parameters=[-0.1, 0.25], ds_max=0.3)
    assert br.stable.all() and not br.special_points
    assert br.unreached == (-0.1,)
    c = br.requested(0.25)[0]
    assert c.amplitude[0] ** 2 == pytest.approx(bautin_radius(0.25, -0.5, 1), rel=1e-10)


def test_mass_matrix_branch_equals_the_plain_one(subcritical):
    _, _, plain, _ = subcritical
    mass = np.array([[2.0, 0.3], [-0.4, 1.5]])
    system = with_mass_matrix(bautin(P2), mass)
    h = hopf_analysis(system, [1e-3, 0.0], 0.05)
    br = continue_cycles(system, h, 0.5, p_min=-1.0, parameters=[-0.1, 0.3], ds_max=0.3)
    assert br.fold_parameter == pytest.approx(plain.fold_parameter, abs=1e-11)
    for v in (-0.1, 0.3):
        a, b = br.requested(v), plain.requested(v)
        assert len(a) == len(b)
        for ca, cb in zip(a, b):
            assert ca.amplitude == pytest.approx(cb.amplitude, rel=1e-10)
            assert np.sort(np.abs(ca.multipliers)) == pytest.approx(np.sort(np.abs(cb.multipliers)), rel=1e-8, abs=1e-12)
            assert ca.stable == cb.stable


@pytest.fixture(scope="module")
def rossler_branch():
    system = rossler()
    h = hopf_analysis(system, rossler_equilibrium(0.12), 0.12)
    near = [h.parameter + d for d in (2e-4, 4e-4, 8e-4)]
    br = continue_cycles(system, h, 0.36, parameters=near + [0.25, h.parameter + 2e-8], ds=0.005, ds_max=0.5)
    return system, h, br, near


def test_requested_value_before_the_first_step_comes_from_the_normal_form(rossler_branch):
    _, h, br, _ = rossler_branch
    p = h.parameter + 2e-8
    assert br.cycles[0].parameter == p and br.cycles[1].label == "start"   # closer to onset than the first step
    c = br.requested(p)[0]
    assert c.amplitude == pytest.approx(h.predicted_amplitude(p), rel=1e-5)
    assert br.unreached == ()


#: first period doubling of the Rossler cycle (b = 2, c = 4) and its period: AUTO-07p 0.9.2,
#: NTST = 80, NCOL = 4, EPSL = EPSU = 1e-10, EPSS = 1e-8 (NTST = 20 gives 0.33485662243)
AUTO_PD_A, AUTO_PD_PERIOD = 0.33485662256, 6.1799339812


def test_rossler_period_doubling_against_auto(rossler_branch):
    _, _, br, _ = rossler_branch
    pd = [s for s in br.special_points if s.kind == "period-doubling"]
    assert len(pd) == 1 and [s.kind for s in br.special_points] == ["period-doubling"]
    assert pd[0].parameter == pytest.approx(AUTO_PD_A, abs=2e-10)
    assert pd[0].period == pytest.approx(AUTO_PD_PERIOD, abs=2e-9)
    assert abs(pd[0].multiplier + 1) < 1e-8
    assert all(c.stable == (c.parameter < pd[0].parameter) for c in br.cycles if abs(c.parameter - AUTO_PD_A) > 1e-6)


def test_normal_form_amplitude_converges_like_the_parameter_distance(rossler_branch):
    _, h, br, near = rossler_branch
    errs = []
    for p in near:
        c = br.requested(p)[0]
        pred = h.predicted_amplitude(p)
        errs.append(np.max(np.abs(c.amplitude - pred) / c.amplitude))
        assert c.period == pytest.approx(h.predicted_period(p), rel=20 * (p - h.parameter))
    assert errs[0] < 5e-3
    # relative error O(p - p_c): doubling the distance doubles it
    assert 1.6 < errs[1] / errs[0] < 2.5 and 1.6 < errs[2] / errs[1] < 2.5
    # and the second-order normal form keeps the same order but is no worse
    c = br.requested(near[0])[0]
    pred2 = h.predicted_amplitude(near[0], order=2)
    assert np.max(np.abs(c.amplitude - pred2) / c.amplitude) < 5e-3


def test_rossler_cycle_against_long_time_integration(rossler_branch):
    """Period from successive Poincare crossings and amplitudes over the last period of a DOP853
    run (rtol 1e-12) started near the equilibrium: the stable cycle at a = 0.25."""
    system, _, br, _ = rossler_branch
    c = br.requested(0.25)[0]
    a = 0.25

    def rhs(t, x):
        return system.rhs(x[None, :], a)[0]

    def section(t, x):
        return x[1]
    section.direction = -1

    x0 = rossler_equilibrium(a) + np.array([0.1, 0.0, 0.0])
    sol = solve_ivp(rhs, (0, 600), x0, method="DOP853", rtol=1e-12, atol=1e-12, events=section, dense_output=True)
    times = sol.t_events[0]
    periods = np.diff(times)
    assert periods[-1] == pytest.approx(periods[-2], rel=1e-11)       # settled
    assert c.period == pytest.approx(periods[-1], rel=1e-9)
    t = np.linspace(times[-2], times[-1], 200001)
    x = sol.sol(t)
    amp = 0.5 * (x.max(axis=1) - x.min(axis=1))
    assert c.amplitude == pytest.approx(amp, rel=1e-8)
    assert c.stable


def test_to_xarray_and_netcdf_roundtrip(subcritical, tmp_path):
    _, h, br, _ = subcritical
    ds = br.to_xarray()
    assert ds.sizes["point"] == len(br)
    assert list(ds["state"].values) == ["x1", "x2"]
    assert np.array_equal(ds["p1"].values, br.parameter)
    assert ds.attrs["fold_parameter"] == br.fold_parameter
    assert ds.attrs["lyapunov_coefficient"] == pytest.approx(1.4, rel=1e-10)
    assert ds.attrs["hopf_bifurcation"] == "subcritical"
    assert ds["profile"].shape == (len(br), 129, 2)
    path = tmp_path / "branch.nc"
    ds.to_netcdf(path, engine="h5netcdf")
    back = xr.open_dataset(path, engine="h5netcdf")
    assert np.array_equal(back["amplitude"].values, br.amplitude)
    assert list(back["label"].values) == list(br.labels)
    back.close()


def test_plots_return_axes(subcritical, tmp_path):
    _, _, br, _ = subcritical
    ax = br.plot()
    assert ax.get_xlabel() == "p1" and "amplitude" in ax.get_ylabel()
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(t.startswith("fold of cycles") for t in labels)
    assert any(t.startswith("Hopf point (subcritical), p1 = 0") for t in labels)
    ax.figure.savefig(tmp_path / "branch.png")
    ax2 = br.plot_cycle(index=-1, states=("x1", "x2"))
    assert ax2.get_xlabel() == "x1"
    import matplotlib.pyplot as plt

    plt.close("all")


def test_bad_continuation_inputs():
    system = bautin(P2)
    h = hopf_analysis(system, [1e-3, 0.0], 0.05)
    with pytest.raises(ModelError, match="ds"):
        continue_cycles(system, h, 0.5, ds=1.0)
    with pytest.raises(ModelError, match="p_max"):
        continue_cycles(system, h, -2.0, p_min=-1.0)
    with pytest.raises(ModelError, match="intervals"):
        continue_cycles(system, h, 0.5, intervals=2)
    with pytest.raises(ModelError, match="parameters"):
        continue_cycles(system, h, 0.5, parameters=[math.nan])
    with pytest.raises(ModelError, match="start"):
        continue_cycles(system, "hopf", 0.5)
    degenerate = hopf_analysis(bautin(0.0), [1e-3, 0.0], 0.05)
    # l1 = 0 still starts (AUTO-like, along the eigenvector); other degenerate onsets do not
    br = continue_cycles(bautin(0.0), degenerate, 0.2, max_points=30, ds_max=0.3)
    assert br.cycles[-1].amplitude[0] ** 2 == pytest.approx(bautin_radius(br.cycles[-1].parameter, 0.0, 1), rel=1e-9)


def test_amplitude_and_point_limits_stop_the_branch():
    system = bautin(-0.5)
    h = hopf_analysis(system, [1e-3, 0.0], 0.05)
    br = continue_cycles(system, h, 10.0, amplitude_max=0.5, ds_max=0.3)
    assert br.stop_reason.startswith("amplitude limit 0.5 exceeded")
    assert np.max(br.amplitude[:-1]) <= 0.5 < np.max(br.amplitude[-1])
    br = continue_cycles(system, h, 10.0, max_points=5)
    assert br.stop_reason == "maximum number of points reached" and len(br) == 6   # the start and 5 steps
    assert br.labels[0] == "start" and br.labels[-1] == "end"
