"""The chapters as a browsable book: execute them (quick mode by default) and render them with Sphinx and MyST-NB.

    refsph book                 # quick mode, into build/book/index.html (a few minutes)
    refsph book --full          # full resolution (each chapter takes minutes)

Executed notebooks are kept in ``build/executed/`` (git ignores ``build/``) and reused while the chapter file is
older than them and was run in the same mode (the test suite writes them too, so after ``pytest`` the book only
renders). The book is built with warnings as errors: a chapter that does not render cleanly fails the build.
Needs the ``chapters`` extra (``pip install -e '.[chapters]'``).
"""
from __future__ import annotations

import json
import os
import shutil
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from .notebook import repository_root

__all__ = ["chapter_files", "execute_chapter", "executed_path", "build_book"]

CONF = '''# Sphinx configuration of the refsph book (written by refsph.teaching.book; edit refsph/teaching/book.py)
project = "refsph: SPH for metal machining, chapter by chapter"
author = "refsph contributors"
extensions = ["myst_nb"]
nb_execution_mode = "off"
myst_enable_extensions = ["dollarmath", "amsmath"]
exclude_patterns = ["_build", "figures"]
html_theme = "alabaster"
html_theme_options = {"page_width": "1100px"}
suppress_warnings = ["mystnb.unknown_mime_type"]
'''


def chapter_files() -> list[Path]:
    """chapters/NN_name.py, in order (FileNotFoundError outside a source checkout, which has no chapters)."""
    folder = repository_root() / "chapters"
    if not folder.is_dir():
        raise FileNotFoundError(f"no chapters/ at {folder}: the chapters and the book need a source checkout of "
                                "refsph (pip install -e . in a clone)")
    return sorted(folder.glob("[0-9][0-9]_*.py"))


def executed_path(chapter: Path) -> Path:
    return repository_root() / "build" / "executed" / (chapter.stem + ".ipynb")


def execute_chapter(chapter: Path, quick: bool = True, timeout: int = 600, figures: Path | None = None):
    """Run one chapter as a notebook (jupytext + nbclient) in its own kernel; returns (notebook, seconds) and
    writes the executed notebook to ``build/executed/``. ``figures``: where its figures go (default: the
    chapter's build folder, see :mod:`refsph.teaching.notebook`)."""
    import jupytext
    import nbclient
    import nbformat

    env = dict(os.environ, REFSPH_QUICK="1" if quick else "0", MPLBACKEND="module://matplotlib_inline.backend_inline")
    if figures is not None:
        env["REFSPH_FIGURES"] = str(figures)
    nb = jupytext.read(chapter)
    client = nbclient.NotebookClient(nb, timeout=timeout, kernel_name="python3",
                                     resources={"metadata": {"path": str(chapter.parent)}})
    t0 = time.perf_counter()
    client.execute(env=env)                      # the kernel's own environment: nothing of this process changes
    seconds = time.perf_counter() - t0
    nb.metadata["refsph"] = {"quick": quick, "seconds": seconds}
    out = executed_path(chapter)
    out.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, out)
    return nb, seconds


def _fresh(chapter: Path, quick: bool) -> bool:
    out = executed_path(chapter)
    if not out.exists() or out.stat().st_mtime < chapter.stat().st_mtime:
        return False
    meta = json.loads(out.read_text()).get("metadata", {}).get("refsph", {})
    return meta.get("quick") == quick


def _index(chapters: list[Path], reports: list[Path]) -> str:
    items = "\n".join(f"chapters/{c.stem}" for c in chapters)
    rep = "\n".join(f"benchmarks/{r.stem}" for r in reports)
    return f"""# refsph: SPH for metal machining, chapter by chapter

Lessons on the Eulerian and Total Lagrangian SPH of Islam, Bansal & Peng for metal machining: each chapter
derives one part, writes its equations as plain code, checks the package against it, shows it working on a
small case and ends with exercises. The benchmark reports hold the full-resolution studies. Built by
`refsph book` from the executed chapters.

```{{toctree}}
:maxdepth: 1
:caption: Chapters

{items}
```

```{{toctree}}
:maxdepth: 1
:caption: Benchmark reports

{rep}
```
"""


def build_book(out: Path | None = None, quick: bool = True, reuse: bool = True, jobs: int = 2) -> Path:
    """Execute the chapters that need it (``jobs`` at a time), then render the book into ``out`` (default
    build/book) with warnings as errors. Returns the path of its index.html."""
    from sphinx.cmd.build import build_main

    root = repository_root()
    out = Path(out) if out is not None else root / "build" / "book"
    chapters = chapter_files()
    todo = [c for c in chapters if not (reuse and _fresh(c, quick))]
    with ThreadPoolExecutor(max(1, jobs)) as ex:
        for c, (_, s) in zip(todo, ex.map(lambda c: execute_chapter(c, quick), todo)):
            print(f"executed {c.name} in {s:.1f} s")
    src = root / "build" / "book-src"                      # the repository's layout, so relative links resolve
    shutil.rmtree(src, ignore_errors=True)
    (src / "chapters").mkdir(parents=True)
    (src / "benchmarks").mkdir()
    reports = sorted((root / "benchmarks").glob("*_report.md"))
    (src / "conf.py").write_text(CONF)
    (src / "index.md").write_text(_index(chapters, reports))
    for c in chapters:
        shutil.copy(executed_path(c), src / "chapters" / (c.stem + ".ipynb"))
    for r in reports:
        shutil.copy(r, src / "benchmarks" / r.name)
    if (root / "figures").exists():
        shutil.copytree(root / "figures", src / "figures")
    code = build_main(["-W", "--keep-going", "-q", "-b", "html", str(src), str(out)])
    if code != 0:
        raise RuntimeError(f"the book did not build cleanly (sphinx exit {code}); see the warnings above")
    return out / "index.html"
