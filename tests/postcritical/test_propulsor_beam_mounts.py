"""Post-critical analysis with massive beam mounts: the beams' kept modes in the state.

The model: examples/imp_beam_mounts.toml with dampers on its mounts, pitch and yaw inertia apart,
and four beams of different lengths (no two beams share a resonance, so every kept mode moves the
damped body and the equilibrium is hyperbolic apart from the flutter pair).

* the Hopf point, refined by Newton on the nonlinear system from a thrust 2 % off, is the
  crossing of the grown linear family with the same kept modes (an independent bisection on its
  eigenvalues), at its frequency; its first Lyapunov coefficient does not depend on the circle of
  the derivatives;
* a short branch of cycles carries the extended state (multipliers of every state).
"""

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import impstab
from impstab.dynamics.beam_mounts import SIM_CUTOFF
from impstab.linear.eigen import state_matrices
from impstab.linear.linearize import ModelFamily
from impstab.model import model_from_dict
from impstab.postcritical import hopf_analysis, propulsor_postcritical
from impstab.postcritical.propulsor import propulsor_system

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def model():
    import tomllib

    d = tomllib.loads((EXAMPLES / "imp_beam_mounts.toml").read_text())
    for j, mount in enumerate(d["mounts"]):
        mount["c_axial"], mount["c_shear"] = 40.0, 8.0
        mount["beam"]["length"] = 0.05 * (1.0 + 0.1 * j)
        mount["position"][0] = 0.3 + 0.01 * j
    d["body"]["inertia"] = [3.0, 5.0, 8.0]  # pitch and yaw apart: a simple Hopf point, not the symmetric double one
    return model_from_dict(d)


def _family_crossing(model, near: float) -> tuple[float, float]:
    """``(thrust, omega)`` where the least-stable body root of the grown family (kept modes of the
    time histories) crosses the imaginary axis near ``near`` (N)."""
    fam = ModelFamily(model, "equilibrium", cutoff=SIM_CUTOFF)

    def root(t):
        m, d, g, k = (a[0] for a in fam.matrices(np.array([t])))
        vals = np.linalg.eigvals(state_matrices(m, d + g, k))
        vals = vals[(vals.imag > 1e-6) & (vals.imag < 200.0)]       # the body's modes (beams above 2000 rad/s)
        return vals[np.argmax(vals.real)]

    t = brentq(lambda t: root(t).real, 0.95 * near, 1.05 * near, xtol=1e-10 * near, rtol=1e-14)
    return t, float(root(t).imag)


def test_hopf_onset_equals_the_crossing_of_the_grown_family(model):
    crit = impstab.critical_thrust(model)
    assert crit.kind == "flutter"
    thrust, omega = _family_crossing(model, crit.thrust)
    system, ns = propulsor_system(model, crit.omega)
    assert ns.n_states == 12 + 2 * ns.system.n_modes and ns.system.n_modes > 0
    assert system.state_names[12] == "eta0" and system.state_names[-1] == f"eta{ns.system.n_modes - 1}_rate"
    start = 1.02 * crit.thrust
    x0 = ns.equilibrium(start)
    assert np.all(x0[12:] == 0.0)
    hopf = hopf_analysis(system, x0, start, omega=crit.omega)
    assert hopf.refined and hopf.iterations > 0
    assert hopf.parameter == pytest.approx(thrust, rel=1e-8)
    assert hopf.omega == pytest.approx(omega, rel=1e-8)
    assert hopf.bifurcation in ("supercritical", "subcritical")
    l1 = [hopf_analysis(system, x0, start, omega=crit.omega, radius=r, check=False).lyapunov_coefficient
          for r in (3.0, 30.0)]
    assert abs(l1[1] - l1[0]) < 1e-6 * abs(hopf.lyapunov_coefficient)
    assert abs(l1[0] - hopf.lyapunov_coefficient) < 1e-6 * abs(hopf.lyapunov_coefficient)


def test_branch_carries_the_modal_states(model):
    res = propulsor_postcritical(model, max_points=3)
    n = 12 + 2 * propulsor_system(model)[1].system.n_modes
    assert res.branch_multipliers.shape[1] == n
    assert res.to_xarray().sizes["multiplier"] == n
    # the trivial Floquet multiplier: the accuracy check of the extended collocation
    assert np.nanmax(res.trivial_multiplier_error) < 1e-6
