"""Nonlinear time simulation of the propulsor on its mounts under follower thrust (THEORY 7, 8).

``simulate(model, thrust, duration, integrator="hamming")`` integrates the rigid-body equations
with the exact mount force law from the nonlinear static equilibrium plus a perturbation, and
returns a :class:`SimulationResult`. Integrators: Hamming's modified predictor-corrector (the
paper's), Gill's RK4, and SciPy's ``solve_ivp`` methods (``dop853``, ``rk45``, ``radau``,
``lsoda``).

:class:`NonlinearSystem` gives other analyses (the Hopf coefficient, periodic orbits) the same
compiled right-hand side on batches of real or complex states, its exact Jacobian and the
static equilibrium state.
"""

from .growth import GrowthFit, classify, fit_run
from .integrators import INTEGRATORS, Integrator, register
from .loading import Constant, Perturbation, Ramp, Step, ThrustHistory, UserThrust
from .result import SimulationResult
from .simulate import StepSizeWarning, simulate
from .system import NonlinearSystem

__all__ = [
    "simulate", "SimulationResult", "Perturbation", "ThrustHistory", "Constant", "Ramp", "Step", "UserThrust",
    "GrowthFit", "fit_run", "classify", "INTEGRATORS", "Integrator", "register", "StepSizeWarning",
    "NonlinearSystem",
]
