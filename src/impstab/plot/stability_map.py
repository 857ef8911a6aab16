"""Stability map of a design study: critical thrust (or margin) over two design parameters."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ModelError

__all__ = ["plot_stability_map", "select_plane"]

_UNITS = {
    "x": "m", "radius": "m", "position": "m", "point": "m", "cg": "m", "length": "m", "center": "m",
    "k_axial": "N/m", "k_shear": "N/m", "c_axial": "N s/m", "c_shear": "N s/m", "mass": "kg",
    "inertia": "kg m^2", "start_angle": "deg", "operating": "N", "thrust_max": "N", "speed": "rad/s",
    "polar_inertia": "kg m^2", "density": "kg/m^3", "sound_speed": "m/s",
}
_LABELS = {"critical_thrust": "critical thrust (N)", "margin": "margin (critical / operating thrust)",
           "undamped_critical_thrust": "undamped critical thrust (N)", "frequency_hz": "frequency at onset (Hz)"}


def _label(path: str) -> str:
    key = path.split(".")[-1].split("[")[0]
    return f"{path} ({_UNITS[key]})" if key in _UNITS else path


def _log_spaced(v: np.ndarray) -> bool:
    v = np.asarray(v, dtype=float)
    if v.size < 3 or np.any(v <= 0):
        return False
    r = v[1:] / v[:-1]
    return bool(np.allclose(r, r[0], rtol=1e-6) and abs(r[0] - 1.0) > 1e-6)


def select_plane(ds, params: list[str], x: str | None, y: str | None, at: dict[str, Any] | None):
    """The 2-D (or 1-D) slice of a grid study to draw, and a note of the values held fixed."""
    x = x or params[0]
    y = y if y is not None else (params[1] if len(params) > 1 and params[1] != x else None)
    for flag, p in (("--x", x), ("--y", y)):
        if p is not None and p not in params:
            raise ModelError(flag, p, f"must be one of the study's parameters {params}")
    if x == y:
        raise ModelError("--y", y, "must differ from --x")
    at = dict(at or {})
    for p in at:
        if p not in params or p in (x, y):
            raise ModelError("--at", p, f"must name one of the other parameters {[q for q in params if q not in (x, y)]}")
    fixed = []
    if "sample" not in ds.dims:
        for p in params:
            if p in (x, y):
                continue
            coord = ds[p]
            j = _index_of(coord.values, at[p], p) if p in at else 0
            ds = ds.isel({p: j})
            fixed.append(f"{p} = {coord.values[j]:.4g}" if coord.dtype.kind == "f" else f"{p} = {coord.values[j]}")
    return ds, x, y, fixed


def _index_of(values: np.ndarray, val: Any, p: str) -> int:
    """Position of the grid value nearest to ``val`` (exact match for words and flags)."""
    if values.dtype.kind in "fiu":
        try:
            return int(np.argmin(np.abs(values.astype(float) - float(val))))
        except (TypeError, ValueError):
            pass
    hits = np.flatnonzero(values.astype(str) == str(val))
    if not hits.size:
        raise ModelError("--at", f"{p}={val}", f"is not one of the values {values.tolist()}")
    return int(hits[0])


def _kind_regions(ax, xs, ys, kind, status):
    """Hatch the divergence and stable-to-the-limit regions; outline the flutter region."""
    from matplotlib.patches import Patch

    handles = []
    ok = status == 0
    flutter = (ok & (kind == 1)).astype(float)
    if flutter.any():
        handles.append(Patch(facecolor="white", edgecolor="0.3", label="flutter (no hatching)"))
        if (1.0 - flutter).any():
            ax.contour(xs, ys, flutter, levels=[0.5], colors="0.15", linewidths=0.9)
    for code, hatch, label in ((2, "xx", "divergence"), (0, "//", "stable up to thrust_max")):
        mask = (ok & (kind == code)).astype(float)
        if mask.any():
            ax.contourf(xs, ys, mask, levels=[0.5, 1.5], colors="none", hatches=[hatch])
            handles.append(Patch(facecolor="white", edgecolor="0.3", hatch=hatch, label=label))
    return handles


def plot_stability_map(result, ax=None, *, x: str | None = None, y: str | None = None,
                       value: str = "critical_thrust", at: dict[str, Any] | None = None, levels: int = 14):
    """Draw the stability map of a study; returns the Axes.

    Filled contours of ``value`` (critical thrust or margin) over parameters ``x`` and ``y``;
    the operating thrust as a contour line (margin 1); divergence and stable-to-the-limit
    regions hatched, the flutter boundary outlined; failed designs marked with crosses. Other
    grid parameters are held at their first value unless given in ``at`` (nearest value).
    A random or Sobol study is drawn as coloured points; a one-parameter grid as a curve.

    Parameters
    ----------
    result : StudyResult
    ax : matplotlib Axes, optional
        Drawn onto when given; otherwise a new figure.
    x, y : str, optional
        Parameter paths; default the first two parameters of the study.
    value : str
        A real output, e.g. ``"critical_thrust"`` or ``"margin"``.
    at : dict, optional
        Values of the other grid parameters (path -> value).
    levels : int
        Number of filled-contour levels.
    """
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    ds0 = result.dataset
    if value not in ds0.data_vars or ds0[value].dtype.kind != "f":
        known = [v for v in ds0.data_vars if ds0[v].dtype.kind == "f"]
        raise ModelError("--value", value, f"must be one of the stored real outputs {known}")
    ds, x, y, fixed = select_plane(_prepare(result), result.parameters, x, y, at)
    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 5.8), layout="constrained")
    margin = ds["margin"] if "margin" in ds else None
    status = ds["status"].values
    kind = ds["kind"].values if "kind" in ds else np.where(np.isfinite(ds[value].values), 1, -1)
    handles: list = []
    if "sample" in ds.dims or y is None:
        handles = _points_or_curve(ax, ds, x, y, value, kind, status, margin)
    else:
        sub = ds.transpose(y, x)
        xs, ys = sub[x].values, sub[y].values
        status = sub["status"].values
        kind = sub["kind"].values if "kind" in sub else np.where(np.isfinite(sub[value].values), 1, -1)
        stable = (kind == 0) & (status == 0)
        # a design stable up to the end of the search is drawn at that end (a lower bound)
        z = _filled(sub, value, stable)
        m = None if margin is None else _filled(sub, "margin", stable)
        if np.isfinite(z).sum() >= 2:
            cf = ax.contourf(xs, ys, z, levels=levels, cmap="viridis")
            ax.figure.colorbar(cf, ax=ax, label=_LABELS.get(value, value))
        handles += _kind_regions(ax, xs, ys, kind, status)
        if m is not None and np.nanmin(m, initial=np.inf) < 1.0 < np.nanmax(m, initial=-np.inf):
            ax.contour(xs, ys, m, levels=[1.0], colors="k", linewidths=2.0)
            handles.append(Line2D([], [], color="k", lw=2.0, label="operating thrust (margin 1)"))
        bad = status > 0
        if bad.any():
            gx, gy = np.meshgrid(xs, ys)
            ax.plot(gx[bad], gy[bad], "x", color="C3", ms=6, ls="none")
            handles.append(Line2D([], [], marker="x", color="C3", ls="none", label="failed design"))
        if _log_spaced(xs):
            ax.set_xscale("log")
        if _log_spaced(ys):
            ax.set_yscale("log")
        ax.set_ylabel(_label(y))
    ax.set_xlabel(_label(x))
    title = f"stability map: {ds0.attrs.get('study_name', '')}"
    missing = int(np.count_nonzero(ds0["status"].values < 0))
    if missing:
        title += f" (incomplete: {missing} of {ds0['status'].size} designs not computed)"
    ax.set_title(title + (f"\n({', '.join(fixed)})" if fixed else ""), fontsize="medium")
    if handles:
        ax.legend(handles=handles, loc="best", fontsize="small", framealpha=0.85)
    return ax


def _prepare(result):
    """The dataset with ``margin`` (when it can be had) and the search limits as lower bounds."""
    ds = result.dataset
    extra = {}
    if "margin" not in ds and "critical_thrust" in ds:
        op = result.operating_thrust()
        if op is not None:
            with np.errstate(invalid="ignore", divide="ignore"):
                extra["margin"] = ds["critical_thrust"].copy(data=ds["critical_thrust"].values / op)
    for by in ("critical_thrust", "margin"):
        limit = result.search_limit(by)
        if limit is not None:
            extra[f"_limit_{by}"] = ds["status"].copy(data=np.asarray(limit, dtype=float))
    return ds.assign(extra) if extra else ds


def _filled(sub, name: str, stable):
    """Values of ``name``, with the search limit where the design is stable up to it."""
    z = np.asarray(sub[name].values, dtype=float)
    if f"_limit_{name}" in sub:
        z = np.where(stable & ~np.isfinite(z), sub[f"_limit_{name}"].values, z)
    return z


def _points_or_curve(ax, ds, x, y, value, kind, status, margin):
    from matplotlib.lines import Line2D

    xv = ds[x].values
    z = ds[value].values
    colors = {0: "0.6", 1: "C0", 2: "C1"}
    names = {0: "stable up to thrust_max", 1: "flutter", 2: "divergence"}
    handles = []
    if y is None:
        order = np.argsort(xv)
        ax.plot(xv[order], z[order], "-", color="0.4", lw=1.2)
        for code in (1, 2):
            sel = (kind == code) & (status == 0)
            if sel.any():
                ax.plot(xv[sel], z[sel], "o", color=colors[code], ms=4)
                handles.append(Line2D([], [], marker="o", color=colors[code], ls="none", label=names[code]))
        if value == "margin":
            ax.axhline(1.0, color="k", lw=1.5)
            handles.append(Line2D([], [], color="k", lw=1.5, label="operating thrust"))
        ax.set_ylabel(_LABELS.get(value, value))
        if _log_spaced(np.sort(xv)):
            ax.set_xscale("log")
        return handles
    yv = ds[y].values
    sel = np.isfinite(z) & (status == 0)
    if sel.any():
        sc = ax.scatter(xv[sel], yv[sel], c=z[sel], s=14, cmap="viridis")
        ax.figure.colorbar(sc, ax=ax, label=_LABELS.get(value, value))
    for code, marker in ((0, "^"), (2, "s")):
        s2 = (kind == code) & (status == 0) & ~np.isfinite(z) if code == 0 else (kind == code) & (status == 0)
        if s2.any():
            ax.scatter(xv[s2], yv[s2], facecolors="none", edgecolors=colors[code], marker=marker, s=22)
            handles.append(Line2D([], [], marker=marker, mfc="none", color=colors[code], ls="none", label=names[code]))
    bad = status > 0
    if bad.any():
        ax.plot(xv[bad], yv[bad], "x", color="C3", ls="none")
        handles.append(Line2D([], [], marker="x", color="C3", ls="none", label="failed design"))
    if margin is not None:
        m = np.asarray(margin.values, dtype=float)
        good = np.isfinite(m)
        if good.sum() >= 3 and np.nanmin(m) < 1.0 < np.nanmax(m):
            try:
                ax.tricontour(xv[good], yv[good], m[good], levels=[1.0], colors="k", linewidths=1.5)
                handles.append(Line2D([], [], color="k", lw=1.5, label="operating thrust (margin 1)"))
            except (ValueError, RuntimeError):
                pass
    ax.set_ylabel(_label(y))
    return handles
