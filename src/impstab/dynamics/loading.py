"""Thrust histories and initial perturbations of a time simulation.

The thrust may be constant (a number), a :class:`Ramp`, a :class:`Step` or any Python callable
``f(t) -> T`` (s -> N). The run starts from the nonlinear static equilibrium at ``T(0)`` plus a
:class:`Perturbation` (displacement and velocity per dof).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError
from ..model.model import DOF_NAMES

__all__ = ["ThrustHistory", "Constant", "Ramp", "Step", "UserThrust", "as_thrust_history", "Perturbation"]

Array = NDArray[np.float64]


class ThrustHistory:
    """Thrust ``T(t)`` (N) as a function of time (s); ``__call__`` accepts arrays."""

    def __call__(self, t):  # pragma: no cover - abstract
        raise NotImplementedError

    def describe(self) -> str:
        """One line for result attributes."""
        return repr(self)

    @property
    def is_constant(self) -> bool:
        return False


@dataclass(frozen=True)
class Constant(ThrustHistory):
    """Constant thrust ``value`` (N)."""

    value: float

    def __call__(self, t):
        return np.full(np.shape(t), float(self.value)) if np.ndim(t) else float(self.value)

    def describe(self) -> str:
        return f"constant {self.value:.10g} N"

    @property
    def is_constant(self) -> bool:
        return True


@dataclass(frozen=True)
class Ramp(ThrustHistory):
    """``start`` (N) until ``delay`` (s), then linear to ``end`` over ``duration`` (s), then ``end``."""

    start: float
    end: float
    duration: float
    delay: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.duration) and self.duration > 0):
            raise ModelError("thrust.duration", self.duration, "ramp duration must be a finite number > 0 s")

    def __call__(self, t):
        s = np.clip((np.asarray(t, dtype=float) - self.delay) / self.duration, 0.0, 1.0)
        out = self.start + (self.end - self.start) * s
        return out if np.ndim(out) else float(out)

    def describe(self) -> str:
        return (f"ramp {self.start:.10g} N -> {self.end:.10g} N over {self.duration:.6g} s "
                f"after {self.delay:.6g} s")


@dataclass(frozen=True)
class Step(ThrustHistory):
    """``before`` (N) for ``t < time`` (s), ``after`` (N) from then on."""

    before: float
    after: float
    time: float

    def __call__(self, t):
        out = np.where(np.asarray(t, dtype=float) < self.time, self.before, self.after)
        return out if np.ndim(out) else float(out)

    def describe(self) -> str:
        return f"step {self.before:.10g} N -> {self.after:.10g} N at {self.time:.6g} s"


@dataclass(frozen=True)
class UserThrust(ThrustHistory):
    """A user function ``f(t) -> T``; evaluated on arrays when it accepts them, else point by point."""

    function: Callable
    name: str = field(default="")

    def __call__(self, t):
        if np.ndim(t) == 0:
            return float(self.function(float(t)))
        t = np.asarray(t, dtype=float)
        try:
            with np.errstate(all="ignore"):
                out = np.asarray(self.function(t), dtype=float)
            if out.shape == t.shape:
                return out
            if out.ndim == 0:
                return np.full(t.shape, float(out))
        except Exception:  # noqa: BLE001 - not vectorised: evaluate point by point
            pass
        return np.array([float(self.function(float(x))) for x in t.ravel()]).reshape(t.shape)

    def describe(self) -> str:
        return f"user function {self.name or getattr(self.function, '__name__', 'f')}(t)"


def as_thrust_history(thrust) -> ThrustHistory:
    """Normalise the ``thrust`` argument of :func:`~impstab.simulate`."""
    if isinstance(thrust, ThrustHistory):
        return thrust
    if callable(thrust):
        return UserThrust(thrust)
    try:
        value = float(thrust)
    except (TypeError, ValueError):
        raise ModelError("thrust", thrust, "must be a number (N), a Ramp, a Step or a callable f(t)") from None
    if not math.isfinite(value) or value < 0:
        raise ModelError("thrust", thrust, "must be a finite number >= 0 (N)")
    return Constant(value)


def _dof_vector(name: str, value) -> Array:
    if value is None:
        return np.zeros(6)
    if isinstance(value, Mapping):
        out = np.zeros(6)
        for key, v in value.items():
            if key not in DOF_NAMES:
                raise ModelError(f"perturbation.{name}.{key}", v, f"unknown dof; use one of {list(DOF_NAMES)}")
            out[DOF_NAMES.index(key)] = float(v)
    else:
        out = np.asarray(value, dtype=float).reshape(-1)
        if out.shape != (6,):
            raise ModelError(f"perturbation.{name}", value, "must have 6 entries (surge ... yaw) or be a dict by dof")
    if not np.all(np.isfinite(out)):
        raise ModelError(f"perturbation.{name}", value, "must be finite")
    return out


@dataclass(frozen=True)
class Perturbation:
    """Initial perturbation from the static equilibrium.

    Parameters
    ----------
    displacement : (6,) array or dict by dof
        Translation of A (m, hull frame) and Euler-angle increments (rad) for
        ``surge, sway, heave, roll, pitch, yaw``.
    velocity : (6,) array or dict by dof
        Initial body-frame velocity of A (m/s) and angular velocity (rad/s), same order.

    The default (:meth:`default`) is a small sway and pitch kick: velocity 1e-5 m/s in sway and
    1e-5 rad/s in pitch, small enough to stay linear for many e-foldings of a flutter mode. It
    starts both planes of a symmetric layout (sway-yaw and heave-pitch), so that sway and pitch
    both show the flutter mode (the paper's Figures 5-6).
    """

    displacement: Sequence[float] | Mapping[str, float] | None = None
    velocity: Sequence[float] | Mapping[str, float] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "displacement", tuple(_dof_vector("displacement", self.displacement)))
        object.__setattr__(self, "velocity", tuple(_dof_vector("velocity", self.velocity)))

    @classmethod
    def default(cls) -> "Perturbation":
        return cls(velocity={"sway": 1e-5, "pitch": 1e-5})

    @classmethod
    def coerce(cls, value) -> "Perturbation":
        """Accept None (default), a Perturbation, a dict with ``displacement``/``velocity``, or a
        12-vector ``(displacement, velocity)``."""
        if value is None:
            return cls.default()
        if isinstance(value, Perturbation):
            return value
        if isinstance(value, Mapping):
            extra = set(value) - {"displacement", "velocity"}
            if extra:
                raise ModelError("perturbation", sorted(extra), "keys must be 'displacement' and/or 'velocity'")
            return cls(value.get("displacement"), value.get("velocity"))
        arr = np.asarray(value, dtype=float).reshape(-1)
        if arr.shape != (12,):
            raise ModelError("perturbation", value, "must be a Perturbation, a dict or 12 numbers")
        return cls(arr[:6], arr[6:])

    @property
    def vector(self) -> Array:
        """The deviation ``z0`` of the state ``(eta, nu)`` (12,)."""
        return np.concatenate([np.asarray(self.displacement), np.asarray(self.velocity)])

    def to_dict(self) -> dict:
        return {"displacement": dict(zip(DOF_NAMES, self.displacement)),
                "velocity": dict(zip(DOF_NAMES, self.velocity))}
