"""benchmarks/ stands on one scaffold (benchmarks/study.py): every study script pins its thread pools with
``study.pin_threads()`` before NumPy (or refsph) is imported, runs its processes through ``study`` rather than a pool
of its own, writes no markdown-table helper or thread variable of its own, and keeps every function under 80 lines
(the rule tests/test_architecture.py applies to refsph/)."""
import ast
import json
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parent.parent / "benchmarks"
SCAFFOLD = "study.py"
SCRIPTS = sorted(p for p in BENCH.glob("*.py") if p.name != SCAFFOLD)
MAX_LINES = 80
HEAVY = ("numpy", "scipy", "refsph", "matplotlib")


def long_functions(path: Path) -> list[str]:
    """'name (N lines)' for each function of the file with MAX_LINES lines or more."""
    tree = ast.parse(path.read_text())
    return [f"{n.name} ({n.end_lineno - n.lineno + 1} lines)" for n in ast.walk(tree)
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and n.end_lineno - n.lineno + 1 >= MAX_LINES]


def _imports(node) -> list[str]:
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
        return [node.module]
    return []


def pinning_problem(path: Path) -> str | None:
    """None if the script calls study.pin_threads() at module level before any heavy import, else what is wrong."""
    tree = ast.parse(path.read_text())
    for node in tree.body:
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Call):
            f = node.value.func
            if isinstance(f, ast.Attribute) and f.attr == "pin_threads" and getattr(f.value, "id", None) == "study":
                return None
        heavy = [m for m in _imports(node) if m.split(".")[0] in HEAVY]
        if heavy:
            return f"imports {heavy[0]} (line {node.lineno}) before study.pin_threads()"
    return "never calls study.pin_threads() at module level"


def copied_scaffolding(path: Path) -> list[str]:
    """Scaffolding the script writes itself instead of taking it from study.py."""
    text = path.read_text()
    found = [s for s in ("OMP_NUM_THREADS", "def _md_table", "def md_table", "ProcessPoolExecutor", "fcntl")
             if s in text]
    return found


def test_there_are_scripts():
    assert len(SCRIPTS) >= 10 and (BENCH / SCAFFOLD).exists()


@pytest.mark.parametrize("path", SCRIPTS + [BENCH / SCAFFOLD], ids=lambda p: p.name)
def test_no_function_of_80_lines(path):
    assert long_functions(path) == [], f"{path.name}: functions of {MAX_LINES} lines or more"


@pytest.mark.parametrize("path", SCRIPTS, ids=lambda p: p.name)
def test_every_study_pins_its_threads_with_the_scaffold(path):
    assert pinning_problem(path) is None, f"{path.name}: {pinning_problem(path)}"


@pytest.mark.parametrize("path", SCRIPTS, ids=lambda p: p.name)
def test_no_copied_scaffolding(path):
    assert copied_scaffolding(path) == [], f"{path.name} writes its own {copied_scaffolding(path)}: use study.py"


def test_the_checks_can_fail(tmp_path):
    """Each check finds what it is for in a script that has it."""
    bad = tmp_path / "bad.py"
    body = "\n".join(f"    x{k} = {k}" for k in range(MAX_LINES))
    bad.write_text(f"import numpy as np\nimport study\nstudy.pin_threads()\n\n\ndef f():\n{body}\n"
                   "import os\nos.environ['OMP_NUM_THREADS'] = '1'\n")
    assert long_functions(bad) == [f"f ({MAX_LINES + 1} lines)"]
    assert pinning_problem(bad).startswith("imports numpy")
    assert copied_scaffolding(bad) == ["OMP_NUM_THREADS"]
    bad.write_text("import json\n")
    assert pinning_problem(bad) == "never calls study.pin_threads() at module level"


def _study():
    import sys
    if str(BENCH) not in sys.path:
        sys.path.insert(0, str(BENCH))
    import study
    return study


def test_run_store_keeps_good_records_and_reads_the_committed_format(tmp_path):
    """A failed run never replaces a good record; a rerun skips what is recorded; the committed records load."""
    study = _study()
    committed = study.RunStore(BENCH / "thermal_cutting_pinball_tu5.json")     # issue 19's finished sweep
    assert committed.load()["runs"]["case 1"]["status"] == "ok"
    assert committed.pending(["case 1", "case 99"]) == ["case 99"]
    store = study.RunStore(tmp_path / "runs.json")
    assert store.commit("a", dict(status="ok", value=1.0))
    assert not store.commit("a", dict(status="failed: RuntimeError: boom"))
    doc = json.loads((tmp_path / "runs.json").read_text())
    assert doc["runs"]["a"] == dict(status="ok", value=1.0) and doc["failed"]["a"]["status"].startswith("failed")
    assert store.commit("b", dict(status="failed: x")) and store.pending(["a", "b", "c"]) == ["c"]
    assert store.pending(["a", "b", "c"], retry_failed=True) == ["b", "c"]
    assert store.pending(["a"], redo=["a"]) == ["a"]
    assert not list(tmp_path.glob("*.tmp"))                       # written atomically: no temporary file left


def test_run_store_merges_another_sweeps_records_without_losing_a_good_one(tmp_path):
    """--merge: a key missing here is added, a good record there replaces a failed one here (which is kept under
    'failed'), and a good record here is never replaced, by a failed one or by a different good one."""
    study = _study()
    here, there = study.RunStore(tmp_path / "here.json"), study.RunStore(tmp_path / "there.json")
    for key, rec in (("good", dict(status="ok", v=1)), ("failed", dict(status="failed: x")),
                     ("good vs failed", dict(status="ok", v=2)), ("same", dict(status="ok", v=3))):
        here.commit(key, rec)
    for key, rec in (("new", dict(status="ok", v=4)), ("failed", dict(status="ok", v=5)),
                     ("good vs failed", dict(status="failed: y")), ("good", dict(status="ok", v=6)),
                     ("same", dict(status="ok", v=3))):
        there.commit(key, rec)
    out = here.merge(tmp_path / "there.json")
    assert out == {"added": ["new"], "replaced": ["failed"], "kept": ["good", "good vs failed"]}
    doc = here.load()
    assert doc["runs"]["new"]["v"] == 4 and doc["runs"]["failed"]["v"] == 5 and doc["runs"]["good"]["v"] == 1
    assert doc["runs"]["good vs failed"]["v"] == 2 and doc["failed"]["failed"]["status"] == "failed: x"
    assert here.merge(tmp_path / "there.json") == {"added": [], "replaced": [], "kept": ["good", "good vs failed"]}
    before = (tmp_path / "here.json").read_text()
    (tmp_path / "bad.json").write_text("{bad")
    for other in (tmp_path / "missing.json", tmp_path / "bad.json"):
        with pytest.raises(ValueError, match=str(other.name)):
            here.merge(other)
    assert (tmp_path / "here.json").read_text() == before


def test_execute_runs_each_task_and_records_a_crash():
    """Fresh processes: every task's result comes back under its key; a task that raises gives a failed record."""
    import math
    out = dict(_study().execute(math.sqrt, {"four": (4.0,), "minus one": (-1.0,)}, jobs=2))
    assert out["four"] == 2.0
    assert out["minus one"]["status"].startswith("failed: ValueError")


def test_page_fills_its_sections():
    page = _study().Page("taylor_report")
    assert page("cost_of_dt", steps="3.7", wall="5.2") == "; 3.7 times the steps, 5.2 times the wall time"
    with pytest.raises(KeyError):
        page("cost_of_dt", steps="3.7")


def _bench(name):
    import importlib.util
    spec = importlib.util.spec_from_file_location(f"bench_{name}", BENCH / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_a_partial_rerun_that_runs_nothing_changes_no_file(tmp_path, monkeypatch, capsys):
    """issue 23: `lammps_crosscheck.py --only bar-lammps bar-refsph` in a fresh clone (no run folders, no LAMMPS or
    the cases recorded) leaves the committed JSON and report as they are, byte for byte."""
    mod = _bench("lammps_crosscheck")
    json_copy, report_copy = tmp_path / "x.json", tmp_path / "x.md"
    json_copy.write_bytes(mod.OUT_JSON.read_bytes())
    report_copy.write_bytes(mod.REPORT.read_bytes())
    monkeypatch.setattr(mod, "STORE", _study().RunStore(json_copy, section="cases"))
    monkeypatch.setattr(mod, "REPORT", report_copy)
    monkeypatch.setattr(mod, "RUNS", tmp_path / "no_runs")
    assert mod.main(["--only", "bar-lammps", "bar-refsph"]) == 0
    assert json_copy.read_bytes() == mod.OUT_JSON.read_bytes()
    assert report_copy.read_bytes() == mod.REPORT.read_bytes()
    assert "nothing ran" in capsys.readouterr().out


def test_a_comparison_that_fails_now_keeps_the_committed_one(monkeypatch, tmp_path):
    mod = _bench("lammps_crosscheck")
    a, b = mod.PAIRS[0]
    for n in (a, b):
        (tmp_path / n / "run").mkdir(parents=True)
    monkeypatch.setattr(mod, "RUNS", tmp_path)
    monkeypatch.setattr(mod, "compare_pair", lambda x, y: (2, "refsph: a run folder is incomplete"))
    old = {f"{a} vs {b}": dict(exit_code=0, table="the committed table")}
    cases = {a: dict(status="ok"), b: dict(status="ok")}
    assert mod.comparisons(cases, old, ran=[a]) == old
    monkeypatch.setattr(mod, "compare_pair", lambda x, y: (1, "a new table"))
    assert mod.comparisons(cases, old, ran=[a])[f"{a} vs {b}"] == dict(exit_code=1, table="a new table")
    assert mod.comparisons(cases, old, ran=["something else"]) == old


def test_merge_records_keeps_what_a_partial_rerun_did_not_redo():
    study = _study()
    committed = [dict(name="a", status="ok", v=1), dict(name="b", status="ok", v=2), dict(name="c", status="ok", v=3)]
    fresh = [dict(name="b", status="ok", v=20), dict(name="c", status="failed: boom"), dict(name="d", status="ok")]
    merged = study.merge_records(committed, fresh)
    assert merged == [dict(name="a", status="ok", v=1), dict(name="b", status="ok", v=20),
                      dict(name="c", status="ok", v=3), dict(name="d", status="ok")]


def test_a_taylor_rerun_in_a_fresh_clone_drops_no_record(tmp_path, monkeypatch):
    """taylor.py --plot-only with no run folders (a fresh clone): the committed JSON stays byte for byte."""
    mod = _bench("taylor")
    copy = tmp_path / "taylor.json"
    copy.write_bytes(mod.OUT_JSON.read_bytes())
    monkeypatch.setattr(mod, "OUT_JSON", copy)
    monkeypatch.setattr(mod, "RUNS", tmp_path / "no_runs")
    assert mod.main(["--plot-only"]) == 0
    assert copy.read_bytes() == (BENCH / "taylor.json").read_bytes()


def test_a_killed_run_process_records_nothing(capsys):
    """A run whose process dies (killed, out of memory) breaks the pool: neither it nor the runs waiting behind it
    get a record (a record would make the sweep skip them); they stay to run, and the sweep says so."""
    import os
    assert list(_study().execute(os._exit, {"a": (1,), "b": (1,)}, jobs=1)) == []
    assert "still to run" in capsys.readouterr().out
