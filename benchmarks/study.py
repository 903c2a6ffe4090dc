"""The scaffold every study in benchmarks/ stands on: one way to pin threads, store runs, run them, time them, write
tables and pages, and parse the common flags.

    import study                    # benchmarks/study.py (a script puts its own folder on sys.path first)
    study.pin_threads()             # before NumPy is imported: BLAS / OpenMP pools at one thread
    import numpy as np

* ``pin_threads()``: the BLAS / OpenMP / NumExpr thread pools at one thread, through the environment (read when
  NumPy is imported, and inherited by every worker process) and, where NumPy is already imported and threadpoolctl
  is installed, through threadpoolctl. refsph's own pair-sum threads are ``Numerics.threads``: ``threads_per_job``.
* ``RunStore``: a keyed, locked, atomic, resumable store of run records in one JSON file
  (``{section: {key: record}}`` plus whatever else the study keeps there). Every write merges under an exclusive
  ``fcntl`` lock (``<file>.lock``, ignored by git) and replaces the file atomically (a ``.tmp`` then
  ``os.replace``), so two sweeps may share a file and a killed sweep leaves it whole. A finished key is skipped by
  the next sweep; a failed run is recorded as failed but never replaces a good record of the same key (it goes to
  the ``failed`` section then).
* ``execute()``: runs ``fn(*args)`` for each key, each in a fresh process (``max_tasks_per_child=1``, spawned: no
  heap or caches from an earlier run, so a wall time is a cold start's), ``jobs`` at a time, or on a
  dask.distributed cluster (``--scheduler ADDRESS``; dask is imported only then), and yields ``(key, result)`` as
  runs finish. A run that raises yields a failed record instead of stopping the sweep.
* ``merge_records()``, ``merge_derived()``, ``write_if_changed()``, ``write_json()``, ``save_figure()``: what a rerun
  writes. A partial rerun (``--only``, a fresh clone without the git-ignored run folders) merges its records into
  the committed ones, a failed run never replaces a good record, and a file (JSON, page, figure) whose content did
  not change is not written: a rerun that reproduced the committed results leaves ``git status`` clean.
* ``observed_order()``, ``richardson()``: the order p of f = f0 + C h^p seen through three resolutions (any
  ratios), and f0 extrapolated from the two finest.
* ``md_table()``, ``fmt()``: markdown tables and cells.
* ``Page``: the prose of a report page, in ``benchmarks/templates/<name>.md``, sections marked ``@@ name``,
  filled with ``string.Template`` (``$name``; a literal dollar is ``$$``).
* ``parser()``: the argparse skeleton with the flags the studies share (``--jobs``, ``--only``, ``--quick``,
  ``--scheduler``, ``--report``, ``--json-figures``, ``--plot-only``, ``--json``).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import string
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
TEMPLATES = HERE / "templates"
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS",
               "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS")


# ----------------------------------------------------------------------------- threads
def pin_threads(n: int = 1) -> None:
    """BLAS / OpenMP / NumExpr pools at ``n`` threads: environment variables (call this before NumPy is imported;
    worker processes inherit them) and, if NumPy is already loaded and threadpoolctl is installed, threadpoolctl."""
    for var in THREAD_VARS:
        os.environ[var] = str(n)
    if "numpy" in sys.modules:
        try:
            from threadpoolctl import threadpool_limits
        except ImportError:
            return
        threadpool_limits(n)


def threads_per_job(jobs: int) -> int:
    """refsph's pair-sum threads for a run when ``jobs`` run at a time (all cores for one job, one each for more)."""
    from refsph.neighbours import threads_per_job as per_job
    return per_job(jobs)


# ----------------------------------------------------------------------------- the run store
def _is_good(rec: dict) -> bool:
    return rec.get("status") == "ok"


class RunStore:
    """Records by key in ``path`` (module text). ``good(record)`` says whether a record is a good one (default:
    status "ok"); ``dump`` turns the document into the file's text."""

    def __init__(self, path: Path, section: str = "runs", good=_is_good, dump=None):
        self.path, self.section, self.good = Path(path), section, good
        self.dump = dump or (lambda doc: json.dumps(doc, indent=1, sort_keys=True, default=float) + "\n")

    def load(self) -> dict:
        """The whole document (``{section: {}}`` if there is no file yet)."""
        doc = json.loads(self.path.read_text()) if self.path.exists() else {}
        doc.setdefault(self.section, {})
        return doc

    def records(self) -> dict:
        return self.load()[self.section]

    def pending(self, keys, redo=(), retry_failed: bool = False) -> list:
        """The keys still to run: not recorded (or recorded failed, with ``retry_failed``), and those in ``redo``."""
        have = self.records()
        return [k for k in keys if k in redo or k not in have or (retry_failed and not self.good(have[k]))]

    def update(self, change) -> dict:
        """Under the lock: load, ``change(doc)`` in place, write atomically; the document written."""
        import fcntl
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with open(self.path.with_suffix(".lock"), "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            doc = self.load()
            change(doc)
            tmp = self.path.with_suffix(".tmp")
            tmp.write_text(self.dump(doc))
            os.replace(tmp, self.path)
        return doc

    def commit(self, key: str, rec: dict) -> bool:
        """Store ``rec`` under ``key``; a failed record does not replace a good one (it is kept under ``failed``).
        True if it went into the section."""
        kept = []

        def change(doc):
            old = doc[self.section].get(key)
            if old is not None and self.good(old) and not self.good(rec):
                doc.setdefault("failed", {})[key] = rec
                return
            doc[self.section][key] = rec
            kept.append(key)
        self.update(change)
        return bool(kept)

    def merge(self, other: Path) -> dict:
        """Take the records of another store's file (a sweep run in another worktree or on another machine): a key
        not here is added, a good record there replaces a failed one here; a key good here, or failed in both, stays
        as it is. {'added': keys, 'replaced': keys, 'kept': keys that differ there and stayed}. ValueError naming
        ``other`` where it is missing or not a store's JSON (nothing here is changed then)."""
        try:
            theirs = json.loads(Path(other).read_text())[self.section]
            if not isinstance(theirs, dict):
                raise TypeError(f"its '{self.section}' is not an object")
        except (OSError, ValueError, KeyError, TypeError) as e:
            raise ValueError(f"{other}: not a sweep's records to merge ({type(e).__name__}: {e})") from None
        out = {"added": [], "replaced": [], "kept": []}

        def change(doc):
            mine = doc[self.section]
            for key, rec in theirs.items():
                if key not in mine:
                    mine[key] = rec
                    out["added"].append(key)
                elif rec != mine[key] and self.good(rec) and not self.good(mine[key]):
                    doc.setdefault("failed", {})[key] = mine[key]
                    mine[key] = rec
                    out["replaced"].append(key)
                elif rec != mine[key]:
                    out["kept"].append(key)
        self.update(change)
        return out

    def set(self, **fields) -> dict:
        """Store top-level fields of the document beside the records (e.g. a machine description)."""
        return self.update(lambda doc: doc.update(fields))


# ----------------------------------------------------------------------------- running
def merge_records(committed: list, fresh: list, key="name") -> list:
    """A list-of-records JSON after a partial rerun: the committed records in their order, each replaced by the
    fresh one of the same ``key`` (a field name, or a function of the record; a fresh failed one never replaces a
    good one), fresh ones not committed before appended. A run folder missing here (a fresh clone) therefore never
    drops its committed record."""
    of = key if callable(key) else (lambda r: r[key])
    new = {of(r): r for r in fresh}
    out = []
    for r in committed:
        f = new.pop(of(r), None)
        out.append(r if f is None or (_is_good(r) and not _is_good(f)) else f)
    return out + list(new.values())


def merge_derived(committed: list, fresh: list, derive, key: str = "name") -> tuple[list, set]:
    """``merge_records``, then the fields ``derive(records)`` computes across the records (in place, one record for
    one; e.g. differences to a reference run: dict fields with a ``"ref"`` key naming the record compared with). A
    record takes its derived fields anew only if it is one of the fresh records that went in or refers (before or
    after) to one; every other committed record stays as it was, byte for byte. Returns (records, the keys of the
    fresh records that went in)."""
    import copy
    merged = merge_records(committed, fresh, key)
    fresh_ids = {id(r) for r in fresh}
    went_in = {r[key] for r in merged if id(r) in fresh_ids}
    derived = derive(copy.deepcopy(merged))

    def refs(r):
        return {v["ref"] for v in r.values() if isinstance(v, dict) and "ref" in v}
    return [d if r[key] in went_in or (refs(r) | refs(d)) & went_in else r
            for r, d in zip(merged, derived, strict=True)], went_in


def run_status(folder: Path) -> str | None:
    """The ``status`` in a run folder's summary.json ("ok", "nan", "error", "running" for a run still going or
    killed, ...); None if the folder holds no summary (a fresh clone: ``runs/`` is not in git)."""
    summary = Path(folder) / "summary.json"
    if not summary.exists():
        return None
    try:
        return json.loads(summary.read_text()).get("status")
    except ValueError:
        return "unreadable"


def write_if_changed(path: Path, text: str) -> bool:
    """Write ``text`` to ``path`` unless it already holds exactly that (a rerun that changed nothing leaves the file,
    and git status, as they were); True if it wrote."""
    path = Path(path)
    if path.exists() and path.read_text() == text:
        return False
    path.write_text(text)
    return True


def _without(o, ignore):
    if isinstance(o, dict):
        return {k: _without(v, ignore) for k, v in o.items() if k not in ignore}
    if isinstance(o, list):
        return [_without(v, ignore) for v in o]
    return o


def write_json(path: Path, doc, ignore=(), indent: int = 1) -> bool:
    """Write ``doc`` as JSON to ``path`` unless the file holds the same document, the fields named in ``ignore`` (at
    any depth) aside: e.g. wall times, which vary from run to run while the numbers do not, so a rerun that reproduced
    the committed numbers leaves the file, and git status, as they were. True if it wrote."""
    path, text = Path(path), json.dumps(doc, indent=indent) + "\n"
    if path.exists():
        try:
            old = json.loads(path.read_text())
        except ValueError:
            old = None
        if _without(old, set(ignore)) == _without(json.loads(text), set(ignore)):
            return False
    path.write_text(text)
    return True


def save_figure(fig, path: Path, **savefig_kw) -> bool:
    """Save ``fig`` (then closed) as the PNG ``path`` unless that file already shows the same picture, pixel for pixel
    (whatever its metadata or compression): a figure redrawn from unchanged data leaves the file, and git status, as
    they were. True if it wrote."""
    import io

    import matplotlib.image
    import matplotlib.pyplot as plt
    import numpy as np
    buf = io.BytesIO()
    fig.savefig(buf, format="png", **savefig_kw)
    plt.close(fig)
    path, data = Path(path), buf.getvalue()
    if path.exists():
        old = path.read_bytes()
        if old == data:
            return False
        try:
            a, b = (matplotlib.image.imread(io.BytesIO(x), format="png") for x in (old, data))
            if a.shape == b.shape and np.array_equal(a, b):
                return False
        except (OSError, ValueError, SyntaxError):            # not a PNG we can read: write the new one
            pass
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data)
    return True


def failed_record(key, error: BaseException) -> dict:
    return dict(key=key, status=f"failed: {type(error).__name__}: {error}"[:600])


def execute(fn, tasks: dict, jobs: int = 1, scheduler: str | None = None, fresh: bool = True):
    """Yield ``(key, fn(*tasks[key]))`` as the runs finish (``tasks``: key -> argument tuple). Local processes,
    ``jobs`` at a time, each run in a fresh (spawned) process if ``fresh``; or a dask.distributed cluster at
    ``scheduler``. A run that raises yields ``failed_record(key, error)``; a run whose process was killed (and with
    it the pool) yields nothing, nor do the runs still waiting: they stay to run, nothing is recorded for them."""
    if not tasks:
        return
    if scheduler:
        yield from _execute_dask(fn, tasks, scheduler)
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed
    from concurrent.futures.process import BrokenProcessPool
    options = dict(max_tasks_per_child=1) if fresh else {}
    broken = []
    with ProcessPoolExecutor(max_workers=max(1, jobs), **options) as pool:
        futures = {pool.submit(fn, *args): key for key, args in tasks.items()}
        for f in as_completed(futures):
            try:
                f.result()
            except BrokenProcessPool:                       # a run's process was killed: the pool is gone, and
                broken.append(futures[f])                   # every run still waiting with it; none is a result
                continue
            except Exception:                                # noqa: BLE001 (recorded by _result below)
                pass
            yield futures[f], _result(f, futures[f])
    if broken:
        print(f"the process pool broke (a run's process was killed): {len(broken)} run(s) not recorded, still to "
              f"run ({', '.join(map(str, broken[:5]))}{' ...' if len(broken) > 5 else ''}); a killed run continues "
              "from its checkpoint next time", flush=True)


def _result(future, key):
    try:
        return future.result()
    except Exception as e:                                   # recorded, so that the other runs go on
        return failed_record(key, e)


def _execute_dask(fn, tasks: dict, scheduler: str):
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        raise SystemExit("--scheduler needs dask.distributed: pip install -e '.[dask]'") from None
    with Client(scheduler) as client:
        futures = {client.submit(fn, *args, key=f"refsph-{key}", pure=False): key for key, args in tasks.items()}
        for f in as_completed(futures):
            yield futures[f], _result(f, futures[f])


def run_all(fn, tasks: dict, jobs: int = 1, fresh: bool = True) -> list:
    """Every run's result, in the order of ``tasks`` (fresh processes, ``jobs`` at a time)."""
    done = dict(execute(fn, tasks, jobs, fresh=fresh))
    return [done[k] for k in tasks]


def timed_in_subprocess(fn, *args):
    """``fn(*args)`` in a fresh process of its own (for one timing that no earlier work in this process may
    pollute); its result."""
    return run_all(fn, {"run": args}, jobs=1)[0]


# ----------------------------------------------------------------------------- parked checkpoints
CHECKPOINT = "restart.npz"          # a run folder's last checkpoint, in snapshots/ (refsph.simulate, refsph.pfem_run)


def _same_arrays(path: Path, arrays: dict) -> bool:
    import numpy as np
    with np.load(path, allow_pickle=False) as z:
        return z.files == list(arrays) and all(np.array_equal(z[k], v) for k, v in arrays.items())


def checkpoint_time(arrays: dict) -> float:
    """How far a checkpoint's run has got: a PFEM checkpoint's nodes' time, an SPH one's time (its run record's t,
    else its step count, in a checkpoint from before the record kept t); -inf where it says neither."""
    if "nodes/t" in arrays:
        return float(arrays["nodes/t"])
    run = json.loads(str(arrays["run"])) if "run" in arrays else {}
    t = run.get("t", run.get("n_steps"))
    return float(t) if isinstance(t, (int, float)) else -math.inf


def _job(job) -> str | None:
    """A job's (options, numerics) as the JSON text park keeps, so that a parked checkpoint is continued only by the
    job that made it."""
    return None if job is None else json.dumps(job, sort_keys=True, default=str)


def park(folder: Path, parked: Path, job=None) -> bool:
    """Keep a killed run's last checkpoint where git keeps it, in the folder ``parked``: ``folder``'s
    ``snapshots/restart.npz`` (its arrays written again compressed, and read back before they replace an older
    one), the state file it names where it is an SPH run's (the snapshot or timed state it continues from; a PFEM
    checkpoint holds its whole state), ``summary.json`` (the commits its earlier parts ran, how far it got) and,
    given, ``job`` (the run's options and numerics, ``job.json``: :func:`unpark` then gives it only to the same
    job). ``runs/`` is not in git, and a new checkout starts without it: a run longer than a working session
    continues in the next one from here. False where ``folder`` has no checkpoint, or ``parked`` holds this one
    already or one as far on (another checkout's, that got further: never replaced by an older one)."""
    import numpy as np
    snaps, parked = Path(folder) / "snapshots", Path(parked)
    if not (snaps / CHECKPOINT).exists():
        return False
    with np.load(snaps / CHECKPOINT, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    if (parked / CHECKPOINT).exists():
        with np.load(parked / CHECKPOINT, allow_pickle=False) as z:
            if checkpoint_time({k: z[k] for k in z.files if k in ("nodes/t", "run")}) >= checkpoint_time(arrays):
                if job is not None and not (parked / "job.json").exists():      # parked before jobs were kept
                    (parked / "job.json").write_text(_job(job))
                return False
    state = None
    if "run" in arrays and "nodes/t" not in arrays:                 # an SPH checkpoint: the state file it names
        state = json.loads(str(arrays["run"])).get("snapshot")
    parked.mkdir(parents=True, exist_ok=True)
    tmp = parked / "restart.tmp.npz"
    try:
        np.savez_compressed(tmp, **arrays)
        if not _same_arrays(tmp, arrays):                           # read back: a parked checkpoint must restart
            raise OSError(f"{tmp}: the compressed checkpoint does not read back as written")
        if state:                                                   # its state, then the checkpoint that names it
            shutil.copyfile(snaps / state, parked / (state + ".tmp"))
            os.replace(parked / (state + ".tmp"), parked / state)
        for name, text in (("summary.json", (Path(folder) / "summary.json").read_text()
                            if (Path(folder) / "summary.json").exists() else None), ("job.json", _job(job))):
            if text is not None:
                (parked / (name + ".tmp")).write_text(text)
                os.replace(parked / (name + ".tmp"), parked / name)
        os.replace(tmp, parked / CHECKPOINT)
    finally:
        tmp.unlink(missing_ok=True)
    for old in parked.glob("*.npz"):                                # the state of the checkpoint replaced
        if old.name not in (CHECKPOINT, state):
            old.unlink()
    return True


def parked_job_differs(parked: Path, job) -> bool:
    """Whether the checkpoint parked in ``parked`` was made by another job than ``job`` (its job.json; False where
    it kept none)."""
    path = Path(parked) / "job.json"
    return path.exists() and path.read_text() != _job(job)


def unpark(parked: Path, folder: Path, job=None) -> bool:
    """Put a parked checkpoint (:func:`park`) back into the run folder ``folder``, so that the run continues from
    it (``refsph run --restart``); only where ``folder`` has no checkpoint of its own (a fresh checkout), and,
    with ``job``, only where the checkpoint was parked by the same job (:func:`parked_job_differs`). True if it
    did."""
    parked, snaps = Path(parked), Path(folder) / "snapshots"
    if (snaps / CHECKPOINT).exists() or not (parked / CHECKPOINT).exists():
        return False
    if job is not None and parked_job_differs(parked, job):
        return False
    snaps.mkdir(parents=True, exist_ok=True)
    states = [f for f in parked.glob("*.npz") if f.name != CHECKPOINT and not f.name.endswith(".tmp.npz")]
    for f in states + [parked / CHECKPOINT]:                        # the checkpoint last
        shutil.copyfile(f, snaps / f.name)
    if (parked / "summary.json").exists() and not (Path(folder) / "summary.json").exists():
        shutil.copyfile(parked / "summary.json", Path(folder) / "summary.json")
    return True


def prune_parked(parked_root: Path, keep) -> list[str]:
    """Remove the parked checkpoints under ``parked_root`` whose folder name ``keep(name)`` rejects (their run is
    recorded, or no longer a job); the names removed."""
    gone = []
    root = Path(parked_root)
    for d in sorted(p for p in root.glob("*") if p.is_dir()) if root.exists() else ():
        if not keep(d.name):
            shutil.rmtree(d)
            gone.append(d.name)
    return gone


# ----------------------------------------------------------------------------- convergence
def observed_order(h, f):
    """The order p of f(h) = f0 + C h^p through three values at h1 > h2 > h3 (any ratios): the root of
    (h1^p - h2^p) / (h2^p - h3^p) = (f1 - f2) / (f2 - f3); None where the differences change sign or grow (no
    convergence to be seen), inf beyond p = 20."""
    (h1, h2, h3), (f1, f2, f3) = h, f
    if (f1 - f2) * (f2 - f3) <= 0:
        return None
    ratio = (f1 - f2) / (f2 - f3)
    g = lambda p: (h1**p - h2**p) / (h2**p - h3**p)  # noqa: E731   (grows with p from its limit at p -> 0)
    lo, hi = 1e-9, 20.0
    if ratio <= g(lo):
        return None
    if ratio >= g(hi):
        return float("inf")
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(mid) < ratio else (lo, mid)
    return 0.5 * (lo + hi)


def richardson(h, f, p: float) -> float:
    """The value at h -> 0 of f(h) = f0 + C h^p through the two finest of ``h`` (largest first), ``f``:
    f0 = f3 + (f3 - f2) / ((h2 / h3)^p - 1)."""
    (h2, h3), (f2, f3) = h[-2:], f[-2:]
    return f3 + (f3 - f2) / ((h2 / h3) ** p - 1.0)


# ----------------------------------------------------------------------------- markdown
def fmt(v, spec: str, scale: float = 1.0, missing: str = "-") -> str:
    """A table cell: ``missing`` for None, a non-finite float, or something that is not a number."""
    if v is None or isinstance(v, (str, dict, list)) or (isinstance(v, float) and not math.isfinite(v)):
        return missing
    return format(v * scale if scale != 1.0 else v, spec)


def md_table(head, rows, align: bool = False) -> str:
    """A markdown table; ``align``: the first column left, the others right (no '|' may be inside a cell then)."""
    if align:
        assert not any("|" in c for row in [head] + list(rows) for c in row), "a '|' inside a table cell"
        rule = "|" + "|".join("---:" if k else ":---" for k in range(len(head))) + "|"
    else:
        rule = "|" + "|".join("---" for _ in head) + "|"
    return "\n".join(["| " + " | ".join(head) + " |", rule] + ["| " + " | ".join(str(c) for c in row) + " |"
                                                               for row in rows])


class Page:
    """The prose of a report page: ``templates/<name>.md``, sections opened by a line ``@@ section``; a section is
    the text up to the next marker without its leading and trailing blank lines, filled with ``string.Template``
    (``$name`` or ``${name}``; ``$$`` is a dollar sign)."""

    def __init__(self, name: str):
        self.name, self.sections, current = name, {}, None
        for line in (TEMPLATES / f"{name}.md").read_text(encoding="utf-8").split("\n"):
            if line.startswith("@@ "):
                current = line[3:].strip()
                self.sections[current] = []
            elif current is not None:
                self.sections[current].append(line)
        self.sections = {k: "\n".join(v).strip("\n") for k, v in self.sections.items()}

    def __call__(self, section: str, **values) -> str:
        return string.Template(self.sections[section]).substitute(values)

    def lines(self, section: str, **values) -> list[str]:
        """The filled section as a list of lines."""
        return self(section, **values).split("\n")


# ----------------------------------------------------------------------------- the command line
FLAGS = {
    "jobs": (("--jobs",), dict(type=int, default=1, help="runs at a time, each in a fresh process (default 1)")),
    "only": (("--only",), dict(default=None, help="run only the jobs whose name contains this string")),
    "quick": (("--quick",), dict(action="store_true", help="quick runs (a try-out)")),
    "scheduler": (("--scheduler",), dict(default=None, metavar="ADDRESS",
                                         help="address of a dask.distributed scheduler (tcp://host:port)")),
    "report": (("--report",), dict(action="store_true", help="no runs: the page from the committed JSON only")),
    "json_figures": (("--json-figures",), dict(action="store_true",
                                               help="only redraw the figures made from the committed JSON alone")),
    "plot_only": (("--plot-only",), dict(action="store_true",
                                         help="no runs: JSON, figures and table from earlier runs")),
}


def parser(doc: str, *flags: str, **overrides) -> argparse.ArgumentParser:
    """The study's argparse parser: the module text as help, the common ``flags`` (keys of FLAGS, in that
    order), each with ``overrides[flag]`` (a dict of argparse keywords) applied."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    return add_flags(ap, *flags, **overrides)


def add_flags(ap: argparse.ArgumentParser, *flags: str, **overrides) -> argparse.ArgumentParser:
    """Add the common ``flags`` to ``ap`` (after a study's own, to keep an order of flags the help shows)."""
    for flag in flags:
        names, kw = FLAGS[flag]
        ap.add_argument(*names, **dict(kw, **overrides.get(flag, {})))
    return ap
