"""Critical thrust of a propulsor model: the first loss of stability from T = 0."""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..limits import check_number
from ..model.model import DOF_NAMES, Model
from .critical import CriticalLoad, Crossing, critical_load_family
from .linearize import ModelFamily
from .practical import PracticalOnset, damping_threshold, practical_problem, practical_onset

__all__ = ["CriticalThrust", "critical_thrust", "PARTICIPATION_THRESHOLD", "operating_point_warnings"]

#: share of kinetic energy above which a dof is listed among the modes involved
PARTICIPATION_THRESHOLD = 0.05
#: compressible fluid: relative change of the critical thrust that ends the frequency iteration
FLUID_TOLERANCE = 1e-8
FLUID_MAX_ITERATIONS = 20


@dataclass(frozen=True, eq=False)
class CriticalThrust:
    """Critical thrust of a model and the mode that goes unstable.

    Attributes
    ----------
    thrust : float or None
        Critical thrust T_c (N); None when stable up to ``thrust_max`` (``kind == "none"``).
    kind : {"flutter", "divergence", "none"}
    omega : float or None
        Angular frequency at onset (rad/s).
    modes : tuple of str
        Dofs whose kinetic-energy share in the merging modes is at least 5 %.
    participation : (6,) array or None
        Those shares, dof order surge, sway, heave, roll, pitch, yaw.
    mode_shape : (6,) complex array or None
        Displacement shape of the critical mode at onset (largest component 1).
    thrust_max, operating_thrust : float, float or None
        Search range end and design thrust (N).
    undamped_thrust : float or None
        Critical thrust of the same model with every damper removed (equal to ``thrust`` for an
        undamped model); the gap shows destabilisation by damping.
    undamped_kind : str
    linearization : {"equilibrium", "classical"}
    crossings : tuple of Crossing
        All stability changes up to ``thrust_max`` (when requested).
    fluid_frequency_hz, fluid_iterations, fluid_change
        With compressible fluid loading: the frequency (Hz) at which the added mass and radiation
        damping were taken (consistent with the onset frequency), the number of fixed-point
        iterations, and the last relative change of the critical thrust.
    practical : PracticalOnset or None
        With a damping threshold (``analysis.min_damping_ratio`` or ``min_log_decrement``): the
        first thrust at which the least-damped mode's damping ratio falls to it
        (:mod:`impstab.linear.practical`); None without a threshold.
    """

    thrust: float | None
    kind: str
    omega: float | None
    modes: tuple[str, ...]
    participation: NDArray[np.float64] | None
    mode_shape: NDArray[np.complex128] | None
    thrust_max: float
    operating_thrust: float | None
    undamped_thrust: float | None
    undamped_kind: str
    linearization: str
    method: str
    crossings: tuple[Crossing, ...] = field(default_factory=tuple)
    model_name: str = ""
    fluid_frequency_hz: float | None = None
    fluid_iterations: int = 0
    fluid_change: float | None = None
    warnings: tuple[str, ...] = ()
    #: viscoelastic mounts: the onset of the Prony realisation checked on the exact laws
    #: (:func:`impstab.linear.viscoelastic.exact_onset`; None where every law is its own Prony
    #: series, standard linear solid or Prony: nothing is fitted), and the fits of the mounts' laws
    exact_onset: object | None = None
    viscoelastic_fits: tuple[dict, ...] = ()
    practical: PracticalOnset | None = None

    def __repr__(self) -> str:
        from ..display import critical_text

        return critical_text(self)

    def _repr_html_(self) -> str:
        from ..display import critical_html

        return critical_html(self)

    @property
    def frequency_hz(self) -> float | None:
        """Onset frequency ``omega / 2 pi`` (Hz)."""
        return None if self.omega is None else self.omega / (2 * np.pi)

    @property
    def margin(self) -> float | None:
        """``critical / operating`` (None without an operating thrust or a critical thrust)."""
        if self.thrust is None or not self.operating_thrust:
            return None
        return self.thrust / self.operating_thrust

    @property
    def practical_thrust(self) -> float | None:
        """Practical critical thrust (N): the least damping ratio falls to the threshold there;
        None without a threshold or when it is kept up to ``thrust_max``."""
        return None if self.practical is None else self.practical.load

    @property
    def practical_margin(self) -> float | None:
        """``practical critical / operating`` (None without either)."""
        p = self.practical_thrust
        if p is None or not self.operating_thrust:
            return None
        return p / self.operating_thrust

    def to_dict(self) -> dict:
        """The JSON object of ``impstab critical --json`` (DESIGN.md), plus extra keys."""
        from .. import __version__

        return {
            "critical_thrust": self.thrust,
            "kind": self.kind,
            "frequency_hz": self.frequency_hz,
            "omega": self.omega,
            "modes": list(self.modes),
            "thrust_max": self.thrust_max,
            "operating_thrust": self.operating_thrust,
            "margin": self.margin,
            "undamped_critical_thrust": self.undamped_thrust,
            "linearization": self.linearization,
            "undamped_kind": self.undamped_kind,
            "participation": None if self.participation is None else dict(zip(DOF_NAMES, map(float, self.participation))),
            "crossings": [c.__dict__ for c in self.crossings],
            "method": self.method,
            "fluid_frequency_hz": self.fluid_frequency_hz,
            "fluid_iterations": self.fluid_iterations,
            "fluid_change": self.fluid_change,
            "warnings": list(self.warnings),
            "viscoelastic": None if not self.viscoelastic_fits else {
                "undamped_stiffness": "static",
                "fits": list(self.viscoelastic_fits),
                "exact_check": None if self.exact_onset is None else self.exact_onset.to_dict(),
            },
            **self._practical_dict(),
            "model": self.model_name,
            "impstab_version": __version__,
        }

    def _practical_dict(self) -> dict:
        p = self.practical
        return {
            "practical_critical_thrust": self.practical_thrust,
            "practical_margin": self.practical_margin,
            "practical_kind": None if p is None else p.kind,
            "practical_frequency_hz": None if p is None else p.frequency_hz,
            "min_damping_ratio": None if p is None else p.damping_ratio,
            "min_log_decrement": None if p is None else p.log_decrement,
        }

    def to_json(self) -> str:
        from ..cli._common import jsonable

        return json.dumps(jsonable(self.to_dict()))


def operating_point_warnings(critical: float | None, operating: float | None, thrust_max: float) -> tuple[str, ...]:
    """What a critical-thrust result must say about the operating point: that the model is
    unstable there, or that the search did not reach it."""
    if operating is None:
        return ()
    if critical is not None and critical < operating:
        return (f"the model is unstable at its operating thrust {operating:g} N: stability is lost at "
                f"{critical:.6g} N (margin {critical / operating:.4g})",)
    if critical is None and thrust_max < operating:
        return (f"the search ends at {thrust_max:g} N, below the operating thrust {operating:g} N: "
                "stability at the operating point is not established",)
    return ()


def _modes(part: NDArray[np.float64] | None) -> tuple[str, ...]:
    if part is None:
        return ()
    return tuple(n for n, s in zip(DOF_NAMES, part) if s >= PARTICIPATION_THRESHOLD)


def _body_part(mode, participation):
    """The body's 6 dofs of a mode and its participation when the family carries internal mount
    dofs (massive beam mounts): the shares renormalised over the body dofs."""
    if mode is not None and len(mode) > 6:
        mode = mode[:6] / mode[:6][np.argmax(np.abs(mode[:6]))] if np.any(mode[:6]) else mode[:6]
    if participation is not None and len(participation) > 6:
        body = np.asarray(participation[:6], dtype=float)
        total = body.sum()
        participation = body / total if total > 0 else body
    return mode, participation


def critical_thrust(
    model: Model,
    *,
    thrust_max: float | None = None,
    linearization: str | None = None,
    n_scan: int = 64,
    all_crossings: bool = False,
    min_damping_ratio: float | None = None,
    min_log_decrement: float | None = None,
) -> CriticalThrust:
    """First loss of stability of ``model`` as the thrust grows from 0 to ``thrust_max``.

    Parameters
    ----------
    model : Model
    thrust_max : float, optional
        Upper end of the search (N); defaults to ``model.analysis.thrust_max``.
    linearization : {"equilibrium", "classical"}, optional
        Defaults to ``model.analysis.linearization``.
    n_scan : int
        Scan intervals before refinement (the refinement is exact; the scan only brackets).
    all_crossings : bool
        Also list every later loss and gain of stability (restabilisation) up to ``thrust_max``.
    min_damping_ratio, min_log_decrement : float, optional
        A damping threshold (one of the two; default the model's ``analysis`` keys): also find the
        practical critical thrust, the first thrust at which the least damping ratio
        ``-Re lambda / |lambda|`` falls to ``min_damping_ratio``, or the least logarithmic decrement
        ``-2 pi Re lambda / Im lambda`` to ``min_log_decrement`` (API 617 / 684 use 0.1).

    Returns
    -------
    CriticalThrust
    """
    t_max = check_number("thrust_max", thrust_max if thrust_max is not None else model.analysis.thrust_max, "thrust")
    search = dict(n_scan=n_scan)
    f_fluid, iterations, change = 0.0, 0, None
    fam = _family(model, linearization)
    res: CriticalLoad = critical_load_family(fam, t_max, all_crossings=all_crossings, **search)
    if model.fluid.compressible:
        # radiation damping and added mass at the onset frequency, iterated to consistency
        for iterations in range(1, FLUID_MAX_ITERATIONS + 1):
            if res.load is None or not res.omega:
                break
            f_new = res.omega / (2 * np.pi)
            fam = _family(model, linearization, fluid_frequency=f_new)
            new = critical_load_family(fam, t_max, all_crossings=all_crossings, **search)
            change = None if new.load is None else abs(new.load - res.load) / new.load
            res, f_fluid = new, f_new
            if change is not None and change <= FLUID_TOLERANCE:
                break
    if model.is_damped or (model.fluid.compressible and f_fluid > 0):
        und = critical_load_family(_undamped_family(model, linearization, f_fluid, fam), t_max, **search)
    else:
        und = res
    load, omega, check, fits, visco_notes = res.load, res.omega, None, (), ()
    if model.is_viscoelastic:
        load, omega, check, fits, visco_notes = _viscoelastic_check(model, res, fam.linearization, f_fluid, fam)
    notes = operating_point_warnings(load, model.thrust.operating, t_max)
    shape, part = _body_part(res.mode, res.participation)
    if min_damping_ratio is None and min_log_decrement is None:
        zeta = model.analysis.min_damping_ratio
    else:
        zeta = damping_threshold(min_damping_ratio, min_log_decrement)
    practical = None if zeta is None else _practical(model, linearization, t_max, zeta, n_scan, f_fluid)
    return CriticalThrust(
        thrust=load,
        kind=res.kind,
        omega=omega,
        modes=_modes(part),
        participation=part,
        mode_shape=shape,
        thrust_max=t_max,
        operating_thrust=model.thrust.operating,
        undamped_thrust=und.load,
        undamped_kind=und.kind,
        linearization=fam.linearization,  # type: ignore[arg-type]
        method=res.method,
        crossings=res.crossings,
        model_name=model.name,
        fluid_frequency_hz=f_fluid if model.fluid.compressible else None,
        fluid_iterations=iterations,
        fluid_change=change,
        warnings=notes + tuple(res.warnings) + visco_notes
        + tuple(f"undamped companion: {w}" for w in und.warnings if und is not res)
        + (() if practical is None else tuple(f"practical onset: {w}" for w in practical.warnings)),
        exact_onset=check,
        viscoelastic_fits=fits,
        practical=practical,
    )


# -- viscoelastic mounts: the augmented first-order family and the check on the exact law ---------
#: a correction by the exact law larger than this (relative) is not the same root: the Prony
#: value stays and a warning says so
EXACT_ACCEPT = 1e-2


def _family(model: Model, linearization: str | None, fluid_frequency: float = 0.0):
    """The elastic family, or the augmented first-order one of a model with viscoelastic mounts."""
    if model.is_viscoelastic:
        from .viscoelastic import ViscoelasticFamily

        return ViscoelasticFamily(model, linearization, fluid_frequency, reduced=True)
    return ModelFamily(model, linearization, fluid_frequency=fluid_frequency)


def _undamped_family(model: Model, linearization: str | None, f_fluid: float, family) -> ModelFamily:
    """The undamped companion's family: the viscoelastic family's elastic part (mounts at their
    static stiffness) where the model has no damper besides its viscoelastic laws, else built."""
    base = getattr(family, "base", None)
    if isinstance(base, ModelFamily) and not (base.packed.damp6.any() or base.packed.damping.any()):
        return base
    return ModelFamily(model, linearization, damped=False, fluid_frequency=f_fluid)


def _viscoelastic_check(model: Model, res: CriticalLoad, linearization: str, f_fluid: float, family=None):
    """``(thrust, omega, ExactOnset or None, fits, warnings)``: the onset of the Prony realisation solved
    again on the exact laws (Newton, :func:`~impstab.linear.viscoelastic.exact_onset`) where a law is
    fitted (fractional Zener, table); the exact root is reported when Newton converges to the same
    root. Where every law is its own Prony series there is no fit to check: ``None``."""
    from .viscoelastic import exact_onset

    fits = tuple(
        {"mount": i, "law": m.viscoelastic.law, "terms": m.viscoelastic.n_terms,
         "fit_error": m.viscoelastic.fit_error,
         "fit_band_hz": None if m.viscoelastic.fit_band_hz is None else m.viscoelastic.fit_band_hz.tolist(),
         "hysteretic": m.viscoelastic.hysteretic}
        for i, m in enumerate(model.mounts) if m.viscoelastic is not None
    )
    notes: list[str] = []
    if any(f["hysteretic"] for f in fits):
        notes.append("a tabulated loss factor that does not vanish at its lowest frequency is non-causal "
                     "(hysteretic): stability uses its causal Prony fit over the table band, and the onset "
                     "is solved again on the table itself at the onset frequency")
    if res.load is None:
        return None, res.omega, None, fits, tuple(notes)
    if all(m.viscoelastic.exact_series for m in model.mounts if m.viscoelastic is not None):
        # standard linear solids and Prony series: the augmented system is the law itself, and its
        # onset is already the root of the exact eigenproblem (nothing fitted to check)
        return res.load, res.omega, None, fits, tuple(notes)
    check = exact_onset(model, res.load, res.omega or 0.0, linearization, f_fluid, family)
    if check.exact_thrust is None:
        notes.append("Newton on the exact viscoelastic eigenproblem did not converge at the onset: "
                     "the value is that of the Prony realisation")
        return res.load, res.omega, check, fits, tuple(notes)
    if abs(check.thrust_difference) > EXACT_ACCEPT:
        notes.append(f"the exact viscoelastic law moves the onset by {check.thrust_difference:.2e} (relative), "
                     "more than a correction: the value is that of the Prony realisation; refine the fit "
                     "(fit_terms, fit_band_hz)")
        return res.load, res.omega, check, fits, tuple(notes)
    return check.exact_thrust, (check.exact_omega if res.omega else res.omega), check, fits, tuple(notes)


def _practical(model: Model, linearization: str | None, t_max: float, zeta: float, n_scan: int,
               f_fluid: float) -> PracticalOnset:
    """The practical onset (compressible fluid: coefficients at its own frequency, iterated)."""
    from .engine import solve

    def at(frequency: float) -> PracticalOnset:
        base, turned = practical_problem(_family(model, linearization, frequency), t_max, zeta,
                                         n_scan=n_scan)
        return practical_onset(base, solve([turned])[0], zeta)

    onset = at(f_fluid)
    if model.fluid.compressible:
        for _ in range(FLUID_MAX_ITERATIONS):
            if onset.load is None or not onset.omega:
                break
            new = at(onset.omega / (2 * np.pi))
            change = None if new.load is None or not new.load else abs(new.load - onset.load) / new.load
            onset = new
            if change is not None and change <= FLUID_TOLERANCE:
                break
    return onset
