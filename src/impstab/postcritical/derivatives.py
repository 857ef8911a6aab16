"""Exact derivatives of ``f(x, p)``: complex-step Jacobians and Cauchy-circle multilinear forms.

Jacobians (batched): ``J(x) u = Im f(x + i h u) / h`` with ``h = 1e-30``. There is no
subtraction, so the result is exact to rounding; the truncation error is ``O(h^2)``, i.e. nil.
The parameter derivative ``df/dp`` is the same complex step in ``p`` (or, where the right-hand
side cannot take a complex parameter, a fourth-order central difference, and the results say so).

Second and third derivatives (the forms ``B(u, v)`` and ``C(u, v, w)`` of the normal-form
formulas): along a direction ``w`` the Taylor coefficients of ``g(z) = f(x0 + z w)`` are the
Cauchy integrals ``a_k = (1 / 2 pi i) oint g(z) z^-k-1 dz``; the trapezoidal rule on the circle
``|z| = r`` with ``N`` points is an FFT::

    c_k = (1/N) sum_j g(r e^{2 pi i j/N}) e^{-2 pi i jk/N} = a_k r^k + a_{k+N} r^{k+N} + ...

so ``D^k f(x0)[w, ..., w] = k! c_k / r^k`` up to the aliased terms ``a_{k+N} r^{k+N}`` (nil for
a polynomial of degree below ``N``, decaying geometrically for an analytic ``f``) and rounding.
Error bound stated for each form: ``k! (N eps max_j |g_j| + max(|c_{N-2}|, |c_{N-1}|)) / r^k``:
the rounding of ``f`` on the circle (``f`` evaluated to relative accuracy ``eps`` of its largest
value there) and the tail, estimated by the highest resolved coefficients, which bound the
aliased ones for coefficients that decay. Mixed forms come from polarization,
``B(u, v) = [D2(u + v) - D2(u - v)] / 4`` and
``C(u, v, w) = [D3(u+v+w) - D3(u+v-w) - D3(u-v+w) + D3(u-v-w)] / 24``, valid for complex
directions (the forms are the complex-multilinear extensions).

Directions are normalized in the scaled norm ``|w / state_scale|`` before the circle is put on
them, so the radius ``r`` is in units of the state scale. The rounding term falls like ``r^-k``
and the aliasing grows like ``r^(k+N)``: the radius should be as large as the region where ``f``
is analytic allows (the propulsor model: 10 state scales; a circle of 0.1 state scales left the
third derivative 5 digits there, the preload terms cancelling at the equilibrium). Where ``f`` is
piecewise, the system's ``region`` codes halve each direction's radius until the disc lies in the
centre's piece (:meth:`Forms.radii`; the argument in :mod:`impstab.postcritical.system`). scipy has no multivariate complex-step
or Cauchy-FFT derivative routine (``scipy.differentiate`` is finite differences), hence this module.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import NumericalError
from .system import DynamicalSystem

__all__ = ["jacobians", "parameter_derivatives", "Forms", "check_derivatives", "COMPLEX_STEP",
           "CIRCLE_RADIUS", "CIRCLE_POINTS"]

Array = NDArray[np.float64]
CArray = NDArray[np.complex128]

#: complex step (in units of the state scale for states; of max(1, |p|) for the parameter)
COMPLEX_STEP = 1e-30
#: default radius of the Cauchy circle, in units of the state scale
CIRCLE_RADIUS = 0.1
#: default number of points on the circle (a power of two)
CIRCLE_POINTS = 16
EPS = np.finfo(float).eps
#: region test of a circle: sampled this many times finer than the circle, at this multiple of
#: its radius, halving the radius at most this many times
REGION_SAMPLES = 4
REGION_MARGIN = 1.5
REGION_HALVINGS = 40


def jacobians(system: DynamicalSystem, states: Array, p: float) -> Array:
    """Jacobians ``df/dx`` at a batch ``(N, n)`` of real states: ``(N, n, n)``, exact to rounding."""
    x = np.asarray(states, dtype=float)
    if system.jacobian is not None:
        return np.asarray(system.call_jacobian(x, p), dtype=float)
    n_pts, n = x.shape
    h = COMPLEX_STEP * system.state_scale
    probe = x[:, None, :] + 1j * np.diag(h)[None, :, :]          # (N, n(direction), n)
    out = system.evaluate(probe.reshape(n_pts * n, n), p).reshape(n_pts, n, n)
    return np.ascontiguousarray(np.swapaxes(out.imag, 1, 2)) / h[None, None, :]


def parameter_derivatives(system: DynamicalSystem, states: Array, p: float) -> tuple[Array, str]:
    """``df/dp`` at a batch of states, ``(N, n)``, and the method used."""
    x = np.asarray(states, dtype=float)
    if system.complex_parameter:
        h = COMPLEX_STEP * max(1.0, abs(p))
        return system.evaluate(x.astype(complex), complex(p, h)).imag / h, "complex-step"
    h = 1e-3 * max(1.0, abs(p))
    f = [system.evaluate(x, p + k * h).real for k in (-2, -1, 1, 2)]
    return (f[0] - 8 * f[1] + 8 * f[2] - f[3]) / (12 * h), "central-difference-4"


@dataclass(frozen=True)
class FormValue:
    """A multilinear form's value and its error bound (same units)."""

    value: CArray
    error: float


class Forms:
    """Derivatives of ``f`` at one point ``(x0, p0)``: Jacobian, ``B(u, v)``, ``C(u, v, w)``.

    Parameters
    ----------
    system : DynamicalSystem
    x0 : (n,) array
    p0 : float
    radius : float
        Cauchy-circle radius in units of the state scale.
    points : int
        Points on the circle (at least 8).
    """

    def __init__(self, system: DynamicalSystem, x0: Array, p0: float, radius: float = CIRCLE_RADIUS,
                 points: int = CIRCLE_POINTS) -> None:
        if points < 8:
            raise ValueError("the Cauchy circle needs at least 8 points")
        self.system = system
        self.x0 = np.asarray(x0, dtype=float)
        self.p0 = float(p0)
        self.radius = float(radius)
        self.points = int(points)
        self.evaluations = 0
        #: smallest circle radius used so far (state scales): below ``radius`` where a piecewise
        #: law's seam is near
        self.smallest_radius = self.radius

    @property
    def method(self) -> str:
        return "analytic" if self.system.second_derivative is not None else "Cauchy circle"

    def jacobian(self) -> Array:
        return jacobians(self.system, self.x0[None, :], self.p0)[0]

    # -------------------------------------------------------------- Taylor coefficients
    def taylor(self, directions: CArray, order: int, p_directions: NDArray | None = None) -> tuple[CArray, Array]:
        """Taylor coefficients of ``f(x0 + z w, p0 + z dp)`` in ``z`` for each direction.

        Returns ``coef (K, order + 1, n)`` with ``coef[k, j] = D^j f[w_k, ..., w_k] / j!`` and the
        error bounds ``(K, order + 1)`` of those coefficients.
        """
        w = np.atleast_2d(np.asarray(directions, dtype=complex))
        n_dir, n = w.shape
        scale = self.system.state_scale
        norms = np.sqrt(np.sum(np.abs(w / scale) ** 2, axis=1))
        if p_directions is not None:
            dp = np.asarray(p_directions, dtype=complex).reshape(n_dir)
            norms = np.sqrt(norms ** 2 + np.abs(dp / max(1.0, abs(self.p0))) ** 2)
        safe = np.where(norms > 0, norms, 1.0)
        unit = w / safe[:, None]
        m = self.points
        radii = self.radii(unit)                                                        # (K,)
        z = radii[:, None] * np.exp(2j * np.pi * np.arange(m) / m)[None, :]             # (K, m)
        states = self.x0[None, None, :] + z[:, :, None] * unit[:, None, :]              # (K, m, n)
        if p_directions is None:
            g = self.system.evaluate(states.reshape(n_dir * m, n), self.p0).reshape(n_dir, m, n)
        else:
            params = self.p0 + z * (dp / safe)[:, None]
            g = self.system.evaluate_rows(states.reshape(n_dir * m, n), params.reshape(-1)).reshape(n_dir, m, n)
        self.evaluations += n_dir * m
        c = np.fft.fft(g, axis=1) / m                                                  # (K, m, n)
        k = np.arange(order + 1)
        fac = safe[:, None] ** k[None, :] / radii[:, None] ** k[None, :]                # (K, order+1)
        coef = c[:, : order + 1, :] * fac[:, :, None]
        coef[norms == 0, 1:, :] = 0.0
        peak = np.max(np.abs(g), axis=(1, 2))
        tail = np.max(np.abs(c[:, m - 2:, :]), axis=(1, 2))
        err = (m * EPS * peak + tail)[:, None] * fac
        err[norms == 0, 1:] = 0.0
        return coef, err

    def radii(self, unit: CArray) -> Array:
        """Circle radius of each unit direction (scaled norm 1): ``radius``, halved until the disc
        lies in the centre's piece of a piecewise ``f`` (the system's ``region`` codes; see
        :mod:`impstab.postcritical.system`). Raises NumericalError when no radius down to
        ``1e-12 radius`` does (the point sits on a seam of the law)."""
        n_dir, n = unit.shape
        r = np.full(n_dir, self.radius)
        region = self.system.region
        if region is None or n_dir == 0:
            return r
        centre = np.asarray(region(self.x0[None, :].astype(complex)))
        m = REGION_SAMPLES * self.points
        ring = REGION_MARGIN * np.exp(2j * np.pi * np.arange(m) / m)
        for _ in range(REGION_HALVINGS):
            states = self.x0[None, None, :] + (r[:, None] * ring[None, :])[:, :, None] * unit[:, None, :]
            codes = np.asarray(region(states.reshape(n_dir * m, n))).reshape(n_dir, m, -1)
            bad = np.any(codes != centre.reshape(1, 1, -1), axis=(1, 2))
            if not bad.any():
                self.smallest_radius = min(self.smallest_radius, float(r.min()))
                return r
            r[bad] /= 2
        raise NumericalError(f"the derivatives at this point: no Cauchy circle down to radius {r.min():.3g} stays "
                             "in one piece of the piecewise right-hand side (the point lies on a seam, e.g. at "
                             "a snubber's contact)")

    # ------------------------------------------------------------------ the forms
    def second(self, u: CArray, v: CArray) -> FormValue:
        """``B(u, v) = sum_jk d2f/dx_j dx_k u_j v_k`` (complex bilinear, symmetric)."""
        if self.system.second_derivative is not None:
            val = self.system.call_second(self.x0[None], self.p0, np.asarray(u)[None], np.asarray(v)[None])[0]
            return FormValue(np.asarray(val, dtype=complex), 0.0)
        u, v = np.asarray(u, dtype=complex), np.asarray(v, dtype=complex)
        coef, err = self.taylor(np.stack([u + v, u - v]), 2)
        # D2(w) = 2 a2(w); B = [D2(u+v) - D2(u-v)] / 4 = [a2(u+v) - a2(u-v)] / 2
        return FormValue((coef[0, 2] - coef[1, 2]) / 2, float(err[0, 2] + err[1, 2]) / 2)

    def third(self, u: CArray, v: CArray, w: CArray) -> FormValue:
        """``C(u, v, w)`` (complex trilinear, symmetric)."""
        if self.system.third_derivative is not None:
            val = self.system.call_third(self.x0[None], self.p0, np.asarray(u)[None], np.asarray(v)[None],
                                         np.asarray(w)[None])[0]
            return FormValue(np.asarray(val, dtype=complex), 0.0)
        u, v, w = (np.asarray(a, dtype=complex) for a in (u, v, w))
        coef, err = self.taylor(np.stack([u + v + w, u + v - w, u - v + w, u - v - w]), 3)
        # D3 = 6 a3; C = [D3(.) - D3(.) - D3(.) + D3(.)] / 24
        a3 = coef[:, 3]
        return FormValue((a3[0] - a3[1] - a3[2] + a3[3]) / 4, float(np.sum(err[:, 3])) / 4)

    def parameter(self) -> tuple[Array, str]:
        """``df/dp`` at the point and the method."""
        val, method = parameter_derivatives(self.system, self.x0[None], self.p0)
        return val[0], method

    def jacobian_total_derivative(self, u: CArray, x_p: Array) -> tuple[CArray, str]:
        """``d/dp [J(x(p), p) u]`` along the equilibrium branch ``x(p)`` with ``dx/dp = x_p``.

        Equal to ``B(u, x_p) + (dJ/dp) u``: the mixed form of the augmented map ``(x, p) -> f``,
        by polarization on the Cauchy circle with a complex parameter, or (where the right-hand
        side takes no complex parameter) a fourth-order central difference of ``J(x(p), p) u``.
        """
        u = np.asarray(u, dtype=complex)
        if self.system.complex_parameter:
            coef, _ = self.taylor(np.stack([u + x_p, u - x_p]), 2, p_directions=np.array([1.0, -1.0]))
            return (coef[0, 2] - coef[1, 2]) / 2, "Cauchy circle"
        h = 1e-3 * max(1.0, abs(self.p0))
        vals = []
        for k in (-2, -1, 1, 2):
            x = self.x0 + k * h * x_p
            vals.append(jacobians(self.system, x[None], self.p0 + k * h)[0] @ u)
        return (vals[0] - 8 * vals[1] + 8 * vals[2] - vals[3]) / (12 * h), "central-difference-4"


def check_derivatives(system: DynamicalSystem, x: Array, p: float, seed: int = 0, radius: float = CIRCLE_RADIUS,
                      points: int = CIRCLE_POINTS) -> dict[str, float]:
    """Independent checks of the exact derivatives at ``(x, p)``.

    * ``jacobian``: largest relative difference between the complex-step Jacobian and a
      central difference with the optimal step (expected ~1e-10; a large value means ``f`` is
      not analytic in its complex extension: ``abs``, ``max``, ``.real`` ...);
    * ``second``, ``third``: change of ``B(u, v)`` and ``C(u, v, w)`` (random ``u, v, w``) between
      circles of radius ``r`` and ``r / 2`` with twice the points, relative to the value or to its
      error bound where the form is zero (expected ~1e-12; above 1: the bound does not hold).
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    rng = np.random.default_rng(seed)
    jac = jacobians(system, x[None], p)[0]
    scale = system.state_scale
    h = np.cbrt(EPS) * np.maximum(np.abs(x), scale)
    probe = np.concatenate([x[None] + np.diag(h), x[None] - np.diag(h)])
    vals = system.evaluate(probe, p).real
    fd = ((vals[:n] - vals[n:]) / (2 * h[:, None])).T
    ref = max(np.max(np.abs(jac)), np.finfo(float).tiny)
    out = {"jacobian": float(np.max(np.abs(jac - fd)) / ref)}
    u, v, w = (rng.standard_normal(n) * scale for _ in range(3))
    f1 = Forms(system, x, p, radius=radius, points=points)
    f2 = Forms(system, x, p, radius=radius / 2, points=2 * points)
    for name, a, b in (("second", f1.second(u, v), f2.second(u, v)), ("third", f1.third(u, v, w), f2.third(u, v, w))):
        # relative to the value, or to the error bound where the value is rounding noise (a zero form)
        size = max(np.max(np.abs(a.value)), np.max(np.abs(b.value)), a.error)
        out[name] = 0.0 if size == 0 else float(np.max(np.abs(a.value - b.value)) / size)
    return out

