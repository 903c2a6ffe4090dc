"""The thermomechanical cutting model (issue 16): frictional heat, the heat balance of a cutting run, mass scaling,
the tool's geometry and the scene's options. The 18-case comparison is a benchmark
(benchmarks/thermal_cutting.py), its page checked in tests/test_reports.py."""
import math

import numpy as np
import pytest

from refsph.contact import CoulombFriction, PinballContact, pinball_contact
from refsph.kernels import get_kernel
from refsph.scenes import get_scene
from refsph.scenes.thermal_cutting import EDGE_RADIUS, drift, tool_particles
from refsph.simulate import cfl_time_step, run
from refsph.state import make_state
from refsph.thermal import Conduction, FrictionHeat, coefficients, thermal_step


def test_friction_power_is_force_times_sliding_speed_and_is_split_as_asked():
    """One particle sliding over a rigid one while pressed onto it: the pinball's friction power is |f_t| |v_t|
    (module text of refsph.contact), and thermal_step puts eta x chip_fraction of it into the particle and the
    rest into the tool row."""
    R, dt, m = 0.5e-5, 1e-9, 2e-6
    xa, va = np.array([[0.0, 0.9e-5]]), np.array([[3.0, -1.0]])          # approaching (p_d > 0) and sliding
    xb, vb = np.array([[0.0, 0.0]]), np.zeros((1, 2))
    fr = CoulombFriction(mu0=0.5, q=2.0, T_room=293.0, T_melt=1800.0)
    cres = pinball_contact(xa, va, np.array([m]), xb, vb, np.inf, R, 80e9, np.inf, dt,
                           PinballContact(k=1 / 3, K_p=50.0, friction=fr), thickness=1e-5, T_a=np.array([293.0]))
    f_t = cres.a[0, 0] * m                                                # the only x force is friction
    assert f_t < 0 and cres.friction_power_a[0] == pytest.approx(abs(f_t) * 3.0, rel=1e-12)
    assert cres.friction_power_b[0] == cres.friction_power_a[0]
    state = make_state(np.vstack([xa, xb]), np.zeros((2, 2)), 7800.0, 1e-10, T0=293.0, body=np.array([0, 1]))
    model = Conduction(k=1e-30, courant=0.3, tools={1: (1e-30, 15.0)})
    k, c = coefficients(model, 500.0, state.body, state.n, [1])
    power = np.concatenate([cres.friction_power_a, cres.friction_power_b])   # Rates.friction_power: every row
    for conduction in (model, None):                     # frictional heat with or without conduction
        T, heat = thermal_step(state, conduction, k, c, 1.3e-5, get_kernel("wendland"), dt,
                               FrictionHeat(eta=1.0, chip_fraction=0.25), power, np.array([False, True]))
        P = cres.friction_power_a[0]
        assert heat["friction"] == pytest.approx(P * dt, rel=1e-12)
        mc = state.m * np.array([500.0, 15.0])
        assert (T - 293.0) * mc == pytest.approx([0.25 * P * dt, 0.75 * P * dt], rel=1e-6)


@pytest.fixture(scope="module")
def short_cut():
    """A short quick cut (one t_u on a 0.5 mm workpiece) with everything switched on."""
    return run("thermal_cutting", "tlsph", quick=True, progress=False,
               options=dict(case=1, length=0.5e-3, travel=1.0), numerics=dict(threads=1))


def test_heat_balance_of_a_cutting_run(short_cut):
    """plastic + frictional heat + the numerical dissipation's heat = heat stored + lost + removed at the fixed rows
    (to round-off: every term is counted where it is made), and the heat made is a fraction of the tool's work
    (chi = 0.9 of the plastic work; the rest is elastic and kinetic energy and the cold work)."""
    hb, m = short_cut.summary["heat_balance"], short_cut.summary["metrics"]
    assert short_cut.summary["status"] == "ok"
    assert hb["plastic_J"] > 0 and hb["friction_J"] > 0 and hb["lost_J"] > 0 and hb["removed_J"] > 0
    assert hb["dissipation_J"] > 0                  # artificial viscosity and contact damping, turned into heat
    assert abs(hb["residual_rel"]) < 1e-9
    made = hb["plastic_J"] + hb["friction_J"] + hb["dissipation_J"]
    assert 0.5 < made / m["tool_work_J_per_m"] < 1.0
    assert 293.0 < m["rake_face_temperature_K"] < m["max_temperature_K"] < 1773.0
    assert m["cutting_force_N_per_m"] > 0 and m["passive_force_N_per_m"] > 0


@pytest.mark.parametrize("wrong", ["chi", "cp"])
def test_the_heat_ledger_catches_a_wrong_chi_or_cp_in_the_heating(monkeypatch, wrong):
    """The ledger counts the plastic heat from the plastic work alone (chi sum m dW_p / rho) and the stored heat from
    the temperatures (sum m c_p (T - T0)): a heating (Eq. (28)) that used another chi or c_p than the law's leaves a
    residual of the size of the error, where the right one balances to round-off (test above)."""
    import dataclasses

    import refsph.plasticity as plasticity
    right = plasticity.temperature_increment
    change = dict(chi=lambda law: dataclasses.replace(law, chi=0.8 * law.chi),
                  cp=lambda law: dataclasses.replace(law, cp=1.25 * law.cp))[wrong]
    monkeypatch.setattr(plasticity, "temperature_increment", lambda dw, rho, law: right(dw, rho, change(law)))
    res = run("thermal_cutting", "tlsph", quick=True, progress=False,
              options=dict(case=1, length=0.5e-3, travel=0.3), numerics=dict(threads=1))
    hb = res.summary["heat_balance"]
    assert hb["plastic_J"] > 0 and abs(hb["residual_rel"]) > 0.05, hb


def test_frictional_heat_without_conduction():
    """Frictional heat is its own switch (Setup.friction_heat): without conduction the heat stays where it is made,
    and the ledger still balances."""
    setup = get_scene("thermal_cutting").setup(quick=True, case=1, length=0.5e-3, travel=0.3)
    setup.thermal = None
    from refsph.simulate import simulate
    res = simulate(setup, "tlsph", progress=False)
    hb = res.summary["heat_balance"]
    assert hb["friction_J"] > 0 and hb["lost_J"] == 0 and hb["removed_J"] == 0
    assert abs(hb["residual_rel"]) < 1e-9


def test_mass_scaling_keeps_rho_cp_and_lengthens_the_step():
    scene = get_scene("thermal_cutting")
    a = scene.setup(case=1, mass_scale=1.0, length=0.6e-3, travel=2.0)
    b = scene.setup(case=1, mass_scale=100.0, length=0.6e-3, travel=2.0)
    n = a.info["n_work"]
    assert b.state.rho[:n] * b.strength.cp == pytest.approx(a.state.rho[:n] * a.strength.cp, rel=1e-12)
    assert b.strength.cp * b.material.rho0 == pytest.approx(a.strength.cp * a.material.rho0, rel=1e-12)
    ratio = cfl_time_step(b.state, b.material, b.h, 0.3) / cfl_time_step(a.state, a.material, a.h, 0.3)
    assert ratio == pytest.approx(10.0, rel=0.02)                       # c_L / sqrt(s), v_c << c_L
    assert b.info["inertia_ratio"] == pytest.approx(100 * a.info["inertia_ratio"])


def test_drift_is_the_change_over_the_window():
    t = np.linspace(0.0, 1.0, 101)
    assert drift(t, 3.0 + 8.0 * t, 0.75, 1.0) == pytest.approx(2.0)             # slope 8 over a quarter
    assert drift(t, np.where(t < 0.5, 100.0, 5.0), 0.75, 1.0) == pytest.approx(0.0, abs=1e-12)
    assert np.isnan(drift(t[:2], t[:2], 0.0, 1.0))


def test_tool_geometry():
    """Rake face 10 deg from the normal to the cut, a 70 deg wedge, the first layer exactly on a line (no
    staircase), and the 10 um edge rounding removing the corner particles once dx resolves it."""
    tu, dx = 0.1e-3, 2e-6
    x, held = tool_particles(dx, tu, (0.0, 0.0))
    u = x[:, 0] * math.sin(math.radians(10)) + x[:, 1] * math.cos(math.radians(10))
    w = x[:, 0] * math.cos(math.radians(10)) - x[:, 1] * math.sin(math.radians(10))
    assert w.min() == pytest.approx(0.5 * dx) and u.min() > 0
    first = w < dx
    assert np.ptp(w[first]) < 1e-12                                      # a flat rake face
    assert np.degrees(np.arctan2(w, u)).max() <= 70.0 + 1e-9
    g = (np.arange(round(2 * EDGE_RADIUS / dx)) + 0.5) * dx              # the sharp wedge's corner lattice
    gu, gw = np.meshgrid(g, g, indexing="ij")
    sharp = np.count_nonzero(np.degrees(np.arctan2(gw, gu)) <= 70.0)
    rounded = np.count_nonzero((u < 2 * EDGE_RADIUS) & (w < 2 * EDGE_RADIUS))
    assert 0 < rounded < sharp
    assert held.any() and not held[first & (u < tu)].any()


def test_scene_options_and_refusals():
    scene = get_scene("thermal_cutting")
    s = scene.setup(case=13, length=0.6e-3, travel=2.0)
    assert s.info["material"] == "Ti6Al4V" and s.info["vc_m_s"] == pytest.approx(40 / 60)
    assert s.info["tu_m"] == pytest.approx(0.1e-3) and s.dp == pytest.approx(0.1e-3 / 5)
    assert s.friction is not None and s.thermal is not None and s.numerics.kernel == "wendland"
    assert scene.setup(material="AISI1045", vc=2.0, tu=0.15e-3, conduction=False, friction=False).thermal is None
    assert s.numerics.contact == "penalty" and s.dissipation_heat and s.thermal.loss.refresh > 0
    big = scene.setup(case=13, length=0.6e-3, travel=2.0, tool_length=10.0, tool_depth=6.0)
    assert big.info["n_tool"] > 3 * s.info["n_tool"] and big.info["tool_length_m"] == pytest.approx(1e-3)
    shaken = scene.setup(case=13, length=0.6e-3, travel=2.0, jitter=0.01, seed=2)
    moved = np.abs(shaken.state.x[:s.info["n_work"]] - s.state.x[:s.info["n_work"]])
    assert 0 < moved.max() <= 0.01 * s.dp and np.array_equal(shaken.state.x[s.info["n_work"]:],
                                                                s.state.x[s.info["n_work"]:])
    with pytest.raises(ValueError, match="jitter"):
        scene.setup(case=13, jitter=0.5)
    with pytest.raises(ValueError, match="material"):
        scene.setup(material="copper")
    for bad in (19, -1, 2.5):
        with pytest.raises(ValueError, match="option case must be a whole number 0-18"):
            scene.setup(case=bad)
    with pytest.raises(ValueError, match="dissipation_heat=false"):   # ESPH has the friction, not the viscous heat
        run("thermal_cutting", "esph", quick=True, progress=False, options=dict(length=0.6e-3, travel=1.0))


def test_metrics_flag_a_temperature_blow_up_and_the_sweep_does_not_count_it(monkeypatch, tmp_path):
    """thermal_cutting_metrics: a particle hotter than BLOW_UP times T_melt adds 'blow_up' (when, and why the numbers
    after it mean nothing), a sane run has no such key (its metrics as before); the sweep records such a run as
    'blow-up', not 'ok'."""
    import importlib.util
    from pathlib import Path
    from types import SimpleNamespace

    from refsph.scenes.thermal_cutting import BLOW_UP, MATERIALS, thermal_cutting_metrics
    t = np.linspace(0.0, 1e-3, 41)
    T_melt = MATERIALS["AISI1045"]["T_melt_K"]
    hist = dict(t=t, T_RF=600 + 0 * t, T_RF_max=650 + 0 * t, T_FCS=500 + 0 * t, chip_mm=0.3 + 0 * t,
                contact_mm=0.3 + 0 * t, max_T=700 + 0 * t, max_eps_p=2 + 0 * t,
                reaction=dict(t=t, dt=np.full(41, 2.5e-5), tool=np.tile([4e5, 1.7e5], (41, 1))))
    info = dict(vc_m_s=1.0, mass_scale=100.0, inertia_ratio=0.01, material="AISI1045")
    assert "blow_up" not in thermal_cutting_metrics(hist, info, 1e-3)
    hist["max_T"] = np.where(t > 0.8e-3, 1.01 * BLOW_UP * T_melt, 700.0)
    m = thermal_cutting_metrics(hist, info, 1e-3)
    assert "blow_up" in m and f"t = {t[t > 0.8e-3][0]:.4e} s" in m["blow_up"]
    spec = importlib.util.spec_from_file_location(
        "bench_tc", Path(__file__).resolve().parent.parent / "benchmarks" / "thermal_cutting.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    import refsph.simulate
    for metrics, status in ((dict(m), "blow-up"), ({k: v for k, v in m.items() if k != "blow_up"}, "ok")):
        summary = dict(status="ok", metrics=metrics, n_particles=10, n_steps=41, wall_time_s=1.0, dp=1e-5,
                       scene_info={}, heat_balance={})
        monkeypatch.setattr(refsph.simulate, "run", lambda *a, **k: SimpleNamespace(summary=summary))
        monkeypatch.setattr(mod, "RUNS", tmp_path)
        rec = mod.run_case("case 1", dict(case=1), {})
        assert rec["status"] == status and (status == "ok" or rec["error"].startswith("a particle at"))


def test_the_dissipation_heat_is_split_into_contact_damping_and_viscosity(short_cut):
    """The ledger's 'dissipation' is the artificial viscosity's heat plus the penalty contact's damping; the summary
    gives the two apart (summing to it), and the damping's part is what the contact's damping power makes over the
    run: zero without damping (penalty_damping 0: the normal force is the spring's alone)."""
    hb, hd = short_cut.summary["heat_balance"], short_cut.summary["heat_dissipation"]
    assert hd["contact_damping_J"] > 0 and hd["viscosity_J"] > 0
    assert hd["contact_damping_J"] + hd["viscosity_J"] == pytest.approx(hb["dissipation_J"], rel=1e-12)
    undamped = run("thermal_cutting", "tlsph", quick=True, progress=False,
                   options=dict(case=1, length=0.5e-3, travel=0.25), numerics=dict(threads=1, penalty_damping=0.0))
    assert undamped.summary["heat_dissipation"]["contact_damping_J"] == 0.0
    assert undamped.summary["heat_dissipation"]["viscosity_J"] > 0


@pytest.mark.parametrize("every", [1, 3])
def test_the_contact_damping_heat_is_the_time_integral_of_its_power(monkeypatch, every):
    """summary.heat_dissipation.contact_damping_J = sum over the steps of dt x the contact's damping power (summed over
    the particles) at the step's last force evaluation (the scene's leapfrog evaluates the forces once a step, at its
    end, and twice in the first, before any contact; the last evaluation's rates make the step's heat; so this checks
    dt, the sum and the kept heat's bookkeeping, not which evaluation), integrated here from the contact's
    own results: recorded at every evaluation of the tool contact
    (PenaltyCoupling.with_tools) and cut into steps by a hook. With the heat step every 3 mechanical steps the
    ledger books the kept heat when it is applied, so the steps after the last heat step are left out."""
    from refsph.coupling import PenaltyCoupling
    calls, steps = [], []
    real = PenaltyCoupling.with_tools

    def recording(self, state, n, dt):
        c = real(self, state, n, dt)
        calls.append(float(c.heat_power_a.sum()))
        return c

    def hook(state, solver):
        steps.append((float(state.t), list(calls)))
        calls.clear()

    monkeypatch.setattr(PenaltyCoupling, "with_tools", recording)
    from refsph.simulate import build, simulate
    b = build("thermal_cutting", "tlsph", quick=True, options=dict(case=1, length=0.5e-3, travel=0.25),
              numerics=dict(threads=1, heat_every=every))
    res = simulate(b.setup, "tlsph", scene=b.scene, metrics=b.metrics, hook=hook, progress=False)
    t = np.array([0.0] + [s[0] for s in steps])
    assert b.setup.numerics.integrator == "leapfrog" and all(len(s[1]) >= 1 for s in steps)
    power = np.array([s[1][-1] for s in steps])
    n_booked = len(steps) - len(steps) % every
    integral = float(np.sum(np.diff(t)[:n_booked] * power[:n_booked]))
    booked = res.summary["heat_dissipation"]["contact_damping_J"]
    assert integral > 0 and booked == pytest.approx(integral, rel=1e-9)


def test_side_by_side_table_names_the_method_and_the_measurement_of_a_case0_run():
    """refsph run thermal_cutting --method both: each row names its method, spacing and length of cut; a case-0 run
    at case 1's material, v_c and t_u (the SPH scene's defaults) shows case 1's measurement, marked; one at
    conditions of no case shows none."""
    from refsph.scenes.thermal_cutting import thermal_cutting_table
    m = dict(cutting_force_N_per_m=3.0e5, passive_force_N_per_m=1.2e5, force_ratio=0.4, cut_length_mm=0.8)
    sph = dict(method="tlsph", status="ok", dp=25e-6, metrics=m,
               scene_info=dict(case=0, material="AISI1045", vc_m_s=1.0, tu_m=1e-4))
    other = dict(sph, scene_info=dict(case=0, material="AISI1045", vc_m_s=1.5, tu_m=1e-4))
    pfem = dict(sph, method="pfem", dp=20e-6, scene_info=dict(case=1, material="AISI1045", vc_m_s=1.0, tu_m=1e-4),
                metrics=dict(m, measured=dict(force_ratio=489 / 622, T_RF_K=668.0, T_FCS_K=647.0)))
    lines = thermal_cutting_table([sph, pfem, other]).splitlines()
    assert lines[1].split()[:2] == ["1*", "tlsph"] and lines[2].split()[:2] == ["1", "pfem"]
    for k in (1, 2):                                   # the measured ratio, 668 K and 647 K on both rows
        cells = lines[k].split()
        assert cells[9] == "0.79" and cells[11] == "668" and cells[13] == "647"
    assert lines[1].split()[-3:-1] == ["25.0", "0.80"] and lines[2].split()[-3] == "20.0"
    assert lines[3].split()[0] == "0" and lines[3].split()[9] == "-" and "*: case 0" in lines[-1]


def test_conductivity_factor_scales_the_workpiece_s_k_only():
    """Option conductivity_factor (a sensitivity study): the workpiece's k of Table A1 times the factor in both
    methods' heat models, the tool's k unchanged, the factor in scene_info / info; refused unless positive."""
    from refsph.pfem.cutting import pfem_cut
    from refsph.scenes.thermal_cutting import MATERIALS
    from refsph.simulate import build
    k = MATERIALS["Ti6Al4V"]["k_W_mK"]
    opts = dict(case=10, length=0.6e-3, travel=1.0)
    base = build("thermal_cutting", "tlsph", quick=True, options=opts).setup
    b = build("thermal_cutting", "tlsph", quick=True, options=dict(opts, conductivity_factor=2.0)).setup
    assert base.thermal.k == k and b.thermal.k == pytest.approx(2 * k)
    assert b.thermal.tools == base.thermal.tools and b.info["conductivity_factor"] == 2.0
    with pytest.raises(ValueError, match="conductivity_factor"):
        build("thermal_cutting", "tlsph", quick=True, options=dict(opts, conductivity_factor=0.0))
    cut = pfem_cut(10, n_tu=3.0, travel=1.0, length=0.6e-3, conductivity_factor=2.0)
    plain = pfem_cut(10, n_tu=3.0, travel=1.0, length=0.6e-3)
    assert cut.heat.k_work == pytest.approx(2 * k) and plain.heat.k_work == k
    assert cut.heat.k_tool == plain.heat.k_tool and cut.info["conductivity_factor"] == 2.0
    k_t = cut.heat.k_tool                                  # the chip-tool conductance follows the workpiece's k
    assert cut.heat.h_int / plain.heat.h_int == pytest.approx((2 * k / (2 * k + k_t)) / (k / (k + k_t)))
    assert "conductivity_factor" not in plain.info
    with pytest.raises(ValueError, match="conductivity_factor"):
        pfem_cut(10, n_tu=3.0, travel=1.0, length=0.6e-3, conductivity_factor=-1.0)
    for bad in (lambda: pfem_cut(10, n_tu=3.0, travel=1.0, length=0.6e-3, conduction=False, conductivity_factor=2.0),
                lambda: build("thermal_cutting", "tlsph", quick=True,
                              options=dict(opts, conduction=False, conductivity_factor=2.0))):
        with pytest.raises(ValueError, match="conductivity_factor"):
            bad()
