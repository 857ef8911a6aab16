"""Exact generalized forces and tangent stiffness of the mounted body under thrust (THEORY 4).

The body pose is ``(u, R)``: translation of A and rotation body -> hull. Generalized coordinates
are ``q = (du, dphi)`` with a *spatial* rotation increment, ``R <- exp(S(dphi)) R``; generalized
forces are the resultant force on the body and the moment about the current position of A
(hull frame). The stiffness is ``K = -dQ/dq``.

Each mount is an elastic element with potential ``V = 1/2 e^T k e`` on its body-end deflection
``e = (u + R r - r, phi)`` with ``phi = log(R)`` (rotation vector), so that
``Q_i = -B_i^T k_i e_i``, ``B_i = [[I, -S(rho_i)], [0, J_l^{-1}(phi)]]``, ``rho_i = R r_i``.
For the paper's mount (translation block only) this is ``f_i = -k_i d_i`` at the arm ``rho_i``.
A nonlinear mount law (:mod:`impstab.model.mount_law`) adds its potential ``V_nl(d_i)`` on the
translation deflection: ``g_i[:3] += grad V_nl`` and ``k_i[:3, :3] += hess V_nl`` in both the
force and the elastic tangent (the preload part uses the total force).
The tangent is ``sum B_i^T k_i B_i`` plus the preload (geometric) part
``-S(f_i) S(rho_i) + H(phi, g_phi) J_l^{-1}`` plus the thrust part
``[[0, S(f_F)], [0, -S(f_F + f_D) S(rho_T) + S(rho_T) S(f_F)]]``.

The functions are compiled with numba (``cache=True``); with ``NUMBA_DISABLE_JIT=1`` the same
code runs as plain Python/NumPy and gives identical results.
"""

from __future__ import annotations

import numpy as np
from .._jit import njit

from ..kinematics.so3 import _cross, _d_jinvT_w, _exp_so3, _jinv, _log_so3, _skew
from ..model.mount_law import LAW_K3_AXIAL, N_LAW, law_gradient, law_hessian

__all__ = ["pose_forces", "static_equilibrium_packed", "linearize_batch", "classical_forms", "MAX_PREDICTOR",
           "NEWTON_FLOOR", "RESIDUAL_FLOOR"]

#: largest accepted predictor step of the continuation (rad, or fraction of the length scale)
MAX_PREDICTOR = 0.02
#: Newton corrections below this (relative to the length scale, or rad) that stop shrinking are
#: rounding: the equilibrium is converged
NEWTON_FLOOR = 1e-9
#: a pose whose force and moment residuals are below this fraction of the thrust (and of the
#: thrust times the length scale) is an equilibrium to rounding, whatever correction Newton's
#: ill-conditioned tangent would still make (very soft mounts under a large thrust)
RESIDUAL_FLOOR = 64 * 2.220446049250313e-16


@njit(cache=True)
def _has_law(laws, i):
    for a in range(LAW_K3_AXIAL, N_LAW):
        if laws[i, a] != 0.0:
            return True
    return False


@njit(cache=True)
def pose_forces(u, rot, thrust, positions, stiffness, damping, e_dir, r_thrust, tangency, laws):
    """Generalized forces and tangent pieces at the pose ``(u, rot)`` under thrust ``T``.

    ``laws`` is the ``(n_mounts, N_LAW)`` table of nonlinear mount laws (rows of zeros: linear
    mounts).

    Returns
    -------
    q_force : (6,) generalized force (N, N m about the current A, hull frame)
    k_elastic : (6, 6) ``sum B^T k B``
    k_preload : (6, 6) mount preload (geometric) stiffness
    k_thrust : (6, 6) load stiffness of the thrust
    d_mount : (6, 6) ``sum B^T c B``
    """
    nm = positions.shape[0]
    q_force = np.zeros(6)
    k_el = np.zeros((6, 6))
    k_pre = np.zeros((6, 6))
    k_thr = np.zeros((6, 6))
    d_m = np.zeros((6, 6))
    phi = _log_so3(rot)
    jinv = _jinv(phi)
    hess = np.zeros((3, 3))
    for i in range(nm):
        r = positions[i]
        rho = rot @ r
        e = np.empty(6)
        e[:3] = u + rho - r
        e[3:] = phi
        b = np.zeros((6, 6))
        b[0, 0] = 1.0
        b[1, 1] = 1.0
        b[2, 2] = 1.0
        b[:3, 3:] = -_skew(rho)
        b[3:, 3:] = jinv
        g = stiffness[i] @ e
        k_i = stiffness[i]
        if _has_law(laws, i):
            g0, g1, g2 = law_gradient(laws, i, e[0], e[1], e[2])
            g[0] += g0
            g[1] += g1
            g[2] += g2
            law_hessian(laws, i, e[0], e[1], e[2], hess)
            k_i = stiffness[i].copy()
            k_i[:3, :3] += hess
        f = -g[:3]
        gphi = g[3:].copy()
        m = -(jinv.T @ gphi)
        q_force[:3] += f
        q_force[3:] += _cross(rho, f) + m
        k_el += b.T @ k_i @ b
        d_m += b.T @ damping[i] @ b
        k_pre[3:, 3:] += -_skew(f) @ _skew(rho)
        if gphi[0] != 0.0 or gphi[1] != 0.0 or gphi[2] != 0.0:
            k_pre[3:, 3:] += _d_jinvT_w(phi, gphi) @ jinv
    rho_t = rot @ r_thrust
    f_f = tangency * thrust * (rot @ e_dir)
    f_d = (1.0 - tangency) * thrust * e_dir
    f_t = f_f + f_d
    q_force[:3] += f_t
    q_force[3:] += _cross(rho_t, f_t)
    k_thr[:3, 3:] = _skew(f_f)
    k_thr[3:, 3:] = -_skew(f_t) @ _skew(rho_t) + _skew(rho_t) @ _skew(f_f)
    return q_force, k_el, k_pre, k_thr, d_m


@njit(cache=True)
def static_equilibrium_packed(
    t_from, t_to, u0, rot0, positions, stiffness, damping, e_dir, r_thrust, tangency, length_scale, laws
):
    """Follow the static equilibrium from ``(u0, rot0)`` at thrust ``t_from`` to ``t_to``.

    Newton's method with the full tangent (preload included) on load steps; a step is accepted
    only if its tangent predictor is small (``MAX_PREDICTOR`` rad, or that fraction of the
    length scale) and it lands near it (the Newton corrections after the first step are smaller
    than half of it); otherwise the step is subdivided. A jump to a distant branch is
    thereby refused: where no nearby equilibrium exists (a limit point) the result is not
    converged. Returns ``(u, rot, iterations, converged)``.

    Convergence: a correction below ``1e-13`` (relative to the length scale, or rad) twice, or
    one below ``NEWTON_FLOOR`` that is no smaller than the one before it, or a residual below
    ``RESIDUAL_FLOOR`` times the thrust (force) and the thrust times the length scale (moment),
    the rounding level of the balance: where the tangent is ill-conditioned (a shear stiffness
    of 1 N/m under 0.5 MN leaves a lateral stiffness of 0.06 N/m) the rounding of the forces
    moves Newton's corrections above ``NEWTON_FLOOR`` although the pose balances to rounding
    (a backward-stable equilibrium; the pose itself is then defined only to that size). The second rule
    recognises the rounding floor of the equilibrium: where the mounts are very soft against
    the thrust (a shear stiffness of 1 N/m under 8 kN) rounding of the forces alone moves the
    pose by more than ``1e-13``, and Newton's corrections stop shrinking there instead of
    falling below a fixed tolerance. Converging Newton corrections always shrink (quadratically,
    or by a factor 1/2 at a limit point), so a correction that does not shrink is rounding.
    """
    total = 0
    u = u0.copy()
    rot = rot0.copy()
    for n_sub in (1, 4, 16, 64, 256, 1024):
        u = u0.copy()
        rot = rot0.copy()
        ok = True
        for k in range(1, n_sub + 1):
            load = t_from + (t_to - t_from) * k / n_sub
            converged = False
            small = 0
            first = -1.0
            later = 0.0
            previous = np.inf
            for it in range(60):
                qf, kel, kpre, kthr, _ = pose_forces(
                    u, rot, load, positions, stiffness, damping, e_dir, r_thrust, tangency, laws
                )
                floor = RESIDUAL_FLOOR * abs(load)
                if it > 0 and np.max(np.abs(qf[:3])) <= floor and np.max(np.abs(qf[3:])) <= floor * length_scale:
                    converged = True  # balanced to rounding
                    break
                step = np.linalg.solve(kel + kpre + kthr, qf)
                total += 1
                if not np.all(np.isfinite(step)):
                    break
                size = max(np.max(np.abs(step[:3])) / length_scale, np.max(np.abs(step[3:])))
                if first < 0.0:
                    first = size
                else:
                    later += size
                if first > MAX_PREDICTOR or later > 0.5 * first + 1e-10:
                    break
                if size < NEWTON_FLOOR and size >= previous:
                    converged = True  # the rounding floor: keep the pose before this correction
                    break
                previous = size
                u = u + step[:3]
                rot = _exp_so3(step[3:]) @ rot
                if size < 1e-13:
                    small += 1
                    if small >= 2 or size < 1e-16:
                        converged = True
                        break
            if not converged:
                ok = False
                break
        if ok:
            return u, rot, total, True
    return u, rot, total, False


@njit(cache=True)
def _block_rotate(mat, rot):
    big = np.zeros((6, 6))
    big[:3, :3] = rot
    big[3:, 3:] = rot
    return big @ mat @ big.T


@njit(cache=True)
def linearize_batch(
    thrusts, spins, mass6, damp6, positions, stiffness, damping, e_dir, r_thrust, tangency,
    preload, polar_inertia, equilibrium, length_scale, t_start=0.0, u_start=None, r_start=None, laws=None,
):
    """Linearized matrices ``M, D, G, K`` (stacks ``(N, 6, 6)``) at each thrust.

    ``laws``: the ``(n_mounts, N_LAW)`` nonlinear mount laws (None: linear mounts); they enter
    the equilibrium form only (the classical form is the tangent at zero deflection, where a
    law adds nothing).

    ``equilibrium=True``: at the nonlinear static equilibrium, followed by continuation along
    the sorted thrusts from the equilibrium ``(u_start, r_start)`` at ``t_start`` (default the
    unloaded pose); a thrust the path cannot reach (past a limit point) is not converged; otherwise the classical form at the undeformed configuration with mount forces
    from linear statics. ``spins`` are the propeller speeds Omega (rad/s) at each thrust;
    ``mass6`` (rigid body plus added mass) and ``damp6`` (fluid radiation damping) are body-frame
    matrices about A, rotated with the body.
    Returns ``M, D, G, K, u0 (N, 3), R0 (N, 3, 3), converged (N,)``.
    """
    n = thrusts.shape[0]
    m_out = np.zeros((n, 6, 6))
    d_out = np.zeros((n, 6, 6))
    g_out = np.zeros((n, 6, 6))
    k_out = np.zeros((n, 6, 6))
    u_out = np.zeros((n, 3))
    r_out = np.zeros((n, 3, 3))
    ok_out = np.ones(n, dtype=np.bool_)
    nm = positions.shape[0]
    if laws is None:
        law_table = np.zeros((nm, N_LAW))
    else:
        law_table = laws
    # condensed elastic stiffness at rest (classical statics)
    k_c = np.zeros((6, 6))
    eye3 = np.eye(3)
    for i in range(nm):
        t6 = np.zeros((6, 6))
        t6[:3, :3] = eye3
        t6[:3, 3:] = -_skew(positions[i])
        t6[3:, 3:] = eye3
        k_c += t6.T @ stiffness[i] @ t6
    order = np.argsort(np.abs(thrusts))
    u_prev = np.zeros(3) if u_start is None else u_start.copy()
    r_prev = np.eye(3) if r_start is None else r_start.copy()
    t_prev = t_start
    for j in range(n):
        idx = order[j]
        thrust = thrusts[idx]
        if equilibrium:
            u, rot, _, conv = static_equilibrium_packed(
                t_prev, thrust, u_prev, r_prev, positions, stiffness, damping, e_dir, r_thrust,
                tangency, length_scale, law_table,
            )
            ok_out[idx] = conv
            if conv:
                u_prev = u
                r_prev = rot
                t_prev = thrust
            qf, kel, kpre, kthr, dm = pose_forces(
                u, rot, thrust, positions, stiffness, damping, e_dir, r_thrust, tangency, law_table
            )
        else:
            u = np.zeros(3)
            rot = np.eye(3)
            load = np.zeros(6)
            load[:3] = thrust * e_dir
            load[3:] = _cross(r_thrust, thrust * e_dir)
            q0 = np.linalg.solve(k_c, load)
            kel = k_c.copy()
            kpre = np.zeros((6, 6))
            dm = np.zeros((6, 6))
            for i in range(nm):
                r = positions[i]
                t6 = np.zeros((6, 6))
                t6[:3, :3] = eye3
                t6[:3, 3:] = -_skew(r)
                t6[3:, 3:] = eye3
                g = stiffness[i] @ (t6 @ q0)
                f = -g[:3]
                kpre[3:, 3:] += -_skew(f) @ _skew(r) - 0.5 * _skew(g[3:])
                dm += t6.T @ damping[i] @ t6
            f_f = tangency * thrust * e_dir
            f_t = thrust * e_dir
            kthr = np.zeros((6, 6))
            kthr[:3, 3:] = _skew(f_f)
            kthr[3:, 3:] = -_skew(f_t) @ _skew(r_thrust) + _skew(r_thrust) @ _skew(f_f)
        k = kel + kthr
        if preload:
            k = k + kpre
        m_out[idx] = _block_rotate(mass6, rot)
        d_out[idx] = dm + _block_rotate(damp6, rot)
        h = polar_inertia * spins[idx] * (rot @ e_dir)
        g_out[idx, 3:, 3:] = -_skew(h)
        k_out[idx] = k
        u_out[idx] = u
        r_out[idx] = rot
    return m_out, d_out, g_out, k_out, u_out, r_out, ok_out


@njit(cache=True)
def _skew_into(out, a):
    """Write the cross-product matrix ``S(a)`` (``S(a) b = a x b``) into the 3x3 ``out``."""
    out[0, 0] = 0.0
    out[0, 1] = -a[2]
    out[0, 2] = a[1]
    out[1, 0] = a[2]
    out[1, 1] = 0.0
    out[1, 2] = -a[0]
    out[2, 0] = -a[1]
    out[2, 1] = a[0]
    out[2, 2] = 0.0


@njit(cache=True)
def _add_skew_product(out, scale, sa, sb):
    """``out[3:, 3:] += scale * sa @ sb`` for 3x3 ``sa, sb``."""
    for i in range(3):
        for j in range(3):
            acc = 0.0
            for k in range(3):
                acc += sa[i, k] * sb[k, j]
            out[3 + i, 3 + j] += scale * acc


@njit(cache=True)
def _add_moved(out, mat, sr, work):
    """``out += T^T mat T`` with ``T = [[I, -sr], [0, I]]``: a 6x6 mount matrix (N/m, N/rad,
    N m/rad; or the damping analogues) at the mount end moved to the reference point A.

    ``sr`` is ``S(r)`` of the mount position ``r`` (m); ``work`` is 6x6 scratch.
    """
    # work = mat @ T
    for i in range(6):
        for j in range(3):
            work[i, j] = mat[i, j]
            acc = 0.0
            for k in range(3):
                acc += mat[i, k] * sr[k, j]
            work[i, 3 + j] = mat[i, 3 + j] - acc
    # out += T^T work; the rows 3..5 of T^T are [S(r), I] (S(r) is skew)
    for j in range(6):
        for i in range(3):
            out[i, j] += work[i, j]
            out[3 + i, j] += sr[i, 0] * work[0, j] + sr[i, 1] * work[1, j] + sr[i, 2] * work[2, j] + work[3 + i, j]


@njit(cache=True)
def classical_forms(mass6, damp6, positions, stiffness, damping, e_dir, r_thrust, tangency, preload):
    """The classical linearization ``K = K0 + T K1`` of many designs, formed directly.

    The same matrices as :func:`linearize_batch` with ``equilibrium=False`` (undeformed
    configuration, mount forces from linear statics), unit propeller spin and polar inertia,
    written out for zero rotation and split into the parts constant and linear in the thrust
    ``T``, without per-design allocations.

    Parameters
    ----------
    mass6, damp6 : (n, 6, 6) arrays
        Body-frame mass (kg, kg m, kg m^2) and fluid damping about A of each design.
    positions : (n, nm, 3) array
        Mount positions (m).
    stiffness, damping : (n, nm, 6, 6) arrays
        Mount stiffness (N/m, N/rad, N m/rad) and damping (N s/m, ...) at the mount ends.
    e_dir, r_thrust : (n, 3) arrays
        Thrust direction (unit) and point of application (m).
    tangency : (n,) array
        Follower fraction of the thrust (1 follower, 0 fixed direction).
    preload : bool
        Include the mount-preload (geometric) stiffness.

    Returns
    -------
    m, d, g : (n, 6, 6) arrays
        ``M``, ``D`` and ``G`` per unit ``I_p Omega`` (kg m^2/s per kg m^2/s).
    k0 : (n, 6, 6) array
        Stiffness at zero thrust, the condensed mount stiffness (N/m, N, N m/rad).
    k1 : (n, 6, 6) array
        Its rate per newton of thrust (1/m, 1, m).
    q1 : (n, 6) array
        Static displacement per newton of thrust from linear statics, ``K0^-1 [e; r_T x e]``
        (m/N, rad/N).
    """
    n = mass6.shape[0]
    nm = positions.shape[1]
    m = np.empty((n, 6, 6))
    d = np.empty((n, 6, 6))
    g = np.zeros((n, 6, 6))
    k0 = np.empty((n, 6, 6))
    k1 = np.empty((n, 6, 6))
    q1 = np.empty((n, 6))
    sr = np.empty((nm, 3, 3))
    sa = np.empty((3, 3))
    sb = np.empty((3, 3))
    work = np.empty((6, 6))
    load = np.empty(6)
    e_t = np.empty(3)
    gi = np.empty(6)
    for c in range(n):
        m[c] = mass6[c]
        kc = k0[c]
        kc[:] = 0.0
        dc = d[c]
        dc[:] = 0.0
        for i in range(nm):
            _skew_into(sr[i], positions[c, i])
            _add_moved(kc, stiffness[c, i], sr[i], work)
            _add_moved(dc, damping[c, i], sr[i], work)
        dc += damp6[c]
        # gyroscopic matrix of a unit angular momentum along the thrust axis
        _skew_into(sa, e_dir[c])
        for i in range(3):
            for j in range(3):
                g[c, 3 + i, 3 + j] = -sa[i, j]
        # static displacement per unit thrust (linear statics at the undeformed configuration)
        e = e_dir[c]
        r = r_thrust[c]
        load[:3] = e
        load[3:] = _cross(r, e)
        q = np.linalg.solve(kc, load)
        q1[c] = q
        # thrust load stiffness per unit thrust: [[0, S(tau e)], [0, -S(e) S(r_T) + S(r_T) S(tau e)]]
        kt = k1[c]
        kt[:] = 0.0
        for i in range(3):
            e_t[i] = tangency[c] * e[i]
        _skew_into(sb, e_t)
        for i in range(3):
            for j in range(3):
                kt[i, 3 + j] = sb[i, j]
        _skew_into(sa, r)
        _add_skew_product(kt, 1.0, sa, sb)
        _skew_into(sb, e)
        _add_skew_product(kt, -1.0, sb, sa)
        if preload:
            # mount preload per unit thrust: sum_i S(g_i[:3]) S(r_i) - 1/2 S(g_i[3:]), g_i = k_i T_i q
            for i in range(nm):
                for a in range(6):
                    acc = 0.0
                    for b in range(3):
                        acc += stiffness[c, i, a, b] * (q[b] - (sr[i, b, 0] * q[3] + sr[i, b, 1] * q[4] + sr[i, b, 2] * q[5]))
                    for b in range(3, 6):
                        acc += stiffness[c, i, a, b] * q[b]
                    gi[a] = acc
                _skew_into(sa, gi[:3])
                _add_skew_product(kt, 1.0, sa, sr[i])
                _skew_into(sa, gi[3:])
                for a in range(3):
                    for b in range(3):
                        kt[3 + a, 3 + b] -= 0.5 * sa[a, b]
    return m, d, g, k0, k1, q1
