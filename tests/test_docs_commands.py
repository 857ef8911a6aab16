"""The documentation matches the command line: every `impstab ...` command shown in README.md and
docs/*.md runs with exit code 0 (in a scratch folder with a copy of the examples, outputs
written there), and every option the text names exists.

Lines that show a command's synopsis (``[--json]``, ``MODEL.toml``, ``a|b``) are not run, but
their options are checked; commands that need a running Dask scheduler are not run either.
"""

from __future__ import annotations

import re
import shlex
import shutil
from pathlib import Path

import pytest

from impstab.cli import cli, main

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
_FENCE = re.compile(r"^```(\w*)\s*$")
_PLACEHOLDER = re.compile(r"^([A-Z][A-Z0-9_]*)([.:,=/].*)?$")
_NEEDS_CLUSTER = ("--scheduler",)


def _blocks(text: str):
    """``(language, first line number, lines)`` of each fenced code block."""
    lang, start, lines, inside = "", 0, [], False
    for n, line in enumerate(text.splitlines(), 1):
        m = _FENCE.match(line.strip())
        if m and not inside:
            lang, start, lines, inside = m.group(1), n + 1, [], True
        elif line.strip() == "```" and inside:
            inside = False
            yield lang, start, lines
        elif inside:
            lines.append(line)


def shown_commands() -> list[tuple[str, list[str]]]:
    """``(where, argv)`` of every impstab command line in a fenced block of the pages."""
    out = []
    for page in PAGES:
        for lang, start, lines in _blocks(page.read_text(encoding="utf-8")):
            if lang in ("python", "toml", "py"):
                continue
            joined, first = "", None
            for k, line in enumerate(lines):
                text = line.strip()
                if joined:
                    joined += " " + text
                elif text.startswith(("impstab ", "$ impstab ")):
                    joined, first = text.removeprefix("$ "), start + k
                else:
                    continue
                if joined.endswith("\\"):
                    joined = joined[:-1]
                    continue
                out.append((f"{page.relative_to(ROOT)}:{first}", shlex.split(joined, comments=True)))
                joined = ""
    return out


def _is_synopsis(argv: list[str]) -> bool:
    for tok in argv[1:]:
        value = tok.split("=", 1)[1] if tok.startswith("--") and "=" in tok else tok
        if tok.startswith("[") or tok.endswith("]") or "|" in tok or tok in ("...", "..") or _PLACEHOLDER.match(value):
            return True
    return False


COMMANDS = shown_commands()
RUNNABLE = [(w, a) for w, a in COMMANDS if not _is_synopsis(a) and not any(t in a for t in _NEEDS_CLUSTER)]


def _options(name: str) -> set[str]:
    cmd = cli.commands[name]
    return {o for p in cmd.params for o in (*p.opts, *p.secondary_opts)}


ALL_OPTIONS = set().union(*(_options(n) for n in cli.commands)) | {"--help", "-h", "--version"}


def test_the_pages_show_commands():
    names = {a[1] for _, a in COMMANDS}
    assert {"check", "critical", "modes", "locus", "simulate", "added-mass", "sweep", "map", "schema"} <= names
    assert len(RUNNABLE) >= 15


@pytest.mark.parametrize("where,argv", COMMANDS, ids=[w for w, _ in COMMANDS])
def test_every_option_shown_exists(where, argv):
    assert argv[1] in cli.commands, f"{where}: no command {argv[1]!r}"
    known = _options(argv[1]) | {"--help", "-h"}
    for tok in argv[2:]:
        for flag in re.findall(r"(?<![\w-])(--?[a-z][a-z0-9-]*)", tok.strip("[]")):
            if tok.startswith(("[", "-")) or tok.startswith(flag):
                assert flag in known, f"{where}: {argv[1]} has no option {flag}"


def test_every_option_named_in_the_text_exists():
    """Inline `--flag` and `impstab cmd --flag` in the prose name real options."""
    bad = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        prose = re.sub(r"```.*?```", "", text, flags=re.S)
        for span in re.findall(r"`([^`\n]+)`", prose):
            span = span.strip()
            if span.startswith("impstab "):
                words = span.split()
                if len(words) > 1 and words[1] in cli.commands:
                    known = _options(words[1]) | {"--help"}
                    bad += [(page.name, span, f) for f in re.findall(r"(?<![\w-])--[a-z][a-z0-9-]*", span) if f not in known]
            elif span.startswith("--"):
                for f in re.findall(r"--[a-z][a-z0-9-]*", span.split()[0]):
                    if f not in ALL_OPTIONS:
                        bad.append((page.name, span, f))
    assert bad == [], f"options named in the docs that no command has: {bad}"


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    """A scratch folder with the examples, where the sweeps shown have run (the other commands
    use their stores)."""
    import os

    folder = tmp_path_factory.mktemp("docs")
    shutil.copytree(ROOT / "examples", folder / "examples")
    old = os.getcwd()
    os.chdir(folder)
    try:
        codes = {w: main(a[1:]) for w, a in RUNNABLE if a[1] == "sweep"}
    finally:
        os.chdir(old)
    return folder, codes


#: exit code and stderr of each distinct command line run so far: a command shown on several pages
#: (the README's quick tour repeats the guides') runs once, in the same scratch folder
_RAN: dict[tuple[str, ...], tuple[int, str]] = {}


@pytest.mark.parametrize("where,argv", RUNNABLE, ids=[w for w, _ in RUNNABLE])
def test_every_command_shown_runs(where, argv, workdir, monkeypatch, capsys):
    folder, sweeps = workdir
    monkeypatch.chdir(folder)
    if argv[1] == "sweep":
        code, err = sweeps[where], ""
    elif tuple(argv) in _RAN:
        code, err = _RAN[tuple(argv)]
    else:
        code = main(argv[1:])
        err = capsys.readouterr().err
        _RAN[tuple(argv)] = code, err
    assert code == 0, f"{where}: {' '.join(argv)} exited {code}: {err}"
