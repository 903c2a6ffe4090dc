"""Every chapter runs as a notebook in quick mode in under a minute, its own checks pass, it is a lesson of a
teachable size, and it ends with exercises whose answer key runs (tests/test_exercises.py).

Chapters are jupytext percent-format .py files; each one compares the package's fast code with its plain
pair-by-pair version in ``assert`` cells, so a failing comparison fails this test. The executed notebooks are
kept in build/executed/ for the book (``refsph book``).

The chapters are executed once per test session, as many at a time as there are cores, each kernel pinned to a
core of its own (so its wall time is what a student's one-core run would take, and refsph's pair sums in it see
one core); each test then reports its chapter's outcome."""
import itertools
import os
import threading
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from refsph.book import chapter_files, execute_chapter
from refsph.neighbours import available_cores

CHAPTERS = chapter_files()
ROOT = Path(__file__).resolve().parent.parent


def _pinned_pool():
    """A thread pool whose k-th thread is pinned to the k-th available core (a kernel it starts inherits that)."""
    cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    counter, lock = itertools.count(), threading.Lock()

    def pin():
        if len(cores) > 1:
            with lock:
                k = next(counter)
            os.sched_setaffinity(0, {cores[k % len(cores)]})
    return ThreadPoolExecutor(max(1, min(available_cores(), 4)), initializer=pin)


@pytest.fixture(scope="session")
def executed(tmp_path_factory):
    """{chapter name: (seconds, exception or None)} of every chapter, executed in quick mode."""
    pytest.importorskip("jupytext")
    pytest.importorskip("nbclient")
    figures = tmp_path_factory.mktemp("figures")

    def one(path):
        try:
            return path.name, (execute_chapter(path, quick=True, timeout=120, figures=figures / path.stem)[1], None)
        except Exception as e:                              # reported by that chapter's test
            return path.name, (None, e)
    with _pinned_pool() as pool:
        return dict(pool.map(one, CHAPTERS))


@pytest.mark.parametrize("path", CHAPTERS, ids=[p.stem for p in CHAPTERS])
def test_chapter_runs_quick(path, executed):
    wall, error = executed[path.name]
    if error is not None:
        raise error
    assert wall < 60.0, f"{path.name} took {wall:.1f} s in quick mode (limit 60 s)"


def test_chapters_exist():
    names = {p.stem for p in CHAPTERS}
    for stem in ("01_kernel", "02_esph", "03_tlsph", "04_johnson_cook", "05_contact", "06_taylor", "07_pressing",
                 "08_cutting", "09_cross_check", "10_where_sph_breaks", "11_thermal_cutting"):
        assert stem in names
