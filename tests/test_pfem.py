"""The PFEM's mechanics against answers known in closed form (issue 24): patch tests to round-off, no volumetric
locking and no pressure checkerboard on a bent cantilever, Newton-Raphson's quadratic convergence, plane-strain
J2 compression against the rigid-plastic curve, the cantilever's period, and a remeshing that conserves mass and
momentum exactly."""
from unittest import mock

import numpy as np
import pytest
import scipy.sparse as sp

from refsph.pfem import solid
from refsph.pfem.element import ppp_stabilisation, pressure_mass, shape_gradients
from refsph.pfem.mesh import alpha_shape_mesh, boundary_edges
from refsph.plasticity import JohnsonCook
from refsph.strength import Elastic

E, NU, RHO = 200e9, 0.3, 7800.0


def lattice(nx, ny, x0, x1, y0, y1):
    X, Y = np.meshgrid(np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1))
    return np.c_[X.ravel(), Y.ravel()]


def law(nu=NU, strength=None):
    return solid.SolidLaw(rho0=RHO, G=E / (2 * (1 + nu)), K=E / (3 * (1 - 2 * nu)), alpha_T=0.0, T_ref=293.0,
                          strength=strength or Elastic())


def fresh_history(mesh):
    m = len(mesh.tri)
    return solid.History(np.zeros((m, 2, 2)), np.zeros(m), np.zeros(m), np.zeros(m), np.ones(m))


def lumped_masses(x, mesh):
    A = shape_gradients(x[mesh.tri])[1]
    return np.bincount(mesh.tri.ravel(), np.repeat(RHO * A / 3.0, 3), minlength=len(x))


def test_element_matrices_are_the_integrals():
    """int N_a N_b and the projection term of Dohrmann & Bochev, by a 3-point rule exact for quadratics."""
    xe = np.array([[[0.1, 0.0], [1.3, 0.2], [0.4, 0.9]]])
    g, A = shape_gradients(xe)
    assert np.allclose(g.sum(axis=1), 0.0) and A[0] > 0
    lam = np.array([[2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])   # N_a at the points
    M = A[0] / 3.0 * lam.T @ lam
    assert np.allclose(pressure_mass(A)[0], M, rtol=1e-14)
    P = lam - lam.mean(axis=1, keepdims=True) * 0 - 1.0 / 3.0
    assert np.allclose(ppp_stabilisation(A)[0], A[0] / 3.0 * P.T @ P, rtol=1e-13, atol=1e-16)
    assert np.allclose(ppp_stabilisation(A)[0] @ np.ones(3), 0.0, atol=1e-16)   # a constant p is not touched


@pytest.mark.parametrize("grad, label", [([[1e-3, 2e-3], [-0.5e-3, 3e-3]], "small"),
                                         ([[0.2, 0.1], [-0.05, -0.15]], "20 % strain")])
def test_patch_test_linear_displacement_is_exact(grad, label):
    """Boundary nodes moved by u = A x + b, interior nodes free (a distorted mesh): the interior nodes land on the
    same linear field and the pressure is uniform, to round-off (small and large deformation)."""
    rng = np.random.default_rng(1)
    x = lattice(6, 6, 0, 1, 0, 1)
    inner = (x[:, 0] > 0) & (x[:, 0] < 1) & (x[:, 1] > 0) & (x[:, 1] < 1)
    x[inner] += rng.uniform(-0.05, 0.05, (inner.sum(), 2))
    mesh = alpha_shape_mesh(x, None)
    du = x @ np.array(grad).T + np.array([1e-4, -2e-4])
    fixed = np.zeros((len(x), 2), bool)
    fixed[~inner] = True
    nodes = solid.make_nodes(x, lumped_masses(x, mesh), 293.0)
    r = solid.newton_step(nodes, mesh, fresh_history(mesh), law(), 1e-3, solid.Loads(fixed=fixed, du_fixed=du),
                          dynamic=False)
    assert np.abs(r.du - du).max() < 1e-14 * np.abs(du).max() * 100
    assert np.ptp(r.p) < 1e-11 * np.abs(r.p).max()
    assert np.ptp(r.history.S, axis=0).max() < 1e-11 * np.abs(r.history.S).max()


def cantilever(ny, nu, L=10.0, H=1.0, P=5e5):
    """Plane-strain cantilever clamped at x = 0 with a parabolic shear load P [N/m] at the tip: tip deflection over
    Timoshenko's, and the nodal mean stress against p = (1 + nu) / 3 sigma_xx = (1 + nu) / 3 P (L - x) y / I."""
    x = lattice(int(ny * L / H), ny, 0, L, -H / 2, H / 2)
    mesh = alpha_shape_mesh(x, None)
    fixed = np.zeros((len(x), 2), bool)
    fixed[x[:, 0] == 0] = True
    tip = np.isclose(x[:, 0], L)
    y = x[tip, 1]
    w = (1 - 4 * y**2 / H**2) * np.where(np.isclose(np.abs(y), H / 2), 0.5, 1.0)   # trapezoid weights
    f = np.zeros((len(x), 2))
    f[tip, 1] = -P * w / w.sum()
    nodes = solid.make_nodes(x, lumped_masses(x, mesh), 293.0)
    r = solid.newton_step(nodes, mesh, fresh_history(mesh), law(nu), 1.0,
                          solid.Loads(fixed=fixed, du_fixed=np.zeros_like(x), f_ext=f), dynamic=False)
    Ep, I, G = E / (1 - nu**2), H**3 / 12, E / (2 * (1 + nu))
    d_tim = P * L**3 / (3 * Ep * I) + P * L / (5 / 6 * G * H)
    d = -r.du[tip & (np.abs(x[:, 1]) < 1e-12), 1][0]
    pa = (1 + nu) / 3 * P * (L - x[:, 0]) * x[:, 1] / I
    inner = (x[:, 0] > 1) & (x[:, 0] < L - 1)
    return d / d_tim, np.abs(r.p - pa)[inner].max() / np.abs(pa).max()


def test_cantilever_converges_without_locking_or_checkerboard():
    """Compressible (nu = 0.3) and nearly incompressible (nu = 0.4999, K / G = 5000) bending: the tip deflection
    converges to Timoshenko's at the same rate for both (a displacement-only linear triangle locks: its deflection
    goes to 0 as nu -> 1/2), and the pressure converges to the linear bending field (a checkerboard would not)."""
    for nu in (0.3, 0.4999):
        res = [cantilever(ny, nu) for ny in (2, 4, 8)]
        err = [1 - d for d, _ in res]
        order = np.log2(err[1] / err[2])
        print(f"nu = {nu}: deflection / Timoshenko {[round(d, 4) for d, _ in res]}, observed order {order:.2f}, "
              f"pressure error {[round(e, 3) for _, e in res]}")
        assert 0 < err[2] < 0.05 and order > 1.2
        assert res[2][1] < 0.5 * res[1][1] and res[1][1] < 0.7 * res[0][1] and res[2][1] < 0.12


def compression(nsteps, strain=0.4, print_newton=False):
    """Plane-strain compression of a square (rollers on two sides, the top pressed by exp(-strain)) with linear
    hardening sigma_y = A + B eps_p: the stress at the end against the rigid-plastic -2 / sqrt(3) sigma_y(eps_p)."""
    x = lattice(4, 4, 0, 1e-3, 0, 1e-3)
    mesh = alpha_shape_mesh(x, None)
    jc = JohnsonCook(A=400e6, B=400e6, n=1.0, C=0.0, m=1.0, eps_dot_0=1.0, T_room=293.0, T_melt=1800.0, cp=450.0,
                     chi=0.9, heating=False)
    lw = law(strength=jc)
    nodes, hist = solid.make_nodes(x, lumped_masses(x, mesh), 293.0), fresh_history(mesh)
    top = np.isclose(x[:, 1], 1e-3)
    fixed = np.zeros((len(x), 2), bool)
    fixed[np.isclose(x[:, 1], 0), 1] = fixed[np.isclose(x[:, 0], 0), 0] = fixed[top, 1] = True
    norms = None
    for k in range(nsteps):
        du = np.zeros_like(x)
        du[top, 1] = 1e-3 * np.exp(-strain * (k + 1) / nsteps) - nodes.x[top, 1]
        r = solid.newton_step(nodes, mesh, hist, lw, 1e-3, solid.Loads(fixed=fixed, du_fixed=du), dynamic=False)
        nodes, hist = solid.commit(nodes, r, 1e-3, dynamic=False), r.history
        if k == nsteps // 2:
            norms = [a for a, _ in r.residuals[1:]]
    R = solid.assemble(nodes, mesh, hist, lw, np.zeros_like(x), nodes.p, 1e-3, False, tangent=False)[0]
    sigma = R[:2 * len(x)][1::2][top].sum() / nodes.x[top, 0].max()
    analytic = -2 / np.sqrt(3) * (400e6 + 400e6 * hist.eps_p.mean())
    return sigma / analytic - 1, norms


def test_newton_converges_quadratically_in_a_plastic_step():
    _, norms = compression(10)
    print("Newton-Raphson residual norms (plastic compression step):", " ".join(f"{r:.1e}" for r in norms))
    assert norms[-1] < 1e-10
    big = [r for r in norms if r > 1e-12]
    for r0, r1 in zip(big[1:-1], big[2:]):                         # e_{k+1} <= C e_k^2 once in the basin
        assert r1 < 10.0 * r0 * r0


def test_plane_strain_compression_against_the_rigid_plastic_curve():
    """At 33 % height reduction (log strain 0.4) the flow stress is within 2 % of -2/sqrt(3) sigma_y(eps_p) at 20
    steps and halves at 40: the radial return's yield stress lags by one step's hardening (first order)."""
    e20, _ = compression(20)
    e40, _ = compression(40)
    print(f"compression stress error: {100 * e20:+.2f} % (20 steps), {100 * e40:+.2f} % (40 steps)")
    assert abs(e20) < 0.02 and 1.6 < e20 / e40 < 2.4


def test_cantilever_period_converges_to_euler_bernoulli():
    """Free vibration in the first mode (trapezoidal rule, dt = T/40): the period over Euler-Bernoulli's converges
    (errors 16 % and 4 % at 2 and 4 elements through the depth)."""
    L, H = 10.0, 1.0
    ratios = []
    for ny in (2, 4):
        x = lattice(int(ny * L / H), ny, 0, L, -H / 2, H / 2)
        mesh = alpha_shape_mesh(x, None)
        nodes, hist = solid.make_nodes(x, lumped_masses(x, mesh), 293.0), fresh_history(mesh)
        b1 = 1.8751 / L
        T_eb = 2 * np.pi / (b1**2 * np.sqrt(E / (1 - NU**2) * H**3 / 12 / (RHO * H)))
        s = b1 * x[:, 0]
        sig = (np.cosh(1.8751) + np.cos(1.8751)) / (np.sinh(1.8751) + np.sin(1.8751))
        nodes.v[:, 1] = 1e-2 * (np.cosh(s) - np.cos(s) - sig * (np.sinh(s) - np.sin(s)))
        fixed = np.zeros((len(x), 2), bool)
        fixed[x[:, 0] == 0] = True
        tip = np.flatnonzero((x[:, 0] == L) & (np.abs(x[:, 1]) < 1e-12))[0]
        t, y = [], []
        for _ in range(50):
            r = solid.newton_step(nodes, mesh, hist, law(), T_eb / 40, solid.Loads(fixed, np.zeros_like(x)))
            nodes, hist = solid.commit(nodes, r, T_eb / 40), r.history
            t.append(nodes.t)
            y.append(nodes.x[tip, 1])
        t, y = np.array(t), np.array(y)
        k = np.flatnonzero(np.diff(np.sign(y)) != 0)
        crossings = t[k] - y[k] * (t[k + 1] - t[k]) / (y[k + 1] - y[k])
        ratios.append(2 * np.mean(np.diff(crossings)) / T_eb)
    print("period / Euler-Bernoulli:", [round(r, 4) for r in ratios])
    assert abs(1 - ratios[1]) < 0.06 and abs(1 - ratios[1]) < 0.4 * abs(1 - ratios[0])


def test_remeshing_keeps_mass_and_momentum_and_a_uniform_history():
    """Algorithm 1: nodes moved, meshed again; masses, momentum and nodal fields are the nodes' own, so they are
    conserved exactly; a uniform history projected to the nodes and back stays uniform."""
    rng = np.random.default_rng(3)
    x = lattice(8, 8, 0, 1e-3, 0, 1e-3) + rng.uniform(-2e-5, 2e-5, (81, 2))
    mesh = alpha_shape_mesh(x, 1.5)
    nodes = solid.make_nodes(x, lumped_masses(x, mesh), 293.0)
    nodes.v[:] = rng.normal(size=nodes.v.shape)
    m0, P0 = nodes.m.sum(), (nodes.m[:, None] * nodes.v).sum(axis=0)
    S = np.broadcast_to(np.array([[1e8, 2e7], [2e7, -5e7]]), (len(mesh.tri), 2, 2))
    area = shape_gradients(x[mesh.tri])[1]
    nodes.S = solid.project_to_nodes(mesh, area, S, nodes.n)
    nodes.x = nodes.x + rng.uniform(-3e-5, 3e-5, nodes.x.shape)           # the nodes move; a new mesh
    new = alpha_shape_mesh(nodes.x, 1.5)
    assert not np.array_equal(new.tri, mesh.tri)
    hist = solid.history_from_nodes(nodes, new)
    assert abs(nodes.m.sum() - m0) <= 1e-12 * m0
    assert np.allclose((nodes.m[:, None] * nodes.v).sum(axis=0), P0, rtol=0, atol=1e-12 * np.abs(P0).max())
    assert np.abs(hist.S - S[0]).max() < 1e-12 * 1e8


def test_alpha_shape_keeps_a_gap_open_and_finds_the_boundary():
    """Two blocks 3 spacings apart: alpha = 1.4 keeps them apart (every boundary edge short), alpha = None bridges
    them; every node of a lattice block's outline is a boundary node, no interior node is."""
    a = lattice(5, 5, 0, 1, 0, 1)
    b = lattice(5, 5, 1.6, 2.6, 0, 1)
    x = np.concatenate([a, b])
    m = alpha_shape_mesh(x, 1.4)
    assert not np.any((x[m.tri][..., 0].min(axis=1) < 1.01) & (x[m.tri][..., 0].max(axis=1) > 1.59))
    assert np.any((x[alpha_shape_mesh(x, None).tri][..., 0].max(axis=1) > 1.59)
                  & (x[alpha_shape_mesh(x, None).tri][..., 0].min(axis=1) < 1.01))
    outline = (np.isclose(a[:, 0], 0) | np.isclose(a[:, 0], 1) | np.isclose(a[:, 1], 0) | np.isclose(a[:, 1], 1))
    assert np.array_equal(m.boundary[:len(a)], outline)
    e = boundary_edges(m.tri)
    assert np.allclose(np.linalg.norm(x[e[:, 1]] - x[e[:, 0]], axis=1), 0.2)
    with pytest.raises(ValueError, match="alpha"):
        alpha_shape_mesh(x, -1.0)


def test_tool_contact_sticks_then_slides_at_mu():
    """An elastic block pressed onto a rigid flat (the penalty inside Newton) and then dragged sideways by its top:
    the tangential force grows while it sticks (F_T / F_N < mu), then the block slides with F_T / F_N = mu to
    round-off (the return map), every bottom node in contact."""
    from refsph.contact import CoulombFriction
    from refsph.penalty import RoundedPolygon
    from refsph.pfem.contact import StepContact, ToolContact, boundary_lengths
    L, H = 1e-3, 0.5e-3
    x = lattice(8, 4, 0, L, 0, H)
    mesh = alpha_shape_mesh(x, None)
    lw = law()
    nodes, hist = solid.make_nodes(x, lumped_masses(x, mesh), 293.0), fresh_history(mesh)
    flat = RoundedPolygon.from_polygon([[-1e-3, -1e-3], [3e-3, -1e-3], [3e-3, 0.0], [-1e-3, 0.0]], 0.0, [0.0, 0.0])
    params = ToolContact(k_normal=200 * lw.G / (L / 8), k_tangent=200 * lw.G / (L / 8),
                         friction=CoulombFriction(mu0=0.3, q=1.0, T_room=293.0, T_melt=1800.0))
    top = np.isclose(x[:, 1], H)
    fixed = np.zeros((len(x), 2), bool)
    fixed[top] = True
    f_T, ratios = np.zeros(len(x)), []
    for k in range(6):
        du = np.zeros_like(x)
        du[top, 1 if k == 0 else 0] = -1e-6 if k == 0 else 0.5e-6
        c = StepContact(params, flat, [0.0, 0.0], [0.0, 0.0], nodes.x, f_T, nodes.T,
                        boundary_lengths(nodes.x, mesh.edges, nodes.n), np.flatnonzero(mesh.boundary))
        r = solid.newton_step(nodes, mesh, hist, lw, 1e-3, solid.Loads(fixed, du, contact=c), dynamic=False)
        nodes, hist, f_T = solid.commit(nodes, r, 1e-3, dynamic=False), r.history, c.last["f_T"]
        F = r.contact_force.sum(axis=0)
        ratios.append(-F[0] / F[1])
        assert np.count_nonzero(c.last["f_N"] > 0) == 9 and F[1] > 0
    print("F_T / F_N per step:", [round(v, 4) for v in ratios])
    assert abs(ratios[0]) < 1e-9 and 0 < ratios[1] < ratios[2] < 0.3
    assert np.allclose(ratios[3:], 0.3, rtol=1e-12)
    assert np.all(nodes.x[np.isclose(x[:, 1], 0), 0] - x[np.isclose(x[:, 1], 0), 0] > 1e-6)   # it slid


def test_transfer_history_keeps_the_kept_triangles_own():
    """A remeshing that keeps a triangle (the same three nodes, in any order) keeps its history exactly; only new
    triangles get the nodal average."""
    rng = np.random.default_rng(5)
    x = lattice(6, 6, 0, 1e-3, 0, 1e-3) + rng.uniform(-1e-5, 1e-5, (49, 2))
    old = alpha_shape_mesh(x, 1.5)
    m = len(old.tri)
    hist = solid.History(rng.normal(size=(m, 2, 2)), rng.normal(size=m), rng.random(m), rng.random(m),
                         1 + 0.01 * rng.random(m), rng.random(m))
    nodes = solid.make_nodes(x, np.ones(len(x)), 293.0)
    from refsph.pfem.mesh import Mesh
    new = Mesh(tri=np.concatenate([old.tri[::-1][:, [1, 2, 0]][:-3], old.tri[:3][:, [0, 2, 1]]]), edges=old.edges,
               boundary=old.boundary)
    out = solid.transfer_history(old, hist, new, nodes)
    src = np.concatenate([np.arange(m)[::-1][:-3], np.arange(3)])
    assert np.array_equal(out.eps_p, hist.eps_p[src]) and np.array_equal(out.S, hist.S[src])
    assert np.array_equal(out.eps_dot, hist.eps_dot[src])


def test_newmark_trapezoidal_keeps_and_damped_rule_takes_the_energy_of_an_oscillator():
    """x'' = -w^2 x by Newmark's rule (the same formulas as the solid's): the trapezoidal rule (Eq. (21)) keeps the
    amplitude, gamma = 0.7 damps a mode at w dt = 1 strongly; unstable parameters are refused."""
    w, dt = 1.0, 1.0
    amp = {}
    for nm in (solid.TRAPEZOIDAL, solid.Newmark((0.7 + 0.5) ** 2 / 4, 0.7)):
        x, v, a = 1.0, 0.0, -1.0
        for _ in range(200):
            # a_{n+1} = -w^2 (x + du) with a_{n+1} = (du - dt v - dt^2 (1/2 - beta) a) / (beta dt^2): linear in du
            du = (dt * v + dt * dt * (0.5 - nm.beta) * a - nm.beta * dt * dt * w * w * x) / (1 + nm.beta * (w * dt)**2)
            a_new = nm.acceleration(du, v, a, dt)
            assert abs(a_new + w * w * (x + du)) < 1e-12
            v = v + dt * ((1 - nm.gamma) * a + nm.gamma * a_new)
            x, a = x + du, a_new
        amp[nm.gamma] = np.hypot(x, v / w)
    assert abs(amp[0.5] - 1.0) < 1e-10 and amp[0.7] < 1e-3
    assert np.array_equal(solid.newmark_of(True).acceleration(np.ones(2), np.ones(2), np.ones(2), 0.5),
                          4.0 / 0.25 * (np.ones(2) - 0.5) - 1.0)
    with pytest.raises(ValueError, match="unconditionally stable"):
        solid.Newmark(0.25, 0.7)


def _oscillator(nm, w, dt, steps):
    """x'' = -w^2 x (m = 1) by the rule nm as the solid uses it: m nm.inertia(a_{n+1}, a_n) + w^2 x_{n+1} = 0 with
    a_{n+1} = nm.acceleration(du, ...), linear in du; (x, v) after ``steps`` steps from x = 1, v = 0."""
    x, v, a = 1.0, 0.0, -w * w
    c = 1.0 - nm.alpha_B
    for _ in range(steps):
        # c (du - dt v - dt^2 (1/2 - beta) a) / (beta dt^2) + alpha_B a + w^2 (x + du) = 0
        k = c / (nm.beta * dt * dt)
        du = (k * (dt * v + dt * dt * (0.5 - nm.beta) * a) - nm.alpha_B * a - w * w * x) / (k + w * w)
        a_new = nm.acceleration(du, v, a, dt)
        assert abs(nm.inertia(a_new, a) + w * w * (x + du)) < 1e-9 * max(1.0, w * w)
        v = v + dt * ((1 - nm.gamma) * a + nm.gamma * a_new)
        x, a = x + du, a_new
    return x, v


def test_bossak_rule_is_second_order_and_damps_the_high_frequencies():
    """Bossak-Newmark (alpha_B = -0.1): over one period of x'' = -x its error falls fourfold per halving of the step
    (second order) where the damped Newmark rule with the same gamma (0.6) falls twofold (first order); a mode at
    w dt = 20 loses nearly all its amplitude in 20 steps; alpha_B = 0 is Newmark's rule to the bit; out of range
    refused."""
    bossak, damped = solid.Newmark.bossak(-0.1), solid.Newmark((0.6 + 0.5) ** 2 / 4, 0.6)
    assert bossak.gamma == pytest.approx(0.6) and bossak.beta == pytest.approx(0.3025)
    err = {}
    for name, nm in (("bossak", bossak), ("damped", damped)):
        e = []
        for n in (64, 128, 256):
            x, v = _oscillator(nm, 1.0, 2 * np.pi / n, n)
            e.append(np.hypot(x - 1.0, v))
        err[name] = np.log2(np.array(e[:-1]) / np.array(e[1:]))       # observed orders
    assert np.all(err["bossak"] > 1.9) and np.all(np.abs(err["damped"] - 1.0) < 0.1)
    x, v = _oscillator(bossak, 20.0, 1.0, 20)
    assert np.hypot(x, v / 20.0) < 0.05
    plain = solid.Newmark(0.25, 0.5, 0.0)
    a_new = np.array([1.0, -2.0])
    assert plain.inertia(a_new, np.ones(2)) is a_new
    with pytest.raises(ValueError, match="alpha_B"):
        solid.Newmark.bossak(-0.5)


@pytest.mark.parametrize("n_tu", [5.0, 7.0, 10.0])
def test_graded_workpiece_is_held_along_its_bottom_and_left(n_tu):
    """The cut's workpiece has a row at y = 0 and a column at x = 0, all held, at any number of nodes across t_u
    (with 5, the coarse rows once stopped at y = dx: nothing held the bottom, and the workpiece bent as a cantilever
    under the tool, 0.5 mm down at 4 t_u of cut)."""
    from refsph.pfem.cutting import graded_workpiece, pfem_cut
    tu = 1e-4
    dx = tu / n_tu
    x, h = graded_workpiece(2.0e-3, tu, dx)
    assert x[:, 1].min() == 0.0 and np.isclose(x[:, 1].max(), 3 * tu)
    bottom = x[:, 1] == 0.0
    assert bottom.sum() >= round(2.0e-3 / (2 * dx))
    ys = np.unique(np.round(x[:, 1] / dx, 9))
    assert np.all(np.diff(ys) <= 2.0 + 1e-9) and np.all(np.diff(ys) >= 1.0 - 1e-9)   # no gap over 2 dx, none under dx
    cut = pfem_cut(1, n_tu=n_tu, travel=4.0, length=1.2e-3, conduction=False)
    held = cut.fixed.all(axis=1)
    assert np.all(held[cut.nodes.x[:, 1] == 0.0]) and np.all(held[cut.nodes.x[:, 0] == 0.0])
    assert held[cut.nodes.x[:, 1] == 0.0].sum() > 10


def flat_tool_contact(x_n):
    """The contact of one step between nodes at x_n (N, 2) and a rigid flat tool below y = 0 at rest: penalties 1e12
    Pa/m, mu 0.3 at 293 K, tributary lengths 1e-4 m, no tangential force at t_n."""
    from refsph.contact import CoulombFriction
    from refsph.penalty import RoundedPolygon
    from refsph.pfem.contact import StepContact, ToolContact
    flat = RoundedPolygon.from_polygon([[-1e-3, -1e-3], [3e-3, -1e-3], [3e-3, 0.0], [-1e-3, 0.0]], 0.0, [0.0, 0.0])
    params = ToolContact(k_normal=1e12, k_tangent=1e12,
                         friction=CoulombFriction(mu0=0.3, q=1.0, T_room=293.0, T_melt=1800.0))
    n = len(x_n)
    return StepContact(params, flat, [0.0, 0.0], [0.0, 0.0], x_n, np.zeros(n), np.full(n, 293.0), np.full(n, 1e-4),
                       np.arange(n))


def test_contact_sets_that_grow_end_a_cycle():
    """StepContact.freeze: a node grazing the tool that leaves the contact set on the next solve changes the sets
    (a cycle can follow); with ``grow`` it keeps its place, so the sets stop changing."""
    x = np.array([[0.0, 1e-4], [1e-4, 1e-4]])
    c = flat_tool_contact(x)
    inside, outside = x - [0.0, 1e-4 + 1e-9], x - [0.0, 1e-4 - 1e-9]
    assert c.freeze(inside) and c.active.all()
    assert c.freeze(outside) and not c.active.any()                  # plain: the grazing nodes leave, then return
    assert c.freeze(inside)
    assert not c.freeze(outside, grow=True) and c.active.all()       # grown: they stay, nothing changes


def test_a_slip_that_reverses_sticks_first():
    """StepContact.freeze: a node that slipped one way in the last solve and whose trial force now points the other
    way beyond the cap sticks (slip 0) rather than slips back; the solve after that decides. Without the rule the
    stagnation node at the tool's edge radius flipped between slipping forwards and backwards on alternate solves
    (case 1's short cut at t_u / 10, step 28: 297 Newton iterations and three halved steps, now 33)."""
    x_n = np.array([[0.0, -1e-7]])                                      # 1e-7 deep: f_N = 10 N/m, cap 3 N/m
    c = flat_tool_contact(x_n)
    forwards, backwards = x_n + [1e-7, 0.0], x_n - [1e-7, 0.0]           # trial forces +-10 N/m, beyond the cap
    c.freeze(forwards)
    first = c.slip[0]
    assert first != 0 and c.active[0]
    assert c.freeze(backwards) and c.slip[0] == 0.0                     # reversed: sticks
    assert c.freeze(backwards) and c.slip[0] == -first                  # from sticking, beyond the cap: slips


def test_a_frozen_slip_turned_against_its_direction_sticks():
    """StepContact.stick_reversed: within a frozen solve a node frozen sliding one way whose trial force at the
    solve's last iterate points the other way is made to stick for the step (its frozen friction would push it the
    way it goes, and the solve cannot settle: case 1 at t_u/10, 1.393 ms); a node whose trial force still points
    its way, and a contact with no frozen sets, are left alone."""
    x_n = np.array([[0.0, -1e-7], [1e-4, -1e-7]])                      # both 1e-7 deep: cap 3 N/m
    c = flat_tool_contact(x_n)
    assert not c.stick_reversed(x_n)                                    # no frozen sets: nothing to do
    c.freeze(x_n + [[1e-7, 0.0], [1e-7, 0.0]])                          # both slide one way (trial -10 N/m)
    first = c.slip.copy()
    assert np.all(first != 0)
    assert c.stick_reversed(x_n + [[-1e-7, 0.0], [2e-7, 0.0]])          # the first turned, the second did not
    assert c.slip[0] == 0.0 and c.slip[1] == first[1]
    assert not c.stick_reversed(x_n + [[-1e-7, 0.0], [2e-7, 0.0]])      # once stuck, nothing more
    c.freeze(x_n + [[1e-7, 0.0], [1e-7, 0.0]])                          # and it stays stuck for the step
    assert c.slip[0] == 0.0 and c.slip[1] == first[1]


def test_a_kept_slip_turned_against_its_direction_sticks_when_sets_grow():
    """StepContact.freeze with ``grow``: a node kept sliding whose trial force now points against its slip is made to
    stick for the step at once (kept sliding, its friction would push it the way it goes: case 8 at t_u/10 spent 80
    Newton corrections so, every second step, before stick_reversed caught it); a kept slip whose trial force still
    points its way stays."""
    x_n = np.array([[0.0, -1e-7], [1e-4, -1e-7]])                      # both 1e-7 deep: cap 3 N/m
    c = flat_tool_contact(x_n)
    c.freeze(x_n + [[1e-7, 0.0], [1e-7, 0.0]])                          # both slide one way (trial -10 N/m)
    first = c.slip.copy()
    assert np.all(first != 0)
    assert c.freeze(x_n + [[-1e-8, 0.0], [2e-7, 0.0]], grow=True)      # the first's trial turned (+1 N/m, in the cap)
    assert c.slip[0] == 0.0 and c.stuck[0] and c.slip[1] == first[1] and not c.stuck[1]
    assert not c.freeze(x_n + [[-1e-8, 0.0], [2e-7, 0.0]], grow=True)  # and nothing changes after that


def test_a_frozen_contact_node_off_the_tool_is_pulled_back_without_friction():
    """StepContact.forces with frozen sets: a node of the contact set that has left the tool (g < 0) gets the
    penalty's pull f_N = k_N l g < 0 and no friction (cap mu max(f_N, 0)); with the cap mu f_N a frozen slip's
    friction turned and pushed the node along (case 8 at t_u/10)."""
    x_n = np.array([[0.0, -1e-7]])
    c = flat_tool_contact(x_n)
    c.freeze(x_n + [[1e-7, 0.0]])                                       # in contact, sliding
    assert c.active[0] and c.slip[0] != 0
    inside = c.forces(x_n + [[1e-7, 0.0]], np.arange(1))
    assert inside["f_N"][0] > 0 and np.isclose(abs(inside["f_T"][0]), 0.3 * inside["f_N"][0])
    off = c.forces(x_n + [[1e-7, 2e-7]], np.arange(1))                 # 1e-7 off the tool, still frozen active
    assert off["f_N"][0] < 0 and off["f_T"][0] == 0.0
    assert np.allclose(off["f"][0], [0.0, off["f_N"][0]])              # the pull along the normal only


def test_solve_linear_fast_path_and_fallback():
    """solve_linear: the diagonal-pivot SuperLU path solves a PFEM-like matrix; a matrix whose diagonal vanishes
    (where diagonal pivots fail) falls back to partial pivoting and is still solved."""
    rng = np.random.default_rng(3)
    n = 60
    B = sp.random(n, n, density=0.05, random_state=4) + sp.diags(np.full(n, 4.0))
    A = (B + B.T).tocsc()
    b = rng.normal(size=n)
    assert np.allclose(A @ solid.solve_linear(A, b), b, rtol=0, atol=1e-10 * np.linalg.norm(b))
    ordering = {}
    x1 = solid.solve_linear(A, b, ordering)                   # the first solve stores its ordering ...
    assert sorted(ordering["inverse"]) == list(range(n))
    A2 = A + sp.diags(rng.random(n))                          # ... the next one, on the same pattern, reuses it
    x2 = solid.solve_linear(A2, b, ordering)
    np.testing.assert_allclose(x1, solid.solve_linear(A, b), rtol=1e-12)
    np.testing.assert_allclose(x2, solid.solve_linear(A2, b), rtol=1e-12)
    P = sp.csc_matrix(np.array([[0.0, 2.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 3.0]]))
    assert np.allclose(solid.solve_linear(P, np.array([4.0, 1.0, 6.0])), [1.0, 2.0, 2.0])


def test_free_matrix_is_the_masked_tangent():
    """The Newton matrix summed into a pattern found once per solve equals the tangent with the held dofs' rows and
    columns replaced by the identity (keep K keep + diag(fix)), contact blocks and mass diagonal included."""
    rng = np.random.default_rng(3)
    x = rng.random((12, 2))
    tri = alpha_shape_mesh(x, 10.0, np.full(12, 0.3)).tri
    n = 12
    dofs = solid._element_dofs(tri, n)
    parts = solid.TangentParts(rng.standard_normal((len(tri), 9, 9)), dofs, n, diag=rng.random(3 * n),
                               kc=rng.standard_normal((n, 2, 2)))
    fix = rng.random(3 * n) < 0.3
    keep = sp.diags((~fix).astype(float))
    expected = (keep @ parts.sparse() @ keep + sp.diags(fix.astype(float))).toarray()
    free = solid.FreeMatrix(dofs, n, fix)
    got = free(parts)
    assert got.format == "csc"
    np.testing.assert_allclose(got.toarray(), expected, rtol=1e-14, atol=1e-14)
    inv = rng.permutation(3 * n)                    # given permuted (the factor's order), the same matrix relabelled
    free.permute(inv)
    perm = free(parts)
    assert perm.has_sorted_indices
    np.testing.assert_array_equal(perm.toarray(), got[inv][:, inv].toarray())
    b = rng.standard_normal(3 * n)
    ordering = dict(inverse=inv, permuted=True)     # solve_linear takes it so, and answers in the original order
    np.testing.assert_allclose(solid.solve_linear(perm, b, ordering), np.linalg.solve(expected, b), rtol=1e-9)


def test_cut_takes_the_damped_newmark_rule_as_an_option():
    """pfem_cut(gamma=...): 0.5 is the paper's trapezoidal rule, above it the damped rule with beta = (gamma + 1/2)^2
    / 4 (case 16 rings with the first), outside [1/2, 1] a ValueError."""
    from refsph.pfem.cutting import pfem_cut

    assert pfem_cut(1, n_tu=3.0, travel=2.0, length=1e-3).newmark == solid.TRAPEZOIDAL
    cut = pfem_cut(1, n_tu=3.0, travel=2.0, length=1e-3, gamma=0.6)
    assert cut.newmark.gamma == 0.6 and cut.newmark.beta == pytest.approx(0.3025, rel=1e-15)
    assert cut.info["newmark_gamma"] == 0.6
    with pytest.raises(ValueError, match="gamma"):
        pfem_cut(1, n_tu=3.0, travel=2.0, length=1e-3, gamma=0.4)


def test_contact_sets_looked_at_inside_the_iterations_give_the_same_cut_in_fewer_iterations():
    """solve_with_active_set with ``settle`` (the sets looked at every two Newton corrections, the cut's default)
    against the sets looked at only after each converged solve (``settle=None``): the quick cut's first 20 steps
    give the same tool force at every step (measured: 2e-10 apart) in fewer Newton iterations (292 against 332)."""
    from dataclasses import replace

    from refsph.pfem.cutting import CutRun, pfem_cut
    runs = {}
    for settle, max_outer in ((None, 8), (2, 16)):
        run = CutRun(replace(pfem_cut(1, n_tu=5.0, travel=4.0, length=1.2e-3), settle=settle, max_outer=max_outer))
        for _ in range(20):
            run.step()
        runs[settle] = (np.array(run.reaction["tool"]), sum(run.iterations), run.retries)
    (F_old, its_old, halved_old), (F_new, its_new, halved_new) = runs[None], runs[2]
    print("Newton iterations, settle None / 2:", its_old, its_new)
    assert halved_old == halved_new == 0
    assert np.allclose(F_new, F_old, rtol=1e-8, atol=1e-6 * np.abs(F_old).max())
    assert its_new < 0.95 * its_old


def test_newton_step_with_settle_returns_after_that_many_corrections():
    """newton_step(settle=k): back after k corrections, flagged not converged, at the point reached; the same
    problem solved on from there converges to the answer of an uninterrupted solve."""
    x = lattice(4, 4, 0, 1e-3, 0, 1e-3)
    mesh = alpha_shape_mesh(x, None)
    lw = law()
    nodes, hist = solid.make_nodes(x, lumped_masses(x, mesh), 293.0), fresh_history(mesh)
    top, bottom = np.isclose(x[:, 1], 1e-3), np.isclose(x[:, 1], 0.0)
    fixed = np.zeros((len(x), 2), bool)
    fixed[top | bottom] = True
    du = np.zeros_like(x)
    du[top, 1] = -2e-5                                                  # 2 % compression: plastic
    loads = solid.Loads(fixed, du)
    whole = solid.newton_step(nodes, mesh, hist, lw, 1e-3, loads, dynamic=False)
    part = solid.newton_step(nodes, mesh, hist, lw, 1e-3, loads, dynamic=False, settle=1)
    assert whole.converged and whole.iterations > 2
    assert not part.converged and part.iterations == 1
    rest = solid.newton_step(nodes, mesh, hist, lw, 1e-3, loads, dynamic=False, du0=part.du, p0=part.p,
                             predictor=False)
    assert rest.converged and np.allclose(rest.du, whole.du, rtol=0, atol=1e-12 * 2e-5)
    calls = []                                # given the settled point's evaluation, it is not computed again
    real = solid._residual
    with mock.patch.object(solid, "_residual", lambda *a, **k: calls.append((a[4], a[10])) or real(*a, **k)):
        again = solid.newton_step(nodes, mesh, hist, lw, 1e-3, loads, dynamic=False, du0=part.du, p0=part.p,
                                  predictor=False, start=part.evaluation)
    assert not any(np.array_equal(du, part.du) and not tangent for du, tangent in calls)   # only its tangent there
    np.testing.assert_array_equal(again.du, rest.du)
    np.testing.assert_array_equal(again.p, rest.p)


def test_settle_below_two_is_refused():
    """solve_with_active_set(settle=0) would spin (no correction between looks at the sets) and settle=1 never has
    the three residuals newton_step's round-off stopping rule needs: both are refused with a ValueError."""
    from refsph.pfem.contact import solve_with_active_set
    for bad in (0, 1, 1.5):
        with pytest.raises(ValueError, match="settle must be None or a whole number of at least 2"):
            solve_with_active_set(None, None, None, None, 1e-9, None, settle=bad)


class _OwnReturnMap:
    """A strength model with its own return map (not the radial return): the tangent falls back to differences."""

    state_fields = ("eps_p",)
    heating = False

    def return_map(self, S, S_zz, eps_p, eps_dot, T, G):
        f = 1.0 / (1.0 + 1e-18 * np.einsum("mij,mij->m", S, S))
        return S * f[:, None, None], S_zz * f, np.zeros(len(S)), np.zeros(len(S))

    def heat(self, d_w_p, rho):
        return np.zeros_like(d_w_p)


@pytest.mark.parametrize("lagged", [True, False])
@pytest.mark.parametrize("kind", ["johnson-cook", "modified", "elastic", "own return map"])
def test_element_tangent_is_the_derivative_of_the_element_residual(kind, lagged):
    """The element tangent (exact for the radial return and the elastic solid, forward differences for another
    law) against central differences of the element residual, on distorted, rotated, heated triangles, most of
    them flowing plastically, the rest elastic (the rate lagged as the cutting runs do it, or the step's own)."""
    from refsph.plasticity import ModifiedJohnsonCook
    rng = np.random.default_rng(3)
    m = 150
    xe = np.array([[0, 0], [1, 0], [0.3, 0.9]])[None] * 1e-4 + rng.normal(0, 1e-5, (m, 3, 2))
    due, pe = rng.normal(0, 2e-7, (m, 3, 2)), rng.normal(0, 3e8, (m, 3))
    S = rng.normal(0, 6e8, (m, 2, 2)) * rng.random(m)[:, None, None]     # some inside the yield surface
    jc = dict(A=553e6, B=601e6, n=0.234, C=0.0134, m=1.0, eps_dot_0=1.0, T_room=293.0, T_melt=1733.0, cp=486.0,
              chi=0.9)
    strength = {"johnson-cook": JohnsonCook(**jc), "elastic": Elastic(), "own return map": _OwnReturnMap(),
                "modified": ModifiedJohnsonCook(**jc, hardening_saturation_strain=2.0)}[kind]
    lw = solid.SolidLaw(rho0=7800.0, G=80e9, K=160e9, alpha_T=1.2e-5, T_ref=293.0, strength=strength)
    hist = solid.History(S=0.5 * (S + np.swapaxes(S, 1, 2)), S_zz=rng.normal(0, 1e8, m), eps_p=rng.random(m) * 2.5,
                         W_p=np.zeros(m), J=1 + rng.normal(0, 0.01, m), eps_dot=rng.random(m) * 1e5 if lagged else None)
    Te, dt = 293 + rng.random(m) * 600, 1e-7
    r_u, r_p, r = solid.element_residual(xe, due, pe, hist, Te, dt, lw)
    K = solid._element_tangent(xe, due, pe, hist, Te, dt, lw, r, r_u, r_p)
    eps = 1e-7 * np.sqrt(np.abs(r["area_n"]))
    Kc = np.empty((m, 9, 6))
    for k in range(6):
        d = np.zeros_like(due)
        d[:, k // 2, k % 2] = eps
        (up, pp, _), (um, pm, _) = (solid.element_residual(xe, due + s * d, pe, hist, Te, dt, lw) for s in (1, -1))
        Kc[:, :, k] = np.concatenate([(up - um).reshape(m, 6), pp - pm], axis=1) / (2 * eps[:, None])
    err = np.maximum(*(np.abs(K[:, rows, :6] - Kc[:, rows]).max(axis=(1, 2)) / np.abs(Kc[:, rows]).max(axis=(1, 2))
                       for rows in (slice(0, 6), slice(6, 9))))   # the force rows and the pressure rows (1e-15 of
    #                                                                them: each against its own size)
    _, svm, sy, _, _ = solid._return_factor(hist, Te, dt, lw, r)
    kink = np.abs(svm / np.where(sy > 0, sy, 1.0) - 1.0) < 1e-4 if hasattr(strength, "flow_stress") else svm < 0
    err = err[~kink]                            # the differences straddle the yield surface there (one here)
    assert np.sum(kink) <= 2
    plastic = int(np.sum(r["d_eps_p"] > 0))
    print(f"{kind}, rate {'lagged' if lagged else 'own'}: {plastic} of {m} plastic, largest error {err.max():.1e}")
    assert err.max() < (1e-8 if kind != "own return map" else 1e-5)       # exact; forward differences
    assert kind in ("elastic", "own return map") or m // 5 < plastic < m - m // 5
    assert solid._exact_tangent_known(strength) == (kind != "own return map")
