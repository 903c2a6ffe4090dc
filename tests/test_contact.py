"""Rigid bodies, clamps and the pinball contact (Eqs. 32-36): formulas, balance laws, a bouncing disc."""
import dataclasses

import numpy as np
import pytest

from refsph.boundaries import Clamp, MirrorPlanes, RigidBody
from refsph.contact import (CoulombFriction, PinballContact, hertz_force, penetration, pinball_contact,
                            pinball_force, rate_force, reduced)
from refsph.esph import ESPHParams
from refsph.solvers import ESPHSolver, TLSPHSolver
from refsph.io import load_reactions
from refsph.kernels import get_kernel
from refsph.scenes import aisi4340_material, Numerics, Setup, lattice
from refsph.simulate import simulate
from refsph.state import concatenate_states, make_state
from refsph.tlsph import TLSPHParams

MAT = aisi4340_material()


# ----------------------------------------------------------------------------- formulas
def test_reduced_with_rigid_partner():
    assert reduced(2.0, 2.0) == pytest.approx(1.0)
    assert reduced(3.0, np.inf) == 3.0


def test_pinball_formulas_one_pair():
    R, r, m, G, dt = 1e-6, 1.8e-6, 2e-7, 80e9, 1e-10
    p_d = penetration(R, R, r)
    assert p_d == pytest.approx(0.2e-6)
    F1 = rate_force(m, np.array([10.0, -10.0]), dt)
    assert F1[0] == pytest.approx(m * 10.0 / dt) and F1[1] == 0.0          # Eq. (34): zero while separating
    F2 = hertz_force(G, R, R, p_d, thickness=2.0)
    assert F2 == pytest.approx(G * np.sqrt(R / 2) * p_d**1.5 / 2.0)        # Eq. (35)
    F = pinball_force(np.array([p_d, -p_d]), np.array([10.0, 10.0]), m, G, R, R, dt, 3.0)
    assert F[0] == pytest.approx(3.0 * min(m * 10.0 / dt, G * np.sqrt(R / 2) * p_d**1.5))   # Eq. (33)
    assert F[1] == 0.0                                                       # no penetration, no force


def _random_contact(seed, friction=None):
    rng = np.random.default_rng(seed)
    dp = 1e-5
    xa = rng.uniform(0, 5 * dp, size=(40, 2))
    xb = rng.uniform(2 * dp, 7 * dp, size=(30, 2))
    va, vb = rng.normal(0, 50, size=(40, 2)), np.tile([-20.0, 5.0], (30, 1))
    ma = rng.uniform(0.5, 1.5, 40) * 7830 * dp * dp
    c = PinballContact(k=1 / 3, K_p=2.0, friction=friction)
    T = rng.uniform(300, 900, 40)
    return pinball_contact(xa, va, ma, xb, vb, np.inf, 0.5 * dp, 80e9, np.inf, 1e-10, c, thickness=dp, T_a=T), ma


@pytest.mark.parametrize("friction", [None, CoulombFriction(mu0=0.5, q=2.0, T_room=293.0, T_melt=1773.0)])
def test_pinball_equal_and_opposite(friction):
    res, ma = _random_contact(1, friction)
    assert res.n_contacts > 5
    total_a = np.sum(ma[:, None] * res.a, axis=0)
    total_b = np.sum(res.force_on_b, axis=0)
    scale = np.sum(np.abs(ma[:, None] * res.a))
    assert np.allclose(total_a + total_b, 0.0, atol=1e-12 * scale)


def test_pinball_without_friction_is_along_line_of_centres():
    """One pair: the force on a is parallel to x_a - x_b and pushes a away."""
    c = PinballContact(k=0.5, K_p=1.0)
    xa, xb = np.array([[0.0, 0.0]]), np.array([[0.6e-5, 0.8e-5]])
    res = pinball_contact(xa, np.array([[100.0, 100.0]]), np.array([1e-6]), xb, np.zeros((1, 2)), np.inf,
                          0.75e-5, 80e9, np.inf, 1e-10, c, thickness=1e-5)
    f = res.a[0] * 1e-6
    e = (xa - xb)[0] / np.linalg.norm(xa - xb)
    assert np.linalg.norm(f) > 0
    assert abs(f[0] * e[1] - f[1] * e[0]) < 1e-12 * np.linalg.norm(f)
    assert f @ e > 0
    assert res.max_penetration == pytest.approx(1.5e-5 - 1e-5)


def test_friction_coefficient_and_cap():
    fr = CoulombFriction(mu0=0.81, q=2.09, T_room=293.0, T_melt=1773.0)
    assert fr.mu(293.0) == pytest.approx(0.81)
    assert fr.mu(1773.0) == pytest.approx(0.0)
    assert fr.mu(1033.0) == pytest.approx(0.81 * (1 - 0.5**2.09))
    with pytest.raises(ValueError):
        CoulombFriction(mu0=-1.0, q=1.0, T_room=293.0, T_melt=1000.0)
    # sliding pair: tangential force <= mu * normal force, and against the sliding
    c = PinballContact(k=0.5, K_p=1.0, friction=fr)
    xa, xb = np.array([[0.0, 0.0]]), np.array([[0.0, 0.9e-5]])
    va = np.array([[30.0, 1.0]])
    res = pinball_contact(xa, va, np.array([1e-6]), xb, np.zeros((1, 2)), np.inf, 0.5e-5, 80e9, np.inf, 1e-10, c,
                          thickness=1e-5, T_a=np.array([293.0]))
    f = res.a[0] * 1e-6
    assert f[1] < 0                                  # normal: pushes a away from b (b is above)
    assert f[0] < 0                                  # tangential: against the sliding (+x)
    assert abs(f[0]) <= 0.81 * abs(f[1]) * (1 + 1e-12)


def test_contact_parameters_validated():
    with pytest.raises(ValueError, match="radius factor k"):
        PinballContact(k=0.0, K_p=1.0)
    with pytest.raises(ValueError, match="K_p"):
        PinballContact(k=0.3, K_p=-1.0)
    with pytest.raises(ValueError, match="rigid body id"):
        RigidBody("tool", 0, (1.0, 0.0))
    with pytest.raises(ValueError, match="non-empty"):
        Clamp("left", np.array([], dtype=int))


# ----------------------------------------------------------------------------- a disc bouncing off a wall of particles
DP = 0.25e-3


def _disc_on_wall(v0=100.0, radius=2.5e-3, layers=3):
    x = lattice([2 * radius, 2 * radius], DP)
    x = x[np.sum((x - radius) ** 2, axis=1) < radius**2]
    x[:, 0] += 0.5 * DP                                           # disc face one half spacing from the wall face
    disc = make_state(x, [-v0, 0.0], MAT.rho0, DP * DP)
    wy = np.arange(-4 * DP, 2 * radius + 4 * DP, DP) + 0.5 * DP
    wx = -(np.arange(layers) + 0.5) * DP
    W = np.stack(np.meshgrid(wx, wy, indexing="ij"), axis=-1).reshape(-1, 2)
    wall = make_state(W, [0.0, 0.0], MAT.rho0, DP * DP, body=np.ones(len(W), dtype=int))
    state = concatenate_states(disc, wall)
    t_end = 2.5 * (8 * radius / MAT.c_longitudinal + 4 * DP / v0)
    return Setup(state=state, material=MAT, dp=DP, numerics=Numerics(beta1=0.5, beta2=0.5), t_end=t_end,
                 n_snapshots=2, rigid=(RigidBody("wall", 1, (0.0, 0.0)),)), disc.n


@pytest.fixture(scope="module", params=["esph", "tlsph"])
def bounce(request, tmp_path_factory):
    setup, n = _disc_on_wall()
    out = tmp_path_factory.mktemp(f"bounce_{request.param}")
    return request.param, setup, n, simulate(setup, request.param, progress=False, out=out), out


def test_bounce_impulse_equals_momentum_change(bounce):
    method, setup, n, res, _ = bounce
    P0 = np.sum(setup.state.m[:n, None] * setup.state.v[:n], axis=0)
    P1 = np.sum(res.state.m[:n, None] * res.state.v[:n], axis=0)
    imp = np.array(res.summary["diagnostics"]["reaction_impulse"]["wall"])
    assert np.allclose(P1 - P0, -imp, rtol=0, atol=1e-10 * abs(P0[0]))
    # one row per step, at the step's midpoint
    t_mid = res.history["reaction"]["t"]
    assert res.history["reaction"]["wall"].shape == (res.summary["n_steps"], 2)
    assert np.all(np.diff(t_mid) > 0) and 0 < t_mid[0] < t_mid[-1] < res.state.t


def test_bounce_rebounds_without_passing_through(bounce):
    method, setup, n, res, _ = bounce
    P0 = np.sum(setup.state.m[:n] * setup.state.v[:n, 0])
    P1 = np.sum(res.state.m[:n] * res.state.v[:n, 0])
    restitution = -P1 / P0
    assert 0.7 < restitution < 1.0, restitution                 # an elastic disc rebounds (vibrations keep some)
    assert np.all(res.state.x[:n, 0] > 0.0)                      # nothing behind the wall face
    wall = res.state.x[n:]
    assert np.allclose(wall, setup.state.x[n:])                  # the wall did not move
    if method == "tlsph":
        assert res.summary["diagnostics"]["max_pinball_penetration_m"] < 0.15 * DP


def test_bounce_reaction_file(bounce):
    method, setup, n, res, out = bounce
    back = load_reactions(out / "reaction_forces.csv")
    assert np.allclose(back["t"], res.history["reaction"]["t"])
    assert np.allclose(back["wall"], res.history["reaction"]["wall"], rtol=1e-8, atol=1e-6)


# ----------------------------------------------------------------------------- clamps and bad input
def test_clamp_holds_and_balances_momentum():
    """A bar clamped at its left column, pushed by a tool at the right: the clamped particles stay put, and
    the momentum of the free particles changes by minus the impulses on tool and clamp."""
    x = lattice([2e-3, 0.5e-3], DP)
    bar = make_state(x, [0.0, 0.0], MAT.rho0, DP * DP)
    ty = (np.arange(-2, 4) + 0.5) * DP
    tx = 2e-3 + (np.arange(3) + 0.5) * DP
    T = np.stack(np.meshgrid(tx, ty, indexing="ij"), axis=-1).reshape(-1, 2)
    tool = make_state(T, [-50.0, 0.0], MAT.rho0, DP * DP, body=np.full(len(T), 2))
    clamp = Clamp("left", np.flatnonzero(x[:, 0] < DP))
    setup = Setup(state=concatenate_states(bar, tool), material=MAT, dp=DP, numerics=Numerics(beta1=0.5, beta2=0.5),
                  t_end=1.5e-6, n_snapshots=1, rigid=(RigidBody("tool", 2, (-50.0, 0.0)),), clamps=(clamp,))
    for method in ("esph", "tlsph"):
        res = simulate(setup, method, progress=False)
        s, n = res.state, bar.n
        assert np.array_equal(s.x[clamp.index], x[clamp.index])
        P1 = np.sum(s.m[:n, None] * s.v[:n], axis=0)
        imp = res.summary["diagnostics"]["reaction_impulse"]
        total = np.array(imp["tool"]) + np.array(imp["left"])
        assert abs(imp["tool"][0]) > 0 and abs(imp["left"][0]) > 0
        assert np.allclose(P1, -total, atol=1e-9 * abs(imp["tool"][0])), method
        assert np.allclose(s.x[n:, 0] - T[:, 0], -50.0 * s.t)          # the tool moved exactly


def test_rigid_body_input_errors():
    setup, n = _disc_on_wall()
    kern = get_kernel("cubic")
    with pytest.raises(ValueError, match="contact"):
        TLSPHSolver(MAT, TLSPHParams(h=1.5 * DP, beta1=0.5, beta2=0.5, eps=0.01, kernel=kern, corrected=True,
                                     ref_update_strain=None), rigid=setup.rigid)
    with pytest.raises(ValueError, match="symmetry"):
        ESPHSolver(MAT, ESPHParams(h=1.5 * DP, dp=DP, beta1=0.5, beta2=0.5, gamma=0.0, n_ap=4, eps=0.01,
                                   kernel=kern), 0.1, rigid=setup.rigid, mirror=MirrorPlanes((1,)))
    # the rigid particles must be the last rows
    bad = dataclasses.replace(setup, state=concatenate_states(
        make_state(setup.state.x[n:], [0.0, 0.0], MAT.rho0, DP * DP, body=np.ones(setup.state.n - n, dtype=int)),
        make_state(setup.state.x[:n], [-1.0, 0.0], MAT.rho0, DP * DP)))
    with pytest.raises(ValueError, match="after every deformable"):
        simulate(bad, "esph", progress=False)
    # a rigid body id that no particle has
    none = dataclasses.replace(setup, rigid=(RigidBody("wall", 7, (0.0, 0.0)),))
    with pytest.raises(ValueError, match="no particle"):
        simulate(none, "tlsph", progress=False)
    # a velocity of the wrong dimension
    wrong = dataclasses.replace(setup, rigid=(RigidBody("wall", 1, (0.0, 0.0, 0.0)),))
    with pytest.raises(ValueError, match="components"):
        simulate(wrong, "esph", progress=False)


def test_friction_input_errors():
    setup, n = _disc_on_wall()
    fr = CoulombFriction(mu0=0.81, q=2.09, T_room=293.0, T_melt=1773.0)
    with pytest.raises(ValueError, match="ESPH"):
        simulate(dataclasses.replace(setup, friction=fr), "esph", progress=False)
    with pytest.raises(ValueError, match="temperature"):                  # the disc state has no T
        simulate(dataclasses.replace(setup, friction=fr), "tlsph", progress=False)


def test_bodies_input_errors():
    setup, n = _disc_on_wall()
    with pytest.raises(ValueError, match="non-negative"):
        Clamp("c", np.array([-1, 0, 1]))
    # body ids without a RigidBody are deformable bodies: TLSPH meets them by the pinball, ESPH warns
    two = dataclasses.replace(setup, rigid=(), t_end=2 * setup.t_end / 100)
    assert simulate(two, "tlsph", progress=False).summary["status"] == "ok"
    with pytest.warns(UserWarning, match="no contact between deformable bodies"):
        simulate(two, "esph", progress=False)
    with pytest.raises(ValueError, match="start with its velocity"):
        simulate(dataclasses.replace(setup, rigid=(RigidBody("wall", 1, (-5.0, 0.0)),)), "esph", progress=False)
    with pytest.raises(ValueError, match="distinct body ids"):
        simulate(dataclasses.replace(setup, rigid=(RigidBody("a", 1, (0.0, 0.0)), RigidBody("b", 1, (0.0, 0.0)))),
                 "esph", progress=False)
    with pytest.raises(ValueError, match="name"):
        simulate(dataclasses.replace(setup, rigid=(RigidBody("t", 1, (0.0, 0.0)),)), "esph", progress=False)
    from refsph.boundaries import RigidWall
    with pytest.raises(ValueError, match="RigidWall"):
        simulate(dataclasses.replace(setup, walls=(RigidWall(0, -1e-3, 0.5 * DP),)), "esph", progress=False)
    fr = CoulombFriction(mu0=0.5, q=2.0, T_room=293.0, T_melt=1773.0)
    with pytest.raises(ValueError, match="rigid"):
        simulate(dataclasses.replace(setup, rigid=(), state=make_state(setup.state.x[:n], setup.state.v[:n],
                                                                        MAT.rho0, DP * DP, T0=293.0),
                                     friction=fr), "tlsph", progress=False)
    with pytest.raises(ValueError, match="q"):
        CoulombFriction(mu0=0.5, q=0.0, T_room=293.0, T_melt=1773.0)


def test_esph_tool_density_floor_and_pressure():
    """ESPH tool particles: density integrated by Eq. (10) but never below rho0 (pressure >= 0); they did
    get compressed during the impact (the floor is not all they do)."""
    setup, n = _disc_on_wall()
    setup = dataclasses.replace(setup, t_end=0.5e-6)                 # stop during the contact (about 1.7 us)
    res = simulate(setup, "esph", progress=False)
    rho_tool = res.state.rho[n:]
    assert np.all(rho_tool >= MAT.rho0)
    assert rho_tool.max() > MAT.rho0 * (1 + 1e-4)


def test_tlsph_friction_run_balances_momentum():
    """A block sliding and pressing on a particle wall, TLSPH with friction: the wall's impulse equals the
    block's change of momentum, and the sliding slows down more than without friction."""
    x = lattice([2e-3, 1e-3], DP)                                      # faces touch: bottom row 1 dp above the wall
    wx = np.arange(-8 * DP, 4e-3, DP) + 0.5 * DP
    W = np.stack(np.meshgrid(wx, -(np.arange(2) + 0.5) * DP, indexing="ij"), axis=-1).reshape(-1, 2)
    out = {}
    for label, fr in (("free", None), ("friction", CoulombFriction(mu0=0.5, q=2.0, T_room=293.0, T_melt=1773.0))):
        block = make_state(x, [30.0, -20.0], MAT.rho0, DP * DP, T0=293.0)
        wall = make_state(W, [0.0, 0.0], MAT.rho0, DP * DP, T0=293.0, body=np.ones(len(W), dtype=int))
        setup = Setup(state=concatenate_states(block, wall), material=MAT, dp=DP,
                      numerics=Numerics(beta1=0.5, beta2=0.5), t_end=1.0e-6, n_snapshots=1,
                      rigid=(RigidBody("wall", 1, (0.0, 0.0)),), friction=fr)
        res = simulate(setup, "tlsph", progress=False)
        nb = block.n
        dP = np.sum(res.state.m[:nb, None] * (res.state.v[:nb] - block.v), axis=0)
        imp = np.array(res.summary["diagnostics"]["reaction_impulse"]["wall"])
        assert np.allclose(dP, -imp, atol=1e-10 * np.sum(block.m) * 30.0), label
        out[label] = np.sum(res.state.m[:nb] * res.state.v[:nb, 0]) / np.sum(block.m)
        if fr is not None:                                            # Coulomb: |tangential| <= mu |normal|
            assert 0 < imp[0] <= 1.05 * fr.mu0 * abs(imp[1])           # (5 %: the wall of particles is bumpy)
    assert out["friction"] < out["free"] - 5.0                        # friction slowed the sliding (30 -> 15 m/s)


def _cube_on_plate(method):
    dp = 0.5e-3
    cube = make_state(lattice([2.5e-3] * 3, dp) + np.array([1.5e-3, 1.5e-3, 0.0]), [0.0, 0.0, -100.0],
                      MAT.rho0, dp**3)
    g = (np.arange(-2, 13) + 0.5) * dp
    P = np.stack(np.meshgrid(g, g, -(np.arange(3) + 0.5) * dp, indexing="ij"), axis=-1).reshape(-1, 3)
    plate = make_state(P, [0.0, 0.0, 0.0], MAT.rho0, dp**3, body=np.ones(len(P), dtype=int))
    setup = Setup(state=concatenate_states(cube, plate), material=MAT, dp=dp,
                  numerics=Numerics(beta1=0.5, beta2=0.5), t_end=6e-6, n_snapshots=1,
                  rigid=(RigidBody("plate", 1, (0.0, 0.0, 0.0)),))
    return cube, simulate(setup, method, progress=False)


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_3d_cube_on_plate_balance(method):
    """3D: a cube (5^3 particles) thrown at a plate of 3 particle layers: nothing passes the plate, and the
    plate's impulse equals the cube's change of momentum."""
    cube, res = _cube_on_plate(method)
    n = cube.n
    dP = np.sum(res.state.m[:n, None] * (res.state.v[:n] - cube.v), axis=0)
    imp = np.array(res.summary["diagnostics"]["reaction_impulse"]["plate"])
    assert np.allclose(dP, -imp, atol=1e-10 * np.sum(cube.m) * 100.0)
    assert np.all(res.state.x[:n, 2] > 0.0)
    assert np.sum(res.state.m[:n] * res.state.v[:n, 2]) > -0.25 * np.sum(cube.m) * 100.0   # stopped, at least


@pytest.mark.parametrize("method", [
    pytest.param("esph", marks=pytest.mark.xfail(strict=True, reason=(
        "known limitation: the ESPH tool couples through Eq. (11), so the cube's bottom layer, in tension as it "
        "unloads (p = -0.7 GPa, sigma_zz = +2.2 GPa at 6 us), pulls on the plate and the cube sticks; its momentum "
        "decays from -100 to -4 m/s by 12 us without a rebound (the 2D disc does rebound)"))),
    "tlsph"])
def test_3d_cube_on_plate_rebounds(method):
    cube, res = _cube_on_plate(method)
    n = cube.n
    assert np.sum(res.state.m[:n] * res.state.v[:n, 2]) > 0.5 * np.sum(cube.m) * 100.0
