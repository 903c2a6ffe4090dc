"""How much of the friction law reaches the rake face: the tool's force on the chip split into the pinball's
line-of-centres part (Eqs. (32)-(35)) and its friction part (mu(T), refsph.contact), resolved along the rake face
and normal to it, time means over the second half of a quick thermal cut (case 1, chapter 11's set-up).

    python benchmarks/rake_face_friction.py          # about a minute on one core; writes rake_face_friction.json

The decomposition evaluates each contact twice, with and without friction (same state, same step), and takes the
difference as the friction force: a diagnostic, not part of a run. Reported:

* mu_friction = (friction force along the face) / (normal force): what the friction law delivers;
* mu_geometric = (line-of-centres force along the face) / (normal force): the sliding resistance of the particle
  lattice itself (a chip particle rides over the tool particles' pinballs, whose lines of centres are not normal to
  the face);
* mu_law = the mean mu(T) of the chip particles in contact: what Coulomb's law would give.
"""
from __future__ import annotations

import dataclasses
import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

OUT_JSON = Path(__file__).resolve().parent / "rake_face_friction.json"


def measure(options: dict) -> dict:
    import refsph.contact as contact
    from refsph.scenes.thermal_cutting import RAKE_DEG
    from refsph.simulate import run
    original = contact.pinball_contact
    rows = []

    def split(x_a, v_a, m_a, x_b, v_b, m_b, R, mu_a, mu_b, dt, law, thickness=1.0, T_a=None):
        c = original(x_a, v_a, m_a, x_b, v_b, m_b, R, mu_a, mu_b, dt, law, thickness, T_a)
        if law.friction is not None and np.all(np.isinf(m_b)):
            c0 = original(x_a, v_a, m_a, x_b, v_b, m_b, R, mu_a, mu_b, dt, dataclasses.replace(law, friction=None),
                          thickness, T_a)
            f_all, f_normal = (c.a * m_a[:, None]).sum(0), (c0.a * m_a[:, None]).sum(0)
            touched = np.any(c0.a != 0, axis=1)
            mu = float(law.friction.mu(T_a[touched]).mean()) if touched.any() else math.nan
            rows.append((*f_normal, *(f_all - f_normal), mu))
        return c

    contact.pinball_contact = split
    try:
        res = run("thermal_cutting", "tlsph", quick=True, progress=False, options=options, numerics=dict(threads=1))
    finally:
        contact.pinball_contact = original
    a = np.asarray(rows)[len(rows) // 2:]
    g = math.radians(RAKE_DEG)
    into_chip, up_face = np.array([-math.cos(g), math.sin(g)]), np.array([math.sin(g), math.cos(g)])
    normal = float(np.mean(a[:, :2] @ into_chip))
    along_geom, along_fric = float(np.mean(a[:, :2] @ up_face)), float(np.mean(a[:, 2:4] @ up_face))
    return dict(options=options, n_evaluations=len(rows), normal_force_N_per_m=normal,
                friction_along_face_N_per_m=along_fric, lattice_along_face_N_per_m=along_geom,
                mu_friction=-along_fric / normal, mu_geometric=-along_geom / normal,
                mu_law=float(np.nanmean(a[:, 4])), force_ratio=res.summary["metrics"]["force_ratio"])


def main(argv=None) -> int:
    ap = study.parser(__doc__)
    ap.add_argument("--json", type=Path, default=OUT_JSON, help="where to write the result (default: "
                                                                  "rake_face_friction.json)")
    path = ap.parse_args(argv).json
    out = measure(dict(case=1, length=1.2e-3, travel=4.0))
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
