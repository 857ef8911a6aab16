"""A validated design study: base model, parameters and their values, outputs, chunking.

:func:`load_study` reads a study file and checks everything that can be checked before anything
runs: the file against its schema, the base model like a model file, every parameter path
against the model schema and the base model, and every grid value (or the range of a
distribution) against the rule of its field. Each failure is a one-line
:class:`~impstab.errors.ModelError` naming the field, the value and the rule.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pydantic import ValidationError

from ..errors import ModelError
from ..limits import MAX_STUDY_BYTES
from ..model.assemble import _error_loc, check_nesting, format_location, model_from_dict, parse_toml, read_text, rule_text
from ..model.schema import mark_at
from ..model.schema_doc import unknown_key_rule
from .isolation import IsolationSettings, isolation_output_info, settings_from_spec
from .paths import ParameterPath, resolve_path
from .reference import DOC_PATH as STUDY_DOC_PATH
from .sampling import axis_values, check_distribution, map_samples, unit_samples
from .schema import VALUES_TAGS, ParameterSpec, RangeSpec, StudyFile

__all__ = ["Study", "Parameter", "load_study", "study_from_dict", "describe", "MAX_DESIGNS", "result_bytes"]

#: largest number of designs in one study
MAX_DESIGNS = 100_000_000
#: bytes per design of each output in memory (floats 8, kind codes 1, "modes" up to 36 characters
#: of 4 bytes), and of the status code and the message (an object pointer) of every design
_OUTPUT_BYTES = {"kind": 1, "undamped_kind": 1, "modes": 144, "bifurcation": 52}
_DESIGN_BYTES = 1 + 8


@dataclass(frozen=True, eq=False)
class Parameter:
    """One varied model-file value.

    Attributes
    ----------
    path : ParameterPath
        Where the value goes in the model file.
    values : (k,) array
        Grid axis (grid sampling) or the value of every sample (random, sobol).
    """

    path: ParameterPath
    values: NDArray

    def __repr__(self) -> str:
        from ..display import parameter_text

        return parameter_text(self)

    @property
    def name(self) -> str:
        """The path as written in the study file (also the name of its coordinate)."""
        return self.path.path


@dataclass(frozen=True, eq=False)
class Study:
    """A design study ready to run (see :func:`load_study`)."""

    name: str
    method: str
    parameters: tuple[Parameter, ...]
    outputs: tuple[str, ...]
    chunk_size: int
    base_model: dict
    model_name: str
    study_text: str
    model_text: str
    fingerprint: str
    source: str | None = None
    model_source: str | None = None
    seed: int = 0
    isolation: IsolationSettings | None = None

    def output_info(self, name: str) -> tuple[str, str]:
        """``(units, description)`` of an output of this study."""
        from .schema import OUTPUTS

        return OUTPUTS.get(name) or isolation_output_info(self.isolation, name) or ("", name)

    def __repr__(self) -> str:
        from ..display import study_definition_text

        return study_definition_text(self)

    @property
    def dims(self) -> tuple[str, ...]:
        """Dimensions of the results: one per parameter for a grid, else ``("sample",)``."""
        return tuple(p.name for p in self.parameters) if self.method == "grid" else ("sample",)

    @property
    def shape(self) -> tuple[int, ...]:
        if self.method == "grid":
            return tuple(len(p.values) for p in self.parameters)
        return (len(self.parameters[0].values),)

    @property
    def size(self) -> int:
        """Number of designs."""
        return int(np.prod(self.shape))


def _shown(value: Any) -> Any:
    """A table of the study file as the user wrote it (keys that were given)."""
    return value.model_dump(exclude_none=True) if hasattr(value, "model_dump") else value


def _schema_error(err: ValidationError) -> ModelError:
    errors = err.errors()
    # an unknown key is a typo: report it first (pydantic lists the key it hides as missing first)
    first = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
    loc = tuple(p for p in _error_loc(StudyFile, first) if p not in VALUES_TAGS)
    field = format_location(loc)
    kind = first["type"]
    if kind == "extra_forbidden":
        where = f"in {format_location(loc[:-1])}" if len(loc) > 1 else "at the top level"
        return ModelError(field, first.get("input"), unknown_key_rule(StudyFile, loc, where, STUDY_DOC_PATH))
    if kind == "missing":
        return ModelError(field, None, f"is required (see {STUDY_DOC_PATH})")
    return ModelError(field, first.get("input"), rule_text(first, mark_at(StudyFile, tuple(first["loc"]))))


def result_bytes(n_designs: int, n_parameters: int, outputs: tuple[str, ...] | list[str], grid: bool) -> int:
    """Estimated memory of a study's results (bytes): every output, status and message of every
    design, and the parameter values (one axis each for a grid, one column each otherwise)."""
    per_design = _DESIGN_BYTES + sum(_OUTPUT_BYTES.get(name, 8) for name in outputs)
    return n_designs * (per_design + (0 if grid else 8 * n_parameters))


def _checked(par: ParameterPath, values: list, field: str) -> NDArray:
    """Values checked with the field's strict schema rule, as an array of the field's type.

    A list is taken as written: ``[true, false]`` is not a list of numbers and ``[3.0, 4.0]``
    not a list of integers (a range of an integer field gives integers itself).
    """
    out = []
    for v in values:
        v = v.item() if isinstance(v, np.generic) else v
        try:
            out.append(par.check(v))
        except ValueError as exc:
            raise ModelError(field, v, f"{exc} (the rule of {par.path})") from None
    dtype = {"float": np.float64, "int": np.int64, "bool": np.bool_, "str": np.str_}[par.kind]
    return np.asarray(out, dtype=dtype)


def _checked_array(par: ParameterPath, values: NDArray, field: str) -> NDArray:
    """A generated column (a range, samples of a distribution) checked with the field's rule.

    The rule of a numeric field is a range, so the smallest and the largest value decide; a
    non-finite value (an infinite quantile) is reported first.
    """
    arr = np.asarray(values)
    if arr.size == 0:
        return arr
    if arr.dtype.kind == "f" and not np.isfinite(arr).all():
        bad = arr[~np.isfinite(arr)][0]
        raise ModelError(field, float(bad), f"must be a finite number (the rule of {par.path})")
    for v in (arr.min(), arr.max()):
        try:
            par.check(v.item())
        except ValueError as exc:
            raise ModelError(field, v.item(), f"{exc} (the rule of {par.path})") from None
    return arr.astype(np.int64 if par.kind == "int" else np.float64)


def _grid_axis(spec: ParameterSpec, par: ParameterPath, i: int) -> NDArray:
    f = f"parameters[{i}]"
    if spec.distribution is not None:
        raise ModelError(f"{f}.distribution", spec.distribution.kind, "is only used with sampling.method = 'random' or 'sobol'")
    if spec.values is None:
        raise ModelError(f"{f}.values", None, "is required: a range {start, stop, num} or a list")
    if isinstance(spec.values, RangeSpec) and spec.values.num is None:
        raise ModelError(f"{f}.values.num", None, "is required for grid sampling (the number of values)")
    try:
        axis = axis_values(spec)
    except ValueError as exc:
        raise ModelError(f"{f}.values", _shown(spec.values), str(exc)) from None
    if isinstance(spec.values, RangeSpec):
        if par.kind not in ("float", "int"):
            raise ModelError(f"{f}.values", _shown(spec.values), f"{par.path} is not a number: give a list of values")
        if par.kind == "int":
            rounded = np.round(axis)
            if not np.allclose(axis, rounded, rtol=0, atol=1e-9 * max(1.0, np.abs(axis).max())):
                raise ModelError(f"{f}.values", _shown(spec.values), f"{par.path} is an integer: the range must hit integers (or give a list)")
            axis = rounded.astype(np.int64)
        values = _checked_array(par, axis, f"{f}.values")
    else:
        values = _checked(par, axis, f"{f}.values")
    if len(np.unique(values)) != len(values):
        raise ModelError(f"{f}.values", axis if len(axis) < 12 else f"{len(axis)} values", "must be distinct")
    return values


def _sample_column(spec: ParameterSpec, par: ParameterPath, i: int, u: NDArray) -> NDArray:
    f = f"parameters[{i}]"
    try:
        check_distribution(spec)
    except ValueError as exc:
        key = "distribution" if spec.distribution is not None else "values"
        raise ModelError(f"{f}.{key}", _shown(getattr(spec, key)), str(exc)) from None
    if isinstance(spec.values, list):
        dtype = _checked(par, spec.values, f"{f}.values").dtype
        return np.asarray(map_samples(spec, u), dtype=dtype)
    if par.kind != "float":
        raise ModelError(f"{f}.values", par.kind, f"{par.path} is not a real number: give a list of values to draw from")
    ends = []
    if isinstance(spec.values, RangeSpec):
        ends = [spec.values.start, spec.values.stop]
    elif spec.distribution.low is not None:
        ends = [spec.distribution.low, spec.distribution.high]
    key = f"{f}.{'values' if spec.values is not None else 'distribution'}"
    _checked(par, ends, key)
    return _checked_array(par, np.asarray(map_samples(spec, u), dtype=np.float64), key)


def load_base_model(name: str, base_dir: str | os.PathLike[str]) -> tuple[Path, str, dict, Any]:
    """The base model of a study or optimisation file: ``(path, text, parsed dict, Model)``.

    ``name`` is the file's ``model`` key, relative to ``base_dir``; a model that cannot be read is
    reported under ``model``, an invalid one under its own field "(in base model NAME)".
    """
    model_path = Path(base_dir) / name
    try:
        model_text = read_text(model_path, "model")
        base = parse_toml(model_text, model_path, "model")
    except ModelError as err:
        raise ModelError("model", name, f"{err.rule} ({model_path})") from None
    try:
        model = model_from_dict(base, name=model_path.stem, source=str(model_path))
    except ModelError as err:
        raise ModelError(f"{err.field} (in base model {name})", err.value, err.rule) from None
    return model_path, model_text, base, model


def study_from_dict(
    data: dict,
    base_dir: str | os.PathLike[str] = ".",
    *,
    source: str | None = None,
    text: str | None = None,
) -> Study:
    """Validate a parsed study file; the base model path is relative to ``base_dir``.

    Raises
    ------
    ModelError
        One line naming the field, the value and the rule.
    """
    if not isinstance(data, dict):
        raise ModelError("(study file)", type(data).__name__, "must be a table of study keys")
    check_nesting(data, max_items=None)
    if "schema_version" not in data:
        raise ModelError("schema_version", None, "is required (schema_version = 1)")
    try:
        doc = StudyFile.model_validate(data)
    except ValidationError as err:
        raise _schema_error(err) from None
    model_path, model_text, base, model = load_base_model(doc.model, base_dir)
    paths: list[ParameterPath] = []
    for i, spec in enumerate(doc.parameters):
        try:
            par = resolve_path(spec.path, base)
        except ValueError as exc:
            raise ModelError(f"parameters[{i}].path", spec.path, str(exc)) from None
        if any(p.segments == par.segments for p in paths):
            raise ModelError(f"parameters[{i}].path", spec.path, "is already varied by another parameter")
        paths.append(par)
    method = doc.sampling.method
    if method == "grid":
        if doc.sampling.n is not None:
            raise ModelError("sampling.n", doc.sampling.n, "is only used with random or sobol sampling (a grid has the product of the nums)")
        columns = [_grid_axis(s, p, i) for i, (s, p) in enumerate(zip(doc.parameters, paths))]
        size = int(np.prod([len(c) for c in columns], dtype=float))
    else:
        if doc.sampling.n is None:
            raise ModelError("sampling.n", None, f"is required with sampling.method = {method!r} (the number of samples)")
        from .sampling import design_count  # n base samples of a Saltelli design are n * (d + 2) designs

        size = design_count(method, doc.sampling.n, len(paths))
    if size > MAX_DESIGNS:
        raise ModelError("parameters", f"{size} designs", f"more than {MAX_DESIGNS} designs in one study")
    isolation = settings_from_spec(doc.isolation, tuple(doc.outputs))
    outputs = tuple(doc.outputs) + (() if isolation is None else tuple(p.name for p in isolation.at))
    needed = result_bytes(size, len(paths), outputs, method == "grid")
    if needed > MAX_STUDY_BYTES:
        where = "sampling.n" if method != "grid" else "parameters"
        raise ModelError(
            where, f"{size} designs",
            f"the results of {size} designs with {len(outputs)} outputs would take about "
            f"{needed / 1024**3:.3g} GiB (limit {MAX_STUDY_BYTES / 1024**3:g} GiB): fewer designs or outputs",
        )
    if method != "grid":
        u = unit_samples(method, size, len(paths), doc.sampling.seed)
        columns = [_sample_column(s, p, i, u[:, i]) for i, (s, p) in enumerate(zip(doc.parameters, paths))]
    canonical = json.dumps({"study": doc.model_dump(mode="json"), "model": base}, sort_keys=True, default=str)
    return Study(
        name=doc.name or (Path(source).stem if source else "study"),
        method=method,
        parameters=tuple(Parameter(p, c) for p, c in zip(paths, columns)),
        outputs=outputs,
        chunk_size=doc.execution.chunk_size,
        base_model=base,
        model_name=model.name,
        study_text=text if text is not None else json.dumps(data, default=str),
        model_text=model_text,
        fingerprint=hashlib.sha256(canonical.encode()).hexdigest(),
        source=source,
        model_source=str(model_path),
        seed=doc.sampling.seed,
        isolation=isolation,
    )


def load_study(path: str | os.PathLike[str]) -> Study:
    """Read and validate a study file (TOML, ``schema_version = 1``).

    Raises
    ------
    ModelError
        One line naming the field, the value and the rule; nothing has run and nothing is written.
    """
    p = Path(path)
    text = read_text(p, "study file")
    data = parse_toml(text, p, "study file", max_items=None)
    return study_from_dict(data, p.parent, source=str(p), text=text)


def describe(study: Study) -> dict[str, Any]:
    """A short JSON-able description of the study (for store attributes and summaries)."""
    return {
        "name": study.name,
        "sampling": study.method,
        "parameters": [p.name for p in study.parameters],
        "dims": list(study.dims),
        "shape": list(study.shape),
        "designs": study.size,
        "outputs": list(study.outputs),
        "seed": study.seed,
    }
