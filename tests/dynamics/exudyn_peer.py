"""The propulsor as an Exudyn multibody system (optional peer code), for the peer test and the
simulation benchmark: a rigid body on axis-aligned Cartesian springs under a body-fixed
(follower) force, integrated by Exudyn's explicit RK4 (``RK44``)."""

from __future__ import annotations

import numpy as np

from impstab.kinematics import euler_zyx_to_matrix


def exudyn_system(model, thrust, eta0, nu0, t_end, steps):
    """``(container, mbs, settings, node)`` of ``model`` at thrust ``thrust`` (N) from the pose ``eta0``
    (position, z-y-x Euler angles) and body-frame velocities ``nu0``; the container owns the
    system (keep it). Raises ImportError without exudyn."""
    import exudyn as exu
    from exudyn.utilities import RigidBodyInertia

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    ground = mbs.CreateGround()
    rot0 = euler_zyx_to_matrix(*eta0[3:])
    body = mbs.CreateRigidBody(
        inertia=RigidBodyInertia(mass=model.body.mass, inertiaTensor=np.array(model.body.inertia_cg)),
        referencePosition=list(eta0[:3]), referenceRotationMatrix=rot0, initialVelocity=list(rot0 @ nu0[:3]),
        initialAngularVelocity=list(rot0 @ nu0[3:]), nodeType=exu.NodeType.RotationRxyz)
    for mt in model.mounts:
        k = mt.stiffness
        if np.count_nonzero(k - np.diag(np.diag(k))):
            raise ValueError("the Exudyn peer model takes axis-aligned springs only")
        mbs.CreateCartesianSpringDamper(itemNumbers=[ground, body], localPosition0=list(mt.position),
                                        localPosition1=list(mt.position), stiffness=list(np.diag(k)[:3]),
                                        damping=[0.0, 0.0, 0.0])
    mbs.CreateForce(itemNumber=body, localPosition=list(model.thrust.point),
                    loadVector=list(thrust * model.thrust.direction), bodyFixed=True)
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps = steps
    settings.timeIntegration.endTime = t_end
    settings.timeIntegration.verboseMode = 0
    settings.solutionSettings.writeSolutionToFile = False
    return sc, mbs, settings, mbs.GetObject(body)["nodeNumber"]
