"""One style for every impstab figure, applied while drawing (an ``rc_context``), never at import."""

from __future__ import annotations

import contextlib
from typing import Iterator

__all__ = ["STYLE", "figure_style", "PALETTE", "ONSET_COLOR", "DEFAULT_DPI"]

#: dots per inch of saved raster figures when no ``--dpi`` is given
DEFAULT_DPI = 150
#: colours of branches and runs (a colour-blind-safe qualitative set without the onset red)
PALETTE = ("#0072B2", "#E69F00", "#009E73", "#CC79A7", "#56B4E9", "#8C564B", "#F0E442", "#7F7F7F", "#000000")
#: the onset of instability, everywhere
ONSET_COLOR = "#D55E00"

STYLE = {
    "font.size": 9.5,
    "axes.titlesize": "medium",
    "axes.labelsize": "medium",
    "legend.fontsize": "small",
    "legend.title_fontsize": "small",
    "legend.frameon": False,
    "axes.grid": True,
    "grid.alpha": 0.35,
    "grid.linewidth": 0.6,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "axes.formatter.useoffset": False,      # no offset labels that collide with titles
    "axes.formatter.limits": (-5, 7),       # plain numbers from 1e-5 to 1e7: no "x 10^5" label
    # plain-text tick labels: with the two settings above no offset or multiplier label is left
    # that mathtext would typeset, and typesetting every tick number through it cost 5-8 ms a
    # distinct label (1.6 s of a 10.6 s report); log axes keep their mathtext powers of ten
    "axes.formatter.use_mathtext": False,
    "lines.linewidth": 1.4,
    "image.cmap": "viridis",
    "svg.fonttype": "none",                 # text stays text in SVG (small, searchable)
    "pdf.fonttype": 42,                     # TrueType fonts embedded in PDF (editable)
    "savefig.bbox": "tight",
    "savefig.pad_inches": 0.05,
}


@contextlib.contextmanager
def figure_style() -> Iterator[None]:
    """Context in which impstab draws: :data:`STYLE` over the user's rcParams."""
    import matplotlib

    with matplotlib.rc_context(STYLE):
        yield
