"""The student's copy and the lecturer's copy of the chapters (issue 25).

* **The student's copy** of a chapter is the chapter itself, ``chapters/NN_name.py``. Its exercises ask for a
  prediction first and keep the expected result in a collapsed block (``<details><summary>What you should
  see</summary> ... </details>``: closed in Jupyter and in the book until clicked); its "write it yourself" task
  hands out a stub that the grader (:mod:`refsph.teaching.grader`) reports as not written yet.
* **The worked solutions** live apart, in ``chapters/solutions/NN_name.py`` (the lecturer's folder, jupytext
  percent format like the chapters): for exercise N a markdown cell that starts ``### Solution N`` and explains,
  and code cells that run in the chapter's namespace, on the chapter's own case, and assert what the student should
  have seen. They do not run on their own.
* **The lecturer's copy** is the chapter with each solution inserted right after its exercise
  (:func:`instructor_notebook`; the inserted cells are tagged ``solution``).

    refsph handout DIR                 # the students' notebooks, DIR/NN_name.ipynb: no solutions
    refsph handout DIR --instructor    # the lecturer's: every exercise followed by its worked solution

Neither overwrites a notebook that is already there (a student's edited copy) unless ``--force``. The tests
(``tests/test_exercises.py``) execute every lecturer's copy in quick mode (:func:`execute`): the handed-out stub
fails its grader, the worked solution passes it, and the solutions' asserts hold, so a solution cannot rot.
"""
from __future__ import annotations

import copy
import os
import re
import time
from pathlib import Path

from .notebook import repository_root

__all__ = ["solutions_path", "student_notebook", "instructor_notebook", "execute", "cell_seconds", "student_part",
           "names_from_solutions", "write_handout"]

EXERCISE = re.compile(r"^### Exercise (\d+)", re.M)
SOLUTION = re.compile(r"^### Solution (\d+)", re.M)


def solutions_path(chapter: Path) -> Path:
    """``chapters/solutions/NN_name.py`` of a chapter (it may not exist)."""
    return Path(chapter).parent / "solutions" / Path(chapter).name


def student_notebook(chapter: Path):
    """The student's copy: the chapter as a notebook (nbformat), as it is."""
    import jupytext

    return jupytext.read(chapter)


def _split_at_exercises(cells) -> list:
    """Markdown cells split so that every '### Exercise N' heading starts a cell of its own."""
    import nbformat

    out = []
    for c in cells:
        starts = [m.start() for m in EXERCISE.finditer(c.source)] if c.cell_type == "markdown" else []
        cuts = [0] + [s for s in starts if s > 0] + [len(c.source)]
        if len(cuts) == 2:
            out.append(c)
            continue
        for a, b in zip(cuts[:-1], cuts[1:]):
            out.append(nbformat.v4.new_markdown_cell(c.source[a:b].strip("\n"), metadata=copy.deepcopy(c.metadata)))
    return out


def solution_cells(chapter: Path) -> dict:
    """{N: [cells]} of the chapter's solutions file ({} if it has none); cells before '### Solution 1' (the file's
    introduction) are left out."""
    import jupytext

    path = solutions_path(chapter)
    if not path.exists():
        return {}
    groups, current = {}, None
    for c in jupytext.read(path).cells:
        m = SOLUTION.search(c.source) if c.cell_type == "markdown" else None
        if m:
            current = int(m.group(1))
            groups.setdefault(current, [])
        if current is not None:
            c = copy.deepcopy(c)
            c.metadata["tags"] = sorted(set(c.metadata.get("tags", [])) | {"solution"})
            groups[current].append(c)
    return groups


def instructor_notebook(chapter: Path):
    """The lecturer's copy: the chapter with the cells of '### Solution N' inserted after exercise N (before the
    next exercise's heading, or at the end). Raises ValueError if a solution has no exercise or the reverse."""
    import nbformat

    nb = student_notebook(chapter)
    sols = solution_cells(chapter)
    if not sols:
        return nb
    cells = _split_at_exercises(nb.cells)
    heads = {int(m.group(1)): k for k, c in enumerate(cells) if c.cell_type == "markdown"
             for m in [EXERCISE.match(c.source)] if m}
    if sorted(heads) != sorted(sols):
        raise ValueError(f"{Path(chapter).name}: exercises {sorted(heads)} but solutions {sorted(sols)} "
                         f"in {solutions_path(chapter)}")
    order = sorted(heads, key=heads.get)                     # exercise numbers in the order they appear
    merged, last = [], 0
    for n, end in zip(order, [heads[m] for m in order[1:]] + [len(cells)]):
        merged += cells[last:end] + sols[n]                  # exercise n's cells, then its solution
        last = end
    note = nbformat.v4.new_markdown_cell(
        f"**Lecturer's copy** of `{Path(chapter).name}`: after each exercise its worked solution from "
        f"`chapters/solutions/{Path(chapter).name}` (cells tagged `solution`). Hand out the student's copy "
        "(`refsph handout DIR`), not this one.", metadata={"tags": ["solution"]})
    nb.cells = merged[:1] + [note] + merged[1:]
    return nb


def execute(nb, quick: bool = True, timeout: int = 600, cwd: Path | None = None, figures: Path | None = None):
    """Run a notebook in a fresh kernel (quick mode by default), in place; returns the seconds it took. An exception
    in a cell raises nbclient's CellExecutionError. ``figures``: where the chapter's figures go."""
    import nbclient

    env = dict(os.environ, REFSPH_QUICK="1" if quick else "0", MPLBACKEND="module://matplotlib_inline.backend_inline")
    if figures is not None:
        env["REFSPH_FIGURES"] = str(figures)
    cwd = cwd or repository_root() / "chapters"
    client = nbclient.NotebookClient(nb, timeout=timeout, kernel_name="python3",
                                     resources={"metadata": {"path": str(cwd)}})
    t0 = time.perf_counter()
    client.execute(env=env)
    return time.perf_counter() - t0


def cell_seconds(cell) -> float:
    """The seconds a cell of an executed notebook ran (nbclient's timing: the kernel busy to idle); 0 if unrecorded."""
    from datetime import datetime

    t = cell.get("metadata", {}).get("execution", {})
    start, end = t.get("iopub.status.busy"), t.get("iopub.status.idle") or t.get("shell.execute_reply")
    if not (start and end):
        return 0.0
    return (datetime.fromisoformat(end.replace("Z", "+00:00"))
            - datetime.fromisoformat(start.replace("Z", "+00:00"))).total_seconds()


def student_part(nb):
    """The student's copy inside an executed lecturer's copy: its cells without those tagged ``solution`` (their
    outputs kept), for the book."""
    out = copy.deepcopy(nb)
    out.cells = [c for c in out.cells if "solution" not in c.metadata.get("tags", [])]
    return out


def _bound_and_used(source: str) -> tuple[set, set]:
    """(names a cell binds, names it reads) of a code cell (IPython's % and ! lines left out)."""
    import ast

    code = "\n".join(line for line in source.splitlines() if not line.lstrip().startswith(("%", "!")))
    bound, used = set(), set()
    for node in ast.walk(ast.parse(code)):
        if isinstance(node, ast.Name):
            (used if isinstance(node.ctx, ast.Load) else bound).add(node.id)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            bound.add(node.name)
        elif isinstance(node, ast.arg) or (isinstance(node, ast.ExceptHandler) and node.name):
            bound.add(node.arg if isinstance(node, ast.arg) else node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            bound.update((a.asname or a.name).split(".")[0] for a in node.names)
    return bound, used


def names_from_solutions(nb) -> set:
    """The names a student's cell of the lecturer's copy reads that only a worked solution before it binds: such a
    cell would fail in the student's copy, so a run of the lecturer's copy stands for a run of the student's only
    when this is empty."""
    own, from_solutions, missing = set(), set(), set()
    for c in nb.cells:
        if c.cell_type != "code":
            continue
        bound, used = _bound_and_used(c.source)
        if "solution" in c.metadata.get("tags", []):
            from_solutions |= bound - own
        else:
            missing |= (used & from_solutions) - own - bound
            own |= bound
    return missing


def write_handout(out: Path, instructor: bool = False, only: list[str] | None = None, force: bool = False) -> list:
    """Write every chapter (or those whose name starts with one of ``only``, e.g. '03') as a notebook into
    ``out``: the student's copy, or with ``instructor`` the lecturer's. A notebook that exists is kept (a student's
    edits) unless ``force``; returns the paths written."""
    import nbformat

    from .book import chapter_files

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    chapters = [c for c in chapter_files() if not only or any(c.stem.startswith(o) for o in only)]
    if only and not chapters:
        raise ValueError(f"no chapter starts with {', '.join(only)} (see chapters/)")
    written, kept = [], []
    for c in chapters:
        target = out / (c.stem + ".ipynb")
        if target.exists() and not force:
            kept.append(target)
            continue
        nbformat.write(instructor_notebook(c) if instructor else student_notebook(c), target)
        written.append(target)
    for k in kept:
        print(f"kept {k} (it exists: a student's edits are not overwritten; --force replaces it)")
    return written
