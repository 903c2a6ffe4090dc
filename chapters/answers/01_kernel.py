"""Answer key of chapter 01 (the smoothing kernel).

* answer_1 -- Exercise 1 (HDP from 1.5 to 2.0 and 3.0): the interior neighbour count grows like (h/dp)^2, but
  the kernel sum at the middle of an edge and at a corner of a 2D block gets *smaller*, towards the continuum
  values 1/2 and 1/4: more neighbours do not cure a free surface.
* answer_2 -- Exercise 2 (KERNEL = "wendland"): inside a perfect lattice Wendland misses the partition of unity
  by more than the cubic spline at every h/dp tried, its miss falls steadily as h/dp grows (the cubic spline's
  does not), and its 2D Fourier transform stays positive where the cubic spline's dips below zero.
"""
import numpy as np
from scipy import integrate, special

from refsph.kernels import get_kernel
from refsph.neighbours import find_pairs, scatter_add


def interior_sum(K, hdp, dim=2):
    """Sum_j V_j W_ij and the neighbour count for a particle inside an infinite square lattice (dp = 1)."""
    n = int(np.ceil(2 * hdp)) + 1
    g = np.arange(-n, n + 1)
    r = np.linalg.norm(np.stack(np.meshgrid(*([g] * dim), indexing="ij"), axis=-1).reshape(-1, dim), axis=1)
    return K.w(r, hdp, dim).sum(), int(np.count_nonzero((r > 0) & (r < 2 * hdp * (1 - 1e-12))))


def block_sums(K, hdp, nx=24, ny=16):
    """Sum_j V_j W_ij at the middle of the bottom edge and at a corner of an nx x ny block (dp = 1)."""
    gx, gy = np.meshgrid(np.arange(nx, dtype=float), np.arange(ny, dtype=float), indexing="ij")
    x = np.column_stack([gx.ravel(), gy.ravel()])
    I, J = find_pairs(x, 2 * hdp)
    Wij = K.w(np.linalg.norm(x[I] - x[J], axis=1), hdp, 2)
    s_w = K.w(0.0, hdp, 2) + scatter_add(I, Wij, len(x)) + scatter_add(J, Wij, len(x))
    edge = np.flatnonzero((x[:, 0] == nx // 2) & (x[:, 1] == 0))[0]
    return s_w[edge], s_w[0]                                    # particle 0 is the corner (0, 0)


def fourier_min_2d(K, kh=np.linspace(0.0, 20.0, 401)):
    r = np.linspace(0.0, 2.0, 2001)
    return integrate.simpson(2 * np.pi * r * K.w(r, 1.0, 2) * special.j0(np.outer(kh, r)), x=r, axis=1).min()


def answer_1():
    cubic = get_kernel("cubic")
    n15 = interior_sum(cubic, 1.5)[1]
    edge15, corner15 = block_sums(cubic, 1.5)
    previous = (edge15, corner15)
    for hdp in (2.0, 3.0):
        n_nb = interior_sum(cubic, hdp)[1]
        edge, corner = block_sums(cubic, hdp)
        assert n_nb > n15 * (hdp / 1.5) ** 2 * 0.7            # many more neighbours, roughly (h/dp)^2
        assert edge < previous[0] and corner < previous[1]      # ... yet the surface sums get worse
        assert edge > 0.5 and corner > 0.25                     # ... towards the continuum values 1/2 and 1/4
        previous = (edge, corner)
    assert previous[0] < edge15 - 0.05                          # clearly further from one at h/dp = 3


def answer_2():
    cubic, wendland = get_kernel("cubic"), get_kernel("wendland")
    hdps = (1.2, 1.5, 2.0, 3.0)
    err_c = [abs(interior_sum(cubic, hdp)[0] - 1) for hdp in hdps]
    err_w = [abs(interior_sum(wendland, hdp)[0] - 1) for hdp in hdps]
    assert all(w > c for w, c in zip(err_w, err_c))             # Wendland misses one by more ...
    assert err_w[0] > 10 * err_c[0]                             # ... much more at small h/dp
    assert all(a > b for a, b in zip(err_w[:-1], err_w[1:]))    # ... and improves steadily with h/dp
    assert not all(a > b for a, b in zip(err_c[:-1], err_c[1:]))  # the cubic spline's error jumps about
    assert fourier_min_2d(wendland) > 0.0 > fourier_min_2d(cubic)
