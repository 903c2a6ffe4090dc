"""Symmetry planes (mirror ghosts) and the rigid frictionless wall."""
import numpy as np
import pytest

from refsph.boundaries import MirrorPlanes, RigidWall
from refsph.scenes import Numerics, Setup, lattice
from refsph.simulate import run, simulate
from refsph.state import make_state
from refsph.scenes.taylor import taylor_material


def test_mirror_ghosts_quarter():
    x = np.array([[0.1, 0.1, 1.0], [0.1, 5.0, 1.0], [5.0, 5.0, 1.0]])
    g = MirrorPlanes((0, 1)).ghosts(x, cutoff=1.0)
    # particle 0 is near both planes: images through x=0, y=0 and the edge; particle 1 only through x=0
    got = sorted(map(tuple, np.round(g.vectors(x), 12)))
    want = sorted([(-0.1, 0.1, 1.0), (0.1, -0.1, 1.0), (-0.1, -0.1, 1.0), (-0.1, 5.0, 1.0)])
    assert got == want
    S = np.arange(27.0).reshape(3, 3, 3)
    Sg = g.tensors(S)
    for k in range(g.n):
        R = np.diag(g.sign[k])
        assert np.array_equal(Sg[k], R @ S[g.src[k]] @ R)
    with pytest.raises(ValueError, match="behind a symmetry plane"):
        MirrorPlanes((0,)).ghosts(-x, 1.0)
    with pytest.raises(ValueError, match="on or behind"):
        MirrorPlanes((0,)).ghosts(np.array([[0.0, 1.0, 1.0]]), 1.0)
    with pytest.raises(ValueError, match="gap"):
        RigidWall(axis=1, position=0.0, gap=0.0)
    with pytest.raises(ValueError, match="distinct"):
        MirrorPlanes((0, 0))


def test_wall_is_unilateral():
    x = np.array([[0.0, 0.5], [1.0, 0.5], [2.0, 3.0]])
    v = np.array([[1.0, -2.0], [0.0, 2.0], [0.0, -2.0]])
    s = make_state(x, v, 1000.0, 1.0)
    wall = RigidWall(axis=1, position=0.0, gap=0.5)
    imp = wall.apply(s, dt=0.1)
    assert imp == pytest.approx(2000.0)                          # particle 0 stopped: m * 2
    assert np.array_equal(s.v, [[1.0, 0.0], [0.0, 2.0], [0.0, -2.0]])   # tangential kept; leaving one free


def _block_on_wall(method, v0=10.0):
    mat = taylor_material()
    dp = 0.5e-3
    x = lattice([4e-3, 4e-3], dp)
    v = np.zeros_like(x)
    v[:, 1] = -v0
    state = make_state(x, v, mat.rho0, dp * dp)
    setup = Setup(state=state, material=mat, dp=dp, numerics=Numerics(), t_end=6e-6, n_snapshots=1,
                  walls=(RigidWall(axis=1, position=0.0, gap=0.5 * dp),))
    return setup


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_elastic_block_bounces_off_wall(method):
    """Impulse from the wall = the body's change of momentum; nothing passes the wall; it bounces."""
    setup = _block_on_wall(method)
    P0 = np.sum(setup.state.m * setup.state.v[:, 1])
    res = simulate(setup, method, progress=False)
    s = res.state
    P1 = np.sum(s.m * s.v[:, 1])
    imp = res.summary["diagnostics"]["wall_impulse"][0]
    assert imp == pytest.approx(P1 - P0, rel=1e-10)
    assert np.min(s.x[:, 1]) >= 0.5 * setup.dp - 1e-15
    assert P1 > 0.5 * abs(P0)                                    # it has bounced (4 mm block: 2 transits ~1.4 us)


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_symmetry_plane_equals_whole_body(method):
    """2D Taylor bar: the half model with mirror ghosts reproduces the whole body."""
    half = run("taylor", method, dim=2, dp=0.5e-3, t_end=8e-6, progress=False, options=dict(symmetry=True))
    whole = run("taylor", method, dim=2, dp=0.5e-3, t_end=8e-6, progress=False, options=dict(symmetry=False))
    xh, xw = half.state.x, whole.state.x
    right = whole.setup.state.x[:, 0] > 0                       # the whole body's right half, by initial position

    def order(X):                                               # match particles by their initial positions
        return np.lexsort((X[:, 1], X[:, 0]))
    ih = order(half.setup.state.x)
    iw = order(whole.setup.state.x[right])
    assert np.allclose(xh[ih], xw[right][iw], rtol=0, atol=1e-9)
    assert half.state.eps_p.max() > 0.05
    assert np.allclose(half.state.eps_p[ih], whole.state.eps_p[right][iw], rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_quarter_model_equals_whole_body_3d(method):
    """3D: two symmetry planes (plane and edge ghosts), the wall, plasticity and -- for TLSPH -- reference
    updates forced by a low threshold: the quarter reproduces the whole block particle by particle."""
    from refsph.scenes.taylor import taylor_johnson_cook
    mat = taylor_material()
    jc = taylor_johnson_cook(1293.0, 1.0)
    dp = 1e-3
    q = lattice([4e-3, 4e-3, 6e-3], dp)
    w = q.copy()
    w = np.concatenate([w * s for s in ([1, 1, 1], [-1, 1, 1], [1, -1, 1], [-1, -1, 1])])

    def setup(x, mirror):
        v = np.zeros_like(x)
        v[:, 2] = -181.0
        st = make_state(x, v, mat.rho0, dp**3, T0=293.0)
        return Setup(state=st, material=mat, dp=dp, numerics=Numerics(ref_update_strain=0.02), t_end=3e-6,
                     n_snapshots=1, strength=jc, mirror=mirror,
                     walls=(RigidWall(axis=2, position=0.0, gap=0.5 * dp),))
    rq = simulate(setup(q, MirrorPlanes((0, 1))), method, progress=False)
    rw = simulate(setup(w, None), method, progress=False)
    n = len(q)
    assert np.allclose(rq.state.x, rw.state.x[:n], rtol=0, atol=1e-12)
    assert rq.state.eps_p.max() > 0.01
    assert np.allclose(rq.state.eps_p, rw.state.eps_p[:n], rtol=1e-8, atol=1e-12)
    if method == "tlsph":
        assert rq.summary["diagnostics"]["reference_updates"] >= 1
    assert 4 * rq.summary["diagnostics"]["wall_impulse"][0] == pytest.approx(
        rw.summary["diagnostics"]["wall_impulse"][0], rel=1e-9)
