"""Text and HTML views of models and results, for the terminal and for notebooks.

Every model and result object prints as one concise line (``repr``), its numbers with units
and no array dumps; the main ones also render as an HTML table in Jupyter (``_repr_html_``).
The classes call the functions here, so that what an engineer sees is written in one place.
User strings (model and study names) are escaped in HTML.
"""

from .html import (  # noqa: F401
    batch_html,
    critical_html,
    locus_html,
    modal_html,
    model_html,
    simulation_html,
    study_html,
)
from .text import (  # noqa: F401
    batch_text,
    body_text,
    critical_load_text,
    critical_text,
    fluid_coefficients_text,
    fluid_loading_text,
    hull_text,
    linear_system_text,
    locus_text,
    modal_form_text,
    modal_text,
    model_text,
    mount_text,
    parameter_text,
    simulation_text,
    study_definition_text,
    study_text,
    sweep_text,
    thrust_text,
)
