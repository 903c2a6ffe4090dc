"""The PFEM's thermal step (Rodriguez Prieto, Larsson & Afrasiabi 2023, Sections 2.1 and 2.3.1-2.3.3): heat
conduction on the linear triangles of the current mesh, implicit in time (backward Euler), solved by Newton-Raphson.

    Eq. (14)  rho c_p DT/Dt = k lap T + Q_s                          (the energy balance, Lagrangian)
    Eq. (18)  C dT/dt + F_int,ther = F_ext,ther                         (semi-discrete: nodal temperatures T)
    Eq. (22)  C (T_{n+1} - T_n) / dt + F_int,ther(T_{n+1}) = F_ext,ther(T_{n+1})      (backward Euler)
    Eq. (6)   q = h_c (T_s - T_inf) + emissivity sigma (T_s^4 - T_inf^4)   (convection + radiation, W/m^2)
    Eq. (5)   Q_s = chi sigma_y epsdot_p;   Eq. (7)  q_f = eta |f_fric| |v_rel|   (the heat sources)

Plane, thickness 1 m: every heat here is per metre of width (J/m, powers W/m). SI units throughout.

**From Eq. (14) to Eq. (18).** Multiply Eq. (14) by a test function, integrate over the body and move one derivative
of the Laplacian onto the test function (Green's formula); the boundary term that appears is the heat flux through
the surface, which Eq. (6) (losses) and Eq. (7) (friction) supply. With T = sum_a N_a T_a, N_a the linear shape
functions of the triangles (1 at node a, 0 at the others, linear in between), and the test function each N_a in
turn:

    C_ab   = sum_e int_e (rho c_p)_e N_a N_b dA        heat capacity matrix                 (:func:`capacity`)
    K_ab   = sum_e int_e k_e grad N_a . grad N_b dA    conductivity, F_int = K T   (:func:`conductivity_matrix`)
    F_ext  = P - L(T)                                  P: nodal heat sources [W/m]; L: the losses of Eq. (6)

On a linear triangle grad N_a is constant, so the element matrices are exact in closed form: K_e = k_e A_e g g^T
(g the 3 x 2 shape gradients, :func:`refsph.pfem.element.shape_gradients`), C_e = (rho c_p)_e A_e / 12 (1 + delta_ab)
(:func:`refsph.pfem.element.pressure_mass`). The paper evaluates its element vectors by Gauss quadrature; for these
two matrices any rule exact for quadratics gives the same numbers. Each body may have its own k and rho c_p (the
workpiece's and the tool's triangles differ): both are given per triangle. The sum over the elements is a sparse
assembly (scipy.sparse COO -> CSR adds the duplicate entries; vectors by np.bincount): no Python loop over elements.

**Lumped capacity (the default).** The paper does not say which C it uses. refsph lumps it: the row sum, C_aa =
sum_e (rho c_p)_e A_e / 3 over the triangles around node a, the heat capacity of the third of each triangle that a
node stands for. Why: with a diagonal positive C, and K of a Delaunay mesh (the PFEM remeshes with Delaunay: the two
angles opposite an inside edge add to at most pi, so K_ab = -k (cot alpha + cot beta) / 2 <= 0 where one k holds on
both sides, as at a boundary edge whose opposite angle is at most pi/2), the matrix C/dt + K of Eq. (22) is an
M-matrix and backward Euler keeps the discrete maximum principle at every dt: without sources and losses a new
temperature is a weighted mean of the old ones and the fixed values, no undershoot where a hot chip meets a cold
tool. The consistent C has positive off-diagonal entries and, at steps short against rho c_p h^2 / k, over- and
undershoots next to a sudden change (``lumped=False`` chooses it; a node held 1000 K above a cold body for
1e-3 rho c_p h^2 / k: 112 K below the cold temperature next to it; both converge as h^2, tests/test_pfem_thermal.py).
The losses follow the same choice: nodal (trapezoidal) quadrature along each boundary edge with the lumped capacity,
three-point Gauss with the consistent one (exact for the T^4 of a linear T along the edge: degree 5).

**The losses, Eq. (6),** act on the boundary edges the caller gives (the alpha-shape's, :mod:`refsph.pfem.mesh`;
a face in contact with the tool is not free, and the caller leaves its edges out). Along an edge of length l with
end nodes a, b and T = N_a T_a + N_b T_b, node a loses L_a = l int_0^1 N_a q(T) ds [W/m] (:func:`edge_losses`).
The T^4 of radiation makes Eq. (22) nonlinear.

**Newton-Raphson.** Eq. (22) is the residual, at every node

    R(T) = C (T - T_n) / dt + K T + L(T) - P = 0,      tangent  dR/dT = C / dt + K + dL/dT

with the exact tangent dL_a/dT_b = l int_0^1 N_a N_b q'(T) ds, q' = h_c + 4 emissivity sigma T^3; iterate
T <- T - (dR/dT)^{-1} R (scipy.sparse.linalg.spsolve), from T_n. Without radiation R is linear and one iteration
solves it; with radiation the exact tangent converges quadratically, and the iterations go on until the residual
stops falling (by less than 4 times, below 1e-9 s) or max |R_a| <= tol max s_a, where
s = (|C|/dt + |K| + |dL/dT|) |T| + |C| |T_n| / dt + |L| + |P| bounds the rounding error of R (a temperature is known
to eps |T|). The bound is pessimistic: the residual's actual floor is ~1e-17 to 1e-16 s, hence tol = 1e-16 by
default; a looser tol stops a quadratic iteration one step early, with a residual ~10 times the floor that does not
cancel in the heat ledger below (1e-11 of the heats, where at the floor it closes to 1e-16).

**Fixed temperatures (Dirichlet)** are unknowns no more: their rows and columns leave the Newton system (the free
nodes' residuals vanish; the fixed nodes' do not). The residual R_a left at a fixed node is the power [W/m] that
holding it at its value supplies; -dt R_a is the heat it removes.

**The heat ledger** of the step (:class:`StepHeat`), in the vocabulary of :mod:`refsph.thermal`. Summed over all
nodes, K T drops out (K 1 = 0: conduction moves heat and makes none), so Eq. (22) summed reads

    source = stored + lost + removed,     source = dt sum_a P_a,   stored = sum_ab C_ab (T_{n+1,b} - T_{n,b}),
                                          lost = dt sum_a L_a(T_{n+1}),   removed = -dt sum_(a fixed) R_a(T_{n+1})

which closes to round-off (not by construction: each term is computed on its own; a wrong tangent, a lost row or a
non-conservative matrix shows as a residual). For K T to drop out in floating point too, the residual evaluates it
as pair fluxes, (K T)_a = sum_b w_ab (T_a - T_b) with w_ab = -K_ab (K 1 = 0 makes the two forms equal): each pair's
flux leaves one node and enters the other, like the antisymmetric pair sums of :mod:`refsph.thermal`, and the sum
over the nodes is rounded at the size of the fluxes, not at that of K's entries times 300 K (with a conductive tool
and long steps the latter is ~1e-11 of the heats).

**Where refsph departs from the paper, and why.** The paper gives no details of its thermal finite elements beyond
Eq. (22); refsph chooses: (i) the lumped capacity and nodal quadrature of the losses by default (above); (ii) the
heat sources as nodal powers P [W/m], given by the caller, held over the step: the staggered scheme of Section 2.3.3
solves the mechanics first, at fixed temperature, and its plastic heat (Eq. (5), per triangle: :func:`nodal_source`
gives int N_a Q_s dA = Q_s,e A_e / 3) and frictional heat (Eq. (7), at the contact nodes) are those of that step;
(iii) the matrices on the configuration the caller gives, the updated one of the mechanical step (the paper solves
"the heat equation ... in the updated configuration"); (iv) between the workpiece and the tool, meshed apart
(:func:`refsph.pfem.mesh.alpha_shape_mesh` keeps no triangle that spans two bodies), heat crosses by a contact
conductance between node pairs that the caller chooses (:func:`contact_conductance`; the paper does not say how
its PFEM conducts into the tool); (v) temperatures in kelvin, T > 0 (radiation needs absolute temperatures);
(vi) for nodes that carry fixed masses (:mod:`refsph.pfem.solid`), the lumped capacity may be the nodes' own m_i c_p
(``thermal_step(..., mc=...)``), which a remeshing leaves alone, where the triangles' (rho c_p)_e A_e / 3 would share
the heat among the nodes anew at each remeshing.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from ..thermal import STEFAN_BOLTZMANN, SurfaceLoss
from .element import pressure_mass, shape_gradients
from .solid import NewtonFailed

__all__ = ["StepHeat", "conductivity_matrix", "capacity", "nodal_source", "edge_losses", "contact_conductance",
           "thermal_step"]

# Quadrature along an edge, s in [0, 1]: points and weights. Nodal (trapezoidal): the lumped losses; Gauss with
# three points: exact to degree 5, so exact for N_a T^4 with a linear T.
NODAL = (np.array([0.0, 1.0]), np.array([0.5, 0.5]))
GAUSS3 = (0.5 + np.sqrt(15.0) / 10.0 * np.array([-1.0, 0.0, 1.0]), np.array([5.0, 8.0, 5.0]) / 18.0)


@dataclass(frozen=True)
class StepHeat:
    """The heats of one thermal step [J per metre of width] (module text): ``source`` (the nodal heat sources, dt
    sum P), ``stored`` (sum C (T_{n+1} - T_n)), ``lost`` (convection + radiation, Eq. (6)), ``removed`` (by the fixed
    temperatures); and the Newton iterations with the largest free-node residual [W/m] before each of them and after
    the last (``residual_norms``, one more than ``iterations``)."""

    source: float
    stored: float
    lost: float
    removed: float
    iterations: int
    residual_norms: tuple

    @property
    def residual(self) -> float:
        """source - stored - lost - removed: zero to round-off."""
        return self.source - self.stored - self.lost - self.removed


# ---------------------------------------------------------------------------------------------------- input checks

def _points(x) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[1] != 2:
        raise ValueError(f"x must be the node positions (N, 2) [m], got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError("x must be finite")
    return x


def _indices(name: str, a, width: int, n: int) -> np.ndarray:
    """An integer array (K, width) of node indices in 0..n-1."""
    a = np.asarray(a)
    if a.ndim != 2 or a.shape[1] != width or not (np.issubdtype(a.dtype, np.integer) or a.size == 0):
        raise ValueError(f"{name} must be an integer array (K, {width}) of node indices, got {a.dtype} {a.shape}")
    if a.size and (a.min() < 0 or a.max() >= n):
        raise ValueError(f"{name} holds node indices outside 0..{n - 1}")
    return a.astype(np.intp)


def _values(name: str, v, m: int, what: str, lower: float, strict: bool, upper: float = np.inf) -> np.ndarray:
    """One value or m values (one per ``what``), finite, > lower (strict) or >= lower, <= upper."""
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{name} must be a number or an array of numbers, got {v!r}") from err
    if a.ndim == 0:
        a = np.full(m, float(a))
    if a.shape != (m,):
        raise ValueError(f"{name} must be one value or one per {what} ({m}), got shape {a.shape}")
    bad = ~np.isfinite(a) | ((a <= lower) if strict else (a < lower)) | (a > upper)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        rng = f"{'>' if strict else '>='} {lower}" + (f" and <= {upper}" if upper < np.inf else "")
        raise ValueError(f"{name} must be finite and {rng}; got {a[i]!r} (entry {i})")
    return a


def _scalar(name: str, v, lower: float, strict: bool, upper: float = np.inf) -> float:
    if np.ndim(v) != 0:
        raise ValueError(f"{name} must be one number, got shape {np.shape(v)}")
    return float(_values(name, v, 1, "", lower, strict, upper)[0])


def _mesh(x, tri) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Checked nodes and triangles, with the shape gradients (M, 3, 2) and areas (M,) of the triangles, which must be
    counter-clockwise (a positive area: an inverted triangle is a failed mechanical step, not a mesh to conduct on)."""
    x = _points(x)
    tri = _indices("tri", tri, 3, len(x))
    g, A = shape_gradients(x[tri])
    if np.any(~(A > 0)):
        i = int(np.flatnonzero(~(A > 0))[0])
        raise ValueError(f"tri: triangle {i} is clockwise or degenerate (signed area {A[i]!r}); "
                         "tri must list counter-clockwise triangles")
    return x, tri, g, A


def _assemble(tri: np.ndarray, ke: np.ndarray, n: int) -> sp.csr_matrix:
    """sum_e of the element matrices ke (M, w, w) on the nodes tri (M, w): COO -> CSR adds the duplicates."""
    w = tri.shape[1]
    rows, cols = np.repeat(tri, w, axis=1), np.tile(tri, (1, w))
    return sp.coo_matrix((ke.ravel(), (rows.ravel(), cols.ravel())), shape=(n, n)).tocsr()


def _to_nodes(tri: np.ndarray, per_vertex: np.ndarray, n: int) -> np.ndarray:
    """sum_e of per-vertex element values (M, w) at the nodes."""
    return np.bincount(tri.ravel(), weights=per_vertex.ravel(), minlength=n)


# ------------------------------------------------------------------------------------------------ the FE operators

def conductivity_matrix(x: np.ndarray, tri: np.ndarray, k) -> sp.csr_matrix:
    """Eq. (18)'s F_int,ther = K T with K_ab = sum_e int_e k_e grad N_a . grad N_b dA = sum_e k_e A_e g_a . g_b
    [W/(m K)]: nodes ``x`` (N, 2) [m], counter-clockwise triangles ``tri`` (M, 3), conductivity ``k`` [W/(m K)]
    per triangle (M,) or one value. Symmetric, K 1 = 0 (a uniform temperature conducts nothing)."""
    x, tri, g, A = _mesh(x, tri)
    return _conductivity(tri, g, A, k, len(x))


def _conductivity(tri, g, A, k, n) -> sp.csr_matrix:
    k = _values("k", k, len(tri), "triangle", 0.0, strict=False)
    return _assemble(tri, (k * A)[:, None, None] * np.einsum("mad,mbd->mab", g, g), n)


def capacity(x: np.ndarray, tri: np.ndarray, rho_cp, lumped: bool = True) -> sp.csr_matrix:
    """Eq. (18)'s heat capacity matrix [J/(m K)]: consistent, C_ab = sum_e (rho c_p)_e A_e / 12 (1 + delta_ab), or
    lumped (the default; module text), its row sum C_aa = sum_e (rho c_p)_e A_e / 3 on the diagonal. ``rho_cp``: the
    volumetric heat capacity [J/(m^3 K)] per triangle (M,) or one value. Both have the same column sums, so
    sum_ab C_ab dT_b, the heat stored, is the same."""
    x, tri, _, A = _mesh(x, tri)
    return _capacity(tri, A, rho_cp, lumped, len(x))


def _capacity(tri, A, rho_cp, lumped, n) -> sp.csr_matrix:
    rho_cp = _values("rho_cp", rho_cp, len(tri), "triangle", 0.0, strict=True)
    if lumped:
        return sp.diags(_to_nodes(tri, np.repeat((rho_cp * A / 3.0)[:, None], 3, axis=1), n)).tocsr()
    return _assemble(tri, rho_cp[:, None, None] * pressure_mass(A), n)


def nodal_source(x: np.ndarray, tri: np.ndarray, q) -> np.ndarray:
    """A heat source per triangle as nodal powers [W/m]: P_a = sum_e int_e N_a Q_e dA = sum_e Q_e A_e / 3, with Q_e
    [W/m^3] constant on the triangle, e.g. the plastic heat of Eq. (5), Q_s = chi sigma_y epsdot_p (constant on a
    linear triangle). ``q``: per triangle (M,) or one value, >= 0."""
    x, tri, _, A = _mesh(x, tri)
    q = _values("q", q, len(tri), "triangle", 0.0, strict=False)
    return _to_nodes(tri, np.repeat((q * A / 3.0)[:, None], 3, axis=1), len(x))


def edge_losses(x: np.ndarray, edges: np.ndarray, T: np.ndarray, h_c: float, emissivity: float, T_inf: float,
                lumped: bool = True) -> tuple[np.ndarray, sp.csr_matrix]:
    """Eq. (6) on the boundary ``edges`` (K, 2): the nodal losses L_a = sum_edges l int_0^1 N_a q(T) ds [W/m], with
    q = h_c (T - T_inf) + emissivity sigma (T^4 - T_inf^4) [W/m^2] and T linear along each edge of length l, and
    their exact derivative dL_a/dT_b = sum_edges l int_0^1 N_a N_b (h_c + 4 emissivity sigma T^3) ds [W/(m K)]
    (sparse, N x N). ``lumped``: nodal (trapezoidal) quadrature, L_a = l/2 q(T_a) and a diagonal derivative; else
    three-point Gauss, exact for linear T (module text). h_c [W/(m^2 K)] >= 0, 0 <= emissivity <= 1, T_inf [K] > 0,
    T (N,) [K] > 0; no defaults for the constants."""
    x = _points(x)
    n = len(x)
    edges = _indices("edges", edges, 2, n)
    T = _values("T", T, n, "node", 0.0, strict=True)
    law = SurfaceLoss(h_c=_scalar("h_c", h_c, 0.0, strict=False), T_ambient=_scalar("T_inf", T_inf, 0.0, strict=True),
                      emissivity=_scalar("emissivity", emissivity, 0.0, strict=False, upper=1.0))
    return _losses(x, edges, T, law, lumped)


def _losses(x, edges, T, law: SurfaceLoss, lumped: bool) -> tuple[np.ndarray, sp.csr_matrix]:
    """:func:`edge_losses` on checked input."""
    n = len(x)
    s, w = NODAL if lumped else GAUSS3
    N = np.stack([1.0 - s, s])                                    # N[a, g]: the edge's shape functions at the points
    length = np.linalg.norm(x[edges[:, 1]] - x[edges[:, 0]], axis=1)
    Tg = T[edges] @ N                                             # (K, G): T at the quadrature points
    dq = law.h_c + 4.0 * law.emissivity * STEFAN_BOLTZMANN * Tg ** 3
    loss = _to_nodes(edges, length[:, None] * ((law.flux(Tg) * w) @ N.T), n)
    dL = length[:, None, None] * np.einsum("ag,bg,kg->kab", N, N, dq * w)
    return loss, _assemble(edges, dL, n)


def contact_conductance(pairs: np.ndarray, length, h_int, n: int) -> sp.csr_matrix:
    """Heat across a contact between bodies meshed apart (module text, (iv)): node pairs ``pairs`` (P, 2), i on one
    body and j on the other, each standing for ``length`` [m] of the interface, exchange h_int l (T_i - T_j) [W/m]
    (``h_int`` [W/(m^2 K)], the thermal contact conductance, per pair or one value). Returns the matrix G [W/(m K)],
    to add to K: G_ii = G_jj = g, G_ij = G_ji = -g for g = h_int l; symmetric with G 1 = 0, so it moves heat and
    makes none. The paper does not say how its PFEM conducts into the tool; which pairs touch is the caller's
    business."""
    pairs = _indices("pairs", pairs, 2, n)
    if np.any(pairs[:, 0] == pairs[:, 1]):
        raise ValueError("pairs must join two different nodes")
    g = (_values("length", length, len(pairs), "pair", 0.0, strict=False)
         * _values("h_int", h_int, len(pairs), "pair", 0.0, strict=False))
    ge = g[:, None, None] * np.array([[1.0, -1.0], [-1.0, 1.0]])
    return _assemble(pairs, ge, n)


# ------------------------------------------------------------------------------------------------ the step, Eq. (22)

def _fixed_nodes(fixed, T_fixed, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The fixed node indices (unique) and their temperatures."""
    if fixed is None:
        return np.zeros(0, dtype=np.intp), np.zeros(0)
    idx = np.asarray(fixed)
    if idx.ndim != 1 or not (np.issubdtype(idx.dtype, np.integer) or idx.size == 0):
        raise ValueError(f"fixed must be a 1-D integer array of node indices, got {idx.dtype} {idx.shape}")
    idx = _indices("fixed", idx[:, None], 1, n)[:, 0]
    if len(np.unique(idx)) != len(idx):
        raise ValueError("fixed lists a node twice")
    if T_fixed is None:
        raise ValueError("fixed needs T_fixed, the temperatures [K] the fixed nodes are held at")
    return idx, _values("T_fixed", T_fixed, len(idx), "fixed node", 0.0, strict=True)


def _newton(residual, T: np.ndarray, free: np.ndarray, linear: bool, tol: float, max_iter: int):
    """Newton-Raphson on the free nodes from T: T <- T - J^{-1} R until max |R| <= tol max(scale) (module text).
    A linear residual (no radiation) is solved by one iteration; a residual that stops falling (by 4 at least) below
    1e-9 of the scale has met round-off. Returns (T, R(T), iterations, the residual norms before each iteration and
    after the last); raises :class:`refsph.pfem.solid.NewtonFailed` after ``max_iter`` iterations."""
    T = T.copy()
    norms = []
    for it in range(max_iter + 1):
        R, J, scale = residual(T)
        r, s = float(np.max(np.abs(R[free]), initial=0.0)), float(np.max(scale[free], initial=0.0))
        norms.append(r)
        if not np.isfinite(r):
            break
        if r <= tol * s or (linear and it == 1) or (it > 0 and r <= 1e-9 * s and r > 0.25 * norms[-2]):
            return T, R, it, norms
        if it == max_iter:
            break
        T[free] -= np.atleast_1d(spsolve(J[free][:, free].tocsc(), R[free]))
    raise NewtonFailed(f"the thermal step did not converge in {max_iter} Newton iterations: max |R| = {norms} W/m")


def thermal_step(x: np.ndarray, tri: np.ndarray, T: np.ndarray, dt: float, k, rho_cp, source=None, *,
                 edges: np.ndarray | None = None, loss: SurfaceLoss | None = None, fixed=None, T_fixed=None,
                 conductance: sp.spmatrix | None = None, lumped: bool = True, mc=None, tol: float = 1e-16,
                 max_iter: int = 25) -> tuple[np.ndarray, StepHeat]:
    """One backward-Euler step of Eq. (22), C (T_{n+1} - T_n) / dt + K T_{n+1} + L(T_{n+1}) = P, by Newton-Raphson
    with the exact tangent (module text). ``x`` (N, 2) [m], ``tri`` (M, 3) counter-clockwise; ``T`` (N,) [K] the
    temperatures T_n; ``dt`` [s]; ``k`` [W/(m K)] and ``rho_cp`` [J/(m^3 K)] per triangle or one value; ``source``:
    the nodal heat powers P (N,) [W/m] (plastic heat, :func:`nodal_source`, and frictional heat, Eq. (7); None:
    none); ``edges`` (K, 2) with ``loss`` (a :class:`refsph.thermal.SurfaceLoss`: its h_c, emissivity and
    T_ambient; the SPH detector fields are unused, the edges are the boundary): the losses of Eq. (6); ``fixed``
    (node indices) held at ``T_fixed`` [K]; ``conductance``: a contact conductance matrix to add to K
    (:func:`contact_conductance`); ``lumped``: the lumped capacity and nodal quadrature of the losses (else
    consistent and Gauss); ``mc`` (N,) [J/(m K)]: instead of ``rho_cp`` (then None), the nodes' own heat capacities
    m_i c_p,i as the lumped C, for nodes that carry fixed masses (:mod:`refsph.pfem.solid`): a remeshing then
    neither makes nor loses heat, where sum_e (rho c_p)_e A_e / 3 changes with the triangles; ``tol``,
    ``max_iter``: Newton's stop. Returns (T_{n+1}, :class:`StepHeat`)."""
    x, tri, g, A = _mesh(x, tri)
    n = len(x)
    T_n = _values("T", T, n, "node", 0.0, strict=True)
    dt = _scalar("dt", dt, 0.0, strict=True)
    P = np.zeros(n) if source is None else _values("source", source, n, "node", -np.inf, strict=False)
    K = _conductivity(tri, g, A, k, n)
    if conductance is not None:
        K = (K + _checked_conductance(conductance, n)).tocsr()
    C = _heat_capacity(tri, A, rho_cp, mc, lumped, n)
    if (loss is None) != (edges is None):
        raise ValueError("the losses of Eq. (6) need both edges (the boundary) and loss (a SurfaceLoss)")
    if loss is not None:
        edges = _indices("edges", edges, 2, n)
        if not isinstance(loss, SurfaceLoss):
            raise ValueError(f"loss must be a refsph.thermal.SurfaceLoss, got {type(loss).__name__}")
    idx, T_idx = _fixed_nodes(fixed, T_fixed, n)
    free = np.ones(n, dtype=bool)
    free[idx] = False
    T_start = T_n.copy()
    T_start[idx] = T_idx
    residual = _residual(x, K, C, T_n, dt, P, edges, loss, lumped)
    linear = loss is None or loss.emissivity == 0.0
    T_new, R, iterations, norms = _newton(residual, T_start, free, linear, tol, max_iter)
    lost = 0.0 if loss is None else dt * float(np.sum(_losses(x, edges, T_new, loss, lumped)[0]))
    heat = StepHeat(source=dt * float(np.sum(P)), stored=float(np.sum(C @ (T_new - T_n))), lost=lost,
                    removed=-dt * float(np.sum(R[idx])), iterations=iterations, residual_norms=tuple(norms))
    return T_new, heat


def _heat_capacity(tri, A, rho_cp, mc, lumped: bool, n: int) -> sp.csr_matrix:
    """C from rho_cp per triangle (:func:`capacity`) or, lumped, from the nodes' m c_p."""
    if mc is None:
        return _capacity(tri, A, rho_cp, lumped, n)
    if rho_cp is not None or not lumped:
        raise ValueError("mc (the nodes' heat capacities) replaces rho_cp (give None) and is a lumped capacity "
                         "(lumped=True)")
    return sp.diags(_values("mc", mc, n, "node", 0.0, strict=True)).tocsr()


def _checked_conductance(G, n: int) -> sp.csr_matrix:
    """A contact conductance matrix: sparse (n, n), symmetric, G 1 = 0 (it moves heat and makes none)."""
    if not sp.issparse(G) or G.shape != (n, n):
        raise ValueError(f"conductance must be a sparse ({n}, {n}) matrix, got {type(G).__name__} {np.shape(G)}")
    G = sp.csr_matrix(G)
    size = np.abs(G.data).max(initial=0.0)
    if not np.all(np.isfinite(G.data)) or np.abs((G - G.T).data).max(initial=0.0) > 1e-12 * size \
            or np.abs(G @ np.ones(n)).max(initial=0.0) > 1e-12 * size:
        raise ValueError("conductance must be finite, symmetric, with zero row sums (contact_conductance makes one)")
    return G


def _residual(x, K, C, T_n, dt, P, edges, loss, lumped):
    """R(T) of Eq. (22) at every node, its tangent dR/dT, and the size of R's round-off: (|C|/dt + |K| + |dL/dT|) |T|
    + |C| |T_n| / dt + |L| + |P| (a temperature is known to eps |T|; module text). K T is evaluated as pair fluxes
    (module text), so that conduction makes no heat in the ledger, to round-off."""
    flux = _pair_fluxes(K)
    A = (C / dt + K).tocsr()
    A_abs = abs(A)

    def residual(T):
        R = C @ (T - T_n) / dt + flux(T) - P
        scale = A_abs @ np.abs(T) + C @ np.abs(T_n) / dt + np.abs(P)
        if loss is None:
            return R, A, scale
        L, dL = _losses(x, edges, T, loss, lumped)
        return R + L, (A + dL).tocsr(), scale + abs(dL) @ np.abs(T) + np.abs(L)

    return residual


def _pair_fluxes(K: sp.spmatrix):
    """K T as a sum of pair fluxes, for a symmetric K with K 1 = 0 (the conductivity matrix, with or without a
    contact conductance): (K T)_a = sum_b w_ab (T_a - T_b), w_ab = -K_ab for each pair a < b with K_ab != 0. Each
    pair's flux leaves one node and enters the other, so sum_a (K T)_a vanishes to the round-off of the fluxes,
    not of K's entries times the temperatures (the antisymmetric pair sum of :mod:`refsph.thermal`). Returns the
    function T -> K T."""
    U = sp.triu(K, k=1).tocoo()
    I, J, w, n = U.row, U.col, -U.data, K.shape[0]

    def flux(T):
        f = w * (T[I] - T[J])
        return np.bincount(I, f, minlength=n) - np.bincount(J, f, minlength=n)

    return flux
