"""ESPH (Section 2.1) and the hypoelastic update (Section 2.3): package vs a plain pair loop, and the
properties the discrete equations must have (momentum conservation, linear patch test in the interior,
objective Jaumann rate, plane-strain s_zz, switches of the artificial viscosity and pressure)."""
import math

import numpy as np
import pytest

from refsph.esph import (ESPHParams, artificial_pressure, artificial_viscosity, esph_rates,
                         velocity_gradient)
from refsph.kernels import get_kernel
from refsph.material import jaumann_deviatoric_rate
from refsph.neighbours import PairSum, find_pairs
from refsph.scenes import aisi4340_material, lattice
from refsph.state import State

MAT = aisi4340_material()
CUBIC = get_kernel("cubic")
DP = 1e-4
H = 1.5 * DP


def random_state(nx=10, ny=9, seed=1, rho_jitter=0.004):
    rng = np.random.default_rng(seed)
    x = lattice([nx * DP, ny * DP], DP) + 0.15 * DP * rng.uniform(-1, 1, (nx * ny, 2))
    n = len(x)
    rho = MAT.rho0 * (1.0 + rho_jitter * rng.uniform(-1, 1, n))
    m = MAT.rho0 * DP * DP * (1.0 + 0.05 * rng.uniform(-1, 1, n))
    xc = x - x.mean(axis=0)
    v = xc @ np.array([[200.0, -3000.0], [3000.0, -100.0]]).T + 5.0 * rng.normal(size=(n, 2))
    S = rng.normal(scale=2e8, size=(n, 2, 2))
    S = 0.5 * (S + np.swapaxes(S, 1, 2))
    return State(x=x, v=v, m=m, rho=rho, S=S, S_zz=-(S[:, 0, 0] + S[:, 1, 1]), X=x.copy(), V0=m / rho)


def params(gamma=0.3):
    return ESPHParams(h=H, dp=DP, beta1=1.5, beta2=1.5, gamma=gamma, n_ap=4.0, eps=0.01, kernel=CUBIC)


def plain_rates(st, prm):
    """Eqs. (10)-(14), (20)-(24), one (i, j) at a time, full neighbour loop, 2D plane strain."""
    n, I2 = st.n, np.eye(2)
    W = lambda r: CUBIC.w(r, prm.h, 2)  # noqa: E731
    p = MAT.K * (st.rho / MAT.rho0 - 1.0)
    sig = [(st.S[i] - p[i] * I2) / st.rho[i] ** 2 for i in range(n)]
    drho, l, dv = np.zeros(n), np.zeros((n, 2, 2)), np.zeros((n, 2))
    for i in range(n):
        for j in range(n):
            xij, vij = st.x[i] - st.x[j], st.v[i] - st.v[j]
            r = math.hypot(*xij)
            if j == i or r >= 2 * prm.h:
                continue
            gW = CUBIC.dw_dr(r, prm.h, 2) * xij / r
            drho[i] += st.m[j] * vij @ gW
            l[i] -= st.m[j] / st.rho[j] * np.outer(vij, gW)
            vx = vij @ xij
            mu = prm.h * vx / (r * r + prm.eps * prm.h**2)
            pi = (-prm.beta1 * MAT.c0 * mu + prm.beta2 * mu * mu) / (0.5 * (st.rho[i] + st.rho[j])) if vx <= 0 else 0.0
            pa = 0.0
            if prm.gamma > 0 and not (p[i] > 0 and p[j] > 0):
                pa = (prm.gamma * (abs(p[i]) / st.rho[i] ** 2 + abs(p[j]) / st.rho[j] ** 2)
                      * (W(r) / W(prm.dp)) ** prm.n_ap)
            dv[i] += st.m[j] * (sig[i] + sig[j] - (pi + pa) * I2) @ gW
    dS, dSzz = np.zeros((n, 2, 2)), np.zeros(n)
    for i in range(n):
        e, w = 0.5 * (l[i] + l[i].T), 0.5 * (l[i] - l[i].T)
        tr = np.trace(e)
        dS[i] = 2 * MAT.G * (e - tr / 3 * I2) + w @ st.S[i] - st.S[i] @ w
        dSzz[i] = -2 * MAT.G * tr / 3
    return drho, dv, dS, dSzz


@pytest.mark.parametrize("gamma", [0.0, 0.3])
def test_package_matches_plain_loop(gamma):
    st, prm = random_state(), params(gamma)
    I, J = find_pairs(st.x, 2 * H)
    got = esph_rates(st, MAT, prm, I, J)
    for name, a, b in zip(("rho", "v", "S", "S_zz"), plain_rates(st, prm), (got.rho, got.v, got.S, got.S_zz)):
        scale = np.abs(a).max()
        assert scale > 0
        assert np.allclose(a, b, rtol=1e-10, atol=1e-10 * scale), name
    assert np.array_equal(got.x, st.v)


def test_pairs_beyond_support_contribute_nothing():
    st, prm = random_state(), params()
    I, J = find_pairs(st.x, 2 * H)
    I2, J2 = find_pairs(st.x, 3 * H)                   # a Verlet list with a skin
    a, b = esph_rates(st, MAT, prm, I, J), esph_rates(st, MAT, prm, I2, J2)
    for f in ("rho", "v", "S", "S_zz"):
        ref = getattr(a, f)
        assert np.allclose(ref, getattr(b, f), rtol=1e-12, atol=1e-12 * np.abs(ref).max()), f


def test_momentum_conserved_to_round_off():
    st = random_state(nx=14, ny=12, seed=7)
    I, J = find_pairs(st.x, 2 * H)
    a = esph_rates(st, MAT, params(), I, J).v
    ma = st.m[:, None] * a
    assert np.abs(ma.sum(axis=0)).max() / np.abs(ma).sum() < 1e-12


def test_velocity_gradient_linear_field_interior():
    n_side = 16
    x = lattice([n_side * DP] * 2, DP)
    V = np.full(len(x), DP * DP)
    A = np.array([[1.0, -2.0], [0.5, 3.0]]) * 1e3
    v = x @ A.T
    I, J = find_pairs(x, 2 * H)
    dx = x[I] - x[J]
    gW = CUBIC.dw_dr_over_r(np.linalg.norm(dx, axis=1), H, 2)[:, None] * dx
    pairs = PairSum(I, J, len(x))
    l = velocity_gradient(pairs, V, v[I] - v[J], gW)
    err = np.linalg.norm(l - A, axis=(1, 2)) / np.linalg.norm(A)
    depth = np.minimum(x, n_side * DP - x).min(axis=1)
    interior = depth > 2 * H
    assert interior.sum() > 50
    assert err[interior].max() < 1e-2            # lattice-sum error of the cubic spline at h = 1.5 dp
    assert err[~interior].max() > 0.3            # no correction at the free surface (documented deficiency)
    # l = A M exactly, M = -sum V_j x_ij (x) grad W: the error is the moment matrix, nothing else
    M = velocity_gradient(pairs, V, dx, gW)
    assert np.allclose(l, A @ M, rtol=1e-12, atol=1e-12 * np.abs(A).max())
    assert np.allclose(M[interior], M[interior][0], rtol=0, atol=1e-12)   # same at every interior particle


def _rot(a):
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])


def test_jaumann_rigid_rotation_corotates_stress():
    """Integrate ds/dt = Jaumann(s, l = spin) over a quarter turn; s must follow R s0 R^T at every angle.

    Checked at every step, not only at 90 degrees: a symmetric tensor rotated by +90 and -90 degrees is the
    same tensor, so a quarter-turn-only check cannot see a wrong sign of the spin terms."""
    w = 2.0e3
    S0 = np.array([[[300e6, 120e6], [120e6, -50e6]], [[-80e6, 40e6], [40e6, 10e6]]])
    Szz0 = -(S0[:, 0, 0] + S0[:, 1, 1])
    l = np.broadcast_to(np.array([[0.0, -w], [w, 0.0]]), (2, 2, 2)).copy()
    n_steps = 200
    dt = 0.5 * math.pi / w / n_steps
    S, Szz = S0.copy(), Szz0.copy()
    f = lambda S_, Z_: jaumann_deviatoric_rate(S_, Z_, l, MAT.G)  # noqa: E731
    inv0 = np.einsum("nab,nab->n", S0, S0)
    for k in range(1, n_steps + 1):              # classical RK4
        k1 = f(S, Szz)
        k2 = f(S + 0.5 * dt * k1[0], Szz + 0.5 * dt * k1[1])
        k3 = f(S + 0.5 * dt * k2[0], Szz + 0.5 * dt * k2[1])
        k4 = f(S + dt * k3[0], Szz + dt * k3[1])
        S = S + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        Szz = Szz + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        R = _rot(k * dt * w)
        assert np.allclose(S, R @ S0 @ R.T, rtol=0, atol=1e-8 * np.abs(S0).max())
        assert np.allclose(np.einsum("nab,nab->n", S, S), inv0, rtol=1e-8)   # tr(s^2) unchanged
    assert np.array_equal(Szz, Szz0)


def test_jaumann_spin_sign():
    """At 45 degrees the two sign conventions differ: the rate must be d/dt (R s R^T) = W s - s W."""
    w = 1.0
    S0 = np.array([[[300e6, 120e6], [120e6, -50e6]]])
    l = np.array([[[0.0, -w], [w, 0.0]]])
    dS, _ = jaumann_deviatoric_rate(S0, np.zeros(1), l, MAT.G)
    assert np.allclose(dS[0], l[0] @ S0[0] - S0[0] @ l[0], rtol=1e-14)
    assert not np.allclose(dS[0], S0[0] @ l[0] - l[0] @ S0[0])


def test_plane_strain_szz_rate():
    rng = np.random.default_rng(3)
    l = rng.normal(size=(20, 2, 2)) * 1e3
    S = rng.normal(size=(20, 2, 2)) * 1e8
    S = 0.5 * (S + np.swapaxes(S, 1, 2))
    dS, dSzz = jaumann_deviatoric_rate(S, -(S[:, 0, 0] + S[:, 1, 1]), l, MAT.G)
    tr = l[:, 0, 0] + l[:, 1, 1]
    assert np.allclose(dSzz, -2 * MAT.G * tr / 3, rtol=1e-14, atol=0)
    # the 3D deviator stays traceless: d/dt (s_xx + s_yy + s_zz) = 0
    assert np.allclose(dS[:, 0, 0] + dS[:, 1, 1] + dSzz, 0, atol=1e-12 * np.abs(dSzz).max())
    # the spin does not touch s_zz
    _, dSzz_spin = jaumann_deviatoric_rate(S, np.zeros(20), l - np.swapaxes(l, 1, 2), MAT.G)
    assert np.all(dSzz_spin == 0)


def test_artificial_pressure_only_with_tension():
    rho = np.full(4, MAT.rho0)
    p_i = np.array([1e8, 1e8, -1e8, -1e8])
    p_j = np.array([2e8, -2e8, 2e8, -2e8])
    pa = artificial_pressure(p_i, p_j, rho, rho, np.full(4, 0.9), 0.3, 4.0)
    assert pa[0] == 0.0                                  # both in compression
    expect = 0.3 * (np.abs(p_i) + np.abs(p_j)) / MAT.rho0**2 * 0.9**4
    assert np.allclose(pa[1:], expect[1:], rtol=1e-14)
    # in esph_rates: an all-compressed state gives identical rates with gamma = 0 and gamma = 0.3
    st = random_state(rho_jitter=0.0)
    st.rho = MAT.rho0 * (1.001 + 0.002 * np.random.default_rng(5).uniform(size=st.n))
    I, J = find_pairs(st.x, 2 * H)
    a0, a3 = esph_rates(st, MAT, params(0.0), I, J), esph_rates(st, MAT, params(0.3), I, J)
    assert np.array_equal(a0.v, a3.v)


def test_artificial_viscosity_only_for_approaching_pairs():
    vr = np.array([-2.0, -1e-3, 0.0, 1e-3, 2.0]) * 1e-3       # v_ij . x_ij [m^2/s]
    r2 = np.full(5, DP**2)
    pi = artificial_viscosity(vr, r2, np.full(5, MAT.rho0), MAT.c0, H, 1.5, 1.5, 0.01)
    assert np.all(pi[2:] == 0.0)
    assert np.all(pi[:2] > 0.0)
    mu = H * vr[0] / (DP**2 + 0.01 * H**2)
    assert math.isclose(pi[0], (-1.5 * MAT.c0 * mu + 1.5 * mu * mu) / MAT.rho0, rel_tol=1e-14)


def test_blocks_of_pairs_give_the_same_rates():
    """esph_rates over many small pair blocks (refsph.neighbours.PairBlocks) = over one block, to round-off."""
    from refsph.neighbours import PairBlocks
    st, prm = random_state(), params()
    I, J = find_pairs(st.x, 2.3 * H)
    one = esph_rates(st, MAT, prm, I, J)
    many = esph_rates(st, MAT, prm, I, J, pairs=PairBlocks(I, J, st.n, size=97, threads=2))
    for f in ("rho", "v", "S", "S_zz", "l"):
        ref = getattr(one, f)
        assert np.allclose(ref, getattr(many, f), rtol=1e-12, atol=1e-13 * np.abs(ref).max()), f
    with pytest.raises(ValueError, match="do not match"):
        esph_rates(st, MAT, prm, I[:-1], J[:-1], pairs=PairBlocks(I, J, st.n))
