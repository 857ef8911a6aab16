"""The ``stats`` command: uncertainty statistics of a random, Sobol or Saltelli study."""

from __future__ import annotations

import textwrap
from pathlib import Path

import click

from ..errors import ModelError
from ._common import check_number, console, draw_and_save, print_json, table

__all__ = ["commands"]


def _column(values: list[str], intervals: list[str]) -> list[str]:
    """``value  [low, high]`` cells with the values right-aligned among themselves."""
    width = max(len(v) for v in values)
    return [f"{v.rjust(width)}  {i}" for v, i in zip(values, intervals)]


def _percent_table(stats):
    conf = f"{100 * stats.confidence:g} %"
    cols = [("q", "right")]
    cells = []
    for name, head in (("critical_thrust", "critical thrust (N)"), ("margin", "margin")):
        if getattr(stats, name) is None:
            continue
        ps = stats.percentiles(name)
        cols.append(f"{head} [{conf} interval]")
        cells.append(_column([p.text(units=False) for p in ps], [p.interval_text() for p in ps]))
    t = table(f"percentiles of the {stats.computed} computed designs", *cols)
    for i, q in enumerate(stats.percents):
        t.add_row(f"{q:g} %", *(c[i] for c in cells))
    return t


def _sensitivity_table(ind):
    conf = f"{100 * ind.confidence:g} %"
    cols = ["parameter", f"first order +- {conf}"] + ([f"total +- {conf}"] if ind.total_order is not None else [])
    t = table(f"Sobol indices of {ind.of}", *cols)
    rows = [ind.cells(i) for i in range(len(ind.parameters))]
    widths = [max(len(r[j].split(" +- ")[0]) for r in rows) for j in range(len(cols) - 1)]
    for p, r in zip(ind.parameters, rows):
        t.add_row(p, *(c.rjust(len(c) + widths[j] - len(c.split(" +- ")[0])) for j, c in enumerate(r)))
    return t


def _summary_table(stats):
    t = table(f"statistics of {stats.study_name} ({stats.sampling})", "quantity", "value")
    for k, v in stats.summary_rows():
        t.add_row(k, v)
    t.add_row("intervals", stats.intervals + (" (independent samples)" if stats.exact else
                                              " (those of independent sampling, for Sobol points)"))
    return t


@click.command("stats")
@click.argument("store", type=click.Path())
@click.option("--target-margin", type=float, default=None,
              help="required margin (critical / operating thrust): the probability of a margin below it "
                   "(default 1, when thrust_max reaches the operating thrust)")
@click.option("--confidence", type=float, default=0.95, show_default=True, help="level of every interval and band")
@click.option("--no-sensitivity", is_flag=True, default=False, help="leave out the Sobol sensitivity indices")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object (units in docs/studies.md)")
@click.option("-o", "--output", default=None, type=click.Path(dir_okay=False),
              help="figure (.png, .svg or .pdf): histogram, ECDF with its band, sensitivity indices")
@click.option("--dpi", type=float, default=None, help="resolution of a PNG figure (default 150; SVG and PDF are vector)")
def stats_cmd(store: str, target_margin: float | None, confidence: float, no_sensitivity: bool, as_json: bool,
              output: str | None, dpi: float | None) -> None:
    """Distribution of the critical thrust and margin, probability of missing a required margin
    and Sobol indices of the random, Sobol or Saltelli study in STORE."""
    from ..plot.save import check_figure_path
    from ..studies import open_study
    from ..studies.statistics import study_statistics

    check_number("--target-margin", target_margin, positive=True)
    check_number("--confidence", confidence, positive=True)
    check_number("--dpi", dpi, positive=True)
    out = check_figure_path(output) if output else None
    res = open_study(store)
    kw = {"confidence": confidence, "sensitivity": not no_sensitivity}
    try:
        stats = study_statistics(res, 1.0 if target_margin is None else target_margin, **kw)
    except ModelError as err:
        if target_margin is not None or err.field != "--target-margin":
            raise
        stats = study_statistics(res, None, **kw)  # the search ends below the operating thrust
    if out is not None:
        draw_and_save(stats.plot, out, dpi)
    if as_json:
        print_json(stats.to_dict())
        return
    con = console()
    con.print(_summary_table(stats))
    con.print()
    con.print(_percent_table(stats))
    if stats.sensitivity is not None:
        con.print()
        con.print(_sensitivity_table(stats.sensitivity))
    con.print()
    for note in stats.notes:
        click.echo(textwrap.fill(f"note: {note}", width=80, subsequent_indent="  "))
    if out is not None:
        con.print(f"wrote {out}")


commands = [stats_cmd]
