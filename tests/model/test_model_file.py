"""Model-file validation: every rule gives one line naming the field, the value and the rule."""

import copy

import numpy as np
import pytest
from conftest import ring_model_dict

import impstab
from impstab.errors import ModelError
from impstab.model import model_from_dict


def mutate(path, value):
    d = ring_model_dict()
    d["mounts"] = [{"position": [-0.2, 0.0, 0.0], "k_axial": 1e4, "k_shear": 1e4}]
    cur = d
    for p in path[:-1]:
        cur = cur[p]
    if value is KeyError:
        del cur[path[-1]]
    else:
        cur[path[-1]] = value
    return d


BAD = [
    (("schema_version",), 2, "schema_version"),
    (("schema_version",), KeyError, "schema_version"),
    (("body", "mass"), -1.0, "body.mass"),
    (("body", "mass"), float("nan"), "body.mass"),
    (("body", "mass"), float("inf"), "body.mass"),
    (("body", "masss"), 1.0, "body.masss"),
    (("body", "cg"), [0.0, 0.0], "body.cg"),
    (("body", "inertia"), [1.0, -6.0, 6.0], "body.inertia"),
    (("body", "inertia"), [1.0, 1.0, 6.0], "body.inertia"),          # triangle inequality
    (("body", "inertia"), [[1, 2, 0], [0, 6, 0], [0, 0, 6]], "body.inertia"),  # not symmetric
    (("mount_rings", 0, "k_shear"), -5.0, "mount_rings[0].k_shear"),
    (("mount_rings", 0, "count"), 0, "mount_rings[0].count"),
    (("mount_rings", 0, "axis"), [0.0, 0.0, 0.0], "mount_rings[0].axis"),
    (("mount_rings", 0, "radius"), 0.0, "mount_rings[0].radius"),
    (("mounts", 0, "k_axial"), KeyError, "mounts[0].k_axial"),
    (("mounts", 0, "position"), [0.0, "a", 0.0], "mounts[0].position"),
    (("mounts", 0, "stiffness"), [[1.0] * 6] * 5, "mounts[0].stiffness"),
    (("thrust", "direction"), [0.0, 0.0, 0.0], "thrust.direction"),
    (("thrust", "tangency"), 1.5, "thrust.tangency"),
    (("thrust", "operating"), -10.0, "thrust.operating"),
    (("thrust", "preload"), True, "thrust.preload"),
    (("analysis", "linearization"), "exact", "analysis.linearization"),
    (("analysis", "thrust_max"), 0.0, "analysis.thrust_max"),
    (("fluid",), {"model": "matrix"}, "fluid.added_mass"),
    (("fluid",), {"model": "potential"}, "fluid.model"),
    (("fluid",), {"model": "strip", "density": 1025.0}, "hull"),
    (("propeller",), {"speed": 10.0, "speed_law": "cubic"}, "propeller.speed_law"),
]


@pytest.mark.parametrize("path,value,field", BAD)
def test_bad_input_names_the_field(path, value, field):
    with pytest.raises(ModelError) as info:
        model_from_dict(mutate(path, value))
    msg = str(info.value)
    assert "\n" not in msg
    assert msg.startswith(field), msg
    assert info.value.field.startswith(field)


def test_mounts_must_restrain_all_motions():
    d = ring_model_dict()
    d["mount_rings"][0]["k_axial"] = 0.0      # nothing resists surge or the rocking motions
    with pytest.raises(ModelError, match="^mounts.*free"):
        model_from_dict(d)
    d = ring_model_dict()
    d["mount_rings"][0]["count"] = 1
    with pytest.raises(ModelError, match="^mounts"):
        model_from_dict(d)


def test_thrust_max_defaults_and_requirements():
    d = ring_model_dict()
    del d["analysis"]
    assert model_from_dict(d).analysis.thrust_max == pytest.approx(20000.0)
    del d["thrust"]["operating"]
    with pytest.raises(ModelError, match="^analysis.thrust_max"):
        model_from_dict(d)
    d = ring_model_dict(propeller={"speed": 100.0, "polar_inertia": 0.1, "speed_law": "sqrt-thrust"})
    del d["thrust"]["operating"]
    with pytest.raises(ModelError, match="^propeller.speed_law"):
        model_from_dict(d)


def test_files(tmp_path):
    with pytest.raises(ModelError, match="file not found"):
        impstab.load_model(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("schema_version = 1\nbody = [")
    with pytest.raises(ModelError, match="not valid TOML"):
        impstab.load_model(bad)
    with pytest.raises(ModelError, match="directory"):
        impstab.load_model(tmp_path)


def test_defaults_and_ring_geometry():
    model = model_from_dict(ring_model_dict())
    pos = np.array([m.position for m in model.mounts])
    assert np.allclose(pos[:, 0], 0.3)
    assert np.allclose(np.hypot(pos[:, 1], pos[:, 2]), 0.15)
    assert np.allclose(pos[0], [0.3, 0.0, 0.15], atol=1e-15)   # start_angle 90: +z
    assert model.thrust.tangency == 1.0 and model.thrust.preload_stiffness
    assert model.analysis.linearization == "equilibrium"


def test_matrix_added_mass_enters_the_mass_matrix():
    am = np.diag([0.0, 20.0, 20.0, 0.0, 1.5, 1.5]).tolist()
    d = ring_model_dict(fluid={"model": "matrix", "added_mass": am})
    model = model_from_dict(d)
    assert np.allclose(model.mass_matrix - model.body.mass_matrix(), am)
    d2 = copy.deepcopy(d)
    d2["fluid"]["added_mass"][1][2] = 5.0
    with pytest.raises(ModelError, match="^fluid.added_mass.*symmetric"):
        model_from_dict(d2)
