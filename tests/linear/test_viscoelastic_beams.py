"""Viscoelastic mounts beside beam mounts with mass: the augmented system carries both.

* the critical thrust's root solves the exact characteristic equation assembled here: the grown
  system of the beams (MountDofs.augment of the 6-dof linearization at the onset) plus each
  viscoelastic mount's standard-linear-solid ratio ``1 + (s - 1) lambda tau / (1 + lambda tau)``
  on ``B^T k B`` at the body's dofs (``B = [I, -S(R0 r)]``, formed by hand), at ``lambda = i omega``;
* the beams' inertia moves it (the massless beams' value differs);
* the Jacobian of the nonlinear equations of the time histories (complex step through the compiled
  right-hand side: Prony internal variables and beam modes as states) has the eigenvalues of the
  augmented family with the same kept modes;
* the modes (body modes, internal mount modes labelled as such, the relaxation root) are roots of
  that exact equation.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import impstab
from impstab.linear.mount_dofs import mount_dofs
from impstab.model import model_from_dict

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "model"))
from test_beam_mount import _model  # noqa: E402

STIFFENING, TAU = 1.5, 4e-3
SPRING = {"position": [-0.2, 0.12, 0.1], "axis": [1.0, 0.0, 0.0], "k_axial": 6.0e4, "k_shear": 1.5e4,
          "viscoelastic": {"law": "standard-linear-solid", "stiffening": STIFFENING, "relaxation_time": TAU}}


def _both(linearization: str, density: float = 1100.0):
    data = _model()
    data["analysis"]["linearization"] = linearization
    for m in data["mounts"]:
        m["beam"]["density"] = density
    data["mounts"].append(dict(SPRING))
    model = model_from_dict(data)
    return replace(model, mounts=tuple(replace(m, beam=replace(m.beam, elements=4)) if m.is_massive_beam else m
                                       for m in model.mounts))


def _skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _exact(model, thrust: float, linearization: str, lam: complex):
    """``F(lambda) = lambda^2 M + lambda (D + G) + K + B^T k B (r(lambda) - 1)`` on the grown dofs at
    ``thrust``: the beams from MountDofs.augment, the viscoelastic spring formed here."""
    lin = impstab.linearize(model, thrust, linearization)
    rot = lin.rotation if linearization == "equilibrium" else np.eye(3)
    m, d, g, k = (a[0] for a in mount_dofs(model).augment(lin.M[None], lin.D[None], lin.G[None], lin.K[None],
                                                           None if linearization == "classical" else rot[None]))
    f = lam * lam * m + lam * (d + g) + k + 0j
    a = np.array(SPRING["axis"]) / np.linalg.norm(SPRING["axis"])
    k3 = SPRING["k_axial"] * np.outer(a, a) + SPRING["k_shear"] * (np.eye(3) - np.outer(a, a))
    b = np.hstack([np.eye(3), -_skew(rot @ np.array(SPRING["position"]))])
    ratio = 1.0 + (STIFFENING - 1.0) * lam * TAU / (1.0 + lam * TAU)
    f[:6, :6] += b.T @ k3 @ b * (ratio - 1.0)
    sv = np.linalg.svd(f, compute_uv=False)
    return sv[-1] / sv[0]


@pytest.mark.parametrize("linearization", ["classical", "equilibrium"])
def test_the_onset_solves_the_exact_characteristic_equation(linearization):
    model = _both(linearization)
    crit = impstab.critical_thrust(model)
    assert crit.kind == "flutter"
    assert _exact(model, crit.thrust, linearization, 1j * crit.omega) < 1e-11
    # the beams' inertia is in it: the massless beams give another onset
    light = impstab.critical_thrust(_both(linearization, density=0.0))
    assert abs(light.thrust - crit.thrust) > 1e-6 * crit.thrust


def test_time_history_jacobian_has_the_augmented_familys_eigenvalues():
    from impstab.dynamics.beam_mounts import SIM_CUTOFF
    from impstab.dynamics.system import NonlinearSystem
    from impstab.linear.viscoelastic import ViscoelasticFamily

    model = _both("equilibrium")
    ns = NonlinearSystem(model)
    thrust = 4000.0
    y0 = ns.equilibrium(thrust)
    mine = np.linalg.eigvals(ns.jacobian(y0, thrust))
    e, a = ViscoelasticFamily(model, "equilibrium", cutoff=SIM_CUTOFF).matrices(np.array([thrust]))
    ref = np.linalg.eigvals(np.linalg.solve(e[0], a[0]))
    assert mine.size == ref.size
    scale = np.abs(ref).max()
    for lam in ref:
        assert np.min(np.abs(mine - lam)) < 1e-9 * scale


def test_modes_carry_the_internal_variables_and_the_beams():
    model = _both("classical")
    md = impstab.modes(model, 0.0)
    assert md.internal_dofs > 0 and md.mount_elements == (4, 4, 4, 4)
    assert md.kind[:6] == ["body"] * 6 and "mount" in md.kind
    # the body modes and the first internal ones are roots of the exact characteristic equation
    for lam in md.eigenvalues[:8]:
        assert _exact(model, 0.0, "classical", lam) < 1e-11
    relax = md.eigenvalues[np.abs(md.eigenvalues.imag) == 0.0]
    assert relax.size >= 1 and np.all(relax.real < 0)      # the relaxation root of the internal variable
