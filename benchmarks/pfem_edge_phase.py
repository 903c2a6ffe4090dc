"""Where the tool's edge sits between node rows, and the PFEM's forces (issue 24): the quick cut (case 1, 4 t_u on a
1.2 mm workpiece) with n_tu = 5, 5.125, ..., 5.875 nodes across t_u (and 10, 10.25, 10.5, 10.75 at the paper's
resolution). The workpiece's rows are dx = t_u / n_tu apart from its top, so the cut line y = H - t_u, and with it
the tool's edge, sits at a different place between two rows in each run, while dx changes by less than 18 %. A
method that resolved the edge would give the same forces in all of them; their spread is the error that the edge's
place on the lattice makes.

Each run twice: the paper's contact (nodes kept out of the tool, ``edge_nodes`` off) and with ``edge_nodes`` (the
mesh kept off the tool: a node inserted on the tool's surface where its edge pokes through the boundary between two
nodes, :func:`refsph.pfem.refine.tool_intrusions`). The overlap measured after each step: how far the tool's outline
pokes through a boundary edge between its nodes, in dx (the mean and largest over the second half of the cut).

    python benchmarks/pfem_edge_phase.py              # t_u/5: 16 runs, about 10 min on one core
    python benchmarks/pfem_edge_phase.py --fine       # also t_u/10: 8 more, about 40 min
    python benchmarks/pfem_edge_phase.py --full       # also case 1's whole cut (16 t_u) at t_u/5, both ways: 8 min
    python benchmarks/pfem_edge_phase.py --report     # the tables from the JSON

Resumable: each finished run is kept in pfem_edge_phase.json (a rerun skips it; a run that fails is recorded as
failed and never replaces a finished one).
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

OUT_JSON = Path(__file__).resolve().parent / "pfem_edge_phase.json"
COARSE = (5.0, 5.125, 5.25, 5.375, 5.5, 5.625, 5.75, 5.875)
FINE = (10.0, 10.25, 10.5, 10.75)
QUICK = dict(case=1, travel=4.0, length=1.2e-3)
KEYS = (("Fc [N/mm]", "Fc", ".1f"), ("Fp [N/mm]", "Fp", ".1f"), ("Fp/Fc", "ratio", ".3f"), ("T_RF [K]", "TRF", ".0f"),
        ("chip [mm]", "chip", ".3f"), ("Newton its", "its", ".0f"), ("CPU [s]", "cpu", ".0f"),
        ("overlap mean [dx]", "overlap_mean", ".3f"), ("overlap max [dx]", "overlap_max", ".3f"))


def overlap(run) -> float:
    """How far the tool's outline pokes through a boundary edge between its two nodes, beyond them [dx] (41 points
    along each edge; 0 where it does not)."""
    from refsph.pfem.refine import gaps_along_edges
    cut, shift = run.cut, run.cut.shift0 + run.cut.v_tool * run.nodes.t
    g = gaps_along_edges(run.nodes.x, run.mesh.edges, lambda x: cut.shape.gap(x, shift), 41)[1]
    inner = g[:, 1:-1].max(axis=1) - np.maximum(np.maximum(g[:, 0], g[:, -1]), 0.0)
    return float(max(inner.max(), 0.0) / cut.info["dx"])


def run_one(n_tu: float, edge_nodes: bool, full: bool = False) -> dict:
    """The quick cut at this n_tu (``full``: case 1's whole cut); its record."""
    from refsph.pfem.cutting import CutRun, pfem_cut
    from refsph.pfem_run import one_blas_thread
    from refsph.simulate import provenance
    cut = pfem_cut(n_tu=n_tu, edge_nodes=edge_nodes, **(dict(case=1) if full else QUICK))
    t0, ov = time.process_time(), []
    run = CutRun(cut)
    with one_blas_thread():
        while not run.done:
            run.step()
            ov.append(overlap(run))
    r = run.result()
    m, ov = r["metrics"], np.asarray(ov[len(ov) // 2:])
    return dict(n_tu=n_tu, edge_nodes=edge_nodes, full=full, status="ok", Fc=m["cutting_force_N_per_m"] / 1e3,
                Fp=m["passive_force_N_per_m"] / 1e3, ratio=m["force_ratio"], TRF=m["rake_face_temperature_K"],
                TFCS=m["free_chip_surface_temperature_K"], chip=m["chip_thickness_mm"],
                its=int(sum(r["newton_iterations"])), steps=r["steps"], halved=r["retries"],
                inserted=r["nodes_inserted"], removed=r["nodes_removed"], nodes_end=int(run.nodes.n),
                overlap_mean=float(ov.mean()), overlap_max=float(ov.max()), cpu=time.process_time() - t0,
                commit=provenance(1).get("commit"))


def key(n_tu: float, edge_nodes: bool, full: bool = False) -> str:
    return f"{'full cut ' if full else ''}n_tu {n_tu:g} {'edge nodes' if edge_nodes else 'paper'}"


def load() -> dict:
    return json.loads(OUT_JSON.read_text())["runs"] if OUT_JSON.exists() else {}


def save(runs: dict) -> None:
    OUT_JSON.write_text(json.dumps(dict(made_by="python benchmarks/pfem_edge_phase.py", runs=runs), indent=1) + "\n")


def stats(rows: list, q: str) -> str:
    v = [r[q] for r in rows]
    if len(v) < 2:
        return f"{v[0]:.4g}" if v else "-"
    m, sd = statistics.mean(v), statistics.stdev(v)
    return f"{m:.4g} ± {sd:.2g} ({100 * sd / abs(m):.1f} %)" if m else f"{m:.3g} ± {sd:.2g}"


def report(runs: dict) -> str:
    lines = ["# The tool's edge between node rows (PFEM quick cut, case 1)", "",
             "Made by `python benchmarks/pfem_edge_phase.py` (module text): each row one run; then, per resolution and "
             "contact, the mean ± the sample standard deviation over the edge's places (the spread the lattice makes).",
             "", "| n_tu | contact | " + " | ".join(k[0] for k in KEYS) + " |", "|---" * (2 + len(KEYS)) + "|"]
    ok = [r for r in runs.values() if r["status"] == "ok" and not r.get("full")]
    for r in sorted(ok, key=lambda r: (r["n_tu"] >= 10, r["edge_nodes"], r["n_tu"])):
        lines.append(f"| {r['n_tu']:g} | {'edge nodes' if r['edge_nodes'] else 'paper'} | "
                     + " | ".join(format(r[k], f) for _, k, f in KEYS) + " |")
    lines += ["", "| resolution | contact | runs | " + " | ".join(k[0] for k in KEYS[:5])
              + " | Newton its | overlap mean [dx] |", "|---" * 10 + "|"]
    for fine in (False, True):
        for en in (False, True):
            sel = [r for r in ok if (r["n_tu"] >= 10) == fine and r["edge_nodes"] == en]
            if sel:
                lines.append(f"| t_u/{10 if fine else 5} | {'edge nodes' if en else 'paper'} | {len(sel)} | "
                             + " | ".join(stats(sel, k) for _, k, _ in KEYS[:5])
                             + f" | {stats(sel, 'its')} | {stats(sel, 'overlap_mean')} |")
    full = sorted((r for r in runs.values() if r["status"] == "ok" and r.get("full")), key=lambda r: r["edge_nodes"])
    if full:
        lines += ["", "Case 1's whole cut (16 t_u, 2.8 mm workpiece) at t_u/5, means over its last quarter:", "",
                  "| contact | " + " | ".join(k[0] for k in KEYS) + " | halved steps |", "|---" * (2 + len(KEYS)) + "|"]
        lines += [f"| {'edge nodes' if r['edge_nodes'] else 'paper'} | "
                  + " | ".join(format(r[k], f) for _, k, f in KEYS) + f" | {r['halved']} |" for r in full]
    failed = [k for k, r in runs.items() if r["status"] != "ok"]
    if failed:
        lines += ["", "Failed: " + ", ".join(failed)]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--report", action="store_true", help="only the tables from the JSON")
    ap.add_argument("--fine", action="store_true", help="also the runs at t_u/10")
    ap.add_argument("--full", action="store_true", help="also case 1's whole cut at t_u/5, both ways")
    args = ap.parse_args(argv)
    runs = load()
    if not args.report:
        todo = [(n, en, False) for n in COARSE + (FINE if args.fine else ()) for en in (False, True)]
        todo += [(5.0, en, True) for en in (False, True)] if args.full else []
        for n, en, full in todo:
            k = key(n, en, full)
            if runs.get(k, {}).get("status") == "ok":
                continue
            try:
                rec = run_one(n, en, full)
            except Exception as e:                                   # recorded, and the sweep goes on
                rec = dict(n_tu=n, edge_nodes=en, full=full, status="failed", error=f"{type(e).__name__}: {e}"[:500])
            runs = load()                                            # another process may have added some
            if rec["status"] == "ok" or k not in runs:
                runs[k] = rec
                save(runs)
            print(k, rec["status"], {q: rec.get(q) for _, q, _ in KEYS}, flush=True)
    if not runs:
        print(f"no {OUT_JSON.name}: run python benchmarks/pfem_edge_phase.py first", file=sys.stderr)
        return 2
    text = report(runs)
    (OUT_JSON.parent / "pfem_edge_phase_report.md").write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
