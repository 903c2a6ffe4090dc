"""Orthogonal cutting scene (Section 3.3): geometry, the measurements (chip thickness, shear bands) on fields
with a known answer, coarse runs of both methods, the CLI."""
from pathlib import Path

import numpy as np
import pytest

from refsph.crosscheck.compare import format_table
from refsph.crosscheck.golden import metric_rows
from refsph.paper_data import CUTTING_GEOMETRY
from refsph.io import analyse_cutting_run
from refsph.scenes.cutting import chip_thickness, shear_bands
from refsph.scenes.measure import TOOL_BODY
from refsph.scenes import get_scene
from refsph.simulate import run


@pytest.mark.parametrize("feed", [0.3e-3, 0.5e-3])
def test_geometry(feed):
    setup = get_scene("cutting").setup(2, 0.01e-3, False, feed=feed)
    s, info = setup.state, setup.info
    n = info["n_work"]
    (Lx, Ly) = CUTTING_GEOMETRY["workpiece_m"]
    assert np.sum(s.m[:n]) == pytest.approx(7830.0 * Lx * Ly, rel=1e-12)
    assert setup.h == pytest.approx(0.018e-3)                          # Table 5
    xt = s.x[n:]
    assert np.all(s.body[n:] == TOOL_BODY)
    assert xt[:, 0].min() - info["dx"] / 2 == pytest.approx(Lx)         # rake face touches the workpiece
    assert xt[:, 1].min() - info["dy"] / 2 == pytest.approx(Ly - feed)  # cutting edge at the depth of cut
    assert xt[:, 1].max() + info["dy"] / 2 == pytest.approx(Ly - feed + 1e-3)
    assert setup.t_end == pytest.approx(1e-3 / 50.0)
    held = setup.clamps[0].index
    assert np.all((s.x[held, 0] < info["dx"]) | (s.x[held, 1] < info["dy"]))


def test_bad_input():
    sc = get_scene("cutting")
    with pytest.raises(ValueError, match="2D"):
        sc.setup(3, 0.01e-3, False)
    with pytest.raises(ValueError, match="feed"):
        sc.setup(2, 0.01e-3, False, feed=1.2e-3)
    with pytest.raises(ValueError, match="travel"):
        sc.setup(2, 0.01e-3, False, travel=-1.0)


def test_chip_thickness_of_a_slab():
    """A vertical slab of chip 0.2 mm wide against the rake face measures 0.2 mm."""
    dy = 0.01e-3
    x = np.stack(np.meshgrid(np.arange(2.8e-3, 3.0e-3, dy) + dy / 2, np.arange(1.0e-3, 1.4e-3, dy) + dy / 2,
                             indexing="ij"), axis=-1).reshape(-1, 2)
    X0 = x.copy()
    X0[:, 1] = 0.9e-3                                                     # all of it came from above the cut line
    assert chip_thickness(x, X0, 0.7e-3, 1e-3, 0.3e-3, 3.0e-3, dy) == pytest.approx(0.2e-3 - dy / 2, rel=1e-9)


def _banded_field(dp, feed, spacing, angle_deg, x_tip, width=1.5):
    """Workpiece lattice (undeformed, x = X0) with straight bands of eps_p = 2 (Gaussian, ``width`` spacings)
    over a background 0.3, crossing the cut layer at ``angle_deg`` to the cutting direction (-x), their middle-row
    crossings every ``spacing`` from x_tip - feed / 2 on."""
    (Lx, Ly) = CUTTING_GEOMETRY["workpiece_m"]
    nx, ny = round(Lx / dp), round(Ly / dp)
    X = np.stack(np.meshgrid((np.arange(nx) + 0.5) * dp, (np.arange(ny) + 0.5) * dp, indexing="ij"),
                 axis=-1).reshape(-1, 2)
    ym = Ly - feed / 2
    # a band through (xc, ym) leaning ahead of the tool: x = xc - (y - ym) / tan(angle)
    shift = X[:, 0] + (X[:, 1] - ym) / np.tan(np.radians(angle_deg))
    centres = np.arange(x_tip - feed / 2 + spacing, Lx - feed, spacing)         # all of each band inside
    d = np.min(np.abs(shift[:, None] - centres[None, :]), axis=1) * np.sin(np.radians(angle_deg))
    eps = 0.3 + 1.7 * np.exp(-0.5 * (d / (width * dp)) ** 2)
    eps[X[:, 1] < Ly - feed] = 0.0
    return X, eps, nx, ny, centres


@pytest.mark.parametrize("angle", [45.0, 60.0, 120.0])
def test_shear_bands_of_a_known_field(angle):
    """Straight bands at a known angle and spacing are counted, spaced and angled as drawn (x = X0, so the
    spacing along the chip equals the material spacing)."""
    dp, feed, spacing, x_tip = 0.01e-3, 0.3e-3, 0.12e-3, 2.0e-3
    X, eps, nx, ny, centres = _banded_field(dp, feed, spacing, angle, x_tip)
    b = shear_bands(X, eps, nx, ny, dp, dp, feed, x_tip)
    assert b["n"] == len(centres)
    assert b["spacing_material_mm"] == pytest.approx(spacing * 1e3, abs=0.5 * dp * 1e3)
    assert b["spacing_mm"] == pytest.approx(spacing * 1e3, abs=0.5 * dp * 1e3)
    assert b["angle_deg"] == pytest.approx(angle, abs=2.0)
    assert np.allclose(b["angles_current_deg"], 180.0 - angle, atol=2.0)   # same line, angle to +x


def test_no_bands_in_a_uniform_field():
    dp, feed = 0.01e-3, 0.3e-3
    X, eps, nx, ny, _ = _banded_field(dp, feed, 0.12e-3, 45.0, 2.0e-3)
    eps[eps > 0] = 1.0
    assert shear_bands(X, eps, nx, ny, dp, dp, feed, 2.0e-3)["n"] == 0


GOLDEN = Path(__file__).resolve().parent.parent / "golden"


@pytest.fixture(scope="module")
def coarse(tmp_path_factory):
    """dp = 0.05 mm, 0.2 mm of cut, both methods, with output folders."""
    out = {}
    for m in ("esph", "tlsph"):
        d = tmp_path_factory.mktemp(f"cut_{m}")
        out[m] = (run("cutting", m, dp=0.05e-3, progress=False, out=d, options=dict(travel=0.2e-3)), d)
    return out


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_coarse_run(coarse, method):
    """The tool meets a cutting force larger than the flow stress times the feed, the workpiece's momentum
    balances the impulses of tool and clamps, nothing passes the rake face."""
    res = coarse[method][0]
    assert res.summary["status"] == "ok"
    met, s, info = res.summary["metrics"], res.state, res.setup.info
    n = info["n_work"]
    assert met["cutting_force_mean_N_per_m"] > 792e6 * info["feed_m"]
    assert met["thrust_force_mean_N_per_m"] > 0
    imp = res.summary["diagnostics"]["reaction_impulse"]
    P = np.sum(s.m[:n, None] * s.v[:n], axis=0)
    assert np.allclose(P, -(np.array(imp["tool"]) + np.array(imp["held"])), atol=1e-9 * imp["tool"][0])
    face = s.x[n:, 0].min()
    above = s.x[:n, 1] > info["y0"] + info["dy"]
    assert np.all(s.x[:n][above, 0] < face)


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_analyse_run_matches_the_run(coarse, method):
    """Re-measuring a run folder (what benchmarks/cutting.py does) gives the run's own metrics."""
    res, out = coarse[method]
    again = analyse_cutting_run(out)
    for k, v in res.summary["metrics"].items():
        assert np.allclose(np.asarray(again[k], dtype=float), np.asarray(v, dtype=float), rtol=1e-6,
                           equal_nan=True), k
    with pytest.raises(ValueError, match="nowhere/summary.json: no such run summary"):    # the file named
        analyse_cutting_run(out / "nowhere")


def test_coarse_regression(coarse):
    """Same numbers as the golden cases metrics_cutting_coarse_{esph,tlsph} (`refsph oracle golden/ --only
    'metrics_cutting*'` writes them). ESPH at 1e-4; TLSPH's pinball switch amplifies round-off (chapter 07), so
    its force means at 2 %, the rest at 5 % (case.json)."""
    for m, (res, _) in coarse.items():
        rows = metric_rows(GOLDEN / f"metrics_cutting_coarse_{m}", res.summary["metrics"])
        assert len(rows) == 4 and all(r.passed for r in rows), format_table(rows)


def test_cli_option_flags_and_numerics(tmp_path, capsys):
    from refsph.cli import main
    import json
    rc = main(["run", "cutting", "--method", "tlsph", "--dp", "0.05e-3", "--feed", "0.5e-3", "--travel=0.02e-3",
               "--set", "ref_update_strain=none", "--set", "contact_Kp=10", "--quiet", "--out", str(tmp_path)])
    assert rc == 0
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["numerics"]["ref_update_strain"] is None and s["numerics"]["contact_Kp"] == 10.0
    assert s["diagnostics"]["reference_updates"] == 0
    assert s["metrics"]["cut_length_mm"] == pytest.approx(0.02)
    assert main(["run", "cutting", "--nonsense", "1", "--quiet"]) == 2
    assert main(["run", "cutting", "--feed", "--quiet"]) == 2
    assert main(["run", "cutting", "--set", "courant=fast", "--quiet"]) == 2
    assert main(["run", "cutting", "--set", "nothing=1", "--quiet"]) == 2


def test_report_reads_summary_files(coarse):
    """The report table takes summaries as written to summary.json (unmeasurable values are null there)."""
    from refsph.scenes.cutting import cutting_table
    from refsph.io import load_run
    summaries = [load_run(out)[0] for _, out in coarse.values()]
    assert any(v is None for s in summaries for v in s["metrics"].values())   # e.g. no band spacing at 0.2 mm
    text = cutting_table(summaries)
    assert "esph" in text and "tlsph" in text and " - " in text
