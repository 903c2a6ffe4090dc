"""The mixed displacement-pressure linear triangle of the PFEM (Rodriguez Prieto, Larsson & Afrasiabi 2023,
Section 2.3.2, Eqs. (16)-(17)), plane strain, thickness 1 m (forces per metre of width).

Displacement and pressure are both linear on each triangle (P1-P1), with nodal values. The pressure p is the mean
stress (the paper's sign: sigma = p I + s, Eq. (15); p > 0 in tension). P1-P1 violates the inf-sup condition; the
paper stabilises it by the polynomial pressure projection of Dohrmann & Bochev (2004, "A stabilized finite element
method for the Stokes problem based on polynomial pressure projections", Int. J. Numer. Meth. Fluids 46, 183; the
paper's ref. [53]): the pressure equation gains

    (1 / G) int_e (p - Pi p) (q - Pi q) dA,      Pi p = the element mean of p (L2 projection on constants)

which needs no mesh parameter and vanishes for a pressure constant on the element (it only acts on the part of p a
linear triangle cannot balance: the checkerboard). 1/G is Dohrmann & Bochev's 1/viscosity for a solid.

On one triangle with area A, N_a the linear shape functions (a = 0, 1, 2):

    int_e N_a N_b dA                   = A / 12 (1 + delta_ab)                           (:func:`pressure_mass`)
    int_e (N_a - 1/3)(N_b - 1/3) dA    = A / 12 delta_ab - A / 36                         (:func:`ppp_stabilisation`)
    grad N_a                           = constant on e                                     (:func:`shape_gradients`)

Every function works on all M triangles at once (arrays (M, ...)).
"""
from __future__ import annotations

import numpy as np

__all__ = ["shape_gradients", "pressure_mass", "ppp_stabilisation"]


def shape_gradients(xe: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """grad N_a of the linear triangles with vertices xe (M, 3, 2), and their signed areas A (M,):
    grad N_a = (y_b - y_c, x_c - x_b) / (2 A) for (a, b, c) the cyclic order."""
    x, y = xe[..., 0], xe[..., 1]
    g = np.empty(xe.shape[:-2] + (3, 2))
    for a, (b, c) in enumerate(((1, 2), (2, 0), (0, 1))):          # the cyclic order
        g[..., a, 0] = y[..., b] - y[..., c]
        g[..., a, 1] = x[..., c] - x[..., b]
    A = 0.5 * (x[..., 1] * y[..., 2] - x[..., 2] * y[..., 1] + x[..., 2] * y[..., 0] - x[..., 0] * y[..., 2]
               + x[..., 0] * y[..., 1] - x[..., 1] * y[..., 0])
    g /= (2.0 * A[..., None, None])
    return g, A


def pressure_mass(A: np.ndarray) -> np.ndarray:
    """int_e N_a N_b dA = A / 12 (1 + delta_ab), (M, 3, 3)."""
    return A[:, None, None] / 12.0 * (np.eye(3) + 1.0)


def ppp_stabilisation(A: np.ndarray) -> np.ndarray:
    """Dohrmann & Bochev's int_e (p - Pi p)(q - Pi q) dA for linear p: A / 12 delta_ab - A / 36, (M, 3, 3)."""
    return A[:, None, None] * (np.eye(3) / 12.0 - 1.0 / 36.0)
