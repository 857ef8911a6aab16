"""The test suite's own scheduling list names real modules (a renamed module would silently
lose its place at the front)."""

from pathlib import Path

from conftest import LONGEST_FIRST


def test_longest_first_names_existing_modules():
    here = Path(__file__).resolve().parent
    missing = [name for name in LONGEST_FIRST if not (here / name).is_file()]
    assert not missing, missing
    assert len(set(LONGEST_FIRST)) == len(LONGEST_FIRST)


def test_make_test_keeps_the_order():
    """pytest-xdist reorders loadscope's modules by their number of tests unless told not to, which
    would silently drop the longest-first order."""
    makefile = (Path(__file__).resolve().parents[1] / "Makefile").read_text(encoding="utf-8")
    (recipe,) = [line for line in makefile.splitlines() if "-m pytest" in line]
    assert "--dist loadscope" in recipe and "--no-loadscope-reorder" in recipe, recipe
