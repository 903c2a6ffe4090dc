"""benchmarks/rake_interface.py: the rake face from both sides (the chip's contact layer, the scene's T_RF, against
the tool's face layer), on a hand-made layout and on a hand-made run folder; its page is what it writes from its
committed JSON."""
import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def _mod():
    spec = importlib.util.spec_from_file_location("bench_rake_interface", ROOT / "benchmarks" / "rake_interface.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


DX = 1e-5
INFO = dict(case=10, material="Ti6Al4V", rake_deg=0.0, apex0=[1e-3, 5e-4], vc_m_s=1.0, dx=DX, tu_m=1e-4,
            measured=dict(TRF_exp_K=701.0))


def _layout(t=0.0):
    """Rake 0 deg: the face is the plane x = apex_x - vc t, u = y - apex_y upwards, n = face_x - x in front of it.
    Workpiece rows at n = dx/2 (900 K, u = 0..4 dx) and 1.5 dx (850 K); tool rows at n = -dx/2 (800 K) and -1.5 dx
    (780 K) along u = 0..6 dx, and one tool row below the edge (u < 0, 300 K) that must not count."""
    face = INFO["apex0"][0] - INFO["vc_m_s"] * t
    y0 = INFO["apex0"][1]
    work = [(face - a * DX, y0 + k * DX, T) for a, T in ((0.5, 900.0), (1.5, 850.0)) for k in range(5)]
    tool = ([(face + a * DX, y0 + k * DX, T) for a, T in ((0.5, 800.0), (1.5, 780.0)) for k in range(7)]
            + [(face + 0.5 * DX, y0 - 3 * DX, 300.0)])
    rows = np.array(work + tool)
    return rows[:, :2], rows[:, 2], dict(INFO, n_work=len(work))


def test_layers_reads_the_chip_and_the_tool_side_of_the_face():
    """The chip layer is the scene's T_RF (workpiece within one spacing, u >= 0); the tool layer the tool rows within
    one spacing behind the face up to the contact length (u <= 4 dx here: 5 of the 7 rows), not below the edge."""
    mod = _mod()
    t = 2e-4
    x, T, info = _layout(t)
    r = mod.layers(x, T, t, info)
    assert (r["chip_K"], r["n_chip"], r["tool_K"], r["n_tool"], r["tool_next_K"]) == (900.0, 5, 800.0, 5, 780.0)
    assert math.isclose(r["contact_m"], 4 * DX, rel_tol=1e-9)
    x[: info["n_work"], 0] -= 5 * DX                       # the chip lifted off: no contact, no reading
    assert mod.layers(x, T, t, info) is None


def test_interface_means_the_last_quarter_and_keeps_other_runs(tmp_path, monkeypatch):
    """interface() takes the snapshots at t >= 3/4 of t_end only; main() updates the JSON for the folders given,
    keeps the others, says which folder it could not read and writes the page from the JSON."""
    mod = _mod()
    run = tmp_path / "case_10_test"
    (run / "snapshots").mkdir(parents=True)
    names = []
    for i, t in enumerate((0.0, 5e-4, 8e-4, 1e-3)):
        x, T, info = _layout(t)
        T = T + (0.0 if t >= 7.5e-4 else 1000.0)           # the early snapshots far hotter: they must not count
        names.append(f"snap_{i:05d}.npz")
        np.savez(run / "snapshots" / names[-1], t=np.array(t), x=x, T=T)
    (run / "summary.json").write_text(json.dumps(dict(method="tlsph", t_end=1e-3, snapshots=names, status="ok",
                                                      scene_info=info,
                                                      metrics=dict(rake_face_temperature_K=900.0))))
    r = mod.interface(run)
    assert len(r["snapshots"]) == 2 and (r["chip_K"], r["tool_K"], r["step_K"]) == (900.0, 800.0, 100.0)
    monkeypatch.setattr(mod, "OUT_JSON", tmp_path / "ri.json")
    monkeypatch.setattr(mod, "OUT_MD", tmp_path / "ri.md")
    (tmp_path / "ri.json").write_text(json.dumps(dict(runs={"older": dict(r, case=1, across=5.0)})))
    assert mod.main(["--run", str(run)]) == 0
    kept = json.loads((tmp_path / "ri.json").read_text())["runs"]
    assert set(kept) == {"older", "case_10_test"}
    assert "| case_10_test | Ti6Al4V | 10 | 2 | 900 | 800 | 780 | 100 | 11.1 | 900 | 701 |" in (
        tmp_path / "ri.md").read_text()
    (run / "summary.json").write_text(json.dumps(dict(method="pfem", t_end=1e-3, snapshots=names)))
    assert mod.main(["--run", str(run)]) == 1                          # said, and the JSON kept as it was
    assert json.loads((tmp_path / "ri.json").read_text())["runs"] == kept
    for text in ("{not json", json.dumps(dict(method="tlsph"))):         # bad summaries: a ValueError naming them
        (run / "summary.json").write_text(text)
        with pytest.raises(ValueError, match="summary"):
            mod.interface(run)
        assert mod.main(["--run", str(run)]) == 1


def test_page_is_generated_from_the_json():
    mod = _mod()
    assert mod.OUT_JSON.exists() and mod.OUT_MD.exists()          # committed: a lost file fails, not skips
    assert mod.page(json.loads(mod.OUT_JSON.read_text())["runs"]) == mod.OUT_MD.read_text()
