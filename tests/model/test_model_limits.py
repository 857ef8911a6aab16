"""Strict types, physical ranges and file bounds of model files (issue: bad input never read as a
wrong value, never an internal error)."""

import json
import math
import os
import stat

import pytest
from conftest import ring_model_dict

import impstab
from impstab.errors import ModelError, format_value, printable
from impstab.limits import MAX_FILE_BYTES, RANGES
from impstab.model import model_from_dict
from impstab.model.schema import ModelFile


def with_value(path, value, base=None):
    d = base or ring_model_dict(hull={"radius": 0.15, "length": 0.8}, fluid={"model": "strip", "density": 1025.0},
                                propeller={"polar_inertia": 0.1, "speed": 10.0})
    cur = d
    for p in path[:-1]:
        cur = cur[p]
    cur[path[-1]] = value
    return d


def refused(d, field, *words):
    with pytest.raises(ModelError) as info:
        model_from_dict(d)
    msg = str(info.value)
    assert info.value.field == field, msg
    assert "\n" not in msg and "np." not in msg and "Value error" not in msg
    for w in words:
        assert w in msg, msg
    return msg


STRICT = [
    (("body", "mass"), True, "body.mass", "not a boolean"),
    (("body", "mass"), "100", "body.mass", "not a string"),
    (("thrust", "preload_stiffness"), "off", "thrust.preload_stiffness", "true or false"),
    (("thrust", "preload_stiffness"), 1, "thrust.preload_stiffness", "true or false"),
    (("thrust", "preload_stiffness"), 0.0, "thrust.preload_stiffness", "true or false"),
    (("schema_version",), 1.0, "schema_version", "integer"),
    (("schema_version",), "1", "schema_version", "integer"),
    (("schema_version",), True, "schema_version", "integer"),
    (("mount_rings", 0, "count"), 3.0, "mount_rings[0].count", "write 3, not 3.0"),
    (("mount_rings", 0, "count"), True, "mount_rings[0].count", "integer"),
    (("name",), 5, "name", "string"),
    (("thrust", "tangency"), False, "thrust.tangency", "boolean"),
    (("body", "inertia"), [1.0, True, 6.0], "body.inertia[1]", "boolean"),
    (("body", "inertia"), [[1.0, 0, 0], [0, "6", 0], [0, 0, 6.0]], "body.inertia[1][1]", "string"),
    (("mount_rings", 0, "k_shear"), [2e4], "mount_rings[0].k_shear", "not a list"),
    (("analysis",), 5, "analysis", "table"),
]


@pytest.mark.parametrize("path,value,field,word", STRICT)
def test_strict_types(path, value, field, word):
    refused(with_value(path, value), field, word)


def test_integers_are_numbers():
    model = model_from_dict(with_value(("body", "mass"), 100))
    assert model.body.mass == 100.0 and isinstance(model.body.mass, float)


RANGE = [
    (("body", "cg"), [1e200, 0, 0], "body.cg[0]", "1e+200"),
    (("body", "mass"), 1e-300, "body.mass", "kg"),
    (("body", "mass"), 1e9, "body.mass", "1e+07 kg"),
    (("mount_rings", 0, "k_shear"), 1e308, "mount_rings[0].k_shear", "N/m"),
    (("mount_rings", 0, "radius"), 1e-300, "mount_rings[0].radius", "m"),
    (("mount_rings", 0, "start_angle"), 1e6, "mount_rings[0].start_angle", "deg"),
    (("mount_rings", 0, "c_axial"), 1e20, "mount_rings[0].c_axial", "N s/m"),
    (("hull", "radius"), 1e-300, "hull.radius", "m"),
    (("hull", "length"), 2e7, "hull.length", "m"),
    (("fluid", "density"), 1e-300, "fluid.density", "kg/m^3"),
    (("thrust", "operating"), 1e308, "thrust.operating", "N"),
    (("analysis", "thrust_max"), 1e308, "analysis.thrust_max", "N"),
    (("propeller", "speed"), 1e9, "propeller.speed", "rad/s"),
    (("propeller", "polar_inertia"), 1e300, "propeller.polar_inertia", "kg m^2"),
    (("body", "inertia"), [1e-300, 1e-300, 1e-300], "body.inertia[0]", "kg m^2"),
    (("mount_rings", 0, "count"), 10**400, "mount_rings[0].count", "between 1 and 1000"),
    (("body", "mass"), 10**400, "body.mass", "finite"),
    (("body", "mass"), math.nan, "body.mass", "finite"),
]


@pytest.mark.parametrize("path,value,field,word", RANGE)
def test_magnitudes_out_of_range(path, value, field, word):
    refused(with_value(path, value), field, word)


def test_hull_too_slender_for_the_quadrature_is_refused_with_the_hull_key():
    d = with_value(("fluid",), {"model": "baffled-cylinder", "density": 1025.0})
    d["hull"] = {"radius": 1e-4, "length": 1000.0}
    refused(d, "hull.length", "quadrature nodes", "strip theory")


def test_a_search_below_the_operating_thrust_says_so():
    """The issue's case: thrust_max 15000 N below the operating thrust 20000 N of a model that is
    unstable from 18012 N (the closed form of the symmetric ring, tests/linear)."""
    d = ring_model_dict(thrust={"operating": 20000.0}, analysis={"thrust_max": 15000.0})
    res = impstab.critical_thrust(model_from_dict(d))
    assert res.thrust is None and res.margin is None
    assert any("below the operating thrust 20000 N" in w and "not established" in w for w in res.warnings)
    d["analysis"] = {}                               # the default search covers the operating point
    res = impstab.critical_thrust(model_from_dict(d))
    assert model_from_dict(d).analysis.thrust_max == 200000.0
    assert res.thrust == pytest.approx(18012.0999227555, rel=1e-9) and res.margin < 1
    assert any("unstable at its operating thrust 20000 N" in w for w in res.warnings)


def test_a_zero_length_direction_is_refused():
    refused(with_value(("thrust", "direction"), [1e-300, 0.0, 0.0]), "thrust.direction", "non-zero")


def test_every_number_of_the_schema_has_a_range():
    """The reference generated from the schema shows a minimum and a maximum for every number."""
    schema = ModelFile.model_json_schema()
    missing = []

    def walk(node, where):
        if isinstance(node, dict):
            if node.get("type") in ("number", "integer") and not ("minimum" in node and "maximum" in node):
                missing.append(where)
            for k, v in node.items():
                walk(v, f"{where}/{k}")
        elif isinstance(node, list):
            for i, v in enumerate(node):
                walk(v, f"{where}/{i}")

    walk(schema, "")
    assert missing == []


def test_extreme_corner_of_the_ranges_stays_finite():
    """The heaviest, stiffest, largest model the ranges allow still gives finite answers."""
    r = RANGES
    d = {
        "schema_version": 1,
        "body": {"mass": r["mass"].high, "cg": [r["coordinate"].high, 0.0, 0.0], "inertia": [1e12, 1e12, 1e12]},
        "mount_rings": [{"count": 3, "radius": r["coordinate"].high, "x": -r["coordinate"].high,
                         "k_axial": r["stiffness"].high, "k_shear": r["stiffness"].high, "c_axial": r["damping"].high}],
        "thrust": {"operating": r["thrust"].high},
    }
    model = model_from_dict(d)
    res = impstab.critical_thrust(model)
    assert res.thrust is None or math.isfinite(res.thrust)


# -- files ----------------------------------------------------------------------------------------

def test_a_fifo_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "model.toml"
    os.mkfifo(fifo)
    with pytest.raises(ModelError, match="not a regular file"):
        impstab.load_model(fifo)


def test_a_device_is_refused():
    with pytest.raises(ModelError, match="not a regular file"):
        impstab.load_model("/dev/zero")


def test_a_huge_file_is_refused_without_reading_it(tmp_path):
    big = tmp_path / "big.toml"
    with open(big, "wb") as f:
        f.truncate(1 << 30)          # sparse: 1 GiB that costs no disk
    with pytest.raises(ModelError, match="larger than the 4 MiB"):
        impstab.load_model(big)
    assert MAX_FILE_BYTES == 4 * 1024**2


def test_binary_and_deeply_nested_files(tmp_path):
    binary = tmp_path / "b.toml"
    binary.write_bytes(b"schema_version = 1\nname = \"\xff\xfe\"\n")
    with pytest.raises(ModelError, match="not UTF-8"):
        impstab.load_model(binary)
    deep = tmp_path / "deep.toml"
    deep.write_text("schema_version = 1\nx = " + "[" * 500 + "]" * 500 + "\n")
    with pytest.raises(ModelError, match="nested too deeply"):
        impstab.load_model(deep)
    nested = tmp_path / "nested.toml"
    nested.write_text("schema_version = 1\n[body]\nmass = 1.0\ninertia = " + "[" * 40 + "1.0" + "]" * 40 + "\n")
    with pytest.raises(ModelError, match="nest at most 32"):
        impstab.load_model(nested)


def test_an_unreadable_file_names_the_path(tmp_path):
    p = tmp_path / "secret.toml"
    p.write_text("schema_version = 1\n")
    p.chmod(0)
    if os.access(p, os.R_OK):  # running as root: permissions do not stop the read
        pytest.skip("permissions are not enforced for this user")
    with pytest.raises(ModelError, match="permission denied"):
        impstab.load_model(p)


# -- the text of messages -------------------------------------------------------------------------

def test_messages_are_one_printable_line():
    assert printable("a\x1b[2J\x07b\u202ec\nd\te") == "a\\x1b[2J\\x07b\\u202ec\\x0ad\\x09e"
    assert printable("Größe λ 推力") == "Größe λ 推力"
    import numpy as np

    assert format_value(np.float64(1e200)) == "1e+200"
    assert format_value([np.float64(1.5), np.int64(2)]) == "[1.5, 2]"
    assert format_value(True) == "true"
    deep: list = []
    cur = deep
    for _ in range(600):
        cur.append([])
        cur = cur[0]
    assert len(format_value(deep)) <= 80          # no recursion, bounded
    assert format_value(10**500) == "<integer of 501 digits>"
    err = ModelError("mounts[0].\x1b]0;title\x07", "\x1b[2J", "unknown key")
    assert "\x1b" not in str(err) and "\x07" not in str(err) and "\n" not in str(err)


def test_unknown_key_with_escape_sequences_is_shown_escaped():
    d = ring_model_dict()
    d["body"]["\x1b[2Jmass"] = 1.0
    with pytest.raises(ModelError) as info:
        model_from_dict(d)
    assert "\x1b" not in str(info.value) and "\\x1b[2Jmass" in str(info.value)
    json.dumps(str(info.value))


def test_the_documented_ranges_are_the_enforced_ones():
    from pathlib import Path

    from impstab import limits

    text = (Path(__file__).resolve().parents[2] / "docs" / "limits.md").read_text()
    for name, r in RANGES.items():
        row = f"| `{name}` | {r.what} | {r.low:g} | {r.high:g} | {r.unit or '-'} |"
        assert row in text, row
    for needle in (f"{limits.MAX_FILE_BYTES // 1024**2} MiB", f"{limits.MAX_NESTING} levels", f"{limits.MAX_QUADRATURE_NODES:.0e}".replace("+0", ""),
                   "10 000 frequencies", f"{limits.MAX_STEPS:.0e}".replace("+0", "") + " steps", "1 GiB", "| 100 |",
                   "| 100 000 |", "2 GiB", f"factor of {limits.LONG_FACTOR}"):
        assert needle in text, needle
    assert limits.MAX_FREQUENCIES == 10_000 and limits.MAX_OUTPUT_BYTES == 1024**3 and limits.MAX_THRUSTS == 100
    assert limits.MAX_LOCUS_STEPS == 100_000 and limits.MAX_STUDY_BYTES == 2 * 1024**3 and limits.MAX_SWEEP_NODES == 10**8
