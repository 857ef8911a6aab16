"""Hopf analysis at the onset: the critical pair, the first Lyapunov coefficient, the normal form.

For ``B x' = f(x, p)`` with Jacobian ``J`` at the equilibrium ``x_c(p)``, the explicit state
matrix is ``A = B^-1 J``. At a Hopf point ``A q = i omega q`` with ``q^H q = 1`` and the adjoint
``A^H p = -i omega p`` with ``p^H q = 1`` (DESIGN.md). Kuznetsov (Elements of Applied Bifurcation
Theory, 3rd ed., eq. (3.20) and (5.39)) gives the normal form ``z' = (sigma + i omega) z + c1 z |z|^2``
on the centre manifold ``x = x_c + z q + conj(z q) + h20 z^2 / 2 + h11 |z|^2 + conj(h20 z^2) / 2 + ...``
with ``h11 = -A^-1 B(q, conj q)``, ``h20 = (2 i omega I - A)^-1 B(q, q)`` and

    c1 = <p, C(q, q, conj q) + 2 B(q, h11) + B(conj q, h20)> / 2,      l1 = Re(c1) / omega,

i.e. ``l1 = Re[<p, C(q,q,qbar)> - 2 <p, B(q, A^-1 B(q,qbar))> + <p, B(qbar, (2 i omega - A)^-1 B(q,q))>] / (2 omega)``.
``l1 < 0``: supercritical (a stable cycle grows from the onset as ``p`` passes it), ``l1 > 0``:
subcritical (an unstable cycle exists on the stable side, down to a fold of cycles).

With a mass matrix the same numbers are computed from the pencil ``(J, B)`` without forming
``B^-1``: ``J q = i omega B q``; the left vector ``w^H J = i omega w^H B`` scaled to ``w^H B q = 1``
gives ``p = B^H w`` and ``<p, B^-1 g> = w^H g``; ``h11 = -J^-1 B_f(q, qbar)``,
``h20 = (2 i omega B - J)^-1 B_f(q, q)`` with the forms ``B_f``, ``C_f`` of ``f`` itself. So ``l1``
is that of the explicit system ``x' = B^-1 f`` with ``q^H q = 1``: a mass matrix changes nothing.

Near the onset the cycle has the normal-form radius ``rho`` with ``rho^2 = -sigma' (p - p_c) / Re(c1)``
(``sigma' = d Re(lambda) / dp``, the crossing speed; ``Re(c1) = omega l1``), the physical cycle
``x(t) = x_c(p) + 2 Re(rho q e^{i theta}) + Re(h20 rho^2 e^{2 i theta}) + h11 rho^2`` and the
period ``2 pi / (omega + omega' (p - p_c) + Im(c1) rho^2)``. (Written with the time scaled so that
the frequency is 1, ``rho^2 = -beta / l1`` with ``beta = sigma' (p - p_c) / omega``: the same thing.)

The plain theory needs a simple pair crossing transversally with ``l1 != 0``; otherwise the
result is ``bifurcation = "degenerate"`` with the reason, and no coefficient is made up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.linalg as sla
from numpy.typing import NDArray
from scipy.optimize import brentq

from ..errors import ModelError, NumericalError
from .derivatives import CIRCLE_POINTS, CIRCLE_RADIUS, Forms, check_derivatives, jacobians
from .equilibrium import Spectrum, solve_equilibrium, spectrum
from .system import DynamicalSystem, as_system

__all__ = ["HopfPoint", "hopf_analysis"]

Array = NDArray[np.float64]
CArray = NDArray[np.complex128]

#: |Im lambda| below this share of the spectral radius: a real eigenvalue (divergence)
REAL_TOLERANCE = 1e-8
#: singular values of (J - lambda B) below this share of the largest: a null direction
NULL_TOLERANCE = 1e-7
#: a defective pair (collision, a Jordan block at i omega): eigenvalue condition number above
#: KAPPA_DEFECTIVE, or another eigenvalue closer than COALESCENCE_DISTANCE (share of the spectral
#: radius). A double eigenvalue perturbed by a relative error e splits by ~sqrt(e) and has
#: kappa ~ 1 / sqrt(e): with the complex-step Jacobian exact to e ~ 1e-12 (measured 1e-10 at
#: worst against finite differences), a computed separation below 1e-6 cannot be told from a
#: coalescence, and one above it is a simple pair. Simple pairs are plain Hopf points however
#: close their neighbour: only the range of validity of the normal form shrinks (a warning).
KAPPA_DEFECTIVE = 1e8
COALESCENCE_DISTANCE = 1e-6
#: spectrum symmetric under lambda -> -conj(lambda) to this share of the spectral radius
SYMMETRY_TOLERANCE = 1e-8
#: crossing speed below this share of |d lambda / dp|: no transversal crossing
TRANSVERSALITY_TOLERANCE = 1e-9
#: a plain Hopf point with another eigenvalue this close (share of |lambda|): a warning that the
#: normal form holds only for |p - p_c| well below (distance) / |d lambda / dp|
NEAR_RESONANCE = 0.05
#: |l1| at most this many times its error bound (a bound, not an estimate: measured errors are 1e2-1e6
#: times smaller, docs/postcritical.md): l1 = 0 to its accuracy, the sign undecided
L1_ZERO_FACTOR = 1.0
#: relative accuracy of l1 aimed at: while the bound is larger, the circles are tried at these
#: multiples of the given radius in turn (a larger one: less rounding; smaller ones: a singularity
#: or seam nearer than the radius), and the smallest bound is kept
L1_TARGET = 1e-6
RADIUS_LADDER = (1.0, 4.0, 0.25, 1.0 / 16.0)
#: Newton refinement of the onset: |Re lambda| below this share of |lambda|, or below
#: ONSET_RESOLUTION x eps x ||J||_F, the rounding of an eigenvalue of the pencil (QZ is backward
#: stable to eps ||J||): a state with stiff modes (the kept modes of massive beam mounts) has a
#: norm thousands of times its onset frequency
ONSET_TOLERANCE = 1e-13
ONSET_RESOLUTION = 4.0
ONSET_ITERATIONS = 40


@dataclass(frozen=True, eq=False)
class HopfPoint:
    """The onset of instability of an equilibrium and, for a Hopf point, its normal form.

    Attributes
    ----------
    parameter : float
        ``p_c`` (units ``parameter_units``).
    state : (n,) array
        The equilibrium ``x_c`` at ``p_c``.
    onset : {"hopf", "divergence"}
        A complex pair on the imaginary axis, or a real eigenvalue at zero.
    eigenvalue : complex
        The critical eigenvalue ``i omega`` (its residual real part shows the refinement).
    omega : float or None
        Angular frequency at onset (rad per time unit); None for a divergence.
    eigenvector, adjoint : (n,) complex arrays or None
        ``q`` (``A q = i omega q``, ``q^H q = 1``, its first largest component real positive) and ``p``
        (``A^H p = -i omega p``, ``p^H q = 1``) of the explicit state matrix ``A = B^-1 J``.
    lyapunov_coefficient : float or None
        First Lyapunov coefficient ``l1`` in Kuznetsov's normalisation (units
        ``1 / (time state^2)`` in the Euclidean norm of the state); None when degenerate.
    lyapunov_error : float or None
        Error bound of ``l1`` (rounding and truncation of the derivatives, propagated, and the
        change between two Cauchy circles).
    normal_form_coefficient : complex or None
        ``c1`` of ``z' = (sigma + i omega) z + c1 z |z|^2`` (``Re c1 = omega l1``).
    crossing_speed : float or None
        ``d Re(lambda) / dp`` at ``p_c`` along the equilibrium branch (1 / (time parameter unit)).
    frequency_slope : float or None
        ``d Im(lambda) / dp``.
    bifurcation : {"supercritical", "subcritical", "degenerate"}
    reason : str or None
        Why the plain theory does not apply (when degenerate).
    h20, h11 : arrays or None
        Second-order centre-manifold coefficients (``h11`` real).
    equilibrium_slope : (n,) array or None
        ``d x_c / dp``.
    spectrum : (n,) complex array
        All eigenvalues of ``(J, B)`` at ``p_c``.
    eigenvalue_condition : float
        ``|w| |B q| / |w^H B q|`` of the critical eigenvalue (large: nearly defective).
    multiplicity : int
        Number of independent eigenvectors at ``i omega`` (2 for a symmetric double pair).
    """

    parameter: float
    state: Array
    onset: str
    eigenvalue: complex
    omega: float | None
    eigenvector: CArray | None
    adjoint: CArray | None
    lyapunov_coefficient: float | None
    lyapunov_error: float | None
    normal_form_coefficient: complex | None
    crossing_speed: float | None
    frequency_slope: float | None
    bifurcation: str
    reason: str | None
    h20: CArray | None
    h11: Array | None
    equilibrium_slope: Array | None
    spectrum: CArray
    eigenvalue_condition: float
    multiplicity: int
    refined: bool
    iterations: int
    derivative_method: str
    parameter_derivative_method: str
    derivative_check: dict = field(default_factory=dict)
    state_names: tuple[str, ...] = ()
    state_units: tuple[str, ...] = ()
    parameter_name: str = "p"
    parameter_units: str = ""
    time_units: str = "s"
    warnings: tuple[str, ...] = ()

    # ----------------------------------------------------------------- derived numbers
    @property
    def period(self) -> float | None:
        """``2 pi / omega`` at onset (time units)."""
        return None if not self.omega else 2 * math.pi / self.omega

    @property
    def frequency(self) -> float | None:
        """``omega / 2 pi`` (cycles per time unit, Hz for seconds)."""
        return None if not self.omega else self.omega / (2 * math.pi)

    @property
    def cycle_side(self) -> int:
        """+1 when the cycles are born for ``p > p_c``, -1 for ``p < p_c``, 0 when unknown."""
        c1, s = self.normal_form_coefficient, self.crossing_speed
        if self.bifurcation == "degenerate" or c1 is None or not s:
            return 0
        return 1 if -s / c1.real > 0 else -1

    def normal_form_radius(self, p: float | NDArray) -> float | NDArray:
        """Normal-form radius ``rho = sqrt(-sigma' (p - p_c) / Re c1)``; NaN where no cycle is predicted.

        ``rho = |z|`` with ``x - x_c = 2 Re(z q) + ...`` and ``q^H q = 1``, so ``2 rho |q_j|`` is the
        first-order amplitude (half peak-to-peak) of state ``j``.
        """
        c1 = self._require()
        r2 = -self.crossing_speed * (np.asarray(p, dtype=float) - self.parameter) / c1.real
        return np.sqrt(np.where(r2 >= 0, r2, np.nan))

    def predicted_period(self, p: float | NDArray) -> float | NDArray:
        """Normal-form period ``2 pi / (omega + omega' (p - p_c) + Im(c1) rho^2)`` (time units)."""
        c1 = self._require()
        dp = np.asarray(p, dtype=float) - self.parameter
        rho = self.normal_form_radius(p)
        return 2 * np.pi / (self.omega + self.frequency_slope * dp + c1.imag * rho ** 2)

    def predicted_cycle(self, p: float, points: int = 256, order: int = 2) -> Array:
        """States ``(points, n)`` over one period of the normal-form cycle at ``p`` (phase 0 first).

        ``order = 1``: ``x_c(p) + 2 Re(rho q e^{i theta})``; ``order = 2`` adds
        ``Re(h20 rho^2 e^{2 i theta}) + h11 rho^2``. ``x_c(p) = x_c + (dx_c/dp) (p - p_c)``.
        """
        self._require()
        rho = float(self.normal_form_radius(p))
        if not math.isfinite(rho):
            raise ModelError("p", p, f"no cycle is predicted on this side of the onset p_c = {self.parameter:.10g}")
        theta = 2 * np.pi * np.arange(points) / points
        z = rho * np.exp(1j * theta)
        x = (self.state + self.equilibrium_slope * (p - self.parameter))[None, :] + 2 * np.real(z[:, None] * self.eigenvector[None, :])
        if order >= 2:
            x = x + np.real(z[:, None] ** 2 * self.h20[None, :]) + (rho ** 2) * self.h11[None, :]
        return x

    def predicted_amplitude(self, p: float, order: int = 1) -> Array:
        """Half peak-to-peak of each state over the normal-form cycle at ``p`` (state units).

        ``order = 1`` is ``2 rho |q_j|``; ``order = 2`` measures the second-order cycle.
        """
        if order == 1:
            return 2 * float(self.normal_form_radius(p)) * np.abs(self.eigenvector)
        x = self.predicted_cycle(p, points=1024, order=order)
        return 0.5 * (x.max(axis=0) - x.min(axis=0))

    def _require(self) -> complex:
        if self.bifurcation == "degenerate" or self.normal_form_coefficient is None:
            raise ModelError("hopf", self.bifurcation, f"no normal-form prediction at a degenerate onset ({self.reason})")
        return self.normal_form_coefficient

    def to_dict(self) -> dict:
        """JSON-ready summary (complex numbers as [re, im])."""
        def cx(v):
            return None if v is None else [float(np.real(v)), float(np.imag(v))]

        return {
            "parameter": self.parameter, "parameter_name": self.parameter_name, "onset": self.onset,
            "omega": self.omega, "period": self.period, "eigenvalue": cx(self.eigenvalue),
            "lyapunov_coefficient": self.lyapunov_coefficient, "lyapunov_error": self.lyapunov_error,
            "normal_form_coefficient": cx(self.normal_form_coefficient),
            "crossing_speed": self.crossing_speed, "frequency_slope": self.frequency_slope,
            "bifurcation": self.bifurcation, "reason": self.reason,
            "state": self.state.tolist(), "state_names": list(self.state_names),
            "eigenvector": None if self.eigenvector is None else [cx(v) for v in self.eigenvector],
            "eigenvalue_condition": self.eigenvalue_condition, "multiplicity": self.multiplicity,
            "refined": self.refined, "iterations": self.iterations,
            "derivative_method": self.derivative_method,
            "parameter_derivative_method": self.parameter_derivative_method,
            "derivative_check": self.derivative_check, "warnings": list(self.warnings),
        }

    def __repr__(self) -> str:
        l1 = "n/a" if self.lyapunov_coefficient is None else f"{self.lyapunov_coefficient:.6g}"
        om = "n/a" if self.omega is None else f"{self.omega:.8g}"
        why = f", {self.reason}" if self.reason else ""
        return (f"HopfPoint({self.parameter_name} = {self.parameter:.10g}, {self.onset}, omega = {om}, "
                f"l1 = {l1}, {self.bifurcation}{why})")


# --------------------------------------------------------------------------- analysis
def hopf_analysis(
    f,
    x0: NDArray,
    p0: float,
    *,
    bracket: tuple[float, float] | None = None,
    omega: float | None = None,
    refine: bool = True,
    radius: float = CIRCLE_RADIUS,
    points: int = CIRCLE_POINTS,
    check: bool = True,
) -> HopfPoint:
    """Locate and analyse the onset of instability of an equilibrium of ``B x' = f(x, p)``.

    Parameters
    ----------
    f : DynamicalSystem or callable
        The system; a plain callable ``f(x, p)`` is a single-state system without mass matrix.
    x0 : (n,) array
        The equilibrium at ``p0``, or a guess for it (Newton's method polishes it).
    p0 : float
        Parameter at (or near) the onset, e.g. the critical load of a linear analysis.
    bracket : (float, float), optional
        An interval in which ``max Re(lambda)`` changes sign; the onset is located in it by
        Brent's method before the Newton refinement.
    omega : float, optional
        Expected onset frequency (rad per time unit): picks the critical pair among several
        near the axis. Default: the eigenvalue (``Im >= 0``) closest to the imaginary axis.
    refine : bool
        Newton's method on ``Re lambda(p) = 0`` with the exact eigenvalue derivative (quadratic
        convergence); ``False`` analyses at ``p0`` as given.
    radius, points : float, int
        Cauchy circle of the second and third derivatives (radius in units of the state scale).
        While the bound of ``l1`` exceeds ``L1_TARGET |l1|``, circles of ``RADIUS_LADDER`` times
        ``radius`` are tried too, and the smallest bound is kept (``derivative_check["circle_radius"]``).
    check : bool
        Compare the complex-step Jacobian with central differences and the forms between two
        circles (:func:`impstab.postcritical.derivatives.check_derivatives`); a Jacobian
        discrepancy above 1e-6 adds a warning (``f`` may not be analytic).

    Returns
    -------
    HopfPoint
        ``bifurcation`` "supercritical" (``l1 < 0``), "subcritical" (``l1 > 0``) or "degenerate"
        with ``reason``: a divergence (real eigenvalue), a symmetric double pair, a collision on
        the axis (reversible / undamped 1:1 resonance), a pair that stays on the axis, a
        non-transversal crossing or ``l1 = 0`` to its accuracy.
    """
    x0 = np.asarray(x0, dtype=float).reshape(-1)
    system = as_system(f, x0.size)
    p = float(p0)
    if not math.isfinite(p):
        raise ModelError("p0", p0, "must be a finite number")
    x = solve_equilibrium(system, x0, p)
    if bracket is not None:
        p, x = _locate_in_bracket(system, x, p, bracket)
    mass = system.mass
    spec = spectrum(jacobians(system, x[None], p)[0], mass)
    target = 1j * omega if omega is not None else None
    idx = _pick(spec, target)
    lam = complex(spec.eigenvalues[idx])
    iterations, refined = 0, False
    if refine:
        p, x, lam, iterations, refined = _refine(system, x, p, lam, bracket)
    hopf = _analyse(system, x, p, lam, iterations, refined, radius, points, check)
    if refine and not refined:
        note = (f"the onset was not refined to |Re lambda| <= {ONSET_TOLERANCE:g} |lambda| (or its rounding) in "
                f"{iterations} Newton steps (Re lambda = {hopf.eigenvalue.real:.3g})")
        hopf = replace(hopf, warnings=hopf.warnings + (note,))
    return hopf


def _pick(spec: Spectrum, target: complex | None) -> int:
    lam = spec.eigenvalues
    if target is not None:
        return spec.nearest(target)
    d = np.where(lam.imag >= -1e-300, np.abs(lam.real), np.inf)
    return int(np.argmin(d))


def _growth(system: DynamicalSystem, x: Array, p: float) -> tuple[float, Array]:
    x = solve_equilibrium(system, x, p)
    lam = spectrum(jacobians(system, x[None], p)[0], system.mass).eigenvalues
    return float(np.max(lam.real)), x


def _locate_in_bracket(system, x, p, bracket) -> tuple[float, Array]:
    a, b = (float(v) for v in bracket)
    if not (math.isfinite(a) and math.isfinite(b) and a < b):
        raise ModelError("bracket", bracket, "must be two finite numbers, lower first")
    memo = {"x": x}

    def g(q):
        val, memo["x"] = _growth(system, memo["x"], q)
        return val

    ga, gb = g(a), g(b)
    if ga * gb > 0:
        raise ModelError("bracket", bracket, f"max Re(lambda) must change sign in it (it is {ga:.3g} and {gb:.3g})")
    root = brentq(g, a, b, xtol=1e-14 * max(1.0, abs(a), abs(b)), rtol=4 * np.finfo(float).eps, maxiter=200)
    _, x = _growth(system, memo["x"], root)
    return root, x


def _eigen_derivative(system, forms: Forms, jac, spec, idx) -> tuple[complex, Array, str]:
    """``d lambda / dp`` along the equilibrium branch and ``dx_c/dp``."""
    q = spec.right[:, idx]
    w = spec.left[:, idx]
    fp, method = forms.parameter()
    x_p = -np.linalg.solve(jac, fp)
    djq, _ = forms.jacobian_total_derivative(q, x_p)
    dlam = complex(np.vdot(w, djq) / np.vdot(w, system.mass @ q))
    return dlam, x_p, method


def _refine(system, x, p, lam, bracket):
    lo, hi = (-math.inf, math.inf) if bracket is None else (float(bracket[0]), float(bracket[1]))
    refined = False
    for it in range(1, ONSET_ITERATIONS + 1):
        jac = jacobians(system, x[None], p)[0]
        spec = spectrum(jac, system.mass)
        idx = spec.nearest(lam, upper=True)
        lam = complex(spec.eigenvalues[idx])
        resolution = ONSET_RESOLUTION * np.finfo(float).eps * float(np.linalg.norm(jac))
        if abs(lam.real) <= max(ONSET_TOLERANCE * abs(lam), resolution, 1e-300):
            return p, x, lam, it - 1, True
        forms = Forms(system, x, p)
        dlam, x_p, _ = _eigen_derivative(system, forms, jac, spec, idx)
        if not (math.isfinite(dlam.real) and dlam.real != 0.0):
            break
        step = -lam.real / dlam.real
        p_new = min(max(p + step, lo), hi)
        try:
            x = solve_equilibrium(system, x + x_p * (p_new - p), p_new)
        except NumericalError:
            break
        if abs(p_new - p) <= 4 * np.finfo(float).eps * max(1.0, abs(p)):
            p = p_new
            refined = True
            break
        p = p_new
    jac = jacobians(system, x[None], p)[0]
    spec = spectrum(jac, system.mass)
    lam = complex(spec.eigenvalues[spec.nearest(lam, upper=True)])
    return p, x, lam, it, refined


def _normalize(q: CArray) -> CArray:
    """``q^H q = 1`` with the first of its largest components (ties within 1e-8) real positive."""
    q = q / np.linalg.norm(q)
    mag = np.abs(q)
    k = int(np.flatnonzero(mag >= (1 - 1e-8) * mag.max())[0])
    return q * (mag[k] / q[k])


def _analyse(system, x, p, lam, iterations, refined, radius, points, check) -> HopfPoint:
    n = system.dimension
    mass = system.mass
    jac = jacobians(system, x[None], p)[0]
    spec = spectrum(jac, mass)
    idx = spec.nearest(lam, upper=True)
    lam = complex(spec.eigenvalues[idx])
    scale = max(float(np.max(np.abs(spec.eigenvalues))), 1e-300)
    forms = Forms(system, x, p, radius=radius, points=points)
    warnings: list[str] = []
    checks: dict = {}
    if check:
        checks = check_derivatives(system, x, p, radius=radius, points=points)
        if checks["jacobian"] > 1e-6:
            warnings.append(f"complex-step and finite-difference Jacobians differ by {checks['jacobian']:.2e} "
                            "(relative): is f analytic in its complex extension?")
    q = _normalize(spec.right[:, idx])
    w = spec.left[:, idx]
    wbq = np.vdot(w, mass @ q)
    kappa = float(np.linalg.norm(w) * np.linalg.norm(mass @ q) / max(abs(wbq), 1e-300))
    dlam, x_p, p_method = _eigen_derivative(system, forms, jac, spec, idx) \
        if abs(wbq) > 0 else (complex(np.inf), np.full(n, np.nan), "n/a")
    onset = "hopf"
    reason = None
    multiplicity = 1
    if abs(lam.imag) <= REAL_TOLERANCE * scale:
        onset = "divergence"
        reason = ("divergence: a real eigenvalue crosses zero (a static instability, fold or pitchfork of "
                  "equilibria): no limit cycle is born")
    else:
        reason, multiplicity = _degeneracy(jac, mass, spec, idx, lam, kappa, dlam, scale, system.state_scale)
    base = dict(parameter=float(p), state=x, onset=onset, eigenvalue=lam,
                omega=None if onset == "divergence" else abs(lam.imag),
                spectrum=spec.eigenvalues, eigenvalue_condition=kappa, multiplicity=multiplicity,
                refined=refined, iterations=iterations, derivative_method=forms.method,
                parameter_derivative_method=p_method, derivative_check=checks,
                state_names=system.state_names, state_units=system.state_units,
                parameter_name=system.parameter_name, parameter_units=system.parameter_units,
                time_units=system.time_units)
    transversal = math.isfinite(dlam.real)
    if reason is not None:
        return HopfPoint(eigenvector=q if onset == "hopf" else None, adjoint=None, lyapunov_coefficient=None,
                         lyapunov_error=None, normal_form_coefficient=None,
                         crossing_speed=float(dlam.real) if transversal else None,
                         frequency_slope=float(dlam.imag) if transversal else None,
                         bifurcation="degenerate", reason=reason, h20=None, h11=None,
                         equilibrium_slope=x_p if transversal else None, warnings=tuple(warnings), **base)
    near = _near_eigenvalue_warning(spec, idx, lam, kappa, dlam, system)
    if near:
        warnings.append(near)
    if lam.imag < 0:
        q, w, lam = np.conj(q), np.conj(w), np.conj(lam)
    om = lam.imag
    w_t = w / np.conj(np.vdot(w, mass @ q))          # w_t^H B q = 1
    adjoint = mass.T @ w_t                             # p = B^H w_t, p^H q = 1
    # the circle's radius: the given one, then smaller ones while the bound stays above
    # L1_TARGET |l1| (a singularity or a seam closer than the radius shows as a large tail or
    # a disagreement with the half circle); the smallest bound wins
    best = None
    ladder = [radius * f for f in RADIUS_LADDER] if forms.method != "analytic" else [radius]
    for r in ladder:
        c1, h20, h11, err = _first_coefficient(Forms(system, x, p, radius=r, points=points), jac, mass, q, w_t, om)
        l1_err = err / om
        if forms.method != "analytic":
            c1b = _first_coefficient(Forms(system, x, p, radius=r / 2, points=2 * points), jac, mass, q, w_t, om)[0]
            l1_err = max(l1_err, abs(c1b.real - c1.real) / om)
        if best is None or l1_err < best[3]:
            best = (c1, h20, h11, l1_err, r)
        if l1_err <= L1_TARGET * abs(c1.real / om):
            break
    c1, h20, h11, l1_err, r = best
    l1 = c1.real / om
    if forms.method != "analytic":
        checks = dict(checks, circle_radius=float(r))
        base["derivative_check"] = checks
    kw = dict(eigenvector=q, adjoint=adjoint, crossing_speed=float(dlam.real), frequency_slope=float(dlam.imag),
              h20=h20, h11=h11, equilibrium_slope=x_p, warnings=tuple(warnings))
    if abs(l1) <= L1_ZERO_FACTOR * l1_err:
        return HopfPoint(lyapunov_coefficient=None, lyapunov_error=float(l1_err), normal_form_coefficient=None,
                         bifurcation="degenerate",
                         reason=(f"l1 = 0 to its accuracy (computed {l1:.3g}, error bound {l1_err:.3g}): a generalized "
                                 "(Bautin) Hopf point; the second Lyapunov coefficient decides"),
                         **kw, **base)
    return HopfPoint(lyapunov_coefficient=float(l1), lyapunov_error=float(l1_err), normal_form_coefficient=complex(c1),
                     bifurcation="supercritical" if l1 < 0 else "subcritical", reason=None, **kw, **base)


def _first_coefficient(forms: Forms, jac, mass, q, w_t, om) -> tuple[complex, CArray, Array, float]:
    """``c1`` (with ``h20``, ``h11``) and its propagated error bound."""
    qb = np.conj(q)
    b11 = forms.second(q, qb)
    b20 = forms.second(q, q)
    h11 = -np.linalg.solve(jac, b11.value).real
    res20 = 2j * om * mass - jac
    h20 = np.linalg.solve(res20, b20.value)
    c3 = forms.third(q, q, qb)
    bq = forms.second(q, h11)
    bqb = forms.second(qb, h20)
    g = np.vdot(w_t, c3.value + 2 * bq.value + bqb.value)
    nw = float(np.linalg.norm(w_t))
    inv11 = 1.0 / sla.svdvals(jac)[-1]
    inv20 = 1.0 / sla.svdvals(res20)[-1]
    op_q = np.linalg.norm(bq.value) / max(np.linalg.norm(h11), 1e-300)
    op_qb = np.linalg.norm(bqb.value) / max(np.linalg.norm(h20), 1e-300)
    err = 0.5 * nw * (c3.error + 2 * bq.error + 2 * op_q * inv11 * b11.error + bqb.error + op_qb * inv20 * b20.error)
    # rounding of the assembled sum
    err += 8 * np.finfo(float).eps * 0.5 * nw * (np.linalg.norm(c3.value) + 2 * np.linalg.norm(bq.value)
                                                  + np.linalg.norm(bqb.value))
    return complex(g / 2), h20, h11, float(err)


def _near_eigenvalue_warning(spec: Spectrum, idx, lam, kappa, dlam, system: DynamicalSystem) -> str | None:
    """A warning when another eigenvalue lies within NEAR_RESONANCE |lambda| of the simple critical one."""
    others = np.delete(spec.eigenvalues, idx)
    if not others.size:
        return None
    k = int(np.argmin(np.abs(others - lam)))
    gap = float(abs(others[k] - lam))
    if gap > NEAR_RESONANCE * abs(lam):
        return None
    span = gap / abs(dlam) if math.isfinite(abs(dlam)) and abs(dlam) > 0 else math.nan
    name = system.parameter_name
    unit = f" {system.parameter_units}" if system.parameter_units else ""
    return (f"near neighbour: eigenvalue {complex(others[k]):.6g} lies {gap:.3g} 1/{system.time_units} from the "
            f"critical one ({gap / abs(lam):.2e} of |lambda|, eigenvalue condition number {kappa:.3g}). The pair is "
            f"simple, so the Hopf theory and its label hold, but the single-pair normal form describes the cycles "
            f"only for |{name} - {name}_c| well below gap / |d lambda/d {name}| = {span:.3g}{unit}; farther out only "
            "the computed branch is reliable")


def _degeneracy(jac, mass, spec: Spectrum, idx, lam, kappa, dlam, scale, states=None) -> tuple[str | None, int]:
    """Why a pair at ``lam`` is not a plain Hopf point (None when it is), and the multiplicity.

    The null directions of ``J - lam B`` are counted in the state scales ``states`` (the
    similar pencil ``S^-1 (J, B) S``, ``S = diag(states)``: same eigenvalues, singular values of
    states in their units of "small"; a state of kg^0.5 m beside one of rad would otherwise set
    the rank test's scale)."""
    lam_all = spec.eigenvalues
    if states is not None:
        sc = np.asarray(states, dtype=float)
        jac, mass = jac * sc[None, :] / sc[:, None], mass * sc[None, :] / sc[:, None]
    shifted = jac - lam * mass
    u, s, vh = sla.svd(shifted)
    null = int(np.sum(s <= NULL_TOLERANCE * s[0]))
    others = np.delete(lam_all, idx)
    dist = float(np.min(np.abs(others - lam)) / scale) if others.size else math.inf
    mirror = np.array([np.min(np.abs(lam_all + np.conj(v))) for v in lam_all])
    symmetric_spectrum = bool(np.all(mirror <= SYMMETRY_TOLERANCE * scale))
    # a neighbour closer than the resolution with one eigenvector: a Jordan block (collision);
    # with two independent eigenvectors: a semisimple double pair unless their Gram matrix is singular
    defective = kappa >= KAPPA_DEFECTIVE or (null < 2 and dist <= COALESCENCE_DISTANCE)
    # in a reversible family (spectrum symmetric about the imaginary axis) a simple pair cannot
    # leave the axis: its mirror image would be a second eigenvalue next to it. A pair that
    # crosses there does so by colliding with its neighbour, however far apart rounding leaves
    # the two computed at the refined point (about sqrt(eps_J) of the radius, near the resolution
    # of COALESCENCE_DISTANCE)
    speed = abs(dlam) if math.isfinite(abs(dlam)) else math.inf
    crossing = math.isfinite(dlam.real) and abs(dlam.real) > TRANSVERSALITY_TOLERANCE * max(speed, 1e-300)
    near = others.size > 0 and float(np.min(np.abs(others - lam))) <= NEAR_RESONANCE * abs(lam)
    defective = defective or (symmetric_spectrum and null < 2 and crossing and near)
    if null >= 2:
        right = vh[-null:].conj().T
        left = u[:, -null:]
        gram = sla.svdvals(left.conj().T @ mass @ right)
        defective = defective or gram[-1] <= 1e-6 * max(gram[0], 1e-300)
    undamped = " (undamped: a reversible system)" if symmetric_spectrum else ""
    if defective:
        return (f"collision on the imaginary axis{undamped}: two pairs merge at i omega (a 1:1 resonance, "
                "d sigma/dp infinite); the onset is not a Hopf point: no isolated attracting cycles are born"), max(null, 1)
    if null >= 2:
        return (f"double Hopf / symmetric: {null} independent eigenvectors at i omega (a pair of multiplicity {null} "
                "crossing together); standing and rotating (whirling) cycles bifurcate; l1 of a single pair does "
                "not apply"), null
    if not math.isfinite(dlam.real):
        return "the crossing speed d sigma/dp is not finite", 1
    if not crossing:
        if symmetric_spectrum:
            return ("reversible / undamped: the pair stays on the imaginary axis (d sigma/dp = 0, spectrum symmetric "
                    "about the axis): no crossing, a conservative family of oscillations, no isolated attracting "
                    "cycles"), 1
        return "non-transversal: the pair touches the imaginary axis without crossing it (d sigma/dp = 0)", 1
    return None, 1
