"""Where the chip is hot: temperature, plastic strain and plastic work against the distance from the rake face, in
the last snapshot of thermal-cutting runs (any method: the PFEM's nodes and the SPH's particles alike).

    python benchmarks/chip_profiles.py                       # case 1 at t_u/5, the PFEM's and the SPH's runs
    python benchmarks/chip_profiles.py --run DIR [DIR ..] [--along 0.3e-3]

The workpiece rows within ``--along`` [m] of the tool's edge along the rake face (u in [0, along) of
:func:`refsph.scenes.thermal_cutting.rake_frame`) are binned by their distance n from the face in half spacings
(dx the run's finest spacing); each bin's means of T [K], eps_p and W_p [J/m^3] and its count. Needs the sweep's run
folders (``benchmarks/thermal_cutting.py``); writes chip_profiles.json next to this file.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT_JSON = Path(__file__).resolve().parent / "chip_profiles.json"
DEFAULT_RUNS = [ROOT / "runs" / "thermal_cutting" / k for k in ("case_1_pfem_n_tu_5", "case_1_n_tu_5")]
FIELDS = ("T", "eps_p", "W_p")


def profile(run_dir: Path, along: float, bins_dx=np.arange(-1.0, 6.01, 0.5)) -> dict:
    """The binned means of FIELDS across the chip near the edge (module text), from the run's last snapshot."""
    from refsph.io import load_snapshot
    from refsph.scenes.thermal_cutting import rake_frame
    s = json.loads((run_dir / "summary.json").read_text())
    info = s["scene_info"]
    z = load_snapshot(run_dir / "snapshots" / s["snapshots"][-1])
    n_work = len(z["x"]) if s["method"] == "pfem" else info["n_work"]
    u, n = rake_frame(z["x"][:n_work], float(z["t"]), info)
    dx = info["dx"]
    near = (u >= 0.0) & (u < along)
    rows = []
    for a, b in zip(bins_dx[:-1], bins_dx[1:]):
        sel = near & (n >= a * dx) & (n < b * dx)
        rows.append(dict(n_from_dx=float(a), n_to_dx=float(b), count=int(sel.sum()),
                         **{f: float(z[f][:n_work][sel].mean()) if sel.any() else None for f in FIELDS}))
    return dict(run=str(run_dir.relative_to(ROOT)) if run_dir.is_relative_to(ROOT) else str(run_dir),
                method=s["method"], t_s=float(z["t"]), dx_m=dx, along_m=along, bins=rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--run", nargs="*", type=Path, default=None, help="run folders (default: case 1, t_u/5, both)")
    ap.add_argument("--along", type=float, default=0.3e-3, help="how far along the rake face [m] (default 0.3 mm)")
    args = ap.parse_args(argv)
    runs = [Path(d).resolve() for d in (args.run or DEFAULT_RUNS)]
    missing = [str(d) for d in runs if not (d / "summary.json").exists()]
    if missing:
        print(f"no run folder at {', '.join(missing)}: run benchmarks/thermal_cutting.py first", file=sys.stderr)
        return 2
    out = [profile(d, args.along) for d in runs]
    for p in out:
        print(f"{p['run']} ({p['method']}, t = {p['t_s'] * 1e3:.2f} ms): n [dx] -> T [K] / eps_p / W_p [GJ/m^3]")
        print("  " + "  ".join(f"{b['n_from_dx']:+.1f}: {b['T']:.0f}/{b['eps_p']:.2f}/{b['W_p'] / 1e9:.2f}"
                               for b in p["bins"] if b["count"]))
    OUT_JSON.write_text(json.dumps(dict(runs=out, made_by="python benchmarks/chip_profiles.py"), indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
