"""Contact checks with closed-form answers (issue 22), each a set-up for the pinball (Eqs. (32)-(36)) and the penalty
contact (:mod:`refsph.penalty`): a block on an inclined plane (:func:`incline`) and a strip striking a rigid plane
(:func:`strip_impact`).

**Block on an inclined plane.** An elastic TLSPH block (``nx`` x ``ny`` particles of spacing ``dx``) rests with its
bottom face on a rigid plane (the top face of a tool whose particles are one row under the block). A body force of
magnitude ``g0`` tilted by theta from the plane's normal presses it with g0 cos(theta) per unit mass and drives it
along the plane with g0 sin(theta).
With Coulomb friction mu (temperature-independent here: T = T_room),

* tan(theta) <= mu: the block sticks (no sliding acceleration);
* tan(theta) > mu: it slides with a = g0 (sin(theta) - mu cos(theta)), and the force on the plane has
  F_t / F_N = mu exactly, whatever the mass scale s (the density times s: every force and mass times s).

The plane is given both ways a TLSPH contact sees a tool: its particles (the pinball, Eqs. (32)-(36)) and its exact
outline (``RigidBody.shape``, the penalty contact of :mod:`refsph.penalty`). ``Numerics.contact`` picks one.
The body force is a solver wrapper (:class:`BodyForce`) around the run's solver (``simulate(setup,
solver=BodyForce(make_solver("tlsph", setup), g, n))``); :func:`sliding` turns a run's record into the measured
acceleration and F_t / F_N.

**Strip striking a rigid plane.** An elastic strip of length L (along y) and width W moves at v0 onto a rigid plane
that its bottom face just touches. A compression wave of speed c = sqrt(E / rho) runs up and back: the strip stays
in contact for

    t_c = 2 L / c,    with the force rho c v0 W (per unit thickness) on the plane,

and leaves at v0. With Poisson's ratio nu = 0 (the strip's material here) nothing moves sideways, so this 1D answer
is exact for the 2D strip (with nu > 0 lateral inertia adds a dispersion of order (W / L)^2 nu^2).
:func:`impact_measures` takes the contact time (from the first to the last step with a force on the plane above 1 %
of its largest) and the rebound velocity from a run.
"""
from __future__ import annotations

import numpy as np

from ..boundaries import RigidBody
from ..contact import CoulombFriction
from ..material import ElasticMaterial
from ..penalty import RoundedPolygon
from ..state import concatenate_states, make_state
from .base import Numerics, Setup
from .measure import lattice

__all__ = ["incline", "BodyForce", "sliding", "sliding_acceleration", "strip_impact", "impact_measures",
           "bar_speed"]

PLANE_BODY = 1


def incline(theta: float, mu: float, *, mass_scale: float, contact: str, dx: float, nx: int, ny: int, g0: float,
            t_end: float, integrator: str = "leapfrog") -> tuple[Setup, np.ndarray, int]:
    """(setup, g, n): the block on the plane (module text), the body force g (2,) [m/s^2] and the number n of the
    block's particles (the leading rows). Elastic steel (E = 200 GPa, nu = 0.3, rho = 7850 s kg/m^3)."""
    if not (0.0 <= theta < np.pi / 2 and mu >= 0 and mass_scale > 0 and dx > 0 and g0 > 0 and t_end > 0):
        raise ValueError("incline needs 0 <= theta < pi/2, mu >= 0 and positive mass_scale, dx, g0, t_end")
    mat = ElasticMaterial(rho0=7850.0 * mass_scale, E=200e9, nu=0.3)
    block = make_state(lattice([nx * dx, ny * dx], dx), [0.0, 0.0], mat.rho0, dx * dx, T0=293.0)
    y0 = block.x[:, 1].min() - 0.5 * dx                                   # the block's bottom face: the plane
    plane, tool = _plane_under((np.arange(-2 * nx, 3 * nx + 1) + 0.5) * dx, y0, dx, mat.rho0)
    friction = CoulombFriction(mu0=mu, q=1.0, T_room=293.0, T_melt=1800.0) if mu > 0 else None
    setup = Setup(state=concatenate_states(block, plane), material=mat, dp=dx, t_end=t_end, n_snapshots=1,
                  rigid=(tool,), friction=friction,
                  numerics=Numerics(contact=contact, integrator=integrator, beta1=0.5, beta2=0.5, threads=1),
                  info=dict(theta=theta, mu=mu, mass_scale=mass_scale, g0=g0, n_block=block.n))
    return setup, g0 * np.array([np.sin(theta), -np.cos(theta)]), block.n


class BodyForce:
    """A solver with a body force ``g`` [m/s^2] on its first ``n`` rows (everything else the wrapped solver's)."""

    def __init__(self, inner, g, n: int):
        self.inner, self.g, self.n = inner, np.asarray(g, dtype=float), int(n)

    def rates(self, state, dt, part="all"):
        r = self.inner.rates(state, dt, part=part)
        if part != "deformation":                       # the leapfrog's stress half has no forces
            r.v[:self.n] += self.g
        return r

    def __getattr__(self, name):
        return getattr(self.inner, name)


def sliding_acceleration(t: np.ndarray, v: np.ndarray) -> float:
    """The slope of the block's mean velocity along the plane over the second half of the run [m/s^2]."""
    late = t > 0.5 * t[-1]
    return float(np.polyfit(t[late], v[late], 1)[0])


def sliding(history: dict, t: np.ndarray, v: np.ndarray) -> dict:
    """The measures of a run: the sliding acceleration ``a`` and the ratio of the plane's tangential to normal
    impulse ``mu_eff`` over the second half of the run (the reaction log: force on the plane per step)."""
    r = history["reaction"]
    late = r["t"] > 0.5 * r["t"][-1]
    F, dt = r["plane"][late], r["dt"][late]
    return dict(a=sliding_acceleration(t, v), mu_eff=float(np.sum(F[:, 0] * dt) / -np.sum(F[:, 1] * dt)))


def _plane_under(xs: np.ndarray, y0: float, dx: float, rho: float):
    """A rigid plane whose top face is y = y0 under the particle columns ``xs``: one row of tool particles (centres
    dx/2 below the face, for the reaction and the pinball) and its outline (a slab one spacing deep, from the first
    column's left face to the last one's right face, for the penalty contact): (state, RigidBody)."""
    row = np.stack([xs, np.full(len(xs), y0 - 0.5 * dx)], axis=1)
    plane = make_state(row, [0.0, 0.0], rho, dx * dx, T0=293.0, body=np.full(len(xs), PLANE_BODY))
    lo, hi = xs[0] - 0.5 * dx, xs[-1] + 0.5 * dx
    outline = [[lo, y0 - dx], [hi, y0 - dx], [hi, y0], [lo, y0]]
    return plane, RigidBody("plane", PLANE_BODY, (0.0, 0.0),
                            shape=RoundedPolygon.from_polygon(outline, 0.0, row.mean(0)))


def bar_speed(mat: ElasticMaterial) -> float:
    """c = sqrt(E / (rho (1 - nu^2))): the speed of a long-wave compression pulse in a strip in plane strain
    (sqrt(E / rho) for nu = 0, the strip of :func:`strip_impact`)."""
    return float(np.sqrt(mat.E / (mat.rho0 * (1.0 - mat.nu ** 2))))


def strip_impact(*, length: float, width: float, dx: float, v0: float, contact: str,
                 integrator: str = "leapfrog") -> tuple[Setup, float]:
    """(setup, t_c): the elastic strip (module text) of ``length`` x ``width`` [m] at spacing dx, moving at v0 [m/s]
    onto the plane its bottom face touches, run to 1.5 t_c; t_c = 2 L / c the closed-form contact time."""
    if not (length > 0 and width > 0 and 0 < dx <= width / 2 and v0 > 0):
        raise ValueError("strip_impact needs positive length and v0, and dx <= width / 2")
    mat = ElasticMaterial(rho0=7850.0, E=200e9, nu=0.0)
    nx, ny = round(width / dx), round(length / dx)
    strip = make_state(lattice([nx * dx, ny * dx], dx), [0.0, -v0], mat.rho0, dx * dx, T0=293.0)
    plane, tool = _plane_under(np.arange(-nx * dx + 0.5 * dx, 2 * nx * dx, dx), strip.x[:, 1].min() - 0.5 * dx, dx,
                               mat.rho0)
    t_c = 2.0 * ny * dx / bar_speed(mat)
    setup = Setup(state=concatenate_states(strip, plane), material=mat, dp=dx, t_end=1.5 * t_c, n_snapshots=1,
                  rigid=(tool,), numerics=Numerics(contact=contact, integrator=integrator, beta1=0.5, beta2=0.5,
                                                   threads=1),
                  info=dict(length=ny * dx, width=nx * dx, v0=v0, t_c=t_c, n_strip=strip.n))
    return setup, t_c


def impact_measures(history: dict, state, n: int, v0: float) -> dict:
    """The contact time (first to last step with a force above 1 % of the largest) [s], the largest force
    [N/m], and the rebound velocity over v0 (the strip's mean vertical velocity at the end)."""
    r = history["reaction"]
    F = -r["plane"][:, 1]                                  # the force the strip puts on the plane, > 0 down
    on = np.flatnonzero(F > 0.01 * F.max())
    t0 = r["t"][on[0]] - 0.5 * r["dt"][on[0]]
    t1 = r["t"][on[-1]] + 0.5 * r["dt"][on[-1]]
    return dict(t_contact=float(t1 - t0), F_max=float(F.max()), rebound=float(np.mean(state.v[:n, 1]) / v0))
