"""The run driver: setup -> solver -> time loop -> summary.json and snapshots.

``simulate`` is four named steps: the initial record (:class:`RunRecord`: summary, history, output files), the
snapshot schedule (:func:`snapshot_times`), one step after another (:func:`step_or_fail`), the final record
(metrics and ``summary.json``). ``run`` builds a registered scene first (what ``refsph run`` calls).

The loop owns what a run is made of: the method (a :class:`~refsph.integrate.Solver`, or a
:class:`~refsph.integrate.SelfAdvancing` method), its stepper (:func:`~refsph.integrate.make_stepper`, with the
state it carries between steps), and the physics beside the mechanics (:func:`step_physics`: a list of
:class:`~refsph.integrate.StepPhysics`, the heat flow when the setup asks for heat). Each step it takes the smallest
of the CFL step and the physics' limits, steps the mechanics, then advances each physics in order; records,
summaries and the restart checkpoint ask each part for its own.

Nothing is lost on a crash: snapshots are written as the run goes, ``summary.json`` is written at every snapshot
(``status: "running"``), at the end *and* on failure (``status`` says which), and a run that produces NaN/inf
stops, reports the field, particle, step and time, and writes ``snapshots/last_good.npz`` with the last finite
state. Nor is anything a user keeps: a run writes only into an empty folder or a run folder of the same scene and
method (:func:`refsph.io.claim_run_folder`; ``overwrite`` removes only refsph's own files), and a run whose folder
vanishes (or its ``snapshots/``) stops with a SimulationError instead of writing it anew (the writers would create
the folders again, and the summary would list snapshots that no longer exist); a write that fails (disk full) stops
it the same way. Every snapshot keeps the checkpoint before it too (``restart_prev.npz``), so a restart whose last
checkpoint or snapshot a crash spoilt continues from the one before (saying so).
"""
from __future__ import annotations

import dataclasses
import inspect
import json
import os
import sys
import time
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, NamedTuple

import numpy as np

from . import __version__
from .contact import PinballContact
from .penalty import PenaltyContact
from .esph import ESPHParams
from .integrate import PARTS, SelfAdvancing, Solver, Step, StepPhysics, Stepper, cfl_time_step, make_stepper
from .stability import warnings_for
from .strength import heat_capacity, heats
from .thermal import HeatFlow
from .boundaries import Clamp
from .io import (Heartbeat, claim_run_folder, json_ready, save_reactions, save_snapshot, state_from_particles,
                 state_from_snapshot, write_json)
from .kernels import get_kernel
from .neighbours import check_threads
from .scenes import Scene, Setup, get_scene
from .solvers import ESPHSolver, TLSPHSolver
from .state import State
from .tlsph import TLSPHParams

__all__ = ["SimulationError", "RunResult", "RunRecord", "Built", "make_solver", "step_physics", "run", "build",
           "check_run", "simulate", "time_step", "snapshot_times", "step_or_fail", "provenance", "run_commits",
           "earlier_commits", "restart_run", "METHODS"]

METHODS = ("esph", "tlsph")
CHECKPOINT = "restart.npz"          # snapshots/restart.npz: how to continue from the last checkpoint (see simulate)
PREVIOUS_CHECKPOINT = "restart_prev.npz"    # the checkpoint before it (a restart falls back on it)
TIMED_STATES = ("checkpoint_a.npz", "checkpoint_b.npz", "checkpoint_c.npz")   # the timed checkpoints' states
CHECKPOINT_EVERY_S = 600.0          # a checkpoint at least this often [s of wall time] between snapshots


class SimulationError(RuntimeError):
    """A run stopped because the state became non-finite or a step failed (message says where and when)."""


@dataclass
class RunResult:
    summary: dict
    state: State
    history: dict
    setup: Setup


def make_solver(method: str, setup: Setup) -> Solver:
    """The ESPH or TLSPH solver of a setup (its Numerics, boundaries, strength model and contact)."""
    nm = setup.numerics
    threads = check_threads(nm.threads, allow_auto=True)   # (the numbers do not depend on it)
    kernel = get_kernel(nm.kernel)
    h = setup.h
    common = dict(strength=setup.strength, mirror=setup.mirror, walls=setup.walls, rigid=setup.rigid,
                  clamps=setup.clamps, threads=threads)
    if nm.contact not in ("pinball", "penalty"):
        raise ValueError(f"Numerics.contact must be 'pinball' or 'penalty', got {nm.contact!r}")
    if setup.friction is not None and not setup.rigid:
        raise ValueError("friction acts in the contact with rigid bodies, and this setup has none")
    penalty = None
    if nm.contact == "penalty" and setup.rigid:
        penalty = PenaltyContact(alpha=nm.penalty_alpha, damping=nm.penalty_damping, offset=0.5 * setup.dp,
                                 time_scale=nm.courant * h / setup.material.c_longitudinal, friction=setup.friction)
    if method == "esph":
        if setup.friction is not None and penalty is None:
            raise ValueError("friction acts in the penalty contact with rigid bodies; ESPH's tools otherwise act "
                             "through the SPH sums and have no friction model (set contact='penalty' with a tool "
                             "that has a shape, run TLSPH, or set friction=None)")
        if setup.dissipation_heat:
            raise ValueError("dissipation_heat is a TLSPH option (ESPH's artificial viscosity heat is not computed); "
                             "a scene that turns it on by default (thermal_cutting) runs ESPH only with "
                             "--option dissipation_heat=false")
        if nm.hourglass:
            raise ValueError("hourglass control is a TLSPH option (ESPH's neighbours change every step, its zig-zag "
                             "modes are the tensile instability's, see gamma)")
        if nm.max_condition is not None:
            raise ValueError("max_condition limits TLSPH's kernel-gradient correction; ESPH has none to limit")
        if nm.gain_step or nm.frequency_step:
            raise ValueError("gain_step and frequency_step limit the step by TLSPH's fixed operator (its corrected "
                             "gradient's gain, its largest frequency); ESPH's neighbours change every step")
        if nm.self_contact is not None:
            raise ValueError("self_contact is a TLSPH option (ESPH's particles keep apart through the pressure of "
                             "their current neighbours, and its artificial pressure, gamma)")
        prm = ESPHParams(h=h, dp=setup.dp, beta1=nm.beta1, beta2=nm.beta2, gamma=nm.gamma, n_ap=nm.n_ap,
                         eps=nm.eps, kernel=kernel, correction=bool(nm.esph_correction))
        return ESPHSolver(setup.material, prm, skin_factor=nm.skin_factor, contact=penalty, **common)
    if method == "tlsph":
        if nm.esph_correction:
            raise ValueError("esph_correction is an ESPH option; TLSPH's kernel-gradient correction is 'corrected'")
        if nm.frequency_step and setup.mirror is not None:
            raise ValueError("frequency_step needs the largest frequency of a body without mirror ghosts; this setup "
                             "has symmetry planes (model the whole body, or use gain_step)")
        prm = TLSPHParams(h=h, beta1=nm.beta1, beta2=nm.beta2, eps=nm.eps, kernel=kernel,
                          corrected=nm.corrected, ref_update_strain=nm.ref_update_strain,
                          hourglass=float(nm.hourglass), viscous_heat=bool(setup.dissipation_heat),
                          max_condition=nm.max_condition)
        contact = penalty
        if penalty is None and (setup.rigid or len(_deformable_bodies(setup)) > 1):
            k = nm.contact_k if nm.contact_k is not None else setup.dp / (2.0 * h)
            contact = PinballContact(k=k, K_p=nm.contact_Kp, friction=setup.friction)
        r_c = None if nm.self_contact is None else nm.self_contact * setup.dp
        return TLSPHSolver(setup.material, prm, contact=contact, dp=setup.dp, self_contact=r_c, **common)
    raise ValueError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")


def step_physics(setup: Setup) -> list[StepPhysics]:
    """The physics a run carries beside the mechanics, in the order the loop advances them: the heat flow
    (:class:`refsph.thermal.HeatFlow`) when the setup conducts heat (``Setup.thermal``) or makes frictional heat
    (``Setup.friction_heat``); none otherwise (the adiabatic model: the return map heats, Eq. (28))."""
    if setup.thermal is None and setup.friction_heat is None:
        return []
    chi = float(getattr(setup.strength, "chi", 0.0)) if heats(setup.strength) else 0.0
    return [HeatFlow(setup.thermal, setup.friction_heat, heat_capacity(setup.strength), chi, setup.h,
                     get_kernel(setup.numerics.kernel), [b.body for b in setup.rigid],
                     dissipation_heat=bool(setup.dissipation_heat), every=setup.numerics.heat_every)]


def _deformable_bodies(setup: Setup) -> list:
    """The body ids of the setup's deformable particles (those of no rigid body)."""
    if setup.state.body is None:
        return [0]
    rigid = {b.body for b in setup.rigid}
    return sorted(set(np.unique(setup.state.body).tolist()) - rigid)


def _validate(method, dim, dp, setup_numerics=None, t_end=None, dt=None, custom: bool = False):
    if method not in METHODS and not custom:
        raise ValueError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")
    if dp is not None and not (np.isfinite(dp) and dp > 0):
        raise ValueError(f"particle spacing dp must be positive, got {dp!r}")
    if t_end is not None and not (np.isfinite(t_end) and t_end > 0):
        raise ValueError(f"t_end must be positive, got {t_end!r}")
    if dt is not None and not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"time step dt must be positive, got {dt!r}")
    if setup_numerics is not None and setup_numerics.h_over_dp < 1.0:
        raise ValueError(f"smoothing length h must be at least the spacing dp (h/dp = "
                         f"{setup_numerics.h_over_dp!r} < 1)")


def snapshot_times(setup: Setup) -> np.ndarray:
    """Output times: ``n_snapshots`` + 1 evenly spaced from 0 to t_end, and the setup's extra times."""
    times = np.linspace(0.0, setup.t_end, setup.n_snapshots + 1)
    extra = [t for t in setup.snapshot_times if 0.0 < t < setup.t_end]
    return np.unique(np.concatenate([times, extra]))


def provenance(threads: int) -> dict:
    """Where a run's numbers come from: refsph version and git commit (when the package is a git checkout; with
    ``dirty`` if it has uncommitted changes), Python, NumPy and SciPy versions, platform, thread count, command line."""
    import platform
    import subprocess

    import scipy
    root = Path(__file__).resolve().parent.parent
    commit = None
    if (root / ".git").exists():
        try:
            git = ["git", "-C", str(root)]
            commit = subprocess.run(git + ["rev-parse", "HEAD"], capture_output=True, text=True, timeout=10,
                                    check=True).stdout.strip()
            dirty = subprocess.run(git + ["status", "--porcelain", "--untracked-files=no"], capture_output=True,
                                   text=True, timeout=10, check=True).stdout.strip()
            commit += " (dirty)" if dirty else ""
        except (OSError, subprocess.SubprocessError):
            commit = None
    return dict(refsph=__version__, git_commit=commit, python=platform.python_version(), numpy=np.__version__,
                scipy=scipy.__version__, platform=platform.platform(), threads=threads, command=list(sys.argv))


def run_commits(prov: dict) -> list:
    """The git commits a run's provenance names, its earlier parts' first (``earlier_commits``, then
    ``git_commit``), each once per stretch of restarts at it."""
    commits = [c for c in list(prov.get("earlier_commits", [])) + [prov.get("git_commit")] if isinstance(c, str)]
    return [c for k, c in enumerate(commits) if k == 0 or c != commits[k - 1]]


def earlier_commits(out) -> list:
    """The git commits a run folder's earlier parts ran (:func:`run_commits` of its summary.json's provenance), for
    a restart that may run another commit; [] where there is none."""
    try:
        return run_commits(json.loads((Path(out) / "summary.json").read_text()).get("provenance") or {})
    except (OSError, ValueError, AttributeError, TypeError):        # no summary, or not one refsph wrote
        return []


def _as_dict(obj) -> dict:
    """A strength model, wall, body ... as {'model': its class, its fields}."""
    fields = dataclasses.asdict(obj) if dataclasses.is_dataclass(obj) else {}
    if "model" in fields:
        return dict(model=type(obj).__name__, fields=fields)
    return dict(model=type(obj).__name__, **fields)


def _open_run_folder(out: Path, name: str, method: str, overwrite: bool, kept: list | None) -> None:
    """A fresh run (``kept`` None) claims ``out`` (:func:`refsph.io.claim_run_folder`: refused unless it is empty or
    a run of the same scene and method); a restart removes the snapshots after those it continues from."""
    if kept is None:
        claim_run_folder(out, name, method, overwrite)
    (out / "snapshots").mkdir(parents=True, exist_ok=True)
    for old in (out / "snapshots").glob("snap_*.npz"):
        if kept is not None and old.name not in kept:
            old.unlink()


class RunRecord:
    """What a run leaves: ``summary`` (summary.json), ``history`` (the recorded scalars), snapshots and the
    reaction-force CSV in ``out`` (None: nothing is written). ``parts``: the run's parts that keep records of their
    own (:class:`RunParts`)."""

    def __init__(self, setup: Setup, parts: "RunParts", out, dt, name: str, record: Callable | None, times,
                 resume: dict | None = None, overwrite: bool = False, checkpoint_every: float | None = None):
        self.setup, self.parts, self.solver, self.record_fn = setup, parts, parts.solver, record
        self.out = Path(out) if out is not None else None
        self.history: dict[str, list] = {}
        self.snapshots: list[str] = []
        self.times, self.next_snap = times, 0
        self.n_steps, self.dts, self.record_every = 0, [], 1
        self.t0, self.c0 = time.perf_counter(), time.process_time()
        self.lost = False                                   # the run folder vanished during the run
        self.checkpoint_every, self.checkpointed = checkpoint_every, time.perf_counter()
        self.states: list = [None, None]                    # the state files of the checkpoint before and the last
        earlier = earlier_commits(self.out) if resume is not None and self.out is not None else []
        if resume is not None:
            self._resume(resume)
        if self.out is not None:
            _open_run_folder(self.out, name, parts.solver.method, overwrite, self.snapshots if resume else None)
        self.summary = _initial_summary(setup, parts, dt, name, times)
        if resume is not None:
            self.summary["restarts"] = int(resume["run"]["restarts"]) + 1
            self.summary["provenance"]["earlier_commits"] = earlier

    def _resume(self, ck: dict) -> None:
        """Continue the record of an interrupted run from its checkpoint."""
        r = ck["run"]
        self.history = {k: list(v) for k, v in r["history"].items()}
        self.snapshots, self.next_snap = list(r["snapshots"]), int(r["next_snap"])
        self.states = [None, r["snapshot"]]
        self.n_steps, self.record_every = int(r["n_steps"]), int(r["record_every"])
        self.dts = list(np.asarray(ck["dts"], dtype=float))
        self.t0 -= float(r["wall_time_s"])
        self.c0 -= float(r["cpu_time_s"])

    def checkpoint(self, snapshot: str, t: float) -> None:
        """``snapshots/restart.npz``: what :func:`simulate` needs to continue from snapshot ``snapshot`` exactly as
        the uninterrupted run (the parts' own states, the history, the counters), written atomically; ``t``: the
        snapshot's time, which a restart checks against the snapshot file's (a file overwritten since is refused)."""
        if self.out is None:
            return
        if not self.present():
            raise SimulationError(self.summary["error"])
        run = dict(snapshot=snapshot, t=float(t), history={k: v for k, v in self.history.items() if k != "reaction"},
                   snapshots=self.snapshots, next_snap=self.next_snap, n_steps=self.n_steps,
                   record_every=self.record_every, wall_time_s=time.perf_counter() - self.t0,
                   cpu_time_s=time.process_time() - self.c0, restarts=self.summary.get("restarts", 0))
        path = self.out / "snapshots" / CHECKPOINT
        tmp = path.with_name("restart.tmp.npz")
        np.savez(tmp, run=json.dumps(json_ready(run)), dts=np.asarray(self.dts, dtype=float),
                 **self.parts.checkpoint())
        if path.exists():                                   # the one before stays, for a restart whose last
            os.replace(path, path.with_name(PREVIOUS_CHECKPOINT))   # checkpoint or snapshot a crash has spoilt
        os.replace(tmp, path)
        self.states, self.checkpointed = [self.states[1], snapshot], time.perf_counter()

    def record(self, state: State) -> None:
        values = self.record_fn(state, self.setup) if self.record_fn is not None else {}
        for p in self.parts.physics:
            values = dict(values, **p.record(state))
        for k, val in values.items():
            self.history.setdefault(k, []).append(val)

    def present(self) -> bool:
        """The run folder is still there; else the run is marked lost and nothing more is written (module text)."""
        if self.out is not None and not self.lost and not (self.out / "snapshots").is_dir():
            self.lost = True
            self.summary.update(status="error", error=f"the run folder {self.out} (or its snapshots/) vanished "
                                                      "during the run")
        return self.out is not None and not self.lost

    def save(self, name: str, state: State) -> Path:
        if not self.present():
            raise SimulationError(self.summary["error"])
        path = self.out / "snapshots" / name
        save_snapshot(path, state, self.setup.material, self.solver.deformation_gradient(state),
                      ids=self.setup.arrays.get("id"))
        return path

    def next_output_time(self) -> float:
        """The next snapshot time not yet written (t_end, the last one, once all are)."""
        return float(self.times[min(self.next_snap, len(self.times) - 1)])

    def snapshot_if_due(self, state: State) -> None:
        """Write every snapshot whose time has come (a killed run keeps its summary up to the last of them)."""
        while self.next_snap < len(self.times) and state.t >= self.times[self.next_snap] * (1 - 1e-12):
            if self.out is not None:
                name = f"snap_{self.next_snap:05d}.npz"
                self.save(name, state)
                self.snapshots.append(name)
                if 0 < self.next_snap < len(self.times) - 1:
                    self.update(state)
                    if self.present():
                        write_json(self.out / "summary.json", self.summary)
            self.next_snap += 1
            if self.out is not None:
                self.checkpoint(name, state.t)              # (a vanished folder: SimulationError)
            if state.t < self.setup.t_end * (1 - 1e-12):
                break

    def update(self, state: State) -> None:
        """The summary's run record and the reaction history (and its CSV) as they stand at ``state``."""
        wall = time.perf_counter() - self.t0
        dts = self.dts
        self.summary.update(
            n_steps=self.n_steps, wall_time_s=wall, cpu_time_s=time.process_time() - self.c0, t_final=state.t,
            dt_min=float(min(dts)) if dts else None, dt_max=float(max(dts)) if dts else None,
            particle_steps_per_s=state.n * self.n_steps / wall if wall > 0 else None,
            snapshots=list(self.snapshots), diagnostics=self.solver.diagnostics())
        for p in self.parts.physics:
            self.summary.update(p.summary(state))
        reactions = self.solver.reaction_history()
        if reactions:
            self.history["reaction"] = reactions
            if self.present():
                save_reactions(self.out / "reaction_forces.csv", reactions, state.dim)
                self.summary["reaction_forces_file"] = "reaction_forces.csv"

    def fail(self, status: str, msg: str, last_good: State) -> SimulationError:
        """Record a failed step (``last_good.npz``, status and message); the error to raise."""
        if self.present():
            path = self.save("last_good.npz", last_good)
            msg += f"; last good state written to {path}"
        self.summary.update(status=status, error=msg)
        return SimulationError(msg)

    def finish(self, state: State, metrics: Callable | None) -> None:
        """The final summary (and its file, unless the run folder vanished: then a SimulationError)."""
        self.update(state)
        if metrics is not None and self.history and self.summary["status"] == "ok":
            self.summary["metrics"] = metrics(self.history, state, self.setup)
        if self.present():
            write_json(self.out / "summary.json", self.summary)
            if self.summary["status"] == "ok":              # the timed checkpoints' states are not needed now
                for name in set(TIMED_STATES) - {self.states[1]}:
                    (self.out / "snapshots" / name).unlink(missing_ok=True)
        elif self.lost:
            raise SimulationError(self.summary["error"])


def _initial_summary(setup: Setup, parts: "RunParts", dt, name: str, times) -> dict:
    """summary.json as a run starts (status 'running')."""
    state, solver = setup.state, parts.solver
    return dict(
        scene=name, method=solver.method, dim=state.dim, dp=setup.dp, h=setup.h, n_particles=state.n,
        t_end=setup.t_end, n_steps=0, dt_mode="fixed" if dt is not None else "cfl",
        courant=setup.numerics.courant, numerics=dataclasses.asdict(setup.numerics), threads=solver.threads,
        material=dataclasses.asdict(setup.material), strength=_as_dict(setup.strength),
        heating=heats(setup.strength),
        boundaries=dict(symmetry_axes=list(setup.mirror.axes) if setup.mirror is not None else [],
                        walls=[dataclasses.asdict(w) for w in setup.walls],
                        rigid_bodies=[dataclasses.asdict(b) for b in setup.rigid],
                        clamps=[c.to_dict() for c in setup.clamps],
                        friction=(dataclasses.asdict(setup.friction) if setup.friction is not None else None)),
        scene_info=setup.info, snapshot_times=[float(t) for t in times], refsph_version=__version__,
        provenance=provenance(solver.threads), status="running", metrics={},
        **{p.name: json_ready(p.describe()) for p in parts.physics})


def check_checkpoint_every(checkpoint_every: float | None) -> None:
    """A checkpoint interval is None or >= 0 seconds (inf: only at snapshots, as None); ValueError naming it."""
    if checkpoint_every is not None and not checkpoint_every >= 0:
        raise ValueError(f"checkpoint_every must be >= 0 seconds or None, got {checkpoint_every!r}")


def _checkpoint_if_due(rec: RunRecord, state: State) -> None:
    """A checkpoint between snapshots once ``rec.checkpoint_every`` seconds of wall time have passed since the last
    (so a killed run loses at most that much): the state in ``snapshots/checkpoint_a.npz``, ``_b`` or ``_c``, one
    that neither the last checkpoint nor the one before names (both stay whole, whenever the run is killed).
    Nothing of the run's numbers changes (the state is only read)."""
    if (rec.out is None or rec.checkpoint_every is None or state.t >= rec.setup.t_end * (1 - 1e-12)
            or time.perf_counter() - rec.checkpointed < rec.checkpoint_every):
        return
    name = next(n for n in TIMED_STATES if n not in rec.states)
    rec.save(name, state)
    rec.checkpoint(name, state.t)


@dataclass
class RunParts:
    """What a run is made of, each keeping its own state: the method (``solver``), its ``stepper`` and the
    ``physics`` beside the mechanics. Their restart arrays are kept apart by prefix (``solver/``, ``stepper/``,
    ``physics/NAME/``)."""

    solver: Solver | SelfAdvancing
    stepper: Stepper
    physics: list

    def bind(self, state: State) -> None:
        for p in self.physics:
            p.bind(state, self.solver)

    def checkpoint(self) -> dict:
        arrays = {f"solver/{k}": v for k, v in self.solver.checkpoint().items()}
        arrays.update({f"stepper/{k}": v for k, v in self.stepper.checkpoint().items()})
        for p in self.physics:
            arrays.update({f"physics/{p.name}/{k}": v for k, v in p.checkpoint().items()})
        return arrays

    def restore(self, arrays: dict, state: State) -> None:
        def part(prefix):
            return {k[len(prefix):]: v for k, v in arrays.items() if k.startswith(prefix)}
        self.solver.restore(part("solver/"), state)
        self.stepper.restore(part("stepper/"))
        for p in self.physics:
            p.restore(part(f"physics/{p.name}/"))


def step_or_fail(state: State, parts: RunParts, dt: float, rec: RunRecord) -> Step:
    """One step of the method (its stepper), or a :class:`SimulationError` that names the step, the time and (for a
    non-finite state) the field and particle, after writing the last good state."""
    try:
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):     # non-finite: caught below
            step = parts.stepper.step(state, parts.solver, dt)
    except ValueError as e:                                 # e.g. a particle crossed a symmetry plane
        raise rec.fail("error", f"step {rec.n_steps + 1} (t = {state.t:.6e} s) failed: {e}", state) from e
    rec.n_steps += 1
    new = step.state
    bad = new.first_nonfinite()                             # every evolved field, T and the plastic ones too
    if bad is not None:
        raise rec.fail("nan", f"non-finite {bad[0]} at particle {bad[1]} in step {rec.n_steps} "
                              f"(t = {state.t:.6e} s -> {new.t:.6e} s)", state)
    return step


def time_step(setup: Setup, dt: float | None, state: State, physics=(), solver=None) -> float:
    """The step the run loop takes from ``state``: the fixed dt, or the CFL step (over the solver's gain with
    ``Numerics.gain_step``; no more than ``Numerics.frequency_step`` of the solver's critical step; and no more
    than each physics' limit, e.g. heat conduction's)."""
    if dt is not None:
        return dt
    step = cfl_time_step(state, setup.material, setup.h, setup.numerics.courant)
    if setup.numerics.gain_step and solver is not None:
        step /= solver.step_gain(state)
    if setup.numerics.frequency_step and solver is not None:
        step = min(step, setup.numerics.frequency_step * solver.critical_step(state))
    for p in physics:
        step = min(step, p.step_limit(state))
    return step


def _warn_fixed_dt(setup: Setup, dt: float | None, state: State) -> None:
    if dt is not None:
        dt_cfl = cfl_time_step(state, setup.material, setup.h, setup.numerics.courant)
        if dt > dt_cfl:
            print(f"refsph: warning: fixed dt = {dt:.3e} s exceeds the CFL estimate {dt_cfl:.3e} s "
                  f"(Courant {setup.numerics.courant}); the run may become unstable", file=sys.stderr)


class _Progress:
    """A progress line on stderr every 2 s; with a run ``folder``, its heartbeat (:class:`refsph.io.Heartbeat`)."""

    def __init__(self, tag: str, t_end: float, on: bool, folder: Path | None = None, t_begin: float = 0.0):
        self.tag, self.t_end, self.on = tag, t_end, on
        self.beat = Heartbeat(folder, t_end, t_begin)
        self.t0 = self.last = time.perf_counter()

    def __call__(self, n_steps: int, t: float, dt: float) -> None:
        self.beat(t, n_steps)
        now = time.perf_counter()
        if self.on and now - self.last > 2.0:
            frac, el = t / self.t_end, now - self.t0
            print(f"[{self.tag}] step {n_steps:6d}  t = {t:.3e} s ({100 * frac:5.1f} %)  dt = {dt:.2e} s  "
                  f"elapsed {el:6.1f} s, ~{el / max(frac, 1e-9) - el:6.1f} s left", file=sys.stderr, flush=True)
            self.last = now


def _readable_checkpoint(folder: Path):
    """(checkpoint arrays, its run record, its snapshot's state) of the last checkpoint in ``folder`` that can be
    read with its snapshot; the one before (``restart_prev.npz``) if a crash spoilt the last or its snapshot (a
    warning says so: the run then continues from the snapshot before, to the same bits); ValueError if neither."""
    failures = []
    for name in (CHECKPOINT, PREVIOUS_CHECKPOINT):
        path = folder / name
        if not path.exists():
            failures.append(f"{path} does not exist")
            continue
        try:
            with np.load(path) as z:
                ck = {k: z[k] for k in z.files}
            run_ck = json.loads(str(ck["run"]))
            state = state_from_snapshot(folder / run_ck["snapshot"])
            if "t" in run_ck and state.t != run_ck["t"]:         # (a checkpoint before 2026-11-29 has no t)
                raise ValueError(f"its state {run_ck['snapshot']} is at t = {state.t!r} s, the checkpoint's at "
                                 f"{run_ck['t']!r} s (overwritten since)")
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as e:
            failures.append(f"{path} (or its snapshot) cannot be read: {type(e).__name__}: {e}")
            continue
        if failures:
            warnings.warn(f"{failures[0]}; continuing from the checkpoint before it, at {run_ck['snapshot']}",
                          UserWarning, stacklevel=3)
            os.replace(path, folder / CHECKPOINT)           # the spoilt one retired: the next checkpoints rotate
        return ck, run_ck, state                            # from this one
    raise ValueError("nothing to restart from (a run writes a checkpoint at every snapshot): " + "; ".join(failures))


def _begin(setup: Setup, parts: RunParts, out, dt, name: str, record, record_every, restart: bool,
           overwrite: bool = False, checkpoint_every: float | None = None):
    """The initial record: a fresh start (the setup's state, recorded and written at t = 0), or with ``restart``
    the checkpoint of the run folder ``out`` (its snapshot, the history and counters, the parts' own states)."""
    if restart:
        if out is None:
            raise ValueError("restart needs the run folder (out=...)")
        ck, run_ck, state = _readable_checkpoint(Path(out) / "snapshots")
        parts.bind(setup.state)                             # (the initial temperatures of the heat ledger)
        if run_ck.get("heat") and not any(k.startswith("physics/") for k in ck):
            ck.update({f"physics/heat/{k}": v for k, v in run_ck["heat"].items()})   # a checkpoint before RunParts
        parts.restore(ck, state)
        rec = RunRecord(setup, parts, out, dt, name, record, snapshot_times(setup),
                        resume=dict(run=run_ck, dts=ck["dts"]), checkpoint_every=checkpoint_every)
        return state, rec
    state = setup.state.copy()
    state.check()
    parts.solver.check_state(state)
    parts.bind(state)
    rec = RunRecord(setup, parts, out, dt, name, record, snapshot_times(setup), overwrite=overwrite,
                    checkpoint_every=checkpoint_every)
    rec.record_every = record_every or max(1, int(setup.t_end / time_step(setup, dt, state, parts.physics) / 400))
    _warn_fixed_dt(setup, dt, state)
    rec.record(state)
    rec.snapshot_if_due(state)
    return state, rec


def _check_method(solver) -> None:
    """A method of one's own is refused before the first step if its members do not fit the loop: a
    :class:`Solver` whose ``rates`` does not take ``part`` (every stepper passes it), or neither protocol."""
    if isinstance(solver, Solver):
        try:
            inspect.signature(solver.rates).bind(solver, 0.0, part=PARTS[0])
        except TypeError as e:
            raise TypeError(f"{type(solver).__name__}.rates must take (state, dt, part='all'): the steppers pass "
                            f"part= (refsph.integrate.PARTS); {e}") from None
        except ValueError:                                  # no signature to read (a builtin): trust it
            pass
    elif not isinstance(solver, SelfAdvancing):
        raise TypeError(f"{type(solver).__name__} is neither a refsph.integrate.Solver nor a SelfAdvancing method")


def simulate(setup: Setup, method: str | None = None, *, scene: Scene | None = None,
             record: Callable[[State, Setup], dict] | None = None,
             metrics: Callable[[dict, State, Setup], dict] | None = None, solver: Solver | None = None,
             hook: Callable[[State, Solver], State | None] | None = None, out=None, dt: float | None = None,
             progress: bool = True, label: str = "", record_every: int | None = None, restart: bool = False,
             meta: dict | None = None, overwrite: bool = False,
             checkpoint_every: float | None = CHECKPOINT_EVERY_S) -> RunResult:
    """Run a prepared setup with ``method`` ('esph' | 'tlsph'), or with a ``solver`` of one's own (any
    :class:`~refsph.integrate.Solver`, e.g. one that wraps ``make_solver(method, setup)`` to add a force, or a
    :class:`~refsph.integrate.SelfAdvancing` method, e.g. an implicit one).

    ``record(state, setup) -> dict`` of scalars is called on the initial state, every ``record_every`` steps
    (default: about 400 records per run) and on the final state; the lists it builds are the ``history``, which
    ``metrics(history, state, setup) -> dict`` turns into ``summary['metrics']``. ``scene``: take both (and the
    name) from a :class:`~refsph.scenes.Scene`. ``hook(state, solver)`` is called after every step (after the
    solver's after-step work and the physics beside it: TLSPH's density is that of the positions before the hook)
    and may return a changed state (prescribed kinematics). ``dt=None``: the CFL step every step; else a fixed
    ``dt``. ``out``: the run folder (summary.json, snapshots/, reaction_forces.csv), None: nothing written. The
    step before each snapshot time is shortened to land on it, so snapshots are at their nominal times (to
    round-off). With ``out``, every snapshot also writes ``snapshots/restart.npz``; ``restart=True`` continues the
    run in ``out`` from there (same setup, solver and callbacks), and gives the same bits as the uninterrupted run;
    between snapshots a checkpoint is also written once ``checkpoint_every`` seconds of wall time have passed since
    the last (None: only at snapshots), so that a killed long run loses at most that much.
    ``meta``: extra entries for summary.json. ``out`` must be missing, empty or a run folder of the same scene and
    method (:func:`refsph.io.claim_run_folder`; ``overwrite=True``: any folder, of which only refsph's run files are
    removed). A run whose folder vanishes, or whose output cannot be written, stops with a SimulationError."""
    if solver is not None and method is not None and method != solver.method:
        raise ValueError(f"method {method!r} does not match the solver's ({solver.method!r}); give one of them")
    method = method if solver is None else solver.method
    _validate(method, setup.state.dim, setup.dp, setup.numerics, setup.t_end, dt, custom=solver is not None)
    record = record or (scene.record if scene is not None else None)
    metrics = metrics or (scene.metrics if scene is not None else None)
    solver = solver if solver is not None else make_solver(method, setup)
    _check_method(solver)
    parts = RunParts(solver, make_stepper(setup.numerics.integrator, solver), step_physics(setup))
    name = scene.name if scene is not None else label
    for message in warnings_for(scene.name if scene is not None else None, method, setup.numerics):
        warnings.warn(message, UserWarning, stacklevel=2)
    check_checkpoint_every(checkpoint_every)
    state, rec = _begin(setup, parts, out, dt, name, record, record_every, restart, overwrite, checkpoint_every)
    rec.summary.update(meta or {})
    show = _Progress(label or f"{name} {method} {state.dim}D", setup.t_end, progress, rec.out, state.t)
    try:
        while state.t < setup.t_end * (1 - 1e-12):
            state = _one_step(setup, parts, rec, state, dt, hook)
            show(rec.n_steps, state.t, rec.dts[-1])
        if rec.n_steps % rec.record_every != 0:
            rec.record(state)
        rec.summary["status"] = "ok"
    except KeyboardInterrupt:
        rec.summary["status"] = "interrupted"
        raise
    except OSError as e:                                    # the output could not be written (disk full, ...)
        rec.summary.update(status="error", error=f"writing the run's output failed: {e}")
        raise SimulationError(rec.summary["error"]) from e
    except Exception as e:
        if rec.summary["status"] == "running":
            rec.summary.update(status="error", error=f"{type(e).__name__}: {e}")
        raise
    finally:
        rec.finish(state, metrics)
    return RunResult(summary=rec.summary, state=state, history=rec.history, setup=setup)


def _one_step(setup: Setup, parts: RunParts, rec: RunRecord, state: State, dt: float | None, hook) -> State:
    """The step size (the CFL step, the physics' limits, the next snapshot time), the mechanical step, each
    physics after it, the hook, then the record and the snapshots that are due."""
    step_dt = time_step(setup, dt, state, parts.physics, parts.solver)
    rec.dts.append(step_dt)                                 # the step size chosen (before any cut to land on time)
    step_dt = min(step_dt, rec.next_output_time() - state.t)   # snapshots land on their nominal times
    prev, step = state, step_or_fail(state, parts, step_dt, rec)
    state = step.state
    for p in parts.physics:                                 # heat after the mechanical step
        with np.errstate(over="ignore", invalid="ignore"):  # a blow-up is caught just below, with its particle
            state = p.advance(prev, Step(state, step.rates), step_dt)
        if state.T is not None and not np.isfinite(state.T).all():
            k = int(np.flatnonzero(~np.isfinite(state.T))[0])
            raise rec.fail("nan", f"non-finite T at particle {k} after the {p.name} step of step {rec.n_steps} "
                                  f"(t = {prev.t:.6e} s)", prev)
    if setup.T_limit is not None and state.T is not None and np.max(state.T) > setup.T_limit:
        k = int(np.argmax(state.T))
        raise rec.fail("blow-up", f"particle {k} at {state.T[k]:.0f} K after step {rec.n_steps} (t = {state.t:.6e} s), "
                                  f"over the scene's limit T_limit = {setup.T_limit:.0f} K: a local numerical blow-up",
                       prev)
    if hook is not None:
        state = hook(state, parts.solver) or state
        if not (np.isfinite(state.v).all() and np.isfinite(state.x).all()):
            raise rec.fail("nan", f"the hook made the state non-finite after step {rec.n_steps}", prev)
    if rec.n_steps % rec.record_every == 0:
        with np.errstate(over="ignore", invalid="ignore"):  # near-blow-up states are caught above
            rec.record(state)
    rec.snapshot_if_due(state)
    _checkpoint_if_due(rec, state)
    return state


def run(scene_name: str, method: str, *, dim: int | None = None, dp: float | None = None,
        t_end: float | None = None, out=None, quick: bool = False, dt: float | None = None, progress: bool = True,
        numerics: dict | None = None, options: dict | None = None, restart: bool = False,
        particles=None, overwrite: bool = False, checkpoint_every: float | None = CHECKPOINT_EVERY_S) -> RunResult:
    """Build scene ``scene_name`` and run it. ``dim``: None = the scene's default; ``numerics`` overrides
    fields of the scene's Numerics; ``options`` sets the scene's own options (``Scene.options``); ``restart``:
    continue the run in ``out`` from its last checkpoint (:func:`restart_run` takes the arguments from it);
    ``particles``: an ``.npz`` of external particles that replace the scene's own (the scene keeps its material,
    numerics, boundaries and end time; :func:`refsph.io.state_from_particles` says what the file holds). Metrics
    that need the scene's own particle layout are then reported as ``metrics_error``. ``overwrite``: see
    :func:`simulate` (``out`` of another scene, method or not a run); so is ``checkpoint_every`` (not part of the
    run's arguments: it changes no number)."""
    setup, scene, metrics, args = _prepare(scene_name, method, dim, dp, t_end, quick, dt, numerics, options, particles)
    if restart and out is not None:
        _check_same_run(Path(out), args)
    return simulate(setup, method, scene=scene, out=out, dt=dt, progress=progress, restart=restart,
                    meta=dict(run_args=args), metrics=metrics, overwrite=overwrite, checkpoint_every=checkpoint_every)


class Built(NamedTuple):
    """What :func:`build` returns: the run's ``setup``, its ``scene`` and the ``metrics`` callback to pass on."""
    setup: Setup
    scene: Scene
    metrics: Callable


def build(scene_name: str, method: str, *, dim: int | None = None, dp: float | None = None,
          t_end: float | None = None, quick: bool = False, dt: float | None = None, numerics: dict | None = None,
          options: dict | None = None, particles=None) -> Built:
    """What :func:`run` would simulate, built and not run (the same arguments, checked the same way): the Setup
    of scene ``scene_name`` with ``numerics`` and ``options`` applied, its Scene and metrics. Change the setup, then
    ``simulate(b.setup, method, scene=b.scene, metrics=b.metrics, hook=...)``: a registered scene with a hook of
    one's own, a record, another solver (README, "Your own scene")."""
    setup, scene, metrics, _ = _prepare(scene_name, method, dim, dp, t_end, quick, dt, numerics, options, particles)
    return Built(setup, scene, metrics)


def _check_same_run(out: Path, args: dict) -> None:
    """A restart continues the run of ``out`` only with the arguments it was made with (``summary.json``'s
    ``run_args``): with others (another time step, another option) its checkpoint would be continued under other
    numerics and the result be neither run's. ValueError naming what differs."""
    try:
        made = json.loads((out / "summary.json").read_text()).get("run_args")
    except (OSError, ValueError):
        return                                              # no summary: _begin says what is missing
    asked = json.loads(json.dumps(json_ready(args)))
    if made is not None and made != asked:
        diff = {k: (made.get(k), asked.get(k)) for k in sorted(set(made) | set(asked)) if made.get(k) != asked.get(k)}
        raise ValueError(f"{out} holds a run made with other arguments (made with, asked: {diff}); continue it as "
                         f"it was made (refsph run --restart {out}) or start the new run in another folder")


def _prepare(scene_name, method, dim, dp, t_end, quick, dt, numerics, options, particles):
    """The setup of a run (scene, numerics and options applied, external particles read), its scene, metrics and
    the arguments that rebuild it (summary.json's run_args)."""
    scene = get_scene(scene_name)
    dim = scene.default_dim if dim is None else dim
    _validate(method, dim, dp, None, t_end, dt)
    setup = scene.setup(dim, dp, quick, **(options or {}))
    if numerics:
        unknown = set(numerics) - {f.name for f in dataclasses.fields(setup.numerics)}
        if unknown:
            raise ValueError(f"unknown numerical parameter(s): {', '.join(sorted(unknown))}")
        setup.numerics = dataclasses.replace(setup.numerics, **numerics)
    if t_end is not None:
        setup.t_end = t_end
    args = dict(scene_name=scene_name, method=method, dim=dim, dp=dp, t_end=t_end, quick=quick, dt=dt,
                numerics=numerics or {}, options=options or {})
    metrics = scene.metrics
    if particles is not None:
        args["particles"] = str(Path(particles).resolve())
        _use_particles(setup, particles)
        metrics = _tolerant(scene.metrics)
    return setup, scene, metrics, args


def check_run(scene_name: str, method: str, *, dim: int | None = None, dp: float | None = None,
              t_end: float | None = None, quick: bool = False, dt: float | None = None, numerics: dict | None = None,
              options: dict | None = None, particles=None) -> None:
    """Everything :func:`run` checks before its first step, without running: the scene and its options, the
    numerics, the method's solver, stepper and physics, the initial state. ``refsph run --method both`` checks both
    methods so that the second one's refusal comes before the first one runs (ValueError/TypeError naming what)."""
    setup, _, _, _ = _prepare(scene_name, method, dim, dp, t_end, quick, dt, numerics, options, particles)
    solver = make_solver(method, setup)
    make_stepper(setup.numerics.integrator, solver)
    step_physics(setup)
    state = setup.state.copy()
    state.check()
    solver.check_state(state)


def _use_particles(setup: Setup, path) -> None:
    """Replace the setup's particles by those of ``path`` (its clamps re-indexed from the file)."""
    T0 = setup.state.T[0] if setup.state.T is not None else None
    state, clamps, ids = state_from_particles(path, setup.material.rho0, T0, [c.name for c in setup.clamps])
    if state.dim != setup.state.dim:
        raise ValueError(f"{path}: the particles are {state.dim}D, the scene is {setup.state.dim}D")
    if setup.rigid and state.body is None:
        raise ValueError(f"{path}: the scene has rigid bodies ({', '.join(b.name for b in setup.rigid)}): give "
                         "the body id of every particle as body")
    setup.state = state
    setup.clamps = tuple(Clamp(c.name, clamps[c.name]) for c in setup.clamps)
    setup.arrays = {} if ids is None else {"id": ids}          # the file's particle ids, which the snapshots keep


def _tolerant(metrics):
    def measured(history, state, setup):
        try:
            return metrics(history, state, setup)
        except (KeyError, IndexError, ValueError) as e:       # a measure made for the scene's own particles
            return dict(metrics_error=f"{type(e).__name__}: {e}")
    return measured


def restart_run(run_dir, progress: bool = True, checkpoint_every: float | None = CHECKPOINT_EVERY_S) -> RunResult:
    """Continue the run in ``run_dir`` (made by :func:`run` / ``refsph run``) from its last checkpoint, with the
    arguments it was started with (``summary.json``'s ``run_args``). A PFEM run folder is continued by
    :func:`refsph.pfem_run.restart_pfem` (``refsph run --restart`` takes either)."""
    path = Path(run_dir) / "summary.json"
    try:
        summary = json.loads(path.read_text())
    except FileNotFoundError:
        raise ValueError(f"{path} does not exist: {run_dir} is not a refsph run folder") from None
    except ValueError as e:
        raise ValueError(f"{path} is not valid JSON ({e})") from None
    args = summary.get("run_args") if isinstance(summary, dict) else None
    if not isinstance(args, dict):
        raise ValueError(f"{path} has no run_args: only runs made by refsph run can be restarted")
    known = set(inspect.signature(run).parameters) - {"out", "progress", "restart", "overwrite", "checkpoint_every"}
    unknown = sorted(set(args) - known)
    if unknown or "scene_name" not in args or "method" not in args:
        what = f"unknown entries {', '.join(unknown)}" if unknown else "no scene_name or method"
        raise ValueError(f"{path}: run_args has {what}; it must hold the arguments of refsph.simulate.run "
                         f"({', '.join(sorted(known))})")
    try:
        return run(**args, out=run_dir, progress=progress, restart=True, checkpoint_every=checkpoint_every)
    except TypeError as e:
        raise ValueError(f"{path}: run_args do not fit refsph.simulate.run ({e})") from None
