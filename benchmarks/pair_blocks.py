"""Cost of one time step of the cutting scene at the paper's resolution, by pair-block size and thread count.

The orthogonal cutting scene (``refsph.scenes.cutting``, feed 0.3 mm, dp = 0.01 mm, h = 0.018 mm: 30,584 particles) is
built as a run builds it and advanced from t = 0 with ``predictor_corrector_step`` at its CFL step: a few
warm-up steps, then ``--steps`` timed steps, ``--repeats`` times; the best repetition is reported (other work
on the machine can only slow a repetition down). For each method, every combination of

* the pair-block size (``refsph.neighbours.PAIR_BLOCK``; ``all`` = one block holding every pair, i.e. no
  blocking), and
* the thread count (``Numerics.threads``)

is timed. The rate evaluations are the same arithmetic whatever the blocks and threads, so the table isolates
what the data layout buys: arrays that fit in the L2 cache (blocks) and two cores at once (threads). The last
column is the time that 1 mm of cut (about 22,400 CFL steps) would take at that speed, the target of issue 5
being under 30 minutes. Output: a table and ``benchmarks/pair_blocks.json`` (``--json``), merged as throughput.py's:
the results timed replace those of the same method, block size and thread count, every other result stays, so a
run restricted with ``--methods``, ``--sizes`` or ``--threads`` drops nothing (``throughput.write_results``).

    python benchmarks/pair_blocks.py           # both methods, sizes all/2^15/2^16/2^17/2^18, 1 and 2 threads
    python benchmarks/pair_blocks.py --methods esph --sizes all 131072 --threads 2 --steps 20
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()      # BLAS is not used in the steps; refsph's own threads are Numerics.threads

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import refsph.neighbours  # noqa: E402
from refsph.integrate import cfl_time_step, predictor_corrector_step  # noqa: E402
from refsph.scenes import get_scene  # noqa: E402
from refsph.simulate import make_solver  # noqa: E402
from throughput import software, write_results  # noqa: E402  (benchmarks/throughput.py, next to this file)

STEPS_PER_MM = 22_400          # CFL steps for 1 mm of cut at the paper's resolution (benchmarks/cutting.json)


def time_step(method: str, size: int | None, threads: int | None, steps: int, repeats: int,
              warmup: int = 3) -> dict:
    """Best s/step of ``method``; ``threads=None``: the code as it is (for a checkout before PairBlocks)."""
    setup = get_scene("cutting").setup(2, 0.01e-3, False, feed=0.3e-3)
    as_is = threads is None
    if not as_is:
        setup.numerics = dataclasses.replace(setup.numerics, threads=threads)
    saved = getattr(refsph.neighbours, "PAIR_BLOCK", None)
    if not as_is:
        refsph.neighbours.PAIR_BLOCK = size if size is not None else 2**62
    try:
        solver = make_solver(method, setup)
        state = setup.state.copy()
        solver.check_state(state)
        dt = cfl_time_step(state, setup.material, setup.h, setup.numerics.courant)
        for _ in range(warmup):
            state = predictor_corrector_step(state, solver, dt)
        wall, cpu = np.inf, np.inf
        for _ in range(repeats):
            t0, c0 = time.perf_counter(), time.process_time()
            for _ in range(steps):
                state = predictor_corrector_step(state, solver, dt)
            wall, cpu = min(wall, time.perf_counter() - t0), min(cpu, time.process_time() - c0)
    finally:
        if not as_is:
            refsph.neighbours.PAIR_BLOCK = saved
    if not np.isfinite(state.x).all():
        raise RuntimeError(f"{method}: non-finite state in the benchmark")
    diag = solver.diagnostics()
    return dict(method=method, block_size=size, threads=threads, n_particles=state.n, n_pairs=diag["n_pairs"],
                steps=steps, repeats=repeats, s_per_step=wall / steps, cpu_s_per_step=cpu / steps,
                minutes_per_mm=wall / steps * STEPS_PER_MM / 60.0)


def _commit(folder: Path) -> str | None:
    import subprocess
    try:
        return subprocess.run(["git", "-C", str(folder), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip() + (" (modified)" if subprocess.run(
                                  ["git", "-C", str(folder), "status", "--porcelain", "--", "."], capture_output=True,
                                  text=True).stdout.strip() else "")
    except (OSError, subprocess.CalledProcessError):
        return None


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--methods", nargs="+", default=["esph", "tlsph"], choices=["esph", "tlsph"])
    ap.add_argument("--sizes", nargs="+", default=["all", "32768", "65536", "131072", "262144"],
                    help="pairs per block, or 'all' (one block)")
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--steps", type=int, default=20, help="timed steps per repetition (default 20)")
    ap.add_argument("--repeats", type=int, default=3, help="repetitions, the best is reported (default 3)")
    ap.add_argument("--as-is", action="store_true",
                    help="time the refsph on the path as it is, once per method (for a checkout from before pair "
                         "blocks: PYTHONPATH=OLD_CHECKOUT python benchmarks/pair_blocks.py --as-is --json old.json)")
    ap.add_argument("--json", type=Path, default=Path(__file__).with_name("pair_blocks.json"))
    args = ap.parse_args(argv)
    sizes = [None if s == "all" else int(s) for s in args.sizes]
    if args.as_is:
        sizes, args.threads = ["as-is"], [None]
    print(", ".join(f"{k} {v}" for k, v in software().items()) + "; cutting scene, paper resolution, feed 0.3 mm")
    header = (f"{'method':6s} {'block':>7s} {'threads':>7s} {'pairs':>8s} {'s/step':>7s} {'cpu s/step':>10s} "
              f"{'min/mm':>7s}")
    print(header + "\n" + "-" * len(header))
    results = []
    for method in args.methods:
        for size in sizes:
            for threads in args.threads:
                r = time_step(method, None if size == "as-is" else size, threads, args.steps, args.repeats)
                r["block_size"] = size if size == "as-is" else r["block_size"]
                results.append(r)
                print(f"{method:6s} {'all' if size is None else size:>7} {threads or 0:7d} {r['n_pairs']:8d} "
                      f"{r['s_per_step']:7.4f} {r['cpu_s_per_step']:10.4f} {r['minutes_per_mm']:7.1f}", flush=True)
    write_results(args.json, results, lambda r: (r["method"], r["block_size"], r["threads"]),
                  refsph_path=str(Path(refsph.neighbours.__file__).parent),
                  refsph_commit=_commit(Path(refsph.neighbours.__file__).parent),
                  scene="cutting, dp = 0.01 mm, h = 0.018 mm, feed 0.3 mm, from t = 0",
                  timing="best of `repeats` repetitions of `steps` predictor-corrector steps after 3 warm-up "
                         "steps; minutes_per_mm = s_per_step x 22,400 steps / 60")
    return results


if __name__ == "__main__":
    main()
