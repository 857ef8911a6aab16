"""Forced response of a model: transfer functions of a unit load, and the model's excitation.

Both run the same linearization as the stability analysis (:func:`impstab.linearize`: static
equilibrium or classical, follower and preload stiffness, gyroscopics with the speed law, mount
dampers) and one stacked solve over all frequencies (:func:`impstab.response.core.harmonic_response`),
with compressible fluid coefficients at every frequency (:mod:`impstab.response.fluid`) and the
hull given by the model's ``[foundation]`` (rigid by default).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import ModelError
from ..linear.linearize import linearize
from ..linear.modes import modes
from ..linear.system import LinearSystem
from ..model.foundation import Foundation
from ..model.model import DOF_NAMES, Model
from ..model.beam_dynamic import LOST_DIGITS_WARNING
from .core import HarmonicSolution, harmonic_response
from .excitation import excitation_lines, shaft_rate, unit_load
from .fluid import fluid_dynamic_stiffness, fluid_spectrum
from .result import ForcedResponse

__all__ = ["frequency_response", "excitation_response", "check_frequencies", "MAX_FREQUENCIES", "default_thrust",
           "DesignInputs", "design_inputs", "solve_designs"]

#: most frequencies in one response (memory: about 1 kB per frequency with four mounts)
MAX_FREQUENCIES = 100_000
#: pivot ratio below which a frequency is reported as (nearly) singular
SINGULAR_PIVOT = 1e-12


def check_frequencies(frequencies: ArrayLike, field: str = "frequencies") -> NDArray[np.float64]:
    """Frequencies (Hz) as a 1-D float array, or a ModelError naming ``field``."""
    try:
        f = np.asarray(frequencies, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(field, frequencies, "must be a list of numbers (Hz)") from None
    f = np.atleast_1d(f)
    if f.ndim != 1:
        raise ModelError(field, f.shape, "must be a 1-D list of frequencies (Hz)")
    if f.size == 0 or f.size > MAX_FREQUENCIES:
        raise ModelError(field, f"{f.size} frequencies", f"must hold 1 to {MAX_FREQUENCIES} frequencies")
    bad = np.flatnonzero(~np.isfinite(f) | (f < 0))
    if bad.size:
        raise ModelError(field, float(f[bad[0]]), "frequencies must be finite and >= 0 (Hz)")
    return f + 0.0


def default_thrust(model: Model, thrust: float | None) -> float:
    """The thrust of a response: the given one, else the operating thrust, else 0 (N)."""
    if thrust is None:
        return float(model.thrust.operating or 0.0)
    t = float(thrust)
    if not np.isfinite(t) or t < 0:
        raise ModelError("thrust", thrust, "must be a finite number >= 0 (N)")
    return t


def _hull_stiffness(model: Model, foundation, f: NDArray) -> tuple[NDArray | None, str]:
    """``S (1, nf, nm)`` of the hull at each attachment (None: rigid) and a description."""
    nm = len(model.mounts)
    found = model.foundation if foundation is None else foundation
    per_mount = list(found) if isinstance(found, Sequence) else [found] * nm
    if len(per_mount) != nm:
        raise ModelError("foundation", f"{len(per_mount)} entries", f"needs one foundation per mount ({nm})")
    for i, fd in enumerate(per_mount):
        if not isinstance(fd, Foundation):
            raise ModelError(f"foundation[{i}]", type(fd).__name__, "must be an impstab.model.foundation.Foundation")
    if all(fd.rigid for fd in per_mount):
        return None, "rigid"
    s = np.stack([fd.dynamic_stiffness(f) for fd in per_mount], axis=-1)[None]
    kinds = sorted({fd.model for fd in per_mount})
    return s, "compliant (" + ", ".join(kinds) + "): isotropic point impedance per attachment, uncoupled"


@dataclass(frozen=True, eq=False)
class DesignInputs:
    """The arrays of one design that :func:`~impstab.response.core.harmonic_response` stacks.

    Attributes
    ----------
    linear : LinearSystem
        The linearization at the response thrust.
    positions : (nm, 3);  mount_stiffness, mount_damping : (nm, 6, 6)
    fluid : (nf, 6, 6) complex or None
        Frequency-dependent fluid part of the dynamic stiffness (compressible fluid only).
    hull : (nf, nm) complex or None
        Hull dynamic stiffness at each attachment (None: rigid).
    settings : dict
        ``fluid`` and ``foundation`` in words.
    viscoelastic : Model or None
        The model, when its mounts follow viscoelastic laws: their exact complex stiffness is then
        applied at each frequency (such a design is solved on its own).
    beams : tuple of (int, BeamMount, axis)
        The beam mounts with mass: each is its exact dynamic stiffness at every frequency
        (:mod:`impstab.response.beam`; such a design is solved on its own).
    """

    linear: LinearSystem
    positions: NDArray
    mount_stiffness: NDArray
    mount_damping: NDArray
    fluid: NDArray | None
    hull: NDArray | None
    settings: dict
    viscoelastic: Model | None = None
    beams: tuple = ()

    @property
    def alone(self) -> bool:
        """True when the design's mounts change with frequency (solved on its own)."""
        return self.viscoelastic is not None or bool(self.beams)


def design_inputs(model: Model, f: NDArray, thrust: float, linearization: str | None = None,
                  foundation=None) -> DesignInputs:
    """Linearize ``model`` at ``thrust`` and gather its response inputs at frequencies ``f`` (Hz).

    The single route from a model to the stacked arrays of :func:`harmonic_response`, used by
    :func:`frequency_response` (one design) and by design studies (many designs in one solve).
    """
    lin = linearize(model, thrust, linearization)
    settings: dict = {}
    fluid_extra = None
    spectrum = fluid_spectrum(model, f)
    if spectrum is not None:
        fluid_extra, _, _ = fluid_dynamic_stiffness(model, spectrum, lin.rotation)
        settings["fluid"] = (
            f"compressible baffled cylinder at every frequency ({spectrum.method}, {spectrum.evaluations} "
            f"evaluations, interpolation error <= {spectrum.interpolation_error:.1e}, "
            f"quadrature error <= {spectrum.quadrature_error:.1e}, relative)"
        )
    else:
        settings["fluid"] = model.fluid.model if model.fluid.model == "none" else f"{model.fluid.model} (frequency independent)"
    hull, hull_text = _hull_stiffness(model, foundation, f)
    settings["foundation"] = hull_text
    viscoelastic = None
    if model.is_viscoelastic:  # the exact complex stiffness k*(omega) of each mount at each frequency
        viscoelastic = model
        settings["mounts"] = "viscoelastic: the exact complex stiffness of each law at every frequency"
    beams = tuple((i, m.beam, m.axis) for i, m in enumerate(model.mounts) if m.is_massive_beam)
    if beams:
        from .beam import beam_lost_digits

        lost = beam_lost_digits(beams, 2.0 * np.pi * f)
        settings["mounts"] = (
            "beam mounts with mass: the exact dynamic stiffness of the continuous Timoshenko beam at every "
            f"frequency (transfer matrix, undamped material, up to {lost:.1f} digits lost to evanescent waves); "
            "hull force at the hull end of each beam")
        if lost > LOST_DIGITS_WARNING:
            settings["beam_warning"] = (
                f"the beam mounts' transfer matrices lose up to {lost:.1f} digits at the highest frequencies "
                "(evanescent bending waves over a long beam): the response there is inaccurate")
    return DesignInputs(
        linear=lin,
        positions=np.array([m.position for m in model.mounts], dtype=float).reshape(-1, 3),
        mount_stiffness=np.array([m.stiffness for m in model.mounts], dtype=float).reshape(-1, 6, 6),
        mount_damping=np.array([m.damping for m in model.mounts], dtype=float).reshape(-1, 6, 6),
        fluid=fluid_extra, hull=None if hull is None else hull[0], settings=settings,
        viscoelastic=viscoelastic, beams=beams,
    )


def solve_designs(designs: Sequence[DesignInputs], f: NDArray, loads: NDArray):
    """One :func:`harmonic_response` over designs of the same mount count (a shared frequency grid).

    ``loads`` is ``(6,)``, ``(nf, 6)`` or ``(nd, nf, 6)``. Designs without fluid or foundation
    terms get zeros (fluid) or an infinite hull stiffness (rigid) beside those that have them.
    """
    stack = lambda name: np.stack([getattr(d, name) for d in designs])  # noqa: E731
    lin = lambda name: np.stack([getattr(d.linear, name) for d in designs])  # noqa: E731
    nm = designs[0].positions.shape[0]
    fluid = None
    if any(d.fluid is not None for d in designs):
        fluid = np.stack([np.zeros((f.size, 6, 6), complex) if d.fluid is None else d.fluid for d in designs])
    hull = None
    if any(d.hull is not None for d in designs):
        hull = np.stack([np.full((f.size, nm), np.inf, complex) if d.hull is None else d.hull for d in designs])
    if len(designs) > 1 and any(d.alone for d in designs):  # frequency-dependent mounts: one by one
        loads = np.asarray(loads, dtype=complex)
        parts = [solve_designs([d], f, loads[j:j + 1] if loads.ndim == 3 and loads.shape[0] > 1 else loads)
                 for j, d in enumerate(designs)]
        return HarmonicSolution(omega=parts[0].omega, **{
            name: np.concatenate([getattr(p, name) for p in parts], axis=0)
            for name in HarmonicSolution.__dataclass_fields__ if name != "omega"})
    respond = harmonic_response
    if designs[0].viscoelastic is not None:
        from functools import partial

        from .viscoelastic import viscoelastic_harmonic_response

        respond = partial(viscoelastic_harmonic_response, designs[0].viscoelastic)
    elif designs[0].beams:
        from functools import partial

        from .beam import beam_harmonic_response

        respond = partial(beam_harmonic_response, designs[0].beams)
    return respond(
        lin("M"), lin("D"), lin("G"), lin("K"), lin("rotation"), stack("positions"), stack("mount_stiffness"),
        stack("mount_damping"), 2.0 * np.pi * f, loads, fluid=fluid, foundation=hull,
        fluid_damping=np.zeros((len(designs), 6, 6)),  # linearize takes the fluid at 0 Hz: no radiation damping in D
    )


def _respond(model: Model, f: NDArray, loads: NDArray, thrust: float, linearization: str | None, foundation,
             input_name: str, source: tuple[str, ...]) -> ForcedResponse:
    inputs = design_inputs(model, f, thrust, linearization, foundation)
    lin = inputs.linear
    settings: dict = {"model": model.name, "model_source": model.source or "", **inputs.settings}
    sol = solve_designs([inputs], f, loads[None])
    md = modes(model, thrust, linearization)
    body = np.array([kind == "body" for kind in md.kind], dtype=bool)
    if not body.all():  # massive beam mounts: their internal modes are counted, not listed
        internal = md.frequency_hz[~body]
        settings["internal_mount_modes"] = (
            f"{internal.size} internal modes of the beam mounts (finite elements {', '.join(map(str, md.mount_elements))}"
            f" per beam), the lowest at {internal.min():.6g} Hz: peaks of the exact response, not listed below")
    warnings: list[str] = []
    if "beam_warning" in settings:
        warnings.append(settings.pop("beam_warning"))
    if not md.stable:
        j = int(np.argmax(md.growth_rate))
        warnings.append(
            f"the linearized system is unstable at T = {thrust:g} N (growth rate {md.growth_rate[j]:.4g} 1/s at "
            f"{md.frequency_hz[j]:.4g} Hz): no steady forced response exists; the values are the formal transfer function"
        )
    sing = np.flatnonzero(sol.pivot_ratio[0] < SINGULAR_PIVOT)
    if sing.size:
        warnings.append(
            f"the dynamic stiffness is singular or nearly so at {sing.size} frequencies (first {f[sing[0]]:.6g} Hz, "
            "an undamped resonance): the response there is unbounded or inaccurate"
        )
    from .. import __version__

    settings["impstab_version"] = __version__
    return ForcedResponse(
        frequency_hz=f, load=np.broadcast_to(loads, (f.size, 6)).copy(), response=sol.response[0],
        mount_deflection=sol.deflection[0], hull_displacement=sol.hull_displacement[0], mount_force=sol.mount_force[0],
        hull_force=sol.hull_force[0], power_input=sol.power_input[0], power_thrust=sol.power_thrust[0],
        power_fluid=sol.power_fluid[0], power_damper=sol.power_damper[0], power_transmitted=sol.power_transmitted[0],
        pivot_ratio=sol.pivot_ratio[0], thrust=float(thrust), linearization=lin.linearization, input=input_name,
        shaft_rate=shaft_rate(model, thrust), source=source, mode_frequency_hz=md.frequency_hz[body],
        mode_growth_rate=md.growth_rate[body], mode_dominant=tuple("/".join(d) for j, d in enumerate(md.dominant()) if body[j]),
        settings=settings, warnings=tuple(warnings),
    )


def frequency_response(
    model: Model,
    frequencies: ArrayLike,
    *,
    thrust: float | None = None,
    input: str | None = None,
    linearization: str | None = None,
    foundation: Foundation | Sequence[Foundation] | None = None,
) -> ForcedResponse:
    """Response to a unit harmonic force or moment at A on one dof, at each frequency.

    Parameters
    ----------
    model : Model
    frequencies : array_like
        Frequencies (Hz), finite and >= 0, at most :data:`MAX_FREQUENCIES`.
    thrust : float, optional
        Thrust of the linearization (N); default the operating thrust, else 0.
    input : str, optional
        Dof of the unit load (hull axes, at A): a force (N) on surge/sway/heave, a moment (N m)
        on roll/pitch/yaw. Default ``model.excitation.input`` (sway unless the model says).
    linearization : {"equilibrium", "classical"}, optional
        Override the model's setting.
    foundation : Foundation or sequence of Foundation, optional
        The hull at the attachments (one for all mounts, or one per mount); default the model's.

    Returns
    -------
    ForcedResponse
        ``.transmissibility`` is ``|F_hull| / |F_in|`` (N/N; N/(N m) for a moment input).
    """
    f = check_frequencies(frequencies)
    t = default_thrust(model, thrust)
    dof = model.excitation.input if input is None else input
    if dof not in DOF_NAMES:
        raise ModelError("input", dof, f"must be one of {list(DOF_NAMES)}")
    return _respond(model, f, unit_load(dof)[None, :], t, linearization, foundation, dof, ())


def excitation_response(
    model: Model,
    *,
    thrust: float | None = None,
    linearization: str | None = None,
    foundation: Foundation | Sequence[Foundation] | None = None,
) -> ForcedResponse:
    """Response to the model's ``[excitation]`` (unbalance, blade rate, spectrum lines) at a thrust.

    One entry per line (``.source`` names its key), sorted as the lines are listed; ``.bands()``
    gives the one-third-octave levels of the hull force. Parameters as :func:`frequency_response`.
    """
    t = default_thrust(model, thrust)
    if not model.excitation.has_loads:
        raise ModelError("excitation", None, "the model has no [excitation] loads (unbalance, blade_rate or spectrum)")
    lin = linearize(model, t, linearization)
    lines = excitation_lines(model, t, lin.rotation)
    f = check_frequencies(lines.frequency_hz, "excitation")
    return _respond(model, f, lines.load, t, linearization, foundation, "excitation", lines.source)
