"""Forced response with viscoelastic mounts: the exact complex stiffness at each frequency.

A viscoelastic mount's translation stiffness is ``k*(omega) = k r(omega)`` with the law's exact
ratio ``r`` (:meth:`impstab.model.viscoelastic.ViscoelasticLaw.ratio`: the standard linear
solid, the Prony series, the fractional Zener law, or the measured table itself, hysteretic or
not). At angular frequency ``omega`` it is the spring ``k Re r`` beside the dashpot
``k Im r / omega``: :func:`viscoelastic_harmonic_response` hands the one harmonic solver
(:func:`~impstab.response.core.harmonic_response`) those mount matrices and the linearization
with the same change, ``K + sum B_i^T k_i (Re r_i - 1) B_i`` and ``D + sum B_i^T k_i (Im r_i /
omega) B_i``, one frequency at a time. The load stiffness (thrust and preload), and so the power
split, is unchanged; the damper power includes the mount's hysteresis.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..model.model import Model
from .core import HarmonicSolution, attachment_maps, harmonic_response

__all__ = ["viscoelastic_harmonic_response", "mount_ratios"]

Array = NDArray[np.float64]


def mount_ratios(model: Model, omega: Array) -> NDArray[np.complex128]:
    """``(nf, nm)`` exact ratios ``k*(omega) / k0`` of every mount (1 for an elastic mount)."""
    omega = np.asarray(omega, dtype=float).reshape(-1)
    out = np.ones((omega.size, len(model.mounts)), dtype=complex)
    for i, m in enumerate(model.mounts):
        if m.viscoelastic is not None:
            out[:, i] = m.viscoelastic.ratio(omega)
    return out


def _slice(a, j: int, axis: int):
    if a is None:
        return None
    a = np.asarray(a)
    if a.shape[axis] == 1:
        return a
    return np.take(a, [j], axis=axis)


def viscoelastic_harmonic_response(model: Model, mass, damping, gyroscopic, stiffness, rotation, positions,
                                   mount_stiffness, mount_damping, omega, loads, fluid=None, foundation=None,
                                   fluid_damping=None) -> HarmonicSolution:
    """:func:`~impstab.response.core.harmonic_response` of one design (``nd = 1``) whose mounts
    follow ``model``'s viscoelastic laws exactly at each frequency (same arguments)."""
    w = np.asarray(omega, dtype=float).reshape(-1)
    ratios = mount_ratios(model, w)
    b = attachment_maps(positions, rotation)[0]                    # (nm, 6, 6)
    km0 = np.asarray(mount_stiffness, dtype=float)
    cm0 = np.asarray(mount_damping, dtype=float)
    loads = np.asarray(loads, dtype=complex)
    loads = loads.reshape((1,) * (3 - loads.ndim) + loads.shape)
    hull = None if foundation is None else np.asarray(foundation, dtype=complex)
    if hull is not None:
        hull = hull.reshape((1,) * (3 - hull.ndim) + hull.shape)
    parts = []
    for j, wj in enumerate(w):
        dk = np.zeros_like(km0)
        dc = np.zeros_like(cm0)
        for i in range(km0.shape[1]):
            r = ratios[j, i]
            if r == 1.0:
                continue
            k3 = km0[0, i, :3, :3]
            dk[0, i, :3, :3] = k3 * (r.real - 1.0)
            if wj > 0.0:
                dc[0, i, :3, :3] = k3 * (r.imag / wj)
        add_k = (np.swapaxes(b, -1, -2) @ dk[0] @ b).sum(axis=0)[None]
        add_c = (np.swapaxes(b, -1, -2) @ dc[0] @ b).sum(axis=0)[None]
        d_fluid = fluid_damping
        if d_fluid is None:  # keep the fluid part that the solver would infer from the elastic mounts
            d_fluid = np.asarray(damping, float) - (np.swapaxes(b, -1, -2) @ cm0[0] @ b).sum(axis=0)[None]
            scale = np.abs(np.asarray(damping, float)).max(axis=(-2, -1), keepdims=True)
            d_fluid = np.where(np.abs(d_fluid) <= 1e-12 * scale, 0.0, d_fluid)
        parts.append(harmonic_response(
            mass, np.asarray(damping, float) + add_c, gyroscopic, np.asarray(stiffness, float) + add_k, rotation,
            positions, km0 + dk, cm0 + dc, np.array([wj]), _slice(loads, j, 1),
            fluid=_slice(fluid, j, 1), foundation=_slice(hull, j, 1), fluid_damping=d_fluid,
        ))
    cat = lambda name: np.concatenate([getattr(p, name) for p in parts], axis=1)  # noqa: E731
    return HarmonicSolution(
        omega=w, response=cat("response"), deflection=cat("deflection"), hull_displacement=cat("hull_displacement"),
        mount_force=cat("mount_force"), hull_force=cat("hull_force"), power_input=cat("power_input"),
        power_thrust=cat("power_thrust"), power_fluid=cat("power_fluid"), power_damper=cat("power_damper"),
        power_transmitted=cat("power_transmitted"), pivot_ratio=cat("pivot_ratio"),
    )
