"""Solvers (ESPH, TLSPH) behind one interface, the predictor-corrector step and the CFL time step.

Predictor-corrector (Monaghan 1989, J. Comput. Phys. 82, 1; the scheme of SPHysics, Gomez-Gesteira et al.
2012), for every evolved field y with rate f(y):

    predictor:  y^{n+1/2} = y^n + dt/2 f(y^n)
    corrector:  y^{n+1/2} = y^n + dt/2 f(y^{n+1/2})
    final:      y^{n+1}   = 2 y^{n+1/2} - y^n  =  y^n + dt f(y^{n+1/2})

It is second order and needs two rate evaluations per step. The paper states only "predictor-corrector
with a CFL time step"; this is the standard SPH form.

CFL time step:  dt = C_cfl h / (c_L + max|v|),  c_L = sqrt((K + 4G/3)/rho0), the dilatational wave speed
(the fastest signal in a solid; the paper's C = sqrt(E/rho) is smaller, so it is used only in Eq. 12).
A fixed dt, as in the paper's tables, is also accepted by the driver.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .esph import ESPHParams, Rates, esph_rates
from .material import ElasticMaterial
from .neighbours import PairSum, VerletList
from .state import State
from .tensor import det
from .tlsph import ReferenceOperator, TLSPHParams, green_lagrange_norm, reference_update, tlsph_rates

__all__ = ["ESPHSolver", "TLSPHSolver", "predictor_corrector_step", "cfl_time_step"]


class ESPHSolver:
    """ESPH rates with a Verlet pair list (cutoff 2h, skin ``skin_factor * h``; the scenes' value is
    ``Numerics.skin_factor``)."""

    method = "esph"
    evolved = ("x", "v", "rho", "S", "S_zz")

    def __init__(self, material: ElasticMaterial, params: ESPHParams, skin_factor: float):
        self.material, self.params = material, params
        self.pairs = VerletList(params.kernel.support * params.h, skin_factor * params.h)
        self._pair_sum: PairSum | None = None              # sparse pattern of the current pair list
        self._pair_sum_build = -1

    @property
    def h(self) -> float:
        return self.params.h

    def rates(self, state: State) -> Rates:
        I, J = self.pairs.update(state.x)
        if self._pair_sum_build != self.pairs.n_builds:
            self._pair_sum, self._pair_sum_build = PairSum(I, J, state.n), self.pairs.n_builds
        return esph_rates(state, self.material, self.params, I, J, pairs=self._pair_sum)

    def after_step(self, state: State) -> State:
        return state

    def diagnostics(self) -> dict:
        return {"neighbour_list_builds": self.pairs.n_builds, "n_pairs": int(len(self.pairs.I))}


class TLSPHSolver:
    """TLSPH rates with a fixed sparse operator, rebuilt at reference-configuration updates."""

    method = "tlsph"
    evolved = ("x", "v", "S", "S_zz")

    def __init__(self, material: ElasticMaterial, params: TLSPHParams):
        self.material, self.params = material, params
        self.op: ReferenceOperator | None = None
        self.n_reference_updates = 0
        self._F_after_step: tuple | None = None

    @property
    def h(self) -> float:
        return self.params.h

    def operator(self, state: State) -> ReferenceOperator:
        if self.op is None:
            p = self.params
            self.op = ReferenceOperator(state.X, state.V0, p.h, p.kernel, p.corrected)
        return self.op

    def rates(self, state: State) -> Rates:
        op = self.operator(state)
        return tlsph_rates(state, self.material, self.params, op, F=self._F_from_after_step(state, op))

    def deformation_gradient(self, state: State) -> np.ndarray:
        return self.operator(state).deformation_gradient(state.x)

    def after_step(self, state: State) -> State:
        """rho = m / (J V0) (Eq. 2); reference update when max |E| > ref_update_strain.

        The F computed here is kept for the first rate evaluation of the next step, which starts from this
        very configuration (it is used only if x is unchanged, checked element by element)."""
        op = self.operator(state)
        F = op.deformation_gradient(state.x)
        state.rho = state.m / (det(F) * state.V0)
        thr = self.params.ref_update_strain
        if thr is not None and float(np.max(green_lagrange_norm(F))) > thr:
            state, self.op = reference_update(state, op, F)
            self.n_reference_updates += 1
            self._F_after_step = None
        else:
            self._F_after_step = (op, state.x.copy(), F)
        return state

    def _F_from_after_step(self, state: State, op: ReferenceOperator) -> np.ndarray | None:
        """The F of the last after_step if it belongs to this operator and these positions (used once)."""
        known, self._F_after_step = self._F_after_step, None
        if known is not None and known[0] is op and np.array_equal(known[1], state.x):
            return known[2]
        return None

    def diagnostics(self) -> dict:
        return {"reference_updates": self.n_reference_updates,
                "n_pairs": int(self.op.n_pairs) if self.op is not None else 0,
                "degenerate_correction_particles": int(len(self.op.degenerate)) if self.op is not None else 0}


def _advance(state: State, rates: Rates, dt: float, evolved) -> State:
    new = replace(state)
    for name in evolved:
        setattr(new, name, getattr(state, name) + dt * getattr(rates, name))
    return new


def predictor_corrector_step(state: State, solver, dt: float) -> State:
    """One predictor-corrector step (two rate evaluations), then the solver's after-step work."""
    half = _advance(state, solver.rates(state), 0.5 * dt, solver.evolved)
    half.t = state.t + 0.5 * dt
    new = _advance(state, solver.rates(half), dt, solver.evolved)
    new.t = state.t + dt
    return solver.after_step(new)


def cfl_time_step(state: State, material: ElasticMaterial, h: float, courant: float) -> float:
    """dt = courant * h / (c_L + max |v|)."""
    if not 0 < courant <= 1:
        raise ValueError(f"Courant number must lie in (0, 1], got {courant!r}")
    vmax = float(np.sqrt(np.max(np.einsum("ik,ik->i", state.v, state.v)))) if state.n else 0.0
    return courant * h / (material.c_longitudinal + vmax)
