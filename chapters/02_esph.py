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
# # Chapter 2 — Eulerian SPH (ESPH) for an elastic solid
#
# SPH was invented for fluids. To model a metal we keep the fluid's machinery — density, pressure, pair forces
# between neighbouring particles — and add a deviatoric stress that remembers how the material was sheared.
# In *Eulerian* SPH (Islam, Bansal & Peng, Section 2.1) every kernel is evaluated at the **current**
# particle positions $\mathbf x_i(t)$: who is whose neighbour, the distances and the kernel gradients all change
# every step. That makes ESPH simple and lets the material separate and flow freely — and, as this chapter
# shows, it is also the root of its two weaknesses: soft free surfaces and the **tensile instability**.
#
# Plan: the equations, a plain pair-by-pair loop that the package is checked against, two small tests of what
# the discrete equations get right and wrong, two details every solid code must get right (the out-of-plane
# stress and the rotation of stress), then two dynamic tests: a vibrating bar and a block pulled apart.
#
# Notation: $\mathbf x_{ij} = \mathbf x_i - \mathbf x_j$, $\mathbf v_{ij} = \mathbf v_i - \mathbf v_j$,
# $r = \lvert\mathbf x_{ij}\rvert$, $V_j = m_j/\rho_j$, $\nabla_i W_{ij} = \frac{dW}{dr}\frac{\mathbf x_{ij}}{r}$
# (Chapter 1). The velocity gradient is $l_{ab} = \partial v_a/\partial x_b$. 2D is **plane strain**; masses and
# volumes are per metre of thickness.

# %%
import matplotlib.pyplot as plt
import numpy as np
from refsph.esph import ESPHParams, esph_rates, velocity_gradient
from refsph.kernels import get_kernel
from refsph.material import jaumann_deviatoric_rate, von_mises
from refsph.neighbours import PairSum, find_pairs
from refsph.teaching.plots import colorbar, particle_field
from refsph.scenes import aisi4340_material, lattice
from refsph.simulate import run
from refsph.state import State
from refsph.teaching.notebook import chapter
ch = chapter("02_esph")

# %% [markdown]
# ## The equations
#
# | Eq. | ESPH |
# |---|---|
# | (10) continuity | $\dfrac{d\rho_i}{dt} = \sum_j m_j\,\mathbf v_{ij}\cdot\nabla_i W_{ij}$ |
# | (23) velocity gradient | $\mathbf l_i = -\sum_j V_j\,\mathbf v_{ij}\otimes\nabla_i W_{ij}$ |
# | (24) pressure, stress | $p_i = K(\rho_i/\rho_0 - 1)$, $\quad\boldsymbol\sigma_i = \mathbf s_i - p_i\mathbf I$ |
# | (11) momentum | $\dfrac{d\mathbf v_i}{dt} = \sum_j m_j\left(\dfrac{\boldsymbol\sigma_i}{\rho_i^2} + \dfrac{\boldsymbol\sigma_j}{\rho_j^2} - \pi_{ij}\mathbf I - p^a_{ij}\mathbf I\right)\nabla_i W_{ij}$ |
# | (12)–(13) artificial viscosity | $\pi_{ij} = \dfrac{-\beta_1 C\mu_{ij} + \beta_2\mu_{ij}^2}{\bar\rho_{ij}}$ if $\mathbf v_{ij}\cdot\mathbf x_{ij}\le 0$, else 0; $\quad\mu_{ij} = \dfrac{h\,\mathbf v_{ij}\cdot\mathbf x_{ij}}{r^2 + \epsilon h^2}$ |
# | (14) artificial pressure | $p^a_{ij} = \gamma\left(\dfrac{\lvert p_i\rvert}{\rho_i^2} + \dfrac{\lvert p_j\rvert}{\rho_j^2}\right)\left[\dfrac{W(r)}{W(\Delta p)}\right]^n$; zero if $p_i>0$ and $p_j>0$ |
# | (20)–(22) Jaumann rate | $\dot{\mathbf s} = 2G\big(\dot{\boldsymbol\epsilon} - \tfrac13\mathrm{tr}(\dot{\boldsymbol\epsilon})\mathbf I\big) + \boldsymbol\omega\mathbf s - \mathbf s\boldsymbol\omega$, $\quad\dot{\boldsymbol\epsilon} = \tfrac12(\mathbf l + \mathbf l^T)$, $\boldsymbol\omega = \tfrac12(\mathbf l - \mathbf l^T)$ |

# %% [markdown]
# **In plain words.** Density changes when neighbours approach or recede (10). The velocity gradient is a
# weighted sum of velocity differences (23). Pressure follows from density (24). Each pair pushes or pulls on
# its two particles with the average of their stresses (11). The artificial viscosity (12) damps pairs that
# approach each other (shocks, noise). The artificial pressure (14) is a short-range *repulsion* that acts only
# where a particle is in tension, against the clumping we meet at the end. The deviatoric stress grows with
# the strain rate and turns with the material (20).
#
# Details of the printed text: Eq. (23) has a dyadic product (the paper prints a dot). The paper writes
# $\mathbf s\boldsymbol\omega - \boldsymbol\omega\mathbf s$, the same law if $l_{ab} = \partial v_b/\partial x_a$;
# with Eq. (23)'s $l_{ab} = \partial v_a/\partial x_b$ it is the order above (the sign matters: checked below).
# $C = \sqrt{E/\rho_0}$, $n = 4$, $\epsilon = 0.01$.
#
# ### The plain loop
#
# Everything in one function, one particle $i$ and one neighbour $j$ at a time: slow, and meant to be read next
# to the table.

# %%
def W_cubic(r, h):
    """Cubic B-spline, Eq. (9), 2D."""
    q, alpha = r / h, 10.0 / (7.0 * np.pi * h * h)
    if q <= 1.0:
        return alpha * (1.0 - 1.5 * q * q + 0.75 * q**3)
    return alpha * 0.25 * (2.0 - q) ** 3 if q <= 2.0 else 0.0


def dW_cubic(r, h):
    """dW/dr of Eq. (9), 2D."""
    q, alpha = r / h, 10.0 / (7.0 * np.pi * h * h)
    if q <= 1.0:
        return alpha / h * (-3.0 * q + 2.25 * q * q)
    return alpha / h * (-0.75 * (2.0 - q) ** 2) if q <= 2.0 else 0.0


def plain_esph_rates(x, v, m, rho, S, mat, h, dp, beta1, beta2, gamma, n_ap=4.0, eps=0.01):
    """ESPH rates in 2D plane strain by a double loop over particles and neighbours.

    Returns d rho/dt (Eq. 10), velocity gradient l (Eq. 23), dv/dt (Eq. 11 with Eqs. 12-14),
    dS/dt and dS_zz/dt (Eq. 20 with plane strain).
    """
    n = len(x)
    K, G, rho0 = mat.K, mat.G, mat.rho0
    C = np.sqrt(mat.E / rho0)                                  # sound speed in Eq. (12)
    I2 = np.eye(2)
    p = [K * (rho[i] / rho0 - 1.0) for i in range(n)]          # Eq. (24)
    sigma = [S[i] - p[i] * I2 for i in range(n)]               # sigma = s - p I (in-plane block)
    W_dp = W_cubic(dp, h)

    drho, l, dv = np.zeros(n), np.zeros((n, 2, 2)), np.zeros((n, 2))
    for i in range(n):
        for j in range(n):                # neighbours: every j != i within 2h (brute force, the plainest search)
            x_ij = x[i] - x[j]
            r = np.hypot(x_ij[0], x_ij[1])
            if j == i or r >= 2.0 * h:
                continue
            v_ij = v[i] - v[j]
            gradW = dW_cubic(r, h) * x_ij / r                  # grad_i W_ij

            drho[i] += m[j] * (v_ij @ gradW)                   # Eq. (10)
            l[i] -= (m[j] / rho[j]) * np.outer(v_ij, gradW)    # Eq. (23)

            vx = v_ij @ x_ij                                   # Eqs. (12)-(13)
            if vx <= 0.0:
                mu = h * vx / (r * r + eps * h * h)
                pi_ij = (-beta1 * C * mu + beta2 * mu * mu) / (0.5 * (rho[i] + rho[j]))
            else:
                pi_ij = 0.0

            if gamma > 0.0 and not (p[i] > 0.0 and p[j] > 0.0):   # Eq. (14)
                pa_ij = gamma * (abs(p[i]) / rho[i]**2 + abs(p[j]) / rho[j]**2) * (W_cubic(r, h) / W_dp) ** n_ap
            else:
                pa_ij = 0.0

            T = sigma[i] / rho[i]**2 + sigma[j] / rho[j]**2 - (pi_ij + pa_ij) * I2
            dv[i] += m[j] * (T @ gradW)                        # Eq. (11)

    dS, dS_zz = np.zeros((n, 2, 2)), np.zeros(n)
    for i in range(n):                                         # Eqs. (20)-(22), plane strain: l_zz = 0
        eps_dot = 0.5 * (l[i] + l[i].T)
        omega = 0.5 * (l[i] - l[i].T)
        tr = eps_dot[0, 0] + eps_dot[1, 1]                     # + eps_dot_zz = 0
        dS[i] = 2.0 * G * (eps_dot - tr / 3.0 * I2) + omega @ S[i] - S[i] @ omega
        dS_zz[i] = 2.0 * G * (0.0 - tr / 3.0)
    return drho, l, dv, dS, dS_zz


# %% [markdown]
# ### The package, checked against the loop
#
# A test state that exercises every term: a $16\times14$ block jittered by up to 15 % of the spacing, random
# masses, densities on both sides of $\rho_0$ (some particles in compression, some in tension, so the artificial
# pressure acts), a random deviatoric stress, and a velocity of rotation, stretch and noise (so some pairs
# approach and the artificial viscosity acts). The package `refsph.esph.esph_rates` visits each pair once and
# adds the pair term to both particles.

# %%
mat = aisi4340_material()          # AISI 4340, Table 3
cubic = get_kernel("cubic")


def random_block(nx=16, ny=14, dp=1e-4, seed=0):
    rng = np.random.default_rng(seed)
    x = lattice([nx * dp, ny * dp], dp) + 0.15 * dp * rng.uniform(-1, 1, (nx * ny, 2))
    n = len(x)
    rho = mat.rho0 * (1.0 + 0.004 * rng.uniform(-1, 1, n))          # p = K (rho/rho0 - 1): about +-0.7 GPa
    m = mat.rho0 * dp * dp * (1.0 + 0.05 * rng.uniform(-1, 1, n))
    A = np.array([[200.0, -3000.0], [3000.0, -100.0]])               # [1/s]: spin, stretch
    v = (x - x.mean(axis=0)) @ A.T + 5.0 * rng.normal(size=(n, 2))   # [m/s]
    S = rng.normal(scale=2e8, size=(n, 2, 2))
    S = 0.5 * (S + np.swapaxes(S, 1, 2))                              # symmetric, ~200 MPa
    st = State(x=x, v=v, m=m, rho=rho, S=S, S_zz=-(S[:, 0, 0] + S[:, 1, 1]), X=x.copy(), V0=m / rho)
    st.check()
    return st


dp_r = 1e-4
st_r = random_block(dp=dp_r)
prm_r = ESPHParams(h=1.5 * dp_r, dp=dp_r, beta1=1.5, beta2=1.5, gamma=0.3, n_ap=4.0, eps=0.01, kernel=cubic)
plain = plain_esph_rates(st_r.x, st_r.v, st_r.m, st_r.rho, st_r.S, mat, prm_r.h, dp_r, prm_r.beta1, prm_r.beta2,
                         prm_r.gamma)
I_r, J_r = find_pairs(st_r.x, 2.0 * prm_r.h)
rates = esph_rates(st_r, mat, prm_r, I_r, J_r)
for name, a, b in [("drho/dt", plain[0], rates.rho), ("dv/dt", plain[2], rates.v), ("dS/dt", plain[3], rates.S),
                   ("dS_zz/dt", plain[4], rates.S_zz)]:
    scale = np.abs(a).max()
    print(f"{name:9s} max |plain - package| / max |plain| = {np.abs(a - b).max() / scale:.1e}")
    assert np.allclose(a, b, rtol=1e-10, atol=1e-10 * scale), name

# %% [markdown]
# **Momentum is conserved exactly.** The bracket in Eq. (11) is symmetric in $i \leftrightarrow j$ and
# $\nabla_j W_{ji} = -\nabla_i W_{ij}$, so the momentum $j$ gives to $i$ is exactly minus the momentum $i$ gives to
# $j$. Whatever the positions, stresses and parameters, the total force is zero to round-off:

# %%
ma = st_r.m[:, None] * rates.v
mom_err = np.abs(ma.sum(axis=0)).max() / np.abs(ma).sum()
print(f"|sum_i m_i dv_i/dt| / sum_i |m_i dv_i/dt| = {mom_err:.1e}")
assert mom_err < 1e-12

# %% [markdown]
# ## Patch test: the velocity gradient at a free surface
#
# Take a linear velocity field $\mathbf v = \mathbf A\mathbf x$. Then $\mathbf v_{ij} = \mathbf A\mathbf x_{ij}$ and
# Eq. (23) gives
#
# $$ \mathbf l_i = \mathbf A\,\mathbf M_i,\qquad \mathbf M_i = -\sum_j V_j\,\mathbf x_{ij}\otimes\nabla_i W_{ij}. $$
#
# So $\mathbf l_i = \mathbf A$ exactly when the "moment matrix" $\mathbf M_i$ is the identity. With a full kernel
# support it nearly is. At a free surface part of the support is empty (Chapter 1), $\mathbf M_i$ is far from
# $\mathbf I$, and ESPH, as in the paper, applies no correction. We compute $\mathbf l_i$ on a square block with the
# package's `velocity_gradient`, and $\mathbf M_i$ with the same function, $\mathbf v$ replaced by $\mathbf x$.

# %%
dp_l, n_side = 1e-4, 20
h_l = 1.5 * dp_l
x_l = lattice([n_side * dp_l] * 2, dp_l)
V_l = np.full(len(x_l), dp_l**2)
A_l = np.array([[1.0, -2.0], [0.5, 3.0]]) * 1e3              # [1/s]
v_l = x_l @ A_l.T
I_l, J_l = find_pairs(x_l, 2.0 * h_l)
dx_l = x_l[I_l] - x_l[J_l]
gW_l = cubic.dw_dr_over_r(np.linalg.norm(dx_l, axis=1), h_l, 2)[:, None] * dx_l
pairs_l = PairSum(I_l, J_l, len(x_l))
l_l = velocity_gradient(pairs_l, V_l, v_l[I_l] - v_l[J_l], gW_l)
M_l = velocity_gradient(pairs_l, V_l, dx_l, gW_l)             # the same sum with v replaced by x
err_l = np.linalg.norm(l_l - A_l, axis=(1, 2)) / np.linalg.norm(A_l)
interior = np.minimum(x_l, n_side * dp_l - x_l).min(axis=1) > 2.0 * h_l     # full kernel support
k_face = np.argmin(np.hypot(x_l[:, 0] - 0.5 * dp_l, x_l[:, 1] - (n_side // 2 + 0.5) * dp_l))
print(f"relative error |l - A| / |A|: interior at most {err_l[interior].max():.1e}, "
      f"surface layers up to {err_l[~interior].max():.2f}")
print(f"M in the outermost layer of the face x = 0: {np.round(M_l[k_face], 2).tolist()}  (should be I)")
assert np.allclose(l_l, A_l @ M_l, rtol=1e-12, atol=1e-12 * np.abs(A_l).max())   # l = A M, everywhere
assert err_l[interior].max() < 1e-2                                               # l ~ A, interior only
assert err_l[~interior].max() > 0.3                                               # ... not at the surface

fig, ax = plt.subplots(figsize=(6, 4.6))
sc = particle_field(ax, x_l, np.log10(err_l), dp_l, vmin=-3, vmax=0,
                    xlim=(-dp_l * 1e3, n_side * dp_l * 1e3), ylim=(-dp_l * 1e3, n_side * dp_l * 1e3))
colorbar(fig, sc, ax, "log10 of relative error of l [-]")
ax.set_xlabel("x [mm]")
ax.set_ylabel("y [mm]")
ax.set_title("ESPH velocity gradient of v = A x")
ch.show(fig, "02_velocity_gradient_patch.png", caption="The error (log10) of the ESPH velocity gradient of the linear "
                                                       "field v = A x on a square block: small inside, tens of per "
                                                       "cent within 2h of the free surface, where the kernel's "
                                                       "support is cut off.")

# %% [markdown]
# Inside, the error is the small lattice-sum error of the cubic spline. Within $2h$ of the surface it grows to
# tens of per cent: a surface particle sees about half a kernel, so Eq. (23) underestimates the derivatives
# normal to the surface. **The surface of an ESPH body is softer than the material**; the vibrating bar below feels it.
# The cure is in the formula: $\mathbf l_i \mathbf M_i^{-1} = \mathbf A$ wherever $\mathbf M_i$ is invertible
# (Randles & Libersky 1996; Bonet & Lok 1999). TLSPH (Chapter 3) does it by default; in ESPH it is the option
# `esph_correction` (the paper's Eq. (23) is the default).

# %%
l_corr = l_l @ np.linalg.inv(M_l)
print(f"corrected: |l M^-1 - A| / |A| at most {np.abs(l_corr - A_l).max() / np.abs(A_l).max():.1e}, everywhere")
assert np.allclose(l_corr, A_l, rtol=0, atol=1e-9 * np.abs(A_l).max())

# %% [markdown]
# A rigid rotation is a linear field too ($\mathbf A$ antisymmetric). Uncorrected, the surface layers read it as a
# strain rate and build stress: a free disc set spinning (`refsph run spinning_disc`) brakes itself. Corrected, it
# spins on. A tenth of a turn at a rim speed of 1 % of $c_L$:

# %%
for corr in (False, True):
    m_sd = run("spinning_disc", "esph", quick=True, progress=False, options=dict(speed=0.01, turns=0.1),
               numerics=dict(esph_correction=corr)).summary["metrics"]
    print(f"esph_correction={corr!s:5s}: L/L0 = {m_sd['angular_momentum_ratio']:.4f}, largest stress "
          f"{m_sd['max_stress_over_1pct']:.2e} x (E 1%)  (the centrifugal stress: "
          f"{m_sd['centrifugal_stress_over_1pct']:.1e})")

# %% [markdown]
# ## Plane strain: why $s_{zz}$ must be carried
#
# In plane strain $\dot\epsilon_{zz} = 0$, but the out-of-plane *stress* is not zero. Eq. (20) for the $zz$
# component gives $\dot s_{zz} = -\tfrac23 G\,\mathrm{tr}\,\dot{\boldsymbol\epsilon}$. The 3D deviator is
# traceless, so the in-plane block alone is not: $s_{xx}+s_{yy} = -s_{zz}$. A code that keeps only the $2\times2$
# block gets the von Mises stress $\sqrt{\tfrac32\,\mathbf s:\mathbf s}$ wrong (so the yield criterion of Chapter 4
# is wrong), and the out-of-plane stress $\sigma_{zz}$ too.
#
# Test: a uniaxial plane-strain stretch $\epsilon_{xx} = 10^{-3}$, whose exact answer is
# $\sigma_{zz} = (K-\tfrac23G)\epsilon$ and von Mises $= 2G\epsilon$.

# %%
e_xx = 1e-3
l_u = np.array([[[e_xx, 0.0], [0.0, 0.0]]])                  # rate 1/s for 1 s: strain 1e-3, no spin
dS_u, dSzz_u = jaumann_deviatoric_rate(np.zeros((1, 2, 2)), np.zeros(1), l_u, mat.G)
p_u = -mat.K * e_xx                                          # Eq. (24), linearised
exact = {"sigma_zz": (mat.K - 2.0 * mat.G / 3.0) * e_xx, "von Mises": 2 * mat.G * e_xx}
with_szz = {"sigma_zz": dSzz_u[0] - p_u, "von Mises": von_mises(dS_u, dSzz_u)[0]}
without = {"sigma_zz": -p_u, "von Mises": von_mises(dS_u, np.zeros(1))[0]}
for key in exact:
    print(f"{key:9s}: with s_zz {with_szz[key] / 1e6:6.1f} MPa, s_zz dropped {without[key] / 1e6:6.1f} MPa, "
          f"exact {exact[key] / 1e6:6.1f} MPa")
    assert abs(with_szz[key] - exact[key]) < 1e-9 * abs(exact[key])
    assert abs(without[key] - exact[key]) > 0.05 * abs(exact[key])

# %% [markdown]
# Under pure in-plane shear ($\mathrm{tr}\,\dot{\boldsymbol\epsilon} = 0$) $s_{zz}$ stays zero and nothing goes
# wrong, which is why the mistake is easy to miss.
#
# ## The Jaumann rate turns the stress with the body
#
# Spin a pre-stressed particle rigidly: $\mathbf l = \boldsymbol\omega = \begin{pmatrix}0&-w\\ w&0\end{pmatrix}$,
# no strain rate. The stress must turn with it, $\mathbf s(t) = \mathbf R(t)\,\mathbf s_0\,\mathbf R(t)^T$ with
# $\mathbf R$ the rotation by $wt$. We integrate Eq. (20) (midpoint rule) once with the sign of `refsph`
# ($\boldsymbol\omega\mathbf s - \mathbf s\boldsymbol\omega$) and once with the opposite sign, and compare with the
# exact rotation after an eighth and after a quarter of a turn.

# %%
w = 1.0e3                                                    # spin [rad/s]
S0, Szz0 = np.array([[[300e6, 120e6], [120e6, -50e6]]]), np.array([-250e6])
l_rot = np.array([[[0.0, -w], [w, 0.0]]])
n_rot = 400
dt_rot = 0.5 * np.pi / w / n_rot


def R(a):
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


rot_err = {}
for sign, name in [(+1, "omega s - s omega (refsph)"), (-1, "s omega - omega s")]:
    S_t = S0.copy()
    for k in range(1, n_rot + 1):
        k1 = sign * jaumann_deviatoric_rate(S_t, Szz0, l_rot, mat.G)[0]
        S_t = S_t + dt_rot * sign * jaumann_deviatoric_rate(S_t + 0.5 * dt_rot * k1, Szz0, l_rot, mat.G)[0]
        if k in (n_rot // 2, n_rot):
            a = k * dt_rot * w
            rot_err[name, k] = np.abs(S_t[0] - R(a) @ S0[0] @ R(a).T).max() / np.abs(S0).max()
    print(f"{name:28s}: error after 1/8 turn {rot_err[name, n_rot // 2]:.1e}, after 1/4 turn {rot_err[name, n_rot]:.1e}")
assert rot_err["omega s - s omega (refsph)", n_rot // 2] < 1e-4 and rot_err["omega s - s omega (refsph)", n_rot] < 1e-4
assert rot_err["s omega - omega s", n_rot // 2] > 0.1

# %% [markdown]
# The wrong sign turns the stress the *other* way: after an eighth of a turn it is far off — yet after a quarter
# turn it agrees again, because a symmetric tensor turned by $+90°$ and by $-90°$ is the same tensor. A rotation
# test at multiples of $90°$ cannot see this sign error; test at an odd angle.
#
# ## A vibrating bar: the wave speed
#
# Scene `bar`: a free–free AISI 4340 bar, $L\times W = 20\times2$ mm, started in its first axial mode
# $v_x = v_0\cos(\pi X/L)$. It oscillates with period $T = 2L/c$, where the plane-strain bar speed is
# $c = \sqrt{E/((1-\nu^2)\rho_0)}$; the scene measures $c$ from the zero crossings of the modal amplitude. The
# artificial pressure is off ($\gamma = 0$): it is a remedy for the tensile instability, not part of the material.

# %%
W_bar, L_bar = 2e-3, 20e-3
c_th = mat.c_bar(2)
T_th = 2 * L_bar / c_th
bar = run("bar", "esph", dim=2, quick=ch.quick, numerics={"gamma": 0.0}, progress=False)
m = bar.summary["metrics"]
print(f"dp = W/{W_bar / bar.setup.dp:.0f}: c = {m['wave_speed_m_s']:.0f} m/s against {c_th:.0f} m/s in theory "
      f"({100 * m['wave_speed_rel_error']:+.1f} %); energy left after two periods {m['energy_final_over_initial']:.2f}; "
      f"momentum drift {m['momentum_drift_rel']:.0e}")
assert m["wave_speed_rel_error"] < 0 and m["momentum_drift_rel"] < 1e-10

# %% [markdown]
# The bar is **too slow**. Its stiffness is carried by every layer across the width, but within $2h$ of
# its sides Eqs. (10) and (23) see a truncated kernel (the patch test above) and build up too little stress: the bar
# is narrower in stiffness than in mass. Some energy is also lost to the artificial viscosity. The affected
# layers are about $2h$ thick, so the error should shrink like $\Delta p / W$: Exercise 2 checks it.
#
# ## The tensile instability
#
# In ESPH the pair force is $\propto \sigma\,\nabla W$ at the *current* distance. $\lvert dW/dr\rvert$ is largest
# at $q = 2/3$ and *grows* as two particles approach it from further out (Chapter 1). In tension the pair force
# attracts; a perturbation that brings two particles closer increases their attraction, and they keep
# approaching: particles clump in pairs and strings, and the material shows unphysical "cracks" (Swegle, Hicks &
# Attaway 1995). With $h = 1.5\,\Delta p$ the nearest neighbours sit exactly at $q = 2/3$, so any stretch moves
# them into the unstable range. TLSPH evaluates the kernel at the fixed *reference* distance: no such feedback.
#
# Scene `tension`: a $10\times10$ mm block, lattice jittered by 1 %, given a uniform expansion (edge velocity
# 300 m/s) that puts it in strong tension; being elastic, it then breathes. We record the smallest pair distance
# over $\Delta p$ and compare ESPH without artificial pressure, ESPH with the paper's $\gamma = 0.3$, and TLSPH.

# %%
ten = {label: run("tension", method, quick=ch.quick, numerics=num, progress=False)
       for label, method, num in [("ESPH, gamma = 0", "esph", {"gamma": 0.0}),
                                  ("ESPH, gamma = 0.3", "esph", {"gamma": 0.3}), ("TLSPH", "tlsph", {})]}
rmin = {label: r.summary["metrics"]["min_pair_distance_over_dp"] for label, r in ten.items()}
for label, r in ten.items():
    print(f"{label:18s}: smallest pair distance over the run {rmin[label]:.3f} dp, "
          f"strongest tension {-r.summary['metrics']['min_pressure_Pa'] / 1e9:.0f} GPa")
assert rmin["ESPH, gamma = 0"] < rmin["TLSPH"] - 0.08            # ESPH without artificial pressure clumps ...
assert rmin["ESPH, gamma = 0.3"] > rmin["ESPH, gamma = 0"] + 0.08  # ... the artificial pressure prevents it

# %%
CLUMP = 0.85                                                    # pairs closer than this (in dp) count as clumped
fig, axes = plt.subplots(1, 2, figsize=(10, 4.4), gridspec_kw=dict(width_ratios=[1.1, 1]))
for (label, r), color in zip(ten.items(), ("C3", "C0", "C1")):
    mh = r.summary["metrics"]["min_pair_distance_history"]
    axes[0].plot(mh[:, 0] * 1e6, mh[:, 1], color, label=label)
axes[0].axhline(CLUMP, color="0.6", ls=":", lw=1)
axes[0].set_xlabel("t [µs]")
axes[0].set_ylabel("smallest pair distance / dp [-]")
axes[0].legend(loc="lower left", frameon=False)
axes[0].set_title("closest pair of particles")
st = ten["ESPH, gamma = 0"].state
side = ten["ESPH, gamma = 0"].setup.info["side"] * 1e3
dp_ten = ten["ESPH, gamma = 0"].setup.dp
I_t, J_t = find_pairs(st.x, 1.5 * dp_ten)
d_t = np.linalg.norm(st.x[I_t] - st.x[J_t], axis=1) / dp_ten
nearest = np.full(st.n, 1.5)                                    # distance to the nearest neighbour / dp
np.minimum.at(nearest, I_t, d_t)
np.minimum.at(nearest, J_t, d_t)
sc = particle_field(axes[1], st.x, nearest, dp_ten, spread=1.0,
                    xlim=(-0.1 * side, 1.1 * side), ylim=(-0.1 * side, 1.1 * side))
Ic, Jc = I_t[d_t < CLUMP], J_t[d_t < CLUMP]
for a, b in zip(Ic, Jc):                                        # clumped pairs as black bars
    axes[1].plot(st.x[[a, b], 0] * 1e3, st.x[[a, b], 1] * 1e3, "k-", lw=2)
colorbar(fig, sc, axes[1], "nearest neighbour / dp [-]")
axes[1].set_xlabel("x [mm]")
axes[1].set_ylabel("y [mm]")
axes[1].set_title(f"ESPH, γ = 0: {len(Ic)} clumped pairs")
fig.tight_layout()
ch.show(fig, "02_tensile_instability.png", caption="The tensile instability: the smallest pair distance in an "
                                                   "expanding block over time (left) for ESPH with γ = 0 and γ = 0.3 "
                                                   "and for TLSPH, and the ESPH block with γ = 0 at the end (right), "
                                                   "coloured by the distance to its nearest neighbour, its clumped "
                                                   "pairs in black.")

# %% [markdown]
# Without artificial pressure the closest pair keeps approaching for as long as the block is in tension, and
# clumped pairs are scattered through it. With $\gamma = 0.3$ and in TLSPH the closest distance only oscillates
# with the breathing of the block. (In full mode the ESPH clumping grows faster: the instability grows on the
# time scale $h/c$.)
#
# ## Where ESPH fails
#
# * **Tensile instability.** In tension ESPH particles clump. In machining, parts of the workpiece and of the
#   chip are in tension, and the clumps look like, and act as, cracks.
# * **The cure is a tuned parameter.** The artificial pressure of Eq. (14) suppresses the clumping here, but
#   $\gamma$ is "a case-dependent tuning parameter" (the paper). It comes from no constitutive law: it also makes
#   an elastic bar softer in tension, and Exercise 1 shows what too much of it does. A large artificial viscosity
#   hides the instability too, at the price of dissipating physical energy.
# * **Free surfaces.** Eq. (23) as printed (the default) is uncorrected, so the surface is too soft and a bar too
#   slow; the error shrinks only like $\Delta p$. In machining the chip, the cut surface and the tool contact are all
#   free surfaces.
# * **On the plus side**, ESPH needs no reference configuration, handles any distortion and separation (pairs
#   simply form and break), and conserves linear momentum exactly.

# %% [markdown]
# ## Your turn
#
# Predict first, run, then open *What you should see*. The last exercise asks for code, graded against the package.
#
# ### Exercise 1 — How much artificial pressure?
#
# Predict: the paper's $\gamma = 0.3$ keeps the particles of the expanding block apart. If $\gamma = 0.02$, is
# the block protected at all? And is a much larger $\gamma = 3$ even safer?

# %% tags=["exercise"]
GAMMA = 0.3        # <- change this (e.g. to 0.02, then to 3.0) and run the cell again
r = run("tension", "esph", quick=ch.quick, numerics={"gamma": GAMMA}, progress=False)
print(f"gamma = {GAMMA}: smallest pair distance over the run = "
      f"{r.summary['metrics']['min_pair_distance_over_dp']:.3f} dp")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# A small $\gamma$ already helps — the closest pair stays further apart than without any artificial pressure,
# though not as far as with $0.3$. A large $\gamma$ is *not* safer: the repulsion itself becomes violent, and at
# $\gamma = 3$ particles are thrown onto each other within microseconds and the smallest distance collapses
# towards zero. The remedy has a window that works, and it has to be found by trial.
# </details>

# %% [markdown]
# ### Exercise 2 — Refine the bar
#
# Predict: the bar's wave-speed error comes from surface layers about $2h$ thick. If you halve the particle
# spacing (16 instead of 8 particles across the width), what happens to the error?

# %% tags=["exercise"]
NW = 8             # <- particles across the bar's width: change this to 16 and run the cell again
r = run("bar", "esph", dim=2, dp=W_bar / NW, t_end=0.9 * T_th, numerics={"gamma": 0.0}, progress=False)
m = r.summary["metrics"]                                        # one half period is enough for the speed
print(f"dp = W/{NW}: c = {m['wave_speed_m_s']:.0f} m/s, error {100 * m['wave_speed_rel_error']:+.2f} %")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# The bar is still too slow, but the error is roughly halved — first-order convergence in $\Delta p$, as expected
# of an error that lives in a surface layer whose thickness is proportional to $\Delta p$. (The run costs about
# eight times more: four times the particles, twice the steps.)
# </details>

# %% [markdown]
# ### Exercise 3 — Write the Jaumann rate yourself
#
# Write Eq. (20) for $n$ particles in 2D plane strain: `S` holds the in-plane deviatoric stresses, shape (n, 2, 2)
# [Pa], `S_zz` the out-of-plane ones, shape (n,), `l` the velocity gradients $l_{ab} = \partial v_a/\partial x_b$,
# shape (n, 2, 2) [1/s]; return $\dot{\mathbf s}$ and $\dot s_{zz}$ [Pa/s]. Whole arrays (`np.swapaxes`, `@`), no
# loop. The grader compares with `refsph.material.jaumann_deviatoric_rate` on a stretch, a rigid spin of a
# pre-stressed particle, a compression and 20 random particles.
#
# Predict: which two details of this chapter will the cases catch if you get them wrong?

# %% tags=["exercise"]
from refsph.teaching.grader import case, check


def my_jaumann(S, S_zz, l, G):
    """Eq. (20) in plane strain: (ds/dt of shape (n, 2, 2), ds_zz/dt of shape (n,))."""
    raise NotImplementedError("write the Jaumann rate, Eq. (20), here")      # <- replace this line by your code


rng_ex = np.random.default_rng(3)
S_rand = rng_ex.normal(scale=2e8, size=(20, 2, 2))
S_rand = S_rand + np.swapaxes(S_rand, 1, 2)                               # symmetric, ~300 MPa
cases_ex3 = [case(np.zeros((1, 2, 2)), np.zeros(1), np.array([[[1e3, 0.0], [0.0, 0.0]]]), mat.G, label="a stretch"),
             case(S0, Szz0, l_rot, mat.G, label="a rigid spin of a pre-stressed particle"),
             case(S0, Szz0, np.array([[[-2e3, 0.0], [0.0, -1e3]]]), mat.G, label="a compression"),
             case(S_rand, -np.trace(S_rand, axis1=1, axis2=2), rng_ex.normal(scale=1e3, size=(20, 2, 2)), mat.G,
                  label="20 random particles")]
report = check(my_jaumann, jaumann_deviatoric_rate, cases_ex3, names=("ds/dt", "ds_zz/dt"))

# %% [markdown]
# <details><summary>What you should see</summary>
#
# As handed out: `FAIL ... not written yet`. The two details: the order of the spin terms (with the printed
# $\mathbf s\boldsymbol\omega - \boldsymbol\omega\mathbf s$ and this chapter's $l_{ab} = \partial v_a/\partial
# x_b$ the rigid spin fails: the stress turns the wrong way), and plane strain (the deviator is that of the 3D
# strain rate, $\mathrm{tr}\,\dot{\boldsymbol\epsilon}/3$ with $\dot\epsilon_{zz} = 0$, and $\dot s_{zz} =
# -\tfrac23 G\,\mathrm{tr}\,\dot{\boldsymbol\epsilon}$ is not zero: the stretch fails without it). When all four
# cases agree: `PASS`.
# </details>
