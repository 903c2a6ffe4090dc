"""Heat conduction in SPH (Rodriguez Prieto, Larsson & Afrasiabi, Eqs. (4), (26), (29)): the first piece of the
thermomechanical cutting model (issue 16). A run conducts heat only when its Setup asks (``Setup.thermal``, a
:class:`Conduction`; None, the default: no conduction, the first paper's adiabatic model; ``thermal_cutting`` conducts).

    Eq. (4)   rho c_p dT/dt = k lap T + Q_s
    Eq. (26)  lap f_i = sum_j 2 f_ij / |r_ij| (e_ij . grad_i W_ij) V_j,    f_ij = f_i - f_j, e_ij = r_ij / |r_ij|
    Eq. (29)  dT_i/dt = a_i sum_j 2 T_ij / |r_ij| (e_ij . grad_i W_ij) V_j + S_i,   a = k / (rho c_p)

Eq. (26) is Brookshaw's (1985) Laplacian: with e_ij . grad_i W_ij = dW/dr, each pair term is
2 (f_i - f_j) (dW/dr)/r V_j, a heat flux between the two particles proportional to their temperature difference.
Summed as an antisymmetric pair term (:meth:`refsph.neighbours.PairSum.antisymmetric`) it moves heat from one
particle to the other and creates none: with one diffusivity the total heat sum_i m_i c_p T_i is conserved to
round-off. At a free surface the missing neighbours carry no flux, so an SPH body is insulated (a zero-flux
boundary) unless a boundary term is added (convection, radiation, a fixed temperature: later parts of issue 16).

Explicit time step (the second paper's Section 2.4.2): dt_t = rho c_p h^2 / k, times a Courant-like factor;
:func:`thermal_time_step`.

Between materials (the workpiece and a conducting tool) the conductivity of a pair is the harmonic mean
k_ij = 2 k_i k_j / (k_i + k_j) (Cleary & Monaghan 1999, J. Comput. Phys. 148, 227), which reduces to Eq. (29) for
one material and carries no flux to an insulating body (k = 0):

    dT_i/dt = 1 / (rho_i c_i) sum_j 2 k_ij (T_i - T_j) (dW/dr)(r_ij) / r_ij V_j              (:func:`conduct`)

Every pair term moves heat and creates none: sum_i m_i c_i T_i is conserved to round-off.

The sources and sinks of a cutting run (:func:`thermal_step`, one explicit step after the mechanical one):

* **plastic heat** chi sigma_y epsdot_p (their Eq. (5)): added by the return map of the strength model
  (:mod:`refsph.plasticity`, Eq. (28) of the first paper), as in the adiabatic runs;
* **frictional heat** q = eta |f_fric| |v_rel| (their Eq. (7)), from the friction power of each contact pair
  (:mod:`refsph.contact`; it reaches the heat flow as ``Rates.friction_power`` of the step), split by
  :class:`FrictionHeat`: a fraction ``chip_fraction`` to the workpiece particle
  of the pair, the rest to the tool particle. The second paper does not say how it splits; the heat is made at
  the interface and conduction across it (harmonic-mean k, above) moves it to wherever the temperatures send it,
  so the split only places the source; 1/2 is the neutral choice (Blok's partition would need the contact
  temperature it is meant to predict);
* **losses** on the free surface (:class:`SurfaceLoss`, Eq. (6)), on the particles a surface detector marks
  (:mod:`refsph.surface`: the SPH detector or the alpha-shape);
* **fixed temperatures** (Dirichlet rows): the heat the reset removes is counted.

:func:`thermal_step` returns the heat of each kind it moved in the step. In a run, :class:`HeatFlow` is the
run loop's heat physics (:class:`refsph.integrate.StepPhysics`): its step limit, its step after the mechanical one,
and the heat ledger, which checks

    plastic + friction + dissipation = stored + lost + removed at fixed rows      (``summary.json``'s ``heat_balance``)

with the plastic heat counted independently of the temperatures the return map changed: chi sum_i m_i dW_p,i /
rho_i (Eq. (28) summed; W_p the plastic work density), and the stored heat sum_i m_i c_p (T_i - T_i(0)). A wrong chi
or c_p in the heating, or heat made or lost anywhere else, shows as a residual. 'dissipation' is the numerical
dissipation a run with ``Setup.dissipation_heat`` turns into heat (artificial viscosity and the penalty contact's
damping, ``Rates.heat_power``; zero otherwise): without it that work leaves the energy balance unaccounted.

The heat capacity c_p of the deformable body is the strength model's (``JohnsonCook.cp``, ``Elastic(cp=...)``): one
place for the number that both the plastic heating (Eq. (28)) and conduction (Eq. (29)) use.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .kernels import Kernel
from .neighbours import PairSum, VerletList, find_pairs
from .surface import surface_alpha_shape, surface_sph

__all__ = ["laplacian", "conduction_rate", "thermal_time_step", "advance_at_rest", "Conduction", "SurfaceLoss",
           "FrictionHeat", "HeatFlow", "coefficients", "pair_conductivity", "conduct", "thermal_step",
           "thermal_step_limit", "free_surface", "describe_heat_flow", "STEFAN_BOLTZMANN"]


def laplacian(f: np.ndarray, x: np.ndarray, V: np.ndarray, h: float, kernel: Kernel,
              pairs: tuple | None = None) -> np.ndarray:
    """Eq. (26), Brookshaw's SPH Laplacian of the particle field ``f`` (N,) at positions ``x`` (N, d) with volumes
    ``V``: lap f_i = sum_j 2 (f_i - f_j) (dW/dr)(r_ij) / r_ij V_j. ``pairs``: half pairs (I, J) within the
    support, if the caller has them (refsph's convention: I < J, each pair once)."""
    I, J, fr = _pairs_and_fr(x, h, kernel, pairs)
    t = 2.0 * (f[I] - f[J]) * fr                            # antisymmetric under i <-> j
    return PairSum(I, J, len(x)).antisymmetric(t, V)


def _pairs_and_fr(x: np.ndarray, h: float, kernel: Kernel, pairs: tuple | None = None):
    """Half pairs within the support (``pairs`` if given) and (dW/dr)/r on each: (I, J, fr)."""
    I, J = pairs if pairs is not None else find_pairs(x, kernel.support * h)
    r = np.sqrt(_distance2(x, I, J))
    return I, J, kernel.dw_dr_over_r(r, h, x.shape[1])      # zero beyond the support


def _distance2(x: np.ndarray, I: np.ndarray, J: np.ndarray) -> np.ndarray:
    """|x_I - x_J|^2 per pair, a component at a time (a gather of contiguous columns: faster than x[I] - x[J])."""
    r2 = np.zeros(len(I))
    for k in range(x.shape[1]):
        xk = np.ascontiguousarray(x[:, k])
        dk = np.take(xk, I) - np.take(xk, J)
        r2 += dk * dk
    return r2


def conduction_rate(T: np.ndarray, x: np.ndarray, V: np.ndarray, a: np.ndarray | float, h: float, kernel: Kernel,
                    pairs: tuple | None = None, source: np.ndarray | float = 0.0) -> np.ndarray:
    """Eq. (29): dT_i/dt = a_i lap T_i + S_i, a = k / (rho c_p) [m^2/s] per particle (or one value), S = Q_s /
    (rho c_p) [K/s] the heat source (plastic work; 0 by default)."""
    return np.asarray(a) * laplacian(T, x, V, h, kernel, pairs) + source


def thermal_time_step(rho: float, cp: float, k: float, h: float, factor: float) -> float:
    """The explicit conduction step rho c_p h^2 / k (the second paper's dt_t) times ``factor`` (its CFL number,
    0.25-0.4 there; stability needs about 0.1-0.3 depending on the kernel, see tests/test_thermal.py)."""
    for name, v in (("rho", rho), ("cp", cp), ("k", k), ("h", h), ("factor", factor)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be positive, got {v!r}")
    return factor * rho * cp * h * h / k


def advance_at_rest(T: np.ndarray, x: np.ndarray, V: np.ndarray, a: float, h: float, kernel: Kernel, t_end: float,
                    factor: float, rho: float, cp: float, k: float) -> tuple[np.ndarray, int]:
    """Eq. (29) alone, for particles at rest, to ``t_end``: midpoint (RK2) steps of at most
    ``thermal_time_step(rho, cp, k, h, factor)``; returns (T, number of steps). The analytic checks use it."""
    dt = thermal_time_step(rho, cp, k, h, factor)
    n = int(np.ceil(t_end / dt))
    dt = t_end / n
    pairs = find_pairs(x, kernel.support * h)
    for _ in range(n):
        k1 = conduction_rate(T, x, V, a, h, kernel, pairs)
        T = T + dt * conduction_rate(T + 0.5 * dt * k1, x, V, a, h, kernel, pairs)
    return T, n


STEFAN_BOLTZMANN = 5.670374419e-8          # W/(m^2 K^4)


@dataclass(frozen=True)
class SurfaceLoss:
    """Heat lost on free surfaces (the second paper's Eq. (6)): q = h_c (T_s - T_inf) + emissivity sigma_SB
    (T_s^4 - T_inf^4) [W/m^2], on the particles the ``detector`` marks ('sph': :func:`refsph.surface.surface_sph`;
    'alpha': :func:`refsph.surface.surface_alpha_shape` with circumradius limit ``alpha_radius`` [m]), each with
    the area V^((d-1)/d) (a spacing per unit thickness in 2D, a spacing squared in 3D). ``refresh``: in a run
    (:class:`HeatFlow`), the surface rows are found again once a particle has moved more than ``refresh`` h since
    they were last found (0: every step); the surface moves with the material, far slower than a step."""

    h_c: float
    emissivity: float
    T_ambient: float
    detector: str = "sph"
    alpha_radius: float | None = None
    refresh: float = 0.0

    def __post_init__(self):
        if not (self.h_c >= 0 and 0 <= self.emissivity <= 1 and self.T_ambient > 0):
            raise ValueError(f"SurfaceLoss needs h_c >= 0, 0 <= emissivity <= 1, T_ambient > 0; got {self}")
        if self.detector not in ("sph", "alpha"):
            raise ValueError(f"SurfaceLoss.detector must be 'sph' or 'alpha', got {self.detector!r}")
        if not (np.isfinite(self.refresh) and 0.0 <= self.refresh <= 0.5):
            raise ValueError(f"SurfaceLoss.refresh must lie in [0, 0.5] (units of h), got {self.refresh!r}")
        if self.detector == "alpha" and not (self.alpha_radius is not None and self.alpha_radius > 0):
            raise ValueError("the alpha-shape detector needs alpha_radius > 0 [m] (PFEM codes: 1.2-1.5 spacings)")

    def flux(self, T: np.ndarray) -> np.ndarray:
        """q(T) [W/m^2], Eq. (6)."""
        return self.h_c * (T - self.T_ambient) + self.emissivity * STEFAN_BOLTZMANN * (T ** 4 - self.T_ambient ** 4)


@dataclass(frozen=True)
class FrictionHeat:
    """The frictional heat of the second paper's Eq. (7), q = ``eta`` |f_fric| |v_rel| (eta: the fraction of the
    friction work that becomes heat, 1 in their Table A3), a fraction ``chip_fraction`` of it into the
    deformable particle of each contact pair, the rest into the tool particle (module text). No defaults.
    ``Setup.friction_heat``; it needs no conduction (without it the heat stays where it is made)."""

    eta: float
    chip_fraction: float

    def __post_init__(self):
        for name in ("eta", "chip_fraction"):
            v = getattr(self, name)
            if not (np.isfinite(v) and 0.0 <= v <= 1.0):
                raise ValueError(f"FrictionHeat.{name} must lie in [0, 1], got {v!r}")


@dataclass(frozen=True)
class Conduction:
    """Heat conduction during a run (``Setup.thermal``). ``k`` [W/(m K)]: the deformable bodies' conductivity (their
    heat capacity is the strength model's ``cp``); ``courant``: the factor on rho c_p h^2 / k; ``tools``: {body id:
    (k, cp)} of the rigid bodies that conduct (the others insulate); ``fixed``: particle indices held at
    ``T_fixed`` [K] (a fixed surface at room temperature); ``loss``: convection and radiation on the free surfaces
    (:class:`SurfaceLoss`; None: none)."""

    k: float
    courant: float
    tools: dict = field(default_factory=dict)
    fixed: tuple = ()
    T_fixed: float | None = None
    loss: SurfaceLoss | None = None

    def __post_init__(self):
        for name in ("k", "courant"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"Conduction.{name} must be positive, got {v!r}")
        if len(self.fixed) and self.T_fixed is None:
            raise ValueError("Conduction.fixed needs T_fixed (the temperature the fixed particles are held at)")


def coefficients(model: Conduction | None, cp: float, body: np.ndarray | None, n: int,
                 rigid_ids=()) -> tuple[np.ndarray, np.ndarray]:
    """Per-particle conductivity and heat capacity: deformable rows ``model.k`` and ``cp`` (the strength model's);
    the rows of a conducting tool its own; the rows of the other rigid bodies ``rigid_ids`` insulate (k = 0), as
    does every row without conduction (``model`` None)."""
    k, c = np.full(n, float(model.k) if model is not None else 0.0), np.full(n, float(cp))
    if body is not None and model is not None:
        for b, (kb, cb) in model.tools.items():
            k[body == b], c[body == b] = kb, cb
        k[np.isin(body, [b for b in rigid_ids if b not in model.tools])] = 0.0
    return k, c


def thermal_step_limit(state, model: Conduction, h: float, cp: float, rigid_ids=()) -> float:
    """courant * min_i rho_i c_i h^2 / k_i over the conducting particles."""
    k, c = coefficients(model, cp, state.body, state.n, rigid_ids)
    return _step_limit(state.rho, k, c, h, model.courant)


def _step_limit(rho: np.ndarray, k: np.ndarray, c: np.ndarray, h: float, courant: float) -> float:
    on = k > 0
    return float(courant * np.min(rho[on] * c[on] * h * h / k[on])) if np.any(on) else np.inf


def free_surface(x: np.ndarray, V: np.ndarray, h: float, kernel: Kernel, loss: SurfaceLoss,
                 pairs: tuple | None = None) -> np.ndarray:
    """The free-surface rows by ``loss.detector`` (every particle of the scene takes part, so that a face in contact
    with another body is not free). ``pairs``: the half pairs (at least those within the support), if the caller
    has them."""
    if loss.detector == "alpha":
        return surface_alpha_shape(x, 1.0, alpha=loss.alpha_radius)
    return surface_sph(x, V, h, kernel, pairs=pairs)


def pair_conductivity(k: np.ndarray, I: np.ndarray, J: np.ndarray) -> np.ndarray:
    """2 k_ij per half pair, k_ij = 2 k_i k_j / (k_i + k_j) the harmonic mean (module text; 0 where both are 0): the
    factor of Eq. (29)'s pair flux 2 k_ij (T_i - T_j) (dW/dr) / r, fixed while the pairs and k are."""
    kk = k[I] + k[J]
    return 2.0 * np.divide(2.0 * k[I] * k[J], kk, out=np.zeros_like(kk), where=kk > 0)


def conduct(state, model: Conduction, h: float, kernel: Kernel, dt: float, cp: float, rigid_ids=()) -> np.ndarray:
    """The temperatures after an explicit conduction step of dt (module text), fixed particles reset: the
    temperatures of :func:`thermal_step` without frictional heat."""
    k, c = coefficients(model, cp, state.body, state.n, rigid_ids)
    return thermal_step(state, model, k, c, h, kernel, dt)[0]


def thermal_step(state, model: Conduction | None, k: np.ndarray, c: np.ndarray, h: float, kernel: Kernel,
                 dt: float, friction_heat: FrictionHeat | None = None, friction_power: np.ndarray | None = None,
                 tool_rows: np.ndarray | None = None, pairs: tuple | None = None,
                 surface: np.ndarray | None = None, pair_sum: PairSum | None = None,
                 k_pair: np.ndarray | None = None) -> tuple[np.ndarray, dict]:
    """One explicit step dt of Eq. (29) with the harmonic-mean conductivity between materials (module text; ``k``,
    ``c``: per row, :func:`coefficients`; ``model`` None: no conduction), the frictional heat (``friction_power``:
    (N,) [W] per row, as the tool contact leaves it in ``Rates.friction_power``; split by ``friction_heat``:
    ``chip_fraction`` to the rows not in ``tool_rows``, the rest to the tool rows), the surface loss, then the fixed
    rows reset. Pairs are found in the current configuration, across bodies (heat flows from the chip into a
    conducting tool); ``pairs``: the half pairs, sorted by I then J, if the caller has them: all those within the
    support, and any beyond it, which add exactly nothing (the kernel's gradient is zero there: :class:`HeatFlow`
    hands over its whole Verlet list, the same sums to the bit); ``pair_sum``: the :class:`PairSum` of ``pairs``,
    if the caller keeps one; ``k_pair``: 2 k_ij of every pair of ``pairs`` (:func:`pair_conductivity`), if the
    caller keeps it; ``surface``: the free-surface rows, if the caller has them (else found here by
    ``model.loss.detector``). Returns (T, heat) with heat = {'friction', 'lost', 'removed'} [J; per
    metre of thickness in 2D] moved in the step."""
    n, d = state.x.shape
    V = state.m / state.rho
    mc = state.m * c
    heat = dict(friction=0.0, lost=0.0, removed=0.0)
    dT = np.zeros(n)
    if model is not None:
        if k_pair is not None and (pairs is None or len(k_pair) != len(pairs[0])):
            raise ValueError("thermal_step: k_pair is one value per pair of the pairs it was made for; pass those "
                             f"pairs too (got {len(k_pair)} values and "
                             f"{'no pairs' if pairs is None else f'{len(pairs[0])} pairs'})")
        I, J, fr = _pairs_and_fr(state.x, h, kernel, pairs)
        pairs = (I, J)
        if k_pair is None:
            k_pair = pair_conductivity(k, I, J)
        q = k_pair * (np.take(state.T, I) - np.take(state.T, J)) * fr      # antisymmetric pair flux
        dT = dt * (PairSum(I, J, n) if pair_sum is None else pair_sum).antisymmetric(q, V) / (state.rho * c)
    if friction_heat is not None and friction_power is not None:
        tool = np.zeros(n, bool) if tool_rows is None else tool_rows
        share = np.where(tool, friction_heat.eta * (1.0 - friction_heat.chip_fraction),
                         friction_heat.eta * friction_heat.chip_fraction)
        Q = share * dt * friction_power                             # the heat each row receives in the step [J]
        dT += Q / mc
        heat["friction"] = float(Q.sum())
    if model is not None and model.loss is not None:          # Eq. (6) on the free surface of the conducting rows
        on = (free_surface(state.x, V, h, kernel, model.loss, pairs) if surface is None else surface) & (k > 0)
        lost = dt * model.loss.flux(state.T[on]) * V[on] ** ((d - 1) / d)
        dT[on] -= lost / mc[on]
        heat["lost"] = float(lost.sum())
    T = state.T + dT
    if model is not None and len(model.fixed):
        fixed = np.asarray(model.fixed)
        heat["removed"] = float(np.sum(mc[fixed] * (T[fixed] - model.T_fixed)))
        T[fixed] = model.T_fixed
    return T, heat


LEDGER = ("plastic", "friction", "dissipation", "lost", "removed")


def dissipation_heat(T: np.ndarray, Q: np.ndarray, mc: np.ndarray, conduction: Conduction | None,
                     ledger: dict) -> np.ndarray:
    """T after the numerical dissipation's heat Q [J per row] goes into the rows it was taken from (ledger
    'dissipation'), the fixed rows reset (ledger 'removed')."""
    T = T + Q / mc
    ledger["dissipation"] += float(Q.sum())
    if conduction is not None and len(conduction.fixed):
        fixed = np.asarray(conduction.fixed)
        ledger["removed"] += float(np.sum(mc[fixed] * (T[fixed] - conduction.T_fixed)))
        T[fixed] = conduction.T_fixed
    return T


def ledger_balance(h: dict, stored: float) -> dict:
    """The heat ledger ``h`` [J] with the heat ``stored``: made (plastic, friction, dissipation), stored, lost
    (surface), removed (at fixed temperatures), and the residual made - stored - lost - removed."""
    made = h["plastic"] + h["friction"] + h["dissipation"]
    residual = made - stored - h["lost"] - h["removed"]
    return dict(plastic_J=h["plastic"], friction_J=h["friction"], dissipation_J=h["dissipation"],
                stored_J=stored, lost_J=h["lost"],
                removed_J=h["removed"], residual_J=residual, residual_rel=residual / made if made > 0 else 0.0)


class KeptHeat:
    """The heat made in the steps since the last heat step, when the heat step runs once every ``every`` mechanical
    steps (``Numerics.heat_every``): the steps' summed dt and, per row, the frictional and dissipated energies
    (power x dt), and the contact damping's energy (the ledger's part of 'dissipation'). The heat step then runs
    over the summed step with the mean powers (the same energies), so that its cost is shared by ``every`` steps: an
    operator split in which conduction lags the mechanics by at most ``every`` - 1 steps (the plastic heat of the
    return map raises T every step), and whose heat step must be stable over ``every`` steps
    (:meth:`HeatFlow.step_limit` divides the limit by ``every``, so a value above the heat step's limit in mechanical
    steps shortens the mechanical step). Snapshots between heat steps show T before the kept heat, and the heat
    kept when a run ends (at most ``every`` - 1 steps) is not applied: the ledger books heat only when it is applied,
    so the balance holds."""

    def __init__(self, every: int):
        self.every = int(every)
        self.store: dict | None = None

    def keep(self, dt: float, power, diss, damping, n: int) -> bool:
        """Keep a step's heat (its powers: None where the step made none); True when the heat step is due."""
        if self.store is None:
            self.store = dict(steps=0, dt=0.0, friction=np.zeros(n), dissipation=np.zeros(n), damping=0.0,
                              has_friction=False, has_dissipation=False, has_damping=False)
        k = self.store
        k["steps"] += 1
        k["dt"] += dt
        for name, p in (("friction", power), ("dissipation", diss)):
            if p is not None:
                k[name] += dt * p
                k["has_" + name] = True
        if damping is not None:
            k["damping"] += dt * float(damping.sum())
            k["has_damping"] = True
        return k["steps"] >= self.every

    def take(self) -> tuple:
        """(dt, friction power, dissipated power, damping power) of the steps kept: their summed step and the mean
        powers over it (the same energies); the store emptied."""
        k, self.store = self.store, None
        dt = k["dt"]
        return (dt, k["friction"] / dt if k["has_friction"] else None,
                k["dissipation"] / dt if k["has_dissipation"] else None,
                np.array([k["damping"] / dt]) if k["has_damping"] else None)

    def checkpoint(self) -> dict:
        return {} if self.store is None else {f"pending_{k}": np.asarray(v) for k, v in self.store.items()}

    def restore(self, arrays: dict) -> "KeptHeat":
        kept = {k.removeprefix("pending_"): np.asarray(arrays[k]) for k in arrays if k.startswith("pending_")}
        self.store = {k: (v.copy() if v.ndim else v.item()) for k, v in kept.items()} or None
        return self
SKIN = 0.3                                  # the heat step's Verlet skin, in units of h


class HeatFlow:
    """The heat of a run as a physics the run loop steps (:class:`refsph.integrate.StepPhysics`): conduction
    (``conduction``, or None), frictional heat (``friction_heat``, or None) and the heat ledger (module text).
    ``cp``, ``chi``: the deformable body's heat capacity and Taylor-Quinney coefficient (the strength model's; chi
    0 when the law does not heat); ``rigid_ids``: the rigid bodies' ids; ``h``, ``kernel``: the run's;
    ``dissipation_heat``: the numerical dissipation of the step's rates (``Rates.heat_power``: artificial viscosity,
    contact damping) heats the row it was taken from (ledger entry 'dissipation'); ``every``: the heat step runs
    once every this many mechanical steps (:class:`KeptHeat`)."""

    name = "heat"

    def __init__(self, conduction: Conduction | None, friction_heat: FrictionHeat | None, cp: float, chi: float,
                 h: float, kernel: Kernel, rigid_ids=(), *, dissipation_heat: bool = False, every: int = 1):
        if not (cp is not None and np.isfinite(cp) and cp > 0):
            raise ValueError("heat conduction and frictional heat need the body's heat capacity: the strength "
                             f"model's cp (JohnsonCook(cp=...), Elastic(cp=...)), got {cp!r}")
        self.conduction, self.friction_heat, self.cp, self.chi = conduction, friction_heat, float(cp), float(chi)
        self.h, self.kernel, self.rigid_ids = h, kernel, tuple(rigid_ids)
        self.dissipation_heat = bool(dissipation_heat)
        self.surface = self.surface_x = None               # the free-surface rows and where they were found
        self.ledger = {k: 0.0 for k in LEDGER}
        self.damping: float | None = 0.0                      # the contact damping's part of 'dissipation' [J]
        self.k = self.c = self.mc = self.T0 = self.tool_rows = None
        self.pairs = VerletList(kernel.support * h, SKIN * h)   # the heat step's pair search (module text)
        self.pair_sum = self.k_pair = None                    # the Verlet list's PairSum and its pairs' 2 k_ij
        self.rho_of_return_map = "start"
        self.every = int(every)
        self.kept = KeptHeat(self.every) if self.every > 1 else None   # the heat made since the last heat step

    def bind(self, state, solver) -> None:
        """Per-row k and c (constant through a run), the initial temperatures, and which density the solver's
        return map uses (ESPH integrates rho: the end of the step's; TLSPH: the start's, Eq. (2))."""
        if state.T is None:
            raise ValueError("heat conduction and frictional heat need temperatures: make_state(..., T0=...)")
        self.k, self.c = coefficients(self.conduction, self.cp, state.body, state.n, self.rigid_ids)
        self.mc = state.m * self.c
        self.T0 = state.T.copy()
        self.tool_rows = None if state.body is None else np.isin(state.body, self.rigid_ids)
        self.rho_of_return_map = "end" if "rho" in getattr(solver, "evolved", ()) else "start"
        self.pair_sum = self.k_pair = None                    # made again from this run's pairs and k

    def step_limit(self, state) -> float:
        if self.conduction is None:
            return np.inf
        return _step_limit(state.rho, self.k, self.c, self.h, self.conduction.courant) / self.every

    def plastic_heat(self, before, after) -> float:
        """chi sum_i m_i (W_p,i(after) - W_p,i(before)) / rho_i [J]: the plastic heat of a step (Eq. (28) summed),
        from the plastic work alone."""
        if self.chi == 0.0 or after.W_p is None:
            return 0.0
        rho = after.rho if self.rho_of_return_map == "end" else before.rho
        return float(self.chi * np.sum(after.m * (after.W_p - before.W_p) / rho))

    def advance(self, before, step, dt: float):
        """The heat step after the mechanical one (``step``: :class:`refsph.integrate.Step`): the ledger takes the
        plastic heat, then conduction, frictional heat, losses and fixed rows move the temperatures (or, between
        heat steps, the step's heat is kept: :class:`KeptHeat`)."""
        after = step.state
        self.ledger["plastic"] += self.plastic_heat(before, after)
        rates = step.rates
        power = rates.friction_power if rates is not None else None
        diss = rates.heat_power if self.dissipation_heat and rates is not None else None
        damping = rates.damping_power if diss is not None and self.damping is not None else None
        if self.kept is not None:
            if not self.kept.keep(dt, power, diss, damping, after.n):
                return after                                # the heat step is not due: T as the mechanics left it
            dt, power, diss, damping = self.kept.take()
        pairs, pair_sum = self.pairs_and_sum(after.x)
        T, moved = thermal_step(after, self.conduction, self.k, self.c, self.h, self.kernel, dt, self.friction_heat,
                                power, self.tool_rows, pairs, self.surface_rows(after, pairs), pair_sum, self.k_pair)
        for key, val in moved.items():
            self.ledger[key] += val
        if diss is not None:
            T = dissipation_heat(T, dt * diss, self.mc, self.conduction, self.ledger)
            if damping is not None:
                self.damping += dt * float(damping.sum())
        after.T = T
        return after

    def surface_rows(self, state, pairs) -> np.ndarray | None:
        """The free-surface rows of the losses (``SurfaceLoss.refresh``): found again once a particle has moved more
        than refresh h since the last time; None (thermal_step finds them) with refresh 0 or no losses."""
        loss = None if self.conduction is None else self.conduction.loss
        if loss is None or loss.refresh == 0.0:
            return None
        if self.surface is not None and len(self.surface) == state.n:
            moved = state.x - self.surface_x
            if np.max(np.einsum("nd,nd->n", moved, moved)) <= (loss.refresh * self.h) ** 2:
                return self.surface
        self.surface = free_surface(state.x, state.m / state.rho, self.h, self.kernel, loss, pairs)
        self.surface_x = state.x.copy()
        return self.surface

    def pairs_and_sum(self, x: np.ndarray) -> tuple:
        """((I, J), their :class:`PairSum`): the half pairs of a Verlet list (cutoff the support, a skin of
        ``SKIN`` h, rebuilt when a particle has moved half the skin), sorted by I then J, and the sparse pattern of
        their sums, both kept until the list is rebuilt, and with them the pairs' 2 k_ij (``k_pair``). The pairs
        beyond the support add exactly nothing to the sums (the kernel is zero there), and the pairs within it are
        those of a fresh search (:func:`refsph.neighbours.find_pairs`) in the same order: the same sums to the bit,
        without a k-d tree, a distance filter or a new sparse pattern every step. (None, None) without conduction."""
        if self.conduction is None:
            return None, None
        builds = self.pairs.n_builds
        I, J = self.pairs.update(x)
        if self.pair_sum is None or self.pairs.n_builds != builds:
            self.pair_sum = PairSum(I, J, len(x))
            self.k_pair = pair_conductivity(self.k, I, J)
        return (I, J), self.pair_sum

    def balance(self, state) -> dict:
        """The heat ledger [J; per metre of thickness in 2D]: made (plastic, friction, dissipation), stored
        (sum m c (T - T0)), lost (surface), removed (at fixed temperatures), and the residual
        made - stored - lost - removed."""
        return ledger_balance(self.ledger, float(np.sum(self.mc * (state.T - self.T0))))

    def record(self, state) -> dict:
        return {f"heat_{k}": v for k, v in self.balance(state).items()}

    def summary(self, state) -> dict:
        """The ledger (:meth:`balance`) and, apart, the two sources of its 'dissipation' [J; per metre in 2D]: the
        tool contact's damping and the artificial viscosity (the rest); None where the run was continued from a
        checkpoint that did not keep them apart."""
        out = dict(heat_balance=self.balance(state))
        if self.dissipation_heat:
            d = self.damping
            out["heat_dissipation"] = dict(contact_damping_J=d,
                                           viscosity_J=None if d is None else self.ledger["dissipation"] - d)
        return out

    def describe(self) -> dict:
        """What summary.json says of the heat model (JSON-ready): :func:`describe_heat_flow`."""
        return describe_heat_flow(self)

    def checkpoint(self) -> dict:
        ck = {k: np.float64(v) for k, v in self.ledger.items()}
        if self.damping is not None:
            ck["damping"] = np.float64(self.damping)
        if self.surface is not None:
            ck.update(surface=self.surface.copy(), surface_x=self.surface_x.copy())
        ck.update(self.kept.checkpoint() if self.kept is not None else {})
        return ck

    def restore(self, arrays: dict) -> None:
        self.ledger = {k: float(arrays[k]) if k in arrays else 0.0 for k in LEDGER}   # (older: no 'dissipation')
        self.damping = float(arrays["damping"]) if "damping" in arrays else (          # (older: not kept apart)
            None if self.ledger["dissipation"] > 0.0 else 0.0)
        if "surface" in arrays:
            self.surface, self.surface_x = np.array(arrays["surface"], dtype=bool), np.array(arrays["surface_x"])
        self.kept = self.kept and self.kept.restore(arrays)


def describe_heat_flow(flow: HeatFlow) -> dict:
    """What summary.json says of a :class:`HeatFlow`'s heat model (JSON-ready)."""
    out = dict(cp=flow.cp, chi=flow.chi)
    if flow.conduction is not None:
        c = flow.conduction
        out["conduction"] = dict(k=c.k, courant=c.courant, tools={str(b): list(v) for b, v in c.tools.items()},
                                 n_fixed=len(c.fixed), T_fixed=c.T_fixed,
                                 loss=None if c.loss is None else {f: getattr(c.loss, f) for f in
                                                                   ("h_c", "emissivity", "T_ambient", "detector",
                                                                    "alpha_radius")})
    if flow.friction_heat is not None:
        out["friction_heat"] = dict(eta=flow.friction_heat.eta, chip_fraction=flow.friction_heat.chip_fraction)
    if flow.dissipation_heat:
        out["dissipation_heat"] = True
    return out
