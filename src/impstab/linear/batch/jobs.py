"""Per-design jobs of a batched critical-thrust evaluation, and the result type."""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from ..critical import _Engine
from ..linearize import ModelFamily

Array = NDArray[np.float64]

#: kind codes: index in this tuple (-1: not available)
KINDS = ("none", "flutter", "divergence")
#: status codes: index in this tuple (-1: not computed)
STATUSES = ("ok", "invalid", "numerical_failure", "error")
_EPS4 = 4 * np.finfo(float).eps


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
        Returns the design's :class:`~impstab.linear.linearize.ModelFamily`, for the rare design
        that needs its own engine (called at most once).
    """

    mass: Array
    k0: Array
    k1: Array
    thrust_max: float
    operating: float
    family: Callable[[], ModelFamily]


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
    evaluations : int
        Eigenproblems solved in total.
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
    evaluations: int = 0

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
    def margin(self) -> Array:
        """``critical / operating`` (NaN without either)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.thrust / self.operating


class _PrimedEngine(_Engine):
    """An engine whose scan chunks were classified beforehand, in a batch with other designs."""

    def __init__(self, family: ModelFamily, p_max: float, job: "_Job") -> None:
        super().__init__(family, p_max)
        self.job = job

    def classify(self, p: Array):
        hit = self.job.primed(p)
        if hit is not None:  # counted by the job that classified it
            return hit
        return super().classify(p)


@dataclass(eq=False)
class _ScanTable:
    """The batched scan of many jobs: one row per job, grid points classified so far.

    ``flags (J, n_pts)`` unstable points, ``ind (J, n_pts, 2)`` the bubble indicators (NaN where
    not classified), ``length (J,)`` points classified (whole chunks of ``chunk`` points from 0).
    """

    flags: NDArray[np.bool_]
    ind: Array
    length: NDArray[np.int64]
    chunk: int


class _Stack(_Engine):
    """The engine's classification applied to a ready stack of operators (no engine set-up)."""

    def __init__(self, ops: Array | None, undamped: bool) -> None:  # noqa: D107
        self._ops = ops
        self.undamped = undamped
        self.evaluations = 0

    def operators(self, p: Array):
        return self._ops, None


@functools.lru_cache(maxsize=64)
def _grid(p_max: float, n_scan: int) -> Array:
    """The scan grid ``linspace(0, p_max, n_scan + 1)``, shared (read-only) by designs alike."""
    grid = np.linspace(0.0, p_max, n_scan + 1)
    grid.setflags(write=False)
    return grid


class _Job:
    """One critical-load search: a design, or the undamped companion of a damped design."""

    def __init__(self, family: ModelFamily, p_max: float, n_scan: int) -> None:
        self._family, self._factory, self.p_max = family, None, p_max
        self.grid = _grid(p_max, n_scan)
        self.table: _ScanTable | None = None
        self.row = -1  # in the scan table
        self.pack: tuple | None = None  # (a0, a1, BlockStructure) of the batch's affine jobs
        self.pack_row = -1
        self.evaluations = 0
        self._engine: _PrimedEngine | None = None
        parts = family.affine_parts()
        self.fast = parts is not None and not (np.any(parts[1] != 0) or np.any(parts[2] != 0))
        if self.fast:  # M^-1 K0 and M^-1 K1 are formed for all jobs at once (_operators)
            self.mass, self.k0, self.k1 = np.array(parts[0]), parts[3], parts[4]
        self.undamped = True if self.fast else self.engine().undamped

    @classmethod
    def affine(cls, design: AffineDesign, n_scan: int) -> "_Job":
        """A job of an undamped affine design given by its matrices (no model assembled).

        The model family is built from ``design.family`` only if the design needs its own engine.
        """
        job = cls.__new__(cls)
        job._family, job._factory, job.p_max = None, design.family, design.thrust_max
        job.grid = _grid(design.thrust_max, n_scan)
        job.table, job.row, job.pack, job.pack_row, job.evaluations, job._engine = None, -1, None, -1, 0, None
        job.fast, job.undamped = True, True
        job.mass, job.k0, job.k1 = design.mass, design.k0, design.k1
        return job

    @property
    def family(self) -> ModelFamily:
        if self._family is None:
            self._family = self._factory()
        return self._family

    def engine(self) -> _PrimedEngine:
        if self._engine is None:
            self._engine = _PrimedEngine(self.family, self.p_max, self)
        return self._engine

    def primed(self, p: Array) -> tuple | None:
        """The batched classification of the scan chunk ``p`` (the engine's), if it was made."""
        t = self.table
        if t is None or not len(p):
            return None
        start = int(np.searchsorted(self.grid, p[0]))
        stop = min(start + t.chunk, len(self.grid))
        if start % t.chunk or stop > t.length[self.row] or len(p) != stop - start or not np.array_equal(p, self.grid[start:stop]):
            return None
        return t.flags[self.row, start:stop], t.ind[self.row, start:stop]

    def point_op(self, x: float) -> Array:
        """The eigen-operator at one load, as the engine forms it."""
        if self.fast:
            return self.a0[None] + np.array([x])[:, None, None] * self.a1[None]
        return self.engine().operators(np.array([x]))[0]


def gather(jobs: list[_Job]) -> tuple:
    """``a0, a1`` stacks and block structure of affine jobs: rows of the pack they share.

    The pack is formed for all affine jobs of a batch at once (``scan._operators``);
    ``job.pack_row`` is a job's row in it (not its row in the scan table, ``job.row``).
    """
    pack = jobs[0].pack
    rows = np.array([j.pack_row for j in jobs])
    return pack[0][rows], pack[1][rows], pack[2].take(rows)
