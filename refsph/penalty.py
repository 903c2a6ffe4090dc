"""Penalty contact of deformable particles against a rigid tool's exact geometry, with return-mapped Coulomb
friction (issue 22): the contact the second paper's own SPH code and LS-DYNA's penalty contact use, offered beside
the pinball of Eqs. (32)-(36) (:mod:`refsph.contact`, the first paper's choice, kept for its numbers).

The pinball pushes only while two particles approach (Eq. (34)), so a particle resting on the tool is pushed in
pulses and friction, bounded by mu times that force, carries little at steady sliding. A penalty force acts for as
long as the particle penetrates. Here the tool is its boundary, not a layer of particles:

**Geometry** (:class:`RoundedPolygon`, 2D). The tool is a convex polygon ``core`` (its vertices, counter-clockwise,
relative to the centroid of the tool's particles, so that the shape follows its rigid body wherever the body is)
grown by ``radius`` r: the set of points within r of the core. Every corner is then a
fillet of radius r (the cutting edge's 10 um rounding) and the faces are the core's edges pushed out by r. The
signed distance of a point x to the tool surface is exact:

    d(x) = dist(x, core) - r                       (x outside the core: the distance to the nearest edge)
    d(x) = -min_k (distance to edge line k) - r     (x inside the core)

and the gap g = offset - d > 0 is the penetration depth of the particle's *surface*, n the outward unit normal at
the nearest surface point. ``offset`` is half a spacing: an SPH body's surface lies dx/2 outside the centres of its
outer particles, so its surface, not its centres, touches the tool's exact face. The tool
is a :class:`refsph.boundaries.RigidBody` (``shape``) that translates with velocity V; its core at time t is
core + c(t), c the centroid of its particles.

**Normal force** (per particle i in contact, g_i > 0; relative normal velocity v_n = (v_i - V) . n, < 0 approaching)

    f_N = m_i (alpha g_i / tau^2 - beta v_n / tau),   clipped at 0 (no adhesion)

a spring of stiffness k = alpha m_i / tau^2 with damping ratio zeta, beta = 2 zeta sqrt(alpha); tau is the run's
CFL step of the material at rest, C h / c_L (``time_scale``), so that the spring removes about the fraction alpha of
the penetration per step (omega dt <= sqrt(alpha), stable for alpha < 4 in the leapfrog). tau and not the step being
taken: a step shortened to land on an output time would otherwise make the spring 1/(dt/tau)^2 times stiffer. With
k proportional to m / tau^2 the contact is independent of mass scaling (tau ~ sqrt(rho) ~ sqrt(m)).

The normal force's non-elastic part, f_N - k g (the damping, or the spring force the clip at 0 drops), takes
the power -(f_N - k g) v_n >= 0 out of the motion (``damping_power``): a run with ``Setup.dissipation_heat`` puts
it into the particle as heat.

**Friction** (Coulomb with mu(T), :class:`refsph.contact.CoulombFriction`), a return map on an elastic tangential
spring of the same stiffness, with per-particle history xi (the stuck tangential displacement, kept between steps):

    xi* = P(xi) + v_t dt                    P: projection on the current tangent plane; v_t = tangential (v_i - V)
    f*  = -k xi*                            trial (stick)
    |f*| <= mu f_N:  f_t = f*,  xi = xi*                        (stick)
    else:            f_t = mu f_N f*/|f*|,  xi = -f_t / k         (slip, return to the Coulomb cone)

The friction power (the heat of their Eq. (7)) is the work the return map dissipates: |f_t| (|xi*| - |xi|) / dt,
= |f_t| |v_t| at steady sliding and 0 while stuck. Sticking needs no cap: the spring holds the particle.

A rigid tool's particles stay in the run (they conduct heat, they carry the reaction force), but the contact is
computed from the geometry alone.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .contact import CoulombFriction

__all__ = ["RoundedPolygon", "PenaltyContact", "PenaltyResult", "penalty_contact", "return_map_friction"]


@dataclass(frozen=True)
class RoundedPolygon:
    """A 2D convex polygon ``core`` ((k, 2) vertices, counter-clockwise, relative to the centroid of the tool's
    particles [m]) grown by ``radius`` [m] (module text): the exact boundary of a tool (``RigidBody.shape``)."""

    core: tuple
    radius: float

    def __post_init__(self):
        c = np.asarray(self.core, dtype=float)
        if c.ndim != 2 or c.shape[1] != 2 or len(c) < 3 or not np.all(np.isfinite(c)):
            raise ValueError(f"RoundedPolygon.core must be (k >= 3, 2) finite vertices, got shape {c.shape}")
        e = np.roll(c, -1, axis=0) - c
        cross = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
        if not np.all(cross > 0):
            raise ValueError("RoundedPolygon.core must be convex with its vertices counter-clockwise")
        if not (np.isfinite(self.radius) and self.radius >= 0):
            raise ValueError(f"RoundedPolygon.radius must be >= 0, got {self.radius!r}")
        object.__setattr__(self, "core", tuple(map(tuple, c.tolist())))

    @classmethod
    def from_polygon(cls, vertices, radius: float, centroid) -> "RoundedPolygon":
        """The tool whose outline is the convex polygon ``vertices`` (world coordinates, either orientation) with
        every corner rounded by ``radius``: each edge line moved inward by the radius, consecutive lines intersected
        (the core), expressed relative to ``centroid`` (that of the tool's particles)."""
        P = np.asarray(vertices, dtype=float)
        area2 = np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1])
        if area2 < 0:
            P = P[::-1]
        e = np.roll(P, -1, axis=0) - P
        nrm = np.stack([e[:, 1], -e[:, 0]], axis=1) / np.linalg.norm(e, axis=1)[:, None]   # outward
        c = np.einsum("kd,kd->k", nrm, P) - radius                                           # n . x = c, moved in
        core = []
        for k in range(len(P)):
            A = np.array([nrm[k - 1], nrm[k]])
            core.append(np.linalg.solve(A, [c[k - 1], c[k]]))
        return cls(core=np.asarray(core) - np.asarray(centroid, dtype=float), radius=float(radius))

    def bounding_circle(self, shift: np.ndarray) -> tuple[np.ndarray, float]:
        """(centre, radius) of a circle that holds the whole tool (core + ``shift`` grown by the radius): a point
        farther than that from the centre has a gap below -(its distance - radius)."""
        P = np.asarray(self.core) + np.asarray(shift, dtype=float)
        c = P.mean(axis=0)
        return c, float(np.sqrt(np.max(np.sum((P - c) ** 2, axis=1)))) + self.radius

    def gap(self, x: np.ndarray, shift: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(g, n) of points x (N, 2) against the tool with its core at core + ``shift`` (2,) [m] (the centroid of the
        tool's particles): the penetration depth g =
        -(signed distance) [m] (> 0 inside the tool) and the outward unit normal n (N, 2) of the tool surface at
        the nearest surface point."""
        P = np.asarray(self.core) + np.asarray(shift, dtype=float)
        a, b = P, np.roll(P, -1, axis=0)
        e = b - a
        L2 = np.einsum("kd,kd->k", e, e)
        normal = np.stack([e[:, 1], -e[:, 0]], axis=1) / np.sqrt(L2)[:, None]   # outward for a CCW polygon
        rel = x[:, None, :] - a[None, :, :]                                       # (N, k, 2)
        s = np.clip(np.einsum("nkd,kd->nk", rel, e) / L2, 0.0, 1.0)
        near = a[None, :, :] + s[:, :, None] * e[None, :, :]
        d_edge = np.linalg.norm(x[:, None, :] - near, axis=2)                    # distance to each edge segment
        side = np.einsum("nkd,kd->nk", rel, normal)                               # signed distance to edge lines
        inside = np.all(side <= 0.0, axis=1)
        k_out = np.argmin(d_edge, axis=1)
        k_in = np.argmax(side, axis=1)                                            # the nearest face from inside
        rows = np.arange(len(x))
        out_vec = x - near[rows, k_out]
        out_dist = d_edge[rows, k_out]
        with np.errstate(invalid="ignore", divide="ignore"):
            n_out = np.where(out_dist[:, None] > 0, out_vec / out_dist[:, None], normal[k_out])
        n = np.where(inside[:, None], normal[k_in], n_out)
        dist = np.where(inside, side[rows, k_in], out_dist)                       # signed distance to the core
        return self.radius - dist, n


@dataclass(frozen=True)
class PenaltyContact:
    """Parameters of the penalty contact (module text): ``alpha`` (fraction of the penetration removed per step,
    stiffness alpha m / tau^2), ``damping`` (the damping ratio zeta of the normal spring), ``offset`` [m] (where the
    particle's surface is: dx/2 outside its centre), ``time_scale`` tau [s] (the CFL step of the material at rest),
    ``friction`` (a :class:`~refsph.contact.CoulombFriction`, or None: frictionless). No defaults (``Numerics`` holds
    the run's)."""

    alpha: float
    damping: float
    offset: float
    time_scale: float
    friction: CoulombFriction | None = None

    def __post_init__(self):
        if not (np.isfinite(self.alpha) and 0.0 < self.alpha < 4.0):
            raise ValueError(f"penalty alpha must lie in (0, 4) (omega dt = sqrt(alpha) < 2), got {self.alpha!r}")
        if not (np.isfinite(self.damping) and self.damping >= 0.0):
            raise ValueError(f"penalty damping ratio must be >= 0, got {self.damping!r}")
        if not (np.isfinite(self.offset) and self.offset >= 0.0):
            raise ValueError(f"penalty offset must be >= 0 [m], got {self.offset!r}")
        if not (np.isfinite(self.time_scale) and self.time_scale > 0.0):
            raise ValueError(f"penalty time_scale must be > 0 [s], got {self.time_scale!r}")


@dataclass
class PenaltyResult:
    """One evaluation: ``a`` (N, d) the contact acceleration of each particle; ``force_on_tool`` (d,) the reaction
    on the tool (the sum of -f over the particles); ``friction_power`` (N,) [W; 2D: W/m] the power each particle's
    return map dissipates; ``xi`` (N, d) the trial tangential history (what the step commits); ``gap`` (N,) the
    penetration depth (<= 0: no contact); ``f_normal`` (N,) and ``f_tangent`` (N, d) the contact forces;
    ``f_trial`` (N, d) the trial (stick) tangential force -k xi* that the return map started from;
    ``damping_power`` (N,) [W; 2D: W/m] the power the normal force's non-elastic part takes out of the motion,
    -(f_N - k g) v_n >= 0 (the damping, beta m v_n^2 / tau, or the spring force the no-adhesion clip drops)."""

    a: np.ndarray
    force_on_tool: np.ndarray
    friction_power: np.ndarray
    xi: np.ndarray
    gap: np.ndarray
    f_normal: np.ndarray
    f_tangent: np.ndarray
    f_trial: np.ndarray
    damping_power: np.ndarray


def return_map_friction(xi_trial: np.ndarray, k: np.ndarray, f_limit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coulomb's return map on the tangential spring (module text): (f_t, xi) from the trial history xi* (N, d),
    the stiffness k (N,) and the limit mu f_N (N,): stick if |k xi*| <= mu f_N, else slip back to the cone. The
    trial force is -k xi*."""
    f_trial = -k[:, None] * xi_trial
    norm = np.linalg.norm(f_trial, axis=1)
    slip = norm > f_limit
    scale = np.where(slip, f_limit / np.where(norm > 0, norm, 1.0), 1.0)
    f_t = f_trial * scale[:, None]
    xi = np.where(slip[:, None], -f_t / np.where(k > 0, k, 1.0)[:, None], xi_trial)
    return f_t, xi


def penalty_contact(x: np.ndarray, v: np.ndarray, m: np.ndarray, T: np.ndarray | None, tool: RoundedPolygon,
                    shift: np.ndarray, V: np.ndarray, dt: float, contact: PenaltyContact,
                    xi: np.ndarray) -> PenaltyResult:
    """The penalty contact of particles (x, v, m; temperatures T for mu(T)) with the tool moved by ``shift`` and
    moving at velocity ``V``, for a step dt, from the committed tangential history ``xi`` (N, d) (module text)."""
    if not (dt is not None and dt > 0):
        raise ValueError(f"the penalty contact needs the step size dt > 0, got {dt!r}")
    n_p, d = x.shape
    if d != 2:
        raise ValueError("the penalty contact's tool geometry (RoundedPolygon) is 2D")
    g, n = tool.gap(x, shift)
    g = g + contact.offset
    on = g > 0.0
    tau = contact.time_scale
    k = np.where(on, contact.alpha * m / (tau * tau), 0.0)
    vr = v - np.asarray(V, dtype=float)
    vn = np.einsum("nd,nd->n", vr, n)
    beta = 2.0 * contact.damping * np.sqrt(contact.alpha)
    fN = np.where(on, np.maximum(k * g - beta * m * vn / tau, 0.0), 0.0)
    f = fN[:, None] * np.where(on[:, None], n, 0.0)
    damping_power = np.where(on, np.maximum(-(fN - k * g) * vn, 0.0), 0.0)
    f_t = np.zeros((n_p, d))
    f_trial = np.zeros((n_p, d))
    power = np.zeros(n_p)
    xi_new = np.zeros((n_p, d))
    if contact.friction is not None and np.any(on):
        if T is None:
            raise ValueError("friction with mu(T) needs temperatures")
        nn = np.where(on[:, None], n, 0.0)
        xi_p = xi - np.einsum("nd,nd->n", xi, nn)[:, None] * nn                 # projected on the tangent plane
        vt = vr - vn[:, None] * nn
        xi_trial = np.where(on[:, None], xi_p + vt * dt, 0.0)
        f_t, xi_new = return_map_friction(xi_trial, k, contact.friction.mu(T) * fN)
        f_trial = -k[:, None] * xi_trial
        slipped = np.linalg.norm(xi_trial, axis=1) - np.linalg.norm(xi_new, axis=1)
        power = np.linalg.norm(f_t, axis=1) * np.maximum(slipped, 0.0) / dt
        f = f + f_t
    return PenaltyResult(a=f / m[:, None], force_on_tool=-f.sum(axis=0), friction_power=power, xi=xi_new, gap=g,
                         f_normal=fN, f_tangent=f_t, f_trial=f_trial, damping_power=damping_power)
