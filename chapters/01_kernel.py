# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.16.0
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Chapter 1 — The smoothing kernel
#
# A particle method has no mesh, so it cannot take a derivative the usual way. SPH replaces every field by a
# weighted average over the neighbouring particles, and the weight is a **smoothing kernel** $W$. Islam, Bansal &
# Peng (Section 2.1) write a field $f$ and its gradient at particle $i$ as
#
# $$ f(\mathbf x_i) \approx \sum_j f(\mathbf x_j)\, W(\mathbf x_{ij})\, V_j , \qquad
#    \nabla f(\mathbf x_i) \approx -\sum_j \big[f(\mathbf x_i)-f(\mathbf x_j)\big]\, \nabla_i W(\mathbf x_{ij})\, V_j
#    \qquad \text{(Eqs. 7, 8)} $$
#
# with $\mathbf x_{ij} = \mathbf x_i - \mathbf x_j$ and particle volume $V_j = m_j/\rho_j$. Two approximations hide
# in these sums:
#
# 1. **Kernel approximation.** Replace the Dirac delta in $f(\mathbf x) = \int f(\mathbf x')\,\delta(\mathbf
#    x-\mathbf x')\,d\mathbf x'$ by a smooth bump $W$ of width $h$ (the *smoothing length*).
# 2. **Particle approximation.** Replace the integral by a sum over particles, each standing for a volume $V_j$.
#
# What we ask of a kernel: it integrates to one (so a constant is reproduced), it depends only on
# $r = \lvert\mathbf x_{ij}\rvert$ (so pair forces are equal and opposite), it has **compact support** (here
# $r < 2h$, so each particle talks to a few dozen neighbours), and it is positive and smooth.
#
# This chapter builds the paper's kernel from its formula, checks the package's fast code against a plain
# transcription, and then shows where the two approximations break down.

# %%
from fractions import Fraction

import matplotlib.pyplot as plt
import numpy as np
from scipy import integrate, special

from refsph.kernels import get_kernel
from refsph.neighbours import find_pairs, pair_count_per_particle, scatter_add
from refsph.teaching.plots import colorbar, particle_field
from refsph.teaching.notebook import chapter
ch = chapter("01_kernel")

# %% [markdown]
# ## The cubic B-spline, Eq. (9)
#
# With the normalised distance $q = r/h$ the paper's kernel is
#
# $$ W(q,h) = \alpha_d\, f(q), \qquad
#    f(q) = \begin{cases} 1 - \tfrac32 q^2 + \tfrac34 q^3, & 0 \le q \le 1,\\[2pt]
#                          \tfrac14 (2-q)^3, & 1 \le q \le 2,\\[2pt]
#                          0, & q > 2. \end{cases} \qquad \text{(Eq. 9)}$$
#
# **In plain words.** $f$ is a bell of two cubic pieces: 1 and flat at the centre, it bends down and at $q=1$
# hands over to the outer piece, which reaches zero at $q=2$ with zero slope and zero curvature.
# So the kernel sees neighbours up to $r = 2h$ and nothing beyond. At the joint $q=1$ the value, slope and
# curvature of the two pieces agree (the kernel is $C^2$); only the third derivative jumps.
#
# Every force needs the slope $\partial W/\partial r = \alpha_d f'(q)/h$, with
# $f'(q) = -3q + \tfrac94 q^2$ for $q\le1$ and $-\tfrac34 (2-q)^2$ for $1\le q\le2$.
#
# **Normalisation.** $W$ must integrate to one. It depends only on $r$, so the integral over the plane is
# $\int_0^{2h} 2\pi r\, W\, dr$ and over space $\int_0^{2h} 4\pi r^2 W\, dr$. With $r = qh$:
#
# $$ 1 = \alpha_2\, 2\pi h^2 \int_0^2 q f(q)\,dq, \qquad 1 = \alpha_3\, 4\pi h^3 \int_0^2 q^2 f(q)\,dq .$$
#
# The integrands are polynomials, so the next cell integrates them **exactly** with fractions: the paper's
# constants $\alpha_2 = 10/(7\pi h^2)$ and $\alpha_3 = 1/(\pi h^3)$ come out of the formula, not out of a book.

# %%
F = Fraction


def poly_mul(p, s):
    """Product of two polynomials given as coefficient lists, lowest power first."""
    out = [F(0)] * (len(p) + len(s) - 1)
    for i, a in enumerate(p):
        for j, b in enumerate(s):
            out[i + j] += F(a) * F(b)
    return out


def poly_int(p, a, b):
    """Exact integral of a polynomial over [a, b]."""
    return sum(c * (F(b) ** (k + 1) - F(a) ** (k + 1)) / (k + 1) for k, c in enumerate(p))


def poly_der(p, x, order):
    """Value at x of the order-th derivative of a polynomial."""
    for _ in range(order):
        p = [k * c for k, c in enumerate(p)][1:]
    return sum(c * F(x) ** k for k, c in enumerate(p))


two_minus_q = [F(2), F(-1)]
inner = [F(1), F(0), F(-3, 2), F(3, 4)]                                     # 1 - 3/2 q^2 + 3/4 q^3 on [0, 1]
outer = [c / 4 for c in poly_mul(poly_mul(two_minus_q, two_minus_q), two_minus_q)]   # (2 - q)^3 / 4 on [1, 2]
q1, q2 = [F(0), F(1)], [F(0), F(0), F(1)]                                 # the polynomials q and q^2
I2 = poly_int(poly_mul(q1, inner), 0, 1) + poly_int(poly_mul(q1, outer), 1, 2)
I3 = poly_int(poly_mul(q2, inner), 0, 1) + poly_int(poly_mul(q2, outer), 1, 2)
print(f"int q f dq = {I2},  int q^2 f dq = {I3}")
print(f"alpha_2 h^2 = 1 / (2 pi I2) = {1 / (2 * I2)} / pi;   alpha_3 h^3 = 1 / (4 pi I3) = {1 / (4 * I3)} / pi")
for order in range(4):
    print(f"f^({order})(1): inner piece {poly_der(inner, 1, order)}, outer piece {poly_der(outer, 1, order)}")

cubic, wendland = get_kernel("cubic"), get_kernel("wendland")
assert 1 / (2 * I2) == F(10, 7) and 1 / (4 * I3) == 1
assert np.isclose(cubic.alpha(1.0, 2), 10 / (7 * np.pi)) and np.isclose(cubic.alpha(1.0, 3), 1 / np.pi)
assert all(poly_der(inner, 1, k) == poly_der(outer, 1, k) for k in range(3))      # C^2 at the joint ...
assert poly_der(inner, 1, 3) != poly_der(outer, 1, 3)                             # ... but not C^3

# %% [markdown]
# ## The Wendland $C^2$ kernel
#
# The second paper of this project (Rodriguez Prieto et al.) uses a Wendland function instead. With the support
# scaled to $2h$ (Dehnen & Aly 2012),
#
# $$ W(q,h) = \alpha_d \left(1-\tfrac q2\right)^4 (2q+1), \quad 0\le q\le 2, \qquad
#    \alpha_2 = \frac{7}{4\pi h^2}, \quad \alpha_3 = \frac{21}{16\pi h^3}, \qquad
#    f'(q) = -5q\left(1-\tfrac q2\right)^3 .$$
#
# One polynomial on the whole support, no joint. Why bother with a second kernel is the subject of the last
# section: the cubic spline has a weakness that shows up only when you give it many neighbours.
#
# ## The kernel in plain code
#
# Eq. (9) as a scalar function with an `if` per line of the formula, and the same for Wendland. The package
# (`refsph.kernels`) evaluates whole arrays without branches; we check it against these on many $q$ values,
# including the joints $q = 1, 2$ and points just either side of them.

# %%
def W_cubic_plain(r, h, dim):
    """Eq. (9), one value at a time."""
    alpha = 10.0 / (7.0 * np.pi * h**2) if dim == 2 else 1.0 / (np.pi * h**3)
    q = r / h
    if q <= 1.0:
        return alpha * (1.0 - 1.5 * q**2 + 0.75 * q**3)
    elif q <= 2.0:
        return alpha * 0.25 * (2.0 - q) ** 3
    return 0.0


def dWdr_cubic_plain(r, h, dim):
    """dW/dr of Eq. (9) = alpha_d f'(q) / h."""
    alpha = 10.0 / (7.0 * np.pi * h**2) if dim == 2 else 1.0 / (np.pi * h**3)
    q = r / h
    if q <= 1.0:
        return alpha / h * (-3.0 * q + 2.25 * q**2)
    elif q <= 2.0:
        return alpha / h * (-0.75 * (2.0 - q) ** 2)
    return 0.0


def W_wendland_plain(r, h, dim):
    alpha = 7.0 / (4.0 * np.pi * h**2) if dim == 2 else 21.0 / (16.0 * np.pi * h**3)
    q = r / h
    return alpha * (1.0 - 0.5 * q) ** 4 * (2.0 * q + 1.0) if q <= 2.0 else 0.0


def dWdr_wendland_plain(r, h, dim):
    alpha = 7.0 / (4.0 * np.pi * h**2) if dim == 2 else 21.0 / (16.0 * np.pi * h**3)
    q = r / h
    return alpha / h * (-5.0 * q * (1.0 - 0.5 * q) ** 3) if q <= 2.0 else 0.0


KERNELS = {"cubic": cubic, "wendland": wendland}
PLAIN = {"cubic": (W_cubic_plain, dWdr_cubic_plain), "wendland": (W_wendland_plain, dWdr_wendland_plain)}
rng = np.random.default_rng(1)
q_test = np.concatenate([np.linspace(0.0, 3.0, 301), rng.uniform(0, 3, 200),
                         [0.0, 1.0, 2.0, 1 - 1e-12, 1 + 1e-12, 2 - 1e-12, 2 + 1e-12]])
worst = 0.0
for name, K in KERNELS.items():
    W_plain, dW_plain = PLAIN[name]
    for h in (1.0, 3.7e-5):          # a unit h and a machining-scale h (tens of micrometres)
        for dim in (2, 3):
            r = q_test * h
            W_ref = np.array([W_plain(ri, h, dim) for ri in r])
            dW_ref = np.array([dW_plain(ri, h, dim) for ri in r])
            W_pkg, dW_pkg = K.w(r, h, dim), K.dw_dr(r, h, dim)
            assert np.allclose(W_pkg, W_ref, rtol=1e-13, atol=1e-15 * W_ref.max())
            assert np.allclose(dW_pkg, dW_ref, rtol=1e-13, atol=1e-15 * abs(dW_ref).max())
            worst = max(worst, np.max(abs(W_pkg - W_ref)) / W_ref.max(),
                        np.max(abs(dW_pkg - dW_ref)) / abs(dW_ref).max())
print(f"package vs plain formula: largest difference relative to the peak = {worst:.1e}")

# %% [markdown]
# The two kernels side by side. Wendland is more peaked at the centre and falls off a little faster; both are
# steepest (the dots) well inside the support, and both fade out smoothly at $q = 2$.

# %%
q_plot = np.linspace(0.0, 2.5, 501)
qq = np.linspace(0, 2, 20001)
q_peak = {name: qq[np.argmax(-K.df(qq))] for name, K in KERNELS.items()}       # where the slope is steepest
fig, axes = plt.subplots(1, 2, figsize=(10, 4))
for (name, K), color in zip(KERNELS.items(), ("C0", "C3")):
    axes[0].plot(q_plot, K.w(q_plot, 1.0, 2), color=color, label=name)
    axes[1].plot(q_plot, K.dw_dr(q_plot, 1.0, 2), color=color, label=name)
    axes[1].plot(q_peak[name], K.dw_dr(q_peak[name], 1.0, 2), "o", color=color)
for ax, ylabel in zip(axes, (r"$h^2\,W$ [-]", r"$h^3\,\partial W/\partial r$ [-]")):
    ax.axvline(2.0, color="0.5", lw=0.8, ls="--")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel(r"$q = r/h$ [-]")
    ax.set_ylabel(ylabel)
    ax.legend(frameon=False)
axes[0].set_title("kernel (2D normalisation)")
axes[1].set_title("radial slope; support ends at q = 2")
fig.tight_layout()
ch.show(fig, "01_kernels.png", caption="The cubic B-spline and the Wendland C2 kernel (left, 2D normalisation) and "
                                       "their radial slopes (right) against q = r/h; both fade out smoothly at the "
                                       "end of the support, q = 2, and the dots mark the steepest slope.")
print(f"|f'(q)| is largest at q = {q_peak['cubic']:.3f} (cubic) and q = {q_peak['wendland']:.3f} (Wendland)")
assert abs(q_peak["cubic"] - 2 / 3) < 1e-3 and abs(q_peak["wendland"] - 0.5) < 1e-3

# %% [markdown]
# ## The kernel gradient
#
# $W$ depends on $\mathbf x_i$ only through $r$, so by the chain rule
#
# $$ \nabla_i W(\mathbf x_{ij}) = \frac{\partial W}{\partial r}\,\frac{\mathbf x_{ij}}{r}. $$
#
# Since $\partial W/\partial r < 0$, $\nabla_i W_{ij}$ points from $i$ **towards** $j$, and swapping $i$ and $j$
# flips its sign. That antisymmetry is what makes pairwise forces conserve momentum (Chapter 2).
#
# The formula divides by $r$, which is zero for a particle paired with itself. Near the centre $f'(q) \propto q$,
# so $\frac1r\frac{\partial W}{\partial r} = \frac{\alpha_d}{h^2}\frac{f'(q)}{q}$ has a finite limit ($-3$ for the
# cubic spline, $-5$ for Wendland, times $\alpha_d/h^2$). The package evaluates this ratio directly, so $\nabla W$ is
# never `nan`. We check the gradient against central finite differences of $W(\lvert\mathbf x\rvert)$ at random
# points, and the limit at $r=0$.

# %%
def fd_gradient(K, x, h, dim, eps):
    """Central finite differences of W(|x|) in each coordinate, x of shape (M, dim)."""
    g = np.empty_like(x)
    for k in range(dim):
        e = np.zeros(dim)
        e[k] = eps
        g[:, k] = (K.w(np.linalg.norm(x + e, axis=1), h, dim) - K.w(np.linalg.norm(x - e, axis=1), h, dim)) / (2 * eps)
    return g


for name, K in KERNELS.items():
    for dim in (2, 3):
        h = 1.3
        d = rng.normal(size=(500, dim))                          # random directions ...
        x = d / np.linalg.norm(d, axis=1, keepdims=True) * rng.uniform(0.01 * h, 2.2 * h, size=(500, 1))
        g_an = K.grad(x, h, dim)                                 # ... and radii from the centre to outside
        err = np.max(np.abs(g_an - fd_gradient(K, x, h, dim, eps=1e-5 * h))) / np.max(np.abs(g_an))
        print(f"{name:9s} {dim}D: max |analytic - finite difference| / max |grad W| = {err:.1e}")
        assert err < 1e-7
        assert np.array_equal(K.grad(-x, h, dim), -g_an)         # grad_j W(x_ji) = -grad_i W(x_ij)
        at0 = K.dw_dr_over_r(np.array([0.0]), h, dim)[0]
        assert np.isclose(at0, K.alpha(h, dim) / h**2 * K.df_over_q_at_zero)   # the finite limit at r = 0
        assert np.all(K.grad(np.zeros((1, dim)), h, dim) == 0.0)  # a particle exerts no gradient on itself

# %% [markdown]
# ## Unit integral and compact support
#
# The fractions above *derived* $\alpha_d$; here an independent numerical check of the package: adaptive
# quadrature of $\int_0^{2h} 2\pi r W\,dr$ (2D) and $\int_0^{2h} 4\pi r^2 W\,dr$ (3D), told where the pieces join.
# And $W$, $\partial W/\partial r$ and $\nabla W$ must be exactly zero, not just small, from $r = 2h$ on.

# %%
for name, K in KERNELS.items():
    for dim in (2, 3):
        h = 0.7
        shell = (lambda r: 2 * np.pi * r) if dim == 2 else (lambda r: 4 * np.pi * r**2)
        val, _ = integrate.quad(lambda r: shell(r) * float(K.w(r, h, dim)), 0.0, 2.5 * h,
                                points=[h, 2 * h], epsabs=1e-13, epsrel=1e-13, limit=200)
        print(f"{name:9s} {dim}D: integral of W - 1 = {val - 1.0:+.1e}")
        assert abs(val - 1.0) < 1e-12
        r_out = np.linspace(2 * h, 5 * h, 1000)
        assert np.all(K.w(r_out, h, dim) == 0.0) and np.all(K.dw_dr(r_out, h, dim) == 0.0)
        x_out = rng.normal(size=(1000, dim))
        x_out *= rng.uniform(2 * h, 5 * h, size=(1000, 1)) / np.linalg.norm(x_out, axis=1, keepdims=True)
        assert np.all(K.grad(x_out, h, dim) == 0.0)
        r_in = np.linspace(0, 2 * h, 1001)[:-1]
        assert np.all(K.w(r_in, h, dim) > 0) and np.all(K.dw_dr(r_in[1:], h, dim) < 0)

# %% [markdown]
# ## The partition of unity: a sum is not an integral
#
# Put $f \equiv 1$ into Eq. (7): a constant is reproduced only if $\sum_j V_j W_{ij} = 1$ (the sum includes
# $j = i$). The gradient of a constant, in the "raw" form $\sum_j V_j \nabla_i W_{ij}$, should be $\mathbf 0$.
# How close the particle sums come depends on the arrangement and on $h/\Delta p$, the smoothing length over the
# particle spacing. The paper uses $h/\Delta p = 1.5$ (Taylor bar, pressing) and $1.8$ (cutting).
#
# First a particle deep inside a perfect square (2D) or cubic (3D) lattice, $V_j = \Delta p^d$: sum over all
# lattice points within $2h$, and count the **neighbours** (other particles with $r < 2h$).

# %%
def interior_sums(K, hdp, dim):
    """Sum_j V_j W_ij, h |Sum_j V_j grad_i W_ij| and the neighbour count inside an infinite lattice (dp = 1)."""
    n = int(np.ceil(2 * hdp)) + 1
    g = np.arange(-n, n + 1)
    xij = -np.stack(np.meshgrid(*([g] * dim), indexing="ij"), axis=-1).reshape(-1, dim).astype(float)
    r = np.linalg.norm(xij, axis=1)
    s_w = K.w(r, hdp, dim).sum()
    s_g = np.linalg.norm(K.grad(xij, hdp, dim).sum(axis=0)) * hdp
    return s_w, s_g, int(np.count_nonzero((r > 0) & (r < 2 * hdp * (1 - 1e-12))))


for name, K in KERNELS.items():
    for dim in (2, 3):
        s_w, s_g, n_nb = interior_sums(K, 1.5, dim)
        print(f"{name:9s} {dim}D, h/dp = 1.5: sum V W - 1 = {s_w - 1:+.1e}, h |sum V grad W| = {s_g:.0e}, "
              f"{n_nb} neighbours")
        assert abs(s_w - 1) < 0.02 and s_g < 1e-12     # close to one; zero gradient by the lattice's symmetry
assert interior_sums(cubic, 1.5, 2)[2] == 24 and interior_sums(cubic, 1.5, 3)[2] == 92

# %% [markdown]
# Inside a perfect lattice the gradient sum vanishes to round-off (every neighbour has a mirror image), and the
# kernel sum misses one by a fraction of a per cent. That small miss does not go away as $\Delta p \to 0$ at fixed
# $h/\Delta p$: it is the particle approximation. The neighbour count grows like $(h/\Delta p)^d$, and it is
# the main cost of SPH.
#
# ### At a free surface the sums are truncated
#
# Now a finite 2D block. Near its edges part of the kernel's support lies in empty space. We compute the sums
# the way the package does — half pairs from `find_pairs` (each pair once), added to both particles with
# `scatter_add` — and check them against a plain sum over all pairs $(i, j)$.

# %%
def block_2d(nx, ny, dp):
    gx, gy = np.meshgrid(np.arange(nx) * dp, np.arange(ny) * dp, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel()])


def sph_sums(x, V, h, K):
    """Sum_j V_j W_ij (including j = i), Sum_j V_j grad_i W_ij and the neighbour count, via half pairs."""
    n, dim = x.shape
    I, J = find_pairs(x, 2 * h)
    xij = x[I] - x[J]
    Wij = K.w(np.linalg.norm(xij, axis=1), h, dim)
    gij = K.grad(xij, h, dim)                                  # grad_i W(x_ij); grad_j W(x_ji) = -gij
    s_w = V * K.w(0.0, h, dim) + scatter_add(I, V * Wij, n) + scatter_add(J, V * Wij, n)
    s_g = scatter_add(I, V * gij, n) - scatter_add(J, V * gij, n)
    inside = np.linalg.norm(xij, axis=1) < 2 * h * (1 - 1e-12)
    return s_w, s_g, pair_count_per_particle(I[inside], J[inside], n)


def sph_sums_plain(x, V, h):
    """The same sums for the cubic spline in 2D, pair by pair over all (i, j): no neighbour list, no symmetry."""
    n = len(x)
    s_w, s_g = np.zeros(n), np.zeros((n, 2))
    for i, (xi, yi) in enumerate(x.tolist()):
        for xj, yj in x.tolist():
            dx, dy = xi - xj, yi - yj
            r = (dx * dx + dy * dy) ** 0.5
            if r < 2 * h:
                s_w[i] += V * W_cubic_plain(r, h, 2)
                if r > 0:
                    dWdr = dWdr_cubic_plain(r, h, 2)
                    s_g[i] += V * dWdr * np.array([dx, dy]) / r
    return s_w, s_g


dp = 1.0e-5                                    # 10 micrometres, as in the paper's cutting model
nx, ny = 24, 16
x_blk, V_blk, h = block_2d(nx, ny, dp), dp**2, 1.5 * dp
s_w, s_g, n_nb = sph_sums(x_blk, V_blk, h, cubic)
s_w_ref, s_g_ref = sph_sums_plain(x_blk, V_blk, h)
assert np.allclose(s_w, s_w_ref, rtol=1e-12) and np.allclose(s_g, s_g_ref, rtol=1e-10, atol=1e-10 / h)

ix, iy = np.round(x_blk[:, 0] / dp).astype(int), np.round(x_blk[:, 1] / dp).astype(int)
depth = np.minimum.reduce([ix, iy, nx - 1 - ix, ny - 1 - iy])      # layers to the nearest surface
centre, edge, corner = [np.flatnonzero(m)[0] for m in ((ix == nx // 2) & (iy == ny // 2),
                                                        (ix == nx // 2) & (iy == 0), (ix == 0) & (iy == 0))]
for label, k in (("centre", centre), ("middle of an edge", edge), ("corner", corner)):
    print(f"cubic, h/dp = 1.5, {label:18s}: sum V W = {s_w[k]:.3f},  h |sum V grad W| = "
          f"{np.linalg.norm(s_g[k]) * h:.2f},  {n_nb[k]} neighbours")
deep = depth >= 3                                                           # support entirely inside
assert np.allclose(s_w[deep], interior_sums(cubic, 1.5, 2)[0], rtol=1e-12)   # = the infinite lattice
assert 0.5 < s_w[edge] < 0.85 and 0.25 < s_w[corner] < s_w[edge]          # a large part of the support is empty
assert np.linalg.norm(s_g[edge]) * h > 0.1 and s_g[edge][1] > 0            # O(1/h), pointing into the block

# %% [markdown]
# The picture: the kernel sum is one inside and falls off in the outer two or three layers; the gradient of a
# constant is zero inside and of order $1/h$ at the surface, pointing into the block.

# %%
fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
lims = dict(xlim=(-1, nx), ylim=(-1, ny), spread=1.0, fill=None)     # in units of dp (scale = 1 / dp)
sc = particle_field(axes[0], x_blk, s_w, dp, scale=1 / dp, **lims)
colorbar(fig, sc, axes[0], r"$\sum_j V_j W_{ij}$ [-]")
axes[0].set_title("kernel sum, h/Δp = 1.5")
sc = particle_field(axes[1], x_blk, np.linalg.norm(s_g, axis=1) * h, dp, scale=1 / dp, **lims)
sel = (depth <= 1) & ((ix + iy) % 2 == 0)          # arrows on the surface layers, every other particle
axes[1].quiver(ix[sel], iy[sel], s_g[sel, 0], s_g[sel, 1], color="k", width=0.005)
colorbar(fig, sc, axes[1], r"$h\,|\sum_j V_j \nabla_i W_{ij}|$ [-]")
axes[1].set_title("gradient of a constant")
for ax in axes:
    ax.set_xlabel(r"$x/\Delta p$ [-]")
    ax.set_ylabel(r"$y/\Delta p$ [-]")
fig.tight_layout()
ch.show(fig, "01_partition_of_unity.png", caption="A block of particles with h/Δp = 1.5: the kernel sum Σ V W (left) "
                                                  "is one inside and falls off in the outer two or three layers; the "
                                                  "gradient of a constant (right) is zero inside and of order 1/h at "
                                                  "the surface, pointing into the block (arrows).")

# %% [markdown]
# At a straight edge half of the support lies outside the material, at a right-angled corner three quarters,
# so the continuum values there are $\frac12$ and $\frac14$. The particle sums are higher than that (a surface
# particle's own volume reaches half a spacing beyond it, and its own row sits where $W$ is largest), but far
# below one. Anything computed with Eq. (7) at the surface — a density by
# summation, an interpolated stress — is underestimated by that factor. Eq. (8) subtracts $f_i$ and so still gives
# zero for a constant, but it gets the gradient of a *linear* field wrong at the surface: Chapter 2 measures
# this on a velocity field, and Chapter 3 corrects it.
#
# ## Why Wendland: the pairing instability
#
# Give the cubic spline many neighbours (a large $h/\Delta p$) to make the sums more accurate, and the particles
# may collapse into pairs. Dehnen & Aly (2012) traced this **pairing instability** to the kernel's Fourier
# transform $\hat W(k)$: a kernel whose transform is negative for some wavenumbers is prone to pairing, one whose
# transform is non-negative is not. Wendland built his functions to have a non-negative transform. For a radial
# kernel
#
# $$ \hat W(k) = \int_0^{2h} 2\pi r\, W(r)\, J_0(kr)\,dr \ \ (2D), \qquad
#    \hat W(k) = \int_0^{2h} 4\pi r^2\, W(r)\, \frac{\sin kr}{kr}\,dr \ \ (3D), $$
#
# with $\hat W(0) = 1$ by normalisation. The next cell evaluates them (Simpson's rule) for $0 \le kh \le 20$.

# %%
def fourier_radial(K, dim, kh, n_r=2001):
    """Fourier transform of the radial kernel (h = 1) at wavenumbers kh, by Simpson's rule on n_r points."""
    r = np.linspace(0.0, 2.0, n_r)
    W = K.w(r, 1.0, dim)
    if dim == 2:
        integrand = 2 * np.pi * r * W * special.j0(np.outer(kh, r))
    else:
        integrand = 4 * np.pi * r**2 * W * np.sinc(np.outer(kh, r) / np.pi)
    return integrate.simpson(integrand, x=r, axis=1)


kh = np.linspace(0.0, 20.0, 401)
for name, K in KERNELS.items():
    for dim in (2, 3):
        w_hat = fourier_radial(K, dim, kh)
        print(f"{name:9s} {dim}D: W_hat(0) = {w_hat[0]:.6f}, smallest W_hat = {w_hat.min():+.1e} "
              f"at kh = {kh[np.argmin(w_hat)]:.1f}")
        assert abs(w_hat[0] - 1.0) < 1e-8
        assert (w_hat.min() < -1e-4) if name == "cubic" else (w_hat.min() > 0.0)

# %% [markdown]
# The cubic spline's transform dips slightly below zero; Wendland's stays positive. At the paper's modest
# neighbour numbers the cubic spline works well; the trouble starts when one raises $h/\Delta p$ to reduce the
# error of the sums. With Wendland that is a free option — but, as Exercise 2 shows, it needs it more.
#
# ## Where it fails
#
# * **Truncated support at free surfaces.** The approximations assume the support is full of particles. At an
#   edge or corner the kernel sum falls well below one and the raw gradient sum is of order $1/h$. In machining,
#   the chip, the machined surface and the tool contact are all such places. Remedies: density from the
#   continuity equation instead of summation, kernel-gradient corrections (Chapter 3), ghost particles at walls.
# * **Sums are not integrals.** Even inside a perfect lattice the kernel sum misses one, and a disordered particle
#   set does worse; the miss does not shrink as $\Delta p \to 0$ at fixed $h/\Delta p$.
# * **Pairing instability** of the cubic spline limits how many neighbours it can use; Wendland is free of it
#   but needs more neighbours for the same accuracy.
# * **Neither kernel cures the tensile instability** of Eulerian SPH in tension (Chapter 2).
# * **One smoothing length for all particles.** Strongly compressed or stretched regions then have too many or
#   too few neighbours; adaptive $h$ is not implemented.

# %% [markdown]
# ## Your turn
#
# Predict first, run, then open *What you should see*. The last exercise asks for code, graded against the package.
#
# ### Exercise 1 — More neighbours, same surface
#
# Predict: if you raise $h/\Delta p$ from 1.5 to 3, the interior particle gets about four times as many
# neighbours. Does the kernel sum at the middle of an edge get closer to one?

# %% tags=["exercise"]
HDP = 1.5          # <- change this (e.g. to 2.0 or 3.0) and run the cell again
s_w_in, _, n_in = interior_sums(cubic, HDP, 2)
s_w_b, _, _ = sph_sums(x_blk, V_blk, HDP * dp, cubic)
print(f"h/dp = {HDP}: interior sum V W - 1 = {s_w_in - 1:+.1e} with {n_in} neighbours; "
      f"edge {s_w_b[edge]:.3f}, corner {s_w_b[corner]:.3f}")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# The neighbour count grows like $(h/\Delta p)^2$, but the edge and corner sums get *worse*, falling towards the
# continuum values $\frac12$ and $\frac14$ of a kernel cut in half or in four (the surface row's excess, its volume
# reaching $\Delta p/2$ outside, shrinks like $\Delta p/h$), and more layers lie within $2h$ of the surface. More
# neighbours do not cure a free surface.
# </details>

# %% [markdown]
# ### Exercise 2 — Switch the kernel to Wendland
#
# Predict: Wendland is the "stable" kernel. Does it also reproduce a constant better inside the lattice, at
# every $h/\Delta p$?

# %% tags=["exercise"]
KERNEL = "cubic"   # <- change this to "wendland" and run the cell again
for hdp in (1.2, 1.5, 2.0, 3.0):
    s_w_in, _, n_in = interior_sums(get_kernel(KERNEL), hdp, 2)
    print(f"{KERNEL}, h/dp = {hdp}: interior sum V W - 1 = {s_w_in - 1:+.1e} ({n_in} neighbours)")
print(f"smallest Fourier transform (2D): {fourier_radial(get_kernel(KERNEL), 2, kh).min():+.1e}")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# The cubic spline's error is small but jumps up and down with $h/\Delta p$ (it depends on how the lattice shells
# fall on the kernel); its Fourier transform has a negative minimum. Wendland's error is larger at every
# $h/\Delta p$ here, much larger at small ones, and falls steadily as $h/\Delta p$ grows; its transform stays
# positive. It is the kernel you *can* give many neighbours, and the one that needs them.
# </details>

# %% [markdown]
# ### Exercise 3 — Write the kernel yourself
#
# Write $W$ and $\nabla_i W$ of the cubic spline, Eq. (9), for many pairs at once: `xij` holds one
# $\mathbf x_{ij}$ per row (shape (M, dim), dim = 2 or 3), `h` is in metres; return `W`, shape (M,), and `gradW`,
# shape (M, dim). Whole arrays, no loop (`np.linalg.norm`, `np.where`). The grader compares your function with
# `refsph.kernels` on five cases, among them pairs exactly at the joints $q = 1$ and $q = 2$, pairs beyond the
# support, and a particle paired with itself ($r = 0$).
#
# Predict: which case will a first attempt most likely fail, and why?

# %% tags=["exercise"]
from refsph.teaching.grader import case, check


def my_cubic(xij, h, dim):
    """W(|x_ij|, h) and grad_i W(x_ij) of Eq. (9) for each row of xij: arrays of shape (M,) and (M, dim)."""
    raise NotImplementedError("write W and grad W of Eq. (9) here")      # <- replace this line by your code


def pkg_cubic(xij, h, dim):                                              # the package's answer
    return cubic.w(np.linalg.norm(xij, axis=1), h, dim), cubic.grad(xij, h, dim)


h_ex = 1.5e-5                                                            # h = 1.5 dp with dp = 10 um [m]
cases_ex3 = [case(rng.uniform(-2.2, 2.2, (60, 2)) * h_ex, h_ex, 2, label="2D, random pairs"),
             case(rng.uniform(-2.2, 2.2, (60, 3)) * h_ex, h_ex, 3, label="3D, random pairs"),
             case(np.array([[h_ex, 0.0], [0.0, -2 * h_ex], [0.6 * h_ex, 0.8 * h_ex]]), h_ex, 2, label="q = 1 and 2"),
             case(np.array([[2.5 * h_ex, 0.0], [0.0, 4.0 * h_ex]]), h_ex, 2, label="beyond the support, q > 2"),
             case(np.zeros((1, 2)), h_ex, 2, label="r = 0: a particle paired with itself")]
report = check(my_cubic, pkg_cubic, cases_ex3, names=("W", "grad W"))

# %% [markdown]
# <details><summary>What you should see</summary>
#
# As handed out: `FAIL ... not written yet`. Then, typically, a failure at $r = 0$: $\nabla W =
# \frac{\partial W}{\partial r}\frac{\mathbf x_{ij}}{r}$ gives $0/0$ = `nan` there. Use the finite limit of this
# chapter's section on the gradient: $\frac1r\frac{\partial W}{\partial r} = \frac{\alpha_d}{h^2}\frac{f'(q)}{q}$, and
# $f'(q)/q = -3 + \frac94 q$ on the inner piece has no division at all. Beyond the support the outer piece
# $\frac14(2-q)^3$ turns negative: it needs its own zero. When all five cases agree: `PASS`.
# </details>
