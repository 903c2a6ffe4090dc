"""Pinball contact of TLSPH (Section 2.4, Eqs. (32)-(36)), with a place for a friction law.

TLSPH cannot let two bodies meet through the SPH sums (its kernels live in each body's reference
configuration), so the paper adds the pinball contact of Campbell, Vignjevic & Libersky (2000, Comput. Methods
Appl. Mech. Engrg. 184, 49) and Belytschko & Yeh (1993, ibid. 105, 375). Every particle carries a pinball of
radius R = k h. For a particle i of one body and j of another, with x_ij = x_i - x_j, r = |x_ij| and
e_ij = x_ij / r:

    Eq. (32)  p_d = (R_i + R_j) - r                                   penetration (contact if p_d > 0)
    Eq. (33)  F_ij = K_p min(F1_ij, F2_ij)
    Eq. (34)  F1_ij = m_ij pdot_d / dt   if pdot_d > 0, else 0        stop the approach within one step
    Eq. (35)  F2_ij = mu_ij sqrt(R_i R_j / (R_i + R_j)) p_d^1.5        Hertz
    Eq. (36)  dv_i/dt += e_ij F_ij / m_i,   dv_j/dt -= e_ij F_ij / m_j  (equal and opposite)

What is implemented, exactly, where the printed equations leave a choice:

- **Penetration rate.** The paper prints pdot_d = |vdot_i - vdot_j| (accelerations, and never negative, so the
  case pdot_d < 0 of Eq. (34) could not occur). We use the rate of Eq. (32): pdot_d = -(v_i - v_j) . e_ij,
  positive while the particles approach. With it Eq. (34) is the force that removes the approach velocity of
  the pair within one step (the pinball idea), and zero while they separate.
- **Effective mass.** Eq. (34) prints rho_i rho_j R_i^3 R_j^3 / (rho_i R_i^3 + rho_j R_j^3), the reduced mass
  of two spheres up to the factor 4 pi / 3. We use the particles' own masses, m_ij = m_i m_j / (m_i + m_j), so
  that F1 stops the approach of the particles as they are (and has the right units in 2D, where masses are
  per unit thickness). For a rigid partner (m_j = infinity) m_ij = m_i.
- **Hertz modulus.** mu is the shear modulus (the units of Eq. (35) need a modulus; the paper's Table 3 gives E
  and nu, from which G = E / (2 (1 + nu))); mu_ij = mu_i mu_j / (mu_i + mu_j), = mu_i for a rigid partner.
- **2D.** Eq. (35) is a force between spheres. In plane strain a particle stands for a row of particles at
  spacing dp through the thickness, so the force per unit thickness is F2 / dp (Eq. (34) is per unit thickness
  already, through the masses).
- **Influence radius.** R = k h with k = dp / (2 h) (1/3 for h = 1.5 dp): two bodies whose surface particles
  sit one spacing apart are just touching, as their faces (centres +- dp/2) are. K_p = 50 (``Numerics.contact_Kp``).
  Both are chosen in chapter 05 by the bounce test there (penetration, impulse, rebound against k and K_p):
  because Eq. (34) acts only while the particles approach, K_p = 1 dissipates nearly all of an elastic
  rebound; the rebound converges from K_p ~ 20 on, and from K_p ~ 500 the contact spring is too stiff for
  the CFL step. K_p > 1 also makes the on/off switch of Eq. (34) amplify round-off (chapter 07).
- **Time step.** dt in Eq. (34) is the step size of the step being taken (both rate evaluations of the
  predictor-corrector step use it).

The force is along the line of centres and, for each pair, equal and opposite; the sum over a rigid body's
particles is the force on the body. Without friction nothing acts along the surface.

**Friction (off by default).** A :class:`CoulombFriction` adds, per contact pair, a tangential force against
the relative sliding velocity v_t = v_ij - (v_ij . e) e (second paper, Rodriguez Prieto, Larsson & Afrasiabi,
Eqs. (10)-(11)):

    f_t = - min(mu(T) F_ij, m_ij |v_t| / dt) v_t / |v_t|,   mu(T) = mu0 (1 - ((T - T_r)/(T_m - T_r))^q)

with T the temperature of the deformable particle. The cap m_ij |v_t| / dt (sticking) keeps friction from
reversing the sliding within a step. The friction power of each pair, |f_t| |v_t| [W; per metre of thickness in
2D], is returned per particle on both sides (``ContactResult.friction_power_a`` / ``_b``): the frictional heat
of their Eq. (7), q = eta |f_fric| |v_rel|, which :mod:`refsph.thermal` deposits when a run conducts heat.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["PinballContact", "CoulombFriction", "ContactResult", "penetration", "penetration_rate",
           "rate_force", "hertz_force", "pinball_force", "pinball_contact", "reduced"]


@dataclass(frozen=True)
class CoulombFriction:
    """Coulomb friction with a temperature-dependent coefficient (second paper, Eqs. (10)-(11)):
    mu(T) = mu0 (1 - ((T - T_room)/(T_melt - T_room))^q), clipped to [0, mu0]. No defaults (material data)."""

    mu0: float
    q: float
    T_room: float
    T_melt: float

    def __post_init__(self):
        for name in ("mu0", "q", "T_room", "T_melt"):
            val = getattr(self, name)
            if not (np.isfinite(val) and val >= 0):
                raise ValueError(f"friction {name} must be a non-negative number, got {val!r}")
        if not self.q > 0:
            raise ValueError(f"friction exponent q must be positive (q = 0 gives mu = 0), got {self.q!r}")
        if not self.T_melt > self.T_room > 0:
            raise ValueError(f"friction needs 0 < T_room < T_melt, got {self.T_room!r}, {self.T_melt!r}")

    def mu(self, T: np.ndarray) -> np.ndarray:
        """Eq. (11): mu0 (1 - T*^q), T* = (T - T_r)/(T_m - T_r) clipped to [0, 1]."""
        Ts = np.clip((np.asarray(T, dtype=float) - self.T_room) / (self.T_melt - self.T_room), 0.0, 1.0)
        return self.mu0 * (1.0 - Ts**self.q)


@dataclass(frozen=True)
class PinballContact:
    """Parameters of Eqs. (32)-(36): pinball radius R = ``k`` h, scaling factor ``K_p``, ``friction`` (None:
    frictionless, the paper's choice)."""

    k: float
    K_p: float
    friction: CoulombFriction | None = None

    def __post_init__(self):
        if not (np.isfinite(self.k) and self.k > 0):
            raise ValueError(f"pinball radius factor k must be positive, got {self.k!r}")
        if not (np.isfinite(self.K_p) and self.K_p > 0):
            raise ValueError(f"pinball scaling factor K_p must be positive, got {self.K_p!r}")


def reduced(a, b):
    """a b / (a + b), = a where b is infinite (a rigid partner)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    with np.errstate(invalid="ignore"):
        return np.where(np.isinf(b), a, a * b / (a + b))


def penetration(R_i, R_j, r):
    """Eq. (32): p_d = (R_i + R_j) - |x_i - x_j|."""
    return R_i + R_j - r


def penetration_rate(dx, dv, r):
    """Rate of Eq. (32): pdot_d = -(v_i - v_j) . (x_i - x_j) / r, positive while approaching (pairs as rows)."""
    return -np.einsum("pk,pk->p", dv, dx) / r


def rate_force(m_ij, pdot, dt):
    """Eq. (34): F1 = m_ij pdot_d / dt where pdot_d > 0, else 0 (m_ij: reduced mass, see module text)."""
    return np.where(pdot > 0.0, m_ij * pdot / dt, 0.0)


def hertz_force(mu_ij, R_i, R_j, p_d, thickness=1.0):
    """Eq. (35): F2 = mu_ij sqrt(R_i R_j / (R_i + R_j)) p_d^1.5 (p_d > 0), divided by ``thickness``
    (2D: dp, the force per unit thickness of a row of particles through it; 3D: 1)."""
    return mu_ij * np.sqrt(R_i * R_j / (R_i + R_j)) * np.maximum(p_d, 0.0) ** 1.5 / thickness


def pinball_force(p_d, pdot, m_ij, mu_ij, R_i, R_j, dt, K_p, thickness=1.0):
    """Eq. (33): F = K_p min(F1, F2) for pairs in contact (p_d > 0); 0 elsewhere."""
    F = K_p * np.minimum(rate_force(m_ij, pdot, dt), hertz_force(mu_ij, R_i, R_j, p_d, thickness))
    return np.where(p_d > 0.0, F, 0.0)


@dataclass
class ContactResult:
    """Forces of one contact evaluation. ``a``: (n_a, d) acceleration added to each particle of the
    deformable set (Eq. (36)); ``force_on_b``: (n_b, d) force on each partner particle (the reaction, equal and
    opposite pair by pair); ``n_contacts``: pairs with p_d > 0; ``max_penetration``: max p_d [m] (0 if none);
    ``friction_power_a``, ``friction_power_b``: (n_a,), (n_b,) the friction power |f_t| |v_t| of each particle's
    pairs [W] (each pair's power counted once on each side; zeros without friction); ``heat_power_a``: (n_a,) the
    power the contact's normal damping dissipates at each particle of set a [W] (the penalty contact's; None: not
    computed, as for the pinball)."""

    a: np.ndarray
    force_on_b: np.ndarray
    n_contacts: int
    max_penetration: float
    friction_power_a: np.ndarray | None = None
    friction_power_b: np.ndarray | None = None
    heat_power_a: np.ndarray | None = None


def pinball_contact(x_a, v_a, m_a, x_b, v_b, m_b, R, mu_a, mu_b, dt, contact: PinballContact,
                    thickness=1.0, T_a=None) -> ContactResult:
    """Eqs. (32)-(36) between particle set a (deformable) and set b (another body; ``m_b``/``mu_b`` may be
    ``np.inf`` for a rigid body), pinball radius R for every particle.

    Pairs are found with a k-d tree over the particles of a that lie in the bounding box of b grown by 2R.
    ``T_a``: temperatures of a (needed only with friction)."""
    n_a, d = x_a.shape
    a = np.zeros((n_a, d))
    force_b = np.zeros((len(x_b), d))
    if n_a == 0 or len(x_b) == 0:
        return ContactResult(a, force_b, 0, 0.0)
    lo, hi = x_b.min(axis=0) - 2 * R, x_b.max(axis=0) + 2 * R
    near = np.flatnonzero(np.all((x_a > lo) & (x_a < hi), axis=1))
    if len(near) == 0:
        return ContactResult(a, force_b, 0, 0.0)
    pairs = cKDTree(x_a[near]).sparse_distance_matrix(cKDTree(x_b), 2 * R, output_type="ndarray")
    pairs = pairs[pairs["v"] > 0.0]                 # coincident centres have no line of centres
    if len(pairs) == 0:
        return ContactResult(a, force_b, 0, 0.0)
    I, J, r = near[pairs["i"]], pairs["j"], pairs["v"]
    dx = x_a[I] - x_b[J]
    dv = v_a[I] - v_b[J]
    e = dx / r[:, None]
    p_d = penetration(R, R, r)                                           # Eq. (32)
    pdot = penetration_rate(dx, dv, r)
    m_ij = reduced(np.take(m_a, I), m_b if np.isscalar(m_b) else np.take(m_b, J))
    mu_ij = reduced(mu_a, mu_b)
    F = pinball_force(p_d, pdot, m_ij, mu_ij, R, R, dt, contact.K_p, thickness)   # Eqs. (33)-(35)
    f = e * F[:, None]                                                   # on a, along the line of centres
    power_a, power_b = np.zeros(n_a), np.zeros(len(x_b))
    if contact.friction is not None:
        if T_a is None:
            raise ValueError("friction needs the temperatures of the deformable body")
        vt = dv - np.einsum("pk,pk->p", dv, e)[:, None] * e
        speed = np.sqrt(np.einsum("pk,pk->p", vt, vt))
        ft = np.minimum(contact.friction.mu(np.take(T_a, I)) * F, m_ij * speed / dt)
        with np.errstate(invalid="ignore", divide="ignore"):
            f -= np.where(speed[:, None] > 0, vt / speed[:, None], 0.0) * ft[:, None]
        power_a = np.bincount(I, weights=ft * speed, minlength=n_a)      # |f_t| |v_t|, the work friction does
        power_b = np.bincount(J, weights=ft * speed, minlength=len(x_b))
    for k in range(d):                                                   # Eq. (36), equal and opposite
        a[:, k] = np.bincount(I, weights=f[:, k], minlength=n_a) / m_a
        force_b[:, k] = -np.bincount(J, weights=f[:, k], minlength=len(x_b))
    inside = p_d > 0
    return ContactResult(a, force_b, int(np.count_nonzero(inside)),
                         float(np.max(p_d[inside])) if inside.any() else 0.0, power_a, power_b)
