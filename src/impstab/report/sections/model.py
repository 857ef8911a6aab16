"""Sections on the model itself: its summary, the static mount loads, the modes and decoupling."""

from __future__ import annotations

import numpy as np

from ...display.format import number
from ..result import NOT_COMPUTED, Note, Section, Table
from ..tables import table
from .titles import TITLES
from .context import ModelContext

__all__ = ["summary_section", "static_section", "modes_section", "mount_rows"]


def _vec(v, digits: int = 4) -> str:
    from ...display.text import _vec as vec

    return vec(v, digits)


def mount_rows(model) -> tuple[list[list[str]], list[str]]:
    """One row per mount (position, axis, stiffness, damping, ratings) and notes on the mounts
    given as a full 6 x 6 stiffness (their axial and mean shear translational stiffness shown)."""
    from ...model.mounts import axial_shear_matrix

    rows, notes = [], []
    for i, m in enumerate(model.mounts):
        k, c, a = np.asarray(m.stiffness), np.asarray(m.damping), np.asarray(m.axis)
        ka = float(a @ k[:3, :3] @ a)
        ks = 0.5 * (float(np.trace(k[:3, :3])) - ka)
        scale = max(float(np.abs(k).max()), 1e-300)
        springs = (not m.has_rotational_stiffness
                   and np.abs(k[:3, :3] - axial_shear_matrix(a, ka, ks)).max() <= 1e-12 * scale)
        ca = float(a @ c[:3, :3] @ a)
        cs = 0.5 * (float(np.trace(c[:3, :3])) - ca)
        mark = "" if springs else " *"
        if not springs:
            d = np.diag(k)
            notes.append(f"* mount {i} is a full 6 x 6 stiffness: its axial and mean shear translational stiffness "
                         f"are shown; diagonal {_vec(d[:3])} N/m, {_vec(d[3:])} N m/rad")
        rows.append([str(i), _vec(m.position), _vec(a, 3), number(ka, 5) + mark, number(ks, 5) + mark,
                     number(ca, 4), number(cs, 4), number(m.rated_force, 5, missing="not rated"),
                     number(None if m.max_deflection is None else 1e3 * m.max_deflection, 4, missing="not rated")])
    return rows, notes


def summary_section(ctx: ModelContext) -> Section:
    from ...display.html import model_html

    m = ctx.model
    blocks: list = [Table(model_html(m))]
    rows, notes = mount_rows(m)
    blocks.append(table(f"mounts ({len(m.mounts)}), numbered as in impstab check", rows,
                        ["mount", "position (m)", "axis", "k_axial (N/m)", "k_shear (N/m)", "c_axial (N s/m)",
                         "c_shear (N s/m)", "rated force (N)", "max deflection (mm)"],
                        ["right"] * 9))
    blocks += [Note(n) for n in notes]
    rows = [("preload stiffness", "included" if m.thrust.preload_stiffness else "left out")]
    p = m.propeller
    if p.polar_inertia or p.speed:
        rows.append(("propeller speed", f"{number(p.speed, 5)} rad/s = {number(p.speed * 60 / (2 * np.pi), 5)} rpm "
                                        f"at the operating thrust ({p.speed_law})"))
    if m.hull is not None:
        h = m.hull
        rows.append(("hull (wetted cylinder)", f"radius {number(h.radius)} m, length {number(h.length)} m, "
                                               f"centre {_vec(h.center)} m"))
    fl = m.fluid
    if fl.model != "none":
        rows.append(("fluid", f"{fl.model}, density {number(fl.density, missing='n/a')} kg/m^3, "
                              + ("incompressible" if fl.sound_speed is None else f"sound speed {number(fl.sound_speed)} m/s")))
    ex = m.excitation
    if ex.has_loads:
        n_lines = len(ex.unbalance) + len(ex.blade_rate) + (0 if ex.spectrum is None else ex.spectrum.frequency_hz.size)
        rows.append(("excitation", f"{len(ex.unbalance)} unbalance, {len(ex.blade_rate)} blade-rate, "
                                   f"{0 if ex.spectrum is None else ex.spectrum.frequency_hz.size} spectrum lines "
                                   f"({n_lines} sources)"))
    else:
        rows.append(("excitation", "none ([excitation] has no loads)"))
    rows.append(("foundation", "rigid hull" if m.foundation.model == "rigid" else f"{m.foundation.model} point impedance"))
    blocks.append(table("further settings", rows))
    return Section("summary", TITLES["summary"], blocks=tuple(blocks), data={"model": m})


def static_section(ctx: ModelContext) -> Section:
    from ...response.static import static_mount_loads

    title = TITLES["static"]
    if not ctx.operating:
        return Section("static", title, NOT_COMPUTED, "the model gives no operating thrust (thrust.operating)")
    st = static_mount_loads(ctx.model)
    util = st.utilisation

    def part(value: float, whole: float, scale: float, digits: int) -> str:
        # a component at rounding level of the whole (a shear of 1e-16 mm on an axial mount) is 0
        return number(0.0 if abs(value) <= 1e-9 * abs(whole) else scale * value, digits)

    rows = []
    for i in range(len(ctx.model.mounts)):
        dm, fm = st.deflection_magnitude[i], st.force_magnitude[i]
        u = "no rating" if not np.isfinite(util[i]) else f"{100 * util[i]:.0f}" + (" (over)" if util[i] > 1 else "")
        rows.append([str(i), part(st.axial_deflection[i], dm, 1e3, 4), part(st.shear_deflection[i], dm, 1e3, 4),
                     number(1e3 * dm, 4), part(st.axial_force[i], fm, 1.0, 5), part(st.shear_force[i], fm, 1.0, 5),
                     number(fm, 5), u])
    header = ["mount", "axial d (mm)", "shear d (mm)", "|d| (mm)", "axial F (N)", "shear F (N)", "|F| (N)", "use (%)"]
    blocks: list = [table(f"static mount deflection and load at the operating thrust {number(st.thrust)} N "
                          f"({st.linearization} linearization)", rows, header, ["right"] * 8)]
    total = st.force.sum(axis=0)
    blocks.append(Note(f"d: body-end deflection of the attachment from the unloaded pose; F: force of the mount on "
                       f"the hull (they sum to {_vec(total, 5)} N, the thrust vector); use: the larger of "
                       "|F| / rated_force and |d| / max_deflection (no rating: neither key given); gravity and "
                       "buoyancy are left out, the loads come from the thrust."))
    blocks += [Note(w, "warning") for w in st.warnings]
    return Section("static", title, blocks=tuple(blocks), data={"static": st})


def modes_section(ctx: ModelContext) -> Section:
    from ...display.html import modal_columns, modal_title
    from ...response.decoupling import decoupling_check

    md = ctx.modal
    check = decoupling_check(ctx.model, ctx.thrust, modal=md)
    where = "the operating thrust" if ctx.operating else "zero thrust (no operating thrust given)"
    header, rows, align = modal_columns(md)
    shares = [0, 1] + list(range(6, len(header)))        # mode, frequency, the share of each dof
    findings = []
    for line in check.lines():
        label, _, text = line.partition(": ")
        findings.append((label, text))
    blocks = [
        table(modal_title(md), [r[:6] for r in rows], header[:6], align[:6]),
        Note("ζ = -growth / |λ| (negative: the mode grows); dominant dofs: the largest kinetic-energy share, with "
             "any within 1 point of it."),
        table("decoupling table: kinetic-energy share of each dof (%)",
              [[r[j] for j in shares] for r in rows], [header[j].replace(" (% KE)", "") for j in shares],
              [align[j] for j in shares]),
        Note("Shares in mass-centre coordinates (a rotation about the cg counts as rotation); each row sums to 100."),
        table(f"decoupling at {where}", findings),
    ]
    return Section("modes", f"{TITLES['modes']} at {where}", blocks=tuple(blocks),
                   data={"modal": md, "decoupling": check})
