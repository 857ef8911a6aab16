"""Condensation of parameters: the bordered collocation system solved through its mesh-point values.

On interval ``i`` the linearized collocation equations read
``E_i w_i + F_i v_i + G_i v_(i+1) + H_i mu = r_i``: ``w_i`` the ``(m - 1) n`` interior nodal values,
``v_i`` the values at the mesh points, ``mu = (T, p)``. An orthogonal factorization
``E_i = Q_i [R_i; 0]`` splits them into ``R_i w_i + ... = (Q_i^T r_i)_top``, which gives the interior
values once the mesh-point values are known, and ``n`` condensed equations
``A_i v_i + B_i v_(i+1) + Hb_i mu = (Q_i^T r_i)_bottom`` (the same ``A_i``, ``B_i`` as the Floquet
reduction uses). The two border rows (phase condition, continuation constraint) are condensed by
substituting the interior values. What remains is a cyclic block-bidiagonal system of ``N n + 2``
unknowns with two dense rows and columns, solved by SuperLU (minimum-degree ordering of
``A^T + A``); the interior values follow by back-substitution. This is AUTO's strategy (Doedel,
Keller and Kernevez 1991) with QR in place of Gaussian elimination; it is ``m`` times smaller than
the full system and its factorization costs a small fraction of the full sparse one.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

__all__ = ["Condensation"]

Array = NDArray[np.float64]


class Condensation:
    """The condensed form of one linearization of the collocation equations.

    Parameters
    ----------
    blocks : (N, m, m + 1, n, n) array
        Derivatives of the collocation equations with respect to the local nodes.
    col_period, col_parameter : (N m n,) arrays
        Derivatives with respect to ``T`` and ``p``.
    """

    def __init__(self, blocks: Array, col_period: Array, col_parameter: Array) -> None:
        n_int, m, _, n, _ = blocks.shape
        self.N, self.m, self.n = n_int, m, n
        k = (m - 1) * n
        self.k = k
        g = blocks.transpose(0, 1, 3, 2, 4).reshape(n_int, m * n, (m + 1) * n)
        h = np.stack([col_period.reshape(n_int, m * n), col_parameter.reshape(n_int, m * n)], axis=2)
        rest = np.concatenate([g[:, :, :n], g[:, :, n + k:], h], axis=2)          # (N, mn, 2n + 2)
        q, r = np.linalg.qr(g[:, :, n: n + k], mode="complete")
        self.qt = np.swapaxes(q, 1, 2)
        rot = self.qt @ rest
        self.r_top = r[:, :k, :]
        self.s = np.linalg.solve(self.r_top, rot[:, :k, :])                           # (N, k, 2n + 2)
        self.a = rot[:, k:, :n]
        self.b = rot[:, k:, n: 2 * n]
        self.hb = rot[:, k:, 2 * n:]
        size = n_int * n + 2
        self.size = size
        i = np.arange(n_int)
        rows_blk = (i[:, None, None] * n + np.arange(n)[None, :, None]) + np.zeros((1, 1, n), int)
        cols_a = i[:, None, None] * n + np.arange(n)[None, None, :] + np.zeros((1, n, 1), int)
        cols_b = ((i + 1) % n_int)[:, None, None] * n + np.arange(n)[None, None, :] + np.zeros((1, n, 1), int)
        rows_h = np.repeat(np.arange(n_int * n), 2)
        cols_h = np.tile([size - 2, size - 1], n_int * n)
        self._rows = np.concatenate([rows_blk.reshape(-1), rows_blk.reshape(-1), rows_h,
                                     np.full(size, size - 2), np.full(size, size - 1)])
        self._cols = np.concatenate([cols_a.reshape(-1), cols_b.reshape(-1), cols_h, np.arange(size), np.arange(size)])

    def factor(self, border: Array):
        """The sparse LU factorization of the condensed system with the border rows ``border``."""
        n_int, m, n, k = self.N, self.m, self.n, self.k
        nx = n_int * m * n
        c_nodes = border[:, :nx].reshape(2, n_int, m, n)
        c_v = c_nodes[:, :, 0, :]                                                    # (2, N, n)
        c_w = c_nodes[:, :, 1:, :].reshape(2, n_int, k)
        cs = np.einsum("rik,ikc->ric", c_w, self.s)                                  # (2, N, 2n + 2)
        coef_v = c_v - cs[:, :, :n]
        coef_v = coef_v + np.roll(-cs[:, :, n: 2 * n], 1, axis=1)                    # v_(i+1) of interval i
        coef_mu = border[:, nx:] - cs[:, :, 2 * n:].sum(axis=1)
        data = np.concatenate([self.a.reshape(-1), self.b.reshape(-1), self.hb.reshape(-1),
                               np.concatenate([coef_v[0].reshape(-1), coef_mu[0]]),
                               np.concatenate([coef_v[1].reshape(-1), coef_mu[1]])])
        mat = sp.csc_matrix((data, (self._rows, self._cols)), shape=(self.size, self.size))
        # minimum-degree ordering on the structure of A^T + A: the cyclic block-bidiagonal part is
        # nearly symmetric in structure, and this ordering keeps the fill of the LU factors 7 times
        # smaller than SuperLU's default (COLAMD) on the propulsor's branches: factorization 4x faster
        return spla.splu(mat, permc_spec="MMD_AT_PLUS_A")

    def solve(self, rhs: Array, border: Array, border_rhs: Array, lu=None) -> Array:
        """Solve ``J x = (rhs, border_rhs)`` with the border rows ``border`` ``(2, N m n + 2)``.

        ``rhs`` is the collocation part ``(N m n,)``; returns ``x`` in the node layout of
        :class:`~impstab.postcritical.periodic.OrbitProblem` (nodes, then ``T``, ``p``). ``lu``:
        :meth:`factor` of the same ``border``, to reuse (default: factorized here).
        """
        n_int, m, n, k = self.N, self.m, self.n, self.k
        nx = n_int * m * n
        rq = (self.qt @ rhs.reshape(n_int, m * n, 1))[:, :, 0]
        t = np.linalg.solve(self.r_top, rq[:, :k, None])[:, :, 0]                   # (N, k)
        c_w = border[:, :nx].reshape(2, n_int, m, n)[:, :, 1:, :].reshape(2, n_int, k)
        r_border = border_rhs - np.einsum("rik,ik->r", c_w, t)
        lu = self.factor(border) if lu is None else lu
        red = lu.solve(np.concatenate([rq[:, k:].reshape(-1), r_border]))
        v = red[:-2].reshape(n_int, n)
        mu = red[-2:]
        w = (t - np.einsum("ikc,ic->ik", self.s[:, :, :n], v)
             - np.einsum("ikc,ic->ik", self.s[:, :, n: 2 * n], np.roll(v, -1, axis=0))
             - self.s[:, :, 2 * n:] @ mu)
        nodes = np.concatenate([v[:, None, :], w.reshape(n_int, m - 1, n)], axis=1)
        return np.concatenate([nodes.reshape(-1), mu])
