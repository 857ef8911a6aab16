"""HTML tables (``_repr_html_``) of the main models and results, for Jupyter and reports.

Plain HTML with a small inline style (no scripts, nothing fetched); every user string escaped.
"""

from __future__ import annotations

import html
import math

import numpy as np

from .format import growth, number, signed_zero_free

__all__ = ["model_html", "critical_html", "modal_html", "locus_html", "simulation_html", "study_html",
           "batch_html", "html_table", "modal_columns", "modal_title"]

_STYLE = ("border-collapse:collapse;font-size:0.9em;margin:0.3em 0;"
          "font-variant-numeric:tabular-nums")
_CELL = "padding:0.15em 0.7em;border-bottom:1px solid #ddd;text-align:{align};vertical-align:top"


def _esc(x) -> str:
    return html.escape(str(x), quote=True)


def html_table(title: str, rows, header=None, align=None) -> str:
    """A titled table; ``rows`` are sequences of cell texts (escaped here)."""
    ncol = max((len(r) for r in rows), default=len(header or ()))
    align = align or (["left"] + ["right"] * (ncol - 1) if header else ["left", "left"])
    out = [f'<table class="impstab" style="{_STYLE}">', f'<caption style="text-align:left;font-weight:bold">'
           f"{_esc(title)}</caption>"]
    if header:
        out.append("<thead><tr>" + "".join(
            f'<th style="{_CELL.format(align=align[j] if j < len(align) else "left")}">{_esc(h)}</th>'
            for j, h in enumerate(header)) + "</tr></thead>")
    out.append("<tbody>")
    for r in rows:
        out.append("<tr>" + "".join(
            f'<td style="{_CELL.format(align=align[j] if j < len(align) else "left")}">{_esc(c)}</td>'
            for j, c in enumerate(r)) + "</tr>")
    out.append("</tbody></table>")
    return "".join(out)


def _vec(v, unit: str) -> str:
    from .text import _vec as vec

    return f"{vec(v, 5)} {unit}".rstrip()


def model_html(m) -> str:
    from ..model.model import DOF_NAMES

    b = m.body
    kc = np.diag(m.elastic_stiffness)
    rows = [
        ("mass", f"{number(b.mass)} kg"),
        ("cg from A", _vec(b.cg, "m")),
        ("principal inertia about cg", _vec(np.linalg.eigvalsh(b.inertia_cg), "kg m^2")),
        ("mounts", str(len(m.mounts))),
        ("K_c diagonal", ", ".join(f"{n} {number(v, 4)}" for n, v in zip(DOF_NAMES[:3], kc[:3])) + " N/m; "
         + ", ".join(f"{n} {number(v, 4)}" for n, v in zip(DOF_NAMES[3:], kc[3:])) + " N m/rad"),
        ("thrust", f"point {_vec(m.thrust.point, 'm')}, direction {_vec(m.thrust.direction, '')}, "
                   f"tangency {number(m.thrust.tangency)}"),
        ("operating thrust", number(m.thrust.operating, 6, "N", missing="not given")),
        ("propeller", "none" if not (m.propeller.polar_inertia and m.propeller.speed) else
         f"J_p {number(m.propeller.polar_inertia)} kg m^2, {number(m.propeller.speed)} rad/s ({m.propeller.speed_law})"),
        ("damping", "mount dampers" if m.is_damped else "none"),
        ("fluid", m.fluid.model if m.fluid.model == "none" else
         f"{m.fluid.model}, added mass diagonal {_vec(np.diag(m.fluid.added_mass), '(kg, kg m^2)')}"),
        ("analysis", f"thrust_max {number(m.analysis.thrust_max)} N, {m.analysis.linearization} linearization"),
    ]
    return html_table(f"Model {m.name}", rows)


def critical_html(c) -> str:
    from .text import critical_rows

    return html_table(f"critical thrust of {c.model_name}" if c.model_name else "critical thrust", critical_rows(c))


def modal_columns(r) -> tuple[list[str], list[list[str]], list[str]]:
    """Header, rows and alignment of the modes table: mode, frequency, damping, growth, dominant
    dofs, then the kinetic-energy share of each dof (the decoupling table, % per mode)."""
    from ..model.model import DOF_NAMES

    scale = float(np.abs(r.eigenvalues).max(initial=0.0))
    header = ["mode", "f (Hz)", "ω (rad/s)", "ζ", "growth (1/s)", "dominant dofs",
              *(f"{n} (% KE)" for n in DOF_NAMES)]
    rows = []
    for j, dom in enumerate(r.dominant()):
        zeta = "0" if abs(r.growth_rate[j]) < 1e-10 * max(scale, 1e-300) else number(r.damping_ratio[j], 4)
        rows.append([str(j + 1), number(r.frequency_hz[j]), number(r.omega[j]), zeta,
                     growth(r.growth_rate[j], scale), ", ".join(dom),
                     *(signed_zero_free(f"{100 * v:.1f}") for v in r.participation[j])])
    align = ["right"] * 5 + ["left"] + ["right"] * 6
    return header, rows, align


def modal_title(r) -> str:
    return f"modes at T = {number(r.thrust)} N ({r.linearization} linearization): " + ("stable" if r.stable else "UNSTABLE")


def modal_html(r) -> str:
    header, rows, align = modal_columns(r)
    return html_table(modal_title(r), rows, header, align)


def locus_html(r) -> str:
    rows = [("thrusts", f"{r.thrust.size}, {number(r.thrust.min())} to {number(r.thrust.max())} N"),
            ("linearization", r.linearization)]
    if r.critical_thrust is not None:
        rows.append(("onset", f"{r.critical_kind} at {number(r.critical_thrust)} N, "
                              f"{number(r.critical_frequency_hz, 4)} Hz"))
    if r.undamped_critical_thrust is not None:
        rows.append(("undamped onset", f"{number(r.undamped_critical_thrust)} N"))
    if r.fluid_frequency_hz:
        rows.append(("fluid coefficients at", f"{number(r.fluid_frequency_hz, 4)} Hz"))
    labels = r.branch_labels()
    lam = r.eigenvalues
    for b, name in enumerate(labels):
        cols = np.flatnonzero(r.modes == b)
        f0 = float(np.nanmax(np.abs(lam[0, cols].imag))) / (2 * np.pi)
        g = float(np.nanmax(lam[:, cols].real))
        rows.append((f"branch {b + 1}", f"{name}: {number(f0, 4)} Hz at {number(r.thrust[0])} N; "
                                        f"largest growth {growth(g, float(np.nanmax(np.abs(lam))))} 1/s"))
    return html_table(f"eigenvalue loci of {r.model_name}", rows)


def simulation_html(r) -> str:
    g = r.growth
    rows = [("thrust", f"{number(r.thrust[0])} N ({r.thrust_history})" if r.thrust.size else "no samples"),
            ("classification", r.classification),
            ("integrator", f"{r.integrator}, step {number(r.dt, 4)} s, {r.steps} steps"),
            ("samples", f"{r.time.size} over {number(r.duration, 4)} s"),
            ("outcome", "completed" if r.completed else f"stopped: {r.stop_reason}")]
    if g is not None:
        rows.append(("envelope", g.envelope + ("" if not math.isfinite(g.rate) else f", fitted {number(g.rate, 4)} 1/s")))
        if g.linear_rate is not None:
            rows.append(("max Re λ (linear)", f"{growth(g.linear_rate, r.fastest_omega)} 1/s"))
    peak = np.abs(r.displacement).max(axis=0) if r.time.size else np.zeros(6)
    rows.append(("largest motion", f"sway {number(peak[1], 3)} m, pitch {number(peak[4], 3)} rad, "
                                   f"yaw {number(peak[5], 3)} rad"))
    return html_table(f"time simulation of {r.model_name}", rows)


def study_html(s) -> str:
    from ..model.reference import label, unit

    ds = s.dataset
    rows = [("study", ds.attrs.get("study_name", "")), ("sampling", ds.attrs.get("sampling", "")),
            ("designs", f"{int(ds['status'].size)}: " + ", ".join(f"{k} {v}" for k, v in s.counts().items() if v))]
    for p in s.parameters:
        v = np.asarray(ds[p].values)
        u = unit(p)
        u = "" if u in (None, "1") else f" {u}"
        span = f"{number(v.min())} to {number(v.max())}{u}" if v.dtype.kind in "fiu" else ", ".join(map(str, v[:6]))
        rows.append((f"parameter {p}", f"{label(p)}: {v.size} values, {span}"))
    if "kind" in ds:
        names = s.kind_names().values.ravel()
        rows.append(("kinds", ", ".join(f"{k or 'failed'} {int(np.count_nonzero(names == k))}"
                                        for k in ("flutter", "divergence", "none", "") if np.count_nonzero(names == k))))
    if "critical_thrust" in ds:
        t = ds["critical_thrust"].values
        if np.isfinite(t).any():
            rows.append(("critical thrust", f"{number(np.nanmin(t))} to {number(np.nanmax(t))} N "
                                            "(designs unstable within the search)"))
    if s.store:
        rows.append(("store", s.store))
    return html_table(f"design study {ds.attrs.get('study_name', '')}", rows)


def batch_html(b) -> str:
    from ..linear.batch.results import KINDS, STATUSES

    kinds = np.asarray(b.kind)
    status = np.asarray(b.status)
    rows = [("designs", str(kinds.size))]
    rows += [(f"kind {name}", str(int(np.count_nonzero(kinds == code)))) for code, name in enumerate(KINDS)]
    rows += [(f"status {name}", str(int(np.count_nonzero(status == code)))) for code, name in enumerate(STATUSES)
             if np.count_nonzero(status == code)]
    t = np.asarray(b.thrust, dtype=float)
    if np.isfinite(t).any():
        rows.append(("critical thrust", f"{number(np.nanmin(t))} to {number(np.nanmax(t))} N"))
    m = np.asarray(b.margin, dtype=float)
    if np.isfinite(m).any():
        rows.append(("margin", f"{number(np.nanmin(m), 4)} to {number(np.nanmax(m), 4)}"))
    rows.append(("eigenproblems", str(b.evaluations)))
    return html_table("batch of critical thrusts", rows)
