"""Writes tests/regression/taylor_3d_1mm.json: the quick 3D Taylor run (dp = 1 mm) of both methods.

Run it only when a change of the numbers is intended (and say why in the commit):
    python tests/regression/make_regression.py
"""
import json
from pathlib import Path

from refsph.simulate import run

out = {}
for m in ("esph", "tlsph"):
    met = run("taylor", m, dim=3, dp=1.0e-3, progress=False).summary["metrics"]
    out[m] = {k: met[k] for k in ("final_length_mm", "final_diameter_mm", "max_plastic_strain", "max_temperature_K")}
path = Path(__file__).parent / "taylor_3d_1mm.json"
path.write_text(json.dumps(out, indent=1) + "\n")
print(path, out)
