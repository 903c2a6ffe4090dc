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
# # Chapter 8 — worked solutions (lecturer's copy)
#
# Each solution runs in the namespace of `chapters/08_cutting.py`, on the chapter's own cut (quick mode: TLSPH at
# dp = 0.05 mm, 0.3 mm of cut; `cut` returns a run it has made before, so the unchanged case is the chapter's run
# `res["tlsph"]`): `refsph handout DIR --instructor` inserts it right after its exercise, and
# `tests/test_exercises.py` executes that copy in quick mode, so every number quoted here is asserted. This file
# does not run on its own.

# %% [markdown]
# ### Solution 1 — A deeper cut
#
# $F_c$ grows from 0.720 to 1.081 MN/m, 1.50 times for 1.67 times the feed, so $F_c/f$ falls by 10 %, from 2.40 to
# 2.16 GJ/m³: about the same, as predicted, but not quite. The paper-resolution runs of the benchmark show the same
# (0.561 to 0.873 MN/m, 1.56 times; $F_c/f$ 7 % lower).
#
# A straight line through the two points, $F_c = F_0 + k f$, says why: $k$ = 1.8 GJ/m³ is the shearing of the
# removed layer, and $F_0$ = 0.18 MN/m does not depend on the feed: the edge ploughing the new surface. Its share
# shrinks as the feed grows, so thin cuts cost more energy per volume: the *size effect* of machining. The thrust
# grows with the feed too (0.233 to 0.361 MN/m).

# %%
base, deep = cut("tlsph", feed=FEEDS[0], travel=TRAVEL_EX, tag="-ex"), cut("tlsph", feed=0.5e-3, travel=TRAVEL_EX,
                                                                          tag="-ex")
assert base is res["tlsph"]                                        # the chapter's run, not run again
(Fc3, Ft3), (Fc5, Ft5) = ((r_.summary["metrics"]["cutting_force_mean_N_per_m"],
                           r_.summary["metrics"]["thrust_force_mean_N_per_m"]) for r_ in (base, deep))
k_sh = (Fc5 - Fc3) / (0.5e-3 - FEEDS[0])
F0 = Fc3 - k_sh * FEEDS[0]
P3, P5 = (BENCH[f"paper-tlsph-f{f}"]["cutting_force_mean_MN_per_m"] for f in ("0.3", "0.5"))
print(f"Fc {1e-6 * Fc3:.3f} -> {1e-6 * Fc5:.3f} MN/m (x {Fc5 / Fc3:.2f}); Fc/f {Fc3 / FEEDS[0] / 1e9:.2f} -> "
      f"{Fc5 / 0.5e-3 / 1e9:.2f} GJ/m^3; Fc = F0 + k f: k = {k_sh / 1e9:.2f} GJ/m^3, F0 = {1e-6 * F0:.2f} MN/m; "
      f"Ft {1e-6 * Ft3:.3f} -> {1e-6 * Ft5:.3f} MN/m; paper resolution {P3:.3f} -> {P5:.3f} MN/m (x {P5 / P3:.2f})")
assert 1.3 < Fc5 / Fc3 < 0.5e-3 / FEEDS[0] and abs(Fc5 / 0.5e-3 / (Fc3 / FEEDS[0]) - 1) < 0.15
assert 0.1e6 < F0 < 0.3e6 and Ft5 > Ft3 and 1.4 < P5 / P3 < 0.5e-3 / FEEDS[0]

# %% [markdown]
# ### Solution 2 — TLSPH without reference updates
#
# The run without updates makes none (4 with), and its new surface carries a mean plastic strain of 0.50 against
# 0.36, 39 % more; the hottest particle is at 907 K against 811 K. Elsewhere little changes: the cutting force
# (0.726 against 0.720 MN/m) and the chip (0.262 against 0.260 mm) are within 1 %.
#
# TLSPH's kernel sums run over the neighbours of the *reference* configuration. Without updates, particles just
# below the cut line keep as neighbours the particles above it, which have gone into the chip: the chip pulls them
# along, so the new surface is sheared and heated by material that has long left. An update re-forms the
# neighbour lists from the current positions, and the bond across the cut breaks. The longer the cut, the more
# tangled the old neighbourhoods get: the benchmark's run without updates is lost after a short cut.

# %%
noupd = cut("tlsph", travel=TRAVEL_EX, numerics=dict(ref_update_strain=None), tag="-ex-None")
row = {}
for label, r_ in (("updates at 0.5", base), ("no updates", noupd)):
    n_, mt_ = r_.setup.info["n_work"], r_.summary["metrics"]
    row[label] = (r_.summary["diagnostics"]["reference_updates"], new_surface(r_), r_.state.T[:n_].max(),
                  mt_["cutting_force_mean_N_per_m"], mt_["chip_thickness_mm"])
    print(f"{label:14s}: {row[label][0]} updates, new surface eps_p {row[label][1]:.2f}, hottest {row[label][2]:.0f} K, "
          f"Fc {1e-6 * row[label][3]:.3f} MN/m, chip {row[label][4]:.3f} mm")
(u_on, s_on, T_on, F_on, c_on), (u_off, s_off, T_off, F_off, c_off) = row.values()
assert u_on > 0 == u_off and s_off > 1.2 * s_on and T_off > T_on + 50
assert abs(F_off / F_on - 1) < 0.05 and abs(c_off / c_on - 1) < 0.05

# %% [markdown]
# ### Solution 3 — How fine must the particles be to see a band?
#
# All five at 0.01 and 0.025 mm, one at 0.05 mm. Along the middle row each drawn band is a Gaussian of width
# $\sigma = 1.5\,\Delta p/\sin 45°$: 0.106 mm at $\Delta p$ = 0.05 mm, so the bands, 0.15 mm apart, are only
# $1.4\sigma$ apart, and two Gaussians less than $2\sigma$ apart add up to one hump with no dip between them. At
# 0.025 mm they are $2.8\sigma$ apart: five peaks. Rule of thumb: bands $s$ apart, each 1.5 spacings wide,
# separate only where $\Delta p < s\sin\theta/3$, here 0.035 mm, finer than the quick spacing. The paper's
# 0.01 mm resolves them easily.

# %%
found3 = {}
for dp_ in (0.01e-3, 0.025e-3, 0.05e-3):
    Xd_, ed_, nx_, ny_, c_ = banded_field(dp_, FEEDS[0], 0.15e-3, 45.0, 2.0e-3)
    found3[dp_] = shear_bands(Xd_, ed_, nx_, ny_, dp_, dp_, FEEDS[0], 2.0e-3)["n"]
    print(f"dp = {1e3 * dp_:.3f} mm: drew {len(c_)}, found {found3[dp_]}")
assert found3[0.01e-3] == found3[0.025e-3] == len(c_) == 5 and found3[0.05e-3] == 1
sigma = {dp_: 1.5 * dp_ / math.sin(math.radians(45.0)) for dp_ in (0.025e-3, 0.05e-3)}     # along the row
assert abs(sigma[0.05e-3] - 0.106e-3) < 1e-6 and 0.15e-3 / sigma[0.05e-3] < 2 < 0.15e-3 / sigma[0.025e-3]

# %% [markdown]
# ### Solution 4 — The force history, yourself
#
# The handed-out stub failed as it should (asserted first). A worked answer: the bin edges
# `np.linspace(0, t_end, n_bins + 1)`, each step's bin from `np.searchsorted` on its midpoint (the last edge
# belongs to the last bin), then `np.bincount` with weights $\Delta t$ and $F\Delta t$; bins with no step left out.
#
# Then three mistakes, each caught: the plain mean of the steps in a bin (the largest step is 4.3 times the
# smallest; the plain mean is off by 0.06 % in the median bin, but by 14 % in a bin where the step size changes
# fast), binning by the step's start instead of its midpoint, and empty bins returned as nan.

# %%
assert not report, "the stub as handed out must fail the grader"


def my_force_history(t, dt, F, t_end, n_bins, mistake=None):
    """(bin centres [s], mean Fc [N/m], mean Ft [N/m]) of the bins that hold a step, as described above."""
    edges = np.linspace(0.0, t_end, n_bins + 1)
    t_in = t - 0.5 * dt if mistake == "step start" else t
    k = np.clip(np.searchsorted(edges, t_in, side="right") - 1, 0, n_bins - 1)
    w = dt if mistake != "plain mean" else np.ones_like(dt)
    total = np.bincount(k, weights=w, minlength=n_bins)
    keep = total > 0 if mistake != "empty bins" else np.ones(n_bins, bool)
    with np.errstate(invalid="ignore"):
        Fc_b, Ft_b = (np.bincount(k, weights=F[:, c] * w, minlength=n_bins)[keep] / total[keep] for c in (0, 1))
    return 0.5 * (edges[1:] + edges[:-1])[keep], Fc_b, Ft_b


names4 = ("t", "Fc", "Ft")
assert check(my_force_history, pkg_force_history, cases_ex4, names=names4)
for wrong in ("plain mean", "step start", "empty bins"):
    assert not check(lambda *a: my_force_history(*a, mistake=wrong), pkg_force_history, cases_ex4, names=names4,
                     name=wrong)
dt4 = cases_ex4[0].args[1]
plain = my_force_history(*cases_ex4[0].args, mistake="plain mean")[1]
off = np.abs(plain / pkg_force_history(*cases_ex4[0].args)[1] - 1)
print(f"TLSPH: the largest step is {dt4.max() / dt4.min():.1f} times the smallest; the plain mean is off by "
      f"{100 * np.median(off):.2f} % in the median bin, {100 * off.max():.0f} % at most")
assert 3.5 < dt4.max() / dt4.min() < 5.0 and np.median(off) < 0.01 and 0.05 < off.max() < 0.3
