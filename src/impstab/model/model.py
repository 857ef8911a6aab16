"""The assembled propulsor model: a frozen, picklable description in SI units."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from .body import RigidBody
from .excitation import Excitation
from .fluid import FluidLoading, Hull
from .foundation import Foundation
from .mounts import Mount, elastic_stiffness, mount_damping
from .thrust import Propeller, Thrust

__all__ = ["Model", "AnalysisSettings", "DOF_NAMES", "LINEARIZATIONS"]

Array = NDArray[np.float64]

DOF_NAMES = ("surge", "sway", "heave", "roll", "pitch", "yaw")
LINEARIZATIONS = ("equilibrium", "classical")


@dataclass(frozen=True)
class AnalysisSettings:
    """Settings of the stability analysis.

    Parameters
    ----------
    thrust_max : float
        Upper end of the critical-thrust search (N).
    linearization : {"equilibrium", "classical"}
        ``"equilibrium"`` linearizes at the nonlinear static equilibrium under thrust (default);
        ``"classical"`` at the undeformed configuration, exactly linear in thrust (paper eq. 21).
    min_damping_ratio : float or None
        Damping-ratio threshold of the practical critical thrust (from ``min_damping_ratio``, or
        converted from ``min_log_decrement``); None: no practical criterion.
    """

    thrust_max: float
    linearization: str = "equilibrium"
    min_damping_ratio: float | None = None


@dataclass(frozen=True, eq=False)
class Model:
    """A soft-mounted propulsor: rigid body, mounts, thrust, propeller and fluid loading.

    Build it in code or with :func:`impstab.load_model`. It is immutable and never re-validated;
    :meth:`with_` returns a modified copy.
    """

    body: RigidBody
    mounts: tuple[Mount, ...]
    thrust: Thrust
    analysis: AnalysisSettings
    propeller: Propeller = field(default_factory=Propeller)
    fluid: FluidLoading = field(default_factory=FluidLoading)
    hull: Hull | None = None
    name: str = "model"
    source: str | None = None
    excitation: Excitation = field(default_factory=Excitation)
    foundation: Foundation = field(default_factory=Foundation)

    def __repr__(self) -> str:
        from ..display import model_text

        return model_text(self)

    def _repr_html_(self) -> str:
        from ..display import model_html

        return model_html(self)

    def __post_init__(self) -> None:
        object.__setattr__(self, "mounts", tuple(self.mounts))

    def with_(self, **changes: object) -> "Model":
        """A copy with some fields replaced (``dataclasses.replace``)."""
        return replace(self, **changes)

    @property
    def mass_matrix(self) -> Array:
        """Total 6 x 6 mass matrix about A at rest: rigid body plus added mass (body frame)."""
        return self.body.mass_matrix() + self.fluid.added_mass

    @property
    def elastic_stiffness(self) -> Array:
        """Condensed elastic mount stiffness ``K_c`` about A at rest."""
        return elastic_stiffness(self.mounts)

    @property
    def damping_matrix(self) -> Array:
        """Condensed mount damping ``D`` about A at rest."""
        return mount_damping(self.mounts)

    @property
    def is_nonlinear(self) -> bool:
        """True when a mount carries a nonlinear law (cubic springs or a snubber)."""
        return any(m.is_nonlinear for m in self.mounts)

    @property
    def is_damped(self) -> bool:
        """True when a mount has a damper or a viscoelastic law (which dissipates too)."""
        return self.is_viscoelastic or any(m.damping.any() for m in self.mounts)

    @property
    def has_massive_beams(self) -> bool:
        """True when a mount is a beam with mass (internal dofs in the linear analyses, kept modes
        in the time histories)."""
        return any(m.is_massive_beam for m in self.mounts)

    @property
    def is_viscoelastic(self) -> bool:
        """True when a mount carries a viscoelastic law (internal variables in the linear analyses)."""
        return any(m.viscoelastic is not None for m in self.mounts)

    def undamped(self) -> "Model":
        """The same model with every mount damper removed and every viscoelastic mount elastic at
        its static stiffness."""
        mounts = tuple(replace(m, damping=np.zeros((6, 6)), viscoelastic=None) for m in self.mounts)
        return replace(self, mounts=mounts)
