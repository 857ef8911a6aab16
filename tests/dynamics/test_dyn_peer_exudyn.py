"""Peer check against a general multibody code (Exudyn, optional): the same body on the same
springs under the same follower force, integrated by Exudyn's RK4, follows impstab's nonlinear
trajectory. Skipped when ``exudyn`` is not installed."""

import numpy as np
import pytest
from _dyn_models import symmetric
from exudyn_peer import exudyn_system

import impstab
from impstab.kinematics import euler_zyx_to_matrix
from impstab.model import model_from_dict

exu = pytest.importorskip("exudyn")


def exudyn_run(model, thrust, eta0, nu0, t_end, steps):
    _, mbs, settings, node = exudyn_system(model, thrust, eta0, nu0, t_end, steps)
    mbs.SolveDynamic(settings, solverType=exu.DynamicSolverType.RK44)
    pos = np.array(mbs.GetNodeOutput(node, exu.OutputVariableType.Position))
    rot = np.array(mbs.GetNodeOutput(node, exu.OutputVariableType.RotationMatrix)).reshape(3, 3)
    return pos, rot


@pytest.mark.filterwarnings("ignore::DeprecationWarning")
def test_exudyn_follows_the_same_nonlinear_trajectory():
    d = symmetric()
    d["body"]["inertia"] = [[1.2, 0.05, 0.02], [0.05, 6.0, 0.1], [0.02, 0.1, 5.5]]
    d["thrust"] = {"point": [-0.1, 0.01, 0.02], "operating": 2000.0}  # off-axis follower: R0 != I
    model = model_from_dict(d)
    thrust, t_end = 8000.0, 1.0
    pert = {"displacement": {"sway": 0.005, "yaw": 0.05, "roll": 0.08}, "velocity": {"heave": 0.05, "pitch": 0.3}}
    res = impstab.simulate(model, thrust=thrust, duration=t_end, integrator="dop853", rtol=1e-11,
                           perturbation=pert, critical_thrust=False)
    eta0 = res.equilibrium[:6] + res.deviation[0, :6]
    pos, rot = exudyn_run(model, thrust, eta0, res.deviation[0, 6:], t_end, 20000)
    end = res.absolute[-1]
    travel = np.abs(res.displacement[:, :3]).max()
    assert np.abs(pos - end[:3]).max() < 1e-6 * max(travel, 1e-3)
    assert np.abs(rot - euler_zyx_to_matrix(*end[3:])).max() < 1e-6
    assert np.abs(res.displacement[:, 3:]).max() > 0.05  # large rotations: a nonlinear check
