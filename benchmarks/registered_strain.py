"""How much of the particles' own deformation TLSPH's plastic update registers, against how often its reference
configuration is updated (issue 22; benchmarks/chip_strain.py found the chip carrying about half the plastic strain
its thickness implies at the scene's ref_update_strain 0.5).

Case 1 of the thermomechanical cutting scene at its defaults (dx = t_u/5, 8 t_u of cut, 2-3 minutes a run) is run
with a hook (``refsph.simulate.simulate(hook=...)``) that every K = 10 steps measures each workpiece particle's
strain increment from its neighbours' relative motion, whatever the solver's F says:

    F_inc,i = (sum_j w_ij dy_ij (x) dX_ij) (sum_j w_ij dX_ij (x) dX_ij)^-1     (kernel-weighted affine fit)
    d_eps_i = sqrt(2/3 e : e),  e = dev(sym(F_inc,i) - I)                        (plane strain: e_zz = 0 before dev)

with dX_ij the pair's separation K steps ago, dy_ij now, over the pairs within the kernel's support then and
w_ij = W(|dX_ij|, h) (the Wendland kernel of the scene). Summed along each particle's path this is the kinematic
equivalent strain eps_kin (a small-increment path integral: for simple shear by gamma it gives gamma/sqrt(3), the
von Mises measure of eps_p). The chip's body (benchmarks/chip_strain.py's zones) then gives the mean eps_p
(registered by the return map, Eqs. (29)-(30)) beside the mean eps_kin, and Merchant's strain of the chip thickness
the run measured.

    python benchmarks/registered_strain.py                 # every reference update of REF_UPDATES not yet recorded
    python benchmarks/registered_strain.py --redo 0.5      # one again

Writes benchmarks/registered_strain.json and benchmarks/registered_strain_report.md (a run folder per value under
--scratch, default a temporary folder).
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

OUT_JSON = Path(__file__).resolve().parent / "registered_strain.json"
OUT_MD = Path(__file__).resolve().parent / "registered_strain_report.md"
REF_UPDATES = (0.5, 0.1, 0.02)  # TLSPH's ref_update_strain: the scene's, the 'refupdate' study's choice, and less
EVERY = 10                      # steps between two affine fits


def strain_increment(xa: np.ndarray, xb: np.ndarray, h: float, kernel) -> np.ndarray:
    """The kinematic equivalent strain increment of each particle from positions ``xa`` to ``xb`` (N, 2): the
    kernel-weighted affine fit of its neighbours' relative motion (module text,
    :func:`chip_strain.affine_maps`); 0 where the fit is singular."""
    import chip_strain as cs
    F = cs.affine_maps(xa, xb, kernel.support * h, lambda r: kernel.w(r, h, 2))
    E = 0.5 * (F + np.swapaxes(F, 1, 2)) - np.eye(2)
    mean = (E[:, 0, 0] + E[:, 1, 1]) / 3.0
    dev = np.stack([E[:, 0, 0] - mean, E[:, 1, 1] - mean, -mean], axis=1)
    return np.sqrt(2.0 / 3.0 * ((dev**2).sum(axis=1) + 2.0 * E[:, 0, 1] ** 2))


def measure(ref_update: float, out: Path) -> dict:
    """Case 1 at the scene's defaults with TLSPH's ``ref_update_strain``, eps_kin accumulated along the way: the chip
    body's means, the run's forces and temperatures."""
    import dataclasses
    import chip_strain as cs
    from refsph.kernels import get_kernel
    from refsph.scenes import get_scene
    from refsph.scenes.thermal_cutting import RAKE_DEG, rake_frame
    from refsph.simulate import simulate
    scene = get_scene("thermal_cutting")
    setup = scene.setup(case=1)
    setup.numerics = dataclasses.replace(setup.numerics, ref_update_strain=ref_update, threads=1)
    nw, h = setup.info["n_work"], setup.numerics.h_over_dp * setup.dp
    kernel = get_kernel(setup.numerics.kernel)
    acc = dict(eps=np.zeros(nw), x=setup.state.x[:nw].copy(), steps=0)

    def hook(state, solver):
        acc["steps"] += 1
        if acc["steps"] % EVERY == 0:
            acc["eps"] += strain_increment(acc["x"], state.x[:nw], h, kernel)
            acc["x"] = state.x[:nw].copy()

    res = simulate(setup, "tlsph", scene=scene, hook=hook, out=out, overwrite=True, progress=False)
    m, st, info = res.summary["metrics"], res.state, res.summary["scene_info"]
    u, n = rake_frame(st.x[:nw], float(st.t), info)
    tu, tc_ = info["tu_m"], 1e-3 * m["chip_thickness_mm"]
    body = cs.zones(u, n, tu, tc_)[0]
    eps_p, eps_kin = float(st.eps_p[:nw][body].mean()), float(acc["eps"][body].mean())
    return dict(ref_update=ref_update, dx_um=1e6 * setup.dp, n_body=int(body.sum()), chip_mm=m["chip_thickness_mm"],
                eps_merchant=cs.merchant_strain(tu, tc_, RAKE_DEG), eps_p=eps_p, eps_kin=eps_kin,
                registered=eps_p / eps_kin, Fc_N_per_mm=1e-3 * m["cutting_force_N_per_m"], Fp_Fc=m["force_ratio"],
                T_RF_K=m["rake_face_temperature_K"], wall_s=res.summary["wall_time_s"])


def report(rows: dict) -> str:
    f = study.fmt
    head = ["ref update", "dx [um]", "chip [mm]", "Merchant eps", "body eps_p", "body eps_kin", "eps_p / eps_kin",
            "eps_p / Merchant", "Fc [N/mm]", "Fp/Fc", "T_RF [K]", "wall [s]"]
    table = [[f(r["ref_update"], ".2f"), f(r["dx_um"], ".0f"), f(r["chip_mm"], ".3f"), f(r["eps_merchant"], ".2f"),
              f(r["eps_p"], ".2f"), f(r["eps_kin"], ".2f"), f(r["registered"], ".2f"),
              f(r["eps_p"] / r["eps_merchant"], ".2f"), f(r["Fc_N_per_mm"], ".0f"), f(r["Fp_Fc"], ".2f"),
              f(r["T_RF_K"], ".0f"), f(r["wall_s"], ".0f")] for _, r in sorted(rows.items(), reverse=True)]
    return ("# How much of the particles' deformation TLSPH registers\n\n"
            "Made by `python benchmarks/registered_strain.py` (module text): case 1 at the scene's defaults (t_u/5, "
            "8 t_u of cut, one run each), the chip body's mean plastic strain eps_p (the return map's) beside the "
            "kinematic strain eps_kin of its particles' own relative motion (kernel-weighted affine fits every "
            f"{EVERY} steps, summed along each path), and Merchant's strain of the run's chip thickness.\n\n"
            + study.md_table(head, table) + "\n")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--redo", type=float, nargs="*", default=[], help="ref_update_strain values to run again")
    ap.add_argument("--scratch", type=Path, default=None, help="where the run folders go (default: a temporary one)")
    args = ap.parse_args(argv)
    rows = json.loads(OUT_JSON.read_text()) if OUT_JSON.exists() else {}
    todo = [r for r in REF_UPDATES if f"{r:g}" not in rows or r in args.redo]
    with tempfile.TemporaryDirectory() as tmp:
        scratch = args.scratch or Path(tmp)
        for r in todo:
            rows[f"{r:g}"] = measure(r, scratch / f"ref_update_{r:g}")
            study.write_json(OUT_JSON, rows)                     # each value kept as soon as it is done
            print(f"ref update {r:g}: eps_p / eps_kin {rows[f'{r:g}']['registered']:.2f}", flush=True)
    study.write_if_changed(OUT_MD, report(rows))
    print(report(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
