"""Metal pressing scene (Section 3.2): geometry, the quick run of both methods, balance laws, regression, CLI."""
from pathlib import Path

import numpy as np
import pytest

from refsph.cli import main
from refsph.crosscheck.compare import format_table
from refsph.crosscheck.golden import metric_rows
from refsph.io import load_run, load_snapshot
from refsph.scenes.measure import TOOL_BODY
from refsph.paper_data import AISI4340_TABLE3, PRESSING_GEOMETRY
from refsph.scenes import get_scene
from refsph.simulate import run

GOLDEN = Path(__file__).resolve().parent.parent / "golden"


@pytest.mark.parametrize("dp", [0.0167e-3, 0.0133e-3, 0.01e-3, 0.00667e-3])
def test_geometry(dp):
    setup = get_scene("pressing").setup(2, dp, False)
    s, info = setup.state, setup.info
    n = info["n_block"]
    (Lx, Ly), (_, Ht) = PRESSING_GEOMETRY["block_m"], PRESSING_GEOMETRY["tool_m"]
    assert np.sum(s.m[:n]) == pytest.approx(AISI4340_TABLE3["rho"] * Lx * Ly, rel=1e-12)    # exact block mass
    xb, xt = s.x[:n], s.x[n:]
    dx, dy = info["dx"], info["dy"]
    assert xb[:, 0].min() - dx / 2 == pytest.approx(0.0, abs=1e-15)
    assert xb[:, 0].max() + dx / 2 == pytest.approx(Lx)
    assert xb[:, 1].max() + dy / 2 == pytest.approx(Ly)
    assert xt[:, 0].min() - dx / 2 == pytest.approx(Lx)                 # the tool face touches the block face
    assert xt[:, 1].max() - xt[:, 1].min() + dy == pytest.approx(Ht, rel=0.02)
    assert np.mean(xt[:, 1]) == pytest.approx(Ly / 2)
    assert np.all(s.body[n:] == TOOL_BODY) and np.all(s.body[:n] == 0)
    assert info["tool_layers"] == 3
    clamp = setup.clamps[0].index
    assert len(clamp) == round(Ly / dy) and np.allclose(xb[clamp, 0], dx / 2)
    line = setup.arrays["line_index"]
    assert len(line) == round(Lx / dx) and np.ptp(xb[line, 1]) == 0
    assert abs(xb[line[0], 1] - Ly / 2) <= dy / 2 * (1 + 1e-9)
    assert setup.t_end == pytest.approx(0.2e-3 / 200.0)


def test_bad_input():
    sc = get_scene("pressing")
    with pytest.raises(ValueError, match="2D"):
        sc.setup(3, 0.0167e-3, False)
    with pytest.raises(ValueError, match="travel"):
        sc.setup(2, 0.0167e-3, False, travel=2e-3)
    with pytest.raises(ValueError, match="coarse"):
        sc.setup(2, 0.3e-3, False)


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("pressing")
    return {m: (run("pressing", m, quick=True, progress=False, out=out / m), out / m) for m in ("esph", "tlsph")}


def test_quick_runs_and_balances_momentum(quick):
    for m, (res, _) in quick.items():
        s, setup = res.state, res.setup
        assert res.summary["status"] == "ok"
        n = setup.info["n_block"]
        P = np.sum(s.m[:n, None] * s.v[:n], axis=0)                        # the block starts at rest
        imp = res.summary["diagnostics"]["reaction_impulse"]
        total = np.array(imp["tool"]) + np.array(imp["left_side"])
        assert np.allclose(P, -total, atol=1e-9 * imp["tool"][0]), m
        # clamped column at rest, tool moved exactly with its velocity
        clamp = setup.clamps[0].index
        assert np.array_equal(s.x[clamp], setup.state.x[clamp])
        assert np.allclose(s.x[n:, 0] - setup.state.x[n:, 0], -200.0 * s.t, rtol=1e-12)


def test_quick_physics(quick):
    """Force level: the mean tool force lies between the plane-strain flow force of the undeformed section
    (2/sqrt 3) A * 0.5 mm and the impact force rho c_L v * 0.5 mm; bands give eps_p > 0.3 along the mid row."""
    for m, (res, _) in quick.items():
        met = res.summary["metrics"]
        mat = res.setup.material
        H = PRESSING_GEOMETRY["block_m"][1]
        lower = 2 / np.sqrt(3) * AISI4340_TABLE3["A_Pa"] * H
        impact = mat.rho0 * mat.c_longitudinal * 200.0 * H
        assert lower < met["tool_force_mean_N_per_m"] < impact, m
        assert 0.5 * impact < met["tool_force_peak_N_per_m"] < 2.0 * impact, m
        assert -met["clamp_force_mean_N_per_m"] > lower, m          # the clamp holds the block (force to -x)
        line = met["plastic_strain_line"]
        assert np.all(np.diff(line[:, 0]) > 0)
        assert line[:, 1].max() > 0.3 and line[:3, 1].max() < 0.05   # more plastic strain on the right (Fig. 8)
        assert 298.0 < met["max_temperature_K"] < 1573.0
        assert met["min_tool_gap_over_dp"] > 0.5                     # no particle through the tool


def test_quick_regression(quick):
    """Same numbers as the golden cases metrics_pressing_quick_{esph,tlsph} (`refsph oracle golden/ --only
    'metrics_pressing*'` writes them; every metric has its tolerance in case.json, the generator refuses one without).

    ESPH is compared at 1e-4 (the strain line point by point: |d| <= 1e-4 |ref| + 1e-6). TLSPH is not reproducible
    to that level across machines: with K_p = 50 the on/off switch of the pinball force (Eq. 34) amplifies
    round-off (a 1e-13 dp shift of the particles moves its max plastic strain by 2.5 %, the strain line by 1 %,
    the mean force by 0.2 %; chapter 07; summing the artificial viscosity in another order, as the pair blocks
    did, moved the mean tool force by 1.0 % and the max plastic strain by 1.9 %). Its integral quantities are
    compared at 2 %, the local ones (peaks, the line as a relative L2 difference) at 5 %."""
    for m, (res, _) in quick.items():
        rows = metric_rows(GOLDEN / f"metrics_pressing_quick_{m}", res.summary["metrics"])
        assert len(rows) == 6 and all(r.passed for r in rows), format_table(rows)


def test_outputs(quick):
    res, out = quick["tlsph"]
    summary, snaps = load_run(out)
    assert summary["boundaries"]["rigid_bodies"][0]["name"] == "tool"
    assert summary["boundaries"]["clamps"][0]["n_particles"] == len(res.setup.clamps[0].index)
    z = load_snapshot(snaps[-1])
    assert "body" in z and np.count_nonzero(z["body"] == TOOL_BODY) == res.setup.info["n_tool"]
    assert z["F"].shape == (res.state.n, 2, 2)
    assert (out / "reaction_forces.csv").exists()
    assert summary["diagnostics"]["reaction_impulse"]["tool"][0] > 0


def test_cli_pressing(tmp_path, capsys):
    code = main(["run", "pressing", "--quick", "--quiet", "--method", "tlsph", "--option", "travel=0.02e-3",
                 "--out", str(tmp_path / "p")])
    assert code == 0
    text = capsys.readouterr().out
    assert "Metal pressing" in text and "tlsph" in text
    assert main(["run", "pressing", "--dim", "3", "--quick", "--quiet", "--out", str(tmp_path / "q")]) == 2


@pytest.mark.slow
@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_paper_resolution_under_ten_minutes(method):
    """dp = 0.00667 mm (Table 4), the whole 0.2 mm of tool travel, one core: under 10 minutes, and the same
    physics checks as the quick run."""
    res = run("pressing", method, progress=False)
    assert res.summary["status"] == "ok"
    assert res.summary["wall_time_s"] < 600.0
    met = res.summary["metrics"]
    H = PRESSING_GEOMETRY["block_m"][1]
    assert 2 / np.sqrt(3) * AISI4340_TABLE3["A_Pa"] * H < met["tool_force_mean_N_per_m"]
    assert met["plastic_strain_line"][:, 1].max() > 0.3
    assert met["min_tool_gap_over_dp"] > 0.5
