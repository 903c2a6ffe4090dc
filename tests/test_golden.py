"""refsph as the oracle: the committed golden cases regenerate byte for byte, refsph compare passes what it should
and fails (naming the quantity) what it should not, the public rates function, and the half-pair convention."""
import filecmp
import shutil
from pathlib import Path

import numpy as np
import pytest

from refsph.cli import main
from refsph.compare import compare
from refsph.golden import savez_fixed, write_golden_cases
from refsph.neighbours import PairBlocks, check_half_pairs, find_pairs
from refsph.oracle import rates
from refsph.scenes import get_scene
from refsph.simulate import run

ROOT = Path(__file__).resolve().parent.parent
GOLDEN = ROOT / "golden"


def test_golden_cases_regenerate_byte_for_byte(tmp_path):
    write_golden_cases(tmp_path / "g")
    cmp = filecmp.dircmp(GOLDEN, tmp_path / "g")
    stack, different = [cmp], []
    while stack:
        c = stack.pop()
        different += [f"{c.left}/{f}" for f in c.diff_files + c.left_only + c.right_only]
        stack += c.subdirs.values()
    assert not different, f"the package drifted from the committed golden cases: {different[:5]}"


def test_compare_golden_cases(tmp_path, capsys):
    test = tmp_path / "t"
    shutil.copytree(GOLDEN, test)
    assert main(["compare", str(GOLDEN), str(test)]) == 0
    with np.load(test / "esph_rates" / "output.npz") as z:
        out = {k: z[k] for k in z.files}
    out["v_dot"] = out["v_dot"] * (1 + 1e-3)                       # a backend 0.1 % off in the acceleration
    savez_fixed(test / "esph_rates" / "output.npz", **out)
    capsys.readouterr()
    assert main(["compare", str(GOLDEN), str(test)]) == 1
    bad = [line for line in capsys.readouterr().out.splitlines() if line.endswith("NO")]
    assert len(bad) == 1 and bad[0].startswith("esph_rates/v_dot")


def test_compare_runs_threads_and_perturbation(tmp_path):
    """A run against itself on another thread count passes; a snapshot field perturbed by 1e-3 fails, named."""
    for k in (1, 2):
        run("bar", "tlsph", quick=True, t_end=2e-6, progress=False, out=tmp_path / f"t{k}", numerics={"threads": k})
    assert all(r.passed for r in compare(tmp_path / "t1", tmp_path / "t2"))
    snap = sorted((tmp_path / "t2" / "snapshots").glob("snap_*.npz"))[-1]
    with np.load(snap) as z:
        d = {k: z[k] for k in z.files}
    d["S"] = d["S"] * (1 + 1e-3)
    np.savez(snap, **d)
    failed = [r.quantity for r in compare(tmp_path / "t1", tmp_path / "t2") if not r.passed]
    assert failed and all(q.endswith(" S") for q in failed)


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_rates_of_a_snapshot_are_the_run_s(tmp_path, method):
    """rates() of a run's first snapshot gives the rates the run used: one step with them reproduces the run's
    first step; F, P, J for TLSPH, half pairs I < J."""
    res = run("pressing", method, quick=True, progress=False, t_end=1e-9, out=tmp_path)
    snap = sorted((tmp_path / "snapshots").glob("snap_*.npz"))[0]
    out = rates(snap, "pressing", method, quick=True)
    n = res.state.n
    assert out["v_dot"].shape == (n, 2) and np.all(out["I"] < out["J"]) and out["n_pairs"] == len(out["I"])
    if method == "tlsph":
        assert out["F"].shape[1:] == (2, 2) and "P" in out and "J" in out
    assert np.all(np.isfinite(out["S_returned"])) and np.any(out["d_eps_p"] >= 0)


def test_half_pair_convention_is_enforced():
    x = np.random.default_rng(0).uniform(0, 1e-3, (50, 2))
    I, J = find_pairs(x, 3e-4)
    check_half_pairs(I, J, 50)
    with pytest.raises(ValueError, match="full .*twice"):
        PairBlocks(np.concatenate([I, J]), np.concatenate([J, I]), 50)
    with pytest.raises(ValueError, match="self-pair"):
        check_half_pairs(np.array([0, 3]), np.array([1, 3]), 50)
    with pytest.raises(ValueError, match="twice"):
        check_half_pairs(np.array([0, 0]), np.array([1, 1]), 50)


def test_rates_input_errors():
    with pytest.raises(TypeError, match="Setup"):
        rates(get_scene("bar").setup(quick=True).state, 42, "esph")


def test_export_vtk(tmp_path):
    """refsph export RUN_DIR --vtk: one VTU per snapshot with every field, and a .pvd with the times."""
    meshio = pytest.importorskip("meshio")
    run("bar", "tlsph", quick=True, t_end=1e-6, progress=False, out=tmp_path)
    assert main(["export", str(tmp_path), "--vtk"]) == 0
    pvd = (tmp_path / "vtk" / "run.pvd").read_text()
    assert pvd.count("<DataSet") == len(list((tmp_path / "snapshots").glob("snap_*.npz")))
    m = meshio.read(tmp_path / "vtk" / "snap_00010.vtu")
    assert m.points.shape[1] == 3 and {"x", "v", "S", "F", "id", "p"} <= set(m.point_data)
    assert m.point_data["S"].shape[1] == 9
