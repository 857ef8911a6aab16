"""Harmonic response of many designs at many frequencies: the one implementation behind every output.

For each design (leading axis ``nd``) the linearization ``M q'' + (D + G) q' + K q = F`` at a
thrust (THEORY 4) is driven harmonically, ``F(t) = Re(F e^{i omega t})``, and

    Z(omega) q = F,    Z = K + i omega (D + G) - omega^2 M + X(omega),

with ``X`` the frequency-dependent part (compressible fluid, a compliant foundation). Then, per
mount ``i`` with body-end map ``B_i = [[I, -S(rho_i)], [0, J_l^{-1}(phi0)]]`` at the arm
``rho_i = R0 r_i`` of the linearization (``R0 = I``, ``phi0 = 0`` classically):

* body-end deflection ``d_i = B_i q`` (translation of the attachment point, rotation);
* force of the mount on the hull ``F_i = P (k_i + i omega c_i)(d_i - P^T x_i)``, ``P = [I 0]``,
  with ``x_i`` the displacement of its hull end: 0 on a rigid hull, else ``S_i x_i = F_i`` for the
  hull point's dynamic stiffness ``S_i`` (:class:`~impstab.model.foundation.Foundation`), so that
  ``x_i = (S_i I + k*_tt)^{-1} P k* d_i``;
* total hull force ``F_hull = sum F_i`` (N, complex 3-vector, hull axes).

Time-averaged powers (W), each ``(omega / 2) Im(q^H Z_e q)`` for the element ``Z_e`` it names, so
that exactly ``input + thrust = fluid + sum_i (damper_i + transmitted_i)``:

* ``input = 1/2 Re(F^H i omega q)``;
* ``thrust = -(omega / 2) Im(q^H K_L q)``, the work of the load stiffness
  ``K_L = K - sum B_i^T k_i B_i`` (follower thrust and mount preload; non-zero only through its
  circulatory part);
* ``fluid = (omega^2 / 2) q^H D_f q`` (radiation damping);
* ``damper_i = (omega^2 / 2) e_i^H c_i e_i`` with the mount's own deflection ``e_i = d_i - P^T x_i``;
* ``transmitted_i = 1/2 Re(F_i^H i omega x_i)``, the power into the hull (0 on a rigid hull).

Everything is batched over designs and frequencies: a study evaluates a chunk of designs in one
call of :func:`harmonic_response` with stacked matrices.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..kinematics import inverse_left_jacobian, rotation_vector, skew
from .kernel import response_outputs, solve_harmonic

__all__ = ["HarmonicSolution", "harmonic_response", "attachment_maps"]

Array = NDArray[np.float64]
CArray = NDArray[np.complex128]


def attachment_maps(positions: Array, rotation: Array) -> Array:
    """Body-end maps ``B_i = [[I, -S(R0 r_i)], [0, J_l^{-1}(log R0)]]`` of every mount.

    Parameters
    ----------
    positions : (nd, nm, 3) array
        Mount attachment points, body frame (m).
    rotation : (nd, 3, 3) array
        Static rotation ``R0`` (body -> hull) of the linearization.

    Returns
    -------
    (nd, nm, 6, 6) array
    """
    positions = np.asarray(positions, dtype=float)
    rotation = np.asarray(rotation, dtype=float)
    nd, nm = positions.shape[:2]
    arms = np.einsum("dij,dmj->dmi", rotation, positions)
    b = np.zeros((nd, nm, 6, 6))
    b[..., :3, :3] = np.eye(3)
    b[..., :3, 3:] = -skew(arms)
    for d in range(nd):
        if np.array_equal(rotation[d], np.eye(3)):
            b[d, :, 3:, 3:] = np.eye(3)
        else:
            b[d, :, 3:, 3:] = inverse_left_jacobian(rotation_vector(rotation[d]))
    return b


@dataclass(frozen=True, eq=False)
class HarmonicSolution:
    """Arrays of :func:`harmonic_response` (axes: design, frequency, mount, component).

    Attributes
    ----------
    omega : (nf,) rad/s
    response : (nd, nf, 6) complex
        ``q`` (m, rad).
    deflection : (nd, nf, nm, 6) complex
        Body-end motion ``d_i = B_i q`` of each mount (m, rad).
    hull_displacement : (nd, nf, nm, 3) complex
        Hull-end displacement ``x_i`` (m); 0 on a rigid hull.
    mount_force : (nd, nf, nm, 3) complex
        Force of each mount on the hull (N).
    hull_force : (nd, nf, 3) complex
        Their sum (N).
    power_input, power_thrust, power_fluid : (nd, nf) W
    power_damper, power_transmitted : (nd, nf, nm) W
    pivot_ratio : (nd, nf)
        Smallest over largest pivot of the elimination (0: singular, an undamped resonance).
    """

    omega: Array
    response: CArray
    deflection: CArray
    hull_displacement: CArray
    mount_force: CArray
    hull_force: CArray
    power_input: Array
    power_thrust: Array
    power_fluid: Array
    power_damper: Array
    power_transmitted: Array
    pivot_ratio: Array


def _sandwich(b: Array, k: Array) -> Array:
    """``sum_i B_i^T k_i B_i`` over the mount axis (``(..., nm, 6, 6)`` -> ``(..., 6, 6)``)."""
    return (np.swapaxes(b, -1, -2) @ k @ b).sum(axis=-3)


def harmonic_response(
    mass: Array,
    damping: Array,
    gyroscopic: Array,
    stiffness: Array,
    rotation: Array,
    positions: Array,
    mount_stiffness: Array,
    mount_damping: Array,
    omega: Array,
    loads: CArray,
    fluid: CArray | None = None,
    foundation: CArray | None = None,
    fluid_damping: Array | None = None,
) -> HarmonicSolution:
    """Forced response, mount and hull forces and powers of ``nd`` designs at ``nf`` frequencies.

    Parameters
    ----------
    mass, damping, gyroscopic, stiffness : (nd, 6, 6) arrays
        ``M, D, G, K`` of the linearization of each design (:func:`impstab.linearize`, or the
        engine's stacked ``linearize_batch``).
    rotation : (nd, 3, 3) array
        Static rotation ``R0`` of each linearization (identity for the classical one).
    positions : (nd, nm, 3) array
        Mount attachment points, body frame (m).
    mount_stiffness, mount_damping : (nd, nm, 6, 6) arrays
        Each mount's 6 x 6 stiffness and damping at its body end (:class:`~impstab.model.Mount`).
    omega : (nf,) array
        Angular frequencies (rad/s), >= 0.
    loads : (nd or 1, nf or 1, 6) complex array
        Generalized load amplitudes at A, hull axes (N, N m); ``(6,)`` and ``(nf, 6)`` are
        shared by all designs.
    fluid : (nd, nf, 6, 6) complex array, optional
        Frequency-dependent fluid part of the dynamic stiffness
        (:func:`~impstab.response.fluid.fluid_dynamic_stiffness`).
    foundation : (nd or 1, nf, nm) complex array, optional
        Dynamic stiffness ``S = i omega Z`` of the hull at each attachment (N/m); None, or
        ``inf`` (per attachment), for a rigid hull. ``(nf, nm)`` is shared by all designs.
    fluid_damping : (nd, 6, 6) array, optional
        The frequency-independent fluid part of ``damping`` (for the power split); default
        ``damping - sum B_i^T c_i B_i`` with entries below 1e-12 of ``max |damping|`` (the
        rounding of that difference) set to 0.

    Returns
    -------
    HarmonicSolution
    """
    c = lambda a, t=float: np.ascontiguousarray(a, dtype=t)  # noqa: E731
    k = c(stiffness)
    nd = k.shape[0]
    w = c(np.asarray(omega, dtype=float).reshape(-1))
    nf = w.size
    b = attachment_maps(positions, rotation)
    km = c(mount_stiffness)
    cm = c(mount_damping)
    nm = km.shape[1]
    # broadcasts copied (np.array, C order), not viewed: a read-only view is another argument
    # type, for which numba would compile the kernels below again
    extra = (np.zeros((nd, 0, 6, 6), dtype=complex) if fluid is None
             else np.array(np.broadcast_to(fluid, (nd, nf, 6, 6)), complex, order="C"))
    hull = np.zeros((1, 0, nm), dtype=complex)
    if foundation is not None and not np.all(np.isinf(foundation)):
        hull = np.asarray(foundation, dtype=complex)
        hull = hull.reshape((1,) * (3 - hull.ndim) + hull.shape)        # (nf, nm) -> (1, nf, nm)
        hull = np.array(np.broadcast_to(hull, (hull.shape[0], nf, nm)), complex, order="C")
    loads = np.asarray(loads, dtype=complex)
    loads = loads.reshape((1,) * (3 - loads.ndim) + loads.shape)        # (6,) or (nf, 6) -> (1, ., 6)
    if fluid_damping is None:
        d_fluid = np.asarray(damping, float) - _sandwich(b, cm)
        scale = np.abs(np.asarray(damping, float)).max(axis=(-2, -1), keepdims=True)
        d_fluid = np.where(np.abs(d_fluid) <= 1e-12 * scale, 0.0, d_fluid)
    else:
        d_fluid = np.array(np.broadcast_to(np.asarray(fluid_damping, float), (nd, 6, 6)), order="C")  # as above
    q, pivot = solve_harmonic(
        c(mass), c(np.asarray(damping, float) + np.asarray(gyroscopic, float)), k, w, c(loads, complex), extra, b, km, cm, hull
    )
    d, x_hull, force, hull_force, p_in, p_thr, p_fl, p_dmp, p_tr = response_outputs(
        q, w, c(loads, complex), extra, b, c((km @ b)[..., :3, :]), c((cm @ b)[..., :3, :]),
        c(np.swapaxes(b, -1, -2) @ cm @ b), km, cm, hull, c(k - _sandwich(b, km)), c(d_fluid),
    )
    return HarmonicSolution(
        omega=w, response=q, deflection=d, hull_displacement=x_hull, mount_force=force,
        hull_force=hull_force, power_input=p_in, power_thrust=p_thr, power_fluid=p_fl,
        power_damper=p_dmp, power_transmitted=p_tr,
        pivot_ratio=pivot,
    )
