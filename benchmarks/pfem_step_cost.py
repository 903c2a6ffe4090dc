"""What a PFEM cutting step costs, and where the time goes: the first steps of case 1's short cut (4 t_u on a 1.2 mm
workpiece) at t_u/10 (the paper's resolution) and t_u/5, timed (CPU seconds of this process, so that other work on
the machine counts less) and then profiled (the element tangent, the element residuals, the sparse factorisation,
the rest; under the profiler), with the forces at the end so that two versions of the code can be seen to give the
same numbers.

    python benchmarks/pfem_step_cost.py                       # both resolutions, about 5 minutes; one record each
    python benchmarks/pfem_step_cost.py --n-tu 10 --steps 30  # one
    python benchmarks/pfem_step_cost.py --report              # the table from the JSON

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


def report(rows: list) -> str:
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
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n-tu", type=float, nargs="*", default=[10.0, 5.0], help="resolutions (default 10 5)")
    ap.add_argument("--steps", type=int, default=30, help="steps timed at each (default 30)")
    ap.add_argument("--label", help="the record's name (default: the git commit of refsph)")
    ap.add_argument("--report", action="store_true", help="only print the table of the JSON")
    args = ap.parse_args(argv)
    rows = json.loads(OUT_JSON.read_text())["rows"] if OUT_JSON.exists() else []
    if not args.report:
        args.label = args.label or version()          # before this script writes its JSON (a tracked file)
        for n_tu in args.n_tu:
            rec = measure(n_tu, args.steps, args.label)
            rows = [r for r in rows if (r["commit"], r["n_tu"], r["steps"]) != (rec["commit"], n_tu, args.steps)]
            rows.append(rec)
            OUT_JSON.write_text(json.dumps(dict(rows=rows), indent=1) + "\n")
            print(f"n_tu {n_tu:g}: {rec['cpu_s']:.1f} s CPU, {rec['iterations']} iterations", flush=True)
    OUT_MD.write_text(report(rows))
    print(report(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
