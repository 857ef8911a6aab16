"""``impstab added-mass``: fluid coefficients of the wetted cylinder segment (THEORY 9)."""

from __future__ import annotations

from typing import Any

import click
import numpy as np

from ..errors import ModelError
from ._common import check_number, console, fmt, print_json, table

__all__ = ["commands", "parse_frequencies"]

_FLAGS = {"radius": "--radius", "length": "--length", "density": "--density",
          "sound_speed": "--sound-speed", "frequency": "--frequency", "frequencies": "--frequencies"}


def parse_frequencies(spec: str) -> np.ndarray:
    """``"START:STOP:NUM"`` -> ``NUM`` equally spaced frequencies from START to STOP (Hz, inclusive)."""
    rule = "must be START:STOP:NUM (Hz, 0 <= START <= STOP, NUM an integer >= 1)"
    parts = spec.split(":")
    if len(parts) != 3:
        raise ModelError("--frequencies", spec, rule)
    try:
        start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise ModelError("--frequencies", spec, rule) from None
    if not (np.isfinite(start) and np.isfinite(stop) and 0.0 <= start <= stop and num >= 1):
        raise ModelError("--frequencies", spec, rule)
    if num == 1 and start != stop:
        raise ModelError("--frequencies", spec, "NUM = 1 needs START = STOP")
    return np.linspace(start, stop, num)


def _fmt(x: float | None, digits: int = 6, missing: str = "none (incompressible)") -> str:
    return fmt(x, digits=digits, missing=missing)


def _with_flag_names(call, *args, **kwargs) -> Any:
    """Run a fluid-model call, naming the command-line flag in a ModelError."""
    try:
        return call(*args, **kwargs)
    except ModelError as exc:
        if exc.field in _FLAGS:
            raise ModelError(_FLAGS[exc.field], exc.value, exc.rule) from None
        raise


def _point_table(r) -> None:
    out = table(f"baffled cylinder  a = {r.radius:g} m, L = {r.length:g} m", "quantity", ("value", "right"), "unit")
    rows = (
        ("added mass m_a", r.added_mass, "kg"),
        ("added inertia I_a (about the centre)", r.added_inertia, "kg m^2"),
        ("radiation resistance R", r.radiation_resistance, "N s/m"),
        ("rotational radiation resistance R_rot", r.rotational_radiation_resistance, "N m s"),
        ("m_a / (rho pi a^2 L)", r.strip_ratio, ""),
        ("I_a / (rho pi a^2 L^3 / 12)", r.inertia_strip_ratio, ""),
        ("loss factor R / (omega m_a)", r.loss_factor, ""),
        ("density", r.density, "kg/m^3"),
        ("sound speed", r.sound_speed, "m/s"),
        ("frequency", r.frequency, "Hz"),
        ("error estimate (relative)", r.error_estimate, ""),
    )
    for label, value, unit in rows:
        out.add_row(label, "incompressible" if value is None and "sound" in label else _fmt(value), unit)
    console().print(out)


def _sweep_table(sweep) -> None:
    first = sweep.points[0]
    c = "incompressible" if first.sound_speed is None else f"c = {_fmt(first.sound_speed)} m/s"
    out = table(f"baffled cylinder  a = {first.radius:g} m, L = {first.length:g} m, {c}",
                *((name, "right") for name in ("f (Hz)", "m_a (kg)", "m_a/strip", "I_a (kg m^2)", "I_a/strip",
                                                "R (N s/m)", "R_rot (N m s)", "loss factor (1)")))
    for p in sweep.points:
        out.add_row(*(_fmt(v, missing="n/a") for v in (
            p.frequency, p.added_mass, p.strip_ratio, p.added_inertia, p.inertia_strip_ratio,
            p.radiation_resistance, p.rotational_radiation_resistance, p.loss_factor)))
    console().print(out)
    if first.sound_speed is None:
        console().print("R, R_rot, loss factor: n/a, there is no radiation in an incompressible fluid (give --sound-speed)")


def _progress(values):
    from rich.progress import track

    err = console(stderr=True)
    return track(values, description="frequencies", console=err, transient=True,
                 disable=not err.is_terminal or len(values) < 20)


@click.command("added-mass")
@click.option("--radius", type=float, required=True, help="Cylinder radius a (m).")
@click.option("--length", type=float, required=True, help="Wetted segment length L (m).")
@click.option("--density", type=float, default=1025.0, show_default=True, help="Fluid density (kg/m^3).")
@click.option("--sound-speed", type=float, default=None, help="Speed of sound (m/s); omit for incompressible.")
@click.option("--frequency", type=float, default=0.0, show_default=True, help="Frequency (Hz).")
@click.option("--frequencies", "frequencies", default=None, metavar="START:STOP:NUM",
              help="Sweep NUM equally spaced frequencies from START to STOP (Hz, inclusive).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object on stdout and nothing else.")
@click.option("-o", "--output", type=click.Path(dir_okay=False), default=None,
              help="With --frequencies: plot the coefficients against frequency to this figure "
                   "(.png, .svg or .pdf), or write them to a netCDF file (.nc).")
@click.option("--dpi", type=float, default=None, help="Resolution of a PNG figure (default 150).")
def added_mass_cmd(radius: float, length: float, density: float, sound_speed: float | None,
                   frequency: float, frequencies: str | None, as_json: bool, output: str | None,
                   dpi: float | None) -> None:
    """Added mass, added inertia and radiation resistance of a cylinder segment in a baffle.

    Coefficients are for transverse motion about the segment centre (SI units, frequency in Hz).
    """
    from .. import fluid

    if frequencies is None:
        if output is not None:
            raise ModelError("--output", output, "needs --frequencies (a plot against frequency)")
        r = _with_flag_names(fluid.baffled_cylinder, radius, length, density, sound_speed, frequency)
        if as_json:
            print_json(r.to_dict())
        else:
            _point_table(r)
        return
    if frequency != 0.0:
        raise ModelError("--frequencies", frequencies, "give either --frequency or --frequencies, not both")
    if output is not None and not output.lower().endswith(".nc"):
        from ..plot.save import check_figure_path

        check_figure_path(output)
    check_number("--dpi", dpi, positive=True)
    grid = parse_frequencies(frequencies)
    # validate the geometry before a long sweep starts
    _with_flag_names(fluid.baffled_cylinder, radius, length, density, sound_speed, 0.0)
    sweep = _with_flag_names(fluid.frequency_sweep, radius, length, grid, density, sound_speed,
                             progress=_progress)
    if output is not None and output.lower().endswith(".nc"):
        from ..io import atomic_path

        with atomic_path(output) as tmp:
            sweep.to_xarray().to_netcdf(tmp, engine="h5netcdf")
    elif output is not None:
        _save_figure(sweep, output, dpi)
    if as_json:
        print_json(sweep.to_dict())
    else:
        _sweep_table(sweep)


def _save_figure(sweep, output: str, dpi: float | None) -> None:
    from ..plot.save import save_figure

    save_figure(sweep.plot(), output, dpi)


commands = [added_mass_cmd]
