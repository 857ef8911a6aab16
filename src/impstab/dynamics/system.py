"""Packing a model (or a linear test system) for the compiled kernels, and Python entry points
to the right-hand side and the mount loads."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.mount_law import N_LAW
from .rhs import (FLAG_LAW, FLAG_ROTATION, KIND_LINEAR, KIND_MODEL, N_PAR, P_CG, P_E, P_IA, P_JP, P_MASS, P_PITCH,
                  P_RADIATION, P_ROTATION, P_RT, P_TANG, PITCH_LIMIT, mount_loads_series, rhs_into)

__all__ = ["DynamicSystem", "pack_dynamics", "linear_dynamics", "evaluate_rhs", "mount_loads"]


@dataclass(frozen=True, eq=False)
class DynamicSystem:
    """A system packed for the compiled kernels.

    ``kind = 0``: the propulsor model (12 states); ``kind = 1``: a linear system ``z' = A z``
    (used to test the integrators on oscillators). ``arrays`` is the tuple handed to the kernels;
    ``length_scale`` (m) is the model's largest mount or thrust arm.
    """

    kind: int
    arrays: tuple
    n_states: int
    n_mounts: int
    length_scale: float = 1.0


def pack_dynamics(model, pitch_limit: float = PITCH_LIMIT) -> DynamicSystem:
    """Pack ``model`` for the kernels: mounts, mass properties, thrust line, propeller."""
    from ..linear.linearize import pack_model

    pk = pack_model(model)
    nm = pk.positions.shape[0]
    rotational = [bool(np.any(k[3:, :] != 0) or np.any(k[:, 3:] != 0) or np.any(c[3:, :] != 0) or np.any(c[:, 3:] != 0))
                  for k, c in zip(pk.stiffness, pk.damping)]
    nonlinear = np.any(pk.laws[:, 3:] != 0.0, axis=1)
    flags = np.array([FLAG_ROTATION * r + FLAG_LAW * int(nl) for r, nl in zip(rotational, nonlinear)], dtype=np.int64)
    par = np.zeros(N_PAR)
    body = model.body
    par[P_MASS] = body.mass
    par[P_CG:P_CG + 3] = body.cg
    par[P_IA:P_IA + 9] = np.asarray(body.inertia_a).ravel()
    par[P_E:P_E + 3] = pk.e_dir
    par[P_RT:P_RT + 3] = pk.r_thrust
    par[P_TANG] = pk.tangency
    par[P_JP] = pk.polar_inertia
    par[P_PITCH] = float(pitch_limit)
    par[P_ROTATION] = float(any(rotational))
    par[P_RADIATION] = float(np.any(pk.damp6 != 0.0))
    arrays = (
        np.ascontiguousarray(pk.positions), np.ascontiguousarray(pk.stiffness),
        np.ascontiguousarray(pk.damping), flags, np.ascontiguousarray(pk.laws), par,
        np.ascontiguousarray(np.linalg.inv(pk.mass6)), np.ascontiguousarray(pk.damp6), np.zeros((1, 1)),
    )
    return DynamicSystem(KIND_MODEL, arrays, 12, nm, float(pk.length_scale))


def linear_dynamics(amat) -> DynamicSystem:
    """A linear system ``z' = A z`` for the same kernels (oscillator tests of the integrators)."""
    amat = np.ascontiguousarray(amat, dtype=float)
    n = amat.shape[0]
    arrays = (np.zeros((0, 3)), np.zeros((0, 6, 6)), np.zeros((0, 6, 6)), np.zeros(0, dtype=np.int64),
              np.zeros((0, N_LAW)), np.zeros(N_PAR), np.zeros((6, 6)), np.zeros((6, 6)), amat)
    return DynamicSystem(KIND_LINEAR, arrays, n, 0)


def evaluate_rhs(system: DynamicSystem, yeq, z, thrust: float, spin: float = 0.0):
    """Python entry to the right-hand side: returns ``(z', status)``."""
    out = np.empty(system.n_states)
    status = rhs_into(system.kind, system.arrays, np.ascontiguousarray(yeq, dtype=float),
                      np.ascontiguousarray(z, dtype=float), float(thrust), float(spin), out)
    return out, int(status)


def mount_loads(system: DynamicSystem, yeq, zs):
    """Mount loads ``(n_samples, n_mounts, 6)``: force (N, hull frame) then moment (N m)."""
    zs = np.ascontiguousarray(np.atleast_2d(zs), dtype=float)
    out = np.zeros((zs.shape[0], system.n_mounts, 6))
    if system.kind == KIND_MODEL and zs.shape[0]:
        mount_loads_series(system.arrays, np.ascontiguousarray(yeq, dtype=float), zs, out)
    return out
