"""Design study throughput: a 100 x 100 grid of the symmetric example over two mount parameters.

Measured in one run on this machine:

* **sweep** -- ``impstab.studies.run_study`` in process (one core), store on disk, end to end:
  variant model files validated and assembled, batched scan across designs, exact refinement,
  chunked zarr writes; the fastest of ``--repeat`` runs (the timeit convention, as every other
  figure here: the other runs were slowed by something else).
* **loop** (the baseline) -- a plain loop of
  ``impstab.critical_thrust(impstab.model.model_from_dict(variant))`` per design in the same
  process, timed on a random subset of the designs (``--loop-sample``, default 500) and scaled
  to the whole grid (said so in the output).
* **LAPACK** -- the time ``np.linalg.eigvals`` alone needs for the eigenproblems the sweep
  solves: the sweep's count of eigenproblems times the per-problem time of ``eigvals`` on a large
  stack of the designs' own scan operators. ``lapack_fraction`` is that time over the sweep's; it
  exceeds 1 when the sweep solves its eigenproblems faster than LAPACK could (the symmetric
  example's operators fall apart into 1 x 1 and 2 x 2 blocks, solved in closed form:
  :mod:`impstab.linear.blocks`).
* **coupled** -- the same measurement of sweep and loop on a layout with no decoupled blocks
  (the asymmetric example, classical linearization, over the first mount's x and shear
  stiffness), so that the figure for designs the block route cannot help is in the same line.
  Beside it the **compiled eigenvalue floor** (:func:`eigenvalue_floor`): the time of just the
  eigenvalue problems these designs need, with the compiled small-matrix routines, timed in a
  round right after each of the sweep's runs and about as long as one (so that both see the
  machine in the same state, over the same span of time), and ``floor_ratio``, the median over
  these pairs of the run's time per design over its round's.
* **workers** -- the same study on a local Dask cluster (``impstab.studies.execute.local_cluster``)
  of each of ``--workers-list`` worker processes (default 1, 2, 4, 8; one thread each; the
  workers write their own chunks), cluster started and warmed up (one chunk on every worker)
  before the clock starts; the fastest of ``--repeat`` runs counts (the timeit convention), and
  every run's time is printed, with the parallel efficiency rate(n) / (n rate(1)) and its bound
  cores / n on a machine with fewer cores than workers. Then the same on a larger grid of the
  same study (``--scale-n``, default 317 x 317 = 1e5 designs; ``--scale-n 1000`` for 1e6), where
  the fixed costs of a run no longer weigh, and there, end to end as the command line runs it,
  ``run_study`` in process against ``run_study(workers=2)`` with the cluster's start, warm-up and
  shutdown included. For the 2-worker runs, the CPU time of this process (client, scheduler) and
  of the workers. Beside it, the machine's own parallelism: the same CPU-bound loop in 1 and then
  2 processes at once (on a machine whose two cores do not run two processes at full speed, no
  program scales). The scaling figure on a bigger machine is one command::

      python benchmarks/sweep.py --no-coupled --scale-n 1000 --workers-list 1,2,4,8,16 --repeat 2

Ends with one JSON line:
``{"designs_per_s", "speedup_vs_loop", "lapack_fraction", "workers_scaling": {"1", "2", "4", "8"}, ...}``,
with ``parallel_efficiency`` (per worker count), ``workers_scaling_at_scale`` (``designs``, the
rates, ``parallel_efficiency``, ``cores``, ``client_cpu_share_2``, ``workers_cpu_s``) and
``workers_2_end_to_end`` (``designs``, ``in_process_s``, ``workers_2_s``, ``speedup``) among the
extra keys.
"""

from __future__ import annotations

from impstab._blas import prefer_single_thread

prefer_single_thread()  # before numpy loads: impstab and the baseline with one BLAS thread, as the CLI runs

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import impstab
from impstab._jit import require_compiled

require_compiled()  # the kernels are what is timed here (a lone call in a fresh process runs them interpreted)
from impstab.linear.engine import second_order_problem
from impstab.linear.linearize import ModelFamily
from impstab.model import model_from_dict
from impstab.studies import load_study, run_study
from impstab.studies.evaluate import evaluate_chunk, variant_dict
from impstab.studies.execute import chunk_task, local_cluster
from impstab.studies.plan import plan_chunks

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "imp_symmetric.toml"

COUPLED_EXAMPLE = EXAMPLE.with_name("imp_asymmetric.toml")
STUDY = """schema_version = 1
name = "benchmark {n} x {n}{label}"
model = "{model}"
[[parameters]]
path = "{x}"
values = {{ start = {x0}, stop = {x1}, num = {n} }}
[[parameters]]
path = "{k}"
values = {{ start = 5e3, stop = 5e4, num = {n}, scale = "log" }}
[execution]
chunk_size = {chunk}
"""
#: the symmetric example over its ring's x and shear stiffness
RING = dict(label="", x="mount_rings[0].x", x0=0.1, x1=0.4, k="mount_rings[0].k_shear")
#: the asymmetric example over its first mount's x and shear stiffness
MOUNT = dict(label=", coupled layout", x="mounts[0].position[0]", x0=0.2, x1=0.4, k="mounts[0].k_shear")


def scan_operator_time(study, designs: np.ndarray, n_scan: int = 64) -> float:
    """Seconds per eigenproblem of ``np.linalg.eigvals`` on a stack of the designs' scan operators."""
    ops = []
    for j in designs:
        idx = np.unravel_index(j, study.shape)
        vals = [p.values[i] for p, i in zip(study.parameters, idx)]
        model = model_from_dict(variant_dict(study.base_model, [p.path.segments for p in study.parameters], vals))
        problem = second_order_problem(ModelFamily(model), model.analysis.thrust_max)  # affine: A0 + T A1
        grid = np.linspace(0.0, model.analysis.thrust_max, n_scan + 1)
        ops.append(problem.a0[None] + grid[:, None, None] * problem.a1[None])
    stack = np.ascontiguousarray(np.concatenate(ops))
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        np.linalg.eigvals(stack)
        best = min(best, time.perf_counter() - t0)
    return best / len(stack)


def loop_time(study, designs: np.ndarray) -> float:
    """Seconds per design of the plain loop (validation, assembly, critical_thrust)."""
    segs = [p.path.segments for p in study.parameters]
    dicts = []
    for j in designs:
        idx = np.unravel_index(j, study.shape)
        dicts.append(variant_dict(study.base_model, segs, [p.values[i] for p, i in zip(study.parameters, idx)]))
    impstab.critical_thrust(model_from_dict(dicts[0]))  # warm-up
    t0 = time.perf_counter()
    for d in dicts:
        impstab.critical_thrust(model_from_dict(d))
    return (time.perf_counter() - t0) / len(dicts)


def eigenvalue_floor(study):
    """The compiled eigenvalue floor of a study: the time of just its designs' eigenvalue problems.

    The engine's own counts on every design of the study (bulk-assembled, as the sweep solves
    them): the eigenproblems with eigenvectors at the compiled decomposition's time
    (``eig_affine``), every other one -- eigenvalues only, and the pair vectors of the attraction
    test -- at the compiled eigenvalue routine's (``eigvals_affine_blocks``), a lower bound for the
    latter. Each is timed per problem on a stack of the designs' own operators at loads across
    their range, as many problems per design as the engine solves (rounded up), so that a round
    of the floor lasts about as long as the engine's part of a sweep. Returns ``time_round``,
    which times one round (call it right after a run of the sweep: both then see the machine in
    the same state, over the same span of time) and returns its seconds per design, and ``floor``,
    which turns the fastest round into the figures.
    """
    from impstab.linear.batch import critical_thrust_batch
    from impstab.linear.blocks import decoupled_blocks, eig_affine, eigvals_affine_blocks
    from impstab.linear.engine.problems import mass_solve
    from impstab.studies.bulk import assemble_bulk

    segs = [p.path.segments for p in study.parameters]
    idx = np.unravel_index(np.arange(study.size), study.shape)
    cols = [np.asarray(p.values)[i] for p, i in zip(study.parameters, idx)]
    stack = assemble_bulk(study.base_model, segs, cols).stack
    res = critical_thrust_batch([None] * study.size, affine=stack)  # the designs not in bulk: skipped
    designs = len(stack)
    values_only = res.evaluations - res.decompositions
    # the engine's own operators M^-1 K0, M^-1 K1 (mass_solve, as the batch forms them)
    a0, a1 = np.moveaxis(mass_solve(stack.mass, np.stack([stack.k0, stack.k1], axis=1)), 1, 0)
    t_max = stack.thrust_max
    blocks = decoupled_blocks(a0, a1, t_max)
    n_vals = max(1, int(np.ceil(values_only / designs)))
    loads = t_max[:, None] * np.linspace(0.0, 1.0, n_vals + 2)[None, 1:-1]
    n_vecs = max(1, int(np.ceil(res.decompositions / designs)))
    fractions = np.linspace(0.0, 1.0, n_vecs + 2)[1:-1]
    b0, b1 = np.concatenate([a0] * n_vecs), np.concatenate([a1] * n_vecs)
    at = np.concatenate([f * t_max for f in fractions])
    b_blocks = decoupled_blocks(b0, b1, np.concatenate([t_max] * n_vecs))
    eigvals_affine_blocks(a0, a1, loads, blocks)
    eig_affine(b0, b1, at, b_blocks)
    best = [np.inf, np.inf]

    def per_design(t_vals: float, t_vecs: float) -> float:
        return (values_only * t_vals + res.decompositions * t_vecs) / designs

    def time_round() -> float:
        t0 = time.perf_counter()
        eigvals_affine_blocks(a0, a1, loads, blocks)
        t_vals = (time.perf_counter() - t0) / loads.size
        t0 = time.perf_counter()
        eig_affine(b0, b1, at, b_blocks)
        t_vecs = (time.perf_counter() - t0) / len(at)
        best[0], best[1] = min(best[0], t_vals), min(best[1], t_vecs)
        return per_design(t_vals, t_vecs)

    def floor() -> dict:
        t_vals, t_vecs = best
        per_design_s = per_design(t_vals, t_vecs)
        return {"floor_us_per_design": per_design_s * 1e6, "eigenvalue_us": t_vals * 1e6,
                "decomposition_us": t_vecs * 1e6, "eigenvalue_problems_per_design": values_only / designs,
                "decompositions_per_design": res.decompositions / designs, "designs": designs}

    return time_round, floor


def coupled_rates(tmp: Path, n: int, chunk: int, loop_sample: int, rng, repeats: int) -> dict:
    """Sweep and loop on the asymmetric example (classical linearization): no decoupled blocks.

    Each run of the sweep is followed by a round of the eigenvalue floor of the same designs,
    about as long as the run, and the pair gives one ratio: the two saw the machine in the same
    state. ``floor_ratio`` is the median of the pairs' ratios (``floor_ratios``: each pair's);
    the designs per second are the fastest run's (the timeit convention). On a shared machine the
    speed changes by 1.5x within minutes: a floor timed apart put the ratio anywhere from 1.2x to
    2.3x, the fastest run over the fastest round of a few milliseconds compared a run slowed by
    the neighbours with a round that had caught a quiet moment.
    """
    text = COUPLED_EXAMPLE.read_text()
    model = tmp / "coupled.toml"
    model.write_text(text.replace("[analysis]", '[analysis]\nlinearization = "classical"', 1))
    path = tmp / "coupled_study.toml"
    path.write_text(STUDY.format(model=model.as_posix(), n=n, chunk=chunk, **MOUNT))
    study = load_study(path)
    run_study(study, None)  # warm-up
    time_round, floor_of = eigenvalue_floor(study)
    runs, ratios = [], []
    for r in range(repeats):
        runs.append(timed_study(study, tmp / f"coupled-{r}.zarr")[0])
        ratios.append(runs[-1] / study.size / time_round())
    seconds = min(runs)
    subset = rng.choice(study.size, size=min(loop_sample, study.size), replace=False)
    t_loop = loop_time(study, subset)
    return {"designs_per_s": study.size / seconds, "speedup_vs_loop": t_loop * study.size / seconds,
            "loop_us_per_design": t_loop * 1e6, "eigenvalue_floor": floor_of(),
            "floor_ratio": float(np.median(ratios)), "floor_ratios": ratios}


def timed_study(study, store: Path, **kw) -> tuple[float, object]:
    t0 = time.perf_counter()
    res = run_study(study, store, report=lambda line: None, **kw)
    return time.perf_counter() - t0, res


def best_study(study, stores: list[Path]) -> tuple[float, object]:
    """The fastest of in-process runs into each of ``stores`` (the timeit convention, as the eigenvalue
    floor, the worker counts and the end-to-end runs: the other runs were slowed by something else)."""
    runs = [timed_study(study, store) for store in stores]
    return min(runs, key=lambda r: r[0])


def _spin(n: int) -> float:
    s = 0.0
    for i in range(n):
        s += i * 0.5
    return s


def machine_parallelism(n: int = 4_000_000) -> float:
    """Speed-up of 2 processes over 1 on the same CPU-bound loop (2.0 on two free cores)."""
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(2) as ex:
        list(ex.map(_spin, [1000, 1000]))  # start both processes
        t0 = time.perf_counter()
        ex.submit(_spin, n).result()
        one = time.perf_counter() - t0
        t0 = time.perf_counter()
        list(ex.map(_spin, [n, n]))
        two = time.perf_counter() - t0
    return 2.0 * one / two


def _cpu_seconds() -> float:
    return time.process_time()


def worker_runs(study, tmp: Path, n_workers: int, repeats: int) -> dict:
    """Best of ``repeats`` runs of ``study`` on a fresh local cluster, and the CPU time it took.

    Returns the rate of the fastest run (designs/s, the timeit convention: the others were
    slowed by something else), every run's seconds, and the CPU seconds of that run in this
    process (client and scheduler) and in the workers. The workers write the chunks.
    """
    from distributed import Client

    runs = []
    with local_cluster(n_workers, dashboard_address=None) as cluster, Client(cluster) as client:
        # warm-up like the in-process run's: one chunk of the study on every worker (imports,
        # compiled-code caches), before the clock starts
        client.run(evaluate_chunk, chunk_task(study, plan_chunks(study), 0))
        for r in range(repeats):
            workers0, client0 = client.run(_cpu_seconds), time.process_time()
            seconds, _ = timed_study(study, tmp / f"w{n_workers}-{study.size}-{r}.zarr", client=client,
                                     in_process_below=0)
            client_cpu = time.process_time() - client0
            workers1 = client.run(_cpu_seconds)
            runs.append((seconds, client_cpu, sum(workers1[w] - workers0[w] for w in workers0)))
    best = min(runs)
    return {"rate": study.size / best[0], "seconds": [r[0] for r in runs], "client_cpu": best[1], "workers_cpu": best[2]}


def scaling(study, tmp: Path, repeats: int, counts: list[int]) -> tuple[dict, dict]:
    """Designs/s on each number of workers (best runs), the parallel efficiency, the CPU shares.

    The efficiency of n workers is rate(n) / (n rate(1)): 1.0 is linear speed-up. On a machine
    with fewer cores than workers it cannot exceed cores / n; that bound is printed beside it.
    """
    out, runs = {}, {}
    cores = os.cpu_count() or 1
    for w in counts:
        runs[w] = worker_runs(study, tmp, w, repeats)
        out[str(w)] = runs[w]["rate"]
        print(f"dask {w:2d} worker{'s' if w > 1 else ' '}  {runs[w]['rate']:,.0f} designs/s on {study.size} designs "
              f"(best of {' '.join(f'{t:.2f}' for t in runs[w]['seconds'])} s; workers' CPU {runs[w]['workers_cpu']:.2f} s)")
    one = out.get("1")
    efficiency = {str(w): out[str(w)] / (w * one) for w in counts} if one else {}
    if efficiency:
        print("efficiency       " + ", ".join(f"{w} workers {efficiency[str(w)]:.2f} (at most {min(1.0, cores / w):.2f} "
                                              f"on {cores} cores)" for w in counts if w > 1))
    extra = {"parallel_efficiency": efficiency, "cores": cores,
             "workers_cpu_s": {str(w): runs[w]["workers_cpu"] for w in runs}}
    if 2 in runs:
        two = runs[2]
        share = two["client_cpu"] / (two["client_cpu"] + two["workers_cpu"])
        extra["client_cpu_share_2"] = share
        print(f"client           in the 2-worker run this process (client, scheduler) used {two['client_cpu']:.2f} s of "
              f"CPU, the workers {two['workers_cpu']:.2f} s ({share:.0%} on this process)")
    return out, extra


def end_to_end(study, tmp: Path, repeats: int, workers: int = 2) -> dict:
    """``run_study`` in process against ``run_study(workers=N)`` as the command line runs them:
    cluster start, worker warm-up and shutdown included (best of ``repeats`` each)."""
    local, dask = [], []
    for r in range(repeats):
        local.append(timed_study(study, tmp / f"e2e-local-{r}.zarr")[0])
        dask.append(timed_study(study, tmp / f"e2e-dask-{r}.zarr", workers=workers, in_process_below=0)[0])
    ratio = min(local) / min(dask)
    print(f"end to end       {study.size} designs: in process {min(local):.2f} s, --workers {workers} {min(dask):.2f} s "
          f"(cluster start included): {ratio:.2f}x")
    return {"designs": study.size, "in_process_s": min(local), f"workers_{workers}_s": min(dask),
            "speedup": ratio}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100, help="grid points per parameter (default 100)")
    ap.add_argument("--chunk", type=int, default=2500,
                    help="designs per chunk (default 2500: about 0.1 s of work, the task size Dask recommends)")
    ap.add_argument("--loop-sample", type=int, default=500, help="designs timed in the plain loop")
    ap.add_argument("--no-workers", action="store_true", help="skip the Dask worker scaling")
    ap.add_argument("--repeat", type=int, default=3,
                    help="runs of each in-process sweep and per worker count; the fastest counts (default 3)")
    ap.add_argument("--scale-n", type=int, default=317,
                    help="grid points per parameter of the larger study for the scaling at scale (default 317: "
                         "1e5 designs; 1000 for 1e6; 0 skips)")
    ap.add_argument("--workers-list", default="1,2,4,8",
                    help="worker counts to measure, comma-separated (default 1,2,4,8)")
    ap.add_argument("--no-coupled", action="store_true", help="skip the coupled-layout measurement")
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        path = tmp / "study.toml"
        path.write_text(STUDY.format(model=EXAMPLE.as_posix(), n=args.n, chunk=args.chunk, **RING))
        study = load_study(path)
        n = study.size
        run_study(load_study(path), None)  # warm-up of the whole path (JIT cache, imports)
        stores = [tmp / f"local-{r}.zarr" for r in range(args.repeat)]
        seconds, res = best_study(study, stores)
        rate = n / seconds
        evaluations = float(np.nansum(res_records(stores[0])))
        subset = rng.choice(n, size=min(args.loop_sample, n), replace=False)
        t_loop = loop_time(study, subset)
        t_eig = scan_operator_time(study, rng.choice(n, size=min(200, n), replace=False))
        t_lapack = evaluations * t_eig
        counts = res.counts()
        kinds = res.kind_names().values.ravel()
        print(f"study            {n} designs ({args.n} x {args.n}) of {EXAMPLE.name}, chunks of {args.chunk}")
        print(f"designs          ok {counts['ok']}, flutter {np.sum(kinds == 'flutter')}, "
              f"stable to thrust_max {np.sum(kinds == 'none')}, failed {n - counts['ok']}")
        print(f"sweep (1 core)   {seconds:.2f} s  = {rate:,.0f} designs/s  ({seconds / n * 1e6:.0f} us/design)")
        print(f"plain loop       {t_loop * 1e6:.0f} us/design, timed on {len(subset)} random designs, "
              f"scaled to {n}: {t_loop * n:.1f} s")
        print(f"speedup          {t_loop * n / seconds:.2f}x")
        print(f"eigenproblems    {evaluations / n:.1f} per design; eigvals alone {t_eig * 1e6:.2f} us each "
              f"-> LAPACK alone {t_lapack:.2f} s = {t_lapack / seconds:.1%} of the sweep")
        coupled = {}
        if not args.no_coupled:
            coupled = coupled_rates(tmp, args.n, args.chunk, args.loop_sample, rng, args.repeat)
            print(f"coupled layout   {coupled['designs_per_s']:,.0f} designs/s, loop {coupled['loop_us_per_design']:.0f} "
                  f"us/design: {coupled['speedup_vs_loop']:.2f}x (asymmetric example, no decoupled blocks)")
            fl = coupled["eigenvalue_floor"]
            print(f"eigenvalue floor {fl['floor_us_per_design']:.1f} us/design: {fl['eigenvalue_problems_per_design']:.1f} "
                  f"eigenvalue problems x {fl['eigenvalue_us']:.2f} us + {fl['decompositions_per_design']:.1f} "
                  f"decompositions x {fl['decomposition_us']:.2f} us (compiled, fastest round); the coupled sweep "
                  f"takes {coupled['floor_ratio']:.2f}x the floor (median of runs each over the round after it: "
                  f"{', '.join(f'{r:.2f}' for r in coupled['floor_ratios'])})")
        workers, at_scale, parallel, e2e = {}, {}, None, {}
        if not args.no_workers:
            counts = sorted({int(w) for w in args.workers_list.split(",") if w.strip()})
            workers, extra = scaling(study, tmp, args.repeat, counts)
            workers_efficiency = extra["parallel_efficiency"]
            if args.scale_n:
                big = tmp / "study_large.toml"
                big.write_text(STUDY.format(model=EXAMPLE.as_posix(), n=args.scale_n, chunk=args.chunk, **RING))
                large = load_study(big)
                at_scale, shares = scaling(large, tmp, max(1, args.repeat - 1), counts)
                at_scale = {"designs": large.size, **at_scale, **shares}
                e2e = end_to_end(large, tmp, max(1, args.repeat - 1))
            parallel = machine_parallelism()
            print(f"machine          runs 2 CPU-bound processes {parallel:.2f}x as fast as 1")
    line = {
        "designs_per_s": rate,
        "speedup_vs_loop": t_loop * n / seconds,
        "lapack_fraction": t_lapack / seconds,
        "workers_scaling": workers,
        "designs": n,
        "loop_us_per_design": t_loop * 1e6,
        "loop_timed_on": len(subset),
        "eigenproblems_per_design": evaluations / n,
    }
    if workers:
        line["parallel_efficiency"] = workers_efficiency
    if at_scale:
        line["workers_scaling_at_scale"] = at_scale
    if e2e:
        line["workers_2_end_to_end"] = e2e
    if parallel is not None:
        line["machine_parallelism_2_processes"] = parallel
    if coupled:
        line["coupled"] = coupled
    print(json.dumps(line))
    return 0


def res_records(store: Path) -> np.ndarray:
    """Eigenproblems solved per chunk, from the store's progress records."""
    import zarr

    return zarr.open_group(str(store), mode="r")["progress/chunks"][:, 3]


if __name__ == "__main__":
    sys.exit(main())
