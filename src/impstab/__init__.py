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

from . import _numba_cache
from .errors import ModelError, NumericalError

_numba_cache.install()  # compiled kernels cached outside the source tree (see impstab._numba_cache)

__all__ = [
    "__version__", "load_model", "Model", "linearize", "LinearSystem", "modes", "critical_thrust",
    "locus", "simulate", "critical_load", "modal_form", "load_study", "run_study", "open_study", "fluid", "ModelError", "NumericalError", "DOF_NAMES",
    "frequency_response", "excitation_response",
]

# The public names are imported on first use: ``import impstab`` (and ``impstab --version``)
# loads neither NumPy nor the numerics.
_LAZY = {
    "load_model": ("model", "load_model"),
    "Model": ("model", "Model"),
    "DOF_NAMES": ("model", "DOF_NAMES"),
    "linearize": ("linear", "linearize"),
    "LinearSystem": ("linear", "LinearSystem"),
    "critical_load": ("linear", "critical_load"),
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
    "fluid": ("fluid", None),
    "report": ("report", None),  # a subpackage; impstab.report(path, ...) is callable
}
__all__ += ["report"]


def _version() -> str:
    from importlib import metadata

    try:
        return metadata.version("impstab")
    except metadata.PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "0.0.0"


def __getattr__(name: str):
    if name == "__version__":
        value = _version()
    elif name in _LAZY:
        from importlib import import_module

        module, attr = _LAZY[name]
        value = import_module(f".{module}", __name__)
        if attr is not None:
            value = getattr(value, attr)
    else:
        raise AttributeError(f"module 'impstab' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
