"""Scene ``spinning_disc``: a free elastic AISI 4340 disc (2D plane strain), radius 5 mm, set spinning as a rigid
body, v = omega e_z x (x - c), with its rim at ``speed`` times the dilatational wave speed c_L; it should go on
spinning for ``turns`` of a turn with its angular momentum and energy unchanged.

What a correct method does: a rigid rotation has no strain rate, so the only stress is the centrifugal one, of the
order of rho omega^2 R^2 (the disc starts unstressed, so it breathes about that state); at the default rim speed,
0.2 % of c_L (12 m/s), that is 2e-4 of the stress E * 1 % a 1 % strain gives. The measured ``max_stress_over_1pct``
says how far above that a method goes. Uncorrected ESPH reads the rotation as a strain rate in the outer layers
(Eq. (23) at a free surface), builds stress turn after turn and stops the disc (chapter 10; ``esph_correction``
cures it); TLSPH (corrected) and corrected ESPH keep it spinning.

Metrics: ``angular_momentum_ratio`` (final / initial, about the centre of mass), ``energy_ratio`` (kinetic +
elastic, final / initial), ``max_stress_over_1pct`` (largest von Mises stress of the run / (E * 0.01)),
``centrifugal_stress_over_1pct`` ((3 + nu)/8 rho omega^2 R^2 / (E * 0.01), the scale of the physical stress),
``min_pair_distance_over_dp``, ``n_fragments`` (pieces held together within 1.5 dp).
"""
from __future__ import annotations

import numpy as np

from ..state import make_state
from .base import Numerics, Scene, Setup
from .measure import (aisi4340_material, angular_momentum, disc, elastic_energy, kinetic_energy, min_pair_distance,
                      n_fragments, von_mises_max)

__all__ = ["SCENE"]

RADIUS = 5e-3
OPTIONS = {
    "speed": (0.002, "rim speed / c_L (0.002: 12 m/s; 0.01: 1 % of the sound speed)"),
    "turns": (0.25, "end time in turns of the disc"),
}


def _default_dp(dim, quick):
    return 0.5e-3 if quick else 0.25e-3


def _build(dim, dp, quick, *, speed, turns):
    if dim != 2:
        raise ValueError("the spinning disc is a 2D (plane strain) scene")
    if not (0 < speed < 0.5 and turns > 0):
        raise ValueError(f"need 0 < speed < 0.5 and turns > 0, got speed={speed!r}, turns={turns!r}")
    mat = aisi4340_material()
    x = disc(RADIUS, dp)
    omega = speed * mat.c_longitudinal / RADIUS
    v = omega * np.stack([-x[:, 1], x[:, 0]], axis=1)
    state = make_state(x, v, mat.rho0, dp * dp)
    t_end = turns * 2.0 * np.pi / omega
    stress_1pct = 0.01 * mat.E
    centrifugal = (3.0 + mat.nu) / 8.0 * mat.rho0 * (omega * RADIUS) ** 2
    return Setup(state=state, material=mat, dp=dp, numerics=Numerics(), t_end=float(t_end), n_snapshots=8,
                 info=dict(radius=RADIUS, omega=float(omega), rim_speed=float(omega * RADIUS), speed=float(speed),
                           turns=float(turns), stress_1pct_Pa=float(stress_1pct),
                           centrifugal_stress_Pa=float(centrifugal)))


def _record(state, setup):
    return dict(t=state.t, L=angular_momentum(state), E_kin=kinetic_energy(state),
                E_el=elastic_energy(state, setup.material), sigma_max=von_mises_max(state),
                min_pair=min_pair_distance(state.x, 1.5 * setup.dp) / setup.dp)


def _metrics(hist, state, setup):
    info = setup.info
    L = np.asarray(hist["L"])
    E = np.asarray(hist["E_kin"]) + np.asarray(hist["E_el"])
    return dict(
        angular_momentum_ratio=float(L[-1] / L[0]),
        energy_ratio=float(E[-1] / E[0]),
        max_stress_over_1pct=float(np.max(hist["sigma_max"]) / info["stress_1pct_Pa"]),
        centrifugal_stress_over_1pct=info["centrifugal_stress_Pa"] / info["stress_1pct_Pa"],
        min_pair_distance_over_dp=float(np.min(hist["min_pair"])),
        n_fragments=n_fragments(state.x, 1.5 * setup.dp),
        angular_momentum_history=np.stack([hist["t"], L / L[0]], axis=1),
        stress_history=np.stack([hist["t"], np.asarray(hist["sigma_max"]) / info["stress_1pct_Pa"]], axis=1),
    )


SCENE = Scene("spinning_disc", "free elastic disc spinning as a rigid body: objectivity (angular momentum, stress)",
              _default_dp, _build, _record, _metrics, options=OPTIONS, default_dim=2, methods=("esph", "tlsph"))
