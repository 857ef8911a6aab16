"""The stability engine: first loss of stability of one-parameter families, over a stack of problems.

One implementation serves a single model (a stack of one), the generic
:func:`impstab.critical_load`, and design studies (:func:`impstab.linear.batch.critical_thrust_batch`):

* :mod:`~impstab.linear.engine.problems` -- a family (second order ``M q'' + (D + G) q' + K(p) q = 0``
  or first order ``E x' = A(p) x``, affine or not) as the operator whose spectrum decides stability;
* :mod:`~impstab.linear.engine.spectra` -- its eigenvalues and decompositions at a load
  (decoupled blocks, compiled small-matrix routines, LAPACK for large operators);
* :mod:`~impstab.linear.engine.scan` -- the scan with the bubble searches;
* :mod:`~impstab.linear.engine.cluster` -- the cluster going unstable, followed across a bracket by
  its spectral projector, and its exact indicator;
* :mod:`~impstab.linear.engine.roots` -- root finding as steps (Newton on exact derivatives, Brent);
* :mod:`~impstab.linear.engine.refine` -- the exact refinement of each bracket and the onset values;
* :mod:`~impstab.linear.engine.solve` -- the Python entry point and its outcomes.
"""

from .problems import Problem, first_order_problem, second_order_problem
from .solve import Crossing, Outcome, StackOutcome, solve, solve_affine
from .tolerances import FLOOR, TOL_CLUSTER, TOL_DUPLICATE, TOL_MARGINAL, TOL_UNSTABLE

__all__ = [
    "Problem", "first_order_problem", "second_order_problem", "Crossing", "Outcome", "StackOutcome", "solve",
    "solve_affine",
    "FLOOR", "TOL_CLUSTER", "TOL_DUPLICATE", "TOL_MARGINAL", "TOL_UNSTABLE",
]
