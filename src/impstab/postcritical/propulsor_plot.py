"""Drawing of a propulsor's post-critical result: the bifurcation diagram (matplotlib, lazily)."""

from __future__ import annotations

import numpy as np

from .propulsor_result import DOF_UNITS, DOFS

__all__ = ["plot_postcritical"]


def plot_postcritical(result, ax=None, dof=None):
    """Amplitude of one coordinate against thrust, stable cycles solid, unstable dashed, the
    Hopf point, folds and the operating thrust marked; returns the axes."""
    import matplotlib.pyplot as plt

    from ..errors import ModelError

    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 4.8), layout="constrained")
    if dof is not None and dof not in DOFS:
        raise ModelError("dof", dof, f"must be one of {', '.join(DOFS)}")
    branch = result.cycles
    if branch is not None and len(branch):
        if dof is None:
            scale = np.asarray(result.settings.get("state_scale", np.ones(12)), dtype=float)[:6]
            dof = DOFS[int(np.argmax(np.nanmax(branch.amplitude[:, :6] / scale[None, :], axis=0)))]
        branch.plot(ax=ax, state=dof)
    else:
        dof = dof or "pitch"
        tc = result.critical_thrust
        if tc is not None:
            ax.plot([tc], [0.0], "o", color="k", ms=6, clip_on=False,
                    label=f"onset ({result.bifurcation or result.kind}), thrust = {tc:.6g}")
            ax.set_xlim(0.0, max(result.thrust_max, tc) * 1.02)
        ax.text(0.5, 0.55, "no branch of limit cycles computed:\n" + _wrap(result.reason or result.stop_reason),
                transform=ax.transAxes, ha="center", va="center", fontsize="small", color="0.25")
        ax.set_xlabel("thrust (N)")
        ax.set_ylabel(f"amplitude of {dof} (half peak-to-peak) ({DOF_UNITS[DOFS.index(dof)]})")
        ax.set_ylim(0.0, 1.0)
        ax.grid(True, alpha=0.3)
    op = result.operating_thrust
    if op is not None:
        lo, hi = ax.get_xlim()
        if lo <= op <= hi:
            ax.axvline(op, color="0.35", ls=":", lw=1.0, label=f"operating thrust {op:.6g} N")
        else:
            side = "left" if op < lo else "right"
            ax.plot([], [], " ", label=f"operating thrust {op:.6g} N (off the diagram, {side})")
    ax.set_title(f"{result.model_name}: {result.bifurcation or result.kind} onset", fontsize="medium")
    ax.legend(loc="best", fontsize="small")
    return ax


def _wrap(text: str, width: int = 60) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(str(text), width)[:6])
