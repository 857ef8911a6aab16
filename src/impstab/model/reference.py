"""Units, descriptions and labels of every model-file key, beside the schema.

:mod:`impstab.model.schema` says which keys exist and what values they accept; this table says
what they mean. :mod:`impstab.model.schema_doc` joins both into ``docs/model-file.md`` and the
JSON Schema of ``impstab schema``; a test keeps this table in step with the schema (every key has
an entry, no entry names a key that does not exist, the committed page equals the generated one).

Paths: ``section.key``, ``[]`` for every table of an array of tables (``mounts[].k_axial``).
Units are SI; ``""`` marks a word, a flag, a count or a table, ``"1"`` a dimensionless number.
Vectors are in the body frame, from the reference point A, dof order ``surge, sway, heave, roll,
pitch, yaw``.
"""

from __future__ import annotations

from .schema_doc import RefEntry as E

__all__ = ["MODEL_REFERENCE", "TITLE", "INTRO", "DOC_PATH", "label", "unit", "markdown_page",
           "json_schema_document"]

DOC_PATH = "docs/model-file.md"
TITLE = "Model-file reference"

MODEL_REFERENCE: dict[str, E] = {
    "schema_version": E("", "Version of the file format; this impstab reads 1."),
    "name": E("", "Name of the model in tables, figures and results; default: the file name without .toml."),
    # [body]
    "body": E("", "The rigid propulsor body."),
    "body.mass": E("kg", "Mass of the rigid body (structure, motor, propeller); the fluid's added mass comes from [fluid].",
                   "body mass"),
    "body.cg": E("m", "Centre of gravity, body frame, from the reference point A.", "body cg"),
    "body.inertia": E("kg m^2", "Inertia about the cg: principal moments [Ixx, Iyy, Izz] or a full symmetric 3 x 3 "
                      "list; must be positive definite and satisfy the triangle inequalities "
                      "(each principal moment at most the sum of the other two).", "body inertia"),
    # [hull]
    "hull": E("", "The wetted cylinder, for fluid loading; required with fluid.model = \"baffled-cylinder\" or "
              "\"strip\"."),
    "hull.radius": E("m", "Radius a of the wetted cylinder.", "hull radius"),
    "hull.length": E("m", "Length L of the wetted segment.", "hull length"),
    "hull.center": E("m", "Centre of the wetted segment, body frame, from A.", "hull centre"),
    # [fluid]
    "fluid": E("", "Fluid loading; absent means none."),
    "fluid.model": E("", "\"none\"; \"baffled-cylinder\" (a segment in a rigid cylindrical baffle, with radiation damping "
                     "when a sound speed is given); \"strip\" (strip theory, rho pi a^2 L); \"matrix\" (a given 6 x 6 "
                     "added mass)."),
    "fluid.density": E("kg/m^3", "Fluid density rho; required with \"baffled-cylinder\" and \"strip\".",
                       "fluid density"),
    "fluid.sound_speed": E("m/s", "Speed of sound; absent means incompressible (no radiation damping).",
                           "sound speed"),
    "fluid.added_mass": E("kg, kg m, kg m^2 by block", "6 x 6 added-mass matrix about A, dof order surge ... yaw; "
                          "required with model = \"matrix\" and read only then; symmetric, positive semi-definite."),
    # [[mounts]]
    "mounts": E("", "One table per mount. Each mount needs either k_axial and k_shear or a full 6 x 6 stiffness; "
                "together with [[mount_rings]] the mounts must restrain all six rigid-body motions."),
    "mounts[].position": E("m", "Attachment point on the body, body frame, from A (the hull end is at the same point at "
                           "rest).", "mount position"),
    "mounts[].axis": E("", "Mount axis (any length, normalised); the axial spring acts along it.", "mount axis"),
    "mounts[].k_axial": E("N/m", "Axial stiffness along the mount axis; with k_shear, instead of stiffness.",
                          "mount axial stiffness k_axial"),
    "mounts[].k_shear": E("N/m", "Shear stiffness normal to the mount axis; with k_axial, instead of stiffness.",
                          "mount shear stiffness k_shear"),
    "mounts[].c_axial": E("N s/m", "Axial viscous damping; not with a 6 x 6 damping.", "mount axial damping c_axial"),
    "mounts[].c_shear": E("N s/m", "Shear viscous damping; not with a 6 x 6 damping.", "mount shear damping c_shear"),
    "mounts[].stiffness": E("N/m, N/rad, N m/m, N m/rad by block", "Full 6 x 6 stiffness of the body end (a beam or a measured mount), hull frame, "
                            "[force; moment] against [displacement; rotation]; symmetric, positive semi-definite; "
                            "instead of k_axial and k_shear."),
    "mounts[].damping": E("N s/m, N s/rad, N m s/m, N m s/rad by block", "Full 6 x 6 viscous damping of the body end, "
                          "same layout; symmetric, positive semi-definite; instead of c_axial and c_shear."),
    "mounts[].rated_force": E("N", "Static force rating of the mount: `impstab check` reports |F| / rated_force at "
                              "the operating thrust and warns above 1.", "mount rated force"),
    "mounts[].max_deflection": E("m", "Static deflection limit of the mount: `impstab check` reports |d| / "
                                 "max_deflection at the operating thrust and warns above 1.", "mount deflection limit"),
    "mounts[].k3_axial": E("N/m^3", "Cubic axial stiffness: axial force -(k_axial d_a + k3_axial d_a^3) on the axial "
                           "deflection d_a; negative softens. Axial-shear mounts only (not with stiffness); the linear "
                           "analyses see it through the static equilibrium.", "mount cubic axial stiffness k3_axial"),
    "mounts[].k3_shear": E("N/m^3", "Cubic shear stiffness: shear force -(k_shear + k3_shear |d_s|^2) d_s; negative "
                           "softens. Axial-shear mounts only.", "mount cubic shear stiffness k3_shear"),
    "mounts[].snubber_clearance": E("m", "Motion limiter: engages when the deflection |d| exceeds it, with the force "
                                    "-snubber_stiffness ramp(|d| - clearance) d/|d|, ramp smoothed (C2) over 5 % of the "
                                    "clearance; 0 means none, > 0 needs snubber_stiffness.", "snubber clearance"),
    "mounts[].snubber_stiffness": E("N/m", "Stiffness of the motion limiter beyond its clearance; required > 0 with "
                                    "snubber_clearance, and only with it.", "snubber stiffness"),
    # viscoelastic mounts (impstab.model.viscoelastic; docs/mounts.md)
    "mounts[].viscoelastic": E("", "Frequency-dependent law: k_axial and k_shear stay the static values and are scaled by "
                          "the complex ratio k*(omega)/k0 of the law; stability and modes use internal variables (one "
                          "3-vector per Prony term), the forced response the exact k*(omega). Axial-shear mounts only."),
    "mounts[].viscoelastic.law": E("", "\"standard-linear-solid\" (k0 (1 + i w s tau)/(1 + i w tau)); \"prony\" "
                              "(1 + sum g_j i w tau_j/(1 + i w tau_j)); \"fractional-zener\" "
                              "((1 + s (i w tau)^alpha)/(1 + (i w tau)^alpha)); \"table\" (s(f)(1 + i eta(f)))."),
    "mounts[].viscoelastic.stiffening": E("1", "k(inf)/k(0) = s > 1 (standard-linear-solid, fractional-zener).",
                                     "stiffening k(inf)/k(0)"),
    "mounts[].viscoelastic.relaxation_time": E("s", "Relaxation time tau (standard-linear-solid, fractional-zener).",
                                          "relaxation time"),
    "mounts[].viscoelastic.alpha": E("1", "Fractional order, strictly between 0 and 1 (fractional-zener).",
                                "fractional order alpha"),
    "mounts[].viscoelastic.terms": E("1, s", "Prony series [[g_1, tau_1], ...]: weights g_j > 0, relaxation times "
                                "tau_j (s) (prony).", "Prony terms"),
    "mounts[].viscoelastic.frequency_hz": E("Hz", "Frequencies of a measured table (ISO 10846), > 0 and strictly "
                                       "increasing (table).", "table frequency"),
    "mounts[].viscoelastic.storage_ratio": E("1", "Storage stiffness over the static stiffness, k'(f)/k0, one per "
                                        "frequency (table).", "storage ratio"),
    "mounts[].viscoelastic.loss_factor": E("1", "Loss factor eta(f) = k''/k', one per frequency (table); a value "
                                      "that does not vanish at the lowest frequency is hysteretic (non-causal).",
                                      "loss factor"),
    "mounts[].viscoelastic.fit_band_hz": E("Hz", "Band [low, high] of the Prony fit of a fractional-zener or table "
                                      "law; default: two decades either side of 1/(2 pi tau), or the table's band.",
                                      "fit band"),
    "mounts[].viscoelastic.fit_terms": E("", "Number of log-spaced relaxation times of the Prony fit (1 ... 30); "
                                    "default 1.5 per decade of the band plus 1, at most 12.", "fit terms"),
    # [mounts.beam] (impstab.model.beam, docs/mounts.md)
    "mounts[].beam": E("", "A Timoshenko beam along the mount axis, instead of k_axial/k_shear or stiffness: hull end "
                       "clamped at position - length * axis, body end at position. Massless, it is exactly the 6 x 6 "
                       "stiffness K_tip (inverse of its clamped-free tip flexibility); with density > 0 its finite "
                       "elements add internal dofs to the stability analysis and their first modes to the time histories "
                       "(docs/mounts.md)."),
    "mounts[].beam.length": E("m", "Free length L of the beam, from the clamped hull end to the body end.",
                              "beam length"),
    "mounts[].beam.outer_diameter": E("m", "Outer diameter of the circular section.", "beam outer diameter"),
    "mounts[].beam.inner_diameter": E("m", "Inner diameter of a hollow section (0: solid); below outer_diameter.",
                                      "beam inner diameter"),
    "mounts[].beam.youngs_modulus": E("Pa", "Young's modulus E (axial and bending stiffness).", "beam Young's modulus"),
    "mounts[].beam.shear_modulus": E("Pa", "Shear modulus G (torsion and shear deformation).", "beam shear modulus"),
    "mounts[].beam.shear_coefficient": E("1", "Timoshenko shear coefficient kappa; default Cowper's value for the "
                                         "(hollow) circular section with nu = E / (2 G) - 1.",
                                         "beam shear coefficient"),
    "mounts[].beam.density": E("kg/m^3", "Density of the beam material; 0 (default): massless; > 0: the mount has its "
                               "own mass (internal finite-element dofs).", "beam density"),
    # [[mount_rings]]
    "mount_rings": E("", "Rings of identical mounts, equally spaced around the axis (count mounts on a circle of "
                     "the given radius in the plane at x)."),
    "mount_rings[].count": E("", "Number of mounts on the ring.", "mounts per ring"),
    "mount_rings[].radius": E("m", "Radius of the circle through the attachment points.", "ring radius"),
    "mount_rings[].x": E("m", "Axial position of the ring plane, body frame, from A.", "ring axial position x"),
    "mount_rings[].start_angle": E("deg", "Angle of the first mount, from +y toward +z.", "ring start angle"),
    "mount_rings[].axis": E("", "Axis of every mount of the ring (normalised).", "ring mount axis"),
    "mount_rings[].k_axial": E("N/m", "Axial stiffness of each mount.", "mount axial stiffness k_axial"),
    "mount_rings[].k_shear": E("N/m", "Shear stiffness of each mount.", "mount shear stiffness k_shear"),
    "mount_rings[].c_axial": E("N s/m", "Axial viscous damping of each mount.", "mount axial damping c_axial"),
    "mount_rings[].c_shear": E("N s/m", "Shear viscous damping of each mount.", "mount shear damping c_shear"),
    "mount_rings[].rated_force": E("N", "Static force rating of each mount of the ring.", "mount rated force"),
    "mount_rings[].max_deflection": E("m", "Static deflection limit of each mount of the ring.",
                                      "mount deflection limit"),
    "mount_rings[].k3_axial": E("N/m^3", "Cubic axial stiffness of each mount (negative softens), as for [[mounts]].",
                                "mount cubic axial stiffness k3_axial"),
    "mount_rings[].k3_shear": E("N/m^3", "Cubic shear stiffness of each mount (negative softens), as for [[mounts]].",
                                "mount cubic shear stiffness k3_shear"),
    "mount_rings[].snubber_clearance": E("m", "Motion limiter clearance of each mount (0: none), as for [[mounts]].",
                                         "snubber clearance"),
    "mount_rings[].snubber_stiffness": E("N/m", "Motion limiter stiffness of each mount; required > 0 with a "
                                         "clearance.", "snubber stiffness"),
    # viscoelastic mounts (impstab.model.viscoelastic; docs/mounts.md)
    "mount_rings[].viscoelastic": E("", "Frequency-dependent law of each mount: k_axial and k_shear stay the static values and are scaled by "
                          "the complex ratio k*(omega)/k0 of the law; stability and modes use internal variables (one "
                          "3-vector per Prony term), the forced response the exact k*(omega). Axial-shear mounts only."),
    "mount_rings[].viscoelastic.law": E("", "\"standard-linear-solid\" (k0 (1 + i w s tau)/(1 + i w tau)); \"prony\" "
                              "(1 + sum g_j i w tau_j/(1 + i w tau_j)); \"fractional-zener\" "
                              "((1 + s (i w tau)^alpha)/(1 + (i w tau)^alpha)); \"table\" (s(f)(1 + i eta(f)))."),
    "mount_rings[].viscoelastic.stiffening": E("1", "k(inf)/k(0) = s > 1 (standard-linear-solid, fractional-zener).",
                                     "stiffening k(inf)/k(0)"),
    "mount_rings[].viscoelastic.relaxation_time": E("s", "Relaxation time tau (standard-linear-solid, fractional-zener).",
                                          "relaxation time"),
    "mount_rings[].viscoelastic.alpha": E("1", "Fractional order, strictly between 0 and 1 (fractional-zener).",
                                "fractional order alpha"),
    "mount_rings[].viscoelastic.terms": E("1, s", "Prony series [[g_1, tau_1], ...]: weights g_j > 0, relaxation times "
                                "tau_j (s) (prony).", "Prony terms"),
    "mount_rings[].viscoelastic.frequency_hz": E("Hz", "Frequencies of a measured table (ISO 10846), > 0 and strictly "
                                       "increasing (table).", "table frequency"),
    "mount_rings[].viscoelastic.storage_ratio": E("1", "Storage stiffness over the static stiffness, k'(f)/k0, one per "
                                        "frequency (table).", "storage ratio"),
    "mount_rings[].viscoelastic.loss_factor": E("1", "Loss factor eta(f) = k''/k', one per frequency (table); a value "
                                      "that does not vanish at the lowest frequency is hysteretic (non-causal).",
                                      "loss factor"),
    "mount_rings[].viscoelastic.fit_band_hz": E("Hz", "Band [low, high] of the Prony fit of a fractional-zener or table "
                                      "law; default: two decades either side of 1/(2 pi tau), or the table's band.",
                                      "fit band"),
    "mount_rings[].viscoelastic.fit_terms": E("", "Number of log-spaced relaxation times of the Prony fit (1 ... 30); "
                                    "default 1.5 per decade of the band plus 1, at most 12.", "fit terms"),
    # [thrust]
    "thrust": E("", "The thrust: a force of magnitude T (the load parameter) along the propulsor's own axis."),
    "thrust.point": E("m", "Point of application, body frame, from A.", "thrust point"),
    "thrust.direction": E("", "Direction of the thrust in the body frame (normalised).", "thrust direction"),
    "thrust.tangency": E("1", "Follower fraction: 1 a pure follower force (turns with the body), 0 a force of fixed "
                         "direction.", "tangency"),
    "thrust.operating": E("N", "Design thrust: margins (critical / operating) are reported against it.",
                          "operating thrust"),
    "thrust.preload_stiffness": E("", "Include the geometric stiffness of the mount preload under thrust.",
                                  "preload stiffness"),
    # [propeller]
    "propeller": E("", "The spinning propeller (gyroscopic moments); absent means none."),
    "propeller.polar_inertia": E("kg m^2", "Polar moment of inertia J_p of the propeller and shaft.",
                                 "propeller polar inertia"),
    "propeller.speed": E("rad/s", "Spin speed at the operating thrust (positive about the thrust direction); "
                         "give speed or speed_rpm, not both.", "propeller speed"),
    "propeller.speed_rpm": E("rpm", "The spin speed in revolutions per minute, instead of speed "
                             "(speed = speed_rpm * 2 pi / 60 rad/s).", "propeller speed"),
    "propeller.speed_law": E("", "\"constant\": the speed is fixed; \"sqrt-thrust\": speed * sqrt(T / operating) "
                             "(needs thrust.operating)."),
    # [analysis]
    "analysis": E("", "Settings of the stability analysis."),
    "analysis.thrust_max": E("N", "Upper end of the critical-thrust search; default 10 x thrust.operating "
                             "(required when no operating thrust is given).", "thrust_max"),
    "analysis.linearization": E("", "\"equilibrium\": the tangent at the nonlinear static equilibrium under thrust; "
                                "\"classical\": at the undeformed configuration (the paper's eq. 21)."),
    "analysis.min_damping_ratio": E("1", "Practical stability criterion: the practical critical thrust is the first "
                                    "thrust at which the least damping ratio -Re(lambda)/|lambda| of any mode falls to "
                                    "this value (give it or min_log_decrement, not both); see docs/practical-stability.md.",
                                    "minimum damping ratio"),
    "analysis.min_log_decrement": E("1", "The practical criterion as a logarithmic decrement -2 pi Re(lambda)/Im(lambda) "
                                    "(API 617 and API 684 ask for at least 0.1); converted to the damping ratio "
                                    "delta / sqrt(4 pi^2 + delta^2).", "minimum logarithmic decrement"),
    # [excitation]
    "excitation": E("", "Operating excitation for the forced response (`impstab response --excitation`); "
                    "see docs/isolation.md."),
    "excitation.input": E("", "Dof of the unit load of `impstab response` when --input is not given "
                          "(surge, sway, heave, roll, pitch or yaw).", "input dof"),
    "excitation.unbalance": E("", "Rotating unbalances at shaft rate; need propeller.speed (or speed_rpm) not 0."),
    "excitation.unbalance[].mass": E("kg", "Unbalance mass m.", "unbalance mass"),
    "excitation.unbalance[].eccentricity": E("m", "Radius e of the unbalance mass: a force m e Omega^2 rotating "
                                             "at shaft rate Omega (the propeller speed law) in the plane normal "
                                             "to the thrust axis.", "unbalance eccentricity"),
    "excitation.unbalance[].point": E("m", "Where the unbalance force acts, body frame, from A; default "
                                      "thrust.point.", "unbalance point"),
    "excitation.unbalance[].phase_deg": E("deg", "Angle of the unbalance at t = 0 in the plane normal to the "
                                          "thrust axis.", "unbalance phase"),
    "excitation.blade_rate": E("", "Blade-rate forces and moments (harmonic x blades x shaft rate); need "
                               "propeller.speed (or speed_rpm) not 0."),
    "excitation.blade_rate[].blades": E("", "Blade count Z (an integer).", "blade count"),
    "excitation.blade_rate[].harmonic": E("", "Harmonic of the blade rate (an integer): the frequency is "
                                          "harmonic * Z * |Omega| / 2 pi.", "blade-rate harmonic"),
    "excitation.blade_rate[].amplitude": E("N, N m by component", "Amplitudes of the force and moment at "
                                           "`point`, body axes, dof order surge ... yaw (magnitudes).",
                                           "blade-rate amplitude"),
    "excitation.blade_rate[].phase_deg": E("deg", "Phase of each of the six components.", "blade-rate phase"),
    "excitation.blade_rate[].point": E("m", "Where the blade-rate load acts, body frame, from A; default "
                                       "thrust.point.", "blade-rate point"),
    "excitation.spectrum": E("", "A table of harmonic lines (a measured or specified spectrum)."),
    "excitation.spectrum.frequency_hz": E("Hz", "Frequency of each line.", "spectrum frequency"),
    "excitation.spectrum.amplitude": E("N, N m by component", "One row of six amplitudes (force and moment at "
                                       "`point`, body axes) per frequency.", "spectrum amplitude"),
    "excitation.spectrum.phase_deg": E("deg", "Phases, same shape as amplitude; default 0.", "spectrum phase"),
    "excitation.spectrum.point": E("m", "Where the spectrum's loads act, body frame, from A.", "spectrum point"),
    # [foundation]
    "foundation": E("", "The hull at every mount attachment for the forced response: rigid (default) or an "
                    "isotropic point impedance per attachment, uncoupled between attachments."),
    "foundation.model": E("", "\"rigid\"; \"lumped\" (Z = damping + i (omega mass - stiffness / omega)); "
                          "\"mobility-table\" or \"impedance-table\" (tables against frequency_hz, linear "
                          "interpolation)."),
    "foundation.mass": E("kg", "Lumped hull mass at each attachment (lumped).", "foundation mass"),
    "foundation.stiffness": E("N/m", "Lumped hull stiffness at each attachment (lumped).", "foundation stiffness"),
    "foundation.damping": E("N s/m", "Lumped hull damping at each attachment (lumped).", "foundation damping"),
    "foundation.frequency_hz": E("Hz", "Frequencies of the table (at least 2, strictly increasing); analysed "
                                 "frequencies must lie inside it.", "foundation table frequency"),
    "foundation.mobility_real": E("m/(N s)", "Real part of the point mobility (>= 0: a passive hull) "
                                  "(mobility-table).", "foundation mobility (real)"),
    "foundation.mobility_imag": E("m/(N s)", "Imaginary part of the point mobility (mobility-table).",
                                  "foundation mobility (imaginary)"),
    "foundation.impedance_real": E("N s/m", "Real part of the point impedance (>= 0) (impedance-table).",
                                   "foundation impedance (real)"),
    "foundation.impedance_imag": E("N s/m", "Imaginary part of the point impedance (impedance-table).",
                                   "foundation impedance (imaginary)"),
}

INTRO = f"""
Every key of an impstab model file (TOML, `schema_version = 1`, SI units), generated from the
schema (`src/impstab/model/schema.py`) and the table of units and descriptions beside it
(`src/impstab/model/reference.py`): `impstab schema --markdown` prints this page, and a test keeps
it equal to the schema. Vectors are in the body frame, measured from the reference point A; the
dof order is `surge, sway, heave, roll, pitch, yaw`. A key with a default may be omitted; a key
the schema does not know is an error (it is a typo), reported with the nearest valid key.
Numbers are checked for sign, finiteness (TOML's `inf` and `nan` are refused) and shape when the
file is read; rules that involve several keys (positive-definite inertia, mounts that restrain
all six motions, exclusive keys) when it is assembled.

**Editor support.** `impstab schema -o impstab-model.schema.json` writes a JSON Schema of the
model file. TOML editors that read JSON Schemas (Taplo, and VS Code's Even Better TOML, which
uses it) then validate and complete model files as they are typed: put the line
`#:schema ./impstab-model.schema.json` at the top of a model file, or associate the schema with
a file pattern in `.taplo.toml`:

```toml
[[rule]]
include = ["**/imp*.toml"]
[rule.schema]
path = "./impstab-model.schema.json"
```

Study files have their own reference, `docs/study-file.md` (`impstab schema --study`).
"""


def unit(path: str) -> str | None:
    """SI unit of the value at a parameter path (``mount_rings[0].k_shear`` -> ``"N/m"``);
    ``"1"`` for a count, a flag or a word; None for an unknown path."""
    import re

    key = re.sub(r"\[\d+\](?=\.)", "[]", path)
    key = re.sub(r"(\[\d+\])+$", "", key)
    ref = MODEL_REFERENCE.get(key)
    if ref is None:
        return None
    return ref.unit or "1"


def label(path: str) -> str:
    """Axis label of a parameter path, e.g. ``mount_rings[0].x`` -> ``"ring axial position x (m)"``.

    The label and unit come from :data:`MODEL_REFERENCE`; a component of a vector is named by its
    axis (``mounts[1].position[2]`` -> ``"mount 2 position z (m)"``). Unknown paths are returned
    as they are.
    """
    import re

    parts = re.findall(r"([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)", path)
    key_parts, which, comp = [], [], None
    for j, (name, idx) in enumerate(parts):
        numbers = [int(i) for i in re.findall(r"\d+", idx)]
        last = j == len(parts) - 1
        if last and numbers:
            comp = numbers
            key_parts.append(name)
        elif numbers:
            key_parts.append(f"{name}[]")
            which.append(numbers[0])
        else:
            key_parts.append(name)
    ref = MODEL_REFERENCE.get(".".join(key_parts))
    if ref is None:
        return path
    text = ref.label or key_parts[-1]
    if which and which[0] > 0:
        noun, _, rest = text.partition(" ")
        text = f"{noun} {which[0] + 1} {rest}".strip()
    if comp:
        if len(comp) == 1 and comp[0] < 3 and ref.unit in ("m", "", "kg m^2"):
            text += " " + ("xyz"[comp[0]] if ref.unit != "kg m^2" else ("Ixx", "Iyy", "Izz")[comp[0]])
        else:
            text += "".join(f"[{c}]" for c in comp)
    unit = ref.unit if ref.unit not in ("", "1") else ""
    return f"{text} ({unit})" if unit else text


def markdown_page() -> str:
    """The text of ``docs/model-file.md``."""
    from .schema import ModelFile
    from .schema_doc import markdown

    return markdown(ModelFile, MODEL_REFERENCE, title=TITLE, intro=INTRO)


def json_schema_document() -> dict:
    """The JSON Schema (draft-07) of model files, with units and descriptions."""
    from .schema import ModelFile
    from .schema_doc import json_schema

    doc = json_schema(ModelFile, MODEL_REFERENCE, title="impstab model file (schema_version 1)", doc_url=DOC_PATH)
    doc["properties"]["schema_version"]["const"] = 1
    return doc
