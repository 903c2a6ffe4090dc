"""Nothing a user keeps is lost (issue 23): ``--out`` takes only an empty folder or a run folder of the same scene
and method, ``--overwrite`` removes only the files refsph writes, and a run whose folder vanishes or whose output
cannot be written stops with exit 3 and says which path, instead of recreating the folder and reporting 'ok'."""
import errno
import json
import shutil

import numpy as np
import pytest

from refsph.cli import main
from refsph.io import claim_run_folder, run_files
from refsph.simulate import SimulationError, run

QUICK = ["--quick", "--t-end", "1e-6", "--quiet"]


def _tree(folder):
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_out_refuses_a_folder_that_is_not_this_run_and_keeps_every_file(tmp_path, capsys):
    mine = tmp_path / "mine"
    (mine / "snapshots").mkdir(parents=True)
    np.save(mine / "snapshots" / "precious.npy", np.arange(3))
    (mine / "notes.txt").write_text("keep me")
    before = _tree(mine)
    assert main(["run", "bar", "--method", "tlsph", "--out", str(mine)] + QUICK) == 2
    assert "not a refsph run" in capsys.readouterr().err and _tree(mine) == before
    other = tmp_path / "other"                                   # another scene's run, and a file of the user's
    assert main(["run", "taylor", "--method", "tlsph", "--dim", "2", "--out", str(other)] + QUICK) == 0
    (other / "snapshots" / "precious.npz").write_bytes(b"user data")
    before = _tree(other)
    assert main(["run", "bar", "--method", "tlsph", "--out", str(other)] + QUICK) == 2
    err = capsys.readouterr().err
    assert "a run of 'taylor'" in err and "--overwrite" in err and _tree(other) == before
    assert main(["run", "bar", "--method", "tlsph", "--out", str(other), "--overwrite"] + QUICK) == 0
    assert (other / "snapshots" / "precious.npz").read_bytes() == b"user data"
    assert json.loads((other / "summary.json").read_text())["scene"] == "bar"
    assert not (other / "reaction_forces.csv").exists()          # the taylor run's stale CSV is gone
    summary = json.loads((other / "summary.json").read_text())
    assert sorted(p.name for p in (other / "snapshots").glob("snap_*.npz")) == summary["snapshots"]


def test_the_same_scene_and_method_reruns_in_place_and_keeps_the_users_files(tmp_path):
    out = tmp_path / "r"
    run("bar", "tlsph", quick=True, t_end=1e-6, progress=False, out=out)
    (out / "snapshots" / "mine.npz").write_bytes(b"x")
    (out / "notes.txt").write_text("y")
    res = run("bar", "tlsph", quick=True, t_end=0.5e-6, progress=False, out=out)
    assert (out / "snapshots" / "mine.npz").read_bytes() == b"x" and (out / "notes.txt").read_text() == "y"
    assert sorted(p.name for p in (out / "snapshots").glob("snap_*.npz")) == res.summary["snapshots"]
    assert set(run_files(out)) >= {out / "summary.json", out / "snapshots" / "restart.npz"}
    with pytest.raises(ValueError, match="is a file"):
        claim_run_folder(out / "notes.txt", "bar", "tlsph")


def test_out_naming_a_file_is_refused_for_a_scene_with_two_methods(tmp_path, capsys):
    """Taylor runs ESPH and TLSPH into OUT/esph and OUT/tlsph: where OUT is a file, the run is refused with exit 2
    and a message naming the file, and the file is left as it was (nothing is created beside it)."""
    notes = tmp_path / "notes.txt"
    notes.write_text("keep me")
    assert main(["run", "taylor", "--dim", "2", "--out", str(notes)] + QUICK) == 2
    assert f"{notes} is a file, not a folder" in capsys.readouterr().err
    assert notes.read_text() == "keep me" and [p.name for p in tmp_path.iterdir()] == ["notes.txt"]


def test_a_run_whose_folder_vanishes_stops_and_says_so(tmp_path, capsys):
    out = tmp_path / "gone"
    calls = []

    def remove_midway(state, solver):
        calls.append(1)
        if len(calls) == 20:
            shutil.rmtree(out)
    with pytest.raises(SimulationError, match="vanished"):
        from refsph.scenes import get_scene
        from refsph.simulate import simulate
        setup = get_scene("bar").setup(quick=True)
        setup.t_end = 2e-6
        simulate(setup, "tlsph", scene=get_scene("bar"), out=out, hook=remove_midway, progress=False)
    assert not out.exists()                                     # not recreated by the writers


def test_a_write_failure_is_exit_3_with_the_path(tmp_path, capsys, monkeypatch):
    import refsph.io
    real = refsph.io.np.savez
    count = []

    def full_disk(path, *a, **k):
        count.append(1)
        if len(count) > 3:
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return real(path, *a, **k)
    monkeypatch.setattr(refsph.io.np, "savez", full_disk)
    assert main(["run", "bar", "--method", "tlsph", "--out", str(tmp_path / "full")] + QUICK) == 3
    err = capsys.readouterr().err
    assert "No space left" in err and "full" in err
