# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Chapter 5 — Contact: the pinball of TLSPH and the particle tool of ESPH
#
# Islam, Bansal & Peng, Section 2.4 (Eqs. 32–36), with the Coulomb friction of Rodriguez Prieto, Larsson &
# Afrasiabi (their Eqs. 10–11).
#
# Pressing and cutting need a second body: a rigid tool, made of particles. How does the tool push the metal?
#
# * **ESPH** evaluates its kernels at the *current* positions. A tool particle that comes within $2h$ of a metal
#   particle is simply a neighbour: it enters the continuity equation, the pressure force and the velocity
#   gradient. Contact comes for free.
# * **TLSPH** evaluates its kernels in each body's *reference* configuration. The neighbours are fixed when the
#   reference is set (chapter 3); a tool particle that arrives later is not among them, and two bodies would pass
#   through each other. So the paper adds an explicit force between particles of different bodies: the *pinball*
#   contact of Campbell, Vignjevic & Libersky (2000) and Belytschko & Yeh (1993).
#
# In this lesson we write the pinball force, code it as a plain pair loop, check the package against that loop,
# throw a steel disc at a wall of tool particles with both methods, and see how the one free constant, $K_p$, was
# chosen.

# %%
import math
import matplotlib.pyplot as plt
import numpy as np
from scipy.spatial import cKDTree
from refsph import contact as contact_module, integrate, material, paper_data
from refsph.boundaries import RigidBody, RigidWall
from refsph.contact import CoulombFriction, PinballContact, pinball_contact
from refsph.scenes import Numerics, Setup, aisi4340_material, lattice
from refsph.simulate import simulate
from refsph.state import concatenate_states, make_state
from refsph.teaching.notebook import chapter
ch = chapter("05_contact")

# %% [markdown]
# ## The pinball force, Eqs. (32)–(36)
#
# Every particle carries a ball (a disc in 2D) of radius $R = k h$. For particle $i$ of one body and $j$ of
# another, $\mathbf x_{ij} = \mathbf x_i - \mathbf x_j$, $r = \lvert\mathbf x_{ij}\rvert$ and
# $\mathbf e_{ij} = \mathbf x_{ij}/r$:
#
# $$p_d = (R_i + R_j) - r \qquad (32)\qquad \text{contact if } p_d > 0$$
#
# $$F_{ij} = K_p \min\left(F^1_{ij}, F^2_{ij}\right) \qquad (33)$$
#
# $$F^1_{ij} = \begin{cases} m_{ij}\,\dot p_d/\Delta t & \dot p_d > 0\\ 0 & \dot p_d \le 0\end{cases}
# \quad (34) \qquad\qquad F^2_{ij} = \mu_{ij}\sqrt{\frac{R_i R_j}{R_i + R_j}}\; p_d^{3/2} \quad (35)$$
#
# $$\frac{d\mathbf v_i}{dt} \mathrel{+}= \mathbf e_{ij}\,\frac{F_{ij}}{m_i}, \qquad
# \frac{d\mathbf v_j}{dt} \mathrel{-}= \mathbf e_{ij}\,\frac{F_{ij}}{m_j} \qquad \text{(36; $j$: the reaction)}$$
#
# $F^1$ is the force that would stop the approach of the pair within one step; $F^2$ is a Hertz spring. The
# smaller of the two acts, scaled by $K_p$, along the line of centres, equal and opposite on the two particles.

# %% [markdown]
# ### Where `refsph` reads or changes the printed equations
#
# * **Penetration rate.** The paper prints $\dot p_d = \lvert\dot{\mathbf v}_i - \dot{\mathbf v}_j\rvert$, which is
#   never negative. `refsph` uses the rate of Eq. (32), $\dot p_d = -(\mathbf v_i - \mathbf v_j)\cdot\mathbf e_{ij}$:
#   positive while the pair approaches, so nothing acts while it separates.
# * **Effective mass.** Printed: $\rho_i\rho_jR_i^3R_j^3/(\rho_iR_i^3+\rho_jR_j^3)$; used: $m_{ij} = m_i m_j/(m_i +
#   m_j)$, the particles' own masses ($m_{ij} = m_i$ for a rigid partner).
# * **Hertz modulus.** The shear modulus $G = E/(2(1+\nu))$, combined as $\mu_{ij} = \mu_i\mu_j/(\mu_i+\mu_j)$
#   ($= \mu_i$ for a rigid partner).
# * **2D.** A particle stands for a row of particles $\Delta p$ apart through the thickness, so the Hertz force
#   per unit thickness is $F^2/\Delta p$.
# * **Radius.** $k = \Delta p/(2h)$, so $R = \Delta p/2$: two bodies whose surface particles are one spacing
#   apart are just touching, as their faces are.
# * **Scaling factor.** $K_p = 50$, chosen below by a bounce test.
#
# How big are the two forces? For a steel particle against a rigid one, $F^1$ does not depend on the penetration
# and $F^2$ does not depend on the speed, so they cross at a penetration that grows with the approach speed.

# %%
mat = aisi4340_material()                      # AISI 4340, elastic constants of Table 3
DP = 0.25e-3                                   # particle spacing [m]
NUM = Numerics(beta1=0.5, beta2=0.5)           # artificial viscosity of Tables 4-5; contact: the defaults
H = NUM.h_over_dp * DP
R_BALL = DP / (2 * H) * H                      # R = k h with k = dp / (2h)
V_IMPACT = 100.0                               # impact speed of the bounce test [m/s]


def F1_rate(m_ij, pdot, dt):
    """Eq. (34) for one pair."""
    return m_ij * pdot / dt if pdot > 0 else 0.0


def F2_hertz(mu_ij, R_i, R_j, p_d, thickness=1.0):
    """Eq. (35) for one pair, per unit thickness in 2D (thickness = dp)."""
    return mu_ij * math.sqrt(R_i * R_j / (R_i + R_j)) * max(p_d, 0.0) ** 1.5 / thickness


m_p = mat.rho0 * DP**2                         # particle mass per unit thickness [kg/m]
dt_cfl = integrate.cfl_time_step(make_state(np.zeros((1, 2)), [[V_IMPACT, 0.0]], mat.rho0, DP**2), mat, H,
                                 NUM.courant)
print(f"K_p = {NUM.contact_Kp}, R = {R_BALL / DP:.2f} dp, G = {mat.G / 1e9:.1f} GPa, time step {dt_cfl * 1e9:.1f} ns")
p = np.linspace(0, 0.6, 300) * DP
fig, ax = plt.subplots(figsize=(7, 4.2))
ax.plot(p / DP, [F2_hertz(mat.G, R_BALL, R_BALL, q, DP) for q in p], "k", lw=2, label=r"$F^2$ (Hertz, Eq. 35)")
for v, c in zip((1.0, 10.0, 100.0), ("C2", "C1", "C3")):
    ax.axhline(F1_rate(m_p, v, dt_cfl), color=c, ls="--", label=fr"$F^1$ (Eq. 34), $\dot p_d$ = {v:g} m/s")
ax.set_yscale("log")
ax.set_ylim(1e3, 3e7)
ax.set_xlabel(r"penetration $p_d$ / $\Delta p$")
ax.set_ylabel("force / $K_p$ [N/m]")
ax.legend(loc="lower right")
fig.tight_layout()
ch.show(fig, "05_force_law.png", caption="The pinball forces per unit K_p: the Hertz force F² (Eq. (35)) grows with "
                                         "penetration, the rate force F¹ (Eq. (34), dashed) does not.")

# %% [markdown]
# The force is the lower of the two curves. At impact speeds the Hertz spring governs until the pair has gone a
# good part of a spacing into each other; the rate force takes over only when the approach has almost stopped.
#
# ## The plainest code: one pair at a time
#
# Eqs. (32)–(36) pair by pair, for a set $a$ of deformable particles and a set $b$ of another body (`math.inf`
# for the mass and modulus of a rigid one). The optional friction is the one of the section on friction below.

# %%
def plain_pinball(x_a, v_a, m_a, x_b, v_b, m_b, R, G_a, G_b, dt, K_p, thickness=1.0, friction=None, T_a=None,
                  candidates=None):
    """Eqs. (32)-(36), one pair at a time. m_b: a number (math.inf: rigid) or one mass per particle of b;
    G_a, G_b: Hertz moduli (math.inf: rigid); candidates: (i, j) pairs to look at (default: all).
    Returns (a, force_b, pairs): acceleration of each particle of a, force on each particle of b, and one record
    per pair in contact."""
    n_a, n_b, d = len(x_a), len(x_b), len(x_a[0])

    def red(p, q):                                               # p q / (p + q), = p for q = inf
        return p if math.isinf(q) else p * q / (p + q)

    a = np.zeros((n_a, d))
    force_b = np.zeros((n_b, d))
    pairs = []
    if candidates is None:
        candidates = [(i, j) for i in range(n_a) for j in range(n_b)]
    for i, j in candidates:
        dx = [float(x_a[i][k] - x_b[j][k]) for k in range(d)]
        r = math.sqrt(sum(c * c for c in dx))
        p_d = (R + R) - r                                        # Eq. (32), R_i = R_j = R
        if p_d <= 0.0 or r == 0.0:
            continue
        e = [c / r for c in dx]
        dv = [float(v_a[i][k] - v_b[j][k]) for k in range(d)]
        pdot = -sum(dv[k] * e[k] for k in range(d))              # rate of Eq. (32), > 0 while approaching
        m_j = m_b if np.isscalar(m_b) else m_b[j]
        m_ij = red(float(m_a[i]), float(m_j))
        F1 = F1_rate(m_ij, pdot, dt)                             # Eq. (34)
        F2 = F2_hertz(red(G_a, G_b), R, R, p_d, thickness)       # Eq. (35)
        F = K_p * min(F1, F2)                                    # Eq. (33)
        f = [F * c for c in e]                                   # on i, along the line of centres
        ft = 0.0
        if friction is not None:
            vn = sum(dv[k] * e[k] for k in range(d))
            vt = [dv[k] - vn * e[k] for k in range(d)]
            speed = math.sqrt(sum(c * c for c in vt))
            Ts = min(max((T_a[i] - friction.T_room) / (friction.T_melt - friction.T_room), 0.0), 1.0)
            mu = friction.mu0 * (1.0 - Ts**friction.q)           # second paper, Eq. (11)
            ft = min(mu * F, m_ij * speed / dt)                  # Coulomb, Eq. (10), capped at sticking
            if speed > 0:
                f = [f[k] - ft * vt[k] / speed for k in range(d)]
        for k in range(d):                                       # Eq. (36): equal and opposite
            a[i, k] += f[k] / m_a[i]
            force_b[j, k] -= f[k]
        pairs.append(dict(i=i, j=j, p_d=p_d, pdot=pdot, F1=F1, F2=F2, F=F, ft=ft, e=e, f=f))
    return a, force_b, pairs


# %% [markdown]
# ## The package against the plain loop
#
# `refsph.contact.pinball_contact` does the same with arrays and a k-d tree. We compare the two on random
# configurations: a jittered block of deformable particles just above a jittered layer of partner particles,
# random velocities, in 2D and 3D, rigid and deformable partners, friction off and on (with random temperatures).
# Each pair is also checked on its own: equal and opposite, pushing and never pulling, and with friction its part
# across the line of centres is at most $\mu(T)$ times the part along it.

# %%
def random_contact(rng, d, n_side, rigid):
    """Jittered block (3 layers) above a jittered layer of partner particles, random velocities, d dimensions."""
    side = [n_side] * (d - 1) + [3]
    xa = lattice([n * DP for n in side], DP) + rng.uniform(-0.2, 0.2, (int(np.prod(side)), d)) * DP
    xb = lattice([n * DP for n in [n_side + 2] * (d - 1) + [1]], DP) - np.r_[[DP] * (d - 1), [0.8 * DP]]
    xb += rng.uniform(-0.2, 0.2, xb.shape) * DP
    va = rng.normal(0.0, 60.0, xa.shape)
    vb = np.broadcast_to(rng.normal(0.0, 30.0, d), xb.shape).copy() if rigid else rng.normal(0.0, 60.0, xb.shape)
    ma = mat.rho0 * DP**d * rng.uniform(0.8, 1.2, len(xa))
    mb = math.inf if rigid else mat.rho0 * DP**d * rng.uniform(0.8, 1.2, len(xb))
    return xa, va, ma, xb, vb, mb


AISI1045 = paper_data.AISI1045_RLA             # friction data of the second paper (Table 2)
friction_1045 = CoulombFriction(mu0=AISI1045["mu0"], q=AISI1045["q_friction"], T_room=AISI1045["T_room_K"],
                                T_melt=AISI1045["T_melt_K"])
rng = np.random.default_rng(5)
dt_test = 2.0e-8
branches = dict(rate=0, hertz=0, separating=0)
n_capped = 0                                   # friction pairs held by the sticking cap m_ij |v_t| / dt
for d in (2, 3):
    thickness = DP if d == 2 else 1.0
    for rigid in (True, False):
        for friction in (None, friction_1045):
            xa, va, ma, xb, vb, mb = random_contact(rng, d, 12 if d == 2 else 4, rigid)
            Ta = rng.uniform(friction_1045.T_room, friction_1045.T_melt, len(xa))
            G_b = math.inf if rigid else mat.G
            contact = PinballContact(k=DP / (2 * H), K_p=NUM.contact_Kp, friction=friction)
            res = pinball_contact(xa, va, ma, xb, vb, mb, R_BALL, mat.G, G_b, dt_test, contact,
                                  thickness=thickness, T_a=Ta)
            a_ref, fb_ref, pairs = plain_pinball(xa, va, ma, xb, vb, mb, R_BALL, mat.G, G_b, dt_test,
                                                 NUM.contact_Kp, thickness, friction, Ta)
            scale = np.max(np.abs(ma[:, None] * a_ref))
            assert len(pairs) == res.n_contacts and len(pairs) >= 8
            assert np.allclose(res.a * ma[:, None], a_ref * ma[:, None], rtol=0, atol=1e-12 * scale)
            assert np.allclose(res.force_on_b, fb_ref, rtol=0, atol=1e-12 * scale)
            assert math.isclose(res.max_penetration, max(q["p_d"] for q in pairs), rel_tol=1e-12)
            # equal and opposite: the total force on a plus the total force on b is zero
            assert np.allclose(np.sum(ma[:, None] * res.a, axis=0) + np.sum(res.force_on_b, axis=0), 0.0,
                               rtol=0, atol=1e-12 * scale)
            for q in pairs:                      # and pair by pair: the package on each pair alone
                i, j = q["i"], q["j"]
                one = pinball_contact(xa[i:i + 1], va[i:i + 1], ma[i:i + 1], xb[j:j + 1], vb[j:j + 1],
                                      mb if rigid else mb[j:j + 1], R_BALL, mat.G, G_b, dt_test, contact,
                                      thickness=thickness, T_a=Ta[i:i + 1])
                f_a, f_b, e = ma[i] * one.a[0], one.force_on_b[0], np.array(q["e"])
                assert np.allclose(f_a, -f_b, rtol=0, atol=1e-12 * scale)
                assert np.allclose(f_a, q["f"], rtol=0, atol=1e-12 * scale)
                f_n = f_a @ e                                     # along the line of centres
                f_t = np.linalg.norm(f_a - f_n * e)              # across it: friction only
                assert f_n >= 0.0                                 # pushes, never pulls
                if friction is None:
                    assert f_t <= 1e-12 * scale
                else:
                    mu_i = friction.mu(Ta[i])
                    assert f_t <= mu_i * f_n * (1 + 1e-12) + 1e-12 * scale
                    dv = va[i] - vb[j]
                    assert (f_a - f_n * e) @ (dv - (dv @ e) * e) <= 1e-12 * scale   # against the sliding
                    n_capped += bool(q["F"] > 0 and f_t < mu_i * f_n * (1 - 1e-9))
                branches["separating" if q["pdot"] <= 0 else ("rate" if q["F1"] <= q["F2"] else "hertz")] += 1
            print(f"{d}D, {'rigid' if rigid else 'deformable'} partner, friction {'on ' if friction else 'off'}: "
                  f"{len(pairs):3d} pairs, max |package - plain loop| = "
                  f"{np.max(np.abs((res.a - a_ref) * ma[:, None])) / scale:.1e} of the largest force")
print("pairs by branch of Eq. (33):", branches, f"; friction pairs held by the sticking cap: {n_capped}")
assert min(branches.values()) > 0 and n_capped > 0               # every branch was exercised

# %% [markdown]
# The same loop can watch a running solver. `ContactSpy` wraps the pinball call of the TLSPH solver (the solver
# looks up `refsph.contact.pinball_contact` at every rate evaluation), runs the plain loop on the same arguments,
# checks that both give the same forces, and keeps the pairs. It changes nothing in the run.

# %%
class ContactSpy:
    """Context manager: every pinball evaluation of a TLSPH run is also done by plain_pinball and compared;
    ``calls`` keeps (dt, pairs, total force on b) per evaluation, two per step (predictor, corrector)."""

    def __enter__(self):
        self.calls, self.worst, self._original = [], 0.0, contact_module.pinball_contact

        def spy(x_a, v_a, m_a, x_b, v_b, m_b, R, mu_a, mu_b, dt, contact, thickness=1.0, T_a=None):
            out = self._original(x_a, v_a, m_a, x_b, v_b, m_b, R, mu_a, mu_b, dt, contact, thickness, T_a)
            near = cKDTree(x_b).query_ball_point(x_a, 2 * R)
            cand = [(i, j) for i, js in enumerate(near) for j in js]
            a, fb, pairs = plain_pinball(x_a, v_a, m_a, x_b, v_b, m_b, R, mu_a, mu_b, dt, contact.K_p, thickness,
                                         contact.friction, T_a, candidates=cand)
            if pairs:
                scale = max(abs(q["F"]) for q in pairs) + 1e-300
                err = max(np.max(np.abs((out.a - a) * m_a[:, None])), np.max(np.abs(out.force_on_b - fb))) / scale
                assert err < 1e-12, err
                self.worst = max(self.worst, err)
            self.calls.append((dt, pairs, out.force_on_b.sum(axis=0)))
            return out

        contact_module.pinball_contact = spy
        return self

    def __exit__(self, *exc):
        contact_module.pinball_contact = self._original
        return False

    def corrector(self):
        """The evaluations whose forces moved the particles and were recorded (the second of each step)."""
        assert len(self.calls) % 2 == 0
        return self.calls[1::2]


# %% [markdown]
# ## The bounce test: a steel disc thrown at a wall
#
# An elastic AISI 4340 disc (2D, radius 2.5 mm, $\Delta p$ = 0.25 mm) flies at 100 m/s towards a wall of three
# layers of rigid particles (a `RigidBody` at rest, its face at $x = 0$). It starts two spacings away, so that no
# disc particle is within the kernel support $2h$ of a wall particle at $t = 0$. We run it with both methods.
#
# In ESPH the wall particles are neighbours. They move with the wall's velocity and carry a density (continuity
# equation, never below $\rho_0$) and a pressure $p \ge 0$, but no deviatoric stress: they push back where the
# metal presses on them, and never pull. In TLSPH the pinball acts.
#
# The reference is a kinematic wall (`RigidWall`: a particle about to come closer than half a spacing to the
# plane is stopped): no penetration, no constant to choose. The coefficient of restitution is
# $e = -P_x(\text{end})/P_x(0)$, with $P_x$ the disc's momentum.

# %%
RD = 2.5e-3                                    # disc radius [m]
GAP_ESPH = 2.0 * DP                            # no disc particle within 2h = 3 dp of a wall particle at t = 0
GAP_TLSPH = 0.25 * DP                          # the pinball needs no kernel-range gap
COL = dict(esph="C0", tlsph="C3")


def disc_state(v0, gap):
    """Disc of radius RD moving at v0 towards -x; its face (leftmost centre - dp/2) at x = gap."""
    x = lattice([2 * RD, 2 * RD], DP)
    x = x[np.sum((x - RD) ** 2, axis=1) < RD**2]
    x[:, 0] += gap - (x[:, 0].min() - 0.5 * DP)
    return make_state(x, [-v0, 0.0], mat.rho0, DP**2)


def wall_state(lo, hi, normal_axis=0, spacing=DP, T0=None):
    """Rigid wall particles (body 1) on x < 0 (normal_axis 0) or y < 0 (1), `spacing` apart, in rows from dp/2 to
    5 dp/2 below the face (so the wall face, and the pinball surface, is at 0), spanning [lo, hi] along it."""
    depth = -0.5 * DP - np.arange(0.0, 2.01 * DP, spacing)
    along = np.arange(lo, hi, spacing) + 0.5 * spacing
    A, B = np.meshgrid(depth, along) if normal_axis == 0 else np.meshgrid(along, depth)
    xw = np.stack([A.ravel(), B.ravel()], axis=1)
    return make_state(xw, np.zeros(2), mat.rho0, spacing**2, T0=T0, body=np.ones(len(xw), dtype=int))


def run_case(body, wall, method="tlsph", numerics=NUM, t_end=1e-6, friction=None, axis=0):
    """A deformable body against a particle wall (a State of body 1) or, with wall=None, against the kinematic
    RigidWall at x[axis] = 0. Records every step: momentum and energy (kinetic + elastic) of the body and its
    closest distance to the wall [dp]."""
    n = body.n
    if wall is None:
        setup = Setup(state=body, material=mat, dp=DP, numerics=numerics, t_end=t_end, n_snapshots=1,
                      walls=(RigidWall(axis, 0.0, 0.5 * DP),))
    else:
        setup = Setup(state=concatenate_states(body, wall), material=mat, dp=DP, numerics=numerics, t_end=t_end,
                      n_snapshots=1, rigid=(RigidBody("wall", 1, (0.0, 0.0)),), friction=friction)
        tree = cKDTree(wall.x)                                   # the wall does not move

    def record(s, _setup):
        xb, p = s.x[:n], material.eos_pressure(s.rho[:n], mat.rho0, mat.K)
        ss = np.einsum("nab,nab->n", s.S[:n], s.S[:n]) + s.S_zz[:n] ** 2
        E_el = np.sum(s.m[:n] / s.rho[:n] * (p * p / (2 * mat.K) + ss / (4 * mat.G)))
        dmin = tree.query(xb)[0].min() if wall is not None else xb[:, axis].min() + 0.5 * DP
        return dict(t=s.t, Px=float(np.sum(s.m[:n] * s.v[:n, 0])), dmin=float(dmin) / DP,
                    face=float(xb[:, axis].min()), E=float(0.5 * np.sum(s.m[:n, None] * s.v[:n] ** 2) + E_el))

    res = simulate(setup, method, progress=False, record=record, record_every=1)
    o = {k: np.asarray(v) for k, v in res.history.items() if k != "reaction"}
    P0, P1 = (np.sum(s.m[:n, None] * s.v[:n], axis=0) for s in (body, res.state))
    o.update(P0=P0, P1=P1, restitution=-P1[axis] / P0[axis], energy=o["E"][-1] / o["E"][0],
             energy_max=o["E"].max() / o["E"][0], closest=o["dmin"].min(), n_steps=res.summary["n_steps"],
             pen=res.summary["diagnostics"].get("max_pinball_penetration_m", 0.0) / DP)
    if wall is not None:                                         # force on the wall, every step
        o["t_F"], o["F"] = res.history["reaction"]["t"], res.history["reaction"]["wall"]
        o["J"] = np.asarray(res.summary["diagnostics"]["reaction_impulse"]["wall"])
    return o


def bounce_t_end(v0, gap):
    """Time to close the gap twice (there and back) plus eight disc crossings of the longitudinal wave."""
    return 2 * gap / v0 + 8 * 2 * RD / mat.c_longitudinal


wall_main = wall_state(-4 * DP, 2 * RD + 4 * DP)
CACHE = {}                                     # bounce(...) runs, by their arguments


def bounce(v0, Kp=NUM.contact_Kp, k_factor=1.0, kinematic=False):
    """One TLSPH disc bounce (cached), from a quarter spacing, with scaling factor Kp and pinball radius factor
    k = k_factor dp / (2h); kinematic: against the RigidWall instead."""
    key = (v0, Kp, k_factor, kinematic)
    if key not in CACHE:
        gap = GAP_TLSPH + max(0.0, k_factor - 1.0) * DP              # no contact at t = 0
        numerics = Numerics(**{**NUM.__dict__, "contact_Kp": Kp, "contact_k": k_factor * DP / (2 * H)})
        CACHE[key] = run_case(disc_state(v0, gap), None if kinematic else wall_main, numerics=numerics,
                              t_end=bounce_t_end(v0, gap))
    return CACHE[key]


disc_main = disc_state(V_IMPACT, GAP_ESPH)
T_END = bounce_t_end(V_IMPACT, GAP_ESPH)
main = {"esph": run_case(disc_main, wall_main, "esph", t_end=T_END)}
with ContactSpy() as spy_main:                 # the TLSPH run, watched by the plain loop at every evaluation
    main["tlsph"] = run_case(disc_main, wall_main, "tlsph", t_end=T_END)
print(f"disc: {disc_main.n} particles, wall: {wall_main.n} particles; TLSPH: {len(spy_main.calls)} pinball "
      f"evaluations, each equal to the plain loop's to {spy_main.worst:.1e} of its largest pair force")
for method, o in main.items():
    print(f"{method.upper():5s}: {o['n_steps']} steps, restitution {o['restitution']:.3f}, closest disc-wall "
          f"distance {o['closest']:.3f} dp" + (f", max pinball penetration {o['pen']:.3f} dp" if o["pen"] else ""))

# %% [markdown]
# ### The checks: impulse, no crossing, a real bounce
#
# Every force between a disc and a wall particle is equal and opposite (ESPH: the antisymmetric pair terms of
# Eq. 11; TLSPH: Eq. 36). So the wall's impulse must equal the disc's change of momentum, to round-off.

# %%
for method, o in main.items():
    err = np.abs(o["J"] + (o["P1"] - o["P0"])) / abs(o["P0"][0])
    print(f"{method.upper():5s}: wall impulse {o['J'][0]:+.6f} N s/m, disc momentum change "
          f"{o['P1'][0] - o['P0'][0]:+.6f} N s/m, mismatch {err.max():.1e} of the initial momentum")
    assert err.max() < 1e-10                                        # the wall's impulse is the disc's change
    assert np.all(o["face"] > 0.0) and o["closest"] > 0.5           # no disc centre crossed the wall face
    assert o["restitution"] > 0.8                                   # it bounced
    assert o["energy_max"] <= 1.0 + 1e-3                            # without making energy
    # the force is recorded once per step; force times step size, summed, is the impulse
    assert np.allclose(np.sum(o["F"] * np.diff(o["t"])[:, None], axis=0), o["J"], rtol=1e-12,
                       atol=1e-12 * abs(o["P0"][0]))
# the spy's corrector evaluations are the recorded ones: their force on the wall, times dt, is the impulse
J_spy = sum(dt * fb for dt, _, fb in spy_main.corrector())
assert np.allclose(J_spy, main["tlsph"]["J"], rtol=1e-12, atol=1e-12 * abs(main["tlsph"]["P0"][0]))
kin = bounce(V_IMPACT, kinematic=True)         # starts closer: shift its clock to the same impact time
t_kin = kin["t"] + (GAP_ESPH - GAP_TLSPH) / V_IMPACT
print(f"kinematic wall: restitution {kin['restitution']:.3f}")

fig, ax = plt.subplots(1, 2, figsize=(10, 4))
for method, o in main.items():
    ax[0].plot(o["t_F"] * 1e6, -o["F"][:, 0] / 1e6, color=COL[method], lw=0.7, label=method.upper())
    ax[1].plot(o["t"] * 1e6, o["Px"], color=COL[method], label=method.upper())
ax[1].plot(t_kin * 1e6, kin["Px"], "k--", lw=1, label="kinematic wall")
ax[0].set_ylabel("force on the wall $-F_x$ [MN/m]")
ax[1].set_ylabel("disc momentum $P_x$ [N s/m]")
for a in ax:
    a.set_xlabel("t [µs]")
    a.legend()
fig.tight_layout()
ch.show(fig, "05_bounce_history.png", caption="A disc bouncing off a wall of tool particles, ESPH and TLSPH: force on "
                                              "the wall (left), disc momentum (right); dashed: a kinematic wall.")

# %% [markdown]
# Both methods bounce the disc, and no disc particle crosses the wall face. Neither gives back all the momentum:
# part of the energy stays in the disc as vibration and part is dissipated by the artificial viscosity; the
# kinematic wall shows how much of that is not the contact's doing.
#
# The two forces look different. The ESPH wall acts from a distance (the kernel reaches $2h$ = 3 spacings) and
# builds up smoothly. The TLSPH force starts only when the pinballs overlap, and it comes in one-step spikes: a
# pair pushed apart stops approaching, $F^1$ drops to zero, the disc behind pushes it in again.
#
# ## Choosing $K_p$
#
# The paper says $K_p$ is "generally chosen through numerical experiment" and does not give its value. Here is the
# experiment: TLSPH bounces for a range of $K_p$, starting a quarter spacing from the wall.

# %%
SPEEDS = (V_IMPACT,) if ch.quick else (50.0, V_IMPACT, 200.0)
KPS = (1.0, 5.0, 50.0, 1000.0) if ch.quick else (1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0)

for v0 in SPEEDS:
    print(f"{v0:.0f} m/s, kinematic wall: restitution {bounce(v0, kinematic=True)['restitution']:.3f}")
    for Kp in KPS:
        o = bounce(v0, Kp)
        print(f"   K_p = {Kp:6g}: restitution {o['restitution']:.3f}, max penetration {o['pen']:.3f} dp, "
              f"energy after / before {o['energy']:.3f} (largest during contact {o['energy_max']:.3f})")
    assert abs(bounce(v0, 50.0)["restitution"] - bounce(v0, kinematic=True)["restitution"]) < 0.05
    assert bounce(v0, 1.0)["restitution"] < 0.5 * bounce(v0, 50.0)["restitution"]
    assert bounce(v0, 50.0)["energy_max"] <= 1.0 + 1e-3              # the default makes no energy
assert max(bounce(v0, 1000.0)["energy"] for v0 in SPEEDS) > 1.0      # K_p = 1000 does

fig, ax = plt.subplots(1, 2, figsize=(10, 4))
for v0, c in zip(SPEEDS, ("C3", "C0", "C2")):
    ax[0].semilogx(KPS, [bounce(v0, Kp)["restitution"] for Kp in KPS], "o-", color=c, label=f"{v0:.0f} m/s")
    ax[0].axhline(bounce(v0, kinematic=True)["restitution"], color=c, ls="--", lw=1)
    ax[1].loglog(KPS, [bounce(v0, Kp)["pen"] for Kp in KPS], "o-", color=c, label=f"{v0:.0f} m/s")
for a in ax:
    a.axvline(NUM.contact_Kp, color="k", lw=0.6)
    a.set_xlabel("$K_p$")
    a.legend()
ax[0].set_ylabel("restitution (dashed: kinematic wall)")
ax[1].set_ylabel(r"max penetration $p_d$ / $\Delta p$")
fig.tight_layout()
ch.show(fig, "05_kp_scan.png", caption="TLSPH bounces against the scaling factor K_p at several speeds: restitution "
                                       "(left; dashed: a kinematic wall) and largest penetration (right).")

# %% [markdown]
# A small $K_p$ lets the disc sink deep into the wall and kills the rebound. At $K_p$ = 50 the restitution has
# reached the kinematic wall's and the penetration is a small fraction of a spacing (a full-mode run shows the
# plateau between). At the other end, $K_p$ = 1000 makes energy: the disc leaves with more than it brought, and
# the penetration grows again. $K_p$ times the Hertz spring is then a spring too stiff for the time step of the
# bulk material (its period is no longer long compared with $\Delta t$), and the explicit integrator amplifies
# its oscillation. $K_p$ = 50 is far from that limit: it is `refsph`'s default.

# %% [markdown]
# ## Friction (off by default)
#
# The paper's contact is frictionless. The second paper uses Coulomb's law with a coefficient that falls with
# temperature like the Johnson–Cook softening term:
#
# $$f_\text{fric} = \mu(T)\, f_\text{cont} \quad (10), \qquad
# \mu(T) = \mu_0\left[1 - \left(\frac{T - T_r}{T_m - T_r}\right)^q\right] \quad (11).$$
#
# `refsph.contact.CoulombFriction` adds to each pinball pair a force against the pair's sliding velocity, of size
# $\mu(T_i)F_{ij}$, capped at $m_{ij}\lvert\mathbf v_t\rvert/\Delta t$ so that friction stops the sliding of a
# pair but never reverses it within a step (the loop above does the same). It is TLSPH only, and needs the
# particles' temperatures in the state (`make_state(..., T0=...)`). Its heat: `Setup.friction_heat` (chapter 11).
#
# The test case: an elastic steel block (2 mm × 1 mm) thrown obliquely at a wall, 100 m/s along it and 25 m/s
# towards it. The ratio of the tangential to the normal impulse on the wall, $J_t/J_n$, measures the drag.

# %%
V_T, V_N = 100.0, 25.0                         # speed along and towards the wall [m/s]


def oblique(method="tlsph", mu0=None, spacing=DP):
    """The 2 mm x 1 mm block thrown at a particle wall along y = 0 whose particles are `spacing` apart;
    mu0: Coulomb friction with AISI 1045's mu(T) law but this mu0 (None: frictionless)."""
    gap = GAP_ESPH if method == "esph" else 0.1 * DP
    body = make_state(lattice([2e-3, 1e-3], DP) + [0.0, gap], [V_T, -V_N], mat.rho0, DP**2, T0=293.0)
    t_end = 2 * gap / V_N + 20 * 1e-3 / mat.c_longitudinal
    wall = wall_state(-4 * DP, 2e-3 + V_T * t_end + 4 * DP, normal_axis=1, spacing=spacing, T0=293.0)
    fr = None if mu0 is None else CoulombFriction(mu0, friction_1045.q, friction_1045.T_room, friction_1045.T_melt)
    o = run_case(body, wall, method, t_end=t_end, friction=fr, axis=1)
    o.update(Jt_over_Jn=o["J"][0] / -o["J"][1], vt_after=o["P1"][0] / np.sum(body.m))
    return o


slide = {"TLSPH, wall particles dp apart": oblique(), "TLSPH, wall particles dp/4 apart": oblique(spacing=DP / 4),
         "ESPH, wall particles dp apart": oblique("esph")}
for case, o in slide.items():
    print(f"{case:34s} (no friction): J_t / J_n = {o['Jt_over_Jn']:+.3f}, speed along the wall after "
          f"{o['vt_after']:6.1f} m/s (before {V_T:.0f})")
drag = [abs(o["Jt_over_Jn"]) for o in slide.values()]
assert drag[2] > drag[0] > drag[1]

# %% [markdown]
# Without friction the wall should not drag the block at all, and yet it does:
#
# * **A TLSPH wall of particles is a washboard.** The pinball surface dips between the wall particles, and since
#   the pinball acts only on approach, sliding over the bumps is not neutral. On a wall of particles a quarter
#   spacing apart the bumps are small and the drag almost vanishes; that wall is the one to use for friction
#   (Exercise 3).
# * **An ESPH wall grabs.** The block's particles see the wall's zero velocity in their velocity gradient and
#   artificial viscosity, over a kernel length.
#
# ## Where it fails
#
# * **$K_p$ too small or too large:** $K_p$ = 1 dissipates the rebound, $K_p$ = 1000 makes energy (above).
# * **Chatter.** The pinball force is a train of one-step spikes; only its average over many steps is smooth.
# * **The time step enters the force.** $F^1$ is divided by $\Delta t$: halving the step doubles it.
# * **Penetration grows with the impact speed.** With $K_p$ = 1 a fast disc goes through the wall face:

# %%
o = bounce(400.0, 1.0)
print(f"K_p = 1 at 400 m/s: lowest disc centre at x = {o['face'].min() / DP:+.2f} dp (the wall face is at 0)")
assert o["face"].min() < 0.0

# %% [markdown]
# * **No self-contact by default.** The solver applies the pinball between tools and between different bodies, not
#   within one: a chip that curls back onto its workpiece passes through it unless `Numerics.self_contact` is set.
# * **Isothermal here:** frictional heat and conduction into the tool are chapter 11's.
# * **Resolution.** The pinball radius, the washboard and the ESPH stand-off all scale with $\Delta p$: a particle
#   wall is a surface only to within a fraction of a spacing.
# * **Sliding.** On a row of tool particles the pinball's resistance to sliding is set by the row's geometry and
#   the step, not by $\mu$. The continuation, `05_penalty_contact`, shows it on a tilted plane with a closed form
#   and writes the alternative of `refsph.penalty`: a penalty force on the tool's exact geometry (issue 22).
#
# ## Your turn
#
# Predict first, run, then open *What you should see*. The last exercise asks for code, graded against the package.
#
# ### Exercise 1 — The scaling factor $K_p$
#
# Predict: with $K_p$ = 5 instead of 50, does the disc go deeper into the wall or less deep? Does it bounce back
# faster or slower?

# %% tags=["exercise"]
K_P = 50          # <- change this (e.g. to 5) and run the cell again
o = bounce(V_IMPACT, K_P)
print(f"K_p = {K_P:g}: restitution {o['restitution']:.3f}, max penetration {o['pen']:.3f} dp, "
      f"energy after / before {o['energy']:.3f}")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# With $K_p$ = 5 the disc sinks several times deeper into the wall and comes back clearly slower: the softer
# contact takes in energy on the way in and does not give it all back (nothing acts while the pairs separate).
# </details>

# %% [markdown]
# ### Exercise 2 — The pinball radius factor $k$
#
# Predict: the pinball radius is $R = k h$, here $k$ = `K_FACTOR` $\times\,\Delta p/(2h)$. With `K_FACTOR` = 1.2,
# does the disc stop closer to the wall or farther from it? Is the contact stiffer?

# %% tags=["exercise"]
K_FACTOR = 1.0    # <- change this (e.g. to 1.2, or 0.8) and run the cell again
o = bounce(V_IMPACT, k_factor=K_FACTOR)
print(f"k = {K_FACTOR:g} dp/(2h): contact starts at 2R = {K_FACTOR:g} dp; closest disc-wall distance "
      f"{o['closest']:.3f} dp, max penetration {o['pen']:.3f} dp, restitution {o['restitution']:.3f}")

# %% [markdown]
# <details><summary>What you should see</summary>
#
# The disc stops about 0.2 spacings farther from the wall (the contact surface moved out with $2R$), while the
# penetration and the restitution hardly change: $k$ sets *where* the wall is, not how stiff it is.
# $k = \Delta p/(2h)$ puts the contact where the faces are.
# </details>

# %% [markdown]
# ### Exercise 3 — Friction and Coulomb's bound
#
# Predict: turn friction on with $\mu_0$ = 0.81 (AISI 1045) for the oblique throw at the fine wall. How much
# speed along the wall does the block lose? Can the friction impulse of the pairs exceed $\mu$ times their
# normal impulse, that is, can $J_f = \sum \Delta t \sum_\text{pairs} \lvert\mathbf f_t\rvert$ exceed
# $\mu J_N$ with $J_N = \sum\Delta t\sum_\text{pairs} F_{ij}$?

# %% tags=["exercise"]
MU0 = 0.0         # <- change this (e.g. to 0.81) and run the cell again
with ContactSpy() as spy:
    o = oblique(mu0=MU0, spacing=DP / 4)
J_N = sum(dt * sum(q["F"] for q in pairs) for dt, pairs, _ in spy.corrector())
J_f = sum(dt * sum(q["ft"] for q in pairs) for dt, pairs, _ in spy.corrector())
print(f"mu0 = {MU0}: J_f / J_N = {J_f / J_N:.3f}, wall J_t / J_n = {o['Jt_over_Jn']:+.3f}, speed along the wall "
      f"after {o['vt_after']:.1f} m/s (before {V_T:.0f})")
assert J_f <= MU0 * J_N * (1 + 1e-12)          # Coulomb's bound, summed over the run

# %% [markdown]
# <details><summary>What you should see</summary>
#
# With $\mu_0$ = 0.81 the block loses a large part of its speed along the wall, $J_f/J_N$ comes out at (or just
# below, where pairs stuck) $\mu_0$, never above it, and the wall's $J_t/J_n$ is close to $\mu_0$ (a little above
# it: the fine wall still has small bumps).
# </details>

# %% [markdown]
# ### Exercise 4 — Write the pinball force yourself
#
# Write Eqs. (32)–(36) for particles $a$ (positions `x_a` [m], velocities `v_a` [m/s], masses `m_a` [kg/m in 2D])
# against rigid particles $b$ at rest (`x_b`): return the acceleration of each $a$ particle, shape (n, d). For a
# rigid partner $m_{ij} = m_i$ and $\mu_{ij} = G$; in 2D divide the Hertz force by `thickness` = $\Delta p$ (3D: 1).
# Whole arrays, no loop over particles. Predict: which case fails if $F^1$ is not zero for separating pairs?

# %% tags=["exercise"]
def my_pinball(x_a, v_a, m_a, x_b, R, G, dt, K_p, thickness):
    """Eqs. (32)-(36): acceleration (n_a, d) of particles a from rigid particles b at rest, pinball radius R."""
    raise NotImplementedError("write the pinball contact here")      # <- replace this line by your code


def pkg_pinball(x_a, v_a, m_a, x_b, R, G, dt, K_p, thickness):
    return pinball_contact(x_a, v_a, m_a, x_b, 0 * x_b, math.inf, R, G, math.inf, dt, PinballContact(1.0, K_p),
                           thickness=thickness).a


from refsph.teaching.grader import case, check
rng_ex, at = np.random.default_rng(9), (R_BALL, mat.G, dt_test, NUM.contact_Kp)
cases_ex4 = [case(*random_contact(rng_ex, 2, 12, True)[:4], *at, DP, label="2D block, random velocities"),
             case(*random_contact(rng_ex, 3, 4, True)[:4], *at, 1.0, label="3D block, random velocities")]
for v0, what in ((V_IMPACT, "the disc pressing into the wall"), (-V_IMPACT, "the disc leaving it")):
    d_ex = disc_state(v0, -0.1 * DP)                                 # its face 0.1 dp inside the wall
    cases_ex4.append(case(d_ex.x, d_ex.v, d_ex.m, wall_main.x, *at, DP, label=what))
report = check(my_pinball, pkg_pinball, cases_ex4)

# %% [markdown]
# <details><summary>What you should see</summary>
#
# As handed out: `FAIL ... not written yet`. The random velocities and the disc leaving the wall catch an $F^1$ that
# does not vanish while a pair separates ($\dot p_d \le 0$: no force, Eq. 34); the 2D cases a missing division by
# the thickness. Pairs: `cKDTree(x_b).query_ball_point(x_a, 2 * R)`, or all distances at once by broadcasting.
# </details>
