"""Time stepping: the solver interface, the predictor-corrector step and the CFL time step.

A *solver* (:class:`Solver`; :mod:`refsph.solvers` has ESPH and TLSPH) knows the physics of one formulation; a
*stepper* knows only how to advance the fields the solver names (``solver.evolved``) with the rates it returns.
The stepper hands the step size to the solver as an argument (``rates(state, dt)``: the TLSPH pinball force of
Eq. (34) depends on it); the solver keeps no time-stepping state of its own.

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
predictor-corrector's two whole evaluations. The force at the end of a step is kept on the solver
(``solver.stepper_state``, written to the restart checkpoint) for the next step's first kick.

CFL time step:  dt = C_cfl h / (c_L + max|v|),  c_L = sqrt((K + 4G/3)/rho0), the dilatational wave speed
(the fastest signal in a solid; the paper's C = sqrt(E/rho) is smaller, so it is used only in Eq. (12)).
A fixed dt, as in the paper's tables, is also accepted by the driver.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Callable, Protocol, runtime_checkable

import numpy as np

from .material import ElasticMaterial
from .state import Rates, State

__all__ = ["Solver", "predictor_corrector_step", "leapfrog_step", "cfl_time_step", "advance", "STEPPERS",
           "get_stepper"]


@runtime_checkable
class Solver(Protocol):
    """What a stepper and the run driver need of a formulation.

    ``method``: its name ('esph', 'tlsph'); ``evolved``: the State fields a stepper integrates; ``h``: the
    smoothing length (for the CFL step); ``threads``: threads of its pair sums. ``check_state(state)`` refuses a
    state it cannot run (ValueError); ``rates(state, dt)`` gives the time derivatives of ``evolved`` at ``state``
    for a step of size ``dt``; ``finish_stage(old, new, rates, dt, final)`` applies the constraints and the
    strength model's return map to the state a stage produced (``final``: the end of the step);
    ``after_step(state)`` does the once-per-step work (TLSPH: density, reference update); the rest is output:
    ``deformation_gradient(state)`` (None where the method has none), ``reaction_history()``, ``diagnostics()``.
    A wrapper that adds a force or a prescribed motion is an object with these members that calls a solver's.
    """

    method: str
    evolved: tuple
    h: float
    threads: int

    def check_state(self, state: State) -> None: ...

    def rates(self, state: State, dt: float) -> Rates: ...

    def finish_stage(self, old: State, new: State, rates: Rates, dt: float, final: bool) -> State: ...

    def after_step(self, state: State) -> State: ...

    def deformation_gradient(self, state: State) -> np.ndarray | None: ...

    def reaction_history(self) -> dict: ...

    def diagnostics(self) -> dict: ...


def advance(state: State, rates: Rates, dt: float, evolved) -> State:
    """A new state with y + dt dy/dt for every field named in ``evolved`` (the others shared with ``state``)."""
    new = replace(state)
    for name in evolved:
        setattr(new, name, getattr(state, name) + dt * getattr(rates, name))
    return new


def predictor_corrector_step(state: State, solver: Solver, dt: float) -> State:
    """One predictor-corrector step (two rate evaluations), then the solver's after-step work.

    Each stage ends with ``solver.finish_stage`` (constraints, return map)."""
    r0 = solver.rates(state, dt)
    half = solver.finish_stage(state, advance(state, r0, 0.5 * dt, solver.evolved), r0, 0.5 * dt, final=False)
    half.t = state.t + 0.5 * dt
    r1 = solver.rates(half, dt)
    new = solver.finish_stage(state, advance(state, r1, dt, solver.evolved), r1, dt, final=True)
    new.t = state.t + dt
    return solver.after_step(new)


def leapfrog_step(state: State, solver: Solver, dt: float) -> State:
    """One kick-drift-kick leapfrog step (module text): one force and one deformation-rate evaluation."""
    a_n = _kept_acceleration(state, solver)
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
    solver.stepper_state = dict(t=np.float64(new.t), x=new.x.copy(), a=rf.v)
    return new


def _kept_acceleration(state: State, solver: Solver) -> np.ndarray | None:
    """The force the last leapfrog step ended with, if it belongs to this very state (time and positions)."""
    kept = getattr(solver, "stepper_state", None)
    if kept and kept["t"] == state.t and kept["x"].shape == state.x.shape and np.array_equal(kept["x"], state.x):
        return kept["a"]
    return None


STEPPERS: dict[str, Callable[[State, Solver, float], State]] = {
    "predictor_corrector": predictor_corrector_step,
    "leapfrog": leapfrog_step,
}


def get_stepper(name: str) -> Callable[[State, Solver, float], State]:
    try:
        return STEPPERS[name]
    except KeyError:
        raise ValueError(f"unknown integrator {name!r}; available: {', '.join(STEPPERS)}") from None


def cfl_time_step(state: State, material: ElasticMaterial, h: float, courant: float) -> float:
    """dt = courant * h / (c_L + max |v|)."""
    if not 0 < courant <= 1:
        raise ValueError(f"Courant number must lie in (0, 1], got {courant!r}")
    vmax = float(np.sqrt(np.max(np.einsum("ik,ik->i", state.v, state.v)))) if state.n else 0.0
    return courant * h / (material.c_longitudinal + vmax)
