"""Orthogonal cutting benchmark (Section 3.3 of Islam, Bansal & Peng): both feeds, both methods.

    python benchmarks/cutting.py                   # all runs, one at a time on both cores (about 2 hours)
    python benchmarks/cutting.py --only paper-     # only the jobs whose name contains 'paper-'
    python benchmarks/cutting.py --plot-only       # the records again from the folders in runs/benchmarks/cutting/
    python benchmarks/cutting.py --plot-only --rerun-of DIR --rerun-label "commit abc1234"
                                                   # ... and vs_rerun: the paper runs against the same runs in DIR
    python benchmarks/cutting.py --report          # benchmarks/cutting_report.md from cutting.json (runs nothing)
    taskset -c 0 python benchmarks/cutting.py --only penalty-
                                                   # run only those, one core; their records go into cutting.json
    python benchmarks/cutting.py --strain-figure 0.3   # only figures/08_cutting_strain_f0.3.png, from the run folders

Runs (2D plane strain, the scene `refsph.scenes.cutting`, 1 mm of cut = 20 us unless stated):
  paper-METHOD-fFEED   dp = 0.01 mm, h = 0.018 mm (Table 5), feed 0.3 and 0.5 mm, both methods, CFL step
  coarse-...           the same at dp = 0.025 mm and 0.0167 mm (feed 0.3 mm), for the work-precision plot
  noupdate-tlsph       TLSPH without reference-configuration updates, dp = 0.025 mm, feed 0.3 mm, 0.5 mm of
                       cut (reduced size), against the same run with updates (coarse-tlsph-f0.3-25um)
  penalty-METHOD-fFEED the paper runs with the penalty tool contact (Numerics.contact = 'penalty'): TLSPH's in
                       place of the paper's pinballs, ESPH's in place of the tool's particles in the SPH sums
Each run is one process; its folder runs/benchmarks/cutting/NAME keeps summary.json, reaction_forces.csv and all
snapshots (every 1/8 of the cut). BLAS/OpenMP pools are pinned to one thread; refsph's pair sums run on the run's
share of the cores (Numerics.threads: all of them with --jobs 1, one each with --jobs 2). Wall times are what the
issue's 30-minute target is about; CPU times add up all threads.

What a rerun writes: the records of the jobs it ran (with --plot-only: of the jobs of --only, default all, whose
folders are there), measured anew from their folders, are merged into the committed cutting.json
(study.merge_derived): every other record stays as it was, byte for byte, so a partial rerun, or one in a fresh
clone where the git-ignored run folders are missing, drops nothing; a run that failed never replaces a good record
(a run that could not run, or was killed, gives no record at all); the vs_paper differences are taken anew only for
the records that ran and those compared with them. A figure drawn from run folders (strain, temperature, reference
updates) is redrawn only when every run it shows was recorded from its folder in this call; one drawn from the
records alone (forces, bands, work-precision, contact) whenever the records allow. A file whose content (a figure:
its pixels) did not change is not written, so a rerun that reproduced the committed results, or had nothing to do,
leaves git status clean. --add (the old way to merge) is the default now and accepted for old commands.
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
RUNS = ROOT / "runs" / "benchmarks" / "cutting"
OUT_JSON = ROOT / "benchmarks" / "cutting.json"
OUT_REPORT = ROOT / "benchmarks" / "cutting_report.md"
FIG = ROOT / "figures"
METHODS = ("tlsph", "esph")
FEEDS = (0.3e-3, 0.5e-3)
DP_PAPER = 0.01e-3
BAND_THRESHOLDS = (0.25, 0.5, 1.0)   # the band count's sensitivity to its threshold (the default is 0.5)


def dp_tag(dp: float) -> str:
    return f"{dp * 1e6:.3g}um"


def job_list():
    jobs = []
    for m in METHODS:
        for f in FEEDS:
            jobs.append(dict(name=f"paper-{m}-f{f * 1e3:g}", method=m, dp=DP_PAPER, feed=f, travel=1e-3,
                             numerics=None))
    for m in METHODS:
        for f in FEEDS:
            jobs.append(dict(name=f"coarse-{m}-f{f * 1e3:g}-25um", method=m, dp=0.025e-3, feed=f, travel=1e-3,
                             numerics=None))
    jobs.append(dict(name="noupdate-tlsph-f0.3-25um", method="tlsph", dp=0.025e-3, feed=0.3e-3, travel=0.5e-3,
                     numerics=dict(ref_update_strain=None)))
    for m in METHODS:
        jobs.append(dict(name=f"coarse-{m}-f0.3-{dp_tag(1e-3 / 60)}", method=m, dp=1e-3 / 60, feed=0.3e-3,
                         travel=1e-3, numerics=None))
    for m in ("tlsph", "esph"):         # the paper runs with the penalty tool contact (ESPH: the tool out of the sums)
        for f in FEEDS:
            jobs.append(dict(name=f"penalty-{m}-f{f * 1e3:g}", method=m, dp=DP_PAPER, feed=f, travel=1e-3,
                             numerics=dict(contact="penalty")))
    return jobs


def is_penalty(r) -> bool:
    """A run (job or record) with the penalty tool contact; the other runs have the paper's (TLSPH: pinballs; ESPH:
    the tool's particles in the SPH sums)."""
    return r["name"].startswith("penalty-")


def run_job(job):
    from refsph.simulate import SimulationError, run
    t0 = time.perf_counter()
    out = RUNS / job["name"]
    try:
        res = run("cutting", job["method"], dp=job["dp"], out=out, progress=True,
                  numerics=dict(job["numerics"] or {}, threads=job["threads"]),
                  options=dict(feed=job["feed"], travel=job["travel"]))
        s = res.summary
        msg = f"{s['status']}, {s['n_steps']} steps"
    except SimulationError as e:                          # a lost run is a result too: summary.json says why
        msg = f"failed: {e}"
    print(f"{job['name']}: {msg}, {time.perf_counter() - t0:.0f} s", flush=True)
    return job["name"]


def _r(a, nd):
    return np.round(np.asarray(a, dtype=float), nd).tolist()


def load(name):
    """(summary, snapshot paths) of run ``name`` in RUNS."""
    from refsph.io import load_run
    return load_run(RUNS / name)


def record(job, runs=None):
    """The record of a finished or failed run in folder runs (default RUNS); the measurements are recomputed from
    the run's files with the current code (refsph.scenes.cutting.analyse_run), so a changed measure needs no new run."""
    from refsph.io import analyse_cutting_run as analyse_run
    from refsph.io import load_run, load_snapshot
    name = job["name"]
    folder = (RUNS if runs is None else Path(runs)) / name
    s, snaps = load_run(folder)
    ok = s["status"] == "ok"
    m = analyse_run(folder) if ok else {}
    last = load_snapshot(snaps[-1]) if snaps else None
    n = s["scene_info"]["n_work"]
    diag = s.get("diagnostics", {})
    rec = dict(name=name, method=s["method"], feed_mm=1e3 * job["feed"], dp_nominal_mm=1e3 * job["dp"],
               dp_mm=1e3 * s["dp"], h_mm=1e3 * s["h"], n_particles=s["n_particles"], n_workpiece=n,
               n_steps=s["n_steps"], wall_time_s=s["wall_time_s"], cpu_time_s=s.get("cpu_time_s"),
               # pair-sum threads (Numerics.threads; 0 = all available cores; runs before it existed: 1)
               threads=s.get("threads", s["numerics"].get("threads", 1)), status=s["status"], error=s.get("error"),
               t_final_us=1e6 * s["t_final"], cut_length_mm=50.0 * s["t_final"] * 1e3,
               ref_update_strain=s["numerics"]["ref_update_strain"],
               contact=(s["numerics"].get("contact", "pinball") if s["method"] == "tlsph"
                        else "penalty" if s["numerics"].get("contact") == "penalty" else None),
               reference_updates=diag.get("reference_updates"),
               max_pinball_penetration_over_dp=(diag["max_pinball_penetration_m"] / s["dp"]
                                                if "max_pinball_penetration_m" in diag else None),
               max_penalty_penetration_over_dp=(diag["max_penalty_penetration_m"] / s["dp"]
                                                if "max_penalty_penetration_m" in diag else None))
    if last is not None:
        eps, T = last["eps_p"][:n], last["T"][:n]
        rec.update(max_plastic_strain_last_snapshot=float(eps.max()), plastic_strain_p99=float(np.percentile(eps, 99)),
                   temperature_p99_K=float(np.percentile(T, 99)))
        rec.update(flank_contact(last["x"][:n], last["x"][n:], s["dp"]))
    if ok:
        from refsph.scenes.cutting import lattice_shape, shear_bands
        info = s["scene_info"]
        x_tip = float(last["x"][n:, 0].min()) - 0.5 * info["dx"]
        rec["n_shear_bands_by_prominence"] = {
            f"{rp:g}": shear_bands(last["x"], last["eps_p"], *lattice_shape(info), info["dx"], info["dy"],
                                   info["feed_m"], x_tip, rel_prominence=rp)["n"] for rp in BAND_THRESHOLDS}
        fc, ft = np.asarray(m["cutting_force_history"]), np.asarray(m["thrust_force_history"])
        q3 = fc[(fc[:, 0] > 0.5 * s["t_end"]) & (fc[:, 0] <= 0.75 * s["t_end"]), 1].mean()
        q4 = fc[fc[:, 0] > 0.75 * s["t_end"], 1].mean()
        rec.update({k: m[k] for k in ("chip_thickness_mm", "shear_angle_from_chip_deg", "n_shear_bands",
                                      "band_spacing_mm", "band_spacing_material_mm", "band_angle_deg",
                                      "band_positions_mm", "band_angles_deg", "band_angles_current_deg",
                                      "max_plastic_strain", "max_temperature_K")})
        rec.update(cutting_force_mean_MN_per_m=1e-6 * m["cutting_force_mean_N_per_m"],
                   thrust_force_mean_MN_per_m=1e-6 * m["thrust_force_mean_N_per_m"],
                   cutting_force_drift=float(q4 / q3 - 1.0),
                   cutting_force_history_mm_MN_per_m=np.column_stack([_r(50.0 * fc[:, 0] * 1e3, 5),
                                                                      _r(1e-6 * fc[:, 1], 4)]).tolist(),
                   thrust_force_history_mm_MN_per_m=np.column_stack([_r(50.0 * ft[:, 0] * 1e3, 5),
                                                                     _r(1e-6 * ft[:, 1], 4)]).tolist(),
                   strain_along_chip_mm=np.column_stack([_r(np.asarray(m["strain_along_chip"])[:, 0], 4),
                                                         _r(np.asarray(m["strain_along_chip"])[:, 1], 4)]).tolist())
    return rec


def _time(r) -> float:
    """The run's CPU time where recorded (the single-core cost, whatever else ran on the machine), else wall."""
    return r["cpu_time_s"] if r.get("cpu_time_s") else r["wall_time_s"]


def add_differences(records):
    """vs_paper: relative differences of the force means and the chip thickness to the dp = 0.01 mm run of the
    same method and feed (the coarse runs' distance to the paper's resolution, for the work-precision plot)."""
    ref = {(r["method"], r["feed_mm"]): r for r in records if r["name"].startswith("paper-") and r["status"] == "ok"}
    for r in records:
        p = ref.get((r["method"], r["feed_mm"]))
        if p is None or r is p or r["status"] != "ok" or r["ref_update_strain"] is None or is_penalty(r):
            continue
        r["vs_paper"] = dict(ref=p["name"],
                             cutting_force_rel=r["cutting_force_mean_MN_per_m"] / p["cutting_force_mean_MN_per_m"] - 1,
                             thrust_force_rel=r["thrust_force_mean_MN_per_m"] / p["thrust_force_mean_MN_per_m"] - 1,
                             chip_thickness_rel=r["chip_thickness_mm"] / p["chip_thickness_mm"] - 1,
                             wall_time_ratio=r["wall_time_s"] / p["wall_time_s"],
                             time_ratio=_time(r) / _time(p))
    return records


def flank_contact(xw, xt, dp) -> dict:
    """The new surface under the tool's clearance (bottom) face at the end of a run: the workpiece particles under
    the face and within 1.5 dp of its row of particles, and their mean gap to it in spacings (about 1: the
    pinballs, radius dp / 2 each, touch at one spacing)."""
    face_y, left = xt[:, 1].min(), xt[:, 0].min()
    under = (xw[:, 0] > left) & (xw[:, 1] < face_y) & (xw[:, 1] > face_y - 1.5 * dp)
    gap = (face_y - xw[under, 1]) / dp
    return dict(flank_particles=int(under.sum()), flank_gap_over_dp=float(gap.mean()) if under.any() else None)


def add_reruns(records, runs, label):
    """vs_rerun: the same paper-resolution run made by other code (in folder runs, e.g. an earlier commit whose
    arithmetic differs from this one's by round-off only): how far such a rerun moves each measurement. This is
    the tolerance a comparison of two implementations of the same equations can expect."""
    jobs = {j["name"]: j for j in job_list()}
    for r in records:
        if not r["name"].startswith("paper-") or r["status"] != "ok":
            continue
        if not (Path(runs) / r["name"] / "summary.json").exists():
            continue
        o = record(jobs[r["name"]], runs)
        if o["status"] != "ok":
            continue
        rel = lambda k: r[k] / o[k] - 1 if r.get(k) is not None and o.get(k) not in (None, 0) else None  # noqa: E731
        r["vs_rerun"] = dict(runs=label, cutting_force_rel=rel("cutting_force_mean_MN_per_m"),
                             thrust_force_rel=rel("thrust_force_mean_MN_per_m"),
                             chip_thickness_rel=rel("chip_thickness_mm"),
                             n_shear_bands=[o["n_shear_bands"], r["n_shear_bands"]],
                             band_spacing_material_mm=[o["band_spacing_material_mm"], r["band_spacing_material_mm"]],
                             band_angle_deg=[o["band_angle_deg"], r["band_angle_deg"]],
                             plastic_strain_p99=[o.get("plastic_strain_p99"), r.get("plastic_strain_p99")],
                             flank_particles=[o.get("flank_particles"), r.get("flank_particles")],
                             flank_gap_over_dp=[o.get("flank_gap_over_dp"), r.get("flank_gap_over_dp")],
                             n_steps=[o["n_steps"], r["n_steps"]], reference_updates=[o["reference_updates"],
                                                                                     r["reference_updates"]])
    return records


def write_json(records) -> bool:
    """One record per line (compact arrays), so that a change shows in git as the runs that changed; strict
    JSON (a measurement that could not be made, e.g. the spacing of a single band, is null). Written only if it
    changed; True if it was."""
    from refsph.io import json_ready
    return study.write_if_changed(OUT_JSON, "[\n" + ",\n".join(json.dumps(json_ready(r), allow_nan=False)
                                                                for r in records) + "\n]\n")


def table(records) -> str:
    f = lambda v, fmt: "-" if v is None or (isinstance(v, float) and not np.isfinite(v)) else format(v, fmt)  # noqa: E731
    lines = [f"{'run':26s} {'N':>6s} {'steps':>6s} {'wall s':>7s} {'cpu s':>7s} {'upd':>4s} {'status':>6s} "
             f"{'Fc':>6s} {'Ft':>6s} "
             f"{'drift':>6s} {'chip':>6s} {'phi_c':>5s} {'bands':>5s} {'spac':>6s} {'spac0':>6s} {'angle':>5s} "
             f"{'eps max':>7s} {'eps p99':>7s} {'T max':>6s}"]
    for r in records:
        lines.append(f"{r['name']:26s} {r['n_particles']:6d} {r['n_steps']:6d} {r['wall_time_s']:7.0f} "
                     f"{f(r.get('cpu_time_s'), '7.0f'):>7s} "
                     f"{f(r['reference_updates'], 'd'):>4s} {r['status']:>6s} "
                     f"{f(r.get('cutting_force_mean_MN_per_m'), '.3f'):>6s} "
                     f"{f(r.get('thrust_force_mean_MN_per_m'), '.3f'):>6s} "
                     f"{f(r.get('cutting_force_drift'), '+.2f'):>6s} {f(r.get('chip_thickness_mm'), '.3f'):>6s} "
                     f"{f(r.get('shear_angle_from_chip_deg'), '.0f'):>5s} {f(r.get('n_shear_bands'), 'd'):>5s} "
                     f"{f(r.get('band_spacing_mm'), '.3f'):>6s} {f(r.get('band_spacing_material_mm'), '.3f'):>6s} "
                     f"{f(r.get('band_angle_deg'), '.0f'):>5s} {f(r.get('max_plastic_strain'), '.1f'):>7s} "
                     f"{f(r.get('plastic_strain_p99'), '.2f'):>7s} {f(r.get('max_temperature_K'), '.0f'):>6s}")
    lines.append("Fc, Ft: cutting / thrust force on the tool [MN/m = kN per mm], mean over the 2nd half of the cut; "
                 "drift: mean Fc of the 4th quarter / 3rd quarter - 1; chip: thickness [mm]; phi_c: shear angle "
                 "atan(feed / chip) [deg]; spac / spac0: band spacing along the chip / in the uncut workpiece [mm]; "
                 "angle: median band angle to the cutting direction [deg]; upd: TLSPH reference updates")
    return "\n".join(lines)


SNAP_INSTANTS = (2, 4, 6, 8)          # snapshots at 1/4, 1/2, 3/4 and all of the cut (n_snapshots = 8)


def _picture(ax, z, dp, field, vmax, cmap="jet", vmin=0.0, xlim=(1.3, 3.6), ylim=(0.25, 2.15)):
    from refsph.teaching.plots import particle_field
    # the committed figures were drawn with jet and squares 1.15 spacings wide; the next rerun of the paper-resolution
    # runs (about 2 CPU-hours each pair) should draw them with the defaults (viridis, 1.5: no gaps)
    return particle_field(ax, z["x"], z[field], dp, body=z["body"], xlim=xlim, ylim=ylim, cmap=cmap, vmin=vmin,
                          vmax=vmax, spread=1.15, fill=None)


def strain_figure(by: dict, feed: float) -> None:
    """figures/08_cutting_strain_fFEED.png: plastic strain of the paper-resolution runs (records ``by`` name) at four
    instants, ESPH above TLSPH (the paper's Figs. 12-13 and 17-18), in the slide style: viridis, squares 1.5
    spacings wide (no gaps in the stretched chip), a labelled colour bar. ``--strain-figure FEED`` draws only this,
    from the run folders, and touches nothing else."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from refsph.io import load_snapshot
    from refsph.teaching.plots import particle_field

    fig = plt.figure(figsize=(16, 7.6))
    axs = fig.subplots(2, 4, gridspec_kw=dict(left=0.04, right=0.92, bottom=0.07, top=0.88, wspace=0.08,
                                              hspace=0.3))
    sc = None
    for row, m in enumerate(("esph", "tlsph")):
        r = by.get(f"paper-{m}-f{feed * 1e3:g}")
        if r is None:
            continue
        _, snaps = load(r["name"])
        for col, k in enumerate(SNAP_INSTANTS):
            ax = axs[row, col]
            if k >= len(snaps):
                ax.set_title(f"{m.upper()}: no snapshot ({r['status']})")
                continue
            z = load_snapshot(snaps[k])
            sc = particle_field(ax, z["x"], z["eps_p"], r["dp_mm"] * 1e-3, body=z["body"], xlim=(1.3, 3.6),
                                ylim=(0.25, 2.15), vmin=0.0, vmax=3.0)
            ax.set_title(f"{m.upper()}, cut {50.0 * z['t'] * 1e3:.2f} mm")
            ax.set_xlabel("x [mm]")
        axs[row, 0].set_ylabel("y [mm]")
    if sc is not None:
        fig.colorbar(sc, cax=fig.add_axes([0.93, 0.2, 0.01, 0.6]), extend="max",
                     label="effective plastic strain [-] (scale cut at 3)")
    fig.suptitle(f"Orthogonal cutting, feed {feed * 1e3:g} mm, dp = 0.01 mm: chip and plastic strain at four "
                 f"instants (cf. the paper's Figs. {'12-13' if feed < 0.4e-3 else '17-18'}); grey: the tool's "
                 "surface layers", fontsize=12)
    study.save_figure(fig, FIG / f"08_cutting_strain_f{feed * 1e3:g}.png", dpi=110)


def plots(records, folders=()):
    """The figures: those drawn from run folders only where every run they show (of those with a record) is in
    ``folders``, the runs recorded from their folders in this call; those drawn from the records always (a figure
    whose pixels did not change is not written)."""
    import matplotlib
    matplotlib.use("Agg")
    FIG.mkdir(exist_ok=True)
    by = {r["name"]: r for r in records}

    def from_folders(names, figure) -> bool:
        shown = {n for n in names if n in by}
        if shown and shown <= set(folders):
            return True
        if shown & set(folders):
            print(f"{figure} figure not redrawn: it needs the run folders of {', '.join(sorted(shown - set(folders)))}")
        return False
    paper = [f"paper-{m}-f{f * 1e3:g}" for m in METHODS for f in FEEDS]
    # Figs. 12-13 and 17-18: plastic strain at four instants, ESPH above TLSPH, one figure per feed
    for feed in FEEDS:
        if from_folders([n for n in paper if n.endswith(f"-f{feed * 1e3:g}")], f"strain f{feed * 1e3:g}"):
            strain_figure(by, feed)
    if from_folders(paper, "temperature"):
        temperature_figure(by)
    forces_figure([r for r in records if r["name"].startswith("paper-")])
    bands_figure(by)
    work_precision_figure(records)
    if from_folders(["coarse-tlsph-f0.3-25um", "noupdate-tlsph-f0.3-25um"], "reference-updates"):
        reference_updates_figure(by)
    contact_figure(records)


COLORS = dict(esph="C0", tlsph="C3")


def temperature_figure(by):
    """Figs. 14-15: temperature at the end of the cut, both methods and feeds."""
    import matplotlib.pyplot as plt
    from refsph.io import load_snapshot
    fig = plt.figure(figsize=(9, 8))
    axs = fig.subplots(2, 2, gridspec_kw=dict(left=0.07, right=0.88, bottom=0.06, top=0.9, wspace=0.1,
                                              hspace=0.25))
    sc = None
    for row, m in enumerate(("esph", "tlsph")):
        for col, feed in enumerate(FEEDS):
            r = by.get(f"paper-{m}-f{feed * 1e3:g}")
            if r is None:
                continue
            _, snaps = load(r["name"])
            z = load_snapshot(snaps[-1])
            sc = _picture(axs[row, col], z, r["dp_mm"] * 1e-3, "T", 1573.0, cmap="inferno", vmin=298.0)
            axs[row, col].set_title(f"{m.upper()}, feed {feed * 1e3:g} mm, cut {50.0 * z['t'] * 1e3:.2f} mm",
                                    fontsize=9)
            axs[row, col].tick_params(labelsize=7)
    if sc is not None:
        fig.colorbar(sc, cax=fig.add_axes([0.9, 0.2, 0.015, 0.6]), label="temperature [K] (298 K to T_melt)")
    fig.suptitle("Temperature at the end of the cut, dp = 0.01 mm (cf. Figs. 14-15; adiabatic: 90 % of the "
                 "plastic work heats the particle, no conduction)", fontsize=10)
    study.save_figure(fig, FIG / "08_cutting_temperature.png", dpi=110)


def forces_figure(paper):
    """Forces against cut length."""
    import matplotlib.pyplot as plt
    colors = COLORS
    fig, axs = plt.subplots(1, 2, figsize=(12, 4.2), constrained_layout=True, sharey=True)
    for ax, key, label in ((axs[0], "cutting_force_history_mm_MN_per_m", "cutting force Fc"),
                           (axs[1], "thrust_force_history_mm_MN_per_m", "thrust force Ft")):
        for r in paper:
            if key not in r:
                continue
            h = np.asarray(r[key])
            k = min(9, len(h))
            ax.plot(h[:, 0], np.convolve(h[:, 1], np.ones(k) / k, mode="same"), color=colors[r["method"]],
                    ls="-" if r["feed_mm"] < 0.4 else "--", lw=1.3,
                    label=f"{r['method'].upper()}, feed {r['feed_mm']:g} mm")
        ax.set_xlabel("cut length [mm]")
        ax.set_title(f"{label} on the tool (running mean over 9 bins of 2.5 um)", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axs[0].set_ylabel("force per unit thickness [MN/m = kN/mm]")
    fig.suptitle("Orthogonal cutting, dp = 0.01 mm: forces (the means are taken over the 2nd half)", fontsize=10)
    study.save_figure(fig, FIG / "08_cutting_forces.png", dpi=120)


def bands_figure(by):
    """The band measurement: plastic strain along the chip (middle row of the cut layer) with the bands found."""
    import matplotlib.pyplot as plt
    colors = COLORS
    fig, axs = plt.subplots(2, 2, figsize=(12, 6.5), constrained_layout=True, sharex=True)
    for row, m in enumerate(("esph", "tlsph")):
        for col, feed in enumerate(FEEDS):
            r = by.get(f"paper-{m}-f{feed * 1e3:g}")
            ax = axs[row, col]
            if r is None or "strain_along_chip_mm" not in r:
                continue
            p = np.asarray(r["strain_along_chip_mm"])
            ax.plot(p[:, 0], p[:, 1], color=colors[m], lw=1)
            inner = p[p[:, 0] < p[-1, 0] - 0.05, 1]           # the entry corner (last 0.05 mm) can dwarf the bands
            if len(inner):
                ax.set_ylim(0.0, 1.25 * inner.max())
            for xb in r["band_positions_mm"]:
                ax.axvline(xb, color="k", lw=0.6, ls=":")
            ax.set_title(f"{m.upper()}, feed {feed * 1e3:g} mm: {r['n_shear_bands']} bands, spacing "
                         f"{r['band_spacing_material_mm']:.3f} mm (uncut) / {r['band_spacing_mm']:.3f} mm (chip), "
                         f"angle {r['band_angle_deg']:.0f} deg", fontsize=9)
            ax.grid(alpha=0.3)
            if row == 1:
                ax.set_xlabel("initial x of the material [mm] (the tool moved from 3 to 2 mm)")
            if col == 0:
                ax.set_ylabel("eps_p, middle row of the cut layer")
    fig.suptitle("Shear bands: peaks of the plastic strain along the chip (dotted: the bands counted; the strain at "
                 "the entry corner, x near 3 mm, runs off the scale)", fontsize=10)
    study.save_figure(fig, FIG / "08_cutting_bands.png", dpi=120)


def work_precision_figure(records):
    """Work-precision: the coarse runs' distance to dp = 0.01 mm against wall time, feed 0.3 mm (from the records
    alone)."""
    import matplotlib.ticker
    import matplotlib.pyplot as plt
    colors, by = COLORS, {r["name"]: r for r in records}
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for ax, key, label in ((axs[0], "cutting_force_rel", "mean cutting force"),
                           (axs[1], "chip_thickness_rel", "chip thickness")):
        for m in METHODS:
            rs = sorted([r for r in records if r["method"] == m and "vs_paper" in r and abs(r["feed_mm"] - 0.3) < 1e-9],
                        key=lambda r: r["wall_time_s"])
            if not rs:
                continue
            ax.loglog([_time(r) for r in rs], [max(100 * abs(r["vs_paper"][key]), 1e-2) for r in rs], "o-",
                      color=colors[m], label=m.upper())
            for r in rs:
                ax.annotate(f"{1e3 * r['dp_nominal_mm']:.3g} um", (_time(r), max(100 * abs(r["vs_paper"][key]), 1e-2)),
                            textcoords="offset points", xytext=(4, 4), fontsize=8, color=colors[m])
            p = by.get(f"paper-{m}-f0.3")
            if p is not None:
                ax.axvline(_time(p), color=colors[m], ls=":", lw=1, label=f"{m.upper()} at 0.01 mm (reference)")
        ax.set_xlabel("CPU time [s] (one core; wall time where no CPU time was recorded)")
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
            axis.set_minor_formatter(matplotlib.ticker.FuncFormatter(
                lambda v, _: f"{v:g}" if f"{v:.0e}"[0] in "25" else ""))
        ax.set_ylabel("|difference to dp = 0.01 mm| [%]")
        ax.set_title(f"{label}, feed 0.3 mm, 1 mm of cut", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    study.save_figure(fig, FIG / "08_cutting_work_precision.png", dpi=120)


def reference_updates_figure(by):
    """TLSPH with and without reference-configuration updates (reduced size): both at the same cut length, and the
    run without updates at its end (its last good state if it failed)."""
    import matplotlib.pyplot as plt
    from refsph.io import load_snapshot
    pair = [by.get("coarse-tlsph-f0.3-25um"), by.get("noupdate-tlsph-f0.3-25um")]
    if all(pair):
        with_upd, without = pair
        (_, snaps_w), (_, snaps_n) = load(with_upd["name"]), load(without["name"])
        last = RUNS / without["name"] / "snapshots" / "last_good.npz"
        z_end = load_snapshot(last if without["status"] != "ok" and last.exists() else snaps_n[-1])
        z_n = [load_snapshot(p) for p in snaps_n]
        z_w = [load_snapshot(p) for p in snaps_w]
        near = 1e-8                 # snapshots land on the first step past their time: equal within 10 ns
        t_common = max(z["t"] for z in z_n if any(abs(z["t"] - w["t"]) < near for w in z_w))
        panels = [(with_upd, next(z for z in z_w if abs(z["t"] - t_common) < near), "with"),
                  (without, next(z for z in z_n if abs(z["t"] - t_common) < near), "without"),
                  (without, z_end, "without")]
        fig = plt.figure(figsize=(14, 4.8))
        axs = fig.subplots(1, 3, gridspec_kw=dict(left=0.05, right=0.9, bottom=0.1, top=0.8, wspace=0.12))
        for ax, (r, z, upd) in zip(axs, panels):
            sc = _picture(ax, z, r["dp_mm"] * 1e-3, "eps_p", 3.0, xlim=(1.9, 3.4), ylim=(0.3, 1.6))
            end = ""
            if z is z_end and r["status"] != "ok":
                end = f" (last good state: the run stopped, {r['status']})"
            ax.set_title(f"TLSPH {upd} reference updates ({r['reference_updates']}),\ncut {50.0 * z['t'] * 1e3:.3f} mm"
                         f"{end}, max eps_p {z['eps_p'][:r['n_workpiece']].max():.1f}", fontsize=8)
        fig.colorbar(sc, cax=fig.add_axes([0.92, 0.2, 0.012, 0.55]), extend="max", label="effective plastic strain")
        fig.suptitle(f"Reduced size (dp = {with_upd['dp_nominal_mm']:.3g} mm, feed {with_upd['feed_mm']:g} mm): "
                     "the chip "
                     "with and without updates of the reference configuration", fontsize=10)
        study.save_figure(fig, FIG / "08_cutting_reference_updates.png", dpi=120)


def _contact_pairs(records, method: str = "tlsph"):
    """(paper-METHOD run, penalty-METHOD run) of each feed both have, the paper's contact first."""
    by = {r["name"]: r for r in records}
    return [(by[r["name"].replace("penalty-", "paper-")], r) for r in records
            if is_penalty(r) and r["method"] == method and r["name"].replace("penalty-", "paper-") in by]


def contact_figure(records):
    """figures/08_cutting_contact_forces.png: TLSPH's cutting and thrust force with the paper's pinball contact and
    with the penalty contact, both feeds, dp = 0.01 mm (from the records alone)."""
    pairs = [(a, b) for a, b in _contact_pairs(records) if "cutting_force_history_mm_MN_per_m" in b]
    if not pairs:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(12, 4.2), constrained_layout=True, sharey=True)
    for ax, key, label in ((axs[0], "cutting_force_history_mm_MN_per_m", "cutting force Fc"),
                           (axs[1], "thrust_force_history_mm_MN_per_m", "thrust force Ft")):
        for pair in pairs:
            for r, c, contact in zip(pair, ("C3", "C2"), ("pinball", "penalty")):
                h = np.asarray(r[key])
                k = min(9, len(h))
                ax.plot(h[:, 0], np.convolve(h[:, 1], np.ones(k) / k, mode="same"), color=c,
                        ls="-" if r["feed_mm"] < 0.4 else "--", lw=1.3, label=f"{contact}, feed {r['feed_mm']:g} mm")
        ax.set_xlabel("cut length [mm]")
        ax.set_title(f"{label} on the tool (running mean over 9 bins of 2.5 um)", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axs[0].set_ylabel("force per unit thickness [MN/m = kN/mm]")
    fig.suptitle("Orthogonal cutting, TLSPH, dp = 0.01 mm: the paper's pinball contact against the penalty contact",
                 fontsize=10)
    study.save_figure(fig, FIG / "08_cutting_contact_forces.png", dpi=120)


TARGET_S = 30 * 60      # the issue's target: 1 mm of cut at the paper's resolution in 30 minutes (two cores)


_v = study.fmt            # a report cell: '-' for a measure that could not be made (null in the JSON)
_md_table = study.md_table


def _fig(name: str, caption: str) -> str:
    return f"![{caption}](../figures/{name})" if (FIG / name).exists() else f"({name}: not made yet)"


def _ratio(a, b):
    return a / b if a is not None and b not in (None, 0) else None


def _pct(v) -> str:
    return _v(v, "+.1f", 100.0)


def report(records) -> str:
    """benchmarks/cutting_report.md: the study as text, every number from the records of cutting.json; the prose is
    benchmarks/templates/cutting_report.md."""
    P = study.Page("cutting_report")
    ok = [r for r in records if r["status"] == "ok"]
    paper = [r for r in ok if r["name"].startswith("paper-")]
    out = _report_runs(P, records, ok, paper)
    pinball = [r for r in ok if not is_penalty(r)]        # the penalty runs have a section of their own
    out += _report_feed(P, {r["name"]: r for r in records if not is_penalty(r)}, pinball)
    out += _report_thrust(P, pinball)
    out += _report_noupdate(P, {r["name"]: r for r in records})
    out += _report_rerun(P, paper)
    out += _report_cost(P, paper)
    out += _report_coarse(P, ok)
    out += _report_contact(P, records)
    return "\n".join(out)


def _pair(a, b, key, spec, scale=1.0) -> str:
    """'pinball / penalty' of one measure."""
    return f"{_v(a.get(key), spec, scale)} / {_v(b.get(key), spec, scale)}"


def _report_contact(P, records) -> list[str]:
    """TLSPH's tool contact: the paper runs (pinballs) against the same runs with the penalty contact; then ESPH's
    (:func:`_report_contact_esph`)."""
    pairs = _contact_pairs(records)
    if not pairs:
        return _report_contact_esph(P, records)
    rel = lambda a, b: None if _ratio(b, a) is None else _ratio(b, a) - 1  # noqa: E731
    rows = [[_v(b["feed_mm"], "g"), f"{a['status']} / {b['status']}", _pair(a, b, "cut_length_mm", ".2f"),
             _pair(a, b, "cutting_force_mean_MN_per_m", ".3f"),
             _pct(rel(a.get("cutting_force_mean_MN_per_m"), b.get("cutting_force_mean_MN_per_m"))),
             _pair(a, b, "thrust_force_mean_MN_per_m", ".3f"), _pair(a, b, "chip_thickness_mm", ".3f"),
             _pair(a, b, "n_shear_bands", "d"), _pair(a, b, "max_plastic_strain", ".1f"),
             _pair(a, b, "plastic_strain_p99", ".2f"), _pair(a, b, "flank_gap_over_dp", ".2f"),
             _pair(a, b, "n_steps", "d"), _pair(a, b, "threads", "d"), _pair(a, b, "wall_time_s", ".1f", 1 / 60),
             _pair(a, b, "cpu_time_s", ".1f", 1 / 60)] for a, b in pairs]
    out = [P("contact"), "", _md_table(
        ["feed [mm]", "status", "cut [mm]", "Fc", "Fc penalty / pinball - 1 [%]", "Ft", "chip [mm]", "bands",
         "eps_p max", "eps_p p99", "flank gap / dp", "steps", "threads", "wall [min]", "CPU [min]"], rows)]
    good = [(a, b) for a, b in pairs if a["status"] == "ok" and b["status"] == "ok"]
    if not good:
        return out + ["", P("contact_failed"), ""] + _report_contact_esph(P, records)
    fc = [b["cutting_force_mean_MN_per_m"] / a["cutting_force_mean_MN_per_m"] - 1 for a, b in good]
    ft = [b["thrust_force_mean_MN_per_m"] / a["thrust_force_mean_MN_per_m"] - 1 for a, b in good]
    ch = [b["chip_thickness_mm"] / a["chip_thickness_mm"] - 1 for a, b in good]
    cpu = [_time(b) / _time(a) for a, b in good]
    span = lambda xs: f"{_pct(xs[0])} %" if len(xs) == 1 else f"{_pct(min(xs))} % to {_pct(max(xs))} %"  # noqa: E731
    each = lambda key, spec: ", ".join(f"{_v(a.get(key), spec)} -> {_v(b.get(key), spec)}"  # noqa: E731
                                       for a, b in good)
    return out + ["", P("contact_end", fc=span(fc), ft=span(ft), chip=span(ch), bands=each("n_shear_bands", "d"),
                        ft_each=each("thrust_force_mean_MN_per_m", ".3f"), gap=each("flank_gap_over_dp", ".2f"),
                        eps_max=each("max_plastic_strain", ".1f"), p99=each("plastic_strain_p99", ".2f"),
                        cpu=", ".join(_v(c, ".2f") for c in cpu),
                        figure=_fig("08_cutting_contact_forces.png", "forces, pinball against penalty contact")),
                  ""] + _report_contact_esph(P, records)


def _report_contact_esph(P, records) -> list[str]:
    """ESPH's tool: the paper runs (the tool's particles in the SPH sums) against the same runs with the penalty
    contact, and the two methods' penalty runs side by side."""
    pairs = _contact_pairs(records, "esph")
    if not pairs:
        return []
    rows = [[_v(b["feed_mm"], "g"), f"{a['status']} / {b['status']}", _pair(a, b, "cut_length_mm", ".2f"),
             _pair(a, b, "cutting_force_mean_MN_per_m", ".3f"), _pair(a, b, "thrust_force_mean_MN_per_m", ".3f"),
             _pair(a, b, "chip_thickness_mm", ".3f"), _pair(a, b, "n_shear_bands", "d"),
             _pair(a, b, "max_plastic_strain", ".1f"), _pair(a, b, "plastic_strain_p99", ".2f"),
             _pair(a, b, "flank_gap_over_dp", ".2f"), _pair(a, b, "n_steps", "d"),
             _pair(a, b, "cpu_time_s", ".1f", 1 / 60)] for a, b in pairs]
    out = [P("contact_esph"), "", _md_table(
        ["feed [mm]", "status", "cut [mm]", "Fc", "Ft", "chip [mm]", "bands", "eps_p max", "eps_p p99",
         "flank gap / dp", "steps", "CPU [min]"], rows)]
    tl = {r["feed_mm"]: r for _, r in _contact_pairs(records) if r["status"] == "ok"}
    good = [(a, b) for a, b in pairs if a["status"] == "ok" and b["status"] == "ok"]
    if not good:
        return out + ["", P("contact_failed"), ""]
    each = lambda key, spec: ", ".join(f"{_v(a.get(key), spec)} -> {_v(b.get(key), spec)}"  # noqa: E731
                                       for a, b in good)
    def side(b, key):                                          # ESPH's value 'against' TLSPH's, same feed
        return f"{_v(b[key], '.3f')} against {_v(tl[b['feed_mm']][key], '.3f')}"
    methods = "; ".join(f"feed {_v(b['feed_mm'], 'g')} mm: Fc {side(b, 'cutting_force_mean_MN_per_m')} MN/m, chip "
                        f"{side(b, 'chip_thickness_mm')} mm" for _, b in good if b["feed_mm"] in tl) or "-"
    return out + ["", P("contact_esph_end", fc=each("cutting_force_mean_MN_per_m", ".3f"),
                        ft=each("thrust_force_mean_MN_per_m", ".3f"), chip=each("chip_thickness_mm", ".3f"),
                        bands=each("n_shear_bands", "d"), eps_max=each("max_plastic_strain", ".1f"),
                        methods=methods), ""]


def _report_runs(P, records, ok, paper) -> list[str]:
    """What was run, the results table and how to read it."""
    from refsph.paper_data import CUTTING_OBSERVED
    from refsph.scenes.cutting import BAND_REL_PROMINENCE
    angle_paper = f"{CUTTING_OBSERVED['band_angle_deg']:g}"
    out = [P("head"), "", _md_table(
        ["run", "method", "feed [mm]", "dp [mm]", "h [mm]", "particles", "steps", "cut [mm]", "ref. update at",
         "threads", "status"],
        [[r["name"], r["method"].upper(), _v(r["feed_mm"], "g"), _v(r["dp_mm"], ".4g"), _v(r["h_mm"], ".4g"),
          r["n_particles"], r["n_steps"], _v(r["cut_length_mm"], ".2f"), _v(r["ref_update_strain"], "g"),
          r.get("threads", "-"), r["status"]] for r in records])]
    out += ["", P("results", band_prominence=f"{BAND_REL_PROMINENCE:g}", angle_paper=angle_paper), "", _md_table(
        ["run", "Fc", "Ft", "Ft/Fc", "drift", "chip", "phi_c", "bands", "spacing chip", "spacing uncut", "angle",
         "eps_p max", "eps_p p99", "T max", "T p99"],
        [[r["name"], _v(r.get("cutting_force_mean_MN_per_m"), ".3f"), _v(r.get("thrust_force_mean_MN_per_m"), ".3f"),
          _v(_ratio(r.get("thrust_force_mean_MN_per_m"), r.get("cutting_force_mean_MN_per_m")), ".2f"),
          _v(r.get("cutting_force_drift"), "+.3f"), _v(r.get("chip_thickness_mm"), ".3f"),
          _v(r.get("shear_angle_from_chip_deg"), ".0f"), _v(r.get("n_shear_bands"), "d"),
          _v(r.get("band_spacing_mm"), ".3f"), _v(r.get("band_spacing_material_mm"), ".3f"),
          _v(r.get("band_angle_deg"), ".0f"), _v(r.get("max_plastic_strain"), ".1f"),
          _v(r.get("plastic_strain_p99"), ".2f"), _v(r.get("max_temperature_K"), ".0f"),
          _v(r.get("temperature_p99_K"), ".0f")] for r in ok])]
    drift = max(abs(r["cutting_force_drift"]) for r in paper) if paper else None
    phi = [r["shear_angle_from_chip_deg"] for r in paper]
    angles = [r["band_angle_deg"] for r in paper if r.get("band_angle_deg") is not None]
    return out + ["", P("how_to_read", drift=_v(drift, ".1%"), phi_min=_v(min(phi, default=None), ".0f"),
                        phi_max=_v(max(phi, default=None), ".0f"), angle_paper=angle_paper,
                        angle_min=_v(min(angles, default=None), ".0f"), angle_max=_v(max(angles, default=None), ".0f"),
                        fig_strain_3=_fig("08_cutting_strain_f0.3.png", "plastic strain, feed 0.3 mm"),
                        fig_strain_5=_fig("08_cutting_strain_f0.5.png", "plastic strain, feed 0.5 mm"),
                        fig_temperature=_fig("08_cutting_temperature.png", "temperature"),
                        fig_forces=_fig("08_cutting_forces.png", "forces"),
                        fig_bands=_fig("08_cutting_bands.png", "shear bands")), ""]


def _report_feed(P, by, ok) -> list[str]:
    """The paper's trend with the feed, and the band count against its threshold."""
    from refsph.paper_data import CUTTING_OBSERVED
    from refsph.scenes.cutting import BAND_REL_PROMINENCE
    rows = []
    for r3 in [r for r in ok if abs(r["feed_mm"] - 0.3) < 1e-9]:
        r5 = by.get(r3["name"].replace("-f0.3", "-f0.5"))
        if r5 is None or r5["status"] != "ok":
            continue
        fc = _ratio(r5["cutting_force_mean_MN_per_m"], r3["cutting_force_mean_MN_per_m"])
        n3, n5 = r3["n_shear_bands"], r5["n_shear_bands"]
        s3, s5 = r3.get("band_spacing_material_mm"), r5.get("band_spacing_material_mm")
        yes = lambda c, known: ("yes" if c else "no") if known else "cannot tell"  # noqa: E731
        rows.append([r3["name"].replace("-f0.3", "-f..."), _v(fc, ".2f"), _v(r5["feed_mm"] / r3["feed_mm"], ".2f"),
                     yes(fc > 1, True), f"{n3} -> {n5}", yes(n5 < n3, True),
                     f"{_v(s3, '.3f')} -> {_v(s5, '.3f')}", yes(s3 is not None and s5 is not None and s5 > s3,
                                                               s3 is not None and s5 is not None),
                     f"{_v(r3['chip_thickness_mm'], '.3f')} -> {_v(r5['chip_thickness_mm'], '.3f')}"])
    out = [P("deeper_feed", deeper_feed=CUTTING_OBSERVED["deeper_feed"]), "",
           _md_table(["runs", "Fc ratio", "feed ratio", "larger force", "bands", "fewer bands",
                      "spacing uncut [mm]", "wider spacing", "chip [mm]"], rows)]
    grows = all(float(row[1]) > 1 for row in rows)
    out += ["", P("deeper_feed_end", grows="at every spacing" if grows else "not in every pair of runs",
                  band_prominence=f"{BAND_REL_PROMINENCE:g}"), ""]
    thr = sorted({k for r in ok for k in (r.get("n_shear_bands_by_prominence") or {})}, key=float)
    out.append(_md_table(["run"] + [f"threshold {t}" for t in thr],
                         [[r["name"]] + [r["n_shear_bands_by_prominence"].get(t, "-") for t in thr]
                          for r in ok if r.get("n_shear_bands_by_prominence")]))
    return out + ["", P("threshold_end"), ""]


def _report_thrust(P, ok) -> list[str]:
    """The thrust and the clearance face."""
    out = [P("thrust"), "", _md_table(
        ["run", "Ft/Fc", "particles under the face", "mean gap / dp"],
        [[r["name"], _v(_ratio(r["thrust_force_mean_MN_per_m"], r["cutting_force_mean_MN_per_m"]), ".2f"),
          _v(r.get("flank_particles"), "d"), _v(r.get("flank_gap_over_dp"), ".2f")] for r in ok])]
    esph_free = all(r.get("flank_particles") == 0 for r in ok if r["method"] == "esph")
    return out + ["", P("thrust_end", esph_free=P("thrust_esph_free") + " " if esph_free else ""), ""]


def _report_noupdate(P, by) -> list[str]:
    """TLSPH with and without reference updates."""
    nu, wu = by.get("noupdate-tlsph-f0.3-25um"), by.get("coarse-tlsph-f0.3-25um")
    if nu is None or wu is None:
        return []
    out = [P("noupdate"), "", _md_table(
        ["run", "status", "cut [mm]", "updates", "eps_p max (last state)", "eps_p p99",
         "deepest pinball penetration / dp", "Fc"],
        [[r["name"], r["status"], _v(r["cut_length_mm"], ".2f"), _v(r["reference_updates"], "d"),
          _v(r.get("max_plastic_strain_last_snapshot"), ".1f"), _v(r.get("plastic_strain_p99"), ".2f"),
          _v(r.get("max_pinball_penetration_over_dp"), ".2f"), _v(r.get("cutting_force_mean_MN_per_m"), ".3f")]
         for r in (wu, nu)])]
    return out + ["", P("noupdate_end", status=nu["status"], error=(nu.get("error") or "").split(" (")[0],
                        figure=_fig("08_cutting_reference_updates.png", "TLSPH with and without reference updates")),
                  ""]


def _report_rerun(P, paper) -> list[str]:
    """Reproducibility: the paper runs against the same runs made by other code (vs_rerun)."""
    rr = [r for r in paper if r.get("vs_rerun")]
    if not rr:
        return []
    out = [P("rerun", runs=rr[0]["vs_rerun"]["runs"]), "", _md_table(
        ["run", "Fc [%]", "Ft [%]", "chip [%]", "bands", "spacing uncut [mm]", "angle [deg]", "eps_p p99",
         "particles under the face", "steps", "updates"],
        [[r["name"], _pct(d["cutting_force_rel"]), _pct(d["thrust_force_rel"]), _pct(d["chip_thickness_rel"]),
          f"{d['n_shear_bands'][0]} -> {d['n_shear_bands'][1]}",
          f"{_v(d['band_spacing_material_mm'][0], '.3f')} -> {_v(d['band_spacing_material_mm'][1], '.3f')}",
          f"{_v(d['band_angle_deg'][0], '.0f')} -> {_v(d['band_angle_deg'][1], '.0f')}",
          f"{_v(d['plastic_strain_p99'][0], '.2f')} -> {_v(d['plastic_strain_p99'][1], '.2f')}",
          f"{_v(d['flank_particles'][0], 'd')} -> {_v(d['flank_particles'][1], 'd')}",
          f"{d['n_steps'][0]} -> {d['n_steps'][1]}",
          f"{_v(d['reference_updates'][0], 'd')} -> {_v(d['reference_updates'][1], 'd')}"]
         for r in rr for d in [r["vs_rerun"]]])]
    fc = max(abs(r["vs_rerun"]["cutting_force_rel"]) for r in rr)
    ch = max(abs(r["vs_rerun"]["chip_thickness_rel"]) for r in rr)
    dn = max(abs(r["vs_rerun"]["n_shear_bands"][1] - r["vs_rerun"]["n_shear_bands"][0]) for r in rr)
    ft = max(rr, key=lambda r: abs(r["vs_rerun"]["thrust_force_rel"]))
    return out + ["", P("rerun_end", fc=_v(fc, ".1%"), chip=_v(ch, ".1%"), bands=dn, thrust_run=ft["name"],
                        thrust=_pct(ft["vs_rerun"]["thrust_force_rel"])), ""]


def _report_cost(P, paper) -> list[str]:
    out = [P("cost", target_min=f"{TARGET_S / 60:.0f}"), "", _md_table(
        ["run", "particles", "steps", "cut [mm]", "wall [min]", "CPU [min]", "wall / target", "particle-steps/s"],
        [[r["name"], r["n_particles"], r["n_steps"], _v(r["cut_length_mm"], ".2f"), _v(r["wall_time_s"], ".1f", 1 / 60),
          _v(r.get("cpu_time_s"), ".1f", 1 / 60), _v(r["wall_time_s"] / TARGET_S, ".2f"),
          _v(r["n_particles"] * r["n_steps"] / r["wall_time_s"], ",.0f")] for r in paper])]
    met = all(r["wall_time_s"] <= TARGET_S for r in paper)
    return out + ["", P("cost_end", met="met by every run" if met else "not met by every run"), ""]


def _report_coarse(P, ok) -> list[str]:
    """Work-precision: the coarse runs against the paper's resolution."""
    wp = sorted([r for r in ok if r.get("vs_paper")], key=lambda r: (r["method"], r["feed_mm"], -r["dp_mm"]))
    if not wp:
        return []
    out = [P("coarse"), "", _md_table(
        ["run", "dp [mm]", "reference", "wall [min]", "wall share", "CPU share", "Fc [%]", "Ft [%]", "chip [%]"],
        [[r["name"], _v(r["dp_mm"], ".4g"), d["ref"], _v(r["wall_time_s"], ".1f", 1 / 60),
          _v(d["wall_time_ratio"], ".0%"), _v(d.get("time_ratio"), ".0%"), _pct(d["cutting_force_rel"]),
          _pct(d["thrust_force_rel"]), _pct(d["chip_thickness_rel"])] for r in wp for d in [r["vs_paper"]]])]
    return out + ["", P("coarse_end", fc=_v(max(abs(r["vs_paper"]["cutting_force_rel"]) for r in wp), ".0%"),
                        figure=_fig("08_cutting_work_precision.png", "work-precision")), ""]


def main(argv=None):
    global RUNS
    args = _parser().parse_args(argv)
    if args.report:
        wrote = study.write_if_changed(OUT_REPORT, report(json.loads(OUT_JSON.read_text())))
        print(f"{'wrote' if wrote else 'unchanged:'} {OUT_REPORT.relative_to(ROOT)}")
        return 0
    if args.json_figures:
        import matplotlib
        matplotlib.use("Agg")
        work_precision_figure(json.loads(OUT_JSON.read_text()))
        return 0
    if args.runs is not None:
        RUNS = Path(args.runs).resolve()
    if args.strain_figure is not None:
        return _strain_figure_only(args.strain_figure * 1e-3)
    jobs = [j for j in job_list() if args.only is None or args.only in j["name"]]
    ran = None
    if not args.plot_only:
        threads = study.threads_per_job(args.jobs)       # all cores for --jobs 1, one each for --jobs 2
        ran = set()
        for name, done in study.execute(run_job, {j["name"]: (dict(j, threads=threads),) for j in jobs}, args.jobs):
            if done != name:                              # it could not run: its folder is no result of this call
                print(f"{name}: {done['status']}", flush=True)
            else:
                ran.add(name)
    record_runs([j for j in jobs if ran is None or j["name"] in ran], args.rerun_of, args.rerun_label)
    return 0


def _recordable(job) -> bool:
    """A finished or failed run in its folder (a run still going, killed or interrupted is no result)."""
    status = study.run_status(RUNS / job["name"])
    if status in ("running", "interrupted", "unreadable"):
        print(f"{job['name']}: status {status!r} in its folder, not recorded")
    return status not in (None, "running", "interrupted", "unreadable")


def record_runs(jobs, rerun_of=None, rerun_label=""):
    """The records of ``jobs`` (those with a run folder) merged into cutting.json (module text: a failed run never
    replaces a good record, every other record stays as it was), the table, and the figures they change."""
    committed = json.loads(OUT_JSON.read_text()) if OUT_JSON.exists() else []
    fresh = [record(j) for j in jobs if _recordable(j)]
    old = {r["name"]: r.get("vs_rerun") for r in committed}
    for r in fresh:                                       # keep the comparison already made (its runs may be gone)
        if old.get(r["name"]) is not None and r["name"].startswith("paper-"):
            r["vs_rerun"] = old[r["name"]]
    records, went_in = study.merge_derived(committed, fresh, add_differences)
    for r in fresh:
        if r["name"] not in went_in:
            print(f"{r['name']}: {r['status']}; the committed good record is kept")
    if rerun_of is not None:
        records = add_reruns(records, Path(rerun_of).resolve(), rerun_label)
    elif not fresh:
        print(f"no run folder to record in {RUNS}: nothing written")
        return records
    print(f"{'wrote' if write_json(records) else 'unchanged:'} {OUT_JSON.relative_to(ROOT)} "
          f"(recorded: {', '.join(sorted(went_in)) or 'none'})")
    print(table(records))
    plots(records, went_in)
    return records


def _strain_figure_only(feed):
    """--strain-figure: figures/08_cutting_strain_fFEED.png from the two paper runs of that feed (both needed)."""
    names = [f"paper-{m}-f{feed * 1e3:g}" for m in METHODS]
    missing = [n for n in names if not (RUNS / n / "summary.json").exists()]
    if missing:
        print(f"--strain-figure needs the run folders of {', '.join(missing)} in {RUNS}: nothing drawn")
        return 1
    jobs = {j["name"]: j for j in job_list()}
    strain_figure({n: record(jobs[n]) for n in names}, feed)
    print(f"figures/08_cutting_strain_f{feed * 1e3:g}.png from {', '.join(names)} (written if its pixels changed)")
    return 0


def _parser():
    ap = study.parser(__doc__, "jobs", "plot_only", "only")
    ap.add_argument("--add", action="store_true",
                    help="(the default now, kept for old commands) the records of the jobs that ran, or with "
                         "--plot-only of the jobs of --only whose folders are there, merged into the JSON")
    ap.add_argument("--runs", default=None, help=f"folder of the run folders (default {RUNS.relative_to(ROOT)})")
    ap.add_argument("--rerun-of", default=None, metavar="DIR",
                    help="folder of the same paper runs made by other code (e.g. an earlier commit): store how far "
                         "each measurement moved (vs_rerun)")
    ap.add_argument("--rerun-label", default="", help="what made the runs of --rerun-of (stored with them)")
    ap.add_argument("--strain-figure", type=float, default=None, metavar="FEED_MM",
                    help="only draw figures/08_cutting_strain_fFEED.png from the paper runs of that feed (mm) in the "
                         "run folders (nothing else is written)")
    ap.add_argument("--json-figures", action="store_true",
                    help="only redraw the figures made from the committed JSON alone "
                         "(figures/08_cutting_work_precision.png)")
    return study.add_flags(ap, "report", report=dict(
        help=f"only write {OUT_REPORT.relative_to(ROOT)} from {OUT_JSON.relative_to(ROOT)} (runs nothing, "
             "changes neither the JSON nor the figures)"))


if __name__ == "__main__":
    sys.exit(main())
