"""Tool contact in the PFEM, as an implicit method does it (issue 24): the gap to the tool's exact boundary enforced
inside the Newton-Raphson iterations by a penalty, Coulomb friction mu(T) by a return map.

The paper (Section 2.3) does not say how its PFEM enforces contact; refsph takes the penalty form standard in
implicit codes (Wriggers, "Computational Contact Mechanics", 2nd ed. 2006, Sections 5.2 and 6.2; the rigid tool
is refsph's exact :class:`refsph.penalty.RoundedPolygon`, the same boundary the SPH penalty contact uses). For a
boundary node i with penetration g_i > 0 (inside the tool), outward tool normal n_i and tangent t_i (n rotated by
+90 deg), tributary boundary length l_i (half its two boundary edges):

    f_N,i   = k_N l_i g_i                                               normal force on the node  [N/m]
    f_T,i*  = f_T,i^n - k_T l_i s_i                                     trial (stick) tangential force
              s_i = ((x_i - x_i^n) - du_tool) . t_i                     the step's slip relative to the tool
    f_T,i   = f_T,i*                            if |f_T,i*| <= mu(T_i) f_N,i      (stick)
            = mu(T_i) f_N,i sign(f_T,i*)        otherwise                         (slip: the return map)
    f_i     = f_N,i n_i + f_T,i t_i,            the force on the tool: -sum_i f_i

Within a solve with frozen sets (:func:`solve_with_active_set`) a node of the contact set that has left the tool
(g_i < 0) is pulled back by the same f_N,i < 0 (the active set's constraint, until the sets are looked at again),
but carries no friction: the cap is mu(T_i) max(f_N,i, 0). With mu f_N,i itself the cap's sign turned, and a frozen
slip's friction pushed the node the way it went (seen in case 8 at t_u/10, 0.568 ms, where Newton stalls: a node
flung 48 um in a step of 1.25 us; the stall itself outlived this mend, chapter 12).

k_N, k_T [Pa/m] are penalties per unit penetration and per unit length of boundary; a few hundred times G / h
keeps the penetration below 1 % of the spacing. mu(T) is :class:`refsph.contact.CoulombFriction` (the second
paper's Eqs. (10)-(11)) at the node's temperature of the last heat step (the staggered scheme of Section 2.3.3).
The Newton matrix gets each node's 2 x 2 derivative df_i/dx_i (central differences, the force of a node depends on
its own position only). The frictional heat of the step is |f_T,i| |s_i| on the sliding nodes (Eq. (7) with
eta = 1 is applied by the caller).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..contact import CoulombFriction
from ..penalty import RoundedPolygon
from .solid import NewtonFailed, newton_step

__all__ = ["ToolContact", "boundary_lengths", "StepContact", "solve_with_active_set"]


@dataclass(frozen=True)
class ToolContact:
    """The penalty contact's parameters (module text): ``k_normal``, ``k_tangent`` [Pa/m], ``friction`` (None:
    frictionless). No defaults."""

    k_normal: float
    k_tangent: float
    friction: CoulombFriction | None

    def __post_init__(self):
        for name in ("k_normal", "k_tangent"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"ToolContact.{name} must be a positive penalty [Pa/m], got {v!r}")


def boundary_lengths(x: np.ndarray, edges: np.ndarray, n: int) -> np.ndarray:
    """l_i: half the length of each boundary edge given to both its nodes (0 off the boundary)."""
    L = np.linalg.norm(x[edges[:, 1]] - x[edges[:, 0]], axis=1)
    return np.bincount(edges.ravel(), np.repeat(0.5 * L, 2), minlength=n)


class StepContact:
    """The contact of one step (the ``contact`` of :class:`refsph.pfem.solid.Loads`): the tool ``shape`` with its
    core at ``shift`` (its position at t_{n+1}) having moved by ``du_tool`` in the step, the nodes' positions
    ``x_n`` and tangential forces ``f_T_n`` (N,) at t_n, their temperatures T and tributary lengths ``length``;
    ``nodes`` the indices that may touch (the workpiece's boundary). Calling it with x_{n+1} gives (f, df/dx)."""

    def __init__(self, params: ToolContact, shape: RoundedPolygon, shift, du_tool, x_n, f_T_n, T, length, nodes):
        self.p, self.shape = params, shape
        self.shift, self.du_tool = np.asarray(shift, dtype=float), np.asarray(du_tool, dtype=float)
        self.x_n, self.f_T_n, self.T, self.length = x_n, f_T_n, T, length
        self.nodes = np.asarray(nodes)
        self.mu = np.zeros(len(x_n)) if params.friction is None else params.friction.mu(T)
        self.last = None
        self.active = self.slip = None                         # frozen sets (None: decided by the gap / the cap)
        self.stuck = np.zeros(len(x_n), bool)                  # made to stick for the step (stick_reversed)

    def freeze(self, x_new: np.ndarray, grow: bool = False) -> bool:
        """Fix the contact and slip sets at positions x_new (the active-set strategy: within one Newton-Raphson
        solve the forces are then smooth); True if the sets changed. ``grow``: a node keeps its place in the sets
        it is in (in contact; slipping, in its direction) and only joins others, so that sets which cycle (a node
        grazing the tool, or at the friction cap, in and out on alternate solves) settle. A node that slipped one
        way and whose trial force now points the other way beyond the cap sticks (slip 0) rather than slips back,
        as a return map from a slip state would: neither slip direction may be consistent (the stagnation node at
        the tool's edge radius, where the chip and the machined surface part, flipped between them forever). With
        ``grow``, a slip kept whose trial force now points against it sticks for the step at once (as
        :meth:`stick_reversed` does after a failed solve: kept sliding, its friction pushes it the way it goes and the
        solve stalls; case 8 at t_u/10 spent 80 Newton corrections so on every second step)."""
        idx = self.nodes
        saved, self.active, self.slip = (self.active, self.slip), None, None
        res = self.forces(x_new[idx], idx)
        active = np.zeros(len(x_new), bool)
        active[idx] = res["gap"] > 0
        slip = np.zeros(len(x_new))
        trial, cap = res["trial"], self.mu[idx] * res["f_N"]
        slip[idx] = np.where(active[idx] & (np.abs(trial) > cap), np.sign(trial), 0.0)
        if saved[1] is not None:
            slip[(saved[1] != 0) & (slip == -saved[1])] = 0.0         # a slip that reverses sticks first
        if grow and saved[0] is not None:
            active |= saved[0]
            self._stick_turned(saved[1][idx], trial)              # a kept slip turned against its trial force
            slip = np.where(saved[1] != 0, saved[1], slip)
        slip[self.stuck] = 0.0
        changed = saved[0] is None or not (np.array_equal(saved[0], active) and np.array_equal(saved[1], slip))
        self.active, self.slip = active, slip
        return changed

    def stick_reversed(self, x_new: np.ndarray) -> bool:
        """Frozen slips whose trial force at positions x_new points against their direction are made to stick (slip
        0) for the rest of the step (:meth:`freeze` keeps them stuck: set free again, the node slid and turned on
        alternate solves); True if there were any. Frozen, such a node's friction pushes it the way it is going, so
        a solve cannot settle (case 1 at t_u/10, 1.393 ms: a node frozen sliding +1 with its trial force -150 times
        the cap)."""
        if self.slip is None:
            return False
        idx = self.nodes
        turned = self._stick_turned(self.slip[idx], self.forces(x_new[idx], idx)["trial"])
        self.slip[idx[turned]] = 0.0
        return bool(np.any(turned))

    def _stick_turned(self, slip: np.ndarray, trial: np.ndarray) -> np.ndarray:
        """The rule of :meth:`stick_reversed` and of :meth:`freeze` with ``grow``: of the nodes ``self.nodes``
        with slip directions ``slip`` and trial forces ``trial``, those sliding against their trial force stick for
        the rest of the step (``self.stuck``); returns them (a mask over ``self.nodes``)."""
        turned = (slip != 0) & (np.sign(trial) == -slip)
        self.stuck[self.nodes[turned]] = True
        return turned

    def forces(self, x: np.ndarray, idx: np.ndarray) -> dict:
        """The forces on nodes ``idx`` at positions x (len(idx), 2): f (.., 2), f_N, f_T, slip s, g, and the trial
        (stick) tangential force f_T* (module text)."""
        g, n = self.shape.gap(x, self.shift)
        t = np.stack([-n[:, 1], n[:, 0]], axis=1)
        on = g > 0 if self.active is None else self.active[idx]
        li = self.length[idx]
        fN = np.where(on, self.p.k_normal * li * g, 0.0)
        s = np.einsum("nd,nd->n", x - self.x_n[idx] - self.du_tool, t)
        trial = self.f_T_n[idx] - self.p.k_tangent * li * s
        cap = self.mu[idx] * np.maximum(fN, 0.0)            # no friction from a pull (module text)
        if self.slip is None:
            fT = np.where(on, np.clip(trial, -cap, cap), 0.0)
        else:
            sl = self.slip[idx]
            fT = np.where(on, np.where(sl != 0, sl * cap, trial), 0.0)
        return dict(f=fN[:, None] * n + fT[:, None] * t, f_N=fN, f_T=fT, slip=np.where(on, s, 0.0), gap=g,
                    trial=trial)

    def __call__(self, x_new: np.ndarray, stiffness: bool = True):
        """(f (N, 2), df/dx (N, 2, 2)) at positions x_new; ``stiffness=False``: the derivative left zero (a line
        search's trial point needs the force only)."""
        N = len(x_new)
        f, k = np.zeros((N, 2)), np.zeros((N, 2, 2))
        idx = self.nodes
        xi = x_new[idx]
        res = self.forces(xi, idx)
        f[idx] = res["f"]
        eps = 1e-7 * np.maximum(self.length[idx], 1e-12)
        for d in range(2 if stiffness else 0):
            e = np.zeros_like(xi)
            e[:, d] = eps
            k[idx, :, d] = (self.forces(xi + e, idx)["f"] - self.forces(xi - e, idx)["f"]) / (2 * eps[:, None])
        full = {key: np.zeros(N) for key in ("f_N", "f_T", "slip", "gap")}
        full["gap"][:] = -np.inf
        for key in full:
            full[key][idx] = res[key]
        self.last = full
        return f, k


def solve_with_active_set(nodes, mesh, hist, law, dt, loads, max_outer: int = 8, dynamic=True, max_iter: int = 25,
                          max_move: float | None = None, du0=None, settle: int | None = None):
    """Newton-Raphson with the contact and slip sets frozen (:meth:`StepContact.freeze`): set at the step's start
    x_n (the tool already at t_{n+1}), the first solve started from ``du0`` (default zeros; not the predictor dt v:
    the trapezoidal rule's velocities ring at an impact, and the predictor would drive the contact nodes deep into
    the tool; sets taken at x_n + du0 instead cost twice the iterations on case 1's short cut at t_u / 10), solved,
    set again from the solution, until the sets stop changing (the active-set strategy, Wriggers 2006, Section
    6.3); then a last solve with the sets free checks that the solution satisfies the contact law itself.
    ``settle`` (None or at least 2): the sets are looked at again after every ``settle`` Newton corrections, not only
    once a solve has converged (the active set updated within the iterations; None: after each converged solve); a
    solve whose sets have not changed then goes on from where it stopped. Sets still changing
    after ``max_outer`` changes cycle (a node grazing the tool or at the friction cap, in and out on alternate
    solves): up to ``max_outer`` more let the sets only grow (:meth:`StepContact.freeze` with ``grow``), which ends
    the cycle, before the last solve with the sets free. A solve that fails (``max_iter`` corrections since the
    sets last changed) with a frozen slip turned against its direction (:meth:`StepContact.stick_reversed`) is made
    again from the same start with that node stuck for the step (it counts as one change of the sets; three such at
    most). Each solve after the first starts from the one before's du and p (with p from t_n instead, a solve whose
    sets had not changed took an iteration to find the pressures again). The result's ``iterations`` counts those
    of every solve."""
    if settle is not None and not (isinstance(settle, (int, np.integer)) and settle >= 2):
        raise ValueError(f"settle must be None or a whole number of at least 2 corrections, got {settle!r} (the "
                         "round-off stopping rule of newton_step needs three residuals of one solve)")
    c = loads.contact
    c.freeze(nodes.x)
    total, pattern, sticks, changes, since = 0, {}, 0, 0, 0              # the solves share the mesh's pattern
    du, p = start = (du0, None)                                          # start: where the sets' solve began
    ev = None                                                 # the residual at (du, p) where the sets did not change
    while changes < 2 * max_outer:
        try:
            r = newton_step(nodes, mesh, hist, law, dt, loads, dynamic=dynamic, predictor=False,
                            max_iter=max_iter - since, max_move=max_move, du0=du, p0=p, pattern=pattern,
                            settle=settle, start=ev)
            since += r.iterations
            if not r.converged and since >= max_iter:
                raise NewtonFailed(f"Newton-Raphson did not converge in {max_iter} iterations with the contact's "
                                   f"sets unchanged (residuals {r.residuals[-3:]})", r.residuals, (r.du, r.p))
        except NewtonFailed as e:                                 # a frozen slip that turned: it sticks, and the
            if sticks >= 3 or len(e.args) < 3 or not c.stick_reversed(nodes.x + e.args[2][0]):   # solve starts
                raise                                                                             # again
            total, sticks, changes, since, ev = total + len(e.args[1]), sticks + 1, changes + 1, 0, None
            du, p = start
            continue
        du, p, total, ev = r.du, r.p, total + r.iterations, r.evaluation
        if c.freeze(nodes.x + r.du, grow=changes >= max_outer - 1):
            changes, since, start, ev = changes + 1, 0, (du, p), None
        elif r.converged:
            c.active = c.slip = None
            last = newton_step(nodes, mesh, hist, law, dt, loads, dynamic=dynamic, predictor=False,
                               max_iter=max_iter, max_move=max_move, du0=r.du, p0=r.p, pattern=pattern)  # sets free
            last.solves_iterations = total + last.iterations
            return last
    raise NewtonFailed(f"the contact's active set changed {2 * max_outer} times", [])
