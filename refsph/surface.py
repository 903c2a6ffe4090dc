"""Free-surface detection, two ways (issue 16: the thermal boundary conditions act on the free surface, and the
second paper blames the gap between its SPH and PFEM results on how each finds it): the heat losses of
:mod:`refsph.thermal` act on the particles one of them marks.

* :func:`surface_sph` -- the SPH detector of Marrone et al. (2010, Comput. Methods Appl. Mech. Engrg. 199, 1455;
  after Doring's eigenvalue criterion): the smallest eigenvalue lambda_min of the moment matrix
  M_i = - sum_j V_j x_ij (x) grad_i W_ij (the identity inside a full support, :mod:`refsph.esph`) falls where
  the support is cut. lambda_min <= ``threshold`` (0.75 as in Marrone et al., who also refine the layer with a
  scan region; refsph stops at the eigenvalue) marks a particle of the surface layer.
* :func:`surface_alpha_shape` -- the alpha-shape of PFEM (Edelsbrunner & Muecke 1994; Idelsohn, Onate & Del Pin
  2004): the Delaunay triangulation of the particles (``scipy.spatial.Delaunay``) without the triangles
  (tetrahedra) whose circumradius exceeds alpha dp; the particles on the faces that only one kept simplex has are
  the surface. alpha ~ 1.2-1.5 in PFEM codes.

Both return a boolean array, True on the surface.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay

from .esph import velocity_gradient
from .kernels import Kernel
from .neighbours import PairSum, find_pairs

__all__ = ["moment_min_eigenvalue", "surface_sph", "surface_alpha_shape", "circumradius"]


def moment_min_eigenvalue(x: np.ndarray, V: np.ndarray, h: float, kernel: Kernel,
                          pairs: tuple | None = None) -> np.ndarray:
    """lambda_min of M_i = - sum_j V_j x_ij (x) grad_i W_ij (symmetric; about 1 inside, less where the support is
    cut; 0 for an isolated particle). ``pairs``: the half pairs, if the caller has them: those within the support
    and any beyond it (they add zero: the kernel vanishes there)."""
    n, d = x.shape
    I, J = pairs if pairs is not None else find_pairs(x, kernel.support * h)
    dx = x[I] - x[J]
    gW = kernel.dw_dr_over_r(np.sqrt(np.sum(dx * dx, axis=1)), h, d)[:, None] * dx
    M = velocity_gradient(PairSum(I, J, n), V, dx, gW)     # Eq. (23) with v replaced by x: the moment matrix
    if d == 2:                                              # closed form: (a + c)/2 - sqrt(((a - c)/2)^2 + b^2)
        a, b, c = M[:, 0, 0], 0.5 * (M[:, 0, 1] + M[:, 1, 0]), M[:, 1, 1]
        return 0.5 * (a + c) - np.sqrt(0.25 * (a - c) ** 2 + b * b)
    return np.linalg.eigvalsh(np.ascontiguousarray(M))[:, 0]


def surface_sph(x: np.ndarray, V: np.ndarray, h: float, kernel: Kernel, threshold: float = 0.75,
                pairs: tuple | None = None) -> np.ndarray:
    """The SPH surface layer: lambda_min(M_i) <= threshold (module text)."""
    return moment_min_eigenvalue(x, V, h, kernel, pairs) <= threshold


def surface_alpha_shape(x: np.ndarray, dp: float, alpha: float = 1.3) -> np.ndarray:
    """The alpha-shape boundary: Delaunay simplices with circumradius <= alpha dp are kept; the vertices of the
    faces that belong to one kept simplex only are the surface (module text). 2D and 3D."""
    n, d = x.shape
    tri = Delaunay(x)
    simp = tri.simplices
    keep = circumradius(x[simp]) <= alpha * dp
    faces = []
    for k in range(d + 1):                                  # the face opposite vertex k of every kept simplex
        faces.append(np.sort(np.delete(simp[keep], k, axis=1), axis=1))
    faces = np.concatenate(faces)
    uniq, counts = np.unique(faces, axis=0, return_counts=True)
    out = np.zeros(n, dtype=bool)
    out[uniq[counts == 1].ravel()] = True
    return out


def circumradius(P: np.ndarray) -> np.ndarray:
    """Circumradius of simplices P (m, d + 1, d): the centre c solves 2 (p_k - p_0) . c = |p_k|^2 - |p_0|^2; a flat
    simplex (its points on a line or plane: a lattice gives such slivers) has an infinite one."""
    p0 = P[:, :1, :]
    A = 2.0 * (P[:, 1:, :] - p0)
    b = np.sum(P[:, 1:, :] ** 2, axis=2) - np.sum(p0 ** 2, axis=2)
    scale = np.max(np.abs(A), axis=(1, 2)) ** A.shape[1]
    ok = np.abs(np.linalg.det(A)) > 1e-12 * np.maximum(scale, np.finfo(float).tiny)
    r = np.full(len(P), np.inf)
    c = np.linalg.solve(A[ok], b[ok][..., None])[..., 0]
    r[ok] = np.linalg.norm(c - p0[ok, 0, :], axis=1)
    return r
