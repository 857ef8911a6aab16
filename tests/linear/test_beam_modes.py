"""Modes and loci with massive beam mounts: the grown (Craig-Bampton) eigenproblem against the roots
of the exact dynamic-stiffness problem, and the locus merging at the critical thrust."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq, linear_sum_assignment

import impstab
from impstab.kinematics import rigid_map6
from impstab.model import model_from_dict
from impstab.model.beam_dynamic import dynamic_stiffness

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "model"))
from test_beam_mount import _model  # noqa: E402


def _massive(elements: int, density: float = 1100.0):
    data = _model()
    data["analysis"]["linearization"] = "classical"
    for m in data["mounts"]:
        m["beam"]["density"] = density
    model = model_from_dict(data)
    return replace(model, mounts=tuple(replace(m, beam=replace(m.beam, elements=elements)) for m in model.mounts))


def _exact_det(model):
    """``w -> det(-w^2 M + sum T6^T K_d(w) T6)`` at T = 0 (the rigid body on the exact beams)."""
    mass = model.mass_matrix
    t6 = [rigid_map6(m.position) for m in model.mounts]
    scale = np.abs(model.elastic_stiffness).max()

    def det(w):
        z = -w * w * mass
        for t, m in zip(t6, model.mounts):
            z = z + t.T @ dynamic_stiffness(m.beam, m.axis, [w]).body[0] @ t
        return np.linalg.det(z / scale)

    return det


def _root_below(det, w_fe, rel=2e-3):
    """The exact root just below a finite-element frequency (consistent mass: an upper bound)."""
    lo, hi = w_fe * (1 - rel), w_fe * (1 + 1e-9)
    assert np.sign(det(lo)) != np.sign(det(hi)), "no sign change of the exact determinant"
    return brentq(det, lo, hi, xtol=1e-14 * w_fe, rtol=1e-15)


def test_modes_at_rest_are_the_roots_of_the_exact_dynamic_stiffness():
    fine = _massive(32)
    md = impstab.modes(fine, 0.0)
    assert md.mount_elements == (32, 32, 32, 32) and md.internal_dofs > 0
    assert md.kind[:6] == ["body"] * 6 and md.kind[6] == "mount"
    assert np.all(md.internal_share[:6] < 1e-2) and md.internal_share[6] > 0.5
    ds = md.to_xarray()
    assert list(ds["kind"].values) == md.kind and np.array_equal(ds["internal_share"].values, md.internal_share)
    det = _exact_det(fine)
    # the six body modes: to 1e-6 relative (the mesh error is far below it at these frequencies)
    for w in md.omega[:6]:
        assert w == pytest.approx(_root_below(det, w), rel=1e-6)
    # the first internal mount mode: second-order convergence of the mesh to the exact root
    exact = _root_below(det, md.omega[6], rel=2e-2)
    errors = [impstab.modes(_massive(n), 0.0).omega[6] / exact - 1 for n in (8, 16)] + [md.omega[6] / exact - 1]
    assert all(e > 0 for e in errors) and errors[0] / errors[1] > 3.5 and errors[1] / errors[2] > 3.5, errors
    assert errors[-1] < 3e-4, errors


def test_locus_merges_at_the_critical_thrust():
    model = _massive(8)
    crit = impstab.critical_thrust(model)
    assert crit.kind == "flutter"
    t = crit.thrust
    res = impstab.locus(model, np.array([0.9, 1 - 1e-4, 1 + 1e-4, 1.1]) * t, critical=True)
    assert res.critical_thrust == pytest.approx(t, rel=1e-12)
    body = ~res.is_mount_branch
    assert body.sum() == 12 and res.internal_share is not None
    assert all(label.startswith("mount internal") for label, b in
               zip(res.branch_labels(), range(res.modes.max() + 1)) if res.is_mount_branch[res.modes == b][0])
    growth = res.growth_rate[:, body].max(axis=1)
    scale = np.abs(res.eigenvalues[:, body]).max()
    assert growth[0] <= 1e-9 * scale and growth[1] <= 1e-6 * scale  # stable below the onset
    assert growth[2] > 0 and growth[3] > growth[2]                   # a growing pair just above it
    # the two merging frequencies: apart below, one frequency (the onset's) above
    lam = res.eigenvalues[2, body]
    top = lam[np.argmax(lam.real)]
    assert abs(top.imag) == pytest.approx(crit.omega, rel=1e-2)
    fig = res.plot()
    assert len(fig.frequency.get_lines()) > 0


def test_symmetric_layout_keeps_its_two_planes_in_the_locus():
    # the example's four beams on a symmetric ring: with internal dofs the two identical planes are
    # one group of dofs; the body branches must still be those of the massless beams
    example = Path(__file__).resolve().parents[2] / "examples" / "imp_beam_mounts.toml"
    model = impstab.load_model(example)
    massless = replace(model, mounts=tuple(replace(m, beam=replace(m.beam, density=0.0)) for m in model.mounts))
    thrusts = np.linspace(0.0, 40000.0, 17)
    grown, plain = impstab.locus(model, thrusts), impstab.locus(massless, thrusts)
    body = grown.body_branches()
    assert body.branch_labels() == plain.branch_labels()
    assert np.array_equal(body.mode, plain.mode)
    # column by column the same tracks below the onset, up to the beams' inertia (a 3e-3 mass
    # share); past a coalescence which of the two merged branches takes the growing root is no
    # continuity's to say: there the same eigenvalues, row by row
    scale = np.abs(plain.eigenvalues).max()
    stable = np.all(plain.eigenvalues.real < 1e-9 * scale, axis=1) & np.all(body.eigenvalues.real < 1e-9 * scale, axis=1)
    assert stable[:5].all() and not stable[-1]
    assert np.abs(body.eigenvalues[stable] - plain.eigenvalues[stable]).max() < 1e-2 * scale
    for b, p in zip(body.eigenvalues[~stable], plain.eigenvalues[~stable]):
        dist = np.abs(b[:, None] - p[None, :])
        rows, cols = linear_sum_assignment(dist)
        assert dist[rows, cols].max() < 1e-2 * scale


def test_the_roll_mode_of_the_decoupling_check_is_a_body_mode():
    from impstab.response.decoupling import decoupling_check

    model = _massive(8)
    md = impstab.modes(model, 0.0)
    check = decoupling_check(model, 0.0, modal=md)
    # an internal mount mode can carry a larger roll share of its (small) body motion
    assert md.participation[np.array(md.kind) == "mount", 3].max() > check.roll_share
    assert md.kind[check.roll_mode] == "body"
    body = [j for j, k in enumerate(md.kind) if k == "body"]
    assert check.roll_mode == body[int(np.argmax(md.participation[body, 3]))]


def _compressible(density: float, elements: int = 2):
    """The test layout with a compressible fluid; 2 elements per beam (the fixed point per mode does
    not depend on the mesh, and each iteration solves the whole grown system)."""
    data = _model()
    data["analysis"]["linearization"] = "classical"
    for m in data["mounts"]:
        m["beam"]["density"] = density
    data["hull"] = {"radius": 0.2, "length": 0.8, "center": [0.1, 0.0, 0.0]}
    data["fluid"] = {"model": "baffled-cylinder", "density": 1025.0, "sound_speed": 1500.0}
    model = model_from_dict(data)
    return replace(model, mounts=tuple(replace(m, beam=replace(m.beam, elements=elements)) for m in model.mounts))


def test_modes_with_compressible_fluid_and_massive_beams_take_the_fluid_at_each_mode_frequency():
    from impstab.linear.mount_dofs import mount_dofs

    model = _compressible(1100.0)
    md = impstab.modes(model, 0.0)
    assert md.internal_dofs > 0 and md.kind[:6] == ["body"] * 6
    dofs = mount_dofs(model)
    k6 = model.elastic_stiffness
    # each mode solves the grown pencil assembled here with the fluid's added mass and radiation
    # damping at that mode's own frequency
    for lam in md.eigenvalues[:8]:
        added, radiation = model.fluid.coefficients_at(abs(lam.imag) / (2 * np.pi))
        m, d, g, k = (a[0] for a in dofs.augment((model.body.mass_matrix() + added)[None], radiation[None],
                                                  np.zeros((1, 6, 6)), k6[None]))
        pencil = lam * lam * m + lam * d + k
        sv = np.linalg.svd(pencil, compute_uv=False)
        assert sv[-1] / sv[0] < 1e-11, (lam, sv[-1] / sv[0])
    # the radiation damping damps every body mode (a pair in the left half-plane)
    assert np.all(md.eigenvalues[:6].real < 0)
    # nearly massless beams: the body modes of the massless-beam model (its own 6-dof fluid iteration)
    light, massless = impstab.modes(_compressible(1e-6), 0.0), impstab.modes(_compressible(0.0), 0.0)
    np.testing.assert_allclose(light.eigenvalues[:6], massless.eigenvalues, rtol=1e-8)

