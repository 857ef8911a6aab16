"""An undamped model stays undamped for the engine when the search range goes past the thrust
at which its static equilibrium is lost (NaN matrices there must not read as damping)."""

import numpy as np

import impstab
from impstab.linear.engine.problems import second_order_problem
from impstab.linear.linearize import ModelFamily


def test_lost_equilibrium_at_the_sampled_loads_is_not_damping(examples):
    model = impstab.load_model(examples / "imp_asymmetric.toml")
    fam = ModelFamily(model, "equilibrium")  # not affine: damping is sampled along the range
    assert fam.affine_parts() is None
    _, d, _, _ = fam.matrices(np.array([0.0, 5e5, 1e6]))
    assert not np.isfinite(d[1:]).all()  # the mounts cannot hold these thrusts: no equilibrium
    assert second_order_problem(fam, 1e6).undamped
    # the onset is the same as with a range the equilibrium reaches throughout
    near = impstab.critical_thrust(model, thrust_max=2e4)
    far = impstab.critical_thrust(model, thrust_max=1e6)
    assert abs(far.thrust - near.thrust) <= 1e-12 * near.thrust and far.kind == near.kind
