"""The reference configuration's F cache (refsph.reference): Eq. (18) is computed once per configuration that a
step sees, and the cache changes no bit of the run."""
import numpy as np
import pytest

from refsph.reference import ReferenceConfiguration
from refsph.scenes import Numerics, Setup, aisi4340_material, lattice
from refsph.simulate import simulate
from refsph.state import make_state
from refsph.tlsph import ReferenceOperator

MAT = aisi4340_material()
DP = 0.1e-3


def _run(integrator, monkeypatch, cache: bool, ref_update_strain=0.5):
    """A 6 x 6 block stretched by a linear velocity field and sheared, about 130 steps; (result, F evaluations)."""
    x = lattice([6 * DP] * 2, DP)
    v = np.stack([20.0 * x[:, 0] / (6 * DP), 5.0 * x[:, 0] / (6 * DP)], axis=1)
    block = make_state(x, (0.0, 0.0), MAT.rho0, DP * DP)
    block.v = v
    setup = Setup(state=block, material=MAT, dp=DP, t_end=1e-6, n_snapshots=1,
                  numerics=Numerics(integrator=integrator, ref_update_strain=ref_update_strain))
    calls = []
    original = ReferenceOperator.deformation_gradient
    monkeypatch.setattr(ReferenceOperator, "deformation_gradient",
                        lambda self, x: calls.append(1) or original(self, x))
    if not cache:
        monkeypatch.setattr(ReferenceConfiguration, "_known_gradient", lambda self, body, op: None)
    res = simulate(setup, method="tlsph", progress=False)
    monkeypatch.undo()
    return res, len(calls)


@pytest.mark.parametrize("integrator, per_step", [("leapfrog", 2), ("predictor_corrector", 2)])
def test_one_F_per_configuration_and_the_same_bits(integrator, per_step, monkeypatch):
    """Leapfrog: F at the half-step positions (the stress rates) and at the new ones (the closing force, which the
    density and reference-update check of end_step reuse); predictor-corrector: at the half step and at the new
    positions (end_step's F reused by the next step's first evaluation). Without the cache a step takes one more."""
    cached, n_cached = _run(integrator, monkeypatch, cache=True)
    plain, n_plain = _run(integrator, monkeypatch, cache=False)
    steps = cached.summary["n_steps"]
    assert steps > 3
    assert n_cached <= per_step * steps + 2
    assert n_plain >= n_cached + steps - 1
    for name in ("x", "v", "rho", "S", "X", "V0"):
        assert np.array_equal(getattr(cached.state, name), getattr(plain.state, name)), name


@pytest.mark.parametrize("integrator", ["leapfrog", "predictor_corrector"])
def test_the_cache_across_reference_updates(integrator, monkeypatch):
    """With the reference configuration updated every few steps (a new operator each time) the run is the same bits
    with and without the cache."""
    cached, _ = _run(integrator, monkeypatch, cache=True, ref_update_strain=5e-4)
    plain, _ = _run(integrator, monkeypatch, cache=False, ref_update_strain=5e-4)
    assert cached.summary["diagnostics"]["reference_updates"] >= 5
    for name in ("x", "v", "rho", "S", "X", "V0"):
        assert np.array_equal(getattr(cached.state, name), getattr(plain.state, name)), name
