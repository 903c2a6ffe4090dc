"""The chapters' grader (refsph.teaching.grader) and hand-out (refsph.teaching.handout), issue 25: the grader passes a
right answer, fails a wrong one with a message that names the case, the output, the element, the values and the
tolerance, and never raises for a student's mistake; the lecturer's copy puts every solution right after its exercise;
handing out never overwrites a student's notebook."""
import numpy as np
import pytest

from refsph.teaching.grader import Report, case, check


def ref(x, h):
    return np.sin(x) * h, np.cos(x)


CASES = [case(np.linspace(0.0, 1.0, 5), 2.0, label="five points"), (np.array([0.0, -1.0]), 1.0), {"x": 3.0, "h": 0.5}]


def test_a_right_answer_passes(capsys):
    rep = check(lambda x, h: (h * np.sin(x), np.cos(x)), ref, CASES, names=("a", "b"))
    assert rep and isinstance(rep, Report) and rep.n_passed == rep.n_cases == 3
    assert "PASS" in capsys.readouterr().out


@pytest.mark.parametrize("student, words", [
    (lambda x, h: (h * np.sin(x), np.cos(x) + 1e-3), ["case 1 (five points)", "b:", "element (0,)", "got 1.001",
                                                      "expected 1", "allowed", "rtol = 1e-10"]),
    (lambda x, h: (h * np.sin(x),), ["returned 1 value, expected 2"]),
    (lambda x, h: (h * np.sin(x), np.cos(x)[None]), ["shape (1, 5), expected (5,)"]),
    (lambda x, h: (h * np.sin(x) / 0.0, np.cos(x)), ["nan", "division by zero"]),
    (lambda x, h: None, ["returned 1 value, expected 2"]),
    (lambda x, h: (h * np.sin(x), "cos"), ["not an array of numbers"]),
    (lambda x, h: 1 / 0, ["case 1 (five points) raised ZeroDivisionError"]),
])
def test_a_wrong_answer_fails_with_a_message(student, words, capsys):
    rep = check(student, ref, CASES, names=("a", "b"))
    out = capsys.readouterr().out
    assert not rep and out.startswith("FAIL") and rep.message in out
    for w in words:
        assert w in out, (w, out)


def test_a_stub_is_not_written_yet(capsys):
    def stub(x, h):
        raise NotImplementedError("write it here")

    rep = check(stub, ref, CASES)
    assert not rep and rep.n_passed == 0 and "not written yet (NotImplementedError: write it here)" in rep.message


def test_the_tolerance_and_the_inputs():
    assert check(lambda x, h: ref(x, h)[0] * (1 + 1e-12), lambda x, h: ref(x, h)[0], CASES, quiet=True)
    assert not check(lambda x, h: ref(x, h)[0] * (1 + 1e-8), lambda x, h: ref(x, h)[0], CASES, quiet=True)
    assert check(lambda x, h: ref(x, h)[0] + 1e-7, lambda x, h: ref(x, h)[0], CASES, atol=1e-6, quiet=True)
    assert not check(lambda x: x > 0, lambda x: x >= 0, [(np.array([0.0, 1.0]),)], quiet=True)   # booleans: equal
    x = np.ones(3)

    def spoils(a):
        a[:] = 5.0                            # writes into its input: the reference still sees ones
        return a

    assert not check(spoils, lambda a: a.copy(), [(x,)], quiet=True) and np.all(x == 1.0)


def test_a_broken_reference_raises():
    with pytest.raises(ZeroDivisionError):
        check(lambda x: x, lambda x: 1 / 0, [(1.0,)], quiet=True)


def test_the_lecturers_copy_and_the_handout(tmp_path):
    pytest.importorskip("jupytext")
    from refsph.cli import main
    from refsph.teaching.book import chapter_files
    from refsph.teaching.handout import instructor_notebook, solutions_path, write_handout

    chapter = next(p for p in chapter_files() if solutions_path(p).exists())
    nb = instructor_notebook(chapter)
    heads = [k for k, c in enumerate(nb.cells) if c.cell_type == "markdown" and c.source.startswith(("### Exercise",
                                                                                                   "### Solution"))]
    order = [nb.cells[k].source.split(" —")[0] for k in heads]
    n = len(order) // 2
    assert order == [f"### {w} {i}" for i in range(1, n + 1) for w in ("Exercise", "Solution")]
    assert all("solution" in c.metadata["tags"] for c in nb.cells[heads[1]:heads[2]])
    assert main(["handout", str(tmp_path), "--only", chapter.stem[:2]]) == 0
    written = tmp_path / (chapter.stem + ".ipynb")
    assert written.exists() and "### Solution" not in written.read_text()
    written.write_text("a student's edits")
    assert write_handout(tmp_path, instructor=True, only=[chapter.stem]) == []      # kept, not overwritten
    assert written.read_text() == "a student's edits"
    assert write_handout(tmp_path, instructor=True, only=[chapter.stem], force=True) == [written]
    assert "### Solution 1" in written.read_text()
