"""Eulerian SPH (Section 2.1): kernels evaluated at the *current* positions.

Per half pair (i, j), with x_ij = x_i - x_j, v_ij = v_i - v_j and grad_i W_ij = (dW/dr) x_ij / r:

    Eq. (10)  d rho_i / dt = sum_j m_j v_ij . grad_i W_ij
    Eq. (23)  l_i          = - sum_j (m_j / rho_j) v_ij (x) grad_i W_ij
    Eq. (11)  d v_i / dt   = sum_j m_j (sigma_i / rho_i^2 + sigma_j / rho_j^2 - pi_ij I - p^a_ij I) grad_i W_ij
    Eq. (12)  pi_ij = (-beta1 C mu_ij + beta2 mu_ij^2) / rho_bar_ij   if v_ij . x_ij <= 0, else 0
    Eq. (13)  mu_ij = h v_ij . x_ij / (|x_ij|^2 + eps h^2),   eps = 0.01
    Eq. (14)  p^a_ij = gamma (|p_i| / rho_i^2 + |p_j| / rho_j^2) (W(r_ij) / W(dp))^n,
              zero when p_i > 0 and p_j > 0 (both in compression)

Every pair term is symmetric (Eqs. (10), (23)) or antisymmetric (Eq. (11)) under i <-> j, so it is computed
once per half pair and added to both particles: linear momentum is conserved to round-off. The adding is
done by :class:`~refsph.neighbours.PairSum` (two sparse products per sum, the pair values as matrix entries),
block by block (:class:`~refsph.neighbours.PairBlocks`: arrays that fit in the cache, optionally on threads).
The velocity gradient (Eq. (23)) is exact for a linear velocity field only where the kernel support is
full; at a free surface it is not, and a rigid rotation there reads as a strain rate (the paper applies no
correction). ``ESPHParams.correction`` (``Numerics.esph_correction``, off by default) normalises it
(Randles & Libersky 1996; Bonet & Lok 1999):

    M_i  = - sum_j V_j x_ij (x) grad_i W_ij        (the moment matrix; the identity inside a full support)
    l_i  = [- sum_j V_j v_ij (x) grad_i W_ij] M_i^-1

so that every linear velocity field, a rigid rotation included, has its exact gradient at every particle. The
momentum equation (Eq. (11)) keeps the uncorrected, antisymmetric kernel gradient: it conserves linear momentum
exactly, and with no spurious stress there is nothing for it to misplace.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kernels import Kernel, correction_matrix
from .material import ElasticMaterial, cauchy_stress, eos_pressure, jaumann_deviatoric_rate
from .neighbours import PairBlocks, PairSum
from .state import Rates, State
from .tensor import empty, matmul, transpose

__all__ = ["ESPHParams", "esph_rates", "artificial_viscosity", "artificial_pressure",
           "velocity_gradient", "continuity_rate"]


@dataclass(frozen=True)
class ESPHParams:
    """Numerical parameters of ESPH. h: smoothing length [m]; dp: initial spacing [m] (Eq. (14));
    beta1, beta2: artificial viscosity (Eq. (12)); gamma: artificial pressure coefficient (Eq. (14), 0 = off);
    n_ap: artificial pressure exponent (paper: 4); eps: Eq. (13) regulariser (paper: 0.01); correction: the
    normalised velocity gradient (module text; False: Eq. (23) as printed)."""

    h: float
    dp: float
    beta1: float
    beta2: float
    gamma: float
    n_ap: float
    eps: float
    kernel: Kernel
    correction: bool = False


def artificial_viscosity(vr, r2, rho_bar, c_bar, h, beta1, beta2, eps):
    """Eqs. (12)-(13): pi_ij for arrays of v_ij.x_ij (vr), |x_ij|^2 (r2) and mean density.

    mu_ij = h vr / (r2 + eps h^2);  pi_ij = (-beta1 c mu + beta2 mu^2) / rho_bar where vr <= 0, else 0.
    """
    mu = h * np.minimum(vr, 0.0) / (r2 + eps * h * h)
    return (-beta1 * c_bar * mu + beta2 * mu * mu) / rho_bar


def _power(w, n):
    """w**n; by repeated multiplication for small integer n (np.power calls pow() per element: ~10x slower)."""
    if float(n).is_integer() and 1 <= n <= 8:
        out = w
        for _ in range(int(n) - 1):
            out = out * w
        return out
    return w**n


def artificial_pressure(p_i, p_j, rho_i, rho_j, w_ratio, gamma, n):
    """Eq. (14): p^a_ij = gamma (|p_i|/rho_i^2 + |p_j|/rho_j^2) (W_ij / W(dp))^n, 0 if p_i > 0 and p_j > 0."""
    return _artificial_pressure(np.abs(p_i) / rho_i**2, np.abs(p_j) / rho_j**2, (p_i > 0) & (p_j > 0),
                                w_ratio, gamma, n)


def _artificial_pressure(a_i, a_j, both_compressed, w_ratio, gamma, n):
    """Eq. (14) from a = |p| / rho^2 of both particles: gamma (a_i + a_j) (W_ij / W(dp))^n, 0 if both p > 0."""
    pa = gamma * (a_i + a_j) * _power(w_ratio, n)
    np.putmask(pa, both_compressed, 0.0)
    return pa


def continuity_rate(pairs: PairSum, m: np.ndarray, vr_gW: np.ndarray) -> np.ndarray:
    """Eq. (10): d rho_i/dt = sum_j m_j v_ij . grad_i W_ij, from one value v_ij . grad_i W_ij per half pair
    (a symmetric pair term) and the masses m of the particles of ``pairs`` (a :class:`~refsph.neighbours.PairSum`)."""
    return pairs.symmetric(vr_gW, m)


def velocity_gradient(pairs: PairSum, V: np.ndarray, dv, gW, out: np.ndarray | None = None) -> np.ndarray:
    """Eq. (23): l_i = -sum_j V_j v_ij (x) grad_i W_ij  (l_ab = dv_a/dx_b; a symmetric pair term).

    ``pairs``: a :class:`~refsph.neighbours.PairSum` of the half pairs; V: volumes m / rho of its particles;
    dv = v_i - v_j and gW = grad_i W_ij per pair, as (P, d) arrays or as d arrays of P values (one per
    component). ``out``: a (d, d, n) array to fill. Returns the (n, d, d) gradient, component-major (see
    :mod:`refsph.tensor`)."""
    if isinstance(dv, np.ndarray) and dv.ndim == 2:
        dv, gW = dv.T, np.asarray(gW).T
    d = len(dv)
    out = np.empty((d, d, pairs.n)) if out is None else out
    for a in range(d):
        for b in range(d):
            out[a, b] = pairs.symmetric(dv[a] * gW[b], V)
            np.negative(out[a, b], out=out[a, b])
    return out.transpose(2, 0, 1)


PARTS = ("all", "deformation", "forces")


def esph_rates(state: State, mat: ElasticMaterial, prm: ESPHParams, I: np.ndarray, J: np.ndarray,
               pairs: PairBlocks | None = None, part: str = "all") -> Rates:
    """All ESPH time derivatives for half pairs (I, J) (pairs beyond 2h contribute zero).

    ``pairs``: a :class:`~refsph.neighbours.PairBlocks` of (I, J), if the caller keeps one (it depends only on
    the pair list, and says how many threads run its blocks); otherwise one is built here. Every pair term
    is computed block by block (:func:`_block_sums`) and the per-particle sums are added up in block order.
    ``part``: 'all'; 'deformation' (Eqs. (10), (23), (20): the rates of rho, S, S_zz and l, dv/dt zero) or
    'forces' (Eq. (11): dv/dt only, the other rates zero), the two halves a staggered stepper (the leapfrog)
    evaluates at different states; 'all' computes both in one pass over the pairs, with the same numbers.
    """
    if part not in PARTS:
        raise ValueError(f"part must be one of {', '.join(PARTS)}, got {part!r}")
    n, d = state.x.shape
    m, rho = state.m, state.rho
    blocks = pairs if pairs is not None else PairBlocks(I, J, n)
    if not isinstance(blocks, PairBlocks):
        raise TypeError(f"pairs must be a refsph.neighbours.PairBlocks (or None), got {type(blocks).__name__}")
    if blocks.n != n or blocks.n_pairs != len(I):
        raise ValueError(f"pair blocks of {blocks.n_pairs} pairs over {blocks.n} particles do not match "
                         f"{len(I)} pairs over {n} particles")

    p = eos_pressure(rho, mat.rho0, mat.K)                              # Eq. (24)
    s = cauchy_stress(state.S, p) / (rho * rho)[:, None, None]          # sigma / rho^2
    particle = dict(x=[np.ascontiguousarray(state.x[:, k]) for k in range(d)],
                    v=[np.ascontiguousarray(state.v[:, k]) for k in range(d)],
                    m=m, V=m / rho, rho=rho, m_s=[[m * s[:, c, b] for b in range(d)] for c in range(d)],
                    a_p=np.abs(p) / (rho * rho), compressed=p > 0)
    sums = blocks.reduce(lambda blk: _block_sums(blk, particle, mat, prm, d, part))
    rows = _row_layout(d, prm.correction, part)

    if part == "forces":                                                # the deformation half is not asked for
        drho, l, dS, dS_zz = np.zeros(n), None, np.zeros((n, d, d)), np.zeros(n)
    else:
        drho = sums[rows["drho"]]                                       # Eq. (10)
        l = empty(n, d)                                                 # Eq. (23)
        for a in range(d):
            for b in range(d):
                l[:, a, b] = sums[rows["l"] + a * d + b]
        if prm.correction:                                              # l M^-1 (module text)
            M = empty(n, d)
            for a in range(d):
                for b in range(d):
                    M[:, a, b] = sums[rows["M"] + a * d + b]
            l = matmul(l, transpose(correction_matrix(M)[0]))
        dS, dS_zz = jaumann_deviatoric_rate(state.S, state.S_zz, l, mat.G)
    acc = np.zeros((d, n)) if part == "deformation" else np.empty((d, n))
    if part != "deformation":
        # Eq. (11) with s = sigma / rho^2, the stress term split in an i-side and a j-side sum (as in TLSPH's
        # ReferenceOperator.momentum_sum), so that no pair array of d x d stresses is gathered:
        #   a_i = sum_j m_j (s_i + s_j) gW_ij - sum_j m_j (pi_ij + p^a_ij) gW_ij
        #       = s_i . (sum_j m_j gW_ij)  +  sum_j m_j s_j gW_ij  -  sum_j m_j (pi_ij + p^a_ij) gW_ij
        # Every term is antisymmetric in (i, j): momentum is conserved to round-off.
        k = rows["mgW"]
        mgW, s_j, visc = sums[k:k + d], sums[k + d:k + d + d * d], sums[k + d + d * d:k + 2 * d + d * d]
        for c in range(d):
            acc[c] = -visc[c]
            for b in range(d):
                acc[c] += s[:, c, b] * mgW[b] + s_j[c * d + b]
    return Rates(x=state.v.copy(), v=acc.T, rho=drho, S=dS, S_zz=dS_zz, l=l)


def _row_layout(d: int, correction: bool, part: str) -> dict:
    """Where each sum of :func:`_block_sums` starts, for the part computed: the deformation rows (drho: 1, l: d^2,
    M: d^2 with the correction) first, then the force rows (mgW: d, s_j: d^2, visc: d), 'total' rows in all."""
    rows, k = {}, 0
    if part != "forces":
        rows.update(drho=0, l=1)
        k = 1 + d * d
        if correction:
            rows["M"] = k
            k += d * d
    if part != "deformation":
        rows["mgW"] = k
        k += 2 * d + d * d
    rows["total"] = k
    return rows


def _block_sums(blk, particle: dict, mat: ElasticMaterial, prm: ESPHParams, d: int, part: str = "all") -> np.ndarray:
    """The pair sums of one block of pairs, one row per sum (each row: the block's window of particles), laid out
    by :func:`_row_layout`:

        drho                   sum_j m_j v_ij . grad_i W_ij                          (Eq. (10))
        l + a d + b            -sum_j V_j (v_ij)_a (grad_i W_ij)_b                  (Eq. (23))
        M + a d + b            -sum_j V_j (x_ij)_a (grad_i W_ij)_b                  (the moment matrix; correction)
        mgW + b                sum_j m_j (grad_i W_ij)_b                             (Eq. (11), i-side)
        mgW + d + c d + b      sum_j m_j (s_j)_cb (grad_i W_ij)_b                   (Eq. (11), j-side)
        mgW + d + d^2 + c      sum_j m_j (pi_ij + p^a_ij) (grad_i W_ij)_c            (Eqs. (11)-(14))

    Per-particle inputs come as one contiguous array per component (gathering from a 1-D array is about 2.5x
    faster than gathering rows of an (N, d) array)."""
    I, J, sums, local = blk.I, blk.J, blk.sums, blk.local
    dx = [np.take(xk, I) - np.take(xk, J) for xk in particle["x"]]     # x_ij
    dv = [np.take(vk, I) - np.take(vk, J) for vk in particle["v"]]     # v_ij
    r2 = dx[0] * dx[0]
    vr = dv[0] * dx[0]                                                  # v_ij . x_ij
    for k in range(1, d):
        r2 += dx[k] * dx[k]
        vr += dv[k] * dx[k]
    w, fr = prm.kernel.w_and_dw_dr_over_r(np.sqrt(r2), prm.h, d)        # W_ij, (dW/dr)/r: zero beyond 2h
    gW = [fr * dxk for dxk in dx]                                       # grad_i W_ij

    m, V = local(particle["m"]), local(particle["V"])
    rows = _row_layout(d, prm.correction, part)
    out = np.empty((rows["total"], sums.n))
    if part != "forces":
        out[rows["drho"]] = continuity_rate(sums, m, fr * vr)           # Eq. (10)
        velocity_gradient(sums, V, dv, gW, out=out[rows["l"]:rows["l"] + d * d].reshape(d, d, sums.n))  # Eq. (23)
        if prm.correction:
            velocity_gradient(sums, V, dx, gW, out=out[rows["M"]:rows["M"] + d * d].reshape(d, d, sums.n))
    if part == "deformation":
        return out

    # pair scalar: artificial viscosity (Eqs. (12)-(13)) + artificial pressure (Eq. (14))
    rho = particle["rho"]
    pi = artificial_viscosity(vr, r2, 0.5 * (np.take(rho, I) + np.take(rho, J)), mat.c0, prm.h, prm.beta1,
                              prm.beta2, prm.eps)
    if prm.gamma > 0.0:
        w /= prm.kernel.w(prm.dp, prm.h, d)                             # W_ij / W(dp)
        a_p, compressed = particle["a_p"], particle["compressed"]
        pi += _artificial_pressure(np.take(a_p, I), np.take(a_p, J), np.take(compressed, I) & np.take(compressed, J),
                                   w, prm.gamma, prm.n_ap)

    k = rows["mgW"]
    for b in range(d):
        out[k + b] = sums.antisymmetric(gW[b], m)
        for c in range(d):
            out[k + d + c * d + b] = sums.antisymmetric(gW[b], local(particle["m_s"][c][b]))
    for c in range(d):
        out[k + d + d * d + c] = sums.antisymmetric(pi * gW[c], m)
    return out
