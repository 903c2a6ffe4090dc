"""Boundaries that a scene may need: symmetry planes (mirror ghosts), a rigid frictionless wall, rigid bodies
(tools) of prescribed motion and clamps, and :class:`Constraints`, which applies the last three in a run and
keeps the reaction log (the force on every tool and clamp at every step).

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
with a prescribed velocity V (and, if given, turn with a prescribed angular velocity, :class:`RigidBody`),

    x_i(t) = x_i(0) + V t,   v_i = V,

made only of the layers that can touch the workpiece. They carry no constitutive stress. How they act on the
workpiece is the method's: in ESPH they are ordinary SPH neighbours (their density is integrated by the
continuity equation, Eq. (10), and floored at rho0, so their own pressure K (rho/rho0 - 1) is never negative;
a workpiece particle in tension still pulls on them through its own stress term of Eq. (11)); in TLSPH they
are partners of the pinball contact (:mod:`refsph.contact`). The solvers record
the force the rest of the system exerts on each body at every step.

**Clamp** (the fixed left side of the pressing block): particles *of the deformable body* whose velocity is
held at zero (an essential boundary condition, as on the nodes of a finite-element model). They keep their
constitutive response; only their motion is prescribed. The force that holds them is recorded like a tool's.
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from .state import Rates, State

__all__ = ["MirrorPlanes", "Ghosts", "RigidWall", "RigidBody", "Clamp", "Constraints", "ReactionLog"]


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
    """A rigid body of prescribed motion: the particles with ``State.body == body`` translate with ``velocity``
    V (m/s, a d-vector) and turn with ``angular_velocity`` omega (rad/s; 2D: a number, about +z; 3D: a vector)
    about ``centre`` (the point c0 it turns about at the start; None: the centroid of its particles then):

        c(t) = c0 + V t,   x_i(t) = c(t) + R(omega t) (x_i(0) - c0),   v_i = V + omega x (x_i - c(t)).

    ``body`` must be a positive id (0 is the workpiece); its particles must come after every deformable
    particle in the state (the solvers work on the leading deformable rows as one block) and start with the
    velocity of this motion (:meth:`velocity_at`). ``shape``: its exact boundary for the penalty contact
    (:class:`refsph.penalty.RoundedPolygon`, relative to the centroid of its particles; None: the body is its
    particles, as the pinball contact sees it)."""

    name: str
    body: int
    velocity: tuple
    angular_velocity: float | tuple = 0.0
    centre: tuple | None = None
    shape: object = None

    def __post_init__(self):
        if isinstance(self.body, bool) or not isinstance(self.body, (int, np.integer)) or self.body < 1:
            raise ValueError(f"rigid body id must be a positive integer (0 is the workpiece), got {self.body!r}")
        v = np.asarray(self.velocity, dtype=float)
        if v.ndim != 1 or not np.all(np.isfinite(v)):
            raise ValueError(f"rigid body velocity must be a finite vector, got {self.velocity!r}")
        object.__setattr__(self, "velocity", tuple(float(c) for c in v))
        w = np.asarray(self.angular_velocity, dtype=float)
        if w.ndim > 1 or not np.all(np.isfinite(w)):
            raise ValueError(f"rigid body angular velocity must be a finite number (2D) or vector (3D), "
                             f"got {self.angular_velocity!r}")
        object.__setattr__(self, "angular_velocity", float(w) if w.ndim == 0 else tuple(float(c) for c in w))
        if self.centre is not None:
            c = np.asarray(self.centre, dtype=float)
            if c.ndim != 1 or not np.all(np.isfinite(c)):
                raise ValueError(f"rigid body centre must be a finite point, got {self.centre!r}")
            object.__setattr__(self, "centre", tuple(float(a) for a in c))

    @property
    def rotates(self) -> bool:
        return bool(np.any(np.asarray(self.angular_velocity) != 0.0))

    def check(self, d: int) -> None:
        if len(self.velocity) != d:
            raise ValueError(f"rigid body {self.name!r}: velocity has {len(self.velocity)} components, "
                             f"the state is {d}D")
        w = np.asarray(self.angular_velocity)
        if (d == 2 and w.ndim != 0) or (d == 3 and w.shape not in ((), (3,))) or (d == 3 and w.ndim == 0 and w != 0):
            raise ValueError(f"rigid body {self.name!r}: angular velocity must be a number in 2D (about z) and a "
                             f"3-vector in 3D, got {self.angular_velocity!r}")
        if self.centre is not None and len(self.centre) != d:
            raise ValueError(f"rigid body {self.name!r}: centre has {len(self.centre)} components, the state is {d}D")
        if self.shape is not None and (d != 2 or self.rotates):
            raise ValueError(f"rigid body {self.name!r}: a shape (the penalty contact's geometry) is implemented for "
                             "2D tools that translate")

    def _omega3(self) -> np.ndarray:
        w = np.asarray(self.angular_velocity, dtype=float)
        return np.array([0.0, 0.0, float(w)]) if w.ndim == 0 else w

    def spin(self, r: np.ndarray) -> np.ndarray:
        """omega x r for offsets r (n, d) from the centre."""
        w = self._omega3()
        if r.shape[1] == 2:
            return w[2] * np.stack([-r[:, 1], r[:, 0]], axis=1)
        return np.cross(w, r)

    def velocity_at(self, x: np.ndarray, centre=None) -> np.ndarray:
        """v = V + omega x (x - c) of particles at x (n, d); c: the centre (default ``centre``, else the
        centroid of x). Use it to give the body's particles their starting velocity."""
        x = np.asarray(x, dtype=float)
        c = np.asarray(centre if centre is not None else (self.centre if self.centre is not None
                                                          else x.mean(axis=0)), dtype=float)
        return np.asarray(self.velocity) + self.spin(x - c)

    def start(self, state: State, rows: slice) -> tuple | None:
        """What the closed-form motion needs of the body's rows at the start (None for a body that only
        translates: its velocity is all): (t0, c0, x - c0); ValueError if the rows do not move with the body."""
        x = state.x[rows]
        if not self.rotates:
            start, ok = None, np.all(state.v[rows] == np.asarray(self.velocity))
        else:
            c0 = np.asarray(self.centre) if self.centre is not None else x.mean(axis=0)
            start, v = (state.t, c0, x - c0), self.velocity_at(x, c0)
            ok = np.allclose(state.v[rows], v, rtol=1e-12, atol=1e-12 * np.max(np.abs(v)))
        if not ok:
            raise ValueError(f"rigid body {self.name!r}: its particles must start with its velocity "
                             f"{self.velocity}" + (" turning at " + str(self.angular_velocity) + " rad/s (give them "
                                                   "RigidBody.velocity_at(x))" if self.rotates else ""))
        return start

    def place(self, state: State, rows: slice, start: tuple | None, t: float) -> None:
        """Put the body's ``rows`` of ``state`` where its motion has them at time ``t`` (in place; ``start`` from
        :meth:`start`): a translating body's velocity reset to V (no drift from round-off), a turning body placed
        by the closed form c(t) + R(omega (t - t0)) (x(t0) - c0) with v = V + omega x r."""
        if start is None:
            state.v[rows] = np.asarray(self.velocity)
            return
        t0, c0, r0 = start
        s = t - t0
        c = c0 + np.asarray(self.velocity) * s
        r = r0 @ self.rotation(s, state.dim).T
        state.x[rows] = c + r
        state.v[rows] = np.asarray(self.velocity) + self.spin(r)

    def rotation(self, t: float, d: int) -> np.ndarray:
        """R(omega t), (d, d): 2D rotation by omega t; 3D Rodrigues' formula about omega / |omega|."""
        w = self._omega3()
        if d == 2:
            a = w[2] * t
            return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        speed = float(np.linalg.norm(w))
        if speed == 0.0:
            return np.eye(3)
        k = w / speed
        K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        a = speed * t
        return np.eye(3) + np.sin(a) * K + (1.0 - np.cos(a)) * K @ K


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


class ReactionLog:
    """The force the rest of the system exerts on each rigid body and clamp (``names``), every step: one row per
    step at the step's midpoint t (the time of the rates that moved it), with dt and d components per name, and the
    impulse of each so far."""

    def __init__(self, names: list[str]):
        self.names = list(names)
        self.dim: int | None = None
        self.last: list[np.ndarray] | None = None           # force on each body / clamp, last evaluation
        self.rows: list[list[float]] = []                   # per step: t_mid, dt, then d components per name
        self.impulse = [0.0 for _ in self.names]

    def keep(self, forces: list[np.ndarray]) -> None:
        """The forces of the latest rate evaluation (the step's, once it ends)."""
        self.last = forces

    def close_step(self, t_mid: float, dt: float) -> None:
        """The step that just ended moved with the kept forces: log them and add their impulse."""
        if self.last is None:
            return
        self.rows.append([t_mid, dt] + [float(c) for f in self.last for c in f])
        for k, f in enumerate(self.last):
            self.impulse[k] = self.impulse[k] + f * dt

    def _table(self) -> np.ndarray:
        return np.asarray(self.rows, dtype=float).reshape(-1, 2 + (self.dim or 1) * len(self.names))

    def checkpoint(self) -> dict:
        """The log, the impulses and the last kept forces (a leapfrog restarted with its kept force evaluates no
        force before its first step ends, so the step is logged with these)."""
        d = self.dim or 1
        ck = dict(reaction_log=self._table(),
                  reaction_impulse=np.array([np.atleast_1d(i) * np.ones(d) for i in self.impulse],
                                            dtype=float).reshape(len(self.impulse), d))
        if self.last is not None:
            ck["reaction_last"] = np.array(self.last, dtype=float)
        return ck

    def restore(self, ck: dict) -> None:
        self.last = [np.array(f) for f in ck["reaction_last"]] if "reaction_last" in ck else None
        self.rows = [list(row) for row in np.asarray(ck["reaction_log"], dtype=float)]
        self.impulse = [np.array(row) for row in ck["reaction_impulse"]]
        if not self.rows:                                       # before the first step: the scalar start value
            self.impulse = [0.0 for _ in self.impulse]

    def history(self) -> dict:
        """{'t': (n_steps,), 'dt': (n_steps,), name: (n_steps, d) force on that rigid body / clamp} (N; 2D: N per
        metre of thickness); dt is the step's size, so sum(F dt) is the impulse."""
        if not self.names or self.dim is None:
            return {}
        d, log = self.dim, self._table()
        out = {"t": log[:, 0], "dt": log[:, 1]}
        for k, name in enumerate(self.names):
            out[name] = log[:, 2 + k * d: 2 + (k + 1) * d]
        return out

    def diagnostics(self) -> dict:
        # impulse the rest of the system gave each rigid body / clamp, N s (2D: N s/m); note the sign
        # convention differs from wall_impulse, which is the impulse the wall gave the model
        return {name: [float(c) for c in np.atleast_1d(imp)] for name, imp in zip(self.names, self.impulse)}


class Constraints:
    """The prescribed motions of a run: rigid walls, rigid bodies and clamps, and what they cost (the reaction log,
    :class:`ReactionLog`; the walls' impulses).

    A solver owns one and calls it at three points of every stage of a step:

    * :meth:`bind` once, on the initial state (which rows are rigid; rigid rows come last);
    * :meth:`constrain` on the rates: the force on each body / clamp is kept (sum m dv/dt over its rows of the
      unconstrained rates; pairs inside one body cancel), then rigid rows get dv/dt = 0 and no stress rate and
      clamped rows dx/dt = dv/dt = 0;
    * :meth:`apply` on the state the stage produced: walls (a unilateral constraint), each rigid body placed by its
      own motion (:meth:`RigidBody.place`), clamps back in place; on the final stage, the step's forces go into
      the log.
    """

    def __init__(self, walls=(), rigid=(), clamps=(), mirror: MirrorPlanes | None = None):
        self.walls = tuple(walls or ())
        self.rigid = tuple(rigid or ())
        self.clamps = tuple(clamps or ())
        names = [b.name for b in self.rigid] + [c.name for c in self.clamps]
        if len(set(names)) != len(names):
            raise ValueError(f"rigid bodies and clamps need distinct names, got {names}")
        for name in names:
            if name in ("t", "dt") or not name or not all(ch.isalnum() or ch in "_-" for ch in name):
                raise ValueError(f"rigid body / clamp name {name!r}: use letters, digits, '_' or '-' "
                                 "(not 't' or 'dt', the time columns of the reaction log)")
        ids = [b.body for b in self.rigid]
        if len(set(ids)) != len(ids):
            raise ValueError(f"rigid bodies need distinct body ids, got {ids}")
        if self.rigid and mirror is not None:
            raise ValueError("rigid bodies together with symmetry planes are not implemented")
        if self.rigid and self.walls:
            raise ValueError("rigid bodies together with RigidWall are not implemented (make the wall a rigid "
                             "body of particles)")
        self.wall_impulse = np.zeros(len(self.walls))
        self.n_deformable: int | None = None   # rows [0, n_deformable) are deformable, the rest rigid
        self.deformable_bodies: list[int] = [0]  # the body ids of those rows (several: they meet by contact)
        self.dim: int | None = None
        self.rows: list[slice] = []            # the rows of each rigid body
        self.starts: list[tuple | None] = []   # per rigid body: RigidBody.start (None: it only translates)
        self.log = ReactionLog(names)

    @property
    def reaction_names(self) -> list[str]:
        """Names of the rigid bodies and clamps, in the order of the reaction log."""
        return self.log.names

    def bind(self, state: State) -> None:
        """Check the state against the constraints and find the rigid rows (ValueError naming what is wrong)."""
        n = state.n
        self.dim = self.log.dim = state.dim
        for w in self.walls:
            w.check(state.dim)
        self.rows, self.starts = [], []
        if self.rigid and state.body is None:
            raise ValueError("rigid bodies need State.body (the body id of every particle)")
        for b in self.rigid:
            rows = _body_rows(b, state)
            self.rows.append(rows)
            self.starts.append(b.start(state, rows))
        n_def = min((r.start for r in self.rows), default=n)
        if sum(r.stop - r.start for r in self.rows) != n - n_def:
            raise ValueError("rigid body particles must come after every deformable particle in the state")
        self.n_deformable = n_def
        self.deformable_bodies = [0] if state.body is None else sorted(np.unique(state.body[:n_def]).tolist())
        for c in self.clamps:
            if c.index[-1] >= n_def:
                raise ValueError(f"clamp {c.name!r} holds particle {c.index[-1]}, which is not a deformable one")

    def constrain(self, state: State, r: Rates, record: bool = True) -> Rates:
        """Prescribed motion on the rates (in place), after keeping the force on each body and clamp (``record``:
        False for rates without forces, the deformation half of a leapfrog step, which keep the last forces)."""
        if not self.rigid and not self.clamps:
            return r
        forces = []
        for rows in self.rows:
            forces.append(np.sum(state.m[rows, None] * r.v[rows], axis=0))
            r.v[rows] = 0.0
            r.x[rows] = state.v[rows]
            r.S[rows] = 0.0
            r.S_zz[rows] = 0.0
        for c in self.clamps:
            forces.append(np.sum(state.m[c.index, None] * r.v[c.index], axis=0))
            r.v[c.index] = 0.0
            r.x[c.index] = 0.0
        if record:
            self.log.keep(forces)
        return r

    def apply(self, old: State, new: State, dt: float, final: bool) -> State:
        """Walls, rigid motion and clamps on the state a stage produced (in place)."""
        for k, wall in enumerate(self.walls):
            imp = wall.apply(new, dt)
            if final:
                self.wall_impulse[k] += imp
        for b, rows, start in zip(self.rigid, self.rows, self.starts):
            b.place(new, rows, start, old.t + dt)
        for c in self.clamps:
            new.v[c.index] = 0.0
            new.x[c.index] = old.x[c.index]
        if final:
            self.log.close_step(old.t + 0.5 * dt, dt)
        return new

    def checkpoint(self) -> dict:
        """What a restart needs besides the state: the reaction log and impulses, the start of turning bodies."""
        ck = dict(self.log.checkpoint(), wall_impulse=self.wall_impulse.copy())
        for k, start in enumerate(self.starts):
            if start is not None:
                ck[f"turning_{k}"] = np.concatenate([[start[0]], start[1], start[2].ravel()])
        return ck

    def restore(self, ck: dict) -> None:
        """The inverse of :meth:`checkpoint`, after :meth:`bind` on the restart state."""
        self.log.restore(ck)
        self.wall_impulse = np.array(ck["wall_impulse"], dtype=float)
        for k, start in enumerate(self.starts):
            if start is not None:
                a, d = ck[f"turning_{k}"], self.dim
                self.starts[k] = (float(a[0]), a[1:1 + d], a[1 + d:].reshape(-1, d))

    def reaction_history(self) -> dict:
        """The reaction log (:meth:`ReactionLog.history`)."""
        return self.log.history()

    def diagnostics(self) -> dict:
        out = {}
        if self.walls:
            # impulse of each wall on the *model* (a quarter/half of the body with symmetry planes), N s (2D: N s/m)
            out["wall_impulse"] = [float(i) for i in self.wall_impulse]
        if self.reaction_names:
            out["reaction_impulse"] = self.log.diagnostics()
        return out


def _body_rows(b: RigidBody, state: State) -> slice:
    """The rows of rigid body ``b`` (consecutive; ValueError otherwise)."""
    b.check(state.dim)
    idx = np.flatnonzero(state.body == b.body)
    if len(idx) == 0:
        raise ValueError(f"rigid body {b.name!r}: no particle has body id {b.body}")
    if idx[-1] - idx[0] + 1 != len(idx):
        raise ValueError(f"rigid body {b.name!r}: its particles must be consecutive rows")
    return slice(int(idx[0]), int(idx[-1]) + 1)
