"""Root finding as steps (reverse communication), for the compiled refinement (THEORY 5).

The refinement evaluates the indicator itself (an eigen-decomposition per load) and hands each
value to a step function that keeps its state in a small array and returns the next load:
:func:`newton_step` (a bracketed Newton iteration on exact derivatives, started at
:func:`hermite_root`) and :func:`brent_step` (scipy's ``brentq``, ported step for step).
"""

from __future__ import annotations

import numpy as np
from ..._jit import njit

from .tolerances import EPS

__all__ = ["hermite_root", "newton_step", "brent_step"]

_EPS4 = 4.0 * EPS


@njit(cache=True, error_model="numpy")
def hermite_root(a, b, fa, fb, da, db):
    """A first point for Newton: the root in ``(a, b)`` of the cubic with ``f`` and ``f'`` at both ends.

    Its error is of order ``h^4`` against the secant's ``h^2``; the secant point where the slopes
    are not known or the cubic has no root inside.
    """
    secant = a - fa * (b - a) / (fb - fa)
    if np.isnan(da) or np.isnan(db):
        return secant
    h = b - a
    # the cubic in t = (x - a) / h with value and slope (times h) at t = 0 and 1
    c0, c1 = fa, da * h
    c2 = 3 * (fb - fa) - (2 * da + db) * h
    c3 = 2 * (fa - fb) + (da + db) * h
    t = (secant - a) / h
    lo, hi = 0.0, 1.0
    for _ in range(30):  # safeguarded Newton on the cubic (a few scalar steps)
        f = c0 + t * (c1 + t * (c2 + t * c3))
        if f == 0.0:
            break
        if (f > 0) == (fa > 0):
            lo = t
        else:
            hi = t
        d = c1 + t * (2 * c2 + 3 * t * c3)
        step = f / d if d != 0.0 else np.inf
        new = t - step
        if not (lo < new < hi):
            new = 0.5 * (lo + hi)
        if abs(new - t) <= 1e-15:
            t = new
            break
        t = new
    x = a + t * h
    return x if min(a, b) < x < max(a, b) else secant


@njit(cache=True, error_model="numpy", _nrt=False)
def newton_step(st, p, f, df):
    """Bracketed Newton (bisection guard) after ``f, df`` at ``p``; returns ``(next, done)``.

    ``st = (lo, hi, f_lo, last Newton step or NaN)``: the bracket, updated here. Done when the
    step is below 4 eps, or lands on an end of the bracket, or when the convergence seen so far
    is clearly quadratic (the step shrank by 1e4 at least) and predicts the error of the next
    point below eps: the error after a step ``d`` is ``C d^2``, ``C`` measured as
    ``|d| / d_prev^2`` from the last two steps. (The indicators cross zero linearly: simple roots.)
    """
    if f == 0.0:
        return p, True
    if np.sign(f) == np.sign(st[2]):
        st[0], st[2] = p, f
    else:
        st[1] = p
    lo, hi = st[0], st[1]
    new = p - f / df if df != 0.0 else np.inf
    prev = st[3]
    st[3] = new - p
    if not (min(lo, hi) < new < max(lo, hi)):
        new = 0.5 * (lo + hi)
        st[3] = np.nan
    step = abs(new - p)
    if step <= _EPS4 * abs(p) or new == lo or new == hi:
        return new, True
    quadratic = not np.isnan(prev) and not np.isnan(st[3]) and step <= 1e-3 * abs(prev)
    return new, quadratic and (step / (prev * prev)) * step * step <= EPS * abs(new)


@njit(cache=True, error_model="numpy", _nrt=False)
def brent_step(st, f):
    """scipy's ``brentq`` (xtol 1e-300, rtol 4 eps) as steps; returns ``(x, done)``.

    ``st = (xpre, xcur, xblk, fpre, fcur, fblk, spre, scur)``; ``f`` is the value at the last
    point returned (NaN on the first call, which starts from ``xpre, xcur, fpre, fcur``).
    """
    xtol, rtol = 1e-300, _EPS4
    xpre, xcur, xblk, fpre, fcur, fblk, spre, scur = st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7]
    if not np.isnan(f):
        fcur = f
    if fpre != 0 and fcur != 0 and (np.signbit(fpre) != np.signbit(fcur)):
        xblk, fblk = xpre, fpre
        spre = scur = xcur - xpre
    if abs(fblk) < abs(fcur):
        xpre, xcur, xblk = xcur, xblk, xcur
        fpre, fcur, fblk = fcur, fblk, fcur
    delta = (xtol + rtol * abs(xcur)) / 2
    sbis = (xblk - xcur) / 2
    done = fcur == 0 or abs(sbis) < delta
    if not done:
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # interpolate
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # extrapolate
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):
                spre, scur = scur, stry
            else:
                spre, scur = sbis, sbis
        else:
            spre, scur = sbis, sbis
        xpre, fpre = xcur, fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0 else -delta
    st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7] = xpre, xcur, xblk, fpre, fcur, fblk, spre, scur
    return xcur, done
