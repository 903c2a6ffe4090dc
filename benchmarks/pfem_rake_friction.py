"""Why the PFEM's Fp/Fc is low: the tool's contact forces of a PFEM cut split into the rake face and the edge and
flank, with the rake face's friction ratio, its sticking and slipping nodes, and the largest Fp/Fc that Coulomb
friction on the rake face alone can give.

    python benchmarks/pfem_rake_friction.py                    # the sweep's case 1 PFEM run folders that exist
    python benchmarks/pfem_rake_friction.py --run DIR [DIR..]  # any finished PFEM cut's run folder

Each run is continued from its last checkpoint (``snapshots/restart.npz``, the cut extended by one t_u so that
steps remain) for ``--steps`` steps; each step's contact (:class:`refsph.pfem.contact.StepContact`) is read at the
converged positions. Without a run folder the quick cut (case 1, t_u/5, 4 t_u; about a minute) is run first. For a
chip on the rake face alone (rake angle alpha) with a friction ratio m = F_T / F_N, the tool's force ratio is

    Fp / Fc = (m cos alpha - sin alpha) / (cos alpha + m sin alpha) = tan(atan(m) - alpha),

so Coulomb friction with mu0 (the law at room temperature, its largest) caps Fp/Fc at tan(atan(mu0) - alpha):
0.55 for AISI 1045 (mu0 = 0.81, alpha = 10 deg). What is above it must come from the edge and the flank.
Writes pfem_rake_friction.json (next to this file).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT_JSON = Path(__file__).resolve().parent / "pfem_rake_friction.json"
SWEEP_RUNS = [ROOT / "runs" / "thermal_cutting" / k for k in ("case_1_pfem_short_n_tu_5", "case_1_pfem_short_n_tu_10",
                                                              "case_1_pfem_n_tu_5", "case_1_pfem")]


def rake_friction_bound(m: float, rake_deg: float) -> float:
    """Fp/Fc = tan(atan(m) - alpha) of a chip on the rake face alone (module text)."""
    return math.tan(math.atan(m) - math.radians(rake_deg))


def contact_split(run_dir: Path, steps: int) -> dict:
    """Continue the run in ``run_dir`` for ``steps`` steps; the sums of its contact forces (module text)."""
    import refsph.pfem.cutting as cutting
    from refsph.io import read_npz
    from refsph.scenes.thermal_cutting import rake_frame
    s = json.loads((run_dir / "summary.json").read_text())
    opt, info = s["run_args"]["options"], s["scene_info"]
    travel = info["travel_m"] / info["tu_m"]
    cut = cutting.pfem_cut(int(opt["case"]), n_tu=float(opt.get("n_tu", 10.0)), travel=travel + 1.0,
                           length=info["length_m"])
    arrays = read_npz(run_dir / "snapshots" / "restart.npz", "the run's checkpoint")
    arrays.pop("run", None)
    run = cutting.CutRun.restore(cut, arrays)
    seen, original = {}, cutting.StepContact.__call__

    def spy(self, x, stiffness=True):
        out = original(self, x, stiffness)
        seen.update(contact=self, x=x.copy())
        return out

    sums = dict(rake_N=0.0, rake_T=0.0, rake_mu_N=0.0, other_x=0.0, other_y=0.0, tool_x=0.0, tool_y=0.0,
                rake_nodes=0, slipping=0, other_nodes=0)
    cutting.StepContact.__call__ = spy
    try:
        for _ in range(steps):
            r = run.step()
            c, x = seen["contact"], seen["x"]
            last = c.last
            u, _ = rake_frame(x, run.nodes.t, cut.info)
            on = last["f_N"] > 0
            rake, other = on & (u >= 0.0), on & (u < 0.0)
            fN, fT, mu = last["f_N"][rake], last["f_T"][rake], c.mu[rake]
            sums["rake_N"] += fN.sum()
            sums["rake_T"] += fT.sum()
            sums["rake_mu_N"] += (mu * fN).sum()
            sums["rake_nodes"] += int(rake.sum())
            sums["slipping"] += int(np.sum(np.abs(np.abs(fT) - mu * fN) <= 1e-9 * mu * fN))
            sums["other_nodes"] += int(other.sum())
            f_other = -r.contact_force[other].sum(axis=0)
            F = -r.contact_force.sum(axis=0)
            sums["other_x"] += f_other[0]
            sums["other_y"] += f_other[1]
            sums["tool_x"] += F[0]
            sums["tool_y"] += F[1]
    finally:
        cutting.StepContact.__call__ = original
    m = sums["rake_T"] / sums["rake_N"]
    mu = sums["rake_mu_N"] / sums["rake_N"]
    rake_deg = info["rake_deg"]
    return dict(run=str(run_dir.relative_to(ROOT) if run_dir.is_relative_to(ROOT) else run_dir),
                n_tu=float(opt.get("n_tu", 10.0)), steps=steps, t_from_s=float(arrays["nodes/t"]),
                Fc_N_per_mm=sums["tool_x"] / steps / 1e3, Fp_N_per_mm=sums["tool_y"] / steps / 1e3,
                force_ratio=sums["tool_y"] / sums["tool_x"], rake_friction_ratio=m, rake_mu_law=mu,
                rake_nodes_per_step=sums["rake_nodes"] / steps, slipping_fraction=sums["slipping"] / sums["rake_nodes"],
                edge_flank_nodes_per_step=sums["other_nodes"] / steps,
                edge_flank_force_N_per_mm=[sums["other_x"] / steps / 1e3, sums["other_y"] / steps / 1e3],
                bound_from_rake_friction=rake_friction_bound(m, rake_deg),
                bound_from_mu_law=rake_friction_bound(mu, rake_deg),
                bound_from_mu0=rake_friction_bound(float(cut.contact.friction.mu0), rake_deg))


def quick_run(folder: Path) -> Path:
    from refsph.pfem_run import run_pfem
    out = folder / "quick"
    run_pfem("thermal_cutting", out=out, quick=True, progress=False)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--run", nargs="*", type=Path, default=None, help="finished PFEM run folders")
    ap.add_argument("--steps", type=int, default=4, help="steps to continue each run (default 4)")
    args = ap.parse_args(argv)
    runs = args.run or [d for d in SWEEP_RUNS if (d / "snapshots" / "restart.npz").exists()
                        and (d / "summary.json").exists()
                        and json.loads((d / "summary.json").read_text()).get("status") == "ok"]
    missing = [str(d) for d in runs if not (Path(d) / "summary.json").exists()
               or not (Path(d) / "snapshots" / "restart.npz").exists()]
    if missing:
        print(f"not a finished PFEM run folder (summary.json and snapshots/restart.npz): {', '.join(missing)}",
              file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory() as tmp:
        if not runs:
            runs = [quick_run(Path(tmp))]
        rows = [contact_split(Path(d).resolve(), args.steps) for d in runs]
    for r in rows:
        print(f"{r['run']}: Fp/Fc {r['force_ratio']:.3f}; rake face F_T/F_N {r['rake_friction_ratio']:.3f} (law's mu "
              f"{r['rake_mu_law']:.3f}), {r['rake_nodes_per_step']:.0f} nodes, {100 * r['slipping_fraction']:.0f} % "
              f"slipping; edge and flank: {r['edge_flank_nodes_per_step']:.1f} nodes, force "
              f"{r['edge_flank_force_N_per_mm'][0]:.1f}, {r['edge_flank_force_N_per_mm'][1]:.1f} N/mm; Fp/Fc bound "
              f"from the rake's ratio {r['bound_from_rake_friction']:.3f}, from the law's mu "
              f"{r['bound_from_mu_law']:.3f}, from mu0 {r['bound_from_mu0']:.3f}")
    OUT_JSON.write_text(json.dumps(dict(rows=rows, made_by="python benchmarks/pfem_rake_friction.py"), indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
