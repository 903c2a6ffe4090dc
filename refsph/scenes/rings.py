"""Scene ``rings``: two elastic AISI 4340 rings (2D plane strain), inner radius 3 mm, outer 4 mm, thrown at each
other along x at +-``speed`` times c_L each (Gray, Monaghan & Swift 2001, CMAME 190, 6641: their rings and their
0.059 c). Elastic rings should bounce off each other and fly apart whole.

* TLSPH: each ring is its own body (body ids 0 and 1); its neighbours are those of its own ring, and the rings
  meet through the pinball contact (Eqs. (32)-(36), both sides deformable).
* ESPH: the rings are one continuum to the SPH sums once within 2h (no contact law; the solver warns): pressure
  pushes them apart, but in tension they stick and swap particles, and without artificial pressure (gamma = 0)
  the tensile instability breaks them up (Gray, Monaghan & Swift's point; chapter 10).

Metrics: ``n_fragments`` at the end (pieces within 1.5 dp; 2 = both rings whole and apart), ``restitution`` (the
relative speed of the rings' centres of mass after / before), ``energy_ratio`` (kinetic + elastic, end / start),
``min_pair_distance_over_dp`` (any two particles, over the run), ``min_interbody_distance_over_dp`` (closest
particles of different rings, over the run: interpenetration shows as values well below 1),
``final_interbody_distance_over_dp``, ``momentum_drift_rel`` (|P(t) - P(0)| / (M v0), largest).
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..state import make_state
from .base import Numerics, Scene, Setup
from .measure import (aisi4340_material, annulus, elastic_energy, kinetic_energy, linear_momentum,
                      min_pair_distance, n_fragments)

__all__ = ["SCENE"]

R_IN, R_OUT = 3e-3, 4e-3
OPTIONS = {
    "speed": (0.059, "speed of each ring / c_L (Gray, Monaghan & Swift: 0.059)"),
    "gap": (2.0, "initial gap between the rings' outer particle centres, in spacings"),
}


def _default_dp(dim, quick):
    return 0.25e-3 if quick else 0.125e-3


def _build(dim, dp, quick, *, speed, gap):
    if dim != 2:
        raise ValueError("the rings are a 2D (plane strain) scene")
    if not (0 < speed < 0.5 and gap > 0):
        raise ValueError(f"need 0 < speed < 0.5 and gap > 0, got speed={speed!r}, gap={gap!r}")
    mat = aisi4340_material()
    xc = R_OUT - 0.5 * dp + 0.5 * gap * dp               # outer centres at +-(gap/2) dp from x = 0
    a, b = annulus(R_IN, R_OUT, dp, (-xc, 0.0)), annulus(R_IN, R_OUT, dp, (xc, 0.0))
    x = np.concatenate([a, b])
    v0 = speed * mat.c_longitudinal
    v = np.zeros_like(x)
    v[:len(a), 0], v[len(a):, 0] = v0, -v0
    body = np.concatenate([np.zeros(len(a), dtype=int), np.ones(len(b), dtype=int)])
    state = make_state(x, v, mat.rho0, dp * dp, body=body)
    t_end = 12.0 * R_OUT / v0                            # approach, contact, and the rings well apart again
    return Setup(state=state, material=mat, dp=dp, numerics=Numerics(), t_end=float(t_end), n_snapshots=8,
                 info=dict(r_inner=R_IN, r_outer=R_OUT, v0=float(v0), speed=float(speed), gap=float(gap)))


def _centre_velocities(state):
    out = []
    for b in (0, 1):
        k = state.body == b
        out.append(np.sum(state.m[k, None] * state.v[k], axis=0) / np.sum(state.m[k]))
    return out


def _interbody_distance(state) -> float:
    a, b = state.x[state.body == 0], state.x[state.body == 1]
    return float(cKDTree(b).query(a)[0].min())


def _record(state, setup):
    va, vb = _centre_velocities(state)
    P = linear_momentum(state)
    return dict(t=state.t, u_rel=float(vb[0] - va[0]), E_kin=kinetic_energy(state),
                E_el=elastic_energy(state, setup.material), Px=float(P[0]), Py=float(P[1]),
                min_pair=min_pair_distance(state.x, 1.5 * setup.dp) / setup.dp,
                gap=_interbody_distance(state) / setup.dp)


def _metrics(hist, state, setup):
    u = np.asarray(hist["u_rel"])
    E = np.asarray(hist["E_kin"]) + np.asarray(hist["E_el"])
    P = np.stack([hist["Px"], hist["Py"]], axis=1)
    gap = np.asarray(hist["gap"])
    return dict(
        n_fragments=n_fragments(state.x, 1.5 * setup.dp),
        restitution=float(-u[-1] / u[0]),
        energy_ratio=float(E[-1] / E[0]),
        min_pair_distance_over_dp=float(np.min(hist["min_pair"])),
        min_interbody_distance_over_dp=float(np.min(gap)),
        final_interbody_distance_over_dp=float(gap[-1]),
        momentum_drift_rel=float(np.max(np.abs(P - P[0])) / (np.sum(state.m) * setup.info["v0"])),
        relative_velocity_history=np.stack([hist["t"], u], axis=1),
        interbody_distance_history=np.stack([hist["t"], gap], axis=1),
    )


SCENE = Scene("rings", "two elastic rings thrown at each other (Gray, Monaghan & Swift 2001): contact, fracture",
              _default_dp, _build, _record, _metrics, options=OPTIONS, default_dim=2, methods=("esph", "tlsph"))
