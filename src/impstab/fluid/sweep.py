"""Baffled-cylinder coefficients over a range of frequencies, and their plot."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError
from .baffled_cylinder import baffled_cylinder
from .result import FluidCoefficients, check_nonnegative

__all__ = ["FrequencySweep", "frequency_sweep"]

_COLUMNS = (
    "frequency", "added_mass", "added_inertia", "radiation_resistance",
    "rotational_radiation_resistance", "strip_ratio", "inertia_strip_ratio", "loss_factor",
    "error_estimate",
)


@dataclass(frozen=True)
class FrequencySweep:
    """Coefficients of one segment at several frequencies (Hz), one :class:`FluidCoefficients` each."""

    points: tuple[FluidCoefficients, ...]

    def __repr__(self) -> str:
        from ..display import sweep_text

        return sweep_text(self)

    def column(self, name: str) -> NDArray[np.float64]:
        """One coefficient against frequency as a float array (None becomes NaN)."""
        return np.array([_nan(getattr(p, name)) for p in self.points], dtype=float)

    @property
    def frequency(self) -> NDArray[np.float64]:
        """Frequencies (Hz)."""
        return self.column("frequency")

    def to_xarray(self):
        """Dataset of every coefficient against ``frequency`` (Hz), each with its unit."""
        import xarray as xr

        from .. import __version__

        first = self.points[0]
        units = {"added_mass": ("kg", "transverse added mass m_a"),
                 "added_inertia": ("kg m^2", "added rotary inertia I_a about the segment centre"),
                 "radiation_resistance": ("N s/m", "radiation resistance R = Re Z_T"),
                 "rotational_radiation_resistance": ("N m s", "rotational radiation resistance R_rot = Re Z_R"),
                 "strip_ratio": ("1", "m_a / (rho pi a^2 L)"),
                 "inertia_strip_ratio": ("1", "I_a / (rho pi a^2 L^3 / 12)"),
                 "loss_factor": ("1", "R / (omega m_a)"),
                 "error_estimate": ("1", "relative error estimate")}
        data = {name: ("frequency", self.column(name), {"units": u, "long_name": text})
                for name, (u, text) in units.items()}
        attrs = {"title": f"{first.model} coefficients, a = {first.radius:g} m, L = {first.length:g} m",
                 "model": first.model, "radius_m": first.radius, "length_m": first.length,
                 "density_kg_m3": first.density, "impstab_version": __version__}
        if first.sound_speed is not None:
            attrs["sound_speed_m_s"] = first.sound_speed
        return xr.Dataset(data, coords={"frequency": ("frequency", self.frequency, {"units": "Hz"})}, attrs=attrs)

    def to_dict(self) -> dict[str, Any]:
        """Settings plus one list per coefficient (``None`` where a value does not exist)."""
        first = self.points[0]
        out: dict[str, Any] = {
            "model": first.model, "radius": first.radius, "length": first.length,
            "density": first.density, "sound_speed": first.sound_speed,
        }
        for name in _COLUMNS:
            out[name] = [getattr(p, name) for p in self.points]
        return out

    def plot(self, axes: Sequence[Any] | None = None) -> Any:
        """Draw the ratios to strip theory and the radiation resistances against frequency.

        Parameters
        ----------
        axes : pair of matplotlib Axes, optional
            Top: ``m_a`` and ``I_a`` over their strip values; bottom: ``R`` and ``R_rot``
            (log scale). Without axes a new ``matplotlib.figure.Figure`` is made (no pyplot,
            no backend is configured).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from ..plot.style import figure_style

        with figure_style():
            return self._draw(axes)

    def _draw(self, axes):
        if axes is None:
            from matplotlib.figure import Figure

            fig = Figure(figsize=(7.0, 6.0), layout="constrained")
            axes = fig.subplots(2, 1, sharex=True)
        top, bottom = axes
        f = self.frequency
        top.plot(f, self.column("strip_ratio"), label=r"$m_a / \rho\pi a^2 L$")
        top.plot(f, self.column("inertia_strip_ratio"), label=r"$I_a / (\rho\pi a^2 L^3/12)$")
        top.set_ylabel("ratio to strip theory")
        top.legend()
        first = self.points[0]
        top.set_title(f"baffled cylinder a = {first.radius:g} m, L = {first.length:g} m")
        for name, label in (("radiation_resistance", "R (N s/m)"), ("rotational_radiation_resistance", "R_rot (N m s)")):
            y = self.column(name)
            keep = np.isfinite(y) & (y > 0)
            if np.any(keep):
                bottom.semilogy(f[keep], y[keep], label=label)
        bottom.set_xlabel("frequency (Hz)")
        bottom.set_ylabel("radiation resistance")
        if bottom.get_legend_handles_labels()[0]:
            bottom.legend()
        return top.figure


def _nan(value: float | None) -> float:
    return np.nan if value is None else value


def frequency_sweep(
    radius: float,
    length: float,
    frequencies: Iterable[float],
    density: float = 1025.0,
    sound_speed: float | None = None,
    progress: Callable[[Iterable[float]], Iterable[float]] | None = None,
) -> FrequencySweep:
    """:func:`~impstab.fluid.baffled_cylinder` at each of ``frequencies`` (Hz).

    ``progress``, if given, wraps the list of frequencies (e.g. a progress bar).
    """
    values = [check_nonnegative("frequencies", f) for f in frequencies]
    if not values:
        raise ModelError("frequencies", [], "must hold at least one frequency")
    iterator = progress(values) if progress is not None else values
    points = tuple(baffled_cylinder(radius, length, density, sound_speed, f) for f in iterator)
    return FrequencySweep(points=points)
