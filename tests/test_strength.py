"""The strength-model seam: a law the package does not ship, added here in one class, runs through the material
point and a particle run without touching refsph; elastic and Johnson-Cook go through the same interface."""
import dataclasses
from dataclasses import dataclass

import numpy as np
import pytest

from refsph.teaching.material_point import material_point
from refsph.plasticity import J2Plasticity, JohnsonCook, ModifiedJohnsonCook
from refsph.scenes import aisi4340_material, get_scene
from refsph.simulate import simulate
from refsph.strength import Elastic, StrengthModel, plastic_update

MAT = aisi4340_material()


@dataclass(frozen=True)
class LinearHardening(J2Plasticity):
    """sigma_y = sigma_0 + H eps_p: the whole law (the return map and the heating come from J2Plasticity)."""

    sigma_0: float
    H: float
    chi: float
    cp: float
    heating: bool = True                                            # the law's own switch (J2Plasticity.heat)

    def flow_stress(self, eps_p, eps_dot, T):
        return self.sigma_0 + self.H * np.asarray(eps_p, dtype=float)


LAW = LinearHardening(sigma_0=500e6, H=2e9, chi=0.9, cp=480.0)


def test_every_law_implements_the_interface():
    jc = get_scene("pressing").setup(quick=True).strength
    assert isinstance(jc, JohnsonCook)
    for law in (Elastic(), jc, LAW,
                ModifiedJohnsonCook(**{k: getattr(jc, k) for k in jc.__dataclass_fields__},
                                    hardening_saturation_strain=2.0)):
        assert isinstance(law, StrengthModel)


def test_linear_hardening_material_point():
    """Uniaxial stress: after yield the stress follows sigma_0 + H eps_p (the plastic strain rate does not
    matter to this law), and the plastic work heats the particle by chi dW / (rho cp)."""
    edot = 1e3
    out = material_point(MAT, LAW, np.diag([edot, 0.0, 0.0]), dt=2e-8, n_steps=800, T0=293.0,
                         lateral_stress_free=True)
    plastic = out["eps_p"] > 1e-3
    assert plastic.sum() > 100
    sigma = out["sigma"][plastic, 0, 0]
    assert np.allclose(sigma, 500e6 + 2e9 * out["eps_p"][plastic], rtol=2e-3)
    dT = out["T"][-1] - 293.0
    assert dT == pytest.approx(0.9 * out["W_p"][-1] / (MAT.rho0 * 480.0), rel=1e-2)


def test_elastic_return_map_is_the_identity():
    S = np.random.default_rng(1).normal(size=(5, 2, 2)) * 1e9
    S_zz = np.zeros(5)
    S_n, S_zz_n, deps, dw, dT = plastic_update(S, S_zz, np.zeros(5), np.full(5, 293.0), np.full(5, 7830.0),
                                               np.full(5, 1e3), Elastic(), MAT.G)
    assert S_n is S and not deps.any() and not dw.any() and not dT.any()


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_a_new_law_in_a_particle_run(method):
    """The pressing block with the law of this file: it yields where its flow stress says, nowhere else, and
    with heating off it stays at room temperature."""
    setup = get_scene("pressing").setup(quick=True)
    setup.strength, setup.t_end = dataclasses.replace(LAW, heating=False), 0.1e-6
    res = simulate(setup, method, progress=False)
    s, n = res.state, setup.info["n_block"]
    assert res.summary["strength"]["model"] == "LinearHardening" and res.summary["heating"] is False
    assert s.eps_p[:n].max() > 0.01
    svm = np.sqrt(1.5 * (np.einsum("nab,nab->n", s.S, s.S) + s.S_zz**2))[:n]
    assert np.all(svm <= LAW.flow_stress(s.eps_p[:n], 0.0, 293.0) * (1 + 1e-9))
    assert np.all(s.T == setup.state.T)
