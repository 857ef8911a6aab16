"""Draw the figures of docs/isolation.md: ``python docs/figures/make_isolation_figures.py``.

isolation-response.png is what ``impstab response examples/imp_isolation.toml
--frequencies 0.5:300:3000 --excitation -o isolation-response.png`` writes; isolation-foundation.png
compares the rigid hull with a compliant one.
"""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import impstab  # noqa: E402
from impstab.cli import main  # noqa: E402
from impstab.model.foundation import Foundation  # noqa: E402
from impstab.plot.response import _hz_axis, _legend  # noqa: E402
from impstab.response import frequency_response  # noqa: E402

HERE = Path(__file__).resolve().parent
EXAMPLE = HERE.parents[1] / "examples" / "imp_isolation.toml"

main(["response", str(EXAMPLE), "--frequencies", "0.5:300:3000", "--excitation", "-o", str(HERE / "isolation-response.png")])

model = impstab.load_model(EXAMPLE)
f = np.geomspace(0.5, 300.0, 2000)
hull = Foundation("lumped", mass=20.0, stiffness=4.0e5, damping=300.0)   # a hull point: 22 Hz resonance
rigid = frequency_response(model, f, input="heave")
soft = frequency_response(model, f, input="heave", foundation=hull)

fig, (ax, axp) = plt.subplots(2, 1, figsize=(9.0, 7.5), layout="constrained", sharex=True)
rigid.plot(ax=ax)
ax.semilogx(f, soft.transmissibility_db, color="C3", lw=1.4, label="heave input, compliant hull")
ax.lines[0].set_label("heave input, rigid hull")
_legend(ax)
ax.set_xlabel("")
ax.set_title("rigid hull against a compliant hull point (20 kg, 4e5 N/m, 300 N s/m at each mount)", fontsize="medium")
axp.loglog(f, soft.power_transmitted.sum(axis=1), color="C3", label="into the hull")
axp.loglog(f, soft.power_damper.sum(axis=1), color="C2", label="dissipated in the mount dampers")
axp.loglog(f, soft.power_input, color="k", ls="--", lw=0.9, label="input (unit heave force)")
axp.set_xlabel("frequency (Hz)")
_hz_axis(axp, 0.5, 300.0)
axp.set_ylabel("time-averaged power (W)")
axp.grid(True, which="both", alpha=0.25)
axp.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="x-small", frameon=False)
fig.savefig(HERE / "isolation-foundation.png", dpi=110)
