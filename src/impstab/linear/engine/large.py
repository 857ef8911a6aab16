"""Large second-order problems: modal reduction with error checks, then the exact onset of the full
model by shift-invert (undamped) or Newton's method (damped) (a finite-element model with hundreds
of dofs).

For ``M q'' + (K0 + p K1) q = 0`` with symmetric ``M`` (positive definite) and ``K0`` of order
``n`` above :data:`LARGE_ORDER`:

1. *Modal basis.* The ``m`` lowest modes of ``K0 phi = omega^2 M phi`` by shift-invert Lanczos
   (``scipy.sparse.linalg.eigsh`` about 0), mass-normalised: accurate to rounding relative to each
   eigenvalue even when the stiff element modes make ``|M^-1 K|`` ten orders above them (a dense
   solver gets the lowest ones only to ``eps`` of the largest).
2. *Reduced problems.* ``Omega^2 + p Phi^T K1 Phi`` with ``m`` and ``2 m`` modes, solved by the
   engine (scan with the bubble searches, exact refinement). Error check: both find the same kind
   of first loss and their loads agree to :data:`TRUNCATION_TOLERANCE`; otherwise the basis is
   doubled (up to ``n / 2``; beyond that the problem is solved dense).
3. *The full model's onset.* The merging cluster of the full pencil ``(K(p), M)`` near the reduced
   onset is followed by shift-invert subspace iteration (right and left, ``k`` vectors, a sparse
   or dense LU of ``K(p) - sigma M``, ``sigma`` the cluster mean) until its projected matrix
   ``C = (Y^T M X)^-1 Y^T K X`` is converged to rounding. The engine's exact indicator
   ``Delta = k tr C^2 - (tr C)^2`` (divergence: ``tr C / k``) and its derivative
   ``Delta' = 2 k tr(C B) - 2 tr C tr B``, ``B = (Y^T M X)^-1 Y^T K1 X``, drive the same bracketed
   Newton iteration as the engine's refinement.
4. *Error check on the full model.* Every eigenvalue of the full ``M^-1 K`` just below the onset
   (``p_c (1 - 1e-6)``, one dense eigenvalue problem) must be stable by the engine's rule, and the
   cluster just above it complex (flutter) or through zero (divergence). If any check fails the
   problem goes to the dense route, with a warning saying why.

A damped problem ``M q'' + (D + G) q' + (K0 + p K1) q = 0`` (``D + G`` constant) of first-order
order above :data:`LARGE_ORDER` takes steps 1 and 2 with the first-order form of the reduced
system (``Phi^T (D + G) Phi`` as its damping), then :func:`damped_full_onset`: Newton's method on
``T(p, omega) x = 0`` of the full model from the reduced onset, and the same check below it.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
from numpy.typing import NDArray

from ..classify import classify_eigenvalues
from ..eigen import cluster_participation
from ...errors import NumericalError
from .tolerances import FLOOR, TOL_CLUSTER, TOL_DUPLICATE, TOL_UNSTABLE

__all__ = ["LARGE_ORDER", "BASIS", "TRUNCATION_TOLERANCE", "reducible", "modal_basis", "reduced_problem", "full_onset",
           "damped_full_onset", "stable_at"]

Array = NDArray[np.float64]

#: operators of undamped second-order problems above this order are reduced
LARGE_ORDER = 96
#: modes in the first reduced basis (it and its double are solved by the compiled routines)
BASIS = 12
#: relative agreement of the onsets with m and 2 m modes that accepts the truncation
TRUNCATION_TOLERANCE = 1e-4
#: relative move of a shift-invert shift that meets an exactly singular factorization (at a
#: coalescence the cluster's mean is the double eigenvalue): it must lift the smallest singular
#: value of ``K(p) - sigma M`` clear of the rounding of its entries (``eps max|K|``, about 1e-7 of a
#: 1e9 N/m beam mesh against eigenvalues near 1e3 1/s^2); the subspace iteration then still
#: gains the ratio of this distance to the next eigenvalue's (about 1e-6) per step
SHIFT_NUDGE = 1e-6


def reducible(problem) -> bool:
    """An affine second-order problem of large order with symmetric M and K0 (undamped, or damped
    with its ``D + G`` given)."""
    if not (problem.affine and problem.second_order is not None and problem.order > LARGE_ORDER):
        return False
    if not (problem.undamped or problem.damping is not None):
        return False
    m, k0 = problem.second_order[0], problem.second_order[1]
    scale_m, scale_k = np.abs(m).max(), np.abs(k0).max()
    return bool(np.abs(m - m.T).max() <= 1e-13 * scale_m and np.abs(k0 - k0.T).max() <= 1e-13 * scale_k)


def _sparse_or_dense(a: Array):
    import scipy.sparse as sparse  # only large systems need it (about 0.1 s of import)

    return sparse.csc_matrix(a) if np.count_nonzero(a) < 0.1 * a.size else a


def modal_basis(problem, m: int) -> tuple[Array, Array]:
    """The ``m`` lowest mass-normalised modes ``(omega^2, Phi)`` of ``K0 phi = omega^2 M phi``."""
    mass, k0, _ = problem.second_order
    n = mass.shape[0]
    if m >= n - 1:
        w, phi = sla.eigh(k0, mass)
    else:
        start = mass @ np.linspace(1.0, 2.0, n)  # a fixed start: the same basis on every run
        import scipy.sparse.linalg as spla

        w, phi = spla.eigsh(_sparse_or_dense(k0), k=m, M=_sparse_or_dense(mass), sigma=0.0, which="LM", v0=start)
    order = np.argsort(w)
    w, phi = w[order], phi[:, order]
    phi = phi / np.sqrt(np.einsum("ij,ik,kj->j", phi, mass, phi))
    return w, phi


def reduced_problem(problem, w: Array, phi: Array):
    """The problem of the modal basis (``M_r = I``): undamped, ``Omega^2 + p Phi^T K1 Phi``; damped,
    the first-order form of ``q'' + Phi^T (D + G) Phi q' + (Omega^2 + p Phi^T K1 Phi) q = 0``."""
    from ..eigen import state_matrices
    from .problems import Problem

    _, _, k1 = problem.second_order
    k1_r = np.ascontiguousarray(phi.T @ k1 @ phi)
    m = len(w)
    if problem.undamped:
        return Problem(True, problem.p_min, problem.p_max, problem.n_scan, m, m, np.diag(w).copy(), k1_r, np.ones(m))
    a0 = state_matrices(np.eye(m), phi.T @ problem.damping @ phi, np.diag(w))
    a1 = np.zeros_like(a0)
    a1[m:, :m] = -k1_r
    return Problem(False, problem.p_min, problem.p_max, problem.n_scan, 2 * m, m, a0, a1, np.ones(m))


class _Pencil:
    """The full pencil ``(K0 + p K1, M)`` and its cluster by shift-invert subspace iteration."""

    def __init__(self, problem) -> None:
        self.mass, self.k0, self.k1 = problem.second_order
        self.sparse = np.count_nonzero(self.k0) < 0.1 * self.k0.size

    def _factor(self, p: float, sigma: float):
        """``(solve, sigma)``: solves with the LU of ``K(p) - sigma M``.

        Shift-invert wants ``sigma`` next to the cluster, and at a coalescence its mean is the
        double eigenvalue itself: when the factorization meets an exactly zero pivot there, the
        shift moves by :data:`SHIFT_NUDGE` of ``|sigma|`` (of ``|p| max|K1| / max|M|``, the load's
        share of the eigenvalues, at a divergence's ``sigma = 0``); the returned ``sigma`` is the
        one factored (the iteration only needs it near the cluster).
        """
        size = abs(sigma) if sigma != 0.0 else abs(p) * np.abs(self.k1).max() / np.abs(self.mass).max()
        for nudge in (0.0, SHIFT_NUDGE, -SHIFT_NUDGE):
            s = sigma + nudge * size
            a = self.k0 + p * self.k1 - s * self.mass
            if self.sparse:
                import scipy.sparse as sparse
                import scipy.sparse.linalg as spla

                try:
                    lu = spla.splu(sparse.csc_matrix(a))
                except RuntimeError:  # "Factor is exactly singular"
                    continue
                return (lambda b, trans="N": lu.solve(b, trans=trans)), s
            lu = sla.lu_factor(a, check_finite=False)
            if np.all(np.diag(lu[0]) != 0.0):
                return (lambda b, trans="N": sla.lu_solve(lu, b, trans=0 if trans == "N" else 1)), s
        raise NumericalError(f"K(p) - sigma M is exactly singular at p = {p:.10g} for three shifts near {sigma:.6g}")

    def cluster(self, p: float, sigma: float, x: Array, y: Array, iterations: int = 30):
        """Right and left bases of the cluster near ``sigma`` at ``p``, and ``C``, ``B``.

        Subspace iteration with ``S = (K(p) - sigma M)^-1 M`` and its transpose. The cluster's
        matrix comes from the Ritz matrix of ``S`` itself, ``T = (Y^T M X)^-1 Y^T M S X``, as
        ``C = sigma I + T^-1``: no product with the stiff ``K`` (whose rounding, ``eps |K|``, is ten
        orders above the low eigenvalues of a fine mesh), only solves with its LU, which are backward
        stable. The iteration stops when ``tr C`` and ``tr C^2`` change by less than 64 eps, or stop
        changing less (the rounding floor; each step multiplies the error by the ratio of the
        cluster's distance to ``sigma`` to that of the next eigenvalue, tiny near a coalescence).
        """
        solve, sigma = self._factor(p, sigma)
        eye = np.eye(x.shape[1])
        prev, change = None, np.inf
        for _ in range(iterations):
            z = solve(self.mass @ x)
            g = y.T @ self.mass @ x
            t = np.linalg.solve(g, y.T @ self.mass @ z)
            c = sigma * eye + np.linalg.inv(t)
            b = np.linalg.solve(g, y.T @ self.k1 @ x)
            sums = np.array([np.trace(c), np.trace(c @ c)])
            x, _ = np.linalg.qr(z)
            y, _ = np.linalg.qr(solve(self.mass.T @ y, trans="T"))
            if prev is not None:
                new_change = float(np.max(np.abs(sums - prev) / np.maximum(np.abs(sums), 1e-300)))
                if new_change <= 64 * np.finfo(float).eps or new_change >= change:
                    break
                change = new_change
            prev = sums
        return x, y, c, b

    def stable_everywhere(self, p: float) -> bool:
        """Whether every eigenvalue of the full ``M^-1 K(p)`` is stable by the engine's rule."""
        s = sla.eigvals(self.k0 + p * self.k1, self.mass)
        unstable, _ = classify_eigenvalues(s[None], True, TOL_UNSTABLE, TOL_CLUSTER, FLOOR, TOL_DUPLICATE)
        return not bool(unstable[0])


def stable_at(problem, p: float) -> bool:
    """Whether the full model is stable at ``p`` (every eigenvalue, dense)."""
    if problem.undamped:
        return _Pencil(problem).stable_everywhere(p)
    return _first_order_stable(problem, p)


def _first_order_stable(problem, p: float) -> bool:
    """Whether every eigenvalue of the full first-order operator ``a0 + p a1`` is stable by the
    engine's rule (one dense eigenvalue problem)."""
    a0, a1 = problem.operators()
    vals = np.linalg.eigvals(a0 + p * a1)
    unstable, _ = classify_eigenvalues(vals[None], False, TOL_UNSTABLE, TOL_CLUSTER, FLOOR, TOL_DUPLICATE)
    return not bool(unstable[0])


def _indicator(c: Array, b: Array, divergence: bool) -> tuple[float, float]:
    k = c.shape[0]
    if divergence:
        return float(np.trace(c).real / k), float(np.trace(b).real / k)
    tc, tb = np.trace(c), np.trace(b)
    return float((k * np.trace(c @ c) - tc * tc).real), float((2 * k * np.trace(c @ b) - 2 * tc * tb).real)


def full_onset(problem, reduced_load: float, kind: str, omega: float, w: Array, phi: Array, width: float):
    """The full model's onset near the reduced one (see the module notes), or ``(None, reason)``.

    Returns ``((load, kind, omega, mode, participation), "")`` on success.
    """
    from .roots import newton_step

    pencil = _Pencil(problem)
    divergence = kind == "divergence"
    # the reduced cluster at its onset, lifted to the full model
    a_r = np.diag(w) + reduced_load * (phi.T @ pencil.k1 @ phi)
    s, v = np.linalg.eig(a_r)
    # the cluster: the eigenvalues at the onset value s_c = omega^2 (divergence: 0), relative to
    # the spectral radius of the reduced operator
    s_c = 0.0 if divergence else omega * omega
    sel = np.flatnonzero(np.abs(s - s_c) <= 1e-4 * max(abs(s_c), 1e-6 * np.abs(s).max()))
    if sel.size < (1 if divergence else 2):
        return None, "the reduced onset's cluster could not be identified"
    lifted = phi @ v[:, sel]  # a real basis of the cluster's (real) invariant subspace
    x = np.linalg.svd(np.concatenate([lifted.real, lifted.imag], axis=1), full_matrices=False)[0][:, : sel.size]
    y = pencil.mass @ x
    sigma = float(np.mean(s[sel].real)) if not divergence else 0.0

    def value(p: float, sigma: float, x: Array, y: Array):
        x, y, c, b = pencil.cluster(p, sigma, x, y)
        f, df = _indicator(c, b, divergence)
        return f, df, x, y, c

    lo, hi = reduced_load * (1 - width), reduced_load * (1 + width)
    for _ in range(6):  # widen until the indicator changes sign over the bracket
        f_lo, _, x_lo, y_lo, _ = value(lo, sigma, x, y)
        f_hi, _, x_hi, y_hi, _ = value(hi, sigma, x, y)
        if np.sign(f_lo) != np.sign(f_hi):
            break
        lo, hi = reduced_load - 4 * (reduced_load - lo), reduced_load + 4 * (hi - reduced_load)
    else:
        return None, "the exact indicator of the full model did not change sign near the reduced onset"
    st = np.array([lo, hi, f_lo, np.nan])
    p = lo - f_lo * (hi - lo) / (f_hi - f_lo)
    root = None
    for _ in range(60):
        f, df, x, y, c = value(p, sigma, x, y)
        if not divergence:
            sigma = float(np.trace(c).real / c.shape[0])
        new, done = newton_step(st, p, f, df)
        if done:
            root = new
            break
        p = new
    if root is None:
        return None, "the Newton iteration on the full model did not converge"
    below = root - 1e-6 * abs(root) * np.sign(hi - lo)
    if not pencil.stable_everywhere(below):
        return None, f"the full model is already unstable at {below:.10g}, below the reduced onset"
    x, y, c, _ = pencil.cluster(root, sigma, x, y)
    vals, vecs = np.linalg.eig(c)
    shapes = x @ vecs
    if divergence:
        omega = 0.0
    else:
        omega = float(np.sqrt(max(np.trace(c).real / c.shape[0], 0.0)))
    lead = int(np.argmax(np.abs(vals.imag))) if not divergence else 0
    mode = shapes[:, lead]
    big = int(np.argmax(np.abs(mode)))
    mode = mode * np.conj(mode[big]) / abs(mode[big]) ** 2
    part = cluster_participation(shapes, vals, np.ones(len(vals), dtype=bool), np.diag(pencil.mass), TOL_DUPLICATE)
    return (float(root), kind, omega, mode, part), ""


def damped_full_onset(problem, reduced_load: float, kind: str, omega: float, mode: NDArray[np.complex128],
                      phi: Array):
    """The full damped model's onset near the reduced one, or ``(None, reason)``.

    Flutter (a Hopf point, ``lambda = i omega``): Newton's method on ``T(p, omega) x = 0``,
    ``T = K0 + p K1 - omega^2 M + i omega (D + G)``, with ``l^H x = 1`` (``l`` the lifted reduced
    mode ``x0 = Phi y``): each step solves ``T z1 = K1 x`` and ``T z2 = (i (D + G) - 2 omega M) x``
    with one LU of ``T``, takes ``(dp, domega)`` real from ``dp l^H z1 + domega l^H z2 = -1`` and
    ``x <- -(dp z1 + domega z2)``; quadratic convergence from the reduced onset, and no product with
    the stiff ``K0``, only backward-stable solves (as in the undamped route). Divergence
    (``lambda = 0``): the same with ``omega = 0`` and real ``x``. Then the checks of the undamped
    route: every eigenvalue of the full first-order operator just below the onset is stable (one
    dense eigenvalue problem); the participation is that of the null space of ``T`` at the onset
    (a repeated pair of a symmetric layout gets the basis-independent participation of its
    eigenspace).

    Returns ``((load, kind, omega, mode, participation), "")`` on success.
    """
    mass, k0, k1 = problem.second_order
    c = problem.damping
    divergence = kind == "divergence"

    def dynamic_stiffness(p: float, w: float):
        return k0 + p * k1 if divergence else k0 + p * k1 - w * w * mass + 1j * w * c

    x = phi @ (mode.real if divergence else mode)
    ell = np.conj(x) / np.vdot(x, x)
    p, w = float(reduced_load), 0.0 if divergence else float(omega)
    previous, converged = np.inf, False
    for it in range(40):
        lu = sla.lu_factor(dynamic_stiffness(p, w), check_finite=False)
        z1 = sla.lu_solve(lu, k1 @ x, check_finite=False)
        if divergence:
            dp, dw = -1.0 / float(ell @ z1), 0.0
            x = -dp * z1
        else:
            z2 = sla.lu_solve(lu, (1j * c - 2.0 * w * mass) @ x, check_finite=False)
            a1, a2 = ell @ z1, ell @ z2
            dp, dw = np.linalg.solve(np.array([[a1.real, a2.real], [a1.imag, a2.imag]]), np.array([-1.0, 0.0]))
            x = -(dp * z1 + dw * z2)
        p, w = p + float(dp), w + float(dw)
        if not (np.isfinite(p) and np.isfinite(w) and np.isfinite(x).all()):
            return None, "the Newton iteration on the full model left the finite numbers"
        size = abs(dp) / abs(p) + abs(dw) / max(abs(w), 1e-300)
        # converged to rounding: a step of a few eps, or steps that stopped shrinking (the floor)
        if size <= 8 * np.finfo(float).eps or (it >= 3 and size >= previous and previous <= 1e-10):
            converged = True
            break
        previous = size
    if not converged:
        return None, "the Newton iteration on the full model did not converge"
    if abs(p - reduced_load) > 100 * TRUNCATION_TOLERANCE * abs(reduced_load):
        return None, f"the Newton iteration on the full model went to {p:.10g}, far from the reduced onset"
    below = p - 1e-6 * abs(p)  # towards p_min
    if not _first_order_stable(problem, below):
        return None, f"the full model is already unstable at {below:.10g}, below its onset near the reduced one"
    # the mode's cluster: the null space of T at the onset, from its smallest singular values up
    # to the first gap of four orders of magnitude (a repeated pair of a symmetric layout: two);
    # the rest of the spectrum is at least a frequency away, ten orders above the rounding
    _, sv, vh = np.linalg.svd(dynamic_stiffness(p, w))
    sv, vh = sv[::-1], vh[::-1]
    k = 1
    while k < len(sv) and sv[k] <= 1e4 * max(sv[k - 1], 1e-300):
        k += 1
    if k == len(sv) or sv[k - 1] > 1e-6 * sv[k]:
        return None, f"the null space of the full model at the onset is not separated (singular values {sv[:3]})"
    shapes = vh[:k].conj().T
    part = cluster_participation(shapes, np.full(k, 1j * w), np.ones(k, dtype=bool), np.diag(mass), TOL_DUPLICATE)
    lead = x / x[int(np.argmax(np.abs(x)))]
    return (float(p), kind, abs(w), lead.astype(complex), part), ""
