"""Start-up: the command table against the command modules, what `--help`, `--version`,
`import impstab` and `critical --json` import, and the numba cache folder and its key."""

from __future__ import annotations

import importlib
import json
import os
import pkgutil
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import impstab
import impstab.cli as cli_pkg
from impstab import _numba_cache
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
    assert eval(res.stdout) == ["impstab._numba_cache", "impstab.errors"]
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


# -- the numba cache ------------------------------------------------------------------------------
def _package_copy(tmp_path: Path) -> Path:
    dest = tmp_path / "impstab"
    shutil.copytree(Path(impstab.__file__).parent, dest, ignore=shutil.ignore_patterns("__pycache__"))
    return dest


def test_key_follows_kernel_sources_and_their_imports(tmp_path):
    pkg = _package_copy(tmp_path)
    sources = _numba_cache.kernel_sources(pkg)
    names = {p.relative_to(pkg).as_posix() for p in sources}
    users = {p.relative_to(pkg).as_posix() for p in pkg.rglob("*.py")
             if _numba_cache.is_kernel_module(p.read_bytes())}
    assert users and users <= names  # every module that defines kernels
    # kernels are declared with impstab._jit's njit (numba imported only when compiling)
    assert {"linear/small_eig.py", "linear/tangent.py", "linear/engine/scan.py", "dynamics/rhs.py",
            "kinematics/so3.py", "model/mount_law.py"} <= users
    assert "precompile.py" not in names  # imports numba to find the kernels, defines none
    key = _numba_cache.source_key(pkg)
    assert _numba_cache.source_key(pkg) == key  # deterministic
    # a module no kernel reaches (a command): editing it keeps the compiled code
    (pkg / "cli" / "schema.py").write_text((pkg / "cli" / "schema.py").read_text() + "\n# edit\n")
    assert "cli/schema.py" not in names and _numba_cache.source_key(pkg) == key
    # a kernel's own file
    kernel = pkg / sorted(users)[0]
    kernel.write_text(kernel.read_text() + "\n# edit\n")
    key2 = _numba_cache.source_key(pkg)
    assert key2 != key
    # a plain module whose constant a kernel module imports (numba freezes it into the code),
    # reached through a package __init__ that re-exports it
    (pkg / "constants_only.py").write_text("LIMIT = 1.0\n")
    (pkg / "reexport").mkdir()
    (pkg / "reexport" / "__init__.py").write_text("from ..constants_only import LIMIT\n")
    (pkg / "kernel_user.py").write_text("from ._jit import njit\nfrom .reexport import (\n    LIMIT,\n)\n\n\n"
                                        "@njit(cache=True)\ndef scaled(x):\n    return LIMIT * x\n")
    key3 = _numba_cache.source_key(pkg)
    assert {"constants_only.py", "reexport/__init__.py", "kernel_user.py"} <= {
        p.relative_to(pkg).as_posix() for p in _numba_cache.kernel_sources(pkg)}
    (pkg / "constants_only.py").write_text("LIMIT = 2.0\n")
    assert _numba_cache.source_key(pkg) not in (key, key2, key3)


def test_numba_cache_folder_is_outside_the_sources_and_the_users_setting_wins(tmp_path):
    code = ("import os, impstab, numba.core.config as c; "
            "print(os.environ.get('NUMBA_CACHE_DIR')); print(c.CACHE_DIR)")
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", _numba_cache.SET_BY_IMPSTAB)}
    env["PYTHONPATH"] = str(SRC)
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert res.returncode == 0, res.stderr
    env_dir, config_dir = res.stdout.split()
    assert env_dir == config_dir == str(_numba_cache.cache_root() / "numba" / _numba_cache.source_key())
    assert not Path(env_dir).is_relative_to(SRC)
    own = tmp_path / "own"
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**env, "NUMBA_CACHE_DIR": str(own)}, timeout=300)
    assert res.stdout.split() == [str(own), str(own)]
    # inherited from an impstab process (a worker): computed again, not taken as the user's own
    stale = str(tmp_path / "parent")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**env, "NUMBA_CACHE_DIR": stale, _numba_cache.SET_BY_IMPSTAB: stale}, timeout=300)
    assert res.stdout.split() == [env_dir, env_dir]
    # numba imported before impstab: the folder still applies to impstab's kernels
    res = subprocess.run([sys.executable, "-c", "import numba; " + code], capture_output=True, text=True, env=env,
                         timeout=300)
    assert res.stdout.split() == [env_dir, env_dir]


def test_two_clones_share_the_compiled_kernels_and_other_code_keeps_numbas_layout(tmp_path):
    """A kernel compiled by one copy of the package is loaded, not compiled, by a copy at another
    path (later time stamps: a fresh clone), from the same folder inside the shared cache; numba's
    own layout stays for code outside the package."""
    first, second = tmp_path / "clone-a" / "src", tmp_path / "clone-b" / "src"
    _package_copy(first)
    (second / "impstab").parent.mkdir(parents=True)
    shutil.copytree(first / "impstab", second / "impstab")
    os.utime(second / "impstab" / "kinematics" / "so3.py")  # newer than the first clone's
    (tmp_path / "other.py").write_text("import numba\n\n@numba.njit(cache=True)\ndef twice(x):\n    return 2 * x\n")
    code = ("import json, os, numpy as np, impstab._jit as jit, impstab._numba_cache as c; jit.require_compiled(); "
            "from impstab.kinematics.so3 import _skew; import other; _skew(np.ones(3)); other.twice(1.0); "
            "print(json.dumps([c.kernel_folder().as_posix(), sum(_skew.stats.cache_hits.values()), "
            "sum(_skew.stats.cache_misses.values()), sum(other.twice.stats.cache_hits.values())]))")
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", _numba_cache.SET_BY_IMPSTAB)}
    env["XDG_CACHE_HOME"] = str(tmp_path / "cache")
    out = []
    for src in (first, second):
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                             env={**env, "PYTHONPATH": os.pathsep.join([str(src), str(tmp_path)])})
        assert res.returncode == 0, res.stderr
        out.append(json.loads(res.stdout.splitlines()[-1]))
    (folder_a, hits_a, misses_a, _), (folder_b, hits_b, misses_b, other_hits) = out
    assert folder_a == folder_b and folder_a.startswith((tmp_path / "cache" / "impstab" / "numba").as_posix())
    assert (hits_a, misses_a) == (0, 1) and (hits_b, misses_b) == (1, 0)
    assert any((Path(folder_a) / "impstab" / "kinematics").glob("so3._skew-*.nbi"))
    # the other module (one path) was cached beside impstab's kernels in numba's layout, and loaded
    assert other_hits == 1 and not (Path(folder_a) / "other").exists()


def test_cache_root_is_the_users_cache_folder_else_the_environments(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert _numba_cache.cache_root() == tmp_path / "xdg" / "impstab"
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/cache")  # not absolute: ignored (XDG base directories)
    assert _numba_cache.cache_root() == Path.home() / ".cache" / "impstab"
    (tmp_path / "a-file").write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "a-file" / "cache"))  # cannot be made
    expected = Path(sys.prefix) / "var" / "cache" / "impstab"
    if sys.prefix != sys.base_prefix and os.access(sys.prefix, os.W_OK):
        assert _numba_cache.cache_root() == expected
    else:
        assert _numba_cache.cache_root() == tmp_path / "a-file" / "cache" / "impstab"


def test_prune_keeps_the_most_recently_compiled_sources(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.delenv(_numba_cache.SET_BY_IMPSTAB, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    current = _numba_cache.cache_dir()
    assert current.parent == tmp_path / "impstab" / "numba"
    (current / "env").mkdir(parents=True)
    for k in range(5):  # key folders compiled 5 to 1 days ago; one never completed (its folder's time)
        marker = current.parent / f"old{k}" / "env" / _numba_cache.MARKER
        marker.parent.mkdir(parents=True)
        marker.write_text("done\n")
        os.utime(marker, (1e9 - 86400 * (5 - k),) * 2)
    os.utime(current.parent / "old0", (1e9 + 1,) * 2)  # a recent folder, but its marker is the oldest
    (current.parent / "partial" / "env").mkdir(parents=True)
    os.utime(current.parent / "partial", (1e9 - 86400 * 10,) * 2)
    environment = tmp_path / "venv" / "var" / "cache" / "impstab" / "numba"  # where earlier versions kept kernels
    (environment / "somekey").mkdir(parents=True)
    removed = _numba_cache.prune(keep=3, environment=environment)
    assert sorted(p.name for p in removed) == ["numba", "old0", "old1", "old2", "partial"]
    assert sorted(p.name for p in current.parent.iterdir()) == sorted(["old3", "old4", current.name])
    assert not environment.exists() and environment.parent.is_dir()
    # the environment's folder in use (the user's cache folder cannot be written): kept
    assert current.parent not in _numba_cache.prune(keep=3, environment=current.parent) and current.is_dir()
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "own"))  # the user's own folder: never pruned
    assert _numba_cache.prune(keep=1) == [] and (current.parent / "old4").is_dir()


# -- the precompile step ---------------------------------------------------------------------------
@pytest.mark.parametrize("from_examples", [True, False])
def test_precompile_cases_are_valid_command_lines(tmp_path, monkeypatch, from_examples):
    from impstab import precompile
    from impstab.model import load_model

    if not from_examples:  # an installed package: no examples beside it, models written instead
        monkeypatch.setattr(precompile, "EXAMPLES", tmp_path / "missing")
    todo = precompile.cases(tmp_path)
    commands = {argv[0] for _, argv in todo}
    assert {"critical", "simulate", "response", "sweep", "locus"} <= commands <= set(COMMANDS)
    for label, argv in todo:
        command = cli.commands[argv[0]]
        command.make_context(argv[0], list(argv[1:]))  # options and arguments parse
        model = Path(argv[1])
        assert model.is_file(), label
        if model.name.startswith("imp_"):
            load_model(model)
        elif argv[0] == "sweep":
            impstab.load_study(model)
    if not from_examples:
        assert all(Path(argv[1]).is_relative_to(tmp_path) for _, argv in todo)


@pytest.mark.parametrize("from_examples", [True, False])
def test_precompile_warm_ups_run(tmp_path, monkeypatch, from_examples):
    """The first phase's calls (the shared kernels, compiled side by side) run on the bundled
    examples and on the models written for an installed package."""
    from impstab import precompile

    if not from_examples:
        monkeypatch.setattr(precompile, "EXAMPLES", tmp_path / "missing")
    first = precompile.warm_ups(precompile._models(tmp_path))
    assert [label for label, _, _ in first] == ["stability engine", "tangent stiffness", "right-hand side, real and complex",
                                                "fixed-step integrator"]
    for label, func, args in first:
        assert precompile._warm(label, func, args, quiet=True) == [], label


def test_precompile_stops_at_a_complete_cache_and_keeps_the_users_own(tmp_path, monkeypatch, capsys):
    from impstab import precompile

    own = tmp_path / "own"
    (own / _numba_cache.versions_tag()).mkdir(parents=True)
    (own / _numba_cache.versions_tag() / precompile.MARKER).write_text("done\n")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(own))
    monkeypatch.delenv(_numba_cache.SET_BY_IMPSTAB, raising=False)
    # precompile sets IMPSTAB_JIT = compiled for its worker processes: restored after the test (the
    # later tests of this process and their subprocesses run under the default policy)
    monkeypatch.setenv("IMPSTAB_JIT", "auto")
    assert precompile.main(["--quiet"]) == 0
    assert "already compiled" in capsys.readouterr().out
    assert precompile.main(["--clean"]) == 0
    assert "not removed" in capsys.readouterr().out
    assert (own / _numba_cache.versions_tag() / precompile.MARKER).is_file()


def test_concurrent_cache_saves_of_one_kernel_keep_every_signature(tmp_path, monkeypatch):
    """numba's cache index update (read, choose a free data file, write) under impstab's lock:
    eight writers saving different signatures of one kernel at once, each pausing between reading
    the index and writing it back, leave eight index entries, each naming its own data. Without
    the lock they choose the same data file and entries are lost (checked)."""
    import threading
    import time

    from numba.core import caching

    from impstab._numba_cache import lock_cache_files

    lock_cache_files()
    read_index = caching.IndexDataCacheFile._load_index

    def slow_read(self):
        out = read_index(self)
        time.sleep(0.02)  # another writer reads the same index meanwhile
        return out

    monkeypatch.setattr(caching.IndexDataCacheFile, "_load_index", slow_read)
    files = [caching.IndexDataCacheFile(str(tmp_path), "kernel-1", ("stamp", 1)) for _ in range(8)]
    threads = [threading.Thread(target=f.save, args=((f"signature {i}",), f"machine code {i}"))
               for i, f in enumerate(files)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    index = caching.IndexDataCacheFile(str(tmp_path), "kernel-1", ("stamp", 1))
    for i in range(8):
        assert index.load((f"signature {i}",)) == f"machine code {i}"
