"""How large the artificial viscosity's stress is against the flow stress, and its power against the plastic power,
over the last quarter of thermal-cutting runs (issue 22, part 3: the mass-scaling rule chosen from the numerical
stress it adds, stated).

    python benchmarks/viscous_stress.py                      # every finished SPH run folder of the sweep
    python benchmarks/viscous_stress.py --run DIR [DIR ..]   # these

TLSPH's artificial viscosity (Eq. (17) with Eqs. (12)-(13), :func:`refsph.tlsph.reference_viscosity`) adds to a
particle's acceleration -sum_j m_j pi_ij (B_i + B_j)/2 grad_0 W_ij, where the stress adds
sum_j m_j (P_i / rho0_i^2 + P_j / rho0_j^2) grad_0 W_ij; a pressure q on both particles (P = -q B) gives the same
term with pi_ij = 2 q / rho0^2. So a pair's viscous pressure is

    q_ij = rho0^2 pi_ij / 2 = (rho0^2 / rho_bar) (beta1 c |mu_ij| + beta2 mu_ij^2) / 2,
    mu_ij = h v_ij . x_ij / (|x_ij|^2 + eps h^2)   (approaching pairs, v_ij . x_ij < 0; else q_ij = 0)

with c = sqrt(E / (s rho)) the (mass-scaled) sound speed of the viscosity. Each workpiece particle's viscous stress is
the kernel-weighted mean over its reference pairs (those of the operator: |X_ij| <= 2h in the snapshot's reference
configuration X), q_i = sum_j V_j q_ij W_ij / sum_j V_j W_ij, set against its von Mises stress (the flow stress
where it flows), over the shear zones (the particles whose plastic strain rate is at least a quarter of the 99th
percentile of the flowing particles'): its median and 90th percentile. Beside it the power the viscosity dissipates
(:func:`~refsph.tlsph.reference_viscosity` on the snapshot's state, as the run computes it but with the velocities
of the snapshot, not of the half step) against the plastic power sum_i V_i sigma_vm,i eps_dot_p,i, and where it is
dissipated: in the layer on the tool (within 1.5 dx of the rake face, from 2 dx below the edge), in the shear
zones, under the cut line ahead of the edge (where the material is pressed down before it is cut) and behind it
(the machined layer), elsewhere (the chip's body); and the viscosity's and the contact damping's share of the tool's
work over the whole run, from its heat ledger. The powers are summed over the snapshots of the last quarter of the
run (the window of the cut's means; each snapshot's ratio is listed too), the stress ratios are the last
snapshot's. How these move with s (c ~ 1/sqrt(s)) is what the mass-scaling rule
trades against the cost. Needs the sweep's run folders (``benchmarks/thermal_cutting.py``, git-ignored); writes
viscous_stress.json next to this file (merged with the runs already recorded there).
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

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "runs" / "thermal_cutting"
OUT_JSON = Path(__file__).resolve().parent / "viscous_stress.json"


def viscous_pressure(X, x, v, rho, V0, m, h, kernel, beta1, beta2, eps, c, pairs=None) -> np.ndarray:
    """q_i (module text) [Pa] of each row from its reference pairs (|X_ij| <= support h; ``pairs``: those half
    pairs (I, J) if the caller has them, e.g. a ReferenceOperator's)."""
    from refsph.neighbours import PairSum, find_pairs
    n, d = x.shape
    I, J = find_pairs(X, kernel.support * h) if pairs is None else pairs
    xij, vij = x[I] - x[J], v[I] - v[J]
    vr = np.einsum("pd,pd->p", vij, xij)
    mu = h * np.minimum(vr, 0.0) / (np.einsum("pd,pd->p", xij, xij) + eps * h * h)
    rho0 = m / V0
    rho0_bar, rho_bar = 0.5 * (rho0[I] + rho0[J]), 0.5 * (rho[I] + rho[J])
    q = rho0_bar**2 / rho_bar * (beta1 * c * np.abs(mu) + beta2 * mu * mu) / 2.0
    W = kernel.w(np.sqrt(np.einsum("pd,pd->p", X[I] - X[J], X[I] - X[J])), h, d)
    sums = PairSum(I, J, n)
    weight = sums.symmetric(W, V0) + V0 * kernel.w(np.zeros(1), h, d)[0]       # the particle itself: q_ii = 0
    return sums.symmetric(q * W, V0) / weight


REGIONS = ("at_tool", "shear_zones", "ahead_below_cut", "machined", "elsewhere")


def snapshot_powers(s: dict, z: dict) -> dict:
    """One snapshot ``z`` of the run with summary ``s``: the viscous pressure's ratio to the von Mises stress over
    the shear zones, the viscosity's power (total and by region, REGIONS) and the plastic power [W/m]."""
    from refsph.kernels import get_kernel
    from refsph.scenes.thermal_cutting import rake_frame
    from refsph.tensor import det, inv, transpose
    from refsph.tlsph import ReferenceOperator, TLSPHParams, reference_viscosity
    info, num, mat = s["scene_info"], s["numerics"], s["material"]
    w = slice(0, info["n_work"])
    X, x, v, m, V0, rho = (np.asarray(z[k][w], dtype=float) for k in ("X", "x", "v", "m", "V0", "rho"))
    kernel, h = get_kernel(num["kernel"]), float(s["h"])
    c = float(np.sqrt(mat["E"] / mat["rho0"]))                      # material.c0 of the (mass-scaled) material
    # the viscosity's power per particle, as the run computes it (Rates.heat_power), on the snapshot's operator
    prm = TLSPHParams(h=h, beta1=num["beta1"], beta2=num["beta2"], eps=num["eps"], kernel=kernel,
                      corrected=num["corrected"], ref_update_strain=None, viscous_heat=True,
                      max_condition=num.get("max_condition"))
    op = ReferenceOperator(X, V0, h, kernel, num["corrected"], max_condition=num.get("max_condition"))
    q = viscous_pressure(X, x, v, rho, V0, m, h, kernel, num["beta1"], num["beta2"], num["eps"], c, (op.I, op.J))
    F = op.deformation_gradient(x)
    J = det(F)
    _, power = reference_viscosity(x, v, m, m / (V0 * J), J[:, None, None] * transpose(inv(F, J)), op, c, prm)
    svm, rate = np.asarray(z["sigma_vm"][w], dtype=float), np.asarray(z["eps_dot_p"][w], dtype=float)
    t, dx = float(z["t"]), float(info["dx"])
    u, n = rake_frame(x, t, info)
    at_tool = (np.abs(n) < 1.5 * dx) & (u > -2.0 * dx)              # the layer on the rake face and round the edge
    below = x[:, 1] < info["y0"]                                    # under the cut line:
    behind = x[:, 0] > info["apex0"][0] - info["vc_m_s"] * t        # the tool moves to -x: machined
    flowing = rate > 0.0
    zone = flowing & (rate >= 0.25 * np.quantile(rate[flowing], 0.99)) if flowing.any() else flowing
    ratio = q[zone] / np.maximum(svm[zone], 1e-9 * mat["E"])
    regions = dict(at_tool=at_tool, shear_zones=zone & ~at_tool, ahead_below_cut=below & ~behind & ~zone & ~at_tool,
                   machined=below & behind & ~zone & ~at_tool, elsewhere=~below & ~zone & ~at_tool)
    return dict(t_s=t, c_m_s=c, n_zone=int(zone.sum()),
                ratio_median=float(np.median(ratio)) if zone.any() else None,
                ratio_p90=float(np.quantile(ratio, 0.9)) if zone.any() else None,
                q_median_MPa=float(np.median(q[zone]) / 1e6) if zone.any() else None,
                viscous_W=float(power.sum()), plastic_W=float(np.sum(m / rho * svm * rate)),   # sigma_vm eps_dot_p
                viscous_by_region_W={k: float(power[sel].sum()) for k, sel in regions.items()})


def measure(run_dir: Path) -> dict:
    """The viscous stress and power (module text) over the snapshots of the last quarter of the run (the window
    of the cut's means): the ratios of the summed powers, the shear-zone stress ratios of the last snapshot."""
    from refsph.io import load_snapshot
    s = json.loads((run_dir / "summary.json").read_text())
    if s.get("method") != "tlsph":
        raise ValueError(f"{run_dir}: a TLSPH run folder is needed (method {s.get('method')!r})")
    if not s.get("snapshots"):
        raise ValueError(f"{run_dir}: the run wrote no snapshot")
    snaps = [load_snapshot(run_dir / "snapshots" / name) for name in s["snapshots"]]
    t_end = float(snaps[-1]["t"])
    parts = [snapshot_powers(s, z) for z in snaps if float(z["t"]) >= 0.75 * t_end]
    last, info = parts[-1], s["scene_info"]
    visc, plastic = sum(p["viscous_W"] for p in parts), sum(p["plastic_W"] for p in parts)
    hb, work = s.get("heat_balance") or {}, (s.get("metrics") or {}).get("tool_work_J_per_m")
    return dict(run=run_dir.name, t_s=[p["t_s"] for p in parts], mass_scale=float(info["mass_scale"]),
                dx_m=float(info["dx"]), c_m_s=last["c_m_s"],
                shear_zones=dict(n=last["n_zone"], median=last["ratio_median"], p90=last["ratio_p90"],
                                 q_median_MPa=last["q_median_MPa"]),
                viscous_over_plastic_power=visc / plastic if plastic > 0 else None,
                viscous_over_plastic_each=[p["viscous_W"] / p["plastic_W"] if p["plastic_W"] > 0 else None
                                           for p in parts],
                viscous_power_share={k: sum(p["viscous_by_region_W"][k] for p in parts) / visc if visc > 0 else None
                                     for k in REGIONS},
                dissipation_of_work=(hb["dissipation_J"] / work if work and "dissipation_J" in hb else None))


def report(rows: list) -> str:
    head = ("run", "s", "dx [um]", "c [m/s]", "shear zones: q / sigma_vm median", "p90", "q median [MPa]",
            "viscous / plastic power (each snapshot)", "viscous power at the tool [%]", "in the shear zones [%]",
            "ahead of the edge, under the cut line [%]", "machined layer [%]", "elsewhere [%]",
            "viscosity + damping heat, whole run [% of work]")
    body = []
    for r in rows:
        sh, z = r["viscous_power_share"], r["shear_zones"]
        shares = [study.fmt(sh[k], ".0f", 100.0) for k in REGIONS]
        body.append((r["run"], f"{r['mass_scale']:.0f}", f"{1e6 * r['dx_m']:.0f}", f"{r['c_m_s']:.0f}",
                     study.fmt(z["median"], ".3f"), study.fmt(z["p90"], ".3f"), study.fmt(z["q_median_MPa"], ".1f"),
                     study.fmt(r["viscous_over_plastic_power"], ".3f") + " (" + ", ".join(
                         study.fmt(e, ".2f") for e in r["viscous_over_plastic_each"]) + ")", *shares,
                     study.fmt(r["dissipation_of_work"], ".1f", 100.0)))
    return study.md_table(head, body)


def _method(run_dir: Path) -> str | None:
    """The method in a run folder's summary.json (None if it cannot be read)."""
    try:
        return json.loads((run_dir / "summary.json").read_text()).get("method")
    except (OSError, ValueError):
        return None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--run", nargs="*", type=Path, default=None, help="run folders (default: the sweep's finished "
                    "SPH runs)")
    args = ap.parse_args(argv)
    if args.run:
        runs = [Path(d).resolve() for d in args.run]
        missing = [str(d) for d in runs if not (d / "summary.json").is_file()]
        if missing:
            print(f"not a run folder (no summary.json): {', '.join(missing)}", file=sys.stderr)
            return 2
    else:
        runs = sorted(d for d in RUNS.glob("*") if study.run_status(d) == "ok" and _method(d) == "tlsph")
        if not runs:
            print(f"no finished SPH run folder under {RUNS}: run benchmarks/thermal_cutting.py first",
                  file=sys.stderr)
            return 2
    try:
        fresh = [measure(d) for d in runs]
    except (ValueError, KeyError, IndexError, OSError) as e:
        print(f"cannot measure: {e}", file=sys.stderr)
        return 2
    old = json.loads(OUT_JSON.read_text())["runs"] if OUT_JSON.is_file() else []
    rows = study.merge_records(old, fresh, key="run")
    study.write_json(OUT_JSON, dict(runs=rows, made_by="python benchmarks/viscous_stress.py"))
    print(report(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
