"""Design studies: thousands to millions of model variants, batched, resumable, on Dask if wanted.

A study file names a base model, the model-file values to vary (``mount_rings[0].k_shear``, ...)
and how (a grid, random or Sobol samples); :func:`run_study` evaluates every variant's critical
thrust in batches, in process or on a Dask cluster, into a zarr store that a rerun resumes::

    from impstab.studies import load_study, run_study, open_study

    result = run_study(load_study("examples/study_mounts.toml"), "mounts.zarr")
    result.best("margin", where=result.dataset["kind"] == 1)["parameters"]
    result.plot(x="mount_rings[0].x", y="mount_rings[0].k_shear", value="margin")

See ``docs/studies.md`` for a walkthrough.
"""

from .execute import run_study
from .result import StudyResult, open_study
from .study import Parameter, Study, load_study, study_from_dict

__all__ = ["load_study", "study_from_dict", "run_study", "open_study", "Study", "Parameter", "StudyResult"]
