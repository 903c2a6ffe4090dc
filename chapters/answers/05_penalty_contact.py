"""Answer key of chapter 05, continued (penalty contact), run by tests/test_exercises.py in quick mode.

* answer_1: penalty stiffness alpha = 0.02 instead of 0.1. The block's face sinks about five times deeper into
  the plane (the spring alpha m / tau^2 is five times softer), still a small fraction of a spacing, and the
  friction is unchanged: F_t / F_N = mu and the closed-form sliding acceleration.
* answer_2: mu = 0.8 with the tilt tan(theta) = 0.6. The block sticks (no sliding acceleration) and the force on
  the plane is F_t / F_N = tan(theta) = 0.6, not mu: a stuck contact carries whatever holds the block, anything
  inside the Coulomb cone.
"""
import math

import numpy as np

from refsph.boundaries import RigidBody
from refsph.contact import CoulombFriction
from refsph.material import ElasticMaterial
from refsph.penalty import RoundedPolygon
from refsph.scenes import Numerics, Setup, lattice
from refsph.simulate import make_solver, simulate
from refsph.state import concatenate_states, make_state

MU, DX, G = 0.3, 1e-4, 2e6                     # the chapter's friction coefficient, spacing [m], gravity [m/s^2]
THETA = math.atan(2 * MU)
GRAVITY = G * np.array([math.sin(THETA), -math.cos(THETA)])


class _Tilted:
    def __init__(self, inner, n):
        self.inner, self.n = inner, n

    def rates(self, state, dt, part="all"):
        r = self.inner.rates(state, dt, part=part)
        if part != "deformation":
            r.v[:self.n] += GRAVITY
        return r

    def __getattr__(self, name):
        return getattr(self.inner, name)


def incline(mu=MU, alpha=0.1, s=100.0):
    """The chapter's 10 x 4 block on the plane (penalty contact), 20 us: sliding acceleration, F_t / F_N on the
    plane and how deep the face sinks [dp], over the second half."""
    mat = ElasticMaterial(rho0=7850.0 * s, E=200e9, nu=0.3)
    block = make_state(lattice([10 * DX, 4 * DX], DX), [0.0, 0.0], mat.rho0, DX**2, T0=293.0)
    face = block.x[:, 1].min() - 0.5 * DX
    row = np.stack([np.arange(-10, 41) * DX, np.full(51, face - 0.5 * DX)], axis=1)
    plane = make_state(row, [0.0, 0.0], mat.rho0, DX**2, T0=293.0, body=np.ones(51, dtype=int))
    shape = RoundedPolygon.from_polygon([[-10 * DX, face - 5 * DX], [40 * DX, face - 5 * DX], [40 * DX, face],
                                         [-10 * DX, face]], 0.0, row.mean(axis=0))
    setup = Setup(state=concatenate_states(block, plane), material=mat, dp=DX, t_end=20e-6, n_snapshots=1,
                  rigid=(RigidBody("plane", 1, (0.0, 0.0), shape=shape),), friction=CoulombFriction(mu, 1.0, 293.0,
                                                                                                     1800.0),
                  numerics=Numerics(contact="penalty", integrator="leapfrog", beta1=0.5, beta2=0.5,
                                    penalty_alpha=alpha))
    n = block.n
    res = simulate(setup, solver=_Tilted(make_solver("tlsph", setup), n), progress=False, record_every=1,
                   record=lambda st, _: dict(t=st.t, vx=float(np.mean(st.v[:n, 0])), y=float(st.x[:n, 1].min())))
    t, late = np.array(res.history["t"]), np.array(res.history["t"]) > 10e-6
    F = res.history["reaction"]["plane"][res.history["reaction"]["t"] > 10e-6]
    return dict(a=np.polyfit(t[late], np.array(res.history["vx"])[late], 1)[0], mu_eff=F[:, 0].sum() / -F[:, 1].sum(),
                sink=(face - np.mean(np.array(res.history["y"])[late]) + 0.5 * DX) / DX)


def answer_1():
    soft, default = incline(alpha=0.02), incline(alpha=0.1)
    assert 3.0 < soft["sink"] / default["sink"] < 7.0           # about five times deeper
    assert soft["sink"] < 0.1                                   # still a small fraction of a spacing
    exact = G * (math.sin(THETA) - MU * math.cos(THETA))
    for o in (soft, default):
        assert abs(o["mu_eff"] - MU) < 0.01 * MU and abs(o["a"] / exact - 1) < 0.02


def answer_2():
    o = incline(mu=0.8)
    assert abs(o["a"]) < 0.05 * G * math.sin(THETA)             # stuck (but for its elastic ringing)
    assert abs(o["mu_eff"] - math.tan(THETA)) < 0.02            # F_t / F_N = tan(theta), not mu
