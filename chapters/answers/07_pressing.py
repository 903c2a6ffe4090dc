"""Answer key of chapter 07 (metal pressing), run by tests/test_exercises.py in quick mode (dp = 1/60 mm).

* answer_1: a faster tool. Doubling the tool speed (200 -> 400 m/s) about doubles the impact peak of the tool
  force (ESPH, first 60 ns), and at both speeds the peak follows the elastic-plastic impact estimate
  sigma_HEL + rho c_B (v - v_HEL) on the block face.
* answer_2: the pinball factor. With K_p = 5 instead of 50 the tool sinks clearly deeper into the TLSPH block
  (deepest pinball penetration after 0.05 mm of tool travel); it stays below one spacing.
* answer_3: no heating. Without adiabatic heating the block stays at room temperature, the mean pressing force is
  higher and the 99th percentile of the plastic strain is lower than with heating: thermal softening helps the
  strain localise.
"""
import dataclasses
import numpy as np

from refsph.boundaries import RigidBody
from refsph.paper_data import PRESSING_GEOMETRY, PRESSING_RESOLUTIONS_M
from refsph.plasticity import yield_stress
from refsph.scenes import aisi4340_johnson_cook, aisi4340_material, get_scene
from refsph.simulate import run, simulate

DP = PRESSING_RESOLUTIONS_M[0]            # the quick spacing, 1/60 mm
SCENE = get_scene("pressing")


def _impact_peak(v):
    """ESPH, the first 60 ns with the tool at speed v: the largest force of the block on the tool [N/m]."""
    st = SCENE.setup(2, DP, True)
    st.state.v[st.info["n_block"]:, 0] = -v
    st.rigid, st.t_end = (RigidBody("tool", 1, (-v, 0.0)),), 60e-9
    rh = simulate(st, "esph", scene=SCENE, progress=False).history["reaction"]
    return float(np.max(np.asarray(rh["tool"])[:, 0]))


def _impact_estimate(v):
    mat, jc = aisi4340_material(), aisi4340_johnson_cook(1.0)
    c_L, c_B = mat.c_longitudinal, np.sqrt(mat.K / mat.rho0)
    sig_hel = (1 - mat.nu) / (1 - 2 * mat.nu) * float(yield_stress(jc, 0.0, 1e6, jc.T_room))
    return (sig_hel + mat.rho0 * c_B * (v - sig_hel / (mat.rho0 * c_L))) * PRESSING_GEOMETRY["block_m"][1]


def answer_1():
    f200, f400 = _impact_peak(200.0), _impact_peak(400.0)
    assert 1.6 < f400 / f200 < 2.4, (f200, f400)                  # about in proportion to the speed
    for v, f in ((200.0, f200), (400.0, f400)):
        assert abs(f / _impact_estimate(v) - 1) < 0.25, (v, f, _impact_estimate(v))
    print(f"impact peak {1e-6 * f200:.2f} -> {1e-6 * f400:.2f} MN/m when the speed doubles")


def _penetration(K_p):
    r = run("pressing", "tlsph", dp=DP, progress=False, options=dict(travel=0.05e-3), numerics=dict(contact_Kp=K_p))
    return r.summary["diagnostics"]["max_pinball_penetration_m"] / r.setup.dp


def answer_2():
    p50, p5 = _penetration(50.0), _penetration(5.0)
    assert p5 > 2 * p50, (p5, p50)                               # a softer pinball lets the tool in deeper
    assert 0 < p50 < p5 < 1.0, (p50, p5)
    print(f"deepest pinball penetration: K_p = 50 {p50:.3f} dp, K_p = 5 {p5:.3f} dp")


def _pressing(heating):
    st = SCENE.setup(2, DP, True)
    st.strength = dataclasses.replace(st.strength, heating=heating)
    r = simulate(st, "esph", scene=SCENE, progress=False)
    n = st.info["n_block"]
    return r.summary["metrics"], float(np.percentile(r.state.eps_p[:n], 99))


def answer_3():
    (m_on, e_on), (m_off, e_off) = _pressing(True), _pressing(False)
    T_room = aisi4340_johnson_cook(1.0).T_room
    assert m_off["max_temperature_K"] == T_room < m_on["max_temperature_K"] - 100
    assert m_off["tool_force_mean_N_per_m"] > m_on["tool_force_mean_N_per_m"]       # stronger without softening
    assert e_off < e_on                                                             # less strain in the bands
    print(f"mean force {1e-6 * m_on['tool_force_mean_N_per_m']:.3f} -> {1e-6 * m_off['tool_force_mean_N_per_m']:.3f}"
          f" MN/m, eps_p p99 {e_on:.3f} -> {e_off:.3f} without heating")
