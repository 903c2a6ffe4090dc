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
# **Why.** Chapters 2 and 3 gave every particle a deviatoric stress that grows without limit: an elastic solid.
# A metal stops carrying more shear stress once it yields; then it flows, gets harder as it flows (strain
# hardening), stronger when deformed fast (rate hardening) and softer when hot (thermal softening) — and the
# plastic work heats it. In an explicit SPH code all of this happens at the end of every stress update, particle
# by particle: the elastic trial stress is pulled back onto the yield surface (a *return map*), and the plastic
# strain, plastic work and temperature are updated. Nothing here couples particles, so one **material point** —
# one particle with a prescribed velocity gradient — is the complete test bench.
#
# The lesson: the equations; the return map as a plain loop, and the package checked against it; which strain
# rate to use; one particle against the analytic curve; adiabatic heating and softening; the modified law; where
# the model fails.

# %%
import math
from dataclasses import replace
import matplotlib.pyplot as plt
import numpy as np
from scipy.integrate import solve_ivp
from refsph.teaching.material_point import material_point
from refsph.plasticity import (JohnsonCook, ModifiedJohnsonCook, equivalent_strain_rate, plastic_strain_increment,
                               radial_return, yield_stress)
from refsph.strength import plastic_update
from refsph.scenes.taylor import taylor_johnson_cook, taylor_material
from refsph.teaching.notebook import chapter
ch = chapter("04_johnson_cook")

# %%
mat = taylor_material()                     # Table 1: rho = 7830 kg/m^3, mu = 82.9 GPa, K = 169.1 GPa
jc = taylor_johnson_cook(1293.0, 1.0)       # Table 1 as printed (T_m = 1293 K); reference rate 1 /s
T0 = jc.T_room
print(f"4340 (Table 1): A = {jc.A / 1e6:.0f} MPa, B = {jc.B / 1e6:.0f} MPa, n = {jc.n}, C = {jc.C}, m = {jc.m}, "
      f"T_room = {jc.T_room} K, T_melt = {jc.T_melt} K, C_p = {jc.cp} J/(kg K), chi = {jc.chi}")

# %% [markdown]
# ## 1. The equations
#
# ### Yield stress (Eqs. 25–27)
#
# $$\sigma_y = \underbrace{\big[A + B\,\bar\epsilon_p^{\,n}\big]}_{\text{strain hardening}}\;
#   \underbrace{\big[1 + C\ln\dot\epsilon^*\big]}_{\text{rate}}\;
#   \underbrace{\big[1 - T^{*m}\big]}_{\text{thermal}}
#   \quad(25),\qquad
#   \dot\epsilon^* = \frac{\dot{\bar\epsilon}}{\dot\epsilon_0}\quad(26),\qquad
#   T^* = \frac{T - T_r}{T_m - T_r}\quad(27).$$
#
# $\bar\epsilon_p$ is the accumulated effective plastic strain; $A$ the yield stress at room temperature and the
# reference rate $\dot\epsilon_0$; $B$, $n$ describe hardening, $C$ the rate sensitivity, $m$ the thermal softening,
# $T_r$ and $T_m$ are the room and melting temperatures. The three factors are independent, each measured
# separately.
#
# Two questions the paper leaves open:
#
# * **Rates below the reference rate.** $\ln\dot\epsilon^*\to-\infty$ as the rate goes to zero: a particle at
#   rest would have no strength. `refsph` uses $\ln\max(\dot\epsilon^*, 1)$ — no rate effect below the reference
#   rate, as in Abaqus and LS-DYNA.
# * **Which rate.** The paper says "the current effective plastic strain rate", but in an explicit code that rate
#   is only known *after* the return map that needs it. `refsph` uses the equivalent **total** deviatoric strain
#   rate of the step, $\dot{\bar\epsilon} = \sqrt{\tfrac23\,\dot{\mathbf e}:\dot{\mathbf e}}$ with
#   $\dot{\mathbf e}$ the deviator of $\tfrac12(\mathbf l + \mathbf l^T)$: known beforehand, and equal to the
#   plastic rate wherever the material flows (Section 3 shows why not the previous step's plastic rate).
#
# $T^*$ is clipped to $[0, 1]$: no extra strength below room temperature, none at all above melting.

# %% [markdown]
# ### Return map (Eqs. 29–31) and heating (Eq. 28)
#
# With $J_2 = \tfrac12\mathbf s:\mathbf s$, the material is elastic while the von Mises stress
# $\sigma_{vm} = \sqrt{3J_2}$ stays below $\sigma_y$. A step first updates $\mathbf s$ elastically (Eq. 20); if this
# *trial* stress lies outside the yield surface, Wilkins' radial return scales it back:
#
# $$\mathbf s_n = c_f\,\mathbf s,\qquad c_f = \min\Big(\frac{\sigma_y}{\sqrt{3J_2}},\,1\Big).$$
#
# The stress removed, $(1-c_f)\mathbf s$, is $2\mu$ times the plastic strain increment; its equivalent value is the
# increment of $\bar\epsilon_p$; the plastic work density is the returned stress times the plastic strain:
#
# $$\Delta\boldsymbol\epsilon_{pl} = \frac{1-c_f}{2\mu}\,\mathbf s\quad(29),\qquad
#   \Delta\bar\epsilon_p = \frac{(1-c_f)\,\sigma_{vm}^{trial}}{3\mu}\quad(30),\qquad
#   \Delta w_p = \Delta\boldsymbol\epsilon_{pl}:\mathbf s_n = \sigma_y\,\Delta\bar\epsilon_p\quad(31).$$
#
# A fraction $\chi$ (Taylor–Quinney, 0.9) of the plastic work becomes heat; with no conduction (adiabatic)
#
# $$\Delta T = \frac{\chi\,\Delta w_p}{\rho\,C_p}\quad(28).$$
#
# The paper prints Eq. (28) as $dT/dt = \chi W_p/(\rho C_p)$ with $W_p$ the *accumulated* work; that is not a rate,
# and it would keep heating a particle that has stopped flowing. The increment form is what is meant.
#
# **Order within a step** (`plastic_update`): $\sigma_y$ from the *start-of-step* $\bar\epsilon_p$ and $T$ and the
# step's total rate; then the return; then Eqs. (30), (31), (28). The three factors of Eq. (25) for 4340:

# %%
eps_grid, rate_grid, T_grid = np.linspace(0.0, 1.0, 401), np.logspace(-6, 6, 400), np.linspace(200.0, 1850.0, 400)
f_hard = yield_stress(jc, eps_grid, jc.eps_dot_0, T0)
f_rate = yield_stress(jc, 0.0, rate_grid * jc.eps_dot_0, T0) / jc.A      # the clamped rate factor of refsph
f_rate_printed = 1.0 + jc.C * np.log(rate_grid)
f_T = yield_stress(jc, 0.0, jc.eps_dot_0, T_grid) / jc.A
assert np.allclose(f_hard, jc.A + jc.B * eps_grid**jc.n, rtol=1e-14)
assert np.all(f_rate[rate_grid <= 1.0] == 1.0) and np.allclose(f_rate[rate_grid > 1], f_rate_printed[rate_grid > 1])
assert np.all(f_T[T_grid <= T0] == 1.0) and np.all(f_T[T_grid >= jc.T_melt] == 0.0)

fig, axes = plt.subplots(1, 3, figsize=(10, 3.8), constrained_layout=True)
axes[0].plot(eps_grid, f_hard / 1e6, "k")
axes[0].set(xlabel=r"plastic strain $\bar\epsilon_p$ [-]", ylabel=r"$A + B\bar\epsilon_p^n$ [MPa]",
            title="strain hardening")
axes[1].semilogx(rate_grid, f_rate_printed, "C3--", label="as printed")
axes[1].semilogx(rate_grid, f_rate, "k", label=r"$\ln\max(\dot\epsilon^*, 1)$")
axes[1].set(xlabel=r"$\dot\epsilon^* = \dot{\bar\epsilon}/\dot\epsilon_0$ [-]", ylabel="rate factor [-]",
            title=f"rate, C = {jc.C}")
axes[1].legend(loc="upper left")
axes[2].plot(T_grid, f_T, "k")
axes[2].set(xlabel="temperature T [K]", ylabel=r"$1 - T^{*m}$ [-]", title=f"thermal, m = {jc.m}")
for ax in axes:
    ax.grid(alpha=0.3)
ch.show(fig, "04_johnson_cook_factors.png", caption="The factors of the Johnson–Cook yield stress of 4340, Eq. (25): "
                                                    "strain hardening, rate (printed and clamped), thermal.")

# %% [markdown]
# The rate factor of 4340 is weak (small $C$); the thermal factor falls almost linearly to zero at $T_m$.
#
# ## 2. The return map as a plain loop
#
# Everything of Section 1 for one particle, in plain Python floats. The deviatoric stress is a list of rows
# ($d\times d$, $d$ = 2 or 3) plus, in 2D plane strain, the out-of-plane component $s_{zz}$.

# %%
def plain_yield_stress(jc, eps_p, eps_dot, T):
    """Eq. (25) for one particle, with the clamps of Section 1."""
    eps_p = max(eps_p, 0.0)
    if isinstance(jc, ModifiedJohnsonCook):                         # modified law (Section 6)
        eps_p = min(eps_p, jc.hardening_saturation_strain)
    rate_star = eps_dot / jc.eps_dot_0                              # Eq. (26)
    T_star = min(max((T - jc.T_room) / (jc.T_melt - jc.T_room), 0.0), 1.0)    # Eq. (27)
    return (jc.A + jc.B * eps_p**jc.n) * (1.0 + jc.C * math.log(max(rate_star, 1.0))) * (1.0 - T_star**jc.m)


def plain_equivalent_rate(l):
    """sqrt(2/3 e':e') of the symmetric part of l (d x d); in 2D the zz rate is 0 but its deviator is not."""
    d = len(l)
    D = [[0.5 * (l[a][b] + l[b][a]) for b in range(d)] for a in range(d)]
    tr = sum(D[a][a] for a in range(d))
    ee = sum((D[a][b] - (tr / 3.0 if a == b else 0.0)) ** 2 for a in range(d) for b in range(d))
    if d == 2:
        ee += (tr / 3.0) ** 2                                       # e'_zz of plane strain
    return math.sqrt(2.0 / 3.0 * ee)


def plain_return_map(s, s_zz, eps_p, T, rho, eps_dot, jc, G, heating=True):
    """Wilkins return + Eqs. (29)-(31) + Eq. (28) for one particle; s is the trial deviatoric stress."""
    d = len(s)
    ss = sum(s[a][b] ** 2 for a in range(d) for b in range(d)) + (s_zz**2 if d == 2 else 0.0)
    sigma_y = plain_yield_stress(jc, eps_p, eps_dot, T)
    y_f = math.sqrt(0.5 * ss) - sigma_y / math.sqrt(3.0)            # yield function sqrt(J2) - sigma_y / sqrt(3)
    c_f = sigma_y / math.sqrt(1.5 * ss) if y_f > 0.0 else 1.0
    s_n = [[c_f * s[a][b] for b in range(d)] for a in range(d)]
    s_zz_n = c_f * s_zz
    deps_pl = [[(1.0 - c_f) / (2.0 * G) * s[a][b] for b in range(d)] for a in range(d)]     # Eq. (29)
    deps_pl_zz = (1.0 - c_f) / (2.0 * G) * s_zz
    dd = sum(deps_pl[a][b] ** 2 for a in range(d) for b in range(d)) + (deps_pl_zz**2 if d == 2 else 0.0)
    deps_p = math.sqrt(2.0 / 3.0 * dd)                                                        # Eq. (30)
    dw_p = sum(deps_pl[a][b] * s_n[a][b] for a in range(d) for b in range(d))                # Eq. (31)
    if d == 2:
        dw_p += deps_pl_zz * s_zz_n
    dT = jc.chi * dw_p / (rho * jc.cp) if heating else 0.0                                   # Eq. (28)
    return dict(s_n=s_n, s_zz_n=s_zz_n, deps_pl=deps_pl, deps_p=deps_p, dw_p=dw_p, dT=dT, sigma_y=sigma_y)

# %% [markdown]
# Random trial states covering every branch — elastic and plastic, rates below and above the reference rate,
# temperatures below room and above melting, plastic strains up to 4 — for the Taylor 4340 and for the modified
# law of AISI 1045 (Section 6), in 3D and in 2D plane strain.

# %%
from refsph.material import ElasticMaterial
from refsph.paper_data import AISI1045_RLA as P45

jc45_args = dict(A=P45["A_Pa"], B=P45["B_Pa"], n=P45["n"], C=P45["C"], m=P45["m"], eps_dot_0=P45["eps_dot_0"],
                 T_room=P45["T_room_K"], T_melt=P45["T_melt_K"], cp=P45["cp_J_kgK"], chi=P45["taylor_quinney"])
jc_1045 = ModifiedJohnsonCook(**jc45_args, hardening_saturation_strain=P45["hardening_saturation_strain"])
jc_1045_plain = JohnsonCook(**jc45_args)
mat_1045 = ElasticMaterial(rho0=P45["rho"], E=P45["E_Pa"], nu=P45["nu"])


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
    target = rng.uniform(0.0, 4.5, n) * jc.A                        # trial von Mises stress 0 .. 4.5 A
    S *= (target / svm)[:, None, None]
    S_zz *= target / svm
    eps_p = np.where(rng.random(n) < 0.1, 0.0, rng.uniform(0.0, 4.0, n))
    T = rng.uniform(200.0, jc.T_melt + 200.0, n)
    eps_dot = jc.eps_dot_0 * 10.0 ** rng.uniform(-4.0, 7.0, n)
    return S, S_zz, eps_p, T, rng.uniform(0.9, 1.1, n) * 7800.0, eps_dot


N_RANDOM = 400
for name, jc_k, G_k in (("4340 (Table 1)", jc, mat.G), ("1045 (modified J-C)", jc_1045, mat_1045.G)):
    for d in (3, 2):
        S, S_zz, eps_p, T, rho, eps_dot = random_trial_states(N_RANDOM, d, jc_k, seed=10 * d + len(name))
        S_n, S_zz_n, deps, dw, dT = plastic_update(S, S_zz, eps_p, T, rho, eps_dot, jc_k, G_k)
        cf, _, _, svm_trial = radial_return(S, S_zz, yield_stress(jc_k, eps_p, eps_dot, T))
        ref = [plain_return_map(S[i].tolist(), float(S_zz[i]), float(eps_p[i]), float(T[i]), float(rho[i]),
                                float(eps_dot[i]), jc_k, G_k) for i in range(N_RANDOM)]
        # each quantity relative to its natural size for that particle (sigma_y: its room-temperature value)
        scale = dict(sigma_y=yield_stress(jc_k, eps_p, eps_dot, jc_k.T_room), s_n=svm_trial[:, None, None],
                     s_zz_n=svm_trial, deps_pl=svm_trial[:, None, None] / (2 * G_k), deps_p=svm_trial / (3 * G_k),
                     dw_p=svm_trial**2 / (3 * G_k), dT=jc_k.chi * svm_trial**2 / (3 * G_k * rho * jc_k.cp))
        pkg = dict(sigma_y=yield_stress(jc_k, eps_p, eps_dot, T), s_n=S_n, s_zz_n=S_zz_n,
                   deps_pl=plastic_strain_increment(S, cf, G_k), deps_p=deps, dw_p=dw, dT=dT)
        for key, val in pkg.items():
            if not (d == 3 and key == "s_zz_n"):
                rel = np.abs(val - np.array([q[key] for q in ref])) / scale[key]
                assert rel.max() < 1e-12, (key, rel.max())
        # plastic particles end on the yield surface, elastic ones are untouched, Eq. (31) is sigma_y d eps_p
        plastic, sy = deps > 0, pkg["sigma_y"]
        svm_n = np.sqrt(1.5 * (np.einsum("nab,nab->n", S_n, S_n) + (S_zz_n**2 if d == 2 else 0.0)))
        assert np.allclose(svm_n[plastic], sy[plastic], rtol=1e-13, atol=1e-12 * jc_k.A)
        assert np.array_equal(S_n[~plastic], S[~plastic])
        assert np.allclose(dw, sy * deps, rtol=1e-12, atol=0)
        l = np.random.default_rng(d).normal(scale=1e4, size=(50, d, d))          # the rate of Eq. (26)
        assert np.allclose(equivalent_strain_rate(l), [plain_equivalent_rate(li.tolist()) for li in l], rtol=1e-13)
        print(f"{name:20} {d}D: plain loop == plastic_update for {N_RANDOM} particles ({plastic.sum()} plastic, "
              f"{(sy == 0).sum()} above T_m)")

# %% [markdown]
# ## 3. Which strain rate in Eq. (26)?
#
# A material point in simple shear, $\mathbf l = \dot\gamma\,\mathbf e_x\otimes\mathbf e_y$, integrated like a
# particle in `refsph` (predictor–corrector: a half step with its own return map, then the full step; see
# `refsph.teaching.material_point`), with the plain return map. The one switch is the rate fed into Eq. (26):
# `"total"` (refsph), the equivalent total rate of the step; or `"plastic"`, the previous step's plastic rate
# $\Delta\bar\epsilon_p^{\,k-1}/\Delta t$.

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
        full = plain_return_map((s + dt * jaumann(np.array(half["s_n"]))).tolist(), 0.0, eps_p, T, 1.0, rate, jc,
                                G, False)
        s = np.array(full["s_n"])
        eps_p += full["deps_p"]
        rate_plastic = full["deps_p"] / dt                         # what "plastic" uses in the next step
        for key, val in (("svm", math.sqrt(1.5 * np.sum(s * s))), ("eps_p", eps_p), ("rate", rate), ("tau", s[0, 1])):
            out[key].append(val)
    return {k: np.array(v) for k, v in out.items()}


gd = math.sqrt(3.0) * 1e4                                           # equivalent rate 1e4 /s
chk = plain_shear_point(jc, mat.G, gd, 1e-8, 300, T0, "total")
mp = material_point(mat, jc, [[0, gd, 0], [0, 0, 0], [0, 0, 0]], 1e-8, 300, T0, heating=False)
assert np.allclose(chk["svm"], mp["sigma_vm"], rtol=1e-12, atol=1e-6)
assert np.allclose(chk["eps_p"], mp["eps_p"], rtol=1e-12, atol=1e-18)
assert np.allclose(chk["tau"], mp["S"][:, 0, 1], rtol=1e-12, atol=1e-6)
print("plain shear loop ('total') == refsph.teaching.material_point over 300 steps")

# %% [markdown]
# The two choices at an equivalent rate of $10^4$ /s, with three time steps around the paper's $10^{-8}$ s:

# %%
RATE_CH, STRAIN_CH = 1e4, 0.05
chatter = {}
for dt in (1e-7, 1e-8, 1e-9):
    n = int(round(STRAIN_CH / (RATE_CH * dt)))
    for mode in ("total", "plastic"):
        chatter[dt, mode] = plain_shear_point(jc, mat.G, math.sqrt(3.0) * RATE_CH, dt, n, T0, mode)
        chatter[dt, mode]["strain"] = RATE_CH * dt * np.arange(n + 1)

late = lambda a: a[len(a) // 2:]                                    # noqa: E731  second half of a run
assert np.allclose(chatter[1e-8, "total"]["svm"][-1], chatter[1e-9, "total"]["svm"][-1], rtol=1e-3)
for dt in (1e-8, 1e-9):
    tot, pla = chatter[dt, "total"], chatter[dt, "plastic"]
    jump_tot, jump_pla = np.abs(np.diff(late(tot["svm"]))).max(), np.abs(np.diff(late(pla["svm"]))).max()
    gap = late(pla["svm"]).mean() / late(tot["svm"]).mean() - 1
    step = 3.0 * mat.G * RATE_CH * dt                               # one step's elastic growth of the trial stress
    above_rate_free = late(pla["svm"]) / yield_stress(jc, late(pla["eps_p"]), jc.eps_dot_0, T0) - 1
    print(f"dt = {dt:.0e} s: largest step-to-step jump of sigma_vm: total rate {jump_tot / 1e6:.2f} MPa, previous "
          f"plastic rate {jump_pla / 1e6:.1f} MPa; mean stress with the plastic rate {100 * gap:+.1f} %")
    assert jump_pla > 10 * jump_tot and gap < -0.03
    assert np.all(above_rate_free > -0.01) and np.all(above_rate_free < 0.01 + 1.5 * step / jc.A)

fig, ax = plt.subplots(figsize=(10, 4.6), layout="constrained")
for dt, c in zip((1e-7, 1e-8, 1e-9), ("C2", "C0", "C3")):
    ax.plot(chatter[dt, "plastic"]["strain"], chatter[dt, "plastic"]["svm"] / 1e6, c, lw=0.7,
            label=f"plastic rate, dt = {dt:.0e} s")
ax.plot(chatter[1e-9, "total"]["strain"], chatter[1e-9, "total"]["svm"] / 1e6, "k", lw=2,
        label="total rate (refsph)")
ep_line = np.linspace(0.0, STRAIN_CH, 200)
for r_, ls in ((RATE_CH, "--"), (jc.eps_dot_0, ":")):
    sy_line = yield_stress(jc, ep_line, r_, T0)
    ax.plot(ep_line + sy_line / (3 * mat.G), sy_line / 1e6, "k" + ls, lw=1,
            label=f"Eq. (25), {r_:.0e} /s")
ax.set(xlabel=r"equivalent strain $\gamma/\sqrt{3}$ [-]", ylabel=r"von Mises stress $\sigma_{vm}$ [MPa]",
       ylim=(jc.A / 1e6 - 80, None), xlim=(0.0, STRAIN_CH), title=f"simple shear at {RATE_CH:.0e} /s")
fig.legend(loc="outside right center")
ch.show(fig, "04_johnson_cook_rate_chatter.png", caption="Simple shear at 10⁴ /s: the previous step's plastic rate "
                                                         "makes the return map chatter; the total rate does not.")

# %% [markdown]
# With the previous step's plastic rate the return map falls into a two-step cycle. After an elastic step the rate
# fed into Eq. (26) is zero, so the stress is returned to the *rate-free* yield stress, and that step takes two
# steps' worth of plastic strain. The next step then sees a yield stress raised by the whole rate term; if one
# step's elastic growth of the trial stress, $3\mu\dot{\bar\epsilon}\Delta t$, is smaller than that, the step is
# elastic — and so on. The stress saws just above the rate-free curve.

# %% [markdown]
# Consequences:
#
# * it **converges to the wrong answer**: the smaller the time step, the finer the sawtooth, but it hugs the
#   rate-free curve and the rate sensitivity is lost (asserted above). Only a large step escapes it;
# * in a body, neighbouring particles cycle with different phases: stress noise at the particle scale.
#
# The total rate is known before the return map, is the plastic rate wherever the material flows, and its curves
# for the three time steps coincide.
#
# ## 4. One particle against the analytic curve
#
# Heating off, room temperature, $10^3$ /s, two loadings with `material_point`:
#
# * **uniaxial stress** along $x$ ($l_{yy} = l_{zz}$ found each step so that $\sigma_{yy} = \sigma_{zz} = 0$). Then
#   $\sigma_{vm} = \lvert\sigma_{xx}\rvert$ and the plastic strain can be read off independently of the package,
#   $\bar\epsilon_p = \epsilon_{xx} - \sigma_{xx}/E$;
# * **simple shear**, $\dot\gamma = \sqrt3\times10^3$ /s.
#
# **The one-step lag.** $\sigma_y$ uses the $\bar\epsilon_p$ of the *start* of the step, so the curve lies below the
# analytic one by one step's hardening, $Bn\bar\epsilon_p^{\,n-1}\Delta\bar\epsilon_p$: large right after yield,
# small later, and first order in the step. We assert (i) after every plastic step $\sigma_{vm} = \sigma_y$ at the
# start-of-step values to round-off, and (ii) the analytic curve within one step's hardening for
# $\bar\epsilon_p > 0.02$.

# %%
N_MP = 400 if ch.quick else 2000           # material-point steps to an equivalent strain of STRAIN_MP
STRAIN_MP, RATE_MP = 0.5, 1e3


def uniaxial(jc, rate, T, n=N_MP, strain=STRAIN_MP):
    return material_point(mat, jc, np.diag([rate, 0.0, 0.0]), strain / (rate * n), n, T, heating=False,
                          lateral_stress_free=True)


def shear(jc, rate, T, n=N_MP, strain=STRAIN_MP, heating=False, material=mat):
    gdot = math.sqrt(3.0) * rate                                    # equivalent rate = gdot / sqrt(3)
    return material_point(material, jc, [[0, gdot, 0], [0, 0, 0], [0, 0, 0]], strain / (rate * n), n, T,
                          heating=heating)


def on_yield_surface(o, jc):
    """max |sigma_vm / sigma_y - 1| over plastic steps, sigma_y at the start-of-step eps_p, T and the step's rate."""
    plastic = np.diff(o["eps_p"]) > 0
    sy_start = yield_stress(jc, o["eps_p"][:-1], o["eps_dot"][1:], o["T"][:-1])
    return np.abs(o["sigma_vm"][1:][plastic] / sy_start[plastic] - 1).max()


def one_step_hardening(o, jc, rate, mask):
    """Largest relative yield-stress increase over one step, where mask."""
    a = yield_stress(jc, o["eps_p"][1:], rate, o["T"][1:])
    b = yield_stress(jc, o["eps_p"][:-1], rate, o["T"][:-1])
    return (a / b - 1)[mask[1:]].max()


uni, shr = uniaxial(jc, RATE_MP, T0), shear(jc, RATE_MP, T0)
s_xx = uni["sigma"][:, 0, 0]
ep_curve = uni["strain"][:, 0, 0] - s_xx / mat.E                   # plastic strain read off the curve
assert np.abs(uni["sigma"][:, 1:, 1:]).max() < 1.0 and np.abs(ep_curve - uni["eps_p"]).max() < 1e-5
for name, o, sig, ep in (("uniaxial", uni, s_xx, ep_curve), ("shear", shr, shr["sigma_vm"], shr["eps_p"])):
    m = o["eps_p"] > 0.02
    err = np.abs(sig[m] / yield_stress(jc, ep[m], RATE_MP, T0) - 1).max()
    tol = one_step_hardening(o, jc, RATE_MP, m) + 2e-4
    print(f"{name:8}: on the yield surface to {on_yield_surface(o, jc):.0e}; vs Eq. (25) for eps_p > 0.02: "
          f"{err:.1e} (one step's hardening {tol - 2e-4:.1e})")
    assert on_yield_surface(o, jc) < 1e-13 and err < tol

N_CONV = (100, 200, 400, 800) if ch.quick else (250, 500, 1000, 2000, 4000)
conv = {}
for n in N_CONV:
    o = shear(jc, RATE_MP, T0, n=n)
    conv[n] = (o["eps_p"], o["sigma_vm"] / yield_stress(jc, o["eps_p"], RATE_MP, T0) - 1)
errs = np.array([np.abs(rel[ep > 0.02]).max() for ep, rel in conv.values()])
orders = np.log2(errs[:-1] / errs[1:]) / np.log2(np.array(N_CONV[1:]) / np.array(N_CONV[:-1]))
print("observed order of the lag:", np.round(orders, 2))
assert np.all((orders > 0.85) & (orders < 1.15))

fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
ep_an = np.linspace(0.0, ep_curve.max(), 300)
axes[0].plot(ep_curve, s_xx / 1e6, "C0", lw=3, label=r"uniaxial $\sigma_{xx}$")
axes[0].plot(shr["eps_p"], shr["sigma_vm"] / 1e6, "C1", label=r"shear $\sigma_{vm}$")
axes[0].plot(ep_an, yield_stress(jc, ep_an, RATE_MP, T0) / 1e6, "k--", lw=1, label="Eq. (25)")
axes[0].set(xlabel=r"plastic strain $\bar\epsilon_p$ [-]", ylabel="stress [MPa]",
            title=f"4340, {RATE_MP:.0e} /s, {T0:.0f} K, heating off")
axes[0].legend()
for n, (ep_n, rel_n) in conv.items():
    axes[1].loglog(ep_n[1:], np.abs(rel_n[1:]) + 1e-16, label=f"{n} steps")
axes[1].set(xlabel=r"plastic strain $\bar\epsilon_p$ [-]", ylabel=r"$|\sigma_{vm}/\sigma_y - 1|$ [-]",
            ylim=(1e-5, 1e-1), title="the one-step lag (shear): first order")
axes[1].legend()
ch.show(fig, "04_johnson_cook_material_point.png", caption="A material point on Eq. (25) in tension and shear (left), "
                                                           "and its first-order lag behind the yield stress (right).")

# %% [markdown]
# Both loadings give the same $\sigma_{vm}(\bar\epsilon_p)$ curve: von Mises plasticity with isotropic hardening does
# not know the loading direction. Doubling the number of steps halves the lag.
#
# **Rate and temperature** move the curve: a higher rate raises it (Exercise 1), a higher temperature lowers it.
# Table 1 prints $T_m$ = 1293 K for 4340, where most codes use 1793 K; at the same temperature the lower $T_m$
# gives a softer steel (Exercise 3):

# %%
T_cmp = np.array([293.0, 400.0, 600.0, 900.0])
curves_T = np.array([yield_stress(jc, 0.2, RATE_MP, T) for T in T_cmp])
ratio = yield_stress(jc, 0.1, RATE_MP, T_cmp[1:]) / yield_stress(replace(jc, T_melt=1793.0), 0.1, RATE_MP, T_cmp[1:])
print("sigma_y(0.2) at", T_cmp, "K:", np.round(curves_T / 1e6), "MPa")
print("sigma_y(T_m = 1293 K) / sigma_y(T_m = 1793 K) at", T_cmp[1:], "K:", np.round(ratio, 3))
assert np.all(np.diff(curves_T) < 0) and np.all(ratio < 1) and np.all(np.diff(ratio) < 0)

# %% [markdown]
# ## 5. Adiabatic heating and thermal softening
#
# With heating on, each step adds $\Delta T = \chi\Delta w_p/(\rho C_p)$. In simple shear $\rho$ stays $\rho_0$, so
# $T - T_r = \chi W_p/(\rho_0 C_p)$ exactly. An independent check of the whole curve: since
# $\mathrm dW_p = \sigma_y\,\mathrm d\bar\epsilon_p$ on the yield surface,
#
# $$\frac{\mathrm dT}{\mathrm d\bar\epsilon_p} = \frac{\chi}{\rho_0 C_p}\,\sigma_y(\bar\epsilon_p, \dot{\bar\epsilon}, T),
#   \qquad T(0) = T_r,$$
#
# an ODE that `scipy.integrate.solve_ivp` solves accurately. The material point must follow it up to its one-step
# lag.

# %%
RATE_AD, STRAIN_AD = 1e4, 2.0
N_AD = 1000 if ch.quick else 5000
iso = shear(jc, RATE_AD, T0, n=N_AD, strain=STRAIN_AD, heating=False)
adi = shear(jc, RATE_AD, T0, n=N_AD, strain=STRAIN_AD, heating=True)

dT_expected = jc.chi * adi["W_p"] / (mat.rho0 * jc.cp)
assert np.abs((adi["T"] - T0) - dT_expected).max() < 1e-12 * dT_expected.max()
assert np.all(iso["T"] == T0) and on_yield_surface(adi, jc) < 1e-13

ode = solve_ivp(lambda e, T: jc.chi / (mat.rho0 * jc.cp) * yield_stress(jc, e, RATE_AD, T),
                (0.0, adi["eps_p"][-1]), [T0], rtol=1e-10, atol=1e-8, dense_output=True)
T_ode = ode.sol(adi["eps_p"])[0]
m = adi["eps_p"] > 0.02
err_s_ode = np.abs(adi["sigma_vm"][m] / yield_stress(jc, adi["eps_p"][m], RATE_AD, T_ode[m]) - 1).max()
sy_k = yield_stress(jc, adi["eps_p"], RATE_AD, adi["T"])
step_change = np.abs(np.diff(sy_k) / sy_k[:-1])[m[1:]].max()       # one step's change of sigma_y (hardening + heat)
print(f"T rises to {adi['T'][-1]:.0f} K; vs the ODE: max |T - T_ode| = {np.abs(adi['T'] - T_ode)[m].max():.2f} K, "
      f"stress {err_s_ode:.1e} (one step's change of sigma_y: {step_change:.1e})")
assert err_s_ode < 2 * step_change + 2e-4 and np.abs(adi["T"] - T_ode)[m].max() < 0.01 * (adi["T"][-1] - T0)
k_peak = int(np.argmax(adi["sigma_vm"]))
assert adi["sigma_vm"][-1] < iso["sigma_vm"][-1] and 0 < k_peak < N_AD

fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
axes[0].plot(2 * iso["strain"][:, 0, 1], iso["S"][:, 0, 1] / 1e6, "k", label="isothermal (heating off)")
axes[0].plot(2 * adi["strain"][:, 0, 1], adi["S"][:, 0, 1] / 1e6, "C3", label="adiabatic (Eq. 28)")
axes[0].plot(2 * adi["strain"][k_peak, 0, 1], adi["S"][k_peak, 0, 1] / 1e6, "C3o")
axes[0].set(xlabel=r"shear strain $\gamma$ [-]", ylabel=r"shear stress $\tau$ [MPa]",
            title=f"4340, simple shear at {RATE_AD:.0e} /s")
axes[0].legend()
axes[1].plot(adi["eps_p"], adi["T"], "C3", lw=3, label="material point")
axes[1].plot(adi["eps_p"], T_ode, "k--", label="ODE")
axes[1].set(xlabel=r"plastic strain $\bar\epsilon_p$ [-]", ylabel="temperature T [K]",
            title="temperature of the adiabatic particle")
axes[1].legend()
ch.show(fig, "04_johnson_cook_adiabatic.png", caption="Adiabatic shear softens past its maximum (left, the dot); the "
                                                      "particle's temperature follows the ODE of Eq. (28) (right).")

# %% [markdown]
# Hardening wins at first, but the hardening rate $Bn\bar\epsilon_p^{\,n-1}$ falls while the heating
# ($\propto\sigma_y$) does not, so the adiabatic curve reaches a maximum and then softens. A material point cannot
# localise, but in a body the first region past that maximum deforms more, heats more and softens more: the
# adiabatic shear band that segments the chip in high-speed machining.
#
# ## 6. The modified Johnson–Cook law
#
# For AISI 1045 Rodriguez Prieto et al. stop the hardening at $\bar\epsilon_p = 2$, where dislocation generation
# and annihilation balance: $A + B\min(\bar\epsilon_p, 2)^n$ in Eq. (25). In `refsph` this is
# `ModifiedJohnsonCook(..., hardening_saturation_strain=2.0)`; `JohnsonCook(...)` is Eq. (25) as printed.

# %%
ep4, RATE_1045 = np.linspace(0.0, 4.0, 801), 1e4
s_mod = yield_stress(jc_1045, ep4, RATE_1045, jc_1045.T_room)
s_org = yield_stress(jc_1045_plain, ep4, RATE_1045, jc_1045.T_room)
below, above = ep4 <= 2.0, ep4 >= 2.0
assert np.array_equal(s_mod[below], s_org[below])
assert np.all(s_mod[above] == s_mod[above][0]) and np.all(s_org[above][1:] > s_mod[above][1:])
N_1045 = 800 if ch.quick else 4000
mp_mod = shear(jc_1045, RATE_1045, jc_1045.T_room, n=N_1045, strain=4.2, material=mat_1045)
assert on_yield_surface(mp_mod, jc_1045) < 1e-13
flat = mp_mod["eps_p"] > 2.0 + 4.0 / N_1045                         # steps whose start-of-step eps_p is past 2
assert np.allclose(mp_mod["sigma_vm"][flat], s_mod[-1], rtol=1e-13)
print(f"1045 at eps_p = 4: Eq. (25) {s_org[-1] / 1e6:.0f} MPa, modified {s_mod[-1] / 1e6:.0f} MPa; the material "
      f"point stays at {mp_mod['sigma_vm'][flat].mean() / 1e6:.0f} MPa past eps_p = 2")

# %% [markdown]
# Below $\bar\epsilon_p = 2$ the two laws are identical (asserted bit for bit), above it the modified one is flat —
# which matters in the primary shear zone of a chip, where plastic strains of several units are common.
#
# ## 7. Where it fails
#
# * **The explicit lag.** $\sigma_y$ uses the start-of-step $\bar\epsilon_p$ and $T$: first order in $\Delta t$
#   (Section 4). An implicit (Newton) return map would remove it; the paper and `refsph` do not use one.
# * **No damage, no failure.** Nothing lets a particle lose its strength except temperature: no damage criterion,
#   no erosion. Chip separation comes from the discretisation, not from the material law.
# * **The clamped rate term** has a kink at $\dot\epsilon_0$ and no rate effect below it: a choice, not part of
#   the 1983 model.
# * **Adiabatic** (paper 1; conduction: `refsph.thermal`, Ch. 11); $C_p$, $\chi$ and the elastic constants do not
#   depend on temperature.
# * **The model itself** is multiplicative (the three effects do not interact), fitted over a limited range, so
#   the strains and rates in a chip are extrapolation; hardening is isotropic (no Bauschinger effect).
# * **At and above $T_m$ the material is a fluid.** $\sigma_y = 0$ gives $c_f = 0$: the whole trial deviator becomes
#   plastic strain, no plastic work is done, and a molten particle stops heating:

# %%
S_trial = np.array([[[0.0, 300e6, 0.0], [300e6, 0.0, 0.0], [0.0, 0.0, 0.0]]])
for T in (jc.T_melt - 50.0, jc.T_melt, jc.T_melt + 100.0):
    S_n, _, deps, dw, dT = plastic_update(S_trial, np.zeros(1), np.array([0.5]), np.array([T]),
                                          np.array([mat.rho0]), np.array([1e4]), jc, mat.G)
    print(f"T = {T:4.0f} K: |s_n| = {np.abs(S_n).max() / 1e6:6.2f} MPa, d eps_p = {deps[0]:.1e}, dT = {dT[0]:.1e} K")
    if T >= jc.T_melt:
        assert np.all(S_n == 0) and dw[0] == 0 and deps[0] > 0

# %% [markdown]
# ## Your turn
#
# Predict first, run, then open *What you should see*. The last exercise asks for code, graded against the package.
#
# ### Exercise 1 — Faster
#
# Predict: a bar of 4340 pulled at $10^5$ /s instead of $10^3$ /s. By what factor does its flow stress rise? And
# pulled at $10^{-2}$ /s, below the reference rate $\dot\epsilon_0$ = 1 /s?

# %% tags=["exercise"]
RATE = 1e3                # <- change this [1/s] (e.g. to 1e5, or 1e-2) and run the cell again
o = material_point(mat, jc, np.diag([RATE, 0.0, 0.0]), 0.3 / (RATE * 300), 300, T0, heating=False,
                   lateral_stress_free=True)
s_02 = np.interp(0.2, o["eps_p"], o["sigma"][:, 0, 0])              # flow stress at eps_p = 0.2
ratio = s_02 / yield_stress(jc, 0.2, jc.eps_dot_0, T0)
print(f"{RATE:.0e} /s: flow stress at eps_p = 0.2 is {s_02 / 1e6:.0f} MPa, {ratio:.3f} x the one at 1 /s; "
      f"1 + C ln(rate / eps_dot_0) = {1 + jc.C * math.log(RATE / jc.eps_dot_0):.3f}")
fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
ax.plot(o["eps_p"], o["sigma"][:, 0, 0] / 1e6)
ax.set(xlabel="plastic strain [-]", ylabel="uniaxial stress [MPa]", title=f"{RATE:.0e} /s")
ch.show(fig, caption="Uniaxial stress against plastic strain of one 4340 particle pulled at the exercise's rate.")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# Above the reference rate the whole curve is lifted by the factor $1 + C\ln\dot\epsilon^*$ (within the one-step
# lag), weakly, since $C$ is small for 4340. Below it the clamp makes the factor 1, while the printed formula would
# give a number *below* 1.
# </details>

# %% [markdown]
# ### Exercise 2 — How much of the work becomes heat?
#
# Predict: in adiabatic shear, what happens to the peak of the stress–strain curve if only half the plastic work
# becomes heat ($\chi$ = 0.45 instead of 0.9)? And with $\chi = 0$?

# %% tags=["exercise"]
CHI = 0.9                 # <- change this (e.g. to 0.45, or 0 = heating off) and run the cell again
o = shear(replace(jc, chi=CHI), RATE_AD, T0, n=500, strain=STRAIN_AD, heating=True)
k = int(np.argmax(o["sigma_vm"]))
print(f"chi = {CHI}: peak stress {o['sigma_vm'][k] / 1e6:.0f} MPa at eps_p = {o['eps_p'][k]:.2f}; at the end "
      f"{o['sigma_vm'][-1] / 1e6:.0f} MPa, T = {o['T'][-1]:.0f} K")
fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
ax.plot(2 * o["strain"][:, 0, 1], o["S"][:, 0, 1] / 1e6)
ax.set(xlabel="shear strain [-]", ylabel="shear stress [MPa]", title=f"adiabatic shear, chi = {CHI}")
ch.show(fig, caption="Shear stress against shear strain of one 4340 particle in adiabatic shear at 1e4 /s.")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# With less heating the particle gets less hot, the peak moves to a larger strain and the softening after it is
# milder. With $\chi = 0$ the temperature stays at room temperature and there is no peak at all: the curve hardens
# to the end, as the isothermal curve of Section 5.
# </details>

# %% [markdown]
# ### Exercise 3 — Which melting temperature?
#
# Predict: the same adiabatic shear with $T_m$ = 1793 K (the usual value for 4340) instead of Table 1's 1293 K.
# Is the particle hotter or colder at the end? Stronger or weaker?

# %% tags=["exercise"]
T_MELT = 1293.0           # <- change this [K] (e.g. to 1793) and run the cell again
o = shear(replace(jc, T_melt=T_MELT), RATE_AD, T0, n=500, strain=STRAIN_AD, heating=True)
k = int(np.argmax(o["sigma_vm"]))
print(f"T_m = {T_MELT:.0f} K: peak at eps_p = {o['eps_p'][k]:.2f}; at the end sigma_vm = "
      f"{o['sigma_vm'][-1] / 1e6:.0f} MPa, T = {o['T'][-1]:.0f} K")
fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
ax.plot(o["eps_p"], o["sigma_vm"] / 1e6)
ax.set(xlabel="plastic strain [-]", ylabel="von Mises stress [MPa]", title=f"T_m = {T_MELT:.0f} K")
ch.show(fig, caption="Von Mises stress against plastic strain of one 4340 particle in adiabatic shear at 1e4 /s.")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# With the higher $T_m$ every kelvin softens less, so the steel stays stronger, the peak comes later, and —
# because the stronger material does more plastic work per unit strain — the particle ends up *hotter*, yet still
# stronger. The choice of $T_m$ changes a machining simulation's forces and temperatures alike.
# </details>

# %% [markdown]
# ### Exercise 4 — Write the return map yourself
#
# Write the return map of Section 1 for $n$ particles, whole arrays, no loop: from the trial deviatoric stress `S`
# (n, d, d) [Pa] (and `S_zz` (n,) in 2D plane strain; zeros in 3D), the start-of-step `eps_p`, `T` [K], the density
# `rho` and the rate `eps_dot` [1/s], return $\mathbf s_n$, $s_{zz,n}$, $\Delta\bar\epsilon_p$, $\Delta w_p$ and
# $\Delta T$ (Eqs. 28–31), $\sigma_y$ from `yield_stress`. Predict: which case fails if $J_2$ leaves out $s_{zz}$?

# %% tags=["exercise"]
def my_return_map(S, S_zz, eps_p, T, rho, eps_dot, jc, G):
    """Radial return and Eqs. (28)-(31): (S_n, S_zz_n, d_eps_p, d_w_p, d_T) from the trial stress."""
    raise NotImplementedError("write the return map here")      # <- replace this line by your code


from refsph.teaching.grader import case, check
s_el = np.array([[[100e6, 50e6, 0.0], [50e6, -100e6, 0.0], [0.0, 0.0, 0.0]]])       # von Mises 194 MPa < A
s_2d = np.array([[[1.2e9, 5e8], [5e8, -0.6e9]]])                                     # with s_zz = -0.6 GPa
one = (np.array([0.1]), np.array([T0]), np.array([mat.rho0]), np.array([1e3]), jc, mat.G)   # eps_p, T, rho, rate
cases_ex4 = [case(s_el, np.zeros(1), *one, label="elastic: inside the yield surface"),
             case(10 * s_el, np.zeros(1), *one, label="3D, plastic, room temperature"),
             case(s_2d, np.array([-0.6e9]), *one, label="2D plane strain: s_zz is part of J2"),
             case(10 * s_el, np.zeros(1), one[0], one[1] + 1100.0, *one[2:], label="molten: sigma_y = 0")]
for d in (3, 2):
    cases_ex4.append(case(*random_trial_states(400, d, jc, seed=d), jc, mat.G, label=f"{d}D, 400 random states"))
report = check(my_return_map, plastic_update, cases_ex4, names=("S_n", "S_zz_n", "d eps_p", "d w_p", "d T"))

# %% [markdown]
# <details><summary>What you should see</summary>
#
# As handed out: `FAIL ... not written yet`. $J_2 = \frac12\mathbf s:\mathbf s$ includes $s_{zz}$ in plane strain:
# without it the 2D case returns to the wrong surface. Above $T_m$, $\sigma_y = 0$ and $c_f = 0$: the whole trial
# deviator becomes plastic strain, with no work done. When all six cases agree: `PASS`.
# </details>
