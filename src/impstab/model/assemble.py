"""From a model file (or a plain dict) to a validated, assembled :class:`Model`.

Every failure is a :class:`~impstab.errors.ModelError` naming the field, the value and the rule.
"""

from __future__ import annotations

import os
import stat
import tomllib
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import ValidationError

from ..errors import ModelError
from ..limits import MAX_FILE_BYTES, MAX_LIST_ITEMS, MAX_MOUNTS, MAX_NESTING, MIN_DIRECTION, RANGES
from .beam import BeamMount, tip_stiffness
from .body import RigidBody
from .isolation_specs import excitation_from_spec, foundation_from_spec
from .fluid import FluidLoading, Hull
from .model import AnalysisSettings, Model
from .mounts import Mount, NonlinearLaw, axial_shear_matrix, elastic_stiffness, ring_positions
from .schema import UNION_TAGS, ModelFile, mark_at
from .thrust import Propeller, Thrust

__all__ = ["load_model", "model_from_dict", "format_location", "unit_vector", "read_toml", "read_text", "check_nesting"]

_SYM_TOL = 1e-9


def format_location(loc: tuple) -> str:
    """``("mounts", 1, "k_axial")`` -> ``"mounts[1].k_axial"``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out or "(file)"


def _lookup(data: Any, loc: tuple) -> Any:
    cur = data
    for part in loc:
        try:
            cur = cur[part]
        except (KeyError, IndexError, TypeError):
            return None
    return cur


def _plain_loc(loc: tuple) -> tuple:
    """The location without the union-branch labels pydantic inserts (``list[float]``, tags)."""
    return tuple(
        p for p in loc if not (isinstance(p, str) and (p.startswith(("list[", "function-")) or p in UNION_TAGS))
    )


#: pydantic's wording of a wrong type, in the words of the file
_TYPE_RULES = {
    "string_type": "must be a string",
    "list_type": "must be a list",
    "model_type": "must be a table of keys",
    "dict_type": "must be a table of keys",
    "model_attributes_type": "must be a table of keys",
    "bool_type": "must be true or false",
    "int_type": "must be an integer",
    "float_type": "must be a number",
}


def _error_loc(root, error: dict) -> tuple:
    """Where a pydantic error is, without union labels; an unknown key is kept as written (it may
    hold brackets or any other character that a label has)."""
    from .schema_doc import clean_loc  # error paths only: the reference machinery is not loaded otherwise

    loc = tuple(error["loc"])
    if error["type"] == "extra_forbidden" and loc:
        return _plain_loc(clean_loc(root, loc[:-1])) + loc[-1:]
    return _plain_loc(clean_loc(root, loc))


#: lengths of the fixed-size lists of the schema (3-vectors, 3x3 and 6x6 matrices)
_VECTOR_SIZES = (3, 6)


def _from_validation_error(err: ValidationError, data: Any) -> ModelError:
    from .reference import DOC_PATH
    from .schema_doc import unknown_key_rule

    errors = err.errors()
    # an unknown key is a typo: report it first (pydantic lists the key it hides as missing first)
    first = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
    loc = _error_loc(ModelFile, first)
    field = format_location(loc)
    value = first.get("input", _lookup(data, loc))
    kind = first["type"]
    if kind == "extra_forbidden":
        where = f"in {format_location(loc[:-1])}" if len(loc) > 1 else "at the top level"
        return ModelError(field, value, unknown_key_rule(ModelFile, loc, where, DOC_PATH))
    if kind == "missing":
        return ModelError(field, None, f"is required (see {DOC_PATH})")
    return ModelError(field, value, rule_text(first, mark_at(ModelFile, tuple(first["loc"]))))


#: errors of a marked value, worded by its mark (range, unit, what it is)
_MARKED = frozenset(("float_type", "finite_number", "greater_than_equal", "less_than_equal", "greater_than",
                     "less_than", "int_type", "int_from_float", "int_parsing", "bool_type", "bool_parsing"))


def rule_text(error: dict, mark: Any = None) -> str:
    """The rule of one pydantic error in the words of the file (``must be a list``).

    ``mark``: the :class:`~impstab.model.schema.RangeMark` (or integer or flag mark) of the value,
    which words a wrong type or a value out of range with the range, its unit and its meaning.
    """
    kind = error["type"]
    ctx = error.get("ctx") or {}
    if mark is not None and kind in _MARKED:
        return mark.rule(error.get("input"))
    if kind in _TYPE_RULES:
        return _TYPE_RULES[kind]
    if kind in ("too_short", "too_long") and "actual_length" in ctx:
        want = ctx.get("min_length") if kind == "too_short" else ctx.get("max_length")
        if want in _VECTOR_SIZES:  # a vector or a matrix row: its size is fixed
            return f"must have {want} items, not {ctx['actual_length']}"
        bound = "at least" if kind == "too_short" else "at most"
        return f"must have {bound} {want} items, not {ctx['actual_length']}"
    if kind in ("string_too_long", "string_too_short"):
        return error["msg"].replace("String should have", "must have")
    msg = error["msg"].replace("Value error, ", "").replace("Input should be", "must be")
    return msg[0].lower() + msg[1:]


def unit_vector(vec: list[float], field: str) -> np.ndarray:
    """``vec / |vec|``; a zero vector is a ModelError naming ``field``."""
    v = np.asarray(vec, dtype=float)
    n = float(np.linalg.norm(v))
    if not n >= MIN_DIRECTION:
        raise ModelError(field, vec, f"must be a non-zero vector (length at least {MIN_DIRECTION:g})")
    return v / n


def _symmetric_psd(mat: np.ndarray, field: str, definite: bool = False) -> None:
    scale = max(float(np.abs(mat).max()), 1e-300)
    if np.abs(mat - mat.T).max() > _SYM_TOL * scale:
        raise ModelError(field, mat.tolist(), "must be symmetric")
    ev = np.linalg.eigvalsh(0.5 * (mat + mat.T))
    if definite and ev.min() <= _SYM_TOL * ev.max():
        raise ModelError(field, mat.tolist(), "must be positive definite")
    if ev.min() < -_SYM_TOL * scale:
        raise ModelError(field, mat.tolist(), "must be positive semi-definite")


def _inertia(spec: list, field: str) -> np.ndarray:
    arr = np.asarray(spec, dtype=float)
    inertia = np.diag(arr) if arr.ndim == 1 else arr
    _symmetric_psd(inertia, field, definite=True)
    p = np.linalg.eigvalsh(inertia)
    moments = RANGES["moment_of_inertia"]
    if p[0] < moments.low or p[2] > moments.high:
        raise ModelError(field, spec, f"principal moments {p.round(12).tolist()} kg m^2 must be {moments.text}")
    if p[2] > p[0] + p[1] * (1 + 1e-12):
        raise ModelError(
            field, spec, f"principal moments {p.round(12).tolist()} break the triangle inequality "
            "(each must not exceed the sum of the other two)"
        )
    return inertia


_LAW_KEYS = ("k3_axial", "k3_shear", "snubber_clearance", "snubber_stiffness")


def _nonlinear_law(spec, axis: np.ndarray, field: str) -> NonlinearLaw | None:
    """The mount's nonlinear law from its keys (None when they add nothing); checks the snubber
    pair: a clearance needs a stiffness > 0, and a stiffness needs a clearance."""
    clearance, stiffness = spec.snubber_clearance, spec.snubber_stiffness
    if clearance > 0.0 and not stiffness > 0.0:
        raise ModelError(f"{field}.snubber_stiffness", stiffness,
                         f"must be > 0 when snubber_clearance is given ({clearance:g} m)")
    if stiffness > 0.0 and not clearance > 0.0:
        raise ModelError(f"{field}.snubber_clearance", clearance,
                         f"must be > 0 when snubber_stiffness is given ({stiffness:g} N/m); 0 means no snubber")
    law = NonlinearLaw(axis, spec.k3_axial, spec.k3_shear, clearance, stiffness)
    return None if law.is_linear else law


# -- viscoelastic mounts (impstab.model.viscoelastic) ---------------------------------------------
_VISCO_KEYS = {
    "standard-linear-solid": ("stiffening", "relaxation_time"),
    "prony": ("terms",),
    "fractional-zener": ("stiffening", "relaxation_time", "alpha"),
    "table": ("frequency_hz", "storage_ratio", "loss_factor"),
}
_VISCO_ALL = ("stiffening", "relaxation_time", "alpha", "terms", "frequency_hz", "storage_ratio", "loss_factor")


def _viscoelastic(spec, field: str):
    """The mount's :class:`~impstab.model.viscoelastic.ViscoelasticLaw` from ``[mounts.viscoelastic]``
    (None without one); every missing, stray or inconsistent key is a one-line ModelError."""
    v = spec.viscoelastic
    if v is None:
        return None
    from .viscoelastic import ViscoelasticLaw

    f = f"{field}.viscoelastic"
    needed = _VISCO_KEYS[v.law]
    for key in needed:
        if getattr(v, key) is None:
            raise ModelError(f"{f}.{key}", None, f"is required with law = {v.law!r} (keys: {', '.join(needed)})")
    for key in _VISCO_ALL:
        if key not in needed and getattr(v, key) is not None:
            raise ModelError(f"{f}.{key}", getattr(v, key), f"is not read with law = {v.law!r} (keys: {', '.join(needed)})")
    fitted = v.law in ("fractional-zener", "table")
    for key in ("fit_band_hz", "fit_terms"):
        if getattr(v, key) is not None and not fitted:
            raise ModelError(f"{f}.{key}", getattr(v, key), "is read only with law = 'fractional-zener' or 'table' (the fitted laws)")
    if v.stiffening is not None and not v.stiffening > 1.0:
        raise ModelError(f"{f}.stiffening", v.stiffening, "must be > 1 (k(inf) / k(0): a viscoelastic mount stiffens with frequency)")
    if v.alpha is not None and not 0.0 < v.alpha < 1.0:
        raise ModelError(f"{f}.alpha", v.alpha, "must be strictly between 0 and 1 (the fractional order)")
    band = None
    if v.fit_band_hz is not None:
        band = v.fit_band_hz
        if not 0.0 < band[0] < band[1]:
            raise ModelError(f"{f}.fit_band_hz", band, "must be [low, high] with 0 < low < high (Hz)")
    if v.law == "standard-linear-solid":
        return ViscoelasticLaw.standard_linear_solid(v.stiffening, v.relaxation_time)
    if v.law == "prony":
        g = np.array([t[0] for t in v.terms], float)
        tau = np.array([t[1] for t in v.terms], float)
        for j, (gj, tj) in enumerate(zip(g, tau)):
            if not (RANGES["prony_weight"].low < gj <= RANGES["prony_weight"].high):
                raise ModelError(f"{f}.terms[{j}][0]", gj, f"must be > 0 and at most {RANGES['prony_weight'].high:g} (the weight g_j)")
            if not (RANGES["relaxation_time"].low <= tj <= RANGES["relaxation_time"].high):
                raise ModelError(f"{f}.terms[{j}][1]", tj, RANGES["relaxation_time"].rule())
        return ViscoelasticLaw.prony(g, tau)
    if v.law == "fractional-zener":
        return ViscoelasticLaw.fractional_zener(v.stiffening, v.relaxation_time, v.alpha, band, v.fit_terms)
    freq, store, loss = (np.asarray(getattr(v, k), float) for k in ("frequency_hz", "storage_ratio", "loss_factor"))
    if freq.size < 2:
        raise ModelError(f"{f}.frequency_hz", v.frequency_hz, "must hold at least two frequencies")
    if freq[0] <= 0.0 or np.any(np.diff(freq) <= 0.0):
        raise ModelError(f"{f}.frequency_hz", v.frequency_hz, "must be > 0 and strictly increasing")
    for key, arr in (("storage_ratio", store), ("loss_factor", loss)):
        if arr.size != freq.size:
            raise ModelError(f"{f}.{key}", f"{arr.size} values", f"must have one value per frequency ({freq.size})")
    return ViscoelasticLaw.table(freq, store, loss, band, v.fit_terms)


# -- beam mounts ([mounts.beam]) ----------------------------------------------------------------
def _beam(m, f: str) -> BeamMount:
    """The beam of a mount table; its keys exclude the spring keys and the nonlinear law."""
    for key in ("k_axial", "k_shear", "stiffness"):
        if getattr(m, key) is not None:
            raise ModelError(f"{f}.{key}", "6x6" if key == "stiffness" else getattr(m, key),
                             "give either [mounts.beam] or k_axial/k_shear or 'stiffness', not two of them")
    for key in _LAW_KEYS:
        if getattr(m, key) != 0.0:
            raise ModelError(f"{f}.{key}", getattr(m, key),
                             "is read only with k_axial/k_shear (an axial-shear mount), not with [mounts.beam]")
    b = m.beam
    if not b.inner_diameter < b.outer_diameter:
        raise ModelError(f"{f}.beam.inner_diameter", b.inner_diameter,
                         f"must be below outer_diameter ({b.outer_diameter:g} m)")
    return BeamMount(b.length, b.outer_diameter, b.inner_diameter, b.youngs_modulus, b.shear_modulus,
                     b.shear_coefficient, b.density)
# -- end of beam mounts --------------------------------------------------------------------------


def _mounts(doc: ModelFile) -> tuple[Mount, ...]:
    mounts: list[Mount] = []
    for i, m in enumerate(doc.mounts):
        f = f"mounts[{i}]"
        pos = np.asarray(m.position, float)
        law = None
        beam = None
        if m.beam is not None:
            beam = _beam(m, f)
            k6 = tip_stiffness(beam, unit_vector(m.axis, f"{f}.axis"))
        elif m.stiffness is not None:
            for key in ("k_axial", "k_shear"):
                if getattr(m, key) is not None:
                    raise ModelError(f"{f}.{key}", getattr(m, key), "give either 'stiffness' (6x6) or k_axial/k_shear, not both")
            if m.viscoelastic is not None:
                raise ModelError(f"{f}.viscoelastic", m.viscoelastic.law,
                                 "is read only with k_axial/k_shear (an axial-shear mount), not with a full 6x6 'stiffness'")
            for key in _LAW_KEYS:
                if getattr(m, key) != 0.0:
                    raise ModelError(f"{f}.{key}", getattr(m, key),
                                     "is read only with k_axial/k_shear (an axial-shear mount), not with a full 6x6 'stiffness'")
            k6 = np.asarray(m.stiffness, float)
            _symmetric_psd(k6, f"{f}.stiffness")
        else:
            for key in ("k_axial", "k_shear"):
                if getattr(m, key) is None:
                    raise ModelError(f"{f}.{key}", None, "is required (or give a full 6x6 'stiffness' or [mounts.beam])")
            axis = unit_vector(m.axis, f"{f}.axis")
            k6 = np.zeros((6, 6))
            k6[:3, :3] = axial_shear_matrix(axis, m.k_axial, m.k_shear)
            law = _nonlinear_law(m, axis, f)
        if m.damping is not None:
            if m.c_axial or m.c_shear:
                raise ModelError(f"{f}.damping", "6x6", "give either 'damping' (6x6) or c_axial/c_shear, not both")
            c6 = np.asarray(m.damping, float)
            _symmetric_psd(c6, f"{f}.damping")
        else:
            axis = unit_vector(m.axis, f"{f}.axis")
            c6 = np.zeros((6, 6))
            c6[:3, :3] = axial_shear_matrix(axis, m.c_axial, m.c_shear)
        mounts.append(Mount(pos, k6, c6, unit_vector(m.axis, f"{f}.axis"), m.rated_force, m.max_deflection,
                            nonlinear=law, viscoelastic=_viscoelastic(m, f), beam=beam))
    for i, ring in enumerate(doc.mount_rings):
        f = f"mount_rings[{i}]"
        axis = unit_vector(ring.axis, f"{f}.axis")
        law = _nonlinear_law(ring, axis, f)
        visco = _viscoelastic(ring, f)
        for pos in ring_positions(ring.count, ring.radius, ring.x, ring.start_angle):
            mount = Mount.axial_shear(pos, axis, ring.k_axial, ring.k_shear, ring.c_axial, ring.c_shear)
            mounts.append(replace(mount, rated_force=ring.rated_force, max_deflection=ring.max_deflection,
                                  nonlinear=law, viscoelastic=visco))
    if not mounts:
        raise ModelError("mounts", [], "the model needs at least one mount or mount ring")
    if len(mounts) > MAX_MOUNTS:
        raise ModelError("mounts", f"{len(mounts)} mounts", f"a model has at most {MAX_MOUNTS} mounts (mounts and ring counts together)")
    kc = elastic_stiffness(mounts)
    ev = np.linalg.eigvalsh(kc)
    if ev.min() <= 1e-9 * ev.max():
        vec = np.linalg.eigh(kc)[1][:, 0]
        names = ("surge", "sway", "heave", "roll", "pitch", "yaw")
        free = [names[j] for j in np.flatnonzero(np.abs(vec) > 0.3)]
        raise ModelError(
            "mounts", f"{len(mounts)} mounts",
            f"leave a rigid-body motion free (involving {', '.join(free)}): the mounts must restrain all six",
        )
    return tuple(mounts)


def _fluid(doc: ModelFile) -> tuple[FluidLoading, Hull | None]:
    hull = None
    if doc.hull is not None:
        hull = Hull(doc.hull.radius, doc.hull.length, np.asarray(doc.hull.center, float))
    spec = doc.fluid
    if spec is None or spec.model == "none":
        if spec is not None and spec.added_mass is not None:
            raise ModelError("fluid.added_mass", "6x6", "is only read with fluid.model = 'matrix'")
        return FluidLoading(), hull
    if spec.model == "matrix":
        if spec.added_mass is None:
            raise ModelError("fluid.added_mass", None, "is required with fluid.model = 'matrix' (6x6 about A)")
        mat = np.asarray(spec.added_mass, float)
        _symmetric_psd(mat, "fluid.added_mass")
        return FluidLoading("matrix", spec.density, spec.sound_speed, mat), hull
    if spec.added_mass is not None:
        raise ModelError("fluid.added_mass", "6x6", f"is only read with fluid.model = 'matrix', not {spec.model!r}")
    if hull is None:
        raise ModelError("hull", None, f"is required with fluid.model = {spec.model!r} (radius, length, center)")
    if spec.density is None:
        raise ModelError("fluid.density", None, f"is required with fluid.model = {spec.model!r}")
    try:
        return FluidLoading.from_hull(spec.model, hull, spec.density, spec.sound_speed), hull
    except ModelError as exc:
        where = {"radius": "hull.radius", "length": "hull.length", "density": "fluid.density"}
        if exc.field in where:
            raise ModelError(where[exc.field], exc.value, exc.rule) from None
        raise


def _spin_speed(spec) -> float:
    """Propeller speed (rad/s) from ``speed`` (rad/s) or ``speed_rpm`` (rpm), which are exclusive."""
    if spec.speed_rpm is None:
        return spec.speed
    if "speed" in spec.model_fields_set:
        raise ModelError("propeller.speed_rpm", spec.speed_rpm, "give either speed (rad/s) or speed_rpm (rpm), not both")
    return spec.speed_rpm * (2.0 * np.pi / 60.0)


def _assemble(doc: ModelFile, name: str, source: str | None) -> Model:
    b = doc.body
    inertia = _inertia(b.inertia, "body.inertia")
    body = RigidBody(b.mass, np.asarray(b.cg, float), inertia)
    mounts = _mounts(doc)
    t = doc.thrust
    thrust = Thrust(
        np.asarray(t.point, float), unit_vector(t.direction, "thrust.direction"), t.tangency, t.operating,
        t.preload_stiffness,
    )
    prop = doc.propeller or Propeller()
    if doc.propeller is not None:
        prop = Propeller(doc.propeller.polar_inertia, _spin_speed(doc.propeller), doc.propeller.speed_law)
        if prop.speed_law == "sqrt-thrust" and t.operating is None:
            raise ModelError("propeller.speed_law", "sqrt-thrust", "needs thrust.operating (the speed is given at the operating thrust)")
    thrust_max = doc.analysis.thrust_max
    if thrust_max is None:
        if t.operating is None:
            raise ModelError("analysis.thrust_max", None, "is required when thrust.operating is not given")
        thrust_max = min(10.0 * t.operating, RANGES["thrust"].high)
    # a thrust_max below the operating thrust is allowed (a search of the low range); every result
    # of the critical-thrust search then says that it did not reach the operating point
    fluid, hull = _fluid(doc)
    return Model(
        body=body, mounts=mounts, thrust=thrust,
        analysis=AnalysisSettings(float(thrust_max), doc.analysis.linearization, _damping_threshold(doc.analysis)),
        propeller=prop, fluid=fluid, hull=hull, name=name, source=source,
        excitation=excitation_from_spec(doc.excitation, prop), foundation=foundation_from_spec(doc.foundation),
    )


def model_from_dict(data: dict, name: str | None = None, source: str | None = None) -> Model:
    """Validate and assemble a model from the parsed contents of a model file."""
    if not isinstance(data, dict):
        raise ModelError("(file)", type(data).__name__, "must be a table of model keys")
    check_nesting(data)
    if "schema_version" not in data:
        raise ModelError("schema_version", None, "is required (schema_version = 1)")
    try:
        doc = ModelFile.model_validate(data)
    except ValidationError as err:
        raise _from_validation_error(err, data) from None
    return _assemble(doc, doc.name or name or "model", source)


def check_nesting(data: Any, limit: int = MAX_NESTING, max_items: int | None = MAX_LIST_ITEMS) -> None:
    """ModelError when tables and arrays nest deeper than ``limit``, or an array holds more than
    ``max_items`` values (checked without recursion, before the schema sees the data)."""
    stack: list[tuple[Any, int, tuple]] = [(data, 0, ())]
    while stack:
        value, depth, loc = stack.pop()
        if depth > limit:
            raise ModelError(format_location(loc[:2]), _lookup(data, loc[:2]),
                             f"tables and arrays may nest at most {limit} levels deep")
        if isinstance(value, dict):
            items = value.items()
        else:
            if max_items is not None and len(value) > max_items:
                raise ModelError(format_location(loc) if loc else "(file)", f"{len(value)} items",
                                 f"an array may hold at most {max_items} items")
            items = enumerate(value)
        for key, item in items:
            if isinstance(item, (dict, list)):
                stack.append((item, depth + 1, loc + (key,)))


def read_text(path: str | os.PathLike[str], what: str = "model file") -> str:
    """The UTF-8 text of a regular file of at most :data:`~impstab.limits.MAX_FILE_BYTES`.

    A FIFO, a device, a socket or a directory is refused without being read (the file is
    opened non-blocking and checked with ``fstat`` before a byte is read); a larger file is
    refused after reading at most one byte more than the limit.
    """
    p = Path(path)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(p, flags)
    except FileNotFoundError:
        raise ModelError(what, str(p), "file not found") from None
    except IsADirectoryError:
        raise ModelError(what, str(p), "is a directory, not a file") from None
    except PermissionError:
        raise ModelError(what, str(p), "cannot be read (permission denied)") from None
    except (OSError, ValueError) as exc:
        reason = getattr(exc, "strerror", None) or exc.__class__.__name__
        raise ModelError(what, str(p), f"cannot be read ({reason})") from None
    try:
        info = os.fstat(fd)
        if stat.S_ISDIR(info.st_mode):
            raise ModelError(what, str(p), "is a directory, not a file")
        if not stat.S_ISREG(info.st_mode):
            raise ModelError(what, str(p), "is not a regular file (a pipe, a device or a socket): give a TOML file")
        limit = f"larger than the {MAX_FILE_BYTES // 1024**2} MiB a {what} may have"
        if info.st_size > MAX_FILE_BYTES:
            raise ModelError(what, str(p), f"is {info.st_size} bytes, {limit}")
        chunks = []
        size = 0
        while size <= MAX_FILE_BYTES:
            chunk = os.read(fd, min(1 << 20, MAX_FILE_BYTES + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > MAX_FILE_BYTES:
            raise ModelError(what, str(p), f"is {limit}")
    except OSError as exc:
        raise ModelError(what, str(p), f"cannot be read ({exc.strerror or exc.__class__.__name__})") from None
    finally:
        os.close(fd)
    try:
        return b"".join(chunks).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ModelError(what, str(p), f"is not UTF-8 text (byte {exc.object[exc.start]:#04x} at offset {exc.start})") from None


def parse_toml(text: str, path: str | os.PathLike[str], what: str = "model file", max_items: int | None = MAX_LIST_ITEMS) -> dict:
    """Parse TOML text, turning a syntax error or too deep a nesting into a one-line ModelError."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(what, str(path), f"is not valid TOML ({exc})") from None
    except RecursionError:
        raise ModelError(what, str(path), f"is nested too deeply (tables and arrays at most {MAX_NESTING} levels)") from None
    check_nesting(data, max_items=max_items)
    return data


def read_toml(path: str | os.PathLike[str], what: str = "model file") -> dict:
    """Read a TOML file, turning every I/O or syntax problem into a one-line ModelError."""
    return parse_toml(read_text(path, what), path, what)


def load_model(path: str | os.PathLike[str]) -> Model:
    """Read, validate and assemble a model file (TOML, schema_version 1, SI units).

    Raises
    ------
    ModelError
        With a one-line message naming the field, the value and the rule.
    """
    data = read_toml(path)
    return model_from_dict(data, name=Path(path).stem, source=str(path))


def _damping_threshold(analysis) -> float | None:
    """``analysis.min_damping_ratio``, or the damping ratio of ``analysis.min_log_decrement``."""
    from .criteria import damping_threshold

    return damping_threshold(analysis.min_damping_ratio, analysis.min_log_decrement,
                             names=("analysis.min_damping_ratio", "analysis.min_log_decrement"))
