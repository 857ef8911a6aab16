"""The periodic boundary-value problem on one mesh: residual, sparse Jacobian, Newton, tangent.

Unknowns ``U = (X, T, p)``: the ``N m`` nodal states (flattened), the period and the parameter.
Equations: the ``N m n`` collocation equations, the integral phase condition
``int_0^1 <x(tau) - x_ref(tau), x_ref'(tau)> dtau = 0`` (``x_ref`` the previous cycle: the new one
is the shift of it that moves least) and one constraint: pseudo-arclength
``<U - U_0, V_0> = ds`` or a fixed parameter ``p = p*``. Inner products are the weighted ones of
:class:`Weights`. Newton's linear systems are solved by condensation of parameters
(:mod:`.condensed`); :meth:`OrbitProblem.matrix` assembles the full sparse Jacobian for checks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from .collocation import Profile, interval_nodes, node_weights, scheme
from .derivatives import jacobians, parameter_derivatives
from .condensed import Condensation
from .floquet import FloquetMultipliers, chain_multipliers
from .system import DynamicalSystem

__all__ = ["Weights", "OrbitProblem", "Solution", "NEWTON_TOLERANCE", "NEWTON_ITERATIONS"]

Array = NDArray[np.float64]

#: Newton converged when the scaled step is below this (relative)
NEWTON_TOLERANCE = 1e-10
NEWTON_ITERATIONS = 12
#: a chord correction (reusing the last factorized Jacobian) is kept while successive steps shrink
#: by this factor or more; otherwise the next correction takes a fresh Jacobian. The converged
#: cycle always gets a fresh Jacobian (its Floquet multipliers and tangent).
CHORD_RATE = 0.1
#: converged as well when the residual stagnates below STAGNANT_RESIDUAL of its terms and the
#: scaled step is below STAGNATION
STAGNANT_RESIDUAL = 1e-9
STAGNATION = 1e-6


@dataclass(frozen=True)
class Weights:
    """Scales of the weighted inner product ``<U, V>`` (states, period, parameter)."""

    state: Array
    period: float
    parameter: float


@dataclass(frozen=True, eq=False)
class Solution:
    """A converged cycle on its mesh, with what the continuation needs from it."""

    profile: Profile
    period: float
    parameter: float
    vector: Array
    blocks: Array
    condensed: Condensation
    phase: Array
    iterations: int
    residual: float

    @property
    def mesh(self) -> Array:
        return self.profile.mesh


class OrbitProblem:
    """Collocation of ``B x' = T f(x, p)`` on a fixed mesh with ``intervals`` of ``degree``."""

    def __init__(self, system: DynamicalSystem, mesh: Array, degree: int, weights: Weights) -> None:
        self.system = system
        self.mesh = np.asarray(mesh, dtype=float)
        self.degree = int(degree)
        self.scheme = scheme(self.degree)
        self.weights = weights
        self.N = self.mesh.size - 1
        self.m = self.degree
        self.n = system.dimension
        self.nx = self.N * self.m * self.n
        self.size = self.nx + 2
        self.h = np.diff(self.mesh)
        self.index = interval_nodes(self.N, self.m)
        w_node = node_weights(self.mesh, self.scheme)
        self.inner_weights = np.concatenate([
            (w_node[:, None] / weights.state[None, :] ** 2).reshape(-1),
            [1.0 / weights.period ** 2, 1.0 / weights.parameter ** 2]])
        n, m, N = self.n, self.m, self.N
        rows = ((np.arange(N)[:, None] * m + np.arange(m)[None, :])[:, :, None, None, None] * n
                + np.arange(n)[None, None, None, :, None])
        cols = self.index[:, None, :, None, None] * n + np.arange(n)[None, None, None, None, :]
        shape = (N, m, m + 1, n, n)
        self._rows = np.broadcast_to(rows, shape).reshape(-1)
        self._cols = np.broadcast_to(cols, shape).reshape(-1)
        self._col_rows = np.arange(self.nx)

    # ------------------------------------------------------------------ layout
    def pack(self, profile: Profile, period: float, parameter: float) -> Array:
        return np.concatenate([profile.nodes.reshape(-1), [period, parameter]])

    def profile(self, u: Array) -> Profile:
        return Profile(self.mesh, u[: self.nx].reshape(self.N * self.m, self.n), self.degree)

    def inner(self, u: Array, v: Array) -> float:
        return float(np.sum(self.inner_weights * u * v))

    def norm(self, u: Array) -> float:
        return float(np.sqrt(max(self.inner(u, u), 0.0)))

    def phase_row(self, ref: Profile) -> Array:
        """Coefficients of ``int <x, x_ref'> dtau`` in the nodal values, ``(nx,)``."""
        d = ref.node_derivatives()                                     # (N, m+1, n)
        coef = self.h[:, None, None] * self.scheme.weights[None, :, None] * d
        row = np.zeros((self.N * self.m, self.n))
        np.add.at(row, self.index, coef)
        return row.reshape(-1)

    # ------------------------------------------------------------------ assembly
    def evaluate(self, u: Array, need_jacobian: bool = True):
        """Collocation residual ``(nx,)`` and, when asked, the blocks and the T and p columns."""
        prof = self.profile(u)
        period, par = float(u[-2]), float(u[-1])
        xc, dxc = prof.collocation_states()                            # (N, m, n)
        pts = xc.reshape(-1, self.n)
        f = self.system.evaluate(pts, par).real.reshape(self.N, self.m, self.n)
        mass = self.system.mass
        hh = self.h[:, None, None]
        lhs = dxc @ mass.T
        res = (lhs - period * hh * f).reshape(-1)
        self.residual_scale = float(np.max(np.abs(lhs))) + float(np.max(np.abs(period * hh * f)))
        if not need_jacobian:
            return res, None, None, None
        jac = jacobians(self.system, pts, par).reshape(self.N, self.m, self.n, self.n)
        fp, _ = parameter_derivatives(self.system, pts, par)
        sch = self.scheme
        blocks = (sch.derivative[None, :, :, None, None] * mass[None, None, None, :, :]
                  - (period * self.h)[:, None, None, None, None] * sch.value[None, :, :, None, None]
                  * jac[:, :, None, :, :])
        col_t = -(hh * f).reshape(-1)
        col_p = -(period * hh * fp.reshape(self.N, self.m, self.n)).reshape(-1)
        return res, blocks, col_t, col_p

    def matrix(self, blocks: Array, col_t: Array, col_p: Array, phase: Array, last: Array) -> sp.csc_matrix:
        """The bordered Jacobian: collocation rows, the phase row, the constraint row ``last``."""
        nx = self.nx
        rows = np.concatenate([self._rows, self._col_rows, self._col_rows, np.full(nx, nx),
                               np.full(self.size, nx + 1)])
        cols = np.concatenate([self._cols, np.full(nx, nx), np.full(nx, nx + 1), np.arange(nx),
                               np.arange(self.size)])
        data = np.concatenate([blocks.reshape(-1), col_t, col_p, phase, last])
        return sp.csc_matrix((data, (rows, cols)), shape=(self.size, self.size))

    # ------------------------------------------------------------------ Newton
    def solve(self, guess: Array, ref: Profile, constraint: tuple[str, Array, float, Array | None],
              tol: float = NEWTON_TOLERANCE, max_iter: int = NEWTON_ITERATIONS) -> Solution | None:
        """Newton's method from ``guess``; None when it does not converge.

        ``constraint`` is ``("arclength", u0, ds, v0)``: ``<U - u0, v0> = ds``, or
        ``("parameter", None, p_star, None)``: ``p = p_star``.
        """
        kind, u0, target, v0 = constraint
        u = np.array(guess, dtype=float)
        phase = self.phase_row(ref)
        phase_full = np.concatenate([phase, [0.0, 0.0]])
        ref_vec = ref.nodes.reshape(-1)
        if kind == "arclength":
            last = self.inner_weights * v0
        else:
            last = np.zeros(self.size)
            last[-1] = 1.0
        scale = np.concatenate([np.tile(self.weights.state, self.N * self.m), [self.weights.period,
                                                                                 self.weights.parameter]])
        converged = False
        prev_res = np.inf
        border = np.stack([phase_full, last])
        cond, lu = None, None
        chord = False          # the next correction reuses the last factorization
        prev_small = np.inf
        newton = 0             # corrections with a fresh Jacobian
        for it in range(max_iter + 1):
            fresh = converged or not chord or cond is None
            try:
                res, blocks, col_t, col_p = self.evaluate(u, need_jacobian=fresh)
            except (FloatingPointError, OverflowError, ValueError):
                return None
            res_norm = float(np.max(np.abs(res)))
            g_phase = float(phase @ (u[: self.nx] - ref_vec))
            g_last = float(last @ (u - u0)) - target if kind == "arclength" else float(u[-1] - target)
            full = np.concatenate([res, [g_phase, g_last]])
            if not np.all(np.isfinite(full)):
                return None
            if fresh:
                cond, lu = Condensation(blocks, col_t, col_p), None
                jac_blocks = blocks
            if converged:
                return Solution(self.profile(u), float(u[-2]), float(u[-1]), u, jac_blocks, cond, phase, newton,
                                float(np.max(np.abs(res))))
            if it == max_iter:
                return None
            try:
                if lu is None:
                    lu = cond.factor(border)
                step = cond.solve(-res, border, -np.array([g_phase, g_last]), lu=lu)
            except (RuntimeError, np.linalg.LinAlgError):
                return None
            if not np.all(np.isfinite(step)):
                return None
            newton += int(fresh)
            u = u + step
            if u[-2] <= 0:
                return None
            size = max(1.0, float(np.max(np.abs(u / scale))))
            small = float(np.max(np.abs(step / scale)))
            # chord steps (the Jacobian of an earlier iterate) while they contract by CHORD_RATE or
            # better: then the error left after a step is below CHORD_RATE / (1 - CHORD_RATE) of it
            chord = fresh or small <= CHORD_RATE * prev_small
            prev_small = small
            if small <= tol * size:
                converged = True
            elif it >= 2 and small <= STAGNATION * size and res_norm <= STAGNANT_RESIDUAL * self.residual_scale \
                    and res_norm >= 0.25 * prev_res:
                # the residual no longer decreases, at the level of rounding, and the steps only stir
                # it: an ill-conditioned cycle (tiny amplitude next to the Hopf point) is as
                # converged as it gets
                converged = True
            prev_res = res_norm
        return None

    def tangent(self, sol: Solution, ref: Profile, orient: Array) -> Array:
        """Unit tangent of the branch at ``sol`` (weighted norm), oriented along ``orient``."""
        phase_full = np.concatenate([sol.phase, [0.0, 0.0]])
        v = sol.condensed.solve(np.zeros(self.nx), np.stack([phase_full, self.inner_weights * orient]),
                                np.array([0.0, 1.0]))
        v = v / self.norm(v)
        return v if self.inner(v, orient) >= 0 else -v

    def floquet(self, sol: Solution) -> FloquetMultipliers:
        d = sol.profile.derivative(np.array([0.0]))[0]
        return chain_multipliers(sol.condensed.a, sol.condensed.b, d, self.weights.state)
