"""Every chapter runs as a notebook in quick mode in under a minute, its own checks pass, it is a lesson of a
teachable size, and it ends with exercises whose answer key runs (one run of the lecturer's copy checks both, see
:func:`test_chapter_runs_quick`; the lesson's shape is checked in tests/test_exercises.py).

Chapters are jupytext percent-format .py files; each one compares the package's fast code with its plain
pair-by-pair version in ``assert`` cells, so a failing comparison fails this test. The executed notebooks are
kept in build/executed/ for the book (``refsph book``).

One chapter per test: the default run's two xdist workers share them, each worker pinned to a core of its own
(tests/conftest.py), so a chapter's kernel, which inherits its worker's core, takes the wall time a student's
one-core run would, and refsph's pair sums in it see one core."""
import pytest

from refsph.teaching.book import chapter_files, save_executed
from refsph.teaching.handout import cell_seconds, execute, instructor_notebook, names_from_solutions, student_part
from refsph.teaching.notebook import shown_figure_problems

CHAPTERS = chapter_files()


@pytest.mark.parametrize("path", CHAPTERS, ids=[p.stem for p in CHAPTERS])
def test_chapter_runs_quick(path, tmp_path):
    """One run of the lecturer's copy (the chapter with its worked solutions after its exercises) in quick mode
    checks both copies: the student's cells run in it in their order, none of them reads a name that only a
    solution binds (so they run the same without the solutions), and they take under a minute (the run's wall
    time, kernel start included, less the solution cells' own seconds); the stub as handed out fails its grader
    without stopping the notebook, the worked solution passes, and every asserted number of the solutions holds.
    Every figure it shows fits a slide (measured as drawn). The student's part, executed, is kept in build/executed/
    for the book."""
    pytest.importorskip("jupytext")
    pytest.importorskip("nbclient")
    nb = instructor_notebook(path)
    assert not names_from_solutions(nb), f"{path.name}: the chapter reads {names_from_solutions(nb)} from a solution"
    wall = execute(nb, quick=True, timeout=600, cwd=path.parent, figures=tmp_path / "figures")
    solving = [cell_seconds(c) for c in nb.cells if "solution" in c.metadata.get("tags", [])]
    seconds = wall - sum(solving)
    assert seconds < 60.0, f"{path.name} took {seconds:.1f} s in quick mode (limit 60 s)"
    save_executed(path, student_part(nb), seconds, quick=True)

    def text(cell):
        return "".join(o.get("text", "") for o in cell.get("outputs", []))

    stubs = [c for c in nb.cells if c.cell_type == "code" and "exercise" in c.metadata.get("tags", [])
             and "raise NotImplementedError" in c.source]
    solved = "".join(text(c) for c in nb.cells if "solution" in c.metadata.get("tags", []))
    assert stubs and all("FAIL" in text(c) and "not written yet" in text(c) for c in stubs)
    assert solved.count("PASS") >= len(stubs), "each graded task's worked solution passes its grader"
    _, bad = shown_figure_problems(nb)                 # every figure shown, measured as drawn (tests/test_figures.py)
    assert not bad, f"{path.name}: figures that do not fit a slide: {bad}"
    assert any(t > 0 for t in solving), "nbclient recorded no cell timing (the solutions' seconds unknown)"


def test_a_chapter_that_reads_a_solution_is_caught():
    """The check behind running the lecturer's copy for both: a student's cell that reads a name only a solution
    defines is reported; one that defines it first is not."""
    import nbformat

    def cell(src, solution=False):
        return nbformat.v4.new_code_cell(src, metadata={"tags": ["solution"]} if solution else {})

    nb = nbformat.v4.new_notebook(cells=[cell("a = 1"), cell("b = a + 1", True), cell("print(b)")])
    assert names_from_solutions(nb) == {"b"}
    nb.cells[2] = cell("b = 2\nprint(b)")
    assert not names_from_solutions(nb)


def test_chapters_exist():
    names = {p.stem for p in CHAPTERS}
    for stem in ("01_kernel", "02_esph", "03_tlsph", "04_johnson_cook", "05_contact", "06_taylor", "07_pressing",
                 "08_cutting", "09_cross_check", "10_where_sph_breaks", "11_thermal_cutting"):
        assert stem in names
