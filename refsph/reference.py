"""TLSPH's reference configuration during a run (Section 2.2): the sparse operator of the current reference
configuration (:class:`~refsph.tlsph.ReferenceOperator`, built once per configuration), its mirrored ghosts, the
deformation gradient of Eq. (18) on it, the density of Eq. (2) and the reference update.

    Eq. (18)  F_i = sum_j V_j (x_j - x_i) (x) grad_i W(X_ij)  (with the correction of Eq. (19) if asked)
    Eq. (2)   rho_i = m_i / (J_i V0_i),  J = det F

:class:`ReferenceConfiguration` is the part of the TLSPH solver (:mod:`refsph.solvers`) that owns the operator's
lifecycle: it is built lazily, kept while the reference configuration stands, and dropped and rebuilt when
max |E| > ``ref_update_strain`` (:func:`~refsph.tlsph.reference_update`: X <- x, V0 <- J V0, F <- I). With rigid
bodies it works on the leading deformable rows only (:meth:`ReferenceConfiguration.rows`).
"""
from __future__ import annotations

import numpy as np

from .boundaries import MirrorPlanes
from .state import State
from .tensor import det
from .tlsph import ReferenceOperator, TLSPHParams, green_lagrange_norm, reference_update

__all__ = ["ReferenceConfiguration", "with_identity"]

def with_identity(F: np.ndarray, state: State) -> np.ndarray:
    """F of the deformable rows extended to every row of ``state`` (rigid rows: F = I)."""
    if len(F) == state.n:
        return F
    out = np.broadcast_to(np.eye(state.dim), (state.n, state.dim, state.dim)).copy()
    out[:len(F)] = F
    return out


class ReferenceConfiguration:
    """The reference configuration of the deformable rows (module text). ``params``: the TLSPH parameters (h,
    kernel, correction, ``ref_update_strain``); ``mirror``: symmetry planes (the ghosts are the mirror images of the
    reference configuration, fixed with the operator; a ghost's F is the mirror image of its source's)."""

    def __init__(self, params: TLSPHParams, mirror: MirrorPlanes | None, threads: int):
        self.params, self.mirror, self.threads = params, mirror, threads
        self.op: ReferenceOperator | None = None
        self.ghost_constant: tuple | None = None           # extended (m, X, V0) of the operator's ghosts
        self.constant: tuple | None = None                 # (whole m, X, V0) -> their deformable rows (views)
        self.n_updates = 0
        self.cache_counts = [0, 0]                         # momentum-sum cache hits, misses of dropped operators
        self.F_known: tuple | None = None                  # (operator, x, F) of the last F computed (a cache)

    def rows(self, state: State, n: int) -> State:
        """The deformable rows [0, n) as a state of views (the whole state if there is no tool). The views of the
        constant fields m, X, V0 are made once per array, so that what the operator caches per array (the
        momentum sum's sum_j m_j grad W) stays valid from one evaluation to the next."""
        if n == state.n:
            return state
        whole = (state.m, state.X, state.V0)
        if self.constant is None or any(a is not b for a, b in zip(whole, self.constant[0])):
            self.constant = (whole, tuple(a[:n] for a in whole))
        m, X, V0 = self.constant[1]
        return state.rows(n, m=m, X=X, V0=V0)

    def operator(self, body: State, several_bodies: bool) -> ReferenceOperator:
        """The sparse operator of the current reference configuration of the deformable rows ``body``
        (``several_bodies``: no pair across two deformable bodies)."""
        if self.op is None:
            p = self.params
            ids = body.body if several_bodies else None
            if self.mirror is None:
                self.op = ReferenceOperator(body.X, body.V0, p.h, p.kernel, p.corrected, threads=self.threads,
                                            body=ids, max_condition=p.max_condition)
            else:
                g = self.mirror.ghosts(body.X, p.kernel.support * p.h)
                self.ghost_constant = g.extend_constant(body)   # m, X, V0: fixed with the operator
                _, X, V0 = self.ghost_constant
                self.op = ReferenceOperator(X, V0, p.h, p.kernel, p.corrected, ghosts=g, threads=self.threads,
                                            body=ids, max_condition=p.max_condition)
        return self.op

    def extended(self, body: State, op: ReferenceOperator) -> State:
        """The deformable rows with the operator's ghosts appended (the rows themselves without symmetry)."""
        return body if op.ghosts is None else op.ghosts.extend_state(body, self.ghost_constant)

    def deformation_gradient(self, ext: State, op: ReferenceOperator) -> np.ndarray:
        """Eq. (18) on the (extended) state; ghost rows are the mirror images of their sources'."""
        F = op.deformation_gradient(ext.x)
        g = op.ghosts
        if g is not None:
            F = np.array(F)
            F[g.n_real:] = g.tensors(F[:g.n_real])
        return F

    def rows_gradient(self, body: State, several_bodies: bool) -> np.ndarray:
        """Eq. (18) on the deformable rows ``body`` (their ghosts left out)."""
        op = self.operator(body, several_bodies)
        return self.deformation_gradient(self.extended(body, op), op)[:body.n]

    def gradient_for_rates(self, body: State, ext: State, op: ReferenceOperator) -> np.ndarray:
        """F for a rate evaluation: the last one computed (by :meth:`end_step` or by a rate evaluation) if it belongs
        to this operator and these positions, else Eq. (18) anew (then kept for :meth:`end_step`)."""
        F = self._known_gradient(body, op)
        if F is None:
            F = self.deformation_gradient(ext, op)
            self.F_known = (op, body.x.copy(), F)
        return F

    def _known_gradient(self, body: State, op: ReferenceOperator) -> np.ndarray | None:
        """The kept F if it was computed on ``op`` at exactly these positions (element by element), else None.
        The stepper's last rate evaluation of a step and :meth:`end_step` see the same x (the leapfrog's closing
        force), and so do :meth:`end_step` and the next step's first evaluation (the predictor-corrector)."""
        known = self.F_known
        if known is not None and known[0] is op and np.array_equal(known[1], body.x):
            return known[2]
        return None

    def end_step(self, state: State, n: int, several_bodies: bool) -> State:
        """rho = m / (J V0) (Eq. (2)) on the deformable rows; a reference update when max |E| >
        ``ref_update_strain``. The F computed here is kept for the first rate evaluation of the next step, which
        starts from this very configuration; it is the rate evaluation's own F where that one saw the same x (the
        check is element by element, so the result is the same bits either way).

        A particle with J <= 0 is inverted (the motion is no longer one-to-one there; Eq. (2) would give it a
        negative density and volume): ValueError naming it, which fails the step (a Lagrangian code's 'negative
        volume' stop; J > 0: Belytschko, Liu, Moran & Elkhodary 2014, ch. 3). A NaN J is left to the step's
        non-finite check."""
        body = self.rows(state, n)
        op = self.operator(body, several_bodies)
        F_ext = self._known_gradient(body, op)
        if F_ext is None:
            F_ext = self.deformation_gradient(self.extended(body, op), op)
        F = F_ext[:body.n]
        J = det(F)
        inverted = np.flatnonzero(J <= 0.0)
        if len(inverted):
            k = int(inverted[0])
            raise ValueError(f"inverted particle: J = det F = {float(J[k]):.6g} at particle {k} (and "
                             f"{len(inverted) - 1} more), so rho = m / (J V0) = "
                             f"{float(body.m[k] / (J[k] * body.V0[k])):.6g} kg/m^3 (Eq. (2))")
        rho = state.rho.copy()                  # (not in place: rho is not evolved, so shared with the old state)
        rho[:body.n] = body.m / (J * body.V0)
        state.rho = rho
        thr = self.params.ref_update_strain
        if thr is not None and float(np.max(green_lagrange_norm(F))) > thr:
            state = reference_update(state, with_identity(F, state))
            self.drop()
            self.operator(self.rows(state, n), several_bodies)
            self.n_updates += 1
            self.F_known = None
        else:
            self.F_known = (op, body.x.copy(), F_ext)
        return state

    def drop(self) -> None:
        """Forget the operator (its pair-sum threads closed, its cache counts kept)."""
        self.cache_counts[0] += self.op.momentum_cache_hits
        self.cache_counts[1] += self.op.momentum_cache_misses
        self.op.pairs.close()
        self.op = None

    def checkpoint(self) -> dict:
        return dict(n_reference_updates=np.int64(self.n_updates),
                    cache_counts=np.array(self.cache_counts, dtype=np.int64))

    def restore(self, ck: dict) -> None:
        self.n_updates = int(ck["n_reference_updates"])
        self.cache_counts = [int(c) for c in ck["cache_counts"]]

    def diagnostics(self) -> dict:
        op = self.op
        hits, misses = self.cache_counts
        if op is not None:
            hits, misses = hits + op.momentum_cache_hits, misses + op.momentum_cache_misses
        out = {"reference_updates": self.n_updates,
               "n_pairs": int(op.n_pairs) if op is not None else 0,
               "degenerate_correction_particles": int(len(op.degenerate)) if op is not None else 0,
               "momentum_sum_cache": {"hits": hits, "misses": misses}}
        if op is not None and op.ghosts is not None:
            out["n_ghosts"] = int(op.ghosts.n)
        return out
