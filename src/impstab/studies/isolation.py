"""Isolation outputs of a chunk of designs, beside their stability outputs.

Every design is linearized at its isolation thrust (``[isolation] thrust``, else its operating
thrust, else 0) exactly as :func:`impstab.frequency_response` does it
(:func:`impstab.response.api.design_inputs`), and all designs of the chunk with the same number
of mounts are solved together in one call of the compiled harmonic kernel
(:func:`impstab.response.api.solve_designs`) over one frequency grid: the log-spaced grid of
``range_hz`` (``points`` frequencies), each named frequency, and 64 log-spaced frequencies over
each named band (both edges included). The static deflections and mount loads are those of
:func:`impstab.response.static_mount_loads`.

Outputs (per design):

* ``peak_transmissibility``, ``peak_frequency_hz``: the largest ``|F_hull| / |F_in|`` on the grid
  of ``range_hz`` and its frequency. A grid value: a resonance narrower than the grid spacing
  is underestimated; the error is at most the fall of the peak over half a step of the grid
  (for a mode of damping ratio zeta, about ``(pi step / (2 zeta))^2 / 8`` relative with
  ``step = ln(high/low)/(points-1)``);
* one output per ``[[isolation.at]]`` entry, named by it: the transmissibility at its
  ``frequency_hz``, or its largest value over its ``band_hz`` (the same grid rule);
* ``static_deflection`` (m), ``peak_mount_load`` (N): the largest static deflection ``|d_i|``
  and force ``|F_i|`` over the mounts at the isolation thrust.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError, NumericalError

__all__ = ["IsolationSettings", "IsolationPoint", "isolation_outputs", "isolation_output_info", "BAND_POINTS"]

#: frequencies of the grid over each named band
BAND_POINTS = 64


@dataclass(frozen=True)
class IsolationPoint:
    """A named output: the transmissibility at ``frequency_hz``, or its peak over ``band_hz``."""

    name: str
    frequency_hz: float | None = None
    band_hz: tuple[float, float] | None = None

    @property
    def description(self) -> str:
        if self.frequency_hz is not None:
            return f"force transmissibility |F_hull| / |F_in| at {self.frequency_hz:g} Hz"
        lo, hi = self.band_hz  # type: ignore[misc]
        return f"largest force transmissibility |F_hull| / |F_in| from {lo:g} to {hi:g} Hz"


@dataclass(frozen=True)
class IsolationSettings:
    """The ``[isolation]`` table of a study file, validated.

    Attributes
    ----------
    input : str or None
        Dof of the unit load at A; None: each design's ``excitation.input`` (sway by default).
    thrust : float or None
        Thrust of the isolation linearization (N); None: each design's operating thrust, else 0.
    range_hz : (low, high) or None
        Range of ``peak_transmissibility``.
    points : int
        Log-spaced frequencies over ``range_hz``.
    at : tuple of IsolationPoint
    """

    input: str | None = None
    thrust: float | None = None
    range_hz: tuple[float, float] | None = None
    points: int = 400
    at: tuple[IsolationPoint, ...] = ()

    def grid(self) -> tuple[NDArray, dict[str, slice]]:
        """All analysed frequencies (Hz) and, per output that reads a stretch of them, its slice."""
        parts: list[NDArray] = []
        where: dict[str, slice] = {}
        start = 0

        def add(name: str, f: NDArray) -> None:
            nonlocal start
            parts.append(np.asarray(f, dtype=float))
            where[name] = slice(start, start + len(parts[-1]))
            start += len(parts[-1])

        if self.range_hz is not None:
            add("peak_transmissibility", np.geomspace(*self.range_hz, self.points))
        for p in self.at:
            add(p.name, [p.frequency_hz] if p.frequency_hz is not None else np.geomspace(*p.band_hz, BAND_POINTS))
        return (np.concatenate(parts) if parts else np.zeros(0)), where


def isolation_output_info(settings: IsolationSettings | None, name: str) -> tuple[str, str] | None:
    """``(units, description)`` of a named isolation output, None if ``name`` is not one."""
    for p in () if settings is None else settings.at:
        if p.name == name:
            return "1", p.description
    return None


def settings_from_spec(spec, outputs: tuple[str, ...]) -> IsolationSettings | None:
    """Check the ``[isolation]`` table (pydantic :class:`~impstab.studies.schema.IsolationSpec` or
    None) against the outputs asked for; ModelError naming the key."""
    from .schema import OUTPUTS, RESPONSE_OUTPUTS

    if spec is None:
        if any(o in RESPONSE_OUTPUTS for o in outputs):
            bad = next(o for o in outputs if o in RESPONSE_OUTPUTS)
            raise ModelError("isolation.range_hz", None, f"is required for the output {bad!r} (the frequency range, Hz)")
        return None
    rng = None
    if spec.range_hz is not None:
        lo, hi = spec.range_hz
        if not 0.0 < lo < hi:
            raise ModelError("isolation.range_hz", list(spec.range_hz), "must be [low, high] with 0 < low < high (Hz, log-spaced grid)")
        rng = (float(lo), float(hi))
    elif any(o in RESPONSE_OUTPUTS for o in outputs):
        bad = next(o for o in outputs if o in RESPONSE_OUTPUTS)
        raise ModelError("isolation.range_hz", None, f"is required for the output {bad!r} (the frequency range, Hz)")
    points: list[IsolationPoint] = []
    for i, p in enumerate(spec.at):
        field = f"isolation.at[{i}]"
        if (p.frequency_hz is None) == (p.band_hz is None):
            raise ModelError(field, p.name, "needs exactly one of frequency_hz (Hz) and band_hz ([low, high], Hz)")
        if p.name in OUTPUTS or p.name in ("status", "message") or any(q.name == p.name for q in points):
            raise ModelError(f"{field}.name", p.name, "must differ from every output name and from the other isolation.at names")
        band = None
        if p.band_hz is not None:
            lo, hi = p.band_hz
            if not 0.0 < lo < hi:
                raise ModelError(f"{field}.band_hz", list(p.band_hz), "must be [low, high] with 0 < low < high (Hz)")
            band = (float(lo), float(hi))
        points.append(IsolationPoint(p.name, None if p.frequency_hz is None else float(p.frequency_hz), band))
    return IsolationSettings(spec.input, None if spec.thrust is None else float(spec.thrust), rng, spec.points, tuple(points))


def isolation_outputs(models: list, settings: IsolationSettings | None, names: tuple[str, ...]):
    """The isolation outputs ``names`` of every design.

    Parameters
    ----------
    models : list of Model or None
        The designs (None: skipped, NaN).
    settings : IsolationSettings or None
    names : tuple of str
        Outputs to compute (:data:`~impstab.studies.schema.ISOLATION_OUTPUTS` and ``at`` names).

    Returns
    -------
    values : dict of name -> (nd,) float array (NaN where not computed)
    messages : dict of design index -> str
        Why a design's isolation outputs could not be computed.
    """
    from ..model.model import DOF_NAMES
    from ..response.api import default_thrust, design_inputs, solve_designs
    from ..response.excitation import unit_load
    from ..response.static import static_mount_loads

    nd = len(models)
    values = {n: np.full(nd, np.nan) for n in names}
    messages: dict[int, str] = {}
    settings = settings or IsolationSettings()
    f, where = settings.grid()
    response_names = [n for n in names if n in where or n == "peak_frequency_hz"]
    if "peak_frequency_hz" in names and "peak_transmissibility" not in where:
        raise ModelError("isolation.range_hz", None, "is required for the output 'peak_frequency_hz'")
    static_names = [n for n in names if n in ("static_deflection", "peak_mount_load")]
    groups: dict[int, list[tuple[int, object, NDArray]]] = {}
    for j, model in enumerate(models):
        if model is None:
            continue
        try:
            t = default_thrust(model, settings.thrust)
            if static_names:
                st = static_mount_loads(model, t)
                if "static_deflection" in values:
                    values["static_deflection"][j] = float(st.deflection_magnitude.max())
                if "peak_mount_load" in values:
                    values["peak_mount_load"][j] = float(st.force_magnitude.max())
            if response_names:
                dof = settings.input or model.excitation.input
                if dof not in DOF_NAMES:
                    raise ModelError("isolation.input", dof, f"must be one of {list(DOF_NAMES)}")
                inputs = design_inputs(model, f, t)
                groups.setdefault(inputs.positions.shape[0], []).append((j, inputs, unit_load(dof)))
        except (ModelError, NumericalError, np.linalg.LinAlgError) as exc:
            for n in names:
                values[n][j] = np.nan
            messages[j] = f"isolation: {exc}"
    for members in groups.values():
        idx = np.array([m[0] for m in members])
        sol = solve_designs([m[1] for m in members], f, np.stack([m[2] for m in members])[:, None, :])
        trans = np.linalg.norm(sol.hull_force, axis=-1)  # |F_hull| per unit |F_in|
        for n, sl in where.items():
            wanted = n in values or (n == "peak_transmissibility" and "peak_frequency_hz" in values)
            if not wanted:
                continue
            part = trans[:, sl]
            k = np.argmax(np.where(np.isnan(part), -np.inf, part), axis=1)
            peak = part[np.arange(len(idx)), k]
            if n in values:
                values[n][idx] = peak
            if n == "peak_transmissibility" and "peak_frequency_hz" in values:
                values["peak_frequency_hz"][idx] = np.where(np.isnan(peak), np.nan, f[sl][k])
    return values, messages
