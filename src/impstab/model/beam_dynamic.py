"""Exact dynamic stiffness of a uniform Timoshenko beam mount at harmonic frequencies.

A beam mount (:class:`~impstab.model.beam.BeamMount`) with mass density ``rho`` carries waves: at
angular frequency ``omega`` each component of the continuous beam obeys a first-order ODE along
its axis ``x`` (beam frame ``(e1 = axis, e2, e3)``, ``x = 0`` the hull end, ``x = L`` the body end),
``y' = B(omega) y`` with the state ``y = [d; s]`` of end displacements ``d`` and the matching
internal resultants ``s`` (the force and moment on the positive face):

* axial ``y = [u, N]``: ``u' = N / (E A)``, ``N' = -rho A omega^2 u``;
* torsion ``y = [phi, T]``: ``phi' = T / (G J)``, ``T' = -rho J omega^2 phi``;
* bending in a plane, ``y = [v, theta, V, M]`` (deflection, section rotation, shear force,
  bending moment): ``v' = theta + V / (kappa G A)``, ``theta' = M / (E I)``,
  ``V' = -rho A omega^2 v``, ``M' = -V - rho I omega^2 theta`` (shear deformation and rotary
  inertia: the full Timoshenko beam).

Its transfer matrix over the length is ``T = expm(B L)`` (:func:`scipy.linalg.expm`, batched over
frequencies), ``y(L) = T y(0)``. With ``T`` split into ``d``/``s`` blocks, the end forces applied to
the beam (``f0 = -s(0)``, ``fL = s(L)``) are exactly

    [f0; fL] = [[T12^-1 T11, -T12^-1], [T21 - T22 T12^-1 T11, T22 T12^-1]] [d0; dL],

the exact 12 x 12 dynamic stiffness (:func:`dynamic_stiffness`): no discretisation, every wave
effect and internal resonance of the isolator. With the hull end clamped the body-end block
``T22 T12^-1`` is the mount's 6 x 6 ``K_d(omega)`` (``K_tip`` at ``omega = 0``) and the force of
the beam on the hull is ``T12^-1 d_L`` (the off-diagonal block with its sign turned): with mass it
differs from the body-end force, which is why the transmitted force is taken there.

The beam material is undamped: the model file has no loss factor for beam mounts (DESIGN), so
``K_d`` is real; viscous dampers given with the mount act in parallel at its ends.

Conditioning. ``expm(B L)`` grows like ``exp(lambda_max L)`` with the largest real part of the
eigenvalues of ``B`` (the evanescent bending wave), and forming ``T12^-1`` loses about
``2 lambda_max L / ln 10`` digits (:attr:`BeamDynamicStiffness.lost_digits`, reported by the
forced response above :data:`LOST_DIGITS_WARNING`). Soft elastomer mounts stay far below it in
the audible range; a long slender steel rod at tens of kHz does not. Why not a finite-element mesh:
its error grows with frequency (the consistent-mass resonances converge from above, as ``h^2``);
the transfer matrix is exact up to that stated rounding.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.typing import ArrayLike, NDArray

from .beam import BeamMount, beam_frame

__all__ = ["BeamDynamicStiffness", "dynamic_stiffness", "clamped_dynamic_stiffness", "LOST_DIGITS_WARNING"]

Array = NDArray[np.float64]

#: digits lost to the evanescent waves above which the forced response warns
LOST_DIGITS_WARNING = 6.0


def _component_stiffness(b: Array, length: float) -> tuple[Array, Array]:
    """``(nf, 2m, 2m)`` end stiffness ``[[f0], [fL]] = K [[d0], [dL]]`` of one component with state
    matrices ``b (nf, 2m, 2m)``, and the largest real part of their eigenvalues ``(nf,)``."""
    m = b.shape[-1] // 2
    t = sla.expm(b * length)
    t11, t12, t21, t22 = t[:, :m, :m], t[:, :m, m:], t[:, m:, :m], t[:, m:, m:]
    eye = np.broadcast_to(np.eye(m), t12.shape)
    inv12 = np.linalg.solve(t12, eye)
    k = np.empty_like(t)
    k[:, :m, :m] = inv12 @ t11
    k[:, :m, m:] = -inv12
    k[:, m:, :m] = t21 - t22 @ inv12 @ t11
    k[:, m:, m:] = t22 @ inv12
    grow = np.linalg.eigvals(b).real.max(axis=-1)
    return k, grow


def dynamic_stiffness_local(beam: BeamMount, omega: ArrayLike) -> tuple[Array, Array]:
    """Exact 12 x 12 dynamic stiffness in the beam frame at angular frequencies ``omega`` (rad/s).

    Dofs ``(u1, u2, u3, theta1, theta2, theta3)`` of the hull end, then of the body end; forces
    and moments applied to the beam. Returns ``(K (nf, 12, 12), lost_digits (nf,))``.
    """
    w2 = np.asarray(omega, dtype=float).reshape(-1) ** 2
    nf = w2.size
    E, G, rho, L = beam.youngs_modulus, beam.shear_modulus, beam.density, beam.length
    A, I, J, kap = beam.area, beam.second_moment, beam.polar_moment, beam.shear_coefficient
    out = np.zeros((nf, 12, 12))
    grow = np.zeros(nf)
    # axial (dof 0) and torsion (dof 3): y = [d, s]
    for dof, stiff, inertia in ((0, E * A, rho * A), (3, G * J, rho * J)):
        b = np.zeros((nf, 2, 2))
        b[:, 0, 1] = 1.0 / stiff
        b[:, 1, 0] = -inertia * w2
        k, g = _component_stiffness(b, L)
        idx = [dof, dof + 6]
        out[np.ix_(range(nf), idx, idx)] = k
        grow = np.maximum(grow, g)
    # bending, y = [v, theta, V, M]
    b = np.zeros((nf, 4, 4))
    b[:, 0, 1] = 1.0
    b[:, 0, 2] = 1.0 / (kap * G * A)  # type: ignore[operator]
    b[:, 1, 3] = 1.0 / (E * I)
    b[:, 2, 0] = -rho * A * w2
    b[:, 3, 1] = -rho * I * w2
    b[:, 3, 2] = -1.0
    kb, g = _component_stiffness(b, L)
    grow = np.maximum(grow, g)
    # e1-e2 plane: (u2, +theta3); e1-e3 plane: (u3, -theta2)  (as model.beam.element_matrices)
    for disp, rot, sign in ((1, 5, 1.0), (2, 4, -1.0)):
        idx = [disp, rot, disp + 6, rot + 6]
        s = np.diag([1.0, sign, 1.0, sign])
        out[np.ix_(range(nf), idx, idx)] = s @ kb @ s
    return out, 2.0 * grow * L / np.log(10.0)


@dataclass(frozen=True, eq=False)
class BeamDynamicStiffness:
    """The exact dynamic stiffness of a beam mount, hull frame (SI units, forces on the beam).

    Attributes
    ----------
    omega : (nf,) array
        Angular frequencies (rad/s).
    full : (nf, 12, 12) array
        Both ends free: dofs of the hull end, then of the body end (translations, rotations).
    lost_digits : (nf,) array
        Decimal digits the transfer-matrix inversion may lose (``2 lambda_max L / ln 10``).
    """

    omega: Array
    full: Array
    lost_digits: Array

    @property
    def body(self) -> Array:
        """``K_d(omega) (nf, 6, 6)``: body-end force per body-end motion, hull end clamped."""
        return self.full[:, 6:, 6:]

    @property
    def transmitted(self) -> Array:
        """``(nf, 6, 6)``: force and moment of the beam ON the hull (at its hull end) per body-end
        motion, hull end clamped (``-`` the off-diagonal block)."""
        return -self.full[:, :6, 6:]


def dynamic_stiffness(beam: BeamMount, axis: ArrayLike, omega: ArrayLike) -> BeamDynamicStiffness:
    """Exact dynamic stiffness of ``beam`` along ``axis`` (hull frame) at ``omega`` (rad/s)."""
    w = np.asarray(omega, dtype=float).reshape(-1)
    local, lost = dynamic_stiffness_local(beam, w)
    r12 = np.kron(np.eye(4), beam_frame(np.asarray(axis, dtype=float)))
    full = r12 @ local @ r12.T
    return BeamDynamicStiffness(omega=w, full=full, lost_digits=lost)


def clamped_dynamic_stiffness(beam: BeamMount, axis: ArrayLike, omega: ArrayLike) -> Array:
    """``K_d(omega) (nf, 6, 6)``: body-end dynamic stiffness of the beam clamped at the hull end."""
    return dynamic_stiffness(beam, axis, omega).body
