"""Smoothing kernels W(r, h) and their radial derivatives.

Both kernels have compact support r <= 2h, so a neighbour search radius of 2h is enough.

* :class:`CubicSpline` -- the cubic B-spline of Islam, Bansal & Peng, Eq. (9):

      W(q, h) = alpha_d * { 1 - 3/2 q^2 + 3/4 q^3   for 0 <= q <= 1
                          { 1/4 (2 - q)^3           for 1 <= q <= 2
                          { 0                       otherwise,
      q = |x_i - x_j| / h,  alpha_2 = 10 / (7 pi h^2),  alpha_3 = 1 / (pi h^3).

* :class:`WendlandC2` -- the Wendland C2 kernel (Wendland 1995; normalisation for support 2h as in
  Dehnen & Aly 2012, MNRAS 425, 1068), used by the second paper (Rodriguez Prieto et al.):

      W(q, h) = alpha_d (1 - q/2)^4 (2 q + 1)   for 0 <= q <= 2,
      alpha_2 = 7 / (4 pi h^2),  alpha_3 = 21 / (16 pi h^3).

The gradient with respect to x_i is  grad_i W(x_ij) = (dW/dr) x_ij / r  with x_ij = x_i - x_j;
it points from i towards j (dW/dr < 0), and grad_j W(x_ji) = -grad_i W(x_ij).
"""
from __future__ import annotations

import numpy as np

from .tensor import det, inv

__all__ = ["Kernel", "CubicSpline", "WendlandC2", "KERNELS", "get_kernel", "correction_matrix"]


def _check_dim(dim: int) -> None:
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")


class Kernel:
    """Radial kernel with compact support ``support * h``. Subclasses give f(q), f'(q) and alpha_d."""

    name: str = ""
    support: float = 2.0  # in units of h

    def alpha(self, h: float, dim: int) -> float:
        raise NotImplementedError

    def f(self, q: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def df(self, q: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def w(self, r, h: float, dim: int) -> np.ndarray:
        """W(r, h) = alpha_d f(r / h)."""
        _check_dim(dim)
        return self.alpha(h, dim) * self.f(np.asarray(r, dtype=float) / h)

    def dw_dr(self, r, h: float, dim: int) -> np.ndarray:
        """dW/dr = alpha_d f'(r / h) / h."""
        _check_dim(dim)
        return self.alpha(h, dim) / h * self.df(np.asarray(r, dtype=float) / h)

    def dw_dr_over_r(self, r, h: float, dim: int) -> np.ndarray:
        """(dW/dr) / r, finite at r = 0 (f'(q) ~ q there), so that grad W = (dW/dr / r) x_ij."""
        _check_dim(dim)
        q = np.asarray(r, dtype=float) / h
        return self.alpha(h, dim) / (h * h) * self.df_over_q(q)

    def df_over_q(self, q: np.ndarray) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        out = np.empty_like(q)
        small = q < 1e-12
        out[~small] = self.df(q[~small]) / q[~small]
        out[small] = self.df_over_q_at_zero
        return out

    df_over_q_at_zero: float = 0.0

    def f_and_df_over_q(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """f(q) and f'(q)/q together (subclasses share the work between them)."""
        return self.f(q), self.df_over_q(q)

    def w_and_dw_dr_over_r(self, r, h: float, dim: int) -> tuple[np.ndarray, np.ndarray]:
        """W(r, h) and (dW/dr)/r in one pass over r: what an ESPH rate evaluation needs of every pair."""
        _check_dim(dim)
        f, g = self.f_and_df_over_q(np.asarray(r, dtype=float) / h)
        a = self.alpha(h, dim)
        f *= a
        g *= a / (h * h)
        return f, g

    def grad(self, xij: np.ndarray, h: float, dim: int) -> np.ndarray:
        """grad_i W(x_ij) = (dW/dr) x_ij / r for separation vectors x_ij of shape (M, dim)."""
        xij = np.asarray(xij, dtype=float)
        r = np.sqrt(np.einsum("pk,pk->p", xij, xij))
        return self.dw_dr_over_r(r, h, dim)[:, None] * xij


class CubicSpline(Kernel):
    """Cubic B-spline, Eq. (9) of Islam, Bansal & Peng."""

    name = "cubic"
    df_over_q_at_zero = -3.0

    def alpha(self, h: float, dim: int) -> float:
        _check_dim(dim)
        return 10.0 / (7.0 * np.pi * h**2) if dim == 2 else 1.0 / (np.pi * h**3)

    # Powers are written as products: q**3 on an array calls pow() per element, ~10x slower.
    def f(self, q):
        q = np.asarray(q, dtype=float)
        t = np.maximum(2.0 - q, 0.0)
        inner = 1.0 - q * q * (1.5 - 0.75 * q)              # 1 - 3/2 q^2 + 3/4 q^3
        return np.where(q <= 1.0, inner, 0.25 * t * t * t)

    def df(self, q):
        q = np.asarray(q, dtype=float)
        t = np.maximum(2.0 - q, 0.0)
        return np.where(q <= 1.0, q * (2.25 * q - 3.0), -0.75 * t * t)

    def df_over_q(self, q):
        # f'(q)/q without the division: -3 + 9/4 q (q <= 1), -3/4 (2-q)^2 / q (1 < q <= 2)
        q = np.asarray(q, dtype=float)
        t = np.maximum(2.0 - q, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            outer = -0.75 * t * t / q
        return np.where(q <= 1.0, -3.0 + 2.25 * q, outer)

    def f_and_df_over_q(self, q):
        # Eq. (9) without branches: a cubic B-spline is a sum of truncated powers (Schoenberg 1946),
        #   f(q) = 1/4 (2 - q)_+^3 - (1 - q)_+^3,   f'(q) / q = (3 (1 - q)_+^2 - 3/4 (2 - q)_+^2) / q,
        # (z)_+ = max(z, 0). No np.where, so about half the work. f equals f() to round-off; f'(q)/q equals
        # df_over_q() to a relative 1e-16 / q: the numerator 3 u^2 - 3/4 t^2 ~ -3q is a difference of numbers
        # near 3, so at q < 1e-8 (particles 1e-8 h apart) f'/q alone loses digits, and at q = 0 it is 0 (the
        # division uses max(q, 1e-12)), not -3. The gradient (f'/q) x_ij, which is what this is for, is right to
        # round-off at every q. Use df_over_q where f'(q)/q itself is needed.
        q = np.asarray(q, dtype=float)
        t = np.maximum(2.0 - q, 0.0)
        u = np.maximum(1.0 - q, 0.0)
        t2, u2 = t * t, u * u
        f = 0.25 * t2 * t - u2 * u
        g = 3.0 * u2 - 0.75 * t2
        g /= np.maximum(q, 1e-12)
        return f, g


class WendlandC2(Kernel):
    """Wendland C2 kernel with support 2h (Dehnen & Aly 2012 normalisation)."""

    name = "wendland"
    df_over_q_at_zero = -5.0

    def alpha(self, h: float, dim: int) -> float:
        _check_dim(dim)
        return 7.0 / (4.0 * np.pi * h**2) if dim == 2 else 21.0 / (16.0 * np.pi * h**3)

    def f(self, q):
        q = np.asarray(q, dtype=float)
        t = np.maximum(1.0 - 0.5 * q, 0.0)
        t2 = t * t
        return t2 * t2 * (2.0 * q + 1.0)

    def df(self, q):
        # d/dq [(1 - q/2)^4 (2q + 1)] = -5 q (1 - q/2)^3
        q = np.asarray(q, dtype=float)
        t = np.maximum(1.0 - 0.5 * q, 0.0)
        return -5.0 * q * t * t * t

    def df_over_q(self, q):
        q = np.asarray(q, dtype=float)
        t = np.maximum(1.0 - 0.5 * q, 0.0)
        return -5.0 * t * t * t

    def f_and_df_over_q(self, q):
        q = np.asarray(q, dtype=float)
        t = np.maximum(1.0 - 0.5 * q, 0.0)
        t3 = t * t * t
        return t3 * t * (2.0 * q + 1.0), -5.0 * t3


KERNELS = {"cubic": CubicSpline(), "wendland": WendlandC2()}


def get_kernel(name: str) -> Kernel:
    """Kernel by name: 'cubic' (Eq. (9)) or 'wendland'."""
    try:
        return KERNELS[name]
    except KeyError:
        raise ValueError(f"unknown kernel {name!r}; choose one of {sorted(KERNELS)}") from None


def correction_matrix(M: np.ndarray, tol: float = 1e-6, max_condition: float | None = None
                      ) -> tuple[np.ndarray, np.ndarray]:
    """L_i = M_i^-T (Bonet & Lok 1999). Where M_i is (nearly) singular -- a particle whose neighbours do not
    span every direction (no neighbours, a single row of particles) -- the Moore-Penrose pseudo-inverse is used
    instead (Bonet & Lok's correction restricted to the directions the neighbours span), so the operator stays
    finite. Returns (L, indices of those degenerate particles); the caller completes F of such a particle with
    the identity in the missing direction (:meth:`refsph.tlsph.ReferenceOperator.deformation_gradient`).

    ``max_condition`` (None: no limit, the paper's correction): where M_i = U diag(s) V^T is invertible but its
    condition number s_max / s_min exceeds it -- a particle on a ragged free surface whose few neighbours lie
    nearly in one line -- L_i = U diag(1 / max(s, s_max / max_condition)) V^T: the correction of the well-spanned
    directions kept, the amplification of the poorly spanned one bounded by max_condition / s_max (a truncated,
    Tikhonov-like pseudo-inverse; refsph's choice, module text of :mod:`refsph.tlsph`). Every particle below the
    limit keeps its exact M_i^-T, to the bit."""
    d = M.shape[1]
    detM = det(M)
    scale = np.maximum(np.abs(np.trace(M, axis1=1, axis2=2)) / d, np.finfo(float).tiny) ** d
    bad = np.flatnonzero(~(np.abs(detM) > tol * scale))
    safe = M.copy()
    safe[bad] = np.eye(d)
    L = np.swapaxes(inv(safe), 1, 2)
    if len(bad):
        L[bad] = np.swapaxes(np.linalg.pinv(M[bad]), 1, 2)
    if max_condition is not None and len(M):
        good = np.ones(len(M), dtype=bool)
        good[bad] = False
        s = np.linalg.svd(M, compute_uv=False)
        capped = np.flatnonzero(good & (s[:, 0] > max_condition * s[:, -1]))
        if len(capped):
            U, s_c, Vt = np.linalg.svd(M[capped])
            floor = np.maximum(s_c, s_c[:, :1] / max_condition)
            L[capped] = np.einsum("nij,nj,njk->nik", U, 1.0 / floor, Vt)     # (V diag(1/s) U^T)^T
    return L, bad
