"""A run longer than a working session is parked (benchmarks/study.py ``park``: its last checkpoint, compressed,
into a folder git keeps) and continued in a new checkout (``unpark``, then ``refsph run --restart``) to the same
bits as the run that was never stopped: an SPH run, whose checkpoint names a state file, and a PFEM run, whose
checkpoint holds its state; and ``thermal_cutting.py --park`` parks only unrecorded jobs and drops the parked
checkpoints of jobs since recorded."""
import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from refsph import load_run, load_snapshot
from refsph.cli import main
from refsph.io import load_reactions
from refsph.pfem_run import run_pfem
from refsph.simulate import run

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
import study  # noqa: E402
from test_restart import _killed  # noqa: E402  (tests/ is on sys.path: pytest's default import mode)

SPH = dict(quick=True, t_end=2e-5, numerics=dict(threads=1, contact="penalty", heat_every=7),
           options=dict(case=1, length=0.5e-3, travel=1.0))


def _script(name):
    spec = importlib.util.spec_from_file_location(f"bench_{name}", ROOT / "benchmarks" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_a_parked_sph_run_continues_in_a_new_folder_to_the_same_bits(tmp_path, monkeypatch):
    """Killed at 45 % (its checkpoint a timed state), parked, and put into an empty folder (a new checkout): the
    restart ends as the whole run; parking the same checkpoint again writes nothing; a park after the run went on
    replaces the checkpoint and its state file (the old one gone), and the older checkpoint never replaces it."""
    whole = run("thermal_cutting", "tlsph", out=tmp_path / "whole", progress=False, checkpoint_every=None, **SPH)
    _killed(monkeypatch, "thermal_cutting", "tlsph", tmp_path / "cut", dict(SPH, checkpoint_every=0.0))
    parked = tmp_path / "parked" / "cut"
    assert study.park(tmp_path / "cut", parked) and not study.park(tmp_path / "cut", parked)
    state = json.loads(str(np.load(parked / "restart.npz")["run"]))["snapshot"]
    assert sorted(p.name for p in parked.iterdir()) == sorted(["restart.npz", "summary.json", state])
    fresh = tmp_path / "checkout" / "cut"
    assert study.unpark(parked, fresh) and not study.unpark(parked, fresh)    # never over a checkpoint of its own
    assert main(["run", "--restart", str(fresh), "--quiet"]) == 0
    a, b = (load_snapshot(load_run(d)[1][-1]) for d in (tmp_path / "whole", fresh))
    assert a["t"] == b["t"] == pytest.approx(SPH["t_end"])
    assert all(np.array_equal(a[k], b[k]) for k in ("x", "v", "rho", "S", "eps_p", "T"))
    again = json.loads((fresh / "summary.json").read_text())
    assert again["status"] == "ok" and again["n_steps"] == whole.summary["n_steps"]
    assert again["heat_balance"] == whole.summary["heat_balance"]
    assert study.park(fresh, parked)                                         # further on: replaces it
    last = json.loads(str(np.load(parked / "restart.npz")["run"]))["snapshot"]
    assert last != state and sorted(p.name for p in parked.iterdir()) == sorted(["restart.npz", "summary.json", last])
    assert not study.park(tmp_path / "cut", parked)                          # the 45 % one is older: kept out
    assert json.loads(str(np.load(parked / "restart.npz")["run"]))["snapshot"] == last


def test_a_parked_pfem_run_continues_in_a_new_folder_to_the_same_bits(tmp_path):
    """A PFEM cut stopped after 3 steps, parked with its job and put into an empty folder, continues to the
    uninterrupted run's reactions and nodes; its summary names the commits of its first part; another job does not
    get it."""
    kw = dict(options=dict(travel="0.3"), quick=True, progress=False)
    whole = run_pfem("thermal_cutting", out=tmp_path / "whole", **kw)
    run_pfem("thermal_cutting", out=tmp_path / "cut", max_steps=3, **kw)
    parked = tmp_path / "parked"
    assert study.park(tmp_path / "cut", parked, job=({"case": 1}, {"method": "pfem"}))
    assert sorted(p.name for p in parked.iterdir()) == ["job.json", "restart.npz", "summary.json"]
    fresh = tmp_path / "checkout"
    assert not study.unpark(parked, fresh, ({"case": 2}, {"method": "pfem"}))   # another job's: not continued
    assert study.parked_job_differs(parked, ({"case": 2}, {"method": "pfem"})) and not (fresh / "snapshots").exists()
    assert study.unpark(parked, fresh, ({"case": 1}, {"method": "pfem"}))
    assert main(["run", "--restart", str(fresh), "--quiet"]) == 0
    a, b = (load_reactions(d / "reaction_forces.csv") for d in (tmp_path / "whole", fresh))
    np.testing.assert_array_equal(a["tool"], b["tool"])
    s = json.loads((fresh / "summary.json").read_text())
    za = load_snapshot(tmp_path / "whole" / "snapshots" / whole.summary["snapshots"][-1])
    zb = load_snapshot(fresh / "snapshots" / s["snapshots"][-1])
    assert all(np.array_equal(za[k], zb[k]) for k in ("x", "T", "eps_p", "triangles"))
    assert s["status"] == "ok" and "earlier_commits" in s["provenance"]


def test_thermal_cutting_parks_unrecorded_jobs_and_drops_recorded_ones(tmp_path, monkeypatch):
    """--park: the checkpoint of an unrecorded job's run folder is parked (its status then says where a rerun
    continues from, once the run folder is gone); a parked checkpoint of a job since recorded is dropped; a job
    without a run folder parks nothing; run_case's folder gets the parked checkpoint back."""
    mod = _script("thermal_cutting")
    monkeypatch.setattr(mod, "RUNS", tmp_path / "runs")
    monkeypatch.setattr(mod, "PARKED", tmp_path / "parked")
    snaps = mod.run_folder("case 2") / "snapshots"
    snaps.mkdir(parents=True)
    np.savez(snaps / "restart.npz", **{"nodes/t": np.array(4e-4), "run": np.array(json.dumps({}))})
    (snaps.parent / "summary.json").write_text(json.dumps(dict(status="running")))
    todo = {"case 1": None, "case 2": None, "case 3": None, "case 9 courant 0.075": None}   # a retry job too
    recorded = {"case 1": dict(status="ok"), "case 9": dict(status="error")}
    assert mod.park(recorded, todo) == ["parked case 2 at t = 0.400 ms"]
    assert mod.park(recorded, todo) == ["nothing to park"]
    (tmp_path / "runs" / "case_2" / "summary.json").unlink()
    line = mod.status_lines({}, {"case 2": None})[0]
    assert line.endswith("parked at t = 0.400 ms (a rerun continues from there)")
    (snaps / "restart.npz").unlink()
    assert study.unpark(mod.PARKED / "case_2", mod.run_folder("case 2"))
    assert np.load(snaps / "restart.npz")["nodes/t"] == 4e-4
    assert mod.park({"case 2": dict(status="ok")}, todo) == ["dropped case_2"]
    assert not (tmp_path / "parked" / "case_2").exists() and (snaps / "restart.npz").exists()
    todo = {"case 2": mod.jobs()["case 2"]}                                  # parked with its job, which then changes
    assert mod.park({}, todo) == ["parked case 2 at t = 0.400 ms"]
    monkeypatch.setattr(mod, "jobs", lambda *a, **k: {"case 2": ({"case": 2, "n_tu": 7.0}, {})})
    assert mod.park({}, {}) == ["dropped case_2"]


def test_the_pfem_scatter_table_spreads_over_todays_runs_only(monkeypatch):
    """The scatter table of the PFEM (PFEM_SCATTER) takes its spread over today's four runs; the earlier solver's
    record of the same cut is a single run read against it, not a member."""
    mod = _script("thermal_cutting")
    rec = lambda fc: dict(status="ok", dp=2e-5, scene_info=dict(tu_m=1e-4), metrics=dict(  # noqa: E731
        cutting_force_N_per_m=1e3 * fc, passive_force_N_per_m=1e5, force_ratio=100 / fc, rake_face_temperature_K=900.0,
        rake_face_temperature_max_K=950.0, free_chip_surface_temperature_K=600.0, chip_thickness_mm=0.4,
        contact_length_mm=0.6))
    runs = {k: rec(fc) for k, fc in zip(mod.PFEM_SCATTER, (396.0, 404.0, 396.0, 404.0))}
    runs["case 2 pfem n_tu 5"] = rec(500.0)
    lines = mod._study_lines(dict(runs=runs))
    i = next(k for k, x in enumerate(lines) if x.startswith("## The PFEM's run-to-run scatter"))
    spread = next(x for x in lines[i:] if x.startswith("Spread"))
    assert "Fc 1.2 %" in spread and "(4 runs)" in spread
    assert any("case 2 pfem n_tu 5" in x for x in lines[i:i + 20] if not x.startswith("|"))
