"""The run-to-run scatter of the cutting scene's metrics (issue 23): the stored tolerances of the metrics that depend
chaotically on details (the cutting and thrust forces, the chip thickness, the shear-band count).

    python benchmarks/metric_scatter.py            # both methods, 4 seeds, both cuts: 20 runs, ~6 min on a busy core
    python benchmarks/metric_scatter.py --report   # no runs: scatter.json and the table from the committed records

Each run is the cutting scene at the golden case's resolution (``metrics_cutting_coarse_<method>``: dp = 0.05 mm,
one core, as refsph.crosscheck.golden.METRIC_RUNS runs it) with the workpiece's particles moved at random by up
to ``SCATTER_JITTER`` = 0.01 dx (the scene's options ``jitter`` and ``seed``; seeds 1 .. --seeds), and once
unperturbed (seed 0). Two cuts:

* ``golden``: the golden case's own 0.2 mm of cut (about 900 steps, under 10 s a run). Its spread goes beside the
  case, ``golden/metrics_cutting_coarse_<method>/scatter.json`` (golden/FORMAT.md), measured around the case's
  values; ``refsph compare`` takes the tolerance of a sensitive metric (``SCATTER_METRICS``) from there. After
  0.2 mm the chip has not risen half a feed along the rake face: no chip thickness, no shear band yet;
* ``chip``: 0.6 mm of cut (about 2700 steps, under 30 s a run), where the chip thickness and a first band are
  measured: their spread, around the unperturbed run, is kept here (``metric_scatter.json`` ``chip_spread``), for a
  ``--tolerances`` file of run comparisons.

The rule (``SCATTER_RULE``): tolerance = k x the largest relative deviation of a perturbed run from the reference
value, k = 2 (four runs rarely see the widest deviation); refsph compare uses the larger of that and case.json's
own tolerance. The records go to ``benchmarks/metric_scatter.json`` (resumable: a recorded run is not run again;
``--redo`` runs everything again). A rerun that reproduces the numbers leaves every file as it was.
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

from refsph.crosscheck.golden import (METRIC_RUNS, SCATTER_JITTER, SCATTER_METRICS, generated_with,  # noqa: E402
                                      scatter_document, spread)
from refsph.crosscheck.compare import SCATTER_FILE  # noqa: E402
from refsph.io import json_ready  # noqa: E402

OUT_JSON = study.HERE / "metric_scatter.json"
GOLDEN = study.ROOT / "golden"
STORE = study.RunStore(OUT_JSON)
CASE = "cutting_coarse"                                 # the golden metrics case whose scatter is measured
CUTS = {"golden": METRIC_RUNS[CASE]["args"]["options"]["travel"], "chip": 0.6e-3}      # length of cut [m]
METHODS = ("esph", "tlsph")
SHOWN = SCATTER_METRICS + ("max_plastic_strain", "max_temperature_K")


def cutting_run(method: str, travel: float, seed: int) -> dict:
    """One run of the golden case's set-up (``travel`` of cut; seed 0: unperturbed) and its scalar metrics."""
    from refsph.simulate import run
    args = METRIC_RUNS[CASE]["args"]
    options = dict(args["options"], travel=travel, **(dict(jitter=SCATTER_JITTER, seed=seed) if seed else {}))
    res = run(METRIC_RUNS[CASE]["scene"], method, progress=False, numerics=dict(threads=1),
              **dict(args, options=options))
    s = res.summary
    return json_ready(dict(status=s["status"], n_steps=s["n_steps"], wall_time_s=s["wall_time_s"],
                           metrics={k: v for k, v in s["metrics"].items() if np.ndim(v) == 0}))


def key(cut: str, method: str, seed: int) -> str:
    return f"{cut} {method} seed {seed}"


def tasks(seeds: int) -> dict:
    return {key(c, m, s): (m, travel, s) for c, travel in CUTS.items() for m in METHODS for s in range(seeds + 1)}


def _runs(records: dict, cut: str, method: str, seeds: int) -> tuple[dict, dict]:
    """(the unperturbed run's metrics, {seed: the perturbed runs' metrics}) of the recorded good runs."""
    good = {s: records[key(cut, method, s)]["metrics"] for s in range(seeds + 1)
            if records.get(key(cut, method, s), {}).get("status") == "ok"}
    return good.get(0, {}), {s: m for s, m in good.items() if s}


def _about(cut: str, seeds: int) -> dict:
    return dict(jitter=SCATTER_JITTER, dp=METRIC_RUNS[CASE]["args"]["dp"], travel=CUTS[cut], runs=seeds,
                measured_with=generated_with())


def write_outputs(seeds: int) -> dict:
    """golden/metrics_cutting_coarse_<method>/scatter.json and the chip cut's spread in metric_scatter.json, from
    the records; {(cut, method): {metric: spread}} for the table."""
    records, table = STORE.records(), {}
    for m in METHODS:
        zero, perturbed = _runs(records, "golden", m, seeds)
        if zero and len(perturbed) >= 2:
            doc = scatter_document(GOLDEN / f"metrics_{CASE}_{m}", zero, perturbed, **_about("golden", seeds))
            study.write_json(GOLDEN / f"metrics_{CASE}_{m}" / SCATTER_FILE, json_ready(doc))
            table["golden", m] = doc["metrics"]
        zero, perturbed = _runs(records, "chip", m, seeds)
        if zero and len(perturbed) >= 2:
            table["chip", m] = {k: spread([p.get(k) for p in perturbed.values()], zero[k]) for k in zero}
    chip = {m: dict(_about("chip", seeds), metrics={k: table["chip", m][k] for k in SHOWN})
            for m in METHODS if ("chip", m) in table}
    if chip and chip != STORE.load().get("chip_spread"):
        STORE.set(chip_spread=json_ready(chip))
    return table


def _cell(s: dict) -> str:
    if s["n"] < 2:
        return f"not measured ({s['n']} of {s['runs']} runs)"
    ref = "-" if s["reference"] is None else f"{s['reference']:.4g}"
    tol = "-" if s["tolerance"] is None else f"{100 * s['tolerance']:.2g} %"
    return (f"ref {ref}, mean {s['mean']:.4g}, std {s['std']:.3g}, max dev {s['max_deviation']:.3g} "
            f"(from ref {s['max_deviation_from_reference']:.3g}), tol {tol}")


def table_text(table: dict) -> str:
    rows = [(f"{cut} {m}", k, _cell(spreads[k])) for (cut, m), spreads in table.items() for k in SHOWN
            if k in spreads]
    return study.md_table(["cut, method", "metric", "spread over the perturbed runs"], rows)


def main(argv=None) -> int:
    ap = study.parser(__doc__, "jobs", "report", report=dict(help="no runs: the outputs from the committed records"))
    ap.add_argument("--seeds", type=int, default=4, help="perturbed runs per cut and method (default 4)")
    ap.add_argument("--redo", action="store_true", help="run every run again, recorded or not")
    args = ap.parse_args(argv)
    if not args.report:
        todo = tasks(args.seeds)
        todo = {k: todo[k] for k in STORE.pending(list(todo), redo=list(todo) if args.redo else (),
                                                  retry_failed=True)}
        print(f"{len(todo)} runs to do", flush=True)
        for n, (name, rec) in enumerate(study.execute(cutting_run, todo, args.jobs)):
            STORE.commit(name, rec)
            print(f"[{n + 1}/{len(todo)}] {name:22s} {rec['status'][:40]:8s} "
                  f"{rec.get('wall_time_s', float('nan')):6.1f} s", flush=True)
    print(table_text(write_outputs(args.seeds)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
