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
# # Chapter 3 — Total Lagrangian SPH (TLSPH)
#
# Islam, Bansal & Peng, Section 2.2 (Eqs. 15–19), Eq. (2), Section 2.3 (Eqs. 20–24) and the reference update at
# the start of Section 3.
#
# **Why another SPH?** Eulerian SPH (chapter 2) evaluates the kernel at the *current* positions: the neighbours
# change all the time, and a solid in tension clumps (the tensile instability). Total Lagrangian SPH evaluates
# every kernel at the *reference* positions $\mathbf X$, where the particles were when the reference configuration
# was last set. Neighbours, kernel gradients and reference volumes $V_j = m_j/\rho_{0j}$ are then fixed until the
# next reference update. The body is described by the map $\mathbf x = \phi(\mathbf X, t)$ and its gradient, the
# deformation gradient $\mathbf F = \partial\mathbf x/\partial\mathbf X$.
#
# The lesson: the equations as plain pair-by-pair loops, and the package checked against them; why the kernel
# gradient needs a correction at a free surface; which stress goes into the momentum equation, and why the stress
# must turn with the body; a vibrating bar; the reference update; where TLSPH fails.

# %%
import math
import matplotlib.pyplot as plt
import numpy as np
from refsph.kernels import get_kernel
from refsph.teaching.plots import colorbar, particle_field
from refsph.scenes import aisi4340_material, get_scene, lattice
from refsph.simulate import SimulationError, run
from refsph.state import make_state
from refsph.tensor import det
from refsph.tlsph import ReferenceOperator, TLSPHParams, green_lagrange_norm, reference_update, tlsph_rates
from refsph.teaching.notebook import chapter
ch = chapter("03_tlsph")

# %%
mat = aisi4340_material()          # AISI 4340, Table 3
kernel = get_kernel("cubic")       # Eq. (9)
print(f"K = {mat.K / 1e9:.1f} GPa, G = {mat.G / 1e9:.1f} GPa, c0 = {mat.c0:.0f} m/s")

# %% [markdown]
# ## 1. The equations
#
# $\nabla_i W_{ij} = \nabla_i W(\mathbf X_i - \mathbf X_j)$ is the kernel gradient in the **reference**
# configuration. Then
#
# $$\mathbf F_i = -\sum_j V_j\,(\mathbf x_i - \mathbf x_j)\otimes\nabla_i W_{ij}\quad(18),\qquad
#   \dot{\mathbf F}_i = -\sum_j V_j\,(\mathbf v_i - \mathbf v_j)\otimes\nabla_i W_{ij}\quad(19),$$
#
# the velocity gradient is $\mathbf l = \dot{\mathbf F}\mathbf F^{-1}$, the density needs no equation,
# $\rho = \rho_0/J$ with $J = \det\mathbf F$ (2), the pressure is $p = K(\rho/\rho_0 - 1)$ (24), the deviatoric
# stress follows the Jaumann rate (20)
# $\dot{\mathbf s} = 2G(\dot{\boldsymbol\epsilon} - \tfrac13\mathrm{tr}\,\dot{\boldsymbol\epsilon}\,\mathbf I) +
# \boldsymbol\omega\mathbf s - \mathbf s\boldsymbol\omega$ with $\dot{\boldsymbol\epsilon}$, $\boldsymbol\omega$
# the symmetric and skew parts of $\mathbf l$, and the momentum equation is
#
# $$\frac{d\mathbf v_i}{dt} = \sum_j m_j\left(\frac{\mathbf P_i}{\rho_{0i}^2} + \frac{\mathbf P_j}{\rho_{0j}^2} -
#   \boldsymbol\Pi_{ij}\right)\nabla_i W_{ij}\quad(17).$$
#
# `refsph` differs from the printed text in three places, each one explained below:
#
# * **Kernel-gradient correction** (Bonet & Lok 1999): every $\nabla_i W_{ij}$ becomes $\mathbf L_i\nabla_i W_{ij}$
#   with $\mathbf L_i = \mathbf M_i^{-T}$, $\mathbf M_i = \sum_j V_j(\mathbf X_j - \mathbf X_i)\otimes\nabla_i W_{ij}$.
#   In Eq. (17) the $j$ term uses $j$'s correction $\mathbf L_j$, so the pair force stays antisymmetric.
# * **Stress measure**: $\mathbf P = J\boldsymbol\sigma\mathbf F^{-T}$, the transpose of the printed
#   $J\mathbf F^{-1}\boldsymbol\sigma$ (§3 below).
# * **Artificial viscosity**: $\boldsymbol\Pi_{ij} = \pi_{ij}(\mathbf B_i + \mathbf B_j)/2$ with
#   $\mathbf B = J\mathbf F^{-T}$ and $\pi_{ij}$ of Eqs. (12)–(13) from current positions and velocities, contracted
#   with the *uncorrected* gradient.

# %% [markdown]
# ### Plain loops
#
# The kernel gradient of Eq. (9), one pair at a time, and the plainest neighbour search:

# %%
def grad_W(Xij, h):
    """grad_i W(X_ij) of the 2D cubic spline, Eq. (9): (dW/dr) X_ij / r."""
    r = math.hypot(Xij[0], Xij[1])
    q = r / h
    if r == 0.0 or q >= 2.0:
        return np.zeros(2)
    alpha = 10.0 / (7.0 * math.pi * h * h)
    dfdq = -3.0 * q + 2.25 * q * q if q <= 1.0 else -0.75 * (2.0 - q) ** 2
    return alpha / h * dfdq * np.asarray(Xij) / r


def neighbours(X, radius):
    """For each i, the list of j != i with |X_i - X_j| < radius (brute force)."""
    pts = [tuple(p) for p in X]
    return [[j for j in range(len(pts)) if j != i and math.dist(pts[i], pts[j]) < radius]
            for i in range(len(pts))]


Xij_test = np.array([[0.3, 0.1], [1.2, -0.7], [-1.5, 0.9]]) * 1e-4
assert np.allclose([grad_W(r, 1e-4) for r in Xij_test], kernel.grad(Xij_test, 1e-4, 2), rtol=1e-13)

# %% [markdown]
# Now all of TLSPH for one state, pair by pair. Every line is one of the equations above.

# %%
def plain_tlsph(state, mat, h, corrected, beta1=1.5, beta2=1.5, eps=0.01):
    """TLSPH rates by plain loops, with P = J sigma F^-T."""
    X, x, v, m, V = state.X, state.x, state.v, state.m, state.V0
    n, d = X.shape
    I2 = np.eye(d)
    nb = neighbours(X, 2.0 * h)                                   # fixed until the next reference update
    gW = {(i, j): grad_W(X[i] - X[j], h) for i in range(n) for j in nb[i]}

    M = np.zeros((n, d, d))                                       # Bonet-Lok: L_i = M_i^-T
    for i in range(n):
        for j in nb[i]:
            M[i] += V[j] * np.outer(X[j] - X[i], gW[i, j])
    L = np.array([np.linalg.inv(M[i]).T if corrected else I2 for i in range(n)])
    g = {(i, j): L[i] @ gW[i, j] for (i, j) in gW}               # corrected gradient

    F, Fdot = np.zeros((n, d, d)), np.zeros((n, d, d))           # Eqs. (18), (19)
    for i in range(n):
        for j in nb[i]:
            F[i] -= V[j] * np.outer(x[i] - x[j], g[i, j])
            Fdot[i] -= V[j] * np.outer(v[i] - v[j], g[i, j])
    J = np.linalg.det(F)
    Finv = np.linalg.inv(F)
    l = Fdot @ Finv                                               # velocity gradient
    rho0 = m / V
    rho = rho0 / J                                                # Eq. (2)
    p = mat.K * (rho / mat.rho0 - 1.0)                            # Eq. (24)
    sigma = state.S - p[:, None, None] * I2
    P = np.array([J[i] * sigma[i] @ Finv[i].T for i in range(n)])    # P = J sigma F^-T
    B = np.array([J[i] * Finv[i].T for i in range(n)])            # for the artificial viscosity

    a = np.zeros((n, d))                                          # Eq. (17)
    for i in range(n):
        for j in nb[i]:
            a[i] += m[j] * (P[i] / rho0[i] ** 2 @ g[i, j] - P[j] / rho0[j] ** 2 @ g[j, i])
            xij, vij = x[i] - x[j], v[i] - v[j]
            vr = vij @ xij
            if vr < 0.0:                                          # Eqs. (12)-(13), approaching pairs only
                mu = h * vr / (xij @ xij + eps * h * h)
                pi = (-beta1 * mat.c0 * mu + beta2 * mu * mu) / (0.5 * (rho[i] + rho[j]))
                a[i] -= m[j] * pi * 0.5 * (B[i] + B[j]) @ gW[i, j]

    dS, dS_zz = np.zeros((n, d, d)), np.zeros(n)                  # Eqs. (20)-(22), plane strain
    for i in range(n):
        eps_dot, omega = 0.5 * (l[i] + l[i].T), 0.5 * (l[i] - l[i].T)
        tr = np.trace(eps_dot)
        dS[i] = 2 * mat.G * (eps_dot - tr / 3 * I2) + omega @ state.S[i] - state.S[i] @ omega
        dS_zz[i] = -2 * mat.G * tr / 3
    return dict(F=F, Fdot=Fdot, l=l, J=J, rho=rho, P=P, a=a, dS=dS, dS_zz=dS_zz)

# %% [markdown]
# A test block: 20 × 15 particles on a slightly irregular lattice (so the correction differs from particle to
# particle), deformed by an affine map plus noise, moving (so the viscosity acts), with a random deviatoric stress.

# %%
def random_block(nx=20, ny=15, dp=1e-4, seed=0):
    rng = np.random.default_rng(seed)
    X = lattice([nx * dp, ny * dp], dp) + 0.1 * dp * rng.uniform(-1, 1, (nx * ny, 2))
    st = make_state(X, 0.0, mat.rho0, dp * dp * (1 + 0.05 * rng.uniform(-1, 1, nx * ny)))
    st.x = X @ np.array([[1.04, 0.12], [-0.05, 0.97]]).T + 0.02 * dp * rng.normal(size=X.shape)
    st.v = rng.normal(scale=5.0, size=X.shape) + (X - X.mean(0)) @ np.array([[0, -2e3], [3e3, 1e3]]).T
    s = rng.normal(scale=100e6, size=(len(X), 3))
    st.S = np.stack([np.stack([s[:, 0], s[:, 2]], -1), np.stack([s[:, 2], s[:, 1]], -1)], 1)
    st.S_zz = -(s[:, 0] + s[:, 1])
    return st, dp


blk, dp_blk = random_block()
for corrected in (False, True):
    prm = TLSPHParams(h=1.5 * dp_blk, beta1=1.5, beta2=1.5, eps=0.01, kernel=kernel, corrected=corrected,
                      ref_update_strain=0.5)
    op = ReferenceOperator(blk.X, blk.V0, prm.h, kernel, corrected)
    out = {}
    rates = tlsph_rates(blk, mat, prm, op, out=out)
    ref = plain_tlsph(blk, mat, prm.h, corrected)
    Fdot_pkg = op.gradient(blk.v)
    big = lambda k: 1e-11 * np.abs(ref[k]).max()                  # noqa: E731
    assert np.allclose(op.deformation_gradient(blk.x), ref["F"], rtol=1e-12, atol=1e-12)
    assert np.allclose(out["F"], ref["F"], rtol=1e-12, atol=1e-12)
    assert np.allclose(out["J"], ref["J"], rtol=1e-12) and np.allclose(out["rho"], ref["rho"], rtol=1e-12)
    for key, pkg, rtol in (("Fdot", Fdot_pkg, 1e-12), ("l", out["l"], 1e-10), ("P", out["P"], 1e-10),
                           ("a", rates.v, 1e-10), ("dS", rates.S, 1e-10), ("dS_zz", rates.S_zz, 1e-10)):
        assert np.allclose(pkg, ref[key], rtol=rtol, atol=big(key)), key
    # energy consistency: power of the stress forces = - stress power, sum m v.a = - sum V P:Fdot
    a_stress = tlsph_rates(blk, mat, TLSPHParams(prm.h, 0.0, 0.0, 0.01, kernel, corrected, None), op).v
    power = np.sum(blk.m[:, None] * blk.v * a_stress)
    stress_power = np.sum(blk.V0[:, None, None] * out["P"] * Fdot_pkg)
    assert abs(power + stress_power) < 1e-12 * np.sum(np.abs(blk.V0[:, None, None] * out["P"] * Fdot_pkg))
    ma = blk.m[:, None] * rates.v
    print(f"corrected={corrected!s:5}: plain loops == package ({blk.n} particles, {op.n_pairs} pairs); "
          f"|sum m a| / sum |m a| = {np.linalg.norm(ma.sum(0)) / np.linalg.norm(ma, axis=1).sum():.0e}")

# %% [markdown]
# The package does the same sums as sparse matrix products built once per reference configuration:
# $\mathbf F$ = `op.deformation_gradient(x)`, $\dot{\mathbf F}$ = `op.gradient(v)`. Two properties hold to
# round-off, with or without the correction:
#
# * **momentum** is conserved, $\sum_i m_i\mathbf a_i = 0$: every pair term of Eq. (17) is antisymmetric;
# * **energy consistency**: the power of the stress forces is minus the stress power,
#   $\sum_i m_i\mathbf v_i\cdot\mathbf a_i = -\sum_i V_i\,\mathbf P_i:\dot{\mathbf F}_i$. The discrete divergence
#   of Eq. (17) is the exact transpose of the discrete gradient of Eq. (19) — which is why $j$'s term must carry
#   $j$'s correction $\mathbf L_j$.
#
# ## 2. The kernel-gradient correction
#
# $\mathbf M_i$ is exactly what the uncorrected Eq. (18) returns for a body at rest, $\mathbf x = \mathbf X$.
# Since $\mathbf a\otimes\mathbf L\mathbf g = (\mathbf a\otimes\mathbf g)\mathbf L^T$, the corrected gradient is
# $\mathbf F_i = \mathbf F^{\rm raw}_i\mathbf M_i^{-1}$: the correction divides out the error that a truncated
# kernel support makes. At a free surface half of the support is missing. A block at rest:

# %%
dp_fs, nx_fs, ny_fs = 1e-4, 30, 20
X_fs = lattice([nx_fs * dp_fs, ny_fs * dp_fs], dp_fs)
V_fs, h_fs = np.full(len(X_fs), dp_fs**2), 1.5 * dp_fs
op_raw = ReferenceOperator(X_fs, V_fs, h_fs, kernel, corrected=False)
op_cor = ReferenceOperator(X_fs, V_fs, h_fs, kernel, corrected=True)
I_n = np.eye(2)


def fnorm(A):
    return np.sqrt(np.einsum("nab,nab->n", A, A))


dist_fs = np.minimum.reduce([X_fs[:, 0], nx_fs * dp_fs - X_fs[:, 0], X_fs[:, 1], ny_fs * dp_fs - X_fs[:, 1]]) / dp_fs
interior, surface = dist_fs > 2 * h_fs / dp_fs + 0.5, dist_fs < 1.0     # complete kernel support / outer row
err_raw = fnorm(op_raw.deformation_gradient(X_fs) - I_n)
err_cor = fnorm(op_cor.deformation_gradient(X_fs) - I_n)
J_raw = det(op_raw.deformation_gradient(X_fs))
print(f"at rest, max |F - I|: printed Eq. (18) surface {err_raw[surface].max():.2f}, interior "
      f"{err_raw[interior].max():.0e};  corrected {err_cor.max():.0e}")
print(f"printed Eq. (18): J at the corner {J_raw.min():.2f} -> pressure K(1/J - 1) = "
      f"{mat.K * (1 / J_raw.min() - 1) / 1e9:.0f} GPa in a body at rest")
assert err_cor.max() < 1e-12 and err_raw[surface].max() > 0.1

# patch test: an affine map x = A X + b must give F = A exactly
A = np.array([[1.10, 0.30], [-0.20, 0.90]])
x_aff = X_fs @ A.T + np.array([1e-3, -2e-3])
e_cor = fnorm(op_cor.deformation_gradient(x_aff) - A)
e_raw = fnorm(op_raw.deformation_gradient(x_aff) - A)
print(f"patch test x = A X + b, max |F - A|: corrected {e_cor.max():.0e}, printed {e_raw.max():.2f}")
assert e_cor.max() < 1e-12 and e_raw[surface].max() > 0.1

# %%
fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), constrained_layout=True)
for ax, err, title in ((axes[0], err_raw, "Eq. (18) as printed"), (axes[1], err_cor, "with the correction")):
    sc = particle_field(ax, X_fs, np.log10(np.maximum(err, 1e-17)), dp_fs, vmin=-17, vmax=0)
    ax.set(xlabel="X [mm]", ylabel="Y [mm]", title=f"{title}: body at rest")
colorbar(fig, sc, axes, "log10 of |F - I| [-]")
ch.show(fig, "03_tlsph_F_free_surface.png", caption="Error (log10) of F for a body at rest: Eq. (18) as printed "
                                                    "(left) fails at the free surface; the corrected F (right) is "
                                                    "exact.")

# %% [markdown]
# Without the correction the interior is nearly right (on a square lattice $\mathbf M = c\,\mathbf I$ with $c$
# close to one), but at the surface $\mathbf F$ is far from $\mathbf I$ and $J$ falls so low at a corner that the
# equation of state turns a body at rest into one under terapascals of pressure (Exercise 1 lets such a body move).
# With the correction every affine motion, rest included, gives the exact $\mathbf F$ — the patch test, without
# which an SPH gradient cannot converge at a boundary.
#
# ## 3. Which stress goes into Eq. (17)?
#
# Eq. (4) reads $\rho_0\dot v_a = \partial P_{aK}/\partial X_K$, and Eq. (17) contracts the *second* index of
# $\mathbf P$ with $\nabla W$. For that contraction the first Piola–Kirchhoff stress is
# $\mathbf P = J\boldsymbol\sigma\mathbf F^{-T}$ (Bonet & Wood, *Nonlinear Continuum Mechanics*, Sec. 5.5). The
# paper prints $J\mathbf F^{-1}\boldsymbol\sigma$, the **nominal stress** $\mathbf N = \mathbf P^T$. Under a
# rotation, $\mathbf F = \mathbf R\mathbf F_0$ and $\boldsymbol\sigma = \mathbf R\boldsymbol\sigma_0\mathbf R^T$:
#
# $$\mathbf P = \mathbf R\mathbf P_0 \quad\text{(the force turns with the body)},\qquad
#   \mathbf N = \mathbf N_0\mathbf R^T \quad\text{(the old stress applied along a wrongly turned gradient)}.$$
#
# The test: a pre-stressed, slightly compressed body, rotated rigidly, must feel the rotated force,
# $\mathbf a^{\rm rot}_i = \mathbf R\,\mathbf a^0_i$. Two pre-stresses (uniform, and varying along $X$), two angles.

# %%
Lx_fs = nx_fs * dp_fs
prm_rot = TLSPHParams(h=h_fs, beta1=0.0, beta2=0.0, eps=0.01, kernel=kernel, corrected=True, ref_update_strain=None)


def Rot(th):
    return np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])


def prestressed(kind):
    """Positions and deviatoric stress of the unrotated body."""
    s_xx, s_xy = np.full(len(X_fs), 200e6), np.full(len(X_fs), 120e6)
    x0 = 0.999 * X_fs
    if kind == "non-uniform":
        s_xx, s_xy = s_xx * (1 + 2 * X_fs[:, 0] / Lx_fs), s_xy * (1 - 3 * X_fs[:, 0] / Lx_fs)
        x0 = X_fs.copy()
        x0[:, 0] -= 0.002 * X_fs[:, 0] ** 2 / Lx_fs               # J varies along X
    return x0, np.stack([np.stack([s_xx, s_xy], -1), np.stack([s_xy, -s_xx], -1)], 1)


def tl_force(x, S, measure):
    """Corrected TLSPH stress force (Eq. 17, no viscosity) with P = J sigma F^-T, or the printed N = J F^-1 sigma."""
    st = make_state(X_fs, 0.0, mat.rho0, V_fs)
    st.x, st.S = x, S
    out = {}
    a = tlsph_rates(st, mat, prm_rot, op_cor, out=out).v
    if measure == "P":
        return a
    N = out["J"][:, None, None] * np.linalg.inv(out["F"]) @ (S - out["p"][:, None, None] * np.eye(2))
    return op_cor.momentum_sum(N / mat.rho0**2, st.m)


for deg in (90, 30):
    R = Rot(np.radians(deg))
    for kind in ("uniform", "non-uniform"):
        x0, S0 = prestressed(kind)
        target = tl_force(x0, S0, "P") @ R.T                       # R a0, particle by particle
        scale = np.linalg.norm(target, axis=1).max()
        errs = {m: np.linalg.norm(tl_force(x0 @ R.T, R @ S0 @ R.T, m) - target, axis=1).max() / scale
                for m in ("P", "N")}
        print(f"{deg:2d} deg, {kind:11}: max |a - R a0| / max |a0|:  J sigma F^-T {errs['P']:.0e},  "
              f"printed J F^-1 sigma {errs['N']:.2f}")
        assert errs["P"] < 1e-11 and errs["N"] > 0.1

# %% [markdown]
# With $\mathbf P = J\boldsymbol\sigma\mathbf F^{-T}$ the rotated body feels exactly the rotated force; with the
# printed form the force is wrong by order one. For a pure compression $\mathbf F = \lambda\mathbf I$ the two forms
# are equal, so a test without rotation cannot tell them apart.
#
# ## 4. The stress must turn with the body
#
# A block with a deviatoric pre-stress $\mathbf s_0$ is turned rigidly by a quarter turn. We prescribe the motion and
# integrate only the stress with the package's rates (TLSPH $\mathbf l$ and the Jaumann rate, Eq. 20) and a
# predictor–corrector step written as in `refsph.integrate`. Exact answer: $\mathbf s(t) = \mathbf R\mathbf s_0\mathbf
# R^T$. Two wrong laws for comparison: the spin terms in the printed order $\mathbf s\boldsymbol\omega -
# \boldsymbol\omega\mathbf s$ (right only for the transposed convention $l_{ab} = \partial v_b/\partial x_a$; `refsph`
# uses $l_{ab} = \partial v_a/\partial x_b$), and no spin terms at all.

# %%
dp_r = 1e-4
X_r = lattice([16 * dp_r, 8 * dp_r], dp_r)
xc_r = X_r.mean(0)
prm_r = TLSPHParams(h=1.5 * dp_r, beta1=1.5, beta2=1.5, eps=0.01, kernel=kernel, corrected=True,
                    ref_update_strain=None)
op_r = ReferenceOperator(X_r, np.full(len(X_r), dp_r**2), prm_r.h, kernel, True)
S0_r = np.array([[250e6, 150e6], [150e6, -100e6]])
omega_r = 2e3                                               # rad/s
n_steps_r = 100 if ch.quick else 400
dt_r = 0.5 * np.pi / omega_r / n_steps_r


def stress_rate(st, law):
    R = Rot(omega_r * st.t)
    st.x = xc_r + (X_r - xc_r) @ R.T
    st.v = omega_r * np.stack([-(st.x[:, 1] - xc_r[1]), st.x[:, 0] - xc_r[0]], 1)
    out = {}
    r = tlsph_rates(st, mat, prm_r, op_r, out=out)
    if law == "Jaumann (refsph)":
        return r.S
    l = out["l"]
    eps_dot, om = 0.5 * (l + np.swapaxes(l, 1, 2)), 0.5 * (l - np.swapaxes(l, 1, 2))
    dS = 2 * mat.G * (eps_dot - np.trace(eps_dot, axis1=1, axis2=2)[:, None, None] / 3 * np.eye(2))
    return dS + st.S @ om - om @ st.S if law == "printed order" else dS


turned = {}
for law in ("Jaumann (refsph)", "printed order", "no spin"):
    st = make_state(X_r, 0.0, mat.rho0, dp_r**2)
    st.S[:] = S0_r
    angle, err = [], 0.0
    for k in range(n_steps_r + 1):
        Sm = st.S.mean(0)                                       # major principal direction of the mean stress
        angle.append(0.5 * np.arctan2(2 * Sm[0, 1], Sm[0, 0] - Sm[1, 1]))
        R = Rot(omega_r * st.t)
        err = max(err, np.abs(st.S - R @ S0_r @ R.T).max() / np.abs(S0_r).max())
        if k < n_steps_r:                                       # predictor-corrector
            half = st.copy()
            half.S, half.t = st.S + 0.5 * dt_r * stress_rate(st, law), st.t + 0.5 * dt_r
            st.S, st.t = st.S + dt_r * stress_rate(half, law), st.t + dt_r
    turned[law] = np.degrees(np.unwrap(2 * (np.array(angle) - angle[0])) / 2)
    print(f"{law:17}: max |s - R s0 R^T| / |s0| over the quarter turn = {err:.1e}")
    assert (err < 2e-3) if law.startswith("Jaumann") else (err > 0.5)

# %%
fig, ax = plt.subplots(figsize=(6.5, 4.2), constrained_layout=True)
body = np.linspace(0.0, 90.0, n_steps_r + 1)
ax.plot([0, 90], [0, 90], color="0.6", lw=8, alpha=0.4, label="exact: turns with the body")
for (law, a), ls in zip(turned.items(), ("-", "--", ":")):
    ax.plot(body, a, "k" + ls, lw=2, label=law)
ax.set(xlabel="rotation of the body [deg]", ylabel="rotation of the stress axes [deg]",
       title="A pre-stressed block, rigid quarter turn")
ax.legend()
ax.grid(alpha=0.3)
ch.show(fig, "03_tlsph_rotation.png", caption="A pre-stressed block turned by a quarter turn: its stress axes turn "
                                              "with the body under the Jaumann rate only.")

# %% [markdown]
# With TLSPH, $\mathbf F = \mathbf R$ exactly, so $\mathbf l = \dot{\mathbf R}\mathbf R^T$ is a pure spin and the
# Jaumann rate only rotates $\mathbf s$; what remains is the time-integration error of the rotation. The wrong
# laws also keep the invariants (they, too, only rotate $\mathbf s$), so constant invariants prove nothing: the
# *orientation* tells. With the printed order the stress turns the wrong way; without spin terms it stays fixed
# in space while the body turns.
#
# ## 5. The vibrating bar
#
# Scene `bar`: a free–free AISI 4340 bar, 20 × 2 mm, started in its first axial mode $v_x = v_0\cos(\pi X/L)$.
# Its period is $T = 2L/c$ with the plane-strain bar speed $c = \sqrt{E/((1-\nu^2)\rho_0)}$.

# %%
bar = run("bar", "tlsph", dim=2, quick=ch.quick, progress=False)
mb = bar.summary["metrics"]
print(f"{bar.summary['n_particles']} particles, {bar.summary['n_steps']} steps: wave speed {mb['wave_speed_m_s']:.0f} "
      f"m/s vs theory {mb['wave_speed_theory_m_s']:.0f} m/s; energy after two periods / initial "
      f"{mb['energy_final_over_initial']:.2f}")
assert abs(mb["wave_speed_rel_error"]) < 0.01

eh, T_bar = mb["energy_history"], bar.setup.info["period_theory"]
E_tot = eh[:, 1] + eh[:, 2]
assert E_tot.max() < E_tot[0] * (1 + 1e-6)          # the viscosity only takes energy out
fig, ax = plt.subplots(figsize=(6.5, 4.2), constrained_layout=True)
for E, lab in ((eh[:, 1], "kinetic"), (eh[:, 2], "elastic"), (E_tot, "total")):
    ax.plot(eh[:, 0] / T_bar, E / E_tot[0], lw=2.5 if lab == "total" else 1.5, label=lab)
ax.set(xlabel="t / T", ylabel="energy / initial energy", title="TLSPH bar, first axial mode")
ax.legend(loc="center left")
ax.grid(alpha=0.3)
ch.show(fig, "03_tlsph_bar.png", caption="Energies of the TLSPH bar in its first axial mode: kinetic and elastic "
                                         "trade places twice a period; the total decays slowly.")

# %% [markdown]
# Kinetic and elastic energy trade places twice per period, and the wave speed is within a percent of theory.
# The total energy decays: the artificial viscosity (Eqs. 12–13) damps approaching pairs. Without it the scheme is
# energy-consistent in space (Section 1) but not in time — the explicit predictor–corrector slowly amplifies the
# highest-frequency particle modes (Exercise 3).
#
# ## 6. Reference-configuration update
#
# After large deformation the reference configuration is reset to the current one (paper, Section 3):
#
# $$\mathbf X \leftarrow \mathbf x,\qquad V \leftarrow J\,V,\qquad \boldsymbol\sigma\ \text{kept}.$$
#
# Neighbours, kernel gradients and correction matrices are rebuilt, and $\mathbf F = \mathbf I$ right after. The
# trigger (`TLSPHSolver.after_step`): update when $\max_i\lVert\mathbf E_i\rVert_F$ exceeds `ref_update_strain`
# (default 0.5), with $\mathbf E = (\mathbf F^T\mathbf F - \mathbf I)/2$ the Green–Lagrange strain, which is zero
# for a rigid motion. We shear a moving, pre-stressed block by $\gamma$, update, and compare.

# %%
nx_u, ny_u, dp_u = 24, 16, 1e-4
X_u = lattice([nx_u * dp_u, ny_u * dp_u], dp_u)
kx, ky = np.pi / (nx_u * dp_u), np.pi / (ny_u * dp_u)
prm_u = TLSPHParams(h=1.5 * dp_u, beta1=0.0, beta2=0.0, eps=0.01, kernel=kernel, corrected=True,
                    ref_update_strain=0.5)
op_u = ReferenceOperator(X_u, np.full(len(X_u), dp_u**2), prm_u.h, kernel, True)
inner_u = np.minimum.reduce([X_u[:, 0], nx_u * dp_u - X_u[:, 0], X_u[:, 1], ny_u * dp_u - X_u[:, 1]]) > 3.5 * dp_u


def sheared_state(gamma):
    """Simple shear gamma plus a smooth non-affine part, a smooth velocity and a non-uniform stress."""
    st = make_state(X_u, 0.0, mat.rho0, dp_u**2)
    sx, sy = np.sin(kx * X_u[:, 0]), np.sin(ky * X_u[:, 1])
    st.x = X_u + np.stack([gamma * X_u[:, 1] + 0.1 * dp_u * sx * sy, 0.005 * X_u[:, 1] * sx], 1)
    st.v = np.stack([20.0 * sy, -10.0 * sx], 1)
    s = 100e6 * np.cos(kx * X_u[:, 0])
    st.S, st.S_zz = np.stack([np.stack([s, 0.5 * s * sy], -1), np.stack([0.5 * s * sy, -0.3 * s], -1)], 1), -0.7 * s
    return st


for gamma in (0.1, 0.3, 0.6, 1.0):
    st = sheared_state(gamma)
    before, after = {}, {}
    tlsph_rates(st, mat, prm_u, op_u, out=before)
    st_new = reference_update(st, before["F"])
    tlsph_rates(st_new, mat, prm_u, ReferenceOperator(st_new.X, st_new.V0, prm_u.h, kernel, True), out=after)
    vol = np.sum(before["J"] * st.V0) / np.sum(st_new.V0)
    F_reset = fnorm(after["F"] - I_n).max()
    rho_jump = np.abs(after["rho"] / before["rho"] - 1).max()
    l_jump = fnorm(after["l"] - before["l"])[inner_u].max() / fnorm(before["l"])[inner_u].max()
    print(f"gamma {gamma:.1f} (max |E| {green_lagrange_norm(before['F']).max():.2f}): after the update max "
          f"|F - I| {F_reset:.0e}, volume ratio - 1 {vol - 1:.0e}, max density jump {rho_jump:.0e}, "
          f"interior jump of l {100 * l_jump:.1f} %")
    assert abs(vol - 1) < 1e-13 and F_reset < 1e-12 and rho_jump < 1e-12

# %% [markdown]
# $\mathbf F$ resets to $\mathbf I$, the current volume $\sum_i J_iV_i$ is carried over exactly, so density and
# pressure do not jump; the velocity gradient, which drives the stress, is continuous up to the discretisation
# error. That error is not zero: before the update the kernels are circles in $\mathbf X$ (sheared ellipses in
# $\mathbf x$), after it circles in $\mathbf x$, with different neighbours. The jump grows with the shear
# accumulated since the last update — a reason not to wait too long; each update also costs a rebuild of the
# operator — a reason not to update too often (Exercise 2).
#
# ## 7. No tensile instability
#
# Chapter 2 showed Eulerian SPH clumping in tension. In TLSPH the pairs and kernel gradients belong to the
# reference configuration: moving two particles closer does not move them along the kernel, so there is no such
# feedback. Scene `tension`: a jittered 10 × 10 mm block in free expansion, in strong tension, with the paper's
# machining viscosity.

# %%
ten = run("tension", "tlsph", dim=2, quick=ch.quick, progress=False)
dmin = ten.summary["metrics"]["min_pair_distance_over_dp"]
print(f"TLSPH, scene 'tension', {ten.summary['n_particles']} particles: min pair distance / dp = {dmin:.3f}")
assert dmin > 0.8          # ESPH without artificial pressure falls below 0.8 (chapter 2)

# %% [markdown]
# ## 8. Where TLSPH fails
#
# **(a) Large distortion without reference updates.** The neighbours are those of $\mathbf X$ for ever. Under a
# large shear, old neighbours stay coupled however far apart they move, and particles that come close never
# interact. Material separation (a chip leaving the workpiece) is impossible between updates. A loose trigger costs
# too: in chapter 11's cut, updating at $\lVert\mathbf E\rVert_F > 0.5$ lets the plastic update register only 71 % of
# the chip particles' own deformation, 91 % at 0.1 (`benchmarks/registered_strain_report.md`).

# %%
from refsph.neighbours import find_pairs

gamma_big = 3.0
x_big = X_u + np.stack([gamma_big * X_u[:, 1], 0 * X_u[:, 1]], 1)
I_cur, J_cur = find_pairs(x_big, 2 * prm_u.h)
ref_pairs = set(zip(op_u.I.tolist(), op_u.J.tolist()))
missing = sum((i, j) not in ref_pairs for i, j in zip(I_cur.tolist(), J_cur.tolist()))
stretch = np.linalg.norm(x_big[op_u.I] - x_big[op_u.J], axis=1).max() / (2 * prm_u.h)
print(f"shear gamma = {gamma_big}: reference neighbours now up to {stretch:.1f} support radii apart; "
      f"{missing} of {len(I_cur)} pairs within 2h do not interact")

# %% [markdown]
# **(b) Zero-energy (hourglass) modes.** $\mathbf F$ at $i$ is built from differences $\mathbf x_j - \mathbf x_i$
# weighted by an odd function of $\mathbf X_{ij}$. A displacement that is *even* about every particle of a regular
# lattice — every second row up, or a checkerboard — therefore has zero gradient in the interior: $\mathbf F =
# \mathbf I$, no stress, no restoring force. Such modes can grow unopposed. The paper relies on the artificial
# viscosity; `refsph` also has Ganzenmüller's (CMAME 286 (2015) 87) penalty force, `--set hourglass=1`
# (`tlsph.hourglass_acceleration`, off by default), which pushes back on the part of $\mathbf x_j - \mathbf x_i$
# that $\mathbf F$ does not explain.

# %%
from refsph.tlsph import hourglass_acceleration

ij_fs = np.round(X_fs / dp_fs - 0.5).astype(int)
zero = np.zeros(len(X_fs))
modes = {"every second row up/down": np.stack([zero, 0.2 * dp_fs * (-1.0) ** ij_fs[:, 1]], 1),
         "checkerboard along x": np.stack([0.2 * dp_fs * (-1.0) ** ij_fs.sum(1), zero], 1)}
fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), constrained_layout=True)
for ax, (name, u) in zip(axes, modes.items()):
    e = fnorm(op_cor.deformation_gradient(X_fs + u) - I_n)
    print(f"{name}: every particle moved by 0.2 dp; max |F - I| interior {e[interior].max():.0e}, "
          f"surface {e[surface].max():.2f}")
    assert e[interior].max() < 1e-12
    a_hg = hourglass_acceleration(X_fs + u, op_cor.deformation_gradient(X_fs + u), np.full(len(X_fs), 1.0),
                                  op_cor, 1.0, 1.0)
    print(f"   hourglass force against it: {-np.sum(a_hg * u) / np.sum(u * u):.2e} (> 0: restoring)")
    assert np.sum(a_hg * u) < 0
    sc = particle_field(ax, X_fs + u, np.log10(np.maximum(e, 1e-17)), dp_fs, vmin=-17, vmax=0, spread=0.8)
    ax.set(xlabel="x [mm]", ylabel="y [mm]", title=name)
colorbar(fig, sc, axes, "log10 of |F - I| [-]")
ch.show(fig, "03_tlsph_hourglass.png", caption="Two zero-energy modes (rows up and down, a checkerboard): |F − I| "
                                               "(log10) stays at round-off inside; F cannot see them.")

# %% [markdown]
# **(c) A singular correction matrix.** $\mathbf M_i$ must be invertible: particle $i$ needs neighbours in all
# directions. A row of particles one layer thick (a thin filament, a torn-off particle) has no neighbours across:

# %%
X_line = np.stack([np.arange(6) * dp_fs, np.zeros(6)], 1)
with np.errstate(divide="ignore", invalid="ignore"):
    op_line = ReferenceOperator(X_line, np.full(6, dp_fs**2), h_fs, kernel, True)
print("det M_i of a row of 6 particles:", det(op_line.M))
print("det F of the row at rest:", det(op_line.deformation_gradient(X_line)))

# %% [markdown]
# `refsph` uses the pseudo-inverse for such particles (`op.degenerate` lists them) and completes $\mathbf F$ with
# the identity in the missing direction ($J = 1$ at rest): it cannot see a stretch across the row.
#
# ## Your turn
#
# Predict first, run, then open *What you should see*. The last exercise asks for code, graded against the package.
# ### Exercise 1 — Switch the correction off
#
# Predict: a bar at rest and then set vibrating, with Eq. (18) exactly as printed (`corrected=False`). Will it
# vibrate a little less accurately, or not at all?

# %% tags=["exercise"]
CORRECTED = True          # <- change this to False and run the cell again
b0 = get_scene("bar").setup(2, None, True)                     # the bar at rest (quick resolution)
J_b = det(ReferenceOperator(b0.state.X, b0.state.V0, b0.h, kernel, CORRECTED).deformation_gradient(b0.state.X))
print(f"at rest: min J = {J_b.min():.3f}, max pressure K(1/J - 1) = {mat.K * (1 / J_b.min() - 1) / 1e9:.3g} GPa")
try:
    with np.errstate(all="ignore"):
        r = run("bar", "tlsph", dim=2, quick=True, progress=False, numerics=dict(corrected=CORRECTED))
    print(f"ran {r.summary['n_steps']} steps; wave speed error {100 * r.summary['metrics']['wave_speed_rel_error']:+.2f} %")
except SimulationError as e:
    print("the run stopped:", e)

# %% [markdown]
# <details><summary>What you should see</summary>
#
# Corrected: $J = 1$ at rest, and the bar vibrates for two periods. Uncorrected: $J \approx 0.1$ at the corners, a
# terapascal of pressure at rest, and the run stops within a few steps. The correction is needed, not a refinement.
# </details>

# %% [markdown]
# ### Exercise 2 — How often to update the reference configuration?
#
# Predict: a block is sheared to $\gamma = 2$ in steps of 0.04. How many updates does a threshold of 0.5 give, and
# 0.1? How many pairs close at the end do *not* interact, with each and without updates (`None`)?

# %% tags=["exercise"]
REF_UPDATE_STRAIN = 0.5   # <- change this (e.g. to 0.1, or None for never) and run the cell again
st = make_state(X_u, 0.0, mat.rho0, dp_u**2)
op = ReferenceOperator(st.X, st.V0, prm_u.h, kernel, True)
updated_at = [0.0]
for gamma in np.linspace(0.0, 2.0, 51)[1:]:                     # prescribed simple shear, step by step
    st.x = X_u + np.stack([gamma * X_u[:, 1], 0 * X_u[:, 1]], 1)
    F = op.deformation_gradient(st.x)
    if REF_UPDATE_STRAIN is not None and green_lagrange_norm(F).max() > REF_UPDATE_STRAIN:
        st = reference_update(st, F)                              # X <- x, V <- J V
        op = ReferenceOperator(st.X, st.V0, prm_u.h, kernel, True)
        updated_at.append(gamma)
I_now, J_now = find_pairs(st.x, 2 * prm_u.h)                   # close now, but not coupled by the operator:
missing = len(set(zip(I_now.tolist(), J_now.tolist())) - set(zip(op.I.tolist(), op.J.tolist())))
print(f"threshold {REF_UPDATE_STRAIN}: {len(updated_at) - 1} updates, the last at gamma = {updated_at[-1]:.2f}; "
      f"at gamma = 2, {missing} of {len(I_now)} close pairs do not interact")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# $\lVert\mathbf E\rVert_F = \tfrac12\sqrt{2\gamma^2 + \gamma^4}$ for a shear $\gamma$ since the last update: 0.5 is
# passed every 0.68 (two updates), 0.1 every 0.16 (twelve rebuilds). At $\gamma = 2$, 738 of 4183 close pairs do
# not interact with 0.5 (sheared by 0.64 since its last update), 197 with 0.1 (by 0.08), 1929 without updates. An
# update sets $\mathbf X \leftarrow \mathbf x$, and $\mathbf x$ is prescribed: only the shear since the *last*
# update counts. In steps of 0.05 both thresholds update last at $\gamma = 1.95$ and give the same count.
# </details>

# %% [markdown]
# ### Exercise 3 — Take the artificial viscosity away
#
# Predict: the bar without artificial viscosity ($\beta_1 = \beta_2 = 0$). Does its total energy stay constant?
# Does halving the time step (Courant number 0.15 instead of 0.3) change the answer?

# %% tags=["exercise"]
COURANT = 0.3             # <- change this (e.g. to 0.15) and run the cell again
with np.errstate(all="ignore"):
    r = run("bar", "tlsph", dim=2, quick=True, progress=False, numerics=dict(beta1=0.0, beta2=0.0, courant=COURANT))
e = r.summary["metrics"]["energy_history"]
t_T, gain = e[:, 0] / T_bar, (e[:, 1] + e[:, 2]) / (e[0, 1] + e[0, 2]) - 1    # energy gained / initial energy
per_period = gain[np.argmin(abs(t_T - 2))] / gain[np.argmin(abs(t_T - 1))]
print(f"Courant {COURANT}, no viscosity, {r.summary['n_steps']} steps: energy gained after two periods "
      f"{gain[-1]:+.2e} of the initial, {per_period:.3g} times that after one")
fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
ax.semilogy(t_T, np.abs(gain))
ax.set(xlabel="t / T", ylabel="|total energy / initial - 1|", title=f"no viscosity, Courant {COURANT}")
ch.show(fig, caption="The energy the undamped bar has gained, relative to its initial energy, over two periods on "
                     "a log scale: a rising straight line is exponential growth.")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# Courant 0.3: the energy grows exponentially, 17-fold in two periods (a surface mode amplified by
# $\sqrt{1+(\omega\Delta t)^4/4}$ per step). Courant 0.15: only $+2.5\cdot10^{-4}$ — to four digits, "constant" —
# but three times the gain after one period, and a rising straight line on the log plot: the same growth, slower,
# not gone. The viscosity is what makes the default step usable.
# </details>

# %% [markdown]
# ### Exercise 4 — Write the corrected deformation gradient yourself
#
# Write Eq. (18) with the correction: from positions `x`, `X` (n, 2) [m], reference volumes `V` [m²] and `h` [m],
# return $\mathbf F$ (n, 2, 2). Use `find_pairs(X, 2 * h)` (each pair once) and `kernel.grad`, no loop over
# particles; the grader compares with `ReferenceOperator`. Predict: which case fails without the correction?

# %% tags=["exercise"]
def my_F(x, X, V, h):
    """Corrected Eq. (18): F_i = -sum_j V_j (x_i - x_j) (x) L_i grad_i W(X_ij), shape (n, 2, 2)."""
    raise NotImplementedError("write the corrected deformation gradient here")   # <- replace by your code


from refsph.teaching.grader import case, check
X_ex, V_ex, rng_ex = lattice([8 * dp_fs, 6 * dp_fs], dp_fs), np.full(48, dp_fs**2), np.random.default_rng(4)
X_jit, V_jit = X_ex + 0.1 * dp_fs * rng_ex.uniform(-1, 1, X_ex.shape), V_ex * rng_ex.uniform(0.9, 1.1, 48)
cases_ex4 = [case(X_ex.copy(), X_ex, V_ex, h_fs, label="a block at rest"),
             case(X_ex @ A.T + 1e-3, X_ex, V_ex, h_fs, label="x = A X + b, the patch test"),
             case(X_jit @ A.T + 0.05 * dp_fs * np.sin(X_jit / dp_fs), X_jit, V_jit, h_fs, label="a jittered block, bent")]
report = check(my_F, lambda x, X, V, h: ReferenceOperator(X, V, h, kernel, True).deformation_gradient(x), cases_ex4)

# %% [markdown]
# <details><summary>What you should see</summary>
#
# As handed out: `FAIL ... not written yet`. Without the correction the block at rest fails at a surface
# particle. Hint: $\mathbf M_i$ is the uncorrected sum with $\mathbf x$ replaced by $\mathbf X$, $\mathbf F_i =
# \mathbf F^{\rm raw}_i\mathbf M_i^{-1}$, each pair adds to both its particles, $\nabla_jW_{ji} = -\nabla_iW_{ij}$.
# </details>
