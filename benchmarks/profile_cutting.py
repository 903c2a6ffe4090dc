"""Where a thermomechanical cutting step spends its time (issue 22, part 5): cProfile over the first t_u of cut of
case 1 at the scene's default resolution (t_u / 5, 2,584 particles), grouped by the piece of the method each
function belongs to.

    python benchmarks/profile_cutting.py                      # about a minute; prints the table
    python benchmarks/profile_cutting.py --set contact=penalty --json /tmp/p.json
    python benchmarks/profile_cutting.py --quick              # the quick scene (a few hundred particles)

The groups are the modules of refsph (refsph.thermal: conduction and the heat step; refsph.surface: the free-surface
detector; refsph.neighbours: pair search and pair sums; refsph.tlsph / reference: the TLSPH rates and the
operator; refsph.contact / penalty / coupling: the tool contact; ...), by each function's own time (tottime), with
the functions of NumPy, SciPy and Python charged to the refsph function that called them.
"""
from __future__ import annotations

import cProfile
import json
import pstats
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

from refsph.cli import _parse_numerics  # noqa: E402
from refsph.simulate import run  # noqa: E402

OPTIONS = dict(case=1, travel=1.0)


def group_of(filename: str) -> str | None:
    """The refsph module of a profiled function (None: not refsph's)."""
    path = Path(filename)
    if "refsph" not in path.parts:
        return None
    return ".".join(path.parts[path.parts.index("refsph"):]).removesuffix(".py")


def charged_times(stats: pstats.Stats) -> dict:
    """Each refsph module's time: its functions' own time plus that of the non-refsph functions they call, directly
    or through other non-refsph functions (SciPy's sparse product under ``@``): a non-refsph function's time is
    split among its callers in proportion to the calls, and passed on up until it reaches refsph functions."""
    shares: dict = {}

    def share(func, seen=()) -> dict:
        """{refsph module: fraction} of the time of ``func``: its callers' shares weighted by their calls, over the
        callers whose chain reaches refsph (a chain back into ``seen``, a call cycle, does not)."""
        if group_of(func[0]) is not None:
            return {group_of(func[0]): 1.0}
        if not seen and func in shares:
            return shares[func]
        parts = [(v[0], share(k, seen + (func,))) for k, v in stats.stats[func][4].items()
                 if k not in seen and k in stats.stats]
        total = sum(calls for calls, sub in parts if sub)
        out: dict = {}
        for calls, sub in parts:
            for mod, f in sub.items():
                out[mod] = out.get(mod, 0.0) + f * calls / total
        if not seen:                                        # (a share found with callers left out is not kept)
            shares[func] = out
        return out

    out: dict[str, float] = {}
    for func, (_, _, tottime, _, _) in stats.stats.items():
        for mod, f in share(func).items():
            out[mod] = out.get(mod, 0.0) + tottime * f
    return out


def main(argv=None) -> int:
    ap = study.parser(__doc__, "quick")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="a Numerics field")
    ap.add_argument("--option", action="append", default=[], metavar="NAME=VALUE",
                    help="a scene option besides case=1, travel=1 (e.g. n_tu=10)")
    ap.add_argument("--top", type=int, default=0, help="also list the N refsph functions that cost most")
    ap.add_argument("--json", type=Path, default=None, help="also write the table as JSON here")
    args = ap.parse_args(argv)
    options = dict(OPTIONS)
    for item in args.option:
        if "=" not in item:
            ap.error(f"--option takes NAME=VALUE (a scene option), got {item!r}")
        name, value = item.split("=", 1)
        options[name] = value
    try:                                                   # refsph run's --set: typed, unknown names refused
        numerics = {"threads": 1, **_parse_numerics(args.set)}
    except ValueError as e:
        ap.error(str(e))
    prof = cProfile.Profile()
    t0 = time.perf_counter()
    prof.enable()
    res = run("thermal_cutting", "tlsph", quick=args.quick, progress=False, options=options, numerics=numerics)
    prof.disable()
    wall = time.perf_counter() - t0
    times = charged_times(pstats.Stats(prof))
    total = sum(times.values())
    steps, n = res.summary["n_steps"], res.summary["n_particles"]
    rows = [[k, study.fmt(v, ".2f"), study.fmt(100 * v / total, ".1f")] for k, v in
            sorted(times.items(), key=lambda kv: -kv[1]) if v > 0.005 * total]
    print(study.md_table(["module", "s", "%"], rows))
    if args.top:
        print()
        pstats.Stats(prof).sort_stats("cumulative").print_stats(r"refsph", args.top)
    print(f"\n{steps} steps, {n} particles, {wall:.1f} s wall (profiled): {1e6 * wall / (steps * n):.2f} us per "
          f"particle-step; numerics {numerics}")
    if args.json:
        args.json.write_text(json.dumps(dict(numerics=numerics, options=options, quick=args.quick, n_steps=steps,
                                             n_particles=n,
                                             wall_s=wall, seconds=times), indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
