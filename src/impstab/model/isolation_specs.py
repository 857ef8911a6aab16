"""Assembly of the ``[excitation]`` and ``[foundation]`` tables: the rules that involve several keys.

Types, shapes, signs and finiteness are checked by the schema; here every cross-key rule fails
with a :class:`~impstab.errors.ModelError` naming the field, the value and the rule.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .excitation import BladeRate, Excitation, SpectrumLines, Unbalance
from .foundation import Foundation
from .thrust import Propeller

__all__ = ["excitation_from_spec", "foundation_from_spec"]


def _nonnegative_rows(rows, field: str) -> np.ndarray:
    arr = np.asarray(rows, dtype=float)
    bad = np.argwhere(arr < 0)
    if bad.size:
        loc = "".join(f"[{int(i)}]" for i in bad[0])
        raise ModelError(f"{field}{loc}", float(arr[tuple(bad[0])]), "amplitudes must be >= 0 (give the sign as a phase of 180 deg)")
    return arr


def excitation_from_spec(spec, propeller: Propeller) -> Excitation:
    """An :class:`Excitation` from a validated ``ExcitationSpec`` (or the empty one for None)."""
    if spec is None:
        return Excitation()
    if (spec.unbalance or spec.blade_rate) and propeller.speed == 0.0:
        field = "excitation.unbalance" if spec.unbalance else "excitation.blade_rate"
        raise ModelError(field, "given", "needs the shaft rate: set propeller.speed (rad/s at the operating thrust)")
    unbalance = tuple(Unbalance(u.mass, u.eccentricity, u.point, u.phase_deg) for u in spec.unbalance)
    blades = []
    for i, b in enumerate(spec.blade_rate):
        amp = _nonnegative_rows(b.amplitude, f"excitation.blade_rate[{i}].amplitude")
        blades.append(BladeRate(b.blades, amp, b.phase_deg, b.harmonic, b.point))
    spectrum = None
    if spec.spectrum is not None:
        s = spec.spectrum
        n = len(s.frequency_hz)
        for key in ("amplitude", "phase_deg"):
            rows = getattr(s, key)
            if rows is not None and len(rows) != n:
                raise ModelError(f"excitation.spectrum.{key}", f"{len(rows)} rows",
                                 f"needs one row of 6 values per frequency ({n} in frequency_hz)")
        amp = _nonnegative_rows(s.amplitude, "excitation.spectrum.amplitude")
        spectrum = SpectrumLines(np.asarray(s.frequency_hz, float), amp, s.phase_deg, s.point)
    return Excitation(spec.input, unbalance, tuple(blades), spectrum)


_LUMPED = ("mass", "stiffness", "damping")
_TABLES = {"mobility-table": ("mobility_real", "mobility_imag"), "impedance-table": ("impedance_real", "impedance_imag")}


def foundation_from_spec(spec) -> Foundation:
    """A :class:`Foundation` from a validated ``FoundationSpec`` (rigid for None)."""
    if spec is None or spec.model == "rigid":
        if spec is not None:
            _only(spec, ())
        return Foundation()
    if spec.model == "lumped":
        _only(spec, _LUMPED)
        if spec.mass == 0.0 and spec.stiffness == 0.0 and spec.damping == 0.0:
            raise ModelError("foundation", "lumped", "needs mass, stiffness or damping > 0 (or model = 'rigid')")
        return Foundation("lumped", spec.mass, spec.stiffness, spec.damping)
    real_key, imag_key = _TABLES[spec.model]
    _only(spec, ("frequency_hz", real_key, imag_key))
    if spec.frequency_hz is None:
        raise ModelError("foundation.frequency_hz", None, f"is required with foundation.model = {spec.model!r}")
    f = np.asarray(spec.frequency_hz, float)
    if f.size < 2 or np.any(np.diff(f) <= 0):
        raise ModelError("foundation.frequency_hz", spec.frequency_hz, "must hold at least 2 strictly increasing frequencies (Hz)")
    parts = []
    for key in (real_key, imag_key):
        v = getattr(spec, key)
        if v is None:
            raise ModelError(f"foundation.{key}", None, f"is required with foundation.model = {spec.model!r}")
        if len(v) != f.size:
            raise ModelError(f"foundation.{key}", f"{len(v)} values", f"needs one value per frequency ({f.size})")
        parts.append(np.asarray(v, float))
    values = parts[0] + 1j * parts[1]
    neg = np.flatnonzero(values.real < 0)
    if neg.size:
        raise ModelError(f"foundation.{real_key}[{neg[0]}]", float(values.real[neg[0]]),
                         "must be >= 0 (a passive hull absorbs power)")
    if spec.model == "mobility-table":
        zero = np.flatnonzero(values == 0)
        if zero.size:
            raise ModelError(f"foundation.{real_key}[{zero[0]}]", 0.0,
                             "a mobility of 0 is a rigid point: give a non-zero value or use model = 'rigid'")
    return Foundation(spec.model, frequency_hz=f, values=values)


def _only(spec, allowed: tuple[str, ...]) -> None:
    """Reject keys of another foundation model (they would be silently ignored)."""
    defaults = {"mass": 0.0, "stiffness": 0.0, "damping": 0.0}
    for key in (*_LUMPED, "frequency_hz", *_TABLES["mobility-table"], *_TABLES["impedance-table"]):
        if key in allowed:
            continue
        value = getattr(spec, key)
        if value is not None and value != defaults.get(key):
            raise ModelError(f"foundation.{key}", value, f"is not read with foundation.model = {spec.model!r}")
