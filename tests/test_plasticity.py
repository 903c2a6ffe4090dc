"""Johnson-Cook (Eqs. 25-31) and the material-point driver."""
import dataclasses

import numpy as np
import pytest

from refsph.teaching.material_point import material_point
from refsph.strength import plastic_update
from refsph.plasticity import (JohnsonCook, ModifiedJohnsonCook, effective_plastic_strain_increment,
                               equivalent_strain_rate, plastic_strain_increment, plastic_work_increment, radial_return,
                               yield_stress)
from refsph.paper_data import AISI1045_RLA
from refsph.scenes.taylor import taylor_johnson_cook, taylor_material

MAT = taylor_material()
JC = taylor_johnson_cook(1293.0, 1.0)


def test_yield_stress_terms():
    # room temperature, reference rate: A + B eps^n
    assert yield_stress(JC, 0.0, 1.0, 293.0) == pytest.approx(792e6, rel=1e-14)
    assert yield_stress(JC, 0.5, 1.0, 293.0) == pytest.approx(792e6 + 510e6 * 0.5**0.26, rel=1e-14)
    # rate term: 1 + C ln(rate / eps_dot_0); below the reference rate no effect (clamped, not negative)
    assert yield_stress(JC, 0.0, 1e4, 293.0) == pytest.approx(792e6 * (1 + 0.014 * np.log(1e4)), rel=1e-14)
    assert yield_stress(JC, 0.0, 1e-6, 293.0) == yield_stress(JC, 0.0, 0.0, 293.0) == pytest.approx(792e6)
    # thermal term: 1 - T*^m, T* = (T - Tr)/(Tm - Tr); T* clipped to [0, 1]
    Ts = (600.0 - 293.0) / (1293.0 - 293.0)
    assert yield_stress(JC, 0.0, 1.0, 600.0) == pytest.approx(792e6 * (1 - Ts**1.03), rel=1e-14)
    assert yield_stress(JC, 0.0, 1.0, 250.0) == pytest.approx(792e6)
    assert yield_stress(JC, 0.3, 1.0, 1293.0) == 0.0
    assert yield_stress(JC, 0.3, 1.0, 1500.0) == 0.0


def test_modified_law_saturates():
    base = dict(A=AISI1045_RLA["A_Pa"], B=AISI1045_RLA["B_Pa"], n=AISI1045_RLA["n"], C=AISI1045_RLA["C"],
                m=AISI1045_RLA["m"], eps_dot_0=AISI1045_RLA["eps_dot_0"], T_room=AISI1045_RLA["T_room_K"],
                T_melt=AISI1045_RLA["T_melt_K"], cp=AISI1045_RLA["cp_J_kgK"], chi=0.9)
    orig = JohnsonCook(**base)
    mod = ModifiedJohnsonCook(**base, hardening_saturation_strain=2.0)
    e = np.linspace(0, 4, 81)
    so, sm = yield_stress(orig, e, 1.0, 293.0), yield_stress(mod, e, 1.0, 293.0)
    assert np.allclose(so[e <= 2], sm[e <= 2], rtol=1e-14)
    assert np.all(sm[e >= 2] == sm[e == 2][0])
    assert np.all(so[e > 2] > sm[e > 2])


def test_johnson_cook_validation():
    fields = {f.name: getattr(JC, f.name) for f in dataclasses.fields(JC)}
    with pytest.raises(ValueError, match="A"):
        JohnsonCook(**dict(fields, A=-1.0))
    with pytest.raises(ValueError, match="T_melt"):
        JohnsonCook(**dict(fields, T_melt=200.0))
    with pytest.raises(ValueError, match="chi"):
        JohnsonCook(**dict(fields, chi=1.5))
    with pytest.raises(ValueError, match="missing"):
        JohnsonCook.from_dict({"A": 1.0})
    with pytest.raises(TypeError):
        JohnsonCook(A=1.0)                                   # no defaults for material constants


@pytest.mark.parametrize("dim", [2, 3])
def test_return_map_on_yield_surface_and_eqs_29_31(dim):
    rng = np.random.default_rng(3)
    n = 200
    S = rng.normal(scale=1e9, size=(n, dim, dim))
    S = 0.5 * (S + np.swapaxes(S, 1, 2))
    tr = np.trace(S, axis1=1, axis2=2)
    S_zz = np.zeros(n)
    if dim == 3:
        for a in range(3):
            S[:, a, a] -= tr / 3
    else:
        S_zz = -tr.copy()                                    # traceless with the out-of-plane component
    sy = np.full(n, 1.0e9)
    cf, Sn, Szn, svm = radial_return(S, S_zz, sy)
    ss = np.einsum("nab,nab->n", Sn, Sn) + (Szn**2 if dim == 2 else 0)
    vm = np.sqrt(1.5 * ss)
    yielded = svm > sy
    assert yielded.any() and (~yielded).any()
    assert np.allclose(vm[yielded], sy[yielded], rtol=1e-13)      # on the yield surface
    assert np.allclose(Sn[~yielded], S[~yielded], rtol=0, atol=0)  # elastic: untouched
    G = MAT.G
    dE = plastic_strain_increment(S, cf, G)                        # Eq. 29
    dEzz = (1 - cf) * S_zz / (2 * G)
    dEE = np.einsum("nab,nab->n", dE, dE) + (dEzz**2 if dim == 2 else 0)
    deps = effective_plastic_strain_increment(svm, cf, G)          # Eq. 30
    assert np.allclose(deps, np.sqrt(2.0 / 3.0 * dEE), rtol=1e-12, atol=0)
    dw = plastic_work_increment(svm, cf, G)                        # Eq. 31 = d eps_pl : s_n
    ddot = np.einsum("nab,nab->n", dE, Sn) + (dEzz * Szn if dim == 2 else 0)
    assert np.allclose(dw, ddot, rtol=1e-12, atol=1e-6)
    assert np.allclose(dw[yielded], sy[yielded] * deps[yielded], rtol=1e-12)


def test_equivalent_strain_rate():
    rate = 1e3
    l3 = np.diag([rate, -rate / 2, -rate / 2])[None]                 # isochoric uniaxial
    assert equivalent_strain_rate(l3)[0] == pytest.approx(rate, rel=1e-14)
    shear = np.array([[[0.0, rate], [0.0, 0.0]]])                   # simple shear gamma_dot
    assert equivalent_strain_rate(shear)[0] == pytest.approx(rate / np.sqrt(3), rel=1e-14)
    spin = np.array([[[0.0, rate], [-rate, 0.0]]])
    assert equivalent_strain_rate(spin)[0] == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("rate,T0", [(1.0, 293.0), (1e3, 293.0), (1e3, 600.0)])
def test_uniaxial_stress_curve_on_johnson_cook(rate, T0):
    n = 1500
    out = material_point(MAT, JC, np.diag([rate, 0.0, 0.0]), dt=0.5 / rate / n, n_steps=n, T0=T0, heating=False,
                         lateral_stress_free=True)
    sxx = out["sigma"][:, 0, 0]
    assert np.max(np.abs(out["sigma"][:, 1, 1])) < 1e-3 * np.max(sxx)              # lateral stress free
    eps = out["strain"][:, 0, 0]
    eps_p_kin = eps - sxx / MAT.E                                                    # total minus elastic
    plastic = out["eps_p"] > 0.02
    assert np.allclose(out["eps_p"][plastic], eps_p_kin[plastic], rtol=2e-3)       # Eq. 30 = kinematics
    analytic = yield_stress(JC, eps_p_kin, rate, T0)
    assert np.max(np.abs(sxx[plastic] / analytic[plastic] - 1)) < 2e-3
    # on the yield surface with the start-of-step values (explicit, as in the paper)
    sy_start = yield_stress(JC, out["eps_p"][:-1], out["eps_dot"][1:], out["T"][:-1])
    yielding = out["eps_p"][1:] > out["eps_p"][:-1]
    assert np.allclose(out["sigma_vm"][1:][yielding], sy_start[yielding], rtol=1e-12)
    assert np.allclose(out["sigma_vm"][1:][yielding], out["sigma_y"][1:][yielding], rtol=1e-12)


def test_simple_shear_curve_and_heating():
    g, n = 1e3, 2000
    l = np.array([[0.0, g, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    iso = material_point(MAT, JC, l, dt=0.3 / g / n, n_steps=n, T0=293.0, heating=False)
    rate = g / np.sqrt(3)
    plastic = iso["eps_p"] > 0.02
    analytic = yield_stress(JC, iso["eps_p"], rate, 293.0)
    assert np.max(np.abs(iso["sigma_vm"][plastic] / analytic[plastic] - 1)) < 3e-3
    # effective plastic strain of simple shear: (gamma - tau/G)/sqrt(3) for small rotations
    gamma = 2 * iso["strain"][:, 0, 1]
    tau = iso["sigma"][:, 0, 1]
    assert np.allclose(iso["eps_p"][plastic], ((gamma - tau / MAT.G) / np.sqrt(3))[plastic], rtol=1e-2)
    adi = material_point(MAT, JC, l, dt=0.3 / g / n, n_steps=n, T0=293.0, heating=True)
    rise = adi["T"] - 293.0
    assert np.allclose(rise, JC.chi * adi["W_p"] / (MAT.rho0 * JC.cp), rtol=1e-12, atol=1e-12)
    assert adi["sigma_vm"][-1] < iso["sigma_vm"][-1]                 # thermal softening
    assert rise[-1] > 10.0


def test_rate_and_temperature_move_the_curve():
    def final_stress(rate, T0):
        n = 400
        out = material_point(MAT, JC, np.diag([rate, 0.0, 0.0]), dt=0.2 / rate / n, n_steps=n, T0=T0,
                             heating=False, lateral_stress_free=True)
        return out["sigma"][-1, 0, 0]
    by_rate = [final_stress(r, 293.0) for r in (1.0, 1e3, 1e5)]
    by_T = [final_stress(1e3, T) for T in (293.0, 600.0, 900.0)]
    assert by_rate[0] < by_rate[1] < by_rate[2]
    assert by_T[0] > by_T[1] > by_T[2]


def test_plastic_update_heating_switch():
    S = np.zeros((1, 3, 3))
    S[0, 0, 1] = S[0, 1, 0] = 1e9
    args = (S, np.zeros(1), np.zeros(1), np.full(1, 293.0), np.full(1, 7830.0), np.full(1, 1e3), JC, MAT.G)
    _, _, deps, dw, dT = plastic_update(*args)
    assert deps[0] > 0 and dT[0] == pytest.approx(0.9 * dw[0] / (7830.0 * 460.0))
    iso = dataclasses.replace(JC, heating=False)                  # the law's own switch
    assert plastic_update(*args[:-2], iso, MAT.G)[4][0] == 0.0 and iso.heat(dw, np.full(1, 7830.0))[0] == 0.0


def test_material_point_validation():
    with pytest.raises(ValueError, match="dt"):
        material_point(MAT, JC, np.eye(3), dt=-1.0, n_steps=3, T0=293.0)
    with pytest.raises(ValueError, match="only l"):
        material_point(MAT, JC, np.ones((3, 3)), dt=1e-6, n_steps=3, T0=293.0, lateral_stress_free=True)
    with pytest.raises(ValueError, match="T0"):
        material_point(MAT, JC, np.eye(3), dt=1e-6, n_steps=3, T0=0.0)
