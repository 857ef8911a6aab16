"""The report without a browser: sections, numbers checked by independent routes, escaping,
provenance, self-containedness, the study report and the hooks of the optional analyses."""

from __future__ import annotations

import datetime as dt
import hashlib
import json
import math
import os
import platform
import re
from pathlib import Path

import numpy as np
import pytest

import impstab
from impstab.errors import ModelError
from impstab.report import PROVIDERS, SECTION_NAMES

from _report_helpers import (EVIL_NAME, GRID_STUDY, RANDOM_STUDY, copy_example, page_text, parse, run_study_file,
                             table_rows, write_model)


# ------------------------------------------------------------------ fixtures (built once per module)
@pytest.fixture(scope="module")
def iso(tmp_path_factory):
    """The full report of the isolation example (every section that applies)."""
    folder = tmp_path_factory.mktemp("iso")
    model = copy_example(folder, "imp_isolation.toml")
    rep = impstab.report(model, folder / "iso.html")
    return rep, model, folder / "iso.html"


@pytest.fixture(scope="module")
def evil(tmp_path_factory):
    """The symmetric example renamed with markup, terminal escapes and mathtext."""
    folder = tmp_path_factory.mktemp("evil")
    text = (Path(copy_example(folder, "imp_symmetric.toml")).read_text(encoding="utf-8")
            .replace('name = "symmetric three-mount IMP"', f"name = {json.dumps(EVIL_NAME)}"))
    model = write_model(folder, "evil.toml", text)
    assert impstab.load_model(model).name == EVIL_NAME
    rep = impstab.report(model, folder / "evil.html", title="<b>bold</b> \x1b[1m title")
    return rep, model


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    folder = tmp_path_factory.mktemp("study")
    result = run_study_file(folder, GRID_STUDY.format(name="ring <i>grid</i>"))
    rep = impstab.report(folder / "study.zarr", folder / "study.html")
    return rep, result, folder / "study.zarr"


def _number(text: str) -> float:
    return float(re.match(r"\s*([-+0-9.e]+)", text).group(1))


# ------------------------------------------------------------------ the model report
def test_a_model_report_has_every_section(iso):
    rep, _, path = iso
    assert [s.name for s in rep.sections] == list(SECTION_NAMES["model"])
    status = {s.name: s.status for s in rep.sections}
    assert set(status.values()) == {"computed"}, status
    html = path.read_text(encoding="utf-8")
    assert html == rep.html
    assert parse(html).sections == {s.name: s.status for s in rep.sections}
    text = page_text(html)
    # the isolation example's onset: a simple pair with a near neighbour (2.6e-2 of |lambda| away),
    # a plain Hopf point, supercritical (l1 = -3.7e-6; docs/postcritical.md)
    assert "Post-critical behaviour" in text and "supercritical" in text


def test_the_page_is_self_contained(iso):
    rep, _, _ = iso
    page = parse(rep.html)
    tags = [t for t, _ in page.tags]
    assert "script" not in tags and "link" not in tags and "iframe" not in tags and "img" not in tags
    assert "object" not in tags and "embed" not in tags
    for tag, attrs in page.tags:
        for name, value in attrs.items():
            if name.startswith("xmlns") or value is None:
                continue
            assert "http:" not in value and "https:" not in value and "//" not in value.split("data:")[0], (tag, name)
            if name in ("href", "xlink:href", "src"):
                assert value.startswith(("#", "data:image/png;base64,")), (tag, name, value[:40])
    assert not re.search(r"url\((?!#)", rep.html), "only references inside the page"
    assert "@import" not in rep.html
    csp = [a["content"] for t, a in page.tags if t == "meta" and a.get("http-equiv") == "Content-Security-Policy"]
    assert csp and csp[0].startswith("default-src 'none'")
    # one id space for all figures: every id once, every reference to an id that exists
    assert len(page.ids) == len(set(page.ids))
    refs = set(re.findall(r'url\(#([^)]+)\)', rep.html)) | set(re.findall(r'href="#([^"]+)"', rep.html))
    assert refs <= set(page.ids)


def test_every_figure_and_table_is_in_the_page_and_not_empty(iso):
    rep, _, _ = iso
    svgs = re.findall(r"<svg\b.*?</svg>", rep.html, re.S)
    assert len(svgs) == rep.figures == 5       # with the post-critical diagram
    for svg in svgs:
        assert len(re.findall(r"<path\b", svg)) > 20 and "<text" in svg
    tables = re.findall(r"<table\b.*?</table>", rep.html, re.S)
    assert len(tables) == rep.tables >= 12
    for t in tables:
        assert re.search(r"<tbody><tr>.*?<td", t, re.S)


def test_print_layout_is_a4_with_a_page_per_section(iso):
    css = iso[0].html
    assert re.search(r"@page\s*{\s*size:\s*A4", css)
    assert re.search(r"@media print\s*{.*\.report-section\s*{[^}]*break-before:\s*page", css, re.S)


def test_static_loads_balance_the_thrust(iso):
    """Three identical axial mounts on a ring around the thrust line share the operating thrust:
    each carries T/3 and deflects T / (3 k_axial) (the forces on the hull sum to the thrust)."""
    rep, _, _ = iso
    rows = table_rows(rep.html, "static mount deflection and load at the operating thrust")
    assert len(rows) == 3
    thrust, k_axial = 2000.0, 1.0e5
    axial_force = [_number(r[4]) for r in rows]
    assert sum(axial_force) == pytest.approx(thrust, rel=1e-4)
    for r in rows:
        assert _number(r[4]) == pytest.approx(thrust / 3, rel=1e-4)
        assert _number(r[3]) == pytest.approx(1e3 * thrust / (3 * k_axial), rel=1e-3)   # |d| (mm)
        # use: the larger of |F| / rated_force (1000 N) and |d| / max_deflection (8 mm)
        assert r[7] == f"{100 * max(thrust / 3 / 1000.0, thrust / (3 * k_axial) / 0.008):.0f}"


def test_decoupling_rows_sum_to_100_and_frequencies_match_numpy(iso):
    rep, model_path, _ = iso
    model = impstab.load_model(model_path)
    lam = np.linalg.eigvals(impstab.linearize(model, 2000.0).state_matrix())
    f = np.sort(np.abs(lam.imag[lam.imag > 0]) / (2 * np.pi))
    rows = table_rows(rep.html, "decoupling table")
    assert len(rows) == 6
    for r in rows:
        assert sum(float(c) for c in r[2:]) == pytest.approx(100.0, abs=0.35)
        assert "-0.0" not in r
    assert [_number(r[1]) for r in rows] == pytest.approx(f, rel=1e-5)


def test_time_histories_straddle_the_onset(iso):
    """The three runs sit below, at and above the critical thrust: max Re(lambda) of the state
    matrix (numpy) is negative, zero and positive there, and the default length lets the
    supercritical run grow by e^3 (within 40 to 400 periods)."""
    rep, model_path, _ = iso
    model = impstab.load_model(model_path)
    crit = rep.section("stability").data["critical"]
    runs = rep.section("simulation").data["runs"]
    assert [r.classification for r in runs] == ["subcritical", "critical", "supercritical"]
    rates = [float(np.linalg.eigvals(impstab.linearize(model, r.thrust[0]).state_matrix()).real.max()) for r in runs]
    assert rates[0] < 0 < rates[2] and abs(rates[1]) < 1e-6
    assert [r.thrust[0] for r in runs] == pytest.approx([0.9 * crit.thrust, crit.thrust, 1.05 * crit.thrust])
    f = crit.frequency_hz
    expected = min(max(3.0 / rates[2], 40 / f), 400 / f)
    assert runs[0].duration == pytest.approx(expected, rel=1e-6)
    rows = table_rows(rep.html, "runs")
    assert _number(rows[0][4]) == pytest.approx(rates[0], rel=1e-3)
    assert _number(rows[2][4]) == pytest.approx(rates[2], rel=1e-3)


def test_transmissibility_band_and_isolation_frequency(iso):
    rep, model_path, _ = iso
    model = impstab.load_model(model_path)
    lam = np.linalg.eigvals(impstab.linearize(model, 2000.0).state_matrix())
    f = np.abs(lam.imag[lam.imag > 0]) / (2 * np.pi)
    data = rep.section("isolation").data
    res, ex = data["transmissibility"], data["excitation"]
    lines = ex.frequency_hz
    assert res.frequency_hz[0] == pytest.approx(f.min() / 4, rel=1e-6)
    assert res.frequency_hz[-1] == pytest.approx(max(10 * f.max(), 1.25 * lines.max()), rel=1e-6)
    onset = res.isolation_frequency_hz()
    from impstab.response import frequency_response

    near = frequency_response(model, [onset * 0.995, onset * 1.005]).transmissibility
    assert near[0] > 1 > near[1]
    assert np.all(res.transmissibility[res.frequency_hz > onset * 1.005] < 1)
    text = page_text(rep.html)
    assert "hull force in one-third-octave bands" in text and "blade_rate[0]" in text


def test_critical_thrust_against_an_eigenvalue_bisection(tmp_path):
    """Classical linearization of the undamped symmetric layout: K(T) = K0 + T K1 exactly, and
    flutter starts where the eigenvalues of M^-1 K(T) first leave the real axis (bisection)."""
    text = copy_example(tmp_path, "imp_symmetric.toml").read_text(encoding="utf-8")
    path = write_model(tmp_path, "classical.toml", text.replace('linearization = "equilibrium"',
                                                                'linearization = "classical"'))
    rep = impstab.report(path, sections=["stability"])
    model = impstab.load_model(path)
    k0, k1 = impstab.linearize(model, 0.0).K, impstab.linearize(model, 1.0).K - impstab.linearize(model, 0.0).K
    m_inv = np.linalg.inv(impstab.linearize(model, 0.0).M)

    def complex_pair(t):
        s = np.linalg.eigvals(m_inv @ (k0 + t * k1))
        return np.abs(s.imag).max() > 1e-9 * np.abs(s).max()

    lo, hi = 0.0, 20000.0
    assert not complex_pair(lo) and complex_pair(hi)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if complex_pair(mid) else (mid, hi)
    row = dict(table_rows(rep.html, "critical thrust of"))
    assert _number(row["critical thrust"]) == pytest.approx(hi, rel=1e-6)
    assert row["margin (critical / operating)"] == f"{hi / 2000.0:.4g}"
    assert "no dampers" in page_text(rep.html)


def test_damping_destabilisation_is_stated(iso):
    rep, _, _ = iso
    crit = rep.section("stability").data["critical"]
    assert crit.thrust < crit.undamped_thrust
    change = 100 * (crit.thrust - crit.undamped_thrust) / crit.undamped_thrust
    assert f"Damping lowers the critical thrust from {crit.undamped_thrust:.6g} N" in page_text(rep.html)
    assert f"{change:+.1f} % (destabilisation by damping" in page_text(rep.html)


# ------------------------------------------------------------------ escaping and provenance
def test_user_strings_are_escaped_everywhere(evil):
    rep, _ = evil
    html = rep.html
    assert "<script" not in html.lower()
    assert "<b>bold" not in html
    for ch in ("\x1b", "\u202e"):
        assert ch not in html
    assert "&lt;script&gt;alert(" in html
    assert "\\x1b[31mred\\x1b[0m" in html and "\\u202eevil" in html
    assert "&lt;b&gt;bold&lt;/b&gt; \\x1b[1m title" in html
    assert [s.name for s in rep.sections if s.status == "failed"] == []
    # the figures carry the name as text, escaped, and the dollar signs as they are (no mathtext)
    svgs = re.findall(r"<svg\b.*?</svg>", html, re.S)
    assert len(svgs) == 4                        # with the post-critical diagram
    titled = [s for s in svgs if "&lt;script&gt;" in s]
    assert len(titled) >= 2 and all("$x^2$" in s for s in titled)


def test_provenance_hash_is_hashlibs_and_the_date_is_utc(iso):
    rep, model, _ = iso
    prov = rep.provenance
    assert prov.sha256 == hashlib.sha256(Path(model).read_bytes()).hexdigest()
    assert prov.input_kind == "model file"
    when = dt.datetime.strptime(prov.generated_utc, "%Y-%m-%d %H:%M:%S UTC").replace(tzinfo=dt.timezone.utc)
    assert abs((dt.datetime.now(dt.timezone.utc) - when).total_seconds()) < 3600
    text = page_text(rep.html)
    assert prov.sha256 in text and prov.generated_utc in text
    assert f"numpy version {np.__version__}" in text and f"Python version {platform.python_version()}" in text
    assert f"impstab version {impstab.__version__}" in text
    assert "Python: impstab.report(" in text


def test_store_digest_follows_its_definition(study):
    """SHA-256 over 'relative path NUL sha256(file) LF' of every file, sorted by path."""
    rep, _, store = study
    lines = []
    for dirpath, _, files in os.walk(store):
        for name in files:
            p = Path(dirpath) / name
            rel = p.relative_to(store).as_posix()
            lines.append((rel, hashlib.sha256(p.read_bytes()).hexdigest()))
    digest = hashlib.sha256(b"".join(r.encode() + b"\0" + h.encode() + b"\n" for r, h in sorted(lines))).hexdigest()
    assert rep.provenance.sha256 == digest and rep.provenance.input_kind == "study store"
    from impstab.report.provenance import tree_sha256

    (store / "extra").write_bytes(b"x")
    try:
        assert tree_sha256(store) != digest
    finally:
        (store / "extra").unlink()


# ------------------------------------------------------------------ the study report
def test_a_study_report(study):
    rep, result, _ = study
    ds = result.dataset
    assert [s.name for s in rep.sections] == list(SECTION_NAMES["study"])
    status = {s.name: s.status for s in rep.sections}
    assert status.pop("statistics") == "not computed" and "grid" in rep.section("statistics").reason
    assert set(status.values()) == {"computed"}
    counts = dict(table_rows(rep.html, "designs by status"))
    assert counts["ok"].startswith(f"{int(np.count_nonzero(ds['status'].values == 0))} (")
    kinds = {r[0]: int(r[2]) for r in table_rows(rep.html, "computed designs by kind of onset")}
    assert kinds == {k: int(np.count_nonzero(ds["kind"].values == c)) for k, c in
                     (("flutter", 1), ("divergence", 2), ("none", 0))}
    assert len(rep.section("maps").figures) == 2
    assert "&lt;i&gt;grid&lt;/i&gt;" in rep.html and "<i>grid" not in rep.html


def test_best_designs_say_when_they_are_censored(study):
    rep, result, _ = study
    ds = result.dataset
    censored = int(np.count_nonzero(ds["kind"].values == 0))
    assert censored > 0, "the grid must hold designs stable up to thrust_max"
    rows = table_rows(rep.html, "best designs by margin")
    best = {r[0]: r for r in rows}
    top = best["largest, all designs"]
    limit = 20000.0 / 2000.0
    assert top[1] == f">= {limit:g}" and "stable up to thrust_max: the true margin is larger than shown" in top[3]
    found = best["largest with an onset found within the search"]
    margins = ds["margin"].values[ds["kind"].values != 0]
    assert _number(found[1]) == pytest.approx(np.nanmax(margins), rel=1e-3)
    assert f"{censored} designs left out by the selection are stable up to thrust_max" in found[3]
    worst = best["smallest (the worst design)"]
    assert _number(worst[1]) == pytest.approx(np.nanmin(ds["margin"].values), rel=1e-3)


# ------------------------------------------------------------------ hooks of the optional analyses
class FakePostcritical:
    """A post-critical result with the JSON keys of DESIGN.md."""

    def to_dict(self):
        return {"critical_thrust": 18012.1, "kind": "flutter", "omega": 24.1, "lyapunov_coefficient": 0.0123,
                "bifurcation": "subcritical", "fold_thrust": 17500.5,
                "branch": {"thrust": [18012.1, 17800.0, 17500.5, 17900.0], "period": [0.26, 0.27, 0.28, 0.29],
                           "stable": [False, False, True, True],
                           "amplitude": {n: [0.0, 0.001, 0.002, 0.003] for n in impstab.DOF_NAMES}}}

    def plot(self, ax=None):
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        b = self.to_dict()["branch"]
        ax.plot(b["thrust"], b["amplitude"]["sway"])
        return ax


def fake_postcritical(model):
    return FakePostcritical()


def failing_postcritical(model):
    raise RuntimeError("continuation stopped: <no cycle>")


def test_postcritical_section_from_a_result(tmp_path):
    path = copy_example(tmp_path, "imp_symmetric.toml")
    rep = impstab.report(path, sections=["postcritical"], postcritical=FakePostcritical())
    sec = rep.section("postcritical")
    assert sec.status == "computed" and len(sec.figures) == 1
    rows = dict(table_rows(rep.html, "Hopf analysis at the onset"))
    assert rows["bifurcation"] == "subcritical" and rows["fold of cycles"] == "17500.5 N"
    assert rows["first Lyapunov coefficient l1"] == "0.0123"
    assert "dangerous" in page_text(rep.html)


def test_postcritical_provider_hook(tmp_path, monkeypatch):
    path = copy_example(tmp_path, "imp_symmetric.toml")
    monkeypatch.setitem(PROVIDERS, "postcritical", f"{__name__}:fake_postcritical")
    assert impstab.report(path, sections=["postcritical"]).section("postcritical").status == "computed"
    monkeypatch.setitem(PROVIDERS, "postcritical", f"{__name__}:failing_postcritical")
    rep = impstab.report(path, sections=["stability", "postcritical"])
    sec = rep.section("postcritical")
    assert sec.status == "failed" and "RuntimeError: continuation stopped" in sec.reason
    assert rep.section("stability").status == "computed"
    assert "continuation stopped: &lt;no cycle&gt;" in rep.html
    monkeypatch.setitem(PROVIDERS, "postcritical", "impstab.no_such_module:analysis")
    sec = impstab.report(path, sections=["postcritical"]).section("postcritical")
    assert sec.status == "not computed" and "impstab.no_such_module.analysis" in sec.reason


class FakeStatistics:
    def summary_rows(self):
        return [("censored at thrust_max", "3 of 12 (25 %)"), ("P(margin < 8)", "0.42 [0.15, 0.72]")]

    def plot(self, ax=None):
        import matplotlib.pyplot as plt

        _, ax = plt.subplots()
        ax.hist([1.0, 2.0, 2.5])
        return ax


def fake_statistics(result, target_margin):
    assert result.dataset.attrs["sampling"] == "random"
    return FakeStatistics()


def test_statistics_hook_on_a_sampled_study(tmp_path, monkeypatch):
    result = run_study_file(tmp_path, RANDOM_STUDY)
    monkeypatch.setitem(PROVIDERS, "statistics", f"{__name__}:fake_statistics")
    rep = impstab.report(result, sections=["statistics"])
    sec = rep.section("statistics")
    assert sec.status == "computed" and len(sec.figures) == 1
    assert dict(table_rows(rep.html, "uncertainty statistics"))["censored at thrust_max"] == "3 of 12 (25 %)"
    monkeypatch.setitem(PROVIDERS, "statistics", "impstab.studies.no_such_statistics:study_statistics")
    sec = impstab.report(result, sections=["statistics"]).section("statistics")
    assert sec.status == "not computed" and "no uncertainty statistics" in sec.reason
    assert impstab.report(result, sections=["statistics"], statistics=FakeStatistics()).section(
        "statistics").status == "computed"


# ------------------------------------------------------------------ the API object and bad input
def test_report_object(iso, tmp_path):
    rep, _, _ = iso
    assert re.match(r"Report\('isolated three-mount IMP: stability report': model report, 9 sections "
                    r"\(9 computed\), 5 figures, \d+ tables, \d+ kB\)", repr(rep))
    frame = rep._repr_html_()
    assert frame.startswith('<iframe title="isolated three-mount IMP: stability report" sandbox=""')
    assert "<svg" not in frame and "&lt;svg" in frame
    out = rep.save(tmp_path / "copy.html")
    assert out.read_text(encoding="utf-8") == rep.html
    assert sorted(p.name for p in tmp_path.iterdir()) == ["copy.html"]
    with pytest.raises(ModelError, match="must end in .html"):
        rep.save(tmp_path / "copy.pdf")
    with pytest.raises(ModelError, match="section = 'maps'"):
        rep.section("maps")
    with pytest.raises(ModelError, match="sections = 'maps': must be among the model report's sections"):
        impstab.report(rep.provenance.input, sections=["locus", "maps"])


def test_a_model_without_operating_thrust(tmp_path):
    text = copy_example(tmp_path, "imp_symmetric.toml").read_text(encoding="utf-8")
    path = write_model(tmp_path, "free.toml", text.replace("operating = 2000.0            # N, design thrust\n", ""))
    rep = impstab.report(path, sections=["static", "stability", "modes"])
    sec = rep.section("static")
    assert sec.status == "not computed" and "thrust.operating" in sec.reason
    assert "Modes and decoupling at zero thrust" in page_text(rep.html)
    assert dict(table_rows(rep.html, "critical thrust of"))["margin (critical / operating)"] == "needs an operating thrust"


def test_bad_input_names_the_field(tmp_path):
    path = copy_example(tmp_path, "imp_symmetric.toml")
    with pytest.raises(ModelError, match="MODEL_OR_STORE .*does not exist"):
        impstab.report(tmp_path / "missing.toml")
    (tmp_path / "notes.txt").write_text("x")
    with pytest.raises(ModelError, match="must be a model file"):
        impstab.report(tmp_path / "notes.txt")
    with pytest.raises(ModelError, match="duration"):
        impstab.report(path, duration=math.nan)
    with pytest.raises(ModelError, match="steps"):
        impstab.report(path, steps=0)
    (tmp_path / "study.toml").write_text(GRID_STUDY.format(name="s"))
    with pytest.raises(ModelError, match="is a study file"):
        impstab.report(tmp_path / "study.toml")


def test_time_histories_of_a_compressible_fluid_model_say_what_they_cannot_show(tmp_path):
    """The time simulation takes the fluid at 0 Hz (no radiation damping): above the critical
    thrust set by radiation damping its linearization (numpy) is still neutral, and the report says so."""
    path = copy_example(tmp_path, "imp_fluid.toml")
    rep = impstab.report(path, sections=["simulation"])
    runs = rep.section("simulation").data["runs"]
    model = impstab.load_model(path)
    lam = np.linalg.eigvals(impstab.linearize(model, runs[-1].thrust[0]).state_matrix())
    assert abs(lam.real.max()) <= 1e-10 * np.abs(lam).max()
    text = page_text(rep.html)
    assert "the run above the critical thrust does not grow" in text
    assert "without the radiation damping" in text


def test_the_package_is_the_function():
    import impstab.report as module
    from impstab import report

    assert report is module is impstab.report
    assert callable(module) and module.report.__module__ == "impstab.report.api"


def test_statistics_of_a_sampled_study(tmp_path):
    """The statistics section of a random study, with the probability of missing the required
    margin counted again from the stored margins (censored designs are above every target)."""
    result = run_study_file(tmp_path, RANDOM_STUDY)
    rep = impstab.report(result, sections=["statistics", "best"], target_margin=8.0)
    sec = rep.section("statistics")
    assert sec.status == "computed" and len(sec.figures) == 1
    margin = result.dataset["margin"].values
    ok = result.dataset["status"].values == 0
    below = int(np.count_nonzero(ok & (margin < 8.0)))
    rows = dict(table_rows(rep.html, "uncertainty statistics"))
    assert f"({below} of {int(ok.sum())})" in rows["P(margin < 8)"]
    assert "percentiles with their 95 % intervals" in rep.html
    assert "sensitivity indices not computed: STORE = '12 computed designs': too few" in page_text(rep.html)
    assert rep.section("best").status == "computed"


def test_a_divergence_onset_has_no_time_histories(tmp_path):
    """A fixed-direction thrust buckles the layout: a divergence, where the straight pose is still an
    exact equilibrium with a singular stiffness (found to rounding), and past which a real
    eigenvalue grows (no oscillation)."""
    text = copy_example(tmp_path, "imp_symmetric.toml").read_text(encoding="utf-8")
    path = write_model(tmp_path, "fixed.toml", text.replace("tangency = 1.0 ", "tangency = 0.0 "))
    rep = impstab.report(path, sections=["stability", "simulation"])
    crit = rep.section("stability").data["critical"]
    assert crit.kind == "divergence"
    model = impstab.load_model(path)
    at = impstab.linearize(model, crit.thrust)
    assert np.abs(at.displacement[1:]).max() < 1e-12 and np.abs(at.rotation - np.eye(3)).max() < 1e-12
    s = np.abs(np.linalg.eigvals(np.linalg.solve(at.M, at.K)))
    assert np.sort(s)[0] <= 1e-12 * s.max()  # the buckling: a zero stiffness eigenvalue
    lam = np.linalg.eigvals(impstab.linearize(model, 1.05 * crit.thrust).state_matrix())
    growing = lam[lam.real > 1e-6 * np.abs(lam).max()]
    assert growing.size and np.all(np.abs(growing.imag) < 1e-9 * np.abs(lam).max())
    sec = rep.section("simulation")
    assert sec.status == "not computed" and "divergence" in sec.reason


def test_a_failed_section_keeps_its_title_and_the_others(tmp_path, monkeypatch):
    from impstab.report.sections import MODEL_SECTIONS

    def broken(ctx):
        raise ValueError("broken <b>")

    monkeypatch.setitem(MODEL_SECTIONS, "locus", broken)
    rep = impstab.report(copy_example(tmp_path, "imp_symmetric.toml"), sections=["stability", "locus"])
    sec = rep.section("locus")
    assert (sec.status, sec.title, sec.reason) == ("failed", "Eigenvalue loci", "ValueError: broken <b>")
    assert rep.section("stability").status == "computed"
    assert "Failed:</strong> ValueError: broken &lt;b&gt;" in rep.html
