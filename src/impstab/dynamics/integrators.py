"""Integrators of a time simulation, in a small registry (in the spirit of SciPy's ``solve_ivp``
solver classes).

* ``hamming``: Hamming's modified predictor-corrector (the paper's integrator), fixed step,
  started by three steps of Gill's RK4, local error estimate recorded along the run; with
  ``tol`` the step halves (and restarts from the last sample) when the relative local error
  exceeds ``tol`` and doubles again when it stays below ``tol / 64``;
* ``gill``: Gill's fourth-order Runge-Kutta alone, fixed step;
* ``dop853``, ``rk45``, ``radau``, ``lsoda``: :func:`scipy.integrate.solve_ivp` on the compiled
  right-hand side, adaptive steps with ``rtol`` and ``atol``; ``radau`` and ``lsoda`` (the stiff
  methods, for viscoelastic mounts with short relaxation times) get the exact Jacobian by
  complex step through the same compiled code.

Each integrator runs a :class:`Problem` and returns a :class:`RawRun`. Register a new one with
:func:`register`.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass
from typing import Callable, ClassVar

import numpy as np
from numpy.typing import NDArray

from ..errors import ModelError
from .kernels import CARRY_ROWS, METHOD_GILL, METHOD_HAMMING, run_fixed
from .rhs import AMPLITUDE, DOUBLE, HALVE, NONFINITE, OK, PITCH, rhs_batch
from .system import COMPLEX_STEP, DynamicSystem, linear_dynamics

__all__ = ["Problem", "RawRun", "Integrator", "INTEGRATORS", "register", "get_integrator", "integrate_linear"]

Array = NDArray[np.float64]

#: smallest step of the step-size control relative to the initial step
MIN_STEP_RATIO = 2.0**-20


@dataclass(frozen=True, eq=False)
class Problem:
    """A run: system, equilibrium offset ``yeq``, initial deviation ``z0`` and sampling.

    The run covers ``n_samples`` sampling intervals of ``stride`` steps of ``h`` (s) each from
    ``t0``; ``loads(t)`` gives thrust (N) and spin (rad/s) as a ``(2, len(t))`` array.
    """

    system: DynamicSystem
    yeq: Array
    z0: Array
    t0: float
    h: float
    stride: int
    n_samples: int
    loads: Callable[[Array], Array]
    weights: Array
    amp_limit: float
    pitch_limit: float
    h_max: float
    tol: float = 0.0
    rtol: float = 1e-8
    atol: Array | None = None
    constant_load: tuple[float, float] | None = None

    @property
    def sample(self) -> float:
        return self.h * self.stride

    @property
    def t_end(self) -> float:
        return self.t0 + self.n_samples * self.sample


@dataclass(frozen=True, eq=False)
class RawRun:
    """What an integrator computed: sample times (s), deviations ``z`` and error estimates.

    ``steps`` is -1 for the adaptive SciPy methods (they report right-hand side evaluations only).
    """

    time: Array
    z: Array
    error: Array | None
    completed: bool
    reason: str | None
    stop_time: float | None
    steps: int
    rhs_evals: int
    restarts: int
    final_step: float
    wall_time: float


INTEGRATORS: dict[str, type["Integrator"]] = {}


def register(cls: type["Integrator"]) -> type["Integrator"]:
    """Class decorator adding an integrator to :data:`INTEGRATORS` under ``cls.name``."""
    INTEGRATORS[cls.name] = cls
    return cls


def get_integrator(name: str) -> "Integrator":
    """The integrator registered as ``name``."""
    key = str(name).lower()
    if key not in INTEGRATORS:
        raise ModelError("integrator", name, f"must be one of {sorted(INTEGRATORS)}")
    return INTEGRATORS[key]()


def _reason(status: int, t: float, problem: Problem) -> str:
    if status == NONFINITE:
        return f"the state became non-finite (blow-up) after t = {t:.6g} s"
    if status == PITCH:
        return (f"pitch angle reached the guard |theta| = {math.degrees(problem.pitch_limit):.4g} deg "
                f"(z-y-x Euler angles are singular at 90 deg) at t = {t:.6g} s")
    if status == AMPLITUDE:
        return f"displacement of A exceeded {problem.amp_limit:.6g} m (blow-up) at t = {t:.6g} s"
    return f"stopped at t = {t:.6g} s"


class Integrator:
    """Base class: ``name``, ``fixed_step`` and :meth:`run`."""

    name: ClassVar[str] = ""
    fixed_step: ClassVar[bool] = True
    description: ClassVar[str] = ""

    def run(self, problem: Problem, progress: Callable[[float], None] | None = None) -> RawRun:
        raise NotImplementedError


class _FixedStep(Integrator):
    method: ClassVar[int] = METHOD_HAMMING
    #: sampling intervals per compiled call (progress is reported between calls)
    chunk_steps: ClassVar[int] = 20000

    def run(self, problem: Problem, progress=None) -> RawRun:
        sysm = problem.system
        n, ns = sysm.n_states, problem.n_samples
        out_z = np.zeros((ns + 2, n))
        out_err = np.full(ns + 2, np.nan)
        times = np.zeros(ns + 2)
        out_z[0] = problem.z0
        times[0] = problem.t0
        carry = np.zeros((CARRY_ROWS, n))
        carry[0] = problem.z0
        h, stride, nhist = problem.h, problem.stride, 0
        tol = problem.tol if self.method == METHOD_HAMMING else 0.0
        k, steps, restarts = 0, 0, 0
        seg_t, seg_k, seg_steps = problem.t0, 0, 0  # start of the current constant-step segment
        reason, stop_time, completed = None, None, True
        start = _time.perf_counter()
        yeq = np.ascontiguousarray(problem.yeq)
        while k < ns:
            ks = min(max(1, self.chunk_steps // stride), ns - k)
            n_steps = ks * stride
            t_chunk = seg_t + (k - seg_k) * stride * h
            if problem.constant_load is not None:  # one column (building 2 n_steps + 1 of them is ~10 %)
                loads = np.array(problem.constant_load, dtype=float).reshape(2, 1)
            else:
                loads = np.ascontiguousarray(problem.loads(t_chunk + 0.5 * h * np.arange(2 * n_steps + 1)))
            allow_double = 2.0 * h <= problem.h_max * (1 + 1e-12)
            status, done, nhist, written = run_fixed(
                self.method, sysm.kind, sysm.arrays, yeq, h, n_steps, stride, loads, carry, nhist,
                out_z, out_err, k, problem.weights, tol, problem.amp_limit, allow_double,
            )
            steps += done
            seg_steps += done
            regular = done // stride
            times[k + 1:k + 1 + regular] = seg_t + (k + 1 - seg_k + np.arange(regular)) * stride * h
            if status == OK or status == DOUBLE:
                k += written
                if status == DOUBLE:
                    restarts += 1
                    seg_t, seg_k, seg_steps = times[k], k, 0
                    h, stride, nhist = 2.0 * h, stride // 2, 0
                    carry[0] = out_z[k]
            elif status == HALVE:
                # the first Hamming step also vouches for the three unchecked Gill steps before it:
                # when it fails, the whole segment restarts
                k = seg_k if seg_steps < 4 else k + regular
                restarts += 1
                if h / 2 < problem.h * MIN_STEP_RATIO:
                    completed, stop_time = False, float(times[k])
                    reason = f"step size underflow below {h / 2:.3g} s at t = {stop_time:.6g} s"
                    break
                seg_t, seg_k, seg_steps = times[k], k, 0
                h, stride, nhist = 0.5 * h, 2 * stride, 0
                carry[0] = out_z[k]
            else:
                if written > regular:
                    times[k + written] = t_chunk + done * h
                k += written
                completed, stop_time = False, float(times[k])
                reason = _reason(status, stop_time, problem)
                break
            if progress is not None:
                progress(min(1.0, k / ns))
        wall = _time.perf_counter() - start
        err = out_err[:k + 1] if self.method == METHOD_HAMMING else None
        starts = restarts + 1
        evals = 4 * steps + starts if self.method == METHOD_GILL else 2 * steps + 7 * starts
        return RawRun(times[:k + 1].copy(), out_z[:k + 1].copy(), None if err is None else err.copy(),
                      completed, reason, stop_time, steps, evals, restarts, h, wall)


@register
class Hamming(_FixedStep):
    name = "hamming"
    method = METHOD_HAMMING
    description = "Hamming's modified predictor-corrector, fixed step, Gill RK4 start"


@register
class Gill(_FixedStep):
    name = "gill"
    method = METHOD_GILL
    description = "Gill's fourth-order Runge-Kutta, fixed step"


class _SolveIvp(Integrator):
    fixed_step = False
    scipy_method: ClassVar[str] = "RK45"
    #: the implicit methods get the exact Jacobian (complex step through the compiled
    #: right-hand side, all columns in one compiled call) instead of SciPy's finite differences
    implicit: ClassVar[bool] = False

    def run(self, problem: Problem, progress=None) -> RawRun:
        from scipy.integrate import solve_ivp

        sysm = problem.system
        kind, arrays = sysm.kind, sysm.arrays
        yeq = np.ascontiguousarray(problem.yeq)
        n = sysm.n_states

        const = problem.constant_load

        def loads_at(t):
            if const is None:
                ld = problem.loads(np.array([t]))
                return float(ld[0, 0]), float(ld[1, 0])
            return const

        one = np.zeros(1, dtype=np.int64)

        def fun(t, z):
            thrust, spin = loads_at(t)
            out = np.empty((1, n))  # a new array each call: solve_ivp keeps the ones it is given
            rhs_batch(kind, arrays, yeq, np.ascontiguousarray(z, dtype=float).reshape(1, n), thrust, spin, out, one)
            return out[0]

        jac = None
        if self.implicit:
            eye = 1j * COMPLEX_STEP * np.eye(n)
            dz = np.empty((n, n), dtype=complex)
            status = np.zeros(n, dtype=np.int64)

            def jac(t, z):
                thrust, spin = loads_at(t)
                probe = np.ascontiguousarray(np.asarray(z, dtype=float)[None, :] + eye)
                rhs_batch(kind, arrays, yeq, probe, thrust, spin, dz, status)
                return dz.imag.T / COMPLEX_STEP

        events = []
        if kind == 0:
            def pitch(t, z):
                return problem.pitch_limit - abs(yeq[4] + z[4])

            def amplitude(t, z):
                return problem.amp_limit - np.max(np.abs(z[:3]))

            pitch.terminal = amplitude.terminal = True
            events = [pitch, amplitude]
        t_eval = problem.t0 + problem.sample * np.arange(problem.n_samples + 1)
        t_eval[-1] = min(t_eval[-1], problem.t_end)
        atol = problem.atol if problem.atol is not None else 1e-12
        start = _time.perf_counter()
        sol = solve_ivp(fun, (problem.t0, problem.t_end), problem.z0, method=self.scipy_method, t_eval=t_eval,
                        rtol=problem.rtol, atol=atol, max_step=problem.h_max if problem.h_max > 0 else np.inf,
                        events=events or None, **({"jac": jac} if jac is not None else {}))
        wall = _time.perf_counter() - start
        times, zs = sol.t, sol.y.T
        completed, reason, stop_time = sol.status == 0, None, None
        if sol.status == 1:
            which = 0 if len(sol.t_events[0]) else 1
            stop_time = float(sol.t_events[which][0])
            times = np.append(times, stop_time)
            zs = np.vstack([zs, sol.y_events[which][0]])
            reason = _reason(PITCH if which == 0 else AMPLITUDE, stop_time, problem)
        elif sol.status < 0:
            stop_time = float(times[-1]) if len(times) else problem.t0
            reason = f"{self.name} failed after t = {stop_time:.6g} s: {sol.message}"
        if progress is not None:
            progress(1.0)
        return RawRun(np.asarray(times, float), np.ascontiguousarray(zs), None, completed, reason, stop_time,
                      -1, int(sol.nfev), 0, math.nan, wall)


@register
class DOP853(_SolveIvp):
    name = "dop853"
    scipy_method = "DOP853"
    description = "solve_ivp DOP853 (explicit Runge-Kutta 8(5,3))"


@register
class RK45(_SolveIvp):
    name = "rk45"
    scipy_method = "RK45"
    description = "solve_ivp RK45 (Dormand-Prince 5(4))"


@register
class Radau(_SolveIvp):
    name = "radau"
    scipy_method = "Radau"
    implicit = True
    description = "solve_ivp Radau (implicit Runge-Kutta, order 5)"


@register
class LSODA(_SolveIvp):
    name = "lsoda"
    scipy_method = "LSODA"
    implicit = True
    description = "solve_ivp LSODA (Adams / BDF switching)"


def integrate_linear(amat, z0, h: float, n_steps: int, integrator: str = "hamming", stride: int = 1,
                     tol: float = 0.0, rtol: float = 1e-10) -> RawRun:
    """Run an integrator on the linear system ``z' = A z`` (the same compiled kernels as the model;
    used to verify the integration formulas on oscillators)."""
    system = linear_dynamics(amat)
    n = system.n_states
    n_samples = -(-int(n_steps) // int(stride))
    problem = Problem(
        system=system, yeq=np.zeros(n), z0=np.asarray(z0, dtype=float), t0=0.0, h=float(h), stride=int(stride),
        n_samples=n_samples, loads=lambda t: np.zeros((2, np.size(t))), weights=np.ones(n), amp_limit=np.inf,
        pitch_limit=math.pi / 2, h_max=float(h) if INTEGRATORS[integrator].fixed_step else 0.0, tol=tol, rtol=rtol,
        atol=np.full(n, 1e-14),
    )
    return get_integrator(integrator).run(problem)
