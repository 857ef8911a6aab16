"""Critical load of a one-parameter family: the first loss of stability from ``p_min``.

The families are second order, ``M q'' + (D + G) q' + K(p) q = 0``, or first order,
``E x' = A(p) x``; affine in the load or given by a function. The search is the stability engine
(:mod:`impstab.linear.engine`, THEORY 5): a scan that brackets (with the bubble searches), then
an exact refinement of each bracket on a smooth indicator to rounding. This module is its
single-problem face: the result types and :func:`critical_load`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from .engine import Crossing, first_order_problem, second_order_problem, solve
from .engine.tolerances import FLOOR, TOL_CLUSTER, TOL_DUPLICATE, TOL_MARGINAL, TOL_UNSTABLE
from .families import CallableFamily, CallableFirstOrderFamily, LinearFamily, LinearFirstOrderFamily, SystemFamily

__all__ = ["CriticalLoad", "Crossing", "critical_load", "critical_load_family",
           "TOL_UNSTABLE", "TOL_MARGINAL", "FLOOR", "TOL_CLUSTER", "TOL_DUPLICATE"]

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class CriticalLoad:
    """Result of a critical-load search.

    Attributes
    ----------
    load : float or None
        Critical load ``p_c`` (first loss of stability from p = 0), None when stable up to ``p_max``.
    kind : {"flutter", "divergence", "none"}
    omega : float or None
        Angular frequency at onset (rad/s); 0 for divergence.
    frequency_hz : float or None
        ``omega / 2 pi`` (Hz).
    mode : (n,) complex array or None
        Displacement shape of the critical mode at onset (largest component 1); for a first-order
        family, its first ``n_dof`` states.
    participation : (n,) array or None
        Kinetic-energy share of each dof in the critical cluster's subspace (first-order
        families: the share of each of the first ``n_dof`` states, weighted by the family's
        ``weights``).
    p_max : float
        Upper end of the search.
    method : str
        ``"coalescence"`` (undamped discriminant) or ``"hopf"`` (first-order real part).
    crossings : tuple of Crossing
        Every stability change up to ``p_max`` (only when requested with ``all_crossings``).
    evaluations : int
        Number of eigenproblems solved.
    warnings : tuple of str
        Numerical trouble met on the way (e.g. an onset located only to the classification
        tolerance), never hidden.
    """

    load: float | None
    kind: str
    omega: float | None
    p_max: float
    method: str
    mode: Array | None = None
    participation: Array | None = None
    crossings: tuple[Crossing, ...] = field(default_factory=tuple)
    evaluations: int = 0
    warnings: tuple[str, ...] = field(default_factory=tuple)

    def __repr__(self) -> str:
        from ..display import critical_load_text

        return critical_load_text(self)

    @property
    def frequency_hz(self) -> float | None:
        return None if self.omega is None else self.omega / (2.0 * np.pi)


def critical_load_family(
    family: SystemFamily,
    p_max: float,
    *,
    p_min: float = 0.0,
    n_scan: int = 64,
    chunk: int = 16,
    all_crossings: bool = False,
    undamped: bool | None = None,
) -> CriticalLoad:
    """Critical load of a family (see :func:`critical_load`).

    Parameters
    ----------
    family : SystemFamily or FirstOrderFamily
        ``p -> (M, D, G, K)`` (:mod:`impstab.linear.families`), or ``p -> (E, A)`` (a family with
        ``first_order = True``, such as :class:`~impstab.linear.families.LinearFirstOrderFamily`).
    p_max, p_min : float
        The load range searched.
    n_scan : int
        Scan intervals on it.
    chunk : int
        Scan points a family that is not affine is evaluated at per call.
    all_crossings : bool
        Also list every later loss and gain of stability up to ``p_max``.
    undamped : bool, optional
        Second-order families: force the undamped (``s``) or the first-order form.

    Raises
    ------
    ValueError
        For a range that is not finite and increasing. Whatever the family raises while it is
        evaluated is raised again.
    """
    problem = _problem(family, p_max, p_min, n_scan, undamped)
    out = solve([problem], all_crossings=all_crossings, chunk=chunk)[0]
    if out.error is not None:
        raise out.error
    return CriticalLoad(out.load, out.kind, out.omega, float(p_max), out.method, out.mode, out.participation,
                        out.crossings, out.evaluations, out.warnings)


def _problem(family, p_max: float, p_min: float, n_scan: int, undamped: bool | None):
    if getattr(family, "first_order", False):
        return first_order_problem(family, p_max, p_min=p_min, n_scan=n_scan)
    return second_order_problem(family, p_max, p_min=p_min, n_scan=n_scan, undamped=undamped)


def critical_load(
    M=None,
    K0=None,
    K1=None,
    D=None,
    G=None,
    p_max: float = 1.0,
    *,
    n_scan: int = 64,
    all_crossings: bool = False,
    A0=None,
    A1=None,
    A=None,
    E=None,
) -> CriticalLoad:
    """Critical load of ``M q'' + (D + G) q' + (K0 + p K1) q = 0`` or ``E x' = A(p) x``.

    Second-order form (positional): ``critical_load(M, K0, K1, D=None, G=None, p_max=...)``, or a
    callable ``M = p -> (M, D, G, K)`` (D or G may be None) for a system that is not affine in the
    load. First-order form (keywords only): ``critical_load(A0=..., A1=..., E=None, p_max=...)``
    for ``A(p) = A0 + p A1``, or ``critical_load(A=func, E=None, p_max=...)`` with
    ``func(p) -> A`` or ``func(p) -> (E, A)``. The first-order form reports the mode and the
    participation of all states (unit weights): use :func:`critical_load_family` with a
    :class:`~impstab.linear.families.LinearFirstOrderFamily` to name the displacement states.

    Parameters
    ----------
    M, K0, K1 : (n, n) array_like
        Mass, stiffness at p = 0, and stiffness per unit load (non-symmetric for follower loads).
    D, G : (n, n) array_like, optional
        Damping (symmetric) and gyroscopic (skew) matrices.
    p_max : float
        Upper end of the search.
    n_scan : int
        Number of scan intervals on ``[0, p_max]``.
    all_crossings : bool
        Also list every later loss and gain of stability up to ``p_max``.
    A0, A1 : (N, N) array_like
        First-order form: the state matrix at p = 0 and per unit load.
    A : callable
        First-order form not affine in the load.
    E : (N, N) array_like, optional
        First-order form: the (invertible) matrix of ``x'``; the identity by default.

    Returns
    -------
    CriticalLoad
        ``.load`` is the first critical value from p = 0 (None if stable up to ``p_max``).

    Examples
    --------
    Ziegler's pendulum (m = l = c = 1): flutter at ``7/2 - sqrt(2)``.

    >>> import numpy as np
    >>> r = critical_load([[3, 1], [1, 1]], [[2, -1], [-1, 1]], [[-1, 1], [0, 0]], p_max=5)
    >>> round(r.load, 10), r.kind
    (2.0857864376, 'flutter')
    """
    first = A0 is not None or A1 is not None or A is not None
    if first:
        if M is not None or K0 is not None or K1 is not None or D is not None or G is not None:
            raise ValueError("give either the first-order form (A0, A1 or A, and E) or the second-order "
                             "matrices (M, K0, K1, D, G), not both")
        if A is not None:
            if A0 is not None or A1 is not None:
                raise ValueError("give either a callable A or the matrices A0 and A1, not both")
            if not callable(A):
                raise ValueError("A must be a callable p -> A(p) (or p -> (E, A)); use A0 and A1 for matrices")
            fam = CallableFirstOrderFamily.build(A, E)
        else:
            if A0 is None or A1 is None:
                raise ValueError("A0 and A1 are both required for the first-order form")
            fam = LinearFirstOrderFamily.build(A0, A1, E)
    elif E is not None:
        raise ValueError("E belongs to the first-order form: give A0 and A1 (or A) with it")
    elif M is None:
        raise ValueError("give the mass matrix M (with K0 and K1), a callable system, or the first-order A0 and A1")
    elif callable(M):
        if K0 is not None or K1 is not None:
            raise ValueError("give either a callable system or the matrices M, K0, K1, not both")
        first_value = M(0.0)
        n = np.asarray(first_value[0]).shape[0]
        fam = CallableFamily(M, n)
    else:
        if K0 is None or K1 is None:
            raise ValueError("K0 and K1 are required with a mass matrix")
        fam = LinearFamily.build(M, K0, K1, D, G)
    return critical_load_family(fam, p_max, n_scan=n_scan, all_crossings=all_crossings)
