"""Harmonic loads of a model's ``[excitation]`` at a thrust: discrete lines with their frequencies.

Each source gives lines ``(frequency_hz, load)``: ``load`` is the complex generalized load at A in
hull axes (N, N m), ``F(t) = Re(load e^{i omega t})``, ready for the solve. A source's force ``F``
and moment ``M`` act at a body point ``r`` in body axes; at the static pose ``R0`` they become
``load = blockdiag(R0, R0) [F; M + r x F]`` (the arm turns with the body, like the thrust's).

* Rotating unbalance (mass m at radius e): shaft rate ``Omega`` from the propeller speed law at
  the thrust (``Omega_op sqrt(T / T_op)`` for ``"sqrt-thrust"``), frequency ``|Omega| / 2 pi``,
  force ``m e Omega^2 (a1 cos(Omega t + phi) + a2 sin(Omega t + phi))`` turning in the plane normal
  to the thrust axis (:func:`plane_axes`) in the sense of the spin: amplitude
  ``m e Omega^2 (a1 - i sgn(Omega) a2) e^{i phi}``.
* Blade-rate load: frequency ``harmonic * blades * |Omega| / 2 pi``, force and moment amplitudes
  per component with their phases.
* Spectrum table: one line per row.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..model.model import Model

__all__ = ["ExcitationLines", "excitation_lines", "plane_axes", "shaft_rate", "unit_load"]

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class ExcitationLines:
    """Discrete harmonic loads at one thrust, in the order unbalance, blade rate, spectrum.

    Attributes
    ----------
    frequency_hz : (n,) Hz
    load : (n, 6) complex
        Generalized load at A, hull axes (N, N m).
    source : tuple of str
        Which key produced each line, e.g. ``"unbalance[0]"``, ``"blade_rate[1]"``, ``"spectrum[4]"``.
    shaft_rate : float
        Omega (rad/s) at the thrust.
    """

    frequency_hz: Array
    load: NDArray[np.complex128]
    source: tuple[str, ...]
    shaft_rate: float


def unit_load(dof: str) -> NDArray[np.complex128]:
    """The unit force or moment on ``dof`` at A, hull axes (N or N m), as a complex 6-vector."""
    from ..errors import ModelError
    from ..model.model import DOF_NAMES

    if dof not in DOF_NAMES:
        raise ModelError("input", dof, f"must be one of {list(DOF_NAMES)}")
    out = np.zeros(6, dtype=complex)
    out[DOF_NAMES.index(dof)] = 1.0
    return out


def plane_axes(direction: Array) -> tuple[Array, Array]:
    """Unit axes ``(a1, a2)`` of the plane normal to ``direction`` with ``(a1, a2, e)`` right-handed.

    ``a1`` is the body y axis projected onto the plane (the z axis when y is nearly along ``e``).
    For ``e = x``: ``a1 = y``, ``a2 = z``.
    """
    e = np.asarray(direction, dtype=float)
    e = e / np.linalg.norm(e)
    ref = np.array([0.0, 1.0, 0.0])
    a1 = ref - (ref @ e) * e
    if np.linalg.norm(a1) < 0.5:
        ref = np.array([0.0, 0.0, 1.0])
        a1 = ref - (ref @ e) * e
    a1 /= np.linalg.norm(a1)
    return a1, np.cross(e, a1)


def shaft_rate(model: Model, thrust: float) -> float:
    """Propeller speed Omega (rad/s) at ``thrust`` (N), by the model's speed law."""
    return float(model.propeller.spin(thrust, model.thrust.operating))


def _at_a(force: NDArray, moment: NDArray, point: Array, rotation: Array) -> NDArray[np.complex128]:
    """``blockdiag(R0, R0) [F; M + r x F]`` for complex body-axis ``F``, ``M`` at body point ``r``."""
    r = np.asarray(point, dtype=float)
    body = np.concatenate([force, moment + np.cross(r, force)])
    out = np.empty(6, dtype=complex)
    out[:3] = rotation @ body[:3]
    out[3:] = rotation @ body[3:]
    return out


def excitation_lines(model: Model, thrust: float, rotation: Array | None = None) -> ExcitationLines:
    """The lines of ``model.excitation`` at ``thrust`` (N) and static rotation ``rotation`` (default I)."""
    rot = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
    ex = model.excitation
    omega = shaft_rate(model, thrust)
    hz = abs(omega) / (2.0 * np.pi)
    freqs: list[float] = []
    loads: list[NDArray] = []
    sources: list[str] = []
    default_point = model.thrust.point
    if ex.unbalance:
        a1, a2 = plane_axes(model.thrust.direction)
        turn = a1 - 1j * np.sign(omega) * a2
        for i, u in enumerate(ex.unbalance):
            force = u.mass * u.eccentricity * omega**2 * turn * np.exp(1j * np.deg2rad(u.phase_deg))
            point = default_point if u.point is None else u.point
            freqs.append(hz)
            loads.append(_at_a(force, np.zeros(3, dtype=complex), point, rot))
            sources.append(f"unbalance[{i}]")
    for i, b in enumerate(ex.blade_rate):
        amp = b.amplitude * np.exp(1j * np.deg2rad(b.phase_deg))
        point = default_point if b.point is None else b.point
        freqs.append(b.harmonic * b.blades * hz)
        loads.append(_at_a(amp[:3], amp[3:], point, rot))
        sources.append(f"blade_rate[{i}]")
    if ex.spectrum is not None:
        s = ex.spectrum
        amp = s.amplitude * np.exp(1j * np.deg2rad(s.phase_deg))
        for j, f in enumerate(s.frequency_hz):
            freqs.append(float(f))
            loads.append(_at_a(amp[j, :3], amp[j, 3:], s.point, rot))
            sources.append(f"spectrum[{j}]")
    load = np.array(loads, dtype=complex).reshape(-1, 6)
    return ExcitationLines(np.array(freqs, dtype=float), load, tuple(sources), omega)
