"""Metal pressing (Section 3.2, Tables 3-4): an AISI 4340 block 1.0 x 0.5 mm, its left side fixed, pressed from
the free right side by a rigid tool 0.1 x 0.7 mm moving at 200 m/s.

Model (2D plane strain; the paper's run is a 3D slab 0.1 mm thick, whose mid-plane this is):

* **Block**: [0, 1.0] x [0, 0.5] mm on a lattice of spacings dx = 1.0 mm / round(1.0 mm / dp) and
  dy = 0.5 mm / round(0.5 mm / dp), so the block has its exact size and mass at every dp (the paper's
  spacings 1/60, 1/100 and 1/150 mm divide both sides; 0.0133 mm gives 75 x 38 particles, dy 1.3 % smaller
  than dx). ``Setup.dp`` is dx; h = 1.5 dx (Table 4: h = 0.01 mm at dp = 0.00667 mm).
* **Fixed left side** (the paper: "the left side of the metal block is fixed"): the first column of
  particles is held at rest (:class:`~refsph.boundaries.Clamp`, v = 0; they keep their stress).
* **Tool**: only the layers that can touch the block: ceil(2h / dx) = 3 columns of particles (the kernel
  support of a block particle at the face reaches 3 spacings) on the tool's left face, 0.7 mm tall, centred on
  the block's mid-height (it overhangs 0.1 mm above and below: the paper does not say where it sits; centred is
  the symmetric choice). The tool face starts touching the block face (x = 1.0 mm) and moves at -200 m/s
  (:class:`~refsph.boundaries.RigidBody`). ESPH: the tool particles are SPH neighbours; TLSPH: pinball contact,
  frictionless (Section 3).
* **End time**: not printed in the paper. We stop after a tool travel of 0.2 mm (20 % of the block length,
  t_end = 1 us), option ``travel``.

Material: Table 3 (E = 207 GPa, nu = 0.3, J-C A, B, n, C, m, T_r = 298 K, T_m = 1573 K, C_p = 480), chi = 0.9
(Section 2.3), eps_dot_0 = 1 /s (not printed, as for the Taylor bar). Numerics: Table 4 (beta1 = beta2 = 0.5,
ESPH gamma = 0.3), Courant 0.3 (the paper's fixed dt = 1e-10 s is ``--dt 1e-10``); ESPH Verlet skin 0.3 h.

Measurements (``summary.json`` metrics):

* ``tool_force_history``: [t, F] with F the force of the block on the tool against its motion, per metre of
  thickness [N/m], time-averaged over 400 equal time bins (each step's value and size are in
  ``reaction_forces.csv``; the pinball contact force comes in impulses a step long, which the bins average);
  also its peak and its time average over the second half of the run, and the same for the clamp
  (``clamp_force_mean_N_per_m``). The peak of the binned TLSPH force depends on how many steps fall in a bin
  (so on dp and dt): compare mean forces.
* ``plastic_strain_line`` (Fig. 8): [x, eps_p] of the row of particles that starts nearest to mid-height
  (on it for an odd number of rows, as at the paper's spacing; half a spacing below it for an even number),
  sorted by their current x [mm, -] (a Lagrangian line: the same particles in both methods).
* ``max_plastic_strain``, ``max_temperature_K`` (block only), ``min_tool_gap_over_dp``: the smallest
  distance between a block and a tool particle, in spacings (1 = the faces touch; less = penetration),
  sampled at the recorded steps (about 400 per run, as every history of ``refsph.simulate``).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from ..boundaries import Clamp, RigidBody
from ..paper_data import PRESSING_GEOMETRY, PRESSING_RESOLUTIONS_M, PRESSING_TABLE4
from ..state import concatenate_states, make_state
from .base import Numerics, Scene, Setup
from .measure import (N_FORCE_BINS, TOOL_BODY, aisi4340_johnson_cook, aisi4340_material, binned_mean,
                      block_lattice, box_outline, kinetic_energy, time_mean)

__all__ = ["SCENE", "pressing_particles", "pressing_table"]

PRESSING_OPTIONS = {
    "travel": (0.2e-3, "tool travel at the end of the run [m] (not printed in the paper); t_end = travel / tool speed"),
    "eps_dot_0": (1.0, "Johnson-Cook reference strain rate [1/s] (not printed in Table 3)"),
    "speed_factor": (1.0, "tool speed / the paper's 200 m/s (0.1: the same travel in ten times the time, chapter 10)"),
}


def pressing_particles(dp: float, n_tool_layers: int):
    """Block and tool particle centres: (x_block, x_tool, dx, dy, clamp index, mid-height row index)."""
    (Lx, Ly), (_, Ht) = PRESSING_GEOMETRY["block_m"], PRESSING_GEOMETRY["tool_m"]
    nx, ny = round(Lx / dp), round(Ly / dp)
    if nx < 4 or ny < 4:
        raise ValueError(f"spacing dp = {dp!r} m is too coarse for a {Lx * 1e3} x {Ly * 1e3} mm block")
    dx, dy = Lx / nx, Ly / ny
    xb, i, j = block_lattice(nx, ny, dx, dy)
    clamp = np.flatnonzero(i == 0)
    j_mid = int(np.argmin(np.abs((np.arange(ny) + 0.5) * dy - 0.5 * Ly)))
    line = np.flatnonzero(j == j_mid)
    nt = round(Ht / dy)
    ti, tj = np.meshgrid(np.arange(n_tool_layers), np.arange(nt), indexing="ij")
    xt = np.stack([Lx + (ti.ravel() + 0.5) * dx, 0.5 * Ly + (tj.ravel() - 0.5 * (nt - 1)) * dy], axis=1)
    return xb, xt, dx, dy, clamp, line


def _default_dp(dim, quick):
    return PRESSING_RESOLUTIONS_M[0] if quick else PRESSING_TABLE4["particle_spacing_m"]


def _build(dim, dp, quick, *, travel, eps_dot_0, speed_factor):
    if dim != 2:
        raise ValueError("the pressing scene is 2D plane strain (the mid-plane of the paper's 0.1 mm slab)")
    if not (np.isfinite(travel) and 0 < travel < 0.9 * PRESSING_GEOMETRY["block_m"][0]):
        raise ValueError(f"tool travel must lie in (0, 0.9 mm), got {travel!r} m")
    t4 = PRESSING_TABLE4
    numerics = Numerics(h_over_dp=1.5,                  # Table 4: 0.01 / 0.00667; "kept as 1.5" (Section 3.2)
                        beta1=t4["beta1"], beta2=t4["beta2"], gamma=t4["artificial_pressure_gamma_esph"],
                        skin_factor=0.3)
    layers = math.ceil(2.0 * numerics.h_over_dp - 1e-9)
    xb, xt, dx, dy, clamp, line = pressing_particles(dp, layers)
    mat = aisi4340_material()
    jc = aisi4340_johnson_cook(eps_dot_0)
    T0 = jc.T_room
    if not (np.isfinite(speed_factor) and speed_factor > 0):
        raise ValueError(f"option speed_factor must be positive, got {speed_factor!r}")
    speed = float(speed_factor) * PRESSING_GEOMETRY["tool_speed_m_s"]
    block = make_state(xb, [0.0, 0.0], mat.rho0, dx * dy, T0=T0)
    tool = make_state(xt, [-speed, 0.0], mat.rho0, dx * dy, T0=T0, body=np.full(len(xt), TOOL_BODY))
    state = concatenate_states(block, tool)
    t_end = float(travel) / speed
    return Setup(state=state, material=mat, dp=dx, numerics=numerics, t_end=t_end, n_snapshots=10,
                 info=dict(n_block=block.n, n_tool=tool.n, dx=dx, dy=dy, tool_layers=layers,
                           travel_m=float(travel), tool_speed_m_s=speed),
                 arrays=dict(line_index=line), strength=jc,
                 rigid=(RigidBody("tool", TOOL_BODY, (-speed, 0.0), shape=box_outline(xt, dx, dy)),),
                 clamps=(Clamp("left_side", clamp),), snapshot_times=tuple(t_end * np.array([0.25, 0.5, 0.75])))


def _record(state, setup):
    n = setup.info["n_block"]
    xb, xt = state.x[:n], state.x[n:]
    near = xb[:, 0] > xt[:, 0].min() - 3 * setup.dp
    gap = float(cKDTree(xt).query(xb[near])[0].min()) if near.any() else float("inf")
    return dict(t=state.t, max_eps_p=float(np.max(state.eps_p[:n])), max_T=float(np.max(state.T[:n])),
                E_kin=kinetic_energy(state, slice(0, n)),
                min_tool_gap_over_dp=gap / setup.dp)


def _metrics(hist, state, setup):
    n = setup.info["n_block"]
    rh = hist["reaction"]
    t, dt = np.asarray(rh["t"]), np.asarray(rh["dt"])
    tool = np.asarray(rh["tool"])[:, 0]                # force of the block on the tool, +x: against its motion
    clamp = np.asarray(rh["left_side"])[:, 0]          # force of the block on the clamped column
    nb = min(N_FORCE_BINS, max(1, len(t)))
    tb, fb = binned_mean(t, dt, tool, setup.t_end, nb)
    _, cb = binned_mean(t, dt, clamp, setup.t_end, nb)
    line = setup.arrays["line_index"]
    order = np.argsort(state.x[line, 0])
    return dict(
        tool_force_history=np.stack([tb, fb], axis=1),
        tool_force_peak_N_per_m=float(np.max(fb)),
        tool_force_mean_N_per_m=time_mean(t, dt, tool, 0.5 * setup.t_end),
        clamp_force_mean_N_per_m=time_mean(t, dt, clamp, 0.5 * setup.t_end),
        clamp_force_history=np.stack([tb, cb], axis=1),
        max_plastic_strain=float(np.max(state.eps_p[:n])),
        max_temperature_K=float(np.max(state.T[:n])),
        plastic_strain_line=np.stack([state.x[line[order], 0] * 1e3, state.eps_p[line[order]]], axis=1),
        min_tool_gap_over_dp=float(np.min(hist["min_tool_gap_over_dp"])),
        tool_travel_mm=float(setup.info["tool_speed_m_s"] * state.t * 1e3),
        kinetic_energy_final_J_per_m=float(hist["E_kin"][-1]),
    )


def pressing_table(summaries: list) -> str:
    """The runs side by side. The paper prints no numbers for this case (only Figs. 7-10)."""
    rows = ["Metal pressing, 2D plane strain (Section 3.2). The paper gives contour plots only (Figs. 7-10),",
            "no numbers: compare the figures of chapter 07 with the paper's Figs. 7-10.",
            "",
            f"{'method':8s} {'dp [um]':>8s} {'particles':>9s} {'steps':>6s} {'wall [s]':>8s} "
            f"{'F peak [kN/mm]':>14s} {'F mean 2nd half':>15s} {'max eps_p':>9s} {'max T [K]':>9s} "
            f"{'min gap/dp':>10s}"]
    for s in summaries:
        m = s.get("metrics") or {}
        if not m:
            rows.append(f"{s['method']:8s} (status {s.get('status')})")
            continue
        rows.append(f"{s['method']:8s} {s['dp'] * 1e6:8.3f} {s['n_particles']:9d} {s['n_steps']:6d} "
                    f"{s['wall_time_s']:8.1f} {m['tool_force_peak_N_per_m'] * 1e-6:14.3f} "
                    f"{m['tool_force_mean_N_per_m'] * 1e-6:15.3f} {m['max_plastic_strain']:9.3f} "
                    f"{m['max_temperature_K']:9.1f} {m['min_tool_gap_over_dp']:10.3f}")
    rows.append("(F: force of the block on the tool per unit thickness; kN per mm of thickness = MN/m)")
    return "\n".join(rows)


SCENE = Scene(
    "pressing",
    "metal pressing: AISI 4340 block 1.0 x 0.5 mm, left side fixed, rigid tool at 200 m/s (Section 3.2)",
    _default_dp, _build, _record, _metrics, options=PRESSING_OPTIONS, default_dim=2,
    methods=("esph", "tlsph"), report=pressing_table)
