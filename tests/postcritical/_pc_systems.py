"""Test systems with closed-form or published answers (vectorized: states along the first axis)."""

from __future__ import annotations

import numpy as np

from impstab.postcritical import DynamicalSystem


def bautin(p2: float, omega: float = 1.0, extra: float | None = None) -> DynamicalSystem:
    """x1' = w [x1 g - x2], x2' = w [x2 g + x1], g = p1 + p2 r - r^2, r = x1^2 + x2^2.

    Hopf at p1 = 0 with frequency w, l1 = 2 p2 (q^H q = 1) for every w; cycles
    r = (p2 +- sqrt(p2^2 + 4 p1)) / 2, fold of cycles at p1 = -p2^2 / 4, period 2 pi / w.
    ``extra``: a third, decoupled state x3' = -extra x3 (Floquet multiplier exp(-extra T)).
    """
    def f(x, p1):
        x1, x2 = x[:, 0], x[:, 1]
        r = x1 ** 2 + x2 ** 2
        g = p1 + p2 * r - r ** 2
        out = [omega * (x1 * g - x2), omega * (x2 * g + x1)]
        if extra is not None:
            out.append(-extra * x[:, 2])
        return np.stack(out, axis=-1)

    return DynamicalSystem(f, 2 if extra is None else 3, vectorized=True, parameter_name="p1")


def bautin_radius(p1: float, p2: float, sign: int) -> float:
    """Squared radius r of the cycle of :func:`bautin` (sign +1: outer, -1: inner)."""
    return (p2 + sign * np.sqrt(p2 ** 2 + 4 * p1)) / 2


def bautin_multiplier(p1: float, p2: float, sign: int, omega: float = 1.0) -> float:
    """Nontrivial multiplier exp(T d(rho')/d rho): rho' = w rho g(rho^2), T = 2 pi / w."""
    r = bautin_radius(p1, p2, sign)
    return float(np.exp(2 * np.pi * 2 * r * (p2 - 2 * r)))


def van_der_pol(vectorized: bool = True) -> DynamicalSystem:
    """x'' - mu (1 - x^2) x' + x = 0 as x' = y, y' = mu (1 - x^2) y - x; parameter mu."""
    if vectorized:
        def f(x, mu):
            return np.stack([x[:, 1], mu * (1 - x[:, 0] ** 2) * x[:, 1] - x[:, 0]], axis=-1)
    else:
        def f(x, mu):
            return np.array([x[1], mu * (1 - x[0] ** 2) * x[1] - x[0]])
    return DynamicalSystem(f, 2, vectorized=vectorized, parameter_name="mu")


#: van der Pol, mu = 1: period and largest x of the limit cycle (published to 9-10 digits)
VDP_PERIOD = 6.663286859
VDP_MAX_X = 2.008619861


def clock_twist(kind: str, b: float = -1.0, omega: float = 1.0, kappa: float = 0.37) -> DynamicalSystem:
    """A stable clock u on the unit circle driving a transverse plane v; parameter a.

    kind "period-doubling": v rotates by half a turn per period (v = R(w t / 2) w_, w_' = diag(a, b) w_
    - |w_|^2 w_), so the multipliers of the cycle (u on the circle, v = 0) are 1, exp(-4 pi / w),
    -exp(a T), -exp(b T): a period doubling exactly at a = 0.
    kind "torus": v' = (kappa J + a) v - |v|^2 v: multipliers exp(a T +- i kappa T), a Neimark-Sacker
    point exactly at a = 0.
    """
    def f(x, a):
        u1, u2, v1, v2 = x[:, 0], x[:, 1], x[:, 2], x[:, 3]
        r = u1 ** 2 + u2 ** 2
        s = v1 ** 2 + v2 ** 2
        du1 = u1 * (1 - r) - omega * u2
        du2 = u2 * (1 - r) + omega * u1
        if kind == "period-doubling":
            c, d = (a + b) / 2, (a - b) / 2
            dv1 = -omega / 2 * v2 + c * v1 + d * (u1 * v1 + u2 * v2) - s * v1
            dv2 = omega / 2 * v1 + c * v2 + d * (u2 * v1 - u1 * v2) - s * v2
        else:
            dv1 = a * v1 - kappa * v2 - s * v1
            dv2 = a * v2 + kappa * v1 - s * v2
        return np.stack([du1, du2, dv1, dv2], axis=-1)

    return DynamicalSystem(f, 4, vectorized=True, parameter_name="a")


def clock_guess(tau):
    tau = np.asarray(tau)
    return np.stack([np.cos(2 * np.pi * tau), np.sin(2 * np.pi * tau), 0 * tau, 0 * tau], axis=-1)


ROSSLER_B, ROSSLER_C = 2.0, 4.0


def rossler() -> DynamicalSystem:
    """x' = -y - z, y' = x + a y, z' = b + z (x - c) with b = 2, c = 4; parameter a."""
    def f(x, a):
        return np.stack([-x[:, 1] - x[:, 2], x[:, 0] + a * x[:, 1], ROSSLER_B + x[:, 2] * (x[:, 0] - ROSSLER_C)], axis=-1)

    return DynamicalSystem(f, 3, vectorized=True, parameter_name="a", state_names=("x", "y", "z"))


def rossler_equilibrium(a: float) -> np.ndarray:
    z = (ROSSLER_C - np.sqrt(ROSSLER_C ** 2 - 4 * a * ROSSLER_B)) / (2 * a)
    return np.array([a * z, -z, z])


def with_mass_matrix(system: DynamicalSystem, mass: np.ndarray) -> DynamicalSystem:
    """The same dynamics written as B x' = B f(x, p)."""
    base = system.rhs

    def f(x, p):
        return base(x, p) @ mass.T

    return DynamicalSystem(f, system.dimension, vectorized=True, mass_matrix=mass,
                           parameter_name=system.parameter_name)
