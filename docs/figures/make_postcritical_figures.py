"""The figures of docs/postcritical.md: benign and dangerous designs side by side, and the
hysteresis loop of the dangerous one under a slow thrust ramp up and down.

Run from the repository root: ``python docs/figures/make_postcritical_figures.py``.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import impstab  # noqa: E402
from impstab.postcritical import propulsor_postcritical  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent


def ramp(t_lo: float, t_hi: float, up: float, hold: float, down: float):
    """A trapezoidal thrust history: ``t_lo`` up to ``t_hi`` in ``up`` s, held ``hold`` s, back in ``down`` s."""
    return lambda t: np.interp(t, [0.0, up, up + hold, up + hold + down], [t_lo, t_hi, t_hi, t_lo])


def main() -> None:
    benign = impstab.load_model(ROOT / "examples" / "imp_hardening.toml")
    danger = impstab.load_model(ROOT / "examples" / "imp_softening.toml")
    rb = propulsor_postcritical(benign, thrust_max=13000.0)
    rd = propulsor_postcritical(danger)
    fig, axes = plt.subplots(1, 2, figsize=(12.5, 4.8), layout="constrained")
    rb.plot(ax=axes[0], dof="pitch")
    rd.plot(ax=axes[1], dof="pitch")
    fig.savefig(HERE / "postcritical-benign-dangerous.png", dpi=110)
    plt.close(fig)

    # hysteresis: a slow ramp from below the fold to above the onset, a hold there, and back
    lo, hi, up, hold, down = 12130.0, 12950.0, 800.0, 1200.0, 1500.0
    history = ramp(lo, hi, up, hold, down)
    sim = impstab.simulate(danger, thrust=history, duration=up + hold + down, sample=0.02,
                           perturbation={"velocity": {"pitch": 1e-4}})
    y = sim.deviation + sim.equilibrium
    t = sim.time
    per = 2 * np.pi / rd.omega
    n = max(1, int(round(per / (t[1] - t[0]))))
    k = (t.size // n) * n
    pitch = y[:k, 4].reshape(-1, n)
    env = 0.5 * (pitch.max(axis=1) - pitch.min(axis=1))      # half peak-to-peak per onset period
    tt = t[:k].reshape(-1, n).mean(axis=1)
    thrust = history(tt)
    rising = tt <= up + hold
    fig, ax = plt.subplots(figsize=(9.5, 4.8), layout="constrained")
    rd.plot(ax=ax, dof="pitch")
    ax.plot(thrust[rising], env[rising], color="C1", lw=1.0, label=f"simulated: up in {up:.0f} s, held {hold:.0f} s")
    ax.plot(thrust[~rising], env[~rising], color="C2", lw=1.0, label=f"simulated: down in {down:.0f} s")
    ax.set_xlim(lo - 20.0, hi + 20.0)
    ax.set_title(f"{danger.name}: hysteresis under a slow thrust ramp", fontsize="medium")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    fig.savefig(HERE / "postcritical-hysteresis.png", dpi=110)
    plt.close(fig)
    big = 0.5 * env.max()
    jump_up = thrust[rising][np.argmax(env[rising] > big)]
    t_up = tt[rising][np.argmax(env[rising] > big)]
    jump_down = thrust[~rising][np.argmax(env[~rising] < big)]
    print(f"benign: {rb.reading}\ndangerous: {rd.reading}")
    print(f"ramp: onto the large cycle at {jump_up:.0f} N (t = {t_up:.0f} s), back to the equilibrium at "
          f"{jump_down:.0f} N; largest pitch amplitude {env.max():.4f} rad")


if __name__ == "__main__":
    main()
