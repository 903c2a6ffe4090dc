"""Johnson-Cook viscoplasticity and adiabatic heating (Section 2.3.1, Eqs. (25)-(31)).

    Eq. (25)  sigma_y = [A + B eps_p^n] [1 + C ln(epsdot*)] [1 - T*^m]
    Eq. (26)  epsdot* = epsdot / epsdot_0
    Eq. (27)  T*      = (T - T_r) / (T_m - T_r)
              y_f     = sqrt(J2) - sigma_y / sqrt(3),  J2 = s:s / 2           (von Mises yield function)
              s_n     = c_f s,   c_f = min(sigma_y / sqrt(3 J2), 1)          (Wilkins radial return)
    Eq. (29)  d eps_pl  = (1 - c_f) / (2 mu) s                               (plastic strain increment)
    Eq. (30)  d eps_p   = sqrt(2/3 d eps_pl : d eps_pl) = (1 - c_f) / (3 mu) sqrt(3/2 s : s)
    Eq. (31)  d w_p     = d eps_pl : s_n                                     (plastic work density)
    Eq. (28)  d T       = chi d w_p / (rho C_p),  chi = 0.9                  (adiabatic heating)

Here s is the *trial* deviatoric stress (the elastic update of the step), s_n the returned one, eps_p the
accumulated effective plastic strain. Eq. (31) gives d w_p = sigma_y d eps_p once s_n is on the yield surface.

Where the paper is silent or loose, refsph does the standard thing:

* **Eq. (28)** is printed as dT/dt = chi W_p / (rho C_p) with W_p the accumulated work; dimensionally it is
  the increment form dT = chi dw_p / (rho C_p) (the issue's and every code's form), which is what refsph uses.
* **log** in Eq. (25) is the natural logarithm (Johnson & Cook 1983).
* **epsdot* < 1**: ln(epsdot*) is negative and unbounded below as the rate goes to zero (a particle that stops
  flowing would get a yield stress that goes to -infinity). refsph uses ln(max(epsdot*, 1)): no rate effect below
  the reference rate, as in Abaqus (Analysis User's Guide, "Johnson-Cook plasticity": the rate factor is 1 for
  rates below epsdot_0) and in LS-DYNA's *MAT_JOHNSON_COOK.
* **Which rate** enters Eq. (26): the paper says the effective plastic strain rate, which is not known before the
  return map of the step. Using the previous step's plastic rate makes an explicit code chatter (no flow ->
  low yield -> much flow -> high yield). refsph uses the equivalent deviatoric strain rate of the step,
  epsdot = sqrt(2/3 e':e'), e' the deviatoric part of (l + l^T)/2, which is the plastic rate wherever the
  material flows (the elastic part is O(sigma_y / E) of it). This is LS-DYNA's default (VP = 0, "scale yield
  stress", total strain rate).
* **T* outside [0, 1]**: T* < 0 is taken as 0 (no hardening below room temperature) and T* >= 1 gives
  sigma_y = 0 (melted), as in Abaqus and LS-DYNA.
* **epsdot_0** is not printed in Table 1; Johnson & Cook's 4340 data use 1 /s, which refsph uses for Taylor.

The **modified** Johnson-Cook law of Rodriguez Prieto, Larsson & Afrasiabi (Eqs. (8)-(9) of their paper): the
hardening term stops growing past a saturation strain (2 for AISI 1045), A + B min(eps_p, eps_sat)^n. It is
:class:`ModifiedJohnsonCook`.

Every law here is a strength model of :mod:`refsph.strength` (the one interface the solvers call);
:func:`refsph.strength.plastic_update` is the return map of a step for any of them.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field, fields

import numpy as np

from .state import PLASTIC_FIELDS

__all__ = ["J2Plasticity", "JohnsonCook", "ModifiedJohnsonCook", "homologous_temperature", "yield_stress",
           "equivalent_strain_rate", "radial_return", "plastic_strain_increment", "effective_plastic_strain_increment",
           "plastic_work_increment", "temperature_increment"]


class J2Plasticity:
    """Von Mises plasticity with Wilkins' radial return (Eqs. (29)-(31)) for any flow stress: the shared part of
    every plasticity law of the strength-model seam (:mod:`refsph.strength`). A subclass gives
    ``flow_stress(eps_p, eps_dot, T)`` [Pa] and, for the heating of Eq. (28), the attributes ``chi`` and ``cp``;
    ``heating`` (True unless the subclass says otherwise) switches that heating."""

    state_fields: tuple = PLASTIC_FIELDS
    heating: bool = True

    def flow_stress(self, eps_p, eps_dot, T):
        raise NotImplementedError

    def return_map(self, S, S_zz, eps_p, eps_dot, T, G: float):
        """Eqs. (29)-(31): s_n = c_f s, c_f = min(sigma_y / sqrt(3 J2), 1); returns (S_n, S_zz_n, d_eps_p, d_w_p)."""
        sy = self.flow_stress(eps_p, eps_dot, T)
        cf, S_n, S_zz_n, svm = radial_return(S, S_zz, sy)
        return S_n, S_zz_n, effective_plastic_strain_increment(svm, cf, G), plastic_work_increment(svm, cf, G)

    def heat(self, d_w_p, rho):
        """Eq. (28): d T = chi d w_p / (rho C_p); zero with ``heating`` off (isothermal)."""
        if not self.heating:
            return np.zeros_like(d_w_p)
        return temperature_increment(d_w_p, rho, self)


@dataclass(frozen=True)
class JohnsonCook(J2Plasticity):
    """Johnson-Cook constants (Eq. (25)), SI units; no defaults (Table 1 / Table 3 of the paper).

    A, B [Pa], n, C, m [-], eps_dot_0 [1/s], T_room, T_melt [K], cp [J/(kg K)], chi (Taylor-Quinney) [-].
    ``heating`` (keyword, a switch, not a constant): plastic work heats the material (Eq. (28)); False: isothermal.
    """

    A: float
    B: float
    n: float
    C: float
    m: float
    eps_dot_0: float
    T_room: float
    T_melt: float
    cp: float
    chi: float
    heating: bool = field(default=True, kw_only=True)

    def __post_init__(self):
        for name in ("A", "B", "n", "C", "m", "eps_dot_0", "T_room", "T_melt", "cp", "chi"):
            val = getattr(self, name)
            if val is None or isinstance(val, bool) or not isinstance(val, numbers.Real) or not math.isfinite(val):
                raise ValueError(f"Johnson-Cook constant {name} must be a finite number, got {val!r}")
        for name in ("A", "eps_dot_0", "T_room", "cp", "m"):
            if not getattr(self, name) > 0:
                raise ValueError(f"Johnson-Cook constant {name} must be positive, got {getattr(self, name)!r}")
        for name in ("B", "n", "C"):
            if getattr(self, name) < 0:
                raise ValueError(f"Johnson-Cook constant {name} must not be negative, got {getattr(self, name)!r}")
        if not self.T_melt > self.T_room:
            raise ValueError(f"T_melt ({self.T_melt!r} K) must exceed T_room ({self.T_room!r} K)")
        if not 0.0 <= self.chi <= 1.0:
            raise ValueError(f"Taylor-Quinney coefficient chi must lie in [0, 1], got {self.chi!r}")
        if not isinstance(self.heating, (bool, np.bool_)):
            raise ValueError(f"heating must be True or False, got {self.heating!r}")

    @classmethod
    def from_dict(cls, d: dict) -> "JohnsonCook":
        """From a dict with every constant named (and optionally ``heating``); a missing key is named in the
        error."""
        names = cls.constants()
        missing = [k for k in names if k not in d]
        if missing:
            raise ValueError(f"missing Johnson-Cook constant(s): {', '.join(missing)}")
        unknown = sorted(set(d) - set(names) - {"heating"})
        if unknown:
            raise ValueError(f"unknown Johnson-Cook constant(s): {', '.join(unknown)}")
        return cls(**{k: d[k] for k in names}, heating=bool(d.get("heating", True)))

    @classmethod
    def constants(cls) -> list[str]:
        """The names of the law's material constants (its fields but the ``heating`` switch)."""
        return [f.name for f in fields(cls) if f.name != "heating"]

    def hardening_strain(self, eps_p: np.ndarray) -> np.ndarray:
        """The plastic strain that enters the hardening term of Eq. (25): eps_p itself."""
        return eps_p

    def flow_stress(self, eps_p, eps_dot, T):
        """Eq. (25), see :func:`yield_stress`."""
        return yield_stress(self, eps_p, eps_dot, T)


@dataclass(frozen=True)
class ModifiedJohnsonCook(JohnsonCook):
    """The modified Johnson-Cook law of Rodriguez Prieto, Larsson & Afrasiabi (their Eqs. (8)-(9)): Eq. (25) with
    the hardening term frozen past ``hardening_saturation_strain`` (2 for their AISI 1045),
    A + B min(eps_p, eps_sat)^n."""

    hardening_saturation_strain: float

    def __post_init__(self):
        super().__post_init__()
        s = self.hardening_saturation_strain
        if isinstance(s, bool) or not isinstance(s, numbers.Real) or not math.isfinite(s) or not s > 0:
            raise ValueError(f"hardening_saturation_strain must be a positive number, got {s!r}")

    def hardening_strain(self, eps_p: np.ndarray) -> np.ndarray:
        """min(eps_p, eps_sat) (their Eq. (9))."""
        return np.minimum(eps_p, self.hardening_saturation_strain)


def homologous_temperature(T, T_room: float, T_melt: float):
    """Eq. (27): T* = (T - T_r) / (T_m - T_r) (not clipped here; :func:`yield_stress` clips it)."""
    return (np.asarray(T, dtype=float) - T_room) / (T_melt - T_room)


def yield_stress(jc: JohnsonCook, eps_p, eps_dot, T):
    """Eq. (25): sigma_y = [A + B eps_p^n] [1 + C ln(max(epsdot*, 1))] [1 - T*^m], T* clipped to [0, 1].

    eps_p: accumulated effective plastic strain; eps_dot: equivalent strain rate [1/s] (Eq. (26) with
    epsdot* = eps_dot / eps_dot_0); T: temperature [K]. A :class:`ModifiedJohnsonCook` caps eps_p at its saturation
    strain (``jc.hardening_strain``). Arrays broadcast.
    """
    eps_p = jc.hardening_strain(np.maximum(np.asarray(eps_p, dtype=float), 0.0))
    hardening = jc.A + jc.B * eps_p**jc.n
    rate = 1.0 + jc.C * np.log(np.maximum(np.asarray(eps_dot, dtype=float) / jc.eps_dot_0, 1.0))
    Ts = np.clip(homologous_temperature(T, jc.T_room, jc.T_melt), 0.0, 1.0)
    thermal = 1.0 - Ts**jc.m
    return hardening * rate * thermal


def equivalent_strain_rate(l: np.ndarray) -> np.ndarray:
    """sqrt(2/3 e':e') with e' the deviatoric part of eps_dot = (l + l^T)/2 (Eq. (21)), for l (N, d, d).

    In 2D plane strain eps_dot_zz = 0 but its deviatoric part -tr/3 is not, and it is included."""
    n, d, _ = l.shape
    D = 0.5 * (l + np.swapaxes(l, 1, 2))
    tr = np.trace(D, axis1=1, axis2=2)
    ee = np.einsum("nab,nab->n", D, D) - tr * tr / 3.0     # e':e' = D:D - tr^2/3 (zz included in 2D)
    return np.sqrt(np.maximum(2.0 / 3.0 * ee, 0.0))


def radial_return(S: np.ndarray, S_zz: np.ndarray, sigma_y: np.ndarray):
    """Wilkins return: c_f = min(sigma_y / sqrt(3 J2), 1), s_n = c_f s. Returns (c_f, S_n, S_zz_n, sigma_vm_trial).

    J2 = s:s/2 includes the plane-strain S_zz in 2D (3D: S_zz is zero and unused)."""
    ss = np.einsum("nab,nab->n", S, S)
    if S.shape[1] == 2:
        ss = ss + S_zz * S_zz
    svm = np.sqrt(1.5 * ss)                                 # sqrt(3 J2)
    with np.errstate(divide="ignore", invalid="ignore"):
        cf = np.where(svm > sigma_y, sigma_y / np.where(svm > 0, svm, 1.0), 1.0)
    return cf, S * cf[:, None, None], S_zz * cf, svm


def plastic_strain_increment(S_trial: np.ndarray, cf: np.ndarray, G: float) -> np.ndarray:
    """Eq. (29): d eps_pl = (1 - c_f) / (2 mu) s for the (N, d, d) stress given (in 2D the in-plane block; the
    out-of-plane part, (1 - c_f) s_zz / (2 mu), is obtained by passing S_zz[:, None, None])."""
    return ((1.0 - cf) / (2.0 * G))[:, None, None] * S_trial


def effective_plastic_strain_increment(svm_trial: np.ndarray, cf: np.ndarray, G: float) -> np.ndarray:
    """Eq. (30): d eps_p = (1 - c_f) / (3 mu) sqrt(3/2 s:s) = (1 - c_f) sigma_vm_trial / (3 mu)."""
    return (1.0 - cf) * svm_trial / (3.0 * G)


def plastic_work_increment(svm_trial: np.ndarray, cf: np.ndarray, G: float) -> np.ndarray:
    """Eq. (31): d w_p = d eps_pl : s_n = (1 - c_f) c_f s:s / (2 mu) = (1 - c_f) c_f sigma_vm_trial^2 / (3 mu)."""
    return (1.0 - cf) * cf * svm_trial * svm_trial / (3.0 * G)


def temperature_increment(dw_p: np.ndarray, rho: np.ndarray, jc) -> np.ndarray:
    """Eq. (28), increment form: dT = chi d w_p / (rho C_p) (``jc``: any law with ``chi`` and ``cp``)."""
    return jc.chi * dw_p / (rho * jc.cp)
