"""Eigenvalue loci: frequency and growth rate against thrust (the paper's Figure 4)."""

from __future__ import annotations

import numpy as np

__all__ = ["plot_locus"]


def plot_locus(result, ax=None):
    """Draw ``result`` (a LocusResult); returns the axes (a pair unless one Axes was given)."""
    import matplotlib.pyplot as plt

    if ax is None:
        fig, axes = plt.subplots(2, 1, sharex=True, figsize=(7.0, 6.0), layout="constrained")
        ax_f, ax_g = axes
    elif isinstance(ax, (list, tuple, np.ndarray)):
        ax_f, ax_g = ax
    else:
        ax_f, ax_g = ax, None
    t = result.thrust
    upper = result.omega >= 0
    freq = np.where(upper, result.frequency_hz, np.nan)
    colors = plt.rcParams["axes.prop_cycle"].by_key().get("color", ["C0"])
    for j in range(result.eigenvalues.shape[1]):
        if np.all(np.isnan(freq[:, j])):
            continue
        ax_f.plot(t, freq[:, j], color=colors[j % len(colors)], lw=1.4)
    ax_f.set_ylabel("frequency (Hz)")
    ax_f.set_title(f"eigenvalue loci: {result.model_name}" if result.model_name else "eigenvalue loci")
    targets = [ax_f] if ax_g is None else [ax_f, ax_g]
    if ax_g is not None:
        for j in range(result.eigenvalues.shape[1]):
            ax_g.plot(t, result.growth_rate[:, j], color=colors[j % len(colors)], lw=1.2)
        ax_g.axhline(0.0, color="0.5", lw=0.8)
        ax_g.set_ylabel("growth rate Re(λ) (1/s)")
        ax_g.set_xlabel("thrust (N)")
    else:
        ax_f.set_xlabel("thrust (N)")
    for a in targets:
        if result.critical_thrust is not None:
            a.axvline(result.critical_thrust, color="C3", ls="--", lw=1.0, label=f"critical {result.critical_thrust:.6g} N")
        if result.operating_thrust is not None:
            a.axvline(result.operating_thrust, color="0.3", ls=":", lw=1.0, label=f"operating {result.operating_thrust:.6g} N")
        a.grid(True, alpha=0.3)
    if result.critical_thrust is not None or result.operating_thrust is not None:
        ax_f.legend(loc="best", fontsize="small")
    return (ax_f, ax_g) if ax_g is not None else ax_f
