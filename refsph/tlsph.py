"""Total Lagrangian SPH (Section 2.2): kernels evaluated in the *reference* configuration X.

Pairs, kernel gradients grad_i W(X_ij) and reference volumes V_j = m_j / rho_0j do not change until the
reference configuration is updated, so every sum below is a product with a fixed sparse matrix
(:class:`ReferenceOperator`), built once per reference configuration.

    Eq. (18)  F_i     = - sum_j V_j (x_i - x_j) (x) grad_i W(X_ij)            (deformation gradient)
    Eq. (19)  Fdot_i  = - sum_j V_j (v_i - v_j) (x) grad_i W(X_ij)
              l_i     = Fdot_i F_i^-1                                          (velocity gradient)
    Eq. (17)  dv_i/dt = sum_j m_j (P_i / rho_0i^2 + P_j / rho_0j^2 - Pi_ij) grad_i W(X_ij)
    Eq. (2)   rho     = rho_0 / J,  J = det F

Kernel-gradient correction (Bonet & Lok 1999, CMAME 180, 97; used in TLSPH by Vignjevic et al. 2006 and
Ganzenmueller 2015): Eq. (18) as printed gives F != I for a body at rest wherever the support is cut
(free surfaces). The corrected gradient  grad~_i W_ij = L_i grad_i W_ij  with

    L_i = M_i^{-T},   M_i = sum_j V_j (X_j - X_i) (x) grad_i W(X_ij)

reproduces any affine field exactly, so F = I at rest and F = A for x = A X, everywhere. refsph uses it
by default (``corrected=True``); ``corrected=False`` gives Eq. (18) as printed.

Stress measure: the paper prints P = J F^-1 sigma. That is the *nominal* stress N = P^T; contracted with
the kernel gradient as in Eq. (17) it must be used as P = N^T = J sigma F^-T (Bonet & Wood, Nonlinear
Continuum Mechanics, Sec. 5.5). refsph uses P = J sigma F^-T and contracts P_aK grad_K W; with the printed
form the force would be wrong under any rotation (F not symmetric).

Artificial viscosity in the reference frame: Pi_ij = pi_ij (B_i + B_j) / 2 with B = J F^-T (the paper's
J F^-1 pi_ij, transposed to the same convention as P, and averaged over the pair so that the pair force is
antisymmetric); pi_ij is Eq. (12)-(13) evaluated with the current x_ij, v_ij.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .esph import Rates, artificial_viscosity
from .kernels import Kernel
from .material import ElasticMaterial, cauchy_stress, eos_pressure, jaumann_deviatoric_rate
from .neighbours import find_pairs, scatter_add
from .state import State
from .tensor import det, identity, inv

__all__ = ["TLSPHParams", "ReferenceOperator", "tlsph_rates", "first_piola", "green_lagrange_norm",
           "reference_update"]


@dataclass(frozen=True)
class TLSPHParams:
    """Numerical parameters of TLSPH. h: smoothing length in the reference configuration [m];
    beta1, beta2, eps: artificial viscosity (Eqs. 12-13); corrected: kernel-gradient correction;
    ref_update_strain: update the reference configuration when max_i |E_i| exceeds it, with
    E = (F^T F - I)/2 the Green-Lagrange strain (None: never)."""

    h: float
    beta1: float
    beta2: float
    eps: float
    kernel: Kernel
    corrected: bool
    ref_update_strain: float | None


class ReferenceOperator:
    """Fixed sparse SPH operators of one reference configuration (X, V).

    For each direction k, ``G[k]`` is the N x N sparse matrix with entries

        G[k][i, j] = V_j (L_i grad_i W(X_ij))_k      (j != i; L = I when not corrected)

    so that  sum_j V_j f_j (x) grad~_i W_ij = (G[k] @ f)_i  and  sum_j V_j grad~_i W_ij = G[k] @ 1.
    ``GT[k]`` is its transpose (CSR), used for the j-side term of the momentum sum (Eq. 17).
    The kernel-gradient correction L is baked into the entries, so F needs no per-step matrix product.
    """

    def __init__(self, X: np.ndarray, V: np.ndarray, h: float, kernel: Kernel, corrected: bool):
        X = np.asarray(X, dtype=float)
        n, d = X.shape
        self.n, self.dim, self.h, self.kernel, self.corrected = n, d, float(h), kernel, bool(corrected)
        self.X = X.copy()
        self.V = np.asarray(V, dtype=float).copy()
        self.I, self.J = find_pairs(X, kernel.support * h)
        I, J = self.I, self.J
        self.n_pairs = len(I)
        self.gW = kernel.grad(X[I] - X[J], h, d)            # grad_i W(X_ij) on half pairs (i < j)
        # directed pairs (row, col, grad_row W(X_row - X_col)): (i, j, gW) and (j, i, -gW)
        rows = np.concatenate([I, J])
        cols = np.concatenate([J, I])
        g = np.concatenate([self.gW, -self.gW])
        # moment matrix M_i = sum_j V_j (X_j - X_i) (x) grad_i W_ij and correction L_i = M_i^-T
        Vg = self.V[cols][:, None] * g
        dXd = X[cols] - X[rows]
        self.M = scatter_add(rows, (dXd[:, :, None] * Vg[:, None, :]).reshape(len(rows), d * d), n).reshape(n, d, d)
        self.L = np.swapaxes(inv(self.M), 1, 2) if corrected else identity(n, d)
        gc = np.einsum("pab,pb->pa", self.L[rows], g)     # corrected gradient L_row grad W
        Vgc = self.V[cols][:, None] * gc
        self.G = [sp.csr_matrix((Vgc[:, k], (rows, cols)), shape=(n, n)) for k in range(d)]
        self.GT = [Gk.T.tocsr() for Gk in self.G]
        self.s = np.stack([Gk @ np.ones(n) for Gk in self.G], axis=1)   # sum_j V_j grad~_i W_ij
        self._sm, self._sm_m = None, None

    def gradient(self, f: np.ndarray) -> np.ndarray:
        """Eq. (16) with the corrected gradient: sum_j V_j (f_j - f_i) (x) grad~_i W_ij, (N, c) -> (N, c, d)."""
        out = np.stack([Gk @ f for Gk in self.G], axis=2)  # [i, c, k]
        return out - f[:, :, None] * self.s[:, None, :]

    def deformation_gradient(self, x: np.ndarray) -> np.ndarray:
        """Eq. (18): F_i = sum_j V_j (x_j - x_i) (x) grad~_i W(X_ij)."""
        return self.gradient(x)

    def momentum_sum(self, Q: np.ndarray, m: np.ndarray) -> np.ndarray:
        """sum_j m_j (Q_i grad~_i W_ij - Q_j grad~_j W_ji) for Q of shape (N, d, d).

        With Q = P / rho_0^2 this is the stress part of Eq. (17). The i-side term is Q_i (sum_j m_j grad~_i W_ij);
        the j-side term uses the transposed operator: m_j grad~_j W_ji = (m_j / V_i) G[k][j, i].
        The pair term is antisymmetric, so sum_i m_i dv_i/dt = 0 (momentum conserved to round-off).
        """
        if self._sm is None or self._sm_m is not m:
            rho_ref = m / self.V
            self._sm = np.stack([Gk @ rho_ref for Gk in self.G], axis=1)  # sum_j m_j grad~_i W_ij (fixed)
            self._sm_m = m
        sm = self._sm
        mQ = m[:, None, None] * Q
        jside = sum(self.GT[k] @ mQ[:, :, k] for k in range(self.dim))  # sum_j m_j Q_j V_i grad~_j W_ji
        return np.einsum("nak,nk->na", Q, sm) - jside / self.V[:, None]


def first_piola(sigma: np.ndarray, F: np.ndarray, J: np.ndarray, Finv: np.ndarray) -> np.ndarray:
    """P = J sigma F^-T (the transpose of the paper's printed J F^-1 sigma; see the module docstring)."""
    return J[:, None, None] * sigma @ np.swapaxes(Finv, 1, 2)


def green_lagrange_norm(F: np.ndarray) -> np.ndarray:
    """|E|_Frobenius with E = (F^T F - I) / 2: zero for any rigid motion."""
    E = 0.5 * (np.swapaxes(F, 1, 2) @ F)
    idx = np.arange(F.shape[1])
    E[:, idx, idx] -= 0.5
    return np.sqrt(np.einsum("nab,nab->n", E, E))


def tlsph_rates(state: State, mat: ElasticMaterial, prm: TLSPHParams, op: ReferenceOperator,
                out: dict | None = None) -> Rates:
    """All TLSPH time derivatives. If ``out`` is a dict, F, J, P and l are stored in it (diagnostics)."""
    n, d = state.x.shape
    x, v, m = state.x, state.v, state.m

    xv = np.concatenate([x, v], axis=1)
    G = op.gradient(xv)                                     # Eqs. (18)-(19) in one product per direction
    F, Fdot = G[:, :d, :], G[:, d:, :]
    J = det(F)
    Finv = inv(F, J)
    l = Fdot @ Finv

    rho_ref = m / op.V                                      # reference density rho_0 = m / V
    rho = rho_ref / J                                       # Eq. (2)
    p = eos_pressure(rho, mat.rho0, mat.K)                  # Eq. (24)
    sigma = cauchy_stress(state.S, p)
    P = first_piola(sigma, F, J, Finv)

    # Eq. (17), stress part: a_i = sum_j m_j (P_i / rho_0i^2 grad~_i W_ij - P_j / rho_0j^2 grad~_j W_ji)
    a = op.momentum_sum(P / (rho_ref**2)[:, None, None], m)

    # Eq. (17), artificial viscosity: a_i -= sum_j m_j pi_ij (B_i + B_j)/2 grad_i W_ij,  B = J F^-T
    if prm.beta1 > 0 or prm.beta2 > 0:
        I, Jp = op.I, op.J
        dx = np.take(x, I, axis=0) - np.take(x, Jp, axis=0)
        dv = np.take(v, I, axis=0) - np.take(v, Jp, axis=0)
        vr = np.einsum("pk,pk->p", dv, dx)
        k = np.flatnonzero(vr < 0.0)                        # only approaching pairs are damped
        if len(k):
            Ik, Jk = I[k], Jp[k]
            r2 = np.einsum("pk,pk->p", dx[k], dx[k])
            pi = artificial_viscosity(vr[k], r2, 0.5 * (rho[Ik] + rho[Jk]), mat.c0, prm.h,
                                      prm.beta1, prm.beta2, prm.eps)
            B = J[:, None, None] * np.swapaxes(Finv, 1, 2)
            Bg = np.einsum("pab,pb->pa", np.take(B, Ik, axis=0) + np.take(B, Jk, axis=0), op.gW[k])
            q = (0.5 * pi)[:, None] * Bg
            a -= scatter_add(Ik, m[Jk][:, None] * q, n) - scatter_add(Jk, m[Ik][:, None] * q, n)

    dS, dS_zz = jaumann_deviatoric_rate(state.S, state.S_zz, l, mat.G)
    if out is not None:
        out.update(F=F, J=J, P=P, l=l, rho=rho, p=p)
    return Rates(x=v.copy(), v=a, rho=None, S=dS, S_zz=dS_zz)


def reference_update(state: State, op: ReferenceOperator) -> tuple[State, ReferenceOperator]:
    """X <- x, V <- J V (Section 3); stress kept. Returns the new state and the rebuilt operator."""
    F = op.deformation_gradient(state.x)
    J = det(F)
    new = state.copy()
    new.X = state.x.copy()
    new.V0 = J * state.V0
    new.rho = state.m / new.V0
    new_op = ReferenceOperator(new.X, new.V0, op.h, op.kernel, op.corrected)
    return new, new_op
