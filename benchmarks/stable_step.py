"""Why the SPH cuts blow up, measured: the largest Courant number each state allows, against the one the run uses
(issue 22; chapter 11, "Why the step breaks").

The leapfrog on the linearised elastic equations u'' = -K u is stable if and only if dt w_max < 2
(:func:`refsph.tlsph.largest_frequency`: w_max^2 the largest eigenvalue of K, found matrix-free by ARPACK). With the
CFL step dt = C h / (c_L + |v|max), the state allows any Courant number below

    C_crit = 2 (c_L + |v|max) / (w_max h).

Case 1 of the thermomechanical cut at dx = t_u/5 (the sweep's 'coarse' settings, ``thermal_cutting.converged(1,
n_tu=5)``) is run at the scene's Courant number 0.3, where it blows up at 0.77 ms, again with
``Numerics.gain_step`` (the CFL step over the corrected gradient's largest gain a_max,
:func:`refsph.tlsph.gradient_gain`), and with ``Numerics.frequency_step`` 0.5 (the step no longer than half the
critical step 2 / w_max of each reference configuration). At every reference update (the operator, hence K,
changes only there, apart from the stress and the positions' slow drift) a hook (``simulate(hook=...)``) records
C_crit, the Courant number in use (0.3; 0.3 / a_max with the gain step; with ``Numerics.frequency_step`` 0.5 no
more than half of the reference configuration's own C_crit), a_max, and the particle where the mode is largest. The
check of the criterion itself, on a lattice and a torn tip (stable at 0.97 of the critical step, failing at 1.03),
is ``tests/test_stable_step.py``.

    python benchmarks/stable_step.py              # the three runs (about 15 min on one core), JSON, page, figure
    python benchmarks/stable_step.py --report     # the page and figure from the JSON

Writes benchmarks/stable_step.json, benchmarks/stable_step_report.md and figures/11_stable_step.png.
"""
from __future__ import annotations

import argparse
import json
import re
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

OUT_JSON = study.HERE / "stable_step.json"
OUT_MD = study.HERE / "stable_step_report.md"
FIGURE = study.ROOT / "figures" / "11_stable_step.png"
RUNS = {"courant 0.3": {}, "courant 0.3 gain step": dict(gain_step=True),        # label: Numerics beside threads=1
        "courant 0.3 frequency step 0.5": dict(frequency_step=0.5)}


def measure(numerics: dict) -> dict:
    """Case 1 at t_u/5 at the scene's Courant number (with ``numerics``: the gain step, the frequency step), C_crit
    at every reference update (module text)."""
    import thermal_cutting as tc
    from refsph.simulate import SimulationError, build, simulate, time_step
    from refsph.tlsph import gradient_gain, largest_frequency
    setup, scene, metrics = build("thermal_cutting", "tlsph", numerics=dict(numerics, threads=1),
                                  options=tc.converged(1, n_tu=5.0))
    h, c = setup.h, setup.material.c_longitudinal
    rows, seen = [], set()

    def hook(state, solver):
        op = solver.reference.op
        if op is None or id(op) in seen:
            return
        seen.clear()
        seen.add(id(op))
        body = solver.reference.rows(state, solver.constraints.n_deformable)
        omega, mode = largest_frequency(body, solver.material, solver.params, op)
        gain = gradient_gain(op)
        vmax = float(np.sqrt(np.max(np.sum(state.v**2, axis=1))))
        peak = int(np.argmax(mode))
        rows.append(dict(t_ms=1e3 * float(state.t), update=int(solver.reference.n_updates),
                         C_crit=2.0 * (c + vmax) / (omega * h), gain_max=float(gain.max()),
                         courant_used=time_step(setup, None, state, (), solver) * (c + vmax) / h,
                         mode_particle=peak, mode_gain=float(gain[peak]), gain_particle=int(np.argmax(gain))))

    start = time.process_time()
    try:
        res = simulate(setup, "tlsph", scene=scene, metrics=metrics, hook=hook, progress=False)
        end = dict(status="ok", t_ms=1e3 * float(res.state.t), failed_particle=None, steps=res.summary["n_steps"])
    except SimulationError as e:
        found = re.search(r"particle (\d+)", str(e))
        end = dict(status="failed", message=str(e)[:300], failed_particle=int(found.group(1)) if found else None)
    return dict(updates=rows, end=end, cpu_min=(time.process_time() - start) / 60.0)


def ordered(data: dict) -> dict:
    """The recorded runs in the order of RUNS."""
    return {k: data[k] for k in RUNS if k in data}


def figure(data: dict) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True)
    for (label, run), color in zip(ordered(data).items(), ("C3", "C0", "C2")):
        t = [r["t_ms"] for r in run["updates"]]
        ax.plot(t, [r["C_crit"] for r in run["updates"]], "o-", color=color, ms=3, label=f"C_crit, {label}")
        ax.plot(t, [r["courant_used"] for r in run["updates"]], "--", color=color, label=f"in use, {label}")
        bx.plot([r["C_crit"] * r["gain_max"] for r in run["updates"]], "o", color=color, ms=3, label=label)
    ax.set(xlabel="t [ms]", ylabel="Courant number", title="largest stable (C_crit) and in use")
    ax.legend(fontsize=7)
    bx.set(xlabel="reference update", ylabel="C_crit x largest gain", title="C_crit against 1 / gain")
    bx.legend(fontsize=7)
    study.save_figure(fig, FIGURE)
    plt.close(fig)


def report(data: dict) -> str:
    f = study.fmt
    parts = ["# The largest stable Courant number of the cut's states\n\n"
             "Made by `python benchmarks/stable_step.py` (module text): case 1 at dx = t_u/5, one run each, C_crit = "
             "2 (c_L + |v|max) / (w_max h) at every reference update, w_max the largest frequency of the linearised "
             "elastic TLSPH equations (`refsph.tlsph.largest_frequency`); a state is stable with the leapfrog below "
             "C_crit. The gain is the corrected gradient's (`refsph.tlsph.gradient_gain`).\n\n"
             "![C_crit](../figures/11_stable_step.png)\n"]
    for label, run in ordered(data).items():
        rows = run["updates"]
        table = [[r["update"], f(r["t_ms"], ".4f"), f(r["C_crit"], ".3f"), f(r["courant_used"], ".3f"),
                  f(r["gain_max"], ".2f"), f(r["C_crit"] * r["gain_max"], ".2f"), r["mode_particle"],
                  f(r["mode_gain"], ".2f")] for r in rows]
        end = run["end"]
        said = (f"ran to its end ({end['t_ms']:.3f} ms, {end.get('steps', '?')} steps)" if end["status"] == "ok" else
                f"failed: {end['message']} (the mode's particle at the last update: {rows[-1]['mode_particle']})")
        parts.append(f"\n## {label}\n\n{said}; {run['cpu_min']:.1f} min of CPU.\n\n" + study.md_table(
            ["update", "t [ms]", "C_crit", "Courant in use", "largest gain", "C_crit x gain", "mode's particle",
             "its gain"], table) + "\n")
    return "".join(parts)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--report", action="store_true", help="only the page and the figure, from the JSON")
    args = ap.parse_args(argv)
    data = json.loads(OUT_JSON.read_text()) if OUT_JSON.exists() else {}
    if not args.report:
        for label, numerics in RUNS.items():
            if label not in data:
                data[label] = measure(numerics)
                study.write_json(OUT_JSON, data)                 # each run kept as soon as it is done
                print(f"{label}: {data[label]['end']['status']}, {len(data[label]['updates'])} updates", flush=True)
    figure(data)
    page = report(data)
    study.write_if_changed(OUT_MD, page)
    print(page)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
