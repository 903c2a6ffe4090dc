# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Chapter 4 — Johnson–Cook viscoplasticity and adiabatic heating
#
# Islam, Bansal & Peng, Section 2.3.1 (Eqs. 25–31); the *modified* Johnson–Cook law of Rodriguez Prieto,
# Larsson & Afrasiabi (their Eqs. 8–9).
#
# Chapters 2 and 3 gave every particle a deviatoric stress $\mathbf s$ that grows with the Jaumann rate
# (Eq. 20) without limit: an elastic solid. A metal stops carrying more shear stress once it yields, then
# flows, gets harder as it flows (strain hardening), stronger when it is deformed fast (rate hardening), and
# softer when it gets hot (thermal softening), and the plastic work heats it. In an explicit SPH code all of
# this happens in one place: at the end of every stress update, particle by particle, the elastic trial stress
# is pulled back onto the yield surface (a *return map*) and the plastic strain, the plastic work and the
# temperature are updated. Nothing in this chapter couples particles, so one **material point** (one particle
# with a prescribed velocity gradient) is the complete test bench.
#
# This chapter
#
# 1. writes Eqs. (25)–(31) out, says what the paper leaves open and what `refsph` does there;
# 2. implements the return map as a plain scalar loop, particle by particle, and checks
#    `refsph.strength.plastic_update` against it on random trial stresses (3D and 2D plane strain);
# 3. shows why the strain rate of Eq. (26) is taken from the *total* deformation of the step, not from the
#    previous step's plastic flow: the latter makes the stress chatter, worse the smaller the time step;
# 4. drives one particle of the 4340 steel of the Taylor test in uniaxial stress and in simple shear and
#    checks that the curves lie on the analytic Johnson–Cook curve (and why they lag it by one step);
# 5. moves the curves with strain rate and temperature, and compares the two melting temperatures of 4340;
# 6. turns on adiabatic heating: $\Delta T = \chi W_p/(\rho C_p)$ to round-off, and thermal softening in shear;
# 7. builds the modified law (hardening stops at plastic strain 2) for AISI 1045;
# 8. lists what the model cannot do.

# %%
import math
import os
import time
from dataclasses import fields, replace
from pathlib import Path

import numpy as np
import matplotlib.pyplot as plt
from scipy.integrate import solve_ivp

from refsph.material import ElasticMaterial
from refsph.material_point import material_point
from refsph.plasticity import (JohnsonCook, ModifiedJohnsonCook, equivalent_strain_rate, plastic_strain_increment,
                               radial_return, yield_stress)
from refsph.strength import plastic_update
from refsph.paper_data import AISI1045_RLA
from refsph.scenes.taylor import taylor_johnson_cook, taylor_material

QUICK = os.environ.get("REFSPH_QUICK", "0") == "1"     # REFSPH_QUICK=1: fewer material-point steps (the tests)
ROOT = Path.cwd().parent if Path.cwd().name == "chapters" else Path.cwd()
# Figures go to figures/ in the repo, or to $REFSPH_FIGURES when that is set (the tests set it to a temporary
# folder, so a quick-mode run never overwrites the committed full-resolution figures).
FIG = Path(os.environ["REFSPH_FIGURES"]) if os.environ.get("REFSPH_FIGURES") else ROOT / "figures"
FIG.mkdir(parents=True, exist_ok=True)
T_START = time.perf_counter()

mat = taylor_material()                     # Table 1: rho = 7830 kg/m^3, mu = 82.9 GPa, K = 169.1 GPa
jc = taylor_johnson_cook(1293.0, 1.0)       # Table 1 as printed (T_m = 1293 K); reference rate 1 /s
jc_1793 = replace(jc, T_melt=1793.0)        # the usual melting temperature of 4340
T0 = jc.T_room
print(f"quick mode: {QUICK}")
print(f"4340 (Table 1): E = {mat.E / 1e9:.1f} GPa, nu = {mat.nu:.3f}, G = {mat.G / 1e9:.1f} GPa")
print(f"  A = {jc.A / 1e6:.0f} MPa, B = {jc.B / 1e6:.0f} MPa, n = {jc.n}, C = {jc.C}, m = {jc.m}, "
      f"eps_dot_0 = {jc.eps_dot_0} /s, T_room = {jc.T_room} K, T_melt = {jc.T_melt} K, "
      f"C_p = {jc.cp} J/(kg K), chi = {jc.chi}")

# %% [markdown]
# ## 1. The equations
#
# ### Yield stress (Eqs. 25–27)
#
# $$\sigma_y = \underbrace{\big[A + B\,\bar\epsilon_p^{\,n}\big]}_{\text{strain hardening}}\;
#   \underbrace{\big[1 + C\ln\dot\epsilon^*\big]}_{\text{rate}}\;
#   \underbrace{\big[1 - T^{*m}\big]}_{\text{thermal}}
#   \qquad(25),\qquad
#   \dot\epsilon^* = \frac{\dot{\bar\epsilon}}{\dot\epsilon_0}\quad(26),\qquad
#   T^* = \frac{T - T_r}{T_m - T_r}\quad(27).$$
#
# $\bar\epsilon_p$ is the accumulated effective plastic strain, $A$ the yield stress at room temperature and
# the reference rate $\dot\epsilon_0$, $B$ and $n$ describe hardening, $C$ the rate sensitivity, $m$ the thermal
# softening, $T_r$ the room and $T_m$ the melting temperature. "log" in Eq. (25) is the natural logarithm
# (Johnson & Cook 1983). The three factors are independent: the model is a product of a hardening curve, a
# rate factor and a temperature factor, each measured separately.
#
# Two questions the paper leaves open:
#
# * **Rates below the reference rate.** For $\dot\epsilon^* < 1$, $\ln\dot\epsilon^*<0$ and it goes to
#   $-\infty$ as the rate goes to zero: a particle at rest would have a yield stress of $-\infty$ (and for
#   $\dot\epsilon^* < e^{-1/C}$ a negative one). `refsph` uses $\ln\max(\dot\epsilon^*, 1)$: no rate effect
#   below the reference rate. This is what Abaqus (the rate factor is 1 below $\dot\epsilon_0$) and LS-DYNA's
#   `*MAT_JOHNSON_COOK` do.
# * **Which rate.** The paper calls $\dot{\bar\epsilon}$ "the current effective plastic strain rate". In an
#   explicit code the plastic strain rate of the step is only known *after* the return map that needs it.
#   The previous step's plastic rate is known, but using it makes the stress chatter (Section 3 shows it). `refsph`
#   uses the equivalent **total** deviatoric strain rate of the step,
#   $$\dot{\bar\epsilon} = \sqrt{\tfrac23\,\dot{\mathbf e}:\dot{\mathbf e}},\qquad
#   \dot{\mathbf e} = \dot{\boldsymbol\epsilon} - \tfrac13\mathrm{tr}(\dot{\boldsymbol\epsilon})\mathbf I,\quad
#   \dot{\boldsymbol\epsilon} = \tfrac12(\mathbf l + \mathbf l^T),$$
#   (in 2D plane strain the out-of-plane $\dot e_{zz} = -\mathrm{tr}\,\dot{\boldsymbol\epsilon}/3$ is included).
#   Wherever the material flows, this *is* the plastic rate up to the elastic part, which is of relative size
#   (hardening modulus)/$E$. It is LS-DYNA's default (`VP = 0`, total strain rate).
#
# $T^*$ is clipped to $[0, 1]$: no extra strength below room temperature, and zero strength at and above the
# melting temperature (Section 8).
#
# ### Yield function and return map
#
# With $J_2 = \tfrac12\mathbf s:\mathbf s$ (the out-of-plane $s_{zz}$ included in 2D plane strain) the von Mises
# yield function is
# $$y_f = \sqrt{J_2} - \sigma_y/\sqrt3 ,$$
# i.e. the material is elastic while the von Mises stress $\sigma_{vm} = \sqrt{3J_2} = \sqrt{\tfrac32\mathbf s:\mathbf s}$
# stays below $\sigma_y$. A step first updates $\mathbf s$ elastically (Eq. 20); this *trial* stress may lie
# outside the yield surface. Wilkins' radial return scales it back:
# $$\mathbf s_n = c_f\,\mathbf s,\qquad c_f = \min\!\Big(\frac{\sigma_y}{\sqrt{3J_2}},\,1\Big).$$
# For von Mises plasticity with a yield stress held fixed over the step this is the exact closest-point
# projection (the flow direction $\partial y_f/\partial\mathbf s \propto\mathbf s$ is radial). The pressure is
# untouched: plastic flow is isochoric.
#
# ### Plastic strain, plastic work, temperature (Eqs. 29–31, 28)
#
# The part of the trial deviatoric strain that the return removed is plastic. Since $\mathbf s = 2\mu\,\mathbf e$
# elastically, the stress removed, $(1-c_f)\mathbf s$, is $2\mu$ times the plastic strain increment:
# $$\Delta\boldsymbol\epsilon_{pl} = \frac{1-c_f}{2\mu}\,\mathbf s \quad(29)$$
# Its equivalent (effective) value, the increment of $\bar\epsilon_p$ (the paper uses the same symbol for both):
# $$\Delta\bar\epsilon_p = \sqrt{\tfrac23\,\Delta\boldsymbol\epsilon_{pl}:\Delta\boldsymbol\epsilon_{pl}}
#    = \frac{1-c_f}{3\mu}\sqrt{\tfrac32\,\mathbf s:\mathbf s} = \frac{(1-c_f)\,\sigma_{vm}^{trial}}{3\mu}\quad(30)$$
# The plastic work density of the step is the returned stress times the plastic strain increment:
# $$\Delta w_p = \Delta\boldsymbol\epsilon_{pl}:\mathbf s_n = \frac{(1-c_f)\,c_f}{2\mu}\,\mathbf s:\mathbf s
#    = \sigma_y\,\Delta\bar\epsilon_p\quad(31)$$
# (the last form because $c_f\sigma_{vm}^{trial} = \sigma_y$ whenever $c_f < 1$). $W_p = \sum\Delta w_p$ is the
# accumulated plastic work density [J/m³].
#
# A fraction $\chi$ (Taylor–Quinney, $\chi = 0.9$) of the plastic work becomes heat; with no conduction
# (adiabatic) the temperature rises by
# $$\Delta T = \frac{\chi\,\Delta w_p}{\rho\,C_p}\qquad(28).$$
# The paper prints Eq. (28) as $dT/dt = \chi W_p/(\rho C_p)$ with $W_p$ the accumulated work. Dimensionally that
# is not a rate ($W_p/(\rho C_p)$ is a temperature, not a temperature per second), and read literally it would
# keep heating a particle that has stopped flowing. The increment form above — equivalently
# $\dot T = \chi\dot W_p/(\rho C_p)$, or $T - T_r = \chi W_p/(\rho C_p)$ for constant $\rho C_p$ — is what is meant
# and what `refsph` does.
#
# **Order within a step** (`plastic_update`): the yield stress is evaluated with the *start-of-step*
# $\bar\epsilon_p$ and $T$ (explicit, as in the paper) and the total equivalent rate of the step; then the return,
# then Eqs. (30), (31), (28).
#
# The three factors of Eq. (25) for the Taylor 4340 steel:

# %%
eps_grid = np.linspace(0.0, 1.0, 401)
rate_grid = np.logspace(-6, 6, 400)                         # eps_dot* = eps_dot / eps_dot_0
T_grid = np.linspace(200.0, 1850.0, 400)
f_hard = jc.A + jc.B * eps_grid**jc.n
f_rate = yield_stress(jc, 0.0, rate_grid * jc.eps_dot_0, T0) / jc.A      # the clamped factor of refsph
f_rate_raw = 1.0 + jc.C * np.log(rate_grid)                               # ln as printed, no clamp
f_T = {Tm: yield_stress(replace(jc, T_melt=Tm), 0.0, jc.eps_dot_0, T_grid) / jc.A for Tm in (1293.0, 1793.0)}
assert np.allclose(yield_stress(jc, eps_grid, jc.eps_dot_0, T0), f_hard, rtol=1e-14)
assert np.all(f_rate[rate_grid <= 1.0] == 1.0) and np.allclose(f_rate[rate_grid > 1], f_rate_raw[rate_grid > 1])
for Tm, f in f_T.items():
    assert np.all(f[T_grid <= T0] == 1.0) and np.all(f[T_grid >= Tm] == 0.0)
print(f"rate factor at eps_dot* = 1e-6: as printed {1 + jc.C * math.log(1e-6):.3f}, refsph 1; "
      f"at 1e4: {1 + jc.C * math.log(1e4):.3f}; the printed factor is negative below eps_dot* = "
      f"exp(-1/C) = {math.exp(-1 / jc.C):.1e}")

fig, axes = plt.subplots(1, 3, figsize=(15, 4.3), constrained_layout=True)
ax = axes[0]
ax.plot(eps_grid, f_hard / 1e6, "k")
ax.set_xlabel(r"effective plastic strain $\bar\epsilon_p$")
ax.set_ylabel(r"$A + B\bar\epsilon_p^n$ [MPa]")
ax.set_title("strain hardening (rate 1 /s, room temperature)")
ax = axes[1]
ax.semilogx(rate_grid, f_rate_raw, "C3--", label=r"$1 + C\ln\dot\epsilon^*$ as printed")
ax.semilogx(rate_grid, f_rate, "k", label=r"refsph: $1 + C\ln\max(\dot\epsilon^*, 1)$")
ax.set_xlabel(r"$\dot\epsilon^* = \dot{\bar\epsilon}/\dot\epsilon_0$")
ax.set_ylabel("rate factor")
ax.set_title(f"rate factor, C = {jc.C}")
ax.legend()
ax = axes[2]
for (Tm, f), ls in zip(f_T.items(), ("k", "C0--")):
    ax.plot(T_grid, f, ls, label=f"$T_m$ = {Tm:.0f} K")
ax.set_xlabel("temperature T [K]")
ax.set_ylabel(r"$1 - T^{*m}$")
ax.set_title(f"thermal factor, m = {jc.m}")
ax.legend()
fig.suptitle("The three factors of Eq. (25), AISI 4340 of Table 1")
fig.savefig(FIG / "04_jc_factors.png", dpi=120)
plt.show()

# %% [markdown]
# ## 2. The return map as a plain loop
#
# Everything of Section 1 for one particle at a time, in plain Python floats. The deviatoric stress is a
# list of rows ($d\times d$, $d$ = 2 or 3) plus, in 2D plane strain, the out-of-plane component $s_{zz}$.

# %%
def plain_yield_stress(jc, eps_p, eps_dot, T):
    """Eq. (25) for one particle, with the clamps of Section 1."""
    eps_p = max(eps_p, 0.0)
    if isinstance(jc, ModifiedJohnsonCook):                         # modified law (Section 7)
        eps_p = min(eps_p, jc.hardening_saturation_strain)
    rate_star = eps_dot / jc.eps_dot_0                              # Eq. (26)
    T_star = (T - jc.T_room) / (jc.T_melt - jc.T_room)              # Eq. (27)
    T_star = min(max(T_star, 0.0), 1.0)
    return (jc.A + jc.B * eps_p**jc.n) * (1.0 + jc.C * math.log(max(rate_star, 1.0))) * (1.0 - T_star**jc.m)


def plain_equivalent_rate(l):
    """sqrt(2/3 e':e') of the symmetric part of l (d x d); in 2D the zz rate is 0 but its deviator is not."""
    d = len(l)
    D = [[0.5 * (l[a][b] + l[b][a]) for b in range(d)] for a in range(d)]
    tr = sum(D[a][a] for a in range(d))
    ee = sum((D[a][b] - (tr / 3.0 if a == b else 0.0)) ** 2 for a in range(d) for b in range(d))
    if d == 2:
        ee += (0.0 - tr / 3.0) ** 2                                 # e'_zz of plane strain
    return math.sqrt(2.0 / 3.0 * ee)


def plain_return_map(s, s_zz, eps_p, T, rho, eps_dot, jc, G, heating=True):
    """Wilkins return + Eqs. (29)-(31) + Eq. (28) for one particle; s is the trial deviatoric stress."""
    d = len(s)
    ss = sum(s[a][b] ** 2 for a in range(d) for b in range(d)) + (s_zz**2 if d == 2 else 0.0)
    J2 = 0.5 * ss
    sigma_y = plain_yield_stress(jc, eps_p, eps_dot, T)
    y_f = math.sqrt(J2) - sigma_y / math.sqrt(3.0)                   # von Mises yield function
    c_f = sigma_y / math.sqrt(3.0 * J2) if y_f > 0.0 else 1.0       # = min(sigma_y / sqrt(3 J2), 1)
    s_n = [[c_f * s[a][b] for b in range(d)] for a in range(d)]
    s_zz_n = c_f * s_zz
    deps_pl = [[(1.0 - c_f) / (2.0 * G) * s[a][b] for b in range(d)] for a in range(d)]     # Eq. (29)
    deps_pl_zz = (1.0 - c_f) / (2.0 * G) * s_zz
    dd = sum(deps_pl[a][b] ** 2 for a in range(d) for b in range(d)) + (deps_pl_zz**2 if d == 2 else 0.0)
    deps_p = math.sqrt(2.0 / 3.0 * dd)                                                        # Eq. (30)
    assert abs(deps_p - (1.0 - c_f) / (3.0 * G) * math.sqrt(1.5 * ss)) <= 1e-14 * max(deps_p, 1e-300)
    dw_p = sum(deps_pl[a][b] * s_n[a][b] for a in range(d) for b in range(d))                # Eq. (31)
    if d == 2:
        dw_p += deps_pl_zz * s_zz_n
    dT = jc.chi * dw_p / (rho * jc.cp) if heating else 0.0                                   # Eq. (28)
    return dict(s_n=s_n, s_zz_n=s_zz_n, c_f=c_f, deps_pl=deps_pl, deps_p=deps_p, dw_p=dw_p, dT=dT,
                sigma_y=sigma_y)

# %% [markdown]
# Random trial states that cover every branch: elastic and plastic particles (trial von Mises stress from 0
# to 3× the yield stress), rates below and above the reference rate, temperatures below room temperature and
# above the melting point, plastic strains from 0 to 4. Two materials: the Taylor 4340 and the modified law for
# AISI 1045 of Section 7 (hardening capped at $\bar\epsilon_p = 2$).

# %%
jc_1045 = ModifiedJohnsonCook(A=AISI1045_RLA["A_Pa"], B=AISI1045_RLA["B_Pa"], n=AISI1045_RLA["n"], C=AISI1045_RLA["C"],
                      m=AISI1045_RLA["m"], eps_dot_0=AISI1045_RLA["eps_dot_0"], T_room=AISI1045_RLA["T_room_K"],
                      T_melt=AISI1045_RLA["T_melt_K"], cp=AISI1045_RLA["cp_J_kgK"],
                      chi=AISI1045_RLA["taylor_quinney"],
                      hardening_saturation_strain=AISI1045_RLA["hardening_saturation_strain"])
mat_1045 = ElasticMaterial(rho0=AISI1045_RLA["rho"], E=AISI1045_RLA["E_Pa"], nu=AISI1045_RLA["nu"])


def random_trial_states(n, d, jc, seed):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, d, d))
    S = 0.5 * (A + np.swapaxes(A, 1, 2))
    if d == 3:
        S -= np.trace(S, axis1=1, axis2=2)[:, None, None] / 3.0 * np.eye(3)
        S_zz = np.zeros(n)
    else:                                                           # plane strain: s_xx + s_yy + s_zz = 0
        S_zz = -np.trace(S, axis1=1, axis2=2)
    svm = np.sqrt(1.5 * (np.einsum("nab,nab->n", S, S) + (S_zz**2 if d == 2 else 0.0)))
    target = rng.uniform(0.0, 3.0, n) * jc.A * 1.5                  # trial von Mises stress 0 .. ~4.5 A
    S *= (target / svm)[:, None, None]
    S_zz *= target / svm
    eps_p = np.where(rng.random(n) < 0.1, 0.0, rng.uniform(0.0, 4.0, n))
    T = rng.uniform(200.0, jc.T_melt + 200.0, n)
    eps_dot = jc.eps_dot_0 * 10.0 ** rng.uniform(-4.0, 7.0, n)
    rho = rng.uniform(0.9, 1.1, n) * 7800.0
    return S, S_zz, eps_p, T, rho, eps_dot


N_RANDOM = 400
for name, jc_k, G_k in (("4340 (Table 1)", jc, mat.G), ("1045 (modified J-C)", jc_1045, mat_1045.G)):
    for d in (3, 2):
        S, S_zz, eps_p, T, rho, eps_dot = random_trial_states(N_RANDOM, d, jc_k, seed=10 * d + len(name))
        S_n, S_zz_n, deps, dw, dT = plastic_update(S, S_zz, eps_p, T, rho, eps_dot, jc_k, G_k, heating=True)
        cf, _, _, svm_trial = radial_return(S, S_zz, yield_stress(jc_k, eps_p, eps_dot, T))
        deps_pl = plastic_strain_increment(S, cf, G_k)
        ref = [plain_return_map(S[i].tolist(), float(S_zz[i]), float(eps_p[i]), float(T[i]), float(rho[i]),
                                float(eps_dot[i]), jc_k, G_k) for i in range(N_RANDOM)]
        r = lambda key: np.array([q[key] for q in ref])              # noqa: E731
        # Each quantity is compared relative to its natural size for that particle: sigma_y to its value at room
        # temperature (1 - T*^m cancels near T_m), stresses to the trial von Mises stress, d eps_p to
        # sigma_vm/(3 mu), d w_p to sigma_vm^2/(3 mu), dT to chi sigma_vm^2/(3 mu rho C_p) (all ~1e-16 * that).
        sy_cold = yield_stress(jc_k, eps_p, eps_dot, jc_k.T_room)
        scale = dict(sigma_y=sy_cold, s_n=svm_trial[:, None, None], s_zz_n=svm_trial,
                     deps_pl=svm_trial[:, None, None] / (2 * G_k), deps_p=svm_trial / (3 * G_k),
                     dw_p=svm_trial**2 / (3 * G_k), dT=jc_k.chi * svm_trial**2 / (3 * G_k * rho * jc_k.cp))
        pkg = dict(sigma_y=yield_stress(jc_k, eps_p, eps_dot, T), s_n=S_n, s_zz_n=S_zz_n, deps_pl=deps_pl,
                   deps_p=deps, dw_p=dw, dT=dT)
        worst = 0.0
        for key, val in pkg.items():
            if d == 3 and key == "s_zz_n":
                continue
            rel = np.abs(val - r(key)) / scale[key]
            worst = max(worst, rel.max())
            assert rel.max() < 1e-12, (key, rel.max())
        # what the equations promise: plastic particles end on the yield surface, elastic ones are untouched,
        # and Eq. (31) is sigma_y * d eps_p
        plastic = deps > 0
        sy = pkg["sigma_y"]
        svm_n = np.sqrt(1.5 * (np.einsum("nab,nab->n", S_n, S_n) + (S_zz_n**2 if d == 2 else 0.0)))
        assert np.allclose(svm_n[plastic], sy[plastic], rtol=1e-13, atol=1e-12 * jc_k.A)
        assert np.array_equal(S_n[~plastic], S[~plastic])
        assert np.allclose(dw, sy * deps, rtol=1e-12, atol=0)
        # the equivalent rate of Eq. (26), plain vs package
        l = np.random.default_rng(d).normal(scale=1e4, size=(50, d, d))
        assert np.allclose(equivalent_strain_rate(l), [plain_equivalent_rate(li.tolist()) for li in l],
                           rtol=1e-13)
        print(f"{name:20} {d}D: plain loop == plastic_update for {N_RANDOM} particles "
              f"({plastic.sum()} plastic, {(sy == 0).sum()} above T_m, {(eps_dot < jc_k.eps_dot_0).sum()} "
              f"below the reference rate); worst difference {worst:.1e} of the natural scale")

# %% [markdown]
# Above the melting temperature $\sigma_y = 0$, so $c_f = 0$: the whole trial deviator is plastic strain
# and no work is done (Eq. 31 with $\mathbf s_n = 0$) — see Section 8.
#
# ## 3. Which strain rate in Eq. (26)? The chatter of the previous step's plastic rate
#
# A material point in simple shear, $\mathbf l = \dot\gamma\,\mathbf e_x\otimes\mathbf e_y$, integrated exactly like
# a particle in `refsph` (predictor–corrector: a half step to $\mathbf s_{1/2}$ with its own return map, then the
# full step with the Jaumann rate at $\mathbf s_{1/2}$; see `refsph.material_point`), with the plain return map of
# Section 2. The only switch is the rate that goes into Eq. (26):
#
# * `"total"` (refsph): the equivalent total rate of the step, $\dot\gamma/\sqrt3$ for simple shear;
# * `"plastic"`: the previous step's effective plastic strain rate $\Delta\bar\epsilon_p^{\,k-1}/\Delta t$ — what
#   "the current effective plastic strain rate" becomes in an explicit code.

# %%
def plain_shear_point(jc, G, gamma_dot, dt, n_steps, T, rate_mode):
    """Simple shear of one particle (tr l = 0: rho and p stay constant), heating off. Returns per-step arrays."""
    l = np.zeros((3, 3))
    l[0, 1] = gamma_dot
    D, W = 0.5 * (l + l.T), 0.5 * (l - l.T)
    rate_total = plain_equivalent_rate(l.tolist())

    def jaumann(s):                                                 # Eq. (20), tr D = 0
        return 2.0 * G * D + W @ s - s @ W

    s = np.zeros((3, 3))
    eps_p, rate_plastic = 0.0, 0.0
    out = dict(svm=[0.0], eps_p=[0.0], rate=[0.0], tau=[0.0])
    for _ in range(n_steps):
        rate = rate_total if rate_mode == "total" else rate_plastic
        half = plain_return_map((s + 0.5 * dt * jaumann(s)).tolist(), 0.0, eps_p, T, 1.0, rate, jc, G, False)
        s_half = np.array(half["s_n"])
        full = plain_return_map((s + dt * jaumann(s_half)).tolist(), 0.0, eps_p, T, 1.0, rate, jc, G, False)
        s = np.array(full["s_n"])
        eps_p += full["deps_p"]
        rate_plastic = full["deps_p"] / dt                         # what "plastic" uses in the next step
        out["svm"].append(math.sqrt(1.5 * np.sum(s * s)))
        out["eps_p"].append(eps_p)
        out["rate"].append(rate)
        out["tau"].append(s[0, 1])
    return {k: np.array(v) for k, v in out.items()}


# the plain loop with refsph's choice is the package's material point, step for step
gd = math.sqrt(3.0) * 1e4                                           # equivalent rate 1e4 /s
chk = plain_shear_point(jc, mat.G, gd, 1e-8, 300, T0, "total")
mp = material_point(mat, jc, [[0, gd, 0], [0, 0, 0], [0, 0, 0]], 1e-8, 300, T0, heating=False)
assert np.allclose(chk["svm"], mp["sigma_vm"], rtol=1e-12, atol=1e-6)
assert np.allclose(chk["eps_p"], mp["eps_p"], rtol=1e-12, atol=1e-18)
assert np.allclose(chk["tau"], mp["S"][:, 0, 1], rtol=1e-12, atol=1e-6)
print("plain shear loop ('total') == refsph.material_point over 300 steps")

# %% [markdown]
# Now the two choices at an equivalent rate of $10^4$ /s (the lower end of machining rates) with three time
# steps around the paper's $\Delta t = 10^{-8}$ s of Table 2, up to an equivalent strain of 0.05:

# %%
RATE_CH = 1e4
STRAIN_CH = 0.05
chatter = {}
for dt in (1e-7, 1e-8, 1e-9):
    n = int(round(STRAIN_CH / (RATE_CH * dt)))
    for mode in ("total", "plastic"):
        chatter[dt, mode] = plain_shear_point(jc, mat.G, math.sqrt(3.0) * RATE_CH, dt, n, T0, mode)
        chatter[dt, mode]["strain"] = RATE_CH * dt * np.arange(n + 1)

late = lambda a: a[len(a) // 2:]                                    # noqa: E731  second half of a run
for dt in (1e-7, 1e-8, 1e-9):
    tot, pla = chatter[dt, "total"], chatter[dt, "plastic"]
    jump_tot = np.abs(np.diff(late(tot["svm"]))).max()
    jump_pla = np.abs(np.diff(late(pla["svm"]))).max()
    mean_gap = late(pla["svm"]).mean() / late(tot["svm"]).mean() - 1
    # per-step growth of the trial von Mises stress vs the whole rate term of the yield stress
    dsvm_step = 3.0 * mat.G * RATE_CH * dt
    rate_term = yield_stress(jc, late(tot["eps_p"]).mean(), RATE_CH, T0) - yield_stress(
        jc, late(tot["eps_p"]).mean(), jc.eps_dot_0, T0)
    print(f"dt = {dt:.0e} s: step-to-step jump of sigma_vm  total {jump_tot / 1e6:7.2f} MPa, "
          f"plastic {jump_pla / 1e6:7.2f} MPa;  mean stress 'plastic' vs 'total' {100 * mean_gap:+.1f} %;  "
          f"3 G eps_dot dt = {dsvm_step / 1e6:6.1f} MPa vs rate term sigma_y C ln(eps_dot*) = {rate_term / 1e6:.0f} MPa")
    chatter[dt, "jumps"] = (jump_tot, jump_pla, mean_gap, dsvm_step, rate_term)
# the total-rate curves converge with dt; the plastic-rate ones chatter once 3 G eps_dot dt < the rate term,
# and then sit on the rate-FREE curve (rate factor 1), within about one elastic increment
assert np.allclose(chatter[1e-8, "total"]["svm"][-1], chatter[1e-9, "total"]["svm"][-1], rtol=1e-3)
for dt in (1e-8, 1e-9):
    jt, jp, gap, step, term = chatter[dt, "jumps"]
    assert step < term and jp > 10 * jt and gap < -0.03
    pla = chatter[dt, "plastic"]
    above_rate_free = late(pla["svm"]) / yield_stress(jc, late(pla["eps_p"]), jc.eps_dot_0, T0) - 1
    print(f"dt = {dt:.0e} s, previous plastic rate: sigma_vm / sigma_y(eps_p, rate factor 1) - 1 between "
          f"{above_rate_free.min():.1e} and {above_rate_free.max():.1e} (one elastic increment: "
          f"{step / yield_stress(jc, late(pla['eps_p']).mean(), jc.eps_dot_0, T0):.1e})")
    assert np.all(above_rate_free > -0.01) and np.all(above_rate_free < 0.01 + 1.5 * step / jc.A)

fig, axes = plt.subplots(1, 2, figsize=(13, 4.6), constrained_layout=True)
ax = axes[0]
for dt, c in zip((1e-7, 1e-8, 1e-9), ("C2", "C0", "C3")):
    ax.plot(chatter[dt, "plastic"]["strain"], chatter[dt, "plastic"]["svm"] / 1e6, c, lw=0.6,
            label=f"previous plastic rate, dt = {dt:.0e} s")
    ax.plot(chatter[dt, "total"]["strain"], chatter[dt, "total"]["svm"] / 1e6, "k" if dt == 1e-9 else "k:",
            lw=1.5, label=f"total rate (refsph), dt = {dt:.0e} s" if dt != 1e-7 else None)
ep_line = np.linspace(0.0, STRAIN_CH, 200)
for r_, lab, dy in ((RATE_CH, f"Eq. (25) at {RATE_CH:.0e} /s", 25), (jc.eps_dot_0, "Eq. (25), rate factor 1", -22)):
    sy_line = yield_stress(jc, ep_line, r_, T0)
    ax.plot(ep_line + sy_line / (3 * mat.G), sy_line / 1e6, color="grey", ls="--", lw=0.9)   # + elastic strain
    ax.text(0.02, float(yield_stress(jc, 0.02 - sy_line[0] / (3 * mat.G), r_, T0)) / 1e6 + dy, lab,
            color="dimgrey", fontsize=9)
ax.set_xlabel(r"equivalent strain $\gamma/\sqrt{3}$")
ax.set_ylabel(r"von Mises stress $\sigma_{vm}$ [MPa]")
ax.set_ylim(jc.A / 1e6 - 80, None)
ax.set_xlim(0.0, STRAIN_CH)
ax.set_title(f"simple shear at an equivalent rate of {RATE_CH:.0e} /s")
ax.legend(fontsize=8, loc="lower right")
ax = axes[1]
run_ = chatter[1e-8, "plastic"]
first = int(np.argmax(run_["eps_p"] > 0))
k = np.arange(first - 3, first + 40)
ax.plot(k, run_["rate"][k] / RATE_CH, "C0o-", ms=3, label="previous plastic rate (chatters)")
ax.plot(k, chatter[1e-8, "total"]["rate"][k] / RATE_CH, "k-", label="total rate (refsph)")
ax.set_xlabel("step")
ax.set_ylabel(r"rate fed into Eq. (26) / applied rate")
ax.set_title("dt = 1e-8 s: the rate used by the return map, around first yield")
ax.legend()
fig.savefig(FIG / "04_rate_chatter.png", dpi=120)
plt.show()

# %% [markdown]
# With the previous step's plastic rate the return map falls into a two-step cycle (right panel). In a step that
# follows an elastic step the rate fed into Eq. (26) is zero, the rate factor is 1, and the stress is returned
# to the rate-free yield stress; the plastic strain of that step is two steps' worth of strain, a plastic rate
# of about twice the applied one. The next step therefore sees a yield stress raised by the whole rate term
# $\sigma_y C\ln\dot\epsilon^*$, and if one step's elastic growth of the trial stress,
# $3\mu\dot{\bar\epsilon}\Delta t$, is smaller than that (numbers printed above), the step is elastic: the
# plastic rate is zero again, and so on. The stress saws between the rate-free curve and one elastic increment
# above it. Consequences:
#
# * the curve **converges to the wrong answer** as the time step shrinks: the sawtooth gets finer, but it hugs
#   the rate-free curve — the rate sensitivity is lost entirely (asserted above). It is not a discretisation
#   error that goes away; it appears *because* the step is small, and SPH runs at small explicit time steps
#   (10⁻⁸ s in Table 2, less in cutting). Only a step so large that one elastic increment exceeds the rate term
#   (here 10⁻⁷ s) escapes it;
# * in a body, neighbouring particles fall into the cycle with different phases: stress noise at the particle
#   scale.
#
# The total rate has neither problem: it is known before the return map, it is the plastic rate wherever the
# material flows, and the curves for the three time steps coincide.
#
# ## 4. One particle of 4340: uniaxial stress and simple shear against the analytic curve
#
# Heating off, room temperature, a fixed equivalent rate of $10^3$ /s. Two loadings with `material_point`:
#
# * **uniaxial stress** along $x$: $l_{xx}$ prescribed, $l_{yy} = l_{zz}$ found each step so that
#   $\sigma_{yy} = \sigma_{zz} = 0$ (`lateral_stress_free=True`). Then $\sigma_{vm} = |\sigma_{xx}|$ and the plastic
#   strain can be read off the curve as $\bar\epsilon_p = \epsilon_{xx} - \sigma_{xx}/E$ ($\epsilon_{xx}$ the
#   logarithmic strain) — independent of the package's own $\bar\epsilon_p$;
# * **simple shear** $\mathbf l = \dot\gamma\,\mathbf e_x\otimes\mathbf e_y$ with $\dot\gamma = \sqrt3\times10^3$ /s
#   (equivalent rate $\dot\gamma/\sqrt3$). For von Mises, $\tau = \sigma_{vm}/\sqrt3$ as long as the normal
#   stresses that the Jaumann rate generates at large shear are small; we compare $\sigma_{vm}$ with
#   $\sigma_y$, which is exact at any $\gamma$.
#
# The analytic curve is $\sigma_y(\bar\epsilon_p, 10^3\,\text{/s}, T_r)$ of Eq. (25).
#
# **The one-step lag.** `plastic_update` evaluates $\sigma_y$ with the $\bar\epsilon_p$ of the *start* of the
# step, so the stress after step $k$ is $\sigma_y(\bar\epsilon_p^{\,k-1})$, not $\sigma_y(\bar\epsilon_p^{\,k})$:
# the curve lies below the analytic one by one step's hardening,
# $\partial\sigma_y/\partial\bar\epsilon_p\,\Delta\bar\epsilon_p \propto B n\bar\epsilon_p^{\,n-1}\Delta\bar\epsilon_p$,
# which is large right after yield ($n - 1 < 0$) and shrinks as $\bar\epsilon_p$ grows. So we assert two things:
# (i) after every plastic step $\sigma_{vm} = \sigma_y$ at the start-of-step values *to round-off*, and
# (ii) against the analytic curve, only where $\bar\epsilon_p > 0.02$, within the largest one-step hardening
# increment there (printed) plus $2\times10^{-4}$ (the uniaxial equivalent rate differs from the applied one by
# the elastic part of the lateral contraction).

# %%
N_MP = 400 if QUICK else 2000           # material-point steps to an equivalent strain of STRAIN_MP
STRAIN_MP = 0.5
RATE_MP = 1e3


def uniaxial(jc, rate, T, n=N_MP, strain=STRAIN_MP, heating=False):
    return material_point(mat, jc, np.diag([rate, 0.0, 0.0]), strain / (rate * n), n, T, heating=heating,
                          lateral_stress_free=True)


def shear(jc, rate, T, n=N_MP, strain=STRAIN_MP, heating=False, material=mat):
    gdot = math.sqrt(3.0) * rate                                    # equivalent rate = gdot / sqrt(3)
    return material_point(material, jc, [[0, gdot, 0], [0, 0, 0], [0, 0, 0]], strain / (rate * n), n, T,
                          heating=heating)


def on_yield_surface(o, jc):
    """sigma_vm after each plastic step vs sigma_y at the start-of-step eps_p, T and the step's rate."""
    plastic = np.diff(o["eps_p"]) > 0
    sy_start = yield_stress(jc, o["eps_p"][:-1], o["eps_dot"][1:], o["T"][:-1])
    return np.abs(o["sigma_vm"][1:][plastic] / sy_start[plastic] - 1).max(), plastic.sum()


def one_step_hardening(o, jc, rate, mask):
    """Relative yield-stress increase over one step, sigma_y(eps_p^k)/sigma_y(eps_p^(k-1)) - 1, where mask."""
    a = yield_stress(jc, o["eps_p"][1:], rate, o["T"][1:])
    b = yield_stress(jc, o["eps_p"][:-1], rate, o["T"][:-1])
    return (a / b - 1)[mask[1:]].max()


uni = uniaxial(jc, RATE_MP, T0)
shr = shear(jc, RATE_MP, T0)

# uniaxial: plastic strain from the curve, compared with the package's eps_p and the analytic curve
s_xx = uni["sigma"][:, 0, 0]
e_xx = uni["strain"][:, 0, 0]
ep_curve = e_xx - s_xx / mat.E
lateral = np.abs(uni["sigma"][:, 1:, 1:]).max()
print(f"uniaxial: max |sigma_yy|, |sigma_zz| = {lateral:.1e} Pa;  max |(eps_xx - sigma_xx/E) - eps_p| = "
      f"{np.abs(ep_curve - uni['eps_p']).max():.1e}")
assert lateral < 1.0 and np.abs(ep_curve - uni["eps_p"]).max() < 1e-5

for name, o, sig, ep in (("uniaxial", uni, s_xx, ep_curve), ("shear", shr, shr["sigma_vm"], shr["eps_p"])):
    err_surface, n_plastic = on_yield_surface(o, jc)
    m = o["eps_p"] > 0.02
    err = np.abs(sig[m] / yield_stress(jc, ep[m], RATE_MP, T0) - 1).max()
    tol = one_step_hardening(o, jc, RATE_MP, m) + 2e-4
    print(f"{name:8}: on the yield surface after {n_plastic} plastic steps to {err_surface:.1e};  "
          f"vs analytic curve (eps_p > 0.02) max rel. error {err:.2e}, tolerance {tol:.2e}")
    assert err_surface < 1e-13
    assert err < tol
tau_ratio = shr["S"][-1, 0, 1] * math.sqrt(3) / shr["sigma_vm"][-1]
print(f"shear at gamma = {math.sqrt(3) * STRAIN_MP:.2f}: sqrt(3) tau / sigma_vm = {tau_ratio:.4f} "
      f"(normal stresses: s_xx = {shr['S'][-1, 0, 0] / 1e6:.1f} MPa, s_yy = {shr['S'][-1, 1, 1] / 1e6:.1f} MPa)")

# %% [markdown]
# The lag is first order in the step: halving the step halves it. Simple shear with 4× more and fewer steps
# (the error is measured against the analytic curve at the particle's own $\bar\epsilon_p$):

# %%
N_CONV = (100, 200, 400, 800) if QUICK else (250, 500, 1000, 2000, 4000)
conv = {}
for n in N_CONV:
    o = shear(jc, RATE_MP, T0, n=n)
    rel = o["sigma_vm"] / yield_stress(jc, o["eps_p"], RATE_MP, T0) - 1
    m = o["eps_p"] > 0.02
    conv[n] = (o["eps_p"], rel, np.abs(rel[m]).max())
errs = np.array([conv[n][2] for n in N_CONV])
orders = np.log2(errs[:-1] / errs[1:]) / np.log2(np.array(N_CONV[1:]) / np.array(N_CONV[:-1]))
i_small = int(np.argmin(np.abs(conv[N_CONV[-1]][0] - 1e-3)))
print("steps to strain 0.5:", N_CONV)
print("max relative lag for eps_p > 0.02:", " ".join(f"{e:.2e}" for e in errs))
print("observed order:", " ".join(f"{q:.2f}" for q in orders))
print(f"with {N_CONV[-1]} steps the lag at eps_p = {conv[N_CONV[-1]][0][i_small]:.1e} is "
      f"{100 * abs(conv[N_CONV[-1]][1][i_small]):.2f} %")
assert np.all((orders > 0.85) & (orders < 1.15))

fig, axes = plt.subplots(1, 3, figsize=(16, 4.6), constrained_layout=True)
ep_an = np.linspace(0.0, ep_curve.max(), 300)
ax = axes[0]
ax.plot(ep_curve, s_xx / 1e6, "C0", lw=2.5, label=r"uniaxial $\sigma_{xx}$ vs $\epsilon_{xx} - \sigma_{xx}/E$")
ax.plot(shr["eps_p"], shr["sigma_vm"] / 1e6, "C1", lw=1.5, label=r"shear $\sigma_{vm}$ vs $\bar\epsilon_p$")
ax.plot(shr["eps_p"], math.sqrt(3) * shr["S"][:, 0, 1] / 1e6, "C1:", lw=1.5, label=r"shear $\sqrt{3}\,\tau$")
ax.plot(ep_an, yield_stress(jc, ep_an, RATE_MP, T0) / 1e6, "k--", lw=1, label="Eq. (25)")
ax.set_xlabel(r"effective plastic strain $\bar\epsilon_p$")
ax.set_ylabel("stress [MPa]")
ax.set_title(f"4340, {RATE_MP:.0e} /s, {T0:.0f} K, heating off, {N_MP} steps")
ax.legend(fontsize=8)
ax = axes[1]
ax.plot(e_xx, s_xx / 1e6, "C0", label=r"uniaxial $\sigma_{xx}$ vs $\epsilon_{xx}$")
ax.plot(shr["strain"][:, 0, 1] * 2 / math.sqrt(3), shr["sigma_vm"] / 1e6, "C1",
        label=r"shear $\sigma_{vm}$ vs $\gamma/\sqrt{3}$")
ax.set_xlim(0, 0.03)
ax.set_xlabel("equivalent total strain")
ax.set_ylabel("stress [MPa]")
ax.set_title("the elastic–plastic transition")
ax.legend(fontsize=8)
ax = axes[2]
for n in N_CONV:
    ep_n, rel_n, _ = conv[n]
    ax.loglog(ep_n[1:], np.abs(rel_n[1:]) + 1e-16, label=f"{n} steps")
ax.axvline(0.02, color="grey", lw=0.8, ls="--")
ax.set_ylim(1e-5, 1e-1)
ax.set_xlabel(r"$\bar\epsilon_p$")
ax.set_ylabel(r"$|\sigma_{vm}/\sigma_y(\bar\epsilon_p) - 1|$")
ax.set_title("one-step hardening lag (simple shear): first order")
ax.legend(fontsize=8)
fig.savefig(FIG / "04_material_point.png", dpi=120)
plt.show()

# %% [markdown]
# Both loadings give the same $\sigma_{vm}(\bar\epsilon_p)$ curve: von Mises plasticity with isotropic hardening
# does not know the loading direction. In simple shear at large $\gamma$ the Jaumann rate rotates part of the
# shear stress into normal stresses, so $\sqrt3\,\tau$ falls slightly below $\sigma_{vm}$ (printed above).
#
# ## 5. Strain rate and temperature move the curve
#
# Uniaxial stress, heating off: rates 1, $10^3$, $10^5$ /s at room temperature; temperatures 293, 600, 900 K at
# $10^3$ /s. The curves are compared on a common grid of $\bar\epsilon_p$ (interpolated).

# %%
ep_cmp = np.linspace(0.03, 0.4, 30)
curves_rate = {r: uniaxial(jc, r, T0) for r in (1.0, 1e3, 1e5)}
curves_T = {T: (uni if T == T0 else uniaxial(jc, RATE_MP, T)) for T in (293.0, 600.0, 900.0)}


def on_grid(o):
    return np.interp(ep_cmp, o["eps_p"], o["sigma"][:, 0, 0])


s_rate = np.array([on_grid(o) for o in curves_rate.values()])
s_T = np.array([on_grid(o) for o in curves_T.values()])
assert np.all(np.diff(s_rate, axis=0) > 0), "higher rate must give a higher curve"
assert np.all(np.diff(s_T, axis=0) < 0), "higher temperature must give a lower curve"
for (r, o), s in zip(curves_rate.items(), s_rate):
    print(f"rate {r:7.0e} /s: sigma at eps_p = 0.2: {np.interp(0.2, ep_cmp, s) / 1e6:6.0f} MPa "
          f"(rate factor {1 + jc.C * math.log(max(r / jc.eps_dot_0, 1)):.3f})")
for (T, o), s in zip(curves_T.items(), s_T):
    print(f"T = {T:4.0f} K:       sigma at eps_p = 0.2: {np.interp(0.2, ep_cmp, s) / 1e6:6.0f} MPa "
          f"(thermal factor {float(yield_stress(jc, 0, 1, T)) / jc.A:.3f})")

# %% [markdown]
# **Which melting temperature?** Table 1 of the paper prints $T_m$ = 1293 K for the 4340 steel; the usual value
# (Johnson & Cook 1985 and most codes) is 1793 K. The Taylor bar and the cutting chip heat to several hundred
# kelvin, so the choice matters: at the same temperature the material with the lower $T_m$ is softer.

# %%
T_cmp = np.array([400.0, 500.0, 600.0])
ratio = yield_stress(jc, 0.1, RATE_MP, T_cmp) / yield_stress(jc_1793, 0.1, RATE_MP, T_cmp)
for T, q in zip(T_cmp, ratio):
    print(f"T = {T:.0f} K: sigma_y(T_m = 1293 K) / sigma_y(T_m = 1793 K) = {q:.3f}  ({100 * (1 - q):.1f} % softer)")
assert np.all(ratio < 1) and np.all(np.diff(ratio) < 0)
curves_Tm = {Tm: uniaxial(j, RATE_MP, 500.0) for Tm, j in ((1293.0, jc), (1793.0, jc_1793))}

fig, axes = plt.subplots(1, 3, figsize=(16, 4.6), constrained_layout=True)
ax = axes[0]
for (r, o), c in zip(curves_rate.items(), ("C0", "C1", "C3")):
    ax.plot(o["eps_p"], o["sigma"][:, 0, 0] / 1e6, c, label=f"{r:.0e} /s")
    ax.plot(ep_an, yield_stress(jc, ep_an, r, T0) / 1e6, "k--", lw=0.7)
ax.set_title(f"rate, T = {T0:.0f} K (dashed: Eq. 25)")
ax = axes[1]
for (T, o), c in zip(curves_T.items(), ("C0", "C1", "C3")):
    ax.plot(o["eps_p"], o["sigma"][:, 0, 0] / 1e6, c, label=f"{T:.0f} K")
    ax.plot(ep_an, yield_stress(jc, ep_an, RATE_MP, T) / 1e6, "k--", lw=0.7)
ax.set_title(f"temperature, {RATE_MP:.0e} /s, T_m = {jc.T_melt:.0f} K")
for ax in axes[:2]:
    ax.set_xlabel(r"$\bar\epsilon_p$")
    ax.set_ylabel(r"uniaxial stress $\sigma_{xx}$ [MPa]")
    ax.legend()
ax = axes[2]
T_line = np.linspace(T0, 1300.0, 300)
for Tm, j, c in ((1293.0, jc, "C3"), (1793.0, jc_1793, "C0")):
    ax.plot(T_line, yield_stress(j, 0.1, RATE_MP, T_line) / 1e6, c, label=f"$T_m$ = {Tm:.0f} K, Eq. (25)")
    o = curves_Tm[Tm]
    ax.plot(500.0, np.interp(0.1, o["eps_p"], o["sigma"][:, 0, 0]) / 1e6, c + "o", ms=7,
            label=f"$T_m$ = {Tm:.0f} K, material point at 500 K")
ax.axvspan(400, 600, color="grey", alpha=0.15)
ax.set_xlabel("T [K]")
ax.set_ylabel(r"$\sigma_y(\bar\epsilon_p = 0.1)$ [MPa]")
ax.set_title(f"T_m = 1293 K (Table 1) vs 1793 K, {RATE_MP:.0e} /s")
ax.legend()
fig.savefig(FIG / "04_rate_temperature.png", dpi=120)
plt.show()

# %% [markdown]
# The rate effect of 4340 is weak ($C$ = 0.014: about 10 % from 1 to $10^3$ /s, since
# $1 + C\ln 10^3 \approx 1.1$); temperature matters much more, and $T_m$ = 1293 K makes the steel noticeably
# softer than $T_m$ = 1793 K everywhere above room temperature (ratios printed above).
#
# ## 6. Adiabatic heating and thermal softening
#
# With heating on, each step adds $\Delta T = \chi\Delta w_p/(\rho C_p)$. In simple shear $\mathrm{tr}\,\mathbf l = 0$,
# so $\rho$ stays $\rho_0$ and the temperature rise must be exactly $\chi W_p/(\rho_0 C_p)$.
#
# An independent check of the whole adiabatic curve: since $\mathrm dW_p = \sigma_y\,\mathrm d\bar\epsilon_p$ on
# the yield surface (Eq. 31), the temperature as a function of plastic strain obeys the ODE
# $$\frac{\mathrm dT}{\mathrm d\bar\epsilon_p} = \frac{\chi}{\rho_0 C_p}\,\sigma_y(\bar\epsilon_p, \dot{\bar\epsilon}, T),
#   \qquad T(0) = T_r,$$
# which `scipy.integrate.solve_ivp` solves to $10^{-10}$; the adiabatic stress–strain curve is then
# $\sigma_y(\bar\epsilon_p, \dot{\bar\epsilon}, T(\bar\epsilon_p))$. The material point must follow it up to its
# first-order lag (now in both $\bar\epsilon_p$ and $T$).

# %%
RATE_AD = 1e4
STRAIN_AD = 2.0                                   # equivalent total strain (gamma = 3.5)
N_AD = 1000 if QUICK else 5000
iso = shear(jc, RATE_AD, T0, n=N_AD, strain=STRAIN_AD, heating=False)
adi = shear(jc, RATE_AD, T0, n=N_AD, strain=STRAIN_AD, heating=True)

dT_expected = jc.chi * adi["W_p"] / (mat.rho0 * jc.cp)
err_T = np.abs((adi["T"] - T0) - dT_expected).max() / dT_expected.max()
print(f"adiabatic shear: T rises to {adi['T'][-1]:.0f} K; max |(T - T_r) - chi W_p/(rho C_p)| / dT_max = {err_T:.1e}")
assert err_T < 1e-12
assert np.all(iso["T"] == T0)
err_surface, _ = on_yield_surface(adi, jc)
assert err_surface < 1e-13                         # on the yield surface at the start-of-step eps_p and T

ode = solve_ivp(lambda e, T: jc.chi / (mat.rho0 * jc.cp) * yield_stress(jc, e, RATE_AD, T),
                (0.0, adi["eps_p"][-1]), [T0], rtol=1e-10, atol=1e-8, dense_output=True)
T_ode = ode.sol(adi["eps_p"])[0]
m = adi["eps_p"] > 0.02
err_T_ode = np.abs(adi["T"][m] - T_ode[m]).max()
err_s_ode = np.abs(adi["sigma_vm"][m] / yield_stress(jc, adi["eps_p"][m], RATE_AD, T_ode[m]) - 1).max()
lag_ad = one_step_hardening(adi, jc, RATE_AD, m)
# the thermal lag: one step's heating lowers sigma_y too, so the lag bound is the size of the total step change
sy_k = yield_stress(jc, adi["eps_p"], RATE_AD, adi["T"])
step_change = np.abs(np.diff(sy_k) / sy_k[:-1])[m[1:]].max()
print(f"vs the ODE (eps_p > 0.02): max |T - T_ode| = {err_T_ode:.2f} K, max relative stress error "
      f"{err_s_ode:.1e} (largest one-step change of sigma_y there: {step_change:.1e})")
assert err_s_ode < 2 * step_change + 2e-4
assert err_T_ode < 0.01 * (adi["T"][-1] - T0)

k_peak = int(np.argmax(adi["sigma_vm"]))
soft = 1 - adi["sigma_vm"][-1] / iso["sigma_vm"][-1]
print(f"adiabatic peak von Mises stress {adi['sigma_vm'][k_peak] / 1e6:.0f} MPa at eps_p = "
      f"{adi['eps_p'][k_peak]:.2f} (T = {adi['T'][k_peak]:.0f} K); at eps_p = {adi['eps_p'][-1]:.2f} the "
      f"adiabatic stress is {100 * soft:.0f} % below the isothermal one")
assert adi["sigma_vm"][-1] < iso["sigma_vm"][-1] and 0 < k_peak < N_AD

gam_iso = 2 * iso["strain"][:, 0, 1]
gam_adi = 2 * adi["strain"][:, 0, 1]
fig, axes = plt.subplots(1, 2, figsize=(13, 4.6), constrained_layout=True)
ax = axes[0]
ax.plot(gam_iso, iso["S"][:, 0, 1] / 1e6, "k", label="isothermal (heating off)")
ax.plot(gam_adi, adi["S"][:, 0, 1] / 1e6, "C3", label="adiabatic (Eq. 28)")
ax.plot(gam_adi[k_peak], adi["S"][k_peak, 0, 1] / 1e6, "C3o")
ax.set_xlabel(r"shear strain $\gamma$")
ax.set_ylabel(r"shear stress $\tau$ [MPa]")
ax.set_title(f"4340 (T_m = {jc.T_melt:.0f} K), simple shear at an equivalent rate of {RATE_AD:.0e} /s")
ax.legend()
ax = axes[1]
ax.plot(adi["eps_p"], adi["T"], "C3", lw=2.5, label="material point")
ax.plot(adi["eps_p"], T_ode, "k--", label=r"ODE $dT/d\bar\epsilon_p = \chi\sigma_y/(\rho C_p)$")
ax.set_xlabel(r"$\bar\epsilon_p$")
ax.set_ylabel("T [K]")
ax.set_title("temperature of the adiabatic particle")
ax.legend()
fig.savefig(FIG / "04_adiabatic_shear.png", dpi=120)
plt.show()

# %% [markdown]
# Hardening wins at first, but the hardening rate $Bn\bar\epsilon_p^{\,n-1}$ falls while the heating
# ($\propto\sigma_y$) does not, so the adiabatic curve reaches a maximum and then softens. A material point
# cannot localise, but in a body the first region past that maximum deforms more, heats more, softens more:
# this is the adiabatic shear band that segments the chip in high-speed machining.
#
# ## 7. The modified Johnson–Cook law (Rodriguez Prieto, Larsson & Afrasiabi)
#
# For AISI 1045 the second paper stops the hardening at $\bar\epsilon_p = 2$, where dislocation generation and
# annihilation balance (their Eqs. 8–9):
# $$\sigma_y = \big[A + B\min(\bar\epsilon_p, 2)^n\big]\big[1 + C\ln\dot\epsilon^*\big]\big[1 - T^{*m}\big].$$
# In `refsph` this is `ModifiedJohnsonCook(..., hardening_saturation_strain=2.0)`; `JohnsonCook(...)` gives Eq. (25)
# as printed.
# The constants are those of their Tables 1–2 (`refsph.paper_data.AISI1045_RLA`; $\dot\epsilon_0$ = 0.004 /s).

# %%
jc_1045_plain = JohnsonCook(**{f.name: getattr(jc_1045, f.name) for f in fields(JohnsonCook)})
ep4 = np.linspace(0.0, 4.0, 801)
RATE_1045 = 1e4
s_mod = yield_stress(jc_1045, ep4, RATE_1045, jc_1045.T_room)
s_org = yield_stress(jc_1045_plain, ep4, RATE_1045, jc_1045.T_room)
below, above = ep4 <= 2.0, ep4 >= 2.0
assert np.array_equal(s_mod[below], s_org[below])
assert np.all(s_mod[above] == s_mod[above][0]) and np.all(s_org[above][1:] > s_mod[above][1:])
print(f"1045 at {RATE_1045:.0e} /s, {jc_1045.T_room:.0f} K: sigma_y(2) = {s_mod[above][0] / 1e6:.0f} MPa; at eps_p = 4 "
      f"original {s_org[-1] / 1e6:.0f} MPa, modified {s_mod[-1] / 1e6:.0f} MPa "
      f"({100 * (s_org[-1] / s_mod[-1] - 1):.1f} % difference)")

N_1045 = 800 if QUICK else 4000
mp_1045 = {name: shear(j, RATE_1045, jc_1045.T_room, n=N_1045, strain=4.2, material=mat_1045)
           for name, j in (("original", jc_1045_plain), ("modified", jc_1045))}
for name, j in (("original", jc_1045_plain), ("modified", jc_1045)):
    assert on_yield_surface(mp_1045[name], j)[0] < 1e-13
flat = mp_1045["modified"]["eps_p"] > 2.0 + 4.0 / N_1045          # steps whose start-of-step eps_p is past 2
assert np.allclose(mp_1045["modified"]["sigma_vm"][flat], s_mod[-1], rtol=1e-13)
svm_flat = mp_1045["modified"]["sigma_vm"][flat]
print(f"material point (modified law): sigma_vm after eps_p > 2 stays at {svm_flat.mean() / 1e6:.1f} MPa "
      f"to {np.ptp(svm_flat) / s_mod[-1]:.0e} relative")

fig, ax = plt.subplots(figsize=(7.5, 4.6), constrained_layout=True)
ax.plot(ep4, s_org / 1e6, "k--", label="Johnson–Cook, Eq. (25)")
ax.plot(ep4, s_mod / 1e6, "C3", label="modified: hardening stops at 2")
for (name, o), c in zip(mp_1045.items(), ("C7", "C0")):
    k = np.flatnonzero(o["eps_p"] > 0)[::max(1, N_1045 // 60)]
    ax.plot(o["eps_p"][k], o["sigma_vm"][k] / 1e6, c + "o", ms=3, label=f"material point, simple shear ({name})")
ax.axvline(2.0, color="grey", lw=0.8)
ax.set_xlabel(r"$\bar\epsilon_p$")
ax.set_ylabel(r"$\sigma_y$ [MPa]")
ax.set_title(f"AISI 1045 (Rodriguez Prieto et al.), {RATE_1045:.0e} /s, {jc_1045.T_room:.0f} K, heating off")
ax.legend()
fig.savefig(FIG / "04_modified_jc.png", dpi=120)
plt.show()

# %% [markdown]
# Below $\bar\epsilon_p = 2$ the two laws are identical (asserted bit for bit); above it the modified one is flat.
# The material points follow each law; the modified one has a small kink at 2 and no hardening after it,
# which matters in the primary shear zone of a chip, where plastic strains of 2–5 are common.
#
# ## 8. Where it fails, and what it leaves out
#
# **(a) The explicit hardening lag.** $\sigma_y$ uses the start-of-step $\bar\epsilon_p$ and $T$: first order in
# $\Delta t$ (Section 4). Its size is one step's hardening relative to the yield stress,
# $Bn\bar\epsilon_p^{\,n-1}\Delta\bar\epsilon_p/\sigma_y$; at SPH time steps the plastic strain per step is
# $10^{-4}$ ($10^4$ /s × $10^{-8}$ s) or less (4340, $10^4$ /s, room temperature):
#
# %%
for ep in (1e-3, 1e-2, 0.1, 1.0):
    d_ep = 1e-4
    lag = yield_stress(jc, ep, 1e4, T0) / yield_stress(jc, ep - d_ep, 1e4, T0) - 1
    print(f"eps_p = {ep:5.0e}: lag of one step of d eps_p = {d_ep:.0e} is {100 * lag:.3f} % of sigma_y")

# %% [markdown]
# Only the first steps after yield see more than a fraction of a percent. An implicit (Newton) return map that
# solves $\sigma_{vm}^{trial} - 3\mu\Delta\bar\epsilon_p = \sigma_y(\bar\epsilon_p + \Delta\bar\epsilon_p, \dots)$
# would remove it; the paper and `refsph` do not.
#
# **(b) No damage, no failure.** The yield stress never falls with strain (only with temperature), and nothing
# in the model lets a particle lose its strength: there is no Johnson–Cook damage criterion and no erosion. Chip
# separation at the tool tip therefore comes from the discretisation (particles pulling apart), not from the
# material law.
#
# **(c) At and above $T_m$ the material is a fluid.** $T^*\ge1$ gives $\sigma_y = 0$: the return map sets the
# deviator to zero ($c_f = 0$), books the whole trial deviator as plastic strain and does no plastic work, so a
# molten particle stops heating and keeps only its pressure:

# %%
S_trial = np.array([[[0.0, 300e6, 0.0], [300e6, 0.0, 0.0], [0.0, 0.0, 0.0]]])
for T in (jc.T_melt - 50.0, jc.T_melt, jc.T_melt + 100.0):
    S_n, _, deps, dw, dT = plastic_update(S_trial, np.zeros(1), np.array([0.5]), np.array([T]),
                                          np.array([mat.rho0]), np.array([1e4]), jc, mat.G)
    print(f"T = {T:6.0f} K: sigma_y = {float(yield_stress(jc, 0.5, 1e4, T)) / 1e6:7.2f} MPa, |s_n| = "
          f"{np.abs(S_n).max() / 1e6:7.2f} MPa, d eps_p = {deps[0]:.2e}, d w_p = {dw[0]:.2e} J/m^3, dT = {dT[0]:.2e} K")
    if T >= jc.T_melt:
        assert np.all(S_n == 0) and dw[0] == 0 and deps[0] > 0

# %% [markdown]
# The thermal factor also has infinite slope at $T^* \to 0^+$ when $m < 1$ (not for 4340's $m = 1.03$, but e.g.
# for many aluminium fits), and with the Table 1 value $T_m$ = 1293 K a 4340 particle reaches zero strength
# 500 K earlier than with the usual 1793 K (Section 5).
#
# **(d) The clamped rate term.** $\ln\max(\dot\epsilon^*, 1)$ has a kink at $\dot\epsilon_0$ and no rate effect
# below it: a choice (Abaqus, LS-DYNA), not part of the 1983 model. For 4340 with $\dot\epsilon_0$ = 1 /s it only
# matters in quasi-static regions; for the 1045 law with $\dot\epsilon_0$ = 0.004 /s it almost never does. The
# unclamped form would give a particle that stops flowing a lower yield stress (at $\dot\epsilon^* = 10^{-6}$ the
# 4340 rate factor would be 0.81 — printed in Section 1) and $-\infty$ at rest. The rate is also the *total*
# equivalent rate of the step (Section 3), which over-estimates the plastic rate in elastic unloading/reloading
# particles — harmless, since those are below the yield surface anyway.
#
# **(e) Adiabatic.** No heat conduction: each particle keeps its own heat. At cutting speeds the primary shear
# zone is close to adiabatic, but the tool–chip contact and the thin secondary shear zone are not; conduction
# (and the friction heating of the second paper) belong to a later issue. $C_p$ and $\chi$ are constants, and
# the elastic constants do not soften with temperature.
#
# **(f) The model itself.** Multiplicative (the three effects do not interact), fitted over a limited range of
# strain, rate and temperature, so the plastic strains of several units and rates of $10^5$–$10^6$ /s in a chip
# are extrapolation; isotropic hardening (no Bauschinger effect); the yield stress follows the current rate
# and temperature instantly (no history).
#
# ## Summary
#
# * Eqs. (25)–(31): a yield stress that is a product of hardening, rate and thermal factors; a radial (Wilkins)
#   return that is exact for von Mises with a fixed yield stress; plastic strain, plastic work
#   ($\Delta w_p = \sigma_y\Delta\bar\epsilon_p$) and the increment form of Eq. (28). The plain scalar loop and
#   `plastic_update` agree to round-off in 3D and 2D plane strain.
# * Eq. (26) takes the total equivalent rate of the step; the previous step's plastic rate chatters and, once
#   the time step is small, loses the rate effect altogether. Below the reference rate the rate factor is 1.
# * One particle in uniaxial stress or simple shear lies on the Johnson–Cook curve, exactly on the yield surface
#   at the start-of-step values, and within one step's hardening of the analytic curve (first order in the step).
# * Rate raises the curve, temperature lowers it; Table 1's $T_m$ = 1293 K makes 4340 markedly softer than
#   1793 K at the temperatures of impact and cutting.
# * Adiabatic heating: $T - T_r = \chi W_p/(\rho C_p)$ to round-off, matching the heating ODE; the adiabatic
#   shear curve peaks and softens — the seed of shear localisation.
# * The modified law of Rodriguez Prieto et al. is the same up to $\bar\epsilon_p = 2$ and flat after it.

# %%
print(f"chapter wall time: {time.perf_counter() - T_START:.1f} s (quick mode: {QUICK})")
