"""Reading a study store: only what is verified reaches a decoder.

:func:`read_store` checks the root metadata against their CRC-32, every coordinate file
against the size and CRC-32 noted when the store was made, and every chunk that has a
completion record against its record (:mod:`impstab.studies.records`). The verified files are
then decoded by zarr from memory. Damaged data are refused with the parts named; chunks without
a record (not computed yet) keep their fill values and are listed.
"""

from __future__ import annotations

import json

from ..io import PathError
from .plan import ChunkPlan
from .records import check_chunk, file_checksum, record_key
from .store_files import StoreFiles
from .store_layout import FORMAT, attributes, data_key, json_doc, names, root_intact, tidy

__all__ = ["StoreView", "read_store"]

class StoreView:
    """What :func:`read_store` found: the dataset, and the chunks not computed yet."""

    def __init__(self, dataset, pending: list[int], n_chunks: int) -> None:
        self.dataset = dataset
        self.pending = pending
        self.n_chunks = n_chunks


def read_store(files: StoreFiles, name: str, field: str = "STORE", data: bool = True) -> StoreView:
    """Read a store, decoding only what is verified.

    The root metadata must match their CRC-32, every coordinate file the size and CRC-32 noted
    when the store was made, and every chunk with a completion record the sizes and CRC-32s
    of its record. Chunks without a record are not computed yet: their designs keep the fill
    values (status -1), whatever files they may hold. The verified files are decoded by zarr
    from memory, so nothing unverified ever reaches a decoder.

    Parameters
    ----------
    files : StoreFiles
    name : str
        The store's name in messages.
    field : str
        How it was given (``STORE``, ``--output``).
    data : bool
        False: the chunks' data are left out (coordinates and attributes only).

    Raises
    ------
    ModelError
        Not a study store, damaged metadata, or damaged chunks (named).
    """
    import xarray as xr
    import zarr
    from zarr.buffer import default_buffer_prototype

    try:
        root_bytes = files.read("zarr.json")
    except OSError as exc:
        raise PathError(field, name, f"cannot be read: {exc.strerror or exc}") from None
    root = json_doc(root_bytes)
    attrs = attributes(root)
    fmt = attrs.get("format")
    if not (isinstance(fmt, str) and fmt.startswith("impstab-study-store")):
        ours = "fingerprint" in attributes(json_doc(files.read("progress/zarr.json")))
        if ours or (root_bytes is not None and "consolidated_metadata" not in (root or {})):
            state = "missing" if root_bytes is None else "damaged"
            raise PathError(field, name, f"its metadata (zarr.json) are {state}" + ("" if ours else
                                          " or it is not an impstab study store") + ": run the study again "
                                          "(impstab sweep STUDY -o STORE) to repair them")
        raise PathError(field, name, "is not an impstab study store")
    if fmt != FORMAT:
        raise PathError(field, name, f"was written in an older store format ({fmt}) that cannot be verified: "
                                      "read it with the impstab version that made it")
    if not root_intact(root):
        raise PathError(field, name, "its metadata (zarr.json) do not match their checksum: run the study again "
                                      "(impstab sweep STUDY -o STORE) to repair them")
    meta = root["consolidated_metadata"]["metadata"]
    prog = meta["progress"]["attributes"]
    arrays = tuple(prog["arrays"])
    plan = ChunkPlan(tuple(json.loads(attrs["shape"])), tuple(attrs["chunk_shape"]))
    view: dict = {"zarr.json": root_bytes}
    damaged: list[str] = []
    pending: list[int] = []
    try:
        for key, (size, crc) in prog["coordinate_files"].items():
            got = files.read(key)
            if file_checksum(got) != (size, crc):
                damaged.append(f"coordinate file {key} " + ("missing" if got is None else "damaged"))
            view[key] = got
        for i in range(plan.n_chunks if data else 0):
            got: dict = {}

            def read(key, got=got):
                got[key] = files.read(key)
                return got[key]

            check = check_chunk(i, files.read(record_key(i)), arrays, [data_key(n, plan, i) for n in arrays], read)
            if check.state == "pending":
                pending.append(i)
            elif check.state == "damaged":
                damaged.append(check.describe())
            else:
                view.update(got)
    except OSError as exc:
        raise PathError(field, name, f"cannot be read: {exc.strerror or exc}") from None
    if damaged:
        raise PathError(field, name, f"holds damaged data, which do not match their checksums: {names(damaged)}; "
                                      "run the study again (impstab sweep STUDY -o STORE) to compute them again")
    proto = default_buffer_prototype().buffer
    mem = zarr.storage.MemoryStore(store_dict={k: proto.from_bytes(v) for k, v in view.items() if v is not None})
    ds = tidy(xr.open_zarr(mem, consolidated=True, chunks=None)).load()
    return StoreView(ds, pending, plan.n_chunks)
