"""Chapters are lessons: at most ~600 lines of code and markdown, no markdown cell over ~250 words, three lines of
set-up, and a "Your turn" section of 2-4 exercises whose answer key (chapters/answers/NN_name.py, functions
answer_1, answer_2, ...) runs here in quick mode, so an answer cannot rot."""
import importlib.util
import re
from pathlib import Path

import pytest

from refsph.teaching.book import chapter_files

ROOT = Path(__file__).resolve().parent.parent
CHAPTERS = chapter_files()
MAX_LINES, MAX_WORDS = 600, 250


def cells(path: Path):
    """(kind, text) of each cell of a percent-format chapter."""
    jupytext = pytest.importorskip("jupytext")
    return [(c.cell_type, c.source) for c in jupytext.read(path).cells]


def answers_module(path: Path):
    key = ROOT / "chapters" / "answers" / path.name
    spec = importlib.util.spec_from_file_location(f"answers_{path.stem}", key)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("path", CHAPTERS, ids=[p.stem for p in CHAPTERS])
def test_chapter_is_a_lesson(path):
    cs = cells(path)
    n_lines = sum(len(text.splitlines()) for _, text in cs)
    assert n_lines <= MAX_LINES, f"{path.name}: {n_lines} lines of code and markdown (at most {MAX_LINES})"
    for kind, text in cs:
        if kind == "markdown":
            words = len(re.findall(r"\S+", text))
            assert words <= MAX_WORDS, f"{path.name}: a markdown cell of {words} words: {text[:80]!r}"
    code = [text for kind, text in cs if kind == "code"]
    assert "chapter(" in code[0] and len(code[0].splitlines()) <= 12, "the first code cell sets the chapter up"
    md = "\n".join(text for kind, text in cs if kind == "markdown")
    assert "## Your turn" in md, f"{path.name} has no 'Your turn' section"
    n_ex = len(re.findall(r"^### Exercise \d", md, re.M))
    assert 2 <= n_ex <= 4, f"{path.name}: {n_ex} exercises (2-4)"
    answers = [n for n in dir(answers_module(path)) if re.fullmatch(r"answer_\d+", n)]
    assert len(answers) == n_ex, f"{path.name}: {n_ex} exercises but {len(answers)} answers"


@pytest.mark.parametrize("path", CHAPTERS, ids=[p.stem for p in CHAPTERS])
def test_answer_key_runs(path, monkeypatch, tmp_path):
    monkeypatch.setenv("REFSPH_QUICK", "1")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.chdir(tmp_path)
    mod = answers_module(path)
    for name in sorted(n for n in dir(mod) if re.fullmatch(r"answer_\d+", n)):
        getattr(mod, name)()                 # each asserts what the student should see


@pytest.mark.parametrize("path", CHAPTERS, ids=[p.stem for p in CHAPTERS])
def test_no_formula_line_reads_as_a_markdown_bullet(path):
    """A wrapped line of TeX that starts with '+ \\...' or '- \\...' is a Markdown bullet: the book then shows raw TeX
    (chapter 03's Jaumann rate did). Keep the operator at the end of the line before."""
    bad = [f"{path.name}:{k}: {line.strip()}" for k, line in enumerate(path.read_text().splitlines(), 1)
           if re.match(r"#\s+[-+*]\s+\\", line)]
    assert not bad, bad
