"""TLSPH (refsph.tlsph): the sparse operators against plain pair loops, the kernel-gradient correction,
conservation, objectivity of the stress measure, and the reference-configuration update."""
import dataclasses
import math

import numpy as np
import pytest

from refsph.kernels import get_kernel
from refsph.scenes import aisi4340_material, lattice
from refsph.state import make_state
from refsph.tensor import det
from refsph.tlsph import (ReferenceOperator, TLSPHParams, first_piola, green_lagrange_norm, reference_update,
                          tlsph_rates)

MAT = aisi4340_material()
KERNEL = get_kernel("cubic")
DP = 1e-4
H = 1.5 * DP


def params(corrected, beta=1.5):
    return TLSPHParams(h=H, beta1=beta, beta2=beta, eps=0.01, kernel=KERNEL, corrected=corrected,
                       ref_update_strain=0.5)


def rot(theta):
    return np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])


def random_block(nx=14, ny=10, seed=0, uniform_rho0=True):
    """Irregular reference lattice, random deformation, velocity and deviatoric pre-stress."""
    rng = np.random.default_rng(seed)
    X = lattice([nx * DP, ny * DP], DP) + 0.1 * DP * rng.uniform(-1, 1, (nx * ny, 2))
    st = make_state(X, 0.0, MAT.rho0, DP * DP * (1 + 0.05 * rng.uniform(-1, 1, nx * ny)))
    if not uniform_rho0:
        st.m = st.m * (1 + 0.02 * rng.uniform(-1, 1, nx * ny))
    A = np.array([[1.04, 0.12], [-0.05, 0.97]])
    st.x = X @ A.T + 0.02 * DP * rng.normal(size=X.shape)
    st.v = rng.normal(scale=5.0, size=X.shape) + (X - X.mean(0)) @ np.array([[0, -2e3], [3e3, 1e3]]).T
    s = rng.normal(scale=100e6, size=(len(X), 3))
    st.S = np.stack([np.stack([s[:, 0], s[:, 2]], -1), np.stack([s[:, 2], s[:, 1]], -1)], 1)
    st.S_zz = -(s[:, 0] + s[:, 1])
    return st


def grad_w(xij, h):
    r = math.hypot(xij[0], xij[1])
    q = r / h
    if r == 0.0 or q >= 2.0:
        return np.zeros(2)
    dfdq = -3.0 * q + 2.25 * q * q if q <= 1.0 else -0.75 * (2.0 - q) ** 2
    return 10.0 / (7.0 * math.pi * h * h) / h * dfdq * np.asarray(xij) / r


def plain_tlsph(st, corrected, beta=1.5, eps=0.01):
    """Eqs. (17)-(19), (2), (24) pair by pair; the viscosity as refsph defines it."""
    X, x, v, m, V = st.X, st.x, st.v, st.m, st.V0
    n = len(X)
    nb = [[j for j in range(n) if j != i and math.dist(X[i], X[j]) < 2 * H] for i in range(n)]
    gW = {(i, j): grad_w(X[i] - X[j], H) for i in range(n) for j in nb[i]}
    L = np.zeros((n, 2, 2))
    for i in range(n):
        M = sum(V[j] * np.outer(X[j] - X[i], gW[i, j]) for j in nb[i])
        L[i] = np.linalg.inv(M).T if corrected else np.eye(2)
    g = {k: L[k[0]] @ gw for k, gw in gW.items()}
    F = np.zeros((n, 2, 2))
    Fdot = np.zeros((n, 2, 2))
    for i in range(n):
        for j in nb[i]:
            F[i] -= V[j] * np.outer(x[i] - x[j], g[i, j])
            Fdot[i] -= V[j] * np.outer(v[i] - v[j], g[i, j])
    J = np.linalg.det(F)
    Finv = np.linalg.inv(F)
    rho0 = m / V
    rho = rho0 / J
    p = MAT.K * (rho / MAT.rho0 - 1)
    sigma = st.S - p[:, None, None] * np.eye(2)
    P = J[:, None, None] * sigma @ np.swapaxes(Finv, 1, 2)
    B = J[:, None, None] * np.swapaxes(Finv, 1, 2)
    a = np.zeros((n, 2))
    for i in range(n):
        for j in nb[i]:
            a[i] += m[j] * (P[i] / rho0[i] ** 2 @ g[i, j] - P[j] / rho0[j] ** 2 @ g[j, i])
            xij, vij = x[i] - x[j], v[i] - v[j]
            vr = vij @ xij
            if vr < 0 and beta > 0:
                mu = H * vr / (xij @ xij + eps * H * H)
                pi = (-beta * MAT.c0 * mu + beta * mu * mu) / (0.5 * (rho[i] + rho[j]))
                a[i] -= m[j] * pi * 0.5 * (B[i] + B[j]) @ gW[i, j]
    return dict(F=F, Fdot=Fdot, J=J, P=P, a=a, l=Fdot @ Finv)


@pytest.fixture(scope="module")
def block():
    return random_block()


@pytest.mark.parametrize("corrected", [False, True])
def test_plain_loops_match_package(block, corrected):
    op = ReferenceOperator(block.X, block.V0, H, KERNEL, corrected)
    out = {}
    rates = tlsph_rates(block, MAT, params(corrected), op, out=out)
    ref = plain_tlsph(block, corrected)
    assert np.allclose(op.deformation_gradient(block.x), ref["F"], rtol=1e-12, atol=1e-12)
    assert np.allclose(out["F"], ref["F"], rtol=1e-12, atol=1e-12)
    assert np.allclose(op.gradient(block.v), ref["Fdot"], rtol=1e-12, atol=1e-12 * np.abs(ref["Fdot"]).max())
    assert np.allclose(out["J"], ref["J"], rtol=1e-12)
    assert np.allclose(out["l"], ref["l"], rtol=1e-10, atol=1e-12 * np.abs(ref["l"]).max())
    assert np.allclose(out["P"], ref["P"], rtol=1e-10, atol=1e-12 * np.abs(ref["P"]).max())
    assert np.allclose(rates.v, ref["a"], rtol=1e-10, atol=1e-11 * np.abs(ref["a"]).max())
    # the momentum sum on its own (stress part of Eq. 17)
    Q = out["P"] / ((block.m / block.V0) ** 2)[:, None, None]
    ref0 = plain_tlsph(block, corrected, beta=0.0)
    assert np.allclose(op.momentum_sum(Q, block.m), ref0["a"], rtol=1e-10, atol=1e-11 * np.abs(ref0["a"]).max())


def _square(nx=16, ny=12):
    X = lattice([nx * DP, ny * DP], DP)
    return X, np.full(len(X), DP * DP)


def _surface_mask(X, nx=16, ny=12):
    d = np.minimum.reduce([X[:, 0], nx * DP - X[:, 0], X[:, 1], ny * DP - X[:, 1]])
    return d < DP


def test_affine_patch_test_exact_with_correction():
    X, V = _square()
    A = np.array([[1.1, 0.3], [-0.2, 0.9]])
    x = X @ A.T + np.array([2e-3, -1e-3])
    F_cor = ReferenceOperator(X, V, H, KERNEL, True).deformation_gradient(x)
    assert np.abs(F_cor - A).max() < 1e-12
    F_raw = ReferenceOperator(X, V, H, KERNEL, False).deformation_gradient(x)
    assert np.abs(F_raw - A)[_surface_mask(X)].max() > 0.1          # Eq. (18) as printed fails at the surface


def test_identity_at_rest_with_correction():
    X, V = _square()
    I2 = np.eye(2)
    assert np.abs(ReferenceOperator(X, V, H, KERNEL, True).deformation_gradient(X) - I2).max() < 1e-12
    F_raw = ReferenceOperator(X, V, H, KERNEL, False).deformation_gradient(X)
    assert np.abs(F_raw - I2)[_surface_mask(X)].max() > 0.1
    # irregular reference positions too
    Xr = X + 0.2 * DP * np.random.default_rng(3).uniform(-1, 1, X.shape)
    assert np.abs(ReferenceOperator(Xr, V, H, KERNEL, True).deformation_gradient(Xr) - I2).max() < 1e-12


@pytest.mark.parametrize("corrected", [False, True])
@pytest.mark.parametrize("seed", [1, 2])
def test_momentum_conserved_to_roundoff(corrected, seed):
    st = random_block(seed=seed, uniform_rho0=False)
    op = ReferenceOperator(st.X, st.V0, H, KERNEL, corrected)
    a = tlsph_rates(st, MAT, params(corrected), op).v
    ma = st.m[:, None] * a
    assert np.linalg.norm(ma.sum(0)) / np.linalg.norm(ma, axis=1).sum() < 1e-12


@pytest.mark.parametrize("corrected", [False, True])
def test_stress_power_identity(corrected):
    """sum m v.a = - sum V P : Fdot (uniform reference density): Eq. (17) is the transpose of Eq. (19)."""
    st = random_block(seed=4)
    op = ReferenceOperator(st.X, st.V0, H, KERNEL, corrected)
    out = {}
    a = tlsph_rates(st, MAT, params(corrected, beta=0.0), op, out=out).v
    power = np.sum(st.m[:, None] * st.v * a)
    sp = st.V0[:, None, None] * out["P"] * op.gradient(st.v)
    assert abs(power + sp.sum()) < 1e-12 * np.abs(sp).sum()


@pytest.mark.parametrize("theta", [math.pi / 2, 0.7])
def test_rotated_prestressed_body_force_is_rotated(theta):
    """Force of the rotated body (x = R x0, sigma = R sigma0 R^T) = R times the force of the unrotated one."""
    X, V = _square()
    op = ReferenceOperator(X, V, H, KERNEL, True)
    x0 = X.copy()
    x0[:, 0] -= 0.002 * X[:, 0] ** 2 / (16 * DP)                    # non-uniform compression: p varies
    s = 150e6 * (1 + X[:, 0] / (16 * DP))
    S0 = np.stack([np.stack([s, 0.6 * s], -1), np.stack([0.6 * s, -0.5 * s], -1)], 1)
    R = rot(theta)
    st0 = make_state(X, 0.0, MAT.rho0, V)
    st0.x, st0.S = x0, S0
    st1 = make_state(X, 0.0, MAT.rho0, V)
    st1.x, st1.S = x0 @ R.T, R @ S0 @ R.T
    prm = params(True, beta=0.0)
    a0 = tlsph_rates(st0, MAT, prm, op).v
    out = {}
    a1 = tlsph_rates(st1, MAT, prm, op, out=out).v
    assert np.abs(a1 - a0 @ R.T).max() < 1e-10 * np.abs(a0).max()
    # the printed form N = J F^-1 sigma in place of P would give a different force
    sigma = st1.S - out["p"][:, None, None] * np.eye(2)
    N = out["J"][:, None, None] * np.linalg.inv(out["F"]) @ sigma
    aN = op.momentum_sum(N / MAT.rho0**2, st1.m)
    assert np.abs(aN - a0 @ R.T).max() > 0.1 * np.abs(a0).max()


def test_first_piola_is_J_sigma_F_invT():
    rng = np.random.default_rng(5)
    F = np.eye(2) + 0.3 * rng.normal(size=(20, 2, 2))
    sym = rng.normal(size=(20, 2, 2))
    sigma = sym + np.swapaxes(sym, 1, 2)
    J = det(F)
    Finv = np.linalg.inv(F)
    P = first_piola(sigma, J, Finv)
    for k in range(20):
        assert np.allclose(P[k], J[k] * sigma[k] @ np.linalg.inv(F[k]).T, rtol=1e-12, atol=1e-14)
    # the Piola identity that makes it the right measure: P F^T = J sigma (symmetric)
    assert np.allclose(P @ np.swapaxes(F, 1, 2), J[:, None, None] * sigma, rtol=1e-12, atol=1e-12)


def test_green_lagrange_norm_zero_for_rotation():
    F = np.array([rot(t) for t in np.linspace(0, 2 * np.pi, 13)])
    assert green_lagrange_norm(F).max() < 1e-14
    shear = np.array([[[1.0, 0.4], [0.0, 1.0]]])
    E = 0.5 * (shear[0].T @ shear[0] - np.eye(2))
    assert green_lagrange_norm(shear)[0] == pytest.approx(np.linalg.norm(E), rel=1e-14)


def test_reference_update_keeps_volume_and_resets_F():
    X, V = _square()
    st = make_state(X, 0.0, MAT.rho0, V)
    sx = np.sin(np.pi * X[:, 0] / (16 * DP))
    st.x = X.copy()
    st.x[:, 0] += 0.4 * X[:, 1] + 0.05 * DP * sx
    st.x[:, 1] *= 1.01
    st.S[:, 0, 1] = st.S[:, 1, 0] = 50e6 * sx
    st.S_zz[:] = 3e6
    op = ReferenceOperator(X, V, H, KERNEL, True)
    F = op.deformation_gradient(st.x)
    J = det(F)
    new = reference_update(st, F)
    new_op = ReferenceOperator(new.X, new.V0, H, KERNEL, True)
    assert np.allclose(new.X, st.x) and np.allclose(new_op.X, st.x)
    assert np.sum(new.V0) == pytest.approx(np.sum(J * st.V0), rel=1e-14)
    assert np.allclose(new.V0, J * st.V0, rtol=1e-14)
    assert np.abs(new_op.deformation_gradient(new.x) - np.eye(2)).max() < 1e-12
    assert np.array_equal(new.S, st.S) and np.array_equal(new.S_zz, st.S_zz)   # stress kept
    assert np.allclose(new.rho, st.m / (J * st.V0), rtol=1e-13)                 # density continuous
    # the original state is untouched
    assert np.array_equal(st.X, X) and np.array_equal(st.V0, V)


def test_singular_correction_matrix_stays_finite():
    """A particle whose neighbours do not span the plane (a single row; an isolated particle) gets the
    pseudo-inverse correction instead of inf/NaN, and is reported as degenerate."""
    from refsph.kernels import get_kernel
    from refsph.tlsph import ReferenceOperator

    dp = 1e-3
    row = np.stack([np.arange(10) * dp, np.zeros(10)], axis=1)
    lonely = np.array([[0.1, 0.1]])
    block = np.stack(np.meshgrid(np.arange(6) * dp, np.arange(6) * dp + 0.05), -1).reshape(-1, 2)
    X = np.concatenate([row, lonely, block])
    op = ReferenceOperator(X, np.full(len(X), dp * dp), 1.5 * dp, get_kernel("cubic"), True)
    assert np.isfinite(op.L).all()
    assert set(op.degenerate.tolist()) == set(range(11))
    # along the row the correction still reproduces an affine field exactly
    F = op.deformation_gradient(2.0 * X)
    np.testing.assert_allclose(F[:10, 0, 0], 2.0, rtol=1e-12)
    np.testing.assert_allclose(F[11:], np.broadcast_to(2.0 * np.eye(2), F[11:].shape), atol=1e-12)
    # across the row, and for the lone particle, nothing is known: F is completed with the identity there, so
    # det F is the stretch along the row (2), not 0, and a reference update stays possible (issue 22's cuts)
    np.testing.assert_allclose(F[:10, 1], np.broadcast_to([0.0, 1.0], (10, 2)), atol=1e-12)
    np.testing.assert_allclose(F[10], np.eye(2), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(F[:10]), 2.0, rtol=1e-12)
    new = reference_update(make_state(X, 0.0, 7800.0, dp * dp), F)
    assert np.all(new.V0 > 0)


def test_blocks_and_threads_give_the_same_rates(block):
    """The artificial viscosity summed over many small pair blocks on two threads = over one block."""
    one = ReferenceOperator(block.X, block.V0, H, KERNEL, True)
    many = ReferenceOperator(block.X, block.V0, H, KERNEL, True, threads=2, block_size=53)
    a, b = (tlsph_rates(block, MAT, params(True), op).v for op in (one, many))
    assert len(many.pairs.blocks) > 5
    assert np.allclose(a, b, rtol=1e-12, atol=1e-13 * np.abs(a).max())


def test_reference_update_refuses_a_singular_F():
    X, V = _square()
    st = make_state(X, 0.0, MAT.rho0, V)
    F = np.broadcast_to(np.eye(2), (len(X), 2, 2)).copy()
    F[3] = [[1.0, 0.0], [0.0, 0.0]]                        # collapsed: J = 0
    with pytest.raises(ValueError, match="particle 3"):
        reference_update(st, F)


def test_end_of_step_refuses_an_inverted_particle():
    """A particle with J = det F <= 0 fails the step (ReferenceConfiguration.end_step) instead of taking the negative
    density m / (J V0) of Eq. (2) into the next step (thermal_cutting case 10 at t_u/10: J = -0.031 gave rho =
    -1.4e9 kg/m^3, and the heat step's surface area V^(1/2) of the negative volume turned its T into NaN). The reference
    update's own J > 0 check does not see it: |E| stays below 1/2 for a particle collapsing along one direction
    (E = (lambda^2 - 1) / 2 >= -1/2) or mirrored (E = 0), so no update runs; here the update is off."""
    from refsph.reference import ReferenceConfiguration

    X, V = _square()
    ref = ReferenceConfiguration(dataclasses.replace(params(True), ref_update_strain=None), None, threads=1)
    st = make_state(X, 0.0, MAT.rho0, V)
    st.x = X * [1.01, 0.99]                                 # stretched, not inverted: rho = m / (J V0)
    np.testing.assert_allclose(ref.end_step(st, st.n, False).rho, MAT.rho0 / (1.01 * 0.99), rtol=1e-10)
    st = make_state(X, 0.0, MAT.rho0, V)
    k = 100
    near = np.linalg.norm(X - X[k], axis=1) <= H               # particle k and its nearest neighbours mirrored in x
    st.x = X.copy()
    st.x[near, 0] = 2.0 * X[k, 0] - X[near, 0]                 # (k alone inverted: J_k < 0, its neighbours' > 0)
    with pytest.raises(ValueError, match=f"inverted particle: J = det F = -.* at particle {k} "):
        ref.end_step(st, st.n, False)


@pytest.mark.parametrize("corrected", [False, True])
def test_viscous_heat_is_the_work_the_viscosity_takes(corrected):
    """Rates.heat_power (viscous_heat): every particle's share >= 0, their sum = -sum m v . a_visc (the power the
    artificial viscosity takes out of the motion), the same over many pair blocks; off by default."""
    st = random_block(seed=5)
    op = ReferenceOperator(st.X, st.V0, H, KERNEL, corrected)
    with_heat = dataclasses.replace(params(corrected), viscous_heat=True)
    r = tlsph_rates(st, MAT, with_heat, op)
    a_stress = tlsph_rates(st, MAT, params(corrected, beta=0.0), op).v
    assert tlsph_rates(st, MAT, params(corrected), op).heat_power is None
    q = r.heat_power
    taken = -np.sum(st.m[:, None] * st.v * (r.v - a_stress))
    assert taken > 0 and np.all(q >= -1e-12 * q.max())
    assert abs(q.sum() - taken) < 1e-10 * taken
    assert np.count_nonzero(q > 1e-6 * q.max()) > 0.5 * st.n
    many = ReferenceOperator(st.X, st.V0, H, KERNEL, corrected, threads=2, block_size=53)
    np.testing.assert_allclose(tlsph_rates(st, MAT, with_heat, many).heat_power, q, rtol=1e-10, atol=1e-12 * q.max())


def test_condition_limit_bounds_the_correction_and_leaves_the_rest():
    """max_condition (issue 22's Ti6Al4V cut at t_u/10: a surface particle with 6 nearly collinear neighbours after
    a reference update had a moment matrix of condition 73, its correction amplified the error of F ~100-fold, and
    its pressure reached -45 GPa): above the limit the smallest singular value is floored at s_max / limit, below it
    L = M^-T to the bit."""
    from refsph.kernels import correction_matrix

    rng = np.random.default_rng(3)
    R1, R2 = rot(0.3), rot(-1.1)
    s = np.array([[1.0, 0.9], [1.0, 0.01], [2.0, 0.05], [1.0, 0.2]])       # conditions 1.1, 100, 40, 5
    M = np.einsum("ij,nj,jk->nik", R1, s, R2) + 1e-3 * rng.standard_normal((4, 2, 2)) * s[:, 1:2, None]
    cond = np.linalg.cond(M)
    free, _ = correction_matrix(M)
    capped, bad = correction_matrix(M, max_condition=20.0)
    assert len(bad) == 0
    below = cond <= 20.0
    assert below.tolist() == [True, False, False, True]
    np.testing.assert_array_equal(capped[below], free[below])                     # untouched, bit for bit
    np.testing.assert_allclose(np.einsum("nji,njk->nik", free, M), np.broadcast_to(np.eye(2), M.shape), atol=1e-9)
    # above: the largest amplification of L is limit / s_max instead of 1 / s_min
    amp = np.linalg.norm(capped, 2, axis=(1, 2))
    smax = np.linalg.svd(M, compute_uv=False)[:, 0]
    np.testing.assert_allclose(amp[~below], 20.0 / smax[~below], rtol=1e-12)
    assert np.all(np.linalg.norm(free, 2, axis=(1, 2))[~below] > 1.9 * amp[~below])
    # the well-spanned direction keeps its exact inverse: L^T M v1 = v1 for M's leading right singular vector
    U, sv, Vt = np.linalg.svd(M[~below])
    v1 = Vt[:, 0, :]
    np.testing.assert_allclose(np.einsum("nji,njk,nk->ni", capped[~below], M[~below], v1), v1, atol=1e-12)
