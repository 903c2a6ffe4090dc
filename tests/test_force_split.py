"""benchmarks/force_split.py splits the tool's force by part of its outline and by normal and friction force: its
sign conventions checked against Merchant's relation for a rake face whose contacts all slip, and its classification
of contacts by their outward normal."""
import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent


def _script():
    spec = importlib.util.spec_from_file_location("bench_force_split", ROOT / "benchmarks" / "force_split.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _row(fs, part, f_N, mu, slipping, gamma):
    """One evaluation's row with a single contact on ``part``: normal force f_N on the chip, friction mu f_N
    against the chip's motion up the rake face (on the flank: along the cut, against the new surface's motion)."""
    g = math.radians(gamma)
    n = fs.tool_normals()[part]
    t = np.array([math.sin(g), math.cos(g)]) if part == "rake face" else np.array([-n[1], n[0]])
    row = []
    for name in fs.PARTS:
        if name == part:
            fn_tool, ft_tool = -f_N * n, mu * f_N * t            # on the tool
            row += [*fn_tool, *ft_tool, f_N, mu * f_N, (mu if slipping else 2 * mu) * f_N,
                    f_N if slipping else 0.0, 1]
        else:
            row += [0.0] * 8 + [0]
    return row


@pytest.mark.parametrize("mu", [0.0, 0.3, 0.81])
def test_a_slipping_rake_face_gives_merchants_ratio(mu):
    fs = _script()
    from refsph.scenes.thermal_cutting import RAKE_DEG
    rows = np.array([_row(fs, "rake face", f, mu, True, RAKE_DEG) for f in (1e5, 3e5)])
    out = fs.split(rows, RAKE_DEG)
    merchant = math.tan(math.atan(mu) - math.radians(RAKE_DEG))
    assert out["Fc"] > 0                                        # the chip pushes the tool back along +x
    assert out["force_ratio"] == pytest.approx(merchant, rel=1e-12, abs=1e-12)
    assert out["rake_only_ratio"] == pytest.approx(merchant, rel=1e-12, abs=1e-12)
    assert out["merchant_bound_mu_eff"] == pytest.approx(merchant, rel=1e-12, abs=1e-12)
    rake = out["parts"]["rake face"]
    assert rake["mu_eff"] == pytest.approx(mu) and rake["mu_law"] == pytest.approx(mu) and rake["slip_share"] == 1


def test_sticking_contacts_lower_the_slip_share_and_the_edge_is_the_rest():
    fs = _script()
    from refsph.scenes.thermal_cutting import RAKE_DEG
    rows = np.array([_row(fs, "rake face", 1e5, 0.5, True, RAKE_DEG), _row(fs, "rake face", 3e5, 0.5, False,
                                                                             RAKE_DEG)])
    rake = fs.split(rows, RAKE_DEG)["parts"]["rake face"]
    assert rake["slip_share"] == pytest.approx(0.25) and rake["mu_law"] == pytest.approx(0.5 * 1 / 4 + 1.0 * 3 / 4)
    normals = fs.tool_normals()
    mid = normals["rake face"] + normals["flank"]
    n = np.array([normals["rake face"], normals["flank"], mid / np.linalg.norm(mid)])
    assert [fs.PARTS[k] for k in fs.classify(n, normals)] == ["rake face", "flank", "edge"]


def test_the_report_is_generated_from_the_json():
    import json
    doc = json.loads((ROOT / "benchmarks" / "force_split.json").read_text())
    assert _script().report(doc) == (ROOT / "benchmarks" / "force_split_report.md").read_text()
