"""Taylor impact scene: geometry, measurement, CLI, time step, and the results against the paper."""
import json
from pathlib import Path

import numpy as np
import pytest

from refsph.cli import main
from refsph.crosscheck.compare import format_table
from refsph.crosscheck.golden import metric_rows
from refsph.paper_data import TAYLOR_GEOMETRY, TAYLOR_RESULTS
from refsph.scenes import get_scene
from refsph.simulate import run
from refsph.scenes.taylor import bar_diameter, bar_length

GOLDEN = Path(__file__).resolve().parent.parent / "golden"
L0, D0 = TAYLOR_GEOMETRY["length_m"], TAYLOR_GEOMETRY["diameter_m"]


@pytest.mark.parametrize("dim,symmetry,dp", [(2, True, 0.5e-3), (2, False, 0.3e-3), (3, True, 0.5e-3),
                                             (3, False, 1.0e-3)])
def test_initial_geometry_measures_exactly(dim, symmetry, dp):
    setup = get_scene("taylor").setup(dim, dp, False, symmetry=symmetry)
    s, info = setup.state, setup.info
    assert bar_length(s.x, info["dz"]) == pytest.approx(L0, rel=1e-12)
    assert bar_diameter(s.x, info["dr"]) == pytest.approx(D0, rel=1e-12)
    R = 0.5 * D0
    if dim == 3:
        exact = 7830.0 * np.pi * R * R * L0 * (0.25 if symmetry else 1.0)
    else:
        exact = 7830.0 * D0 * L0 * (0.5 if symmetry else 1.0)
    assert np.sum(s.m) == pytest.approx(exact, rel=1e-12)
    assert np.all(s.v[:, -1] == -181.0) and np.all(s.T == 293.0)


def _quick3d(method):
    return run("taylor", method, dim=3, dp=1.0e-3, progress=False)


@pytest.fixture(scope="module")
def quick3d():
    return {m: _quick3d(m) for m in ("esph", "tlsph")}


def test_quick_3d_against_experiment(quick3d):
    """dp = 1 mm (4 particles across the radius): length within 2 %, diameter within 12 % of the experiment.
    (The issue's 5 % diameter target is for the paper's 0.5 mm; see the slow test and benchmarks/taylor.py.)"""
    for m, res in quick3d.items():
        met = res.summary["metrics"]
        assert res.summary["status"] == "ok"
        assert abs(met["final_length_mm"] / 34.6 - 1) < 0.02, m
        assert abs(met["final_diameter_mm"] / 9.5 - 1) < 0.12, m
        assert 0.1 < met["max_plastic_strain"] < 2.0
        assert 293.0 < met["max_temperature_K"] < 1293.0
        assert met["rest_time_s"] < met["end_time_s"] - 30e-6      # at rest well before the end
        assert met["length_oscillation_mm"] < 0.2
        assert met["settled"]


def test_quick_3d_regression(quick3d):
    """Same numbers as the golden cases metrics_taylor_3d_1mm_{esph,tlsph} (their tolerances and why: case.json;
    `refsph oracle golden/ --only 'metrics_taylor*'` writes them)."""
    for m, res in quick3d.items():
        rows = metric_rows(GOLDEN / f"metrics_taylor_3d_1mm_{m}", res.summary["metrics"])
        assert all(r.passed for r in rows), format_table(rows)


def test_fixed_dt_matches_cfl_2d():
    """The paper's fixed dt = 1e-8 s gives the same bar as the CFL step (2D, 40 us: the plastic phase)."""
    a = run("taylor", "tlsph", dim=2, dp=0.5e-3, t_end=40e-6, progress=False)
    b = run("taylor", "tlsph", dim=2, dp=0.5e-3, t_end=40e-6, dt=1e-8, progress=False)
    La = a.history["length"][-1]
    Lb = b.history["length"][-1]
    assert abs(La / Lb - 1) < 2e-3
    assert abs(a.history["diameter"][-1] / b.history["diameter"][-1] - 1) < 2e-3


def test_cli_taylor_table(tmp_path, capsys):
    rc = main(["run", "taylor", "--dim", "2", "--dp", "1e-3", "--t-end", "4e-6", "--quiet", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert rc == 0
    assert "experiment" in out and "refsph ESPH" in out and "refsph TLSPH" in out
    for m in ("esph", "tlsph"):
        s = json.loads((tmp_path / m / "summary.json").read_text())
        assert s["strength"]["T_melt"] == 1293.0
        assert {"final_length_mm", "final_diameter_mm", "length_history", "max_plastic_strain",
                "max_temperature_K"} <= set(s["metrics"])
        assert s["metrics"]["reference"] == TAYLOR_RESULTS


def test_cli_options(tmp_path, capsys):
    assert main(["run", "taylor", "--option", "nonsense=1", "--quiet"]) == 2
    assert main(["run", "taylor", "--option", "T_melt=hot", "--quiet"]) == 2
    assert main(["run", "taylor", "--option", "T_melt", "--quiet"]) == 2
    rc = main(["run", "taylor", "--method", "tlsph", "--dim", "2", "--dp", "1e-3", "--t-end", "2e-6", "--quiet",
               "--option", "T_melt=1793", "--out", str(tmp_path)])
    assert rc == 0
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["strength"]["T_melt"] == 1793.0
    snaps = sorted((tmp_path / "snapshots").glob("snap_*.npz"))
    z = np.load(snaps[-1])
    assert {"eps_p", "T", "W_p", "eps_dot_p"} <= set(z.files)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["esph", pytest.param("tlsph", marks=pytest.mark.xfail(
    strict=True, reason="known miss: TLSPH diameter -5.2 % at dp = 0.5 mm (README, chapter 06)"))])
def test_paper_resolution_targets(method):
    """dp = 0.5 mm, 3D quarter: the issue's targets (length 2 %, diameter 5 % of the experiment).
    TLSPH's diameter misses by 0.2 points (reported, not tuned); strict xfail turns a fix into a failure to
    update the documentation."""
    met = run("taylor", method, dim=3, dp=0.5e-3, progress=False).summary["metrics"]
    assert abs(met["final_length_mm"] / 34.6 - 1) < 0.02
    assert abs(met["final_diameter_mm"] / 9.5 - 1) < 0.05


def test_short_run_is_not_settled():
    met = run("taylor", "tlsph", dim=2, dp=1e-3, t_end=6e-6, progress=False).summary["metrics"]
    assert met["settled"] is False
    L_last = met["length_history"][-1][1]
    assert met["final_length_mm"] == pytest.approx(1e3 * L_last)       # the last value, not a window mean
