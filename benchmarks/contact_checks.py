"""Contact checks with closed-form answers (issue 22, part 2): the paper's pinball (Eqs. (32)-(36)) against the
penalty contact on the tool's exact geometry (refsph.penalty), on the set-ups of refsph/scenes/contact_checks.py.

    python benchmarks/contact_checks.py      # about 10 minutes on one core; writes contact_checks.json and
                                             # contact_checks_report.md
    python benchmarks/contact_checks.py --report     # the page again from the JSON

* mass scale: a block on a plane above the friction angle (tan theta = 2 mu, mu = 0.3), density times s = 1, 10,
  100, 1000: the sliding acceleration against g (sin theta - mu cos theta) and F_t / F_N on the plane against mu;
* threshold: theta around the friction angle (tan theta / mu = 0.8, 0.95, 1.05, 1.25): stuck or sliding, and the
  acceleration against the closed form;
* impact: an elastic strip (L = 2 mm, W = L / 5, nu = 0: the 1D answer is exact) striking a rigid plane at 5 m/s,
  L / dx = 20, 40, 80, 160: the contact time against 2 L / c and the peak force against rho c v0 W, with the
  observed order of the contact-time error between successive resolutions.

A rerun that gives the committed numbers again (wall times aside) leaves contact_checks.json as it is, a run that
fails writes nothing, and this page is written only when it changes.
"""
from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

from refsph.scenes.contact_checks import (BodyForce, bar_speed, impact_measures, incline,  # noqa: E402
                                          sliding, strip_impact)
from refsph.simulate import make_solver, simulate  # noqa: E402

OUT_JSON = Path(__file__).with_name("contact_checks.json")
OUT_REPORT = Path(__file__).with_name("contact_checks_report.md")
CONTACTS = ("pinball", "penalty")
MU, DX, G0, T_END = 0.3, 1e-4, 2e6, 40e-6
SCALES = (1.0, 10.0, 100.0, 1000.0)
RATIOS = (0.8, 0.95, 1.05, 1.25)
IMPACT_N = (20, 40, 80, 160)
L_STRIP, V0 = 2e-3, 5.0


def slide(theta: float, s: float, contact: str) -> dict:
    """One block-on-plane run: the measured acceleration and mu_eff against the closed form."""
    setup, g, n = incline(theta, MU, mass_scale=s, contact=contact, dx=DX, nx=10, ny=4, g0=G0, t_end=T_END)
    record = []
    t0 = time.perf_counter()
    res = simulate(setup, solver=BodyForce(make_solver("tlsph", setup), g, n), progress=False,
                   hook=lambda st, sv: record.append((st.t, float(np.mean(st.v[:n, 0])))))
    t, v = np.array(record).T
    m = sliding(res.history, t, v)
    exact = max(G0 * (math.sin(theta) - MU * math.cos(theta)), 0.0)
    return dict(contact=contact, s=s, tan_ratio=math.tan(theta) / MU, a=m["a"], a_exact=exact, mu_eff=m["mu_eff"],
                stuck=abs(m["a"]) < 0.01 * G0 * math.sin(theta), n_steps=res.summary["n_steps"],
                wall_s=time.perf_counter() - t0)


def impact(n: int, contact: str) -> dict:
    """One strip impact at L / dx = n."""
    setup, t_c = strip_impact(length=L_STRIP, width=L_STRIP / 5, dx=L_STRIP / n, v0=V0, contact=contact)
    t0 = time.perf_counter()
    res = simulate(setup, "tlsph", progress=False)
    m = impact_measures(res.history, res.state, setup.info["n_strip"], V0)
    F_1d = setup.material.rho0 * bar_speed(setup.material) * V0 * setup.info["width"]
    return dict(contact=contact, n=n, particles=setup.state.n, t_contact=m["t_contact"], t_c=t_c,
                error=m["t_contact"] / t_c - 1.0, F_max_over_1d=m["F_max"] / F_1d, rebound=m["rebound"],
                n_steps=res.summary["n_steps"], wall_s=time.perf_counter() - t0)


def orders(rows: list) -> dict:
    """Observed order of the contact-time error between successive resolutions, per contact."""
    out = {}
    for c in CONTACTS:
        e = [abs(r["error"]) for r in rows if r["contact"] == c]
        out[c] = [math.log2(a / b) if a > 0 and b > 0 else None for a, b in zip(e, e[1:])]
    return out


def measure() -> dict:
    theta_slide = math.atan(2.0 * MU)
    scale = [slide(theta_slide, s, c) for c in CONTACTS for s in SCALES]
    threshold = [slide(math.atan(r * MU), 1.0, c) for c in CONTACTS for r in RATIOS]
    imp = [impact(n, c) for c in CONTACTS for n in IMPACT_N]
    return dict(mu=MU, g0=G0, dx=DX, mass_scale=scale, threshold=threshold, impact=imp, impact_orders=orders(imp))


def report(doc: dict) -> str:
    f = study.fmt
    rows = [[r["contact"], f(r["s"], "g"), f(r["a"] / r["a_exact"], ".3f"), f(r["mu_eff"] / doc["mu"], ".3f")]
            for r in doc["mass_scale"]]
    t1 = study.md_table(["contact", "mass scale s", "a / a_exact", "(F_t/F_N) / mu"], rows)
    rows = [[r["contact"], f(r["tan_ratio"], ".2f"), "stuck" if r["stuck"] else "slides",
             "expected " + ("stuck" if r["tan_ratio"] <= 1 else "slides"),
             f(r["a"] / r["a_exact"], ".3f") if r["a_exact"] > 0 else f(r["a"] / doc["g0"], ".1e")]
            for r in doc["threshold"]]
    t2 = study.md_table(["contact", "tan(theta) / mu", "measured", "closed form", "a / a_exact (stuck: a / g)"],
                        rows)
    rows = [[r["contact"], str(r["n"]), f(r["error"], "+.4f"), f(r["F_max_over_1d"], ".3f"),
             f(r["rebound"], ".3f")] for r in doc["impact"]]
    t3 = study.md_table(["contact", "L / dx", "t_contact / (2L/c) - 1", "F_max / (rho c v0 W)", "v_out / v0"], rows)
    orders_line = "; ".join(f"{c}: " + ", ".join(f(p, ".2f") for p in ps) for c, ps in doc["impact_orders"].items())
    return "\n\n".join(["# Contact checks with closed-form answers (`benchmarks/contact_checks.py`)",
                        __doc__.split("\n\n", 1)[1].strip(), "## Block on a plane: mass scale", t1,
                        "## Block on a plane: the friction angle", t2, "## Strip impact: contact time", t3,
                        f"Observed order of |t_contact / (2L/c) - 1| between successive resolutions: {orders_line}."]
                       ) + "\n"


def main(argv=None) -> int:
    ap = study.parser(__doc__, "report")
    args = ap.parse_args(argv)
    if not args.report:
        study.write_json(OUT_JSON, measure(), ignore=("wall_s",))
    study.write_if_changed(OUT_REPORT, report(json.loads(OUT_JSON.read_text())))
    print(OUT_REPORT.read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
