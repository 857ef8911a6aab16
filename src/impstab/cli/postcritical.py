"""``impstab postcritical``: Hopf analysis at the onset and the branch of limit cycles."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from ..errors import ModelError
from ._common import (check_number, console, data_and_figure, draw_and_save, figure_options, fmt, print_json, table,
                      user_text)

__all__ = ["commands", "parse_thrusts", "MAX_REQUESTED"]

#: most thrusts ``--thrusts`` may list
MAX_REQUESTED = 200
#: most continuation steps ``--max-points`` may ask for
MAX_POINTS = 5000


def parse_thrusts(text: str | None) -> list[float] | None:
    """``T1,T2,..`` (N) as numbers, each a valid thrust; None when not given."""
    if text is None:
        return None
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ModelError("--thrusts", text, "must be numbers separated by commas, e.g. 10400,10500") from None
    if not values:
        raise ModelError("--thrusts", text, "must list at least one thrust")
    if len(values) > MAX_REQUESTED:
        raise ModelError("--thrusts", f"{len(values)} thrusts", f"must list at most {MAX_REQUESTED} thrusts")
    return [check_number("--thrusts", v, kind="thrust_or_zero") for v in values]


def _progress(enabled: bool):
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                    console=Console(stderr=True), transient=True, disable=not enabled)


def _summary(res) -> None:
    con = console()
    t = table(f"post-critical analysis of {user_text(res.model_name)}", "quantity", ("value", "right"))
    t.add_row("critical thrust T_c", fmt(res.critical_thrust, "N", 10, missing="none up to thrust_max"))
    t.add_row("kind", res.kind)
    t.add_row("onset frequency", "n/a" if not res.omega else f"{fmt(res.frequency_hz, 'Hz')} ({fmt(res.omega, 'rad/s')})")
    t.add_row("first Lyapunov coefficient l1", fmt(res.lyapunov_coefficient, digits=6, missing="not defined here"))
    t.add_row("crossing speed d(Re lambda)/dT", fmt(res.crossing_speed, "1/(s N)", 6))
    t.add_row("bifurcation", res.bifurcation or "none")
    t.add_row("fold of cycles", fmt(res.fold_thrust, "N", 8, missing="none on the computed branch"))
    t.add_row("practical limit thrust", fmt(res.practical_limit_thrust, "N", 8, missing="none"))
    t.add_row("operating thrust", fmt(res.operating_thrust, "N", missing="not given"))
    con.print(t)
    if res.reason:
        con.print(f"reason: {user_text(res.reason)}")
    k = res.branch_thrust.size
    if k:
        import numpy as np

        picks = sorted(set(np.linspace(0, k - 1, min(k, 12)).round().astype(int).tolist())
                       | {i for i, lab in enumerate(res.branch_label) if lab in ("requested", "fold", "no cycle")})
        dofs = res_dofs()
        scale = np.asarray(res.settings.get("state_scale", np.ones(12)), dtype=float)[:6]
        with np.errstate(invalid="ignore"):
            size = np.nan_to_num(np.nanmax(res.branch_amplitude / scale[None, :], axis=0, initial=0.0))
        shown = sorted(np.argsort(-size, kind="stable")[:3].tolist())
        b = table(f"branch: {k} points ({len(picks)} shown; amplitudes of the three largest coordinates, "
                  f"half peak-to-peak)", ("thrust (N)", "right"), ("period (s)", "right"), "stable",
                  *((f"{dofs[j]} ({'m' if j < 3 else 'rad'})", "right") for j in shown),
                  ("mount\nforce (N)", "right"), "label")
        for i in picks:
            label = res.branch_label[i] or "-"
            if res.snubber_contact[i]:
                label += ", snubber"
            b.add_row(fmt(res.branch_thrust[i], digits=8), fmt(res.branch_period[i], digits=6, missing="-"),
                      "yes" if res.branch_stable[i] else "no",
                      *(fmt(res.branch_amplitude[i, j], digits=4, missing="-") for j in shown),
                      fmt(res.peak_mount_force[i], digits=5, missing="-"), label)
        con.print(b)
        con.print(f"branch end: {user_text(res.stop_reason)}; largest |mu_trivial - 1| = "
                  f"{fmt(float(np.nanmax(res.trivial_multiplier_error)) if np.any(np.isfinite(res.trivial_multiplier_error)) else None, digits=2)}")
    for w in res.warnings:
        con.print(f"[yellow]warning:[/yellow] {user_text(w)}")
    con.print(f"[bold]reading:[/bold] {user_text(res.reading)}")


def res_dofs():
    from ..postcritical.propulsor_result import DOFS

    return DOFS


@click.command("postcritical")
@click.argument("model_file", type=click.Path(dir_okay=False))
@click.option("--thrust-max", type=float, default=None, help="upper end of the onset search and of the branch (N)")
@click.option("--thrusts", default=None, help="thrusts T1,T2,.. (N) at which cycles are wanted, each solved exactly")
@click.option("--max-points", type=int, default=None, help="continuation steps at most (default 60)")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object and nothing else")
@click.option("-o", "--output", type=click.Path(dir_okay=False), default=None,
              help="OUT.nc (netCDF, with the bifurcation diagram as PNG beside it) or a figure only (.png, .svg, .pdf)")
@figure_options
def postcritical_cmd(model_file, thrust_max, thrusts, max_points, as_json, output, figure, dpi, no_plot) -> None:
    """Hopf analysis at the onset and the branch of limit cycles past it.

    The first Lyapunov coefficient l1 decides the onset: supercritical (l1 < 0, benign: a small
    stable cycle grows gently past the critical thrust) or subcritical (l1 > 0, dangerous: large
    cycles exist below it, down to the fold of cycles, which is then the practical limit).
    Undamped models, symmetric rings and divergence onsets are reported as degenerate with the
    reason. The branch of cycles is continued in thrust with Floquet multipliers.
    """
    from ..model import load_model
    from ..postcritical.propulsor import DEFAULTS, propulsor_postcritical

    t_max = check_number("--thrust-max", thrust_max, kind="thrust")
    requested = parse_thrusts(thrusts)
    if max_points is not None and not 1 <= max_points <= MAX_POINTS:
        raise ModelError("--max-points", max_points, f"must be an integer from 1 to {MAX_POINTS}")
    data = fig_path = None
    if output is not None:
        data, fig_path = data_and_figure(Path(output), (".nc",), figure, no_plot, dpi)
    elif figure is not None:
        from ..io import check_output
        from ..plot.save import check_figure_path

        fig_path = check_figure_path(figure, "--figure")
        check_output(fig_path, option="--figure")
    model = load_model(model_file)
    t_max = t_max if t_max is not None else model.analysis.thrust_max
    if requested:
        for v in requested:
            if v > t_max:
                raise ModelError("--thrusts", v, f"must not exceed the thrust_max of {t_max:g} N")
    points = int(max_points or DEFAULTS["max_points"])
    with _progress(sys.stderr.isatty() and not as_json) as bar:
        task = bar.add_task("limit cycles", total=points)
        res = propulsor_postcritical(model, thrust_max=t_max, thrusts=requested, max_points=points,
                                     progress=lambda k, p: bar.update(task, completed=min(k, points),
                                                                      description=f"limit cycles, T = {p:.6g} N"))
    if data is not None:
        from ..io import write_netcdf

        write_netcdf(res.to_xarray(), data, option="--output")
    if fig_path is not None:
        draw_and_save(lambda: res.plot(), fig_path, dpi)
    if as_json:
        obj = res.to_dict()
        obj["output"] = None if data is None else str(data)
        obj["figure"] = None if fig_path is None else str(fig_path)
        print_json(obj)
        return
    _summary(res)
    written = [p for p in (data, fig_path) if p is not None]
    if written:
        console().print("wrote " + " and ".join(user_text(p) for p in written))


commands = [postcritical_cmd]
