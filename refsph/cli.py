"""Command line: ``refsph list``, ``refsph run SCENE [--method {esph,tlsph,both,pfem}] ...``, ``refsph book``,
``refsph oracle DIR``, ``refsph compare REF TEST``, ``refsph export RUN_DIR --vtk`` and ``refsph handout DIR``.

Exit codes (:data:`EXIT_CODES`): 0 done, 1 a comparison found a difference (or the book failed), 2 bad input (a
message names the parameter or the file), 3 the run failed, 4 an internal error (a bug), 130 interrupted. Every
subcommand's errors end in one boundary (:func:`main`): a message, never a traceback (``REFSPH_DEBUG=1``)."""
from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import zipfile

import numpy as np

from .scenes import SCENES, Numerics, parse_bool
from .scenes.base import numerics_field_optional
from .simulate import CHECKPOINT_EVERY_S, METHODS, SimulationError, check_run, run


def _fmt(v):
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, np.ndarray) or isinstance(v, list):
        return f"<{np.asarray(v).shape} array>"
    return str(v)


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="refsph", description="Reference ESPH/TLSPH for metal machining")
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("list", help="list the scenes")
    b = sub.add_parser("book", help="execute the chapters and render them as a book (build/book/index.html)")
    b.add_argument("--full", action="store_true", help="full resolution (default: quick mode, REFSPH_QUICK=1)")
    b.add_argument("--rerun", action="store_true", help="execute every chapter again (default: reuse the "
                   "executed notebooks in build/executed/ that are newer than their chapter)")
    b.add_argument("--jobs", type=int, default=2, help="chapters executed at a time (default 2)")
    hd = sub.add_parser("handout", help="write the chapters as notebooks into DIR: the students' copies, or with "
                                        "--instructor the lecturer's (each exercise followed by its worked solution)")
    hd.add_argument("dir")
    hd.add_argument("--instructor", action="store_true", help="the lecturer's copy, with chapters/solutions/ merged in")
    hd.add_argument("--only", nargs="+", default=None, metavar="NN", help="these chapters only (e.g. 01 05)")
    hd.add_argument("--force", action="store_true", help="replace notebooks already in DIR (default: keep them)")
    o = sub.add_parser("oracle", help="write the golden cases (inputs, refsph's outputs, tolerances) into DIR, "
                                      "computed with NumPy's, OpenBLAS's and glibc's CPU-independent code paths "
                                      "(refsph.crosscheck.golden; every case: a few minutes)")
    o.add_argument("dir")
    o.add_argument("--only", nargs="+", default=None, metavar="CASE",
                   help="write these cases only (names or patterns such as 'kernel_*'), keeping the others in DIR")
    c = sub.add_parser("compare", help="compare golden-case or run folders: TEST against REF (exit 1 if any "
                                       "quantity is outside its tolerance)")
    c.add_argument("ref")
    c.add_argument("test")
    c.add_argument("--only", nargs="+", default=None, metavar="CASE",
                   help="golden cases to compare (names or patterns such as 'kernel_*'; default: every case)")
    c.add_argument("--tolerances", default=None, metavar="FILE",
                   help='JSON: {"fields": {NAME: rtol}, "metrics": {NAME: rtol}, "field": rtol, "metric": rtol}')
    e = sub.add_parser("export", help="export a run folder's snapshots (--vtk: VTU files and a ParaView .pvd)")
    e.add_argument("run_dir")
    e.add_argument("--vtk", action="store_true", required=True, help="VTK (ParaView) via meshio")
    r = sub.add_parser("run", help="run a scene")
    r.add_argument("scene", nargs="?", help="the scene (see 'refsph list'); not with --restart")
    r.add_argument("--from", dest="particles", default=None, metavar="FILE.npz",
                   help="start the scene's physics from external particles (x, v, m; optional body, rho, S, S_zz, "
                        "X, V0, T, clamp_<name>; see refsph.io.state_from_particles)")
    r.add_argument("--restart", default=None, metavar="RUN_DIR",
                   help="continue the run in RUN_DIR from its last checkpoint (written at every snapshot and every "
                        "--checkpoint-every seconds of wall time), with the arguments it was started with "
                        "(bit for bit the same as the uninterrupted run)")
    r.add_argument("--method", choices=METHODS + ("both", "pfem"), default=None,
                   help="formulation (default: the scene's; 'pfem': the Particle Finite Element Method, for "
                        "thermal_cutting; 'both' runs ESPH then TLSPH, or for a scene with a PFEM version its SPH "
                        "method then the PFEM)")
    r.add_argument("--dim", type=int, choices=(2, 3), default=None, help="dimension (default: the scene's)")
    r.add_argument("--dp", type=float, default=None, help="particle spacing [m] (default: the scene's)")
    r.add_argument("--t-end", type=float, default=None, help="end time [s] (default: the scene's)")
    r.add_argument("--dt", type=float, default=None, help="fixed time step [s] (default: CFL)")
    r.add_argument("--out", default=None, help="output directory (default: runs/SCENE-METHOD-DIMd); refused if it "
                   "holds anything but a run of the same scene and method")
    r.add_argument("--overwrite", action="store_true", help="write into --out whatever it holds: only the files "
                   "refsph writes in a run folder are removed, every other file is kept")
    r.add_argument("--quick", action="store_true", help="coarse, fast version of the scene")
    r.add_argument("--quiet", action="store_true", help="no progress lines")
    r.add_argument("--checkpoint-every", type=_seconds, default=CHECKPOINT_EVERY_S, metavar="SECONDS",
                   help=f"a restart checkpoint between snapshots every SECONDS of wall time (default "
                        f"{CHECKPOINT_EVERY_S:g}; 0: after every step; inf: only at snapshots); a --restart takes "
                        "its own (not the first part's)")
    r.add_argument("--option", action="append", default=[], metavar="NAME=VALUE",
                   help="a scene option (see 'refsph list'), e.g. --option T_melt=1793 (or --T_melt 1793); "
                        "repeatable")
    r.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a numerical parameter (a field of refsph.scenes.Numerics), e.g. --set contact_Kp=10, "
                        "--set ref_update_strain=none; repeatable")
    return ap


NUMBER_FLAGS = ("--dp", "--t-end", "--dt", "--checkpoint-every")


def _seconds(text: str) -> float:
    """--checkpoint-every: a number of seconds >= 0 (inf allowed); argparse's message otherwise."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"must be >= 0 seconds (inf: only at snapshots), got {text!r}")
    return value


def _join_negative_numbers(argv: list) -> list:
    """``--dp -1e-3`` as ``--dp=-1e-3``: argparse takes a token like -1e-3 for an option and says 'expected one
    argument'; joined, the value reaches the check that names it (dp must be positive)."""
    out, k = [], 0
    while k < len(argv):
        if argv[k] in NUMBER_FLAGS and k + 1 < len(argv) and argv[k + 1].startswith("-"):
            try:
                float(argv[k + 1])
            except ValueError:
                pass
            else:
                out.append(f"{argv[k]}={argv[k + 1]}")
                k += 2
                continue
        out.append(argv[k])
        k += 1
    return out


EXIT_CODES = {0: "done", 1: "compare found a difference / the book failed", 2: "bad input (a message says which)",
              3: "the run failed (non-finite state, lost or unwritable output)", 4: "internal error (a bug in refsph)",
              130: "interrupted"}


def main(argv=None) -> int:
    """``refsph``'s one error boundary: every subcommand's error ends as a message and an exit code
    (:data:`EXIT_CODES`), never a traceback (``REFSPH_DEBUG=1`` shows it)."""
    try:
        return _main(argv)
    except KeyboardInterrupt:
        print("refsph: interrupted", file=sys.stderr)
        return 130
    except SystemExit:
        raise
    except MemoryError:
        if os.environ.get("REFSPH_DEBUG"):
            raise
        print("refsph: out of memory: the problem is too large for this machine (choose a larger dp)",
              file=sys.stderr)
        return 2
    except SimulationError as e:
        print(f"refsph: run failed: {e}", file=sys.stderr)
        return 3
    except (ValueError, TypeError, KeyError, OSError, EOFError, zipfile.BadZipFile) as e:
        if os.environ.get("REFSPH_DEBUG"):
            raise
        print(f"refsph: {e if isinstance(e, ValueError) else f'{type(e).__name__}: {e}'}", file=sys.stderr)
        return 2
    except Exception as e:                                  # noqa: BLE001 -- the boundary: a bug, said as one
        if os.environ.get("REFSPH_DEBUG"):
            raise
        print(f"refsph: internal error (a bug in refsph; please report it with the command line): "
              f"{type(e).__name__}: {e}  [REFSPH_DEBUG=1 shows the traceback]", file=sys.stderr)
        return 4


def _main(argv=None) -> int:
    ap = _parser()
    args, extra = ap.parse_known_args(_join_negative_numbers(list(sys.argv[1:] if argv is None else argv)))
    if extra and args.cmd != "run":
        ap.error(f"unrecognized arguments: {' '.join(extra)}")
    if args.cmd == "book":
        return _book(args)
    if args.cmd == "handout":
        from .teaching.handout import write_handout
        written = write_handout(args.dir, instructor=args.instructor, only=args.only, force=args.force)
        print(f"{len(written)} {'lecturer' if args.instructor else 'student'} notebooks in {args.dir}")
        return 0
    if args.cmd == "oracle":
        from .crosscheck.golden import write_golden_cases
        try:
            names = write_golden_cases(args.dir, args.only)
        except RuntimeError as e:
            print(f"refsph: {e}", file=sys.stderr)
            return 3
        print(f"{len(names)} golden cases in {args.dir}: {', '.join(names)}")
        return 0
    if args.cmd == "compare":
        return _compare(args)
    if args.cmd == "export":
        from .crosscheck.export import export_vtk
        try:
            print(f"ParaView: {export_vtk(args.run_dir)}")
        except (ImportError, OSError) as e:
            print(f"refsph: {e}", file=sys.stderr)
            return 2
        return 0
    if args.cmd == "list":
        from .pfem_run import PFEM_SCENES, pfem_options
        for name, sc in SCENES.items():
            print(f"{name:10s} {sc.description}")
            print(f"{'':10s} default: {sc.default_dim}D, methods {', '.join(sc.methods)}")
            if name in PFEM_SCENES:
                print(f"{'':10s} also --method pfem (2D; its options: {', '.join(pfem_options())})")
            for opt, (default, help_) in sc.options.items():
                print(f"{'':10s} --option {opt}=VALUE  {help_} (default {default})")
        return 0
    return _run(args, extra)


def _attempt(fn):
    """(fn(), 0), or (None, exit code) with the message on stderr: 3 for a run that failed, 2 for bad input."""
    try:
        return fn(), 0
    except SimulationError as e:
        print(f"refsph: run failed: {e}", file=sys.stderr)
        return None, 3
    except (ValueError, OSError) as e:
        print(f"refsph: {e}", file=sys.stderr)
        return None, 2


def _restart(args, extra=()) -> int:
    from .simulate import restart_run
    given = [flag for flag, value in (("a scene", args.scene), ("--from", args.particles), ("--method", args.method),
                                      ("--dim", args.dim), ("--dp", args.dp), ("--t-end", args.t_end),
                                      ("--dt", args.dt), ("--out", args.out), ("--overwrite", args.overwrite or None),
                                      ("--quick", args.quick or None), ("--option", args.option or None),
                                      ("--set", args.set or None)) if value is not None]
    if given or extra:
        print(f"refsph: --restart continues the run in RUN_DIR with the scene and settings of its summary.json; it "
              f"takes no {', '.join(given + list(extra))} (only --quiet and --checkpoint-every)", file=sys.stderr)
        return 2
    from .pfem_run import is_pfem_run, restart_pfem
    again = restart_pfem if is_pfem_run(args.restart) else restart_run
    res, code = _attempt(lambda: again(args.restart, progress=not args.quiet, checkpoint_every=args.checkpoint_every))
    if code:
        return code
    s = res.summary
    print(f"{s['scene']} {s['method']} {s['dim']}D: continued to t = {s['t_final']:.6g} s, {s['n_steps']} steps "
          f"in all; output: {args.restart}/summary.json")
    return 0


def _compare(args) -> int:
    from .crosscheck.compare import compare, format_table
    from .io import read_json
    try:
        tol = read_json(args.tolerances, "tolerances file") if args.tolerances else None
        rows = compare(args.ref, args.test, tol, only=args.only)
    except (OSError, ValueError, KeyError) as e:
        print(f"refsph: {e}", file=sys.stderr)
        return 2
    print(format_table(rows))
    return 0 if all(r.passed for r in rows) else 1


def _book(args) -> int:
    from .teaching.book import build_book
    try:
        index = build_book(quick=not args.full, reuse=not args.rerun, jobs=args.jobs)
    except Exception as e:                                  # a chapter's failing cell, a timeout, no sphinx ...
        print(f"refsph: the book was not built: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    print(f"book: {index}")
    return 0


def _run(args, extra) -> int:
    """``refsph run``: each method of the scene in turn, its metrics printed, then the scene's report."""
    if args.restart is not None:
        return _restart(args, extra)
    if args.scene not in SCENES:
        print(f"refsph: unknown scene {args.scene!r}; available: {', '.join(sorted(SCENES))}", file=sys.stderr)
        return 2
    scene = SCENES[args.scene]
    try:
        options = _parse_options(args.option)          # checked and converted by run() (Scene.setup)
        options.update(_option_flags(extra, scene))
        numerics = _parse_numerics(args.set)
    except ValueError as e:
        print(f"refsph: {e}", file=sys.stderr)
        return 2
    dim = args.dim if args.dim is not None else scene.default_dim
    from .pfem_run import PFEM_SCENES
    both = tuple(scene.methods) + ("pfem",) if args.scene in PFEM_SCENES else METHODS
    methods = scene.methods if args.method is None else (both if args.method == "both" else (args.method,))
    if "pfem" in methods:
        code = _pfem_refusals(args, dim)
        if code:
            return code
    summaries = []
    if len(methods) > 1:                               # both methods' refusals before either runs
        for method in methods:
            if method == "pfem":
                continue
            _, code = _attempt(lambda: check_run(args.scene, method, dim=dim, dp=args.dp, t_end=args.t_end,
                                                 quick=args.quick, dt=args.dt, options=options, numerics=numerics,
                                                 particles=args.particles))
            if code:
                return code
    for method in methods:
        out = args.out or f"runs/{args.scene}-{method}-{dim}d"
        if args.out and len(methods) > 1:
            out = f"{args.out}/{method}"
        if method == "pfem":
            from .pfem_run import run_pfem
            out = args.out or f"runs/{args.scene}-pfem-2d"
            if args.out and len(methods) > 1:
                out = f"{args.out}/pfem"
            res, code = _attempt(lambda: run_pfem(args.scene, out=out, options=options, quick=args.quick,
                                                  progress=not args.quiet, overwrite=args.overwrite,
                                                  checkpoint_every=args.checkpoint_every))
        else:
            res, code = _attempt(lambda: run(args.scene, method, dim=dim, dp=args.dp, t_end=args.t_end, out=out,
                                             quick=args.quick, dt=args.dt, progress=not args.quiet,
                                             options=options, numerics=numerics, particles=args.particles,
                                             overwrite=args.overwrite, checkpoint_every=args.checkpoint_every))
        if code:
            return code
        s = res.summary
        summaries.append(s)
        print(f"{s['scene']} {s['method']} {s['dim']}D: {s['n_particles']} particles, {s['n_steps']} steps, "
              f"{s['wall_time_s']:.1f} s ({s['particle_steps_per_s']:.3g} particle-steps/s)")
        for k, v in s["metrics"].items():
            if k != "reference":
                print(f"  {k:32s} {_fmt(v)}")
        print(f"output: {out}/summary.json, {out}/snapshots/")
    if scene.report is not None:
        print()
        print(scene.report(summaries))
    return 0


def _pfem_refusals(args, dim) -> int:
    """2 with a message if the PFEM cannot take what was asked (it is 2D, its spacing and end come from the scene
    options, it has no SPH numerics); 0 otherwise."""
    from .pfem_run import PFEM_SCENES
    if args.scene not in PFEM_SCENES:
        print(f"refsph: scene {args.scene!r} has no PFEM version (PFEM scenes: {', '.join(PFEM_SCENES)})",
              file=sys.stderr)
        return 2
    given = [flag for flag, value in (("--dp", args.dp), ("--t-end", args.t_end), ("--dt", args.dt),
                                      ("--set", args.set or None), ("--from", args.particles)) if value is not None]
    if dim != 2 or given:
        what = ", ".join(given + ([f"--dim {dim}"] if dim != 2 else []))
        print(f"refsph: the PFEM cut is 2D and takes its spacing and length from the scene options (n_tu, travel; "
              f"'refsph list'), not {what}", file=sys.stderr)
        return 2
    return 0


def _parse_options(items) -> dict:
    """NAME=VALUE strings -> {name: 'VALUE'}; :meth:`refsph.scenes.Scene.setup` checks and converts them."""
    out = {}
    for item in items:
        if "=" not in item:
            raise ValueError(f"--option needs NAME=VALUE, got {item!r}")
        name, value = item.split("=", 1)
        out[name] = value
    return out


def _option_flags(tokens, scene) -> dict:
    """Scene options given as their own flags: ``--feed 0.3e-3`` or ``--feed=0.3e-3`` (``-`` read as ``_``)."""
    out, k = {}, 0
    while k < len(tokens):
        tok = tokens[k]
        if not tok.startswith("--"):
            raise ValueError(f"unrecognized argument {tok!r}")
        name, eq, value = tok[2:].partition("=")
        name = name.replace("-", "_")
        if name not in scene.options:
            known = ", ".join(f"--{o}" for o in scene.options) or "none"
            raise ValueError(f"unrecognized argument {tok!r} (scene {scene.name!r} options: {known})")
        if not eq:
            if k + 1 >= len(tokens):
                raise ValueError(f"{tok} needs a value")
            k += 1
            value = tokens[k]
        out[name] = value
        k += 1
    return out


def _parse_numerics(items) -> dict:
    """NAME=VALUE strings -> Numerics overrides, each converted like the field's default ('none' for None)."""
    defaults = {f.name: f.default for f in dataclasses.fields(Numerics)}
    out = {}
    for item in items:
        name, eq, value = item.partition("=")
        if not eq:
            raise ValueError(f"--set needs NAME=VALUE, got {item!r}")
        if name not in defaults:
            raise ValueError(f"unknown numerical parameter {name!r} (known: {', '.join(defaults)})")
        d = defaults[name]
        if value.lower() == "none" and numerics_field_optional(name):
            out[name] = None
        elif isinstance(d, bool):
            out[name] = parse_bool(value, f"--set {name}")
        elif isinstance(d, str):
            out[name] = value
        elif isinstance(d, int):
            try:
                out[name] = int(value)
            except ValueError:
                raise ValueError(f"--set {name} must be a whole number, got {value!r}") from None
        else:
            try:
                out[name] = float(value)
            except ValueError:
                raise ValueError(f"--set {name} must be a number, got {value!r}") from None
    return out


if __name__ == "__main__":
    sys.exit(main())
