"""The model- and study-file reference: in step with the schema, committed pages current,
a JSON Schema that an independent validator (jsonschema) applies like pydantic, errors that
name the unknown key and the nearest valid one, speed_rpm."""

import copy
import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from impstab.cli import main
from impstab.errors import ModelError
from impstab.model import model_from_dict
from impstab.model import reference as model_ref
from impstab.model.schema import ModelFile
from impstab.model.schema_doc import check_reference, walk
from impstab.studies import reference as study_ref
from impstab.studies import study_from_dict
from impstab.studies.schema import StudyFile

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def _base() -> dict:
    return tomllib.loads((EXAMPLES / "imp_symmetric.toml").read_text())


@pytest.mark.parametrize("root,table", [(ModelFile, model_ref.MODEL_REFERENCE), (StudyFile, study_ref.STUDY_REFERENCE)])
def test_every_key_has_an_entry_and_no_entry_is_stale(root, table):
    missing, stale = check_reference(root, table)
    assert missing == [], f"schema keys without a reference entry: {missing}"
    assert stale == [], f"reference entries that name no schema key: {stale}"
    for k in walk(root):
        assert table[k.path].description.strip(), k.path


@pytest.mark.parametrize("page,make", [("docs/model-file.md", model_ref.markdown_page),
                                       ("docs/study-file.md", study_ref.markdown_page)])
def test_committed_reference_page_equals_the_generated_one(page, make):
    committed = (ROOT / page).read_text(encoding="utf-8")
    assert committed == make(), f"{page} is out of date: run `impstab schema{' --study' if 'study' in page else ''} --markdown -o {page}`"


def test_reference_page_lists_every_key_with_unit_and_default():
    text = model_ref.markdown_page()
    for k in walk(ModelFile):
        assert f"| `{k.key}` |" in text, k.path
    row = next(line for line in text.splitlines() if line.startswith("| `k_shear` |") and "each mount" in line)
    assert "| N/m |" in row and "**required**" in row and ">= 0, <= 1e+13" in row
    row = next(line for line in text.splitlines() if line.startswith("| `tangency` |"))
    assert "`1.0`" in row and ">= 0, <= 1" in row
    assert "## `[[mount_rings]]`" in text and "## `[propeller]`" in text


def _validator(doc):
    jsonschema = pytest.importorskip("jsonschema")
    jsonschema.Draft7Validator.check_schema(doc)
    return jsonschema.Draft7Validator(doc)


def test_json_schema_accepts_every_example_and_refuses_what_pydantic_refuses():
    model_v = _validator(model_ref.json_schema_document())
    study_v = _validator(study_ref.json_schema_document())
    for path in EXAMPLES.glob("*.toml"):
        if path.name.startswith("optimize"):  # optimisation files: their own reader (tests/optimize)
            continue
        data = tomllib.loads(path.read_text())
        v = study_v if path.name.startswith("study") else model_v
        assert list(v.iter_errors(data)) == [], path.name
    bad_cases = [
        lambda d: d["mount_rings"][0].update(k_sheer=1.0),        # unknown key
        lambda d: d["mount_rings"][0].update(k_shear=-1.0),       # sign
        lambda d: d["thrust"].update(tangency=1.5),               # bound
        lambda d: d["body"].update(cg=[0.0, 0.0]),                # shape
        lambda d: d["analysis"].update(linearization="tangent"),  # choice
        lambda d: d.update(schema_version=2),                     # version
        lambda d: d["body"].pop("mass"),                          # required
    ]
    for change in bad_cases:
        data = _base()
        change(data)
        assert list(model_v.iter_errors(data)), data
        with pytest.raises(ModelError):
            model_from_dict(data)


def test_json_schema_carries_units_and_descriptions():
    doc = model_ref.json_schema_document()
    ring = doc["definitions"]["MountRingSpec"]["properties"]
    assert "[N/m]" in ring["k_shear"]["description"] and "[m]" in ring["x"]["description"]
    assert doc["properties"]["schema_version"]["const"] == 1
    assert "docs/model-file.md" in doc["description"]
    assert "null" not in json.dumps(doc)  # TOML has no null: optional keys are simply absent


def test_schema_command_writes_json_and_markdown(tmp_path, capsys):
    out = tmp_path / "m.schema.json"
    assert main(["schema", "-o", str(out)]) == 0
    assert json.loads(out.read_text()) == model_ref.json_schema_document()
    assert main(["schema", "--study", "--markdown"]) == 0
    assert capsys.readouterr().out == study_ref.markdown_page()


@pytest.mark.parametrize("section,key,typo,near", [
    ("mount_rings", "k_shear", "k_sheer", "k_shear"),
    ("mount_rings", "start_angle", "start_angel", "start_angle"),
    ("thrust", "operating", "operatng", "operating"),
])
def test_unknown_key_is_named_before_the_key_it_hides(section, key, typo, near):
    data = _base()
    table = data[section][0] if isinstance(data[section], list) else data[section]
    table[typo] = table.pop(key)
    with pytest.raises(ModelError) as info:
        model_from_dict(data)
    where = f"{section}[0]" if isinstance(data[section], list) else section
    assert f"unknown key '{typo}' in {where} (did you mean '{near}'?)" in str(info.value)
    assert "docs/model-file.md" in str(info.value)
    assert "is required" not in str(info.value)


def test_unknown_key_in_a_mount_table_and_at_the_top_level():
    data = _base()
    data["mounts"] = [{"position": [0.3, 0.0, 0.0], "k_axial": 1e5, "k_sheer": 2e4}]
    with pytest.raises(ModelError, match=r"unknown key 'k_sheer' in mounts\[0\] \(did you mean 'k_shear'\?\)"):
        model_from_dict(data)
    data = _base()
    data["analysys"] = {}
    with pytest.raises(ModelError, match=r"unknown key 'analysys' at the top level \(did you mean 'analysis'\?\)"):
        model_from_dict(data)
    data = _base()
    data["thrust"]["zzz"] = 1.0  # nothing near: the valid keys are listed
    with pytest.raises(ModelError, match=r"valid keys: point, direction, tangency"):
        model_from_dict(data)


def test_unknown_study_key_is_named_with_the_nearest(tmp_path):
    (tmp_path / "m.toml").write_text((EXAMPLES / "imp_symmetric.toml").read_text())
    study = {"schema_version": 1, "model": "m.toml",
             "parameters": [{"path": "mount_rings[0].x", "valeus": [0.1, 0.2]}]}
    with pytest.raises(ModelError, match=r"unknown key 'valeus' in parameters\[0\] \(did you mean 'values'\?\).*docs/study-file.md"):
        study_from_dict(study, tmp_path)
    study = {"schema_version": 1, "model": "m.toml", "samplng": {},
             "parameters": [{"path": "mount_rings[0].x", "values": [0.1, 0.2]}]}
    with pytest.raises(ModelError, match=r"unknown key 'samplng' at the top level \(did you mean 'sampling'\?\)"):
        study_from_dict(study, tmp_path)
    study.pop("samplng")
    study["parameters"][0]["values"] = {"start": 0.1, "stop": 0.2, "nun": 3}  # in a branch of a union
    with pytest.raises(ModelError, match=r"unknown key 'nun' in parameters\[0\]\.values \(did you mean 'num'\?\)"):
        study_from_dict(study, tmp_path)


def test_speed_rpm_is_the_speed_in_revolutions_per_minute():
    data = tomllib.loads((EXAMPLES / "imp_damped.toml").read_text())
    rad = model_from_dict(copy.deepcopy(data))
    data["propeller"].pop("speed")
    data["propeller"]["speed_rpm"] = 150.0 * 60.0 / (2.0 * math.pi)  # 1432.39 rpm
    rpm = model_from_dict(data)
    assert rpm.propeller.speed == pytest.approx(150.0, rel=1e-15)
    import impstab

    np.testing.assert_allclose(impstab.linearize(rpm, 5000.0).G, impstab.linearize(rad, 5000.0).G, rtol=1e-14)
    data["propeller"]["speed"] = 150.0
    with pytest.raises(ModelError, match=r"propeller.speed_rpm = .*give either speed \(rad/s\) or speed_rpm \(rpm\), not both"):
        model_from_dict(data)
    data["propeller"].pop("speed")
    data["propeller"]["speed_rpm"] = float("inf")
    with pytest.raises(ModelError, match=r"propeller.speed_rpm"):
        model_from_dict(data)


@pytest.mark.parametrize("path,label", [
    ("mount_rings[0].x", "ring axial position x (m)"),
    ("mount_rings[0].k_shear", "mount shear stiffness k_shear (N/m)"),
    ("mount_rings[1].x", "ring 2 axial position x (m)"),
    ("mounts[2].position[1]", "mount 3 position y (m)"),
    ("thrust.operating", "operating thrust (N)"),
    ("mount_rings[0].count", "mounts per ring"),
])
def test_axis_labels_come_from_the_reference(path, label):
    assert model_ref.label(path) == label


def test_walker_documents_nested_tables_of_array_entries():
    """A table inside each entry of an array of tables (the shape of ``[mounts.beam]``)."""
    from typing import Annotated, Literal, Optional

    from pydantic import BaseModel, ConfigDict, Field, StrictFloat

    from impstab.model.schema_doc import RefEntry, allowed_keys, markdown

    class _S(BaseModel):
        model_config = ConfigDict(extra="forbid")

    class Beam(_S):
        length: Annotated[StrictFloat, Field(gt=0, allow_inf_nan=False)]
        law: Literal["a", "b"] = "a"

    class Mount(_S):
        position: Annotated[list[Annotated[float, Field(allow_inf_nan=False)]], Field(min_length=3, max_length=3)]
        beam: Optional[Beam] = None

    class File(_S):
        mounts: list[Mount] = []

    keys = {k.path: k for k in walk(File)}
    assert list(keys) == ["mounts", "mounts[].position", "mounts[].beam", "mounts[].beam.length", "mounts[].beam.law"]
    assert keys["mounts[].beam.length"].section == "[mounts.beam]" and keys["mounts[].beam"].kind == "table"
    assert keys["mounts[].beam.length"].rule == "> 0, finite" and keys["mounts[].beam.length"].required
    assert keys["mounts[].position"].type == "3 numbers" and keys["mounts[].beam.law"].default == '"a"'
    assert allowed_keys(File, ("mounts", 0, "beam")) == ["length", "law"]
    table = {p: RefEntry("m" if "length" in p else "", f"about {p}") for p in keys}
    assert "## `[mounts.beam]`" in markdown(File, table, title="t", intro="i")
