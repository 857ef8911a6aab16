"""Uncertainty statistics of sampled studies, against independent computations on the same samples.

The study results here are built from the store of a real study file (its samples, coordinates
and attributes) with the critical thrusts replaced by known values, so that every statistic can
be recomputed in the test from the *uncensored* values: scipy's ECDF, binomial test, beta
quantiles and order-statistic intervals; SALib called directly; the closed-form Sobol indices of
the Ishigami function.
"""

from __future__ import annotations

import json
import math

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from _study_helpers import EXAMPLES, write_study  # noqa: E402
from scipy import stats  # noqa: E402

from impstab.cli import main  # noqa: E402
from impstab.errors import ModelError  # noqa: E402
from impstab.studies import StudyResult, load_study, open_study, run_study  # noqa: E402
from impstab.studies.plan import plan_chunks  # noqa: E402
from impstab.studies.sensitivity import sensitivity_indices  # noqa: E402
from impstab.studies.statistics import clopper_pearson, study_statistics  # noqa: E402
from impstab.studies.store import StudyStore  # noqa: E402

THRUST_MAX = 20000.0  # imp_symmetric.toml
OPERATING = 2000.0

THREE = """
[[parameters]]
path = "mount_rings[0].k_shear"
values = {{ start = 1.0e4, stop = 3.0e4 }}
[[parameters]]
path = "mount_rings[0].k_axial"
values = {{ start = 5.0e4, stop = 1.5e5 }}
[[parameters]]
path = "mount_rings[0].x"
values = {{ start = 0.2, stop = 0.4 }}
[sampling]
method = "{method}"
n = {n}
seed = {seed}
"""
BOUNDS = [(1.0e4, 3.0e4), (5.0e4, 1.5e5), (0.2, 0.4)]


def fake_result(folder, method: str, n: int, thrust, *, seed: int = 3, status=None,
                operating: float = OPERATING) -> StudyResult:
    """A study's result (store layout, samples, attributes) with the critical thrusts ``thrust``
    (a function of the ``(designs, 3)`` parameter values): above ``thrust_max`` a design is
    stored as stable up to it, like the engine stores it."""
    model = "imp_symmetric.toml"
    if operating != OPERATING:
        folder.mkdir(parents=True, exist_ok=True)
        model = "operating.toml"
        text = (EXAMPLES / "imp_symmetric.toml").read_text()
        (folder / model).write_text(text.replace("operating = 2000.0 ", f"operating = {operating!r} "))
    study = load_study(write_study(folder, THREE.format(method=method, n=n, seed=seed), model=model,
                                   chunk_size=None, name=f"{method}.toml"))
    ds = StudyStore.create_or_resume(study, plan_chunks(study), None).open_dataset().load()
    x = np.column_stack([ds[p].values for p in json.loads(ds.attrs["parameters"])])
    t = np.asarray(thrust(x), dtype=float)
    st = np.zeros(t.size, dtype=np.int8) if status is None else np.asarray(status, dtype=np.int8)
    ok = st == 0
    stable = ok & (t > THRUST_MAX)
    crit = np.where(ok & ~stable, t, np.nan)
    kind = np.where(ok, np.where(stable, 0, 1), -1).astype(np.int8)
    ds = ds.assign(critical_thrust=ds["critical_thrust"].copy(data=crit), margin=ds["margin"].copy(data=crit / operating),
                   kind=ds["kind"].copy(data=kind), status=ds["status"].copy(data=st))
    return StudyResult(ds, None), t


def lognormal_thrust(x):
    """A critical thrust that grows with the shear stiffness, scattered like the examples'."""
    return 16000.0 * (x[:, 0] / 2.0e4) ** 1.2 * (1.0 + 0.5 * (x[:, 2] - 0.3))


@pytest.fixture(scope="module")
def random_case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("random")
    n = 600
    status = np.zeros(n, dtype=np.int8)
    status[[5, 77, 400]] = 1          # invalid
    status[[123]] = 2                 # numerical failure
    res, t = fake_result(folder, "random", n, lognormal_thrust, status=status)
    return res, t, status


def _complete_sample(t, status):
    """What the statistics must equal: the uncensored values of the computed designs."""
    return np.sort(t[status == 0])


# -- distribution, censoring ---------------------------------------------------------------------

def test_censoring_and_failures_are_counted(random_case):
    res, t, status = random_case
    s = study_statistics(res, None, sensitivity=False)
    ok = status == 0
    assert s.computed == int(ok.sum()) == 596
    assert s.failed == {"invalid": 3, "numerical_failure": 1, "error": 0}
    assert s.not_computed == 0
    expected = int(np.count_nonzero(ok & (t > THRUST_MAX)))
    assert 20 < expected < 300                                   # the case censors some designs
    assert s.critical_thrust.censored == s.margin.censored == s.censored == expected
    assert s.censored_fraction == pytest.approx(expected / ok.sum())
    assert s.critical_thrust.n == s.margin.n == ok.sum()         # failed designs are not in n
    assert s.critical_thrust.exact_up_to == THRUST_MAX
    assert s.margin.exact_up_to == pytest.approx(THRUST_MAX / OPERATING)
    assert s.exact and s.intervals == "exact"


def test_ecdf_is_exact_below_the_censoring_point(random_case):
    res, t, status = random_case
    d = study_statistics(res, None, sensitivity=False).critical_thrust
    full = stats.ecdf(_complete_sample(t, status))               # scipy, on the uncensored values
    grid = np.linspace(t.min() * 0.9, THRUST_MAX, 400)
    np.testing.assert_allclose(d.ecdf(grid), full.cdf.evaluate(grid), rtol=0, atol=1e-15)
    assert np.isnan(d.ecdf([THRUST_MAX * 1.0001, 1e9])).all()    # not known above the limit
    eps = math.sqrt(math.log(2 / 0.05) / (2 * d.n))              # DKW, Massart's constant
    assert d.band_halfwidth == pytest.approx(eps)
    lo, hi = d.band(grid)
    np.testing.assert_allclose(lo, np.clip(full.cdf.evaluate(grid) - eps, 0, 1))
    np.testing.assert_allclose(hi, np.clip(full.cdf.evaluate(grid) + eps, 0, 1))


def test_pointwise_band_is_clopper_pearson(random_case):
    res, t, status = random_case
    d = study_statistics(res, None, sensitivity=False).critical_thrust
    x = d.observed[::37]
    lo, hi = d.pointwise_band(x)
    for xi, a, b in zip(x, lo, hi):
        k = int(np.count_nonzero(_complete_sample(t, status) <= xi))
        ci = stats.binomtest(k, d.n).proportion_ci(0.95, method="exact")
        assert (a, b) == pytest.approx((ci.low, ci.high), rel=1e-9, abs=1e-14)


@pytest.mark.parametrize("k,n", [(0, 50), (1, 50), (17, 1024), (50, 50), (999, 1000)])
def test_clopper_pearson_against_binomtest_and_beta_quantiles(k, n):
    lo, hi = clopper_pearson(k, n, 0.9)
    ci = stats.binomtest(k, n).proportion_ci(confidence_level=0.9, method="exact")
    assert (float(lo), float(hi)) == pytest.approx((ci.low, ci.high), rel=1e-10, abs=1e-15)
    a = 0.1
    assert float(lo) == (0.0 if k == 0 else pytest.approx(stats.beta(k, n - k + 1).ppf(a / 2), rel=1e-10))
    assert float(hi) == (1.0 if k == n else pytest.approx(stats.beta(k + 1, n - k).ppf(1 - a / 2), rel=1e-10))


def test_probability_of_missing_the_margin(random_case):
    res, t, status = random_case
    ok = status == 0
    for target in (5.0, 7.5, THRUST_MAX / OPERATING):
        p = study_statistics(res, target, sensitivity=False).probability
        k = int(np.count_nonzero(t[ok] / OPERATING < target))    # the uncensored margins
        ci = stats.binomtest(k, int(ok.sum())).proportion_ci(0.95, method="exact")
        assert (p.below, p.n) == (k, ok.sum())
        assert p.estimate == pytest.approx(k / ok.sum())
        assert (p.low, p.high) == pytest.approx((ci.low, ci.high), rel=1e-9)
        assert p.exact and "Clopper-Pearson" in p.method
    assert study_statistics(res, 7.5, sensitivity=False).probability.below > 0


def test_a_target_above_the_search_limit_is_refused(random_case):
    res, _, _ = random_case
    with pytest.raises(ModelError, match="--target-margin.*thrust_max"):
        study_statistics(res, 10.5, sensitivity=False)


@pytest.mark.parametrize("quantity,scale", [("critical_thrust", 1.0), ("margin", 1.0 / OPERATING)])
def test_percentiles_flag_censoring(random_case, quantity, scale):
    res, t, status = random_case
    s = study_statistics(res, None, sensitivity=False, percents=(1, 5, 25, 50, 60, 80, 90, 99))
    d = getattr(s, quantity)
    true = _complete_sample(t, status) * scale
    n, limit = true.size, THRUST_MAX * scale
    f_limit = np.count_nonzero(true <= limit) / n
    assert 0.5 < f_limit < 0.95                                  # some percentiles lie above the limit
    seen_censored = False
    for q in s.percents:
        pc = d.percentile(q)
        k = math.ceil(q / 100 * n - 1e-9)                       # inverse ECDF: the k-th smallest value
        ci = stats.quantile_test(true, q=0, p=q / 100).confidence_interval(0.95)
        if q / 100 <= f_limit:
            assert not pc.censored and pc.value == pytest.approx(true[k - 1], rel=1e-12)
        else:
            seen_censored = True
            assert pc.censored and pc.value is None and pc.above == pytest.approx(limit)
            assert pc.text(units=False).startswith(">") and pc.text(units=False) == f"> {limit:.5g}"
        for end, above, ref in ((pc.low, pc.low_above, ci.low), (pc.high, pc.high_above, ci.high)):
            if ref <= limit:
                assert end == pytest.approx(ref, rel=1e-12) and above is None
            else:                                                # beyond the limit: never a number
                assert end is None and above == pytest.approx(limit)
    assert seen_censored


def test_histogram_counts_the_observed_values(random_case):
    res, t, status = random_case
    d = study_statistics(res, None, sensitivity=False).critical_thrust
    edges, counts = d.histogram()
    true = _complete_sample(t, status)
    np.testing.assert_array_equal(counts, np.histogram(true[true <= THRUST_MAX], bins=edges)[0])
    assert counts.sum() + d.censored == d.n and edges[-1] <= THRUST_MAX


def test_sobol_intervals_are_marked_approximate(tmp_path):
    res, _ = fake_result(tmp_path, "sobol", 256, lognormal_thrust)
    s = study_statistics(res, 7.0, sensitivity=False)
    assert not s.exact and s.intervals == "approximate" and not s.probability.exact
    assert "approximate" in s.probability.method and any("approximate" in n for n in s.notes)


def test_grid_study_is_refused(tmp_path):
    path = write_study(tmp_path, '[[parameters]]\npath = "mount_rings[0].x"\nvalues = [0.2, 0.3]\n')
    res = run_study(load_study(path), None)
    with pytest.raises(ModelError, match="grid is not a sample"):
        study_statistics(res)


# -- Sobol indices ----------------------------------------------------------------------------

A_ISH, B_ISH = 7.0, 0.1


def ishigami(x):
    """The Ishigami function of the three parameters mapped onto [-pi, pi] (indices are
    invariant under such a map), shifted to positive values below thrust_max."""
    z = np.column_stack([-np.pi + 2 * np.pi * (x[:, i] - lo) / (hi - lo) for i, (lo, hi) in enumerate(BOUNDS)])
    y = np.sin(z[:, 0]) + A_ISH * np.sin(z[:, 1]) ** 2 + B_ISH * z[:, 2] ** 4 * np.sin(z[:, 0])
    return 500.0 * (y + 12.0)               # 630 N to 14870 N


def ishigami_indices():
    """Closed form (Ishigami and Homma 1990; Sobol' 2001)."""
    a, b, pi = A_ISH, B_ISH, np.pi
    v1 = 0.5 * (1 + b * pi**4 / 5) ** 2
    v2 = a**2 / 8
    v13 = 8 * b**2 * pi**8 / 225
    v = v1 + v2 + v13                     # = a^2/8 + b pi^4/5 + b^2 pi^8/18 + 1/2
    assert v == pytest.approx(a**2 / 8 + b * pi**4 / 5 + b**2 * pi**8 / 18 + 0.5)
    return np.array([v1, v2, 0.0]) / v, np.array([v1 + v13, v2, v13]) / v


def test_ishigami_closed_form_values():
    s1, st = ishigami_indices()
    np.testing.assert_allclose(s1, [0.314, 0.442, 0.0], atol=6e-4)
    np.testing.assert_allclose(st, [0.558, 0.442, 0.244], atol=6e-4)


def test_saltelli_design_is_salibs(tmp_path):
    """The stored samples are SALib's cross-sampled design of the same seed, in SALib's order."""
    from SALib.sample import sobol as saltelli

    res, _ = fake_result(tmp_path, "saltelli", 64, ishigami, seed=5)
    x = np.column_stack([res.dataset[p].values for p in res.parameters])
    problem = {"num_vars": 3, "names": ["a", "b", "c"], "bounds": [list(b) for b in BOUNDS]}
    np.testing.assert_allclose(x, saltelli.sample(problem, 64, calc_second_order=False, seed=5), rtol=1e-12)
    assert res.dataset.attrs["sampling"] == "saltelli" and x.shape == (64 * 5, 3)


def test_sobol_indices_of_ishigami_from_a_saltelli_study(tmp_path):
    from SALib.analyze import sobol

    n = 4096
    res, y = fake_result(tmp_path, "saltelli", n, ishigami, seed=2)
    ind = sensitivity_indices(res)
    s1, st = ishigami_indices()
    assert ind.method == "saltelli" and ind.quantity == "margin" and not ind.capped and ind.of == "margin"
    assert ind.evaluations == n * 5 and ind.dropped == 0
    np.testing.assert_allclose(ind.first_order, s1, atol=0.03)
    np.testing.assert_allclose(ind.total_order, st, atol=0.03)
    assert np.all(np.abs(ind.first_order - s1) < 3 * ind.first_order_conf + 0.01)
    # SALib on the same outputs, directly
    problem = {"num_vars": 3, "names": list(res.parameters), "bounds": [list(b) for b in BOUNDS]}
    ref = sobol.analyze(problem, y / OPERATING, calc_second_order=False, num_resamples=200, seed=1)
    np.testing.assert_allclose(ind.first_order, ref["S1"], rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(ind.total_order, ref["ST"], rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(ind.first_order_conf, ref["S1_conf"], rtol=1e-12)
    # the statistics use only the rows of A and B for the distribution
    s = study_statistics(res, None)
    assert s.rows == 2 * n and s.computed == 2 * n and s.designs == 5 * n
    assert s.sensitivity.to_dict()["total_order"] == pytest.approx(list(ind.total_order))


def test_saltelli_failures_drop_whole_base_samples(tmp_path):
    n = 256
    status = np.zeros(5 * n, dtype=np.int8)
    status[[7, 12, 13]] = 1                 # rows of base samples 1 (7) and 2 (12, 13)
    res, _ = fake_result(tmp_path, "saltelli", n, ishigami, status=status)
    ind = sensitivity_indices(res)
    assert ind.dropped == 2 and ind.evaluations == (n - 2) * 5


def test_given_data_indices_of_ishigami(tmp_path):
    from SALib.analyze import rbd_fast

    res, y = fake_result(tmp_path, "random", 4096, ishigami, seed=4)
    ind = sensitivity_indices(res)
    s1, _ = ishigami_indices()
    assert ind.method == "rbd-fast" and ind.total_order is None
    np.testing.assert_allclose(ind.first_order, s1, atol=0.05)
    x = np.column_stack([res.dataset[p].values for p in res.parameters])
    problem = {"num_vars": 3, "names": list(res.parameters), "bounds": [list(b) for b in BOUNDS]}
    ref = rbd_fast.analyze(problem, x, y / OPERATING, M=10, num_resamples=200, seed=1)
    np.testing.assert_allclose(ind.first_order, ref["S1"], rtol=1e-12)
    np.testing.assert_allclose(ind.first_order_conf, ref["S1_conf"], rtol=1e-12)


def test_indices_of_a_censored_quantity_say_so(random_case):
    res, t, status = random_case
    ind = sensitivity_indices(res)
    limit = THRUST_MAX / OPERATING
    assert ind.capped and ind.cap == pytest.approx(limit) and ind.censored == np.count_nonzero((status == 0) & (t > THRUST_MAX))
    assert ind.of == f"min(margin, {limit:.4g})" and "not of the uncensored one" in ind.note
    from SALib.analyze import rbd_fast

    ok = status == 0
    x = np.column_stack([res.dataset[p].values for p in res.parameters])[ok]
    capped = np.minimum(t[ok], THRUST_MAX) / OPERATING           # the censored designs at their limit
    ref = rbd_fast.analyze({"num_vars": 3, "names": list("abc"), "bounds": [[0, 1]] * 3}, x, capped,
                           M=10, num_resamples=200, seed=1)
    np.testing.assert_allclose(ind.first_order, ref["S1"], rtol=1e-12)
    assert ind.dropped == 4 and ind.evaluations == ok.sum()


# -- best design ------------------------------------------------------------------------------

def test_best_flags_a_censored_design_and_the_tie(random_case):
    res, t, status = random_case
    ok = status == 0
    censored = int(np.count_nonzero(ok & (t > THRUST_MAX)))
    best = res.best("margin")
    assert best["lower_bound"] and best["value"] == pytest.approx(THRUST_MAX / OPERATING)
    assert best["tied"] == censored > 1
    assert "stable up to thrust_max: the true margin is larger than shown" in best["warning"]
    assert f"a tie: {censored} designs" in best["warning"]
    sel = res.best("margin", where=res.dataset["kind"] == 1)   # the designs that do go unstable
    assert not sel["lower_bound"] and sel["value"] == pytest.approx(t[ok & (t <= THRUST_MAX)].max() / OPERATING)
    assert sel["censored_left_out"] == censored and "largest of the selection only" in sel["warning"]
    worst = res.best("margin", minimum=True)
    assert worst["value"] == pytest.approx(t[ok].min() / OPERATING) and worst["warning"] is None


def test_best_without_censoring_has_no_warning(tmp_path):
    res, t = fake_result(tmp_path, "random", 50, lambda x: 5000.0 + x[:, 0] * 0.1)
    best = res.best("critical_thrust")
    assert best["value"] == pytest.approx(t.max()) and not best["lower_bound"] and best["warning"] is None


# -- the study file, the command line, the result object -------------------------------------

def test_saltelli_study_runs_and_gives_indices(tmp_path, capsys):
    body = THREE.format(method="saltelli", n=8, seed=1).replace(
        'values = { start = 1.0e4, stop = 3.0e4 }', 'distribution = { kind = "lognormal", median = 2.0e4, sigma = 0.2 }')
    path = write_study(tmp_path, body, chunk_size=16)
    study = load_study(path)
    assert study.size == 8 * 5 and study.method == "saltelli" and study.dims == ("sample",)
    assert main(["sweep", str(path), "-o", str(tmp_path / "s.zarr"), "--no-progress"]) == 0
    capsys.readouterr()
    res = open_study(tmp_path / "s.zarr")
    s = study_statistics(res, 1.5)
    assert s.sensitivity.method == "saltelli" and s.rows == 16 and s.designs == 40


def test_stats_command_table_json_and_figure(random_case, tmp_path, capsys):
    res, t, status = random_case
    res.to_netcdf(tmp_path / "r.nc")
    fig = tmp_path / "stats.png"
    assert main(["stats", str(tmp_path / "r.nc"), "--target-margin", "7.5", "-o", str(fig)]) == 0
    out = capsys.readouterr().out
    assert max(len(line) for line in out.splitlines()) <= 80
    assert "P(margin < 7.5)" in out and "> 20000" in out and "censored" in out
    assert fig.read_bytes()[:4] == b"\x89PNG" and fig.stat().st_size > 20_000
    assert main(["stats", str(tmp_path / "r.nc"), "--target-margin", "7.5", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    ok = status == 0
    k = int(np.count_nonzero(t[ok] / OPERATING < 7.5))
    assert data["probability"]["below"] == k and data["computed"] == ok.sum()
    assert data["failed"] == {"invalid": 3, "numerical_failure": 1, "error": 0}
    assert data["censored"] == np.count_nonzero(ok & (t > THRUST_MAX))
    assert data["critical_thrust"]["units"] == "N" and data["thrust_max"] == THRUST_MAX
    top = data["critical_thrust"]["percentiles"][-1]              # 99 %: above the limit
    assert top["value"] is None and top["above"] == THRUST_MAX
    assert data["sensitivity"]["capped"] and data["sensitivity"]["of"].startswith("min(margin")
    for svg in ("stats.svg", "stats.pdf"):
        assert main(["stats", str(tmp_path / "r.nc"), "--no-sensitivity", "-o", str(tmp_path / svg)]) == 0
        assert (tmp_path / svg).stat().st_size > 5_000


@pytest.mark.parametrize("args,field", [(["--target-margin", "11"], "--target-margin"),
                                        (["--target-margin", "-1"], "--target-margin"),
                                        (["-o", "x.txt"], "--output"), (["--confidence", "1.5"], "--confidence"),
                                        (["--dpi", "0"], "--dpi"), (["--dpi", "5000"], "--dpi")])
def test_stats_command_bad_input(random_case, tmp_path, capsys, args, field):
    res, _, _ = random_case
    res.to_netcdf(tmp_path / "r.nc")
    fig = tmp_path / "f.png"
    argv = ["stats", str(tmp_path / "r.nc"), *args]
    if "-o" not in args:
        argv += ["-o", str(fig)]
    assert main(argv) == 2
    assert field in capsys.readouterr().err
    assert not fig.exists() and not list(tmp_path.glob(".*part*"))


def test_default_target_is_left_out_when_the_search_ends_below_the_operating_thrust(tmp_path, capsys):
    res, _ = fake_result(tmp_path, "random", 200, lognormal_thrust, operating=25000.0)
    assert res.operating_thrust()[0] == 25000.0
    res.to_netcdf(tmp_path / "r.nc")
    assert main(["stats", str(tmp_path / "r.nc"), "--json", "--no-sensitivity"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["probability"] is None and data["margin"]["exact_up_to"] == pytest.approx(0.8)
    assert main(["stats", str(tmp_path / "r.nc"), "--target-margin", "1"]) == 2
    assert "--target-margin" in capsys.readouterr().err


def test_result_object_views(random_case):
    res, _, _ = random_case
    s = study_statistics(res, 7.5)
    text = repr(s)
    assert len(text) < 1200 and "P(margin < 7.5)" in text and "censored" in text
    html = s._repr_html_()
    assert html.count("<table") == 2 and "P(margin &lt; 7.5)" in html and "min(margin, 10)" in html
    ds = s.to_xarray()
    assert ds["critical_thrust_percentile"].attrs["units"] == "N"
    pct = ds["critical_thrust_percentile"].sel(percent=99.0)
    assert np.isnan(pct) and ds["critical_thrust_percentile_above"].sel(percent=99.0) == THRUST_MAX
    assert set(ds["parameter"].values) == set(res.parameters) and ds["first_order"].attrs["units"] == "1"
    axes = s.plot()
    assert axes.histogram is not None and axes.sensitivity is not None
    labels = axes.ecdf.get_legend_handles_labels()[1]
    assert any("DKW" in lab for lab in labels) and any("Clopper-Pearson" in lab for lab in labels)
    plt.close(axes.figure)
    _, ax = plt.subplots()
    assert s.plot(ax=ax) is ax
    assert s.sensitivity.plot() is not None and s.margin.plot() is not None
    plt.close("all")
