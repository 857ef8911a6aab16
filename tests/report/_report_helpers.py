"""Models, studies and page parsing shared by the report tests."""

from __future__ import annotations

import html
import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"

#: a model name with markup, terminal escapes, a bidirectional override and matplotlib mathtext
EVIL_NAME = "<script>alert('x')</script> \x1b[31mred\x1b[0m \u202eevil & $x^2$ \"quoted\""

GRID_STUDY = """schema_version = 1
name = "{name}"
model = "imp_symmetric.toml"
outputs = ["critical_thrust", "kind", "frequency_hz", "margin", "undamped_critical_thrust", "modes"]

[[parameters]]
path = "mount_rings[0].x"
values = {{ start = 0.0, stop = 0.3, num = 4 }}

[[parameters]]
path = "mount_rings[0].k_shear"
values = {{ start = 5.0e3, stop = 4.0e4, num = 3, scale = "log" }}

[sampling]
method = "grid"
"""

RANDOM_STUDY = """schema_version = 1
name = "scatter"
model = "imp_symmetric.toml"
outputs = ["critical_thrust", "kind", "frequency_hz", "margin"]

[[parameters]]
path = "mount_rings[0].k_shear"
distribution = { kind = "lognormal", median = 2.0e4, sigma = 0.2 }

[[parameters]]
path = "mount_rings[0].k_axial"
distribution = { kind = "lognormal", median = 1.0e5, sigma = 0.2 }

[sampling]
method = "random"
n = 12
seed = 3
"""


def copy_example(folder: Path, name: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / name
    shutil.copy(EXAMPLES / name, target)
    return target


def write_model(folder: Path, name: str, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    p = folder / name
    p.write_text(text, encoding="utf-8")
    return p


def run_study_file(folder: Path, text: str, store: str = "study.zarr"):
    """Write a study file on a copy of the symmetric example and run it into a store."""
    from impstab.studies import load_study, run_study

    copy_example(folder, "imp_symmetric.toml")
    path = folder / "study.toml"
    path.write_text(text, encoding="utf-8")
    return run_study(load_study(path), folder / store)


class PageParser(HTMLParser):
    """Tags, attributes, text and the sections of a report page."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[tuple[str, dict]] = []
        self.text: list[str] = []
        self.sections: dict[str, str] = {}
        self.ids: list[str] = []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.tags.append((tag, a))
        if "id" in a:
            self.ids.append(a["id"])
        if tag == "section":
            self.sections[a["data-section"]] = a["data-status"]

    def handle_data(self, data):
        self.text.append(data)


def parse(html: str) -> PageParser:
    p = PageParser()
    p.feed(html)
    p.close()
    return p


def page_text(html: str) -> str:
    """The visible text of the page (entities decoded), whitespace collapsed."""
    return re.sub(r"\s+", " ", " ".join(parse(html).text))


def table_rows(page: str, caption_start: str) -> list[list[str]]:
    """Cell texts (entities decoded) of the table whose caption starts with ``caption_start``."""
    m = re.search(r"<table[^>]*><caption[^>]*>" + re.escape(caption_start) + r".*?</table>", page, re.S)
    assert m, f"no table {caption_start!r}"
    rows = []
    for tr in re.findall(r"<tr>(.*?)</tr>", m.group(0), re.S):
        cells = re.findall(r"<td[^>]*>(.*?)</td>", tr, re.S)
        if cells:
            rows.append([html.unescape(re.sub(r"<[^>]+>", "", c)) for c in cells])
    return rows
