"""The sections of a report, in page order: one builder each, ``builder(context) -> Section``.

A builder computes what its section shows (or takes it from the context, where several
sections share an analysis) and returns tables, figures and notes; one that cannot apply to
the input returns a section marked "not computed" with the reason.
"""

from .context import ModelContext, ReportOptions
from .titles import TITLES
from .isolation import isolation_section
from .model import modes_section, static_section, summary_section
from .postcritical import postcritical_section
from .simulation import simulation_section
from .stability import locus_section, stability_section
from .study import StudyContext, best_section, maps_section, statistics_section, status_section, study_section

__all__ = ["MODEL_SECTIONS", "STUDY_SECTIONS", "TITLES", "ModelContext", "StudyContext", "ReportOptions"]

#: sections of a model report, in page order
MODEL_SECTIONS = {
    "summary": summary_section,
    "static": static_section,
    "modes": modes_section,
    "stability": stability_section,
    "locus": locus_section,
    "simulation": simulation_section,
    "isolation": isolation_section,
    "postcritical": postcritical_section,
}
#: sections of a study report, in page order
STUDY_SECTIONS = {
    "study": study_section,
    "status": status_section,
    "maps": maps_section,
    "best": best_section,
    "statistics": statistics_section,
}
