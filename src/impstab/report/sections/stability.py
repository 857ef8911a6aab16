"""Sections on stability: the critical thrust and margin (damped beside undamped), the locus."""

from __future__ import annotations

from dataclasses import replace

from ...display.format import number
from ..result import Figure, Note, Section, Table
from ..svg import draw_svg, mathtext_safe
from ..tables import table
from .titles import TITLES
from .context import ModelContext

__all__ = ["stability_section", "locus_section", "damping_note"]


def damping_note(crit, damped: bool) -> str:
    """The damped onset against the undamped one, in words."""
    if not damped:
        return "The model has no dampers and no radiation damping: the undamped critical thrust is the critical thrust."
    t, u = crit.thrust, crit.undamped_thrust
    if t is None and u is None:
        return f"Stable up to thrust_max = {number(crit.thrust_max)} N with and without damping."
    if t is None:
        return (f"Damping stabilises: without damping the model loses stability at {number(u)} N ({crit.undamped_kind}), "
                f"with it none is found up to thrust_max = {number(crit.thrust_max)} N.")
    if u is None:
        return (f"Damping destabilises: with damping the onset is at {number(t)} N ({crit.kind}), while the undamped "
                f"model is stable up to thrust_max = {number(crit.thrust_max)} N.")
    change = (t - u) / u
    if abs(change) < 1e-9:
        return f"Damping leaves the onset at {number(t)} N."
    verb = "lowers" if change < 0 else "raises"
    what = ("destabilisation by damping, the paradox of follower-force systems" if change < 0
            else "damping stabilises")
    return (f"Damping {verb} the critical thrust from {number(u)} N (undamped, {crit.undamped_kind}) to {number(t)} N "
            f"({crit.kind}): {100 * change:+.1f} % ({what}).")


def stability_section(ctx: ModelContext) -> Section:
    from ...display.text import critical_rows

    crit = ctx.critical
    rows = critical_rows(crit, ctx.damped)
    for c in crit.crossings:
        rows.append((f"crossing ({c.direction})", f"{number(c.load, 10)} N, {c.kind}"))
    if crit.fluid_frequency_hz is not None:
        rows.append(("fluid coefficients at", f"{number(crit.fluid_frequency_hz)} Hz ({crit.fluid_iterations} iterations)"))
    title = f"critical thrust of {ctx.model.name}"
    blocks: list = [table(title, rows), Note(damping_note(crit, ctx.damped))]
    if crit.margin is not None and crit.margin < 1:
        blocks.append(Note(f"the margin {number(crit.margin, 4)} is below 1: the propulsor is unstable at its "
                           "operating thrust", "warning"))
    blocks += [Note(w, "warning") for w in crit.warnings]
    return Section("stability", TITLES["stability"], blocks=tuple(blocks), data={"critical": crit})


def locus_section(ctx: ModelContext) -> Section:
    from ...display.html import locus_html

    loc = ctx.locus
    drawn = replace(loc, model_name=mathtext_safe(loc.model_name))
    svg = draw_svg(drawn.plot, "locus")
    caption = ("Eigenvalue loci against thrust (the paper's Figure 4): frequency above growth rate, one colour per "
               f"branch, named by its dominant dofs; {loc.thrust.size} thrusts from {number(loc.thrust[0])} to "
               f"{number(loc.thrust[-1])} N. Dashed: the onset; dash-dotted: the undamped onset; dotted: the "
               "operating thrust.")
    return Section("locus", TITLES["locus"], blocks=(Figure(svg, caption), Table(locus_html(loc))),
                   data={"locus": loc})
