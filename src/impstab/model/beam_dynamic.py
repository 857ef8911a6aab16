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
eigenvalues of ``B`` (the evanescent bending wave), and inverting its block ``T12`` would lose about
``2 lambda_max L / ln 10`` digits: a long slender steel rod at tens of kHz loses them all. So where
``lambda_max L`` exceeds :data:`SEGMENT_GROWTH` the beam is cut into ``2^p`` equal segments, each
its own exact transfer matrix, joined by exact condensation of the inner nodes (still no
discretisation: the segments are exact). The digits one segment may lose are
:attr:`BeamDynamicStiffness.lost_digits` (below one); the forced response warns above
:data:`LOST_DIGITS_WARNING`. The condensation divides by the joined segments' clamped-clamped
dynamic stiffness, singular exactly at their resonances (a rounding effect within about 1e-10 of
such a frequency, in relative terms). Why not a finite-element mesh: its error grows with
frequency (the consistent-mass resonances converge from above, as ``h^2``); the transfer matrix is
exact up to that rounding.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.typing import ArrayLike, NDArray

from .beam import BeamMount, beam_frame

__all__ = ["BeamDynamicStiffness", "dynamic_stiffness", "clamped_dynamic_stiffness", "LOST_DIGITS_WARNING"]

Array = NDArray[np.float64]

#: digits lost to the evanescent waves above which the forced response warns
LOST_DIGITS_WARNING = 6.0


#: largest ``lambda_max h`` of one segment's transfer matrix ``expm(B h)`` (growth ``e^2``: under two
#: digits lost to its inversion)
SEGMENT_GROWTH = 2.0


def _two_port(t: Array) -> Array:
    """End stiffness ``[[f0], [fh]] = K [[d0], [dh]]`` of a segment from its transfer matrix."""
    m = t.shape[-1] // 2
    t11, t12, t21, t22 = t[:, :m, :m], t[:, :m, m:], t[:, m:, :m], t[:, m:, m:]
    inv12 = np.linalg.solve(t12, np.broadcast_to(np.eye(m), t12.shape))
    k = np.empty_like(t)
    k[:, :m, :m] = inv12 @ t11
    k[:, :m, m:] = -inv12
    k[:, m:, :m] = t21 - t22 @ inv12 @ t11
    k[:, m:, m:] = t22 @ inv12
    return k


def _doubled(k: Array) -> Array:
    """Two equal segments joined end to end, the middle node condensed exactly."""
    m = k.shape[-1] // 2
    a11, a12, a21, a22 = k[:, :m, :m], k[:, :m, m:], k[:, m:, :m], k[:, m:, m:]
    s = a22 + a11
    left = np.linalg.solve(s, a21)        # S^-1 A21
    right = np.linalg.solve(s, a12)       # S^-1 B12 (B = A)
    out = np.empty_like(k)
    out[:, :m, :m] = a11 - a12 @ left
    out[:, :m, m:] = -a12 @ right
    out[:, m:, :m] = -a21 @ left
    out[:, m:, m:] = a22 - a21 @ right
    return out


def _component_stiffness(b: Array, length: float) -> tuple[Array, Array]:
    """``(nf, 2m, 2m)`` end stiffness ``[[f0], [fL]] = K [[d0], [dL]]`` of one component with state
    matrices ``b (nf, 2m, 2m)``, and the digits one segment's transfer matrix may lose ``(nf,)``.

    Where the evanescent wave grows by more than ``e^SEGMENT_GROWTH`` over the length, the beam is
    cut into ``2^p`` equal segments (each its exact transfer matrix) joined by exact condensation of
    the inner nodes (``p`` doublings): exact still, without the inversion of ``expm(B L)`` that
    would lose ``2 lambda_max L / ln 10`` digits.
    """
    grow = np.linalg.eigvals(b).real.max(axis=-1)
    p = int(max(0, np.ceil(np.log2(max(float(grow.max()) * length / SEGMENT_GROWTH, 1.0)))))
    h = length / 2**p
    k = _two_port(sla.expm(b * h))
    for _ in range(p):
        k = _doubled(k)
    return k, 2.0 * grow * h / np.log(10.0)


def dynamic_stiffness_local(beam: BeamMount, omega: ArrayLike, rotary_inertia: bool = True) -> tuple[Array, Array]:
    """Exact 12 x 12 dynamic stiffness in the beam frame at angular frequencies ``omega`` (rad/s).

    Dofs ``(u1, u2, u3, theta1, theta2, theta3)`` of the hull end, then of the body end; forces
    and moments applied to the beam. ``rotary_inertia=False`` drops the sections' rotary inertia
    in bending (with a large shear coefficient: the Euler-Bernoulli beam). Returns
    ``(K (nf, 12, 12), lost_digits (nf,))``.
    """
    w = np.ascontiguousarray(np.asarray(omega, dtype=float).reshape(-1))
    return _local_cached(beam, w.tobytes(), bool(rotary_inertia))


@functools.lru_cache(maxsize=2)
def _local_cached(beam: BeamMount, omega_bytes: bytes, rotary_inertia: bool) -> tuple[Array, Array]:
    """:func:`dynamic_stiffness_local` of one beam at one frequency grid, kept for the mounts that
    share both (a ring of equal mounts, the response and its conditioning note); read-only."""
    w2 = np.frombuffer(omega_bytes, dtype=float) ** 2
    nf = w2.size
    E, G, rho, L = beam.youngs_modulus, beam.shear_modulus, beam.density, beam.length
    A, I, J, kap = beam.area, beam.second_moment, beam.polar_moment, beam.shear_coefficient
    out = np.zeros((nf, 12, 12))
    grow = np.zeros(nf)  # digits lost, the worst component
    # axial (dof 0) and torsion (dof 3): y = [d, s]
    # (no evanescent wave: expm(B L) in closed form, cos and sin of kL, k = omega sqrt(inertia / stiff))
    for dof, stiff, inertia in ((0, E * A, rho * A), (3, G * J, rho * J)):
        kl = np.sqrt(w2 * inertia / stiff) * L
        t = np.empty((nf, 2, 2))
        t[:, 0, 0] = t[:, 1, 1] = np.cos(kl)
        t[:, 0, 1] = L / stiff * np.sinc(kl / np.pi)                     # sin(kL) / (stiff k)
        t[:, 1, 0] = -inertia * w2 * L * np.sinc(kl / np.pi)             # -stiff k sin(kL)
        idx = [dof, dof + 6]
        out[np.ix_(range(nf), idx, idx)] = _two_port(t)
    # bending, y = [v, theta, V, M]
    b = np.zeros((nf, 4, 4))
    b[:, 0, 1] = 1.0
    b[:, 0, 2] = 1.0 / (kap * G * A)  # type: ignore[operator]
    b[:, 1, 3] = 1.0 / (E * I)
    b[:, 2, 0] = -rho * A * w2
    b[:, 3, 1] = -rho * I * w2 if rotary_inertia else 0.0
    b[:, 3, 2] = -1.0
    kb, g = _component_stiffness(b, L)
    grow = np.maximum(grow, g)
    # e1-e2 plane: (u2, +theta3); e1-e3 plane: (u3, -theta2)  (as model.beam.element_matrices)
    for disp, rot, sign in ((1, 5, 1.0), (2, 4, -1.0)):
        idx = [disp, rot, disp + 6, rot + 6]
        s = np.diag([1.0, sign, 1.0, sign])
        out[np.ix_(range(nf), idx, idx)] = s @ kb @ s
    out.flags.writeable = False
    grow.flags.writeable = False
    return out, grow


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
        Decimal digits one segment's transfer-matrix inversion may lose (``2 lambda_max h / ln 10``).
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
