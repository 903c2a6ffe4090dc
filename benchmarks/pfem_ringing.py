"""The step-to-step ringing of the cutting force in the sweep's PFEM cuts (issue 24): for each run folder of
benchmarks/thermal_cutting.py's PFEM keys, from its reaction_forces.csv (the tool's force at every step), the
alternation of Fc

    a_k = |F_k - (F_{k-1} + F_{k+1}) / 2|,          reported as mean(a) / mean(|F|) in each quarter of the cut,

which is 0 for a force that varies linearly and 2 e for one that alternates F0 (1 + e), F0 (1 - e), ... (an
oscillation of period two steps: the undamped ringing of the paper's trapezoidal rule; Newmark's gamma > 1/2 damps
it). Read from the run folders (runs/thermal_cutting/,
made by the sweep; a folder of a run still going gives what it has so far), kept in pfem_ringing.json (a key whose
folder is gone keeps its earlier row) and tabulated in pfem_ringing_report.md.

    python benchmarks/pfem_ringing.py [--runs DIR ...]   # read the folders, write the JSON and the page
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

import thermal_cutting as tc  # noqa: E402

OUT_JSON = Path(__file__).resolve().parent / "pfem_ringing.json"
OUT_MD = Path(__file__).resolve().parent / "pfem_ringing_report.md"


def alternation(F: np.ndarray, parts: int = 4) -> list[float]:
    """mean |F_k - (F_{k-1} + F_{k+1}) / 2| / mean |F_k| over each of ``parts`` equal parts of the steps."""
    a = np.abs(F[1:-1] - 0.5 * (F[:-2] + F[2:]))
    return [float(a[i].mean() / np.abs(F[1:-1][i]).mean()) for i in np.array_split(np.arange(len(a)), parts)]


def row(folder: Path) -> dict | None:
    """The alternation of Fc by quarter, the steps and the simulated time of one run folder (None without forces)."""
    path = folder / "reaction_forces.csv"
    if not path.exists():
        return None
    d = np.loadtxt(path, delimiter=",", comments="#", ndmin=2)
    if len(d) < 16:
        return None
    summary = json.loads((folder / "summary.json").read_text()) if (folder / "summary.json").exists() else {}
    return dict(alternation=alternation(d[:, 2]), steps=len(d), t_ms=float(d[-1, 0] * 1e3),
                status=summary.get("status"), gamma=summary.get("scene_info", {}).get("newmark_gamma"),
                **({"alpha_B": a} if (a := summary.get("scene_info", {}).get("newmark_alpha_B")) else {}))


def report(rows: dict) -> str:
    lines = ["# The PFEM cuts' step-to-step ringing of Fc", "", "Made by `python benchmarks/pfem_ringing.py` from the "
             "sweep's run folders (module text): mean |F_k - (F_{k-1} + F_{k+1})/2| / mean |F| in each quarter of "
             "the steps run.", "", "| run | gamma | status | steps | t [ms] | 1st quarter | 2nd | 3rd | 4th |",
             "|---|---|---|---|---|---|---|---|---|"]
    for key, r in rows.items():
        q = " | ".join(f"{v:.3f}" for v in r["alternation"])
        rule = f"{r['gamma']}" + (f" (Bossak {r['alpha_B']:g})" if r.get("alpha_B") else "")
        lines.append(f"| {key} | {rule} | {r['status']} | {r['steps']} | {r['t_ms']:.3f} | {q} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    return tc.folder_study(argv, __doc__, row, lambda options, numerics: numerics.get("method") == "pfem", OUT_JSON,
                           OUT_MD, report)


if __name__ == "__main__":
    raise SystemExit(main())
