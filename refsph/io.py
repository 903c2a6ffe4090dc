"""Run output: ``summary.json`` and snapshots ``snapshots/snap_NNNNN.npz``, with loaders.

A run directory holds

    summary.json              scene, method, dim, dp, h, n_particles, n_steps, wall_time_s, status, metrics, ...
    snapshots/snap_00000.npz  one file per output time (NumPy .npz, arrays below, SI units)
    snapshots/last_good.npz   only after a failure: the last state that was finite
    reaction_forces.csv       scenes with rigid bodies or clamps: the force on each, every step (below)

Snapshot arrays (N particles, d dimensions):

| key       | shape     | unit          | meaning                                              |
|-----------|-----------|---------------|------------------------------------------------------|
| t         | ()        | s             | time                                                 |
| x, v      | (N, d)    | m, m/s        | position, velocity                                   |
| m         | (N,)      | kg (2D: kg/m) | mass                                                 |
| rho       | (N,)      | kg/m^3        | density                                              |
| p         | (N,)      | Pa            | pressure, Eq. (24)                                   |
| S         | (N, d, d) | Pa            | deviatoric Cauchy stress (in-plane block in 2D)      |
| S_zz      | (N,)      | Pa            | out-of-plane deviatoric stress (2D plane strain)     |
| sigma_vm  | (N,)      | Pa            | von Mises stress sqrt(3 J2), S_zz included           |
| X, V0     | (N, d), (N,) | m, m^d     | reference position and volume (TLSPH)                |
| F         | (N, d, d) | -             | deformation gradient (TLSPH only)                    |
| eps_p     | (N,)      | -             | effective plastic strain (plasticity runs only)      |
| eps_dot_p | (N,)      | 1/s           | plastic strain rate of the last step (plasticity)    |
| W_p       | (N,)      | J/m^3         | plastic work density (plasticity)                    |
| T         | (N,)      | K             | temperature (plasticity)                             |
| body      | (N,)      | -             | body id (scenes with tools: 0 workpiece, see summary["boundaries"]) |
| units     | ()        | -             | JSON string: unit of every key                       |

``reaction_forces.csv``: a comment line, a header ``t,dt,<name>_x,<name>_y[,<name>_z],...`` and one row per
time step: the midpoint time of the step [s], its size [s] and the force the rest of the system exerted on each
rigid body or clamp during it [N; 2D: N per metre of thickness] (sum of force x dt = impulse).
``load_reactions`` reads it back.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from .material import eos_pressure, von_mises
from .state import FIELD_UNITS, State

__all__ = ["save_snapshot", "load_snapshot", "load_run", "write_json", "json_ready", "save_reactions", "load_reactions",
           "SNAPSHOT_UNITS"]

SNAPSHOT_UNITS = dict(FIELD_UNITS, p="Pa", sigma_vm="Pa", F="1")


def save_snapshot(path, state: State, material, F: np.ndarray | None = None) -> None:
    """Write one snapshot (atomically: a crash never leaves a half-written file)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays = dict(
        t=np.float64(state.t), x=state.x, v=state.v, m=state.m, rho=state.rho,
        p=eos_pressure(state.rho, material.rho0, material.K), S=state.S, S_zz=state.S_zz,
        sigma_vm=von_mises(state.S, state.S_zz), X=state.X, V0=state.V0,
    )
    if F is not None:
        arrays["F"] = F
    if state.plastic:
        arrays.update(eps_p=state.eps_p, eps_dot_p=state.eps_dot_p, W_p=state.W_p, T=state.T)
    if state.body is not None:
        arrays["body"] = state.body
    units = {k: SNAPSHOT_UNITS[k] for k in arrays}
    tmp = path.with_name(path.name + ".tmp.npz")
    np.savez(tmp, units=json.dumps(units), **arrays)
    os.replace(tmp, path)


def load_snapshot(path) -> dict:
    """Snapshot as a dict of arrays (``t`` a float, ``units`` a dict)."""
    with np.load(path, allow_pickle=False) as z:
        out = {k: z[k] for k in z.files}
    out["units"] = json.loads(str(out["units"]))
    out["t"] = float(out["t"])
    return out


def load_run(directory) -> tuple[dict, list[Path]]:
    """(summary dict, sorted list of snapshot paths) of a run directory."""
    directory = Path(directory)
    with open(directory / "summary.json") as f:
        summary = json.load(f)
    snaps = sorted((directory / "snapshots").glob("snap_*.npz"))
    return summary, snaps


def json_ready(o):
    """``o`` with arrays as lists and non-finite floats (nan, inf) as None, so that the file is strict JSON
    (``null``), which every JSON reader loads; a measurement that could not be made is null."""
    if isinstance(o, dict):
        return {k: json_ready(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [json_ready(v) for v in o]
    if isinstance(o, np.ndarray):
        return json_ready(o.tolist())
    if isinstance(o, (np.floating, float)):
        return float(o) if np.isfinite(o) else None
    if isinstance(o, (np.integer, np.bool_)):
        return o.item()
    return o


def write_json(path, data: dict) -> None:
    """Write strict JSON (:func:`json_ready`: nan -> null) atomically (temporary file, then rename)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w") as f:
        json.dump(json_ready(data), f, indent=2, allow_nan=False)
        f.write("\n")
    os.replace(tmp, path)


def save_reactions(path, reactions: dict, dim: int) -> None:
    """Write the reaction history (``{'t': (n,), name: (n, d)}``) as CSV, atomically."""
    path = Path(path)
    names = [k for k in reactions if k not in ("t", "dt")]
    axes = "xyz"[:dim]
    cols = [reactions["t"][:, None], reactions["dt"][:, None]] + [np.asarray(reactions[k]).reshape(-1, dim)
                                                                  for k in names]
    header = ",".join(["t", "dt"] + [f"{k}_{a}" for k in names for a in axes])
    tmp = path.with_name(path.name + ".tmp")
    np.savetxt(tmp, np.hstack(cols), delimiter=",", fmt="%.9e",
               header="refsph reaction forces: t [s] (step midpoint), dt [s] (step size), force on each body "
                      "[N; 2D: N/m]\n" + header,
               comments="# ")
    os.replace(tmp, path)


def load_reactions(path) -> dict:
    """``reaction_forces.csv`` back as {'t': (n,), name: (n, d)}."""
    with open(path) as f:
        f.readline()
        header = f.readline().lstrip("# ").strip().split(",")
    data = np.loadtxt(path, delimiter=",", comments="#", ndmin=2)
    out = {"t": data[:, 0], "dt": data[:, 1]}
    for k, col in enumerate(header[2:], start=2):
        name = col.rsplit("_", 1)[0]
        out.setdefault(name, []).append(data[:, k])
    return {k: (np.stack(v, axis=1) if k not in ("t", "dt") else v) for k, v in out.items()}
