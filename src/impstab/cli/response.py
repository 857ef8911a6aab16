"""``impstab response``: forced response and force transmissibility to the hull."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from ..errors import ModelError
from ._common import check_number, console, print_json

__all__ = ["commands"]

LINEARIZATION = click.Choice(["equilibrium", "classical"])


def _frequencies(spec: str) -> np.ndarray:
    """``START:STOP:NUM`` (Hz) with NUM bounded by ``impstab.response.MAX_FREQUENCIES``."""
    from ..response.api import MAX_FREQUENCIES
    from .added_mass import parse_frequencies

    parts = spec.split(":")
    if len(parts) == 3:
        try:
            num = int(parts[2])
        except ValueError:
            num = 0
        if num > MAX_FREQUENCIES:
            raise ModelError("--frequencies", spec, f"NUM must be at most {MAX_FREQUENCIES}")
    return parse_frequencies(spec)


def _isolation_onset(f: np.ndarray, t: np.ndarray) -> float | None:
    """Lowest frequency above which the transmissibility stays below 1 up to the range end (Hz)."""
    above = np.flatnonzero(~(t < 1.0))
    if above.size == 0:
        return float(f[0])
    last = above[-1]
    if last == f.size - 1:
        return None
    t0, t1 = np.log(t[last]), np.log(t[last + 1])
    return float(f[last] + (f[last + 1] - f[last]) * t0 / (t0 - t1)) if t0 != t1 else float(f[last + 1])


def _summary(res, model_name: str) -> None:
    from rich.table import Table

    con = console()
    kind = "moment" if res.input_unit == "N m" else "force"
    t = Table(title=f"forced response of {model_name} at T = {res.thrust:g} N ({res.linearization}), unit {res.input} {kind} at A")
    t.add_column("quantity")
    t.add_column("value")
    f, tr = res.frequency_hz, res.transmissibility
    unit = "N/(N m)" if kind == "moment" else "N/N"
    t.add_row("frequencies", f"{f.size} from {f[0]:g} to {f[-1]:g} Hz")
    j = int(np.nanargmax(tr))
    t.add_row("peak transmissibility", f"{tr[j]:.5g} {unit} ({20 * np.log10(tr[j]):.2f} dB) at {f[j]:.5g} Hz")
    onset = _isolation_onset(f, tr) if kind == "force" else None
    if kind == "force":
        t.add_row("isolation (transmissibility < 1) from", "not reached in the range" if onset is None else f"{onset:.5g} Hz")
    t.add_row(f"transmissibility at {f[-1]:g} Hz", f"{tr[-1]:.5g} {unit} ({20 * np.log10(tr[-1]):.2f} dB)")
    modes = ", ".join(f"{fm:.4g} ({d})" for fm, d in zip(res.mode_frequency_hz, res.mode_dominant))
    t.add_row("modes at this thrust (Hz, dominant dof)", modes)
    if np.any(res.power_transmitted):
        k = int(np.argmax(res.power_transmitted.sum(axis=-1)))
        t.add_row("largest power into the hull", f"{res.power_transmitted[k].sum():.4g} W at {f[k]:.5g} Hz")
    t.add_row("foundation", str(res.settings.get("foundation", "")))
    t.add_row("fluid", str(res.settings.get("fluid", "")))
    con.print(t)
    for w in res.warnings:
        con.print(f"[yellow]warning:[/yellow] {w}")


def _excitation_tables(ex) -> None:
    from rich.table import Table

    con = console()
    t = Table(title=f"excitation lines at T = {ex.thrust:g} N (shaft rate {ex.shaft_rate:.5g} rad/s)")
    for col in ("source", "f (Hz)", "|F_hull| (N)", "level (dB re 1 N rms)", "power into hull (W)"):
        t.add_column(col, justify="left" if col == "source" else "right")
    mag = ex.hull_force_magnitude
    for i, src in enumerate(ex.source):
        level = 20 * np.log10(mag[i] / np.sqrt(2)) if mag[i] > 0 else -np.inf
        t.add_row(src, f"{ex.frequency_hz[i]:.5g}", f"{mag[i]:.5g}", f"{level:.2f}", f"{ex.power_transmitted[i].sum():.4g}")
    con.print(t)
    b = ex.bands()
    if b.index.size:
        bt = Table(title="hull force in one-third-octave bands (IEC 61260, base ten)")
        for col in ("nominal (Hz)", "band (Hz)", "lines", "level (dB re 1 N)"):
            bt.add_column(col, justify="right")
        for i in range(b.index.size):
            lvl = b.level_db[i]
            bt.add_row(f"{b.nominal_hz[i]:g}", f"{b.lower_hz[i]:.4g} - {b.upper_hz[i]:.4g}", str(b.lines[i]),
                       f"{lvl:.2f}" if np.isfinite(lvl) else "-")
        con.print(bt)
    for w in ex.warnings:
        con.print(f"[yellow]warning:[/yellow] {w}")


def _write(out: Path, res, ex, plot: bool) -> list[Path]:
    from ..io import atomic_path

    written = []
    if out.suffix.lower() == ".nc":
        with atomic_path(out) as tmp:
            res.to_xarray().to_netcdf(tmp, engine="h5netcdf")
            if ex is not None:
                ex.to_xarray().to_netcdf(tmp, mode="a", group="excitation", engine="h5netcdf")
        written.append(out)
    if plot:
        import matplotlib

        if matplotlib.get_backend().lower() != "agg":
            matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt

        png = out.with_suffix(".png")
        if ex is None:
            fig, axes = plt.subplots(figsize=(9.0, 4.6), layout="constrained")
            res.plot(ax=axes)
        else:
            fig, axes = plt.subplots(2, 1, figsize=(9.0, 8.4), layout="constrained")
            res.plot(ax=axes[0])
            ex.plot(ax=axes[1])
        with atomic_path(png) as tmp:
            fig.savefig(tmp, format="png", dpi=120)
        plt.close(fig)
        written.append(png)
    return written


@click.command("response")
@click.argument("model_file", type=click.Path(dir_okay=False))
@click.option("--frequencies", "spec", required=True, help="START:STOP:NUM in Hz (numpy.linspace, NUM <= 100000)")
@click.option("--thrust", type=float, default=None, help="thrust T (N); default the operating thrust, else 0")
@click.option("--input", "dof", default=None, help="dof of the unit force/moment at A (default excitation.input, else sway)")
@click.option("--linearization", type=LINEARIZATION, default=None, help="override the model's setting")
@click.option("--excitation", is_flag=True, help="also the response to the model's [excitation] loads, with band levels")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object and nothing else")
@click.option("-o", "--output", type=click.Path(dir_okay=False), default=None,
              help="OUT.nc (netCDF; a PNG is written beside it) or OUT.png")
@click.option("--no-plot", is_flag=True, help="with -o OUT.nc: do not write the PNG")
def response_cmd(model_file: str, spec: str, thrust: float | None, dof: str | None, linearization: str | None,
                 excitation: bool, as_json: bool, output: str | None, no_plot: bool) -> None:
    """Forced response and force transmissibility |F_hull| / |F_in| to the hull."""
    from ..model import load_model
    from ..model.model import DOF_NAMES
    from ..response import excitation_response, frequency_response

    freqs = _frequencies(spec)
    check_number("--thrust", thrust, nonneg=True)
    if dof is not None and dof not in DOF_NAMES:
        raise ModelError("--input", dof, f"must be one of {list(DOF_NAMES)}")
    out = Path(output) if output else None
    if out is not None and out.suffix.lower() not in (".nc", ".png"):
        raise ModelError("--output", output, "must end in .nc (netCDF; a PNG is written beside it) or .png")
    model = load_model(model_file)
    res = frequency_response(model, freqs, thrust=thrust, input=dof, linearization=linearization)
    ex = excitation_response(model, thrust=thrust, linearization=linearization) if excitation else None
    written = _write(out, res, ex, plot=not (no_plot and out.suffix.lower() == ".nc")) if out is not None else []
    if as_json:
        obj = res.to_dict()
        if ex is not None:
            obj["excitation"] = ex.to_dict()
        print_json(obj)
        return
    _summary(res, model.name)
    if ex is not None:
        _excitation_tables(ex)
    if written:
        console().print("wrote " + " and ".join(map(str, written)))


commands = [response_cmd]
