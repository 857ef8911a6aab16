"""What the sections of a model report share: the model, the options, the analyses done once."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

__all__ = ["ReportOptions", "ModelContext"]


@dataclass(frozen=True)
class ReportOptions:
    """Settings of a report (see :func:`impstab.report`).

    Attributes
    ----------
    simulation : bool
        Run the time histories (the slowest part of a report).
    duration : float or None
        Length of each time history (s); default: see :mod:`impstab.report.sections.simulation`.
    frequencies : array or None
        Frequencies (Hz) of the transmissibility; default from the natural frequencies.
    steps : int
        Thrust intervals of the locus.
    postcritical, statistics : result objects or None
        Results computed beforehand, shown instead of calling the providers.
    target_margin : float or None
        Required margin of a study's statistics (None: 1, when the search reaches the operating thrust).
    """

    simulation: bool = True
    duration: float | None = None
    frequencies: object = None
    steps: int = 200
    postcritical: object = None
    statistics: object = None
    target_margin: float | None = None


class ModelContext:
    """The model of a report and the analyses several sections draw from, each computed once."""

    def __init__(self, model, options: ReportOptions) -> None:
        self.model = model
        self.options = options

    @property
    def operating(self) -> float | None:
        """Operating thrust (N), None when the model gives none."""
        return self.model.thrust.operating

    @property
    def thrust(self) -> float:
        """Thrust of the operating-point analyses: the operating thrust, else 0 (N)."""
        return float(self.operating or 0.0)

    @property
    def damped(self) -> bool:
        """Whether the model dissipates: mount dampers or radiation damping of a compressible fluid."""
        return bool(self.model.is_damped or self.model.fluid.compressible)

    @cached_property
    def critical(self):
        from ...linear.critical_thrust import critical_thrust

        return critical_thrust(self.model)

    @cached_property
    def modal(self):
        from ...linear.modes import modes

        return modes(self.model, self.thrust)

    @cached_property
    def locus(self):
        from ...linear.locus import locus

        return locus(self.model, steps=self.options.steps, critical=True)

    @cached_property
    def natural_frequencies_hz(self) -> np.ndarray:
        """Damped natural frequencies at the operating thrust (Hz, > 0), ascending."""
        f = np.asarray(self.modal.frequency_hz, dtype=float)
        return np.sort(f[f > 0])
