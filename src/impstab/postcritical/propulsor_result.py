"""The result of a propulsor's post-critical analysis: the onset, its label and the cycle branch."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["PostcriticalResult", "DOFS", "READING"]

Array = NDArray[np.float64]

#: the six coordinates whose amplitudes are reported (X_A, Y_A, Z_A in m; phi, theta, psi in rad)
DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
DOF_UNITS = ("m", "m", "m", "rad", "rad", "rad")

#: the engineer's reading of each label (the first words of :attr:`PostcriticalResult.reading`)
READING = {
    "supercritical": "benign",
    "subcritical": "dangerous",
    "degenerate": "undetermined",
    None: "stable",
}


def _none(x) -> float | None:
    """``x`` as a float, None for None or NaN (JSON has no NaN)."""
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


@dataclass(frozen=True, eq=False)
class PostcriticalResult:
    """Post-critical behaviour of a propulsor model: Hopf analysis at the onset and the cycles past it.

    Attributes
    ----------
    critical_thrust : float or None
        Onset thrust T_c (N), refined on the nonlinear model's equilibrium branch; None when stable
        up to ``thrust_max``.
    kind : {"flutter", "divergence", "none"}
    omega : float or None
        Angular frequency of the critical pair at onset (rad/s).
    lyapunov_coefficient : float or None
        First Lyapunov coefficient l1 (Kuznetsov's normalisation, ``q^H q = 1`` on the 12 states in
        SI units; 1 / (s state^2)); None at a degenerate onset.
    lyapunov_error : float or None
        Error bound of l1.
    bifurcation : {"supercritical", "subcritical", "degenerate"} or None
        None when there is no onset.
    reason : str or None
        Why the plain Hopf theory does not apply (degenerate), or why there is no onset.
    crossing_speed : float or None
        ``d Re(lambda) / dT`` at the onset (1 / (s N)).
    fold_thrust : float or None
        Lowest thrust of a fold of cycles on the computed branch (N).
    branch_thrust, branch_period : (k,) arrays
        Thrust (N) and period (s) of each point of the branch (NaN period for a "no cycle" entry).
    branch_stable : (k,) bool array
        Every nontrivial Floquet multiplier inside the unit circle (for a "no cycle" entry: the
        equilibrium is stable there).
    branch_amplitude : (k, 6) array
        Half peak-to-peak of X_A, Y_A, Z_A (m) and phi, theta, psi (rad) over one period.
    branch_multipliers : (k, n_states) complex array
        Floquet multipliers by decreasing modulus (the trivial one included).
    trivial_multiplier_error : (k,) array
        ``|mu_trivial - 1|`` of each cycle: the accuracy check of the multipliers.
    largest_multiplier : (k,) array
        Largest modulus of the nontrivial multipliers (below 1: stable).
    peak_mount_deflection, peak_mount_force : (k,) arrays
        Largest ``|d|`` (m) and largest mount force magnitude (N) over the mounts and one period.
    snubber_contact : (k,) bool array
        Some mount's deflection exceeds its snubber clearance on the cycle.
    branch_label : tuple of str
        "start", "", "requested", "fold", "period-doubling", "torus", "end", or "no cycle"
        (a requested thrust at which the computed branch has no cycle).
    operating_thrust, thrust_max : float or None, float
    linear_kind, linear_critical_thrust
        The linear analysis's answer (:func:`impstab.critical_thrust`).
    hopf : HopfPoint or None
        The full Hopf analysis (eigenvectors, normal form, predictions).
    cycles : CycleBranch or None
        The generic branch (cycle profiles, special points), for plots and cycle shapes.
    stop_reason : str
    settings : dict
    warnings : tuple of str
    model_name : str
    """

    critical_thrust: float | None
    kind: str
    omega: float | None
    lyapunov_coefficient: float | None
    lyapunov_error: float | None
    bifurcation: str | None
    reason: str | None
    crossing_speed: float | None
    fold_thrust: float | None
    branch_thrust: Array
    branch_period: Array
    branch_stable: NDArray[np.bool_]
    branch_amplitude: Array
    branch_multipliers: NDArray[np.complex128]
    trivial_multiplier_error: Array
    largest_multiplier: Array
    peak_mount_deflection: Array
    peak_mount_force: Array
    snubber_contact: NDArray[np.bool_]
    branch_label: tuple[str, ...]
    operating_thrust: float | None
    thrust_max: float
    linear_kind: str
    linear_critical_thrust: float | None
    hopf: object = None
    cycles: object = None
    stop_reason: str = ""
    settings: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    model_name: str = ""

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_branch(cls, *, hopf, kind, branch, peaks, requested, stable_below=None, **base) -> "PostcriticalResult":
        cyc = branch.cycles
        missing = [t for t in requested if not branch.requested(t)]
        n = len(cyc) + len(missing)
        thrust = np.concatenate([branch.parameter, missing]) if n else np.zeros(0)
        period = np.concatenate([branch.period, np.full(len(missing), np.nan)]) if n else np.zeros(0)
        amp = np.zeros((n, 6))
        amp[:len(cyc)] = branch.amplitude[:, :6] if cyc else 0.0
        tc = hopf.parameter
        stable = np.zeros(n, dtype=bool)
        stable[:len(cyc)] = branch.stable
        mult = np.full((n, branch.multipliers.shape[1] if cyc else 12), np.nan + 0j)
        if cyc:
            mult[:len(cyc)] = branch.multipliers
        triv = np.concatenate([branch.trivial_error, np.full(len(missing), np.nan)])
        largest = np.concatenate([[c.largest_multiplier for c in cyc], np.full(len(missing), np.nan)])
        pk = np.array([p[:2] for p in peaks], dtype=float).reshape(-1, 2)
        defl = np.concatenate([pk[:, 0], np.full(len(missing), np.nan)])
        force = np.concatenate([pk[:, 1], np.full(len(missing), np.nan)])
        contact = np.concatenate([np.array([p[2] for p in peaks], dtype=bool), np.zeros(len(missing), dtype=bool)])
        for k, t in enumerate(missing):
            eq_stable = _equilibrium_stable(hopf, t)
            stable[len(cyc) + k] = eq_stable
            amp[len(cyc) + k] = 0.0 if eq_stable else np.nan
            defl[len(cyc) + k] = np.nan
        labels = tuple(branch.labels) + ("no cycle",) * len(missing)
        warnings = tuple(branch.warnings) + tuple(hopf.warnings)
        if missing:
            warnings += (f"no cycle on the computed branch at the requested thrust(s) "
                         f"{', '.join(f'{t:.6g}' for t in missing)} N (listed as 'no cycle')",)
        return cls(critical_thrust=tc, kind=kind, omega=hopf.omega, lyapunov_coefficient=hopf.lyapunov_coefficient,
                   lyapunov_error=hopf.lyapunov_error, bifurcation=hopf.bifurcation, reason=hopf.reason,
                   crossing_speed=hopf.crossing_speed, fold_thrust=branch.fold_parameter, branch_thrust=thrust,
                   branch_period=period, branch_stable=stable, branch_amplitude=amp, branch_multipliers=mult,
                   trivial_multiplier_error=triv, largest_multiplier=largest, peak_mount_deflection=defl, peak_mount_force=force,
                   snubber_contact=contact, branch_label=labels, hopf=hopf, cycles=branch,
                   stop_reason=branch.stop_reason, warnings=warnings, **base)

    @classmethod
    def from_hopf(cls, *, hopf, kind, requested, **base) -> "PostcriticalResult":
        """The Hopf analysis alone (the branch not computed)."""
        res = cls.without_branch(critical_thrust=hopf.parameter, kind=kind, omega=hopf.omega,
                                 bifurcation=hopf.bifurcation, reason=hopf.reason, requested=requested,
                                 stable_below=hopf.parameter, hopf=hopf, **base)
        from dataclasses import replace

        return replace(res, lyapunov_coefficient=hopf.lyapunov_coefficient, lyapunov_error=hopf.lyapunov_error,
                       stop_reason="the branch of cycles was not computed")

    @classmethod
    def without_branch(cls, *, critical_thrust, kind, omega, bifurcation, reason, requested, stable_below,
                       hopf=None, **base) -> "PostcriticalResult":
        n = len(requested)
        thrust = np.array(requested, dtype=float)
        stable = thrust < stable_below
        amp = np.where(stable[:, None], 0.0, np.nan) * np.ones((n, 6))
        nan = np.full(n, np.nan)
        return cls(critical_thrust=critical_thrust, kind=kind, omega=omega, lyapunov_coefficient=None,
                   lyapunov_error=None, bifurcation=bifurcation, reason=reason,
                   crossing_speed=None if hopf is None else hopf.crossing_speed, fold_thrust=None,
                   branch_thrust=thrust, branch_period=nan.copy(), branch_stable=stable, branch_amplitude=amp,
                   branch_multipliers=np.full((n, 12), np.nan + 0j), trivial_multiplier_error=nan.copy(), largest_multiplier=nan.copy(),
                   peak_mount_deflection=nan.copy(), peak_mount_force=nan.copy(),
                   snubber_contact=np.zeros(n, dtype=bool), branch_label=("no cycle",) * n, hopf=hopf,
                   stop_reason="no branch: " + (reason or ""),
                   warnings=() if hopf is None else tuple(hopf.warnings), **base)

    # ------------------------------------------------------------------ the engineer's reading
    @property
    def frequency_hz(self) -> float | None:
        return None if not self.omega else self.omega / (2 * math.pi)

    @property
    def practical_limit_thrust(self) -> float | None:
        """The thrust not to exceed (N): the onset for a supercritical or degenerate onset, the
        fold of cycles for a subcritical one (the lowest thrust on the computed branch when it
        shows no fold); None when stable up to ``thrust_max``."""
        if self.critical_thrust is None:
            return None
        if self.bifurcation == "subcritical":
            if self.fold_thrust is not None:
                return float(self.fold_thrust)
            cyc = self.branch_thrust[np.array([lab != "no cycle" for lab in self.branch_label], dtype=bool)]
            return float(min(cyc.min(), self.critical_thrust)) if cyc.size else float(self.critical_thrust)
        return float(self.critical_thrust)

    @property
    def reading(self) -> str:
        """One line: benign or dangerous, and the practical limit thrust."""
        tc = self.critical_thrust
        if tc is None:
            return f"stable: no onset of instability up to thrust_max = {self.thrust_max:.6g} N"
        if self.bifurcation == "supercritical":
            return (f"benign: past T_c = {tc:.6g} N a small stable limit cycle grows gently with thrust (it can be "
                    f"monitored); practical limit thrust {tc:.6g} N")
        if self.bifurcation == "subcritical":
            if self.fold_thrust is not None:
                return (f"dangerous: large oscillations exist below T_c = {tc:.6g} N down to the fold of cycles at "
                        f"{self.fold_thrust:.6g} N, with hysteresis; practical limit thrust {self.fold_thrust:.6g} N "
                        f"(the fold)")
            return (f"dangerous: the onset at T_c = {tc:.6g} N is subcritical and the computed branch shows no fold "
                    f"(it stopped: {self.stop_reason}); large oscillations exist at least down to "
                    f"{self.practical_limit_thrust:.6g} N: practical limit thrust below that")
        return (f"undetermined: the plain Hopf theory does not apply at T_c = {tc:.6g} N ({self.reason}); "
                f"practical limit thrust T_c = {tc:.6g} N")

    # ------------------------------------------------------------------ output
    def to_dict(self) -> dict:
        """The keys of ``impstab postcritical --json`` (DESIGN.md), and more; NaN as None."""
        amp = {name: [_none(v) for v in self.branch_amplitude[:, j]] for j, name in enumerate(DOFS)}
        return {
            "critical_thrust": _none(self.critical_thrust), "kind": self.kind, "omega": _none(self.omega),
            "lyapunov_coefficient": _none(self.lyapunov_coefficient), "bifurcation": self.bifurcation,
            "fold_thrust": _none(self.fold_thrust),
            "branch": {
                "thrust": [float(t) for t in self.branch_thrust], "period": [_none(v) for v in self.branch_period],
                "stable": [bool(s) for s in self.branch_stable], "amplitude": amp,
                "label": list(self.branch_label),
                "trivial_multiplier_error": [_none(v) for v in self.trivial_multiplier_error],
                "largest_multiplier": [_none(v) for v in self.largest_multiplier],
                "peak_mount_deflection": [_none(v) for v in self.peak_mount_deflection],
                "peak_mount_force": [_none(v) for v in self.peak_mount_force],
                "snubber_contact": [bool(s) for s in self.snubber_contact],
            },
            "frequency_hz": _none(self.frequency_hz), "lyapunov_error": _none(self.lyapunov_error),
            "reason": self.reason, "crossing_speed": _none(self.crossing_speed),
            "practical_limit_thrust": _none(self.practical_limit_thrust), "reading": self.reading,
            "operating_thrust": _none(self.operating_thrust), "thrust_max": float(self.thrust_max),
            "linear_kind": self.linear_kind, "linear_critical_thrust": _none(self.linear_critical_thrust),
            "stop_reason": self.stop_reason, "warnings": list(self.warnings),
            "units": {"thrust": "N", "period": "s", "amplitude": dict(zip(DOFS, DOF_UNITS)), "omega": "rad/s",
                      "peak_mount_deflection": "m", "peak_mount_force": "N", "crossing_speed": "1/(s N)"},
        }

    def to_json(self) -> str:
        return json.dumps(self.to_dict())

    def to_xarray(self, phases: int = 129):
        """Dataset over ``point`` (and ``dof``, ``multiplier``, ``phase``, ``state``); units and
        settings in attrs; netCDF-ready. ``profile`` holds each cycle's 12 states over one period
        (NaN for "no cycle" entries)."""
        import xarray as xr

        from .. import __version__

        k = self.branch_thrust.size
        tau = np.linspace(0.0, 1.0, phases)
        prof = np.full((k, phases, 12), np.nan)
        if self.cycles is not None:
            for i, c in enumerate(self.cycles.cycles):
                prof[i] = c.profile(tau)[:, :12]  # the body's states (viscoelastic internal variables left out)
        from .propulsor import STATE_NAMES, STATE_UNITS

        data = {
            "thrust": ("point", self.branch_thrust, {"units": "N"}),
            "period": ("point", self.branch_period, {"units": "s"}),
            "stable": ("point", self.branch_stable.astype(np.int8),
                       {"long_name": "1: every nontrivial Floquet multiplier inside the unit circle"}),
            "amplitude": (("point", "dof"), self.branch_amplitude,
                          {"long_name": "half peak-to-peak over one period", "units": json.dumps(dict(zip(DOFS, DOF_UNITS)))}),
            "multiplier_real": (("point", "multiplier"), self.branch_multipliers.real),
            "multiplier_imag": (("point", "multiplier"), self.branch_multipliers.imag),
            "trivial_multiplier_error": ("point", self.trivial_multiplier_error, {"long_name": "|mu_trivial - 1|"}),
            "largest_multiplier": ("point", self.largest_multiplier,
                                   {"long_name": "largest modulus of the nontrivial Floquet multipliers"}),
            "peak_mount_deflection": ("point", self.peak_mount_deflection, {"units": "m"}),
            "peak_mount_force": ("point", self.peak_mount_force, {"units": "N"}),
            "snubber_contact": ("point", self.snubber_contact.astype(np.int8)),
            "label": ("point", np.array(self.branch_label, dtype=object).astype(str)),
            "profile": (("point", "phase", "state"), prof, {"long_name": "cycle states over one period",
                                                            "units": json.dumps(dict(zip(STATE_NAMES, STATE_UNITS)))}),
        }
        attrs = {
            "title": f"post-critical analysis of {self.model_name}", "impstab_version": __version__,
            "model": self.model_name, "kind": self.kind, "bifurcation": self.bifurcation or "none",
            "reason": self.reason or "", "reading": self.reading, "stop_reason": self.stop_reason,
            "thrust_max": float(self.thrust_max), "linear_kind": self.linear_kind,
            "settings": json.dumps(self.settings), "warnings": json.dumps(list(self.warnings)),
            "units": json.dumps({"thrust": "N", "period": "s", "omega": "rad/s", "lyapunov_coefficient": "1/(s state^2)",
                                 "crossing_speed": "1/(s N)"}),
            "convention": ("amplitude = half peak-to-peak of X_A, Y_A, Z_A (m) and phi, theta, psi (rad) over one "
                           "period; l1 in Kuznetsov's normalisation, q^H q = 1 on the 12 SI states"),
        }
        for name in ("critical_thrust", "omega", "lyapunov_coefficient", "lyapunov_error", "crossing_speed",
                     "fold_thrust", "operating_thrust", "linear_critical_thrust", "practical_limit_thrust"):
            v = _none(getattr(self, name))
            attrs[name] = math.nan if v is None else v
        coords = {"point": np.arange(k), "dof": list(DOFS), "phase": tau, "state": list(STATE_NAMES),
                  "multiplier": np.arange(self.branch_multipliers.shape[1])}
        return xr.Dataset(data, coords=coords, attrs=attrs)

    # ------------------------------------------------------------------ drawing
    def plot(self, ax=None, dof: str | None = None):
        """Bifurcation diagram: amplitude of ``dof`` against thrust; returns the axes.

        Stable cycles solid, unstable dashed, the Hopf point, folds and the operating thrust
        marked. ``dof`` defaults to the coordinate with the largest scaled amplitude.
        """
        from .propulsor_plot import plot_postcritical

        return plot_postcritical(self, ax=ax, dof=dof)

    def plot_cycle(self, thrust: float | None = None, dofs: tuple[str, str] = ("pitch", "yaw"), ax=None):
        """Phase portrait of the cycle nearest ``thrust`` (a stable one when there is a choice;
        default the last cycle) in the plane of two coordinates; returns the axes."""
        from ..errors import ModelError

        if self.cycles is None or not len(self.cycles):
            raise ModelError("thrust", thrust, f"there is no computed cycle ({self.reason or self.stop_reason})")
        br = self.cycles
        for name in dofs:
            if name not in DOFS + ("u", "v", "w", "p", "q", "r"):
                raise ModelError("dofs", name, f"must name states among {', '.join(DOFS)}")
        if thrust is None:
            index = len(br) - 1
        else:
            dist = np.abs(br.parameter - float(thrust)) + 1e-9 * np.abs(float(thrust)) * ~br.stable
            index = int(np.argmin(dist))
        return br.plot_cycle(index, tuple(dofs), ax=ax)

    def __repr__(self) -> str:
        tc = "none" if self.critical_thrust is None else f"{self.critical_thrust:.8g} N"
        l1 = "n/a" if self.lyapunov_coefficient is None else f"{self.lyapunov_coefficient:.6g}"
        return (f"PostcriticalResult(T_c = {tc}, {self.kind}, l1 = {l1}, {self.bifurcation}, "
                f"fold = {self.fold_thrust}, {self.branch_thrust.size} branch points)")


def _equilibrium_stable(hopf, thrust: float) -> bool:
    """Whether the equilibrium is stable at ``thrust`` near a single onset: below it (the
    equilibrium branch loses stability at the onset as the thrust grows)."""
    return bool(thrust < hopf.parameter)
