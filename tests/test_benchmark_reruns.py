"""A rerun of a benchmark loses nothing (issue 23): a partial rerun, or one in a fresh clone where the git-ignored run
folders are missing, updates only the records it ran; a run that failed never replaces a committed good record; a
rerun with nothing to do, or one that reproduced the committed results, writes nothing (JSON, page or figure).

Checked at the level of the functions that write (benchmarks/study.py's helpers and the scripts' record_runs,
plots and write_results) on the committed JSON, with the run folders and the measurements faked, so no run is
made."""
import copy
import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BENCH = ROOT / "benchmarks"


def load_benchmark(name: str):
    """benchmarks/<name>.py as a fresh module object (a test may change its globals freely)."""
    spec = importlib.util.spec_from_file_location(f"rerun_{name}", BENCH / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


study = load_benchmark("study")


# ----------------------------------------------------------------------------- study.py
def test_merge_records_keeps_a_good_record_against_a_failed_rerun():
    committed = [dict(name="a", status="ok", v=1), dict(name="b", status="ok", v=2), dict(name="c", status="nan")]
    fresh = [dict(name="a", status="nan"), dict(name="c", status="ok", v=3), dict(name="d", status="ok", v=4)]
    out = study.merge_records(committed, fresh)
    assert out == [committed[0], committed[1], fresh[1], fresh[2]]
    by_key = study.merge_records([dict(m="x", n=1, t=1.0)], [dict(m="x", n=1, t=2.0), dict(m="x", n=2, t=3.0)],
                                 key=lambda r: (r["m"], r["n"]))
    assert by_key == [dict(m="x", n=1, t=2.0), dict(m="x", n=2, t=3.0)]


def _derive(records):
    """A toy cross-record field: each record's value over the record named 'base'."""
    base = next(r for r in records if r["name"] == "base")
    for r in records:
        if r is not base:
            r["vs"] = dict(ref="base", rel=r["value"] / base["value"])
    return records


def test_merge_derived_takes_anew_only_what_the_rerun_touched():
    # x's committed difference is stale on purpose: only a rerun of x or of its reference may change it
    committed = [dict(name="base", status="ok", value=2.0), dict(name="x", status="ok", value=4.0,
                                                                 vs=dict(ref="base", rel=99.0))]
    out, went_in = study.merge_derived(committed, [dict(name="y", status="ok", value=1.0)], _derive)
    assert went_in == {"y"} and out[1] == committed[1] and out[2]["vs"] == dict(ref="base", rel=0.5)
    out, went_in = study.merge_derived(committed, [dict(name="base", status="ok", value=8.0)], _derive)
    assert went_in == {"base"} and out[1]["vs"]["rel"] == 0.5
    out, went_in = study.merge_derived(committed, [dict(name="base", status="nan", value=1.0)], _derive)
    assert went_in == set() and out == committed


def test_write_json_ignores_what_only_timing_changed(tmp_path):
    path = tmp_path / "doc.json"
    doc = dict(rows=[dict(n=10, error=0.1, wall_s=1.0)])
    assert study.write_json(path, doc, ignore=("wall_s",))
    text = path.read_text()
    assert not study.write_json(path, dict(rows=[dict(n=10, error=0.1, wall_s=7.0)]), ignore=("wall_s",))
    assert path.read_text() == text
    assert study.write_json(path, dict(rows=[dict(n=10, error=0.2, wall_s=7.0)]), ignore=("wall_s",))
    assert json.loads(path.read_text())["rows"][0]["error"] == 0.2


def test_save_figure_writes_only_a_changed_picture(tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def draw(y):
        fig, ax = plt.subplots(figsize=(2, 2))
        ax.plot([0, 1], [0, y])
        return fig
    path = tmp_path / "f.png"
    assert study.save_figure(draw(1.0), path, dpi=40)
    png = path.read_bytes()
    assert not study.save_figure(draw(1.0), path, dpi=40)
    assert not study.save_figure(draw(1.0), path, dpi=40, metadata={"Software": "other"})    # other bytes, same pixels
    assert path.read_bytes() == png
    assert study.save_figure(draw(0.5), path, dpi=40) and path.read_bytes() != png


def test_run_status(tmp_path):
    assert study.run_status(tmp_path / "none") is None
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "summary.json").write_text(json.dumps(dict(status="nan")))
    assert study.run_status(tmp_path / "run") == "nan"


# ----------------------------------------------------------------------------- cutting.py and pressing.py
def _fake_study(name, monkeypatch, tmp_path):
    """The script with its JSON a copy of the committed one in tmp_path, no run folders, the measurements of a run
    (record) and the figures (plots) replaced by what the test gives and a list of the plots calls."""
    mod = load_benchmark(name)
    committed = (BENCH / f"{name}.json").read_text()
    (tmp_path / "benchmarks").mkdir()
    for attr, value in dict(ROOT=tmp_path, RUNS=tmp_path / "runs", OUT_JSON=tmp_path / "benchmarks" / f"{name}.json",
                            FIG=tmp_path / "figures").items():
        monkeypatch.setattr(mod, attr, value)
    mod.OUT_JSON.write_text(committed)
    mod.fresh, mod.plotted = {}, []
    monkeypatch.setattr(mod, "record", lambda job: copy.deepcopy(mod.fresh[job["name"]]))
    monkeypatch.setattr(mod, "plots", lambda records, *a, folders=(), **k: mod.plotted.append(set(a[0] if a
                                                                                                  else folders)))
    return mod, committed


def _rerun(mod, name, status, **changes):
    """A run folder of ``name`` with ``status`` and its record: the committed one with ``changes``."""
    (mod.RUNS / name).mkdir(parents=True)
    (mod.RUNS / name / "summary.json").write_text(json.dumps(dict(status=status)))
    old = next(r for r in json.loads(mod.OUT_JSON.read_text()) if r["name"] == name)
    mod.fresh[name] = dict({k: v for k, v in old.items() if not k.startswith("vs_")}, status=status, **changes)


def _changed(before: str, after: str) -> set:
    """The names of the records whose lines differ."""
    a, b = before.splitlines(), after.splitlines()
    assert len(a) == len(b)
    return {json.loads(y.rstrip(","))["name"] for x, y in zip(a, b) if x != y}


@pytest.mark.parametrize("name", ["cutting", "pressing"])
def test_a_rerun_without_run_folders_writes_nothing(name, monkeypatch, tmp_path):
    """A fresh clone: --plot-only (and a rerun whose runs all could not run) finds no folder; before issue 23 it
    rewrote the JSON with no records at all."""
    mod, committed = _fake_study(name, monkeypatch, tmp_path)
    mod.record_runs(mod.job_list())
    assert mod.OUT_JSON.read_text() == committed and mod.plotted == []


@pytest.mark.parametrize("name, run", [("cutting", "paper-esph-f0.3"), ("pressing", "conv-esph-6.67um")])
def test_a_failed_rerun_keeps_the_committed_good_record(name, run, monkeypatch, tmp_path):
    mod, committed = _fake_study(name, monkeypatch, tmp_path)
    _rerun(mod, run, "nan", wall_time_s=1.0)
    mod.record_runs(mod.job_list())
    assert mod.OUT_JSON.read_text() == committed
    assert all(run not in folders for folders in mod.plotted)      # its folder holds the failed run: no figure from it


def test_cutting_partial_rerun_updates_what_it_ran_and_what_compares_with_it(monkeypatch, tmp_path):
    mod, committed = _fake_study("cutting", monkeypatch, tmp_path)
    paper = next(r for r in json.loads(committed) if r["name"] == "paper-tlsph-f0.3")
    _rerun(mod, "paper-tlsph-f0.3", "ok", cutting_force_mean_MN_per_m=1.1 * paper["cutting_force_mean_MN_per_m"])
    _rerun(mod, "noupdate-tlsph-f0.3-25um", "nan", wall_time_s=1.0)       # failed over failed: a new result
    _rerun(mod, "coarse-esph-f0.3-25um", "running")                         # a killed run: no result
    mod.record_runs(mod.job_list())
    after = mod.OUT_JSON.read_text()
    # the coarse TLSPH runs at feed 0.3 are compared with paper-tlsph-f0.3 (vs_paper); every other line stays
    assert _changed(committed, after) == {"paper-tlsph-f0.3", "noupdate-tlsph-f0.3-25um", "coarse-tlsph-f0.3-25um",
                                          "coarse-tlsph-f0.3-16.7um"}
    by = {r["name"]: r for r in json.loads(after)}
    assert by["paper-tlsph-f0.3"]["vs_rerun"] == paper["vs_rerun"]          # the comparison made before is kept
    coarse = by["coarse-tlsph-f0.3-25um"]
    assert coarse["vs_paper"]["cutting_force_rel"] == pytest.approx(
        coarse["cutting_force_mean_MN_per_m"] / by["paper-tlsph-f0.3"]["cutting_force_mean_MN_per_m"] - 1)
    assert mod.plotted == [{"paper-tlsph-f0.3", "noupdate-tlsph-f0.3-25um"}]


def test_pressing_partial_rerun_updates_what_it_ran_and_what_compares_with_it(monkeypatch, tmp_path):
    mod, committed = _fake_study("pressing", monkeypatch, tmp_path)
    _rerun(mod, "conv-tlsph-16.7um", "ok", wall_time_s=6.5)
    mod.record_runs([j for j in mod.job_list() if "16.7um" in j["name"]])
    after = mod.OUT_JSON.read_text()
    assert _changed(committed, after) == {"conv-tlsph-16.7um", "penalty-tlsph-16.7um"}    # vs_base of the penalty run
    by = {r["name"]: r for r in json.loads(after)}
    assert by["conv-tlsph-16.7um"]["vs_finest"]["ref"] == "conv-tlsph-6.67um"
    assert by["conv-tlsph-16.7um"]["vs_finest"]["wall_time_ratio"] == pytest.approx(
        6.5 / by["conv-tlsph-6.67um"]["wall_time_s"])
    assert mod.plotted == [{"conv-tlsph-16.7um"}]


def test_cutting_figures_from_run_folders_need_every_run_they_show(monkeypatch, tmp_path):
    mod = load_benchmark("cutting")
    drawn = []
    for f in ("strain_figure", "temperature_figure", "reference_updates_figure", "forces_figure", "bands_figure",
              "work_precision_figure", "contact_figure"):
        monkeypatch.setattr(mod, f, lambda *a, f=f: drawn.append((f, a[-1] if f == "strain_figure" else None)))
    monkeypatch.setattr(mod, "FIG", tmp_path)
    records = json.loads((BENCH / "cutting.json").read_text())
    from_records = {("forces_figure", None), ("bands_figure", None), ("work_precision_figure", None),
                    ("contact_figure", None)}
    mod.plots(records, {"paper-esph-f0.3", "coarse-tlsph-f0.3-25um"})
    assert set(drawn) == from_records
    drawn.clear()
    mod.plots(records, {"paper-esph-f0.3", "paper-tlsph-f0.3"})
    assert set(drawn) == from_records | {("strain_figure", 0.3e-3)}


def test_pressing_resolution_figure_needs_every_conv_folder(monkeypatch, tmp_path):
    mod = load_benchmark("pressing")
    drawn = []
    for f in ("_plot_work_precision", "_plot_contact", "_plot_force", "_plot_resolution"):
        monkeypatch.setattr(mod, f, lambda *a, f=f: drawn.append(f))
    monkeypatch.setattr(mod, "FIG", tmp_path)
    records = json.loads((BENCH / "pressing.json").read_text())
    mod.plots(records, folders={r["name"] for r in records if r["name"] != "conv-esph-6.67um"})
    assert "_plot_resolution" not in drawn and "_plot_force" in drawn
    drawn.clear()
    mod.plots(records, folders={r["name"] for r in records if r["name"].startswith("conv-")})
    assert "_plot_resolution" in drawn


def test_taylor_figures_from_run_folders_wait_for_their_folders(monkeypatch, tmp_path):
    """A partial rerun in a fresh clone (runs/ holds only what ran): the folder figures are kept, not broken."""
    mod = load_benchmark("taylor")
    drawn = []
    monkeypatch.setattr(mod, "_plot_work_precision", lambda records: drawn.append("work_precision"))
    monkeypatch.setattr(mod, "_plot_length_history", lambda records: drawn.append("length_history"))
    monkeypatch.setattr(mod, "_plot_sections", lambda: drawn.append("sections"))
    monkeypatch.setattr(mod, "FIG", tmp_path)
    monkeypatch.setattr(mod, "RUNS", tmp_path / "runs")
    records = json.loads((BENCH / "taylor.json").read_text())
    for m in mod.METHODS:                                # only the conv runs at 0.5 mm were rerun
        (tmp_path / "runs" / f"conv-{m}-0.5mm").mkdir(parents=True)
        (tmp_path / "runs" / f"conv-{m}-0.5mm" / "summary.json").write_text("{}")
    mod.plots(records)
    assert drawn == ["work_precision", "sections"]       # the length history also shows the dt = 1e-8 s runs


# ----------------------------------------------------------------------------- throughput.py, pair_blocks.py
def test_throughput_partial_rerun_keeps_the_other_results(tmp_path):
    mod = load_benchmark("throughput")
    path = tmp_path / "throughput.json"
    committed = json.loads((BENCH / "throughput.json").read_text())
    path.write_text(json.dumps(committed))
    key = lambda r: (r["method"], r["integrator"], r["n_particles"])        # noqa: E731
    rerun = dict(committed["results"][0], wall_s=123.0)
    mod.write_results(path, [rerun], key, **{k: v for k, v in committed["meta"].items()
                                             if k not in mod.software() and k != "integrator_study"}
                      | dict(timing="another timing"))
    doc = json.loads(path.read_text())
    assert len(doc["results"]) == len(committed["results"])
    assert doc["results"][0]["wall_s"] == 123.0 and doc["results"][1:] == committed["results"][1:]
    assert doc["meta"] == committed["meta"]               # the kept results' meta, the integrator study with it
    assert doc["results"][0]["run_meta"]["timing"] == "another timing"
    # every result rerun: the file is the new run's, the integrator study (not rerun) stays
    mod.write_results(path, [dict(r, wall_s=1.0) for r in committed["results"]], key, timing="t")
    doc = json.loads(path.read_text())
    assert doc["meta"]["timing"] == "t" and doc["meta"]["integrator_study"] == committed["meta"]["integrator_study"]
    assert all("run_meta" not in r for r in doc["results"])
    mod.write_results(path, [dict(r, wall_s=2.0) for r in committed["results"]], key, integrator_study=[dict(c=1)])
    assert json.loads(path.read_text())["meta"]["integrator_study"] == [dict(c=1)]      # --study: replaced
