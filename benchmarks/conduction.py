"""Heat conduction (refsph.thermal, Brookshaw's Laplacian, the second paper's Eqs. (26), (29)) against analytic
solutions: error and convergence order in the particle spacing (issue 16's first must-show).

    python benchmarks/conduction.py          # about 10 s; writes benchmarks/conduction.json

* pulse: a Gaussian temperature pulse in a 12 x 12 mm steel block, far from the edges (the interior operator):
  T = T0 + 100 K t0/(t0 + t) exp(-r^2 / (4 a (t0 + t))), a = k/(rho c_p), width 1 mm at t0, compared at t = t0;
* insulated block: the first cosine mode of a 10 x 2 mm block with free (zero-flux) surfaces,
  T = T0 + 100 K cos(pi x / L) exp(-a pi^2 t / L^2), compared at half its decay time.
Midpoint (RK2) time steps at 0.1 rho c_p h^2 / k, h = 1.5 dp, cubic kernel. Error: largest |T - T_exact| / 100 K.
A rerun that gives the committed numbers again, wall times aside, leaves conduction.json as it is (study.write_json);
a run that fails writes nothing.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

from refsph.kernels import get_kernel  # noqa: E402
from refsph.scenes import lattice  # noqa: E402
from refsph.thermal import advance_at_rest  # noqa: E402

OUT = Path(__file__).with_name("conduction.json")
RHO, CP, K = 7870.0, 486.0, 50.7            # AISI 1045 of the second paper (Table 2)
A = K / (RHO * CP)
KERNEL = get_kernel("cubic")


def advance(T, x, dp, t_end):
    return advance_at_rest(T, x, np.full(len(x), dp * dp), A, 1.5 * dp, KERNEL, t_end, 0.1, RHO, CP, K)


def pulse(n, L=12e-3, s0=1e-3):
    dp = L / n
    x = lattice([L, L], dp) - L / 2
    t0 = s0 ** 2 / (2 * A)
    r2 = np.sum(x * x, axis=1)
    T, steps = advance(293.0 + 100.0 * np.exp(-r2 / (4 * A * t0)), x, dp, t0)
    return float(np.max(np.abs(T - (293.0 + 50.0 * np.exp(-r2 / (8 * A * t0))))) / 100.0), steps, dp


def insulated(n, L=10e-3, W=2e-3):
    dp = L / n
    x = lattice([L, W], dp)
    t = 0.5 * L * L / (A * np.pi ** 2)
    T, steps = advance(293.0 + 100.0 * np.cos(np.pi * x[:, 0] / L), x, dp, t)
    exact = 293.0 + 100.0 * np.cos(np.pi * x[:, 0] / L) * np.exp(-A * np.pi ** 2 * t / L ** 2)
    return float(np.max(np.abs(T - exact)) / 100.0), steps, dp


def main(argv=None):
    ap = study.parser(__doc__)
    ap.add_argument("--json", type=Path, default=OUT, help="where to write the results (default: conduction.json)")
    path = ap.parse_args(argv).json
    out = {}
    for name, fn, sizes in (("pulse", pulse, (24, 48, 96)), ("insulated", insulated, (10, 20, 40, 80))):
        rows = []
        for n in sizes:
            t0 = time.perf_counter()
            err, steps, dp = fn(n)
            rows.append(dict(n=n, dp_m=dp, steps=steps, error=err, wall_s=time.perf_counter() - t0))
        for a, b in zip(rows, rows[1:]):
            b["order"] = float(np.log(a["error"] / b["error"]) / np.log(b["n"] / a["n"]))
        out[name] = rows
        print(name)
        for r in rows:
            print(f"  {r['n']:4d} across, dp = {r['dp_m'] * 1e3:.3f} mm: error {r['error']:.2e}"
                  + (f", order {r['order']:.2f}" if "order" in r else ""))
    wrote = study.write_json(path, out, ignore=("wall_s",))
    print(f"wrote {path}" if wrote else f"{path}: the same numbers (wall times aside), not rewritten")


if __name__ == "__main__":
    main()
