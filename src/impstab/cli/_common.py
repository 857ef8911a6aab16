"""Shared command-line plumbing: error reporting with exit codes, consoles, JSON output."""

from __future__ import annotations

import json
import math
import sys
import warnings
from typing import Any

import click

from ..errors import ModelError, NumericalError, printable
from ..io import check_output  # noqa: F401  (re-exported for the commands)

__all__ = ["run_guarded", "print_json", "jsonable", "BadInput", "console", "check_number", "table", "TextTable", "fmt",
           "figure_options", "data_and_figure", "draw_and_save", "user_text", "at_thrust", "check_output"]


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
    check_number("--dpi", dpi, kind="dpi")
    suffix = out.suffix.lower()
    if suffix in FIGURE_FORMATS:
        if no_plot:
            raise ModelError("--no-plot", True, f"contradicts the figure output {out}")
        if figure is not None:
            raise ModelError("--figure", figure, f"give either -o {out} (a figure) or --figure, not both")
        check_output(out, option="--output")
        return None, out
    if suffix not in data_suffixes:
        allowed = ", ".join(data_suffixes + FIGURE_FORMATS)
        raise ModelError("--output", str(out), f"must end in {allowed}")
    if no_plot:
        if figure is not None:
            raise ModelError("--figure", figure, "contradicts --no-plot")
        return out, None
    fig = check_figure_path(figure, "--figure") if figure is not None else out.with_suffix(".png")
    check_output(out, option="--output")
    check_output(fig, option="--figure" if figure is not None else "--output")
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


def check_number(field: str, value: float | None, positive: bool = False, nonneg: bool = False,
                 kind: str | None = None) -> float | None:
    """A command-line number within its physical range, or a ModelError naming the option.

    ``kind`` names a range of :data:`impstab.limits.RANGES` (``"thrust"``, ``"duration"``, ...);
    without it the number must be finite (within +-1e15), and > 0 or >= 0 as asked.
    """
    from ..limits import check_number as _check

    if value is None:
        return None
    if kind is None:
        kind = "positive" if positive else "nonnegative" if nonneg else "number"
    return _check(field, value, kind)


def at_thrust(option: str, thrust: float, model, compute):
    """``compute()`` at a command-line thrust (N). Where no static equilibrium is found there and
    the model has lost stability at or below that thrust, the thrust is beyond what the model
    can carry: bad input naming ``option`` (exit 2), with the critical thrust. A failure below
    the critical thrust stays a numerical failure (exit 1)."""
    try:
        return compute()
    except NumericalError as exc:
        from ..linear.critical_thrust import critical_thrust

        try:
            crit = critical_thrust(model, thrust_max=max(thrust, model.analysis.thrust_max))
        except (NumericalError, ModelError):
            raise exc from None
        if crit.thrust is not None and thrust >= crit.thrust:
            reason = getattr(exc, "reason", "its mounts do not carry this thrust")
            raise ModelError(option, thrust, f"no static equilibrium found at this thrust: {reason}; the model "
                                             f"loses stability at {crit.thrust:.6g} N ({crit.kind})") from None
        raise


def user_text(value: object) -> str:
    """A user string (model name, path, key) ready for a rich console: control characters
    shown escaped (:func:`impstab.errors.printable`) and rich markup brackets escaped."""
    from rich.markup import escape

    return escape(printable(value))


def print_json(obj: dict) -> None:
    """Print one JSON object on stdout and nothing else."""
    sys.stdout.write(json.dumps(jsonable(obj)) + "\n")


#: click >= 8.2 raises this for a group called without a command (older versions print the help)
_NO_ARGS_IS_HELP = getattr(click.exceptions, "NoArgsIsHelpError", ())


def _say(kind: str, text: object) -> None:
    """One line on stderr: ``impstab: <kind>: <text>`` with the text made printable."""
    click.echo(f"impstab: {kind}: {printable(text)}", err=True)


def _warning_lines(caught: list) -> list[str]:
    """Distinct warnings of a run, one line each (numpy's floating-point warnings included)."""
    lines: list[str] = []
    for w in caught:
        text = f"{w.category.__name__}: {w.message}" if issubclass(w.category, RuntimeWarning) else str(w.message)
        if text not in lines:
            lines.append(text)
    return lines


def run_guarded(command: click.Command, argv: list[str] | None) -> int:
    """Run a click command, mapping errors to one-line messages and exit codes.

    Exit codes: 0 success, 2 bad input (a :class:`~impstab.errors.ModelError` or a usage
    error: exactly one line on stderr), 1 a numerical or internal failure (one line),
    130 interrupted. Warnings raised during the run (numpy floating-point warnings among them)
    never spill as multi-line tracebacks: after a successful or failed computation each distinct
    one is reported on one line; after bad input only the error line is printed. User strings
    in every message are shown with control characters escaped.
    """
    caught: list = []
    code = 1
    try:
        # record what the warning filters let through (numpy's floating-point warnings among them);
        # filters set by impstab or its libraries still apply
        with warnings.catch_warnings(record=True) as caught:
            try:
                code = _invoke(command, argv)
            except ModelError as exc:
                code = 2
                _say("error", exc)
            except click.exceptions.Exit as exc:
                code = int(exc.exit_code or 0)
            except (click.exceptions.Abort, KeyboardInterrupt):
                code = 130
                _say("error", "interrupted")
            except _NO_ARGS_IS_HELP as exc:  # a bare command group: its help, as with --help
                click.echo(exc.ctx.get_help() if exc.ctx is not None else "")
                code = 0
            except click.ClickException as exc:
                code = 2 if isinstance(exc, click.UsageError) else exc.exit_code
                _say("error", exc.format_message())
            except NumericalError as exc:
                code = 1
                _say("numerical failure", exc)
            except BrokenPipeError:
                _silence_stdout()
                return 1
            except RecursionError:
                code = 2
                _say("error", "the input is nested too deeply to be read")
            except MemoryError:
                code = 1
                _say("error", "out of memory")
            except OSError as exc:
                code = 2 if exc.filename is not None else 1
                where = f"{exc.filename}: " if exc.filename is not None else ""
                _say("error", f"{where}{exc.strerror or type(exc).__name__}")
            except Exception as exc:  # noqa: BLE001 - last line of defence: no traceback for users
                if isinstance(exc, ValueError) and "null" in str(exc):  # "embedded null byte": a path with NUL
                    code = 2
                    _say("error", "a path or argument contains a NUL character")
                else:
                    code = 1
                    _say("internal error", f"{type(exc).__name__}: {exc}")
    except BrokenPipeError:
        _silence_stdout()
        return 1
    if code != 2:
        for line in _warning_lines(caught):
            _say("warning", line)
    _flush()
    return code


def _invoke(command: click.Command, argv: list[str] | None) -> int:
    """Parse and run ``command`` (``command.main`` without its own handling of Ctrl-C, which
    prints an empty line before the one that reports it)."""
    args = sys.argv[1:] if argv is None else list(argv)
    with command.make_context("impstab", args) as ctx:
        command.invoke(ctx)
    return 0


def _flush() -> None:
    """Flush stdout now, so that a closed pipe is noticed here and not at interpreter exit."""
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _silence_stdout()
    except (OSError, ValueError):
        pass


def _silence_stdout() -> None:
    """After the reader of stdout went away: point stdout at /dev/null (Python would otherwise
    print a traceback when it flushes stdout at exit)."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):
        pass
