"""What every chapter needs before its first equation, in one call (chapters/ are lessons, not reports):

    from refsph.teaching.notebook import chapter
    ch = chapter("05_contact")      # ch.quick, ch.show(fig, "name.png", caption="..."), ch.tmp, ch.elapsed()

* **Quick mode.** ``REFSPH_QUICK=1`` (the tests, the book) makes every chapter run in under a minute;
  without it a chapter runs at full resolution. ``ch.quick`` says which.
* **Figures.** ``ch.show(fig, name, caption="...")`` saves a figure and shows it with its caption (the book
  prints the caption under the figure and uses it as the image's alt text; the notebook shows it in italics below
  the figure). ``ch.save(fig, name)`` only saves. Both write ``build/figures/<chapter>/<name>`` (git ignores
  ``build/``), so running a chapter never changes the repository. Only ``REFSPH_WRITE_FIGURES=1`` writes the
  committed ``figures/<name>`` instead (do it at full resolution, on purpose). ``REFSPH_FIGURES=DIR`` sends them
  to DIR.
* **Warnings** are shown as ``Category: message``, without the file and line that raised them (a path of the
  machine that ran the chapter, which would otherwise end up in the book).
* **Scratch space.** ``ch.tmp``: a temporary folder for run output, removed when the kernel exits.
* **Style.** Figures for slides: larger fonts, the perceptual colour map viridis (:data:`FIELD_CMAP`).
"""
from __future__ import annotations

import atexit
import base64
import io
import os
import shutil
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Chapter", "chapter", "FIELD_CMAP", "repository_root", "show_figure", "format_warning", "CAPTION_KEY"]

FIELD_CMAP = "viridis"
CAPTION_KEY = "refsph"        # output metadata {"refsph": {"caption": ...}} of a figure (or {"caption_text": true})


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

    def show(self, fig, name: str | None = None, *, caption: str, dpi: int = 120) -> None:
        """Show a figure with its caption, having saved it as ``name`` first when one is given (see
        :meth:`save`); the figure is closed afterwards. The caption says what the figure shows in a sentence or
        two, in plain text (Unicode symbols, no TeX): it is the figure's caption and alt text in the book."""
        if name is not None:
            self.save(fig, name, dpi=dpi)
        show_figure(fig, caption)

    def elapsed(self) -> float:
        """Seconds since the chapter started."""
        return time.perf_counter() - self.started


def show_figure(fig, caption: str) -> None:
    """Display ``fig`` as a PNG output carrying ``caption`` in its metadata (under :data:`CAPTION_KEY`), then
    the caption as an italic Markdown output, and close the figure. :func:`refsph.teaching.book.caption_figures`
    turns the pair into a captioned figure with alt text. Outside IPython (a chapter run as a script) the caption
    is printed and the figure goes to ``plt.show()``."""
    import matplotlib.pyplot as plt

    caption = " ".join(caption.split())
    if not caption:
        raise ValueError("a figure needs a caption: a sentence or two saying what it shows")
    try:
        from IPython import get_ipython
        from IPython.display import display
    except ImportError:
        get_ipython = None
    if get_ipython is None or get_ipython() is None:
        print(f"Figure: {caption}")
        plt.show()
        plt.close(fig)
        return
    buf = io.BytesIO()
    fig.savefig(buf, format="png", bbox_inches="tight")       # what the inline backend would show
    plt.close(fig)
    png = base64.b64encode(buf.getvalue()).decode("ascii")
    display({"image/png": png, "text/plain": f"<Figure: {caption}>"}, raw=True,
            metadata={CAPTION_KEY: {"caption": caption}})
    display({"text/markdown": f"*{caption}*", "text/plain": caption}, raw=True,
            metadata={CAPTION_KEY: {"caption_text": True}})


def format_warning(message, category, filename, lineno, line=None) -> str:
    """A warning as the chapters show it: ``Category: message``, without the path and line of the code that
    raised it (for :data:`warnings.formatwarning`)."""
    return f"{category.__name__}: {message}\n"


def _shown(path: Path, root: Path) -> str:
    """``path`` as a chapter prints it: relative to the checkout, or only its last part (no machine path)."""
    try:
        return str(path.resolve().relative_to(root.resolve()))
    except ValueError:
        return f".../{path.name}"


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
    warnings.formatwarning = format_warning
    print(f"chapter {name}: quick mode {quick}; figures -> {_shown(figures, root)}")
    return Chapter(name=name, quick=quick, figures=figures, tmp=tmp)
