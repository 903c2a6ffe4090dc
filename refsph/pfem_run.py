"""``refsph run thermal_cutting --method pfem``: a PFEM cut (:mod:`refsph.pfem.cutting`) written as a run folder like
an SPH run's, so that ``refsph compare``, ``refsph export --vtk``, the restart and the plots take it unchanged.

The folder (:mod:`refsph.io` documents the common files):

    summary.json              scene, method 'pfem', dim 2, dp (the finest spacing dx), n_particles (nodes),
                              n_steps, t_end, status, metrics (the SPH scene's keys), scene_info, heat_balance,
                              newton (iterations, halved steps, remeshings), run_args, wall_time_s, cpu_time_s
                              (the steps' CPU seconds, over restarts; null where a restart continued a checkpoint
                              that did not keep them), provenance;
                              written at the start and at each checkpoint with status 'running' (so a killed run
                              can be continued, and read), at the end with the run's status
    snapshots/snap_NNNNN.npz  the nodes as particles (t, id, x, v, m, rho, p, S, S_zz, sigma_vm, eps_p, eps_dot_p,
                              W_p, T, body) plus the mesh: ``triangles`` (M, 3) and ``boundary_edges`` (K, 2), rows
                              of the node arrays (int64); ``tool_x`` (P, 2) and ``tool_T`` (P,): the tool's nodes
                              where the heat step meshes it
    snapshots/units.json      the unit of each array
    snapshots/restart.npz     the last checkpoint, the whole run (``refsph run --restart`` continues from it):
                              written at every snapshot and, between them, every 10 minutes of wall time
    reaction_forces.csv       the force on the tool, every step

``rho`` of a node is rho0 / J with J its area-weighted volume ratio; ``p`` is the nodal pressure of the mixed
element (the mean stress, positive in compression like the SPH snapshots' pressure).

Scene options (``--option NAME=VALUE``): case, n_tu, travel, length, penalty, courant, alpha, friction, conduction,
chip_fraction, eta and the rest of :func:`refsph.pfem.cutting.pfem_cut`'s parameters; ``--quick``: case 1's short cut
at dx = t_u / 5 (4 t_u of a workpiece 1.2 mm long, the SPH scene's quick cut).
"""
from __future__ import annotations

import contextlib
import inspect
import json
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from .io import Heartbeat, claim_run_folder, read_npz, save_reactions, write_json, write_snapshot
from .material import von_mises
from .pfem.cutting import CutRun, pfem_cut
from .pfem.solid import TRAPEZOIDAL, NewtonFailed
from .scenes.base import parse_bool
from .simulate import CHECKPOINT_EVERY_S, SimulationError, check_checkpoint_every, earlier_commits, provenance

RINGING_HINT = (" [with the paper's trapezoidal rule the chip's ringing is undamped late in a cut, and Newton can "
                "stall there (README, PFEM: cases 8 and 16); Newmark's damped rule, --option gamma=0.6 (a departure "
                "from the paper), ran case 16 at t_u/5 and case 8 at t_u/10 to their ends; --option bossak=-0.1, "
                "Bossak-Newmark, damps the same frequencies at second order]")

__all__ = ["run_pfem", "restart_pfem", "one_blas_thread", "is_pfem_run", "pfem_options", "PFEM_SCENES", "QUICK",
           "N_SNAPSHOTS", "PFEMRunResult"]

PFEM_SCENES = ("thermal_cutting",)
QUICK = dict(case=1, n_tu=5.0, travel=4.0, length=1.2e-3)          # the SPH scene's quick cut
N_SNAPSHOTS = 8                                                      # as the SPH scene: t = 0 and 8 more
UNITS = dict(t="s", id="1 (node id)", x="m", v="m/s", m="kg/m", rho="kg/m^3", p="Pa", S="Pa", S_zz="Pa",
             sigma_vm="Pa", eps_p="1", eps_dot_p="1/s", W_p="J/m^3", T="K", body="1",
             triangles="1 (node rows)", boundary_edges="1 (node rows)", tool_x="m", tool_T="K")
CHECKPOINT, PREVIOUS = "restart.npz", "restart_prev.npz"


class PFEMRunResult:
    """What :func:`run_pfem` returns: ``summary`` (summary.json's content) and ``result`` (:meth:`CutRun.result`)."""

    def __init__(self, summary: dict, result: dict):
        self.summary, self.result = summary, result


def pfem_options() -> list[str]:
    """The scene options the PFEM cut takes (the parameters of :func:`refsph.pfem.cutting.pfem_cut`)."""
    return list(inspect.signature(pfem_cut).parameters)


def _options(options: dict, quick: bool) -> dict:
    """The keyword arguments of :func:`pfem_cut` from the scene options (strings from the command line converted);
    ValueError naming an unknown option."""
    known = inspect.signature(pfem_cut).parameters
    out = dict(QUICK) if quick else {}
    for name, value in (options or {}).items():
        if name not in known:
            raise ValueError(f"option {name!r} is not an option of the PFEM cut; its options: {', '.join(known)}")
        default = known[name].default
        if isinstance(default, bool):                       # friction, conduction, refine, edge_nodes
            out[name] = parse_bool(value, f"option {name}")  # its own message: true or false
            continue
        try:
            if name in ("case", "seed"):
                out[name] = int(float(value))
            elif name == "length" and value in (None, "none"):
                out[name] = None
            else:
                out[name] = float(value)
        except (TypeError, ValueError) as e:
            raise ValueError(f"option {name} must be a number (default {default!r}), got {value!r}") from e
    if "case" not in out:
        out["case"] = 1
    return out


def _snapshot(path: Path, run: CutRun) -> None:
    """The nodes as particles, the mesh and (with the heat step) the tool's nodes (module text), atomically."""
    n, mesh, law = run.nodes, run.mesh, run.cut.law
    J = np.where(mesh.meshed, n.J, 1.0)                     # a node without a triangle: at its reference density
    arrays = dict(t=np.float64(n.t), id=run.ids, x=n.x, v=n.v, m=n.m, rho=law.rho0 / J,
                  p=-n.p, S=n.S, S_zz=n.S_zz, sigma_vm=von_mises(n.S, n.S_zz), eps_p=n.eps_p, eps_dot_p=n.eps_dot,
                  W_p=n.W_p, T=n.T, body=np.zeros(n.n, dtype=np.int32), triangles=mesh.tri.astype(np.int64),
                  boundary_edges=mesh.edges.astype(np.int64))
    if run.T_tool is not None:
        arrays.update(tool_x=run.tool_x(n.t), tool_T=run.T_tool)
    write_snapshot(path, arrays, UNITS)


def _checkpoint(folder: Path, run: CutRun, snapshots: list, next_snap: int) -> None:
    """restart.npz (the previous one kept as restart_prev.npz), atomically."""
    arrays = run.checkpoint()
    arrays["run"] = np.array(json.dumps(dict(snapshots=snapshots, next_snap=next_snap)))
    path = folder / CHECKPOINT
    if path.exists():
        os.replace(path, folder / PREVIOUS)
    tmp = folder / (CHECKPOINT + ".tmp.npz")
    np.savez(tmp, **arrays)
    os.replace(tmp, path)


def _restore(folder: Path, cut):
    """The run of the last readable checkpoint (restart.npz, else restart_prev.npz): (CutRun, snapshots, next
    snapshot); ValueError naming what could not be read."""
    failures = []
    for name in (CHECKPOINT, PREVIOUS):
        try:
            arrays = read_npz(folder / name, "PFEM checkpoint")
            rec = json.loads(str(arrays.pop("run")))
            restored = CutRun.restore(cut, arrays), rec["snapshots"], rec["next_snap"]
        except (ValueError, KeyError) as e:
            failures.append(f"{type(e).__name__}: {e}")
            continue
        if failures:                                         # said, as the SPH restart says it (refsph.simulate)
            warnings.warn(f"{failures[0]}; continuing from the checkpoint before it, {folder / PREVIOUS}",
                          stacklevel=2)
        return restored
    raise ValueError(f"{folder}: nothing to restart from ({'; '.join(failures)})")


def run_pfem(scene_name: str = "thermal_cutting", *, out=None, options: dict | None = None, quick: bool = False,
             progress: bool = True, restart: bool = False, overwrite: bool = False,
             max_steps: int | None = None, checkpoint_every: float | None = CHECKPOINT_EVERY_S) -> PFEMRunResult:
    """Run the PFEM version of a scene into the run folder ``out`` (default runs/SCENE-pfem-2d; module text);
    ``restart``: continue the run there from its last checkpoint. ``max_steps``: stop after that many steps of
    this call (the folder can be continued with ``restart``). Between snapshots a checkpoint is also written once
    ``checkpoint_every`` seconds of wall time have passed since the last (None: only at snapshots), so that a
    killed long run loses at most that much (the checkpoint holds the whole run: the same bits on a restart).
    BLAS runs at one thread meanwhile (:func:`one_blas_thread`). Returns a :class:`PFEMRunResult`."""
    check_checkpoint_every(checkpoint_every)
    with one_blas_thread():
        return _run_pfem(scene_name, out, options, quick, progress, restart, overwrite, max_steps, checkpoint_every)


def one_blas_thread():
    """A context in which BLAS uses one thread, where threadpoolctl is installed (the ``fast`` extra; else a
    context that changes nothing: start Python with OPENBLAS_NUM_THREADS=1 for the same). SuperLU's factorisations
    and the Newton residual's norms call BLAS, and BLAS threads that compete with other work for the cores spin:
    with one other run on this 2-core machine a norm of 19,000 numbers took 15.6 ms at two threads against 10 us at
    one, and ten steps late in case 1's cut at t_u/10 took 107 against 55 s of CPU (README, issue 24)."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return contextlib.nullcontext()
    return threadpool_limits(1, user_api="blas")


def _run_pfem(scene_name, out, options, quick, progress, restart, overwrite, max_steps,
              checkpoint_every=None) -> PFEMRunResult:
    """:func:`run_pfem`'s run."""
    if scene_name not in PFEM_SCENES:
        raise ValueError(f"scene {scene_name!r} has no PFEM version; PFEM scenes: {', '.join(PFEM_SCENES)}")
    kwargs = _options(options, quick)
    cut = pfem_cut(**kwargs)
    out = Path(out or f"runs/{scene_name}-pfem-2d")
    snaps_dir = out / "snapshots"
    if restart:
        run, snapshots, next_snap = _restore(snaps_dir, cut)
    else:
        claim_run_folder(out, scene_name, "pfem", overwrite)
        snaps_dir.mkdir(parents=True, exist_ok=True)
        run, snapshots, next_snap = CutRun(cut), [], 0
        _snapshot(snaps_dir / "snap_00000.npz", run)
        snapshots.append("snap_00000.npz")
        next_snap = 1
        _checkpoint(snaps_dir, run, snapshots, next_snap)
    times = np.linspace(0.0, cut.t_end, N_SNAPSHOTS + 1)
    args = dict(scene_name=scene_name, method="pfem", options=dict(options or {}), quick=bool(quick))
    prov = _provenance(out, restart)                        # the code this call runs, taken once at its start

    def running_summary():                                  # at each checkpoint: a killed run can be continued
        write_json(out / "summary.json", _summary(scene_name, run, run.result(), kwargs, args, snapshots, "running",
                                                  None, prov))
    if not restart:
        running_summary()
    status, error, t_start, steps0 = "ok", None, time.perf_counter(), run.steps
    beat, last_print, checkpointed = Heartbeat(out, cut.t_end, run.nodes.t), 0.0, time.perf_counter()
    try:
        while not run.done and (max_steps is None or run.steps - steps0 < max_steps):
            run.step()
            if not np.all(np.isfinite(run.nodes.x)) or not np.all(np.isfinite(run.nodes.T)):
                raise FloatingPointError(f"non-finite nodes after step {run.steps} (t = {run.nodes.t:.6e} s)")
            due = next_snap <= N_SNAPSHOTS and run.nodes.t >= times[next_snap] * (1 - 1e-9)
            if due:
                name = f"snap_{len(snapshots):05d}.npz"             # one snapshot however many times a step passed
                _snapshot(snaps_dir / name, run)
                snapshots.append(name)
                while next_snap <= N_SNAPSHOTS and run.nodes.t >= times[next_snap] * (1 - 1e-9):
                    next_snap += 1
            if due or (checkpoint_every is not None and time.perf_counter() - checkpointed >= checkpoint_every):
                _checkpoint(snaps_dir, run, snapshots, next_snap)       # at a snapshot, or timed between them
                running_summary()
                checkpointed = time.perf_counter()
            beat(run.nodes.t, run.steps)                    # the heartbeat between checkpoints
            now = time.perf_counter()
            if progress and now - last_print > 2.0:
                last_print = now
                F = run.reaction["tool"][-1]
                print(f"[{scene_name} pfem 2D] step {run.steps:6d}  t = {run.nodes.t:.3e} s "
                      f"({100 * run.nodes.t / cut.t_end:5.1f} %)  Fc = {F[0] / 1e3:7.1f} N/mm  "
                      f"Newton {run.iterations[-1]:3d}  elapsed {now - t_start:7.1f} s", file=sys.stderr, flush=True)
    except Exception as e:                                  # a failed Newton, a non-finite state: kept, not lost
        status, error = "failed", f"{type(e).__name__}: {e}" + (RINGING_HINT if isinstance(e, NewtonFailed)
                                                                 and run.cut.newmark is TRAPEZOIDAL else "")
        _snapshot(snaps_dir / "last_good.npz", run)
    res = run.result()
    reaction = {k: np.asarray(v, dtype=float) for k, v in run.reaction.items()}
    if len(reaction["t"]):
        save_reactions(out / "reaction_forces.csv", dict(t=reaction["t"], dt=reaction["dt"],
                                                         tool=reaction["tool"].reshape(-1, 2)), 2)
    summary = _summary(scene_name, run, res, kwargs, args, snapshots, status, error, prov)
    write_json(out / "summary.json", summary)
    if status != "ok":
        raise SimulationError(f"PFEM {scene_name}: {error}; the last state is in {snaps_dir / 'last_good.npz'}")
    return PFEMRunResult(summary, res)


def _provenance(out: Path, restart: bool) -> dict:
    """:func:`refsph.simulate.provenance` at the start of this call; a restarted run's also names the commits its
    earlier parts ran (:func:`refsph.simulate.earlier_commits`), since a run may be continued at another commit."""
    prov = provenance(1)
    if restart:
        prov["earlier_commits"] = earlier_commits(out)
    return prov


def _summary(scene_name: str, run: CutRun, res: dict, kwargs: dict, args: dict, snapshots: list, status: str,
             error: str | None, prov: dict) -> dict:
    """summary.json's content (module text); ``prov`` the run's provenance (:func:`_provenance`)."""
    cut = run.cut
    it = np.asarray(run.iterations)
    summary = dict(scene=scene_name, method="pfem", dim=2, dp=cut.info["dx"], h=None, n_particles=run.nodes.n,
                   t_end=cut.t_end, t_final=run.nodes.t, n_steps=run.steps,
                   status=status if status != "ok" or run.done else "partial", metrics=res["metrics"],
                   scene_info=dict(cut.info), heat_balance=res["heat_balance"],
                   newton=dict(iterations=int(it.sum()), max_per_step=int(it.max()) if len(it) else 0,
                               halved_steps=run.retries, remeshes=run.remeshes, max_move=cut.max_move,
                               max_iter=cut.max_iter, settle=cut.settle,
                               max_outer=cut.max_outer, nodes_inserted=run.inserted, nodes_removed=run.removed),
                   options=kwargs, run_args=args, wall_time_s=run.wall, cpu_time_s=run.cpu, snapshots=snapshots,
                   particle_steps_per_s=run.nodes.n * run.steps / run.wall if run.wall > 0 else 0.0,
                   reaction_forces_file="reaction_forces.csv", provenance=prov)
    if error:
        summary["error"] = error
    return summary


def restart_pfem(run_dir, progress: bool = True, checkpoint_every: float | None = CHECKPOINT_EVERY_S) -> PFEMRunResult:
    """Continue the PFEM run in ``run_dir`` from its last checkpoint, with the arguments it was started with
    (``summary.json``'s ``run_args``)."""
    check_checkpoint_every(checkpoint_every)                  # said as itself, not as a folder's fault
    path = Path(run_dir) / "summary.json"
    try:
        args = json.loads(path.read_text())["run_args"]
        return run_pfem(args["scene_name"], out=run_dir, options=args.get("options"), quick=bool(args.get("quick")),
                        progress=progress, restart=True, checkpoint_every=checkpoint_every)
    except FileNotFoundError:
        raise ValueError(f"{path} does not exist: {run_dir} is not a refsph run folder") from None
    except (KeyError, TypeError, ValueError) as e:
        raise ValueError(f"{path}: not a PFEM run folder that can be continued ({type(e).__name__}: {e})") from None


def is_pfem_run(run_dir) -> bool:
    """True if ``run_dir``'s summary.json says method 'pfem'."""
    try:
        return json.loads((Path(run_dir) / "summary.json").read_text()).get("method") == "pfem"
    except (OSError, ValueError, AttributeError):
        return False
