"""Study file schema (TOML, ``schema_version = 1``): pydantic at the file boundary only.

.. code-block:: toml

    schema_version = 1
    model = "imp.toml"                  # base model, relative to the study file
    outputs = ["critical_thrust", "kind", "frequency_hz", "margin", "undamped_critical_thrust"]

    [[parameters]]
    path = "mount_rings[0].x"           # dotted path into the model file
    values = { start = 0.1, stop = 0.4, num = 60 }            # or a list: values = [0.1, 0.2]

    [[parameters]]
    path = "mount_rings[0].k_shear"
    values = { start = 1e4, stop = 1e6, num = 60, scale = "log" }

    [sampling]                          # optional
    method = "grid"                     # "grid" | "random" | "sobol" | "saltelli"
    # n = 10000; seed = 1               # random / sobol (saltelli: n base samples)

    [execution]                         # optional
    chunk_size = 1024                   # designs per chunk (the unit of work and of resuming)

With ``random`` or ``sobol`` sampling each parameter is drawn from ``values`` (a range without
``num``: uniform, or log-uniform with ``scale = "log"``; a list: each entry equally likely) or
from a ``distribution`` table: ``{kind = "normal", mean, std}``, ``{kind = "lognormal", median,
sigma}``, ``{kind = "truncnormal", mean, std, low, high}``, ``{kind = "uniform" | "loguniform",
low, high}``.

``saltelli`` sampling draws Saltelli's cross-sampled design for Sobol sensitivity indices
(:func:`impstab.studies.sampling.unit_samples`): ``n`` base samples give ``n * (d + 2)``
designs for ``d`` parameters, from the same distributions.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal, Optional, Union

from pydantic import (BaseModel, ConfigDict, Discriminator, Field, StrictBool, StrictFloat, StrictInt, StrictStr, Tag,
                      field_validator)

from ..limits import MAX_TEXT
from ..model.schema import DofName, Finite, Integer, Positive, Text, integer, number

__all__ = ["StudyFile", "ParameterSpec", "RangeSpec", "DistributionSpec", "IsolationSpec", "IsolationPoint", "OUTPUTS",
           "DEFAULT_OUTPUTS", "ISOLATION_OUTPUTS", "RESPONSE_OUTPUTS", "POSTCRITICAL_OUTPUTS"]

#: every output a study can store, with its units and meaning
OUTPUTS = {
    "critical_thrust": ("N", "critical thrust (first loss of stability from T = 0)"),
    "kind": ("", "kind of instability at the critical thrust"),
    "frequency_hz": ("Hz", "frequency at onset"),
    "omega": ("rad/s", "angular frequency at onset"),
    "margin": ("1", "critical thrust / operating thrust"),
    "undamped_critical_thrust": ("N", "critical thrust with every damper removed"),
    "undamped_kind": ("", "kind of instability with every damper removed"),
    "practical_critical_thrust": ("N", "first thrust at which the least damping ratio falls to "
                                  "analysis.min_damping_ratio (or min_log_decrement); NaN without one"),
    "practical_margin": ("1", "practical critical thrust / operating thrust"),
    "modes": ("", "dofs with at least 5 % of the kinetic energy of the critical mode"),
    "thrust_max": ("N", "upper end of the critical-thrust search"),
    "operating_thrust": ("N", "operating thrust"),
    "lyapunov_coefficient": ("1/s", "first Lyapunov coefficient l1 of the Hopf point at the onset (Kuznetsov's "
                                    "normalisation, q^H q = 1 on the 12 SI states; < 0 benign, > 0 dangerous)"),
    "bifurcation": ("", "supercritical, subcritical, degenerate or none (no onset up to thrust_max)"),
    "fold_thrust": ("N", "lowest thrust of a fold of limit cycles on the computed branch (NaN: no fold)"),
    "peak_transmissibility": ("1", "largest force transmissibility |F_hull| / |F_in| over isolation.range_hz (N/N; N/(N m) for a moment input)"),
    "peak_frequency_hz": ("Hz", "frequency of the peak transmissibility"),
    "static_deflection": ("m", "largest static deflection |d| of a mount at the isolation thrust"),
    "peak_mount_load": ("N", "largest static force |F| of a mount on the hull at the isolation thrust"),
}
#: outputs that need the post-critical analysis of each design (impstab.postcritical)
POSTCRITICAL_OUTPUTS = ("lyapunov_coefficient", "bifurcation", "fold_thrust")
#: the outputs computed by the isolation evaluation (beside the named [[isolation.at]] outputs)
ISOLATION_OUTPUTS = ("peak_transmissibility", "peak_frequency_hz", "static_deflection", "peak_mount_load")
#: the outputs that need the forced response (a frequency grid)
RESPONSE_OUTPUTS = ("peak_transmissibility", "peak_frequency_hz")
DEFAULT_OUTPUTS = ("critical_thrust", "kind", "frequency_hz", "margin", "undamped_critical_thrust")

#: one value of a list of values: checked against the rule of its parameter's field later
Scalar = Union[StrictBool, StrictInt, StrictFloat, Annotated[StrictStr, Field(max_length=MAX_TEXT)]]
#: most values of one parameter (a list, or ``num`` of a range)
MAX_VALUES = 10_000_000


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class RangeSpec(_Strict):
    """``start`` to ``stop``: ``num`` points for a grid, a uniform range for random sampling."""

    start: Finite
    stop: Finite
    num: Optional[integer(1, MAX_VALUES, "grid values of one parameter")] = None  # type: ignore[valid-type]
    scale: Literal["linear", "log"] = "linear"


class DistributionSpec(_Strict):
    """A probability distribution of one parameter (random and sobol sampling)."""

    kind: Literal["uniform", "loguniform", "normal", "lognormal", "truncnormal"]
    low: Optional[Finite] = None
    high: Optional[Finite] = None
    mean: Optional[Finite] = None
    std: Optional[Positive] = None
    median: Optional[Positive] = None
    sigma: Optional[Positive] = None


#: labels of the two shapes of ``values`` (left out of the field names in messages)
VALUES_TAGS = ("range", "value list")


def _values_shape(value: Any) -> str:
    return "range" if isinstance(value, (dict, RangeSpec)) else "value list"


ValuesSpec = Annotated[
    Union[Annotated[RangeSpec, Tag("range")],
          Annotated[list[Scalar], Field(min_length=1, max_length=MAX_VALUES), Tag("value list")]],
    Discriminator(_values_shape),
]


class ParameterSpec(_Strict):
    path: Text
    values: Optional[ValuesSpec] = None
    distribution: Optional[DistributionSpec] = None


class SamplingSpec(_Strict):
    method: Literal["grid", "random", "sobol", "saltelli"] = "grid"
    n: Optional[integer(1, 100_000_000, "samples (base samples with saltelli)")] = None  # type: ignore[valid-type]
    seed: integer(0, 2**63 - 1, "a seed") = 0  # type: ignore[valid-type]


class ExecutionSpec(_Strict):
    chunk_size: integer(1, 1_000_000, "designs per chunk") = 1024  # type: ignore[valid-type]


Frequency = number("frequency")
#: an output name: a lower-case identifier
OutputName = Annotated[StrictStr, Field(pattern=r"^[a-z][a-z0-9_]{0,62}$")]


class IsolationPoint(_Strict):
    """A named isolation output: the transmissibility at one frequency, or its peak in a band."""

    name: OutputName
    frequency_hz: Optional[Frequency] = None
    band_hz: Optional[Annotated[list[Frequency], Field(min_length=2, max_length=2)]] = None


class IsolationSpec(_Strict):
    """How the isolation outputs of every design are evaluated."""

    input: Optional[DofName] = None
    thrust: Optional[number("thrust_or_zero")] = None  # type: ignore[valid-type]
    range_hz: Optional[Annotated[list[Frequency], Field(min_length=2, max_length=2)]] = None
    points: integer(2, 100_000, "frequencies of the isolation grid") = 400  # type: ignore[valid-type]
    at: Annotated[list[IsolationPoint], Field(max_length=64)] = []


class StudyFile(_Strict):
    """The whole study file."""

    schema_version: Integer
    name: Optional[Text] = None
    model: Text
    outputs: Annotated[list[Literal[tuple(OUTPUTS)]], Field(min_length=1)] = list(DEFAULT_OUTPUTS)  # type: ignore[valid-type]
    parameters: Annotated[list[ParameterSpec], Field(min_length=1, max_length=32)]
    sampling: SamplingSpec = SamplingSpec()
    execution: ExecutionSpec = ExecutionSpec()
    isolation: Optional[IsolationSpec] = None

    @field_validator("schema_version")
    @classmethod
    def _version(cls, v: int) -> int:
        if v != 1:
            raise ValueError("this impstab reads study files with schema_version 1")
        return v

    @field_validator("outputs")
    @classmethod
    def _unique(cls, v: list[str]) -> list[str]:
        if len(set(v)) != len(v):
            raise ValueError("lists an output twice")
        return v
