"""Compressible fluid loading at every frequency: interpolated coefficients and the response."""

import copy

import numpy as np
import pytest
from _resp_models import asym_full, model

import impstab
from impstab.response import frequency_response
from impstab.response.fluid import DIRECT_LIMIT, TOLERANCE, fluid_spectrum


def _wet(d: dict) -> dict:
    d = copy.deepcopy(d)
    d["hull"] = {"radius": 0.15, "length": 0.8, "center": [0.05, 0.01, 0.0]}
    d["fluid"] = {"model": "baffled-cylinder", "density": 1025.0, "sound_speed": 1500.0}
    return d


@pytest.mark.parametrize("top", [300.0, 3000.0])
def test_interpolated_coefficients_match_direct_evaluation(top):
    """Chebyshev panels against baffled_cylinder at frequencies that are not nodes."""
    mdl = model(_wet(asym_full()))
    f = np.linspace(0.0, top, 5000)
    spec = fluid_spectrum(mdl, f)
    assert spec.method == "chebyshev" and spec.interpolation_error <= TOLERANCE
    probe = np.arange(7, f.size, 613)
    for i in probe:
        c = impstab.fluid.baffled_cylinder(0.15, 0.8, 1025.0, 1500.0, f[i])
        w = 2 * np.pi * f[i]
        scale_t = np.hypot(c.added_mass, c.radiation_resistance / w)
        scale_r = np.hypot(c.added_inertia, c.rotational_radiation_resistance / w)
        assert abs(spec.added_mass[i] - c.added_mass) <= 1e-9 * scale_t
        assert abs(spec.radiation_resistance[i] - c.radiation_resistance) <= 1e-9 * w * scale_t
        assert abs(spec.added_inertia[i] - c.added_inertia) <= 1e-9 * scale_r
        assert abs(spec.rotational_radiation_resistance[i] - c.rotational_radiation_resistance) <= 1e-9 * w * scale_r


@pytest.mark.parametrize("count", [20, DIRECT_LIMIT + 150])
@pytest.mark.parametrize("linearization", ["equilibrium", "classical"])
def test_response_with_frequency_dependent_added_mass_and_radiation(count, linearization):
    """Against a solve that takes M(f) and D(f) from the model's own fluid loading at each f."""
    mdl = model(_wet(asym_full()))
    thrust = 8000.0
    f = np.linspace(0.5, 400.0, count)
    res = frequency_response(mdl, f, thrust=thrust, input="pitch", linearization=linearization)
    lin = impstab.linearize(mdl, thrust, linearization)
    big = np.zeros((6, 6))
    big[:3, :3] = big[3:, 3:] = lin.rotation
    rot = lambda a: big @ a @ big.T  # noqa: E731
    m0 = rot(mdl.fluid.added_mass)
    load = np.eye(6)[4]
    worst = 0.0
    for n, fn in enumerate(f):
        added, radiation = mdl.fluid.coefficients_at(fn)
        w = 2 * np.pi * fn
        z = lin.K + 1j * w * (lin.D + rot(radiation) + lin.G) - w**2 * (lin.M - m0 + rot(added))
        q = np.linalg.solve(z, load)
        worst = max(worst, np.abs(res.response[n] - q).max() / np.abs(q).max())
    assert worst <= 1e-9
    assert "compressible" in res.settings["fluid"]
    # radiation damping appears in the power balance as the fluid term
    assert res.power_fluid.min() >= 0 and res.power_fluid.max() > 0
    assert np.abs(res.power_balance_error).max() <= 1e-9 * np.abs(res.power_input).max()


def test_incompressible_fluid_is_frequency_independent():
    d = _wet(asym_full())
    del d["fluid"]["sound_speed"]
    mdl = model(d)
    assert fluid_spectrum(mdl, [1.0, 2.0]) is None
    res = frequency_response(mdl, [0.0, 5.0], thrust=1000.0)
    assert res.power_fluid.max() == 0.0
