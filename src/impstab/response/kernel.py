"""The compiled harmonic solve over designs and frequencies, with the mount forces and powers.

For each design and frequency one loop forms the 6 x 6 complex dynamic stiffness
``Z = K + i omega C - omega^2 M + X`` (plus the series correction of a compliant foundation),
solves ``Z q = F`` by Gaussian elimination with partial pivoting (the algorithm of LAPACK's
``zgesv``, unblocked, which is what ``zgesv`` does at this size; pivots chosen by
``|Re| + |Im|`` like LAPACK's ``izamax``) and evaluates the mount forces on
the hull and the powers of :mod:`impstab.response.core`. The elimination is backward stable like
``numpy.linalg.solve``; the two agree to rounding (tests/response/test_kernel.py).

Why a kernel of its own: ``numpy.linalg.solve`` on a stack of 6 x 6 systems spends most of its
time in per-matrix overhead (copies into Fortran order, workspace, the gufunc loop) and measured
only 3-5 times a Python loop of solves; forming the stack and the mount quantities with NumPy
(stacked small matmuls, einsum) cost more than the solve. Done here in scratch arrays, a
frequency costs about a microsecond with four mounts (benchmarks/response.py). A modal or
state-space method would be cheaper still but loses accuracy with the conditioning of the
eigenvectors, which is unbounded at the flutter onset (a defective double eigenvalue);
elimination on each system does not.

Compiled with numba (``cache=True``, NumPy error model: a singular system gives inf/NaN, flagged
by the pivot ratio, instead of raising); with ``NUMBA_DISABLE_JIT=1`` the same code runs as Python.
"""

from __future__ import annotations

import numpy as np
from .._jit import njit

__all__ = ["solve_harmonic", "response_outputs", "eliminate"]


@njit(cache=True, nogil=True, error_model="numpy")
def eliminate(a, b):  # pragma: no cover - compiled
    """Solve ``a x = b`` in place (``a (n, n)``, ``b (n, r)`` complex; ``b`` becomes ``x``).

    Gaussian elimination with partial pivoting. Returns the smallest over the largest pivot
    magnitude (0 for a singular matrix).
    """
    n = a.shape[0]
    nr = b.shape[1]
    big = 0.0
    small = np.inf
    for k in range(n):
        p = k
        best = abs(a[k, k].real) + abs(a[k, k].imag)
        for i in range(k + 1, n):
            v = abs(a[i, k].real) + abs(a[i, k].imag)
            if v > best:
                best = v
                p = i
        if p != k:
            for j in range(n):
                t = a[k, j]
                a[k, j] = a[p, j]
                a[p, j] = t
            for j in range(nr):
                t = b[k, j]
                b[k, j] = b[p, j]
                b[p, j] = t
        big = max(big, best)
        small = min(small, best)
        if best == 0.0:
            continue
        inv = 1.0 / a[k, k]
        for i in range(k + 1, n):
            factor = a[i, k] * inv
            if factor != 0.0:
                for j in range(k + 1, n):
                    a[i, j] -= factor * a[k, j]
                for j in range(nr):
                    b[i, j] -= factor * b[k, j]
    for i in range(n - 1, -1, -1):
        for j in range(nr):
            acc = b[i, j]
            for c in range(i + 1, n):
                acc -= a[i, c] * b[c, j]
            if a[i, i] == 0.0:
                b[i, j] = complex(np.nan, np.nan)  # singular: numba's complex division would raise
            else:
                b[i, j] = acc / a[i, i]
    return small / big if big > 0.0 else 0.0


@njit(cache=True, nogil=True, error_model="numpy", compile_first=True)
def solve_harmonic(mass, damping, stiffness, omega, loads, extra, maps, mount_k, mount_c, hull):  # pragma: no cover - compiled
    """Solve ``Z q = F`` for every design and frequency.

    Parameters
    ----------
    mass, damping, stiffness : (nd, 6, 6) float
        M, C (= D + G) and K.
    omega : (nf,) float
        Angular frequencies (rad/s).
    loads : (nd or 1, nf or 1, 6) complex
        Load amplitudes at A (N, N m); an axis of length 1 is shared.
    extra : (nd, nf or 0, 6, 6) complex
        Frequency-dependent part X of Z (fluid); an empty axis means none.
    maps : (nd, nm, 6, 6) float
        Body-end maps B_i of the mounts.
    mount_k, mount_c : (nd, nm, 6, 6) float
        Mount stiffness and damping at the body end.
    hull : (nd or 1, nf or 0, nm) complex
        Dynamic stiffness S of the hull at each attachment (N/m); an empty axis is a rigid hull.
        A compliant hull adds ``B^T (k_eff - k*) B`` with
        ``k_eff - k* = -k*[:, :3] (S I + k*_tt)^-1 k*[:3, :]`` (the mount in series with the hull point).

    Returns
    -------
    q : (nd, nf, 6) complex
    pivot_ratio : (nd, nf) float
        Smallest over largest pivot magnitude (0: singular, an undamped resonance hit exactly).
    """
    nd = stiffness.shape[0]
    nf = omega.shape[0]
    nm = maps.shape[1]
    q_out = np.empty((nd, nf, 6), dtype=np.complex128)
    ratio = np.empty((nd, nf))
    a = np.empty((6, 6), dtype=np.complex128)
    rhs = np.empty((6, 1), dtype=np.complex128)
    kstar = np.empty((6, 6), dtype=np.complex128)
    ser = np.empty((3, 3), dtype=np.complex128)
    red = np.empty((3, 6), dtype=np.complex128)
    corr = np.empty((6, 6), dtype=np.complex128)
    tmp = np.empty((6, 6), dtype=np.complex128)
    step_fl = 1 if loads.shape[1] > 1 else 0
    step_dl = 1 if loads.shape[0] > 1 else 0
    step_dh = 1 if hull.shape[0] > 1 else 0
    has_extra = extra.shape[1] > 0
    compliant = hull.shape[1] > 0
    for d in range(nd):
        for f in range(nf):
            w = omega[f]
            w2 = w * w
            for i in range(6):
                for j in range(6):
                    a[i, j] = complex(stiffness[d, i, j] - w2 * mass[d, i, j], w * damping[d, i, j])
            if has_extra:
                for i in range(6):
                    for j in range(6):
                        a[i, j] += extra[d, f, i, j]
            if compliant:
                for mi in range(nm):
                    s = hull[d * step_dh, f, mi]
                    if not (np.isfinite(s.real) and np.isfinite(s.imag)):
                        continue
                    for i in range(6):
                        for j in range(6):
                            kstar[i, j] = complex(mount_k[d, mi, i, j], w * mount_c[d, mi, i, j])
                    for i in range(3):
                        for j in range(3):
                            ser[i, j] = kstar[i, j]
                        ser[i, i] += s
                        for j in range(6):
                            red[i, j] = kstar[i, j]
                    eliminate(ser, red)
                    for i in range(6):
                        for j in range(6):
                            acc = 0.0j
                            for c in range(3):
                                acc += kstar[i, c] * red[c, j]
                            corr[i, j] = acc
                    for i in range(6):
                        for j in range(6):
                            acc = 0.0j
                            for c in range(6):
                                acc += corr[i, c] * maps[d, mi, c, j]
                            tmp[i, j] = acc
                    for i in range(6):
                        for j in range(6):
                            acc = 0.0j
                            for c in range(6):
                                acc += maps[d, mi, c, i] * tmp[c, j]
                            a[i, j] -= acc
            for i in range(6):
                rhs[i, 0] = loads[d * step_dl, f * step_fl, i]
            ratio[d, f] = eliminate(a, rhs)
            for i in range(6):
                q_out[d, f, i] = rhs[i, 0]
    return q_out, ratio


@njit(cache=True, nogil=True, error_model="numpy")
def _quad_parts(a, qr, qi):  # pragma: no cover - compiled
    """``q^H A q`` for a real ``A`` and ``q = qr + i qi``: returns ``(Re, Im)``."""
    re = 0.0
    im = 0.0
    for i in range(6):
        ar = 0.0
        ai = 0.0
        for j in range(6):
            ar += a[i, j] * qr[j]
            ai += a[i, j] * qi[j]
        re += qr[i] * ar + qi[i] * ai
        im += qr[i] * ai - qi[i] * ar
    return re, im


@njit(cache=True, nogil=True, error_model="numpy", compile_first=True)
def response_outputs(
    q, omega, loads, extra, maps, force_k, force_c, damper, mount_k, mount_c, hull, load_k, fluid_d
):  # pragma: no cover - compiled
    """Mount deflections and forces, hull-end motion and the powers from the response ``q``.

    ``force_k, force_c (nd, nm, 3, 6)`` are ``(k_i B_i)[:3]`` and ``(c_i B_i)[:3]``, so that the
    rigid-hull force is ``f* = (force_k + i omega force_c) q``; ``damper (nd, nm, 6, 6)`` is
    ``B_i^T c_i B_i``. On a compliant hull (``hull (nd or 1, nf, nm)``, else an empty second
    axis) ``x = (S I + k*_tt)^-1 f*`` and ``F = S x``; the mount's own deflection is ``B q - x``.
    ``load_k`` and ``fluid_d (nd, 6, 6)`` are the load stiffness and the constant fluid damping;
    ``loads`` and ``extra`` as in :func:`solve_harmonic`.

    Returns ``deflection (nd, nf, nm, 6)``, ``hull_disp (nd, nf, nm, 3)``, ``force (nd, nf, nm, 3)``,
    ``hull_force (nd, nf, 3)`` (the sum over the mounts) complex; ``power_input``, ``power_thrust``, ``power_fluid (nd, nf)``, ``power_damper`` and
    ``power_transmitted (nd, nf, nm)`` float (W).
    """
    nd = q.shape[0]
    nf = omega.shape[0]
    nm = force_k.shape[1]
    d_out = np.empty((nd, nf, nm, 6), dtype=np.complex128)
    x_out = np.zeros((nd, nf, nm, 3), dtype=np.complex128)
    f_out = np.empty((nd, nf, nm, 3), dtype=np.complex128)
    h_out = np.zeros((nd, nf, 3), dtype=np.complex128)
    p_in = np.empty((nd, nf))
    p_thr = np.empty((nd, nf))
    p_fl = np.empty((nd, nf))
    p_dmp = np.empty((nd, nf, nm))
    p_tr = np.zeros((nd, nf, nm))
    ser = np.empty((3, 3), dtype=np.complex128)
    fs = np.empty((3, 1), dtype=np.complex128)
    hc = np.empty(3, dtype=np.complex128)
    qr = np.empty(6)
    qi = np.empty(6)
    step_fl = 1 if loads.shape[1] > 1 else 0
    step_dl = 1 if loads.shape[0] > 1 else 0
    step_dh = 1 if hull.shape[0] > 1 else 0
    has_extra = extra.shape[1] > 0
    compliant = hull.shape[1] > 0
    for d in range(nd):
        for f in range(nf):
            w = omega[f]
            for i in range(6):
                qr[i] = q[d, f, i].real
                qi[i] = q[d, f, i].imag
            # body: input power (w/2) Im(q^H F), thrust -(w/2) Im(q^H K_L q), fluid (w^2/2) q^H D_f q
            acc = 0.0
            for i in range(6):
                load = loads[d * step_dl, f * step_fl, i]
                acc += qr[i] * load.imag - qi[i] * load.real
            p_in[d, f] = 0.5 * w * acc
            p_thr[d, f] = -0.5 * w * _quad_parts(load_k[d], qr, qi)[1]
            fl = 0.5 * w * w * _quad_parts(fluid_d[d], qr, qi)[0]
            if has_extra:
                im = 0.0
                for i in range(6):
                    row = 0.0j
                    for j in range(6):
                        row += extra[d, f, i, j] * q[d, f, j]
                    im += (q[d, f, i].conjugate() * row).imag
                fl += 0.5 * w * im
            p_fl[d, f] = fl
            for mi in range(nm):
                for i in range(6):
                    dr = 0.0
                    di = 0.0
                    for j in range(6):
                        dr += maps[d, mi, i, j] * qr[j]
                        di += maps[d, mi, i, j] * qi[j]
                    d_out[d, f, mi, i] = complex(dr, di)
                for i in range(3):
                    kr = 0.0
                    ki = 0.0
                    cr = 0.0
                    ci = 0.0
                    for j in range(6):
                        a = force_k[d, mi, i, j]
                        b = force_c[d, mi, i, j]
                        kr += a * qr[j]
                        ki += a * qi[j]
                        cr += b * qr[j]
                        ci += b * qi[j]
                    hc[i] = complex(cr, ci)
                    fs[i, 0] = complex(kr - w * ci, ki + w * cr)
                acc = _quad_parts(damper[d, mi], qr, qi)[0]
                if compliant:
                    s = hull[d * step_dh, f, mi]
                    if np.isfinite(s.real) and np.isfinite(s.imag):
                        for i in range(3):
                            for j in range(3):
                                ser[i, j] = complex(mount_k[d, mi, i, j], w * mount_c[d, mi, i, j])
                            ser[i, i] += s
                        eliminate(ser, fs)  # fs becomes the hull-end displacement x
                        ptr = 0.0
                        for i in range(3):
                            x = fs[i, 0]
                            x_out[d, f, mi, i] = x
                            force = s * x
                            f_out[d, f, mi, i] = force
                            h_out[d, f, i] += force
                            ptr += (force.conjugate() * complex(0.0, w) * x).real
                            # e^H c e with e = B q - x: q^H B^T c B q - 2 Re(x^H Hc q) + x^H c_tt x
                            acc -= 2.0 * (x.conjugate() * hc[i]).real
                            for j in range(3):
                                acc += (x.conjugate() * mount_c[d, mi, i, j] * fs[j, 0]).real
                        p_tr[d, f, mi] = 0.5 * ptr
                        p_dmp[d, f, mi] = 0.5 * w * w * acc
                        continue
                for i in range(3):
                    f_out[d, f, mi, i] = fs[i, 0]
                    h_out[d, f, i] += fs[i, 0]
                p_dmp[d, f, mi] = 0.5 * w * w * acc
    return d_out, x_out, f_out, h_out, p_in, p_thr, p_fl, p_dmp, p_tr
