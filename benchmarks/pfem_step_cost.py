"""What a PFEM cutting step costs, and where the time goes: the first steps of case 1's short cut (4 t_u on a 1.2 mm
workpiece) at t_u/10 (the paper's resolution) and t_u/5, timed (CPU seconds of this process, so that other work on
the machine counts less) and then profiled (the element tangent, the element residuals, the sparse factorisation,
the rest; under the profiler), with the forces at the end so that two versions of the code can be seen to give the
same numbers.

    python benchmarks/pfem_step_cost.py                       # both resolutions, about 5 minutes; one record each
    python benchmarks/pfem_step_cost.py --n-tu 10 --steps 30  # one
    python benchmarks/pfem_step_cost.py --report              # the table from the JSON
    python benchmarks/pfem_step_cost.py --full [--gamma G]    # the whole of case 1 at t_u/10 (about 40 minutes)

``--full`` runs the cut the sweep records as 'case 1 pfem' (benchmarks/thermal_cutting.py: 16 t_u of cut on a 2.8
mm workpiece at t_u/10, the paper's resolution; ``--gamma``: Newmark's gamma, 0.5 the paper's rule) from its start,
into runs/pfem_cost/ (a fresh folder each time: the CPU seconds are those of one uninterrupted run; a run that
fails is recorded with how far it got), and keeps its cost (CPU and wall seconds of this
process, steps, Newton iterations, halved steps, nodes) with its measures beside those of the sweep's record of the
same cut (made by an older version of the solver: the digits the two share are those the path to the solution
does not move).

A record is keyed by the git commit and the resolution, so running this at an older commit (``git checkout <rev> --
refsph``, with ``--label``) adds that version's row beside today's (the before-and-after of a change):
benchmarks/pfem_step_cost.json and pfem_step_cost_report.md.
"""
from __future__ import annotations

import argparse
import cProfile
import json
import pstats
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

OUT_JSON = Path(__file__).resolve().parent / "pfem_step_cost.json"
OUT_MD = Path(__file__).resolve().parent / "pfem_step_cost_report.md"
SWEEP_JSON = Path(__file__).resolve().parent / "thermal_cutting.json"
FULL_KEY = "case 1 pfem"                      # the sweep's record of the cut that --full times
FULL_OPTIONS = dict(case=1, n_tu=10.0, travel=16.0, length=2.8e-3)
MEASURES = (("Fc [N/mm]", "cutting_force_N_per_m", 1e-3), ("Fp [N/mm]", "passive_force_N_per_m", 1e-3),
            ("T_RF [K]", "rake_face_temperature_K", 1.0), ("T_FCS [K]", "free_chip_surface_temperature_K", 1.0),
            ("chip [mm]", "chip_thickness_mm", 1.0))
PARTS = (("tangent", "_element_tangent"), ("element residuals", "element_residual"), ("factorisation", "gstrf"))
# (the element residuals: all of them, the tangent's included)


def version() -> str:
    """refsph's git commit, short, with '(dirty)' where its tracked files differ from it."""
    from refsph.simulate import provenance

    commit = provenance(1)["git_commit"] or "unknown"
    return commit[:7] + (" (dirty)" if "dirty" in commit else "")


def measure(n_tu: float, steps: int, label: str | None = None) -> dict:
    """CPU and wall seconds of ``steps`` steps of the short cut at t_u / n_tu (case 1), then the same steps again
    under cProfile for the split; the Newton iterations and the tool force averaged over the last five steps."""
    import numpy as np

    from refsph.pfem import cutting

    def fresh():
        return cutting.CutRun(cutting.pfem_cut(1, n_tu=n_tu, travel=4.0, length=1.2e-3))

    run = fresh()
    cpu, wall = time.process_time(), time.perf_counter()
    for _ in range(steps):
        run.step()
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    prof, again = cProfile.Profile(), fresh()
    prof.enable()
    for _ in range(steps):
        again.step()
    prof.disable()
    stats = pstats.Stats(prof).stats
    total = sum(v[3] for k, v in stats.items() if k[2] == "step" and k[0].endswith("cutting.py"))
    split = {name: sum(v[3] for k, v in stats.items() if k[2] == func or k[2].endswith(f".{func}>")) / total
             for name, func in PARTS}
    F = np.mean(np.array(run.reaction["tool"][-5:]), axis=0)
    return dict(commit=label or version(), n_tu=n_tu, steps=steps, nodes=int(run.nodes.n), cpu_s=round(cpu, 2),
                wall_s=round(wall, 2), iterations=int(sum(run.iterations)),
                cpu_per_iteration_ms=round(1e3 * cpu / max(sum(run.iterations), 1), 1),
                split={k: round(v, 3) for k, v in split.items()}, tool_force_N_per_m=[float(f) for f in F])


def full_folder(gamma: float) -> Path:
    """The run folder of --full (runs/ is not tracked)."""
    name = "case_1_n_tu_10" + ("" if gamma == 0.5 else f"_gamma_{gamma:g}")
    return Path(__file__).resolve().parents[1] / "runs" / "pfem_cost" / name


def measure_full(label: str | None = None, gamma: float = 0.5) -> dict:
    """The whole of case 1 at t_u / 10 (module text) with Newmark's ``gamma`` (0.5: the paper's trapezoidal rule):
    its cost and measures, run from its start; a run that fails is recorded as failed, with how far it got."""
    import shutil

    from refsph.pfem_run import run_pfem
    from refsph.simulate import SimulationError

    out = full_folder(gamma)
    if out.exists():
        shutil.rmtree(out)
    cpu, wall = time.process_time(), time.perf_counter()
    try:
        run_pfem("thermal_cutting", out=out, progress=True, options=dict(FULL_OPTIONS, gamma=gamma))
    except SimulationError as e:
        print(f"failed: {e}", file=sys.stderr)
    return full_record(out, label, time.process_time() - cpu, time.perf_counter() - wall)


def full_record(out: Path, label: str | None, cpu: float | None, wall: float | None = None) -> dict:
    """The record of a --full run from its folder's summary.json: ``cpu`` and ``wall`` [s] as this process
    measured them (``cpu`` None: a run whose process ended before it could record, ``--record``; its wall time is
    then the run's own)."""
    s = json.loads((out / "summary.json").read_text())
    m = s.get("metrics") or {}
    ok = s["status"] == "ok"
    return dict(commit=label or version(), options=dict(s["options"]), status=s["status"],
                t_final_s=s["t_final"], t_end_s=s["t_end"], steps=s["n_steps"], nodes=s["n_particles"],
                cpu_s=None if cpu is None else round(cpu, 1),
                wall_s=round(s["wall_time_s"] if wall is None else wall, 1),
                iterations=s["newton"]["iterations"], halved_steps=s["newton"]["halved_steps"],
                measures={key: float(m[key]) for _, key, _ in MEASURES} if ok else None,
                error=s.get("error", "")[:200])


def records() -> tuple[list, list]:
    """(rows, full): this script's records in its JSON (empty where there is none yet)."""
    data = json.loads(OUT_JSON.read_text()) if OUT_JSON.exists() else {}
    return data.get("rows", []), data.get("full", [])


def sweep_record() -> dict | None:
    """The sweep's record of the cut --full times (None: not recorded)."""
    if not SWEEP_JSON.exists():
        return None
    return json.loads(SWEEP_JSON.read_text())["runs"].get(FULL_KEY)        # the records by key


def full_report(full: list, sweep: dict | None) -> list[str]:
    """The table of the whole cut's records, the sweep's record last."""
    if not full:
        return []
    names = [name for name, _, _ in MEASURES]
    lines = ["", "# The whole cut: case 1 at t_u/10 (16 t_u of cut, the sweep's 'case 1 pfem'), from its start", "",
             "Made by `python benchmarks/pfem_step_cost.py --full`: CPU and wall seconds of one uninterrupted run "
             "(other work ran beside it, except in the row marked 'alone': the other runs on the machine stopped, "
             "its second core idle; the tree then differed from a069aae in benchmark data files only, not in "
             "refsph/), its measures beside the sweep's record of the same cut.", "",
             "| version | steps | halved | nodes | Newton iterations | CPU [min] | wall [min] | " + " | ".join(names)
             + " |", "|---" * (7 + len(names)) + "|"]
    for r in full:
        gamma = r["options"].get("gamma", 0.5)
        state = "" if r["status"] == "ok" else \
            f" ({r['status']} at {1e3 * r['t_final_s']:.3g} of {1e3 * r['t_end_s']:.3g} ms)"
        lines.append(f"| {r['commit']}{'' if gamma == 0.5 else f', gamma {gamma:g}'}{state} | {r['steps']} | "
                     f"{r['halved_steps']} | {r['nodes']} | {r['iterations']} | "
                     f"{'-' if r['cpu_s'] is None else format(r['cpu_s'] / 60, '.1f')} | {r['wall_s'] / 60:.1f} | "
                     + " | ".join("-" if r["measures"] is None else f"{r['measures'][key] * f:.4g}"
                                  for _, key, f in MEASURES) + " |")
    if sweep is not None and sweep.get("status") == "ok":
        m = sweep["metrics"]
        lines.append(f"| the sweep's record | {sweep['n_steps']} | - | {sweep['n_particles']} | - | - | "
                     f"{sweep['wall_time_s'] / 60:.1f} | " + " | ".join(f"{m[key] * f:.4g}" for _, key, f in MEASURES)
                     + " |")
    return lines


def report(rows: list, full: list | None = None, sweep: dict | None = None) -> str:
    """The table of the records, by resolution and then as recorded."""
    lines = ["# What a PFEM cutting step costs (case 1's short cut, its first steps)", "",
             "Made by `python benchmarks/pfem_step_cost.py` (module text): CPU seconds of one process (other work ran "
             "beside it), the split under cProfile as fractions of the step (the element residuals include the "
             "tangent's), the tool force averaged over the last five steps: versions that agree on it to many "
             "digits changed the path to the numbers, not the numbers.", "",
             "| commit | n_tu | steps | nodes | Newton iterations | CPU s | ms per iteration | tangent | "
             "element residuals (all) | factorisation | tool force (x, y) [N/m] |", "|---" * 11 + "|"]
    for r in sorted(rows, key=lambda r: r["n_tu"]):
        s = r["split"]
        lines.append(f"| {r['commit']} | {r['n_tu']:g} | {r['steps']} | {r['nodes']} | {r['iterations']} | "
                     f"{r['cpu_s']:.1f} | {r['cpu_per_iteration_ms']:.0f} | {100 * s['tangent']:.0f} % | "
                     f"{100 * s['element residuals']:.0f} % | {100 * s['factorisation']:.0f} % | "
                     f"{r['tool_force_N_per_m'][0]:.6f}, {r['tool_force_N_per_m'][1]:.6f} |")
    lines += full_report(full or [], sweep)
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n-tu", type=float, nargs="*", default=[10.0, 5.0], help="resolutions (default 10 5)")
    ap.add_argument("--steps", type=int, default=30, help="steps timed at each (default 30)")
    ap.add_argument("--label", help="the record's name (default: the git commit of refsph)")
    ap.add_argument("--report", action="store_true", help="only print the table of the JSON")
    ap.add_argument("--full", action="store_true", help="the whole of case 1 at t_u/10 instead (module text)")
    ap.add_argument("--gamma", type=float, default=0.5, help="--full: Newmark's gamma (default 0.5, the paper's)")
    ap.add_argument("--record", action="store_true",
                    help="--full: record the run in its folder (one whose process ended before it could) without "
                         "running it again; its CPU time is then unknown")
    args = ap.parse_args(argv)
    rows, full = records()
    if args.record and not (full_folder(args.gamma) / "summary.json").exists():
        ap.error(f"--record: no run in {full_folder(args.gamma)} (run --full first)")
    if args.full and not args.report:
        rec = full_record(full_folder(args.gamma), args.label, None) if args.record else \
            measure_full(args.label or version(), args.gamma)
        rows, full = records()                        # read again: rows added while the cut ran stay
        full = [r for r in full if (r["commit"], r["options"].get("gamma", 0.5))
                != (rec["commit"], rec["options"].get("gamma", 0.5))] + [rec]
        OUT_JSON.write_text(json.dumps(dict(rows=rows, full=full), indent=1) + "\n")
        print(f"case 1 at t_u/10: {rec['status']}, {rec['wall_s'] / 60:.1f} min, {rec['iterations']} iterations",
              flush=True)
    elif not args.report:
        args.label = args.label or version()          # before this script writes its JSON (a tracked file)
        for n_tu in args.n_tu:
            rec = measure(n_tu, args.steps, args.label)
            rows = [r for r in rows if (r["commit"], r["n_tu"], r["steps"]) != (rec["commit"], n_tu, args.steps)]
            rows.append(rec)
            OUT_JSON.write_text(json.dumps(dict(rows=rows, full=full), indent=1) + "\n")
            print(f"n_tu {n_tu:g}: {rec['cpu_s']:.1f} s CPU, {rec['iterations']} iterations", flush=True)
    text = report(rows, full, sweep_record())
    OUT_MD.write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
