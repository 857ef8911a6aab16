"""Internal dofs of massive beam mounts: the body's linear system grown beyond 6 dofs.

A beam mount with ``density > 0`` (:mod:`impstab.model.beam`) is cut into finite elements, hull end
clamped, its body-end node rigidly attached to the body at the mount: node displacement
``T6(r) q`` with ``T6(r) = [[I, -S(r)], [0, I]]`` and ``r`` the attachment arm (``R0 r_i`` at a
rotated equilibrium, as every mount of the linearization). The inner nodes' ``6 (n_e - 1)`` dofs
``z`` are appended to the body's ``q``:

    M_aug = [[M + sum T6^T m_tt T6,  T6^T m_ti], [m_ti^T T6, m_ii]]
    K_aug = [[K + sum T6^T (k_tt - K_tip) T6,  T6^T k_ti], [k_ti^T T6, k_ii]]

with ``D`` and ``G`` zero on the new dofs. ``K`` is the body's tangent stiffness in which the mount
already acts as its static tip stiffness ``K_tip = k_tt - k_ti k_ii^-1 k_ti^T`` (preload and
follower terms included). These inner dofs are carried in Craig-Bampton coordinates
(:class:`MountDofs`): static constraint modes plus the fixed-interface modes of each beam below
:data:`CUTOFF` times the body's highest frequency. Then ``K_aug = diag(K, Omega^2)`` and all
coupling is inertial; the static condensation of ``K_aug`` onto ``q`` is ``K`` exactly: the
statics, the preload stiffness and every massless limit are those of the equivalent 6 x 6 mount,
and the beam adds its distributed inertia and its internal resonances. The thrust does not act on
the beam itself (no geometric stiffness of the beam from its own axial load) and the beam's axis
stays the hull-frame mount axis at a rotated equilibrium (rotations of the body end enter through
the body-end node's dofs only).

The augmented system goes to the one stability engine as a second-order family of order
``6 + n_internal`` (:class:`~impstab.linear.linearize.ModelFamily` with ``mount_dofs``); the engine
reduces large undamped ones modally with its own error checks
(:mod:`impstab.linear.engine.large`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.typing import NDArray

from ..kinematics import rigid_map6
from ..model.beam import internal_matrices

__all__ = ["MountDofs", "mount_dofs"]

Array = NDArray[np.float64]


#: fixed-interface modes of a beam above this multiple of the highest natural frequency of the body
#: on its mounts (at rest, every mount as its static stiffness) are left to the static constraint
#: modes: their dynamic contribution to the body's eigenvalues is below about ``CUTOFF^-2 = 1e-6``
#: of their effective mass share, and the grown operator's spread stays near ``CUTOFF^2``
CUTOFF = 1.0e3


@dataclass(frozen=True, eq=False)
class MountDofs:
    """The internal dofs of a model's massive beam mounts, in Craig-Bampton form.

    For each beam (inner nodes ``i``, body-end node ``t``) the inner displacements are
    ``z = Psi u_t + Phi eta``: the static constraint modes ``Psi = -k_ii^-1 k_it`` and the
    fixed-interface modes ``Phi`` (``k_ii phi = omega_j^2 m_ii phi``, mass-normalised) below
    :data:`CUTOFF` times the body's highest frequency. In these coordinates the beam's stiffness is
    ``diag(K_tip, Omega^2)`` exactly (no stiffness coupling) and its mass
    ``[[m_tt*, m_te], [m_te^T, I]]`` with ``m_tt* = [I; Psi]^T m [I; Psi]``,
    ``m_te = [I; Psi]^T m [0; Phi]``. With every mode kept this is the finite-element model in other
    coordinates; dropping the fast modes keeps the statics exact.

    Attributes
    ----------
    positions : (nb, 3) array
        Attachment points (body frame) of the massive beam mounts.
    m_tt : (nb, 6, 6) array
        Body-end mass of each beam with its constraint modes (hull frame).
    m_te : tuple of (6, n_j) arrays
        Mass coupling of the body end with each beam's kept modes.
    omega2 : (n,) array
        Squared fixed-interface frequencies of the kept modes (rad^2/s^2), beam after beam.
    offsets : tuple of int
        First internal dof of each beam (from 0).
    dropped : int
        Fixed-interface modes left to the constraint modes (above the cutoff).
    cutoff : float
        The frequency (rad/s) above which modes were dropped.
    """

    positions: Array
    m_tt: Array
    m_te: tuple[Array, ...]
    omega2: Array
    offsets: tuple[int, ...]
    dropped: int = 0
    cutoff: float = np.inf

    @property
    def n(self) -> int:
        """Number of internal dofs (kept modes)."""
        return int(self.omega2.shape[0])

    def augment(self, m: Array, d: Array, g: Array, k: Array, rotations: Array | None = None):
        """Stacks ``(N, 6, 6)`` of the body system grown to ``(N, 6 + n, 6 + n)``.

        ``rotations (N, 3, 3)``: static rotations ``R0`` of the body (arms ``R0 r``); None: at rest.
        NaN entries (no equilibrium) stay NaN.
        """
        count = m.shape[0]
        size = 6 + self.n
        out = [np.zeros((count, size, size)) for _ in range(4)]
        for o, a in zip(out, (m, d, g, k)):
            o[:, :6, :6] = a
        ma, _, _, ka = out
        idx = np.arange(6, size)
        ka[:, idx, idx] = self.omega2
        ma[:, idx, idx] = 1.0
        for j, pos in enumerate(self.positions):
            arms = np.broadcast_to(pos, (count, 3)) if rotations is None else rotations @ pos
            t = rigid_map6(arms)                             # (N, 6, 6)
            tt = np.swapaxes(t, -1, -2)
            ma[:, :6, :6] += tt @ self.m_tt[j] @ t
            sl = slice(6 + self.offsets[j], 6 + self.offsets[j] + self.m_te[j].shape[1])
            mb = tt @ self.m_te[j]
            ma[:, :6, sl], ma[:, sl, :6] = mb, np.swapaxes(mb, -1, -2)
        bad = ~(np.isfinite(m).all(axis=(1, 2)) & np.isfinite(k).all(axis=(1, 2)))
        for o in out:
            o[bad] = np.nan
        return tuple(out)


def _body_frequency(model, beams_mass: Array, positions: Array) -> float:
    """Highest natural frequency (rad/s) of the body on its mounts at rest, the beams' constraint
    mass included (every mount as its static stiffness)."""
    from ..model.mounts import elastic_stiffness

    m = model.mass_matrix.copy()
    if len(positions):
        t = rigid_map6(positions)
        m += (np.swapaxes(t, -1, -2) @ beams_mass @ t).sum(axis=0)
    return float(np.sqrt(sla.eigvalsh(elastic_stiffness(model.mounts), m).max()))


def mount_dofs(model, elements: int | None = None, cutoff: float = CUTOFF) -> MountDofs | None:
    """The internal dofs of ``model``'s massive beam mounts (None when it has none).

    ``elements`` overrides each beam's element count (:data:`~impstab.model.beam.DEFAULT_ELEMENTS`);
    ``cutoff``: keep the fixed-interface modes below ``cutoff`` times the body's highest frequency
    (``numpy.inf``: all of them, the finite-element model itself).
    """
    beams = [mt for mt in model.mounts if mt.is_massive_beam]
    if not beams:
        return None
    parts = []
    for mt in beams:
        ktt, kti, kii, mtt, mti, mii = internal_matrices(mt.beam, mt.axis, elements)
        if kii.shape[0] == 0:
            parts.append((mtt, np.zeros((6, 0)), np.zeros((0, 6)), np.zeros(0)))
            continue
        psi = -np.linalg.solve(kii, kti.T)                    # (n_i, 6) constraint modes
        w2, phi = sla.eigh(kii, mii)                          # mass-normalised fixed-interface modes
        m_star = mtt + mti @ psi + psi.T @ mti.T + psi.T @ mii @ psi
        m_te = (mti + psi.T @ mii) @ phi                      # (6, n_i)
        parts.append((0.5 * (m_star + m_star.T), m_te, phi, w2))
    positions = np.array([mt.position for mt in beams])
    w_body = _body_frequency(model, np.array([p[0] for p in parts]), positions)
    limit = cutoff * w_body
    m_te, omega2, offsets = [], [], []
    start = dropped = 0
    for _, mte, _, w2 in parts:
        keep = np.sqrt(np.maximum(w2, 0.0)) <= limit
        dropped += int((~keep).sum())
        m_te.append(mte[:, keep])
        omega2.append(w2[keep])
        offsets.append(start)
        start += int(keep.sum())
    return MountDofs(positions=positions, m_tt=np.array([p[0] for p in parts]), m_te=tuple(m_te),
                     omega2=np.concatenate(omega2), offsets=tuple(offsets), dropped=dropped, cutoff=limit)

