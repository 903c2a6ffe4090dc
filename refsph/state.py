"""Particle state: a dataclass of arrays, SI units.

Shapes: N particles in d = 2 or 3 dimensions. In 2D every extensive quantity is per unit thickness
(mass in kg/m, volume in m^2) and the model is plane strain: the out-of-plane strain rate is zero but the
out-of-plane normal stress is not, so the deviatoric stress carries its zz component ``S_zz``. Dropping it
(as some codes do) makes the pressure p = -(s_xx + s_yy + s_zz)/3 + ... and the von Mises stress wrong.

| field | shape     | unit            | meaning                                                  |
|-------|-----------|-----------------|----------------------------------------------------------|
| x     | (N, d)    | m               | current position                                         |
| v     | (N, d)    | m/s             | velocity                                                 |
| m     | (N,)      | kg (2D: kg/m)   | mass, constant                                           |
| rho   | (N,)      | kg/m^3          | density (ESPH: integrated by Eq. (10); TLSPH: m/(J V0))    |
| S     | (N, d, d) | Pa              | deviatoric Cauchy stress (in-plane block in 2D)          |
| S_zz  | (N,)      | Pa              | out-of-plane deviatoric normal stress (2D plane strain; zero and unused in 3D) |
| X     | (N, d)    | m               | reference position (TLSPH; the initial position for ESPH)|
| V0    | (N,)      | m^3 (2D: m^2)   | reference volume (TLSPH; V <- J V at a reference update) |
| t     | scalar    | s               | time                                                     |

Plastic and thermal fields, present (arrays) only when the scene's strength model is a plasticity law
(``PLASTIC_FIELDS``, see :mod:`refsph.strength`; else None):

| field     | shape | unit    | meaning                                                          |
|-----------|-------|---------|------------------------------------------------------------------|
| eps_p     | (N,)  | -       | accumulated effective plastic strain (Eq. (30) summed)             |
| eps_dot_p | (N,)  | 1/s     | effective plastic strain rate of the last step, d eps_p / dt     |
| W_p       | (N,)  | J/m^3   | accumulated plastic work density (Eq. (31) summed)                 |
| T         | (N,)  | K       | temperature (Eq. (28), adiabatic)                                  |

Scenes with several bodies (a workpiece and rigid tools) also carry

| field | shape | unit | meaning                                                                        |
|-------|-------|------|--------------------------------------------------------------------------------|
| body  | (N,)  | -    | body id of each particle (0: the deformable workpiece; rigid tools: their own id) |

(see :class:`~refsph.boundaries.RigidBody`); ``body = None`` means every particle is body 0.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

__all__ = ["State", "Rates", "FIELD_UNITS", "PLASTIC_FIELDS", "make_state", "concatenate_states"]

FIELD_UNITS = {
    "x": "m",
    "v": "m/s",
    "m": "kg (2D: kg per metre of thickness)",
    "rho": "kg/m^3",
    "S": "Pa",
    "S_zz": "Pa",
    "X": "m",
    "V0": "m^3 (2D: m^2)",
    "t": "s",
    "eps_p": "1",
    "eps_dot_p": "1/s",
    "W_p": "J/m^3",
    "T": "K",
    "body": "1 (body id)",
}

PLASTIC_FIELDS = ("eps_p", "eps_dot_p", "W_p", "T")


@dataclass
class State:
    x: np.ndarray
    v: np.ndarray
    m: np.ndarray
    rho: np.ndarray
    S: np.ndarray
    S_zz: np.ndarray
    X: np.ndarray
    V0: np.ndarray
    t: float = 0.0
    eps_p: np.ndarray | None = None
    eps_dot_p: np.ndarray | None = None
    W_p: np.ndarray | None = None
    T: np.ndarray | None = None
    body: np.ndarray | None = None

    @property
    def plastic(self) -> bool:
        """True if the state carries the Johnson-Cook fields (eps_p, eps_dot_p, W_p, T)."""
        return self.eps_p is not None

    @property
    def n(self) -> int:
        return self.x.shape[0]

    @property
    def dim(self) -> int:
        return self.x.shape[1]

    def rows(self, n: int, **given) -> "State":
        """The first n rows as a state of views (the time kept; ``given``: fields to take as they are, e.g. views
        made once that a cache keys on)."""
        part = {f.name: getattr(self, f.name)[:n] for f in fields(self)
                if f.name != "t" and f.name not in given and getattr(self, f.name) is not None}
        return replace(self, **part, **given)

    def copy(self) -> "State":
        return replace(self, **{f.name: np.array(getattr(self, f.name), copy=True)
                                for f in fields(self) if f.name != "t" and getattr(self, f.name) is not None})

    def check(self) -> None:
        """Shapes and finiteness; raises ValueError naming the offending field."""
        n, d = self.x.shape
        if d not in (2, 3):
            raise ValueError(f"x must have shape (N, 2) or (N, 3), got {self.x.shape}")
        expect = {"v": (n, d), "m": (n,), "rho": (n,), "S": (n, d, d), "S_zz": (n,),
                  "X": (n, d), "V0": (n,)}
        for name, shape in expect.items():
            a = getattr(self, name)
            if a.shape != shape:
                raise ValueError(f"state field {name} must have shape {shape}, got {a.shape}")
        present = [getattr(self, k) is not None for k in PLASTIC_FIELDS]
        if any(present) and not all(present):
            raise ValueError(f"state fields {', '.join(PLASTIC_FIELDS)} must be all present or all None")
        if all(present):
            for name in PLASTIC_FIELDS:
                if getattr(self, name).shape != (n,):
                    raise ValueError(f"state field {name} must have shape {(n,)}, got {getattr(self, name).shape}")
            if np.any(self.T <= 0):
                raise ValueError("state field T must be positive (kelvin)")
        if self.body is not None and (self.body.shape != (n,) or not np.issubdtype(self.body.dtype, np.integer)):
            raise ValueError(f"state field body must be an integer array of shape {(n,)}, "
                             f"got {self.body.dtype} {self.body.shape}")
        for name in ("m", "rho", "V0"):
            if not np.all(getattr(self, name) > 0):
                raise ValueError(f"state field {name} must be positive everywhere")
        for name in ("x", "v", "rho", "S", "S_zz", "X"):
            if not np.all(np.isfinite(getattr(self, name))):
                raise ValueError(f"state field {name} must be finite")

    def first_nonfinite(self) -> tuple[str, int] | None:
        """(field, particle index) of the first NaN/inf in an evolving field, or None."""
        for name in ("x", "v", "rho", "S", "S_zz") + (PLASTIC_FIELDS if self.plastic else ()):
            a = getattr(self, name)
            with np.errstate(invalid="ignore", over="ignore"):
                fine = np.isfinite(np.sum(a))       # a NaN or inf anywhere makes the sum NaN or inf: the fast check
            if fine:                                # (a sum that overflows from finite values falls through)
                continue
            bad = ~np.isfinite(a.reshape(a.shape[0], -1)).all(axis=1)
            if bad.any():
                return name, int(np.flatnonzero(bad)[0])
        return None


@dataclass
class Rates:
    """Time derivatives of the evolved fields of a :class:`State` (same shapes). ``rho`` is None where density is not
    integrated (TLSPH, Eq. (2)); ``l`` is the velocity gradient the stress rate came from (the strength model takes
    its strain rate from it). ``friction_power``: (N,) the friction power |f_t| |v_t| [W; 2D: W/m] each row takes
    part in at this evaluation (the tool contact's, :mod:`refsph.contact`; None: no friction), the source of the
    frictional heat (:class:`refsph.thermal.HeatFlow`). ``heat_power``: (N,) the power [W; 2D: W/m] the numerical
    dissipation (artificial viscosity, :func:`refsph.tlsph.reference_viscosity`; the penalty contact's normal
    damping, :mod:`refsph.penalty`) takes out of the motion in each row (None: not computed), the heat a run with
    ``Setup.dissipation_heat`` puts back; ``damping_power``: (N,) the contact damping's part of it (None: no tool
    contact in it), which the heat ledger reports apart."""

    x: np.ndarray
    v: np.ndarray
    rho: np.ndarray | None
    S: np.ndarray
    S_zz: np.ndarray
    l: np.ndarray | None = None
    friction_power: np.ndarray | None = None
    heat_power: np.ndarray | None = None
    damping_power: np.ndarray | None = None

    def rows(self, n: int) -> "Rates":
        """The rates of the first n rows (the real particles of a real + ghost evaluation)."""
        def first(a):
            return None if a is None else a[:n]
        return Rates(x=self.x[:n], v=self.v[:n], rho=first(self.rho), S=self.S[:n], S_zz=self.S_zz[:n],
                     l=first(self.l), friction_power=first(self.friction_power), heat_power=first(self.heat_power),
                     damping_power=first(self.damping_power))


def make_state(x: np.ndarray, v: np.ndarray, rho0: float, volume: np.ndarray | float,
               T0: float | None = None, body: np.ndarray | None = None, *, S: np.ndarray | None = None,
               S_zz: np.ndarray | float | None = None, rho: np.ndarray | float | None = None,
               X: np.ndarray | None = None) -> State:
    """A state at rest density ``rho0`` unless told otherwise: m = rho0 V, X = x, V0 = V.

    ``T0`` (kelvin): give it for a plasticity law; the state then carries eps_p = eps_dot_p = W_p = 0 and T = T0.
    Without it those fields are None (elastic material). ``body``: body id per particle (see the table above),
    or None for a single body.

    An initial stress: ``S`` (N, d, d) or (d, d) deviatoric stress (traceless; in 2D with ``S_zz``, so that
    S_xx + S_yy + S_zz = 0), and ``rho``, the current density, which sets the pressure p = K (rho / rho0 - 1)
    (Eq. (24)). What each method reads of it:

    * ESPH reads ``S``, ``S_zz`` and ``rho`` (it integrates rho by Eq. (10)): both parts of the stress are used;
    * TLSPH reads ``S`` and ``S_zz``, and computes rho and p from m, V0 and J = det F (Eq. (2)), so it cannot
      start from a pressure that the configuration does not carry: its solver refuses a state whose rho is not
      m / (J V0). To start TLSPH deformed, give the reference positions ``X`` (default: x) and rho = m / (J V0).

    ``S`` must be symmetric and traceless, ``rho`` finite and positive (ValueError naming the field otherwise).
    """
    x = np.array(x, dtype=float)
    n, d = x.shape
    V = np.broadcast_to(np.asarray(volume, dtype=float), (n,)).copy()
    if np.any(V <= 0):
        raise ValueError("particle volume must be positive")
    if not rho0 > 0:
        raise ValueError(f"rho0 must be positive, got {rho0!r}")
    if T0 is not None and not (np.isfinite(T0) and T0 > 0):
        raise ValueError(f"initial temperature T0 must be positive (kelvin), got {T0!r}")
    thermal = {} if T0 is None else dict(eps_p=np.zeros(n), eps_dot_p=np.zeros(n), W_p=np.zeros(n),
                                         T=np.full(n, float(T0)))
    S = np.zeros((n, d, d)) if S is None else np.broadcast_to(np.asarray(S, dtype=float), (n, d, d)).copy()
    S_zz = np.zeros(n) if S_zz is None else np.broadcast_to(np.asarray(S_zz, dtype=float), (n,)).copy()
    trace = np.trace(S, axis1=1, axis2=2) + (S_zz if d == 2 else 0.0)
    if not np.all(np.isfinite(S)) or not np.allclose(S, S.transpose(0, 2, 1), rtol=0,
                                                     atol=1e-12 * np.max(np.abs(S), initial=1.0)):
        raise ValueError("initial deviatoric stress S must be finite and symmetric")
    if not np.all(np.abs(trace) <= 1e-12 * np.max(np.abs(S), initial=1.0)):
        raise ValueError("initial deviatoric stress S must be traceless (in 2D: S_xx + S_yy + S_zz = 0); put the "
                         "mean stress into the density rho")
    if d == 3 and np.any(S_zz != 0):
        raise ValueError("S_zz is the 2D plane-strain component; in 3D it is S[:, 2, 2]")
    rho = np.full(n, float(rho0)) if rho is None else np.broadcast_to(np.asarray(rho, dtype=float), (n,)).copy()
    if not np.all(np.isfinite(rho) & (rho > 0)):
        raise ValueError("initial density rho must be finite and positive")
    X = x.copy() if X is None else np.array(X, dtype=float)
    if X.shape != x.shape:
        raise ValueError(f"reference positions X must have the shape of x {x.shape}, got {X.shape}")
    return State(
        x=x,
        v=np.broadcast_to(np.asarray(v, dtype=float), (n, d)).copy(),
        m=rho0 * V,
        rho=rho,
        S=S,
        S_zz=S_zz,
        X=X,
        V0=V,
        body=None if body is None else np.asarray(body, dtype=np.int32).copy(),
        **thermal,
    )


def concatenate_states(*states: State) -> State:
    """One state holding the particles of several (same dimension, same time, all with or all without the
    thermal fields); ``body`` of a part without one is 0."""
    if not states:
        raise ValueError("nothing to concatenate")
    if len({s.dim for s in states}) != 1 or len({s.plastic for s in states}) != 1 or len({s.t for s in states}) != 1:
        raise ValueError("states to concatenate must have the same dimension, the same fields and the same time")
    out = {}
    for f in fields(State):
        if f.name == "t":
            continue
        if f.name == "body":
            out["body"] = np.concatenate([s.body if s.body is not None else np.zeros(s.n, dtype=np.int32)
                                          for s in states]).astype(np.int32)
        elif getattr(states[0], f.name) is not None:
            out[f.name] = np.concatenate([getattr(s, f.name) for s in states])
    return State(t=states[0].t, **out)
