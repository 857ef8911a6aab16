"""Model: the validated file schema, the rigid body, mounts, thrust, propeller and fluid loading."""

from .assemble import load_model, model_from_dict
from .body import RigidBody
from .fluid import FluidLoading, Hull
from .model import DOF_NAMES, AnalysisSettings, Model
from .mounts import Mount
from .thrust import Propeller, Thrust

__all__ = [
    "load_model", "model_from_dict", "Model", "RigidBody", "Mount", "Thrust", "Propeller",
    "FluidLoading", "Hull", "AnalysisSettings", "DOF_NAMES",
]
