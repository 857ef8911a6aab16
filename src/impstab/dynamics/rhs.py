"""Nonlinear equations of motion of the propulsor on its mounts (THEORY 2, 4 and 7).

State ``y = (eta, nu)``: ``eta = (X_A, Y_A, Z_A, phi, theta, psi)`` is the position of the
reference point A (hull frame, m) and the z-y-x Euler angles (rad) of the rotation
``R = J1(phi, theta, psi)`` body -> hull; ``nu = (u, v, w, p, q, r)`` are the velocity of A and
the angular velocity, both in the body frame (m/s, rad/s). The equations are

    eta' = J(eta) nu,   (M_RB + M_A) nu' + C_RB(nu) nu = tau(eta, nu, t)

with ``tau`` (body frame, moment about A) made of

* the mounts: mount i has a 6 x 6 stiffness ``k_i`` and damping ``c_i`` on its body-end deflection
  ``e_i = (X_A + R r_i - r_i, log R)`` (hull frame); the generalized force is the potential and
  Rayleigh form ``-B_i^T (k_i e_i + c_i e_i')``, ``B_i = [[I, -S(rho_i)], [0, J_l^{-1}]]``,
  ``rho_i = R r_i``. For the paper's mounts (translation block only) this is
  ``f_i = -k_i d_i - c_i d_i'`` at the body point;
* the thrust ``T (eta_t R e + (1 - eta_t) e)`` at ``R r_T`` (follower part, fixed part);
* the propeller gyroscopic moment ``-nu2 x h``, ``h = J_p Omega e`` (body frame);
* the fluid radiation damping ``-D_A nu`` (zero for incompressible fluid loading).

``C_RB(nu) nu`` is evaluated as the Newton-Euler terms ``m (w x v + w x (w x r_G))`` and
``w x I_A w + m r_G x (w x v)``. The added-mass Coriolis term ``C_A(nu) nu`` is omitted: the
fluid is at rest and the motions are small (THEORY 2); it is quadratic in ``nu`` and does not
change the linearization. Gravity and buoyancy are neglected (neutrally buoyant body).

The integrators work on the deviation ``z = y - y_eq`` from the static equilibrium ``y_eq``.

Everything here is compiled with numba (``cache=True``); with ``NUMBA_DISABLE_JIT=1`` the same
code runs as plain Python and gives identical results. The code uses scalar loops only (no BLAS
calls), so that both paths do the same floating-point operations in the same order.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..kinematics.so3 import _jinv, _log_so3

__all__ = ["rhs_into", "mount_loads_series", "PITCH_LIMIT", "KIND_MODEL", "KIND_LINEAR"]

#: default guard on the pitch angle (rad): the z-y-x Euler angles are singular at +-90 degrees
PITCH_LIMIT = math.radians(85.0)

# layout of the scalar parameter vector
P_MASS, P_CG, P_IA, P_E, P_RT, P_TANG, P_JP, P_PITCH = 0, 1, 4, 13, 16, 19, 20, 21
N_PAR = 22

#: status codes of the right-hand side and the steppers
OK, NONFINITE, PITCH, AMPLITUDE, HALVE, DOUBLE, UNDERFLOW = 0, 1, 2, 3, 4, 5, 6

KIND_MODEL, KIND_LINEAR = 0, 1

#: workspace of the right-hand side: pose (12), mount deflections (12), load (6), tau (6), nu (6)
WS = 42


@njit(cache=True, inline="always")
def _cross3(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True, inline="always")
def _euler_into(phi, theta, psi, rot):
    """Rotation body -> hull for z-y-x Euler angles (``J1``); same formula as the linear module."""
    cf, sf = math.cos(phi), math.sin(phi)
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    rot[0, 0] = cp * ct
    rot[0, 1] = -sp * cf + cp * st * sf
    rot[0, 2] = sp * sf + cp * cf * st
    rot[1, 0] = sp * ct
    rot[1, 1] = cp * cf + sp * st * sf
    rot[1, 2] = -cp * sf + sp * st * cf
    rot[2, 0] = -st
    rot[2, 1] = ct * sf
    rot[2, 2] = ct * cf


@njit(cache=True, inline="always")
def _rotate(rot, x0, x1, x2):
    return (rot[0, 0] * x0 + rot[0, 1] * x1 + rot[0, 2] * x2,
            rot[1, 0] * x0 + rot[1, 1] * x1 + rot[1, 2] * x2,
            rot[2, 0] * x0 + rot[2, 1] * x1 + rot[2, 2] * x2)


@njit(cache=True, inline="always")
def _rotate_t(rot, x0, x1, x2):
    return (rot[0, 0] * x0 + rot[1, 0] * x1 + rot[2, 0] * x2,
            rot[0, 1] * x0 + rot[1, 1] * x1 + rot[2, 1] * x2,
            rot[0, 2] * x0 + rot[1, 2] * x1 + rot[2, 2] * x2)


@njit(cache=True, inline="always")
def _mount_load(i, arrays, rot, jinv, ws):
    """Force (hull frame, N) and mount moment (N m) of mount ``i`` on the body into ``ws[24:30]``
    (pose in ``ws[0:12]``, see :func:`_pose_into`); returns the arm ``rho_i = R r_i`` (m)."""
    pos, kmat, cmat, full = arrays[0], arrays[1], arrays[2], arrays[3]
    x, vh, wh, phi = ws[0:3], ws[3:6], ws[6:9], ws[9:12]
    e, ed, out = ws[12:18], ws[18:24], ws[24:30]
    r0, r1, r2 = pos[i, 0], pos[i, 1], pos[i, 2]
    rho0, rho1, rho2 = _rotate(rot, r0, r1, r2)
    e[0], e[1], e[2] = x[0] + rho0 - r0, x[1] + rho1 - r1, x[2] + rho2 - r2
    c0, c1, c2 = _cross3(wh[0], wh[1], wh[2], rho0, rho1, rho2)
    ed[0], ed[1], ed[2] = vh[0] + c0, vh[1] + c1, vh[2] + c2
    nb = 3
    if full[i] != 0:
        nb = 6
        for a in range(3):
            e[3 + a] = phi[a]
            ed[3 + a] = jinv[a, 0] * wh[0] + jinv[a, 1] * wh[1] + jinv[a, 2] * wh[2]
    for a in range(6):
        out[a] = 0.0
    for a in range(nb):
        g = 0.0
        for b in range(nb):
            g += kmat[i, a, b] * e[b] + cmat[i, a, b] * ed[b]
        out[a] = -g
    if nb == 6:
        g3, g4, g5 = out[3], out[4], out[5]
        for a in range(3):
            out[3 + a] = jinv[0, a] * g3 + jinv[1, a] * g4 + jinv[2, a] * g5
    return rho0, rho1, rho2


@njit(cache=True, inline="always")
def _pose_into(arrays, yeq, z, rot, jinv, ws):
    """Absolute pose: R into ``rot``; position, hull-frame velocities and rotation vector into
    ``ws[0:12]``; ``J_l^{-1}`` into ``jinv`` (only when a mount has rotational terms)."""
    for a in range(3):
        ws[a] = yeq[a] + z[a]
    _euler_into(yeq[3] + z[3], yeq[4] + z[4], yeq[5] + z[5], rot)
    ws[3], ws[4], ws[5] = _rotate(rot, yeq[6] + z[6], yeq[7] + z[7], yeq[8] + z[8])
    ws[6], ws[7], ws[8] = _rotate(rot, yeq[9] + z[9], yeq[10] + z[10], yeq[11] + z[11])
    full = arrays[3]
    any_full = False
    for i in range(full.shape[0]):
        if full[i] != 0:
            any_full = True
    if any_full:
        phi = _log_so3(rot)
        jl = _jinv(phi)
        for a in range(3):
            ws[9 + a] = phi[a]
            for b in range(3):
                jinv[a, b] = jl[a, b]


@njit(cache=True)
def rhs_into(kind, arrays, yeq, z, thrust, spin, out):
    """``out = z'`` at deviation ``z`` with thrust ``thrust`` (N) and spin ``spin`` (rad/s).

    Returns a status: 0, or 2 when ``|theta|`` reached the pitch guard (the derivative is still
    computed unless ``cos(theta)`` vanishes).
    """
    if kind == KIND_LINEAR:
        amat = arrays[7]
        n = z.shape[0]
        for i in range(n):
            s = 0.0
            for j in range(n):
                s += amat[i, j] * z[j]
            out[i] = s
        return OK
    par, minv, damp6 = arrays[4], arrays[5], arrays[6]
    theta = yeq[4] + z[4]
    ct = math.cos(theta)
    status = OK
    if abs(theta) >= par[P_PITCH]:
        status = PITCH
        if abs(ct) < 1e-12:
            for i in range(12):
                out[i] = math.nan
            return status
    mats = np.zeros((2, 3, 3))
    ws = np.zeros(WS)
    rot, jinv = mats[0], mats[1]
    _pose_into(arrays, yeq, z, rot, jinv, ws)
    vh = ws[3:6]
    u, v, w = yeq[6] + z[6], yeq[7] + z[7], yeq[8] + z[8]
    p, q, r = yeq[9] + z[9], yeq[10] + z[10], yeq[11] + z[11]
    # kinematics: X' = R nu1, Xi' = J2(Xi) nu2
    out[0], out[1], out[2] = vh[0], vh[1], vh[2]
    sf, cf = math.sin(yeq[3] + z[3]), math.cos(yeq[3] + z[3])
    tt = math.sin(theta) / ct
    out[3] = p + sf * tt * q + cf * tt * r
    out[4] = cf * q - sf * r
    out[5] = (sf * q + cf * r) / ct
    # forces in the hull frame, moments about A
    f0 = f1 = f2 = m0 = m1 = m2 = 0.0
    load = ws[24:30]
    for i in range(arrays[0].shape[0]):
        rho0, rho1, rho2 = _mount_load(i, arrays, rot, jinv, ws)
        c0, c1, c2 = _cross3(rho0, rho1, rho2, load[0], load[1], load[2])
        f0 += load[0]
        f1 += load[1]
        f2 += load[2]
        m0 += c0 + load[3]
        m1 += c1 + load[4]
        m2 += c2 + load[5]
    e0, e1, e2 = par[P_E], par[P_E + 1], par[P_E + 2]
    tang = par[P_TANG]
    re0, re1, re2 = _rotate(rot, e0, e1, e2)
    t0 = thrust * (tang * re0 + (1.0 - tang) * e0)
    t1 = thrust * (tang * re1 + (1.0 - tang) * e1)
    t2 = thrust * (tang * re2 + (1.0 - tang) * e2)
    rt0, rt1, rt2 = _rotate(rot, par[P_RT], par[P_RT + 1], par[P_RT + 2])
    c0, c1, c2 = _cross3(rt0, rt1, rt2, t0, t1, t2)
    f0 += t0
    f1 += t1
    f2 += t2
    m0 += c0
    m1 += c1
    m2 += c2
    tau = ws[30:36]
    tau[0], tau[1], tau[2] = _rotate_t(rot, f0, f1, f2)
    tau[3], tau[4], tau[5] = _rotate_t(rot, m0, m1, m2)
    # propeller gyroscopic moment -w x h
    hmag = par[P_JP] * spin
    c0, c1, c2 = _cross3(p, q, r, hmag * e0, hmag * e1, hmag * e2)
    tau[3] -= c0
    tau[4] -= c1
    tau[5] -= c2
    # Coriolis-centripetal terms C_RB(nu) nu (Newton-Euler form)
    mass = par[P_MASS]
    g0, g1, g2 = par[P_CG], par[P_CG + 1], par[P_CG + 2]
    wv0, wv1, wv2 = _cross3(p, q, r, u, v, w)
    wg0, wg1, wg2 = _cross3(p, q, r, g0, g1, g2)
    wwg0, wwg1, wwg2 = _cross3(p, q, r, wg0, wg1, wg2)
    tau[0] -= mass * (wv0 + wwg0)
    tau[1] -= mass * (wv1 + wwg1)
    tau[2] -= mass * (wv2 + wwg2)
    ia = par[P_IA:P_IA + 9]
    iw0 = ia[0] * p + ia[1] * q + ia[2] * r
    iw1 = ia[3] * p + ia[4] * q + ia[5] * r
    iw2 = ia[6] * p + ia[7] * q + ia[8] * r
    c0, c1, c2 = _cross3(p, q, r, iw0, iw1, iw2)
    d0, d1, d2 = _cross3(g0, g1, g2, wv0, wv1, wv2)
    tau[3] -= c0 + mass * d0
    tau[4] -= c1 + mass * d1
    tau[5] -= c2 + mass * d2
    # fluid radiation damping, then nu' = M^-1 tau
    nu = ws[36:42]
    nu[0], nu[1], nu[2], nu[3], nu[4], nu[5] = u, v, w, p, q, r
    for a in range(6):
        s = 0.0
        for b in range(6):
            s += damp6[a, b] * nu[b]
        tau[a] -= s
    for a in range(6):
        s = 0.0
        for b in range(6):
            s += minv[a, b] * tau[b]
        out[6 + a] = s
    return status


@njit(cache=True)
def mount_loads_series(arrays, yeq, zs, out):
    """Mount forces (hull frame, N) and mount moments (N m) on the body for each state row of
    ``zs``; ``out`` has shape ``(n_samples, n_mounts, 6)``."""
    mats = np.zeros((2, 3, 3))
    ws = np.zeros(WS)
    for k in range(zs.shape[0]):
        _pose_into(arrays, yeq, zs[k], mats[0], mats[1], ws)
        for i in range(arrays[0].shape[0]):
            _mount_load(i, arrays, mats[0], mats[1], ws)
            for a in range(6):
                out[k, i, a] = ws[24 + a]
