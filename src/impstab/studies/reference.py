"""Units and descriptions of every study-file key, beside the schema (:mod:`impstab.studies.schema`).

Joined with the schema by :mod:`impstab.model.schema_doc` into ``docs/study-file.md`` and the JSON
Schema of ``impstab schema --study``; a test keeps this table in step with the schema.
"""

from __future__ import annotations

from ..model.schema_doc import RefEntry as E
from .schema import OUTPUTS

__all__ = ["STUDY_REFERENCE", "TITLE", "INTRO", "DOC_PATH", "markdown_page", "json_schema_document"]

DOC_PATH = "docs/study-file.md"
TITLE = "Study-file reference"

_outputs = "; ".join(f"`{k}`" + (f" ({u})" if u else "") + f": {d}" for k, (u, d) in OUTPUTS.items())

STUDY_REFERENCE: dict[str, E] = {
    "schema_version": E("", "Version of the file format; this impstab reads 1."),
    "name": E("", "Name of the study in tables, figures and the store; default: the file name without .toml."),
    "model": E("", "The base model file, relative to the study file; every design is this model with the "
               "parameters changed."),
    "outputs": E("", f"What is stored for every design: {_outputs}."),
    "parameters": E("", "One table per varied model-file value (at most 32). A grid has one dimension per "
                    "parameter; random, sobol and saltelli sampling draw every parameter for each sample."),
    "parameters[].path": E("", "Dotted path of the value in the model file: keys joined by '.', list entries by "
                           "[index], e.g. mount_rings[0].k_shear, mounts[2].position[1], thrust.operating. It must "
                           "end at one number, integer, flag or word (see docs/model-file.md for the keys and "
                           "their units); schema_version and name cannot be varied."),
    "parameters[].values": E("the path's unit", "The values: a range table {start, stop, num, scale} (a grid of num "
                             "values; with random, sobol or saltelli sampling and no num, a uniform or log-uniform range) "
                             "or a list of values (a grid axis, or values drawn with equal probabilities). Each "
                             "value is checked by the rule of its model-file key."),
    "parameters[].values.start": E("the path's unit", "First value of the range."),
    "parameters[].values.stop": E("the path's unit", "Last value of the range (included)."),
    "parameters[].values.num": E("", "Number of grid values from start to stop; grid sampling only."),
    "parameters[].values.scale": E("", "\"linear\": equal steps; \"log\": geometric steps (start and stop > 0), "
                                   "log-uniform when sampled."),
    "parameters[].distribution": E("", "A probability distribution of the value, instead of values (random, sobol "
                                   "and saltelli sampling only)."),
    "parameters[].distribution.kind": E("", "\"uniform\" and \"loguniform\" (low, high); \"normal\" (mean, std); "
                                        "\"lognormal\" (median, sigma of the logarithm); \"truncnormal\" (mean, std, "
                                        "low, high)."),
    "parameters[].distribution.low": E("the path's unit", "Lower end (uniform, loguniform, truncnormal)."),
    "parameters[].distribution.high": E("the path's unit", "Upper end (uniform, loguniform, truncnormal)."),
    "parameters[].distribution.mean": E("the path's unit", "Mean (normal; of the untruncated normal for truncnormal)."),
    "parameters[].distribution.std": E("the path's unit", "Standard deviation (normal, truncnormal)."),
    "parameters[].distribution.median": E("the path's unit", "Median (lognormal)."),
    "parameters[].distribution.sigma": E("1", "Standard deviation of the natural logarithm (lognormal): 0.2 is "
                                         "about 20 % scatter."),
    "sampling": E("", "How the designs are chosen."),
    "sampling.method": E("", "\"grid\": every combination of the parameters' values; \"random\": independent "
                         "draws; \"sobol\": a scrambled Sobol sequence (use a power of two for n); \"saltelli\": "
                         "Saltelli's cross-sampled design for first-order and total Sobol indices (impstab stats), "
                         "n base samples giving n * (d + 2) designs for d parameters."),
    "sampling.n": E("", "Number of samples (random and sobol), or of base samples (saltelli: n * (d + 2) designs); "
                    "not used by a grid."),
    "sampling.seed": E("", "Seed of the random, Sobol and Saltelli samples: the samples follow from the study file "
                       "alone."),
    "isolation": E("", "How the isolation outputs are evaluated (peak_transmissibility, peak_frequency_hz, "
                   "static_deflection, peak_mount_load and the named [[isolation.at]] outputs): each design is "
                   "linearized at the isolation thrust like impstab response, all designs of a chunk solved "
                   "together. See docs/isolation.md."),
    "isolation.input": E("", "Dof of the unit harmonic load at A (a force on surge/sway/heave, a moment on "
                         "roll/pitch/yaw); default: each design's excitation.input (sway)."),
    "isolation.thrust": E("N", "Thrust of the linearization and of the static loads; default: each design's "
                          "operating thrust, else 0."),
    "isolation.range_hz": E("Hz", "[low, high], 0 < low < high: the range of peak_transmissibility and "
                            "peak_frequency_hz, on a log-spaced grid of points frequencies (a grid value: a "
                            "resonance narrower than the spacing is underestimated)."),
    "isolation.points": E("", "Frequencies of the log-spaced grid over range_hz."),
    "isolation.at": E("", "Named isolation outputs (at most 64), each stored as an output of its own name "
                      "(not listed in outputs)."),
    "isolation.at[].name": E("", "Output name: a lower-case identifier, different from every other output."),
    "isolation.at[].frequency_hz": E("Hz", "Store the force transmissibility |F_hull| / |F_in| at this frequency."),
    "isolation.at[].band_hz": E("Hz", "[low, high]: store the largest transmissibility over this band (64 "
                                "log-spaced frequencies, edges included). Give frequency_hz or band_hz."),
    "execution": E("", "How the work is cut up."),
    "execution.chunk_size": E("", "Designs computed, written and resumed together (the unit of work of a Dask "
                              "worker and of resuming)."),
}

INTRO = """
Every key of an impstab study file (TOML, `schema_version = 1`), generated from the schema
(`src/impstab/studies/schema.py`) and the table of units and descriptions beside it
(`src/impstab/studies/reference.py`): `impstab schema --study --markdown` prints this page, and a
test keeps it equal to the schema. A study varies values of a model file (their keys and units
are in `docs/model-file.md`); the walkthrough is `docs/studies.md`. Unknown keys are errors,
reported with the nearest valid key. `impstab schema --study -o impstab-study.schema.json`
writes a JSON Schema for TOML editors (see `docs/model-file.md`, "Editor support").
"""


def markdown_page() -> str:
    """The text of ``docs/study-file.md``."""
    from ..model.schema_doc import markdown
    from .schema import StudyFile

    return markdown(StudyFile, STUDY_REFERENCE, title=TITLE, intro=INTRO)


def json_schema_document() -> dict:
    """The JSON Schema (draft-07) of study files, with units and descriptions."""
    from ..model.schema_doc import json_schema
    from .schema import StudyFile

    doc = json_schema(StudyFile, STUDY_REFERENCE, title="impstab study file (schema_version 1)", doc_url=DOC_PATH)
    doc["properties"]["schema_version"]["const"] = 1
    return doc
