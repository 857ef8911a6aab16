"""``impstab report``: one self-contained HTML report of a model or of a design study."""

from __future__ import annotations

import shlex
from pathlib import Path

import click

from ..errors import ModelError
from ._common import check_number

__all__ = ["commands"]

#: API argument -> the option that sets it (errors name the option)
_OPTION = {"sections": "--sections", "duration": "--duration", "steps": "--steps", "target_margin": "--target-margin"}


def _default_output(source: str) -> Path:
    stem = Path(str(source).rstrip("/\\")).name
    for suffix in (".zarr", ".toml", ".nc"):
        stem = stem.removesuffix(suffix)
    return Path(f"{stem or 'impstab'}-report.html")


def _command_line(ctx: click.Context) -> str:
    """The command as given: its argument and the options set on the command line."""
    from click.core import ParameterSource

    words = ["impstab", ctx.info_name or "report"]
    for param in ctx.command.params:
        value = ctx.params.get(param.name)
        if ctx.get_parameter_source(param.name) not in (ParameterSource.COMMANDLINE, ParameterSource.ENVIRONMENT):
            continue
        if isinstance(param, click.Argument):
            words.append(str(value))
        elif getattr(param, "is_flag", False):
            words.append(param.opts[-1] if value else (param.secondary_opts or param.opts)[-1])
        else:
            words += [param.opts[-1], str(value)]
    return shlex.join(words)


@click.command("report")
@click.argument("model_or_store", type=click.Path())
@click.option("-o", "--output", type=click.Path(dir_okay=False), default=None,
              help="the HTML file (.html); default MODEL-report.html in the current folder")
@click.option("--sections", default=None,
              help="comma-separated sections to include (default all); model: summary, static, modes, stability, "
                   "locus, simulation, isolation, postcritical; study: study, status, maps, best, statistics")
@click.option("--no-simulation", "no_simulation", is_flag=True,
              help="leave out the time histories (a faster report)")
@click.option("--title", default=None, help="page title (default from the model's or study's name)")
@click.option("--duration", type=float, default=None,
              help="length of each time history (s); default: the supercritical run grows by e^3, 40 to 400 periods")
@click.option("--steps", type=int, default=200, show_default=True, help="thrust intervals of the locus")
@click.option("--target-margin", type=float, default=None,
              help="study statistics: required margin, the probability of a margin below it (default 1)")
@click.pass_context
def report_cmd(ctx: click.Context, model_or_store: str, output: str | None, sections: str | None,
               no_simulation: bool, title: str | None, duration: float | None, steps: int,
               target_margin: float | None) -> None:
    """An HTML report of MODEL_OR_STORE: a model file (.toml) or a study store (impstab sweep).

    One self-contained file (inline SVG figures and CSS, no script, nothing fetched) with the
    model, static mount loads, modes and decoupling, critical thrust and margin (damped beside
    undamped), the locus, time histories, vibration isolation, the post-critical section and the
    provenance (version, the input's SHA-256, date and command); for a study: its summary, the
    designs by status, stability maps, the best designs and the statistics.
    """
    import matplotlib

    from ..report import report
    from ..report.render import printable
    from ..report.result import check_report_path

    if matplotlib.get_backend().lower() != "agg":
        matplotlib.use("Agg", force=True)
    out = check_report_path(output) if output is not None else _default_output(model_or_store)
    check_number("--duration", duration, kind="duration")
    from ._common import check_output

    check_output(out, option="--output")
    check_number("--target-margin", target_margin, positive=True)
    chosen = None
    if sections is not None:
        chosen = [s.strip() for s in sections.split(",") if s.strip()]
        if not chosen:
            raise ModelError("--sections", sections, "must name at least one section, separated by commas")
    try:
        rep = report(model_or_store, out, sections=chosen, simulation=not no_simulation, title=title,
                     duration=duration, steps=steps, target_margin=target_margin, command=_command_line(ctx))
    except ModelError as exc:
        if exc.field in _OPTION:
            raise ModelError(_OPTION[exc.field], exc.value, exc.rule) from None
        raise
    states: dict[str, list[str]] = {}
    for s in rep.sections:
        states.setdefault(s.status, []).append(s.name)
    click.echo(f"wrote {printable(str(out))}: {len(rep.sections)} sections ("
               + ", ".join(f"{len(v)} {k}" for k, v in states.items()) + f"), {rep.figures} figures, {rep.tables} tables")
    for s in rep.sections:
        if s.status == "not computed":
            click.echo(f"{s.name}: not computed: {printable(s.reason)}")
        elif s.status == "failed":
            click.echo(f"impstab: warning: section {s.name} failed: {printable(s.reason)}", err=True)


commands = [report_cmd]
