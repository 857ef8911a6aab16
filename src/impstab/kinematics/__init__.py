"""Kinematics, the ground floor of impstab: skew matrices, rigid-body maps, SO(3), Euler angles.

Used by the model, the linear analyses and the nonlinear dynamics alike; it imports none of them.

Conventions (THEORY 1): ``skew(a) @ b == cross(a, b)``; the rigid-body map of a body point
at arm ``r`` (from the reference point A) is ``d = rigid_map(r) @ q`` with
``q = (u_x, u_y, u_z, r_x, r_y, r_z)``; finite rotations are updated with a *spatial*
increment, ``R <- expm(skew(dphi)) @ R``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .so3 import _exp_so3, _jinv, _log_so3

__all__ = [
    "skew",
    "rigid_map",
    "rigid_map6",
    "rotation_from_vector",
    "rotation_vector",
    "inverse_left_jacobian",
    "euler_zyx_to_matrix",
    "matrix_to_euler_zyx",
    "block_rotate",
]

Array = NDArray[np.float64]


# S(a) and [I, -S(r)], row by row: the flat positions of their nonzero entries, the component
# of the vector at each and its sign (filled in one gather instead of an assignment per entry)
_SKEW_AT, _SKEW_FROM = np.array([1, 2, 3, 5, 6, 7]), np.array([2, 1, 2, 0, 1, 0])
_SKEW_SIGN = np.array([-1.0, 1.0, 1.0, -1.0, -1.0, 1.0])
_RIGID_ONE, _RIGID_AT = np.array([0, 7, 14]), np.array([4, 5, 9, 11, 15, 16])


def skew(a: Array) -> Array:
    """Skew matrix ``S(a)`` with ``S(a) @ b = a x b``; works on stacks ``(..., 3)``."""
    a = np.asarray(a, dtype=float)
    s = np.zeros(a.shape[:-1] + (9,))
    s[..., _SKEW_AT] = a[..., _SKEW_FROM] * _SKEW_SIGN
    return s.reshape(a.shape[:-1] + (3, 3))


def rigid_map(r: Array) -> Array:
    """``T(r) = [I, -S(r)]`` (3 x 6): displacement of the body point at arm ``r``."""
    r = np.asarray(r, dtype=float)
    t = np.zeros(r.shape[:-1] + (18,))
    t[..., _RIGID_ONE] = 1.0
    t[..., _RIGID_AT] = r[..., _SKEW_FROM] * -_SKEW_SIGN
    return t.reshape(r.shape[:-1] + (3, 6))


def rigid_map6(r: Array) -> Array:
    """``[[I, -S(r)], [0, I]]`` (6 x 6): translation and rotation of the body point at ``r``."""
    r = np.asarray(r, dtype=float)
    t = np.zeros(r.shape[:-1] + (6, 6))
    t[..., :3, :] = rigid_map(r)
    t[..., 3:, 3:] = np.eye(3)
    return t


def rotation_from_vector(phi: Array) -> Array:
    """Rotation matrix ``exp(S(phi))`` (Rodrigues), accurate for small and large angles."""
    return _exp_so3(np.ascontiguousarray(phi, dtype=float))


def rotation_vector(rot: Array) -> Array:
    """Rotation vector ``phi`` with ``exp(S(phi)) = rot`` (angle below pi)."""
    return _log_so3(np.ascontiguousarray(rot, dtype=float))


def inverse_left_jacobian(phi: Array) -> Array:
    """``J_l^{-1}(phi)``: rate of the rotation vector per spatial rotation increment.

    If ``R = exp(S(phi))`` and ``R <- exp(S(dphi)) R``, then ``phi <- phi + J_l^{-1}(phi) dphi``
    to first order.
    """
    return _jinv(np.ascontiguousarray(phi, dtype=float))


def euler_zyx_to_matrix(phi: float, theta: float, psi: float) -> Array:
    """Rotation body -> hull for the z-y-x Euler sequence (the paper's ``J1``, eq. 4)."""
    cf, sf = np.cos(phi), np.sin(phi)
    ct, st = np.cos(theta), np.sin(theta)
    cp, sp = np.cos(psi), np.sin(psi)
    return np.array(
        [
            [cp * ct, -sp * cf + cp * st * sf, sp * sf + cp * cf * st],
            [sp * ct, cp * cf + sp * st * sf, -cp * sf + sp * st * cf],
            [-st, ct * sf, ct * cf],
        ]
    )


def matrix_to_euler_zyx(rot: Array) -> tuple[float, float, float]:
    """Euler angles ``(phi, theta, psi)`` (z-y-x sequence) of a rotation body -> hull."""
    theta = float(np.arcsin(np.clip(-rot[2, 0], -1.0, 1.0)))
    phi = float(np.arctan2(rot[2, 1], rot[2, 2]))
    psi = float(np.arctan2(rot[1, 0], rot[0, 0]))
    return phi, theta, psi


def block_rotate(matrix6: Array, rot: Array) -> Array:
    """``blockdiag(R, R) @ A @ blockdiag(R, R).T`` for a 6 x 6 matrix in (translation, rotation)."""
    big = np.zeros((6, 6))
    big[:3, :3] = rot
    big[3:, 3:] = rot
    return big @ matrix6 @ big.T
