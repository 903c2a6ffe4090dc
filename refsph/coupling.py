"""How the bodies of a run meet: TLSPH's pinball contact (Eqs. (32)-(36), :mod:`refsph.contact`) between the
deformable rows and the rigid tools, and between every two deformable bodies (:class:`PinballCoupling`); or, for
either method, the penalty contact on the tools' exact geometry (:mod:`refsph.penalty`, :class:`PenaltyCoupling`).

:class:`PinballCoupling` is the part of the TLSPH solver (:mod:`refsph.solvers`) that knows which rows meet which:
the deformable rows [0, n) against the rigid rows [n, N) (a rigid partner: m_b = mu_b = inf), and each pair of
deformable bodies once (equal and opposite forces, both sides deformable). The pinball radius is R = k h for every
particle; in 2D the Hertz force is per unit thickness (``thickness`` = the spacing dp). It keeps the contact's
diagnostics (the largest penetration so far, the contacts of the last evaluation).
"""
from __future__ import annotations

import numpy as np

from scipy.spatial import cKDTree

from . import contact as _contact
from .boundaries import RigidBody
from .contact import ContactResult, PinballContact
from .penalty import PenaltyContact, penalty_contact
from .state import State

__all__ = ["PinballCoupling", "PenaltyCoupling"]


def _check_dt(dt) -> None:
    if not (dt is not None and dt > 0):
        raise ValueError(f"the tool contact needs the step size dt > 0 (the pinball's Eq. (34), the penalty's "
                         f"tangential history), got {dt!r}")


class PinballCoupling:
    """The pinball contact of a solver's bodies (module text): ``contact`` its parameters (and friction law),
    ``R`` the pinball radius [m], ``G`` the deformable material's shear modulus [Pa], ``dp`` the spacing (2D: the
    thickness the Hertz force is divided by)."""

    def __init__(self, contact: PinballContact, R: float, G: float, dp: float | None):
        if not (dp is not None and dp > 0):
            raise ValueError("the pinball contact needs the particle spacing dp (2D: force per unit thickness)")
        self.contact, self.R, self.G, self.dp = contact, R, G, dp
        self.max_penetration = 0.0
        self.n_contacts = 0
        self.n_body_contacts = 0

    def thickness(self, dim: int) -> float:
        return self.dp if dim == 2 else 1.0

    def with_tools(self, state: State, n: int, dt: float) -> ContactResult:
        """The contact of the deformable rows [0, n) with the rigid rows [n, N) for a step dt."""
        _check_dt(dt)
        c = _contact.pinball_contact(state.x[:n], state.v[:n], state.m[:n], state.x[n:], state.v[n:], np.inf,
                                     self.R, self.G, np.inf, dt, self.contact, thickness=self.thickness(state.dim),
                                     T_a=None if state.T is None else state.T[:n])
        self.max_penetration = max(self.max_penetration, c.max_penetration)
        self.n_contacts = c.n_contacts
        return c

    def between_bodies(self, body: State, ids: list[int], dt: float) -> np.ndarray:
        """dv/dt of the deformable rows ``body`` from the contact between every two of the bodies ``ids``."""
        _check_dt(dt)
        acc = np.zeros_like(body.x)
        rows = [np.flatnonzero(body.body == b) for b in ids]
        n_contacts = 0
        for k, ra in enumerate(rows):
            for rb in rows[k + 1:]:
                c = _contact.pinball_contact(body.x[ra], body.v[ra], body.m[ra], body.x[rb], body.v[rb], body.m[rb],
                                             self.R, self.G, self.G, dt, self.contact,
                                             thickness=self.thickness(body.dim),
                                             T_a=None if body.T is None else body.T[ra])
                acc[ra] += c.a
                acc[rb] += c.force_on_b / body.m[rb, None]
                self.max_penetration = max(self.max_penetration, c.max_penetration)
                n_contacts += c.n_contacts
        self.n_body_contacts = n_contacts
        return acc

    def checkpoint(self) -> dict:
        return dict(max_penetration=np.float64(self.max_penetration), n_contacts=np.int64(self.n_contacts))

    def restore(self, ck: dict) -> None:
        self.max_penetration, self.n_contacts = float(ck["max_penetration"]), int(ck["n_contacts"])

    def diagnostics(self, several_bodies: bool) -> dict:
        out = {"max_pinball_penetration_m": self.max_penetration, "pinball_contacts_last_step": self.n_contacts}
        if several_bodies:
            out["pinball_contacts_between_bodies_last_step"] = self.n_body_contacts
        return out


class PenaltyCoupling:
    """The penalty contact (:mod:`refsph.penalty`) of the deformable rows [0, n) with every rigid body that has a
    ``shape``: the forces from the exact geometry, the reaction spread over the body's rows in proportion to their
    mass (their sum is the force on the body), the friction power deposited on the deformable particle and on the
    body's particle nearest to it (each contact's power counted once on each side, as the pinball does). The
    tangential history xi of the last evaluation is committed at the end of the step (:meth:`commit`)."""

    def __init__(self, contact: PenaltyContact, rigid: tuple[RigidBody, ...]):
        if not rigid or any(b.shape is None for b in rigid):
            raise ValueError("the penalty contact needs the exact geometry of every rigid body (RigidBody.shape, a "
                             "refsph.penalty.RoundedPolygon); use the pinball contact for bodies made of particles")
        self.contact, self.rigid = contact, tuple(rigid)
        self.xi: np.ndarray | None = None                  # committed tangential history (n, d)
        self.trial: np.ndarray | None = None               # the last evaluation's
        self.max_penetration = 0.0
        self.n_contacts = 0
        self.rows: list | None = None                      # each body's rows (State.body is fixed in a run)
        self.trees: dict = {}                              # each body's k-d tree in its own frame (nearest_rows)

    def body_rows(self, state: State) -> list:
        """The rows of each rigid body (found once: a run's State.body does not change)."""
        if self.rows is None:
            self.rows = [np.flatnonzero(state.body == b.body) for b in self.rigid]
        return self.rows

    def candidates(self, x: np.ndarray, shape, shift: np.ndarray) -> np.ndarray:
        """The rows of x that can touch the tool: within its bounding circle grown by the contact's offset (the
        others have no contact force; leaving them out of :func:`~refsph.penalty.penalty_contact` changes no
        number, and saves the exact distance of every particle of a large workpiece)."""
        centre, radius = shape.bounding_circle(shift)
        d = x - centre
        return np.flatnonzero(np.einsum("nd,nd->n", d, d) <= (radius + self.contact.offset) ** 2)

    def nearest_rows(self, i: int, xb: np.ndarray, shift: np.ndarray, points: np.ndarray) -> np.ndarray:
        """For each of ``points``, the index into ``xb`` (body i's particles, moved by ``shift``) of the particle
        nearest to it: the answer of a k-d tree of ``xb`` built anew, without building one each step. A rigid body's
        particles keep their places relative to ``shift`` up to round-off, so the tree is built once in that frame;
        it names each point's 4 nearest there, and these are measured at their current places. Where the body's
        particles have moved in its frame by more than the gap between a point's nearest and 4th nearest could hide
        (a turning body), the tree is built anew."""
        rel = xb - shift
        cached = self.trees.get(i)
        if cached is None or cached[1].shape != rel.shape:
            cached = self.trees[i] = (cKDTree(rel), rel)
        tree, rel0 = cached
        k = min(4, len(xb))
        dist, cand = tree.query(points - shift, k=k)
        dist, cand = dist.reshape(len(points), k), cand.reshape(len(points), k)
        moved = rel - rel0
        slack = 2.0 * float(np.sqrt(np.einsum("nd,nd->n", moved, moved).max())) + 1e-12 * (1.0 + float(
            np.abs(points).max()))
        if k < len(xb) and np.any(dist[:, -1] <= dist[:, 0] + slack):
            self.trees[i] = (cKDTree(rel), rel)
            return cKDTree(xb).query(points)[1]
        gap = xb[cand] - points[:, None, :]
        r2 = gap[..., 0] * gap[..., 0]
        for a in range(1, xb.shape[1]):
            r2 += gap[..., a] * gap[..., a]
        return cand[np.arange(len(points)), np.argmin(r2, axis=1)]

    def with_tools(self, state: State, n: int, dt: float) -> ContactResult:
        """The contact of the deformable rows [0, n) with the rigid bodies for a step dt (a ContactResult: the
        deformable rows' acceleration, the force on each rigid row, the friction power on both sides)."""
        _check_dt(dt)
        d = state.dim
        if self.xi is None or self.xi.shape != (n, d):
            self.xi = np.zeros((n, d))
        x, v, m = state.x[:n], state.v[:n], state.m[:n]
        T = None if state.T is None else state.T[:n]
        a, power_a, damping_a = np.zeros((n, d)), np.zeros(n), np.zeros(n)
        force_b, power_b = np.zeros((state.n - n, d)), np.zeros(state.n - n)
        trial, contacts, deepest = np.zeros((n, d)), 0, 0.0
        for i, (b, rows) in enumerate(zip(self.rigid, self.body_rows(state))):
            xb = state.x[rows]
            shift = xb.mean(axis=0)
            near = self.candidates(x, b.shape, shift)
            c = penalty_contact(x[near], v[near], m[near], None if T is None else T[near], b.shape, shift,
                                np.asarray(b.velocity), dt, self.contact, self.xi[near])
            a[near] += c.a
            trial[near] += c.xi
            power_a[near] += c.friction_power
            damping_a[near] += c.damping_power
            mb = state.m[rows]
            force_b[rows - n] = c.force_on_tool[None, :] * (mb / mb.sum())[:, None]
            hot = np.flatnonzero(c.friction_power > 0)
            if len(hot):
                nearest = self.nearest_rows(i, xb, shift, x[near[hot]])
                np.add.at(power_b, rows[nearest] - n, c.friction_power[hot])
            contacts += int(np.count_nonzero(c.gap > 0))
            deepest = max(deepest, float(c.gap.max(initial=0.0)))
        self.trial = trial
        self.max_penetration = max(self.max_penetration, deepest)
        self.n_contacts = contacts
        return ContactResult(a=a, force_on_b=force_b, n_contacts=contacts, max_penetration=deepest,
                             friction_power_a=power_a, friction_power_b=power_b, heat_power_a=damping_a)

    def commit(self) -> None:
        """The step ended: its last evaluation's tangential history becomes the committed one."""
        if self.trial is not None:
            self.xi, self.trial = self.trial, None

    def checkpoint(self) -> dict:
        ck = dict(max_penetration=np.float64(self.max_penetration), n_contacts=np.int64(self.n_contacts))
        if self.xi is not None:
            ck["penalty_xi"] = self.xi.copy()
        return ck

    def restore(self, ck: dict) -> None:
        self.max_penetration, self.n_contacts = float(ck["max_penetration"]), int(ck["n_contacts"])
        self.xi = np.array(ck["penalty_xi"]) if "penalty_xi" in ck else None

    def diagnostics(self, several_bodies: bool) -> dict:
        return {"max_penalty_penetration_m": self.max_penetration, "penalty_contacts_last_step": self.n_contacts}
