"""The run driver: scene -> solver -> time loop -> summary.json and snapshots.

Nothing is lost on a crash: snapshots are written as the run goes, ``summary.json`` is written at the
end *and* on failure (``status`` says which), and a run that produces NaN/inf stops, reports the field,
particle, step and time, and writes ``snapshots/last_good.npz`` with the last finite state.
"""
from __future__ import annotations

import dataclasses
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import __version__
from .contact import PinballContact
from .esph import ESPHParams
from .integrate import ESPHSolver, TLSPHSolver, cfl_time_step, predictor_corrector_step
from .io import save_reactions, save_snapshot, write_json
from .kernels import get_kernel
from .neighbours import available_cores
from .scenes import Setup, convert_options, get_scene
from .state import State
from .tlsph import TLSPHParams

__all__ = ["SimulationError", "RunResult", "make_solver", "run", "simulate", "METHODS"]

METHODS = ("esph", "tlsph")


class SimulationError(RuntimeError):
    """A run stopped because the state became non-finite (message says where and when)."""


@dataclass
class RunResult:
    summary: dict
    state: State
    history: dict
    setup: Setup


def make_solver(method: str, setup: Setup):
    """ESPH or TLSPH solver for a setup."""
    nm = setup.numerics
    if isinstance(nm.threads, bool) or not isinstance(nm.threads, (int, np.integer)) or nm.threads < 0:
        raise ValueError(f"Numerics.threads must be a whole number >= 0 (0 = one thread per available core), "
                         f"got {nm.threads!r}")
    threads = available_cores() if nm.threads == 0 else int(nm.threads)    # (numbers do not depend on it)
    kernel = get_kernel(nm.kernel)
    h = setup.h
    if method == "esph":
        if setup.friction is not None:
            raise ValueError("friction is a law of the TLSPH pinball contact; ESPH tools act through the SPH "
                             "sums and have no friction model (run TLSPH, or set friction=None)")
        prm = ESPHParams(h=h, dp=setup.dp, beta1=nm.beta1, beta2=nm.beta2, gamma=nm.gamma, n_ap=nm.n_ap,
                         eps=nm.eps, kernel=kernel)
        return ESPHSolver(setup.material, prm, skin_factor=nm.skin_factor, plasticity=setup.plasticity,
                          mirror=setup.mirror, walls=setup.walls, rigid=setup.rigid, clamps=setup.clamps,
                          threads=threads)
    if method == "tlsph":
        prm = TLSPHParams(h=h, beta1=nm.beta1, beta2=nm.beta2, eps=nm.eps, kernel=kernel,
                          corrected=nm.corrected, ref_update_strain=nm.ref_update_strain)
        contact = None
        if setup.friction is not None and not setup.rigid:
            raise ValueError("friction acts in the contact with rigid bodies, and this setup has none")
        if setup.rigid:
            k = nm.contact_k if nm.contact_k is not None else setup.dp / (2.0 * h)
            contact = PinballContact(k=k, K_p=nm.contact_Kp, friction=setup.friction)
        return TLSPHSolver(setup.material, prm, plasticity=setup.plasticity, mirror=setup.mirror,
                           walls=setup.walls, rigid=setup.rigid, clamps=setup.clamps, contact=contact,
                           dp=setup.dp, threads=threads)
    raise ValueError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")


def _validate(method, dim, dp, setup_numerics=None, t_end=None, dt=None):
    if method not in METHODS:
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


def simulate(setup: Setup, method: str, *, scene=None, out=None, dt: float | None = None,
             progress: bool = True, label: str = "", record_every: int | None = None) -> RunResult:
    """Run a prepared setup. ``dt=None``: CFL step every step; else fixed ``dt`` (checked against CFL)."""
    _validate(method, setup.state.dim, setup.dp, setup.numerics, setup.t_end, dt)
    state = setup.state.copy()
    state.check()
    solver = make_solver(method, setup)
    solver.check_state(state)
    out = Path(out) if out is not None else None
    if out is not None:
        (out / "snapshots").mkdir(parents=True, exist_ok=True)
        for old in (out / "snapshots").glob("*.npz"):
            old.unlink()

    def F_of(s):
        return solver.deformation_gradient(s) if method == "tlsph" else None

    history: dict[str, list] = {}

    def record(s):
        if scene is not None:
            for k, val in scene.record(s, setup).items():
                history.setdefault(k, []).append(val)

    snap_times = np.linspace(0.0, setup.t_end, setup.n_snapshots + 1)
    extra = [t for t in setup.snapshot_times if 0.0 < t < setup.t_end]
    snap_times = np.unique(np.concatenate([snap_times, extra]))
    snap_next = 0
    snapshots = []

    def update_outputs(s):
        """The summary's run record and the reaction history (and its CSV) as they stand at state s."""
        wall = time.perf_counter() - t0
        summary.update(n_steps=n_steps, wall_time_s=wall, cpu_time_s=time.process_time() - c0, t_final=s.t,
                       dt_min=float(min(dts)) if dts else None, dt_max=float(max(dts)) if dts else None,
                       particle_steps_per_s=s.n * n_steps / wall if wall > 0 else None,
                       snapshots=list(snapshots), diagnostics=solver.diagnostics())
        reactions = solver.reaction_history()
        if reactions:
            history["reaction"] = reactions
            if out is not None:
                save_reactions(out / "reaction_forces.csv", reactions, s.dim)
                summary["reaction_forces_file"] = "reaction_forces.csv"

    def maybe_snapshot(s, force=False):
        nonlocal snap_next
        while snap_next < len(snap_times) and (s.t >= snap_times[snap_next] * (1 - 1e-12) or force):
            if out is not None:
                name = f"snap_{snap_next:05d}.npz"
                save_snapshot(out / "snapshots" / name, s, setup.material, F_of(s))
                snapshots.append(name)
                if 0 < snap_next < len(snap_times) - 1:     # a killed run keeps its record up to here
                    update_outputs(s)
                    write_json(out / "summary.json", summary)
            snap_next += 1
            force = False
            if s.t < setup.t_end * (1 - 1e-12):
                break

    summary = dict(scene=scene.name if scene is not None else label, method=method, dim=state.dim,
                   dp=setup.dp, h=setup.h, n_particles=state.n, t_end=setup.t_end, n_steps=0,
                   dt_mode="fixed" if dt is not None else "cfl", courant=setup.numerics.courant,
                   numerics=dataclasses.asdict(setup.numerics), threads=solver.threads,
                   material=dataclasses.asdict(setup.material),
                   plasticity=dataclasses.asdict(setup.plasticity) if setup.plasticity is not None else None,
                   boundaries=dict(symmetry_axes=list(setup.mirror.axes) if setup.mirror is not None else [],
                                   walls=[dataclasses.asdict(w) for w in setup.walls],
                                   rigid_bodies=[dataclasses.asdict(b) for b in setup.rigid],
                                   clamps=[c.to_dict() for c in setup.clamps],
                                   friction=(dataclasses.asdict(setup.friction) if setup.friction is not None
                                             else None)),
                   scene_info=setup.info, snapshot_times=[float(t) for t in snap_times],
                   refsph_version=__version__,
                   status="running", metrics={})

    t0, c0 = time.perf_counter(), time.process_time()
    last_print = t0
    n_steps = 0
    dts = []
    if record_every is None:
        dt_est = dt if dt is not None else cfl_time_step(state, setup.material, setup.h, setup.numerics.courant)
        record_every = max(1, int(setup.t_end / dt_est / 400))
    if dt is not None:
        dt_cfl = cfl_time_step(state, setup.material, setup.h, setup.numerics.courant)
        if dt > dt_cfl:
            print(f"refsph: warning: fixed dt = {dt:.3e} s exceeds the CFL estimate {dt_cfl:.3e} s "
                  f"(Courant {setup.numerics.courant}); the run may become unstable", file=sys.stderr)
    record(state)
    maybe_snapshot(state)
    tag = label or f"{summary['scene']} {method} {state.dim}D"
    try:
        while state.t < setup.t_end * (1 - 1e-12):
            step_dt = dt if dt is not None else cfl_time_step(state, setup.material, setup.h,
                                                               setup.numerics.courant)
            dts.append(step_dt)                             # the step size chosen (before any cut to land on t_end)
            step_dt = min(step_dt, setup.t_end - state.t)
            prev = state
            try:
                with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # non-finite: caught below
                    state = predictor_corrector_step(state, solver, step_dt)
            except ValueError as e:                         # e.g. a particle crossed a symmetry plane
                msg = f"step {n_steps + 1} (t = {prev.t:.6e} s) failed: {e}"
                if out is not None:
                    save_snapshot(out / "snapshots" / "last_good.npz", prev, setup.material, F_of(prev))
                    msg += f"; last good state written to {out / 'snapshots' / 'last_good.npz'}"
                summary.update(status="error", error=msg)
                raise SimulationError(msg) from e
            n_steps += 1
            if not (np.isfinite(state.v).all() and np.isfinite(state.x).all()):
                bad = state.first_nonfinite() or ("x/v", -1)
                msg = (f"non-finite {bad[0]} at particle {bad[1]} in step {n_steps} "
                       f"(t = {prev.t:.6e} s -> {state.t:.6e} s)")
                if out is not None:
                    save_snapshot(out / "snapshots" / "last_good.npz", prev, setup.material, F_of(prev))
                    msg += f"; last good state written to {out / 'snapshots' / 'last_good.npz'}"
                summary.update(status="nan", error=msg)
                raise SimulationError(msg)
            if n_steps % record_every == 0:
                with np.errstate(over="ignore", invalid="ignore"):  # near-blow-up states are caught above
                    record(state)
            maybe_snapshot(state)
            now = time.perf_counter()
            if progress and now - last_print > 2.0:
                frac = state.t / setup.t_end
                el = now - t0
                print(f"[{tag}] step {n_steps:6d}  t = {state.t:.3e} s ({100 * frac:5.1f} %)  "
                      f"dt = {step_dt:.2e} s  elapsed {el:6.1f} s, ~{el / max(frac, 1e-9) - el:6.1f} s left",
                      file=sys.stderr, flush=True)
                last_print = now
        if n_steps % record_every != 0:
            record(state)
        summary["status"] = "ok"
    except KeyboardInterrupt:
        summary["status"] = "interrupted"
        raise
    except Exception as e:
        if summary["status"] == "running":
            summary.update(status="error", error=f"{type(e).__name__}: {e}")
        raise
    finally:
        update_outputs(state)
        if scene is not None and history and summary["status"] == "ok":
            summary["metrics"] = scene.metrics(history, state, setup)
        if out is not None:
            write_json(out / "summary.json", summary)
    return RunResult(summary=summary, state=state, history=history, setup=setup)


def run(scene_name: str, method: str, *, dim: int | None = None, dp: float | None = None,
        t_end: float | None = None, out=None, quick: bool = False, dt: float | None = None, progress: bool = True,
        numerics: dict | None = None, options: dict | None = None) -> RunResult:
    """Build scene ``scene_name`` and run it. ``dim``: None = the scene's default; ``numerics`` overrides
    fields of the scene's Numerics; ``options`` sets the scene's own options (``Scene.options``)."""
    scene = get_scene(scene_name)
    if dim is None:
        dim = scene.default_dim
    _validate(method, dim, dp, None, t_end, dt)
    options = convert_options(scene, options or {})
    if dp is None:
        dp = scene.default_dp(dim, quick)
    setup = scene.build(dim, dp, quick, **options)
    if numerics:
        unknown = set(numerics) - {f.name for f in dataclasses.fields(setup.numerics)}
        if unknown:
            raise ValueError(f"unknown numerical parameter(s): {', '.join(sorted(unknown))}")
        setup.numerics = dataclasses.replace(setup.numerics, **numerics)
    if t_end is not None:
        setup.t_end = t_end
    return simulate(setup, method, scene=scene, out=out, dt=dt, progress=progress)
