"""The tool's edge radius in the PFEM cut: case 1 over 8 t_u of cut (the first half of the sweep's 'case 1 pfem n_tu
5' and 'case 1 pfem', on their workpiece) at t_u/5 with the contact outline's edge radius 5, 10 (the paper's), 20
and 30 um, and at t_u/10 (10 um nodes) with 10, 20 and 30 um: forces, temperatures, chip, steps, Newton iterations.

    python benchmarks/pfem_edge_radius.py            # t_u/5: 5 min on one core; t_u/10: hours; writes the JSON
    python benchmarks/pfem_edge_radius.py --report   # the table from the JSON

Why: the paper's PFEM gives Fp/Fc = 0.62 for case 1, more than Coulomb friction on the 10 deg rake face can give at
mu0 = 0.81 (Merchant's bound 0.55, at mu(850 K) about 0.47), so the rest of its thrust has to act on the edge or the
flank; refsph's PFEM puts about 1 % of Fp there (force_split_report.md). A node-based contact or a coarse node row
makes an edge effectively blunter than its 10 um; this scan measures how much thrust a blunter edge adds. Each row's
change is against the paper's 10 um (percent). The runs go to runs/pfem_edge_radius/ (kept: a rerun continues or
skips them). Read the changes with the PFEM's resolution error: the edge's place between node rows moves Fp by
+-8.5 % on the quick cut (pfem_edge_phase_report.md). At t_u/5 the 5 um and 10 um outlines give the same converged
cut to every digit shown (they differ within 14 um of the apex, and no converged node lies there: the workpiece
parts from the tool ahead of its edge). At t_u/10 a blunter edge makes Newton struggle (20 um: 14 halved steps and
624 iterations in the first 47 steps, against none halved at 10 um): those runs take hours, and the JSON is written
only when all have run.
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()
import pfem_time_step  # noqa: E402  (a cut at one value of a PFEM option, and its table)

ROOT = Path(__file__).resolve().parents[1]
OUT_JSON = Path(__file__).resolve().parent / "pfem_edge_radius.json"
RUNS = ROOT / "runs" / "pfem_edge_radius"
RADII = {"case 1 t_u/5 8 t_u": (5e-6, 10e-6, 20e-6, 30e-6), "case 1 t_u/10 8 t_u": (10e-6, 20e-6, 30e-6)}
PAPER = 10e-6
TITLES = {"case 1 t_u/5 8 t_u": "# The tool's edge radius in the PFEM cut (case 1, 8 t_u of cut; t_u/5: 20 um nodes)",
          "case 1 t_u/10 8 t_u": "## The same at t_u/10 (10 um nodes)"}
MADE_BY = ("Made by `python benchmarks/pfem_edge_radius.py` (module text). edge_radius in m; in brackets: the change "
           "against the paper's 10 um, percent.")


def report(rows: list) -> str:
    """A table per cut, each row's change against the paper's 10 um."""
    return pfem_time_step.per_cut_report(rows, TITLES, "edge_radius", MADE_BY, "The same, at t_u/10.", PAPER)


def main(argv=None) -> int:
    return pfem_time_step.scan_main(argv, __doc__, RADII, "edge_radius", RUNS, OUT_JSON, report, cuts=tuple(TITLES))


if __name__ == "__main__":
    raise SystemExit(main())
