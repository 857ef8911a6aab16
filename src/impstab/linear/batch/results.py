"""Inputs and results of a batched critical-thrust evaluation."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from ..linearize import ModelFamily

Array = NDArray[np.float64]

#: kind codes: index in this tuple (-1: not available)
KINDS = ("none", "flutter", "divergence")
#: status codes: index in this tuple (-1: not computed)
STATUSES = ("ok", "invalid", "numerical_failure", "error")


@dataclass(frozen=True, eq=False)
class AffineDesign:
    """A design given by its matrices: undamped, non-gyroscopic, ``K = K0 + T K1`` exactly.

    Attributes
    ----------
    mass, k0, k1 : (6, 6) arrays
        ``M`` (kg, kg m, kg m^2), ``K0`` and ``K1`` (stiffness and its rate per newton of thrust).
    thrust_max : float
        End of the thrust search (N).
    operating : float
        Operating thrust (N; NaN without one).
    family : callable
        Returns the design's :class:`~impstab.linear.linearize.ModelFamily` (the engine itself
        needs only the matrices; the family is there for callers that want the model's view).
    """

    mass: Array
    k0: Array
    k1: Array
    thrust_max: float
    operating: float
    family: Callable[[], ModelFamily]


@dataclass(frozen=True, eq=False)
class AffineStack:
    """Designs given by their matrices, stacked: each undamped, non-gyroscopic, ``K = K0 + T K1``.

    The form in which a design study's bulk assembly hands a chunk's designs to
    :func:`~impstab.linear.batch.critical_thrust_batch` (its ``affine`` argument): the engine
    takes the stacks as they are, with no object per design.

    Attributes
    ----------
    rows : (J,) int array
        The designs' positions in the batch.
    mass, k0, k1 : (J, 6, 6) arrays
        ``M`` (kg, kg m, kg m^2), ``K0`` and ``K1`` of each design, as in :class:`AffineDesign`.
    thrust_max, operating : (J,) arrays
        End of the thrust search and operating thrust (N; NaN without one).
    """

    rows: NDArray[np.intp]
    mass: Array
    k0: Array
    k1: Array
    thrust_max: Array
    operating: Array

    def __len__(self) -> int:
        return len(self.rows)

    def take(self, which) -> "AffineStack":
        """The designs at positions ``which`` of this stack (an index array or a slice)."""
        return AffineStack(*(np.asarray(getattr(self, f))[which] for f in _STACKED))

    @staticmethod
    def of(rows, designs: list[AffineDesign]) -> "AffineStack":
        """The stack of separate :class:`AffineDesign` objects at ``rows`` of the batch."""
        return AffineStack(np.asarray(rows, dtype=np.intp), np.stack([d.mass for d in designs]),
                           np.stack([d.k0 for d in designs]), np.stack([d.k1 for d in designs]),
                           np.array([d.thrust_max for d in designs], dtype=float),
                           np.array([d.operating for d in designs], dtype=float))

    @staticmethod
    def joined(parts: list["AffineStack"]) -> "AffineStack":
        """One stack of the designs of ``parts``, in order."""
        return AffineStack(*(np.concatenate([getattr(p, f) for p in parts]) for f in _STACKED))


_STACKED = ("rows", "mass", "k0", "k1", "thrust_max", "operating")


@dataclass(frozen=True, eq=False)
class BatchCriticalThrust:
    """Critical thrusts of a batch of designs, one entry per design.

    Attributes
    ----------
    thrust, omega : (N,) float arrays
        Critical thrust (N) and angular frequency at onset (rad/s); NaN when the design has none
        up to its ``thrust_max`` or failed.
    kind, undamped_kind : (N,) int8 arrays
        Codes into :data:`KINDS`; -1 for a failed design.
    undamped_thrust : (N,) float array
        Critical thrust with every damper removed (N).
    thrust_max, operating : (N,) float arrays
        Search range end and operating thrust (N; NaN without one).
    modes : list of str
        Dofs with at least 5 % of the kinetic energy of the critical mode, comma-separated.
    status : (N,) int8 array
        Codes into :data:`STATUSES`.
    message : list of str
        Empty when ``status`` is 0, else a one-line reason.
    practical_thrust : (N,) float array
        Practical critical thrust (N; :mod:`impstab.linear.practical`): the least damping ratio
        falls to the design's ``analysis.min_damping_ratio`` there; NaN without a threshold, when
        the threshold is kept up to ``thrust_max``, or for a failed design.
    evaluations : int
        Eigenproblems solved in total.
    decompositions, pair_problems : int
        Of those, the designs given by their matrices (:class:`AffineDesign`) solved with
        eigenvectors, and with the right and left vectors of two eigenvalues only.
    """

    thrust: Array
    kind: NDArray[np.int8]
    omega: Array
    undamped_thrust: Array
    undamped_kind: NDArray[np.int8]
    thrust_max: Array
    operating: Array
    modes: list[str]
    status: NDArray[np.int8]
    message: list[str]
    practical_thrust: Array | None = None
    evaluations: int = 0
    decompositions: int = 0
    pair_problems: int = 0

    def __repr__(self) -> str:
        from ...display import batch_text

        return batch_text(self)

    def _repr_html_(self) -> str:
        from ...display import batch_html

        return batch_html(self)

    @property
    def frequency_hz(self) -> Array:
        """Onset frequency ``omega / 2 pi`` (Hz)."""
        return self.omega / (2.0 * np.pi)

    @property
    def practical_margin(self) -> Array:
        """``practical critical / operating`` (NaN without either)."""
        p = np.full(self.thrust.shape, np.nan) if self.practical_thrust is None else self.practical_thrust
        with np.errstate(invalid="ignore", divide="ignore"):
            return p / self.operating

    @property
    def margin(self) -> Array:
        """``critical / operating`` (NaN without either)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.thrust / self.operating
