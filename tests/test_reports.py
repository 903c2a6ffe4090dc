"""The benchmark reports (benchmarks/*_report.md) are what the benchmark scripts write from the committed JSON:
regenerating one gives the committed file byte for byte (so a report cannot drift from its data); and the
README's work-precision figures are redrawn from the JSON by the code as it is."""
import importlib.util
import json
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent


def _script(name):
    spec = importlib.util.spec_from_file_location(f"bench_{name}", ROOT / "benchmarks" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("name", ["taylor", "pressing", "cutting", "stable_step"])
def test_report_is_generated_from_the_json(name):
    records = json.loads((ROOT / "benchmarks" / f"{name}.json").read_text())
    assert _script(name).report(records) == (ROOT / "benchmarks" / f"{name}_report.md").read_text()


@pytest.mark.parametrize("name, figure", [("taylor", "06_taylor_work_precision.png"),
                                          ("pressing", "07_pressing_work_precision.png")])
def test_readme_figures_are_what_the_code_draws(name, figure, tmp_path):
    mod = _script(name)
    mod.FIG = tmp_path
    mod.plots(json.loads((ROOT / "benchmarks" / f"{name}.json").read_text()), json_only=True)
    new, old = matplotlib.image.imread(tmp_path / figure), matplotlib.image.imread(ROOT / "figures" / figure)
    assert new.shape == old.shape and np.abs(new - old).max() < 0.05     # the same picture (fonts may vary)


@pytest.mark.parametrize("name, page", [("lammps_crosscheck", "lammps_crosscheck_report.md"),
                                        ("stability_map", "stability_map_report.md"),
                                        ("thermal_cutting", "thermal_cutting_report.md")])
def test_study_page_is_generated_from_the_json(name, page):
    """The LAMMPS cross-check, the stability map, the 18 measured cuts: their pages are what the scripts write from
    their JSON."""
    mod = _script(name)
    assert mod.report(json.loads((ROOT / "benchmarks" / f"{name}.json").read_text())) == \
        (ROOT / "benchmarks" / page).read_text()


def test_pfem_rake_friction_record_keeps_its_bound():
    """benchmarks/pfem_rake_friction.py: Fp/Fc of a chip on the rake face alone is tan(atan(m) - alpha) (zero at
    m = tan(alpha), 0.55 at AISI 1045's mu0 = 0.81 and 10 deg), and each committed row's bounds are that
    function of its own friction ratios (rake face and edge only: the flank carried nothing)."""
    mod = _script("pfem_rake_friction")
    assert abs(mod.rake_friction_bound(np.tan(np.radians(10.0)), 10.0)) < 1e-12
    assert mod.rake_friction_bound(0.81, 10.0) == pytest.approx(0.5545, abs=1e-4)
    rows = json.loads((ROOT / "benchmarks" / "pfem_rake_friction.json").read_text())["rows"]
    assert rows
    for r in rows:
        assert r["bound_from_rake_friction"] == pytest.approx(mod.rake_friction_bound(r["rake_friction_ratio"], 10.0))
        assert r["bound_from_mu_law"] == pytest.approx(mod.rake_friction_bound(r["rake_mu_law"], 10.0))
        assert r["rake_friction_ratio"] < r["rake_mu_law"] + 1e-12     # Coulomb: never above the law's mu
        assert 0.0 <= r["slipping_fraction"] <= 1.0


def test_pfem_alpha_report_is_generated_from_the_json():
    """benchmarks/pfem_alpha_report.md is what pfem_alpha.report writes from the committed JSON: both cuts, each
    with the default alpha (the reference of its changes) and a value on either side of it."""
    mod = _script("pfem_alpha")
    rows = json.loads((ROOT / "benchmarks" / "pfem_alpha.json").read_text())["rows"]
    assert mod.report(rows) == (ROOT / "benchmarks" / "pfem_alpha_report.md").read_text()
    for cut in mod.TITLES:
        alphas = {r["alpha"] for r in rows if r.get("cut", "") == cut and r["status"] == "ok"}
        assert mod.DEFAULT in alphas and min(alphas) < mod.DEFAULT < max(alphas), cut


def test_thermal_cutting_trend_steps_compare_each_step_sign():
    """thermal_cutting.trend_steps: two steps on each line; a step counts as the measured's when the two changes have
    one sign, and one of opposite sign is listed with both changes in percent at the line's fixed value; a missing
    case drops its steps; the table's cell names the scatter, and each such step's z, only where a step went the
    other way."""
    mod = _script("thermal_cutting")
    rows = [dict(material="AISI1045", vc=vc, tu=tu, Fc_N_per_mm=100 * tu, Fc_exp=tu, Fp_N_per_mm=tu, Fp_exp=tu,
                 TRF=vc + tu, TRF_exp=vc) for vc in (60, 120, 180) for tu in (0.1, 0.15, 0.2)]
    t = mod.trend_steps(rows)["AISI1045"]
    assert t["Fc with t_u"] == (6, 6, []) and t["T_RF with v_c"] == (6, 6, [])
    assert t["Fc with v_c"] == (6, 6, [])          # refsph's Fc flat (sign 0), the measured flat too: the same sign
    rows[1]["Fc_N_per_mm"] = 5.0                     # vc 60: 10 -> 5 -> 20, measured 0.1 -> 0.15 -> 0.2: one step
    n, same, other = mod.trend_steps(rows)["AISI1045"]["Fc with t_u"]
    assert (n, same) == (6, 5) and [(x, round(d), round(de)) for x, d, de in other] == [(60, -50, 50)]
    rows[4]["Fp_N_per_mm"] = None                    # vc 120, tu 0.15 not recorded: its two Fp steps drop
    assert mod.trend_steps(rows)["AISI1045"]["Fp with t_u"][0] == 4
    cells = mod._trend_step_lines({"x": rows}, {("x", "AISI1045"): {"Fc": dict(std_pct=6.0)}})[0].split(" | ")
    assert cells[2] == "5 of 6 (-50.0 / +50.0 at 60 m/min (z -7.5)), sd 6.0 %"   # -50 / (6 hypot(1, 0.5))
    assert cells[3] == "4 of 4"


def test_thermal_cutting_trends_read_every_line():
    """thermal_cutting.trends: a quantity 'rises with t_u' only if it rises at every v_c (one dip says no), and a
    missing case makes the verdict '-' (None)."""
    mod = _script("thermal_cutting")
    rows = [dict(material="AISI1045", vc=vc, tu=tu, Fc_N_per_mm=100 * tu + vc, Fc_exp=tu, Fp_N_per_mm=1.0 * tu,
                 Fp_exp=tu, TRF=vc + tu, TRF_exp=vc) for vc in (60, 120) for tu in (0.1, 0.15, 0.2)]
    t = mod.trends(rows)["AISI1045"]
    assert t["Fc_rises_with_tu"] and t["Fp_rises_with_tu"] and t["TRF_rises_with_vc"]
    rows[4]["Fp_N_per_mm"] = 0.0                                       # vc 120, tu 0.15: a dip
    assert mod.trends(rows)["AISI1045"]["Fp_rises_with_tu"] is False
    rows[4]["Fp_N_per_mm"] = None                                      # not recorded
    assert mod.trends(rows)["AISI1045"]["Fp_rises_with_tu"] is None
    assert mod.trends(rows)["Ti6Al4V"]["Fc_rises_with_tu"] is None     # no Ti6Al4V rows at all
    t = mod.trends(rows)["AISI1045"]                                   # the line at vc 60 is still read
    assert t["Fp_rises_with_tu_lines"] == (1, 1, 2) and t["Fc_rises_with_tu_lines"] == (2, 2, 2)
    assert mod._trend_cell(t, "Fp_rises_with_tu") == "yes, 1 of 2 lines recorded / yes"
    rows[4]["Fp_exp"] = 0.0                          # a measured dip on the line refsph has not recorded: not read
    t = mod.trends(rows)["AISI1045"]
    assert t["Fp_exp_rises_with_tu"] is True and t["Fp_exp_rises_with_tu_lines"] == (1, 1, 2)
    rows[4]["Fp_N_per_mm"] = 0.0                     # recorded now: the measured dip counts
    assert mod.trends(rows)["AISI1045"]["Fp_exp_rises_with_tu_lines"] == (1, 2, 2)
    rows[4]["Fp_exp"] = 0.15
    assert mod._trend_cell(mod.trends(rows)["AISI1045"], "Fp_rises_with_tu") == "no (1 of 2 rise) / yes"
    assert mod._trend_cell(mod.trends(rows)["Ti6Al4V"], "Fc_rises_with_tu") == "- / -"
    t = mod.trends(rows)["AISI1045"]                 # Fc = 100 tu + vc rises with vc: it does not fall, on two lines
    assert t["Fc_falls_with_vc"] is False and t["Fc_falls_with_vc_lines"] == (0, 3, 3)
    assert mod._trend_cell(t, "Fc_falls_with_vc") == "no (0 of 3 fall) / no (0 of 3 fall)"
    for r in rows:
        r["Fc_N_per_mm"], r["Fc_exp"] = 100 * r["tu"] - r["vc"], -r["vc"]
    assert mod._trend_cell(mod.trends(rows)["AISI1045"], "Fc_falls_with_vc") == "yes / yes"


def test_thermal_cutting_rake_face_ceiling_is_merchants_bound():
    """rake_face_ceiling: tan(atan(mu) - 10 deg) at mu0 (AISI 1045: mu0 = 0.81 -> 0.554) and at mu(T) of the measured
    T_RF (lower: mu(T) <= mu0); a case's measured ratio counts as above the ceiling only if it is."""
    import math
    mod = _script("thermal_cutting")
    rows = mod.comparison({"runs": {}})
    c = {x["material"]: x for x in mod.rake_face_ceiling(rows)}
    steel = c["AISI1045"]
    assert steel["ceiling_mu0"] == pytest.approx(math.tan(math.atan(0.81) - math.radians(10.0)), rel=1e-12)
    assert steel["ceiling_T"][1] < steel["ceiling_mu0"] and steel["error_T"] > steel["error_mu0"] > 0
    assert steel["error_T"] > steel["error_T_cooler"] > steel["error_mu0"]      # a cooler face: mu(T) nearer mu0
    assert steel["above"]["_exp"] == 9 and steel["above"][""] == steel["recorded"] == 0   # no refsph record
    for r in rows:                                   # a measured ratio on the ceiling: error 0, not counted above it
        if r["material"] == "AISI1045":
            r["ratio_exp"] = steel["ceiling_mu0"]
    steel = mod.rake_face_ceiling(rows)[0]
    assert steel["error_mu0"] == pytest.approx(0.0, abs=1e-9) and steel["above"]["_exp"] == 0


def test_thermal_cutting_own_ceiling_uses_each_predictions_temperature():
    """own_ceilings: a prediction just below the ceiling at mu(its own T_RF) is not above it, one at twice it is
    (mean 2), and a hotter rake face lowers the ceiling (the same Fp/Fc is then above it)."""
    import math
    mod = _script("thermal_cutting")
    mu = lambda T: 0.81 * (1.0 - ((T - 293.0) / (1773.0 - 293.0)) ** 2.09)           # noqa: E731  (AISI 1045)
    from refsph.scenes.thermal_cutting import MATERIALS
    assert MATERIALS["AISI1045"]["T_melt_K"] == 1773.0
    on = math.tan(math.atan(mu(700.0)) - math.radians(10.0))
    rows = [dict(material="AISI1045", ratio=0.999 * on, TRF=700.0), dict(material="AISI1045", ratio=2 * on, TRF=700.0)]
    got = mod.own_ceilings({"x": (rows[:1], "ratio", "TRF"), "y": (rows[1:], "ratio", "TRF"),
                            "hot": ([dict(rows[0], TRF=1100.0)], "ratio", "TRF")})
    assert got[("AISI1045", "x")][:2] == (0, 1) and got[("AISI1045", "x")][2] == pytest.approx(0.999)
    assert got[("AISI1045", "y")][:2] == (1, 1) and got[("AISI1045", "y")][2] == pytest.approx(2.0)
    assert got[("AISI1045", "hot")][0] == 1 and got[("Ti6Al4V", "x")][1] == 0


def test_thermal_cutting_method_gap_is_pfem_minus_sph():
    """method_gaps: per case with both methods recorded, PFEM - SPH in K for temperatures and PFEM / SPH - 1 in %
    for Fc and Fp/Fc, refsph's beside the paper's (case 1: T_RF 850 - 671.5 K); the mean rows count the cases
    whose sign is the paper's."""
    mod = _script("thermal_cutting")
    rec = lambda trf, fc, fp: dict(status="ok", metrics=dict(                       # noqa: E731
        rake_face_temperature_K=trf, free_chip_surface_temperature_K=500.0, cutting_force_N_per_m=fc * 1e3,
        passive_force_N_per_m=fp * 1e3, force_ratio=fp / fc))
    res = dict(runs={"case 1": rec(600.0, 400.0, 200.0), "case 1" + mod.PFEM10: rec(800.0, 300.0, 120.0),
                     "case 2": rec(600.0, 400.0, 200.0)})           # case 2: no PFEM record, no row
    (g,) = mod.method_gaps(res)
    assert not g["retried"]
    assert g["case"] == 1 and g["ours"]["TRF"] == 200.0 and g["ours"]["TFCS"] == 0.0
    assert g["ours"]["Fc"] == pytest.approx(-25.0) and g["ours"]["ratio"] == pytest.approx(-20.0)
    assert g["paper"]["TRF"] == pytest.approx(850.0 - 671.5)
    assert g["paper"]["Fc"] == pytest.approx(100.0 * (499.73 / 703.54 - 1.0))
    res["runs"]["case 1" + mod.PFEM10 + mod.RETRIES[mod.PFEM10][0]] = res["runs"]["case 1" + mod.PFEM10]
    res["runs"]["case 1" + mod.PFEM10] = dict(status="failed")      # by its Bossak retry: the same numbers, marked
    (r,) = mod.method_gaps(res)
    assert r["retried"] and r["ours"] == g["ours"] and mod._gap_lines([r])[0].startswith("| 1 † |")
    lines = mod._gap_lines([g])
    assert len(lines) == 2 and "(same sign: 1 of 1)" in lines[1].split("|")[4]          # T_RF: both hotter
    assert "(same sign: 0 of 1)" in lines[1].split("|")[10]                             # Fp/Fc: the paper's rises


def test_pfem_edge_radius_report_is_generated_from_the_json():
    """benchmarks/pfem_edge_radius_report.md is what pfem_edge_radius.report writes from the committed JSON: the t_u/5
    cut has the paper's 10 um (the reference of its changes) and blunter edges; a cut recorded at all has 10 um."""
    mod = _script("pfem_edge_radius")
    rows = json.loads((ROOT / "benchmarks" / "pfem_edge_radius.json").read_text())["rows"]
    assert mod.report(rows) == (ROOT / "benchmarks" / "pfem_edge_radius_report.md").read_text()
    for k, cut in enumerate(mod.TITLES):
        radii = {r["edge_radius"] for r in rows if r.get("cut", "") == cut and r["status"] == "ok"}
        assert (mod.PAPER in radii and max(radii) > mod.PAPER) if k == 0 or radii else True, cut


def test_pfem_time_step_report_is_generated_from_the_json():
    """benchmarks/pfem_time_step_report.md is what pfem_time_step.report writes from the committed JSON, and the
    committed study has the default step (courant 0.25) and a smaller one to measure it against."""
    mod = _script("pfem_time_step")
    rows = json.loads((ROOT / "benchmarks" / "pfem_time_step.json").read_text())["rows"]
    assert mod.report(rows) == (ROOT / "benchmarks" / "pfem_time_step_report.md").read_text()
    courants = {r["courant"] for r in rows if r["status"] == "ok"}
    assert 0.25 in courants and min(courants) < 0.25


def test_pfem_step_cost_report_is_generated_from_the_json_and_the_versions_agree():
    """benchmarks/pfem_step_cost_report.md is what pfem_step_cost.report writes from the committed JSON; at each
    resolution every recorded version gives the same tool force (to 1e-6), so a speed-up there changed no number."""
    mod = _script("pfem_step_cost")
    data = json.loads((ROOT / "benchmarks" / "pfem_step_cost.json").read_text())
    rows = data["rows"]
    assert mod.report(rows, data.get("full", []), mod.sweep_record()) == \
        (ROOT / "benchmarks" / "pfem_step_cost_report.md").read_text()
    for n_tu in {r["n_tu"] for r in rows}:
        forces = [r["tool_force_N_per_m"] for r in rows if r["n_tu"] == n_tu]
        assert len(forces) >= 2, (n_tu, forces)                     # versions to agree: at least two records
        for f in forces[1:]:
            assert f == pytest.approx(forces[0], rel=1e-6), (n_tu, forces)


def _cut_rec(fc: float) -> dict:
    """A sweep record that ended well with Fc = fc N/mm, Fp = 50 N/mm and fixed temperatures and chip."""
    return dict(status="ok", dp=1e-5, scene_info=dict(tu_m=1e-4),
                metrics=dict(cutting_force_N_per_m=1e3 * fc, passive_force_N_per_m=5e4, force_ratio=50 / fc,
                             rake_face_temperature_K=600.0, rake_face_temperature_max_K=650.0,
                             free_chip_surface_temperature_K=500.0, chip_thickness_mm=0.3, contact_length_mm=0.3))


def test_thermal_cutting_single_run_against_a_scatter_group():
    """One run against the mean and standard deviation of a scatter group, from the records: a group made of one
    run's copies has no spread (no z), and a run 10 % above a group of two at 100 +- 10 % is z = +1."""
    mod = _script("thermal_cutting")
    res = dict(runs={"a": _cut_rec(90.0), "b": _cut_rec(110.0), "one": _cut_rec(110.0)})
    line = mod._single_run_line(res, "one", ("a", "b"))
    sd = np.std([90.0, 110.0], ddof=1)
    assert f"Fc [N/mm] +10.0 % (z = {10.0 / sd:+.1f})" in line and "Fp [N/mm] +0.0 %," in line
    assert "not recorded yet" in mod._single_run_line(res, "missing", ("a", "b"))
    assert "not recorded yet" in mod._single_run_line(res, "one", ("a",))


def test_thermal_cutting_pair_change_in_units_of_a_like_case_s_scatter():
    """Two single runs: the change in percent of the base run, and z in the scatter group's relative standard
    deviation (a group at 90 and 110 has 14.1 %, so a 10 % change is z = 0.71); missing runs are said, not drawn."""
    mod = _script("thermal_cutting")
    res = dict(runs={"g": _cut_rec(90.0), "g jitter 1": _cut_rec(110.0), "base": _cut_rec(200.0),
                     "new": _cut_rec(220.0)})
    line = mod._pair_change_line(res, "new", "base", ("g", "g jitter 1"))
    rel_sd = 100 * np.std([90.0, 110.0], ddof=1) / 100.0
    assert f"Fc [N/mm] +10.0 % (z = {10.0 / rel_sd:+.1f})" in line and "Fp [N/mm] +0.0 %," in line
    assert "its 1 jittered runs" in line
    assert "not recorded yet" in mod._pair_change_line(res, "new", "missing", ("g", "g jitter 1"))
    assert "not recorded yet" in mod._pair_change_line(res, "new", "base", ("g",))


def test_thermal_cutting_status_reads_records_and_run_folders(tmp_path, monkeypatch):
    """thermal_cutting --status: a recorded job shows its record's status, a job whose run folder has a summary
    shows how far it got (simulated time against the end), any other is 'to run'."""
    mod = _script("thermal_cutting")
    monkeypatch.setattr(mod, "RUNS", tmp_path)
    folder = mod.run_folder("case 2")
    folder.mkdir()
    (folder / "summary.json").write_text(json.dumps(dict(status="running", t_final=6e-4, t_end=2.4e-3, n_steps=10,
                                                         wall_time_s=600.0)))
    todo = {"case 1": None, "case 2": None, "case 1 s/2": None}
    lines = mod.status_lines({"case 1": dict(status="ok", wall_time_s=1920.0)}, todo)
    assert lines[0].split() == ["case", "1", "recorded:", "ok", "(32", "min)"]
    assert "t = 0.600 of 2.400 ms (25 %)" in lines[1] and "about 30 min to go" in lines[1]
    assert lines[2].endswith("to run") and mod.run_folder("case 1 s/2").name == "case_1_s2"


def test_thermal_cutting_status_of_a_killed_run_names_its_last_checkpoint(tmp_path, monkeypatch):
    """A run whose process is gone: 'stopped', where it was last heard of, and the time of the checkpoint a rerun
    continues from (restart.npz's; none said where the checkpoint does not tell it)."""
    import socket
    import time
    mod = _script("thermal_cutting")
    monkeypatch.setattr(mod, "RUNS", tmp_path)
    folder = mod.run_folder("case 2")
    (folder / "snapshots").mkdir(parents=True)
    (folder / "progress.json").write_text(json.dumps(dict(t=1e-3, t_end=2e-3, t_begin=0.0, wall_s=60.0, steps=5,
                                                          written=time.time(), pid=2**22 + 12345,
                                                          host=socket.gethostname())))
    line = mod.status_lines({}, {"case 2": None})[0]
    assert "stopped" in line and "t = 1.000 of 2.000 ms" in line and line.endswith("from its last checkpoint")
    np.savez(folder / "snapshots" / "restart.npz", run=json.dumps(dict(t=4e-4, snapshot="checkpoint_a.npz")))
    line = mod.status_lines({}, {"case 2": None})[0]
    assert line.endswith("from its last checkpoint, at t = 0.400 ms")


def test_thermal_cutting_backfills_cpu_seconds_only_from_the_same_run(tmp_path, monkeypatch):
    """--backfill-cpu: a record without CPU seconds takes them from its run folder's summary when that summary is
    the same run (ok, the same steps); a record that has them, a folder of another run, or none, are left alone."""
    mod = _script("thermal_cutting")
    monkeypatch.setattr(mod, "RUNS", tmp_path / "runs")
    for key, steps, status in (("case 1", 100, "ok"), ("case 2", 99, "ok"), ("case 3", 100, "running"),
                               ("case 5", 100, "ok")):
        folder = mod.run_folder(key)
        folder.mkdir(parents=True)
        (folder / "summary.json").write_text(json.dumps(dict(status=status, n_steps=steps, cpu_time_s=60.0)))
    runs = {k: dict(status="ok", n_steps=100) for k in ("case 1", "case 2", "case 3", "case 4")}
    runs["case 5"] = dict(status="ok", n_steps=100, cpu_time_s=30.0)
    path = tmp_path / "sweep.json"
    path.write_text(json.dumps(dict(runs=runs)))
    assert mod.backfill_cpu(mod.store(path)) == ["case 1"]
    got = json.loads(path.read_text())["runs"]
    assert got["case 1"]["cpu_time_s"] == 60.0 and got["case 5"]["cpu_time_s"] == 30.0
    assert all("cpu_time_s" not in got[k] for k in ("case 2", "case 3", "case 4"))


def test_viscous_pressure_is_the_pair_pressure_of_the_artificial_viscosity(tmp_path, capsys):
    """benchmarks/viscous_stress.py: on a lattice squeezed uniformly (x = 0.98 X, v = -gamma x: every pair
    approaches) a pair's viscous pressure is rho0^2 pi_ij / 2 (rho0 the reference density; pi_ij of Eqs. (12)-(13),
    refsph.esph.artificial_viscosity, with the current one), averaged over
    each particle's neighbours with the kernel (the particle itself counted with q = 0); a rigid motion gives none;
    a folder that is not a run is refused with a message, not a traceback."""
    from refsph.esph import artificial_viscosity
    from refsph.kernels import get_kernel
    from refsph.neighbours import find_pairs
    from refsph.scenes import lattice
    mod = _script("viscous_stress")
    dp, rho0, c, b1, b2, eps = 1e-4, 7850.0, 5000.0, 0.5, 0.5, 0.01
    h, kernel = 1.3 * dp, get_kernel("wendland")
    X = lattice([10 * dp, 10 * dp], dp)
    x = 0.98 * X                                                             # squeezed: rho = rho0 / J, J = 0.98^2
    n, rho = len(X), rho0 / 0.98**2
    V0, m = np.full(n, dp * dp), np.full(n, rho0 * dp * dp)
    v = -50.0 * x
    q = mod.viscous_pressure(X, x, v, np.full(n, rho), V0, m, h, kernel, b1, b2, eps, c)
    i = int(np.argmin(np.sum((X - X.mean(axis=0)) ** 2, axis=1)))           # an interior particle
    I, J = find_pairs(X, 2 * h)
    mine = np.flatnonzero((I == i) | (J == i))
    xij, vij = x[I[mine]] - x[J[mine]], v[I[mine]] - v[J[mine]]
    pi = artificial_viscosity(np.sum(vij * xij, axis=1), np.sum(xij * xij, axis=1), rho, c, h, b1, b2, eps)
    Xij = X[I[mine]] - X[J[mine]]
    W = kernel.w(np.sqrt(np.sum(Xij * Xij, axis=1)), h, 2)                  # weights of the reference pairs
    expected = np.sum(W * rho0**2 * pi / 2) / (np.sum(W) + kernel.w(np.zeros(1), h, 2)[0])
    assert np.all(pi > 0) and q[i] == pytest.approx(expected, rel=1e-12)
    assert np.all(mod.viscous_pressure(X, X + 1e-5, np.tile([3.0, -1.0], (n, 1)), np.full(n, rho), V0, m, h,
                                       kernel, b1, b2, eps, c) == 0.0)
    assert mod.main(["--run", str(tmp_path)]) == 2
    assert "not a run folder" in capsys.readouterr().err


def test_thermal_cutting_takes_a_failed_case_again_at_half_the_step():
    """thermal_cutting.comparison: a case of the t_u/10 table that failed at the sweep's step takes its run at half
    the step ('case N courant 0.075') where that one is recorded 'ok', and its row says so; a case that ran at the
    sweep's step keeps that run."""
    mod = _script("thermal_cutting")
    runs = json.loads((ROOT / "benchmarks" / "thermal_cutting.json").read_text())["runs"]
    ok = next(r for r in runs.values() if r["status"] == "ok" and r.get("metrics"))
    res = dict(runs={"case 9": dict(status="error", error="inverted particle"), "case 9" + mod.RETRY: ok,
                     "case 8": ok, "case 8" + mod.RETRY: dict(ok, metrics=dict(ok["metrics"], force_ratio=9.0))})
    rows = {r["case"]: r for r in mod.comparison(res)}
    assert rows[9]["status"] == "ok" and rows[9]["key"] == "case 9" + mod.RETRY
    assert "ok (courant 0.075)" in mod._case_line(rows[9])
    assert rows[8]["key"] == "case 8" and "courant" not in mod._case_line(rows[8])
    assert rows[7]["status"] == "to run"
    del res["runs"]["case 9" + mod.RETRY]
    assert {r["case"]: r for r in mod.comparison(res)}[9]["status"] == "error"


def test_thermal_cutting_queues_the_retry_of_a_failed_case():
    """retry_jobs: a failed t_u/10 case gets its retry (SPH at half the step, PFEM with the damped rule), an ok or
    missing one none, and a study not asked for none."""
    mod = _script("thermal_cutting")
    recs = {"case 3": dict(status="blow-up"), "case 4": dict(status="ok"), "case 12 pfem": dict(status="error")}
    out = mod.retry_jobs(recs)
    bossak = "case 12 pfem n_tu 10" + mod.BOSSAK
    assert set(out) == {"case 3" + mod.RETRY, bossak}
    options, numerics = out[bossak]
    assert options["case"] == 12 and options["n_tu"] == 10.0 and options["bossak"] == mod.BOSSAK_ALPHA
    assert numerics == dict(method="pfem")
    assert out["case 3" + mod.RETRY][1]["courant"] == mod.RETRY_COURANT
    assert set(mod.retry_jobs(recs, studies=("pfem",))) == {bossak}
    refined = "case 3" + mod.REFINED                                  # a refined case: at half the CFL step
    out = mod.retry_jobs({refined: dict(status="blow-up")}, studies=("refined",))
    assert list(out) == [refined + mod.REFINED_RETRY] and out[refined + mod.REFINED_RETRY][1] == dict(
        ref_update_strain=mod.REF_UPDATE, frequency_step=mod.FREQUENCY_STEP, courant=mod.COURANT)
    ok = json.loads((ROOT / "benchmarks" / "thermal_cutting.json").read_text())["runs"]["case 3"]
    page = "\n".join(mod._study_lines(dict(runs={refined: dict(status="blow-up"), refined + mod.REFINED_RETRY: ok})))
    assert f"| {refined} |" in page and f"| {refined + mod.REFINED_RETRY} |" in page
    two = "case 4" + mod.PFEM10 + mod.TO_2MM                         # a PFEM cut to 2 mm: its Bossak retry
    out = mod.retry_jobs(dict(recs, **{two: dict(status="failed")}), studies=("pfem",))
    assert set(out) == {bossak, two + mod.BOSSAK}
    options = out[two + mod.BOSSAK][0]
    assert (options["case"], options["travel"], options["length"], options["bossak"]) == (4, 20.0, 3e-3, -0.1)


def test_thermal_cutting_takes_a_failed_pfem_case_with_the_damped_rule():
    """thermal_cutting.comparison of the PFEM at t_u/10: a case that failed with the trapezoidal rule takes its run
    with gamma 0.6 ('case N pfem' + DAMPED) where that one is 'ok', and its row says so; the t_u/5 PFEM table and
    the SPH table do not take it."""
    mod = _script("thermal_cutting")
    runs = json.loads((ROOT / "benchmarks" / "thermal_cutting.json").read_text())["runs"]
    ok = next(r for r in runs.values() if r["status"] == "ok" and r.get("metrics"))
    res = dict(runs={"case 8 pfem": dict(status="failed", error="NewtonFailed"), "case 8 pfem" + mod.DAMPED: ok,
                     "case 8 pfem n_tu 5": dict(status="failed"), "case 8 pfem n_tu 5" + mod.DAMPED: ok})
    rows = {r["case"]: r for r in mod.comparison(res, mod.PFEM10)}
    assert rows[8]["status"] == "ok" and rows[8]["key"] == "case 8 pfem" + mod.DAMPED
    assert "ok (gamma 0.6)" in mod._case_line(rows[8])
    assert {r["case"]: r for r in mod.comparison(res, mod.PFEM)}[8]["status"] == "failed"
    res["runs"]["case 8 pfem n_tu 10" + mod.BOSSAK] = ok                # Bossak-Newmark before the damped rule
    rows = {r["case"]: r for r in mod.comparison(res, mod.PFEM10)}
    assert rows[8]["key"] == "case 8 pfem n_tu 10" + mod.BOSSAK and "ok (Bossak -0.1)" in mod._case_line(rows[8])
    res["runs"]["case 8 pfem n_tu 10" + mod.BOSSAK] = dict(status="failed")
    assert {r["case"]: r for r in mod.comparison(res, mod.PFEM10)}[8]["key"] == "case 8 pfem" + mod.DAMPED
    del res["runs"]["case 8 pfem" + mod.DAMPED]
    assert {r["case"]: r for r in mod.comparison(res, mod.PFEM10)}[8]["status"] == "failed"


def test_thermal_cutting_means_at_the_paper_length_of_cut():
    """window_means: means over a stretch of the tool's travel from a record's histories (a linear history's mean is
    its midpoint value; None before the run reaches the window's end); over the last quarter of a committed run's cut
    it gives that run's recorded metrics (the same window, from 100 points instead of every step)."""
    mod = _script("thermal_cutting")
    t = np.linspace(0.0, 2e-3, 201)                                 # 2 mm at 1 m/s
    rec = dict(status="ok", histories=dict(temperature_history=[[s, 300.0 + 1e5 * s, None] for s in t],
                                           cutting_force_history=[[s, 2.0] for s in t],
                                           passive_force_history=[[s, 1e3 * s] for s in t]))
    w = mod.window_means(rec, 1.0, 1.5e-3, 2.0e-3)
    assert w["TRF"] == pytest.approx(300.0 + 1e5 * 1.75e-3) and w["ratio"] == pytest.approx(1.75e-3 / 2.0 * 1e3)
    assert np.isnan(w["TFCS"]) and mod.window_means(rec, 0.5, 1.5e-3, 2.0e-3) is None
    assert mod.window_means(dict(rec, status="failed: x"), 1.0, 1.5e-3, 2.0e-3) is None
    runs = mod.load()["runs"]
    for key, vc in (("case 3 pfem", 1.0), ("case 11", 20 / 60)):
        m, end = runs[key]["metrics"], vc * runs[key]["histories"]["temperature_history"][-1][0]
        w = mod.window_means(runs[key], vc, 0.75 * end, end)
        assert w["TRF"] == pytest.approx(m["rake_face_temperature_K"], rel=0.01)
        assert w["ratio"] == pytest.approx(m["force_ratio"], rel=0.03)
    done = dict(runs["case 1 pfem 2 mm"])                             # case 1's PFEM cut to 2 mm, as recorded
    res = dict(runs={"case 1 pfem": runs["case 1 pfem"], "case 1 pfem 2 mm": dict(status="failed"),
                     "case 1 pfem 2 mm" + mod.BOSSAK: done})        # failed, and its Bossak retry ran
    row = mod.paper_length_rows(res, mod.PFEM10)[0]
    assert row["key2"] == "case 1 pfem 2 mm" + mod.BOSSAK
    assert row["2mm"]["TRF"][0] == pytest.approx(mod.window_means(done, 1.0, *mod.PAPER_CUT)["TRF"])


def test_thermal_cutting_paper_spacing_takes_the_fine_runs_of_the_thicker_cuts():
    """paper_spacing_rows: AISI 1045's nine PFEM rows, the t_u = 0.1 mm cases from their t_u/10 runs (with the
    retries), the others from the runs at 10 um near the tool (15 and 20 nodes across t_u, cases 8 and 9 with the
    Bossak rule), never from their t_u/10 runs; a fine run's window at 2 mm comes from its own longer cut."""
    mod = _script("thermal_cutting")
    runs = mod.load()["runs"]
    res = dict(runs={k: runs[k] for k in ("case 1 pfem", "case 2 pfem", "case 4 pfem", "case 3 pfem")})
    res["runs"]["case 2 pfem n_tu 15"] = runs["case 2 pfem"]                 # a stand-in for the fine run
    rows = {r["case"]: r for r in mod.paper_spacing_rows(res)}
    assert sorted(rows) == list(range(1, 10))
    assert rows[1]["key"] == "case 1 pfem" and rows[4]["key"] == "case 4 pfem"
    assert rows[2]["key"] == "case 2 pfem n_tu 15" and rows[2]["status"] == "ok" and rows[2]["key2"] == rows[2]["key"]
    assert rows[3]["key"] == "case 3 pfem n_tu 20" and rows[3]["status"] == "to run"      # not its t_u/10 run
    assert rows[8]["key"] == "case 8 pfem n_tu 15" + mod.BOSSAK and rows[9]["key"] == "case 9 pfem n_tu 20" + mod.BOSSAK
    assert rows[2]["2mm"]["TRF"][0] == pytest.approx(mod.window_means(runs["case 2 pfem"], 1.0, *mod.PAPER_CUT)["TRF"])



def test_thermal_cutting_pfem_spacing_order_through_three_spacings():
    """pfem_spacing_convergence: case 2's three PFEM spacings with Fc = 400 + C dx^2 give the order 2 and the limit
    400, T_RF changing sign gives no order; a case with a spacing missing names only the missing key; the Bossak
    cases take their Bossak runs at every spacing."""
    mod = _script("thermal_cutting")
    assert mod.pfem_spacing_keys(9) == ("case 9 pfem n_tu 5" + mod.BOSSAK, "case 9 pfem n_tu 10" + mod.BOSSAK,
                                        "case 9 pfem n_tu 20" + mod.BOSSAK)
    keys = mod.pfem_spacing_keys(2)
    assert keys == ("case 2 pfem n_tu 5 rerun", "case 2 pfem rerun", "case 2 pfem n_tu 15")   # today's solver
    assert mod.pfem_spacing_keys(8)[0] == "case 8 pfem n_tu 5" + mod.BOSSAK                   # made by it already
    jobs = mod.jobs()
    assert all(k in jobs for n in mod.PFEM_RERUN_CASES for k in mod.pfem_spacing_keys(n))
    runs = {k: _resolution_record(400.0 + 1e3 * (1.0 / n) ** 2, n) for k, n in zip(keys, (5, 10, 15))}
    for r, t in zip(runs.values(), (600.0, 620.0, 610.0)):
        r["metrics"]["rake_face_temperature_K"] = t
    rows = {(r["case"], r["name"]): r for r in mod.pfem_spacing_convergence(dict(runs=runs))}
    fc = rows[2, "Fc [N/mm]"]
    assert fc["p"] == pytest.approx(2.0, rel=1e-6) and fc["f0"] == pytest.approx(400.0, rel=1e-9)
    assert fc["h"] == pytest.approx([20.0, 10.0, 1e2 / 15])
    assert rows[2, "T_RF [K]"]["p"] is None and rows[2, "T_RF [K]"]["f0"] is None
    slow = mod.pfem_spacing_convergence(dict(runs={k: _resolution_record(400.0 + 1e3 * (1.0 / n) ** 0.3, n)
                                                   for k, n in zip(keys, (5, 10, 15))}))
    (fc,) = [r for r in slow if r["case"] == 2 and r["name"] == "Fc [N/mm]"]
    assert fc["p"] == pytest.approx(0.3, rel=1e-6) and fc["f0"] is None          # below PFEM_ORDER_MIN: none
    assert rows[2, "T_RF [K]"]["exp"] == 730.0                                   # the measured value of case 2
    assert rows[3, None]["keys"] == [f"'{k}'" for k in mod.pfem_spacing_keys(3)]   # nothing of case 3 given
    runs["case 2 pfem rerun"] = dict(status="failed")
    (row,) = [r for r in mod.pfem_spacing_convergence(dict(runs=runs)) if r["case"] == 2]
    assert row["keys"] == ["'case 2 pfem rerun' (failed)"]
    lines = mod._pfem_spacing_lines([row])
    assert lines[-1].count("|") == lines[1].count("|") and "'case 2 pfem rerun' (failed)" in lines[-1]
    jobs = [k for k, _ in mod.pfem_resolution_jobs()]
    assert "case 9 pfem n_tu 5" + mod.BOSSAK in jobs and "case 8 pfem n_tu 5" + mod.BOSSAK not in jobs   # the
    assert "case 8 pfem n_tu 5" + mod.BOSSAK in [k for k, _ in mod.time_rule_jobs()]       # time rule's study's

def test_thermal_cutting_pfem_spacing_changes_are_read_against_the_pfem_scatter():
    """Case 2's spacing changes carry a z from the PFEM's scatter runs at each spacing (PFEM_SCATTER at t_u/5,
    PFEM_SCATTER10 at t_u/10 and taken at the finer spacing), other cases none; pfem_scatter_line gives both spreads
    and how far the sweep's older records lie from each group's mean, and says so where too few runs are recorded."""
    import math
    mod = _script("thermal_cutting")
    keys = mod.pfem_spacing_keys(2)
    assert keys[0] == mod.PFEM_SCATTER[0]                  # the unperturbed scatter run is the spacing's t_u/5 run
    assert keys[1] == mod.PFEM_SCATTER10[0]                # ... and its t_u/10 run
    runs = {k: _resolution_record(fc, n) for k, fc, n in zip(keys, (396.0, 440.0, 444.0), (5, 10, 15))}
    assert math.isnan(mod.pfem_spacing_convergence(dict(runs=runs))[1]["z1"])
    assert "Case 2 at t_u/5: 1 of 4 runs recorded" in mod.pfem_scatter_line(dict(runs=runs))
    for k, fc in zip(mod.PFEM_SCATTER[1:], (404.0, 396.0, 404.0)):         # mean 400, sd 4.62 (1.15 %)
        runs[k] = _resolution_record(fc, 5)
    fc = {(r["case"], r["name"]): r for r in mod.pfem_spacing_convergence(dict(runs=runs))}[2, "Fc [N/mm]"]
    assert math.isnan(fc["z1"]) and math.isnan(fc["z2"])                   # no spread at t_u/10 yet: no z
    for k, fc in zip(mod.PFEM_SCATTER10[1:], (436.0, 444.0, 440.0)):       # mean 440, sd 3.27 (0.74 %)
        runs[k] = _resolution_record(fc, 10)
    rows = {(r["case"], r["name"]): r for r in mod.pfem_spacing_convergence(dict(runs=runs))}
    fc = rows[2, "Fc [N/mm]"]
    s5 = float(np.std([396.0, 404.0, 396.0, 404.0], ddof=1)) / 400.0
    s10 = float(np.std([440.0, 436.0, 444.0, 440.0], ddof=1)) / 440.0
    assert fc["z1"] == pytest.approx(44.0 / math.hypot(s5 * 396.0, s10 * 440.0), rel=1e-12)
    assert fc["z2"] == pytest.approx(4.0 / (s10 * math.hypot(440.0, 444.0)), rel=1e-12)
    assert math.isnan(rows[2, "T_RF [K]"]["z1"])                             # no spread: no z (0 / 0)
    assert "+11.1 % (" in mod._pfem_spacing_lines([fc])[-1]
    line = mod.pfem_scatter_line(dict(runs=runs))
    assert "Case 2 at t_u/5, 4 runs: " in line and "Fc 1.2 %" in line and "mean by -." in line  # no older record given
    assert "At t_u/10, 4 runs: " in line and "Fc 0.7 %" in line
    assert f"Case 10 (Ti6Al4V) at t_u/10: 0 of {len(mod.PFEM_SCATTER10_TI)} runs recorded" in line
    runs["case 2 pfem n_tu 5"] = _resolution_record(409.24, 5)               # two deviations above the mean
    assert "Fc +2.3 % (+2.0)" in mod.pfem_scatter_line(dict(runs=runs))
    runs["case 2 pfem"] = _resolution_record(440.0 - 3 * 3.266, 10)         # three below the t_u/10 mean
    assert "Fc -2.2 % (-3.0)" in mod.pfem_scatter_line(dict(runs=runs))
    for k, fc in zip(mod.PFEM_SCATTER10_TI, (300.0, 310.0, 320.0)):          # Ti6Al4V at t_u/10: sd 3.2 %
        runs[k] = _resolution_record(fc, 10)
    assert "Case 10 (Ti6Al4V) at t_u/10, 3 runs: " in mod.pfem_scatter_line(dict(runs=runs))
    of = {k: mod.pfem_scatter_of(dict(runs=runs), k)["Fc"]["std_pct"]
          for k in ("case 14 pfem n_tu 5", "case 2 pfem", "case 5 pfem n_tu 15", "case 14 pfem", "case 16 pfem 2 mm")}
    assert of["case 14 pfem n_tu 5"] == pytest.approx(100 * s5)               # t_u/5: case 2's, either material
    assert of["case 2 pfem"] == of["case 5 pfem n_tu 15"] == pytest.approx(100 * s10)   # steel, t_u/10 and finer
    assert of["case 14 pfem"] == of["case 16 pfem 2 mm"] == pytest.approx(100 * 10.0 / 310.0)   # Ti6Al4V's


def test_thermal_cutting_solver_changes_are_read_against_the_pfem_scatter():
    """solver_changes pairs each record with its rerun (SOLVER_CHANGES: both t_u/5 and t_u/10 tables), only where
    both ended well, and reads each change against the scatter at the pair's spacing (pfem_scatter_of) as a change
    between two single runs (change_z); the line counts the changes beyond 2 sd among those with a scatter, names
    those without one, and says nothing of z where none has one."""
    import math
    mod = _script("thermal_cutting")
    pairs = list(zip(mod.SOLVER_CHANGES[::2], mod.SOLVER_CHANGES[1::2]))
    assert all(new == old + mod.RERUN for old, new in pairs)
    assert ("case 12 pfem n_tu 5", "case 12 pfem n_tu 5 rerun") in pairs
    assert ("case 4 pfem", "case 4 pfem rerun") in pairs
    assert "case 12 pfem" not in mod.SOLVER_CHANGES                     # t_u/10: AISI 1045's cases 1-7 only
    assert mod.REDONE[mod.PFEM] == mod.REDONE[mod.PFEM10] == (mod.RERUN,)
    runs = {"case 4 pfem": _resolution_record(400.0, 10), "case 4 pfem rerun": _resolution_record(440.0, 10),
            "case 7 pfem": _resolution_record(400.0, 10), "case 7 pfem rerun": _resolution_record(404.0, 10),
            "case 12 pfem n_tu 5": _resolution_record(400.0, 5), "case 12 pfem n_tu 5 rerun": dict(status="failed")}
    rows = mod.solver_changes(dict(runs=runs))["Fc [N/mm]"]
    assert [r[0] for r in rows] == ["case 4 pfem rerun", "case 7 pfem rerun"]   # the failed rerun left out
    assert rows[0][1] == pytest.approx(10.0) and math.isnan(rows[0][2])       # no scatter runs: no z
    assert "beyond" not in mod.solver_changes_line(dict(runs=runs))
    for k, fc in zip(mod.PFEM_SCATTER, (392.0, 408.0, 392.0, 408.0)):        # sd 2.31 % of the mean at t_u/5
        runs[k] = _resolution_record(fc, 5)
    runs["case 12 pfem n_tu 5 rerun"] = _resolution_record(480.0, 5)         # a t_u/5 pair reads t_u/5's scatter
    rows = mod.solver_changes(dict(runs=runs))["Fc [N/mm]"]
    assert math.isnan(rows[0][2])                                            # t_u/10 pairs: t_u/10's scatter, none
    s5 = 100 * float(np.std([392.0, 408.0, 392.0, 408.0], ddof=1)) / 400.0
    assert rows[2][0] == "case 12 pfem n_tu 5 rerun"
    assert rows[2][2] == pytest.approx(20.0 / (s5 * math.hypot(400.0, 480.0) / 400.0), rel=1e-12)   # 5.6 sd
    assert "Fc mean |change| 10.3 %, largest +20.0 % ('case 12 pfem n_tu 5 rerun'), 1 of 1 beyond 2 sd (2 without " \
        "a scatter yet)" in mod.solver_changes_line(dict(runs=runs))
    runs.pop("case 12 pfem n_tu 5 rerun")
    for k, fc in zip(mod.PFEM_SCATTER10, (396.0, 404.0, 396.0, 404.0)):      # half of it at t_u/10
        runs[k] = _resolution_record(fc, 10)
    rows = mod.solver_changes(dict(runs=runs))["Fc [N/mm]"]
    sd = 100 * float(np.std([396.0, 404.0, 396.0, 404.0], ddof=1)) / 400.0
    assert rows[0][2] == pytest.approx(10.0 / (sd * math.hypot(1.0, 1.1)), rel=1e-12)    # 5.8 sd: beyond
    assert rows[1][2] == pytest.approx(1.0 / (sd * math.hypot(1.0, 1.01)), rel=1e-12)    # 0.6 sd: within
    assert mod.change_z(-50.0, 10.0) == pytest.approx(-50.0 / (10.0 * math.hypot(1.0, 0.5)), rel=1e-12)
    line = mod.solver_changes_line(dict(runs=runs))
    assert "Over the 2 pairs" in line
    assert "Fc mean |change| 5.5 %, largest +10.0 % ('case 4 pfem rerun'), 1 of 2 beyond 2 sd;" in line
    assert mod.solver_changes_line(dict(runs={})).startswith("No record and its rerun")


def test_thermal_cutting_pfem_scatter_of_reads_the_spacing_and_material_of_the_run():
    """pfem_scatter_of: a run at t_u/5 reads case 2's t_u/5 scatter whatever its material or key; a finer one case
    2's t_u/10 scatter for AISI 1045 (cases 1-9) and case 10's for Ti6Al4V (10-18); the spacing from the record's
    options where recorded (a key without 'n_tu 5' cut at t_u/5 is still t_u/5), else from the key; a key that is
    not the PFEM's refused."""
    mod = _script("thermal_cutting")
    runs = {}
    for keys, fcs, n in ((mod.PFEM_SCATTER, (390.0, 410.0), 5), (mod.PFEM_SCATTER10, (380.0, 420.0), 10),
                         (mod.PFEM_SCATTER10_TI, (360.0, 440.0), 10)):
        runs.update({k: _resolution_record(fc, n) for k, fc in zip(keys, fcs)})
    sd = {n: 100 * float(np.std(f, ddof=1)) / 400.0 for n, f in ((5, (390.0, 410.0)), (10, (380.0, 420.0)),
                                                                   ("ti", (360.0, 440.0)))}
    runs["case 16 pfem gamma 0.6"] = dict(_resolution_record(300.0, 5), options=dict(case=16, n_tu=5.0))
    want = {"case 2 pfem n_tu 5 rerun": 5, "case 14 pfem n_tu 5": 5, "case 16 pfem gamma 0.6": 5,
            "case 2 pfem": 10, "case 9 pfem": 10, "case 1 pfem n_tu 15": 10, "case 8 pfem n_tu 15 bossak -0.1": 10,
            "case 10 pfem": "ti", "case 14 pfem": "ti", "case 16 pfem 2 mm": "ti"}
    got = {k: mod.pfem_scatter_of(dict(runs=runs), k)["Fc"]["std_pct"] for k in want}
    assert got == {k: pytest.approx(sd[w], rel=1e-12) for k, w in want.items()}
    with pytest.raises(ValueError, match="not a PFEM run"):
        mod.pfem_scatter_of(dict(runs=runs), "case 10 n_tu 15")


def test_pfem_cut_jitter_moves_only_free_nodes_by_at_most_their_spacing_fraction():
    """pfem_cut(jitter=0.01, seed=k): each free node of the workpiece moved by at most 0.01 of its own spacing, the
    held ones (bottom row, left column) and the tool where they were, the same seed the same nodes, another seed
    others; jitter 0 the unperturbed cut to the bit; a jitter out of range refused."""
    from refsph.pfem.cutting import pfem_cut
    kw = dict(case=1, n_tu=5.0, travel=2.0, length=0.6e-3, conduction=False)
    a, b, c, d = (pfem_cut(**kw, **extra) for extra in (dict(), dict(jitter=0.01, seed=1),
                                                        dict(jitter=0.01, seed=1), dict(jitter=0.01, seed=2)))
    held = a.fixed.any(axis=1)
    move = np.abs(b.nodes.x - a.nodes.x)
    assert np.all(move[held] == 0.0) and np.all(move[~held] > 0.0)
    assert np.all(move <= 0.01 * a.h[:, None] * (1 + 1e-12))
    assert np.array_equal(b.nodes.x, c.nodes.x) and not np.array_equal(b.nodes.x, d.nodes.x)
    assert np.array_equal(b.X0, b.nodes.x) and np.array_equal(b.fixed, a.fixed)
    assert np.array_equal(pfem_cut(**kw, jitter=0.0).nodes.x, a.nodes.x)
    assert b.info["length_m"] == a.info["length_m"] and b.info["jitter"] == 0.01 and b.info["seed"] == 1
    with pytest.raises(ValueError, match="jitter"):
        pfem_cut(**kw, jitter=-0.1)


def _resolution_record(fc, n):
    """A made-up 'ok' record of a cut at n particles across t_u with Fc = ``fc`` N/mm (the other quantities fixed)."""
    return dict(status="ok", dp=1e-4 / n, scene_info=dict(tu_m=1e-4),
                metrics=dict(cutting_force_N_per_m=1e3 * fc, passive_force_N_per_m=5e4, force_ratio=50 / fc,
                             rake_face_temperature_K=600.0, rake_face_temperature_max_K=650.0,
                             free_chip_surface_temperature_K=500.0, chip_thickness_mm=0.3, contact_length_mm=0.3))


def test_thermal_cutting_resolution_order_is_read_only_where_the_changes_beat_the_scatter():
    """resolution_convergence: Fc = 300 + C dx^2 through t_u/5, /10, /15 with a scatter of 1 N/mm gives the order 2
    and the limit 300; the same runs with a scatter of 100 N/mm give no order (both changes inside the scatter), and
    one change beyond twice its deviation names it; a missing t_u/15 run says so. study.observed_order and
    study.richardson on an exact power law."""
    import math
    mod = _script("thermal_cutting")
    st = mod.study
    h = [1 / 5, 1 / 10, 1 / 15]
    assert abs(st.observed_order(h, [1 + 2 * x**1.5 for x in h]) - 1.5) < 1e-9
    assert abs(st.richardson(h, [1 + 2 * x**1.5 for x in h], 1.5) - 1.0) < 1e-12
    assert st.observed_order(h, [1.0, 2.0, 1.5]) is None

    rec = _resolution_record

    def records(spread, with_fine=True):
        runs = {}
        for case, keys in mod.RESOLUTION_KEYS.items():
            for key, n in zip(keys, mod.RESOLUTION_N):
                if n != 15.0 or with_fine:
                    runs[key] = rec(300.0 + 1e4 * (1 / n) ** 2, n)
            for group, n in zip(mod.RESOLUTION_NOISE[case], (5.0, 10.0)):
                for k, sign in zip(group, (1, -1, 1, -1)):
                    runs.setdefault(k, rec(300.0 + 1e4 * (1 / n) ** 2 + sign * spread, n))
        return dict(runs=runs)

    for case in (1, 10):
        rows = {r["name"]: r for r in mod.resolution_convergence(records(1.0)) if r["case"] == case}
        fc = rows["Fc [N/mm]"]
        assert fc["verdict"] == "order" and abs(fc["p"] - 2.0) < 1e-6 and abs(fc["f0"] - 300.0) < 1e-6
        lo, hi = fc["p_range"]
        assert 1.5 < lo < 2.0 < hi < 2.5 and mod._order_cell(fc) == f"2.0 ({lo:.1f}-{hi:.1f})"
        assert rows["T_RF [K]"]["p"] is None and mod._order_cell(rows["T_RF [K]"]) == "a change inside the scatter"
    noisy = {r["name"]: r for r in mod.resolution_convergence(records(100.0)) if r["case"] == 1}["Fc [N/mm]"]
    assert noisy["verdict"] == "both changes inside the scatter" and noisy["p"] is None and math.isfinite(noisy["z2"])
    one = dict(noisy, z1=-1.5, z2=5.2)                          # one change beyond twice its deviation: no order
    assert mod._verdict(one["f"], *one["sd"], one["z1"], one["z2"]) == "only t_u/10 -> 15 beyond the scatter"
    assert mod._verdict(one["f"], *one["sd"], 3.0, 0.5) == "only t_u/5 -> 10 beyond the scatter"
    missing = [r for r in mod.resolution_convergence(records(1.0, with_fine=False)) if r["name"] == "Fc [N/mm]"]
    assert all(mod._order_cell(r) == "t_u/15 to run" for r in missing)
    assert "| 1 | Fc [N/mm] | 700.0 | 400.0 | 344.4 |" in "\n".join(mod._resolution_lines(records(1.0)))

    def verdict(fine, drop=()):                          # case 1's Fc with t_u/15's run at ``fine``
        res = records(1.0)
        res["runs"]["case 1 n_tu 15"] = rec(fine, 15.0)
        for k in drop:
            del res["runs"][k]
        r = next(r for r in mod.resolution_convergence(res) if r["case"] == 1 and r["name"] == "Fc [N/mm]")
        return mod._order_cell(r)
    assert verdict(500.0) == "not monotone"                # down by 300, then up by 100: beyond the scatter
    assert verdict(200.0) == "no convergence seen"         # 700 -> 400 -> 200: shrinks too slowly for any p > 0
    assert verdict(344.4, drop=("case 1",)) == "t_u/5 or t_u/10 not recorded"
    assert verdict(344.4, drop=mod.SCATTER_T5) == "scatter not measured"


def test_thermal_cutting_sweep_takes_a_failed_case_again_in_the_same_call(tmp_path, monkeypatch, capsys):
    """thermal_cutting.sweep: a case that fails in this call is retried in it (retry_jobs: 'case 16 pfem' with the
    Bossak rule), also one run again by --redo that fails again; a failure recorded before the call and not run in
    it is not, nor one that another sweep on the same file records meanwhile ('case 1 pfem', while 'case 1' runs
    here); the retry's record is stored."""
    import argparse
    mod = _script("thermal_cutting")
    calls = []
    runs = mod.store(tmp_path / "sweep.json")

    def fake_run(key, options, numerics, quick):
        calls.append(key)
        if key == "case 1":                                   # another sweep on the file records a failure
            runs.commit("case 1 pfem", dict(key="case 1 pfem", status="failed: elsewhere", options={}, metrics={}))
        status = "failed: Newton stalled" if key in ("case 16 pfem", "case 17 pfem") else "ok"
        return key, dict(key=key, status=status, options=options, metrics={}, wall_time_s=1.0)

    monkeypatch.setattr(mod.study, "execute", lambda fn, tasks, jobs, scheduler: (fake_run(*a) for a in tasks.values()))
    for k in ("case 17 pfem", "case 12 pfem"):
        runs.commit(k, dict(key=k, status="failed: before", options={}, metrics={}))
    todo = mod.jobs()
    asked = ("case 16 pfem", "case 15 pfem", "case 1", "case 17 pfem")
    args = argparse.Namespace(study=None, redo=("case 17 pfem",), jobs=1, scheduler=None, quick=False)
    ran = mod.sweep(runs, {k: todo[k] for k in asked}, args)
    retries = ["case 16 pfem n_tu 10" + mod.BOSSAK, "case 17 pfem n_tu 10" + mod.BOSSAK]
    assert calls == list(asked) + retries and ran == calls
    rec = runs.records()[retries[0]]
    assert rec["status"] == "ok" and rec["options"]["bossak"] == mod.BOSSAK_ALPHA
    assert "retrying what failed: " + ", ".join(retries) in capsys.readouterr().out


def test_thermal_cutting_reference_update_study_runs_what_its_keys_say():
    """The 'refupdate' study (reference_update_jobs): every key's ref_update_strain is the number in the key, the
    rest of its run the sweep's of the same resolution; the key without 'ref update' in its table is the scene's own
    value (SCENE_REF_UPDATE, read from the scene), and the table's column says which."""
    mod = _script("thermal_cutting")
    from refsph.scenes import get_scene
    assert get_scene("thermal_cutting").setup(case=1, quick=True).numerics.ref_update_strain == mod.SCENE_REF_UPDATE
    todo = mod.reference_update_jobs()
    assert set(todo) <= set(mod.jobs(studies=("refupdate",))) and set(mod.REF_SCATTER) <= set(todo)
    for key, (options, numerics) in todo.items():
        r = float(key.split(mod.REF_KEY)[1].split()[0])
        assert numerics["ref_update_strain"] == r
        n_tu = 5.0 if mod.COARSE in key else mod.N_TU
        more = dict(courant=mod.RETRY_COURANT) if key.endswith(mod.RETRY) else {}
        if key.endswith(f" courant {mod.COURANT:g}"):                  # a t_u/5 failure again at half the step
            more = dict(courant=mod.COURANT)
        assert options["n_tu"] == n_tu and numerics == mod.sweep_numerics(n_tu, ref_update_strain=r, **more)
        assert ("jitter" in key) == ("jitter" in options)
    assert [k for k in mod.REF_RUNS if mod.REF_KEY not in k] == ["case 1 n_tu 5", "case 10 n_tu 5", "case 1", "case 10"]
    runs = json.loads((ROOT / "benchmarks" / "thermal_cutting.json").read_text())["runs"]
    ok = runs["case 1 n_tu 5"]
    res = dict(runs={"case 1 n_tu 5": ok,
                     "case 1 n_tu 5 ref update 0.1": dict(ok, numerics={"ref_update_strain": 0.1})})
    page = "\n".join(mod._study_lines(res))
    assert "| case 1 n_tu 5 | 0.50 |" in page and "| case 1 n_tu 5 ref update 0.1 | 0.10 |" in page


def test_thermal_cutting_frequency_study_is_the_gain_study_with_the_frequency_step():
    """The 'frequency' study: each gain-study run again with frequency_step instead of gain_step (nothing else
    changed), under the same key with FREQ_KEY for GAIN_KEY, and each in the gain table beside its gain run."""
    mod = _script("thermal_cutting")
    todo = {key: (options, numerics) for study, key, options, numerics in mod.more_jobs() if study == "frequency"}
    gain = mod.gain_step_jobs()
    assert len(todo) == len(gain) == 8
    for key, (options, numerics) in gain.items():
        f_options, f_numerics = todo[key.replace(mod.GAIN_KEY, mod.FREQ_KEY)]
        assert f_options == options and numerics.pop("gain_step") is True
        assert f_numerics == dict(numerics, frequency_step=mod.FREQUENCY_STEP)
        assert key in mod.GAIN_RUNS and key.replace(mod.GAIN_KEY, mod.FREQ_KEY) in mod.GAIN_RUNS


def test_thermal_cutting_refined_study_is_the_sweep_at_the_tighter_reference_update():
    """The 'refined' study: the 18 cuts of the t_u/10 table with the same scene options, at reference update
    REF_UPDATE under the frequency step (the scene's courant), case 1's the very run of the 'frequency' study; its
    table lists them in case order."""
    mod = _script("thermal_cutting")
    todo = mod.jobs(studies=("refined",))
    assert list(todo)[:18] == list(mod.REFINED_RUNS) and len(todo) == 20
    for n in (1, 10):                                 # the resolution check: the same at t_u/15
        options, numerics = todo[f"case {n} n_tu 15{mod.REFINED}"]
        base_options, base_numerics = todo[f"case {n}{mod.REFINED}"]
        assert options == dict(base_options, n_tu=15.0) and numerics == base_numerics
    assert all(k in mod.REFINED_RESOLUTION for k in (f"case 1 n_tu 5{mod.REF_KEY}0.1", f"case 10 n_tu 15{mod.REFINED}"))
    sweep = mod.jobs(studies=("cases",))
    for n, key in enumerate(mod.REFINED_RUNS, start=1):
        options, numerics = todo[key]
        assert options == sweep[f"case {n}"][0]
        assert numerics == dict(ref_update_strain=mod.REF_UPDATE, frequency_step=mod.FREQUENCY_STEP)
    assert todo["case 1" + mod.REFINED] == mod.jobs(studies=("frequency",))["case 1" + mod.REFINED]


def test_thermal_cutting_heat_split_at_the_refined_update():
    """The 'contact' study's runs at REF_UPDATE: cases 10 and 1 as their 'refined' runs, with chip_fraction 1 only,
    and in the study's table beside them."""
    mod = _script("thermal_cutting")
    todo, refined = mod.jobs(studies=("contact",)), mod.jobs(studies=("refined",))
    for n in (1, 10):
        key = f"case {n}{mod.REFINED}"
        options, numerics = todo[key + mod.TO_CHIP]
        assert options == dict(refined[key][0], chip_fraction=1.0) and numerics == refined[key][1]
        assert refined[key][0].get("chip_fraction", 0.5) == 0.5
        assert {key, key + mod.TO_CHIP} <= set(next(k for t, k, _ in mod.STUDIES if t.startswith("Contact and heat")))


def test_thermal_cutting_ledger_line_compares_where_the_work_goes():
    """_ledger_line: per material, the mean share of each heat source in the tool's work over the cases both groups
    have recorded ok, and the mean of the per-case ratios of the tool's work; a case recorded in one group only is
    left out."""
    mod = _script("thermal_cutting")
    ok = json.loads((ROOT / "benchmarks" / "thermal_cutting.json").read_text())["runs"]["case 3"]

    def rec(work, plastic, friction, diss):
        return dict(ok, metrics=dict(ok["metrics"], tool_work_J_per_m=work),
                    heat_balance=dict(ok["heat_balance"], plastic_J=plastic, friction_J=friction, dissipation_J=diss))
    runs = {"case 3": rec(100.0, 70.0, 2.0, 20.0), "case 3" + mod.REFINED: rec(80.0, 64.0, 8.0, 4.0),
            "case 2": rec(100.0, 70.0, 4.0, 20.0), "case 2" + mod.REFINED: rec(40.0, 32.0, 2.0, 4.0),
            "case 4": rec(100.0, 10.0, 10.0, 10.0)}         # not in the refined group: left out
    line = mod._ledger_line(dict(runs=runs), mod.REFINED, "")
    # case 3: 80 / 10 / 5 % (70 / 2 / 20), case 2: 80 / 5 / 10 % (70 / 4 / 20); work 0.8 and 0.4: mean 0.6 (the
    # ratio of the means would be 120 / 200 = 0.6 too, so case 2's base work differs below)
    assert "AISI1045 (2 cases): plastic 80.0 % (70.0 %), friction 7.5 % (3.0 %)" in line
    assert "viscosity + contact damping 7.5 % (20.0 %); the tool's work 0.60 of the t_u/10 table's" in line
    runs["case 2"] = rec(50.0, 35.0, 2.0, 10.0)       # the same shares; work ratios 0.8 and 0.8 (means: 120 / 150)
    assert "the tool's work 0.80 of" in mod._ledger_line(dict(runs=runs), mod.REFINED, "")
    assert "Ti6Al4V" not in line
    assert "none recorded yet" in mod._ledger_line(dict(runs={"case 4": runs["case 4"]}), mod.REFINED, "")


def test_thermal_cutting_refuses_to_skip_a_record_made_with_other_numerics(tmp_path):
    """_sweep_round: a key recorded with other scene options or other numerics than its job now asks for is not
    skipped as done, and not run over either: the sweep stops and names it (--redo runs it again)."""
    from types import SimpleNamespace
    mod = _script("thermal_cutting")
    runs = mod.study.RunStore(tmp_path / "tc.json")
    options, numerics = mod.converged(1, n_tu=5.0), dict(ref_update_strain=0.1)
    runs.commit("k", dict(key="k", status="ok", options=options, numerics=numerics, metrics={}))
    args = SimpleNamespace(redo=[], jobs=1, scheduler=None, quick=False)
    for asked in ((options, dict(ref_update_strain=0.5)), (dict(options, n_tu=10.0), numerics)):
        with pytest.raises(SystemExit, match="other scene options or numerics"):
            mod._sweep_round(runs, {"k": asked}, args)
    assert mod._sweep_round(runs, {"k": (options, numerics)}, args) == []          # the same: recorded, skipped


def test_thermal_cutting_dof_figure_is_what_the_code_draws(tmp_path):
    """The 18 cuts' degrees-of-freedom figure is drawn from the page's DOF table (dof_rows of the committed JSON)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    mod = _script("thermal_cutting")
    mod.FIG = tmp_path
    rows = mod.dof_rows(json.loads((ROOT / "benchmarks" / "thermal_cutting.json").read_text()))
    assert {(r["dx"], r["material"]) for r in rows} == {(d, m) for d in ("t_u/5", "t_u/10")
                                                        for m in ("AISI1045", "Ti6Al4V")}
    for r in rows:                                      # the table's DOF: 3 per PFEM node, 2 per SPH particle
        assert r["dof_pfem"] == 3 * r["nodes"] and r["dof_sph"] == 2 * r["particles"]
    mod.dof_figure(rows, plt)
    figure = "11_thermal_cutting_dof.png"
    new, old = matplotlib.image.imread(tmp_path / figure), matplotlib.image.imread(ROOT / "figures" / figure)
    assert new.shape == old.shape and np.abs(new - old).max() < 0.05


def test_thermal_cutting_ceiling_figure_is_what_the_code_draws(tmp_path):
    """The Fp/Fc-T_RF figure is drawn from the committed JSON, and what it shows holds: every measured Fp/Fc lies above
    the rake-face friction ceiling at its measured T_RF and at 15 % below it, for both materials."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    mod = _script("thermal_cutting")
    mod.FIG = tmp_path
    series = mod.ceiling_series(json.loads((ROOT / "benchmarks" / "thermal_cutting.json").read_text()))
    rows = next(iter(series.values()))[0]
    for mat in mod.MATERIAL_NAMES:
        _, _, ceiling = mod._ceiling_law(mat)
        mine = [r for r in rows if r["material"] == mat]
        assert len(mine) == 9
        for f in (1.0, 1.0 - mod.TRF_TARGET):
            assert all(r["ratio_exp"] > ceiling(f * r["TRF_exp"]) for r in mine), (mat, f)
    mod.ceiling_figure(series, plt)
    figure = "11_thermal_cutting_ceiling.png"
    new, old = matplotlib.image.imread(tmp_path / figure), matplotlib.image.imread(ROOT / "figures" / figure)
    assert new.shape == old.shape and np.abs(new - old).max() < 0.05


def test_thermal_cutting_refined_figure_draws_each_recorded_case_of_both_numerics():
    """The 'refined' figure: measured_cuts with REFINED_SERIES draws the t_u/10 table's 18 cases and, for the
    reference update 0.1, exactly the cases recorded ok."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from refsph.teaching.plots import measured_cuts
    mod = _script("thermal_cutting")
    runs = json.loads((ROOT / "benchmarks" / "thermal_cutting.json").read_text())["runs"]
    fig, axes = plt.subplots(3, 1)
    drawn = measured_cuts(axes, runs, mod.REFINED_SERIES)
    plt.close(fig)
    (sweep, _, _, _), (refined, suffix, _, _) = mod.REFINED_SERIES
    assert suffix == mod.REFINED and drawn[sweep] == list(range(1, 19))     # case 9 by its retry
    assert runs["case 9"]["status"] != "ok" and runs["case 9" + mod.RETRY]["status"] == "ok"
    for label, sfx, *_ in mod.REFINED_SERIES:      # the cases the tables take, those recorded ok or retried ok
        assert drawn[label] == [r["case"] for r in mod.comparison(dict(runs=runs), sfx) if r["status"] == "ok"]
    ok, bad = runs["case 3"], dict(runs["case 3"], status="blow-up")
    retry = dict(ok, metrics=dict(ok["metrics"], rake_face_temperature_K=-1.0))    # told apart by T_RF
    for made, want in (({"case 3": ok, "case 3" + mod.RETRY: retry}, [ok]),    # both ok: the run itself
                       ({"case 3" + mod.RETRY: retry}, []),                    # no run: its retry is not drawn
                       ({"case 3": bad, "case 3" + mod.RETRY: retry}, [retry])):   # failed: its retry
        fig, axes = plt.subplots(3, 1)
        drawn = measured_cuts(axes, made, mod.REFINED_SERIES[:1], mod.RETRIES)
        T = [y for line in axes[0].lines if line.get_label() == sweep for y in line.get_ydata()]
        plt.close(fig)
        assert T == [r["metrics"]["rake_face_temperature_K"] for r in want]
        assert [r["case"] for r in mod.comparison(dict(runs=made)) if r["status"] == "ok"] == [3] * len(want)


def test_measured_cuts_takes_the_sweeps_retries():
    """The figure's default retries are the sweep's (a failed case is drawn from the same retry the tables take)."""
    from refsph.teaching.plots import CUT_RETRIES, CUT_SERIES
    mod = _script("thermal_cutting")
    assert CUT_RETRIES == {k: v for k, v in mod.RETRIES.items() if k in CUT_RETRIES}
    assert {s for _, s, *_ in CUT_SERIES + mod.REFINED_SERIES if s in mod.RETRIES} <= set(CUT_RETRIES)


def test_a_case_made_again_by_todays_solver_is_taken_before_its_record():
    """cut_record with ``redone``: the rerun where it ended well (before the record, ok or failed, and its retry),
    else what it took before; the tables' REDONE is the figure's CUT_REDONE; comparison takes the rerun."""
    from refsph.teaching.plots import CUT_REDONE, cut_record
    mod = _script("thermal_cutting")
    assert CUT_REDONE == mod.REDONE
    ok, bad = dict(status="ok"), dict(status="failed")
    runs = {"case 2 pfem": ok, "case 2 pfem rerun": dict(status="ok", tag=1), "case 3 pfem": bad,
            "case 3 pfem n_tu 10 bossak -0.1": ok, "case 3 pfem rerun": bad}
    assert cut_record(runs, "case 2 pfem", (), (" rerun",)) == ("case 2 pfem rerun", runs["case 2 pfem rerun"])
    assert cut_record(runs, "case 2 pfem") == ("case 2 pfem", ok)
    bossak = " n_tu 10 bossak -0.1"
    assert cut_record(runs, "case 3 pfem", (bossak,), (" rerun",))[0] == "case 3 pfem" + bossak   # its rerun failed
    runs.update({"case 6 pfem": dict(status="ok", tag=6), "case 6 pfem rerun": bad})   # an ok record, a failed rerun
    assert cut_record(runs, "case 6 pfem", (bossak,), (" rerun",)) == ("case 6 pfem", runs["case 6 pfem"])
    runs["case 6 pfem" + bossak] = dict(status="ok", tag=7)                            # ... then its retry: taken
    retried = ("case 6 pfem" + bossak, runs["case 6 pfem" + bossak])
    assert cut_record(runs, "case 6 pfem", (bossak,), (" rerun",)) == retried
    assert cut_record(runs, "case 6 pfem", (bossak,)) == ("case 6 pfem", runs["case 6 pfem"])   # no redone asked
    assert "case 6 pfem" + bossak in mod.retry_jobs({"case 6 pfem": ok, "case 6 pfem rerun": bad})
    assert "case 6 pfem" + bossak not in mod.retry_jobs({"case 6 pfem": ok, "case 6 pfem rerun": ok})
    rec = _resolution_record(420.0, 10)
    rows = mod.comparison(dict(runs={"case 2 pfem": _resolution_record(400.0, 10), "case 2 pfem rerun": rec}),
                          mod.PFEM10)
    assert rows[1]["key"] == "case 2 pfem rerun" and rows[1]["Fc_N_per_mm"] == pytest.approx(420.0)


def test_dof_changes_counts_the_moves_between_resolutions():
    mod = _script("thermal_cutting")
    base = {f"{q}_{m}": 10.0 for q, _ in mod.DOF_QUANTITIES for m in ("pfem", "sph")}
    fine = dict(base, TRF_pfem=12.5, ratio_sph=4.0, TFCS_sph=float("nan"))
    rows = [dict(base, dx="t_u/5", material="AISI1045"), dict(fine, dx="t_u/10", material="AISI1045")]
    assert mod.dof_changes(rows) == dict(n=5, fall=1, rise=1, lo="-6.0", hi="+2.5")


def test_thermal_cutting_scatter_and_mass_scale_at_the_refined_update():
    """Case 10's scatter at REF_UPDATE: the 'refined' run's options with the seeds of SCATTER_TI10's jitter, and the
    same three at half the mass scale, all at REFINED_NUMERICS; each group compared with the group at the scene's
    update or at s (COMPARED), the t_u/15 check and the heat split read against it (SINGLES)."""
    mod = _script("thermal_cutting")
    todo, refined = mod.jobs(studies=("scatter", "scaling")), mod.jobs(studies=("refined",))
    base_options, base_numerics = refined[f"case 10{mod.REFINED}"]
    sweep_jitter = mod.jobs(studies=("scatter",))
    for key, key_s2 in zip(mod.SCATTER_TI10_REF, mod.SCATTER_TI10_REF_S2):
        options, numerics = refined[key] if key in refined else todo[key]
        options_s2, numerics_s2 = todo[key_s2]
        assert numerics == numerics_s2 == base_numerics
        assert {k: v for k, v in options.items() if k not in ("jitter", "seed")} == base_options
        assert options_s2 == dict(options, mass_scale=base_options.get("mass_scale", mod._s(10)) / 2)
        if key != f"case 10{mod.REFINED}":
            old = sweep_jitter[key.replace(mod.REFINED, "")][0]
            assert (options["jitter"], options["seed"]) == (old["jitter"], old["seed"])
    assert mod.COMPARED[mod.SCATTER_TI10_REF] == mod.SCATTER_TI10
    assert mod.COMPARED[mod.SCATTER_TI10_REF_S2] == mod.SCATTER_TI10_REF
    assert f"case 10 n_tu 15{mod.REFINED}" in mod.SINGLES[mod.SCATTER_TI10_REF]
    steel, steel_s2 = refined[f"case 1{mod.REFINED}"], todo[f"case 1 s/2{mod.REFINED}"]   # steel's, one run at s/2
    assert steel_s2 == (dict(steel[0], mass_scale=mod._s(1) / 2), steel[1])
    assert f"case 1 s/2{mod.REFINED}" in mod.SINGLES[mod.SCATTER_REF]
    tables = [k for _, k, _ in mod.STUDIES]
    assert mod.SCATTER_TI10_REF in tables and mod.SCATTER_TI10_REF_S2 in tables


def test_thermal_cutting_refined_resolution_reads_the_scatter_at_its_update():
    """The resolution check at REF_UPDATE reads its own runs and scatter groups (REFINED_NOISE: case 10's t_u/10
    group the one measured at REF_UPDATE, not SCATTER_TI10): Fc = 300 + C dx^2 with a scatter of 1 N/mm there gives
    the order 2 even where the groups at the scene's 0.5 spread by 100; the page's table has the section's prose."""
    mod = _script("thermal_cutting")
    assert mod.REFINED_NOISE == {1: (mod.REF_SCATTER, mod.SCATTER_REF), 10: (mod.REF_SCATTER_TI, mod.SCATTER_TI10_REF)}

    rec = _resolution_record
    runs = {}
    for group in (mod.SCATTER_TI10, mod.SCATTER_KEYS):           # the scene's 0.5: a large spread
        for k, sign in zip(group, (1, -1, 1, -1)):
            runs[k] = rec(300.0 + 1e4 / 100 + sign * 100.0, 10.0)
    runs[mod.SCATTER_REF[2]] = rec(300.0 + 1e4 / 100 + 100.0, 10.0)   # case 1 at 0.1: one jittered run far off
    for case, keys in mod.REFINED_RESOLUTION_KEYS.items():
        for key, n in zip(keys, mod.RESOLUTION_N):
            runs[key] = rec(300.0 + 1e4 * (1 / n) ** 2, n)
        for group, n in zip(mod.REFINED_NOISE[case], (5.0, 10.0)):
            for k, sign in zip(group, (1, -1, 1, -1)):
                runs.setdefault(k, rec(300.0 + 1e4 * (1 / n) ** 2 + sign * 1.0, n))
    res = dict(runs=runs)
    rows = {(r["case"], r["name"]): r for r in mod.resolution_convergence(res, mod.REFINED_RESOLUTION_KEYS,
                                                                          mod.REFINED_NOISE)}
    assert rows[(10, "Fc [N/mm]")]["verdict"] == "order" and abs(rows[(10, "Fc [N/mm]")]["p"] - 2.0) < 1e-6
    assert rows[(1, "Fc [N/mm]")]["verdict"] != "order"          # case 1's t_u/10 scatter at 0.1 is wide
    assert rows[(10, "Fc [N/mm]")]["f"] == [700.0, 400.0, 300.0 + 1e4 / 225]
    text = "\n".join(mod._resolution_lines(res, mod.REFINED_RESOLUTION_KEYS, mod.REFINED_NOISE, "refined_orders"))
    assert "The same reading at ref update 0.1" in text and "| 10 | Fc [N/mm] | 700.0 | 400.0 | 344.4 |" in text


def test_thermal_cutting_rake_gap_is_the_rake_face_less_the_free_surface():
    """rake_gaps: T_RF - T_FCS per case for the measurement, the paper's two methods and each of refsph's groups
    (None where a case is not recorded); the table's mean per material is over the cases every column has."""
    mod = _script("thermal_cutting")
    rows = [dict(case=n, material="AISI1045" if n < 10 else "Ti6Al4V", TRF_exp=700.0 + n, TFCS_exp=600.0,
                 TRF_sph=800.0, TFCS_sph=650.0, TRF_pfem=900.0, TFCS_pfem=640.0, TRF=750.0 + 10 * n, TFCS=600.0)
            for n in range(1, 19)]
    other = [dict(r, TRF=None) if r["case"] == 2 else dict(r, TRF=1000.0) for r in rows]
    gaps = mod.rake_gaps(rows, {"a": rows, "b": other})
    assert gaps[0]["gap"] == {"measured": 101.0, "paper SPH": 150.0, "paper PFEM": 260.0, "a": 160.0, "b": 400.0}
    assert gaps[1]["gap"]["b"] is None and gaps[1]["gap"]["a"] == 170.0
    assert mod.rake_gaps(rows[:1], {"c": [dict(rows[0], TFCS=float("nan"))]})[0]["gap"]["c"] is None
    lines = mod._rake_gap_lines(gaps)
    steel = next(x for x in lines if x.startswith("| mean") and "AISI1045" in x)
    # cases 1 and 3-9 (case 2 lacks 'b'): mean n = 5.375, so measured 105.4, 'a' 150 + 10 mean n = 203.75
    assert steel == "| mean (8 cases) | AISI1045 | 105 | 150 | 260 | 204 | 400 |"
    assert "| 2 | AISI1045 | 102 | 150 | 260 | 170 | - |" in lines


def test_thermal_cutting_gap_study_changes_one_option_of_the_refupdate_runs():
    """The 'gap' study: cases 10 and 1 at t_u/5 and REF_UPDATE as the 'refupdate' study's runs, each with one scene
    option changed (friction off; the numerical dissipation's heat left out), in its table beside them; _values'
    gap is T_RF - T_FCS."""
    mod = _script("thermal_cutting")
    gap, base = mod.jobs(studies=("gap",)), mod.jobs(studies=("refupdate",))
    jitter = {k: gap.pop(k) for k in mod.REF_SCATTER_TI[1:]}           # case 10's scatter at t_u/5 and REF_UPDATE
    for key, seed in zip(mod.REF_SCATTER_TI[1:], (1, 2)):
        case1 = base[key.replace("case 10 ", "case 1 ", 1)]
        assert jitter[key] == (dict(base[mod.REF_SCATTER_TI[0]][0], jitter=0.01, seed=seed), case1[1])
        assert case1[0]["seed"] == seed
    for n in (10, 1):                                                   # and at t_u/10, where it scatters less
        refined = mod.jobs(studies=("refined",))[f"case {n}{mod.REFINED}"]
        assert gap.pop(f"case {n}{mod.REFINED} friction without heat") == (dict(refined[0], eta=0.0), refined[1])
    for n in (1, 10):                                                   # the same split in the PFEM
        pfem = mod.jobs(studies=("pfem",))[f"case {n} pfem"]
        assert gap.pop(f"case {n} pfem friction without heat") == (dict(pfem[0], eta=0.0), pfem[1])
    assert len(gap) == 2 * len(mod.GAP_CHANGES)
    for n in (10, 1):
        b_opts, b_num = base[f"case {n} n_tu 5{mod.REF_KEY}0.1"]
        for sfx, change in mod.GAP_CHANGES:
            opts, num = gap[f"case {n} n_tu 5{mod.REF_KEY}0.1{sfx}"]
            assert opts == dict(b_opts, **change) and num == b_num and len(change) == 1
    assert set(gap) | {f"case {n} n_tu 5{mod.REF_KEY}0.1" for n in (10, 1)} == set(mod.GAP_RUNS)
    assert mod.GAP_RUNS in [k for _, k, _ in mod.STUDIES]
    rec = _resolution_record(300.0, 5.0)
    assert mod._values(rec)["gap"] == 100.0


def test_thermal_cutting_every_key_the_page_reads_is_a_run_the_sweep_makes():
    """Every key of the page's study tables, its group comparisons (COMPARED, SINGLES, TABLE_SINGLES) and the
    resolution checks' scatter groups is a run that jobs() makes, or the retry of one (retry_jobs, asked as if every
    run had failed): a misspelt key would show 'to run' forever."""
    mod = _script("thermal_cutting")
    made = set(mod.jobs())
    failed = {k: dict(status="blow-up") for k in made}
    made |= set(mod.retry_jobs(failed))
    read = {k for _, keys, _ in mod.STUDIES for k in keys}
    for group, other in mod.COMPARED.items():
        read |= set(group) | set(other)
    read |= {k for group, singles in mod.SINGLES.items() for k in (*group, *singles)}
    read |= {k for pairs in mod.TABLE_SINGLES.values() for group, singles in pairs for k in (*group, *singles)}
    for noise in (mod.RESOLUTION_NOISE, mod.REFINED_NOISE):
        read |= {k for groups in noise.values() for g in groups for k in g}
    read |= {k for keys in mod.REFINED_RESOLUTION_KEYS.values() for k in keys}
    assert not sorted(read - made)


def test_thermal_cutting_force_slopes_separate_the_growing_thrust_from_the_intercept():
    """force_slopes: forces exactly linear in t_u (Fc = 100 + 2000 t_u, Fp = 50 + 600 t_u) give the slope ratio 0.3
    and the thinnest cut's Fp/Fc 110 / 300 as 50 / 300 + 60 / 300; a scatter of Fp alone gives the sd of p / c as
    the least-squares slope's over c, one of Fc alone as p / c^2 times the slope's; the two parts add up to the thin
    cut's own Fp/Fc where the line is not straight; a line that lacks a cut has no fit; the summary counts each
    material's lines above Merchant's ceiling at mu0."""
    mod = _script("thermal_cutting")
    rows = [dict(material=m, vc=v, tu=t, TRF_exp=700.0, Fc=100 + 2000 * t, Fp=50 + 600 * t)
            for m in mod.MATERIAL_NAMES for v in (60.0, 120.0) for t in (0.10, 0.15, 0.20)]
    steep = [dict(r, Fp=0.9 * r["Fc"]) for r in rows]                       # p / c = 0.9: above either ceiling
    gap = [dict(r, Fp=None) if r["vc"] == 120.0 and r["tu"] == 0.15 else r for r in rows]
    bent = [dict(r, Fp=r["Fp"] + (6.0 if r["tu"] == 0.15 else -3.0)) for r in rows]    # the same fit, not straight
    slopes = mod.force_slopes({"a": (rows, "Fc", "Fp"), "b": (steep, "Fc", "Fp"), "c": (gap, "Fc", "Fp"),
                               "d": (bent, "Fc", "Fp")},
                              {("a", "AISI1045"): (0.0, 10.0), ("b", "AISI1045"): (10.0, 0.0)})
    assert [(s["material"], s["vc"]) for s in slopes] == [(m, v) for m in mod.MATERIAL_NAMES for v in (60.0, 120.0)]
    first = slopes[0]["fits"]
    assert first["a"][0] == pytest.approx(0.3, rel=1e-9)
    assert first["a"][2:] == pytest.approx((50 / 300, 60 / 300), rel=1e-9)
    w = np.array([-10.0, 0.0, 10.0])                                   # (t - mean) / sum((t - mean)^2), 1/mm
    fp = 50 + 600 * np.array([0.10, 0.15, 0.20])
    assert first["a"][1] == pytest.approx(np.sqrt(np.sum((w * 0.1 * fp) ** 2)) / 2000.0, rel=1e-9)
    fc = 100 + 2000 * np.array([0.10, 0.15, 0.20])
    assert first["b"][1] == pytest.approx(0.9 / 2000.0 * np.sqrt(np.sum((w * 0.1 * fc) ** 2)), rel=1e-9)
    assert first["d"][0] == pytest.approx(0.3, rel=1e-9) and first["d"][2] == pytest.approx(50 / 300, rel=1e-9)
    assert first["d"][2] + first["d"][3] == pytest.approx((110 - 3) / 300, rel=1e-9)   # the cut's own Fp/Fc
    assert slopes[2]["fits"]["a"][1] is None                                          # no scatter for Ti6Al4V
    assert slopes[1]["fits"]["c"] is None and slopes[0]["fits"]["c"] is not None
    steel, titanium = mod._slope_lines(slopes)[-2:]
    assert steel.startswith("\nAISI1045") and titanium.startswith("\nTi6Al4V")
    assert "b 0.90 (0.30 + 0.60), 2 of 2" in steel and "a 0.30 (0.17 + 0.20), 0 of 2" in steel
    assert "c 0.30 (0.17 + 0.20), 0 of 1" in steel and "b 0.90 (0.30 + 0.60), 2 of 2" in titanium


def test_thermal_cutting_ratio_part_errors_tell_which_part_of_the_thrust_is_missed():
    """ratio_part_errors: a prediction with the measured slope and a smaller intercept (Fp = 20 + 600 t_u against
    50 + 600 t_u, the same Fc) misses only the intercept: with the measured intercept its error is 0, with the
    measured growing part it stays the full error, mean(30 / Fp_measured)."""
    mod = _script("thermal_cutting")
    meas = [dict(case=3 * i + j + 1, material="AISI1045", vc=v, tu=t, Fc=100 + 2000 * t, Fp=50 + 600 * t)
            for i, v in enumerate((60.0, 120.0)) for j, t in enumerate((0.10, 0.15, 0.20))]
    low = [dict(r, Fp=r["Fp"] - 30.0) for r in meas]
    got = mod.ratio_part_errors({"measured": (meas, "Fc", "Fp"), "low": (low, "Fc", "Fp")})
    n, full, with_intercept, with_growing = got[("AISI1045", "low")]
    assert n == 6 and list(got) == [("AISI1045", "low")]
    assert full == pytest.approx(100 * np.mean([30.0 / r["Fp"] for r in meas]), rel=1e-9)
    assert with_intercept == pytest.approx(0.0, abs=1e-9) and with_growing == pytest.approx(full, rel=1e-9)
    low[4]["Fp"] = None                                        # the 120 m/min line incomplete: its three cases out
    got = mod.ratio_part_errors({"measured": (meas, "Fc", "Fp"), "low": (low, "Fc", "Fp")})
    assert got[("AISI1045", "low")][0] == 3
