"""Model file schema (TOML, ``schema_version = 1``, SI units): pydantic at the file boundary only.

The schema checks types, shapes, ranges and finiteness and rejects unknown keys (they are typos).
Types are strict: a number is an integer or a float literal (never ``true`` or ``"100"``), a flag
is ``true`` or ``false`` (never ``1`` or ``"off"``), an integer is an integer literal (``3``, not
``3.0``). Every magnitude has the physical range of :data:`impstab.limits.RANGES`, carried as the
``minimum`` / ``maximum`` of its JSON schema (so the model-file reference shows it) and checked
with a message that names the range and its unit.

Physical rules that involve several values (positive-definite inertia, restrained mounts, ...)
are checked when the validated file is assembled into a :class:`~impstab.model.Model`
(:mod:`impstab.model.assemble`).
"""

from __future__ import annotations

import types
import typing
from typing import Annotated, Any, Literal, Optional, Union

from pydantic import BaseModel, ConfigDict, Discriminator, Field, Tag, field_validator

from ..limits import MAX_MOUNTS, MAX_TEXT, RANGES, as_boolean, as_integer

__all__ = ["ModelFile", "MountSpec", "MountRingSpec", "number", "integer", "mark_at", "RangeMark", "UNION_TAGS"]


class RangeMark:
    """Marks a number of the schema with its range of :data:`impstab.limits.RANGES`.

    Validation itself runs in pydantic-core (strict float, ``ge``/``le``, no inf/nan: no Python
    call per number); the mark only words a failure: :func:`impstab.model.assemble.rule_text`
    finds it at the error's location and names the range, its unit and what it is.
    """

    __slots__ = ("kind",)

    def __init__(self, kind: str) -> None:
        self.kind = kind

    def rule(self, value: object) -> str:
        try:
            RANGES[self.kind].validate(value)
        except ValueError as exc:
            return str(exc)
        return RANGES[self.kind].rule()


class IntegerMark:
    """Marks an integer of the schema with its range and meaning (see :class:`RangeMark`)."""

    __slots__ = ("low", "high", "what")

    def __init__(self, low: int | None = None, high: int | None = None, what: str = "") -> None:
        self.low, self.high, self.what = low, high, what

    def rule(self, value: object) -> str:
        try:
            n = as_integer(value)
        except ValueError as exc:
            return str(exc)
        if self.low is not None and self.high is not None:
            return f"must be an integer between {self.low} and {self.high} ({self.what})"
        return f"must be an integer (not {n})"


class FlagMark:
    """Marks a flag of the schema (see :class:`RangeMark`)."""

    __slots__ = ()

    def rule(self, value: object) -> str:
        try:
            as_boolean(value)
        except ValueError as exc:
            return str(exc)
        return "must be true or false"


def number(kind: str) -> Any:
    """A strict float in the range ``RANGES[kind]`` (integers are numbers; booleans, strings are not)."""
    r = RANGES[kind]
    return Annotated[float, Field(ge=r.low, le=r.high, strict=True, allow_inf_nan=False), RangeMark(kind)]


# -- the type aliases every key uses (strict, ranged) ------------------------------------------
Finite = number("number")                 # any finite number within +-1e15
Positive = number("positive")             # 1e-12 ... 1e15
NonNegative = number("nonnegative")       # 0 ... 1e15
Integer = Annotated[int, Field(strict=True), IntegerMark()]  # 3, never 3.0 or true
Flag = Annotated[bool, Field(strict=True), FlagMark()]
Text = Annotated[str, Field(strict=True, max_length=MAX_TEXT)]
StrictFloat, StrictInt, StrictBool = Finite, Integer, Flag



def integer(low: int, high: int, what: str) -> Any:
    """A strict integer in ``[low, high]`` (``3.0``, ``true`` and ``"3"`` are not integers)."""
    return Annotated[int, Field(ge=low, le=high, strict=True), IntegerMark(low, high, what)]


def mark_at(root: type[BaseModel], loc: tuple) -> Any:
    """The :class:`RangeMark`, :class:`IntegerMark` or :class:`FlagMark` of the value at ``loc``
    (a pydantic error location: keys, list indices, union labels and tags), or None."""
    tp: Any = root
    for part in loc:
        core, _ = _strip(tp)
        if isinstance(part, int):
            core = _list_branch(core)
            if typing.get_origin(core) is not list:
                return None
            tp = typing.get_args(core)[0]
        elif isinstance(core, type) and issubclass(core, BaseModel):
            info = core.model_fields.get(part)
            if info is None:
                return None
            tp = Annotated[(info.annotation, *info.metadata)] if info.metadata else info.annotation
        elif typing.get_origin(core) in (Union, types.UnionType):
            tagged = [a for a in typing.get_args(core) if any(isinstance(m, Tag) and m.tag == part for m in _strip(a)[1])]
            if tagged:
                tp = tagged[0]
            # else: a label pydantic inserts for a union branch ("list[float]"): the index that
            # follows picks the list branch
        # else: a label on a plain value (a validator's name): nothing to descend into
    _, meta = _strip(tp)
    return next((m for m in meta if isinstance(m, (RangeMark, IntegerMark, FlagMark))), None)


def _strip(tp: Any) -> tuple[Any, list]:
    """Remove ``Optional`` and ``Annotated`` wrappers; returns the core type and the metadata."""
    meta: list = []
    while True:
        origin = typing.get_origin(tp)
        if origin is Annotated:
            meta.extend(tp.__metadata__)
            tp = tp.__origin__
        elif origin in (Union, types.UnionType):
            args = [a for a in typing.get_args(tp) if a is not type(None)]
            if len(args) != 1:
                return tp, meta
            tp = args[0]
        else:
            return tp, meta


def _list_branch(core: Any) -> Any:
    if typing.get_origin(core) in (Union, types.UnionType):
        for arg in typing.get_args(core):
            inner, _ = _strip(arg)
            if typing.get_origin(inner) is list:
                return inner
    return core


# physical magnitudes (SI units; ranges and reasons in docs/limits.md)
Mass = number("mass")                     # kg
Moment = number("moment_of_inertia")      # kg m^2, a principal moment
InertiaEntry = number("inertia_entry")    # kg m^2, an entry of the inertia tensor
PolarInertia = number("polar_inertia")    # kg m^2
Coordinate = number("coordinate")         # m, a point in the body frame
Size = number("size")                     # m, a radius or a length (> 0)
Component = number("direction")           # a component of a direction or axis vector
Angle = number("angle")                   # degrees
Stiffness = number("stiffness")           # N/m
Damping = number("damping")               # N s/m
Thrust = number("thrust")                 # N
Fraction = number("fraction")             # 0 ... 1
SpinSpeed = number("spin_speed")          # rad/s
SpinSpeedRpm = number("spin_speed_rpm")   # rpm
Density = number("density")               # kg/m^3
SoundSpeed = number("sound_speed")        # m/s

Vec3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
Point3 = Annotated[list[Coordinate], Field(min_length=3, max_length=3)]
Direction3 = Annotated[list[Component], Field(min_length=3, max_length=3)]
Row6 = Annotated[list[Finite], Field(min_length=6, max_length=6)]
Mat6 = Annotated[list[Row6], Field(min_length=6, max_length=6)]
Row3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
Mat3 = Annotated[list[Row3], Field(min_length=3, max_length=3)]


def _matrix6(kind: str) -> Any:
    row = Annotated[list[number(kind)], Field(min_length=6, max_length=6)]  # type: ignore[misc]
    return Annotated[list[row], Field(min_length=6, max_length=6)]


Stiffness6 = _matrix6("stiffness_entry")
Damping6 = _matrix6("damping_entry")
AddedMass6 = _matrix6("added_mass_entry")
Moments3 = Annotated[list[Moment], Field(min_length=3, max_length=3)]
Tensor3 = Annotated[list[Annotated[list[InertiaEntry], Field(min_length=3, max_length=3)]], Field(min_length=3, max_length=3)]

#: labels of the branches of a union of list shapes (left out of the field names in messages)
UNION_TAGS = ("principal moments", "tensor")


def _inertia_shape(value: Any) -> str:
    if isinstance(value, list) and value and all(isinstance(row, list) for row in value):
        return "tensor"
    return "principal moments"


Inertia = Annotated[
    Union[Annotated[Moments3, Tag("principal moments")], Annotated[Tensor3, Tag("tensor")]],
    Discriminator(_inertia_shape),
]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class BodySpec(_Strict):
    mass: Mass
    cg: Point3 = [0.0, 0.0, 0.0]
    inertia: Inertia


class HullSpec(_Strict):
    radius: Size
    length: Size
    center: Point3 = [0.0, 0.0, 0.0]


class FluidSpec(_Strict):
    model: Literal["none", "baffled-cylinder", "strip", "matrix"] = "none"
    density: Optional[Density] = None
    sound_speed: Optional[SoundSpeed] = None
    added_mass: Optional[AddedMass6] = None


# -- viscoelastic mounts (impstab.model.viscoelastic) -------------------------------------------
Frequencies = Annotated[list[number("frequency")], Field(min_length=1, max_length=10000)]
PronyTerm = Annotated[list[Finite], Field(min_length=2, max_length=2)]


class ViscoelasticSpec(_Strict):
    """``[mounts.viscoelastic]``: a frequency-dependent law on the static k_axial / k_shear."""

    law: Literal["standard-linear-solid", "prony", "fractional-zener", "table"]
    stiffening: Optional[number("stiffening")] = None            # k(inf) / k(0) > 1
    relaxation_time: Optional[number("relaxation_time")] = None  # s
    alpha: Optional[number("fraction")] = None                   # 0 < alpha < 1
    terms: Optional[Annotated[list[PronyTerm], Field(min_length=1, max_length=100)]] = None  # [[g_j, tau_j], ...]
    frequency_hz: Optional[Frequencies] = None                   # Hz, strictly increasing (table)
    storage_ratio: Optional[Annotated[list[number("storage_ratio")], Field(min_length=1, max_length=10000)]] = None
    loss_factor: Optional[Annotated[list[number("loss_factor")], Field(min_length=1, max_length=10000)]] = None
    fit_band_hz: Optional[Annotated[list[number("frequency")], Field(min_length=2, max_length=2)]] = None
    fit_terms: Optional[integer(1, 30, "Prony terms of the fit")] = None  # type: ignore[valid-type]


# -- beam mounts ([mounts.beam], impstab.model.beam) -------------------------------------------
class BeamSpec(_Strict):
    """A Timoshenko beam along the mount axis, hull end clamped, body end at the mount position."""

    length: Size                                   # m, free length
    outer_diameter: Size                           # m, circular section
    inner_diameter: number("bore") = 0.0           # m, 0: solid
    youngs_modulus: number("modulus")              # Pa
    shear_modulus: number("modulus")               # Pa
    shear_coefficient: Optional[number("shear_coefficient")] = None  # default: Cowper's value
    density: number("material_density") = 0.0     # kg/m^3, > 0: the mount has its own mass
# -- end of beam mounts --------------------------------------------------------------------------


class MountSpec(_Strict):
    position: Point3
    axis: Direction3 = [1.0, 0.0, 0.0]
    k_axial: Optional[Stiffness] = None
    k_shear: Optional[Stiffness] = None
    c_axial: Damping = 0.0
    c_shear: Damping = 0.0
    stiffness: Optional[Stiffness6] = None
    damping: Optional[Damping6] = None
    rated_force: Optional[Positive] = None      # N, static force rating (isolation design)
    max_deflection: Optional[Positive] = None   # m, static deflection limit
    # nonlinear mount law (axial-shear mounts only; see impstab.model.mount_law)
    k3_axial: number("cubic_stiffness") = 0.0
    k3_shear: number("cubic_stiffness") = 0.0
    snubber_clearance: number("clearance") = 0.0
    snubber_stiffness: number("stiffness") = 0.0
    # frequency-dependent mount law (impstab.model.viscoelastic)
    viscoelastic: Optional[ViscoelasticSpec] = None
    beam: Optional[BeamSpec] = None             # a Timoshenko beam instead of k_axial/k_shear/stiffness


class MountRingSpec(_Strict):
    count: integer(1, MAX_MOUNTS, "mounts on the ring")  # type: ignore[valid-type]
    radius: Size
    x: Coordinate = 0.0
    start_angle: Angle = 0.0
    axis: Direction3 = [1.0, 0.0, 0.0]
    k_axial: Stiffness
    k_shear: Stiffness
    c_axial: Damping = 0.0
    c_shear: Damping = 0.0
    rated_force: Optional[Positive] = None      # N, static force rating (isolation design)
    max_deflection: Optional[Positive] = None   # m, static deflection limit
    # nonlinear mount law (see impstab.model.mount_law)
    k3_axial: number("cubic_stiffness") = 0.0
    k3_shear: number("cubic_stiffness") = 0.0
    snubber_clearance: number("clearance") = 0.0
    snubber_stiffness: number("stiffness") = 0.0
    # frequency-dependent mount law (impstab.model.viscoelastic)
    viscoelastic: Optional[ViscoelasticSpec] = None


class ThrustSpec(_Strict):
    point: Point3 = [0.0, 0.0, 0.0]
    direction: Direction3 = [1.0, 0.0, 0.0]
    tangency: Fraction = 1.0
    operating: Optional[Thrust] = None
    preload_stiffness: Flag = True


class PropellerSpec(_Strict):
    polar_inertia: PolarInertia = 0.0
    speed: SpinSpeed = 0.0
    speed_rpm: Optional[SpinSpeedRpm] = None  # rpm, instead of speed (rad/s)
    speed_law: Literal["constant", "sqrt-thrust"] = "constant"


class AnalysisSpec(_Strict):
    thrust_max: Optional[Thrust] = None
    linearization: Literal["equilibrium", "classical"] = "equilibrium"
    min_damping_ratio: Optional[number("damping_ratio")] = None  # 1, practical criterion
    min_log_decrement: Optional[number("log_decrement")] = None  # 1, practical criterion


# -- forced response and isolation (docs/isolation.md) ------------------------------------------
DofName = Literal["surge", "sway", "heave", "roll", "pitch", "yaw"]
Count = Annotated[int, Field(ge=1, le=1000, strict=True)]
Table = Annotated[list[NonNegative], Field(min_length=1, max_length=100000)]
Rows6 = Annotated[list[Row6], Field(min_length=1, max_length=100000)]
Values = Annotated[list[Finite], Field(max_length=100000)]


class UnbalanceSpec(_Strict):
    mass: Positive                      # kg, unbalance mass m
    eccentricity: Positive              # m, its radius e: force m e Omega^2 at shaft rate
    point: Optional[Vec3] = None        # m, body frame; default thrust.point
    phase_deg: Finite = 0.0             # deg, angle at t = 0 in the plane normal to the thrust axis


class BladeRateSpec(_Strict):
    blades: Count                       # blade count Z: frequency harmonic * Z * Omega / 2 pi
    harmonic: Count = 1
    amplitude: Row6                     # N, N m: force and moment at `point`, body axes
    phase_deg: Row6 = [0.0] * 6         # deg, per component
    point: Optional[Vec3] = None        # m, body frame; default thrust.point


class SpectrumSpec(_Strict):
    frequency_hz: Table                 # Hz, one harmonic line per row
    amplitude: Rows6                    # N, N m per row: force and moment at `point`, body axes
    phase_deg: Optional[Rows6] = None   # deg per row and component; default 0
    point: Vec3 = [0.0, 0.0, 0.0]       # m, body frame; default A


class ExcitationSpec(_Strict):
    input: DofName = "sway"             # dof of the unit load of `impstab response` (its --input)
    unbalance: list[UnbalanceSpec] = []
    blade_rate: list[BladeRateSpec] = []
    spectrum: Optional[SpectrumSpec] = None


class FoundationSpec(_Strict):
    model: Literal["rigid", "lumped", "mobility-table", "impedance-table"] = "rigid"
    mass: NonNegative = 0.0             # kg      (lumped: Z = damping + i (w mass - stiffness / w))
    stiffness: NonNegative = 0.0        # N/m     (lumped)
    damping: NonNegative = 0.0          # N s/m   (lumped)
    frequency_hz: Optional[Table] = None            # Hz (tables), strictly increasing
    mobility_real: Optional[Values] = None    # m/(N s) (mobility-table)
    mobility_imag: Optional[Values] = None
    impedance_real: Optional[Values] = None   # N s/m (impedance-table)
    impedance_imag: Optional[Values] = None


class ModelFile(_Strict):
    """The whole model file."""

    schema_version: Annotated[Integer, Field(json_schema_extra={"minimum": 1, "maximum": 1})]
    name: Optional[Text] = None
    body: BodySpec
    hull: Optional[HullSpec] = None
    fluid: Optional[FluidSpec] = None
    mounts: Annotated[list[MountSpec], Field(max_length=MAX_MOUNTS)] = []
    mount_rings: Annotated[list[MountRingSpec], Field(max_length=MAX_MOUNTS)] = []
    thrust: ThrustSpec = ThrustSpec()
    propeller: Optional[PropellerSpec] = None
    analysis: AnalysisSpec = AnalysisSpec()
    excitation: Optional[ExcitationSpec] = None   # forced response: loads (docs/isolation.md)
    foundation: Optional[FoundationSpec] = None   # forced response: compliant hull at the mounts

    @field_validator("schema_version")
    @classmethod
    def _version(cls, v: int) -> int:
        if v != 1:
            raise ValueError("this impstab reads schema_version 1")
        return v
