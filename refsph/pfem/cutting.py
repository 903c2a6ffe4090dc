"""The second paper's orthogonal cut with the PFEM (Section 2.3.5, Figure 5): the same case, tool and measures as
refsph's SPH scene (:mod:`refsph.scenes.thermal_cutting`), solved by Algorithm 1.

Scene: the workpiece 3 t_u high, its bottom row and left column held, graded (the paper's Figure 5): spacing
dx = t_u / n_tu in a band 2 t_u deep under the top surface (the uncut layer and the shear zones under it), 2 dx
below; the tool of the SPH scene (10 deg rake, 10 deg clearance, 10 um edge radius; rigid, at -v_c) as the exact
rounded polygon of :mod:`refsph.pfem.contact`. Real density: the implicit step has no stability limit, so nothing
is mass-scaled (the SPH runs scale the density by s; here s = 1).

Each step (Algorithm 1): the tool moves by -v_c dt; Newton-Raphson solves the mechanical step with the contact
inside it (:func:`refsph.pfem.solid.newton_step`); the nodes move; the plastic work heats the nodes (chi dW_p of
each triangle, a third to each node, over m_i c_p: adiabatic, or the source of the heat step when conduction is
on); the history goes to the nodes and the nodes are meshed again (remeshing every step). A step whose Newton fails
is retried at half the step (up to four times). dt = ``courant`` dx / v_c: the tool moves a fraction of the finest
spacing per step (the mesh, not stability, limits it).

**Status (issue 24): the first tool contact is passed, the 18 cuts are not yet run.** Newton-Raphson had stalled
at the first contact (at a scaled residual ~0.3, however small the step): the trapezoidal rule's velocities ring
at an impact, and the predictor du = dt v drove the contact nodes deep into the tool. Each step now starts from
du = 0 and freezes the contact and slip sets within a Newton solve
(:func:`~refsph.pfem.contact.solve_with_active_set`). The quick cut (case 1, t_u/5, 4 t_u) then went past the
first contact, at steps halved a few times, to 0.78 t_u (Fc about 110 N/mm, eps_p 0.8), where a Newton solve
still needed more than 25 iterations at dt / 32 (with a damped Newmark rule, gamma = 0.7, the same at 0.79 t_u);
allowed 80 iterations (now the default; 43 were needed once) it went on past 1 t_u.
A flat contact with friction works (``tests/test_pfem.py``:
stick, then slide at F_T / F_N = mu to round-off).

The measures are the SPH scene's own functions (:func:`refsph.scenes.thermal_cutting.chip_measures`,
:func:`~refsph.scenes.thermal_cutting.thermal_cutting_metrics`), so the two methods are measured alike.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..contact import CoulombFriction
from ..paper_data import AISI1045_RLA, CONTACT_RLA, TI6AL4V_RLA, rla_cutting_case
from ..plasticity import JohnsonCook, ModifiedJohnsonCook
from ..scenes.thermal_cutting import (CLEARANCE_DEG, EDGE_RADIUS, RAKE_DEG, chip_measures, thermal_cutting_metrics,
                                      tool_shape)
from .contact import StepContact, ToolContact, boundary_lengths, solve_with_active_set
from .mesh import alpha_shape_mesh, remesh_needed
from .solid import (TRAPEZOIDAL, Loads, Newmark, NewtonFailed, SolidLaw, commit, history_from_nodes, make_nodes,
                    settle_nodes, transfer_history)

__all__ = ["PFEMCut", "graded_workpiece", "pfem_cut", "run_pfem_cut"]

MATERIALS = {"AISI1045": AISI1045_RLA, "Ti6Al4V": TI6AL4V_RLA}


@dataclass
class PFEMCut:
    """A PFEM cut as data: the nodes (:class:`refsph.pfem.solid.Nodes`), their spacing ``h`` (N,) [m] (the
    alpha-shape's local size), the held components ``fixed`` (N, 2), the ``law``, the tool (``shape``, its core's
    position ``shift0`` at t = 0 and velocity ``v_tool`` [m/s]), the ``contact``, ``alpha``, the step ``dt`` and
    ``t_end`` [s], the initial positions ``X0`` and ``info`` (the SPH scene's keys, for the measures); a remeshing
    every ``remesh_every`` steps and whenever a triangle's quality drops below ``remesh_quality``; ``newmark`` the
    time rule (the paper's trapezoidal rule by default); ``max_iter`` Newton iterations per solve; ``max_move`` the
    largest Newton correction of a node, in its local sizes (:func:`refsph.pfem.solid.newton_step`)."""

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
    remesh_every: int = 1
    remesh_quality: float = 0.3
    newmark: Newmark = TRAPEZOIDAL
    max_iter: int = 80
    max_move: float | None = 0.05


def graded_workpiece(length: float, tu: float, dx: float) -> tuple[np.ndarray, np.ndarray]:
    """(x (N, 2), h (N,)): rows dx apart (columns dx apart) in the top 2 tu of a workpiece 3 tu high and ``length``
    long, rows and columns 2 dx apart below (module text)."""
    H = 3.0 * tu
    nx, nf = round(length / dx), round(2.0 * tu / dx)
    ny = round(H / dx)
    fine = [(i * dx, (ny - j) * dx) for j in range(nf + 1) for i in range(nx + 1)]
    coarse = [(i * 2 * dx, (ny - nf) * dx - j * 2 * dx) for j in range(1, (ny - nf) // 2 + 1)
              for i in range(nx // 2 + 1)]
    x = np.array(fine + coarse)
    h = np.concatenate([np.full(len(fine), dx), np.full(len(coarse), 2 * dx)])
    return x, h


def pfem_cut(case: int, n_tu: float = 10.0, travel: float = 16.0, length: float | None = None,
             courant: float = 0.25, alpha: float = 1.4, penalty: float = 200.0, friction: bool = True) -> PFEMCut:
    """The cut of row ``case`` of the paper's Appendix B: dx = t_u / n_tu, ``travel`` t_u of cut on a workpiece
    ``length`` [m] long (default (travel + 12) t_u), dt = courant dx / v_c, contact penalties ``penalty`` G / dx."""
    row = rla_cutting_case(int(case))
    mat = MATERIALS[row["material"]]
    vc, tu = row["vc_m_per_min"] / 60.0, row["tu_mm"] * 1e-3
    dx = tu / n_tu
    length = (travel + 12.0) * tu if length is None else length
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
    apex = np.array([x[:, 0].max() + 0.5 * dx, y0])
    centroid = apex + np.array([2.0 * tu, 2.0 * tu])
    shape = tool_shape(tu, apex, centroid, 10.0, 6.0)
    mu = CoulombFriction(mu0=mat["mu0"], q=mat["q_friction"], T_room=T0, T_melt=mat["T_melt_K"]) if friction else None
    contact = ToolContact(k_normal=penalty * law.G / dx, k_tangent=penalty * law.G / dx, friction=mu)
    fixed = np.zeros((len(x), 2), bool)
    fixed[(x[:, 1] < 1e-12) | (x[:, 0] < 1e-12)] = True
    A_cell = np.where(h > dx * 1.5, 4 * dx * dx, dx * dx)
    nodes = make_nodes(x, mat["rho"] * A_cell, T0)
    info = dict(case=int(case), material=row["material"], vc_m_s=vc, tu_m=tu, dx=dx, length_m=float(x[:, 0].max()),
                height_m=H, y0=y0, n_work=len(x), travel_m=travel * tu, mass_scale=1.0,
                inertia_ratio=mat["rho"] * vc * vc / mat["A_Pa"], rake_deg=RAKE_DEG, clearance_deg=CLEARANCE_DEG,
                edge_radius_m=EDGE_RADIUS, apex0=apex.tolist(), measured=row, method="pfem", alpha=alpha,
                courant=courant, penalty=penalty)
    return PFEMCut(nodes=nodes, h=h, fixed=fixed, law=law, shape=shape, shift0=centroid, v_tool=np.array([-vc, 0.0]),
                   contact=contact, alpha=alpha, dt=courant * dx / vc, t_end=travel * tu / vc, X0=x.copy(), info=info)


def run_pfem_cut(cut: PFEMCut, progress=None, max_steps: int | None = None) -> dict:
    """Algorithm 1 to t_end (module text); the run's history and metrics (the SPH scene's keys), its nodes and mesh
    at the end, and the Newton record (iterations per step, retries, wall time)."""
    nodes, law, info = cut.nodes, cut.law, cut.info
    hist = {k: [] for k in ("t", "T_RF", "T_RF_max", "T_FCS", "chip_mm", "contact_mm", "max_T", "max_eps_p")}
    reaction = dict(t=[], dt=[], tool=[])
    f_T = np.zeros(nodes.n)
    mesh = alpha_shape_mesh(nodes.x, cut.alpha, cut.h)
    hist_e = history_from_nodes(nodes, mesh)
    iters, retries, t0, step, remeshes = [], 0, time.perf_counter(), 0, 0
    zero = np.zeros_like(nodes.x)
    while nodes.t < cut.t_end * (1 - 1e-9) and (max_steps is None or step < max_steps):
        dt = min(cut.dt, cut.t_end - nodes.t)
        for attempt in range(5):
            t1 = nodes.t + dt
            contact = StepContact(cut.contact, cut.shape, cut.shift0 + cut.v_tool * t1, cut.v_tool * dt, nodes.x,
                                  f_T, nodes.T, boundary_lengths(nodes.x, mesh.edges, nodes.n),
                                  np.flatnonzero(mesh.boundary))
            try:
                r = solve_with_active_set(nodes, mesh, hist_e, law, dt, Loads(cut.fixed, zero, contact=contact),
                                          dynamic=cut.newmark, max_iter=cut.max_iter, max_move=cut.max_move)
                break
            except NewtonFailed as e:
                dt, retries = 0.5 * dt, retries + 1
                last_failure = e
        else:
            raise NewtonFailed(f"PFEM cut: Newton failed at t = {nodes.t:.3e} s even at dt = {dt:.2e} s",
                               *last_failure.args[1:])
        iters.append(r.iterations)
        nodes = commit(nodes, r, dt, cut.newmark)
        c = contact.last
        f_T = c["f_T"]
        F_tool = -r.contact_force.sum(axis=0) if r.contact_force is not None else np.zeros(2)
        settle_nodes(nodes, mesh, r, law.strength)
        if remesh_needed(nodes.x, mesh, cut.remesh_quality) or step % cut.remesh_every == cut.remesh_every - 1:
            new = alpha_shape_mesh(nodes.x, cut.alpha, cut.h)            # Algorithm 1: "if remeshing is needed"
            hist_e, mesh = transfer_history(mesh, r.history, new, nodes), new
            remeshes += 1
        else:
            hist_e = r.history
        reaction["t"].append(nodes.t)
        reaction["dt"].append(dt)
        reaction["tool"].append(F_tool)
        m = chip_measures(nodes.x, cut.X0, nodes.T, nodes.t, info)
        for k, v in dict(t=nodes.t, max_T=float(nodes.T.max()), max_eps_p=float(nodes.eps_p.max()), **m).items():
            hist[k].append(v)
        step += 1
        if progress:
            progress(step, nodes, F_tool, r)
    hist["reaction"] = {k: np.asarray(v) for k, v in reaction.items()}
    metrics = thermal_cutting_metrics(hist, info, cut.t_end)
    return dict(nodes=nodes, mesh=mesh, history=hist, metrics=metrics, newton_iterations=iters, retries=retries,
                wall_time_s=time.perf_counter() - t0, steps=step, remeshes=remeshes)
