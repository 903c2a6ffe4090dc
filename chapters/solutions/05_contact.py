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
# # Chapter 5 — worked solutions (lecturer's copy)
#
# Each solution runs in the namespace of `chapters/05_contact.py`, on the chapter's own disc bounce and oblique
# throw (`bounce`, `oblique`, `ContactSpy`): `refsph handout DIR --instructor` inserts it right after its exercise,
# and `tests/test_exercises.py` executes that copy in quick mode, so every number quoted here is asserted. This
# file does not run on its own.

# %% [markdown]
# ### Solution 1 — The scaling factor $K_p$
#
# At impact speed the Hertz spring $F^2 \propto p_d^{3/2}$ is the smaller of the two forces (the chapter's force
# law figure), so carrying the same push with $K_p$ ten times smaller takes a penetration $10^{2/3} \approx 4.6$
# times larger. Measured: 0.22 against 0.066 spacings, 3.3 times deeper (less than 4.6: near the end of the
# approach $F^1$, which does not depend on $p_d$, is the smaller force).
#
# And it comes back slower, because the pinball is a one-way spring: $F = K_p\min(F^1, F^2)$ with $F^1 = 0$
# once a pair stops approaching, so the energy the spring took in on the way in is never given back. The deeper
# the penetration, the more is lost: restitution 0.63 against 0.90. With $K_p$ = 50 the penetration is small and the
# rebound is the disc's own elasticity, as against the kinematic wall.

# %%
soft, default = bounce(V_IMPACT, 5.0), bounce(V_IMPACT, 50.0)
for Kp, o_k in ((5, soft), (50, default)):
    print(f"K_p = {Kp:2d}: max penetration {o_k['pen']:.3f} dp, restitution {o_k['restitution']:.3f}")
print(f"penetration ratio {soft['pen'] / default['pen']:.1f} (Hertz alone: 10^(2/3) = {10 ** (2 / 3):.1f})")
assert 2.0 * default["pen"] < soft["pen"] < 6.0 * default["pen"]
assert 0.0 < soft["restitution"] < default["restitution"] - 0.1

# %% [markdown]
# ### Solution 2 — The pinball radius factor $k$
#
# Contact starts when the pinballs overlap, at a centre distance $2R = k_{\rm factor}\Delta p$: with 1.2 the disc
# is stopped 0.20 spacings farther out (closest 1.14 against 0.93 dp). How stiff the contact is does not change with
# where it starts: the Hertz force grows only like $\sqrt{R}$ (10 % stiffer, so 6 % less penetration: 0.063 against
# 0.066 dp) and $F^1$ not at all; the restitution moves from 0.900 to 0.906. $k = \Delta p/(2h)$ is the choice that puts the contact surface where
# the bodies' faces are, half a spacing outside each surface row.

# %%
wide = bounce(V_IMPACT, k_factor=1.2)
for label, o_k in (("k_factor 1.0", default), ("k_factor 1.2", wide)):
    print(f"{label}: closest {o_k['closest']:.3f} dp, penetration {o_k['pen']:.3f} dp, "
          f"restitution {o_k['restitution']:.3f}")
assert 0.1 < wide["closest"] - default["closest"] < 0.3                # about 0.2 dp farther out
assert abs(wide["pen"] - default["pen"]) < 0.5 * default["pen"]
assert abs(wide["restitution"] - default["restitution"]) < 0.05

# %% [markdown]
# ### Solution 3 — Friction and Coulomb's bound
#
# Each pair's friction is $\min(\mu F_{ij}, m_{ij}\lvert\mathbf v_t\rvert/\Delta t)$: at most $\mu$ times its normal
# force, by construction. Summed over pairs and steps, $J_f \le \mu_0 J_N$ (here $\mu(T) = \mu_0$, the block stays at
# room temperature), equal where no pair stuck: 0.810 here. On the wall the tangential impulse also holds the
# washboard's drag, so $J_t/J_n$ = 0.834, a little above $\mu_0$.
#
# A closed form for the speed lost: the tangential impulse is $\mu_0$ times the normal one, and the normal one
# reverses the approach, $J_n = (1 + e)\,m v_N$ with $e$ the normal restitution, so $\Delta v_t \approx
# \mu_0(1 + e)v_N$ = 37.7 m/s; the run loses 38.8 (100 to 61.2 m/s).

# %%
free = slide["TLSPH, wall particles dp/4 apart"]                       # the chapter's frictionless throw
with ContactSpy() as spy_ex:
    rough = oblique(mu0=0.81, spacing=DP / 4)
J_N3 = sum(dt * sum(q["F"] for q in pairs) for dt, pairs, _ in spy_ex.corrector())
J_f3 = sum(dt * sum(q["ft"] for q in pairs) for dt, pairs, _ in spy_ex.corrector())
e_n = -rough["P1"][1] / rough["P0"][1]                                 # normal restitution
print(f"mu0 = 0.81: J_f / J_N = {J_f3 / J_N3:.3f}, wall J_t / J_n = {rough['Jt_over_Jn']:.3f}; speed along the "
      f"wall {free['vt_after']:.1f} -> {rough['vt_after']:.1f} m/s; mu0 (1 + e) v_N = {0.81 * (1 + e_n) * V_N:.1f} m/s")
assert J_f3 <= 0.81 * J_N3 * (1 + 1e-12) and J_f3 > 0.9 * 0.81 * J_N3
assert 0.7 * 0.81 < rough["Jt_over_Jn"] <= 1.05 * 0.81 and abs(free["Jt_over_Jn"]) < 0.1 * 0.81
assert rough["vt_after"] < free["vt_after"] - 20.0
assert abs((V_T - rough["vt_after"]) / (0.81 * (1 + e_n) * V_N) - 1) < 0.2

# %% [markdown]
# ### Solution 4 — Write the pinball force yourself
#
# The handed-out stub failed as it should (asserted first). A worked answer: all pairs within $2R$ from a k-d tree,
# then Eqs. (32)–(36) on the pair arrays: $p_d = 2R - r$, $\mathbf e = \mathbf x_{ij}/r$, $\dot p_d = -\mathbf
# v_i\cdot\mathbf e$ (the wall is at rest), $F^1 = m_i\dot p_d/\Delta t$ where $\dot p_d > 0$ and 0 elsewhere, $F^2 =
# G\sqrt{R/2}\,p_d^{3/2}$/thickness, and `np.add.at` to sum $\mathbf e F/m_i$ per particle.
#
# Then a mistake the cases catch: the paper's printed $\dot p_d = \lvert\dot{\mathbf v}_i - \dot{\mathbf v}_j\rvert$,
# read as speeds, never negative, so the contact also pushes pairs that already separate. The first case's random velocities catch it
# (the leaving disc would too).

# %%
assert not report, "the stub as handed out must fail the grader"


def my_pinball(x_a, v_a, m_a, x_b, R, G, dt, K_p, thickness, printed_rate=False):
    """Eqs. (32)-(36): acceleration (n_a, d) of particles a from rigid particles b at rest, pinball radius R."""
    near = cKDTree(x_b).query_ball_point(x_a, 2 * R)
    i = np.array([k for k, js in enumerate(near) for _ in js], dtype=int)
    j = np.array([jj for js in near for jj in js], dtype=int)
    dx = x_a[i] - x_b[j]
    r = np.linalg.norm(dx, axis=1)
    p_d, e = 2 * R - r, dx / r[:, None]                               # Eq. (32), the line of centres
    pdot = np.linalg.norm(v_a[i], axis=1) if printed_rate else -np.einsum("pk,pk->p", v_a[i], e)
    F1 = np.where(pdot > 0, m_a[i] * pdot / dt, 0.0)                  # Eq. (34), m_ij = m_i
    F2 = G * np.sqrt(R * R / (2 * R)) * np.maximum(p_d, 0.0) ** 1.5 / thickness   # Eq. (35), mu_ij = G
    F = np.where(p_d > 0, K_p * np.minimum(F1, F2), 0.0)             # Eq. (33)
    a = np.zeros_like(x_a)
    np.add.at(a, i, e * (F / m_a[i])[:, None])                        # Eq. (36)
    return a


assert check(my_pinball, pkg_pinball, cases_ex4)
assert not check(lambda *args: my_pinball(*args, printed_rate=True), pkg_pinball, cases_ex4, name="printed rate")
