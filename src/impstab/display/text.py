"""One-line text views (``repr``) of models and results: what they are, in numbers with units."""

from __future__ import annotations

import math

import numpy as np

from .format import growth, number

__all__ = [
    "model_text", "body_text", "mount_text", "thrust_text", "fluid_loading_text", "hull_text",
    "linear_system_text", "modal_text", "critical_text", "critical_load_text", "locus_text",
    "simulation_text", "study_text", "batch_text", "fluid_coefficients_text", "sweep_text",
    "study_definition_text", "parameter_text", "modal_form_text", "critical_rows",
]


def _vec(v, digits: int = 4) -> str:
    """Entries below 1e-12 of the largest are rounding residues and print as 0."""
    v = np.ravel(np.asarray(v, dtype=float))
    v = np.where(np.abs(v) < 1e-12 * np.abs(v).max(initial=0.0), 0.0, v)
    return "[" + ", ".join(number(float(x), digits) for x in v) + "]"


def _n(x, unit: str = "N", digits: int = 6, missing: str = "n/a") -> str:
    return number(x, digits, unit, missing=missing)


def model_text(m) -> str:
    parts = [f"{number(m.body.mass, 6)} kg", f"{len(m.mounts)} mounts"]
    if m.thrust.operating is not None:
        parts.append(f"operating {_n(m.thrust.operating)}")
    parts.append(f"thrust_max {_n(m.analysis.thrust_max)}")
    if m.fluid.model != "none":
        parts.append(f"fluid {m.fluid.model}")
    if m.propeller.polar_inertia and m.propeller.speed:
        parts.append(f"propeller {number(m.propeller.speed, 4)} rad/s")
    if m.is_damped:
        parts.append("damped")
    parts.append(m.analysis.linearization)
    return f"Model({m.name!r}: {', '.join(parts)})"


def body_text(b) -> str:
    return (f"RigidBody(mass {number(b.mass)} kg, cg {_vec(b.cg)} m, principal inertia "
            f"{_vec(np.linalg.eigvalsh(b.inertia_cg))} kg m^2)")


def mount_text(mt) -> str:
    k = np.diag(mt.stiffness)
    text = f"Mount(at {_vec(mt.position)} m, stiffness diagonal {_vec(k[:3])} N/m"
    if np.any(k[3:]):
        text += f", {_vec(k[3:])} N m/rad"
    if np.any(mt.damping):
        text += f", damping diagonal {_vec(np.diag(mt.damping)[:3])} N s/m"
    law = getattr(mt, "nonlinear", None)
    if law is not None and not law.is_linear:
        if law.k3_axial or law.k3_shear:
            text += f", k3 axial {number(law.k3_axial)}, shear {number(law.k3_shear)} N/m^3"
        if law.has_snubber:
            text += f", snubber {number(law.snubber_clearance)} m, {number(law.snubber_stiffness)} N/m"
    visco = getattr(mt, "viscoelastic", None)
    if visco is not None:
        text += f", viscoelastic {visco.describe()}"
    return text + ")"


def thrust_text(t) -> str:
    op = f", operating {_n(t.operating)}" if t.operating is not None else ""
    return (f"Thrust(point {_vec(t.point)} m, direction {_vec(t.direction)}, tangency {number(t.tangency)}{op}"
            f"{'' if t.preload_stiffness else ', no preload stiffness'})")


def fluid_loading_text(f) -> str:
    if f.model == "none":
        return "FluidLoading('none')"
    c = "incompressible" if f.sound_speed is None else f"c {number(f.sound_speed)} m/s"
    rho = "" if f.density is None else f", rho {number(f.density)} kg/m^3"
    return f"FluidLoading({f.model!r}{rho}, {c}, added mass diagonal {_vec(np.diag(f.added_mass))} kg, kg m^2)"


def hull_text(h) -> str:
    return f"Hull(radius {number(h.radius)} m, length {number(h.length)} m, centre {_vec(h.center)} m)"


def linear_system_text(s) -> str:
    what = []
    if np.any(s.D):
        what.append("damped")
    if np.any(s.G):
        what.append("gyroscopic")
    extra = f", {', '.join(what)}" if what else ""
    defl = float(np.linalg.norm(s.displacement)) if s.displacement is not None else math.nan
    return (f"LinearSystem(T = {_n(s.thrust)}, {s.linearization}, {s.M.shape[0]} dofs{extra}, "
            f"static deflection |u| = {number(defl, 4)} m)")


def modal_text(r) -> str:
    freqs = ", ".join(number(f, 4) for f in r.frequency_hz)
    state = "stable" if r.stable else f"UNSTABLE (max growth {growth(float(r.growth_rate.max()))} 1/s)"
    return f"ModalResult(T = {_n(r.thrust)}, {r.linearization}, {len(r.eigenvalues)} modes at {freqs} Hz, {state})"


def critical_text(c) -> str:
    name = f"{c.model_name!r}: " if c.model_name else ""
    if c.thrust is None:
        core = f"stable up to {_n(c.thrust_max)}"
    else:
        core = f"{c.kind} at {_n(c.thrust)}"
        if c.omega:
            core += f", {number(c.frequency_hz, 4)} Hz"
        if c.modes:
            core += f", {'+'.join(c.modes)}"
    if c.margin is not None:
        core += f"; margin {number(c.margin, 4)}"
    if c.undamped_thrust is not None and c.thrust is not None and abs(c.undamped_thrust - c.thrust) > 1e-9 * c.thrust:
        core += f"; undamped {_n(c.undamped_thrust)}"
    return f"CriticalThrust({name}{core}; {c.linearization})"


def critical_load_text(c) -> str:
    if c.load is None:
        return f"CriticalLoad(stable up to p_max = {number(c.p_max)}, {c.method}, {c.evaluations} eigenproblems)"
    freq = f", omega {number(c.omega, 6)} rad/s" if c.omega else ""
    return f"CriticalLoad({c.kind} at p = {number(c.load, 10)}{freq}, {c.method}, {c.evaluations} eigenproblems)"


def locus_text(r) -> str:
    t = r.thrust
    branches = int(r.modes.max()) + 1 if r.eigenvalues.size else 0
    onset = f", onset {_n(r.critical_thrust)} ({r.critical_kind})" if r.critical_thrust is not None else ""
    name = f"{r.model_name!r}: " if r.model_name else ""
    return (f"LocusResult({name}{t.size} thrusts {number(t.min())} to {_n(t.max())}, {branches} branches"
            f"{onset}, {r.linearization})")


def simulation_text(r) -> str:
    g = r.growth
    rate = "no growth fit" if g is None or not math.isfinite(g.rate) else f"{g.envelope} {number(g.rate, 4)} 1/s"
    state = "completed" if r.completed else f"stopped at {number(r.stop_time, 4)} s"
    thrust = f"T = {_n(r.thrust[0])}" if r.thrust.size else "no samples"
    return (f"SimulationResult({r.model_name!r}: {thrust}, {r.integrator}, {r.time.size} samples over "
            f"{number(r.duration, 4)} s, {state}, {rate}, {r.classification})")


def study_text(s) -> str:
    ds = s.dataset
    counts = s.counts()
    shape = " x ".join(str(ds.sizes[d]) for d in ds["status"].dims)
    done = ", ".join(f"{k} {v}" for k, v in counts.items() if v)
    where = f"; store {s.store}" if s.store else ""
    return (f"StudyResult({ds.attrs.get('study_name', '')!r}: {ds.attrs.get('sampling', '')} {shape} = "
            f"{int(ds['status'].size)} designs, {done}{where})")


def batch_text(b) -> str:
    from ..linear.batch.results import KINDS

    kinds = np.asarray(b.kind)
    counts = ", ".join(f"{name} {int(np.count_nonzero(kinds == code))}" for code, name in enumerate(KINDS)
                       if np.count_nonzero(kinds == code))
    failed = int(np.count_nonzero(np.asarray(b.status) != 0))
    t = np.asarray(b.thrust, dtype=float)
    rng = f"; critical thrust {number(np.nanmin(t))} to {_n(np.nanmax(t))}" if np.isfinite(t).any() else ""
    return f"BatchCriticalThrust({t.size} designs: {counts}, failed {failed}{rng})"


def fluid_coefficients_text(c) -> str:
    r = "" if c.radiation_resistance is None else f", R {number(c.radiation_resistance, 4)} N s/m"
    return (f"FluidCoefficients({c.model}, a = {number(c.radius)} m, L = {number(c.length)} m, f = "
            f"{number(c.frequency)} Hz: m_a {number(c.added_mass, 6)} kg, I_a {number(c.added_inertia, 6)} kg m^2{r})")


def sweep_text(s) -> str:
    f = s.frequency
    first = s.points[0]
    return (f"FrequencySweep({first.model}, a = {number(first.radius)} m, L = {number(first.length)} m, "
            f"{f.size} frequencies {number(f.min())} to {number(f.max())} Hz)")


def study_definition_text(s) -> str:
    names = ", ".join(p.name for p in s.parameters)
    return f"Study({s.name!r}: {s.method}, {s.size} designs over {names}; outputs {', '.join(s.outputs)})"


def parameter_text(p) -> str:
    from ..model.reference import unit

    v = np.asarray(p.values)
    u = unit(p.name)
    u = "" if u in (None, "1") else f" {u}"
    if v.dtype.kind in "fiu" and v.size:
        return f"Parameter({p.name}: {v.size} values, {number(v.min())} to {number(v.max())}{u})"
    return f"Parameter({p.name}: {v.size} values {sorted(set(map(str, v.tolist())))[:6]})"


def modal_form_text(f) -> str:
    freqs = ", ".join(number(w / (2 * np.pi), 4) for w in f.omega0)
    return f"ModalForm({f.n_modes} modes at {freqs} Hz{', truncated' if f.truncated else ''})"


def _num(x, unit: str = "", digits: int = 6, missing: str = "n/a") -> str:
    return number(x, digits, unit, missing=missing)


def practical_rows(res) -> list[tuple[str, str]]:
    """The rows of the practical criterion (none without a damping threshold)."""
    p = getattr(res, "practical", None)
    if p is None:
        return []
    rows = [("practical criterion", f"damping ratio >= {_num(p.damping_ratio, '', 4)} "
                                    f"(log decr. {_num(p.log_decrement, '', 4)})")]
    if p.load is None:
        value = f"none up to {res.thrust_max:g} N (every mode keeps the threshold)"
    elif p.at_start:
        value = "0 N (the least-damped mode is below the threshold already at T = 0)"
    else:
        value = f"{_num(p.load, 'N', 10)} ({p.kind}, {_num(p.frequency_hz)} Hz)"
    rows.append(("practical critical thrust", value))
    rows.append(("practical margin", _margin_text(res.practical_margin, res, "threshold kept up to thrust_max")))
    return rows


def _margin_text(margin: float | None, res, beyond: str) -> str:
    """A margin's cell: its value, or why there is none (no operating thrust; no onset up to
    ``thrust_max``, then a lower bound with ``beyond`` saying what held that far)."""
    if margin is not None:
        return _num(margin, "", 4)
    if res.operating_thrust is None:
        return "needs an operating thrust"
    return f"> {res.thrust_max / res.operating_thrust:.4g} ({beyond})"


def critical_rows(res, damped: bool | None = None) -> list[tuple[str, str]]:
    """The rows of the ``critical`` table: every value with its unit, every gap explained.

    ``damped``: whether the model has dampers (or radiation damping); None when unknown.
    """
    rows = []
    if res.thrust is None:
        rows.append(("critical thrust", f"none up to {res.thrust_max:g} N (stable over the whole range)"))
    else:
        rows.append(("critical thrust", _num(res.thrust, "N", 10)))
        rows.append(("kind", res.kind))
        rows.append(("frequency", f"{_num(res.frequency_hz)} Hz ({_num(res.omega)} rad/s)"))
        rows.append(("modes involved", ", ".join(res.modes)))
    rows.append(("operating thrust", _num(res.operating_thrust, "N", missing="not given (thrust.operating)")))
    rows.append(("margin (critical / operating)", _margin_text(res.margin, res, "stable up to thrust_max")))
    same = res.undamped_thrust == res.thrust and res.undamped_kind == res.kind
    if damped is False or (damped is None and same):
        und = "same as the critical thrust (no dampers)" if damped is False else "same as the critical thrust"
    elif res.undamped_thrust is None:
        und = f"none up to {res.thrust_max:g} N (stable without damping)"
    else:
        und = f"{_num(res.undamped_thrust, 'N', 10)} ({res.undamped_kind})"
    rows.append(("undamped critical thrust", und))
    rows.extend(practical_rows(res))
    rows.append(("linearization", res.linearization))
    rows.append(("search range", f"0 to {res.thrust_max:g} N"))
    return rows
