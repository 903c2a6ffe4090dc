"""Time stepping: the solver interface, the predictor-corrector step and the CFL time step.

A *solver* (:class:`Solver`; :mod:`refsph.solvers` has ESPH and TLSPH) knows the physics of one formulation; a
*stepper* knows only how to advance the fields the solver names (``solver.evolved``) with the rates it returns.
The stepper hands the step size to the solver as an argument (``rates(state, dt, part)``: the TLSPH pinball force
of Eq. (34) depends on it); the solver keeps no time-stepping state of its own: what a stepper carries from one step
to the next (the leapfrog's last force) lives on the stepper (:class:`Leapfrog`), which the run loop owns and
checkpoints. A method that advances its own state (an implicit one: :class:`SelfAdvancing`) is stepped by
:class:`OwnAdvance`, so it runs in the same loop.

Besides the mechanics, a run may carry other physics (heat: :class:`refsph.thermal.HeatFlow`): each is a
:class:`StepPhysics` that the loop calls in order: its step limit, its advance after the mechanical step, its
record, its summary, its checkpoint.

Predictor-corrector (Monaghan 1989, J. Comput. Phys. 82, 1; the scheme of SPHysics, Gomez-Gesteira et al.
2012), for every evolved field y with rate f(y):

    predictor:  y^{n+1/2} = y^n + dt/2 f(y^n)
    corrector:  y^{n+1/2} = y^n + dt/2 f(y^{n+1/2})
    final:      y^{n+1}   = 2 y^{n+1/2} - y^n  =  y^n + dt f(y^{n+1/2})

It is second order and needs two rate evaluations per step. The paper states only "predictor-corrector
with a CFL time step"; this is the standard SPH form. Its amplification factor for an undamped oscillation of
frequency w is |1 + i w dt - (w dt)^2/2| = sqrt(1 + (w dt)^4/4) > 1: without artificial viscosity every mode grows,
the fastest (the particle-scale ones, w dt ~ 1) by a few per cent a step.

Leapfrog (kick-drift-kick, the "second-order leapfrog" of Rodriguez Prieto, Larsson & Afrasiabi, Section 2.4.2;
staggered as in Wilkins' HEMP: the stress is a "position", advanced with the mid-step velocity):

    v^{n+1/2} = v^n + dt/2 a(x^n, S^n)                               (kick; a^n kept from the last step)
    S^{n+1}   = S^n + dt dS/dt(x^n + dt/2 v^{n+1/2}, v^{n+1/2})      (also rho in ESPH; then the return map)
    x^{n+1}   = x^n + dt v^{n+1/2}                                   (drift)
    v^{n+1}   = v^{n+1/2} + dt/2 a(x^{n+1}, S^{n+1})                 (kick; artificial viscosity with v^{n+1/2})

It is symplectic for the elastic part (|amplification| = 1 for w dt < 2): an undamped solid keeps its energy, up
to an oscillation of relative size (w dt)^2/8, with no drift. It evaluates the forces once and the deformation
rates once per step (``solver.rates(state, dt, part=...)``, the two halves of one rate evaluation), against the
predictor-corrector's two whole evaluations. The force at the end of a step is kept on the stepper
(:class:`Leapfrog`, written to the restart checkpoint) for the next step's first kick.

A step returns :class:`Step`: the new state and the rates of its last force evaluation (the predictor-corrector's
midpoint rates, the leapfrog's end-of-step forces), whose ``friction_power`` is the frictional heat source of the
step.

CFL time step:  dt = C_cfl h / (c_L + max|v|),  c_L = sqrt((K + 4G/3)/rho0), the dilatational wave speed
(the fastest signal in a solid; the paper's C = sqrt(E/rho) is smaller, so it is used only in Eq. (12)).
A fixed dt, as in the paper's tables, is also accepted by the driver.
"""
from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple, Protocol, runtime_checkable

import numpy as np

from .material import ElasticMaterial
from .state import Rates, State

__all__ = ["Solver", "SelfAdvancing", "Stepper", "StepPhysics", "Step", "PredictorCorrector", "Leapfrog",
           "OwnAdvance", "predictor_corrector_step", "leapfrog_step", "cfl_time_step", "advance", "STEPPERS",
           "get_stepper", "make_stepper", "PARTS"]

PARTS = ("all", "deformation", "forces")     # what rates(state, dt, part) evaluates: the leapfrog's two halves


@runtime_checkable
class Solver(Protocol):
    """What a stepper and the run driver need of a formulation.

    ``method``: its name ('esph', 'tlsph'); ``evolved``: the State fields a stepper integrates; ``h``: the
    smoothing length (for the CFL step); ``threads``: threads of its pair sums. ``check_state(state)`` refuses a
    state it cannot run (ValueError); ``rates(state, dt, part)`` gives the time derivatives of ``evolved`` at
    ``state`` for a step of size ``dt``; ``part`` is one of :data:`PARTS`: 'all', or the leapfrog's halves
    'deformation' (the stress and density rates, with the velocity gradient ``l``) and 'forces' (dv/dt);
    ``finish_stage(old, new, rates, dt, final)`` applies the constraints and the strength model's return map to
    the state a stage produced (``final``: the end of the step); ``after_step(state)`` does the once-per-step work
    (TLSPH: density, reference update); ``checkpoint()`` / ``restore(arrays, state)``: what a restart needs besides
    the state; the rest is output: ``deformation_gradient(state)`` (None where the method has none),
    ``reaction_history()``, ``diagnostics()``. A wrapper that adds a force or a prescribed motion is an object
    with these members that calls a solver's (``tests/test_api.py`` runs one with every stepper).
    """

    method: str
    evolved: tuple
    h: float
    threads: int

    def check_state(self, state: State) -> None: ...

    def rates(self, state: State, dt: float, part: str = "all") -> Rates: ...

    def finish_stage(self, old: State, new: State, rates: Rates, dt: float, final: bool) -> State: ...

    def after_step(self, state: State) -> State: ...

    def checkpoint(self) -> dict: ...

    def restore(self, arrays: dict, state: State) -> None: ...

    def deformation_gradient(self, state: State) -> np.ndarray | None: ...

    def reaction_history(self) -> dict: ...

    def diagnostics(self) -> dict: ...


@runtime_checkable
class SelfAdvancing(Protocol):
    """A method that advances its own state (an implicit one solves for the end of the step): the run loop steps
    it with :class:`OwnAdvance`. ``advance(state, dt)`` returns the state at t + dt; the other members are the
    :class:`Solver`'s output and restart members."""

    method: str
    h: float
    threads: int

    def check_state(self, state: State) -> None: ...

    def advance(self, state: State, dt: float) -> State: ...

    def checkpoint(self) -> dict: ...

    def restore(self, arrays: dict, state: State) -> None: ...

    def deformation_gradient(self, state: State) -> np.ndarray | None: ...

    def reaction_history(self) -> dict: ...

    def diagnostics(self) -> dict: ...


class Step(NamedTuple):
    """What one step gives: the new ``state`` and the ``rates`` of its last force evaluation (None for a method
    that advances itself), whose ``friction_power`` is the step's frictional heat source."""

    state: State
    rates: Rates | None


@runtime_checkable
class Stepper(Protocol):
    """A time stepper: ``step(state, solver, dt)`` -> :class:`Step`; what it carries from one step to the next is
    its own (``checkpoint()`` -> arrays, ``restore(arrays)``), owned by the run loop."""

    name: str

    def step(self, state: State, solver, dt: float) -> Step: ...

    def checkpoint(self) -> dict: ...

    def restore(self, arrays: dict) -> None: ...


@runtime_checkable
class StepPhysics(Protocol):
    """Physics beside the mechanics (heat now: :class:`refsph.thermal.HeatFlow`), called by the run loop in this
    order: ``bind(state, solver)`` once at the start; every step ``step_limit(state)`` (the largest stable step,
    inf for none), then after the mechanical step ``advance(before, step, dt)`` -> the state with this physics'
    fields advanced; ``record(state)`` -> scalars for the history; ``describe()`` -> what summary.json says of the
    model (under ``name``), ``summary(state)`` -> entries of summary.json as they stand; ``checkpoint()`` -> arrays
    and ``restore(arrays)`` for a restart."""

    name: str

    def bind(self, state: State, solver) -> None: ...

    def step_limit(self, state: State) -> float: ...

    def advance(self, before: State, step: Step, dt: float) -> State: ...

    def record(self, state: State) -> dict: ...

    def describe(self) -> dict: ...

    def summary(self, state: State) -> dict: ...

    def checkpoint(self) -> dict: ...

    def restore(self, arrays: dict) -> None: ...


def advance(state: State, rates: Rates, dt: float, evolved) -> State:
    """A new state with y + dt dy/dt for every field named in ``evolved`` (the others shared with ``state``)."""
    new = replace(state)
    for name in evolved:
        setattr(new, name, getattr(state, name) + dt * getattr(rates, name))
    return new


class PredictorCorrector:
    """Predictor-corrector (module text): two rate evaluations per step, nothing kept between steps."""

    name = "predictor_corrector"

    def step(self, state: State, solver: Solver, dt: float) -> Step:
        """One step, then the solver's after-step work. Each stage ends with ``solver.finish_stage`` (constraints,
        return map)."""
        r0 = solver.rates(state, dt, part="all")
        half = solver.finish_stage(state, advance(state, r0, 0.5 * dt, solver.evolved), r0, 0.5 * dt, final=False)
        half.t = state.t + 0.5 * dt
        r1 = solver.rates(half, dt, part="all")
        new = solver.finish_stage(state, advance(state, r1, dt, solver.evolved), r1, dt, final=True)
        new.t = state.t + dt
        return Step(solver.after_step(new), r1)

    def checkpoint(self) -> dict:
        return {}

    def restore(self, arrays: dict) -> None:
        return None


class Leapfrog:
    """Kick-drift-kick leapfrog (module text): one force and one deformation-rate evaluation per step. It keeps the
    force the last step ended with (``kept``: t, x, a) for the next step's first kick."""

    name = "leapfrog"

    def __init__(self):
        self.kept: dict | None = None

    def step(self, state: State, solver: Solver, dt: float) -> Step:
        a_n = self._kept_acceleration(state)
        if a_n is None:
            a_n = solver.rates(state, dt, part="forces").v
        v_half = state.v + 0.5 * dt * a_n
        mid = replace(state, x=state.x + 0.5 * dt * v_half, v=v_half)
        rd = solver.rates(mid, dt, part="deformation")
        new = replace(state, x=state.x + dt * v_half, v=v_half)
        for name in solver.evolved:
            if name not in ("x", "v"):
                setattr(new, name, getattr(state, name) + dt * getattr(rd, name))
        new = solver.finish_stage(state, new, rd, dt, final=True)
        new.t = state.t + dt
        rf = solver.rates(new, dt, part="forces")
        new.v = new.v + 0.5 * dt * rf.v
        new = solver.after_step(new)
        self.kept = dict(t=np.float64(new.t), x=new.x.copy(), a=rf.v)
        return Step(new, rf)

    def _kept_acceleration(self, state: State) -> np.ndarray | None:
        """The force the last step ended with, if it belongs to this very state (time and positions)."""
        k = self.kept
        if k and k["t"] == state.t and k["x"].shape == state.x.shape and np.array_equal(k["x"], state.x):
            return k["a"]
        return None

    def checkpoint(self) -> dict:
        return dict(self.kept) if self.kept else {}

    def restore(self, arrays: dict) -> None:
        self.kept = dict(arrays) if arrays else None


class OwnAdvance:
    """The stepper of a :class:`SelfAdvancing` method: the method's own ``advance(state, dt)``."""

    name = "own"

    def step(self, state: State, solver: SelfAdvancing, dt: float) -> Step:
        return Step(solver.advance(state, dt), None)

    def checkpoint(self) -> dict:
        return {}

    def restore(self, arrays: dict) -> None:
        return None


STEPPERS: dict[str, type] = {
    "predictor_corrector": PredictorCorrector,
    "leapfrog": Leapfrog,
}


def get_stepper(name: str) -> type:
    """The stepper class named ``name`` (:data:`STEPPERS`)."""
    try:
        return STEPPERS[name]
    except KeyError:
        raise ValueError(f"unknown integrator {name!r}; available: {', '.join(STEPPERS)}") from None


def make_stepper(name: str, solver=None) -> Stepper:
    """A fresh stepper for a run: :class:`OwnAdvance` for a method that advances itself, else ``STEPPERS[name]``."""
    if solver is not None and isinstance(solver, SelfAdvancing) and not isinstance(solver, Solver):
        return OwnAdvance()
    return get_stepper(name)()


def predictor_corrector_step(state: State, solver: Solver, dt: float) -> State:
    """One predictor-corrector step (:class:`PredictorCorrector`): the new state."""
    return PredictorCorrector().step(state, solver, dt).state


def leapfrog_step(state: State, solver: Solver, dt: float) -> State:
    """One leapfrog step from a state with no kept force (the step evaluates the force at ``state`` first); a run
    keeps one :class:`Leapfrog` and so evaluates the forces once per step."""
    return Leapfrog().step(state, solver, dt).state


def cfl_time_step(state: State, material: ElasticMaterial, h: float, courant: float) -> float:
    """dt = courant * h / (c_L + max |v|)."""
    if not 0 < courant <= 1:
        raise ValueError(f"Courant number must lie in (0, 1], got {courant!r}")
    vmax = float(np.sqrt(np.max(np.einsum("ik,ik->i", state.v, state.v)))) if state.n else 0.0
    return courant * h / (material.c_longitudinal + vmax)
