"""``refsph compare REF TEST``: another code's numbers against refsph's, quantity by quantity, and where they differ.

Two kinds of folders are compared:

* **golden cases** (``refsph oracle DIR``, a folder with ``index.json``): for every case of REF, every array of its
  ``output.npz`` against the same array in TEST/<case>/output.npz, with the case's own tolerance (``case.json``)
  and error measure (``case.json``'s ``measure``, where a case names one for an array: the relative L2 difference,
  or a pointwise relative error with a floor; see :func:`compare_case`), or, for a metric that scatters by nature
  (the cutting forces), the tolerance stored with the case from the measured scatter of perturbed runs
  (``<case>/scatter.json``, :func:`scatter_tolerances`; the table says so beside the row);
* **run folders** (``refsph run ... --out DIR``, a folder with ``summary.json``): the scalar metrics of
  ``summary.json`` and the snapshot fields, particles matched by ``id`` (the row where a snapshot has no ids),
  snapshots matched by time (TEST interpolated linearly in time where its snapshot times differ from REF's).

The error of an array is max |test - ref| / max |ref| (positions: relative to the largest displacement
max |x_ref - X_ref|, so that a 1 um shift of a 1 mm body counts; a PFEM run's nodes have no X: against their
positions in REF's first snapshot); of a scalar |test - ref| / |ref|. For run folders
the scale max |ref| is taken over all of REF's snapshots, so that a field passing through zero (a vibrating bar at
half a period) is not judged against its own near-zero size.

**Where it fails.** Each row (:class:`Row`) says where its error is largest: the particle (golden cases: the row, or
the pair with its particles I and J, as the case's ``arrays[...].rows`` says; runs: the particle id), the component,
the time, and both values. A row is labelled where the number alone would mislead: ``missing`` (TEST has no such
case, array, metric, snapshot time or particle: a case a backend does not implement yet), ``shape mismatch``,
``dtype`` (TEST's dtype is not REF's: a float32 backend keeps ~7 digits, which fails every 1e-10 tolerance, and
the label says why), ``interpolated`` (TEST had no snapshot at REF's time: its values there are interpolated
linearly between its two snapshots around it), ``not finite`` (TEST has nan or inf). What differs between the two
folders as a whole (another scene, method, dimension or particle count; another golden format) is said before the
table (:class:`Rows` ``notes``).

Default tolerances, from what was measured: the same code on any thread count gives the same bits (the pair
blocks add in a fixed order, ``tests/test_driver.py``), and another machine's NumPy changes the last digits, so a
run against a rerun of itself is held to 1e-6 (``DEFAULTS``). Other comparisons need looser ones, given in a JSON
file ``--tolerances FILE``: {"fields": {"S": 1e-3}, "metrics": {"cutting_force_mean_N_per_m": 0.05},
"field": default, "metric": default}; a tolerance null means "not compared" (``"field": null`` compares only the
fields the file names: another code rarely writes every field refsph does). What was measured for such files
(README): a fixed dt against the CFL step moves the Taylor bar by 0.01 mm (3e-4) and the pressing force by
0.01 % (ESPH) and 1 % (TLSPH); a rerun with the sums in another order moves the cutting forces by a few per cent
and the chip thickness by up to 7 %; moving the particles at random by 0.01 dx (benchmarks/metric_scatter.py) moves
the coarse cutting runs' forces by up to 0.6 % after 0.2 mm of cut and up to 13 % after 0.6 mm (TLSPH's thrust;
the chip thickness 1.4 %, the band count by one); refsph against LAMMPS-SMD: benchmarks/lammps/tolerances.json.
"""
from __future__ import annotations

import fnmatch
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..io import read_json, read_npz

__all__ = ["Row", "Rows", "compare", "compare_case", "compare_cases", "compare_runs", "format_table",
           "scatter_tolerances", "DEFAULTS", "FIELDS", "LABELS", "SCATTER_FILE"]

DEFAULTS = dict(field=1e-6, metric=1e-6)
FIELDS = ("x", "v", "rho", "S", "S_zz", "F", "eps_p", "T")
LABELS = ("missing", "shape mismatch", "dtype", "interpolated", "not finite")
SCATTER_FILE = "scatter.json"   # <case>/scatter.json: tolerances from the scatter of perturbed runs (golden/FORMAT.md)
SNAPSHOT_META = ("units",)      # entries of a snapshot that are not numbers (an earlier refsph's units, a JSON text)


@dataclass
class Row:
    """One compared quantity: its ``error`` against its ``tolerance``; ``labels`` (:data:`LABELS`) and ``note``
    where the number alone would mislead; where the error is largest: ``where`` (particle or pair, component),
    ``time`` [s] (runs), ``ref_value`` and ``test_value``; ``tolerance_from``: where the tolerance comes from
    where a stored scatter was consulted (the stored scatter, or case.json's where that is the larger)."""

    quantity: str
    error: float
    tolerance: float
    labels: tuple = ()
    note: str = ""
    where: str = ""
    time: float | None = None
    ref_value: float | None = None
    test_value: float | None = None
    tolerance_from: str = ""

    @property
    def passed(self) -> bool:
        return bool(np.isfinite(self.error) and self.error <= self.tolerance)

    @property
    def label(self) -> str:
        return ", ".join(self.labels)


class Rows(list):
    """The rows of a comparison, with ``notes``: what differs between REF and TEST as a whole (said first)."""

    def __init__(self, rows=(), notes=()):
        super().__init__(rows)
        self.notes = list(notes)


def _rel(test, ref, scale=None) -> float:
    test, ref = np.asarray(test, dtype=float), np.asarray(ref, dtype=float)
    if test.shape != ref.shape:
        return float("inf")
    s = float(np.max(np.abs(ref))) if scale is None else scale
    diff = float(np.max(np.abs(test - ref))) if ref.size else 0.0
    return diff / s if s > 0 else diff


def _pointwise(test: np.ndarray, ref: np.ndarray, measure: dict | None) -> np.ndarray:
    """The per-entry difference whose largest entry is the worst point: |d| or, for a pointwise measure,
    |d| / (|ref| + floor)."""
    d = np.abs(test - ref)
    if measure and measure.get("kind") == "pointwise":
        d = d / (np.abs(ref) + measure["floor"])
    return d


def _format_index(idx: tuple) -> str:
    return "[" + ", ".join(str(int(i)) for i in idx) + "]"


def _locate(test, ref, measure: dict | None = None, rows: str | None = "row", pairs=None, ids=None) -> dict:
    """Where |test - ref| (or the measure's pointwise error) is largest: Row fields ``where``, ``ref_value``,
    ``test_value``. ``rows``: what axis 0 counts (a golden array's ``rows``; 'particle' with ``ids`` for runs);
    ``pairs``: (I, J) to name a pair's particles."""
    test, ref = np.asarray(test, dtype=float), np.asarray(ref, dtype=float)
    if ref.size == 0:
        return {}
    d = _pointwise(test, ref, measure)
    d = np.where(np.isnan(d), np.inf, d)                 # a nan is the worst point there is
    idx = np.unravel_index(int(np.argmax(d)), d.shape)
    out = dict(ref_value=float(ref[idx]), test_value=float(test[idx]))
    if ref.ndim == 0:
        out["where"] = ""
        return out
    k = int(idx[0])
    if ids is not None:
        where = f"particle id {int(ids[k])}" + (f" (row {k})" if int(ids[k]) != k else "")
    elif rows == "pair" and pairs is not None:
        where = f"pair {k} (I {int(pairs[0][k])}, J {int(pairs[1][k])})"
    else:
        where = f"{rows or 'row'} {k}"
    if ref.ndim > 1:
        where += f" component {_format_index(idx[1:])}"
    out["where"] = where
    return out


def _check(test, ref) -> tuple[tuple, str]:
    """Labels and a note that the error alone would not explain: the dtype, non-finite values."""
    labels, notes = [], []
    t, r = np.asarray(test), np.asarray(ref)
    if t.dtype != r.dtype:
        labels.append("dtype")
        notes.append(f"TEST is {t.dtype}, REF {r.dtype}" + (
            f": {t.dtype} keeps {np.finfo(t.dtype).precision} digits (round-off {np.finfo(t.dtype).eps:.1e}), "
            "more than a round-off tolerance allows" if t.dtype.kind == "f" and t.dtype.itemsize < 8 else ""))
    if t.dtype.kind in "fc" and not np.all(np.isfinite(t)):
        labels.append("not finite")
        notes.append(f"TEST has {int(np.count_nonzero(~np.isfinite(t)))} non-finite values")
    return tuple(labels), "; ".join(notes)


def _array_row(quantity: str, test, ref, tol: float, measure: dict | None = None, scale=None,
               missing: str = "TEST has no such array", **where) -> Row:
    """The row of one array: its error, labels and worst point (``where``: :func:`_locate`'s keywords); test None:
    missing (``missing`` says what is)."""
    if test is None:
        return Row(quantity, float("inf"), tol, ("missing",), missing)
    t, r = np.asarray(test), np.asarray(ref)
    if t.shape != r.shape:
        return Row(quantity, float("inf"), tol, ("shape mismatch",), f"TEST has shape {t.shape}, REF {r.shape}")
    labels, note = _check(t, r)
    if t.dtype.kind not in "fiub":
        return Row(quantity, float("inf"), tol, ("dtype",), f"TEST holds {t.dtype}, not numbers")
    err = _error(t, r, measure) if scale is None else _rel(t, r, scale)
    if not np.isfinite(err) and "not finite" not in labels:
        labels += ("not finite",)
    row = Row(quantity, err, tol, labels, note)
    if not row.passed:
        for k, v in _locate(t, r, measure, **where).items():
            setattr(row, k, v)
    return row


def compare_cases(ref: Path, test: Path, tolerances: dict | None = None, only=None) -> Rows:
    """Every output array of every golden case of ``ref`` (``only``: the cases whose names match one of these
    patterns, as in ``kernel_*``) against ``test`` (a missing case or array fails, labelled missing)."""
    fields = (tolerances or {}).get("fields", {})
    index = read_json(ref / "index.json", "golden index")
    names = index["cases"]
    if only:
        chosen = [n for n in names if any(fnmatch.fnmatchcase(n, pat) for pat in only)]
        if not chosen:
            raise ValueError(f"no golden case matches {' '.join(only)} (the cases: {', '.join(names)})")
        names = chosen
    notes = []
    if (test / "index.json").exists():
        other = read_json(test / "index.json", "golden index")
        other = other.get("format_version") if isinstance(other, dict) else None
        if other != index.get("format_version"):
            notes.append(f"REF is golden format version {index.get('format_version')}, TEST says {other}")
    rows, absent = Rows(notes=notes), []
    for name in names:
        path = test / name / "output.npz"
        out_test = None
        if path.exists():
            out_test = read_npz(path, "golden-case output")
        else:
            absent.append(name)
        rows += compare_case(ref / name, out_test, fields)
    if absent:
        rows.notes.append(f"TEST has no output.npz for {len(absent)} of the {len(names)} cases (labelled missing): "
                          + ", ".join(absent))
    return rows


def compare_case(case_dir: Path, out_test: dict | None, fields: dict | None = None) -> list[Row]:
    """The output arrays of one golden case (folder ``case_dir``) against ``out_test`` {name: array} (None: TEST
    has no output for this case), each with the case's tolerance (``fields``: {name: tolerance} overriding it) and
    error measure (a missing array fails; one whose ``fields`` tolerance is None is not compared), and where each
    failing one fails worst (the case's ``rows``: the particle, or the pair and its particles I, J)."""
    case_dir, fields = Path(case_dir), fields or {}
    case = read_json(case_dir / "case.json", "golden case")
    measure = case.get("measure", {})
    out_ref = read_npz(case_dir / "output.npz", "golden-case output")
    scatter, stale = scatter_tolerances(case_dir, out_ref, case["tolerance"])     # {array: (tolerance, from)}
    pairs = None
    rows = []
    for k, a in out_ref.items():
        if k in fields and fields[k] is None:               # a tolerance null: not compared (module text)
            continue
        tol = fields.get(k, scatter[k][0] if k in scatter else case["tolerance"].get(k, DEFAULTS["field"]))
        kind = case.get("arrays", {}).get(f"output/{k}", {}).get("rows", "row")
        if kind == "pair" and pairs is None:
            pairs = _pairs_of(case_dir)
        missing = (f"TEST has no {case_dir.name}/output.npz" if out_test is None
                   else f"TEST's {case_dir.name}/output.npz has no array {k}")
        row = _array_row(f"{case_dir.name}/{k}", None if out_test is None else out_test.get(k), a, tol,
                         measure.get(k), rows=kind, pairs=pairs if kind == "pair" else None, missing=missing)
        if k in scatter and k not in fields:
            row.tolerance_from = scatter[k][1]
        if k in stale:
            row.note = "; ".join(filter(None, [row.note, stale[k]]))
        rows.append(row)
    return rows


def scatter_tolerances(case_dir, out_ref: dict, own: dict) -> tuple[dict, dict]:
    """The tolerances a golden case stores from the measured scatter of its metrics (``<case>/scatter.json``,
    written by benchmarks/metric_scatter.py; golden/FORMAT.md): {array: (tolerance, where it comes from)}, the
    tolerance the larger of the stored one and the case's own (``own``: case.json's), and {array: note} for the
    stored ones that were measured around another value than the case's output holds now (stale: the case's own
    tolerance then). No file: ({}, {})."""
    case_dir = Path(case_dir)
    path = case_dir / SCATTER_FILE
    if not path.is_file():
        return {}, {}
    doc = read_json(path, "stored scatter")
    tolerances, stale = {}, {}
    for k, tol in doc.get("tolerance", {}).items():
        if k not in out_ref or tol is None:
            continue
        around = doc["metrics"][k]["reference"]
        if around != float(out_ref[k]):
            stale[k] = (f"{path} is stale: measured around {around!r}, the case holds {float(out_ref[k])!r}; the "
                        "case's own tolerance is used (run benchmarks/metric_scatter.py again)")
            continue
        where = f"{case_dir.name}/{SCATTER_FILE}"
        mine = float(own.get(k, 0.0))
        tolerances[k] = ((float(tol), f"the stored scatter ({where})") if tol > mine else
                         (mine, f"case.json, larger than the stored scatter's {tol:.1e} ({where})"))
    return tolerances, stale


def _pairs_of(case_dir: Path):
    """The pair list (I, J) of a golden case's input, or None."""
    z = read_npz(case_dir / "input.npz", "golden-case input")
    return (z["I"], z["J"]) if "I" in z and "J" in z else None


def _error(test, ref, measure: dict | None) -> float:
    """The error of a golden case's array: max |test - ref| / max |ref| (no ``measure``), or as its case.json's
    ``measure`` says: {"kind": "l2"}: ||test - ref|| / ||ref||; {"kind": "pointwise", "floor": f}:
    max_i |test_i - ref_i| / (|ref_i| + f), i.e. |d_i| <= tol |ref_i| + tol f at every point."""
    if not measure:
        return _rel(test, ref)
    test, ref = np.asarray(test, dtype=float), np.asarray(ref, dtype=float)
    if test.shape != ref.shape:
        return float("inf")
    if measure["kind"] == "l2":
        return float(np.linalg.norm(test - ref) / np.linalg.norm(ref))
    if measure["kind"] == "pointwise":
        return float(np.max(np.abs(test - ref) / (np.abs(ref) + measure["floor"])))
    raise ValueError(f"unknown error measure {measure!r}")


def _metric_rows(ref: dict, test: dict, tol: dict) -> list[Row]:
    rows = []
    for k, v in ref.items():
        limit = _tolerance(tol, "metric", k)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or limit is None:
            continue
        w = test.get(k)
        if not isinstance(w, (int, float)) or isinstance(w, bool):
            rows.append(Row(f"metric {k}", float("inf"), limit, ("missing",),
                            "TEST's summary.json has no such metric" if w is None else f"TEST's value is {w!r}"))
            continue
        err = abs(w - v) / abs(v) if v != 0 else abs(w)
        rows.append(Row(f"metric {k}", float(err), limit, () if np.isfinite(w) else ("not finite",),
                        ref_value=float(v), test_value=float(w)))
    return rows


def _tolerance(tol: dict, kind: str, name: str):
    """The tolerance of field or metric ``name`` (``kind`` 'field' | 'metric'): the file's own entry, else its
    default; None means "not compared" (a file that sets ``"field": null`` compares only the fields it names)."""
    own = tol.get(kind + "s", {})
    return own[name] if name in own else tol.get(kind, DEFAULTS[kind])


def _at_time(snaps: list, t: float) -> dict | None:
    """The TEST fields at time t: a snapshot at t, or the linear interpolation of the two around it (its
    ``interpolated``: the two times)."""
    times = [z["t"] for z in snaps]
    for z in snaps:
        if abs(z["t"] - t) <= 1e-12 * max(abs(t), 1e-30):
            return z
    k = int(np.searchsorted(times, t))
    if k == 0 or k == len(snaps):
        return None
    a, b = snaps[k - 1], snaps[k]
    w = (t - a["t"]) / (b["t"] - a["t"])
    out = {"t": t, "interpolated": (a["t"], b["t"])}
    if "id" in a:                    # ids are matched, never interpolated (4079.0 may come back as 4078.999...)
        out["id"] = a["id"]
    rows = _rows_of(b, a["id"]) if "id" in a else slice(None)
    for f in FIELDS:
        if f in a and f in b:
            out[f] = (1 - w) * a[f] + w * b[f][rows]
    return out


def _rows_of(z: dict, ids: np.ndarray):
    """The rows of snapshot ``z`` that hold particles ``ids`` (all rows, in order, where z has no ids)."""
    if "id" not in z:
        return slice(None)
    order = np.argsort(z["id"])
    return order[np.searchsorted(z["id"][order], ids)]


def _displacement(z: dict, first: dict) -> np.ndarray:
    """x - X of snapshot ``z``; where it has no reference positions X (a PFEM run's nodes), x against the same
    particle's x in REF's ``first`` snapshot (particles matched by id; those not in it count as not moved)."""
    if "X" in z:
        return z["x"] - z["X"]
    if "id" not in z or "id" not in first:
        return z["x"] - first["x"] if len(z["x"]) == len(first["x"]) else np.zeros_like(z["x"])
    _, here, there = np.intersect1d(z["id"], first["id"], return_indices=True)
    out = np.zeros_like(z["x"])
    out[here] = z["x"][here] - first["x"][there]
    return out


def _absent_ids(z: dict, ids: np.ndarray) -> np.ndarray:
    """The particles ``ids`` that snapshot ``z`` does not hold (none where z has no ids and as many rows)."""
    if "id" not in z:
        return ids[len(z["x"]):] if len(z["x"]) < len(ids) else ids[:0]
    return np.setdiff1d(ids, z["id"])


def _load_snapshot(path: Path) -> dict:
    """A snapshot's numeric arrays (``t`` a float); the ``units`` text of an earlier refsph's snapshot is skipped
    (refsph's units are in ``snapshots/units.json`` now, which no comparison needs)."""
    out = {k: v for k, v in read_npz(path, "snapshot").items() if k not in SNAPSHOT_META}
    if "t" not in out:
        raise ValueError(f"{path}: not a snapshot (no t)")
    out["t"] = float(out["t"])
    return out


def _run_notes(s_ref: dict, s_test: dict) -> list[str]:
    """What differs between two runs as a whole: scene, method, dimension, particle count, spacing."""
    notes = []
    for key in ("scene", "method", "dim", "n_particles", "dp"):
        a, b = s_ref.get(key), s_test.get(key)
        if a is None:
            continue
        if b is None:
            notes.append(f"TEST's summary.json does not say its {key} (REF: {a})")
        elif a != b:
            notes.append(f"different {key}: REF {a}, TEST {b}")
    return notes


def compare_runs(ref: Path, test: Path, tolerances: dict | None = None) -> Rows:
    """Metrics and snapshot fields of run folder ``test`` against ``ref`` (see the module text)."""
    tol = dict(DEFAULTS, **(tolerances or {}))
    s_ref, s_test = (read_json(d / "summary.json", "run summary") for d in (ref, test))
    p_ref = sorted((ref / "snapshots").glob("snap_*.npz"))
    p_test = sorted((test / "snapshots").glob("snap_*.npz"))
    rows = Rows(_metric_rows(s_ref.get("metrics", {}), s_test.get("metrics", {}), tol), _run_notes(s_ref, s_test))
    test_snaps = [_load_snapshot(p) for p in p_test]
    ref_snaps = [_load_snapshot(p) for p in p_ref]
    scale = {f: max(float(np.max(np.abs(_displacement(z, ref_snaps[0]) if f == "x" else z[f]))) for z in ref_snaps)
             for f in FIELDS if all(f in z for z in ref_snaps)}
    for p, z in zip(p_ref, ref_snaps):
        ids = z.get("id", np.arange(len(z["x"])))
        other = _at_time(test_snaps, z["t"])
        absent = _absent_ids(other, ids) if other is not None else ids
        match = _rows_of(other, ids) if other is not None and not len(absent) else None
        for f in FIELDS:
            limit = _tolerance(tol, "field", f)
            if f not in z or limit is None:
                continue
            q = f"{p.stem} (t = {z['t']:.4g} s) {f}"
            if other is None:
                row = Row(q, float("inf"), limit, ("missing",), f"TEST has no snapshot at or around t = {z['t']:.6g} s")
            elif len(absent):
                row = Row(q, float("inf"), limit, ("missing",), f"TEST lacks {len(absent)} of REF's particles "
                          f"(ids {', '.join(str(int(i)) for i in absent[:5])}{' ...' if len(absent) > 5 else ''})")
            elif f not in other:
                row = Row(q, float("inf"), limit, ("missing",), f"TEST's snapshot has no field {f}")
            else:
                row = _array_row(q, np.asarray(other[f])[match], z[f], limit, scale=scale.get(f), ids=ids)
                if "interpolated" in other:
                    row.labels += ("interpolated",)
                    a, b = other["interpolated"]
                    row.note = "; ".join(filter(None, [row.note, f"TEST interpolated between its snapshots at "
                                                                f"t = {a:.6g} s and {b:.6g} s"]))
            row.time = z["t"]
            rows.append(row)
    return rows


def check_tolerances(tol) -> dict:
    """The ``--tolerances`` document, checked (ValueError naming what is wrong): a JSON object with the keys
    'fields' and 'metrics' (objects of name: rtol) and 'field', 'metric' (a default rtol); an rtol is a number >= 0
    or null (not compared)."""
    if tol is None:
        return {}
    if not isinstance(tol, dict):
        raise ValueError(f"tolerances must be a JSON object like {{\"fields\": {{\"S\": 1e-3}}}}, got a "
                         f"{type(tol).__name__}")
    def rtol(where, v):
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float)) or not v >= 0):
            raise ValueError(f"tolerance {where} must be a number >= 0 or null, got {v!r}")
    for key, v in tol.items():
        if key in ("fields", "metrics"):
            if not isinstance(v, dict):
                raise ValueError(f"tolerances {key!r} must be an object of name: rtol, got {v!r}")
            for name, r in v.items():
                rtol(f"{key}.{name}", r)
        elif key in ("field", "metric"):
            rtol(key, v)
        else:
            raise ValueError(f"unknown tolerance key {key!r} (fields, metrics, field, metric)")
    return tol


def compare(ref, test, tolerances: dict | None = None, only=None) -> Rows:
    """Golden-case folders or run folders (decided by REF: index.json or summary.json); ``only``: golden cases by
    name or pattern."""
    ref, test = Path(ref), Path(test)
    tolerances = check_tolerances(tolerances)
    if not test.is_dir():
        raise ValueError(f"{test} is not a folder")
    if (ref / "index.json").exists():
        return compare_cases(ref, test, tolerances, only)
    if only:
        raise ValueError("--only selects golden cases; it has no meaning for run folders")
    if (ref / "summary.json").exists():
        return compare_runs(ref, test, tolerances)
    raise ValueError(f"{ref} is neither a golden-case folder (index.json) nor a run folder (summary.json)")


def _detail(r: Row, said: str) -> list[str]:
    """The lines under a failing row: where it fails worst, with both values; its note (unless it is ``said``, the
    note of the failing row above: a case TEST lacks is said once, not once per array)."""
    lines = []
    if r.ref_value is not None:
        at = ", ".join(filter(None, [r.where, f"t = {r.time:.6g} s" if r.time is not None else ""]))
        lines.append(f"    worst{' at ' + at if at else ''}: REF {r.ref_value:.10g}, TEST {r.test_value:.10g}")
    if r.note and r.note != said:
        lines.append(f"    {r.note}")
    return lines


def format_table(rows: list[Row]) -> str:
    """The comparison as text: the notes on REF and TEST as a whole, one line per quantity (error, tolerance, pass,
    labels), and under each failing one where it fails worst and why."""
    width = max([len(r.quantity) for r in rows] + [8])
    lines = [f"NOTE: {n}" for n in getattr(rows, "notes", [])]
    lines.append(f"{'quantity':{width}s}  {'max error':>10s}  {'tolerance':>9s}  pass")
    said = ""
    for r in rows:
        lines.append(f"{r.quantity:{width}s}  {r.error:10.3e}  {r.tolerance:9.1e}  {'yes' if r.passed else 'NO'}"
                     + (f"   {r.label}" if r.labels else "")
                     + (f"   tolerance from {r.tolerance_from}" if r.tolerance_from else ""))
        if not r.passed:
            lines += _detail(r, said)
            said = r.note
    failed = [r for r in rows if not r.passed]
    counts = {lab: sum(lab in r.labels for r in failed) for lab in LABELS}
    why = ", ".join(f"{n} {lab}" for lab, n in counts.items() if n)
    lines.append(f"compare: {len(rows) - len(failed)} of {len(rows)} within tolerance"
                 + (f", {len(failed)} NOT" + (f" ({why})" if why else "") if failed else ""))
    return "\n".join(lines)
