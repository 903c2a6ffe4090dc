"""Taylor impact (Section 3.1, Tables 1-2): a 4340 steel cylinder, 37.97 mm long and 7.595 mm across, hits a
rigid frictionless wall at 181 m/s.

Model (what the scene needs, nothing more):

* **3D**: a quarter of the cylinder, x >= 0, y >= 0, axis along z, the wall at z = 0. The planes x = 0 and
  y = 0 are symmetry planes (mirror ghosts, :class:`~refsph.boundaries.MirrorPlanes`); the wall is a
  unilateral kinematic constraint (:class:`~refsph.boundaries.RigidWall`). The particles sit on rings: ring k
  at radius (k + 1/2) dr, dr = R / round(R / dp), with round((pi/2) r_k / dr) particles spread evenly over
  the quarter circle, and layers dz = L / round(L / dp) apart; each carries the exact volume of its cell
  ((pi/2) r_k dr / n_k * dz), so the body has the cylinder's mass and its outer ring sits half a spacing
  inside the true surface. (A cubic lattice cut to a circle has a staircase surface whose outermost centres
  lie up to a whole spacing from the axis-aligned ones: the measured diameter would start 5 % too large.)
* **2D** (plane strain): the section through the axis, a slab 7.595 mm wide, infinitely long out of plane;
  half of it with the symmetry plane x = 0. It is the quick teaching case; it cannot match the experiment,
  because a slab can only spread sideways in one direction (the mushroom of a cylinder spreads in two), so it
  is stiffer against shortening and its "diameter" is a width.
* ``symmetry=False`` models the whole body (a check of the symmetry planes).

Numerics: Table 2 (h = 1.5 dp, beta1 = beta2 = 1.5, ESPH gamma = 0.3), Courant 0.3, t_end = 80 us; the ESPH
Verlet skin is 0.3 h (the default 0.1 h would rebuild the list every few steps at 181 m/s).

Measurements (stated in chapter 06): length L = max z + dz/2 - (min z - dz/2), from particle centres plus
half a spacing at each end; diameter D = 2 (max r + dr/2), r = sqrt(x^2 + y^2) (2D: |x|), over all particles
(the widest point is the foot of the mushroom). At t = 0 these give exactly 37.97 and 7.595 mm.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..boundaries import MirrorPlanes, RigidWall
from ..material import ElasticMaterial
from ..paper_data import TAYLOR_GEOMETRY, TAYLOR_RESULTS, TAYLOR_TABLE1, TAYLOR_TABLE2
from ..plasticity import JohnsonCook
from ..state import make_state
from .base import Numerics, Scene, Setup
from .measure import check_particle_count, kinetic_energy

__all__ = ["SCENE", "comparison_table", "taylor_material", "taylor_johnson_cook", "taylor_particles",
           "lattice_cylinder", "bar_length",
           "bar_diameter"]

REST_WINDOW = 30e-6      # s: the final length is the mean over this last stretch (two free-ringing periods)

TAYLOR_OPTIONS = {
    "T_melt": (TAYLOR_TABLE1["T_melt_K"], "melting temperature [K] (Table 1 prints 1293; 1793 is usual for 4340)"),
    "symmetry": (True, "use the symmetry planes (3D: quarter model, 2D: half model); False: whole body"),
    "eps_dot_0": (1.0, "Johnson-Cook reference strain rate [1/s] (not printed in Table 1; Johnson & Cook: 1)"),
    "heating": (True, "plastic work heats the bar and softens it (Eq. (28)); False: isothermal, as LAMMPS-SMD"),
    "speed_factor": (1.0, "impact speed / the experiment's 181 m/s (2: the hard case of chapter 10)"),
    "layout": ("rings", "3D particle layout: 'rings' (exact volumes, see above) or 'lattice' (a cubic lattice cut to "
                        "the cylinder, as LAMMPS's create_atoms makes it; dr = dz = dp)"),
}


def taylor_material() -> ElasticMaterial:
    """Table 1: rho = 7830 kg/m^3, mu = 82.9 GPa, K = 169.1 GPa."""
    t = TAYLOR_TABLE1
    return ElasticMaterial.from_shear_bulk(t["rho"], t["shear_modulus_Pa"], t["bulk_modulus_Pa"])


def taylor_johnson_cook(T_melt: float, eps_dot_0: float) -> JohnsonCook:
    """Table 1 Johnson-Cook constants with the given T_melt and reference rate; chi = 0.9 (Eq. (28))."""
    t = TAYLOR_TABLE1
    return JohnsonCook(A=t["A_Pa"], B=t["B_Pa"], n=t["n"], C=t["C"], m=t["m"], eps_dot_0=float(eps_dot_0),
                       T_room=t["T_room_K"], T_melt=float(T_melt), cp=t["cp_J_kgK"], chi=t["taylor_quinney"])


def taylor_particles(dim: int, dp: float, symmetry: bool, length: float, diameter: float):
    """Particle centres, volumes and the (lateral, axial) spacings (dr, dz) of the bar standing on z = 0."""
    R = 0.5 * diameter
    nr = max(1, int(round(R / dp)))
    nz = max(1, int(round(length / dp)))
    dr, dz = R / nr, length / nz
    check_particle_count(2 * nr, nz, *((2 * nr,) if dim == 3 else ()), dp=dp)
    zs = (np.arange(nz) + 0.5) * dz
    if dim == 2:
        xs = (np.arange(nr) + 0.5) * dr
        if not symmetry:
            xs = np.concatenate([-xs[::-1], xs])
        X, Z = np.meshgrid(xs, zs, indexing="ij")
        pts = np.stack([X.ravel(), Z.ravel()], axis=1)
        vol = np.full(len(pts), dr * dz)
        return pts, vol, dr, dz
    sector = 0.5 * np.pi if symmetry else 2.0 * np.pi
    xy, area = [], []
    for k in range(nr):
        r = (k + 0.5) * dr
        nk = max(1, int(round(sector * r / dr)))
        th = (np.arange(nk) + 0.5) * sector / nk
        xy.append(np.stack([r * np.cos(th), r * np.sin(th)], axis=1))
        area.append(np.full(nk, sector * r * dr / nk))
    xy, area = np.concatenate(xy), np.concatenate(area)
    pts = np.concatenate([np.column_stack([xy, np.full(len(xy), z)]) for z in zs])
    vol = np.tile(area, nz) * dz
    return pts, vol, dr, dz


def lattice_cylinder(dp: float, symmetry: bool, length: float, diameter: float):
    """The cubic lattice of spacing dp (cell centres (i + 1/2) dp, the axis through a cell corner) cut to the
    cylinder r <= R, 0 <= z <= L, and each particle's volume dp^3; the quarter x, y > 0 with ``symmetry``. It is
    the particle set of LAMMPS's ``lattice sc dp origin 0.5 0.5 0.5`` + ``create_atoms`` in a cylinder region, in
    LAMMPS's order (x fastest, then y, then z); its surface is a staircase (see the module text)."""
    R = 0.5 * diameter
    n = int(np.ceil(R / dp))
    check_particle_count(2 * n, 2 * n, np.ceil(length / dp), dp=dp)
    a = (np.arange(-n, n) + 0.5) * dp
    if symmetry:
        a = a[a > 0]
    zs = (np.arange(int(np.ceil(length / dp))) + 0.5) * dp
    zs = zs[zs <= length]
    Z, Y, X = np.meshgrid(zs, a, a, indexing="ij")
    pts = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
    pts = pts[np.hypot(pts[:, 0], pts[:, 1]) <= R]
    return pts, np.full(len(pts), dp**3), dp, dp


def _default_dp(dim, quick):
    """2D: 0.5 mm quick, 0.25 mm otherwise. 3D: 1.0 mm quick, 0.75 mm otherwise -- the plain
    ``refsph run taylor`` (both methods in about a minute); the paper's 0.5 mm is ``--dp 0.5e-3``
    (about 3 minutes per method)."""
    if dim == 2:
        return 0.5e-3 if quick else 0.25e-3
    return 1.0e-3 if quick else 0.75e-3


def _build(dim, dp, quick, *, T_melt, symmetry, eps_dot_0, heating, layout, speed_factor):
    g = TAYLOR_GEOMETRY
    mat = taylor_material()
    jc = dataclasses.replace(taylor_johnson_cook(T_melt, eps_dot_0), heating=bool(heating))
    if not isinstance(symmetry, (bool, np.bool_)):         # strings are converted by Scene.setup
        raise ValueError(f"option symmetry must be True or False, got {symmetry!r}")
    symmetry = bool(symmetry)
    if not (np.isfinite(T_melt) and T_melt > 293.0):
        raise ValueError(f"option T_melt must exceed the room temperature 293 K, got {T_melt!r}")
    if layout not in ("rings", "lattice") or (layout == "lattice" and dim != 3):
        raise ValueError(f"option layout must be 'rings' or (3D only) 'lattice', got {layout!r}")
    make = lattice_cylinder if layout == "lattice" else lambda *a: taylor_particles(dim, *a)
    x, vol, dr, dz = make(dp, symmetry, g["length_m"], g["diameter_m"])
    v = np.zeros_like(x)
    if not (np.isfinite(speed_factor) and speed_factor > 0):
        raise ValueError(f"option speed_factor must be positive, got {speed_factor!r}")
    v0 = float(speed_factor) * g["impact_velocity_m_s"]
    v[:, -1] = -v0
    state = make_state(x, v, mat.rho0, vol, T0=jc.T_room)
    t2 = TAYLOR_TABLE2
    numerics = Numerics(h_over_dp=t2["smoothing_length_m"] / t2["particle_spacing_m"], beta1=t2["beta1"],
                        beta2=t2["beta2"], gamma=t2["artificial_pressure_gamma_esph"], skin_factor=0.3)
    mirror = MirrorPlanes(tuple(range(dim - 1))) if symmetry else None
    wall = RigidWall(axis=dim - 1, position=0.0, gap=0.5 * dz)
    t_end = 80e-6
    fraction_inv = (4.0 if dim == 3 else 2.0) if symmetry else 1.0     # whole body / model
    m_total = float(np.sum(state.m)) * fraction_inv
    return Setup(state=state, material=mat, dp=dp, numerics=numerics, t_end=t_end, n_snapshots=10,
                 strength=jc, mirror=mirror, walls=(wall,), snapshot_times=(15e-6, 30e-6),
                 info=dict(dr=dr, dz=dz, symmetry=symmetry, length0=g["length_m"], diameter0=g["diameter_m"],
                           v0=v0, mass_per_model=float(np.sum(state.m)),
                           mass_full_body=m_total, model_fraction_inverse=fraction_inv,
                           model=("quarter" if dim == 3 else "half") if symmetry else "whole", layout=layout,
                           reference=TAYLOR_RESULTS))


def bar_length(x: np.ndarray, dz: float) -> float:
    """L = max z + dz/2 - (min z - dz/2) (axis = last coordinate)."""
    z = x[:, -1]
    return float(z.max() - z.min() + dz)


def bar_diameter(x: np.ndarray, dr: float) -> float:
    """D = 2 (max r + dr/2), r the distance from the axis (2D: |x|)."""
    r = np.sqrt(np.sum(x[:, :-1] ** 2, axis=1))
    return float(2.0 * (r.max() + 0.5 * dr))


def _record(state, setup):
    info = setup.info
    return dict(t=state.t, length=bar_length(state.x, info["dz"]), diameter=bar_diameter(state.x, info["dr"]),
                E_kin=kinetic_energy(state),
                plastic_work=float(np.sum(state.W_p * state.m / state.rho)),
                max_eps_p=float(state.eps_p.max()), max_T=float(state.T.max()))


def _metrics(hist, state, setup):
    """Final length and diameter, histories, peaks, and when the bar came to rest.

    After the plastic flow stops the bar leaves the wall and rings in its free axial mode (period
    2 L / c_bar, about 13 us), so its length oscillates by a few hundredths of a millimetre. The final length is
    the mean over the last ``REST_WINDOW`` (30 us, two periods), the oscillation is reported beside it. The rest
    time is when the plastic work of the whole bar reaches 99.5 % of its final value (the permanent shape is set);
    a run counts as ``settled`` if it went on for at least ``REST_WINDOW`` after that; a shorter run (e.g.
    ``--t-end 10e-6``) reports the length and diameter of its last instant and ``settled: false``, and the
    comparison table marks them. ``plastic_work_whole_body`` is the plastic work of the whole
    cylinder (the model's times 4 or 2) in J (2D: J per metre of thickness); ``history['plastic_work']`` is
    the model's."""
    t = np.asarray(hist["t"])
    L = np.asarray(hist["length"])
    D = np.asarray(hist["diameter"])
    Wp = np.asarray(hist["plastic_work"])
    done = np.flatnonzero(Wp >= 0.995 * Wp[-1])
    t_rest = float(t[done[0]]) if Wp[-1] > 0 else float("nan")
    settled = bool(np.isfinite(t_rest) and t[-1] - t_rest >= REST_WINDOW)
    # averaged over the last REST_WINDOW only once the bar is at rest; a shorter run reports its last values
    win = (t >= t[-1] - REST_WINDOW) if settled else (t == t[-1])
    E0 = float(hist["E_kin"][0])
    return dict(
        final_length_mm=1e3 * float(np.mean(L[win])),
        final_diameter_mm=1e3 * float(np.mean(D[win])),
        settled=settled,
        length_oscillation_mm=1e3 * 0.5 * float(L[win].max() - L[win].min()),
        length_history=np.stack([t, L], axis=1),
        diameter_history=np.stack([t, D], axis=1),
        max_plastic_strain=float(state.eps_p.max()),
        max_temperature_K=float(state.T.max()),
        rest_time_s=t_rest,
        end_time_s=float(t[-1]),
        plastic_work_whole_body=float(Wp[-1]) * setup.info["model_fraction_inverse"],
        kinetic_energy_final_over_initial=float(hist["E_kin"][-1]) / E0,
        T_melt_K=setup.strength.T_melt,
        model=setup.info["model"],
        reference=setup.info["reference"],
    )


def comparison_table(summaries: list) -> str:
    """Final length and diameter of each run next to the experiment, LS-DYNA and the paper's SPH."""
    ref = TAYLOR_RESULTS
    cols = [("experiment", "experiment"), ("LS-DYNA", "ls_dyna"), ("paper ESPH", "paper_esph"),
            ("paper TLSPH", "paper_tlsph")]
    runs = [s for s in summaries if s.get("status") == "ok" and s.get("metrics")]
    head = f"{'':22s}" + "".join(f"{c:>12s}" for c, _ in cols) + "".join(
        f"{'refsph ' + s['method'].upper():>14s}" for s in runs)
    lines = [head]
    for key, label in (("final_length_mm", "final length [mm]"), ("final_diameter_mm", "final diameter [mm]")):
        row = f"{label:22s}" + "".join(f"{ref[key][k]:12.2f}" for _, k in cols)
        row += "".join(f"{s['metrics'][key]:13.2f}{' ' if s['metrics'].get('settled', True) else '*'}" for s in runs)
        lines.append(row)
        exp = ref[key]["experiment"]
        row = f"{'  vs experiment':22s}" + "".join(f"{100 * (ref[key][k] - exp) / exp:+11.1f}%" for _, k in cols)
        row += "".join(f"{100 * (s['metrics'][key] - exp) / exp:+13.1f}%" for s in runs)
        lines.append(row)
    for s in runs:
        m = s["metrics"]
        lines.append(f"refsph {s['method'].upper()}: {s['dim']}D {m['model']} model, dp = {1e3 * s['dp']:.3g} mm, "
                     f"{s['n_particles']} particles, {s['n_steps']} steps ({s['dt_mode']} dt), "
                     f"{s['wall_time_s']:.0f} s; max eps_p = {m['max_plastic_strain']:.2f}, "
                     f"max T = {m['max_temperature_K']:.0f} K, at rest from {1e6 * m['rest_time_s']:.0f} us "
                     f"(T_melt = {m['T_melt_K']:.0f} K)")
    if any(not s["metrics"].get("settled", True) for s in runs):
        lines.append("* not at rest: the run ended before the plastic flow had stopped for 30 us (use the default "
                     "t_end)")
    lines.append("targets: length within 2 %, diameter within 5 % of the experiment at the paper's dp = 0.5 mm "
                 "(refsph run taylor --dp 0.5e-3; coarser spacings give narrower feet, README and chapter 06)")
    return "\n".join(lines)


SCENE = Scene(
    "taylor",
    "Taylor impact: 4340 cylinder 37.97 x 7.595 mm at 181 m/s on a rigid frictionless wall (Section 3.1)",
    _default_dp, _build, _record, _metrics, options=TAYLOR_OPTIONS, default_dim=3,
    methods=("esph", "tlsph"), report=comparison_table)
