"""The cycle a long time integration settles on: the independent answer of the post-critical tests."""

from __future__ import annotations

import impstab


def settled_amplitude(model, thrust, tc, duration, dt):
    """Amplitudes (half peak-to-peak) of the six coordinates after ``duration`` s of a Hamming run
    from a small pitch displacement, over 0.5 s sampled at 1e-4 s from the state reached."""
    settle = impstab.simulate(model, thrust=thrust, duration=duration, dt=dt, integrator="hamming",
                              critical_thrust=tc, sample=0.5, perturbation={"displacement": {"pitch": 0.001}})
    z = settle.deviation[-1]
    run = impstab.simulate(model, thrust=thrust, duration=0.5, dt=dt, integrator="hamming", critical_thrust=tc,
                           sample=1e-4, perturbation={"displacement": z[:6], "velocity": z[6:]})
    y = run.deviation + run.equilibrium
    return 0.5 * (y[:, :6].max(axis=0) - y[:, :6].min(axis=0))
