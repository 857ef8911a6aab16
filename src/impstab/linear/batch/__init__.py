"""Critical thrust of many models at once (design studies).

The steps of the engine in :mod:`impstab.linear.critical` are run for all designs together:

1. the thrust scan: the grid operators of all designs (``M^-1 K`` or the state matrix,
   THEORY 5) are classified in a few stacked calls of compiled eigenvalue routines -- block by
   block where a design's operators decouple (:mod:`impstab.linear.blocks`: closed forms for
   the planes of a symmetric layout), the small-matrix QR (:mod:`impstab.linear.small_eig`)
   otherwise -- with the engine's own classification (same tolerances, same bubble
   indicators), chunk by chunk, each design stopping where its scan would;
2. the bracket logic of the scan, vectorized across designs; the bubble searches (scipy's
   bounded Brent minimisation, which the engine uses, ported step for step) run in lockstep so
   that each step is one stacked classification; the ``attracting`` test is vectorized for
   affine undamped designs;
3. the exact refinement, vectorized for affine undamped designs (the common case: symmetric
   layouts, or the classical linearization): the root of the cluster discriminant by bracketed
   Newton steps to machine precision, with the eigen-decompositions block by block (closed
   forms, or compiled QR and inverse iteration: :mod:`impstab.linear.small_eigvec`). Where the
   cluster is ambiguous or the indicator does not change sign, the bracket is halved or stepped
   back as the engine does, still vectorized. A design that leaves this path (unstable at zero
   thrust, an exactly defective point), and every damped, gyroscopic or rotating-equilibrium
   design, is refined by its own engine, exactly as in :func:`impstab.critical_thrust`.

The values agree with :func:`impstab.critical_thrust` to rounding. A design with compressible
fluid loading goes through :func:`impstab.critical_thrust` itself. Failures are per design: a
model whose analysis raises gets a status and a message.
"""

from .api import critical_thrust_batch
from .jobs import KINDS, STATUSES, AffineDesign, BatchCriticalThrust

__all__ = ["AffineDesign", "BatchCriticalThrust", "critical_thrust_batch", "KINDS", "STATUSES"]
