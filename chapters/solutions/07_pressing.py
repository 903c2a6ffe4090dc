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
# # Chapter 7 — worked solutions (lecturer's copy)
#
# Each solution runs in the namespace of `chapters/07_pressing.py`, on the chapter's own pressing test (quick mode:
# dp = 1/60 mm, 0.2 mm of tool travel; `impact_peak`, `penetration`, `pressing_esph` and the runs `res`):
# `refsph handout DIR --instructor` inserts it right after its exercise, and `tests/test_exercises.py` executes
# that copy in quick mode, so every number quoted here is asserted. This file does not run on its own.

# %% [markdown]
# ### Solution 1 — A faster tool
#
# The impact peak goes from 3.75 to 7.38 MN/m, 1.97 times, and stays within 3 % of the estimate (3.85 and
# 7.53 MN/m). The elastic estimate $\rho c_L v H_0$ (4.67 and 9.34 MN/m) is too high: the block yields at once.
#
# Why a little less than double: the estimate is a straight line that does not pass through zero,
# $F = \left[\sigma_{HEL}(1 - c_B/c_L) + \rho c_B v\right]H_0$. The elastic precursor carries $\sigma_{HEL}$
# whatever the speed; only the plastic wave's share, $\rho c_B v$, grows with $v$, and at 200 m/s it is already
# most of the force. So the impact grows nearly, not exactly, in proportion to the speed (the estimate: 1.95).

# %%
peak = {v: impact_peak(v) for v in (200.0, 400.0)}            # the 200 m/s run was done by the exercise
for v, f_v in peak.items():
    print(f"{v:.0f} m/s: impact peak {1e-6 * f_v:.2f} MN/m, estimate {1e-6 * impact_force(v):.2f} MN/m "
          f"(ratio {f_v / impact_force(v):.2f}); elastic rho c_L v H0 = {1e-6 * mat.rho0 * c_L * v * LY:.2f} MN/m")
print(f"peak ratio 400 / 200 m/s: {peak[400.0] / peak[200.0]:.2f}; estimate {impact_force(400.0) / impact_force(200.0):.2f}")
assert all(abs(f_v / impact_force(v) - 1) < 0.035 for v, f_v in peak.items())
assert 1.9 < peak[400.0] / peak[200.0] < 2.0 and impact_force(400.0) / impact_force(200.0) < 2.0

# %% [markdown]
# ### Solution 2 — How hard is the pinball?
#
# Deeper: 0.171 spacings with $K_p$ = 5 against 0.050 with $K_p$ = 50, 3.5 times. The face pushes the block
# with $K_p\min(F^1, F^2)$; while the tool advances the Hertz force $F^2\propto p_d^{3/2}$ is the smaller one,
# so carrying the same push with a ten times smaller $K_p$ needs $10^{2/3}\approx 4.6$ times the overlap (less
# here: $F^1$ takes over as the pairs stop approaching, as in chapter 5). Both stay below a spacing: the faces
# still sit where they should. $K_p$ is a numerical stiffness; the benchmark report shows what it does to the
# strain field.

# %%
pen = {K: penetration(K) for K in (50.0, 5.0)}               # K_p = 50 was done by the exercise
print(f"deepest penetration: K_p = 50 {pen[50.0]:.3f} dp, K_p = 5 {pen[5.0]:.3f} dp (ratio {pen[5.0] / pen[50.0]:.1f})")
assert 0.0 < pen[50.0] < 0.1 and 2.5 * pen[50.0] < pen[5.0] < 4.6 * pen[50.0] and pen[5.0] < 1.0

# %% [markdown]
# ### Solution 3 — Switch off the heating
#
# Isothermal, the block stays at 298 K (631 K at its hottest with heating), the mean pressing force is 4.9 % higher
# (1.052 against 1.003 MN/m), and the strain in the bands is lower: the 99th percentile 0.650 against 0.734, the
# maximum 1.00 against 1.09. The mean strain is the same (0.258 and 0.260): the tool imposes the same shape
# change, and heating decides where it goes. Where a band heats, $1 - T^{*m}$ lowers its flow stress, so the
# next increment of strain goes there again: localisation feeds itself. The stronger isothermal block also takes
# more plastic work (164 against 160 J/m). In cutting, this softening is what lets the chip segment.

# %%
hot, cold = res["esph"], pressing_esph(False)
out = {}
for label, r_h in (("heating", hot), ("isothermal", cold)):
    mt_h, e_h = r_h.summary["metrics"], r_h.state.eps_p[:n_b]
    W_h = float(np.sum(r_h.state.W_p[:n_b] * r_h.state.m[:n_b] / r_h.state.rho[:n_b]))
    out[label] = (mt_h["tool_force_mean_N_per_m"], mt_h["max_temperature_K"], np.percentile(e_h, 99), e_h.max(),
                  e_h.mean(), W_h)
    print(f"{label:10s}: mean tool force {1e-6 * out[label][0]:.3f} MN/m, max T {out[label][1]:.0f} K, eps_p 99th "
          f"percentile {out[label][2]:.3f}, max {out[label][3]:.2f}, mean {out[label][4]:.3f}; plastic work {W_h:.1f} J/m")
(F_on, T_on, p99_on, max_on, mean_on, W_on), (F_off, T_off, p99_off, max_off, mean_off, W_off) = out.values()
assert T_off == jc.T_room < T_on - 200
assert 1.02 < F_off / F_on < 1.08 and p99_off < 0.95 * p99_on and max_off < max_on
assert abs(mean_off / mean_on - 1) < 0.03 and W_off > W_on

# %% [markdown]
# ### Solution 4 — The tool and the clamp, yourself
#
# The handed-out stub failed as it should (asserted first). A worked answer: the forces first, $\mathbf F =
# \sum_i m_i\mathbf a_i$ over the tool's rows and over the clamp's, then the prescribed motion: $\dot{\mathbf
# v} = 0$ on both, $\dot{\mathbf x} = 0$ on the clamp (the tool keeps $\dot{\mathbf x} = \mathbf v$). Pairs
# inside the tool add nothing to its sum: each pushes both partners equally and oppositely.
#
# Then three mistakes, each caught: zeroing the rates before summing (forces of zero), leaving out the masses, and
# a clamp that keeps $\dot{\mathbf x} = \mathbf v$ (caught only by the case with random velocities: a clamped
# particle is at rest in a real state).

# %%
assert not report, "the stub as handed out must fail the grader"


def my_constraints(m, v, a, n_block, clamp, mistake=None):
    """(force on the tool, force on the clamp, dv/dt, dx/dt) of the pressing's tool and clamp, from the masses m,
    velocities v and the accelerations a of every particle before the constraints."""
    a, xdot = a.copy(), v.copy()
    if mistake == "zero first":
        a[n_block:], a[clamp] = 0.0, 0.0
    w = np.ones_like(m) if mistake == "no mass" else m
    F_tool = np.sum(w[n_block:, None] * a[n_block:], axis=0)          # what the block's pairs push on the tool
    F_clamp = np.sum(w[clamp, None] * a[clamp], axis=0)
    a[n_block:], a[clamp] = 0.0, 0.0                                  # rigid: moves with v; clamped: at rest
    if mistake != "clamp moves":
        xdot[clamp] = 0.0
    return F_tool, F_clamp, a, xdot


names = ("F_tool", "F_clamp", "dv/dt", "dx/dt")
assert check(my_constraints, pkg_constraints, cases_ex4, names=names)
for wrong in ("zero first", "no mass", "clamp moves"):
    assert not check(lambda *args: my_constraints(*args, mistake=wrong), pkg_constraints, cases_ex4, names=names,
                     name=wrong)
