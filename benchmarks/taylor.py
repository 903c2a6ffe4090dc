"""Taylor impact benchmark (Section 3.1 of Islam, Bansal & Peng): every Taylor number and figure of refsph.

    python benchmarks/taylor.py                 # all runs (about 35 CPU-minutes; --jobs 2 halves the wall time)
    python benchmarks/taylor.py --plot-only     # figures and table again from runs/benchmarks/taylor/
    python benchmarks/taylor.py --report        # benchmarks/taylor_report.md from the committed taylor.json only

Runs (3D quarter model, both methods):
  convergence  dp = 1.0, 0.75, 0.5 mm, CFL time step (Courant 0.3)
  tmelt        dp = 0.5 mm with T_melt = 1793 K (Table 1 prints 1293 K)
  fixed_dt     dp = 0.5 mm with the paper's fixed dt = 1e-8 s
  sensitivity  dp = 0.75 mm: artificial viscosity beta = 0.5 (both), TLSPH reference update at |E| > 0.1,
               ESPH without artificial pressure
Writes benchmarks/taylor.json (one record per run: method, dp, dt mode, T_melt, final length and diameter,
rest time, peaks, wall time, particle count, steps) and the figures
  figures/06_taylor_work_precision.png   error against wall time (the work-precision plot)
  figures/06_taylor_length_history.png   length against time (cf. the paper's Fig. 3)
  figures/06_taylor_sections.png         plastic strain and temperature on the section at 15 and 30 us (Figs. 4-5)
  benchmarks/taylor_report.md            (--report) the study as a report, every table number from taylor.json
Wall times are single-core (each run is a fresh process, study.execute); with --jobs 2 two runs share the machine's
two cores. A rerun merges the records of the finished runs in the run folders there into the committed taylor.json
(study.merge_records): a run folder missing in a fresh clone drops no record, a failed or unfinished run gives none
(the committed record stays); a file whose content (a figure: its pixels) did not change is not written.
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
RUNS = ROOT / "runs" / "benchmarks" / "taylor"
OUT_JSON = ROOT / "benchmarks" / "taylor.json"
REPORT = ROOT / "benchmarks" / "taylor_report.md"
FIG = ROOT / "figures"
METHODS = ("esph", "tlsph")


def job_list(finest: float | None):
    jobs = []
    dps = [1.0e-3, 0.75e-3, 0.5e-3] + ([finest] if finest else [])
    for dp in dps:
        for m in METHODS:
            jobs.append(dict(name=f"conv-{m}-{dp * 1e3:g}mm", method=m, dp=dp, dt=None, T_melt=1293.0))
    for m in METHODS:
        jobs.append(dict(name=f"tmelt1793-{m}-0.5mm", method=m, dp=0.5e-3, dt=None, T_melt=1793.0))
        jobs.append(dict(name=f"dt1e-8-{m}-0.5mm", method=m, dp=0.5e-3, dt=1e-8, T_melt=1293.0))
    # sensitivity to numerical choices the paper fixes or leaves open, at dp = 0.75 mm (compare conv-*-0.75mm)
    for m in METHODS:
        jobs.append(dict(name=f"sens-beta0.5-{m}-0.75mm", method=m, dp=0.75e-3, dt=None, T_melt=1293.0,
                         numerics=dict(beta1=0.5, beta2=0.5)))
    jobs.append(dict(name="sens-refupdate0.1-tlsph-0.75mm", method="tlsph", dp=0.75e-3, dt=None, T_melt=1293.0,
                     numerics=dict(ref_update_strain=0.1)))
    jobs.append(dict(name="sens-gamma0-esph-0.75mm", method="esph", dp=0.75e-3, dt=None, T_melt=1293.0,
                     numerics=dict(gamma=0.0)))
    return jobs


def run_job(job):
    from refsph.simulate import run
    t0 = time.perf_counter()
    res = run("taylor", job["method"], dim=3, dp=job["dp"], dt=job["dt"], out=RUNS / job["name"], progress=False,
              options=dict(T_melt=job["T_melt"]), numerics=dict(job.get("numerics") or {}, threads=job["threads"]))
    s = res.summary
    print(f"{job['name']}: {time.perf_counter() - t0:.0f} s, L = {s['metrics']['final_length_mm']:.2f} mm, "
          f"D = {s['metrics']['final_diameter_mm']:.2f} mm", flush=True)
    return job["name"]


def record(name):
    with open(RUNS / name / "summary.json") as f:
        s = json.load(f)
    m = s["metrics"]
    return dict(name=name, method=s["method"], dp_mm=1e3 * s["dp"], dt_mode=s["dt_mode"],
                dt_s=s["dt_max"] if s["dt_mode"] == "fixed" else None, courant=s["courant"], T_melt_K=m["T_melt_K"],
                final_length_mm=m["final_length_mm"], final_diameter_mm=m["final_diameter_mm"],
                length_oscillation_mm=m["length_oscillation_mm"], rest_time_us=1e6 * m["rest_time_s"],
                end_time_us=1e6 * m["end_time_s"], max_plastic_strain=m["max_plastic_strain"],
                max_temperature_K=m["max_temperature_K"], wall_time_s=s["wall_time_s"],
                n_particles=s["n_particles"], n_ghosts=s["diagnostics"].get("n_ghosts"), n_steps=s["n_steps"],
                numerics=dict(beta1=s["numerics"]["beta1"], beta2=s["numerics"]["beta2"], gamma=s["numerics"]["gamma"],
                              ref_update_strain=s["numerics"]["ref_update_strain"]),
                diagnostics=s["diagnostics"])


def plots(records, json_only: bool = False):
    """The benchmark's figures; ``json_only``: only those drawn from the records alone (the work-precision plot)."""
    import matplotlib
    matplotlib.use("Agg")
    FIG.mkdir(exist_ok=True)
    _plot_work_precision(records)
    if json_only:                                       # the rest needs the run folders
        return
    # from the run folders: only where every run a figure shows has its folder (a partial rerun in a fresh clone
    # keeps the committed figure)
    history = [r["name"] for r in records if r["dp_mm"] == 0.5 and r["name"].startswith(("conv-", "dt1e-8-"))]
    for figure, names, draw in (("06_taylor_length_history.png", history, lambda: _plot_length_history(records)),
                                ("06_taylor_sections.png", [f"conv-{m}-0.5mm" for m in METHODS], _plot_sections)):
        missing = [n for n in names if not (RUNS / n / "summary.json").exists()]
        if missing:
            print(f"{figure} not redrawn: it needs the run folders of {', '.join(missing)}")
        else:
            draw()


COLORS = dict(esph="C0", tlsph="C3")


def _plot_work_precision(records):
    """Error against wall time."""
    import matplotlib.pyplot as plt
    from refsph.paper_data import TAYLOR_RESULTS
    Lexp = TAYLOR_RESULTS["final_length_mm"]["experiment"]
    Dexp = TAYLOR_RESULTS["final_diameter_mm"]["experiment"]
    conv = [r for r in records if r["name"].startswith("conv-")]
    colors = COLORS
    fig, axs = plt.subplots(1, 2, figsize=(10, 4))
    for ax, key, ref, label in ((axs[0], "final_length_mm", Lexp, "length"),
                                (axs[1], "final_diameter_mm", Dexp, "diameter")):
        for m in METHODS:
            rs = sorted([r for r in conv if r["method"] == m], key=lambda r: -r["dp_mm"])
            w = [r["wall_time_s"] for r in rs]
            e = [100 * abs(r[key] - ref) / ref for r in rs]
            ax.loglog(w, e, "o-", color=colors[m], label=m.upper())
            for r, wi, ei in zip(rs, w, e):
                ax.annotate(f"{r['dp_mm']:g} mm", (wi, ei), textcoords="offset points", xytext=(4, 4), fontsize=8)
        styles = {"paper_esph": ("C0", "paper ESPH"), "paper_tlsph": ("C3", "paper TLSPH"),
                  "ls_dyna": ("gray", "LS-DYNA")}
        for k, (c, lab) in styles.items():
            ax.axhline(100 * abs(TAYLOR_RESULTS[key][k] - ref) / ref, ls=":", color=c, lw=1, label=lab)
        ax.axhline(2.0 if key == "final_length_mm" else 5.0, color="k", lw=0.8, ls="--", label="issue target")
        ax.set_xlabel("wall time [s] (one core)")
        ax.set_ylabel(f"|{label} - experiment| / experiment [%]")
        ax.set_title(f"Taylor bar, 3D quarter model: final {label}")
        ax.legend(fontsize=7)
    fig.tight_layout()
    study.save_figure(fig, FIG / "06_taylor_work_precision.png", dpi=120)


def _plot_length_history(records):
    """Length against time (Fig. 3)."""
    import matplotlib.pyplot as plt
    from refsph.io import load_run
    from refsph.paper_data import TAYLOR_RESULTS
    Lexp, colors = TAYLOR_RESULTS["final_length_mm"]["experiment"], COLORS
    fig, ax = plt.subplots(figsize=(6, 4))
    for r in records:
        if r["dp_mm"] != 0.5 or not r["name"].startswith(("conv-", "dt1e-8-")):
            continue
        s, _ = load_run(RUNS / r["name"])
        h = np.asarray(s["metrics"]["length_history"])
        ls = "-" if r["dt_mode"] == "cfl" else "--"
        ax.plot(1e6 * h[:, 0], 1e3 * h[:, 1], ls, color=colors[r["method"]],
                label=f"{r['method'].upper()} ({'CFL' if r['dt_mode'] == 'cfl' else 'dt = 1e-8 s'})")
    ax.axhline(Lexp, color="k", ls=":", label="experiment (final)")
    ax.axhline(TAYLOR_RESULTS["final_length_mm"]["ls_dyna"], color="gray", ls="-.", label="LS-DYNA (final)")
    ax.set_xlabel("t [us]")
    ax.set_ylabel("length [mm]")
    ax.set_title("Taylor bar length, dp = 0.5 mm (cf. Fig. 3)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    study.save_figure(fig, FIG / "06_taylor_length_history.png", dpi=120)


def _plot_sections():
    """Sections at 15 and 30 us (Figs. 4-5): the particles next to the symmetry plane y = 0, mirrored to x < 0."""
    import matplotlib.pyplot as plt
    from refsph.io import load_run, load_snapshot
    fig, axs = plt.subplots(2, 4, figsize=(12, 7), sharey=True)
    for col, (m, tt) in enumerate([(m, tt) for m in METHODS for tt in (15e-6, 30e-6)]):
        _, snaps = load_run(RUNS / f"conv-{m}-0.5mm")
        snap = min((load_snapshot(p) for p in snaps), key=lambda z: abs(z["t"] - tt))
        x = snap["x"]
        sec = np.abs(x[:, 1]) < 0.5e-3                      # the first layer of particles off the plane y = 0
        xs, zs = np.concatenate([x[sec, 0], -x[sec, 0]]), np.concatenate([x[sec, 2], x[sec, 2]])
        # the committed figure was drawn with jet; the next rerun of the benchmark should use viridis / inferno
        for row, (key, label, vmax) in enumerate((("eps_p", "effective plastic strain", None),
                                                  ("T", "temperature [K]", None))):
            val = np.concatenate([snap[key][sec], snap[key][sec]])
            ax = axs[row, col]
            sc = ax.scatter(1e3 * xs, 1e3 * zs, c=val, s=9, cmap="jet", vmin=0 if key == "eps_p" else 293.0)
            ax.set_aspect("equal")
            ax.set_xlim(-7, 7)
            ax.set_ylim(0, 16)
            ax.set_title(f"{m.upper()}, t = {1e6 * snap['t']:.0f} us", fontsize=9)
            fig.colorbar(sc, ax=ax, shrink=0.7, label=label)
            ax.set_xlabel("x [mm]")
    axs[0, 0].set_ylabel("z [mm]")
    axs[1, 0].set_ylabel("z [mm]")
    fig.suptitle("Taylor bar, section through the axis (lower 16 mm), dp = 0.5 mm (cf. Figs. 4-5)")
    fig.tight_layout()
    study.save_figure(fig, FIG / "06_taylor_sections.png", dpi=120)


def table(records) -> str:
    lines = [f"{'run':24s} {'dp':>5s} {'dt':>8s} {'T_m':>5s} {'L [mm]':>7s} {'D [mm]':>7s} {'rest us':>7s} "
             f"{'eps_p':>5s} {'T K':>5s} {'wall s':>7s} {'N':>6s} {'steps':>6s}"]
    for r in records:
        lines.append(f"{r['name']:24s} {r['dp_mm']:5.3g} {('%.0e' % r['dt_s']) if r['dt_s'] else 'CFL':>8s} "
                     f"{r['T_melt_K']:5.0f} {r['final_length_mm']:7.2f} {r['final_diameter_mm']:7.2f} "
                     f"{r['rest_time_us']:7.1f} {r['max_plastic_strain']:5.2f} {r['max_temperature_K']:5.0f} "
                     f"{r['wall_time_s']:7.0f} {r['n_particles']:6d} {r['n_steps']:6d}")
    lines.append("experiment 34.6 / 9.5 mm; LS-DYNA 34.4 / 10.6; paper ESPH 34.19 / 9.80; paper TLSPH 34.18 / 9.83")
    return "\n".join(lines)


PAGE = "taylor_report"          # the page's prose: benchmarks/templates/taylor_report.md


def _errors():
    """(error of L, error of D) against the experiment [%], as functions of a record."""
    from refsph.paper_data import TAYLOR_RESULTS as REF
    Lx, Dx = REF["final_length_mm"]["experiment"], REF["final_diameter_mm"]["experiment"]
    return (lambda r: 100 * (r["final_length_mm"] / Lx - 1)), (lambda r: 100 * (r["final_diameter_mm"] / Dx - 1))


def _run_table(rows) -> list[str]:
    eL, eD = _errors()
    lines = ["| run | method | dp [mm] | dt | T_m [K] | L [mm] | L vs exp. | D [mm] | D vs exp. "
             "| L oscillation [mm] | at rest from [µs] | max plastic strain | max T [K] |", "|---" * 13 + "|"]
    for r in rows:
        dt = f"{r['dt_s']:.0e} s" if r.get("dt_s") else "CFL"
        lines.append(f"| `{r['name']}` | {r['method'].upper()} | {r['dp_mm']:g} | {dt} | {r['T_melt_K']:.0f} | "
                     f"{r['final_length_mm']:.2f} | {eL(r):+.1f} % | {r['final_diameter_mm']:.2f} | "
                     f"{eD(r):+.1f} % | {r['length_oscillation_mm']:.3f} | {r['rest_time_us']:.1f} | "
                     f"{r['max_plastic_strain']:.2f} | {r['max_temperature_K']:.0f} |")
    return lines


def report(records) -> str:
    """The study as a markdown report, from the benchmark records only (taylor.json): nothing is run or redrawn.
    The reference values (experiment, LS-DYNA, the paper's SPH) are the paper's, from refsph.paper_data; the prose
    is benchmarks/templates/taylor_report.md."""
    P = study.Page(PAGE)
    conv = sorted([r for r in records if r["name"].startswith("conv-")], key=lambda r: (r["method"], -r["dp_mm"]))
    out = _report_head(P, conv[0]) + ["", P("convergence"), ""] + _run_table(conv) + [""]
    out += _report_convergence(P, conv)
    out += _report_variants(P, {r["name"]: r for r in records})
    out += _report_sensitivity(P, records)
    out += _report_cost(P, records, conv) + ["", P("figures")]
    return "\n".join(out) + "\n"


def _report_head(P, first) -> list[str]:
    from refsph.paper_data import TAYLOR_RESULTS as REF
    nm = first["numerics"]
    out = P.lines("head", end_us=f"{first['end_time_us']:.0f}", courant=f"{first['courant']:g}",
                  T_melt=f"{first['T_melt_K']:.0f}", beta1=f"{nm['beta1']:g}", beta2=f"{nm['beta2']:g}",
                  gamma=f"{nm['gamma']:g}", ref_update=f"{nm['ref_update_strain']:g}")
    out += ["", "| | experiment | LS-DYNA | paper ESPH | paper TLSPH |", "|---|---|---|---|---|"]
    for key, label in (("final_length_mm", "final length [mm]"), ("final_diameter_mm", "final diameter [mm]")):
        out.append(f"| {label} | " + " | ".join(f"{REF[key][k]:.2f}" for k in
                                                 ("experiment", "ls_dyna", "paper_esph", "paper_tlsph")) + " |")
    return out


def _report_convergence(P, conv) -> list[str]:
    from refsph.paper_data import TAYLOR_RESULTS as REF
    eL, eD = _errors()
    out = []
    for m in METHODS:
        rs = [r for r in conv if r["method"] == m]
        a, b = rs[0], rs[-1]
        errD = [abs(eD(r)) for r in rs]
        trend = ("falls at every refinement" if all(x > y for x, y in zip(errD, errD[1:]))
                 else "does not fall steadily")
        out.append(P("convergence_of_method", method=m.upper(), dp_a=f"{a['dp_mm']:g}", dp_b=f"{b['dp_mm']:g}",
                     dL=f"{b['final_length_mm'] - a['final_length_mm']:+.2f}",
                     dD=f"{b['final_diameter_mm'] - a['final_diameter_mm']:+.2f}", trend=trend,
                     err_a=f"{errD[0]:.1f}", err_b=f"{errD[-1]:.1f}", errL_min=f"{min(abs(eL(r)) for r in rs):.1f}",
                     errL_max=f"{max(abs(eL(r)) for r in rs):.1f}"))
    out += ["", P("targets"), ""]
    for r in conv:
        if r["dp_mm"] <= 0.5:
            out.append(P("target", method=r["method"].upper(), dp=f"{r['dp_mm']:g}", eL=f"{eL(r):+.1f}",
                         L_met="met" if abs(eL(r)) < 2 else "missed", eD=f"{eD(r):+.1f}",
                         D_met="met" if abs(eD(r)) < 5 else "missed"))
    pE, pT = (REF["final_diameter_mm"][k] for k in ("paper_esph", "paper_tlsph"))
    fine = {m: [r for r in conv if r["method"] == m][-1] for m in METHODS}
    gap = 100 * (fine["esph"]["final_diameter_mm"] / fine["tlsph"]["final_diameter_mm"] - 1)
    return out + ["", P("convergence_end", paper_gap=f"{100 * abs(pT / pE - 1):.1f}", gap=f"{gap:.1f}")]


def _report_variants(P, by) -> list[str]:
    """The melting temperature and the time step: each against the default run of its method at 0.5 mm."""
    out = []
    for prefix in ("tmelt1793-", "dt1e-8-"):
        rows, notes = [], []
        for m in METHODS:
            base, other = by.get(f"conv-{m}-0.5mm"), by.get(f"{prefix}{m}-0.5mm")
            if base is None or other is None:
                continue
            rows += [base, other]
            cost = ""
            if prefix == "dt1e-8-":
                cost = P("cost_of_dt", steps=f"{other['n_steps'] / base['n_steps']:.1f}",
                         wall=f"{other['wall_time_s'] / base['wall_time_s']:.1f}")
            notes.append(P("against_default", method=m.upper(),
                           dL=f"{other['final_length_mm'] - base['final_length_mm']:+.3f}",
                           dD=f"{other['final_diameter_mm'] - base['final_diameter_mm']:+.3f}", cost=cost))
        out += ["", P(prefix), ""] + _run_table(rows) + [""] + notes
    return out


def _report_sensitivity(P, records) -> list[str]:
    by = {r["name"]: r for r in records}
    sens = [r for r in records if r["name"].startswith("sens-")]
    out = ["", P("sensitivity")]
    for r in sens:
        base = by[f"conv-{r['method']}-0.75mm"]
        what = r["name"].split("-")[1]
        out.append(f"| `{r['name']}` | {P(what) if what in P.sections else r['name']} | "
                   f"{r['final_length_mm'] - base['final_length_mm']:+.3f} | "
                   f"{r['final_diameter_mm'] - base['final_diameter_mm']:+.3f} | {r['final_length_mm']:.2f} | "
                   f"{r['final_diameter_mm']:.2f} |")
    beta = {m: by.get(f"sens-beta0.5-{m}-0.75mm") for m in METHODS}
    if all(beta.values()):
        dD = {m: beta[m]["final_diameter_mm"] - by[f"conv-{m}-0.75mm"]["final_diameter_mm"] for m in METHODS}
        gap = by["conv-esph-0.75mm"]["final_diameter_mm"] - by["conv-tlsph-0.75mm"]["final_diameter_mm"]
        gap_low = beta["esph"]["final_diameter_mm"] - beta["tlsph"]["final_diameter_mm"]
        others = max(abs(r["final_diameter_mm"] - by[f"conv-{r['method']}-0.75mm"]["final_diameter_mm"])
                     for r in sens if not r["name"].startswith("sens-beta"))
        out += ["", P("viscosity", dD_esph=f"{dD['esph']:+.2f}", dD_tlsph=f"{dD['tlsph']:+.2f}",
                      grows="grows" if abs(gap_low) > abs(gap) else "shrinks", gap=f"{gap:.2f}",
                      gap_low=f"{gap_low:.2f}", others=f"{others:.2f}",
                      explains="does not explain" if abs(gap_low) > 0.5 * abs(gap) else "explains much of")]
    return out


def _report_cost(P, records, conv) -> list[str]:
    out = ["", P("cost")]
    for r in records:
        out.append(f"| `{r['name']}` | {r['dp_mm']:g} | {r['n_particles']} | {r['n_ghosts']} | {r['n_steps']} | "
                   f"{r['wall_time_s']:.0f} |")
    out.append("")
    for m in METHODS:
        rs = [r for r in conv if r["method"] == m]
        logdp = np.log([r["dp_mm"] for r in rs])
        k_wall, k_n, k_steps = (-np.polyfit(logdp, np.log([r[key] for r in rs]), 1)[0]
                                for key in ("wall_time_s", "n_particles", "n_steps"))
        out.append(P("cost_fit", method=m.upper(), k_wall=f"{k_wall:.1f}", k_n=f"{k_n:.1f}",
                     k_steps=f"{k_steps:.1f}"))
    return out


def main(argv=None):
    ap = study.parser(__doc__, "jobs", "plot_only", "only",
                      plot_only=dict(help="no runs: figures and table from earlier runs"))
    ap.add_argument("--finest", type=float, default=None, help="an extra, finer spacing [m] for the convergence study")
    study.add_flags(ap, "json_figures", "report",
                    json_figures=dict(help="only redraw the figures made from the committed JSON alone "
                                           "(figures/06_taylor_work_precision.png)"),
                    report=dict(help="no runs: write benchmarks/taylor_report.md from the committed "
                                     "benchmarks/taylor.json only"))
    args = ap.parse_args(argv)
    if args.json_figures:
        plots(json.loads(OUT_JSON.read_text()), json_only=True)
        return 0
    if args.report:
        REPORT.write_text(report(json.loads(OUT_JSON.read_text())))
        print(f"report written to {REPORT.relative_to(ROOT)}")
        return 0
    jobs = job_list(args.finest)
    if args.only:
        jobs = [j for j in jobs if args.only in j["name"]]
    if not args.plot_only:
        jobs.sort(key=lambda j: (j["dp"], j["dt"] is None))       # longest first
        # each run in a fresh process: its wall time is the work-precision plot's work (study.execute)
        threads = study.threads_per_job(args.jobs)       # all cores for --jobs 1, one each for --jobs 2
        for name, done in study.execute(run_job, {j["name"]: (dict(j, threads=threads),) for j in jobs}, args.jobs):
            if done != name:
                print(f"{name}: {done['status']}", flush=True)
    # every run that exists (the 0.375 mm ones too, if an earlier call made them with --finest), merged into the
    # committed records: a run whose folder is not here (a fresh clone, a partial rerun) keeps its record
    # (a folder whose run failed, or still runs, gives no record: its committed one stays)
    names = [j["name"] for j in job_list(args.finest or 0.375e-3) if study.run_status(RUNS / j["name"]) == "ok"]
    committed = json.loads(OUT_JSON.read_text()) if OUT_JSON.exists() else []
    records = study.merge_records(committed, [record(n) for n in names])
    study.write_if_changed(OUT_JSON, json.dumps(records, indent=1) + "\n")
    print(table(records))
    plots(records)                  # those from the run folders only where they are; each written if it changed
    return 0


if __name__ == "__main__":
    sys.exit(main())
