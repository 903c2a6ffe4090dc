"""Elastic material and the hypoelastic constitutive update (Section 2.3, Eqs. (20)-(24)).

    Eq. (21)  eps_dot = (l + l^T) / 2                      strain rate
    Eq. (22)  omega   = (l - l^T) / 2                      spin
    Eq. (20)  s_dot   = 2 G (eps_dot - tr(eps_dot)/3 I) + omega s - s omega     (Jaumann rate)
    Eq. (24)  p       = K (rho / rho0 - 1)                 linear equation of state
              sigma   = s - p I

Here l_ab = d v_a / d x_b. The paper prints the spin terms as ``s omega - omega s``; that is the same law
when the velocity gradient is written l_ab = d v_b / d x_a (then omega changes sign). With l_ab = dv_a/dx_b,
``omega s - s omega`` is the one that makes the stress co-rotate with a rigid rotation (tested).

Plane strain (2D): l_zz = 0, so the zz deviatoric component evolves as s_zz_dot = -2 G tr(eps_dot) / 3 and
the spin terms do not touch it. It is carried in ``S_zz``.
"""
from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from .tensor import component_major, matmul, transpose

__all__ = [
    "ElasticMaterial",
    "eos_pressure",
    "strain_rate_and_spin",
    "jaumann_deviatoric_rate",
    "von_mises",
    "cauchy_stress",
]


@dataclass(frozen=True)
class ElasticMaterial:
    """Isotropic linear elastic constants, SI units. No defaults: every constant must be given.

    rho0 -- rest density [kg/m^3]; E -- Young's modulus [Pa]; nu -- Poisson's ratio [-].
    """

    rho0: float
    E: float
    nu: float

    def __post_init__(self):
        for name in ("rho0", "E", "nu"):
            val = getattr(self, name)
            if val is None or not isinstance(val, (int, float)) or not math.isfinite(val):
                raise ValueError(f"material constant {name} must be a finite number, got {val!r}")
        if self.rho0 <= 0:
            raise ValueError(f"material constant rho0 must be positive, got {self.rho0!r}")
        if self.E <= 0:
            raise ValueError(f"material constant E must be positive, got {self.E!r}")
        if not -1.0 < self.nu < 0.5:
            raise ValueError(f"material constant nu must lie in (-1, 0.5), got {self.nu!r}")

    @classmethod
    def from_shear_bulk(cls, rho0: float, G: float, K: float) -> "ElasticMaterial":
        """From shear modulus G and bulk modulus K (Table 1 of the paper gives mu and K)."""
        for name, val in (("G", G), ("K", K)):
            if val is None or not val > 0:
                raise ValueError(f"material constant {name} must be positive, got {val!r}")
        E = 9.0 * K * G / (3.0 * K + G)
        nu = (3.0 * K - 2.0 * G) / (2.0 * (3.0 * K + G))
        return cls(rho0=rho0, E=E, nu=nu)

    @classmethod
    def from_dict(cls, d: dict) -> "ElasticMaterial":
        """From {'rho0', 'E', 'nu'} or {'rho0', 'G', 'K'}; a missing key is named in the error."""
        if "rho0" not in d:
            raise ValueError("missing material constant 'rho0'")
        if "E" in d or "nu" in d:
            for k in ("E", "nu"):
                if k not in d:
                    raise ValueError(f"missing material constant {k!r}")
            return cls(rho0=d["rho0"], E=d["E"], nu=d["nu"])
        for k in ("G", "K"):
            if k not in d:
                raise ValueError(f"missing material constant {k!r} (give E and nu, or G and K)")
        return cls.from_shear_bulk(d["rho0"], d["G"], d["K"])

    @property
    def G(self) -> float:
        """Shear modulus mu = E / (2 (1 + nu))."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def K(self) -> float:
        """Bulk modulus K = E / (3 (1 - 2 nu))."""
        return self.E / (3.0 * (1.0 - 2.0 * self.nu))

    @property
    def c0(self) -> float:
        """Sound speed used by the paper in the artificial viscosity, C = sqrt(E / rho) (after Eq. (13))."""
        return math.sqrt(self.E / self.rho0)

    @property
    def c_longitudinal(self) -> float:
        """Dilatational wave speed sqrt((K + 4G/3) / rho0): the fastest signal, used for the CFL step."""
        return math.sqrt((self.K + 4.0 * self.G / 3.0) / self.rho0)

    def c_bar(self, dim: int) -> float:
        """Long-wavelength speed of an axial wave in a slender bar with free sides:
        sqrt(E / rho0) in 3D, sqrt(E / ((1 - nu^2) rho0)) in 2D plane strain."""
        if dim == 3:
            return math.sqrt(self.E / self.rho0)
        return math.sqrt(self.E / ((1.0 - self.nu**2) * self.rho0))


def eos_pressure(rho: np.ndarray, rho0: float, K: float) -> np.ndarray:
    """Eq. (24): p = K (rho / rho0 - 1)."""
    return K * (rho / rho0 - 1.0)


def strain_rate_and_spin(l: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eqs. (21)-(22): eps_dot = (l + l^T)/2, omega = (l - l^T)/2, for l of shape (N, d, d)."""
    lT = transpose(l)
    return 0.5 * (l + lT), 0.5 * (l - lT)


def jaumann_deviatoric_rate(S: np.ndarray, S_zz: np.ndarray, l: np.ndarray, G: float):
    """Eq. (20): s_dot = 2 G (eps_dot - tr(eps_dot)/3 I) + omega s - s omega.

    S is the (N, d, d) deviatoric stress, S_zz the plane-strain out-of-plane component (2D), l the
    velocity gradient l_ab = dv_a/dx_b. Returns (dS, dS_zz), dS stored component-major (see
    :mod:`refsph.tensor`). In 3D dS_zz is zero (S_zz unused).

    In 2D the spin has one component, omega = [[0, w], [-w, 0]] with w = (l_01 - l_10)/2, and the
    spin terms are written out:  omega s - s omega = w [[s_01 + s_10, s_11 - s_00], [s_11 - s_00, -(s_01 + s_10)]].
    """
    n, d, _ = l.shape
    S = component_major(S)
    l = component_major(l)
    eps_dot, omega = strain_rate_and_spin(l)
    tr = eps_dot[:, 0, 0] + eps_dot[:, 1, 1]
    if d == 3:
        tr += eps_dot[:, 2, 2]
    dS = 2.0 * G * eps_dot
    for a in range(d):
        dS[:, a, a] -= (2.0 * G / 3.0) * tr
    if d == 2:
        w = omega[:, 0, 1]
        on_diagonal = w * (S[:, 0, 1] + S[:, 1, 0])
        off_diagonal = w * (S[:, 1, 1] - S[:, 0, 0])
        dS[:, 0, 0] += on_diagonal
        dS[:, 1, 1] -= on_diagonal
        dS[:, 0, 1] += off_diagonal
        dS[:, 1, 0] += off_diagonal
        dS_zz = -(2.0 * G / 3.0) * tr
    else:
        dS += matmul(omega, S) - matmul(S, omega)
        dS_zz = np.zeros(n)
    return dS, dS_zz


def cauchy_stress(S: np.ndarray, p: np.ndarray) -> np.ndarray:
    """sigma = s - p I (in-plane block in 2D); a new component-major stack."""
    sigma = component_major(S, copy=True)
    for a in range(S.shape[1]):
        sigma[:, a, a] -= p
    return sigma


def von_mises(S: np.ndarray, S_zz: np.ndarray) -> np.ndarray:
    """sigma_vm = sqrt(3 J2), J2 = s:s / 2, with the out-of-plane component in 2D plane strain."""
    ss = np.einsum("nab,nab->n", S, S)
    if S.shape[1] == 2:
        ss = ss + S_zz**2
    return np.sqrt(1.5 * ss)
