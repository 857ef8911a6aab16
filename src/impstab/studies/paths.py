"""Parameter paths: dotted locations in a model file, such as ``mount_rings[0].k_shear``.

A path is checked against the model-file schema (:mod:`impstab.model.schema`) and against the
base model before anything runs: every key must exist in the schema, every index in the base
model, and the path must end at one value (a number, an integer, a flag or a word). The result
is a :class:`ParameterPath` that validates candidate values with the schema's own rule for that
field and sets them in a copy of a model-file dict.
"""

from __future__ import annotations

import re
import types
import typing
from dataclasses import dataclass
from typing import Annotated, Any, Literal, Union

import numpy as np
from pydantic import BaseModel, TypeAdapter, ValidationError

from ..model.assemble import rule_text
from ..model.schema import FlagMark, IntegerMark, ModelFile, RangeMark, _strip

__all__ = ["ParameterPath", "parse_path", "resolve_path", "set_values", "variant_dict"]

_SEGMENT = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)$")
_FROZEN = ("schema_version", "name")


def parse_path(path: str) -> tuple[str | int, ...]:
    """``"mounts[1].position[0]"`` -> ``("mounts", 1, "position", 0)``; ValueError if malformed."""
    if not isinstance(path, str) or not path.strip():
        raise ValueError("must be a dotted path such as 'mount_rings[0].k_shear'")
    out: list[str | int] = []
    for part in path.strip().split("."):
        m = _SEGMENT.match(part)
        if m is None:
            raise ValueError(f"segment {part!r} is not a key optionally followed by [index]")
        out.append(m.group(1))
        out.extend(int(i) for i in re.findall(r"\[(\d+)\]", m.group(2)))
    return tuple(out)


def _location(segments: tuple) -> str:
    text = ""
    for s in segments:
        text += f"[{s}]" if isinstance(s, int) else ("." if text else "") + s
    return text or "(model file)"


def _is_list(tp: Any) -> bool:
    return typing.get_origin(_strip(tp)[0]) is list


def _pick_branch(tp: Any, value: Any) -> Any:
    """For a union of list shapes (a 3-vector or a 3x3 matrix), the branch the value has."""
    nested = isinstance(value, list) and bool(value) and isinstance(value[0], list)
    for arg in typing.get_args(_strip(tp)[0]):
        if not _is_list(arg):
            continue
        inner = typing.get_args(_strip(arg)[0])[0]
        if _is_list(inner) == nested:
            return arg
    return tp


@dataclass(frozen=True, eq=False)
class ParameterPath:
    """A validated path to one scalar value of the model file.

    Attributes
    ----------
    path : str
        The path as written, e.g. ``"mount_rings[0].x"``.
    segments : tuple of str or int
        Keys and list indices.
    kind : {"float", "int", "bool", "str"}
        Type of the value at the end of the path.
    choices : tuple of str
        Allowed words when the field is a choice (empty otherwise).
    """

    path: str
    segments: tuple[str | int, ...]
    kind: str
    choices: tuple[str, ...]
    adapter: TypeAdapter
    mark: Any = None

    def check(self, value: Any) -> Any:
        """The value as the schema accepts it; ValueError with the schema's rule otherwise."""
        try:
            return self.adapter.validate_python(value)
        except ValidationError as err:
            raise ValueError(rule_text(err.errors()[0], self.mark)) from None


def resolve_path(path: str, base: dict) -> ParameterPath:
    """Check ``path`` against the model-file schema and the base model ``base``.

    Raises
    ------
    ValueError
        With a message that names the failing part of the path.
    """
    segments = parse_path(path)
    if segments[0] in _FROZEN:
        raise ValueError(f"{segments[0]!r} cannot be varied")
    tp: Any = ModelFile
    value: Any = base
    for j, seg in enumerate(segments):
        where = _location(segments[:j])
        core, _ = _strip(tp)
        if isinstance(seg, str):
            if typing.get_origin(core) is list or typing.get_origin(core) in (Union, types.UnionType):
                raise ValueError(f"{where} is a list: index it before the key, e.g. {where}[0].{seg}")
            if not (isinstance(core, type) and issubclass(core, BaseModel)):
                raise ValueError(f"{where} is a single value, it has no key {seg!r}")
            fields = core.model_fields
            if seg not in fields:
                known = ", ".join(fields)
                raise ValueError(f"{where} has no key {seg!r} (known keys: {known})")
            info = fields[seg]
            tp = Annotated[(info.annotation, *info.metadata)] if info.metadata else info.annotation
            value = value.get(seg) if isinstance(value, dict) else None
        else:
            if typing.get_origin(core) in (Union, types.UnionType):
                tp = _pick_branch(tp, value)
                core, _ = _strip(tp)
            if typing.get_origin(core) is not list:
                raise ValueError(f"{where} is not a list, it cannot take an index [{seg}]")
            if not isinstance(value, list):
                raise ValueError(f"{where} is not set in the base model, so [{seg}] does not exist")
            if seg >= len(value):
                count = f"{len(value)} entr{'y' if len(value) == 1 else 'ies'}"
                raise ValueError(f"{where} has {count} in the base model, so [{seg}] does not exist")
            tp = typing.get_args(core)[0]
            value = value[seg]
    core, meta = _strip(tp)
    choices: tuple[str, ...] = ()
    if typing.get_origin(core) is Literal:
        kind, choices = "str", tuple(str(a) for a in typing.get_args(core))
    elif core in (float, int, bool, str):
        kind = core.__name__
    else:
        raise ValueError(
            f"{_location(segments)} is a table or a list, not one value: give the path to a single "
            "number, e.g. mounts[0].position[1]"
        )
    adapter = TypeAdapter(Annotated[(core, *meta)] if meta else core)
    mark = next((m for m in meta if isinstance(m, (RangeMark, IntegerMark, FlagMark))), None)
    return ParameterPath(path, segments, kind, choices, adapter, mark)


def set_values(base: dict, paths: list, values: list[Any]) -> dict:
    """A copy of the model-file dict ``base`` with each path set to its value.

    ``paths`` are :class:`ParameterPath` objects or segment tuples (from :func:`parse_path`).
    Only the containers along the paths are copied; ``base`` is never modified. Missing optional
    tables on a path (e.g. ``[propeller]``) are created.
    """
    root = dict(base)
    for par, val in zip(paths, values):
        cur: Any = root
        segs = par.segments if isinstance(par, ParameterPath) else tuple(par)
        for seg in segs[:-1]:
            if isinstance(cur, dict):
                child = cur.get(seg)
                child = {} if child is None else child
            else:
                child = cur[seg]
            child = list(child) if isinstance(child, list) else dict(child)
            cur[seg] = child
            cur = child
        cur[segs[-1]] = val
    return root


def variant_dict(base: dict, segments, values) -> dict:
    """The model-file dict of one design: ``base`` with each path set to its value."""
    vals = [v.item() if isinstance(v, np.generic) else v for v in values]
    return set_values(base, [tuple(s) for s in segments], vals)
