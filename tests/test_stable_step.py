"""refsph.tlsph.largest_frequency: the largest frequency of the linearised elastic TLSPH equations, and the
leapfrog's stability limit dt w_max < 2 that it predicts (benchmarks/stable_step.py reads the cut's blow-ups with
it). Checked against the dense operator (every column by a finite difference) and against refsph's own leapfrog:
stable for 400 steps at 0.97 of the critical step, failing within them at 1.03, on a lattice and on a torn tip.
And Numerics.frequency_step, the step held under a fraction of that critical step (refsph's option, off by
default)."""
import dataclasses

import numpy as np
import pytest

from refsph.material import ElasticMaterial
from refsph.scenes.base import Numerics, Setup
from refsph.scenes.measure import block_lattice
from refsph.simulate import SimulationError, make_solver, simulate
from refsph.state import make_state
from refsph.tlsph import gradient_gain, largest_frequency, tlsph_rates

DX = 1e-4
MAT = ElasticMaterial(rho0=7800.0, E=2.0e11, nu=0.3)


def _lattice(n=10):
    return block_lattice(n, n, DX, DX)[0]


def _torn_tip(n=10):
    X = _lattice(n)
    return np.vstack([X, X[-1] + [2.2 * DX, 0.3 * DX]])             # a straggler by two edge particles


def _setup(X, t_end=1.0, v0=1e-3):
    state = make_state(X, [0.0, 0.0], MAT.rho0, DX * DX)
    state.v[:] = v0 * np.random.default_rng(1).standard_normal(state.v.shape)
    return Setup(state=state, material=MAT, dp=DX, t_end=t_end, n_snapshots=1,
                 numerics=Numerics(threads=1, ref_update_strain=None, kernel="wendland", h_over_dp=1.3, beta1=0.0,
                                   beta2=0.0, integrator="leapfrog"))


def _frequency(X):
    setup = _setup(X)
    solver = make_solver("tlsph", setup)
    op = solver.reference.operator(setup.state, False)
    omega, mode = largest_frequency(setup.state, MAT, solver.params, op)
    return omega, mode, op, solver


def test_the_largest_frequency_is_the_dense_operators():
    """Every column of K by a finite difference of the rates: K is symmetric (to the differences' round-off), its
    eigenvalues real and >= 0 up to round-off, and the largest one is what ARPACK found (1e-4)."""
    X = _lattice(6)
    omega, _, op, solver = _frequency(X)
    body, prm = _setup(X, v0=0.0).state, dataclasses.replace(solver.params, beta1=0.0, beta2=0.0)
    n = len(X)
    a0 = tlsph_rates(body, MAT, prm, op, part="forces").v
    K = np.zeros((2 * n, 2 * n))
    for k in range(2 * n):
        u = np.zeros(2 * n)
        u[k] = 1.0
        u = u.reshape(n, 2)
        eps = 1e-8 * DX
        rate = tlsph_rates(dataclasses.replace(body, v=u), MAT, prm, op, part="deformation")
        moved = dataclasses.replace(body, x=body.x + eps * u, S=body.S + eps * rate.S, S_zz=body.S_zz + eps * rate.S_zz)
        K[:, k] = (a0 - tlsph_rates(moved, MAT, prm, op, part="forces").v).ravel() / eps
    assert np.abs(K - K.T).max() < 1e-5 * np.abs(K).max()
    ev = np.linalg.eigvalsh(0.5 * (K + K.T))
    assert ev.min() > -1e-6 * ev.max()
    assert omega**2 == pytest.approx(ev.max(), rel=1e-4)


@pytest.mark.parametrize("body", ["lattice", "torn tip"])
def test_the_leapfrog_is_stable_below_two_over_the_frequency_and_fails_above(body):
    """refsph's leapfrog (kick-drift-kick, the stress from the half-step velocity) with no artificial viscosity,
    from small random velocities: 400 steps at 0.97 of dt = 2 / w_max stay small, at 1.03 the run fails (an
    inverted particle) within 100 of them. The torn tip's gain raises w_max: its critical Courant number is
    lower, about 1 / gain."""
    X = _lattice() if body == "lattice" else _torn_tip()
    omega, mode, op, _ = _frequency(X)
    dt = 2.0 / omega
    c_crit = dt * MAT.c_longitudinal / (1.3 * DX)
    gain = gradient_gain(op).max()
    if body == "lattice":
        assert 1.0 < c_crit < 1.1 and gain < 1.0
    else:
        assert c_crit < 0.85 and 0.9 < c_crit * gain < 1.1
    res = simulate(_setup(X, t_end=400 * 0.97 * dt), "tlsph", dt=0.97 * dt, progress=False)
    assert res.summary["n_steps"] == 400 and np.abs(res.state.v).max() < 1e-2
    with pytest.raises(SimulationError, match="inverted particle") as failed:
        simulate(_setup(X, t_end=400 * 1.03 * dt), "tlsph", dt=1.03 * dt, progress=False)
    step = int(str(failed.value).split("step ")[1].split()[0])
    assert step < 100


def test_mirror_ghosts_are_refused():
    from refsph.tlsph import ReferenceOperator
    omega, _, op, solver = _frequency(_lattice(4))
    fake = ReferenceOperator(op.X, op.V, op.h, op.kernel, True)
    fake.ghosts = object()
    with pytest.raises(ValueError, match="mirror ghosts"):
        largest_frequency(_setup(_lattice(4)).state, MAT, solver.params, fake)


def test_frequency_step_holds_the_step_under_the_critical_one():
    """A healthy lattice at Courant 0.3 with frequency_step 0.5: the CFL step is the smaller (C_crit 1.04), the run
    bit for bit the plain one. The torn tip at Courant 1.0, above its C_crit (0.82): the plain run fails, with
    frequency_step 0.9 the step is 0.9 of 2 / w_max and the run lasts."""
    from refsph.simulate import time_step
    X = _lattice()

    def numerics(setup, **kw):
        return dataclasses.replace(setup, numerics=dataclasses.replace(setup.numerics, **kw))

    base = _setup(X, t_end=2e-6)
    plain, limited = (simulate(numerics(base, courant=0.3, frequency_step=f), "tlsph", progress=False)
                      for f in (0.0, 0.5))
    assert plain.summary["n_steps"] == limited.summary["n_steps"]
    assert np.array_equal(plain.state.x, limited.state.x)
    omega, _, _, _ = _frequency(_torn_tip())
    tip = numerics(_setup(_torn_tip(), t_end=150 * 2.0 / omega), courant=1.0)
    with pytest.raises(SimulationError, match="inverted particle"):
        simulate(tip, "tlsph", progress=False)
    tip = numerics(tip, frequency_step=0.9)
    solver = make_solver("tlsph", tip)
    assert time_step(tip, None, tip.state, (), solver) == pytest.approx(0.9 * 2.0 / omega, rel=1e-3)
    res = simulate(tip, "tlsph", progress=False)
    assert res.summary["status"] == "ok" and np.abs(res.state.v).max() < 1e-2


def test_frequency_step_is_checked_and_refused_where_it_cannot_work():
    from refsph.scenes import get_scene
    for bad in (-0.1, 1.5, True):
        with pytest.raises(ValueError, match="frequency_step"):
            Numerics(frequency_step=bad)
    setup = get_scene("taylor").setup(2, None, True)                  # symmetry planes: no frequency for ghosts
    setup.numerics = dataclasses.replace(setup.numerics, frequency_step=0.5)
    with pytest.raises(ValueError, match="frequency_step needs"):
        make_solver("tlsph", setup)
    with pytest.raises(ValueError, match="gain_step and frequency_step"):
        make_solver("esph", setup)
