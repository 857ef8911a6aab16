"""Nonlinear mount law: cubic axial and shear springs and a smoothed snubber (compiled).

The law acts on the translation deflection ``d`` of a mount's body end (hull frame, THEORY 7:
``d = X_A + R r - r``), with the mount's unit axis ``a`` (hull frame), ``d_a = a . d`` and the
shear part ``d_s = d - d_a a``. It adds to the mount's linear springs the potential

    V_nl(d) = k3_axial d_a^4 / 4 + k3_shear |d_s|^4 / 4 + k_snub W(|d| - c)

so that the total force of an axial-shear mount on the body is

    f = -(k_axial d_a + k3_axial d_a^3) a - (k_shear + k3_shear |d_s|^2) d_s
        - k_snub ramp(|d| - c) d / |d|,

with ``ramp = W'``. The snubber (motion limiter, clearance ``c > 0``) engages when ``|d|``
exceeds the clearance; its ramp is smoothed over ``w = 0.05 c`` by the quartic whose slope is
the cubic smoothstep, ``t = x / w``:

    ramp(x) = 0                       x <= 0
    ramp(x) = w (t^3 - t^4 / 2)       0 <= x <= w     (ramp' = 3 t^2 - 2 t^3, ramp'' = 6 t (1 - t) / w)
    ramp(x) = x - w / 2               x >= w

so ramp, ramp' and ramp'' are continuous (C2) and the snubber force beyond ``1.05 c`` is
``k_snub (|d| - 1.025 c)``. Its potential is ``W(x) = w^2 (t^4 / 4 - t^5 / 10)`` on the
smoothing interval and ``x^2 / 2 - w x / 2 + 0.15 w^2`` beyond it.

A law is packed per mount as a row of ``N_LAW`` numbers (``LAW_*`` offsets); a row of zeros is
a linear mount. The gradient is written with analytic operations only (square root through
:mod:`impstab.kinematics.scalar`, branches on real parts), so the compiled function also runs on
complex deflections (exact complex-step derivatives). The Hessian (the tangent stiffness of the
law) is real-only.
"""

from __future__ import annotations

from .._jit import njit

from ..kinematics.scalar import sqrt

__all__ = ["LAW_AXIS", "LAW_K3_AXIAL", "LAW_K3_SHEAR", "LAW_CLEARANCE", "LAW_SNUBBER", "N_LAW",
           "SNUBBER_SMOOTHING", "law_gradient", "law_hessian"]

#: offsets in a packed law row: axis (3, unit, hull frame), k3_axial, k3_shear (N/m^3),
#: snubber clearance (m), snubber stiffness (N/m)
LAW_AXIS, LAW_K3_AXIAL, LAW_K3_SHEAR, LAW_CLEARANCE, LAW_SNUBBER = 0, 3, 4, 5, 6
N_LAW = 7
#: width of the snubber's smoothing interval, as a fraction of the clearance
SNUBBER_SMOOTHING = 0.05


@njit(cache=True, inline="always", error_model="numpy")
def _ramp(x, w):
    """``(ramp(x), ramp'(x))`` of the snubber for ``x > 0`` (smoothing width ``w``)."""
    t = x / w
    if t.real < 1.0:
        return w * t * t * t * (1.0 - 0.5 * t), t * t * (3.0 - 2.0 * t)
    return x - 0.5 * w, 1.0 + 0.0 * t


@njit(cache=True, inline="always", error_model="numpy")
def law_gradient(laws, i, d0, d1, d2):
    """Gradient ``dV_nl/dd`` (N, hull frame) of mount ``i``'s nonlinear potential at ``d`` (m).

    The nonlinear part of the mount force on the body is minus this. ``laws`` is the
    ``(n_mounts, N_LAW)`` table; ``d`` may be complex (analytic continuation).
    """
    a0, a1, a2 = laws[i, LAW_AXIS], laws[i, LAW_AXIS + 1], laws[i, LAW_AXIS + 2]
    k3a, k3s = laws[i, LAW_K3_AXIAL], laws[i, LAW_K3_SHEAR]
    clear, ksn = laws[i, LAW_CLEARANCE], laws[i, LAW_SNUBBER]
    da = a0 * d0 + a1 * d1 + a2 * d2
    s0, s1, s2 = d0 - da * a0, d1 - da * a1, d2 - da * a2
    ca = k3a * da * da * da
    cs = k3s * (s0 * s0 + s1 * s1 + s2 * s2)
    g0, g1, g2 = ca * a0 + cs * s0, ca * a1 + cs * s1, ca * a2 + cs * s2
    if clear > 0.0:
        r2 = d0 * d0 + d1 * d1 + d2 * d2
        if r2.real > clear * clear:
            r = sqrt(r2)
            ramp, _ = _ramp(r - clear, SNUBBER_SMOOTHING * clear)
            q = ksn * ramp / r
            g0, g1, g2 = g0 + q * d0, g1 + q * d1, g2 + q * d2
    return g0, g1, g2


@njit(cache=True, error_model="numpy")
def law_hessian(laws, i, d0, d1, d2, hess):
    """Hessian ``d^2 V_nl / dd^2`` (N/m) of mount ``i``'s law at the real deflection ``d`` into
    the 3 x 3 ``hess`` (overwritten): the law's part of the mount's tangent stiffness."""
    a = (laws[i, LAW_AXIS], laws[i, LAW_AXIS + 1], laws[i, LAW_AXIS + 2])
    d = (d0, d1, d2)
    k3a, k3s = laws[i, LAW_K3_AXIAL], laws[i, LAW_K3_SHEAR]
    clear, ksn = laws[i, LAW_CLEARANCE], laws[i, LAW_SNUBBER]
    da = a[0] * d0 + a[1] * d1 + a[2] * d2
    s = (d0 - da * a[0], d1 - da * a[1], d2 - da * a[2])
    s2 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2]
    # 3 k3a d_a^2 a a^T + k3s (|d_s|^2 P + 2 d_s d_s^T), P = I - a a^T
    for p in range(3):
        for q in range(3):
            proj = (1.0 if p == q else 0.0) - a[p] * a[q]
            hess[p, q] = 3.0 * k3a * da * da * a[p] * a[q] + k3s * (s2 * proj + 2.0 * s[p] * s[q])
    if clear > 0.0:
        r2 = d0 * d0 + d1 * d1 + d2 * d2
        if r2 > clear * clear:
            r = sqrt(r2)
            ramp, slope = _ramp(r - clear, SNUBBER_SMOOTHING * clear)
            # k_snub [ramp' n n^T + ramp / r (I - n n^T)], n = d / r
            for p in range(3):
                for q in range(3):
                    hess[p, q] += ksn * ((slope - ramp / r) * d[p] * d[q] / r2 + (ramp / r if p == q else 0.0))
