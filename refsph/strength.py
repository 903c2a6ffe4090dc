"""The strength-model seam: one interface for every law of the deviatoric stress (the return map), as LAMMPS's SMD
package gives every strength model one signature.

A strength model is any object with

    state_fields                                  names of the State fields it needs besides S and S_zz:
                                                  () for an elastic solid, PLASTIC_FIELDS for a plasticity law
    return_map(S, S_zz, eps_p, eps_dot, T, G)     -> (S_n, S_zz_n, d_eps_p, d_w_p): the trial deviatoric stress
                                                  returned to the law's admissible set, the plastic strain and
                                                  plastic work density of the step
    heat(d_w_p, rho)                              -> d_T, the temperature rise of that plastic work (Eq. (28));
                                                  zero for a law whose ``heating`` switch is off (isothermal)

The solvers know nothing else of the law: at the end of every stage of a step they call :func:`strength_stage`,
which calls :func:`plastic_update`, which calls the model. The laws refsph ships:

* :class:`Elastic` (this module): no return map (``state_fields = ()``);
* :class:`~refsph.plasticity.JohnsonCook` (Eq. (25)) and :class:`~refsph.plasticity.ModifiedJohnsonCook` (the
  hardening limit of Rodriguez Prieto et al., their Eq. (9)), both von Mises laws with Wilkins' radial return
  (:class:`~refsph.plasticity.J2Plasticity`, Eqs. (29)-(31)).

Adding a law is one class in one file: a von Mises law subclasses ``J2Plasticity`` and gives its flow stress
``flow_stress(eps_p, eps_dot, T)`` (and ``chi``, ``cp`` for its heating); any other law implements the three
members above. Whether plastic work heats is the law's own switch (``JohnsonCook(..., heating=False)``:
isothermal, the plastic work still accumulated), read by :func:`heats`. ``tests/test_strength.py`` adds a
linear-hardening law that way, in the test file alone.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from .plasticity import equivalent_strain_rate
from .state import PLASTIC_FIELDS, State

__all__ = ["StrengthModel", "Elastic", "plastic_update", "strength_stage", "heats", "heat_capacity",
           "PLASTIC_FIELDS"]


@runtime_checkable
class StrengthModel(Protocol):
    """What the solvers need of a strength law (see the module text)."""

    state_fields: tuple

    def return_map(self, S: np.ndarray, S_zz: np.ndarray, eps_p: np.ndarray, eps_dot: np.ndarray, T: np.ndarray,
                   G: float) -> tuple: ...

    def heat(self, d_w_p: np.ndarray, rho: np.ndarray) -> np.ndarray: ...


class Elastic:
    """Hypoelastic solid (Eqs. (20)-(24) alone): the trial stress is the stress, nothing plastic happens. ``cp``
    [J/(kg K)]: its heat capacity, needed only when the run conducts heat (None: not given)."""

    state_fields: tuple = ()
    heating = False

    def __init__(self, cp: float | None = None):
        if cp is not None and not (np.isfinite(cp) and cp > 0):
            raise ValueError(f"Elastic(cp=...) must be a positive heat capacity [J/(kg K)], got {cp!r}")
        self.cp = cp

    def return_map(self, S, S_zz, eps_p, eps_dot, T, G):
        zero = np.zeros(len(S))
        return S, S_zz, zero, zero

    def heat(self, d_w_p, rho):
        return np.zeros_like(d_w_p)

    def __repr__(self) -> str:
        return "Elastic()" if self.cp is None else f"Elastic(cp={self.cp!r})"


def heats(model: StrengthModel) -> bool:
    """Whether the law turns plastic work into heat (Eq. (28)): its ``heating`` switch (False for an elastic
    solid; True for a law that does not say)."""
    return bool(getattr(model, "heating", True)) and bool(model.state_fields)


def heat_capacity(model: StrengthModel) -> float | None:
    """The law's heat capacity c_p [J/(kg K)] (None if it gives none): the one number the plastic heating
    (Eq. (28)) and heat conduction (:mod:`refsph.thermal`) use."""
    return getattr(model, "cp", None)


def plastic_update(S: np.ndarray, S_zz: np.ndarray, eps_p: np.ndarray, T: np.ndarray, rho: np.ndarray,
                   eps_dot: np.ndarray, model: StrengthModel, G: float):
    """One return map at the end of a step (for Johnson-Cook: Eqs. (25)-(31)).

    S, S_zz: trial deviatoric stress (the elastic update); eps_p, T: values at the start of the step; rho:
    density; eps_dot: equivalent strain rate of the step. The flow stress is evaluated with the start-of-step
    eps_p and T (explicit, as in the paper). Returns (S_n, S_zz_n, d_eps_p, d_w_p, d_T); d_T is zero for a law
    whose heating is off (isothermal: the plastic work is still accumulated)."""
    S_n, S_zz_n, deps, dw = model.return_map(S, S_zz, eps_p, eps_dot, T, G)
    dT = model.heat(dw, rho)
    return S_n, S_zz_n, deps, dw, dT


def check_strength_fields(model: StrengthModel, state: State) -> None:
    """The state carries every field the model needs (ValueError naming them otherwise)."""
    missing = [k for k in model.state_fields if getattr(state, k, None) is None]
    if missing:
        raise ValueError(f"the strength model {type(model).__name__} needs the state fields {', '.join(missing)} "
                         "(make_state(..., T0=room temperature) adds eps_p, eps_dot_p, W_p and T)")


def strength_stage(model: StrengthModel, old: State, new: State, l: np.ndarray, rho: np.ndarray, dt: float,
                   final: bool, G: float) -> State:
    """The return map on the state a stage of the step produced (``new``, in place), with the stage's velocity
    gradient ``l`` (its equivalent strain rate enters the flow stress) and the start-of-step plastic fields of
    ``old``. Only the final stage accumulates eps_p, W_p and T; an intermediate stage (the predictor's half
    state) is only returned to the yield surface, so that the midpoint rates see an admissible stress."""
    if isinstance(model, Elastic):
        return new
    check_strength_fields(model, old)
    eps_dot = equivalent_strain_rate(l)
    S, S_zz, deps, dw, dT = plastic_update(new.S, new.S_zz, old.eps_p, old.T, rho, eps_dot, model, G)
    new.S, new.S_zz = S, S_zz
    if final and old.plastic:                  # a law without plastic fields (state_fields = ()) keeps none
        new.eps_p = old.eps_p + deps
        new.W_p = old.W_p + dw
        new.T = old.T + dT
        new.eps_dot_p = deps / dt
    return new
