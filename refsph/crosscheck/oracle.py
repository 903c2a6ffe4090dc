"""refsph as the oracle of other backends: the full-scene rates of a state, and golden cases to compare against.

**Rates of a state.** :func:`rates` gives every rate and derived field of a scene at a given state, exactly as a
run computes them (walls, clamps, symmetry ghosts, the pinball contact, the constraints), and what the strength
model's return map makes of a step of size dt:

    from refsph.crosscheck.oracle import rates
    out = rates("runs/pressing-tlsph-2d/snapshots/snap_00005.npz", "pressing", "tlsph", quick=True)
    out["v_dot"], out["F"], out["S_returned"]

**Pair-list convention.** Every sum over neighbours in refsph runs over *half pairs*: each interacting pair once,
I < J, no self-pairs, no duplicates, returned in ``out["I"], out["J"]``. A pair term is computed once and added
to i and (with the sign the equation asks for) to j. A full (both-direction) list, the usual GPU layout, is
refused by :func:`refsph.neighbours.check_half_pairs` with a message saying so.

**Golden cases.** ``refsph oracle DIR`` (:func:`write_golden_cases`) writes a versioned set of small cases, each a
folder with ``input.npz``, ``output.npz`` and ``case.json`` (every array with its shape, unit and meaning, the
equations it exercises, the tolerance another backend should meet and why). ``refsph compare REF TEST``
(:mod:`refsph.crosscheck.compare`) checks another code's outputs against them.
"""
from __future__ import annotations


import numpy as np

from ..integrate import advance, cfl_time_step
from ..io import state_from_snapshot
from ..scenes import Scene, Setup, get_scene
from ..simulate import make_solver
from ..state import State

__all__ = ["rates", "state_from_snapshot"]


def rates(state, setup, method: str, *, dt: float | None = None, **scene_args) -> dict:
    """Every rate and derived field of ``setup`` at ``state`` with ``method`` ('esph' | 'tlsph').

    ``state``: a State, a snapshot path or a loaded snapshot; ``setup``: a :class:`~refsph.scenes.Setup`, a
    :class:`~refsph.scenes.Scene` or a scene name (then ``scene_args``, e.g. ``quick=True, feed=0.5e-3``, build
    it as ``Scene.setup`` does); ``dt``: the step size (default: the CFL step at this state), which enters the
    TLSPH pinball force (Eq. (34)) and the return map below.

    Returns a dict of arrays (SI units, one row per particle of ``state``): ``x_dot, v_dot, S_dot, S_zz_dot`` (and
    ``rho_dot`` for ESPH): the constrained rates; ``l``: velocity gradient; ``p``: pressure; for TLSPH ``F, J_det, P``
    (of the deformable rows; J_det = det F); ``I, J``: the half pairs used (for ESPH the Verlet list, pairs up to 2h +
    skin, those beyond 2h contribute zero; with symmetry planes J may index mirror ghosts, rows >= N); ``n_pairs``;
    ``dt``; the return map of a step of size dt from this state with these rates: ``S_trial = S + dt S_dot`` (and
    ``S_zz_trial``) before it, ``S_returned``, ``S_zz_returned``, ``d_eps_p``, ``d_w_p``, ``d_T`` after it (the strength
    model of the setup; unchanged for an elastic one).
    """
    if isinstance(setup, str):
        setup = get_scene(setup)
    if isinstance(setup, Scene):
        setup = setup.setup(**scene_args)
    if not isinstance(setup, Setup):
        raise TypeError(f"setup must be a Setup, a Scene or a scene name, got {type(setup).__name__}")
    state = state_from_snapshot(state) if not isinstance(state, State) else state.copy()
    state.check()
    solver = make_solver(method, setup)
    solver.check_state(state)
    dt = cfl_time_step(state, setup.material, setup.h, setup.numerics.courant) if dt is None else float(dt)
    extra: dict = {}
    r = solver.rates(state, dt, out=extra)
    extra.pop("l", None)                                    # the deformable rows' l: r.l has every row
    pairs = dict(I=extra.pop("pair_i"), J=extra.pop("pair_j"))
    if "J" in extra:                                        # TLSPH's det F (the solver's name), not a pair index
        extra["J_det"] = extra.pop("J")
    out = dict(x_dot=r.x, v_dot=r.v, S_dot=r.S, S_zz_dot=r.S_zz, l=r.l, dt=dt, n_pairs=len(pairs["I"]), **extra,
               **pairs)
    if r.rho is not None:
        out["rho_dot"] = r.rho
    trial = advance(state, r, dt, solver.evolved)
    out.update(S_trial=np.array(trial.S), S_zz_trial=np.array(trial.S_zz))
    new = solver.finish_stage(state, trial, r, dt, final=True)
    out.update(S_returned=new.S, S_zz_returned=new.S_zz)
    if state.plastic:
        out.update(d_eps_p=new.eps_p - state.eps_p, d_w_p=new.W_p - state.W_p, d_T=new.T - state.T)
    return out
