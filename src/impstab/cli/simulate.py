"""``impstab simulate``: nonlinear time histories under follower thrust."""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import click

from ..display.format import growth
from ..errors import ModelError, printable
from ..limits import LONG_FACTOR, MAX_STEPS, MAX_THRUSTS
from ._common import (at_thrust, check_number, console, data_and_figure, draw_and_save, figure_options, fmt, print_json,
                      table, user_text)

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


def _progress(enabled: bool):
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    return Progress(TextColumn("{task.description}"), BarColumn(), TimeRemainingColumn(),
                    console=Console(stderr=True), transient=True, disable=not enabled)


def _draw(results):
    from ..plot.simulation import plot_simulations

    return results[0].plot() if len(results) == 1 else plot_simulations(results)


def _write(results, out: Path) -> None:
    from ..dynamics.result import combine_results, results_to_dataframe
    from ..io import write_csv, write_netcdf

    if out.suffix.lower() == ".csv":
        write_csv(results_to_dataframe(results), out, option="--output", index=False)
    else:
        write_netcdf(results[0].to_xarray() if len(results) == 1 else combine_results(results), out, option="--output")


def _table(results, model_name: str):
    t = table(f"time simulation of {user_text(model_name)}", ("thrust (N)", "right"), "class", "envelope",
              ("fitted\ngrowth (1/s)", "right"), ("max Re λ\n(1/s)", "right"), ("diff.", "right"), "status")
    for r in results:
        g = r.growth
        diff = g.relative_difference if g else None
        exponential = g is not None and g.envelope in ("exponential growth", "decaying") and math.isfinite(g.rate)
        t.add_row(
            fmt(r.thrust[0]), r.classification, g.envelope if g else "no fit",
            fmt(g.rate, digits=5) if exponential else "n/a",
            growth(g.linear_rate, r.fastest_omega) if g and g.linear_rate is not None else "not computed",
            fmt(100 * diff, "%", digits=2) if diff is not None and exponential else "n/a",
            "completed" if r.completed else "[red]stopped[/red]",
        )
    return t


def _notes(results) -> list[str]:
    lines = ["fitted growth, and its difference from max Re λ: for exponential envelopes only (n/a otherwise)"]
    steps = ", ".join(str(r.steps) if r.steps >= 0 else f"{r.rhs_evaluations} f-evals" for r in results)
    lines.append(f"steps: {steps}; run time: {', '.join(fmt(r.wall_time, digits=3) for r in results)} s")
    lines += [f"T = {r.thrust[0]:.6g} N: {user_text(r.stop_reason)}" for r in results if not r.completed]
    for r in results:
        g = r.growth
        if g is not None and g.envelope == "limit cycle" and g.amplitude:
            amps = ", ".join(f"{k} {fmt(v, digits=4)} {'m' if k in ('surge', 'sway', 'heave') else 'rad'}"
                             for k, v in g.amplitude.items())
            lines.append(f"T = {r.thrust[0]:.6g} N: limit cycle, period {fmt(g.period, digits=6)} s, amplitude {amps}")
        if g is not None and g.reason:
            lines.append(f"T = {r.thrust[0]:.6g} N: {g.envelope}: {g.reason}")
    return lines


@click.command("simulate")
@click.argument("model_file", type=click.Path(dir_okay=False))
@click.option("--thrust", type=float, default=None, help="constant thrust T (N)")
@click.option("--thrusts", default=None,
              help="several thrusts T1,T2,... (N), one figure (e.g. sub-, at and supercritical)")
@click.option("--duration", type=float, required=True, help="simulated time (s)")
@click.option("--integrator", type=INTEGRATOR, default="hamming", show_default=True)
@click.option("--dt", type=float, default=None, help="fixed step (s); default 40 steps per period of the fastest mode "
                   "(and of the fastest relaxation of viscoelastic mounts)")
@click.option("--sample", type=float, default=None, help="output sampling interval (s); default every step")
@click.option("--tol", type=float, default=None, help="hamming: relative local error per step for step-size control")
@click.option("--displace", multiple=True, metavar="DOF=VALUE", help="initial displacement (m, rad), repeatable")
@click.option("--kick", multiple=True, metavar="DOF=VALUE", help="initial velocity (m/s, rad/s), repeatable")
@click.option("-o", "--output", type=click.Path(dir_okay=False), default=None,
              help="netCDF (.nc) or CSV (.csv) file, with a PNG of sway and pitch beside it; "
                   "or a figure only (.png, .svg, .pdf)")
@figure_options
@click.option("--json", "as_json", is_flag=True, help="print one JSON object (settings and outcome of each run)")
@click.option("--allow-long", is_flag=True,
              help=f"run beyond the limit of {MAX_STEPS:.0e} time steps (up to {LONG_FACTOR} times more), "
                   "with a progress bar on a terminal")
def simulate_cmd(model_file, thrust, thrusts, duration, integrator, dt, sample, tol, displace, kick, output,
                 figure, dpi, no_plot, as_json, allow_long) -> None:
    """Nonlinear time histories of MODEL_FILE from the static equilibrium under thrust.

    Writes the time histories (netCDF or CSV) and a PNG of sway and pitch like the paper's
    Figures 5-6, and reports the fitted envelope growth rate beside max Re(lambda) of the
    linearized system and the sub/at/supercritical classification.
    """
    from ..dynamics.simulate import CLI_NAMES, check_step, check_work, default_step, simulate
    from ..linear.critical_thrust import critical_thrust
    from ..model import load_model

    values = _thrust_list(thrust, thrusts)
    duration = check_number("--duration", duration, kind="duration")
    dt = check_number("--dt", dt, kind="time_step")
    sample = check_number("--sample", sample, kind="time_step")
    tol = check_number("--tol", tol, kind="tolerance")
    out = Path(output) if output else Path(Path(model_file).stem + "-simulation.nc")
    data, fig_path = data_and_figure(out, (".nc", ".csv"), figure, no_plot, dpi)
    pert = None
    if displace or kick:
        pert = {"displacement": _dof_values("--displace", displace), "velocity": _dof_values("--kick", kick)}
    model = load_model(model_file)
    from ..io import check_output

    for path in (data, fig_path):
        if path is not None:
            check_output(path, option="--output")  # before the run, not after it
    crit = critical_thrust(model, linearization="equilibrium").thrust
    steps = {v: at_thrust("--thrusts" if thrusts else "--thrust", v, model, lambda v=v: default_step(model, v))
             for v in values}
    if len(values) > 1 and dt is None:  # one time grid for all runs
        dt = min(steps.values())
    if len(values) > 1 and sample is None:
        sample = dt * max(1, math.ceil(duration / dt / 100_000))
    check_work(model, [dt or steps[v] for v in values], duration, dt, sample, allow_long, CLI_NAMES)
    for v in values:
        check_step(model, v, integrator, dt, CLI_NAMES)
    results = []
    with _progress(sys.stderr.isatty() and not as_json) as bar, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for v in values:
            task = bar.add_task(f"T = {v:.6g} N", total=1.0)
            results.append(simulate(model, thrust=v, duration=duration, integrator=integrator.lower(), dt=dt,
                                    perturbation=pert, sample=sample, tol=tol, critical_thrust=crit,
                                    progress=lambda f, task=task: bar.update(task, completed=f), allow_long=allow_long))
    for w in dict.fromkeys(str(w.message) for w in caught):
        click.echo(f"impstab: warning: {printable(w)}", err=True)
    if data is not None:
        _write(results, data)
    if fig_path is not None:
        draw_and_save(lambda: _draw(results), fig_path, dpi)
    if as_json:
        print_json({"runs": [r.to_dict() for r in results], "critical_thrust": crit,
                    "output": None if data is None else str(data), "figure": None if fig_path is None else str(fig_path)})
        return
    con = console()
    con.print(_table(results, model.name))
    for line in _notes(results):
        con.print(line)
    con.print(f"critical thrust {crit:.8g} N" if crit is not None
              else f"no critical thrust up to thrust_max = {model.analysis.thrust_max:g} N")
    con.print("wrote " + " and ".join(user_text(p) for p in (data, fig_path) if p is not None))


commands = [simulate_cmd]
