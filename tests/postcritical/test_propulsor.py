"""Post-critical analysis of propulsor models against independent answers.

* the supercritical cycle of the benign example (hardening shear springs) at a thrust past the
  onset equals the one a long time integration with impstab's Hamming integrator settles on
  (:func:`impstab.simulate`, its own envelope fit): period and amplitudes of every coordinate;
* near the onset the computed branch approaches the normal-form cycle, the relative error of
  the first-order amplitude falling like ``T - T_c`` (halving with the distance);
* the hand argument on l1: in a layout whose axial stiffness centre lies on the thrust line the
  static deflection is a pure surge, so the shear springs are straight at equilibrium and a cubic
  shear law ``k3_shear`` changes neither the equilibrium nor its tangent (T_c and omega
  unchanged) nor the quadratic form; it enters only the cubic form, linearly. So l1 is affine in
  k3_shear: ``l1(k) + l1(-k) = 2 l1(0)``, and it changes sign at ``k* = -l1(0) / slope``:
  hardening gives a supercritical onset, softening a subcritical one;
* the degenerate onsets say so with the reason, never with a coefficient: an undamped model (a
  1:1 resonance), a symmetric ring (a double pair), a divergence;
* the softening example (subcritical): between its fold and T_c the branch has two cycles, the
  small one unstable and the large one stable; 50 N past T_c a long Hamming run from a small
  displacement jumps to the large cycle that the snubbers bound;
* every requested thrust appears exactly in the branch; JSON keys of DESIGN.md; bad input.
"""

import json
import math

import numpy as np
import pytest
import xarray as xr

import impstab
from _settled import settled_amplitude
from impstab.cli import main
from impstab.errors import ModelError
from impstab.model import model_from_dict
from impstab.postcritical import PostcriticalResult, hopf_analysis, propulsor_postcritical
from impstab.postcritical.propulsor import propulsor_system

DESIGN_KEYS = {"critical_thrust", "kind", "omega", "lyapunov_coefficient", "bifurcation", "fold_thrust", "branch"}
BRANCH_KEYS = {"thrust", "period", "stable", "amplitude"}
DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
#: past the onset by this much the benign example's cycle is settled on within a few hundred seconds
PAST = 300.0


def layout(k3_shear=0.0, **extra) -> dict:
    """The examples' layout: axial stiffness centre on the thrust line (sum k_a y = sum k_a z = 0)."""
    mounts = []
    for pos, ka, ks in [([0.30, 0.16, 0.02], 1.2e5, 2.2e4), ([0.28, -0.05, 0.15], 0.9e5, 1.8e4),
                        ([0.33, -0.09, -0.13], 1.0e5, 2.0e4), ([-0.20, -0.19, -0.29 / 3], 0.3e5, 1.0e4)]:
        mounts.append({"position": pos, "k_axial": ka, "k_shear": ks, "c_axial": 40.0, "c_shear": 8.0,
                       "k3_shear": k3_shear, **extra})
    return {"schema_version": 1, "name": "layout", "body": {"mass": 120.0, "cg": [0.05, 0.01, -0.005],
            "inertia": [[1.4, 0.05, 0.0], [0.05, 7.5, 0.1], [0.0, 0.1, 7.0]]}, "mounts": mounts,
            "thrust": {"operating": 3000.0}, "analysis": {"thrust_max": 30000.0}}


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def benign(examples_dir):
    model = impstab.load_model(examples_dir / "imp_hardening.toml")
    tc = impstab.critical_thrust(model).thrust
    near = [tc + 0.25, tc + 0.5, tc + 1.0]
    res = propulsor_postcritical(model, thrusts=near + [tc + PAST, tc - 100.0], max_points=40)
    return model, tc, near, res


@pytest.fixture(scope="module")
def examples_dir():
    from pathlib import Path

    return Path(__file__).resolve().parents[2] / "examples"


def _cycle(res, thrust):
    idx = [i for i, t in enumerate(res.branch_thrust) if t == thrust]
    assert idx, f"{thrust} not in the branch"
    return idx


# ------------------------------------------------------------------ supercritical: the simulation agrees
def test_a_long_hamming_run_lands_on_the_computed_cycle(benign):
    model, tc, _, res = benign
    assert res.bifurcation == "supercritical" and res.lyapunov_coefficient < 0 and res.kind == "flutter"
    assert res.critical_thrust == pytest.approx(tc, rel=1e-9)          # the linear engine's onset, refined
    (i,) = _cycle(res, tc + PAST)
    assert res.branch_stable[i] and res.branch_label[i] == "requested"
    # 1000 s from a pitch displacement (the cycle attracts at |mu| = 0.992 per period), then two
    # periods sampled densely from the state reached; dt = 1 ms (the error falls as dt^4)
    settle = impstab.simulate(model, thrust=tc + PAST, duration=1000.0, dt=1e-3, integrator="hamming",
                              critical_thrust=tc, sample=0.5, perturbation={"displacement": {"pitch": 0.03}})
    z = settle.deviation[-1]
    run2 = impstab.simulate(model, thrust=tc + PAST, duration=0.65, dt=1e-3, integrator="hamming", critical_thrust=tc,
                            sample=1e-4, perturbation={"displacement": z[:6], "velocity": z[6:]})
    y = run2.deviation + run2.equilibrium
    amplitude = 0.5 * (y[:, :6].max(axis=0) - y[:, :6].min(axis=0))
    x = y[:, 4] - 0.5 * (y[:, 4].max() + y[:, 4].min())
    k = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    t = run2.time
    crossings = t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])
    assert crossings.size >= 2
    assert np.diff(crossings).mean() == pytest.approx(res.branch_period[i], rel=1e-8)
    np.testing.assert_allclose(amplitude, res.branch_amplitude[i], rtol=2e-6)
    assert res.branch_amplitude[i, 4] > 0.02                             # a real oscillation, 0.035 rad of pitch
    assert res.trivial_multiplier_error[i] < 1e-8 and res.largest_multiplier[i] < 1.0


def test_the_branch_approaches_the_normal_form_cycle_at_the_onset(benign):
    _, tc, near, res = benign
    hopf = res.hopf
    errors = []
    for t in near:
        (i,) = _cycle(res, t)
        predicted = hopf.predicted_amplitude(t, order=1)[:6]
        j = int(np.argmax(res.branch_amplitude[i] / np.asarray(res.settings["state_scale"][:6])))
        errors.append(abs(predicted[j] / res.branch_amplitude[i, j] - 1.0))
        assert res.branch_period[i] == pytest.approx(float(hopf.predicted_period(t)), rel=1e-5)
    # O(T - T_c): the error halves with the distance to the onset
    assert errors[0] < 2e-3
    assert errors[1] / errors[0] == pytest.approx(2.0, rel=0.15)
    assert errors[2] / errors[1] == pytest.approx(2.0, rel=0.15)


def test_every_requested_thrust_appears_exactly(benign):
    _, tc, near, res = benign
    for t in near + [tc + PAST]:
        (i,) = _cycle(res, t)
        assert res.branch_label[i] == "requested" and np.isfinite(res.branch_period[i])
    (i,) = _cycle(res, tc - 100.0)        # below a supercritical onset: the stable equilibrium, no cycle
    assert res.branch_label[i] == "no cycle" and res.branch_stable[i] and np.all(res.branch_amplitude[i] == 0.0)
    d = res.to_dict()
    assert set(DESIGN_KEYS) <= set(d) and set(BRANCH_KEYS) <= set(d["branch"])
    assert set(d["branch"]["amplitude"]) == set(DOFS)
    assert all(t in d["branch"]["thrust"] for t in near)
    json.dumps(d, allow_nan=False)


# ------------------------------------------------------------------ the hand argument on l1 and k3
def _hopf(k3):
    model = model_from_dict(layout(k3))
    crit = impstab.critical_thrust(model)
    system, ns = propulsor_system(model, crit.omega)
    return hopf_analysis(system, ns.equilibrium(crit.thrust), crit.thrust, omega=crit.omega)


def test_l1_is_affine_in_the_cubic_shear_stiffness_and_changes_sign_with_it():
    k = 1.0e7
    h0, hp, hm = _hopf(0.0), _hopf(k), _hopf(-k)
    for h in (hp, hm):                      # the tangent does not see k3_shear: same onset, same pair
        assert h.parameter == pytest.approx(h0.parameter, rel=1e-10)
        assert h.omega == pytest.approx(h0.omega, rel=1e-10)
    assert hp.lyapunov_coefficient + hm.lyapunov_coefficient == pytest.approx(
        2 * h0.lyapunov_coefficient, abs=1e-6 * abs(hp.lyapunov_coefficient))
    assert hp.bifurcation == "supercritical" and hm.bifurcation == "subcritical"
    slope = (hp.lyapunov_coefficient - hm.lyapunov_coefficient) / (2 * k)
    assert slope < 0                         # hardening lowers l1
    k_star = -h0.lyapunov_coefficient / slope
    # the zero of the affine law, from the two sides
    h_below, h_above = _hopf(k_star - 0.2 * abs(k_star)), _hopf(k_star + 0.2 * abs(k_star))
    assert {h_below.bifurcation, h_above.bifurcation} == {"supercritical", "subcritical"}
    assert h_below.lyapunov_coefficient == pytest.approx(-h_above.lyapunov_coefficient, rel=1e-5)


# ------------------------------------------------------------------ degenerate onsets
@pytest.mark.parametrize("name,words", [
    ("imp_asymmetric.toml", "collision"),        # undamped: a reversible system, 1:1 resonance
    ("imp_damped.toml", "symmetric"),            # a damped ring without spin: two pairs cross together
])
def test_degenerate_onsets_give_the_reason_and_no_coefficient(examples_dir, name, words):
    import tomllib

    with open(examples_dir / name, "rb") as fh:
        d = tomllib.load(fh)
    d.pop("propeller", None)                     # gyroscopic coupling would split the ring's double pairs
    model = model_from_dict(d)
    res = propulsor_postcritical(model, thrusts=[1000.0])
    assert res.bifurcation == "degenerate" and words in res.reason
    assert res.lyapunov_coefficient is None and res.fold_thrust is None
    assert res.critical_thrust == pytest.approx(impstab.critical_thrust(model).thrust, rel=1e-8)
    assert list(res.branch_thrust) == [1000.0] and res.branch_label == ("no cycle",)
    assert res.branch_stable[0] and res.branch_amplitude[0, 0] == 0.0
    assert res.reading.startswith("undetermined")
    json.dumps(res.to_dict(), allow_nan=False)


def test_a_divergence_onset_is_degenerate():
    d = layout(1e7)
    d["thrust"]["tangency"] = 0.0          # a dead load: a static instability
    d["analysis"]["thrust_max"] = 1.0e6
    model = model_from_dict(d)
    crit = impstab.critical_thrust(model)
    if crit.kind != "divergence":
        pytest.skip(f"the dead-load layout loses stability by {crit.kind}")
    res = propulsor_postcritical(model)
    assert res.kind == "divergence" and res.bifurcation == "degenerate" and "divergence" in res.reason
    assert res.lyapunov_coefficient is None and res.branch_thrust.size == 0


def test_no_onset_up_to_thrust_max(examples_dir):
    model = impstab.load_model(examples_dir / "imp_hardening.toml")
    res = propulsor_postcritical(model, thrust_max=5000.0, thrusts=[4000.0])
    assert res.kind == "none" and res.critical_thrust is None and res.bifurcation is None
    assert res.branch_label == ("no cycle",) and res.reading.startswith("stable")


# ------------------------------------------------------------------ subcritical: the dangerous example
#: between the softening example's fold (292 N below its onset) and the onset
BELOW = 150.0


@pytest.fixture(scope="module")
def dangerous(examples_dir):
    """The softening example's branch, through a thrust between its fold and T_c and one past T_c."""
    model = impstab.load_model(examples_dir / "imp_softening.toml")
    tc = impstab.critical_thrust(model).thrust
    return model, tc, propulsor_postcritical(model, thrusts=[tc - BELOW, tc + 50.0])


def test_the_softening_design_is_subcritical_with_a_fold_below_the_onset(dangerous):
    model, tc, res = dangerous
    assert res.bifurcation == "subcritical" and res.lyapunov_coefficient > 0
    assert res.fold_thrust is not None and res.fold_thrust < res.critical_thrust
    assert res.practical_limit_thrust == res.fold_thrust
    assert res.reading.startswith("dangerous")
    assert np.any(res.snubber_contact)                        # the snubber is what stops the growth
    # just below the onset, between the fold and T_c, two cycles: the small unstable one and the large stable one
    assert res.fold_thrust < tc - BELOW
    idx = _cycle(res, tc - BELOW)
    assert len(idx) == 2
    small, large = sorted(idx, key=lambda i: res.branch_amplitude[i, 4])
    assert not res.branch_stable[small] and res.branch_stable[large]


def test_past_the_subcritical_onset_a_run_jumps_to_the_snubber_cycle(dangerous):
    # from 0.001 rad of pitch, 50 N past the onset, a long run grows onto the large stable cycle
    # that the snubbers bound, the only stable cycle the branch has there
    model, tc, res = dangerous
    (i,) = _cycle(res, tc + 50.0)
    assert res.branch_stable[i] and res.snubber_contact[i] and res.branch_amplitude[i, 4] > 0.04
    amplitude = settled_amplitude(model, tc + 50.0, tc, 3000.0, 5e-4)
    np.testing.assert_allclose(amplitude, res.branch_amplitude[i], rtol=1e-3)


# ------------------------------------------------------------------ outputs and the command line
def test_dataset_and_figures(benign, tmp_path):
    _, tc, _, res = benign
    ds = res.to_xarray()
    ds.to_netcdf(tmp_path / "p.nc", engine="h5netcdf")
    back = xr.load_dataset(tmp_path / "p.nc", engine="h5netcdf")
    assert back.attrs["bifurcation"] == "supercritical" and back["thrust"].attrs["units"] == "N"
    assert back.attrs["critical_thrust"] == pytest.approx(tc, rel=1e-9)
    assert json.loads(back.attrs["settings"])["max_points"] == 40
    np.testing.assert_array_equal(back["amplitude"].values, res.branch_amplitude)
    import matplotlib

    matplotlib.use("Agg")
    ax = res.plot()
    assert ax.get_xlabel() == "thrust (N)" and "amplitude" in ax.get_ylabel()
    ax2 = res.plot_cycle(tc + PAST)
    assert "pitch" in ax2.get_xlabel()
    import matplotlib.pyplot as plt

    plt.close("all")


def test_cli_json_keys_and_outputs(capsys, examples_dir, tmp_path):
    out = tmp_path / "pc.nc"
    code, text, err = run(capsys, "postcritical", examples_dir / "imp_hardening.toml", "--thrusts", "12700,13000",
                          "--max-points", "12", "--json", "-o", out)
    assert code == 0, err
    assert text.count("\n") == 1
    d = json.loads(text)
    assert DESIGN_KEYS <= set(d) and BRANCH_KEYS <= set(d["branch"]) and set(d["branch"]["amplitude"]) == set(DOFS)
    assert d["kind"] == "flutter" and d["bifurcation"] == "supercritical"
    assert 12700.0 in d["branch"]["thrust"] and 13000.0 in d["branch"]["thrust"]
    assert isinstance(d["lyapunov_coefficient"], float) and d["fold_thrust"] is None
    assert out.exists() and out.with_suffix(".png").stat().st_size > 1000
    code, text, err = run(capsys, "postcritical", examples_dir / "imp_hardening.toml", "--max-points", "3")
    assert code == 0 and "reading: benign" in text


@pytest.mark.parametrize("args,field", [
    (("--thrusts", "abc"), "--thrusts"),
    (("--thrusts", "-5"), "--thrusts"),
    (("--thrusts", "1e12"), "--thrusts"),
    (("--thrusts", "20000"), "--thrusts"),            # beyond thrust_max
    (("--thrust-max", "-1"), "--thrust-max"),
    (("--thrust-max", "nan"), "--thrust-max"),
    (("--max-points", "0"), "--max-points"),
    (("-o", "OUT/x.txt"), "--output"),
])
def test_cli_bad_input_exit_2(capsys, examples_dir, tmp_path, args, field):
    args = [str(tmp_path / a[4:]) if a.startswith("OUT/") else a for a in args]
    code, out, err = run(capsys, "postcritical", examples_dir / "imp_hardening.toml", *args)
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("impstab: error: ") and field in err
    assert list(tmp_path.iterdir()) == []


def test_api_bad_thrusts(examples_dir):
    model = impstab.load_model(examples_dir / "imp_hardening.toml")
    with pytest.raises(ModelError, match="thrusts"):
        propulsor_postcritical(model, thrusts=[math.nan])
    with pytest.raises(ModelError, match="thrusts"):
        propulsor_postcritical(model, thrusts=[True])


def test_report_provider_is_this_analysis():
    from impstab.report.analyses import find_provider

    func, reason = find_provider("postcritical")
    assert func is propulsor_postcritical and reason == ""
    assert PostcriticalResult.__dataclass_params__.frozen
