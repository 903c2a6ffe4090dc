"""Sphinx configuration of the refsph book (MyST-NB: the chapters as executed notebooks, Markdown pages).

``refsph book`` executes the chapters (quick mode), lays the sources out in ``build/book-src`` in the repository's
layout (``chapters/*.ipynb``, ``benchmarks/*_report.md``, ``figures/`` and the Markdown pages of this folder:
``index.md``, the course map, is the front page) and renders them with this file, read in place:

    sphinx-build -W --keep-going -b html -c book build/book-src build/book

Two things happen at build time: the course map's figure is drawn from ``course.json`` (which chapter needs which)
into the sources, and MathJax is served with the book (``_static/mathjax/``) so that equations render offline.
MathJax comes from the PyPI package ``sphinx-mathjax-offline`` (MathJax 3.2.2; in the ``chapters`` and ``test``
extras): only the SVG output and what it loads are copied (about 7 MB instead of the package's 24), and SVG needs
no web fonts, which browsers refuse to load from ``file://`` pages in another folder. Without the package the
book falls back to MathJax from a CDN (equations then need a network) and says so.
"""
import importlib.util
import shutil
import sys
from pathlib import Path

from refsph.teaching.book import draw_dependencies, load_course

HERE = Path(__file__).resolve().parent

project = "refsph: SPH for metal machining, chapter by chapter"
author = "refsph contributors"
copyright = "refsph contributors (MIT licence)"
extensions = ["myst_nb"]
nb_execution_mode = "off"                     # refsph book executes the chapters itself (build/executed/)
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_dmath_double_inline = True               # $$...$$ inside a paragraph is display math, as in Jupyter
exclude_patterns = ["_build", "figures", "**.ipynb_checkpoints"]
html_theme = "alabaster"
html_theme_options = {"page_width": "1100px"}
html_title = "refsph: SPH for metal machining"
suppress_warnings = ["mystnb.unknown_mime_type"]

# --- MathJax, served with the book ------------------------------------------------------------------------------
# tex-svg.js and what it may load: TeX extensions on demand (\boldsymbol, ...), the menu, the accessibility
# modules and the speech rule engine (the menu's speech and explorer options)
MATHJAX_PARTS = ["tex-svg.js", "input/tex/extensions", "ui", "a11y", "sre"]
_spec = importlib.util.find_spec("sphinx-mathjax-offline")
MATHJAX_SOURCE = (Path(next(iter(_spec.submodule_search_locations))) / "static" / "mathjax") if _spec else None
if MATHJAX_SOURCE is not None and (MATHJAX_SOURCE / MATHJAX_PARTS[0]).is_file():
    mathjax_path = "mathjax/tex-svg.js"       # relative: from the book's _static/
else:
    MATHJAX_SOURCE = None
    print("book/conf.py: sphinx-mathjax-offline is not installed, so MathJax loads from a CDN and equations need "
          "a network (pip install -e '.[chapters]')", file=sys.stderr)


def copy_mathjax(app, exception):
    if exception is None and MATHJAX_SOURCE is not None and app.builder.format == "html":
        target = Path(app.outdir) / "_static" / "mathjax"
        for part in MATHJAX_PARTS:
            src, dst = MATHJAX_SOURCE / part, target / part
            dst.parent.mkdir(parents=True, exist_ok=True)
            if src.is_dir():
                shutil.copytree(src, dst, dirs_exist_ok=True)
            else:
                shutil.copy2(src, dst)


# --- the course map's figure ------------------------------------------------------------------------------------
def draw_course_map(app):
    draw_dependencies(load_course(HERE / "course.json"), Path(app.srcdir) / "_generated" / "chapter_dependencies.png")


def setup(app):
    app.connect("builder-inited", draw_course_map)
    app.connect("build-finished", copy_mathjax)
