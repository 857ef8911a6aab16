"""Massive beam mounts: finite-element resonances against the continuous Timoshenko beam, the body
coupled with the mount's internal dofs, and the critical thrust of the grown system."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.optimize import brentq

import impstab
from impstab.linear.linearize import ModelFamily
from impstab.model import model_from_dict
from impstab.model.beam import BeamMount, beam_matrices

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "model"))
from test_beam_mount import _model  # noqa: E402

BEAM = BeamMount(0.05, 0.04, 0.012, 5.0e6, 1.7e6, density=1100.0)


def _exact_bending(beam: BeamMount) -> float:
    """First bending resonance (rad/s) of the clamped-free continuous Timoshenko beam: the
    transfer matrix ``expm(A L)`` of ``kGA (v'' - psi') + rho A w^2 v = 0``,
    ``EI psi'' + kGA (v' - psi) + rho I w^2 psi = 0`` with v = psi = 0 at the root and shear
    ``v' - psi`` and moment ``psi'`` zero at the tip; the first sign change of the 2 x 2 determinant."""
    E, G, rho, A, I, k, L = (beam.youngs_modulus, beam.shear_modulus, beam.density, beam.area,
                             beam.second_moment, beam.shear_coefficient, beam.length)

    def det(w):
        a = np.zeros((4, 4))  # state (v, v', psi, psi')
        a[0, 1] = a[2, 3] = 1.0
        a[1, 0], a[1, 3] = -rho * w * w / (k * G), 1.0
        a[3, 1], a[3, 2] = -k * G * A / (E * I), k * G * A / (E * I) - rho * w * w / E
        t = sla.expm(a * L)
        return np.linalg.det(np.array([t[1] - t[2], t[3]])[:, [1, 3]])

    grid = np.linspace(1.0, 2 * np.pi * 3000.0, 3001)
    vals = [det(w) for w in grid]
    j = next(i for i in range(len(vals) - 1) if np.sign(vals[i]) != np.sign(vals[i + 1]))
    return brentq(det, grid[j], grid[j + 1], xtol=1e-13, rtol=1e-15)


def _fe_frequencies(beam: BeamMount, n: int) -> np.ndarray:
    k, m = beam_matrices(beam, [0.3, -0.4, 0.8], n)
    return np.sqrt(sla.eigvalsh(k[6:, 6:], m[6:, 6:]))  # hull node clamped, tip free


def test_fe_resonances_converge_to_the_continuous_beam():
    w_axial = np.pi / (2 * BEAM.length) * np.sqrt(BEAM.youngs_modulus / BEAM.density)
    w_torsion = w_axial * np.sqrt(BEAM.shear_modulus / BEAM.youngs_modulus)
    w_bend = _exact_bending(BEAM)
    errors = []
    for n in (2, 4, 8, 16, 32):
        w = _fe_frequencies(BEAM, n)
        errors.append([abs(w[0] / w_bend - 1), abs(w[1] / w_bend - 1),
                       np.min(np.abs(w / w_axial - 1)), np.min(np.abs(w / w_torsion - 1))])
    errors = np.array(errors)
    # consistent mass: second order in the element size, from above (Rayleigh-Ritz)
    ratios = errors[:-1] / errors[1:]
    assert np.all((ratios > 3.8) & (ratios < 4.2)), ratios
    # at the default 8 elements the first internal resonances are within 0.2 %
    assert errors[2].max() < 2e-3
    assert errors[-1].max() < 1.1e-4


def test_euler_bernoulli_limit_of_a_slender_beam():
    # slender steel rod: the Timoshenko value approaches 1.87510407^2 sqrt(EI / (rho A L^4))
    rod = BeamMount(1.0, 0.01, 0.0, 2.1e11, 8.1e10, density=7850.0)
    w_eb = 1.87510407**2 * np.sqrt(rod.youngs_modulus * rod.second_moment / (rod.density * rod.area))
    exact = _exact_bending(rod)
    assert exact < w_eb and exact == pytest.approx(w_eb, rel=1e-4)  # (r / L)^2 = 6e-6 corrections
    assert _fe_frequencies(rod, 32)[0] == pytest.approx(exact, rel=1e-5)


def _single_mount_model(elements: int, density: float = 1100.0, body_mass: float = 0.2):
    data = {"schema_version": 1, "body": {"mass": body_mass, "inertia": [1e-4, 1e-4, 1e-4]},
            "mounts": [{"position": [0.0, 0.0, 0.0], "axis": [1.0, 0.0, 0.0],
                        "beam": {"length": 0.05, "outer_diameter": 0.04, "inner_diameter": 0.012,
                                 "youngs_modulus": 5.0e6, "shear_modulus": 1.7e6, "density": density}}],
            "analysis": {"thrust_max": 100.0}}
    model = model_from_dict(data)
    return replace(model, mounts=tuple(replace(m, beam=replace(m.beam, elements=elements)) for m in model.mounts))


def test_body_on_a_massive_rod_is_the_mass_loaded_rod():
    # surge of a body of mass M on a clamped rod: (w L / c) tan(w L / c) = rho A L / M
    body_mass = 0.2
    c = np.sqrt(BEAM.youngs_modulus / BEAM.density)
    ratio = BEAM.density * BEAM.area * BEAM.length / body_mass
    x = brentq(lambda x: x * np.tan(x) - ratio, 1e-9, np.pi / 2 - 1e-12, xtol=1e-15)
    exact = x * c / BEAM.length
    errors = []
    for n in (4, 8, 16, 32):
        fam = ModelFamily(_single_mount_model(n, body_mass=body_mass), "classical")
        m, _, _, k = (a[0] for a in fam.matrices(np.array([0.0])))
        assert fam.n == 6 + 6 * (n - 1)
        vals, vecs = sla.eigh(k, m)
        surge = np.abs(vecs[0]) * np.sqrt(m[0, 0]) > 0.1  # modes with the body in surge
        w = np.sqrt(vals[surge])
        errors.append(np.min(np.abs(w / exact - 1)))
    errors = np.array(errors)
    assert np.all(errors[:-1] / errors[1:] > 3.5), errors
    assert errors[-1] < 1e-5, errors


def test_craig_bampton_coordinates_keep_the_finite_element_spectrum():
    from impstab.model.beam import internal_matrices
    from impstab.linear.mount_dofs import mount_dofs

    # every mode kept: the grown system at rest has the spectrum of the body attached to the full
    # finite-element meshes in physical coordinates (assembled here by hand)
    model = model_from_dict(_massive(1100.0))
    fam = ModelFamily(model, "classical")
    assert fam.internal.dropped == 0
    m, _, _, k = (a[0] for a in fam.matrices(np.array([0.0])))
    body = ModelFamily(model, "classical", mount_dofs=False)
    mb, _, _, kb = (a[0] for a in body.matrices(np.array([0.0])))
    blocks_k, blocks_m, coupling = [], [], []
    mm, kk = mb.copy(), kb.copy()
    from impstab.kinematics import rigid_map6
    for mt in model.mounts:
        ktt, kti, kii, mtt, mti, mii = internal_matrices(mt.beam, mt.axis)
        t = rigid_map6(mt.position)
        kk += t.T @ (ktt - mt.stiffness) @ t
        mm += t.T @ mtt @ t
        blocks_k.append(kii), blocks_m.append(mii), coupling.append((t.T @ kti, t.T @ mti))
    n = 6 + sum(b.shape[0] for b in blocks_k)
    K, M = np.zeros((n, n)), np.zeros((n, n))
    K[:6, :6], M[:6, :6] = kk, mm
    at = 6
    for kii, mii, (kc, mc) in zip(blocks_k, blocks_m, coupling):
        sl = slice(at, at + kii.shape[0])
        K[sl, sl], M[sl, sl], K[:6, sl], K[sl, :6], M[:6, sl], M[sl, :6] = kii, mii, kc, kc.T, mc, mc.T
        at += kii.shape[0]
    physical = np.sort(sla.eigvals(K, M).real)
    modal = np.sort(sla.eigvals(k, m).real)
    assert np.allclose(modal[:40], physical[:40], rtol=1e-9, atol=0)
    assert mount_dofs(model, cutoff=np.inf).n == fam.internal.n


def test_condensation_of_the_grown_system_is_the_body_system():
    model = model_from_dict(_massive(1100.0))
    fam = ModelFamily(model, "equilibrium")
    body = ModelFamily(model, "equilibrium", mount_dofs=False)
    for t in (0.0, 4000.0):
        _, _, _, k = (a[0] for a in fam.matrices(np.array([t])))
        _, _, _, kb = (a[0] for a in body.matrices(np.array([t])))
        schur = k[:6, :6] - k[:6, 6:] @ np.linalg.solve(k[6:, 6:], k[6:, :6])
        assert np.abs(schur - kb).max() <= 1e-9 * np.abs(kb).max()


def _massive(density: float, linearization: str = "classical") -> dict:
    data = _model()
    data["analysis"]["linearization"] = linearization
    for m in data["mounts"]:
        m["beam"]["density"] = density
    return data


@pytest.mark.parametrize("linearization", ["classical", "equilibrium"])
def test_critical_thrust_of_the_grown_system_by_dense_eigenvalues(linearization):
    model = model_from_dict(_massive(1100.0, linearization))
    crit = impstab.critical_thrust(model)
    assert crit.kind == "flutter" and crit.method == "coalescence"
    fam = ModelFamily(model, linearization)
    assert fam.n == 6 + 4 * 6 * 7

    def spectrum(t):
        m, _, _, k = (a[0] for a in fam.matrices(np.array([t])))
        return sla.eigvals(k, m)  # s = omega^2, dense QZ of the full pencil

    below, above = spectrum(crit.thrust * (1 - 1e-6)), spectrum(crit.thrust * (1 + 1e-6))
    assert np.all(np.abs(below.imag) <= 1e-9 * np.abs(below)) and below.real.min() > 0
    assert np.abs(above.imag).max() > 1e-5 * np.abs(above[np.argmax(np.abs(above.imag))])
    s_c = crit.omega**2
    assert np.min(np.abs(above - s_c)) < 1e-2 * s_c
    # a light mount moves the onset a little from the massless beam's
    massless = impstab.critical_thrust(model_from_dict(_massive(0.0, linearization)))
    assert 0 < abs(crit.thrust / massless.thrust - 1) < 1e-2
    assert len(crit.participation) == 6 and crit.participation.sum() == pytest.approx(1.0)


def test_vanishing_density_gives_the_massless_beam():
    from impstab.linear.mount_dofs import mount_dofs

    # internal resonances a million times above the body's: all left to the constraint modes
    dofs = mount_dofs(model_from_dict(_massive(1e-3)))
    assert dofs.n == 0 and dofs.dropped == 4 * 6 * 7
    light = impstab.critical_thrust(model_from_dict(_massive(1e-3)))
    massless = impstab.critical_thrust(model_from_dict(_massive(0.0)))
    assert light.thrust == pytest.approx(massless.thrust, rel=1e-6)


def test_cli_on_the_beam_example(capsys):
    import json

    from impstab.cli import main

    example = str(Path(__file__).resolve().parents[2] / "examples" / "imp_beam_mounts.toml")
    assert main(["critical", example, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["kind"] == "flutter" and out["modes"] == ["pitch", "yaw"]
    assert main(["modes", example, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    kinds = [m["kind"] for m in out["modes"]]
    assert kinds[:6] == ["body"] * 6 and set(kinds[6:]) == {"mount"}
    assert out["mount_elements"] == [8, 8, 8, 8] and out["internal_dofs"] == len(kinds) - 6
