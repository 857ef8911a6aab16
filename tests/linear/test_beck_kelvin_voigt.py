"""Beck's column with Kelvin-Voigt internal damping: the destabilisation paradox.

A cantilever under a tangential follower end load (the Hermite finite-element column of
tests/linear/test_beck_column.py, L = EI = m = 1, ``p = P L^2 / EI``) flutters at p = 20.05
undamped (Beck 1952). With Kelvin-Voigt internal damping ``D = eta K_e`` (the bending stiffness
only, not the load's geometric part) the critical load does not return to 20.05 as eta -> 0: it
drops to about 10.94, the destabilisation paradox (Bolotin & Zhinzher 1969; Kirillov & Seyranian,
"The effect of small internal and external damping on the stability of distributed
non-conservative systems", J. Appl. Math. Mech. 69 (2005) 529-552; the paradox for the Pflueger
and Beck columns is also stated in Tommasini, Kirillov, Misseroni & Bigoni, J. Mech. Phys. Solids
91 (2016) 204-215). The published limit is quoted to the three or four figures 10.94.

Independent reference here: the vanishing-damping limit is the smallest load at which the first
order damping sensitivity of the lowest undamped mode changes sign. For ``(lambda^2 M + lambda eta
K_e + K(p)) u = 0`` at ``eta = 0`` with ``lambda = i omega`` and the real right and left
eigenvectors ``u``, ``v`` of ``K(p) u = omega^2 M u``, ``d lambda / d eta = -(v^T K_e u) /
(2 v^T M u)``: the root of ``v^T K_e u`` in p, by brentq on the undamped eigenvectors (no damped
eigenproblem, no stability engine). The engine's damped critical loads must converge to it as
eta -> 0 (quadratically in eta), and the mesh must have converged: 16 and 32 elements agree to 1e-7
relative (cubic Hermite elements, h^4), so the converged value is 10.93885 to the six figures the
mesh allows.
"""

from __future__ import annotations

import functools
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.optimize import brentq

from impstab.linear import critical_load

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_beck_column import beck_matrices  # noqa: E402

PUBLISHED_LIMIT = 10.94      # vanishing Kelvin-Voigt damping (Bolotin & Zhinzher; Kirillov & Seyranian)
PUBLISHED_UNDAMPED = 20.05   # Beck


@functools.lru_cache(maxsize=None)
def vanishing_damping_limit(n_el: int) -> float:
    """Root in p of ``v^T K_e u`` for the lowest undamped mode (see the module notes)."""
    M, K0, K1 = beck_matrices(n_el)

    def sensitivity(p):
        s, vl, vr = sla.eig(K0 + p * K1, M, left=True, right=True)
        j = int(np.argmin(s.real))
        u, v = vr[:, j].real, vl[:, j].real
        return float(v @ K0 @ u / (v @ M @ u))

    assert sensitivity(0.0) > 0 and sensitivity(14.0) < 0
    return brentq(sensitivity, 0.0, 14.0, xtol=1e-14, rtol=8.9e-16)


def test_undamped_beck_column():
    M, K0, K1 = beck_matrices(16)
    res = critical_load(M, K0, K1, p_max=22.0)
    assert res.kind == "flutter" and round(res.load, 2) == PUBLISHED_UNDAMPED


def test_vanishing_kelvin_voigt_damping_drops_the_critical_load_to_the_paradox_limit():
    M, K0, K1 = beck_matrices(16)
    limit = vanishing_damping_limit(16)
    loads = []
    for eta in (1e-2, 1e-3, 1e-4, 1e-5):
        res = critical_load(M, K0, K1, D=eta * K0, p_max=22.0)
        assert res.kind == "flutter"
        loads.append(res.load)
    excess = np.array(loads) - limit
    # from above, quadratically in eta (each tenfold smaller eta: a hundredfold smaller excess), to the
    # limit (at eta = 1e-5 the excess, about 3e-8, is at the engine's own accuracy)
    assert np.all(excess > 0), excess
    assert np.all(np.abs(excess[:2] / excess[1:3] / 100 - 1) < 0.01), excess
    assert excess[-1] < 1e-8 * limit
    assert loads[-1] < 0.55 * PUBLISHED_UNDAMPED  # far below the undamped 20.05


def test_the_limit_has_converged_with_the_mesh_and_is_the_published_value():
    p16, p32 = vanishing_damping_limit(16), vanishing_damping_limit(32)
    assert abs(p16 / p32 - 1) < 1e-7
    assert round(p32, 2) == PUBLISHED_LIMIT
    assert p32 == pytest.approx(10.93885, abs=1e-5)


@pytest.mark.parametrize("n_el,eta", [(4, 1e-2), (8, 1e-3)])
def test_a_damped_onset_reports_the_participation_of_its_crossing_mode(n_el, eta):
    """A Hopf onset's eigenvalue is simple: its participation is the kinetic-energy share of the
    displacement part of the crossing eigenvector at the onset itself (here from LAPACK's
    eigenvectors of the state matrix), not of the modes somewhat below it (measured 4e-14, 6e-13;
    taken at the scan's stable bracket end, they differed by 1e-3)."""
    from impstab.linear.eigen import kinetic_shares, state_matrices

    M, K0, K1 = beck_matrices(n_el)
    res = critical_load(M, K0, K1, D=eta * K0, p_max=22.0)
    assert res.kind == "flutter"
    vals, vecs = np.linalg.eig(state_matrices(M, eta * K0, K0 + res.load * K1))
    j = int(np.argmin(np.abs(vals - 1j * res.omega)))
    assert abs(vals[j].real) < 1e-9 * res.omega
    q = vecs[: M.shape[0], j]
    np.testing.assert_allclose(res.participation, kinetic_shares(q[:, None], M), atol=1e-9)
