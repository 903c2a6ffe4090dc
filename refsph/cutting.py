"""Orthogonal cutting (Section 3.3, Tables 3 and 5): an AISI 4340 workpiece 3 x 1 mm, a rigid frictionless tool
0.5 x 1 mm moving at 50 m/s, feed (depth of cut) 0.3 or 0.5 mm, 2D plane strain.

PRELIMINARY (issue 5 is open): geometry, held boundaries, forces and chip thickness are in place; the shear-band
measurements, chapter 08 and the paper-resolution study are not yet.

Model, and the choices the paper leaves open (its Fig. 11 is not in the text we have):

* **Workpiece** [0, 3] x [0, 1] mm on a lattice of spacings 3 mm / round(3 mm / dp) and 1 mm / round(1 mm / dp),
  held by clamps (:class:`~refsph.boundaries.Clamp`) on its bottom row and its left column of particles.
* **Tool**: the rectangle [3, 3.5] x [1 - feed, 2 - feed] mm, i.e. rake and clearance angles 0 (the paper gives
  only the size), its cutting edge at the cut depth, touching the workpiece's right face at t = 0 and moving at
  -50 m/s along x. Only its surface layers are modelled: ceil(2h/dp) columns on the rake face and as many rows on
  the clearance face (an L of particles). Frictionless (Section 3.3).
* **Cut length** (not printed): option ``travel``, 1 mm by default (t_end = 20 us).

Numerics: Table 5 (dp = 0.01 mm, h = 0.018 mm: h/dp = 1.8, beta1 = beta2 = 0.5), ESPH gamma = 0.3, Courant 0.3,
ESPH Verlet skin 0.3 h; TLSPH reference updates at max |E| > 0.5 (``Numerics.ref_update_strain``).

Measurements (``summary.json`` metrics): ``cutting_force_history`` and ``thrust_force_history`` ([t, F], per
metre of thickness, 400 time bins): the force of the workpiece on the tool along -x (against the cut) and along
+y (pushing the tool away from the workpiece); their time averages over the second half of the run;
``max_plastic_strain``, ``max_temperature_K``; ``chip_thickness_mm``: the horizontal width of the material that
was above the cut line and now lies within one feed above the original surface, next to the rake face (the chip
rises along the vertical rake face, so its thickness is horizontal there), the median over rows of one spacing.
"""
from __future__ import annotations

import math

import numpy as np

from .boundaries import Clamp, RigidBody
from .pressing import _binned, _time_mean, pressing_johnson_cook, pressing_material
from .state import concatenate_states, make_state

__all__ = ["make_scene", "cutting_particles", "CUTTING_GEOMETRY", "TOOL_BODY"]

TOOL_BODY = 1
N_FORCE_BINS = 400
# Section 3.3 and Table 5
CUTTING_GEOMETRY = dict(workpiece_m=(3.0e-3, 1.0e-3), tool_m=(0.5e-3, 1.0e-3), tool_speed_m_s=50.0,
                        feeds_m=(0.3e-3, 0.5e-3), particle_spacing_m=0.01e-3, smoothing_length_m=0.018e-3,
                        time_step_s=1e-10, beta1=0.5, beta2=0.5)

CUTTING_OPTIONS = {
    "feed": (0.3e-3, "depth of cut (the paper's 'feeding length') [m]: 0.3e-3 or 0.5e-3 in the paper"),
    "travel": (1.0e-3, "length of cut at the end of the run [m] (not printed in the paper)"),
    "eps_dot_0": (1.0, "Johnson-Cook reference strain rate [1/s] (not printed in Table 3)"),
}


def cutting_particles(dp: float, feed: float, n_tool_layers: int):
    """(workpiece x, tool x, dx, dy, clamp index, cut depth y0) for spacing dp."""
    (Lx, Ly), (Wt, Ht) = CUTTING_GEOMETRY["workpiece_m"], CUTTING_GEOMETRY["tool_m"]
    nx, ny = round(Lx / dp), round(Ly / dp)
    if ny < 8:
        raise ValueError(f"spacing dp = {dp!r} m is too coarse for a {Ly * 1e3} mm deep workpiece")
    dx, dy = Lx / nx, Ly / ny
    if not (2 * dy <= feed <= Ly - 2 * dy):
        raise ValueError(f"feed must lie between two spacings and the workpiece depth less two spacings, got {feed!r}")
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    xw = np.stack([(i.ravel() + 0.5) * dx, (j.ravel() + 0.5) * dy], axis=1)
    clamp = np.flatnonzero((i.ravel() == 0) | (j.ravel() == 0))
    y0 = Ly - feed
    ti, tj = np.meshgrid(np.arange(round(Wt / dx)), np.arange(round(Ht / dy)), indexing="ij")
    surface = (ti.ravel() < n_tool_layers) | (tj.ravel() < n_tool_layers)
    xt = np.stack([Lx + (ti.ravel() + 0.5) * dx, y0 + (tj.ravel() + 0.5) * dy], axis=1)[surface]
    return xw, xt, dx, dy, clamp, y0


def _default_dp(dim, quick):
    return 0.025e-3 if quick else CUTTING_GEOMETRY["particle_spacing_m"]


def _build(dim, dp, quick, feed=CUTTING_OPTIONS["feed"][0], travel=CUTTING_OPTIONS["travel"][0], eps_dot_0=1.0):
    from .scenes import Numerics, Setup
    if dim != 2:
        raise ValueError("the cutting scene is 2D plane strain")
    if not (np.isfinite(travel) and 0 < travel <= 2.0e-3):
        raise ValueError(f"travel must lie in (0, 2 mm], got {travel!r} m")
    g = CUTTING_GEOMETRY
    numerics = Numerics(h_over_dp=g["smoothing_length_m"] / g["particle_spacing_m"], beta1=g["beta1"],
                        beta2=g["beta2"], gamma=0.3, skin_factor=0.3)
    layers = math.ceil(2.0 * numerics.h_over_dp - 1e-9)
    xw, xt, dx, dy, clamp, y0 = cutting_particles(dp, float(feed), layers)
    mat = pressing_material()                           # Table 3 (the same AISI 4340 as the pressing)
    jc = pressing_johnson_cook(eps_dot_0)
    speed = g["tool_speed_m_s"]
    work = make_state(xw, [0.0, 0.0], mat.rho0, dx * dy, T0=jc.T_room)
    tool = make_state(xt, [-speed, 0.0], mat.rho0, dx * dy, T0=jc.T_room, body=np.full(len(xt), TOOL_BODY))
    t_end = float(travel) / speed
    return Setup(state=concatenate_states(work, tool), material=mat, dp=dx, numerics=numerics, t_end=t_end,
                 n_snapshots=8, info=dict(n_work=work.n, n_tool=tool.n, dx=dx, dy=dy, feed_m=float(feed), y0=y0,
                                          tool_layers=layers, travel_m=float(travel), tool_speed_m_s=speed,
                                          eps_dot_0=float(eps_dot_0)),
                 plasticity=jc, rigid=(RigidBody("tool", TOOL_BODY, (-speed, 0.0)),),
                 clamps=(Clamp("held", clamp),))


def _record(state, setup):
    n = setup.info["n_work"]
    return dict(t=state.t, max_eps_p=float(np.max(state.eps_p[:n])), max_T=float(np.max(state.T[:n])))


def chip_thickness(x: np.ndarray, X0: np.ndarray, y0: float, surface: float, feed: float, tool_face: float,
                   dy: float) -> float:
    """Median over rows (height dy) between surface + feed/2 and surface + feed of the horizontal width of chip
    material (initially above the cut line y0) next to the rake face x = tool_face [m]; nan if no row has chip."""
    chip = X0[:, 1] > y0
    widths = []
    for yl in np.arange(surface + 0.5 * feed, surface + feed, dy):
        row = chip & (x[:, 1] >= yl) & (x[:, 1] < yl + dy) & (x[:, 0] < tool_face)
        if np.count_nonzero(row) >= 2:
            widths.append(tool_face - x[row, 0].min())
    return float(np.median(widths)) if widths else float("nan")


def _metrics(hist, state, setup):
    info = setup.info
    n = info["n_work"]
    rh = hist["reaction"]
    t, dt = np.asarray(rh["t"]), np.asarray(rh["dt"])
    Fc = np.asarray(rh["tool"])[:, 0]                  # against the cut (the tool moves along -x)
    Ft = np.asarray(rh["tool"])[:, 1]                  # pushing the tool up, away from the workpiece
    nb = min(N_FORCE_BINS, max(1, len(t)))
    tb, cb = _binned(t, dt, Fc, setup.t_end, nb)
    _, tb_ = _binned(t, dt, Ft, setup.t_end, nb)
    tool_face = float(state.x[n:, 0].min()) - 0.5 * info["dx"]
    # initial positions: the workpiece's particle order is the lattice's, rebuilt here (TLSPH updates X)
    X0 = setup.state.x[:n]
    return dict(
        cutting_force_history=np.stack([tb, cb], axis=1),
        thrust_force_history=np.stack([tb, tb_], axis=1),
        cutting_force_mean_N_per_m=_time_mean(t, dt, Fc, 0.5 * setup.t_end),
        thrust_force_mean_N_per_m=_time_mean(t, dt, Ft, 0.5 * setup.t_end),
        max_plastic_strain=float(np.max(state.eps_p[:n])),
        max_temperature_K=float(np.max(state.T[:n])),
        chip_thickness_mm=1e3 * chip_thickness(state.x[:n], X0, info["y0"], CUTTING_GEOMETRY["workpiece_m"][1],
                                               info["feed_m"], tool_face, info["dy"]),
        cut_length_mm=float(info["tool_speed_m_s"] * state.t * 1e3),
    )


def make_scene():
    from .scenes import Scene                               # late import: scenes imports this module
    return Scene(
        "cutting",
        "orthogonal cutting (PRELIMINARY): AISI 4340 3 x 1 mm, rigid tool 0.5 x 1 mm at 50 m/s (Section 3.3)",
        _default_dp, _build, _record, _metrics, options=CUTTING_OPTIONS, default_dim=2,
        methods=("esph", "tlsph"))
