"""Every chapter runs as a notebook in quick mode in under a minute, its own checks pass, it is a lesson of a
teachable size, and it ends with exercises whose answer key runs (tests/test_exercises.py).

Chapters are jupytext percent-format .py files; each one compares the package's fast code with its plain
pair-by-pair version in ``assert`` cells, so a failing comparison fails this test. The executed notebooks are
kept in build/executed/ for the book (``refsph book``).

One chapter per test: the default run's two xdist workers share them, each worker pinned to a core of its own
(tests/conftest.py), so a chapter's kernel, which inherits its worker's core, takes the wall time a student's
one-core run would, and refsph's pair sums in it see one core."""
import pytest

from refsph.teaching.book import chapter_files, execute_chapter

CHAPTERS = chapter_files()


@pytest.mark.parametrize("path", CHAPTERS, ids=[p.stem for p in CHAPTERS])
def test_chapter_runs_quick(path, tmp_path):
    pytest.importorskip("jupytext")
    pytest.importorskip("nbclient")
    wall = execute_chapter(path, quick=True, timeout=120, figures=tmp_path / "figures")[1]
    assert wall < 60.0, f"{path.name} took {wall:.1f} s in quick mode (limit 60 s)"


def test_chapters_exist():
    names = {p.stem for p in CHAPTERS}
    for stem in ("01_kernel", "02_esph", "03_tlsph", "04_johnson_cook", "05_contact", "06_taylor", "07_pressing",
                 "08_cutting", "09_cross_check", "10_where_sph_breaks", "11_thermal_cutting"):
        assert stem in names
