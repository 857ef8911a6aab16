"""Compiled SO(3) primitives: skew matrices, exponential and logarithm, left Jacobian.

Used by the force law and its tangent (:mod:`impstab.linear.tangent`), the nonlinear equations
of motion and the plain-NumPy helpers of :mod:`impstab.kinematics`. Compiled with numba
(``cache=True``); with ``NUMBA_DISABLE_JIT=1`` the same code runs as plain Python.

``_log_so3_into`` and ``_jinv_into`` write into arrays the caller owns (no allocation, for the
right-hand side of the equations of motion) and are type-generic: written with the analytic
functions of :mod:`impstab.kinematics.scalar` and branches on real parts, they also run on a
complex rotation matrix (exact complex-step derivatives). ``_log_so3`` and ``_jinv`` return new
arrays and call them.
"""

from __future__ import annotations

import math

import numpy as np
from .._jit import njit

from .scalar import acos, cos, sin, sqrt

__all__ = ["_skew", "_cross", "_exp_so3", "_log_so3", "_log_so3_into", "_jinv_coeffs", "_jinv", "_jinv_into",
           "_d_jinvT_w"]


@njit(cache=True)
def _skew(a):
    s = np.zeros((3, 3))
    s[0, 1] = -a[2]
    s[0, 2] = a[1]
    s[1, 0] = a[2]
    s[1, 2] = -a[0]
    s[2, 0] = -a[1]
    s[2, 1] = a[0]
    return s


@njit(cache=True)
def _cross(a, b):
    out = np.empty(3)
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]
    return out


@njit(cache=True)
def _exp_so3(phi):
    theta = math.sqrt(phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2)
    s = _skew(phi)
    if theta < 1e-4:
        t2 = theta * theta
        a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0
        b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
    else:
        a = math.sin(theta) / theta
        b = (1.0 - math.cos(theta)) / (theta * theta)
    return np.eye(3) + a * s + b * (s @ s)


@njit(cache=True, inline="always")
def _log_so3_into(rot, w):
    """Rotation vector of ``rot`` (angle below pi) into ``w[0:3]``."""
    c = 0.5 * (rot[0, 0] + rot[1, 1] + rot[2, 2] - 1.0)
    # rounding beyond the identity: clamp a real cosine (a complex one is the analytic
    # continuation, beyond 1 on half of any complex circle: acos(c)^2 is analytic there)
    if c.imag == 0.0 and c.real > 1.0:
        c = c - (c.real - 1.0)
    elif c.imag == 0.0 and c.real < -1.0:
        c = c - (c.real + 1.0)
    theta = acos(c)
    if theta.real < 1e-4:
        scale = 1.0 + theta * theta / 6.0
    else:
        scale = theta / sin(theta)
    w[0] = 0.5 * (rot[2, 1] - rot[1, 2]) * scale
    w[1] = 0.5 * (rot[0, 2] - rot[2, 0]) * scale
    w[2] = 0.5 * (rot[1, 0] - rot[0, 1]) * scale


@njit(cache=True)
def _log_so3(rot):
    w = np.empty(3)
    _log_so3_into(rot, w)
    return w


@njit(cache=True, inline="always")
def _jinv_coeffs(theta):
    # c(theta) = 1/theta^2 - cot(theta/2) / (2 theta);  c1 = c'(theta) / theta
    if theta.real < 0.25:
        t2 = theta * theta
        c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0 + t2**3 / 1209600.0 + t2**4 / 47900160.0
        c1 = 1.0 / 360.0 + t2 / 7560.0 + t2 * t2 / 201600.0 + t2**3 / 5987520.0
        return c, c1
    half = 0.5 * theta
    cot = cos(half) / sin(half)
    c = 1.0 / theta**2 - cot / (2.0 * theta)
    dc = -2.0 / theta**3 + 1.0 / (4.0 * theta * sin(half) ** 2) + cot / (2.0 * theta**2)
    return c, dc / theta


@njit(cache=True, inline="always")
def _jinv_into(phi, out):
    """``J_l^{-1}(phi) = I - S(phi) / 2 + c(theta) S(phi)^2`` into the 3 x 3 ``out``."""
    t2 = phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]
    c, _ = _jinv_coeffs(sqrt(t2))
    for i in range(3):
        for j in range(3):
            # S(phi)^2 = phi phi^T - |phi|^2 I
            out[i, j] = c * (phi[i] * phi[j] - (t2 if i == j else 0.0)) + (1.0 if i == j else 0.0)
    out[0, 1] += 0.5 * phi[2]
    out[0, 2] -= 0.5 * phi[1]
    out[1, 0] -= 0.5 * phi[2]
    out[1, 2] += 0.5 * phi[0]
    out[2, 0] += 0.5 * phi[1]
    out[2, 1] -= 0.5 * phi[0]


@njit(cache=True)
def _jinv(phi):
    out = np.empty((3, 3))
    _jinv_into(phi, out)
    return out


@njit(cache=True)
def _d_jinvT_w(phi, w):
    """H = d(J_l^{-1}(phi)^T w)/dphi for fixed w."""
    theta2 = phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2
    c, c1 = _jinv_coeffs(math.sqrt(theta2))
    pw = phi[0] * w[0] + phi[1] * w[1] + phi[2] * w[2]
    h = -0.5 * _skew(w)
    for i in range(3):
        for j in range(3):
            h[i, j] += c * (pw * (1.0 if i == j else 0.0) + phi[i] * w[j] - 2.0 * w[i] * phi[j])
            h[i, j] += c1 * (phi[i] * pw - theta2 * w[i]) * phi[j]
    return h
