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
import thermal_cutting as tc  # noqa: E402  (the sweep's cuts)

ROOT = Path(__file__).resolve().parents[1]
OUT_JSON = Path(__file__).resolve().parent / "pfem_time_step.json"
RUNS = ROOT / "runs" / "pfem_time_step"
COURANTS = (1.0, 0.5, 0.25, 0.125)
KEYS = (("Fc [N/mm]", "cutting_force_N_per_m", 1e-3, ".1f"), ("Fp [N/mm]", "passive_force_N_per_m", 1e-3, ".1f"),
        ("Fp/Fc", "force_ratio", 1.0, ".3f"), ("T_RF [K]", "rake_face_temperature_K", 1.0, ".0f"),
        ("T_FCS [K]", "free_chip_surface_temperature_K", 1.0, ".0f"), ("chip [mm]", "chip_thickness_mm", 1.0, ".3f"))


def run_one(value: float, option: str = "courant", runs: Path = RUNS, cut: str = "") -> dict:
    """The cut ``cut`` (a key of CUTS: '' the quick cut) with the PFEM option ``option`` (a number) at ``value``
    (continued if a run folder is there); its record, the value under the option's name."""
    from refsph.pfem_run import run_pfem
    base, quick = CUTS[cut]
    out = runs / f"{cut.replace(' ', '_').replace('/', '') + '_' if cut else ''}{option}_{value:g}"
    restart = (out / "snapshots" / "restart.npz").exists()
    if (out / "summary.json").exists() and json.loads((out / "summary.json").read_text()).get("status") == "ok":
        s = json.loads((out / "summary.json").read_text())
    else:
        s = run_pfem("thermal_cutting", out=out, options=dict(base, **{option: value}), quick=quick,
                     progress=False, restart=restart).summary
    rec = {option: value, "status": s["status"], "n_steps": s["n_steps"], "wall_time_s": s["wall_time_s"],
           "newton": s["newton"], "metrics": {k: s["metrics"].get(k) for _, k, _, _ in KEYS}}
    return dict(rec, cut=cut) if cut else rec


# the cuts a scan may run: '' the quick cut (case 1, t_u/5, 4 t_u on 1.2 mm), 'case 1 t_u/5' the whole cut of the
# sweep's 'case 1 pfem n_tu 5' (its options as the sweep gives them: 16 t_u of cut, 12 t_u left uncut), 'case 1
# t_u/5 8 t_u' its first half (the same workpiece), 'case 1 t_u/10 8 t_u' that at t_u/10 (the sweep's 'case 1 pfem')
def _pfem(options: dict) -> dict:
    """The sweep's scene options that the PFEM cut takes (thermal_cutting.PFEM_OPTIONS)."""
    return {k: v for k, v in options.items() if k in tc.PFEM_OPTIONS}


CUTS = {"": ({}, True), "case 1 t_u/5": (_pfem(tc.converged(1, n_tu=5.0)), False)}
CUTS.update({f"case 1 t_u/{n:g} 8 t_u": (_pfem(tc.converged(1, n_tu=n, travel=8.0, length=tc.converged(1)["length"])),
                                         False) for n in (5.0, 10.0)})


TITLE = "# The PFEM cut's time step (quick cut: case 1, t_u/5, 4 t_u)"
MADE_BY = ("Made by `python benchmarks/pfem_time_step.py` (module text). In brackets: the change against the next "
           "smaller step, percent.")


def report(rows: list, option: str = "courant", title: str = TITLE, made_by: str = MADE_BY,
           reference: float | None = None) -> str:
    """The table, from the largest value of ``option`` down, with each quantity's change (percent) against the next
    smaller value, or against the row at ``reference`` where one is given."""
    rows = sorted(rows, key=lambda r: -r[option])
    ref = next((r["metrics"] for r in rows if r[option] == reference), None)
    head = f"| {option} | steps | halved | Newton iterations | " + " | ".join(k[0] for k in KEYS) + " |"
    lines = [title, "", made_by, "", head, "|---" * (4 + len(KEYS)) + "|"]
    for i, r in enumerate(rows):
        if reference is None:                       # against the next smaller value
            base = rows[i + 1]["metrics"] if i + 1 < len(rows) else None
        else:                                       # against the reference row (itself: no change shown)
            base = None if r[option] == reference else ref
        cells = []
        for _, key, scale, fmt in KEYS:
            v = r["metrics"][key]
            d = "" if base is None or not base[key] or v is None else f" ({100 * (v / base[key] - 1):+.1f})"
            cells.append("-" if v is None else f"{format(v * scale, fmt)}{d}")
        lines.append(f"| {r[option]:g} | {r['n_steps']} | {r['newton']['halved_steps']} | "
                     f"{r['newton']['iterations']} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def per_cut_report(rows: list, titles: dict, option: str, made_by: str, again: str, reference: float) -> str:
    """A table per cut of ``titles`` ({cut: title}) that has rows, each row's change against ``reference``; the
    first table says ``made_by``, the others ``again``."""
    parts = []
    for cut, title in titles.items():
        sel = [r for r in rows if r.get("cut", "") == cut]
        if sel:
            parts.append(report(sel, option=option, title=title, made_by=again if parts else made_by,
                                reference=reference))
    return "\n".join(parts)


def scan_main(argv, doc: str, values, option: str, runs: Path, out_json: Path, report_fn, cuts=("",)) -> int:
    """The command of a scan over one option of the cuts ``cuts`` (keys of CUTS; ``values`` the option's values, or
    {cut: values} where they differ from cut to cut): run what is missing (a committed
    row that was 'ok' is kept where its rerun is not), write the JSON and its page, print the page; --report: the
    page only."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--report", action="store_true", help="only the table from the JSON")
    args = ap.parse_args(argv)
    script = f"python benchmarks/{out_json.stem}.py"
    if not args.report:
        old = {(r.get("cut", ""), r[option]): r for r in json.loads(out_json.read_text())["rows"]} \
            if out_json.exists() else {}
        rows = []
        for cut in cuts:
            for v in (values[cut] if isinstance(values, dict) else values):
                r = run_one(v, option=option, runs=runs, cut=cut)
                keep = r["status"] != "ok" and old.get((cut, v), {}).get("status") == "ok"
                rows.append(old[(cut, v)] if keep else r)
        out_json.write_text(json.dumps(dict(rows=rows, made_by=script), indent=1) + "\n")
    if not out_json.exists():
        print(f"no {out_json.name}: run {script} first", file=sys.stderr)
        return 2
    text = report_fn(json.loads(out_json.read_text())["rows"])
    (out_json.parent / f"{out_json.stem}_report.md").write_text(text)
    print(text)
    return 0


def main(argv=None) -> int:
    return scan_main(argv, __doc__, COURANTS, "courant", RUNS, OUT_JSON, report)


if __name__ == "__main__":
    raise SystemExit(main())
