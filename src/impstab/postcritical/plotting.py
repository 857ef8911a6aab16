"""Drawing of cycle branches: the bifurcation diagram and a phase portrait (matplotlib, lazily)."""

from __future__ import annotations

import numpy as np

__all__ = ["plot_branch", "plot_phase_portrait"]

_MARKERS = {"fold": ("s", "C3", "fold of cycles"), "period-doubling": ("D", "C4", "period doubling"),
            "torus": ("^", "C2", "torus (Neimark-Sacker)")}


def _fmt(value: float, scale: float) -> str:
    """``value`` to 6 digits, rounding noise around zero (below 1e-12 of ``scale``) shown as 0."""
    return "0" if abs(value) <= 1e-12 * abs(scale) else f"{value:.6g}"


def _label(name: str, unit: str) -> str:
    return f"{name} ({unit})" if unit else name


def plot_branch(branch, ax=None, state=None, operating=None):
    """Amplitude of one state against the parameter; stable solid, unstable dashed; returns the axes."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(7.0, 4.5), layout="constrained")
    amp = branch.amplitude
    if state is None:
        scale = np.asarray(branch.settings.get("state_scale", np.ones(amp.shape[1])), dtype=float)
        j = int(np.argmax(np.nanmax(amp / scale[None, :], axis=0))) if amp.size else 0
    else:
        j = branch.state_index(state)
    p = branch.parameter
    pscale = max(float(np.max(np.abs(p))) if p.size else 1.0, float(branch.settings.get("parameter_scale", 1.0)))
    a = amp[:, j] if amp.size else np.array([])
    stable = branch.stable
    hopf = branch.hopf
    if hopf is not None and p.size:
        # the branch leaves the Hopf point with zero amplitude
        p = np.concatenate([[hopf.parameter], p])
        a = np.concatenate([[0.0], a])
        stable = np.concatenate([[stable[0]], stable])
    drawn = {True: False, False: False}
    k = 0
    while k < p.size - 1:
        e = k
        while e + 1 < p.size - 1 and stable[e + 1] == stable[k + 1]:
            e += 1
        s = bool(stable[k + 1])
        ax.plot(p[k: e + 2], a[k: e + 2], color="C0", ls="-" if s else "--", lw=1.6,
                label=None if drawn[s] else ("stable cycles" if s else "unstable cycles"))
        drawn[s] = True
        k = e + 1
    if hopf is not None:
        ax.plot([hopf.parameter], [0.0], "o", color="k", ms=6, zorder=5, clip_on=False,
                label=f"Hopf point ({hopf.bifurcation}), {branch.parameter_name} = {_fmt(hopf.parameter, pscale)}"
                      f"{' ' + branch.parameter_units if branch.parameter_units else ''}")
    seen = set()
    for sp in branch.special_points:
        mk, col, name = _MARKERS[sp.kind]
        ax.plot([sp.parameter], [sp.cycle.amplitude[j]], mk, color=col, ms=7, zorder=6, clip_on=False,
                label=None if sp.kind in seen else f"{name}, {branch.parameter_name} = {_fmt(sp.parameter, pscale)}"
                                                   f"{' ' + branch.parameter_units if branch.parameter_units else ''}")
        seen.add(sp.kind)
    if operating is not None:
        ax.axvline(operating, color="0.35", ls=":", lw=1.0, label=f"operating {operating:.6g}")
    ax.set_xlabel(_label(branch.parameter_name, branch.parameter_units))
    name = branch.state_names[j] if branch.state_names else f"x{j + 1}"
    unit = branch.state_units[j] if branch.state_units else ""
    ax.set_ylabel(_label(f"amplitude of {name} (half peak-to-peak)", unit))
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    ax.set_title("limit cycles: bifurcation diagram")
    ax.legend(loc="best", fontsize="small")
    return ax


def plot_phase_portrait(branch, index=-1, states=(0, 1), ax=None):
    """One cycle in the plane of two states (closed curve, start point marked); returns the axes."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5.5, 5.0), layout="constrained")
    cyc = branch.cycles[index]
    i, j = (branch.state_index(s) for s in states)
    _, x = cyc.sample(801)
    style = "-" if cyc.stable else "--"
    ax.plot(x[:, i], x[:, j], style, color="C0", lw=1.6,
            label=f"{'stable' if cyc.stable else 'unstable'} cycle, period {cyc.period:.6g} {branch.time_units}")
    ax.plot([x[0, i]], [x[0, j]], "o", color="C1", ms=5, label="t = 0")
    if branch.hopf is not None:
        ax.plot([branch.hopf.state[i]], [branch.hopf.state[j]], "+", color="k", ms=9,
                label="equilibrium at the Hopf point")
    names, units = branch.state_names, branch.state_units
    ax.set_xlabel(_label(names[i], units[i]))
    ax.set_ylabel(_label(names[j], units[j]))
    ax.set_title(f"cycle at {branch.parameter_name} = {cyc.parameter:.6g} {branch.parameter_units}".rstrip())
    ax.grid(True, alpha=0.3)
    # below the axes: a closed curve leaves no free corner for a legend inside
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=3, fontsize="small", frameon=False)
    return ax
