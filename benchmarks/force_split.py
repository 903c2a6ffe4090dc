"""Where the tool's force comes from in a steady cut (issue 22): the force ratio Fp/Fc that the thermomechanical
cutting scene predicts for AISI 1045 is about 0.43 where the second paper's measurements give 0.65-0.83. This script
takes a cut the sweep recorded (``benchmarks/thermal_cutting.py``; its run folder under ``runs/thermal_cutting/``),
continues it from its last checkpoint for a short window (``--travel`` t_u more of cut, 1 by default), records
every evaluation of the penalty contact (:func:`refsph.penalty.penalty_contact`) and splits the force on the tool by
where it acts and how:

* **rake face**, **edge** (the 10 um fillet) and **flank** (the clearance face): a contact belongs to the part of
  the tool's outline its normal comes from (the rake face's normal and the flank's within 1 deg; the rest is the
  fillet);
* each part's normal and tangential (friction) force, resolved into Fc (along the cut) and Fp (normal to it);
* on the rake face: the delivered friction coefficient mu_eff = sum |f_t| / sum f_N against the law's mu(T) of the
  same contacts (force-weighted), and the share of the normal force carried by contacts that slip (the return map
  capped them at mu f_N) rather than stick;
* Merchant's bound for a face of rake angle gamma whose contacts all slip at mu: Fp/Fc = tan(atan(mu) - gamma).

    python benchmarks/force_split.py                    # cases 1, 4, 11 and case 1 at t_u/5, 2-5 minutes each
    python benchmarks/force_split.py --keys "case 4"    # the sweep's key(s); writes force_split.json
    python benchmarks/force_split.py --keys "case 1" --set penalty_alpha=0.4    # a what-if: a stiffer penalty
    python benchmarks/force_split.py --keys --folders runs/pfem_cost/case_1_n_tu_10   # a PFEM run folder
    python benchmarks/force_split.py --merge /tmp/split.json   # rows made elsewhere (--json /tmp/split.json)

The window's means are printed beside the sweep's record (means over the last quarter of the cut), so that a reader
sees how representative the short window is. The continued run is written to a scratch folder (``--scratch``); the
recorded run is only read.
"""
from __future__ import annotations

import json
import math
import shutil
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402
import thermal_cutting  # noqa: E402
from pfem_rake_friction import rake_friction_bound  # noqa: E402   (Merchant's tan(atan(m) - alpha))

ROOT = Path(__file__).resolve().parents[1]
OUT_JSON = Path(__file__).resolve().parent / "force_split.json"
REPORT = Path(__file__).resolve().parent / "force_split_report.md"
SWEEP_JSON = Path(__file__).resolve().parent / "thermal_cutting.json"
PARTS = ("rake face", "edge", "flank")
PART_WIDTH = 9                                    # the numbers of one part in a row (:func:`row_of`)
DEFAULT_KEYS = ["case 1", "case 4", "case 11", "case 1 n_tu 5 courant 0.075"]   # t_u/10; the last at t_u/5


def tool_normals() -> dict:
    """The outward normals of the rake face and the flank in the scene's frame (tool moving along -x, chip rising
    along the rake face): the rake face leans back by the rake angle gamma, the flank rises by the clearance angle."""
    from refsph.scenes.thermal_cutting import CLEARANCE_DEG, RAKE_DEG
    g, c = math.radians(RAKE_DEG), math.radians(CLEARANCE_DEG)
    return {"rake face": np.array([-math.cos(g), math.sin(g)]), "flank": np.array([math.sin(c), -math.cos(c)])}


def classify(n: np.ndarray, normals: dict, tol_deg: float = 1.0) -> np.ndarray:
    """The part of the outline (index into PARTS) of contacts with outward tool normals n (M, 2)."""
    part = np.full(len(n), PARTS.index("edge"))
    for name, nn in normals.items():
        part[n @ nn > math.cos(math.radians(tol_deg))] = PARTS.index(name)
    return part


def row_of(n, f_N, f_t, mu, slip, dt: float) -> list:
    """One evaluation's row from its contacts: outward tool normals n (M, 2), the normal force f_N (M,) and the
    tangential force f_t (M, 2) on the workpiece, mu(T) (M,), which contacts slip (M,), and the step dt [s] it
    stands for (the weight of its time mean). Per part of PARTS: the normal and the friction force on the tool (x, y),
    sum f_N, sum |f_t|, sum mu f_N, the slipping contacts' f_N, the number of contacts; then dt."""
    part, row = classify(n, tool_normals()), []
    fn, ft = -f_N[:, None] * n, -f_t                                # on the tool
    for k in range(len(PARTS)):
        s = part == k
        row += [*fn[s].sum(0), *ft[s].sum(0), float(f_N[s].sum()), float(np.linalg.norm(f_t[s], axis=1).sum()),
                float((mu * f_N)[s].sum()), float(f_N[s & slip].sum()), int(s.sum())]
    return row + [float(dt)]


def row_from_penalty(c, x, T, tool, shift, contact, dt: float) -> list:
    """The row of one SPH penalty evaluation (:class:`refsph.penalty.PenaltyResult` ``c`` of particles x with
    temperatures T against ``tool`` at ``shift``): a contact slips where the return map capped its trial force
    (:func:`refsph.penalty.return_map_friction`); a step without contact gives a row of zeros."""
    on = c.gap > 0
    _, n = tool.gap(x[on], shift) if np.any(on) else (None, np.zeros((0, 2)))
    f_N = c.f_normal[on]
    mu = contact.friction.mu(T[on]) if contact.friction is not None and np.any(on) else np.zeros(len(f_N))
    slip = np.linalg.norm(c.f_trial[on], axis=1) > mu * f_N
    return row_of(n, f_N, c.f_tangent[on], mu, slip, dt)


def row_from_step_contact(c, x: np.ndarray, dt: float) -> list:
    """The row of one PFEM step's converged contact (:class:`refsph.pfem.contact.StepContact` ``c`` after its last
    call, which was at node positions x): f = f_N n + f_T t on the node, t = n turned by +90 deg; with the sets free
    (the last solve) f_T is the trial force clipped to mu f_N, so a node slips where |f_T| reached the cap."""
    last = c.last
    idx = np.flatnonzero(last["gap"] > 0)
    _, n = c.shape.gap(x[idx], c.shift) if len(idx) else (None, np.zeros((0, 2)))
    t = np.stack([-n[:, 1], n[:, 0]], axis=1)
    f_N, f_T, mu = last["f_N"][idx], last["f_T"][idx], c.mu[idx]
    return row_of(n, f_N, f_T[:, None] * t, mu, (mu > 0) & (np.abs(f_T) >= mu * f_N * (1 - 1e-9)), dt)


def scratch_copy(folder: Path, scratch: Path) -> Path:
    """The scratch folder a continuation of ``folder`` is written to (emptied first); refused where it is the
    recorded folder or lies inside it, or the other way round, so that the recorded run is only read."""
    work = scratch / folder.name
    a, b = work.resolve(), folder.resolve()
    if a == b or b in a.parents or a in b.parents:
        raise SystemExit(f"--scratch {scratch}: the continuation would overwrite the recorded run {folder}")
    if work.exists():
        shutil.rmtree(work)
    return work


def continue_run(folder: Path, travel: float, scratch: Path, numerics: dict | None = None):
    """Continue the recorded SPH run in ``folder`` (a copy in ``scratch``) by ``travel`` t_u of cut with the
    arguments it was made with (``numerics``: fields changed for a what-if, else the recorded numerics must be
    the rebuilt ones), recording every penalty evaluation: (rows, summary of the window, recorded summary)."""
    import dataclasses

    import refsph.coupling as coupling
    from refsph.simulate import build, simulate

    summary = json.loads((folder / "summary.json").read_text())
    args = summary["run_args"]
    work = scratch_copy(folder, scratch)
    shutil.copytree(folder, work)
    setup, scene, metrics = build(args["scene_name"], args["method"], dim=args["dim"], dp=args["dp"],
                                  t_end=args["t_end"], quick=args["quick"], dt=args["dt"],
                                  numerics=dict(args["numerics"] or {}, **(numerics or {})), options=args["options"],
                                  particles=args.get("particles"))
    rebuilt = dataclasses.asdict(setup.numerics)
    differ = {k: (v, rebuilt[k]) for k, v in summary["numerics"].items()
              if k in rebuilt and rebuilt[k] != v and k not in (numerics or {})}
    if differ:
        raise SystemExit(f"{folder}: the scene rebuilds other numerics than the run's (recorded, now): {differ}")
    info = setup.info
    setup.t_end = float(summary["t_final"]) + travel * info["tu_m"] / info["vc_m_s"]
    if setup.t_end * info["vc_m_s"] > 0.8 * info["length_m"]:
        raise SystemExit(f"{folder}: {travel} t_u more would cut past 80 % of the workpiece")
    rows, original = [], coupling.penalty_contact

    def recorded(x, v, m, T, tool, shift, V, dt, contact, xi):
        c = original(x, v, m, T, tool, shift, V, dt, contact, xi)
        rows.append(row_from_penalty(c, x, T, tool, shift, contact, dt))
        return c

    coupling.penalty_contact = recorded
    try:
        res = simulate(setup, args["method"], scene=scene, out=work, dt=args["dt"], progress=False, restart=True,
                       meta=dict(run_args=args), metrics=metrics)
    finally:
        coupling.penalty_contact = original
    return np.asarray(rows), res.summary, summary


def continue_pfem(folder: Path, travel: float, scratch: Path, numerics: dict | None = None):
    """:func:`continue_run` for a PFEM run folder (:mod:`refsph.pfem_run`): its CutRun restored from the last
    checkpoint and stepped ``travel`` t_u on, each step's converged contact recorded (:func:`row_from_step_contact`;
    the last :class:`refsph.pfem.contact.StepContact` a step made is the try that converged)."""
    import dataclasses

    from refsph.pfem import cutting
    from refsph.pfem_run import CHECKPOINT, PREVIOUS, _options, _restore

    if numerics:
        raise SystemExit("--set applies to SPH runs only")
    summary = json.loads((folder / "summary.json").read_text())
    work = scratch_copy(folder, scratch)
    (work / "snapshots").mkdir(parents=True)
    for name in (CHECKPOINT, PREVIOUS):
        if (folder / "snapshots" / name).exists():
            shutil.copy(folder / "snapshots" / name, work / "snapshots" / name)
    kwargs = _options(summary["run_args"]["options"], summary["run_args"]["quick"])
    cut = cutting.pfem_cut(**kwargs)
    t_more = travel * cut.info["tu_m"] / cut.info["vc_m_s"]
    run, _, _ = _restore(work / "snapshots", dataclasses.replace(cut, t_end=float(summary["t_final"]) + t_more))
    made, rows, original = [], [], cutting.StepContact

    class Recorded(original):
        def __init__(self, *a, **kw):
            super().__init__(*a, **kw)
            made.append(self)

        def __call__(self, x_new, stiffness=True):
            self.x_last = np.array(x_new)
            return super().__call__(x_new, stiffness)

    cutting.StepContact = Recorded
    try:
        while not run.done:
            run.step()
            rows.append(row_from_step_contact(made[-1], made[-1].x_last, run.reaction["dt"][-1]))
            made.clear()
    finally:
        cutting.StepContact = original
    return np.asarray(rows), dict(t_final=run.nodes.t), summary


def split(rows: np.ndarray, gamma_deg: float) -> dict:
    """The window's means of the recorded rows (:func:`continue_run`) as the force split (module text)."""
    width = PART_WIDTH
    mean = np.average(rows[:, :-1], axis=0, weights=rows[:, -1])          # time means (each row's dt)
    parts, Fx, Fy = {}, 0.0, 0.0
    for k, name in enumerate(PARTS):
        fnx, fny, ftx, fty, fN, ft, cap, fN_slip, count = mean[k * width:(k + 1) * width]
        # the force on the tool: Fc along the cut (the tool moves along -x, so +x resists it), Fp = the force
        # pushing the tool away from the workpiece (+y)
        parts[name] = dict(Fc_normal=fnx, Fc_friction=ftx, Fp_normal=fny, Fp_friction=fty, f_N=fN, f_t=ft,
                           mu_eff=ft / fN if fN > 0 else math.nan, mu_law=cap / fN if fN > 0 else math.nan,
                           slip_share=fN_slip / fN if fN > 0 else math.nan, contacts=count)
        Fx, Fy = Fx + fnx + ftx, Fy + fny + fty
    rake = parts["rake face"]
    g = math.radians(gamma_deg)
    N, mu = rake["f_N"], rake["mu_law"] if rake["f_N"] > 0 else 0.0        # the rake face slipping at mu(T)
    Fc_other = Fx - rake["Fc_normal"] - rake["Fc_friction"]
    Fp_other = Fy - rake["Fp_normal"] - rake["Fp_friction"]
    slipping = (N * (mu * math.cos(g) - math.sin(g)) + Fp_other) / (N * (math.cos(g) + mu * math.sin(g)) + Fc_other)
    return dict(Fc=Fx, Fp=Fy, force_ratio=Fy / Fx, parts=parts, ratio_rake_slipping=slipping,
                rake_only_ratio=(rake["Fp_normal"] + rake["Fp_friction"]) / (rake["Fc_normal"] + rake["Fc_friction"]),
                merchant_bound_mu_law=rake_friction_bound(rake["mu_law"], gamma_deg),
                merchant_bound_mu_eff=rake_friction_bound(rake["mu_eff"], gamma_deg))


def measure(key: str, travel: float, scratch: Path, folder: Path | None = None, numerics: dict | None = None,
            label: str | None = None) -> dict:
    """The force split of the sweep's record ``key`` (its run folder; or the run folder ``folder``, SPH or PFEM),
    continued by ``travel`` t_u (with the Numerics fields ``numerics`` changed: a what-if) and labelled ``label``
    (default ``key``); the record's forces from the folder's summary.json."""
    from refsph.scenes.thermal_cutting import RAKE_DEG
    if folder is None:
        record = json.loads(SWEEP_JSON.read_text())["runs"].get(key)
        if record is None or record.get("status") != "ok":
            raise SystemExit(f"{key!r}: no recorded run in {SWEEP_JSON.name} (run benchmarks/thermal_cutting.py)")
        folder = thermal_cutting.run_folder(key)
    if not (folder / "snapshots" / "restart.npz").exists():
        raise SystemExit(f"{key!r}: its run folder {folder} has no checkpoint to continue from")
    method = json.loads((folder / "summary.json").read_text())["method"]
    rows, window, recorded = (continue_pfem if method == "pfem" else continue_run)(folder, travel, scratch, numerics)
    if recorded["status"] != "ok" or len(rows) == 0:
        raise SystemExit(f"{key!r}: the run in {folder} did not end 'ok', or no contact in the window")
    out = split(rows, RAKE_DEG)
    m, info = recorded["metrics"], recorded["scene_info"]
    row = info["measured"]
    return dict(key=label or key, method=method, numerics_changed=dict(numerics or {}), material=row["material"],
                case=info["case"], dx_m=info["dx"], tu_m=info["tu_m"],
                measured_force_ratio=row["Fp_exp_N"] / row["Fc_exp_N"], travel_t_u=travel, evaluations=len(rows),
                t_start_s=recorded["t_final"], t_end_s=window["t_final"],
                recorded_Fc_N_per_m=m["cutting_force_N_per_m"], recorded_Fp_N_per_m=m["passive_force_N_per_m"], **out)


def share(r: dict, name: str, k: str) -> float:
    """The share of the window's force ``k`` ('Fc' or 'Fp') that part ``name`` of the tool carries (normal and
    friction force together)."""
    p = r["parts"][name]
    return (p[f"{k}_normal"] + p[f"{k}_friction"]) / r[k]


def spacing(r: dict, runs: dict) -> tuple:
    """(case, dx [m]) of row ``r``: recorded in the row, or, for a row made before they were (labelled by its sweep
    key or that key's run folder, a what-if by the key before its comma), the sweep record's; (None, None) where
    neither says."""
    if "dx_m" in r:
        return r["case"], r["dx_m"]
    label = r["key"].split(",")[0]
    for key, record in runs.items():
        if label in (key, thermal_cutting.run_folder(key).name) and record.get("status") == "ok":
            return record["scene_info"]["case"], record["scene_info"]["dx"]
    return None, None


HEAD = ("case", "material", "dx [um]", "Fc [N/mm] window (record)", "Fp/Fc window (record)", "Fp/Fc measured",
        "rake face: share of Fc, Fp", "edge", "flank",
        "rake face mu_eff / mu(T)", "slipping share of rake f_N", "Fp/Fc of the rake face alone",
        "Merchant bound at mu(T)", "Fp/Fc with the rake face slipping at mu(T)")


def table(results: list, runs: dict | None = None) -> str:
    """The markdown table of the results (``runs``: the sweep's records, for the spacing of older rows)."""
    rows = []
    for r in results:
        dx = spacing(r, runs or {})[1]
        rake = r["parts"]["rake face"]

        def shares(name):
            return f"{share(r, name, 'Fc'):.2f}, {share(r, name, 'Fp'):.2f}"
        label = r["key"] + (" (PFEM)" if r.get("method") == "pfem" else "")
        rows.append([label, r["material"], "-" if dx is None else f"{dx * 1e6:.1f}",
                     f"{r['Fc'] / 1e3:.0f} ({r['recorded_Fc_N_per_m'] / 1e3:.0f})",
                     f"{r['force_ratio']:.2f} ({r['recorded_Fp_N_per_m'] / r['recorded_Fc_N_per_m']:.2f})",
                     f"{r['measured_force_ratio']:.2f}",
                     shares("rake face"), shares("edge"), shares("flank"),
                     f"{rake['mu_eff']:.2f} / {rake['mu_law']:.2f}",
                     f"{rake['slip_share']:.2f}", f"{r['rake_only_ratio']:.2f}", f"{r['merchant_bound_mu_law']:.2f}",
                     f"{r['ratio_rake_slipping']:.2f}"])
    return study.md_table(HEAD, rows)


def report(doc: dict) -> str:
    """benchmarks/force_split_report.md from the JSON document (the template's prose filled with its numbers)."""
    from refsph.scenes.thermal_cutting import RAKE_DEG
    results = doc["results"]
    page = study.Page("force_split_report")

    def span(values, spec=".2f", scale=1.0):
        lo, hi = format(min(values) * scale, spec), format(max(values) * scale, spec)
        return (lo, "") if lo == hi else (lo, "-" + hi)

    def group(r):                                          # the paragraphs: per material and method
        return r["material"] + (", PFEM" if r.get("method") == "pfem" else "")
    v = {}
    for name, values in (("rake_fc", [share(r, "rake face", "Fc") for r in results]),
                         ("rake_fp", [share(r, "rake face", "Fp") for r in results])):
        v[f"{name}_min"], v[f"{name}_max"] = span(values)
    v["flank_fp_max"] = f'{max(share(r, "flank", "Fp") for r in results):.2f}'
    fc_dev = max(abs(r["Fc"] / r["recorded_Fc_N_per_m"] - 1) for r in results)
    ratio_dev = max(abs(r["force_ratio"] - r["recorded_Fp_N_per_m"] / r["recorded_Fc_N_per_m"]) for r in results)
    travel = sorted({r["travel_t_u"] for r in results})
    runs = json.loads(SWEEP_JSON.read_text())["runs"] if SWEEP_JSON.exists() else {}
    parts = [page("head", travel="/".join(f"{t:g}" for t in travel), rake_deg=f"{RAKE_DEG:g}"), table(results, runs),
             page("how_to_read", fc_window_dev=f"{100 * fc_dev:.0f}", ratio_window_dev=f"{ratio_dev:.2f}", **v)]
    for material in sorted({group(r) for r in results}):
        rs = [r for r in results if group(r) == material and not r.get("numerics_changed")]
        rake, m = [r["parts"]["rake face"] for r in rs], {}
        for name, values, spec, scale in (
                ("stick", [1.0 - p["slip_share"] for p in rake], ".0f", 100.0),
                ("mueff", [p["mu_eff"] for p in rake], ".2f", 1.0), ("mulaw", [p["mu_law"] for p in rake], ".2f", 1.0),
                ("bound", [r["merchant_bound_mu_law"] for r in rs], ".2f", 1.0),
                ("measured", [r["measured_force_ratio"] for r in rs], ".2f", 1.0)):
            m[f"{name}_min"], m[f"{name}_max"] = span(values, spec, scale)
        parts.append(page("material", material=material, rows=", ".join(r["key"] for r in rs), **m))
    above = [r["key"] for r in results if r["merchant_bound_mu_law"] >= r["measured_force_ratio"]]
    slipping = []
    for material in sorted({group(r) for r in results}):
        rs = [r for r in results if group(r) == material and not r.get("numerics_changed")]
        lo, hi = span([r["ratio_rake_slipping"] for r in rs])
        mlo, mhi = span([r["measured_force_ratio"] for r in rs])
        elo, ehi = span([100 * (1 - r["ratio_rake_slipping"] / r["measured_force_ratio"]) for r in rs], ".0f")
        slipping.append(f"{material} {lo}{hi} against the measured {mlo}{mhi} ({elo}{ehi} % low)")
    parts.append(page("conclusion", bound_vs_measured="below the measured ratio in every row" if not above else
                      f"at or above the measured ratio in {', '.join(above)}", slipping="; ".join(slipping)))
    parts += [whatif(page, r, base) for r in results if r.get("numerics_changed")
              for base in results if base["key"] == r["key"].split(",")[0]]
    pairs = spacing_pairs(results, runs)
    if pairs:
        parts.append(page("spacing", pairs="; ".join(pairs)))
    return "\n\n".join(parts) + "\n"


def spacing_pairs(results: list, runs: dict) -> list:
    """One phrase per case and method split at more than one spacing (rows with the sweep's numerics), coarsest
    to finest (of rows at the same spacing the first in ``results``): the edge's share of Fc and Fp, the rake
    face's slipping share and mu_eff / mu(T), the window's Fp/Fc and Merchant's bound at mu(T)."""
    groups = {}
    for r in results:
        case, dx = spacing(r, runs)
        if dx is None or r.get("numerics_changed"):
            continue
        rows = groups.setdefault((case, r.get("method", "tlsph")), [])
        if all(dx != d for d, _ in rows):                  # one row per spacing: the first in the file
            rows.append((dx, r))
    out = []
    for (case, method), pairs in sorted(groups.items()):
        if len({dx for dx, _ in pairs}) < 2:
            continue
        pairs.sort(key=lambda t: -t[0])
        rows, rake = [r for _, r in pairs], [r["parts"]["rake face"] for _, r in pairs]

        def chain(values, spec=".2f") -> str:
            return " -> ".join(v if isinstance(v, str) else format(v, spec) for v in values)
        keys = chain([repr(r["key"]) for r in rows])
        edge_fc, edge_fp = (chain([share(r, "edge", k) for r in rows]) for k in ("Fc", "Fp"))
        mus = chain([f"{x['mu_eff']:.2f} / {x['mu_law']:.2f}" for x in rake])
        out.append(f"case {case} ({'PFEM' if method == 'pfem' else 'SPH'}; {keys}), "
                   f"{chain([1e6 * dx for dx, _ in pairs], '.1f')} um: the edge's share of Fc {edge_fc} and of Fp "
                   f"{edge_fp}, the rake face's slipping share {chain([x['slip_share'] for x in rake])} and mu_eff / "
                   f"mu(T) {mus}, Fp/Fc {chain([r['force_ratio'] for r in rows])} (Merchant's bound at mu(T) "
                   f"{chain([r['merchant_bound_mu_law'] for r in rows])})")
    return out


def whatif(page, r: dict, base: dict) -> str:
    """The what-if paragraph of the report: row ``r`` (a continuation with changed numerics) against ``base``."""
    def rake(x, k):
        return x["parts"]["rake face"][k]
    return page("whatif", label=r["key"], change=", ".join(f"{k} = {v}" for k, v in r["numerics_changed"].items()),
                stick_base=f"{100 * (1 - rake(base, 'slip_share')):.0f}",
                stick_whatif=f"{100 * (1 - rake(r, 'slip_share')):.0f}", mueff_base=f"{rake(base, 'mu_eff'):.2f}",
                mueff_whatif=f"{rake(r, 'mu_eff'):.2f}", ratio_base=f"{base['force_ratio']:.2f}",
                ratio_whatif=f"{r['force_ratio']:.2f}", fc_base=f"{base['Fc'] / 1e3:.0f}",
                fc_whatif=f"{r['Fc'] / 1e3:.0f}")


def _read_json(path: Path, ap, flag: str = "--json") -> dict:
    """The JSON document at ``path`` (given as ``flag``); a clear error (not a traceback) where it is not JSON."""
    try:
        doc = json.loads(path.read_text())
    except (OSError, ValueError) as e:
        ap.error(f"{flag} {path}: cannot be read as JSON ({e})")
    return doc if isinstance(doc, dict) else {}


def _merged_rows(path: Path, ap) -> list:
    """The rows of the force-split JSON ``path`` given to --merge, each with its key, one per key (the last)."""
    if not path.exists():
        ap.error(f"--merge {path}: does not exist")
    rows = _read_json(path, ap, "--merge").get("results")
    if not isinstance(rows, list) or not all(isinstance(r, dict) and isinstance(r.get("key"), str) for r in rows):
        ap.error(f"--merge {path}: not a force-split file (a 'results' list of rows, each with its 'key')")
    return list({r["key"]: r for r in rows}.values())


def main(argv=None) -> int:
    from refsph.cli import _parse_numerics

    ap = study.parser(__doc__)
    ap.add_argument("--keys", nargs="*", default=DEFAULT_KEYS, help="the sweep's keys (default: "
                                                                              + ", ".join(DEFAULT_KEYS) + ")")
    ap.add_argument("--folders", nargs="+", type=Path, default=[], help="run folders (SPH or PFEM) to split as "
                                                                         "well, each labelled by its name")
    ap.add_argument("--travel", type=float, default=1.0, help="t_u of cut in the window (default 1)")
    ap.add_argument("--set", nargs="+", default=[], metavar="NAME=VALUE", help="a what-if: Numerics fields changed "
                    "in the continuation (SPH), e.g. penalty_alpha=0.4; the rows are labelled with them")
    ap.add_argument("--scratch", type=Path, default=None, help="where the continued runs go (default: a temporary "
                                                               "folder, removed)")
    ap.add_argument("--json", type=Path, default=OUT_JSON, help="where to write the results (default: "
                                                                "force_split.json)")
    ap.add_argument("--report", action="store_true", help="no runs: the report page from the JSON")
    ap.add_argument("--merge", type=Path, default=None, metavar="JSON",
                    help="no runs: take the rows of another force-split JSON (a run with --json elsewhere) into "
                         "--json, replacing rows of the same key, then the page")
    a = ap.parse_args(argv)
    if a.json.exists() and not isinstance(_read_json(a.json, ap).get("results"), list):
        ap.error(f"--json {a.json}: not a force-split file (no 'results' list); refusing to read or overwrite it")
    if a.merge is not None:
        if a.folders or a.set or a.report or a.keys != DEFAULT_KEYS:
            ap.error("--merge runs nothing: give it without --keys, --folders, --set and --report")
        _write(a.json, _read_json(a.json, ap)["results"] if a.json.exists() else [], _merged_rows(a.merge, ap))
        return 0
    if a.report:                                           # the committed page only from the committed JSON
        if not a.json.exists():
            ap.error(f"--report: {a.json} does not exist (run the script first)")
        page = report(_read_json(a.json, ap))
        if a.json.resolve() == OUT_JSON:
            study.write_if_changed(REPORT, page)
        print(page)
        return 0
    if not (a.travel > 0):
        ap.error(f"--travel must be > 0, got {a.travel}")
    try:
        changed = _parse_numerics(a.set)                   # refsph run's --set: typed, unknown names refused
    except ValueError as e:
        ap.error(str(e))
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        scratch = a.scratch or Path(tmp)
        suffix = "".join(f", {k} {v}" for k, v in changed.items())
        jobs = [(key, None) for key in a.keys] + [(f.name, f) for f in a.folders]
        for key, folder in jobs:
            results.append(measure(key, a.travel, scratch, folder, changed, key + suffix))
            print(table(results[-1:]), flush=True)
    _write(a.json, _read_json(a.json, ap)["results"] if a.json.exists() else [], results)
    return 0


def _write(path: Path, old: list, results: list) -> None:
    """``results`` into the JSON at ``path`` (rows of the same key replaced), the page if it is the committed one."""
    keep = [r for r in old if r["key"] not in {r["key"] for r in results}]
    doc = dict(results=keep + results)
    page = report(doc) if path.resolve() == OUT_JSON else None   # made before anything is written: a row the
    study.write_json(path, doc)                                   # page cannot take leaves both files as they were
    if page is not None:
        study.write_if_changed(REPORT, page)
    print(table(keep + results))


if __name__ == "__main__":
    sys.exit(main())
