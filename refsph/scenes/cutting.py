"""Orthogonal cutting (Section 3.3, Tables 3 and 5): an AISI 4340 workpiece 3 x 1 mm, a rigid frictionless tool
0.5 x 1 mm moving at 50 m/s, feed (depth of cut) 0.3 or 0.5 mm, 2D plane strain.

Model, and the choices the paper leaves open (its Fig. 11 is not in the text we have):

* **Workpiece** [0, 3] x [0, 1] mm on a lattice of spacings 3 mm / round(3 mm / dp) and 1 mm / round(1 mm / dp),
  held by clamps (:class:`~refsph.boundaries.Clamp`) on its bottom row and its left column of particles (the
  paper: "the workpiece bottom fixed"; the left column stops the whole workpiece from being pushed along).
* **Tool**: the rectangle [3, 3.5] x [1 - feed, 2 - feed] mm, i.e. rake and clearance angles 0 (the paper gives
  only the size), its cutting edge at the cut depth, touching the workpiece's right face at t = 0 and moving at
  -50 m/s along x. Only its surface layers are modelled: ceil(2h/dp) columns on the rake face and as many rows on
  the clearance face (an L of particles), so that every workpiece particle near the tool sees a full kernel
  support of tool. Frictionless (Section 3.3).
* **Cut length** (not printed): option ``travel``, 1 mm by default (t_end = 20 us), a third of the workpiece.
* **Perturbed runs**: ``jitter`` moves the workpiece's particles at random by up to that many spacings (``seed``;
  0 by default: the lattice), for the run-to-run scatter of the metrics (``benchmarks/metric_scatter.py``). The
  measurements keep the lattice as the material coordinates (a jitter of 0.01 dx moves no particle across a row).

Numerics: Table 5 (dp = 0.01 mm, h = 0.018 mm: h/dp = 1.8, beta1 = beta2 = 0.5), ESPH gamma = 0.3, CFL step with
Courant 0.3 (the paper's fixed 1e-10 s is 9x smaller), ESPH Verlet skin 0.15 h; TLSPH reference updates at
max |E| > 0.5 (``Numerics.ref_update_strain``).

Measurements (``summary.json`` metrics, :func:`cutting_metrics`; :func:`refsph.io.analyse_cutting_run` recomputes
them from a run folder):

* ``cutting_force_history``, ``thrust_force_history`` ([t, F], per metre of thickness, 400 time bins): the force of
  the workpiece on the tool along +x (against the cut; the tool moves along -x) and along +y (pushing the tool
  away from the workpiece); ``cutting_force_mean_N_per_m``, ``thrust_force_mean_N_per_m``: their time averages
  over the steady part, taken as the second half of the cut (``STEADY_FROM``);
* ``chip_thickness_mm``: the horizontal width of the material that was above the cut line and now lies between
  half a feed and one feed above the original surface, next to the rake face (the chip rises along the vertical
  rake face, so its thickness is horizontal there), the median over rows of one spacing;
  ``shear_angle_from_chip_deg``: atan(feed / chip thickness), the shear angle that continuity of a chip of that
  thickness implies for rake angle 0 (Merchant);
* ``n_shear_bands``, ``band_spacing_mm`` (along the chip), ``band_spacing_material_mm`` (in the uncut workpiece),
  ``band_angle_deg`` (to the cutting direction): see :func:`shear_bands`;
* ``max_plastic_strain``, ``max_temperature_K`` (workpiece), ``cut_length_mm``.
"""
from __future__ import annotations

import math

import numpy as np

from ..boundaries import Clamp, RigidBody
from ..paper_data import CUTTING_GEOMETRY, CUTTING_OBSERVED, CUTTING_TABLE5
from ..state import concatenate_states, make_state
from .base import Numerics, Scene, Setup
from .measure import (N_FORCE_BINS, TOOL_BODY, aisi4340_johnson_cook, aisi4340_material, binned_mean, box_outline,
                      check_particle_count, block_lattice, jittered, time_mean)

__all__ = ["SCENE", "cutting_particles", "chip_thickness", "lattice_shape", "shear_bands", "cutting_metrics",
           "cutting_table", "STEADY_FROM", "BAND_REL_PROMINENCE"]
STEADY_FROM = 0.5             # force means over the second half of the run (t > STEADY_FROM t_end)
BAND_REL_PROMINENCE = 0.5     # a shear band: a strain peak along the chip at least this x the median above its
#                               surroundings (see shear_bands)
CUTTING_OPTIONS = {
    "feed": (0.3e-3, "depth of cut (the paper's 'feeding length') [m]: 0.3e-3 or 0.5e-3 in the paper"),
    "travel": (1.0e-3, "length of cut at the end of the run [m] (not printed in the paper)"),
    "eps_dot_0": (1.0, "Johnson-Cook reference strain rate [1/s] (not printed in Table 3)"),
    "jitter": (0.0, "random displacement of the workpiece's particles, in units of dx (a perturbed run)"),
    "seed": (0, "the random seed of the jitter"),
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
    xw, i, j = block_lattice(nx, ny, dx, dy)
    clamp = np.flatnonzero((i == 0) | (j == 0))
    y0 = Ly - feed
    check_particle_count(round(Wt / dx), round(Ht / dy), dp=dx)
    ti, tj = np.meshgrid(np.arange(round(Wt / dx)), np.arange(round(Ht / dy)), indexing="ij")
    surface = (ti.ravel() < n_tool_layers) | (tj.ravel() < n_tool_layers)
    xt = np.stack([Lx + (ti.ravel() + 0.5) * dx, y0 + (tj.ravel() + 0.5) * dy], axis=1)[surface]
    return xw, xt, dx, dy, clamp, y0


def _default_dp(dim, quick):
    return 0.025e-3 if quick else CUTTING_TABLE5["particle_spacing_m"]


def _build(dim, dp, quick, *, feed, travel, eps_dot_0, jitter, seed):
    if dim != 2:
        raise ValueError("the cutting scene is 2D plane strain")
    if not (np.isfinite(travel) and 0 < travel <= 2.0e-3):
        raise ValueError(f"travel must lie in (0, 2 mm], got {travel!r} m")
    g, t5 = CUTTING_GEOMETRY, CUTTING_TABLE5
    numerics = Numerics(h_over_dp=t5["smoothing_length_m"] / t5["particle_spacing_m"], beta1=t5["beta1"],
                        beta2=t5["beta2"], gamma=t5["artificial_pressure_gamma_esph"], skin_factor=0.15)
    layers = math.ceil(2.0 * numerics.h_over_dp - 1e-9)
    xw, xt, dx, dy, clamp, y0 = cutting_particles(dp, float(feed), layers)
    xw = jittered(xw, jitter, (dx, dy), seed)
    mat = aisi4340_material()                           # Table 3 (the same AISI 4340 as the pressing)
    jc = aisi4340_johnson_cook(eps_dot_0)
    speed = g["tool_speed_m_s"]
    work = make_state(xw, [0.0, 0.0], mat.rho0, dx * dy, T0=jc.T_room)
    tool = make_state(xt, [-speed, 0.0], mat.rho0, dx * dy, T0=jc.T_room, body=np.full(len(xt), TOOL_BODY))
    t_end = float(travel) / speed
    perturbed = dict(jitter=float(jitter), seed=int(seed)) if jitter > 0 else {}   # (no jitter: the info as before)
    return Setup(state=concatenate_states(work, tool), material=mat, dp=dx, numerics=numerics, t_end=t_end,
                 n_snapshots=8, info=dict(n_work=work.n, n_tool=tool.n, dx=dx, dy=dy, feed_m=float(feed), y0=y0,
                                          tool_layers=layers, travel_m=float(travel), tool_speed_m_s=speed,
                                          eps_dot_0=float(eps_dot_0), **perturbed),
                 strength=jc, rigid=(RigidBody("tool", TOOL_BODY, (-speed, 0.0), shape=box_outline(xt, dx, dy)),),
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


def lattice_shape(setup_info: dict) -> tuple[int, int]:
    """(nx, ny) of the workpiece lattice: particle k of the workpiece is column k // ny, row k % ny."""
    (Lx, Ly) = CUTTING_GEOMETRY["workpiece_m"]
    return round(Lx / setup_info["dx"]), round(Ly / setup_info["dy"])


def shear_bands(x: np.ndarray, eps_p: np.ndarray, nx: int, ny: int, dx: float, dy: float, feed: float,
                x_tip: float, rel_prominence: float = BAND_REL_PROMINENCE) -> dict:
    """Shear bands in the cut layer, found in the plastic strain of the workpiece lattice (material coordinates).

    The workpiece particles are a lattice in their initial positions X0 = ((i + 1/2) dx, (j + 1/2) dy), so
    eps_p[i, j] is the plastic strain field over the undeformed workpiece. A shear band is a thin line of high
    eps_p that crosses the cut layer (the rows above the cut line y0 = Ly - feed) from the cut line to the free
    surface. Method:

    1. **Profile along the chip**: eps_p(i) on the middle row of the cut layer (the row whose cell holds
       y0 + feed/2; where that is a boundary between two rows, an even number of rows, the upper one), for
       the material the tool has reached, i.e. X0_x > x_tip - feed (``x_tip``: the cutting edge's x at this
       instant; the margin of one feed keeps the band now forming at the tool tip, which crosses the middle row
       ahead of the edge). A 3-point running mean removes particle-scale noise.
    2. **Bands** are the peaks of that profile (:func:`scipy.signal.find_peaks`) whose prominence is at least
       ``rel_prominence`` times the profile's median: a band is a local strain maximum well above its
       surroundings, not a ripple. ``n`` counts them.
    3. **Spacing**: between neighbouring bands, in material coordinates (the uncut length of workpiece that makes
       one chip segment, ``spacing_material_mm``) and along the chip as it is now (the arc length between the
       bands along the middle row's current positions, ``spacing_mm``, what a picture of the chip shows).
    4. **Angle**: each band is followed row by row from the middle row up to the surface and down to the cut
       line (in each row the strain maximum within two columns of the row before); a straight line
       X0_x = a + b X0_y fitted to it gives the band's angle to the cutting direction (the tool moves along -x)
       in the undeformed workpiece, phi = atan2(1, -b): 45 deg leans ahead of the tool, 90 deg is vertical. A
       band forms in material just ahead of the tool that has not deformed much yet, so this is close to its
       angle when it formed; in the chip the bands have since rotated (``angles_current_deg``: the same particles'
       line in the current configuration, angle to +x, for reference).
    """
    from scipy.signal import find_peaks

    E = eps_p[: nx * ny].reshape(nx, ny)
    xc = x[: nx * ny].reshape(nx, ny, 2)
    Ly = ny * dy
    j0 = int(math.ceil((Ly - feed) / dy - 0.5 - 1e-9))     # first row above the cut line
    jm = int(math.floor((Ly - 0.5 * feed) / dy + 1e-6))     # middle row (with an even count: the one above)
    X = (np.arange(nx) + 0.5) * dx
    cols = np.flatnonzero(X > x_tip - feed)
    empty = dict(n=0, spacing_mm=float("nan"), spacing_material_mm=float("nan"), angle_deg=float("nan"),
                 peaks_X_mm=[], angles_deg=[], angles_current_deg=[], profile=np.zeros((0, 2)), rows=(j0, jm))
    if len(cols) < 5:
        return empty
    e = np.convolve(E[cols, jm], np.ones(3) / 3.0, mode="same")
    e[0], e[-1] = E[cols[0], jm], E[cols[-1], jm]
    med = float(np.median(e))
    peaks, _ = find_peaks(e, prominence=rel_prominence * max(med, 1e-12))
    out = dict(empty, profile=np.stack([X[cols] * 1e3, e], axis=1))
    if len(peaks) == 0:
        return out
    ip = cols[peaks]
    # arc length along the middle row's current positions (material order)
    mid = xc[cols, jm]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(mid, axis=0), axis=1))])
    angles, angles_cur = [], []
    for i in ip:
        track = {jm: i}
        for rng in (range(jm + 1, ny), range(jm - 1, j0 - 1, -1)):
            prev = i
            for j in rng:
                lo, hi = max(prev - 2, 0), min(prev + 3, nx)
                prev = lo + int(np.argmax(E[lo:hi, j]))
                track[j] = prev
        js = np.array(sorted(track))
        its = np.array([track[j] for j in js])
        b = np.polyfit((js + 0.5) * dy, (its + 0.5) * dx, 1)[0]
        angles.append(float(np.degrees(np.arctan2(1.0, -b))))
        pts = xc[its, js]
        d = np.linalg.svd(pts - pts.mean(axis=0), full_matrices=False)[2][0]
        angles_cur.append(float(np.degrees(np.arctan2(abs(d[1]), d[0] * np.sign(d[1] or 1.0))) % 180.0))
    out.update(n=int(len(ip)), peaks_X_mm=[float(X[i] * 1e3) for i in ip], angles_deg=angles,
               angles_current_deg=angles_cur, angle_deg=float(np.median(angles)))
    if len(ip) >= 2:
        out.update(spacing_material_mm=float(np.mean(np.diff(X[ip]))) * 1e3,
                   spacing_mm=float(np.mean(np.diff(arc[peaks]))) * 1e3)
    return out


def cutting_metrics(reaction: dict, x: np.ndarray, eps_p: np.ndarray, T: np.ndarray, t: float, info: dict,
                    t_end: float) -> dict:
    """The ``metrics`` of ``summary.json`` from the tool's reaction history (``{'t', 'dt', 'tool'}``, as
    :func:`refsph.io.load_reactions` returns it) and the final positions, plastic strain and temperature of all
    particles (workpiece first, then the tool). :func:`refsph.io.analyse_cutting_run` calls it on a run
    folder."""
    n = info["n_work"]
    t_r, dt = np.asarray(reaction["t"]), np.asarray(reaction["dt"])
    F = np.asarray(reaction["tool"])
    Fc, Ft = F[:, 0], F[:, 1]         # Fc against the cut (the tool moves along -x); Ft pushes the tool up (+y)
    nb = min(N_FORCE_BINS, max(1, len(t_r)))
    tb, cb = binned_mean(t_r, dt, Fc, t_end, nb)
    _, tb_ = binned_mean(t_r, dt, Ft, t_end, nb)
    x_tip = float(x[n:, 0].min()) - 0.5 * info["dx"]     # the rake face (and the cutting edge) at time t
    nx, ny = lattice_shape(info)
    X0 = block_lattice(nx, ny, info["dx"], info["dy"])[0]          # initial positions (the lattice)
    Ly = CUTTING_GEOMETRY["workpiece_m"][1]
    feed = info["feed_m"]
    bands = shear_bands(x, eps_p, nx, ny, info["dx"], info["dy"], feed, x_tip)
    tc = chip_thickness(x[:n], X0, info["y0"], Ly, feed, x_tip, info["dy"])
    return dict(
        cutting_force_history=np.stack([tb, cb], axis=1),
        thrust_force_history=np.stack([tb, tb_], axis=1),
        cutting_force_mean_N_per_m=time_mean(t_r, dt, Fc, STEADY_FROM * t_end),
        thrust_force_mean_N_per_m=time_mean(t_r, dt, Ft, STEADY_FROM * t_end),
        max_plastic_strain=float(np.max(eps_p[:n])),
        max_temperature_K=float(np.max(T[:n])),
        chip_thickness_mm=1e3 * tc,
        shear_angle_from_chip_deg=float(np.degrees(np.arctan2(feed, tc))) if np.isfinite(tc) else float("nan"),
        n_shear_bands=bands["n"],
        band_spacing_mm=bands["spacing_mm"],
        band_spacing_material_mm=bands["spacing_material_mm"],
        band_angle_deg=bands["angle_deg"],
        band_positions_mm=bands["peaks_X_mm"],
        band_angles_deg=bands["angles_deg"],
        band_angles_current_deg=bands["angles_current_deg"],
        strain_along_chip=bands["profile"],
        cut_length_mm=float(info["tool_speed_m_s"] * t * 1e3),
    )


def _metrics(hist, state, setup):
    return cutting_metrics(hist["reaction"], state.x, state.eps_p, state.T, state.t, setup.info, setup.t_end)


def _cell(value, width: int, fmt: str, scale: float = 1.0) -> str:
    """A table cell; '-' for a measure that could not be made (nan in memory, null in summary.json)."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return f"{'-':>{width}s}"
    return f"{value * scale if scale != 1.0 else value:{width}{fmt}}"


def cutting_table(summaries: list) -> str:
    """The runs side by side, with what the paper reports (in words; no forces are printed)."""
    rows = ["Orthogonal cutting, 2D plane strain (Section 3.3). The paper prints no forces; it reports bands from the",
            f"tool tip to the free surface at about {CUTTING_OBSERVED['band_angle_deg']:.0f} deg, and for the deeper "
            f"feed: {CUTTING_OBSERVED['deeper_feed']}.",
            "",
            f"{'method':7s} {'feed':>5s} {'dp[um]':>6s} {'particles':>9s} {'steps':>6s} {'wall[s]':>7s} "
            f"{'ref.upd':>7s} {'Fc[kN/mm]':>9s} {'Ft[kN/mm]':>9s} {'chip[mm]':>8s} {'bands':>5s} "
            f"{'spacing[mm]':>11s} {'angle[deg]':>10s} {'paper':>5s} {'max eps_p':>9s} {'max T[K]':>8s}"]
    for s in summaries:
        m = s.get("metrics") or {}
        feed = s.get("scene_info", {}).get("feed_m", float("nan")) * 1e3
        if not m:
            rows.append(f"{s['method']:7s} {feed:5.2f} (status {s.get('status')}: {s.get('error', '')})")
            continue
        upd = s.get("diagnostics", {}).get("reference_updates")
        mm = lambda key, width, fmt, scale=1.0: _cell(m.get(key), width, fmt, scale)  # noqa: E731
        rows.append(f"{s['method']:7s} {feed:5.2f} {s['dp'] * 1e6:6.2f} {s['n_particles']:9d} {s['n_steps']:6d} "
                    f"{s['wall_time_s']:7.0f} {'-' if upd is None else upd:>7} "
                    f"{mm('cutting_force_mean_N_per_m', 9, '.3f', 1e-6)} "
                    f"{mm('thrust_force_mean_N_per_m', 9, '.3f', 1e-6)} "
                    f"{mm('chip_thickness_mm', 8, '.3f')} {mm('n_shear_bands', 5, 'd')} "
                    f"{mm('band_spacing_mm', 11, '.3f')} "
                    f"{mm('band_angle_deg', 10, '.1f')} {CUTTING_OBSERVED['band_angle_deg']:5.0f} "
                    f"{mm('max_plastic_strain', 9, '.2f')} {mm('max_temperature_K', 8, '.0f')}")
    rows.append(f"(Fc, Ft: cutting and thrust force on the tool per unit thickness, means over the last "
                f"{100 * (1 - STEADY_FROM):.0f} % of the cut; kN per mm = MN/m. "
                "Bands: see refsph.scenes.cutting.shear_bands)")
    return "\n".join(rows)


SCENE = Scene(
    "cutting",
    "orthogonal cutting: AISI 4340 3 x 1 mm, rigid tool 0.5 x 1 mm at 50 m/s (Section 3.3)",
    _default_dp, _build, _record, _metrics, options=CUTTING_OPTIONS, default_dim=2,
    methods=("esph", "tlsph"), report=cutting_table)
