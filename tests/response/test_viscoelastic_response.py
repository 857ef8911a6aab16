"""Forced response with viscoelastic mounts: the exact complex stiffness at each frequency."""

import numpy as np
import pytest
from conftest import ring_model_dict

import impstab
from impstab.kinematics import rigid_map
from impstab.model import model_from_dict

LAWS = [
    {"law": "standard-linear-solid", "stiffening": 1.8, "relaxation_time": 5e-3},
    {"law": "fractional-zener", "stiffening": 2.5, "relaxation_time": 1e-3, "alpha": 0.3},
    {"law": "table", "frequency_hz": [0.5, 5.0, 50.0], "storage_ratio": [1.0, 1.2, 1.5], "loss_factor": [0.1, 0.1, 0.1]},
]


@pytest.mark.parametrize("visco", LAWS, ids=["sls", "fractional", "hysteretic-table"])
@pytest.mark.parametrize("thrust", [0.0, 6000.0])
def test_response_uses_the_exact_complex_stiffness(visco, thrust):
    d = ring_model_dict()
    d["mount_rings"][0]["viscoelastic"] = visco
    model = model_from_dict(d)
    f = np.array([0.0, 0.7, 3.0, 9.5, 40.0])
    res = impstab.frequency_response(model, f, thrust=thrust, input="sway")
    lin = impstab.linearize(model, thrust)
    law = model.mounts[0].viscoelastic
    arms = (lin.rotation @ np.array([m.position for m in model.mounts]).T).T
    for j, fj in enumerate(f):
        w = 2 * np.pi * fj
        if visco["law"] == "standard-linear-solid":  # written out: k0 (1 + i w s tau) / (1 + i w tau)
            r = (1 + 1j * w * 1.8 * 5e-3) / (1 + 1j * w * 5e-3)
        elif visco["law"] == "fractional-zener":
            z = (1j * w * 1e-3) ** 0.3
            r = (1 + 2.5 * z) / (1 + z)
        else:
            r = complex(law.ratio(w))
        z_dyn = lin.K - w * w * lin.M + 1j * w * (lin.D + lin.G) + 0j
        maps = [rigid_map(a) for a in arms]
        for b, m in zip(maps, model.mounts):
            z_dyn += b.T @ m.stiffness[:3, :3] @ b * (r - 1)
        load = np.zeros(6, complex)
        load[1] = 1.0
        q = np.linalg.solve(z_dyn, load)
        np.testing.assert_allclose(res.response[j], q, rtol=1e-9, atol=1e-12 * np.abs(q).max())
        hull = sum(m.stiffness[:3, :3] @ b @ q * r for b, m in zip(maps, model.mounts))
        assert res.transmissibility[j] == pytest.approx(np.linalg.norm(hull), rel=1e-9)
