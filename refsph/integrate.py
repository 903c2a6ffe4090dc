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

from dataclasses import fields, replace

import numpy as np

from .esph import ESPHParams, Rates, esph_rates
from .material import ElasticMaterial
from .neighbours import PairBlocks, VerletList
from .state import State
from .tensor import det
from .boundaries import Ghosts, MirrorPlanes
from .contact import PinballContact, pinball_contact
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

    def _init_common(self, material, plasticity, mirror, walls, rigid=(), clamps=()):
        self.material = material
        self.plasticity = plasticity
        self.mirror = mirror
        self.walls = tuple(walls or ())
        self.wall_impulse = np.zeros(len(self.walls))
        self.rigid = tuple(rigid or ())
        self.clamps = tuple(clamps or ())
        names = [b.name for b in self.rigid] + [c.name for c in self.clamps]
        if len(set(names)) != len(names):
            raise ValueError(f"rigid bodies and clamps need distinct names, got {names}")
        for name in names:
            if name in ("t", "dt") or not name or not all(ch.isalnum() or ch in "_-" for ch in name):
                raise ValueError(f"rigid body / clamp name {name!r}: use letters, digits, '_' or '-' "
                                 "(not 't' or 'dt', the time columns of the reaction log)")
        ids = [b.body for b in self.rigid]
        if len(set(ids)) != len(ids):
            raise ValueError(f"rigid bodies need distinct body ids, got {ids}")
        if self.rigid and mirror is not None:
            raise ValueError("rigid bodies together with symmetry planes are not implemented")
        if self.rigid and self.walls:
            raise ValueError("rigid bodies together with RigidWall are not implemented (make the wall a rigid "
                             "body of particles)")
        self.dt: float | None = None           # size of the step being taken (set by predictor_corrector_step)
        self.n_deformable: int | None = None   # rows [0, n_deformable) are deformable, the rest rigid
        self.dim: int | None = None            # of the state bound (with n_deformable)
        self._rigid_rows: list[slice] = []
        self._reaction: list[np.ndarray] | None = None     # force on each rigid body / clamp, last evaluation
        self.reaction_log: list[list[float]] = []          # per step: t_mid, dt, then d components per body/clamp
        self.reaction_impulse = [0.0 for _ in names]

    @property
    def reaction_names(self) -> list[str]:
        """Names of the rigid bodies and clamps, in the order of the reaction log."""
        return [b.name for b in self.rigid] + [c.name for c in self.clamps]

    def check_state(self, state: State) -> None:
        """The state fits the solver: the Johnson-Cook fields where plasticity is on, boundaries in its
        dimension, rigid bodies as trailing rows of their body id, clamps on deformable particles (ValueError
        otherwise)."""
        self._check_plastic(state)
        for w in self.walls:
            w.check(state.dim)
        if self.mirror is not None:
            self.mirror.check(state.dim)
        self._bind_bodies(state)

    def _check_plastic(self, state: State) -> None:
        if self.plasticity is not None and not state.plastic:
            raise ValueError("a Johnson-Cook material needs a state with eps_p, eps_dot_p, W_p and T "
                             "(make_state(..., T0=room temperature))")

    def _bind_bodies(self, state: State) -> None:
        n = state.n
        self.dim = state.dim
        if not self.rigid:
            self.n_deformable, self._rigid_rows = n, []
        else:
            if state.body is None:
                raise ValueError("rigid bodies need State.body (the body id of every particle)")
            rows = []
            for b in self.rigid:
                b.check(state.dim)
                idx = np.flatnonzero(state.body == b.body)
                if len(idx) == 0:
                    raise ValueError(f"rigid body {b.name!r}: no particle has body id {b.body}")
                if idx[-1] - idx[0] + 1 != len(idx):
                    raise ValueError(f"rigid body {b.name!r}: its particles must be consecutive rows")
                rows.append(slice(int(idx[0]), int(idx[-1]) + 1))
            n_def = min(r.start for r in rows)
            if sum(r.stop - r.start for r in rows) != n - n_def:
                raise ValueError("rigid body particles must come after every deformable particle in the state")
            for b, r in zip(self.rigid, rows):
                if not np.all(state.v[r] == np.asarray(b.velocity)):
                    raise ValueError(f"rigid body {b.name!r}: its particles must start with its velocity "
                                     f"{b.velocity}")
            self.n_deformable, self._rigid_rows = n_def, rows
        if state.body is not None and np.any(state.body[:self.n_deformable] != 0):
            other = sorted(set(np.unique(state.body[:self.n_deformable]).tolist()) - {0})
            raise ValueError(f"body ids {other} are not declared as rigid bodies; the deformable workpiece is "
                             "body 0 (a second deformable body is not implemented)")
        for c in self.clamps:
            if c.index[-1] >= self.n_deformable:
                raise ValueError(f"clamp {c.name!r} holds particle {c.index[-1]}, which is not a deformable one")

    def _constrain(self, state: State, r: Rates) -> Rates:
        """Prescribed motion on the rates: rigid rows move with their velocity (dv/dt = 0, no stress rate),
        clamped rows stay (dx/dt = dv/dt = 0). The force on each body / clamp is kept first: sum m dv/dt over
        its rows of the unconstrained rates (pairs inside one body cancel), i.e. what the rest exerts on it."""
        if not self.rigid and not self.clamps:
            return r
        forces = []
        for b, rows in zip(self.rigid, self._rigid_rows):
            forces.append(np.sum(state.m[rows, None] * r.v[rows], axis=0))
            r.v[rows] = 0.0
            r.x[rows] = np.asarray(b.velocity)
            r.S[rows] = 0.0
            r.S_zz[rows] = 0.0
        for c in self.clamps:
            forces.append(np.sum(state.m[c.index, None] * r.v[c.index], axis=0))
            r.v[c.index] = 0.0
            r.x[c.index] = 0.0
        self._reaction = forces
        return r

    def finish_stage(self, old: State, new: State, rates: Rates, dt: float, final: bool) -> State:
        for k, wall in enumerate(self.walls):
            imp = wall.apply(new, dt)
            if final:
                self.wall_impulse[k] += imp
        for b, rows in zip(self.rigid, self._rigid_rows):       # exact rigid motion (no drift from round-off)
            new.v[rows] = np.asarray(b.velocity)
            if rates.rho is not None:                            # ESPH: the tool's own pressure is >= 0
                new.rho[rows] = np.maximum(new.rho[rows], self.material.rho0)
        for c in self.clamps:
            new.v[c.index] = 0.0
            new.x[c.index] = old.x[c.index]
        if final and self._reaction is not None:
            self.reaction_log.append([old.t + 0.5 * dt, dt] + [float(c) for f in self._reaction for c in f])
            for k, f in enumerate(self._reaction):
                self.reaction_impulse[k] = self.reaction_impulse[k] + f * dt
        jc = self.plasticity
        if jc is not None:
            self._check_plastic(old)
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

    def reaction_history(self) -> dict:
        """{'t': (n_steps,), 'dt': (n_steps,), name: (n_steps, d) force on that rigid body / clamp} (N; 2D: N per
        metre of thickness), one row per step at the step's midpoint t (the time of the rates that moved it);
        dt is the step's size, so sum(F dt) is the impulse."""
        names = self.reaction_names
        if not names or self.dim is None:
            return {}
        d = self.dim
        log = np.asarray(self.reaction_log, dtype=float).reshape(-1, 2 + d * len(names))
        out = {"t": log[:, 0], "dt": log[:, 1]}
        for k, name in enumerate(names):
            out[name] = log[:, 2 + k * d: 2 + (k + 1) * d]
        return out

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
        if self.reaction_names:
            # impulse the rest of the system gave each rigid body / clamp, N s (2D: N s/m); note the sign
            # convention differs from wall_impulse, which is the impulse the wall gave the model
            out["reaction_impulse"] = {name: [float(c) for c in np.atleast_1d(imp)]
                                       for name, imp in zip(self.reaction_names, self.reaction_impulse)}
        return out


class ESPHSolver(_Solver):
    """ESPH rates with a Verlet pair list (cutoff 2h, skin ``skin_factor * h``; the scenes' value is
    ``Numerics.skin_factor``). With symmetry planes (``mirror``) the ghosts are chosen when the list is built
    (every particle within 2h + skin of a plane) and move with their sources until the next build."""

    method = "esph"
    evolved = ("x", "v", "rho", "S", "S_zz")

    def __init__(self, material: ElasticMaterial, params: ESPHParams, skin_factor: float, *,
                 plasticity: JohnsonCook | None = None, mirror: MirrorPlanes | None = None, walls=(),
                 rigid=(), clamps=(), threads: int = 1):
        self._init_common(material, plasticity, mirror, walls, rigid, clamps)
        self.params = params
        self.threads = _check_threads(threads)
        self.pairs = VerletList(params.kernel.support * params.h, skin_factor * params.h)
        self._pair_sum: PairBlocks | None = None           # blocks and sparse patterns of the current pair list
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
        """Eqs. (10)-(14), (23) over all particles, rigid ones included (they are ordinary SPH neighbours:
        velocity V, density by Eq. 10 floored at rho0, stress -p I with p = K (rho/rho0 - 1) >= 0)."""
        if self.n_deformable is None:
            self._bind_bodies(state)
        (I, J), ext = self._pairs_and_state(state)
        if self._pair_sum_build != self.pairs.n_builds:
            if self._pair_sum is not None:
                self._pair_sum.close()
            self._pair_sum = PairBlocks(I, J, ext.n, threads=self.threads)
            self._pair_sum_build = self.pairs.n_builds
        r = esph_rates(ext, self.material, self.params, I, J, pairs=self._pair_sum)
        r = r if ext is state else self._real_rows(r, state.n)
        return self._constrain(state, r)

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
    ghost's F is the mirror image of its source's. With rigid bodies the operator covers the deformable rows
    only, and the bodies meet through the pinball ``contact`` (:mod:`refsph.contact`; ``dp`` gives the 2D
    force per unit thickness)."""

    method = "tlsph"
    evolved = ("x", "v", "S", "S_zz")

    def __init__(self, material: ElasticMaterial, params: TLSPHParams, *, plasticity: JohnsonCook | None = None,
                 mirror: MirrorPlanes | None = None, walls=(), rigid=(), clamps=(),
                 contact: PinballContact | None = None, dp: float | None = None, threads: int = 1):
        self._init_common(material, plasticity, mirror, walls, rigid, clamps)
        self.threads = _check_threads(threads)
        if self.rigid and contact is None:
            raise ValueError("TLSPH with rigid bodies needs a contact model (PinballContact)")
        if contact is not None and not (dp is not None and dp > 0):
            raise ValueError("the pinball contact needs the particle spacing dp (2D: force per unit thickness)")
        self.dp = dp
        self.params = params
        self.contact = contact
        self.max_penetration = 0.0
        self.n_contacts = 0
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
                self.op = ReferenceOperator(state.X, state.V0, p.h, p.kernel, p.corrected, threads=self.threads)
            else:
                g = self.mirror.ghosts(state.X, p.kernel.support * p.h)
                self._ghost_constant = g.extend_constant(state)   # m, X, V0: fixed with the operator
                _, X, V0 = self._ghost_constant
                self.op = ReferenceOperator(X, V0, p.h, p.kernel, p.corrected, ghosts=g, threads=self.threads)
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

    def check_state(self, state: State) -> None:
        super().check_state(state)
        if self.contact is not None and self.contact.friction is not None and state.T is None:
            raise ValueError("friction with mu(T) needs a state with temperatures (make_state(..., T0=...))")

    @staticmethod
    def _with_identity(F: np.ndarray, state: State) -> np.ndarray:
        """F of the deformable rows extended to every row of ``state`` (rigid rows: F = I)."""
        if len(F) == state.n:
            return F
        out = np.broadcast_to(np.eye(state.dim), (state.n, state.dim, state.dim)).copy()
        out[:len(F)] = F
        return out

    def _deformable(self, state: State) -> State:
        """The deformable rows [0, n_deformable) as a state of views (the whole state if there is no tool)."""
        if self.n_deformable is None:
            self._bind_bodies(state)
        n = self.n_deformable
        if n == state.n:
            return state
        return State(**{f.name: (getattr(state, f.name)[:n] if isinstance(getattr(state, f.name), np.ndarray)
                                 else getattr(state, f.name)) for f in fields(State)})

    def rates(self, state: State) -> Rates:
        """Eqs. (16)-(23) on the deformable body; with rigid bodies, the pinball contact (Eqs. 32-36)."""
        body = self._deformable(state)
        op = self.operator(body)
        ext = self._extended(body, op)
        F = self._F_from_after_step(body, op)
        if F is None:
            F = self._F(ext, op)
        r = tlsph_rates(ext, self.material, self.params, op, F=F)
        r = r if ext is body else self._real_rows(r, body.n)
        if body is not state:
            r = self._with_rigid(state, r)
        return self._constrain(state, r)

    def _with_rigid(self, state: State, r: Rates) -> Rates:
        """Rates of all rows: the deformable ones plus the pinball contact, the rigid ones carrying the reaction
        (dv/dt = contact force / m, turned into the recorded force and then zeroed by ``_constrain``)."""
        if self.dt is None:
            raise ValueError("the pinball contact needs the step size (solver.dt; set by predictor_corrector_step)")
        n, N, d = self.n_deformable, state.n, state.dim
        R = self.contact.k * self.params.h
        c = pinball_contact(state.x[:n], state.v[:n], state.m[:n], state.x[n:], state.v[n:], np.inf, R,
                            self.material.G, np.inf, self.dt, self.contact,
                            thickness=self.dp if d == 2 else 1.0,
                            T_a=None if state.T is None else state.T[:n])
        self.max_penetration = max(self.max_penetration, c.max_penetration)
        self.n_contacts = c.n_contacts
        v = np.empty((N, d))
        v[:n] = r.v + c.a
        v[n:] = c.force_on_b / state.m[n:, None]
        S = np.zeros((N, d, d))
        S[:n] = r.S
        S_zz = np.zeros(N)
        S_zz[:n] = r.S_zz
        l = np.zeros((N, d, d))
        l[:n] = r.l
        return Rates(x=state.v.copy(), v=v, rho=None, S=S, S_zz=S_zz, l=l)

    def deformation_gradient(self, state: State) -> np.ndarray:
        body = self._deformable(state)
        op = self.operator(body)
        return self._with_identity(self._F(self._extended(body, op), op)[:body.n], state)

    def after_step(self, state: State) -> State:
        """rho = m / (J V0) (Eq. 2); reference update when max |E| > ref_update_strain.

        The F computed here is kept for the first rate evaluation of the next step, which starts from this
        very configuration (it is used only if x is unchanged, checked element by element)."""
        body = self._deformable(state)
        op = self.operator(body)
        F_ext = self._F(self._extended(body, op), op)
        F = F_ext[:body.n]
        rho = state.rho.copy()                  # (not in place: rho is not evolved, so shared with the old state)
        rho[:body.n] = body.m / (det(F) * body.V0)
        state.rho = rho
        thr = self.params.ref_update_strain
        if thr is not None and float(np.max(green_lagrange_norm(F))) > thr:
            state = reset_reference(state, self._with_identity(F, state))
            self.op.pairs.close()
            self.op = None
            self.operator(self._deformable(state))
            self.n_reference_updates += 1
            self._F_after_step = None
        else:
            self._F_after_step = (op, body.x.copy(), F_ext)
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
        if self.contact is not None:
            out["max_pinball_penetration_m"] = self.max_penetration
            out["pinball_contacts_last_step"] = self.n_contacts
        out.update(self._common_diagnostics())
        return out


def _check_threads(threads) -> int:
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ValueError(f"threads must be a whole number >= 1, got {threads!r}")
    return int(threads)


def _advance(state: State, rates: Rates, dt: float, evolved) -> State:
    new = replace(state)
    for name in evolved:
        setattr(new, name, getattr(state, name) + dt * getattr(rates, name))
    return new


def predictor_corrector_step(state: State, solver, dt: float) -> State:
    """One predictor-corrector step (two rate evaluations), then the solver's after-step work.

    Each stage ends with ``solver.finish_stage`` (walls, plastic return map; see :class:`_Solver`)."""
    solver.dt = dt
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
