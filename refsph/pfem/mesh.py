"""PFEM meshing (Rodriguez Prieto, Larsson & Afrasiabi 2023, Section 2.3.4 and Algorithm 1, steps 1-2): the particles
are the nodes; a mesh is made from them by a Delaunay triangulation, and the alpha-shape keeps the triangles that
belong to the body.

    step 1   Delaunay triangulation of the nodes                         (scipy.spatial.Delaunay)
    step 2   alpha-shape: keep a triangle if its circumradius R_e <= alpha h_e;
             the edges that only one kept triangle has are the boundary (external and internal)

h_e is the local node spacing: the mean over the triangle's three nodes of each node's distance to its nearest
neighbour (:func:`nodal_spacing`). The paper writes the criterion with one spacing for the whole body; with a graded
node distribution (its Figure 5) a single h either fills the coarse region's concavities with large triangles or
opens holes in the fine region, so refsph takes the local one (as Cremonesi et al. 2020, "A state of the art review
of the Particle Finite Element Method", Arch. Comput. Methods Eng. 27, 1709, Section 3.2, recommend). alpha ~ 1.2-1.5
in PFEM codes; too small opens spurious holes, too large bridges real gaps (the paper's Figure 3). Triangles whose
nodes belong to different bodies (``body``) are never kept: the tool and the workpiece are meshed apart.

Nothing of the nodes changes in a remeshing (positions, velocities, masses, pressure, temperature, the history
projected to them): the mass of a node is fixed, so mass and momentum are conserved exactly by construction
(``tests/test_pfem.py`` checks it). What a remeshing does change is which triangles carry the element history; see
:mod:`refsph.pfem.solid`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import Delaunay, cKDTree

from ..surface import circumradius

__all__ = ["Mesh", "nodal_spacing", "alpha_shape_mesh", "mesh_of", "boundary_edges", "signed_areas",
           "triangle_quality", "topology", "remesh_needed", "tributary_areas"]


@dataclass
class Mesh:
    """A triangle mesh of the nodes: ``tri`` (M, 3) node indices, counter-clockwise; ``edges`` (K, 2) the boundary
    edges, oriented with the body on their left (outward normal (dy, -dx) / length); ``boundary`` (N,) bool, the
    nodes on a boundary edge; ``alpha`` the alpha of the shape (None: every Delaunay triangle kept)."""

    tri: np.ndarray
    edges: np.ndarray
    boundary: np.ndarray
    alpha: float | None = None

    @property
    def meshed(self) -> np.ndarray:
        """(N,) bool: the nodes that belong to at least one triangle (a node alone is in free flight)."""
        out = np.zeros(len(self.boundary), dtype=bool)
        out[self.tri.ravel()] = True
        return out


def signed_areas(x: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """A_e = ((x_1 - x_0) x (x_2 - x_0)) / 2: positive for a counter-clockwise triangle."""
    a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def tributary_areas(x: np.ndarray, tri: np.ndarray, n: int) -> np.ndarray:
    """a_k: a third of the area of each triangle of node k (the lumped mass of a node is rho a_k)."""
    return np.bincount(tri.ravel(), np.repeat(np.abs(signed_areas(x, tri)) / 3.0, 3), minlength=n)


def nodal_spacing(x: np.ndarray) -> np.ndarray:
    """h_i: the distance from node i to its nearest neighbour (module text)."""
    d, _ = cKDTree(x).query(x, k=2)
    return d[:, 1]


def boundary_edges(tri: np.ndarray) -> np.ndarray:
    """The edges that belong to one triangle only, in the triangle's (counter-clockwise) order: the body lies on
    their left."""
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    key = np.sort(e, axis=1)
    _, inv, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return e[counts[inv.ravel()] == 1]


def alpha_shape_mesh(x: np.ndarray, alpha: float | None, h: np.ndarray | None = None,
                     body: np.ndarray | None = None) -> Mesh:
    """Algorithm 1, steps 1-2: the Delaunay triangles of the nodes ``x`` (N, 2) with circumradius <= alpha h_e
    (``h``: the nodal spacing, default :func:`nodal_spacing`; ``alpha`` None keeps every triangle), none spanning
    two bodies and none of zero area; oriented counter-clockwise, with their boundary."""
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[1] != 2 or len(x) < 3 or not np.all(np.isfinite(x)):
        raise ValueError(f"PFEM nodes must be (N >= 3, 2) finite positions, got shape {x.shape}")
    if alpha is not None and not (np.isfinite(alpha) and alpha > 0):
        raise ValueError(f"alpha must be a positive number, got {alpha!r}")
    tri = Delaunay(x).simplices.astype(np.int64)
    A = signed_areas(x, tri)
    tri[A < 0] = tri[A < 0][:, [0, 2, 1]]
    h = nodal_spacing(x) if h is None else np.asarray(h, dtype=float)
    keep = np.abs(A) > 1e-10 * np.mean(h[tri], axis=1) ** 2
    if alpha is not None:
        keep &= circumradius(x[tri]) <= alpha * np.mean(h[tri], axis=1)
    if body is not None:
        b = np.asarray(body)[tri]
        keep &= (b[:, 0] == b[:, 1]) & (b[:, 1] == b[:, 2])
    return mesh_of(tri[keep], len(x), alpha)


def mesh_of(tri: np.ndarray, n: int, alpha: float | None) -> Mesh:
    """The :class:`Mesh` of the counter-clockwise triangles ``tri`` of n nodes, with their boundary."""
    edges = boundary_edges(tri)
    boundary = np.zeros(n, dtype=bool)
    boundary[edges.ravel()] = True
    return Mesh(tri=tri, edges=edges, boundary=boundary, alpha=alpha)


def triangle_quality(x: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """q = 4 sqrt(3) A / (sum of the squared edges): 1 for an equilateral triangle, 0 for a flat one, < 0 inverted."""
    a, b, c = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
    A = 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    e2 = np.sum((b - a) ** 2, axis=1) + np.sum((c - b) ** 2, axis=1) + np.sum((a - c) ** 2, axis=1)
    return 4.0 * np.sqrt(3.0) * A / e2


def topology(n: int, tri: np.ndarray) -> tuple[int, int]:
    """(bodies, holes) of a triangle mesh of n nodes: the connected pieces, and the holes from Euler's formula
    V - E + F = bodies - holes (F the triangles, V the nodes they use, E their edges)."""
    used = np.unique(tri)
    e = np.unique(np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1), axis=0)
    label = connected_components(coo_matrix((np.ones(len(e)), tuple(e.T)), shape=(n, n)), directed=False)[1]
    bodies = len(np.unique(label[used]))
    return bodies, bodies - (len(used) - len(e) + len(tri))


def remesh_needed(x: np.ndarray, mesh, q_min: float) -> bool:
    """Algorithm 1's test: a triangle of quality below ``q_min`` (:func:`triangle_quality`)."""
    return bool(np.min(triangle_quality(x, mesh.tri)) < q_min)
