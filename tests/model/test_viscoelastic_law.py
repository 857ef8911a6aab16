"""Viscoelastic mount laws: closed forms of the standard linear solid, the Prony fit, the file keys."""

import copy

import numpy as np
import pytest
from conftest import ring_model_dict
from scipy.integrate import solve_ivp

from impstab.cli import main
from impstab.errors import ModelError
from impstab.model import model_from_dict
from impstab.model.viscoelastic import ViscoelasticLaw


def test_standard_linear_solid_complex_stiffness_closed_form():
    s, tau = 2.5, 3e-3
    law = ViscoelasticLaw.standard_linear_solid(s, tau)
    w = np.logspace(-1, 5, 50)
    # storage and loss of the three-parameter solid, written out
    storage = (1 + s * (w * tau) ** 2) / (1 + (w * tau) ** 2)
    loss = (s - 1) * w * tau / (1 + (w * tau) ** 2)
    r = law.ratio(w)
    np.testing.assert_allclose(r.real, storage, rtol=1e-13)
    np.testing.assert_allclose(r.imag, loss, rtol=1e-13)
    # the loss factor peaks at w tau = 1 / sqrt(s) with (s - 1) / (2 sqrt(s))
    wp = 1 / (tau * np.sqrt(s))
    rp = law.ratio(wp)
    assert rp.imag / rp.real == pytest.approx((s - 1) / (2 * np.sqrt(s)), rel=1e-13)
    assert law.high_frequency_ratio == pytest.approx(s)


def test_standard_linear_solid_relaxation_against_the_internal_variable_ode():
    """Step deflection d = 1 at t = 0: f/k0 = 1 + g (1 - z), tau z' = 1 - z, z(0) = 0 (the DESIGN
    law integrated), equal to the closed form s - (s - 1)(1 - exp(-t/tau))."""
    s, tau = 1.8, 0.02
    law = ViscoelasticLaw.standard_linear_solid(s, tau)
    t = np.linspace(0, 0.1, 11)
    sol = solve_ivp(lambda _t, z: (1 - z) / tau, (0, 0.1), [0.0], t_eval=t, rtol=1e-12, atol=1e-14)
    force = 1 + (s - 1) * (1 - sol.y[0])
    np.testing.assert_allclose(law.relaxation(t), force, rtol=1e-9)
    np.testing.assert_allclose(law.relaxation(t), s - (s - 1) * (1 - np.exp(-t / tau)), rtol=1e-14)


def test_fractional_zener_fit_error_is_stated_and_true():
    law = ViscoelasticLaw.fractional_zener(3.0, 1e-3, 0.5)
    lo, hi = law.fit_band_hz
    w = 2 * np.pi * np.logspace(np.log10(lo), np.log10(hi), 977)
    x = (1j * w * 1e-3) ** 0.5
    exact = (1 + 3.0 * x) / (1 + x)               # the law, written out
    err = np.abs(law.fit_ratio(w) - exact) / np.abs(exact)
    assert err.max() <= law.fit_error * 1.05 + 1e-12
    assert law.fit_error < 0.05 and law.n_terms >= 3
    assert np.all(law.weights > 0)
    np.testing.assert_allclose(law.ratio(w), exact, rtol=1e-13)


def test_table_interpolates_its_points_and_fits_them():
    f = np.array([1.0, 10.0, 100.0, 1000.0])
    s = np.array([1.02, 1.2, 1.6, 1.9])
    eta = np.array([0.02, 0.12, 0.15, 0.08])
    law = ViscoelasticLaw.table(f, s, eta)
    r = law.ratio(2 * np.pi * f)
    np.testing.assert_allclose(r.real, s, rtol=1e-13)
    np.testing.assert_allclose(r.imag, s * eta, rtol=1e-13)
    assert law.hysteretic  # eta(1 Hz) > 0
    assert 0 < law.fit_error < 0.5


def _visco_dict(visco: dict, where: str = "mount_rings") -> dict:
    d = ring_model_dict()
    if where == "mount_rings":
        d["mount_rings"][0]["viscoelastic"] = visco
    return d


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return repr(v)


RING_TOML = """schema_version = 1
[body]
mass = 100.0
inertia = [1.0, 6.0, 6.0]
[[mount_rings]]
count = 3
radius = 0.15
x = 0.3
start_angle = 90.0
k_axial = 1.0e5
k_shear = 2.0e4
[mount_rings.viscoelastic]
{keys}
[thrust]
operating = 2000.0
"""


@pytest.mark.parametrize("visco, field, words", [
    ({"law": "standard-linear-solid", "stiffening": 1.0, "relaxation_time": 1e-3}, "stiffening", "must be > 1"),
    ({"law": "standard-linear-solid", "stiffening": 0.5, "relaxation_time": 1e-3}, "stiffening", "between 1 and"),
    ({"law": "fractional-zener", "stiffening": 2.0, "relaxation_time": 1e-3, "alpha": 1.0}, "alpha", "strictly between 0 and 1"),
    ({"law": "fractional-zener", "stiffening": 2.0, "relaxation_time": 1e-3, "alpha": 0.0}, "alpha", "strictly between 0 and 1"),
    ({"law": "fractional-zener", "stiffening": 2.0, "relaxation_time": 1e-3}, "alpha", "is required"),
    ({"law": "standard-linear-solid", "stiffening": 2.0}, "relaxation_time", "is required"),
    ({"law": "standard-linear-solid", "stiffening": 2.0, "relaxation_time": 1e-3, "alpha": 0.5}, "alpha", "is not read"),
    ({"law": "table", "frequency_hz": [10.0, 1.0], "storage_ratio": [1.0, 1.2], "loss_factor": [0.1, 0.1]},
     "frequency_hz", "strictly increasing"),
    ({"law": "table", "frequency_hz": [1.0, 10.0], "storage_ratio": [1.0, 1.2, 1.3], "loss_factor": [0.1, 0.1]},
     "storage_ratio", "one value per frequency"),
    ({"law": "prony", "terms": [[0.5, 1e-3], [0.0, 1e-2]]}, "terms[1][0]", "must be > 0"),
    ({"law": "prony", "terms": [[0.5, True]]}, "terms[0][1]", "must be a number"),
    ({"law": "prony"}, "terms", "is required"),
    ({"law": "maxwell"}, "law", ""),
])
def test_bad_viscoelastic_keys_are_one_line_exit_2(tmp_path, capsys, visco, field, words):
    d = _visco_dict(visco)
    with pytest.raises(ModelError) as info:
        model_from_dict(copy.deepcopy(d))
    msg = str(info.value)
    assert f"mount_rings[0].viscoelastic.{field}" in msg and words in msg and "\n" not in msg
    path = tmp_path / "bad.toml"
    path.write_text(RING_TOML.format(keys="\n".join(f"{k} = {_toml_value(v)}" for k, v in visco.items())))
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "viscoelastic" in err


def test_viscoelastic_needs_an_axial_shear_mount():
    d = ring_model_dict()
    d["mounts"] = [{"position": [0.0, 0.0, 0.0], "stiffness": np.diag([1e4] * 6).tolist(),
                    "viscoelastic": {"law": "standard-linear-solid", "stiffening": 2.0, "relaxation_time": 1e-3}}]
    with pytest.raises(ModelError, match=r"mounts\[0\]\.viscoelastic.*axial-shear"):
        model_from_dict(d)


def test_ring_mounts_carry_the_law_and_undamped_drops_it():
    d = _visco_dict({"law": "standard-linear-solid", "stiffening": 2.0, "relaxation_time": 1e-3})
    model = model_from_dict(d)
    assert model.is_viscoelastic and model.is_damped
    assert all(m.viscoelastic.stiffening == 2.0 for m in model.mounts)
    assert not model.undamped().is_viscoelastic
