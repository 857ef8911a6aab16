"""Composite Gauss-Kronrod (G10/K21) rules on fixed panel layouts.

Every integral in :mod:`impstab.fluid` is a sum over panels of a 21-point Kronrod rule whose
ten Gauss nodes give a second, lower-order value on the same evaluations. The Kronrod sum is
returned; ``|Kronrod - Gauss|`` summed over panels is a conservative error estimate (it measures
the error of the Gauss rule, which is much larger than that of the Kronrod rule).

Panel layouts are built once per geometry, vectorised: the integrand is evaluated on all nodes
in one call, so no Python loop runs over panels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["PanelRule", "graded_edges", "split_long", "growing_edges"]

FloatArray = NDArray[np.float64]

# QUADPACK qk21: Kronrod abscissae on [0, 1) (the Gauss ones are the odd entries) and weights.
_XK = np.array([
    0.995657163025808080735527280689003, 0.973906528517171720077964012084452,
    0.930157491355708226001207180059508, 0.865063366688984510732096688423493,
    0.780817726586416897063717578345042, 0.679409568299024406234327365114874,
    0.562757134668604683339000099272694, 0.433395394129247190799265943165784,
    0.294392862701460198131126603103866, 0.148874338981631210884826001129720, 0.0,
])
_WK = np.array([
    0.011694638867371874278064396062192, 0.032558162307964727478818972459390,
    0.054755896574351996031381300244580, 0.075039674810919952767043140916190,
    0.093125454583697605535065465083366, 0.109387158802297641899210590325805,
    0.123491976262065851077958109831074, 0.134709217311473325928054001771707,
    0.142775938577060080797094273138717, 0.147739104901338491374841515972068,
    0.149445554002916905664936468389821,
])
_WG_HALF = np.array([
    0.066671344308688137593568809893332, 0.149451349150580593145776339657697,
    0.219086362515982043995534934228163, 0.269266719309996355091226921569469,
    0.295524224714752870173892994651338,
])

NODES = np.concatenate([-_XK[:-1], _XK[::-1]])  # 21 abscissae on [-1, 1], ascending
WEIGHTS_K = np.concatenate([_WK[:-1], _WK[::-1]])
WEIGHTS_G = np.zeros(21)
WEIGHTS_G[1:10:2] = _WG_HALF
WEIGHTS_G[11:20:2] = _WG_HALF[::-1]


@dataclass(frozen=True)
class PanelRule:
    """Nodes and weights of a composite G10/K21 rule on the panels between ``edges``.

    Attributes
    ----------
    x : ndarray, shape (npanel, 21)
        Nodes, one row per panel.
    wk, wg : ndarray, shape (npanel, 21)
        Kronrod and Gauss weights (the Gauss weights vanish on the Kronrod-only nodes).
    """

    x: FloatArray
    wk: FloatArray
    wg: FloatArray

    @classmethod
    def from_edges(cls, edges: FloatArray) -> "PanelRule":
        """Build the rule on the panels ``[edges[i], edges[i + 1]]`` (edges strictly increasing)."""
        e = np.asarray(edges, dtype=float)
        half = 0.5 * np.diff(e)[:, None]
        mid = 0.5 * (e[1:] + e[:-1])[:, None]
        return cls(x=mid + half * NODES, wk=half * WEIGHTS_K, wg=half * WEIGHTS_G)

    def integrate(self, values: NDArray) -> tuple[complex, float, float]:
        """Kronrod sum of ``values`` (same shape as ``x``) and error estimates of its parts.

        Returns
        -------
        total : complex
            Kronrod estimate of the integral.
        err_re, err_im : float
            ``sum over panels |Re(K - G)|`` and the same for the imaginary part.
        """
        k = np.sum(values * self.wk, axis=1)
        g = np.sum(values * self.wg, axis=1)
        d = k - g
        return complex(k.sum()), float(np.abs(d.real).sum()), float(np.abs(np.imag(d)).sum())


def graded_edges(extent: float, ratio: float, smallest: float) -> FloatArray:
    """Offsets ``0 < extent * ratio**m < ... < extent * ratio < extent`` graded toward 0.

    Geometric grading toward a point singularity: each panel ``[r h, h]`` sees the singularity
    at a fixed fraction of its own length, so the rule converges at the same rate on every panel.
    The first panel ``[0, extent * ratio**m]`` is no longer than ``smallest``.
    """
    levels = max(0, int(np.ceil(np.log(smallest / extent) / np.log(ratio))))
    return np.concatenate([[0.0], extent * ratio ** np.arange(levels, -1, -1)])


def split_long(edges: FloatArray, width: float) -> FloatArray:
    """Split every panel longer than ``width`` into equal panels no longer than ``width``."""
    e = np.asarray(edges, dtype=float)
    lengths = np.diff(e)
    counts = np.maximum(1, np.ceil(lengths / width * (1.0 - 1e-12)).astype(int))
    if np.all(counts == 1):
        return e
    pieces = [np.linspace(a, b, n + 1)[:-1] for a, b, n in zip(e[:-1], e[1:], counts)]
    return np.concatenate(pieces + [e[-1:]])


def growing_edges(first: float, growth: float, cap: float, end: float) -> FloatArray:
    """Edges ``0 = t0 < t1 < ... >= end`` with widths ``min(max(first, growth * t_j), cap)``.

    Used on lines that leave a singularity behind: the admissible panel width grows with the
    distance to it, up to ``cap`` (set by the other scale of the integrand).
    """
    edges = [0.0]
    t = 0.0
    while t < end:
        t += min(max(first, growth * t), cap)
        edges.append(t)
    return np.array(edges)
