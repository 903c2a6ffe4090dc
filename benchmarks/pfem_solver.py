"""The PFEM's linear solve, timed (issue 24): the Newton matrix of the cut (refsph.pfem.cutting.pfem_cut, case 1,
the short cut) at two resolutions, factored as assembled (u of all nodes, then p of all nodes; scipy's spsolve,
SuperLU with COLAMD) and reordered first (refsph.pfem.solid.sparse_solve with band_order: reverse Cuthill-McKee).
Both solutions must agree to 1e-6 relative (the same system, factored in another order; the penalties make it
ill-conditioned: the two differ by ~1e-9). Writes pfem_solver.json.

    python benchmarks/pfem_solver.py            # n_tu = 5 and 10 (about a minute)
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from refsph.pfem.cutting import CutRun, pfem_cut
from refsph.pfem.solid import assemble, band_order, sparse_solve


def newton_matrix(n_tu: float):
    """The cut's Newton matrix at t = 0 for a small random increment, with the held rows replaced by identity rows
    (as refsph.pfem.solid.newton_step builds it), and a right-hand side."""
    cut = pfem_cut(1, n_tu=n_tu, travel=4.0, length=1.2e-3)
    run = CutRun(cut)
    nodes = run.nodes
    du = 1e-3 * cut.info["dx"] * np.random.default_rng(0).standard_normal(nodes.x.shape)
    R, K, _, _ = assemble(nodes, run.mesh, run.hist_e, cut.law, du, nodes.p, cut.dt, cut.newmark, True)
    fix = np.concatenate([cut.fixed.ravel(), np.zeros(nodes.n, bool)])
    keep = sp.diags((~fix).astype(float))
    return (keep @ K @ keep + sp.diags(fix.astype(float))).tocsc(), np.where(fix, 0.0, -R)


def best_of(f, repeat=3):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main() -> int:
    rows = []
    for n_tu in (5.0, 10.0):
        K, b = newton_matrix(n_tu)
        t_plain, x_plain = best_of(lambda: spsolve(K, b))
        t_order, order = best_of(lambda: band_order(K))
        t_band, x_band = best_of(lambda: sparse_solve(K, b, order))
        err = float(np.linalg.norm(x_band - x_plain) / np.linalg.norm(x_plain))
        rows.append(dict(n_tu=n_tu, unknowns=K.shape[0], nnz=int(K.nnz), spsolve_s=t_plain, band_order_s=t_order,
                         sparse_solve_s=t_band, speedup=t_plain / t_band, rel_difference=err))
        print(f"n_tu {n_tu:4.0f}: {K.shape[0]:6d} unknowns, spsolve {t_plain:.3f} s, reordered {t_band:.3f} s "
              f"(+ ordering {t_order:.3f} s once per step), x {t_plain / t_band:.1f}, difference {err:.1e}")
        if not err < 1e-6:
            print("the two solutions differ", file=sys.stderr)
            return 1
    Path(__file__).with_suffix(".json").write_text(json.dumps(dict(rows=rows), indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
