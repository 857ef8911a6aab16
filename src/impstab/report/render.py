"""The page: jinja2 templates with autoescaping, user strings made printable.

Every string from the user (model and study names, file names, messages) reaches the page
through the template's autoescaping (``<``, ``&``, quotes become entities) after
:func:`printable` has written control characters (terminal escapes such as ESC, bidirectional
overrides) as visible escapes. Tables are built by :func:`impstab.display.html.html_table`, which
escapes every cell, and figures are SVG written by matplotlib, which escapes its text; only
those two are inserted as markup.
"""

from __future__ import annotations

import re
from functools import lru_cache

__all__ = ["printable", "render_page"]

def _escape(ch: str) -> str:
    code = ord(ch)
    if code < 0x100:
        return f"\\x{code:02x}"
    if code < 0x10000:
        return f"\\u{code:04x}"
    return f"\\U{code:08x}"


def printable(text) -> str:
    """``text`` with every character Python does not count as printable (``str.isprintable``:
    controls such as ESC and line feeds, bidirectional overrides and other format characters,
    separators, surrogates) written as its Python escape (``\\x1b``, ``\\u202e``): what a
    terminal or a browser would act on, shown instead."""
    s = text if isinstance(text, str) else str(text)
    if s.isprintable():
        return s
    return "".join(ch if ch.isprintable() else _escape(ch) for ch in s)


@lru_cache(maxsize=1)
def _environment():
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("impstab.report", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )
    env.filters["printable"] = printable
    env.filters["anchor"] = lambda name: re.sub(r"[^a-z0-9-]+", "-", str(name).lower())
    return env


def render_page(**context) -> str:
    """The report page from ``report.html.j2`` (see the template for the names it uses)."""
    from markupsafe import Markup

    from .result import Figure, Note, Table

    def block(b):
        if isinstance(b, Table):
            return Markup(f'<div class="table-wrap{" wide" if b.wide else ""}">') + Markup(b.html) + Markup("</div>")
        if isinstance(b, Figure):
            cap = Markup("<figcaption>{}</figcaption>").format(printable(b.caption)) if b.caption else Markup("")
            return Markup("<figure>") + Markup(b.svg) + cap + Markup("</figure>")
        if isinstance(b, Note):
            return Markup('<p class="{}">{}</p>').format(b.kind, printable(b.text))
        raise TypeError(f"unknown report block {type(b).__name__}")

    env = _environment()
    return env.get_template("report.html.j2").render(block=block, **context)
