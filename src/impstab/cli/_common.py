"""Shared command-line plumbing: error reporting with exit codes, consoles, JSON output."""

from __future__ import annotations

import json
import math
import sys
import warnings
from typing import Any

import click

from ..errors import ModelError, NumericalError, printable

__all__ = ["run_guarded", "print_json", "jsonable", "BadInput", "console", "check_number", "user_text", "at_thrust", "check_output"]


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
    """A rich console; piped or redirected output is 160 columns wide so tables do not wrap."""
    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    return Console(highlight=False, width=None if stream.isatty() else 160, stderr=stderr)


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
            raise ModelError(option, thrust, f"no static equilibrium found at this thrust: the model loses stability "
                                             f"at {crit.thrust:.6g} N ({crit.kind}) and its mounts do not carry "
                                             "this thrust") from None
        raise


def check_output(option: str, path: object) -> None:
    """An output path must be a new file or a regular file: a FIFO, a device, a socket or a
    folder of that name would be replaced by the rename that writes the output."""
    import os
    import stat

    try:
        mode = os.lstat(os.fspath(path)).st_mode  # type: ignore[arg-type]
    except FileNotFoundError:
        return
    except (OSError, ValueError):
        return  # unreadable parent or odd name: the write itself reports it with the path
    if stat.S_ISLNK(mode):
        try:
            mode = os.stat(os.fspath(path)).st_mode  # type: ignore[arg-type]
        except OSError:
            return
    if not stat.S_ISREG(mode):
        kind = "a folder" if stat.S_ISDIR(mode) else "not a regular file (a pipe, a device or a socket)"
        raise ModelError(option, str(path), f"exists and is {kind}: give the name of a file to write")


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
