"""Thermomechanical orthogonal cutting after Rodriguez Prieto, Larsson & Afrasiabi (2023): the 18 measured cuts of
their Appendix B (AISI 1045 at 60/120/180 m/min, Ti6Al4V at 20/40/60 m/min; uncut chip thickness 0.10/0.15/0.20 mm),
2D plane strain, TLSPH. (ESPH takes the penalty contact and its friction too, but computes no heat of its
artificial viscosity, ``dissipation_heat``; with ``--option dissipation_heat=false`` its quick cut of case 1 fails
at 0.33 ms of 0.8: the tool particle at the edge's lowest corner, which takes the frictional heat of the contacts
nearest to it and conducts poorly, passes T_limit; with all of that heat in the chip, ``--option chip_fraction=1``,
the paper's code's choice, it runs. Not pursued here: the paper's cuts are run with TLSPH.)

The model, as in their Sections 2.1-2.4 and Tables 1-2, A1-A3 (``refsph.paper_data``), and what refsph chooses:

* **Workpiece** [0, L] x [0, 3 t_u] (L = 3 mm, 3 t_u high: their "at least 3x"), spacing dx = t_u / ``n_tu``
  (5 by default: the time budget of a 2-core machine; their PFEM uses 10-20 across t_u, their SPH does not say),
  held (v = 0, T = 293 K) on its bottom row and its left column (their "fixed surfaces").
* **Material**: modified Johnson-Cook (their Eq. (9): hardening frozen past plastic strain 2, AISI 1045; Ti6Al4V
  has no limit in their table), chi = 0.9 (Table A3), plastic heat through the return map.
* **Tool**: rigid, 10 deg rake, 10 deg clearance, moving at -v_c along x with its cutting edge at the cut depth
  3 t_u - t_u = 2 t_u. Mechanically it is its exact outline (:func:`tool_shape`: the wedge of 70 deg between rake
  and clearance face, ``tool_length`` t_u along the rake face and ``tool_depth`` t_u deep, 5 x 3 by default, every
  corner rounded to the 10 um edge radius) and the **penalty contact** (:mod:`refsph.penalty`: a force while a
  particle's surface is inside the outline, Coulomb friction as a return map with stick and slip); the pinball
  (:mod:`refsph.contact`, the first paper's) is ``--set contact=pinball``. Thermally it is a lattice of particles
  aligned with the rake face (the face the chip slides on is flat, not a staircase) that conducts with its own k
  and the paper's reduced heat capacity c_p = 15 J/(kg K) (Table A2; their reason, after Childs: the tool reaches
  its steady temperature within the short simulated cut instead of seconds), held at 293 K on its top and back
  faces.
* **Friction**: Coulomb, mu(T) = mu0 (1 - T*^q) (their Eqs. (10)-(11), Table 2), return-mapped in the penalty
  contact; frictional heat eta |f_t| |v_t| (the work the return map dissipates) with eta = 1, half into the chip,
  half into the tool (:class:`refsph.thermal.FrictionHeat`, ``chip_fraction``; the paper's SPH code puts it all
  into the workpiece: ``chip_fraction=1``).
* **Heat**: Brookshaw conduction in workpiece and tool (:mod:`refsph.thermal`), convection and radiation on the
  free surface (their Eq. (6); h_c and the emissivity are not printed: :data:`refsph.paper_data.RLA_SURFACE_LOSS`)
  on the particles the ``detector`` marks ('sph' or 'alpha'; found again once a particle has moved 0.1 h). The
  numerical dissipation (artificial viscosity, contact damping) becomes heat where it is taken from the motion
  (``dissipation_heat``, ``Setup.dissipation_heat``), so the heat ledger accounts for the tool's work.
* **Numerics**: Wendland kernel, h = 1.3 dx, leapfrog, Courant 0.3 (their 0.25-0.40) on the smaller of the
  mechanical and thermal steps; artificial viscosity beta1 = beta2 = 0.5 (the first paper's cutting, Table 5).
* **Mass scaling** (the run-time remedy; their GPU code runs at the real speed): the density is multiplied by
  s and the heat capacity divided by s, so rho c_p (hence conduction and the heating per unit plastic work) is
  unchanged and only inertia changes; the wave speed falls by sqrt(s), the explicit step grows by about sqrt(s).
  s is chosen so that s rho v_c^2 = ``inertia_ratio`` A (1 % of the initial yield stress by default), unless
  ``mass_scale`` gives it. The rule keeps the artificial viscosity's stress, ~ beta1 rho c h |grad v| with
  rho c = sqrt(s rho E), the same fraction of A in every case (beta1 sqrt(inertia_ratio E / A) h |grad v| / v_c).
* **Cut length**: ``travel`` t_u (8 by default; the benchmark's sweep: 16 at dx = t_u / 10); steady-state means
  over the last quarter of the cut, with each quantity's drift over that quarter (:func:`drift`).
* **Conductivity** (a sensitivity study, not the paper's model): ``conductivity_factor`` multiplies the workpiece's
  k of Table A1 (a room-temperature value held constant, as the paper does), e.g. 2 for Ti6Al4V, whose conductivity
  about doubles between room temperature and 1000 K.
* **Perturbed runs**: ``jitter`` moves the workpiece's particles at random by up to that many dx (``seed``), for the
  run-to-run scatter.

Measurements (``metrics``; the experiment's values: :func:`refsph.paper_data.rla_cutting_case`):

* ``cutting_force_N_per_m`` / ``passive_force_N_per_m``: the force of the workpiece on the tool along +x
  (against the cut) and +y (pushing the tool off the workpiece), per metre of width, time means over the second
  half of the cut; ``force_ratio`` = Fp / Fc (width-free, compared with the measured ratio);
* ``rake_face_temperature_K``: the mean temperature of the workpiece particles in contact with the rake face
  (centre within one spacing of it, from the cutting edge to the end of contact), time mean over the last quarter
  (``rake_face_temperature_max_K``: the hottest of them);
* ``free_chip_surface_temperature_K``: the mean temperature of the chip's outer layer (in each dx-band along
  the rake face, the chip particles within one spacing of the farthest from the face) between 1 and 3 t_u along
  the rake face, where the chip leaves the contact (what a camera on the chip's back sees), time mean;
* ``chip_thickness_mm``: the median over dx-bands between 0.5 and 2 t_u along the rake face of the distance of
  the farthest chip particle from the face plus dx/2, time mean; ``contact_length_mm``: the distance along the
  rake face from the edge to the last chip particle in contact, time mean;
* the histories (forces, temperatures), the heat balance (``summary.json`` ``heat_balance``) and the tool work.
"""
from __future__ import annotations

import math

import numpy as np

from ..boundaries import Clamp, RigidBody
from ..contact import CoulombFriction
from ..material import ElasticMaterial
from ..paper_data import (AISI1045_RLA, CONTACT_RLA, RLA_SURFACE_LOSS, TI6AL4V_RLA, TOOL_CARBIDE_RLA,
                          rla_cutting_case)
from ..plasticity import JohnsonCook, ModifiedJohnsonCook
from ..penalty import RoundedPolygon
from ..state import concatenate_states, make_state
from ..thermal import Conduction, FrictionHeat, SurfaceLoss
from .base import Numerics, Scene, Setup, parse_bool
from .measure import (N_FORCE_BINS, TOOL_BODY, binned_mean, block_lattice, check_particle_count, jittered,
                      time_mean)

__all__ = ["SCENE", "MATERIALS", "tool_particles", "tool_shape", "mass_scale_for", "rake_frame", "chip_measures",
           "drift", "thermal_cutting_metrics", "thermal_cutting_table", "STEADY_FROM"]

STEADY_FROM = 0.75              # means over the last quarter of the cut
BLOW_UP = 2.0                   # a particle above this multiple of T_melt [K] is a numerical blow-up (Setup.T_limit)
RAKE_DEG, CLEARANCE_DEG, EDGE_RADIUS = 10.0, 10.0, 10e-6
MATERIALS = {"AISI1045": AISI1045_RLA, "Ti6Al4V": TI6AL4V_RLA}
OPTIONS = {
    "case": (0, "row 1-18 of the second paper's Appendix B (sets material, vc, tu); 0: material, vc, tu as given"),
    "material": ("AISI1045", "workpiece: AISI1045 or Ti6Al4V"),
    "vc": (1.0, "cutting speed [m/s] (the paper's m/min / 60)"),
    "tu": (0.1e-3, "uncut chip thickness [m]"),
    "n_tu": (5.0, "particles across the uncut chip thickness (dx = tu / n_tu; --dp overrides)"),
    "travel": (8.0, "length of cut in units of tu"),
    "length": (3.0e-3, "workpiece length [m]"),
    "mass_scale": (0.0, "density factor s (c_p / s keeps rho c_p); 0: chosen from inertia_ratio"),
    "inertia_ratio": (0.01, "with mass_scale 0: s such that s rho vc^2 = inertia_ratio x A"),
    "detector": ("sph", "free-surface detector of the heat losses: sph or alpha"),
    "chip_fraction": (0.5, "share of the frictional heat that goes into the chip (the rest into the tool; the "
                           "paper's SPH code: 1)"),
    "eta": (CONTACT_RLA["friction_work_to_heat"], "fraction of the frictional work that becomes heat (their Eq. (7), "
                                                  "Table A3: 1; 0: friction acts and makes no heat)"),
    "dissipation_heat": (True, "artificial viscosity and contact damping become heat (false: their work is lost)"),
    "tool_length": (5.0, "the tool's rake face, in units of tu"),
    "tool_depth": (3.0, "the tool's depth behind the rake face, in units of tu"),
    "jitter": (0.0, "random displacement of the workpiece's particles, in units of dx (a perturbed run)"),
    "seed": (0, "the random seed of the jitter"),
    "friction": (True, "Coulomb friction mu(T) on the tool (false: frictionless)"),
    "conduction": (True, "heat conduction, frictional heat and losses (false: adiabatic, the first paper's model)"),
    "conductivity_factor": (1.0, "the workpiece's conductivity times this (1: the paper's room-temperature k; a "
                                 "sensitivity study: Ti6Al4V's k about doubles by 1000 K, a carbon steel's falls)"),
}


def mass_scale_for(material: dict, vc: float, inertia_ratio: float) -> float:
    """s with s rho v_c^2 = inertia_ratio A (never below 1): the density factor of the mass scaling."""
    return max(1.0, inertia_ratio * material["A_Pa"] / (material["rho"] * vc * vc))


def tool_particles(dx: float, tu: float, apex, length: float = 5.0, depth: float = 3.0
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The tool's particles (a lattice in rake-face coordinates u along the face from the edge, w into the tool:
    u, w = (i + 1/2) dx, (j + 1/2) dx, 0 < u < ``length`` tu, 0 < w < ``depth`` tu), those inside the 70 deg wedge
    and the rounded edge, placed with the edge at ``apex``; and a mask of the held rows (top and back layers)."""
    g, beta = math.radians(RAKE_DEG), math.radians(90.0 - RAKE_DEG - CLEARANCE_DEG)
    nu_, nw = round(length * tu / dx), round(depth * tu / dx)
    check_particle_count(nu_, nw, dp=dx)
    u, w = [a.ravel() * dx for a in np.meshgrid(np.arange(nu_) + 0.5, np.arange(nw) + 0.5, indexing="ij")]
    keep = np.arctan2(w, u) <= beta
    rc = EDGE_RADIUS / math.sin(beta / 2)                 # the edge circle's centre, on the bisector
    cu, cw = rc * math.cos(beta / 2), rc * math.sin(beta / 2)
    tangent = EDGE_RADIUS / math.tan(beta / 2)             # tangent points at this distance from the apex
    corner = (u < tangent) & (u * math.cos(beta) + w * math.sin(beta) < tangent)
    keep &= ~(corner & ((u - cu) ** 2 + (w - cw) ** 2 > EDGE_RADIUS ** 2))
    u, w = u[keep], w[keep]
    held = (u > (nu_ - 1) * dx) | (w > (nw - 1) * dx)
    x = apex[0] + u * math.sin(g) + w * math.cos(g)
    y = apex[1] + u * math.cos(g) - w * math.sin(g)
    return np.stack([x, y], axis=1), held


def tool_shape(tu: float, apex, centroid, length: float = 5.0, depth: float = 3.0,
               radius: float = EDGE_RADIUS) -> RoundedPolygon:
    """The tool's exact outline for the penalty contact (``Numerics.contact = 'penalty'``): in the rake-face
    coordinates of :func:`tool_particles` the polygon (0, 0), (L, 0), (L, D), (D / tan(beta), D), L = ``length``
    tu, D = ``depth`` tu (rake face w = 0, flank at the wedge angle beta, the held top and back faces), every
    corner rounded by the edge radius ``radius`` (the paper's cutting edge: 10 um; the far corners alike), placed
    with the edge at ``apex``; ``centroid``: that of the tool's particles."""
    if not 0.0 < radius < tu:
        raise ValueError(f"the tool's edge radius must be positive and below t_u = {tu!r} m, got {radius!r}")
    g, beta = math.radians(RAKE_DEG), math.radians(90.0 - RAKE_DEG - CLEARANCE_DEG)
    L, D = length * tu, depth * tu
    uw = np.array([[0.0, 0.0], [L, 0.0], [L, D], [D / math.tan(beta), D]])
    x = apex[0] + uw[:, 0] * math.sin(g) + uw[:, 1] * math.cos(g)
    y = apex[1] + uw[:, 0] * math.cos(g) - uw[:, 1] * math.sin(g)
    return RoundedPolygon.from_polygon(np.stack([x, y], axis=1), radius, centroid)


def _case_values(case, material, vc, tu):
    if not (np.isfinite(case) and float(case) == int(case)) or not 0 <= int(case) <= 18:
        raise ValueError(f"option case must be a whole number 0-18, got {case!r}")
    if int(case) != 0:
        given = [f"{k} = {v!r}" for k, v, default in (("material", material, OPTIONS["material"][0]),
                                                      ("vc", vc, OPTIONS["vc"][0]), ("tu", tu, OPTIONS["tu"][0]))
                 if v != default]
        if given:
            raise ValueError(f"option case {int(case)} sets material, vc and tu from the paper's table; give either "
                             f"the case or {', '.join(given)} (case 0)")
    if int(case) == 0:
        if material not in MATERIALS:
            raise ValueError(f"material must be one of {', '.join(MATERIALS)}, got {material!r}")
        return None, material, float(vc), float(tu)
    row = rla_cutting_case(int(case))
    return row, row["material"], row["vc_m_per_min"] / 60.0, row["tu_mm"] * 1e-3


def _strength(mat: dict, s: float) -> JohnsonCook:
    jc = dict(A=mat["A_Pa"], B=mat["B_Pa"], n=mat["n"], C=mat["C"], m=mat["m"], eps_dot_0=mat["eps_dot_0"],
              T_room=CONTACT_RLA["T_ref_K"], T_melt=mat["T_melt_K"], cp=mat["cp_J_kgK"] / s,
              chi=CONTACT_RLA["plastic_work_to_heat"])
    if "hardening_saturation_strain" in mat:
        return ModifiedJohnsonCook(**jc, hardening_saturation_strain=mat["hardening_saturation_strain"])
    return JohnsonCook(**jc)


def _default_dp(dim, quick):
    return None                                       # from the options: tu / n_tu


def _build(dim, dp, quick, *, case, material, vc, tu, n_tu, travel, length, mass_scale, inertia_ratio, detector,
           chip_fraction, eta, friction, conduction, dissipation_heat, tool_length, tool_depth, jitter, seed,
           conductivity_factor):
    if dim != 2:
        raise ValueError("the thermal cutting scene is 2D plane strain")
    row, material, vc, tu = _case_values(case, material, vc, tu)
    for name, v in (("vc", vc), ("tu", tu), ("travel", travel), ("length", length), ("n_tu", n_tu),
                    ("inertia_ratio", inertia_ratio), ("tool_length", tool_length), ("tool_depth", tool_depth),
                    ("conductivity_factor", conductivity_factor)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"option {name} must be positive, got {v!r}")
    conducting = parse_bool(conduction, "option conduction")
    if float(conductivity_factor) != 1.0 and not conducting:
        raise ValueError("option conductivity_factor acts on the heat conduction; with conduction=false it would do "
                         "nothing")
    if not (np.isfinite(mass_scale) and mass_scale >= 0):
        raise ValueError(f"option mass_scale must be >= 0 (0: chosen from inertia_ratio), got {mass_scale!r}")
    mat = MATERIALS[material]
    dx = float(dp) if dp is not None else tu / (n_tu * (0.8 if quick else 1.0))
    if tu < 2 * dx or travel * tu > 0.8 * length:
        raise ValueError(f"need tu >= 2 dx and a cut (travel x tu) within 80 % of the workpiece length; got "
                         f"tu = {tu!r} m, dx = {dx!r} m, travel = {travel!r} tu, length = {length!r} m")
    s = float(mass_scale) if mass_scale > 0 else mass_scale_for(mat, vc, inertia_ratio * (4.0 if quick else 1.0))
    H = 3.0 * tu
    nx, ny = round(length / dx), round(H / dx)
    xw, i, j = block_lattice(nx, ny, dx, dx)
    held = np.flatnonzero((i == 0) | (j == 0))
    xw = jittered(xw, jitter, dx, seed)               # a perturbed run (the run-to-run scatter)
    y0 = ny * dx - tu
    xt, tool_held = tool_particles(dx, tu, (nx * dx, y0), tool_length, tool_depth)
    T0 = CONTACT_RLA["T_ref_K"]
    work = make_state(xw, [0.0, 0.0], s * mat["rho"], dx * dx, T0=T0)
    tool_mat = TOOL_CARBIDE_RLA
    tool = make_state(xt, [-vc, 0.0], tool_mat["rho"], dx * dx, T0=T0, body=np.full(len(xt), TOOL_BODY))
    numerics = Numerics(h_over_dp=1.3, kernel="wendland", integrator="leapfrog", courant=0.3, beta1=0.5, beta2=0.5,
                        contact="penalty")
    thermal = friction_heat = None
    heat_of_dissipation = False
    if conducting:
        loss = SurfaceLoss(**RLA_SURFACE_LOSS, T_ambient=T0, detector=detector, alpha_radius=1.3 * dx, refresh=0.1)
        thermal = Conduction(k=mat["k_W_mK"] * float(conductivity_factor), courant=0.3,
                             tools={TOOL_BODY: (tool_mat["k_W_mK"], tool_mat["cp_J_kgK"])},
                             fixed=tuple(int(k) for k in np.concatenate([held, work.n + np.flatnonzero(tool_held)])),
                             T_fixed=T0, loss=loss)
        friction_heat = FrictionHeat(eta=float(eta), chip_fraction=float(chip_fraction))
        heat_of_dissipation = parse_bool(dissipation_heat, "option dissipation_heat")
    mu = CoulombFriction(mu0=mat["mu0"], q=mat["q_friction"], T_room=T0, T_melt=mat["T_melt_K"])
    info = dict(case=int(case), material=material, vc_m_s=vc, tu_m=tu, dx=dx, length_m=nx * dx, height_m=ny * dx,
                y0=y0, n_work=work.n, n_tool=tool.n, travel_m=travel * tu, mass_scale=s,
                inertia_ratio=s * mat["rho"] * vc * vc / mat["A_Pa"], rake_deg=RAKE_DEG, clearance_deg=CLEARANCE_DEG,
                edge_radius_m=EDGE_RADIUS, apex0=[nx * dx, y0], detector=detector, chip_fraction=float(chip_fraction),
                eta=float(eta), A_Pa=mat["A_Pa"], tool_length_m=tool_length * tu, tool_depth_m=tool_depth * tu,
                jitter=float(jitter), seed=int(seed), conductivity_factor=float(conductivity_factor), measured=row)
    body = RigidBody("tool", TOOL_BODY, (-vc, 0.0),
                     shape=tool_shape(tu, (nx * dx, y0), xt.mean(axis=0), tool_length, tool_depth))
    return Setup(state=concatenate_states(work, tool), material=ElasticMaterial(s * mat["rho"], mat["E_Pa"], mat["nu"]),
                 dp=dx, numerics=numerics, t_end=travel * tu / vc, n_snapshots=8, info=info,
                 strength=_strength(mat, s), rigid=(body,),
                 clamps=(Clamp("held", held),), friction=mu if parse_bool(friction, "option friction") else None,
                 thermal=thermal, friction_heat=friction_heat, dissipation_heat=heat_of_dissipation,
                 T_limit=BLOW_UP * mat["T_melt_K"])


def rake_frame(x: np.ndarray, t: float, info: dict) -> tuple[np.ndarray, np.ndarray]:
    """(u, n) of points x at time t: u along the rake face from the cutting edge, n the distance in front of the
    face (n > 0 in the chip, n < 0 inside the tool)."""
    g = math.radians(info["rake_deg"])
    dx_ = x[:, 0] - (info["apex0"][0] - info["vc_m_s"] * t)
    dy_ = x[:, 1] - info["apex0"][1]
    return dx_ * math.sin(g) + dy_ * math.cos(g), -(dx_ * math.cos(g) - dy_ * math.sin(g))


def chip_measures(x: np.ndarray, X0: np.ndarray, T: np.ndarray, t: float, info: dict) -> dict:
    """The rake-face, chip and contact measures of one workpiece state (module text): current positions x,
    *initial* positions X0 (the chip is the material that started above the cut line; TLSPH's reference positions
    X move with its reference updates, so they do not say that) and temperatures T of the workpiece rows."""
    dx, tu = info["dx"], info["tu_m"]
    u, n = rake_frame(x, t, info)
    chip = X0[:, 1] > info["y0"]
    touch = (np.abs(n) < dx) & (u >= 0.0)                   # on the rake face, whatever material it is
    out = dict(T_RF=np.nan, T_RF_max=np.nan, T_FCS=np.nan, chip_mm=np.nan, contact_mm=np.nan)
    if np.any(touch):
        out.update(T_RF=float(T[touch].mean()), T_RF_max=float(T[touch].max()), contact_mm=1e3 * float(u[touch].max()))
    bands = np.floor(u / dx).astype(int)
    outer, thick = [], []
    for b in range(int(0.5 * tu / dx), int(3 * tu / dx)):
        sel = chip & (bands == b) & (n > -dx)
        if np.count_nonzero(sel) < 2:
            continue
        far = n[sel].max()
        if b * dx >= tu:                                  # the free chip surface: 1-3 tu along the face
            outer.append(T[sel][n[sel] > far - dx])
        if b * dx <= 2 * tu:                              # the thickness: 0.5-2 tu along the face
            thick.append(far + 0.5 * dx)
    if outer:
        out["T_FCS"] = float(np.concatenate(outer).mean())
    if thick:
        out["chip_mm"] = 1e3 * float(np.median(thick))
    return out


def _record(state, setup):
    n = setup.info["n_work"]
    m = chip_measures(state.x[:n], setup.state.x[:n], state.T[:n], state.t, setup.info)
    return dict(t=state.t, max_T=float(np.max(state.T[:n])), max_eps_p=float(np.max(state.eps_p[:n])), **m)


def _steady(hist: dict, key: str, t_from: float) -> float:
    t, v = np.asarray(hist["t"]), np.asarray(hist[key], dtype=float)
    sel = (t >= t_from) & np.isfinite(v)
    return float(v[sel].mean()) if sel.any() else float("nan")


def drift(t, v, t_from: float, t_end: float, weights=None) -> float:
    """How much v(t) moves over [t_from, t_end]: the slope of the least-squares line through the samples with
    t >= t_from, times the window's length (NaN with fewer than 3 finite samples)."""
    t, v = np.asarray(t, dtype=float), np.asarray(v, dtype=float)
    sel = (t >= t_from) & np.isfinite(v)
    if np.count_nonzero(sel) < 3:
        return float("nan")
    w = None if weights is None else np.sqrt(np.asarray(weights, dtype=float)[sel])
    return float(np.polyfit(t[sel], v[sel], 1, w=w)[0] * (t_end - t_from))


def thermal_cutting_metrics(hist: dict, info: dict, t_end: float) -> dict:
    """The ``metrics`` of a run from its history (the recorded measures and the tool's reaction): means over the
    last quarter of the cut (``STEADY_FROM``) and the drift of each over that quarter (:func:`drift`); and, only
    where a particle got hotter than ``BLOW_UP`` times the melting temperature, ``blow_up``: when, and that the
    numbers after it are not to be trusted (no material model of refsph means anything there; such a particle is
    a local numerical instability, e.g. two particles of the chip's free surface closing to half a spacing and
    oscillating against each other, their artificial viscosity heating them)."""
    r = hist["reaction"]
    t_r, dt, F = np.asarray(r["t"]), np.asarray(r["dt"]), np.asarray(r["tool"])
    t_from = STEADY_FROM * t_end
    Fc, Fp = time_mean(t_r, dt, F[:, 0], t_from), time_mean(t_r, dt, F[:, 1], t_from)
    drifts = dict(cutting_force_N_per_m=drift(t_r, F[:, 0], t_from, t_end, dt),
                  passive_force_N_per_m=drift(t_r, F[:, 1], t_from, t_end, dt))
    for key, name in (("T_RF", "rake_face_temperature_K"), ("T_RF_max", "rake_face_temperature_max_K"),
                      ("T_FCS", "free_chip_surface_temperature_K"), ("chip_mm", "chip_thickness_mm"),
                      ("contact_mm", "contact_length_mm")):
        drifts[name] = drift(hist["t"], hist[key], t_from, t_end)
    nb = min(N_FORCE_BINS, max(1, len(t_r)))
    tb, cb = binned_mean(t_r, dt, F[:, 0], t_end, nb)
    _, pb = binned_mean(t_r, dt, F[:, 1], t_end, nb)
    out = dict(
        cutting_force_N_per_m=Fc, passive_force_N_per_m=Fp, force_ratio=Fp / Fc if Fc else float("nan"),
        rake_face_temperature_K=_steady(hist, "T_RF", t_from),
        rake_face_temperature_max_K=_steady(hist, "T_RF_max", t_from),
        free_chip_surface_temperature_K=_steady(hist, "T_FCS", t_from),
        chip_thickness_mm=_steady(hist, "chip_mm", t_from), contact_length_mm=_steady(hist, "contact_mm", t_from),
        max_temperature_K=float(np.max(hist["max_T"])), max_plastic_strain=float(np.max(hist["max_eps_p"])),
        tool_work_J_per_m=float(np.sum(F[:, 0] * dt) * info["vc_m_s"]),
        cut_length_mm=1e3 * info["vc_m_s"] * float(hist["t"][-1]),
        mass_scale=info["mass_scale"], inertia_ratio=info["inertia_ratio"], drift_last_quarter=drifts,
        cutting_force_history=np.stack([tb, cb], axis=1), passive_force_history=np.stack([tb, pb], axis=1),
        temperature_history=np.stack([np.asarray(hist["t"]), np.asarray(hist["T_RF"], dtype=float),
                                      np.asarray(hist["T_FCS"], dtype=float)], axis=1))
    blow_up = np.flatnonzero(np.asarray(hist["max_T"]) > BLOW_UP * MATERIALS[info["material"]]["T_melt_K"])
    if len(blow_up):                                 # only then: a run that stayed sane keeps its metrics as they were
        k = int(blow_up[0])
        out["blow_up"] = (f"a particle at {hist['max_T'][k]:.0f} K at t = {hist['t'][k]:.4e} s, over {BLOW_UP:g} times "
                          f"the melting temperature: a local numerical blow-up; the temperatures after it (and the "
                          f"forces, through the softening) are not the material's")
    row = info.get("measured")
    if row:
        out["measured"] = dict(Fc_N=row["Fc_exp_N"], Fp_N=row["Fp_exp_N"], T_RF_K=row["TRF_exp_K"],
                               T_FCS_K=row["TFCS_exp_K"], force_ratio=row["Fp_exp_N"] / row["Fc_exp_N"])
        out["width_matching_Fc_mm"] = 1e3 * row["Fc_exp_N"] / Fc if Fc else float("nan")
    return out


def _metrics(hist, state, setup):
    return thermal_cutting_metrics(hist, setup.info, setup.t_end)


def _matching_case(info: dict) -> int | None:
    """The paper's case (1-18) with a case-0 run's material, v_c and t_u, or None."""
    for n in range(1, 19):
        row = rla_cutting_case(n)
        if (row["material"] == info.get("material") and abs(row["vc_m_per_min"] / 60.0 - info.get("vc_m_s", -1)) < 1e-9
                and abs(row["tu_mm"] * 1e-3 - info.get("tu_m", -1)) < 1e-12):
            return n
    return None


def thermal_cutting_table(summaries: list) -> str:
    """The runs side by side with the measurement of their case (forces per mm of width; the measured forces'
    width is not stated, so their ratio is what compares). A case-0 run at the conditions of one of the paper's
    cases (the SPH scene's defaults are case 1's) shows that case's measurement, its case marked '*'. The spacing
    and the length of cut are shown: the SPH scene and the PFEM cut have their own defaults (``--method both``)."""
    rows = [f"{'case':>4s} {'method':6s} {'mat':8s} {'vc':>5s} {'tu':>5s} {'status':8s} {'Fc[N/mm]':>8s} "
            f"{'Fp[N/mm]':>8s} {'Fp/Fc':>5s} {'meas':>5s} {'T_RF':>5s} {'meas':>5s} {'T_FCS':>5s} {'meas':>5s} "
            f"{'chip':>5s} {'l_c':>5s} {'dx[um]':>6s} {'cut':>5s} {'wall[s]':>7s}"]
    marked = False
    for s in summaries:
        i, m = s.get("scene_info", {}), s.get("metrics") or {}
        meas, case = m.get("measured") or {}, f"{i.get('case', 0):4d}"
        n = _matching_case(i) if not meas and i.get("case", 0) == 0 else None
        if n is not None:
            row = rla_cutting_case(n)
            meas = dict(force_ratio=row["Fp_exp_N"] / row["Fc_exp_N"], T_RF_K=row["TRF_exp_K"],
                        T_FCS_K=row["TFCS_exp_K"])
            case, marked = f"{n:3d}*", True
        f = lambda v, w, p: f"{v:{w}.{p}f}" if isinstance(v, (int, float)) and math.isfinite(v) else f"{'-':>{w}s}"  # noqa: E731
        rows.append(f"{case} {s.get('method', '?'):6s} {i.get('material', '?'):8s} {60 * i.get('vc_m_s', 0):5.0f} "
                    f"{1e3 * i.get('tu_m', 0):5.2f} {s.get('status', '?'):8s} "
                    f"{f(1e-3 * m.get('cutting_force_N_per_m', math.nan), 8, 1)} "
                    f"{f(1e-3 * m.get('passive_force_N_per_m', math.nan), 8, 1)} {f(m.get('force_ratio'), 5, 2)} "
                    f"{f(meas.get('force_ratio'), 5, 2)} {f(m.get('rake_face_temperature_K'), 5, 0)} "
                    f"{f(meas.get('T_RF_K'), 5, 0)} {f(m.get('free_chip_surface_temperature_K'), 5, 0)} "
                    f"{f(meas.get('T_FCS_K'), 5, 0)} {f(m.get('chip_thickness_mm'), 5, 3)} "
                    f"{f(m.get('contact_length_mm'), 5, 3)} {f(1e6 * (s.get('dp') or math.nan), 6, 1)} "
                    f"{f(m.get('cut_length_mm'), 5, 2)} {f(s.get('wall_time_s'), 7, 0)}")
    star = "; *: case 0 at that case's material, vc and tu, its measurement shown" if marked else ""
    rows.append("(vc in m/min, tu, chip thickness, contact length l_c and the length of cut in mm, temperatures in "
                "K; means over the last quarter of the cut; each method at its own defaults unless the options say"
                f" otherwise: compare runs at the same dx and cut{star})")
    return "\n".join(rows)


SCENE = Scene(
    "thermal_cutting",
    "thermomechanical orthogonal cutting (Rodriguez Prieto, Larsson & Afrasiabi 2023): AISI 1045 / Ti6Al4V, "
    "friction mu(T), conduction into the tool; --case 1..18",
    _default_dp, _build, _record, _metrics, options=OPTIONS, default_dim=2, methods=("tlsph",),
    report=thermal_cutting_table)
