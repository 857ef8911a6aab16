"""Exact dynamic stiffness of Timoshenko beam mounts against independent answers: the static tip
stiffness, the rod and shaft closed forms, the Euler-Bernoulli closed form, the finite-element mesh."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

from impstab.model.beam import BeamMount, beam_frame, internal_matrices, tip_stiffness
from impstab.model.beam_dynamic import dynamic_stiffness, dynamic_stiffness_local

BEAM = BeamMount(0.05, 0.04, 0.012, 5.0e6, 1.7e6, density=1100.0)
AXIS = np.array([0.3, -0.4, 0.8])


def test_zero_frequency_is_the_static_tip_stiffness():
    kt = tip_stiffness(BEAM, AXIS)
    dyn = dynamic_stiffness(BEAM, AXIS, [0.0])
    assert np.abs(dyn.body[0] - kt).max() <= 1e-10 * np.abs(kt).max()
    # statics: the hull carries the body-end force; its moment adds the lever L a x F
    f = dyn.transmitted[0]
    assert np.abs(f[:3] - kt[:3]).max() <= 1e-10 * np.abs(kt).max()
    lever = np.cross(BEAM.length * AXIS / np.linalg.norm(AXIS), kt[:3].T).T  # r_body - r_hull = L a
    assert np.abs(f[3:] - (kt[3:] + lever)).max() <= 1e-10 * np.abs(kt).max()


def test_reciprocity():
    full = dynamic_stiffness(BEAM, AXIS, np.linspace(0.0, 2 * np.pi * 3000.0, 7)).full
    assert np.abs(full - np.swapaxes(full, -1, -2)).max() <= 1e-12 * np.abs(full).max()


def test_rod_and_shaft_closed_forms():
    # clamped rod: EA k cot(kL) at the free end, EA k / sin(kL) transmitted, k = omega sqrt(rho / E)
    w = np.linspace(10.0, 2 * np.pi * 2500.0, 41)  # through the first clamped-clamped resonances
    k_local, _ = dynamic_stiffness_local(BEAM, w)
    L = BEAM.length
    for dof, stiff, modulus in ((0, BEAM.youngs_modulus * BEAM.area, BEAM.youngs_modulus),
                                (3, BEAM.shear_modulus * BEAM.polar_moment, BEAM.shear_modulus)):
        k = w * np.sqrt(BEAM.density / modulus)
        body = stiff * k / np.tan(k * L)
        trans = stiff * k / np.sin(k * L)
        assert np.allclose(k_local[:, dof + 6, dof + 6], body, rtol=1e-9, atol=0)
        assert np.allclose(-k_local[:, dof, dof + 6], trans, rtol=1e-9, atol=0)
        assert np.allclose(k_local[:, dof, dof], body, rtol=1e-9, atol=0)


@pytest.mark.parametrize("top", [30.0, 60.0])
def test_euler_bernoulli_limit(top):
    # infinite shear stiffness and no rotary inertia: the Euler-Bernoulli clamped-free tip stiffness
    # (beta^4 = rho A w^2 / (E I); D = 1 - cos cosh):
    # K_vv = EI b^3 (cos sinh + sin cosh) / D, K_vt = -EI b^2 sin sinh / D, K_tt = EI b (sin cosh - cos sinh) / D;
    # up to beta L = 60, where one transfer matrix over L would lose 2 beta L / ln 10 = 52 digits
    stiff = BeamMount(0.05, 0.04, 0.0, 5.0e6, 1.7e6, shear_coefficient=1e16, density=1100.0)
    EI = stiff.youngs_modulus * stiff.second_moment
    x = np.linspace(0.05, top, 301)
    b = x / stiff.length
    w = np.sqrt(EI / (stiff.density * stiff.area)) * b**2
    k_local, lost = dynamic_stiffness_local(stiff, w, rotary_inertia=False)
    assert lost.max() < 2.0
    c, s, ch, sh = np.cos(x), np.sin(x), np.cosh(x), np.sinh(x)
    den = 1.0 - c * ch
    kvv = EI * b**3 * (c * sh + s * ch) / den
    kvt = -EI * b**2 * s * sh / den
    ktt = EI * b * (s * ch - c * sh) / den
    # e1-e2 plane: (u2, +theta3); e1-e3 plane: (u3, -theta2); relative to the block's size
    for v, t, sign in ((7, 11, 1.0), (8, 10, -1.0)):
        size = np.abs(np.stack([kvv, kvt * b, ktt * b * b])).max(axis=0)
        assert np.all(np.abs(k_local[:, v, v] - kvv) <= 1e-9 * size)
        assert np.all(np.abs(sign * k_local[:, v, t] - kvt) * b <= 1e-9 * size)
        assert np.all(np.abs(k_local[:, t, t] - ktt) * b * b <= 1e-9 * size)


def _fe_dynamic(beam, axis, w, n):
    ktt, kti, kii, mtt, mti, mii = internal_matrices(beam, axis, n)
    out = []
    for wj in w:
        a = kii - wj**2 * mii
        b = kti - wj**2 * mti
        out.append(ktt - wj**2 * mtt - b @ np.linalg.solve(a, b.T))
    return np.array(out)


def test_finite_elements_converge_to_the_exact_dynamic_stiffness():
    # the mesh condensed onto the body end at omega (hull end clamped) below the first internal
    # resonance (the first clamped-clamped mode, about 320 Hz here): second order in the element size
    k_ii = internal_matrices(BEAM, AXIS, 32)
    w_first = np.sqrt(sla.eigvalsh(k_ii[2], k_ii[5])[0])
    w = np.linspace(0.05, 0.8, 6) * w_first
    exact = dynamic_stiffness(BEAM, AXIS, w).body
    scale = np.abs(exact).max(axis=(1, 2))
    errors = np.array([np.abs(_fe_dynamic(BEAM, AXIS, w, n) - exact).max(axis=(1, 2)) / scale
                       for n in (4, 8, 16, 32)])
    ratios = errors[:-1] / errors[1:]
    assert np.all((ratios > 3.7) & (ratios < 4.1)), ratios
    assert errors[-1].max() < 1.5e-3 and errors[-1, 0] < 1e-8, errors[-1]
