"""Fluid loading inside the model (THEORY 9): the transform to A, strip theory, compressibility."""

import copy

import numpy as np
import pytest
from conftest import ring_model_dict

import impstab
from impstab import linearize
from impstab.fluid import baffled_cylinder
from impstab.model import model_from_dict

HULL = {"radius": 0.15, "length": 0.8, "center": [0.1, 0.02, 0.0]}


def fluid_dict(model="baffled-cylinder", sound_speed=None, shift=0.0):
    d = ring_model_dict(hull=copy.deepcopy(HULL), fluid={"model": model, "density": 1025.0})
    d["body"]["cg"] = [0.03, 0.0, 0.01]
    d["thrust"]["point"] = [-0.05, 0.0, 0.0]
    if sound_speed:
        d["fluid"]["sound_speed"] = sound_speed
    # move the reference point A by `shift` along x: every body-frame position changes
    d["body"]["cg"][0] -= shift
    d["hull"]["center"][0] -= shift
    d["thrust"]["point"][0] -= shift
    d["mount_rings"][0]["x"] -= shift
    return d


@pytest.mark.parametrize("linearization", ["classical", "equilibrium"])
@pytest.mark.parametrize("thrust", [0.0, 6000.0])
def test_eigenvalues_do_not_depend_on_where_a_is(linearization, thrust):
    def spectrum(shift):
        lam = linearize(model_from_dict(fluid_dict(shift=shift)), thrust, linearization).eigenvalues()
        return lam[np.lexsort((lam.real, lam.imag))]   # by frequency: real parts are ~0 here

    ref = spectrum(0.0)
    for shift in (0.25, -0.4):
        assert np.allclose(spectrum(shift), ref, rtol=1e-10, atol=1e-9 * np.abs(ref).max())


def test_added_mass_matrix_about_a():
    model = model_from_dict(fluid_dict())
    c = baffled_cylinder(radius=0.15, length=0.8, density=1025.0)
    ma, ia = c.added_mass, c.added_inertia
    cx, cy = 0.1, 0.02
    m_a = model.fluid.added_mass
    # independent: kinetic energy of the segment centre's transverse velocity and rotation
    for _ in range(4):
        q = np.random.default_rng(3).normal(size=6)
        v, w = q[:3], q[3:]
        vc = v + np.cross(w, [cx, cy, 0.0])
        energy = ma * (vc[1] ** 2 + vc[2] ** 2) + ia * (w[1] ** 2 + w[2] ** 2)
        assert q @ m_a @ q == pytest.approx(energy, rel=1e-12)


def test_strip_theory_model():
    model = model_from_dict(fluid_dict(model="strip"))
    rho, a, length = 1025.0, 0.15, 0.8
    assert model.fluid.added_mass[1, 1] == pytest.approx(rho * np.pi * a**2 * length, rel=1e-14)
    baffled = model_from_dict(fluid_dict())
    assert baffled.fluid.added_mass[1, 1] < model.fluid.added_mass[1, 1]   # end effects reduce it


def test_compressible_coefficients_are_taken_at_the_onset_frequency():
    d = fluid_dict(sound_speed=1500.0)
    model = model_from_dict(d)
    res = impstab.critical_thrust(model)
    assert res.fluid_frequency_hz == pytest.approx(res.frequency_hz, rel=1e-6)
    assert res.fluid_iterations >= 1 and res.fluid_change is not None and res.fluid_change <= 1e-8
    # the undamped companion drops the radiation damping but keeps the added mass
    inc = impstab.critical_thrust(model_from_dict(fluid_dict()))
    assert res.undamped_thrust == pytest.approx(inc.thrust, rel=1e-3)
    mass, damp = model.fluid.coefficients_at(res.fluid_frequency_hz)
    assert np.all(np.diag(damp)[[1, 2, 4, 5]] > 0) and np.diag(damp)[0] == 0


def test_check_prints_coefficients(capsys, tmp_path):
    from impstab.cli import main

    code = main(["check", "examples/imp_fluid.toml"])
    out = capsys.readouterr().out
    assert code == 0
    assert "x strip theory" in out and "added mass" in out


def test_modes_take_fluid_coefficients_at_their_own_frequency():
    model = model_from_dict(fluid_dict(sound_speed=1500.0))
    res = impstab.modes(model, 3000.0)
    from impstab.linear.linearize import ModelFamily

    for j in (0, 2):
        f = res.frequency_hz[j]
        fam = ModelFamily(model, fluid_frequency=f)
        m, d, g, k, u0, r0 = fam.evaluate(np.array([3000.0]))
        from impstab.linear.eigen import state_matrices

        lam = np.linalg.eigvals(state_matrices(m[0], d[0] + g[0], k[0]))
        assert np.min(np.abs(lam - res.eigenvalues[j])) < 1e-9 * abs(res.eigenvalues[j])
        assert res.growth_rate[j] < 0    # radiation damps every transverse mode
