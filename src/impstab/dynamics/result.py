"""Result of a time simulation: sampled time histories and what produced them."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, fields

import numpy as np
from numpy.typing import NDArray

from ..model.model import DOF_NAMES
from .growth import GrowthFit

__all__ = ["SimulationResult", "combine_results", "results_to_dataframe"]

Array = NDArray[np.float64]

_VELOCITY_NAMES = ("u", "v", "w", "p", "q", "r")
_SCALARS = ("model_name", "integrator", "dt", "final_dt", "sample", "duration", "thrust_history", "completed",
            "stop_reason", "stop_time", "steps", "rhs_evaluations", "restarts", "wall_time", "fastest_omega",
            "fastest_mode", "step_limit", "length_scale", "critical_thrust", "classification")


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Time histories of a nonlinear run from the static equilibrium.

    Attributes
    ----------
    time : (k,) sample times (s)
    deviation : (k, 12) state minus the equilibrium: displacement of A (m, hull frame), Euler
        angles (rad), body-frame velocity (m/s) and angular velocity (rad/s)
    equilibrium : (12,) the static equilibrium ``(X_A, Xi, 0)`` at ``T(0)``
    thrust : (k,) thrust at the samples (N)
    mount_loads : (k, n_mounts, 6) force of each mount on the body (N, hull frame) and its moment
        (N m; non-zero for mounts with rotational stiffness only); for a massive beam mount the
        load of its static tip stiffness (and dampers) at the body-end deflection, without the
        beam's inertia force (:mod:`impstab.dynamics.beam_mounts`)
    error_estimate : (k,) or None
        Hamming's relative local error estimate, largest over each sampling interval.
    completed : bool
        False when the run stopped early; ``stop_reason`` and ``stop_time`` (s) say why and when.
    growth : GrowthFit
        What the run shows: envelope label, fitted growth rate beside ``max Re(lambda)`` at the
        same thrust, a limit cycle's period and amplitudes, or why it is undetermined.
    classification : {"subcritical", "critical", "supercritical", "unknown", "not computed"}
    internal_variables : (k, n_terms, 3) or None
        The internal variables ``w_ij`` of the viscoelastic mounts' Prony terms (m, hull frame;
        at rest equal to the mount's deflection, :mod:`impstab.dynamics.viscoelastic`); None
        without viscoelastic mounts.
    internal_mounts : (n_terms,) int array or None
        The mount of each Prony term.
    beam_modes, beam_mode_rates : (k, n_modes) or None
        The kept fixed-interface modal coordinates ``eta`` of the massive beam mounts (kg^0.5 m,
        unit modal mass; 0 at rest) and their rates (kg^0.5 m/s)
        (:mod:`impstab.dynamics.beam_mounts`); None without massive beam mounts.
    beam_mode_mounts : (n_modes,) int array or None
        The mount of each kept mode.
    beam_mode_omega : (n_modes,) array or None
        The fixed-interface (hull and body end clamped) frequency of each kept mode (rad/s).
    """

    time: Array
    deviation: Array
    equilibrium: Array
    thrust: Array
    mount_loads: Array
    error_estimate: Array | None
    model_name: str
    integrator: str
    dt: float
    final_dt: float
    sample: float
    duration: float
    thrust_history: str
    perturbation: dict
    completed: bool
    stop_reason: str | None
    stop_time: float | None
    steps: int
    rhs_evaluations: int
    restarts: int
    wall_time: float
    fastest_omega: float
    fastest_mode: str
    step_limit: float
    length_scale: float
    growth: GrowthFit | None
    critical_thrust: float | None
    classification: str
    tolerances: dict = field(default_factory=dict)
    internal_variables: Array | None = None
    internal_mounts: Array | None = None
    beam_modes: Array | None = None
    beam_mode_rates: Array | None = None
    beam_mode_mounts: Array | None = None
    beam_mode_omega: Array | None = None

    @property
    def displacement(self) -> Array:
        """(k, 6) displacement of A (m) and Euler angles (rad) relative to the equilibrium."""
        return self.deviation[:, :6]

    @property
    def absolute(self) -> Array:
        """(k, 6) displacement of A from the unloaded position (m) and absolute Euler angles (rad)."""
        return self.deviation[:, :6] + self.equilibrium[None, :6]

    @property
    def velocity(self) -> Array:
        """(k, 6) body-frame velocity of A (m/s) and angular velocity (rad/s)."""
        return self.deviation[:, 6:] + self.equilibrium[None, 6:]

    def to_dict(self) -> dict:
        """Settings and outcome without the time histories (JSON-ready)."""
        out = {name: getattr(self, name) for name in _SCALARS}
        out["perturbation"] = self.perturbation
        out["equilibrium"] = self.equilibrium.tolist()
        out["growth"] = None if self.growth is None else self.growth.to_dict()
        out["tolerances"] = self.tolerances
        return out

    def to_xarray(self):
        """Dataset with coordinate ``time``; variables by dof; settings in ``attrs``."""
        import xarray as xr

        from .. import __version__

        data = {}
        for j, name in enumerate(DOF_NAMES):
            unit, vunit = ("m", "m/s") if j < 3 else ("rad", "rad/s")
            what = "displacement of A" if j < 3 else "Euler angle"
            data[name] = ("time", self.displacement[:, j],
                          {"units": unit, "long_name": f"{name}: {what} from the equilibrium"})
            data[f"{name}_absolute"] = ("time", self.absolute[:, j],
                                        {"units": unit, "long_name": f"{name}: {what}, absolute"})
            data[f"{name}_velocity"] = ("time", self.velocity[:, j],
                                        {"units": vunit, "long_name": f"body-frame velocity {_VELOCITY_NAMES[j]}"})
        data["thrust"] = ("time", self.thrust, {"units": "N", "long_name": "thrust at each sample"})
        data["mount_force"] = (("time", "mount", "axis"), self.mount_loads[:, :, :3],
                               {"units": "N", "long_name": "force of the mount on the body, hull frame"})
        data["mount_moment"] = (("time", "mount", "axis"), self.mount_loads[:, :, 3:],
                                {"units": "N m", "long_name": "moment of the mount on the body (rotational stiffness)"})
        coords_extra = {}
        if self.internal_variables is not None:
            data["internal_variable"] = (("time", "term", "axis"), self.internal_variables, {
                "units": "m", "long_name": "viscoelastic internal variable of each Prony term, hull frame"})
            coords_extra["term"] = ("term", np.arange(self.internal_variables.shape[1]),
                                    {"units": "1", "long_name": "Prony term number"})
            coords_extra["term_mount"] = ("term", np.asarray(self.internal_mounts),
                                          {"units": "1", "long_name": "mount of each Prony term"})
        if self.beam_modes is not None:
            data["beam_modal_coordinate"] = (("time", "beam_mode"), self.beam_modes, {
                "units": "kg^0.5 m", "long_name": "kept fixed-interface modal coordinate of a massive beam mount"})
            data["beam_modal_rate"] = (("time", "beam_mode"), self.beam_mode_rates, {
                "units": "kg^0.5 m/s", "long_name": "rate of the modal coordinate"})
            coords_extra["beam_mode"] = ("beam_mode", np.arange(self.beam_modes.shape[1]),
                                         {"units": "1", "long_name": "kept beam mode number"})
            coords_extra["beam_mode_mount"] = ("beam_mode", np.asarray(self.beam_mode_mounts),
                                               {"units": "1", "long_name": "mount of each kept beam mode"})
            coords_extra["beam_mode_omega"] = ("beam_mode", np.asarray(self.beam_mode_omega), {
                "units": "rad/s", "long_name": "fixed-interface frequency of each kept beam mode"})
        if self.error_estimate is not None:
            data["error_estimate"] = ("time", self.error_estimate, {
                "units": "1", "long_name": "Hamming relative local error estimate (9/121)|p - c|"})
        attrs = {"title": f"time simulation of {self.model_name}", "impstab_version": __version__,
                 "perturbation": json.dumps(self.perturbation), "equilibrium": self.equilibrium.tolist(),
                 "growth": json.dumps(None if self.growth is None else self.growth.to_dict()),
                 "tolerances": json.dumps(self.tolerances),
                 "convention": "state deviation from the static equilibrium at T(0); Euler angles z-y-x; "
                               "velocities in the body frame; growth rates in 1/s"}
        for name in _SCALARS:
            value = getattr(self, name)
            if value is None:
                continue
            attrs[name] = int(value) if isinstance(value, bool) else value
        if self.growth is not None:
            attrs["growth_rate_fit"] = self.growth.rate
            if self.growth.linear_rate is not None:
                attrs["growth_rate_linear"] = self.growth.linear_rate
        coords = {"time": ("time", self.time, {"units": "s", "long_name": "time"}),
                  "mount": ("mount", np.arange(self.mount_loads.shape[1]), {"units": "1", "long_name": "mount number"}),
                  "axis": ("axis", ["x", "y", "z"], {"long_name": "hull-frame axis"}), **coords_extra}
        return xr.Dataset(data, coords=coords, attrs=attrs)

    @classmethod
    def from_xarray(cls, ds) -> "SimulationResult":
        """Rebuild a result from :meth:`to_xarray` output (e.g. read back from netCDF)."""
        a = ds.attrs
        dev = np.column_stack([ds[n].values for n in DOF_NAMES] + [ds[f"{n}_velocity"].values for n in DOF_NAMES])
        eq = np.asarray(a["equilibrium"], dtype=float)
        dev[:, 6:] -= eq[None, 6:]
        loads = np.concatenate([ds["mount_force"].values, ds["mount_moment"].values], axis=2)
        g = json.loads(a.get("growth", "null"))
        growth = None if g is None else GrowthFit.from_dict(g)
        kw = {f.name: None for f in fields(cls)}
        kw.update({n: (a[n].item() if hasattr(a[n], "item") else a[n]) for n in _SCALARS if n in a})
        kw.update(time=ds["time"].values, deviation=dev, equilibrium=eq, thrust=ds["thrust"].values, mount_loads=loads,
                  error_estimate=ds["error_estimate"].values if "error_estimate" in ds else None,
                  perturbation=json.loads(a["perturbation"]), growth=growth, completed=bool(a["completed"]),
                  tolerances=json.loads(a.get("tolerances", "{}")),
                  internal_variables=ds["internal_variable"].values if "internal_variable" in ds else None,
                  internal_mounts=ds["term_mount"].values if "term_mount" in ds.coords else None)
        if "beam_modal_coordinate" in ds:
            kw.update(beam_modes=ds["beam_modal_coordinate"].values, beam_mode_rates=ds["beam_modal_rate"].values,
                      beam_mode_mounts=ds["beam_mode_mount"].values, beam_mode_omega=ds["beam_mode_omega"].values)
        return cls(**kw)

    def plot(self, ax=None):
        """Sway above pitch against time, like the paper's Figures 5-6.

        ``ax`` may be None (a new figure), one Axes (sway only) or a pair; returns a
        :class:`~impstab.plot.SimulationAxes` ``(sway, pitch)``, or the one Axes given.
        """
        from ..plot.simulation import plot_simulation

        return plot_simulation(self, ax=ax)

    def __repr__(self) -> str:
        from ..display import simulation_text

        return simulation_text(self)

    def _repr_html_(self) -> str:
        from ..display import simulation_html

        return simulation_html(self)


def combine_results(results) -> "xarray.Dataset":  # noqa: F821
    """Several runs (e.g. sub-, at and supercritical thrusts) in one dataset along ``case``.

    Runs on the same time grid align exactly; a run that stopped early is padded with NaN.
    Per-run outcomes become variables over ``case``; shared settings stay in ``attrs``. The
    thrust of each run (at t = 0, N) is the coordinate ``thrust`` on ``case``, with an index, so
    that ``ds.sel(thrust=19000.0)`` picks a run (after reading the file back, restore the index
    with ``ds.set_xindex("thrust")``); the thrust at every sample is ``applied_thrust``. Every
    variable keeps its units.
    """
    import xarray as xr

    sets = []
    for r in results:
        ds = r.to_xarray().rename({"thrust": "applied_thrust"})
        ds.attrs = {}
        sets.append(ds)
    per_case = {
        "classification": ("case", [r.classification for r in results],
                           {"long_name": "thrust against the critical thrust: subcritical, critical, supercritical"}),
        "envelope": ("case", [r.growth.envelope if r.growth else "" for r in results],
                     {"long_name": "shape of the envelope of the motion"}),
        "growth_rate_fit": ("case", [r.growth.rate if r.growth else np.nan for r in results],
                            {"units": "1/s", "long_name": "envelope growth rate fitted to the run"}),
        "growth_rate_linear": ("case", [np.nan if r.growth is None or r.growth.linear_rate is None
                                        else r.growth.linear_rate for r in results],
                               {"units": "1/s", "long_name": "max Re(lambda) of the linearization"}),
        "completed": ("case", [int(r.completed) for r in results],
                      {"units": "1", "long_name": "1 when the run reached its duration, 0 when it stopped"}),
        "stop_time": ("case", [np.nan if r.stop_time is None else r.stop_time for r in results],
                      {"units": "s", "long_name": "time at which a run stopped early (NaN: it completed)"}),
        "stop_reason": ("case", [r.stop_reason or "" for r in results], {"long_name": "why a run stopped early"}),
    }
    keep = ("impstab_version", "model_name", "integrator", "dt", "sample", "duration", "perturbation", "convention")
    first = results[0].to_xarray().attrs
    out = xr.concat(sets, dim="case", join="outer", combine_attrs="override")
    out = out.assign(per_case)
    out = out.assign_coords(
        case=("case", np.arange(len(results)), {"units": "1", "long_name": "run number"}),
        thrust=("case", [float(r.thrust[0]) for r in results], {"units": "N", "long_name": "thrust of the run at t = 0"}),
    ).set_xindex("thrust")
    out.attrs = {**{k: v for k, v in first.items() if k in keep},
                 "title": f"time simulations of {results[0].model_name} at {len(results)} thrusts"}
    return out


def results_to_dataframe(results):
    """Long table (pandas) of one or several runs: one row per sample, column ``case_thrust``;
    mount forces as ``mount{i}_f{x,y,z}`` (N)."""
    import pandas as pd

    frames = []
    for r in results:
        cols = {"case_thrust": np.full(r.time.size, float(r.thrust[0])), "time": r.time}
        for j, name in enumerate(DOF_NAMES):
            cols[name] = r.displacement[:, j]
        for j, name in enumerate(DOF_NAMES):
            cols[f"{name}_absolute"] = r.absolute[:, j]
        for j, name in enumerate(DOF_NAMES):
            cols[f"{name}_velocity"] = r.velocity[:, j]
        cols["thrust"] = r.thrust
        for i in range(r.mount_loads.shape[1]):
            for a, ax in enumerate("xyz"):
                cols[f"mount{i}_f{ax}"] = r.mount_loads[:, i, a]
        frames.append(pd.DataFrame(cols))
    return pd.concat(frames, ignore_index=True)
