"""Drawing of result objects with matplotlib; imported lazily, nothing configured at import.

Every ``.plot(ax=None)`` of a result draws inside :func:`~impstab.plot.style.figure_style` (an
``rc_context``: your own rcParams are untouched outside it) and returns the matplotlib handle:
the Axes for a figure of one panel, a named tuple of Axes for a figure of several
(:class:`LocusAxes`, :class:`SimulationAxes`, :class:`StatisticsAxes`), each with a ``.figure``. See ``docs/figures.md``.
"""

from .handles import LocusAxes, SimulationAxes, StatisticsAxes

__all__ = ["LocusAxes", "SimulationAxes", "StatisticsAxes"]
