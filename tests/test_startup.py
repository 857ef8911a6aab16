"""Start-up: the command table against the command modules, and what `--help`, `--version`,
`import impstab` and `critical --json` import."""

from __future__ import annotations

import importlib
import json
import os
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

import impstab
import impstab.cli as cli_pkg
from impstab.cli import COMMANDS, cli, main, short_help

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"


def _command_modules():
    for info in pkgutil.iter_modules(cli_pkg.__path__):
        module = importlib.import_module(f"impstab.cli.{info.name}")
        if hasattr(module, "commands"):
            yield info.name, module


def test_table_lists_every_command_of_every_module():
    defined = {c.name: name for name, module in _command_modules() for c in module.commands}
    listed = {name: module for name, (module, _) in COMMANDS.items()}
    missing = sorted(set(defined) - set(listed))
    assert not missing, "add to impstab.cli.COMMANDS: " + "; ".join(
        f'"{n}": ("{defined[n]}", "..."),' for n in missing)
    assert listed == defined


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_table_help_is_the_commands_own(name):
    command = importlib.import_module(f"impstab.cli.{COMMANDS[name][0]}")
    command = next(c for c in command.commands if c.name == name)
    own = command.get_short_help_str(10_000)
    assert COMMANDS[name][1] == own, f'impstab.cli.COMMANDS entry: "{name}": ("{COMMANDS[name][0]}", "{own}"),'
    for limit in (30, 45, 60, 200):  # the list of --help cuts both the same way at any width
        assert short_help(COMMANDS[name][1], limit) == command.get_short_help_str(limit)


def test_group_resolves_commands_from_the_table(capsys):
    assert sorted(cli.commands) == sorted(COMMANDS)
    assert "critical" in cli.commands and "no-such" not in cli.commands
    assert cli.commands["critical"].name == "critical"
    assert main(["no-such-command"]) == 2
    assert "No such command" in capsys.readouterr().err


def test_help_lists_every_command_with_its_help(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    for name, (_, text) in COMMANDS.items():
        line = next(l for l in out.splitlines() if l.strip().startswith(name + " "))
        shown = line.strip()[len(name):].strip()
        assert text.startswith(shown.removesuffix("...")), (name, shown)


def _imported(*code_or_argv: str, env_extra: dict | None = None) -> set[str]:
    """Top-level modules loaded by a fresh interpreter running impstab's command line (or code)."""
    probe = (
        "import sys, json\n"
        "from impstab.cli import main\n"
        "try:\n    code = main(sys.argv[1:])\n"
        "finally:\n    sys.stderr.write('\\nMODULES ' + json.dumps(sorted(sys.modules)) + '\\n')\n"
    )
    env = {**os.environ, "PYTHONPATH": str(SRC), **(env_extra or {})}
    res = subprocess.run([sys.executable, "-c", probe, *code_or_argv], capture_output=True, text=True, env=env,
                         timeout=600)
    assert res.returncode == 0, res.stderr
    line = [l for l in res.stderr.splitlines() if l.startswith("MODULES ")][-1]
    return set(json.loads(line.removeprefix("MODULES ")))


NUMERICS = ("numpy", "scipy", "numba", "pydantic", "rich", "matplotlib", "xarray", "dask", "zarr")


@pytest.mark.parametrize("argv", [["--version"], ["--help"]])
def test_help_and_version_import_no_numerics(argv):
    loaded = _imported(*argv)
    assert not [m for m in NUMERICS if m in loaded]
    assert not [m for m in loaded if m.startswith(("impstab.model", "impstab.linear", "impstab.dynamics", "impstab.cli."))
                and m != "impstab.cli._common"]


def test_a_commands_help_imports_its_module_only():
    loaded = _imported("critical", "--help")
    assert "impstab.cli.core" in loaded
    assert not [m for m in loaded if m.startswith(("impstab.cli.sweep", "impstab.cli.simulate", "impstab.cli.response"))]
    assert not [m for m in NUMERICS[1:] if m in loaded]  # NumPy only (the module imports it)


def test_import_impstab_is_cheap_and_names_stay_public():
    res = subprocess.run(
        [sys.executable, "-c", "import sys, impstab; print(sorted(m for m in sys.modules if m.split('.')[0] in "
         f"{NUMERICS!r} or m.startswith('impstab.')))"],
        capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(SRC)}, timeout=120,
    )
    assert res.returncode == 0, res.stderr
    assert eval(res.stdout) == ["impstab.errors"]
    for name in impstab.__all__:
        assert getattr(impstab, name) is not None, name
    assert set(impstab.__all__) <= set(dir(impstab))
    from impstab.linear import LinearSystem, critical_load, linearize

    assert (impstab.linearize, impstab.critical_load, impstab.LinearSystem) == (linearize, critical_load, LinearSystem)
    with pytest.raises(AttributeError, match="no_such_name"):
        impstab.no_such_name  # noqa: B018


def test_critical_json_imports_no_plotting_tables_or_stores(examples):
    loaded = _imported("critical", str(examples / "imp_symmetric.toml"), "--json")
    heavy = [m for m in ("matplotlib", "xarray", "dask", "zarr", "rich", "scipy.optimize", "h5py", "pandas")
             if m in loaded]
    assert heavy == []
