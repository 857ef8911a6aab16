"""An optimisation file (TOML, ``schema_version = 1``): design variables, objective, constraints.

.. code-block:: toml

    schema_version = 1
    model = "imp_isolation.toml"           # base model, relative to this file

    [[variables]]
    path = "mount_rings[0].k_shear"        # a study path (docs/study-file.md) to a real number
    low = 5.0e3
    high = 1.0e5
    scale = "log"                          # "linear" (default) or "log"

    [objective]
    isolation = "t_shaft_band"             # minimised: peak_transmissibility or an [[isolation.at]] name

    [constraints]
    margin_min = 2.0                       # critical / operating thrust >= 2
    static_deflection_max = 0.008          # m, every mount
    peak_mount_load_max = 1000.0           # N, every mount
    benign_onset = false                   # true: a supercritical Hopf point (or no onset) required

    [isolation]                            # as in a study file
    range_hz = [0.5, 300.0]
    [[isolation.at]]
    name = "t_shaft_band"
    band_hz = [20.0, 30.0]

    [optimizer]
    population = 24
    generations = 15
    seed = 0

Everything is checked before anything runs (pydantic at the file boundary, then every path and
bound against the model's own rules); each failure is a one-line
:class:`~impstab.errors.ModelError` naming the key.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal, Optional

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from ..errors import ModelError
from ..model.assemble import _error_loc, format_location, parse_toml, read_text, rule_text
from ..model.schema import Finite, Flag, Integer, Text, integer, mark_at, number
from ..model.schema_doc import unknown_key_rule
from ..studies.isolation import IsolationSettings, settings_from_spec
from ..studies.paths import ParameterPath, resolve_path
from ..studies.study import load_base_model
from ..studies.schema import ISOLATION_OUTPUTS, IsolationSpec

__all__ = ["OptimizationFile", "Optimization", "load_optimization", "optimization_from_dict", "DOC_PATH"]

DOC_PATH = "docs/optimize.md"


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class VariableSpec(_Strict):
    path: Text
    low: Finite
    high: Finite
    scale: Literal["linear", "log"] = "linear"


class ObjectiveSpec(_Strict):
    isolation: Text = "peak_transmissibility"


class ConstraintSpec(_Strict):
    margin_min: Optional[number("positive")] = None  # type: ignore[valid-type]
    static_deflection_max: Optional[number("size")] = None  # type: ignore[valid-type]
    peak_mount_load_max: Optional[number("thrust")] = None  # type: ignore[valid-type]
    benign_onset: Flag = False


class OptimizerSpec(_Strict):
    population: integer(4, 10_000, "designs per generation") = 24  # type: ignore[valid-type]
    generations: integer(1, 10_000, "generations") = 15  # type: ignore[valid-type]
    seed: integer(0, 2**32 - 1, "a seed") = 0  # type: ignore[valid-type]
    polish: Flag = True
    polish_evaluations: integer(1, 10_000, "evaluations of the polish") = 60  # type: ignore[valid-type]


class OptimizationFile(_Strict):
    schema_version: Integer
    name: Optional[Text] = None
    model: Text
    variables: Annotated[list[VariableSpec], Field(min_length=1, max_length=16)]
    objective: ObjectiveSpec = ObjectiveSpec()
    constraints: ConstraintSpec = ConstraintSpec()
    isolation: Optional[IsolationSpec] = None
    optimizer: OptimizerSpec = OptimizerSpec()


@dataclass(frozen=True)
class Variable:
    """One design variable: a model-file value between bounds."""

    path: ParameterPath
    low: float
    high: float
    log: bool

    @property
    def name(self) -> str:
        return self.path.path


@dataclass(frozen=True, eq=False)
class Optimization:
    """A validated optimisation problem (see :func:`load_optimization`)."""

    name: str
    variables: tuple[Variable, ...]
    objective: str
    margin_min: float | None
    static_deflection_max: float | None
    peak_mount_load_max: float | None
    isolation: IsolationSettings | None
    population: int
    generations: int
    seed: int
    polish: bool
    polish_evaluations: int
    base_model: dict
    model_name: str
    model_text: str
    text: str
    fingerprint: str
    source: str | None = None
    model_source: str | None = None

    #: require a benign onset: a supercritical Hopf point, or no onset up to thrust_max
    #: (the post-critical analysis of each design, :mod:`impstab.postcritical`)
    benign_onset: bool = False

    @property
    def outputs(self) -> tuple[str, ...]:
        """The study outputs every evaluation stores."""
        out = ["margin", "critical_thrust", "kind", "thrust_max", "operating_thrust", "frequency_hz"]
        if self.objective in ISOLATION_OUTPUTS:
            out.append(self.objective)
        out += ["static_deflection", "peak_mount_load"]
        if self.benign_onset:
            out += ["bifurcation", "lyapunov_coefficient"]
        return tuple(dict.fromkeys(out))


def _schema_error(err: ValidationError) -> ModelError:
    errors = err.errors()
    first = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
    loc = _error_loc(OptimizationFile, first)
    field = format_location(loc)
    if first["type"] == "extra_forbidden":
        where = f"in {format_location(loc[:-1])}" if len(loc) > 1 else "at the top level"
        return ModelError(field, first.get("input"), unknown_key_rule(OptimizationFile, loc, where, DOC_PATH))
    if first["type"] == "missing":
        return ModelError(field, None, f"is required (see {DOC_PATH})")
    return ModelError(field, first.get("input"), rule_text(first, mark_at(OptimizationFile, tuple(first["loc"]))))


def optimization_from_dict(data: dict, base_dir: str | os.PathLike[str] = ".", *, source: str | None = None,
                           text: str | None = None) -> Optimization:
    """Validate a parsed optimisation file; the model path is relative to ``base_dir``."""
    if not isinstance(data, dict):
        raise ModelError("(optimization file)", type(data).__name__, "must be a table of keys")
    if "schema_version" not in data:
        raise ModelError("schema_version", None, "is required (schema_version = 1)")
    try:
        doc = OptimizationFile.model_validate(data)
    except ValidationError as err:
        raise _schema_error(err) from None
    if doc.schema_version != 1:
        raise ModelError("schema_version", doc.schema_version, "this impstab reads optimization files with schema_version 1")
    model_path, model_text, base, model = load_base_model(doc.model, base_dir)
    variables: list[Variable] = []
    for i, v in enumerate(doc.variables):
        f = f"variables[{i}]"
        try:
            par = resolve_path(v.path, base)
        except ValueError as exc:
            raise ModelError(f"{f}.path", v.path, str(exc)) from None
        if par.kind != "float":
            raise ModelError(f"{f}.path", v.path, "must lead to a real number (a design variable is continuous)")
        if any(p.path.segments == par.segments for p in variables):
            raise ModelError(f"{f}.path", v.path, "is already a design variable")
        for key in ("low", "high"):
            try:
                par.check(getattr(v, key))
            except ValueError as exc:
                raise ModelError(f"{f}.{key}", getattr(v, key), f"{exc} (the rule of {par.path})") from None
        if not v.low < v.high:
            raise ModelError(f"{f}.high", v.high, f"must be larger than low ({v.low:g})")
        if v.scale == "log" and v.low <= 0:
            raise ModelError(f"{f}.low", v.low, "must be > 0 with scale = 'log'")
        variables.append(Variable(par, float(v.low), float(v.high), v.scale == "log"))
    isolation = settings_from_spec(doc.isolation, (doc.objective.isolation,) if doc.objective.isolation in ISOLATION_OUTPUTS else ())
    named = () if isolation is None else tuple(p.name for p in isolation.at)
    allowed = ("peak_transmissibility",) + named
    if doc.objective.isolation not in allowed:
        raise ModelError("objective.isolation", doc.objective.isolation,
                         f"must be peak_transmissibility or a name of [[isolation.at]] ({', '.join(allowed)})")
    canonical = json.dumps({"opt": doc.model_dump(mode="json"), "model": base}, sort_keys=True, default=str)
    return Optimization(
        name=doc.name or (Path(source).stem if source else "optimization"),
        variables=tuple(variables), objective=doc.objective.isolation,
        margin_min=doc.constraints.margin_min, static_deflection_max=doc.constraints.static_deflection_max,
        peak_mount_load_max=doc.constraints.peak_mount_load_max, isolation=isolation,
        population=doc.optimizer.population, generations=doc.optimizer.generations, seed=doc.optimizer.seed,
        polish=doc.optimizer.polish, polish_evaluations=doc.optimizer.polish_evaluations,
        base_model=base, model_name=model.name, model_text=model_text,
        text=text if text is not None else json.dumps(data, default=str),
        fingerprint=hashlib.sha256(canonical.encode()).hexdigest(), source=source, model_source=str(model_path),
        benign_onset=doc.constraints.benign_onset,
    )


def load_optimization(path: str | os.PathLike[str]) -> Optimization:
    """Read and validate an optimisation file; ModelError (one line) on any bad key."""
    p = Path(path)
    text = read_text(p, "optimization file")
    data = parse_toml(text, p, "optimization file")
    return optimization_from_dict(data, p.parent, source=str(p), text=text)


def bounds(opt: Optimization):
    """The :class:`~impstab.optimize.engine.Variables` of ``opt``."""
    from .engine import Variables

    return Variables(np.array([v.low for v in opt.variables]), np.array([v.high for v in opt.variables]),
                     np.array([v.log for v in opt.variables]))
