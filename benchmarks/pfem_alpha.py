"""The PFEM's boundary detector, the alpha-shape: the quick cut (case 1, t_u/5, 4 t_u on a 1.2 mm workpiece) and
case 1's whole cut at t_u/5 (the sweep's 'case 1 n_tu 5 pfem': 16 t_u of cut) with alpha = 1.25, 1.4 (refsph's
default), 1.7 and 2.0: forces, temperatures, chip, steps, Newton iterations.

    python benchmarks/pfem_alpha.py            # about 15 minutes on one core; writes pfem_alpha.json
    python benchmarks/pfem_alpha.py --report   # the table from the JSON

The paper explains part of the difference between its PFEM's and its SPH's forces by their boundary detectors
("PFEM uses the alpha-shape whereas SPH constructs a free-surface detection algorithm") and leaves the study to
future work; refsph's SPH side is the report of thermal_cutting.py (the detector of the heat losses). In refsph's
PFEM the alpha-shape decides which triangles the mesh keeps (a triangle whose circumradius exceeds alpha times the
local spacing is left out) and so which nodes are on the boundary: only those may touch the tool, each with its
tributary boundary length, and only their edges lose heat. Each row's change is against alpha = 1.4 (percent).
The runs go to runs/pfem_alpha/alpha_A and runs/pfem_alpha/case_1_t_u5_alpha_A (kept: a rerun continues or
skips them). Read the changes with the PFEM's resolution error: the edge's place between node rows moves Fp by
+-8.5 % on the same quick cut (pfem_edge_phase_report.md), and with its path sensitivity (three whole cuts of
case 1 at t_u/10 by different solver versions spread Fc and Fp by about 7 %).
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()
import pfem_time_step  # noqa: E402  (the quick cut at one value of a PFEM option, and its table)

ROOT = Path(__file__).resolve().parents[1]
OUT_JSON = Path(__file__).resolve().parent / "pfem_alpha.json"
RUNS = ROOT / "runs" / "pfem_alpha"
ALPHAS = (1.25, 1.4, 1.7, 2.0)
DEFAULT = 1.4
TITLES = {"": "# The PFEM's alpha-shape (quick cut: case 1, t_u/5, 4 t_u)",
          "case 1 t_u/5": "## Case 1's whole cut at t_u/5 (16 t_u of cut; means over its last quarter)"}
MADE_BY = ("Made by `python benchmarks/pfem_alpha.py` (module text). In brackets: the change against alpha = "
           f"{DEFAULT:g} (refsph's default), percent.")


def report(rows: list) -> str:
    """A table per cut, each row's change against alpha = DEFAULT."""
    return pfem_time_step.per_cut_report(rows, TITLES, "alpha", MADE_BY, "The same, on the whole cut.", DEFAULT)


def main(argv=None) -> int:
    return pfem_time_step.scan_main(argv, __doc__, ALPHAS, "alpha", RUNS, OUT_JSON, report, cuts=tuple(TITLES))


if __name__ == "__main__":
    raise SystemExit(main())
