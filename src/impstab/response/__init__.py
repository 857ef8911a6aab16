"""Forced response and vibration isolation: transmissibility, mount and hull forces, transmitted
power, one-third-octave band levels, static mount loads, the mount system's decoupling.

>>> import numpy as np, impstab
>>> from impstab.response import frequency_response
>>> model = impstab.load_model("examples/imp_isolation.toml")           # doctest: +SKIP
>>> res = frequency_response(model, np.linspace(1, 100, 400))           # doctest: +SKIP
>>> res.transmissibility, res.plot()                                    # doctest: +SKIP

Conventions: ``x(t) = Re(X e^{i omega t})``, frequencies in Hz, hull axes, dof order
``surge .. yaw`` of the reference point A (THEORY 1); see docs/isolation.md.
"""

from __future__ import annotations

from .api import MAX_FREQUENCIES, check_frequencies, excitation_response, frequency_response
from .bands import BandLevels, band_levels
from .core import HarmonicSolution, attachment_maps, harmonic_response
from .decoupling import DecouplingCheck, decoupling_check
from .excitation import ExcitationLines, excitation_lines
from .result import ForcedResponse
from .static import StaticMountLoads, static_loads_batch, static_mount_loads

__all__ = [
    "frequency_response", "excitation_response", "ForcedResponse", "harmonic_response", "HarmonicSolution",
    "attachment_maps", "band_levels", "BandLevels", "excitation_lines", "ExcitationLines", "static_mount_loads",
    "static_loads_batch", "StaticMountLoads", "decoupling_check", "DecouplingCheck", "check_frequencies",
    "MAX_FREQUENCIES",
]
