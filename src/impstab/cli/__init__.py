"""Command-line interface: a thin layer over the Python API.

Each command area lives in its own module and exposes a list ``commands`` of click commands.
Exit codes: 0 success, 2 bad input (one line on stderr naming the field), 1 internal failure.
"""

from __future__ import annotations

import sys

import click

from . import added_mass, core, schema, simulate, stats, sweep
from . import response as response_cli
from ._common import run_guarded

__all__ = ["main", "cli"]


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="impstab")
def cli() -> None:
    """impstab: dynamic stability of soft-mounted propulsors under follower thrust."""


for _module in (core, added_mass, simulate, sweep, schema, response_cli, stats):
    for _command in _module.commands:
        cli.add_command(_command)


def main(argv: list[str] | None = None) -> int:
    """Console entry point; returns the exit code."""
    code = run_guarded(cli, argv)
    if argv is None:
        sys.exit(code)
    return code
