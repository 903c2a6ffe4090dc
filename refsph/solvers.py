"""The two formulations as solvers (:class:`~refsph.integrate.Solver`): ESPH and TLSPH.

A solver is composed of the pieces the paper keeps apart, as LAMMPS's SMD package keeps pair styles, integration
fixes and material models apart:

* the rates of its formulation (:func:`refsph.esph.esph_rates`, :func:`refsph.tlsph.tlsph_rates`, and for TLSPH
  the pinball contact of :mod:`refsph.contact` with the rigid bodies);
* a :class:`~refsph.boundaries.Constraints` (rigid walls, rigid bodies, clamps and the reaction log) and, for
  symmetry, :class:`~refsph.boundaries.MirrorPlanes`;
* a strength model (:mod:`refsph.strength`: elastic, Johnson-Cook, modified Johnson-Cook, or a user's law).

At the end of every stage of a step (:func:`finish_stage`) the constraints act first (a kinematic
constraint), then the strength model's return map with the stage's strain rate. Only the final stage
(``final=True``) accumulates eps_p, W_p and T and the wall and tool impulses.
"""
from __future__ import annotations

import warnings

import numpy as np

from . import contact as _contact
from .boundaries import Constraints, Ghosts, MirrorPlanes
from .contact import PinballContact
from .esph import ESPHParams, esph_rates
from .material import ElasticMaterial, eos_pressure
from .neighbours import PairBlocks, VerletList, check_threads
from .state import Rates, State
from .strength import Elastic, StrengthModel, check_strength_fields, strength_stage
from .tensor import det
from .tlsph import ReferenceOperator, TLSPHParams, green_lagrange_norm, reference_update, tlsph_rates

__all__ = ["ESPHSolver", "TLSPHSolver", "finish_stage"]


def finish_stage(constraints: Constraints, strength: StrengthModel, material: ElasticMaterial, heating: bool,
                 old: State, new: State, rates: Rates, dt: float, final: bool) -> State:
    """Constraints, then the return map, on the state a stage produced (``new``, in place). ESPH integrates
    rho (``rates.rho`` is not None): its tools' density is floored at rho0 and the return map uses the new
    density; TLSPH's density is the one of the start of the step (Eq. (2), set after the step)."""
    esph = rates.rho is not None
    constraints.apply(old, new, dt, final, rho_floor=material.rho0 if esph else None)
    rho = new.rho if esph else old.rho
    return strength_stage(strength, old, new, rates.l, rho, dt, final, material.G, heating)


def _compose(solver, material: ElasticMaterial, params, strength: StrengthModel | None, heating: bool,
             mirror: MirrorPlanes | None, constraints: Constraints, threads: int) -> None:
    """The parts every solver is made of: material and parameters, strength model (None: elastic), heating switch,
    symmetry planes, constraints, threads."""
    solver.material, solver.params = material, params
    solver.strength = strength if strength is not None else Elastic()
    solver.heating = bool(heating)
    solver.mirror, solver.constraints = mirror, constraints
    solver.threads = check_threads(threads)


def _check_common(strength: StrengthModel, mirror: MirrorPlanes | None, constraints: Constraints,
                  state: State) -> None:
    check_strength_fields(strength, state)
    if mirror is not None:
        mirror.check(state.dim)
    constraints.bind(state)


class ESPHSolver:
    """ESPH rates with a Verlet pair list (cutoff 2h, skin ``skin_factor * h``; the scenes' value is
    ``Numerics.skin_factor``). With symmetry planes (``mirror``) the ghosts are chosen when the list is built
    (every particle within 2h + skin of a plane) and move with their sources until the next build. Rigid bodies
    are ordinary SPH neighbours (velocity V, density by Eq. (10) floored at rho0, stress -p I with p >= 0)."""

    method = "esph"
    evolved = ("x", "v", "rho", "S", "S_zz")

    def __init__(self, material: ElasticMaterial, params: ESPHParams, skin_factor: float, *,
                 strength: StrengthModel | None = None, heating: bool = True, mirror: MirrorPlanes | None = None,
                 walls=(), rigid=(), clamps=(), threads: int = 1):
        _compose(self, material, params, strength, heating, mirror, Constraints(walls, rigid, clamps, mirror),
                 threads)
        self.pairs = VerletList(params.kernel.support * params.h, skin_factor * params.h)
        self._pair_sum: PairBlocks | None = None           # blocks and sparse patterns of the current pair list
        self._pair_sum_build = -1
        self._ghosts: Ghosts | None = None
        self._ghost_constant: tuple | None = None          # extended (m, X, V0) of the current ghosts

    @property
    def h(self) -> float:
        return self.params.h

    def check_state(self, state: State) -> None:
        """The state fits the solver (ValueError naming what does not). Several deformable bodies are accepted
        with a warning: ESPH has no contact law between them, they are one continuum to the SPH sums."""
        _check_common(self.strength, self.mirror, self.constraints, state)
        if len(self.constraints.deformable_bodies) > 1:
            warnings.warn(f"ESPH has no contact between deformable bodies {self.constraints.deformable_bodies}: "
                          "within 2h they are one continuum to the SPH sums (pressure pushes them apart, tension "
                          "glues them and particles can change sides). TLSPH has the pinball contact.",
                          stacklevel=2)

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

    def rates(self, state: State, dt: float | None = None, out: dict | None = None, part: str = "all") -> Rates:
        """Eqs. (10)-(14), (23) over all particles, rigid ones included; constrained (``dt`` is not used).
        ``out``: a dict that receives the pair list (I, J) and the pressure p (Eq. (24)) of ``state``'s rows.
        ``part``: 'all', 'deformation' or 'forces' (:func:`~refsph.esph.esph_rates`; the leapfrog's halves)."""
        if self.constraints.dim is None:
            self.constraints.bind(state)
        (I, J), ext = self._pairs_and_state(state)
        if self._pair_sum_build != self.pairs.n_builds:
            if self._pair_sum is not None:
                self._pair_sum.close()
            self._pair_sum = PairBlocks(I, J, ext.n, threads=self.threads)
            self._pair_sum_build = self.pairs.n_builds
        r = esph_rates(ext, self.material, self.params, I, J, pairs=self._pair_sum, part=part)
        r = r if ext is state else r.rows(state.n)
        if out is not None:
            out.update(I=I, J=J, p=eos_pressure(state.rho, self.material.rho0, self.material.K))
        return self.constraints.constrain(state, r, record=part != "deformation")

    def finish_stage(self, old: State, new: State, rates: Rates, dt: float, final: bool) -> State:
        return finish_stage(self.constraints, self.strength, self.material, self.heating, old, new, rates, dt, final)

    def after_step(self, state: State) -> State:
        return state

    def deformation_gradient(self, state: State) -> None:
        """ESPH has no deformation gradient."""
        return None

    def checkpoint(self) -> dict:
        """What a restart needs besides the state: the positions the Verlet list was built at (the list and its
        ghosts follow from them), the counters, the constraints' log."""
        ck = {f"constraints/{k}": v for k, v in self.constraints.checkpoint().items()}
        ck["n_builds"] = np.int64(self.pairs.n_builds)
        if self.pairs._x_build is not None:
            ck["x_build"] = self.pairs._x_build
        return ck

    def restore(self, ck: dict, state: State) -> None:
        """Continue from a :meth:`checkpoint` at ``state`` exactly as the uninterrupted run would."""
        self.check_state(state)
        self.constraints.restore({k.split("/", 1)[1]: v for k, v in ck.items() if k.startswith("constraints/")})
        if "x_build" in ck:
            x_build = np.array(ck["x_build"])
            if self.mirror is None:
                self.pairs.build(x_build)
            else:
                self._ghosts = self.mirror.ghosts(x_build, self.pairs.cutoff + self.pairs.skin)
                self._ghost_constant = self._ghosts.extend_constant(state)
                I, J = self.pairs.build(self._ghosts.extend_vectors(x_build), track=x_build)
                keep = I < state.n
                self.pairs.I, self.pairs.J = I[keep], J[keep]
        self.pairs.n_builds = int(ck["n_builds"])
        self._pair_sum_build = -1

    def reaction_history(self) -> dict:
        return self.constraints.reaction_history()

    def diagnostics(self) -> dict:
        out = {"neighbour_list_builds": self.pairs.n_builds, "n_pairs": int(len(self.pairs.I))}
        if self._ghosts is not None:
            out["n_ghosts"] = int(self._ghosts.n)
        out.update(self.constraints.diagnostics())
        return out


class TLSPHSolver:
    """TLSPH rates with a fixed sparse operator, rebuilt at reference-configuration updates. With symmetry
    planes the ghosts are the mirror images of the reference configuration (fixed with the operator); a
    ghost's F is the mirror image of its source's. With rigid bodies the operator covers the deformable rows
    only, and the bodies meet through the pinball ``contact`` (:mod:`refsph.contact`; ``dp`` gives the 2D
    force per unit thickness)."""

    method = "tlsph"
    evolved = ("x", "v", "S", "S_zz")

    def __init__(self, material: ElasticMaterial, params: TLSPHParams, *, strength: StrengthModel | None = None,
                 heating: bool = True, mirror: MirrorPlanes | None = None, walls=(), rigid=(), clamps=(),
                 contact: PinballContact | None = None, dp: float | None = None, threads: int = 1):
        _compose(self, material, params, strength, heating, mirror, Constraints(walls, rigid, clamps, mirror),
                 threads)
        if self.constraints.rigid and contact is None:
            raise ValueError("TLSPH with rigid bodies needs a contact model (PinballContact)")
        self.n_body_contacts = 0
        if contact is not None and not (dp is not None and dp > 0):
            raise ValueError("the pinball contact needs the particle spacing dp (2D: force per unit thickness)")
        self.dp, self.contact = dp, contact
        self.max_penetration = 0.0
        self.n_contacts = 0
        self.friction_power: tuple | None = None           # (deformable rows, rigid rows) [W], last contact
        self.op: ReferenceOperator | None = None
        self._ghost_constant: tuple | None = None          # extended (m, X, V0) of the operator's ghosts
        self._constant: tuple | None = None                # (whole m, X, V0) -> their deformable rows (views)
        self.n_reference_updates = 0
        self._cache_counts = [0, 0]                        # momentum-sum cache hits, misses of dropped operators
        self._F_after_step: tuple | None = None            # (operator, x, F) of the last after_step (a cache)

    @property
    def h(self) -> float:
        return self.params.h

    def operator(self, body: State) -> ReferenceOperator:
        """The sparse operator of the current reference configuration of the deformable rows ``body``."""
        if self.op is None:
            p = self.params
            ids = body.body if len(self.constraints.deformable_bodies) > 1 else None
            if self.mirror is None:
                self.op = ReferenceOperator(body.X, body.V0, p.h, p.kernel, p.corrected, threads=self.threads,
                                            body=ids)
            else:
                g = self.mirror.ghosts(body.X, p.kernel.support * p.h)
                self._ghost_constant = g.extend_constant(body)   # m, X, V0: fixed with the operator
                _, X, V0 = self._ghost_constant
                self.op = ReferenceOperator(X, V0, p.h, p.kernel, p.corrected, ghosts=g, threads=self.threads,
                                            body=ids)
        return self.op

    def _extended(self, body: State, op: ReferenceOperator) -> State:
        return body if op.ghosts is None else op.ghosts.extend_state(body, self._ghost_constant)

    def _F(self, ext: State, op: ReferenceOperator) -> np.ndarray:
        """Eq. (18) on the (extended) state; ghost rows are the mirror images of their sources'."""
        F = op.deformation_gradient(ext.x)
        g = op.ghosts
        if g is not None:
            F = np.array(F)
            F[g.n_real:] = g.tensors(F[:g.n_real])
        return F

    def check_state(self, state: State) -> None:
        """The state fits the solver (ValueError naming what does not); TLSPH computes rho = m / (J V0)
        (Eq. (2)) and refuses a state whose rho says otherwise (an initial pressure it would silently drop). J is
        1 in the reference configuration (every x = X) and det F of the operator otherwise."""
        _check_common(self.strength, self.mirror, self.constraints, state)
        if len(self.constraints.deformable_bodies) > 1 and self.contact is None:
            raise ValueError(f"deformable bodies {self.constraints.deformable_bodies} meet only through the pinball "
                             "contact: give the solver a PinballContact (refsph.simulate.make_solver does)")
        if self.contact is not None and self.contact.friction is not None and state.T is None:
            raise ValueError("friction with mu(T) needs a state with temperatures (make_state(..., T0=...))")
        body = self._deformable(state)
        J = np.ones(body.n)                     # the reference configuration itself: J = 1 (by definition)
        if np.any(body.x != body.X):            # a deformed start: the J the operator gives (Eq. (18))
            op = self.operator(body)
            J = det(self._F(self._extended(body, op), op)[:body.n])
        rho = body.m / (J * body.V0)
        if not np.allclose(body.rho, rho, rtol=1e-8, atol=0.0):
            k = int(np.argmax(np.abs(body.rho - rho)))
            raise ValueError(f"TLSPH takes the density from m / (J V0) (Eq. (2)) and does not read State.rho: "
                             f"particle {k} has rho = {body.rho[k]:.6g}, m / (J V0) = {rho[k]:.6g} kg/m^3. An "
                             "initial pressure needs ESPH, or an initial deformation (x != X) in TLSPH")

    @staticmethod
    def _with_identity(F: np.ndarray, state: State) -> np.ndarray:
        """F of the deformable rows extended to every row of ``state`` (rigid rows: F = I)."""
        if len(F) == state.n:
            return F
        out = np.broadcast_to(np.eye(state.dim), (state.n, state.dim, state.dim)).copy()
        out[:len(F)] = F
        return out

    def _deformable(self, state: State) -> State:
        """The deformable rows [0, n_deformable) as a state of views (the whole state if there is no tool). The
        views of the constant fields m, X, V0 are made once per array, so that what the operator caches per
        array (the momentum sum's sum_j m_j grad W) stays valid from one evaluation to the next."""
        if self.constraints.dim is None:
            self.constraints.bind(state)
        n = self.constraints.n_deformable
        if n == state.n:
            return state
        whole = (state.m, state.X, state.V0)
        if self._constant is None or any(a is not b for a, b in zip(whole, self._constant[0])):
            self._constant = (whole, tuple(a[:n] for a in whole))
        m, X, V0 = self._constant[1]
        part = {name: (None if a is None else a[:n]) for name, a in
                (("x", state.x), ("v", state.v), ("rho", state.rho), ("S", state.S), ("S_zz", state.S_zz),
                 ("eps_p", state.eps_p), ("eps_dot_p", state.eps_dot_p), ("W_p", state.W_p), ("T", state.T),
                 ("body", state.body))}
        return State(m=m, X=X, V0=V0, t=state.t, **part)

    def rates(self, state: State, dt: float, out: dict | None = None, part: str = "all") -> Rates:
        """Eqs. (16)-(23) on the deformable body; with rigid bodies, the pinball contact (Eqs. (32)-(36)) for a
        step of size ``dt`` (Eq. (34)). ``out``: a dict that receives F, J, P, l, rho, p of the deformable rows
        (:func:`~refsph.tlsph.tlsph_rates`) and the operator's half pairs (I, J). ``part``: 'all', 'deformation'
        (stress rates) or 'forces' (dv/dt, contact included): the leapfrog's halves."""
        body = self._deformable(state)
        op = self.operator(body)
        ext = self._extended(body, op)
        F = self._F_from_after_step(body, op)
        if F is None:
            F = self._F(ext, op)
        r = tlsph_rates(ext, self.material, self.params, op, F=F, out=out, part=part)
        r = r if ext is body else r.rows(body.n)
        if out is not None:
            out.update({k: (None if out[k] is None else out[k][:body.n]) for k in ("F", "J", "P", "l", "rho", "p")},
                       I=op.I, J=op.J)
        if part != "deformation" and len(self.constraints.deformable_bodies) > 1:
            r.v = r.v + self._body_contact(body, dt)
        if body is not state:
            r = self._with_rigid(state, r, dt, contact=part != "deformation")
        return self.constraints.constrain(state, r, record=part != "deformation")

    def _with_rigid(self, state: State, r: Rates, dt: float, contact: bool = True) -> Rates:
        """Rates of all rows: the deformable ones plus the pinball contact (``contact``), the rigid ones carrying
        the reaction (dv/dt = contact force / m, turned into the recorded force and then zeroed by the
        constraints)."""
        n, N, d = self.constraints.n_deformable, state.n, state.dim
        v = np.zeros((N, d))
        v[:n] = r.v
        if contact:
            c = self._contact(state, dt)
            v[:n] += c.a
            v[n:] = c.force_on_b / state.m[n:, None]
        S = np.zeros((N, d, d))
        S[:n] = r.S
        S_zz = np.zeros(N)
        S_zz[:n] = r.S_zz
        l = None
        if r.l is not None:
            l = np.zeros((N, d, d))
            l[:n] = r.l
        return Rates(x=state.v.copy(), v=v, rho=None, S=S, S_zz=S_zz, l=l)

    def _body_contact(self, body: State, dt: float) -> np.ndarray:
        """dv/dt of the deformable rows from the pinball contact (Eqs. (32)-(36)) between every two of their
        bodies (each pair of bodies once; equal and opposite forces, both sides deformable)."""
        if not (dt is not None and dt > 0):
            raise ValueError(f"the pinball contact needs the step size dt > 0 (Eq. (34)), got {dt!r}")
        acc = np.zeros_like(body.x)
        ids = self.constraints.deformable_bodies
        rows = [np.flatnonzero(body.body == b) for b in ids]
        G, R = self.material.G, self.contact.k * self.params.h
        n_contacts, thickness = 0, self.dp if body.dim == 2 else 1.0
        for k, ra in enumerate(rows):
            for rb in rows[k + 1:]:
                c = _contact.pinball_contact(body.x[ra], body.v[ra], body.m[ra], body.x[rb], body.v[rb], body.m[rb],
                                             R, G, G, dt, self.contact, thickness=thickness,
                                             T_a=None if body.T is None else body.T[ra])
                acc[ra] += c.a
                acc[rb] += c.force_on_b / body.m[rb, None]
                self.max_penetration = max(self.max_penetration, c.max_penetration)
                n_contacts += c.n_contacts
        self.n_body_contacts = n_contacts
        return acc

    def _contact(self, state: State, dt: float):
        """The pinball contact (Eqs. (32)-(36)) of the deformable rows with the rigid ones, for a step dt."""
        if not (dt is not None and dt > 0):
            raise ValueError(f"the pinball contact needs the step size dt > 0 (Eq. (34)), got {dt!r}")
        n, d = self.constraints.n_deformable, state.dim
        c = _contact.pinball_contact(state.x[:n], state.v[:n], state.m[:n], state.x[n:], state.v[n:], np.inf,
                                     self.contact.k * self.params.h, self.material.G, np.inf, dt, self.contact,
                                     thickness=self.dp if d == 2 else 1.0,
                                     T_a=None if state.T is None else state.T[:n])
        self.max_penetration = max(self.max_penetration, c.max_penetration)
        self.n_contacts = c.n_contacts
        self.friction_power = (c.friction_power_a, c.friction_power_b)   # the frictional heat (refsph.thermal)
        return c

    def finish_stage(self, old: State, new: State, rates: Rates, dt: float, final: bool) -> State:
        return finish_stage(self.constraints, self.strength, self.material, self.heating, old, new, rates, dt, final)

    def deformation_gradient(self, state: State) -> np.ndarray:
        """Eq. (18) for every row (rigid rows: I)."""
        body = self._deformable(state)
        op = self.operator(body)
        return self._with_identity(self._F(self._extended(body, op), op)[:body.n], state)

    def after_step(self, state: State) -> State:
        """rho = m / (J V0) (Eq. (2)); reference update (:func:`~refsph.tlsph.reference_update`) when
        max |E| > ref_update_strain.

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
            state = reference_update(state, self._with_identity(F, state))
            self._drop_operator()
            self.operator(self._deformable(state))
            self.n_reference_updates += 1
            self._F_after_step = None
        else:
            self._F_after_step = (op, body.x.copy(), F_ext)
        return state

    def checkpoint(self) -> dict:
        """What a restart needs besides the state (the operator follows from X and V0): counters, the log."""
        ck = {f"constraints/{k}": v for k, v in self.constraints.checkpoint().items()}
        ck.update(n_reference_updates=np.int64(self.n_reference_updates),
                  cache_counts=np.array(self._cache_counts, dtype=np.int64),
                  max_penetration=np.float64(self.max_penetration), n_contacts=np.int64(self.n_contacts))
        return ck

    def restore(self, ck: dict, state: State) -> None:
        """Continue from a :meth:`checkpoint` at ``state`` exactly as the uninterrupted run would."""
        self.check_state(state)
        self.constraints.restore({k.split("/", 1)[1]: v for k, v in ck.items() if k.startswith("constraints/")})
        self.n_reference_updates = int(ck["n_reference_updates"])
        self._cache_counts = [int(c) for c in ck["cache_counts"]]
        self.max_penetration, self.n_contacts = float(ck["max_penetration"]), int(ck["n_contacts"])

    def _drop_operator(self) -> None:
        self._cache_counts[0] += self.op.momentum_cache_hits
        self._cache_counts[1] += self.op.momentum_cache_misses
        self.op.pairs.close()
        self.op = None

    def _F_from_after_step(self, body: State, op: ReferenceOperator) -> np.ndarray | None:
        """The F of the last after_step if it belongs to this operator and these positions (used once)."""
        known, self._F_after_step = self._F_after_step, None
        if known is not None and known[0] is op and np.array_equal(known[1], body.x):
            return known[2]
        return None

    def reaction_history(self) -> dict:
        return self.constraints.reaction_history()

    def diagnostics(self) -> dict:
        op = self.op
        hits, misses = self._cache_counts
        if op is not None:
            hits, misses = hits + op.momentum_cache_hits, misses + op.momentum_cache_misses
        out = {"reference_updates": self.n_reference_updates,
               "n_pairs": int(op.n_pairs) if op is not None else 0,
               "degenerate_correction_particles": int(len(op.degenerate)) if op is not None else 0,
               "momentum_sum_cache": {"hits": hits, "misses": misses}}
        if op is not None and op.ghosts is not None:
            out["n_ghosts"] = int(op.ghosts.n)
        if self.contact is not None:
            out["max_pinball_penetration_m"] = self.max_penetration
            out["pinball_contacts_last_step"] = self.n_contacts
            if len(self.constraints.deformable_bodies) > 1:
                out["pinball_contacts_between_bodies_last_step"] = self.n_body_contacts
        out.update(self.constraints.diagnostics())
        return out
