"""What every chapter needs before its first equation, in one call (chapters/ are lessons, not reports):

    from refsph.teaching.notebook import chapter
    ch = chapter("05_contact")      # ch.quick, ch.save(fig, "name.png"), ch.tmp, ch.elapsed()

* **Quick mode.** ``REFSPH_QUICK=1`` (the tests, the book) makes every chapter run in under a minute;
  without it a chapter runs at full resolution. ``ch.quick`` says which.
* **Figures.** ``ch.save(fig, name)`` writes ``build/figures/<chapter>/<name>`` (git ignores ``build/``), so
  running a chapter never changes the repository. Only ``REFSPH_WRITE_FIGURES=1`` writes the committed
  ``figures/<name>`` instead (do it at full resolution, on purpose). ``REFSPH_FIGURES=DIR`` sends them to DIR.
* **Scratch space.** ``ch.tmp``: a temporary folder for run output, removed when the kernel exits.
* **Style.** Figures for slides: larger fonts, the perceptual colour map viridis (:data:`FIELD_CMAP`).
"""
from __future__ import annotations

import atexit
import os
import shutil
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Chapter", "chapter", "FIELD_CMAP", "repository_root"]

FIELD_CMAP = "viridis"


def repository_root() -> Path:
    """The refsph checkout (the folder holding chapters/ and figures/)."""
    return Path(__file__).resolve().parents[2]


@dataclass
class Chapter:
    name: str
    quick: bool
    figures: Path
    tmp: Path
    started: float = field(default_factory=time.perf_counter)

    def save(self, fig, name: str, dpi: int = 120) -> Path:
        """Save a matplotlib figure as ``name`` in the chapter's figure folder; returns the path."""
        path = self.figures / name
        fig.savefig(path, dpi=dpi)
        return path

    def elapsed(self) -> float:
        """Seconds since the chapter started."""
        return time.perf_counter() - self.started


def _style() -> None:
    import matplotlib as mpl
    mpl.rcParams.update({"font.size": 11, "axes.titlesize": 11, "axes.labelsize": 11, "xtick.labelsize": 10,
                         "ytick.labelsize": 10, "legend.fontsize": 9, "image.cmap": FIELD_CMAP,
                         "figure.dpi": 100})


def chapter(name: str) -> Chapter:
    """Set up a chapter: quick mode from ``REFSPH_QUICK``, its figure folder, a scratch folder, the plot style."""
    quick = os.environ.get("REFSPH_QUICK", "0") == "1"
    root = repository_root()
    if not (root / "chapters").is_dir():                    # an installed package: work where the notebook runs
        root = Path.cwd()
    if os.environ.get("REFSPH_FIGURES"):
        figures = Path(os.environ["REFSPH_FIGURES"])
    elif os.environ.get("REFSPH_WRITE_FIGURES", "0") == "1":
        figures = root / "figures"
    else:
        figures = root / "build" / "figures" / name
    figures.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f"refsph-{name}-"))
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)
    _style()
    print(f"chapter {name}: quick mode {quick}; figures -> {figures}")
    return Chapter(name=name, quick=quick, figures=figures, tmp=tmp)
