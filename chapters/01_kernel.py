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
# Every SPH formula in this project is a sum over neighbours weighted by a **smoothing kernel**
# $W$. Islam, Bansal & Peng (Section 2.1) write a field $f$ and its gradient at particle $i$ as
#
# $$ f(\mathbf x_i) \approx \sum_j f(\mathbf x_j)\, W(\mathbf x_{ij})\, V_j , \qquad
#    \nabla f(\mathbf x_i) \approx -\sum_j \big[f(\mathbf x_i)-f(\mathbf x_j)\big]\, \nabla_i W(\mathbf x_{ij})\, V_j
#    \qquad \text{(Eqs. 7, 8)} $$
#
# with $\mathbf x_{ij} = \mathbf x_i - \mathbf x_j$ and particle volume $V_j = m_j/\rho_j$.
# These sums come from two approximations:
#
# 1. **Kernel approximation.** Write $f(\mathbf x) = \int f(\mathbf x')\,\delta(\mathbf x-\mathbf x')\,d\mathbf x'$
#    and replace the Dirac delta by a smooth, peaked function $W(\mathbf x-\mathbf x', h)$ of width $h$
#    (the *smoothing length*). This is accurate to $O(h^2)$ if $W$ is symmetric and integrates to one.
# 2. **Particle approximation.** Replace the integral by a sum over particles, each standing for a volume $V_j$.
#
# This chapter is about $W$: what the paper's kernel is, why it is normalised the way it is, how its
# gradient is computed, and — just as important for a teacher — **where the two approximations break down**.
# We check every claim with numbers, and we check the package's vectorised code `refsph.kernels`
# against the plainest possible transcription of the formulas.
#
# What we ask of a kernel:
#
# * **unit integral** $\int W\,dV = 1$ (so a constant is reproduced by the kernel approximation),
# * **symmetry** $W(\mathbf x_{ij}) = W(\mathbf x_{ji})$, depending only on $r=|\mathbf x_{ij}|$
#   (so $\nabla_i W_{ij} = -\nabla_j W_{ji}$ and pairwise forces conserve momentum),
# * **compact support** (here $r < 2h$), so each particle only talks to a few dozen neighbours,
# * **positivity** and **smoothness** (continuous first and second derivatives), and it should tend to
#   $\delta$ as $h\to 0$.

# %%
import os
from fractions import Fraction
from pathlib import Path

import numpy as np
from scipy import integrate, special

from refsph.kernels import get_kernel
from refsph.neighbours import find_pairs, pair_count_per_particle, scatter_add

QUICK = os.environ.get("REFSPH_QUICK", "0") == "1"


def _repo_root() -> Path:
    """The folder holding pyproject.toml and refsph/ (works from the repo root or from chapters/)."""
    here = Path.cwd().resolve()
    for p in (here, *here.parents):
        if (p / "pyproject.toml").exists() and (p / "refsph").is_dir():
            return p
    return here.parent if here.name == "chapters" else here


ROOT = _repo_root()
# Figures go to figures/ in the repo, or to $REFSPH_FIGURES when that is set (the tests set it to a temporary
# folder, so a quick-mode run never overwrites the committed full-resolution figures).
FIGDIR = Path(os.environ["REFSPH_FIGURES"]) if os.environ.get("REFSPH_FIGURES") else ROOT / "figures"
FIGDIR.mkdir(parents=True, exist_ok=True)
cubic, wendland = get_kernel("cubic"), get_kernel("wendland")
KERNELS = {"cubic": cubic, "wendland": wendland}
print(f"QUICK = {QUICK}; figures go to {FIGDIR}")

# %% [markdown]
# ## 1. The cubic B-spline, Eq. (9)
#
# The paper uses the cubic B-spline (Monaghan & Lattanzio 1985). With the normalised distance
# $q = r/h = |\mathbf x_i-\mathbf x_j|/h$,
#
# $$ W(q,h) = \alpha_d\, f(q), \qquad
#    f(q) = \begin{cases} 1 - \tfrac32 q^2 + \tfrac34 q^3, & 0 \le q \le 1,\\[2pt]
#                          \tfrac14 (2-q)^3, & 1 \le q \le 2,\\[2pt]
#                          0, & q > 2. \end{cases} \qquad \text{(Eq. 9)}$$
#
# **In plain words.** $f$ is a bell made of two cubic pieces. It is 1 at the centre, flat there
# ($f'(0)=0$), bends down, and at $q=1$ hands over to the outer piece $\frac14(2-q)^3$, which
# reaches zero at $q=2$ with zero slope and zero curvature. So the kernel "sees" neighbours up to
# $r = 2h$ and nothing beyond: the **support radius is $2h$**. Where the pieces meet, $f$, $f'$ and
# $f''$ all agree ($f(1)=\frac14$, $f'(1)=-\frac34$, $f''(1)=\frac32$), so the kernel is $C^2$; only
# the third derivative jumps. (Its name: as a function of one variable, $f$ is Schoenberg's $M_4$ B-spline, the
# convolution of four unit box functions, rescaled to the support $[-2, 2]$; SPH uses this 1D profile as a radial function.)
#
# The derivative with respect to $r$ (we need it for every force) is $\partial W/\partial r = \alpha_d f'(q)/h$ with
#
# $$ f'(q) = \begin{cases} -3q + \tfrac94 q^2, & 0 \le q \le 1,\\ -\tfrac34 (2-q)^2, & 1 \le q \le 2,\\ 0, & q > 2. \end{cases}$$
#
# **Normalisation $\alpha_d$.** $W$ must integrate to one over space. Because $W$ depends only on $r$,
# the integral over the plane is $\int_0^{2h} 2\pi r\, W\, dr$ and over space $\int_0^{2h} 4\pi r^2 W\, dr$.
# Substituting $r = qh$:
#
# $$ 1 = \alpha_2\, 2\pi h^2 \int_0^2 q f(q)\,dq, \qquad 1 = \alpha_3\, 4\pi h^3 \int_0^2 q^2 f(q)\,dq .$$
#
# The integrals are of polynomials, so we can do them exactly with fractions:
# $\int_0^2 q f\,dq = \frac{7}{20}$ and $\int_0^2 q^2 f\,dq = \frac14$, which gives the paper's
#
# $$ \alpha_2 = \frac{10}{7\pi h^2}, \qquad \alpha_3 = \frac{1}{\pi h^3}. $$
#
# The next cell does this arithmetic with exact rational numbers (no floating point), so the reader
# can see the constants come out of the formula and are not copied from somewhere.

# %%
def poly_integral(coeffs, a, b):
    """Exact integral of sum_k c_k q^k over [a, b] with Fraction coefficients c_k (lowest power first)."""
    return sum(Fraction(c) * (Fraction(b) ** (k + 1) - Fraction(a) ** (k + 1)) / (k + 1) for k, c in enumerate(coeffs))


def poly_mul(p, s):
    out = [Fraction(0)] * (len(p) + len(s) - 1)
    for i, a in enumerate(p):
        for j, b in enumerate(s):
            out[i + j] += Fraction(a) * Fraction(b)
    return out


def poly_pow(p, n):
    out = [Fraction(1)]
    for _ in range(n):
        out = poly_mul(out, p)
    return out


F = Fraction
# cubic spline pieces as polynomials in q
cubic_inner = [F(1), F(0), F(-3, 2), F(3, 4)]                 # 1 - 3/2 q^2 + 3/4 q^3 on [0, 1]
cubic_outer = [c / 4 for c in poly_pow([F(2), F(-1)], 3)]       # (2 - q)^3 / 4          on [1, 2]
# Wendland C2 (support 2h): (1 - q/2)^4 (2q + 1) on [0, 2]
wendland_poly = poly_mul(poly_pow([F(1), F(-1, 2)], 4), [F(1), F(2)])

q1, q2 = [F(0), F(1)], [F(0), F(0), F(1)]  # the polynomials q and q^2
I2_cubic = poly_integral(poly_mul(q1, cubic_inner), 0, 1) + poly_integral(poly_mul(q1, cubic_outer), 1, 2)
I3_cubic = poly_integral(poly_mul(q2, cubic_inner), 0, 1) + poly_integral(poly_mul(q2, cubic_outer), 1, 2)
I2_wend = poly_integral(poly_mul(q1, wendland_poly), 0, 2)
I3_wend = poly_integral(poly_mul(q2, wendland_poly), 0, 2)
print(f"cubic:    int q f dq = {I2_cubic},  int q^2 f dq = {I3_cubic}")
print(f"wendland: int q f dq = {I2_wend},  int q^2 f dq = {I3_wend}")
# alpha_2 h^2 = 1 / (2 pi I2),  alpha_3 h^3 = 1 / (4 pi I3)
print(f"cubic:    alpha_2 h^2 = 1/(2 pi * {I2_cubic}) = {1 / (2 * I2_cubic)}/pi ;"
      f"  alpha_3 h^3 = 1/(4 pi * {I3_cubic}) = {1 / (4 * I3_cubic)}/pi")
print(f"wendland: alpha_2 h^2 = {1 / (2 * I2_wend)}/pi ;  alpha_3 h^3 = {1 / (4 * I3_wend)}/pi")

assert I2_cubic == F(7, 20) and I3_cubic == F(1, 4)
assert 1 / (2 * I2_cubic) == F(10, 7) and 1 / (4 * I3_cubic) == 1
assert 1 / (2 * I2_wend) == F(7, 4) and 1 / (4 * I3_wend) == F(21, 16)
# the package's constants are these numbers over pi (h = 1)
assert np.isclose(cubic.alpha(1.0, 2), 10 / (7 * np.pi)) and np.isclose(cubic.alpha(1.0, 3), 1 / np.pi)
assert np.isclose(wendland.alpha(1.0, 2), 7 / (4 * np.pi)) and np.isclose(wendland.alpha(1.0, 3), 21 / (16 * np.pi))

# smoothness of the cubic spline at the joint q = 1: value, slope and curvature of the two pieces agree
def poly_eval(p, x):
    return sum(c * F(x) ** k for k, c in enumerate(p))


def poly_der(p):
    return [k * c for k, c in enumerate(p)][1:]


for order in range(4):
    d_in, d_out = cubic_inner, cubic_outer
    for _ in range(order):
        d_in, d_out = poly_der(d_in), poly_der(d_out)
    print(f"  f^({order})(1): inner piece {poly_eval(d_in, 1)}, outer piece {poly_eval(d_out, 1)}")
    if order < 3:
        assert poly_eval(d_in, 1) == poly_eval(d_out, 1)   # C^0, C^1, C^2
assert poly_eval(poly_der(poly_der(poly_der(cubic_inner))), 1) != poly_eval(poly_der(poly_der(poly_der(cubic_outer))), 1)

# %% [markdown]
# The last printed line shows the third derivative jumping at $q=1$ ($\frac92$ inside, $-\frac32$ outside): the
# cubic spline is $C^2$ but not $C^3$.
#
# ## 2. The Wendland $C^2$ kernel
#
# The second paper of this project (Rodriguez Prieto et al., PFEM–SPH orthogonal cutting) uses a Wendland
# function instead (Wendland 1995). With the support scaled to $2h$, as Dehnen & Aly (2012) tabulate it,
#
# $$ W(q,h) = \alpha_d \left(1-\tfrac q2\right)^4 (2q+1), \quad 0\le q\le 2, \qquad
#    \alpha_2 = \frac{7}{4\pi h^2}, \quad \alpha_3 = \frac{21}{16\pi h^3}, $$
#
# $$ f'(q) = -5q\left(1-\tfrac q2\right)^3 .$$
#
# It is a single polynomial of degree five (hence "Wendland quintic" in some papers) on the whole
# support, so there is no branch at $q=1$; it is $C^2$ as a function of $\mathbf x$ (the $C^2$ in its name),
# positive, and its first and second derivatives vanish at $q=2$. The constants were derived exactly in
# the cell above ($\int_0^2 q f\,dq = \frac27$, $\int_0^2 q^2 f\,dq = \frac4{21}$).
#
# **Why use it?** Wendland constructed these functions to be *positive definite*: their Fourier transform
# is non-negative. Dehnen & Aly (2012) showed by linear stability analysis that this is what protects SPH from
# the **pairing (clumping) instability**, in which particles collapse into pairs when a kernel is used with many
# neighbours. The B-splines, the cubic included, have Fourier transforms that dip below zero, so their
# neighbour number cannot be raised freely; Wendland kernels are stable for *any* number of neighbours,
# and have a smoother, flatter profile. The price: for the same $h/\Delta p$, the discrete sums are a little
# less accurate (we see this in Section 6), so they are used with somewhat more neighbours. We compute the
# Fourier transforms in Section 7.
#
# ## 3. The kernel in its plainest form
#
# Here is Eq. (9) as a scalar Python function with an `if`/`else` per line of the formula, and the same for
# Wendland. This is the reference against which the package's vectorised, branch-free NumPy code
# (`np.where`, `np.clip`) is checked.

# %%
def W_cubic_plain(r, h, dim):
    """Eq. (9), one value at a time."""
    alpha = 10.0 / (7.0 * np.pi * h**2) if dim == 2 else 1.0 / (np.pi * h**3)
    q = r / h
    if q <= 1.0:
        return alpha * (1.0 - 1.5 * q**2 + 0.75 * q**3)
    elif q <= 2.0:
        return alpha * 0.25 * (2.0 - q) ** 3
    else:
        return 0.0


def dWdr_cubic_plain(r, h, dim):
    """dW/dr of Eq. (9) = alpha_d f'(q) / h."""
    alpha = 10.0 / (7.0 * np.pi * h**2) if dim == 2 else 1.0 / (np.pi * h**3)
    q = r / h
    if q <= 1.0:
        return alpha / h * (-3.0 * q + 2.25 * q**2)
    elif q <= 2.0:
        return alpha / h * (-0.75 * (2.0 - q) ** 2)
    else:
        return 0.0


def W_wendland_plain(r, h, dim):
    alpha = 7.0 / (4.0 * np.pi * h**2) if dim == 2 else 21.0 / (16.0 * np.pi * h**3)
    q = r / h
    if q <= 2.0:
        return alpha * (1.0 - 0.5 * q) ** 4 * (2.0 * q + 1.0)
    else:
        return 0.0


def dWdr_wendland_plain(r, h, dim):
    alpha = 7.0 / (4.0 * np.pi * h**2) if dim == 2 else 21.0 / (16.0 * np.pi * h**3)
    q = r / h
    if q <= 2.0:
        return alpha / h * (-5.0 * q * (1.0 - 0.5 * q) ** 3)
    else:
        return 0.0


PLAIN = {"cubic": (W_cubic_plain, dWdr_cubic_plain), "wendland": (W_wendland_plain, dWdr_wendland_plain)}

# %% [markdown]
# The comparison: many $q$ values (uniform on $[0, 3]$, plus the special points $0, 1, 2$ and points just either
# side of them), two smoothing lengths, both dimensions, both kernels, for $W$ and $\partial W/\partial r$.

# %%
rng = np.random.default_rng(1)
q_test = np.concatenate([np.linspace(0.0, 3.0, 301 if QUICK else 3001), rng.uniform(0, 3, 200 if QUICK else 2000),
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
            worst = max(worst, np.max(abs(W_pkg - W_ref)) / W_ref.max(), np.max(abs(dW_pkg - dW_ref)) / abs(dW_ref).max())
print(f"package vs plain scalar formula: {len(q_test)} q values x 2 h x 2 dims x 2 kernels, "
      f"largest difference relative to the peak = {worst:.1e}")

# %% [markdown]
# ## 4. The kernel gradient
#
# Because $W$ depends on $\mathbf x_i$ only through $r = |\mathbf x_i - \mathbf x_j|$, the chain rule gives
#
# $$ \nabla_i W(\mathbf x_{ij}) = \frac{\partial W}{\partial r}\,\frac{\partial r}{\partial \mathbf x_i}
#    = \frac{\partial W}{\partial r}\,\frac{\mathbf x_{ij}}{r}. $$
#
# Since $\partial W/\partial r < 0$ inside the support, $\nabla_i W_{ij}$ points from $i$ **towards** $j$, and
# swapping $i$ and $j$ flips its sign: $\nabla_j W_{ji} = -\nabla_i W_{ij}$. That antisymmetry is what makes the
# pairwise momentum equation (Eq. 11) conserve momentum.
#
# A practical detail: the formula divides by $r$, which is zero for a particle with itself (or two particles
# on top of each other). Both kernels have $f'(q) \propto q$ near the centre, so the ratio
# $\frac{1}{r}\frac{\partial W}{\partial r} = \frac{\alpha_d}{h^2}\frac{f'(q)}{q}$ has a finite limit:
# $f'(q)/q = -3 + \frac94 q \to -3$ for the cubic spline and $-5(1-\frac q2)^3 \to -5$ for Wendland.
# The package evaluates this ratio directly (`dw_dr_over_r`), so $\nabla W$ is never `nan`.
#
# **Check against finite differences.** We pick random separation vectors inside the support and compare the
# analytic gradient with central differences of $W(|\mathbf x|)$,
# $\partial_k W \approx [W(\mathbf x + \epsilon \mathbf e_k) - W(\mathbf x - \epsilon \mathbf e_k)]/(2\epsilon)$,
# whose error is $O(\epsilon^2)$.

# %%
def fd_gradient(K, x, h, dim, eps):
    """Central finite differences of W(|x|) in each coordinate, x of shape (M, dim)."""
    g = np.empty_like(x)
    for k in range(dim):
        e = np.zeros(dim)
        e[k] = eps
        g[:, k] = (K.w(np.linalg.norm(x + e, axis=1), h, dim) - K.w(np.linalg.norm(x - e, axis=1), h, dim)) / (2 * eps)
    return g


n_fd = 500 if QUICK else 5000
fd_errors = {}
for name, K in KERNELS.items():
    for dim in (2, 3):
        h = 1.3
        # random directions, radii uniform in (0.01 h, 2.2 h): covers the centre, the q = 1 joint and outside
        d = rng.normal(size=(n_fd, dim))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        x = d * rng.uniform(0.01 * h, 2.2 * h, size=(n_fd, 1))
        g_an = K.grad(x, h, dim)
        g_fd = fd_gradient(K, x, h, dim, eps=1e-5 * h)
        scale = np.max(np.abs(g_an))
        err = np.max(np.abs(g_an - g_fd)) / scale
        fd_errors[(name, dim)] = err
        assert err < 1e-7, (name, dim, err)
        # antisymmetry grad_j W(x_ji) = -grad_i W(x_ij)
        assert np.array_equal(K.grad(-x, h, dim), -g_an)
for (name, dim), err in fd_errors.items():
    print(f"{name:9s} {dim}D: max |analytic - central FD| / max |grad W| = {err:.1e}  ({n_fd} random points, eps = 1e-5 h)")

# the limit at r = 0: finite, equal to alpha_d / h^2 * (-3) or (-5)
for name, K, lim in (("cubic", cubic, -3.0), ("wendland", wendland, -5.0)):
    for dim in (2, 3):
        h = 0.8
        at0 = K.dw_dr_over_r(np.array([0.0]), h, dim)[0]
        near0 = K.dw_dr(np.array([1e-7 * h]), h, dim)[0] / (1e-7 * h)
        assert np.isfinite(at0) and np.isclose(at0, K.alpha(h, dim) / h**2 * lim) and np.isclose(at0, near0, rtol=1e-6)
        assert np.all(K.grad(np.zeros((1, dim)), h, dim) == 0.0)    # a particle exerts no gradient on itself
print("dW/dr / r at r = 0 is finite and equals the limit alpha_d f'(q)/q -> alpha_d/h^2 * (-3 | -5)")

# %% [markdown]
# ## 5. Unit integral, compact support and positivity
#
# The exact fractions in Section 1 *derived* $\alpha_d$. Here we check the package numerically in two independent ways:
#
# * **radial quadrature**: $\int_0^{2h} 2\pi r W\,dr$ (2D) and $\int_0^{2h} 4\pi r^2 W\,dr$ (3D) with adaptive
#   Gauss–Kronrod (`scipy.integrate.quad`), telling it where the pieces join ($r = h$, $r = 2h$);
# * **Cartesian lattice sum** $\sum_{\mathbf n} (\delta x)^d\, W(|\mathbf n\,\delta x|)$ over all nodes of a
#   square (cubic) lattice. This is a completely different route — no polar coordinates — and, as Section 6
#   will show, *it is exactly the SPH particle sum for a particle in a perfect lattice with spacing $\delta x$*.

# %%
radial_err = {}
for name, K in KERNELS.items():
    for dim in (2, 3):
        h = 0.7
        shell = (lambda r: 2 * np.pi * r) if dim == 2 else (lambda r: 4 * np.pi * r**2)
        val, _ = integrate.quad(lambda r: shell(r) * float(K.w(r, h, dim)), 0.0, 2.5 * h,
                                points=[h, 2 * h], epsabs=1e-13, epsrel=1e-13, limit=200)
        radial_err[(name, dim)] = val - 1.0
        assert abs(val - 1.0) < 1e-6
        assert abs(val - 1.0) < 1e-12          # in fact it is exact to round-off
        print(f"{name:9s} {dim}D radial quadrature: integral - 1 = {val - 1.0:+.1e}")


def lattice_sum(K, h, dim, dx):
    """sum over lattice nodes n dx of dx^d W(|n dx|): a Cartesian (Riemann) sum of the kernel integral."""
    n = int(np.ceil(2 * h / dx)) + 1
    g = np.arange(-n, n + 1) * dx
    grids = np.meshgrid(*([g] * dim), indexing="ij")
    r = np.sqrt(sum(G**2 for G in grids))
    return dx**dim * K.w(r, h, dim).sum()


lattice_conv = {}
ratios = [1.0, 1.5, 2.0, 3.0, 4.0] + ([] if QUICK else [6.0, 8.0])
for name, K in KERNELS.items():
    for dim in (2, 3):
        errs = [lattice_sum(K, 1.0, dim, 1.0 / hdx) - 1.0 for hdx in ratios]
        lattice_conv[(name, dim)] = errs
        print(f"{name:9s} {dim}D lattice sum - 1 for h/dx = {ratios}:")
        print("          " + "  ".join(f"{e:+.1e}" for e in errs))
        assert abs(errs[-1]) < 1e-4 and abs(errs[-1]) < max(abs(e) for e in errs[:2])

# compact support: W = 0 and grad W = 0 for r >= 2h (exactly, not just small); W > 0 inside
for name, K in KERNELS.items():
    for dim in (2, 3):
        h = 1.1
        r_out = np.concatenate([[2 * h], np.linspace(2 * h, 5 * h, 1000)])
        assert np.all(K.w(r_out, h, dim) == 0.0) and np.all(K.dw_dr(r_out, h, dim) == 0.0)
        assert np.all(K.dw_dr_over_r(r_out, h, dim) == 0.0)
        x_out = rng.normal(size=(1000, dim))
        x_out *= (rng.uniform(2 * h, 5 * h, size=(1000, 1)) / np.linalg.norm(x_out, axis=1, keepdims=True))
        assert np.all(K.grad(x_out, h, dim) == 0.0)
        r_in = np.linspace(0, 2 * h, 1001)[:-1]
        assert np.all(K.w(r_in, h, dim) > 0) and np.all(K.dw_dr(r_in[1:], h, dim) < 0)
print("compact support: W, dW/dr and grad W are exactly 0 for r >= 2h; W > 0 and dW/dr < 0 for 0 < r < 2h")

# %% [markdown]
# The radial integrals are one to round-off. The lattice sums converge to one quickly as the lattice is refined
# (the summand is smooth and vanishes with two derivatives at the edge of the support), but at the coarse
# spacings of a real simulation, $h/\delta x \approx 1$–$2$, they are off by up to a few per cent. That is the
# particle-approximation error of Section 6.
#
# ## 6. The discrete partition of unity and the neighbour count
#
# In a simulation the integral becomes a sum. For a constant field $f\equiv 1$, Eq. (7) gives
# $\sum_j V_j W_{ij}$ (the sum includes $j=i$), which should be 1. For the gradient of a constant, the
# "raw" form $\sum_j V_j \nabla_i W_{ij}$ should be $\mathbf 0$. Neither holds exactly for particles; how close they
# are depends on the particle arrangement and on $h/\Delta p$, the ratio of smoothing length to particle spacing.
# The paper uses $h/\Delta p = 1.5$ (Taylor bar, metal pressing) and $1.8$ (cutting, $h = 0.018$ mm,
# $\Delta p = 0.01$ mm); the second paper uses $1.3$.
#
# First, a particle deep inside a perfect square (2D) or cubic (3D) lattice with $V_j = \Delta p^d$: we simply sum
# over all lattice offsets within $2h$. We also count its **neighbours**: the other particles with $r < 2h$
# (pairs at exactly $r = 2h$ carry $W = 0$ and are not counted).

# %%
def lattice_offsets(hdp, dim):
    """All lattice offsets (in units of dp) of a square/cubic lattice that can lie within 2h."""
    n = int(np.ceil(2 * hdp)) + 1
    g = np.arange(-n, n + 1)
    return np.stack(np.meshgrid(*([g] * dim), indexing="ij"), axis=-1).reshape(-1, dim).astype(float)


def interior_sums(K, hdp, dim, dp=1.0):
    """Sum_j V_j W_ij, |Sum_j V_j grad_i W_ij| and the neighbour count for a particle inside an infinite lattice."""
    h = hdp * dp
    xj = lattice_offsets(hdp, dim) * dp       # particle i sits at the origin
    xij = -xj
    r = np.linalg.norm(xij, axis=1)
    V = dp**dim
    s_w = V * K.w(r, h, dim).sum()
    s_g = V * K.grad(xij, h, dim).sum(axis=0)
    n_nb = int(np.count_nonzero((r > 0) & (r < 2 * h * (1 - 1e-12))))
    return s_w, np.linalg.norm(s_g) * h, n_nb


HDP = (1.2, 1.3, 1.5, 1.8, 2.0)
pou = {}
print("interior particle of a perfect lattice:")
print(f"{'h/dp':>5} {'kernel':>9} | {'2D: sum VW':>11} {'|h sum V gradW|':>15} {'neigh.':>6} | "
      f"{'3D: sum VW':>11} {'|h sum V gradW|':>15} {'neigh.':>6}")
for hdp in HDP:
    for name, K in KERNELS.items():
        row = [interior_sums(K, hdp, dim) for dim in (2, 3)]
        pou[(name, hdp)] = row
        print(f"{hdp:5.1f} {name:>9} | {row[0][0]:11.5f} {row[0][1]:15.1e} {row[0][2]:6d} | "
              f"{row[1][0]:11.5f} {row[1][1]:15.1e} {row[1][2]:6d}")
        for s_w, s_g, _ in row:
            assert abs(s_w - 1) < 0.02      # within 2 % of one inside the lattice
            assert s_g < 1e-12              # the gradient sum vanishes by symmetry of the lattice
# neighbour numbers are lattice geometry, the same for both kernels; spot values
assert pou[("cubic", 1.5)][0][2] == 24 and pou[("cubic", 1.5)][1][2] == 92
assert pou[("cubic", 1.2)][0][2] == 20 and pou[("cubic", 2.0)][1][2] == 250

# %% [markdown]
# Inside a perfect lattice the gradient sum vanishes to round-off for any $h/\Delta p$ — every neighbour has a mirror
# image — and $\sum_j V_j W_{ij}$ is within a fraction of a per cent of one for the cubic spline. The Wendland kernel
# overshoots more at small $h/\Delta p$ (1.8 % at 1.2) and needs $h/\Delta p \gtrsim 1.5$ to be as good: this is the
# "more neighbours" it asks for. Note also that the error is not monotone in $h/\Delta p$: it depends on how the
# lattice shells fall relative to the kernel's shape.
#
# The neighbour count grows like $(2h/\Delta p)^d$: $\pi (2h/\Delta p)^2$ in 2D and $\frac43\pi (2h/\Delta p)^3$ in
# 3D, minus the particle itself, up to lattice effects. At the paper's $h/\Delta p=1.8$ a 3D particle has 178
# neighbours; this number is the main cost driver of SPH.
#
# ### At a free surface the sums are truncated
#
# Now a finite 2D block of particles. Near its edges the kernel's support sticks out into empty space: there is
# nobody there to sum over. We use the package's own machinery — half pairs from `find_pairs` (each pair once),
# accumulated onto both particles with `scatter_add` — and check it against a plain all-pairs computation.

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
    n_nb = pair_count_per_particle(I[inside], J[inside], n)
    return s_w, s_g, n_nb


def sph_sums_plain(x, V, h, K):
    """The same sums over all (i, j), no neighbour list, no symmetry trick."""
    n, dim = x.shape
    s_w, s_g = np.zeros(n), np.zeros((n, dim))
    for i in range(n):
        xij = x[i] - x
        s_w[i] = V * K.w(np.linalg.norm(xij, axis=1), h, dim).sum()
        s_g[i] = V * K.grad(xij, h, dim).sum(axis=0)
    return s_w, s_g


dp = 1.0e-5                    # 10 micrometres, as in the paper's cutting model
nx, ny = (24, 16) if QUICK else (40, 26)
x_blk = block_2d(nx, ny, dp)
V_blk = dp**2
# distance of each particle from the nearest free surface, in particle spacings
depth = np.minimum.reduce([x_blk[:, 0], x_blk[:, 1], (nx - 1) * dp - x_blk[:, 0], (ny - 1) * dp - x_blk[:, 1]]) / dp
ix, iy = np.round(x_blk[:, 0] / dp).astype(int), np.round(x_blk[:, 1] / dp).astype(int)
corner = (ix == 0) & (iy == 0)
edge_mid = (iy == 0) & (ix == nx // 2)            # middle of the bottom edge
centre = (ix == nx // 2) & (iy == ny // 2)

block = {}
for name, K in KERNELS.items():
    for hdp in (1.2, 1.5, 2.0):
        h = hdp * dp
        s_w, s_g, n_nb = sph_sums(x_blk, V_blk, h, K)
        block[(name, hdp)] = (s_w, s_g, n_nb)
        if hdp == 1.5:
            s_w_ref, s_g_ref = sph_sums_plain(x_blk, V_blk, h, K)
            assert np.allclose(s_w, s_w_ref, rtol=1e-12) and np.allclose(s_g, s_g_ref, rtol=1e-10, atol=1e-10 / h)

print("2D block, sum_j V_j W_ij  /  |h sum_j V_j grad_i W_ij|  /  neighbours")
print(f"{'kernel':>9} {'h/dp':>5} | {'centre':>22} | {'middle of an edge':>22} | {'corner':>22}")
for (name, hdp), (s_w, s_g, n_nb) in block.items():
    h = hdp * dp
    cells = []
    for mask in (centre, edge_mid, corner):
        k = np.flatnonzero(mask)[0]
        cells.append(f"{s_w[k]:.3f} / {np.linalg.norm(s_g[k]) * h:.1e} / {n_nb[k]:3d}")
    print(f"{name:>9} {hdp:5.1f} | " + " | ".join(f"{c:>22}" for c in cells))

    deep = depth >= 2 * hdp              # support entirely inside the block
    s_in, g_in, n_in = interior_sums(KERNELS[name], hdp, 2)
    assert np.allclose(s_w[deep], s_in, rtol=1e-12)             # = the infinite-lattice value
    assert np.all(np.linalg.norm(s_g[deep], axis=1) * h < 1e-9)  # zero (round-off) in the interior
    assert np.all(n_nb[deep] == n_in)
    e, c = s_w[edge_mid][0], s_w[corner][0]
    assert 0.6 < e < 0.85 and 0.4 < c < 0.7 and c < e     # a large part of the support is empty
    assert np.linalg.norm(s_g[edge_mid][0]) * h > 0.1                    # O(1/h) at the surface, not zero
    assert s_g[edge_mid][0][1] > 0      # grad_i W points towards the neighbours, i.e. into the block (+y)
# the deficit grows with h/dp towards the continuum values 1/2 (edge) and 1/4 (corner)
for name in KERNELS:
    e = [block[(name, hdp)][0][edge_mid][0] for hdp in (1.2, 1.5, 2.0)]
    c = [block[(name, hdp)][0][corner][0] for hdp in (1.2, 1.5, 2.0)]
    assert e[0] > e[1] > e[2] > 0.5 and c[0] > c[1] > c[2] > 0.25

# %% [markdown]
# The numbers say it plainly:
#
# * **Partition of unity fails at the surface.** For a point on a straight edge half of the kernel support lies
#   outside the material, at a right-angled corner three quarters: the continuum values are $\frac12$ and $\frac14$.
#   The particle sums are a bit higher — a surface particle's own volume reaches $\Delta p/2$ beyond its centre, and
#   its own row of particles sits where $W$ is largest — so with the cubic spline we find
#   $\sum_j V_j W_{ij} = 0.79, 0.73, 0.67$ at the middle of an edge and $0.61, 0.53, 0.45$ at a corner for
#   $h/\Delta p = 1.2, 1.5, 2.0$, drifting towards $\frac12$ and $\frac14$ as $h/\Delta p$ grows. Anything
#   computed with Eq. (7) there — density by summation, an interpolated stress — is underestimated by
#   the same factor. (The paper's ESPH, and this package, evolve the density with the continuity equation, Eq. (10),
#   starting from the set initial density, so the density itself does not show this deficit; the sums in the
#   force and strain-rate equations still do.)
# * **The gradient of a constant is not zero at the surface.** $\sum_j V_j \nabla_i W_{ij}$ is zero to round-off in
#   the interior but of order $1/h$ at the edge, pointing into the block. Eq. (8) subtracts $f_i$ and so gives
#   zero for a constant field, but the same truncation spoils linear fields: the matrix
#   $\mathbf M_i = \sum_j V_j (\mathbf x_j - \mathbf x_i) \otimes \nabla_i W_{ij}$, which should be the identity
#   (so that the gradient of $f = \mathbf x$ comes out as $\mathbf I$), is far from it at a free surface (next cell).
#   Chapter 03 uses exactly this matrix for the kernel-gradient correction of TLSPH,
#   $\tilde\nabla_i W_{ij} = \mathbf M_i^{-T} \nabla_i W_{ij}$ (Bonet & Lok 1999), which restores first-order
#   consistency near surfaces.
# * **Interior particles** of the block have exactly the infinite-lattice values of the table above (checked).

# %%
def moment_matrix(x, V, h, K):
    """M_i = sum_j V_j (x_j - x_i) (x) grad_i W_ij -- the SPH gradient of the field f(x) = x. Should be I."""
    n, dim = x.shape
    I, J = find_pairs(x, 2 * h)
    xij = x[I] - x[J]
    gij = K.grad(xij, h, dim)
    # pair (I, J): contributes V (x_J - x_I) (x) grad_I W = -V xij (x) gij to I,
    #              and V (x_I - x_J) (x) grad_J W(x_JI) = V xij (x) (-gij) to J
    outer = -V * np.einsum("pa,pb->pab", xij, gij)
    return scatter_add(I, outer, n) + scatter_add(J, outer, n)


M_blk = moment_matrix(x_blk, V_blk, 1.5 * dp, cubic)
for label, mask in (("centre", centre), ("middle of an edge", edge_mid), ("corner", corner)):
    k = np.flatnonzero(mask)[0]
    print(f"cubic, h/dp = 1.5, {label:>18}: M_i = {np.array2string(np.round(M_blk[k], 3) + 0.0, precision=3).replace(chr(10), '')}")
k_c, k_e = np.flatnonzero(centre)[0], np.flatnonzero(edge_mid)[0]
assert np.allclose(M_blk[k_c], np.eye(2), atol=0.01)         # ~ I inside (0.7 % lattice error)
assert abs(M_blk[k_e][1, 1] - 1.0) > 0.3                     # the surface-normal component is far from 1

# %% [markdown]
# ## 7. Why Wendland: the Fourier transform and the pairing instability
#
# A traditional explanation of the pairing instability looks at the kernel gradient: $|\partial W/\partial r|$ of the
# cubic spline peaks at $q = 2/3$ and falls to zero at the centre, so two particles closer than $\frac23 h$ repel
# each other *less* the closer they get, and may pair up. But the Wendland kernel has the same feature (its
# $|f'|$ peaks at $q = 1/2$) and yet does not pair. Dehnen & Aly (2012) traced the instability to the kernel's
# **Fourier transform** $\hat W(k)$: a kernel whose transform is negative for some wavenumbers is prone to
# pairing once it has enough neighbours, one with a non-negative transform is not. (In 1D the $M_4$ spline's
# transform is $\mathrm{sinc}^4 \ge 0$; it is the use of the same profile as a *radial* function in 2D and 3D that
# lets it dip below zero.) For a radial kernel,
#
# $$ \hat W(k) = \int_0^{2h} 2\pi r\, W(r)\, J_0(kr)\,dr \ \ (2D), \qquad
#    \hat W(k) = \int_0^{2h} 4\pi r^2\, W(r)\, \frac{\sin kr}{kr}\,dr \ \ (3D), $$
#
# with $\hat W(0) = 1$ by normalisation. We evaluate these on a grid of $kh$.

# %%
def fourier_radial(K, dim, kh, n_r):
    """Fourier transform of the radial kernel (h = 1) at wavenumbers kh, by Simpson's rule on n_r points."""
    r = np.linspace(0.0, 2.0, n_r)
    W = K.w(r, 1.0, dim)
    if dim == 2:
        integrand = 2 * np.pi * r[None, :] * W[None, :] * special.j0(np.outer(kh, r))
    else:
        integrand = 4 * np.pi * r[None, :] ** 2 * W[None, :] * np.sinc(np.outer(kh, r) / np.pi)
    return integrate.simpson(integrand, x=r, axis=1)


kh = np.linspace(0.0, 20.0, 401 if QUICK else 2001)
n_r = 2001 if QUICK else 8001
FT = {(name, dim): fourier_radial(K, dim, kh, n_r) for name, K in KERNELS.items() for dim in (2, 3)}
for (name, dim), w_hat in FT.items():
    k_min = kh[np.argmin(w_hat)]
    print(f"{name:9s} {dim}D: W_hat(0) = {w_hat[0]:.6f}, min W_hat over 0 <= kh <= 20 = {w_hat.min():+.2e} at kh = {k_min:.2f}")
    assert abs(w_hat[0] - 1.0) < 1e-8
for dim in (2, 3):
    assert FT[("cubic", dim)].min() < -1e-4          # the cubic spline's transform goes negative ...
    assert FT[("wendland", dim)].min() > 0.0          # ... Wendland's stays positive
# where the gradient magnitude peaks
qq = np.linspace(0, 2, 20001)
q_peak = {name: qq[np.argmax(-K.df(qq))] for name, K in KERNELS.items()}
print(f"|f'(q)| peaks at q = {q_peak['cubic']:.4f} (cubic, 2/3) and q = {q_peak['wendland']:.4f} (Wendland, 1/2)")
assert abs(q_peak["cubic"] - 2 / 3) < 1e-3 and abs(q_peak["wendland"] - 0.5) < 1e-3

# %% [markdown]
# The cubic spline's transform dips below zero (by about $6\times10^{-4}$ of its peak, near $kh \approx 7$–$8$);
# Wendland's stays positive. The dip is small, and in practice the cubic spline works well at the modest neighbour
# numbers of the paper; the trouble starts when one increases $h/\Delta p$ to reduce the noise of the particle
# sums — with the cubic spline that is not a free option, with Wendland it is.
#
# ## Figures
#
# Plotting is kept apart from the computations above: these cells only draw what was already computed.

# %%
import matplotlib

if "MPLBACKEND" not in os.environ:
    matplotlib.use("Agg")
import matplotlib.pyplot as plt

q_plot = np.linspace(0.0, 2.5, 501)
fig, axes = plt.subplots(1, 2, figsize=(10, 4))
styles = {"cubic": dict(color="C0", label="cubic B-spline, Eq. (9)"), "wendland": dict(color="C3", label="Wendland C2")}
for name, K in KERNELS.items():
    axes[0].plot(q_plot, K.w(q_plot, 1.0, 2), **styles[name])
    axes[1].plot(q_plot, K.dw_dr(q_plot, 1.0, 2), **styles[name])
    axes[1].plot(q_peak[name], K.dw_dr(q_peak[name], 1.0, 2), "o", color=styles[name]["color"], ms=5)
for ax, yl, title in ((axes[0], r"$h^2\,W$", "kernel (2D normalisation)"),
                      (axes[1], r"$h^3\,\partial W/\partial r$", "radial derivative (dots: steepest point)")):
    ax.axvline(1.0, color="0.8", lw=0.8, ls=":")
    ax.axvline(2.0, color="0.5", lw=0.8, ls="--")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel(r"$q = r/h$")
    ax.set_ylabel(yl)
    ax.set_title(title)
    ax.legend(frameon=False)
axes[0].annotate("support ends at $q=2$", xy=(2.0, 0.25), xytext=(1.35, 0.4), arrowprops=dict(arrowstyle="->", lw=0.7))
fig.suptitle("Smoothing kernels, h = 1")
fig.tight_layout()
fig.savefig(FIGDIR / "01_kernels.png", dpi=130)
plt.show()

# %%
fig, axes = plt.subplots(1, 3, figsize=(15, 4.4), gridspec_kw=dict(width_ratios=[1.25, 1.25, 1]))
s_w, s_g, _ = block[("cubic", 1.5)]
h = 1.5 * dp
xs, ys = x_blk[:, 0] / dp, x_blk[:, 1] / dp
sc = axes[0].scatter(xs, ys, c=s_w, cmap="viridis", vmin=0.4, vmax=1.05, s=14)
fig.colorbar(sc, ax=axes[0], label=r"$\sum_j V_j W_{ij}$")
axes[0].set_title(r"partition of unity, cubic, $h/\Delta p = 1.5$")
g_mag = np.linalg.norm(s_g, axis=1) * h
sc = axes[1].scatter(xs, ys, c=g_mag, cmap="magma_r", s=14)
sel = (depth <= 1) & ((ix + iy) % 2 == 0)        # arrows only where the sum is not zero, every other particle
axes[1].quiver(xs[sel], ys[sel], s_g[sel, 0] * h, s_g[sel, 1] * h, color="C0", scale=6, width=0.005)
fig.colorbar(sc, ax=axes[1], label=r"$h\,|\sum_j V_j \nabla_i W_{ij}|$")
axes[1].set_title(r"gradient of a constant (arrows: direction)")
for ax in axes[:2]:
    ax.set_aspect("equal")
    ax.set_xlabel(r"$x/\Delta p$")
    ax.set_ylabel(r"$y/\Delta p$")
# profile across the bottom free surface, along the middle column
col = ix == nx // 2
order = np.argsort(iy[col])
for hdp, ls in ((1.2, ":"), (1.5, "-"), (2.0, "--")):
    for name, K in KERNELS.items():
        sw = block[(name, hdp)][0][col][order]
        axes[2].plot(iy[col][order][: ny // 2], sw[: ny // 2], ls=ls, color=styles[name]["color"], marker=".",
                     label=f"{name}, $h/\\Delta p$ = {hdp}")
axes[2].axhline(1.0, color="k", lw=0.5)
axes[2].set_xlabel(r"distance from the free surface / $\Delta p$")
axes[2].set_ylabel(r"$\sum_j V_j W_{ij}$")
axes[2].set_title("deficit near the free surface")
axes[2].legend(frameon=False, fontsize=7, ncol=2, loc="lower right")
fig.suptitle("Kernel sums on a 2D block of particles: exact inside, truncated at the free surface")
fig.tight_layout()
fig.savefig(FIGDIR / "01_partition_of_unity.png", dpi=130)
plt.show()

# %%
fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
for ax, dim in zip(axes, (2, 3)):
    for name in KERNELS:
        ax.plot(kh, FT[(name, dim)], color=styles[name]["color"], label=styles[name]["label"])
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_ylim(-1.5e-3, 4e-3)
    ax.set_xlabel(r"$k h$")
    ax.set_ylabel(r"$\hat W(k)$   ($\hat W(0) = 1$, off the scale)")
    ax.set_title(f"{dim}D Fourier transform (zoom on zero)")
    ax.legend(frameon=False)
fig.suptitle("Negative Fourier transform = prone to pairing (Dehnen & Aly 2012)")
fig.tight_layout()
fig.savefig(FIGDIR / "01_kernel_fourier.png", dpi=130)
plt.show()

# %% [markdown]
# ## Where it fails — limits a user should know
#
# * **Truncated support at free surfaces.** The kernel and particle approximations assume the support is full of
#   particles. At an edge $\sum_j V_j W_{ij}\approx 0.7$ and at a corner $\approx 0.5$ ($h/\Delta p = 1.5$), and the raw gradient
#   sum is $O(1/h)$ instead of zero. In machining, the chip's free surface, the machined surface and the tool
#   contact are all such places. Remedies: density by the continuity equation instead of summation, kernel or
#   kernel-gradient corrections (Chapter 03), or ghost/dummy particles at walls.
# * **Discrete sums are not integrals.** Even inside a perfect lattice, $\sum_j V_j W_{ij}$ is off by up to
#   $\approx 0.35\,\%$ (cubic) or $1.8\,\%$ (Wendland, $h/\Delta p = 1.2$), and a disordered particle set does
#   worse; the error does not go to zero as $\Delta p\to 0$ at fixed $h/\Delta p$.
# * **Pairing instability of the cubic spline.** Its Fourier transform is negative for some wavenumbers, so
#   it cannot be used with many more neighbours to reduce that error (Dehnen & Aly 2012). The Wendland $C^2$
#   kernel is free of it, at the price of needing a few more neighbours for the same accuracy.
# * **Neither kernel cures the tensile instability** of Eulerian SPH in solids under tension (Swegle et al. 1995);
#   that is what the artificial pressure of Eq. (14) and the Lagrangian kernel of TLSPH are for (Chapters 02, 03).
# * **Cost.** The neighbour count grows like $(h/\Delta p)^d$: 24 (2D) and 92 (3D) neighbours at
#   $h/\Delta p = 1.5$, 36 and 178 at $1.8$.
# * **A constant $h$.** The package uses one smoothing length for all particles. Strongly compressed or
#   stretched regions then have too many or too few neighbours; adaptive $h$ is not implemented.
