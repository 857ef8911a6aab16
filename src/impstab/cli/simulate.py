"""``impstab simulate``: nonlinear time histories under follower thrust."""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import click

from ..errors import ModelError, printable
from ..limits import LONG_FACTOR, MAX_OUTPUT_BYTES, MAX_STEPS, MAX_THRUSTS, describe_count
from ._common import at_thrust, check_number, check_output, print_json, user_text

__all__ = ["commands"]

INTEGRATOR = click.Choice(["hamming", "gill", "dop853", "rk45", "radau", "lsoda"], case_sensitive=False)


def _thrust_list(thrust: float | None, thrusts: str | None) -> list[float]:
    if thrust is not None and thrusts is not None:
        raise ModelError("--thrusts", thrusts, "give either --thrust or --thrusts, not both")
    if thrusts is not None:
        try:
            values = [float(v) for v in thrusts.split(",") if v.strip()]
        except ValueError:
            raise ModelError("--thrusts", thrusts,
                             "must be numbers separated by commas, e.g. 10000,18012,20000") from None
        if not values:
            raise ModelError("--thrusts", thrusts, "must list at least one thrust")
        if len(values) > MAX_THRUSTS:
            raise ModelError("--thrusts", f"{len(values)} thrusts", f"must list at most {MAX_THRUSTS} thrusts")
        return [check_number("--thrusts", v, kind="thrust_or_zero") for v in values]
    if thrust is None:
        raise ModelError("--thrust", None, "give the thrust in N (--thrust T) or several (--thrusts T1,T2,T3)")
    return [check_number("--thrust", thrust, kind="thrust_or_zero")]


def _dof_values(option: str, items: tuple[str, ...]) -> dict[str, float]:
    from ..model.model import DOF_NAMES

    out = {}
    for item in items:
        name, _, value = item.partition("=")
        name = name.strip().lower()
        if name not in DOF_NAMES:
            raise ModelError(option, item, f"must be DOF=VALUE with DOF one of {list(DOF_NAMES)}")
        try:
            v = float(value)
        except ValueError:
            raise ModelError(option, item, "must be DOF=VALUE with a number VALUE") from None
        out[name] = check_number(option, v, kind="displacement" if option == "--displace" else "velocity")
    return out


def _check_work(model, step_sizes: list[float], duration: float, dt: float | None, sample: float | None,
                allow_long: bool) -> None:
    """Refuse a simulation whose time steps or stored samples exceed the limits, before it runs.

    ``step_sizes`` holds each run's step (s). The samples of a run are every step, at most
    :data:`~impstab.dynamics.simulate.MAX_SAMPLES` of them, unless ``--sample`` is given; each
    takes 8 bytes for the time, the 12 states, the thrust, the error estimate and the 6 loads of
    every mount, twice (the run and the file written from it).
    """
    from ..dynamics.simulate import MAX_SAMPLES

    limit = MAX_STEPS * (LONG_FACTOR if allow_long else 1)
    total = sum(duration / h for h in step_sizes)
    option = "--dt" if dt is not None else "--duration"
    if total > limit:
        hint = "" if allow_long else f"; --allow-long runs up to {describe_count(limit * LONG_FACTOR)} with a progress bar"
        raise ModelError(option, dt if dt is not None else duration,
                         f"would need {describe_count(total)} time steps (limit {describe_count(limit)}){hint}")
    per_sample = 8 * 2 * (15 + 6 * len(model.mounts))
    samples = sum(math.ceil(duration / sample) if sample is not None else min(math.ceil(duration / h), MAX_SAMPLES)
                  for h in step_sizes)
    if samples * per_sample > MAX_OUTPUT_BYTES:
        raise ModelError("--sample" if sample is not None else option, sample if sample is not None else duration,
                         f"{describe_count(samples)} stored samples would take {samples * per_sample / 1024**3:.3g} GiB "
                         f"(limit {MAX_OUTPUT_BYTES / 1024**3:g} GiB): use a longer --sample interval")


def _progress(enabled: bool):
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    return Progress(TextColumn("{task.description}"), BarColumn(), TimeRemainingColumn(),
                    console=Console(stderr=True), transient=True, disable=not enabled)


def _save_png(results, png: Path) -> None:
    import matplotlib

    matplotlib.use("Agg", force=False) if matplotlib.get_backend().lower() != "agg" else None
    import matplotlib.pyplot as plt

    from ..io import atomic_path
    from ..plot.simulation import plot_simulations

    if len(results) == 1:
        axes = results[0].plot()
        fig = axes[0].figure
    else:
        fig = plot_simulations(results)[0, 0].figure
    with atomic_path(png) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)


def _write(results, out: Path) -> None:
    from ..dynamics.result import combine_results, results_to_dataframe
    from ..io import atomic_path

    with atomic_path(out) as tmp:
        if out.suffix.lower() == ".csv":
            results_to_dataframe(results).to_csv(tmp, index=False)
        else:
            ds = results[0].to_xarray() if len(results) == 1 else combine_results(results)
            ds.to_netcdf(tmp, engine="h5netcdf")


def _table(results, model_name: str):
    from rich.table import Table

    t = Table(title=f"time simulation of {user_text(model_name)}")
    for col in ("thrust (N)", "class", "envelope", "fitted growth (1/s)", "max Re(λ) (1/s)", "difference",
                "steps", "run (s)", "status"):
        t.add_column(col)
    for r in results:
        g = r.growth
        diff = g.relative_difference if g else None
        t.add_row(
            f"{r.thrust[0]:.6g}", r.classification, g.envelope if g else "-",
            f"{g.rate:.5g}" if g and math.isfinite(g.rate) else "-",
            f"{g.linear_rate:.5g}" if g and g.linear_rate is not None else "-",
            f"{100 * diff:.2f} %" if diff is not None else "-",
            str(r.steps) if r.steps >= 0 else f"{r.rhs_evaluations} f-evals", f"{r.wall_time:.3g}",
            "completed" if r.completed else f"[red]stopped[/red]: {user_text(r.stop_reason)}",
        )
    return t


@click.command("simulate")
@click.argument("model_file", type=click.Path(dir_okay=False))
@click.option("--thrust", type=float, default=None, help="constant thrust T (N)")
@click.option("--thrusts", default=None,
              help="several thrusts T1,T2,... (N), one figure (e.g. sub-, at and supercritical)")
@click.option("--duration", type=float, required=True, help="simulated time (s)")
@click.option("--integrator", type=INTEGRATOR, default="hamming", show_default=True)
@click.option("--dt", type=float, default=None, help="fixed step (s); default 40 steps per period of the fastest mode")
@click.option("--sample", type=float, default=None, help="output sampling interval (s); default every step")
@click.option("--tol", type=float, default=None, help="hamming: relative local error per step for step-size control")
@click.option("--displace", multiple=True, metavar="DOF=VALUE", help="initial displacement (m, rad), repeatable")
@click.option("--kick", multiple=True, metavar="DOF=VALUE", help="initial velocity (m/s, rad/s), repeatable")
@click.option("-o", "--output", type=click.Path(dir_okay=False), default=None,
              help="netCDF (.nc) or CSV (.csv) file; a PNG of sway and pitch is written beside it")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object (settings and outcome of each run)")
@click.option("--allow-long", is_flag=True,
              help=f"run beyond the limit of {MAX_STEPS:.0e} time steps (up to {LONG_FACTOR} times more), "
                   "with a progress bar on a terminal")
def simulate_cmd(model_file, thrust, thrusts, duration, integrator, dt, sample, tol, displace, kick, output,
                 as_json, allow_long) -> None:
    """Nonlinear time histories of MODEL_FILE from the static equilibrium under thrust.

    Writes the time histories (netCDF or CSV) and a PNG of sway and pitch like the paper's
    Figures 5-6, and reports the fitted envelope growth rate beside max Re(lambda) of the
    linearized system and the sub/at/supercritical classification.
    """
    from ..dynamics.simulate import default_step, simulate
    from ..linear.critical_thrust import critical_thrust
    from ..model import load_model

    values = _thrust_list(thrust, thrusts)
    duration = check_number("--duration", duration, kind="duration")
    dt = check_number("--dt", dt, kind="time_step")
    sample = check_number("--sample", sample, kind="time_step")
    tol = check_number("--tol", tol, kind="tolerance")
    out = Path(output) if output else Path(Path(model_file).stem + "-simulation.nc")
    if out.suffix.lower() not in (".nc", ".csv"):
        raise ModelError("--output", output, "must end in .nc (netCDF) or .csv; a PNG is written beside it")
    check_output("--output", out)
    check_output("--output", out.with_suffix(".png"))
    pert = None
    if displace or kick:
        pert = {"displacement": _dof_values("--displace", displace), "velocity": _dof_values("--kick", kick)}
    model = load_model(model_file)
    crit = critical_thrust(model, linearization="equilibrium").thrust
    steps = {v: at_thrust("--thrusts" if thrusts else "--thrust", v, model, lambda v=v: default_step(model, v))
             for v in values}
    if len(values) > 1 and dt is None:  # one time grid for all runs
        dt = min(steps.values())
    if len(values) > 1 and sample is None:
        sample = dt * max(1, math.ceil(duration / dt / 100_000))
    _check_work(model, [dt or steps[v] for v in values], duration, dt, sample, allow_long)
    results = []
    with _progress(sys.stderr.isatty() and not as_json) as bar, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for v in values:
            task = bar.add_task(f"T = {v:.6g} N", total=1.0)
            results.append(simulate(model, thrust=v, duration=duration, integrator=integrator.lower(), dt=dt,
                                    perturbation=pert, sample=sample, tol=tol, critical_thrust=crit,
                                    progress=lambda f, task=task: bar.update(task, completed=f)))
    for w in dict.fromkeys(str(w.message) for w in caught):
        click.echo(f"impstab: warning: {printable(w)}", err=True)
    _write(results, out)
    png = out.with_suffix(".png")
    _save_png(results, png)
    if as_json:
        print_json({"runs": [r.to_dict() for r in results], "critical_thrust": crit, "output": str(out),
                    "figure": str(png)})
        return
    from rich.console import Console

    con = Console(highlight=False, width=None if sys.stdout.isatty() else 160)
    con.print(_table(results, model.name))
    con.print(f"critical thrust {crit:.8g} N" if crit is not None else "no critical thrust up to thrust_max")
    con.print(f"wrote {user_text(out)} and {user_text(png)}")


commands = [simulate_cmd]
