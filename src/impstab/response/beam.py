"""Forced response with massive beam mounts: the exact dynamic stiffness at each frequency.

A beam mount with mass density is, at angular frequency ``omega``, the exact 12 x 12 dynamic
stiffness of the continuous Timoshenko beam (:mod:`impstab.model.beam_dynamic`: wave effects and
the isolator's internal resonances, no mesh). Its hull end translates with the hull point ``x``
(0 on a rigid hull; rotations held, as for every mount), its body end moves with ``d = B q``. With
the viscous dampers ``c`` given with the mount in parallel (as for every mount: ``e = d - P^T x``)
the mount's blocks on those dofs are

    Z_bb = K_bb + i omega c,  Z_bh = K_bh P^T - i omega c P^T,
    Z_hb = P K_hb - i omega P c,  Z_hh = P K_hh P^T + i omega P c P^T,

the hull point obeys ``S x = -(Z_hh x + Z_hb d)`` (``S``: its dynamic stiffness), so
``x = -(S I + Z_hh)^-1 Z_hb d`` and the body sees ``K_eff = Z_bb - Z_bh (S I + Z_hh)^-1 Z_hb``
(rigid hull: ``K_eff = Z_bb``). The force of the mount ON the hull is ``F = -(Z_hh x + Z_hb d)``,
taken at the hull end: with the beam's mass it is not the body-end force. For a massless mount
these reduce to the 6 x 6 forms of :mod:`impstab.response.core`.

:func:`beam_harmonic_response` hands the one harmonic solver
(:func:`~impstab.response.core.harmonic_response`) the body with those mounts removed from the
stiffness and damping and ``sum B^T K_eff B`` added to the frequency-dependent part of the dynamic
stiffness, then evaluates the beam mounts' hull forces, hull-end motion and powers from the response
(the power balance ``input + thrust = fluid + sum(damper + transmitted)`` holds: the beam material
is undamped, see the module above).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..model.beam import BeamMount
from ..model.beam_dynamic import dynamic_stiffness
from .core import HarmonicSolution, attachment_maps, harmonic_response

__all__ = ["beam_harmonic_response", "beam_lost_digits", "BeamEntry"]

Array = NDArray[np.float64]
#: (mount index, beam, axis in the hull frame)
BeamEntry = tuple[int, BeamMount, Array]


def _sandwich(b: Array, k: Array) -> Array:
    return np.swapaxes(b, -1, -2) @ k @ b


def beam_harmonic_response(beams: Sequence[BeamEntry], mass, damping, gyroscopic, stiffness, rotation, positions,
                           mount_stiffness, mount_damping, omega, loads, fluid=None, foundation=None,
                           fluid_damping=None) -> HarmonicSolution:
    """:func:`~impstab.response.core.harmonic_response` of one design (``nd = 1``) whose mounts
    ``beams`` (index, beam, axis) are their exact dynamic stiffness at each frequency (same
    arguments); :func:`beam_lost_digits` states the rounding of the beams' transfer matrices."""
    w = np.asarray(omega, dtype=float).reshape(-1)
    nf = w.size
    b = attachment_maps(positions, rotation)[0]                        # (nm, 6, 6)
    km = np.array(mount_stiffness, dtype=float)
    cm = np.array(mount_damping, dtype=float)
    k_body = np.array(stiffness, dtype=float)
    d_body = np.array(damping, dtype=float)
    nm = km.shape[1]
    hull = None
    if foundation is not None and not np.all(np.isinf(foundation)):
        hull = np.asarray(foundation, dtype=complex)
        hull = np.broadcast_to(hull.reshape((1,) * (3 - hull.ndim) + hull.shape), (1, nf, nm)).copy()
    extra = np.zeros((1, nf, 6, 6), dtype=complex)
    if fluid is not None:
        extra += np.broadcast_to(np.asarray(fluid, dtype=complex), (1, nf, 6, 6))
    parts = []
    for i, beam, axis in beams:
        bi = b[i]
        c6 = cm[0, i].copy()
        k_body[0] -= _sandwich(bi, km[0, i])
        d_body[0] -= _sandwich(bi, c6)
        km[0, i] = 0.0
        cm[0, i] = 0.0
        dyn = dynamic_stiffness(beam, axis, w).full                     # (nf, 12, 12) real
        iwc = 1j * w[:, None, None] * c6
        z_bb = dyn[:, 6:, 6:] + iwc
        z_bh = dyn[:, 6:, :3] - iwc[:, :, :3]
        z_hb = dyn[:, :3, 6:] - iwc[:, :3, :]
        z_hh = dyn[:, :3, :3] + iwc[:, :3, :3]
        s = None if hull is None else hull[0, :, i]
        if s is not None and np.all(np.isfinite(s)):
            # x = X d with X = -(S I + Z_hh)^-1 Z_hb
            x_map = -np.linalg.solve(z_hh + s[:, None, None] * np.eye(3), z_hb)
            k_eff = z_bb + z_bh @ x_map
            hull[0, :, i] = np.inf
        else:
            x_map = np.zeros((nf, 3, 6), dtype=complex)
            k_eff = z_bb
        extra[0] += _sandwich(bi, k_eff)
        parts.append((i, bi, c6, k_eff, x_map, -(z_hh @ x_map + z_hb)))
    sol = harmonic_response(mass, d_body, gyroscopic, k_body, rotation, positions, km, cm, w, loads,
                            fluid=extra, foundation=hull, fluid_damping=fluid_damping)
    q = sol.response[0]                                                 # (nf, 6)
    x_out = sol.hull_displacement.copy()
    f_out = sol.mount_force.copy()
    p_dmp = sol.power_damper.copy()
    p_tr = sol.power_transmitted.copy()
    p_fl = sol.power_fluid.copy()
    for i, bi, c6, k_eff, x_map, f_map in parts:
        d = sol.deflection[0, :, i]                                     # (nf, 6) = B q
        x = np.einsum("fij,fj->fi", x_map, d)
        force = np.einsum("fij,fj->fi", f_map, d)
        e = d.copy()
        e[:, :3] -= x
        x_out[0, :, i] = x
        f_out[0, :, i] = force
        p_dmp[0, :, i] = 0.5 * w * w * np.einsum("fi,ij,fj->f", e.conj(), c6, e).real
        p_tr[0, :, i] = 0.5 * (force.conj() * (1j * w[:, None]) * x).sum(axis=1).real
        # the solver booked this mount's part of the frequency-dependent stiffness as fluid power
        zq = np.einsum("fij,fj->fi", bi.T @ k_eff @ bi, q)
        p_fl[0] -= 0.5 * w * (q.conj() * zq).sum(axis=1).imag
    return HarmonicSolution(
        omega=w, response=sol.response, deflection=sol.deflection, hull_displacement=x_out, mount_force=f_out,
        hull_force=f_out.sum(axis=2), power_input=sol.power_input, power_thrust=sol.power_thrust,
        power_fluid=p_fl, power_damper=p_dmp, power_transmitted=p_tr, pivot_ratio=sol.pivot_ratio,
    )


def beam_lost_digits(beams: Sequence[BeamEntry], omega) -> float:
    """Most decimal digits the beams' transfer matrices may lose over ``omega`` (rad/s)."""
    w = np.asarray(omega, dtype=float).reshape(-1)
    return max((float(dynamic_stiffness(beam, axis, w).lost_digits.max()) for _, beam, axis in beams), default=0.0)
