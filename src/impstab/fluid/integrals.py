"""Wavenumber integrals of the segment windows against the modal impedance ratio.

In the dimensionless wavenumber ``s = k a`` with ``ell = L / (2a)`` and ``s0 = k0 a`` this module
computes

    J_n = integral_0^inf r(s) j_n(ell s)^2 ds,      n = 0 (translation), 1 (rotation),

with ``r`` the impedance ratio of :mod:`impstab.fluid.impedance` (``z = i omega rho a r``).
The integral is split at ``S = max(s0 + LINE_OFFSET, X_MIN / ell)``:

* ``[0, S]`` on the real axis, composite Gauss-Kronrod panels graded geometrically toward the
  logarithmic singularities of ``r`` (``s = 0`` when incompressible, the branch point ``s0``
  from both sides otherwise) and no longer than one period ``pi / ell`` of the oscillation;
* ``[S, inf)``: ``j_n^2 = n_n + c_n e^{2 i ell s} + conj``. The non-oscillating part is
  integrated on panels doubling their distance from ``s0`` up to ``s_far >= 2 s0``, then after
  ``s = s_far / u`` (a smooth integrand on ``0 < u <= 1``); the oscillating parts
  are moved, by Cauchy's theorem, onto the vertical line ``s = S + i t`` where they decay like
  ``e^{-2 ell t}`` (no oscillation, no asymptotic expansion). ``r`` is real on ``s > s0``, so the
  ``e^{-2 i ell s}`` part is the complex conjugate of the ``e^{+2 i ell s}`` part.

Nothing here is truncated except ``e^{-2 ell t}`` below ``e^{-40}``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .impedance import evanescent_ratio, radiating_ratio
from .quadrature import PanelRule, graded_edges, growing_edges, split_long
from .windows import ORDERS, window_parts, window_squared

__all__ = ["WindowIntegrals", "window_integrals", "estimate_nodes"]

GRADING_RATIO = 0.3     # panel [r h, h] sees the singularity at 0.43 of its length
GRADING_DEPTH = 1e-8    # innermost panel, relative to min(graded extent, 1)
LINE_OFFSET = 1.5       # distance of the vertical line from the branch point (in s = k a)
X_MIN = 2.0             # ell * S at least this (the tail split cancels for small ell * S)
DECAY = 40.0            # e^{-2 ell t} integrated down to e^{-DECAY}
_U_EDGES = np.array([0.0, 0.125, 0.25, 0.5, 1.0])


@dataclass(frozen=True)
class WindowIntegrals:
    """``J_0`` and ``J_1`` with conservative relative error estimates.

    Attributes
    ----------
    values : tuple of complex
        ``(J_0, J_1)``.
    errors : tuple of float
        Relative error estimates ``(Re J_0, Im J_0, Re J_1, Im J_1)``; 0 for an imaginary part
        that vanishes identically (no radiation).
    nodes : int
        Number of impedance evaluations.
    """

    values: tuple[complex, complex]
    errors: tuple[float, float, float, float]
    nodes: int


def _refined(edges: np.ndarray, refine: int) -> np.ndarray:
    if refine == 1:
        return edges
    parts = [np.linspace(a, b, refine + 1)[:-1] for a, b in zip(edges[:-1], edges[1:])]
    return np.concatenate(parts + [edges[-1:]])


def _real_axis(ell: float, s0: float, upper: float, refine: int):
    """Sum over the graded real-axis pieces: returns per order (total, err_re, err_im), nodes."""
    width = np.pi / ell
    if s0 > 0.0:
        pieces = [(s0, -1.0, s0), (s0, 1.0, upper - s0)]
    else:
        pieces = [(0.0, 1.0, upper)]
    sums = np.zeros((len(ORDERS), 3), dtype=complex)
    count = 0
    for origin, direction, extent in pieces:
        smallest = GRADING_DEPTH**refine * min(extent, 1.0)
        edges = _refined(split_long(graded_edges(extent, GRADING_RATIO, smallest), width), refine)
        rule = PanelRule.from_edges(edges)
        d = rule.x                      # distance from the origin of the piece, exact
        s = origin + direction * d
        if direction < 0:
            r = radiating_ratio(np.sqrt(d * (2.0 * s0 - d)))
        else:
            r = evanescent_ratio(np.sqrt(d * (2.0 * s0 + d)))
        for i, order in enumerate(ORDERS):
            sums[i] += rule.integrate(r * window_squared(ell * s, order))
        count += d.size
    return sums, count


def _tail(ell: float, s0: float, upper: float, refine: int):
    """Integral over ``[upper, inf)``: returns per order (total, err_re, 0), nodes."""
    sums = np.zeros((len(ORDERS), 3), dtype=complex)
    dist = upper - s0
    # non-oscillating part: panels doubling their distance from the branch point up to
    # s = far >= 2 s0, then s = far / u on 0 < u <= 1 (the branch point is then at u >= 2)
    steps = max(0, int(np.ceil(np.log2(max(s0, dist) / dist))))
    s_edges = s0 + dist * 2.0 ** np.arange(steps + 1)
    far = s_edges[-1]
    near = PanelRule.from_edges(_refined(s_edges, refine)) if steps else None
    rule = PanelRule.from_edges(_refined(_U_EDGES, refine))
    s_far = far / rule.x
    count = rule.x.size
    for i, order in enumerate(ORDERS):
        n, _ = window_parts(ell * s_far, order)
        jacobian = s_far * s_far / far  # ds = (s^2 / far) du
        sums[i] += rule.integrate(evanescent_ratio(np.sqrt((s_far - s0) * (s_far + s0))) * n * jacobian)
        if near is not None:
            s = near.x
            n, _ = window_parts(ell * s, order)
            sums[i] += near.integrate(evanescent_ratio(np.sqrt((s - s0) * (s + s0))) * n)
    count += 0 if near is None else near.x.size
    # oscillating parts on s = S + i t
    edges = growing_edges(first=dist, growth=1.0, cap=3.0 / ell, end=DECAY / (2.0 * ell))
    rule = PanelRule.from_edges(_refined(edges, refine))
    t = rule.x
    s = upper + 1j * t
    r = evanescent_ratio(np.sqrt((s - s0) * (s + s0)))
    decay = np.exp(-2.0 * ell * t)
    phase = 2j * np.exp(2j * ell * upper)  # 2 Re[i e^{2 i ell S} integral]; ds = i dt
    for i, order in enumerate(ORDERS):
        _, c = window_parts(ell * s, order)
        total, err_re, err_im = rule.integrate(r * c * decay)
        sums[i, 0] += (phase * total).real
        sums[i, 1] += 2.0 * np.hypot(err_re, err_im)
    return sums, count + t.size


def estimate_nodes(ell: float, s0: float, refine: int = 1) -> int:
    """Upper estimate of the impedance evaluations of :func:`window_integrals`, in O(1).

    Counts the panels of the layout from its rules instead of building it (whose size grows
    like ``(s0 + 1.5) ell / pi``, the number of half periods of the window on the real axis),
    so that a layout too large for memory is refused before any of it exists.
    """
    nodes_per_panel = 21 * refine
    upper = max(s0 + LINE_OFFSET, X_MIN / ell)
    width = np.pi / ell
    extents = [s0, upper - s0] if s0 > 0.0 else [upper]
    panels = 0.0
    for extent in extents:
        smallest = GRADING_DEPTH**refine * min(extent, 1.0)
        levels = max(0.0, np.ceil(np.log(smallest / extent) / np.log(GRADING_RATIO)))
        panels += levels + 2.0 + extent / width
    dist = upper - s0
    panels += max(0.0, np.ceil(np.log2(max(s0, dist) / dist))) + len(_U_EDGES) - 1
    cap, end = 3.0 / ell, DECAY / (2.0 * ell)
    panels += max(0.0, np.log2(cap / dist)) + 3.0 + end / cap
    total = nodes_per_panel * panels
    return int(min(total, 2.0**62))


def window_integrals(ell: float, s0: float, refine: int = 1) -> WindowIntegrals:
    """Compute ``J_0`` and ``J_1`` for half-length ratio ``ell = L/(2a)`` and ``s0 = k0 a``.

    Parameters
    ----------
    ell : float
        ``L / (2a)`` (> 0).
    s0 : float
        ``k0 a = omega a / c`` (>= 0; 0 is the incompressible fluid).
    refine : int
        Panel subdivision factor: 1 is the production layout; ``m`` splits every panel into
        ``m`` and raises the grading depth to the power ``m`` (for refinement and checks).
    """
    upper = max(s0 + LINE_OFFSET, X_MIN / ell)
    real, n_real = _real_axis(ell, s0, upper, refine)
    tail, n_tail = _tail(ell, s0, upper, refine)
    sums = real + tail
    values = (complex(sums[0, 0]), complex(sums[1, 0]))
    errors: list[float] = []
    for i in range(len(ORDERS)):
        total, err_re, err_im = sums[i]
        errors.append(float(err_re.real / abs(total.real)))
        errors.append(float(err_im.real / abs(total.imag)) if total.imag != 0.0 else 0.0)
    return WindowIntegrals(values=values, errors=tuple(errors), nodes=n_real + n_tail)
