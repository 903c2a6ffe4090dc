"""Scene ``bar``: a free-free elastic AISI 4340 bar, 20 x 2 mm (x 2 mm in 3D), in its first axial mode,
v_x(X, 0) = v0 cos(pi X / L). Its period is T = 2 L / c_bar: the measured wave speed, energy and momentum drift
test the elastic part of both formulations (chapters 02 and 03)."""
from __future__ import annotations

import numpy as np

from ..state import make_state
from .base import Numerics, Scene, Setup
from .measure import (aisi4340_material, elastic_energy, kinetic_energy, lattice, linear_momentum,
                      zero_crossings)

__all__ = ["SCENE", "period_and_wave_speed"]


def _geometry(dim):
    L, W = 20e-3, 2e-3
    return L, W, ([L, W] if dim == 2 else [L, W, W])


def _default_dp(dim, quick):
    _, W, _ = _geometry(dim)
    if dim == 2:
        return W / (8 if quick else 16)
    return W / (4 if quick else 8)


def _build(dim, dp, quick):
    """Free-free elastic bar, first axial mode: v_x(X, 0) = v0 cos(pi X / L). Period T = 2 L / c_bar."""
    L, W, lengths = _geometry(dim)
    mat = aisi4340_material()
    x = lattice(lengths, dp)
    v0 = 1.0
    v = np.zeros_like(x)
    v[:, 0] = v0 * np.cos(np.pi * x[:, 0] / L)
    state = make_state(x, v, mat.rho0, dp**dim)
    period = 2.0 * L / mat.c_bar(dim)
    return Setup(state=state, material=mat, dp=dp, numerics=Numerics(), t_end=2.0 * period, n_snapshots=10,
                 info=dict(L=L, W=W, v0=v0, period_theory=period))


def _record(state, setup):
    L = setup.info["L"]
    phi = np.cos(np.pi * state.X[:, 0] / L)
    amp = float(np.sum(state.m * state.v[:, 0] * phi) / np.sum(state.m * phi * phi))
    P = linear_momentum(state)
    return dict(t=state.t, amplitude=amp, E_kin=kinetic_energy(state),
                E_el=elastic_energy(state, setup.material), Px=float(P[0]), Py=float(P[1]))


def period_and_wave_speed(t: np.ndarray, amplitude: np.ndarray, L: float) -> tuple[float, float]:
    """The period T of the first axial mode, twice the mean spacing of the amplitude's zero crossings, and the
    wave speed c = 2 L / T (NaN without two crossings). Used for refsph's runs and for other codes' output."""
    tz = zero_crossings(np.asarray(t, dtype=float), np.asarray(amplitude, dtype=float))
    if len(tz) < 2:
        return float("nan"), float("nan")
    period = 2.0 * float(np.mean(np.diff(tz)))
    return period, 2.0 * L / period


def _metrics(hist, state, setup):
    t, a = np.asarray(hist["t"]), np.asarray(hist["amplitude"])
    L = setup.info["L"]
    c_th = setup.material.c_bar(state.dim)
    period, c = period_and_wave_speed(t, a, L)
    E = np.asarray(hist["E_kin"]) + np.asarray(hist["E_el"])
    P = np.stack([hist["Px"], hist["Py"]], axis=1)
    p_scale = float(np.sum(state.m)) * setup.info["v0"]
    return dict(
        period_s=period,
        wave_speed_m_s=c,
        wave_speed_theory_m_s=c_th,
        wave_speed_rel_error=(c - c_th) / c_th,
        energy_history=np.stack([t, hist["E_kin"], hist["E_el"]], axis=1),
        amplitude_history=np.stack([t, a], axis=1),
        energy_final_over_initial=float(E[-1] / E[0]),
        momentum_drift_rel=float(np.max(np.abs(P - P[0])) / p_scale),
    )


SCENE = Scene("bar", "free-free elastic AISI 4340 bar 20 x 2 mm in its first axial mode: wave speed, energy, momentum",
              _default_dp, _build, _record, _metrics)
