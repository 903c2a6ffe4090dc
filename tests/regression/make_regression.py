"""Writes the regression files of tests/test_taylor.py, tests/test_pressing.py and tests/test_cutting.py:

* ``taylor_3d_1mm.json``: the quick 3D Taylor run (dp = 1 mm) of both methods;
* ``pressing_quick.json``: the quick pressing run (dp = 1/60 mm, CFL step) of both methods;
* ``cutting_coarse.json``: the cutting run at dp = 0.05 mm, 0.2 mm of cut, of both methods (tests/test_cutting.py).

Run it only when a change of the numbers is intended (and say why in the commit):
    python tests/regression/make_regression.py            # both
    python tests/regression/make_regression.py pressing   # one of them
"""
import json
import sys
from pathlib import Path

from refsph.simulate import run

HERE = Path(__file__).parent
which = sys.argv[1:] or ["taylor", "pressing", "cutting"]

if "taylor" in which:
    out = {}
    for m in ("esph", "tlsph"):
        met = run("taylor", m, dim=3, dp=1.0e-3, progress=False).summary["metrics"]
        out[m] = {k: met[k] for k in ("final_length_mm", "final_diameter_mm", "max_plastic_strain",
                                      "max_temperature_K")}
    path = HERE / "taylor_3d_1mm.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(path, out)

if "pressing" in which:
    out = {}
    for m in ("esph", "tlsph"):
        met = run("pressing", m, quick=True, progress=False).summary["metrics"]
        out[m] = {k: met[k] for k in ("tool_force_peak_N_per_m", "tool_force_mean_N_per_m",
                                      "clamp_force_mean_N_per_m", "max_plastic_strain", "max_temperature_K")}
        out[m]["plastic_strain_line_eps_p"] = [float(e) for e in met["plastic_strain_line"][:, 1]]
    path = HERE / "pressing_quick.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(path, {m: {k: v for k, v in d.items() if k != "plastic_strain_line_eps_p"} for m, d in out.items()})

if "cutting" in which:
    out = {}
    for m in ("esph", "tlsph"):
        met = run("cutting", m, dp=0.05e-3, progress=False, options=dict(travel=0.2e-3)).summary["metrics"]
        out[m] = {k: met[k] for k in ("cutting_force_mean_N_per_m", "thrust_force_mean_N_per_m", "max_temperature_K",
                                      "max_plastic_strain")}
    path = HERE / "cutting_coarse.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(path, out)
