"""Decoupled blocks of affine operator families ``A(p) = A0 + p A1``, and their eigenproblems.

A rigid body on a symmetric mount layout, with its thrust on the axis, falls apart into
independent motions: surge, roll, and the sway-yaw and heave-pitch planes (the paper's
Figure 4). Its operators ``M^-1 K(p)`` are then block diagonal after a permutation of the dofs,
and the eigen-decomposition of the whole is that of each block: closed forms for blocks of one
and two dofs, the compiled small-matrix routines for larger ones (eigenvalues by
:mod:`impstab.linear.small_eig`, eigenvectors by :mod:`impstab.linear.small_eigvec`); a
coupled design is one block of six.
Design studies solve millions of such eigenproblems, so the stability engine
(:mod:`impstab.linear.engine`) uses this decomposition wherever a problem has it, through the
per-design routines :func:`block_eigvals_at` and :func:`block_eig_at`.

Which dofs are coupled
----------------------
Assembled in floating point, the coupling terms that vanish by symmetry are not exactly zero
but rounding residues (``1e-17`` of the matrix norm in the bundled example: sums of
``k y_i z_i`` over a ring). Two dofs ``i, j`` are coupled when, anywhere on the load range
``[0, p_max]``, an entry ``A_ij`` or ``A_ji`` exceeds :data:`TOL_DECOUPLE` times the largest
entry of the operator, all judged on the operators balanced by a power-of-two diagonal
similarity (so that the mixed units of translations and rotations do not matter). Dropping what
is below is a perturbation of at most ``n TOL_DECOUPLE`` of the operator's norm: within the
backward error of LAPACK's own ``geev`` on the full matrix (a few ``eps |A|``). The eigenvalues
are therefore as accurate as LAPACK's (simple ones to ``eps |A| / s_i``, a defective double one
to ``sqrt(eps |A|)``), and the symmetric functions of a cluster that the engine refines on to
``eps``.

Conventions
-----------
Eigenvalues of a block are listed together; eigenvectors are unit columns (2-norm), the
``k``-th column belonging to the ``k``-th eigenvalue; the returned inverse is the matrix of left
eigenvectors ``V^-1``.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import copysign, sqrt

import numpy as np
from .._jit import njit
from numpy.typing import NDArray

from .small_eig import MAX_ORDER, _balance, _solve_one, eigvals_affine
from .small_eigvec import _eig_block

__all__ = ["BlockStructure", "TOL_DECOUPLE", "decoupled_blocks", "eigvals_affine_blocks", "eig_affine",
           "block_eigvals_at", "block_eig_at", "eig_workspace"]

_EPS = float(np.finfo(float).eps)
#: coupling (relative to the balanced operator's largest entry) below which dofs are decoupled
TOL_DECOUPLE = 16.0 * _EPS


@dataclass(frozen=True, eq=False)
class BlockStructure:
    """The independent blocks of each design's operators.

    Attributes
    ----------
    order : (N, n) int array
        The dofs of each design listed block by block (blocks by their first dof).
    starts : (N, n + 1) int array
        Start of block ``b`` in ``order`` at ``starts[:, b]``; ``starts[:, nblocks] = n`` and the
        entries after it are ``n`` too.
    nblocks : (N,) int array
        Number of blocks.
    largest : (N,) int array
        Size of the largest block (1 for a diagonal operator, ``n`` for a coupled one).
    mirror : (N, n) int array
        0 at the positions of ``order`` in a block solved on its own. A block of three dofs or
        more that is a signed copy of an earlier one (``A_b = S A_c S`` over the load range, ``S``
        a diagonal of signs: the identical planes of a symmetric layout) is not solved again: at
        its ``k``-th position ``mirror = s_k (i + 1)``, ``i`` the position of the ``k``-th dof of
        block ``c`` and ``s_k = +-1``. Its eigenvalues are those of ``c``, its eigenvectors ``S``
        times those of ``c``.
    fixed : (N, n) complex array
        The eigenvalues, at the positions of ``order``, of each block of three dofs or more that
        does not change over the load range (``p_max A1`` within the decoupling tolerance on it:
        the surge and roll motions of a symmetric layout under an axial thrust), computed once;
        NaN elsewhere.
    """

    order: NDArray[np.int64]
    starts: NDArray[np.int64]
    nblocks: NDArray[np.int64]
    largest: NDArray[np.int64]
    mirror: NDArray[np.int64]
    fixed: NDArray[np.complex128]

    def take(self, rows: NDArray) -> "BlockStructure":
        """The structure of the designs ``rows``."""
        return BlockStructure(self.order[rows], self.starts[rows], self.nblocks[rows], self.largest[rows],
                              self.mirror[rows], self.fixed[rows])


@njit(cache=True, error_model="numpy")
def _mirror_signs(a0, a1, s, p_max, order, lo, src, m, f, limit, signs):
    """Signs ``S`` with block ``lo`` of design ``s`` equal to ``S (block src) S`` within ``limit``
    (balanced units, at ``p = 0`` and ``p_max`` alike) into ``signs[:m]``; False: not such a copy."""
    for x in range(m):
        signs[x] = 0
    signs[0] = 1
    for _ in range(m):  # spread the signs along the couplings (a block is connected)
        for x in range(m):
            if signs[x] != 0:
                continue
            for y in range(m):
                if signs[y] == 0:
                    continue
                for a, b in ((x, y), (y, x)):
                    i, j = order[s, lo + a], order[s, lo + b]
                    k, l = order[s, src + a], order[s, src + b]
                    w = f[j] / f[i]
                    here = a0[s, i, j] + p_max * a1[s, i, j]
                    there = a0[s, k, l] + p_max * a1[s, k, l]
                    if abs(there) * w > limit and abs(here) * w > limit:
                        signs[x] = signs[y] if (here > 0) == (there > 0) else -signs[y]
                        break
                if signs[x] != 0:
                    break
    for x in range(m):
        if signs[x] == 0:
            return False
    for x in range(m):
        for y in range(m):
            i, j = order[s, lo + x], order[s, lo + y]
            k, l = order[s, src + x], order[s, src + y]
            w = f[j] / f[i]
            d = signs[x] * signs[y]
            if (abs(a0[s, i, j] - d * a0[s, k, l]) + abs(p_max) * abs(a1[s, i, j] - d * a1[s, k, l])) * w > limit:
                return False
    return True


@njit(cache=True, error_model="numpy")
def _load_free(a1, s, p_max, order, lo, m, f, limit):
    """Whether ``p_max A1`` on the block at ``lo`` is within ``limit`` (balanced units) everywhere."""
    for x in range(m):
        for y in range(m):
            i, j = order[s, lo + x], order[s, lo + y]
            if abs(p_max * a1[s, i, j]) * f[j] / f[i] > limit:
                return False
    return True


@njit(cache=True, error_model="numpy")
def _structure(a0, a1, p_max, tol, order, starts, nblocks, largest, mirror, fixed):
    count, n = a0.shape[0], a0.shape[1]
    c = np.empty((n, n))
    f = np.empty(n)
    label = np.empty(n, dtype=np.int64)
    signs = np.empty(n, dtype=np.int64)
    blk = np.empty((n, n))
    v, wr, wi = np.empty(n), np.empty(n), np.empty(n)
    for s in range(count):
        for i in range(n):
            for j in range(n):
                c[i, j] = abs(a0[s, i, j]) + abs(p_max[s]) * abs(a1[s, i, j])
        _balance(c, n, f)
        # the operator's size at both ends of the range, in the balanced units
        end0 = 0.0
        end1 = 0.0
        finite = np.isfinite(p_max[s])
        for i in range(n):
            for j in range(n):
                w = f[j] / f[i]
                end0 = max(end0, abs(a0[s, i, j]) * w)
                end1 = max(end1, abs(a0[s, i, j] + p_max[s] * a1[s, i, j]) * w)
                finite = finite and np.isfinite(a0[s, i, j]) and np.isfinite(a1[s, i, j])
        limit = tol * min(end0, end1)
        finite = finite and np.isfinite(limit)
        for i in range(n):
            label[i] = i
        changed = True
        while changed:  # connected components: propagate the smallest label
            changed = False
            for i in range(n):
                for j in range(i + 1, n):
                    if not finite or c[i, j] > limit or c[j, i] > limit:
                        m = min(label[i], label[j])
                        if label[i] != m or label[j] != m:
                            label[i] = m
                            label[j] = m
                            changed = True
        k = 0
        b = 0
        big = 0
        for root in range(n):
            first = k
            for i in range(n):
                if label[i] == root:
                    order[s, k] = i
                    k += 1
            if k > first:
                starts[s, b] = first
                b += 1
                big = max(big, k - first)
        for r in range(b, n + 1):
            starts[s, r] = n
        nblocks[s] = b
        largest[s] = big
        for i in range(n):
            mirror[s, i] = 0
            fixed[s, i] = complex(np.nan, np.nan)
        if not finite:
            continue
        for bb in range(b):  # a block of three dofs or more that the load does not change: solved once
            lo, m = starts[s, bb], starts[s, bb + 1] - starts[s, bb]
            if m < 3 or not _load_free(a1, s, p_max[s], order, lo, m, f, limit):
                continue
            _fill_block(a0, a1, s, 0.0, order, lo, m, blk)
            if not _solve_one(blk, m, v, wr, wi, fixed[s, lo:lo + m]):
                for x in range(m):
                    fixed[s, lo + x] = complex(np.nan, np.nan)
        for bb in range(1, b):  # a block of three dofs or more that copies an earlier one
            lo, m = starts[s, bb], starts[s, bb + 1] - starts[s, bb]
            if m < 3:
                continue
            for cc in range(bb):
                src = starts[s, cc]
                if starts[s, cc + 1] - src != m or mirror[s, src] != 0:
                    continue
                if _mirror_signs(a0, a1, s, p_max[s], order, lo, src, m, f, limit, signs):
                    for x in range(m):
                        mirror[s, lo + x] = signs[x] * (src + x + 1)
                    break


def decoupled_blocks(a0: NDArray[np.float64], a1: NDArray[np.float64], p_max: NDArray[np.float64]) -> BlockStructure:
    """The independent blocks of ``A0[i] + p A1[i]`` on ``0 <= p <= p_max[i]``.

    Parameters
    ----------
    a0, a1 : (N, n, n) float arrays
    p_max : (N,) float array
        End of each design's load range.

    Returns
    -------
    BlockStructure
        A design whose operators are not finite is one block.
    """
    a0 = np.ascontiguousarray(a0, dtype=float)
    a1 = np.ascontiguousarray(a1, dtype=float)
    count, n = a0.shape[0], a0.shape[-1]
    order = np.empty((count, n), dtype=np.int64)
    starts = np.empty((count, n + 1), dtype=np.int64)
    nblocks = np.empty(count, dtype=np.int64)
    largest = np.empty(count, dtype=np.int64)
    mirror = np.empty((count, n), dtype=np.int64)
    fixed = np.empty((count, n), dtype=np.complex128)
    _structure(a0, a1, np.ascontiguousarray(p_max, dtype=float), TOL_DECOUPLE, order, starts, nblocks, largest,
               mirror, fixed)
    return BlockStructure(order, starts, nblocks, largest, mirror, fixed)


@njit(cache=True, error_model="numpy")
def _values2(a, b, c, d):
    """Eigenvalues of ``[[a, b], [c, d]]`` (LAPACK ``dlanv2``'s standardisation, unscaled)."""
    p = 0.5 * (a - d)
    bc = b * c
    q = p * p + bc
    if q >= 0.0:
        z = p + copysign(sqrt(q), p)
        if z == 0.0:
            return complex(d, 0.0), complex(d, 0.0)
        return complex(d + z, 0.0), complex(d - bc / z, 0.0)
    m = 0.5 * (a + d)
    w = sqrt(-q)
    return complex(m, w), complex(m, -w)


#: ``first`` of :func:`_vector2`: NumPy booleans, compiled once (``True`` and ``False`` would each be
#: a literal type of their own, compiled separately)
_FIRST, _SECOND = np.bool_(True), np.bool_(False)


@njit(cache=True, error_model="numpy")
def _vector2(lam, a, b, c, d, first):
    """Unit eigenvector of ``[[a, b], [c, d]]`` for ``lam``: the larger of the two row solutions."""
    x1, y1 = complex(b, 0.0), lam - a
    x2, y2 = lam - d, complex(c, 0.0)
    n1 = x1.real**2 + x1.imag**2 + y1.real**2 + y1.imag**2
    n2 = x2.real**2 + x2.imag**2 + y2.real**2 + y2.imag**2
    if n1 >= n2 and n1 > 0.0:
        s = 1.0 / sqrt(n1)
        return x1 * s, y1 * s
    if n2 > 0.0:
        s = 1.0 / sqrt(n2)
        return x2 * s, y2 * s
    # a multiple of the identity: any basis
    if first:
        return complex(1.0, 0.0), complex(0.0, 0.0)
    return complex(0.0, 0.0), complex(1.0, 0.0)


@njit(cache=True, error_model="numpy", _nrt=False)
def _fill_block(a0, a1, s, p, order, lo, m, w):
    """``w[:m, :m]`` = the block of dofs ``order[s, lo:lo + m]`` of ``a0[s] + p a1[s]``."""
    for x in range(m):
        for y in range(m):
            i, j = order[s, lo + x], order[s, lo + y]
            w[x, y] = a0[s, i, j] + p * a1[s, i, j]


@njit(cache=True, error_model="numpy", _nrt=False)
def block_eigvals_at(a0, a1, s, p, order, starts, nblocks, mirror, fixed, w, v, wr, wi, out):
    """Eigenvalues of design ``s`` at load ``p``, block by block, into ``out (n,)``; False: failed.

    ``w (n, n)``, ``v, wr, wi (n,)`` are work arrays; ``mirror``, ``fixed`` as in
    :class:`BlockStructure`.
    """
    n = a0.shape[1]
    good = True
    for b in range(nblocks[s]):
        lo, hi = starts[s, b], starts[s, b + 1]
        m = hi - lo
        if not np.isnan(fixed[s, lo].real):  # the same at every load
            for x in range(m):
                out[lo + x] = fixed[s, lo + x]
            continue
        if mirror[s, lo] != 0:  # a signed copy of an earlier block: the same eigenvalues
            src = abs(mirror[s, lo]) - 1
            for x in range(m):
                out[lo + x] = out[src + x]
            continue
        _fill_block(a0, a1, s, p, order, lo, m, w)
        if m == 1:
            out[lo] = complex(w[0, 0], 0.0)
        elif m == 2:
            l1, l2 = _values2(w[0, 0], w[0, 1], w[1, 0], w[1, 1])
            out[lo] = l1
            out[lo + 1] = l2
        else:
            good = _solve_one(w, m, v, wr, wi, out[lo:hi]) and good
    for i in range(n):
        good = good and np.isfinite(out[i].real) and np.isfinite(out[i].imag)
    return good


@njit(cache=True, error_model="numpy")
def _eigvals_blocks(a0, a1, loads, order, starts, nblocks, mirror, fixed, out, ok):
    n = a0.shape[1]
    w = np.empty((n, n))
    v, wr, wi = np.empty(n), np.empty(n), np.empty(n)
    for s in range(a0.shape[0]):
        for k in range(loads.shape[1]):
            ok[s, k] = block_eigvals_at(a0, a1, s, loads[s, k], order, starts, nblocks, mirror, fixed, w, v, wr, wi,
                                        out[s, k])


def eigvals_affine_blocks(a0: NDArray[np.float64], a1: NDArray[np.float64], loads: NDArray[np.float64],
                          blocks: BlockStructure) -> NDArray[np.complex128]:
    """Eigenvalues of ``a0[i] + loads[i, k] a1[i]``, block by block; shape ``(N, K, n)``.

    The same values as :func:`impstab.linear.small_eig.eigvals_affine` to rounding (see the
    module notes); a problem whose blocks fail (not finite, no convergence) is solved whole by it.
    """
    a0 = np.ascontiguousarray(a0, dtype=float)
    a1 = np.ascontiguousarray(a1, dtype=float)
    loads = np.ascontiguousarray(loads, dtype=float)
    out = np.empty(loads.shape + (a0.shape[-1],), dtype=np.complex128)
    ok = np.ones(loads.shape, dtype=np.bool_)
    _eigvals_blocks(a0, a1, loads, blocks.order, blocks.starts, blocks.nblocks, blocks.mirror, blocks.fixed,
                    out, ok)
    if not ok.all():
        s, k = np.nonzero(~ok)
        out[s, k] = eigvals_affine(a0[s], a1[s], loads[s, k][:, None])[:, 0]
    return out


@njit(cache=True, error_model="numpy")
def eig_workspace(n):
    """Work arrays of :func:`block_eig_at` for operators of order ``n``."""
    return (np.empty((n, n)), np.empty((n, n)), np.empty(n), np.empty(n), np.empty(n),
            np.empty(n, dtype=np.complex128), np.empty((n, n), dtype=np.complex128),
            np.empty((n, n), dtype=np.complex128), np.empty((n, n), dtype=np.complex128),
            np.empty(n, dtype=np.int64), np.empty(n, dtype=np.complex128), np.empty((n, n)), np.empty(n))


@njit(cache=True, error_model="numpy", _nrt=False)
def block_eig_at(a0, a1, s, p, order, starts, nblocks, mirror, vals, vecs, inv, ws):
    """Eigen-decomposition of design ``s`` at load ``p``, block by block; False: failed.

    Closed forms up to two dofs, else compiled QR and inverse iteration
    (:mod:`impstab.linear.small_eigvec`). ``vals (n,)``, ``vecs (n, n)`` (unit columns) and
    ``inv (n, n)`` (``vecs^-1``) receive the result; ``ws`` is :func:`eig_workspace`.
    """
    w, w0, v, wr, wi, bv, bvec, binv, lu, piv, x, lu_real, x_real = ws
    n = a0.shape[1]
    good = True
    for r in range(n):
        for c in range(n):
            vecs[r, c] = 0.0
            inv[r, c] = 0.0
    for b in range(nblocks[s]):
        lo, hi = starts[s, b], starts[s, b + 1]
        m = hi - lo
        if mirror[s, lo] != 0:  # A_b = S A_c S: the values of c, vectors S V_c, inverse V_c^-1 S
            src = abs(mirror[s, lo]) - 1
            for xx in range(m):
                vals[lo + xx] = vals[src + xx]
                sx = 1.0 if mirror[s, lo + xx] > 0 else -1.0
                for yy in range(m):
                    sy = 1.0 if mirror[s, lo + yy] > 0 else -1.0
                    vecs[order[s, lo + xx], lo + yy] = sx * vecs[order[s, src + xx], src + yy]
                    inv[lo + xx, order[s, lo + yy]] = inv[src + xx, order[s, src + yy]] * sy
            continue
        _fill_block(a0, a1, s, p, order, lo, m, w0)
        if m == 1:
            r = order[s, lo]
            vals[lo] = complex(w0[0, 0], 0.0)
            vecs[r, lo] = 1.0
            inv[lo, r] = 1.0
            continue
        if m == 2:
            i, j = order[s, lo], order[s, lo + 1]
            a, bb, c, d = w0[0, 0], w0[0, 1], w0[1, 0], w0[1, 1]
            l1, l2 = _values2(a, bb, c, d)
            v00, v10 = _vector2(l1, a, bb, c, d, _FIRST)
            v01, v11 = _vector2(l2, a, bb, c, d, _SECOND)
            det = v00 * v11 - v01 * v10
            if det == 0.0 or not (np.isfinite(det.real) and np.isfinite(det.imag)):
                good = False
                continue
            vals[lo] = l1
            vals[lo + 1] = l2
            vecs[i, lo] = v00
            vecs[j, lo] = v10
            vecs[i, lo + 1] = v01
            vecs[j, lo + 1] = v11
            inv[lo, i] = v11 / det
            inv[lo, j] = -v01 / det
            inv[lo + 1, i] = -v10 / det
            inv[lo + 1, j] = v00 / det
            continue
        for xx in range(m):  # loops, not a slice copy: numba's array copy needs its runtime
            for yy in range(m):
                w[xx, yy] = w0[xx, yy]
        if not _eig_block(w, w0, m, v, wr, wi, bv, bvec, binv, lu, piv, x, lu_real, x_real):
            good = False
            continue
        for xx in range(m):
            vals[lo + xx] = bv[xx]
            for yy in range(m):
                vecs[order[s, lo + xx], lo + yy] = bvec[xx, yy]
                inv[lo + xx, order[s, lo + yy]] = binv[xx, yy]
    return good


@njit(cache=True, error_model="numpy")
def _eig_blocks(a0, a1, loads, order, starts, nblocks, mirror, vals, vecs, inv, ok):
    """Eigen-decomposition of each design, block by block (closed forms up to two dofs)."""
    ws = eig_workspace(a0.shape[1])
    for s in range(a0.shape[0]):
        ok[s] = block_eig_at(a0, a1, s, loads[s], order, starts, nblocks, mirror, vals[s], vecs[s], inv[s], ws)


def _lapack(ops: NDArray[np.float64]) -> tuple:
    """``np.linalg.eig`` and the inverse of the eigenvectors; rows that fail are NaN, not ok."""
    count, n = ops.shape[0], ops.shape[-1]
    vals = np.full((count, n), np.nan + 0j)
    vecs = np.full((count, n, n), np.nan + 0j)
    inv = np.full((count, n, n), np.nan + 0j)
    ok = np.isfinite(ops).all(axis=(-2, -1))
    rows = np.flatnonzero(ok)
    if rows.size:
        v, w = np.linalg.eig(ops[rows])
        vals[rows], vecs[rows] = v, w
        try:
            inv[rows] = np.linalg.inv(vecs[rows])
        except np.linalg.LinAlgError:
            for r in rows:
                try:
                    inv[r] = np.linalg.inv(vecs[r])
                except np.linalg.LinAlgError:
                    ok[r] = False
    return vals, vecs, inv, ok


def eig_affine(a0: NDArray[np.float64], a1: NDArray[np.float64], loads: NDArray[np.float64],
               blocks: BlockStructure | None = None) -> tuple:
    """Eigenvalues, unit eigenvectors and their inverse of ``a0[i] + loads[i] a1[i]``.

    Parameters
    ----------
    a0, a1 : (N, n, n) float arrays
    loads : (N,) float array
    blocks : BlockStructure, optional
        Each block is solved on its own: in closed form up to two dofs, else by the compiled
        QR (:mod:`impstab.linear.small_eig`) and inverse iteration. A design whose blocks fail
        (a residual above ``64 m eps |A|``, singular eigenvectors), and every design without a
        structure, goes to ``np.linalg.eig`` on the whole operator.

    Returns
    -------
    vals : (N, n) complex array
    vecs : (N, n, n) complex array
        Unit columns; ``vecs[i] @ diag(vals[i]) = A_i vecs[i]``.
    inv : (N, n, n) complex array
        ``vecs[i]^-1`` (the left eigenvectors as rows).
    ok : (N,) bool array
        False where the operator is not finite or its eigenvectors are singular (an exactly
        defective point): those rows are NaN.
    """
    a0 = np.ascontiguousarray(a0, dtype=float)
    a1 = np.ascontiguousarray(a1, dtype=float)
    loads = np.ascontiguousarray(loads, dtype=float)
    count, n = a0.shape[0], a0.shape[-1]
    compiled = np.zeros(count, dtype=bool) if blocks is None else blocks.largest <= MAX_ORDER
    vals = np.empty((count, n), dtype=np.complex128)
    vecs = np.empty((count, n, n), dtype=np.complex128)
    inv = np.empty((count, n, n), dtype=np.complex128)
    ok = np.zeros(count, dtype=np.bool_)
    if blocks is not None and compiled.all():  # the usual case: no copies
        _eig_blocks(a0, a1, loads, blocks.order, blocks.starts, blocks.nblocks, blocks.mirror, vals, vecs, inv, ok)
    elif compiled.any():
        rows = np.flatnonzero(compiled)
        sub = blocks.take(rows)
        v, w, u, good = (np.empty((len(rows), n), np.complex128), np.empty((len(rows), n, n), np.complex128),
                         np.empty((len(rows), n, n), np.complex128), np.zeros(len(rows), np.bool_))
        _eig_blocks(a0[rows], a1[rows], loads[rows], sub.order, sub.starts, sub.nblocks, sub.mirror, v, w, u, good)
        vals[rows], vecs[rows], inv[rows], ok[rows] = v, w, u, good
    rest = np.flatnonzero(~ok)
    if rest.size:
        ops = a0[rest] + loads[rest, None, None] * a1[rest]
        vals[rest], vecs[rest], inv[rest], ok[rest] = _lapack(ops)
    return vals, vecs, inv, ok
