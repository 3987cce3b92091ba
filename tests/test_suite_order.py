"""The suite's own scheduling (``conftest.py``): the longest files first, as make test runs it."""

from pathlib import Path

from conftest import LONGEST_FIRST

HERE = Path(__file__).resolve().parent


def test_the_longest_files_named_first_exist():
    """A renamed file would fall silently to the end of the run."""
    missing = [name for name in LONGEST_FIRST if not (HERE / name).is_file()]
    assert missing == [] and len(set(LONGEST_FIRST)) == len(LONGEST_FIRST)


def test_make_test_keeps_conftests_order():
    """pytest-xdist orders loadfile's files by their number of tests unless told not to: the
    longest-first order then had no effect (test_readme.py started at 72 % of the run)."""
    recipe = (HERE.parent / "Makefile").read_text(encoding="utf-8")
    line = next(ln for ln in recipe.splitlines() if "-m pytest" in ln)
    assert "--dist loadfile" in line and "--no-loadscope-reorder" in line
