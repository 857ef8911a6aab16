"""Command-line interface: a thin layer over the Python API.

Each command area lives in its own module and exposes a list ``commands`` of click commands.
Exit codes: 0 success, 2 bad input (one line on stderr naming the field), 1 internal failure.

A command's module (and with it NumPy, the numerics, numba) is imported only when that command
runs: ``impstab --help`` lists the commands from :data:`COMMANDS` and ``impstab --version``
imports none of them. A new command is one line in :data:`COMMANDS`; a test checks the table
against the modules (names, modules and one-line helps).
"""

from __future__ import annotations

import sys
from collections.abc import Iterator, MutableMapping
from importlib import import_module

import click

from ._common import run_guarded

__all__ = ["main", "cli", "COMMANDS", "load_command", "short_help"]

#: every command: name -> (module of impstab.cli that defines it, first sentence of its help)
COMMANDS: dict[str, tuple[str, str]] = {
    "check": ("core", "Validate MODEL_FILE and print a summary of the assembled model."),
    "modes": ("core", "Natural frequencies, damping, growth rates, the decoupling table and mode shapes at a thrust."),
    "locus": ("core", "Eigenvalue loci against thrust: netCDF data and a figure like the paper's Figure 4."),
    "critical": ("core", "Critical thrust, kind, frequency and margin."),
    "added-mass": ("added_mass", "Added mass, added inertia and radiation resistance of a cylinder segment in a baffle."),
    "simulate": ("simulate", "Nonlinear time histories of MODEL_FILE from the static equilibrium under thrust."),
    "postcritical": ("postcritical", "Hopf analysis at the onset and the branch of limit cycles past it."),
    "response": ("response", "Forced response and force transmissibility |F_hull| / |F_in| to the hull."),
    "sweep": ("sweep", "Run the design study STUDY_FILE (or resume it) into a zarr store."),
    "optimize": ("optimize", "Search the design variables of OPT_FILE for the best isolation that meets its constraints."),
    "map": ("sweep", "Draw the stability map of the study in STORE (PNG, SVG or PDF by the suffix)."),
    "schema": ("schema", "Print the JSON Schema of model files (or of study files, --study)."),
    "stats": ("stats", "Distribution of the critical thrust and margin, probability of missing a required margin and Sobol indices of the random, Sobol or Saltelli study in STORE."),
    "report": ("report", "An HTML report of MODEL_OR_STORE: a model file (.toml) or a study store (impstab sweep)."),
}


def load_command(name: str) -> click.Command:
    """The click command ``name`` of :data:`COMMANDS`, importing its module."""
    module = import_module(f"{__name__}.{COMMANDS[name][0]}")
    for command in module.commands:
        if command.name == name:
            return command
    raise LookupError(f"impstab.cli.{COMMANDS[name][0]} defines no command {name!r}")


def short_help(text: str, limit: int) -> str:
    """``text`` cut to ``limit`` characters as click cuts a command's help in a command list."""
    return click.Command(None, help=text).get_short_help_str(limit)


class _Commands(MutableMapping):
    """``group.commands`` that imports a command's module on first access to that command."""

    def __init__(self, names) -> None:
        self._names = list(names)
        self._loaded: dict[str, click.Command] = {}

    def __getitem__(self, name: str) -> click.Command:
        if name not in self._loaded:
            if name not in self._names:
                raise KeyError(name)
            self._loaded[name] = load_command(name)
        return self._loaded[name]

    def __setitem__(self, name: str, command: click.Command) -> None:
        if name not in self._names:
            self._names.append(name)
        self._loaded[name] = command

    def __delitem__(self, name: str) -> None:
        self._names.remove(name)
        self._loaded.pop(name, None)

    def __iter__(self) -> Iterator[str]:
        return iter(list(self._names))

    def __len__(self) -> int:
        return len(self._names)

    def __contains__(self, name: object) -> bool:
        return name in self._names


class LazyGroup(click.Group):
    """A click group whose commands come from :data:`COMMANDS`, imported when they run."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.commands = _Commands(COMMANDS)  # type: ignore[assignment]

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(self.commands)

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """The command list of ``--help`` from the table (a command added at run time: its own help)."""
        names = self.list_commands(ctx)
        if not names:
            return
        limit = formatter.width - 6 - max(len(n) for n in names)
        rows = []
        for name in names:
            if name in COMMANDS and name not in self.commands._loaded:  # type: ignore[attr-defined]
                text = short_help(COMMANDS[name][1], limit)
            else:
                command = self.commands[name]
                if command.hidden:
                    continue
                text = command.get_short_help_str(limit)
            rows.append((name, text))
        with formatter.section("Commands"):
            formatter.write_dl(rows)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="impstab")
def cli() -> None:
    """impstab: dynamic stability of soft-mounted propulsors under follower thrust."""


def main(argv: list[str] | None = None) -> int:
    """Console entry point; returns the exit code."""
    from .. import _jit
    from .._blas import prefer_single_thread

    prefer_single_thread()  # before numpy loads (see impstab._blas)
    _jit.announce_compiling(lambda line: print(line, file=sys.stderr, flush=True))
    code = run_guarded(cli, argv)
    if argv is None:
        sys.exit(code)
    return code
