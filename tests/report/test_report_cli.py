"""``impstab report``: output, options, the command line in the provenance, bad input."""

from __future__ import annotations

import pytest

from impstab.cli import main

from _report_helpers import GRID_STUDY, copy_example, page_text, parse, run_study_file


def test_report_command_writes_one_page(tmp_path, capsys):
    model = copy_example(tmp_path, "imp_symmetric.toml")
    out = tmp_path / "out" / "sym.html"
    code = main(["report", str(model), "-o", str(out), "--sections", "stability,locus", "--title", "<T> & co"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert captured.out == f"wrote {out}: 3 sections (3 computed), 1 figures, 3 tables\n"
    html = out.read_text(encoding="utf-8")
    assert parse(html).sections == {"stability": "computed", "locus": "computed", "provenance": "computed"}
    text = page_text(html)
    assert f"impstab report {model} --output {out} --sections stability,locus --title '<T> & co'" in text
    assert "&lt;T&gt; &amp; co" in html and "<T>" not in html
    assert sorted(p.name for p in out.parent.iterdir()) == ["sym.html"]      # no temporary file left


def test_no_simulation_and_the_default_name(tmp_path, monkeypatch, capsys):
    model = copy_example(tmp_path, "imp_symmetric.toml")
    monkeypatch.chdir(tmp_path)
    assert main(["report", str(model), "--no-simulation", "--sections", "simulation"]) == 0
    out = capsys.readouterr().out
    assert ("\nsimulation: not computed: left out of this report: no time histories asked for (--no-simulation; "
            "simulation=False in Python)\n") in out
    html = (tmp_path / "imp_symmetric-report.html").read_text(encoding="utf-8")
    assert parse(html).sections["simulation"] == "not computed"
    assert "--no-simulation" in page_text(html)


def test_study_store_report(tmp_path, monkeypatch, capsys):
    run_study_file(tmp_path, GRID_STUDY.format(name="grid"))
    monkeypatch.chdir(tmp_path)
    assert main(["report", "study.zarr", "--sections", "status,best"]) == 0
    html = (tmp_path / "study-report.html").read_text(encoding="utf-8")
    assert parse(html).sections == {"status": "computed", "best": "computed", "provenance": "computed"}


@pytest.mark.parametrize("args,field", [
    (["-o", "r.pdf"], "--output"),
    (["--sections", "stability,maps"], "--sections"),
    (["--sections", " , "], "--sections"),
    (["--duration", "0"], "--duration"),
    (["--duration", "nan"], "--duration"),
    (["--steps", "0"], "--steps"),
    (["--target-margin", "-1"], "--target-margin"),
])
def test_bad_options_exit_2_with_one_line(tmp_path, capsys, args, field, monkeypatch):
    model = copy_example(tmp_path, "imp_symmetric.toml")
    monkeypatch.chdir(tmp_path)
    assert main(["report", str(model), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"impstab: error: {field} = ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["imp_symmetric.toml"]


def test_bad_inputs_exit_2(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "study.toml").write_text(GRID_STUDY.format(name="s"))
    (tmp_path / "broken.toml").write_text("schema_version = 1\nname = 'x'\n[body]\nmass = -1.0\n")
    for arg, words in (("missing.toml", "does not exist"), ("study.toml", "is a study file"),
                       ("broken.toml", "body"), (".", "STORE = '.'")):
        assert main(["report", arg]) == 2, arg
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and words in err, (arg, err)
    assert not list(tmp_path.glob("*.html"))
