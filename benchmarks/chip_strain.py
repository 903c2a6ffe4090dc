"""How much plastic strain the chip carries against what its thickness implies (issues 22 and 24): for each run folder
of benchmarks/thermal_cutting.py's t_u/10 cuts (SPH and PFEM) and of its 'refupdate' study (:func:`wanted`), from its
last snapshot, the mean effective plastic strain of the chip's body against the strain of Merchant's thin shear
plane for the chip thickness the run itself measured (``chip_thickness_mm`` of its summary):

    r = t_u / t_c,   tan(phi) = r cos(gamma) / (1 - r sin(gamma)),   shear = cos(gamma) / (sin(phi) cos(phi - gamma)),
    eps_Merchant = shear / sqrt(3)                                        (von Mises equivalent of simple shear)

(Merchant 1945; e.g. Shaw, Metal Cutting Principles, 2nd ed., Ch. 3). gamma is the rake angle (10 deg). Continuity
alone fixes it: material that enters the chip at v_c and leaves at v_c t_u / t_c has been sheared by about that much,
in a thin primary zone or a wide one; the secondary zone at the rake face adds to it. The chip's body: the
workpiece rows between 1.5 and 3 t_u along the rake face and between 25 and 75 % of t_c from the face (away from the
secondary zone and the free surface): past the primary shear plane (which meets n = 0.75 t_c within 0.3 t_u of the
edge for shear angles of 10-45 deg), and made after the cut's start (material 3 t_u along left the shear plane
3 t_c / v_c ago, 1.1 ms in case 1 of its 1.6; farther along, the chip holds the start's transient), in the rake-face
frame of :func:`refsph.scenes.thermal_cutting.rake_frame`; also the rows within 10 % of t_c of the face (the
secondary zone). Their mean temperature too. For SPH runs also how the body's particles crowd (:func:`compaction`:
neighbours within 1.5 dx now and at the start, the area ratio of their starting neighbourhoods). Read from the run
folders (made by the sweep; not in git), kept in chip_strain.json (a key whose folder is gone keeps its earlier row)
and tabulated in chip_strain_report.md.

    python benchmarks/chip_strain.py [--runs DIR ...]   # read the folders, write the JSON and the page
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

import thermal_cutting as tc  # noqa: E402

OUT_JSON = Path(__file__).resolve().parent / "chip_strain.json"
OUT_MD = Path(__file__).resolve().parent / "chip_strain_report.md"
ALONG = (1.5, 3.0)          # the chip's body: from 1.5 to 3 t_u along the rake face ...
ACROSS = (0.25, 0.75)       # ... and from 25 to 75 % of the chip thickness from the face
SECONDARY = 0.1             # the secondary zone: within 10 % of the chip thickness from the face


def merchant_strain(tu: float, tc_: float, rake_deg: float) -> float:
    """The equivalent plastic strain of Merchant's thin shear plane for uncut chip thickness ``tu`` and chip
    thickness ``tc_`` (any one unit) on a tool of rake angle ``rake_deg`` (module text)."""
    g, r = math.radians(rake_deg), tu / tc_
    phi = math.atan(r * math.cos(g) / (1.0 - r * math.sin(g)))
    return math.cos(g) / (math.sin(phi) * math.cos(phi - g)) / math.sqrt(3.0)


def zones(u, n, tu: float, tc_: float) -> tuple[np.ndarray, np.ndarray]:
    """The masks of the chip's body and of its secondary zone (module text); u, n [m] in the rake-face frame, tu,
    tc_ [m]."""
    along = (u >= ALONG[0] * tu) & (u < ALONG[1] * tu)
    return along & (n >= ACROSS[0] * tc_) & (n < ACROSS[1] * tc_), along & (n >= 0.0) & (n < SECONDARY * tc_)


def body_means(body: np.ndarray, face: np.ndarray, eps_p, T) -> dict:
    """Mean eps_p and T of the rows of the chip's body and of its secondary zone (the masks of :func:`zones`)."""
    out = dict(n_body=int(body.sum()), n_face=int(face.sum()))
    for name, sel in (("body", body), ("face", face)):
        out[f"eps_{name}"] = float(eps_p[sel].mean()) if sel.any() else math.nan
        out[f"T_{name}_K"] = float(T[sel].mean()) if sel.any() else math.nan
    return out


def affine_maps(xa: np.ndarray, xb: np.ndarray, radius: float, weight=None) -> np.ndarray:
    """Each particle's affine map F (N, 2, 2) that best carries its neighbours (within ``radius`` of it in ``xa``)
    from ``xa`` to ``xb`` in the least squares weighted by ``weight(|dX|)`` (None: 1):
    F = (sum w dy (x) dX) (sum w dX (x) dX)^-1; the identity where the neighbours do not span the plane."""
    from scipy.spatial import cKDTree
    I, J = cKDTree(xa).query_pairs(radius, output_type="ndarray").T
    dX, dy = xa[J] - xa[I], xb[J] - xb[I]
    w = np.ones(len(I)) if weight is None else weight(np.linalg.norm(dX, axis=1))
    n = len(xa)
    A, B = np.zeros((n, 2, 2)), np.zeros((n, 2, 2))
    for a in range(2):
        for b in range(2):
            A[:, a, b] = np.bincount(I, w * dy[:, a] * dX[:, b], n) + np.bincount(J, w * dy[:, a] * dX[:, b], n)
            B[:, a, b] = np.bincount(I, w * dX[:, a] * dX[:, b], n) + np.bincount(J, w * dX[:, a] * dX[:, b], n)
    ok = np.abs(np.linalg.det(B)) > 1e-12 * np.einsum("nii->n", B) ** 2
    F = np.tile(np.eye(2), (n, 1, 1))
    F[ok] = A[ok] @ np.linalg.inv(B[ok])
    return F


def compaction(X0: np.ndarray, x: np.ndarray, rows: np.ndarray, dx: float) -> dict:
    """How the SPH chip's particles crowd: for the particles ``rows`` (indices into X0, x: the positions at the start
    and now), the mean number of others within 1.5 dx now and at the start, and the median area ratio J of the
    affine map that best carries each one's starting neighbours (within 2.1 dx at the start) to where they are now,
    :func:`affine_maps`. A material that keeps its volume has J = 1 and its particles keep their
    number of neighbours; J < 1 with more neighbours: particles crowd into each other's room, where the deformation
    gradient of Eq. (18) on a reference configuration does not look."""
    from scipy.spatial import cKDTree
    start, now = cKDTree(X0), cKDTree(x)
    J = np.linalg.det(affine_maps(X0, x, 2.1 * dx)[rows])
    count = lambda tree, pts: float(np.mean([len(tree.query_ball_point(p, 1.5 * dx)) - 1 for p in pts]))  # noqa: E731
    return dict(neighbours_now=count(now, x[rows]), neighbours_start=count(start, X0[rows]),
                area_ratio=float(np.median(J)) if len(J) else math.nan)


def row(folder: Path) -> dict | None:
    """The chip's strain of one finished run folder (None without a summary, a good status or a snapshot, or with a
    particle past the blow-up limit: the sweep's 'blow-up', whose summary says 'ok')."""
    from refsph.io import load_snapshot
    from refsph.scenes.thermal_cutting import RAKE_DEG, rake_frame
    path = folder / "summary.json"
    if not path.exists():
        return None
    s = json.loads(path.read_text())
    if s.get("status") != "ok" or not s.get("snapshots") or "blow_up" in s.get("metrics", {}):
        return None
    info, m = s["scene_info"], s["metrics"]
    z = load_snapshot(folder / "snapshots" / s["snapshots"][-1])
    n_work = len(z["x"]) if s["method"] == "pfem" else info["n_work"]
    u, n = rake_frame(z["x"][:n_work], float(z["t"]), info)
    tu, tc_ = info["tu_m"], 1e-3 * m["chip_thickness_mm"]
    eps_m = merchant_strain(tu, tc_, RAKE_DEG)
    body, face = zones(u, n, tu, tc_)
    out = dict(method=s["method"], tu_mm=1e3 * tu, chip_mm=m["chip_thickness_mm"], eps_merchant=eps_m,
               **body_means(body, face, z["eps_p"][:n_work], z["T"][:n_work]))
    out["body_over_merchant"] = out["eps_body"] / eps_m
    out["ref_update"] = s.get("numerics", {}).get("ref_update_strain") if s["method"] == "tlsph" else None
    out["across"] = tu / s["dp"]
    if s["method"] != "pfem":                                   # SPH particles keep their identity; PFEM nodes not
        z0 = load_snapshot(folder / "snapshots" / s["snapshots"][0])
        if np.array_equal(z0["id"][:n_work], z["id"][:n_work]):
            out.update(compaction(z0["x"][:n_work], z["x"][:n_work], np.flatnonzero(body), s["dp"]))
    return out


def report(rows: dict) -> str:
    f = study.fmt
    lines = ["# The chip's plastic strain against its thickness", "",
             "Made by `python benchmarks/chip_strain.py` from the sweep's run folders (module text): the mean "
             f"effective plastic strain of the chip's body ({ALONG[0]:g}-{ALONG[1]:g} t_u along the rake face, "
             f"{100 * ACROSS[0]:g}-{100 * ACROSS[1]:g} % of the chip thickness t_c from it) in the run's last "
             "snapshot, against Merchant's thin-shear-plane strain for the t_c the run measured; the secondary "
             f"zone: within {100 * SECONDARY:g} % of t_c of the face.", "",
             "| run | method | ref update | t_u [mm] | t_c [mm] | Merchant eps | body eps | body / Merchant | "
             "body T [K] | secondary-zone eps | its T [K] | rows (body, zone) | neighbours now / start | "
             "area ratio J |",
             "|---" * 14 + "|"]
    for key, r in rows.items():
        lines.append(f"| {key} | {r['method']} | {f(r.get('ref_update'), '.2f')} | {r['tu_mm']:.2f} "
                     f"| {r['chip_mm']:.3f} | {f(r['eps_merchant'], '.2f')} "
                     f"| {f(r['eps_body'], '.2f')} | {f(r['body_over_merchant'], '.2f')} | {f(r['T_body_K'], '.0f')} "
                     f"| {f(r['eps_face'], '.2f')} | {f(r['T_face_K'], '.0f')} | {r['n_body']}, {r['n_face']} | "
                     f"{f(r.get('neighbours_now'), '.1f')} / {f(r.get('neighbours_start'), '.1f')} | "
                     f"{f(r.get('area_ratio'), '.2f')} |")
    for group in sorted({_group(r) for r in rows.values()}):       # method, reference update, particles across t_u
        sel = [r for r in rows.values() if _group(r) == group]
        method, ref, across = group
        name = f"{method} (ref update {ref:g}, t_u/{across})" if ref else f"{method} (t_u/{across})"
        x = [r["body_over_merchant"] for r in sel if math.isfinite(r["body_over_merchant"])]
        if x:
            lines.append(f"\n{name}: body / Merchant {np.mean(x):.2f} on average, {min(x):.2f}-{max(x):.2f} "
                         f"({len(x)} runs).")
        J = [r["area_ratio"] for r in sel if "area_ratio" in r]
        if J:
            lines.append(f"{name}: the area ratio J of the body's starting neighbourhoods {min(J):.2f}-{max(J):.2f} (a "
                         "material that keeps its volume: 1; particles that crowd: below 1; neighbours within 1.5 dx "
                         "in the table).")
    return "\n".join(lines) + "\n"


def _group(r: dict) -> tuple:
    """(method, TLSPH's ref_update_strain or 0, particles across t_u) of a row (rows kept from before these were
    recorded: t_u/10, the only resolution read then)."""
    return r["method"], r.get("ref_update") or 0.0, int(round(r.get("across", 10.0)))


def wanted(options: dict, numerics: dict) -> bool:
    """The runs read: the sweep's at t_u/10, and the 'refupdate' study's (TLSPH's reference updated more or less
    often, at t_u/5 too)."""
    return float(options.get("n_tu", 0.0)) == 10.0 or "ref_update_strain" in numerics


def main(argv=None) -> int:
    return tc.folder_study(argv, __doc__, row, wanted,
                           OUT_JSON, OUT_MD, report, sort_key=lambda kv: (kv[1]["method"], kv[0]))


if __name__ == "__main__":
    raise SystemExit(main())
