"""Draw the trade-off figures of docs/isolation.md and docs/optimize.md:
``python docs/figures/make_tradeoff_figures.py``.

isolation-tradeoff.png: every design of examples/study_isolation.toml, the shaft-band
transmissibility against the margin, the Pareto front, the required margin 4 and the static
limits; isolation-optimize.png: what ``impstab optimize examples/optimize_isolation.toml`` draws.
"""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

from impstab.optimize.problem import load_optimization  # noqa: E402
from impstab.optimize.run import run_optimization  # noqa: E402
from impstab.plot.save import save_figure  # noqa: E402
from impstab.studies import load_study, run_study  # noqa: E402

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parents[1] / "examples"

study = run_study(load_study(EXAMPLES / "study_isolation.toml"))
ax = study.plot_tradeoff("t_shaft_band", required_margin=4.0, deflection_limit=0.008, load_limit=1000.0)
save_figure(ax.figure, HERE / "isolation-tradeoff.png", 130)

res = run_optimization(load_optimization(EXAMPLES / "optimize_isolation.toml"))
save_figure(res.plot().figure, HERE / "isolation-optimize.png", 130)
print(res.chosen)
