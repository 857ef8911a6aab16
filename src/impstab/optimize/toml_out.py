"""A model-file dict written back as TOML (the chosen design of an optimisation).

Python's standard library reads TOML but does not write it; this writes the subset model files
use: scalars, lists (nested), tables and arrays of tables at any depth. Floats are written with
``repr`` (the shortest text that reads back to the same float), so the file round-trips exactly
through :func:`impstab.load_model`.
"""

from __future__ import annotations

import json
import math
from typing import Any

__all__ = ["dumps"]


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"cannot write the non-finite number {v!r} to a model file")
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    raise TypeError(f"cannot write a {type(v).__name__} to a model file")


def _is_tables(v: Any) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def _key(k: str) -> str:
    return k if k.replace("_", "").replace("-", "").isalnum() else json.dumps(k)


def _table(d: dict, prefix: str, out: list[str]) -> None:
    for k, v in d.items():
        if not isinstance(v, dict) and not _is_tables(v):
            out.append(f"{_key(k)} = {_value(v)}")
    for k, v in d.items():
        name = f"{prefix}.{_key(k)}" if prefix else _key(k)
        if isinstance(v, dict):
            out.append(f"\n[{name}]")
            _table(v, name, out)
        elif _is_tables(v):
            for item in v:
                out.append(f"\n[[{name}]]")
                _table(item, name, out)


def dumps(data: dict, header: str = "") -> str:
    """``data`` (a parsed model file) as TOML text, after the comment lines of ``header``."""
    out = [f"# {line}" if line else "#" for line in header.splitlines()]
    _table(data, "", out)
    return "\n".join(out).lstrip("\n") + "\n"
