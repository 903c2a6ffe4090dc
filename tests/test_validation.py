"""Elastic validation on whole runs: wave speed, momentum, energy, tensile instability."""
import pytest

from refsph.scenes import get_scene
from refsph.simulate import run

W = 2e-3  # bar width in scene 'bar'


def _period(dim=2):
    setup = get_scene("bar").setup(dim, W / 4, True)
    return setup.info["period_theory"]


@pytest.mark.parametrize("method, dp, dim", [("tlsph", W / 8, 2), ("esph", W / 16, 2), ("tlsph", W / 4, 3)])
def test_bar_wave_speed_within_3_percent(method, dp, dim):
    """First axial mode of a free-free bar: c = 2 L / T within 3 % of sqrt(E / ((1 - nu^2) rho)) (2D plane
    strain) or sqrt(E / rho) (3D).

    ESPH needs 16 particles across the bar: its free-surface layers are soft (Eq. 23 is not corrected)."""
    # artificial pressure (a tensile-instability remedy) off: it softens the bar in its tensile half-cycle
    res = run("bar", method, dim=dim, dp=dp, t_end=2.05 * _period(dim), numerics={"gamma": 0.0},
              progress=False)
    m = res.summary["metrics"]
    assert abs(m["wave_speed_rel_error"]) < 0.03, m["wave_speed_rel_error"]


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_free_flight_momentum_and_energy(method):
    res = run("bar", method, quick=True, t_end=_period(), progress=False)
    m = res.summary["metrics"]
    assert m["momentum_drift_rel"] < 1e-12
    # energy is reported and only dissipated (artificial viscosity), never created
    assert 0.5 < m["energy_final_over_initial"] <= 1.0 + 1e-3


def test_fixed_dt_matches_cfl():
    """The paper's fixed dt (here 1/2 of the CFL step) gives the same wave speed as the CFL step."""
    p = _period()
    a = run("bar", "tlsph", quick=True, t_end=1.05 * p, progress=False).summary
    dt = 0.5 * a["dt_min"]
    b = run("bar", "tlsph", quick=True, t_end=1.05 * p, dt=dt, progress=False).summary
    assert b["dt_mode"] == "fixed" and b["n_steps"] > a["n_steps"]
    assert b["metrics"]["wave_speed_m_s"] == pytest.approx(a["metrics"]["wave_speed_m_s"], rel=2e-3)


def test_tensile_instability_measured():
    """Block in tension: ESPH without artificial pressure clumps (min pair distance falls far below dp),
    artificial pressure (gamma = 0.3) and TLSPH do not."""
    r = {}
    for label, method, num in (("esph0", "esph", {"gamma": 0.0}), ("esph03", "esph", {"gamma": 0.3}),
                               ("tlsph", "tlsph", {})):
        res = run("tension", method, quick=True, numerics=num, progress=False)
        r[label] = res.summary["metrics"]["min_pair_distance_over_dp"]
    assert r["esph0"] < 0.85, r
    assert r["esph03"] > r["esph0"] + 0.1, r
    assert r["tlsph"] > r["esph0"] + 0.1, r
