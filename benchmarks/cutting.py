"""Orthogonal cutting benchmark (Section 3.3 of Islam, Bansal & Peng): both feeds, both methods.

    python benchmarks/cutting.py --jobs 2          # all runs, two at a time (about 3 hours of CPU, see below)
    python benchmarks/cutting.py --only paper-     # only the jobs whose name contains 'paper-'
    python benchmarks/cutting.py --plot-only       # JSON, table and figures again from runs/benchmarks/cutting/

Runs (2D plane strain, the scene `refsph.cutting`, 1 mm of cut = 20 us unless stated):
  paper-METHOD-fFEED   dp = 0.01 mm, h = 0.018 mm (Table 5), feed 0.3 and 0.5 mm, both methods, CFL step
  coarse-...           the same at dp = 0.025 mm and 0.0167 mm (feed 0.3 mm), for the work-precision plot
  noupdate-tlsph       TLSPH without reference-configuration updates, dp = 0.025 mm, feed 0.3 mm, 0.5 mm of
                       cut (reduced size), against the same run with updates (coarse-tlsph-f0.3-25um)
Each run is one process; its folder runs/benchmarks/cutting/NAME keeps summary.json, reaction_forces.csv and all
snapshots (every 1/8 of the cut). Wall times are single-core (BLAS/OpenMP pools pinned to one thread); with
--jobs 2 two runs share the machine's two cores.
"""
from __future__ import annotations

import os

# one core per run: pin the BLAS / OpenMP thread pools before NumPy is imported (inherited by the workers)
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS",
             "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402
from concurrent.futures import ProcessPoolExecutor  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
RUNS = ROOT / "runs" / "benchmarks" / "cutting"
OUT_JSON = ROOT / "benchmarks" / "cutting.json"
FIG = ROOT / "figures"
METHODS = ("tlsph", "esph")
FEEDS = (0.3e-3, 0.5e-3)
DP_PAPER = 0.01e-3


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
    return jobs


def run_job(job):
    from refsph.simulate import SimulationError, run
    t0 = time.perf_counter()
    out = RUNS / job["name"]
    try:
        res = run("cutting", job["method"], dp=job["dp"], out=out, progress=True, numerics=job["numerics"],
                  options=dict(feed=job["feed"], travel=job["travel"]))
        s = res.summary
        msg = f"{s['status']}, {s['n_steps']} steps"
    except SimulationError as e:                          # a lost run is a result too: summary.json says why
        msg = f"failed: {e}"
    print(f"{job['name']}: {msg}, {time.perf_counter() - t0:.0f} s", flush=True)
    return job["name"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--jobs", type=int, default=1, help="runs at a time (default 1)")
    ap.add_argument("--plot-only", action="store_true", help="no runs: JSON, figures and table from earlier runs")
    ap.add_argument("--only", default=None, help="run only the jobs whose name contains this string")
    args = ap.parse_args(argv)
    jobs = [j for j in job_list() if args.only is None or args.only in j["name"]]
    if not args.plot_only:
        with ProcessPoolExecutor(max_workers=args.jobs, max_tasks_per_child=1) as ex:
            list(ex.map(run_job, jobs))


if __name__ == "__main__":
    main()
