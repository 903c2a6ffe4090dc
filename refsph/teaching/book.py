"""The chapters as a browsable book: execute them (quick mode by default) and render them with Sphinx and MyST-NB.

    refsph book                 # quick mode, into build/book/index.html (a few minutes)
    refsph book --full          # full resolution (each chapter takes minutes)

The book's configuration and front matter live in ``book/`` as ordinary files: ``book/conf.py`` (Sphinx),
``book/index.md`` (the course map, the front page), ``book/course.json`` (which chapter needs which; the course
map's figure is drawn from it at build time by :func:`draw_dependencies`) and the other pages there. The sources
are laid out in ``build/book-src`` in the repository's layout (``chapters/``, ``benchmarks/``, ``figures/`` and
the pages of ``book/``), so relative links resolve, and rendered with ``sphinx-build -c book``.

Executed notebooks are kept in ``build/executed/`` (git ignores ``build/``) and reused while the chapter file is
older than them and was run in the same mode (the test suite writes them too, so after ``pytest`` the book only
renders). The book is built with warnings as errors, and its pages are then read back (:func:`rendering_problems`):
raw TeX outside the math MathJax typesets, a figure without a caption or alt text, a machine's path in a page, or
MathJax loaded from the network fail the build. Needs the ``chapters`` extra (``pip install -e '.[chapters]'``).
"""
from __future__ import annotations

import json
import os
import re
import shutil
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from html.parser import HTMLParser
from pathlib import Path

from .notebook import CAPTION_KEY, repository_root

__all__ = ["chapter_files", "execute_chapter", "save_executed", "executed_path", "build_book", "book_folder",
           "load_course", "draw_dependencies", "caption_figures", "figure_markdown", "assemble", "render", "raw_tex",
           "rendering_problems", "RAW_TEX"]


def chapter_files() -> list[Path]:
    """chapters/NN_name.py, in order (FileNotFoundError outside a source checkout, which has no chapters)."""
    folder = repository_root() / "chapters"
    if not folder.is_dir():
        raise FileNotFoundError(f"no chapters/ at {folder}: the chapters and the book need a source checkout of "
                                "refsph (pip install -e . in a clone)")
    return sorted(folder.glob("[0-9][0-9]_*.py"))


def book_folder() -> Path:
    """``book/``: the book's conf.py, front page (the course map) and course data."""
    return repository_root() / "book"


def executed_path(chapter: Path) -> Path:
    return repository_root() / "build" / "executed" / (chapter.stem + ".ipynb")


def execute_chapter(chapter: Path, quick: bool = True, timeout: int = 600, figures: Path | None = None):
    """Run one chapter as a notebook (jupytext + nbclient) in its own kernel; returns (notebook, seconds) and
    writes the executed notebook to ``build/executed/``. ``figures``: where its figures go (default: the
    chapter's build folder, see :mod:`refsph.teaching.notebook`)."""
    import jupytext
    import nbclient

    env = dict(os.environ, REFSPH_QUICK="1" if quick else "0", MPLBACKEND="module://matplotlib_inline.backend_inline")
    if figures is not None:
        env["REFSPH_FIGURES"] = str(figures)
    nb = jupytext.read(chapter)
    client = nbclient.NotebookClient(nb, timeout=timeout, kernel_name="python3",
                                     resources={"metadata": {"path": str(chapter.parent)}})
    t0 = time.perf_counter()
    client.execute(env=env)                      # the kernel's own environment: nothing of this process changes
    seconds = time.perf_counter() - t0
    save_executed(chapter, nb, seconds, quick)
    return nb, seconds


def save_executed(chapter: Path, nb, seconds: float, quick: bool) -> Path:
    """Keep an executed student's copy of ``chapter`` in ``build/executed/`` for the book, with the mode it ran in
    and its seconds (the test suite saves the student's part of the lecturer's run here, so the book reuses it)."""
    import nbformat

    nb.metadata["refsph"] = {"quick": quick, "seconds": seconds}
    out = executed_path(chapter)
    out.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, out)
    return out


def _fresh(chapter: Path, quick: bool) -> bool:
    out = executed_path(chapter)
    if not out.exists() or out.stat().st_mtime < chapter.stat().st_mtime:
        return False
    meta = json.loads(out.read_text()).get("metadata", {}).get("refsph", {})
    return meta.get("quick") == quick


# --- the course map's figure ------------------------------------------------------------------------------------

def load_course(path: Path | None = None) -> dict:
    """``book/course.json``: {"chapters": {stem: {"title": ..., "needs": [stems]}}}."""
    return json.loads(Path(path or book_folder() / "course.json").read_text())


def _levels(needs: dict[str, list[str]]) -> dict[str, int]:
    """Each chapter's column: one more than the deepest chapter it needs (ValueError on a cycle)."""
    level: dict[str, int] = {}

    def visit(stem, path=()):
        if stem in path:
            raise ValueError(f"chapter dependencies form a cycle: {' -> '.join(path + (stem,))}")
        if stem not in level:
            level[stem] = 1 + max((visit(n, path + (stem,)) for n in needs[stem]), default=-1)
        return level[stem]

    for stem in needs:
        visit(stem)
    return level


def _positions(needs: dict[str, list[str]]) -> dict[str, tuple[float, float]]:
    """(column, row) of each chapter: the column from :func:`_levels`, the rows of a column centred and in the
    order of the mean row of what each chapter needs (fewer crossings), then file order."""
    level = _levels(needs)
    columns: dict[int, list[str]] = {}
    for stem in needs:
        columns.setdefault(level[stem], []).append(stem)
    pos: dict[str, tuple[float, float]] = {}
    for lv in sorted(columns):
        col = columns[lv]
        key = {s: sum(pos[n][1] for n in needs[s]) / len(needs[s]) if needs[s] else 0.0 for s in col}
        col.sort(key=lambda s: -key[s])                     # stable: file order among equals
        pos.update({s: (lv, (len(col) - 1) / 2 - k) for k, s in enumerate(col)})
    return pos


def draw_dependencies(course: dict, path: Path) -> Path:
    """Draw which chapter needs which (an arrow from each chapter to those that build on it), one column per
    depth, and save it as ``path`` (PNG). It keeps to the size rule of :mod:`refsph.teaching.plots`: at most 10 x
    6.5 in (1.25 in a column and a row: eight columns, five rows), text of 14 pt (long ``short`` names in
    book/course.json are broken into lines)."""
    from matplotlib.figure import Figure

    from .plots import SLIDE

    chapters = course["chapters"]
    needs = {stem: list(c["needs"]) for stem, c in chapters.items()}
    pos = _positions(needs)
    n_cols = 1 + max(x for x, _ in pos.values())
    half = max(abs(y) for _, y in pos.values()) + 0.6
    pitch = 1.25                                            # inches a column (and a row) where the slide has room
    fig = Figure(figsize=(min(pitch * n_cols, SLIDE["max_width_in"]), min(pitch * 2 * half, SLIDE["max_height_in"])))
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(-0.6, n_cols - 0.4)
    ax.set_ylim(-half, half)
    ax.axis("off")
    box = dict(boxstyle="round,pad=0.4", fc="#e8eef7", ec="#33507a", lw=1.2)
    labels = {}
    for stem, (x, y) in pos.items():
        number = stem.split("_", 1)[0] + ("+" if stem == "05_penalty_contact" else "")
        labels[stem] = ax.text(x, y, f"{number}\n{chapters[stem].get('short', chapters[stem]['title'])}",
                               ha="center", va="center", fontsize=SLIDE["min_font_pt"], bbox=box, zorder=3,
                               family="DejaVu Sans")
    for stem, ns in needs.items():
        for n in ns:
            ax.annotate("", xy=pos[stem], xytext=pos[n], zorder=4,        # after the boxes: clipped to them
                        arrowprops=dict(arrowstyle="-|>", color="0.3", lw=1.3, mutation_scale=16, shrinkA=1,
                                        shrinkB=1, patchA=labels[n].get_bbox_patch(),
                                        patchB=labels[stem].get_bbox_patch()))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


# --- the sources ------------------------------------------------------------------------------------------------

_IMAGE_LINE = re.compile(r"^!\[([^\]\n]+)\]\(([^)\s]+)\)[ \t]*$", re.M)


def figure_markdown(text: str) -> str:
    """Markdown with each image that stands alone on its line, ``![text](path)``, turned into a MyST figure whose
    caption and alt text are that text (in Jupyter such an image shows as it is; in the book it gets a caption)."""
    return _IMAGE_LINE.sub(lambda m: f"```{{figure}} {m[2]}\n:alt: {_plain(m[1])}\n\n{m[1]}\n```", text)


def _plain(caption: str) -> str:
    """A caption as alt text: no TeX, emphasis or code marks."""
    return " ".join(re.sub(r"[$*`\\]", "", caption).split())


_HIDDEN = "# outputs of the cell above (MyST-NB skips a cell without source)"


def _figure_cell(output, caption: str):
    import nbformat

    cell = nbformat.v4.new_code_cell(_HIDDEN, metadata={"tags": ["remove-input"],
                                                   "mystnb": {"figure": {"caption": caption},
                                                              "image": {"alt": _plain(caption)}}})
    cell.outputs = [output]
    return cell


def caption_figures(nb):
    """Give every figure shown by :func:`refsph.teaching.notebook.show_figure` its caption and alt text in the
    book: the figure's output moves into a cell of its own (input hidden) whose MyST-NB metadata holds the caption
    and alt text; the outputs after it follow in another hidden-input cell, so a caption never applies to anything
    else. The caption's italic Markdown copy, which the notebook shows, is dropped. Images in Markdown cells become
    captioned figures (:func:`figure_markdown`). Returns ``nb``."""
    import nbformat

    cells = []
    for cell in nb.cells:
        cells.append(cell)
        if cell.cell_type == "markdown":
            cell.source = figure_markdown(cell.source)
        if cell.cell_type != "code":
            continue
        outputs, cell.outputs = cell.outputs, []
        current = cell
        for out in outputs:
            meta = out.get("metadata", {}).get(CAPTION_KEY, {})
            if meta.get("caption_text"):
                continue
            if meta.get("caption"):
                cells.append(_figure_cell(out, meta["caption"]))
                current = None
                continue
            if current is None:
                current = nbformat.v4.new_code_cell(_HIDDEN, metadata={"tags": ["remove-input"]})
                cells.append(current)
            current.outputs.append(out)
    nb.cells = cells
    return nb


def assemble(src: Path, notebooks: list[Path], reports: list[Path] | None = None) -> Path:
    """Lay the book's sources out in ``src`` (emptied first): the pages of ``book/`` (except conf.py, which
    Sphinx reads in place), ``chapters/`` with ``notebooks`` (their figures captioned, :func:`caption_figures`),
    ``benchmarks/`` with the reports (default: benchmarks/*_report.md; their images captioned,
    :func:`figure_markdown`) and the committed ``figures/``."""
    import nbformat

    root = repository_root()
    src = Path(src)
    shutil.rmtree(src, ignore_errors=True)
    (src / "chapters").mkdir(parents=True)
    (src / "benchmarks").mkdir()
    for page in book_folder().iterdir():
        if page.is_file() and page.suffix == ".md":
            shutil.copy(page, src / page.name)
    for path in notebooks:
        nbformat.write(caption_figures(nbformat.read(path, as_version=4)), src / "chapters" / (path.stem + ".ipynb"))
    for r in reports if reports is not None else sorted((root / "benchmarks").glob("*_report.md")):
        (src / "benchmarks" / r.name).write_text(figure_markdown(r.read_text(encoding="utf-8")), encoding="utf-8")
    if (root / "figures").exists():
        shutil.copytree(root / "figures", src / "figures")
    return src


def render(src: Path, out: Path) -> Path:
    """Render the sources in ``src`` into ``out`` with ``book/conf.py``, warnings as errors, and read the pages
    back (:func:`rendering_problems`); RuntimeError if either fails. Returns the path of index.html."""
    from sphinx.cmd.build import build_main

    code = build_main(["-W", "--keep-going", "-q", "-b", "html", "-c", str(book_folder()), str(src), str(out)])
    if code != 0:
        raise RuntimeError(f"the book did not build cleanly (sphinx exit {code}); see the warnings above")
    problems = rendering_problems(out)
    if problems:
        lines = [f"  {page}: {p}" for page, ps in problems.items() for p in ps[:5]]
        raise RuntimeError("the book built, but does not render everywhere:\n" + "\n".join(lines))
    return Path(out) / "index.html"


def build_book(out: Path | None = None, quick: bool = True, reuse: bool = True, jobs: int = 2) -> Path:
    """Execute the chapters that need it (``jobs`` at a time), then render the book into ``out`` (default
    build/book) with warnings as errors. Returns the path of its index.html."""
    root = repository_root()
    out = Path(out) if out is not None else root / "build" / "book"
    chapters = chapter_files()
    todo = [c for c in chapters if not (reuse and _fresh(c, quick))]
    with ThreadPoolExecutor(max(1, jobs)) as ex:
        for c, (_, s) in zip(todo, ex.map(lambda c: execute_chapter(c, quick), todo)):
            print(f"executed {c.name} in {s:.1f} s")
    src = assemble(root / "build" / "book-src", [executed_path(c) for c in chapters])
    return render(src, out)


# --- reading the built pages back -------------------------------------------------------------------------------

_SKIP_TAGS = {"script", "style", "pre", "code", "textarea", "head", "title"}
_VOID_TAGS = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}
RAW_TEX = re.compile(r"\\[A-Za-z]+|\\[()\[\]{}]|\$")
_HASH_NAME = re.compile(r"[0-9a-f]{16,}\.\w+$")


class _Page(HTMLParser):
    """The text of a page outside the elements MathJax typesets (class ``math``) and outside code, its images
    (attributes and whether each sits in a captioned figure) and its scripts' sources."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack: list[tuple[str, bool]] = []
        self.skipping = 0
        self.text: list[str] = []
        self.all_text: list[str] = []
        self.images: list[dict] = []
        self.scripts: list[str] = []
        self.figures: list[dict] = []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "img":
            self.images.append(dict(attrs, figure=self.figures[-1] if self.figures else None))
        if tag == "script" and attrs.get("src"):
            self.scripts.append(attrs["src"])
        if tag == "figure":
            self.figures.append({"caption": False})
        if tag == "figcaption" and self.figures:
            self.figures[-1]["caption"] = True
        if tag in _VOID_TAGS:
            return
        skip = tag in _SKIP_TAGS or "math" in (attrs.get("class") or "").split()
        self.stack.append((tag, skip))
        self.skipping += skip

    def handle_endtag(self, tag):
        if tag == "figure" and self.figures:
            self.figures.pop()
        while self.stack:
            name, skip = self.stack.pop()
            self.skipping -= skip
            if name == tag:
                break

    def handle_data(self, data):
        self.all_text.append(data)
        if not self.skipping:
            self.text.append(data)


def raw_tex(html: str) -> list[str]:
    """Fragments of TeX (a control word such as ``\\frac``, ``\\(``, a ``$``) in the text of a page outside the
    math MathJax typesets and outside code: what a reader sees raw. Each with 30 characters of context."""
    page = _Page()
    page.feed(html)
    text = "".join(page.text)
    return [" ".join(text[max(0, m.start() - 30):m.end() + 30].split()) for m in RAW_TEX.finditer(text)]


def _page_problems(html: str, machine_path: re.Pattern) -> list[str]:
    page = _Page()
    page.feed(html)
    problems = [f"raw TeX: ...{f}..." for f in raw_tex(html)]
    for img in page.images:
        alt = (img.get("alt") or "").strip()
        if not alt or _HASH_NAME.search(alt) or alt == img.get("src"):
            problems.append(f"an image without alt text: {img.get('src')}")
        if not (img["figure"] and img["figure"]["caption"]):
            problems.append(f"a figure without a caption: {img.get('src')}")
    problems += [f"MathJax from the network: {s}" for s in page.scripts if "mathjax" in s.lower() and "//" in s]
    problems += [f"a machine path: {m[0]}" for m in machine_path.finditer("".join(page.all_text))]
    return problems


def _machine_path() -> re.Pattern:
    """This machine's paths as a page may show them: the checkout, the home folder, and what Python, pytest and
    the chapters make in the temporary folder (not the folder's bare name, which instructions may use)."""
    tmp = re.escape(tempfile.gettempdir().rstrip("/"))
    return re.compile("|".join([re.escape(str(repository_root())) + r"[^\s<'\"]*",
                                re.escape(str(Path.home()).rstrip("/")) + r"/[^\s<'\"]*",
                                tmp + r"/(?:pytest-of-|tmp|refsph-)[^\s<'\"]*"]))


def rendering_problems(out: Path) -> dict[str, list[str]]:
    """{page: problems} of a built book: raw TeX outside math (:func:`raw_tex`), an image without alt text or
    outside a captioned figure, MathJax loaded from the network, or this machine's paths (the checkout, the home
    and temporary folders) in a page. Empty when the book renders everywhere."""
    out = Path(out)
    machine_path = _machine_path()
    problems = {}
    for page in sorted(out.rglob("*.html")):
        if page.parent.name.startswith("_") or page.name in ("genindex.html", "search.html"):
            continue
        rel = page.relative_to(out)
        found = _page_problems(page.read_text(encoding="utf-8"), machine_path)
        if found:
            problems[str(rel)] = found
    return problems
