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
# # Chapter 2 — worked solutions (lecturer's copy)
#
# Each solution runs in the namespace of `chapters/02_esph.py`, on the chapter's own scenes (`tension`, `bar`):
# `refsph handout DIR --instructor` inserts it right after its exercise, and `tests/test_exercises.py` executes
# that copy in quick mode, so every number quoted here is asserted. This file does not run on its own.

# %% [markdown]
# ### Solution 1 — How much artificial pressure?
#
# The chapter already ran $\gamma$ = 0 and 0.3 (`rmin`); add 0.02 and 3. In quick mode the closest pair comes to
# 0.78 dp without artificial pressure, 0.88 with $\gamma$ = 0.02 and 0.94 with 0.3: a little repulsion helps, the
# paper's value keeps the lattice nearly intact. At $\gamma$ = 3 it falls to 0.001 dp: two particles on top of
# each other.
#
# Why more is worse: Eq. (14) is a repulsion $\propto\gamma\,(\lvert p_i\rvert/\rho_i^2 + \lvert p_j\rvert/\rho_j^2)
# [W(r)/W(\Delta p)]^4$ added to the pair's stress term $\boldsymbol\sigma_i/\rho_i^2 + \boldsymbol\sigma_j/\rho_j^2$.
# At $r = \Delta p$ it is $\gamma$ times the pressure part of that term, so at $\gamma = 3$ three times the
# tension it is meant to balance, and it grows with the fourth power of $W$ as the pair closes in. Each pair it
# flings apart is thrown onto the next one: the remedy is itself a short-range force, and too much of it is a new
# instability. There is a window, and nothing in the physics says where it is.

# %%
rmin_ex = {0.0: rmin["ESPH, gamma = 0"], 0.3: rmin["ESPH, gamma = 0.3"]}
for g in (0.02, 3.0):
    rmin_ex[g] = run("tension", "esph", quick=ch.quick, numerics={"gamma": g},
                     progress=False).summary["metrics"]["min_pair_distance_over_dp"]
for g in sorted(rmin_ex):
    print(f"gamma = {g:4}: smallest pair distance {rmin_ex[g]:.3f} dp")
assert rmin_ex[0.3] > 0.85                                       # the paper's gamma keeps the particles apart
assert rmin_ex[0.0] < rmin_ex[0.02] < rmin_ex[0.3] - 0.02        # a small one protects, only partly ...
assert rmin_ex[3.0] < 0.5 * rmin_ex[0.3]                         # ... and a large one makes particles collide

# %% [markdown]
# ### Solution 2 — Refine the bar
#
# With 8 particles across the width the bar is 6.3 % slower than theory, with 16 2.8 %: the error falls by a
# factor 2.3 when the spacing halves, and the error times the number of particles across, $W/\Delta p$, stays
# near $-0.5$.
#
# A model of it: within about $2h = 3\Delta p$ of each side Eq. (23) sees a truncated kernel, and the layer is
# softer (the patch test). If layers of total thickness $a\,\Delta p$ carried no stress at all, the bar would
# have the stiffness of a width $W - a\Delta p$ and the mass of $W$, so $c/c_0 = \sqrt{1 - a\Delta p/W} \approx
# 1 - a\Delta p/(2W)$. The measured $-0.5\,\Delta p/W$ gives $a \approx 1$: as if half a spacing on each side
# were missing — the $2h$ layers are soft, not empty. Either way the error is first order in $\Delta p$, which
# is why uncorrected ESPH converges slowly wherever there is a free surface.

# %%
err_nw = {NW: m["wave_speed_rel_error"]}                          # the exercise cell's run is one of them
for nw in (8, 16):
    if nw not in err_nw:
        r_nw = run("bar", "esph", dim=2, dp=W_bar / nw, t_end=0.9 * T_th, numerics={"gamma": 0.0}, progress=False)
        err_nw[nw] = r_nw.summary["metrics"]["wave_speed_rel_error"]
    print(f"dp = W/{nw:2d}: error {100 * err_nw[nw]:+.2f} %, error x W/dp = {err_nw[nw] * nw:+.3f}")
assert err_nw[8] < 0 and err_nw[16] < 0                           # too slow at both resolutions
assert 1.5 < err_nw[8] / err_nw[16] < 3.5                         # the error roughly halves: first order in dp
assert all(0.3 < -e * nw < 0.7 for nw, e in err_nw.items())      # error about -0.5 dp / W

# %% [markdown]
# ### Solution 3 — Write the Jaumann rate yourself
#
# The handed-out stub failed as it should (asserted first). A worked answer: the symmetric and skew parts of
# $\mathbf l$, the deviator of the *3D* strain rate (its trace over the plane, as $\dot\epsilon_{zz} = 0$, divided by
# 3), the spin terms in the order $\boldsymbol\omega\mathbf s - \mathbf s\boldsymbol\omega$ that goes with
# $l_{ab} = \partial v_a/\partial x_b$, and $\dot s_{zz} = 2G(0 - \mathrm{tr}\,\dot{\boldsymbol\epsilon}/3)$.
#
# Then the two mistakes the cases are there to catch, each failing at the case named in the message: the printed
# order of the spin terms (the rigid spin), and a 2D deviator with no $\dot s_{zz}$ (the stretch).

# %%
assert not report, "the stub as handed out must fail the grader"


def my_jaumann(S, S_zz, l, G):
    """Eq. (20) in plane strain: (ds/dt of shape (n, 2, 2), ds_zz/dt of shape (n,))."""
    eps_dot, omega = 0.5 * (l + np.swapaxes(l, 1, 2)), 0.5 * (l - np.swapaxes(l, 1, 2))
    tr = np.trace(eps_dot, axis1=1, axis2=2)                      # + eps_dot_zz = 0 in plane strain
    dS = 2.0 * G * (eps_dot - tr[:, None, None] / 3.0 * np.eye(2)) + omega @ S - S @ omega
    return dS, 2.0 * G * (0.0 - tr / 3.0)


assert check(my_jaumann, jaumann_deviatoric_rate, cases_ex3, names=("ds/dt", "ds_zz/dt"))


def printed_order(S, S_zz, l, G):
    dS, dS_zz = my_jaumann(S, S_zz, l, G)
    omega = 0.5 * (l - np.swapaxes(l, 1, 2))
    return dS - 2.0 * (omega @ S - S @ omega), dS_zz              # s omega - omega s


def in_plane_only(S, S_zz, l, G):
    eps_dot, omega = 0.5 * (l + np.swapaxes(l, 1, 2)), 0.5 * (l - np.swapaxes(l, 1, 2))
    dev = eps_dot - np.trace(eps_dot, axis1=1, axis2=2)[:, None, None] / 2.0 * np.eye(2)
    return 2.0 * G * dev + omega @ S - S @ omega, np.zeros(len(S))


assert not check(printed_order, jaumann_deviatoric_rate, cases_ex3, names=("ds/dt", "ds_zz/dt"))
assert not check(in_plane_only, jaumann_deviatoric_rate, cases_ex3, names=("ds/dt", "ds_zz/dt"))
