"""Tables for the report: the package's HTML tables with every cell made printable first."""

from __future__ import annotations

import re

from ..display.html import html_table
from .render import printable
from .result import Table

__all__ = ["table"]


def table(title: str, rows, header=None, align=None) -> Table:
    """A :class:`~impstab.report.result.Table` of text cells (escaped by
    :func:`impstab.display.html.html_table`, control characters written as escapes)."""
    rows = [[printable(c) for c in r] for r in rows]
    header = None if header is None else [_unit_together(printable(h)) for h in header]
    return Table(html_table(printable(title), rows, header, align))


def _unit_together(text: str) -> str:
    """A header's unit in parentheses kept on one line (``(N s/m)`` is never split)."""
    return re.sub(r"\([^()]*\)", lambda m: m.group(0).replace(" ", "\u00a0"), text)
