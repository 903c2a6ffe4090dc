"""Answer key of chapter 06 (the Taylor impact test), run by tests/test_exercises.py in quick mode.

All three exercises use the 2D half slab (plane strain) at 1 mm with TLSPH, against the reference run at the
paper's 181 m/s and the printed T_m = 1293 K.

* answer_1: impact speed 250 m/s instead of 181 m/s (and 120 m/s). The faster bar ends clearly shorter, with a
  wider foot, more plastic strain and a hotter foot; the slower bar the opposite: the plastic work has to take up
  a kinetic energy that grows as v0^2.
* answer_2: melting temperature 1793 K (the usual value for 4340) instead of the printed 1293 K. The hot metal
  softens less, so the foot gets a little narrower and the bar no shorter; the change is small (well under a
  spacing), because only a small volume at the centre of the foot gets hot.
* answer_3: spacing 0.5 mm instead of 1 mm. The finer slab has a clearly wider foot (by a sizeable fraction of
  a spacing or more) and a length that changes much less: the 1 mm diameter is far from converged, the
  length nearly is (coarse spacings give narrow feet, as in the 3D benchmark).
"""
from functools import lru_cache

from refsph.paper_data import TAYLOR_GEOMETRY
from refsph.scenes import get_scene
from refsph.simulate import simulate

V0 = TAYLOR_GEOMETRY["impact_velocity_m_s"]


@lru_cache(maxsize=None)
def _bar_2d(dp=1e-3, v0=V0, T_melt=None):
    """Final metrics of the 2D TLSPH half slab hitting the wall at v0 [m/s]."""
    scene = get_scene("taylor")
    setup = scene.setup(2, dp, True, **({} if T_melt is None else dict(T_melt=T_melt)))
    setup.state.v[:, -1] = -v0
    return simulate(setup, "tlsph", scene=scene, progress=False).summary["metrics"]


def answer_1():
    ref, fast, slow = _bar_2d(), _bar_2d(v0=250.0), _bar_2d(v0=120.0)
    for m in (ref, fast, slow):
        assert m["settled"]
    # faster: clearly shorter (by more than half a millimetre), wider foot, more strain, hotter
    assert fast["final_length_mm"] < ref["final_length_mm"] - 0.5
    assert fast["final_diameter_mm"] > ref["final_diameter_mm"] + 0.5
    assert fast["max_plastic_strain"] > ref["max_plastic_strain"]
    assert fast["max_temperature_K"] > ref["max_temperature_K"]
    # slower: the opposite
    assert slow["final_length_mm"] > ref["final_length_mm"] + 0.5
    assert slow["final_diameter_mm"] < ref["final_diameter_mm"]
    assert slow["max_plastic_strain"] < ref["max_plastic_strain"]


def answer_2():
    ref, cool = _bar_2d(), _bar_2d(T_melt=1793.0)
    dD = cool["final_diameter_mm"] - ref["final_diameter_mm"]
    dL = cool["final_length_mm"] - ref["final_length_mm"]
    assert dD < 0.0, "a higher melting temperature softens less: the foot must get narrower"
    assert abs(dD) < 0.5, "... but only a little (well under the 1 mm spacing)"
    assert dL > -0.01 and abs(dL) < 0.2, "the length hardly changes, and the bar does not get shorter"


def answer_3():
    coarse, fine = _bar_2d(), _bar_2d(dp=0.5e-3)
    dD = fine["final_diameter_mm"] - coarse["final_diameter_mm"]
    dL = fine["final_length_mm"] - coarse["final_length_mm"]
    assert dD > 0.4, "the finer slab has a clearly wider foot"
    assert abs(dL) < 0.5 * dD, "the length changes much less than the foot width"
