"""What the scenes share: lattices of particles, the materials of the paper's tables, time averages of force
histories, energies and momentum. Every scene module imports what it needs from here (and nothing from another
scene).
"""
from __future__ import annotations

import numpy as np

from ..material import ElasticMaterial, eos_pressure, von_mises
from ..neighbours import find_pairs
from ..paper_data import AISI4340_TABLE3
from ..penalty import RoundedPolygon
from ..plasticity import JohnsonCook
from ..state import State

__all__ = ["TOOL_BODY", "N_FORCE_BINS", "lattice", "block_lattice", "aisi4340_material", "aisi4340_johnson_cook",
           "binned_mean", "time_mean", "jittered", "kinetic_energy", "elastic_energy", "linear_momentum",
           "min_pair_distance", "zero_crossings", "disc", "annulus", "angular_momentum", "n_fragments", "von_mises_max"]

TOOL_BODY = 1           # body id of the tool in the scenes with one (0 is the workpiece)
N_FORCE_BINS = 400      # force histories in summary.json: time averages over this many equal bins


MAX_PARTICLES = 10_000_000   # a lattice larger than this is refused before it is allocated (pure NumPy: ~1 kB each)


def check_particle_count(*counts, dp: float | None = None) -> None:
    """Refuse (ValueError) a lattice of prod(counts) points above ``MAX_PARTICLES`` before any array is made (a
    spacing of 1e-8 m would otherwise ask for terabytes)."""
    n = 1
    for c in counts:
        n *= max(int(c), 0)
    if n > MAX_PARTICLES:
        raise ValueError(f"{'the spacing dp = ' + repr(dp) + ' m' if dp is not None else 'this resolution'} would "
                         f"make {n:.3g} lattice points, more than refsph builds ({MAX_PARTICLES:.0e}; a pure-NumPy "
                         "code needs about 1 kB per particle): choose a larger dp")


# ----------------------------------------------------------------------------- particles and materials
def lattice(lengths, dp: float) -> np.ndarray:
    """Particle centres of a box [0, L_0] x ... on a square/cubic lattice of spacing dp (cell centres)."""
    axes = []
    for L in lengths:
        n = int(round(L / dp))
        if n < 1:
            raise ValueError(f"spacing dp={dp!r} is larger than the body ({L!r} m)")
        axes.append(n)
    check_particle_count(*axes, dp=dp)
    axes = [(np.arange(n) + 0.5) * dp for n in axes]
    grids = np.meshgrid(*axes, indexing="ij")
    return np.stack([g.ravel() for g in grids], axis=1)


def block_lattice(nx: int, ny: int, dx: float, dy: float):
    """Cell centres ((i + 1/2) dx, (j + 1/2) dy) of an nx x ny block, particle k = i ny + j (column i, row j),
    with the (i, j) of every particle: the layout of the pressing block and of the cutting workpiece."""
    check_particle_count(nx, ny, dp=min(dx, dy))
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    i, j = i.ravel(), j.ravel()
    return np.stack([(i + 0.5) * dx, (j + 0.5) * dy], axis=1), i, j


MAX_JITTER = 0.1        # a perturbed run moves particles by at most this many spacings


def jittered(x: np.ndarray, jitter: float, spacing, seed: int) -> np.ndarray:
    """``x`` with every coordinate moved at random (uniform, random seed ``seed``) by up to ``jitter`` spacings
    (``spacing``: one number or one per axis): a perturbed run, for the run-to-run scatter of a scene's metrics;
    ``x`` itself where jitter is 0. ValueError unless 0 <= jitter <= MAX_JITTER."""
    if not (np.isfinite(jitter) and 0.0 <= jitter <= MAX_JITTER):
        raise ValueError(f"option jitter must lie in [0, {MAX_JITTER}] (units of dx), got {jitter!r}")
    if jitter == 0:
        return x
    return x + float(jitter) * np.asarray(spacing) * np.random.default_rng(int(seed)).uniform(-1.0, 1.0, x.shape)


def aisi4340_material() -> ElasticMaterial:
    """Table 3: rho = 7830 kg/m^3, E = 207 GPa, nu = 0.3 (the workpiece of the pressing and the cutting, and the
    elastic test scenes)."""
    t = AISI4340_TABLE3
    return ElasticMaterial(rho0=t["rho"], E=t["E_Pa"], nu=t["nu"])


def box_outline(x: np.ndarray, dx: float, dy: float) -> RoundedPolygon:
    """The exact outline of a rectangular tool made of lattice particles x (a block, or only its surface layers),
    for the penalty contact (``Numerics.contact = 'penalty'``): the sharp rectangle the particles fill (their faces
    dx/2 and dy/2 beyond the outer centres), relative to the particles' centroid (``RigidBody.shape``)."""
    lo, hi = x.min(axis=0) - [0.5 * dx, 0.5 * dy], x.max(axis=0) + [0.5 * dx, 0.5 * dy]
    rect = [[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]]
    return RoundedPolygon.from_polygon(rect, 0.0, x.mean(axis=0))


def aisi4340_johnson_cook(eps_dot_0: float, heating: bool = True) -> JohnsonCook:
    """Table 3 Johnson-Cook constants, chi = 0.9 (Section 2.3), the given reference strain rate (not printed);
    ``heating``: plastic work heats the material (Eq. (28); False: isothermal)."""
    t = AISI4340_TABLE3
    return JohnsonCook(A=t["A_Pa"], B=t["B_Pa"], n=t["n"], C=t["C"], m=t["m"], eps_dot_0=float(eps_dot_0),
                       T_room=t["T_room_K"], T_melt=t["T_melt_K"], cp=t["cp_J_kgK"], chi=t["taylor_quinney"],
                       heating=heating)


# ----------------------------------------------------------------------------- time averages
def binned_mean(t, dt, f, t_end, n_bins):
    """Time average of a per-step force over equal time bins (each step weighted by its size dt, put in the
    bin of its midpoint t): (bin centres, means) of the bins that hold a step."""
    edges = np.linspace(0.0, t_end, n_bins + 1)
    k = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, n_bins - 1)
    w = np.bincount(k, weights=dt, minlength=n_bins)
    s = np.bincount(k, weights=f * dt, minlength=n_bins)
    ok = w > 0
    return 0.5 * (edges[1:] + edges[:-1])[ok], s[ok] / w[ok]


def time_mean(t, dt, f, t_from):
    """(1 / duration) * integral of f dt over the steps whose midpoint lies after t_from."""
    sel = t > t_from
    return float(np.sum(f[sel] * dt[sel]) / np.sum(dt[sel])) if sel.any() else float("nan")


def zero_crossings(t: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Times where a(t) changes sign (linear interpolation between samples)."""
    s = np.sign(a)
    k = np.flatnonzero((s[1:] != s[:-1]) & (s[1:] != 0))
    return t[k] - a[k] * (t[k + 1] - t[k]) / (a[k + 1] - a[k])


# ----------------------------------------------------------------------------- energies and momentum
def kinetic_energy(state: State, rows=slice(None)) -> float:
    """sum_i m_i |v_i|^2 / 2 over ``rows`` (default: every particle)."""
    m, v = state.m[rows], state.v[rows]
    return float(0.5 * np.sum(m * np.einsum("ik,ik->i", v, v)))


def elastic_energy(state: State, mat: ElasticMaterial) -> float:
    """sum_i V_i (p_i^2 / (2K) + s_i:s_i / (4G)), V = m / rho; small-strain energy of the stress state."""
    p = eos_pressure(state.rho, mat.rho0, mat.K)
    ss = np.einsum("nab,nab->n", state.S, state.S)
    if state.dim == 2:
        ss = ss + state.S_zz**2
    V = state.m / state.rho
    return float(np.sum(V * (p * p / (2.0 * mat.K) + ss / (4.0 * mat.G))))


def linear_momentum(state: State) -> np.ndarray:
    """sum_i m_i v_i."""
    return np.sum(state.m[:, None] * state.v, axis=0)


def min_pair_distance(x: np.ndarray, radius: float) -> float:
    """The smallest distance between two particles closer than ``radius`` (inf if none)."""
    I, J = find_pairs(x, radius)
    if len(I) == 0:
        return float("inf")
    d = x[I] - x[J]
    return float(np.sqrt(np.min(np.einsum("pk,pk->p", d, d))))


# ----------------------------------------------------------------------------- shapes and survival measures
def disc(radius: float, dp: float, centre=(0.0, 0.0)) -> np.ndarray:
    """Particle centres of a 2D disc: the square lattice of spacing dp (a node at the centre) cut to r <= radius
    - dp/2, so that the cells (dp x dp) fill it and its edge is half a spacing outside the outer centres."""
    return annulus(0.0, radius, dp, centre)


def annulus(r_inner: float, r_outer: float, dp: float, centre=(0.0, 0.0)) -> np.ndarray:
    """Particle centres of a 2D ring r_inner <= r <= r_outer on the square lattice of spacing dp centred at
    ``centre`` (Gray, Monaghan & Swift 2001 build their rings this way): centres with r_inner + dp/2 <= r <=
    r_outer - dp/2 (r_inner = 0: every centre from the middle out)."""
    if not (0 <= r_inner < r_outer and dp > 0):
        raise ValueError(f"need 0 <= r_inner < r_outer and dp > 0, got {r_inner!r}, {r_outer!r}, {dp!r}")
    n = int(np.ceil(r_outer / dp)) + 1
    check_particle_count(2 * n + 1, 2 * n + 1, dp=dp)
    a = np.arange(-n, n + 1) * dp
    X, Y = np.meshgrid(a, a, indexing="ij")
    pts = np.stack([X.ravel(), Y.ravel()], axis=1)
    r = np.hypot(pts[:, 0], pts[:, 1])
    lo = r_inner + 0.5 * dp if r_inner > 0 else -1.0
    keep = (r >= lo) & (r <= r_outer - 0.5 * dp + 1e-12 * dp)
    return pts[keep] + np.asarray(centre, dtype=float)


def angular_momentum(state: State, rows=slice(None), about=None) -> np.ndarray | float:
    """sum_i m_i (x_i - c) x v_i about ``about`` (default: the rows' centre of mass): a scalar in 2D (the z
    component), a vector in 3D."""
    m, x, v = state.m[rows], state.x[rows], state.v[rows]
    c = np.sum(m[:, None] * x, axis=0) / np.sum(m) if about is None else np.asarray(about, dtype=float)
    r = x - c
    if state.dim == 2:
        return float(np.sum(m * (r[:, 0] * v[:, 1] - r[:, 1] * v[:, 0])))
    return np.sum(m[:, None] * np.cross(r, v), axis=0)


def n_fragments(x: np.ndarray, bond: float, min_size: int = 1) -> int:
    """The number of connected pieces: particles closer than ``bond`` (e.g. 1.5 dp) belong to one piece; pieces of
    fewer than ``min_size`` particles are not counted (1: every loose particle is a fragment)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(x)
    if n == 0:
        return 0
    I, J = find_pairs(x, bond)
    graph = coo_matrix((np.ones(len(I)), (I, J)), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    sizes = np.bincount(labels)
    return int(np.sum(sizes >= min_size))


def von_mises_max(state: State) -> float:
    """The largest von Mises stress sqrt(3 J2) of the state (pressure from the linear EOS does not enter)."""
    return float(np.max(von_mises(state.S, state.S_zz))) if state.n else 0.0
