"""Stability map of a design study: critical thrust (or margin) over two design parameters.

A grid study is drawn cell by cell (``pcolormesh``): every design is one cell, coloured by its
own value, so nothing is interpolated between grid points; region boundaries (the operating
thrust, divergence, the end of the search) follow the cell edges. Designs stable over the whole
search have no critical thrust, only a lower bound: they are a grey region of their own,
counted in the legend, and left out of the colour scale so that it spans the values that were
found. Axes are labelled with the parameters' names and units from the model-file reference.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ModelError
from .style import ONSET_COLOR, figure_style

__all__ = ["plot_stability_map", "select_plane", "value_label"]

_SHORT = {
    "critical_thrust": "critical thrust (N)",
    "margin": "margin = critical / operating thrust",
    "undamped_critical_thrust": "undamped critical thrust (N)",
    "frequency_hz": "frequency at the onset (Hz)",
    "omega": "angular frequency at the onset (rad/s)",
    "thrust_max": "end of the search thrust_max (N)",
    "operating_thrust": "operating thrust (N)",
}
_CENSORED = "#D9D9D9"
_DIVERGENCE_HATCH = "xxx"


def value_label(name: str) -> str:
    """Axis or colour-bar label of a study output, with its unit."""
    if name in _SHORT:
        return _SHORT[name]
    from ..studies.schema import OUTPUTS

    unit, text = OUTPUTS.get(name, ("", name))
    return f"{text} ({unit})" if unit and unit != "1" else text


def _label(path: str) -> str:
    from ..model.reference import label

    return label(path)


def _log_spaced(v: np.ndarray) -> bool:
    v = np.asarray(v, dtype=float)
    if v.size < 3 or np.any(v <= 0):
        return False
    r = v[1:] / v[:-1]
    return bool(np.allclose(r, r[0], rtol=1e-6) and abs(r[0] - 1.0) > 1e-6)


def _edges(v: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around grid values: midpoints (geometric on a log axis), mirrored at the ends."""
    v = np.asarray(v, dtype=float)
    if v.size == 1:
        return np.array([v[0] * 0.9, v[0] * 1.1]) if log else np.array([v[0] - 0.5, v[0] + 0.5])
    w = np.log(v) if log else v
    mid = 0.5 * (w[1:] + w[:-1])
    e = np.concatenate([[w[0] - (mid[0] - w[0])], mid, [w[-1] + (w[-1] - mid[-1])]])
    return np.exp(e) if log else e


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
            val = coord.values[j]
            fixed.append(f"{_label(p)} = {val:.4g}" if coord.dtype.kind == "f" else f"{_label(p)} = {val}")
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


def _boundary(mask: np.ndarray, xe: np.ndarray, ye: np.ndarray) -> list:
    """Line segments along the cell edges that separate ``mask`` from the rest (ny, nx)."""
    segs = []
    ny, nx = mask.shape
    for i in range(ny):
        for j in range(nx - 1):
            if mask[i, j] != mask[i, j + 1]:
                segs.append([(xe[j + 1], ye[i]), (xe[j + 1], ye[i + 1])])
    for i in range(ny - 1):
        for j in range(nx):
            if mask[i, j] != mask[i + 1, j]:
                segs.append([(xe[j], ye[i + 1]), (xe[j + 1], ye[i + 1])])
    return segs


def _limit_text(result, by: str) -> str:
    t_max = result.thrust_max()
    if t_max is None:
        return "the end of the search"
    vals = np.unique(np.asarray(t_max, dtype=float)[np.isfinite(t_max)])
    if vals.size != 1:
        return "thrust_max"
    if by == "margin":
        lim = result.search_limit("margin")
        lv = np.unique(np.asarray(lim, dtype=float)[np.isfinite(lim)]) if lim is not None else []
        if len(lv) == 1:
            return f"thrust_max = {vals[0]:.6g} N (margin > {lv[0]:.4g})"
    return f"thrust_max = {vals[0]:.6g} N"


def plot_stability_map(result, ax=None, *, x: str | None = None, y: str | None = None,
                       value: str = "critical_thrust", at: dict[str, Any] | None = None):
    """Draw the stability map of a study; returns the Axes.

    A grid over two parameters is drawn cell by cell, coloured by ``value`` (critical thrust or
    margin); designs stable up to ``thrust_max`` grey (their value is only a lower bound),
    divergence hatched, the cells with a margin below 1 (unstable at the operating thrust)
    outlined in black, failed designs crossed. Other grid parameters are held at their first
    value unless given in ``at`` (nearest value). A random or Sobol study is drawn as points,
    a one-parameter grid as a curve.

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
    """
    import matplotlib.pyplot as plt

    ds0 = result.dataset
    if value not in ds0.data_vars or ds0[value].dtype.kind != "f":
        known = [v for v in ds0.data_vars if ds0[v].dtype.kind == "f"]
        raise ModelError("--value", value, f"must be one of the stored real outputs {known}")
    ds, x, y, fixed = select_plane(_prepare(result), result.parameters, x, y, at)
    with figure_style():
        if ax is None:
            _, ax = plt.subplots(figsize=(8.2, 5.6), layout="constrained")
        status = ds["status"].values
        kind = ds["kind"].values if "kind" in ds else np.where(np.isfinite(ds[value].values), 1, -1)
        censored_text = f"stable up to {_limit_text(result, value)}, censored"
        if "sample" in ds.dims:
            handles = _points(ax, ds, x, y, value, kind, status, censored_text)
            others = [_label(p) for p in result.parameters if p not in (x, y)]
            if others:
                fixed = [f"projection: {', '.join(others)} also var{'ies' if len(others) == 1 else 'y'}"]
        elif y is None:
            handles = _curve(ax, ds, x, value, kind, status, censored_text)
        else:
            handles = _cells(ax, ds, x, y, value, censored_text)
            ax.set_ylabel(_label(y))
        ax.set_xlabel(_label(x))
        title = f"stability map: {ds0.attrs.get('study_name', '')}"
        missing = int(np.count_nonzero(ds0["status"].values < 0))
        if missing:
            title += f" (incomplete: {missing} of {ds0['status'].size} designs not computed)"
        ax.set_title(title + (f"\n{', '.join(fixed)}" if fixed else ""))
        if handles:
            _legend_below(ax, handles)
    return ax


def _legend_below(ax, handles) -> None:
    """The legend under the plot, outside the data: a figure legend when the layout engine can
    make room for it (a figure of this module's own), else one under the axes."""
    from matplotlib.layout_engine import ConstrainedLayoutEngine

    fig = ax.figure
    if isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine) and len(fig.axes) <= 2:
        fig.legend(handles=handles, loc="outside lower center", ncols=1 if len(handles) < 3 else 2)
    else:
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(0.0, -0.14), ncols=1, borderaxespad=0.0)


def _cells(ax, ds, x, y, value, censored_text) -> list:
    from matplotlib.collections import LineCollection
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    sub = ds.transpose(y, x)
    xs, ys = sub[x].values, sub[y].values
    xlog, ylog = _log_spaced(xs), _log_spaced(ys)
    xe, ye = _edges(xs, xlog), _edges(ys, ylog)
    status = sub["status"].values
    kind = sub["kind"].values if "kind" in sub else np.where(np.isfinite(sub[value].values), 1, -1)
    ok = status == 0
    censored = ok & (kind == 0)
    z = np.asarray(sub[value].values, dtype=float)
    shown = ok & np.isfinite(z) & ~censored
    handles = []
    if shown.any():
        mesh = ax.pcolormesh(xe, ye, np.ma.masked_where(~shown, z), cmap="viridis", shading="flat",
                             vmin=float(z[shown].min()), vmax=float(z[shown].max()))
        ax.figure.colorbar(mesh, ax=ax, label=value_label(value) + ", one cell per design")
    if censored.any():
        ax.pcolormesh(xe, ye, np.ma.masked_where(~censored, np.ones_like(z)), cmap=ListedColormap([_CENSORED]),
                      shading="flat")
        handles.append(Patch(facecolor=_CENSORED, edgecolor="0.5",
                             label=f"{censored_text}: {int(censored.sum())} of {censored.size}"))
    div = ok & (kind == 2)
    if div.any():
        ax.pcolormesh(xe, ye, np.ma.masked_where(~div, np.ones_like(z)), cmap=ListedColormap(["none"]),
                      shading="flat", hatch=_DIVERGENCE_HATCH, edgecolor="0.2", linewidth=0.0)
        handles.append(Patch(facecolor="white", edgecolor="0.2", hatch=_DIVERGENCE_HATCH,
                             label="divergence (the other coloured cells: flutter)"))
    if "margin" in sub:
        m = np.asarray(sub["margin"].values, dtype=float)
        below = ok & np.isfinite(m) & (m < 1.0) & ~censored
        if below.any():
            ax.add_collection(LineCollection(_boundary(below, xe, ye), colors="k", linewidths=2.0))
            handles.append(Patch(facecolor="none", edgecolor="k", linewidth=2.0,
                                 label=f"margin < 1 (unstable at the operating thrust): {int(below.sum())} of {below.size}"))
    bad = status > 0
    if bad.any():
        gx, gy = np.meshgrid(xs, ys)
        ax.plot(gx[bad], gy[bad], "x", color=ONSET_COLOR, ms=6, ls="none")
        from matplotlib.lines import Line2D

        handles.append(Line2D([], [], marker="x", color=ONSET_COLOR, ls="none",
                              label=f"failed design ({int(bad.sum())}; see 'status' and 'message')"))
    if (status < 0).any():
        handles.append(Patch(facecolor="white", edgecolor="0.5", label="not computed yet (blank)"))
    if xlog:
        ax.set_xscale("log")
    if ylog:
        ax.set_yscale("log")
    ax.set_xlim(xe[0], xe[-1])
    ax.set_ylim(ye[0], ye[-1])
    ax.grid(False)
    return handles


def _prepare(result):
    """The dataset with ``margin`` (when it can be had) and each design's search limit
    (``_limit_critical_thrust``, ``_limit_margin``): the lower bound of a censored design."""
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


def _curve(ax, ds, x, value, kind, status, censored_text) -> list:
    from matplotlib.lines import Line2D

    from .style import PALETTE

    xv = np.asarray(ds[x].values)
    z = np.asarray(ds[value].values, dtype=float)
    order = np.argsort(xv)
    xv, z, kind, status = xv[order], z[order], kind[order], status[order]
    ok = status == 0
    handles = []
    line = np.where(ok & (kind != 0), z, np.nan)
    ax.plot(xv, line, "-", color=PALETTE[0], lw=1.4)
    for code, marker, name in ((1, "o", "flutter"), (2, "s", "divergence")):
        sel = ok & (kind == code) & np.isfinite(z)
        if sel.any():
            ax.plot(xv[sel], z[sel], marker, color=PALETTE[0] if code == 1 else PALETTE[1], ms=4, ls="none")
            handles.append(Line2D([], [], marker=marker, color=PALETTE[0] if code == 1 else PALETTE[1], ls="none",
                                  label=name))
    cens = ok & (kind == 0)
    if cens.any():
        name = f"_limit_{value}"
        at = ds[name].values[order][cens] if name in ds else np.full(cens.sum(), np.nanmax(z, initial=0.0))
        ax.plot(xv[cens], at, "^", mfc="none", color="0.45", ls="none")
        handles.append(Line2D([], [], marker="^", mfc="none", color="0.45", ls="none",
                              label=f"{censored_text}, drawn at the limit ({int(cens.sum())})"))
    if value == "margin":
        ax.axhline(1.0, color="k", lw=1.5)
        handles.append(Line2D([], [], color="k", lw=1.5, label="margin 1: the operating thrust"))
    bad = status > 0
    if bad.any():
        ax.plot(xv[bad], np.zeros(bad.sum()), "x", color=ONSET_COLOR, ls="none")
        handles.append(Line2D([], [], marker="x", color=ONSET_COLOR, ls="none", label="failed design"))
    ax.set_ylabel(value_label(value))
    if _log_spaced(xv):
        ax.set_xscale("log")
    return handles


def _points(ax, ds, x, y, value, kind, status, censored_text) -> list:
    from matplotlib.lines import Line2D

    xv = ds[x].values
    z = np.asarray(ds[value].values, dtype=float)
    ok = status == 0
    handles = []
    yv = ds[y].values if y is not None else z
    shown = ok & np.isfinite(z) & (kind != 0)
    if y is not None and shown.any():
        sc = ax.scatter(xv[shown], yv[shown], c=z[shown], s=12, cmap="viridis")
        ax.figure.colorbar(sc, ax=ax, label=value_label(value))
    elif shown.any():
        ax.plot(xv[shown], z[shown], "o", ms=3, color="C0", ls="none")
    cens = ok & (kind == 0)
    if cens.any() and y is not None:
        ax.scatter(xv[cens], yv[cens], facecolors="none", edgecolors="0.55", marker="o", s=14)
        handles.append(Line2D([], [], marker="o", mfc="none", color="0.55", ls="none",
                              label=f"{censored_text}: {int(cens.sum())} of {cens.size}"))
    div = ok & (kind == 2)
    if div.any() and y is not None:
        ax.scatter(xv[div], yv[div], facecolors="none", edgecolors="k", marker="s", s=22)
        handles.append(Line2D([], [], marker="s", mfc="none", color="k", ls="none", label="divergence"))
    if "margin" in ds and y is not None:
        m = np.asarray(ds["margin"].values, dtype=float)
        below = ok & np.isfinite(m) & (m < 1.0) & (kind != 0)
        if below.any():
            ax.scatter(xv[below], yv[below], facecolors="none", edgecolors="k", marker="o", s=40, linewidths=1.2)
            handles.append(Line2D([], [], marker="o", mfc="none", color="k", ls="none",
                                  label=f"margin < 1 (unstable at the operating thrust): {int(below.sum())}"))
    bad = status > 0
    if bad.any():
        ax.plot(xv[bad], yv[bad] if y is not None else np.zeros(bad.sum()), "x", color=ONSET_COLOR, ls="none")
        handles.append(Line2D([], [], marker="x", color=ONSET_COLOR, ls="none", label="failed design"))
    ax.set_ylabel(_label(y) if y is not None else value_label(value))
    return handles
