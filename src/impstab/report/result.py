"""What a report is made of: sections of tables, figures and notes, its provenance, the page."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ModelError

__all__ = ["Report", "Section", "Figure", "Table", "Note", "Provenance", "COMPUTED", "NOT_COMPUTED", "FAILED",
           "REPORT_SUFFIXES"]

#: states of a section
COMPUTED, NOT_COMPUTED, FAILED = "computed", "not computed", "failed"
#: file suffixes a report is saved under
REPORT_SUFFIXES = (".html", ".htm")


@dataclass(frozen=True)
class Figure:
    """An inline SVG figure (its ids made unique in the page) and its caption (plain text)."""

    svg: str
    caption: str = ""


@dataclass(frozen=True)
class Table:
    """An HTML table whose cells were escaped where it was built (:func:`impstab.display.html.html_table`);
    ``wide`` gives it at least half the page's width (a long caption over few columns)."""

    html: str
    wide: bool = False


@dataclass(frozen=True)
class Note:
    """A sentence under a table or figure (plain text, escaped when the page is written);
    ``kind`` is ``"note"`` or ``"warning"``."""

    text: str
    kind: str = "note"


@dataclass(frozen=True)
class Section:
    """One section of a report.

    Attributes
    ----------
    name : str
        Its key (``"stability"``, ``"locus"``, ...): what ``--sections`` chooses.
    title : str
    status : {"computed", "not computed", "failed"}
    reason : str
        Why it was not computed, or what failed (empty when computed).
    blocks : tuple of Table, Figure and Note
        The content, in page order.
    data : dict
        The result objects the section was drawn from (``{"critical": CriticalThrust, ...}``),
        for a script that wants the numbers behind the page.
    """

    name: str
    title: str
    status: str = COMPUTED
    reason: str = ""
    blocks: tuple = ()
    data: dict = field(default_factory=dict, compare=False)

    @property
    def figures(self) -> tuple[Figure, ...]:
        return tuple(b for b in self.blocks if isinstance(b, Figure))

    @property
    def tables(self) -> tuple[Table, ...]:
        return tuple(b for b in self.blocks if isinstance(b, Table))

    @property
    def notes(self) -> tuple[Note, ...]:
        return tuple(b for b in self.blocks if isinstance(b, Note))

    def __repr__(self) -> str:
        what = f"{len(self.tables)} tables, {len(self.figures)} figures" if self.status == COMPUTED else self.reason
        return f"Section({self.name!r}: {self.status}; {what})"


@dataclass(frozen=True)
class Provenance:
    """What produced a report: versions, the input and its SHA-256, when, and how.

    Attributes
    ----------
    input : str
        The input as given (model file, study store or export), or a description of an
        in-memory object.
    input_kind : str
        ``"model file"``, ``"study store"``, ``"study export"``, ``"model object"``, ...
    sha256 : str or None
        SHA-256 of the input file; of a store folder, of its files (see
        :func:`impstab.report.provenance.tree_sha256`); None for an object built in memory.
    generated_utc : str
        ISO 8601 date and time (UTC) the report was made.
    command : str
        The command line (``impstab report ...``) or the Python call.
    versions : dict
        impstab, Python, numpy, scipy, matplotlib, jinja2.
    platform : str
    """

    input: str
    input_kind: str
    sha256: str | None
    generated_utc: str
    command: str
    versions: dict
    platform: str

    def rows(self) -> list[tuple[str, str]]:
        rows = [("input", f"{self.input} ({self.input_kind})"),
                ("SHA-256", self.sha256 or "none: the input was built in memory, not read from a file"),
                ("generated (UTC)", self.generated_utc), ("command", self.command)]
        rows += [(f"{name} version", v) for name, v in self.versions.items()]
        rows.append(("platform", self.platform))
        return rows


@dataclass(frozen=True, eq=False)
class Report:
    """A self-contained HTML report: the page and the sections it was made of.

    Attributes
    ----------
    html : str
        The whole page (inline CSS and SVG, no script, nothing fetched).
    title : str
    kind : {"model", "study"}
    sections : tuple of Section
    provenance : Provenance
    """

    html: str
    title: str
    kind: str
    sections: tuple[Section, ...]
    provenance: Provenance

    def section(self, name: str) -> Section:
        """The section called ``name``."""
        for s in self.sections:
            if s.name == name:
                return s
        raise ModelError("section", name, f"must be one of {[s.name for s in self.sections]}")

    @property
    def figures(self) -> int:
        return sum(len(s.figures) for s in self.sections)

    @property
    def tables(self) -> int:
        return sum(len(s.tables) for s in self.sections)

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the page to ``path`` (``.html``), under a temporary name renamed on success."""
        from ..io import atomic_path

        p = check_report_path(path)
        with atomic_path(p) as tmp:
            tmp.write_text(self.html, encoding="utf-8")
        return p

    def _repr_html_(self) -> str:
        """The page in a sandboxed frame, so that its style leaves the notebook's alone."""
        import html

        return (f'<iframe title="{html.escape(self.title, quote=True)}" sandbox="" '
                f'style="width:100%;height:48em;border:1px solid #ccc" srcdoc="{html.escape(self.html, quote=True)}">'
                "</iframe>")

    def __repr__(self) -> str:
        states = {}
        for s in self.sections:
            states[s.status] = states.get(s.status, 0) + 1
        done = ", ".join(f"{n} {k}" for k, n in states.items())
        return (f"Report({self.title!r}: {self.kind} report, {len(self.sections)} sections ({done}), "
                f"{self.figures} figures, {self.tables} tables, {len(self.html.encode()) / 1024:.0f} kB)")


def check_report_path(path: str | os.PathLike[str], flag: str = "--output") -> Path:
    """``path`` as a Path when it ends in .html or .htm; a ModelError naming ``flag`` otherwise."""
    p = Path(path)
    if p.suffix.lower() not in REPORT_SUFFIXES:
        raise ModelError(flag, str(path), "must end in .html (the report is one HTML file)")
    return p
