"""Model dictionaries for the time-simulation tests (same keys as the model file)."""

from __future__ import annotations

import numpy as np


def symmetric() -> dict:
    """The symmetric three-mount ring of ``examples/imp_symmetric.toml`` (T_c about 18012 N).

    Written out rather than imported from ``tests/conftest.py``: a subprocess test imports this
    module with only this folder on its path.
    """
    return {
        "schema_version": 1,
        "name": "ring",
        "body": {"mass": 100.0, "inertia": [1.0, 6.0, 6.0]},
        "mount_rings": [
            {"count": 3, "radius": 0.15, "x": 0.3, "start_angle": 90.0, "k_axial": 1.0e5, "k_shear": 2.0e4}
        ],
        "thrust": {"operating": 2000.0},
        "analysis": {"thrust_max": 30000.0},
    }


def asymmetric(damped: bool = False, gyro: bool = False, tangency: float = 1.0) -> dict:
    """Tilted mounts, a full 6 x 6 mount, cg and thrust line off the axis; optional dampers and a
    spinning propeller (speed proportional to sqrt(T))."""
    full = np.array([
        [3.0e4, 0, 0, 0, 500.0, 0],
        [0, 1.0e4, 0, -300.0, 0, 0],
        [0, 0, 1.0e4, 0, 0, 0],
        [0, -300.0, 0, 800.0, 0, 0],
        [500.0, 0, 0, 0, 900.0, 0],
        [0, 0, 0, 0, 0, 700.0],
    ])
    c = (40.0, 8.0) if damped else (0.0, 0.0)
    d = {
        "schema_version": 1,
        "name": "asym",
        "body": {"mass": 120.0, "cg": [0.05, 0.01, -0.005],
                 "inertia": [[1.4, 0.05, 0.0], [0.05, 7.5, 0.1], [0.0, 0.1, 7.0]]},
        "mounts": [
            {"position": [0.30, 0.16, 0.02], "axis": [1.0, 0.1, 0.0], "k_axial": 1.2e5, "k_shear": 2.2e4,
             "c_axial": c[0], "c_shear": c[1]},
            {"position": [0.28, -0.05, 0.15], "axis": [1.0, 0.0, 0.15], "k_axial": 0.9e5, "k_shear": 1.8e4},
            {"position": [0.33, -0.09, -0.13], "axis": [1.0, -0.05, -0.05], "k_axial": 1.0e5, "k_shear": 2.0e4},
            {"position": [-0.20, 0.0, -0.14], "stiffness": full.tolist(),
             **({"damping": (0.002 * full).tolist()} if damped else {})},
        ],
        "thrust": {"point": [-0.1, 0.01, 0.02], "direction": [1.0, 0.01, -0.02], "tangency": tangency,
                   "operating": 3000.0},
        "analysis": {"thrust_max": 60000.0},
    }
    if gyro:
        d["propeller"] = {"polar_inertia": 0.05, "speed": 200.0, "speed_law": "sqrt-thrust"}
    return d
