"""benchmarks/force_split.py splits the tool's force by part of its outline and by normal and friction force: its
rows read from real contact results (an SPH penalty evaluation, a PFEM step contact) against the scene's tool add up
to the force on the tool and put the friction of a chip sliding up the rake face on the tool along the face; its
split of a rake face whose contacts all slip gives Merchant's relation; points next to each part of the tool's
outline are classified by that part; and the committed report is what the script writes from the JSON."""
import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
TU, DX = 1e-4, 1e-5


def _script():
    spec = importlib.util.spec_from_file_location("bench_force_split", ROOT / "benchmarks" / "force_split.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _tool():
    """The scene's tool outline with its edge at the origin (its core's centroid at shift), and the rake face's
    direction up the face u and outward normal n."""
    from refsph.scenes.thermal_cutting import RAKE_DEG, tool_shape
    centroid = np.array([3e-4, 1.5e-4])
    g = math.radians(RAKE_DEG)
    return tool_shape(TU, (0.0, 0.0), centroid, 10.0, 6.0), centroid, np.array([math.sin(g), math.cos(g)]), \
        np.array([-math.cos(g), math.sin(g)])


def _friction():
    from refsph.contact import CoulombFriction
    return CoulombFriction(mu0=0.8, q=12.0, T_room=293.0, T_melt=1733.0)


def _totals(fs, row):
    """The force on the tool (x, y) summed over the parts of a row, and the rake face's friction force."""
    w = fs.PART_WIDTH
    parts = np.array(row[:-1]).reshape(len(fs.PARTS), w)
    return parts[:, 0:2].sum(0) + parts[:, 2:4].sum(0), parts[fs.PARTS.index("rake face"), 2:4]


@pytest.mark.parametrize("speed", [0.01, 5.0])                   # stick, slip
def test_penalty_rows_add_up_to_the_force_on_the_tool(speed):
    from refsph.penalty import PenaltyContact, penalty_contact
    fs = _script()
    tool, shift, up, n = _tool()
    x = np.array([3 * TU * up + 0.3 * DX * n, 2 * TU * up + 0.2 * DX * n])       # on the rake face, touching
    V = np.array([-1.0, 0.0])                                                      # the tool's velocity
    v = np.tile(V + speed * up, (2, 1))                                            # the chip slides up the face
    m, T, dt = np.full(2, 7.8e3 * DX * DX), np.full(2, 600.0), 1e-6     # slip: v dt > mu g
    contact = PenaltyContact(alpha=0.1, damping=0.5, offset=0.5 * DX, time_scale=DX / 5e3, friction=_friction())
    c = penalty_contact(x, v, m, T, tool, shift, V, dt, contact, np.zeros((2, 2)))
    assert np.all(c.gap > 0)
    row = fs.row_from_penalty(c, x, T, tool, shift, contact, dt)
    total, rake_friction = _totals(fs, row)
    np.testing.assert_allclose(total, c.force_on_tool, rtol=1e-12)
    assert row[-1] == dt and rake_friction @ up > 0 and abs(rake_friction @ n) < 1e-9 * np.abs(rake_friction).max()
    out = fs.split(np.array([row]), 10.0)
    slipping = out["parts"]["rake face"]["slip_share"]
    assert (slipping == 1.0) if speed > 1 else (slipping == 0.0)


def test_pfem_rows_add_up_to_the_force_on_the_tool():
    from refsph.pfem.contact import StepContact, ToolContact
    fs = _script()
    tool, shift, up, n = _tool()
    x_n = np.array([3 * TU * up - 0.01 * DX * n, 2 * TU * up + 0.5 * DX * n, 4 * TU * up - 0.02 * DX * n])
    du_tool = np.array([-2e-7, 0.0])
    x_new = x_n + du_tool + np.array([0.0, 0.0, 1.0])[:, None] * 5e-8 * up   # the tool's move; node 2 slides up
    params = ToolContact(k_normal=1e17, k_tangent=1e17, friction=_friction())
    c = StepContact(params, tool, shift + du_tool, du_tool, x_n, np.zeros(3), np.full(3, 600.0), np.full(3, DX),
                    np.arange(3))
    f, _ = c(x_new)
    row = fs.row_from_step_contact(c, x_new, 2.5e-6)
    total, rake_friction = _totals(fs, row)
    np.testing.assert_allclose(total, -f.sum(0), rtol=1e-12)
    assert rake_friction @ up > 0 and row[fs.PARTS.index("rake face") * fs.PART_WIDTH + 8] == 2    # two nodes touch


@pytest.mark.parametrize("mu", [0.0, 0.3, 0.81])
def test_a_slipping_rake_face_gives_merchants_ratio(mu):
    fs = _script()
    _, _, up, n = _tool()
    f_N = np.array([1e5, 3e5])
    row = fs.row_of(np.array([n, n]), f_N, -mu * f_N[:, None] * up, np.full(2, mu), np.ones(2, bool), 1e-9)
    out = fs.split(np.array([row, row]), 10.0)
    merchant = math.tan(math.atan(mu) - math.radians(10.0))
    assert out["Fc"] > 0                                        # the chip pushes the tool back along +x
    for key in ("force_ratio", "rake_only_ratio", "merchant_bound_mu_eff", "ratio_rake_slipping"):
        assert out[key] == pytest.approx(merchant, rel=1e-12, abs=1e-12), key
    rake = out["parts"]["rake face"]
    assert rake["mu_eff"] == pytest.approx(mu) and rake["mu_law"] == pytest.approx(mu) and rake["slip_share"] == 1


def test_points_next_to_the_outline_are_classified_by_their_part():
    fs = _script()
    tool, shift, up, n = _tool()
    from refsph.scenes.thermal_cutting import CLEARANCE_DEG
    c = math.radians(CLEARANCE_DEG)
    along_flank = np.array([math.cos(c), math.sin(c)])
    x = np.array([2 * TU * up + 0.2 * DX * n,                                     # off the rake face
                  2 * TU * along_flank + 0.2 * DX * np.array([math.sin(c), -math.cos(c)]),   # off the flank
                  -0.2 * DX * (up + along_flank) / np.linalg.norm(up + along_flank)])  # off the edge, between
    _, normals = tool.gap(x, shift)
    assert [fs.PARTS[k] for k in fs.classify(normals, fs.tool_normals())] == ["rake face", "flank", "edge"]


def test_the_scratch_copy_never_is_the_recorded_run(tmp_path):
    fs = _script()
    run = tmp_path / "case_1"
    run.mkdir()
    with pytest.raises(SystemExit, match="overwrite the recorded run"):
        fs.scratch_copy(run, tmp_path)
    assert run.exists() and fs.scratch_copy(run, tmp_path / "scratch") == tmp_path / "scratch" / "case_1"


def test_the_report_is_generated_from_the_json():
    doc = json.loads((ROOT / "benchmarks" / "force_split.json").read_text())
    assert _script().report(doc) == (ROOT / "benchmarks" / "force_split_report.md").read_text()


def test_merge_takes_rows_made_elsewhere(tmp_path, capsys):
    """--merge: the rows of another force-split JSON join --json, a row of the same key replaced; anything else is
    refused by name."""
    fs = _script()
    rows = json.loads((ROOT / "benchmarks" / "force_split.json").read_text())["results"]
    (tmp_path / "a.json").write_text(json.dumps(dict(results=rows[:2])))
    (tmp_path / "b.json").write_text(json.dumps(dict(results=[dict(rows[1], Fc=1.0), rows[2]])))
    assert fs.main(["--merge", str(tmp_path / "b.json"), "--json", str(tmp_path / "a.json")]) == 0
    merged = json.loads((tmp_path / "a.json").read_text())["results"]
    assert [r["key"] for r in merged] == [rows[0]["key"], rows[1]["key"], rows[2]["key"]] and merged[1]["Fc"] == 1.0
    for text, says in (("[1, 2]", "not a force-split file"), ('{"results": [{"Fc": 1}]}', "each with its 'key'"),
                       ("{", "--merge")):
        (tmp_path / "c.json").write_text(text)
        with pytest.raises(SystemExit):
            fs.main(["--merge", str(tmp_path / "c.json"), "--json", str(tmp_path / "a.json")])
        assert says in capsys.readouterr().err
    with pytest.raises(SystemExit):
        fs.main(["--merge", str(tmp_path / "none.json"), "--json", str(tmp_path / "a.json")])
    assert "does not exist" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        fs.main(["--merge", str(tmp_path / "b.json"), "--report"])
    assert "runs nothing" in capsys.readouterr().err
    assert json.loads((tmp_path / "a.json").read_text())["results"] == merged      # untouched by the refusals


def test_spacing_pairs_compare_one_case_across_spacings():
    """A row's spacing comes from the row or from the sweep's record of its key (or run folder); rows of one case
    and method at two spacings give one phrase, coarsest to finest; a what-if or a lone spacing gives none."""
    fs = _script()
    row = {k: v for k, v in json.loads((ROOT / "benchmarks" / "force_split.json").read_text())["results"][0].items()
           if k not in ("case", "dx_m", "tu_m")}                     # a row as made before the spacing was kept
    rows = [row]
    a, b = (dict(row, key=k, method="pfem", case=7, dx_m=dx) for k, dx in (("fine", 1e-5), ("coarse", 2e-5)))
    b["parts"] = dict(b["parts"], edge={k: 0.0 for k in b["parts"]["edge"]})
    assert fs.spacing(a, {}) == (7, 1e-5) and fs.spacing(dict(rows[0], key="nowhere"), {}) == (None, None)
    runs = {"case 3 pfem": dict(status="ok", scene_info=dict(case=3, dx=2e-5))}
    assert fs.spacing(dict(rows[0], key="case_3_pfem"), runs) == (3, 2e-5)
    assert fs.spacing(dict(rows[0], key="case 3 pfem, penalty 1"), runs) == (3, 2e-5)
    (phrase,) = fs.spacing_pairs([a, b, dict(a, key="what-if", numerics_changed={"x": 1}, dx_m=5e-6),
                                  dict(b, key="coarse again")], {})            # one row per spacing: the first
    assert phrase.startswith("case 7 (PFEM; 'coarse' -> 'fine'), 20.0 -> 10.0 um: the edge's share of Fc 0.00 -> "
                             f"{fs.share(a, 'edge', 'Fc'):.2f}")
    assert fs.spacing_pairs([a], {}) == []
