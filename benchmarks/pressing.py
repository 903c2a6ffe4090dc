"""Metal pressing benchmark (Section 3.2 of Islam, Bansal & Peng): the resolution study of Fig. 10 and more.

    python benchmarks/pressing.py                 # all runs, one at a time (about 9 CPU-minutes)
    python benchmarks/pressing.py --jobs 2        # two runs at a time (two cores)
    python benchmarks/pressing.py --only conv-    # only the jobs whose name contains 'conv-'
    python benchmarks/pressing.py --plot-only     # the records again from the folders in runs/benchmarks/pressing/
    python benchmarks/pressing.py --report        # benchmarks/pressing_report.md from the committed JSON only
    python benchmarks/pressing.py --only penalty- # run only those; their records go into the JSON

Runs (2D plane strain, the scene `refsph.scenes.pressing`, tool travel 0.2 mm = 1 us, both methods unless stated):
  conv       dp = 0.0167, 0.0133, 0.01, 0.00667 mm (the paper's Fig. 10; h/dp = 1.5), CFL step (Courant 0.3)
  dt1e-10    dp = 0.01 mm with the paper's fixed dt = 1e-10 s (Table 4)
  kp10/kp200 TLSPH at dp = 0.01 mm with the pinball scaling factor K_p = 10 and 200 (default 50)
  penalty    both methods at the four spacings with the penalty tool contact (Numerics.contact = 'penalty'): TLSPH's
             in place of the paper's pinballs, ESPH's in place of the paper's tool in the SPH sums
Each run is one process; its run folder runs/benchmarks/pressing/NAME keeps summary.json, reaction_forces.csv
and the final snapshot (the others are deleted). Writes benchmarks/pressing.json, one record per run (a line
each): method, spacing, particle count, steps, wall time, the scalar metrics of the scene, the binned tool
force history [ns, MN/m], the plastic-strain line [mm, -], and the differences to a reference run
(`vs_finest`: the finest conv run of the same method; `vs_base`: the conv run of the same method and dp).
Figures:
  figures/07_pressing_work_precision.png   difference to the finest run against wall time (work-precision)
  figures/07_pressing_resolution.png       final plastic strain at the four spacings, both methods (Fig. 10)
  figures/07_pressing_force.png            tool force against time at the four spacings
  figures/07_pressing_contact_force.png    TLSPH's tool force, pinball against penalty contact, finest spacing
                                           (ESPH's pair: in the report's table)
Report: `--report` reads only benchmarks/pressing.json (it runs nothing and rewrites neither the JSON nor a
figure) and writes benchmarks/pressing_report.md: what was run, the result tables, the sensitivity to the time
step and to K_p, the cost, and the figures above (chapter 07 teaches the lesson and links the report).
Wall times are single-core (the BLAS/OpenMP pools are pinned to one thread) and each run starts in a fresh
process, as `refsph run` would (a reused worker process runs ESPH up to ~1.8x faster after a large run, because
its heap has grown already); with --jobs 2 two runs share the machine's two cores.

What a rerun writes: the records of the jobs it ran (with --plot-only: of the jobs of --only, default all, whose
folders are there and hold a finished run) are merged into the committed pressing.json (study.merge_derived):
every other record stays as it was, byte for byte, so a partial rerun, or one in a fresh clone where the
git-ignored run folders are missing, drops nothing, and a run that failed or could not run gives no record (the
committed one stays). The differences (vs_finest, vs_base) are taken anew only for the records that ran and those
compared with them. The resolution figure (from the run folders) is redrawn only when every conv run was recorded
from its folder in this call; the others (from the records) whenever there are records. A file whose content (a
figure: its pixels) did not change is not written, so a rerun that reproduced the committed results, or had
nothing to do, leaves git status clean. --add (the old way to merge) is the default now and accepted for old
commands.
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()         # one core per run: BLAS / OpenMP pools at one thread (inherited by the workers)

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
RUNS = ROOT / "runs" / "benchmarks" / "pressing"
OUT_JSON = ROOT / "benchmarks" / "pressing.json"
OUT_REPORT = ROOT / "benchmarks" / "pressing_report.md"
FIG = ROOT / "figures"
METHODS = ("esph", "tlsph")
DP_SENS = 0.01e-3                    # spacing of the dt and K_p sensitivity runs
N_LINE_GRID = 400                    # points of the common x grid on which two plastic-strain lines are compared


def resolutions():
    from refsph.paper_data import PRESSING_RESOLUTIONS_M
    return tuple(PRESSING_RESOLUTIONS_M)


def dp_tag(dp: float) -> str:
    """0.0167e-3 -> '16.7um' (the spacing in micrometres, 3 digits)."""
    return f"{dp * 1e6:.3g}um"


def job_list():
    jobs = []
    for dp in resolutions():
        for m in METHODS:
            jobs.append(dict(name=f"conv-{m}-{dp_tag(dp)}", method=m, dp=dp, dt=None, numerics=None))
    for m in METHODS:
        jobs.append(dict(name=f"dt1e-10-{m}-{dp_tag(DP_SENS)}", method=m, dp=DP_SENS, dt=1e-10, numerics=None))
    for kp in (10.0, 200.0):
        jobs.append(dict(name=f"kp{kp:g}-tlsph-{dp_tag(DP_SENS)}", method="tlsph", dp=DP_SENS, dt=None,
                         numerics=dict(contact_Kp=kp)))
    for m in ("tlsph", "esph"):         # the penalty tool contact (ESPH: the tool out of the SPH sums)
        for dp in resolutions():
            jobs.append(dict(name=f"penalty-{m}-{dp_tag(dp)}", method=m, dp=dp, dt=None,
                             numerics=dict(contact="penalty")))
    return jobs


def is_penalty(r) -> bool:
    """A run (job or record) with the penalty tool contact; the other runs have the paper's tool contact (TLSPH:
    the pinballs; ESPH: the tool's particles in the SPH sums)."""
    return r["name"].startswith("penalty-")


def run_job(job):
    from refsph.simulate import run
    t0 = time.perf_counter()
    out = RUNS / job["name"]
    res = run("pressing", job["method"], dp=job["dp"], dt=job["dt"], out=out, progress=False,
              numerics=dict(job["numerics"] or {}, threads=job["threads"]))
    snaps = sorted((out / "snapshots").glob("snap_*.npz"))
    for p in snaps[:-1]:                                   # keep the final snapshot only
        p.unlink()
    s, m = res.summary, res.summary["metrics"]
    print(f"{job['name']}: {s['n_particles']} particles, {s['n_steps']} steps, {time.perf_counter() - t0:.0f} s; "
          f"F mean {m['tool_force_mean_N_per_m'] * 1e-6:.3f} MN/m, max eps_p {m['max_plastic_strain']:.2f}",
          flush=True)
    return job["name"]


def _r(a, nd):
    return np.round(np.asarray(a, dtype=float), nd).tolist()


def record(job):
    from refsph.io import load_snapshot
    name = job["name"]
    with open(RUNS / name / "summary.json") as f:
        s = json.load(f)
    m, nm = s["metrics"], s["numerics"]
    final = sorted((RUNS / name / "snapshots").glob("snap_*.npz"))[-1]
    z = load_snapshot(final)
    block = z["body"] == 0
    eps = z["eps_p"][block]
    fh = np.asarray(m["tool_force_history"])
    line = np.asarray(m["plastic_strain_line"])
    imp = s["diagnostics"]["reaction_impulse"]
    contact = (nm.get("contact", "pinball") if s["method"] == "tlsph"
               else "penalty" if nm.get("contact") == "penalty" else None)   # ESPH's own: the tool in the sums
    pen = s["diagnostics"].get("max_penalty_penetration_m")
    return dict(
        name=name, method=s["method"], dp_nominal_mm=1e3 * job["dp"], dp_mm=1e3 * s["dp"], h_mm=1e3 * s["h"],
        n_particles=s["n_particles"], n_block=int(block.sum()), n_steps=s["n_steps"],
        wall_time_s=s["wall_time_s"], cpu_time_s=s.get("cpu_time_s"), dt_mode=s["dt_mode"],
        dt_s=s["dt_max"] if s["dt_mode"] == "fixed" else None,
        dt_max_s=s["dt_max"], dt_min_s=s["dt_min"], courant=s["courant"],
        contact=contact, contact_Kp=nm["contact_Kp"] if contact == "pinball" else None, status=s["status"],
        t_final_us=1e6 * s["t_final"], tool_travel_mm=m["tool_travel_mm"],
        tool_force_peak_MN_per_m=1e-6 * m["tool_force_peak_N_per_m"],
        tool_force_mean_MN_per_m=1e-6 * m["tool_force_mean_N_per_m"],
        clamp_force_mean_MN_per_m=1e-6 * m["clamp_force_mean_N_per_m"],
        tool_impulse_N_s_per_m=imp["tool"][0], clamp_impulse_N_s_per_m=imp["left_side"][0],
        max_plastic_strain=m["max_plastic_strain"], plastic_strain_p99=float(np.percentile(eps, 99)),
        max_temperature_K=m["max_temperature_K"], min_tool_gap_over_dp=m["min_tool_gap_over_dp"],
        kinetic_energy_final_J_per_m=m["kinetic_energy_final_J_per_m"],
        line_peak=float(line[:, 1].max()), line_peak_x_mm=float(line[np.argmax(line[:, 1]), 0]),
        line_peak_width_mm=peak_width(line),
        reference_updates=s["diagnostics"].get("reference_updates"),
        max_pinball_penetration_over_dp=(s["diagnostics"]["max_pinball_penetration_m"] / s["dp"]
                                         if "max_pinball_penetration_m" in s["diagnostics"] else None),
        max_penalty_penetration_over_dp=None if pen is None else pen / s["dp"],
        tool_force_history_ns_MN_per_m=np.column_stack([_r(1e9 * fh[:, 0], 3), _r(1e-6 * fh[:, 1], 5)]).tolist(),
        plastic_strain_line_mm=np.column_stack([_r(line[:, 0], 6), _r(line[:, 1], 5)]).tolist(),
    )


def peak_width(line) -> float:
    """Width [mm] of the strain peak along the line: the x extent of the particles around the peak (contiguous,
    in x order) whose eps_p is above half the peak. The line crosses the X of the shear bands there, so this is
    a measure of how wide the bands are where they cross."""
    line = np.asarray(line)
    e = line[:, 1]
    k = int(np.argmax(e))
    i = j = k
    while i > 0 and e[i - 1] > 0.5 * e[k]:
        i -= 1
    while j < len(e) - 1 and e[j + 1] > 0.5 * e[k]:
        j += 1
    return float(line[j, 0] - line[i, 0])


def line_difference(a, b) -> float:
    """Relative L2 difference of two plastic-strain lines [[x, eps_p], ...] (different particle rows):
    ||a - b|| / ||b|| on N_LINE_GRID points spread over the x range both cover, linear interpolation."""
    a, b = np.asarray(a), np.asarray(b)
    x = np.linspace(max(a[0, 0], b[0, 0]), min(a[-1, 0], b[-1, 0]), N_LINE_GRID)
    ea, eb = np.interp(x, a[:, 0], a[:, 1]), np.interp(x, b[:, 0], b[:, 1])
    return float(np.sqrt(np.mean((ea - eb) ** 2) / np.mean(eb**2)))


def differences(r, ref) -> dict:
    """Three scalar results of r against a reference run: relative differences (not percent)."""
    return dict(ref=ref["name"],
                force_mean_rel=r["tool_force_mean_MN_per_m"] / ref["tool_force_mean_MN_per_m"] - 1.0,
                line_peak_rel=r["line_peak"] / ref["line_peak"] - 1.0,
                line_L2_rel=line_difference(r["plastic_strain_line_mm"], ref["plastic_strain_line_mm"]),
                line_width_rel=r["line_peak_width_mm"] / ref["line_peak_width_mm"] - 1.0,
                wall_time_ratio=r["wall_time_s"] / ref["wall_time_s"])


def add_differences(records):
    """vs_finest: against the finest conv run of the method; vs_base: against the conv run of the method at
    the same nominal spacing (for the dt and K_p runs). The penalty runs: vs_finest against the finest penalty run
    of the method, vs_base against the method's conv run (the paper's contact) at the same spacing."""
    conv = {(r["method"], r["dp_nominal_mm"]): r for r in records if r["name"].startswith("conv-")}
    penalty = [r for r in records if is_penalty(r)]
    for r in records:
        if is_penalty(r):           # vs_finest: the finest penalty run; vs_base: the pinball run at the same dp
            r["vs_finest"] = differences(r, min([c for c in penalty if c["method"] == r["method"]],
                                                key=lambda c: c["dp_nominal_mm"]))
            if (r["method"], r["dp_nominal_mm"]) in conv:
                r["vs_base"] = differences(r, conv[(r["method"], r["dp_nominal_mm"])])
            continue
        own = [c for (m, _), c in conv.items() if m == r["method"]]
        if own:
            finest = min(own, key=lambda c: c["dp_nominal_mm"])
            r["vs_finest"] = differences(r, finest)
        base = conv.get((r["method"], r["dp_nominal_mm"]))
        if base is not None and not r["name"].startswith("conv-"):
            r["vs_base"] = differences(r, base)
    return records


def write_json(records) -> bool:
    """One record per line (compact arrays), so that a change shows in git as the runs that changed. Written only if
    it changed; True if it was."""
    return study.write_if_changed(OUT_JSON, "[\n" + ",\n".join(json.dumps(r) for r in records) + "\n]\n")


def table(records) -> str:
    lines = [f"{'run':22s} {'dp um':>6s} {'N':>6s} {'steps':>6s} {'wall s':>7s} {'F peak':>7s} {'F mean':>7s} "
             f"{'clamp':>7s} {'eps max':>7s} {'eps p99':>7s} {'line pk':>7s} {'at x':>5s} {'T max':>6s} "
             f"{'gap/dp':>6s} {'dF fin':>7s} {'dpk fin':>7s} {'L2 fin':>6s}"]
    for r in records:
        d = r.get("vs_finest", {})
        fin = (f"{100 * d['force_mean_rel']:+6.1f}% {100 * d['line_peak_rel']:+6.1f}% {100 * d['line_L2_rel']:5.1f}%"
               if d and d["ref"] != r["name"] else f"{'(ref)':>7s} {'':7s} {'':6s}")
        lines.append(f"{r['name']:22s} {1e3 * r['dp_mm']:6.2f} {r['n_particles']:6d} {r['n_steps']:6d} "
                     f"{r['wall_time_s']:7.1f} {r['tool_force_peak_MN_per_m']:7.3f} "
                     f"{r['tool_force_mean_MN_per_m']:7.3f} {r['clamp_force_mean_MN_per_m']:7.3f} "
                     f"{r['max_plastic_strain']:7.2f} {r['plastic_strain_p99']:7.3f} "
                     f"{r['line_peak']:7.3f} {r['line_peak_x_mm']:5.2f} {r['line_peak_width_mm']:5.3f} "
                     f"{r['max_temperature_K']:6.0f} "
                     f"{r['min_tool_gap_over_dp']:6.2f} {fin}")
    lines.append("F: force of the block on the tool [MN/m = kN per mm of thickness], peak of the 400-bin history "
                 "and mean over the 2nd half; clamp: force on the clamped column (mean, 2nd half); eps p99: 99th "
                 "percentile of eps_p in the block; line pk: peak of eps_p along the mid-height row, at x [mm], "
                 "width [mm] where it is above half its peak; "
                 "d.. fin: difference to the finest run of the same method")
    return "\n".join(lines)


def _moving_average(y, k):
    if len(y) < k:
        return np.asarray(y)
    return np.convolve(y, np.ones(k) / k, mode="same")


def plots(records, json_only: bool = False, folders=()):
    """The benchmark's figures; ``json_only``: only the work-precision and contact plots; the resolution figure (from
    the run folders) only if every conv run is in ``folders``, the runs recorded from their folders in this call. A
    figure whose pixels did not change is not written."""
    import matplotlib
    matplotlib.use("Agg")
    FIG.mkdir(exist_ok=True)
    conv = {m: sorted([r for r in records if r["name"].startswith("conv-") and r["method"] == m],
                      key=lambda r: -r["dp_mm"]) for m in METHODS}
    if not all(conv.values()):
        print("no figures: they need conv runs of both methods")
        return
    _plot_work_precision(records, conv)
    _plot_contact(records)
    if json_only:
        return
    _plot_force(conv)
    shown = {r["name"] for m in METHODS for r in conv[m]}
    if shown <= set(folders):
        _plot_resolution(conv)
    elif shown & set(folders):
        print("the resolution figure is not redrawn: it needs the run folders of "
              f"{', '.join(sorted(shown - set(folders)))}")


COLORS = dict(esph="C0", tlsph="C3")


def _plot_work_precision(records, conv):
    """Difference to the finest run of the same method against wall time."""
    import matplotlib.ticker
    import matplotlib.pyplot as plt
    colors = COLORS
    plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}" if f"{v:.0e}"[0] in "1235" else "")
    fig, axs = plt.subplots(2, 2, figsize=(11, 8.5), layout="constrained")
    for ax, key, label in ((axs[0, 0], "force_mean_rel", "mean tool force, 2nd half"),
                           (axs[0, 1], "line_peak_rel", "peak of eps_p along the mid-height row"),
                           (axs[1, 0], "line_L2_rel", "L2 difference of the eps_p line"),
                           (axs[1, 1], "line_width_rel", "width of the line's strain peak (half maximum)")):
        for m in METHODS:
            rs = [r for r in conv[m] if "vs_finest" in r and r["vs_finest"]["ref"] != r["name"]]
            w = [r["wall_time_s"] for r in rs]
            e = [max(100 * abs(r["vs_finest"][key]), 1e-3) for r in rs]
            ax.loglog(w, e, "o-", color=colors[m], label=f"{m.upper()}, CFL step")
            for r, wi, ei in zip(rs, w, e):
                ax.annotate(f"{1e3 * r['dp_nominal_mm']:.3g} um", (wi, ei), textcoords="offset points",
                            xytext=(4, 4), fontsize=8, color=colors[m])
            fin = [r for r in conv[m] if r.get("vs_finest", {}).get("ref") == r["name"]]
            for r in fin:
                ax.axvline(r["wall_time_s"], color=colors[m], ls=":", lw=1,
                           label=f"{m.upper()}: wall time of the finest run ({1e3 * r['dp_nominal_mm']:.3g} um), "
                                 "the reference")
            for r in records:
                if r["method"] == m and r["name"].startswith("dt1e-10-") and "vs_finest" in r:
                    ax.loglog([r["wall_time_s"]], [max(100 * abs(r["vs_finest"][key]), 1e-3)], "s", mfc="none",
                              color=colors[m], label=f"{m.upper()}, dt = 1e-10 s, {1e3 * r['dp_nominal_mm']:.3g} um")
        ax.set_xlabel("wall time [s] (one core)")
        ax.set_ylabel("|difference to the finest run| [%]")
        ax.set_title(label, fontsize=10)
        ax.grid(alpha=0.3, which="both")
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_formatter(plain)
            axis.set_minor_formatter(plain)
    handles, labels = axs[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=3, fontsize=8)
    fig.suptitle("Metal pressing, 2D plane strain: work-precision (each method against its own finest run, "
                 "dp = 0.00667 mm)", fontsize=11)
    study.save_figure(fig, FIG / "07_pressing_work_precision.png", dpi=120)


def _plot_resolution(conv):
    """Fig. 10 analogue: final plastic strain at the four spacings."""
    import matplotlib.pyplot as plt
    from refsph.io import load_snapshot
    ncol = max(len(conv[m]) for m in METHODS)
    fig = plt.figure(figsize=(3.3 * ncol + 1.0, 6.6))
    axs = fig.subplots(2, ncol, squeeze=False, gridspec_kw=dict(left=0.05, right=0.9, bottom=0.08, top=0.86,
                                                                  wspace=0.12, hspace=0.32))
    vmax = 1.0
    xlim, ylim = (-0.03, 0.9), (-0.15, 0.65)
    for row, m in enumerate(METHODS):
        for col, r in enumerate(conv[m]):
            z = load_snapshot(sorted((RUNS / r["name"] / "snapshots").glob("snap_*.npz"))[-1])
            ax = axs[row, col]
            ax.set_aspect("equal")
            ax.set_xlim(*xlim)
            ax.set_ylim(*ylim)
            ax.apply_aspect()
            pt_per_mm = ax.get_position().width * fig.get_figwidth() * 72 / (xlim[1] - xlim[0])
            size = (1.3 * pt_per_mm * r["dp_mm"]) ** 2          # marker area [pt^2]: one spacing across
            b = z["body"] == 0
            ax.scatter(1e3 * z["x"][~b, 0], 1e3 * z["x"][~b, 1], c="0.6", s=size, lw=0, marker="s")
            order = np.argsort(z["eps_p"][b])
            sc = ax.scatter(1e3 * z["x"][b][order, 0], 1e3 * z["x"][b][order, 1], c=z["eps_p"][b][order], s=size,
                            lw=0, marker="s", cmap="jet", vmin=0.0, vmax=vmax)
            ax.set_title(f"{m.upper()}, dp = {1e3 * r['dp_nominal_mm']:.3g} um ({r['n_block']} particles)\n"
                         f"wall {r['wall_time_s']:.0f} s, max eps_p {r['max_plastic_strain']:.2f}", fontsize=8)
            ax.tick_params(labelsize=7)
            if row == 1:
                ax.set_xlabel("x [mm]", fontsize=8)
            if col == 0:
                ax.set_ylabel("y [mm]", fontsize=8)
    cax = fig.add_axes([0.92, 0.2, 0.012, 0.6])
    fig.colorbar(sc, cax=cax, label=f"effective plastic strain (colour scale cut at {vmax:g})", extend="max")
    fig.suptitle("Metal pressing, tool travel 0.2 mm: final plastic strain at four spacings (cf. Fig. 10); "
                 "grey: the tool", fontsize=10)
    study.save_figure(fig, FIG / "07_pressing_resolution.png", dpi=130)


def _plot_force(conv):
    """Tool force against time."""
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(12, 4.2), constrained_layout=True, sharey=True)
    for ax, m in zip(axs, METHODS):
        for k, r in enumerate(conv[m]):
            h = np.asarray(r["tool_force_history_ns_MN_per_m"])
            c = plt.cm.viridis(k / max(1, len(conv[m]) - 1))
            ax.plot(h[:, 0], h[:, 1], color=c, lw=0.5, alpha=0.35)
            ax.plot(h[:, 0], _moving_average(h[:, 1], 9), color=c, lw=1.4,
                    label=f"dp = {1e3 * r['dp_nominal_mm']:.3g} um (mean 2nd half {r['tool_force_mean_MN_per_m']:.3f})")
        ax.set_xlabel("t [ns]")
        ax.set_title(f"{m.upper()}: force of the block on the tool (thin: 2.5 ns bins, thick: 22.5 ns running mean)",
                     fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    axs[0].set_ylabel("tool force [MN/m]")
    axs[0].set_ylim(bottom=0)
    fig.suptitle("Metal pressing: tool force against time at the four spacings, CFL step", fontsize=10)
    study.save_figure(fig, FIG / "07_pressing_force.png", dpi=120)


def _contact_pairs(records, method: str = "tlsph"):
    """(the paper's contact: conv-METHOD run, penalty run of the method) at each spacing both have, coarsest
    first."""
    pin = {r["dp_nominal_mm"]: r for r in records if r["name"].startswith(f"conv-{method}-")}
    pen = sorted([r for r in records if is_penalty(r) and r["method"] == method], key=lambda r: -r["dp_nominal_mm"])
    return [(pin[r["dp_nominal_mm"]], r) for r in pen if r["dp_nominal_mm"] in pin]


def _plot_contact(records):
    """figures/07_pressing_contact_force.png: TLSPH's tool force with the pinball and the penalty contact at the
    finest spacing both have (from the records alone)."""
    pairs = _contact_pairs(records)
    if not pairs:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4.2), constrained_layout=True)
    for r, c, label in ((pairs[-1][0], "C3", "pinball (the paper's)"), (pairs[-1][1], "C2", "penalty")):
        h = np.asarray(r["tool_force_history_ns_MN_per_m"])
        ax.plot(h[:, 0], h[:, 1], color=c, lw=0.5, alpha=0.35)
        ax.plot(h[:, 0], _moving_average(h[:, 1], 9), color=c, lw=1.4,
                label=f"{label}: mean 2nd half {r['tool_force_mean_MN_per_m']:.3f}, peak "
                      f"{r['tool_force_peak_MN_per_m']:.2f} MN/m")
    ax.set_xlabel("t [ns]")
    ax.set_ylabel("tool force [MN/m]")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(f"Metal pressing, TLSPH, dp = {_um(pairs[-1][1])} um: force of the block on the tool, two tool "
                 "contacts\n(thin: 2.5 ns bins, thick: 22.5 ns running mean)", fontsize=9)
    study.save_figure(fig, FIG / "07_pressing_contact_force.png", dpi=120)


def _pct(x, signed=True) -> str:
    """A relative difference (not percent) as a percentage with one decimal."""
    return f"{100 * x:+.1f} %" if signed else f"{100 * x:.1f} %"


def _aligned(head, rows) -> str:
    """A markdown table, the first column left-aligned, the others right."""
    return study.md_table(head, rows, align=True)


def _fig(name, caption) -> str:
    return f"![{caption}](../figures/{name})" if (FIG / name).exists() else f"(figure `figures/{name}` not there)"


def _join(xs) -> str:
    return ", ".join(f"{x:g}" for x in xs)


def _um(r) -> str:
    return f"{1e3 * r['dp_nominal_mm']:.3g}"


def report(records) -> str:
    """benchmarks/pressing_report.md from the records of benchmarks/pressing.json (runs nothing); the prose is
    benchmarks/templates/pressing_report.md."""
    P = study.Page("pressing_report")
    conv = sorted([r for r in records if r["name"].startswith("conv-")], key=lambda r: (r["method"], -r["dp_mm"]))
    conv_m = {m: [r for r in conv if r["method"] == m] for m in METHODS}
    L = [P("head", n_runs=len(records)), ""]
    L += _report_runs(P, records)
    L += _report_resolution(P, records, conv, conv_m)
    L += _report_convergence(P, records, conv_m)
    L += _report_cost(P, records, conv, conv_m)
    L += _report_sensitivity(P, records, conv)
    L += _report_contact(P, records)
    L += [P("snapshots"), ""]
    return "\n".join(L)


def _report_runs(P, records) -> list[str]:
    dt_label = lambda r: "CFL 0.3" if r["dt_mode"] == "cfl" else f"fixed {r['dt_s']:.0e} s"  # noqa: E731
    L = [P("what", speed=_join(sorted({round(r["tool_travel_mm"] / r["t_final_us"] * 1e3) for r in records})),
           travel=_join(sorted({round(r["tool_travel_mm"], 6) for r in records})),
           t_end=_join(sorted({round(r["t_final_us"], 6) for r in records})),
           h_dp=_join(sorted({round(r["h_mm"] / r["dp_mm"], 3) for r in records}))), ""]
    L += [_aligned(["run", "method", "dp [um]", "particles", "steps", "time step", "K_p", "wall [s]", "status"],
                    [[r["name"], r["method"].upper(), _um(r), f"{r['n_particles']}", f"{r['n_steps']}", dt_label(r),
                      "-" if r["contact_Kp"] is None else f"{r['contact_Kp']:g}", f"{r['wall_time_s']:.1f}",
                      r["status"]] for r in records]), ""]
    return L


def _report_resolution(P, records, conv, conv_m) -> list[str]:
    L = [P("resolution", n_bins=_join(sorted({len(r["tool_force_history_ns_MN_per_m"]) for r in records}))), ""]
    L += [_aligned(["run", "dp [um]", "F mean", "clamp", "F peak", "line peak", "at x [mm]", "width [mm]",
                     "eps p99", "eps max", "T max [K]", "gap/dp"],
                    [[r["name"], _um(r), f"{r['tool_force_mean_MN_per_m']:.3f}",
                      f"{-r['clamp_force_mean_MN_per_m']:.3f}", f"{r['tool_force_peak_MN_per_m']:.2f}",
                      f"{r['line_peak']:.3f}", f"{r['line_peak_x_mm']:.2f}", f"{r['line_peak_width_mm']:.3f}",
                      f"{r['plastic_strain_p99']:.3f}", f"{r['max_plastic_strain']:.2f}",
                      f"{r['max_temperature_K']:.0f}", f"{r['min_tool_gap_over_dp']:.2f}"] for r in conv]), ""]
    L += [_fig("07_pressing_resolution.png", "final plastic strain at the four spacings, ESPH and TLSPH"), "",
          _fig("07_pressing_force.png", "tool force against time at the four spacings"), ""]
    fine = {m: conv_m[m][-1] for m in METHODS if conv_m[m]}
    coarse = {m: conv_m[m][0] for m in METHODS if conv_m[m]}

    def change(key, fmt, sep, unit=""):
        return ", ".join(f"{m.upper()}{sep}{format(coarse[m][key], fmt)} to {format(fine[m][key], fmt)}{unit}"
                         for m in fine)
    return L + [P("how_to_read", width=change("line_peak_width_mm", ".3f", " from ", " mm"),
                  max_growth=change("max_plastic_strain", ".2f", " from "),
                  p99=change("plastic_strain_p99", ".3f", " ")), ""]


def _report_convergence(P, records, conv_m) -> list[str]:
    L = [P("convergence"), ""]
    rows = []
    for r in records:
        d = r.get("vs_finest")
        if d is None or d["ref"] == r["name"] or is_penalty(r):     # the penalty runs: their own section
            continue
        rows.append([r["name"], d["ref"], f"{r['wall_time_s']:.1f}", _pct(d["force_mean_rel"]),
                     _pct(d["line_peak_rel"]), _pct(d["line_L2_rel"], False), _pct(d["line_width_rel"])])
    L += [_aligned(["run", "against", "wall [s]", "F mean", "line peak", "line L2", "width"], rows), ""]
    L += [_fig("07_pressing_work_precision.png", "work-precision: difference to the finest run against wall time"), ""]
    worst_f = {m: max(abs(r["vs_finest"]["force_mean_rel"]) for r in conv_m[m][:-1]) for m in METHODS if conv_m[m]}
    return L + [P("force_within", worst=", ".join(f"{100 * worst_f[m]:.1f} % ({m.upper()})" for m in worst_f)), ""]


def _report_cost(P, records, conv, conv_m) -> list[str]:
    kps = {r["name"]: 1e-3 * r["n_particles"] * r["n_steps"] / r["wall_time_s"] for r in records}
    rows = [[r["name"], f"{r['n_particles']}", f"{r['n_steps']}", f"{r['wall_time_s']:.1f}", f"{kps[r['name']]:.0f}"]
            for r in conv]
    L = [P("cost"), "", _aligned(["run", "particles", "steps", "wall [s]", "k particle-steps/s"], rows), ""]
    fits = []
    for m in METHODS:
        rs = conv_m[m]
        if len(rs) >= 2:
            k = np.polyfit(np.log([r["dp_mm"] for r in rs]), np.log([r["wall_time_s"] for r in rs]), 1)[0]
            fits.append(f"{m.upper()} wall ~ dp^{k:.1f}")
    ratio = np.mean([kps[a["name"]] / kps[b["name"]] for a, b in zip(conv_m["tlsph"], conv_m["esph"])])
    return L + [P("cost_fit", fits=", ".join(fits), ratio=f"{ratio:.1f}"), ""]


def _report_sensitivity(P, records, conv) -> list[str]:
    """The time step and the pinball factor: each run against its conv run (vs_base)."""
    by = {r["name"]: r for r in records}
    kp_default = _join(sorted({r["contact_Kp"] for r in conv if r["contact_Kp"] is not None}))
    L = []
    for prefix, title, text in (("dt1e-10-", "dt1e-10-", "dt1e-10-_text"), ("kp", "kp", "kp_text")):
        sens = [r for r in records if r["name"].startswith(prefix)]
        if not sens:
            continue
        L += [P(title), "", P("vs_base"), ""]
        rows = []
        for r in sens:
            d = r["vs_base"]
            base = by[d["ref"]]
            pen = r.get("max_pinball_penetration_over_dp")
            pen_b = base.get("max_pinball_penetration_over_dp")
            rows.append([r["name"], d["ref"], f"{r['n_steps']} / {base['n_steps']}", f"{d['wall_time_ratio']:.1f}",
                         _pct(d["force_mean_rel"]), _pct(d["line_peak_rel"]), _pct(d["line_L2_rel"], False),
                         _pct(d["line_width_rel"]),
                         "-" if pen is None else f"{pen:.3f} / {pen_b:.3f}"])
        L += [_aligned(["run", "against", "steps", "wall ratio", "F mean", "line peak", "line L2", "width",
                         "penetration/dp"], rows), "", P(text, kp_default=kp_default), ""]
    return L


def _pair_cell(a, b, key, spec, scale=1.0) -> str:
    """'pinball / penalty' of one measure."""
    return f"{study.fmt(a.get(key), spec, scale)} / {study.fmt(b.get(key), spec, scale)}"


def _orders(pairs, k) -> str:
    """The observed orders of the mean force of contact k (0 pinball, 1 penalty) from each three successive
    spacings."""
    rs = [p[k] for p in pairs]
    out = []
    for a, b, c in zip(rs, rs[1:], rs[2:]):
        p = study.observed_order([r["dp_mm"] for r in (a, b, c)], [r["tool_force_mean_MN_per_m"] for r in (a, b, c)])
        word = "none (the differences change sign or grow)" if p is None else study.fmt(p, ".1f")
        out.append(f"{_um(a)}, {_um(b)}, {_um(c)} um: {word}")
    return "; ".join(out)


CONTACT_COLUMNS = ["dp [um]", "F mean", "penalty / paper's - 1", "F peak", "clamp", "line peak", "at x [mm]",
                   "width [mm]", "eps p99", "eps max", "T max [K]", "gap/dp", "penetration/dp", "steps", "wall [s]",
                   "CPU [s]"]


def _contact_rows(pairs) -> list[list[str]]:
    """A row per (paper's contact, penalty) pair: the columns CONTACT_COLUMNS, each cell 'paper's / penalty'."""
    return [[_um(b), _pair_cell(a, b, "tool_force_mean_MN_per_m", ".3f"),
             _pct(b["tool_force_mean_MN_per_m"] / a["tool_force_mean_MN_per_m"] - 1),
             _pair_cell(a, b, "tool_force_peak_MN_per_m", ".2f"),
             _pair_cell(a, b, "clamp_force_mean_MN_per_m", ".3f", -1),
             _pair_cell(a, b, "line_peak", ".3f"), _pair_cell(a, b, "line_peak_x_mm", ".2f"),
             _pair_cell(a, b, "line_peak_width_mm", ".3f"), _pair_cell(a, b, "plastic_strain_p99", ".3f"),
             _pair_cell(a, b, "max_plastic_strain", ".2f"), _pair_cell(a, b, "max_temperature_K", ".0f"),
             _pair_cell(a, b, "min_tool_gap_over_dp", ".2f"),
             f"{study.fmt(a.get('max_pinball_penetration_over_dp'), '.3f')} / "
             f"{study.fmt(b.get('max_penalty_penetration_over_dp'), '.3f')}",
             _pair_cell(a, b, "n_steps", "d"), _pair_cell(a, b, "wall_time_s", ".1f"),
             _pair_cell(a, b, "cpu_time_s", ".1f")] for a, b in pairs]


def _span(pairs, k, key, spec) -> str:
    """The first (coarsest) and last (finest) value of ``key`` of contact k (0 the paper's, 1 penalty)."""
    return f"{format(pairs[0][k][key], spec)} to {format(pairs[-1][k][key], spec)}"


def _report_contact(P, records) -> list[str]:
    """The tool contact: TLSPH's pinballs (conv-tlsph) against the penalty contact, spacing by spacing; then ESPH's
    tool in the SPH sums against the penalty contact (:func:`_report_contact_esph`)."""
    pairs = _contact_pairs(records)
    if not pairs:
        return _report_contact_esph(P, records)
    L = [P("contact"), "", _aligned(CONTACT_COLUMNS, _contact_rows(pairs)), ""]
    diff = [b["tool_force_mean_MN_per_m"] / a["tool_force_mean_MN_per_m"] - 1 for a, b in pairs]
    cost = [b["cpu_time_s"] / a["wall_time_s"] for a, b in pairs if b.get("cpu_time_s")]
    a, b = pairs[-1]
    L += [P("contact_end", dp_fine=_um(b), f_pin=f"{a['tool_force_mean_MN_per_m']:.3f}",
            f_pen=f"{b['tool_force_mean_MN_per_m']:.3f}", diff_min=_pct(min(diff)), diff_max=_pct(max(diff)),
            peak_pin=_span(pairs, 0, "tool_force_peak_MN_per_m", ".2f"),
            peak_pen=_span(pairs, 1, "tool_force_peak_MN_per_m", ".2f"),
            max_pin=_span(pairs, 0, "max_plastic_strain", ".2f"), max_pen=_span(pairs, 1, "max_plastic_strain", ".2f"),
            x_pin=f"{a['line_peak_x_mm']:.2f}", x_pen=f"{b['line_peak_x_mm']:.2f}",
            line_l2=_pct(b["vs_base"]["line_L2_rel"], False) if b.get("vs_base") else "-",
            cost=f"{min(cost):.1f} to {max(cost):.1f}" if cost else "-",
            figure=_fig("07_pressing_contact_force.png", "tool force, pinball against penalty contact")), ""]
    if len(pairs) >= 3:
        L += [P("contact_order", order_pen=_orders(pairs, 1), order_pin=_orders(pairs, 0)), ""]
    return L + _report_contact_esph(P, records)


def _report_contact_esph(P, records) -> list[str]:
    """ESPH's tool: the paper's (its particles in the SPH sums, conv-esph) against the penalty contact, spacing by
    spacing, and the two methods' penalty runs against each other at the finest spacing both have."""
    pairs = _contact_pairs(records, "esph")
    if not pairs:
        return []
    L = [P("contact_esph"), "", _aligned(CONTACT_COLUMNS, _contact_rows(pairs)), ""]
    diff = [b["tool_force_mean_MN_per_m"] / a["tool_force_mean_MN_per_m"] - 1 for a, b in pairs]
    pen_t = {r["dp_nominal_mm"]: r for _, r in _contact_pairs(records)}
    both = [(pen_t[b["dp_nominal_mm"]], b) for _, b in pairs if b["dp_nominal_mm"] in pen_t]
    methods = "-"
    if both:
        t, e = both[-1]
        each = ", ".join(_pct(e2["tool_force_mean_MN_per_m"] / t2["tool_force_mean_MN_per_m"] - 1) for t2, e2 in both)
        methods = (f"{e['tool_force_mean_MN_per_m']:.3f} against TLSPH's {t['tool_force_mean_MN_per_m']:.3f} MN/m "
                   f"({_pct(e['tool_force_mean_MN_per_m'] / t['tool_force_mean_MN_per_m'] - 1)}) at {_um(e)} um, "
                   f"over the spacings {each}")
    L += [P("contact_esph_end", diffs=", ".join(_pct(d) for d in diff),
            peak_sums=_span(pairs, 0, "tool_force_peak_MN_per_m", ".2f"),
            peak_pen=_span(pairs, 1, "tool_force_peak_MN_per_m", ".2f"),
            max_sums=_span(pairs, 0, "max_plastic_strain", ".2f"), max_pen=_span(pairs, 1, "max_plastic_strain", ".2f"),
            methods=methods), ""]
    if len(pairs) >= 3:
        L += [P("contact_order_esph", order_pen=_orders(pairs, 1), order_sums=_orders(pairs, 0)), ""]
    return L


def main(argv=None):
    ap = study.parser(__doc__, "jobs", "plot_only", "only", "json_figures", "report",
                      json_figures=dict(help="only redraw the figures made from the committed JSON alone "
                                             "(figures/07_pressing_work_precision.png, 07_pressing_contact_force.png)"),
                      report=dict(help=f"no runs: write {OUT_REPORT.name} from the committed {OUT_JSON.name} "
                                       "(nothing else)"))
    ap.add_argument("--add", action="store_true",
                    help="(the default now, kept for old commands) the records of the jobs that ran, or with "
                         "--plot-only of the jobs of --only whose folders are there, merged into the JSON")
    args = ap.parse_args(argv)
    if args.json_figures:
        plots(json.loads(OUT_JSON.read_text()), json_only=True)
        return 0
    if args.report:
        wrote = study.write_if_changed(OUT_REPORT, report(json.loads(OUT_JSON.read_text())))
        print(f"{'wrote' if wrote else 'unchanged:'} {OUT_REPORT.relative_to(ROOT)} from {OUT_JSON.relative_to(ROOT)}")
        return 0
    todo = [j for j in job_list() if args.only is None or args.only in j["name"]]
    ran = None
    if not args.plot_only:
        todo.sort(key=lambda j: (j["dp"], j["dt"] is None))      # longest first
        # a fresh process for every run (study.execute): a worker that ran a large run before starts the next one
        # with a grown heap and runs it faster (glibc returns freed memory to the OS only at the top of the heap),
        # so reused workers would make the wall times depend on the order of the runs
        threads = study.threads_per_job(args.jobs)       # all cores for --jobs 1, one each for --jobs 2
        ran = set()
        for name, done in study.execute(run_job, {j["name"]: (dict(j, threads=threads),) for j in todo}, args.jobs):
            if done != name:                              # failed or could not run: no result of this call
                print(f"{name}: {done['status']}", flush=True)
            else:
                ran.add(name)
    record_runs([j for j in job_list() if j in todo and (ran is None or j["name"] in ran)])
    return 0


def _finished(job) -> bool:
    """A run folder holding a finished run (a failed, killed or running one gives no record)."""
    status = study.run_status(RUNS / job["name"])
    if status not in (None, "ok"):
        print(f"{job['name']}: status {status!r} in its folder, not recorded")
    return status == "ok"


def record_runs(jobs) -> list:
    """The records of ``jobs`` (those with a finished run in their folder) merged into pressing.json (module text),
    the table, and the figures they change."""
    committed = json.loads(OUT_JSON.read_text()) if OUT_JSON.exists() else []
    fresh = [record(j) for j in jobs if _finished(j)]
    if not fresh:
        print(f"no finished run to record in {RUNS}: nothing written")
        return committed
    records, went_in = study.merge_derived(committed, fresh, add_differences)
    print(f"{'wrote' if write_json(records) else 'unchanged:'} {OUT_JSON.relative_to(ROOT)} "
          f"(recorded: {', '.join(sorted(went_in))})")
    print(table(records))
    plots(records, folders=went_in)
    return records


if __name__ == "__main__":
    sys.exit(main())
