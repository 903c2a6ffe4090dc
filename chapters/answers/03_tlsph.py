"""Answer key of chapter 3 (TLSPH), run by tests/test_exercises.py in quick mode.

* answer_1: without the kernel-gradient correction (Eq. (18) as printed) a bar at rest has J far below 1 at its
  corners (a pressure of hundreds of GPa), and set vibrating it stops within a few steps with a non-finite
  state; with the correction J = 1 at rest and the bar runs with the right wave speed.
* answer_2: a smaller reference-update threshold gives more updates in the same shear (0.1: about four times as
  many as 0.5), never updating gives none, and then a large part of the pairs that are close at gamma = 2 do not
  interact; with updates only the few pairs that came close since the last update are missing.
* answer_3: without artificial viscosity the bar's total energy grows many times over at Courant number 0.3,
  and stays constant to a fraction of a percent at 0.15.
"""
import numpy as np

from refsph.kernels import get_kernel
from refsph.neighbours import find_pairs
from refsph.scenes import aisi4340_material, get_scene, lattice
from refsph.simulate import SimulationError, run
from refsph.state import make_state
from refsph.tensor import det
from refsph.tlsph import ReferenceOperator, green_lagrange_norm, reference_update

KERNEL = get_kernel("cubic")
MAT = aisi4340_material()


def bar_at_rest(corrected):
    """min J of the quick bar at rest, and whether a run of it completes (its wave-speed error, or None)."""
    setup = get_scene("bar").setup(2, None, True)
    op = ReferenceOperator(setup.state.X, setup.state.V0, setup.h, KERNEL, corrected)
    J = det(op.deformation_gradient(setup.state.X))
    try:
        with np.errstate(all="ignore"):
            r = run("bar", "tlsph", dim=2, quick=True, progress=False, numerics=dict(corrected=corrected))
    except SimulationError:
        return J.min(), None
    return J.min(), r.summary["metrics"]["wave_speed_rel_error"]


def shear_updates(threshold, gamma_end=2.0, n=40, nx=24, ny=16, dp=1e-4):
    """Exercise 2's prescribed shear: (number of updates, close pairs that do not interact, close pairs)."""
    X = lattice([nx * dp, ny * dp], dp)
    h = 1.5 * dp
    st = make_state(X, 0.0, MAT.rho0, dp * dp)
    op = ReferenceOperator(st.X, st.V0, h, KERNEL, True)
    n_updates = 0
    for gamma in np.linspace(0.0, gamma_end, n + 1)[1:]:
        st.x = X + np.stack([gamma * X[:, 1], 0 * X[:, 1]], 1)
        F = op.deformation_gradient(st.x)
        if threshold is not None and green_lagrange_norm(F).max() > threshold:
            st = reference_update(st, F)
            op = ReferenceOperator(st.X, st.V0, h, KERNEL, True)
            n_updates += 1
    I_now, J_now = find_pairs(st.x, 2 * h)
    pairs = set(zip(op.I.tolist(), op.J.tolist()))
    missing = sum((i, j) not in pairs for i, j in zip(I_now.tolist(), J_now.tolist()))
    return n_updates, missing, len(I_now)


def bar_energy_growth(courant):
    with np.errstate(all="ignore"):
        r = run("bar", "tlsph", dim=2, quick=True, progress=False,
                numerics=dict(beta1=0.0, beta2=0.0, courant=courant))
    e = r.summary["metrics"]["energy_history"]
    E = e[:, 1] + e[:, 2]
    return E.max() / E[0]


def answer_1():
    J_on, speed_on = bar_at_rest(True)
    J_off, speed_off = bar_at_rest(False)
    assert abs(J_on - 1) < 1e-10 and speed_on is not None and abs(speed_on) < 0.01
    assert J_off < 0.5                       # corners: half of the kernel support missing
    assert MAT.K * (1 / J_off - 1) > 1e11    # > 100 GPa of spurious pressure at rest
    assert speed_off is None                 # the run stops with a non-finite state


def answer_2():
    n5, miss5, total = shear_updates(0.5)
    n1, miss1, _ = shear_updates(0.1)
    n0, miss0, _ = shear_updates(None)
    assert n0 == 0 and 2 <= n5 <= 8 and n1 > 2 * n5
    assert miss0 > 0.3 * total               # without updates most close pairs do not interact
    assert miss5 < 0.5 * miss0 and miss1 <= miss5


def answer_3():
    assert bar_energy_growth(0.3) > 2.0      # exponential growth of a surface mode
    assert bar_energy_growth(0.15) < 1.01    # half the time step: nearly conservative
