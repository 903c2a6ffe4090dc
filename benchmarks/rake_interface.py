"""The rake face seen from both sides: the chip's contact layer against the tool's face layer, in the snapshots of
the last quarter of thermal-cutting SPH runs.

    python benchmarks/rake_interface.py --run DIR [DIR ..]      # run folders of benchmarks/thermal_cutting.py

Issue 22 asks which temperature the measured T_RF is. The scene's T_RF is the mean temperature of the *workpiece*
particles within one spacing of the rake face, from the edge to the end of contact (fixed before the sweep). A
"rake face" is a surface of the tool; the measurements' source introduces a way to measure its temperature "without
manipulating the chip flow" (Afrasiabi et al., Metals 11 (2021) 1683, abstract), which the paper does not describe,
so either side of the face may be what was measured. In the SPH the two bodies meet across one spacing, the
chip's contact layer dx/2 in front of the face and the tool's first row about dx/2 behind it, and the pair
conduction between them (harmonic-mean k, :mod:`refsph.thermal`) carries a temperature step that shrinks with dx.
This script measures that step:

    chip layer  mean T of the workpiece rows with |n| < dx, 0 <= u       (the scene's T_RF, one snapshot)
    tool layer  mean T of the tool rows with -dx < n <= 0, 0 <= u <= L  (L the contact length of the snapshot)
    step        chip layer - tool layer

(u along the rake face from the edge, n in front of it: :func:`refsph.scenes.thermal_cutting.rake_frame`), each
the mean over the snapshots at t >= 3/4 of the cut (the scene's steady window). Run folders are git-ignored and
the sweep removes none, but a fresh clone has none: so the numbers are kept in rake_interface.json, one entry per
run folder's name, updated only for the folders given, and the page rake_interface_report.md is written from it.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
OUT_JSON, OUT_MD = HERE / "rake_interface.json", HERE / "rake_interface_report.md"


def layers(x: np.ndarray, T: np.ndarray, t: float, info: dict) -> dict | None:
    """The chip's contact layer and the tool's face layer of one SPH snapshot (module text): their mean
    temperatures [K] and counts, the next tool row's (-2 dx < n <= -dx) and the contact length [m]; None where no
    workpiece particle touches the face. Rows [0, n_work) are the workpiece, the rest the tool."""
    from refsph.scenes.thermal_cutting import rake_frame
    n_work, dx = info["n_work"], info["dx"]
    u, n = rake_frame(x, t, info)
    work = np.arange(len(x)) < n_work
    touch = work & (np.abs(n) < dx) & (u >= 0.0)
    if not touch.any():
        return None
    L = float(u[touch].max())
    face = ~work & (u >= 0.0) & (u <= L)
    tool, behind = face & (n > -dx) & (n <= 0.0), face & (n > -2 * dx) & (n <= -dx)

    def mean(sel):
        return float(T[sel].mean()) if sel.any() else float("nan")

    return dict(t_s=float(t), contact_m=L, chip_K=mean(touch), tool_K=mean(tool), tool_next_K=mean(behind),
                n_chip=int(touch.sum()), n_tool=int(tool.sum()))


def interface(run_dir: Path) -> dict:
    """The layers of every snapshot of the run's steady window and their means (module text); ValueError naming
    the folder for a PFEM run, or a summary without the scene's info or its snapshots."""
    from refsph.io import load_snapshot, read_json
    from refsph.scenes.thermal_cutting import STEADY_FROM
    s = read_json(run_dir / "summary.json", "run summary")
    if s.get("method") == "pfem":
        raise ValueError(f"{run_dir}: a PFEM run (its tool's temperatures are not in the snapshots); SPH runs only")
    if not all(k in s for k in ("scene_info", "t_end", "snapshots")):
        raise ValueError(f"{run_dir}: its summary.json lacks scene_info, t_end or snapshots: not a thermal-cutting run")
    info, t_end = s["scene_info"], float(s["t_end"])
    snaps = [load_snapshot(run_dir / "snapshots" / name) for name in s["snapshots"]]
    rows = [r for z in snaps if float(z["t"]) >= STEADY_FROM * t_end - 1e-12
            for r in [layers(np.asarray(z["x"]), np.asarray(z["T"]), float(z["t"]), info)] if r is not None]
    if not rows:
        raise ValueError(f"{run_dir}: no snapshot of the last quarter with a chip on the rake face")
    means = {k: float(np.mean([r[k] for r in rows])) for k in ("chip_K", "tool_K", "tool_next_K")}
    m = s.get("metrics") or {}
    return dict(case=int(info["case"]), material=info["material"], dx_um=1e6 * info["dx"],
                across=info["tu_m"] / info["dx"], status=s.get("status"), snapshots=rows, **means,
                step_K=means["chip_K"] - means["tool_K"], T_RF_K=m.get("rake_face_temperature_K"),
                T_RF_measured_K=(info.get("measured") or {}).get("TRF_exp_K"))


def _f(v, spec: str = ".0f") -> str:
    return "-" if v is None else format(v, spec)


def page(runs: dict) -> str:
    """rake_interface_report.md from the kept numbers."""
    lines = ["# The rake face from both sides (`benchmarks/rake_interface.py`)", "",
             "Made by `python benchmarks/rake_interface.py --run DIR ..` from the run folders of "
             "`benchmarks/thermal_cutting.py` (the key is the folder's name); see the script's text for the "
             "definitions. Means over the snapshots of the last quarter of the cut.", "",
             "| run | material | across t_u | snapshots | chip layer [K] | tool face layer [K] | next tool row [K] | "
             "step [K] | step [% of T_RF] | T_RF (run) [K] | T_RF measured [K] |", "|---" * 11 + "|"]
    for key in sorted(runs, key=lambda k: (runs[k]["case"], runs[k]["across"], k)):
        r = runs[key]
        lines.append(f"| {key} | {r['material']} | {r['across']:.0f} | {len(r['snapshots'])} | {_f(r['chip_K'])} | "
                     f"{_f(r['tool_K'])} | {_f(r['tool_next_K'])} | {_f(r['step_K'])} | "
                     f"{_f(100.0 * r['step_K'] / r['T_RF_K'] if r['T_RF_K'] else None, '.1f')} | {_f(r['T_RF_K'])} | "
                     f"{_f(r['T_RF_measured_K'])} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--run", nargs="*", type=Path, default=[], help="SPH run folders of the thermal-cutting sweep")
    args = ap.parse_args(argv)
    kept = json.loads(OUT_JSON.read_text())["runs"] if OUT_JSON.exists() else {}
    missing = [str(d) for d in args.run if not (Path(d) / "summary.json").exists()]
    if missing:
        print(f"no run folder at {', '.join(missing)}: run benchmarks/thermal_cutting.py first", file=sys.stderr)
        return 2
    failed = 0
    for d in (Path(d).resolve() for d in args.run):
        try:
            r = interface(d)
        except ValueError as e:                  # an unfinished or a PFEM run: said, and the others still kept
            print(e, file=sys.stderr)
            failed += 1
            continue
        kept[d.name] = r
        print(f"{d.name}: chip layer {r['chip_K']:.0f} K, tool face layer {r['tool_K']:.0f} K, "
              f"step {r['step_K']:.0f} K over {len(r['snapshots'])} snapshots")
    OUT_JSON.write_text(json.dumps(dict(runs=kept, made_by="python benchmarks/rake_interface.py --run ..."),
                                   indent=1) + "\n")
    OUT_MD.write_text(page(kept))
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
