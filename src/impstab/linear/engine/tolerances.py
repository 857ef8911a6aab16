"""The stability engine's tolerances (THEORY 5), one definition for every part of it.

The classification thresholds only bracket an onset; the onset itself is refined on exact
indicators to rounding (:mod:`impstab.linear.engine.refine`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["TOL_UNSTABLE", "TOL_MARGINAL", "FLOOR", "TOL_CLUSTER", "TOL_DUPLICATE", "TOL_COPIES", "TOL_REPEATED", "EPS"]

#: relative size of an imaginary part (of s) or a real part (of lambda) that counts as unstable
TOL_UNSTABLE = 1e-7
#: real part (relative to the eigenvalue) below which a branch counts as marginal (on the axis)
TOL_MARGINAL = 1e-11
#: rounding floor, relative to the spectral radius
FLOOR = 1e3 * float(np.finfo(float).eps)
#: relative distance within which eigenvalues belong to one cluster
TOL_CLUSTER = 1e-6
#: relative gap below which two real s are symmetric duplicates, not an approach
TOL_DUPLICATE = 1e-9
#: relative spread within which the upper half of a first-order cluster of more than one pair is
#: copies of one eigenvalue (identical planes), refined by Newton on their mean growth
TOL_COPIES = 1e-9
#: relative distance (to the largest magnitude) within which two eigenvalues of one decomposition
#: are one repeated eigenvalue, whose eigenvectors are one basis of its eigenspace among many
TOL_REPEATED = 1e-8
#: machine epsilon of float64
EPS = float(np.finfo(float).eps)
