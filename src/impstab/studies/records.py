"""Completion records: what proves that a chunk of a study store is complete and intact.

A chunk is done when its record exists, and its data are trusted only while they match it.
The record is written after the chunk's data (by the process that wrote them) and holds

* ``finished_at`` (s since the epoch), ``runs`` (times the chunk was computed), ``seconds``
  (computing time), ``evaluations`` (eigenproblems solved) and ``chunk`` (its own number);
* for every array of the chunk (each output, ``status``, ``message``): the size in bytes and
  the CRC-32 of the stored chunk file, as zarr encoded it (read back after the write);
* the CRC-32 of all the fields before it, so that a damaged record is recognised as such.

Records are the rows of the store's array ``progress/chunks`` (float64, one uncompressed zarr
chunk per row: a 8-byte field per column, every value an integer below 2**53 or a time), so
zarr and xarray read them as an ordinary array, and :func:`decode` reads one without zarr.
CRC-32 (``zlib.crc32``, about 1 GB/s) detects any damage short of a deliberate forgery: every
burst of up to 32 flipped bits and a truncation always, other damage with odds of 2**-32.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass

import numpy as np

__all__ = ["columns", "encode", "decode", "file_checksum", "Check", "check_chunk", "record_key"]

BASE = ("finished_at", "runs", "seconds", "evaluations", "chunk")


def columns(arrays: tuple[str, ...]) -> tuple[str, ...]:
    """The record's columns for a store whose chunks hold ``arrays``."""
    per_array = tuple(f"{name}:{what}" for name in arrays for what in ("bytes", "crc32"))
    return (*BASE, *per_array, "record:crc32")


def record_key(index: int) -> str:
    """The key of chunk ``index``'s record in the store."""
    return f"progress/chunks/c/{index}/0"


def file_checksum(data: bytes | None) -> tuple[int, int]:
    """``(size, crc32)`` of a stored file's bytes; ``(0, 0)`` for a file that is not there."""
    if data is None:
        return 0, 0
    return len(data), zlib.crc32(data)


def encode(fields: np.ndarray) -> bytes:
    """The record file of ``fields`` (all columns but the last), with its own CRC-32 appended."""
    body = np.ascontiguousarray(fields, dtype="<f8").tobytes()
    return body + np.array([zlib.crc32(body)], dtype="<f8").tobytes()


def decode(data: bytes | None, n_columns: int) -> np.ndarray | None:
    """The record's fields, or None if there is no record or it is damaged (size or CRC)."""
    if data is None or len(data) != 8 * n_columns:
        return None
    row = np.frombuffer(data, dtype="<f8")
    body = data[: 8 * (n_columns - 1)]
    if row[-1] != zlib.crc32(body) or not np.isfinite(row[0]):
        return None
    return row.astype(np.float64)


@dataclass(frozen=True)
class Check:
    """The verdict on one chunk: ``state`` is ``"done"``, ``"pending"`` (no record) or ``"damaged"``."""

    index: int
    state: str
    problems: tuple[str, ...] = ()

    def describe(self) -> str:
        """``chunk 3 (critical_thrust/c/1/0 missing)``."""
        return f"chunk {self.index}" + (f" ({'; '.join(self.problems)})" if self.problems else "")


def check_chunk(index: int, record_bytes: bytes | None, arrays: tuple[str, ...], data_keys: list[str],
                read) -> Check:
    """Verify chunk ``index`` against its record.

    Parameters
    ----------
    index : int
    record_bytes : bytes or None
        The stored record file.
    arrays : tuple of str
        The arrays of a chunk, in the record's order.
    data_keys : list of str
        The key of the chunk's file of each array.
    read : callable
        ``read(key) -> bytes or None``.
    """
    n = len(columns(arrays))
    if record_bytes is None:
        return Check(index, "pending")
    row = decode(record_bytes, n)
    if row is None:
        return Check(index, "damaged", (f"its completion record {record_key(index)} is damaged",))
    if int(row[4]) != index:
        return Check(index, "damaged", (f"its completion record {record_key(index)} is that of chunk {int(row[4])}",))
    problems = []
    for k, key in enumerate(data_keys):
        size, crc = int(row[len(BASE) + 2 * k]), int(row[len(BASE) + 2 * k + 1])
        got = read(key)
        if got is None and size:
            problems.append(f"{key} missing")
        elif got is not None and len(got) != size:
            problems.append(f"{key} truncated to {len(got)} of {size} bytes" if len(got) < size
                            else f"{key} has {len(got)} bytes instead of {size}")
        elif got is not None and zlib.crc32(got) != crc:
            problems.append(f"{key} corrupt, its checksum differs")
    return Check(index, "damaged" if problems else "done", tuple(problems))
