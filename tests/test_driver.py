"""The run driver, CLI and output files: validation, summary and snapshots, failure handling."""
import dataclasses
import json

import numpy as np
import pytest

from refsph import load_run, load_snapshot
from refsph.cli import main
from refsph.material import ElasticMaterial
from refsph.scenes import get_scene
from refsph.simulate import SimulationError, run, simulate

REQUIRED = {"scene", "method", "dim", "dp", "n_particles", "n_steps", "wall_time_s", "metrics"}


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_run_writes_summary_and_snapshots(tmp_path, method):
    out = tmp_path / "run"
    res = run("bar", method, quick=True, t_end=2e-6, out=out, progress=False)
    summary, snaps = load_run(out)
    assert REQUIRED <= set(summary)
    assert summary["status"] == "ok"
    assert summary["n_particles"] == res.state.n and summary["n_steps"] > 0
    assert summary["method"] == method and summary["dim"] == 2
    assert len(snaps) == get_scene("bar").setup(2, summary["dp"], True).n_snapshots + 1
    last = load_snapshot(snaps[-1])
    assert last["t"] == pytest.approx(2e-6)
    np.testing.assert_allclose(last["x"], res.state.x)
    assert last["units"]["x"] == "m" and last["units"]["p"] == "Pa"
    assert ("F" in last) == (method == "tlsph")
    for key in ("x", "v", "m", "rho", "p", "S", "S_zz", "sigma_vm", "X", "V0"):
        assert key in last
    assert np.array_equal(last["id"], np.arange(res.state.n))           # particle ids line up with other codes
    prov = summary["provenance"]
    assert {"refsph", "git_commit", "python", "numpy", "scipy", "platform", "threads", "command"} <= set(prov)
    assert prov["numpy"] == np.__version__ and prov["threads"] == summary["threads"]


def test_snapshots_hold_numbers_only_and_old_ones_still_read(tmp_path, monkeypatch):
    """Issue 23: every array of a snapshot is a plain number array (C and C++ npz readers read no unicode arrays);
    the units are in snapshots/units.json, written once per run and listed among refsph's run files; a snapshot of
    an earlier refsph, with its units as a 0-d JSON text inside and no units.json, still reads (load_snapshot,
    state_from_snapshot, compare); a restart does not need the units."""
    import refsph.io
    from refsph.crosscheck.compare import compare
    from refsph.io import UNITS_FILE, run_files, state_from_snapshot
    written = []
    real = refsph.io.write_json
    monkeypatch.setattr(refsph.io, "write_json", lambda path, data: (written.append(path.name), real(path, data)))
    out = tmp_path / "run"
    run("pressing", "tlsph", quick=True, t_end=0.2e-6, out=out, progress=False)     # F, plasticity, a tool (body)
    _, snaps = load_run(out)
    units_file = out / "snapshots" / UNITS_FILE
    assert written.count(UNITS_FILE) == 1 and units_file in run_files(out)
    units = json.loads(units_file.read_text())
    for p in snaps:
        with np.load(p, allow_pickle=False) as z:
            assert "units" not in z.files and all(z[k].dtype.kind in "fi" for k in z.files), p.name
            assert set(z.files) == set(units)
    last = load_snapshot(snaps[-1])
    assert last["units"] == units and units["p"] == "Pa" and units["T"] == "K" and units["id"].startswith("1")
    with np.load(snaps[-1]) as z:                                     # the same snapshot as an earlier refsph wrote it
        old = {k: z[k] for k in z.files}
    old_dir = tmp_path / "old"
    old_dir.mkdir()
    np.savez(old_dir / "snap_00000.npz", units=json.dumps(units), **old)
    back = load_snapshot(old_dir / "snap_00000.npz")
    assert back["units"] == units and back["t"] == last["t"] and np.array_equal(back["S"], last["S"])
    assert np.array_equal(state_from_snapshot(old_dir / "snap_00000.npz").x, last["x"])
    np.savez(snaps[-1], units=json.dumps(units), **old)                 # compare reads an old snapshot beside new ones
    assert all(r.passed for r in compare(out, out))
    units_file.write_text("{broken")
    with pytest.raises(ValueError, match="units.json"):
        load_snapshot(snaps[0])
    with np.load(snaps[0]) as z:                                        # a restart reads no units
        assert np.array_equal(state_from_snapshot(snaps[0]).x, z["x"])


def test_summary_is_written_at_every_snapshot(tmp_path, monkeypatch):
    """A run that is killed keeps a summary.json (status 'running') up to its last snapshot."""
    import refsph.simulate as sim
    seen = []
    real = sim.write_json

    def spy(path, data):
        seen.append((data["status"], data["n_steps"], len(data["snapshots"])))
        real(path, data)

    monkeypatch.setattr(sim, "write_json", spy)
    res = run("bar", "tlsph", quick=True, t_end=2e-6, out=tmp_path, progress=False)
    n_snap = res.setup.n_snapshots
    running = [x for x in seen if x[0] == "running"]
    assert len(running) == n_snap - 1                       # at every snapshot but the first and the last
    assert [x[2] for x in running] == list(range(2, n_snap + 1))
    assert all(a[1] < b[1] for a, b in zip(running, running[1:]))
    assert seen[-1][0] == "ok" and json.loads((tmp_path / "summary.json").read_text())["status"] == "ok"


def test_blow_up_stops_at_the_inverted_particle_and_keeps_last_good(tmp_path):
    out = tmp_path / "bad"
    setup = get_scene("bar").setup(2, get_scene("bar").default_dp(2, True), True)
    setup.t_end = 2e-5                           # a fixed dt 5 x above the CFL limit blows TLSPH up
    setup.numerics = dataclasses.replace(setup.numerics, ref_update_strain=None)   # (no reference update either:
    #                                            the end of the step refuses the first J = det F <= 0 itself)
    with pytest.raises(SimulationError, match=r"step \d+ .* failed: inverted particle: J = det F = -.* at particle"):
        simulate(setup, "tlsph", scene=get_scene("bar"), out=out, dt=8e-8, progress=False)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "error" and "inverted particle" in summary["error"]
    good = load_snapshot(out / "snapshots" / "last_good.npz")
    assert np.isfinite(good["x"]).all() and np.isfinite(good["v"]).all() and np.all(good["rho"] > 0)


def test_nan_stops_and_keeps_last_good(tmp_path):
    """A non-finite field (here put into particle 3's velocity after the 5th step) stops the run with status 'nan'
    and the field, particle and step named (a TLSPH blow-up stops earlier, at its first inverted particle)."""
    from refsph.simulate import make_solver

    class NaNAfter:
        def __init__(self, inner, n):
            self.inner, self.n, self.steps = inner, n, 0

        def after_step(self, state):
            state, self.steps = self.inner.after_step(state), self.steps + 1
            if self.steps == self.n:
                state.v[3, 0] = np.nan
            return state

        def __getattr__(self, name):                               # everything else: the wrapped solver's
            return getattr(self.inner, name)

    out = tmp_path / "bad"
    setup = get_scene("bar").setup(2, get_scene("bar").default_dp(2, True), True)
    setup.t_end = 2e-6
    with pytest.raises(SimulationError, match=r"non-finite v at particle 3 in step 5 "):
        simulate(setup, solver=NaNAfter(make_solver("esph", setup), 5), scene=get_scene("bar"), out=out,
                 progress=False)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "nan" and "step" in summary["error"]
    good = load_snapshot(out / "snapshots" / "last_good.npz")
    assert np.isfinite(good["x"]).all() and np.isfinite(good["v"]).all()


@pytest.mark.parametrize("kwargs, word", [
    (dict(dp=-1e-3), "dp"), (dict(dp=0.0), "dp"), (dict(t_end=-1.0), "t_end"), (dict(dt=0.0), "dt"),
    (dict(dim=4), "dim"), (dict(numerics={"h_over_dp": 0.8}), "h"), (dict(numerics={"bogus": 1}), "bogus"),
])
def test_bad_input_names_the_parameter(kwargs, word):
    with pytest.raises(ValueError, match=word):
        run("bar", "esph", quick=True, progress=False, **kwargs)


def test_unknown_scene_and_method():
    with pytest.raises(ValueError, match="unknown scene 'nope'"):
        run("nope", "esph")
    with pytest.raises(ValueError, match="unknown method 'fem'"):
        run("bar", "fem")


@pytest.mark.parametrize("d, missing", [({"rho0": 1.0, "E": 1.0}, "nu"), ({"E": 1.0, "nu": 0.3}, "rho0"),
                                        ({"rho0": 1.0, "G": 1.0}, "K")])
def test_missing_material_constant(d, missing):
    with pytest.raises(ValueError, match=missing):
        ElasticMaterial.from_dict(d)


def test_material_constants_have_no_defaults():
    with pytest.raises(TypeError):
        ElasticMaterial(rho0=7830.0, E=207e9)  # nu missing
    with pytest.raises(ValueError, match="nu"):
        ElasticMaterial(rho0=7830.0, E=207e9, nu=0.5)
    m = ElasticMaterial.from_shear_bulk(7830.0, 82.9e9, 169.1e9)
    assert m.G == pytest.approx(82.9e9) and m.K == pytest.approx(169.1e9)


def test_cli_list_and_run(tmp_path, capsys):
    assert main(["list"]) == 0
    assert "bar" in capsys.readouterr().out
    out = tmp_path / "cli"
    assert main(["run", "bar", "--method", "tlsph", "--quick", "--t-end", "1e-6", "--out", str(out),
                 "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "particles" in text and (out / "summary.json").exists()
    assert main(["run", "nope"]) == 2
    assert main(["run", "bar", "--dp", "-1", "--out", str(tmp_path / "x")]) == 2
    assert "dp" in capsys.readouterr().err
    # a whole-number numerical parameter from --set: threads; --out of the TLSPH run refused for ESPH (issue 23)
    # unless --overwrite
    args = ["run", "bar", "--method", "esph", "--quick", "--t-end", "1e-6", "--out", str(out), "--quiet", "--set",
            "threads=1"]
    assert main(args) == 2 and "--overwrite" in capsys.readouterr().err
    assert json.loads((out / "summary.json").read_text())["method"] == "tlsph"
    assert main(args + ["--overwrite"]) == 0
    assert json.loads((out / "summary.json").read_text())["threads"] == 1
    assert main(["run", "bar", "--quick", "--set", "threads=1.5", "--out", str(tmp_path / "y")]) == 2
    assert "whole number" in capsys.readouterr().err


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_threads_change_speed_not_numbers(tmp_path, monkeypatch, method):
    """A short cut with small pair blocks (many per evaluation) on 1 and on 2 threads: the same bits."""
    import refsph.neighbours
    monkeypatch.setattr(refsph.neighbours, "PAIR_BLOCK", 2000)
    runs = [run("cutting", method, dp=0.1e-3, t_end=0.5e-6, out=tmp_path / f"t{k}", progress=False,
                numerics={"threads": k}) for k in (1, 2)]
    assert runs[0].summary["n_steps"] == runs[1].summary["n_steps"] > 10
    a, b = (load_snapshot(load_run(tmp_path / f"t{k}")[1][-1]) for k in (1, 2))
    for key in ("x", "v", "S", "eps_p", "T"):
        assert np.array_equal(a[key], b[key]), key
    assert np.any(a["eps_p"] > 0)                            # the tool has cut into the workpiece


def test_bad_thread_count():
    with pytest.raises(ValueError, match="threads"):
        run("bar", "esph", quick=True, progress=False, numerics={"threads": -1})


def test_a_run_stops_when_a_particle_passes_the_setups_temperature_limit(tmp_path):
    """Setup.T_limit: the run stops at the first step with a particle hotter than it (status 'blow-up', the
    particle named, the last good state kept), instead of running on with a blown-up particle."""
    from refsph.scenes.base import Numerics, Setup
    from refsph.state import make_state
    dp = 1e-4
    g = np.arange(6) * dp
    x = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    mat = ElasticMaterial(rho0=7800.0, E=2.0e11, nu=0.3)
    state = make_state(x, [0.0, 0.0], mat.rho0, dp * dp, T0=300.0)
    state.T[7] = 900.0
    setup = Setup(state=state, material=mat, dp=dp, t_end=20 * dp / mat.c_longitudinal, n_snapshots=1,
                  numerics=Numerics(threads=1), T_limit=800.0)
    with pytest.raises(SimulationError, match="particle 7 at 900 K after step 1 .*T_limit = 800 K"):
        simulate(setup, "tlsph", progress=False, out=tmp_path / "run")
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["status"] == "blow-up" and summary["n_steps"] == 1
    assert (tmp_path / "run" / "snapshots" / "last_good.npz").exists()
    setup.T_limit = None
    assert simulate(setup, "tlsph", progress=False).summary["status"] == "ok"
