"""Loaded once by the fork server of local Dask clusters, before their workers are forked from it.

:func:`impstab.studies.distributed.local_cluster` starts its worker processes by forking them
from one server process (multiprocessing's ``forkserver``) that has imported this module. A
worker started afresh pays some 2 s of CPU before its first chunk is done: importing numpy,
scipy, numba, Dask and impstab (1.5 s), and numba's first calls, which load the compiled code
from its cache and numba's own typing machinery (0.3 s). Paid once in the server, every forked
worker starts with all of it in memory; on two cores with 8 workers that is 16 s of CPU saved.

Importing this module therefore computes one chunk of two small designs, a symmetric and a
coupled mount layout, through the same path a study takes (:func:`evaluate_chunk`). It never
fails: a warm-up that goes wrong only leaves the first chunk of each worker slower.
"""

from __future__ import annotations

import numpy as np

from .evaluate import ChunkTask, evaluate_chunk

__all__ = ["warm_up"]

#: a small base model (three mounts on a ring); the warm-up varies the first mount's stiffness
_MODEL = {
    "schema_version": 1,
    "name": "warm-up",
    "body": {"mass": 100.0, "cg": [0.0, 0.0, 0.0], "inertia": [1.0, 6.0, 6.0]},
    "mount_rings": [{"count": 3, "radius": 0.15, "x": 0.3, "start_angle": 90.0, "axis": [1.0, 0.0, 0.0],
                     "k_axial": 1.0e5, "k_shear": 2.0e4}],
    "mounts": [{"position": [0.1, 0.0, 0.2], "k_axial": 1.0e4, "k_shear": 1.0e4}],
    "thrust": {"point": [0.0, 0.0, 0.0], "direction": [1.0, 0.0, 0.0], "tangency": 1.0, "operating": 2000.0},
    "analysis": {"thrust_max": 20000.0},
}


def warm_up() -> bool:
    """Compute one chunk of two designs (the symmetric ring alone, and with an extra mount)."""
    try:
        ring = {k: v for k, v in _MODEL.items() if k != "mounts"}
        for model in (ring, _MODEL):
            task = ChunkTask(index=0, block=(2,), base_model=model, segments=(("mount_rings", 0, "k_shear"),),
                             columns=(np.array([2.0e4, 2.5e4]),), outputs=("critical_thrust", "kind", "margin", "modes"),
                             model_name="warm-up")
            res = evaluate_chunk(task)
            if (res.data["status"] != 0).any():
                return False
        return True
    except Exception:  # noqa: BLE001 - a warm-up never stops anything
        return False


warm_up()
