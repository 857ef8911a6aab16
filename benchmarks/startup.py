"""Start-up: how soon impstab answers, against the interpreter importing its own base, same run.

Baseline: ``python -c "import numpy, scipy.linalg, pydantic"``, what any tool of this kind pays
before it computes anything (the goal: a warm ``critical --json`` within 2x of it), run with the
BLAS thread count impstab's command line sets (:mod:`impstab._blas`).

impstab, each in a fresh process (``--repeat`` rounds, each running the baseline and every command
once in turn; medians, and ratios as the median over the rounds of the command over the baseline
of the same round; wall time and the child's CPU time, user + sys, which a loaded machine
disturbs less):

* ``impstab --version``, ``impstab --help``;
  (``python -m impstab.precompile`` runs first: kernels in the cache and impstab's bytecode written,
  as a second run of any command finds them; the baseline's libraries have theirs from ``pip``)
* ``impstab critical examples/imp_symmetric.toml --json``, warm (its kernels in the cache), and
  the same with ``IMPSTAB_JIT=compiled`` (numba imported and the kernels loaded from the cache,
  which is what every run paid before single-model analyses ran their kernels interpreted, see
  ``impstab._jit``); the CPU ratio of a warm ``critical --json`` on every other example too;
* the first ``critical`` and the first ``simulate`` with an empty kernel cache (each its own
  empty ``NUMBA_CACHE_DIR``: numba compiles), against the first of each after
  ``python -m impstab.precompile`` filled impstab's own cache in an empty user cache folder
  (numba loads), and the first of each in a copy of the package at another path, a second clone
  that finds the kernels the first compiled (:mod:`impstab._numba_cache`); the precompile step
  itself is timed too (``--skip-cold`` leaves these out: minutes);
* where a warm ``critical`` spends its time: ``python -X importtime`` self times summed by
  top-level package; in one process, whether numba was imported and the seconds spent in
  interpreted kernels; and under ``IMPSTAB_JIT=compiled``, ``import numba`` and the load of each
  compiled kernel from the cache.

Prints tables and ratios and ends with one JSON line.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import impstab as impstab_package
from impstab._blas import prefer_single_thread

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "imp_symmetric.toml"
BASELINE = [sys.executable, "-c", "import numpy, scipy.linalg, pydantic"]


def impstab_command() -> list[str]:
    """The ``impstab`` console script beside this interpreter, else ``python -m impstab``."""
    script = Path(sys.executable).parent / "impstab"
    return [str(script)] if script.is_file() else [sys.executable, "-m", "impstab"]


def run(argv: list[str], env: dict | None = None) -> tuple[float, float, subprocess.CompletedProcess]:
    """(wall s, CPU s of the child, the finished process)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    res = subprocess.run(argv, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} failed ({res.returncode}):\n{res.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, res


COMPILED = {**os.environ, "IMPSTAB_JIT": "compiled"}
#: the baseline's environment: the BLAS thread count impstab's command line sets (impstab._blas),
#: so that both import numpy's BLAS alike
SINGLE_THREAD = dict(os.environ)
prefer_single_thread(SINGLE_THREAD)
OTHER_EXAMPLES = ["imp_asymmetric", "imp_damped", "imp_fluid", "imp_viscoelastic", "imp_beam_mounts",
                  "imp_hardening"]


def rounds(rows: dict[str, tuple], repeat: int) -> dict[str, list[tuple[float, float]]]:
    """``repeat`` rounds, each running every row once in turn (``(label, argv, [env])``): its
    ``(wall s, CPU s)`` per round. Rows measured in the same round see the machine at the same
    speed; on a shared machine that drifts by tens of percent within a minute, a row measured
    in a block of its own would carry the drift into its ratio to the baseline."""
    out: dict[str, list[tuple[float, float]]] = {key: [] for key in rows}
    for _ in range(repeat):
        for key, (_, argv, *env) in rows.items():
            out[key].append(run(argv, *env)[:2])
    return out


def paired_ratio(runs: dict[str, list[tuple[float, float]]], key: str, which: int) -> float:
    """The median over the rounds of ``key``'s time over the baseline's in the same round
    (``which``: 0 wall, 1 CPU)."""
    return statistics.median(r[which] / b[which] for r, b in zip(runs[key], runs["baseline"]))


def importtime_breakdown(argv: list[str], repeat: int) -> dict[str, float]:
    """Median over runs of ``-X importtime`` self times (s) summed by top-level package."""
    sums: list[dict[str, float]] = []
    for _ in range(repeat):
        res = subprocess.run([sys.executable, "-X", "importtime", *argv], capture_output=True, text=True)
        by: dict[str, float] = {}
        for line in res.stderr.splitlines():
            if not line.startswith("import time:") or "self [us]" in line:
                continue
            self_us, _, name = line.removeprefix("import time:").split("|", 2)
            top = name.strip().split(".")[0]
            by[top] = by.get(top, 0.0) + int(self_us) * 1e-6
        sums.append(by)
    names = set().union(*sums)
    return {n: statistics.median(s.get(n, 0.0) for s in sums) for n in names}


_INTERPRETED = r"""
import json, sys, time
from impstab import _jit
from impstab.model import load_model
from impstab.linear.critical_thrust import critical_thrust
model = load_model(sys.argv[1])
t = time.process_time(); critical_thrust(model); first = time.process_time() - t
print(json.dumps({"first_call": first, "interpreted_s": _jit._spent, "numba": "numba" in sys.modules,
                  "compiled": _jit.compiled()}))
"""

_KERNEL_LOADS = r"""
import json, sys, time
t0 = time.process_time()
import numba
t_numba = time.process_time() - t0
from numba.core.dispatcher import Dispatcher
loads = []
original = Dispatcher._compile_for_args
def timed(self, *args, **kws):
    t = time.process_time()
    try:
        return original(self, *args, **kws)
    finally:
        loads.append((self.py_func.__module__ + "." + self.py_func.__qualname__, time.process_time() - t))
Dispatcher._compile_for_args = timed
from impstab.model import load_model
from impstab.linear.critical_thrust import critical_thrust
model = load_model(sys.argv[1])
t = time.process_time(); critical_thrust(model); first = time.process_time() - t
t = time.process_time(); critical_thrust(model); second = time.process_time() - t
print(json.dumps({"import_numba": t_numba, "loads": loads, "first_call": first, "second_call": second}))
"""


def cold_and_precompiled(impstab: list[str], tmp: Path) -> dict[str, float]:
    """First ``critical`` / ``simulate`` in empty caches, precompile, both after it, and both in a
    copy of the package at another path, a second clone (wall s)."""
    critical = [*impstab, "critical", str(EXAMPLE), "--json"]
    simulate = [*impstab, "simulate", str(EXAMPLE), "--thrust", "19000", "--duration", "1", "--no-plot",
                "-o", str(tmp / "sim.csv"), "--json"]
    out = {}
    for name, argv in (("critical", critical), ("simulate", simulate)):
        env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp / f"empty-{name}")}
        wall, cpu, _ = run(argv, env)
        out[f"cold_{name}_s"], out[f"cold_{name}_cpu_s"] = wall, cpu
        print(f"  first {name:9s} empty cache      {wall:7.1f} s  (cpu {cpu:6.1f} s)", flush=True)
    # impstab's own cache (not a NUMBA_CACHE_DIR of the user's), in an empty user cache folder
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "IMPSTAB_NUMBA_CACHE_DIR")}
    env["XDG_CACHE_HOME"] = str(tmp / "user-cache")
    wall, cpu, _ = run([sys.executable, "-m", "impstab.precompile", "-q"], env)
    out["precompile_s"], out["precompile_cpu_s"] = wall, cpu
    print(f"  python -m impstab.precompile     {wall:7.1f} s  (cpu {cpu:6.1f} s)", flush=True)
    for name, argv in (("critical", critical), ("simulate", simulate)):
        wall, cpu, _ = run(argv, env)
        out[f"first_{name}_s"], out[f"first_{name}_cpu_s"] = wall, cpu
        print(f"  first {name:9s} after precompile {wall:7.1f} s  (cpu {cpu:6.1f} s)", flush=True)
    clone = tmp / "second-clone" / "src"
    shutil.copytree(Path(impstab_package.__file__).parent, clone / "impstab", ignore=shutil.ignore_patterns("__pycache__"))
    second = {**env, "PYTHONPATH": os.pathsep.join([str(clone), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)}
    for name, argv in (("critical", critical), ("simulate", simulate)):
        argv = [sys.executable, "-m", "impstab", *argv[len(impstab):]]
        wall, cpu, _ = run(argv, second)
        out[f"second_clone_{name}_s"], out[f"second_clone_{name}_cpu_s"] = wall, cpu
        print(f"  first {name:9s} in a second clone {wall:6.1f} s  (cpu {cpu:6.1f} s)", flush=True)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=7, help="runs per warm measurement (median)")
    parser.add_argument("--skip-cold", action="store_true", help="leave out the empty-cache runs (minutes)")
    args = parser.parse_args()
    impstab = impstab_command()
    subprocess.run([sys.executable, "-m", "impstab.precompile", "-q"], check=True, capture_output=True)
    critical = [*impstab, "critical", str(EXAMPLE), "--json"]
    run(critical)  # warm the file system cache

    print(f"warm start-up, median of {args.repeat} rounds of fresh processes, every command once a round "
          "(shared machine: see the cpu column too)")
    rows = {
        "baseline": ("python -c 'import numpy, scipy.linalg, pydantic'", BASELINE, SINGLE_THREAD),
        "python": ("python -c pass", [sys.executable, "-c", "pass"]),
        "version": ("impstab --version", [*impstab, "--version"]),
        "help": ("impstab --help", [*impstab, "--help"]),
        "critical": ("impstab critical imp_symmetric.toml --json", critical),
        "critical_compiled": ("  the same, IMPSTAB_JIT=compiled", critical, COMPILED),
    }
    for name in OTHER_EXAMPLES:
        rows[name] = (f"impstab critical {name}.toml --json",
                      [*impstab, "critical", str(ROOT / "examples" / f"{name}.toml"), "--json"])
    runs = rounds(rows, args.repeat)
    times = {}
    for key, (label, *_) in rows.items():
        times[key] = (statistics.median(r[0] for r in runs[key]), statistics.median(r[1] for r in runs[key]))
        print(f"  {label:46s} {times[key][0]:6.3f} s  (cpu {times[key][1]:6.3f} s)")
    base_wall, base_cpu = times["baseline"]
    print("  ratios: the median over the rounds of the command's time over the baseline's in the same round")
    ratios = {k: (paired_ratio(runs, k, 0), paired_ratio(runs, k, 1)) for k in ("version", "help", "critical",
                                                                                "critical_compiled")}
    for k, (rw, rc) in ratios.items():
        print(f"  ratio {k:17s} / baseline: {rw:5.2f} (cpu {rc:5.2f})")
    examples = {name: paired_ratio(runs, name, 1) for name in OTHER_EXAMPLES}
    print("  cpu ratio of a warm critical --json / baseline: "
          + ", ".join(f"{name} {r:.2f}" for name, r in examples.items()))

    print("warm critical: import time by package (python -X importtime, self times summed, median)")
    by = importtime_breakdown(critical[1:] if impstab[0] == sys.executable else critical,
                              max(3, args.repeat // 2))
    total = sum(by.values())
    for name, sec in sorted(by.items(), key=lambda kv: -kv[1])[:12]:
        print(f"  {name:16s} {sec * 1e3:7.1f} ms  {100 * sec / total:5.1f} %")
    print(f"  {'total':16s} {total * 1e3:7.1f} ms")

    _, _, res = run([sys.executable, "-c", _INTERPRETED, str(EXAMPLE)])
    ki = json.loads(res.stdout.strip().splitlines()[-1])
    print(f"warm critical (cpu): first critical_thrust {ki['first_call']:.3f} s, of it {ki['interpreted_s']:.3f} s "
          f"in interpreted kernels; numba imported: {ki['numba']}")
    _, _, res = run([sys.executable, "-c", _KERNEL_LOADS, str(EXAMPLE)], COMPILED)
    kl = json.loads(res.stdout.strip().splitlines()[-1])
    print(f"IMPSTAB_JIT=compiled (cpu): import numba {kl['import_numba']:.3f} s; "
          f"first critical_thrust {kl['first_call']:.3f} s, second {kl['second_call'] * 1e3:.2f} ms")
    for name, sec in kl["loads"]:
        print(f"  load from the cache  {name:50s} {sec:6.3f} s")

    line = {
        "version_s": times["version"][0], "help_s": times["help"][0], "warm_critical_s": times["critical"][0],
        "baseline_s": base_wall, "version_ratio": ratios["version"][0], "help_ratio": ratios["help"][0],
        "warm_critical_ratio": ratios["critical"][0], "warm_critical_cpu_ratio": ratios["critical"][1],
        "warm_critical_compiled_cpu_ratio": ratios["critical_compiled"][1],
        "warm_critical_cpu_ratio_examples": examples, "interpreted_kernels_cpu_s": ki["interpreted_s"],
        "numba_imported": ki["numba"],
        "import_numba_cpu_s": kl["import_numba"], "kernel_loads_cpu_s": kl["first_call"] - kl["second_call"],
        "numba_import_share": by.get("numba", 0.0) / total if total else None,
    }
    if not args.skip_cold:
        print("first calls: empty kernel cache against after python -m impstab.precompile")
        with tempfile.TemporaryDirectory(prefix="impstab-startup-") as tmp:
            cold = cold_and_precompiled(impstab, Path(tmp))
        line.update(cold)
        line["first_call_s"] = cold["first_critical_s"]
        line["first_call_ratio"] = cold["cold_critical_s"] / cold["first_critical_s"]
        line["first_simulate_ratio"] = cold["cold_simulate_s"] / cold["first_simulate_s"]
        line["second_clone_simulate_ratio"] = cold["cold_simulate_s"] / cold["second_clone_simulate_s"]
        print(f"  ratio first critical, empty / precompiled: {line['first_call_ratio']:.1f}; "
              f"simulate {line['first_simulate_ratio']:.1f}; simulate in a second clone "
              f"{line['second_clone_simulate_ratio']:.1f}")
    print(json.dumps(line))
    return 0


if __name__ == "__main__":
    sys.exit(main())
