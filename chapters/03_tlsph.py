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
# Islam, Bansal & Peng, Section 2.2 (Eqs. 15–19), Eq. (2), Section 2.3 (Eqs. 20–24) and the start of
# Section 3 (reference-configuration update).
#
# In Eulerian SPH (chapter 2) the kernel is evaluated at the *current* positions $\mathbf{x}$, so the
# neighbours of a particle change all the time. In **Total Lagrangian SPH** every kernel is evaluated at the
# *reference* positions $\mathbf{X}$ (where the particles were when the reference configuration was last
# set). The neighbours, the kernel gradients $\nabla_i W(\mathbf{X}_{ij})$ and the reference volumes
# $V_j = m_j/\rho_{0j}$ stay fixed until the next reference update. The body is then described by the
# mapping $\mathbf{x} = \phi(\mathbf{X}, t)$ and its gradient $\mathbf{F} = \partial\mathbf{x}/\partial\mathbf{X}$.
#
# This chapter
#
# 1. writes the TLSPH equations as plain pair-by-pair Python loops and checks the fast package code
#    (`refsph.tlsph`) against them, with and without the kernel-gradient correction;
# 2. shows why the correction is needed: Eq. (18) as printed gives $\mathbf{F}\neq\mathbf{I}$ at a free
#    surface of a body at rest;
# 3. explains which stress goes into Eq. (17) and shows what happens with the printed form under a rotation;
# 4. spins a pre-stressed block rigidly and checks that the stress co-rotates (Jaumann rate, Eq. 20);
# 5. measures the wave speed and the energy of a vibrating bar;
# 6. performs a reference-configuration update and checks what it keeps;
# 7. looks at the tensile instability (absent), and at where TLSPH fails.

# %%
import math
import os
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import matplotlib.pyplot as plt
from matplotlib.lines import Line2D

from refsph.kernels import get_kernel
from refsph.material import von_mises
from refsph.neighbours import find_pairs
from refsph.scenes import aisi4340_material, lattice
from refsph.simulate import SimulationError, run
from refsph.state import make_state
from refsph.tensor import det
from refsph.tlsph import (ReferenceOperator, TLSPHParams, green_lagrange_norm,
                          reference_update, tlsph_rates)

QUICK = os.environ.get("REFSPH_QUICK", "0") == "1"     # REFSPH_QUICK=1: coarse, short runs (the tests use it)
ROOT = Path.cwd().parent if Path.cwd().name == "chapters" else Path.cwd()
# Figures go to figures/ in the repo, or to $REFSPH_FIGURES when that is set (the tests set it to a temporary
# folder, so a quick-mode run never overwrites the committed full-resolution figures).
FIG = Path(os.environ["REFSPH_FIGURES"]) if os.environ.get("REFSPH_FIGURES") else ROOT / "figures"
FIG.mkdir(parents=True, exist_ok=True)
T_START = time.perf_counter()

mat = aisi4340_material()       # AISI 4340, Table 3: rho0 = 7830 kg/m^3, E = 207 GPa, nu = 0.3
kernel = get_kernel("cubic")                    # Eq. (9)
print(f"quick mode: {QUICK};  K = {mat.K / 1e9:.1f} GPa, G = {mat.G / 1e9:.1f} GPa, "
      f"C = sqrt(E/rho) = {mat.c0:.0f} m/s")

# %% [markdown]
# ## 1. The equations
#
# With $V_j = m_j/\rho_{0j}$ (reference volume) and $\nabla_i W_{ij} = \nabla_i W(\mathbf{X}_i - \mathbf{X}_j)$
# (the kernel gradient in the **reference** configuration; it points from $i$ towards $j$):
#
# | | |
# |---|---|
# | Eq. (18) | $\mathbf{F}_i = -\sum_j V_j\,(\mathbf{x}_i - \mathbf{x}_j)\otimes\nabla_i W_{ij}$ (deformation gradient) |
# | Eq. (19) | $\dot{\mathbf{F}}_i = -\sum_j V_j\,(\mathbf{v}_i - \mathbf{v}_j)\otimes\nabla_i W_{ij}$ |
# | | $\mathbf{l}_i = \dot{\mathbf{F}}_i\mathbf{F}_i^{-1}$ (velocity gradient, $l_{ab}=\partial v_a/\partial x_b$) |
# | Eq. (2)  | $\rho_i = \rho_{0i}/J_i$, $J = \det\mathbf{F}$ — mass conservation needs no equation |
# | Eq. (24) | $p = K(\rho/\rho_0 - 1)$, $\boldsymbol\sigma = \mathbf{s} - p\mathbf{I}$ |
# | Eq. (20) | $\dot{\mathbf{s}} = 2G(\dot{\boldsymbol\epsilon} - \tfrac13\mathrm{tr}\,\dot{\boldsymbol\epsilon}\,\mathbf{I}) + \boldsymbol\omega\mathbf{s} - \mathbf{s}\boldsymbol\omega$, $\dot{\boldsymbol\epsilon}$, $\boldsymbol\omega$ = sym/skew of $\mathbf{l}$ (Eqs. 21–22; the printed order $\mathbf{s}\boldsymbol\omega-\boldsymbol\omega\mathbf{s}$ belongs to the transposed convention for $\mathbf{l}$, Section 4) |
# | Eq. (17) | $\dfrac{d\mathbf{v}_i}{dt} = \sum_j m_j\left(\dfrac{\mathbf{P}_i}{\rho_{0i}^2} + \dfrac{\mathbf{P}_j}{\rho_{0j}^2} - \boldsymbol\Pi_{ij}\right)\nabla_i W_{ij}$ |
#
# Three places where `refsph` deliberately differs from the printed text (all explained and tested below):
#
# * **Kernel-gradient correction** (Bonet & Lok 1999, CMAME 180, 97). Every $\nabla_i W_{ij}$ is replaced by
#   $\tilde\nabla_i W_{ij} = \mathbf{L}_i\nabla_i W_{ij}$ with
#   $\mathbf{L}_i = \mathbf{M}_i^{-T}$, $\mathbf{M}_i = \sum_j V_j(\mathbf{X}_j - \mathbf{X}_i)\otimes\nabla_i W_{ij}$.
#   In Eq. (17) the $j$ term uses particle $j$'s correction, $\mathbf{P}_j\,\mathbf{L}_j\nabla_i W_{ij}$, so the pair
#   force stays antisymmetric. `corrected=False` gives the equations exactly as printed.
# * **Stress measure.** The paper prints $\mathbf{P} = J\mathbf{F}^{-1}\boldsymbol\sigma$; contracted with the
#   gradient as in Eq. (17) the right tensor is its transpose, $\mathbf{P} = J\boldsymbol\sigma\mathbf{F}^{-T}$
#   (Section 3 below).
# * **Artificial viscosity** in the reference frame: $\boldsymbol\Pi_{ij} = \pi_{ij}(\mathbf{B}_i + \mathbf{B}_j)/2$ with
#   $\mathbf{B} = J\mathbf{F}^{-T}$ (the printed $J\mathbf{F}^{-1}\pi_{ij}$, transposed like $\mathbf{P}$ and
#   averaged over the pair so that the pair force is antisymmetric); $\pi_{ij}$ is Eqs. (12)–(13) with the
#   *current* $\mathbf{x}_{ij}$, $\mathbf{v}_{ij}$, $\bar\rho_{ij}$. It is contracted with the *uncorrected*
#   $\nabla_i W_{ij}$ (a symmetric pair weight, so it conserves momentum by construction).
#
# ### Plain loops
#
# First the kernel gradient of Eq. (9), one pair at a time:

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
    """For each i, the list of j != i with |X_i - X_j| < radius (brute force: the plainest search)."""
    pts = [tuple(p) for p in X]
    return [[j for j in range(len(pts)) if j != i and math.dist(pts[i], pts[j]) < radius]
            for i in range(len(pts))]


Xij_test = np.array([[0.3, 0.1], [1.2, -0.7], [-1.5, 0.9]]) * 1e-4
assert np.allclose([grad_W(r, 1e-4) for r in Xij_test], kernel.grad(Xij_test, 1e-4, 2), rtol=1e-13)

# %% [markdown]
# Now all of TLSPH for one state, pair by pair. Every line is one of the equations above.

# %%
def plain_tlsph(state, mat, h, corrected, beta1=1.5, beta2=1.5, eps=0.01, stress="P"):
    """TLSPH rates by plain loops. stress='P': P = J sigma F^-T (refsph); 'N': the printed J F^-1 sigma."""
    X, x, v, m, V = state.X, state.x, state.v, state.m, state.V0
    n, d = X.shape
    I2 = np.eye(d)
    nb = neighbours(X, 2.0 * h)                                   # fixed until the next reference update
    gW = {(i, j): grad_W(X[i] - X[j], h) for i in range(n) for j in nb[i]}   # grad_i W(X_ij), fixed too

    # Bonet-Lok correction: M_i = sum_j V_j (X_j - X_i) (x) grad_i W_ij,  L_i = M_i^-T
    M = np.zeros((n, d, d))
    for i in range(n):
        for j in nb[i]:
            M[i] += V[j] * np.outer(X[j] - X[i], gW[i, j])
    L = np.array([np.linalg.inv(M[i]).T if corrected else I2 for i in range(n)])
    g = {(i, j): L[i] @ gW[i, j] for (i, j) in gW}               # corrected gradient  L_i grad_i W_ij

    # Eqs. (18), (19)
    F = np.zeros((n, d, d))
    Fdot = np.zeros((n, d, d))
    for i in range(n):
        for j in nb[i]:
            F[i] -= V[j] * np.outer(x[i] - x[j], g[i, j])
            Fdot[i] -= V[j] * np.outer(v[i] - v[j], g[i, j])
    J = np.array([np.linalg.det(F[i]) for i in range(n)])
    Finv = np.array([np.linalg.inv(F[i]) for i in range(n)])
    l = np.array([Fdot[i] @ Finv[i] for i in range(n)])            # velocity gradient

    rho0 = m / V                                                  # reference density
    rho = rho0 / J                                                # Eq. (2)
    p = mat.K * (rho / mat.rho0 - 1.0)                            # Eq. (24)
    sigma = np.array([state.S[i] - p[i] * I2 for i in range(n)])
    if stress == "P":
        P = np.array([J[i] * sigma[i] @ Finv[i].T for i in range(n)])    # P = J sigma F^-T
    else:
        P = np.array([J[i] * Finv[i] @ sigma[i] for i in range(n)])      # printed: J F^-1 sigma (= N)
    B = np.array([J[i] * Finv[i].T for i in range(n)])            # for the artificial viscosity

    # Eq. (17): a_i = sum_j m_j (P_i/rho0i^2 L_i grad_i W_ij - P_j/rho0j^2 L_j grad_j W_ji) - viscosity
    a = np.zeros((n, d))
    for i in range(n):
        for j in nb[i]:
            a[i] += m[j] * (P[i] / rho0[i] ** 2 @ g[i, j] - P[j] / rho0[j] ** 2 @ g[j, i])
            xij, vij = x[i] - x[j], v[i] - v[j]
            vr = vij @ xij
            if vr < 0.0:                                          # Eqs. (12)-(13), approaching pairs only
                mu = h * vr / (xij @ xij + eps * h * h)
                pi = (-beta1 * mat.c0 * mu + beta2 * mu * mu) / (0.5 * (rho[i] + rho[j]))
                a[i] -= m[j] * pi * 0.5 * (B[i] + B[j]) @ gW[i, j]

    # Eqs. (20)-(22), plane strain: the zz deviatoric stress only sees the volumetric rate
    dS = np.zeros((n, d, d))
    dS_zz = np.zeros(n)
    for i in range(n):
        eps_dot, omega = 0.5 * (l[i] + l[i].T), 0.5 * (l[i] - l[i].T)
        tr = np.trace(eps_dot)
        dS[i] = 2 * mat.G * (eps_dot - tr / 3 * I2) + omega @ state.S[i] - state.S[i] @ omega
        dS_zz[i] = -2 * mat.G * tr / 3
    return dict(F=F, Fdot=Fdot, l=l, J=J, rho=rho, p=p, P=P, a=a, dS=dS, dS_zz=dS_zz, M=M, L=L)

# %% [markdown]
# ### A small, randomly deformed, moving, pre-stressed block
#
# 20 × 15 particles on a slightly irregular reference lattice (so that the correction matrices differ from
# particle to particle), deformed by an affine map plus random noise, with a random velocity field (so that the
# artificial viscosity acts on many pairs) and a random deviatoric pre-stress of ~100 MPa.

# %%
def random_block(nx=20, ny=15, dp=1e-4, seed=0):
    rng = np.random.default_rng(seed)
    X = lattice([nx * dp, ny * dp], dp) + 0.1 * dp * rng.uniform(-1, 1, (nx * ny, 2))
    st = make_state(X, 0.0, mat.rho0, dp * dp * (1 + 0.05 * rng.uniform(-1, 1, nx * ny)))
    A = np.array([[1.04, 0.12], [-0.05, 0.97]])
    st.x = X @ A.T + 0.02 * dp * rng.normal(size=X.shape)
    st.v = rng.normal(scale=5.0, size=X.shape) + (X - X.mean(0)) @ np.array([[0, -2e3], [3e3, 1e3]]).T
    s = rng.normal(scale=100e6, size=(len(X), 3))
    st.S = np.stack([np.stack([s[:, 0], s[:, 2]], -1), np.stack([s[:, 2], s[:, 1]], -1)], 1)
    st.S_zz = -(s[:, 0] + s[:, 1])
    return st, dp


blk, dp_blk = random_block()
h_blk = 1.5 * dp_blk
for corrected in (False, True):
    prm = TLSPHParams(h=h_blk, beta1=1.5, beta2=1.5, eps=0.01, kernel=kernel, corrected=corrected,
                      ref_update_strain=0.5)
    op = ReferenceOperator(blk.X, blk.V0, prm.h, kernel, corrected)
    out = {}
    rates = tlsph_rates(blk, mat, prm, op, out=out)
    ref = plain_tlsph(blk, mat, h_blk, corrected)
    Fdot_pkg = op.gradient(blk.v)
    amax = np.abs(ref["a"]).max()
    assert np.allclose(op.deformation_gradient(blk.x), ref["F"], rtol=1e-12, atol=1e-12)
    assert np.allclose(out["F"], ref["F"], rtol=1e-12, atol=1e-12)
    assert np.allclose(Fdot_pkg, ref["Fdot"], rtol=1e-12, atol=1e-12 * np.abs(ref["Fdot"]).max())
    assert np.allclose(out["l"], ref["l"], rtol=1e-10, atol=1e-12 * np.abs(ref["l"]).max())
    assert np.allclose(out["J"], ref["J"], rtol=1e-12)
    assert np.allclose(out["rho"], ref["rho"], rtol=1e-12)
    assert np.allclose(out["P"], ref["P"], rtol=1e-10, atol=1e-12 * np.abs(ref["P"]).max())
    assert np.allclose(rates.v, ref["a"], rtol=1e-10, atol=1e-11 * amax)
    assert np.allclose(rates.S, ref["dS"], rtol=1e-10, atol=1e-11 * np.abs(ref["dS"]).max())
    assert np.allclose(rates.S_zz, ref["dS_zz"], rtol=1e-10, atol=1e-11 * np.abs(ref["dS_zz"]).max())
    ma = blk.m[:, None] * rates.v
    # internal power of the stress forces vs stress power: sum_i m_i v_i . a_i = - sum_i V_i P_i : Fdot_i
    a_stress = tlsph_rates(blk, mat, replace(prm, beta1=0.0, beta2=0.0), op).v
    power = np.sum(blk.m[:, None] * blk.v * a_stress)
    stress_power = np.sum(blk.V0[:, None, None] * out["P"] * Fdot_pkg)
    power_scale = np.sum(np.abs(blk.V0[:, None, None] * out["P"] * Fdot_pkg))
    assert abs(power + stress_power) < 1e-12 * power_scale
    print(f"corrected={corrected!s:5}: plain loops == package  (N = {blk.n}, {op.n_pairs} pairs); "
          f"max|a| = {amax:.3e} m/s^2;  |sum m a| / sum |m a| = "
          f"{np.linalg.norm(ma.sum(0)) / np.linalg.norm(ma, axis=1).sum():.1e};  "
          f"|power + sum V P:Fdot| / scale = {abs(power + stress_power) / power_scale:.1e}")

# %% [markdown]
# The package does the same sums as sparse matrix products: for direction $k$,
# $G_k[i,j] = V_j(\mathbf{L}_i\nabla_i W_{ij})_k$ is built once per reference configuration, and
# $\mathbf{F} = $ `op.gradient(x)`, $\dot{\mathbf{F}} = $ `op.gradient(v)`.
#
# Two properties hold to round-off, with or without the correction:
#
# * **Linear momentum** is conserved, $\sum_i m_i\mathbf{a}_i = 0$: every pair term of Eq. (17) is
#   antisymmetric in $i \leftrightarrow j$.
# * **Energy consistency**: the power of the stress forces equals minus the stress power,
#   $\sum_i m_i\mathbf{v}_i\cdot\mathbf{a}_i = -\sum_i V_i\,\mathbf{P}_i:\dot{\mathbf{F}}_i$ (for a uniform reference
#   density). Swapping $i$ and $j$ in the $j$ term of Eq. (17) turns it into the $\mathbf{v}_j$ term of Eq. (19):
#   the discrete divergence in Eq. (17) is the exact transpose of the discrete gradient in Eq. (19). This is why
#   $j$'s term must carry $j$'s correction $\mathbf{L}_j$.
#
# ## 2. The kernel-gradient correction
#
# A useful way to read the correction: $\mathbf{M}_i$ is exactly what the uncorrected Eq. (18) returns for the
# identity map $\mathbf{x} = \mathbf{X}$, and the corrected deformation gradient is
# $\mathbf{F}_i = \mathbf{F}^{\rm raw}_i\mathbf{M}_i^{-1}$ (because $\mathbf{a}\otimes\mathbf{L}\mathbf{g} =
# (\mathbf{a}\otimes\mathbf{g})\mathbf{L}^T$). So the correction *divides out* the error that the truncated
# kernel support makes.
#
# Eq. (18) is printed in two forms that are equal only where the kernel support is complete:
# the **position form** $-\sum_j V_j(\mathbf{x}_i-\mathbf{x}_j)\otimes\nabla_i W_{ij}$ and the **displacement form**
# $\mathbf{I} - \sum_j V_j(\mathbf{u}_i-\mathbf{u}_j)\otimes\nabla_i W_{ij}$. We evaluate both on a block at rest and under
# an affine map $\mathbf{x} = \mathbf{A}\mathbf{X}$ (patch test).

# %%
dp_fs = 1e-4
nx_fs, ny_fs = 30, 20
X_fs = lattice([nx_fs * dp_fs, ny_fs * dp_fs], dp_fs)
V_fs = np.full(len(X_fs), dp_fs**2)
h_fs = 1.5 * dp_fs
op_raw = ReferenceOperator(X_fs, V_fs, h_fs, kernel, corrected=False)
op_cor = ReferenceOperator(X_fs, V_fs, h_fs, kernel, corrected=True)
I_n = np.broadcast_to(np.eye(2), (len(X_fs), 2, 2))


def fnorm(A):
    return np.sqrt(np.einsum("nab,nab->n", A, A))


# distance to the nearest free surface, in units of dp: "interior" = complete kernel support
dist_fs = np.minimum.reduce([X_fs[:, 0], nx_fs * dp_fs - X_fs[:, 0], X_fs[:, 1], ny_fs * dp_fs - X_fs[:, 1]]) / dp_fs
interior = dist_fs > 2 * h_fs / dp_fs + 0.5
surface = dist_fs < 1.0

F_rest_raw = op_raw.deformation_gradient(X_fs)                    # position form, at rest
F_rest_cor = op_cor.deformation_gradient(X_fs)
err_raw, err_cor = fnorm(F_rest_raw - I_n), fnorm(F_rest_cor - I_n)
J_raw = det(F_rest_raw)
print("body at rest, |F - I| (Frobenius):")
print(f"  Eq. (18) as printed (position form): surface max {err_raw[surface].max():.3f}, "
      f"corner {err_raw.max():.3f}, interior max {err_raw[interior].max():.2e}")
print(f"  corrected:                           max over all particles {err_cor.max():.1e}")
print(f"  uncorrected J at rest: min {J_raw.min():.3f} (corner) -> spurious pressure K(1/J - 1) = "
      f"{mat.K * (1 / J_raw.min() - 1) / 1e9:.0f} GPa")
assert err_cor.max() < 1e-12 and err_raw[surface].max() > 0.1

# %%
fig, axes = plt.subplots(1, 2, figsize=(13, 4.4), constrained_layout=True)
LogNorm = plt.matplotlib.colors.LogNorm
for ax, err, title, norm in ((axes[0], err_raw, "Eq. (18) as printed (uncorrected)", LogNorm(1e-3, 1.0)),
                             (axes[1], err_cor, "with kernel-gradient correction", LogNorm(1e-17, 1e-13))):
    sc = ax.scatter(X_fs[:, 0] * 1e3, X_fs[:, 1] * 1e3, c=np.clip(err, norm.vmin, None), s=22, cmap="viridis",
                    norm=norm)
    ax.set_aspect("equal")
    ax.set_xlabel("X [mm]")
    ax.set_ylabel("Y [mm]")
    ax.set_title(f"{title}\nmax |F - I| = {err.max():.2g}")
    fig.colorbar(sc, ax=ax, label="|F - I|  (Frobenius norm)", shrink=0.8)
fig.suptitle("Deformation gradient of a body at rest, 30 x 20 particles, h = 1.5 dp, cubic spline")
fig.savefig(FIG / "03_F_free_surface.png", dpi=120)
plt.show()

# %% [markdown]
# Without the correction the interior is not exact either: on a square lattice the discrete sum is
# isotropic, $\mathbf{M} = c\,\mathbf{I}$ with $c$ close to but not equal to one (the printed interior value).
# At the surface half of the support is missing, $\mathbf{F}$ is far from $\mathbf{I}$ and $J$ drops to about
# 0.1 at a corner: the equation of state turns that into a pressure of a terapascal. An uncorrected TLSPH body
# therefore explodes within a few steps (Section 5).
#
# **Patch test.** An affine map must give $\mathbf{F}=\mathbf{A}$ exactly — any SPH gradient that cannot do
# this cannot converge at the boundary.

# %%
A = np.array([[1.10, 0.30], [-0.20, 0.90]])                        # stretch + shear + rotation
x_aff = X_fs @ A.T + np.array([1e-3, -2e-3])                       # plus a translation
U_aff = x_aff - X_fs
F_aff_cor = op_cor.deformation_gradient(x_aff)
F_aff_pos = op_raw.deformation_gradient(x_aff)
F_aff_dsp = I_n + op_raw.gradient(U_aff)                          # displacement form of Eq. (18)
F_rest_dsp = I_n + op_raw.gradient(np.zeros_like(X_fs))
e_cor, e_pos, e_dsp = (fnorm(F - A) for F in (F_aff_cor, F_aff_pos, F_aff_dsp))
print("patch test x = A X + b, max |F - A|:")
print(f"  corrected:                       all particles {e_cor.max():.1e}")
print(f"  uncorrected, position form:      surface {e_pos[surface].max():.3f}, interior {e_pos[interior].max():.1e}")
print(f"  uncorrected, displacement form:  surface {e_dsp[surface].max():.3f}, interior {e_dsp[interior].max():.1e}"
      f"   (at rest it gives |F - I| = {fnorm(F_rest_dsp - I_n).max():.0e})")
assert e_cor.max() < 1e-12
assert e_pos[surface].max() > 0.1 and e_dsp[surface].max() > 0.01

# %% [markdown]
# The displacement form gives $\mathbf{F}=\mathbf{I}$ at rest (trivially: $\mathbf{u}=0$) but still fails the
# patch test at the surface; only the corrected gradient passes both. `refsph` uses the position form with
# the correction.
#
# ## 3. Which stress goes into Eq. (17)?
#
# Eq. (4) reads $\rho_0\,\dot{\mathbf{v}} = \nabla_0\cdot\mathbf{P}$, i.e. $\rho_0\dot v_a = \partial P_{aK}/\partial X_K$:
# the first index of $\mathbf{P}$ is spatial, the second material, and Eq. (17) contracts the second one with
# $\nabla_i W$: $(\mathbf{P}\nabla W)_a = P_{aK}\,\partial_K W$. For that contraction the first Piola–Kirchhoff
# stress is $\mathbf{P} = J\boldsymbol\sigma\mathbf{F}^{-T}$ (Bonet & Wood, *Nonlinear Continuum Mechanics*,
# Sec. 5.5). The paper prints $\mathbf{P} = J\mathbf{F}^{-1}\boldsymbol\sigma$, which is the **nominal stress**
# $\mathbf{N} = \mathbf{P}^T$ (the convention of codes that write $\nabla_0 \cdot$ as a contraction on the first
# index). The two agree only when $\mathbf{P}$ happens to be symmetric (e.g. $\mathbf{F}=\lambda\mathbf{I}$); a rotation
# breaks that.
#
# **Numerical check.** A pre-stressed body rigidly rotated by 90° ($\mathbf{x} = \mathbf{R}\mathbf{x}^0$, stress rotated
# with it, $\boldsymbol\sigma = \mathbf{R}\boldsymbol\sigma_0\mathbf{R}^T$) must feel the rotated force of the
# unrotated body: $\mathbf{a}^{\rm rot}_i = \mathbf{R}\,\mathbf{a}^0_i$. The unrotated body $\mathbf{x}^0$ is compressed
# slightly (so that $J<1$ and the equation of state adds a pressure of a few hundred MPa) and carries a deviatoric
# pre-stress. Two states: a **uniform** one ($\mathbf{x}^0 = 0.999\,\mathbf{X}$, constant deviatoric stress: the
# force vanishes in the deep interior, only the free surfaces feel a net force) and a **non-uniform** one
# (compression and deviatoric stress varying along $X$: force $\approx \nabla\cdot\boldsymbol\sigma/\rho$
# everywhere). We also repeat the test for a 30° rotation.

# %%
prm_rot = TLSPHParams(h=h_fs, beta1=0.0, beta2=0.0, eps=0.01, kernel=kernel, corrected=True, ref_update_strain=None)
Lx_fs = nx_fs * dp_fs
lam = 0.999                                                        # uniform compression of the unrotated body
deep = dist_fs > 4 * h_fs / dp_fs + 0.5     # neighbours *and their neighbours* have complete supports


def Rot(th):
    return np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])


def stress_field(X, kind):
    s_xx = 200e6 * np.ones(len(X))
    s_xy = 120e6 * np.ones(len(X))
    if kind == "non-uniform":
        s_xx = s_xx * (1 + 2 * X[:, 0] / Lx_fs)
        s_xy = s_xy * (1 - 3 * X[:, 0] / Lx_fs)
    return np.stack([np.stack([s_xx, s_xy], -1), np.stack([s_xy, -s_xx], -1)], 1)


def unrotated_positions(kind):
    if kind == "uniform":
        return lam * X_fs
    x0 = X_fs.copy()
    x0[:, 0] -= 0.002 * X_fs[:, 0] ** 2 / Lx_fs            # F0 = diag(1 - 0.004 X/L, 1): J varies along X
    return x0


def tl_force(x, S, measure):
    """Corrected TLSPH stress force (Eq. 17, no viscosity) with P = J sigma F^-T or the printed N = J F^-1 sigma."""
    st = make_state(X_fs, 0.0, mat.rho0, V_fs)
    st.x, st.S = x, S
    out = {}
    a = tlsph_rates(st, mat, prm_rot, op_cor, out=out).v
    if measure == "P":
        return a, out
    F, J = out["F"], out["J"]
    sigma = S - out["p"][:, None, None] * np.eye(2)
    N = J[:, None, None] * np.linalg.inv(F) @ sigma
    return op_cor.momentum_sum(N / mat.rho0**2, st.m), out


rot_rows = []
for deg in (90, 30):
    R = Rot(np.radians(deg))
    for kind in ("uniform", "non-uniform"):
        S0 = stress_field(X_fs, kind)
        x0 = unrotated_positions(kind)
        a0, out0 = tl_force(x0, S0, "P")                 # unrotated body, P = J sigma F^-T (refsph)
        target = a0 @ R.T                                # R a0, particle by particle
        if deg == 90 and kind == "uniform":
            a_uniform = dict(a0=a0, target=target)
        for name in ("P", "N"):
            a, out = tl_force(x0 @ R.T, R @ S0 @ R.T, name)
            err = np.linalg.norm(a - target, axis=1)
            ref_mag = np.linalg.norm(a0, axis=1)
            rot_rows.append((deg, kind, name, ref_mag[surface].max(), err[surface].max(),
                             ref_mag[deep].max(), err[deep].max()))
            if deg == 90 and kind == "uniform":
                a_uniform[name] = a
                p_uni = out["p"].mean()
print(f"uniform state: pressure from J = {lam}^2: {p_uni / 1e6:.0f} MPa; deviatoric s_xx = 200 MPa, "
      f"s_xy = 120 MPa; non-uniform: p from {out0['p'].min() / 1e6:.0f} to {out0['p'].max() / 1e6:.0f} MPa")
print(f"{'':29} |  surface particles:              |  deep interior:")
print(f"{'angle':>5} {'state':>11} {'measure':>11} | {'max|a0|':>9} {'max|a - R a0|':>13} {'rel.':>8} |"
      f" {'max|a0|':>9} {'max|a - R a0|':>13} {'rel.':>8}   [m/s^2]")
names = {"P": "J sig F^-T", "N": "J F^-1 sig"}
for deg, kind, name, a0s, es, a0d, ed in rot_rows:
    rel_d = f"{ed / a0d:8.1e}" if a0d > 1e-9 * a0s else f"{'(0: round-off)':>8}"
    print(f"{deg:5d} {kind:>11} {names[name]:>11} | {a0s:9.2e} {es:13.2e} {es / a0s:8.1e} |"
          f" {a0d:9.2e} {ed:13.2e} {rel_d}")
for deg, kind, name, a0s, es, a0d, ed in rot_rows:
    if name == "P":
        assert es < 1e-11 * a0s and ed < 1e-11 * a0s
        if kind == "uniform":
            assert a0d < 1e-12 * a0s                     # uniform stress: no force in the deep interior
    else:
        assert es > 0.1 * a0s
        if kind == "non-uniform":
            assert ed > 0.1 * a0d

# %%
k_corner = np.argmax(np.linalg.norm(a_uniform["a0"], axis=1))
print("corner particle, uniform pre-stress, 90 degree rotation (m/s^2):")
print(f"  unrotated body                      a0 = {a_uniform['a0'][k_corner]}")
print(f"  rotated, expected                 R a0 = {a_uniform['target'][k_corner]}")
print(f"  rotated, P = J sigma F^-T (refsph)     = {a_uniform['P'][k_corner]}")
print(f"  rotated, N = J F^-1 sigma (printed)    = {a_uniform['N'][k_corner]}")

# %% [markdown]
# With $\mathbf{P}=J\boldsymbol\sigma\mathbf{F}^{-T}$ the rotated body feels exactly the rotated force (to
# round-off), and a uniform stress gives zero force in the deep interior. With the printed form the force is
# wrong by order one at the surface, and for the non-uniform state in the interior too. With
# $\mathbf{F}=\mathbf{R}\mathbf{F}_0$ and $\boldsymbol\sigma=\mathbf{R}\boldsymbol\sigma_0\mathbf{R}^T$:
# $\mathbf{P} = J\mathbf{R}\boldsymbol\sigma_0\mathbf{R}^T\mathbf{R}\mathbf{F}_0^{-T} = \mathbf{R}\mathbf{P}_0$ — the force
# rotates with the body — whereas $\mathbf{N} = J\mathbf{F}_0^{-1}\mathbf{R}^T\mathbf{R}\boldsymbol\sigma_0\mathbf{R}^T =
# \mathbf{N}_0\mathbf{R}^T$, contracted with $\nabla W$ that is $\mathbf{N}_0(\mathbf{R}^T\nabla W)$: the
# stress of the unrotated body applied along a wrongly rotated gradient.
# A curiosity of 2D: a trace-free symmetric 2×2 tensor is a scaled reflection, $\mathbf{s}\mathbf{R}^T = \mathbf{R}\mathbf{s}$,
# so in the uniform state (with $\mathbf{F}_0 = \lambda\mathbf{I}$) the deviatoric part happens to give the right force
# and the whole error comes from the pressure (at 90°, $\mathbf{R}^T = -\mathbf{R}$: the pressure force has the wrong
# sign). For $\mathbf{F}=\lambda\mathbf{I}$ (pure compression, no rotation) both forms are equal, so a test
# without rotation can easily miss the difference.
#
# ## 4. Rigid rotation of a pre-stressed body: the stress must co-rotate
#
# A block with a uniform deviatoric pre-stress $\mathbf{s}_0$ is turned rigidly by a quarter turn,
# $\mathbf{x}(t) = \mathbf{x}_c + \mathbf{R}(\omega t)(\mathbf{X}-\mathbf{x}_c)$, $\mathbf{v} = \omega\,\mathbf{e}_z\times(\mathbf{x}-\mathbf{x}_c)$.
# We prescribe the motion and integrate only the stress, with the package's rates (`tlsph_rates`: TLSPH
# $\mathbf{F}$, $\dot{\mathbf{F}}$, $\mathbf{l}$ and the Jaumann rate, Eq. 20) and the predictor–corrector scheme
# of `refsph.integrate`. (A free dynamic run cannot do this test cleanly: a body with a uniform stress and free
# edges is not in equilibrium and would spring back to a stress-free shape within a few wave transits.)
# The exact answer is $\mathbf{s}(t) = \mathbf{R}\mathbf{s}_0\mathbf{R}^T$, with constant invariants.
#
# For comparison we also integrate two wrong laws: the spin terms with the printed order
# ($\mathbf{s}\boldsymbol\omega - \boldsymbol\omega\mathbf{s}$, which is right only for the transposed
# convention $l_{ab} = \partial v_b/\partial x_a$; `refsph` uses $l_{ab} = \partial v_a/\partial x_b$, see
# `refsph/material.py`) and no spin terms at all (a non-objective rate).

# %%
nx_r, ny_r, dp_r = 16, 8, 1e-4
X_r = lattice([nx_r * dp_r, ny_r * dp_r], dp_r)
xc_r = X_r.mean(0)
prm_r = TLSPHParams(h=1.5 * dp_r, beta1=1.5, beta2=1.5, eps=0.01, kernel=kernel, corrected=True,
                    ref_update_strain=None)
op_r = ReferenceOperator(X_r, np.full(len(X_r), dp_r**2), prm_r.h, kernel, True)
S0_r = np.array([[250e6, 150e6], [150e6, -100e6]])
S0zz_r = -np.trace(S0_r)
omega_r = 2e3                                               # rad/s; strains stay zero, only the angle matters
n_steps_r = 100 if QUICK else 400
T_r = 0.5 * np.pi / omega_r
dt_r = T_r / n_steps_r


def kinematics(t):
    R = Rot(omega_r * t)
    x = xc_r + (X_r - xc_r) @ R.T
    v = omega_r * np.stack([-(x[:, 1] - xc_r[1]), x[:, 0] - xc_r[0]], 1)
    return x, v


def spin_rate(st, law):
    x, v = kinematics(st.t)
    st.x, st.v = x, v
    out = {}
    r = tlsph_rates(st, mat, prm_r, op_r, out=out)
    if law == "jaumann":                                      # refsph (Eq. 20, omega s - s omega)
        return r.S, r.S_zz
    l = out["l"]
    eps_dot, om = 0.5 * (l + np.swapaxes(l, 1, 2)), 0.5 * (l - np.swapaxes(l, 1, 2))
    dS = 2 * mat.G * (eps_dot - np.trace(eps_dot, axis1=1, axis2=2)[:, None, None] / 3 * np.eye(2))
    if law == "printed order":
        dS = dS + st.S @ om - om @ st.S
    return dS, r.S_zz


hist_r = {}
for law in ("jaumann", "printed order", "no spin"):
    st = make_state(X_r, 0.0, mat.rho0, dp_r**2)
    st.S[:] = S0_r
    st.S_zz[:] = S0zz_r
    rows = []
    for k in range(n_steps_r + 1):
        x_now, _ = kinematics(st.t)
        J_now = det(op_r.deformation_gradient(x_now))
        p_now = mat.K * (1.0 / J_now - 1.0)                 # Eqs. (2), (24) with rho0 = m / V0
        rows.append((st.t, st.S.mean(0).ravel(), von_mises(st.S, st.S_zz).mean(),
                     np.ptp(von_mises(st.S, st.S_zz)), np.abs(p_now).max(), st.S.copy(), x_now))
        if k == n_steps_r:
            break
        # predictor-corrector (refsph.integrate): half step with the rate at t, full step with the rate at t+dt/2
        dS, dSzz = spin_rate(st, law)
        half = st.copy()
        half.S, half.S_zz, half.t = st.S + 0.5 * dt_r * dS, st.S_zz + 0.5 * dt_r * dSzz, st.t + 0.5 * dt_r
        dS, dSzz = spin_rate(half, law)
        st.S, st.S_zz, st.t = st.S + dt_r * dS, st.S_zz + dt_r * dSzz, st.t + dt_r
    hist_r[law] = rows

vm0 = von_mises(S0_r[None], np.array([S0zz_r]))[0]
print(f"quarter turn in {n_steps_r} steps; von Mises of s0 = {vm0 / 1e6:.1f} MPa")
print(f"{'law':>14} | max over the turn of |s - R s0 R^T| / |s0| | von Mises change | spread over particles |"
      f" max |p|")
rot_err = {}
for law, rows in hist_r.items():
    err = max(np.abs(r[5] - Rot(omega_r * r[0]) @ S0_r @ Rot(omega_r * r[0]).T).max() for r in rows)
    rot_err[law] = err / np.abs(S0_r).max()
    dvm = max(abs(r[2] - vm0) for r in rows) / vm0
    spread = max(r[3] for r in rows) / vm0
    pmax = max(r[4] for r in rows)
    print(f"{law:>14} | {rot_err[law]:41.1e} | {dvm:16.1e} | {spread:21.1e} | {pmax:.1e} Pa")
assert rot_err["jaumann"] < 2e-3 and rot_err["printed order"] > 0.5 and rot_err["no spin"] > 0.5

# %%
LAWS = (("jaumann", "-", "Jaumann, refsph (Eq. 20)"), ("printed order", "--", "spin terms in printed order"),
        ("no spin", ":", "no spin terms"))
fig, axes = plt.subplots(1, 3, figsize=(15, 4.4), constrained_layout=True)
ang = lambda rows: np.array([r[0] for r in rows]) * omega_r * 180 / np.pi  # noqa: E731
th = np.linspace(0, 0.5 * np.pi, 200)
S_ex = np.array([Rot(t) @ S0_r @ Rot(t).T for t in th])
ax = axes[0]
for comp, (i, j), c in (("s_xx", (0, 0), "C0"), ("s_yy", (1, 1), "C1"), ("s_xy", (0, 1), "C2")):
    ax.plot(th * 180 / np.pi, S_ex[:, i, j] / 1e6, "-", color=c, lw=6, alpha=0.25)
    for law, ls, _ in LAWS:
        rows = hist_r[law]
        ax.plot(ang(rows), [r[1][2 * i + j] / 1e6 for r in rows], ls, color=c, lw=1.5)
handles = [Line2D([], [], color=c, lw=2, label=comp) for comp, c in (("s_xx", "C0"), ("s_yy", "C1"), ("s_xy", "C2"))]
handles += [Line2D([], [], color="0.5", lw=6, alpha=0.35, label="exact R s0 R^T")]
handles += [Line2D([], [], color="k", ls=ls, label=lab) for _, ls, lab in LAWS]
ax.legend(handles=handles, fontsize=7.5, ncol=2, loc="lower left")
ax.set_ylim(-400, 340)
ax.set_xlabel("rotation angle [deg]")
ax.set_ylabel("deviatoric stress (mean over particles) [MPa]")
ax.set_title("stress components")
ax.grid(alpha=0.3)

ax = axes[1]
for law, ls, lab in LAWS:
    rows = hist_r[law]
    ax.plot(ang(rows), [1e6 * (r[2] - vm0) / vm0 for r in rows], ls, lw=2, label=f"von Mises, {lab}")
ax.plot(ang(hist_r["jaumann"]), [1e6 * r[4] / vm0 for r in hist_r["jaumann"]], "k-.", label="max |p| / von Mises(s0)")
ax.set_xlabel("rotation angle [deg]")
ax.set_ylabel("relative change  [x 1e-6]")
ax.set_title(f"invariants stay constant (drift: time-integration error, {n_steps_r} steps)")
ax.legend(fontsize=8)
ax.grid(alpha=0.3)

ax = axes[2]
for law, ls, lab in LAWS:
    rows = hist_r[law]
    Sm = np.array([r[1].reshape(2, 2) for r in rows])
    theta_p = 0.5 * np.arctan2(2 * Sm[:, 0, 1], Sm[:, 0, 0] - Sm[:, 1, 1])   # major principal direction
    turned = np.degrees(np.unwrap(2 * (theta_p - theta_p[0])) / 2)
    ax.plot(ang(rows), turned, ls, lw=2, label=lab)
ax.plot([0, 90], [0, 90], color="0.5", lw=6, alpha=0.3, label="exact: turns with the body")
ax.set_xlabel("rotation angle of the body [deg]")
ax.set_ylabel("rotation of the principal stress axes [deg]")
ax.set_title("orientation: only the Jaumann rate co-rotates")
ax.legend(fontsize=8)
ax.grid(alpha=0.3)
fig.suptitle(f"Rigid quarter turn of a pre-stressed block ({X_r.shape[0]} particles; prescribed motion, "
             "TLSPH velocity gradient, predictor-corrector stress update)")
fig.savefig(FIG / "03_rotation.png", dpi=120)
plt.show()

# %% [markdown]
# With TLSPH, $\mathbf{F}=\mathbf{R}$ exactly (corrected gradient), so $\mathbf{l}=\dot{\mathbf{R}}\mathbf{R}^T$ is a
# pure spin: no strain rate, and the Jaumann rate only rotates $\mathbf{s}$. The remaining error is the time
# integration error of the rotation, $O((\omega\Delta t)^2)$ per quarter turn. Both wrong laws also keep the
# invariants (they, too, only rotate $\mathbf{s}$) — so constant invariants alone prove nothing; the
# *orientation* shows the difference: with the printed order the stress turns the wrong way, without spin terms
# it stays fixed in space while the body turns. (At exactly 90° the printed order happens to agree again: a
# 2D deviatoric tensor turned by +90° or −90° is the same tensor.) The slow drift of the von Mises stress is the
# amplitude error of the explicit predictor–corrector step on a pure rotation, about $(2\omega\Delta t)^4/8$ per
# step; it vanishes as $\Delta t\to0$.
#
# ## 5. Wave speed and energy: the vibrating bar
#
# Scene `bar`: a free–free AISI 4340 bar, 20 × 2 mm, started in its first axial mode
# $v_x = v_0\cos(\pi X/L)$. The period is $T = 2L/c$ with the plane-strain bar speed
# $c = \sqrt{E/((1-\nu^2)\rho_0)}$. Quick mode: $dp = W/8$, else $W/16$.

# %%
t0 = time.perf_counter()
bar = run("bar", "tlsph", dim=2, quick=QUICK, progress=False)
mb = bar.summary["metrics"]
print(f"TLSPH bar, dp = W/{bar.setup.info['W'] / bar.setup.dp:.0f}, {bar.summary['n_particles']} particles, "
      f"{bar.summary['n_steps']} steps, {time.perf_counter() - t0:.1f} s")
print(f"  wave speed {mb['wave_speed_m_s']:.1f} m/s vs theory {mb['wave_speed_theory_m_s']:.1f} m/s: "
      f"{100 * mb['wave_speed_rel_error']:+.2f} %")
print(f"  energy after 2 periods / initial: {mb['energy_final_over_initial']:.3f}   "
      f"momentum drift {mb['momentum_drift_rel']:.1e}   reference updates: "
      f"{bar.summary['diagnostics']['reference_updates']}")
assert abs(mb["wave_speed_rel_error"]) < 0.01

# %% [markdown]
# The artificial viscosity (Eqs. 12–13, $\beta_1=\beta_2=1.5$) damps approaching pairs, so the total energy
# decays. Is the undamped scheme energy-conserving? Semi-discretely yes: the force of Eq. (17) is the exact
# transpose of Eq. (19) (checked in Section 1: internal power $= -\sum_i V_i\,\mathbf{P}_i:\dot{\mathbf{F}}_i$).
# But the time integrator is not: the predictor–corrector of `refsph.integrate` is the explicit midpoint rule,
# which multiplies an undamped oscillation of frequency $\omega$ by $\sqrt{1+(\omega\Delta t)^4/4}$ every step.
# For the highest-frequency particle modes at the default Courant number 0.3 that is a slow but exponential
# growth; halving the time step reduces the rate per unit time about 8-fold.

# %%
bar_runs = {"AV on, Courant 0.3 (default)": bar}
for label, num in (("AV off, Courant 0.3", dict(beta1=0.0, beta2=0.0)),
                   ("AV off, Courant 0.15", dict(beta1=0.0, beta2=0.0, courant=0.15))):
    t0 = time.perf_counter()
    with np.errstate(all="ignore"):          # the unstable run may overflow the energy diagnostic at full resolution
        bar_runs[label] = run("bar", "tlsph", dim=2, dp=bar.setup.dp, quick=QUICK, progress=False, numerics=num)
    print(f"{label}: {time.perf_counter() - t0:.1f} s")
e_bar = {}
for label, r in bar_runs.items():
    m = r.summary["metrics"]
    E = m["energy_history"][:, 1] + m["energy_history"][:, 2]
    e_bar[label] = E.max() / E[0]
    print(f"{label:28}: {r.summary['n_steps']:5d} steps, wave speed {100 * m['wave_speed_rel_error']:+8.2f} %, "
          f"total energy / initial: max {E.max() / E[0]:.6g}, final {E[-1] / E[0]:.6g}, "
          f"reference updates {r.summary['diagnostics']['reference_updates']}")
s_nv = bar_runs["AV off, Courant 0.3"].state
ij_b = np.round(bar.setup.state.X / bar.setup.dp - 0.5).astype(int)   # lattice indices of the initial state
mid_b = (ij_b[:, 0] > 5) & (ij_b[:, 0] < ij_b[:, 0].max() - 5)
prof = np.array([s_nv.v[mid_b & (ij_b[:, 1] == k), 1].mean() for k in range(ij_b[:, 1].max() + 1)])
print("AV off, Courant 0.3, t = 2T: mean v_y of each particle row, bottom to top, / max:",
      np.array2string(prof / np.abs(prof).max(), precision=2))
assert e_bar["AV off, Courant 0.3"] > 2 and e_bar["AV off, Courant 0.15"] < 1.01
assert e_bar["AV on, Courant 0.3 (default)"] < 1.0 + 1e-6

try:
    with np.errstate(all="ignore"):                                # the blow-up overflows on its way to NaN
        run("bar", "tlsph", dim=2, dp=bar.setup.dp, quick=QUICK, progress=False, numerics=dict(corrected=False))
    print("uncorrected bar: ran")
except SimulationError as e:
    print(f"uncorrected bar (Eq. 18 as printed): {e}")

# %%
eh = mb["energy_history"]
T_bar = bar.setup.info["period_theory"]
E0 = eh[0, 1] + eh[0, 2]
fig, axes = plt.subplots(1, 3, figsize=(15, 4), constrained_layout=True)
axes[0].plot(np.asarray(bar.history["t"]) / T_bar, bar.history["amplitude"], "C0")
axes[0].set_xlabel("t / T (theory)")
axes[0].set_ylabel("modal velocity amplitude [m/s]")
axes[0].set_title(f"first axial mode: c = {mb['wave_speed_m_s']:.0f} m/s\n"
                  f"({100 * mb['wave_speed_rel_error']:+.2f} % vs sqrt(E/((1-nu^2) rho)))")
axes[0].grid(alpha=0.3)
axes[1].plot(eh[:, 0] / T_bar, eh[:, 1] / E0, label="kinetic")
axes[1].plot(eh[:, 0] / T_bar, eh[:, 2] / E0, label="elastic")
axes[1].plot(eh[:, 0] / T_bar, (eh[:, 1] + eh[:, 2]) / E0, "k", label="total")
axes[1].set_xlabel("t / T (theory)")
axes[1].set_ylabel("energy / initial energy")
axes[1].set_title("energy exchange (artificial viscosity on)")
axes[1].legend(loc="center left")
axes[1].grid(alpha=0.3)
for (label, r), c in zip(bar_runs.items(), ("k", "C3", "C2")):
    e = r.summary["metrics"]["energy_history"]
    axes[2].semilogy(e[:, 0] / T_bar, (e[:, 1] + e[:, 2]) / (e[0, 1] + e[0, 2]), color=c, label=label)
axes[2].set_xlabel("t / T (theory)")
axes[2].set_ylabel("total energy / initial")
axes[2].set_title("total energy: viscosity and time step")
axes[2].legend()
axes[2].grid(alpha=0.3, which="both")
fig.suptitle(f"TLSPH bar (scene 'bar'), dp = W/{bar.setup.info['W'] / bar.setup.dp:.0f}, "
             f"{bar.summary['n_particles']} particles")
fig.savefig(FIG / "03_bar.png", dpi=120)
plt.show()

# %% [markdown]
# The mode that grows without viscosity is a high-frequency transverse mode concentrated at the free surfaces
# (the outermost particle row moves against the rows beneath it, see the printed profile); at full resolution it
# destroys the run (the "wave speed" printed for it is meaningless). With the default Courant number the
# artificial viscosity is therefore not optional in this scheme; it costs part of the vibration energy
# (printed above: the total energy after two periods). Without viscosity and with half the time step the
# same scheme keeps the energy to a few parts in $10^4$. With Eq. (18) uncorrected the bar does not survive ten
# steps: the terapascal surface pressure of Section 2 blows it apart.
#
# ## 6. Reference-configuration update
#
# After large deformation the reference configuration is reset to the current one (paper, start of Section 3,
# after Leroch et al. 2016):
#
# $$\mathbf{X} \leftarrow \mathbf{x},\qquad V \leftarrow J\,V,\qquad \boldsymbol\sigma\ \text{kept}.$$
#
# Neighbours, kernel gradients and correction matrices are then rebuilt from the new $\mathbf{X}$, and
# $\mathbf{F}$ is measured from the new reference ($\mathbf{F}=\mathbf{I}$ right after the update).
# **Trigger** in `refsph` (`TLSPHSolver.after_step`): an update is made after a step in which
# $\max_i\|\mathbf{E}_i\|_F > $ `ref_update_strain` (default 0.5), with $\mathbf{E} = (\mathbf{F}^T\mathbf{F}-\mathbf{I})/2$ the
# Green–Lagrange strain — zero for any rigid motion, so rotations never trigger an update.
#
# We shear a block by $\gamma$ (plus a small smooth non-affine displacement, a smooth velocity field and a
# non-uniform pre-stress, so that every particle feels a force), update, and compare. The artificial viscosity
# is off here, so the force is the stress divergence alone; for this analytic field we can also compute the
# exact continuum value $\mathbf{a} = \nabla_0\cdot\mathbf{P}/\rho_0$ (Eq. 4) by central differences.

# %%
nx_u, ny_u, dp_u = 24, 16, 1e-4
X_u = lattice([nx_u * dp_u, ny_u * dp_u], dp_u)
Lx_u, Ly_u = nx_u * dp_u, ny_u * dp_u
prm_u = TLSPHParams(h=1.5 * dp_u, beta1=0.0, beta2=0.0, eps=0.01, kernel=kernel, corrected=True,
                    ref_update_strain=0.5)
dist_u = np.minimum.reduce([X_u[:, 0], Lx_u - X_u[:, 0], X_u[:, 1], Ly_u - X_u[:, 1]]) / dp_u
interior_u = dist_u > 3.5                      # complete kernel support (2h = 3 dp) in the first reference
kx, ky = np.pi / Lx_u, np.pi / Ly_u
amp_u = 0.1 * dp_u


def mapping(X, gamma):
    """x = phi(X): simple shear gamma plus a smooth non-affine part, and its exact gradient F."""
    sx, cx, sy, cy = np.sin(kx * X[:, 0]), np.cos(kx * X[:, 0]), np.sin(ky * X[:, 1]), np.cos(ky * X[:, 1])
    x = X.copy()
    x[:, 0] += gamma * X[:, 1] + amp_u * sx * sy
    x[:, 1] += 0.005 * X[:, 1] * sx
    F = np.empty((len(X), 2, 2))
    F[:, 0, 0] = 1 + amp_u * kx * cx * sy
    F[:, 0, 1] = gamma + amp_u * ky * sx * cy
    F[:, 1, 0] = 0.005 * X[:, 1] * kx * cx
    F[:, 1, 1] = 1 + 0.005 * sx
    return x, F


def prestress(X):
    s = 100e6 * np.cos(kx * X[:, 0])
    sy = np.sin(ky * X[:, 1])
    return np.stack([np.stack([s, 0.5 * s * sy], -1), np.stack([0.5 * s * sy, -0.3 * s], -1)], 1), -0.7 * s


def sheared_state(gamma):
    st = make_state(X_u, 0.0, mat.rho0, dp_u**2)
    st.x, _ = mapping(X_u, gamma)
    st.v = np.stack([20.0 * np.sin(ky * X_u[:, 1]), -10.0 * np.sin(kx * X_u[:, 0])], 1)
    st.S, st.S_zz = prestress(X_u)
    return st


def exact_acceleration(X, gamma, e=1e-4 * dp_u):
    """a = (1/rho0) dP_aK/dX_K of the analytic field, P = J sigma F^-T, p = K (1/J - 1)."""
    def P_of(Y):
        _, F = mapping(Y, gamma)
        J = det(F)
        sigma = prestress(Y)[0] - (mat.K * (1 / J - 1))[:, None, None] * np.eye(2)
        return J[:, None, None] * sigma @ np.swapaxes(np.linalg.inv(F), 1, 2)
    a = np.zeros_like(X)
    for K in range(2):
        dX = np.zeros(2)
        dX[K] = e
        a += (P_of(X + dX)[:, :, K] - P_of(X - dX)[:, :, K]) / (2 * e)
    return a / mat.rho0


def rms(a):
    return np.sqrt(np.mean(np.sum(a * a, axis=1)))


op_u = ReferenceOperator(X_u, np.full(len(X_u), dp_u**2), prm_u.h, kernel, True)
upd_rows = []
for gamma in (0.0, 0.1, 0.3, 0.6, 1.0):
    st = sheared_state(gamma)
    out_b = {}
    a_b = tlsph_rates(st, mat, prm_u, op_u, out=out_b).v          # before the update
    st_new = reference_update(st, op_u.deformation_gradient(st.x))
    op_new = ReferenceOperator(st_new.X, st_new.V0, prm_u.h, kernel, True)
    out_a = {}
    a_a = tlsph_rates(st_new, mat, prm_u, op_new, out=out_a).v    # right after it (same x, v, stress)
    a_ex = exact_acceleration(X_u, gamma)
    upd_rows.append(dict(
        gamma=gamma, E_max=green_lagrange_norm(out_b["F"]).max(),
        vol_ratio=np.sum(out_b["J"] * st.V0) / np.sum(st_new.V0),
        F_reset=fnorm(out_a["F"] - np.eye(2)).max(),
        rho_jump=np.abs(out_a["rho"] / out_b["rho"] - 1).max(),
        l_jump=fnorm(out_a["l"] - out_b["l"])[interior_u].max() / fnorm(out_b["l"])[interior_u].max(),
        jump_all=rms(a_a - a_b) / rms(a_b),
        jump_int=rms((a_a - a_b)[interior_u]) / rms(a_ex[interior_u]),
        err_b=rms((a_b - a_ex)[interior_u]) / rms(a_ex[interior_u]),
        err_a=rms((a_a - a_ex)[interior_u]) / rms(a_ex[interior_u])))

print(f"{'gamma':>5} {'max|E|':>7} | {'sum J V / sum V_new':>19} {'max|F_new - I|':>14} {'max rho jump':>12} "
      f"{'max l jump (interior)':>21}")
for r in upd_rows:
    print(f"{r['gamma']:5.1f} {r['E_max']:7.3f} | {r['vol_ratio']:19.15f} {r['F_reset']:14.1e} {r['rho_jump']:12.1e} "
          f"{100 * r['l_jump']:20.2f}%")
    assert abs(r["vol_ratio"] - 1) < 1e-13 and r["F_reset"] < 1e-12 and r["rho_jump"] < 1e-12
print()
print(f"{'':14}momentum rate (RMS):  relative jump at the update  |  error vs exact, interior:")
print(f"{'gamma':>5} {'all particles':>30} {'interior':>10} | {'before':>10} {'after':>8}")
for r in upd_rows:
    print(f"{r['gamma']:5.1f} {100 * r['jump_all']:29.2f}% {100 * r['jump_int']:9.2f}% | "
          f"{100 * r['err_b']:9.2f}% {100 * r['err_a']:7.2f}%")

# %% [markdown]
# * $\mathbf{F}$ resets to $\mathbf{I}$ (to round-off), and $\sum_i J_iV_i$ — the current volume — is carried over
#   exactly into the new reference volumes, so the density $\rho=m/(JV)$ and hence the pressure do not jump.
#   The velocity gradient $\mathbf{l}$ (which drives the stress rate) is continuous to a fraction of a percent.
# * The stress is kept, so the stress *field* is continuous. The momentum rate is continuous only up to the
#   discretisation error: before the update, $\nabla_0\cdot\mathbf{P}$ is evaluated on kernels that are circles
#   in $\mathbf{X}$ (sheared ellipses in $\mathbf{x}$); after it, on circles in $\mathbf{x}$, with different neighbour sets.
#   The comparison with the exact value shows that the jump is just the difference of two discretisation
#   errors of a few percent each. It grows with the shear accumulated since the last update (the sheared
#   particle arrangement resolves the field worse) and is largest near the free surfaces — a reason not to
#   wait too long with an update, and not to update too often either (every update also costs an operator
#   rebuild, Section 8).
#
# ## 7. Tensile instability: absent in TLSPH
#
# Chapter 2 showed the tensile instability of Eulerian SPH: in tension, a perturbation that brings two
# particles closer can increase their attraction, so particles clump in pairs and strings
# (`figures/02_tensile_instability.png`: in scene `tension`, ESPH without artificial pressure clumps, its minimum
# pair distance falls steadily). In TLSPH the pairs and kernel gradients are those of the reference
# configuration; moving two particles closer does not move them along the kernel, so there is no such feedback.
# Scene `tension`: a 10 × 10 mm block, lattice jittered by 1 %, in free expansion (edge velocity 300 m/s) that
# puts it in strong tension, with the paper's machining viscosity $\beta_1=\beta_2=0.5$, for
# $24\,\mathrm{side}/c_L \approx 40$ µs — here with TLSPH.

# %%
t0 = time.perf_counter()
ten = run("tension", "tlsph", dim=2, quick=QUICK, progress=False)
mt = ten.summary["metrics"]
print(f"TLSPH, scene 'tension' (v_edge {ten.setup.info['v_edge']:.0f} m/s, beta1 = {ten.setup.numerics.beta1}, "
      f"t_end = {1e6 * ten.setup.t_end:.1f} us), dp = {1e3 * ten.setup.dp} mm, {ten.summary['n_particles']} particles, "
      f"{time.perf_counter() - t0:.1f} s")
print(f"  min pair distance / dp {mt['min_pair_distance_over_dp']:.3f} (final {mt['final_min_pair_distance_over_dp']:.3f}), "
      f"min pressure {mt['min_pressure_Pa'] / 1e9:.1f} GPa, {ten.summary['n_steps']} steps, "
      f"reference updates {ten.summary['diagnostics']['reference_updates']}")
assert mt["min_pair_distance_over_dp"] > 0.8          # ESPH without artificial pressure: 0.78 (quick), 0.47 (full)

# Is a drop of the minimum distance clumping? Compare every nearest-neighbour pair's current separation x_ij
# with the one the deformation gradient predicts, (F_i + F_j)/2 X_ij.
sv = ten.state
op_tv = ReferenceOperator(sv.X, sv.V0, ten.setup.h, kernel, True)
F_tv = op_tv.deformation_gradient(sv.x)
nn = np.linalg.norm(sv.X[op_tv.I] - sv.X[op_tv.J], axis=1) < 1.05 * ten.setup.dp     # nearest neighbours
Ii, Jj = op_tv.I[nn], op_tv.J[nn]
X_nn = sv.X[Ii] - sv.X[Jj]
x_nn = sv.x[Ii] - sv.x[Jj]
x_pred = np.einsum("pab,pb->pa", 0.5 * (F_tv[Ii] + F_tv[Jj]), X_nn)
hg_err = np.linalg.norm(x_nn - x_pred, axis=1) / np.linalg.norm(X_nn, axis=1)
d_now = np.linalg.norm(x_nn, axis=1) / ten.setup.dp
d_pred = np.linalg.norm(x_pred, axis=1) / ten.setup.dp
print(f"final state, nearest-neighbour pairs: min distance / dp {d_now.min():.3f}, as predicted by F "
      f"{d_pred.min():.3f};  |x_ij - F X_ij| / |X_ij|: median {np.median(hg_err):.3f}, max {hg_err.max():.3f}")
assert d_pred.min() > 0.95

# %%
fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
mh = mt["min_pair_distance_history"]
ax.plot(mh[:, 0] * 1e6, mh[:, 1], "C1", label=f"TLSPH, scene 'tension' (min {mh[:, 1].min():.3f})")
ax.plot([1e6 * sv.t], [d_pred.min()], "C0D", ms=7,
        label=f"at the end, nearest neighbours as predicted by F: {d_pred.min():.3f}")
ax.axhline(1.0, color="0.6", ls=":", lw=1)
ax.set_ylim(0.5, 1.05)
ax.set_xlabel("t [us]")
ax.set_ylabel("min pair distance / dp")
ax.set_title(f"TLSPH, scene 'tension' (v_edge 300 m/s, beta = 0.5, dp = {1e3 * ten.setup.dp} mm)\n"
             "no tensile clumping (ESPH: chapter 2); the slow drift is a zero-energy mode", fontsize=10)
ax.legend(fontsize=8, loc="lower left")
ax.grid(alpha=0.3)
fig.savefig(FIG / "03_tension.png", dpi=120)
plt.show()

# %% [markdown]
# The minimum distance oscillates with the breathing of the block below its jittered initial value (quick mode,
# $\Delta p = 0.5$ mm: minimum $0.935\,\Delta p$); at full resolution ($\Delta p = 0.25$ mm) it also drifts slowly
# down, to $0.855\,\Delta p$ — but that is *not* clumping by the tensile instability: the deformation gradient
# predicts at least $0.97\,\Delta p$ for every nearest-neighbour pair at the end (quick $0.975$, full $0.974$), the
# strain field is smooth. The close pairs are pairs whose relative displacement $\mathbf{F}$ does not see,
# $\mathbf{x}_{ij}\neq\mathbf{F}\mathbf{X}_{ij}$ — a zero-energy (hourglass) mode, the subject of Section 8(c). The
# last printed line measures it: $|\mathbf{x}_{ij}-\mathbf{F}\mathbf{X}_{ij}|/|\mathbf{X}_{ij}|$ has median $0.008$ and
# maximum $0.046$ in quick mode, $0.027$ and $0.137$ at full resolution.
#
# %% [markdown]
# ## 8. Where TLSPH fails
#
# **(a) Large distortion without reference updates.** The neighbours are those of $\mathbf{X}$ for ever.
# Under a large shear, particles that were neighbours stay coupled however far apart they move, and
# particles that come close never interact. Material separation (a chip leaving the workpiece) is
# impossible: the SPH sums keep coupling the two sides. Updates fix the neighbourhoods, but each update is a
# new reference configuration in which the errors of Section 6 are made again.

# %%
gamma_big = 3.0
x_big = X_u.copy()
x_big[:, 0] += gamma_big * X_u[:, 1]
d_cur = np.linalg.norm(x_big[op_u.I] - x_big[op_u.J], axis=1)
I_cur, J_cur = find_pairs(x_big, 2 * prm_u.h)
ref_pairs = set(zip(op_u.I.tolist(), op_u.J.tolist()))
missing = sum((i, j) not in ref_pairs for i, j in zip(I_cur.tolist(), J_cur.tolist()))
print(f"simple shear gamma = {gamma_big}: max current distance of reference neighbours = "
      f"{d_cur.max() / (2 * prm_u.h):.1f} x support radius 2h;")
print(f"  {missing} of {len(I_cur)} pairs that are within 2h now do not interact "
      f"(max |E| = {green_lagrange_norm(op_u.deformation_gradient(x_big)).max():.1f}).")

# %% [markdown]
# **(b) The cost of updates.** An update rebuilds the neighbour list, the kernel gradients, the correction
# matrices and the sparse operator. Relative to one rate evaluation (which is two sparse products):

# %%
bar_state = bar.state
op_bar = ReferenceOperator(bar_state.X, bar_state.V0, bar.setup.h, kernel, True)
prm_bar = TLSPHParams(h=bar.setup.h, beta1=1.5, beta2=1.5, eps=0.01, kernel=kernel, corrected=True,
                      ref_update_strain=0.5)
reps = 5


def timeit(f):
    f()
    t = time.perf_counter()
    for _ in range(reps):
        f()
    return (time.perf_counter() - t) / reps


t_build = timeit(lambda: ReferenceOperator(bar_state.X, bar_state.V0, bar.setup.h, kernel, True))
t_rates = timeit(lambda: tlsph_rates(bar_state, mat, prm_bar, op_bar))
print(f"bar, {bar_state.n} particles: operator rebuild {1e3 * t_build:.2f} ms, one rate evaluation "
      f"{1e3 * t_rates:.2f} ms -> an update costs ~{t_build / t_rates:.0f} rate evaluations "
      f"(~{t_build / (2 * t_rates):.0f} time steps)")

# %% [markdown]
# In a cutting simulation with continuous large plastic flow the trigger fires often, and each update also
# restarts the accumulation of discretisation error (Section 6).
#
# **(c) Hourglass (zero-energy) modes.** TLSPH is a collocation scheme: $\mathbf{F}$ and the stress live at the
# particles, and the gradient at $i$ is built from the differences $\mathbf{x}_j-\mathbf{x}_i$ weighted with an odd
# function of $\mathbf{X}_{ij}$. On a regular lattice, any displacement pattern that is *even* about every
# particle ($\mathbf{u}_{i+k} = \mathbf{u}_{i-k}$ for every lattice offset $k$) — every second row moving up, or a
# checkerboard — has zero gradient in the interior: $\mathbf{F}=\mathbf{I}$, no stress, no restoring force. Such
# modes can grow unopposed and dominate the solution (G. C. Ganzenmüller, "An hourglass control algorithm for
# Lagrangian Smooth Particle Hydrodynamics", Comput. Methods Appl. Mech. Engrg. 286 (2015) 87–106,
# doi:10.1016/j.cma.2014.12.005). The paper uses no hourglass control. Scene `tension` (Section 7) shows such
# a mode in a real run: neighbour pairs closer than $\mathbf{F}$ predicts, opposed only by the (weak) viscosity.

# %%
ij_fs = np.round(X_fs / dp_fs - 0.5).astype(int)
amp_hg = 0.2 * dp_fs
modes = {"every second row up / down": np.stack([0 * X_fs[:, 0], amp_hg * (-1.0) ** ij_fs[:, 1]], 1),
         "checkerboard, along x": np.stack([amp_hg * (-1.0) ** (ij_fs[:, 0] + ij_fs[:, 1]), 0 * X_fs[:, 0]], 1)}
e_modes = {}
for name, u in modes.items():
    e_modes[name] = fnorm(op_cor.deformation_gradient(X_fs + u) - I_n)
    print(f"{name:28}: amplitude 0.2 dp -> max |F - I| interior {e_modes[name][interior].max():.1e}, "
          f"surface {e_modes[name][surface].max():.2f}")
    assert e_modes[name][interior].max() < 1e-12

# %%
fig, axes = plt.subplots(1, 2, figsize=(13, 5), constrained_layout=True)
for ax, (name, u) in zip(axes, modes.items()):
    x_show = X_fs + u
    sc = ax.scatter(x_show[:, 0] * 1e3, x_show[:, 1] * 1e3, c=np.clip(e_modes[name], 1e-16, None), s=9,
                    cmap="viridis", norm=plt.matplotlib.colors.LogNorm(1e-16, 1.0))
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(f"{name}, amplitude 0.2 dp\ninterior max |F - I| = {e_modes[name][interior].max():.0e}")
fig.colorbar(sc, ax=axes, label="|F - I| (corrected TLSPH)")
fig.suptitle("Zero-energy (hourglass) modes: the particles move, but F = I away from the surface")
fig.savefig(FIG / "03_hourglass.png", dpi=120)
plt.show()

# %% [markdown]
# Both patterns move every particle by 0.2 dp, yet the interior sees no strain at all: no stress, no restoring
# force. Ganzenmüller (2015) adds a penalty force that compares each pair's actual separation with the one
# predicted by $\mathbf{F}_i$, which removes these modes; the paper and `refsph` rely on the artificial viscosity.
#
# **(d) A singular correction matrix.** $\mathbf{M}_i$ must be invertible, i.e. particle $i$ needs neighbours that
# span all directions. A particle with too few neighbours — a thin filament, a particle torn off with one
# neighbour left, a row of particles one layer thick — has a singular $\mathbf{M}_i$, and $\mathbf{L}_i=\mathbf{M}_i^{-T}$
# does not exist:

# %%
X_line = np.stack([np.arange(6) * dp_fs, np.zeros(6)], 1)            # one layer of particles
with np.errstate(divide="ignore", invalid="ignore"):
    op_line = ReferenceOperator(X_line, np.full(6, dp_fs**2), h_fs, kernel, True)
print("det M_i for a row of 6 particles:", det(op_line.M))
print("degenerate particles (pseudo-inverse used):", op_line.degenerate)
print("finite correction matrices:", np.isfinite(op_line.L).all(axis=(1, 2)))
print("det F of the row at rest:", det(op_line.deformation_gradient(X_line)))

# %% [markdown]
# Production codes guard against this (fall back to the uncorrected gradient or a pseudo-inverse when
# $\det\mathbf{M}$ is small). `refsph` uses the Moore–Penrose pseudo-inverse for such particles (the correction
# restricted to the directions the neighbours span; `op.degenerate` lists them), so the operator stays finite. But
# $\mathbf{F}$ of such a particle is still singular in the missing direction ($J = 0$), so a run that depends on it
# stops with a non-finite-state error; its scenes never produce such particles between reference updates.
#
# ## Summary
#
# * TLSPH evaluates every kernel in the reference configuration: fixed pairs, one sparse operator, and
#   Eqs. (17)–(19) become matrix products. Momentum is conserved to round-off.
# * Eq. (18) as printed is wrong at free surfaces ($J\approx0.1$ at a corner); the Bonet–Lok correction makes
#   $\mathbf{F}$ exact for every affine motion, including rest.
# * The first Piola–Kirchhoff stress in Eq. (17) is $J\boldsymbol\sigma\mathbf{F}^{-T}$; the printed
#   $J\mathbf{F}^{-1}\boldsymbol\sigma$ gives wrong forces as soon as the body rotates.
# * The Jaumann rate with the TLSPH velocity gradient co-rotates the stress exactly under rigid rotation.
# * TLSPH has no tensile instability, but needs reference updates for large distortion (cost, jumps),
#   cannot separate material between updates, has zero-energy modes that need damping, and needs enough
#   neighbours for the correction.

# %%
print(f"chapter wall time: {time.perf_counter() - T_START:.1f} s (quick mode: {QUICK})")
