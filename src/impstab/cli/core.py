"""Core commands: check, modes, locus, critical."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from ..errors import ModelError
from ._common import check_number, console, print_json

__all__ = ["commands"]

LINEARIZATION = click.Choice(["equilibrium", "classical"])


def _load(path: str):
    from ..model import load_model

    return load_model(path)


def _fmt(x: float | None, unit: str = "", digits: int = 6) -> str:
    if x is None:
        return "-"
    return f"{x:.{digits}g}{(' ' + unit) if unit else ''}"


@click.command("check")
@click.argument("model_file", type=click.Path(dir_okay=False))
def check_cmd(model_file: str) -> None:
    """Validate MODEL_FILE and print a summary of the assembled model."""
    from rich.table import Table

    from ..linear.modes import modes
    from ..model.model import DOF_NAMES

    model = _load(model_file)
    con = console()
    b = model.body
    con.print(f"[bold]{model.name}[/bold]  ({model_file}): valid, schema_version 1")
    t = Table(title="assembled model", show_header=True)
    t.add_column("item")
    t.add_column("value")
    t.add_row("mass", _fmt(b.mass, "kg"))
    t.add_row("cg from A", str(np.round(b.cg, 6).tolist()) + " m")
    t.add_row("principal inertia about cg", str(np.round(np.linalg.eigvalsh(b.inertia_cg), 6).tolist()) + " kg m^2")
    t.add_row("mounts", str(len(model.mounts)))
    kc = model.elastic_stiffness
    t.add_row("K_c diagonal", ", ".join(f"{n} {v:.4g}" for n, v in zip(DOF_NAMES, np.diag(kc))))
    th = model.thrust
    t.add_row("thrust", f"point {th.point.tolist()} m, direction {np.round(th.direction, 6).tolist()}, tangency {th.tangency:g}")
    t.add_row("operating thrust", _fmt(th.operating, "N"))
    t.add_row("preload stiffness", str(th.preload_stiffness))
    p = model.propeller
    t.add_row("propeller", f"J_p {p.polar_inertia:g} kg m^2, speed {p.speed:g} rad/s ({p.speed_law})")
    fl = model.fluid
    t.add_row("fluid", fl.model if fl.model == "none" else f"{fl.model}, added mass diag {np.round(np.diag(fl.added_mass), 6).tolist()}")
    if fl.model in ("baffled-cylinder", "strip") and model.hull is not None:
        from .. import fluid as _fluid

        h = model.hull
        ref = _fluid.strip_theory(radius=h.radius, length=h.length, density=fl.density)
        ma, ia = fl.added_mass[1, 1], None
        coeffs = (
            _fluid.baffled_cylinder(radius=h.radius, length=h.length, density=fl.density)
            if fl.model == "baffled-cylinder" else ref
        )
        ma, ia = coeffs.added_mass, coeffs.added_inertia
        t.add_row("added mass m_a", f"{ma:.6g} kg ({ma / ref.added_mass:.4f} x strip theory)")
        t.add_row("added inertia I_a", f"{ia:.6g} kg m^2 ({ia / ref.added_inertia:.4f} x strip theory)")
    t.add_row("analysis", f"thrust_max {model.analysis.thrust_max:g} N, linearization {model.analysis.linearization}")
    con.print(t)
    md = modes(model, 0.0)
    con.print("natural frequencies at zero thrust (Hz): " + ", ".join(f"{f:.4g}" for f in md.frequency_hz))


@click.command("modes")
@click.argument("model_file", type=click.Path(dir_okay=False))
@click.option("--thrust", type=float, default=0.0, show_default=True, help="thrust T (N)")
@click.option("--linearization", type=LINEARIZATION, default=None, help="override the model's setting")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object")
def modes_cmd(model_file: str, thrust: float, linearization: str | None, as_json: bool) -> None:
    """Natural frequencies, damping, growth rates and mode shapes at a thrust."""
    from rich.table import Table

    from ..linear.modes import modes
    from ..model.model import DOF_NAMES

    check_number("--thrust", thrust, nonneg=True)
    model = _load(model_file)
    res = modes(model, thrust, linearization)
    if as_json:
        print_json(res.to_dict())
        return
    t = Table(title=f"modes of {model.name} at T = {thrust:g} N ({res.linearization})")
    for col in ("mode", "f (Hz)", "omega (rad/s)", "zeta", "growth (1/s)", "dominant"):
        t.add_column(col)
    for name in DOF_NAMES:
        t.add_column(f"|{name}|", justify="right")
    for j, dom in enumerate(res.dominant()):
        t.add_row(
            str(j + 1), f"{res.frequency_hz[j]:.6g}", f"{res.omega[j]:.6g}", f"{res.damping_ratio[j]:.4g}",
            f"{res.growth_rate[j]:.4g}", ", ".join(dom), *(f"{abs(v):.3f}" for v in res.shapes[:, j]),
        )
    con = console()
    con.print(t)
    con.print("shapes: displacement of A (m) and rotation (rad), largest component 1; "
              + ("stable" if res.stable else "[red]UNSTABLE[/red]"))


@click.command("locus")
@click.argument("model_file", type=click.Path(dir_okay=False))
@click.option("--thrust-max", type=float, default=None, help="upper thrust (N); default analysis.thrust_max")
@click.option("--steps", type=int, default=200, show_default=True, help="thrust intervals")
@click.option("--linearization", type=LINEARIZATION, default=None)
@click.option("-o", "--output", type=click.Path(dir_okay=False), default=None, help="netCDF file (.nc); a PNG is written beside it")
def locus_cmd(model_file: str, thrust_max: float | None, steps: int, linearization: str | None, output: str | None) -> None:
    """Eigenvalue loci against thrust: netCDF data and a PNG like the paper's Figure 4."""
    from ..io import check_output, write_netcdf
    from ..linear.critical_thrust import critical_thrust
    from ..linear.locus import locus

    check_number("--thrust-max", thrust_max, positive=True)
    if steps < 1 or steps > 100000:
        raise ModelError("--steps", steps, "must be between 1 and 100000")
    if output is not None and Path(output).suffix.lower() not in (".nc", ".png"):
        raise ModelError("--output", output, "must end in .nc (netCDF; a PNG is written beside it) or .png")
    model = _load(model_file)
    out = Path(output) if output else Path(Path(model_file).stem + "-locus.nc")
    check_output(out, option="--output")
    res = locus(model, steps=steps, thrust_max=thrust_max, linearization=linearization)
    crit = critical_thrust(model, thrust_max=res.thrust[-1], linearization=linearization)
    from dataclasses import replace

    res = replace(res, critical_thrust=crit.thrust)
    png = out.with_suffix(".png")
    if out.suffix.lower() == ".nc":
        write_netcdf(res.to_xarray(), out, option="--output")
    _save_png(res, png)
    con = console()
    con.print(f"critical thrust: {_fmt(crit.thrust, 'N')} ({crit.kind})")
    if out.suffix.lower() == ".nc":
        con.print(f"wrote {out} and {png}")
    else:
        con.print(f"wrote {png}")


def _save_png(res, png: Path) -> None:
    import matplotlib

    matplotlib.use("Agg", force=False) if matplotlib.get_backend().lower() != "agg" else None
    import matplotlib.pyplot as plt

    from ..io import save_figure

    axes = res.plot()
    fig = axes[0].figure
    try:
        save_figure(fig, png, option="--output", dpi=120)
    finally:
        plt.close(fig)


@click.command("critical")
@click.argument("model_file", type=click.Path(dir_okay=False))
@click.option("--json", "as_json", is_flag=True, help="print one JSON object and nothing else")
@click.option("--thrust-max", type=float, default=None, help="override analysis.thrust_max (N)")
@click.option("--linearization", type=LINEARIZATION, default=None)
@click.option("--all-crossings", is_flag=True, help="also list later losses and gains of stability")
def critical_cmd(model_file: str, as_json: bool, thrust_max: float | None, linearization: str | None, all_crossings: bool) -> None:
    """Critical thrust, kind, frequency and margin."""
    from rich.table import Table

    from ..linear.critical_thrust import critical_thrust

    check_number("--thrust-max", thrust_max, positive=True)
    model = _load(model_file)
    res = critical_thrust(model, thrust_max=thrust_max, linearization=linearization, all_crossings=all_crossings)
    if as_json:
        print_json(res.to_dict())
        return
    t = Table(title=f"critical thrust of {model.name}")
    t.add_column("quantity")
    t.add_column("value")
    if res.thrust is None:
        t.add_row("critical thrust", f"none up to {res.thrust_max:g} N (stable over the whole range)")
    else:
        t.add_row("critical thrust", _fmt(res.thrust, "N", 10))
        t.add_row("kind", res.kind)
        t.add_row("frequency", f"{res.frequency_hz:.6g} Hz ({res.omega:.6g} rad/s)")
        t.add_row("modes involved", ", ".join(res.modes))
    t.add_row("operating thrust", _fmt(res.operating_thrust, "N"))
    t.add_row("margin (critical / operating)", _fmt(res.margin, "", 4))
    t.add_row("undamped critical thrust", _fmt(res.undamped_thrust, "N", 10) + (f" ({res.undamped_kind})" if res.undamped_thrust else ""))
    t.add_row("linearization", res.linearization)
    t.add_row("search range", f"0 to {res.thrust_max:g} N")
    for c in res.crossings:
        t.add_row(f"crossing ({c.direction})", f"{c.load:.10g} N, {c.kind}, {c.omega / (2 * np.pi):.6g} Hz")
    if res.fluid_frequency_hz is not None:
        t.add_row("fluid coefficients at", f"{res.fluid_frequency_hz:.6g} Hz ({res.fluid_iterations} iterations, last change {res.fluid_change if res.fluid_change is not None else float('nan'):.2e})")
    con = console()
    con.print(t)
    for w in res.warnings:
        con.print(f"[yellow]warning:[/yellow] {w}")


commands = [check_cmd, modes_cmd, locus_cmd, critical_cmd]
