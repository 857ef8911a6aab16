"""Shared command-line plumbing: error reporting with exit codes, consoles, JSON output."""

from __future__ import annotations

import json
import math
import sys
from typing import Any

import click

from ..errors import ModelError, NumericalError

__all__ = ["run_guarded", "print_json", "jsonable", "BadInput", "console", "check_number"]


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
