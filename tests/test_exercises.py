"""Chapters are lessons: at most ~600 lines of code and markdown, no markdown cell over ~250 words, a set-up cell
of at most 12 lines, and a "Your turn" section of 2-4 exercises.

Exercises that teach (issue 25): every exercise keeps its expected result in a collapsed block (``<details><summary>
What you should see</summary> ... </details>``, closed in Jupyter and in the book, so "predict first" can work), at
least one exercise is a graded "write it yourself" task (a stub that raises NotImplementedError, checked by
:func:`refsph.teaching.grader.check` against the package), and the worked solutions live apart from the student's
copy, in ``chapters/solutions/NN_name.py`` (one ``### Solution N`` per exercise). The lecturer's copy, the chapter
with its solutions merged in (:mod:`refsph.teaching.handout`), runs in quick mode in tests/test_chapters.py (one run
for both copies): the handed-out stub fails its grader, the worked solution passes it, and every solution's asserts
hold, so no solution can rot. Every chapter
has its worked solutions (the answer keys of the first version, test scripts beside the student's copy, are gone)."""
import re
from pathlib import Path

import pytest

from refsph.teaching.book import chapter_files
from refsph.teaching.handout import SOLUTION, solutions_path

ROOT = Path(__file__).resolve().parent.parent
CHAPTERS = chapter_files()
MAX_LINES, MAX_WORDS = 600, 250
HIDDEN = re.compile(r"<details><summary>What you should see</summary>\n\n.+?\n</details>", re.S)
TEACHING = CHAPTERS


def cells(path: Path):
    """(kind, text, tags) of each cell of a percent-format chapter."""
    jupytext = pytest.importorskip("jupytext")
    return [(c.cell_type, c.source, c.metadata.get("tags", [])) for c in jupytext.read(path).cells]


def exercise_sections(path: Path) -> dict:
    """{N: the text of exercise N's cells, from its heading to the next exercise's or the end}."""
    sections, current = {}, None
    for kind, text, _ in cells(path):
        parts = re.split(r"(?m)^(?=### Exercise \d)", text) if kind == "markdown" else [text]
        for part in parts:
            m = re.match(r"### Exercise (\d+)", part)
            if m:
                current = int(m.group(1))
                sections[current] = ""
            if current is not None:
                sections[current] += part + "\n"
    return sections


@pytest.mark.parametrize("path", CHAPTERS, ids=[p.stem for p in CHAPTERS])
def test_chapter_is_a_lesson(path):
    cs = cells(path)
    n_lines = sum(len(text.splitlines()) for _, text, _ in cs)
    assert n_lines <= MAX_LINES, f"{path.name}: {n_lines} lines of code and markdown (at most {MAX_LINES})"
    for kind, text, _ in cs:
        if kind == "markdown":
            words = len(re.findall(r"\S+", text))
            assert words <= MAX_WORDS, f"{path.name}: a markdown cell of {words} words: {text[:80]!r}"
    code = [text for kind, text, _ in cs if kind == "code"]
    assert "chapter(" in code[0] and len(code[0].splitlines()) <= 12, "the first code cell sets the chapter up"
    md = "\n".join(text for kind, text, _ in cs if kind == "markdown")
    assert "## Your turn" in md, f"{path.name} has no 'Your turn' section"
    n_ex = len(re.findall(r"^### Exercise \d", md, re.M))
    assert 2 <= n_ex <= 4, f"{path.name}: {n_ex} exercises (2-4)"
    sol = solutions_path(path)
    assert sol.exists(), f"{path.name}: no worked solutions in {sol}"
    numbers = sorted(int(n) for kind, text, _ in cells(sol) if kind == "markdown" for n in SOLUTION.findall(text))
    assert numbers == list(range(1, n_ex + 1)), f"{sol}: solutions {numbers} for exercises 1-{n_ex}"
    for kind, text, _ in cells(sol):
        words = len(re.findall(r"\S+", text))
        assert kind != "markdown" or words <= MAX_WORDS, f"{sol.name}: a markdown cell of {words} words"


@pytest.mark.parametrize("path", CHAPTERS, ids=[p.stem for p in CHAPTERS])
def test_exercises_teach(path):
    """Predict -> run -> compare: every exercise's expected result is hidden in a collapsed block after its cell (never
    the next visible text), at least one exercise is a graded stub, and the worked solutions live apart."""
    assert solutions_path(path).exists(), f"no worked solutions in {solutions_path(path)}"
    sections = exercise_sections(path)
    for n, text in sections.items():
        assert HIDDEN.search(text), f"{path.name}, exercise {n}: no collapsed 'What you should see' block"
        assert "What you should see" not in HIDDEN.sub("", text), \
            f"{path.name}, exercise {n}: an expected result outside the collapsed block"
    graded = [text for kind, text, tags in cells(path)
              if kind == "code" and "exercise" in tags and "raise NotImplementedError" in text and "check(" in text]
    assert graded, f"{path.name}: no graded 'write it yourself' task (a stub that raises NotImplementedError, "\
                   "and a check(...) call)"


FORMULA_FILES = CHAPTERS + [solutions_path(p) for p in TEACHING]


@pytest.mark.parametrize("path", FORMULA_FILES, ids=[p.parent.name + "/" + p.stem for p in FORMULA_FILES])
def test_no_formula_line_reads_as_a_markdown_bullet(path):
    """A wrapped line of TeX that starts with '+ \\...' or '- \\...' is a Markdown bullet: the book then shows raw TeX
    (chapter 03's Jaumann rate did). Keep the operator at the end of the line before."""
    bad = [f"{path.name}:{k}: {line.strip()}" for k, line in enumerate(path.read_text().splitlines(), 1)
           if re.match(r"#\s+[-+*]\s+\\", line)]
    assert not bad, bad
