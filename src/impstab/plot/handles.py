"""What ``.plot()`` returns: one Axes, or a named tuple of the Axes of a multi-panel figure.

Like python-control's plotting functions, a figure of several panels hands back all of its
Axes, so that they can be restyled, annotated or saved; a named tuple names each panel by what
it shows and unpacks like a plain tuple (``ax_f, ax_g = locus.plot()``).
"""

from __future__ import annotations

from typing import Any, NamedTuple

__all__ = ["LocusAxes", "SimulationAxes", "StatisticsAxes"]


class LocusAxes(NamedTuple):
    """The two panels of a locus figure: ``frequency`` (Hz) above ``growth`` (1/s)."""

    frequency: Any
    growth: Any

    @property
    def figure(self) -> Any:
        """The matplotlib Figure."""
        return self.frequency.figure


class SimulationAxes(NamedTuple):
    """Time histories: ``sway`` above ``pitch``; one Axes each for one run, an array of Axes
    (one per run, left to right) for several."""

    sway: Any
    pitch: Any

    @property
    def figure(self) -> Any:
        """The matplotlib Figure."""
        first = self.sway
        while isinstance(first, (list, tuple)) or hasattr(first, "shape"):
            first = first[0]
        return first.figure


class StatisticsAxes(NamedTuple):
    """The panels of the statistics of a sampled study: ``histogram``, ``ecdf`` and
    ``sensitivity`` (None when the study has no indices)."""

    histogram: Any
    ecdf: Any
    sensitivity: Any

    @property
    def figure(self) -> Any:
        """The matplotlib Figure."""
        return self.ecdf.figure
