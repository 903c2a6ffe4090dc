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
# # Chapter 5, continued — worked solutions (lecturer's copy)
#
# Each solution runs in the namespace of `chapters/05_penalty_contact.py`, on the chapter's own tilted plane
# (`incline`): `refsph handout DIR --instructor` inserts it right after its exercise, and `tests/test_exercises.py`
# executes that copy in quick mode, so every number quoted here is asserted. This file does not run on its own.

# %% [markdown]
# ### Solution 1 — The penalty stiffness $\alpha$
#
# The normal force is a spring, $k = \alpha m/\tau^2$, and at rest on the plane the face sinks until the spring
# carries the weight of the column above it: the sink goes like $1/\alpha$. Measured with 0.02 against 0.1: 0.026
# against 0.0056 spacings, 4.6 times deeper, close to the factor 5 of a linear spring — still a small fraction of
# a spacing, so the geometry is hardly changed.
#
# The friction does not change: the return map limits each particle's tangential spring at $\mu f_N$, whatever
# its stiffness, so a sliding block still has $F_t/F_N = \mu$ and the closed-form acceleration
# $g(\sin\theta - \mu\cos\theta)$. $\alpha$ sets how far the surface gives, not how it rubs.

# %%
stiff = runs["penalty", 100.0, MU_P]                                   # the chapter's run: alpha = 0.1
soft = incline("penalty", 100.0, alpha=0.02)
for alpha, o_a in ((0.1, stiff), (0.02, soft)):
    print(f"alpha = {alpha:4}: sink {o_a['sink']:.4f} dp, F_t / F_N = {o_a['mu_eff']:.3f}, "
          f"a / closed form = {o_a['a'] / A_EXACT:.3f}")
print(f"sink ratio {soft['sink'] / stiff['sink']:.2f} (1 / alpha: 5)")
assert 3.0 < soft["sink"] / stiff["sink"] < 7.0 and soft["sink"] < 0.1
for o_a in (stiff, soft):
    assert abs(o_a["mu_eff"] - MU_P) < 0.01 * MU_P and abs(o_a["a"] / A_EXACT - 1) < 0.02

# %% [markdown]
# ### Solution 2 — Below the friction angle
#
# Coulomb's law is an inequality, $\lvert F_t\rvert \le \mu F_N$, with equality only while the contact slides. A
# block at rest on the plane needs a tangential force $mg\sin\theta$ against a normal one $mg\cos\theta$: a ratio
# $\tan\theta = 0.6$, inside the cone of $\mu = 0.8$. So it sticks ($a \approx 0$, but for its elastic ringing),
# and the plane carries $F_t/F_N = 0.6$, not 0.8. Each particle's spring stays inside its cone, which is what the
# return map is for; the pinball holds a block only by its washboard, not inside a Coulomb cone.

# %%
stuck = incline("penalty", 100.0, mu=0.8)
print(f"mu = 0.8: a = {stuck['a']:.3g} m/s^2 (g sin theta = {G_P * math.sin(THETA):.3g}), "
      f"F_t / F_N = {stuck['mu_eff']:.3f} (tan theta = {math.tan(THETA):.3f})")
assert abs(stuck["a"]) < 0.05 * G_P * math.sin(THETA) and abs(stuck["mu_eff"] - math.tan(THETA)) < 0.02

# %% [markdown]
# ### Solution 3 — Write the friction return map yourself
#
# The handed-out stub failed as it should (asserted first). A worked answer: the trial force $-k\boldsymbol\xi^*$,
# its size, and where it exceeds $\mu f_N$ the force scaled back onto the cone and the spring shortened to what
# that force stretches, $\boldsymbol\xi = -\mathbf f_t/k$; elsewhere the trial is kept. With no normal force the
# cone is a point: no friction, and the spring is released.
#
# Then the usual mistake, the force returned but the spring not: the force passes, the history `xi` fails.

# %%
assert not report, "the stub as handed out must fail the grader"


def my_friction(xi_trial, k, f_limit):
    """Coulomb's return map: stick if |k xi*| <= mu f_N, else slip back onto the cone; returns (f_t, xi)."""
    f_trial = -k[:, None] * xi_trial
    size = np.linalg.norm(f_trial, axis=1)
    slip = size > f_limit
    f_t = np.where(slip[:, None], f_trial * (f_limit / np.where(slip, size, 1.0))[:, None], f_trial)
    return f_t, np.where(slip[:, None], -f_t / k[:, None], xi_trial)


def spring_kept(xi_trial, k, f_limit):
    return my_friction(xi_trial, k, f_limit)[0], xi_trial


assert check(my_friction, penalty.return_map_friction, cases_ex3, names=("f_t", "xi"))
assert not check(spring_kept, penalty.return_map_friction, cases_ex3, names=("f_t", "xi"))
