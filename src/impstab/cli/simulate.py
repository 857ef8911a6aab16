"""Command-line commands of this area (filled in by its module)."""

commands: list = []
