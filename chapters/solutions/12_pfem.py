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
# # Chapter 12 — worked solutions (lecturer's copy)
#
# Each solution runs in the namespace of `chapters/12_pfem.py`, on the chapter's own cases (section 1's point set,
# section 3's cantilever, section 5's steel, section 2's triangle): `refsph handout DIR --instructor` inserts it right
# after its exercise, and `tests/test_exercises.py` executes that copy in quick mode, so every number quoted here is
# asserted. This file does not run on its own.

# %% [markdown]
# ### Solution 1 — The α window
#
# Swept in steps of 0.05, α keeps 2 bodies, no hole and an empty notch on one unbroken window, 0.90–1.55, which
# holds 1.4. Above it the 3-spacing gap is bridged: the jitter brings two nodes across it closer than 3 spacings,
# and a triangle spanning it is round enough from α = 1.6 (one body; from 1.7 the notch fills too). Below it holes
# open: 2 at 0.85, 4 at 0.8, where the jitter made a triangle of the lattice a little too round. The window is
# narrow and set by the point set, not by the physics: a finer jitter or a wider gap moves its edges.

# %%
alphas = np.round(np.arange(0.7, 2.5001, 0.05), 2)
sweep = {a: topology(pts, alpha_shape_mesh(pts, a)) for a in alphas}
good = [a for a, t in sweep.items() if (t["bodies"], t["holes"], t["notch"]) == (2, 0, 0)]
print(f"window {good[0]:.2f}-{good[-1]:.2f}; " + "; ".join(
    f"{a:.2f}: {sweep[a]['bodies']} bodies, {sweep[a]['holes']} holes, {sweep[a]['notch']} in the notch"
    for a in (0.8, 0.85, good[0], good[-1], 1.6, 1.7)))
assert (good[0], good[-1]) == (0.9, 1.55) and len(good) == 14 and 1.4 in good         # one unbroken window
assert sweep[1.6]["bodies"] == 1 and sweep[1.6]["notch"] == 0 < sweep[1.7]["notch"]
assert (sweep[0.85]["holes"], sweep[0.8]["holes"]) == (2, 4)

# %% [markdown]
# ### Solution 2 — Remeshing creep and the spacing
#
# Over 4 quasi-static steps, each followed by a remeshing with every triangle averaged, the tip deflection grows by
# 0.36, 0.15 and 0.04 of Timoshenko's per remeshing at 2, 4 and 8 elements deep: it falls 2.5 times at the first
# halving and 3.4 times at the second, towards four, i.e. as the spacing squared. The averaging smears the bending
# stress over about one spacing at the outer fibres (a share $\sim h/H$ of the section), by an amount itself
# $\sim h$ (the stress changes by $h\,\partial\sigma/\partial y$ across a spacing): two factors of $h$.

# %%
per_remesh = {ny: np.diff(held_cantilever(ny, 4, averaged)[0]).mean() for ny in (2, 4, 8)}
print("creep per remeshing:", {ny: round(float(c), 4) for ny, c in per_remesh.items()})
assert [round(per_remesh[ny], 2) for ny in (2, 4, 8)] == [0.36, 0.15, 0.04]
assert round(per_remesh[2] / per_remesh[4], 1) == 2.5 and round(per_remesh[4] / per_remesh[8], 1) == 3.4

# %% [markdown]
# ### Solution 3 — Lumped or consistent heat capacity
#
# Lumped keeps every temperature in [293, 1300] K, and the hot node's neighbours warm a little; consistent
# undershoots next to the hot node, to 180 K, 11 % of the 1007 K jump below the cold start. Backward Euler solves
# $(C/\Delta t + K)\,T_{n+1} = (C/\Delta t)\,T_n$. With a lumped (diagonal) $C$ and a Delaunay mesh (no obtuse angle
# sums, so every off-diagonal of $K$ is $\le 0$) the matrix is an M-matrix: each new temperature is a weighted mean
# of its neighbours' new ones and its own old one, so no new extreme. The consistent $C$ has positive off-diagonals
# ($\rho c_p A/12$), which at a short step outweigh the conduction and break the sign pattern: heat is taken from
# the neighbours of the hot node to build the linear profile inside each triangle. A short step makes it worse;
# lumping is the PFEM's (and refsph's) choice for exactly this.

# %%
T_by = {lumped: thermal.thermal_step(sq, alpha_shape_mesh(sq, None).tri, np.full(len(sq), 293.0),
                                     1e-3 * rc45 * 1.25e-4**2 / k45, k45, rc45, fixed=[hot], T_fixed=1300.0,
                                     lumped=lumped)[0] for lumped in (True, False)}
for lumped, T_l in T_by.items():
    print(f"lumped {lumped}: T from {T_l.min():.1f} to {T_l.max():.1f} K, hottest free node {np.sort(T_l)[-2]:.2f} K")
assert T_by[True].min() >= 293.0 - 1e-9 and T_by[True].max() <= 1300.0 + 1e-9 and np.sort(T_by[True])[-2] > 293.0
assert round(T_by[False].min()) == 180 and round((293.0 - T_by[False].min()) / (1300.0 - 293.0), 2) == 0.11

# %% [markdown]
# ### Solution 4 — Write the mixed triangle yourself
#
# The handed-out stub failed as it should (asserted first). A worked answer: `np.roll` along the vertex axis
# gives, for every vertex $a$ at once, the next two $b$ and $c$; the signed area is the shoelace sum; the two
# matrices are $A$ times $(1 + \delta_{ab})/12$ and $\delta_{ab}/12 - 1/36$, what section 2's quadrature printed.
#
# Then the two mistakes: $|A|$ fails the clockwise triangle, whose gradients need the sign to come out right (the
# other two cases are counter-clockwise, as `alpha_shape_mesh` orders them); $\int N_aN_b$ in place of the
# projection term fails at once. And the consistent heat capacity of Exercise 3 is $\rho c_p\int N_aN_b\,dA$,
# assembled: the same matrix.

# %%
assert not report, "the stub as handed out must fail the grader"


def my_triangles(xe, signed=True, projection=True):
    """(grad N (M, 3, 2), A (M,), int N_a N_b dA (M, 3, 3), int (N_a - 1/3)(N_b - 1/3) dA (M, 3, 3))."""
    x, y = xe[..., 0], xe[..., 1]
    xb, yb, xc, yc = np.roll(x, -1, axis=1), np.roll(y, -1, axis=1), np.roll(x, -2, axis=1), np.roll(y, -2, axis=1)
    A = 0.5 * (x * yb - xb * y).sum(axis=1)                                  # the shoelace formula, signed
    if not signed:
        A = np.abs(A)
    g = np.stack([yb - yc, xc - xb], axis=-1) / (2 * A[:, None, None])
    M = A[:, None, None] * (1 + np.eye(3)) / 12
    return g, A, M, A[:, None, None] * (np.eye(3) / 12 - 1 / 36) if projection else M


def pkg_triangles(xe):
    g, A = shape_gradients(xe)
    return g, A, pressure_mass(A), ppp_stabilisation(A)


assert check(my_triangles, pkg_triangles, cases_ex4, names=("grad N", "A", "int N N dA", "int (N - 1/3)(N - 1/3) dA"))
absolute = check(lambda xe: my_triangles(xe, signed=False), pkg_triangles, cases_ex4, name="|A|")
assert not absolute and absolute.n_passed == 2
assert not check(lambda xe: my_triangles(xe, projection=False), pkg_triangles, cases_ex4, name="int N N twice")
tri_p = alpha_shape_mesh(patch, None).tri
C_consistent = thermal.capacity(patch, tri_p, rc45, lumped=False).toarray()
C_mine = np.zeros_like(C_consistent)
np.add.at(C_mine, (tri_p[:, :, None], tri_p[:, None, :]), rc45 * my_triangles(patch[tri_p])[2])
assert np.allclose(C_mine, C_consistent, rtol=1e-12, atol=1e-12 * np.abs(C_consistent).max())
