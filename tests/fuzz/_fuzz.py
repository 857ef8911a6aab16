"""Shared parts of the fuzz tests: hostile values, mutations of valid files, and the one check
every run of the command line must pass (exit 0 or 2, one line for 2, nothing left behind)."""

from __future__ import annotations

import contextlib
import copy
import io
import json
import math
from pathlib import Path

from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

from impstab.cli import main

def fuzz(examples: int) -> settings:
    """The profile of every fuzz test: the same ``examples`` on every run, no deadline, no database."""
    return settings(max_examples=examples, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

HOSTILE_STRINGS = ["", "x", "\x1b[2J\x1b]0;title\x07", "[/bold][red]", "\u202eevil", "a\nb", "\x00", "1", "true", "nan",
                   "é" * 5000]
SPECIAL_NUMBERS = [0, -0.0, 1, -1, 3.0, 1000, 1001, 1e308, -1e308, 1e200, 1e-300, 5e-324, 1e15, 1e13, 1e9, 1e-12,
                   math.inf, -math.inf, math.nan, 10**400, -(10**30), 360.0, 2**63]


def nested(depth: int) -> list:
    out: list = [1.0]
    for _ in range(depth):
        out = [out]
    return out


scalars = st.one_of(
    st.booleans(),
    st.sampled_from(SPECIAL_NUMBERS),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**20), max_value=10**20),
    st.sampled_from(HOSTILE_STRINGS),
    st.text(st.characters(exclude_categories=("Cs",)), max_size=8),
)
hostile = st.one_of(
    scalars,
    st.lists(scalars, max_size=7),
    st.lists(st.lists(st.sampled_from([0.0, 1.0, True, "a"]), min_size=3, max_size=3), min_size=3, max_size=6),
    st.dictionaries(st.sampled_from(["a", "mass", "x", "\x1b[1m"]), scalars, max_size=2),
    st.integers(min_value=33, max_value=120).map(nested),
    st.sampled_from([10_000, 50_000]).map(lambda n: [0.0] * n),
)


def leaves(doc, path=()):
    """Every location of a parsed TOML document (tables, lists and values), as key/index paths."""
    out = [path]
    if isinstance(doc, dict):
        for k, v in doc.items():
            out += leaves(v, path + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            out += leaves(v, path + (i,))
    return out


def _get(doc, path):
    for p in path:
        doc = doc[p]
    return doc


@st.composite
def mutated(draw, bases: list[dict], max_changes: int = 3, gentle: bool = False):
    """A copy of one of ``bases`` with up to ``max_changes`` changes: a number scaled (by 0.5 to 2
    when ``gentle``, by up to 1e400 otherwise), a value replaced by a hostile one, a key removed,
    an unknown key added, a value wrapped in a list."""
    doc = copy.deepcopy(draw(st.sampled_from(bases)))
    for _ in range(draw(st.integers(min_value=0 if gentle else 1, max_value=max_changes))):
        paths = [p for p in leaves(doc) if p]
        path = draw(st.sampled_from(paths))
        parent, key = _get(doc, path[:-1]), path[-1]
        value = parent[key]
        numeric = isinstance(value, (int, float)) and not isinstance(value, bool)
        action = "scale" if gentle else draw(st.sampled_from(["scale", "replace", "replace", "delete", "unknown", "wrap"]))
        if action == "scale" and numeric:
            factor = draw(st.floats(0.5, 2.0)) if gentle else draw(st.sampled_from([-1.0, 0.0, 1e-300, 1e-9, 1e9, 1e300, 1.5]))
            scaled = value * factor
            parent[key] = int(scaled) if isinstance(value, int) and math.isfinite(scaled) and abs(scaled) < 2**62 else scaled
        elif action == "scale" or gentle:
            continue
        elif action == "replace":
            parent[key] = draw(hostile)
        elif action == "delete":
            del parent[key]
        elif action == "unknown" and isinstance(parent, dict):
            parent[draw(st.sampled_from(["masss", "\x1b[2Jkey", "k\u202e", "x y"]))] = draw(scalars)
        elif action == "wrap":
            parent[key] = [value]
    return doc


def run_cli(*argv: str) -> tuple[int, str, str]:
    """``impstab ARGV`` in this process: exit code, stdout, stderr."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


def check_run(code: int, out: str, err: str, folder: Path | None = None, as_json: bool = False,
              expected: tuple[str, ...] = ()) -> None:
    """The promise of the command line, whatever the input."""
    assert code in (0, 2), f"exit {code}: {err}"
    assert "Traceback" not in err and "Traceback" not in out, err
    for stream in (out, err):
        assert "\x1b" not in stream and "\x07" not in stream and "\u202e" not in stream, repr(stream[:300])
    lines = err.splitlines()
    assert all(line.startswith("impstab: ") for line in lines), err
    if code == 2:
        assert len(lines) == 1 and lines[0].startswith("impstab: error: "), err
        assert "np.float64" not in err and "Value error" not in err
        if folder is not None:
            assert sorted(p.name for p in folder.iterdir()) == [], "files left behind"
    elif as_json:
        assert out.count("\n") == 1
        json.loads(out)
    if code == 0 and folder is not None:
        left = sorted(p.name for p in folder.iterdir())
        assert all(name in expected for name in left), left
