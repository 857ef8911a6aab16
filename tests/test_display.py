"""Notebook and terminal views: concise reprs without array dumps, HTML tables that parse and
escape user strings, terminal tables that fit 80 columns as plain text, no "-0" anywhere."""

import html.parser
import re
from pathlib import Path

import numpy as np
import pytest

import impstab
from impstab.cli import main
from impstab.display.format import number
from impstab.model import model_from_dict
from impstab.studies import load_study, run_study

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
NEG_ZERO = re.compile(r"(?<![\w.])-0(\.0*)?(?![\d.eE]*[1-9])(?!\w)")


@pytest.fixture(scope="module")
def objects(tmp_path_factory):
    model = impstab.load_model(EXAMPLES / "imp_damped.toml")
    folder = tmp_path_factory.mktemp("study")
    (folder / "m.toml").write_text((EXAMPLES / "imp_symmetric.toml").read_text())
    (folder / "s.toml").write_text('schema_version = 1\nmodel = "m.toml"\n[[parameters]]\npath = "mount_rings[0].x"\n'
                                   'values = [0.1, 0.3]\n')
    study = load_study(folder / "s.toml")
    from impstab.linear.batch import critical_thrust_batch  # noqa: F401  (the batch API is public)

    out = {
        "model": model, "body": model.body, "mount": model.mounts[0], "thrust": model.thrust,
        "fluid": impstab.load_model(EXAMPLES / "imp_fluid.toml").fluid,
        "hull": impstab.load_model(EXAMPLES / "imp_fluid.toml").hull,
        "linear": impstab.linearize(model, 5000.0), "modes": impstab.modes(model, 5000.0),
        "critical": impstab.critical_thrust(model), "locus": impstab.locus(model, steps=20, critical=True),
        "simulation": impstab.simulate(model, thrust=5000.0, duration=0.3, critical_thrust=False),
        "study": run_study(study, None), "study_file": study, "parameter": study.parameters[0],
        "coefficients": impstab.fluid.baffled_cylinder(0.15, 0.8, 1025.0, 1500.0, 3.0),
        "sweep": impstab.fluid.frequency_sweep(0.15, 0.8, [0.0, 10.0], 1025.0),
    }
    return out


def test_every_repr_is_one_short_line_without_arrays(objects):
    for name, obj in objects.items():
        text = repr(obj)
        assert "\n" not in text and len(text) < 260, (name, text)
        assert "array(" not in text and "[[" not in text, (name, text)
        assert not NEG_ZERO.search(text), (name, text)
    assert len(repr(objects["model"])) < 200  # it used to print 2,786 characters


def test_reprs_say_what_matters(objects):
    assert repr(objects["critical"]).startswith("CriticalThrust('damped three-mount IMP': flutter at 16291.3 N")
    assert "undamped 18000 N" in repr(objects["critical"])
    assert repr(objects["model"]) == ("Model('damped three-mount IMP': 100 kg, 3 mounts, operating 2000 N, "
                                      "thrust_max 20000 N, propeller 150 rad/s, damped, equilibrium)")
    assert "2 designs, ok 2" in repr(objects["study"])


class _Checker(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.stack, self.tags = [], []

    def handle_starttag(self, tag, attrs):
        self.stack.append(tag)
        self.tags.append(tag)

    def handle_endtag(self, tag):
        assert self.stack and self.stack.pop() == tag, tag


@pytest.mark.parametrize("name", ["model", "modes", "critical", "locus", "simulation", "study"])
def test_html_tables_are_well_formed(objects, name):
    text = objects[name]._repr_html_()
    checker = _Checker()
    checker.feed(text)
    assert checker.stack == [] and "table" in checker.tags and "td" in checker.tags
    assert "<script" not in text and "http" not in text


def test_html_escapes_user_strings():
    from conftest import ring_model_dict

    model = model_from_dict(ring_model_dict(name="<script>alert(1)</script> & co"))
    text = model._repr_html_() + impstab.critical_thrust(model)._repr_html_()
    assert "<script>" not in text and "&lt;script&gt;" in text


def test_batch_result_views():
    from conftest import ring_model_dict
    from impstab.linear.batch import critical_thrust_batch

    models = [model_from_dict(ring_model_dict()), model_from_dict(ring_model_dict(analysis={"thrust_max": 1000.0}))]
    res = critical_thrust_batch(models)
    text = repr(res)
    assert text.startswith("BatchCriticalThrust(2 designs: none 1, flutter 1, failed 0")
    assert "<table" in res._repr_html_()


@pytest.mark.parametrize("value,digits,text", [(-0.0, 4, "0"), (-1e-20, 3, "-1e-20"), (-0.0004, 2, "-0.0004"),
                                               (None, 4, "n/a"), (float("nan"), 4, "n/a"), (2.5, 3, "2.5")])
def test_number_format_never_prints_minus_zero(value, digits, text):
    assert number(value, digits) == text
    assert number(-0.00001, 2, fmt="f") == "0.00"


@pytest.mark.parametrize("args", [
    ("check", "imp_damped.toml"), ("check", "imp_fluid.toml"), ("critical", "imp_damped.toml"),
    ("critical", "imp_asymmetric.toml", "--all-crossings"), ("modes", "imp_symmetric.toml", "--thrust", "5000"),
    ("modes", "imp_damped.toml", "--thrust", "17000"), ("simulate", "imp_symmetric.toml", "--thrusts",
                                                        "15000,18012.1,19000", "--duration", "2", "--no-plot", "-o", "OUT"),
])
def test_tables_fit_80_columns_as_plain_text(args, capsys, monkeypatch, tmp_path):
    monkeypatch.setenv("COLUMNS", "80")
    argv = [str(EXAMPLES / a) if a.endswith(".toml") else str(tmp_path / "o.nc") if a == "OUT" else a for a in args]
    assert main(argv) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert max(len(line) for line in lines) <= 80, max(lines, key=len)
    assert not re.search("[\u2500-\u257f]", out)  # no box-drawing characters when piped
    assert "\x1b[" not in out                     # no colour codes
    assert not NEG_ZERO.search(out), NEG_ZERO.search(out)
    assert not re.search(r"(?<=\s)-(?=\s|$)", out), "a bare dash"
