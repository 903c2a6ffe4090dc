"""benchmarks/pfem_ringing.py: the step-to-step alternation of a force history is 0 for a linear one and twice the
relative amplitude for an oscillation of period two steps; a run folder's CSV is read into a row."""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))


def test_alternation_of_smooth_and_ringing_forces():
    import pfem_ringing as pr
    k = np.arange(400)
    smooth = 300.0 + 0.1 * k                                            # linear: no alternation at all
    assert np.allclose(pr.alternation(smooth), 0.0, atol=1e-12)
    ringing = 300.0 * (1 + 0.1 * (-1.0) ** k * (k >= 200))             # +-10 % in the second half only
    a = pr.alternation(ringing)
    assert a[0] == 0.0 and a[1] < 0.01 and np.allclose(a[2:], 0.2, rtol=0.01)


def test_a_run_folder_gives_a_row(tmp_path):
    import pfem_ringing as pr
    assert pr.row(tmp_path) is None                                     # no forces
    t = np.arange(1, 41) * 1e-6
    F = 300.0 * (1 + 0.05 * (-1.0) ** np.arange(40))
    np.savetxt(tmp_path / "reaction_forces.csv", np.column_stack([t, np.full(40, 1e-6), F, 0.3 * F]),
               delimiter=",", header="refsph reaction forces\nt,dt,tool_x,tool_y")
    r = pr.row(tmp_path)
    assert r["steps"] == 40 and np.isclose(r["t_ms"], 0.04) and np.allclose(r["alternation"], 0.1, rtol=0.01)
