"""Boundaries that a scene may need: symmetry planes (mirror ghosts), a rigid frictionless wall, rigid bodies
(tools) of prescribed velocity and clamps.

The paper does not say how its Taylor bar meets the wall or whether it uses symmetry; these are the standard
choices, stated here and in chapter 06.

**Symmetry plane** x_a = 0 (the body on the side x_a > 0), imposed with mirror ghost particles (Libersky et al.
1993, "High strain Lagrangian hydrodynamics", J. Comput. Phys. 109, 67; the usual SPH symmetry condition).
Every particle within ``cutoff`` of the plane gets an image with

    x_g = R x_s,  v_g = R v_s,  S_g = R S_s R,  F_g = R F_s R,  m_g = m_s, rho_g = rho_s, ...

R = diag(+-1) flipping the axis of the plane. With two planes (a quarter model) the particles near both
planes also get the image through the edge (R flips both axes). The ghosts take part in the SPH sums of the real
particles exactly as the missing half (quarter) of the body would; their own rates are not used. The
condition this gives is the symmetry one: zero normal velocity and zero shear traction on the plane, with the
normal traction the other half would exert.

**Rigid frictionless wall** x_a = c (the body on the side x_a > c), imposed as a unilateral kinematic
constraint: a particle that moves towards the wall and whose centre is, or within the next step would be,
closer than half a spacing to it (x_a + dt v_a < c + gap, gap = dp / 2, so that the body's face -- centres
minus half a spacing -- touches the wall) gets v_a <- 0. Every particle is kept at x_a >= c + gap (a position
projection, which only acts on particles in contact). The tangential velocity is left free (no friction) and
the velocity of a particle moving away is left alone, so the body can rebound. The impulse the
wall gives is the sum of m (v_a,after - v_a,before).
It is the simplest thing that a Taylor impact needs; tools are :class:`RigidBody` particles (below).

**Rigid body** (the paper's tools, Section 2.4): particles of their own body id (``State.body``) that move
with a prescribed velocity V,

    x_i(t) = x_i(0) + V t,   v_i = V,

made only of the layers that can touch the workpiece. They carry no constitutive stress. How they act on the
workpiece is the method's: in ESPH they are ordinary SPH neighbours (their density is integrated by the
continuity equation, Eq. 10, and floored at rho0, so their own pressure K (rho/rho0 - 1) is never negative;
a workpiece particle in tension still pulls on them through its own stress term of Eq. 11); in TLSPH they are partners of the pinball contact (:mod:`refsph.contact`). The solvers record
the force the rest of the system exerts on each body at every step.

**Clamp** (the fixed left side of the pressing block): particles *of the deformable body* whose velocity is
held at zero (an essential boundary condition, as on the nodes of a finite-element model). They keep their
constitutive response; only their motion is prescribed. The force that holds them is recorded like a tool's.
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from .state import State

__all__ = ["MirrorPlanes", "Ghosts", "RigidWall", "RigidBody", "Clamp"]


@dataclass(frozen=True)
class Ghosts:
    """Mirror images of some real particles: ``src`` (index of each ghost's source) and ``sign`` (R as a
    (N_g, d) array of +-1). Extended arrays are [real; ghosts]."""

    n_real: int
    src: np.ndarray
    sign: np.ndarray

    @property
    def n(self) -> int:
        return len(self.src)

    def vectors(self, a: np.ndarray) -> np.ndarray:
        """R a_s for each ghost (N_g, d)."""
        return a[self.src] * self.sign

    def tensors(self, T: np.ndarray) -> np.ndarray:
        """R T_s R for each ghost (N_g, d, d)."""
        return T[self.src] * self.sign[:, :, None] * self.sign[:, None, :]

    def scalars(self, s: np.ndarray) -> np.ndarray:
        return s[self.src]

    def extend_vectors(self, a: np.ndarray) -> np.ndarray:
        return np.concatenate([a, self.vectors(a)])

    def extend_tensors(self, T: np.ndarray) -> np.ndarray:
        return np.concatenate([np.asarray(T), self.tensors(np.asarray(T))])

    def extend_scalars(self, s: np.ndarray) -> np.ndarray:
        return np.concatenate([s, self.scalars(s)])

    def extend_state(self, state: State, constant: tuple | None = None) -> State:
        """The state of real particles and ghosts (mechanical fields only; thermal fields are per particle
        and never summed over neighbours).

        ``constant``: (m, X, V0) already extended -- the fields that do not change while these ghosts are in
        use. A solver passes the same arrays every call, so that what it caches per array (the TLSPH momentum
        sum's sum_j m_j grad W) stays valid; without it they are extended here."""
        if constant is None:
            constant = self.extend_constant(state)
        m, X, V0 = constant
        return State(x=self.extend_vectors(state.x), v=self.extend_vectors(state.v), m=m,
                     rho=self.extend_scalars(state.rho), S=self.extend_tensors(state.S),
                     S_zz=self.extend_scalars(state.S_zz), X=X, V0=V0, t=state.t)

    def extend_constant(self, state: State) -> tuple:
        """(m, X, V0) of real particles and ghosts, for :meth:`extend_state`."""
        return self.extend_scalars(state.m), self.extend_vectors(state.X), self.extend_scalars(state.V0)


@dataclass(frozen=True)
class MirrorPlanes:
    """Symmetry planes x_a = 0 for each a in ``axes`` (the body lies at x_a > 0)."""

    axes: tuple[int, ...]

    def __post_init__(self):
        if len(set(self.axes)) != len(self.axes):
            raise ValueError(f"symmetry axes must be distinct, got {self.axes!r}")

    def check(self, d: int) -> None:
        """Every axis exists in d dimensions (ValueError otherwise)."""
        for a in self.axes:
            if not 0 <= a < d:
                raise ValueError(f"symmetry axis {a} does not exist in {d}D")

    def ghosts(self, x: np.ndarray, cutoff: float) -> Ghosts:
        """Images of every particle within ``cutoff`` of a plane (and of the edges/corner where planes meet)."""
        n, d = x.shape
        self.check(d)
        if n:
            bad = np.flatnonzero(np.any(x[:, list(self.axes)] <= 0, axis=1))
            if len(bad):
                raise ValueError(f"particle {bad[0]} lies on or behind a symmetry plane (x_a <= 0 for an axis in "
                                 f"{self.axes}); the body must lie strictly on the side x_a > 0")
        srcs, signs = [], []
        for k in range(1, len(self.axes) + 1):
            for subset in combinations(self.axes, k):
                near = np.all(x[:, list(subset)] < cutoff, axis=1)
                idx = np.flatnonzero(near)
                sign = np.ones((len(idx), d))
                sign[:, list(subset)] = -1.0
                srcs.append(idx)
                signs.append(sign)
        src = np.concatenate(srcs) if srcs else np.zeros(0, dtype=np.intp)
        sign = np.concatenate(signs) if signs else np.ones((0, d))
        return Ghosts(n_real=n, src=src.astype(np.intp), sign=sign)


@dataclass(frozen=True)
class RigidWall:
    """Rigid frictionless wall x_axis = position, body on the side x_axis > position; ``gap``: half a spacing."""

    axis: int
    position: float
    gap: float

    def __post_init__(self):
        if isinstance(self.axis, bool) or not isinstance(self.axis, (int, np.integer)) or self.axis < 0:
            raise ValueError(f"wall axis must be a non-negative integer, got {self.axis!r}")
        if not np.isfinite(self.position):
            raise ValueError(f"wall position must be finite, got {self.position!r}")
        if not (np.isfinite(self.gap) and self.gap > 0):
            raise ValueError(f"wall gap must be positive, got {self.gap!r}")

    def check(self, d: int) -> None:
        """The wall's axis exists in d dimensions (ValueError otherwise)."""
        if self.axis >= d:
            raise ValueError(f"wall axis {self.axis} does not exist in {d}D")

    def apply(self, state: State, dt: float) -> float:
        """Unilateral constraint in place on ``state`` (positions and velocities); returns the impulse the wall
        gave along +axis (per unit thickness in 2D).

        A particle is stopped (v_a <- 0) if it moves towards the wall and would be closer than the gap within
        ``dt`` (x_a + dt v_a < c + gap): testing the position alone misses a particle that sits a rounding
        error above the gap while its velocity keeps growing towards the wall."""
        a = self.axis
        z0 = self.position + self.gap
        hit = np.flatnonzero((state.v[:, a] < 0.0) & (state.x[:, a] + dt * state.v[:, a] < z0))
        impulse = float(-np.sum(state.m[hit] * state.v[hit, a]))
        state.v[hit, a] = 0.0
        state.x[:, a] = np.maximum(state.x[:, a], z0)
        return impulse


@dataclass(frozen=True)
class RigidBody:
    """A rigid body of prescribed translation: the particles with ``State.body == body`` move with
    ``velocity`` (m/s, a d-vector): x(t) = x(0) + V t. ``body`` must be a positive id (0 is the workpiece);
    its particles must come after every deformable particle in the state (the solvers work on the leading
    deformable rows as one block)."""

    name: str
    body: int
    velocity: tuple

    def __post_init__(self):
        if isinstance(self.body, bool) or not isinstance(self.body, (int, np.integer)) or self.body < 1:
            raise ValueError(f"rigid body id must be a positive integer (0 is the workpiece), got {self.body!r}")
        v = np.asarray(self.velocity, dtype=float)
        if v.ndim != 1 or not np.all(np.isfinite(v)):
            raise ValueError(f"rigid body velocity must be a finite vector, got {self.velocity!r}")
        object.__setattr__(self, "velocity", tuple(float(c) for c in v))

    def check(self, d: int) -> None:
        if len(self.velocity) != d:
            raise ValueError(f"rigid body {self.name!r}: velocity has {len(self.velocity)} components, "
                             f"the state is {d}D")


@dataclass(frozen=True, eq=False)
class Clamp:
    """Particles ``index`` of a deformable body held at rest (v = 0, x fixed): a fixed boundary."""

    name: str
    index: np.ndarray

    def __post_init__(self):
        idx = np.asarray(self.index)
        if idx.ndim != 1 or not np.issubdtype(idx.dtype, np.integer) or len(idx) == 0 or idx.min() < 0:
            raise ValueError(f"clamp {self.name!r}: index must be a non-empty 1-D array of non-negative integers")
        object.__setattr__(self, "index", np.unique(idx).astype(np.intp))

    def to_dict(self) -> dict:
        return dict(name=self.name, n_particles=int(len(self.index)))
