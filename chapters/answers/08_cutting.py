"""Answer key of chapter 08 (orthogonal cutting), "Your turn". Quick mode (REFSPH_QUICK=1, as in the tests):
TLSPH at dp = 0.05 mm over 0.2 mm of cut, about 5 s per run.

* answer_1 (a deeper cut): feed 0.5 mm against 0.3 mm. The cutting force grows with the feed, by roughly the
  ratio of the feeds, so the specific cutting energy Fc / feed stays about the same.
* answer_2 (TLSPH without reference updates): with ``ref_update_strain=None`` no update is made, and the layer
  just under the cut line (the new surface the tool has passed) is strained more and the hottest particle is
  hotter than with updates: the workpiece is still tied to its old neighbours in the chip. (A longer cut loses
  the run; a lost run counts as the same answer.)
* answer_3 (bands need particles): five drawn bands 0.15 mm apart, 1.5 spacings wide, are all found at
  dp = 0.01 and 0.025 mm, and merge at dp = 0.05 mm, where the measure finds fewer than were drawn.
"""
import math
import os

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402

from refsph.paper_data import CUTTING_GEOMETRY  # noqa: E402
from refsph.scenes.cutting import shear_bands  # noqa: E402
from refsph.simulate import SimulationError, run  # noqa: E402

QUICK = os.environ.get("REFSPH_QUICK", "0") == "1"
DP = 0.05e-3 if QUICK else 0.025e-3
TRAVEL_EX = 0.2e-3 if QUICK else 0.5e-3
(LX, LY) = CUTTING_GEOMETRY["workpiece_m"]


def _cut(feed=0.3e-3, numerics=None):
    return run("cutting", "tlsph", dp=DP, progress=False, numerics=numerics, options=dict(feed=feed, travel=TRAVEL_EX))


def answer_1():
    Fc = {f: _cut(feed=f).summary["metrics"]["cutting_force_mean_N_per_m"] for f in (0.3e-3, 0.5e-3)}
    ratio = Fc[0.5e-3] / Fc[0.3e-3]
    print(f"Fc(0.5 mm) / Fc(0.3 mm) = {ratio:.2f}; Fc / feed: {Fc[0.3e-3] / 0.3e-3 / 1e9:.2f} and "
          f"{Fc[0.5e-3] / 0.5e-3 / 1e9:.2f} GJ/m^3")
    assert 1.2 < ratio < 2.2, ratio                     # larger, roughly in proportion to the feed (5/3)
    assert abs(Fc[0.5e-3] / 0.5e-3 / (Fc[0.3e-3] / 0.3e-3) - 1) < 0.35      # about the same specific energy


def _surface_strain(numerics):
    """(reference updates, mean eps_p of the two rows under the cut line the tool has passed, max T); None if lost."""
    try:
        r = _cut(numerics=numerics)
    except SimulationError:
        return None
    n, y0, dy = r.setup.info["n_work"], r.setup.info["y0"], r.setup.info["dy"]
    X, x_tip = r.setup.state.x[:n], r.state.x[n:, 0].min()
    surface = (X[:, 1] < y0) & (X[:, 1] > y0 - 2 * dy) & (X[:, 0] > x_tip)
    return r.summary["diagnostics"]["reference_updates"], float(r.state.eps_p[:n][surface].mean()), r.state.T[:n].max()


def answer_2():
    with_upd, without = _surface_strain(dict(ref_update_strain=0.5)), _surface_strain(dict(ref_update_strain=None))
    print(f"with updates: {with_upd}; without: {without if without else 'lost'}")
    assert with_upd is not None and with_upd[0] > 0
    if without is None:                                  # lost: the failure the benchmark shows at a longer cut
        return
    assert without[0] == 0
    assert without[1] > 1.15 * with_upd[1]               # the new surface is dragged along with the chip
    assert without[2] > with_upd[2]                      # and the edge particles heat more


def _banded_count(dp, feed=0.3e-3, spacing=0.15e-3, angle_deg=45.0, x_tip=2.0e-3, width=1.5):
    nx, ny = round(LX / dp), round(LY / dp)
    X = np.stack(np.meshgrid((np.arange(nx) + 0.5) * dp, (np.arange(ny) + 0.5) * dp, indexing="ij"),
                 axis=-1).reshape(-1, 2)
    shift = X[:, 0] + (X[:, 1] - (LY - feed / 2)) / math.tan(math.radians(angle_deg))
    centres = np.arange(x_tip - feed / 2 + spacing, LX - feed, spacing)
    d = np.min(np.abs(shift[:, None] - centres[None, :]), axis=1) * math.sin(math.radians(angle_deg))
    eps = 0.3 + 1.7 * np.exp(-0.5 * (d / (width * dp)) ** 2)
    eps[X[:, 1] < LY - feed] = 0.0
    return len(centres), shear_bands(X, eps, nx, ny, dp, dp, feed, x_tip)["n"]


def answer_3():
    counts = {dp: _banded_count(dp) for dp in (0.01e-3, 0.025e-3, 0.05e-3)}
    print({f"{1e3 * dp:g} mm": f"drew {a}, found {b}" for dp, (a, b) in counts.items()})
    drawn = counts[0.01e-3][0]
    assert counts[0.01e-3][1] == drawn and counts[0.025e-3][1] == drawn      # resolved: all found
    assert counts[0.05e-3][1] < drawn                                        # too coarse: they merge
