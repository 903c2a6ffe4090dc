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
# # Chapter 3 — worked solutions (lecturer's copy)
#
# Each solution runs in the namespace of `chapters/03_tlsph.py`, on the chapter's own bar and sheared block:
# `refsph handout DIR --instructor` inserts it right after its exercise, and `tests/test_exercises.py` executes
# that copy in quick mode, so every number quoted here is asserted. This file does not run on its own.

# %% [markdown]
# ### Solution 1 — Switch the correction off
#
# Uncorrected, $\mathbf F$ of a body at rest is the moment matrix $\mathbf M_i$ itself (Section 2), and at a corner
# a quarter of the kernel support is filled: $J = \det\mathbf M$ falls to 0.12. The equation of state reads that
# as a compression, $p = K(1/J - 1)$ = 1.3 TPa, at the corners and edges only: a body at rest
# with enormous pressure *gradients* at its surface. The first steps accelerate the surface particles violently and
# the state turns non-finite within a few steps: `run` raises `SimulationError`. Corrected, $J = 1$ to round-off
# and the bar vibrates with the right wave speed (the chapter's Section 5 run).
#
# So the correction is not an accuracy refinement: Eq. (18) as printed does not even keep a body at rest.

# %%
J_at_rest = {}
for corrected in (True, False):
    J_at_rest[corrected] = det(ReferenceOperator(b0.state.X, b0.state.V0, b0.h, kernel, corrected)
                               .deformation_gradient(b0.state.X)).min()
    print(f"corrected={corrected!s:5}: min J at rest {J_at_rest[corrected]:.3f}, "
          f"pressure K(1/J - 1) = {mat.K * (1 / J_at_rest[corrected] - 1) / 1e9:.3g} GPa")
try:
    with np.errstate(all="ignore"):
        run("bar", "tlsph", dim=2, quick=True, progress=False, numerics=dict(corrected=False))
    stopped = False
except SimulationError as err:
    stopped = True
    print("uncorrected run:", err)
assert abs(J_at_rest[True] - 1) < 1e-10 and abs(mb["wave_speed_rel_error"]) < 0.01
assert J_at_rest[False] < 0.2 and mat.K * (1 / J_at_rest[False] - 1) > 1e12      # > 1 TPa at rest
assert stopped                                                                     # a non-finite state

# %% [markdown]
# ### Solution 2 — How often to update the reference configuration?
#
# From the last update the block is in simple shear by $\Delta\gamma$, and $\lVert\mathbf E\rVert_F =
# \tfrac12\sqrt{2\Delta\gamma^2 + \Delta\gamma^4}$ passes a threshold $E^*$ at $\Delta\gamma^* =
# (\sqrt{1 + 4E^{*2}} - 1)^{1/2}$: 0.644 for 0.5, 0.141 for 0.1. In steps of 0.04 the update comes at the next
# step past it, every 0.68 (two updates, at 1.36 last) or every 0.16 (twelve, at 1.92 last).
#
# An update sets $\mathbf X \leftarrow \mathbf x$, and $\mathbf x$ is prescribed, so the reference configuration
# after an update does not depend on the threshold or on the history, only on *when* the last update happened. At
# $\gamma = 2$ the 0.5 run has been sheared by 0.64 since then and misses 738 of 4183 close pairs, the 0.1 run
# (0.08) misses 197, and no updates 1929, nearly half. The old path, 40 steps of 0.05, shows the trap: both
# thresholds updated last at $\gamma = 1.95$, so their end states were identical (206 missing) and the exercise
# could not tell them apart.
#
# The price of a small threshold: twelve operator rebuilds instead of two, and a jump of the velocity gradient at
# each (Section 6). A larger one lets pairs that come close go without interaction for longer.

# %%
def shear_block(threshold, n_steps):
    """The exercise's shear to gamma = 2 in n_steps: (gammas of the updates, close pairs not coupled, close pairs)."""
    st_s = make_state(X_u, 0.0, mat.rho0, dp_u**2)
    op_s, ups = ReferenceOperator(st_s.X, st_s.V0, prm_u.h, kernel, True), []
    for g in np.linspace(0.0, 2.0, n_steps + 1)[1:]:
        st_s.x = X_u + np.stack([g * X_u[:, 1], 0 * X_u[:, 1]], 1)
        F_s = op_s.deformation_gradient(st_s.x)
        if threshold is not None and green_lagrange_norm(F_s).max() > threshold:
            st_s = reference_update(st_s, F_s)
            op_s, ups = ReferenceOperator(st_s.X, st_s.V0, prm_u.h, kernel, True), ups + [g]
    I_s, J_s = find_pairs(st_s.x, 2 * prm_u.h)
    coupled = set(zip(op_s.I.tolist(), op_s.J.tolist()))
    return ups, sum((i, j) not in coupled for i, j in zip(I_s.tolist(), J_s.tolist())), len(I_s)


for E_star in (0.5, 0.1):
    print(f"threshold {E_star}: passed at a shear of {np.sqrt(np.sqrt(1 + 4 * E_star**2) - 1):.3f} since the last update")
ex2 = {thr: shear_block(thr, 50) for thr in (0.5, 0.1, None)}
for thr, (ups, miss, close) in ex2.items():
    print(f"threshold {thr}: {len(ups)} updates {np.round(ups, 2).tolist()}; {miss} of {close} close pairs not coupled")
assert [len(ex2[t][0]) for t in (0.5, 0.1, None)] == [2, 12, 0] and np.allclose(ex2[0.5][0], [0.68, 1.36])
assert ex2[0.1][1] < ex2[0.5][1] < 0.5 * ex2[None][1] and ex2[None][1] > 0.3 * ex2[None][2]
old = {thr: shear_block(thr, 40) for thr in (0.5, 0.1)}                  # the old path, steps of 0.05
assert abs(old[0.5][0][-1] - 1.95) < 1e-12 and abs(old[0.1][0][-1] - 1.95) < 1e-12 and old[0.5][1] == old[0.1][1]

# %% [markdown]
# ### Solution 3 — Take the artificial viscosity away
#
# At Courant 0.3 the gain grows about fivefold every quarter period. At 0.15 it is $+2.5\cdot10^{-4}$ after two
# periods — the old `.4g` format printed `1`, which read as "conserved" — but run six periods and it grows by a
# factor of about 2.2 every period: the same exponential, slower.
#
# How much slower is predicted. The predictor–corrector multiplies an undamped oscillation of frequency $\omega$
# by $\lvert A\rvert = \sqrt{1 + (\omega\Delta t)^4/4}$ per step, so the energy grows by $\ln\lvert A\rvert^2
# \approx (\omega\Delta t)^4/4$ per step, and per unit time by $\omega^4\Delta t^3/4$. Halving $\Delta t$ divides the
# exponent by $2^3 = 8$: measured, 6.3 and 0.80 per period. No time step makes the undamped scheme conservative; it
# only delays the blow-up (at 0.15 the gain would reach the bar's own energy after about 12 periods). Hence the
# artificial viscosity, or the leapfrog, which does not amplify (Chapter 10).

# %%
def energy_gain(courant, periods):
    with np.errstate(all="ignore"):
        r_e = run("bar", "tlsph", dim=2, quick=True, progress=False, t_end=periods * T_bar,
                  numerics=dict(beta1=0.0, beta2=0.0, courant=courant))
    e_e = r_e.summary["metrics"]["energy_history"]
    return e_e[:, 0] / T_bar, (e_e[:, 1] + e_e[:, 2]) / (e_e[0, 1] + e_e[0, 2]) - 1


rate, ran = {}, {COURANT: (t_T, gain)}                              # the exercise cell's run: two periods
for courant, periods, window in ((0.3, 2, (0.5, 2.0)), (0.15, 6, (2.0, 6.0))):
    t_c, gain_c = ran[courant] if courant in ran and periods == 2 else energy_gain(courant, periods)
    fit = (t_c >= window[0]) & (t_c <= window[1])
    rate[courant] = np.polyfit(t_c[fit], np.log(gain_c[fit]), 1)[0]          # exponent per period
    print(f"Courant {courant}: gain {gain_c[np.argmin(abs(t_c - 2))]:+.2e} after two periods, "
          f"{gain_c[-1]:+.2e} after {periods}; grows by exp({rate[courant]:.2f}) per period")
print(f"ratio of the exponents {rate[0.3] / rate[0.15]:.1f} (theory: 2^3 = 8)")
assert rate[0.15] > 0.5 and 6.0 < rate[0.3] / rate[0.15] < 10.0

# %% [markdown]
# ### Solution 4 — Write the corrected deformation gradient yourself
#
# The handed-out stub failed as it should (asserted first). A worked answer in three lines of algebra: one helper
# does the pair sum $-\sum_j V_j(\mathbf u_i - \mathbf u_j)\otimes\nabla_iW_{ij}$ for any field $\mathbf u$, adding
# each pair to both of its particles (for particle $j$ both factors change sign, so it gets the same outer product,
# weighted by $V_i$). Applied to $\mathbf X$ it is $\mathbf M_i$ (Section 2), applied to $\mathbf x$ it is the
# uncorrected $\mathbf F$, and $\mathbf F_i = \mathbf F^{\rm raw}_i\mathbf M_i^{-1}$.
#
# The mistake the cases catch: no correction at all passes nowhere, failing first on the block at rest at a
# surface particle. (Swapping $V_i$ and $V_j$ would fail only the third case, the one with unequal volumes.)

# %%
assert not report, "the stub as handed out must fail the grader"


def my_F(x, X, V, h):
    """Corrected Eq. (18): F_i = -sum_j V_j (x_i - x_j) (x) L_i grad_i W(X_ij), shape (n, 2, 2)."""
    I, J = find_pairs(X, 2 * h)                                       # each pair once, in the reference
    g = kernel.grad(X[I] - X[J], h, 2)                                # grad_i W_ij; grad_j W_ji = -g

    def pair_sum(u):
        out = np.zeros((len(X), 2, 2))
        d = np.einsum("pa,pb->pab", u[I] - u[J], g)
        np.add.at(out, I, -V[J, None, None] * d)
        np.add.at(out, J, -V[I, None, None] * d)
        return out

    return pair_sum(x) @ np.linalg.inv(pair_sum(X))


def reference_F(x, X, V, h):
    return ReferenceOperator(X, V, h, kernel, True).deformation_gradient(x)


def uncorrected(x, X, V, h):
    return ReferenceOperator(X, V, h, kernel, False).deformation_gradient(x)


assert check(my_F, reference_F, cases_ex4)
assert not check(uncorrected, reference_F, cases_ex4)
