"""Compiled fixed-step integrators: Gill's fourth-order Runge-Kutta and Hamming's modified
predictor-corrector (THEORY 8), on the right-hand side of :mod:`impstab.dynamics.rhs`.

One entry point, :func:`run_fixed`, advances a run by a number of steps and writes samples into
preallocated arrays; the integrator history (the last four states and three derivatives, and the
last predictor-corrector difference) is carried in an array between calls, so a run cut into
chunks gives exactly the same numbers as one call.

Hamming's method with step ``h`` and ``f_j = f(t_j, y_j)``:

* predictor (Milne)  ``p = y_{n-3} + (4h/3)(2 f_n - f_{n-1} + 2 f_{n-2})``
* modifier           ``m = p - (112/121)(p_n - c_n)``  (``p_n - c_n = 0`` after a (re)start)
* corrector          ``c = [9 y_n - y_{n-2} + 3h (f(t_{n+1}, m) + 2 f_n - f_{n-1})] / 8``
* final value        ``y_{n+1} = c + (9/121)(p - c)``, then ``f_{n+1} = f(t_{n+1}, y_{n+1})``
* local error        ``(9/121)|p - c|``

started (and restarted) by three steps of Gill's method

    k1 = h f(t, y);  k2 = h f(t + h/2, y + k1/2)
    k3 = h f(t + h/2, y + (sqrt2 - 1)/2 k1 + (1 - 1/sqrt2) k2)
    k4 = h f(t + h, y - k2/sqrt2 + (1 + 1/sqrt2) k3)
    y+ = y + [k1 + (2 - sqrt2) k2 + (2 + sqrt2) k3 + k4] / 6

The recorded error estimate is relative: ``(9/121) max_i w_i |p_i - c_i| / max_i w_i |y_i|``
with unit weights ``w`` that make every state component a length (see ``error_weights``).
With ``NUMBA_DISABLE_JIT=1`` the same code runs as plain Python and gives identical results.
"""

from __future__ import annotations

import math

import numpy as np
from .._jit import njit

from .rhs import AMPLITUDE, DOUBLE, HALVE, KIND_LINEAR, KIND_MODEL, NONFINITE, OK, PITCH, linear_rhs, model_rhs, workspace

__all__ = ["run_fixed", "METHOD_GILL", "METHOD_HAMMING", "CARRY_ROWS"]

METHOD_GILL, METHOD_HAMMING = 0, 1
#: rows of the carried history: y_n, y_{n-1}, y_{n-2}, y_{n-3}, f_n, f_{n-1}, f_{n-2}, p_n - c_n
CARRY_ROWS = 8

SQ2 = math.sqrt(2.0)
GILL_A = (SQ2 - 1.0) / 2.0
GILL_B = 1.0 - 1.0 / SQ2
GILL_C = -1.0 / SQ2
GILL_D = 1.0 + 1.0 / SQ2
GILL_W2 = 2.0 - SQ2
GILL_W3 = 2.0 + SQ2
HAM_MOD = 112.0 / 121.0
HAM_FIN = 9.0 / 121.0


@njit(cache=True, inline="always", error_model="numpy")
def _shift(carry, znew, fnew, pc, n):
    for i in range(n):
        carry[3, i] = carry[2, i]
        carry[2, i] = carry[1, i]
        carry[1, i] = carry[0, i]
        carry[0, i] = znew[i]
        carry[6, i] = carry[5, i]
        carry[5, i] = carry[4, i]
        carry[4, i] = fnew[i]
        carry[7, i] = pc[i]


@njit(cache=True, error_model="numpy", compile_first=True)
def run_fixed(method, kind, arrays, yeq, h, n_steps, stride, loads, carry, nhist, out_z, out_err, k0,
              weights, tol, amp_limit, allow_double):
    """Advance ``n_steps`` fixed steps of size ``h`` (s) from the state in ``carry[0]``.

    Parameters
    ----------
    method : 0 (Gill) or 1 (Hamming)
    loads : (2, 2 n_steps + 1) thrust (N) and propeller spin (rad/s) at ``t0 + j h / 2``, or
        (2, 1) when they are constant
    carry : (8, n) history, updated in place; ``nhist`` levels of it are valid (0: only ``y_n``)
    out_z, out_err : sample arrays; samples are written at rows ``k0 + 1, k0 + 2, ...`` every
        ``stride`` steps (the caller wrote row ``k0``)
    weights : (n,) error weights; ``tol > 0`` turns on step-size control (status 4 halve,
        5 double, the latter only at a sample and when ``allow_double``)
    amp_limit : stop when a translation of the deviation exceeds it (m)

    Returns
    -------
    status, steps_done, nhist, samples_written
        On a stop (non-finite state, pitch guard, amplitude) the last accepted state is written as
        one extra sample when it does not fall on the sampling grid.

    All buffers (the Runge-Kutta stages, the predictor, the right-hand side's workspace) are
    allocated once per call, before the step loop; the loop allocates nothing.
    """
    n = carry.shape[1]
    buffers = np.empty((8, n))
    rot, jinv, ws = workspace(buffers[0])
    return _advance(method, kind, arrays, yeq, h, n_steps, stride, loads, carry, nhist, out_z, out_err, k0,
                    weights, tol, amp_limit, allow_double, buffers[0], buffers[1], buffers[2], buffers[3],
                    buffers[4], buffers[5], buffers[6], buffers[7], rot, jinv, ws)


@njit(cache=True, error_model="numpy", _nrt=False)
def _advance(method, kind, arrays, yeq, h, n_steps, stride, loads, carry, nhist, out_z, out_err, k0,
             weights, tol, amp_limit, allow_double, k1, k2, k3, k4, tmp, znew, fnew, pc, rot, jinv, ws):
    """The step loop of :func:`run_fixed` on buffers it allocated.

    Compiled without numba's runtime (no reference counting in the loop) and with the
    right-hand side inlined at its only call site: each step walks through its stages (Gill:
    three stage evaluations, Hamming: the modifier; then the new state), preparing the stage's
    state in ``tmp`` and evaluating f there. One call site keeps the compiled code small while
    the right-hand side is inlined (a call with its ~130 scalar arguments costs a quarter of an
    evaluation).
    """
    n = carry.shape[1]
    pos, kmat, cmat, flags, laws = arrays[0], arrays[1], arrays[2], arrays[3], arrays[4]
    par, minv, damp6, amat = arrays[5], arrays[6], arrays[7], arrays[8]
    vstart, vpar = arrays[9], arrays[10]
    bpos, bmat, bstart, bmode, mass6 = arrays[11], arrays[12], arrays[13], arrays[14], arrays[15]
    constant = loads.shape[1] == 1
    written = 0
    errmax = -1.0
    quiet = 0
    status = OK
    done = 0
    stop = False
    for step in range(n_steps):
        j = 2 * step
        gill = method == METHOD_GILL or nhist < 4
        final = 3 if gill else 1  # the stage that evaluates f at the new state
        stage = -1 if nhist == 0 else 0  # stage -1: f at the current state after a (re)start
        acc = OK
        err = -1.0
        while True:
            # the state of this stage into tmp, its load index and the buffer f goes to
            jl = j + 2
            dest = fnew
            if stage == -1:
                for i in range(n):
                    tmp[i] = carry[0, i]
                jl = j
            elif stage == final:
                if gill:
                    for i in range(n):
                        k4[i] = h * k4[i]
                        znew[i] = carry[0, i] + (k1[i] + GILL_W2 * k2[i] + GILL_W3 * k3[i] + k4[i]) / 6.0
                        pc[i] = 0.0
                else:
                    # corrector with f at the modifier (in k2), final value, local error
                    num = 0.0
                    den = 0.0
                    for i in range(n):
                        c = (9.0 * carry[0, i] - carry[2, i] + 3.0 * h * (k2[i] + 2.0 * carry[4, i] - carry[5, i])) / 8.0
                        znew[i] = c + HAM_FIN * (pc[i] - c)
                        pc[i] = pc[i] - c
                        num = max(num, weights[i] * abs(pc[i]))
                        den = max(den, weights[i] * abs(znew[i]))
                    err = HAM_FIN * num / max(den, 1e-300)
                if acc != OK:
                    status = acc
                    stop = True
                    break
                finite = True
                for i in range(n):
                    if not math.isfinite(znew[i]):
                        finite = False
                if not finite or not (err < math.inf):
                    status = NONFINITE
                    stop = True
                    break
                if tol > 0.0 and err > tol:
                    status = HALVE
                    stop = True
                    break
                for i in range(n):
                    tmp[i] = znew[i]
            elif gill:
                if stage == 0:
                    for i in range(n):
                        k1[i] = h * carry[4, i]
                        tmp[i] = carry[0, i] + 0.5 * k1[i]
                    jl = j + 1
                    dest = k2
                elif stage == 1:
                    for i in range(n):
                        k2[i] = h * k2[i]
                        tmp[i] = carry[0, i] + GILL_A * k1[i] + GILL_B * k2[i]
                    jl = j + 1
                    dest = k3
                else:
                    for i in range(n):
                        k3[i] = h * k3[i]
                        tmp[i] = carry[0, i] + GILL_C * k2[i] + GILL_D * k3[i]
                    dest = k4
            else:
                # Hamming: predictor (into pc) and modifier (into tmp)
                for i in range(n):
                    pc[i] = carry[3, i] + (4.0 * h / 3.0) * (2.0 * carry[4, i] - carry[5, i] + 2.0 * carry[6, i])
                    tmp[i] = pc[i] - HAM_MOD * carry[7, i]
                dest = k2
            # the one evaluation of the right-hand side
            if kind == KIND_LINEAR:
                st = linear_rhs(amat, tmp, dest)
            else:
                if constant:
                    jl = 0
                st = model_rhs(pos, kmat, cmat, flags, laws, vstart, vpar, par, minv, damp6, bpos, bmat, bstart,
                               bmode, mass6, yeq, tmp, loads[0, jl], loads[1, jl], dest, rot, jinv, ws)
            if stage == -1:
                if st != OK:
                    status = st
                    stop = True
                    break
                for i in range(n):
                    carry[4, i] = fnew[i]
                    carry[7, i] = 0.0
                nhist = 1
            elif stage == final:
                if st != OK:
                    status = st
                    stop = True
                break
            else:
                acc = max(acc, st)
            stage += 1
        if stop:
            break
        amp = 0.0
        if kind == KIND_MODEL:
            amp = max(abs(znew[0]), max(abs(znew[1]), abs(znew[2])))
        if amp > amp_limit:
            status = AMPLITUDE
            break
        _shift(carry, znew, fnew, pc, n)
        nhist = min(nhist + 1, 4)
        done = step + 1
        errmax = max(errmax, err)
        if tol > 0.0 and 0.0 <= err < tol / 64.0:
            quiet += 1
        elif err >= 0.0:
            quiet = 0
        if done % stride == 0:
            written += 1
            for i in range(n):
                out_z[k0 + written, i] = carry[0, i]
            out_err[k0 + written] = errmax if errmax >= 0.0 else math.nan
            errmax = -1.0
            if allow_double and tol > 0.0 and stride % 2 == 0 and quiet >= max(2 * stride, 20):
                status = DOUBLE
                break
    if (status == NONFINITE or status == PITCH or status == AMPLITUDE) and done % stride != 0:
        written += 1
        for i in range(n):
            out_z[k0 + written, i] = carry[0, i]
        out_err[k0 + written] = errmax if errmax >= 0.0 else math.nan
    return status, done, nhist, written
