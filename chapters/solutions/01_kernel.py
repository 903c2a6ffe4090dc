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
# # Chapter 1 — worked solutions (lecturer's copy)
#
# Each solution runs in the namespace of `chapters/01_kernel.py`, on the chapter's own lattice and block:
# `refsph handout DIR --instructor` inserts it right after its exercise, and `tests/test_exercises.py` executes
# that copy in quick mode, so every number quoted here is asserted. This file does not run on its own.

# %% [markdown]
# ### Solution 1 — More neighbours, same surface
#
# Run the cell with `HDP` = 1.5, 2 and 3. The neighbour count follows the number of lattice points in a disc of
# radius $2h$, about $\pi(2h/\Delta p)^2$: 24, 44, 108. The interior sum stays within a fraction of a per cent of
# one. But the edge sum falls from 0.73 to 0.61 and the corner sum from 0.53 to 0.38: towards $\frac12$ and
# $\frac14$, the continuum integrals of a kernel cut in half and in four, not towards one.
#
# Why they start above $\frac12$ and $\frac14$: the surface row sits where $W$ is largest, and its particles'
# volumes reach $\Delta p/2$ beyond the surface. That excess is of order $\Delta p/h$: the edge's excess over
# $\frac12$, times $h/\Delta p$, is 0.34 at all three (asserted). More neighbours make the particle sum a better
# approximation of the
# *truncated* integral. A free surface needs a correction (Chapter 3) or ghost particles, not resolution.

# %%
rows = {}
for hdp in (1.5, 2.0, 3.0):
    s_in, _, n_in = interior_sums(cubic, hdp, 2)
    s_b = sph_sums(x_blk, V_blk, hdp * dp, cubic)[0]
    rows[hdp] = (n_in, s_in - 1, s_b[edge], s_b[corner])
    print(f"h/dp = {hdp}: {n_in:3d} neighbours, interior {s_in - 1:+.1e}, edge {s_b[edge]:.3f}, "
          f"corner {s_b[corner]:.3f}; edge excess over 1/2 times h/dp = {(s_b[edge] - 0.5) * hdp:.3f}")
n_nb, err_in, e_edge, e_corner = (np.array(col) for col in zip(*rows.values()))
assert list(n_nb) == [24, 44, 108] and np.all(np.abs(err_in) < 4e-3)
assert e_edge[0] > e_edge[1] > e_edge[2] > 0.5 and e_corner[0] > e_corner[1] > e_corner[2] > 0.25
excess = (e_edge - 0.5) * np.array(list(rows))                          # (edge sum - 1/2) h / dp
assert np.all(np.abs(excess / excess[-1] - 1) < 0.02)                   # the excess goes like dp / h

# %% [markdown]
# ### Solution 2 — Switch the kernel to Wendland
#
# Cubic: $-2.4\cdot10^{-4}$, $+3.4\cdot10^{-3}$, $-4.2\cdot10^{-5}$, $-2.7\cdot10^{-5}$ at $h/\Delta p$ = 1.2, 1.5,
# 2, 3; Wendland: $1.8\cdot10^{-2}$, $5.1\cdot10^{-3}$, $1.2\cdot10^{-3}$, $1.6\cdot10^{-4}$. Wendland misses one
# by more at every $h/\Delta p$ (75 times more at 1.2), and its miss falls steadily.
#
# The Fourier transform explains both. By Poisson's summation formula a lattice sum of $W$ is its integral, one,
# plus $\hat W$ at the reciprocal lattice vectors, the shortest of which have $kh = 2\pi h/\Delta p$:
# $\sum_j V_jW_{ij} - 1 \approx \sum_{\mathbf k\ne0}\hat W(\mathbf k)$. Wendland's $\hat W$ is positive and falls
# steadily with $kh$, so its error is positive and falls steadily. The cubic spline's $\hat W$ swings about zero
# (its negative dip is the pairing instability's signature), so its error changes sign with $h/\Delta p$ and can be
# small by accident. The code sums the three nearest shells.

# %%
shells = np.array([1.0, np.sqrt(2.0), 2.0])                     # |k| of the three nearest shells (4 vectors each)
for name in ("cubic", "wendland"):
    K = get_kernel(name)
    errs = np.array([interior_sums(K, hdp, 2)[0] - 1 for hdp in (1.2, 1.5, 2.0, 3.0)])
    poisson = np.array([4 * fourier_radial(K, 2, 2 * np.pi * hdp * shells).sum() for hdp in (1.2, 1.5, 2.0, 3.0)])
    print(f"{name:8s}: sum V W - 1 = {', '.join(f'{e:+.1e}' for e in errs)}; Poisson, 3 shells: "
          f"{', '.join(f'{e:+.1e}' for e in poisson)}")
    assert np.all(np.sign(errs) == np.sign(poisson))            # the sign of the error is that of W_hat
    if name == "wendland":
        assert np.all(np.diff(errs) < 0) and np.all(np.abs(poisson / errs - 1) < 0.1)
        err_w = errs
    else:
        err_c = errs
assert np.all(err_w > np.abs(err_c)) and err_w[0] > 10 * abs(err_c[0])
assert fourier_radial(get_kernel("wendland"), 2, kh).min() > 0 > fourier_radial(cubic, 2, kh).min()

# %% [markdown]
# ### Solution 3 — Write the kernel yourself
#
# The handed-out stub failed as it should (asserted first). A worked answer: $q = r/h$, the two pieces with
# `np.where`, and the outer piece clipped at zero so that it vanishes beyond $q = 2$. For the gradient use
# $\nabla_iW = \frac{\alpha_d}{h^2}\frac{f'(q)}{q}\mathbf x_{ij}$: on the inner piece $f'(q)/q = -3 + \frac94q$
# has no division, so $r = 0$ gives a zero gradient (as $\mathbf x_{ij} = 0$) instead of $0/0$. The outer piece
# divides by $q \ge 1$ only.
#
# Then the mistake most first attempts make, $\frac{\partial W}{\partial r}\,\mathbf x_{ij}/r$: right everywhere
# but at $r = 0$, where the grader reports `nan`.

# %%
assert not report, "the stub as handed out must fail the grader"


def my_cubic(xij, h, dim):
    """W(|x_ij|, h) and grad_i W(x_ij) of Eq. (9) for each row of xij: arrays of shape (M,) and (M, dim)."""
    alpha = 10.0 / (7.0 * np.pi * h**2) if dim == 2 else 1.0 / (np.pi * h**3)
    q = np.linalg.norm(xij, axis=1) / h
    outer = np.clip(2.0 - q, 0.0, None)                          # zero beyond the support
    f = np.where(q <= 1.0, 1.0 - 1.5 * q**2 + 0.75 * q**3, 0.25 * outer**3)
    df_over_q = np.where(q <= 1.0, -3.0 + 2.25 * q, -0.75 * outer**2 / np.maximum(q, 1.0))
    return alpha * f, (alpha / h**2 * df_over_q)[:, None] * xij


assert check(my_cubic, pkg_cubic, cases_ex3, names=("W", "grad W"))


def divides_by_r(xij, h, dim):
    r = np.linalg.norm(xij, axis=1)
    return cubic.w(r, h, dim), (cubic.dw_dr(r, h, dim) / r)[:, None] * xij


assert not check(divides_by_r, pkg_cubic, cases_ex3, names=("W", "grad W"))
