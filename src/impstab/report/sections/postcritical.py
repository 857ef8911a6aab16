"""The post-critical section, drawn from a post-critical result (see :mod:`impstab.report.analyses`).

What it reads is the interface of ``impstab postcritical --json`` (DESIGN.md): ``to_dict()``
with ``critical_thrust``, ``kind``, ``omega``, ``lyapunov_coefficient``, ``bifurcation``,
``fold_thrust`` and ``branch`` (``thrust``, ``period``, ``stable``, ``amplitude`` by dof), and
``plot(ax=None)`` for the bifurcation diagram.
"""

from __future__ import annotations

import math

import numpy as np

from ...display.format import number
from ..analyses import find_provider
from ..result import NOT_COMPUTED, Figure, Note, Section
from ..svg import draw_svg
from ..tables import table
from .titles import TITLES
from .context import ModelContext

__all__ = ["postcritical_section", "postcritical_blocks", "READING"]

#: the engineer's reading of each kind of onset
READING = {
    "supercritical": "benign: a small stable limit cycle grows gently with thrust past the onset (it can be monitored)",
    "subcritical": ("dangerous: a large oscillation exists below the linear critical thrust, down to the fold of "
                    "cycles, with hysteresis; the fold thrust is the practical limit"),
    "degenerate": "the plain Hopf theory does not apply at this onset (see the reason)",
}

TITLE = TITLES["postcritical"]


def postcritical_blocks(result) -> list:
    """Tables, notes and the bifurcation diagram of a post-critical result."""
    d = result.to_dict()
    bif = d.get("bifurcation")
    omega = d.get("omega")
    rows = [("critical thrust", number(d.get("critical_thrust"), 10, "N", missing="none up to thrust_max")),
            ("kind", str(d.get("kind"))),
            ("onset frequency", "n/a" if not omega else f"{number(omega / (2 * math.pi))} Hz ({number(omega)} rad/s)"),
            ("first Lyapunov coefficient l1", number(d.get("lyapunov_coefficient"), 6,
                                                     missing="not defined at this onset")),
            ("bifurcation", str(bif) if bif else "none"),
            ("fold of cycles", number(d.get("fold_thrust"), 8, "N", missing="none on the computed branch"))]
    if d.get("reason"):
        rows.append(("reason", str(d["reason"])))
    blocks: list = [table("Hopf analysis at the onset and the branch of limit cycles", rows)]
    if bif in READING:
        blocks.append(Note(f"Reading: {READING[bif]}."))
    branch = d.get("branch") or {}
    thrust = np.asarray(branch.get("thrust", []), dtype=float)
    if thrust.size:
        amp = branch.get("amplitude", {})
        stable = np.asarray(branch.get("stable", []), dtype=bool)
        period = np.asarray(branch.get("period", []), dtype=float)
        picks = sorted(set(np.linspace(0, thrust.size - 1, min(thrust.size, 8)).round().astype(int)))
        names = list(amp)
        rows = [[number(thrust[i]), number(period[i], 5) if i < period.size else "n/a",
                 ("stable" if stable[i] else "unstable") if i < stable.size else "n/a",
                 *(number(amp[n][i], 4) for n in names)] for i in picks]
        blocks.append(table(f"limit cycles on the branch ({thrust.size} computed, {len(picks)} shown)", rows,
                            ["thrust (N)", "period (s)", "stability", *(f"{n} ({'m' if k < 3 else 'rad'})"
                                                                        for k, n in enumerate(names))]))
    if hasattr(result, "plot"):
        blocks.insert(1, Figure(draw_svg(result.plot, "postcritical"),
                                "Bifurcation diagram: cycle amplitude against thrust, stable cycles solid, unstable "
                                "dashed; the Hopf point and any fold marked."))
    blocks += [Note(str(w), "warning") for w in d.get("warnings", []) or []]
    return blocks


def postcritical_section(ctx: ModelContext) -> Section:
    result = ctx.options.postcritical
    if result is None:
        provider, reason = find_provider("postcritical")
        if provider is None:
            return Section("postcritical", TITLE, NOT_COMPUTED, reason)
        result = provider(ctx.model)
    return Section("postcritical", TITLE, blocks=tuple(postcritical_blocks(result)), data={"postcritical": result})
