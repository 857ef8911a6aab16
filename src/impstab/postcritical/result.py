"""Results of the periodic-orbit computations: one cycle, special points, a branch of cycles."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from .collocation import Profile
from .hopf import HopfPoint

__all__ = ["Cycle", "SpecialPoint", "CycleBranch", "SPECIAL_KINDS"]

Array = NDArray[np.float64]
CArray = NDArray[np.complex128]

SPECIAL_KINDS = ("fold", "period-doubling", "torus")


@dataclass(frozen=True, eq=False)
class Cycle:
    """One periodic orbit of ``B x' = f(x, p)``.

    Attributes
    ----------
    parameter : float
        ``p`` (parameter units).
    period : float
        ``T`` (time units).
    profile : Profile
        The orbit over scaled time ``tau = t / T in [0, 1)`` (piecewise polynomial).
    multipliers : (n,) complex array
        Floquet multipliers, sorted by decreasing modulus, the trivial one included.
    trivial : int
        Index of the trivial multiplier (eigenvector along ``x'(0)``).
    trivial_error : float
        ``|mu_trivial - 1|``: the accuracy check of the multipliers.
    stable : bool
        Every nontrivial multiplier inside the unit circle.
    stability_tolerance : float
        Accuracy of the multipliers' moduli (``max(1e-9, 10 trivial_error)``): a cycle whose
        ``largest_multiplier`` is within it of 1 is marginal (at a fold, a period doubling, a
        torus point or next to the Hopf point) and its label is not decided by the multipliers.
    amplitude : (n,) array
        Half the peak-to-peak of each state over one period (state units).
    minimum, maximum, mean : (n,) arrays
        Extremes and time average of each state over one period.
    mesh_error : float
        Estimated largest error of the profile between mesh points (in units of the state scale).
    arclength : float
        Position along the branch (weighted arclength from its start).
    label : str
        "" for a regular point, "requested" for a cycle at a requested parameter value,
        "fold", "period-doubling", "torus", "end" (the last point), "start".
    """

    parameter: float
    period: float
    profile: Profile
    multipliers: CArray
    trivial: int
    trivial_error: float
    stable: bool
    stability_tolerance: float
    amplitude: Array
    minimum: Array
    maximum: Array
    mean: Array
    mesh_error: float
    arclength: float = 0.0
    label: str = ""
    newton_iterations: int = 0

    @property
    def nontrivial_multipliers(self) -> CArray:
        return np.delete(self.multipliers, self.trivial)

    @property
    def largest_multiplier(self) -> float:
        """Largest modulus of the nontrivial multipliers (below 1: stable)."""
        nt = self.nontrivial_multipliers
        return float(np.max(np.abs(nt))) if nt.size else 0.0

    def states(self, t: NDArray) -> Array:
        """States at times ``t`` (time units, periodic with the period)."""
        return self.profile(np.asarray(t, dtype=float) / self.period)

    def sample(self, points: int = 401) -> tuple[Array, Array]:
        """``(t, x)``: ``points`` times over one closed period ``[0, T]`` and the states there."""
        tau = np.linspace(0.0, 1.0, points)
        return tau * self.period, self.profile(tau)

    def __repr__(self) -> str:
        state = "stable" if self.stable else "unstable"
        return (f"Cycle(p = {self.parameter:.10g}, period = {self.period:.10g}, {state}, "
                f"max |mu| = {self.largest_multiplier:.6g}, |mu_1 - 1| = {self.trivial_error:.1e})")


@dataclass(frozen=True, eq=False)
class SpecialPoint:
    """A bifurcation of cycles located on the branch.

    Attributes
    ----------
    kind : {"fold", "period-doubling", "torus"}
        Limit point of cycles (a real multiplier through +1, the branch turns in ``p``), a real
        multiplier through -1, a complex pair through the unit circle (Neimark-Sacker).
    cycle : Cycle
        The cycle at the located point.
    test_value : float
        The test function there (``dp/ds``, ``mu + 1``, ``|mu| - 1``): zero to its tolerance.
    multiplier : complex or None
        The critical multiplier (``+1`` for a fold, ``-1``, ``e^{i theta}``).
    """

    kind: str
    cycle: Cycle
    test_value: float
    multiplier: complex | None

    @property
    def parameter(self) -> float:
        return self.cycle.parameter

    @property
    def period(self) -> float:
        return self.cycle.period

    def __repr__(self) -> str:
        return f"SpecialPoint({self.kind}, p = {self.parameter:.12g}, period = {self.period:.10g})"


@dataclass(frozen=True, eq=False)
class CycleBranch:
    """A branch of periodic orbits continued in the parameter.

    Attributes
    ----------
    cycles : tuple of Cycle
        In branch (arclength) order; regular steps, requested parameter values, special points
        and the end point.
    hopf : HopfPoint or None
        The Hopf point the branch starts from.
    special_points : tuple of SpecialPoint
    stop_reason : str
        Why the continuation ended.
    unreached : tuple of float
        Requested parameter values the branch did not pass.
    settings : dict
        Degree, intervals, step limits and tolerances used.
    state_names, state_units, parameter_name, parameter_units, time_units
    """

    cycles: tuple[Cycle, ...]
    hopf: HopfPoint | None
    special_points: tuple[SpecialPoint, ...]
    stop_reason: str
    unreached: tuple[float, ...] = ()
    settings: dict = field(default_factory=dict)
    state_names: tuple[str, ...] = ()
    state_units: tuple[str, ...] = ()
    parameter_name: str = "p"
    parameter_units: str = ""
    time_units: str = "s"
    warnings: tuple[str, ...] = ()

    # -------------------------------------------------------------- per-point arrays
    def __len__(self) -> int:
        return len(self.cycles)

    @property
    def parameter(self) -> Array:
        return np.array([c.parameter for c in self.cycles])

    @property
    def period(self) -> Array:
        return np.array([c.period for c in self.cycles])

    @property
    def stable(self) -> NDArray[np.bool_]:
        return np.array([c.stable for c in self.cycles], dtype=bool)

    @property
    def amplitude(self) -> Array:
        """``(points, n)`` half peak-to-peak of each state."""
        return np.array([c.amplitude for c in self.cycles]).reshape(len(self.cycles), -1)

    @property
    def multipliers(self) -> CArray:
        return np.array([c.multipliers for c in self.cycles]).reshape(len(self.cycles), -1)

    @property
    def trivial_error(self) -> Array:
        return np.array([c.trivial_error for c in self.cycles])

    @property
    def labels(self) -> tuple[str, ...]:
        return tuple(c.label for c in self.cycles)

    @property
    def folds(self) -> tuple[SpecialPoint, ...]:
        return tuple(s for s in self.special_points if s.kind == "fold")

    @property
    def fold_parameter(self) -> float | None:
        """Lowest parameter of a fold of cycles on the branch (None without a fold)."""
        folds = self.folds
        return min(s.parameter for s in folds) if folds else None

    def requested(self, p: float) -> tuple[Cycle, ...]:
        """The cycles at the requested parameter value ``p`` (exact), in branch order."""
        return tuple(c for c in self.cycles if c.label == "requested" and c.parameter == p)

    # -------------------------------------------------------------- output
    def to_dict(self) -> dict:
        """JSON-ready branch (arrays as lists; multipliers as [re, im] pairs)."""
        return {
            "parameter_name": self.parameter_name, "parameter": self.parameter.tolist(),
            "period": self.period.tolist(), "stable": self.stable.tolist(),
            "amplitude": {name: self.amplitude[:, j].tolist() for j, name in enumerate(self.state_names)},
            "trivial_multiplier_error": self.trivial_error.tolist(), "label": list(self.labels),
            "special_points": [{"kind": s.kind, "parameter": s.parameter, "period": s.period,
                                "test_value": s.test_value} for s in self.special_points],
            "fold_parameter": self.fold_parameter, "stop_reason": self.stop_reason,
            "unreached": list(self.unreached), "settings": self.settings, "warnings": list(self.warnings),
            "hopf": None if self.hopf is None else self.hopf.to_dict(),
        }

    def to_xarray(self, phases: int = 129):
        """Dataset over ``point`` (and ``state``, ``multiplier``, ``phase``); units and settings in attrs.

        Variables: the parameter (named ``parameter_name``), ``period``, ``stable``, ``amplitude``,
        ``minimum``, ``maximum``, ``mean``, the multipliers (real and imaginary parts),
        ``trivial_multiplier_error``, ``label`` and the cycle shapes ``profile`` sampled at
        ``phases`` equally spaced ``tau = t / T`` over one closed period.
        """
        import xarray as xr

        from .. import __version__

        k = len(self.cycles)
        units = list(self.state_units)
        tau = np.linspace(0.0, 1.0, phases)
        prof = np.array([c.profile(tau) for c in self.cycles]).reshape(k, phases, -1)
        mu = self.multipliers
        pname = self.parameter_name or "parameter"
        data = {
            pname: ("point", self.parameter, {"units": self.parameter_units, "long_name": "continuation parameter"}),
            "period": ("point", self.period, {"units": self.time_units}),
            "stable": ("point", self.stable.astype(np.int8), {"long_name": "1: every nontrivial Floquet multiplier inside the unit circle"}),
            "amplitude": (("point", "state"), self.amplitude, {"long_name": "half peak-to-peak over one period"}),
            "minimum": (("point", "state"), np.array([c.minimum for c in self.cycles]).reshape(k, -1)),
            "maximum": (("point", "state"), np.array([c.maximum for c in self.cycles]).reshape(k, -1)),
            "mean": (("point", "state"), np.array([c.mean for c in self.cycles]).reshape(k, -1)),
            "multiplier_real": (("point", "multiplier"), mu.real),
            "multiplier_imag": (("point", "multiplier"), mu.imag),
            "trivial_multiplier_error": ("point", self.trivial_error, {"long_name": "|mu_trivial - 1|"}),
            "mesh_error": ("point", np.array([c.mesh_error for c in self.cycles]),
                           {"long_name": "estimated profile error between mesh points, in units of the state scale"}),
            "arclength": ("point", np.array([c.arclength for c in self.cycles])),
            "label": ("point", np.array(self.labels, dtype=object).astype(str)),
            "profile": (("point", "phase", "state"), prof, {"long_name": "cycle shape over one period"}),
        }
        attrs = {
            "title": "branch of periodic orbits", "impstab_version": __version__,
            "state_units": json.dumps(units), "parameter_units": self.parameter_units, "time_units": self.time_units,
            "stop_reason": self.stop_reason, "settings": json.dumps(self.settings),
            "special_points": json.dumps([{"kind": s.kind, "parameter": s.parameter, "period": s.period}
                                          for s in self.special_points]),
            "unreached": json.dumps(list(self.unreached)), "warnings": json.dumps(list(self.warnings)),
            "convention": "amplitude = half peak-to-peak of each state over one period; stable = all nontrivial "
                          "Floquet multipliers inside the unit circle; multipliers sorted by decreasing modulus",
        }
        if self.fold_parameter is not None:
            attrs["fold_parameter"] = self.fold_parameter
        if self.hopf is not None:
            h = self.hopf
            attrs.update({"hopf_parameter": h.parameter, "hopf_bifurcation": h.bifurcation,
                          "hopf_omega": h.omega if h.omega is not None else math.nan,
                          "lyapunov_coefficient": h.lyapunov_coefficient if h.lyapunov_coefficient is not None else math.nan,
                          "hopf_reason": h.reason or ""})
        coords = {"point": np.arange(k), "state": list(self.state_names), "phase": tau,
                  "multiplier": np.arange(mu.shape[1])}
        ds = xr.Dataset(data, coords=coords, attrs=attrs)
        ds["state"].attrs["units"] = json.dumps(units)
        return ds

    def plot(self, ax=None, state: int | str | None = None, operating: float | None = None):
        """Bifurcation diagram: amplitude of ``state`` against the parameter; returns the axes.

        Stable cycles solid, unstable dashed; the Hopf point, folds, period doublings and torus
        points marked. ``state`` defaults to the state with the largest scaled amplitude.
        """
        from .plotting import plot_branch

        return plot_branch(self, ax=ax, state=state, operating=operating)

    def plot_cycle(self, index: int = -1, states: tuple[int | str, int | str] = (0, 1), ax=None):
        """Phase portrait of cycle ``index`` in the plane of two states; returns the axes."""
        from .plotting import plot_phase_portrait

        return plot_phase_portrait(self, index=index, states=states, ax=ax)

    def state_index(self, state: int | str) -> int:
        if isinstance(state, str):
            if state not in self.state_names:
                from ..errors import ModelError

                raise ModelError("state", state, f"must be one of {', '.join(self.state_names)}")
            return self.state_names.index(state)
        return int(state)

    def __repr__(self) -> str:
        p = self.parameter
        span = f"{p.min():.6g} .. {p.max():.6g}" if p.size else "empty"
        return (f"CycleBranch({len(self.cycles)} cycles, {self.parameter_name} in {span}, "
                f"{len(self.special_points)} special points, stop: {self.stop_reason})")
