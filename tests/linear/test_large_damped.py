"""Large damped second-order problems: modal reduction, then Newton's method on the full model.

A damped problem above the engine's dense size (``M q'' + (D + G) q' + (K0 + p K1) q = 0`` with
more than 48 dofs) is solved on the undamped modes of ``(K0, M)`` with m and 2 m modes, and its
onset is then found on the full model by Newton's method on ``T(p, omega) x = 0``
(:func:`impstab.linear.engine.large.damped_full_onset`). Independent answers:

* Euler's clamped-free column under a dead (non-follower) end load, with Kelvin-Voigt damping: a
  dead load is conservative, damping does not move its static loss of stability, which is the
  closed form ``p = pi^2 / 4`` (``P L^2 / EI``); 50 Hermite elements (200 states) reach it to
  1.4e-9 (the mesh's h^4 error), where the dense scan of the same matrices lands at 1.3e-8; the
  participation is that of the closed-form buckling mode;
* Beck's column with Kelvin-Voigt damping ``eta = 1e-3``: ``T(p, omega)`` singular to rounding
  at the onset; the same 50-element matrices solved by the dense scan of all 200 states (1.8e-9
  and 1.1e-8 apart in two runs: the dense scan's own accuracy on a spectrum that reaches 1e7),
  and a 16-element mesh on the dense small route (a different discretization: 6e-8 apart, its
  h^4 error);
* the damped variant of examples/imp_beam_mounts.toml (348 states): LAPACK's eigenvalues of the
  full first-order operator, stable on a grid below the onset and crossing at it (the crossing
  interpolated from 1e-6 on either side: 3.6e-12 apart; the engine's dense scan: 6e-12);
* where the reduction's own check fails, the problem is solved dense and says so.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import impstab
from impstab.linear import critical_load
from impstab.linear.eigen import kinetic_shares, state_matrices
from impstab.linear.engine import large
from impstab.model import model_from_dict

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_beck_column import beck_matrices  # noqa: E402

ETA = 1e-3  # Kelvin-Voigt: D = eta K0 (the bending stiffness, not the load's geometric part)


def _dense(monkeypatch, func, *args, **kw):
    """``func`` with the dense route forced (no problem counts as large)."""
    with monkeypatch.context() as m:
        m.setattr(large, "LARGE_ORDER", 10**9)
        return func(*args, **kw)


def test_a_dead_load_on_a_damped_column_diverges_at_the_euler_load():
    M, K0, K1 = beck_matrices(50, follower=False)
    assert 2 * M.shape[0] > large.LARGE_ORDER
    res = critical_load(M, K0, K1, D=ETA * K0, p_max=5.0)
    assert res.kind == "divergence" and res.warnings == ()
    assert abs(res.load / (np.pi**2 / 4) - 1) < 1e-8  # measured 1.4e-9
    # the participation is that of Euler's buckling mode w = 1 - cos(pi x / 2), w' = pi/2 sin(pi x / 2)
    # at the nodes (deflection, rotation), weighted by the mass diagonal
    x = np.linspace(0.0, 1.0, 51)[1:]
    shape = np.empty(2 * len(x))
    shape[0::2], shape[1::2] = 1 - np.cos(np.pi * x / 2), np.pi / 2 * np.sin(np.pi * x / 2)
    shares = shape**2 * np.diag(M) / (shape**2 * np.diag(M)).sum()
    assert np.abs(res.participation - shares).max() < 1e-6 * shares.max()


def test_damped_beck_column_reduced_equals_dense_and_the_coarser_mesh(monkeypatch):
    M, K0, K1 = beck_matrices(50)
    res = critical_load(M, K0, K1, D=ETA * K0, p_max=22.0)
    assert res.kind == "flutter" and res.warnings == () and res.method == "hopf"
    # the onset satisfies the Hopf condition of the full model to rounding: T(p, omega) is singular
    t = K0 + res.load * K1 - res.omega**2 * M + 1j * res.omega * ETA * K0
    sv = np.linalg.svd(t, compute_uv=False)
    assert sv[-1] < 1e-16 * sv[0] and sv[-2] > 1e8 * sv[-1]  # measured 4e-19; one null vector, 1e11 clear
    # the dense scan of the 200 states agrees to its own accuracy on this stiff spectrum (the
    # Kelvin-Voigt damping puts the element modes at |lambda| ~ 1e7): measured 1.8e-9 and 1.1e-8
    # apart in two runs, by whether its eigenvalues came from LAPACK or the compiled routines
    dense = _dense(monkeypatch, critical_load, M, K0, K1, D=ETA * K0, p_max=22.0)
    assert dense.kind == "flutter"
    assert abs(res.load / dense.load - 1) < 3e-8 and abs(res.omega / dense.omega - 1) < 3e-8
    # the participation: kinetic shares of the displacement part of LAPACK's eigenvector of the
    # full first-order operator at the onset (measured 2e-10 apart)
    vals, vecs = np.linalg.eig(state_matrices(M, ETA * K0, K0 + res.load * K1))
    q = vecs[: M.shape[0], np.argmin(np.abs(vals - 1j * res.omega))]
    np.testing.assert_allclose(res.participation, kinetic_shares(q[:, None], M), atol=1e-8)
    m16, k16, k116 = beck_matrices(16)
    coarse = critical_load(m16, k16, k116, D=ETA * k16, p_max=22.0)  # 64 states: the dense route
    assert abs(res.load / coarse.load - 1) < 2e-7  # measured 6e-8: the 16-element mesh's h^4 error
    assert res.load < 0.55 * 20.05  # the destabilisation paradox: far below the undamped 20.05


def test_when_the_reduction_fails_its_check_the_problem_is_solved_dense(monkeypatch):
    M, K0, K1 = beck_matrices(50)
    dense = _dense(monkeypatch, critical_load, M, K0, K1, D=ETA * K0, p_max=22.0)
    monkeypatch.setattr(large, "TRUNCATION_TOLERANCE", 0.0)  # no two bases ever agree
    res = critical_load(M, K0, K1, D=ETA * K0, p_max=22.0)
    assert res.load == dense.load and res.omega == dense.omega
    assert len(res.warnings) == 1 and "modal reduction not used" in res.warnings[0] and "disagree" in res.warnings[0]


def test_damped_massive_beam_mounts_onset_is_the_first_crossing_of_the_full_operator():
    """The damped beam example (348 states): LAPACK's eigenvalues of the full first-order operator
    are stable on a grid up to just below the onset and one pair crosses there, at the onset's
    frequency; the crossing interpolated from the two sides is the onset."""
    import tomllib

    from impstab.linear.linearize import ModelFamily

    d = tomllib.loads((Path(__file__).resolve().parents[2] / "examples" / "imp_beam_mounts.toml").read_text())
    for mount in d["mounts"]:
        mount["c_axial"], mount["c_shear"] = 40.0, 8.0
    model = model_from_dict(d)
    res = impstab.critical_thrust(model, linearization="equilibrium")
    assert res.kind == "flutter" and res.warnings == ()
    fam = ModelFamily(model, "equilibrium")
    assert 2 * fam.n > large.LARGE_ORDER
    delta = 1e-6
    thrusts = res.thrust * np.array([0.25, 0.5, 0.75, 1 - delta, 1 + delta])
    m, d_, g, k = fam.matrices(thrusts)[:4]
    crossing = []
    for j in range(len(thrusts)):
        a = state_matrices(m[j], d_[j] + g[j], k[j])
        vals = np.linalg.eigvals(a)
        pair = np.argsort(np.abs(np.abs(vals) - res.omega) + np.abs(np.abs(vals.imag) - res.omega))[:2]
        rest = np.delete(vals, pair)
        # every other eigenvalue stable to LAPACK's absolute accuracy eps ||A|| (largest: 2e-11)
        assert rest.real.max() < 100 * np.finfo(float).eps * np.linalg.norm(a, 1), thrusts[j]
        assert abs(vals[pair[0]] - vals[pair[1]].conjugate()) < 1e-9 * res.omega
        crossing.append(vals[pair][np.argmax(vals[pair].imag)])
    # the pair nearest the onset frequency: stable on the grid and just below, unstable just above
    assert all(c.real < 0 for c in crossing[:-1]) and crossing[-1].real > 0
    below, above = crossing[-2:]
    assert abs(below.imag / res.omega - 1) < 1e-6 and abs(above.imag / res.omega - 1) < 1e-6
    onset = thrusts[-2] - below.real * (thrusts[-1] - thrusts[-2]) / (above.real - below.real)
    # measured 3.6e-12 (the dense scan of the engine: 6e-12, in 20 times the time)
    assert abs(onset / res.thrust - 1) < 1e-10
