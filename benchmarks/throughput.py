"""Throughput of one full elastic time step, ESPH and TLSPH, on one core.

A 2D square-lattice block of AISI 4340 (rho0 = 7830 kg/m^3, E = 207 GPa, nu = 0.3), spacing dp = 0.1 mm,
h = 1.5 dp, cubic kernel, with small random velocities (1 m/s rms per component, fixed seed, so that about
half of the pairs approach and the artificial viscosity works), is advanced with ``predictor_corrector_step``
(two rate evaluations + the solver's after-step work) at its CFL time step. The solvers are built exactly
as a run builds them (``refsph.simulate.make_solver`` with the default ``refsph.scenes.Numerics``):
artificial viscosity beta1 = beta2 = 1.5, ESPH artificial pressure gamma = 0.3, TLSPH kernel-gradient
correction, ESPH Verlet skin 0.1 h.

One warm-up step (it builds the ESPH pair list / the TLSPH reference operator) is not timed; its time is
the column ``setup s``. Then ``--steps`` steps are timed ``--repeats`` times and the best repetition is
reported: other work on the machine can only make a repetition slower. With velocities this small the pair
list is not rebuilt and the reference configuration is not updated inside the timed steps.

    particle-steps/s = particles x steps / wall time
    ns/pair/step     = wall time / (steps x half pairs), half pair = (i < j) with |x_i - x_j| < 2h

Both steppers are timed (``--integrators``): the predictor-corrector (two rate evaluations per step) and the
leapfrog (one force and one deformation-rate evaluation per step, ``refsph.integrate.leapfrog_step``).

Error per unit of work (``--study``): the 2D quick elastic bar of ``refsph run bar`` (TLSPH, the default
artificial viscosity, two periods) with each stepper at Courant 0.1 ... 0.6; the error is the largest
difference of the modal amplitude history from a reference run (leapfrog, Courant 0.025), relative to the initial
amplitude; the work is the wall time of the run. Written to the same JSON (``integrator_study``).

Usage:  python benchmarks/throughput.py [--sizes 100 200] [--steps N] [--repeats R] [--json PATH] [--study]

What a rerun writes (``write_results``, pair_blocks.py's too): the results it timed replace those of the same method,
stepper and size in the JSON (``--json``), every other result stays as it was, so a run restricted with
``--sizes``, ``--methods`` or ``--integrators`` drops nothing; the integrator study is replaced only by ``--study``.
Where results of an earlier run are kept, the file's ``meta`` stays theirs and each new result carries, as
``run_meta``, the fields of its own run's meta that differ (versions, commit). A run that fails writes nothing.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

# one core: pin the BLAS / OpenMP thread pools before NumPy is imported (scipy.sparse is single-threaded)
study.pin_threads()

import argparse  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
import scipy  # noqa: E402

import refsph  # noqa: E402
from refsph.integrate import STEPPERS, cfl_time_step  # noqa: E402
from refsph.neighbours import find_pairs  # noqa: E402
from refsph.scenes import Numerics, Setup, aisi4340_material, lattice  # noqa: E402
from refsph.simulate import make_solver  # noqa: E402
from refsph.state import make_state  # noqa: E402

METHODS = ("esph", "tlsph")


def block_setup(n_side: int, dp: float = 1.0e-4, v_rms: float = 1.0, seed: int = 2024) -> Setup:
    """n_side x n_side lattice block of AISI 4340 with random velocities of rms ``v_rms`` per component."""
    mat = aisi4340_material()
    x = lattice([n_side * dp, n_side * dp], dp)
    v = v_rms * np.random.default_rng(seed).standard_normal(x.shape)
    state = make_state(x, v, mat.rho0, dp * dp)
    return Setup(state=state, material=mat, dp=dp, numerics=Numerics(threads=1), t_end=1.0, n_snapshots=0)


def _step_function(integrator: str, solver):
    """``step(state, solver, dt) -> state`` as a run steps: one stepper object for the whole run where refsph has
    them (``refsph.integrate.make_stepper``: the leapfrog keeps its force between steps), else the step function."""
    import refsph.integrate
    make = getattr(refsph.integrate, "make_stepper", None)
    if make is None:
        return STEPPERS[integrator]
    stepper = make(integrator, solver)
    return lambda state, solver, dt: stepper.step(state, solver, dt).state


def half_pairs_within_support(setup: Setup) -> int:
    """Half pairs (i < j) with |x_i - x_j| < 2h: the pairs with a non-zero kernel."""
    x = setup.state.x
    I, J = find_pairs(x, 2.0 * setup.h)
    r2 = np.sum((x[I] - x[J]) ** 2, axis=1)
    return int(np.count_nonzero(r2 < (2.0 * setup.h) ** 2))


def time_method(method: str, setup: Setup, steps: int, repeats: int, integrator: str = "predictor_corrector") -> dict:
    """Best-of-``repeats`` wall (and CPU) time of ``steps`` steps of ``integrator``, after one warm-up step."""
    solver = make_solver(method, setup)
    step = _step_function(integrator, solver)
    state = setup.state.copy()
    dt = cfl_time_step(state, setup.material, setup.h, setup.numerics.courant)
    t0 = time.perf_counter()
    state = step(state, solver, dt)                            # warm-up: builds the pairs / the operator
    t_setup = time.perf_counter() - t0
    wall, cpu = np.inf, np.inf
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(steps):
            state = step(state, solver, dt)
        wall = min(wall, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
    if not (np.isfinite(state.v).all() and np.isfinite(state.x).all()):
        raise RuntimeError(f"{method}: non-finite state in the benchmark run")
    n, n_half = state.n, half_pairs_within_support(setup)
    return dict(method=method, integrator=integrator, n_particles=n, half_pairs=n_half, pairs_per_particle=n_half / n,
                steps=steps, repeats=repeats, wall_s=wall, cpu_s=cpu, s_per_step=wall / steps,
                particle_steps_per_s=n * steps / wall, ns_per_pair_step=1e9 * wall / (steps * n_half),
                setup_s=t_setup, diagnostics=solver.diagnostics())


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[100, 200],
                    help="lattice side lengths (particles = side^2); default: 100 200")
    ap.add_argument("--steps", type=int, default=None,
                    help="timed steps per repetition (default: about 4e5 particle-steps, at least 2)")
    ap.add_argument("--repeats", type=int, default=5, help="repetitions, the best is reported (default 5)")
    ap.add_argument("--methods", nargs="+", default=list(METHODS), choices=METHODS)
    ap.add_argument("--integrators", nargs="+", default=list(STEPPERS), choices=list(STEPPERS))
    ap.add_argument("--study", action="store_true", help="also the error-per-work study of both steppers")
    ap.add_argument("--json", type=Path, default=Path(__file__).with_name("throughput.json"),
                    help="where to write the results (default: benchmarks/throughput.json)")
    args = ap.parse_args(argv)

    print(f"refsph {refsph.__version__}, NumPy {np.__version__}, SciPy {scipy.__version__}, "
          f"Python {platform.python_version()} on {platform.machine()}, single core "
          f"(BLAS/OpenMP pools pinned to 1 thread; scipy.sparse is single-threaded);")
    print("2D AISI 4340 block, h = 1.5 dp, cubic kernel, artificial viscosity 1.5/1.5, ESPH artificial "
          "pressure 0.3, TLSPH corrected; one step of predictor_corrector = 2 rate evaluations, of leapfrog = "
          "1 force + 1 deformation-rate evaluation")
    print("pair = half pair (i < j) with |x_i - x_j| < 2h; best of the repetitions\n")
    header = (f"{'method':6s} {'integrator':19s} {'particles':>9s} {'pairs/part':>10s} {'steps':>5s} "
              f"{'particle-steps/s':>16s} {'ns/pair/step':>12s} {'wall s':>7s} {'cpu s':>7s} {'setup s':>7s}")
    print(header)
    print("-" * len(header))
    results = []
    for side in args.sizes:
        setup = block_setup(side)
        n = setup.state.n
        steps = args.steps or max(2, int(round(4e5 / n)))
        for method, integrator in [(m, i) for m in args.methods for i in args.integrators]:
            r = time_method(method, setup, steps, args.repeats, integrator)
            results.append(r)
            print(f"{method:6s} {integrator:19s} {n:9d} {r['pairs_per_particle']:10.2f} {steps:5d} "
                  f"{r['particle_steps_per_s']:16.3e} {r['ns_per_pair_step']:12.1f} {r['wall_s']:7.3f} "
                  f"{r['cpu_s']:7.3f} {r['setup_s']:7.3f}", flush=True)
    study = integrator_study() if args.study else None
    write_results(args.json, results, lambda r: (r["method"], r["integrator"], r["n_particles"]), threads=1,
                  pair_definition="half pair (i < j) with |x_i - x_j| < 2h in the initial lattice",
                  timing="best of `repeats` repetitions of `steps` steps of each integrator, after one warm-up "
                         "step; particle_steps_per_s and ns_per_pair_step from the wall time",
                  **({"integrator_study": study} if study else {}))
    return results


def integrator_study(courants=(0.1, 0.2, 0.3, 0.45, 0.6)) -> list[dict]:
    """Error against work of both steppers on the quick 2D TLSPH bar (module text); each run is timed in a fresh
    process of its own (study.timed_in_subprocess), so no earlier run's heap or caches enter its wall time."""

    def amplitude(integrator, courant):
        return study.timed_in_subprocess(bar_amplitude, integrator, courant)

    ref, _, _ = amplitude("leapfrog", 0.025)
    print(f"\n{'integrator':19s} {'courant':>7s} {'steps':>6s} {'wall s':>7s} {'amplitude error':>15s}")
    out = []
    for integrator in STEPPERS:
        for c in courants:
            h, wall, steps = amplitude(integrator, c)
            err = float(np.max(np.abs(np.interp(ref[:, 0], h[:, 0], h[:, 1]) - ref[:, 1])) / abs(ref[0, 1]))
            out.append(dict(integrator=integrator, courant=c, steps=steps, wall_s=wall, amplitude_error=err))
            print(f"{integrator:19s} {c:7.3f} {steps:6d} {wall:7.2f} {err:15.3e}", flush=True)
    return out


def bar_amplitude(integrator: str, courant: float):
    """(amplitude history, wall time, steps) of the quick 2D TLSPH bar with one stepper at one Courant number."""
    from refsph.simulate import run
    t0 = time.perf_counter()
    res = run("bar", "tlsph", dim=2, quick=True, progress=False,
              numerics=dict(threads=1, integrator=integrator, courant=courant))
    h = np.asarray(res.summary["metrics"]["amplitude_history"])
    return h, time.perf_counter() - t0, res.summary["n_steps"]


def software() -> dict:
    """Versions and machine, for the record of a timing."""
    return dict(refsph=refsph.__version__, numpy=np.__version__, scipy=scipy.__version__,
                python=platform.python_version(), machine=platform.machine(), cores=os.cpu_count())


SECTIONS = ("integrator_study",)      # meta fields that are results of their own: replaced only when given


def write_results(path: Path, results: list, key, **meta) -> None:
    """{meta: software() + meta, results} as JSON at path, merged into what the file holds (module text): a result
    replaces the one of the same ``key(result)`` (study.merge_records), the others stay as they were."""
    meta = dict(software(), **meta)
    old = json.loads(path.read_text()) if path.exists() else {}
    old_meta, new_keys = old.get("meta", {}), {key(r) for r in results}
    kept = [r for r in old.get("results", []) if key(r) not in new_keys]
    sections = {k: v for k, v in meta.items() if k in SECTIONS}
    if kept:                            # the file's meta stays the earlier run's; the new results say where they differ
        differ = {k: v for k, v in meta.items() if k not in SECTIONS and old_meta.get(k) != v}
        results = [dict(r, run_meta=differ) if differ else r for r in results]
        meta = dict(old_meta, **sections)
    else:
        meta = {**{k: v for k, v in meta.items() if k not in SECTIONS},
                **{k: old_meta[k] for k in SECTIONS if k in old_meta}, **sections}
    doc = dict(meta=meta, results=study.merge_records(old.get("results", []), results, key))
    wrote = study.write_if_changed(path, json.dumps(doc, indent=2) + "\n")
    print(f"\n{'written' if wrote else 'unchanged:'} {path}")


if __name__ == "__main__":
    main()
