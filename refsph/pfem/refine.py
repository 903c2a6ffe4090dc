"""Node insertion and removal at a remeshing (issue 24; the paper's Section 2.3.4 and Figure 5 name it but give no
rule, so refsph states its own, after Cremonesi et al. 2020, "A state of the art review of the Particle Finite
Element Method", Arch. Comput. Methods Eng. 27, 1709, Section 3.3, and Rodriguez et al. 2016, Comput. Mech. 57,
"The particle finite element method (PFEM) in thermo-mechanical problems"):

    removal    two nodes closer than r_min min(h_i, h_j) (h the node's target spacing) are merged into one
    insertion  a triangle larger than a_max h_e^2 / 2 (h_e the mean of its nodes' h; h^2 / 2 a triangle of the
               initial lattice) gets a node at its centroid

Without them the nodes of the chip pile up against the rake face (pairs a tenth of a spacing apart, sliver
triangles between them: Newton-Raphson fails there) and the stretched regions open into holes.

**What is conserved, exactly (to round-off).** A merge of j into i: m_i <- m_i + m_j, the momentum m v and the
heat m c_p T summed (v and T the mass-weighted means; c_p is one constant per body), the nodal history (S, S_zz,
eps_p, W_p, J, p, a) mass-weighted, the contact's tangential force f_T summed; i keeps its position (a boundary
node stays on the boundary: i is the held node, else the boundary node, else the lower index). An insertion in
triangle e (area A) takes from each of its nodes k the mass its tributary area loses when e is split in three:
rho_k A / 9 with rho_k = m_k / a_k, a_k the node's tributary area (a third of each of its triangles); the new node
gets the sum, with the momentum and heat that mass carried (the three keep their velocities and temperatures), and
the triangle's own history (S, S_zz, eps_p, W_p, J, eps_dot of the element: what the centroid had). So total mass,
momentum and heat content are unchanged; kinetic energy is not (a merge is an inelastic collision).

Nodes are not inserted where ``forbidden`` says (inside or within half a spacing of the tool), and held nodes are
never removed. Each node carries a persistent ``id`` (new nodes take the next free ones), so a snapshot's particles
can be followed across node changes.

**The tool's edge between two nodes** (the cut's ``edge_nodes``; off by default). The contact keeps nodes out of the
tool, not triangles: a convex corner of the tool (the 10 um cutting edge) can pass between two boundary nodes, and
the triangle it pokes into resists nothing. On the sweep's cuts at t_u/10 one or two boundary edges are poked so, by
0.2-0.5 spacings (``benchmarks/pfem_edge_phase.py`` measures it). :func:`tool_intrusions` finds them (41 points
along each boundary edge; poked where a point inside lies deeper in the tool than a tenth of the spacing and than
either end by as much) and puts a node on the tool's surface above the deepest point, q = p + g n, inside the
edge's triangle, with the mass rule above at q's barycentric coordinates (rho_k A lambda_k / 3 from each node: A / 9
at the centroid). Each new mesh then leaves out the triangles whose centroid is inside the tool, so the boundary
runs a-q-b around the edge. refsph's own rule, after the adaptive insertion of particles near the tool of
Rodriguez Prieto et al. 2018 ("Generation of segmental chips in metal cutting modeled with the PFEM", Comput. Mech.
61, 639), whose rule is not reproduced; the other standard remedy, a second contact pass of the tool's corners
against the boundary's segments (Wriggers 2006, Section 5.2), is not built.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial import cKDTree

from .mesh import Mesh, signed_areas, tributary_areas
from .solid import History, Nodes

__all__ = ["NodeRule", "NodeChange", "refine_nodes", "renumber_mesh", "close_pairs", "pick_merges", "pick_insertions",
           "tool_intrusions", "gaps_along_edges", "owner_triangles"]

NODAL = ("S", "S_zz", "eps_p", "W_p", "J", "p", "a", "eps_dot")     # mass-weighted in a merge
ELEMENT = ("S", "S_zz", "eps_p", "W_p", "J", "eps_dot")              # an inserted node takes its triangle's


@dataclass(frozen=True)
class NodeRule:
    """The rule of the module text: merge nodes closer than ``r_min`` times the smaller target spacing; insert a
    node in a triangle of area above ``a_max`` h_e^2 / 2. No defaults (the cut's are in
    :func:`refsph.pfem.cutting.pfem_cut`)."""

    r_min: float
    a_max: float

    def __post_init__(self):
        if not (0.0 < self.r_min < 1.0 and self.a_max > 1.0):
            raise ValueError(f"NodeRule: need 0 < r_min < 1 (a fraction of the spacing) and a_max > 1 (a multiple of "
                             f"a lattice triangle's area); got r_min = {self.r_min!r}, a_max = {self.a_max!r}")


@dataclass
class NodeChange:
    """What :func:`refine_nodes` did: ``old_to_new`` (N_old,) the new index of each old node (-1: merged away),
    ``parents`` (K, 3) the old nodes of each inserted node's triangle (the new nodes are the last K), ``merged``
    (R, 2) the (kept, removed) old index pairs."""

    old_to_new: np.ndarray
    parents: np.ndarray
    merged: np.ndarray

    @property
    def changed(self) -> bool:
        return len(self.parents) > 0 or len(self.merged) > 0


def close_pairs(x: np.ndarray, h: np.ndarray, r_min: float) -> np.ndarray:
    """(P, 2) node pairs closer than r_min min(h_i, h_j), the closest first."""
    i, j = cKDTree(x).query_pairs(r_min * float(h.max()), output_type="ndarray").T
    d = np.linalg.norm(x[i] - x[j], axis=1)
    near = d < r_min * np.minimum(h[i], h[j])
    order = np.argsort(d[near], kind="stable")
    return np.stack([i[near][order], j[near][order]], axis=1)


def pick_merges(x, h, held, boundary, r_min):
    """(the (kept, removed) pairs (R, 2), the nodes in a merge (N,) bool): greedy over the closest pairs
    (:func:`close_pairs`), each node in one merge at most, two held nodes never; the kept node is the held one, else
    the boundary one, else the lower index."""
    used = np.zeros(len(x), bool)
    merged = []
    for i, j in close_pairs(x, h, r_min):
        if used[i] or used[j] or (held[i] and held[j]):
            continue
        rank_i, rank_j = (held[i], boundary[i], -i), (held[j], boundary[j], -j)
        merged.append((i, j) if rank_i >= rank_j else (j, i))
        used[[i, j]] = True
    return np.array(merged, dtype=np.int64).reshape(-1, 2), used


def pick_insertions(nodes: Nodes, mesh: Mesh, h: np.ndarray, used: np.ndarray, a_max: float, forbidden=None):
    """(the triangles that get a node (K,), the mass each of their nodes gives it (K, 3)): triangles of area above
    a_max h_e^2 / 2 none of whose nodes is in a merge (``used``), whose centroid is not ``forbidden``; the masses
    rho_k A / 9 (module text)."""
    A = np.abs(signed_areas(nodes.x, mesh.tri))
    h_e = h[mesh.tri].mean(axis=1)
    big = (A > a_max * 0.5 * h_e**2) & ~used[mesh.tri].any(axis=1)
    if forbidden is not None and big.any():
        big[big] &= ~np.asarray(forbidden(nodes.x[mesh.tri[big]].mean(axis=1)), bool)
    ins = np.flatnonzero(big)
    a = tributary_areas(nodes.x, mesh.tri, nodes.n)
    rho = np.where(a > 0, nodes.m / np.where(a > 0, a, 1.0), 0.0)
    return ins, rho[mesh.tri[ins]] * (A[ins] / 9.0)[:, None]


def owner_triangles(tri: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(K,) the triangle of ``tri`` each boundary edge (K, 2) belongs to (a boundary edge has one triangle; -1 for an
    edge of no triangle)."""
    n = int(max(tri.max(), edges.max())) + 1
    own = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    key = own[:, 0] * n + own[:, 1]
    order = np.argsort(key, kind="stable")
    want = edges[:, 0] * n + edges[:, 1]
    pos = np.clip(np.searchsorted(key[order], want), 0, len(key) - 1)
    hit = key[order][pos] == want
    return np.where(hit, order[pos] % len(tri), -1)


def gaps_along_edges(x: np.ndarray, edges: np.ndarray, gap, samples: int = 41):
    """(points (K, S, 2), g (K, S), n (K, S, 2)): ``samples`` points evenly along each edge (K, 2), its ends
    included, and the tool's penetration depth and outward normal there (``gap(x) -> (g, n)``)."""
    s = np.linspace(0.0, 1.0, samples)
    P = x[edges[:, 0], None, :] * (1.0 - s)[None, :, None] + x[edges[:, 1], None, :] * s[None, :, None]
    g, n = gap(P.reshape(-1, 2))
    return P, g.reshape(len(edges), samples), n.reshape(len(edges), samples, 2)


def tool_intrusions(x: np.ndarray, mesh: Mesh, gap, depth: np.ndarray, samples: int = 41):
    """Where a convex tool's outline pokes through the body's boundary between two nodes (module text): (the
    triangles (K,), the barycentric coordinates (K, 3) in them of the tool-surface points where a node goes).
    ``gap(x) -> (g, n)`` the tool's penetration depth and outward normal at points x (:meth:`RoundedPolygon.gap`);
    ``depth`` (N,) the least penetration, per node, that counts. A boundary edge (a, b) is poked where a point inside
    it, sampled at ``samples`` points, lies deeper in the tool than ``depth`` (the mean of its nodes') and than
    either end by as much; the node goes to the tool's surface above the deepest point, q = p + g n, if q lies
    inside the edge's triangle (each coordinate above 0.05); one node per triangle, the deepest."""
    e = mesh.edges
    if len(e) == 0:
        return np.zeros(0, np.int64), np.zeros((0, 3))
    P, g, n = gaps_along_edges(x, e, gap, samples)
    k = 1 + np.argmax(g[:, 1:-1], axis=1)
    rows = np.arange(len(e))
    g_in, d_min = g[rows, k], depth[e].mean(axis=1)
    poked = (g_in > d_min) & (g_in > np.maximum(g[:, 0], g[:, -1]) + d_min)
    tri_of = owner_triangles(mesh.tri, e)
    poked &= tri_of >= 0
    q = P[rows, k] + g_in[:, None] * n[rows, k]
    t = tri_of[poked]
    lam = barycentric(x[mesh.tri[t]], q[poked])
    ok = np.all(lam > 0.05, axis=1)
    t, lam, depth_in = t[ok], lam[ok], g_in[poked][ok]
    order = np.argsort(-depth_in, kind="stable")
    _, first = np.unique(t[order], return_index=True)
    pick = order[first]
    return t[pick], lam[pick]


def barycentric(corners: np.ndarray, q: np.ndarray) -> np.ndarray:
    """(K, 3) the barycentric coordinates of points q (K, 2) in triangles with ``corners`` (K, 3, 2)."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    l1 = ((q[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (q[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])) / det
    l2 = ((b[:, 0] - a[:, 0]) * (q[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (q[:, 0] - a[:, 0])) / det
    return np.stack([1.0 - l1 - l2, l1, l2], axis=1)


def refine_nodes(nodes: Nodes, mesh: Mesh, hist: History, h: np.ndarray, fixed: np.ndarray, rule: NodeRule,
                 extra: dict | None = None, forbidden=None, boundary: np.ndarray | None = None, points=None):
    """The nodes after the removals and insertions of ``rule`` (module text) on the mesh ``mesh`` with the
    triangles' history ``hist``. ``h`` (N,) the target spacings, ``fixed`` (N, 2) the held components; ``extra``: more
    per-node arrays to carry (name -> (array, how): how 'sum' (a force), 'keep' (the kept node's: an id, an initial
    position) or 'mean'; a new node's 'sum' is 0, its 'keep' and 'mean' the parents' mass-weighted mean, except the
    key 'id', which counts on from the largest); ``forbidden(x) -> bool (K,)``: where no node may be inserted;
    ``points``: (triangles (P,), barycentric coordinates (P, 3)) of more nodes to insert at those points rather than
    at centroids (:func:`tool_intrusions`; each old node k of the triangle gives rho_k A lambda_k / 3, the rule of
    the module text at any point; skipped where a node is in a merge or the triangle gets its centroid). Returns
    (nodes, h, fixed, extra, :class:`NodeChange`); the inputs are not changed."""
    n = nodes.n
    extra = dict(extra or {})
    boundary = mesh.boundary if boundary is None else boundary
    held = np.asarray(fixed, bool).any(axis=1)
    merged, used = pick_merges(nodes.x, h, held, boundary, rule.r_min)
    ins, share = pick_insertions(nodes, mesh, h, used, rule.a_max, forbidden)
    at = nodes.x[mesh.tri[ins]].mean(axis=1)
    if points is not None and len(points[0]):
        ins, share, at = _with_points(nodes, mesh, used, ins, share, at, *points)
    parents = mesh.tri[ins]
    m = nodes.m.copy()
    np.subtract.at(m, parents.ravel(), share.ravel())
    m_new = share.sum(axis=1)
    w_new = share / np.where(m_new > 0, m_new, 1.0)[:, None]               # each parent's part of the new mass

    def new_mean(values):
        v = values[parents]
        return np.einsum("kp,kp...->k...", w_new, v)

    keep, drop = merged[:, 0], merged[:, 1]
    mk, md = nodes.m[keep], nodes.m[drop]
    wk, wd = mk / (mk + md), md / (mk + md)

    def merge_mean(values):
        out = values.copy()
        shape = (-1,) + (1,) * (values.ndim - 1)
        out[keep] = wk.reshape(shape) * values[keep] + wd.reshape(shape) * values[drop]
        return out

    alive = np.ones(n, bool)
    alive[drop] = False
    old_to_new = np.full(n, -1, dtype=np.int64)
    old_to_new[alive] = np.arange(int(alive.sum()))
    m_merged = m.copy()
    m_merged[keep] = m[keep] + m[drop]

    def assemble(kept_values, new_values):
        return np.concatenate([kept_values[alive], new_values])

    fields = {}
    for name in ("v", "T") + NODAL:
        values = getattr(nodes, name)
        element = getattr(hist, name, None) if name in ELEMENT else None
        fields[name] = assemble(merge_mean(values), element[ins] if element is not None else new_mean(values))
    out = replace(nodes, x=assemble(nodes.x, at), m=assemble(m_merged, m_new), **fields)
    h_kept = h.copy()
    np.minimum.at(h_kept, keep, h[drop])
    fixed_kept = np.asarray(fixed, bool).copy()
    fixed_kept[keep] |= fixed_kept[drop]
    h_out = assemble(h_kept, h[parents].mean(axis=1))
    fixed_out = assemble(fixed_kept, np.zeros((len(ins), 2), bool))
    extra_out = {}
    for key, (values, how) in extra.items():
        values = np.asarray(values)
        if how == "sum":
            v = values.copy()
            np.add.at(v, keep, values[drop])
            new = np.zeros((len(ins),) + values.shape[1:], values.dtype)
        elif how == "mean":
            v, new = merge_mean(values), new_mean(values)
        elif how == "keep":
            v = values
            new = (values.max() + 1 + np.arange(len(ins))).astype(values.dtype) if key == "id" else new_mean(values)
        else:
            raise ValueError(f"refine_nodes: extra[{key!r}]: how must be 'sum', 'mean' or 'keep', got {how!r}")
        extra_out[key] = assemble(v, new)
    return out, h_out, fixed_out, extra_out, NodeChange(old_to_new=old_to_new, parents=parents, merged=merged)


def _with_points(nodes, mesh, used, ins, share, at, tri_pts, lam):
    """The centroid insertions (ins, share, at) and the point insertions of :func:`refine_nodes` together."""
    tri_pts, lam = np.asarray(tri_pts, np.int64), np.asarray(lam, float)
    ok = ~used[mesh.tri[tri_pts]].any(axis=1) & ~np.isin(tri_pts, ins)
    tri_pts, lam = tri_pts[ok], lam[ok]
    A = np.abs(signed_areas(nodes.x, mesh.tri[tri_pts]))
    a = tributary_areas(nodes.x, mesh.tri, nodes.n)
    rho = np.where(a > 0, nodes.m / np.where(a > 0, a, 1.0), 0.0)
    pts = np.einsum("kp,kpd->kd", lam, nodes.x[mesh.tri[tri_pts]])
    return (np.concatenate([ins, tri_pts]), np.concatenate([share, rho[mesh.tri[tri_pts]] * lam * (A / 3.0)[:, None]]),
            np.concatenate([at, pts]))


def renumber_mesh(mesh: Mesh, hist: History, change: NodeChange) -> tuple[Mesh, History]:
    """The old mesh in the new node numbering, without the triangles that lost a node, with their history (so that
    :func:`refsph.pfem.solid.transfer_history` keeps the history of every triangle that survives)."""
    tri = change.old_to_new[mesh.tri]
    ok = (tri >= 0).all(axis=1)
    h = History(**{k: (None if getattr(hist, k) is None else getattr(hist, k)[ok])
                   for k in ("S", "S_zz", "eps_p", "W_p", "J", "eps_dot")})
    return Mesh(tri=tri[ok], edges=np.zeros((0, 2), np.int64), boundary=np.zeros(0, bool), alpha=mesh.alpha), h
