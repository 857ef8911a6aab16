"""The compiled stacked solve and the batched evaluation of many designs."""

import numpy as np
from _resp_models import asym_full, model, ring_damped

import impstab
from impstab.response import frequency_response, harmonic_response
from impstab.response.kernel import solve_harmonic


def test_stacked_solve_equals_numpy_solve():
    rng = np.random.default_rng(7)
    nd, nf = 3, 40
    m = rng.normal(size=(nd, 6, 6))
    c = rng.normal(size=(nd, 6, 6))
    k = rng.normal(size=(nd, 6, 6))
    w = rng.uniform(0, 10, nf)
    loads = rng.normal(size=(nd, nf, 6)) + 1j * rng.normal(size=(nd, nf, 6))
    extra = rng.normal(size=(nd, nf, 6, 6)) + 1j * rng.normal(size=(nd, nf, 6, 6))
    none = np.zeros((1, 0, 0), complex)
    q, ratio = solve_harmonic(m, c, k, w, loads, extra, np.zeros((nd, 0, 6, 6)), np.zeros((nd, 0, 6, 6)),
                              np.zeros((nd, 0, 6, 6)), none)
    z = k[:, None] + 1j * w[None, :, None, None] * c[:, None] - w[None, :, None, None] ** 2 * m[:, None] + extra
    ref = np.linalg.solve(z, loads[..., None])[..., 0]
    assert np.abs(q - ref).max() <= 1e-12 * np.abs(ref).max()
    assert ratio.min() > 0


def test_singular_system_is_flagged_not_raised():
    """An undamped resonance hit exactly: the pivot ratio is 0 and the response is not finite."""
    m = np.eye(6)[None]
    k = np.diag([1.0, 4.0, 9.0, 16.0, 25.0, 36.0])[None]
    loads = np.ones((1, 1, 6), complex)
    none = np.zeros((1, 0, 0), complex)
    empty = np.zeros((1, 0, 6, 6))
    q, ratio = solve_harmonic(m, np.zeros((1, 6, 6)), k, np.array([0.5, 2.0]), loads, np.zeros((1, 0, 6, 6), complex),
                              empty, empty, empty, none)
    assert ratio[0, 0] > 0 and ratio[0, 1] == 0.0
    assert np.all(np.isfinite(q[0, 0])) and not np.all(np.isfinite(q[0, 1]))


def test_undamped_resonance_warns_in_the_result():
    mdl = model(ring_damped(mount_rings=[{"count": 3, "radius": 0.15, "x": 0.3, "start_angle": 90.0,
                                            "k_axial": 1.0e5, "k_shear": 2.0e4}]))
    f_surge = np.sqrt(3e5 / 100.0) / (2 * np.pi)
    res = frequency_response(mdl, [1.0, f_surge], thrust=0.0, input="surge")
    assert any("singular" in w for w in res.warnings)


def test_unstable_thrust_is_reported():
    mdl = impstab.load_model("examples/imp_symmetric.toml")
    res = frequency_response(mdl, [1.0, 2.0], thrust=19000.0)      # above the critical 18012 N
    assert any("unstable" in w for w in res.warnings)


def test_batched_designs_equal_one_design_at_a_time():
    """A study evaluates a chunk of designs in one call: stacked M, D, G, K, poses and mounts."""
    designs = [asym_full(tangency=t, spin=s) for t, s in ((0.8, 300.0), (1.0, 0.0), (0.3, 150.0))]
    thrusts = [9000.0, 3000.0, 15000.0]
    f = np.geomspace(0.5, 50.0, 30)
    stack = {k: [] for k in ("M", "D", "G", "K", "R", "pos", "km", "cm")}
    singles = []
    for d, t in zip(designs, thrusts):
        mdl = model(d)
        lin = impstab.linearize(mdl, t)
        for key, val in (("M", lin.M), ("D", lin.D), ("G", lin.G), ("K", lin.K), ("R", lin.rotation),
                         ("pos", [m.position for m in mdl.mounts]), ("km", [m.stiffness for m in mdl.mounts]),
                         ("cm", [m.damping for m in mdl.mounts])):
            stack[key].append(np.asarray(val, float))
        singles.append(frequency_response(mdl, f, thrust=t, input="heave"))
    s = {k: np.array(v) for k, v in stack.items()}
    load = np.zeros((1, 1, 6), complex)
    load[..., 2] = 1.0
    sol = harmonic_response(s["M"], s["D"], s["G"], s["K"], s["R"], s["pos"], s["km"], s["cm"], 2 * np.pi * f, load)
    for i, one in enumerate(singles):
        assert np.array_equal(sol.response[i], one.response)
        assert np.array_equal(sol.hull_force[i], one.hull_force)
