"""Compile every numba kernel the command line uses, once, into impstab's cache.

``python -m impstab.precompile`` (run by ``make demo`` and ``make test`` after installing) runs
each command on small cases through the command line, so that numba compiles each kernel with
the argument types the commands give it and stores it in the cache of
:mod:`impstab._numba_cache` (outside the source tree, shared by every clone on the machine; kept
until the kernels' sources change).
A later ``impstab critical`` or ``impstab simulate`` loads the machine code instead of compiling
it for minutes.

Two phases, spread over the same ``--jobs`` processes (default the cores available, at most 4).
Every command computes a critical thrust first, so every case needs the kernels of the stability
engine, and most need the tangent stiffness at the static equilibrium, the right-hand side and
a time integration. The first phase compiles these independent sets side by side through public
entry points (:func:`warm_ups`: ``critical_load`` on a generic family; ``linearize`` of a model;
the nonlinear right-hand side at real and complex states; the fixed-step integrator on a linear
oscillator), so that no case starts before they are in the cache (two processes each compiling
the engine would do the same minute of work twice), and no two of them compile the same kernel.
The second phase runs each command's cases in one of those processes, the heaviest first; they
load the shared kernels (or have them already) and compile only their own.

The cases use the bundled ``examples/`` when run from a source tree, else two small models
and a small study written here. A command that uses kernels gets a line in :func:`cases`;
kernels that only the Python API reaches (or argument types only it passes) compile on their
first call. Whatever kernels exist are compiled this way: nothing here names them.

Output: one progress line per case (seconds, kernel signatures compiled and loaded from the
cache), then a summary; exit code 1 if a case failed (its message is printed). A marker in the
cache folder makes a later run return at once.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
import tempfile
import time
from pathlib import Path

from . import _numba_cache

__all__ = ["cases", "warm_ups", "main", "kernels", "MARKER"]

#: written into the cache folder when every case ran
MARKER = _numba_cache.MARKER

#: the bundled examples when running from a source tree (src/impstab/precompile.py)
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

_SYMMETRIC = """schema_version = 1
name = "precompile: symmetric ring"
[body]
mass = 100.0
inertia = [1.0, 6.0, 6.0]
[[mount_rings]]
count = 3
radius = 0.15
x = 0.3
start_angle = 90.0
k_axial = 1.0e5
k_shear = 2.0e4
{damping}
[thrust]
operating = 2000.0
[analysis]
thrust_max = 20000.0
"""


def _models(folder: Path) -> dict[str, Path]:
    """The model files of the cases: the examples, else two written into ``folder``."""
    if (EXAMPLES / "imp_symmetric.toml").is_file():
        return {p.stem.removeprefix("imp_"): p for p in sorted(EXAMPLES.glob("imp_*.toml"))}
    out = {}
    for name, damping in (("symmetric", ""), ("damped", "c_axial = 60.0\nc_shear = 5.0")):
        path = folder / f"imp_{name}.toml"
        path.write_text(_SYMMETRIC.format(damping=damping), encoding="utf-8")
        out[name] = path
    return out


_GRID = """schema_version = 1
name = "precompile: {name}"
model = {model!r}
outputs = ["critical_thrust", "kind", "frequency_hz", "margin", "undamped_critical_thrust", "modes"]
[[parameters]]
path = "{first}"
values = {values}
[[parameters]]
path = "{second}"
values = {second_values}
[sampling]
method = "grid"
"""


def _studies(folder: Path, models: dict[str, Path]) -> dict[str, Path]:
    """The study files of the cases: the examples (else a small grid on the symmetric model), a
    grid with unrestrained designs among valid ones, and one on the asymmetric model."""
    out = {}
    if (EXAMPLES / "study_mounts.toml").is_file():
        out = {p.stem.removeprefix("study_"): p for p in sorted(EXAMPLES.glob("study_*.toml"))}
    ring = ("mount_rings[0].x", "[0.25, 0.3]")
    grids = {"unrestrained designs": ("symmetric", ("mount_rings[0].k_shear", "[0.0, 2.0e4]"), ring)}
    if not out:
        grids["grid"] = ("symmetric", ("mount_rings[0].k_axial", "[0.8e5, 1.2e5]"), ring)
    if "asymmetric" in models:
        grids["asymmetric"] = ("asymmetric", ("mounts[0].k_shear", "[1.5e4, 3.0e4]"), ("thrust.point[2]", "[0.0, 0.03]"))
    for name, (model, (first, values), (second, second_values)) in grids.items():
        path = folder / f"study_{name.replace(' ', '_')}.toml"
        path.write_text(_GRID.format(name=name, model=str(models[model].resolve()), first=first, values=values,
                                     second=second, second_values=second_values), encoding="utf-8")
        out[name] = path
    return out


def _with_lumped_hull(folder: Path, model: Path) -> Path:
    """``model`` on a compliant hull (a lumped foundation at every attachment)."""
    path = folder / f"{model.stem}_lumped_hull.toml"
    path.write_text(model.read_text(encoding="utf-8") + '\n[foundation]\nmodel = "lumped"\nmass = 30.0\n'
                    "stiffness = 4.0e5\ndamping = 900.0\n", encoding="utf-8")
    return path


def cases(folder: Path, models: dict[str, Path] | None = None) -> list[tuple[str, list[str]]]:
    """``(label, argv)`` of each command run: every kernel path of the command line (``models``:
    those of :func:`_models`, found or written into ``folder`` when not given)."""
    models = _models(folder) if models is None else models
    sym = str(models["symmetric"])
    out: list[tuple[str, list[str]]] = []
    # every case but one on each model: the massive beam mounts' --all-crossings compiles nothing
    # the plain case has not (the same large-model route) and takes seconds of dense eigenproblems
    for name, path in models.items():
        p = str(path)
        runs = [
            (f"critical {name}", ["critical", p, "--json"]),
            (f"critical {name} --all-crossings", ["critical", p, "--json", "--all-crossings"]),
            (f"critical {name} classical", ["critical", p, "--json", "--linearization", "classical"]),
            (f"modes {name}", ["modes", p, "--json"]),
            (f"check {name}", ["check", p]),
            (f"locus {name}", ["locus", p, "--steps", "8", "--no-plot", "-o", str(folder / f"{name}.nc")]),
            (f"simulate {name}", ["simulate", p, "--thrust", "1000", "--duration", "0.05", "--no-plot",
                                  "-o", str(folder / f"sim-{name}.csv")]),
            (f"response {name}", ["response", p, "--frequencies", "1:40:16", "--json"]),
        ]
        out += [(label, argv) for label, argv in runs if not (name == "beam_mounts" and "--all-crossings" in argv)]
    for integrator in ("gill", "dop853", "rk45", "radau", "lsoda"):
        out.append((f"simulate {integrator}", ["simulate", sym, "--thrust", "19000", "--duration", "0.05",
                                             "--integrator", integrator, "--no-plot", "-o", str(folder / "sim.csv")]))
    if "isolation" in models:
        out.append(("response --excitation", ["response", str(models["isolation"]), "--frequencies", "1:40:16",
                                              "--excitation", "--json"]))
    out.append(("response lumped hull", ["response", str(_with_lumped_hull(folder, models["symmetric"])),
                                         "--frequencies", "1:40:16", "--json"]))
    for name in ("hardening", "softening"):
        if name in models:
            out.append((f"postcritical {name}", ["postcritical", str(models[name]), "--max-points", "3", "--json"]))
    for name, path in _studies(folder, models).items():
        out.append((f"sweep {name}", ["sweep", str(path), "-o", str(folder / f"{path.stem}.zarr"), "--no-progress"]))
    return out


def _engine_family() -> None:
    """The stability engine's kernels: the critical load of a generic 6-dof follower-force family,
    undamped (second-order classification) and damped (first-order), through the same stacked
    arrays a model's critical thrust hands the engine."""
    import numpy as np

    from .linear.critical import critical_load

    m = np.diag([100.0, 100.0, 100.0, 1.0, 6.0, 6.0])
    k0 = np.diag([3.0e5, 6.0e4, 6.0e4, 2.0e3, 4.0e3, 4.0e3])
    k1 = np.zeros((6, 6))
    k1[1, 5], k1[2, 4] = -1.0, 1.0  # the follower thrust's load stiffness (THEORY 4)
    critical_load(m, k0, k1, p_max=1.0e5)
    critical_load(m, k0, k1, D=np.diag([40.0, 8.0, 8.0, 1.0, 1.0, 1.0]), p_max=1.0e5)


def _tangent_stiffness(model: str) -> None:
    """The tangent stiffness at the static equilibrium (Newton statics of ``model``, then the
    classical and equilibrium forms)."""
    from .linear.linearize import linearize
    from .model import load_model

    linearize(load_model(model), thrust=1000.0)


def _right_hand_side(model: str) -> None:
    """The nonlinear right-hand side of ``model`` at real states (the SciPy integrators' ``fun``)
    and at complex ones (their Jacobian, and the post-critical analysis: complex-step
    derivatives)."""
    import numpy as np

    from .dynamics.system import NonlinearSystem
    from .model import load_model

    ns = NonlinearSystem(load_model(model))
    ns.rhs(np.zeros(ns.n_states), 1000.0)
    ns.rhs(np.zeros(ns.n_states, dtype=complex), 1000.0)


def _fixed_step_integrator() -> None:
    """The fixed-step integrators' compiled step loop (Gill's start, Hamming's method), on a
    linear oscillator: a model's time history calls it with the same argument types."""
    import numpy as np

    from .dynamics.integrators import integrate_linear

    integrate_linear(np.array([[0.0, 1.0], [-1.0, 0.0]]), np.array([1.0, 0.0]), 0.01, 8)


def warm_ups(models: dict[str, Path]) -> list[tuple[str, object, tuple]]:
    """``(label, function, arguments)`` of the first phase, the heaviest first: independent kernel
    sets that the cases share, compiled side by side (each to the first process free) before any
    case runs; no two of them compile the same kernel."""
    sym = str(models["symmetric"])
    return [("stability engine", _engine_family, ()),
            ("tangent stiffness", _tangent_stiffness, (str(models.get("asymmetric", sym)),)),
            ("right-hand side, real and complex", _right_hand_side, (str(models.get("hardening", sym)),)),
            ("fixed-step integrator", _fixed_step_integrator, ())]


def _warm(label: str, func, args: tuple, quiet: bool) -> list[tuple[str, str]]:
    """Run one warm-up in this process; its failure ``(label, message)``, if any."""
    with _progress("warm-up", label, quiet):
        try:
            func(*args)
        except Exception as exc:  # reported with the cases' failures; the cases still run
            return [(label, f"{type(exc).__name__}: {exc}")]
    return []


@contextlib.contextmanager
def _progress(tag: str, label: str, quiet: bool):
    """One progress line for the block: its seconds and the kernel signatures it compiled and
    loaded; the block may set ``status`` in the yielded dict (appended to the line)."""
    t0 = time.perf_counter()
    before = _counts() if "numba" in sys.modules else (0, 0)
    note = {"status": ""}
    try:
        yield note
    finally:
        after = _counts() if "numba" in sys.modules else (0, 0)
        if not quiet:
            print(f"  [{tag}] {label:36s} {time.perf_counter() - t0:6.1f} s  compiled {after[0] - before[0]:3d}, "
                  f"from the cache {after[1] - before[1]:3d}{note['status']}", flush=True)


def kernels() -> dict[str, object]:
    """Every numba dispatcher defined in a loaded impstab module, by ``module.name``."""
    from numba.core.dispatcher import Dispatcher

    found: dict[str, object] = {}
    for name, module in list(sys.modules.items()):
        if not (name == "impstab" or name.startswith("impstab.")) or module is None:
            continue
        for attr, value in list(vars(module).items()):
            if isinstance(value, Dispatcher) and value.py_func.__module__ == name:
                found[f"{name}.{attr}"] = value
    return found


def _counts() -> tuple[int, int]:
    """(signatures compiled, signatures loaded from the cache) over all kernels so far."""
    compiled = loaded = 0
    for disp in kernels().values():
        stats = disp.stats  # type: ignore[attr-defined]
        compiled += sum(stats.cache_misses.values())
        loaded += sum(stats.cache_hits.values())
    return compiled, loaded


#: expected compile work (seconds, measured on two cores) of each command's cases after the warm-ups,
#: which compile the kernels every command shares (every command computes the critical thrust).
#: The larger go first to the parallel workers, each to the first one free (the longest-first
#: rule): the time integrators' other kernels, the studies' bulk paths, the periodic orbits'
#: complex-step Jacobian, the harmonic solver; the other commands reuse what the warm-ups compiled
_WEIGHT = {"simulate": 40, "sweep": 20, "postcritical": 15, "response": 8}


def _run(numbered: list[tuple[int, str, list[str]]], total: int, quiet: bool) -> list[tuple[str, str]]:
    """Run the cases through the command line in this process; their failures ``(label, message)``."""
    import matplotlib

    matplotlib.use("Agg")
    from .cli import main as cli_main

    failed = []
    for k, label, argv in numbered:
        out, err = io.StringIO(), io.StringIO()
        with _progress(f"{k:2d}/{total}", label, quiet) as note:
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                code = cli_main(argv)
            note["status"] = "" if code == 0 else f"  FAILED (exit {code})"
        if code != 0:
            failed.append((label, err.getvalue().strip()))
    return failed


def _groups(numbered, jobs: int):
    """The cases by command, heaviest first (one command's cases share their kernels)."""
    by: dict[str, list] = {}
    for case in numbered:
        by.setdefault(case[2][0], []).append(case)
    return sorted(by.values(), key=lambda g: -_WEIGHT.get(g[0][2][0], 1))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m impstab.precompile", description=__doc__.split("\n")[0])
    parser.add_argument("-j", "--jobs", type=int, default=None,
                        help="processes compiling at once (default: the cores available, at most 4)")
    parser.add_argument("-q", "--quiet", action="store_true", help="only the first and the summary line")
    parser.add_argument("--force", action="store_true", help="run the cases even if this cache is complete")
    parser.add_argument("--clean", action="store_true",
                        help="remove impstab's compiled kernels (every cache folder, shared by the clones on this "
                             "machine) and stop")
    args = parser.parse_args(argv)

    from ._blas import prefer_single_thread

    prefer_single_thread()  # as the commands run (and before numpy loads, see impstab._blas)
    _numba_cache.install()
    # compile from the first call here and in the worker processes (a single-model command would
    # otherwise run its kernels interpreted, see impstab._jit, and compile nothing)
    os.environ["IMPSTAB_JIT"] = "compiled"
    if args.clean:
        return _clean()
    _bytecode()
    marker = _numba_cache.kernel_folder() / MARKER
    if marker.is_file() and not args.force:
        print(f"impstab: kernels already compiled in {marker.parent}")
        return 0
    jobs = args.jobs or min(4, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)
    print(f"impstab: compiling kernels into {marker.parent} ({jobs} processes)", flush=True)
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="impstab-precompile-") as tmp:
        models = _models(Path(tmp))
        numbered = [(k, label, a) for k, (label, a) in enumerate(cases(Path(tmp), models), 1)]
        total = len(numbered)
        first = warm_ups(models)
        groups = _groups(numbered, jobs)
        failed: list[tuple[str, str]] = []
        if jobs > 1:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            # the kernels every command shares, side by side; once all are in the cache, one command
            # per process, in the same processes (a fresh one costs its imports and numba's start again)
            workers = min(jobs, max(len(first), len(groups)))
            with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
                for result in pool.map(_warm, *zip(*first), [args.quiet] * len(first)):
                    failed += result
                for result in pool.map(_run, groups, [total] * len(groups), [args.quiet] * len(groups)):
                    failed += result
        else:
            for label, func, fargs in first:
                failed += _warm(label, func, fargs, args.quiet)
            failed += _run([c for g in groups for c in g], total, args.quiet)
    print(f"impstab: {total} cases in {time.perf_counter() - start:.1f} s", flush=True)
    for label, message in failed:
        print(f"impstab: precompile case {label!r} failed:\n{message}", file=sys.stderr)
    if failed:
        return 1
    marker.parent.mkdir(parents=True, exist_ok=True)
    marker.write_text(f"{total} cases\n", encoding="utf-8")
    for folder in _numba_cache.prune():
        print(f"impstab: removed older compiled kernels, {folder}")
    return 0


def _bytecode() -> None:
    """Write the bytecode of impstab's own modules (a no-op where it is up to date or read-only).

    An editable install (``make``) leaves it to the first import, which skips it where
    ``PYTHONDONTWRITEBYTECODE`` is set: every command would then compile impstab's sources again
    (about 0.15 s of each start-up).
    """
    import compileall

    with contextlib.redirect_stdout(io.StringIO()):
        compileall.compile_dir(str(Path(__file__).resolve().parent), quiet=2, workers=0)


def _clean() -> int:
    import shutil

    own = _numba_cache.user_setting()
    if own:
        print(f"impstab: NUMBA_CACHE_DIR={own} is the user's own setting: not removed")
        return 0
    folder = _numba_cache.cache_root() / "numba"
    shutil.rmtree(folder, ignore_errors=True)
    print(f"impstab: removed {folder}")
    environment = _numba_cache._environment_cache()  # where earlier versions kept them
    if environment is not None and environment != folder and environment.is_dir():
        shutil.rmtree(environment, ignore_errors=True)
        print(f"impstab: removed {environment}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
