"""Linear stability: linearization, eigenproblems, mode tracking, loci, critical loads, modal form."""

from .critical import CriticalLoad, Crossing, critical_load, critical_load_family
from .families import (
    CallableFamily, CallableFirstOrderFamily, FirstOrderFamily, LinearFamily, LinearFirstOrderFamily, SystemFamily,
)
from .linearize import ModelFamily, linearize
from .system import LinearSystem

__all__ = [
    "LinearSystem", "linearize", "ModelFamily", "LinearFamily", "CallableFamily", "SystemFamily",
    "FirstOrderFamily", "LinearFirstOrderFamily", "CallableFirstOrderFamily",
    "critical_load", "critical_load_family", "CriticalLoad", "Crossing",
]
