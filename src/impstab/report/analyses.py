"""Optional analyses a report shows when impstab offers them: the hooks.

Two sections come from analyses that live outside the report and may be missing from an
installation: the propulsor's post-critical analysis (:mod:`impstab.postcritical`) and the
uncertainty statistics of a sampled study. Each is found through :data:`PROVIDERS`, a
``"module:function"`` name: the function is called with the model (or the study result) and
returns a result object, and the section is drawn from that object alone:

* **post-critical** (``PROVIDERS["postcritical"]``, called as ``f(model)``): an object whose
  ``to_dict()`` has the keys of ``impstab postcritical --json`` (DESIGN.md: ``critical_thrust``,
  ``kind``, ``omega``, ``lyapunov_coefficient``, ``bifurcation``, ``fold_thrust``, ``branch``)
  and whose ``plot(ax=None)`` draws the bifurcation diagram;
* **statistics** (``PROVIDERS["statistics"]``, called as ``f(study_result, target_margin)``,
  :func:`impstab.studies.statistics.study_statistics`): an object with ``summary_rows()``
  (``(quantity, value)`` text pairs) or ``_repr_html_()``, and ``plot(ax=None)``; its
  ``percentiles(quantity)``, ``sensitivity`` and ``notes`` are shown when it has them.

A result can also be handed to :func:`impstab.report` directly (``postcritical=``,
``statistics=``), computed with settings of one's own. When the provider does not exist, the
section says "not computed" and why; when it fails, "failed" with the message.
"""

from __future__ import annotations

from importlib import import_module
from typing import Callable

__all__ = ["PROVIDERS", "find_provider"]

#: where the optional analyses are found: section -> "module:function"
PROVIDERS: dict[str, str] = {
    "postcritical": "impstab.postcritical:propulsor_postcritical",
    "statistics": "impstab.studies.statistics:study_statistics",
}

_ABSENT = {
    "postcritical": ("impstab.postcritical offers no post-critical analysis of a propulsor model in this "
                     "version (only the generic Hopf and cycle machinery for x' = f(x, p)); "
                     "the section is filled once {name} exists"),
    "statistics": "this version of impstab has no uncertainty statistics of studies ({name} is missing)",
}


def find_provider(section: str) -> tuple[Callable | None, str]:
    """``(function, "")`` for the analysis of ``section``, or ``(None, reason)`` when this
    installation does not have it."""
    name = PROVIDERS[section]
    module, _, attr = name.partition(":")
    try:
        func = getattr(import_module(module), attr, None)
    except ModuleNotFoundError as exc:
        if exc.name is None or not (module == exc.name or module.startswith(exc.name + ".")):
            raise                      # the module exists but lacks one of its own imports: say so
        func = None
    if func is None:
        return None, _ABSENT[section].format(name=name.replace(":", "."))
    return func, ""
