"""Plots of particle fields, kept apart from the physics (used by the chapters and the benchmark scripts).

Only matplotlib's object interface is used: every function draws on an ``Axes`` it is given.
"""
from __future__ import annotations

import numpy as np

__all__ = ["particle_field"]


def particle_field(ax, x: np.ndarray, value: np.ndarray, dp: float, *, body: np.ndarray | None = None,
                   xlim=None, ylim=None, scale: float = 1e3, cmap: str = "jet", vmin=None, vmax=None,
                   rigid_color: str = "0.6"):
    """2D particles as squares one spacing ``dp`` wide (so that a continuum looks like one), coloured by
    ``value``; particles with ``body > 0`` (rigid tools) in grey. Coordinates are multiplied by ``scale``
    (default: metres to mm). Higher values are drawn last, so thin bands of high value stay visible. Returns
    the scatter of the deformable particles (for a colour bar)."""
    x = np.asarray(x) * scale
    deform = np.ones(len(x), dtype=bool) if body is None else np.asarray(body) == 0
    ax.set_aspect("equal")
    if xlim is not None:
        ax.set_xlim(*xlim)
    if ylim is not None:
        ax.set_ylim(*ylim)
    ax.apply_aspect()
    x0, x1 = ax.get_xlim()
    fig = ax.get_figure()
    pt_per_unit = ax.get_position().width * fig.get_figwidth() * 72 / (x1 - x0)
    size = (1.15 * pt_per_unit * dp * scale) ** 2          # marker area [pt^2]: one spacing across
    if not deform.all():
        ax.scatter(x[~deform, 0], x[~deform, 1], c=rigid_color, s=size, lw=0, marker="s")
    v = np.asarray(value)[deform]
    order = np.argsort(v, kind="stable")
    return ax.scatter(x[deform][order, 0], x[deform][order, 1], c=v[order], s=size, lw=0, marker="s", cmap=cmap,
                      vmin=vmin, vmax=vmax)
