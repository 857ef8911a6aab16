"""The reference of a file schema: every key with its type, unit, default and rule.

The pydantic schema (:mod:`impstab.model.schema`, :mod:`impstab.studies.schema`) says which keys
exist, their types, bounds, shapes and defaults; a reference table beside it
(:mod:`impstab.model.reference`, :mod:`impstab.studies.reference`) adds what the code cannot
say: the unit, a description and a short axis label. This module joins the two into

* :func:`walk`: one :class:`KeyDoc` per key, in the order of the schema;
* :func:`markdown`: the reference page (``docs/model-file.md``, ``docs/study-file.md``);
* :func:`json_schema`: a JSON Schema (draft-07) with the descriptions and units, for TOML editors
  (Taplo, Even Better TOML) that validate and complete files as they are typed;
* :func:`allowed_keys` and :func:`suggest`: the keys valid at a location, and the nearest one to
  a misspelt key, for error messages.

Key paths are written ``section.key``; an array of tables is written with ``[]``, e.g.
``mounts[].k_axial`` for the key ``k_axial`` of every ``[[mounts]]`` table.
"""

from __future__ import annotations

import difflib
import json
import math
import re
import types
import typing
from dataclasses import dataclass
from typing import Annotated, Any, Mapping, Union

from pydantic import BaseModel, TypeAdapter, ValidationError
from pydantic_core import PydanticUndefined

__all__ = ["KeyDoc", "RefEntry", "walk", "markdown", "json_schema", "allowed_keys", "suggest", "check_reference",
           "clean_loc", "unknown_key_rule"]


@dataclass(frozen=True)
class RefEntry:
    """What the schema cannot say about a key: its unit, description and short label.

    Attributes
    ----------
    unit : str
        SI unit (``""`` for a word, a flag or a count; ``"1"`` for a dimensionless number).
    description : str
        One or two sentences: meaning, conventions, rules that involve other keys.
    label : str
        Short name for an axis or a table column, e.g. ``"ring axial position x"`` (default: the
        key itself).
    """

    unit: str
    description: str
    label: str = ""


@dataclass(frozen=True)
class KeyDoc:
    """One key of a file schema.

    Attributes
    ----------
    path : str
        ``mounts[].k_axial``; a section is a path too (``body``, ``mounts``).
    section : str
        The TOML table it is written in: ``"(top level)"``, ``"[body]"``, ``"[[mounts]]"``.
    key : str
        The key itself.
    kind : {"value", "table", "array of tables"}
    type : str
        In words: ``"number"``, ``"integer"``, ``"3 numbers"``, ``"6 x 6 numbers"``, ...
    required : bool
    default : str
        TOML text of the default (``""`` when required or when absence has a meaning).
    rule : str
        Bounds, shape and choices from the schema, e.g. ``"> 0, finite"``.
    owner : str
        Name of the schema class that holds the key (for the JSON Schema).
    """

    path: str
    section: str
    key: str
    kind: str
    type: str
    required: bool
    default: str
    rule: str
    owner: str


# -- the schema's types ----------------------------------------------------------------------
def _annotation(info) -> Any:
    return Annotated[(info.annotation, *info.metadata)] if info.metadata else info.annotation


def _models_in(tp: Any, in_list: bool = False) -> list[tuple[type[BaseModel], bool]]:
    """Schema classes reachable in a type, each with whether it sits inside a list."""
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        return [(tp, in_list)]
    origin = typing.get_origin(tp)
    if origin is Annotated:
        return _models_in(typing.get_args(tp)[0], in_list)
    out: list[tuple[type[BaseModel], bool]] = []
    if origin in (Union, types.UnionType):
        for arg in typing.get_args(tp):
            out += _models_in(arg, in_list)
    elif origin is list:
        for arg in typing.get_args(tp):
            out += _models_in(arg, True)
    return out


def _resolve(frag: dict, defs: dict) -> dict:
    while "$ref" in frag:
        frag = defs[frag["$ref"].rsplit("/", 1)[-1]]
    return frag


def _number_rule(frag: dict) -> list[str]:
    rule = []
    for key, sym in (("exclusiveMinimum", ">"), ("minimum", ">="), ("exclusiveMaximum", "<"), ("maximum", "<=")):
        if key in frag:
            rule.append(f"{sym} {_num(frag[key])}")
    return rule


def _num(v: Any) -> str:
    if isinstance(v, float) and v.is_integer() and abs(v) < 1e15:
        return str(int(v))
    return f"{v:g}" if isinstance(v, float) else str(v)


def _describe(frag: dict, defs: dict) -> tuple[str, list[str]]:
    """``(type in words, rules)`` of a JSON-schema fragment."""
    frag = _resolve(frag, defs)
    if "anyOf" in frag:
        parts = [_describe(f, defs) for f in frag["anyOf"] if _resolve(f, defs).get("type") != "null"]
        types_ = list(dict.fromkeys(p[0] for p in parts))
        rules = list(dict.fromkeys(r for p in parts for r in p[1]))
        if len(types_) > 1 and all(t in _SCALARS for t in types_):
            return "number, integer, true/false or string", rules
        return " or ".join(types_), rules
    if "enum" in frag:
        return "string", ["one of " + ", ".join(json.dumps(v) for v in frag["enum"])]
    if "const" in frag:
        return "string", [f"= {json.dumps(frag['const'])}"]
    kind = frag.get("type")
    if kind == "number":
        return "number", _number_rule(frag)
    if kind == "integer":
        return "integer", _number_rule(frag)
    if kind == "boolean":
        return "true or false", []
    if kind == "string":
        return "string", []
    if kind == "object":
        return "table", []
    if kind == "array":
        item_type, item_rule = _describe(frag.get("items", {}), defs)
        lo, hi = frag.get("minItems"), frag.get("maxItems")
        if item_type == "table":
            return "array of tables", []
        if lo is not None and lo == hi:
            if re.fullmatch(r"\d+( x \d+)* numbers", item_type):
                text = f"{lo} x {item_type}"
            elif item_type in _SCALARS:
                text = f"{lo} {item_type}s"
            else:
                text = f"{lo} of: {item_type}"
        else:
            size = []
            if lo:
                size.append(f"at least {lo}")
            if hi is not None:
                size.append(f"at most {hi}")
            text = (f"list of {item_type}s" if item_type in ("number", "integer", "string") else f"list of: {item_type}")
            text += f" ({', '.join(size)})" if size else ""
        rules = [f"each {r}" if not r.startswith("each") else r for r in item_rule]
        return text, rules
    return "value", []


_SCALARS = ("number", "integer", "string", "true or false")


def _finite_rule(tp: Any, frag: dict, defs: dict) -> bool:
    """Whether the validator refuses infinite numbers for this key (probed, not parsed)."""
    frag = _resolve(frag, defs)
    probes = []
    for branch in frag.get("anyOf", [frag]):
        branch = _resolve(branch, defs)
        probe = _inf_like(branch, defs)
        if probe is not None:
            probes.append(probe)
    if not probes:
        return False
    adapter = TypeAdapter(tp)
    for probe in probes:
        try:
            adapter.validate_python(probe)
            return False
        except ValidationError as err:
            if not any(e["type"] == "finite_number" for e in err.errors()):
                return False
    return True


def _inf_like(frag: dict, defs: dict) -> Any:
    kind = frag.get("type")
    if kind == "number":
        return math.inf
    if kind == "array":
        item = _inf_like(_resolve(frag.get("items", {}), defs), defs)
        if item is None:
            return None
        return [item] * max(1, int(frag.get("minItems", 1)))
    return None


def _toml(value: Any) -> str:
    if value is None or value is PydanticUndefined:
        return ""
    if isinstance(value, BaseModel):
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return str(value)


# -- walking ---------------------------------------------------------------------------------
def walk(root: type[BaseModel]) -> list[KeyDoc]:
    """Every key of the schema ``root``, depth first in the order of the schema classes."""
    defs = root.model_json_schema().get("$defs", {})
    out: list[KeyDoc] = []
    _walk(root, "", "(top level)", defs, out)
    return out


def _walk(cls: type[BaseModel], prefix: str, section: str, defs: dict, out: list[KeyDoc]) -> None:
    props = cls.model_json_schema()["properties"]
    for name, info in cls.model_fields.items():
        path = f"{prefix}{name}"
        tp = _annotation(info)
        frag = props.get(name, {})
        models = _models_in(tp)
        default = info.default if info.default_factory is None else info.default_factory()
        required = info.is_required()
        if models:
            in_list = any(lst for _, lst in models)
            type_text, rules = _describe(frag, defs)
            if type_text in ("table", "array of tables"):
                kind = type_text
            else:
                kind = "table or list"  # e.g. a range table or a list of values
            out.append(KeyDoc(path, section, name, kind, type_text, required, "", "; ".join(rules), cls.__name__))
            seen = set()
            for sub, lst in models:
                if sub in seen:
                    continue
                seen.add(sub)
                sub_prefix = f"{path}[]." if lst else f"{path}."
                sub_section = f"[[{path.replace('[]', '')}]]" if lst else f"[{path.replace('[]', '')}]"
                _walk(sub, sub_prefix, sub_section, defs, out)
            continue
        type_text, rules = _describe(frag, defs)
        if _finite_rule(tp, frag, defs):
            rules.append("entries finite" if "numbers" in type_text else "finite")
        out.append(KeyDoc(path, section, name, "value", type_text, required, "" if required else _toml(default),
                          ", ".join(rules), cls.__name__))


def clean_loc(root: type[BaseModel], loc: tuple) -> tuple:
    """``loc`` of a pydantic error without the labels it inserts for union branches
    (``"list[float]"``, ``"function-after[...]"``, the name of a schema class)."""
    names = _class_names(root)
    return tuple(p for p in loc if not (isinstance(p, str) and ("[" in p or p.startswith("function-") or p in names)))


def _class_names(root: type[BaseModel], seen: set | None = None) -> set[str]:
    seen = set() if seen is None else seen
    if root.__name__ in seen:
        return seen
    seen.add(root.__name__)
    for info in root.model_fields.values():
        for m, _ in _models_in(_annotation(info)):
            _class_names(m, seen)
    return seen


def unknown_key_rule(root: type[BaseModel], loc: tuple, where: str, doc: str) -> str:
    """The rule text for an unknown key at ``loc``: where it is (``"in mounts[0]"``), the nearest
    valid key, the reference page."""
    key = str(loc[-1])
    choices = allowed_keys(root, loc[:-1])
    near = suggest(key, choices)
    hint = f" (did you mean {near!r}?)" if near else (f" (valid keys: {', '.join(choices)})" if choices else "")
    return f"unknown key {key!r} {where}{hint}; every key is listed in {doc}"


def allowed_keys(root: type[BaseModel], loc: tuple) -> list[str]:
    """Keys valid in the table at ``loc`` (keys and list indices, as pydantic reports them)."""
    classes: list[type[BaseModel]] = [root]
    for part in loc:
        if isinstance(part, int):
            continue
        nxt: list[type[BaseModel]] = []
        for cls in classes:
            info = cls.model_fields.get(part)
            if info is not None:
                nxt += [m for m, _ in _models_in(_annotation(info))]
        if not nxt:
            return []
        classes = nxt
    return list(dict.fromkeys(k for cls in classes for k in cls.model_fields))


def suggest(word: str, choices: list[str]) -> str | None:
    """The choice nearest to a misspelt ``word``, or None when none is near."""
    hits = difflib.get_close_matches(str(word), choices, n=1, cutoff=0.6)
    if not hits:
        lower = {c.lower(): c for c in choices}
        hits = difflib.get_close_matches(str(word).lower(), list(lower), n=1, cutoff=0.6)
        hits = [lower[h] for h in hits]
    return hits[0] if hits else None


def check_reference(root: type[BaseModel], table: Mapping[str, RefEntry]) -> tuple[list[str], list[str]]:
    """``(keys of the schema without an entry, entries that name no key)``."""
    paths = [k.path for k in walk(root)]
    return [p for p in paths if p not in table], [p for p in table if p not in paths]


# -- output ----------------------------------------------------------------------------------
def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def markdown(root: type[BaseModel], table: Mapping[str, RefEntry], *, title: str, intro: str) -> str:
    """The reference page: one table of keys per TOML section, in the order of the schema."""
    keys = walk(root)
    lines = [f"# {title}", "", intro.strip(), ""]
    sections: dict[str, list[KeyDoc]] = {}
    for k in keys:
        sections.setdefault(k.section, []).append(k)
    for section, members in sections.items():
        lines.append(f"## `{section}`" if section != "(top level)" else "## Top level")
        lines.append("")
        head = table.get(_section_path(members[0].path))
        if head is not None and section != "(top level)":
            lines += [head.description, ""]
        lines.append("| key | type | unit | default | rule | description |")
        lines.append("| --- | --- | --- | --- | --- | --- |")
        for k in members:
            ref = table.get(k.path, RefEntry("?", "(not documented)"))
            if k.kind in ("table", "array of tables", "table or list"):
                default = "**required**" if k.required else "optional"
                where = f"[[{k.path.replace('[]', '')}]]" if k.kind == "array of tables" else f"[{k.path.replace('[]', '')}]"
                desc = f"{ref.description} Keys: `{where}` below."
                lines.append(f"| `{k.key}` | {_cell(k.type)} | {_cell(ref.unit)} | {default} | {_cell(k.rule)} | {_cell(desc)} |")
                continue
            default = "**required**" if k.required else (f"`{k.default}`" if k.default else "absent")
            rule = _cell(k.rule)
            lines.append(f"| `{k.key}` | {_cell(k.type)} | {_cell(ref.unit)} | {default} | {rule} | {_cell(ref.description)} |")
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def _section_path(path: str) -> str:
    return path.rsplit(".", 1)[0].removesuffix("[]") if "." in path else ""


def json_schema(root: type[BaseModel], table: Mapping[str, RefEntry], *, title: str, doc_url: str) -> dict:
    """A draft-07 JSON Schema of the file with every key's description and unit."""
    schema = root.model_json_schema(ref_template="#/definitions/{model}")
    defs = schema.pop("$defs", {})
    by_owner: dict[tuple[str, str], KeyDoc] = {}
    for k in walk(root):
        by_owner.setdefault((k.owner, k.key), k)
    for owner, frag in [(root.__name__, schema), *defs.items()]:
        frag.pop("title", None)
        for name, prop in frag.get("properties", {}).items():
            k = by_owner.get((owner, name))
            prop.pop("title", None)
            if "$ref" in prop:
                prop.pop("default", None)  # a table's default is its keys' defaults, listed there
            if k is None:
                continue
            ref = table.get(k.path)
            if ref is None:
                continue
            unit = f" [{ref.unit}]" if ref.unit and ref.unit != "1" else ""
            text = ref.description + unit
            prop["description"] = text
            prop["markdownDescription"] = f"**{k.path}**{unit}: {ref.description}" + (f"\n\nRule: {k.rule}" if k.rule else "")
    out = {"$schema": "http://json-schema.org/draft-07/schema#"}
    out.update(schema)
    out.update(title=title, description=f"Every key, its unit and its rules: {doc_url}")
    if defs:
        out["definitions"] = defs
    return _without_null(out)


def _without_null(frag: Any) -> Any:
    """TOML has no null: an optional key is simply absent, so drop the ``null`` branches."""
    if isinstance(frag, list):
        return [_without_null(f) for f in frag]
    if not isinstance(frag, dict):
        return frag
    out = {k: _without_null(v) for k, v in frag.items()}
    if "anyOf" in out:
        branches = [b for b in out["anyOf"] if b != {"type": "null"}]
        if len(branches) != len(out["anyOf"]) and out.get("default", 0) is None:
            del out["default"]
        if len(branches) == 1:
            del out["anyOf"]
            out = {**branches[0], **out}
        else:
            out["anyOf"] = branches
    return out
