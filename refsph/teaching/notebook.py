"""What every chapter needs before its first equation, in one call (chapters/ are lessons, not reports):

    from refsph.teaching.notebook import chapter
    ch = chapter("05_contact")      # ch.quick, ch.show(fig, "name.png", caption="..."), ch.tmp, ch.elapsed()
                                    # ch.animate(fig, draw, frames, "name.gif", caption="...")

* **Quick mode.** ``REFSPH_QUICK=1`` (the tests, the book) makes every chapter run in under a minute;
  without it a chapter runs at full resolution. ``ch.quick`` says which.
* **Figures.** ``ch.show(fig, name, caption="...")`` saves a figure and shows it with its caption (the book
  prints the caption under the figure and uses it as the image's alt text; the notebook shows it in italics below
  the figure). ``ch.save(fig, name)`` only saves. Both write ``build/figures/<chapter>/<name>`` (git ignores
  ``build/``), so running a chapter never changes the repository. Only ``REFSPH_WRITE_FIGURES=1`` writes the
  committed ``figures/<name>`` instead (do it at full resolution, on purpose). ``REFSPH_FIGURES=DIR`` sends them
  to DIR.
* **Animations.** ``ch.animate(fig, draw, frames, name, caption="...")`` calls ``draw(frame)`` for each frame,
  and shows the frames as an animated GIF (no ffmpeg, no JavaScript: it plays in Jupyter, in the book, offline
  and on a slide), captioned like a figure; with a name it is saved too (``name.gif``, next to the figures).
  Keep them small: at most :data:`MAX_FRAMES` frames at 80 dpi is a few hundred kB in the book.
* **Warnings** are shown as ``Category: message``, without the file and line that raised them (a path of the
  machine that ran the chapter, which would otherwise end up in the book).
* **Scratch space.** ``ch.tmp``: a temporary folder for run output, removed when the kernel exits.
* **Style.** Figures for slides, by one rule for every chapter (:mod:`refsph.teaching.plots`): at most 10 x 6.5
  in, every text at least 14 pt at that size (:func:`refsph.teaching.plots.slide_style`, applied here), and the
  perceptual colour map viridis (:data:`FIELD_CMAP`). Each figure shown records its size and what breaks the
  rule, if anything, in its output's metadata; the tests read it (``tests/test_figures.py``).
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

__all__ = ["Chapter", "chapter", "FIELD_CMAP", "repository_root", "show_figure", "show_animation", "animation_gif",
           "shown_figure_problems",
           "format_warning", "CAPTION_KEY", "MAX_FRAMES"]

FIELD_CMAP = "viridis"
CAPTION_KEY = "refsph"        # output metadata {"refsph": {"caption": ...}} of a figure (or {"caption_text": true})
MAX_FRAMES = 30               # frames of an animation at most: the book stays lean


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

    def animate(self, fig, draw, frames, name: str | None = None, *, caption: str, fps: float = 6,
                dpi: int = 80) -> None:
        """Show an animation with its caption: ``draw(frame)`` updates ``fig`` for each item of ``frames`` (at most
        :data:`MAX_FRAMES`), and the frames are shown as an animated GIF (:func:`animation_gif`), saved first as
        ``name`` (a ``.gif``) when one is given. The caption says what moves, in plain text, as a figure's does
        (:meth:`show`); the figure is closed afterwards."""
        if not " ".join(caption.split()):
            raise ValueError("an animation needs a caption: a sentence or two saying what moves")
        gif = animation_gif(fig, draw, frames, fps=fps, dpi=dpi)
        if name is not None:
            (self.figures / name).write_bytes(gif)
        show_animation(gif, caption, fig)

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
    except ImportError:
        get_ipython = None
    if get_ipython is None or get_ipython() is None:
        print(f"Figure: {caption}")
        plt.show()
        plt.close(fig)
        return
    buf = io.BytesIO()
    fig.savefig(buf, format="png", bbox_inches="tight")       # what the inline backend would show
    slide = _slide_check(fig)
    plt.close(fig)
    _display("image/png", buf.getvalue(), caption, slide)


def _slide_check(fig) -> dict:
    """The figure's size as saved and its size-rule problems (:func:`refsph.teaching.plots.slide_problems`), for the
    output's metadata (the tests read it)."""
    from .plots import slide_problems

    box = fig.get_tightbbox(fig.canvas.get_renderer())
    return {"width_in": round(box.width, 2), "height_in": round(box.height, 2), "problems": slide_problems(fig)}


def shown_figure_problems(nb) -> tuple[int, list[str]]:
    """(how many figures and animations an executed notebook showed with their slide check, the problems of those
    that break the size rule), read from the outputs' metadata that :func:`show_figure` writes."""
    measured, bad = 0, []
    for cell in nb["cells"]:
        for out in cell.get("outputs", []):
            meta = out.get("metadata", {}).get(CAPTION_KEY, {})
            if "caption" in meta and "slide" in meta:
                measured += 1
                bad += [f"{meta['caption'][:50]}...: {p}" for p in meta["slide"].get("problems", [])]
    return measured, bad


def _display(mime: str, data: bytes, caption: str, slide: dict) -> None:
    """An image output carrying the caption (and the slide check) in its metadata, then the caption in italics."""
    from IPython.display import display

    kind = "Animation" if mime == "image/gif" else "Figure"
    display({mime: base64.b64encode(data).decode("ascii"), "text/plain": f"<{kind}: {caption}>"}, raw=True,
            metadata={CAPTION_KEY: {"caption": caption, "slide": slide}})
    display({"text/markdown": f"*{caption}*", "text/plain": caption}, raw=True,
            metadata={CAPTION_KEY: {"caption_text": True}})


def animation_gif(fig, draw, frames, *, fps: float = 6, dpi: int = 80) -> bytes:
    """An animated GIF of ``fig``: ``draw(frame)`` is called for each item of ``frames`` (at most
    :data:`MAX_FRAMES`) and the figure is rendered at ``dpi`` on the same canvas each time (not cropped, so the
    frames line up). One palette of 128 colours for all frames, no dithering: flat plots stay flat and small.
    The GIF loops, ``fps`` frames a second; returns its bytes."""
    from PIL import Image

    frames = list(frames)
    if not 2 <= len(frames) <= MAX_FRAMES:
        raise ValueError(f"an animation needs 2 to {MAX_FRAMES} frames (the book stays lean), got {len(frames)}")
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = fig.canvas if hasattr(fig.canvas, "buffer_rgba") else FigureCanvasAgg(fig)      # Agg (and inline)
    images, dpi0 = [], fig.dpi
    fig.set_dpi(dpi)                                            # the whole canvas, drawn: the frames line up
    try:
        for frame in frames:
            draw(frame)
            canvas.draw()
            images.append(Image.frombuffer("RGBA", canvas.get_width_height(), canvas.buffer_rgba()).convert("RGB"))
    finally:
        fig.set_dpi(dpi0)
    w, h = images[0].size
    some = images[::-(-len(images) // 6)] + images[-1:]         # one palette for all, from up to 7 of the frames
    sheet = Image.new("RGB", (w, h * len(some)))
    for k, im in enumerate(some):
        sheet.paste(im, (0, k * h))
    palette = sheet.quantize(colors=128, method=Image.Quantize.MEDIANCUT)
    frames_p = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in images]
    out = io.BytesIO()
    frames_p[0].save(out, format="GIF", save_all=True, append_images=frames_p[1:], duration=round(1000 / fps),
                     loop=0, optimize=True)
    return out.getvalue()


def show_animation(gif: bytes, caption: str, fig=None) -> None:
    """Display an animated GIF with its caption, as :func:`show_figure` does a figure (the book makes it a captioned
    figure with alt text); ``fig``, the figure it was drawn from, is checked against the size rule and closed."""
    import matplotlib.pyplot as plt

    caption = " ".join(caption.split())
    if not caption:
        raise ValueError("an animation needs a caption: a sentence or two saying what moves")
    slide = {}
    if fig is not None:
        fig.canvas.draw()                                       # laid out at its own dpi, as a figure is shown
        slide = _slide_check(fig)
        plt.close(fig)
    try:
        from IPython import get_ipython
    except ImportError:
        get_ipython = None
    if get_ipython is None or get_ipython() is None:
        print(f"Animation ({len(gif) / 1e3:.0f} kB): {caption}")
        return
    _display("image/gif", gif, caption, slide)


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
    """Figures for slides (the size rule of :mod:`refsph.teaching.plots`) and the colour map of fields."""
    import matplotlib as mpl

    from .plots import slide_style

    mpl.rcParams.update(dict(slide_style(), **{"image.cmap": FIELD_CMAP}))


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
