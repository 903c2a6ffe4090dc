"""Every chapter runs as a notebook in quick mode in under a minute, and its own checks pass.

Chapters are jupytext percent-format .py files; each one compares the package's fast code with its plain
pair-by-pair version in ``assert`` cells, so a failing comparison fails this test.
"""
import time
from pathlib import Path

import pytest

CHAPTERS = sorted((Path(__file__).resolve().parent.parent / "chapters").glob("[0-9][0-9]_*.py"))


@pytest.mark.parametrize("path", CHAPTERS, ids=[p.stem for p in CHAPTERS])
def test_chapter_runs_quick(path, tmp_path, monkeypatch):
    jupytext = pytest.importorskip("jupytext")
    nbclient = pytest.importorskip("nbclient")
    monkeypatch.setenv("REFSPH_QUICK", "1")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.setenv("REFSPH_FIGURES", str(tmp_path))      # quick-mode figures must not replace figures/
    nb = jupytext.read(path)
    client = nbclient.NotebookClient(nb, timeout=120, kernel_name="python3",
                                     resources={"metadata": {"path": str(path.parent)}})
    t0 = time.perf_counter()
    client.execute()
    wall = time.perf_counter() - t0
    assert wall < 60.0, f"{path.name} took {wall:.1f} s in quick mode (limit 60 s)"


def test_chapters_exist():
    names = {p.stem for p in CHAPTERS}
    for stem in ("01_kernel", "02_esph", "03_tlsph", "04_johnson_cook", "05_contact", "06_taylor", "07_pressing",
                 "08_cutting"):
        assert stem in names
