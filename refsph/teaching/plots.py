"""Plots of particle fields, kept apart from the physics (used by the chapters and the benchmark scripts).

Only matplotlib's object interface is used: every function draws on an ``Axes`` it is given. Fields use a
perceptual colour map (viridis by default) with a labelled colour bar (:func:`colorbar`).
"""
from __future__ import annotations

import numpy as np

__all__ = ["particle_field", "colorbar"]


def particle_field(ax, x: np.ndarray, value: np.ndarray, dp: float, *, body: np.ndarray | None = None,
                   xlim=None, ylim=None, scale: float = 1e3, cmap: str = "viridis", vmin=None, vmax=None,
                   rigid_color: str = "0.6", spread: float = 1.5, fill: float | None = 2.5):
    """2D particles as squares ``spread`` spacings ``dp`` wide (1.5: a deformed, stretched continuum still looks
    like one, with no white gaps between particles), coloured by ``value``; particles with ``body > 0`` (rigid
    tools) in grey. Coordinates are multiplied by ``scale`` (default: metres to mm); ``xlim``, ``ylim`` in those
    units (default: the particles' extent plus one spacing; the marker size is set from them). Higher values are drawn
    last, so thin bands of high value stay visible. ``fill``: an underlay of squares that many spacings wide in
    the same colours, drawn first, so that where the material has opened up (a chip stretched to several spacings
    between particles) no white speckles show (None: no underlay). Returns the scatter of the deformable particles
    (for :func:`colorbar`)."""
    x = np.asarray(x) * scale
    deform = np.ones(len(x), dtype=bool) if body is None else np.asarray(body) == 0
    ax.set_aspect("equal")
    pad = dp * scale                                        # no limits given: the particles' extent + one spacing
    ax.set_xlim(*(xlim if xlim is not None else (x[:, 0].min() - pad, x[:, 0].max() + pad)))
    ax.set_ylim(*(ylim if ylim is not None else (x[:, 1].min() - pad, x[:, 1].max() + pad)))
    ax.apply_aspect()
    x0, x1 = ax.get_xlim()
    fig = ax.get_figure()
    pt_per_unit = ax.get_position().width * fig.get_figwidth() * 72 / (x1 - x0)
    size = (spread * pt_per_unit * dp * scale) ** 2         # marker area [pt^2]
    if not deform.all():
        ax.scatter(x[~deform, 0], x[~deform, 1], c=rigid_color, s=size, lw=0, marker="s")
    v = np.asarray(value)[deform]
    order = np.argsort(v, kind="stable")
    if fill is not None:
        ax.scatter(x[deform][order, 0], x[deform][order, 1], c=v[order], s=(fill / spread) ** 2 * size, lw=0,
                   marker="s", cmap=cmap, vmin=vmin, vmax=vmax)
    return ax.scatter(x[deform][order, 0], x[deform][order, 1], c=v[order], s=size, lw=0, marker="s", cmap=cmap,
                      vmin=vmin, vmax=vmax)


def colorbar(fig, mappable, ax, label: str, **kwargs):
    """A colour bar beside ``ax`` with its quantity and unit as ``label`` (e.g. "effective plastic strain [-]")."""
    cb = fig.colorbar(mappable, ax=ax, **kwargs)
    cb.set_label(label)
    return cb
