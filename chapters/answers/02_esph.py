"""Answer key of chapter 02 (Eulerian SPH).

* answer_1 -- Exercise 1 (GAMMA from 0.3 to 0.02 and to 3.0, scene `tension`, ESPH): a small gamma protects the
  expanding block only partly (its closest pair comes nearer than with the paper's 0.3), and a large gamma is
  worse, not safer: at gamma = 3 the repulsion throws particles onto each other and the smallest pair distance
  collapses to a small fraction of the spacing.
* answer_2 -- Exercise 2 (NW from 8 to 16 particles across the width of scene `bar`, ESPH, gamma = 0): the bar is
  too slow at both resolutions, and halving the spacing roughly halves the wave-speed error (first order in dp).
"""
from refsph.scenes import aisi4340_material
from refsph.simulate import run


def min_pair_distance(gamma):
    r = run("tension", "esph", quick=True, numerics={"gamma": gamma}, progress=False)
    return r.summary["metrics"]["min_pair_distance_over_dp"]


def wave_speed_error(nw):
    mat = aisi4340_material()
    W, L = 2e-3, 20e-3
    t_end = 0.9 * 2 * L / mat.c_bar(2)                 # one half period: two zero crossings of the amplitude
    r = run("bar", "esph", dim=2, dp=W / nw, t_end=t_end, numerics={"gamma": 0.0}, progress=False)
    return r.summary["metrics"]["wave_speed_rel_error"]


def answer_1():
    paper, small, large = min_pair_distance(0.3), min_pair_distance(0.02), min_pair_distance(3.0)
    assert paper > 0.85                                 # the paper's gamma keeps the particles apart
    assert small < paper - 0.02                         # a small gamma protects only partly ...
    assert large < 0.5 * paper                          # ... and a large one makes particles collide


def answer_2():
    coarse, fine = wave_speed_error(8), wave_speed_error(16)
    assert coarse < 0 and fine < 0                      # too slow at both resolutions
    assert 1.5 < coarse / fine < 3.5                    # the error roughly halves: first order in dp
