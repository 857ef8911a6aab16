"""A sweep's values equal `impstab critical` on the same variants; failed variants are recorded."""

import copy
import json

import numpy as np
import pytest
from _study_helpers import EXAMPLES, GRID_6x5, to_toml, write_study
from conftest import asymmetric_model_dict

import impstab
from impstab.cli import main
from impstab.errors import NumericalError
from impstab.linear.batch import api as batch  # the module that builds the families
from impstab.linear.batch import STATUSES, critical_thrust_batch
from impstab.model import model_from_dict
from impstab.model.assemble import read_toml
from impstab.studies import load_study, run_study
from impstab.studies.evaluate import variant_dict

REL = 1e-10
KEYS = ("critical_thrust", "frequency_hz", "margin", "undamped_critical_thrust")


def _close(a, b) -> bool:
    if a is None or b is None or (isinstance(b, float) and np.isnan(b)):
        return (a is None or np.isnan(a)) and (b is None or np.isnan(b))
    return abs(a - b) <= REL * max(abs(a), abs(b))


def _compare_with_cli(tmp_path, capsys, study, result, picks):
    """Run `impstab critical --json` on the variant files of the picked designs."""
    ds = result.dataset
    segs = [p.path.segments for p in study.parameters]
    kinds = result.kind_names()
    for n, idx in enumerate(picks):
        vals = [p.values[i] for p, i in zip(study.parameters, idx)] if study.method == "grid" else \
            [p.values[idx[0]] for p in study.parameters]
        path = tmp_path / f"variant{n}.toml"
        path.write_text(to_toml(variant_dict(study.base_model, segs, vals)))
        assert main(["critical", str(path), "--json"]) == 0
        ref = json.loads(capsys.readouterr().out)
        sel = dict(zip(ds["status"].dims, idx))
        assert int(ds["status"][sel]) == 0
        assert str(kinds[sel].values) == ref["kind"]
        for key in KEYS:
            if key in ds:
                assert _close(ref[key], float(ds[key][sel])), (key, ref[key], float(ds[key][sel]))


def test_grid_values_equal_critical_on_sampled_variants(tmp_path, capsys):
    study = load_study(write_study(tmp_path, GRID_6x5))
    res = run_study(study, tmp_path / "s.zarr")
    assert res.counts()["ok"] == 30
    rng = np.random.default_rng(3)
    picks = [tuple(rng.integers(0, s) for s in study.shape) for _ in range(6)]
    _compare_with_cli(tmp_path, capsys, study, res, picks)


def test_flutter_divergence_and_none_in_one_sweep(tmp_path, capsys):
    body = """
[[parameters]]
path = "thrust.tangency"
values = [0.0, 0.5, 1.0]
[[parameters]]
path = "mount_rings[0].x"
values = [-0.3, 0.1, 0.3]
"""
    study = load_study(write_study(tmp_path, body, header='outputs = ["critical_thrust", "kind", "frequency_hz", "margin", "modes"]'))
    res = run_study(study, None)
    assert set(res.kind_names().values.ravel()) == {"none", "flutter", "divergence"}
    _compare_with_cli(tmp_path, capsys, study, res, [(i, j) for i in range(3) for j in range(3)])


def test_damped_and_asymmetric_models(tmp_path, capsys):
    # damping with a spin law that follows the thrust, and an asymmetric equilibrium linearization
    damped = write_study(tmp_path / "d", """
[[parameters]]
path = "mount_rings[0].c_shear"
values = [2.0, 20.0]
[[parameters]]
path = "mount_rings[0].x"
values = [0.25, 0.3]
""", model="imp_damped.toml")
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "asym.toml").write_text(to_toml(asymmetric_model_dict()))
    asym = write_study(tmp_path / "a", """
[[parameters]]
path = "mounts[0].k_shear"
values = [1.5e4, 3e4]
[[parameters]]
path = "thrust.point[2]"
values = [0.0, 0.03]
""", model="asym.toml")
    for path in (damped, asym):
        study = load_study(path)
        res = run_study(study, None)
        _compare_with_cli(tmp_path, capsys, study, res, [(i, j) for i in range(2) for j in range(2)])


def test_compressible_fluid_model(tmp_path, capsys):
    # added mass and radiation damping at the onset frequency, iterated like `impstab critical`
    path = write_study(tmp_path, '[[parameters]]\npath = "mount_rings[0].k_shear"\nvalues = [1.5e4, 2.5e4]\n',
                       model="imp_fluid.toml")
    study = load_study(path)
    res = run_study(study, None)
    _compare_with_cli(tmp_path, capsys, study, res, [(0,), (1,)])


def _variants(base, n, rng, changes):
    out = []
    for _ in range(n):
        d = copy.deepcopy(base)
        for change in changes:
            change(d, rng)
        out.append(d)
    return out


def _ring(key, lo, hi, log=False):
    return lambda d, r: d["mount_rings"][0].__setitem__(key, float(10 ** r.uniform(lo, hi) if log else r.uniform(lo, hi)))


@pytest.mark.parametrize("vectorized", [True, False])
def test_batch_equals_single_model_function(vectorized):
    """critical_thrust_batch against critical_thrust, model by model, on varied layouts."""
    rng = np.random.default_rng(11)
    sym = read_toml(EXAMPLES / "imp_symmetric.toml")
    cls = asymmetric_model_dict(analysis={"thrust_max": 60000.0, "linearization": "classical"})
    cls["mounts"][0]["c_axial"] = 0.0
    cls["mounts"][0]["c_shear"] = 0.0
    dicts = _variants(sym, 40, rng, [_ring("x", -0.3, 0.5), _ring("k_shear", 3.3, 5, True), _ring("k_axial", 3.5, 5.5, True),
                                      lambda d, r: d["thrust"].__setitem__("tangency", float(r.uniform(0, 1))),
                                      lambda d, r: d["mount_rings"][0].__setitem__("count", int(r.integers(3, 6)))])
    dicts += _variants(cls, 12, rng, [lambda d, r: d["mounts"][0].__setitem__("k_shear", float(10 ** r.uniform(3.5, 5)))])
    models = [model_from_dict(d) for d in dicts]
    got = critical_thrust_batch(models, vectorized=vectorized)
    for j, m in enumerate(models):
        try:
            ref = impstab.critical_thrust(m)
        except Exception as exc:  # the batch records what the single-model function raises
            assert got.status[j] > 0 and type(exc).__name__ in got.message[j]
            continue
        assert got.status[j] == 0
        assert batch.KINDS[got.kind[j]] == ref.kind
        assert _close(ref.thrust, got.thrust[j]) and _close(ref.omega, got.omega[j])
        assert _close(ref.undamped_thrust, got.undamped_thrust[j])
        assert got.modes[j] == ",".join(ref.modes)


def test_failed_variants_are_recorded_and_the_study_goes_on(tmp_path, capsys):
    body = """
[[parameters]]
path = "mount_rings[0].k_shear"
values = [0.0, 1e4, 2e4]
[[parameters]]
path = "mount_rings[0].count"
values = [1, 3]
"""
    path = write_study(tmp_path, body)
    code = main(["sweep", str(path), "-o", str(tmp_path / "f.zarr"), "--no-progress"])
    out, err = capsys.readouterr()
    assert code == 0
    assert "designs failed" in err and err.count("\n") == 1
    res = run_study(load_study(path), tmp_path / "f.zarr")
    ds = res.dataset
    status = ds["status"].values
    # k_shear = 0, or a single mount: the mounts leave rigid-body motions free
    assert status[0, 0] == STATUSES.index("invalid") and status[1, 0] == STATUSES.index("invalid")
    assert status[1, 1] == 0 and status[2, 1] == 0
    msg = str(ds["message"].values[0, 0])
    assert msg.startswith("mounts") and "restrain" in msg
    assert np.isnan(ds["critical_thrust"].values[0, 0]) and ds["kind"].values[0, 0] == -1
    assert np.isfinite(ds["critical_thrust"].values[1, 1])


def test_numerical_failure_of_one_design(monkeypatch):
    base = read_toml(EXAMPLES / "imp_symmetric.toml")
    models = []
    for op in (2000.0, 1234.0, 3000.0):
        d = copy.deepcopy(base)
        d["thrust"]["operating"] = op
        models.append(model_from_dict(d))
    real = batch.ModelFamily

    def family(model, *args, **kw):
        if model.thrust.operating == 1234.0:
            raise NumericalError("no static equilibrium found at thrust 1 N")
        return real(model, *args, **kw)

    monkeypatch.setattr(batch, "ModelFamily", family)
    got = critical_thrust_batch(models)
    assert got.status.tolist() == [0, STATUSES.index("numerical_failure"), 0]
    assert "no static equilibrium" in got.message[1]
    assert np.isnan(got.thrust[1]) and got.thrust[0] == got.thrust[2]


def _planar_closed_form(x, k_sh, k_ax=1.0e5, radius=0.15, m=100.0, inertia=6.0):
    """Flutter thrust of the symmetric three-mount ring (sway-yaw plane, preload), THEORY 4."""
    k_y, k_yt = 3 * k_sh, 3 * k_sh * x
    c0 = 3 * k_sh * x**2 + 1.5 * k_ax * radius**2
    p = k_y * inertia + m * c0
    return (p - 2 * np.sqrt(m * inertia * (k_y * c0 - k_yt**2))) / (m * x)


def test_grid_sweep_equals_the_closed_form(tmp_path):
    """An independent answer for every design of a grid: the planar closed form of the ring."""
    study = load_study(write_study(tmp_path, """
[[parameters]]
path = "mount_rings[0].x"
values = { start = 0.1, stop = 0.4, num = 7 }
[[parameters]]
path = "mount_rings[0].k_shear"
values = { start = 5e3, stop = 5e4, num = 9, scale = "log" }
""", chunk_size=20))
    ds = run_study(study, None).dataset
    x = ds["mount_rings[0].x"].values[:, None]
    k_sh = ds["mount_rings[0].k_shear"].values[None, :]
    exact = _planar_closed_form(x, k_sh)
    got, kind = ds["critical_thrust"].values, ds["kind"].values
    flutter = exact <= 20000.0
    assert flutter.sum() >= 20 and (~flutter).sum() >= 10
    assert (kind[flutter] == 1).all() and (kind[~flutter] == 0).all()
    np.testing.assert_allclose(got[flutter], exact[flutter], rtol=1e-11)
    np.testing.assert_allclose(ds["margin"].values[flutter], exact[flutter] / 2000.0, rtol=1e-11)


def test_wide_brackets_are_halved_before_the_exact_refinement():
    """A coupled layout whose merging pair rotates over a grid interval (a third mode close by):
    the cluster at the bracket's unstable end is not clearly one at its stable end, so the
    bracket is halved on the classification before the exact refinement, which then succeeds
    (no warning), and the batch equals the single-model function."""
    from impstab.linear.engine import second_order_problem, solve

    base = read_toml(EXAMPLES / "imp_asymmetric.toml")
    base["analysis"]["linearization"] = "classical"
    models = []
    for x in np.linspace(0.20, 0.225, 4):
        for k in np.geomspace(8.5e3, 9.8e3, 4):
            d = copy.deepcopy(base)
            d["mounts"][0]["position"][0] = float(x)
            d["mounts"][0]["k_shear"] = float(k)
            models.append(model_from_dict(d))
    outcomes = solve([second_order_problem(batch.ModelFamily(m), m.analysis.thrust_max) for m in models])
    assert sum(o.bisections for o in outcomes) > 0 and not any(o.warnings for o in outcomes)
    got = critical_thrust_batch(models)
    for j, m in enumerate(models):
        ref = impstab.critical_thrust(m)
        assert got.status[j] == 0 and batch.KINDS[got.kind[j]] == ref.kind
        assert _close(ref.thrust, got.thrust[j]) and _close(ref.omega, got.omega[j])
        assert got.modes[j] == ",".join(ref.modes)


def test_mixed_batch_of_damped_and_affine_designs():
    """Designs whose jobs are not all affine (a damped, spinning model before a symmetric one):
    each affine job finds its own operators, whatever its place among the batch's jobs."""
    damped = impstab.load_model(EXAMPLES / "imp_damped.toml")
    sym = impstab.load_model(EXAMPLES / "imp_symmetric.toml")
    d = read_toml(EXAMPLES / "imp_symmetric.toml")
    d["mount_rings"][0]["x"] = 0.12
    other = model_from_dict(d)
    models = [damped, sym, damped, other, sym]
    got = critical_thrust_batch(models)
    for j, m in enumerate(models):
        ref = impstab.critical_thrust(m)
        assert got.status[j] == 0, got.message[j]
        assert _close(ref.thrust, got.thrust[j]) and _close(ref.undamped_thrust, got.undamped_thrust[j])
