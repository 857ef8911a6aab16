"""Beam mounts: a Timoshenko beam along the mount axis, hull end clamped, body end at the mount.

A beam mount (``[mounts.beam]``, DESIGN "Model file, round 2 additions") lies along its unit axis
``a`` from its clamped hull end at ``position - length a`` to its body end at ``position``. Its
section is circular (``outer_diameter``, ``inner_diameter``), its material isotropic (``E``, ``G``),
and the Timoshenko shear coefficient is Cowper's value for the hollow circle unless given.

Statics (every mount, massless or not). The clamped-free tip flexibility in the beam's local frame
``(e1 = a, e2, e3)``, dof order ``(u1, u2, u3, theta1, theta2, theta3)``, is

* axial ``u1 = L / (E A) F1``, torsion ``theta1 = L / (G J) M1``;
* bending in the ``e1-e2`` plane: ``[u2, theta3] = [[L^3/(3EI) + L/(kappa G A), +L^2/(2EI)],
  [+L^2/(2EI), L/(EI)]] [F2, M3]`` (a rotation about ``e3`` turns ``e1`` into ``e2``: the slope is
  ``+theta3``);
* bending in the ``e1-e3`` plane: the same with ``-L^2/(2EI)`` between ``u3`` and ``theta2`` (the
  slope is ``-theta2``).

``K_tip`` (:func:`tip_stiffness`) is its inverse rotated to the hull frame. A massless beam mount is
exactly the 6 x 6 ``stiffness`` mount of THEORY 3 with that matrix.

Dynamics (``density > 0``). The beam is cut into Timoshenko finite elements with the exact static
("interdependent interpolation") shape functions (Przemieniecki 1968, Friedman & Kosmatka 1993):
their stiffness reproduces the continuous beam's static stiffness exactly for any element count, so
the static condensation of the mesh onto the tip is ``K_tip`` to rounding; the consistent mass
matrix (translational and rotary inertia, with the shear parameter ``Phi = 12 E I / (kappa G A l^2)``)
converges to the continuous beam's inertia as the mesh is refined (:func:`beam_matrices`). The hull
end node is clamped and the tip node is the body end: the ``6 (n_elements - 1)`` dofs of the inner
nodes are the mount's internal dofs (:func:`internal_matrices`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["BeamMount", "cowper_shear_coefficient", "tip_flexibility_local", "tip_stiffness", "beam_frame",
           "element_matrices", "beam_matrices", "internal_matrices", "DEFAULT_ELEMENTS"]

Array = NDArray[np.float64]

#: finite elements per massive beam mount in the stability analysis (convergence: docs/mounts.md)
DEFAULT_ELEMENTS = 8


def cowper_shear_coefficient(poisson: float, inner_over_outer: float = 0.0) -> float:
    """Cowper's (1966) Timoshenko shear coefficient of a hollow circular section.

    ``kappa = 6 (1 + nu) (1 + m^2)^2 / ((7 + 6 nu) (1 + m^2)^2 + (20 + 12 nu) m^2)`` with
    ``m = d_inner / d_outer``; ``6 (1 + nu) / (7 + 6 nu)`` for the solid circle.
    """
    nu, m2 = float(poisson), float(inner_over_outer) ** 2
    return 6.0 * (1.0 + nu) * (1.0 + m2) ** 2 / ((7.0 + 6.0 * nu) * (1.0 + m2) ** 2 + (20.0 + 12.0 * nu) * m2)


@dataclass(frozen=True)
class BeamMount:
    """A Timoshenko beam mount of circular section (SI units).

    Parameters
    ----------
    length : float
        Free length L between the clamped hull end and the body end (m).
    outer_diameter, inner_diameter : float
        Section diameters (m); ``inner_diameter = 0`` is a solid section.
    youngs_modulus, shear_modulus : float
        E and G (Pa).
    shear_coefficient : float or None
        Timoshenko kappa; None: Cowper's value for the section with ``nu = E / (2 G) - 1``.
    density : float
        Material density (kg/m^3); 0: massless (the mount is its static 6 x 6 stiffness).
    elements : int
        Finite elements along the beam when it has mass.
    """

    length: float
    outer_diameter: float
    inner_diameter: float
    youngs_modulus: float
    shear_modulus: float
    shear_coefficient: float | None = None
    density: float = 0.0
    elements: int = DEFAULT_ELEMENTS

    def __post_init__(self) -> None:
        for name in ("length", "outer_diameter", "youngs_modulus", "shear_modulus"):
            if not float(getattr(self, name)) > 0.0:
                raise ValueError(f"BeamMount.{name} must be > 0, not {getattr(self, name)}")
        if not 0.0 <= self.inner_diameter < self.outer_diameter:
            raise ValueError("BeamMount.inner_diameter must be >= 0 and below outer_diameter")
        if self.density < 0.0:
            raise ValueError("BeamMount.density must be >= 0")
        if int(self.elements) < 1:
            raise ValueError("BeamMount.elements must be at least 1")
        if self.shear_coefficient is None:
            object.__setattr__(self, "shear_coefficient", cowper_shear_coefficient(
                self.poisson_ratio, self.inner_diameter / self.outer_diameter))
        if not float(self.shear_coefficient) > 0.0:  # type: ignore[arg-type]
            raise ValueError("BeamMount.shear_coefficient must be > 0")

    @property
    def poisson_ratio(self) -> float:
        """``nu = E / (2 G) - 1`` (isotropic material)."""
        return self.youngs_modulus / (2.0 * self.shear_modulus) - 1.0

    @property
    def area(self) -> float:
        """Section area A (m^2)."""
        return 0.25 * np.pi * (self.outer_diameter ** 2 - self.inner_diameter ** 2)

    @property
    def second_moment(self) -> float:
        """Second moment of area I about a diameter (m^4)."""
        return np.pi / 64.0 * (self.outer_diameter ** 4 - self.inner_diameter ** 4)

    @property
    def polar_moment(self) -> float:
        """Torsion constant J = 2 I of the circular section (m^4)."""
        return 2.0 * self.second_moment

    @property
    def mass(self) -> float:
        """Mass of the beam (kg)."""
        return self.density * self.area * self.length

    @property
    def is_massive(self) -> bool:
        return self.density > 0.0


def tip_flexibility_local(beam: BeamMount) -> Array:
    """Clamped-free tip flexibility (6 x 6) in the beam frame ``(e1 = axis, e2, e3)``.

    Dof order ``(u1, u2, u3, theta1, theta2, theta3)``; see the module docstring for the signs.
    """
    L, E, G = beam.length, beam.youngs_modulus, beam.shear_modulus
    A, I, J, k = beam.area, beam.second_moment, beam.polar_moment, beam.shear_coefficient
    c = np.zeros((6, 6))
    c[0, 0] = L / (E * A)
    c[3, 3] = L / (G * J)
    bend = L ** 3 / (3.0 * E * I) + L / (k * G * A)
    couple = L ** 2 / (2.0 * E * I)
    c[1, 1] = c[2, 2] = bend
    c[4, 4] = c[5, 5] = L / (E * I)
    c[1, 5] = c[5, 1] = couple
    c[2, 4] = c[4, 2] = -couple
    return c


def beam_frame(axis: Array) -> Array:
    """Rotation ``[e1 e2 e3]`` (columns, hull frame) of a beam along ``axis`` (any e2 normal to it:
    the circular section makes the choice immaterial)."""
    e1 = np.asarray(axis, dtype=float)
    e1 = e1 / np.linalg.norm(e1)
    trial = np.eye(3)[int(np.argmin(np.abs(e1)))]
    e2 = trial - (trial @ e1) * e1
    e2 /= np.linalg.norm(e2)
    return np.column_stack([e1, e2, np.cross(e1, e2)])


def _rotate6(local: Array, frame: Array) -> Array:
    r6 = np.kron(np.eye(2), frame)
    return r6 @ local @ r6.T


def tip_stiffness(beam: BeamMount, axis: Array) -> Array:
    """``K_tip``: the inverse of the clamped-free tip flexibility, hull frame (N/m, N/rad, N m/rad).

    ``[f; m] = -K_tip [d; phi]`` is the force and moment of the beam on the body end.
    """
    k = np.linalg.inv(tip_flexibility_local(beam))
    k = 0.5 * (k + k.T)
    return _rotate6(k, beam_frame(axis))


# -- finite elements ---------------------------------------------------------------------------
def _bending(EI: float, kGA: float, rhoA: float, rhoI: float, l: float) -> tuple[Array, Array]:
    """Timoshenko element in one plane, dofs ``(v1, s1, v2, s2)`` with ``s = dv/dx`` at zero shear
    (the rotation whose positive sense raises v): exact static stiffness, consistent mass."""
    phi = 12.0 * EI / (kGA * l * l)
    k = EI / ((1.0 + phi) * l ** 3) * np.array([
        [12.0, 6 * l, -12.0, 6 * l],
        [6 * l, (4 + phi) * l * l, -6 * l, (2 - phi) * l * l],
        [-12.0, -6 * l, 12.0, -6 * l],
        [6 * l, (2 - phi) * l * l, -6 * l, (4 + phi) * l * l],
    ])
    p2 = phi * phi
    a11 = 13 / 35 + 7 * phi / 10 + p2 / 3
    a12 = (11 / 210 + 11 * phi / 120 + p2 / 24) * l
    a13 = 9 / 70 + 3 * phi / 10 + p2 / 6
    a14 = -(13 / 420 + 3 * phi / 40 + p2 / 24) * l
    a22 = (1 / 105 + phi / 60 + p2 / 120) * l * l
    a24 = -(1 / 140 + phi / 60 + p2 / 120) * l * l
    mt = rhoA * l / (1.0 + phi) ** 2 * np.array([
        [a11, a12, a13, a14],
        [a12, a22, -a14, a24],
        [a13, -a14, a11, -a12],
        [a14, a24, -a12, a22],
    ])
    b12 = (1 / 10 - phi / 2) * l
    b22 = (2 / 15 + phi / 6 + p2 / 3) * l * l
    b24 = (-1 / 30 - phi / 6 + p2 / 6) * l * l
    mr = rhoI / ((1.0 + phi) ** 2 * l) * np.array([
        [6 / 5, b12, -6 / 5, b12],
        [b12, b22, -b12, b24],
        [-6 / 5, -b12, 6 / 5, -b12],
        [b12, b24, -b12, b22],
    ])
    return k, mt + mr


def element_matrices(beam: BeamMount, l: float) -> tuple[Array, Array]:
    """Stiffness and consistent mass (12 x 12) of one element of length ``l``, beam frame.

    Dofs ``(u1, u2, u3, theta1, theta2, theta3)`` of node 1, then of node 2.
    """
    E, G = beam.youngs_modulus, beam.shear_modulus
    A, I, J, kap, rho = beam.area, beam.second_moment, beam.polar_moment, beam.shear_coefficient, beam.density
    k = np.zeros((12, 12))
    m = np.zeros((12, 12))
    bar_k = np.array([[1.0, -1.0], [-1.0, 1.0]]) / l
    bar_m = np.array([[2.0, 1.0], [1.0, 2.0]]) * l / 6.0
    for dof, stiff, inertia in ((0, E * A, rho * A), (3, G * J, rho * J)):  # axial, torsion
        idx = [dof, dof + 6]
        k[np.ix_(idx, idx)] += stiff * bar_k
        m[np.ix_(idx, idx)] += inertia * bar_m
    kb, mb = _bending(E * I, kap * G * A, rho * A, rho * I, l)
    # e1-e2 plane: (u2, +theta3); e1-e3 plane: (u3, -theta2)
    for disp, rot, sign in ((1, 5, 1.0), (2, 4, -1.0)):
        idx = [disp, rot, disp + 6, rot + 6]
        s = np.diag([1.0, sign, 1.0, sign])
        k[np.ix_(idx, idx)] += s @ kb @ s
        m[np.ix_(idx, idx)] += s @ mb @ s
    return k, m


def beam_matrices(beam: BeamMount, axis: Array, elements: int | None = None) -> tuple[Array, Array]:
    """Stiffness and consistent mass of the free mesh, hull frame: ``6 (n + 1)`` dofs, node 0 at the
    hull end, node ``n`` at the body end."""
    n = int(beam.elements if elements is None else elements)
    ke, me = element_matrices(beam, beam.length / n)
    r12 = np.kron(np.eye(4), beam_frame(axis))
    ke, me = r12 @ ke @ r12.T, r12 @ me @ r12.T
    size = 6 * (n + 1)
    k = np.zeros((size, size))
    m = np.zeros((size, size))
    for e in range(n):
        sl = slice(6 * e, 6 * e + 12)
        k[sl, sl] += ke
        m[sl, sl] += me
    return k, m


def internal_matrices(beam: BeamMount, axis: Array, elements: int | None = None):
    """The clamped mesh split into the body-end node ``t`` and the inner nodes ``i``.

    Returns ``(k_tt, k_ti, k_ii, m_tt, m_ti, m_ii)``, hull frame: ``6 x 6``, ``6 x n_i``,
    ``n_i x n_i``, with ``n_i = 6 (elements - 1)``. The static condensation
    ``k_tt - k_ti k_ii^-1 k_ti^T`` is :func:`tip_stiffness` to rounding.
    """
    k, m = beam_matrices(beam, axis, elements)
    t = slice(k.shape[0] - 6, k.shape[0])
    i = slice(6, k.shape[0] - 6)
    return k[t, t], k[t, i], k[i, i], m[t, t], m[t, i], m[i, i]
