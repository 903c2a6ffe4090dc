"""How the bodies of a TLSPH run meet: the pinball contact (Eqs. (32)-(36), :mod:`refsph.contact`) between the
deformable rows and the rigid tools, and between every two deformable bodies.

:class:`PinballCoupling` is the part of the TLSPH solver (:mod:`refsph.solvers`) that knows which rows meet which:
the deformable rows [0, n) against the rigid rows [n, N) (a rigid partner: m_b = mu_b = inf), and each pair of
deformable bodies once (equal and opposite forces, both sides deformable). The pinball radius is R = k h for every
particle; in 2D the Hertz force is per unit thickness (``thickness`` = the spacing dp). It keeps the contact's
diagnostics (the largest penetration so far, the contacts of the last evaluation).
"""
from __future__ import annotations

import numpy as np

from . import contact as _contact
from .contact import ContactResult, PinballContact
from .state import State

__all__ = ["PinballCoupling"]


def _check_dt(dt) -> None:
    if not (dt is not None and dt > 0):
        raise ValueError(f"the pinball contact needs the step size dt > 0 (Eq. (34)), got {dt!r}")


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
