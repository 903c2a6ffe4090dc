"""The PFEM cut from a script: case 1 of the second paper at t_u/5 over its first 2 t_u, stepped by hand (the
Bossak-Newmark rule instead of the paper's trapezoidal one), the tool force printed as it goes, then the measures
the SPH scene gives (the metrics of summary.json) and the heat ledger."""
from refsph.pfem.cutting import CutRun, pfem_cut

cut = pfem_cut(1, n_tu=5.0, travel=2.0, length=1.2e-3, bossak=-0.1)   # case 1: AISI 1045, 60 m/min, 0.1 mm
run = CutRun(cut)
while not run.done:
    step = run.step()                                 # mechanics (Newton with the contact), heat, remeshing
    if run.steps % 10 == 0:
        Fc, Fp = run.reaction["tool"][-1]             # the workpiece's force on the tool [N/m]
        print(f"step {run.steps:3d}  t = {1e6 * run.nodes.t:6.2f} us  Fc = {Fc / 1e3:6.1f} N/mm  "
              f"Fp = {Fp / 1e3:6.1f} N/mm  Newton {step.iterations}")
res = run.result()
m = res["metrics"]
print(f"{res['steps']} steps, {len(run.nodes.x)} nodes: Fc {m['cutting_force_N_per_m'] / 1e3:.1f} N/mm, Fp/Fc "
      f"{m['force_ratio']:.2f}, T_RF {m['rake_face_temperature_K']:.0f} K, chip {m['chip_thickness_mm']:.3f} mm")
print("heat ledger:", {k: round(v, 6) for k, v in res["heat_balance"].items()})
