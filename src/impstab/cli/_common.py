"""Shared command-line plumbing: error reporting with exit codes, consoles, JSON output."""

from __future__ import annotations

import json
import math
import sys
from typing import Any

import click

from ..errors import ModelError, NumericalError

__all__ = ["run_guarded", "print_json", "jsonable", "BadInput", "console", "check_number", "table", "TextTable", "fmt",
           "figure_options", "data_and_figure", "draw_and_save"]


class BadInput(click.ClickException):
    """A command-line value that breaks a rule (exit code 2)."""

    exit_code = 2


def jsonable(value: Any) -> Any:
    """Convert numpy scalars/arrays and non-finite floats into plain JSON values."""
    import numpy as np

    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, (np.floating, float)):
        f = float(value)
        return f if math.isfinite(f) else None
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value


def console(stderr: bool = False):
    """A rich console as wide as the terminal (``COLUMNS`` when set; 80 columns when piped).

    Piped or redirected, it writes plain text: no colours, and the tables of :func:`table` have
    no box-drawing characters.
    """
    from rich.console import Console

    return Console(highlight=False, stderr=stderr, soft_wrap=False)


def _is_tty(stderr: bool = False) -> bool:
    stream = sys.stderr if stderr else sys.stdout
    try:
        return stream.isatty()
    except (AttributeError, ValueError):
        return False


class TextTable:
    """Rows for the terminal: ruled in a terminal, plain columns under a dashed header line when
    piped, as wide as the console allows.

    Columns are names (text: wrapped at spaces, never inside a word) or ``(name, "right")`` for
    numbers (right-aligned, never wrapped: a number cut in two is misread). A header may hold
    ``"\\n"`` to break a long name.
    """

    def __init__(self, title: str | None, columns) -> None:
        self.title = title
        self.columns = [(c, "left") if isinstance(c, str) else tuple(c) for c in columns]
        self.rows: list[tuple[str, ...]] = []

    def add_row(self, *cells: str) -> None:
        self.rows.append(tuple(str(c) for c in cells))

    def __rich__(self):
        import re
        import textwrap

        from rich import box
        from rich.markup import render
        from rich.table import Table

        plain = box.Box("    \n    \n -- \n    \n    \n -- \n    \n    \n", ascii=True)
        t = Table(title=self.title, box=box.SIMPLE_HEAD if _is_tty() else plain, title_justify="left",
                  show_edge=False, pad_edge=False, collapse_padding=True)
        for j, (name, justify) in enumerate(self.columns):
            words = [w for cell in [name, *(r[j] for r in self.rows if j < len(r))]
                     for w in re.split(r"\s+", render(cell).plain) if w]
            longest = max((len(w) for w in words), default=1)
            if justify == "right":  # a number column is as wide as its numbers: break its header
                cells = [len(render(r[j]).plain) for r in self.rows if j < len(r)]
                width = max(cells + [longest])
                name = "\n".join(textwrap.wrap(name.replace("\n", " "), width)) or name
            t.add_column(name, justify=justify, no_wrap=justify == "right", min_width=longest)
        for r in self.rows:
            t.add_row(*r)
        return t


def table(title: str | None = None, *columns: str | tuple[str, str]) -> TextTable:
    """A :class:`TextTable` with these columns (print it with :func:`console`)."""
    return TextTable(title, columns)


def fmt(value, unit: str = "", digits: int = 6, missing: str = "n/a") -> str:
    """A number for a table: ``digits`` significant digits, its unit, never ``-0``; None and
    NaN as ``missing`` (give the reason where the column's meaning does not say it)."""
    from ..display.format import number

    return number(value, digits, unit, missing=missing)


def figure_options(command):
    """``--figure FILE``, ``--dpi N`` and ``--no-plot`` for a command that draws."""
    command = click.option("--no-plot", "no_plot", is_flag=True, help="write the data only, no figure")(command)
    command = click.option("--dpi", type=float, default=None,
                           help="resolution of a PNG figure (default 150; SVG and PDF are vector)")(command)
    command = click.option("--figure", type=click.Path(dir_okay=False), default=None,
                           help="figure file (.png, .svg or .pdf); default: beside the data, as PNG")(command)
    return command


def data_and_figure(out, data_suffixes: tuple[str, ...], figure: str | None, no_plot: bool, dpi: float | None):
    """``(data path or None, figure path or None)`` from ``-o``, ``--figure`` and ``--no-plot``.

    ``-o`` ending in a data suffix writes the data and, unless ``--no-plot``, a figure
    (``--figure``, default the PNG beside it); ``-o`` ending in .png, .svg or .pdf writes the
    figure only.
    """
    from pathlib import Path

    from ..plot.save import FIGURE_FORMATS, check_figure_path

    out = Path(out)
    check_number("--dpi", dpi, positive=True)
    suffix = out.suffix.lower()
    if suffix in FIGURE_FORMATS:
        if no_plot:
            raise ModelError("--no-plot", True, f"contradicts the figure output {out}")
        if figure is not None:
            raise ModelError("--figure", figure, f"give either -o {out} (a figure) or --figure, not both")
        return None, out
    if suffix not in data_suffixes:
        allowed = ", ".join(data_suffixes + FIGURE_FORMATS)
        raise ModelError("--output", str(out), f"must end in {allowed}")
    if no_plot:
        if figure is not None:
            raise ModelError("--figure", figure, "contradicts --no-plot")
        return out, None
    fig = check_figure_path(figure, "--figure") if figure is not None else out.with_suffix(".png")
    return out, fig


def draw_and_save(draw, path, dpi: float | None = None):
    """Call ``draw()`` (returns Axes or a tuple of Axes) without a display, save its figure to
    ``path`` (format by the suffix), close it; returns the path."""
    import matplotlib

    if matplotlib.get_backend().lower() != "agg":
        matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    from ..plot.save import save_figure

    handle = draw()
    fig = handle.figure if hasattr(handle, "figure") else handle[0].figure
    try:
        return save_figure(fig, path, dpi)
    finally:
        plt.close(fig)


def check_number(field: str, value: float | None, positive: bool = False, nonneg: bool = False) -> None:
    """Reject a non-finite (or, as asked, non-positive / negative) command-line number."""
    if value is None:
        return
    if not math.isfinite(value):
        raise ModelError(field, value, "must be a finite number")
    if positive and value <= 0:
        raise ModelError(field, value, "must be > 0")
    if nonneg and value < 0:
        raise ModelError(field, value, "must be >= 0")


def print_json(obj: dict) -> None:
    """Print one JSON object on stdout and nothing else."""
    sys.stdout.write(json.dumps(jsonable(obj)) + "\n")


def run_guarded(command: click.Command, argv: list[str] | None) -> int:
    """Run a click command, mapping errors to one-line messages and exit codes."""
    try:
        # outside standalone mode click returns ctx.exit(n)'s code instead of raising it
        return int(command.main(args=argv, prog_name="impstab", standalone_mode=False) or 0)
    except ModelError as exc:
        click.echo(f"impstab: error: {exc}", err=True)
        return 2
    except click.exceptions.Exit as exc:
        return int(exc.exit_code or 0)
    except click.exceptions.Abort:
        click.echo("impstab: aborted", err=True)
        return 1
    except click.ClickException as exc:
        code = 2 if isinstance(exc, click.UsageError) else exc.exit_code
        click.echo(f"impstab: error: {exc.format_message()}", err=True)
        return code
    except NumericalError as exc:
        click.echo(f"impstab: numerical failure: {exc}", err=True)
        return 1
    except Exception as exc:  # noqa: BLE001 - last line of defence: no traceback for users
        click.echo(f"impstab: internal error: {type(exc).__name__}: {exc}", err=True)
        return 1
