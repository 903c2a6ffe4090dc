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
# # Chapter 7 — Metal pressing, ESPH and TLSPH side by side
#
# A steel block is clamped on one side and a rigid tool hits the other side at 200 m/s. What happens inside the
# block? The block is *upset*: its pressed end spreads until it is as tall as the tool, and the plastic strain does
# not spread evenly but gathers in **shear bands** that cross in an X. Where the bands are, the material heats up,
# softens, and deforms even more: the first step towards the chip of chapter 8.
#
# This is the paper's Section 3.2 (Islam, Bansal & Peng, Tables 3–4, Figs. 6–10), and the first scene with a
# **tool**. How the tool touches the block is where the two methods differ:
#
# * in **ESPH** the tool's particles are ordinary SPH neighbours of the block's particles;
# * in **TLSPH** they cannot be (each body's kernels live in its own reference configuration), so the paper uses
#   the **pinball contact** of chapter 5.
#
# In this lesson we set up the test with plain code, check the package's layout and contact force against it, run
# both methods, read the shear bands, the temperature and the forces, and check the force level with two
# estimates a student can do by hand. The paper shows contour plots only, so there is no number to match: the
# checks are balances and hand estimates.

# %%
import matplotlib.pyplot as plt
import numpy as np
from refsph.boundaries import RigidBody
from refsph.contact import PinballContact, pinball_contact
from refsph.paper_data import PRESSING_GEOMETRY, PRESSING_RESOLUTIONS_M, PRESSING_TABLE4
from refsph.plasticity import yield_stress
from refsph.teaching.plots import colorbar, particle_field
from refsph.scenes import aisi4340_johnson_cook, aisi4340_material, get_scene
from refsph.scenes.pressing import pressing_particles, pressing_table
from refsph.simulate import run, simulate
from refsph.teaching.notebook import chapter
ch = chapter("07_pressing")

# %% [markdown]
# ## The test
#
# **Material.** AISI 4340 steel (Table 3) with the Johnson–Cook law of chapter 4 (Eqs. 25–31): the yield stress
# grows with plastic strain and strain rate and falls with temperature,
#
# $$\sigma_y = \left[A + B\,\bar\varepsilon_p^{\,n}\right]\left[1 + C\ln\dot\varepsilon^*\right]\left[1 - T^{*m}\right],
# \qquad T^* = \frac{T - T_r}{T_m - T_r},$$
#
# and plastic work heats the material (adiabatic, Eq. 28): $\Delta T = \chi\,\Delta w_p/(\rho\,C_p)$ with
# $\chi = 0.9$.
#
# **Geometry.** Block 1.0 mm × 0.5 mm, tool 0.1 mm × 0.7 mm at 200 m/s. The paper leaves several things open;
# `refsph.scenes.pressing` chooses:
#
# * **2D plane strain** (the mid-plane of the paper's 0.1 mm slab);
# * the tool **centred** on the block's mid-height (it overhangs 0.1 mm above and below);
# * the tool as **3 columns** of particles: a rigid body acts only through the layers a block particle can reach,
#   $\lceil 2h/\Delta p\rceil = 3$ for $h = 1.5\,\Delta p$;
# * the fixed left side is a **clamp**: the first column of block particles held at rest;
# * the run stops after **0.2 mm of tool travel** (1 µs), when the pressed face is as tall as the tool;
# * the CFL time step instead of the paper's fixed $10^{-10}$ s; pinball factor $K_p = 50$ (the paper gives none).

# %%
mat, jc = aisi4340_material(), aisi4340_johnson_cook(1.0)
(LX, LY), (WT, HT) = PRESSING_GEOMETRY["block_m"], PRESSING_GEOMETRY["tool_m"]
V_TOOL = PRESSING_GEOMETRY["tool_speed_m_s"]
DP = PRESSING_RESOLUTIONS_M[0] if ch.quick else PRESSING_TABLE4["particle_spacing_m"]   # 1/60 mm or 1/150 mm
c_L, c_B = mat.c_longitudinal, np.sqrt(mat.K / mat.rho0)
print(f"spacing dp = {1e3 * DP:.5f} mm; c_L = {c_L:.0f} m/s, bulk speed c_B = {c_B:.0f} m/s")
print(f"an elastic wave crosses the block in {1e9 * LX / c_L:.0f} ns; the run lasts {1e9 * 0.2e-3 / V_TOOL:.0f} ns")

# %% [markdown]
# ### The particles, plainly
#
# The block is a lattice with spacings $\Delta x = L_x/\mathrm{round}(L_x/\Delta p)$ and
# $\Delta y = L_y/\mathrm{round}(L_y/\Delta p)$, so it has its exact size and mass at every spacing. The tool is
# three columns just right of the block, centred on its mid-height. We also mark the clamped column and the row of
# particles nearest mid-height (we follow its strain later, as the paper's Fig. 8 does). A plain version of the
# layout, by loops, checked against `pressing_particles` at the four spacings of the paper's Fig. 10:

# %%
def plain_layout(dp, layers):
    """Block centres, tool centres, the clamped column and the mid-height row, by plain loops."""
    nx, ny = round(LX / dp), round(LY / dp)
    dx, dy = LX / nx, LY / ny
    block, clamp, row = [], [], []
    j_mid = min(range(ny), key=lambda j: abs((j + 0.5) * dy - 0.5 * LY))   # the row nearest mid-height
    for i in range(nx):
        for j in range(ny):
            if i == 0:
                clamp.append(len(block))
            if j == j_mid:
                row.append(len(block))
            block.append(((i + 0.5) * dx, (j + 0.5) * dy))
    nt = round(HT / dy)
    tool = [(LX + (i + 0.5) * dx, 0.5 * LY + (j - 0.5 * (nt - 1)) * dy) for i in range(layers) for j in range(nt)]
    return np.array(block), np.array(tool), dx, dy, np.array(clamp), np.array(row)


scene = get_scene("pressing")
for dp in PRESSING_RESOLUTIONS_M:
    st = scene.setup(2, dp, True)
    layers, n = st.info["tool_layers"], st.info["n_block"]
    pb, pt, pdx, pdy, pcl, prow = plain_layout(dp, layers)
    xb, xt, dx, dy, clamp, line = pressing_particles(dp, layers)
    assert np.allclose(pb, xb, rtol=0, atol=1e-18) and np.allclose(pt, xt, rtol=0, atol=1e-18)
    assert pdx == dx and pdy == dy and np.array_equal(pcl, clamp) and np.array_equal(prow, line)
    assert np.array_equal(st.state.x[:n], xb) and np.all(st.state.body[n:] > 0)
    assert abs(st.state.m[:n].sum() / (mat.rho0 * LX * LY) - 1) < 1e-12          # exact mass
    assert np.all(st.state.v[n:, 0] == -V_TOOL) and np.all(st.state.v[:n] == 0)
    print(f"dp = {1e3 * dp:.5f} mm: block {round(LX / dp)} x {round(LY / dp)}, tool {layers} x {len(xt) // layers}"
          f" particles -- plain layout == pressing_particles")

# %%
st0 = scene.setup(2, DP, True)
n_b, x0 = st0.info["n_block"], st0.state.x
fig, ax = plt.subplots(figsize=(8, 5), constrained_layout=True)
ms = 5 if ch.quick else 1.2
ax.plot(1e3 * x0[:n_b, 0], 1e3 * x0[:n_b, 1], ".", ms=ms, color="0.6", label="block (AISI 4340)")
ax.plot(*(1e3 * x0[st0.clamps[0].index].T), "s", ms=ms, color="k", label="clamped column")
ax.plot(*(1e3 * x0[st0.arrays["line_index"]].T), ".", ms=ms, color="C2", label="mid-height row")
ax.plot(1e3 * x0[n_b:, 0], 1e3 * x0[n_b:, 1], ".", ms=ms, color="C1", label="rigid tool")
ax.annotate("200 m/s", xy=(1.15, 0.25), xytext=(1.3, 0.25), arrowprops=dict(arrowstyle="->", lw=2), va="center")
ax.set(aspect="equal", xlim=(-0.05, 1.5), ylim=(-0.15, 0.65), xlabel="x [mm]", ylabel="y [mm]",
       title=f"The pressing test (cf. the paper's Fig. 6), dp = {1e3 * DP:.4f} mm")
ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.17), ncol=2)
ch.show(fig, "07_pressing_setup.png", caption="The pressing test: the AISI 4340 block (grey) with its clamped column "
                                              "(black) and the row of particles at mid-height (green), and the rigid "
                                              "tool (orange).")

# %% [markdown]
# ## The contact: ESPH neighbours, TLSPH pinballs
#
# In ESPH the tool's particles enter the block's SPH sums like any neighbour: they carry a density and a
# pressure, and the ordinary pair forces between block and tool, summed over the tool, are the force on the tool.
#
# In TLSPH every particle carries a pinball of radius $R = k h$ (with $k = \Delta p/2h$: two faces one spacing
# apart just touch). A block particle $i$ and a tool particle $j$ overlap by $p_d = 2R - r_{ij}$ (Eq. 32); while
# $p_d > 0$ they are pushed apart along the line of centres with (Eqs. 33–36)
#
# $$F_{ij} = K_p \min\!\left(\frac{m_i\,\dot p_d}{\Delta t}\ \text{if } \dot p_d > 0 \text{ else } 0,\;\;
# \frac{G}{\Delta p}\sqrt{R/2}\;p_d^{1.5}\right),\qquad \dot p_d = -(\mathbf v_i - \mathbf v_j)\cdot\mathbf e_{ij}.$$
#
# The first branch is the force that stops the approach within one step (the tool is rigid, so only $m_i$
# enters); the second is a Hertz force, divided by $\Delta p$ to make it a force per metre of thickness in 2D.
# The first branch **acts only while the particles approach**, and with $K_p > 1$ it does more than stop them:
# remember this for "where it fails". A plain loop over random pairs, against `pinball_contact`:

# %%
rng = np.random.default_rng(7)
h_c = 1.5 * DP
R_c = (DP / (2 * h_c)) * h_c
xa = np.column_stack([rng.uniform(0.0, 3 * DP, 60), rng.uniform(0.0, 6 * DP, 60)])
xt_ = np.column_stack([np.full(12, 3.2 * DP), np.arange(12) * 0.5 * DP])
va, vt = rng.normal(scale=100.0, size=xa.shape), np.tile([-V_TOOL, 0.0], (12, 1))
ma = np.full(60, mat.rho0 * DP * DP)
dt_c = 1e-9
contact = PinballContact(k=DP / (2 * h_c), K_p=50.0)
acc_plain, f_tool_plain = np.zeros_like(xa), np.zeros_like(xt_)
for i in range(len(xa)):
    for j in range(len(xt_)):
        d = xa[i] - xt_[j]
        r = np.hypot(*d)
        p_d = 2 * R_c - r                                               # Eq. (32)
        if p_d <= 0 or r == 0:
            continue
        e = d / r
        pdot = -float(np.dot(va[i] - vt[j], e))
        F1 = ma[i] * pdot / dt_c if pdot > 0 else 0.0                   # Eq. (34), rigid partner: m_ij = m_i
        F2 = mat.G * np.sqrt(R_c * R_c / (2 * R_c)) * p_d**1.5 / DP     # Eq. (35), per unit thickness
        F = contact.K_p * min(F1, F2)                                   # Eq. (33)
        acc_plain[i] += F * e / ma[i]                                   # Eq. (36)
        f_tool_plain[j] -= F * e
res_c = pinball_contact(xa, va, ma, xt_, vt, np.inf, R_c, mat.G, np.inf, dt_c, contact, thickness=DP)
scale = np.abs(acc_plain).max()
assert np.allclose(res_c.a, acc_plain, rtol=1e-12, atol=1e-12 * scale)
assert np.allclose(res_c.force_on_b, f_tool_plain, rtol=1e-12, atol=1e-12 * scale * ma[0])
print(f"{res_c.n_contacts} pairs in contact -- plain loop == pinball_contact")

# %% [markdown]
# ## Both methods, side by side
#
# Both methods at the spacing printed above (quick mode: 1/60 mm, the coarsest of the paper's Fig. 10; full mode:
# the paper's 1/150 mm). `pressing_table` is what `refsph run pressing` prints.

# %%
res = {m: run("pressing", m, dp=DP, out=ch.tmp / m, progress=False) for m in ("esph", "tlsph")}
print(pressing_table([r.summary for r in res.values()]))
n_b, dx = res["esph"].setup.info["n_block"], res["esph"].setup.info["dx"]

# %% [markdown]
# ### Shear bands and heat (the paper's Figs. 7 and 9)
#
# The final state, coloured by the effective plastic strain (top; the scale is cut at 1 so the bands show) and by
# the temperature (bottom). The temperature is checked against the integrated Eq. (28),
# $T - T_r \approx \chi W_p/(\rho C_p)$, with $W_p$ the plastic work per unit volume each particle has done.

# %%
def plain_temperature_rise(W_p, rho):
    """Eq. (28), integrated: dT = chi W_p / (rho C_p) with the accumulated plastic work density."""
    return jc.chi * W_p / (rho * jc.cp)


fig, axes = plt.subplots(2, 2, figsize=(9.6, 6.4), sharex=True, sharey=True)
fig.subplots_adjust(left=0.07, right=0.85, bottom=0.09, top=0.94, wspace=0.06, hspace=0.16)   # fixed: marker sizes
T_hi = max(np.percentile(r.state.T[:n_b], 99.5) for r in res.values())
for k, (m, r) in enumerate(res.items()):
    s = r.state
    # each step adds chi dW_p / (rho C_p) with that step's rho, so the sum is close to (not equal to) this
    err = np.abs((s.T[:n_b] - jc.T_room) - plain_temperature_rise(s.W_p[:n_b], s.rho[:n_b])).max()
    assert err < 0.05 * (s.T[:n_b].max() - jc.T_room)
    lim = dict(body=s.body, xlim=(-0.03, 0.9), ylim=(-0.15, 0.65))
    pe = particle_field(axes[0, k], s.x, s.eps_p, dx, vmin=0, vmax=1.0, **lim)
    pT = particle_field(axes[1, k], s.x, s.T, dx, cmap="inferno", vmin=jc.T_room, vmax=T_hi, **lim)
    axes[0, k].set_title(f"{m.upper()}, tool travel {1e3 * V_TOOL * s.t:.2f} mm")
    axes[1, k].set_xlabel("x [mm]")
    print(f"{m.upper():5s}: max T {s.T[:n_b].max():.0f} K; T - T_r == chi W_p/(rho C_p) to {err:.1f} K")
axes[0, 0].set_ylabel("y [mm]")
axes[1, 0].set_ylabel("y [mm]")
for row, (pc, label) in enumerate(((pe, "effective plastic strain [-]"), (pT, "temperature [K]"))):
    y0, y1 = axes[row, 1].get_position().y0, axes[row, 1].get_position().y1
    colorbar(fig, pc, axes[row, :], label, extend="max", cax=fig.add_axes([0.87, y0, 0.015, y1 - y0]))
ch.show(fig, "07_pressing_fields.png", caption="The pressed block at the end of the run, ESPH (left) and TLSPH "
                                               "(right): effective plastic strain (top, scale cut at 1), with two "
                                               "shear bands crossing in an X, and temperature (bottom).")

# %% [markdown]
# How to read it:
#
# * The plastic zone starts at the block's right corners, which slide outward along the frictionless tool face.
# * From the ends of the tool face, two **shear bands** run into the block and cross in an X at mid-height. A
#   second, weaker pair runs in from the clamped corners on the left.
# * Between the bands the material strains less, and a triangle in front of the clamp hardly deforms at all.
# * The **temperature follows the strain**: hot in the bands, hottest at the tool's corners. A few hundred kelvin
#   take a noticeable part off the yield stress through $1 - T^{*m}$: the thermal softening that lets the bands
#   slide "more easily", as the paper puts it.
# * Both methods give the same picture. ESPH's bands are a little more diffuse (the paper says the same);
#   TLSPH's corner particles carry more strain.

# %% [markdown]
# ### Plastic strain across the block (the paper's Fig. 8)
#
# Fig. 8 plots the plastic strain "across the block". We follow the row of particles that started at mid-height
# (the same particles at every time and in both methods) and plot their strain against their current $x$. A plain
# version of the scene's metric `plastic_strain_line`:

# %%
fig, ax = plt.subplots(figsize=(8, 3.8), constrained_layout=True)
for m, r in res.items():
    X0 = r.setup.state.x[:n_b]
    y_rows = np.unique(X0[:, 1])
    y_mid = y_rows[np.argmin(np.abs(y_rows - 0.5 * LY))]
    row = sorted((i for i in range(n_b) if X0[i, 1] == y_mid), key=lambda i: r.state.x[i, 0])
    plain = np.array([[1e3 * r.state.x[i, 0], r.state.eps_p[i]] for i in row])
    line_m = np.asarray(r.summary["metrics"]["plastic_strain_line"])
    assert np.array_equal(plain, line_m)
    ax.plot(line_m[:, 0], line_m[:, 1], ".-", ms=4, label=m.upper())
    print(f"{m.upper():5s}: peak eps_p {line_m[:, 1].max():.2f} at x = {line_m[np.argmax(line_m[:, 1]), 0]:.2f} mm")
ax.set(xlabel="current x [mm]", ylabel="effective plastic strain [-]",
       title="Plastic strain along the mid-height row, end of the run (cf. Fig. 8)")
ax.grid(alpha=0.3)
ax.legend()
ch.show(fig, "07_pressing_strain_line.png", caption="Effective plastic strain along the row of particles that started "
                                                    "at mid-height, against their current x, at the end of the run "
                                                    "(cf. the paper's Fig. 8): both methods peak where the row "
                                                    "crosses the X of the shear bands.")

# %% [markdown]
# As in the paper, the strain grows from left to right (the right part of the block is "subjected to more plastic
# deformation"), and the two methods follow the same curve. The peak is where the row passes through the crossing
# of the X-shaped bands; the smaller bump further left is where it crosses the bands from the clamped corners.

# %% [markdown]
# ## The forces, and a check by hand
#
# Every step records the force of the block on the tool and on the clamp, per metre of thickness
# (MN/m = kN per mm of thickness). Two estimates tell us what to expect.
#
# **The impact.** At first contact the tool hits the block's face like a flying plate. If the block stayed
# elastic the face stress would be $\rho c_L v$. But that is far beyond yield, so the wave splits: an elastic
# precursor up to the Hugoniot elastic limit $\sigma_{HEL} = \frac{1-\nu}{1-2\nu}\,\sigma_y$, then a plastic wave
# at about the bulk speed $c_B = \sqrt{K/\rho}$:
#
# $$\sigma_{\rm impact} \approx \sigma_{HEL} + \rho\, c_B\,(v - v_{HEL}),\qquad v_{HEL} = \frac{\sigma_{HEL}}{\rho c_L},
# \qquad F_{\rm impact} = \sigma_{\rm impact} H_0 .$$
#
# **Steady pressing.** Later the block flows plastically. A vertical section through free-edged, fully plastic
# material in plane strain carries $|\sigma_{xx}| = \tfrac{2}{\sqrt3}\sigma_y$, so the pressing force is about
# $F \approx \tfrac{2}{\sqrt3}\,\sigma_y H$, with $H$ the height of the tool face the block now touches and
# $\sigma_y$ at the state of the particles there, at the nominal strain rate $v/L$.

# %%
def impact_force(v):
    """Elastic-plastic impact force per unit thickness on the block face H0 (uniaxial strain) [N/m]."""
    sig_hel = (1 - mat.nu) / (1 - 2 * mat.nu) * float(yield_stress(jc, 0.0, 1e6, jc.T_room))
    v_hel = sig_hel / (mat.rho0 * c_L)
    return (sig_hel + mat.rho0 * c_B * max(v - v_hel, 0.0)) * LY


def yield_plain(e, rate, T):
    """Eq. (25), plain."""
    Ts = min(max((T - jc.T_room) / (jc.T_melt - jc.T_room), 0.0), 1.0)
    return (jc.A + jc.B * e**jc.n) * (1 + jc.C * np.log(max(rate / jc.eps_dot_0, 1.0))) * (1 - Ts**jc.m)


def running_mean(t, f, width):
    """Mean of f over a window of the given width in t (both arrays per step)."""
    c = np.concatenate([[0.0], np.cumsum(f)])
    lo, hi = np.searchsorted(t, t - 0.5 * width), np.searchsorted(t, t + 0.5 * width, side="right")
    return (c[hi] - c[lo]) / (hi - lo)


assert abs(yield_plain(0.3, 2e5, 600.0) / float(yield_stress(jc, 0.3, 2e5, 600.0)) - 1) < 1e-14
fig, ax = plt.subplots(figsize=(9, 5.6), constrained_layout=True)
for m, r in res.items():
    rh = r.history["reaction"]
    t, f_tool, f_clamp = np.asarray(rh["t"]), np.asarray(rh["tool"])[:, 0], -np.asarray(rh["left_side"])[:, 0]
    col = "C0" if m == "esph" else "C3"
    ax.plot(1e9 * t, 1e-6 * running_mean(t, f_tool, 25e-9), color=col, lw=1.8, label=f"{m.upper()}: on the tool")
    ax.plot(1e9 * t, 1e-6 * running_mean(t, f_clamp, 25e-9), color=col, lw=1.0, ls="--",
            label=f"{m.upper()}: on the clamp")
    xb_end = r.state.x[:n_b]
    face = xb_end[:, 0] > xb_end[:, 0].max() - 1.5 * dx              # the particles along the tool face
    H = np.ptp(xb_end[face, 1]) + res["esph"].setup.info["dy"]
    sy = yield_plain(r.state.eps_p[:n_b][face].mean(), V_TOOL / (xb_end[:, 0].max()), r.state.T[:n_b][face].mean())
    print(f"{m.upper():5s}: mean tool force over the 2nd half {1e-6 * r.summary['metrics']['tool_force_mean_N_per_m']:.2f}"
          f" MN/m; hand estimate 2/sqrt(3) sigma_y H = {1e-6 * 2 / np.sqrt(3) * sy * H:.2f} MN/m "
          f"(face {1e3 * H:.2f} mm tall, sigma_y = {sy / 1e6:.0f} MPa)")
ax.axhline(1e-6 * impact_force(V_TOOL), color="0.3", ls=":", label="elastic-plastic impact estimate")
ax.axvline(1e9 * LX / c_L, color="0.6", lw=0.8)
ax.text(1e9 * LX / c_L + 5, 2.5, "$L / c_L$", color="0.4")
ax.set(xlabel="t [ns]", ylabel="force [MN/m]", title="Forces of the block on tool and clamp (25 ns running mean)")
ax.grid(alpha=0.3)
ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.17), ncol=2)
ch.show(fig, "07_pressing_forces.png", caption="The forces of the block on the tool (solid) and on the clamp (dashed) "
                                               "with ESPH and TLSPH, as 25 ns running means, and the elastic-plastic "
                                               "impact estimate (dotted).")
print(f"impact estimate {1e-6 * impact_force(V_TOOL):.2f} MN/m (elastic: rho c_L v H0 = "
      f"{1e-6 * mat.rho0 * c_L * V_TOOL * LY:.2f} MN/m)")

# %% [markdown]
# The story of the curve:
#
# 1. **Impact.** The force jumps to about the elastic-plastic impact estimate, well below the elastic one.
# 2. **Release.** It then falls almost to zero: the impact has set the block's right part moving with the tool,
#    and release waves from the free top and bottom edges take the pressure off the face.
# 3. **The wave reaches the clamp** at about $L/c_L$ (vertical line), and the clamp force rises.
# 4. **Pressing.** The force rings about a mean level, the flow force of the upsetting block. The hand estimate
#    $\tfrac{2}{\sqrt3}\sigma_y H$ lands close to it (printed above). The clamp carries less than the tool on
#    average: the difference is the rate at which the block's momentum grows.

# %% [markdown]
# ### Momentum and energy
#
# The tool and the clamp are the only external forces on the block, and every internal force (SPH pairs, ESPH's
# block–tool pairs, the pinball pairs) is equal and opposite. So the block's change of momentum must equal minus
# the impulses it gave tool and clamp, to round-off. And the tool's work $v J_{\rm tool}$ must go into kinetic
# energy, elastic energy $\sum_i V_i\,(p_i^2/2K + \mathbf s_i:\mathbf s_i/4G)$, plastic work, and what the
# artificial viscosity dissipates.

# %%
for m, r in res.items():
    s0, s1 = r.setup.state, r.state
    dP = np.sum(s1.m[:n_b, None] * s1.v[:n_b], axis=0) - np.sum(s0.m[:n_b, None] * s0.v[:n_b], axis=0)
    J = r.summary["diagnostics"]["reaction_impulse"]
    J_tool, J_clamp = np.array(J["tool"]), np.array(J["left_side"])
    err = np.abs(dP + J_tool + J_clamp).max() / abs(J_tool[0])
    assert err < 1e-9
    W_tool = V_TOOL * J_tool[0]
    E_kin = float(0.5 * np.sum(s1.m[:n_b] * np.sum(s1.v[:n_b] ** 2, axis=1)))
    p = mat.K * (s1.rho[:n_b] / mat.rho0 - 1)                                      # Eq. (24)
    ss = np.einsum("nab,nab->n", s1.S[:n_b], s1.S[:n_b]) + s1.S_zz[:n_b] ** 2      # s:s, with s_zz
    E_el = float(np.sum(s1.m[:n_b] / s1.rho[:n_b] * (p * p / (2 * mat.K) + ss / (4 * mat.G))))
    W_pl = float(np.sum(s1.W_p[:n_b] * s1.m[:n_b] / s1.rho[:n_b]))
    print(f"{m.upper():5s}: momentum balance to {err:.0e} of J_tool; tool work {W_tool:.0f} J/m -> plastic "
          f"{100 * W_pl / W_tool:.0f} %, kinetic {100 * E_kin / W_tool:.0f} %, elastic {100 * E_el / W_tool:.0f} %, "
          f"rest (viscosity, contact) {100 * (1 - (E_kin + E_el + W_pl) / W_tool):.0f} %")

# %% [markdown]
# The momentum balance holds to round-off in both methods. Most of the tool's work becomes plastic work (and 90 %
# of that becomes heat); the kinetic energy is the block's right part moving with the tool. The rest is what the
# artificial viscosity and, in TLSPH, the pinball contact take out (its first branch stops approaching pairs: an
# inelastic collision).

# %% [markdown]
# ## Finer particles: the resolution study (the paper's Fig. 10)
#
# `python benchmarks/pressing.py` runs both methods at the four spacings of Fig. 10, the paper's fixed time step,
# and other pinball factors; its tables, the work-precision plot and what they mean are in the
# [pressing benchmark report](../benchmarks/pressing_report.md) (`benchmarks/pressing_report.md`). The
# main result, the final plastic strain at the four spacings at full resolution:
#
# ![Final plastic strain at four spacings, ESPH (top) and TLSPH (bottom)](../figures/07_pressing_resolution.png)
#
# As in the paper, the bands become narrower and sharper as the spacing shrinks, while the overall shape (how far
# the block spreads, where the bands cross) and the mean force hardly change. ESPH does not care about the
# smaller time step; TLSPH's strain line moves by 4–10 % (L2) with the time step and with $K_p$, because both
# enter its contact law.

# %% [markdown]
# ## Where it fails
#
# **Nothing to compare with.** The paper gives contour plots only: no force, no peak strain, no temperature. The
# numbers here are checked by balances and hand estimates, not validated.
#
# **The maximum plastic strain is a corner value.** The largest strains sit at a few particles where the block's
# corners meet the tool's edges. There the strain has no finite limit as the spacing shrinks: the maximum is set by
# the particle size and grows on refinement, while a percentile settles (the report shows both):

# %%
for m, r in res.items():
    e, xe = r.state.eps_p[:n_b], r.state.x[:n_b]
    top = np.argsort(e)[-5:]
    face_x = r.state.x[n_b:, 0].min() - 0.5 * dx
    print(f"{m.upper():5s}: 5 largest eps_p {np.round(e[top], 2)} at y = {np.round(1e3 * xe[top, 1], 2)} mm, within "
          f"{(face_x - xe[top, 0]).max() / dx:.1f} dx of the tool face; 99th percentile {np.percentile(e, 99):.2f}")

# %% [markdown]
# **TLSPH's force chatters, and its symmetry breaks.** The pinball force $K_p m\,\dot p_d/\Delta t$ acts only
# while a pair approaches. With $K_p = 50$ one step does more than stop the approach: the particle is pushed back,
# the pair separates, the force is off in the next step, the block's stress pushes it back towards the tool. The
# force on the tool jumps from step to step; its mean is right (the momentum balance holds exactly), a single
# step's value is not. The same over-reaction amplifies round-off: the test is symmetric about mid-height, and
# ESPH stays symmetric, while TLSPH's particles drift away from their mirror twins. Both, measured:

# %%
for m, r in res.items():
    rh = r.history["reaction"]
    t, f = np.asarray(rh["t"]), np.asarray(rh["tool"])[:, 0]
    f2 = f[t > 0.5 * t[-1]]
    X0, x1 = r.setup.state.x, r.state.x
    dy = r.setup.info["dy"]
    cell = {(round(2 * x / dx), round(2 * y / dy)): i for i, (x, y) in enumerate(X0)}   # half-spacing grid
    twin = np.array([cell[round(2 * x / dx), round(2 * (LY - y) / dy)] for x, y in X0])  # the mirror partner
    assert np.allclose(X0[twin] * [1, -1] + [0, LY], X0, rtol=0, atol=1e-9 * DP)
    mis = np.max(np.abs(x1[twin] * [1, -1] + [0, LY] - x1)) / dx
    print(f"{m.upper():5s}: step-to-step change of the tool force {100 * np.mean(np.abs(np.diff(f2))) / f2.mean():.0f}"
          f" % of its mean; largest distance from the mirror twin {mis:.1e} dx")

# %% [markdown]
# **2D plane strain against a 3D slab.** The paper's block is 0.1 mm thick, five times thinner than it is tall,
# and the paper does not say what holds its front and back faces. If they are free, the slab is closer to
# *plane stress*, where a von Mises section flows at $\sigma_y$ instead of $\tfrac{2}{\sqrt3}\sigma_y$: the force
# would be lower by the factor $\sqrt3/2$, and the slab would thicken where it is squeezed, which a 2D model
# cannot show.

# %% [markdown]
# ## Your turn
#
# Predict first, run, then open *What you should see*. The last exercise asks for code, graded against the package.
#
# ### Exercise 1 — A faster tool
#
# Predict: the tool hits the block twice as fast. What happens to the force in the first few nanoseconds, the
# impact? Does it double, grow by less, or hardly change? Use the impact estimate above.

# %% tags=["exercise"]
from functools import cache


@cache                                   # (each speed runs once)
def impact_peak(v):
    """ESPH, the first 60 ns with the tool at speed v: the largest force of the block on the tool [N/m]."""
    st = scene.setup(2, PRESSING_RESOLUTIONS_M[0], True)
    st.state.v[st.info["n_block"]:, 0] = -v
    st.rigid, st.t_end = (RigidBody("tool", 1, (-v, 0.0)),), 60e-9                # the first 60 ns only
    return float(np.asarray(simulate(st, "esph", scene=scene, progress=False).history["reaction"]["tool"])[:, 0].max())


V = 200.0          # <- tool speed [m/s]: change this (e.g. to 400) and run the cell again
print(f"v = {V:.0f} m/s: impact peak of the tool force {1e-6 * impact_peak(V):.2f} MN/m; estimate "
      f"{1e-6 * impact_force(V):.2f} MN/m (at 200 m/s: {1e-6 * impact_force(200.0):.2f} MN/m)")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# The impact force grows about in proportion to the speed (the $\rho c_B v$ term dominates, the elastic precursor
# adds a little), and it follows the estimate. The mean pressing force later would hardly change: the rate term
# $C\ln\dot\varepsilon^*$ of Johnson–Cook is small.
# </details>

# %% [markdown]
# ### Exercise 2 — How hard is the pinball?
#
# Predict: with a smaller pinball factor $K_p$, does the tool sink deeper into the TLSPH block, or less deep?

# %% tags=["exercise"]
@cache
def penetration(K_p):
    """TLSPH, 0.05 mm of tool travel: the deepest pinball penetration, in spacings."""
    r = run("pressing", "tlsph", dp=PRESSING_RESOLUTIONS_M[0], progress=False, options=dict(travel=0.05e-3),
            numerics=dict(contact_Kp=K_p))
    return r.summary["diagnostics"]["max_pinball_penetration_m"] / r.setup.dp


K_P = 50.0         # <- pinball scaling factor: change this (e.g. to 5) and run the cell again
print(f"K_p = {K_P:g}: deepest pinball penetration {penetration(K_P):.3f} dp after 0.05 mm of tool travel")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# The smaller $K_p$, the deeper the penetration (the first branch of the force stops an approach less hard); with
# a large $K_p$ the penetration is a small fraction of a spacing. $K_p$ is a numerical stiffness, not a material
# property.
# </details>

# %% [markdown]
# ### Exercise 3 — Switch off the heating
#
# Predict: without adiabatic heating ($\Delta T = 0$, no thermal softening), is the pressing force higher or
# lower? Are the shear bands stronger or weaker?

# %% tags=["exercise"]
import dataclasses


def pressing_esph(heating):
    """The chapter's ESPH run, with or without heating by plastic work (Eq. 28); True: the run above."""
    if heating:
        return res["esph"]
    st = scene.setup(2, DP, True)
    st.strength = dataclasses.replace(st.strength, heating=False)              # the law's own switch
    return simulate(st, "esph", scene=scene, progress=False)


HEATING = True     # <- change this to False (isothermal: no heating by plastic work) and run again
for label, r in (("chapter, heating", res["esph"]), (f"heating = {HEATING}", pressing_esph(HEATING))):
    mt = r.summary["metrics"]
    print(f"{label:17s}: mean tool force {1e-6 * mt['tool_force_mean_N_per_m']:.3f} MN/m, max T "
          f"{mt['max_temperature_K']:.0f} K, 99th percentile of eps_p {np.percentile(r.state.eps_p[:n_b], 99):.3f}")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# Without heating the temperature stays at room temperature, the material stays stronger, the pressing force is a
# few per cent higher, and the strain in the bands is lower: thermal softening is what helps the strain to
# localise, and in machining it is what lets the chip form.
# </details>

# %% [markdown]
# ### Exercise 4 — The tool and the clamp, yourself
#
# The tool and the clamped column are prescribed motions, imposed on the rates of every stage: the tool's rows
# (`n_block` onwards) move with their velocity (dx/dt = v, dv/dt = 0), the clamp's rows (`clamp`) stay put
# (dx/dt = dv/dt = 0). The force the block exerts on each is $\sum_i m_i\,\dot{\mathbf v}_i$ over its rows,
# with the accelerations `a` the SPH sums and the contact gave them (pairs inside one body cancel): the momentum
# the constraint removes. Write it: return the force on the tool, on the clamp (N/m, shape (2,)) and the rates
# dv/dt and dx/dt after the constraints. The grader uses the chapter's states with random accelerations. Predict:
# which outputs are wrong if you zero the rates first?

# %% tags=["exercise"]
def my_constraints(m, v, a, n_block, clamp):
    """(force on the tool, force on the clamp, dv/dt, dx/dt) of the pressing's tool and clamp, from the masses m,
    velocities v and the accelerations a of every particle before the constraints."""
    raise NotImplementedError("write the tool and the clamp here")      # <- replace this line by your code


from types import SimpleNamespace

from refsph.boundaries import Clamp, Constraints
from refsph.state import Rates
from refsph.teaching.grader import case, check


def pkg_constraints(m, v, a, n_block, clamp):
    n, d = v.shape
    s = SimpleNamespace(n=n, dim=d, m=m, v=v, x=np.zeros_like(v), t=0.0, body=(np.arange(n) >= n_block).astype(int))
    cons = Constraints(rigid=(RigidBody("tool", 1, tuple(v[-1])),), clamps=(Clamp("clamp", clamp),))
    cons.bind(s)
    r = Rates(x=v.copy(), v=a, rho=None, S=np.zeros((n, d, d)), S_zz=np.zeros(n))
    cons.constrain(s, r)
    cons.log.close_step(0.0, 1.0)                                   # one step of 1 s: the log holds the forces
    h = cons.reaction_history()
    return h["tool"][0], h["clamp"][0], r.v, r.x


rng_ex = np.random.default_rng(4)
v_rand = np.concatenate([rng_ex.normal(scale=50.0, size=(n_b, 2)), st0.state.v[n_b:]])     # the tool keeps its v
cases_ex4 = [case(s.m, v, rng_ex.normal(scale=1e9, size=v.shape), n_b, st0.clamps[0].index, label=label)
             for s, v, label in ((st0.state, st0.state.v, "the set-up, t = 0"),
                                 (res["esph"].state, res["esph"].state.v, "ESPH, end of the run"),
                                 (res["tlsph"].state, res["tlsph"].state.v, "TLSPH, end of the run"),
                                 (st0.state, v_rand, "the set-up, random velocities"))]
report = check(my_constraints, pkg_constraints, cases_ex4, names=("F_tool", "F_clamp", "dv/dt", "dx/dt"))

# %% [markdown]
# <details><summary>What you should see</summary>
#
# As handed out: `FAIL ... not written yet`. Zeroing first gives forces of zero: `F_tool` fails in the first
# case. Forgetting the masses, or $\dot{\mathbf x} = \mathbf v$ left on the clamp, fail too. This is why the
# momentum balance above holds to round-off: the logged force is exactly the momentum the constraint takes out.
# </details>
