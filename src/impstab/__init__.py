"""impstab: dynamic stability of soft-mounted integrated motor propulsors.

A propulsor on compliant mounts carries its own thrust as a follower force; above a critical
thrust two pairs of natural frequencies merge and it flutters. impstab builds the model, finds
the critical thrust and its mode, draws the eigenvalue loci and the time histories, and runs
design studies.

Conventions: SI units; dof order ``surge, sway, heave, roll, pitch, yaw`` of the reference
point A; eigenvalues ``lambda = sigma + i omega`` with growth rate ``sigma`` (1/s) and angular
frequency ``omega`` (rad/s); ``frequency_hz = omega / 2 pi``.
"""

from __future__ import annotations

from importlib import metadata as _metadata

from .errors import ModelError, NumericalError
from .linear import LinearSystem, critical_load, linearize
from .model import DOF_NAMES, Model, load_model

try:
    __version__ = _metadata.version("impstab")
except _metadata.PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0"

__all__ = [
    "__version__", "load_model", "Model", "linearize", "LinearSystem", "modes", "critical_thrust",
    "locus", "simulate", "critical_load", "modal_form", "load_study", "run_study", "open_study", "fluid", "ModelError", "NumericalError", "DOF_NAMES",
]

_LAZY = {
    "modes": ("linear.modes", "modes"),
    "critical_thrust": ("linear.critical_thrust", "critical_thrust"),
    "locus": ("linear.locus", "locus"),
    "modal_form": ("linear.modal_form", "modal_form"),
    "simulate": ("dynamics.simulate", "simulate"),
    "load_study": ("studies", "load_study"),
    "run_study": ("studies", "run_study"),
    "open_study": ("studies", "open_study"),
    "frequency_response": ("response", "frequency_response"),
    "excitation_response": ("response", "excitation_response"),
}
__all__ += ["frequency_response", "excitation_response"]


def __getattr__(name: str):
    if name == "fluid":
        from importlib import import_module

        return import_module(".fluid", __name__)
    if name in _LAZY:
        from importlib import import_module

        module, attr = _LAZY[name]
        value = getattr(import_module(f".{module}", __name__), attr)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'impstab' has no attribute {name!r}")
