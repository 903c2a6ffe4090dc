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
# # Chapter 6 — The Taylor impact test
#
# Islam, Bansal & Peng, Section 3.1 (Tables 1–2, Figs. 2–5): a cylinder of low-strength 4340 steel, 37.97 mm long
# and 7.595 mm across, hits a rigid, frictionless wall at 181 m/s. The front end mushrooms, the bar gets shorter,
# stops, and rebounds. The experiment (House et al. 1995) gives the final length and the diameter of the
# mushroom; so do LS-DYNA and the paper's ESPH and TLSPH. This is the first test in the paper in which the
# Johnson–Cook plasticity (chapter 4), the walls and, in 3D, the symmetry planes all work together.
#
# This chapter
#
# 1. sets the test up: the material (Table 1), the numerics (Table 2), the particles on rings, the
#    symmetry planes (mirror ghosts), the wall, and how length and diameter are measured from particles —
#    each with a plain-Python version checked against the package;
# 2. checks the symmetry planes in a way that cannot fail silently: the half model against the whole body;
# 3. runs the quick teaching case, 2D plane strain, with both methods, and explains why it *cannot* match
#    the experiment;
# 4. runs the 3D quarter model with both methods and shows the benchmark study (`benchmarks/taylor.py`):
#    convergence, the melting temperature, the time step;
# 5. says where it fails.
#
# Numbers quoted in the text are never typed in by hand: they are printed by the cells.

# %%
import math
import os
import shutil
import tempfile
import time
import json
from itertools import combinations
from pathlib import Path

import numpy as np
import matplotlib.pyplot as plt
from scipy.spatial import cKDTree

from refsph.boundaries import MirrorPlanes, RigidWall
from refsph.io import load_run, load_snapshot
from refsph.plasticity import yield_stress
from refsph.paper_data import TAYLOR_GEOMETRY, TAYLOR_RESULTS, TAYLOR_TABLE1, TAYLOR_TABLE2
from refsph.scenes import get_scene
from refsph.simulate import make_solver, run
from refsph.state import make_state
from refsph.scenes.taylor import (bar_diameter, bar_length, comparison_table, taylor_johnson_cook, taylor_material,
                           taylor_particles)

QUICK = os.environ.get("REFSPH_QUICK", "0") == "1"     # REFSPH_QUICK=1: coarse runs (the tests use it)
ROOT = Path.cwd().parent if Path.cwd().name == "chapters" else Path.cwd()
# Figures go to figures/ in the repo, or to $REFSPH_FIGURES when that is set (the tests set it to a temporary
# folder, so a quick-mode run never overwrites the committed full-resolution figures).
FIG = Path(os.environ["REFSPH_FIGURES"]) if os.environ.get("REFSPH_FIGURES") else ROOT / "figures"
FIG.mkdir(parents=True, exist_ok=True)
TMP = Path(tempfile.mkdtemp(prefix="refsph_ch06_"))    # run directories (snapshots): removed at the end
T_START = time.perf_counter()

GEO = TAYLOR_GEOMETRY
L0, D0, V0 = GEO["length_m"], GEO["diameter_m"], GEO["impact_velocity_m_s"]
R0 = 0.5 * D0
L_EXP = TAYLOR_RESULTS["final_length_mm"]["experiment"]
D_EXP = TAYLOR_RESULTS["final_diameter_mm"]["experiment"]
DP_2D = 0.5e-3 if QUICK else 0.25e-3                   # 2D plane strain spacing
DP_3D = 1.0e-3 if QUICK else TAYLOR_TABLE2["particle_spacing_m"]   # 3D quarter model (the paper: 0.5 mm)
METHODS = ("esph", "tlsph")
COL = dict(esph="C0", tlsph="C3")
print(f"quick mode: {QUICK};  2D spacing {1e3 * DP_2D} mm, 3D spacing {1e3 * DP_3D} mm;  run folders in {TMP}")

# %% [markdown]
# ## 1. The set-up
#
# ### Material (Table 1) and numerics (Table 2)
#
# The bar is elastic–plastic: the elastic part is the hypo-elastic solid of chapters 2–3 with the shear
# modulus $\mu$ and bulk modulus $K$ of Table 1; the plastic part is Johnson–Cook with adiabatic heating
# (chapter 4, Eqs. 25–31):
#
# $$\sigma_y = \left[A + B\,\bar\varepsilon_p^{\,n}\right]\left[1 + C\ln\dot\varepsilon^*\right]\left[1 - T^{*m}\right],\qquad
# T^* = \frac{T - T_r}{T_m - T_r},\qquad \Delta T = \frac{\chi\,\Delta w_p}{\rho\,C_p}.$$
#
# Table 1 prints $T_m = 1293$ K. That is almost certainly a typo for 1793 K, the usual value for 4340
# (Johnson & Cook 1983); `refsph` uses the printed value by default and the benchmark runs both (Section 4).
# The reference strain rate $\dot\varepsilon_0$ is not printed; `refsph` uses 1/s (Johnson & Cook's).

# %%
mat = taylor_material()
jc = taylor_johnson_cook(TAYLOR_TABLE1["T_melt_K"], 1.0)
print("Table 1 (refsph.paper_data.TAYLOR_TABLE1):")
for k, v in TAYLOR_TABLE1.items():
    print(f"  {k:18s} {v:g}")
print("Table 2 (refsph.paper_data.TAYLOR_TABLE2):")
for k, v in TAYLOR_TABLE2.items():
    print(f"  {k:32s} {v:g}")
print(f"derived: E = {mat.E / 1e9:.1f} GPa, nu = {mat.nu:.3f}, c_L = sqrt((K + 4G/3)/rho) = {mat.c_longitudinal:.0f} m/s, "
      f"c_bar = sqrt(E/rho) = {mat.c0:.0f} m/s")
assert abs(mat.G - TAYLOR_TABLE1["shear_modulus_Pa"]) < 1e-6 * mat.G
assert abs(mat.K - TAYLOR_TABLE1["bulk_modulus_Pa"]) < 1e-6 * mat.K

h_paper = TAYLOR_TABLE2["smoothing_length_m"]
dt_cfl = 0.3 * h_paper / (mat.c_longitudinal + V0)
print(f"h / dp = {h_paper / TAYLOR_TABLE2['particle_spacing_m']:.2f}; CFL step at dp = 0.5 mm (Courant 0.3, "
      f"c_L + v0): {dt_cfl:.2e} s; Table 2's fixed dt = {TAYLOR_TABLE2['time_step_s']:.0e} s is Courant "
      f"{0.3 * TAYLOR_TABLE2['time_step_s'] / dt_cfl:.3f}")
M_body = mat.rho0 * math.pi * R0**2 * L0
print(f"bar: mass {1e3 * M_body:.2f} g, momentum {M_body * V0:.3f} N s, kinetic energy {0.5 * M_body * V0**2:.0f} J; "
      f"the elastic impact stress rho c_L v0 = {mat.rho0 * mat.c_longitudinal * V0 / 1e9:.1f} GPa "
      f"is {mat.rho0 * mat.c_longitudinal * V0 / jc.A:.0f} x the yield stress A")

# %% [markdown]
# The impact stress is many times the yield stress: the front end flows plastically at once. A plastic front
# runs up the bar, slows down, and stops after a few tens of microseconds; the elastic rest of the bar is
# decelerated by the elastic waves ringing between the front and the free end.
#
# ### Particles on rings
#
# The 3D model is a **quarter** of the cylinder ($x\ge0$, $y\ge0$, axis along $z$, wall at $z=0$). The particles
# of a cross-section sit on rings: ring $k$ at radius $r_k = (k+\tfrac12)\,\Delta r$ with
# $\Delta r = R/\mathrm{round}(R/\Delta p)$ carries $n_k = \mathrm{round}(\tfrac{\pi}{2} r_k/\Delta r)$ particles,
# evenly spread over the quarter circle; the layers are $\Delta z = L/\mathrm{round}(L/\Delta p)$ apart. Each particle
# gets the exact volume of its cell, $\tfrac{\pi}{2}r_k\Delta r\,\Delta z/n_k$, so the model has the cylinder's mass
# exactly, and the outer ring sits half a spacing inside the true surface — just as the outer row of a lattice
# sits half a spacing inside a flat face.
#
# Why not a cubic lattice cut to a circle? Its surface is a staircase. Wherever the circle passes close to a
# lattice centre, that centre lies almost on the circle itself, not half a spacing inside it. Measured as
# "outermost centre plus half a spacing" (below), the diameter then starts too large. A plain version of the ring
# construction first, checked against `taylor_particles`:

# %%
def plain_rings(dp, R, L, sector=0.5 * math.pi):
    """Ring layout by plain loops: (centres, volumes, dr, dz)."""
    nr, nz = max(1, round(R / dp)), max(1, round(L / dp))
    dr, dz = R / nr, L / nz
    section = []                                       # (x, y, area) of one layer
    for k in range(nr):
        r = (k + 0.5) * dr
        nk = max(1, round(sector * r / dr))
        for j in range(nk):
            th = (j + 0.5) * sector / nk
            section.append((r * math.cos(th), r * math.sin(th), sector * r * dr / nk))
    pts, vol = [], []
    for iz in range(nz):
        for x, y, a in section:
            pts.append((x, y, (iz + 0.5) * dz))
            vol.append(a * dz)
    return np.array(pts), np.array(vol), dr, dz


def cut_lattice_section(dp, R):
    """A square lattice (cell centres) in the quarter plane, cut to the circle r <= R."""
    c = (np.arange(int(R / dp) + 2) + 0.5) * dp
    X, Y = np.meshgrid(c, c, indexing="ij")
    keep = np.hypot(X, Y) <= R
    return np.stack([X[keep], Y[keep]], axis=1)


for dp in (1.0e-3, 0.75e-3, 0.5e-3):
    x_p, v_p, dr_p, dz_p = plain_rings(dp, R0, L0)
    x_k, v_k, dr_k, dz_k = taylor_particles(3, dp, True, L0, D0)
    assert np.allclose(x_p, x_k, rtol=0, atol=1e-15) and np.allclose(v_p, v_k, rtol=1e-13)
    assert dr_p == dr_k and dz_p == dz_k
    sec = x_k[x_k[:, 2] == x_k[0, 2]]                  # one layer
    lat = cut_lattice_section(dp, R0)
    D_rings = 2 * (np.hypot(sec[:, 0], sec[:, 1]).max() + 0.5 * dr_k)
    D_lat = 2 * (np.hypot(lat[:, 0], lat[:, 1]).max() + 0.5 * dp)
    print(f"dp = {1e3 * dp:4.2f} mm: rings {round(R0 / dp)} x {len(sec)} particles per layer, {len(x_k)} in the quarter;"
          f" measured D at t = 0: rings {1e3 * D_rings:.3f} mm ({100 * (D_rings / D0 - 1):+.1f} %), cut lattice "
          f"{1e3 * D_lat:.3f} mm ({100 * (D_lat / D0 - 1):+.1f} %), lattice area / circle "
          f"{len(lat) * dp * dp / (0.25 * math.pi * R0**2):.3f}")

# %%
dp_show = 0.5e-3
x_show, _, dr_show, _ = taylor_particles(3, dp_show, True, L0, D0)
sec_show = x_show[x_show[:, 2] == x_show[0, 2]]
lat_show = cut_lattice_section(dp_show, R0)
th = np.linspace(0, 0.5 * math.pi, 200)
fig, axes = plt.subplots(1, 2, figsize=(10, 5), constrained_layout=True)
for ax, pts, d_half, title in ((axes[0], sec_show, 0.5 * dr_show, "rings (refsph)"),
                               (axes[1], lat_show, 0.5 * dp_show, "square lattice cut to the circle")):
    r_max = np.hypot(pts[:, 0], pts[:, 1]).max()
    ax.plot(1e3 * pts[:, 0], 1e3 * pts[:, 1], "k.", ms=6)
    ax.plot(1e3 * R0 * np.cos(th), 1e3 * R0 * np.sin(th), "C2-", label=f"the cylinder, R = {1e3 * R0:.4f} mm")
    ax.plot(1e3 * (r_max + d_half) * np.cos(th), 1e3 * (r_max + d_half) * np.sin(th), "C3--",
            label=f"measured: max r + half a spacing ({100 * ((r_max + d_half) / R0 - 1):+.1f} %)")
    ax.set_aspect("equal")
    ax.set_xlim(0, 4.6)
    ax.set_ylim(0, 4.6)
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(f"{title}\ndp = {1e3 * dp_show} mm, {len(pts)} particles per quarter layer", fontsize=10)
    ax.legend(fontsize=8, loc="upper right")
fig.savefig(FIG / "06_rings.png", dpi=120)
plt.show()

# %% [markdown]
# With rings the measured diameter is exactly 7.595 mm at $t=0$; the cut lattice starts several percent too
# large (printed above) — as large as the 5 % within which we want to match the experiment.
#
# In **2D** (plane strain) the model is the section through the axis, a slab 7.595 mm wide and infinitely long
# out of plane, on a plain lattice with $\Delta x = R/\mathrm{round}(R/\Delta p)$, $\Delta z$ as in 3D. The half model
# keeps $x\ge0$.
#
# ### Measuring length and diameter
#
# A particle is a cell around its centre, so the body's face is half a spacing beyond the outermost centres:
#
# $$L = \max_i z_i - \min_i z_i + \Delta z,\qquad D = 2\left(\max_i r_i + \tfrac12\Delta r\right),\quad
# r_i = \sqrt{x_i^2+y_i^2}\ \ (\text{2D: } r_i = |x_i|).$$
#
# $D$ is the largest diameter of the bar, which after the impact is the foot of the mushroom. In 2D "$D$" is the
# width of the slab. Plain loops against `bar_length` / `bar_diameter`, and the values at $t=0$:

# %%
def plain_length(x, dz):
    zmin, zmax = math.inf, -math.inf
    for p in x:
        zmin, zmax = min(zmin, p[-1]), max(zmax, p[-1])
    return (zmax + 0.5 * dz) - (zmin - 0.5 * dz)


def plain_diameter(x, dr):
    rmax = 0.0
    for p in x:
        rmax = max(rmax, math.sqrt(sum(c * c for c in p[:-1])))
    return 2.0 * (rmax + 0.5 * dr)


scene = get_scene("taylor")
rng = np.random.default_rng(6)
for dim, dp, sym in ((2, 0.5e-3, True), (2, 0.5e-3, False), (2, 0.25e-3, True), (3, 1e-3, True),
                     (3, 0.5e-3, True), (3, 1e-3, False)):
    st = scene.setup(dim, dp, True, symmetry=sym)
    info, x = st.info, st.state.x
    L_meas, D_meas = bar_length(x, info["dz"]), bar_diameter(x, info["dr"])
    assert abs(L_meas - L0) < 1e-12 and abs(D_meas - D0) < 1e-12          # exact at t = 0
    x_moved = x + 1e-4 * rng.normal(size=x.shape)                           # any configuration
    assert abs(plain_length(x_moved, info["dz"]) - bar_length(x_moved, info["dz"])) < 1e-15
    assert abs(plain_diameter(x_moved, info["dr"]) - bar_diameter(x_moved, info["dr"])) < 1e-15
    # mass: the model's mass is its share of the cylinder's (2D: per metre of thickness)
    fraction = info["model_fraction_inverse"]
    m_exact = mat.rho0 * (math.pi * R0**2 * L0 if dim == 3 else D0 * L0) / fraction
    m_model = float(st.state.m.sum())
    assert abs(m_model / m_exact - 1) < 1e-12
    unit = "kg" if dim == 3 else "kg/m"
    print(f"{dim}D {info['model']:7s} dp = {1e3 * dp:4.2f} mm: {st.state.n:6d} particles, dr = {1e3 * info['dr']:.4f} mm, "
          f"dz = {1e3 * info['dz']:.4f} mm;  L = {1e3 * L_meas:.4f} mm, D = {1e3 * D_meas:.4f} mm;  mass "
          f"{m_model:.6g} {unit} = rho x {'pi R^2 L' if dim == 3 else 'D L'} / {fraction:g}")

# %% [markdown]
# ### Symmetry planes: mirror ghosts
#
# The quarter model has two symmetry planes, $x=0$ and $y=0$ (the 2D half model one, $x=0$). Each is imposed
# with **mirror ghost particles** (Libersky et al. 1993): every particle within the kernel's reach of a plane gets
# an image on the other side,
#
# $$\mathbf{x}_g = \mathbf{R}\mathbf{x}_s,\quad \mathbf{v}_g = \mathbf{R}\mathbf{v}_s,\quad
# \mathbf{S}_g = \mathbf{R}\mathbf{S}_s\mathbf{R},\quad \mathbf{F}_g = \mathbf{R}\mathbf{F}_s\mathbf{R}\ \text{(TLSPH)},\quad
# m_g = m_s,\ \rho_g=\rho_s,$$
#
# with $\mathbf{R} = \mathrm{diag}(\pm1)$ flipping the axis normal to the plane. A particle near *both* planes
# also gets the image through the edge ($\mathbf{R}$ flips $x$ and $y$) — without it the particles near the
# axis would miss a quarter of their neighbours. The ghosts enter the SPH sums of the real particles exactly
# as the missing three quarters of the body would; their own rates are never used. In TLSPH the ghosts are
# images of the reference configuration and are fixed with the operator; a ghost's $\mathbf{F}$ is the image of
# its source's (its own neighbourhood is cut off, so it could not be computed from its neighbours).
#
# Plain loops against `MirrorPlanes.ghosts` and `Ghosts.extend_state`, on the quarter model with random
# velocities, stresses and deformation gradients:

# %%
def plain_ghosts(x, axes, cutoff):
    """{(source, signs): None} for every image: one per non-empty set of planes the particle is near."""
    out = []
    for i in range(len(x)):
        for k in range(1, len(axes) + 1):
            for subset in combinations(axes, k):
                if all(x[i][a] < cutoff for a in subset):
                    sign = [1.0] * x.shape[1]
                    for a in subset:
                        sign[a] = -1.0
                    out.append((i, tuple(sign)))
    return out


for dim, dp in ((3, 1e-3), (2, 0.5e-3)):
    st = scene.setup(dim, dp, True).state
    n, d = st.x.shape
    st.v = rng.normal(scale=50.0, size=(n, d))
    A = rng.normal(scale=1e8, size=(n, d, d))
    st.S = A + np.swapaxes(A, 1, 2)
    h = 1.5 * dp
    mirror = MirrorPlanes(tuple(range(d - 1)))
    g = mirror.ghosts(st.x, 2 * h)
    ext = g.extend_state(st)
    plain = plain_ghosts(st.x, tuple(range(d - 1)), 2 * h)
    pkg = [(int(s), tuple(sg)) for s, sg in zip(g.src, g.sign)]
    assert sorted(plain) == sorted(pkg) and len(set(pkg)) == len(pkg)
    F = np.eye(d) + 0.1 * rng.normal(size=(n, d, d))
    F_ghost = g.tensors(F)
    for k, (s, sign) in enumerate(pkg):
        Rm = np.diag(sign)
        gk = n + k
        assert np.array_equal(ext.x[gk], Rm @ st.x[s]) and np.array_equal(ext.v[gk], Rm @ st.v[s])
        assert np.array_equal(ext.X[gk], Rm @ st.X[s])
        assert np.allclose(ext.S[gk], Rm @ st.S[s] @ Rm, rtol=0, atol=0)
        assert np.allclose(F_ghost[k], Rm @ F[s] @ Rm, rtol=0, atol=0)
        assert ext.m[gk] == st.m[s] and ext.rho[gk] == st.rho[s] and ext.V0[gk] == st.V0[s]
    assert np.array_equal(ext.x[:n], st.x)
    kinds = {}
    for _, sign in pkg:
        key = "edge (x and y)" if sign.count(-1.0) == 2 else ("plane x = 0" if sign[0] < 0 else "plane y = 0")
        kinds[key] = kinds.get(key, 0) + 1
    print(f"{dim}D, dp = {1e3 * dp} mm, cutoff 2h = {1e3 * 2 * h} mm: {n} real particles, {g.n} ghosts "
          f"({', '.join(f'{v} {k}' for k, v in kinds.items())}) -- plain loops == package")

# %% [markdown]
# Through the ghosts a symmetry plane gets what symmetry demands: no normal velocity across it (a particle and
# its image approach the plane at the same speed), no shear traction on it, and the normal traction the other
# half would exert. One more check, with the solver itself: a deformation that respects the symmetry (here an
# affine stretch $\mathbf{x} = \mathbf{A}\mathbf{X}$ with diagonal $\mathbf{A}$) must give $\mathbf{F}=\mathbf{A}$ at
# *every* particle of the quarter model, also next to the planes and on the axis — only if the ghosts supply the
# missing neighbours correctly.

# %%
setup_q = scene.setup(3, 1e-3, True)
solver_q = make_solver("tlsph", setup_q)
st_q = setup_q.state.copy()
A_st = np.diag([1.05, 1.02, 0.93])
st_q.x = st_q.X @ A_st.T
F_q = solver_q.deformation_gradient(st_q)
err_F = np.abs(F_q - A_st).max()
print(f"TLSPH quarter model, x = A X: max |F - A| over all {st_q.n} particles = {err_F:.1e}")
assert err_F < 1e-12

# %% [markdown]
# ### The wall
#
# The paper says only "rigid wall, frictionless". `refsph` imposes it as a **unilateral kinematic constraint**
# (`RigidWall`) at the end of every stage of the predictor–corrector step (before the plastic return map): a
# particle whose centre would come closer than half a spacing to the wall within the step, $z_i + \Delta t\,v_{z,i} <
# \tfrac12\Delta z$, while moving towards it ($v_{z,i}<0$), gets $v_{z,i}\leftarrow 0$; every centre is kept at
# $z_i \ge \tfrac12\Delta z$ (so the body's face, centre minus half a spacing, touches the wall). The tangential
# velocity is untouched — no friction — and a particle moving away is left alone, so the bar can rebound.
# The wall's impulse is $\sum_i m_i\,(v_{z,i}^{\rm after} - v_{z,i}^{\rm before})$. A plain version:

# %%
def plain_wall(x, v, m, dt, c, gap, axis):
    x, v = x.copy(), v.copy()
    impulse = 0.0
    for i in range(len(x)):
        if v[i, axis] < 0.0 and x[i, axis] + dt * v[i, axis] < c + gap:
            impulse += -m[i] * v[i, axis]
            v[i, axis] = 0.0
        x[i, axis] = max(x[i, axis], c + gap)
    return x, v, impulse


n_w = 400
x_w = np.column_stack([rng.uniform(0, 4e-3, n_w), rng.uniform(0, 4e-3, n_w), rng.uniform(0.0, 1.5e-3, n_w)])
st_w = make_state(x_w, rng.normal(scale=100.0, size=(n_w, 3)), mat.rho0, np.full(n_w, 1e-9))
wall = RigidWall(axis=2, position=0.0, gap=0.25e-3)
x_ref, v_ref, imp_ref = plain_wall(st_w.x, st_w.v, st_w.m, 5e-6, 0.0, 0.25e-3, 2)
imp = wall.apply(st_w, 5e-6)
assert np.array_equal(st_w.x, x_ref) and np.array_equal(st_w.v, v_ref) and abs(imp - imp_ref) < 1e-15 * abs(imp_ref)
print(f"wall: {int(np.sum(v_ref[:, 2] == 0))} of {n_w} random particles stopped, impulse {imp:.3e} N s "
      f"-- plain loop == RigidWall.apply")

# %% [markdown]
# It is the simplest wall a Taylor test needs: it takes exactly the momentum it removes (checked on whole runs
# below), and it cannot pull, so the bar leaves the wall when it rebounds.
#
# ## 2. The symmetry planes, checked: half model against the whole body
#
# The strongest test of the ghosts is to leave them out: the 2D **whole** slab (`symmetry=False`, no ghosts,
# twice the particles) must do exactly what the **half** model does on $x \ge 0$. Both are run for a short time
# (printed below; long enough for the wall impact, the plastic flow and, in TLSPH, a reference update), with both
# methods; the particles of the half model are matched to those of the whole body by their initial positions.

# %%
SYM_T = 12e-6 if QUICK else 20e-6                      # long enough for a TLSPH reference update (asserted)
sym_rows = []
for method in METHODS:
    pair = {}
    for sym in (True, False):
        t0 = time.perf_counter()
        r = run("taylor", method, dim=2, dp=0.5e-3, t_end=SYM_T, progress=False, options=dict(symmetry=sym))
        pair[sym] = (r, time.perf_counter() - t0)
    (rh, wh), (rw, ww) = pair[True], pair[False]
    sh, sw = rh.state, rw.state
    dist, idx = cKDTree(rw.setup.state.x).query(rh.setup.state.x)       # half particle -> same whole particle
    assert dist.max() < 1e-12
    Lh, Dh = bar_length(sh.x, rh.setup.info["dz"]), bar_diameter(sh.x, rh.setup.info["dr"])
    Lw, Dw = bar_length(sw.x, rw.setup.info["dz"]), bar_diameter(sw.x, rw.setup.info["dr"])
    row = dict(method=method, Lh=Lh, Lw=Lw, Dh=Dh, Dw=Dw, nh=sh.n, nw=sw.n, wh=wh, ww=ww,
               dx=np.abs(sh.x - sw.x[idx]).max() / 0.5e-3, deps=np.abs(sh.eps_p - sw.eps_p[idx]).max(),
               dT=np.abs(sh.T - sw.T[idx]).max(),
               # the whole body must stay mirror-symmetric about x = 0
               asym=np.abs(sw.x - sw.x[cKDTree(rw.setup.state.x).query(rw.setup.state.x * [-1, 1])[1]]
                           * [-1, 1]).max() / 0.5e-3,
               refs=rh.summary["diagnostics"].get("reference_updates"))
    sym_rows.append(row)

print(f"2D plane strain, dp = 0.5 mm, t = {1e6 * SYM_T:.0f} us: half model (mirror ghosts) vs whole body")
print(f"{'':6s} {'L half':>10s} {'L whole':>10s} {'D half':>10s} {'D whole':>10s} {'|dL| mm':>8s} {'|dD| mm':>8s} "
      f"{'max|dx|/dp':>10s} {'max|d eps_p|':>12s} {'max|dT| K':>9s} {'whole asym/dp':>13s} {'s half/whole':>13s}")
for r in sym_rows:
    assert r["method"] == "esph" or r["refs"] >= 1      # the check must include a reference update
    print(f"{r['method']:6s} {1e3 * r['Lh']:10.5f} {1e3 * r['Lw']:10.5f} {1e3 * r['Dh']:10.5f} {1e3 * r['Dw']:10.5f} "
          f"{1e3 * abs(r['Lh'] - r['Lw']):8.1e} {1e3 * abs(r['Dh'] - r['Dw']):8.1e} {r['dx']:10.1e} {r['deps']:12.1e} "
          f"{r['dT']:9.1e} {r['asym']:13.1e} {r['wh']:6.1f}/{r['ww']:.1f}")
    # stated tolerance: 1e-6 mm on L and D, 1e-6 dp on every position (round-off gives ~1e-11)
    assert abs(r["Lh"] - r["Lw"]) < 1e-9 and abs(r["Dh"] - r["Dw"]) < 1e-9
    assert r["dx"] < 1e-6 and r["deps"] < 1e-6
print(f"TLSPH half model: {sym_rows[1]['refs']} reference update(s) in {1e6 * SYM_T:.0f} us")
print("tolerance: |dL|, |dD| < 1e-6 mm and every particle within 1e-6 dp of its twin -- passed")

# %% [markdown]
# The half model reproduces the whole body particle by particle, to round-off (the columns `max|dx|/dp`,
# `max|d eps_p|`), for both methods, through the impact, the plastic flow and (TLSPH) the reference update. The
# stated tolerance (10⁻⁶ mm on $L$ and $D$, 10⁻⁶ spacings per particle) is far above the round-off and far below
# anything physical; a wrong sign in $\mathbf{R}\mathbf{S}\mathbf{R}$, a missing edge ghost or a ghost that lags its
# source would break it by many orders of magnitude. The same construction in 3D adds the second plane and the
# edge ghosts, which the plain-loop check and the affine test above cover.
#
# ## 3. The quick teaching case: 2D plane strain
#
# Both methods, the half model, the full 80 µs (the bar is at rest and has left the wall well before that), at
# the spacing printed below. Snapshots at 15 and 30 µs (the times of Figs. 4–5) are written to a temporary
# folder.

# %%
res2 = {}
for method in METHODS:
    t0 = time.perf_counter()
    res2[method] = run("taylor", method, dim=2, dp=DP_2D, out=TMP / f"2d_{method}", progress=False)
    s = res2[method].summary
    print(f"2D {method.upper():5s}: dp = {1e3 * DP_2D} mm, {s['n_particles']} particles "
          f"(+{s['diagnostics']['n_ghosts']} ghosts), {s['n_steps']} steps (CFL dt up to {s['dt_max']:.2e} s), "
          f"{s['diagnostics'].get('reference_updates', 0)} reference updates, {time.perf_counter() - t0:.1f} s")

# %%
print(f"{'':24s} {'final L [mm]':>12s} {'vs exp':>8s} {'final D [mm]':>12s} {'vs exp':>8s}   (2D: D is a width)")
for k, label in (("experiment", "experiment (3D bar)"), ("ls_dyna", "LS-DYNA (3D)"), ("paper_esph", "paper ESPH (3D)"),
                 ("paper_tlsph", "paper TLSPH (3D)")):
    Lr, Dr = TAYLOR_RESULTS["final_length_mm"][k], TAYLOR_RESULTS["final_diameter_mm"][k]
    print(f"{label:24s} {Lr:12.2f} {100 * (Lr / L_EXP - 1):+7.1f}% {Dr:12.2f} {100 * (Dr / D_EXP - 1):+7.1f}%")
for method in METHODS:
    mt = res2[method].summary["metrics"]
    print(f"{'refsph 2D ' + method.upper():24s} {mt['final_length_mm']:12.2f} "
          f"{100 * (mt['final_length_mm'] / L_EXP - 1):+7.1f}% {mt['final_diameter_mm']:12.2f} "
          f"{100 * (mt['final_diameter_mm'] / D_EXP - 1):+7.1f}%")
for method in METHODS:
    mt = res2[method].summary["metrics"]
    print(f"2D {method.upper():5s}: max eps_p {mt['max_plastic_strain']:.2f}, max T {mt['max_temperature_K']:.0f} K, "
          f"plastic work {mt['plastic_work_whole_body'] / 1e3:.1f} kJ/m = "
          f"{mt['plastic_work_whole_body'] / (0.5 * mat.rho0 * D0 * L0 * V0**2):.2f}"
          f" of the initial kinetic energy, at rest from {1e6 * mt['rest_time_s']:.0f} us, final length "
          f"oscillation +-{mt['length_oscillation_mm']:.3f} mm")

# %% [markdown]
# **Why plane strain cannot match the experiment.** The 2D model is not a cylinder but a slab, infinitely long
# out of the plane. Its front end can spread sideways in one direction only ($x$); the cylinder's spreads in
# every radial direction. Plastic flow keeps the volume, so the slab must push the shortened material out along
# $x$ alone: there is no hoop direction to take up part of it. The constraint $\dot\varepsilon_{zz}=0$ out of plane
# (an out-of-plane stress $s_{zz}$ builds up) also makes the slab stiffer against shortening: for a von Mises
# material the axial stress needed to make it flow is $2/\sqrt3 \approx 1.15$ times the uniaxial yield stress
# (plane-strain compression). Its "diameter" is a width. So the 2D numbers are printed next to the
# experiment only to show the size of the difference (see the table above), not as a validation. The quick 2D
# case is for the mechanics: the wall, the plastic front, the rebound, the fields, and the two methods side by side.
#
# ### Length and width against time

# %%
fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), constrained_layout=True)
for method in METHODS:
    hh = res2[method].history
    t_us = 1e6 * np.asarray(hh["t"])
    axes[0].plot(t_us, 1e3 * np.asarray(hh["length"]), color=COL[method], label=f"2D {method.upper()}")
    axes[1].plot(t_us, 1e3 * np.asarray(hh["diameter"]), color=COL[method], label=f"2D {method.upper()}")
for ax, key, lab in ((axes[0], "final_length_mm", "length"), (axes[1], "final_diameter_mm", "width / diameter")):
    ax.axhline(TAYLOR_RESULTS[key]["experiment"], color="k", ls=":", label="experiment, final (3D bar)")
    ax.axhline(TAYLOR_RESULTS[key]["ls_dyna"], color="0.5", ls="-.", label="LS-DYNA, final (3D)")
    ax.set_xlabel("t [us]")
    ax.set_ylabel(f"{lab} [mm]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
axes[0].set_title(f"2D plane strain, half model, dp = {1e3 * DP_2D} mm: length")
axes[1].set_title("2D plane strain: width of the foot (the 2D 'diameter')")
fig.savefig(FIG / "06_2d_history.png", dpi=120)
plt.show()

# %% [markdown]
# The length falls fast at first (the end moves at nearly 181 m/s), then slower as the plastic front slows down
# and the rear of the bar is braked; it stops, and the bar rings in its free axial mode after it has left the
# wall (the small wiggle at the end; the final length is the mean over the last 30 µs). The width grows while the
# foot flows outward along the wall.
#
# ### Plastic strain and temperature at 15 and 30 µs
#
# The half model, mirrored to $x<0$ to show the whole section (cf. Figs. 4–5 of the paper, which are 3D).

# %%
snaps2, snaps_all = {}, {}
for method in METHODS:
    _, paths = load_run(TMP / f"2d_{method}")
    snaps_all[method] = [load_snapshot(p) for p in paths]
    snaps2[method] = [min(snaps_all[method], key=lambda z: abs(z["t"] - tt)) for tt in (15e-6, 30e-6)]
panels = [(m, k) for m in METHODS for k in range(2)]
vmax = dict(eps_p=max(snaps2[m][k]["eps_p"].max() for m, k in panels),
            T=max(snaps2[m][k]["T"].max() for m, k in panels))
fig, axes = plt.subplots(2, 4, figsize=(12, 10), constrained_layout=True, sharex=True, sharey=True)
for row, (key, lab, cmap, vmin) in enumerate((("eps_p", "effective plastic strain", "viridis", 0.0),
                                             ("T", "temperature [K]", "inferno", jc.T_room))):
    for col, (method, k) in enumerate(panels):
        z = snaps2[method][k]
        x = z["x"]
        ax = axes[row, col]
        sc = ax.scatter(1e3 * np.concatenate([x[:, 0], -x[:, 0]]), 1e3 * np.concatenate([x[:, 1], x[:, 1]]),
                        c=np.concatenate([z[key], z[key]]), s=6 if QUICK else 2, cmap=cmap, vmin=vmin, vmax=vmax[key])
        ax.set_aspect("equal")
        ax.set_ylim(0, 20)
        ax.set_title(f"{method.upper()}, t = {1e6 * z['t']:.1f} us", fontsize=10)
        if row == 1:
            ax.set_xlabel("x [mm]")
        if col == 0:
            ax.set_ylabel("z [mm]")
    fig.colorbar(sc, ax=axes[row, :], shrink=0.8, label=lab)
fig.suptitle(f"2D plane strain, dp = {1e3 * DP_2D} mm: the lower 20 mm of the section (half model, mirrored)")
fig.savefig(FIG / "06_2d_fields.png", dpi=120)
plt.show()
for method, k in panels:
    z = snaps2[method][k]
    print(f"{method.upper():5s} t = {1e6 * z['t']:5.1f} us: max eps_p {z['eps_p'].max():.2f}, max T {z['T'].max():.0f} K, "
          f"plastic zone (eps_p > 0.01) up to z = {1e3 * z['x'][z['eps_p'] > 0.01, 1].max():.1f} mm")

# %% [markdown]
# The plastic strain (and with it the temperature: $\Delta T$ is proportional to the plastic work) is largest at the
# wall, in the centre of the foot, and falls off towards the rear. Between 15 and 30 µs the plastic zone grows
# little while the strain at the wall still grows (printed above); the printed peak values also show how close
# the two methods come.
#
# ### The wall impulse and the rebound
#
# The wall is the only external force along $z$, and every internal force — the SPH pair forces and the forces
# of the mirror ghosts (a symmetry plane pushes only along its normal) — cancels in the sum. So the wall impulse
# must equal the change of the body's momentum *exactly*. It exceeds the initial momentum $m v_0$: the wall
# first stops the bar and then pushes it back (the rebound).

# %%
for method in METHODS:
    r = res2[method]
    s0, s1 = r.setup.state, r.state
    P0 = float(np.sum(s0.m * s0.v[:, 1]))                  # per metre of thickness, half model
    P1 = float(np.sum(s1.m * s1.v[:, 1]))
    J_wall = r.summary["diagnostics"]["wall_impulse"][0]
    assert abs(P1 - P0 - J_wall) < 1e-9 * abs(P0)
    print(f"2D {method.upper():5s}: wall impulse / initial momentum = {J_wall / abs(P0):.4f};  rebound velocity "
          f"{P1 / np.sum(s1.m):+.1f} m/s (= {P1 / abs(P0):.3f} v0);  |P1 - P0 - impulse| / |P0| = "
          f"{abs(P1 - P0 - J_wall) / abs(P0):.1e};  final KE / initial "
          f"{r.summary['metrics']['kinetic_energy_final_over_initial']:.4f}")

# %% [markdown]
# ## 4. The 3D quarter model
#
# The quarter model with both methods at the spacing printed below: in quick mode a coarse 1 mm (few rings across
# the radius, see Section 5), in full mode the paper's 0.5 mm.

# %%
res3 = {}
for method in METHODS:
    t0 = time.perf_counter()
    res3[method] = run("taylor", method, dim=3, dp=DP_3D, progress=False)
    s = res3[method].summary
    print(f"3D {method.upper():5s}: dp = {1e3 * DP_3D} mm, {s['n_particles']} particles "
          f"(+{s['diagnostics']['n_ghosts']} ghosts), {s['n_steps']} steps, "
          f"{s['diagnostics'].get('reference_updates', 0)} reference updates, {time.perf_counter() - t0:.1f} s")
print()
print(comparison_table([res3[m].summary for m in METHODS]))

# %%
for method in METHODS:
    r = res3[method]
    s0, s1 = r.setup.state, r.state
    P0, P1 = float(np.sum(s0.m * s0.v[:, 2])), float(np.sum(s1.m * s1.v[:, 2]))
    J_wall = r.summary["diagnostics"]["wall_impulse"][0]
    assert abs(P1 - P0 - J_wall) < 1e-9 * abs(P0)
    mt = r.summary["metrics"]
    print(f"3D {method.upper():5s}: wall impulse / initial momentum = {J_wall / abs(P0):.4f}; plastic work "
          f"{mt['plastic_work_whole_body']:.0f} J = {mt['plastic_work_whole_body'] / (0.5 * M_body * V0**2):.2f} of the kinetic energy; "
          f"final length oscillation +-{mt['length_oscillation_mm']:.3f} mm")

fig, ax_d = plt.subplot_mosaic([["L", "esph", "tlsph"], ["D", "esph", "tlsph"]], figsize=(13, 7.5),
                                constrained_layout=True, gridspec_kw=dict(width_ratios=[1.6, 1, 1]))
for method in METHODS:
    hh = res3[method].history
    t_us = 1e6 * np.asarray(hh["t"])
    ax_d["L"].plot(t_us, 1e3 * np.asarray(hh["length"]), color=COL[method], label=f"3D {method.upper()}")
    ax_d["D"].plot(t_us, 1e3 * np.asarray(hh["diameter"]), color=COL[method], label=f"3D {method.upper()}")
for key, lab in (("L", "final_length_mm"), ("D", "final_diameter_mm")):
    ax_d[key].axhline(TAYLOR_RESULTS[lab]["experiment"], color="k", ls=":", label="experiment, final")
    ax_d[key].axhline(TAYLOR_RESULTS[lab]["ls_dyna"], color="0.5", ls="-.", label="LS-DYNA, final")
    ax_d[key].grid(alpha=0.3)
    ax_d[key].legend(fontsize=8)
ax_d["L"].set_ylabel("length [mm]")
ax_d["D"].set_ylabel("diameter [mm]")
ax_d["D"].set_xlabel("t [us]")
ax_d["L"].set_title(f"3D quarter model, dp = {1e3 * DP_3D} mm")
axes = [None, ax_d["esph"], ax_d["tlsph"]]
vmax3 = max(res3[m].state.eps_p.max() for m in METHODS)
for ax, method in zip(axes[1:], METHODS):
    s = res3[method].state
    r_ = np.hypot(s.x[:, 0], s.x[:, 1])
    order = np.argsort(s.eps_p)
    sc = ax.scatter(1e3 * np.concatenate([r_[order], -r_[order]]), 1e3 * np.concatenate([s.x[order, 2]] * 2),
                    c=np.concatenate([s.eps_p[order]] * 2), s=8 if QUICK else 3, cmap="viridis", vmin=0, vmax=vmax3)
    ax.axvline(0.5 * D_EXP, color="k", ls=":", lw=1)
    ax.axvline(-0.5 * D_EXP, color="k", ls=":", lw=1)
    ax.axhline(L_EXP, color="k", ls=":", lw=1)
    ax.set_aspect("equal")
    ax.set_xlabel("r [mm] (mirrored)")
    ax.set_ylabel("z [mm]")
    ax.set_title(f"3D {method.upper()}, t = {1e6 * s.t:.0f} us: all particles at (r, z)\n"
                 "dotted: experiment's final L and D", fontsize=9)
fig.colorbar(sc, ax=axes[1:], shrink=0.6, label="effective plastic strain")
fig.savefig(FIG / "06_3d_final.png", dpi=120)
plt.show()

# %% [markdown]
# The right panels plot every particle of the final state at its distance from the axis and its height: the
# silhouette of the deformed bar. The comparison table above sets the numbers against the experiment, LS-DYNA
# and the paper; the 2 % (length) and 5 % (diameter) lines are the targets of the project. Section 5 explains
# why the coarse quick-mode spacing is a poor judge of the diameter.
#
# ### The benchmark study (`benchmarks/taylor.py`)
#
# The full 3D study — convergence in the spacing (1.0, 0.75, 0.5 mm), the melting temperature (1293 K as printed,
# 1793 K as usual), the CFL time step against the paper's fixed $\Delta t = 10^{-8}$ s — takes tens of CPU minutes
# and is therefore not run here. `python benchmarks/taylor.py --jobs 2` runs it and writes `benchmarks/taylor.json`
# and three figures; this section shows them if they exist.

# %%
BENCH_JSON = ROOT / "benchmarks" / "taylor.json"
BENCH_FIGS = [ROOT / "figures" / f"06_taylor_{n}.png" for n in ("work_precision", "length_history", "sections")]


def rel(path):
    try:
        return path.relative_to(ROOT)
    except ValueError:
        return path


def bench_tables(records):
    """Print the convergence, T_melt and time-step comparisons from the benchmark records."""
    by_name = {r["name"]: r for r in records}

    def line(r, extra=""):
        return (f"{r['method'].upper():6s} {r['dp_mm']:5.2f} {('%.0e s' % r['dt_s']) if r.get('dt_s') else 'CFL':>8s} "
                f"{r['T_melt_K']:6.0f} {r['final_length_mm']:7.2f} {100 * (r['final_length_mm'] / L_EXP - 1):+6.1f}% "
                f"{r['final_diameter_mm']:7.2f} {100 * (r['final_diameter_mm'] / D_EXP - 1):+6.1f}% "
                f"{r['rest_time_us']:7.1f} {r['max_plastic_strain']:6.2f} {r['max_temperature_K']:6.0f} "
                f"{r['n_particles']:7d} {r['n_steps']:7d} {r['wall_time_s']:8.0f}{extra}")

    head = (f"{'method':6s} {'dp mm':>5s} {'dt':>8s} {'T_m K':>6s} {'L mm':>7s} {'vs exp':>7s} {'D mm':>7s} "
            f"{'vs exp':>7s} {'rest us':>7s} {'eps_p':>6s} {'T K':>6s} {'N':>7s} {'steps':>7s} {'wall s':>8s}")
    print(f"experiment: L = {L_EXP} mm, D = {D_EXP} mm; paper ESPH {TAYLOR_RESULTS['final_length_mm']['paper_esph']} / "
          f"{TAYLOR_RESULTS['final_diameter_mm']['paper_esph']}, paper TLSPH "
          f"{TAYLOR_RESULTS['final_length_mm']['paper_tlsph']} / {TAYLOR_RESULTS['final_diameter_mm']['paper_tlsph']}")
    conv = sorted([r for r in records if r["name"].startswith("conv-")], key=lambda r: (r["method"], -r["dp_mm"]))
    print("\n(a) convergence in the spacing (CFL time step, T_m = 1293 K); wall time on one core")
    print(head)
    for r in conv:
        print(line(r))
    for m in METHODS:
        rs = [r for r in conv if r["method"] == m]
        if len(rs) >= 2:
            print(f"    {m.upper()}: from dp = {rs[0]['dp_mm']:g} to {rs[-1]['dp_mm']:g} mm, L changes by "
                  f"{rs[-1]['final_length_mm'] - rs[0]['final_length_mm']:+.2f} mm, D by "
                  f"{rs[-1]['final_diameter_mm'] - rs[0]['final_diameter_mm']:+.2f} mm, wall time x "
                  f"{rs[-1]['wall_time_s'] / rs[0]['wall_time_s']:.0f}")
    for title, prefix in (("(b) melting temperature: 1293 K (Table 1 as printed) vs 1793 K (usual), dp = 0.5 mm",
                           "tmelt1793-"),
                          ("(c) time step: CFL (Courant 0.3) vs the paper's fixed dt = 1e-8 s, dp = 0.5 mm", "dt1e-8-")):
        print("\n" + title)
        print(head)
        for m in METHODS:
            base, other = by_name.get(f"conv-{m}-0.5mm"), by_name.get(f"{prefix}{m}-0.5mm")
            for r in (base, other):
                if r is not None:
                    print(line(r))
            if base is not None and other is not None:
                print(f"    {m.upper()}: difference L {other['final_length_mm'] - base['final_length_mm']:+.3f} mm, "
                      f"D {other['final_diameter_mm'] - base['final_diameter_mm']:+.3f} mm")
    sens = [r for r in records if r["name"].startswith("sens-")]
    if sens:
        print("\n(d) sensitivity to numerical choices, dp = 0.75 mm (each against the plain run of its method)")
        print(head)
        for r in sens:
            base = by_name.get(f"conv-{r['method']}-0.75mm")
            what = r["name"].split("-")[1]
            print(line(r, f"  {what}"))
            if base is not None:
                print(f"    {r['method'].upper()} {what}: L {r['final_length_mm'] - base['final_length_mm']:+.3f} mm, "
                      f"D {r['final_diameter_mm'] - base['final_diameter_mm']:+.3f} mm against the default numerics")


if BENCH_JSON.exists():
    bench = json.loads(BENCH_JSON.read_text())
    print(f"{rel(BENCH_JSON)}: {len(bench)} runs")
    bench_tables(bench)
else:
    bench = None
    print(f"{rel(BENCH_JSON)} does not exist yet: run  python benchmarks/taylor.py --jobs 2  "
          "(tens of CPU minutes; 'python benchmarks/taylor.py --plot-only' redraws from runs/benchmarks/taylor/)")

# %%
shown = 0
for path in BENCH_FIGS:
    if path.exists():
        img = plt.imread(path)
        fig, ax = plt.subplots(figsize=(img.shape[1] / 100, img.shape[0] / 100))
        ax.imshow(img)
        ax.set_axis_off()
        ax.set_title(f"{rel(path)} (written by benchmarks/taylor.py)", fontsize=9)
        plt.show()
        shown += 1
    else:
        print(f"{rel(path)}: not there yet (made by python benchmarks/taylor.py)")
print(f"{shown} of {len(BENCH_FIGS)} benchmark figures shown")

# %% [markdown]
# ### Against the targets
#
# The project's targets at the paper's spacing (dp = 0.5 mm, 3D): the final length within 2 % and the diameter
# within 5 % of the experiment. The verdict is computed from the benchmark records, not typed in:

# %%
if bench is not None:
    for r in sorted(bench, key=lambda r: (r["name"].split("-")[0], r["method"], -r["dp_mm"])):
        if r["dp_mm"] > 0.5 or not r["name"].startswith("conv-"):
            continue
        eL = 100 * (r["final_length_mm"] / L_EXP - 1)
        eD = 100 * (r["final_diameter_mm"] / D_EXP - 1)
        print(f"{r['method'].upper():6s} dp = {r['dp_mm']:g} mm: length {eL:+.1f} % "
              f"({'met' if abs(eL) < 2 else 'MISSED'}), diameter {eD:+.1f} % ({'met' if abs(eD) < 5 else 'MISSED'})")

# %% [markdown]
# Where a target is missed, the miss is reported, not tuned away. What the numbers say about the two methods:
# ESPH lands close to the experiment at every spacing, TLSPH is stiffer — a longer bar and a narrower foot —
# and approaches the experiment as the spacing shrinks (convergence table (a)). The paper's TLSPH and ESPH
# agree with each other to 0.3 %; refsph's do not. Table (d) tests the suspects one at a time: the artificial
# viscosity (the paper's $\beta_1 = \beta_2 = 1.5$ is large; lowering it widens the foot of *both* methods by a
# similar amount, so it does not explain the gap between them), the TLSPH reference update (forcing frequent
# updates changes little) and the ESPH artificial pressure. What is left is the formulation itself: refsph's TLSPH
# is kernel-gradient corrected (chapter 3; the uncorrected form cannot hold a free surface at rest) and keeps
# neighbours chosen in the undeformed bar, which smooths the strain over the reference support; its error
# falls steadily with the spacing (table (a)), ESPH's moves less. The wall is the same for both methods.
#
# How to read them: `06_taylor_work_precision.png` plots the error of the final length and diameter against the
# wall time, for the three spacings — the cost of accuracy, and whether the error falls as the spacing does
# (see the tables above). `06_taylor_length_history.png` is the counterpart of the paper's Fig. 3.
# `06_taylor_sections.png` shows the plastic strain and temperature on the section through the axis at 15 and
# 30 µs (cf. Figs. 4–5).
#
# ## 5. Where it fails
#
# **(a) ESPH particle disorder.** The paper notes that its ESPH particles are irregular "even with the artificial
# pressure", its TLSPH particles regular. The same shows here. ESPH evaluates its kernels at the current positions:
# in the foot, where the material is sheared strongly and stretched sideways, particles slip past each other
# and bunch up (the tensile instability, chapter 2). TLSPH keeps its reference neighbours, so the rows of
# particles stay rows. A simple measure is the nearest-neighbour distance at the end, relative to the one at
# $t = 0$:

# %%
def nn_distance(x):
    d, _ = cKDTree(x).query(x, k=2)
    return d[:, 1]


fig, axes = plt.subplots(1, 2, figsize=(10, 6), constrained_layout=True, sharey=True)
for label, res in (("2D", res2), ("3D", res3)):
    for method in METHODS:
        s0, s1 = res[method].setup.state, res[method].state
        d0, d1 = nn_distance(s0.x), nn_distance(s1.x)
        print(f"{label} {method.upper():5s}: nearest-neighbour distance at the end / initial minimum: min "
              f"{d1.min() / d0.min():.2f}, 1st percentile {np.percentile(d1, 1) / d0.min():.2f};  "
              f"particles closer than 0.5 x that: {int(np.sum(d1 < 0.5 * d0.min()))}")
for ax, method in zip(axes, METHODS):
    s = res2[method].state
    ax.scatter(1e3 * s.x[:, 0], 1e3 * s.x[:, 1], c=s.eps_p, s=10 if QUICK else 3, cmap="viridis")
    ax.set_aspect("equal")
    ax.set_ylim(0, 10)
    ax.set_xlabel("x [mm]")
    ax.set_title(f"2D {method.upper()}, t = {1e6 * s.t:.0f} us, the foot (colour: eps_p)")
axes[0].set_ylabel("z [mm]")
fig.savefig(FIG / "06_2d_foot_particles.png", dpi=120)
plt.show()

# %% [markdown]
# The measured diameter is set by the outermost particle: a disordered edge makes it noisy. The bar in the
# figure has already rebounded, which is why the lowest row is above the wall.
#
# **(b) Coarse resolution.** The diameter is measured from the outermost particle centre plus half a spacing. The
# true surface can lie anywhere within about half a spacing of that, on each side, so the measured $D$ is
# uncertain by up to one radial spacing $\Delta r$. Compare it with the 5 % target:

# %%
for dp in (1.0e-3, 0.75e-3, 0.5e-3, 0.25e-3):
    pts, _, dr, dz = taylor_particles(3, dp, True, L0, D0)
    print(f"dp = {1e3 * dp:4.2f} mm: {round(R0 / dp)} rings across the radius, dr = {1e3 * dr:.3f} mm = "
          f"{100 * dr / (1e-3 * D_EXP):.1f} % of the experiment's final D; quarter model {len(pts)} particles")

# %% [markdown]
# Compare the printed percentages with the 5 % target: at the paper's spacing the measurement's own resolution is
# of the size of the target, at the quick-mode spacing larger, and whether one particle moves out by one ring
# decides the result. The
# length is better off: $\Delta z$ is a small fraction of 34.6 mm. The convergence table of Section 4 shows how the
# numbers move with the spacing. A smaller spacing costs: the particle count grows as $\Delta p^{-3}$ and the
# number of steps as $\Delta p^{-1}$ (CFL), so the wall time grows as about $\Delta p^{-4}$ (see the wall-time column).
#
# **(c) Explicit hardening lag.** The return map of a step uses the yield stress at the *start* of the step,
# $\sigma_y(\bar\varepsilon_p^{\rm start})$, not at its end (as the paper: explicit). Where the material flows fast
# the yield stress lags behind the hardening by $\sigma_y(\bar\varepsilon_p^{\rm start}+\Delta\bar\varepsilon_p) -
# \sigma_y(\bar\varepsilon_p^{\rm start})$. It is largest where plastic flow starts, because
# $d(\bar\varepsilon_p^{\,n})/d\bar\varepsilon_p$ is unbounded at $\bar\varepsilon_p = 0$ for $n = 0.26$. From the 2D
# snapshots (each holds the plastic strain rate of its last step, $\Delta\bar\varepsilon_p = \dot{\bar\varepsilon}_p\Delta t$):

# %%
for method in METHODS:
    for z in snaps_all[method]:
        if not 0 < z["t"] <= 30.5e-6:
            continue
        dt_step = (res2[method].setup.numerics.courant * res2[method].setup.h
                   / (mat.c_longitudinal + np.sqrt(np.sum(z["v"] ** 2, axis=1)).max()))
        flowing = z["eps_dot_p"] > 0
        deps = z["eps_dot_p"][flowing] * dt_step
        e1, T1, rate = z["eps_p"][flowing], z["T"][flowing], z["eps_dot_p"][flowing]
        sy_end = yield_stress(jc, e1, rate, T1)
        lag = (sy_end - yield_stress(jc, np.maximum(e1 - deps, 0.0), rate, T1)) / sy_end
        print(f"2D {method.upper():5s} t = {1e6 * z['t']:4.1f} us: {int(flowing.sum()):5d} particles flowing, "
              f"max step increment {deps.max() if deps.size else 0:.1e}; yield-stress lag median "
              f"{100 * np.median(lag) if lag.size else 0:.3f} %, max {100 * lag.max() if lag.size else 0:.3f} %")

# %% [markdown]
# The lag grows with the step and with the strain rate: it is largest early, while the plastic front runs. Compare
# the printed percentages with the percent-level differences the comparison tables are about. The paper's fixed
# $\Delta t = 10^{-8}$ s is several times smaller than the CFL step (Section 1), which is one of the things the
# CFL-vs-fixed-$\Delta t$ comparison in Section 4 measures.
#
# **(d) Plane strain** (Section 3): the 2D model is a slab, not a cylinder; it can teach, not validate.
#
# **(e) The melting temperature.** Table 1's $T_m = 1293$ K is almost certainly a typo for 1793 K. It matters
# through the thermal softening factor $1 - T^{*m}$ at the temperatures the bar reaches:

# %%
T_peak = max(res3[m].summary["metrics"]["max_temperature_K"] for m in METHODS)
for T_m in (1293.0, 1793.0):
    Ts = (T_peak - jc.T_room) / (T_m - jc.T_room)
    print(f"T_m = {T_m:.0f} K: at the peak temperature of the 3D runs, {T_peak:.0f} K, T* = {Ts:.3f} and the yield "
          f"stress is multiplied by 1 - T*^m = {1 - Ts**jc.m:.3f}")

# %% [markdown]
# The difference (printed above) matters only where it is hot, in the centre of the foot — a small volume. The benchmark's
# 1293-vs-1793 K comparison (Section 4) shows what it does to the final length and diameter.
#
# **(f) No friction.** The wall is frictionless, as the paper states. The foot slides outward along it without
# resistance; a real anvil holds it back. How far the bottom corner of the bar slid:

# %%
for label, res in (("2D", res2), ("3D", res3)):
    for method in METHODS:
        s0, s1 = res[method].setup.state, res[method].state
        r0 = np.sqrt(np.sum(s0.x[:, :-1] ** 2, axis=1))
        r1 = np.sqrt(np.sum(s1.x[:, :-1] ** 2, axis=1))
        bottom = s0.x[:, -1] == s0.x[:, -1].min()
        corner = np.flatnonzero(bottom)[np.argmax(r0[bottom])]
        print(f"{label} {method.upper():5s}: the particle at the outer bottom corner moved outward by "
              f"{1e3 * (r1[corner] - r0[corner]):.2f} mm (from r = {1e3 * r0[corner]:.2f} to {1e3 * r1[corner]:.2f} mm)")

# %% [markdown]
# With friction that slide would be shorter and the foot narrower; the paper and `refsph` both leave it out,
# so both are expected to err towards a large foot diameter on that account. Proper contact (tools, friction)
# comes with the machining scenes.
#
# ## Summary
#
# * The Taylor bar is modelled as a quarter cylinder (3D) or a half slab (2D) with mirror ghosts on the symmetry
#   planes and a unilateral kinematic wall. Particles sit on rings, so the measured length, diameter and mass are
#   exact at $t = 0$.
# * The mirror ghosts are checked by plain loops, by an affine deformation, and by running the half model against
#   the whole body: they agree particle by particle to round-off. The wall impulse equals the body's change of
#   momentum to round-off, and exceeds the initial momentum because the bar rebounds.
# * 2D plane strain is the quick teaching case; it cannot match the experiment (a slab is not a cylinder).
# * The 3D quarter model is compared with the experiment, LS-DYNA and the paper in the table of Section 4; the
#   benchmark gives convergence, the melting-temperature and the time-step comparisons.
# * Limits: ESPH disorder in the foot, the diameter's resolution of about one spacing, the explicit hardening
#   lag, plane strain, the $T_m$ typo, no friction.

# %%
shutil.rmtree(TMP, ignore_errors=True)
print(f"chapter wall time: {time.perf_counter() - T_START:.1f} s (quick mode: {QUICK})")
