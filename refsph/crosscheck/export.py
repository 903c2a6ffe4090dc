"""``refsph export RUN_DIR --vtk``: a run's snapshots as a time series ParaView opens.

One VTU file per snapshot (the particles as vertex cells, a PFEM run's nodes with its triangles as cells, every
snapshot array as point data: vectors as 3 components, tensors as 9; a 2D run's tensors get their plane-strain zz
component: S_zz for S (the snapshot's own array), 1 for the deformation gradient F (no stretch across the plane, so
ParaView's det F is J), 0 otherwise) and a ParaView collection ``RUN_DIR/vtk/run.pvd`` that gives each file its time.
The file format is written by meshio (an optional extra: ``pip install -e '.[vtk]'``), not by hand; the units of every
field go into the collection's comments and ``vtk/units.json``.
"""
from __future__ import annotations

import json
from pathlib import Path
from xml.sax.saxutils import escape

import numpy as np

from ..io import load_run, load_snapshot

__all__ = ["export_vtk"]


MESH_ARRAYS = ("triangles", "boundary_edges", "tool_x", "tool_T")   # a PFEM snapshot's mesh and tool (refsph.pfem_run)


def _point_data(z: dict, d: int) -> dict:
    out = {}
    n = len(z["x"])
    for k, a in z.items():
        if k in ("t", "units") + MESH_ARRAYS or not isinstance(a, np.ndarray) or a.shape[:1] != (n,):
            continue
        if a.ndim == 2 and a.shape[1] == d:                 # vectors -> 3 components
            b = np.zeros((n, 3))
            b[:, :d] = a
            out[k] = b
        elif a.ndim == 3:                                   # d x d tensors -> 9 components
            b = np.zeros((n, 3, 3))
            b[:, :d, :d] = a
            if d == 2:                                      # the plane-strain zz component (module text)
                b[:, 2, 2] = z[f"{k}_zz"] if f"{k}_zz" in z else (1.0 if k == "F" else 0.0)
            out[k] = b.reshape(n, 9)
        elif a.ndim == 1:
            out[k] = a.astype(float) if a.dtype.kind in "iub" else a
    return out


def export_vtk(run_dir) -> Path:
    """Write ``RUN_DIR/vtk/snap_NNNNN.vtu`` for every snapshot and ``RUN_DIR/vtk/run.pvd``; returns the .pvd path."""
    try:
        import meshio
    except ImportError:
        raise ImportError("refsph export --vtk needs meshio: pip install -e '.[vtk]' (or pip install meshio)") from None
    run_dir = Path(run_dir)
    _, snaps = load_run(run_dir)
    if not snaps:
        raise FileNotFoundError(f"{run_dir} has no snapshots")
    out = run_dir / "vtk"
    out.mkdir(exist_ok=True)
    entries, units = [], {}
    for p in snaps:
        z = load_snapshot(p)
        x = z["x"]
        n, d = x.shape
        pts = np.zeros((n, 3))
        pts[:, :d] = x
        units = z["units"]
        cells = [("triangle", z["triangles"])] if "triangles" in z else [("vertex", np.arange(n).reshape(-1, 1))]
        mesh = meshio.Mesh(pts, cells, point_data=_point_data(z, d))
        name = p.stem + ".vtu"
        mesh.write(out / name)
        entries.append(f'    <DataSet timestep="{z["t"]!r}" group="" part="0" file="{escape(name)}"/>')
    (out / "units.json").write_text(json.dumps(units, indent=1) + "\n")
    comment = escape("refsph snapshots; units: " + ", ".join(f"{k} [{u}]" for k, u in units.items()))
    pvd = out / "run.pvd"
    pvd.write_text('<?xml version="1.0"?>\n<!-- ' + comment.replace("--", "- -") + ' -->\n'
                   '<VTKFile type="Collection" version="0.1">\n  <Collection>\n' + "\n".join(entries)
                   + "\n  </Collection>\n</VTKFile>\n")
    return pvd
