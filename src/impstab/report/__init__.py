"""The HTML report: one self-contained page of a model or a design study for a design review.

>>> import impstab
>>> rep = impstab.report("examples/imp_isolation.toml", "isolation-report.html")   # doctest: +SKIP
>>> rep.sections, rep.provenance.sha256                                              # doctest: +SKIP

The page has inline CSS and inline SVG figures, no script and nothing it fetches; every user
string is escaped. A section is computed, "not computed" (with the reason: no operating thrust,
an analysis this installation lacks) or "failed" (with the message); see ``docs/report.md``.

``impstab.report`` is this module and can be called: ``impstab.report(source, path, ...)`` is
:func:`impstab.report.api.report`.
"""

from __future__ import annotations

import sys
import types

from .analyses import PROVIDERS
from .api import SECTION_NAMES, report
from .result import Figure, Note, Provenance, Report, Section, Table

__all__ = ["report", "Report", "Section", "Figure", "Table", "Note", "Provenance", "SECTION_NAMES", "PROVIDERS"]


class _CallableModule(types.ModuleType):
    """The package ``impstab.report``, callable as the function :func:`report` (the attribute
    ``impstab.report`` is this module once it is imported, so the two must be one object)."""

    def __call__(self, *args, **kwargs) -> Report:
        return report(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
