"""Matplotlib figures as inline SVG for an HTML page.

The figure is drawn by the result's own ``.plot()`` inside :func:`impstab.plot.style.figure_style`
and saved as SVG with text kept as text (searchable, and the page's own fonts), no date and no
metadata block. Several SVG documents in one page share one id space: every ``id`` and every
reference to it (``url(#...)``, ``href="#..."``) gets the figure's own prefix, so that no clip
path or marker of one figure is taken for another's.
"""

from __future__ import annotations

import io
import re
from typing import Callable

__all__ = ["figure_svg", "draw_svg", "mathtext_safe"]

_HEADER = re.compile(r"^.*?(?=<svg\b)", re.S)
_METADATA = re.compile(r"<metadata>.*?</metadata>\s*", re.S)
_ID = re.compile(r'\bid="([^"]+)"')
_URL = re.compile(r"url\(#([^)]+)\)")
_HREF = re.compile(r'(xlink:href|href)="#([^"]+)"')
_SIZE = re.compile(r'<svg\b([^>]*?)\swidth="([\d.]+)pt"\s+height="([\d.]+)pt"')


def mathtext_safe(text: str) -> str:
    """``text`` with its dollar signs escaped, so that matplotlib draws it as it is (a name with
    two ``$`` would otherwise be read as mathematics, or fail to parse)."""
    return text.replace("$", r"\$")


def figure_svg(fig, prefix: str) -> str:
    """The ``<svg>`` element of ``fig`` with its ids prefixed by ``prefix`` (closes nothing)."""
    from ..plot.style import figure_style

    buf = io.StringIO()
    with figure_style():
        import matplotlib

        with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": prefix}):
            fig.savefig(buf, format="svg", metadata={"Date": None})
    text = _METADATA.sub("", _HEADER.sub("", buf.getvalue(), count=1), count=1)
    text = _ID.sub(lambda m: f'id="{prefix}-{m.group(1)}"', text)
    text = _URL.sub(lambda m: f"url(#{prefix}-{m.group(1)})", text)
    text = _HREF.sub(lambda m: f'{m.group(1)}="#{prefix}-{m.group(2)}"', text)
    # natural size as a maximum; the page scales the figure down to its column, never up
    text = _SIZE.sub(lambda m: (f'<svg{m.group(1)} role="img" class="figure" width="{m.group(2)}pt" '
                                f'height="{m.group(3)}pt" style="max-width:100%;height:auto"'), text, count=1)
    return text.strip()


def draw_svg(draw: Callable[[], object], prefix: str) -> str:
    """Call ``draw()`` (returns Axes, a tuple of Axes or a Figure) and return its figure as
    inline SVG; every figure it opened is closed whatever happens (nothing is shown)."""
    import matplotlib.pyplot as plt

    from ..plot.style import figure_style

    before = set(plt.get_fignums())
    try:
        with figure_style():
            handle = draw()
        fig = _figure_of(handle)
        return figure_svg(fig, prefix)
    finally:
        for num in set(plt.get_fignums()) - before:
            plt.close(num)


def _figure_of(handle):
    from matplotlib.figure import Figure

    if isinstance(handle, Figure):
        return handle
    if hasattr(handle, "figure"):
        return handle.figure
    first = handle[0]
    while not hasattr(first, "figure"):
        first = first[0]
    return first.figure
