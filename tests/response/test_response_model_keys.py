"""Validation of the isolation keys: [excitation], [foundation], mount ratings."""

import copy

import numpy as np
import pytest
from _resp_models import asym_full, ring_damped

from impstab.errors import ModelError
from impstab.model import model_from_dict


def _bad(d, field, rule):
    with pytest.raises(ModelError) as err:
        model_from_dict(d)
    assert err.value.field == field, str(err.value)
    assert rule in str(err.value)


def _ex(**ex):
    d = copy.deepcopy(asym_full())
    d["excitation"] = ex
    return d


def test_valid_keys_assemble():
    d = _ex(input="yaw", unbalance=[{"mass": 0.01, "eccentricity": 0.002}],
            blade_rate=[{"blades": 5, "amplitude": [1, 0, 0, 0, 0, 0]}, {"blades": 5, "harmonic": 2, "amplitude": [0.5] * 6}],
            spectrum={"frequency_hz": [10.0, 20.0], "amplitude": [[1.0] * 6, [2.0] * 6], "phase_deg": [[0.0] * 6, [90.0] * 6]})
    d["foundation"] = {"model": "lumped", "mass": 20.0, "stiffness": 1e6, "damping": 100.0}
    d["mounts"][0].update(rated_force=2000.0, max_deflection=0.01)
    m = model_from_dict(d)
    assert m.excitation.input == "yaw" and len(m.excitation.blade_rate) == 2 and m.excitation.spectrum.amplitude.shape == (2, 6)
    assert m.foundation.model == "lumped" and m.mounts[0].rated_force == 2000.0 and m.mounts[1].rated_force is None
    assert np.allclose(m.mounts[0].axis, np.array([1.0, 0.1, 0.0]) / np.linalg.norm([1.0, 0.1, 0.0]))
    r = ring_damped()
    r["mount_rings"][0]["max_deflection"] = 0.005
    assert all(mt.max_deflection == 0.005 for mt in model_from_dict(r).mounts)


@pytest.mark.parametrize(
    "ex,field,rule",
    [
        ({"input": "twist"}, "excitation.input", "must be"),
        ({"unbalance": [{"mass": 0.01}]}, "excitation.unbalance[0].eccentricity", "is required"),
        ({"unbalance": [{"mass": -0.01, "eccentricity": 0.002}]}, "excitation.unbalance[0].mass", "greater than 0"),
        ({"blade_rate": [{"blades": 0, "amplitude": [1] * 6}]}, "excitation.blade_rate[0].blades", "greater than or equal to 1"),
        ({"blade_rate": [{"blades": 5.5, "amplitude": [1] * 6}]}, "excitation.blade_rate[0].blades", "integer"),
        ({"blade_rate": [{"blades": True, "amplitude": [1] * 6}]}, "excitation.blade_rate[0].blades", "integer"),
        ({"blade_rate": [{"blades": 5, "amplitude": [1] * 5}]}, "excitation.blade_rate[0].amplitude", "6 items"),
        ({"blade_rate": [{"blades": 5, "amplitude": [1, -1, 0, 0, 0, 0]}]}, "excitation.blade_rate[0].amplitude[1]", ">= 0"),
        ({"spectrum": {"frequency_hz": [1.0, 2.0], "amplitude": [[1] * 6]}}, "excitation.spectrum.amplitude", "one row"),
        ({"spectrum": {"frequency_hz": [-1.0], "amplitude": [[1] * 6]}}, "excitation.spectrum.frequency_hz[0]", "greater than or equal to 0"),
        ({"spectrum": {"frequency_hz": [1.0], "amplitude": [[1] * 6], "phase_deg": [[0] * 6] * 2}}, "excitation.spectrum.phase_deg", "one row"),
        ({"spectrum": {"frequency_hz": [1.0], "amplitude": [[1] * 6], "colour": 1}}, "excitation.spectrum.colour", "unknown key"),
    ],
)
def test_bad_excitation_keys(ex, field, rule):
    _bad(_ex(**ex), field, rule)


@pytest.mark.parametrize(
    "found,field,rule",
    [
        ({"model": "lumped"}, "foundation", "needs mass, stiffness or damping"),
        ({"model": "lumped", "mass": -1.0}, "foundation.mass", "greater than or equal to 0"),
        ({"model": "rigid", "stiffness": 1e5}, "foundation.stiffness", "is not read"),
        ({"model": "mobility-table", "frequency_hz": [1.0, 2.0], "mobility_real": [1e-4, 1e-4]},
         "foundation.mobility_imag", "is required"),
        ({"model": "mobility-table", "frequency_hz": [2.0, 1.0], "mobility_real": [1e-4] * 2, "mobility_imag": [0.0] * 2},
         "foundation.frequency_hz", "strictly increasing"),
        ({"model": "mobility-table", "frequency_hz": [1.0, 2.0], "mobility_real": [-1e-4, 1e-4], "mobility_imag": [0.0] * 2},
         "foundation.mobility_real[0]", "passive"),
        ({"model": "mobility-table", "frequency_hz": [1.0, 2.0], "mobility_real": [0.0, 1e-4], "mobility_imag": [0.0] * 2},
         "foundation.mobility_real[0]", "rigid point"),
        ({"model": "impedance-table", "frequency_hz": [1.0, 2.0, 3.0], "impedance_real": [1.0] * 3, "impedance_imag": [0.0] * 2},
         "foundation.impedance_imag", "one value per frequency"),
        ({"model": "impedance-table", "frequency_hz": [1.0, 2.0], "impedance_real": [1.0] * 2, "impedance_imag": [0.0] * 2,
          "mass": 3.0}, "foundation.mass", "is not read"),
        ({"model": "soft"}, "foundation.model", "must be"),
    ],
)
def test_bad_foundation_keys(found, field, rule):
    d = copy.deepcopy(asym_full())
    d["foundation"] = found
    _bad(d, field, rule)


@pytest.mark.parametrize("key,value,rule", [("rated_force", 0.0, "greater than 0"), ("max_deflection", "1 mm", "number")])
def test_bad_ratings(key, value, rule):
    d = copy.deepcopy(asym_full())
    d["mounts"][1][key] = value
    _bad(d, f"mounts[1].{key}", rule)


def test_table_foundation_outside_its_range_is_an_error():
    from impstab.response import frequency_response

    d = copy.deepcopy(asym_full())
    d["foundation"] = {"model": "impedance-table", "frequency_hz": [1.0, 50.0], "impedance_real": [1e3, 1e3],
                       "impedance_imag": [0.0, 0.0]}
    m = model_from_dict(d)
    with pytest.raises(ModelError) as err:
        frequency_response(m, [0.5, 10.0])
    assert err.value.field == "foundation.frequency_hz" and "1 to 50 Hz" in str(err.value)
