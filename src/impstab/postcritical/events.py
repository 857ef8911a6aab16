"""Test functions of the bifurcations of cycles and their location along the branch."""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from scipy.optimize import brentq

from ..errors import NumericalError
from .tracing import BranchPoint, Tracer

__all__ = ["TESTS", "events", "locate", "critical_multiplier"]

#: real multiplier: |Im mu| below this share of max(1, |mu|)
REAL_MULTIPLIER = 1e-7
#: relative accuracy of the arclength of a located special point
LOCATE_XTOL = 1e-12


def _real_below_minus_one(pt: BranchPoint) -> int:
    nt = pt.floquet.nontrivial
    real = np.abs(nt.imag) <= REAL_MULTIPLIER * np.maximum(1.0, np.abs(nt))
    return int(np.sum(real & (nt.real < -1.0)))


def _complex_outside(pt: BranchPoint) -> int:
    nt = pt.floquet.nontrivial
    cplx = np.abs(nt.imag) > REAL_MULTIPLIER * np.maximum(1.0, np.abs(nt))
    return int(np.sum(cplx & (np.abs(nt) > 1.0)))


def _pd_test(pt: BranchPoint) -> float:
    nt = pt.floquet.nontrivial
    real = np.abs(nt.imag) <= REAL_MULTIPLIER * np.maximum(1.0, np.abs(nt))
    if not np.any(real & (nt.real < 0)):
        return math.nan
    cand = nt[real & (nt.real < 0)].real
    return float(cand[np.argmin(np.abs(cand + 1.0))] + 1.0)


def _ns_test(pt: BranchPoint) -> float:
    nt = pt.floquet.nontrivial
    cplx = np.abs(nt.imag) > REAL_MULTIPLIER * np.maximum(1.0, np.abs(nt))
    if not np.any(cplx):
        return math.nan
    mod = np.abs(nt[cplx])
    return float(mod[np.argmin(np.abs(mod - 1.0))] - 1.0)


def _fold_test(pt: BranchPoint) -> float:
    return float(pt.tangent[-1])


TESTS: dict[str, Callable[[BranchPoint], float]] = {"fold": _fold_test, "period-doubling": _pd_test, "torus": _ns_test}


def critical_multiplier(kind: str, pt: BranchPoint) -> complex | None:
    nt = pt.floquet.nontrivial
    if kind == "fold":
        return complex(nt[np.argmin(np.abs(nt - 1.0))]) if nt.size else None
    if kind == "period-doubling":
        return complex(nt[np.argmin(np.abs(nt + 1.0))])
    cplx = nt[np.abs(nt.imag) > 0]
    return complex(cplx[np.argmin(np.abs(np.abs(cplx) - 1.0))]) if cplx.size else None


def events(a: BranchPoint, b: BranchPoint) -> list[str]:
    out = []
    if _fold_test(a) * _fold_test(b) < 0:
        out.append("fold")
    if (_real_below_minus_one(a) - _real_below_minus_one(b)) % 2 == 1:
        ta, tb = _pd_test(a), _pd_test(b)
        if math.isfinite(ta) and math.isfinite(tb) and ta * tb < 0:
            out.append("period-doubling")
    if _complex_outside(a) != _complex_outside(b):
        ta, tb = _ns_test(a), _ns_test(b)
        if math.isfinite(ta) and math.isfinite(tb) and ta * tb < 0:
            out.append("torus")
    return out


def locate(tracer: Tracer, a: BranchPoint, b: BranchPoint, kind: str) -> BranchPoint | None:
    test = TESTS[kind]
    ds_total = b.arclength - a.arclength
    memo: dict[float, BranchPoint] = {}

    def g(s: float) -> float:
        if s <= 0:
            return test(a)
        if s >= ds_total:
            return test(b)
        pt = tracer.correct(a, s, kind)
        if pt is None:
            raise NumericalError(f"no convergence while locating a {kind}")
        memo[s] = pt
        val = test(pt)
        if not math.isfinite(val):
            raise NumericalError(f"the {kind} test function is undefined inside its bracket")
        return val

    try:
        s_star = brentq(g, 0.0, ds_total, xtol=LOCATE_XTOL * max(1.0, abs(ds_total)), rtol=4 * np.finfo(float).eps,
                        maxiter=60)
    except (NumericalError, ValueError, RuntimeError):
        return None
    pt = memo.get(s_star) or tracer.correct(a, s_star, kind)
    if pt is not None:
        pt.label = kind
    return pt


