"""The Taylor impact with the PFEM (issue 24's check of the method on a large plastic deformation): the 2D plane
strain half slab of :mod:`refsph.scenes.taylor` (Table 1's 4340 steel, Johnson-Cook, 181 m/s onto a rigid
frictionless wall), beside the SPH slabs of chapter 06.

Nodes on a lattice of spacing ~dp that fills the half section exactly (0 <= x <= R, 0 <= y <= L; a finite element
body's boundary nodes lie on its surface, where SPH particles sit half a spacing inside), x held at x = 0 (the
symmetry plane), the wall a flat frictionless penalty contact (:mod:`refsph.pfem.contact`), the trapezoidal rule
at a fixed step, remeshed when a triangle degrades. Length L = max y - min y and width 2 max x at the end.

**Status (issue 24): a first look, not yet a check.** dp = 0.5 mm, dt = 0.25 us. With the paper's trapezoidal rule
the impact face rings on the penalty wall (it damps nothing: at dp = 1 mm the bottom had lifted 68 um after
10 us) and the foot spreads fast: 11.9 mm wide at 10 us, 16.1 mm at 25 us, where Newton failed. With a damped
Newmark rule (gamma = 0.7) the face stays on the wall and the slab shortens to 34.96 mm at 26 us (the SPH slabs,
``refsph run taylor --dim 2 --dp 0.5e-3``: 35.2-35.4 mm at rest, foot 10.7-10.9 mm) with a foot of 13.3 mm; then
the wall contact is lost (nodes 4.6 mm through the wall at 50 us, the slab "rebounds" to 39.5 mm): the contact
node set (the alpha-shape boundary) or the penalty lets nodes through after the heavy deformation of the corner.
At dp = 1 mm (dt = 0.5 us, gamma = 0.7) the run stays on the wall and ends at 34.88 mm long, 13.58 mm wide at
50 us (rebounding from the wall from 40 us): the length is the SPH slabs' within 1.5 %, the foot 25 % wider (the
SPH slabs' artificial viscosity, beta1 = beta2 = 1.5, resists the spreading; the PFEM has none; not yet measured).
"""
from __future__ import annotations

import time

import numpy as np

from ..paper_data import TAYLOR_GEOMETRY
from ..penalty import RoundedPolygon
from ..scenes.taylor import taylor_johnson_cook, taylor_material
from .contact import StepContact, ToolContact, boundary_lengths, solve_with_active_set
from .element import shape_gradients
from .mesh import alpha_shape_mesh, remesh_needed
from .solid import (TRAPEZOIDAL, Loads, Newmark, SolidLaw, commit, history_from_nodes, make_nodes, settle_nodes,
                    transfer_history)

__all__ = ["pfem_taylor_2d"]


def pfem_taylor_2d(dp: float, dt: float, t_end: float, alpha: float = 1.4, penalty: float = 50.0,
                   remesh_quality: float = 0.3, progress=None, newmark: Newmark = TRAPEZOIDAL) -> dict:
    """The impact to ``t_end`` [s] at step ``dt`` [s] (``newmark``: the time rule): final length and width [m],
    the history of both, the mass and the Newton record."""
    g = TAYLOR_GEOMETRY
    L, R, v0 = g["length_m"], 0.5 * g["diameter_m"], g["impact_velocity_m_s"]
    nx, ny = max(1, round(R / dp)), max(1, round(L / dp))
    X, Y = np.meshgrid(np.linspace(0, R, nx + 1), np.linspace(0, L, ny + 1))
    x = np.c_[X.ravel(), Y.ravel()]
    mat, jc = taylor_material(), taylor_johnson_cook(1293.0, 1.0)
    law = SolidLaw.from_elastic(mat, jc, alpha_T=0.0, T_ref=jc.T_room)
    mesh = alpha_shape_mesh(x, alpha)
    A = shape_gradients(x[mesh.tri])[1]
    m = np.bincount(mesh.tri.ravel(), np.repeat(mat.rho0 * A / 3.0, 3), minlength=len(x))
    nodes = make_nodes(x, m, jc.T_room)
    nodes.v[:, 1] = -v0
    h = np.full(len(x), min(R / nx, L / ny))
    fixed = np.zeros((len(x), 2), bool)
    fixed[np.isclose(x[:, 0], 0.0), 0] = True
    wall = RoundedPolygon.from_polygon([[-L, -L], [2 * L, -L], [2 * L, 0.0], [-L, 0.0]], 0.0, [0.0, 0.0])
    contact = ToolContact(k_normal=penalty * law.G / h[0], k_tangent=penalty * law.G / h[0], friction=None)
    hist_e, zero = history_from_nodes(nodes, mesh), np.zeros_like(x)
    out = dict(t=[], length=[], width=[], iterations=[])
    t0 = time.perf_counter()
    while nodes.t < t_end * (1 - 1e-9):
        step_dt = min(dt, t_end - nodes.t)
        c = StepContact(contact, wall, [0.0, 0.0], [0.0, 0.0], nodes.x, np.zeros(nodes.n), nodes.T,
                        boundary_lengths(nodes.x, mesh.edges, nodes.n), np.flatnonzero(mesh.boundary))
        r = solve_with_active_set(nodes, mesh, hist_e, law, step_dt, Loads(fixed, zero, contact=c), dynamic=newmark)
        nodes = commit(nodes, r, step_dt, newmark)
        settle_nodes(nodes, mesh, r, jc)
        hist_e = r.history
        if remesh_needed(nodes.x, mesh, remesh_quality):
            new = alpha_shape_mesh(nodes.x, alpha, h)
            hist_e, mesh = transfer_history(mesh, r.history, new, nodes), new
        out["t"].append(nodes.t)
        out["length"].append(float(np.ptp(nodes.x[:, 1])))
        out["width"].append(2.0 * float(nodes.x[:, 0].max()))
        out["iterations"].append(r.iterations)
        if progress:
            progress(nodes, out)
    return dict(final_length_m=out["length"][-1], final_width_m=out["width"][-1], history=out,
                mass=float(nodes.m.sum()), n_nodes=nodes.n, max_eps_p=float(nodes.eps_p.max()),
                wall_time_s=time.perf_counter() - t0, nodes=nodes, mesh=mesh)

