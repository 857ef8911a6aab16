"""Results of a design study: the Dataset, the best design, the stability map, exports."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ModelError

__all__ = ["StudyResult", "open_study"]


@dataclass(frozen=True, eq=False)
class StudyResult:
    """The results of a study, loaded in memory.

    Attributes
    ----------
    dataset : xarray.Dataset
        One variable per output plus ``status`` (codes in ``attrs["flag_meanings"]``) and
        ``message``; one dimension per grid parameter, or ``sample``; the study file, the base
        model, the package version and timestamps in ``attrs``.
    store : str or None
        Where the results are stored (None for an in-memory study).
    pending_chunks : tuple of int
        The chunks not computed yet (their designs have status -1 and fill values): an
        interrupted study read before it was resumed.
    """

    dataset: Any
    store: str | None = None
    pending_chunks: tuple[int, ...] = ()

    def __repr__(self) -> str:
        from ..display import study_text

        return study_text(self)

    def _repr_html_(self) -> str:
        from ..display import study_html

        return study_html(self)

    def __post_init__(self) -> None:
        # parameter coordinates carry the units of their model-file keys
        from ..model.reference import label, unit

        ds = self.dataset
        for p in json.loads(ds.attrs.get("parameters", "[]")):
            if p in ds.coords and "units" not in ds[p].attrs:
                u = unit(p)
                if u is not None:
                    ds[p].attrs["units"] = u
                    ds[p].attrs.setdefault("label", label(p))
        if "sample" in ds.coords and "units" not in ds["sample"].attrs:
            ds["sample"].attrs["units"] = "1"

    @classmethod
    def from_store(cls, st) -> "StudyResult":
        return cls(st.load_dataset(), None if st.path is None else str(st.path),
                   tuple(int(i) for i in (~st.done()).nonzero()[0]))

    # -- views --------------------------------------------------------------------------------
    @property
    def parameters(self) -> list[str]:
        """Parameter paths, in the order of the study file."""
        return json.loads(self.dataset.attrs["parameters"])

    @property
    def complete(self) -> bool:
        """Whether every design has been computed."""
        return bool((self.dataset["status"] >= 0).all())

    def counts(self) -> dict[str, int]:
        """Number of designs per status (``not_computed`` for status -1)."""
        meanings = self.dataset["status"].attrs["flag_meanings"].split()
        codes = self.dataset["status"].values.ravel()
        out = {m: int(np.count_nonzero(codes == k)) for k, m in enumerate(meanings)}
        out["not_computed"] = int(np.count_nonzero(codes < 0))
        return out

    def to_xarray(self):
        """The results as an xarray Dataset (a copy)."""
        return self.dataset.copy()

    def kind_names(self, var: str = "kind"):
        """``var`` (a kind code variable) as strings: ``"flutter"``, ``"divergence"``, ``"none"`` or ``""``."""
        meanings = np.array(self.dataset[var].attrs["flag_meanings"].split() + [""])
        return self.dataset[var].copy(data=meanings[self.dataset[var].values.astype(int)])

    def best(self, by: str = "margin", *, minimum: bool = False, where=None) -> dict[str, Any]:
        """The design with the largest (or smallest) value of ``by`` among the computed designs.

        A design that stays stable over the whole search (kind ``"none"``) has no critical
        thrust; it ranks with its search limit (``thrust_max``, or ``thrust_max / operating`` for
        the margin) as a lower bound, and the answer says so (``"lower_bound": True`` and a
        ``"warning"``: the true value is larger than shown). Designs that share that bound are a
        tie that the study cannot break (``"tied"``). A selection (``where``) that leaves out
        designs stable up to a limit above the value found says so as well: the value is then
        the largest of the selection only, often just an artefact of the cut-off.

        Parameters
        ----------
        by : str
            ``"margin"``, ``"critical_thrust"`` or any other float output.
        minimum : bool
            The smallest value instead (the worst design).
        where : boolean DataArray or array, optional
            Only these designs, e.g. ``ds["kind"] == 1`` (flutter within the search range).

        Returns
        -------
        dict
            ``parameters`` (path -> value), ``value`` (of ``by``, or its lower bound), ``values``
            (every stored output), ``index`` (position in the design array), ``lower_bound`` and
            ``tied`` (number of designs sharing the value), ``censored_left_out`` (designs outside
            ``where`` stable up to a limit at or above ``value``: larger than it) and ``warning``
            (a sentence when the value is a bound, a tie or a cut-off artefact; else None).
        """
        ds = self.dataset
        if by not in ds.data_vars or ds[by].dtype.kind != "f":
            known = [v for v in ds.data_vars if ds[v].dtype.kind == "f"]
            raise ModelError("by", by, f"must be one of the stored real outputs {known}")
        value = ds[by].values.astype(float)
        bound = np.zeros(value.shape, dtype=bool)
        if by in ("margin", "critical_thrust") and "kind" in ds:
            stable = (ds["kind"].values == 0) & (ds["status"].values == 0)
            limit = self.search_limit(by)
            if limit is not None:
                value = np.where(stable, limit, value)
                bound = stable
        bounds_all = np.where(bound, value, np.nan)
        if where is not None:
            mask = where.broadcast_like(ds[by]).transpose(*ds[by].dims).values if hasattr(where, "dims") else np.asarray(where)
            mask = np.broadcast_to(mask, value.shape)
            value = np.where(mask, value, np.nan)
            bound = bound & mask
        if not np.isfinite(value).any():
            raise ModelError("by", by, "no computed (and selected) design has a value for it")
        pick = np.where(np.isfinite(value), value, np.inf if minimum else -np.inf)
        flat = int(np.argmin(pick) if minimum else np.argmax(pick))
        idx = np.unravel_index(flat, value.shape)
        sel = dict(zip(ds[by].dims, idx))
        point = ds.isel(sel)
        params = {p: _plain(point[p].values) for p in self.parameters}
        values = {v: _plain(point[v].values) for v in ds.data_vars}
        for v in ("kind", "undamped_kind"):
            if v in ds:
                values[v] = self.kind_names(v).isel(sel).item()
        chosen, tied = float(value[idx]), int(np.count_nonzero(pick == pick[idx]))
        left_out, floor = 0, np.nan
        if not minimum:
            with np.errstate(invalid="ignore"):
                better = np.isfinite(bounds_all) & ~np.isfinite(value) & (bounds_all >= chosen)
            left_out = int(np.count_nonzero(better))
            floor = float(bounds_all[better].min()) if left_out else np.nan
        return {
            "parameters": params,
            "value": chosen,
            "values": values,
            "index": {d: int(i) for d, i in sel.items()},
            "lower_bound": bool(bound[idx]),
            "tied": tied,
            "censored_left_out": left_out,
            "warning": _best_warning(by, chosen, bool(bound[idx]), tied, left_out, floor),
        }

    def statistics(self, target_margin: float | None = 1.0, **kw):
        """Uncertainty statistics of a random, Sobol or Saltelli study: distributions of the
        critical thrust and margin with censoring at ``thrust_max``, the probability of a margin
        below ``target_margin``, Sobol indices (:func:`impstab.studies.statistics.study_statistics`)."""
        from .statistics import study_statistics

        return study_statistics(self, target_margin, **kw)

    def sensitivity(self, quantity: str | None = None, **kw):
        """Sobol sensitivity indices (:func:`impstab.studies.sensitivity.sensitivity_indices`)."""
        from .sensitivity import sensitivity_indices

        return sensitivity_indices(self, quantity, **kw)

    def operating_thrust(self):
        """Operating thrust of every design (N), an array shaped like the designs; None if unset."""
        return self._per_design("operating_thrust", "thrust.operating", "thrust", "operating")

    def thrust_max(self):
        """Upper end of every design's critical-thrust search (N); None if unknown."""
        t_max = self._per_design("thrust_max", "analysis.thrust_max", "analysis", "thrust_max")
        op = self.operating_thrust()
        if t_max is None and op is not None:
            t_max = 10.0 * op  # the model-file default
        return t_max

    def search_limit(self, by: str = "critical_thrust"):
        """Per-design end of the search: ``thrust_max`` (N), or ``thrust_max / operating`` for
        ``by="margin"``; None when unknown. A design stable up to it has at least this value."""
        t_max, op = self.thrust_max(), self.operating_thrust()
        if by == "critical_thrust" or t_max is None:
            return t_max
        if op is None:
            return None
        with np.errstate(invalid="ignore", divide="ignore"):
            return t_max / op

    def _per_design(self, output: str, path: str, section: str, key: str):
        ds = self.dataset
        ref = ds["status"]
        if output in ds:
            return ds[output].values.astype(float)
        if path in ds.coords:
            return ds[path].broadcast_like(ref).transpose(*ref.dims).values.astype(float)
        value = _base_value(ds.attrs, section, key)
        return None if value is None else np.full(ref.shape, float(value))

    def model_dict(self, parameters: dict[str, Any]) -> dict:
        """The model-file dict of one design: the stored base model with ``parameters`` set.

        ``parameters`` maps paths to values, e.g. ``result.best()["parameters"]``.
        """
        import tomllib

        from .paths import variant_dict
        from .paths import parse_path

        unknown = [p for p in parameters if p not in self.parameters]
        if unknown:
            raise ModelError("parameters", unknown, f"are not parameters of this study {self.parameters}")
        base = tomllib.loads(self.dataset.attrs["model_file"])
        return variant_dict(base, [parse_path(p) for p in parameters], list(parameters.values()))

    def model(self, parameters: dict[str, Any]):
        """The :class:`~impstab.model.Model` of one design (validated like a model file)."""
        from ..model.assemble import model_from_dict

        return model_from_dict(self.model_dict(parameters), name=self.dataset.attrs.get("model_name", "model"))

    def plot(self, ax=None, *, x: str | None = None, y: str | None = None, value: str = "critical_thrust",
             at: dict[str, Any] | None = None):
        """Draw the stability map; returns the matplotlib Axes.

        See :func:`impstab.plot.stability_map.plot_stability_map`.
        """
        from ..plot.stability_map import plot_stability_map

        return plot_stability_map(self, ax=ax, x=x, y=y, value=value, at=at)

    def tradeoff(self, isolation: str = "peak_transmissibility", stability: str = "margin", **limits) -> dict:
        """Isolation against stability of every design with the Pareto front
        (:func:`impstab.studies.pareto.tradeoff_table`)."""
        from .pareto import tradeoff_table

        return tradeoff_table(self, isolation, stability, **limits)

    def plot_tradeoff(self, isolation: str = "peak_transmissibility", stability: str = "margin", *, ax=None, **kw):
        """Draw the isolation-versus-stability trade-off with the Pareto front and the requirements;
        returns the matplotlib Axes (:func:`impstab.plot.tradeoff.plot_tradeoff`)."""
        from ..plot.tradeoff import plot_tradeoff

        return plot_tradeoff(self, isolation, stability, ax=ax, **kw)

    # -- exports ------------------------------------------------------------------------------
    def to_netcdf(self, path: str | os.PathLike[str], *, option: str = "path") -> Path:
        """Write the results to a netCDF file, whole or not at all (:func:`impstab.io.write_output`).

        ``option`` names the path in the error message (``--export`` on the command line).
        """
        from ..io import write_netcdf

        return write_netcdf(self.dataset, path, option=option)

    def to_csv(self, path: str | os.PathLike[str], *, option: str = "path") -> Path:
        """Write one row per design (parameters, outputs, status, message) to a CSV file."""
        from ..io import write_csv

        ds = self.dataset
        frame = ds.to_dataframe().reset_index()
        for v in ("kind", "undamped_kind", "status"):
            if v in ds:
                names = np.array(ds[v].attrs["flag_meanings"].split() + ["not_computed" if v == "status" else ""])
                frame[v] = names[frame[v].to_numpy().astype(int)]
        first = [c for c in ("sample", *self.parameters) if c in frame.columns]
        frame = frame[first + [c for c in frame.columns if c not in first]]
        return write_csv(frame, path, option=option, index=False)

    def export(self, path: str | os.PathLike[str], *, option: str = "--export") -> Path:
        """Write to ``.nc`` (netCDF) or ``.csv`` by the file's extension."""
        suffix = Path(path).suffix.lower()
        if suffix == ".nc":
            return self.to_netcdf(path, option=option)
        if suffix == ".csv":
            return self.to_csv(path, option=option)
        raise ModelError(option, str(path), "must end in .nc (netCDF) or .csv")


def _best_warning(by: str, value: float, bound: bool, tied: int, left_out: int, floor: float) -> str | None:
    """What :meth:`StudyResult.best` must say about a value set by the end of the search."""
    name = by.replace("_", " ")
    if bound:
        text = f"stable up to thrust_max: the true {name} is larger than shown"
        if tied > 1:
            text += f"; a tie: {tied} designs are stable up to the same limit and cannot be ranked, this is the first"
        return text
    if left_out:
        return (f"{left_out} designs left out by the selection are stable up to thrust_max, with {name}s of at least "
                f"{floor:.6g}: {value:.6g} is the largest of the selection only, set by the end of the search; "
                "raise analysis.thrust_max to rank them")
    return None


def _plain(v):
    v = np.asarray(v)
    return v.item() if v.ndim == 0 else v.tolist()


def _base_value(attrs: dict, section: str, key: str):
    import tomllib

    try:
        return tomllib.loads(attrs.get("model_file", "")).get(section, {}).get(key)
    except tomllib.TOMLDecodeError:
        return None


def open_study(store: str | os.PathLike[str]) -> StudyResult:
    """Load the results of a study: its zarr store (complete or not) or a netCDF export.

    A store is verified first (:func:`impstab.studies.store.read_store`): only data that match
    their completion records are read. Chunks not computed yet (an interrupted study) are
    returned with status -1 and listed in ``pending_chunks``.

    Raises
    ------
    ModelError
        If ``store`` is neither, or the store holds damaged data (the chunks and files are named;
        rerunning the study computes them again).
    """
    import xarray as xr

    from ..io import PathError
    from .store import read_store, tidy
    from .store_files import FolderFiles

    p = Path(store)
    if p.is_file() and p.suffix.lower() == ".nc":
        try:
            ds = xr.load_dataset(p, engine="h5netcdf")
        except Exception as exc:  # noqa: BLE001 - any unreadable file is "not a study"
            raise PathError("STORE", p, f"cannot be read as netCDF ({type(exc).__name__})") from None
        if not str(ds.attrs.get("format", "")).startswith("impstab-study-store"):
            raise PathError("STORE", p, "is not an export of an impstab study")
        return StudyResult(tidy(ds), None)
    if not p.is_dir():
        raise PathError("STORE", p, "is not a folder (give the zarr store written by 'impstab sweep', or its .nc export)")
    view = read_store(FolderFiles(p, "STORE"), str(p), field="STORE")
    return StudyResult(view.dataset, str(p), tuple(view.pending))
