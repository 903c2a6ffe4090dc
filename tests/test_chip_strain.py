"""benchmarks/chip_strain.py: Merchant's strain from the chip thickness in closed form, the chip's body picked out of
the rake-face frame, and the page made from the committed JSON."""
import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))


def test_merchant_strain_in_closed_form():
    import chip_strain as cs
    assert math.isclose(cs.merchant_strain(1.0, 1.0, 0.0), 2.0 / math.sqrt(3.0))        # r = 1, no rake: phi 45 deg
    g = math.radians(10.0)                                                              # r = 1: phi = 45 + gamma / 2
    phi = math.pi / 4 + g / 2
    assert math.isclose(cs.merchant_strain(0.1, 0.1, 10.0), math.cos(g) / (math.sin(phi) * math.cos(phi - g)) / 3**0.5)
    assert cs.merchant_strain(0.1, 0.4, 10.0) > cs.merchant_strain(0.1, 0.3, 10.0)      # a thicker chip: more shear


def test_the_chips_body_and_secondary_zone_are_picked_out():
    import chip_strain as cs
    tu, tc = 1e-4, 3e-4
    u, n = np.meshgrid(np.linspace(0.0, 8 * tu, 161), np.linspace(-tc, 2 * tc, 121))
    u, n = u.ravel(), n.ravel()
    body = (u >= 1.5 * tu) & (u < 3 * tu) & (n >= 0.25 * tc) & (n < 0.75 * tc)
    face = (u >= 1.5 * tu) & (u < 3 * tu) & (n >= 0) & (n < 0.1 * tc)
    eps = np.where(body, 1.0, np.where(face, 3.0, 7.0))
    out = cs.body_means(*cs.zones(u, n, tu, tc), eps, 300.0 + 100.0 * eps)
    assert out["eps_body"] == 1.0 and out["eps_face"] == 3.0 and out["T_body_K"] == 400.0
    assert out["n_body"] == body.sum() > 0 and out["n_face"] == face.sum() > 0


def test_page_is_made_from_the_json():
    import chip_strain as cs
    rows = json.loads((ROOT / "benchmarks" / "chip_strain.json").read_text())
    assert cs.report(rows) == (ROOT / "benchmarks" / "chip_strain_report.md").read_text()


def test_compaction_of_a_lattice_squeezed_to_half_its_area():
    """A square lattice squeezed to half its width in x: every neighbourhood's area ratio is 0.5 and the particles
    have more neighbours within 1.5 dx; a lattice moved rigidly keeps J = 1 and its neighbour count."""
    import chip_strain as cs
    dx = 1.0
    g = np.arange(12) * dx
    X0 = np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)
    inner = np.flatnonzero(np.all((X0 > 3) & (X0 < 8), axis=1))
    squeezed = cs.compaction(X0, X0 * [0.5, 1.0], inner, dx)
    assert np.isclose(squeezed["area_ratio"], 0.5) and squeezed["neighbours_now"] > squeezed["neighbours_start"]
    c, s = np.cos(0.3), np.sin(0.3)
    moved = cs.compaction(X0, X0 @ np.array([[c, s], [-s, c]]) + 5.0, inner, dx)
    assert np.isclose(moved["area_ratio"], 1.0) and np.isclose(moved["neighbours_now"], moved["neighbours_start"])


def test_the_reference_update_runs_are_read_and_summarised_apart():
    """wanted: the sweep's t_u/10 runs and the 'refupdate' study's (any resolution); the page's summary lines keep
    each method, reference update and resolution apart."""
    import chip_strain as cs
    assert cs.wanted(dict(n_tu=10.0), {}) and cs.wanted(dict(n_tu=5.0), dict(ref_update_strain=0.1))
    assert not cs.wanted(dict(n_tu=5.0), {}) and not cs.wanted(dict(n_tu=15.0), dict(courant=0.15))
    base = dict(method="tlsph", tu_mm=0.1, chip_mm=0.3, eps_merchant=2.0, eps_body=1.0, body_over_merchant=0.5,
                T_body_K=600.0, eps_face=1.5, T_face_K=650.0, n_body=10, n_face=2)
    rows = {"a": dict(base, ref_update=0.5, across=10.0), "b": dict(base, ref_update=0.1, across=5.0,
                                                                      body_over_merchant=0.9)}
    page = cs.report(rows)
    assert "tlsph (ref update 0.5, t_u/10): body / Merchant 0.50" in page
    assert "tlsph (ref update 0.1, t_u/5): body / Merchant 0.90" in page


def test_a_run_with_a_blow_up_gives_no_row(tmp_path):
    """row: a run folder whose summary says 'ok' but whose metrics flag a blow-up (the sweep records it 'blow-up')
    is not read."""
    import chip_strain as cs
    (tmp_path / "summary.json").write_text(json.dumps(dict(status="ok", snapshots=["snap_00000.npz"],
                                                           metrics=dict(blow_up="a particle at 44351 K"))))
    assert cs.row(tmp_path) is None
