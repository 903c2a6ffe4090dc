"""refsph as the oracle: the committed golden cases regenerate byte for byte (on any CPU: the generator runs with
NumPy's, OpenBLAS's and glibc's CPU dispatch pinned, refsph.crosscheck.golden), refsph compare passes what it should
and fails (naming the quantity) what it should not, the public rates function, and the half-pair convention."""
import filecmp
import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from refsph.cli import main
from refsph.crosscheck.compare import SCATTER_FILE, compare, format_table
from refsph.crosscheck.golden import (METRIC_RUNS, SCATTER_K, SCATTER_RULE, case_names, generated_with, metric_rows,
                                     written_names,
                                      pinned_environment, savez_fixed, spread, write_golden_cases)
from refsph.neighbours import PairBlocks, check_half_pairs, find_pairs
from refsph.crosscheck.oracle import rates
from refsph.scenes import get_scene
from refsph.simulate import run

ROOT = Path(__file__).resolve().parent.parent
GOLDEN = ROOT / "golden"
FAST = [n for n in case_names() if not n.startswith("metrics_")]     # metrics_*: whole runs, the scene tests' own


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory):
    """Every case but the metrics_* ones, written again the way `refsph oracle` writes them (a pinned child)."""
    out = tmp_path_factory.mktemp("golden") / "g"
    assert write_golden_cases(out, FAST) == FAST
    return out


def _different(a: Path, b: Path) -> list[str]:
    """The files that differ between golden folders a and b, or are in one only (a stored scatter.json, which the
    generator does not write, aside)."""
    cmp = filecmp.dircmp(a, b)
    stack, different = [cmp], []
    while stack:
        c = stack.pop()
        different += [f"{c.left}/{f}" for f in c.diff_files + c.left_only + c.right_only if f != SCATTER_FILE]
        stack += c.subdirs.values()
    return different


def test_golden_cases_regenerate_byte_for_byte(regenerated):
    """The same bytes on any CPU of the architecture (NumPy's SIMD dispatch, OpenBLAS's kernels and glibc's FMA
    variants are pinned to the baseline in the generator's child process: without that, the cases written on an
    AVX-512 machine differ in the last bits on an AVX2 one). Other software (NumPy, SciPy, the C library) may
    round differently: then the bytes are not compared (the tolerance test below still holds them)."""
    committed = json.loads((GOLDEN / "index.json").read_text())
    if committed["generated_with"] != generated_with():
        pytest.skip(f"the golden cases were written with {committed['generated_with']}, this is {generated_with()}:"
                    " byte identity holds only for the same software (regenerate them: refsph oracle golden/)")
    different = [d for name in FAST for d in _different(GOLDEN / name, regenerated / name)]
    assert filecmp.cmp(GOLDEN / "index.json", regenerated / "index.json", shallow=False)
    assert not different, f"the package drifted from the committed golden cases: {different[:5]}"


def test_golden_cases_regenerate_within_tolerance(regenerated):
    """On any software, every regenerated output within its case's tolerance (and the inputs the same)."""
    rows = compare(GOLDEN, regenerated, only=FAST)
    assert all(r.passed for r in rows), format_table([r for r in rows if not r.passed])
    for name in FAST:
        with np.load(GOLDEN / name / "input.npz") as a, np.load(regenerated / name / "input.npz") as b:
            assert a.files == b.files
            for k in a.files:
                assert np.allclose(a[k], b[k], rtol=1e-14, atol=0), (name, k)


@pytest.mark.slow
def test_metric_cases_regenerate_byte_for_byte(tmp_path):
    """The metrics_* cases (whole runs, minutes) written again give the same bytes."""
    committed = json.loads((GOLDEN / "index.json").read_text())
    if committed["generated_with"] != generated_with():
        pytest.skip("other software than the committed cases' (see the fast test)")
    write_golden_cases(tmp_path / "g", ["metrics_*"])
    assert not [d for name in case_names(["metrics_*"]) for d in _different(GOLDEN / name, tmp_path / "g" / name)]


def test_generator_runs_without_cpu_dispatch():
    """The child the cases are computed in sees none of NumPy's dispatched CPU features (the mechanism itself);
    naming features this CPU lacks is accepted (NumPy refuses only baseline ones)."""
    code = ("from numpy._core._multiarray_umath import __cpu_dispatch__ as d, __cpu_features__ as f; "
            "print(sum(bool(f[k]) for k in d), len(d))")
    out = subprocess.run([sys.executable, "-W", "error", "-c", code], env=pinned_environment(), check=True,
                         capture_output=True, text=True)
    on, n = map(int, out.stdout.split())
    assert n > 0 and on == 0


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
    lines = capsys.readouterr().out.splitlines()
    bad = [k for k, line in enumerate(lines) if line.endswith("NO")]
    assert len(bad) == 1 and lines[bad[0]].startswith("esph_rates/v_dot")
    worst = np.unravel_index(np.argmax(np.abs(out["v_dot"])), out["v_dot"].shape)      # where 0.1 % is most
    assert lines[bad[0] + 1].startswith(f"    worst at particle {worst[0]} component [{worst[1]}]: REF ")


def _golden_copy(tmp_path, cases) -> Path:
    test = tmp_path / "t"
    for case in cases:
        shutil.copytree(GOLDEN / case, test / case)
    return test


def _outputs(path: Path) -> dict:
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


def test_compare_labels_what_a_number_would_hide(tmp_path):
    """Golden cases: a case TEST lacks, an array it lacks, one of another shape, a float32 backend and a nan are
    each labelled (missing, shape mismatch, dtype with the digits float32 keeps, not finite) and counted in the
    last line; the cases TEST lacks are said up front."""
    test = _golden_copy(tmp_path, ["kernel_cubic_2d", "esph_rates", "esph_pair_terms"])
    out = _outputs(test / "kernel_cubic_2d" / "output.npz")
    np.savez(test / "kernel_cubic_2d" / "output.npz", **{k: v.astype(np.float32) for k, v in out.items()})
    out = _outputs(test / "esph_rates" / "output.npz")
    del out["l"]
    out["v_dot"] = out["v_dot"][:, :1]
    out["rho_dot"][7] = np.nan
    np.savez(test / "esph_rates" / "output.npz", **out)
    rows = compare(GOLDEN, test, only=["kernel_cubic_2d", "esph_rates*", "esph_pair_terms"])
    by = {r.quantity: r for r in rows}
    assert all(by[f"kernel_cubic_2d/{k}"].labels == ("dtype",) and not by[f"kernel_cubic_2d/{k}"].passed
               for k in ("W", "dW_dr", "grad_W"))
    assert "float32 keeps 6 digits" in by["kernel_cubic_2d/W"].note
    assert by["esph_rates/l"].labels == ("missing",) and "has no array l" in by["esph_rates/l"].note
    assert by["esph_rates/v_dot"].labels == ("shape mismatch",) and "(120, 1)" in by["esph_rates/v_dot"].note
    assert by["esph_rates/rho_dot"].labels == ("not finite",) and by["esph_rates/rho_dot"].where == "particle 7"
    assert all(by[f"{c}/v_dot"].labels == ("missing",) for c in ("esph_rates_no_viscosity", "esph_rates_stress_only"))
    assert all(r.passed for r in rows if r.quantity.startswith("esph_pair_terms/"))
    table = format_table(rows)
    assert table.splitlines()[0].startswith("NOTE: TEST has no output.npz for 3 of the 6 cases")
    assert table.count("TEST has no esph_rates_stress_only/output.npz") == 1          # said once, not per array
    assert table.splitlines()[-1].endswith("(16 missing, 1 shape mismatch, 3 dtype, 1 not finite)")


def test_compare_runs_localises_and_labels(tmp_path):
    """Run folders: different methods are said first; a TEST snapshot missing is interpolated from its neighbours
    and labelled so; a particle TEST lacks is missing; a float32 field is labelled dtype; a failing field names the
    particle id, component, time and both values; a snapshot of an earlier refsph, with its units as a JSON text
    inside, is read (the text skipped)."""
    kw = dict(quick=True, t_end=2e-6, progress=False, numerics={"threads": 1})
    run("bar", "tlsph", out=tmp_path / "ref", **kw)
    run("bar", "esph", out=tmp_path / "esph", **kw)
    notes = compare(tmp_path / "ref", tmp_path / "esph").notes
    assert "different method: REF tlsph, TEST esph" in notes
    test = tmp_path / "t"
    shutil.copytree(tmp_path / "ref", test)
    snaps = sorted((test / "snapshots").glob("snap_*.npz"))
    snaps[3].unlink()                                           # TEST has no snapshot at REF's 4th time
    z = _outputs(snaps[5])
    z["units"] = json.dumps({"x": "m", "v": "m/s"})
    z["S"] = z["S"].astype(np.float32)
    z["v"][11, 1] += 1.0
    np.savez(snaps[5], **z)
    z = _outputs(snaps[7])
    np.savez(snaps[7], **{k: (v[1:] if np.ndim(v) and len(v) == len(z["x"]) else v) for k, v in z.items()})
    rows = compare(tmp_path / "ref", test)
    assert rows.notes == []

    def at(snap):
        return {r.quantity.split()[-1]: r for r in rows if r.quantity.startswith(snap.stem)}
    assert all("interpolated" in r.labels for r in at(snaps[3]).values())
    assert "interpolated between its snapshots" in at(snaps[3])["x"].note
    s5 = at(snaps[5])
    assert s5["S"].labels == ("dtype",) and s5["x"].passed
    assert not s5["v"].passed and s5["v"].where == "particle id 11 component [1]"
    assert s5["v"].time == float(_outputs(tmp_path / "ref" / "snapshots" / snaps[5].name)["t"])
    assert s5["v"].test_value - s5["v"].ref_value == pytest.approx(1.0)
    assert all(r.labels == ("missing",) and "lacks 1 of REF's particles (ids 0)" in r.note
               for r in at(snaps[7]).values())
    assert f"worst at particle id 11 component [1], t = {s5['v'].time:.6g} s" in format_table(rows)


@pytest.mark.parametrize("case, array, change, passes", [
    ("conduction", "T_dot", lambda a: a * (1 + 1e-12), True),
    ("conduction", "lap_T", lambda a: a * (1 + 1e-6), False),
    ("surface_notch", "surface_sph", lambda a: a, True),
    ("surface_notch", "surface_alpha", lambda a: np.where(np.arange(len(a)) == np.argmax(a), 0, a), False),
    ("pinball_friction", "friction_power_a_rigid", lambda a: a * (1 + 1e-6), False),
    ("step_tlsph_thermal_cutting", "T", lambda a: a + 1e-11 * np.max(a), True),
    ("run_thermal_cutting_tlsph", "S", lambda a: a + 1e-5 * np.max(np.abs(a)), False),
    ("run_taylor_tlsph_leapfrog", "v", lambda a: a * (1 + 1e-8), True),
])
def test_compare_new_cases(tmp_path, case, array, change, passes):
    """The new cases through `refsph compare`: within the tolerance passes, beyond it fails on that array only
    (the detectors' masks exactly: one particle moved off the surface fails)."""
    test = tmp_path / "t"
    shutil.copytree(GOLDEN / case, test / case)
    with np.load(test / case / "output.npz") as z:
        out = {k: z[k] for k in z.files}
    out[array] = change(out[array])
    savez_fixed(test / case / "output.npz", **out)
    rows = compare(GOLDEN, test, only=[case])
    assert [r.quantity for r in rows if not r.passed] == ([] if passes else [f"{case}/{array}"])


def _golden_metrics(name: str) -> dict:
    """A metrics_* case's values back as a run's summary metrics (the strain line as (x, eps_p) rows)."""
    with np.load(GOLDEN / name / "output.npz") as z:
        met = {k: float(z[k]) if z[k].ndim == 0 else z[k] for k in z.files}
    if "plastic_strain_line_eps_p" in met:
        e = met.pop("plastic_strain_line_eps_p")
        met["plastic_strain_line"] = np.stack([np.arange(len(e)), e], axis=1)
    return met


def test_metric_cases_and_their_measures():
    """Every scene test's regression case exists with a tolerance per metric; the measures do what case.json says:
    TLSPH's strain line as a relative L2 difference (4 % passes, 6 % fails), ESPH's pointwise
    (|d| <= 1e-4 |ref| + 1e-6: 0.9e-6 added everywhere passes, 2e-6 fails), scalars relative."""
    for key in METRIC_RUNS:
        for m in ("esph", "tlsph"):
            rows = metric_rows(GOLDEN / f"metrics_{key}_{m}", _golden_metrics(f"metrics_{key}_{m}"))
            assert rows and all(r.passed and r.error == 0 for r in rows)
    for m, scale, passes in (("tlsph", 1.04, True), ("tlsph", 1.06, False)):
        met = _golden_metrics(f"metrics_pressing_quick_{m}")
        met["plastic_strain_line"][:, 1] *= scale
        assert all(r.passed for r in metric_rows(GOLDEN / f"metrics_pressing_quick_{m}", met)) == passes
    for add, passes in ((0.9e-6, True), (2e-6, False)):
        met = _golden_metrics("metrics_pressing_quick_esph")
        met["plastic_strain_line"][:, 1] += add
        rows = metric_rows(GOLDEN / "metrics_pressing_quick_esph", met)
        assert all(r.passed for r in rows) == passes
    met = _golden_metrics("metrics_cutting_coarse_tlsph")
    met["max_plastic_strain"] *= 1.051                           # local maxima at 5 % (the forces: the stored scatter)
    assert [r.quantity for r in metric_rows(GOLDEN / "metrics_cutting_coarse_tlsph", met) if not r.passed] == [
        "metrics_cutting_coarse_tlsph/max_plastic_strain"]


def test_stored_scatter_sets_the_tolerance_and_says_so(tmp_path):
    """The cutting forces scatter by nature: metrics_cutting_coarse_*/scatter.json (benchmarks/metric_scatter.py)
    holds their spread over runs with the particles perturbed and a tolerance by its rule (k x the largest relative
    deviation from the case's value); the metrics check and refsph compare hold them to it (never tighter than
    case.json's own) and say so; a stale file is not used and says so; the other metrics keep case.json's."""
    for m in ("esph", "tlsph"):
        name = f"metrics_cutting_coarse_{m}"
        sc = json.loads((GOLDEN / name / SCATTER_FILE).read_text())
        own = json.loads((GOLDEN / name / "case.json").read_text())["tolerance"]
        assert sc["rule"] == SCATTER_RULE and sc["k"] == SCATTER_K and len(sc["seeds"]) >= 3
        met = _golden_metrics(name)
        for k in ("cutting_force_mean_N_per_m", "thrust_force_mean_N_per_m"):
            s = sc["metrics"][k]
            assert s["reference"] == met[k] and len(s["values"]) == len(sc["seeds"])
            assert sc["tolerance"][k] == pytest.approx(SCATTER_K * max(abs(v - met[k]) for v in s["values"]) / met[k])
        rows = metric_rows(GOLDEN / name, met)
        assert len(rows) == 4 and all(r.passed for r in rows)
        for r in rows:
            k = r.quantity.split("/")[1]
            stored = sc["tolerance"].get(k)
            assert r.tolerance == (own[k] if stored is None else max(stored, own[k]))
            assert r.tolerance_from == ("" if stored is None else f"the stored scatter ({name}/{SCATTER_FILE})"
                                        if stored > own[k] else f"case.json, larger than the stored scatter's "
                                        f"{stored:.1e} ({name}/{SCATTER_FILE})")
        k = "cutting_force_mean_N_per_m"
        said = "the stored scatter" if sc["tolerance"][k] > own[k] else "case.json"
        assert f"tolerance from {said}" in format_table(rows)
        tol = next(r.tolerance for r in rows if r.quantity.endswith(k))
        for factor, passes in ((0.9, True), (1.1, False)):
            off = dict(met, **{k: met[k] * (1 + factor * tol)})
            assert [r.passed for r in metric_rows(GOLDEN / name, off) if r.quantity.endswith(k)] == [passes]
    stale = tmp_path / name
    shutil.copytree(GOLDEN / name, stale)
    sc["metrics"][k]["reference"] *= 1.01                       # measured around another value than the case's
    (stale / SCATTER_FILE).write_text(json.dumps(sc))
    row = next(r for r in metric_rows(stale, met) if r.quantity.endswith(k))
    assert row.tolerance == own[k] and not row.tolerance_from and "is stale" in row.note


def test_spread_and_its_rule(tmp_path):
    """benchmarks/metric_scatter.py's statistics: mean, sample std, largest deviation from the mean and from the
    reference, the tolerance k x the largest relative deviation; runs that measured nothing (null, nan) left out;
    no tolerance around 0 or from fewer than two runs. refsph oracle keeps a case's stored scatter.json."""
    s = spread([1.0, 2.0, 4.0], 2.0)
    assert s["mean"] == pytest.approx(7 / 3) and s["std"] == pytest.approx(np.std([1, 2, 4], ddof=1))
    assert s["max_deviation"] == pytest.approx(5 / 3) and s["max_deviation_from_reference"] == 2.0
    assert s["relative_max_deviation"] == 1.0 and s["tolerance"] == SCATTER_K
    s = spread([None, float("nan"), 0.4], 0.5)
    assert s["n"] == 1 and s["runs"] == 3 and s["tolerance"] is None and s["mean"] is None
    assert spread([0, 0, 0], 0)["tolerance"] is None and spread([0, 0, 0], 0)["max_deviation"] == 0
    write_golden_cases(tmp_path, ["kernel_cubic_2d"])
    (tmp_path / "kernel_cubic_2d" / SCATTER_FILE).write_text("{}\n")
    write_golden_cases(tmp_path, ["kernel_cubic_2d"])                   # written again: the stored scatter stays
    assert (tmp_path / "kernel_cubic_2d" / SCATTER_FILE).read_text() == "{}\n"
    assert sorted(p.name for p in (tmp_path / "kernel_cubic_2d").iterdir()) == ["case.json", "input.npz",
                                                                               "output.npz", SCATTER_FILE]


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
    first step (the accelerations and stress rates of the run's first rates evaluation, at t = 0, to round-off);
    F, P, J_det = det F for TLSPH (not the pair index J, issue 23), half pairs I < J."""
    import refsph.solvers as solvers
    cls = solvers.ESPHSolver if method == "esph" else solvers.TLSPHSolver
    first, original = [], cls.rates

    def recording(self, state, dt=None, *args, **kwargs):
        r = original(self, state, dt, *args, **kwargs)
        if not first:
            first.append((state.t, dt, r.v.copy(), r.S.copy()))
        return r
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(cls, "rates", recording)
        res = run("pressing", method, quick=True, progress=False, t_end=1e-9, out=tmp_path)
    snap = sorted((tmp_path / "snapshots").glob("snap_*.npz"))[0]
    t0, dt0, v_dot0, S_dot0 = first[0]
    assert t0 == 0.0
    out = rates(snap, "pressing", method, quick=True, dt=dt0)
    np.testing.assert_allclose(out["v_dot"], v_dot0, rtol=1e-12, atol=1e-12 * np.max(np.abs(v_dot0)))
    np.testing.assert_allclose(out["S_dot"], S_dot0, rtol=1e-12, atol=1e-12 * np.max(np.abs(S_dot0)))
    n = res.state.n
    assert out["v_dot"].shape == (n, 2) and np.all(out["I"] < out["J"]) and out["n_pairs"] == len(out["I"])
    if method == "tlsph":
        from refsph.tensor import det
        assert out["F"].shape[1:] == (2, 2) and "P" in out
        np.testing.assert_allclose(out["J_det"], det(out["F"]), rtol=1e-12)
    assert out["I"].dtype.kind == "i" and out["J"].dtype.kind == "i" and len(out["J"]) == out["n_pairs"]
    assert np.all(np.isfinite(out["S_returned"])) and np.all(out["d_eps_p"] >= 0)


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
    from refsph.io import load_snapshot                          # 2D: the plane-strain zz components (issue 23)
    z = load_snapshot(tmp_path / "snapshots" / "snap_00010.npz")
    assert np.any(z["S_zz"] != 0)
    np.testing.assert_array_equal(m.point_data["S"][:, 8], z["S_zz"])
    np.testing.assert_allclose(np.linalg.det(m.point_data["F"].reshape(-1, 3, 3)), np.linalg.det(z["F"]), rtol=1e-12)


def test_oracle_refuses_a_folder_it_did_not_write_and_names_bad_patterns(tmp_path, capsys):
    """refsph oracle empties what it writes into, so it refuses a non-empty folder without a golden index.json
    (nothing there is touched) and says which pattern matches no case, with no traceback."""
    from refsph.cli import main
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep me")
    assert main(["oracle", str(mine), "--only", "pinball"]) == 2
    assert "not a golden-case directory" in capsys.readouterr().err
    assert (mine / "notes.txt").read_text() == "keep me" and len(list(mine.iterdir())) == 1
    assert main(["oracle", str(tmp_path / "new"), "--only", "no_such_case"]) == 2
    err = capsys.readouterr().err
    assert "no golden case matches no_such_case" in err and "Traceback" not in err


def test_oracle_only_names_what_it_writes(tmp_path, capsys):
    """`--only` writes a chosen case's group-mates too (computed together): the count and the names printed are those
    of the folders written (it said "5 golden cases" for nine folders)."""
    from refsph.cli import main
    names = written_names(["kernel_*", "esph_pair_terms"])
    assert set(case_names(["kernel_*", "esph_pair_terms"])) < set(names)
    assert {n for n in names if n.startswith("esph_rates")} and "pinball" not in names
    assert main(["oracle", str(tmp_path / "g"), "--only", "kernel_*", "esph_pair_terms"]) == 0
    assert capsys.readouterr().out.startswith(f"{len(names)} golden cases in")
    assert sorted(p.name for p in (tmp_path / "g").iterdir() if p.is_dir()) == sorted(names)


def test_null_field_tolerance_leaves_the_array_out(tmp_path, capsys):
    """A ``--tolerances`` file's ``"fields": {"W": null}`` means "not compared" for golden cases too (it raised a
    TypeError before): the kernel case's W is left out, its dW_dr still compared, and a wrong W then passes."""
    test = tmp_path / "mine"
    shutil.copytree(GOLDEN / "kernel_cubic_2d", test / "kernel_cubic_2d")
    out = dict(np.load(test / "kernel_cubic_2d" / "output.npz"))
    out["W"] = out["W"] * 2.0
    np.savez(test / "kernel_cubic_2d" / "output.npz", **out)
    tol = tmp_path / "tol.json"
    tol.write_text(json.dumps({"fields": {"W": None}}))
    args = ["compare", str(GOLDEN), str(test), "--only", "kernel_cubic_2d"]
    assert main(args) == 1                                      # W wrong: fails by default
    assert main(args + ["--tolerances", str(tol)]) == 0
    table = capsys.readouterr().out.split("kernel_cubic_2d/W")
    assert len(table) == 2                                      # W in the first table only
