"""Scene ``tension``: an elastic AISI 4340 block, 10 x 10 mm, expanding in free flight, so that it goes into
tension: the tensile instability (particles clumping in pairs) shows as a small minimum pair distance."""
from __future__ import annotations

import numpy as np

from ..material import eos_pressure
from ..state import make_state
from .base import Numerics, Scene, Setup
from .measure import aisi4340_material, lattice, min_pair_distance

__all__ = ["SCENE"]


def _default_dp(dim, quick):
    return (0.5e-3 if quick else 0.25e-3) if dim == 2 else 1.0e-3


def _build(dim, dp, quick):
    """Square (cubic) block in free flight with a uniform expansion v = rate (x - x_c) (edge speed 300 m/s)
    that puts it in tension (down to about -15 GPa in the first breathing cycle); a 1 % random lattice
    perturbation (fixed seed) seeds the tensile instability. Artificial viscosity beta1 = beta2 = 0.5 (the paper's
    Tables 4-5): with 1.5 the breathing is damped out before clumping can grow. t_end = 24 side / c_L (about
    40 us)."""
    side = 10e-3
    mat = aisi4340_material()
    x = lattice([side] * dim, dp)
    rng = np.random.default_rng(12345)
    x = x + 0.01 * dp * rng.uniform(-1.0, 1.0, size=x.shape)
    v_edge = 300.0
    rate = v_edge / (0.5 * side)
    v = rate * (x - 0.5 * side)
    state = make_state(x, v, mat.rho0, dp**dim)
    t_end = 24.0 * side / mat.c_longitudinal
    return Setup(state=state, material=mat, dp=dp, numerics=Numerics(beta1=0.5, beta2=0.5), t_end=t_end,
                 n_snapshots=10, info=dict(side=side, v_edge=v_edge))


def _record(state, setup):
    p = eos_pressure(state.rho, setup.material.rho0, setup.material.K)
    return dict(t=state.t, min_pair_distance_over_dp=min_pair_distance(state.x, 1.5 * setup.dp) / setup.dp,
                min_pressure_Pa=float(np.min(p)))


def _metrics(hist, state, setup):
    r = np.asarray(hist["min_pair_distance_over_dp"])
    return dict(
        min_pair_distance_over_dp=float(np.min(r)),
        final_min_pair_distance_over_dp=float(r[-1]),
        min_pair_distance_history=np.stack([hist["t"], r], axis=1),
        min_pressure_Pa=float(np.min(hist["min_pressure_Pa"])),
    )


SCENE = Scene("tension",
              "elastic AISI 4340 block 10 x 10 mm expanding in free flight: tensile instability (min pair distance)",
              _default_dp, _build, _record, _metrics)
