"""Command line: ``refsph list`` and ``refsph run SCENE --method {esph,tlsph} ...``."""
from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from .scenes import SCENES
from .simulate import METHODS, SimulationError, run


def _fmt(v):
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, np.ndarray) or isinstance(v, list):
        return f"<{np.asarray(v).shape} array>"
    return str(v)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="refsph", description="Reference ESPH/TLSPH for metal machining")
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("list", help="list the scenes")
    r = sub.add_parser("run", help="run a scene")
    r.add_argument("scene")
    r.add_argument("--method", choices=METHODS, default="tlsph")
    r.add_argument("--dim", type=int, choices=(2, 3), default=2)
    r.add_argument("--dp", type=float, default=None, help="particle spacing [m] (default: the scene's)")
    r.add_argument("--t-end", type=float, default=None, help="end time [s] (default: the scene's)")
    r.add_argument("--dt", type=float, default=None, help="fixed time step [s] (default: CFL)")
    r.add_argument("--out", default=None, help="output directory (default: runs/SCENE-METHOD-DIMd)")
    r.add_argument("--quick", action="store_true", help="coarse, fast version of the scene")
    r.add_argument("--quiet", action="store_true", help="no progress lines")
    args = ap.parse_args(argv)

    if args.cmd == "list":
        for name, sc in SCENES.items():
            print(f"{name:10s} {sc.description}")
        return 0

    if args.scene not in SCENES:
        print(f"refsph: unknown scene {args.scene!r}; available: {', '.join(sorted(SCENES))}", file=sys.stderr)
        return 2
    out = args.out or f"runs/{args.scene}-{args.method}-{args.dim}d"
    try:
        res = run(args.scene, args.method, dim=args.dim, dp=args.dp, t_end=args.t_end, out=out,
                  quick=args.quick, dt=args.dt, progress=not args.quiet)
    except SimulationError as e:
        print(f"refsph: run failed: {e}", file=sys.stderr)
        return 3
    except ValueError as e:
        print(f"refsph: {e}", file=sys.stderr)
        return 2
    s = res.summary
    print(f"{s['scene']} {s['method']} {s['dim']}D: {s['n_particles']} particles, {s['n_steps']} steps, "
          f"{s['wall_time_s']:.1f} s ({s['particle_steps_per_s']:.3g} particle-steps/s)")
    for k, v in s["metrics"].items():
        print(f"  {k:32s} {_fmt(v)}")
    print(f"output: {out}/summary.json, {out}/snapshots/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
