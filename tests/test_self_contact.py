"""Self-contact of a TLSPH body (refsph.self_contact): the pair force against its formula, only below r_c, only
within one body, momentum conserved; off by default (the golden cases hold that); refused for ESPH; and on a
crowded pair in a TLSPH run it pushes the pair apart where the run without it lets the pair stay."""
import dataclasses

import numpy as np
import pytest

from refsph.self_contact import reduced_modulus, self_contact_forces
from refsph.scenes.base import Numerics


def test_pair_force_matches_the_formula_in_2d_and_3d():
    E_star, r_c = 2.0e11, 5e-6
    for dim in (2, 3):
        x = np.zeros((2, dim))
        x[1, 0] = 0.7 * r_c
        f = self_contact_forces(x, None, r_c, E_star)
        delta = 0.3 * r_c
        size = E_star * delta if dim == 2 else (4 / 3) * E_star * np.sqrt(r_c / 4) * delta ** 1.5
        np.testing.assert_allclose(f[0], -size * np.eye(dim)[0], rtol=1e-12)   # pushed away from particle 1
        np.testing.assert_allclose(f[1], size * np.eye(dim)[0], rtol=1e-12)


def test_only_closer_than_r_c_and_within_one_body():
    x = np.array([[0.0, 0.0], [1.01, 0.0], [0.0, 0.5], [5.0, 5.0], [5.2, 5.0]])
    f = self_contact_forces(x, np.array([0, 0, 0, 1, 2]), 1.0, 1.0)
    assert np.all(f[1] == 0.0)                  # 1.01 > r_c: no force
    assert f[0, 1] < 0.0 < f[2, 1]              # 0.5 apart, one body: pushed apart along y
    assert np.all(f[3:] == 0.0)                 # 0.2 apart, two bodies: the contact model's business


def test_momentum_is_conserved_and_a_coincident_pair_is_left_alone():
    rng = np.random.default_rng(3)
    x = rng.random((400, 2))
    f = self_contact_forces(x, None, 0.05, 7.0)
    assert np.abs(f).max() > 0.0
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-12 * np.abs(f).max())
    g = self_contact_forces(np.zeros((2, 2)), None, 0.05, 7.0)
    assert np.all(g == 0.0)                     # no direction to push: no force (not NaN)


def test_reduced_modulus():
    assert reduced_modulus(2.0e11, 0.3) == pytest.approx(2.0e11 / (2 * 0.91))


def test_numerics_checks_and_esph_refuses():
    assert Numerics().self_contact is None
    for bad in (0.0, -0.5, 1.5, float("nan")):
        with pytest.raises(ValueError, match="self_contact"):
            Numerics(self_contact=bad)
    from refsph.scenes import get_scene
    from refsph.simulate import make_solver
    setup = get_scene("taylor").setup(2, None, True)
    setup.numerics = dataclasses.replace(setup.numerics, self_contact=0.5)
    with pytest.raises(ValueError, match="self_contact is a TLSPH option"):
        make_solver("esph", setup)


def test_a_crowded_pair_is_pushed_apart_in_a_tlsph_run():
    """A free square block whose two middle particles start 0.2 dp apart (the reference configuration itself, so
    TLSPH sees no strain there): without self-contact they stay crowded, with it they part to about r_c."""
    from refsph.material import ElasticMaterial
    from refsph.scenes.base import Setup
    from refsph.simulate import simulate
    from refsph.state import make_state
    dp = 1e-4
    g = np.arange(8) * dp
    x = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    a, b = 3 * 8 + 3, 3 * 8 + 4
    x[a, 0] += 0.4 * dp
    x[b, 0] -= 0.4 * dp
    mat = ElasticMaterial(rho0=7800.0, E=2.0e11, nu=0.3)
    gaps = {}
    for sc in (None, 0.5):
        state = make_state(x, [0.0, 0.0], mat.rho0, dp * dp)
        setup = Setup(state=state, material=mat, dp=dp, t_end=40 * dp / mat.c_longitudinal, n_snapshots=1,
                      numerics=Numerics(self_contact=sc, threads=1, ref_update_strain=None))
        res = simulate(setup, "tlsph", progress=False)
        gaps[sc] = np.linalg.norm(res.state.x[a] - res.state.x[b]) / dp
    assert gaps[None] < 0.3
    assert gaps[0.5] > 0.4


def _bench():
    import importlib.util
    from pathlib import Path
    spec = importlib.util.spec_from_file_location(
        "bench_tc_sc", Path(__file__).resolve().parent.parent / "benchmarks" / "thermal_cutting.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_sweeps_crowding_measure_and_self_contact_study():
    """benchmarks/thermal_cutting.py: ``crowding`` counts the workpiece's particles with a neighbour closer than
    dp/2 (the tool's left out); every run of the 'selfcontact' study but the reruns has self_contact set, and each
    rerun has the options and numerics of the record it repeats."""
    from types import SimpleNamespace

    from refsph.scenes.measure import TOOL_BODY
    mod = _bench()
    dp = 1e-5
    g = np.arange(4) * dp
    x = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    x[5] = x[4] + [0.3 * dp, 0.0]                   # one crowded pair in the workpiece
    body = np.zeros(16, dtype=int)
    body[-2:] = TOOL_BODY
    x[-1] = x[-2] + [0.1 * dp, 0.0]                 # a closer pair in the tool: not counted
    c = mod.crowding(SimpleNamespace(x=x, body=body), dp)
    assert c["fraction_below_half_dp"] == pytest.approx(2 / 14)
    assert c["min_distance_dp"] == pytest.approx(0.3)
    jobs = mod.self_contact_jobs()
    for key, (options, numerics) in jobs.items():
        if key.endswith(mod.RERUN):
            assert mod.jobs()[key[:-len(mod.RERUN)]] == (options, numerics)
        else:
            assert numerics["self_contact"] == mod.SELF_CONTACT and mod.SELF_KEY in key


def test_the_sweeps_failure_site(tmp_path):
    """benchmarks/thermal_cutting.py's ``failure_site``: the hottest workpiece particle of a last good state (the
    tool's left out), with its reference and current neighbours within the support and its nearest neighbour."""
    from refsph.scenes.measure import TOOL_BODY
    mod = _bench()
    dp = 1e-5
    g = np.arange(5) * dp
    X = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    x = X.copy()
    x[24] += [3 * dp, 0.0]                          # the corner particle, torn off
    T = np.full(25, 300.0)
    T[24] = 5000.0
    body = np.zeros(25, dtype=int)
    xt = np.array([[9 * dp, 4 * dp]])               # a tool particle next to it, hotter still: not counted
    np.savez(tmp_path / "last_good.npz", x=np.vstack([x, xt]), X=np.vstack([X, xt]), T=np.append(T, 9000.0),
             v=np.zeros((26, 2)), body=np.append(body, TOOL_BODY))
    site = mod.failure_site(tmp_path / "last_good.npz", dp, 1.5 * dp)
    assert site["particle"] == 24 and site["T_K"] == 5000.0
    assert site["reference_neighbours"] == 3         # (3, 4), (4, 3), (3, 3) within 1.5 dp of (4, 4)
    assert site["current_neighbours"] == 0
    assert site["nearest_dp"] == pytest.approx(np.sqrt(10.0))     # (4, 3) from (7, 4)


def test_the_half_step_groups_mean_errors():
    """_group_errors: mean |error| against the measurements (refsph.paper_data, through ``comparison``) of the
    cases recorded 'ok' in both the half-step group and the 'coarse' table, per material; a case recorded in only one
    of them is left out."""
    from refsph.paper_data import rla_cutting_case
    mod = _bench()
    c = rla_cutting_case(1)                          # AISI 1045
    ratio = c["Fp_exp_N"] / c["Fc_exp_N"]

    def rec(f_T, status="ok"):
        return dict(status=status, metrics=dict(rake_face_temperature_K=f_T * c["TRF_exp_K"],
                                                free_chip_surface_temperature_K=1.1 * c["TFCS_exp_K"],
                                                force_ratio=0.5 * ratio, cutting_force_N_per_m=4e5,
                                                passive_force_N_per_m=2e5 * ratio))
    runs = {"case 1 n_tu 5": rec(1.1), f"case 1 n_tu 5{mod.HALF_STEP}": rec(0.9),
            "case 2 n_tu 5": rec(1.5), f"case 2 n_tu 5{mod.HALF_STEP}": rec(1.5, status="blow-up")}
    line = mod._group_errors(dict(runs=runs))
    assert "AISI1045 (1 cases): T_RF 10.0 % (before 10.0 %), T_FCS 10.0 % (10.0 %), Fp/Fc 50.0 % (50.0 %)" in line
    assert "Ti6Al4V" not in line and "the 'coarse' table's" in line
    # the 'refined' group (t_u/10 at reference update 0.1) against the t_u/10 table, the same way
    line = mod._group_errors(dict(runs={"case 1": rec(1.1), f"case 1{mod.REFINED}": rec(0.8)}), mod.REFINED, "",
                                 "the t_u/10")
    assert "AISI1045 (1 cases): T_RF 20.0 % (before 10.0 %)" in line and "the t_u/10 table's" in line
