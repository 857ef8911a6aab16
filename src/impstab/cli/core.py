"""Core commands: check, modes, locus, critical."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from ..errors import ModelError
from ..limits import MAX_LOCUS_STEPS
from ._common import (at_thrust, check_number, console, data_and_figure, draw_and_save, figure_options, fmt, print_json,
                      table, user_text)

__all__ = ["commands"]

LINEARIZATION = click.Choice(["equilibrium", "classical"])


def _load(path: str):
    from ..model import load_model

    return load_model(path)


def _fmt(x: float | None, unit: str = "", digits: int = 6, missing: str = "n/a") -> str:
    return fmt(x, unit, digits, missing)


def _margin_rows(res, damped: bool | None = None) -> list[tuple[str, str]]:
    """The rows of the ``critical`` table, the margin saying so when it is below 1 (``check``
    shows the same rows for its critical thrust and margin)."""
    from ..display.text import critical_rows

    rows = critical_rows(res, damped)
    op = res.operating_thrust
    if res.margin is not None and res.margin < 1.0:
        note = f"{{}} [red](UNSTABLE at the operating thrust)[/red]"
    elif res.margin is None and op and res.thrust_max < op:
        note = (f"> {res.thrust_max / op:.4g}, [yellow]not established[/yellow]: the search ends at "
                f"{res.thrust_max:g} N, below the operating thrust {op:g} N")
    else:
        return rows
    return [(k, note.format(v) if k.startswith("margin") else v) for k, v in rows]


def _vec(v, unit: str) -> str:
    return "[" + ", ".join(fmt(float(x), digits=6) for x in np.asarray(v, dtype=float)) + f"] {unit}"


@click.command("check")
@click.argument("model_file", type=click.Path(dir_okay=False))
def check_cmd(model_file: str) -> None:
    """Validate MODEL_FILE and print a summary of the assembled model."""
    from ..linear.critical_thrust import critical_thrust
    from ..linear.modes import modes
    from ..model.model import DOF_NAMES

    model = _load(model_file)
    con = console()
    b = model.body
    con.print(f"[bold]{user_text(model.name)}[/bold]  ({user_text(model_file)}): valid, schema_version 1")
    t = table("assembled model", "item", "value")
    t.add_row("mass", _fmt(b.mass, "kg"))
    t.add_row("cg from A", _vec(b.cg, "m"))
    t.add_row("principal inertia about cg", _vec(np.linalg.eigvalsh(b.inertia_cg), "kg m^2"))
    t.add_row("mounts", str(len(model.mounts)))
    for i, m in enumerate(model.mounts):
        if m.viscoelastic is not None:
            t.add_row(f"mount {i} law", m.viscoelastic.describe())
    kc = np.diag(model.elastic_stiffness)
    t.add_row("K_c diagonal", ", ".join(f"{n} {_fmt(v, digits=4)}" for n, v in zip(DOF_NAMES[:3], kc[:3])) + " N/m; "
              + ", ".join(f"{n} {_fmt(v, digits=4)}" for n, v in zip(DOF_NAMES[3:], kc[3:])) + " N m/rad")
    th = model.thrust
    t.add_row("thrust", f"point {_vec(th.point, 'm')}, direction {_vec(th.direction, '')}".rstrip()
              + f", tangency {_fmt(th.tangency)}")
    t.add_row("operating thrust", _fmt(th.operating, "N", missing="not given (thrust.operating): no margins"))
    t.add_row("preload stiffness", "included" if th.preload_stiffness else "left out")
    p = model.propeller
    if p.polar_inertia or p.speed:
        rpm = p.speed * 60.0 / (2.0 * np.pi)
        t.add_row("propeller", f"J_p {_fmt(p.polar_inertia)} kg m^2, speed {_fmt(p.speed)} rad/s "
                  f"({_fmt(rpm, digits=5)} rpm), {p.speed_law}")
    else:
        t.add_row("propeller", "no spinning propeller")
    fl = model.fluid
    t.add_row("fluid", "none" if fl.model == "none" else
              f"{fl.model}, added mass diagonal {_vec(np.diag(fl.added_mass), '(kg, kg m^2)')}")
    if fl.model in ("baffled-cylinder", "strip") and model.hull is not None:
        from .. import fluid as _fluid

        h = model.hull
        ref = _fluid.strip_theory(radius=h.radius, length=h.length, density=fl.density)
        coeffs = (
            _fluid.baffled_cylinder(radius=h.radius, length=h.length, density=fl.density)
            if fl.model == "baffled-cylinder" else ref
        )
        ma, ia = coeffs.added_mass, coeffs.added_inertia
        t.add_row("added mass m_a", f"{_fmt(ma)} kg ({ma / ref.added_mass:.4f} x strip theory)")
        t.add_row("added inertia I_a", f"{_fmt(ia)} kg m^2 ({ia / ref.added_inertia:.4f} x strip theory)")
    t.add_row("analysis", f"thrust_max {_fmt(model.analysis.thrust_max, 'N')}, "
              f"linearization {model.analysis.linearization}")
    crit = critical_thrust(model)
    rows = dict(_margin_rows(crit, model.is_damped or model.fluid.compressible))
    t.add_row("critical thrust", rows["critical thrust"] + (f" ({crit.kind})" if crit.thrust is not None else ""))
    t.add_row("margin (critical / operating)", rows["margin (critical / operating)"])
    con.print(t)
    md = modes(model, 0.0)
    if md.internal_share is not None:  # beam mounts with mass: the body modes, the internal ones counted
        body = [f for f, kind in zip(md.frequency_hz, md.kind) if kind == "body"]
        con.print("natural frequencies at zero thrust (Hz): " + ", ".join(_fmt(f, digits=4) for f in body)
                  + f"; and {len(md.kind) - len(body)} internal mount modes from "
                  f"{_fmt(min((f for f, k in zip(md.frequency_hz, md.kind) if k == 'mount'), default=np.nan), digits=4)}"
                  " Hz (`impstab modes`)")
    else:
        con.print("natural frequencies at zero thrust (Hz): " + ", ".join(_fmt(f, digits=4) for f in md.frequency_hz))
    for w in crit.warnings:
        con.print(f"[yellow]warning:[/yellow] {user_text(w)}")
    _static_loads_table(model, con)


def _static_loads_table(model, con) -> None:
    """Static deflection and load of each mount at the operating thrust, with utilisations."""
    from ..errors import NumericalError
    from ..response.static import static_mount_loads

    if not model.thrust.operating:
        con.print("static mount loads: no operating thrust (thrust.operating), so none are reported")
        return
    try:
        st = static_mount_loads(model)
    except NumericalError as exc:
        con.print(f"[yellow]warning:[/yellow] static mount loads at the operating thrust: {user_text(exc)}")
        return
    t = table(f"static mount deflection and load at the operating thrust {st.thrust:g} N ({st.linearization})",
              ("mount", "right"), ("axial d (mm)", "right"), ("shear d (mm)", "right"), ("|d| (mm)", "right"),
              ("axial F (N)", "right"), ("shear F (N)", "right"), ("|F| (N)", "right"), ("use (%)", "right"))
    util = st.utilisation

    def part(value: float, whole: float, scale: float, digits: int) -> str:
        # a component at rounding level of the whole (a shear of 1e-16 mm on an axial mount) is 0
        return _fmt(0.0 if abs(value) <= 1e-9 * abs(whole) else scale * value, digits=digits)

    for i in range(len(model.mounts)):
        u = "no rating" if not np.isfinite(util[i]) else (
            f"[red]{100 * util[i]:.0f}[/red]" if util[i] > 1 else f"{100 * util[i]:.0f}")
        dm, fm = st.deflection_magnitude[i], st.force_magnitude[i]
        t.add_row(
            str(i), part(st.axial_deflection[i], dm, 1e3, 4), part(st.shear_deflection[i], dm, 1e3, 4),
            _fmt(1e3 * dm, digits=4), part(st.axial_force[i], fm, 1.0, 5), part(st.shear_force[i], fm, 1.0, 5),
            _fmt(fm, digits=5), u,
        )
    con.print(t)
    con.print("mounts numbered as in `impstab check` above; d: body-end deflection of the attachment from the "
              "unloaded pose; F: force of the mount on the hull; use: the larger of |F| / rated_force and "
              "|d| / max_deflection (no rating: neither key given)")
    for w in st.warnings:
        con.print(f"[yellow]warning:[/yellow] {user_text(w)}")


@click.command("modes")
@click.argument("model_file", type=click.Path(dir_okay=False))
@click.option("--thrust", type=float, default=0.0, show_default=True, help="thrust T (N)")
@click.option("--linearization", type=LINEARIZATION, default=None, help="override the model's setting")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object")
@click.option("--shapes", is_flag=True, help="also print the mode shapes at A")
def modes_cmd(model_file: str, thrust: float, linearization: str | None, as_json: bool, shapes: bool) -> None:
    """Natural frequencies, damping, growth rates, the decoupling table and mode shapes at a thrust."""
    from ..display.format import growth
    from ..model.model import DOF_NAMES
    from ..response.decoupling import decoupling_check

    from ..linear.critical_thrust import critical_thrust

    thrust = check_number("--thrust", thrust, kind="thrust_or_zero")
    model = _load(model_file)
    from ..linear.modes import modes

    res = at_thrust("--thrust", thrust, model, lambda: modes(model, thrust, linearization))
    check = decoupling_check(model, thrust, linearization, modal=res)
    crit = critical_thrust(model, thrust_max=max(thrust, model.analysis.thrust_max), linearization=linearization)
    if as_json:
        print_json({**res.to_dict(), "decoupling": check.to_dict(), "stable": res.stable,
                    "critical_thrust": crit.thrust, "critical_kind": crit.kind,
                    "warnings": _modes_warnings(res, crit, thrust)})
        return
    scale = float(np.abs(res.eigenvalues).max(initial=0.0))
    grown = res.internal_share is not None  # massive beam mounts: body and internal mount modes
    extra_cols = (("kind", "left"), ("internal KE (%)", "right")) if grown else ()
    t = table(f"modes of {user_text(model.name)} at T = {thrust:g} N ({res.linearization} linearization)",
              ("mode", "right"), ("f (Hz)", "right"), ("omega (rad/s)", "right"), ("zeta (1)", "right"),
              ("growth (1/s)", "right"), "dominant dof", *extra_cols)
    for j, dom in enumerate(res.dominant()):
        more = (res.kind[j], f"{100 * res.internal_share[j]:.1f}") if grown else ()  # type: ignore[index]
        t.add_row(str(j + 1), _fmt(res.frequency_hz[j]), _fmt(res.omega[j]),
                  "0" if abs(res.growth_rate[j]) < 1e-10 * max(scale, 1e-300) else _fmt(res.damping_ratio[j], digits=4),
                  growth(res.growth_rate[j], scale), "/".join(dom), *more)
    con = console()
    con.print(t)
    if grown:
        con.print(f"beam mounts with mass: {', '.join(map(str, res.mount_elements))} finite elements per beam, "
                  f"{res.internal_dofs} internal (Craig-Bampton) dofs; kind 'mount': most of the mode's kinetic "
                  "energy in the mounts' internal dofs (internal KE), else 'body'; the dof shares below are "
                  "the body's part of the energy")
    e = table("decoupling table: kinetic-energy shares of each mode by dof (%)", ("mode", "right"),
              *((n, "right") for n in DOF_NAMES))
    for j in range(len(res.eigenvalues)):
        e.add_row(str(j + 1), *(f"{round(100 * v, 1) + 0.0:.1f}" for v in res.participation[j]))
    con.print(e)
    con.print("shares: each dof's part of the mode's kinetic energy in mass-centre coordinates (rows sum to 100); "
              "dominant: the largest share (with any within 1 point of it); zeta = -growth / |lambda| "
              "(negative: the mode grows); the complex shapes are in --json and --shapes")
    first = (f"stability is first lost at {crit.thrust:.8g} N ({crit.kind})" if crit.thrust is not None
             else f"stable from 0 to {crit.thrust_max:g} N")
    con.print(("stable" if res.stable else "[red]UNSTABLE[/red]") + f" at {thrust:g} N; {first}")
    for w in _modes_warnings(res, crit, thrust):
        con.print(f"[yellow]warning:[/yellow] {user_text(w)}")
    if shapes:
        st = table("mode shapes at A: displacement (m) and rotation (rad), largest component 1", ("mode", "right"),
                   *((f"|{n}|", "right") for n in DOF_NAMES))
        for j in range(res.shapes.shape[1]):
            st.add_row(str(j + 1), *(f"{abs(v):.3f}" for v in res.shapes[:, j]))
        con.print(st)
    con.print("decoupling")
    for line in check.lines():
        con.print("  " + line)


@click.command("locus")
@click.argument("model_file", type=click.Path(dir_okay=False))
@click.option("--thrust-max", type=float, default=None, help="upper thrust (N); default analysis.thrust_max")
@click.option("--steps", type=int, default=200, show_default=True, help="thrust intervals")
@click.option("--linearization", type=LINEARIZATION, default=None)
@click.option("-o", "--output", type=click.Path(dir_okay=False), default=None,
              help="netCDF file (.nc; a PNG is written beside it) or a figure only (.png, .svg, .pdf)")
@figure_options
def locus_cmd(model_file: str, thrust_max: float | None, steps: int, linearization: str | None, output: str | None,
              figure: str | None, dpi: float | None, no_plot: bool) -> None:
    """Eigenvalue loci against thrust: netCDF data and a figure like the paper's Figure 4."""
    from ..io import check_output, write_netcdf
    from ..linear.locus import locus

    thrust_max = check_number("--thrust-max", thrust_max, kind="thrust")
    if steps < 1 or steps > MAX_LOCUS_STEPS:
        raise ModelError("--steps", steps, f"must be between 1 and {MAX_LOCUS_STEPS}")
    out = Path(output) if output else Path(Path(model_file).stem + "-locus.nc")
    data, fig_path = data_and_figure(out, (".nc",), figure, no_plot, dpi)
    model = _load(model_file)
    for path in (data, fig_path):
        if path is not None:
            check_output(path, option="--output")
    try:
        res = locus(model, steps=steps, thrust_max=thrust_max, linearization=linearization, critical=True)
    except ModelError as exc:
        if exc.field != "thrust_max":
            raise
        raise ModelError("--thrust-max" if thrust_max is not None else "analysis.thrust_max", exc.value, exc.rule) from None
    if data is not None:
        write_netcdf(res.to_xarray(), data, option="--output")
    if fig_path is not None:
        draw_and_save(res.plot, fig_path, dpi)
    con = console()
    if res.critical_thrust is None:
        con.print(f"critical thrust: none up to {res.thrust[-1]:g} N (stable over the whole range)")
    else:
        con.print(f"critical thrust: {_fmt(res.critical_thrust, 'N')} ({res.critical_kind})")
    con.print("wrote " + " and ".join(user_text(p) for p in (data, fig_path) if p is not None))


@click.command("critical")
@click.argument("model_file", type=click.Path(dir_okay=False))
@click.option("--json", "as_json", is_flag=True, help="print one JSON object and nothing else")
@click.option("--thrust-max", type=float, default=None, help="override analysis.thrust_max (N)")
@click.option("--linearization", type=LINEARIZATION, default=None)
@click.option("--all-crossings", is_flag=True, help="also list later losses and gains of stability")
@click.option("--min-damping-ratio", type=float, default=None,
              help="practical criterion: override analysis.min_damping_ratio (1)")
@click.option("--min-log-decrement", type=float, default=None,
              help="practical criterion: override analysis.min_log_decrement (1; API 617/684: 0.1)")
def critical_cmd(model_file: str, as_json: bool, thrust_max: float | None, linearization: str | None, all_crossings: bool,
                 min_damping_ratio: float | None, min_log_decrement: float | None) -> None:
    """Critical thrust, kind, frequency and margin."""
    from ..linear.critical_thrust import critical_thrust
    from ..model.criteria import damping_threshold

    thrust_max = check_number("--thrust-max", thrust_max, kind="thrust")
    zeta = damping_threshold(min_damping_ratio, min_log_decrement, names=("--min-damping-ratio", "--min-log-decrement"))
    model = _load(model_file)
    res = critical_thrust(model, thrust_max=thrust_max, linearization=linearization, all_crossings=all_crossings,
                          min_damping_ratio=zeta)
    if as_json:
        print_json(res.to_dict())
        return
    t = table(f"critical thrust of {user_text(model.name)}", "quantity", "value")
    for name, value in _margin_rows(res, model.is_damped or model.fluid.compressible):
        t.add_row(name, value)
    for c in res.crossings:
        t.add_row(f"crossing ({c.direction})", f"{c.load:.10g} N, {c.kind}, {fmt(c.omega / (2 * np.pi))} Hz")
    for row in _viscoelastic_rows(res):
        t.add_row(*row)
    if res.fluid_frequency_hz is not None:
        change = "" if res.fluid_change is None else f", last change {res.fluid_change:.2e}"
        t.add_row("fluid coefficients at", f"{_fmt(res.fluid_frequency_hz)} Hz ({res.fluid_iterations} iterations{change})")
    con = console()
    con.print(t)
    for w in res.warnings:
        con.print(f"[yellow]warning:[/yellow] {user_text(w)}")


def _viscoelastic_rows(res) -> list[tuple[str, str]]:
    """Rows on viscoelastic mounts: the Prony realisation and the check of the onset on the exact law."""
    if not res.viscoelastic_fits:
        return []
    fits = res.viscoelastic_fits
    worst = max(f["fit_error"] for f in fits)
    terms = sum(f["terms"] for f in fits)
    rows = [("viscoelastic mounts", f"{len(fits)} mounts, {terms} Prony terms ({3 * terms} internal states), "
             f"largest fit error {worst:.2e}; undamped = static stiffness")]
    check = res.exact_onset
    if check is None and res.thrust is not None and worst == 0.0:
        rows.append(("exact-law check", "none needed: every law is its own Prony series"))
    if check is not None:
        rows.append(("exact-law check", "Newton did not converge" if check.exact_thrust is None else
                     f"Prony onset {check.thrust:.10g} N, exact {check.exact_thrust:.10g} N "
                     f"(relative difference {check.thrust_difference:.2e})"))
    return rows


def _modes_warnings(res, crit, thrust: float) -> list[str]:
    """What ``modes`` must say when its eigenvalues and the critical-thrust search disagree."""
    out = []
    if not res.stable and (crit.thrust is None or thrust < crit.thrust * (1 - 1e-6)):
        out.append(f"an eigenvalue grows at {thrust:g} N although the critical-thrust search finds the model "
                   + (f"stable below {crit.thrust:.8g} N" if crit.thrust is not None else f"stable up to {crit.thrust_max:g} N"))
    return out


commands = [check_cmd, modes_cmd, locus_cmd, critical_cmd]
