"""A table of bad inputs and broken files for every subcommand (issue 23): each ends as a clear message and exit code
2 or 3 (or a valid run, 0), never a traceback, never exit 4 (an internal error), and never a changed file outside
the run's --out."""
import json

import numpy as np
import pytest

from refsph.cli import main

TINY = ["--quick", "--quiet", "--t-end", "1e-7"]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A finished quick run, and broken copies of its files."""
    d = tmp_path_factory.mktemp("fuzz")
    assert main(["run", "bar", "--method", "tlsph", "--out", str(d / "run")] + TINY) == 0
    snaps = sorted((d / "run" / "snapshots").glob("snap_*.npz"))
    (d / "garbage.npz").write_bytes(b"not a zip file at all")
    (d / "trunc.npz").write_bytes(snaps[-1].read_bytes()[:300])
    z = dict(np.load(snaps[0]))
    np.savez(d / "no_v.npz", x=z["x"], m=z["m"])
    twins = z["x"].copy()
    twins[1] = twins[0]
    np.savez(d / "twins.npz", x=twins, v=z["v"], m=z["m"])
    (d / "tol_list.json").write_text("[1, 2]")
    (d / "tol_bad.json").write_text("{not json")
    (d / "tol_neg.json").write_text('{"field": -1}')
    (d / "a_file").write_text("x")
    (d / "foreign").mkdir()
    (d / "foreign" / "thesis.tex").write_text("keep")
    for name, spoil in (("trunc_snap", "snap"), ("trunc_ck", "ck"), ("bad_args", "args"), ("bad_summary", "json")):
        import shutil
        shutil.copytree(d / "run", d / name)
        if spoil == "snap":
            for p in sorted((d / name / "snapshots").glob("snap_*.npz")):
                p.write_bytes(p.read_bytes()[:100])
        elif spoil == "ck":
            for p in (d / name / "snapshots").glob("restart*.npz"):
                p.write_bytes(b"junk")
        elif spoil == "args":
            s = json.loads((d / name / "summary.json").read_text())
            s["run_args"]["dim"] = "two"
            (d / name / "summary.json").write_text(json.dumps(s))
        else:
            (d / name / "summary.json").write_text("{")
    return d


CASES = [
    # run: numbers and parameters
    ["run", "bar", "--dp", "1e-8"], ["run", "bar", "--dp", "-1e-3"], ["run", "bar", "--dp", "abc"],
    ["run", "bar", "--t-end", "-1"], ["run", "bar", "--dt", "0"], ["run", "bar", "--dt", "nan"],
    ["run", "bar", "--dim", "4"], ["run", "nope"], ["run"], ["run", "bar", "--method", "sph"],
    *[["run", "bar", "--set", s] for s in ("hourglass=-1", "gamma=nan", "ref_update_strain=-1", "h_over_dp=nan",
                                          "h_over_dp=100", "beta1=-5", "eps=-1", "beta2=nan", "n_ap=nan",
                                          "threads=1.5", "threads=-2", "kernel=gauss", "nonsense=1", "contact=glue",
                                          "integrator=euler", "courant=0", "courant=5", "penalty_alpha=9",
                                          "corrected=maybe", "beta1", "=1")],
    ["run", "bar", "--option", "foo=1"], ["run", "bar", "--option", "length"], ["run", "bar", "--length", "-1"],
    ["run", "thermal_cutting", "--case", "1.5"], ["run", "thermal_cutting", "--case", "1", "--material", "Unobtainium"],
    ["run", "thermal_cutting", "--case", "19"], ["run", "thermal_cutting", "--jitter", "0.5"],
    ["run", "thermal_cutting", "--dim", "3"], ["run", "thermal_cutting", "--method", "esph"],
    ["run", "cutting", "--method", "both", "--set", "esph_correction=true"],
    ["run", "thermal_cutting", "--set", "contact=penalty", "--method", "esph"],
    # run: files
    ["run", "bar", "--from", "{d}/missing.npz"], ["run", "bar", "--from", "{d}/garbage.npz"],
    ["run", "bar", "--from", "{d}/trunc.npz"], ["run", "bar", "--from", "{d}/no_v.npz"],
    ["run", "bar", "--from", "{d}/twins.npz"],
    ["run", "bar", "--out", "{d}/a_file"], ["run", "bar", "--out", "{d}/foreign"],
    ["run", "taylor", "--dim", "2", "--method", "tlsph", "--out", "{d}/run"],
    # restart
    ["run", "--restart", "{d}/nowhere"], ["run", "--restart", "{d}/run", "--t-end", "1"],
    ["run", "--restart", "{d}/run", "--from", "{d}/twins.npz"], ["run", "bar", "--restart", "{d}/run"],
    ["run", "--restart", "{d}/trunc_ck"], ["run", "--restart", "{d}/trunc_snap"], ["run", "--restart", "{d}/bad_args"],
    ["run", "--restart", "{d}/bad_summary"], ["run", "--restart", "{d}/foreign"],
    # compare, export, oracle
    ["compare", "{d}/nowhere", "{d}/run"], ["compare", "{d}/run", "{d}/nowhere"], ["compare", "{d}/run", "{d}/a_file"],
    ["compare", "{d}/run", "{d}/trunc_snap"], ["compare", "{d}/run", "{d}/bad_summary"],
    ["compare", "{d}/run", "{d}/run", "--tolerances", "{d}/tol_list.json"],
    ["compare", "{d}/run", "{d}/run", "--tolerances", "{d}/tol_bad.json"],
    ["compare", "{d}/run", "{d}/run", "--tolerances", "{d}/tol_neg.json"],
    ["compare", "{d}/run", "{d}/run", "--tolerances", "{d}/missing.json"],
    ["compare", "{d}/run", "{d}/run", "--only", "kernel_*"],
    ["export", "{d}/trunc_snap", "--vtk"], ["export", "{d}/nowhere", "--vtk"], ["export", "{d}/foreign", "--vtk"],
    ["oracle", "/proc/x"], ["oracle", "{d}/foreign"], ["oracle", "{d}/a_file"],
    ["oracle", "{d}/new_golden", "--only", "no_such_case"],
    ["list", "--extra"], ["frobnicate"],
    # scene options of every scene
    *[["run", sc, "--quick", "--option", o] for sc, o in (
        ("spinning_disc", "speed=-1"), ("spinning_disc", "speed=nan"), ("spinning_disc", "turns=0"),
        ("rings", "speed=-0.1"), ("rings", "gap=-3"), ("rings", "gap=abc"),
        ("taylor", "T_melt=100"), ("taylor", "T_melt=-1"), ("taylor", "symmetry=perhaps"),
        ("taylor", "eps_dot_0=0"), ("taylor", "heating=2"), ("taylor", "speed_factor=-1"),
        ("taylor", "layout=hexagonal"), ("pressing", "travel=-1e-4"), ("pressing", "travel=5"),
        ("pressing", "speed_factor=0"), ("pressing", "eps_dot_0=nan"), ("cutting", "feed=0"), ("cutting", "feed=2e-3"),
        ("cutting", "travel=-1"), ("cutting", "travel=10"), ("thermal_cutting", "material=steel"),
        ("thermal_cutting", "vc=0"), ("thermal_cutting", "tu=-1e-4"), ("thermal_cutting", "n_tu=0"),
        ("thermal_cutting", "n_tu=1"), ("thermal_cutting", "travel=100"), ("thermal_cutting", "length=1e-5"),
        ("thermal_cutting", "mass_scale=-1"), ("thermal_cutting", "inertia_ratio=0"),
        ("thermal_cutting", "detector=eye"), ("thermal_cutting", "chip_fraction=2"),
        ("thermal_cutting", "dissipation_heat=sometimes"), ("thermal_cutting", "tool_length=0"),
        ("thermal_cutting", "tool_depth=nan"), ("thermal_cutting", "friction=1.5"), ("thermal_cutting", "case=-1"),
        ("thermal_cutting", "seed=x"), ("bar", "speed=1"))],
    # numbers every scene takes
    *[["run", sc, "--quick"] + flags for sc in ("spinning_disc", "pressing", "cutting", "thermal_cutting")
      for flags in (["--dp", "0"], ["--dt", "-1e-9"], ["--t-end", "inf"], ["--set", "courant=nan"])],
    ["run", "taylor", "--dim", "3", "--dp", "1e-9"], ["run", "rings", "--dp", "1e-9"],
    ["run", "bar", "--quick", "--checkpoint-every", "-1"], ["run", "bar", "--quick", "--checkpoint-every", "nan"],
    ["run", "bar", "--quick", "--checkpoint-every", "often"],
    ["run", "thermal_cutting", "--method", "pfem", "--quick", "--checkpoint-every", "-5"],
    ["run", "--restart", "{d}/run", "--checkpoint-every", "-1"],
]


def _run(argv):
    try:
        return main(argv)
    except SystemExit as e:                                  # argparse: usage and exit 2
        return e.code


@pytest.mark.parametrize("argv", CASES, ids=[" ".join(a).replace("{d}/", "") for a in CASES])
def test_bad_input_is_a_message_not_a_traceback(argv, files, capsys, monkeypatch):
    monkeypatch.chdir(files)                                 # a default --out (runs/...) lands in the temporary folder
    before = {p: p.stat().st_mtime_ns for p in files.rglob("*") if p.is_file()}
    code = _run([a.format(d=files) for a in argv])
    out = capsys.readouterr()
    assert code in (2, 3), (code, out.err[-500:])
    assert "Traceback" not in out.err + out.out and out.err.strip(), out.err[-500:]
    changed = [p for p, t in before.items() if not p.exists() or p.stat().st_mtime_ns != t]
    assert not changed, changed                              # nothing outside a new --out was touched
