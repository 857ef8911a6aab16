"""Chunk planning: the study's design array cut into blocks of about ``chunk_size`` designs.

A chunk is a rectangular block of the design array (the store's chunks are the same blocks), so
that each chunk is written, marked done and resumed on its own. Chunks are numbered in C order
of the chunk grid; the designs inside a chunk in C order of the block.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .study import Study

__all__ = ["ChunkPlan", "plan_chunks", "chunk_shape"]


def chunk_shape(shape: tuple[int, ...], target: int) -> tuple[int, ...]:
    """Block shape of at most ``target`` designs, filled from the last dimension backwards."""
    out = [1] * len(shape)
    room = max(int(target), 1)
    for k in range(len(shape) - 1, -1, -1):
        out[k] = max(1, min(shape[k], room))
        room //= out[k]
        if room <= 1:
            break
    return tuple(out)


@dataclass(frozen=True)
class ChunkPlan:
    """The blocks of a design array of shape ``shape`` cut by ``chunks``."""

    shape: tuple[int, ...]
    chunks: tuple[int, ...]

    @property
    def grid(self) -> tuple[int, ...]:
        """Number of chunks along each dimension."""
        return tuple(-(-s // c) for s, c in zip(self.shape, self.chunks))

    @property
    def n_chunks(self) -> int:
        return int(np.prod(self.grid))

    def slices(self, index: int) -> tuple[slice, ...]:
        """The block of chunk ``index`` as one slice per dimension."""
        pos = np.unravel_index(index, self.grid)
        return tuple(slice(int(p) * c, min((int(p) + 1) * c, s)) for p, c, s in zip(pos, self.chunks, self.shape))

    def block_shape(self, index: int) -> tuple[int, ...]:
        return tuple(s.stop - s.start for s in self.slices(index))

    def design_columns(self, study: Study, index: int) -> list[np.ndarray]:
        """Each parameter's value at every design of chunk ``index`` (flattened, C order)."""
        sl = self.slices(index)
        if study.method != "grid":
            return [p.values[sl[0]] for p in study.parameters]
        axes = [p.values[s] for p, s in zip(study.parameters, sl)]
        mesh = np.meshgrid(*axes, indexing="ij") if axes else []
        return [m.ravel() for m in mesh]


def plan_chunks(study: Study) -> ChunkPlan:
    """The chunk plan of ``study`` (blocks of at most ``study.chunk_size`` designs)."""
    return ChunkPlan(study.shape, chunk_shape(study.shape, study.chunk_size))
