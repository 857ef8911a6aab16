"""Model file schema (TOML, ``schema_version = 1``, SI units): pydantic at the file boundary only.

The schema checks types, shapes, signs and finiteness and rejects unknown keys (they are typos).
Physical rules that involve several values (positive-definite inertia, restrained mounts, ...)
are checked when the validated file is assembled into a :class:`~impstab.model.Model`
(:mod:`impstab.model.assemble`).
"""

from __future__ import annotations

from typing import Annotated, Literal, Optional, Union

from pydantic import BaseModel, ConfigDict, Field, field_validator

__all__ = ["ModelFile", "MountSpec", "MountRingSpec"]

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Vec3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
Row6 = Annotated[list[Finite], Field(min_length=6, max_length=6)]
Mat6 = Annotated[list[Row6], Field(min_length=6, max_length=6)]
Row3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
Mat3 = Annotated[list[Row3], Field(min_length=3, max_length=3)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class BodySpec(_Strict):
    mass: Positive
    cg: Vec3 = [0.0, 0.0, 0.0]
    inertia: Union[Vec3, Mat3]


class HullSpec(_Strict):
    radius: Positive
    length: Positive
    center: Vec3 = [0.0, 0.0, 0.0]


class FluidSpec(_Strict):
    model: Literal["none", "baffled-cylinder", "strip", "matrix"] = "none"
    density: Optional[Positive] = None
    sound_speed: Optional[Positive] = None
    added_mass: Optional[Mat6] = None


class MountSpec(_Strict):
    position: Vec3
    axis: Vec3 = [1.0, 0.0, 0.0]
    k_axial: Optional[NonNegative] = None
    k_shear: Optional[NonNegative] = None
    c_axial: NonNegative = 0.0
    c_shear: NonNegative = 0.0
    stiffness: Optional[Mat6] = None
    damping: Optional[Mat6] = None
    rated_force: Optional[Positive] = None      # N, static force rating (isolation design)
    max_deflection: Optional[Positive] = None   # m, static deflection limit
    # nonlinear mount law (axial-shear mounts only; see impstab.model.mount_law)
    k3_axial: Finite = 0.0
    k3_shear: Finite = 0.0
    snubber_clearance: NonNegative = 0.0
    snubber_stiffness: NonNegative = 0.0


class MountRingSpec(_Strict):
    count: Annotated[int, Field(ge=1, le=1000)]
    radius: Positive
    x: Finite = 0.0
    start_angle: Finite = 0.0
    axis: Vec3 = [1.0, 0.0, 0.0]
    k_axial: NonNegative
    k_shear: NonNegative
    c_axial: NonNegative = 0.0
    c_shear: NonNegative = 0.0
    rated_force: Optional[Positive] = None      # N, static force rating (isolation design)
    max_deflection: Optional[Positive] = None   # m, static deflection limit
    # nonlinear mount law (see impstab.model.mount_law)
    k3_axial: Finite = 0.0
    k3_shear: Finite = 0.0
    snubber_clearance: NonNegative = 0.0
    snubber_stiffness: NonNegative = 0.0


class ThrustSpec(_Strict):
    point: Vec3 = [0.0, 0.0, 0.0]
    direction: Vec3 = [1.0, 0.0, 0.0]
    tangency: Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)] = 1.0
    operating: Optional[Positive] = None
    preload_stiffness: bool = True


class PropellerSpec(_Strict):
    polar_inertia: NonNegative = 0.0
    speed: Finite = 0.0
    speed_rpm: Optional[Finite] = None  # rpm, instead of speed (rad/s)
    speed_law: Literal["constant", "sqrt-thrust"] = "constant"


class AnalysisSpec(_Strict):
    thrust_max: Optional[Positive] = None
    linearization: Literal["equilibrium", "classical"] = "equilibrium"


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

    schema_version: int
    name: Optional[str] = None
    body: BodySpec
    hull: Optional[HullSpec] = None
    fluid: Optional[FluidSpec] = None
    mounts: list[MountSpec] = []
    mount_rings: list[MountRingSpec] = []
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
