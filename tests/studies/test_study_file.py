"""Study files: schema, parameter paths, sampling, chunk plans; bad files give one clear line."""

import numpy as np
import pytest
from _study_helpers import GRID_6x5, write_study

from impstab.cli import main
from impstab.errors import ModelError
from impstab.studies import load_study
from impstab.studies.paths import resolve_path, set_values
from impstab.studies.plan import chunk_shape, plan_chunks


def test_grid_study_is_read_and_checked(tmp_path):
    study = load_study(write_study(tmp_path, GRID_6x5))
    assert study.method == "grid"
    assert study.dims == ("mount_rings[0].x", "mount_rings[0].k_shear")
    assert study.shape == (6, 5) and study.size == 30
    assert study.outputs == ("critical_thrust", "kind", "frequency_hz", "margin", "undamped_critical_thrust")
    k = study.parameters[1].values
    np.testing.assert_allclose(k[1:] / k[:-1], (10.0) ** 0.25, rtol=1e-12)
    np.testing.assert_allclose(study.parameters[0].values, np.linspace(0.1, 0.4, 6))
    # comments and layout do not change the study
    again = write_study(tmp_path, "# same study\n" + GRID_6x5, name="again.toml")
    assert load_study(again).fingerprint == study.fingerprint


def test_integer_word_and_flag_parameters(tmp_path):
    body = """
[[parameters]]
path = "mount_rings[0].count"
values = { start = 3, stop = 6, num = 4 }
[[parameters]]
path = "analysis.linearization"
values = ["equilibrium", "classical"]
[[parameters]]
path = "thrust.preload_stiffness"
values = [true, false]
"""
    study = load_study(write_study(tmp_path, body))
    assert study.parameters[0].values.tolist() == [3, 4, 5, 6]
    assert study.parameters[0].values.dtype.kind == "i"
    assert study.parameters[1].values.tolist() == ["equilibrium", "classical"]
    assert study.parameters[2].values.tolist() == [True, False]


@pytest.mark.parametrize("method", ["random", "sobol"])
def test_random_and_sobol_samples_are_reproducible(tmp_path, method):
    body = f"""
[[parameters]]
path = "mount_rings[0].k_shear"
distribution = {{ kind = "lognormal", median = 2e4, sigma = 0.2 }}
[[parameters]]
path = "mount_rings[0].x"
values = {{ start = 0.2, stop = 0.4 }}
[[parameters]]
path = "mount_rings[0].k_axial"
distribution = {{ kind = "truncnormal", mean = 1e5, std = 3e4, low = 5e4, high = 1.5e5 }}
[[parameters]]
path = "mount_rings[0].count"
values = [3, 4, 6]
[sampling]
method = "{method}"
n = 256
seed = 7
"""
    path = write_study(tmp_path, body)
    a, b = load_study(path), load_study(path)
    assert a.dims == ("sample",) and a.shape == (256,)
    for pa, pb in zip(a.parameters, b.parameters):
        np.testing.assert_array_equal(pa.values, pb.values)
    k_sh, x, k_ax, count = (p.values for p in a.parameters)
    assert np.all((x >= 0.2) & (x <= 0.4)) and np.all((k_ax >= 5e4) & (k_ax <= 1.5e5))
    assert abs(np.median(np.log(k_sh)) - np.log(2e4)) < 0.05
    assert set(count.tolist()) == {3, 4, 6}
    other = write_study(tmp_path, body.replace("seed = 7", "seed = 8"), name="other.toml")
    assert not np.array_equal(load_study(other).parameters[0].values, k_sh)


def test_set_values_copies_only_the_paths(tmp_path):
    base = {"mount_rings": [{"x": 0.3, "k_shear": 1.0}], "thrust": {"operating": 1.0}}
    full = {"schema_version": 1, "body": {"mass": 1.0, "inertia": [1.0, 1.0, 1.0]}, **base}
    paths = [resolve_path("mount_rings[0].x", full), resolve_path("propeller.speed", full)]
    new = set_values(full, paths, [0.1, 5.0])
    assert new["mount_rings"][0]["x"] == 0.1 and new["propeller"] == {"speed": 5.0}
    assert full["mount_rings"][0]["x"] == 0.3 and "propeller" not in full
    assert new["thrust"] is full["thrust"]  # untouched branches are shared


def test_chunk_plan_covers_every_design_once(tmp_path):
    assert chunk_shape((60, 60), 1024) == (17, 60)
    assert chunk_shape((7, 5, 3), 8) == (1, 2, 3)
    study = load_study(write_study(tmp_path, GRID_6x5, chunk_size=7))
    plan = plan_chunks(study)
    seen = np.zeros(study.shape, dtype=int)
    for i in range(plan.n_chunks):
        seen[plan.slices(i)] += 1
        assert np.prod(plan.block_shape(i)) <= 7
        cols = plan.design_columns(study, i)
        assert len(cols[0]) == np.prod(plan.block_shape(i))
    assert np.all(seen == 1)


BAD = [
    ("sampleing = 1", "", "sampleing", "unknown key"),
    ("", 'path = "mount_rings[0].k_sheer"\nvalues = [1e4]', "parameters[0].path", "k_sheer"),
    ("", 'path = "mount_rings[2].x"\nvalues = [0.1]', "parameters[0].path", "has 1 entry"),
    ("", 'path = "body.cg"\nvalues = [0.1]', "parameters[0].path", "not one value"),
    ("", 'path = "mount_rings.x"\nvalues = [0.1]', "parameters[0].path", "is a list"),
    ("", 'path = "mount_rings[0].x"\nvalues = { start = 0.1, stop = 0.4 }', "parameters[0].values.num", "required"),
    ("", 'path = "mount_rings[0].k_shear"\nvalues = [-1.0, 1e4]', "parameters[0].values", "must be between 0 and 1e+13 N/m"),
    ("", 'path = "mount_rings[0].count"\nvalues = { start = 1, stop = 2, num = 3 }', "parameters[0].values", "integer"),
    ("", 'path = "mount_rings[0].x"\nvalues = { start = 0.0, stop = 0.4, num = 3, scale = "log" }', "parameters[0].values", "> 0"),
    ("", 'path = "mount_rings[0].x"\ndistribution = { kind = "normal", mean = 0.3, std = 0.01 }', "parameters[0].distribution", "random"),
    ('[sampling]\nmethod = "random"', 'path = "mount_rings[0].x"\nvalues = { start = 0.1, stop = 0.4 }', "sampling.n", "required"),
    ('[sampling]\nmethod = "sobol"\nn = 8', 'path = "mount_rings[0].x"\ndistribution = { kind = "normal", mean = 0.3 }', "parameters[0].distribution", "std"),
    ('outputs = ["critical_thrustt"]', 'path = "mount_rings[0].x"\nvalues = [0.1]', "outputs[0]", "critical_thrust"),
    ("", 'path = "mount_rings[0].x"\nvalues = [0.1, 0.1]', "parameters[0].values", "distinct"),
    # strict types: the variants are checked with the model file's own strict rules
    ("", 'path = "mount_rings[0].k_shear"\nvalues = [true, false]', "parameters[0].values", "not a boolean"),
    ("", 'path = "body.mass"\nvalues = ["100", "200"]', "parameters[0].values", "not a string"),
    ("", 'path = "mount_rings[0].count"\nvalues = [3.0, 4.0]', "parameters[0].values", "write 3, not 3.0"),
    ("", 'path = "thrust.preload_stiffness"\nvalues = [1, 0]', "parameters[0].values", "true or false"),
    ("", 'path = "body.cg[0]"\nvalues = [0.0, 1e200]', "parameters[0].values", "between -1000 and 1000 m"),
    ("", 'path = "mount_rings[0].x"\nvalues = { start = 0.1, stop = 0.4, num = 3.0 }', "parameters[0].values.num", "integer"),
    ("", 'path = "mount_rings[0].x"\nvalues = { start = true, stop = 0.4, num = 3 }', "parameters[0].values.start", "boolean"),
    ('[sampling]\nmethod = "random"\nn = 8\nseed = 1.5', 'path = "mount_rings[0].x"\nvalues = { start = 0.1, stop = 0.4 }',
     "sampling.seed", "integer"),
    # a normal distribution reaches negative stiffnesses: refused before anything runs
    ('[sampling]\nmethod = "random"\nn = 64', 'path = "mount_rings[0].k_shear"\ndistribution = { kind = "normal", mean = 1e3, std = 1e3 }',
     "parameters[0].distribution", "between 0 and 1e+13 N/m"),
    # results too large for memory, estimated before anything runs
    ("", 'path = "mount_rings[0].x"\nvalues = { start = 0.1, stop = 0.4, num = 10000 }\n[[parameters]]\n'
         'path = "mount_rings[0].k_shear"\nvalues = { start = 1e4, stop = 1e5, num = 10000 }', "parameters", "GiB"),
]


def _bad_study(tmp_path, header, param):
    body = f"[[parameters]]\n{param}\n" if param else GRID_6x5
    if header.startswith("[sampling]"):
        return write_study(tmp_path, body + "\n" + header, chunk_size=None)
    return write_study(tmp_path, body, header=header)


@pytest.mark.parametrize("header,param,field,rule", BAD)
def test_bad_study_file_names_the_field(tmp_path, capsys, header, param, field, rule):
    path = _bad_study(tmp_path, header, param)
    with pytest.raises(ModelError) as err:
        load_study(path)
    assert err.value.field.startswith(field) and rule in str(err.value)
    # the command line: one line naming the field, exit code 2, nothing written
    before = set(tmp_path.iterdir())
    code = main(["sweep", str(path), "-o", str(tmp_path / "out.zarr"), "--export", str(tmp_path / "r.csv")])
    out, errtext = capsys.readouterr()
    assert code == 2
    assert errtext.count("\n") == 1 and field in errtext
    assert set(tmp_path.iterdir()) == before


@pytest.mark.parametrize(
    "change,field",
    [
        (lambda t: t.replace("schema_version = 1", "schema_version = 2"), "schema_version"),
        (lambda t: t.replace("schema_version = 1", "schema_version = 1.0"), "schema_version"),
        (lambda t: t.replace("schema_version = 1", 'schema_version = "1"'), "schema_version"),
        (lambda t: t.replace('model = "imp_symmetric.toml"', 'model = "missing.toml"'), "model"),
        (lambda t: t + "\n[parameters\n", "study file"),
    ],
)
def test_bad_study_header(tmp_path, capsys, change, field):
    path = write_study(tmp_path, GRID_6x5)
    path.write_text(change(path.read_text()))
    code = main(["sweep", str(path), "-o", str(tmp_path / "out.zarr")])
    _, err = capsys.readouterr()
    assert code == 2 and err.count("\n") == 1 and field in err
    assert not (tmp_path / "out.zarr").exists()


def test_bad_base_model_is_named(tmp_path, capsys):
    path = write_study(tmp_path, GRID_6x5)
    model = tmp_path / "imp_symmetric.toml"
    model.write_text(model.read_text().replace("k_axial = 1.0e5", "k_axial = -1.0e5"))
    code = main(["sweep", str(path), "-o", str(tmp_path / "out.zarr")])
    _, err = capsys.readouterr()
    assert code == 2 and "mount_rings[0].k_axial" in err and "base model" in err


@pytest.mark.parametrize(
    "args,field",
    [
        (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "--workers"),
        (["--workers", "0"], "--workers"),
        (["--export", "r.xlsx"], "--export"),
    ],
)
def test_bad_sweep_options(tmp_path, capsys, args, field):
    path = write_study(tmp_path, GRID_6x5)
    args = [str(tmp_path / a) if a.endswith(".xlsx") else a for a in args]
    code = main(["sweep", str(path), "-o", str(tmp_path / "out.zarr"), *args])
    _, err = capsys.readouterr()
    assert code == 2 and field in err
    assert not (tmp_path / "out.zarr").exists()
