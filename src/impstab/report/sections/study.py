"""Sections of a study report: the study, counts by status, stability maps, best designs, statistics.

A design stable over its whole search (kind ``"none"``) has no critical thrust: its value is
only a lower bound, ``thrust_max`` (``thrust_max / operating`` for the margin). Such designs are
censored, and the best-design table says so wherever one is chosen or left out.
"""

from __future__ import annotations

import json

import numpy as np

from ...display.format import number
from ..analyses import find_provider
from ..result import NOT_COMPUTED, Figure, Note, Section, Table
from ..svg import draw_svg, mathtext_safe
from ..tables import table
from .titles import TITLES
from ...studies.statistics import SAMPLED

__all__ = ["StudyContext", "study_section", "status_section", "maps_section", "best_section", "statistics_section"]



class StudyContext:
    """The study result of a report and its options."""

    def __init__(self, result, options) -> None:
        self.result = result
        self.options = options
        self.dataset = result.dataset

    @property
    def sampling(self) -> str:
        return str(self.dataset.attrs.get("sampling", ""))

    def for_drawing(self):
        """The result with its name safe for matplotlib's text (dollar signs escaped)."""
        from ...studies.result import StudyResult

        ds = self.dataset
        return StudyResult(ds.assign_attrs(study_name=mathtext_safe(str(ds.attrs.get("study_name", "")))),
                           self.result.store)


def _value_text(by: str, value: float) -> str:
    return number(value, 4) if by == "margin" else number(value, 6, "N")


def _design_text(parameters: dict) -> str:
    from ...model.reference import unit

    parts = []
    for p, v in parameters.items():
        u = unit(p)
        u = "" if u in (None, "1") else u
        parts.append(f"{p} = {number(v, 6, u) if isinstance(v, (int, float)) and not isinstance(v, bool) else v}")
    return ", ".join(parts)


def study_section(ctx: StudyContext) -> Section:
    from ...display.html import study_html

    a = ctx.dataset.attrs
    rows = [("outputs", ", ".join(json.loads(a.get("outputs", "[]")))),
            ("base model", f"{a.get('model_name', '')} ({a.get('model_path', '')})"),
            ("study file", str(a.get("study_path", ""))),
            ("created", str(a.get("created", ""))), ("completed", str(a.get("completed", "not complete"))),
            ("computed by", f"impstab {a.get('impstab_version', 'unknown')}")]
    blocks = [Table(study_html(ctx.result)), table("study settings", rows)]
    return Section("study", TITLES["study"], blocks=tuple(blocks), data={"study": ctx.result})


def status_section(ctx: StudyContext) -> Section:
    ds = ctx.dataset
    counts = ctx.result.counts()
    total = int(ds["status"].size)
    rows = [(k.replace("_", " "), f"{v} ({100 * v / total:.1f} %)") for k, v in counts.items()]
    blocks: list = [table("designs by status", rows, ["status", "designs"], ["left", "right"])]
    if "kind" in ds:
        names = ctx.result.kind_names().values.ravel()
        ok = ds["status"].values.ravel() == 0
        meaning = {"flutter": "flutter within the search", "divergence": "divergence within the search",
                   "none": "stable up to thrust_max (censored: the critical thrust is only a lower bound)"}
        krows = [(k, meaning[k], str(int(np.count_nonzero(ok & (names == k))))) for k in ("flutter", "divergence", "none")]
        blocks.append(table("computed designs by kind of onset", krows, ["kind", "meaning", "designs"],
                            ["left", "left", "right"]))
    failed = ds["status"].values.ravel() > 0
    if failed.any():
        msgs = ds["message"].values.ravel()[failed]
        first = list(dict.fromkeys(str(m) for m in msgs))[:5]
        blocks.append(Note(f"{int(failed.sum())} designs failed; first messages: " + " | ".join(first), "warning"))
    if counts.get("not_computed"):
        blocks.append(Note(f"{counts['not_computed']} designs are not computed yet: rerun `impstab sweep` to "
                           "resume the study.", "warning"))
    return Section("status", TITLES["status"], blocks=tuple(blocks), data={"counts": counts})


def maps_section(ctx: StudyContext) -> Section:
    ds = ctx.dataset
    drawn = ctx.for_drawing()
    values = [v for v in ("critical_thrust", "margin") if v in ds.data_vars]
    if not values:
        return Section("maps", TITLES["maps"], NOT_COMPUTED,
                       "the study stores neither critical_thrust nor margin (its outputs)")
    params = ctx.result.parameters
    if "sample" in ds.dims:
        how = (f"one point per design over {' and '.join(params[:2])}"
               + (" (the other parameters vary too: a projection)" if len(params) > 2 else "")
               + "; hollow points are stable up to thrust_max (censored: only a lower bound is known)")
    elif len(params) == 1:
        how = f"one point per design along {params[0]}; censored designs (stable up to thrust_max) marked apart"
    else:
        how = (f"one cell per design over {params[0]} and {params[1]}, nothing interpolated"
               + (f" (other parameters at their first value)" if len(params) > 2 else "")
               + "; grey: stable up to thrust_max (censored: only a lower bound), hatched: divergence, outlined: "
               "margin below 1, crossed: failed designs")
    blocks = []
    for v in values:
        svg = draw_svg(lambda v=v: drawn.plot(value=v), f"map-{v.replace('_', '-')}")
        blocks.append(Figure(svg, f"{v.replace('_', ' ')}: {how}."))
    return Section("maps", TITLES["maps"], blocks=tuple(blocks))


def best_section(ctx: StudyContext) -> Section:
    res = ctx.result
    ds = ctx.dataset
    # the margin when the designs have an operating thrust to measure it against
    by = "margin" if "margin" in ds.data_vars and res.search_limit("margin") is not None else "critical_thrust"
    if by not in ds.data_vars:
        return Section("best", TITLES["best"], NOT_COMPUTED, "the study stores neither margin nor critical_thrust")
    censored = (ds["kind"].values == 0) & (ds["status"].values == 0) if "kind" in ds else np.zeros(ds[by].shape, bool)
    n_censored = int(np.count_nonzero(censored))
    rows, notes, picks = [], [], {}
    choices = [("largest, all designs", {}), ("smallest (the worst design)", {"minimum": True})]
    if "kind" in ds and n_censored:
        choices.insert(1, ("largest with an onset found within the search", {"where": ds["kind"] != 0}))
    for what, kw in choices:
        try:
            b = res.best(by, **kw)
        except Exception as exc:  # noqa: BLE001 - a selection with no design is a row, not a failure
            rows.append([what, "none", "", str(exc)])
            continue
        picks[what] = b
        value = (">= " if b["lower_bound"] else "") + _value_text(by, b["value"])
        vals = b["values"]
        note = "" if b["lower_bound"] else str(vals.get("kind", ""))
        if note and "frequency_hz" in vals:
            note += f" at {number(vals['frequency_hz'], 4, 'Hz')}"
        note = "; ".join(t for t in (note, b.get("warning")) if t)      # best() says what a censored value means
        rows.append([what, value, _design_text(b["parameters"]), note])
    blocks: list = [table(f"best designs by {by.replace('_', ' ')}", rows, [by.replace("_", " "), "value", "design", "note"],
                          ["left", "right", "left", "left"])]
    if n_censored:
        notes.append(Note(f"{n_censored} of {int(ds['status'].size)} designs are stable up to thrust_max: their "
                          f"{by.replace('_', ' ')} is only known to be at least the search limit. Raise "
                          "analysis.thrust_max to rank them."))
    return Section("best", TITLES["best"], blocks=tuple(blocks + notes), data={"best": picks, "by": by})


def _statistics(provider, result, target: float | None) -> tuple[object, str]:
    """The provider's statistics at the required margin, and a note of what had to be left out.

    At the default margin 1 a study whose search ends below the operating thrust has no
    probability to give (as ``impstab stats``); a study too small for sensitivity indices gets
    its statistics without them, and the note says why.
    """
    from ...errors import ModelError

    def compute(**kw):
        if target is not None:
            return provider(result, target, **kw)
        try:
            return provider(result, 1.0, **kw)
        except ModelError as err:
            if err.field != "--target-margin":
                raise
            return provider(result, None, **kw)

    try:
        return compute(), ""
    except ModelError as err:
        try:
            stats = compute(sensitivity=False)
        except (ModelError, TypeError):
            raise err from None
        return stats, f"sensitivity indices not computed: {err}"


def _draw_statistics(stats):
    """The statistics figure on the page's width: the distribution, its ECDF and (when computed)
    the sensitivity indices one above the other, each panel as wide as the page (their legends
    need the room)."""
    import matplotlib.pyplot as plt

    if not hasattr(stats, "main"):                       # another kind of statistics: its own figure
        return stats.plot()
    sens = getattr(stats, "sensitivity", None)
    heights = [3.6, 3.6] + ([1.0 + 0.5 * len(getattr(sens, "parameters", ()))] if sens is not None else [])
    fig, axes = plt.subplots(len(heights), 1, figsize=(8.4, sum(heights) + 0.3), layout="constrained",
                             gridspec_kw={"height_ratios": heights})
    return stats.plot(ax=list(axes))


def statistics_section(ctx: StudyContext) -> Section:
    title = TITLES["statistics"]
    stats = ctx.options.statistics
    if stats is None:
        if ctx.sampling not in SAMPLED:
            return Section("statistics", title, NOT_COMPUTED,
                           f"a {ctx.sampling} study is not a sample of a distribution: statistics need random, "
                           "Sobol or Saltelli sampling")
        provider, reason = find_provider("statistics")
        if provider is None:
            return Section("statistics", title, NOT_COMPUTED, reason)
        stats, left_out = _statistics(provider, ctx.result, ctx.options.target_margin)
    else:
        left_out = ""
    blocks: list = []
    if hasattr(stats, "summary_rows"):
        blocks.append(table("uncertainty statistics", stats.summary_rows(), ["quantity", "value"]))
    elif hasattr(stats, "_repr_html_"):
        blocks.append(Table(stats._repr_html_()))
    if hasattr(stats, "percentiles"):
        rows = []
        for quantity in ("critical_thrust", "margin"):
            if getattr(stats, quantity, None) is not None:
                rows += [[quantity.replace("_", " "), f"{p.percent:g}", p.text(), p.interval_text()]
                         for p in stats.percentiles(quantity)]
        if rows:
            level = getattr(stats, "confidence", 0.95)
            blocks.append(table(f"percentiles with their {100 * level:g} % intervals", rows,
                                ["quantity", "percent", "value", "interval"], ["left", "right", "right", "right"]))
    sens = getattr(stats, "sensitivity", None)
    if sens is not None and hasattr(sens, "_repr_html_"):
        blocks.append(Table(sens._repr_html_(), wide=True))
    if hasattr(stats, "plot"):
        blocks.append(Figure(draw_svg(lambda: _draw_statistics(stats), "statistics"),
                             "Distribution of the critical thrust or margin over the computed designs (censored "
                             "designs apart), its empirical distribution function with the confidence band, and "
                             "the sensitivity indices when computed."))
    blocks += [Note(str(n)) for n in getattr(stats, "notes", ())]
    if left_out:
        blocks.append(Note(left_out))
    return Section("statistics", title, blocks=tuple(blocks), data={"statistics": stats})
