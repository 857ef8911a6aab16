"""Saving figures: PNG, SVG or PDF by the file's suffix, written atomically."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import ModelError
from .style import DEFAULT_DPI, figure_style

__all__ = ["FIGURE_FORMATS", "save_figure", "check_figure_path"]

#: file suffixes a figure can be saved as
FIGURE_FORMATS = (".png", ".svg", ".pdf")


def check_figure_path(path: str | os.PathLike[str], flag: str = "--output") -> Path:
    """``path`` as a Path if it ends in a figure format; ModelError naming ``flag`` otherwise."""
    p = Path(path)
    if p.suffix.lower() not in FIGURE_FORMATS:
        raise ModelError(flag, str(path), "must end in .png, .svg or .pdf")
    return p


def save_figure(fig, path: str | os.PathLike[str], dpi: float | None = None, flag: str = "--output") -> Path:
    """Write ``fig`` to ``path`` (format from the suffix; ``dpi`` for PNG, default
    :data:`DEFAULT_DPI`); a temporary name is renamed on success, so no partial file is left."""
    from ..io import atomic_path

    p = check_figure_path(path, flag)
    if dpi is not None and not (dpi > 0 and dpi <= 2400):
        raise ModelError("--dpi", dpi, "must be between 1 and 2400")
    with figure_style(), atomic_path(p) as tmp:
        fig.savefig(tmp, format=p.suffix.lower().lstrip("."), dpi=dpi or DEFAULT_DPI,
                    metadata=_metadata(p.suffix.lower()))
    return p


def _metadata(suffix: str) -> dict:
    from .. import __version__

    creator = f"impstab {__version__}"
    if suffix == ".png":
        return {"Software": creator}
    if suffix == ".svg":
        return {"Creator": creator, "Date": None}      # no date: the same figure gives the same file
    return {"Creator": creator, "CreationDate": None}
