"""Viscoelastic mounts in the time histories: the internal variables as states, and the step.

Each Prony term j of a viscoelastic mount i (:mod:`impstab.model.viscoelastic`, the one
realisation of the law; fitted laws use their stored fit) brings an internal 3-vector ``w_ij``
(hull frame, m) with ``tau_ij w_ij' = d_i - w_ij`` and the force ``-g_ij k_i (d_i - w_ij)`` on the
body (:mod:`impstab.dynamics.rhs`). They are appended to the 12 states of the body, in the
order of the mounts and of their terms, and every integrator sees the extended state: the
SciPy methods (``radau`` and ``lsoda`` are implicit or switch to implicit formulas, so a
relaxation time far below the step costs them nothing), and the fixed-step ``hamming`` and
``gill``, for which the internal variables are plain states.

Why plain states and not an exponential (recursive-convolution) update for the fixed-step
methods: the update ``w+ = e^(-h/tau) w + int e^(-(h-s)/tau) d(s) ds / tau`` is exact only for
a deflection known over the step; inside Gill's stages and Hamming's predictor-corrector it must
be interpolated from the stage or history values, and the usual linear interpolation (the
finite-element recursion) is second order: it would spoil the fourth order of both methods,
and an order-four exponential variant is a different integrator (exponential Runge-Kutta),
not the paper's. With plain states the methods stay what they are, of order four, and agree
with the linear analysis to their accuracy; their price is the explicit stability limit on the
real relaxation roots ``lambda = -rate`` of the augmented system (rate about ``1 / tau``, the
stiffening moving it), measured on ``z' = -z`` with :func:`~impstab.dynamics.integrators.integrate_linear`:
Hamming's method is unstable for ``h rate`` above 0.89, Gill's above 2.78 (the classical RK4
bound). Hence:

* the default step takes :data:`~impstab.dynamics.simulate.STEPS_PER_PERIOD` steps per
  ``2 pi / rate`` as well as per period of the fastest mode (``h rate = 0.157``): a default run is
  stable and accurate for any relaxation time, at the cost of many steps when ``tau`` is small;
* a given ``dt`` above :data:`EXPLICIT_LIMIT` ``/ rate`` (80 % of the measured bound) is refused
  with one line naming ``radau`` and ``lsoda`` (:func:`check_explicit_step`); between the
  accuracy limit and that bound it warns like an oversized step on a mode.

The roots come from the augmented first-order family of the stability analysis
(:class:`~impstab.linear.viscoelastic.ViscoelasticFamily`): one set of equations for both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..model.model import DOF_NAMES, Model

__all__ = ["AugmentedRoots", "augmented_roots", "check_explicit_step", "EXPLICIT_LIMIT", "smallest_relaxation",
           "step_limit"]

#: largest ``h x rate`` a fixed-step method is run at on a real relaxation root: 80 % of the
#: measured bound of its real stability interval (Hamming 0.89, Gill 2.78)
EXPLICIT_LIMIT = {"hamming": 0.7, "gill": 2.2}


@dataclass(frozen=True)
class AugmentedRoots:
    """What the augmented system's eigenvalues at one thrust say about the time step.

    Attributes
    ----------
    omega : float
        Largest ``|lambda|`` of an oscillating root (rad/s).
    mode : str
        Its dominant dof.
    rate : float
        Largest ``|lambda|`` of a real root (1/s): the fastest relaxation (0 when none).
    max_real : float
        ``max Re(lambda)`` (1/s): the linear growth rate at that thrust.
    """

    omega: float
    mode: str
    rate: float
    max_real: float


def augmented_roots(model: Model, thrust: float) -> AugmentedRoots:
    """Eigenvalues of the model's augmented first-order system at the static equilibrium at
    ``thrust`` (N), sorted into oscillating roots and real (relaxation) roots."""
    from ..linear.viscoelastic import ViscoelasticFamily

    from .beam_mounts import SIM_CUTOFF

    # massive beam mounts: their modes as the time histories keep them (beam_mounts.SIM_CUTOFF)
    e, a = ViscoelasticFamily(model, "equilibrium", cutoff=SIM_CUTOFF).matrices(np.array([float(thrust)]))
    vals, vecs = np.linalg.eig(np.linalg.solve(e[0], a[0]))
    scale = max(float(np.abs(vals).max()), 1e-300)
    real = np.abs(vals.imag) <= 1e-9 * scale
    omega, mode = 0.0, DOF_NAMES[0]
    if (~real).any():
        j = int(np.flatnonzero(~real)[np.argmax(np.abs(vals[~real]))])
        shape = np.abs(vecs[:6, j]) * np.sqrt(np.diag(model.mass_matrix))
        omega, mode = float(abs(vals[j])), DOF_NAMES[int(np.argmax(shape))]
    rate = float(np.abs(vals[real]).max()) if real.any() else 0.0
    return AugmentedRoots(omega, mode, rate, float(vals.real.max()))


def smallest_relaxation(model: Model) -> tuple[int, float]:
    """``(mount index, tau (s))`` of the shortest relaxation time of the model's Prony terms."""
    found = [(float(m.viscoelastic.relaxation_times.min()), i) for i, m in enumerate(model.mounts)
             if m.viscoelastic is not None and m.viscoelastic.n_terms]
    tau, i = min(found)
    return i, tau


def check_explicit_step(model: Model, integrator: str, dt: float, rate: float, field: str = "dt") -> None:
    """Refuse a fixed step ``dt`` (s) of ``integrator`` beyond its stability limit on the fastest
    relaxation root ``rate`` (1/s) of the viscoelastic internal variables (one line, naming the
    stiff alternatives)."""
    limit = EXPLICIT_LIMIT.get(integrator)
    if limit is None or rate <= 0.0 or dt * rate <= limit:
        return
    i, tau = smallest_relaxation(model)
    raise ModelError(field, dt, (
        f"the explicit {integrator} step is unstable on the relaxation of the viscoelastic internal variables "
        f"(fastest rate {rate:.4g} 1/s; mounts[{i}].viscoelastic has tau = {tau:.4g} s) for dt x rate above {limit:g}: "
        f"use dt <= {limit / rate:.4g} s, or integrator radau or lsoda (implicit, for short relaxation times)"))


def step_limit(omega: float, rate: float, steps_per_period: int) -> float:
    """The default fixed step (s): ``steps_per_period`` steps per period ``2 pi / omega`` of the
    fastest mode and per ``2 pi / rate`` of the fastest relaxation."""
    return 2 * math.pi / (steps_per_period * max(omega, rate))
