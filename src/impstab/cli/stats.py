"""The ``stats`` command: uncertainty statistics of a random, Sobol or Saltelli study."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import click

from ..errors import ModelError
from ._common import check_number, console, print_json

__all__ = ["commands"]

_FIGURES = (".png", ".svg", ".pdf")


def _percent_table(stats):
    from rich import box
    from rich.table import Table

    t = Table(box=box.SIMPLE_HEAD, title=f"percentiles of the {stats.computed} computed designs, "
              f"{100 * stats.confidence:g} % intervals", title_justify="left")
    t.add_column("q", justify="right")
    t.add_column("critical thrust (N)", justify="right")
    t.add_column("interval (N)")
    if stats.margin is not None:
        t.add_column("margin", justify="right")
        t.add_column("interval")
    crit = stats.percentiles("critical_thrust") if stats.critical_thrust is not None else []
    marg = stats.percentiles("margin") if stats.margin is not None else []
    for i, q in enumerate(stats.percents):
        row = [f"{q:g} %"]
        row += [crit[i].text(units=False), crit[i].interval_text()] if crit else ["n/a", ""]
        if marg:
            row += [marg[i].text(units=False), marg[i].interval_text()]
        t.add_row(*row)
    return t


def _sensitivity_table(ind):
    from rich import box
    from rich.table import Table

    t = Table(box=box.SIMPLE_HEAD, title=f"Sobol indices of {ind.of}", title_justify="left")
    conf = f"{100 * ind.confidence:g} %"
    t.add_column("parameter")
    t.add_column(f"first order +- {conf}", justify="right")
    if ind.total_order is not None:
        t.add_column(f"total +- {conf}", justify="right")
    for i, p in enumerate(ind.parameters):
        row = [p, f"{ind.first_order[i]:.3f} +- {ind.first_order_conf[i]:.3f}"]
        if ind.total_order is not None:
            row.append(f"{ind.total_order[i]:.3f} +- {ind.total_order_conf[i]:.3f}")
        t.add_row(*row)
    return t


def _summary_table(stats):
    from rich import box
    from rich.table import Table

    t = Table(box=box.SIMPLE_HEAD, show_header=False, title=f"statistics of {stats.study_name} ({stats.sampling})",
              title_justify="left")
    t.add_column("quantity", no_wrap=True)
    t.add_column("value", max_width=58)
    for k, v in stats.summary_rows():
        t.add_row(k, v)
    t.add_row("intervals", stats.intervals + (" (independent samples)" if stats.exact else
                                              " (those of independent sampling, for Sobol points)"))
    return t


def _save(ax, out: Path, dpi: float | None) -> None:
    from ..io import atomic_path

    with atomic_path(out) as tmp:
        ax.figure.savefig(tmp, format=out.suffix.lower().lstrip("."), dpi=dpi or 150)


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
@click.option("--dpi", type=float, default=None, help="resolution of a PNG figure (default 150)")
def stats_cmd(store: str, target_margin: float | None, confidence: float, no_sensitivity: bool, as_json: bool,
              output: str | None, dpi: float | None) -> None:
    """Distribution of the critical thrust and margin, probability of missing a required margin
    and Sobol indices of the random, Sobol or Saltelli study in STORE."""
    from ..studies import open_study
    from ..studies.statistics import study_statistics

    check_number("--target-margin", target_margin, positive=True)
    check_number("--confidence", confidence, positive=True)
    out = Path(output) if output else None
    if out is not None and out.suffix.lower() not in _FIGURES:
        raise ModelError("--output", str(out), "must end in .png, .svg or .pdf")
    if dpi is not None and not (math.isfinite(dpi) and 1 <= dpi <= 2400):
        raise ModelError("--dpi", dpi, "must be between 1 and 2400")
    res = open_study(store)
    kw = {"confidence": confidence, "sensitivity": not no_sensitivity}
    try:
        stats = study_statistics(res, 1.0 if target_margin is None else target_margin, **kw)
    except ModelError as err:
        if target_margin is not None or err.field != "--target-margin":
            raise
        stats = study_statistics(res, None, **kw)  # the search ends below the operating thrust
    if out is not None:
        import matplotlib

        if matplotlib.get_backend().lower() != "agg":
            matplotlib.use("Agg", force=True)
        import matplotlib.pyplot as plt

        axes = stats.plot()
        try:
            _save(axes, out, dpi)
        finally:
            plt.close(axes.figure)
    if as_json:
        print_json(stats.to_dict())
        return
    con = console()
    con.print(_summary_table(stats))
    con.print(_percent_table(stats))
    if stats.sensitivity is not None:
        con.print(_sensitivity_table(stats.sensitivity))
    for note in stats.notes:
        click.echo(textwrap.fill(f"note: {note}", width=80, subsequent_indent="  "))
    if out is not None:
        con.print(f"wrote {out}")


commands = [stats_cmd]
