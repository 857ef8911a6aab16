"""The engine on a stack of problems: each problem as if alone, failures kept to their problem.

Independent answers: Ziegler's closed form 7/2 - sqrt 2 and 41/28 + b^2/2 (THEORY 10), and a
2 x 2 system whose coalescence lies (by construction) just below the start of the range.
"""

from __future__ import annotations

import numpy as np
import pytest

from impstab.linear.engine import first_order_problem, second_order_problem, solve
from impstab.linear.families import CallableFamily, LinearFamily, LinearFirstOrderFamily

M_Z = np.array([[3.0, 1.0], [1.0, 1.0]])
K0_Z = np.array([[2.0, -1.0], [-1.0, 1.0]])
K1_Z = -np.array([[1.0, -1.0], [0.0, 0.0]])
P_FLUTTER = 3.5 - np.sqrt(2.0)


def _ziegler_first_order(b: float = 0.0) -> LinearFirstOrderFamily:
    n = 2
    a0 = np.block([[np.zeros((n, n)), np.eye(n)], [-K0_Z, -b * K0_Z]])
    a1 = np.zeros((4, 4))
    a1[n:, :n] = -K1_Z
    e = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), M_Z]])
    return LinearFirstOrderFamily.build(a0, a1, e, n_dof=2, weights=np.diag(M_Z))


def _problems():
    return [
        second_order_problem(LinearFamily.build(M_Z, K0_Z, K1_Z), 5.0),
        second_order_problem(LinearFamily.build(M_Z, K0_Z, K1_Z, D=0.1 * K0_Z), 4.0),
        second_order_problem(CallableFamily(lambda p: (M_Z, None, None, K0_Z + p * K1_Z), 2), 5.0),
        first_order_problem(_ziegler_first_order(0.1), 4.0),
        second_order_problem(LinearFamily.build(2 * M_Z, K0_Z, K1_Z), 5.0),
    ]


def test_a_stack_equals_each_problem_alone():
    together = solve(_problems())
    alone = [solve([p])[0] for p in _problems()]
    for t, a in zip(together, alone):
        assert t.load == a.load and t.omega == a.omega and t.kind == a.kind
        np.testing.assert_array_equal(t.participation, a.participation)
        np.testing.assert_array_equal(t.mode, a.mode)
    assert together[0].load == pytest.approx(P_FLUTTER, rel=1e-14)
    assert together[2].load == pytest.approx(P_FLUTTER, rel=1e-12)
    assert together[4].load == pytest.approx(P_FLUTTER, rel=1e-14)  # the mass does not move the load
    for k in (1, 3):
        assert together[k].load == pytest.approx(41 / 28 + 0.1**2 / 2, rel=1e-12)


def test_a_failing_problem_stops_only_itself():
    def family(p):
        if 1.5 < p < 2.4:
            raise RuntimeError("no linearization between 1.5 and 2.4")
        return M_Z, None, None, K0_Z + p * K1_Z

    problems = _problems()
    problems.insert(1, second_order_problem(CallableFamily(family, 2), 5.0))
    out = solve(problems)
    assert isinstance(out[1].error, RuntimeError) and "between" in str(out[1].error)
    assert out[0].error is None and out[0].load == pytest.approx(P_FLUTTER, rel=1e-14)
    assert out[5].load == pytest.approx(P_FLUTTER, rel=1e-14)


def test_a_bracket_that_cannot_step_back_further_is_reported_with_a_warning():
    """``K = [[2, 1], [-(p - p_c), 2]]``, M = I: ``s = 2 +- sqrt(-(p - p_c))`` coalesces at
    ``p_c = -1e-15``, just below the range. At p = 0 the pair is complex by 3e-8, under the
    classification tolerance (stable), at the next grid point clearly complex: the exact
    indicator shows the stable end already past the onset, and it cannot step back below 0.
    The engine then says so, the other problems of the same stack are exact."""
    p_c = -1e-15
    k0 = np.array([[2.0, 1.0], [p_c, 2.0]])
    k1 = np.array([[0.0, 0.0], [-1.0, 0.0]])
    odd = second_order_problem(LinearFamily.build(np.eye(2), k0, k1), 1.0)
    out = solve([odd] + _problems())
    assert out[0].load == pytest.approx(1.0 / 64) and out[0].kind == "flutter"
    assert len(out[0].warnings) == 1 and "bisection" in out[0].warnings[0]
    assert out[1].load == pytest.approx(P_FLUTTER, rel=1e-14) and not out[1].warnings
