"""A divergence interval narrower than the scan spacing is found (closed-form answer)."""

import numpy as np
import pytest

from impstab import critical_load

P0, W = 0.3712, 0.004   # a dip of the smallest stiffness eigenvalue below zero around P0


def system(p: float):
    s1 = 1.0 - 2.0 * np.exp(-(((p - P0) / W) ** 2))
    return np.eye(2), None, None, np.diag([s1, 4.0])


def test_narrow_divergence_interval():
    res = critical_load(system, p_max=1.0, all_crossings=True)   # grid spacing 1/64 > width
    lo = P0 - W * np.sqrt(np.log(2.0))
    hi = P0 + W * np.sqrt(np.log(2.0))
    assert res.kind == "divergence"
    assert res.load == pytest.approx(lo, rel=1e-12)
    assert [c.direction for c in res.crossings] == ["loss", "gain"]
    assert res.crossings[1].load == pytest.approx(hi, rel=1e-12)
