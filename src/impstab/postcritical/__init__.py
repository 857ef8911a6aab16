"""Post-critical behaviour of ``B x' = f(x, p)``: Hopf normal form, periodic orbits, Floquet multipliers.

The generic machinery, for any first-order system (optionally with a constant invertible mass
matrix ``B``):

* :class:`DynamicalSystem`: the right-hand side and its calling convention (single states or
  batches ``(N, n)``), optional analytic derivatives, names, units and scales;
* :func:`hopf_analysis` -> :class:`HopfPoint`: the onset refined, the critical pair, the first
  Lyapunov coefficient in Kuznetsov's normalisation, the crossing speed, the label
  (supercritical, subcritical, degenerate with the reason) and the normal-form cycle;
* :func:`continue_cycles` -> :class:`CycleBranch`: periodic orbits by orthogonal collocation on
  an adaptive mesh, pseudo-arclength continuation through folds, Floquet multipliers, folds,
  period doublings and torus points located, cycles at requested parameter values;
* :func:`find_cycle`, :func:`cycle_at`, :func:`cycles_at`: single cycles;
* :mod:`.derivatives`: exact Jacobians (complex step) and multilinear forms (Cauchy circle);
* :func:`propulsor_postcritical` -> :class:`PostcriticalResult`: the same machinery on a
  propulsor model's nonlinear equations of motion, with the thrust as the parameter.
"""

from .collocation import Profile
from .continuation import continue_cycles, cycle_at, cycles_at, find_cycle
from .derivatives import Forms, check_derivatives, jacobians
from .hopf import HopfPoint, hopf_analysis
from .result import Cycle, CycleBranch, SpecialPoint
from .propulsor import propulsor_postcritical
from .propulsor_result import PostcriticalResult
from .system import DynamicalSystem

__all__ = ["DynamicalSystem", "HopfPoint", "hopf_analysis", "continue_cycles", "find_cycle", "cycle_at",
           "cycles_at", "Cycle", "CycleBranch", "SpecialPoint", "Profile", "Forms", "jacobians",
           "check_derivatives", "propulsor_postcritical", "PostcriticalResult"]
