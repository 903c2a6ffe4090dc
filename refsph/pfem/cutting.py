"""The second paper's orthogonal cut with the PFEM (Section 2.3.5, Figure 5): the same case, tool and measures as
refsph's SPH scene (:mod:`refsph.scenes.thermal_cutting`), solved by Algorithm 1.

Scene: the workpiece 3 t_u high, its bottom row and left column held, graded (the paper's Figure 5): spacing
dx = t_u / n_tu in a band 2 t_u deep under the top surface (the uncut layer and the shear zones under it), 2 dx
below; the tool of the SPH scene (10 deg rake, 10 deg clearance, 10 um edge radius; rigid, at -v_c) as the exact
rounded polygon of :mod:`refsph.pfem.contact`. Real density: the implicit step has no stability limit, so nothing
is mass-scaled (the SPH runs scale the density by s; here s = 1). Eq. (13)'s thermal expansion is left out
(alpha_T = 0): the paper's tables give no coefficient, and the SPH scene has none, so both see the same mechanics.

Each step (Algorithm 1): the tool moves by -v_c dt; Newton-Raphson solves the mechanical step with the contact
inside it (:func:`refsph.pfem.solid.newton_step`); the nodes move; the plastic work heats the nodes (chi dW_p of
each triangle, a third to each node, over m_i c_p: adiabatic, or the source of the heat step when conduction is
on); the history goes to the nodes, nodes closer than half a spacing are merged and triangles larger than 2.5
lattice triangles get a node (:mod:`refsph.pfem.refine`: mass, momentum and heat kept exactly), and the nodes are
meshed again (remeshing every step: Algorithm 1 remeshes "if remeshing is needed" without saying when; with
``remesh_when_needed`` only where a triangle's quality falls below 0.3, which on case 1's whole cut at t_u / 5
remeshes 71 of 320 steps and gives a rake face 60 K cooler, README). A step whose Newton fails
is retried at half the step (up to four times). dt = ``courant`` dx / v_c: the tool moves a fraction of the finest
spacing per step (the mesh, not stability, limits it).

**Heat** (``conduction``, on by default; :class:`CutHeat`): after each mechanical step, one backward-Euler step of
Eq. (22) (:func:`refsph.pfem.thermal.thermal_step`) on the workpiece's mesh and the tool's, solved together: the
plastic heat of the step (Eq. (5), chi dW_p A of each triangle, a third to each node) and the frictional heat
(Eq. (7), eta |f_T| |slip| of each sliding node, ``chip_fraction`` of it to the node, the rest to the nearest tool
node) as sources; conduction in both bodies; between them a contact conductance (:func:`~refsph.pfem.thermal.
contact_conductance`) from each workpiece node that carries a contact force to the nearest tool node, h_int =
(2 k_w k_t / (k_w + k_t)) / dx: the two bodies' harmonic-mean conductivity over one spacing, i.e. contact as good
as the material itself (the paper gives no interface conductance); the tool's top and back faces and the
workpiece's held bottom row and left column at 293 K; convection and radiation (Eq. (6)) on both bodies' free
boundary edges (the alpha-shape's; edges in contact left out). The tool is a lattice of nodes like the SPH scene's
tool particles (same size, the paper's reduced c_p = 15 J/(kg K)), meshed once and moved rigidly. The heat ledger
(``CutRun.ledger``) closes to round-off. ``conduction=False``: adiabatic (the plastic heat stays where it is made).

**Newton-Raphson at the tool.** At the first contact Newton-Raphson used to stall (a scaled residual ~0.3 for tens
of iterations, then a halved step): a node on the tool, where the flowing elements' tangent is soft, got a
correction of about 12 spacings from a residual that a few tenths of one remove, and the line search crawled. Each
step starts from du = 0, freezes the contact and slip sets within a Newton solve
(:func:`~refsph.pfem.contact.solve_with_active_set`), and limits each correction to ``max_move`` = 0.05 of a node's
local size (:func:`~refsph.pfem.solid.newton_step`). The quick cut's first 15 steps: 140 s and 10 halved steps with a
limit of 0.25, 43 s and 1 with 0.05. Later in a cut a node grazing the tool (or at the friction cap) can drop out
of the sets and come back on alternate solves, at any step size: case 4 failed so at step 145 even at dt / 16, and
passes when the sets may only grow after 8 solves (the same function's second stage). What a step costs at
t_u / 10 (case 1's short cut, steps 4-16: 327 Newton iterations, 20-39 a step, in two or three solves): a limit of
0.1 gives 320, the previous step's du as the start 483, v dt as the start 693, a limit widened by each node's own
motion |v| dt 453; without friction 423 and with a quarter of the penalty 336. The crawl at scaled residuals
0.1-0.02 that failed the short cut at t_u / 10 (step 28, even at dt / 16) was the contact after all: the
stagnation node at the edge radius slipped forwards in one solve and backwards in the next, each solve's
correction for it about one spacing, and ``max_move`` scaled every node's correction down with it. A slip that
reverses now sticks first (:meth:`~refsph.pfem.contact.StepContact.freeze`): step 28 takes 33 iterations (297 and
three halved steps before), steps 28-39 take 27-44, and the quick cut at t_u / 5 halves no step (4 before; the
converged steps' iterations alike, 1335 against 1328; 68 s against 192 s, timed beside different loads; its forces
move by 0.2 %). An implicit return map
(the yield stress at the step's end, Simo & Hughes 1998 Box 3.1, which puts the hardening into the tangent) was
tried on steps 28-39 too: the same iterations (23-44) at 1.7 times the time, so the explicit one of Eqs. (29)-(31)
stays. Most of a step's iterations are then its first solve climbing from du = 0 under the limit (seven at a scaled
residual of 1 before the correction fits in 0.05 of a spacing): ``warm_start`` begins each step from the last
step's du (scaled by the ratio of the steps; carried through node insertions and merges like the other per-node
arrays; the contact sets still taken at x_n, since sets taken at x_n + du cost twice the iterations). Steps 28-37
of the short cut at t_u / 10: 181 iterations against 324; the quick cut at t_u / 5: 1194 against 1335, with the
same forces and temperatures to 1e-9 (the path changes, not the solution). The crawl that remains is mostly
one node, the stagnation node at the edge radius, whose solution moves about half a spacing in a step: the limit
as a trust region (doubled after each correction it cut short that the line search took whole, back to 0.05
after a backtrack; capped at 4 or 8 times 0.05, or grown by 1.5 up to 3 times) took 689-728 iterations against
626 on the quick cut's first 40 steps, and starting each step with the nodes that the tool's move pushed into
it projected back onto its outline, 628: neither is kept. Nor is modified Newton in the crawl (the last factors
reused while the limit cuts the correction short: 1100 iterations against 626, and a converged point 0.5 % off
in the tool force), nor a wider limit with today's solver (0.1: 663 iterations against 582; 0.2: 735, and Fp
57 % higher, another solution of the contact problem; 0.5: halved steps). In the crawl the correction the limit
cuts short is consistent (the wanted move of the worst node falls by exactly the 0.05 taken each iteration), but
about 150 nodes want more than the limit at its start: the warm start is off for the whole zone ahead of the
tool, not for one node.

**The sets looked at inside the iterations.** What the crawl leaves was spent converging solves whose sets then
changed: each solve ran to the tolerance (1e-10) before its sets were looked at, and the next solve started at a
scaled residual of 1e-2 to 5e-2 again. With ``settle = 2`` the sets are looked at after every two corrections
(:func:`~refsph.pfem.contact.solve_with_active_set`, the active set updated inside the Newton iterations), and a
solve whose sets did not change goes on. The short cut at t_u / 10, steps 1-30: 362 iterations against 533
(-32 %), the tool force the same to 1e-11; at t_u / 5, steps 1-60: 648 against 833 (-22 %), the force 6e-5 apart
(a node's stick or slip taken from another point: another solution of the frictional contact problem, within the
tolerance of the contact law). Looked at so often the sets change more often, so ``max_outer`` (the changes before
the sets may only grow) is 16 instead of 8: with 8, three steps of the t_u / 5 cut failed and were halved. Every
1, 3 or 4 corrections: 477, 466 and 370 iterations at t_u / 10 (1 and 3 with a step of 98-122 iterations; 1 is
refused now: a solve of one correction at a time never has the three residuals the round-off stopping rule needs).
CPU (the short cut at t_u / 10, steps 1-30, beside other runs): 28.5 against 39.2 s. Each piece of a solve
evaluates the residual at its start again (no tangent), about 5 % of a correction's work.

**The chip rings.** The paper's trapezoidal rule damps nothing, and in the chip its pressures swing from step to
step: case 16 (Ti6Al4V, 60 m/min, t_u/5) failed at 0.85 ms of 1.6 with Newton stalled at a scaled residual of
1e-3 even at dt / 16; in its last steps the cutting force alternated (270, 317, 287, 312, 276, 316 N/mm) and the
pressures of chip nodes 5-10 dx up the rake face jumped by 1-3 GPa a step (one inserted node at -9.5 GPa).
Continued from the 0.8 ms checkpoint with the damped rule ``gamma = 0.6`` (beta = 0.3025) it passes 0.95 ms
with 24-31 iterations a step. ``pfem_cut(gamma=...)`` selects it (default 0.5, the paper's rule; a departure
from the paper where used, first-order in time).

The measures are the SPH scene's own functions (:func:`refsph.scenes.thermal_cutting.chip_measures`,
:func:`~refsph.scenes.thermal_cutting.thermal_cutting_metrics`), so the two methods are measured alike.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, field, fields

import numpy as np
from scipy.spatial import cKDTree

from ..contact import CoulombFriction
from ..paper_data import AISI1045_RLA, CONTACT_RLA, RLA_SURFACE_LOSS, TI6AL4V_RLA, TOOL_CARBIDE_RLA, rla_cutting_case
from ..plasticity import JohnsonCook, ModifiedJohnsonCook
from ..scenes.measure import jittered
from ..scenes.thermal_cutting import (CLEARANCE_DEG, EDGE_RADIUS, RAKE_DEG, chip_measures, thermal_cutting_metrics,
                                      tool_particles, tool_shape)
from ..thermal import SurfaceLoss
from .contact import StepContact, ToolContact, boundary_lengths, solve_with_active_set
from .mesh import Mesh, alpha_shape_mesh, mesh_of, remesh_needed, tributary_areas
from .refine import NodeRule, refine_nodes, renumber_mesh, tool_intrusions
from .solid import (TRAPEZOIDAL, History, Loads, Newmark, NewtonFailed, Nodes, SolidLaw, commit, history_from_nodes,
                    make_nodes, plastic_heat, settle_nodes, transfer_history)
from .thermal import contact_conductance, thermal_step

__all__ = ["PFEMCut", "CutHeat", "CutRun", "graded_workpiece", "pfem_cut", "heat_step", "refine_run", "run_pfem_cut"]

MATERIALS = {"AISI1045": AISI1045_RLA, "Ti6Al4V": TI6AL4V_RLA}
HISTORY_KEYS = ("t", "T_RF", "T_RF_max", "T_FCS", "chip_mm", "contact_mm", "max_T", "max_eps_p")
LEDGER = ("plastic", "friction", "friction_to_tool", "stored", "lost", "removed")


@dataclass
class CutHeat:
    """The cut's heat model (module text): the workpiece's k [W/(m K)] and c_p [J/(kg K)]; the tool's nodes ``x_tool``
    (P, 2) at t = 0, its triangles ``tool_tri`` (Q, 3), its k, and m c_p of each tool node ``tool_mc`` (P,) [J/(m K)];
    ``tool_fixed`` (tool node indices held at ``T_fixed``; the workpiece's held nodes are held at it too);
    ``tool_edges`` (K, 2) the tool mesh's free boundary edges (the held faces lose nothing: fixed temperature);
    ``h_int`` [W/(m^2 K)] the contact conductance; ``loss`` the losses of Eq. (6); ``chip_fraction`` of the frictional
    heat into the workpiece; ``eta`` the fraction of the frictional work that becomes heat. No defaults."""

    k_work: float
    cp_work: float
    x_tool: np.ndarray
    tool_tri: np.ndarray
    k_tool: float
    tool_mc: np.ndarray
    tool_fixed: np.ndarray
    tool_edges: np.ndarray
    T_fixed: float
    h_int: float
    loss: SurfaceLoss
    chip_fraction: float
    eta: float


@dataclass
class PFEMCut:
    """A PFEM cut as data: the nodes (:class:`refsph.pfem.solid.Nodes`), their spacing ``h`` (N,) [m] (the
    alpha-shape's local size), the held components ``fixed`` (N, 2), the ``law``, the tool (``shape``, its core's
    position ``shift0`` at t = 0 and velocity ``v_tool`` [m/s]), the ``contact``, ``alpha``, the step ``dt`` and
    ``t_end`` [s], the initial positions ``X0`` and ``info`` (the SPH scene's keys, for the measures); ``heat`` the
    heat model (:class:`CutHeat`; None: adiabatic); a remeshing every ``remesh_every`` steps (None: never so) and
    whenever a triangle's quality drops below ``remesh_quality``; ``newmark`` the time rule (the paper's trapezoidal
    rule by default); ``max_iter`` Newton iterations per solve; ``max_move`` the largest Newton correction of a
    node, in its local sizes (:func:`refsph.pfem.solid.newton_step`); ``settle`` and ``max_outer`` the active-set
    strategy's (:func:`refsph.pfem.contact.solve_with_active_set`: the sets looked at every ``settle`` corrections,
    None: after each converged solve); ``node_rule`` the node insertion and removal at each remeshing
    (:class:`refsph.pfem.refine.NodeRule`; None: the nodes stay as they are); ``warm_start``: each step's
    Newton-Raphson starts from the last step's du (scaled by the ratio of the steps; False: from du = 0), which
    changes the path to the solution, not the solution (module text); ``edge_nodes``: the mesh kept off the tool
    (a node inserted on the tool's surface where its edge pokes through the boundary between two nodes, deeper than
    a tenth of their spacing, :func:`refsph.pfem.refine.tool_intrusions`; triangles whose centroid is inside the tool
    left out of each new mesh; needs ``node_rule``; False: the paper's node-on-tool contact alone, module text)."""

    nodes: object
    h: np.ndarray
    fixed: np.ndarray
    law: SolidLaw
    shape: object
    shift0: np.ndarray
    v_tool: np.ndarray
    contact: ToolContact
    alpha: float
    dt: float
    t_end: float
    X0: np.ndarray
    info: dict = field(default_factory=dict)
    heat: CutHeat | None = None
    remesh_every: int | None = 1
    remesh_quality: float = 0.3
    newmark: Newmark = TRAPEZOIDAL
    max_iter: int = 80
    max_move: float | None = 0.05
    settle: int | None = 2
    max_outer: int = 16
    node_rule: NodeRule | None = None
    warm_start: bool = True
    edge_nodes: bool = False


def graded_workpiece(length: float, tu: float, dx: float) -> tuple[np.ndarray, np.ndarray]:
    """(x (N, 2), h (N,)): rows dx apart (columns dx apart) in the top 2 tu of a workpiece 3 tu high and ``length``
    long, rows and columns 2 dx apart below, from y = 0 (the held bottom row) up to at least dx under the fine band
    (module text)."""
    H = 3.0 * tu
    nx, nf = round(length / dx), round(2.0 * tu / dx)
    ny = round(H / dx)
    fine = [(i * dx, (ny - j) * dx) for j in range(nf + 1) for i in range(nx + 1)]
    coarse = [(i * 2 * dx, y) for y in np.arange(0.0, (ny - nf - 0.5) * dx, 2 * dx) for i in range(nx // 2 + 1)]
    x = np.array(fine + coarse)
    h = np.concatenate([np.full(len(fine), dx), np.full(len(coarse), 2 * dx)])
    return x, h


def _check_cut(*, n_tu, travel, length, tu, courant, penalty, chip_fraction, eta, gamma, bossak,
               conductivity_factor=1.0, conduction=True) -> None:
    """ValueError naming what :func:`pfem_cut` cannot take."""
    if not (np.isfinite(conductivity_factor) and conductivity_factor > 0):
        raise ValueError(f"PFEM cut: conductivity_factor must be positive, got {conductivity_factor!r}")
    if conductivity_factor != 1.0 and not conduction:
        raise ValueError("PFEM cut: conductivity_factor acts on the heat step; without conduction it would do nothing")
    if not (n_tu >= 2 and travel > 0 and length > 1.25 * travel * tu and courant > 0 and penalty > 0
            and 0.0 <= chip_fraction <= 1.0 and 0.0 <= eta <= 1.0):
        raise ValueError(f"PFEM cut: need n_tu >= 2, travel > 0, a cut within 80 % of the workpiece, courant > 0, "
                         f"penalty > 0, 0 <= chip_fraction <= 1 and 0 <= eta <= 1; got n_tu = {n_tu!r}, "
                         f"travel = {travel!r} tu, length = {length!r} m, courant = {courant!r}, "
                         f"penalty = {penalty!r}, chip_fraction = {chip_fraction!r}, eta = {eta!r}")
    if bossak != 0.0 and gamma != 0.5:
        raise ValueError(f"PFEM cut: give gamma (damped Newmark) or bossak (Bossak-Newmark), not both; got gamma = "
                         f"{gamma!r}, bossak = {bossak!r}")


def _cut_heat(k_w: float, cp_w: float, xt: np.ndarray, tool_held: np.ndarray, dx: float, T0: float,
              chip_fraction: float, eta: float) -> CutHeat:
    """The heat step's model of a cut (:class:`CutHeat`): the workpiece's k_w and c_p, the tool meshed by its
    alpha-shape (the paper's carbide, its held rows at T0), the chip-tool conductance of perfect contact
    2 k_w k_t / ((k_w + k_t) dx), the losses on the free edges, the frictional heat's split and eta."""
    tool = TOOL_CARBIDE_RLA
    tmesh = alpha_shape_mesh(xt, 1.4, np.full(len(xt), dx))
    tool_mc = tool["rho"] * tool["cp_J_kgK"] * tributary_areas(xt, tmesh.tri, len(xt))
    k_t = tool["k_W_mK"]
    return CutHeat(k_work=k_w, cp_work=cp_w, x_tool=xt, tool_tri=tmesh.tri, k_tool=k_t, tool_mc=tool_mc,
                   tool_fixed=np.flatnonzero(tool_held),
                   tool_edges=tmesh.edges[~np.isin(tmesh.edges, np.flatnonzero(tool_held)).all(axis=1)],
                   T_fixed=T0, h_int=2.0 * k_w * k_t / (k_w + k_t) / dx,
                   loss=SurfaceLoss(**RLA_SURFACE_LOSS, T_ambient=T0), chip_fraction=float(chip_fraction),
                   eta=float(eta))


def pfem_cut(case: int, n_tu: float = 10.0, travel: float = 16.0, length: float | None = None,
             courant: float = 0.25, alpha: float = 1.4, penalty: float = 20.0, friction: bool = True,
             conduction: bool = True, chip_fraction: float = 0.5, refine: bool = True, r_min: float = 0.5,
             a_max: float = 2.5, gamma: float = 0.5, edge_nodes: bool = False,
             remesh_when_needed: bool = False, bossak: float = 0.0, edge_radius: float = EDGE_RADIUS,
             eta: float = CONTACT_RLA["friction_work_to_heat"], jitter: float = 0.0, seed: int = 0,
             conductivity_factor: float = 1.0) -> PFEMCut:
    """The cut of row ``case`` of the paper's Appendix B: dx = t_u / n_tu, ``travel`` t_u of cut on a workpiece
    ``length`` [m] long (default (travel + 12) t_u), dt = courant dx / v_c, contact penalties ``penalty`` G / dx;
    ``conduction``: the heat step (module text; False: adiabatic), ``chip_fraction`` of the frictional heat into
    the chip; ``refine``: node removal and insertion at each remeshing with ``r_min`` and ``a_max``
    (:class:`refsph.pfem.refine.NodeRule`; False: the nodes stay as they are); ``gamma``: Newmark's gamma, 0.5 the
    paper's trapezoidal rule (Eq. (21)), above it the damped rule of :class:`refsph.pfem.solid.Newmark` with
    beta = (gamma + 1/2)^2 / 4 (a departure from the paper: it damps the chip's ringing, module text); ``bossak``:
    instead, Bossak's alpha_B in [-1/3, 0) (:meth:`refsph.pfem.solid.Newmark.bossak`: damped at second order);
    ``edge_nodes``: the mesh kept off the tool (:class:`PFEMCut`; with ``refine``); ``remesh_when_needed``:
    Algorithm 1's "if remeshing is needed" read literally, a remeshing only where a triangle's quality falls below
    ``remesh_quality`` (False: after every step as well, refsph's default; module text); ``edge_radius`` [m]: the
    tool's edge radius in the contact's outline (the paper's 10 um; the meshed tool of the heat step keeps it);
    ``eta``: the fraction of the frictional work that becomes heat (Eq. (7); the paper's 1; 0 keeps friction's
    mechanics without its heat); ``jitter``: each coordinate of the workpiece's free nodes moved at random by up to
    that many of their spacings (:func:`refsph.scenes.measure.jittered`, seed ``seed``): a perturbed run, for the
    run-to-run scatter (on the square lattice, Delaunay's choice of diagonal, and so the path, turns on rounding);
    ``conductivity_factor``: the workpiece's k of Table A1 times this, the chip-tool conductance with it (1: the
    paper's; a sensitivity study, as the SPH scene's option)."""
    row = rla_cutting_case(int(case))
    mat = MATERIALS[row["material"]]
    vc, tu = row["vc_m_per_min"] / 60.0, row["tu_mm"] * 1e-3
    dx = tu / n_tu
    length = (travel + 12.0) * tu if length is None else length
    _check_cut(n_tu=n_tu, travel=travel, length=length, tu=tu, courant=courant, penalty=penalty,
               chip_fraction=chip_fraction, eta=eta, gamma=gamma, bossak=bossak,
               conductivity_factor=conductivity_factor, conduction=conduction)
    newmark = (Newmark.bossak(bossak) if bossak != 0.0 else TRAPEZOIDAL if gamma == 0.5      # raise out of range
               else Newmark((gamma + 0.5) ** 2 / 4.0, gamma))
    x, h = graded_workpiece(length, tu, dx)
    H = 3.0 * tu
    y0 = H - tu
    T0 = CONTACT_RLA["T_ref_K"]
    jc = dict(A=mat["A_Pa"], B=mat["B_Pa"], n=mat["n"], C=mat["C"], m=mat["m"], eps_dot_0=mat["eps_dot_0"],
              T_room=T0, T_melt=mat["T_melt_K"], cp=mat["cp_J_kgK"], chi=CONTACT_RLA["plastic_work_to_heat"])
    strength = (ModifiedJohnsonCook(**jc, hardening_saturation_strain=mat["hardening_saturation_strain"])
                if "hardening_saturation_strain" in mat else JohnsonCook(**jc))
    E, nu = mat["E_Pa"], mat["nu"]
    law = SolidLaw(rho0=mat["rho"], G=E / (2 * (1 + nu)), K=E / (3 * (1 - 2 * nu)), alpha_T=0.0, T_ref=T0,
                   strength=strength)
    x_end = float(x[:, 0].max())
    apex = np.array([x_end + 0.5 * dx, y0])
    fixed = np.repeat(((x[:, 1] < 1e-12) | (x[:, 0] < 1e-12))[:, None], 2, axis=1)
    x = np.where(fixed, x, jittered(x, jitter, h[:, None], seed))      # a perturbed run (held nodes stay)
    xt, tool_held = tool_particles(dx, tu, apex, 10.0, 6.0)
    centroid = xt.mean(axis=0)
    shape = tool_shape(tu, apex, centroid, 10.0, 6.0, radius=edge_radius)
    mu = CoulombFriction(mu0=mat["mu0"], q=mat["q_friction"], T_room=T0, T_melt=mat["T_melt_K"]) if friction else None
    contact = ToolContact(k_normal=penalty * law.G / dx, k_tangent=penalty * law.G / dx, friction=mu)
    A_cell = np.where(h > dx * 1.5, 4 * dx * dx, dx * dx)
    nodes = make_nodes(x, mat["rho"] * A_cell, T0)
    heat = _cut_heat(mat["k_W_mK"] * float(conductivity_factor), mat["cp_J_kgK"], xt, tool_held, dx, T0,
                     chip_fraction, eta) if conduction else None
    info = dict(case=int(case), material=row["material"], vc_m_s=vc, tu_m=tu, dx=dx, length_m=x_end,
                height_m=H, y0=y0, n_work=len(x), n_tool=len(xt), travel_m=travel * tu, mass_scale=1.0,
                inertia_ratio=mat["rho"] * vc * vc / mat["A_Pa"], rake_deg=RAKE_DEG, clearance_deg=CLEARANCE_DEG,
                edge_radius_m=float(edge_radius), apex0=apex.tolist(), measured=row, method="pfem", alpha=alpha,
                courant=courant, penalty=penalty, conduction=bool(conduction), chip_fraction=float(chip_fraction),
                h_int=None if heat is None else heat.h_int, refine=bool(refine), r_min=r_min, a_max=a_max,
                newmark_gamma=float(newmark.gamma), edge_nodes=bool(edge_nodes),
                remesh_when_needed=bool(remesh_when_needed), eta=float(eta), jitter=float(jitter), seed=int(seed),
                **({"newmark_alpha_B": float(bossak)} if bossak else {}),
                **({"conductivity_factor": float(conductivity_factor)} if conductivity_factor != 1.0 else {}))
    return PFEMCut(nodes=nodes, h=h, fixed=fixed, law=law, shape=shape, shift0=centroid, v_tool=np.array([-vc, 0.0]),
                   contact=contact, alpha=alpha, dt=courant * dx / vc, t_end=travel * tu / vc, X0=x.copy(), info=info,
                   heat=heat, node_rule=NodeRule(r_min=r_min, a_max=a_max) if refine else None, newmark=newmark,
                   edge_nodes=bool(edge_nodes) and bool(refine), remesh_every=None if remesh_when_needed else 1)


class CutRun:
    """A PFEM cut in progress (Algorithm 1, one :meth:`step` at a time): the nodes, their mesh and the triangles'
    history, the tool's temperatures, the contact's tangential forces, the recorded history, the heat ledger
    (``ledger`` [J/m]: plastic, friction, friction_to_tool, stored, lost, removed) and the Newton record.
    :meth:`checkpoint` / :meth:`restore` save and continue it exactly (the run folder's restart.npz)."""

    def __init__(self, cut: PFEMCut):
        self.cut = cut
        self.nodes = cut.nodes
        self.h, self.fixed, self.X0 = cut.h.copy(), cut.fixed.copy(), cut.X0.copy()   # per node: they change
        self.ids = np.arange(self.nodes.n, dtype=np.int64)                               # with the node rule
        self.mesh = cut_mesh(cut, self.nodes, self.h)
        self.hist_e = history_from_nodes(self.nodes, self.mesh)
        self.f_T = np.zeros(self.nodes.n)
        self.T_tool = None if cut.heat is None else np.full(len(cut.heat.x_tool), cut.heat.T_fixed)
        self.hist = {k: [] for k in HISTORY_KEYS}
        self.reaction = dict(t=[], dt=[], tool=[])
        self.iterations, self.retries, self.steps, self.remeshes, self.wall, self.cpu = [], 0, 0, 0, 0.0, 0.0
        self.inserted = self.removed = 0
        self.ledger = {k: 0.0 for k in LEDGER}
        self.du_prev, self.dt_prev = None, None                                  # the warm start

    @property
    def done(self) -> bool:
        return self.nodes.t >= self.cut.t_end * (1 - 1e-9)

    def step(self):
        """One step: the mechanics with the contact (halving the step up to four times if Newton fails), the heat
        step, the remeshing and the measures; returns the converged :class:`refsph.pfem.solid.StepResult`."""
        t0, c0 = time.perf_counter(), time.process_time()
        cut, nodes, mesh = self.cut, self.nodes, self.mesh
        dt = min(cut.dt, cut.t_end - nodes.t)
        zero = np.zeros_like(nodes.x)
        for _ in range(5):
            t1 = nodes.t + dt
            contact = StepContact(cut.contact, cut.shape, cut.shift0 + cut.v_tool * t1, cut.v_tool * dt, nodes.x,
                                  self.f_T, nodes.T, boundary_lengths(nodes.x, mesh.edges, nodes.n),
                                  np.flatnonzero(mesh.boundary))
            du0 = self.du_prev * (dt / self.dt_prev) if cut.warm_start and self.du_prev is not None else None
            try:
                r = solve_with_active_set(nodes, mesh, self.hist_e, cut.law, dt, Loads(self.fixed, zero,
                                                                                         contact=contact),
                                          dynamic=cut.newmark, max_iter=cut.max_iter, max_move=cut.max_move,
                                          du0=du0, settle=cut.settle, max_outer=cut.max_outer)
                break
            except NewtonFailed as e:
                dt, self.retries = 0.5 * dt, self.retries + 1
                failure = e
        else:
            raise NewtonFailed(f"PFEM cut: Newton failed at t = {nodes.t:.3e} s even at dt = {2.0 * dt:.2e} s "
                               f"(the last try: {failure})", *failure.args[1:])     # (dt was halved after it)
        self.iterations.append(r.iterations)
        self.du_prev, self.dt_prev = r.du.copy(), dt
        nodes = commit(nodes, r, dt, cut.newmark)
        c = contact.last
        self.f_T = c["f_T"]
        F_tool = -r.contact_force.sum(axis=0) if r.contact_force is not None else np.zeros(2)
        settle_nodes(nodes, mesh, r, cut.law.strength, heat=cut.heat is None)
        if cut.heat is not None:
            heat_step(self, nodes, mesh, r, contact, dt)
        every = cut.remesh_every
        if remesh_needed(nodes.x, mesh, cut.remesh_quality) or (every is not None and self.steps % every == every - 1):
            old, hist = mesh, r.history                                 # Algorithm 1: "if remeshing is needed"
            if cut.node_rule is not None:
                nodes, old, hist = refine_run(self, nodes, mesh, hist)
            new = cut_mesh(cut, nodes, self.h)
            self.hist_e, self.mesh = transfer_history(old, hist, new, nodes), new
            self.remeshes += 1
        else:
            self.hist_e = r.history
        self.nodes = nodes
        self.reaction["t"].append(nodes.t - 0.5 * dt)                     # the step's midpoint, as the SPH runs
        self.reaction["dt"].append(dt)
        self.reaction["tool"].append(F_tool)
        m = chip_measures(nodes.x, self.X0, nodes.T, nodes.t, cut.info)
        for k, v in dict(t=nodes.t, max_T=float(nodes.T.max()), max_eps_p=float(nodes.eps_p.max()), **m).items():
            self.hist[k].append(v)
        self.steps += 1
        self.wall += time.perf_counter() - t0
        self.cpu = None if self.cpu is None else self.cpu + time.process_time() - c0    # None: not kept before
        return r

    def tool_x(self, t: float) -> np.ndarray:
        """The tool's nodes at time t (moved rigidly)."""
        return self.cut.heat.x_tool + self.cut.v_tool * t

    def heat_balance(self) -> dict | None:
        """The heat ledger [J/m] with its residual made - stored - lost - removed (made: plastic + friction)."""
        if self.cut.heat is None:
            return None
        L = self.ledger
        made = L["plastic"] + L["friction"]
        res = made - L["stored"] - L["lost"] - L["removed"]
        return dict(plastic_J=L["plastic"], friction_J=L["friction"], friction_to_tool_J=L["friction_to_tool"],
                    stored_J=L["stored"], lost_J=L["lost"], removed_J=L["removed"], residual_J=res,
                    residual_rel=res / made if made > 0 else 0.0)

    def result(self) -> dict:
        """The run's history and metrics (the SPH scene's keys), its nodes and mesh, the Newton record."""
        hist = {k: list(v) for k, v in self.hist.items()}
        hist["reaction"] = {k: np.asarray(v) for k, v in self.reaction.items()}
        metrics = thermal_cutting_metrics(hist, self.cut.info, self.cut.t_end) if self.steps else {}
        return dict(nodes=self.nodes, mesh=self.mesh, history=hist, metrics=metrics, newton_iterations=self.iterations,
                    retries=self.retries, wall_time_s=self.wall, cpu_time_s=self.cpu, steps=self.steps,
                    remeshes=self.remeshes, nodes_inserted=self.inserted, nodes_removed=self.removed,
                    heat_balance=self.heat_balance(), T_tool=self.T_tool)

    def checkpoint(self) -> dict:
        """Everything :meth:`restore` needs, as arrays (one .npz)."""
        out = {f"nodes/{f.name}": np.asarray(getattr(self.nodes, f.name)) for f in fields(Nodes)}
        out.update({f"mesh/{k}": getattr(self.mesh, k) for k in ("tri", "edges", "boundary")})
        out.update({f"hist/{f.name}": getattr(self.hist_e, f.name) for f in fields(History)
                    if getattr(self.hist_e, f.name) is not None})
        out.update(f_T=self.f_T, h=self.h, fixed=self.fixed, X0=self.X0, ids=self.ids)
        if self.du_prev is not None:
            out.update(du_prev=self.du_prev, dt_prev=np.array(self.dt_prev))
        if self.T_tool is not None:
            out["T_tool"] = self.T_tool
        out["record"] = np.array(json.dumps(dict(
            hist=self.hist, reaction={k: np.asarray(v).tolist() for k, v in self.reaction.items()},
            iterations=self.iterations, retries=self.retries, steps=self.steps, remeshes=self.remeshes, wall=self.wall,
            ledger=self.ledger, inserted=self.inserted, removed=self.removed, cpu=self.cpu)))
        return out

    @classmethod
    def restore(cls, cut: PFEMCut, arrays: dict) -> "CutRun":
        """The run a :meth:`checkpoint` saved, continued with ``cut`` (the same scene)."""
        run = cls.__new__(cls)
        run.cut = cut
        kw = {f.name: arrays[f"nodes/{f.name}"] for f in fields(Nodes)}
        kw["t"] = float(kw["t"])
        run.nodes = Nodes(**kw)
        run.mesh = Mesh(tri=arrays["mesh/tri"], edges=arrays["mesh/edges"], boundary=arrays["mesh/boundary"],
                        alpha=cut.alpha)
        run.hist_e = History(**{f.name: arrays.get(f"hist/{f.name}") for f in fields(History)})
        run.f_T = arrays["f_T"]
        run.h, run.fixed, run.X0 = (np.asarray(arrays.get(k, getattr(cut, k))).copy() for k in ("h", "fixed", "X0"))
        run.ids = np.asarray(arrays.get("ids", np.arange(run.nodes.n)), dtype=np.int64)
        run.T_tool = arrays.get("T_tool")
        run.du_prev = arrays.get("du_prev")
        run.dt_prev = None if run.du_prev is None else float(arrays["dt_prev"])
        rec = json.loads(str(arrays["record"]))
        run.hist = rec["hist"]
        run.reaction = {k: [np.asarray(row) if k == "tool" else row for row in v] for k, v in rec["reaction"].items()}
        run.iterations, run.retries, run.steps = rec["iterations"], rec["retries"], rec["steps"]
        run.remeshes, run.wall, run.ledger, run.cpu = rec["remeshes"], rec["wall"], rec["ledger"], rec.get("cpu")
        run.inserted, run.removed = rec.get("inserted", 0), rec.get("removed", 0)
        return run


def cut_mesh(cut: PFEMCut, nodes: Nodes, h: np.ndarray) -> Mesh:
    """Algorithm 1's mesh of the nodes (the alpha-shape with spacings h), without the triangles whose centroid is
    inside the tool where ``cut.edge_nodes`` is set."""
    mesh = alpha_shape_mesh(nodes.x, cut.alpha, h)
    if not cut.edge_nodes:
        return mesh
    inside = cut.shape.gap(nodes.x[mesh.tri].mean(axis=1), cut.shift0 + cut.v_tool * nodes.t)[0] > 0
    return mesh_of(mesh.tri[~inside], nodes.n, mesh.alpha) if inside.any() else mesh


def refine_run(run: "CutRun", nodes: Nodes, mesh: Mesh, hist: History):
    """The node rule of the cut (:func:`refsph.pfem.refine.refine_nodes`; no node inserted within half a spacing
    of the tool): (nodes, the old mesh renumbered, its history); ``run``'s per-node arrays (h, fixed, X0, ids,
    f_T, the warm start's du) follow."""
    cut = run.cut
    shift = cut.shift0 + cut.v_tool * nodes.t
    carry = dict(id=(run.ids, "keep"), X0=(run.X0, "keep"), f_T=(run.f_T, "sum"))
    if run.du_prev is not None:
        carry["du"] = (run.du_prev, "mean")
    points = (tool_intrusions(nodes.x, mesh, lambda x: cut.shape.gap(x, shift), 0.1 * run.h) if cut.edge_nodes
              else None)
    nodes, h, fixed, extra, change = refine_nodes(
        nodes, mesh, hist, run.h, run.fixed, cut.node_rule, extra=carry,
        forbidden=lambda x: cut.shape.gap(x, shift)[0] > -0.5 * cut.info["dx"], points=points)
    if not change.changed:
        return nodes, mesh, hist
    run.h, run.fixed, run.ids, run.X0, run.f_T = h, fixed, extra["id"], extra["X0"], extra["f_T"]
    run.du_prev = extra.get("du", run.du_prev)
    run.inserted += len(change.parents)
    run.removed += len(change.merged)
    return (nodes, *renumber_mesh(mesh, hist, change))


def heat_step(run: "CutRun", nodes: Nodes, mesh: Mesh, r, contact: StepContact, dt: float) -> None:
    """The heat step of the cut (module text), in place: nodes.T, the tool's temperatures and the ledger of ``run``.
    The frictional work of a node is |f_T| times its slip less the elastic part (f_T^n - f_T) / (k_T l) of it: what
    the return map dissipates (zero where the node sticks)."""
    hm, n, c = run.cut.heat, nodes.n, contact.last
    xt = run.tool_x(nodes.t)
    q_p = plastic_heat(mesh, r, run.cut.law.strength, n)                      # [J/m] per node
    kl = contact.p.k_tangent * np.maximum(contact.length, 1e-300)
    q_f = hm.eta * np.abs(c["f_T"]) * np.abs(c["slip"] - (contact.f_T_n - c["f_T"]) / kl)
    q_f[c["f_N"] <= 0] = 0.0
    touching = np.flatnonzero(c["f_N"] > 0)
    nearest = cKDTree(xt).query(nodes.x[touching])[1] if len(touching) else np.zeros(0, dtype=np.int64)
    P = np.zeros(n + len(xt))
    P[:n] = (q_p + hm.chip_fraction * q_f) / dt
    np.add.at(P, n + nearest, (1.0 - hm.chip_fraction) * q_f[touching] / dt)
    length = boundary_lengths(nodes.x, mesh.edges, n)[touching]
    G = contact_conductance(np.stack([touching, n + nearest], axis=1), length, hm.h_int, n + len(xt))
    free = mesh.edges[~np.isin(mesh.edges, touching).any(axis=1)]
    x_all = np.concatenate([nodes.x, xt])
    tri = np.concatenate([mesh.tri, hm.tool_tri + n])
    k = np.concatenate([np.full(len(mesh.tri), hm.k_work), np.full(len(hm.tool_tri), hm.k_tool)])
    mc = np.concatenate([nodes.m * hm.cp_work, hm.tool_mc])
    fixed = np.concatenate([np.flatnonzero(run.fixed[:, 0]), n + hm.tool_fixed])
    T, step = thermal_step(x_all, tri, np.concatenate([nodes.T, run.T_tool]), dt, k, None, P,
                           edges=np.concatenate([free, hm.tool_edges + n]), loss=hm.loss, fixed=fixed,
                           T_fixed=hm.T_fixed, conductance=G, mc=mc)
    nodes.T, run.T_tool = T[:n], T[n:]
    L = run.ledger
    L["plastic"] += float(q_p.sum())
    L["friction"] += float(q_f.sum())
    L["friction_to_tool"] += float((1.0 - hm.chip_fraction) * q_f[touching].sum())
    L["stored"] += step.stored
    L["lost"] += step.lost
    L["removed"] += step.removed


def run_pfem_cut(cut: PFEMCut, progress=None, max_steps: int | None = None) -> dict:
    """Algorithm 1 to t_end (module text): :class:`CutRun` stepped to the end (or ``max_steps``); its
    :meth:`CutRun.result`. ``progress(step, nodes, F_tool, step_result)`` after each step."""
    run = CutRun(cut)
    while not run.done and (max_steps is None or run.steps < max_steps):
        r = run.step()
        if progress:
            progress(run.steps, run.nodes, run.reaction["tool"][-1], r)
    return run.result()
