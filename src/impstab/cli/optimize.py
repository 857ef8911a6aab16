"""``impstab optimize``: the mount design that isolates best under stability and static limits."""

from __future__ import annotations

from pathlib import Path

import click

from ._common import check_output, console, draw_and_save, fmt, print_json, table, user_text

__all__ = ["commands"]


@click.command("optimize")
@click.argument("opt_file", type=click.Path(dir_okay=False))
@click.option("-o", "--output", "store", type=click.Path(), default=None,
              help="zarr store of the Pareto set (a folder); default OPT.zarr in the current folder")
@click.option("--model", "model_out", type=click.Path(dir_okay=False), default=None,
              help="model file (.toml) of the chosen design; default OPT-chosen.toml")
@click.option("--figure", type=click.Path(dir_okay=False), default=None,
              help="figure of every evaluated design and the Pareto front (.png, .svg, .pdf); default OPT.png")
@click.option("--no-plot", "no_plot", is_flag=True, help="no figure")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object instead of the table")
def optimize_cmd(opt_file: str, store: str | None, model_out: str | None, figure: str | None, no_plot: bool,
                 as_json: bool) -> None:
    """Search the design variables of OPT_FILE for the best isolation that meets its constraints."""
    from ..errors import ModelError
    from ..optimize.problem import load_optimization
    from ..optimize.run import run_optimization
    from ..plot.save import check_figure_path

    stem = Path(opt_file).stem
    opt = load_optimization(opt_file)
    out = Path(store) if store else Path(stem + ".zarr")
    model_path = Path(model_out) if model_out else Path(stem + "-chosen.toml")
    if model_path.suffix.lower() != ".toml":
        raise ModelError("--model", str(model_path), "must end in .toml (a model file)")
    check_output(model_path, option="--model")
    fig = None
    if not no_plot:
        fig = check_figure_path(figure, "--figure") if figure else Path(stem + ".png")
        check_output(fig, option="--figure")
    elif figure is not None:
        raise ModelError("--figure", figure, "contradicts --no-plot")
    res = run_optimization(opt, str(out), str(model_path))
    if fig is not None:
        draw_and_save(res.plot, fig)
    data = res.to_dict()
    data["figure"] = None if fig is None else str(fig)
    if as_json:
        print_json(data)
        return
    c = res.chosen
    t = table(f"optimisation {user_text(opt.name)}", "quantity", "value")
    t.add_row("designs evaluated", f"{data['evaluations']} in {opt.generations} batched generations of {opt.population}, "
                                   f"{data['feasible_designs']} feasible; polish {data['polish_evaluations']} evaluations")
    for k, v in c["parameters"].items():
        t.add_row(f"chosen {user_text(k)}", fmt(v))
    t.add_row(f"chosen {user_text(opt.objective)}", fmt(c["isolation"], "N/N"))
    t.add_row("chosen margin", (">= " if c["margin_is_lower_bound"] else "") + fmt(c["margin"]))
    t.add_row("chosen static deflection / peak mount load", f"{fmt(1e3 * c['static_deflection'], 'mm')} / {fmt(c['peak_mount_load'], 'N')}")
    t.add_row("polished", "yes (better than the best of the population)" if c["polished"] else "no (the population's best stands)")
    t.add_row("Pareto set", f"{data['pareto_designs']} designs in {user_text(out)}")
    t.add_row("chosen design", user_text(data["model_file"]))
    if fig is not None:
        t.add_row("figure", user_text(fig))
    t.add_row("time", f"{res.seconds:.3g} s")
    console().print(t)


commands = [optimize_cmd]
