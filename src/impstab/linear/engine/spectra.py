"""Spectra of one problem of the engine's stack at a load (compiled).

Every problem ``j`` of a stack has an operator ``A_j(p)`` of order ``N``: ``M^-1 K(p)`` (undamped
second-order problems, eigenvalues ``s = omega^2``) or ``E^-1 A(p)`` (first-order problems, among
them the state matrix of a damped or gyroscopic second-order one; eigenvalues ``lambda``).
Where it comes from:

* *affine* problems carry ``A0`` and ``A1`` (``A = A0 + p A1``), formed here one load at a time,
  and their decoupled blocks (:mod:`impstab.linear.blocks`: closed forms for 1 x 1 and 2 x 2
  blocks, compiled QR and inverse iteration for larger ones);
* any other problem gets its operators from a Python *provider* (a load-dependent linearization,
  a user function), called from the compiled code in object mode (numba ``objmode``), one call
  per scan chunk or per load.

Eigenvalues and eigen-decompositions come from the compiled small-matrix routines
(:mod:`impstab.linear.small_eig`, :mod:`impstab.linear.small_eigvec`) up to order
:data:`~impstab.linear.small_eig.MAX_ORDER`; larger operators, and any that the compiled
routines cannot resolve (no convergence, a defective block), go to LAPACK through NumPy. A
repeated eigenvalue's vectors are one basis of its eigenspace among many, and the compiled
routines and LAPACK return different ones; the refinement turns that basis toward the cluster it
follows before it uses it (:func:`impstab.linear.engine.cluster.align_repeated`), so no result
depends on which routine decomposed the operator.

:func:`spectrum` is the one entry point of the scan and the refinement (numba links a
function's callees into it and optimises them again, so the engine keeps a single function
above these routines). Decompositions are kept in a small cache (least recently used) per
problem. A provider that raises stops its own problem only: the exception is kept on the
provider and the problem reports :data:`PROVIDER_ERROR`.

Reference counts: :func:`spectrum` and the small-matrix routines under it allocate nothing and are
compiled without numba's runtime (``_nrt=False``, as the simulation's right-hand side). With the
runtime, numba increments and decrements the count of every array a function receives, each
array of a tuple included, with an atomic instruction, once per call: 4,790 of them in one
``critical_load`` of the asymmetric example, about a fifth of its compiled time, most of them on
the 44 arrays of ``spectrum``'s three tuples. A callee without its own setting is compiled with
its caller's, so the few that must keep the runtime say ``_nrt=True``: those that enter object
mode, where arrays made in compiled code are handed to Python.
"""

from __future__ import annotations

import itertools

import numpy as np
from ..._jit import njit, objmode

from ..blocks import block_eig_at, block_eigvals_at, eig_workspace
from ..small_eig import MAX_ORDER, _solve_one
from ..small_eigvec import lapack_eig
from .layout import AFFINE, KEY, LARGEST

__all__ = ["register", "unregister", "spectrum", "workspace", "cache_new", "operators_at",
           "OK", "FAILED", "NOT_FINITE", "PROVIDER_ERROR"]

#: status codes: decomposed; eigenvectors singular (an exactly defective point); operator not
#: finite (no static equilibrium there); the provider raised
OK, FAILED, NOT_FINITE, PROVIDER_ERROR = 1, 0, -1, -2
#: decompositions kept per problem
SLOTS = 8

_PROVIDERS: dict[int, object] = {}
_KEYS = itertools.count()


def register(provider: object) -> int:
    """Make ``provider`` reachable from compiled code; returns its key."""
    key = next(_KEYS)
    _PROVIDERS[key] = provider
    return key


def unregister(key: int) -> None:
    _PROVIDERS.pop(key, None)


# -- the Python side, called in object mode ----------------------------------------------------
def _bridge_operators(key, loads, out):
    """``out[i] = A(loads[i])`` from the provider; 0, or 1 when it raised (kept on the provider)."""
    provider = _PROVIDERS[key]
    try:
        out[...] = provider.operators(np.asarray(loads))
    except Exception as exc:  # noqa: BLE001 - the problem's own failure, reported with it
        provider.error = exc
        return 1
    return 0


def _bridge_weights(key, p, out):
    """Participation weights (mass diagonal) at load ``p`` from the provider."""
    provider = _PROVIDERS[key]
    try:
        out[...] = provider.weights(float(p))
    except Exception as exc:  # noqa: BLE001
        provider.error = exc
        return 1
    return 0


def _lapack_eigvals(op, out):
    out[...] = np.linalg.eigvals(op)


# -- compiled ----------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy", _nrt=True)
def _provided_operators(key, loads, out):
    with objmode(status="int64"):
        status = _bridge_operators(key, loads, out)
    return status


@njit(cache=True, error_model="numpy", _nrt=True)
def provided_weights(key, p, out):
    """Participation weights at ``p`` from the provider ``key``; 0, or 1 when it raised."""
    with objmode(status="int64"):
        status = _bridge_weights(key, p, out)
    return status


@njit(cache=True, error_model="numpy", _nrt=True)
def _lapack_values(op, out):
    with objmode():
        _lapack_eigvals(op, out)


@njit(cache=True, error_model="numpy", _nrt=True)
def _lapack_vectors(op, vals, vecs, inv):
    with objmode(status="int64"):
        status = lapack_eig(op, vals, vecs, inv)
    return status


@njit(cache=True, error_model="numpy")
def workspace(n, chunk):
    """Work arrays of :func:`spectrum` for operators of order ``n``, up to ``chunk`` loads a call
    (and, last, ``n`` floats of scratch for the classification of its eigenvalues)."""
    order = np.arange(n).reshape(1, n)
    starts = np.full((1, n + 1), n, dtype=np.int64)
    starts[0, 0] = 0
    chunk = max(chunk, 2)
    return (eig_workspace(n), np.empty((n, n)), np.empty(n), np.empty(n), np.empty(n),
            np.empty((chunk, n, n)), np.zeros((1, n, n)), order, starts, np.ones(1, dtype=np.int64),
            np.empty((chunk, n), dtype=np.complex128), np.empty(chunk, dtype=np.bool_),
            np.zeros((1, n), dtype=np.int64), np.empty(n))


@njit(cache=True, error_model="numpy")
def cache_new(n):
    """Decompositions at up to :data:`SLOTS` loads: load, status, values, vectors, inverse, age, clock."""
    return (np.full(SLOTS, np.nan), np.zeros(SLOTS, dtype=np.int64), np.empty((SLOTS, n), dtype=np.complex128),
            np.empty((SLOTS, n, n), dtype=np.complex128), np.empty((SLOTS, n, n), dtype=np.complex128),
            np.zeros(SLOTS, dtype=np.int64), np.zeros(1, dtype=np.int64))


def _finite_numpy(a):
    """:func:`_finite` while kernels run interpreted: one NumPy test, not a Python loop."""
    return bool(np.isfinite(a).all())


@njit(cache=True, error_model="numpy", _nrt=False, interpreted=_finite_numpy)
def _finite(a):
    for x in a.flat:
        if not np.isfinite(x):
            return False
    return True


@njit(cache=True, error_model="numpy", _nrt=False)
def operators_at(jobs, j, loads, out):
    """``out[i] = A_j(loads[i])``; returns 0, or 1 when the provider failed."""
    if jobs.ints[j, AFFINE]:
        n = out.shape[1]
        for i in range(len(loads)):
            p = loads[i]
            for r in range(n):
                for c in range(n):
                    out[i, r, c] = jobs.a0[j, r, c] + p * jobs.a1[j, r, c]
        return 0
    return _provided_operators(jobs.ints[j, KEY], loads, out)


def _values_of_numpy(op, ws, out):
    """:func:`_values_of` while kernels run interpreted: the same steps, without copying ``op``
    element by element in Python (interpreted, :func:`_solve_one` is LAPACK's ``geev``, which
    leaves its matrix as it is)."""
    n = op.shape[0]
    if n > MAX_ORDER or not _solve_one(op, n, ws[2], ws[3], ws[4], out):
        _lapack_values(op, out)


@njit(cache=True, error_model="numpy", _nrt=False, interpreted=_values_of_numpy)
def _values_of(op, ws, out):
    """Eigenvalues of the real matrix ``op`` into ``out``: compiled QR, else LAPACK."""
    n = op.shape[0]
    if n <= MAX_ORDER:
        w, v, wr, wi = ws[1], ws[2], ws[3], ws[4]
        for r in range(n):  # a loop, not ``w[:, :] = op``: numba's array copy needs its runtime
            for c in range(n):
                w[r, c] = op[r, c]
        if _solve_one(w, n, v, wr, wi, out):
            return
    _lapack_values(op, out)


#: the ``vectors`` argument of :func:`spectrum`. NumPy booleans, not ``False`` and ``True``: numba
#: compiles a compiled callee once more for each literal constant it is passed (``Literal[bool]``),
#: but once for a NumPy boolean of either value
VALUES, DECOMPOSITION = np.bool_(False), np.bool_(True)


@njit(cache=True, error_model="numpy", _nrt=False)
def spectrum(jobs, j, loads, vectors, cache, ws, ev):
    """Eigenvalues or a decomposition of problem ``j``; returns ``(status, slot)``.

    ``vectors`` :data:`VALUES` (False): the eigenvalues at every load of ``loads`` into ``ws[10][:m]``, with
    ``ws[11][i]`` set where the operator is not finite (its eigenvalues are then those of the
    identity, a stable placeholder); the status is 0, or :data:`PROVIDER_ERROR`.

    ``vectors`` :data:`DECOMPOSITION` (True): the decomposition at ``loads[0]`` (values, unit eigenvectors, their
    inverse) in cache slot ``slot``, computed unless cached; the status (:data:`OK`,
    :data:`FAILED`, :data:`NOT_FINITE`, :data:`PROVIDER_ERROR`) is also ``cache[1][slot]``.
    ``ev[0]`` counts the eigenproblems solved, ``ev[1]`` the decompositions among them.
    """
    m = len(loads)
    n = jobs.a0.shape[1]
    compiled = jobs.ints[j, AFFINE] == 1 and jobs.ints[j, LARGEST] <= MAX_ORDER
    ops = ws[5]
    if not vectors:
        vals, lost = ws[10], ws[11]
        if compiled:
            w, v, wr, wi = ws[1], ws[2], ws[3], ws[4]
            for i in range(m):
                lost[i] = False
                if not block_eigvals_at(jobs.a0, jobs.a1, j, loads[i], jobs.order, jobs.starts, jobs.nblocks,
                                        jobs.mirror, jobs.fixed, w, v, wr, wi, vals[i]):
                    operators_at(jobs, j, loads[i:i + 1], ops[:1])
                    lost[i] = not _finite(ops[0])
                    if lost[i]:
                        vals[i, :] = 1.0
                    else:
                        _values_of(ops[0], ws, vals[i])
        else:
            if operators_at(jobs, j, loads, ops[:m]) != 0:
                return PROVIDER_ERROR, -1
            for i in range(m):
                lost[i] = not _finite(ops[i])
                if lost[i]:
                    vals[i, :] = 1.0
                else:
                    _values_of(ops[i], ws, vals[i])
        ev[0] += m
        return 0, -1
    # a decomposition, cached
    p = loads[0]
    c_loads, c_status, c_vals, c_vecs, c_inv, c_age, clock = cache
    clock[0] += 1
    s = 0
    for t in range(SLOTS):
        if c_loads[t] == p:
            c_age[t] = clock[0]
            return c_status[t], t
        if c_age[t] < c_age[s]:
            s = t
    c_loads[s] = p
    c_age[s] = clock[0]
    vals, vecs, inv = c_vals[s], c_vecs[s], c_inv[s]
    ev[0] += 1
    ev[1] += 1
    if compiled and block_eig_at(jobs.a0, jobs.a1, j, p, jobs.order, jobs.starts, jobs.nblocks, jobs.mirror,
                                 vals, vecs, inv, ws[0]):
        c_status[s] = OK
        return OK, s
    if operators_at(jobs, j, loads[:1], ops[:1]) != 0:
        c_status[s] = PROVIDER_ERROR
        c_loads[s] = np.nan
        return PROVIDER_ERROR, s
    if not _finite(ops[0]):
        c_status[s] = NOT_FINITE
        vals[:] = np.nan
        return NOT_FINITE, s
    # the one design of ws[6..9] as an int64, as ``j`` above: numba compiles a callee once per
    # argument type, and a literal 0 is a type of its own (``Literal[int](0)``)
    if n <= MAX_ORDER and block_eig_at(ops[:1], ws[6], np.int64(0), 0.0, ws[7], ws[8], ws[9], ws[12], vals, vecs,
                                       inv, ws[0]):
        c_status[s] = OK
        return OK, s
    c_status[s] = _lapack_vectors(ops[0], vals, vecs, inv)
    return c_status[s], s
