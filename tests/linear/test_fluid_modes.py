"""Modes with compressible fluid loading: each eigenvalue once, with its multiplicity.

Independent answer: at each listed mode's own frequency, the quadratic pencil
``lambda^2 M + lambda (D + G) + K`` (the fluid coefficients taken there) solved as a generalized
eigenproblem by scipy (not by impstab's modal routine): the listed value is one of its
eigenvalues, it is listed as often as the pencil repeats it, and the listed shapes of a repeated
value are independent null vectors of the pencil.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

import impstab
from impstab.linear.linearize import ModelFamily


def _pencil(model, thrust, f):
    fam = ModelFamily(model, None, fluid_frequency=f)
    m, d, g, k, _, _ = fam.evaluate(np.array([thrust]))
    return m[0], d[0] + g[0], k[0]


@pytest.mark.parametrize("thrust", [0.0, 5000.0])
def test_fluid_modes_listed_once_with_multiplicity(thrust):
    model = impstab.load_model("examples/imp_fluid.toml")
    res = impstab.modes(model, thrust=thrust)
    lam = res.eigenvalues
    assert len(lam) == 6
    groups: list[list[int]] = []
    for j in range(len(lam)):
        for grp in groups:
            if abs(lam[grp[0]] - lam[j]) <= 1e-9 * abs(lam[j]):
                grp.append(j)
                break
        else:
            groups.append([j])
    assert any(len(g) == 2 for g in groups)  # the symmetric layout repeats its plane modes
    for grp in groups:
        value = lam[grp[0]]
        m, c, k = _pencil(model, thrust, abs(value.imag) / (2 * np.pi))
        n = m.shape[0]
        a = np.block([[np.zeros((n, n)), np.eye(n)], [-k, -c]])
        b = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), m]])
        ev = scipy.linalg.eigvals(a, b)
        near = np.abs(ev - value) <= 1e-7 * abs(value)
        assert near.any()
        assert len(grp) == int(near.sum())
        x = res.shapes[:, grp]
        sv = np.linalg.svd(x, compute_uv=False)
        assert sv[-1] > 1e-6 * sv[0]  # independent shapes
        resid = (value**2 * m + value * c + k) @ x
        assert np.abs(resid).max() <= 1e-8 * np.abs(k).max() * np.abs(x).max()
