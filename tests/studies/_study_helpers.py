"""Helpers for the study tests: study files in a temporary folder, model dicts as TOML."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

GRID_6x5 = """
[[parameters]]
path = "mount_rings[0].x"
values = { start = 0.1, stop = 0.4, num = 6 }
[[parameters]]
path = "mount_rings[0].k_shear"
values = { start = 5e3, stop = 5e4, num = 5, scale = "log" }
"""


def write_study(folder: Path, body: str, model: str = "imp_symmetric.toml", chunk_size: int | None = 8,
                name: str = "study.toml", header: str = "") -> Path:
    """A study file in ``folder`` on a copy of an example model (or a model file already there)."""
    folder.mkdir(parents=True, exist_ok=True)
    if (EXAMPLES / model).exists() and not (folder / model).exists():
        shutil.copy(EXAMPLES / model, folder / model)
    text = f'schema_version = 1\nmodel = "{model}"\n{header}\n{body}\n'
    if chunk_size is not None:
        text += f"[execution]\nchunk_size = {chunk_size}\n"
    path = folder / name
    path.write_text(text)
    return path


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    raise TypeError(type(v))


def to_toml(d: dict) -> str:
    """A model-file dict as TOML (top-level keys, tables and arrays of tables)."""
    lines = [f"{k} = {_value(v)}" for k, v in d.items()
             if not isinstance(v, dict) and not (isinstance(v, list) and v and isinstance(v[0], dict))]
    for k, v in d.items():
        if isinstance(v, dict):
            lines.append(f"[{k}]")
            lines += [f"{kk} = {_value(vv)}" for kk, vv in v.items()]
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            for item in v:
                lines.append(f"[[{k}]]")
                lines += [f"{kk} = {_value(vv)}" for kk, vv in item.items()]
    return "\n".join(lines) + "\n"
