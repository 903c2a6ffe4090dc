"""The two formulations as solvers (:class:`~refsph.integrate.Solver`): ESPH and TLSPH.

A solver is composed of the pieces the paper keeps apart, as LAMMPS's SMD package keeps pair styles, integration
fixes and material models apart:

* the rates of its formulation (:func:`refsph.esph.esph_rates`, :func:`refsph.tlsph.tlsph_rates`; for TLSPH the
  reference configuration, :class:`refsph.reference.ReferenceConfiguration`, and the pinball contact of its bodies,
  :class:`refsph.coupling.PinballCoupling`; for either, the penalty tool contact,
  :class:`refsph.coupling.PenaltyCoupling`);
* a :class:`~refsph.boundaries.Constraints` (rigid walls, rigid bodies, clamps and the reaction log) and, for
  symmetry, :class:`~refsph.boundaries.MirrorPlanes`;
* a strength model (:mod:`refsph.strength`: elastic, Johnson-Cook, modified Johnson-Cook, or a user's law; whether
  plastic work heats is the law's own switch).

What both share is :class:`SolverBase`: the smoothing length, the end of a stage (the constraints act first, a
kinematic constraint, then the strength model's return map with the stage's strain rate; only the final stage,
``final=True``, accumulates eps_p, W_p and T and the wall and tool impulses), the reaction log, and the restart
checkpoint's layout (the constraints' arrays under ``constraints/``).
"""
from __future__ import annotations

import warnings

import numpy as np

from .boundaries import Constraints, Ghosts, MirrorPlanes
from .contact import PinballContact
from .coupling import PenaltyCoupling, PinballCoupling
from .esph import ESPHParams, esph_rates
from .material import ElasticMaterial, eos_pressure
from .neighbours import PairBlocks, VerletList, check_threads
from .penalty import PenaltyContact
from .reference import ReferenceConfiguration, with_identity
from .self_contact import contact_distance, self_contact_acceleration
from .state import Rates, State
from .strength import Elastic, StrengthModel, check_strength_fields, strength_stage
from .tensor import det
from .tlsph import TLSPHParams, tlsph_rates

__all__ = ["SolverBase", "ESPHSolver", "TLSPHSolver"]

CONSTRAINTS = "constraints/"            # the constraints' arrays in a solver's checkpoint


class SolverBase:
    """What ESPH and TLSPH share (module text). A subclass sets ``method`` and ``evolved``, gives ``rates``,
    ``after_step``, ``deformation_gradient`` and ``check_state``, and may add to the checkpoint
    (:meth:`own_checkpoint`, :meth:`own_restore`) and the diagnostics (:meth:`own_diagnostics`)."""

    method: str
    evolved: tuple
    contact = None                                        # the tool contact, where the method has one

    def __init__(self, material: ElasticMaterial, params, strength: StrengthModel | None,
                 mirror: MirrorPlanes | None, constraints: Constraints, threads: int):
        self.material, self.params = material, params
        self.strength = strength if strength is not None else Elastic()
        self.mirror, self.constraints = mirror, constraints
        self.threads = check_threads(threads)

    @property
    def h(self) -> float:
        return self.params.h

    def check_common(self, state: State) -> None:
        """The strength model's fields, the symmetry planes and the constraints against ``state``; a tool contact
        with friction mu(T) needs the state's temperatures."""
        check_strength_fields(self.strength, state)
        if self.mirror is not None:
            self.mirror.check(state.dim)
        self.constraints.bind(state)
        if self.contact is not None and self.contact.friction is not None and state.T is None:
            raise ValueError("friction with mu(T) needs a state with temperatures (make_state(..., T0=...))")

    def stage_density(self, old: State, new: State) -> np.ndarray:
        """The density the return map of a stage uses (TLSPH: the start of the step's, Eq. (2))."""
        return old.rho

    def finish_stage(self, old: State, new: State, rates: Rates, dt: float, final: bool) -> State:
        """Constraints, then the return map, on the state a stage produced (``new``, in place)."""
        self.constraints.apply(old, new, dt, final)
        return strength_stage(self.strength, old, new, rates.l, self.stage_density(old, new), dt, final,
                              self.material.G)

    def reaction_history(self) -> dict:
        return self.constraints.reaction_history()

    def step_gain(self, state: State) -> float:
        """What the CFL step is divided by under ``Numerics.gain_step`` (1 here; TLSPH: its gradient's gain)."""
        return 1.0

    def critical_step(self, state: State) -> float:
        """The step ``Numerics.frequency_step`` is a fraction of (no limit here; TLSPH: 2 / w_max)."""
        return float("inf")

    def checkpoint(self) -> dict:
        """What a restart needs besides the state: the constraints' log and the solver's own counters."""
        ck = {CONSTRAINTS + k: v for k, v in self.constraints.checkpoint().items()}
        ck.update(self.own_checkpoint())
        return ck

    def restore(self, ck: dict, state: State) -> None:
        """Continue from a :meth:`checkpoint` at ``state`` exactly as the uninterrupted run would."""
        self.check_state(state)
        self.constraints.restore({k[len(CONSTRAINTS):]: v for k, v in ck.items() if k.startswith(CONSTRAINTS)})
        self.own_restore({k: v for k, v in ck.items() if not k.startswith(CONSTRAINTS)}, state)

    def diagnostics(self) -> dict:
        out = self.own_diagnostics()
        out.update(self.constraints.diagnostics())
        return out

    def check_state(self, state: State) -> None:
        raise NotImplementedError

    def own_checkpoint(self) -> dict:
        return {}

    def own_restore(self, ck: dict, state: State) -> None:
        return None

    def own_diagnostics(self) -> dict:
        return {}


class ESPHSolver(SolverBase):
    """ESPH rates with a Verlet pair list (cutoff 2h, skin ``skin_factor * h``; the scenes' value is
    ``Numerics.skin_factor``). With symmetry planes (``mirror``) the ghosts are chosen when the list is built
    (every particle within 2h + skin of a plane) and move with their sources until the next build. Rigid bodies
    are ordinary SPH neighbours (velocity V, density by Eq. (10) floored at rho0, stress -p I with p >= 0), the
    paper's way; with ``contact`` a :class:`~refsph.penalty.PenaltyContact` they are not: the SPH sums cover the
    deformable rows only, and the tools act through the penalty contact on their exact outline (Coulomb friction
    mu(T) included: :class:`~refsph.coupling.PenaltyCoupling`, as TLSPH's; not in the paper)."""

    method = "esph"
    evolved = ("x", "v", "rho", "S", "S_zz")

    def __init__(self, material: ElasticMaterial, params: ESPHParams, skin_factor: float, *,
                 strength: StrengthModel | None = None, mirror: MirrorPlanes | None = None, walls=(), rigid=(),
                 clamps=(), threads: int = 1, contact: PenaltyContact | None = None):
        super().__init__(material, params, strength, mirror, Constraints(walls, rigid, clamps, mirror), threads)
        if contact is not None and not self.constraints.rigid:
            raise ValueError("the penalty contact acts between the deformable rows and rigid bodies, and this setup "
                             "has none (give rigid=..., or contact=None)")
        if contact is not None and not isinstance(contact, PenaltyContact):
            raise TypeError("ESPH's tool contact is the penalty contact (refsph.penalty.PenaltyContact) or none (the "
                            f"tools in the SPH sums); got {type(contact).__name__}")
        self.contact = contact
        self.coupling = None if contact is None else PenaltyCoupling(contact, self.constraints.rigid)
        self.pairs = VerletList(params.kernel.support * params.h, skin_factor * params.h)
        self.pair_sum: PairBlocks | None = None            # blocks and sparse patterns of the current pair list
        self.pair_sum_build = -1
        self.ghosts: Ghosts | None = None
        self.ghost_constant: tuple | None = None           # extended (m, X, V0) of the current ghosts

    def check_state(self, state: State) -> None:
        """The state fits the solver (ValueError naming what does not). Several deformable bodies are accepted
        with a warning: ESPH has no contact law between them, they are one continuum to the SPH sums."""
        self.check_common(state)
        if len(self.constraints.deformable_bodies) > 1:
            warnings.warn(f"ESPH has no contact between deformable bodies {self.constraints.deformable_bodies}: "
                          "within 2h they are one continuum to the SPH sums (pressure pushes them apart, tension "
                          "glues them and particles can change sides). TLSPH has the pinball contact.",
                          stacklevel=2)

    def stage_density(self, old: State, new: State) -> np.ndarray:
        """ESPH integrates rho: the stage's new density, a tool's floored at rho0 (its own pressure is never
        negative)."""
        for rows in self.constraints.rows:
            new.rho[rows] = np.maximum(new.rho[rows], self.material.rho0)
        return new.rho

    def _build_with_ghosts(self, x: np.ndarray, state: State) -> None:
        """The pair list of positions ``x`` with the ghosts of the symmetry planes (ghost-ghost pairs dropped)."""
        self.ghosts = self.mirror.ghosts(x, self.pairs.cutoff + self.pairs.skin)
        self.ghost_constant = self.ghosts.extend_constant(state)
        I, J = self.pairs.build(self.ghosts.extend_vectors(x), track=x)
        keep = I < state.n                                  # ghost-ghost pairs act on ghosts only
        self.pairs.I, self.pairs.J = I[keep], J[keep]

    def _pairs_and_state(self, state: State):
        if self.mirror is None:
            return self.pairs.update(state.x), state
        if self.ghosts is None or self.pairs.needs_rebuild(state.x):
            self._build_with_ghosts(state.x, state)
        return (self.pairs.I, self.pairs.J), self.ghosts.extend_state(state, self.ghost_constant)

    def _body(self, state: State) -> State:
        """The rows in the SPH sums: every row, or with the penalty contact the deformable rows [0, n) (views)."""
        if self.constraints.dim is None:
            self.constraints.bind(state)
        n = self.constraints.n_deformable
        return state if self.coupling is None or n == state.n else state.rows(n)

    def rates(self, state: State, dt: float | None = None, part: str = "all", out: dict | None = None) -> Rates:
        """Eqs. (10)-(14), (23) over all particles, rigid ones included (``dt`` is not used); with the penalty
        contact over the deformable rows, then the contact for a step of size ``dt``; constrained. ``part``: 'all',
        'deformation' or 'forces' (:func:`~refsph.esph.esph_rates`; the leapfrog's halves). ``out``: a dict that
        receives the pair list (I, J) and the pressure p (Eq. (24)) of ``state``'s rows."""
        body = self._body(state)
        (I, J), ext = self._pairs_and_state(body)
        if self.pair_sum_build != self.pairs.n_builds:
            if self.pair_sum is not None:
                self.pair_sum.close()
            self.pair_sum = PairBlocks(I, J, ext.n, threads=self.threads)
            self.pair_sum_build = self.pairs.n_builds
        r = esph_rates(ext, self.material, self.params, I, J, pairs=self.pair_sum, part=part)
        r = r if ext is body else r.rows(body.n)
        if out is not None:
            out.update(pair_i=I, pair_j=J, p=eos_pressure(state.rho, self.material.rho0, self.material.K))
        if body is not state:
            r = _with_rigid(self, state, r, dt, contact=part != "deformation")
        return self.constraints.constrain(state, r, record=part != "deformation")

    def after_step(self, state: State) -> State:
        """The penalty contact's tangential history of the step committed (stick / slip); nothing else."""
        if self.coupling is not None:
            self.coupling.commit()
        return state

    def deformation_gradient(self, state: State) -> None:
        """ESPH has no deformation gradient."""
        return None

    def own_checkpoint(self) -> dict:
        """The positions the Verlet list was built at (the list and its ghosts follow from them), the counter."""
        ck = dict(n_builds=np.int64(self.pairs.n_builds))
        if self.pairs.x_build is not None:
            ck["x_build"] = self.pairs.x_build
        if self.coupling is not None:
            ck.update(self.coupling.checkpoint())
        return ck

    def own_restore(self, ck: dict, state: State) -> None:
        if "x_build" in ck:
            x_build = np.array(ck["x_build"])
            if self.mirror is None:
                self.pairs.build(x_build)
            else:
                self._build_with_ghosts(x_build, self._body(state))
        self.pairs.n_builds = int(ck["n_builds"])
        self.pair_sum_build = -1
        if self.coupling is not None:
            self.coupling.restore(ck)

    def own_diagnostics(self) -> dict:
        out = {"neighbour_list_builds": self.pairs.n_builds, "n_pairs": int(len(self.pairs.I))}
        if self.ghosts is not None:
            out["n_ghosts"] = int(self.ghosts.n)
        if self.coupling is not None:
            out.update(self.coupling.diagnostics(False))
        return out


class TLSPHSolver(SolverBase):
    """TLSPH rates with a fixed sparse operator, rebuilt at reference-configuration updates
    (:class:`~refsph.reference.ReferenceConfiguration`). With symmetry planes the ghosts are the mirror images of
    the reference configuration (fixed with the operator); a ghost's F is the mirror image of its source's. With
    rigid bodies the operator covers the deformable rows only, and the bodies meet through the ``contact``: the
    pinball (:class:`~refsph.contact.PinballContact`, :class:`~refsph.coupling.PinballCoupling`; ``dp``: 2D force
    per unit thickness) or the tools' penalty contact (:class:`~refsph.penalty.PenaltyContact`,
    :class:`~refsph.coupling.PenaltyCoupling`). ``self_contact``: r_c [m] of :mod:`refsph.self_contact` (None: off)."""

    method = "tlsph"
    evolved = ("x", "v", "S", "S_zz")

    def __init__(self, material: ElasticMaterial, params: TLSPHParams, *, strength: StrengthModel | None = None,
                 mirror: MirrorPlanes | None = None, walls=(), rigid=(), clamps=(),
                 contact: PinballContact | PenaltyContact | None = None, dp: float | None = None, threads: int = 1,
                 self_contact: float | None = None):
        super().__init__(material, params, strength, mirror, Constraints(walls, rigid, clamps, mirror), threads)
        self.self_contact = contact_distance(self_contact)
        if self.constraints.rigid and contact is None:
            raise ValueError("TLSPH with rigid bodies needs a contact model (PinballContact or PenaltyContact)")
        self.contact = contact
        if isinstance(contact, PenaltyContact):
            self.coupling = PenaltyCoupling(contact, self.constraints.rigid)
        else:
            self.coupling = None if contact is None else PinballCoupling(contact, contact.k * params.h, material.G,
                                                                         dp)
        self.reference = ReferenceConfiguration(params, mirror, self.threads)

    @property
    def several_bodies(self) -> bool:
        """More than one deformable body (they meet through the contact, not through the operator)."""
        return len(self.constraints.deformable_bodies) > 1

    def _body(self, state: State) -> State:
        """The deformable rows of ``state`` (views)."""
        if self.constraints.dim is None:
            self.constraints.bind(state)
        return self.reference.rows(state, self.constraints.n_deformable)

    def check_state(self, state: State) -> None:
        """The state fits the solver (ValueError naming what does not); TLSPH computes rho = m / (J V0)
        (Eq. (2)) and refuses a state whose rho says otherwise (an initial pressure it would silently drop). J is
        1 in the reference configuration (every x = X) and det F of the operator otherwise."""
        self.check_common(state)
        if self.several_bodies and not isinstance(self.contact, PinballContact):
            raise ValueError(f"deformable bodies {self.constraints.deformable_bodies} meet only through the pinball "
                             "contact: give the solver a PinballContact (refsph.simulate.make_solver does)")
        body = self._body(state)
        J = np.ones(body.n)                     # the reference configuration itself: J = 1 (by definition)
        if np.any(body.x != body.X):            # a deformed start: the J the operator gives (Eq. (18))
            J = det(self.reference.rows_gradient(body, self.several_bodies))
        rho = body.m / (J * body.V0)
        if not np.allclose(body.rho, rho, rtol=1e-8, atol=0.0):
            k = int(np.argmax(np.abs(body.rho - rho)))
            raise ValueError(f"TLSPH takes the density from m / (J V0) (Eq. (2)) and does not read State.rho: "
                             f"particle {k} has rho = {body.rho[k]:.6g}, m / (J V0) = {rho[k]:.6g} kg/m^3. An "
                             "initial pressure needs ESPH, or an initial deformation (x != X) in TLSPH")

    def rates(self, state: State, dt: float, part: str = "all", out: dict | None = None) -> Rates:
        """Eqs. (16)-(23) on the deformable body; with rigid bodies, the pinball contact (Eqs. (32)-(36)) for a
        step of size ``dt`` (Eq. (34)). ``part``: 'all', 'deformation' (stress rates) or 'forces' (dv/dt, contact
        included): the leapfrog's halves. ``out``: a dict that receives F, J, P, l, rho, p of the deformable rows
        (:func:`~refsph.tlsph.tlsph_rates`; J there is det F) and the operator's half pairs (pair_i, pair_j)."""
        body = self._body(state)
        ref = self.reference
        op = ref.operator(body, self.several_bodies)
        ext = ref.extended(body, op)
        F = ref.gradient_for_rates(body, ext, op)
        r = tlsph_rates(ext, self.material, self.params, op, F=F, out=out, part=part)
        r = r if ext is body else r.rows(body.n)
        if out is not None:
            out.update({k: (None if out[k] is None else out[k][:body.n]) for k in ("F", "J", "P", "l", "rho", "p")},
                       pair_i=op.I, pair_j=op.J)
        if part != "deformation" and self.several_bodies:
            r.v = r.v + self.coupling.between_bodies(body, self.constraints.deformable_bodies, dt)
        if part != "deformation" and self.self_contact is not None:
            r.v = r.v + self_contact_acceleration(body, self.self_contact, self.material, self.several_bodies)
        if body is not state:
            r = _with_rigid(self, state, r, dt, contact=part != "deformation")
        return self.constraints.constrain(state, r, record=part != "deformation")

    def deformation_gradient(self, state: State) -> np.ndarray:
        """Eq. (18) for every row (rigid rows: I)."""
        return with_identity(self.reference.rows_gradient(self._body(state), self.several_bodies), state)

    def step_gain(self, state: State) -> float:
        """max(1, the corrected gradient's largest gain) (:meth:`~refsph.tlsph.ReferenceOperator.max_gain`)."""
        return self.reference.operator(self._body(state), self.several_bodies).max_gain()

    def critical_step(self, state: State) -> float:
        """2 / w_max of the reference configuration (:meth:`~refsph.tlsph.ReferenceOperator.critical_step`)."""
        body = self._body(state)
        return self.reference.operator(body, self.several_bodies).critical_step(body, self.material, self.params)

    def after_step(self, state: State) -> State:
        """rho = m / (J V0) (Eq. (2)); reference update when max |E| > ref_update_strain (ReferenceConfiguration)."""
        self._body(state)
        if isinstance(self.coupling, PenaltyCoupling):
            self.coupling.commit()                          # the step's tangential history (stick / slip)
        return self.reference.end_step(state, self.constraints.n_deformable, self.several_bodies)

    def own_checkpoint(self) -> dict:
        """The reference configuration's counters and the contact's (the operator follows from X and V0)."""
        ck = self.reference.checkpoint()
        if self.coupling is not None:
            ck.update(self.coupling.checkpoint())
        return ck

    def own_restore(self, ck: dict, state: State) -> None:
        self.reference.restore(ck)
        if self.coupling is not None:
            self.coupling.restore(ck)

    def own_diagnostics(self) -> dict:
        out = self.reference.diagnostics()
        if self.coupling is not None:
            out.update(self.coupling.diagnostics(self.several_bodies))
        return out


def _with_rigid(solver: SolverBase, state: State, r: Rates, dt: float, contact: bool = True) -> Rates:
    """Rates of all rows: the deformable ones plus the tool contact (``contact``), the rigid ones carrying
    the reaction (dv/dt = contact force / m, turned into the recorded force and then zeroed by the
    constraints), the contact's friction power on both sides (``Rates.friction_power``) and, where the rates
    carry the viscous heat, the contact's damping power added to it (``Rates.heat_power``; that part alone in
    ``Rates.damping_power``)."""
    n, N, d = solver.constraints.n_deformable, state.n, state.dim
    v = np.zeros((N, d))
    v[:n] = r.v
    power = heat = damping = None
    if r.heat_power is not None:
        heat = np.zeros(N)
        heat[:n] = r.heat_power
    if contact:
        c = solver.coupling.with_tools(state, n, dt)
        v[:n] += c.a
        v[n:] = c.force_on_b / state.m[n:, None]
        if c.friction_power_a is not None:
            power = np.concatenate([c.friction_power_a, c.friction_power_b])
        if heat is not None and c.heat_power_a is not None:
            heat[:n] += c.heat_power_a
            damping = np.zeros(N)
            damping[:n] = c.heat_power_a
    S = np.zeros((N, d, d))
    S[:n] = r.S
    S_zz = np.zeros(N)
    S_zz[:n] = r.S_zz
    l = None
    if r.l is not None:
        l = np.zeros((N, d, d))
        l[:n] = r.l
    rho = None
    if r.rho is not None:                                   # ESPH integrates rho; a tool's stays where it is
        rho = np.zeros(N)
        rho[:n] = r.rho
    return Rates(x=state.v.copy(), v=v, rho=rho, S=S, S_zz=S_zz, l=l, friction_power=power, heat_power=heat,
                 damping_power=damping)
