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
from .boundaries import Ghosts, MirrorPlanes
from .plasticity import JohnsonCook, equivalent_strain_rate, plastic_update
from .tlsph import ReferenceOperator, TLSPHParams, green_lagrange_norm, reset_reference, tlsph_rates

__all__ = ["ESPHSolver", "TLSPHSolver", "predictor_corrector_step", "cfl_time_step"]


class _Solver:
    """What ESPH and TLSPH share: boundaries (symmetry planes, rigid walls) and the Johnson-Cook return map.

    ``finish_stage`` is called on the state produced by each stage of the step (see
    :func:`predictor_corrector_step`): walls first (a kinematic constraint), then the plastic return map with
    the stage's strain rate. Only the final stage (``final=True``) accumulates eps_p, W_p and T and the wall
    impulse; the predictor's half state is returned to the yield surface with the start-of-step values, so that
    the midpoint rates see an admissible stress."""

    def _init_common(self, material, plasticity, mirror, walls):
        self.material = material
        self.plasticity = plasticity
        self.mirror = mirror
        self.walls = tuple(walls or ())
        self.wall_impulse = np.zeros(len(self.walls))

    def check_state(self, state: State) -> None:
        """The state fits the solver: the Johnson-Cook fields where plasticity is on, boundaries in its
        dimension (ValueError otherwise)."""
        if self.plasticity is not None and not state.plastic:
            raise ValueError("a Johnson-Cook material needs a state with eps_p, eps_dot_p, W_p and T "
                             "(make_state(..., T0=room temperature))")
        for w in self.walls:
            w.check(state.dim)
        if self.mirror is not None:
            self.mirror.check(state.dim)

    def finish_stage(self, old: State, new: State, rates: Rates, dt: float, final: bool) -> State:
        for k, wall in enumerate(self.walls):
            imp = wall.apply(new, dt)
            if final:
                self.wall_impulse[k] += imp
        jc = self.plasticity
        if jc is not None:
            self.check_state(old)
            eps_dot = equivalent_strain_rate(rates.l)
            rho = new.rho if rates.rho is not None else old.rho
            S, S_zz, deps, dw, dT = plastic_update(new.S, new.S_zz, old.eps_p, old.T, rho, eps_dot, jc,
                                                   self.material.G)
            new.S, new.S_zz = S, S_zz
            if final:
                new.eps_p = old.eps_p + deps
                new.W_p = old.W_p + dw
                new.T = old.T + dT
                new.eps_dot_p = deps / dt
        return new

    @staticmethod
    def _real_rows(r: Rates, n: int) -> Rates:
        """The rates of the first n (real) particles of an extended (real + ghost) evaluation."""
        return Rates(x=r.x[:n], v=r.v[:n], rho=None if r.rho is None else r.rho[:n], S=r.S[:n], S_zz=r.S_zz[:n],
                     l=r.l[:n])

    def _common_diagnostics(self) -> dict:
        out = {}
        if self.walls:
            # impulse of each wall on the *model* (a quarter/half of the body with symmetry planes), N s (2D: N s/m)
            out["wall_impulse"] = [float(i) for i in self.wall_impulse]
        return out


class ESPHSolver(_Solver):
    """ESPH rates with a Verlet pair list (cutoff 2h, skin ``skin_factor * h``; the scenes' value is
    ``Numerics.skin_factor``). With symmetry planes (``mirror``) the ghosts are chosen when the list is built
    (every particle within 2h + skin of a plane) and move with their sources until the next build."""

    method = "esph"
    evolved = ("x", "v", "rho", "S", "S_zz")

    def __init__(self, material: ElasticMaterial, params: ESPHParams, skin_factor: float, *,
                 plasticity: JohnsonCook | None = None, mirror: MirrorPlanes | None = None, walls=()):
        self._init_common(material, plasticity, mirror, walls)
        self.params = params
        self.pairs = VerletList(params.kernel.support * params.h, skin_factor * params.h)
        self._pair_sum: PairSum | None = None              # sparse pattern of the current pair list
        self._pair_sum_build = -1
        self._ghosts: Ghosts | None = None
        self._ghost_constant: tuple | None = None          # extended (m, X, V0) of the current ghosts

    @property
    def h(self) -> float:
        return self.params.h

    def _pairs_and_state(self, state: State):
        if self.mirror is None:
            return self.pairs.update(state.x), state
        x = state.x
        if self._ghosts is None or self.pairs.needs_rebuild(x):
            self._ghosts = self.mirror.ghosts(x, self.pairs.cutoff + self.pairs.skin)
            self._ghost_constant = self._ghosts.extend_constant(state)
            I, J = self.pairs.build(self._ghosts.extend_vectors(x), track=x)
            keep = I < state.n                              # ghost-ghost pairs act on ghosts only
            self.pairs.I, self.pairs.J = I[keep], J[keep]
        return (self.pairs.I, self.pairs.J), self._ghosts.extend_state(state, self._ghost_constant)

    def rates(self, state: State) -> Rates:
        (I, J), ext = self._pairs_and_state(state)
        if self._pair_sum_build != self.pairs.n_builds:
            self._pair_sum, self._pair_sum_build = PairSum(I, J, ext.n), self.pairs.n_builds
        r = esph_rates(ext, self.material, self.params, I, J, pairs=self._pair_sum)
        return r if ext is state else self._real_rows(r, state.n)

    def after_step(self, state: State) -> State:
        return state

    def diagnostics(self) -> dict:
        out = {"neighbour_list_builds": self.pairs.n_builds, "n_pairs": int(len(self.pairs.I))}
        if self._ghosts is not None:
            out["n_ghosts"] = int(self._ghosts.n)
        out.update(self._common_diagnostics())
        return out


class TLSPHSolver(_Solver):
    """TLSPH rates with a fixed sparse operator, rebuilt at reference-configuration updates. With symmetry
    planes the ghosts are the mirror images of the reference configuration (fixed with the operator); a
    ghost's F is the mirror image of its source's."""

    method = "tlsph"
    evolved = ("x", "v", "S", "S_zz")

    def __init__(self, material: ElasticMaterial, params: TLSPHParams, *, plasticity: JohnsonCook | None = None,
                 mirror: MirrorPlanes | None = None, walls=()):
        self._init_common(material, plasticity, mirror, walls)
        self.params = params
        self.op: ReferenceOperator | None = None
        self._ghost_constant: tuple | None = None          # extended (m, X, V0) of the operator's ghosts
        self.n_reference_updates = 0
        self._F_after_step: tuple | None = None

    @property
    def h(self) -> float:
        return self.params.h

    def operator(self, state: State) -> ReferenceOperator:
        if self.op is None:
            p = self.params
            if self.mirror is None:
                self.op = ReferenceOperator(state.X, state.V0, p.h, p.kernel, p.corrected)
            else:
                g = self.mirror.ghosts(state.X, p.kernel.support * p.h)
                self._ghost_constant = g.extend_constant(state)   # m, X, V0: fixed with the operator
                _, X, V0 = self._ghost_constant
                self.op = ReferenceOperator(X, V0, p.h, p.kernel, p.corrected, ghosts=g)
        return self.op

    def _extended(self, state: State, op: ReferenceOperator) -> State:
        return state if op.ghosts is None else op.ghosts.extend_state(state, self._ghost_constant)

    def _F(self, ext: State, op: ReferenceOperator) -> np.ndarray:
        """Eq. (18) on the (extended) state; ghost rows are the mirror images of their sources'."""
        F = op.deformation_gradient(ext.x)
        g = op.ghosts
        if g is not None:
            F = np.array(F)
            F[g.n_real:] = g.tensors(F[:g.n_real])
        return F

    def rates(self, state: State) -> Rates:
        op = self.operator(state)
        ext = self._extended(state, op)
        F = self._F_from_after_step(state, op)
        if F is None:
            F = self._F(ext, op)
        r = tlsph_rates(ext, self.material, self.params, op, F=F)
        return r if ext is state else self._real_rows(r, state.n)

    def deformation_gradient(self, state: State) -> np.ndarray:
        op = self.operator(state)
        return self._F(self._extended(state, op), op)[:state.n]

    def after_step(self, state: State) -> State:
        """rho = m / (J V0) (Eq. 2); reference update when max |E| > ref_update_strain.

        The F computed here is kept for the first rate evaluation of the next step, which starts from this
        very configuration (it is used only if x is unchanged, checked element by element)."""
        op = self.operator(state)
        F_ext = self._F(self._extended(state, op), op)
        F = F_ext[:state.n]
        state.rho = state.m / (det(F) * state.V0)
        thr = self.params.ref_update_strain
        if thr is not None and float(np.max(green_lagrange_norm(F))) > thr:
            state = reset_reference(state, F)
            self.op = None
            self.operator(state)
            self.n_reference_updates += 1
            self._F_after_step = None
        else:
            self._F_after_step = (op, state.x.copy(), F_ext)
        return state

    def _F_from_after_step(self, state: State, op: ReferenceOperator) -> np.ndarray | None:
        """The F of the last after_step if it belongs to this operator and these positions (used once)."""
        known, self._F_after_step = self._F_after_step, None
        if known is not None and known[0] is op and np.array_equal(known[1], state.x):
            return known[2]
        return None

    def diagnostics(self) -> dict:
        out = {"reference_updates": self.n_reference_updates,
               "n_pairs": int(self.op.n_pairs) if self.op is not None else 0,
               "degenerate_correction_particles": int(len(self.op.degenerate)) if self.op is not None else 0}
        if self.op is not None and self.op.ghosts is not None:
            out["n_ghosts"] = int(self.op.ghosts.n)
        out.update(self._common_diagnostics())
        return out


def _advance(state: State, rates: Rates, dt: float, evolved) -> State:
    new = replace(state)
    for name in evolved:
        setattr(new, name, getattr(state, name) + dt * getattr(rates, name))
    return new


def predictor_corrector_step(state: State, solver, dt: float) -> State:
    """One predictor-corrector step (two rate evaluations), then the solver's after-step work.

    Each stage ends with ``solver.finish_stage`` (walls, plastic return map; see :class:`_Solver`)."""
    r0 = solver.rates(state)
    half = solver.finish_stage(state, _advance(state, r0, 0.5 * dt, solver.evolved), r0, 0.5 * dt, final=False)
    half.t = state.t + 0.5 * dt
    r1 = solver.rates(half)
    new = solver.finish_stage(state, _advance(state, r1, dt, solver.evolved), r1, dt, final=True)
    new.t = state.t + dt
    return solver.after_step(new)


def cfl_time_step(state: State, material: ElasticMaterial, h: float, courant: float) -> float:
    """dt = courant * h / (c_L + max |v|)."""
    if not 0 < courant <= 1:
        raise ValueError(f"Courant number must lie in (0, 1], got {courant!r}")
    vmax = float(np.sqrt(np.max(np.einsum("ik,ik->i", state.v, state.v)))) if state.n else 0.0
    return courant * h / (material.c_longitudinal + vmax)
