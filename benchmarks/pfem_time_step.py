"""The PFEM cut's time step: the quick cut (case 1, t_u/5, 4 t_u on a 1.2 mm workpiece) at dt = courant dx / v_c for
courant 1, 0.5, 0.25 (the default) and 0.125: forces, temperatures, chip, steps, halved steps, Newton iterations.

    python benchmarks/pfem_time_step.py            # about 10 minutes on one core; writes pfem_time_step.json
    python benchmarks/pfem_time_step.py --report   # the table from the JSON

Each change of the step is measured against the next smaller one, so the table says from which step on the digits
stop moving (an implicit step has no stability limit: accuracy, the remeshing and Newton-Raphson set it). The runs
go to runs/pfem_time_step/courant_C (kept: a rerun continues or skips them).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

ROOT = Path(__file__).resolve().parents[1]
OUT_JSON = Path(__file__).resolve().parent / "pfem_time_step.json"
RUNS = ROOT / "runs" / "pfem_time_step"
COURANTS = (1.0, 0.5, 0.25, 0.125)
KEYS = (("Fc [N/mm]", "cutting_force_N_per_m", 1e-3, ".1f"), ("Fp [N/mm]", "passive_force_N_per_m", 1e-3, ".1f"),
        ("Fp/Fc", "force_ratio", 1.0, ".3f"), ("T_RF [K]", "rake_face_temperature_K", 1.0, ".0f"),
        ("T_FCS [K]", "free_chip_surface_temperature_K", 1.0, ".0f"), ("chip [mm]", "chip_thickness_mm", 1.0, ".3f"))


def run_one(courant: float) -> dict:
    """The quick cut at this courant number (continued if a run folder is there); its record."""
    from refsph.pfem_run import run_pfem
    out = RUNS / f"courant_{courant:g}"
    restart = (out / "snapshots" / "restart.npz").exists()
    if (out / "summary.json").exists() and json.loads((out / "summary.json").read_text()).get("status") == "ok":
        s = json.loads((out / "summary.json").read_text())
    else:
        s = run_pfem("thermal_cutting", out=out, options=dict(courant=courant), quick=True, progress=False,
                     restart=restart).summary
    return dict(courant=courant, status=s["status"], n_steps=s["n_steps"], wall_time_s=s["wall_time_s"],
                newton=s["newton"], metrics={k: s["metrics"].get(k) for _, k, _, _ in KEYS})


def report(rows: list) -> str:
    """The table, with each quantity's change against the next smaller step (percent)."""
    rows = sorted(rows, key=lambda r: -r["courant"])
    head = "| courant | steps | halved | Newton iterations | " + " | ".join(k[0] for k in KEYS) + " |"
    lines = ["# The PFEM cut's time step (quick cut: case 1, t_u/5, 4 t_u)", "",
             "Made by `python benchmarks/pfem_time_step.py` (module text). In brackets: the change against the next "
             "smaller step, percent.", "", head, "|---" * (4 + len(KEYS)) + "|"]
    for i, r in enumerate(rows):
        finer = rows[i + 1]["metrics"] if i + 1 < len(rows) else None
        cells = []
        for _, key, scale, fmt in KEYS:
            v = r["metrics"][key]
            d = "" if finer is None or not finer[key] else f" ({100 * (v / finer[key] - 1):+.1f})"
            cells.append(f"{format(v * scale, fmt)}{d}")
        lines.append(f"| {r['courant']:g} | {r['n_steps']} | {r['newton']['halved_steps']} | "
                     f"{r['newton']['iterations']} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--report", action="store_true", help="only the table from the JSON")
    args = ap.parse_args(argv)
    if not args.report:
        rows = [run_one(c) for c in COURANTS]
        OUT_JSON.write_text(json.dumps(dict(rows=rows, made_by="python benchmarks/pfem_time_step.py"), indent=1)
                            + "\n")
    if not OUT_JSON.exists():
        print(f"no {OUT_JSON.name}: run python benchmarks/pfem_time_step.py first", file=sys.stderr)
        return 2
    text = report(json.loads(OUT_JSON.read_text())["rows"])
    (OUT_JSON.parent / "pfem_time_step_report.md").write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
