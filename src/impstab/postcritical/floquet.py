"""Floquet multipliers from the collocation Jacobian, by condensation and a stable product reduction.

The linearized collocation equations of one interval relate its ``m + 1`` nodal values. Eliminating
the ``m - 1`` interior nodes by an orthogonal (QR) condensation leaves ``n`` equations

    A_i v_i + B_i v_(i+1) = 0,          i = 0 .. N - 1,

between the values at the mesh points, which are the collocation approximation of the variational
flow over that interval (superconvergent, ``O(h^2m)``). The monodromy matrix is the product
``(-B_(N-1)^-1 A_(N-1)) ... (-B_0^-1 A_0)``; forming it loses the small multipliers of strongly
damped modes to rounding. Instead (Fairgrieve & Jepson 1991, AUTO's FLOWKM) ``v_1 .. v_(N-1)`` are
eliminated by QR factorizations of ``[B_i; A_(i+1)]`` (pairwise, in a binary tree), which keeps a relation
``P v_0 + Q v_N = 0`` without any inverse, and the multipliers ``mu`` (``v_N = mu v_0``) are the
eigenvalues of the pencil ``(P, -Q)`` by the QZ algorithm. Small and large multipliers keep their
relative accuracy; the trivial multiplier (the phase direction ``x'(0)``) is found by its eigenvector.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from numpy.typing import NDArray

from ..errors import NumericalError

__all__ = ["FloquetMultipliers", "condense", "multipliers", "chain_multipliers", "reduce_product"]

Array = NDArray[np.float64]
CArray = NDArray[np.complex128]

#: the trivial multiplier is sought among those within this distance of 1
TRIVIAL_WINDOW = 0.2


@dataclass(frozen=True, eq=False)
class FloquetMultipliers:
    """Multipliers of one cycle.

    Attributes
    ----------
    values : (n,) complex array
        All multipliers, the trivial one included, sorted by decreasing modulus.
    trivial : int
        Index of the trivial multiplier (eigenvector along ``x'(0)``).
    trivial_error : float
        ``|mu_trivial - 1|``: an accuracy check of the whole computation.
    alignment : float
        ``|cos|`` of the angle between the trivial eigenvector and ``x'(0)`` (1 ideally).
    """

    values: CArray
    trivial: int
    trivial_error: float
    alignment: float

    @property
    def nontrivial(self) -> CArray:
        return np.delete(self.values, self.trivial)

    @property
    def largest(self) -> float:
        """Largest modulus among the nontrivial multipliers."""
        nt = self.nontrivial
        return float(np.max(np.abs(nt))) if nt.size else 0.0


def condense(blocks: Array) -> tuple[Array, Array]:
    """Per-interval relations ``A_i v_i + B_i v_(i+1) = 0`` from collocation blocks.

    ``blocks[i, k, j]`` (shape ``(N, m, m + 1, n, n)``) is the derivative of collocation equation
    ``k`` of interval ``i`` with respect to its local node ``j``.
    """
    n_int, m, _, n, _ = blocks.shape
    g = blocks.transpose(0, 1, 3, 2, 4).reshape(n_int, m * n, (m + 1) * n)
    interior = g[:, :, n: m * n]
    q, _ = np.linalg.qr(interior, mode="complete")
    qt = np.swapaxes(q, 1, 2)[:, (m - 1) * n:, :]                  # (N, n, m n): left null rows
    return qt @ g[:, :, :n], qt @ g[:, :, m * n:]


def reduce_product(a: Array, b: Array) -> tuple[Array, Array]:
    """``P v_0 + Q v_N = 0`` from the chain ``A_i v_i + B_i v_(i+1) = 0`` by QR eliminations.

    Neighbouring relations ``P_k v_a + Q_k v_b = 0`` and ``P_(k+1) v_b + Q_(k+1) v_c = 0`` are merged
    by the orthogonal factor of ``[Q_k; P_(k+1)]``, whose last ``n`` rows annihilate ``v_b``; the
    merges of one level are batched (a binary tree of ``log2 N`` levels).
    """
    n = a.shape[1]
    p_mat, q_mat = a, b
    while p_mat.shape[0] > 1:
        k = p_mat.shape[0] // 2 * 2
        stack = np.concatenate([q_mat[0:k:2], p_mat[1:k:2]], axis=1)       # (k/2, 2n, n)
        qq, _ = np.linalg.qr(stack, mode="complete")
        low = np.swapaxes(qq[:, :, n:], 1, 2)                               # (k/2, n, 2n)
        new_p = low[:, :, :n] @ p_mat[0:k:2]
        new_q = low[:, :, n:] @ q_mat[1:k:2]
        if k < p_mat.shape[0]:
            new_p = np.concatenate([new_p, p_mat[k:]], axis=0)
            new_q = np.concatenate([new_q, q_mat[k:]], axis=0)
        p_mat, q_mat = new_p, new_q
    return p_mat[0], q_mat[0]


def multipliers(blocks: Array, phase_direction: Array, scale: Array) -> FloquetMultipliers:
    """Floquet multipliers of the cycle whose collocation Jacobian blocks are ``blocks``.

    Parameters
    ----------
    blocks : (N, m, m + 1, n, n) array
    phase_direction : (n,) array
        ``x'(0)``, the eigenvector of the trivial multiplier.
    scale : (n,) array
        State scale for the alignment test.
    """
    a, b = condense(blocks)
    return chain_multipliers(a, b, phase_direction, scale)


def chain_multipliers(a: Array, b: Array, phase_direction: Array, scale: Array) -> FloquetMultipliers:
    """Floquet multipliers from the condensed chain ``A_i v_i + B_i v_(i+1) = 0``, ``(N, n, n)`` each."""
    p_mat, q_mat = reduce_product(a, b)
    try:
        mu, vec = sla.eig(p_mat, -q_mat, right=True)
    except (sla.LinAlgError, ValueError) as exc:
        raise NumericalError("Floquet multipliers: the QZ algorithm failed") from exc
    if not np.all(np.isfinite(mu)):
        raise NumericalError("Floquet multipliers: infinite multipliers (singular condensed map)")
    order = np.argsort(-np.abs(mu), kind="stable")
    mu, vec = mu[order], vec[:, order]
    d = phase_direction / scale
    vs = vec / scale[:, None]
    align = np.abs(d.conj() @ vs) / (np.linalg.norm(d) * np.linalg.norm(vs, axis=0) + 1e-300)
    near = np.abs(mu - 1.0) <= TRIVIAL_WINDOW
    if np.any(near):
        k = int(np.argmax(np.where(near, align, -1.0)))
    else:
        k = int(np.argmin(np.abs(mu - 1.0)))
    return FloquetMultipliers(mu, k, float(abs(mu[k] - 1.0)), float(align[k]))
