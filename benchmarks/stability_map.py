"""The stability map: each hard case, each method, the paper's settings and one change at a time.

    python benchmarks/stability_map.py --jobs 2     # every run not yet done (about 25 CPU-minutes), then the map
    python benchmarks/stability_map.py --report     # table and figure again from the committed JSON only

Hard cases (quick resolution, 2D):
  bar          the free elastic bar, 10 periods                     survived: energy not grown by 5 % (viscosity
                                                                     may damp it: that is accuracy, not stability)
  spinning     a free disc spinning at 1 % of c_L, a quarter turn    survived: |L/L0 - 1| < 1e-2, stress < 3x the
                                                                     centrifugal scale (3 + nu)/8 rho w^2 R^2
  rings        two elastic rings thrown at each other                survived: two pieces, never closer than dp/2
  taylor2x     the Taylor bar at twice the speed (362 m/s)           survived: finite, one piece
  pressing10x  the pressing block, the tool at a tenth of its speed:   survived: finite, the block one piece
               the same 0.2 mm travel in ten times the end time
Settings: the baseline is the paper's (artificial viscosity beta1 = beta2 = 1.5, ESPH artificial pressure
gamma = 0.3, the predictor-corrector at Courant 0.3; ESPH uncorrected, TLSPH without hourglass control); each
variant changes one thing (or, marked +, two). Accuracy: the case's own number (energy ratio, L/L0, restitution,
final length, mean tool force), reported beside survived / failed, with the final state's fragment count and
smallest pair distance (every case: particles clumping show there first).

Writes benchmarks/stability_map.json (one record per run, resumable: a rerun skips what is done, and one with nothing
to do writes nothing), benchmarks/stability_map_report.md and figures/10_stability_map.png (each only when its
content, a figure's pixels, changed). refsph.stability holds the rules the run-time
warning applies; tests/test_hard_cases.py checks them against this map.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
OUT_JSON = ROOT / "benchmarks" / "stability_map.json"
REPORT = ROOT / "benchmarks" / "stability_map_report.md"
FIGURE = ROOT / "figures" / "10_stability_map.png"
STORE = study.RunStore(OUT_JSON, good=lambda rec: "survived" in rec)   # a run that failed to run has no verdict

CASES = ("bar", "spinning", "rings", "taylor2x", "pressing10x")
COMMON = {"baseline": {}, "beta 0": dict(beta1=0.0, beta2=0.0), "beta 0.5": dict(beta1=0.5, beta2=0.5),
          "leapfrog": dict(integrator="leapfrog"), "leapfrog + beta 0": dict(integrator="leapfrog", beta1=0.0,
                                                                              beta2=0.0),
          "courant 0.6": dict(courant=0.6)}
VARIANTS = {"esph": dict(COMMON, **{"gamma 0": dict(gamma=0.0), "corrected": dict(esph_correction=True)}),
            "tlsph": dict(COMMON, **{"hourglass 1": dict(hourglass=1.0),
                                     "hourglass 1 + leapfrog": dict(hourglass=1.0, integrator="leapfrog")})}


def _case_args(case: str) -> tuple[str, dict]:
    if case == "bar":
        period = 2 * 20e-3 / 5382.7                       # 2D plane-strain c_bar of AISI 4340
        return "bar", dict(quick=True, t_end=10 * period)
    if case == "spinning":
        return "spinning_disc", dict(quick=True, options=dict(speed=0.01, turns=0.25))
    if case == "rings":
        return "rings", dict(quick=True)
    if case == "taylor2x":
        return "taylor", dict(dim=2, quick=True, options=dict(speed_factor=2.0))
    return "pressing", dict(quick=True, options=dict(speed_factor=0.1))


def judge(case: str, res) -> tuple[bool, float, str]:
    """(survived, accuracy number, what the number is) of a finished run."""
    from refsph.scenes.measure import n_fragments
    m, st, dp = res.summary["metrics"], res.state, res.setup.dp
    if case == "bar":
        e = m["energy_final_over_initial"]
        return bool(np.isfinite(e) and e < 1.05), e, "energy ratio"
    if case == "spinning":
        scale = m["centrifugal_stress_over_1pct"]
        ok = abs(m["angular_momentum_ratio"] - 1) < 1e-2 and m["max_stress_over_1pct"] < 3 * scale
        return bool(ok), m["angular_momentum_ratio"], "L / L0"
    if case == "rings":
        ok = m["n_fragments"] == 2 and m["min_interbody_distance_over_dp"] > 0.5
        return bool(ok), m["restitution"], "restitution"
    body = st.x if st.body is None else st.x[st.body == 0]
    one = n_fragments(body, 1.5 * dp) == 1
    if case == "taylor2x":
        return bool(one), m["final_length_mm"], "final length [mm]"
    return bool(one), m["tool_force_mean_N_per_m"] * 1e-6, "mean tool force [MN/m]"


def run_one(key: str) -> dict:
    from refsph.scenes.measure import min_pair_distance, n_fragments
    from refsph.simulate import SimulationError, run
    case, method, variant = key.split("|")
    scene, kw = _case_args(case)
    numerics = dict(VARIANTS[method][variant], threads=1)
    t0 = time.perf_counter()
    rec = dict(key=key, case=case, scene=scene, method=method, variant=variant, numerics=VARIANTS[method][variant])
    try:
        res = run(scene, method, progress=False, numerics=numerics, **kw)
        ok, acc, what = judge(case, res)
        dp = res.setup.dp
        rec.update(status="ok", survived=ok, accuracy=acc, measure=what, n_steps=res.summary["n_steps"],
                   n_fragments=n_fragments(res.state.x, 1.5 * dp),
                   min_pair_distance_over_dp=min_pair_distance(res.state.x, 1.5 * dp) / dp)
    except SimulationError as e:
        rec.update(status="failed", survived=False, accuracy=float("nan"), measure="", error=str(e)[:300])
    rec["wall_time_s"] = time.perf_counter() - t0
    return rec


def keys() -> list[str]:
    return [f"{c}|{m}|{v}" for c in CASES for m in VARIANTS for v in VARIANTS[m]]


def report(res: dict) -> str:
    runs = res["runs"]
    P = study.Page("stability_map_report")          # the prose: benchmarks/templates/stability_map_report.md
    lines = [P("head"), ""]
    for method in VARIANTS:
        lines += [f"## {method.upper()}", "", "| setting | " + " | ".join(CASES) + " |",
                  "|---|" + "---|" * len(CASES)]
        for v in VARIANTS[method]:
            cells = []
            for c in CASES:
                r = runs.get(f"{c}|{method}|{v}")
                if r is None or not STORE.good(r):
                    cells.append("(to run)")
                    continue
                acc = "" if not np.isfinite(r["accuracy"]) else f" {r['accuracy']:.3g}"
                cells.append(f"{'yes' if r['survived'] else 'NO'}{acc} ({r['wall_time_s']:.0f} s)")
            lines.append(f"| {v} | " + " | ".join(cells) + " |")
        lines.append("")
    done = [r["wall_time_s"] for r in runs.values() if STORE.good(r)]
    lines += [P("total", done=len(done), all=len(keys()), minutes=f"{sum(done) / 60:.1f}"), ""]
    return "\n".join(lines)


def figure(res: dict) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from refsph.teaching.plots import slide_style, stability_map
    with plt.rc_context(slide_style()):                     # the figure chapter 10 shows, drawn by the same code
        fig, axes = plt.subplots(2, 1, figsize=(8.5, 6.4), sharex=True, constrained_layout=True)
        stability_map(axes, res["runs"], CASES, {m: list(v) for m, v in VARIANTS.items()})
        study.save_figure(fig, FIGURE, dpi=110)


def main(argv=None) -> int:
    ap = study.parser(__doc__, "jobs", "only", "report",
                      only=dict(nargs="*", help="cases to run (default: all)"),
                      report=dict(help="table and figure from the committed JSON only"))
    args = ap.parse_args(argv)
    if not args.report:
        todo = [k for k in STORE.pending(keys(), retry_failed=True)
                if args.only is None or k.split("|")[0] in args.only]
        print(f"{len(todo)} runs to do ({len(STORE.records())} done)", flush=True)
        if not todo:                                        # a rerun with nothing to do leaves every file as it was
            print("nothing to run; the JSON, the page and the figure are unchanged (--report rewrites them)")
            return 0
        for k, (key, rec) in enumerate(study.execute(run_one, {key: (key,) for key in todo}, args.jobs)):
            STORE.commit(key, rec)
            print(f"[{k + 1}/{len(todo)}] {key:40s} {'survived' if rec.get('survived') else 'FAILED':9s} "
                  f"{rec.get('accuracy', float('nan')):.4g} {rec.get('wall_time_s', float('nan')):6.1f} s", flush=True)
    res = STORE.load()
    study.write_if_changed(REPORT, report(res))
    figure(res)
    print(f"{OUT_JSON}, {REPORT}, {FIGURE}: each written where its content changed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
