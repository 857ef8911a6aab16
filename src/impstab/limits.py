"""Physical ranges of every input magnitude and the limits on work and memory.

Each number a model file, a study file or a command line gives has a range that no real
propulsor model leaves and inside which every computation of impstab stays finite (no
overflow to infinity, no underflow to zero, no division by zero). The ranges are enforced at
the boundary, where the value is read, with a one-line :class:`~impstab.errors.ModelError`
naming the field, the value and the range; the model-file schema carries them as its
``minimum`` / ``maximum`` constraints, so the model-file reference lists them.

Work and memory are estimated before they are spent (input file size, quadrature nodes of the
baffled-cylinder coefficients, time steps and output size of a simulation, frequency counts,
study sizes) and refused beyond the limits below, naming the option that sets them.
``docs/limits.md`` holds the same table with the reasons.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import ModelError

__all__ = [
    "Range", "RANGES", "as_number", "as_integer", "as_boolean", "check_number", "check_integer",
    "refuse_work",
    "MAX_FILE_BYTES", "MAX_NESTING", "MAX_LIST_ITEMS", "MAX_TEXT", "MAX_MOUNTS", "MAX_QUADRATURE_NODES",
    "MAX_SWEEP_NODES", "MAX_FREQUENCIES", "MAX_STEPS", "MAX_OUTPUT_BYTES", "MAX_THRUSTS",
    "MAX_LOCUS_STEPS", "MAX_STUDY_BYTES", "LONG_FACTOR", "MIN_DIRECTION",
]


def _g(x: float) -> str:
    return f"{x:g}"


@dataclass(frozen=True)
class Range:
    """A closed interval ``[low, high]`` of one kind of magnitude.

    Attributes
    ----------
    low, high : float
        Ends of the range (in ``unit``).
    unit : str
        SI unit, as written in the documentation (``""`` for a pure number).
    what : str
        The kind of magnitude, in words (``"a mass"``).
    """

    low: float
    high: float
    unit: str
    what: str

    @property
    def text(self) -> str:
        """``"between 0.001 and 1e+07 kg"``."""
        unit = f" {self.unit}" if self.unit else ""
        return f"between {_g(self.low)} and {_g(self.high)}{unit}"

    def rule(self) -> str:
        """The rule in words, for error messages."""
        return f"must be {self.text} ({self.what})"

    def validate(self, value: object) -> float:
        """``value`` as a float, or ValueError with the rule (a boolean or a string is not a number)."""
        x = as_number(value)
        if not (self.low <= x <= self.high):
            raise ValueError(self.rule())
        return x


def as_number(value: object) -> float:
    """A real number as a float; ValueError for booleans, strings and non-finite values.

    Integers are numbers (``mass = 100`` is 100.0 kg); ``true``, ``"100"`` and ``nan`` are not.
    """
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        raise ValueError("must be a number, not a boolean")
    if isinstance(value, str):
        raise ValueError("must be a number, not a string")
    if isinstance(value, int):
        if abs(value) > 1e300:
            raise ValueError("must be a finite number of sensible size")
        return float(value)
    try:
        import numbers

        if not isinstance(value, numbers.Real):
            raise TypeError
        x = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"must be a number, not {_kind(value)}") from None
    if not math.isfinite(x):
        raise ValueError("must be a finite number")
    return x


def as_integer(value: object) -> int:
    """An integer; ValueError for booleans, strings and floats (``3.0`` is not an integer)."""
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        raise ValueError("must be an integer, not a boolean")
    if isinstance(value, str):
        raise ValueError("must be an integer, not a string")
    import numbers

    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, float):
        hint = f" (write {int(value)}, not {value!r})" if math.isfinite(value) and value.is_integer() else ""
        raise ValueError(f"must be an integer{hint}")
    raise ValueError(f"must be an integer, not {_kind(value)}")


def as_boolean(value: object) -> bool:
    """A boolean (``true`` or ``false``); ValueError for numbers and strings."""
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        return bool(value)
    kind = "a string" if isinstance(value, str) else _kind(value)
    raise ValueError(f"must be true or false, not {kind}")


def _kind(value: object) -> str:
    if isinstance(value, (list, tuple)):
        return "a list"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, (int, float)):
        return "a number"
    return f"a {type(value).__name__}"


#: the range of each kind of magnitude (SI units); see ``docs/limits.md`` for the reasons
RANGES: dict[str, Range] = {
    "number": Range(-1e15, 1e15, "", "a finite number"),
    "positive": Range(1e-12, 1e15, "", "a positive number"),
    "nonnegative": Range(0.0, 1e15, "", "a number >= 0"),
    "mass": Range(1e-3, 1e7, "kg", "a propulsor mass"),
    "moment_of_inertia": Range(1e-9, 1e12, "kg m^2", "a principal moment of inertia"),
    "inertia_entry": Range(-1e12, 1e12, "kg m^2", "an inertia tensor entry"),
    "polar_inertia": Range(0.0, 1e12, "kg m^2", "a rotor polar inertia"),
    "coordinate": Range(-1e3, 1e3, "m", "a position in the body frame"),
    "size": Range(1e-4, 1e3, "m", "a radius or a length"),
    "direction": Range(-1e6, 1e6, "", "a direction component"),
    "angle": Range(-360.0, 360.0, "deg", "an angle in degrees"),
    "stiffness": Range(0.0, 1e13, "N/m", "a mount stiffness"),
    "cubic_stiffness": Range(-1e20, 1e20, "N/m^3", "a cubic mount stiffness"),
    "clearance": Range(0.0, 10.0, "m", "a snubber clearance"),
    # beam mounts ([mounts.beam])
    "bore": Range(0.0, 1e3, "m", "an inner diameter (0: solid)"),
    "modulus": Range(1e3, 1e13, "Pa", "an elastic modulus"),
    "shear_coefficient": Range(1e-3, 1.0, "", "a Timoshenko shear coefficient"),
    "material_density": Range(0.0, 1e5, "kg/m^3", "a material density (0: massless)"),
    "stiffness_entry": Range(-1e13, 1e13, "N/m, N or N m/rad", "a 6x6 stiffness entry"),
    "damping": Range(0.0, 1e11, "N s/m", "a mount damping"),
    "damping_entry": Range(-1e11, 1e11, "N s/m, N s or N m s/rad", "a 6x6 damping entry"),
    "added_mass_entry": Range(-1e12, 1e12, "kg, kg m or kg m^2", "a 6x6 added-mass entry"),
    "thrust": Range(1e-3, 1e9, "N", "a thrust"),
    "thrust_or_zero": Range(0.0, 1e9, "N", "a thrust"),
    "fraction": Range(0.0, 1.0, "", "a fraction"),
    "damping_ratio": Range(0.0, 0.9, "", "a damping-ratio threshold"),
    "log_decrement": Range(0.0, 12.0, "", "a logarithmic-decrement threshold"),
    "spin_speed": Range(-1e5, 1e5, "rad/s", "a propeller speed"),
    "spin_speed_rpm": Range(-1e6, 1e6, "rpm", "a propeller speed"),
    "density": Range(1e-3, 1e5, "kg/m^3", "a fluid density"),
    "sound_speed": Range(1.0, 1e5, "m/s", "a speed of sound"),
    "frequency": Range(0.0, 1e6, "Hz", "a frequency"),
    "duration": Range(1e-6, 1e7, "s", "a simulated time"),
    "time_step": Range(1e-12, 1e4, "s", "a time step or sampling interval"),
    "tolerance": Range(1e-15, 1.0, "", "a relative tolerance"),
    "dpi": Range(10.0, 1200.0, "dots per inch", "a figure resolution"),
    "displacement": Range(-1e3, 1e3, "m or rad", "an initial displacement"),
    "velocity": Range(-1e6, 1e6, "m/s or rad/s", "an initial velocity"),
    # viscoelastic mounts (impstab.model.viscoelastic)
    "stiffening": Range(1.0, 1e6, "", "a high-frequency to static stiffness ratio"),
    "relaxation_time": Range(1e-9, 1e6, "s", "a relaxation time"),
    "prony_weight": Range(0.0, 1e6, "", "a Prony weight g_j"),
    "storage_ratio": Range(1e-3, 1e6, "", "a storage-stiffness ratio k'(f) / k0"),
    "loss_factor": Range(0.0, 10.0, "", "a loss factor"),
}

#: a direction or mount axis shorter than this (in the units the user wrote) is "zero"
MIN_DIRECTION = 1e-6

#: largest model or study file read (bytes): the largest realistic model, 1000 mounts with full
#: 6x6 matrices, is about 1 MB; parsing 4 MiB of TOML numbers takes about 2 s
MAX_FILE_BYTES = 4 * 1024 * 1024
#: deepest nesting of tables and arrays in a model or study file (a model needs 5)
MAX_NESTING = 32
#: most items of one array in a model file (a study's list of values may hold more)
MAX_LIST_ITEMS = 100_000
#: longest string value (a name, a path), in characters
MAX_TEXT = 4096
#: most mounts in one model (mounts plus every ring's count)
MAX_MOUNTS = 1000
#: most quadrature nodes of one baffled-cylinder evaluation (production layout; about 0.4 s and
#: 100 MB; the error control refines it at most 4x)
MAX_QUADRATURE_NODES = 1_000_000
#: most quadrature nodes of a whole ``added-mass --frequencies`` sweep (about a minute)
MAX_SWEEP_NODES = 100_000_000
#: most frequencies of ``added-mass --frequencies``
MAX_FREQUENCIES = 10_000
#: most time steps of ``simulate`` over all its thrusts (about 100 s of compiled stepping)
MAX_STEPS = 100_000_000
#: largest memory for the stored time histories of ``simulate`` (bytes)
MAX_OUTPUT_BYTES = 1024**3
#: most thrusts of ``simulate --thrusts``
MAX_THRUSTS = 100
#: most thrust intervals of ``locus --steps``
MAX_LOCUS_STEPS = 100_000
#: largest estimated size of a study's results in memory (bytes)
MAX_STUDY_BYTES = 2 * 1024**3
#: ``--allow-long`` multiplies the work limits (not the memory limits) by this
LONG_FACTOR = 1000


def check_number(field: str, value: object, kind: str) -> float:
    """``value`` as a float within ``RANGES[kind]``, or a ModelError naming ``field``."""
    try:
        return RANGES[kind].validate(value)
    except ValueError as exc:
        raise ModelError(field, value, str(exc)) from None


def check_integer(field: str, value: object, low: int, high: int, what: str = "") -> int:
    """``value`` as an int in ``[low, high]``, or a ModelError naming ``field``."""
    try:
        n = as_integer(value)
    except ValueError as exc:
        raise ModelError(field, value, str(exc)) from None
    if not (low <= n <= high):
        raise ModelError(field, value, f"must be an integer between {low} and {high}{f' ({what})' if what else ''}")
    return n


def describe_count(n: float) -> str:
    """A large count in plain words: ``3.2e+09``."""
    return f"{n:.3g}" if n >= 1e6 else str(int(n))


def refuse_work(field: str, value: object, needed: float, limit: float, what: str, hint: str = "") -> None:
    """ModelError when the estimated ``needed`` amount of ``what`` exceeds ``limit``."""
    if needed > limit:
        extra = f"; {hint}" if hint else ""
        raise ModelError(field, value, f"would need {describe_count(needed)} {what} (limit {describe_count(limit)}){extra}")
