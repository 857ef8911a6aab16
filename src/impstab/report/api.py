"""``impstab.report``: a self-contained HTML report of a model or of a design study."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Iterable

import numpy as np

from ..display.format import number
from ..errors import ModelError
from .provenance import make_provenance
from .render import printable, render_page
from .result import COMPUTED, FAILED, Report, Section
from .sections import MODEL_SECTIONS, STUDY_SECTIONS, TITLES, ModelContext, ReportOptions, StudyContext
from .tables import table

__all__ = ["report", "SECTION_NAMES"]

#: the sections ``sections=`` (``--sections``) chooses from, for a model and for a study
SECTION_NAMES = {"model": tuple(MODEL_SECTIONS) + ("provenance",), "study": tuple(STUDY_SECTIONS) + ("provenance",)}
_INPUT = "MODEL_OR_STORE"


def report(
    source,
    path: str | os.PathLike[str] | None = None,
    *,
    sections: Iterable[str] | None = None,
    simulation: bool = True,
    title: str | None = None,
    duration: float | None = None,
    frequencies=None,
    steps: int = 200,
    postcritical=None,
    statistics=None,
    target_margin: float | None = None,
    command: str | None = None,
) -> Report:
    """A self-contained HTML report of a model or a design study.

    Parameters
    ----------
    source : str, path, Model or StudyResult
        A model file (``.toml``), a study store (the folder ``impstab sweep`` writes) or its
        ``.nc`` export, or the object itself.
    path : str or path, optional
        Also save the page there (``.html``; written under a temporary name, then renamed).
    sections : iterable of str, optional
        The sections to include, by name (:data:`SECTION_NAMES`); default all. The provenance
        section is always included.
    simulation : bool
        Run the time histories (False: a faster report; the section says it was left out).
    title : str, optional
        Page title; default from the model's or study's name.
    duration : float, optional
        Length of each time history (s); default: long enough for the supercritical run to grow
        by e^3 at its linear rate, within 40 to 400 periods of the onset frequency.
    frequencies : array_like, optional
        Frequencies (Hz) of the transmissibility; default a band from the natural frequencies.
    steps : int
        Thrust intervals of the locus.
    postcritical, statistics : result, optional
        A post-critical result or study statistics computed beforehand (see
        :mod:`impstab.report.analyses`), shown instead of computing them.
    target_margin : float, optional
        Required margin of a sampled study: the statistics give the probability of a margin below
        it; default 1 (an instability at the operating thrust), when the search reaches it.
    command : str, optional
        The command line to record in the provenance (the CLI passes its own).

    Returns
    -------
    Report
        ``.html`` (the page), ``.sections``, ``.provenance``; ``.save(path)``.
    """
    kind, obj, origin, described = _open(source)
    names = _chosen(kind, sections)
    if duration is not None and not (np.isfinite(float(duration)) and float(duration) > 0):
        raise ModelError("duration", duration, "must be a finite number of seconds > 0")
    if not isinstance(steps, (int, np.integer)) or isinstance(steps, bool) or not 1 <= steps <= 100000:
        raise ModelError("steps", steps, "must be an integer between 1 and 100000")
    if target_margin is not None and not (np.isfinite(float(target_margin)) and float(target_margin) > 0):
        raise ModelError("target_margin", target_margin, "must be a finite number > 0")
    if frequencies is not None:
        from ..response.api import check_frequencies

        frequencies = check_frequencies(frequencies)
    options = ReportOptions(simulation=bool(simulation), duration=None if duration is None else float(duration),
                            frequencies=frequencies, steps=int(steps), postcritical=postcritical, statistics=statistics,
                            target_margin=None if target_margin is None else float(target_margin))
    prov = make_provenance(origin, described, command or _python_call(source, path, sections, simulation))
    if kind == "model":
        from .._jit import require_compiled

        require_compiled()  # a model's report computes loci, time histories and cycles: seconds of kernel time
        ctx = ModelContext(obj, options)
        builders = MODEL_SECTIONS
        name = obj.name
        default_title = f"{name}: stability report"
    else:
        ctx = StudyContext(obj, options)
        builders = STUDY_SECTIONS
        name = str(obj.dataset.attrs.get("study_name", ""))
        default_title = f"{name}: design study report"
    built = [_build(builders[n], ctx, n) for n in builders if n in names]
    built.append(_provenance_section(prov, options, names, kind))
    page_title = printable(title) if title is not None else default_title
    html = render_page(
        title=page_title, kind=kind, subtitle=f"{prov.input} · {prov.generated_utc}",
        facts=_model_facts(built) if kind == "model" else _study_facts(built),
        sections=built, provenance=prov,
    )
    rep = Report(html, page_title, kind, tuple(built), prov)
    if path is not None:
        rep.save(path)
    return rep


def _open(source):
    """``(kind, object, file or folder or None, description of the input)``."""
    from ..model.model import Model
    from ..studies.result import StudyResult

    if isinstance(source, Model):
        src = source.source if source.source and Path(source.source).is_file() else None
        what = "model object, read from this file (hashed when the report was made)" if src else "model object"
        return "model", _printable_model(source), src, what
    if isinstance(source, StudyResult):
        src = source.store if source.store and Path(source.store).exists() else None
        return "study", _printable_study(source), src, "study result, from this store" if src else "study result"
    if not isinstance(source, (str, os.PathLike)):
        raise ModelError(_INPUT, type(source).__name__, "must be a model file, a study store, a Model or a StudyResult")
    p = Path(source)
    if not p.exists():
        raise ModelError(_INPUT, str(p), "does not exist")
    if p.is_dir() or p.suffix.lower() == ".nc":
        from ..studies.result import open_study

        return "study", _printable_study(open_study(p)), p, "study store" if p.is_dir() else "study export (netCDF)"
    if p.suffix.lower() != ".toml":
        raise ModelError(_INPUT, str(p), "must be a model file (.toml), a study store (a folder written by "
                                         "'impstab sweep') or its .nc export")
    _refuse_study_file(p)
    from ..model import load_model

    return "model", _printable_model(load_model(p)), p, "model file"


def _refuse_study_file(p: Path) -> None:
    """A study file is not a model: say what to run instead of listing its keys as unknown."""
    import tomllib

    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return  # load_model reports what is wrong with the file
    if isinstance(data.get("model"), str) and "parameters" in data:
        raise ModelError(_INPUT, str(p), "is a study file: run 'impstab sweep' on it, then report on its store")


def _printable_model(model):
    name = printable(model.name)
    return model if name == model.name else model.with_(name=name)


def _printable_study(result):
    from ..studies.result import StudyResult

    attrs = result.dataset.attrs
    clean = {k: printable(attrs[k]) for k in ("study_name", "model_name", "model_path", "study_path") if k in attrs}
    if all(clean[k] == attrs[k] for k in clean):
        return result
    return StudyResult(result.dataset.assign_attrs(**clean), result.store)


def _chosen(kind: str, sections) -> tuple[str, ...]:
    allowed = SECTION_NAMES[kind]
    if sections is None:
        return allowed
    names = [sections] if isinstance(sections, str) else list(sections)
    for n in names:
        if n not in allowed:
            raise ModelError("sections", n, f"must be among the {kind} report's sections {list(allowed)}")
    return tuple(n for n in allowed if n in names)


def _build(builder, ctx, name: str) -> Section:
    """The section, or a failed one that says what went wrong (the rest of the report goes on)."""
    try:
        return builder(ctx)
    except Exception as exc:  # noqa: BLE001 - a report shows a failed analysis instead of losing the others
        return Section(name, TITLES.get(name, name), FAILED, printable(f"{type(exc).__name__}: {exc}"))


def _python_call(source, path, sections, simulation) -> str:
    args = [repr(str(source)) if isinstance(source, (str, os.PathLike)) else type(source).__name__]
    if path is not None:
        args.append(repr(str(path)))
    if sections is not None:
        args.append(f"sections={list([sections] if isinstance(sections, str) else sections)!r}")
    if not simulation:
        args.append("simulation=False")
    return printable(f"Python: impstab.report({', '.join(args)})")


def _provenance_section(prov, options: ReportOptions, names, kind: str) -> Section:
    rows = prov.rows()
    rows.append(("sections", ", ".join(names)))
    if kind == "model":
        rows.append(("time histories", "run" if options.simulation else "left out"))
        if options.duration is not None:
            rows.append(("time-history length", f"{number(options.duration)} s"))
    return Section("provenance", "Provenance", blocks=(table("what produced this report", rows),),
                   data={"provenance": prov})


def _data(sections, key):
    for s in sections:
        if s.status == COMPUTED and key in s.data:
            return s.data[key]
    return None


def _model_facts(sections) -> list[tuple[str, str, str]]:
    facts = []
    crit = _data(sections, "critical")
    if crit is not None:
        if crit.thrust is None:
            facts.append(("critical thrust", f"none up to {number(crit.thrust_max)} N", "censored"))
        else:
            facts.append(("critical thrust", f"{number(crit.thrust)} N, {crit.kind}"
                          + (f" at {number(crit.frequency_hz, 4)} Hz" if crit.omega else ""), ""))
        if crit.margin is not None:
            facts.append(("margin (critical / operating)", number(crit.margin, 4), "bad" if crit.margin < 1 else ""))
        elif crit.operating_thrust:
            facts.append(("margin (critical / operating)",
                          f"> {number(crit.thrust_max / crit.operating_thrust, 4)} (stable up to thrust_max)", "censored"))
        if crit.undamped_thrust != crit.thrust:
            facts.append(("undamped critical thrust", number(crit.undamped_thrust, 6, "N", missing="none up to thrust_max"), ""))
    modal = _data(sections, "modal")
    if modal is not None:
        facts.append((f"at T = {number(modal.thrust)} N", "stable" if modal.stable else "UNSTABLE",
                      "" if modal.stable else "bad"))
    st = _data(sections, "static")
    if st is not None and np.isfinite(st.utilisation).any():
        j = int(np.nanargmax(st.utilisation))
        u = float(st.utilisation[j])
        facts.append(("largest static mount use", f"{100 * u:.0f} % (mount {j})", "bad" if u > 1 else ""))
    return facts


def _study_facts(sections) -> list[tuple[str, str, str]]:
    facts = []
    counts = _data(sections, "counts")
    if counts is not None:
        total = sum(counts.values())
        facts.append(("designs", f"{total} ({counts.get('ok', 0)} computed)", ""))
        failed = total - counts.get("ok", 0) - counts.get("not_computed", 0)
        if failed:
            facts.append(("failed designs", str(failed), "bad"))
    study = _data(sections, "study")
    if study is not None and "kind" in study.dataset:
        ds = study.dataset
        n = int(np.count_nonzero((ds["kind"].values == 0) & (ds["status"].values == 0)))
        facts.append(("stable up to thrust_max (censored)", str(n), "censored" if n else ""))
    best = _data(sections, "best")
    if best:
        by = _data(sections, "by")
        first = next(iter(best.values()))
        bound = first["lower_bound"]
        value = number(first["value"], 4) if by == "margin" else number(first["value"], 6, "N")
        facts.append((f"largest {by.replace('_', ' ')}", (">= " if bound else "") + value
                      + (" (censored at thrust_max)" if bound else ""), "censored" if bound else ""))
    return facts
