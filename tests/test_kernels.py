"""Smoothing kernels (refsph.kernels): normalisation, gradient, support, r -> 0 limit, errors.

The reference values are the formulas themselves (Eq. (9) of Islam, Bansal & Peng; Wendland C2 with
support 2h as in Dehnen & Aly 2012), written here once more as plain scalar if/else functions.
"""
import numpy as np
import pytest
from scipy import integrate

from refsph.kernels import KERNELS, CubicSpline, WendlandC2, get_kernel

NAMES = ["cubic", "wendland"]
DIMS = [2, 3]


def w_plain(name, r, h, dim):
    """W(r, h) one value at a time, straight from the formulas."""
    q = r / h
    if name == "cubic":
        alpha = 10.0 / (7.0 * np.pi * h**2) if dim == 2 else 1.0 / (np.pi * h**3)
        if q <= 1.0:
            return alpha * (1.0 - 1.5 * q**2 + 0.75 * q**3)
        if q <= 2.0:
            return alpha * 0.25 * (2.0 - q) ** 3
        return 0.0
    alpha = 7.0 / (4.0 * np.pi * h**2) if dim == 2 else 21.0 / (16.0 * np.pi * h**3)
    return alpha * (1.0 - 0.5 * q) ** 4 * (2.0 * q + 1.0) if q <= 2.0 else 0.0


def dw_dr_plain(name, r, h, dim):
    q = r / h
    if name == "cubic":
        alpha = 10.0 / (7.0 * np.pi * h**2) if dim == 2 else 1.0 / (np.pi * h**3)
        if q <= 1.0:
            return alpha / h * (-3.0 * q + 2.25 * q**2)
        if q <= 2.0:
            return alpha / h * (-0.75 * (2.0 - q) ** 2)
        return 0.0
    alpha = 7.0 / (4.0 * np.pi * h**2) if dim == 2 else 21.0 / (16.0 * np.pi * h**3)
    return alpha / h * (-5.0 * q * (1.0 - 0.5 * q) ** 3) if q <= 2.0 else 0.0


def random_separations(rng, n, dim, rmin, rmax):
    d = rng.normal(size=(n, dim))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return d * rng.uniform(rmin, rmax, size=(n, 1))


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("dim", DIMS)
@pytest.mark.parametrize("h", [1.0, 0.37, 2.5e-5])
def test_unit_integral_radial_quadrature(name, dim, h):
    K = get_kernel(name)
    shell = 2 * np.pi if dim == 2 else 4 * np.pi
    val, _ = integrate.quad(lambda r: shell * r ** (dim - 1) * float(K.w(r, h, dim)), 0.0, 2.0 * h,
                            points=[h], epsabs=1e-13, epsrel=1e-13, limit=200)
    assert abs(val - 1.0) < 1e-8


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("dim", DIMS)
def test_matches_plain_scalar_formula(name, dim):
    K = get_kernel(name)
    rng = np.random.default_rng(0)
    q = np.concatenate([np.linspace(0.0, 3.0, 601), rng.uniform(0, 3, 400),
                        [0.0, 1.0, 2.0, 1 - 1e-13, 1 + 1e-13, 2 - 1e-13, 2 + 1e-13, 10.0]])
    for h in (1.0, 0.013, 4.2):
        r = q * h
        w_ref = np.array([w_plain(name, ri, h, dim) for ri in r])
        dw_ref = np.array([dw_dr_plain(name, ri, h, dim) for ri in r])
        np.testing.assert_allclose(K.w(r, h, dim), w_ref, rtol=1e-13, atol=1e-15 * w_ref.max())
        np.testing.assert_allclose(K.dw_dr(r, h, dim), dw_ref, rtol=1e-13, atol=1e-15 * np.abs(dw_ref).max())


def test_known_values():
    # peak values alpha_d f(0) and the joint q = 1 (f = 1/4), hand-computed
    c, w = CubicSpline(), WendlandC2()
    assert c.w(0.0, 1.0, 2) == pytest.approx(10 / (7 * np.pi))
    assert c.w(1.0, 1.0, 3) == pytest.approx(0.25 / np.pi)
    assert c.dw_dr(1.0, 1.0, 3) == pytest.approx(-0.75 / np.pi)
    assert w.w(0.0, 1.0, 3) == pytest.approx(21 / (16 * np.pi))
    assert w.w(1.0, 2.0, 2) == pytest.approx(7 / (4 * np.pi * 4) * 0.75**4 * 2.0)   # q = 1/2
    assert w.dw_dr(1.0, 1.0, 2) == pytest.approx(7 / (4 * np.pi) * (-5.0 / 8.0))


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("dim", DIMS)
def test_gradient_matches_finite_differences(name, dim):
    K = get_kernel(name)
    rng = np.random.default_rng(42 + dim)
    h = 0.9
    x = random_separations(rng, 400, dim, 0.01 * h, 2.3 * h)
    g = K.grad(x, h, dim)
    eps = 1e-5 * h
    g_fd = np.empty_like(x)
    for k in range(dim):
        e = np.zeros(dim)
        e[k] = eps
        g_fd[:, k] = (K.w(np.linalg.norm(x + e, axis=1), h, dim)
                      - K.w(np.linalg.norm(x - e, axis=1), h, dim)) / (2 * eps)
    assert np.max(np.abs(g - g_fd)) < 1e-7 * np.max(np.abs(g))
    # and the radial derivative against FD in r
    r = np.linspace(0.01, 2.2, 300) * h
    dw_fd = (K.w(r + eps, h, dim) - K.w(r - eps, h, dim)) / (2 * eps)
    assert np.max(np.abs(K.dw_dr(r, h, dim) - dw_fd)) < 1e-7 * np.max(np.abs(dw_fd))


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("dim", DIMS)
def test_gradient_antisymmetric_and_points_to_neighbour(name, dim):
    K = get_kernel(name)
    x = random_separations(np.random.default_rng(7), 100, dim, 0.05, 1.95)   # x_ij, h = 1
    g = K.grad(x, 1.0, dim)
    np.testing.assert_array_equal(K.grad(-x, 1.0, dim), -g)
    # grad_i W(x_ij) is anti-parallel to x_ij = x_i - x_j: it points from i towards j
    cosang = np.einsum("pk,pk->p", g, x) / (np.linalg.norm(g, axis=1) * np.linalg.norm(x, axis=1))
    np.testing.assert_allclose(cosang, -1.0, atol=1e-12)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("dim", DIMS)
def test_compact_support(name, dim):
    K = get_kernel(name)
    h = 1.7
    r = np.concatenate([[2 * h], np.linspace(2 * h, 6 * h, 500)])
    assert np.all(K.w(r, h, dim) == 0.0)
    assert np.all(K.dw_dr(r, h, dim) == 0.0)
    assert np.all(K.dw_dr_over_r(r, h, dim) == 0.0)
    x = random_separations(np.random.default_rng(3), 200, dim, 2 * h, 6 * h)
    assert np.all(K.grad(x, h, dim) == 0.0)
    # and strictly positive / decreasing inside
    r_in = np.linspace(0.0, 2 * h, 801)[:-1]
    assert np.all(K.w(r_in, h, dim) > 0.0)
    assert np.all(K.dw_dr(r_in[1:], h, dim) < 0.0)


@pytest.mark.parametrize("name, limit", [("cubic", -3.0), ("wendland", -5.0)])
@pytest.mark.parametrize("dim", DIMS)
def test_dw_dr_over_r_at_zero_and_near_q1(name, limit, dim):
    K = get_kernel(name)
    h = 0.6
    at0 = K.dw_dr_over_r(np.array([0.0]), h, dim)[0]
    assert np.isfinite(at0)
    assert at0 == pytest.approx(K.alpha(h, dim) / h**2 * limit, rel=1e-14)
    # continuous at 0: the ratio for tiny r approaches the limit
    tiny = np.array([1e-14, 1e-10, 1e-7]) * h
    np.testing.assert_allclose(K.dw_dr_over_r(tiny, h, dim), at0, rtol=1e-6)
    # a particle with itself: zero gradient, no nan
    g0 = K.grad(np.zeros((3, dim)), h, dim)
    assert np.all(g0 == 0.0)
    # away from 0 it equals dW/dr / r, including across the cubic's joint q = 1 (r = h) and at q = 2
    r = h * np.array([1e-3, 0.5, 1 - 1e-9, 1.0, 1 + 1e-9, 1.5, 2 - 1e-9, 2.0])
    np.testing.assert_allclose(K.dw_dr_over_r(r, h, dim), K.dw_dr(r, h, dim) / r, rtol=1e-12, atol=1e-300)
    assert np.all(np.isfinite(K.dw_dr_over_r(r, h, dim)))
    # continuous across q = 1
    left, right = K.dw_dr_over_r(h * np.array([1 - 1e-10, 1 + 1e-10]), h, dim)
    assert left == pytest.approx(right, rel=1e-8)


def test_get_kernel():
    assert get_kernel("cubic") is KERNELS["cubic"] and isinstance(get_kernel("cubic"), CubicSpline)
    assert isinstance(get_kernel("wendland"), WendlandC2)
    with pytest.raises(ValueError, match="quintic_spline"):
        get_kernel("quintic_spline")


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("dim", [0, 1, 4])
def test_bad_dimension_raises(name, dim):
    K = get_kernel(name)
    for call in (lambda: K.alpha(1.0, dim), lambda: K.w(0.5, 1.0, dim), lambda: K.dw_dr(0.5, 1.0, dim),
                 lambda: K.dw_dr_over_r(0.5, 1.0, dim), lambda: K.grad(np.ones((2, 2)), 1.0, dim)):
        with pytest.raises(ValueError, match="dim"):
            call()


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("dim", DIMS)
@pytest.mark.parametrize("hdp", [1.2, 1.5, 2.0])
def test_lattice_partition_of_unity_interior(name, dim, hdp):
    """Sum_j V_j W_ij within 2 % of 1 and Sum_j V_j grad W_ij = 0 for a particle inside a perfect lattice."""
    K = get_kernel(name)
    n = int(np.ceil(2 * hdp)) + 1
    g = np.arange(-n, n + 1, dtype=float)
    xj = np.stack(np.meshgrid(*([g] * dim), indexing="ij"), axis=-1).reshape(-1, dim)   # dp = 1, i at 0
    s_w = K.w(np.linalg.norm(xj, axis=1), hdp, dim).sum()
    s_g = K.grad(-xj, hdp, dim).sum(axis=0)
    assert abs(s_w - 1.0) < 0.02
    assert s_w != 1.0                      # it is a sum, not an integral: not exactly one
    assert np.all(np.abs(s_g) * hdp < 1e-12)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("dim", DIMS)
def test_fused_value_and_gradient_match_the_separate_ones(name, dim):
    """w_and_dw_dr_over_r (one pass, what ESPH uses) equals w and dw_dr_over_r to round-off, q = 0 included."""
    k, h = get_kernel(name), 0.7
    r = np.concatenate([[0.0, 1e-14, 1e-6], np.linspace(0.0, 2.6 * h, 1001)])
    w, g = k.w_and_dw_dr_over_r(r, h, dim)
    assert np.allclose(w, k.w(r, h, dim), rtol=1e-13, atol=1e-14 * k.w(0.0, h, dim))
    ref = k.dw_dr_over_r(r, h, dim)
    nonzero = r > 1e-9
    assert np.allclose(g[nonzero], ref[nonzero], rtol=1e-9, atol=1e-12 * np.abs(ref).max())
    assert np.all(np.isfinite(g))
    assert np.all(w[r >= 2 * h] == 0.0) and np.all(g[r >= 2 * h] == 0.0)
