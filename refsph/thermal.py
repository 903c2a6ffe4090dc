"""Heat conduction in SPH (Rodriguez Prieto, Larsson & Afrasiabi, Eqs. (4), (26), (29)): the first piece of the
thermomechanical cutting model (issue 16); the scenes do not use it yet.

    Eq. (4)   rho c_p dT/dt = k lap T + Q_s
    Eq. (26)  lap f_i = sum_j 2 f_ij / |r_ij| (e_ij . grad_i W_ij) V_j,    f_ij = f_i - f_j, e_ij = r_ij / |r_ij|
    Eq. (29)  dT_i/dt = a_i sum_j 2 T_ij / |r_ij| (e_ij . grad_i W_ij) V_j + S_i,   a = k / (rho c_p)

Eq. (26) is Brookshaw's (1985) Laplacian: with e_ij . grad_i W_ij = dW/dr, each pair term is
2 (f_i - f_j) (dW/dr)/r V_j, a heat flux between the two particles proportional to their temperature difference.
Summed as an antisymmetric pair term (:meth:`refsph.neighbours.PairSum.antisymmetric`) it moves heat from one
particle to the other and creates none: with one diffusivity the total heat sum_i m_i c_p T_i is conserved to
round-off. At a free surface the missing neighbours carry no flux, so an SPH body is insulated (a zero-flux
boundary) unless a boundary term is added (convection, radiation, a fixed temperature: later parts of issue 16).

Explicit time step (the second paper's Section 2.4.2): dt_t = rho c_p h^2 / k, times a Courant-like factor;
:func:`thermal_time_step`.
"""
from __future__ import annotations

import numpy as np

from .kernels import Kernel
from .neighbours import PairSum, find_pairs

__all__ = ["laplacian", "conduction_rate", "thermal_time_step"]


def laplacian(f: np.ndarray, x: np.ndarray, V: np.ndarray, h: float, kernel: Kernel,
              pairs: tuple | None = None) -> np.ndarray:
    """Eq. (26), Brookshaw's SPH Laplacian of the particle field ``f`` (N,) at positions ``x`` (N, d) with volumes
    ``V``: lap f_i = sum_j 2 (f_i - f_j) (dW/dr)(r_ij) / r_ij V_j. ``pairs``: half pairs (I, J) within the
    support, if the caller has them (refsph's convention: I < J, each pair once)."""
    n, d = x.shape
    I, J = pairs if pairs is not None else find_pairs(x, kernel.support * h)
    r = np.sqrt(np.sum((x[I] - x[J]) ** 2, axis=1))
    fr = kernel.dw_dr_over_r(r, h, d)                       # (dW/dr) / r, zero beyond the support
    t = 2.0 * (f[I] - f[J]) * fr                            # antisymmetric under i <-> j
    return PairSum(I, J, n).antisymmetric(t, V)


def conduction_rate(T: np.ndarray, x: np.ndarray, V: np.ndarray, a: np.ndarray | float, h: float, kernel: Kernel,
                    pairs: tuple | None = None, source: np.ndarray | float = 0.0) -> np.ndarray:
    """Eq. (29): dT_i/dt = a_i lap T_i + S_i, a = k / (rho c_p) [m^2/s] per particle (or one value), S = Q_s /
    (rho c_p) [K/s] the heat source (plastic work; 0 by default)."""
    return np.asarray(a) * laplacian(T, x, V, h, kernel, pairs) + source


def thermal_time_step(rho: float, cp: float, k: float, h: float, factor: float) -> float:
    """The explicit conduction step rho c_p h^2 / k (the second paper's dt_t) times ``factor`` (its CFL number,
    0.25-0.4 there; stability needs about 0.1-0.3 depending on the kernel, see tests/test_thermal.py)."""
    for name, v in (("rho", rho), ("cp", cp), ("k", k), ("h", h), ("factor", factor)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be positive, got {v!r}")
    return factor * rho * cp * h * h / k
