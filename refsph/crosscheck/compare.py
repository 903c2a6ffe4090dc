"""``refsph compare REF TEST``: another code's numbers against refsph's, quantity by quantity.

Two kinds of folders are compared:

* **golden cases** (``refsph oracle DIR``, a folder with ``index.json``): for every case of REF, every array of its
  ``output.npz`` against the same array in TEST/<case>/output.npz, with the case's own tolerance (``case.json``)
  and error measure (``case.json``'s ``measure``, where a case names one for an array: the relative L2 difference,
  or a pointwise relative error with a floor; see :func:`compare_case`);
* **run folders** (``refsph run ... --out DIR``, a folder with ``summary.json``): the scalar metrics of
  ``summary.json`` and the snapshot fields, particles matched by ``id`` (the row where a snapshot has no ids),
  snapshots matched by time (TEST interpolated linearly in time where its snapshot times differ from REF's).

The error of an array is max |test - ref| / max |ref| (positions: relative to the largest displacement
max |x_ref - X_ref|, so that a 1 um shift of a 1 mm body counts); of a scalar |test - ref| / |ref|. For run folders
the scale max |ref| is taken over all of REF's snapshots, so that a field passing through zero (a vibrating bar at
half a period) is not judged against its own near-zero size.

Default tolerances, from what was measured: the same code on any thread count gives the same bits (the pair
blocks add in a fixed order, ``tests/test_driver.py``), and another machine's NumPy changes the last digits, so a
run against a rerun of itself is held to 1e-6 (``DEFAULTS``). Other comparisons need looser ones, given in a JSON
file ``--tolerances FILE``: {"fields": {"S": 1e-3}, "metrics": {"cutting_force_mean_N_per_m": 0.05},
"field": default, "metric": default}; a tolerance null means "not compared" (``"field": null`` compares only the
fields the file names: another code rarely writes every field refsph does). What was measured for such files
(README): a fixed dt against the CFL step moves the Taylor bar by 0.01 mm (3e-4) and the pressing force by
0.01 % (ESPH) and 1 % (TLSPH); a rerun with the sums in another order moves the cutting forces by a few per cent
and the chip thickness by up to 7 %; refsph against LAMMPS-SMD: benchmarks/lammps/tolerances.json.
"""
from __future__ import annotations

import fnmatch
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..io import load_run, load_snapshot

__all__ = ["Row", "compare", "compare_case", "compare_cases", "compare_runs", "format_table", "DEFAULTS", "FIELDS"]

DEFAULTS = dict(field=1e-6, metric=1e-6)
FIELDS = ("x", "v", "rho", "S", "S_zz", "F", "eps_p", "T")


@dataclass
class Row:
    quantity: str
    error: float
    tolerance: float

    @property
    def passed(self) -> bool:
        return bool(np.isfinite(self.error) and self.error <= self.tolerance)


def _rel(test, ref, scale=None) -> float:
    test, ref = np.asarray(test, dtype=float), np.asarray(ref, dtype=float)
    if test.shape != ref.shape:
        return float("inf")
    s = float(np.max(np.abs(ref))) if scale is None else scale
    diff = float(np.max(np.abs(test - ref))) if ref.size else 0.0
    return diff / s if s > 0 else diff


def compare_cases(ref: Path, test: Path, tolerances: dict | None = None, only=None) -> list[Row]:
    """Every output array of every golden case of ``ref`` (``only``: the cases whose names match one of these
    patterns, as in ``kernel_*``) against ``test`` (a missing case or array fails)."""
    fields = (tolerances or {}).get("fields", {})
    rows = []
    names = json.loads((ref / "index.json").read_text())["cases"]
    if only:
        chosen = [n for n in names if any(fnmatch.fnmatchcase(n, pat) for pat in only)]
        if not chosen:
            raise ValueError(f"no golden case matches {' '.join(only)} (the cases: {', '.join(names)})")
        names = chosen
    for name in names:
        path = test / name / "output.npz"
        out_test = {}
        if path.exists():
            with np.load(path) as t:
                out_test = {k: t[k] for k in t.files}
        rows += compare_case(ref / name, out_test, fields)
    return rows


def compare_case(case_dir: Path, out_test: dict, fields: dict | None = None) -> list[Row]:
    """The output arrays of one golden case (folder ``case_dir``) against ``out_test`` {name: array}, each with the
    case's tolerance (``fields``: {name: tolerance} overriding it) and error measure (a missing array fails)."""
    case_dir = Path(case_dir)
    case = json.loads((case_dir / "case.json").read_text())
    measure = case.get("measure", {})
    with np.load(case_dir / "output.npz") as r:
        out_ref = {k: r[k] for k in r.files}
    rows = []
    for k, a in out_ref.items():
        tol = (fields or {}).get(k, case["tolerance"].get(k, DEFAULTS["field"]))
        err = _error(out_test[k], a, measure.get(k)) if k in out_test else float("inf")
        rows.append(Row(f"{case_dir.name}/{k}", err, tol))
    return rows


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
        err = (abs(w - v) / abs(v) if v != 0 else abs(w)) if isinstance(w, (int, float)) else float("inf")
        rows.append(Row(f"metric {k}", float(err), limit))
    return rows


def _tolerance(tol: dict, kind: str, name: str):
    """The tolerance of field or metric ``name`` (``kind`` 'field' | 'metric'): the file's own entry, else its
    default; None means "not compared" (a file that sets ``"field": null`` compares only the fields it names)."""
    own = tol.get(kind + "s", {})
    return own[name] if name in own else tol.get(kind, DEFAULTS[kind])


def _at_time(snaps: list, t: float) -> dict | None:
    """The TEST fields at time t: a snapshot at t, or the linear interpolation of the two around it."""
    times = [z["t"] for z in snaps]
    for z in snaps:
        if abs(z["t"] - t) <= 1e-12 * max(abs(t), 1e-30):
            return z
    k = int(np.searchsorted(times, t))
    if k == 0 or k == len(snaps):
        return None
    a, b = snaps[k - 1], snaps[k]
    w = (t - a["t"]) / (b["t"] - a["t"])
    out = {"t": t}
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


def compare_runs(ref: Path, test: Path, tolerances: dict | None = None) -> list[Row]:
    """Metrics and snapshot fields of run folder ``test`` against ``ref`` (see the module text)."""
    tol = dict(DEFAULTS, **(tolerances or {}))
    s_ref, p_ref = load_run(ref)
    s_test, p_test = load_run(test)
    rows = _metric_rows(s_ref.get("metrics", {}), s_test.get("metrics", {}), tol)
    test_snaps = [load_snapshot(p) for p in p_test]
    ref_snaps = [load_snapshot(p) for p in p_ref]
    scale = {f: max(float(np.max(np.abs(z["x"] - z["X"] if f == "x" else z[f]))) for z in ref_snaps)
             for f in FIELDS if all(f in z for z in ref_snaps)}
    for p, z in zip(p_ref, ref_snaps):
        other = _at_time(test_snaps, z["t"])
        match = _rows_of(other, z.get("id", np.arange(len(z["x"])))) if other is not None else None
        for f in FIELDS:
            limit = _tolerance(tol, "field", f)
            if f not in z or limit is None:
                continue
            err = (_rel(other[f][match], z[f], scale.get(f)) if other is not None and f in other
                   else float("inf"))
            rows.append(Row(f"{p.stem} (t = {z['t']:.4g} s) {f}", err, limit))
    return rows


def compare(ref, test, tolerances: dict | None = None, only=None) -> list[Row]:
    """Golden-case folders or run folders (decided by REF: index.json or summary.json); ``only``: golden cases by
    name or pattern."""
    ref, test = Path(ref), Path(test)
    if (ref / "index.json").exists():
        return compare_cases(ref, test, tolerances, only)
    if only:
        raise ValueError("--only selects golden cases; it has no meaning for run folders")
    if (ref / "summary.json").exists():
        return compare_runs(ref, test, tolerances)
    raise ValueError(f"{ref} is neither a golden-case folder (index.json) nor a run folder (summary.json)")


def format_table(rows: list[Row]) -> str:
    width = max([len(r.quantity) for r in rows] + [8])
    lines = [f"{'quantity':{width}s}  {'max error':>10s}  {'tolerance':>9s}  pass"]
    for r in rows:
        lines.append(f"{r.quantity:{width}s}  {r.error:10.3e}  {r.tolerance:9.1e}  {'yes' if r.passed else 'NO'}")
    failed = sum(not r.passed for r in rows)
    lines.append(f"compare: {len(rows) - failed} of {len(rows)} within tolerance" + (f", {failed} NOT" if failed
                                                                                     else ""))
    return "\n".join(lines)
