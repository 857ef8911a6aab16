"""Forced response with massive beam mounts: the exact dynamic stiffness in the one response route,
against the mass-loaded rod's closed form, the massless limit and the power balance."""

from __future__ import annotations

import copy
import sys
from pathlib import Path

import numpy as np
import pytest

from impstab.model import model_from_dict
from impstab.model.foundation import Foundation
from impstab.response import frequency_response

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "model"))
from test_beam_mount import _model  # noqa: E402

L, DO, DI, E, G, RHO = 0.05, 0.04, 0.012, 5.0e6, 1.7e6, 1100.0


def _rod_on_body(body_mass: float) -> dict:
    return {"schema_version": 1, "body": {"mass": body_mass, "inertia": [1e-3, 1e-3, 1e-3]},
            "mounts": [{"position": [0.0, 0.0, 0.0], "axis": [1.0, 0.0, 0.0],
                        "beam": {"length": L, "outer_diameter": DO, "inner_diameter": DI,
                                 "youngs_modulus": E, "shear_modulus": G, "density": RHO}}],
            "analysis": {"thrust_max": 100.0}}


@pytest.mark.parametrize("body_mass", [0.2, 50.0])
def test_surge_transmissibility_is_the_mass_loaded_rod(body_mass):
    # a body of mass M on a clamped rod, surge force F at the body end: the rod's end stiffness
    # EA k cot(kL) carries the body, the hull receives EA k / sin(kL) u (k = omega sqrt(rho / E)):
    # |F_hull / F| = 1 / |cos(kL) - M omega^2 sin(kL) / (EA k)|, peaks at the mass-loaded rod's
    # resonances, which tend to the body-blocked rod's n pi / L sqrt(E / rho) as M grows
    model = model_from_dict(_rod_on_body(body_mass))
    f = np.linspace(5.0, 2500.0, 500)
    res = frequency_response(model, f, input="surge")
    w = 2 * np.pi * f
    k = w * np.sqrt(RHO / E)
    ea = E * np.pi / 4 * (DO**2 - DI**2)
    exact = 1.0 / np.abs(np.cos(k * L) - body_mass * w**2 * np.sin(k * L) / (ea * k))
    assert np.allclose(res.transmissibility, exact, rtol=1e-9, atol=0)
    # the force on the hull is along the rod, not the body-end force EA k cot(kL) u
    u = res.response[:, 0]
    body_end = ea * k / np.tan(k * L) * u
    assert np.allclose(res.hull_force[:, 0] / body_end, 1.0 / np.cos(k * L), rtol=1e-8, atol=0)
    if body_mass > 1.0:  # heavy body: the internal axial resonance of the blocked rod shows as a peak
        high = f > 100.0  # above the body's own surge resonance (7.6 Hz)
        peak = f[high][np.argmax(res.transmissibility[high])]
        blocked = np.sqrt(E / RHO) / (2 * L)  # first clamped-clamped rod resonance (Hz)
        assert abs(peak / blocked - 1) < 0.02


def _four_mounts(density: float) -> dict:
    data = _model()
    for m in data["mounts"]:
        m["beam"]["density"] = density
    data["mounts"][1]["c_axial"] = 30.0
    data["mounts"][1]["c_shear"] = 10.0
    return data


def test_vanishing_density_is_the_massless_mount_on_a_compliant_hull():
    # density 1e-6 kg/m^3: internal resonances far above; the exact route (beam blocks with the hull
    # end in series with the hull) must meet the massless 6 x 6 mount route of the harmonic solver
    hull = Foundation(model="lumped", mass=30.0, stiffness=4.0e5, damping=900.0)
    f = np.geomspace(1.0, 500.0, 60)
    light = frequency_response(model_from_dict(_four_mounts(1e-6)), f, input="sway", foundation=hull)
    massless = frequency_response(model_from_dict(_four_mounts(0.0)), f, input="sway", foundation=hull)
    for name in ("response", "hull_force", "mount_force", "hull_displacement"):
        a, b = getattr(light, name), getattr(massless, name)
        assert np.abs(a - b).max() <= 1e-7 * np.abs(b).max(), name
    for name in ("power_damper", "power_transmitted"):
        a, b = getattr(light, name), getattr(massless, name)
        assert np.abs(a - b).max() <= 1e-7 * np.abs(b).max(), name


def test_power_balance_with_massive_beams_dampers_thrust_and_a_compliant_hull():
    hull = Foundation(model="lumped", mass=30.0, stiffness=4.0e5, damping=900.0)
    model = model_from_dict(_four_mounts(RHO))
    res = frequency_response(model, np.geomspace(1.0, 2000.0, 80), input="heave", thrust=3000.0, foundation=hull)
    lhs = res.power_input + res.power_thrust
    rhs = res.power_fluid + res.power_damper.sum(axis=1) + res.power_transmitted.sum(axis=1)
    assert np.abs(lhs - rhs).max() <= 1e-9 * np.abs(res.power_input).max()
    assert np.all(res.power_transmitted.sum(axis=1) > 0) and np.abs(res.power_fluid).max() <= 1e-12 * np.abs(lhs).max()


def test_designs_stacked_with_massive_beams_are_solved_each_alone():
    from impstab.response.api import design_inputs, solve_designs

    f = np.geomspace(5.0, 1500.0, 30)
    loads = np.zeros((2, 1, 6), complex)
    loads[:, 0, 1] = 1.0
    models = [model_from_dict(_four_mounts(RHO)), model_from_dict(_four_mounts(2 * RHO))]
    both = solve_designs([design_inputs(m, f, 0.0) for m in models], f, loads)
    for j, m in enumerate(models):
        one = solve_designs([design_inputs(m, f, 0.0)], f, loads[j:j + 1])
        assert np.array_equal(both.hull_force[j], one.hull_force[0])


def test_cli_response_on_the_beam_example(tmp_path, capsys):
    import json

    from impstab.cli import main

    example = str(Path(__file__).resolve().parents[2] / "examples" / "imp_beam_mounts.toml")
    assert main(["response", example, "--frequencies", "1:1500:300", "--input", "surge", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert "exact dynamic stiffness" in json.dumps(out)
