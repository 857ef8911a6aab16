"""Excitation lines (unbalance, blade rate, spectrum), their response and the band levels."""

import copy

import numpy as np
import pytest
from _resp_models import DOFS, asym_full, model, reference_response, skew

import impstab
from impstab.errors import ModelError
from impstab.response import band_levels, excitation_lines, excitation_response
from impstab.response.bands import band_edges, band_index, nominal_frequency


def _with_excitation(d: dict, **ex) -> dict:
    d = copy.deepcopy(d)
    d["excitation"] = ex
    return d


UNBALANCE = {"mass": 0.03, "eccentricity": 0.004, "point": [-0.15, 0.0, 0.01]}


def test_unbalance_scales_with_the_square_of_the_shaft_rate_under_the_sqrt_thrust_law():
    """Omega = speed sqrt(T / T_op): the force m e Omega^2 grows like T, its frequency like sqrt T."""
    d = _with_excitation(asym_full(spin=200.0), unbalance=[UNBALANCE])
    mdl = model(d)
    t_op = d["thrust"]["operating"]
    for t in (0.25 * t_op, t_op, 4.0 * t_op):
        lines = excitation_lines(mdl, t)            # unrotated: the force in body axes at A
        omega = 200.0 * np.sqrt(t / t_op)
        assert lines.frequency_hz[0] == pytest.approx(omega / (2 * np.pi), rel=1e-14)
        force = lines.load[0, :3]
        # a1 - i a2: two orthogonal components of the same amplitude, a quarter period apart
        assert np.linalg.norm(force) == pytest.approx(0.03 * 0.004 * omega**2 * np.sqrt(2), rel=1e-13)
        assert np.linalg.norm(force.real) == pytest.approx(0.03 * 0.004 * omega**2, rel=1e-13)
        r = np.array(UNBALANCE["point"])
        assert np.allclose(lines.load[0, 3:], np.cross(r, force), rtol=0, atol=1e-14 * abs(force).max())
    ratio = excitation_lines(mdl, 4 * t_op).load[0, :3] / excitation_lines(mdl, t_op).load[0, :3]
    assert np.allclose(ratio[np.abs(ratio) > 0], 4.0, rtol=1e-13)


def test_unbalance_force_turns_with_the_shaft_in_the_plane_normal_to_the_thrust():
    d = _with_excitation(asym_full(spin=-120.0, law="constant"), unbalance=[dict(UNBALANCE, phase_deg=30.0)])
    mdl = model(d)
    lines = excitation_lines(mdl, 0.0)
    e = mdl.thrust.direction
    amp = lines.load[0, :3]
    w = 120.0
    for t in np.linspace(0.0, 0.05, 7):
        f_t = np.real(amp * np.exp(1j * w * t))
        assert abs(f_t @ e) <= 1e-12 * np.linalg.norm(f_t)           # in the plane normal to e
        assert np.linalg.norm(f_t) == pytest.approx(0.03 * 0.004 * w**2, rel=1e-12)
    # turning sense: Omega < 0 turns clockwise about e, so d/dt F is along -e x F
    f0 = np.real(amp)
    df = np.real(1j * w * amp)
    assert np.cross(f0, df) @ e < 0


def test_blade_rate_line_frequency_and_load_at_a():
    blade = {"blades": 5, "harmonic": 2, "amplitude": [10.0, 2.0, 0.0, 1.0, 0.5, 0.0],
             "phase_deg": [0.0, 90.0, 0.0, 0.0, 180.0, 0.0], "point": [-0.2, 0.01, 0.0]}
    d = _with_excitation(asym_full(spin=150.0), blade_rate=[blade])
    mdl = model(d)
    t = 5000.0
    omega = 150.0 * np.sqrt(t / d["thrust"]["operating"])
    lin = impstab.linearize(mdl, t)
    lines = excitation_lines(mdl, t, lin.rotation)
    assert lines.frequency_hz[0] == pytest.approx(2 * 5 * omega / (2 * np.pi), rel=1e-14)
    force = np.array([10.0, 2.0j, 0.0])
    moment = np.array([1.0, -0.5, 0.0])
    r = np.array(blade["point"])
    rot = lin.rotation
    assert np.allclose(lines.load[0, :3], rot @ force, atol=1e-13)
    assert np.allclose(lines.load[0, 3:], rot @ (moment + skew(r) @ force), atol=1e-13)


def test_excitation_response_equals_the_reference_solve_line_by_line():
    spectrum = {"frequency_hz": [12.0, 40.0, 40.0], "amplitude": [[0, 1, 0, 0, 0, 0], [0, 0, 2, 0, 0.1, 0], [1, 0, 0, 0, 0, 0]],
                "phase_deg": [[0] * 6, [0, 0, 45, 0, 0, 0], [0] * 6], "point": [0.1, 0.0, 0.0]}
    d = _with_excitation(asym_full(spin=150.0), unbalance=[UNBALANCE],
                         blade_rate=[{"blades": 7, "amplitude": [30.0, 3.0, 3.0, 1.0, 1.0, 1.0]}], spectrum=spectrum)
    mdl = model(d)
    t = 3000.0
    res = excitation_response(mdl, thrust=t)
    assert res.source == ("unbalance[0]", "blade_rate[0]", "spectrum[0]", "spectrum[1]", "spectrum[2]")
    assert res.input == "excitation" and np.all(np.isnan(res.transmissibility))
    for n in range(len(res.source)):
        q, forces, _ = reference_response(mdl, [res.frequency_hz[n]], res.load[n], t)
        assert np.abs(res.response[n] - q[0]).max() <= 1e-10 * np.abs(q).max()
        assert np.abs(res.hull_force[n] - forces[0].sum(axis=0)).max() <= 1e-10 * np.abs(forces).max()
    bands = res.bands()
    # the two 40 Hz lines add coherently, then every frequency adds in power
    f40 = res.hull_force[3] + res.hull_force[4]
    k = int(np.flatnonzero(bands.nominal_hz == 40.0)[0])
    assert bands.mean_square[k] == pytest.approx(0.5 * np.sum(np.abs(f40) ** 2), rel=1e-12)
    assert bands.lines[k] == 2


def test_excitation_needs_loads_and_a_shaft_rate():
    with pytest.raises(ModelError, match="no \\[excitation\\] loads"):
        excitation_response(model(asym_full()))
    d = _with_excitation(asym_full(), unbalance=[UNBALANCE])
    d["propeller"]["speed"] = 0.0
    with pytest.raises(ModelError, match="propeller.speed"):
        model(d)


def test_band_levels_by_hand():
    """Lines at 100 and 110 Hz (one band), 1000 Hz and 0 Hz (no band)."""
    f = np.array([100.0, 110.0, 1000.0, 0.0])
    amp = np.array([[3.0, 4.0, 0.0], [0.0, 0.0, 2.0j], [1.0, 1.0, 1.0], [5.0, 0.0, 0.0]])
    b = band_levels(f, amp)
    assert b.nominal_hz[0] == 100.0 and b.nominal_hz[-1] == 1000.0 and b.index.size == 11
    assert b.level_db[0] == pytest.approx(10 * np.log10((25.0 + 4.0) / 2.0), abs=1e-12)
    assert b.level_db[-1] == pytest.approx(10 * np.log10(3.0 / 2.0), abs=1e-12)
    assert np.all(np.isinf(b.level_db[1:-1])) and b.lines.tolist() == [2] + [0] * 9 + [1]


def test_iec_61260_base_ten_bands():
    lower, mid, upper = band_edges(np.array([0, -10, 10]))
    assert np.allclose(mid, [1000.0, 100.0, 10000.0], rtol=1e-15)
    assert np.allclose(upper / lower, 10 ** 0.1, rtol=1e-15)
    assert np.allclose(np.sqrt(lower * upper), mid, rtol=1e-15)
    nominal = nominal_frequency(np.arange(-17, 4))
    assert nominal.tolist() == [20, 25, 31.5, 40, 50, 63, 80, 100, 125, 160, 200, 250, 315, 400, 500, 630, 800,
                                1000, 1250, 1600, 2000]
    assert band_index(np.array([891.0, 892.0, 1122.0, 1123.0])).tolist() == [-1, 0, 0, 1]


def test_rotated_equilibrium_turns_the_excitation_with_the_body():
    d = _with_excitation(asym_full(spin=150.0), spectrum={"frequency_hz": [20.0], "amplitude": [[0, 1.0, 0, 0, 0, 0]]})
    mdl = model(d)
    lin = impstab.linearize(mdl, 40000.0)
    assert np.abs(lin.rotation - np.eye(3)).max() > 1e-3
    lines = excitation_lines(mdl, 40000.0, lin.rotation)
    assert np.allclose(lines.load[0, :3], lin.rotation[:, 1], atol=1e-15)
    assert DOFS[1] == "sway"
