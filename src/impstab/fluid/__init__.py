"""Fluid loading of the wetted hull: a cylinder segment in a rigid cylindrical baffle (THEORY 9).

>>> import impstab.fluid as fl
>>> r = fl.baffled_cylinder(radius=0.15, length=0.8, density=1025.0)
>>> round(r.added_mass, 3), round(r.added_inertia, 4)   # kg; kg m^2 about the segment centre
(47.196, 1.7864)
>>> round(fl.strip_theory(0.15, 0.8).added_mass, 3)     # rho pi a^2 L
57.962

Conventions: SI units; time factor ``e^{i omega t}``; ``frequency`` in Hz, ``omega`` in rad/s.
See ``docs/fluid.md`` for the formulas, the numerics and the validation.
"""

from __future__ import annotations

from .baffled_cylinder import baffled_cylinder, check_work, quadrature_nodes
from .impedance import incompressible_kernel, modal_impedance
from .result import FluidCoefficients
from .strip import strip_theory
from .sweep import FrequencySweep, frequency_sweep

__all__ = [
    "baffled_cylinder", "strip_theory", "FluidCoefficients", "frequency_sweep", "FrequencySweep",
    "modal_impedance", "incompressible_kernel", "quadrature_nodes", "check_work",
]
