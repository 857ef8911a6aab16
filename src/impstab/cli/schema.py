"""``impstab schema``: the JSON Schema (or the reference page) of model and study files."""

from __future__ import annotations

import json
from pathlib import Path

import click

__all__ = ["commands"]


@click.command("schema")
@click.option("--study", is_flag=True, help="the study-file schema instead of the model-file schema")
@click.option("--markdown", is_flag=True, help="the reference page (docs/model-file.md, docs/study-file.md) instead")
@click.option("-o", "--output", type=click.Path(dir_okay=False), default=None,
              help="write to this file instead of printing it")
def schema_cmd(study: bool, markdown: bool, output: str | None) -> None:
    """Print the JSON Schema of model files (or of study files, --study).

    TOML editors that read JSON Schemas (Taplo, Even Better TOML) use it to validate and
    complete files as they are typed; see docs/model-file.md.
    """
    if study:
        from ..studies import reference as ref
    else:
        from ..model import reference as ref  # type: ignore[no-redef]
    text = ref.markdown_page() if markdown else json.dumps(ref.json_schema_document(), indent=2) + "\n"
    if output is None:
        click.echo(text, nl=False)
        return
    from ..io import atomic_path

    with atomic_path(output) as tmp:
        Path(tmp).write_text(text, encoding="utf-8")
    click.echo(f"wrote {output}", err=True)


commands = [schema_cmd]
