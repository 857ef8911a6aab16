"""Critical thrust of many models at once (design studies).

All designs of a batch are problems of one call of the stability engine
(:mod:`impstab.linear.engine`): the same scan, bubble searches and exact refinement as
:func:`impstab.critical_thrust`, compiled, over the stack of designs. Designs assembled in bulk
(:class:`AffineDesign`: matrices of an undamped affine design; :class:`AffineStack`: many
such designs as stacked arrays) need no model at all. A design
with compressible fluid loading goes through :func:`impstab.critical_thrust` itself (its
coefficients follow the onset frequency). Failures are per design: a model whose analysis
raises gets a status and a message.
"""

from .api import critical_thrust_batch
from .results import KINDS, STATUSES, AffineDesign, AffineStack, BatchCriticalThrust

__all__ = ["AffineDesign", "AffineStack", "BatchCriticalThrust", "critical_thrust_batch", "KINDS", "STATUSES"]
