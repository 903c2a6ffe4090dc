"""A run's heartbeat (refsph.io.write_progress): both run loops write progress.json between their checkpoints, and
the sweep's --status reads it where it is newer than the run's summary."""
import json
import os
import sys
import time
from pathlib import Path

from refsph import io as rio
from refsph.pfem_run import run_pfem
from refsph.simulate import run

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))


def test_an_sph_run_writes_its_heartbeat(tmp_path, monkeypatch):
    monkeypatch.setattr(rio, "HEARTBEAT_S", 0.0)
    res = run("bar", "tlsph", quick=True, t_end=2e-6, out=tmp_path, progress=False)
    b = json.loads((tmp_path / "progress.json").read_text())
    assert 0 < b["t"] <= b["t_end"] == res.summary["t_end"] and 0 < b["steps"] <= res.summary["n_steps"]
    assert b["t_begin"] == 0.0 and b["wall_s"] >= 0 and abs(b["written"] - time.time()) < 600
    assert tmp_path / "progress.json" in rio.run_files(tmp_path)          # a rerun into the folder removes it


def test_a_pfem_run_writes_its_heartbeat(tmp_path, monkeypatch):
    monkeypatch.setattr(rio, "HEARTBEAT_S", 0.0)
    run_pfem("thermal_cutting", out=tmp_path, options=dict(travel="0.3"), quick=True, progress=False, max_steps=2)
    b = json.loads((tmp_path / "progress.json").read_text())
    assert b["steps"] == 2 and 0 < b["t"] < b["t_end"] and b["t_begin"] == 0.0


def test_the_sweep_status_reads_a_newer_heartbeat(tmp_path, monkeypatch):
    import thermal_cutting as tc
    monkeypatch.setattr(tc, "RUNS", tmp_path)
    folder = tc.run_folder("case 1 pfem")
    folder.mkdir(parents=True)
    line, = tc.status_lines({}, {"case 1 pfem": None})
    assert line.endswith("to run")
    rio.write_progress(folder, 0.1e-3, 1.6e-3, 50, 300.0, 0.0)          # before its first summary: running
    line, = tc.status_lines({}, {"case 1 pfem": None})
    assert "running: t = 0.100 of 1.600 ms" in line
    (folder / "progress.json").unlink()
    summary = dict(status="running", t_final=0.2e-3, t_end=1.6e-3, n_steps=100, wall_time_s=600.0)
    (folder / "summary.json").write_text(json.dumps(summary))
    old = time.time() - 3600
    os.utime(folder / "summary.json", (old, old))
    line, = tc.status_lines({}, {"case 1 pfem": None})
    assert "t = 0.200 of 1.600 ms" in line and "summary written 60 min ago" in line
    rio.write_progress(folder, 0.8e-3, 1.6e-3, 400, 1200.0, 0.2e-3)      # 0.6 ms in 20 min: 0.8 ms in 27 more
    line, = tc.status_lines({}, {"case 1 pfem": None})
    assert "t = 0.800 of 1.600 ms (50 %), 400 steps" in line and "about 27 min to go" in line
    assert "heartbeat 0 min ago" in line


def test_the_sweep_status_says_a_run_whose_process_is_gone_stopped(tmp_path, monkeypatch):
    import subprocess
    import sys
    import thermal_cutting as tc
    monkeypatch.setattr(tc, "RUNS", tmp_path)
    folder = tc.run_folder("case 1 pfem")
    folder.mkdir(parents=True)
    (folder / "summary.json").write_text(json.dumps(dict(status="running", t_final=0.2e-3, t_end=1.6e-3)))
    old = time.time() - 3600
    os.utime(folder / "summary.json", (old, old))
    rio.write_progress(folder, 0.8e-3, 1.6e-3, 400, 1200.0, 0.2e-3)
    beat = json.loads((folder / "progress.json").read_text())
    assert beat["pid"] == os.getpid() and rio.writer_alive(beat) is True
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()                                                         # a process id that no process has now
    (folder / "progress.json").write_text(json.dumps(dict(beat, pid=gone.pid)))
    line, = tc.status_lines({}, {"case 1 pfem": None})
    assert f"stopped: its process ({gone.pid}) is gone" in line and "t = 0.800 of 1.600 ms (50 %)" in line
    later = time.time() + 10                                            # killed just after writing its summary
    os.utime(folder / "summary.json", (later, later))
    line, = tc.status_lines({}, {"case 1 pfem": None})
    assert "stopped: its process" in line
    assert rio.writer_alive(dict(beat, host="another machine")) is None
