"""The PFEM thermal step (refsph.pfem.thermal: the second paper's Eqs. (14), (18), (22), with the losses of Eq. (6))
against analytic solutions: a sine mode decaying in a strip (second order in space, first in time), the steady
parabola of a uniform source, a small body cooling by convection (the lumped solution at small Biot number), Newton's
quadratic convergence with radiation, the heat ledger, and bad input. Meshes: Delaunay triangulations of lattices
(refsph.pfem.mesh.alpha_shape_mesh with no alpha: every triangle kept). A square lattice is co-circular, so Delaunay
splits its cells along either diagonal, mixed: the meshes are not the textbook's uniform ones, and the nodal errors
below are those of a PFEM mesh, not of a finite-difference stencil in disguise."""
import numpy as np
import pytest
import scipy.sparse as sp

from refsph.pfem.mesh import alpha_shape_mesh
from refsph.pfem.thermal import (StepHeat, capacity, conductivity_matrix, contact_conductance, edge_losses,
                                 nodal_source, thermal_step)
from refsph.thermal import STEFAN_BOLTZMANN, SurfaceLoss

K_STEEL, RC_STEEL = 50.0, 3.6e6          # W/(m K), J/(m^3 K): a steel, diffusivity 1.4e-5 m^2/s
K_CU, RC_CU = 400.0, 3.4e6               # a copper: a small body of it cools at a small Biot number
T0 = 300.0


def lattice_mesh(nx: int, ny: int, Lx: float, Ly: float, x0: float = 0.0):
    """Nodes of an (nx + 1) x (ny + 1) lattice on [x0, x0 + Lx] x [0, Ly], and their Delaunay mesh."""
    X, Y = np.meshgrid(np.linspace(x0, x0 + Lx, nx + 1), np.linspace(0.0, Ly, ny + 1), indexing="ij")
    x = np.column_stack([X.ravel(), Y.ravel()])
    return x, alpha_shape_mesh(x, None)


def orders(errors):
    """Observed orders between successive halvings: log2(e_i / e_{i+1})."""
    e = np.abs(np.asarray(errors))
    return np.log2(e[:-1] / e[1:])


# ------------------------------------------------------------------------------------ 1. a sine mode in a strip

L_STRIP = 1e-2
KW = np.pi / L_STRIP                                  # the mode's wave number
LAM = K_STEEL / RC_STEEL * KW ** 2                    # its decay rate a k^2 [1/s]


def decay_sine_mode(n: int, steps: int, t_end: float, lumped: bool):
    """The strip [0, L] x [0, L/8] with n x n/8 square cells, ends held at T0, long sides insulated, starting from
    T0 + 10 sin(k x): (T, x, dt, the mode's amplitude / 10 K, its capacity-weighted projection)."""
    x, mesh = lattice_mesh(n, max(1, n // 8), L_STRIP, L_STRIP / 8)
    s = np.sin(KW * x[:, 0])
    ends = np.flatnonzero(np.isclose(x[:, 0], 0.0, atol=1e-9 * L_STRIP)
                          | np.isclose(x[:, 0], L_STRIP, atol=1e-9 * L_STRIP))
    assert len(ends) == 2 * (max(1, n // 8) + 1)
    T, dt = T0 + 10.0 * s, t_end / steps
    for _ in range(steps):
        T, heat = thermal_step(x, mesh.tri, T, dt, K_STEEL, RC_STEEL, fixed=ends, T_fixed=T0, lumped=lumped)
        assert heat.iterations == 1                  # linear: one Newton iteration
    c = capacity(x, mesh.tri, RC_STEEL).diagonal()
    amplitude = np.sum(c * (T - T0) * s) / np.sum(c * s * s) / 10.0
    return T, x, dt, c, amplitude


@pytest.mark.parametrize("lumped", [True, False], ids=["lumped", "consistent"])
def test_sine_mode_decays_at_second_order_in_space(lumped):
    """T = T0 + 10 sin(k x) exp(-a k^2 t) in a strip held at T0 at both ends; 10 backward-Euler steps to t = 0.5 /
    (a k^2), on 8, 16, 32 cells along. Backward Euler turns exp(-lam dt) into 1 / (1 + lam dt) also for the exact
    sine (the equation continuous in space, discrete in time): read through that factor, the mode's decay rate and the
    nodal temperatures carry the error in space alone, whatever dt (the error in dt: the next test).
    Measured (lumped): rate -1.49e-2, -3.59e-3, -8.86e-4 (orders 2.05, 2.02); capacity-weighted RMS nodal error / 10 K
    4.1e-3, 1.0e-3, 2.4e-4 (2.02, 2.06). Consistent: rate +1.08e-2, +2.84e-3, +7.20e-4 (1.92, 1.98); RMS 3.4e-3,
    8.9e-4, 2.2e-4 (1.94, 2.04). The 1D theory: -(k h)^2 / 12 lumped (slower), +(k h)^2 / 12 consistent (faster)."""
    t_end, steps = 0.5 / LAM, 10
    rate_errors, rms_errors = [], []
    for n in (8, 16, 32):
        T, x, dt, c, amplitude = decay_sine_mode(n, steps, t_end, lumped)
        rate = (amplitude ** (-1.0 / steps) - 1.0) / dt          # lam_h, from amplitude = (1 + lam_h dt)^-steps
        rate_errors.append(rate / LAM - 1.0)
        exact = T0 + 10.0 * np.sin(KW * x[:, 0]) * (1.0 + LAM * dt) ** -steps
        rms_errors.append(np.sqrt(np.sum(c * (T - exact) ** 2) / np.sum(c)) / 10.0)
    print(f"lumped={lumped}: rate errors {np.array(rate_errors)}, orders {orders(rate_errors)}; "
          f"RMS nodal errors {np.array(rms_errors)}, orders {orders(rms_errors)}")
    assert np.all((orders(rate_errors) > 1.8) & (orders(rate_errors) < 2.3))
    assert np.all((orders(rms_errors) > 1.8) & (orders(rms_errors) < 2.3))
    theory = (KW * L_STRIP / 32) ** 2 / 12 * (-1.0 if lumped else 1.0)
    assert 0.7 < rate_errors[-1] / theory < 1.4, (rate_errors[-1], theory)
    assert abs(rate_errors[-1]) < 1e-3


def test_backward_euler_is_first_order_in_time():
    """The same mode on 64 cells along (error in space -2.5e-4 of the rate), to t = 1 / (a k^2) in 5, 10, 20, 40
    steps: the decay rate read directly, -ln(amplitude) / t, carries backward Euler's ln(1 + lam dt) / (lam dt) - 1
    ~ -lam dt / 2. Measured: -8.86e-2, -4.71e-2, -2.44e-2, -1.25e-2: orders 0.91, 0.95, 0.96 (1 as dt -> 0)."""
    t_end = 1.0 / LAM
    errors = []
    for steps in (5, 10, 20, 40):
        _, _, dt, _, amplitude = decay_sine_mode(64, steps, t_end, True)
        errors.append(-np.log(amplitude) / t_end / LAM - 1.0)
        be = np.log1p(LAM * dt) / (LAM * dt) - 1.0               # backward Euler on the exact mode
        assert abs(errors[-1] - be) < 1e-3, (steps, errors[-1], be)
    print(f"time errors {np.array(errors)}, orders {orders(errors)}")
    assert np.all(np.array(errors) < 0)                          # backward Euler decays too slowly
    assert np.all((orders(errors) > 0.85) & (orders(errors) < 1.1))


# ----------------------------------------------------------------------------------------- 2. the steady state

def test_steady_state_with_a_uniform_source_is_the_parabola():
    """A uniform source q (per triangle, :func:`nodal_source`) in the strip, ends held at T0: the steady temperature
    is T0 + q x (L - x) / (2 k). One backward-Euler step of dt = 1e12 s is the steady solve (C / dt ~ 1e-14 of K).
    On a mesh of one diagonal direction linear elements are exact at the nodes; Delaunay mixes the diagonals of a
    square lattice, and a node's share of the source (a third of each triangle around it) then varies from node to
    node: the nodal error is O(h^2): measured 0.079 and 0.082 q h^2 / k on 16 and 32 cells (0.25 % and 0.064 % of
    the 250 K rise); tolerance 0.1 q h^2 / k. A second step from the steady state changes nothing and removes at
    the ends exactly the heat the source makes."""
    q, rise = 1e9, 1e9 * L_STRIP ** 2 / (8 * K_STEEL)           # W/m^3; the parabola's 250 K
    errors = []
    for n in (16, 32):
        x, mesh = lattice_mesh(n, n // 8, L_STRIP, L_STRIP / 8)
        ends = np.flatnonzero(np.isclose(x[:, 0], 0.0, atol=1e-12) | np.isclose(x[:, 0], L_STRIP, atol=1e-12))
        P = nodal_source(x, mesh.tri, q)
        assert np.isclose(P.sum(), q * L_STRIP ** 2 / 8, rtol=1e-13)
        T, _ = thermal_step(x, mesh.tri, T0, 1e12, K_STEEL, RC_STEEL, P, fixed=ends, T_fixed=T0)
        exact = T0 + q / (2 * K_STEEL) * x[:, 0] * (L_STRIP - x[:, 0])
        errors.append(np.max(np.abs(T - exact)))
        assert errors[-1] < 0.1 * q * (L_STRIP / n) ** 2 / K_STEEL, (n, errors[-1])
        T2, heat = thermal_step(x, mesh.tri, T, 1e12, K_STEEL, RC_STEEL, P, fixed=ends, T_fixed=T0)
        assert np.max(np.abs(T2 - T)) < 1e-11 * rise
        assert abs(heat.removed - heat.source) < 1e-12 * heat.source and heat.lost == 0.0
    print(f"steady nodal errors {errors} K of {rise} K")
    assert errors[1] < errors[0] / 3


# -------------------------------------------------------------------------- 3. a small body: convection, radiation

A_BODY = 1e-2                                          # a 1 cm copper square: Biot number h A/(P k) ~ 1e-3


def small_body(n: int = 8):
    x, mesh = lattice_mesh(n, n, A_BODY, A_BODY)
    return x, mesh


def mean_excess(x, mesh, T, T_inf):
    c = capacity(x, mesh.tri, RC_CU).diagonal()
    return np.sum(c * (T - T_inf)) / np.sum(c)


@pytest.mark.parametrize("lumped", [True, False], ids=["lumped", "consistent"])
def test_small_body_cools_by_convection_as_the_lumped_solution(lumped):
    """Convection only (h_c = 100 W/(m^2 K)) from a 1 cm copper square at 600 K into 300 K: at Biot number
    h_c (A/P) / k = 6e-4 the body stays nearly uniform, and its mean excess decays as exp(-lam t),
    lam = h_c P / (rho c_p A); backward Euler makes that (1 + lam dt)^-n. 40 steps of lam dt = 0.029 to lam t = 1.18.
    Measured: 4.7e-4 (relative) from the lumped backward-Euler solution (tolerance 1e-3, the Biot number's size) and
    1.7 % above exp(-lam t) (tolerance 2.5 %: backward Euler's lam^2 dt t / 2 = 1.7 %)."""
    x, mesh = small_body()
    loss = SurfaceLoss(h_c=100.0, emissivity=0.0, T_ambient=300.0)
    lam = loss.h_c * 4 * A_BODY / (RC_CU * A_BODY ** 2)
    dt, steps = 2.5, 40
    T = np.full(len(x), 600.0)
    for _ in range(steps):
        T, heat = thermal_step(x, mesh.tri, T, dt, K_CU, RC_CU, edges=mesh.edges, loss=loss, lumped=lumped)
        assert heat.iterations == 1 and heat.lost > 0
    ratio = mean_excess(x, mesh, T, 300.0) / 300.0
    be, exact = (1.0 + lam * dt) ** -steps, np.exp(-lam * dt * steps)
    print(f"lumped={lumped}: excess ratio {ratio:.6f}, backward Euler {be:.6f}, exp {exact:.6f}")
    assert abs(ratio / be - 1.0) < 1e-3
    assert 0 < ratio / exact - 1.0 < 0.025


def newton_orders(norms):
    """Observed orders of convergence, log(r_{k+1} / r_k) / log(r_k / r_{k-1}), of the residual norms well above
    round-off (more than 1e3 times the last)."""
    r = np.array(norms)
    r = r[r > 1e3 * r[-1]]
    return np.log(r[2:] / r[1:-1]) / np.log(r[1:-1] / r[:-2])


@pytest.mark.parametrize("lumped", [True, False], ids=["lumped", "consistent"])
def test_radiation_newton_converges_quadratically(lumped):
    """Radiation (emissivity 0.8) and convection from the copper square at 1200 K, one long step (dt = 200 s): the
    T^4 makes Eq. (22) nonlinear, and Newton with the exact tangent converges quadratically. Measured residual norms
    [W/m]: 128, 32.9, 4.82, 0.155, 1.75e-4, 2.9e-10, 1.3e-10 (round-off): orders 1.4, 1.8, 2.0 (a tangent without
    the radiation's 4 emissivity sigma T^3 would give 1). Then 10 steps of 20 s against the lumped body's own
    backward Euler, c_tot (T' - T) / dt = -P q(T') solved as a scalar (Biot number 2e-3): measured 2.5e-4 of the
    excess apart (tolerance 2e-3)."""
    x, mesh = small_body()
    loss = SurfaceLoss(h_c=10.0, emissivity=0.8, T_ambient=300.0)
    T, heat = thermal_step(x, mesh.tri, 1200.0, 200.0, K_CU, RC_CU, edges=mesh.edges, loss=loss, lumped=lumped)
    p = newton_orders(heat.residual_norms)
    print(f"lumped={lumped}: Newton residual norms {heat.residual_norms}, orders {p}")
    assert heat.iterations >= 4 and p[-1] > 1.8
    assert abs(heat.residual) < 1e-12 * heat.lost

    T, Tb, dt = np.full(len(x), 1200.0), 1200.0, 20.0
    ctot, perimeter = RC_CU * A_BODY ** 2, 4 * A_BODY
    for _ in range(10):
        T, heat = thermal_step(x, mesh.tri, T, dt, K_CU, RC_CU, edges=mesh.edges, loss=loss, lumped=lumped)
        Told = Tb
        for _ in range(30):                                   # the scalar backward Euler, by Newton
            f = ctot * (Tb - Told) / dt + perimeter * float(loss.flux(np.array(Tb)))
            df = ctot / dt + perimeter * (loss.h_c + 4 * loss.emissivity * STEFAN_BOLTZMANN * Tb ** 3)
            Tb -= f / df
    mean = 300.0 + mean_excess(x, mesh, T, 300.0)
    print(f"mean T {mean:.4f} K, lumped body {Tb:.4f} K")
    assert abs(mean - Tb) < 2e-3 * (Tb - 300.0)


@pytest.mark.parametrize("lumped", [True, False], ids=["lumped", "consistent"])
def test_edge_loss_tangent_is_the_derivative(lumped):
    """dL/dT of :func:`edge_losses` against central differences of L, at scattered boundary temperatures."""
    x, mesh = small_body(4)
    rng = np.random.default_rng(3)
    T = rng.uniform(300.0, 1500.0, len(x))
    args = (10.0, 0.7, 290.0)
    L, dL = edge_losses(x, mesh.edges, T, *args, lumped=lumped)
    dL = dL.toarray()
    on = np.unique(mesh.edges)
    for b in on:
        e = np.zeros(len(x))
        e[b] = 1e-2
        fd = (edge_losses(x, mesh.edges, T + e, *args, lumped=lumped)[0]
              - edge_losses(x, mesh.edges, T - e, *args, lumped=lumped)[0]) / 2e-2
        assert np.allclose(dL[:, b], fd, rtol=1e-7, atol=1e-9 * np.abs(dL).max())
    # the total loss of a uniform temperature: q(T) times the perimeter, either quadrature
    L, _ = edge_losses(x, mesh.edges, np.full(len(x), 900.0), *args, lumped=lumped)
    q = 10.0 * 610.0 + 0.7 * STEFAN_BOLTZMANN * (900.0 ** 4 - 290.0 ** 4)
    assert np.isclose(L.sum(), q * 4 * A_BODY, rtol=1e-13)
    assert np.all(L[np.setdiff1d(np.arange(len(x)), on)] == 0.0)


# --------------------------------------------------------------------------------------------------- 4. the ledger

def two_bodies(n: int = 6, gap: float = 0.02):
    """A workpiece [0, a]^2 and a tool [a (1 + gap), a (2 + gap)] x [0, a], meshed apart (no triangle spans them):
    nodes, mesh, per-triangle body, the facing node pairs across the gap and the length each stands for."""
    a, h = A_BODY, A_BODY / n
    xw, _ = lattice_mesh(n, n, a, a)
    xt, _ = lattice_mesh(n, n, a, a, x0=a * (1 + gap))
    x = np.vstack([xw, xt])
    body = np.repeat([0, 1], len(xw))
    mesh = alpha_shape_mesh(x, None, body=body)
    tri_body = body[mesh.tri[:, 0]]
    right = np.flatnonzero(np.isclose(x[:, 0], a) & (body == 0))
    left = np.flatnonzero(np.isclose(x[:, 0], a * (1 + gap)) & (body == 1))
    right, left = right[np.argsort(x[right, 1])], left[np.argsort(x[left, 1])]
    length = np.full(n + 1, h)
    length[[0, -1]] = h / 2
    return x, mesh, tri_body, np.column_stack([right, left]), length


@pytest.mark.parametrize("lumped", [True, False], ids=["lumped", "consistent"])
def test_heat_ledger_closes(lumped):
    """Everything at once: a hot steel workpiece with a plastic source (per triangle) and a frictional one (at its
    contact nodes), a cold copper tool across a contact conductance, convection and radiation on the free edges,
    the tool's far side held at 300 K. Each step: source = stored + lost + removed to 1e-12 of the largest, and the
    stored heat against sum_e (rho c_p)_e A_e mean(dT over the triangle's nodes), computed here (the capacity's
    column sums, lumped or consistent)."""
    x, mesh, tri_body, pairs, length = two_bodies()
    k = np.where(tri_body == 0, K_STEEL, K_CU)
    rc = np.where(tri_body == 0, RC_STEEL, RC_CU)
    G = contact_conductance(pairs, length, 1e5, len(x))
    contact_face = np.isin(mesh.edges, pairs).all(axis=1)
    free_edges = mesh.edges[~contact_face]
    fixed = np.flatnonzero(np.isclose(x[:, 0], x[:, 0].max()))
    P = nodal_source(x, mesh.tri, np.where(tri_body == 0, 2e9, 0.0))
    P[pairs[:, 0]] += 50.0                                  # frictional heat [W/m] at the workpiece's contact nodes
    loss = SurfaceLoss(h_c=20.0, emissivity=0.6, T_ambient=300.0)
    T = np.where(x[:, 0] < A_BODY * 1.01, 800.0, 300.0)
    e1, e2 = x[mesh.tri[:, 1]] - x[mesh.tri[:, 0]], x[mesh.tri[:, 2]] - x[mesh.tri[:, 0]]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    for _ in range(5):
        T_new, heat = thermal_step(x, mesh.tri, T, 0.05, k, rc, P, edges=free_edges, loss=loss, fixed=fixed,
                                   T_fixed=300.0, conductance=G, lumped=lumped)
        assert isinstance(heat, StepHeat)
        terms = np.array([heat.source, heat.stored, heat.lost, heat.removed])
        print(f"lumped={lumped}: source, stored, lost, removed {terms} J/m, residual {heat.residual:.2e}")
        assert np.all(terms[[0, 2, 3]] > 0)
        assert abs(heat.residual) < 1e-12 * np.abs(terms).max()
        assert np.isclose(heat.source, 0.05 * P.sum(), rtol=1e-14)
        stored = np.sum(rc * area * (T_new - T)[mesh.tri].mean(axis=1))
        assert np.isclose(heat.stored, stored, rtol=1e-12)
        T = T_new


def test_contact_conductance_moves_heat_and_makes_none():
    """The two bodies alone (no losses, nothing fixed), the workpiece at 800 K and the tool at 300 K: heat crosses
    the contact and none is made (sum C T conserved to 1e-13); after three long steps both lie at the
    capacity-weighted mean."""
    x, mesh, tri_body, pairs, length = two_bodies()
    k = np.where(tri_body == 0, K_STEEL, K_CU)
    rc = np.where(tri_body == 0, RC_STEEL, RC_CU)
    G = contact_conductance(pairs, length, 1e5, len(x))
    assert abs(G @ np.ones(len(x))).max() == 0.0 and abs(G - G.T).max() == 0.0
    T = np.where(x[:, 0] < A_BODY * 1.01, 800.0, 300.0)
    c = capacity(x, mesh.tri, rc).diagonal()
    mean = np.sum(c * T) / np.sum(c)
    T1, heat = thermal_step(x, mesh.tri, T, 1.0, k, rc, conductance=G)
    assert T1[pairs[:, 1]].min() > 300.0 + 1.0                 # the tool's contact face warmed
    assert abs(np.sum(c * T1) - np.sum(c * T)) < 1e-13 * np.sum(c * T)
    assert abs(heat.stored) < 1e-13 * np.sum(c * np.abs(T1 - T))
    for _ in range(3):
        T, _ = thermal_step(x, mesh.tri, T, 1e4, k, rc, conductance=G)
    assert np.ptp(T) < 1e-6 * 500.0 and abs(T.mean() - mean) < 1e-9 * mean


# ----------------------------------------------------------------------------------- operators, the max principle

def test_operators_conserve_and_pass_the_patch_test():
    """K symmetric with K 1 = 0; a linear temperature conducts nothing into an inner node (the patch test); both
    capacities hold sum rho c_p A with the same column sums; two materials enter per triangle."""
    x, mesh = small_body(6)
    rng = np.random.default_rng(0)
    k = rng.uniform(10.0, 400.0, len(mesh.tri))
    K = conductivity_matrix(x, mesh.tri, k)
    assert abs(K - K.T).max() < 1e-14 * abs(K).max()
    assert abs(K @ np.ones(len(x))).max() < 1e-13 * abs(K).max()
    inner = np.setdiff1d(np.arange(len(x)), np.unique(mesh.edges))
    Kc = conductivity_matrix(x, mesh.tri, 50.0)
    assert abs(Kc @ (300.0 + 1e4 * x[:, 0] - 3e4 * x[:, 1]))[inner].max() < 1e-10
    assert abs(K @ (1e4 * x[:, 0]))[inner].max() > 1.0           # not for a conductivity that jumps
    rc = np.where(np.arange(len(mesh.tri)) % 2 == 0, RC_STEEL, RC_CU)
    Cl, Cc = capacity(x, mesh.tri, rc), capacity(x, mesh.tri, rc, lumped=False)
    total = np.sum(rc) * (A_BODY / 6) ** 2 / 2
    assert np.isclose(Cl.sum(), total, rtol=1e-13) and np.isclose(Cc.sum(), total, rtol=1e-13)
    assert np.allclose(np.asarray(Cc.sum(axis=0)).ravel(), Cl.diagonal(), rtol=1e-13)
    assert sp.triu(Cc, k=1).nnz > 0 and sp.triu(Cl, k=1).nnz == 0


def test_lumped_capacity_keeps_the_maximum_principle():
    """A cold square with one boundary node held at 1300 K, one short step (dt = 1e-3 rho c_p h^2 / k): the lumped
    capacity keeps every temperature within [300, 1300] K (an M-matrix on a Delaunay mesh, module text); the
    consistent one undershoots next to the hot node (measured: 112 K below 300 K, an 11 % undershoot of the 1000 K
    jump)."""
    x, mesh = small_body(8)
    hot = np.flatnonzero(np.isclose(x[:, 0], 0.0) & np.isclose(x[:, 1], A_BODY / 2))
    dt = 1e-3 * RC_CU * (A_BODY / 8) ** 2 / K_CU
    T_l, _ = thermal_step(x, mesh.tri, T0, dt, K_CU, RC_CU, fixed=hot, T_fixed=1300.0)
    T_c, _ = thermal_step(x, mesh.tri, T0, dt, K_CU, RC_CU, fixed=hot, T_fixed=1300.0, lumped=False)
    print(f"lowest T: lumped {T_l.min():.6f} K, consistent {T_c.min():.6f} K")
    assert T_l.min() >= T0 - 1e-9 and T_l.max() <= 1300.0 and T_l.max() > T0 + 1.0
    assert T_c.min() < T0 - 10.0


def test_nodal_heat_capacities_keep_the_heat_through_a_remeshing():
    """With ``mc`` (the nodes' m c_p, fixed with their masses) the capacity does not follow the triangles: an insulated
    body stepped on one mesh and then on another of the same nodes keeps sum mc T to 1e-13, while the area-based
    lumped capacity of the two meshes differs node by node (so its heat would jump at the remeshing). With mc equal to
    that lumped capacity the step is the rho_cp one."""
    x, mesh = small_body(6)
    sheared = x + np.column_stack([1e-3 * x[:, 1], np.zeros(len(x))])      # one diagonal direction everywhere
    other = alpha_shape_mesh(sheared, None).tri
    c1, c2 = capacity(x, mesh.tri, RC_CU).diagonal(), capacity(x, other, RC_CU).diagonal()
    assert np.abs(c1 - c2).max() > 0.1 * c1.max()                # the two meshes share the nodes' heat differently
    rng = np.random.default_rng(1)
    T = rng.uniform(300.0, 900.0, len(x))
    T_a, _ = thermal_step(x, mesh.tri, T, 0.5, K_CU, RC_CU)
    T_b, _ = thermal_step(x, mesh.tri, T, 0.5, K_CU, None, mc=c1)
    assert np.allclose(T_a, T_b, rtol=1e-13, atol=0)
    mc = rng.uniform(0.5, 1.5, len(x)) * c1
    T1, h1 = thermal_step(x, mesh.tri, T, 0.5, K_CU, None, mc=mc)
    T2, h2 = thermal_step(x, other, T1, 0.5, K_CU, None, mc=mc)
    assert abs(np.sum(mc * T2) - np.sum(mc * T)) < 1e-13 * np.sum(mc * T)
    assert np.ptp(T2) < np.ptp(T1) < np.ptp(T)


# ------------------------------------------------------------------------------------------------- 5. bad input

def _good():
    x, mesh = small_body(2)
    return dict(x=x, tri=mesh.tri, T=np.full(len(x), 400.0), dt=1.0, k=50.0, rho_cp=RC_STEEL), mesh.edges


@pytest.mark.parametrize("change, name", [
    (dict(k=-1.0), "k"), (dict(k=np.nan), "k"), (dict(k=np.ones(3)), "k"), (dict(rho_cp=0.0), "rho_cp"),
    (dict(rho_cp=np.inf), "rho_cp"), (dict(dt=0.0), "dt"), (dict(dt=np.nan), "dt"), (dict(T="hot"), "T"),
    (dict(T=np.full(3, 400.0)), "T"), (dict(T=-1.0), "T"), (dict(source=np.ones(2)), "source"),
    (dict(source=np.nan), "source"), (dict(fixed=[0], T_fixed=np.nan), "T_fixed"), (dict(fixed=[0]), "fixed"),
    (dict(fixed=[0.5], T_fixed=300.0), "fixed"), (dict(fixed=[99], T_fixed=300.0), "fixed"),
    (dict(loss=SurfaceLoss(10.0, 0.5, 300.0)), "edges"),
    (dict(conductance=sp.eye(3)), "conductance"), (dict(conductance=sp.eye(9)), "conductance"),
    (dict(conductance=np.zeros((9, 9))), "conductance"), (dict(mc=np.ones(9)), "mc"),
    (dict(rho_cp=None, mc=-np.ones(9)), "mc"),
    (dict(edges=np.array([[0, 99]]), loss=SurfaceLoss(10.0, 0.5, 300.0)), "edges"),
    (dict(edges=np.array([[0, 1]]), loss=(10.0, 0.5, 300.0)), "loss"),
])
def test_bad_input_raises_naming_the_parameter(change, name):
    kw, _ = _good()
    kw.update(change)
    with pytest.raises(ValueError, match=rf"\b{name}\b"):
        thermal_step(kw.pop("x"), kw.pop("tri"), kw.pop("T"), kw.pop("dt"), kw.pop("k"), kw.pop("rho_cp"), **kw)


def test_bad_mesh_and_loss_input_raises_naming_the_parameter():
    kw, edges = _good()
    x, tri = kw["x"], kw["tri"]
    for bad_x in (x[:, :1], np.where(np.arange(x.size).reshape(x.shape) == 3, np.nan, x)):
        with pytest.raises(ValueError, match=r"\bx\b"):
            conductivity_matrix(bad_x, tri, 1.0)
    for bad_tri in (tri.astype(float), tri[:, :2], tri + 100, tri[:, ::-1]):   # float, shape, range, clockwise
        with pytest.raises(ValueError, match=r"\btri\b"):
            capacity(x, bad_tri, 1.0)
    T = np.full(len(x), 400.0)
    for args, name in (((-1.0, 0.5, 300.0), "h_c"), ((1.0, 1.5, 300.0), "emissivity"), ((1.0, 0.5, np.nan), "T_inf"),
                       ((1.0, 0.5, [300.0, 300.0]), "T_inf")):
        with pytest.raises(ValueError, match=rf"\b{name}\b"):
            edge_losses(x, edges, T, *args)
    with pytest.raises(ValueError, match=r"\bedges\b"):
        edge_losses(x, edges[:, :1], T, 1.0, 0.5, 300.0)
    with pytest.raises(ValueError, match=r"\bq\b"):
        nodal_source(x, tri, -1.0)
    with pytest.raises(ValueError, match=r"\bh_int\b"):
        contact_conductance(np.array([[0, 1]]), 1e-3, -5.0, len(x))
    with pytest.raises(ValueError, match=r"\bpairs\b"):
        contact_conductance(np.array([[0, 0]]), 1e-3, 5.0, len(x))
