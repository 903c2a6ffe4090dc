"""Run output: ``summary.json`` and snapshots ``snapshots/snap_NNNNN.npz``, with loaders.

A run directory holds

    summary.json              scene, method, dim, dp, h, n_particles, n_steps, wall_time_s, status, metrics, ...
    snapshots/snap_00000.npz  one file per output time (NumPy .npz, arrays below, SI units): numbers only
    snapshots/units.json      the unit of every snapshot array, {"t": "s", "x": "m", ...}: once per run folder
    snapshots/last_good.npz   only after a failure: the last state that was finite
    snapshots/restart.npz     the last checkpoint (solver state, history) for refsph run --restart: written at
                              every snapshot and, between them, every 10 minutes of wall time (its state then in
                              snapshots/checkpoint_a.npz, _b or _c, in turn; removed when the run ends well);
                              restart_prev.npz: the one before
    reaction_forces.csv       scenes with rigid bodies or clamps: the force on each, every step (below)

Snapshot arrays (N particles, d dimensions):

| key       | shape     | unit          | meaning                                              |
|-----------|-----------|---------------|------------------------------------------------------|
| t         | ()        | s             | time                                                 |
| id        | (N,)      | -             | particle id: its row in the initial state (never reordered) |
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

Every entry is a plain number array (float64; ``id`` int64, ``body`` int32), so that any npz reader, a C or C++
one too, reads every snapshot; the units are in ``snapshots/units.json`` beside them (the same arrays in every
snapshot of a run, ``last_good.npz`` included), not in the npz. Snapshots of earlier refsph versions
carry them as a 0-d unicode array ``units`` holding that JSON; :func:`load_snapshot` reads both.

``reaction_forces.csv``: a comment line, a header ``t,dt,<name>_x,<name>_y[,<name>_z],...`` and one row per
time step: the midpoint time of the step [s], its size [s] and the force the rest of the system exerted on each
rigid body or clamp during it [N; 2D: N per metre of thickness] (sum of force x dt = impulse).
``load_reactions`` reads it back.
"""
from __future__ import annotations

import json
import zipfile
import os
import socket
import time
from pathlib import Path

import numpy as np

from .material import eos_pressure, von_mises
from .state import FIELD_UNITS, PLASTIC_FIELDS, State

__all__ = ["run_files", "claim_run_folder", "save_snapshot", "write_snapshot", "save_units", "load_snapshot",
           "state_from_snapshot", "state_from_particles", "load_run", "write_json", "json_ready", "save_reactions",
           "load_reactions", "analyse_cutting_run", "SNAPSHOT_UNITS", "UNITS_FILE"]

SNAPSHOT_UNITS = dict(FIELD_UNITS, p="Pa", sigma_vm="Pa", F="1", id="1 (particle id)")
UNITS_FILE = "units.json"       # snapshots/units.json: the unit of every snapshot array (module text)


def save_snapshot(path, state: State, material, F: np.ndarray | None = None, ids: np.ndarray | None = None) -> None:
    """Write one snapshot, numbers only, and the units of its arrays in ``units.json`` beside it (:func:`save_units`;
    both atomically: a crash never leaves a half-written file). ``ids``: the particles' ids, if not their rows
    (particles read with ``--from`` keep the ids of their file)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays = dict(
        t=np.float64(state.t), x=state.x, v=state.v, m=state.m, rho=state.rho,
        p=eos_pressure(state.rho, material.rho0, material.K), S=state.S, S_zz=state.S_zz,
        sigma_vm=von_mises(state.S, state.S_zz), X=state.X, V0=state.V0,
        id=np.arange(state.n, dtype=np.int64) if ids is None else np.asarray(ids, dtype=np.int64),
    )                                                   # refsph never reorders particles: by default the id is the row
    if F is not None:
        arrays["F"] = F
    if state.plastic:
        arrays.update(eps_p=state.eps_p, eps_dot_p=state.eps_dot_p, W_p=state.W_p, T=state.T)
    if state.body is not None:
        arrays["body"] = state.body
    write_snapshot(path, arrays, SNAPSHOT_UNITS)


def write_snapshot(path, arrays: dict, units: dict) -> None:
    """Write ``arrays`` (numbers only) as the snapshot ``path`` and their units (``units``: {array: unit}, a
    superset) in ``units.json`` beside it, both atomically: a crash never leaves a half-written file."""
    path = Path(path)
    save_units(path.parent, {k: units[k] for k in arrays})
    tmp = path.with_name(path.name + ".tmp.npz")
    np.savez(tmp, **arrays)
    os.replace(tmp, path)


def save_units(folder, units: dict) -> None:
    """``folder/units.json``: {array: unit} of the snapshots in ``folder``, written atomically (:func:`write_json`),
    once: a file that already says exactly this is left as it is."""
    path = Path(folder) / UNITS_FILE
    try:
        if json.loads(path.read_text()) == units:
            return
    except (OSError, ValueError):
        pass
    write_json(path, units)


def read_npz(path, what: str = "file") -> dict:
    """Every array of an ``.npz`` file; a file that is missing, truncated or not an npz is a ValueError naming it
    (not NumPy's or zipfile's bare message)."""
    try:
        with np.load(path, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise ValueError(f"{path}: no such {what}") from None
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as e:
        raise ValueError(f"{path}: not a readable {what} (truncated or not an .npz: {type(e).__name__}: {e})") from None


def read_json(path, what: str = "file"):
    """A JSON file's content; missing or invalid is a ValueError naming the file."""
    try:
        return json.loads(Path(path).read_text())
    except FileNotFoundError:
        raise ValueError(f"{path}: no such {what}") from None
    except (OSError, ValueError) as e:
        raise ValueError(f"{path}: not a readable {what} (invalid JSON: {e})") from None


def _snapshot_arrays(path) -> tuple[dict, str | None]:
    """A snapshot's arrays (``t`` a float) and the JSON text of an old snapshot's ``units`` entry (None in a
    snapshot of numbers only); ValueError naming the file if it cannot be read or lacks ``t``, ``x``."""
    out = read_npz(path, "snapshot")
    missing = [k for k in ("t", "x") if k not in out]
    if missing:
        raise ValueError(f"{path}: not a refsph snapshot (no {', '.join(missing)})")
    text = out.pop("units", None)
    out["t"] = float(out["t"])
    return out, None if text is None else str(text)


def load_snapshot(path) -> dict:
    """Snapshot as a dict of arrays (``t`` a float) and ``units``: {array: unit} from ``units.json`` beside it (an
    old snapshot's own ``units`` entry where it has one; {} where neither is there); ValueError naming the file if
    the snapshot or the units file cannot be read, or the snapshot lacks ``t``, ``x``."""
    out, text = _snapshot_arrays(path)
    beside = Path(path).parent / UNITS_FILE
    if text is not None:
        units = json.loads(text)
    else:
        units = read_json(beside, "units file") if beside.is_file() else {}
    if not isinstance(units, dict):
        raise ValueError(f"{beside if text is None else path}: the units are not a JSON object of array: unit")
    out["units"] = {k: u for k, u in units.items() if k in out}
    return out


def state_from_snapshot(snap) -> State:
    """A :class:`~refsph.state.State` from a snapshot (a path, or the dict :func:`load_snapshot` gives); the units
    are not read (a restart does not need them)."""
    z = _snapshot_arrays(snap)[0] if isinstance(snap, (str, Path)) else snap
    extra = {k: np.array(z[k]) for k in PLASTIC_FIELDS + ("body",) if k in z}
    return State(x=np.array(z["x"]), v=np.array(z["v"]), m=np.array(z["m"]), rho=np.array(z["rho"]),
                 S=np.array(z["S"]), S_zz=np.array(z["S_zz"]), X=np.array(z["X"]), V0=np.array(z["V0"]),
                 t=float(z["t"]), **extra)


def state_from_particles(path, rho0: float, T0: float | None, clamp_names=()) -> tuple[State, dict, np.ndarray | None]:
    """An external particle set (``.npz``) as a State, the clamps' index arrays it gives, and its particle ids.

    Required arrays: ``x`` (N, d) [m], ``v`` (N, d) [m/s], ``m`` (N,) [kg; 2D: kg/m]. Optional: ``body`` (N,)
    (ids of rigid bodies, their rows last; needed where the scene has tools), ``rho`` (default rho0), ``S``
    (N, d, d) and ``S_zz`` (N,) [Pa] (default 0), ``X`` (default x), ``V0`` (default m / rho0), ``T`` (default
    ``T0``) and ``eps_p``, ``eps_dot_p``, ``W_p`` (default 0) for a plasticity law, ``clamp_<name>`` index
    arrays for every clamp of the scene, and ``id`` (N,) distinct integers: the particles' ids, which the run's
    snapshots then carry (None: the rows). Errors name the missing or inconsistent array."""
    with np.load(path, allow_pickle=False) as z:
        a = {k: z[k] for k in z.files}
    missing = [k for k in ("x", "v", "m") if k not in a]
    if missing:
        raise ValueError(f"{path}: missing array(s) {', '.join(missing)} (x (N, d), v (N, d), m (N,) are needed)")
    x = np.asarray(a["x"], dtype=float)
    if x.ndim != 2 or x.shape[1] not in (2, 3):
        raise ValueError(f"{path}: x must have shape (N, 2) or (N, 3), got {x.shape}")
    n, d = x.shape
    shapes = dict(v=(n, d), m=(n,), body=(n,), rho=(n,), S=(n, d, d), S_zz=(n,), X=(n, d), V0=(n,), T=(n,),
                  eps_p=(n,), eps_dot_p=(n,), W_p=(n,), id=(n,))
    for k, shape in shapes.items():
        if k in a and np.shape(a[k]) != shape:
            raise ValueError(f"{path}: array {k} has shape {np.shape(a[k])}, expected {shape} (N = {n} from x)")
    m = np.asarray(a["m"], dtype=float)
    _, first, count = np.unique(x, axis=0, return_index=True, return_counts=True)
    if np.any(count > 1):
        k = int(first[np.argmax(count > 1)])
        twin = int(np.flatnonzero(np.all(x == x[k], axis=1))[1])
        raise ValueError(f"{path}: particles {k} and {twin} sit at the same position {x[k].tolist()} (and "
                         f"{int(np.sum(count[count > 1] - 1)) - 1} more coincident); SPH needs distinct particles")
    plastic = T0 is not None
    state = State(x=x, v=np.asarray(a["v"], dtype=float), m=m, rho=np.asarray(a.get("rho", np.full(n, rho0)), float),
                  S=np.asarray(a.get("S", np.zeros((n, d, d))), float), S_zz=np.asarray(a.get("S_zz", np.zeros(n)),
                                                                                         float),
                  X=np.asarray(a.get("X", x), float), V0=np.asarray(a.get("V0", m / rho0), float),
                  body=np.asarray(a["body"], dtype=np.int32) if "body" in a else None,
                  **({k: np.asarray(a.get(k, np.zeros(n) if k != "T" else np.full(n, T0)), float)
                      for k in PLASTIC_FIELDS} if plastic else {}))
    state.check()
    clamps = {}
    for name in clamp_names:
        if f"clamp_{name}" not in a:
            raise ValueError(f"{path}: the scene holds particles by the clamp {name!r}: give their indices as "
                             f"clamp_{name}")
        clamps[name] = np.asarray(a[f"clamp_{name}"])
    ids = None
    if "id" in a:
        ids = np.asarray(a["id"])
        if ids.dtype.kind not in "iu" or len(np.unique(ids)) != n:
            raise ValueError(f"{path}: id must hold N = {n} distinct integers (the particles' ids), got "
                             f"dtype {ids.dtype} with {len(np.unique(ids))} distinct values")
    return state, clamps, ids


def load_run(directory) -> tuple[dict, list[Path]]:
    """(summary dict, sorted list of snapshot paths) of a run directory."""
    directory = Path(directory)
    summary = read_json(directory / "summary.json", "run summary")
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


PROGRESS = "progress.json"          # a run folder's heartbeat (write_progress) ...
HEARTBEAT_S = 30.0                  # ... written this often [s of wall time] by the run loops
RUN_FILE_PATTERNS = ("summary.json", "summary.json.tmp", PROGRESS, PROGRESS + ".tmp", "reaction_forces.csv",
                     "reaction_forces.csv.tmp",
                     "snapshots/snap_[0-9][0-9][0-9][0-9][0-9].npz", "snapshots/*.tmp.npz", "snapshots/restart.npz",
                     "snapshots/restart_prev.npz", "snapshots/checkpoint_[abc].npz", "snapshots/last_good.npz",
                     f"snapshots/{UNITS_FILE}", f"snapshots/{UNITS_FILE}.tmp",
                     "vtk/snap_[0-9][0-9][0-9][0-9][0-9].vtu", "vtk/run.pvd", "vtk/units.json")


def run_files(folder) -> list[Path]:
    """The files of ``folder`` that refsph writes in a run folder (``RUN_FILE_PATTERNS``: the summary, the
    reaction CSV, the snapshots, their units and the restart checkpoint, ``refsph export``'s VTK files); nothing
    else."""
    folder = Path(folder)
    return sorted({p for pattern in RUN_FILE_PATTERNS for p in folder.glob(pattern) if p.is_file()})


def claim_run_folder(out, scene: str, method: str, overwrite: bool = False) -> list[Path]:
    """Make ``out`` ready for a run of ``scene`` with ``method``, losing nothing that refsph did not write: a
    missing or empty folder is taken; a run folder of the same scene and method has its old run files removed
    (:func:`run_files`; other files stay); anything else (another scene's or method's run, a folder that is not a
    run, a file) is refused with a ValueError that says what is there, unless ``overwrite``, which removes only
    refsph's run files and keeps every other file. Returns the files kept that refsph did not write."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out} is a file, not a folder")
    blocking = next((p for p in out.parents if p.exists() and not p.is_dir()), None)
    if blocking is not None:           # e.g. --out FILE for a scene run with two methods (FILE/esph, FILE/tlsph)
        raise ValueError(f"--out {out}: {blocking} is a file, not a folder")
    if not out.exists():
        return []
    everything = [p for p in out.rglob("*") if p.is_file()]
    if not everything:
        return []
    ours = run_files(out)
    foreign = sorted(set(everything) - set(ours))
    summary = out / "summary.json"
    try:
        previous = json.loads(summary.read_text()) if summary.exists() else None
    except (OSError, ValueError):
        previous = None
    same = isinstance(previous, dict) and (previous.get("scene"), previous.get("method")) == (scene, method)
    if not same and not overwrite:
        if isinstance(previous, dict):
            what = f"a run of {previous.get('scene')!r} with {previous.get('method')!r}"
        else:
            what = f"{len(everything)} file(s) that are not a refsph run (e.g. {everything[0].relative_to(out)})"
        raise ValueError(f"--out {out} holds {what}; refsph writes a run of {scene!r} with {method!r} only into an "
                         "empty folder or a run folder of the same scene and method. Give another --out, or "
                         "--overwrite (overwrite=True) to replace the run there: only the files refsph writes "
                         f"are removed ({len(ours)} here), the other {len(foreign)} are kept")
    for p in ours:
        p.unlink()
    return foreign


def write_json(path, data: dict) -> None:
    """Write strict JSON (:func:`json_ready`: nan -> null) atomically (temporary file, then rename)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w") as f:
        json.dump(json_ready(data), f, indent=2, allow_nan=False)
        f.write("\n")
    os.replace(tmp, path)


def write_progress(folder, t: float, t_end: float, steps: int, wall_s: float, t_begin: float) -> None:
    """A run's heartbeat, ``<folder>/progress.json``: the simulated time t and t_end [s], the steps, the simulated
    time this process began at (``t_begin``: a restart's) and its wall seconds so far, when it was written (Unix
    time), and the process that wrote it (``pid``, ``host``: a reader on that machine can tell a run whose process is
    gone, :func:`writer_alive`). :class:`Heartbeat` writes it every ``HEARTBEAT_S`` (30 s) of a run, so a long run's
    progress is known between its checkpoints (summary.json is written only at each snapshot); written atomically,
    and not needed by anything that reads a run."""
    write_json(Path(folder) / PROGRESS, dict(t=float(t), t_end=float(t_end), steps=int(steps), t_begin=float(t_begin),
                                             wall_s=float(wall_s), written=time.time(), pid=os.getpid(),
                                             host=socket.gethostname()))


def writer_alive(beat: dict) -> bool | None:
    """Whether the process that wrote the heartbeat ``beat`` (:func:`write_progress`'s fields) still runs: None
    where that cannot be told (written elsewhere, or by a version without ``pid``). A process id can be taken again
    by another process after a restart of the machine, so True means only "some process has that id"."""
    pid = beat.get("pid")
    if pid is None or beat.get("host") != socket.gethostname():
        return None
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return False
    except PermissionError:                 # alive, another user's
        return True
    return True


class Heartbeat:
    """The run loops' heartbeat: called after every step with (t, steps), it writes :func:`write_progress` into
    ``folder`` once ``HEARTBEAT_S`` of wall time have passed since the last (or since it was made); ``folder``
    None: nothing. ``t_end`` and ``t_begin`` (the simulated time this process starts at) as there."""

    def __init__(self, folder, t_end: float, t_begin: float):
        self.folder, self.t_end, self.t_begin = folder, t_end, t_begin
        self.start = self.last = time.perf_counter()

    def __call__(self, t: float, steps: int) -> None:
        now = time.perf_counter()
        if self.folder is not None and now - self.last >= HEARTBEAT_S:
            self.last = now
            write_progress(self.folder, t, self.t_end, steps, now - self.start, self.t_begin)


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


def analyse_cutting_run(directory, snapshot: int = -1) -> dict:
    """:func:`refsph.scenes.cutting.cutting_metrics` of a cutting run folder (``refsph run cutting --out DIR``)
    from its ``summary.json``, ``reaction_forces.csv`` and snapshot number ``snapshot`` (default: the last); the
    forces cover the whole run. Lets a changed measurement be applied to earlier runs without running them again
    (benchmarks/cutting.py). It lives here, not in the scene, because it reads run files: scenes only build."""
    from .scenes.cutting import cutting_metrics      # here, not at the top: importing io stays free of the scenes

    directory = Path(directory)
    summary, snaps = load_run(directory)
    if summary.get("scene") != "cutting":
        raise ValueError(f"{directory} is not a cutting run (scene {summary.get('scene')!r})")
    if not snaps:
        raise FileNotFoundError(f"{directory} has no snapshots")
    z = load_snapshot(snaps[snapshot])
    return cutting_metrics(load_reactions(directory / "reaction_forces.csv"), z["x"], z["eps_p"], z["T"], z["t"],
                           summary["scene_info"], summary["t_end"])
