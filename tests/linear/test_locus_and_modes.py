"""Loci, mode tracking and modal results against independent routes."""

import numpy as np
import pytest
import scipy.linalg as sla
from conftest import asymmetric_model_dict, ring_model_dict

import impstab
from impstab import linearize
from impstab.linear.locus import LocusResult, locus
from impstab.linear.modes import modes
from impstab.model import model_from_dict


def test_locus_values_equal_independent_eigenvalues():
    model = model_from_dict(asymmetric_model_dict())
    thrusts = np.linspace(0.0, 20000.0, 31)
    res = locus(model, thrusts)
    for i in (0, 10, 30):
        ref = sla.eigvals(linearize(model, thrusts[i]).state_matrix())
        got = res.eigenvalues[i]
        assert np.allclose(np.sort_complex(got), np.sort_complex(ref), rtol=1e-9, atol=1e-9 * np.abs(ref).max())


def test_tracking_keeps_branches_continuous():
    model = model_from_dict(ring_model_dict())
    res = locus(model, steps=300, thrust_max=17000.0)   # below the merge: all branches distinct or dual
    jumps = np.abs(np.diff(res.eigenvalues, axis=0)) / np.abs(res.eigenvalues).max()
    assert jumps.max() < 0.02    # no branch jumps between the separated curves


def test_locus_round_trips_through_netcdf(tmp_path):
    model = model_from_dict(ring_model_dict())
    res = locus(model, steps=20)
    path = tmp_path / "l.nc"
    res.to_xarray().to_netcdf(path, engine="h5netcdf")
    import xarray as xr

    back = LocusResult.from_xarray(xr.load_dataset(path))
    assert np.array_equal(back.eigenvalues, res.eigenvalues)
    assert back.linearization == res.linearization


def test_single_oscillator_modes():
    # one mount ring made very stiff except in sway: check a damped mode against the closed form
    model = model_from_dict(ring_model_dict())
    res = modes(model, 0.0)
    k_surge = model.elastic_stiffness[0, 0]
    w = np.sqrt(k_surge / 100.0)
    surge = [j for j, d in enumerate(res.dominant()) if d == ("surge",)]
    assert len(surge) == 1 and res.omega[surge[0]] == pytest.approx(w, rel=1e-12)
    assert res.stable


def test_damped_surge_mode_matches_single_oscillator():
    d = ring_model_dict()
    d["mount_rings"][0]["c_axial"] = 300.0
    model = model_from_dict(d)
    res = modes(model, 0.0)
    k, c, m = 3e5, 900.0, 100.0
    wn, zeta = np.sqrt(k / m), c / (2 * np.sqrt(k * m))
    j = [i for i, dd in enumerate(res.dominant()) if dd == ("surge",)][0]
    assert res.eigenvalues[j] == pytest.approx(complex(-zeta * wn, wn * np.sqrt(1 - zeta**2)), rel=1e-12)
    assert res.damping_ratio[j] == pytest.approx(zeta, rel=1e-12)


def test_callable_system_in_the_generic_engine():
    m = np.array([[3.0, 1.0], [1.0, 1.0]])
    k0 = np.array([[2.0, -1.0], [-1.0, 1.0]])
    k1 = np.array([[-1.0, 1.0], [0.0, 0.0]])
    res = impstab.critical_load(lambda p: (m, None, None, k0 + p * k1), p_max=5.0)
    assert res.load == pytest.approx(3.5 - np.sqrt(2), rel=1e-13)
    with pytest.raises(ValueError):
        impstab.critical_load(lambda p: (m, None, None, k0), k0, k1, p_max=5.0)


@pytest.mark.parametrize("thrust", [0.0, 5000.0, 15000.0])
def test_repeated_modes_are_the_planes_of_a_symmetric_layout(thrust):
    """A symmetric layout's equal frequencies come as the sway-yaw and heave-pitch plane modes,
    whatever basis the eigensolver returned; each plane mode's shape is the eigenvector of the
    planar 2 x 2 problem (an independent route)."""
    model = impstab.load_model("examples/imp_symmetric.toml")
    res = modes(model, thrust)
    sys = linearize(model, thrust)
    a = np.linalg.solve(sys.M, sys.K)
    for plane, (t, r), other in (("sway-yaw", (1, 5), (2, 4)), ("heave-pitch", (2, 4), (1, 5))):
        s, v = np.linalg.eig(a[np.ix_([t, r], [t, r])])
        for k in range(2):
            omega = np.sqrt(s[k].real)
            j = [i for i in range(6) if abs(res.eigenvalues[i].imag - omega) <= 1e-9 * omega
                 and np.abs(res.shapes[list(other), i]).max() <= 1e-12]
            assert len(j) == 1, (plane, k, res.shapes)
            shape = res.shapes[:, j[0]]
            assert np.abs(shape[[0, 3]]).max() <= 1e-12
            ratio = shape[t] / shape[r]
            assert abs(ratio - v[0, k] / v[1, k]) <= 1e-10 * max(1.0, abs(ratio))
