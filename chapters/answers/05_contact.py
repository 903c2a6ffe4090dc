"""Answer key of chapter 05 (contact), run by tests/test_exercises.py in quick mode.

* answer_1: K_p = 5 instead of 50. The softer pinball lets the steel disc sink several times deeper into the
  particle wall and it bounces back clearly slower (lower restitution): the contact takes in energy on the way in
  and, acting only while pairs approach, does not give it all back.
* answer_2: pinball radius factor k = 1.2 dp/(2h) instead of dp/(2h). The disc stops about 0.2 spacings farther
  from the wall (the contact surface moves out with 2R), while penetration and restitution hardly change: k sets
  where the wall is, not how stiff it is.
* answer_3: Coulomb friction with mu0 = 0.81 for a block thrown obliquely at a fine particle wall (dp/4 apart).
  The block loses a large part of its speed along the wall, and the tangential impulse on the wall is about
  mu0 times the normal one, never much above it (Coulomb's bound; the fine wall's small bumps add a little).
"""
import numpy as np
from scipy.spatial import cKDTree

from refsph.boundaries import RigidBody
from refsph.contact import CoulombFriction
from refsph.scenes import Numerics, Setup, aisi4340_material, lattice
from refsph.simulate import simulate
from refsph.state import concatenate_states, make_state

MAT = aisi4340_material()
DP, RD, V0 = 0.25e-3, 2.5e-3, 100.0            # spacing, disc radius [m], impact speed [m/s]
NUM = Numerics(beta1=0.5, beta2=0.5)
H = NUM.h_over_dp * DP


def _wall(lo, hi, normal_axis=0, spacing=DP, T0=None):
    """Rigid particles (body 1) below the face x = 0 (normal_axis 0) or y = 0 (1), spanning [lo, hi] along it."""
    depth = -0.5 * DP - np.arange(0.0, 2.01 * DP, spacing)
    along = np.arange(lo, hi, spacing) + 0.5 * spacing
    A, B = np.meshgrid(depth, along) if normal_axis == 0 else np.meshgrid(along, depth)
    xw = np.stack([A.ravel(), B.ravel()], axis=1)
    return make_state(xw, np.zeros(2), MAT.rho0, spacing**2, T0=T0, body=np.ones(len(xw), dtype=int))


def _run(body, wall, t_end, numerics=NUM, friction=None):
    setup = Setup(state=concatenate_states(body, wall), material=MAT, dp=DP, numerics=numerics, t_end=t_end,
                  n_snapshots=1, rigid=(RigidBody("wall", 1, (0.0, 0.0)),), friction=friction)
    tree, n = cKDTree(wall.x), body.n
    res = simulate(setup, "tlsph", progress=False, record_every=1,
                   record=lambda s, _: dict(t=s.t, dmin=float(tree.query(s.x[:n])[0].min()) / DP))
    P1 = np.sum(res.state.m[:n, None] * res.state.v[:n], axis=0)
    return dict(P1=P1, closest=min(res.history["dmin"]),
                pen=res.summary["diagnostics"]["max_pinball_penetration_m"] / DP,
                J=np.asarray(res.summary["diagnostics"]["reaction_impulse"]["wall"]))


def bounce(Kp=50.0, k_factor=1.0):
    """The chapter's TLSPH disc bounce at 100 m/s, from a quarter spacing (plus the extra pinball reach)."""
    gap = 0.25 * DP + max(0.0, k_factor - 1.0) * DP
    x = lattice([2 * RD, 2 * RD], DP)
    x = x[np.sum((x - RD) ** 2, axis=1) < RD**2]
    x[:, 0] += gap - (x[:, 0].min() - 0.5 * DP)
    disc = make_state(x, [-V0, 0.0], MAT.rho0, DP**2)
    numerics = Numerics(**{**NUM.__dict__, "contact_Kp": Kp, "contact_k": k_factor * DP / (2 * H)})
    o = _run(disc, _wall(-4 * DP, 2 * RD + 4 * DP), 2 * gap / V0 + 16 * RD / MAT.c_longitudinal, numerics)
    o["restitution"] = o["P1"][0] / (np.sum(disc.m) * V0)
    return o


def oblique(mu0):
    """The 2 mm x 1 mm block, 100 m/s along and 25 m/s towards a wall of particles dp/4 apart."""
    V_T, V_N, gap, spacing = 100.0, 25.0, 0.1 * DP, DP / 4
    block = make_state(lattice([2e-3, 1e-3], DP) + [0.0, gap], [V_T, -V_N], MAT.rho0, DP**2, T0=293.0)
    t_end = 2 * gap / V_N + 20 * 1e-3 / MAT.c_longitudinal
    wall = _wall(-4 * DP, 2e-3 + V_T * t_end + 4 * DP, normal_axis=1, spacing=spacing, T0=293.0)
    fr = None if mu0 is None else CoulombFriction(mu0=mu0, q=2.09, T_room=293.0, T_melt=1773.0)
    o = _run(block, wall, t_end, friction=fr)
    o.update(Jt_over_Jn=o["J"][0] / -o["J"][1], vt_after=o["P1"][0] / np.sum(block.m))
    return o


def answer_1():
    soft, default = bounce(Kp=5.0), bounce(Kp=50.0)
    assert soft["pen"] > 2.0 * default["pen"]                  # several times deeper
    assert soft["restitution"] < default["restitution"] - 0.1  # clearly slower rebound
    assert 0.0 < soft["restitution"] < 1.0


def answer_2():
    wide, default = bounce(k_factor=1.2), bounce(k_factor=1.0)
    assert 0.1 < wide["closest"] - default["closest"] < 0.3     # the disc stops about 0.2 dp farther out
    assert abs(wide["pen"] - default["pen"]) < 0.5 * default["pen"]
    assert abs(wide["restitution"] - default["restitution"]) < 0.05


def answer_3():
    mu0 = 0.81
    free, rough = oblique(None), oblique(mu0)
    assert rough["vt_after"] < free["vt_after"] - 20.0          # friction slowed the sliding a lot
    assert 0.7 * mu0 < rough["Jt_over_Jn"] <= 1.05 * mu0        # Coulomb: J_t about mu0 J_n, not above (5 %: bumps)
    assert abs(free["Jt_over_Jn"]) < 0.1 * mu0                  # the fine wall alone hardly drags
