"""Every chapter runs as a notebook in quick mode in under a minute, its own checks pass, it is a lesson of a
teachable size, and it ends with exercises whose answer key runs (tests/test_exercises.py).

Chapters are jupytext percent-format .py files; each one compares the package's fast code with its plain
pair-by-pair version in ``assert`` cells, so a failing comparison fails this test. The executed notebooks are
kept in build/executed/ for the book (``refsph book``)."""
from pathlib import Path

import pytest

from refsph.book import chapter_files, execute_chapter

CHAPTERS = chapter_files()
ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("path", CHAPTERS, ids=[p.stem for p in CHAPTERS])
def test_chapter_runs_quick(path, tmp_path):
    pytest.importorskip("jupytext")
    pytest.importorskip("nbclient")
    _, wall = execute_chapter(path, quick=True, timeout=120, figures=tmp_path)
    assert wall < 60.0, f"{path.name} took {wall:.1f} s in quick mode (limit 60 s)"


def test_chapters_exist():
    names = {p.stem for p in CHAPTERS}
    for stem in ("01_kernel", "02_esph", "03_tlsph", "04_johnson_cook", "05_contact", "06_taylor", "07_pressing",
                 "08_cutting"):
        assert stem in names
