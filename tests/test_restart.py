"""A run stopped and restarted from its last snapshot ends with the same bits as the run that was never stopped
(both methods; mirror ghosts and a wall, a clamp and a tool), and its metrics are the same too."""
import json

import numpy as np
import pytest

import refsph.simulate as sim
from refsph import load_run, load_snapshot
from refsph.cli import main
from refsph.simulate import run

CASES = [("taylor", "tlsph", dict(dim=2, quick=True, t_end=6e-6)),
         ("taylor", "tlsph", dict(dim=2, quick=True, t_end=6e-6, numerics=dict(gain_step=True))),  # step over gain
         ("pressing", "esph", dict(quick=True, t_end=0.2e-6)),
         ("pressing", "tlsph", dict(quick=True, t_end=0.2e-6)),
         ("pressing", "tlsph", dict(quick=True, t_end=0.2e-6, numerics=dict(integrator="leapfrog"))),  # kept force
         ("taylor", "esph", dict(dim=2, quick=True, t_end=6e-6, numerics=dict(integrator="leapfrog"))),
         ("thermal_cutting", "tlsph", dict(quick=True, t_end=2e-5, numerics=dict(threads=1),     # heat flow, ledger
                                           options=dict(case=1, length=0.5e-3, travel=1.0))),
         ("thermal_cutting", "tlsph", dict(quick=True, t_end=2e-5, numerics=dict(threads=1, contact="penalty"),
                                           options=dict(case=1, length=0.5e-3, travel=1.0))),   # friction history
         ("thermal_cutting", "tlsph", dict(quick=True, t_end=2e-5,                # the step under 2 / w_max
                                           numerics=dict(threads=1, contact="penalty", frequency_step=0.2),
                                           options=dict(case=1, length=0.5e-3, travel=1.0))),
         ("thermal_cutting", "tlsph", dict(quick=True, t_end=2e-5,                # heat kept between heat steps
                                           numerics=dict(threads=1, contact="penalty", heat_every=7),
                                           options=dict(case=1, length=0.5e-3, travel=1.0))),
         ("pressing", "esph", dict(quick=True, t_end=0.2e-6, numerics=dict(contact="penalty")))]   # ESPH's tool out


def _killed(monkeypatch, scene, method, out, kw):
    """The same run, interrupted (as by Ctrl-C) at 45 % of its time, after a few snapshots were written."""
    original = sim.simulate

    def with_kill(*args, **k):
        def hook(state, solver):
            if state.t > 0.45 * kw["t_end"]:
                raise KeyboardInterrupt
        return original(*args, **dict(k, hook=hook))

    monkeypatch.setattr(sim, "simulate", with_kill)
    with pytest.raises(KeyboardInterrupt):
        run(scene, method, out=out, progress=False, **kw)
    monkeypatch.setattr(sim, "simulate", original)


@pytest.mark.parametrize("scene, method, kw", CASES,
                         ids=[f"{c[0]}-{c[1]}" + ("-leapfrog" if "integrator" in c[2].get("numerics", {}) else "")
                              + ("-penalty" if c[2].get("numerics", {}).get("contact") == "penalty" else "")
                              + ("-heat_every" if "heat_every" in c[2].get("numerics", {}) else "")
                              for c in CASES])
def test_restart_is_bit_for_bit(tmp_path, monkeypatch, scene, method, kw):
    whole = run(scene, method, out=tmp_path / "whole", progress=False, **kw)
    _killed(monkeypatch, scene, method, tmp_path / "cut", kw)
    cut = json.loads((tmp_path / "cut" / "summary.json").read_text())
    assert cut["status"] == "interrupted" and cut["t_final"] < kw["t_end"]
    if "heat_every" in kw.get("numerics", {}):                           # the checkpoint holds heat not yet applied
        assert np.load(tmp_path / "cut" / "snapshots" / "restart.npz")["physics/heat/pending_steps"] > 0
    assert main(["run", "--restart", str(tmp_path / "cut"), "--quiet"]) == 0
    a = load_snapshot(load_run(tmp_path / "whole")[1][-1])
    b = load_snapshot(load_run(tmp_path / "cut")[1][-1])
    assert a["t"] == b["t"] == pytest.approx(kw["t_end"])
    for key in ("x", "v", "rho", "S", "S_zz", "eps_p", "T"):
        assert np.array_equal(a[key], b[key]), key
    again = json.loads((tmp_path / "cut" / "summary.json").read_text())
    assert again["status"] == "ok" and again["restarts"] == 1 and again["n_steps"] == whole.summary["n_steps"]
    numbers = {k: v for k, v in whole.summary["metrics"].items() if isinstance(v, (int, float))}
    assert numbers and all(again["metrics"][k] == v for k, v in numbers.items() if v == v)
    forces = [d / "reaction_forces.csv" for d in (tmp_path / "whole", tmp_path / "cut")]
    assert forces[0].exists() == (scene in ("pressing", "thermal_cutting"))     # the scenes with tools or clamps
    if forces[0].exists():                                         # every step's reaction, none lost at the restart
        assert forces[0].read_text() == forces[1].read_text()
    assert ("heat_balance" in whole.summary) == (scene == "thermal_cutting")
    if "heat_balance" in whole.summary:                            # the heat ledger continues, not restarts
        assert again["heat_balance"] == whole.summary["heat_balance"]


def _same_run(whole, cut):
    """The restarted run ``cut`` ends as ``whole``: its last snapshot, step count, metrics, reactions, heat ledger."""
    a, b = (load_snapshot(load_run(d)[1][-1]) for d in (whole, cut))
    assert all(np.array_equal(a[k], b[k]) for k in ("x", "v", "rho", "S", "S_zz", "eps_p", "T"))
    s, again = (json.loads((d / "summary.json").read_text()) for d in (whole, cut))
    assert again["status"] == "ok" and again["n_steps"] == s["n_steps"] and again["snapshots"] == s["snapshots"]
    numbers = {k: v for k, v in s["metrics"].items() if isinstance(v, (int, float)) and v == v}
    assert numbers and all(again["metrics"][k] == v for k, v in numbers.items())
    assert again["heat_balance"] == s["heat_balance"]
    assert (whole / "reaction_forces.csv").read_text() == (cut / "reaction_forces.csv").read_text()


@pytest.mark.parametrize("case", [6, 7], ids=["penalty", "heat_every"])
def test_restart_from_a_timed_checkpoint_is_bit_for_bit(tmp_path, monkeypatch, case):
    """Between snapshots a checkpoint is written every ``checkpoint_every`` seconds of wall time (here 0: after every
    step): it changes no bit of the run; a killed run continues from the step it reached (not from its last
    snapshot); with that checkpoint's state spoilt, from the one before, whose state file is another; a finished
    run keeps none of the timed states."""
    from refsph.io import run_files
    kw = dict(CASES[case][2])                                       # thermal cutting: friction history, heat kept
    whole = run("thermal_cutting", "tlsph", out=tmp_path / "whole", progress=False, checkpoint_every=None, **kw)
    every = run("thermal_cutting", "tlsph", out=tmp_path / "every", progress=False, checkpoint_every=0.0, **kw)
    assert np.array_equal(whole.state.x, every.state.x) and np.array_equal(whole.state.T, every.state.T)
    assert not list((tmp_path / "every" / "snapshots").glob("checkpoint_*"))
    for spoil in (False, True):
        cut = tmp_path / f"cut{spoil}"
        _killed(monkeypatch, "thermal_cutting", "tlsph", cut, dict(kw, checkpoint_every=0.0))
        ck, prev = (json.loads(str(np.load(cut / "snapshots" / n)["run"])) for n in ("restart.npz", "restart_prev.npz"))
        assert ck["snapshot"] != prev["snapshot"] and {ck["snapshot"], prev["snapshot"]} <= set(sim.TIMED_STATES)
        assert ck["n_steps"] == prev["n_steps"] + 1 and ck["next_snap"] < len(whole.summary["snapshots"])
        assert {cut / "snapshots" / n for n in sim.TIMED_STATES} <= set(run_files(cut))
        if spoil:
            path = cut / "snapshots" / ck["snapshot"]
            path.write_bytes(path.read_bytes()[:200])
            with pytest.warns(UserWarning, match="checkpoint before"):
                assert main(["run", "--restart", str(cut), "--quiet"]) == 0
        else:
            assert main(["run", "--restart", str(cut), "--quiet"]) == 0
        _same_run(tmp_path / "whole", cut)
        assert not list((cut / "snapshots").glob("checkpoint_*"))
    with pytest.raises(ValueError, match="checkpoint_every"):
        run("thermal_cutting", "tlsph", out=tmp_path / "bad", progress=False, checkpoint_every=-1.0, **kw)


def test_a_checkpoint_whose_state_was_overwritten_is_refused(tmp_path, monkeypatch):
    """A checkpoint names its state file and its time: a state file overwritten since (another step's state under
    its name) is not continued from silently; the restart takes the checkpoint before, or says there is none."""
    kw = dict(CASES[6][2])
    whole = run("thermal_cutting", "tlsph", out=tmp_path / "whole", progress=False, checkpoint_every=None, **kw)
    cut = tmp_path / "cut"
    _killed(monkeypatch, "thermal_cutting", "tlsph", cut, dict(kw, checkpoint_every=0.0))
    snaps = cut / "snapshots"
    ck, prev = (json.loads(str(np.load(snaps / n)["run"]))["snapshot"] for n in ("restart.npz", "restart_prev.npz"))
    (snaps / ck).write_bytes((snaps / prev).read_bytes())        # the last checkpoint's state: an older step's
    with pytest.warns(UserWarning, match="overwritten since"):
        assert main(["run", "--restart", str(cut), "--quiet"]) == 0
    _same_run(tmp_path / "whole", cut)
    assert whole.summary["status"] == "ok"
    cut2 = tmp_path / "cut2"
    _killed(monkeypatch, "thermal_cutting", "tlsph", cut2, dict(kw, checkpoint_every=0.0))
    snaps = cut2 / "snapshots"
    for n in ("restart.npz", "restart_prev.npz"):                 # both states swapped: neither can be continued
        name = json.loads(str(np.load(snaps / n)["run"]))["snapshot"]
        (snaps / name).write_bytes((snaps / "snap_00000.npz").read_bytes())
    with pytest.raises(ValueError, match="nothing to restart from"):
        run("thermal_cutting", "tlsph", out=cut2, progress=False, restart=True, **kw)


def test_restart_input_errors(tmp_path, capsys):
    assert main(["run", "--restart", str(tmp_path / "nothing"), "--quiet"]) == 2
    assert main(["run", "bar", "--restart", str(tmp_path), "--quiet"]) == 2
    assert "takes no a scene" in capsys.readouterr().err
    for flags in (["--t-end", "1e-6"], ["--from", "p.npz"], ["--set", "beta1=1"], ["--out", "x"]):
        assert main(["run", "--restart", str(tmp_path), "--quiet"] + flags) == 2      # not silently ignored
        assert flags[0] in capsys.readouterr().err


KW = dict(quick=True, t_end=0.2e-6)


@pytest.mark.parametrize("spoil", ["checkpoint", "snapshot"])
def test_restart_falls_back_to_the_checkpoint_before_a_spoilt_one(tmp_path, monkeypatch, spoil):
    """A crash can leave the last checkpoint or the last snapshot truncated: --restart says so and continues from
    the checkpoint before it (restart_prev.npz), to the same bits as the run that was never stopped."""
    whole = run("pressing", "tlsph", out=tmp_path / "whole", progress=False, **KW)
    _killed(monkeypatch, "pressing", "tlsph", tmp_path / "cut", KW)
    snaps = tmp_path / "cut" / "snapshots"
    last = json.loads(str(np.load(snaps / "restart.npz")["run"]))["snapshot"]
    victim = snaps / ("restart.npz" if spoil == "checkpoint" else last)
    victim.write_bytes(victim.read_bytes()[:200])                  # truncated
    with pytest.warns(UserWarning, match="checkpoint before"):
        assert main(["run", "--restart", str(tmp_path / "cut"), "--quiet"]) == 0
    a, b = (load_snapshot(load_run(tmp_path / d)[1][-1]) for d in ("whole", "cut"))
    assert all(np.array_equal(a[k], b[k]) for k in ("x", "v", "S", "eps_p"))
    again = json.loads((tmp_path / "cut" / "summary.json").read_text())
    assert again["n_steps"] == whole.summary["n_steps"] and again["snapshots"] == whole.summary["snapshots"]


def test_a_restart_names_the_commit_of_the_part_before(tmp_path, monkeypatch):
    """A run continued at another commit keeps that of its first part in provenance.earlier_commits."""
    commits = iter(["first", "second"])
    monkeypatch.setattr(sim, "provenance", lambda threads: dict(git_commit=next(commits), threads=threads))
    _killed(monkeypatch, "pressing", "tlsph", tmp_path / "cut", KW)
    assert json.loads((tmp_path / "cut" / "summary.json").read_text())["provenance"]["git_commit"] == "first"
    run("pressing", "tlsph", out=tmp_path / "cut", progress=False, restart=True, **KW)
    prov = json.loads((tmp_path / "cut" / "summary.json").read_text())["provenance"]
    assert prov["git_commit"] == "second" and prov["earlier_commits"] == ["first"]


def test_restart_refuses_a_hand_edited_summary(tmp_path, capsys):
    run("bar", "tlsph", out=tmp_path / "r", progress=False, quick=True, t_end=0.2e-6)
    path = tmp_path / "r" / "summary.json"
    s = json.loads(path.read_text())
    s["run_args"]["colour"] = "red"
    path.write_text(json.dumps(s))
    assert main(["run", "--restart", str(tmp_path / "r"), "--quiet"]) == 2
    assert "unknown entries colour" in capsys.readouterr().err
    path.write_text("{not json")
    assert main(["run", "--restart", str(tmp_path / "r"), "--quiet"]) == 2
    assert "summary.json is not valid JSON" in capsys.readouterr().err


def test_run_from_external_particles(tmp_path, capsys):
    """--from: another code's particles (here the scene's own, shifted in time by nothing) give the scene's run;
    missing or inconsistent arrays are named."""
    from refsph.scenes import get_scene
    setup = get_scene("pressing").setup(quick=True)
    s = setup.state
    f = tmp_path / "p.npz"
    np.savez(f, x=s.x, v=s.v, m=s.m, body=s.body, clamp_left_side=setup.clamps[0].index)
    res = run("pressing", "tlsph", quick=True, t_end=0.05e-6, progress=False, particles=f, out=tmp_path / "r")
    ref = run("pressing", "tlsph", quick=True, t_end=0.05e-6, progress=False)
    assert np.array_equal(res.state.x, ref.state.x)                  # the same particles: the same run
    assert res.summary["run_args"]["particles"] == str(f.resolve())
    ids = np.random.default_rng(0).permutation(s.n) + 1000         # the file's own ids: the snapshots keep them
    np.savez(f, x=s.x, v=s.v, m=s.m, body=s.body, clamp_left_side=setup.clamps[0].index, id=ids)
    run("pressing", "tlsph", quick=True, t_end=0.05e-6, progress=False, particles=f, out=tmp_path / "ids")
    snaps = sorted((tmp_path / "ids" / "snapshots").glob("snap_*.npz"))
    assert all(np.array_equal(np.load(p)["id"], ids) for p in snaps) and len(snaps) > 1
    np.savez(f, x=s.x, v=s.v, m=s.m, body=s.body, clamp_left_side=setup.clamps[0].index, id=np.zeros(s.n, int))
    assert main(["run", "pressing", "--quick", "--quiet", "--from", str(f), "--out", str(tmp_path / "q")]) == 2
    assert "distinct integers" in capsys.readouterr().err
    np.savez(f, x=s.x, v=s.v, m=s.m, body=s.body)
    assert main(["run", "pressing", "--quick", "--quiet", "--from", str(f), "--out", str(tmp_path / "q")]) == 2
    assert "clamp_left_side" in capsys.readouterr().err
    twins = s.x.copy()
    twins[5] = twins[4]
    np.savez(f, x=twins, v=s.v, m=s.m, body=s.body, clamp_left_side=setup.clamps[0].index)
    assert main(["run", "pressing", "--quick", "--quiet", "--from", str(f), "--out", str(tmp_path / "q")]) == 2
    assert "particles 4 and 5 sit at the same position" in capsys.readouterr().err
    np.savez(f, x=s.x, v=s.v[:10], m=s.m)
    assert main(["run", "pressing", "--quick", "--quiet", "--from", str(f), "--out", str(tmp_path / "q")]) == 2
    assert "array v has shape" in capsys.readouterr().err
    np.savez(f, x=s.x, m=s.m)
    assert main(["run", "pressing", "--quick", "--quiet", "--from", str(f), "--out", str(tmp_path / "q")]) == 2
    assert "missing array(s) v" in capsys.readouterr().err


def test_a_restart_with_other_arguments_is_refused(tmp_path, monkeypatch):
    """run(..., restart=True) continues a run folder only with the arguments it was made with: a killed run asked to
    go on at another time step (or with another option) is refused with what differs, and nothing is written;
    with its own arguments it goes on."""
    kw = dict(dim=2, quick=True, t_end=6e-6)
    _killed(monkeypatch, "taylor", "tlsph", tmp_path / "cut", kw)
    before = (tmp_path / "cut" / "summary.json").read_text()
    with pytest.raises(ValueError, match="other arguments.*courant"):
        run("taylor", "tlsph", out=tmp_path / "cut", progress=False, restart=True, numerics=dict(courant=0.15), **kw)
    with pytest.raises(ValueError, match="other arguments.*t_end"):
        run("taylor", "tlsph", out=tmp_path / "cut", progress=False, restart=True, **dict(kw, t_end=5e-6))
    assert (tmp_path / "cut" / "summary.json").read_text() == before
    assert run("taylor", "tlsph", out=tmp_path / "cut", progress=False, restart=True, **kw).summary["status"] == "ok"


def test_earlier_commits_reads_what_it_can(tmp_path):
    """earlier_commits: a commit once per stretch of restarts at it; nothing from a folder without a summary or with
    one that refsph did not write."""
    assert sim.earlier_commits(tmp_path) == []
    prov = dict(git_commit="b", earlier_commits=["a", "b"])
    (tmp_path / "summary.json").write_text(json.dumps(dict(provenance=prov)))
    assert sim.earlier_commits(tmp_path) == ["a", "b"]
    for bad in ('{"provenance": "x"}', '{"provenance": {"earlier_commits": 3}}', "[1]", "{"):
        (tmp_path / "summary.json").write_text(bad)
        assert sim.earlier_commits(tmp_path) == []


def test_the_command_line_sets_the_checkpoint_interval(tmp_path, monkeypatch):
    """refsph run --checkpoint-every S reaches the run loop (a run and a restart), 600 s without it."""
    seen, original = [], sim.simulate

    def spy(*args, **k):
        seen.append(k["checkpoint_every"])
        return original(*args, **k)
    monkeypatch.setattr(sim, "simulate", spy)
    out = str(tmp_path / "r")
    assert main(["run", "pressing", "--method", "tlsph", "--quick", "--t-end", "0.1e-6", "--out", out, "--quiet",
                 "--checkpoint-every", "0"]) == 0
    assert main(["run", "--restart", out, "--quiet", "--checkpoint-every", "inf"]) == 0
    assert main(["run", "pressing", "--method", "tlsph", "--quick", "--t-end", "0.1e-6", "--out", out, "--quiet"]) == 0
    assert seen == [0.0, float("inf"), 600.0] and sim.CHECKPOINT_EVERY_S == 600.0
