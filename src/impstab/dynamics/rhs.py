"""Nonlinear equations of motion of the propulsor on its mounts (THEORY 2, 4 and 7).

State ``y = (eta, nu)``: ``eta = (X_A, Y_A, Z_A, phi, theta, psi)`` is the position of the
reference point A (hull frame, m) and the z-y-x Euler angles (rad) of the rotation
``R = J1(phi, theta, psi)`` body -> hull; ``nu = (u, v, w, p, q, r)`` are the velocity of A and
the angular velocity, both in the body frame (m/s, rad/s). The equations are

    eta' = J(eta) nu,   (M_RB + M_A) nu' + C_RB(nu) nu = tau(eta, nu, t)

with ``tau`` (body frame, moment about A) made of

* the mounts: mount i has a 6 x 6 stiffness ``k_i`` and damping ``c_i`` on its body-end deflection
  ``e_i = (X_A + R r_i - r_i, log R)`` (hull frame); the generalized force is the potential and
  Rayleigh form ``-B_i^T (k_i e_i + c_i e_i' + [grad V_nl(d_i); 0])``,
  ``B_i = [[I, -S(rho_i)], [0, J_l^{-1}]]``, ``rho_i = R r_i``, where ``V_nl`` is the mount's
  nonlinear law on the translation deflection ``d_i`` (cubic springs, snubber;
  :mod:`impstab.model.mount_law`). For the paper's mounts this is
  ``f_i = -k_i d_i - c_i d_i' - grad V_nl(d_i)`` at the body point;
* viscoelastic mounts (:mod:`impstab.model.viscoelastic`): each Prony term j of mount i is an
  internal 3-vector ``w_ij`` (hull frame, m), a state appended after the 12 of the body, with
  ``tau_ij w_ij' = d_i - w_ij``; the mount's force gains ``-g_ij k_i (d_i - w_ij)`` at the body
  point (``k_i`` its static translation stiffness). The Prony terms are linear in the
  deflection and add to the elastic and nonlinear law above (which act on the static part), as
  a Maxwell element in parallel with the mount: at rest ``w_ij = d_i`` and the static
  equilibrium is the elastic one; linearized at it, the equations are those of
  :mod:`impstab.linear.viscoelastic`;
* the thrust ``T (eta_t R e + (1 - eta_t) e)`` at ``R r_T`` (follower part, fixed part);
* the propeller gyroscopic moment ``-nu2 x h``, ``h = J_p Omega e`` (body frame);
* the fluid radiation damping ``-D_A nu`` (zero for incompressible fluid loading);
* massive beam mounts (:mod:`impstab.dynamics.beam_mounts`): the mount acts by its static tip
  stiffness ``K_tip`` as above, and its inertia in Craig-Bampton form (:mod:`impstab.linear.mount_dofs`):
  kept fixed-interface modes ``eta_b`` (unit modal mass, stiffness ``Omega_b^2``, no damping) are
  states after the Prony internal variables (all ``eta``, then all ``eta'``). With the body-end
  node acceleration ``a_b = R6 (T_b nu' + c_b)`` (hull frame), ``R6 = diag(R, R)``,
  ``T_b = [[I, -S(r_b)], [0, I]]``, ``c_b = (w x v + w x (w x r_b), 0)`` (body frame),

      eta_b'' = -Omega_b^2 eta_b - m_te,b^T a_b,
      f_b = -(m_tt,b a_b + m_te,b eta_b'') = -N_b a_b + m_te,b Omega_b^2 eta_b,  N_b = m_tt,b - m_te,b m_te,b^T

  is the inertia force of beam b on the body at its body end (hull frame, force and moment), and
  the body's equation becomes ``(M + sum T_b^T R6^T N_b R6 T_b) nu' = tau - sum T_b^T R6^T
  (N_b R6 c_b - m_te,b Omega_b^2 eta_b)``, solved per evaluation (6 x 6 elimination without
  pivoting: the matrix is symmetric positive definite) instead of the product with ``M^-1``.
  This conserves the beam's kinetic energy ``(V_b, eta_b')^T [[m_tt, m_te], [m_te^T, I]] (V_b,
  eta_b') / 2`` plus ``Omega_b^2 eta_b^2 / 2``; at rest ``eta_b = 0`` and the statics are
  unchanged. Linearized at an equilibrium it is the grown system of
  :meth:`~impstab.linear.mount_dofs.MountDofs.augment` with the same kept modes.

``C_RB(nu) nu`` is evaluated as the Newton-Euler terms ``m (w x v + w x (w x r_G))`` and
``w x I_A w + m r_G x (w x v)``. The added-mass Coriolis term ``C_A(nu) nu`` is omitted: the
fluid is at rest and the motions are small (THEORY 2); it is quadratic in ``nu`` and does not
change the linearization. Gravity and buoyancy are neglected (neutrally buoyant body).

The integrators work on the deviation ``z = y - y_eq`` from the static equilibrium ``y_eq``.

Everything here is compiled with numba (``cache=True``); with ``NUMBA_DISABLE_JIT=1`` the same
code runs as plain Python and gives identical results. The code uses scalar loops only (no BLAS
calls), so that both paths do the same floating-point operations in the same order.

Speed: :func:`model_rhs` allocates nothing and takes no slices; the pose, the rotation and the
mount deflections live in scalars and in workspace arrays the caller passes in (see
:func:`workspace`). It is compiled without numba's runtime (``_nrt=False``, numba's own switch
for code that must not allocate; every helper it uses is inlined into it), so a call touches
no reference count: with the runtime, numba's reference-count pruning leaves an atomic
increment and decrement per array argument and call in a function of this shape (about 40 per
evaluation, measured), which cost more than the arithmetic. Complex states: every operation on the state is analytic (trigonometric functions and
square roots through :mod:`impstab.kinematics.scalar`, comparisons on real parts only), so the
same code compiles for complex128 states and complex-step or Cauchy-integral derivatives of it
are exact. The non-analytic spots are guards only: the pitch guard compares ``Re(theta)``, the
snubber's contact test compares ``Re(d . d)`` with the squared clearance (``|d| = sqrt(d . d)``
is analytic away from ``d = 0``, and the snubber never acts near ``d = 0``), the ramp's
smoothing interval is chosen on the real part, and the clamp of the rotation angle in
``log R`` (rounding only) acts on the real part.
"""

from __future__ import annotations

import math

import numpy as np
from .._jit import njit

from ..kinematics.scalar import cos, sin
from ..kinematics.so3 import _jinv_into, _log_so3_into
from ..model.mount_law import law_gradient

__all__ = ["rhs_batch", "model_rhs", "beam_body", "mount_loads_series", "workspace", "PITCH_LIMIT",
           "KIND_MODEL", "KIND_LINEAR", "FLAG_ROTATION", "FLAG_LAW", "N_BODY"]

#: default guard on the pitch angle (rad): the z-y-x Euler angles are singular at +-90 degrees
PITCH_LIMIT = math.radians(85.0)

# layout of the scalar parameter vector; P_ROTATION: 1 when a mount has rotational terms,
# P_RADIATION: 1 when the fluid radiation damping is not zero
P_MASS, P_CG, P_IA, P_E, P_RT, P_TANG, P_JP, P_PITCH, P_ROTATION, P_RADIATION = 0, 1, 4, 13, 16, 19, 20, 21, 22, 23
N_PAR = 24

#: status codes of the right-hand side and the steppers
OK, NONFINITE, PITCH, AMPLITUDE, HALVE, DOUBLE, UNDERFLOW = 0, 1, 2, 3, 4, 5, 6

KIND_MODEL, KIND_LINEAR = 0, 1

#: per-mount flags: the mount has rotational stiffness or damping (a 6 x 6 mount); it carries a
#: nonlinear law
FLAG_ROTATION, FLAG_LAW = 1, 2

#: states of the body; the internal variables of viscoelastic mounts follow them
N_BODY = 12

#: length of the vector workspace: rotation vector (3), then the deflection and its rate (12);
#: for massive beam mounts the 6 x 6 system of the body's acceleration (36 + 6), the body-end map
#: ``G = R6 T_b`` (36) and a 6-vector
WS = 15
WS_A, WS_B, WS_G, WS_V = WS, WS + 36, WS + 42, WS + 78
WS_BEAM = WS + 84


@njit(cache=True, error_model="numpy")
def workspace(z):
    """``(rot, jinv, ws)``: the workspace of :func:`model_rhs` for states of ``z``'s dtype."""
    return np.zeros((3, 3), dtype=z.dtype), np.zeros((3, 3), dtype=z.dtype), np.zeros(WS_BEAM, dtype=z.dtype)


@njit(cache=True, inline="always", error_model="numpy")
def _cross3(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True, inline="always", error_model="numpy")
def _euler_into(phi, theta, psi, rot):
    """Rotation body -> hull for z-y-x Euler angles (``J1``); same formula as the linear module.
    Returns ``(cos phi, sin phi, cos theta, sin theta)`` for the kinematics ``J2``."""
    cf, sf = cos(phi), sin(phi)
    ct, st = cos(theta), sin(theta)
    cp, sp = cos(psi), sin(psi)
    rot[0, 0] = cp * ct
    rot[0, 1] = -sp * cf + cp * st * sf
    rot[0, 2] = sp * sf + cp * cf * st
    rot[1, 0] = sp * ct
    rot[1, 1] = cp * cf + sp * st * sf
    rot[1, 2] = -cp * sf + sp * st * cf
    rot[2, 0] = -st
    rot[2, 1] = ct * sf
    rot[2, 2] = ct * cf
    return cf, sf, ct, st


@njit(cache=True, inline="always", error_model="numpy")
def _rotate(rot, x0, x1, x2):
    return (rot[0, 0] * x0 + rot[0, 1] * x1 + rot[0, 2] * x2,
            rot[1, 0] * x0 + rot[1, 1] * x1 + rot[1, 2] * x2,
            rot[2, 0] * x0 + rot[2, 1] * x1 + rot[2, 2] * x2)


@njit(cache=True, inline="always", error_model="numpy")
def _rotate_t(rot, x0, x1, x2):
    return (rot[0, 0] * x0 + rot[1, 0] * x1 + rot[2, 0] * x2,
            rot[0, 1] * x0 + rot[1, 1] * x1 + rot[2, 1] * x2,
            rot[0, 2] * x0 + rot[1, 2] * x1 + rot[2, 2] * x2)


@njit(cache=True, inline="always", error_model="numpy")
def _pose_into(par, yeq, z, rot, jinv, ws):
    """R into ``rot``; when a mount has rotational terms, ``log R`` into ``ws[0:3]`` and
    ``J_l^{-1}(log R)`` into ``jinv``. Returns ``(cos phi, sin phi, cos theta, sin theta)``."""
    trig = _euler_into(yeq[3] + z[3], yeq[4] + z[4], yeq[5] + z[5], rot)
    if par[P_ROTATION] != 0.0:
        _log_so3_into(rot, ws)
        _jinv_into(ws, jinv)
    return trig


@njit(cache=True, inline="always", error_model="numpy")
def _mount_load(i, pos, kmat, cmat, flags, laws, rot, jinv, ws, x0, x1, x2, vh0, vh1, vh2, wh0, wh1, wh2):
    """Force of mount ``i`` on the body (hull frame, N), its mount moment (N m) and its arm
    ``rho_i = R r_i`` (m), as nine scalars; the pose is given by its parts."""
    r0, r1, r2 = pos[i, 0], pos[i, 1], pos[i, 2]
    rho0, rho1, rho2 = _rotate(rot, r0, r1, r2)
    d0, d1, d2 = x0 + rho0 - r0, x1 + rho1 - r1, x2 + rho2 - r2
    c0, c1, c2 = _cross3(wh0, wh1, wh2, rho0, rho1, rho2)
    dd0, dd1, dd2 = vh0 + c0, vh1 + c1, vh2 + c2
    m0 = m1 = m2 = 0.0 * d0
    if flags[i] & FLAG_ROTATION:
        # 6 x 6 mount: e = (d, log R), e' = (d', J_l^{-1} w)
        ws[3], ws[4], ws[5], ws[6], ws[7], ws[8] = d0, d1, d2, ws[0], ws[1], ws[2]
        ws[9], ws[10], ws[11] = dd0, dd1, dd2
        for a in range(3):
            ws[12 + a] = jinv[a, 0] * wh0 + jinv[a, 1] * wh1 + jinv[a, 2] * wh2
        g0 = g1 = g2 = g3 = g4 = g5 = 0.0 * d0
        for b in range(6):
            eb, edb = ws[3 + b], ws[9 + b]
            g0 += kmat[i, 0, b] * eb + cmat[i, 0, b] * edb
            g1 += kmat[i, 1, b] * eb + cmat[i, 1, b] * edb
            g2 += kmat[i, 2, b] * eb + cmat[i, 2, b] * edb
            g3 += kmat[i, 3, b] * eb + cmat[i, 3, b] * edb
            g4 += kmat[i, 4, b] * eb + cmat[i, 4, b] * edb
            g5 += kmat[i, 5, b] * eb + cmat[i, 5, b] * edb
        m0 = -(jinv[0, 0] * g3 + jinv[1, 0] * g4 + jinv[2, 0] * g5)
        m1 = -(jinv[0, 1] * g3 + jinv[1, 1] * g4 + jinv[2, 1] * g5)
        m2 = -(jinv[0, 2] * g3 + jinv[1, 2] * g4 + jinv[2, 2] * g5)
    else:
        g0 = kmat[i, 0, 0] * d0 + cmat[i, 0, 0] * dd0
        g0 += kmat[i, 0, 1] * d1 + cmat[i, 0, 1] * dd1
        g0 += kmat[i, 0, 2] * d2 + cmat[i, 0, 2] * dd2
        g1 = kmat[i, 1, 0] * d0 + cmat[i, 1, 0] * dd0
        g1 += kmat[i, 1, 1] * d1 + cmat[i, 1, 1] * dd1
        g1 += kmat[i, 1, 2] * d2 + cmat[i, 1, 2] * dd2
        g2 = kmat[i, 2, 0] * d0 + cmat[i, 2, 0] * dd0
        g2 += kmat[i, 2, 1] * d1 + cmat[i, 2, 1] * dd1
        g2 += kmat[i, 2, 2] * d2 + cmat[i, 2, 2] * dd2
    if flags[i] & FLAG_LAW:
        n0, n1, n2 = law_gradient(laws, i, d0, d1, d2)
        g0 += n0
        g1 += n1
        g2 += n2
    return -g0, -g1, -g2, m0, m1, m2, rho0, rho1, rho2


@njit(cache=True, inline="always", error_model="numpy")
def _prony_load(i, kmat, vstart, vpar, yeq, z, d0, d1, d2, out):
    """Force of the Prony terms of mount ``i`` on the body (hull frame, N) at deflection ``d``,
    and the rates ``w_ij' = (d - w_ij) / tau_ij`` of their internal variables into ``out``."""
    f0 = f1 = f2 = 0.0 * d0
    for j in range(vstart[i], vstart[i + 1]):
        s = N_BODY + 3 * j
        g, tau = vpar[j, 0], vpar[j, 1]
        e0 = d0 - (yeq[s] + z[s])
        e1 = d1 - (yeq[s + 1] + z[s + 1])
        e2 = d2 - (yeq[s + 2] + z[s + 2])
        out[s], out[s + 1], out[s + 2] = e0 / tau, e1 / tau, e2 / tau
        f0 -= g * (kmat[i, 0, 0] * e0 + kmat[i, 0, 1] * e1 + kmat[i, 0, 2] * e2)
        f1 -= g * (kmat[i, 1, 0] * e0 + kmat[i, 1, 1] * e1 + kmat[i, 1, 2] * e2)
        f2 -= g * (kmat[i, 2, 0] * e0 + kmat[i, 2, 1] * e1 + kmat[i, 2, 2] * e2)
    return f0, f1, f2


@njit(cache=True, inline="always", error_model="numpy")
def _beam_map_into(rot, r0, r1, r2, ws):
    """``G = R6 T(r) = [[R, -R S(r)], [0, R]]`` (body-frame ``nu`` -> hull-frame velocity of the
    body-end node at arm ``r``) into ``ws[WS_G:WS_G + 36]``, row-major."""
    for a in range(6):
        for c in range(6):
            ws[WS_G + 6 * a + c] = 0.0
    for a in range(3):
        ra0, ra1, ra2 = rot[a, 0], rot[a, 1], rot[a, 2]
        for c in range(3):
            ws[WS_G + 6 * a + c] = rot[a, c]
            ws[WS_G + 6 * (a + 3) + c + 3] = rot[a, c]
        # row a of -R S(r): -S(r) = [[0, r2, -r1], [-r2, 0, r0], [r1, -r0, 0]]
        ws[WS_G + 6 * a + 3] = -ra1 * r2 + ra2 * r1
        ws[WS_G + 6 * a + 4] = ra0 * r2 - ra2 * r0
        ws[WS_G + 6 * a + 5] = -ra0 * r1 + ra1 * r0


@njit(cache=True, inline="always", error_model="numpy")
def _beam_bias(rot, p, q, r, wv0, wv1, wv2, r0, r1, r2):
    """``R (w x v + w x (w x r))`` (hull frame): the body-end node's acceleration at ``nu' = 0``."""
    c0, c1, c2 = _cross3(p, q, r, r0, r1, r2)
    d0, d1, d2 = _cross3(p, q, r, c0, c1, c2)
    return _rotate(rot, wv0 + d0, wv1 + d1, wv2 + d2)


@njit(cache=True, error_model="numpy", _nrt=False)
def beam_body(bpos, bmat, bstart, bmode, mass6, s0, yeq, z, rot, p, q, r, u, v, w, tau0, tau1, tau2, tau3, tau4,
              tau5, ws, out):
    """Body acceleration ``nu'`` into ``out[6:12]`` and the rates of the beams' modal states into
    ``out[s0:s0 + 2 n]`` for the generalized force ``tau`` (body frame, moment about A) of
    everything but the beams' inertia (:mod:`impstab.dynamics.rhs`, massive beam mounts).

    ``bpos (nb, 3)`` arms, ``bmat (nb, 6, 6)`` ``N_b = m_tt - m_te m_te^T`` (hull frame),
    ``bstart (nb + 1,)`` the modes of beam b are ``bstart[b]:bstart[b + 1]``, ``bmode (n, 7)``
    per mode ``(Omega^2, m_te column)``, ``mass6`` the body's ``M_RB + M_A``; the states are
    ``eta = y[s0:s0 + n]``, ``eta' = y[s0 + n:s0 + 2 n]``.
    """
    n = bmode.shape[0]
    for a in range(6):
        for c in range(6):
            ws[WS_A + 6 * a + c] = mass6[a, c]
    ws[WS_B], ws[WS_B + 1], ws[WS_B + 2] = tau0, tau1, tau2
    ws[WS_B + 3], ws[WS_B + 4], ws[WS_B + 5] = tau3, tau4, tau5
    wv0, wv1, wv2 = _cross3(p, q, r, u, v, w)
    for b in range(bpos.shape[0]):
        r0, r1, r2 = bpos[b, 0], bpos[b, 1], bpos[b, 2]
        _beam_map_into(rot, r0, r1, r2, ws)
        ch0, ch1, ch2 = _beam_bias(rot, p, q, r, wv0, wv1, wv2, r0, r1, r2)
        # y = -N (R6 c) + m_te Omega^2 eta (hull frame), then tau += G^T y
        for a in range(6):
            ws[WS_V + a] = -(bmat[b, a, 0] * ch0 + bmat[b, a, 1] * ch1 + bmat[b, a, 2] * ch2)
        for j in range(bstart[b], bstart[b + 1]):
            k = bmode[j, 0] * (yeq[s0 + j] + z[s0 + j])
            for a in range(6):
                ws[WS_V + a] += bmode[j, 1 + a] * k
        for a in range(6):
            acc = 0.0 * ws[WS_V]
            for c in range(6):
                acc += ws[WS_G + 6 * c + a] * ws[WS_V + c]
            ws[WS_B + a] += acc
        # mass: A += G^T N G, column by column (N G e_c into ws[WS_V:])
        for c in range(6):
            for a in range(6):
                acc = 0.0 * ws[WS_V]
                for k in range(6):
                    acc += bmat[b, a, k] * ws[WS_G + 6 * k + c]
                ws[WS_V + a] = acc
            for a in range(6):
                acc = 0.0 * ws[WS_V]
                for k in range(6):
                    acc += ws[WS_G + 6 * k + a] * ws[WS_V + k]
                ws[WS_A + 6 * a + c] += acc
    # A nu' = tau: elimination without pivoting (A symmetric positive definite), nu' into out[6:12]
    for k in range(6):
        piv = ws[WS_A + 7 * k]
        for i in range(k + 1, 6):
            f = ws[WS_A + 6 * i + k] / piv
            for j in range(k + 1, 6):
                ws[WS_A + 6 * i + j] -= f * ws[WS_A + 6 * k + j]
            ws[WS_B + i] -= f * ws[WS_B + k]
    for i in range(5, -1, -1):
        acc = ws[WS_B + i]
        for j in range(i + 1, 6):
            acc -= ws[WS_A + 6 * i + j] * out[6 + j]
        out[6 + i] = acc / ws[WS_A + 7 * i]
    # modes: eta'' = -Omega^2 eta - m_te^T a, a = G nu' + R6 c
    for b in range(bpos.shape[0]):
        r0, r1, r2 = bpos[b, 0], bpos[b, 1], bpos[b, 2]
        _beam_map_into(rot, r0, r1, r2, ws)
        ch0, ch1, ch2 = _beam_bias(rot, p, q, r, wv0, wv1, wv2, r0, r1, r2)
        for a in range(6):
            acc = 0.0 * ws[WS_V]
            for c in range(6):
                acc += ws[WS_G + 6 * a + c] * out[6 + c]
            ws[WS_V + a] = acc
        ws[WS_V] += ch0
        ws[WS_V + 1] += ch1
        ws[WS_V + 2] += ch2
        for j in range(bstart[b], bstart[b + 1]):
            acc = -bmode[j, 0] * (yeq[s0 + j] + z[s0 + j])
            for a in range(6):
                acc -= bmode[j, 1 + a] * ws[WS_V + a]
            out[s0 + j] = yeq[s0 + n + j] + z[s0 + n + j]
            out[s0 + n + j] = acc


@njit(cache=True, error_model="numpy", _nrt=False, inline="always")
def model_rhs(pos, kmat, cmat, flags, laws, vstart, vpar, par, minv, damp6, bpos, bmat, bstart, bmode, mass6, yeq, z,
              thrust, spin, out, rot, jinv, ws):
    """``out = z'`` of the propulsor model at deviation ``z`` (thrust ``thrust`` N, spin
    ``spin`` rad/s), allocation-free: ``rot``, ``jinv`` and ``ws`` are the workspace of
    :func:`workspace` (of ``z``'s dtype; real or complex).

    ``vstart (n_mounts + 1,)``: the Prony terms of mount i are ``vstart[i]:vstart[i + 1]``;
    ``vpar (n_terms, 2)``: their weight ``g`` and relaxation time ``tau`` (s); their internal
    variables are the states ``12 + 3 j : 15 + 3 j``. ``bpos, bmat, bstart, bmode, mass6``: the
    massive beam mounts (:func:`beam_body`; no rows without them), their modal states after the
    internal variables.

    Returns a status: 0, or 2 when ``|Re theta|`` reached the pitch guard (the derivative is
    still computed unless ``cos(theta)`` vanishes).
    """
    theta = yeq[4] + z[4]
    status = OK
    if abs(theta.real) >= par[P_PITCH]:
        status = PITCH
        if abs(cos(theta).real) < 1e-12:
            for i in range(out.shape[0]):
                out[i] = math.nan
            return status
    cf, sf, ct, st = _pose_into(par, yeq, z, rot, jinv, ws)
    x0, x1, x2 = yeq[0] + z[0], yeq[1] + z[1], yeq[2] + z[2]
    u, v, w = yeq[6] + z[6], yeq[7] + z[7], yeq[8] + z[8]
    p, q, r = yeq[9] + z[9], yeq[10] + z[10], yeq[11] + z[11]
    vh0, vh1, vh2 = _rotate(rot, u, v, w)
    wh0, wh1, wh2 = _rotate(rot, p, q, r)
    # kinematics: X' = R nu1, Xi' = J2(Xi) nu2
    out[0], out[1], out[2] = vh0, vh1, vh2
    tt = st / ct
    out[3] = p + sf * tt * q + cf * tt * r
    out[4] = cf * q - sf * r
    out[5] = (sf * q + cf * r) / ct
    # forces in the hull frame, moments about A
    f0 = f1 = f2 = m0 = m1 = m2 = 0.0 * x0
    for i in range(pos.shape[0]):
        l0, l1, l2, l3, l4, l5, rho0, rho1, rho2 = _mount_load(
            i, pos, kmat, cmat, flags, laws, rot, jinv, ws, x0, x1, x2, vh0, vh1, vh2, wh0, wh1, wh2)
        if vstart[i + 1] > vstart[i]:
            v0, v1, v2 = _prony_load(i, kmat, vstart, vpar, yeq, z, x0 + rho0 - pos[i, 0], x1 + rho1 - pos[i, 1],
                                     x2 + rho2 - pos[i, 2], out)
            l0 += v0
            l1 += v1
            l2 += v2
        c0, c1, c2 = _cross3(rho0, rho1, rho2, l0, l1, l2)
        f0 += l0
        f1 += l1
        f2 += l2
        m0 += c0 + l3
        m1 += c1 + l4
        m2 += c2 + l5
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
    tau0, tau1, tau2 = _rotate_t(rot, f0, f1, f2)
    tau3, tau4, tau5 = _rotate_t(rot, m0, m1, m2)
    # propeller gyroscopic moment -w x h
    hmag = par[P_JP] * spin
    c0, c1, c2 = _cross3(p, q, r, hmag * e0, hmag * e1, hmag * e2)
    tau3 -= c0
    tau4 -= c1
    tau5 -= c2
    # Coriolis-centripetal terms C_RB(nu) nu (Newton-Euler form)
    mass = par[P_MASS]
    g0, g1, g2 = par[P_CG], par[P_CG + 1], par[P_CG + 2]
    wv0, wv1, wv2 = _cross3(p, q, r, u, v, w)
    wg0, wg1, wg2 = _cross3(p, q, r, g0, g1, g2)
    wwg0, wwg1, wwg2 = _cross3(p, q, r, wg0, wg1, wg2)
    tau0 -= mass * (wv0 + wwg0)
    tau1 -= mass * (wv1 + wwg1)
    tau2 -= mass * (wv2 + wwg2)
    iw0 = par[P_IA] * p + par[P_IA + 1] * q + par[P_IA + 2] * r
    iw1 = par[P_IA + 3] * p + par[P_IA + 4] * q + par[P_IA + 5] * r
    iw2 = par[P_IA + 6] * p + par[P_IA + 7] * q + par[P_IA + 8] * r
    c0, c1, c2 = _cross3(p, q, r, iw0, iw1, iw2)
    d0, d1, d2 = _cross3(g0, g1, g2, wv0, wv1, wv2)
    tau3 -= c0 + mass * d0
    tau4 -= c1 + mass * d1
    tau5 -= c2 + mass * d2
    # fluid radiation damping, then nu' = M^-1 tau
    if par[P_RADIATION] != 0.0:
        for a in range(6):
            s = damp6[a, 0] * u
            s += damp6[a, 1] * v
            s += damp6[a, 2] * w
            s += damp6[a, 3] * p
            s += damp6[a, 4] * q
            s += damp6[a, 5] * r
            ws[3 + a] = s
        tau0 -= ws[3]
        tau1 -= ws[4]
        tau2 -= ws[5]
        tau3 -= ws[6]
        tau4 -= ws[7]
        tau5 -= ws[8]
    if bpos.shape[0] > 0:
        beam_body(bpos, bmat, bstart, bmode, mass6, N_BODY + 3 * vpar.shape[0], yeq, z, rot, p, q, r, u, v, w,
                  tau0, tau1, tau2, tau3, tau4, tau5, ws, out)
        return status
    for a in range(6):
        s = minv[a, 0] * tau0
        s += minv[a, 1] * tau1
        s += minv[a, 2] * tau2
        s += minv[a, 3] * tau3
        s += minv[a, 4] * tau4
        s += minv[a, 5] * tau5
        out[6 + a] = s
    return status


@njit(cache=True, error_model="numpy", _nrt=False)
def linear_rhs(amat, z, out):
    """``out = A z`` (the linear test systems of the integrators)."""
    n = z.shape[0]
    for i in range(n):
        s = 0.0 * z[0]
        for j in range(n):
            s += amat[i, j] * z[j]
        out[i] = s
    return OK


@njit(cache=True, error_model="numpy", compile_first=True)
def rhs_batch(kind, arrays, yeq, zs, thrust, spin, out, status):
    """``out[k] = z'`` at each row ``zs[k]`` (real or complex) with thrust ``thrust`` (N) and spin
    ``spin`` (rad/s), one workspace for all rows; ``status[k]`` the row's status.

    ``arrays`` is the tuple of :class:`~impstab.dynamics.system.DynamicSystem`. The one entry
    point from Python (a single state is a batch of one row); compiled loops call
    :func:`model_rhs` with a workspace of their own.
    """
    if zs.shape[0] == 0:
        return
    rot, jinv, ws = workspace(zs[0])
    pos, kmat, cmat, flags, laws = arrays[0], arrays[1], arrays[2], arrays[3], arrays[4]
    par, minv, damp6, amat = arrays[5], arrays[6], arrays[7], arrays[8]
    vstart, vpar = arrays[9], arrays[10]
    bpos, bmat, bstart, bmode, mass6 = arrays[11], arrays[12], arrays[13], arrays[14], arrays[15]
    for k in range(zs.shape[0]):
        if kind == KIND_LINEAR:
            status[k] = linear_rhs(amat, zs[k], out[k])
        else:
            status[k] = model_rhs(pos, kmat, cmat, flags, laws, vstart, vpar, par, minv, damp6, bpos, bmat, bstart,
                                  bmode, mass6, yeq, zs[k], thrust, spin, out[k], rot, jinv, ws)


@njit(cache=True, error_model="numpy", compile_first=True)
def mount_loads_series(arrays, yeq, zs, out):
    """Mount forces (hull frame, N) and mount moments (N m) on the body for each state row of
    ``zs``, the Prony terms of viscoelastic mounts included; ``out`` has shape
    ``(n_samples, n_mounts, 6)``. A massive beam mount's load is that of its static tip stiffness
    (and dampers) at the body-end deflection, without the beam's inertia force
    (:mod:`impstab.dynamics.beam_mounts`)."""
    pos, kmat, cmat, flags, laws, par = arrays[0], arrays[1], arrays[2], arrays[3], arrays[4], arrays[5]
    vstart, vpar = arrays[9], arrays[10]
    rot, jinv, ws = workspace(yeq)
    rates = np.zeros(yeq.shape[0])
    for k in range(zs.shape[0]):
        z = zs[k]
        _pose_into(par, yeq, z, rot, jinv, ws)
        vh0, vh1, vh2 = _rotate(rot, yeq[6] + z[6], yeq[7] + z[7], yeq[8] + z[8])
        wh0, wh1, wh2 = _rotate(rot, yeq[9] + z[9], yeq[10] + z[10], yeq[11] + z[11])
        x0, x1, x2 = yeq[0] + z[0], yeq[1] + z[1], yeq[2] + z[2]
        for i in range(pos.shape[0]):
            load = _mount_load(i, pos, kmat, cmat, flags, laws, rot, jinv, ws, x0, x1, x2, vh0, vh1, vh2,
                               wh0, wh1, wh2)
            for a in range(6):
                out[k, i, a] = load[a]
            if vstart[i + 1] > vstart[i]:
                v = _prony_load(i, kmat, vstart, vpar, yeq, z, x0 + load[6] - pos[i, 0], x1 + load[7] - pos[i, 1],
                                x2 + load[8] - pos[i, 2], rates)
                for a in range(3):
                    out[k, i, a] += v[a]
