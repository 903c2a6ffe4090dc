"""Total Lagrangian SPH (Section 2.2): kernels evaluated in the *reference* configuration X.

Pairs, kernel gradients grad_i W(X_ij) and reference volumes V_j = m_j / rho_0j do not change until the
reference configuration is updated, so every sum below is a product with a fixed sparse matrix
(:class:`ReferenceOperator`), built once per reference configuration. The artificial viscosity, whose pair
terms depend on the current x_ij and v_ij, is summed block by block with the operator's
:class:`~refsph.neighbours.PairBlocks` (fixed sparse patterns, new values at each evaluation).

    Eq. (15)  f(X_i)  = sum_j V_j f(X_j) W(X_ij),  V_j = m_j / rho_0j         (interpolation; refsph needs only
                                                                               its gradient, Eq. (16))
    Eq. (16)  grad f(X_i) = - sum_j V_j (f(X_i) - f(X_j)) (x) grad_i W(X_ij)  (:meth:`ReferenceOperator.gradient`)
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

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.integrate import quad

from .esph import artificial_viscosity
from .kernels import Kernel, correction_matrix
from .material import ElasticMaterial, cauchy_stress, eos_pressure, jaumann_deviatoric_rate
from .neighbours import PairBlocks, find_pairs, scatter_add
from .state import Rates, State
from .tensor import component_major, det, identity, inv, matmul, rowdot, transpose

__all__ = ["TLSPHParams", "ReferenceOperator", "tlsph_rates", "first_piola", "green_lagrange_norm", "gradient_gain",
           "full_support_gain", "largest_frequency",
           "reference_update", "reference_viscosity", "correction_matrix", "hourglass_acceleration"]


@dataclass(frozen=True)
class TLSPHParams:
    """Numerical parameters of TLSPH. h: smoothing length in the reference configuration [m];
    beta1, beta2, eps: artificial viscosity (Eqs. (12)-(13)); corrected: kernel-gradient correction;
    ref_update_strain: update the reference configuration when max_i |E_i| exceeds it, with
    E = (F^T F - I)/2 the Green-Lagrange strain (None: never); hourglass: the coefficient alpha of
    :func:`hourglass_acceleration` (0: off, as in the paper); viscous_heat: also return the power the artificial
    viscosity dissipates in each particle (``Rates.heat_power``, :func:`reference_viscosity`), for a run that turns
    it into heat (``Setup.dissipation_heat``); max_condition: the largest condition number of the moment matrix the
    kernel-gradient correction inverts as it is (None: no limit; :func:`refsph.kernels.correction_matrix`)."""

    h: float
    beta1: float
    beta2: float
    eps: float
    kernel: Kernel
    corrected: bool
    ref_update_strain: float | None
    hourglass: float = 0.0
    viscous_heat: bool = False
    max_condition: float | None = None


class ReferenceOperator:
    """Fixed sparse SPH operators of one reference configuration (X, V).

    For each direction k, ``G[k]`` is the N x N sparse matrix with entries

        G[k][i, j] = V_j (L_i grad_i W(X_ij))_k      (j != i; L = I when not corrected)

    so that  sum_j V_j f_j (x) grad~_i W_ij = (G[k] @ f)_i  and  sum_j V_j grad~_i W_ij = G[k] @ 1.
    ``GT[k]`` is its transpose (CSR), used for the j-side term of the momentum sum (Eq. (17)).
    The kernel-gradient correction L is baked into the entries, so F needs no per-step matrix product.

    ``pairs`` is a :class:`~refsph.neighbours.PairBlocks` of the half pairs (``block_size`` pairs per block,
    None = ``PAIR_BLOCK``), used by the artificial viscosity; its ``threads`` also run the independent sparse
    products of :meth:`gradient` and :meth:`momentum_sum` at the same time. The numbers do not depend on them.
    """

    def __init__(self, X: np.ndarray, V: np.ndarray, h: float, kernel: Kernel, corrected: bool,
                 ghosts=None, threads: int = 1, block_size: int | None = None, body: np.ndarray | None = None,
                 max_condition: float | None = None):
        X = np.asarray(X, dtype=float)
        n, d = X.shape
        self.n, self.dim, self.h, self.kernel, self.corrected = n, d, float(h), kernel, bool(corrected)
        self.X = X.copy()
        self.V = np.asarray(V, dtype=float).copy()
        self.ghosts = ghosts
        self.I, self.J = find_pairs(X, kernel.support * h)
        if ghosts is not None:
            # X = [real; mirror ghosts] (refsph.boundaries): ghost-ghost pairs act on ghosts only; dropped
            keep = self.I < ghosts.n_real
            self.I, self.J = self.I[keep], self.J[keep]
        if body is not None:
            # several deformable bodies: a particle's neighbours are those of its own body (the bodies meet
            # through the pinball contact, refsph.contact); ``body`` covers the real rows, ghosts take their source's
            b = np.asarray(body) if ghosts is None else ghosts.extend_scalars(np.asarray(body))
            keep = b[self.I] == b[self.J]
            self.I, self.J = self.I[keep], self.J[keep]
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
        if ghosts is not None:
            # a ghost's own neighbourhood is cut off; its moment matrix is the mirror image of its source's
            nr = ghosts.n_real
            self.M[nr:] = ghosts.tensors(self.M[:nr])
        self.L, self.degenerate = (correction_matrix(self.M, max_condition=max_condition) if corrected
                                   else (identity(n, d), np.zeros(0, dtype=np.intp)))
        if ghosts is not None:
            self.degenerate = self.degenerate[self.degenerate < ghosts.n_real]
        # the directions a degenerate particle's neighbours do not span: I - M+ M (F is completed there, below)
        self.unspanned = np.eye(d)[None] - np.linalg.pinv(self.M[self.degenerate]) @ self.M[self.degenerate]
        gc = np.einsum("pab,pb->pa", self.L[rows], g)     # corrected gradient L_row grad W
        Vgc = self.V[cols][:, None] * gc
        self.G = [sp.csr_matrix((Vgc[:, k], (rows, cols)), shape=(n, n)) for k in range(d)]
        self.GT = [Gk.T.tocsr() for Gk in self.G]
        self.s = np.stack([Gk @ np.ones(n) for Gk in self.G], axis=1)   # sum_j V_j grad~_i W_ij
        self.pairs = PairBlocks(I, J, n, size=block_size, threads=threads)     # for the artificial viscosity
        for blk in self.pairs.blocks:                          # its reference gradients, per component
            blk.gW = [np.ascontiguousarray(self.gW[blk.sl, k]) for k in range(d)]
        self._sm, self._sm_m = None, None
        self._W: tuple | None = None                          # hourglass constants, made on first use
        self.momentum_cache_hits = self.momentum_cache_misses = 0
        self._max_gain = self._critical_step = None         # max_gain(), critical_step(): made on first use

    def max_gain(self) -> float:
        """max(1, max_i a_i) of :func:`gradient_gain`, made once: the CFL step's divisor (``Numerics.gain_step``)."""
        if self._max_gain is None:
            self._max_gain = max(1.0, float(np.max(gradient_gain(self), initial=0.0)))
        return self._max_gain

    def critical_step(self, state: State, mat: ElasticMaterial, prm: TLSPHParams) -> float:
        """2 / w_max [s] of :func:`largest_frequency` about x = X at rest without stress (so a restart finds it
        again), made once: ``Numerics.frequency_step``'s limit. ``state``: the operator's rows (for the masses)."""
        if self._critical_step is None:
            rest = dataclasses.replace(state, x=self.X[:state.n].copy(), v=np.zeros_like(state.v),
                                       S=np.zeros_like(state.S), S_zz=np.zeros_like(state.S_zz))
            self._critical_step = 2.0 / largest_frequency(rest, mat, prm, self)[0]
        return self._critical_step

    def hourglass_constants(self) -> tuple[list, np.ndarray]:
        """What :func:`hourglass_acceleration` needs of the reference configuration, made once: X_j - X_i on the
        half pairs (one array per component) and V_i V_j W(|X_ij|) / |X_ij|^2."""
        if self._W is None:
            Xij = [np.ascontiguousarray(self.X[self.J, a] - self.X[self.I, a]) for a in range(self.dim)]
            R2 = sum(c * c for c in Xij)
            W = self.kernel.w(np.sqrt(R2), self.h, self.dim)
            self._W = (Xij, self.V[self.I] * self.V[self.J] * W / R2)
        return self._W

    def gradient(self, f: np.ndarray) -> np.ndarray:
        """Eq. (16) with the corrected gradient: sum_j V_j (f_j - f_i) (x) grad~_i W_ij, (N, c) -> (N, c, d).

        Computed as (G[k] @ f)_i - f_i s_ik, one column of f at a time (SciPy's single-vector CSR product is
        its fastest sparse kernel). The result is stored component-major (see :mod:`refsph.tensor`).
        """
        f = np.asarray(f, dtype=float)
        n, c = f.shape
        fT = np.ascontiguousarray(f.T)                      # fT[a]: column a of f, contiguous
        out = np.empty((self.dim, c, n))                    # out[k, a, i]: each component contiguous
        tasks = [(k, a) for k in range(self.dim) for a in range(c)]
        products = self.pairs.map(lambda ka: self.G[ka[0]] @ fT[ka[1]], tasks)   # independent: on threads
        for (k, a), Gf in zip(tasks, products):
            np.subtract(Gf, fT[a] * self.s[:, k], out=out[k, a])
        return out.transpose(2, 1, 0)

    def deformation_gradient(self, x: np.ndarray) -> np.ndarray:
        """Eq. (18): F_i = sum_j V_j (x_j - x_i) (x) grad~_i W(X_ij). A degenerate particle (its neighbours do not
        span every direction: a chain, a lone particle torn off a chip) knows F only in the directions they span;
        there it is Eq. (18) with the pseudo-inverse correction (:func:`refsph.kernels.correction_matrix`), and in
        the others F is completed with the identity, F_i += I - M_i^+ M_i (no stretch where nothing is known; the
        paper is silent; without it det F = 0 and the particle's density and reference volume are undefined)."""
        F = self.gradient(x)
        if len(self.degenerate):
            F[self.degenerate] += self.unspanned
        return F

    def momentum_sum(self, Q: np.ndarray, m: np.ndarray) -> np.ndarray:
        """sum_j m_j (Q_i grad~_i W_ij - Q_j grad~_j W_ji) for Q of shape (N, d, d).

        With Q = P / rho_0^2 this is the stress part of Eq. (17). The i-side term is Q_i (sum_j m_j grad~_i W_ij);
        the j-side term uses the transposed operator: m_j grad~_j W_ji = (m_j / V_i) G[k][j, i].
        The pair term is antisymmetric, so sum_i m_i dv_i/dt = 0 (momentum conserved to round-off).
        """
        if self._sm is None or self._sm_m is not m:          # cached per mass array (the masses are constant)
            rho_ref = m / self.V
            self._sm = np.stack([Gk @ rho_ref for Gk in self.G], axis=1)  # sum_j m_j grad~_i W_ij (fixed)
            self._sm_m = m
            self.momentum_cache_misses += 1
        else:
            self.momentum_cache_hits += 1
        sm = self._sm
        Q = component_major(Q)
        d = self.dim
        out = np.empty((d, self.n))                         # out[a, i]
        tasks = [(a, k) for a in range(d) for k in range(d)]
        # sum_j m_j Q_j,ak V_i grad~_j W_ji, one sparse product per (a, k), independent: on threads
        jside = self.pairs.map(lambda ak: self.GT[ak[1]] @ (m * Q[:, ak[0], ak[1]]), tasks)
        for a in range(d):
            iside = rowdot(Q[:, a, :], sm)                                  # Q_i,ak sm_ik
            js = jside[a * d]
            for k in range(1, d):
                js += jside[a * d + k]
            out[a] = iside - js / self.V
        return out.T


def full_support_gain(kernel: Kernel, h: float, dim: int) -> float:
    """int |grad W| dV over the kernel's support [1/m]: what sum_j V_j |grad_i W(X_ij)| tends to for a particle
    whose support is full (a fine lattice), the reference of :func:`gradient_gain`."""
    shell = {2: lambda r: 2.0 * np.pi * r, 3: lambda r: 4.0 * np.pi * r * r}[dim]   # the kernels' 2D and 3D
    value, _ = quad(lambda r: shell(r) * abs(float(kernel.dw_dr(r, h, dim))), 0.0, kernel.support * h, limit=200)
    return float(value)


def gradient_gain(op: ReferenceOperator) -> np.ndarray:
    """The gain of Eq. (18)'s corrected gradient at each real particle, against a full support's (refsph's
    measure, not the paper's):

        a_i = sum_j V_j |L_i grad_i W(X_ij)| / int |grad W| dV      (about 1 inside a body)

    Eq. (18) gives |F_i - F'_i| <= a_i (int |grad W| dV) max_j |u_ij - u'_ij| for two displacement fields u, u', so
    a particle's stiffness grows like a_i^2 and its frequency like a_i. Where a reference update leaves a particle
    with few neighbours on one side (a torn chip tip), L_i = M_i^-T amplifies and a_i reaches 3 (the sweep's
    blown-up cuts), while the CFL step assumes 1: ``Numerics.gain_step`` divides the step by max(1, max_i a_i).
    Computed from the operator's matrices G_k (entries V_j (L_i grad_i W_ij)_k), ghost rows left out."""
    magnitude = sum(Gk.multiply(Gk) for Gk in op.G).sqrt()
    A = np.asarray(magnitude.sum(axis=1)).ravel()
    n = op.n if op.ghosts is None else op.ghosts.n_real
    return A[:n] / full_support_gain(op.kernel, op.h, op.dim)


def largest_frequency(state: State, mat: ElasticMaterial, prm: TLSPHParams, op: ReferenceOperator, *,
                      tol: float = 1e-3, seed: int = 0) -> tuple[float, np.ndarray]:
    """The largest angular frequency w_max [rad/s] of the elastic TLSPH equations linearised about ``state`` on
    ``op`` (refsph's diagnostic; the paper gives only the CFL step), and the mode's amplitude per particle (N,).

    A displacement u moves x by eps u and, through Eqs. (19) and (20) with u for v, the deviatoric stress by
    eps dS/dt; Eqs. (24) and (17) (artificial viscosity off: it damps, it does not stiffen; hourglass control as
    ``prm`` says) then change the acceleration by -eps K u. The leapfrog on u'' = -K u is stable if and only if

        dt w_max < 2,   w_max^2 = the largest |eigenvalue| of K       (Hairer, Lubich & Wanner 2006, Sec. I.5)

    for the linear elastic body exactly, and to first order about any state (plastic flow only softens; a tool's
    penalty spring alpha m / tau^2, :mod:`refsph.penalty`, adds a frequency sqrt(alpha) / tau with tau the CFL step at
    the run's Courant number, so dt sqrt(alpha) / tau <= sqrt(alpha), 0.32 at the scenes' alpha = 0.1: left out). So
    2 / (w_max h / (c_L + |v|max)) is the largest Courant number the state allows, against the CFL step's. K is
    applied matrix-free (three rate evaluations) and its largest eigenvalue found by ARPACK (SciPy's ``eigs``,
    relative ``tol``). ``state``: the operator's rows (a body without ghosts: mirror planes are refused)."""
    from scipy.sparse.linalg import LinearOperator, eigs
    if op.ghosts is not None:
        raise ValueError("largest_frequency takes a body without mirror ghosts")
    n, d = state.x.shape
    if n != op.n:
        raise ValueError(f"the state has {n} rows, the operator {op.n}")
    prm = dataclasses.replace(prm, beta1=0.0, beta2=0.0)
    a0 = tlsph_rates(state, mat, prm, op, part="forces").v
    size = float(np.sqrt(np.median(op.V)))                  # a particle spacing [m]

    def K(u):
        u = u.reshape(n, d)
        eps = 1e-6 * size / max(float(np.max(np.abs(u))), 1e-300)
        rate = tlsph_rates(dataclasses.replace(state, v=u), mat, prm, op, part="deformation")
        moved = dataclasses.replace(state, x=state.x + eps * u, S=state.S + eps * rate.S,
                                    S_zz=state.S_zz + eps * rate.S_zz)
        return (a0 - tlsph_rates(moved, mat, prm, op, part="forces").v).ravel() / eps

    start = np.random.default_rng(seed).standard_normal(n * d)
    w, vec = eigs(LinearOperator((n * d, n * d), matvec=K, dtype=float), k=1, which="LM", v0=start, tol=tol,
                  ncv=min(n * d - 1, 30), maxiter=5000)
    mode = np.sqrt(np.sum(np.abs(vec[:, 0].reshape(n, d)) ** 2, axis=1))
    return float(np.sqrt(abs(w[0]))), mode / mode.max()


def first_piola(sigma: np.ndarray, J: np.ndarray, Finv: np.ndarray) -> np.ndarray:
    """P = J sigma F^-T (the transpose of the paper's printed J F^-1 sigma; see the module docstring)."""
    return matmul(J[:, None, None] * sigma, transpose(Finv))


def green_lagrange_norm(F: np.ndarray) -> np.ndarray:
    """|E|_Frobenius with E = (F^T F - I) / 2: zero for any rigid motion."""
    F = component_major(F)
    E = 0.5 * matmul(transpose(F), F)
    for a in range(F.shape[1]):
        E[:, a, a] -= 0.5
    return np.sqrt(sum(E[:, a, b] ** 2 for a in range(F.shape[1]) for b in range(F.shape[1])))


def reference_viscosity(x: np.ndarray, v: np.ndarray, m: np.ndarray, rho: np.ndarray, B: np.ndarray,
                        op: ReferenceOperator, c0: float, prm: TLSPHParams) -> tuple[np.ndarray, np.ndarray | None]:
    """Artificial viscosity of Eq. (17) in the reference frame: -sum_j m_j pi_ij (B_i + B_j)/2 grad_i W(X_ij);
    returns (a, q), q (N,) [W; 2D: W/m] the power it dissipates in each particle if ``prm.viscous_heat`` (else None).

    pi_ij is Eqs. (12)-(13) with the current x_ij, v_ij (zero for receding pairs, v_ij . x_ij >= 0). As in the
    stress term, the pair sum is split into an i-side and a j-side sum, so that no B is gathered per pair:

        sum_j m_j pi_ij (B_i + B_j) g_ij / 2 = B_i (sum_j m_j pi_ij g_ij) / 2 + (sum_j m_j B_j pi_ij g_ij) / 2,

    g_ij = grad_i W(X_ij). Both are antisymmetric pair sums (momentum conserved to round-off), computed block
    by block over ``op.pairs`` (a :class:`~refsph.neighbours.PairBlocks`, see :func:`_viscosity_block`).
    B is (N, d, d).

    The dissipated power (Monaghan's energy equation, the viscous term of the SPH energy equation, in the
    reference frame): the pair's forces -/+ m_i m_j pi_ij gbar_ij (gbar_ij = (B_i + B_j) g_ij / 2) do the work
    -m_i m_j pi_ij v_ij . gbar_ij per unit time on the two particles together (<= 0: pi_ij is zero for receding
    pairs); each particle takes half of it as heat,

        q_i = m_i / 2 sum_j m_j pi_ij v_ij . gbar_ij   >= 0,    sum_i q_i = -sum_i m_i v_i . a_i (the viscous a).
    """
    n, d = x.shape
    particle = dict(x=[np.ascontiguousarray(x[:, k]) for k in range(d)],
                    v=[np.ascontiguousarray(v[:, k]) for k in range(d)],
                    rho=rho, m=m, m_B=[[m * B[:, c, b] for b in range(d)] for c in range(d)])
    if prm.viscous_heat:
        particle["B"] = [[np.ascontiguousarray(B[:, c, b]) for b in range(d)] for c in range(d)]
    sums = op.pairs.reduce(lambda blk: _viscosity_block(blk, particle, c0, prm, d))
    a = np.empty((n, d))
    for c in range(d):                          # rows of block b: sum_j m_j pi g_b, sum_j m_j B_j,cb pi g_b (c...)
        a[:, c] = sum(B[:, c, b] * sums[b * (d + 1)] + sums[b * (d + 1) + 1 + c] for b in range(d))
    a *= -0.5
    return a, (0.5 * m * sums[d * (d + 1)] if prm.viscous_heat else None)


def _viscosity_block(blk, particle: dict, c0: float, prm: TLSPHParams, d: int) -> np.ndarray:
    """Over one block's pairs (rows over its window): for each direction b, the row sum_j m_j pi_ij (g_ij)_b,
    then the d rows sum_j m_j (B_j)_cb pi_ij (g_ij)_b, c = 0..d-1; with ``particle['B']`` one more row,
    sum_j m_j pi_ij v_ij . (B_i + B_j) g_ij / 2 (the viscous heat, :func:`reference_viscosity`)."""
    I, J = blk.I, blk.J
    dx = [np.take(xk, I) - np.take(xk, J) for xk in particle["x"]]     # current x_ij
    dv = [np.take(vk, I) - np.take(vk, J) for vk in particle["v"]]     # v_ij
    r2 = dx[0] * dx[0]
    vr = dv[0] * dx[0]
    for k in range(1, d):
        r2 += dx[k] * dx[k]
        vr += dv[k] * dx[k]
    rho = particle["rho"]
    pi = artificial_viscosity(vr, r2, 0.5 * (np.take(rho, I) + np.take(rho, J)), c0, prm.h, prm.beta1,
                              prm.beta2, prm.eps)
    heat = "B" in particle
    out = np.empty((d * (d + 1) + heat, blk.sums.n))
    for b in range(d):
        t = pi * blk.gW[b]
        out[b * (d + 1)] = blk.sums.antisymmetric(t, blk.local(particle["m"]))
        for c in range(d):
            out[b * (d + 1) + 1 + c] = blk.sums.antisymmetric(t, blk.local(particle["m_B"][c][b]))
    if heat:                                    # v_ij . gbar_ij, gbar_ij = (B_i + B_j) g_ij / 2; symmetric in i, j
        w = np.zeros(len(I))
        for c in range(d):
            for b in range(d):
                Bcb = particle["B"][c][b]
                w += dv[c] * (0.5 * (np.take(Bcb, I) + np.take(Bcb, J))) * blk.gW[b]
        out[d * (d + 1)] = blk.sums.symmetric(pi * w, blk.local(particle["m"]))
    return out


def tlsph_rates(state: State, mat: ElasticMaterial, prm: TLSPHParams, op: ReferenceOperator,
                out: dict | None = None, F: np.ndarray | None = None, part: str = "all") -> Rates:
    """All TLSPH time derivatives. If ``out`` is a dict, F, J, P and l are stored in it (diagnostics).

    ``F``: the deformation gradient of ``state.x`` on ``op`` (Eq. (18)), if the caller already has it. ``part``:
    'all'; 'deformation' (Eqs. (19), (20): the stress rates and l, dv/dt zero; P is not computed) or 'forces'
    (Eq. (17): dv/dt only, the stress rates zero), the halves a staggered stepper evaluates apart."""
    if part not in ("all", "deformation", "forces"):
        raise ValueError(f"part must be 'all', 'deformation' or 'forces', got {part!r}")
    n, d = state.x.shape
    x, v, m = state.x, state.v, state.m

    if F is None:
        F = op.deformation_gradient(x)                      # Eq. (18)
    J = det(F)
    Finv = inv(F, J)
    rho_ref = m / op.V                                      # reference density rho_0 = m / V
    rho = rho_ref / J                                       # Eq. (2)
    p = eos_pressure(rho, mat.rho0, mat.K)                  # Eq. (24)
    l, P, heat_power = None, None, None
    if part == "forces":                                    # the deformation half is not asked for
        dS, dS_zz = np.zeros((n, d, d)), np.zeros(n)
    else:
        Fdot = op.gradient(v)                               # Eq. (19)
        l = matmul(Fdot, Finv)
        dS, dS_zz = jaumann_deviatoric_rate(state.S, state.S_zz, l, mat.G)
    if part == "deformation":                               # the force half is not asked for
        a = np.zeros((n, d))
    else:
        sigma = cauchy_stress(state.S, p)
        P = first_piola(sigma, J, Finv)
        # Eq. (17), stress part: a_i = sum_j m_j (P_i / rho_0i^2 grad~_i W_ij - P_j / rho_0j^2 grad~_j W_ji)
        a = op.momentum_sum(P / (rho_ref**2)[:, None, None], m)
        # Eq. (17), artificial viscosity: a_i -= sum_j m_j pi_ij (B_i + B_j)/2 grad_i W_ij,  B = J F^-T
        if prm.beta1 > 0 or prm.beta2 > 0:
            B = J[:, None, None] * transpose(Finv)
            a_visc, heat_power = reference_viscosity(x, v, m, rho, B, op, mat.c0, prm)
            a += a_visc
        if prm.hourglass > 0:
            a += hourglass_acceleration(x, F, m, op, mat.E, prm.hourglass)
    if out is not None:
        out.update(F=F, J=J, P=P, l=l, rho=rho, p=p)
    return Rates(x=v.copy(), v=a, rho=None, S=dS, S_zz=dS_zz, l=l, heat_power=heat_power)


def hourglass_acceleration(x: np.ndarray, F: np.ndarray, m: np.ndarray, op: ReferenceOperator, E: float,
                           alpha: float) -> np.ndarray:
    """Hourglass control (Ganzenmueller 2015, CMAME 286, 87; the scheme of LAMMPS's SMD package): a penalty on the
    part of the pair separation that F does not explain. With X_ij = X_j - X_i, x_ij = x_j - x_i, r = |x_ij|:

        eps_ij  = (F_i + F_j)/2 X_ij - x_ij          (the error of the linear prediction, both sides averaged)
        delta   = eps_ij . x_ij / r                   (its part along the pair)
        f_i     = -alpha E V_i V_j W(X_ij) / |X_ij|^2 delta x_ij / r,   f_j = -f_i

    so dv_i/dt = sum_j f_i / m_i. It vanishes for every linear (affine) deformation, where F X_ij = x_ij exactly,
    and pushes back the zig-zag (zero-energy) modes that F, a sum over the neighbours, cannot see. Linear and
    angular momentum are conserved (the pair force is along x_ij). alpha ~ 0.1-10 (LAMMPS's default 10); it
    stiffens the particle-scale modes and so lowers the stable time step a little at large alpha."""
    I, J = op.I, op.J
    n, d = x.shape
    real = op.ghosts.n_real if op.ghosts is not None else op.n
    Xij, coef = op.hourglass_constants()                    # X_j - X_i per component; V_i V_j W(X_ij) / |X_ij|^2
    xij = [np.take(x[:, a], J) - np.take(x[:, a], I) for a in range(d)]
    err = []
    for a in range(d):                                      # (F_i + F_j)/2 X_ij - x_ij, one component at a time
        Fa = [np.ascontiguousarray(F[:, a, b]) for b in range(d)]
        e = -xij[a]
        for b in range(d):
            e = e + 0.5 * (np.take(Fa[b], I) + np.take(Fa[b], J)) * Xij[b]
        err.append(e)
    r2 = sum(c * c for c in xij)
    mag = (-alpha * E) * coef * sum(e * c for e, c in zip(err, xij)) / r2     # delta / r folded in
    acc = np.empty((n, d))
    for a in range(d):
        f = mag * xij[a]                                    # on i; -f on j
        acc[:, a] = np.bincount(I, f, minlength=n) - np.bincount(J, f, minlength=n)
    acc[:real] /= m[:real, None]
    acc[real:] = 0.0                                        # ghosts: their own rows are not used
    return acc


def reference_update(state: State, F: np.ndarray) -> State:
    """Reference-configuration update (Section 3): X <- x, V0 <- J V0, J = det F, rho = m / V0; stress and every
    other field kept. ``F``: the deformation gradient of ``state.x`` on the old reference configuration (Eq. (18)).
    A new state; the operator of the new configuration is ``ReferenceOperator(new.X, new.V0, ...)``."""
    J = det(F)
    bad = np.flatnonzero(~(J > 0))
    if len(bad):
        raise ValueError(f"reference update: J = det F = {J[bad[0]]!r} at particle {bad[0]} (and {len(bad) - 1} "
                         "more); the new reference volume J V0 would not be positive (a particle whose neighbours "
                         "lie in one line, or an inverted one)")
    new = state.copy()
    new.X = state.x.copy()
    new.V0 = J * state.V0
    new.rho = state.m / new.V0
    return new
