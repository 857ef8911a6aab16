"""Beam mounts: the clamped-free tip compliances, the model file, the equivalent 6 x 6 mount."""

from __future__ import annotations

import copy

import numpy as np
import pytest

import impstab
from impstab.errors import ModelError
from impstab.model import model_from_dict
from impstab.model.beam import BeamMount, beam_frame, cowper_shear_coefficient, internal_matrices, tip_stiffness

L, DO, DI, E, G = 0.05, 0.04, 0.012, 5.0e6, 1.7e6
BEAM = BeamMount(L, DO, DI, E, G)
AREA = np.pi / 4 * (DO**2 - DI**2)
I2 = np.pi / 64 * (DO**4 - DI**4)


def _compliance(axis, load):
    """Tip displacement and rotation (hull frame) of the clamped beam under a tip load."""
    return np.linalg.solve(tip_stiffness(BEAM, axis), load)


@pytest.mark.parametrize("axis", [[1.0, 0.0, 0.0], [0.2, -0.7, 0.4]])
def test_tip_compliances_are_the_closed_forms(axis):
    frame = beam_frame(axis)
    e1, e2, e3 = frame.T
    kappa = cowper_shear_coefficient(E / (2 * G) - 1, DI / DO)
    f = lambda force=(0, 0, 0), moment=(0, 0, 0): _compliance(axis, np.concatenate([force, moment]))  # noqa: E731
    # axial L/(EA), torsion L/(GJ)
    assert f(force=e1)[:3] @ e1 == pytest.approx(L / (E * AREA), rel=1e-12)
    assert f(moment=e1)[3:] @ e1 == pytest.approx(L / (G * 2 * I2), rel=1e-12)
    # transverse force: L^3/(3EI) + L/(kappa G A) deflection, L^2/(2EI) rotation (right-hand rule)
    for ev, rot in ((e2, e3), (e3, -e2)):
        d = f(force=ev)
        assert d[:3] @ ev == pytest.approx(L**3 / (3 * E * I2) + L / (kappa * G * AREA), rel=1e-12)
        assert d[3:] @ rot == pytest.approx(L**2 / (2 * E * I2), rel=1e-12)
        # tip moment about the rotation axis: L/(EI) rotation, L^2/(2EI) deflection along ev
        d = f(moment=rot)
        assert d[3:] @ rot == pytest.approx(L / (E * I2), rel=1e-12)
        assert d[:3] @ ev == pytest.approx(L**2 / (2 * E * I2), rel=1e-12)


def test_a_bent_cantilever_rotates_toward_its_deflection():
    # a tip force along +y on a beam along +x: the tip section turns about +z (right-hand rule)
    d = _compliance([1.0, 0.0, 0.0], np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0]))
    assert d[1] > 0 and d[5] > 0 and abs(d[4]) < 1e-15 * d[5]
    d = _compliance([1.0, 0.0, 0.0], np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0]))
    assert d[2] > 0 and d[4] < 0


def test_cowper_values():
    # Cowper (1966): solid circle 6(1+nu)/(7+6nu); thin-walled tube (m -> 1) 2(1+nu)/(4+3nu)
    assert cowper_shear_coefficient(0.3) == pytest.approx(6 * 1.3 / (7 + 1.8), rel=1e-15)
    assert cowper_shear_coefficient(0.3, 1.0) == pytest.approx(2 * 1.3 / (4 + 0.9), rel=1e-15)


@pytest.mark.parametrize("elements", [1, 2, 5, 16])
def test_condensed_mesh_is_the_tip_stiffness(elements):
    axis = [0.3, 0.5, -0.8]
    ktt, kti, kii, *_ = internal_matrices(BEAM, axis, elements)
    kc = ktt - kti @ np.linalg.solve(kii, kti.T) if elements > 1 else ktt
    kt = tip_stiffness(BEAM, axis)
    assert np.abs(kc - kt).max() <= 1e-11 * np.abs(kt).max()


def _model(beam: dict | None = None, **extra) -> dict:
    beam = beam or {"length": L, "outer_diameter": DO, "inner_diameter": DI, "youngs_modulus": E, "shear_modulus": G}
    mounts = []
    for pos, axis in (([0.3, 0.16, 0.02], [1.0, 0.1, 0.0]), ([0.28, -0.05, 0.15], [1.0, 0.0, 0.15]),
                      ([0.33, -0.09, -0.13], [1.0, -0.05, -0.05]), ([-0.2, 0.0, -0.14], [0.0, 0.0, 1.0])):
        mounts.append({"position": pos, "axis": axis, "beam": dict(beam)})
    mounts[0].update(extra)
    return {"schema_version": 1, "body": {"mass": 120.0, "cg": [0.05, 0.01, -0.005],
                                          "inertia": [[1.4, 0.05, 0.0], [0.05, 7.5, 0.1], [0.0, 0.1, 7.0]]},
            "mounts": mounts, "thrust": {"point": [-0.1, 0.01, 0.02], "direction": [1.0, 0.01, -0.02],
                                         "operating": 3000.0},
            "analysis": {"thrust_max": 3.0e4}}


def _stiffness_twin(data: dict) -> dict:
    """The same model with each beam written as its 6 x 6 stiffness, formed by hand from the
    closed-form flexibility (not through impstab's beam module)."""
    twin = copy.deepcopy(data)
    for m in twin["mounts"]:
        b = m.pop("beam")
        a, i2 = np.pi / 4 * (b["outer_diameter"]**2 - b.get("inner_diameter", 0.0)**2), np.pi / 64 * (b["outer_diameter"]**4 - b.get("inner_diameter", 0.0)**4)
        e, g, ln = b["youngs_modulus"], b["shear_modulus"], b["length"]
        nu, r = e / (2 * g) - 1, b.get("inner_diameter", 0.0) / b["outer_diameter"]
        kap = 6 * (1 + nu) * (1 + r * r)**2 / ((7 + 6 * nu) * (1 + r * r)**2 + (20 + 12 * nu) * r * r)
        c = np.zeros((6, 6))
        c[0, 0], c[3, 3] = ln / (e * a), ln / (g * 2 * i2)
        c[1, 1] = c[2, 2] = ln**3 / (3 * e * i2) + ln / (kap * g * a)
        c[4, 4] = c[5, 5] = ln / (e * i2)
        c[1, 5] = c[5, 1] = ln**2 / (2 * e * i2)
        c[2, 4] = c[4, 2] = -ln**2 / (2 * e * i2)
        ax = np.asarray(m["axis"], float) / np.linalg.norm(m["axis"])
        t = np.array([0.0, 1.0, 0.0]) if abs(ax[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
        e2 = np.cross(t, ax)
        e2 /= np.linalg.norm(e2)
        r3 = np.column_stack([ax, e2, np.cross(ax, e2)])
        r6 = np.kron(np.eye(2), r3)
        k = r6 @ np.linalg.inv(c) @ r6.T
        m["stiffness"] = (0.5 * (k + k.T)).tolist()
    return twin


@pytest.mark.parametrize("linearization", ["classical", "equilibrium"])
def test_massless_beam_equals_its_stiffness_mount(linearization):
    data = _model()
    data["analysis"]["linearization"] = linearization
    beam = impstab.critical_thrust(model_from_dict(data))
    twin = impstab.critical_thrust(model_from_dict(_stiffness_twin(data)))
    assert beam.kind == twin.kind != "none"
    assert beam.thrust == pytest.approx(twin.thrust, rel=1e-12)
    assert beam.omega == pytest.approx(twin.omega, rel=1e-10)


@pytest.mark.parametrize("extra, field, words", [
    ({"k_axial": 1e5}, "mounts[0].k_axial", "not two of them"),
    ({"stiffness": np.eye(6).tolist()}, "mounts[0].stiffness", "not two of them"),
    ({"k3_axial": 1e9}, "mounts[0].k3_axial", "not with [mounts.beam]"),
])
def test_beam_with_spring_keys_is_refused(extra, field, words):
    with pytest.raises(ModelError) as info:
        model_from_dict(_model(**extra))
    assert info.value.field == field and words in str(info.value)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("key, value, field, words", [
    ("inner_diameter", 0.04, "mounts[0].beam.inner_diameter", "below outer_diameter"),
    ("inner_diameter", 0.05, "mounts[0].beam.inner_diameter", "below outer_diameter"),
    ("youngs_modulus", True, "mounts[0].beam.youngs_modulus", "not a boolean"),
    ("shear_modulus", "1e6", "mounts[0].beam.shear_modulus", "must be a number"),
    ("density", -1.0, "mounts[0].beam.density", "kg/m^3"),
    ("length", 0.0, "mounts[0].beam.length", "m"),
    ("shear_coefficient", 1.5, "mounts[0].beam.shear_coefficient", "shear coefficient"),
    ("thickness", 1.0, "mounts[0].beam.thickness", "unknown"),
])
def test_bad_beam_values(key, value, field, words):
    data = _model()
    data["mounts"][0]["beam"][key] = value
    with pytest.raises(ModelError) as info:
        model_from_dict(data)
    assert info.value.field == field, str(info.value)
    assert words in str(info.value), str(info.value)


def test_missing_beam_key():
    data = _model()
    del data["mounts"][0]["beam"]["youngs_modulus"]
    with pytest.raises(ModelError) as info:
        model_from_dict(data)
    assert info.value.field == "mounts[0].beam.youngs_modulus" and "required" in str(info.value)


def test_beam_keys_are_study_paths():
    from impstab.studies.paths import resolve_path

    data = _model()
    for key in ("length", "outer_diameter", "inner_diameter", "youngs_modulus", "shear_modulus", "density",
                "shear_coefficient"):
        p = resolve_path(f"mounts[0].beam.{key}", data)
        assert p.kind == "float"
