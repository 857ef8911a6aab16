"""The test suite's own scheduling list names real modules (a renamed module would silently
lose its place at the front)."""

from pathlib import Path

from conftest import LONGEST_FIRST


def test_longest_first_names_existing_modules():
    here = Path(__file__).resolve().parent
    missing = [name for name in LONGEST_FIRST if not (here / name).is_file()]
    assert not missing, missing
    assert len(set(LONGEST_FIRST)) == len(LONGEST_FIRST)
