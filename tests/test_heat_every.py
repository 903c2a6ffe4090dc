"""The heat step once every few mechanical steps (``Numerics.heat_every``, :class:`refsph.thermal.HeatFlow`): the
kept heat is the heat made, the temperatures follow the every-step heat flow to the split's error, a checkpoint
taken between heat steps continues to the same bits, and a bad value is refused by name. And the penalty coupling's
nearest tool particle (the friction heat's other side), found without a k-d tree a step, is the k-d tree's."""
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial import cKDTree

from refsph.boundaries import RigidBody
from refsph.coupling import PenaltyCoupling
from refsph.integrate import Step
from refsph.kernels import get_kernel
from refsph.penalty import PenaltyContact, RoundedPolygon
from refsph.scenes.base import Numerics
from refsph.state import Rates, make_state
from refsph.thermal import Conduction, FrictionHeat, HeatFlow

DX, H, DT = 1e-5, 1.3e-5, 4e-10          # the heat step's stable step here: 0.3 rho c h^2 / k = 4.0e-9 s


def _state():
    g = np.stack(np.meshgrid(np.arange(12), np.arange(12)), -1).reshape(-1, 2) * DX
    state = make_state(g, [0.0, 0.0], 7800.0, DX * DX, T0=293.0)
    state.T = 293.0 + 400.0 * np.exp(-((g[:, 0] - 6 * DX) ** 2 + (g[:, 1] - 6 * DX) ** 2) / (3 * DX) ** 2)
    return state


def _flow(every: int, state) -> HeatFlow:
    flow = HeatFlow(Conduction(k=50.0, courant=0.3), FrictionHeat(eta=1.0, chip_fraction=1.0), 500.0, 0.0, H,
                    get_kernel("wendland"), every=every, dissipation_heat=True)
    flow.bind(state, SimpleNamespace(evolved=()))
    return flow


def _steps(flow: HeatFlow, state, n: int, t_list=None):
    """n steps of the heat flow on a body at rest, a friction power on one row changing from step to step."""
    z2, z = np.zeros((state.n, 2)), np.zeros(state.n)
    for i in range(n):
        power = np.zeros(state.n)
        power[30] = 1e3 * (1 + i % 3)                              # [W/m], changing from step to step
        diss, damping = 0.5 * power[::-1].copy(), 0.1 * power                # dissipation, of which damping
        rates = Rates(x=z2, v=z2, rho=None, S=np.zeros((state.n, 2, 2)), S_zz=z, friction_power=power,
                      heat_power=diss, damping_power=damping)
        after = state.copy()
        after.t = state.t + DT
        state = flow.advance(state, Step(after, rates), DT)
        if t_list is not None:
            t_list.append(state.T.copy())
    return state


def test_the_heat_kept_is_the_heat_made_and_the_temperatures_follow_every_step():
    every = 4
    one, kept = _flow(1, _state()), _flow(every, _state())
    seen: list = []
    a = _steps(one, _state(), 4 * every)
    b = _steps(kept, _state(), 4 * every, seen)
    T0 = _state().T
    for k, T in enumerate(seen):                   # between heat steps T stays as the last one left it
        assert np.array_equal(T, seen[k - 1] if k else T0) == ((k + 1) % every != 0)
    for key in ("friction", "dissipation"):                        # the heat kept is the heat made
        assert kept.ledger[key] == pytest.approx(one.ledger[key], rel=1e-12) and one.ledger[key] > 0
    assert kept.damping == pytest.approx(one.damping, rel=1e-12) and one.damping > 0
    assert abs(kept.balance(b)["residual_rel"]) < 1e-9               # (the every-step flow: the same round-off)
    change = np.abs(a.T - T0).max()
    assert change > 0.1                                            # the heat flowed (K)
    assert np.abs(b.T - a.T).max() < 1e-3 * change                 # the split's error (6e-5 of it here)
    assert kept.step_limit(b) == pytest.approx(one.step_limit(a) / every, rel=1e-14)


def test_a_checkpoint_between_heat_steps_continues_to_the_same_bits():
    every = 4
    whole = _flow(every, _state())
    s = _steps(whole, _state(), 6)                                 # 2 steps kept since the last heat step
    ck = whole.checkpoint()
    assert int(ck["pending_steps"]) == 2                           # (KeptHeat.checkpoint)
    again = _flow(every, _state())
    again.restore({k: np.asarray(v) for k, v in ck.items()})
    a = _steps(whole, s.copy(), 7)
    b = _steps(again, s.copy(), 7)
    assert np.array_equal(a.T, b.T) and whole.ledger == again.ledger


@pytest.mark.parametrize("bad", [0, -1, 1.5, True, "2"])
def test_heat_every_is_a_whole_number_of_steps(bad):
    with pytest.raises(ValueError, match="heat_every"):
        Numerics(heat_every=bad)


def test_the_nearest_tool_particle_is_the_k_d_trees():
    rng = np.random.default_rng(3)
    g = np.stack(np.meshgrid(np.arange(40), np.arange(25)), -1).reshape(-1, 2) * DX
    xb = g + rng.normal(0.0, 1e-3 * DX, g.shape)                   # a tool's particles, not a perfect lattice
    shape = RoundedPolygon(np.array([[-19.5, -12.0], [19.5, -12.0], [19.5, 12.0], [-19.5, 12.0]]) * DX, 0.0)
    coupling = PenaltyCoupling(PenaltyContact(alpha=0.1, damping=0.5, offset=0.5 * DX, time_scale=1e-9,
                                              friction=None), (RigidBody("tool", 1, (-1.0, 0.0), shape=shape),))
    for step in range(3):                                          # the tool moves: the tree is kept
        move = np.array([-0.37 * DX * step, 0.0])
        points = rng.uniform(-2 * DX, 41 * DX, (200, 2)) + move
        now = xb + move
        got = coupling.nearest_rows(0, now, now.mean(axis=0), points)
        assert np.array_equal(got, cKDTree(now).query(points)[1])
    turned = (xb - xb.mean(axis=0)) @ np.array([[np.cos(0.2), -np.sin(0.2)], [np.sin(0.2), np.cos(0.2)]])
    got = coupling.nearest_rows(0, turned, turned.mean(axis=0), points)   # moved in its own frame: built anew
    assert np.array_equal(got, cKDTree(turned).query(points)[1])
