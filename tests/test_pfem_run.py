"""``refsph run thermal_cutting --method pfem`` (refsph.pfem_run): the run folder has the SPH runs' layout (summary,
snapshots of numbers with their units, the triangles, the reaction CSV, the restart checkpoint); a restarted run
gives the numbers of an uninterrupted one to the bit; the heat ledger closes; ParaView gets the triangles; the CLI
refuses what the PFEM cannot take. A short cut: the quick scene with 0.3 t_u of travel (8 steps, ~20 s)."""
import json
import shutil

import numpy as np
import pytest

from refsph.cli import main
from refsph.crosscheck.compare import compare
from refsph.io import load_reactions, load_snapshot
from refsph.pfem_run import restart_pfem, run_pfem

SHORT = dict(travel="0.3")


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("pfem") / "run"
    res = run_pfem("thermal_cutting", out=out, options=SHORT, quick=True, progress=False)
    return out, res


def test_run_folder_has_the_sph_layout(short_run):
    out, res = short_run
    s = json.loads((out / "summary.json").read_text())
    assert s["method"] == "pfem" and s["scene"] == "thermal_cutting" and s["status"] == "ok"
    assert s["n_steps"] >= 6 and s["t_final"] == pytest.approx(s["t_end"], rel=1e-12)
    for key in ("cutting_force_N_per_m", "passive_force_N_per_m", "force_ratio", "rake_face_temperature_K",
                "chip_thickness_mm", "contact_length_mm", "measured"):
        assert key in s["metrics"]
    assert s["metrics"]["cutting_force_N_per_m"] > 0
    assert s["run_args"] == dict(scene_name="thermal_cutting", method="pfem", options=SHORT, quick=True)
    snaps = [load_snapshot(out / "snapshots" / name) for name in s["snapshots"]]
    assert len(snaps) >= 4 and snaps[0]["t"] == 0.0 and snaps[-1]["t"] == pytest.approx(s["t_end"], rel=1e-12)
    z = snaps[-1]
    n = len(z["x"])
    assert n == s["n_particles"]
    assert z["triangles"].dtype == np.int64 and z["triangles"].min() >= 0 and z["triangles"].max() < n
    assert z["units"]["triangles"].startswith("1") and z["units"]["p"] == "Pa" and z["units"]["tool_T"] == "K"
    for k, a in z.items():                                     # numbers only
        if isinstance(a, np.ndarray):
            assert a.dtype.kind in "fi", k
    x, tri = z["x"], z["triangles"]
    area = 0.5 * ((x[tri[:, 1], 0] - x[tri[:, 0], 0]) * (x[tri[:, 2], 1] - x[tri[:, 0], 1])
                  - (x[tri[:, 1], 1] - x[tri[:, 0], 1]) * (x[tri[:, 2], 0] - x[tri[:, 0], 0]))
    assert np.all(area > 0)                                    # counter-clockwise, none inverted
    assert abs(z["m"].sum() - snaps[0]["m"].sum()) <= 1e-12 * snaps[0]["m"].sum()   # node changes keep the mass
    assert len(np.unique(z["id"])) == n and z["id"].dtype == np.int64               # ids follow the nodes
    r = load_reactions(out / "reaction_forces.csv")
    assert len(r["t"]) == s["n_steps"] and np.all(np.diff(r["t"]) > 0)
    hb = s["heat_balance"]
    assert hb["plastic_J"] > 0 and abs(hb["residual_rel"]) < 1e-12     # the ledger closes to round-off
    assert np.max(z["T"]) > 300.0 and np.max(z["tool_T"]) > 293.0       # the chip and the tool heat


def test_restart_gives_the_uninterrupted_numbers(short_run, tmp_path):
    out, res = short_run
    part = tmp_path / "split"
    first = run_pfem("thermal_cutting", out=part, options=SHORT, quick=True, progress=False, max_steps=4)
    assert first.summary["status"] == "partial" and first.summary["n_steps"] == 4
    assert main(["run", "--restart", str(part), "--quiet"]) == 0          # the CLI dispatches to restart_pfem
    second = restart_pfem(part, progress=False)                            # nothing left to do: the same summary
    a, b = load_reactions(out / "reaction_forces.csv"), load_reactions(part / "reaction_forces.csv")
    np.testing.assert_array_equal(a["tool"], b["tool"])
    np.testing.assert_array_equal(a["t"], b["t"])
    for key in ("cutting_force_N_per_m", "rake_face_temperature_K", "max_temperature_K"):
        assert second.summary["metrics"][key] == res.summary["metrics"][key]
    za = load_snapshot(out / "snapshots" / res.summary["snapshots"][-1])
    zb = load_snapshot(part / "snapshots" / second.summary["snapshots"][-1])
    for k in ("x", "T", "eps_p", "triangles", "tool_T"):
        np.testing.assert_array_equal(za[k], zb[k])


def test_refsph_compare_takes_pfem_run_folders(short_run, tmp_path):
    """`refsph compare` on two PFEM run folders: the nodes have no reference positions X, so positions are judged
    against the largest displacement from REF's first snapshot; a copy passes, a node moved by 1 um fails at its
    id and time (the CLI said only "'X'" before)."""
    out, _ = short_run
    assert main(["compare", str(out), str(out)]) == 0
    test = tmp_path / "moved"
    shutil.copytree(out, test)
    last = sorted((test / "snapshots").glob("snap_*.npz"))[-1]
    with np.load(last) as f:
        z = dict(f)
    z["x"][5, 0] += 1e-6
    np.savez(last, **z)
    rows = compare(out, test)
    bad = [r for r in rows if not r.passed]
    assert [r.quantity.split()[-1] for r in bad] == ["x"] and bad[0].where.startswith(f"particle id {int(z['id'][5])}")
    assert main(["compare", str(out), str(test)]) == 1


def test_a_timed_checkpoint_changes_nothing_and_is_continued(short_run, tmp_path, monkeypatch):
    """checkpoint_every=0: a checkpoint after every step (between snapshots too: here only at the start and the end,
    which moves no number of the PFEM, whose step does not land on them); the run stopped after 5 steps continues
    from its fifth step, not from its last snapshot, to the uninterrupted run's numbers."""
    import refsph.pfem_run as pr
    monkeypatch.setattr(pr, "N_SNAPSHOTS", 1)
    out, res = short_run
    part = tmp_path / "timed"
    first = run_pfem("thermal_cutting", out=part, options=SHORT, quick=True, progress=False, max_steps=5,
                     checkpoint_every=0.0)
    kept, snaps, _ = pr._restore(part / "snapshots", pr.pfem_cut(**pr._options(SHORT, True)))
    assert first.summary["n_steps"] == 5 and kept.steps == 5 and snaps == ["snap_00000.npz"]
    second = restart_pfem(part, progress=False, checkpoint_every=0.0)
    assert second.summary["n_steps"] == res.summary["n_steps"]
    np.testing.assert_array_equal(load_reactions(out / "reaction_forces.csv")["tool"],
                                  load_reactions(part / "reaction_forces.csv")["tool"])
    for key in ("cutting_force_N_per_m", "rake_face_temperature_K", "max_temperature_K"):
        assert second.summary["metrics"][key] == res.summary["metrics"][key]
    with pytest.raises(ValueError, match="checkpoint_every"):
        run_pfem("thermal_cutting", out=tmp_path / "bad", options=SHORT, quick=True, checkpoint_every=float("nan"))
    with pytest.raises(ValueError, match="checkpoint_every must be"):            # not "not a PFEM run folder"
        restart_pfem(part, checkpoint_every=-1.0)


def test_provenance_is_the_code_that_ran(tmp_path, monkeypatch):
    """summary.json's provenance is taken when a run starts, not when the summary is written (a long run outlives
    its commit); a run continued at another commit names the earlier one."""
    import refsph.pfem_run as pr
    out = tmp_path / "run"
    commits = iter(["aaaa", "bbbb", "cccc", "dddd"])
    monkeypatch.setattr(pr, "provenance", lambda threads: dict(git_commit=next(commits), threads=threads))
    run_pfem("thermal_cutting", out=out, options=SHORT, quick=True, progress=False, max_steps=2)
    assert json.loads((out / "summary.json").read_text())["provenance"]["git_commit"] == "aaaa"
    restart_pfem(out, progress=False)
    prov = json.loads((out / "summary.json").read_text())["provenance"]
    assert prov["git_commit"] == "bbbb" and prov["earlier_commits"] == ["aaaa"]


def test_export_gives_paraview_the_triangles(short_run):
    meshio = pytest.importorskip("meshio")
    from refsph.crosscheck.export import export_vtk
    out, res = short_run
    export_vtk(out)
    last = res.summary["snapshots"][-1].replace(".npz", ".vtu")
    m = meshio.read(out / "vtk" / last)
    z = load_snapshot(out / "snapshots" / res.summary["snapshots"][-1])
    assert m.cells[0].type == "triangle"
    np.testing.assert_array_equal(m.cells[0].data, z["triangles"])
    np.testing.assert_allclose(m.point_data["T"], z["T"])
    assert "triangles" not in m.point_data and "tool_x" not in m.point_data


@pytest.mark.parametrize("args, says", [
    (("run", "taylor", "--method", "pfem"), "no PFEM version"),
    (("run", "thermal_cutting", "--method", "pfem", "--dp", "1e-5"), "--dp"),
    (("run", "thermal_cutting", "--method", "pfem", "--set", "beta1=1"), "--set"),
    (("run", "thermal_cutting", "--method", "pfem", "--option", "mass_scale=10"), "not an option of the PFEM cut"),
    (("run", "thermal_cutting", "--method", "pfem", "--option", "n_tu=abc"), "must be a number"),
    (("run", "thermal_cutting", "--method", "pfem", "--option", "edge_nodes=maybe"), "must be true or false"),
    (("run", "thermal_cutting", "--method", "pfem", "--option", "edge_radius=0"), "edge radius must be positive"),
])
def test_cli_refuses_what_the_pfem_cannot_take(args, says, tmp_path, capsys):
    assert main(list(args) + ["--out", str(tmp_path / "o")]) == 2
    assert says in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_a_spoilt_last_checkpoint_falls_back_on_the_one_before(short_run, tmp_path):
    """With restart.npz spoilt (a crash while writing it), --restart continues from restart_prev.npz, says so, and
    still ends as the uninterrupted run: the same reactions at every step."""
    out, res = short_run
    part = tmp_path / "split"
    run_pfem("thermal_cutting", out=part, options=SHORT, quick=True, progress=False, max_steps=3, checkpoint_every=0)
    snaps = part / "snapshots"
    assert (snaps / "restart_prev.npz").exists()
    (snaps / "restart.npz").write_bytes(b"not a zip")
    with pytest.warns(UserWarning, match="continuing from the checkpoint before it"):
        assert main(["run", "--restart", str(part), "--quiet"]) == 0
    a, b = load_reactions(out / "reaction_forces.csv"), load_reactions(part / "reaction_forces.csv")
    np.testing.assert_array_equal(a["t"], b["t"])
    np.testing.assert_array_equal(a["tool"], b["tool"])


def test_a_spoilt_checkpoint_is_a_clear_error(tmp_path, capsys):
    """A truncated restart.npz falls back on restart_prev.npz; with both spoilt, refsph run --restart says which
    files it could not read (exit 2), no zipfile traceback."""
    out = tmp_path / "run"
    run_pfem("thermal_cutting", out=out, options=SHORT, quick=True, progress=False, max_steps=1)
    snaps = out / "snapshots"
    for name in ("restart.npz", "restart_prev.npz"):
        if (snaps / name).exists():
            (snaps / name).write_bytes(b"not a zip")
    assert main(["run", "--restart", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "nothing to restart from" in err and "restart.npz" in err and "Traceback" not in err


def test_a_failed_cut_says_where_and_why_without_the_arrays():
    """A cut whose Newton-Raphson cannot converge (here: one iteration allowed) fails with the time, the last step
    it tried (dt / 16 after four halvings) and that try's own reason; the iterate it carries (NewtonFailed's
    args) is not printed."""
    from refsph.pfem.cutting import CutRun, pfem_cut
    from refsph.pfem.solid import NewtonFailed

    cut = pfem_cut(1, n_tu=5.0, travel=0.3, length=1.2e-3)
    cut.max_iter = 1
    run = CutRun(cut)
    with pytest.raises(NewtonFailed) as info:
        for _ in range(20):
            run.step()
    msg = str(info.value)
    assert msg.startswith("PFEM cut: Newton failed at t = ")
    assert f"even at dt = {cut.dt / 16:.2e} s" in msg and "(the last try: " in msg
    assert "array(" not in msg and len(msg) < 600
    assert len(info.value.args) == 3 and isinstance(info.value.args[2][0], np.ndarray)   # the iterate is kept


def test_a_killed_run_can_be_continued_from_the_command_line(short_run, tmp_path, monkeypatch):
    """A run killed between checkpoints (here: an interrupt in its fifth step) has summary.json with status
    'running' and how far it got, and `refsph run --restart` continues it to the uninterrupted run's numbers."""
    from refsph.pfem.cutting import CutRun

    step, calls = CutRun.step, []

    def interrupted(self):
        calls.append(1)
        if len(calls) == 5:
            raise KeyboardInterrupt
        return step(self)
    monkeypatch.setattr(CutRun, "step", interrupted)
    out = tmp_path / "killed"
    with pytest.raises(KeyboardInterrupt):
        run_pfem("thermal_cutting", out=out, options=SHORT, quick=True, progress=False)
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "running" and 0 < s["n_steps"] < 5 and s["method"] == "pfem"
    monkeypatch.setattr(CutRun, "step", step)
    assert main(["run", "--restart", str(out), "--quiet"]) == 0
    done = json.loads((out / "summary.json").read_text())
    assert done["status"] == "ok" and done["n_steps"] == short_run[1].summary["n_steps"]
    assert done["metrics"]["cutting_force_N_per_m"] == short_run[1].summary["metrics"]["cutting_force_N_per_m"]
    full = short_run[1].summary                             # CPU seconds of the steps, kept across the restart
    assert 0 < full["cpu_time_s"] <= 1.5 * full["wall_time_s"] + 1.0
    assert 0 < s["cpu_time_s"] < done["cpu_time_s"]


def test_a_pfem_run_holds_blas_at_one_thread(monkeypatch):
    """run_pfem runs inside one_blas_thread (BLAS threads that compete with other work for the cores spin: SuperLU
    and the residual norms call BLAS); without threadpoolctl the context changes nothing."""
    import builtins
    import contextlib

    import refsph.pfem_run as pr
    threadpoolctl = pytest.importorskip("threadpoolctl")
    with pr.one_blas_thread():
        blas = [p for p in threadpoolctl.threadpool_info() if p["user_api"] == "blas"]
        assert blas and all(p["num_threads"] == 1 for p in blas)
    entered = []

    @contextlib.contextmanager
    def spy():
        entered.append(True)
        yield

    monkeypatch.setattr(pr, "one_blas_thread", spy)
    with pytest.raises(ValueError, match="has no PFEM version"):
        pr.run_pfem("taylor_bar_of_nothing")
    assert entered == [True]
    monkeypatch.undo()
    real_import = builtins.__import__
    monkeypatch.setattr(builtins, "__import__", lambda name, *a, **k: (_ for _ in ()).throw(ImportError(name))
                        if name == "threadpoolctl" else real_import(name, *a, **k))
    assert isinstance(pr.one_blas_thread(), contextlib.nullcontext)


def test_a_stalled_newton_with_the_trapezoidal_rule_names_the_damped_rule(tmp_path, monkeypatch):
    """A run whose Newton fails with the paper's trapezoidal rule says, in its error and summary, that the damped
    rule (--option gamma=0.6, a departure) exists; with the damped rule the same failure does not repeat the hint."""
    from refsph.pfem.cutting import CutRun
    from refsph.pfem.solid import NewtonFailed
    from refsph.simulate import SimulationError

    step, calls = CutRun.step, []

    def stalls(self):
        calls.append(1)
        if len(calls) % 3 == 0:
            raise NewtonFailed("PFEM cut: Newton failed (a test)", [], None)
        return step(self)
    monkeypatch.setattr(CutRun, "step", stalls)
    for gamma, hinted in ((0.5, True), (0.6, False)):
        out = tmp_path / f"gamma_{gamma}"
        with pytest.raises(SimulationError) as info:
            run_pfem("thermal_cutting", out=out, options=dict(SHORT, gamma=gamma), quick=True, progress=False)
        s = json.loads((out / "summary.json").read_text())
        assert s["status"] == "failed" and "Newton failed (a test)" in s["error"]
        assert ("--option gamma=0.6" in str(info.value)) == hinted and ("--option gamma=0.6" in s["error"]) == hinted


def test_remeshing_when_needed_is_an_option():
    """--option remesh_when_needed=true: Algorithm 1's "if remeshing is needed" read literally (a remeshing only
    where a triangle's quality falls below 0.3); by default the cut remeshes after every step."""
    from refsph.pfem.cutting import pfem_cut, run_pfem_cut
    from refsph.pfem_run import _options

    kw = _options(dict(SHORT, remesh_when_needed="true"), quick=True)
    assert kw["remesh_when_needed"] is True
    lazy, every = pfem_cut(**kw), pfem_cut(**_options(SHORT, quick=True))
    assert lazy.remesh_every is None and lazy.info["remesh_when_needed"] and every.remesh_every == 1
    a, b = run_pfem_cut(lazy), run_pfem_cut(every)
    assert b["remeshes"] == b["steps"] and a["remeshes"] < a["steps"] and a["steps"] == b["steps"]
    with pytest.raises(ValueError, match="true or false"):
        _options(dict(remesh_when_needed="sometimes"), quick=True)


def test_friction_without_its_heat_is_an_option():
    """--option eta=0: friction acts (its force on the tool) but its work makes no heat, in the chip or the tool;
    the default is the paper's eta = 1 (Eq. (7)); eta outside [0, 1] is refused."""
    from refsph.pfem.cutting import pfem_cut, run_pfem_cut
    from refsph.pfem_run import _options

    kw = _options(dict(SHORT, travel="0.6", eta="0"), quick=True)
    cold, hot = pfem_cut(**kw), pfem_cut(**_options(dict(SHORT, travel="0.6"), quick=True))
    assert kw["eta"] == 0.0 and cold.info["eta"] == 0.0 and cold.heat.eta == 0.0 and hot.info["eta"] == 1.0
    a, b = run_pfem_cut(cold), run_pfem_cut(hot)
    assert b["heat_balance"]["friction_J"] > 0.0 and b["heat_balance"]["friction_to_tool_J"] > 0.0
    assert a["heat_balance"]["friction_J"] == 0.0 and a["heat_balance"]["friction_to_tool_J"] == 0.0
    assert abs(a["metrics"]["passive_force_N_per_m"]) > 0.0
    with pytest.raises(ValueError, match="eta"):
        pfem_cut(**_options(dict(SHORT, eta="1.5"), quick=True))


def test_a_checkpoint_without_cpu_seconds_continues_with_them_unknown():
    """CutRun.restore of a checkpoint written before the CPU seconds were kept: the run goes on and says it does
    not know them (None), rather than counting from zero; a checkpoint that kept them goes on counting."""
    import json as js

    from refsph.pfem.cutting import CutRun, pfem_cut

    cut = pfem_cut(1, n_tu=5.0, travel=0.3, length=1.2e-3)
    run = CutRun(cut)
    run.step()
    ck = run.checkpoint()
    assert js.loads(str(ck["record"]))["cpu"] > 0
    again = CutRun.restore(cut, dict(ck))
    again.step()
    assert again.cpu > run.cpu
    rec = js.loads(str(ck["record"]))
    del rec["cpu"]
    old = CutRun.restore(cut, dict(ck, record=np.array(js.dumps(rec))))
    old.step()
    assert old.cpu is None and old.result()["cpu_time_s"] is None


def test_the_edge_radius_is_an_option_of_the_contact_outline():
    """--option edge_radius=R [m]: the contact's outline has the tool's edge rounded by R (the paper's 10 um by
    default), so the outline's apex moves back along the bisector by R (1/sin(beta/2) - 1)."""
    import math
    from refsph.pfem.cutting import pfem_cut
    from refsph.pfem_run import _options
    from refsph.scenes.thermal_cutting import CLEARANCE_DEG, RAKE_DEG

    kw = _options(dict(SHORT, edge_radius="3e-5"), quick=True)
    blunt, sharp = pfem_cut(**kw), pfem_cut(**_options(SHORT, quick=True))
    assert blunt.shape.radius == 3e-5 and sharp.shape.radius == 1e-5 and blunt.info["edge_radius_m"] == 3e-5
    half = math.radians(90.0 - RAKE_DEG - CLEARANCE_DEG) / 2
    apex = np.array(sharp.info["apex0"]) - sharp.shift0                  # the sharp corner, in the outline's frame
    tip = [min(np.linalg.norm(apex - np.array(c)) for c in cut.shape.core) - cut.shape.radius for cut in (sharp, blunt)]
    assert tip[1] - tip[0] == pytest.approx(2e-5 * (1 / math.sin(half) - 1), rel=1e-9)
