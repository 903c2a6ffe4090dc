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
# # Chapter 4 — worked solutions (lecturer's copy)
#
# Each solution runs in the namespace of `chapters/04_johnson_cook.py`, with the chapter's material point
# (`uniaxial`, `shear`) and Table 1's 4340: `refsph handout DIR --instructor` inserts it right after its exercise,
# and `tests/test_exercises.py` executes that copy in quick mode, so every number quoted here is asserted. This file
# does not run on its own.

# %% [markdown]
# ### Solution 1 — Faster
#
# The rate factor of Eq. (25) is $1 + C\ln(\dot\epsilon/\dot\epsilon_0)$ with $C$ = 0.014 (Table 1): at
# $10^3$ /s it is 1.097, at $10^5$ /s 1.161. The material point's flow stress at $\bar\epsilon_p$ = 0.2, divided by
# Eq. (25) at the reference rate, gives the same factors to within the one-step lag (a few $10^{-4}$ with 300
# steps). A hundred times faster is only 6 % stronger: 4340's rate sensitivity is weak.
#
# At $10^{-2}$ /s the printed formula would give $1 + C\ln 10^{-2}$ = 0.936, a steel *weaker* than at the
# reference rate and, at still lower rates, one with no strength at all. The clamp $\ln\max(\dot\epsilon^*, 1)$
# makes it exactly 1: below $\dot\epsilon_0$ there is no rate effect.

# %%
for rate in (1e-2, 1e3, 1e5):
    o_r = uniaxial(jc, rate, T0, n=300, strain=0.3)
    factor = np.interp(0.2, o_r["eps_p"], o_r["sigma"][:, 0, 0]) / yield_stress(jc, 0.2, jc.eps_dot_0, T0)
    law = 1 + jc.C * math.log(max(rate / jc.eps_dot_0, 1.0))
    print(f"{rate:.0e} /s: flow stress / Eq. (25) at 1 /s = {factor:.4f}; 1 + C ln max(rate*, 1) = {law:.4f}; "
          f"as printed {1 + jc.C * math.log(rate / jc.eps_dot_0):.4f}")
    assert abs(factor / law - 1) < 2e-3                         # the factor, to within the one-step lag
assert abs(1 + jc.C * math.log(1e-2) - 0.936) < 1e-3

# %% [markdown]
# ### Solution 2 — How much of the work becomes heat?
#
# The peak is where hardening and thermal softening balance: $\partial\sigma_y/\partial\bar\epsilon_p =
# Bn\bar\epsilon_p^{\,n-1}[\ldots]$ falls as the strain grows, while the softening per unit strain,
# $-\frac{\partial\sigma_y}{\partial T}\frac{dT}{d\bar\epsilon_p}$ with $\frac{dT}{d\bar\epsilon_p} =
# \frac{\chi\sigma_y}{\rho C_p}$, is proportional to $\chi$. Halve $\chi$ and the hardening slope must fall further
# before the two balance. Measured at $\bar\epsilon_p$ = 2: with $\chi$ = 0.9 the peak is at 0.27 and the particle
# ends at 781 MPa and 811 K; with 0.45 the peak moves to 0.56 and it ends cooler and stronger, 1119 MPa and 597 K.
# With $\chi = 0$ nothing heats, and the curve hardens to the end (1583 MPa), with no peak.
#
# In a body this is the difference between a shear band and none: the earlier and sharper the peak, the sooner a
# region that deforms a little more also softens more (Section 5).

# %%
runs_chi = {c: shear(replace(jc, chi=c), RATE_AD, T0, n=500, strain=STRAIN_AD, heating=True) for c in (0.9, 0.45, 0.0)}
peak = {}
for c, o_c in runs_chi.items():
    k_c = int(np.argmax(o_c["sigma_vm"]))
    peak[c] = (o_c["eps_p"][k_c], k_c, o_c["sigma_vm"][-1], o_c["T"][-1])
    print(f"chi = {c:4}: peak at eps_p = {peak[c][0]:.2f}, at the end {peak[c][2] / 1e6:.0f} MPa and {peak[c][3]:.0f} K")
assert peak[0.45][0] > peak[0.9][0] and peak[0.45][3] < peak[0.9][3] and peak[0.45][2] > peak[0.9][2]
assert np.all(runs_chi[0.0]["T"] == T0) and peak[0.0][1] == len(runs_chi[0.0]["eps_p"]) - 1   # hardens to the end

# %% [markdown]
# ### Solution 3 — Which melting temperature?
#
# With $T_m$ = 1793 K the homologous temperature $T^*$ of a given temperature is smaller, so $1 - T^{*m}$ is
# larger: each kelvin softens less. The particle ends stronger (993 against 781 MPa), its peak comes later (0.41
# against 0.27) — and it is *hotter* (869 against 811 K), because the heat per unit strain is
# $\chi\sigma_y/(\rho C_p)$: a stronger material does more plastic
# work per unit strain and heats faster. Stronger and hotter at once, which is why the printed 1293 K changes a
# cutting simulation's forces *and* temperatures.

# %%
runs_Tm = {Tm: shear(replace(jc, T_melt=Tm), RATE_AD, T0, n=500, strain=STRAIN_AD, heating=True) for Tm in (1293.0, 1793.0)}
for Tm, o_t in runs_Tm.items():
    print(f"T_m = {Tm:.0f} K: peak at eps_p = {o_t['eps_p'][np.argmax(o_t['sigma_vm'])]:.2f}; at the end "
          f"{o_t['sigma_vm'][-1] / 1e6:.0f} MPa and {o_t['T'][-1]:.0f} K")
low, high = runs_Tm[1293.0], runs_Tm[1793.0]
assert high["sigma_vm"][-1] > 1.1 * low["sigma_vm"][-1] and high["T"][-1] > low["T"][-1]
assert high["eps_p"][np.argmax(high["sigma_vm"])] > low["eps_p"][np.argmax(low["sigma_vm"])]

# %% [markdown]
# ### Solution 4 — Write the return map yourself
#
# The handed-out stub failed as it should (asserted first). A worked answer: $\mathbf s:\mathbf s$ with $s_{zz}^2$
# added in 2D, the trial von Mises stress $\sqrt{3J_2} = \sqrt{\frac32\mathbf s:\mathbf s}$, $c_f =
# \min(\sigma_y/\sqrt{3J_2}, 1)$ (with a guard for a zero stress), then Eq. (30) $\Delta\bar\epsilon_p =
# (1-c_f)\sqrt{3J_2}/(3G)$, Eq. (31) $\Delta w_p = \sigma_y\Delta\bar\epsilon_p$ — which is
# $\Delta\boldsymbol\epsilon_{pl}:\mathbf s_n$, since $\mathbf s_n$ lies on the yield surface — and Eq. (28).
#
# Then the mistake the 2D case is there for: $J_2$ over the in-plane block only.

# %%
assert not report, "the stub as handed out must fail the grader"


def my_return_map(S, S_zz, eps_p, T, rho, eps_dot, jc, G):
    """Radial return and Eqs. (28)-(31): (S_n, S_zz_n, d_eps_p, d_w_p, d_T) from the trial stress."""
    ss = np.einsum("nab,nab->n", S, S) + (S_zz**2 if S.shape[1] == 2 else 0.0)
    svm = np.sqrt(1.5 * ss)                                       # sqrt(3 J2) of the trial stress
    sy = yield_stress(jc, eps_p, eps_dot, T)
    cf = np.where(svm > sy, sy / np.where(svm > 0, svm, 1.0), 1.0)
    d_eps_p = (1.0 - cf) * svm / (3.0 * G)                        # Eq. (30)
    d_w_p = sy * d_eps_p                                          # Eq. (31): s_n is on the yield surface
    return cf[:, None, None] * S, cf * S_zz, d_eps_p, d_w_p, jc.chi * d_w_p / (rho * jc.cp)


assert check(my_return_map, plastic_update, cases_ex4, names=("S_n", "S_zz_n", "d eps_p", "d w_p", "d T"))


def in_plane_J2(S, S_zz, eps_p, T, rho, eps_dot, jc, G):
    """The same with J2 over the in-plane block only: s_zz left out."""
    svm = np.sqrt(1.5 * np.einsum("nab,nab->n", S, S))
    sy = yield_stress(jc, eps_p, eps_dot, T)
    cf = np.where(svm > sy, sy / np.where(svm > 0, svm, 1.0), 1.0)
    d_eps_p = (1.0 - cf) * svm / (3.0 * G)
    return cf[:, None, None] * S, cf * S_zz, d_eps_p, sy * d_eps_p, jc.chi * sy * d_eps_p / (rho * jc.cp)


assert not check(in_plane_J2, plastic_update, cases_ex4, names=("S_n", "S_zz_n", "d eps_p", "d w_p", "d T"))
