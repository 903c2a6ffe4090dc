"""Scenes as data: geometry, material, numerics, what to record and which metrics to report.

Each scene is a :class:`Scene` with ``build(dim, dp, quick) -> Setup``, ``record(state, setup)`` (scalars
stored in the history every few steps) and ``metrics(history, state, setup)`` (the ``metrics`` object of
``summary.json``). The registry :data:`SCENES` is what ``refsph list`` prints.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .boundaries import MirrorPlanes
from .material import ElasticMaterial, eos_pressure
from .plasticity import JohnsonCook
from .neighbours import find_pairs
from .state import State, make_state

__all__ = ["Numerics", "Setup", "Scene", "SCENES", "get_scene", "convert_options", "lattice", "AISI4340_ELASTIC",
           "kinetic_energy", "elastic_energy", "linear_momentum", "min_pair_distance"]

# AISI 4340, elastic constants of Table 3 (Islam, Bansal & Peng)
AISI4340_ELASTIC = dict(rho0=7830.0, E=207e9, nu=0.3)


@dataclass(frozen=True)
class Numerics:
    """Numerical parameters of a run (not material constants, so defaults are allowed here).

    h_over_dp: smoothing length / spacing; beta1, beta2: artificial viscosity (Eq. 12); gamma: ESPH
    artificial pressure (Eq. 14; 0 = off); n_ap: its exponent; eps: Eq. (13); kernel: 'cubic' | 'wendland';
    courant: CFL number; corrected: TLSPH kernel-gradient correction; ref_update_strain: TLSPH reference
    update trigger on max |E| (None = never); skin_factor: ESPH Verlet skin in units of h; contact_k: TLSPH
    pinball radius R = contact_k h (Eq. 32; None = dp / (2h), pinballs of neighbouring bodies touch at one
    spacing); contact_Kp: the pinball scaling factor K_p (Eq. 33); threads: threads that share the pair sums
    (0 = one per available core). The numbers of a run do not depend on ``threads``, only its speed does.
    """

    h_over_dp: float = 1.5
    beta1: float = 1.5
    beta2: float = 1.5
    gamma: float = 0.3
    n_ap: float = 4.0
    eps: float = 0.01
    kernel: str = "cubic"
    courant: float = 0.3
    corrected: bool = True
    ref_update_strain: float | None = 0.5
    skin_factor: float = 0.1
    contact_k: float | None = None
    contact_Kp: float = 50.0
    threads: int = 0


@dataclass
class Setup:
    """Everything a run needs. ``plasticity``: Johnson-Cook constants (None: elastic); ``mirror``: symmetry
    planes (:class:`~refsph.boundaries.MirrorPlanes`, None: none); ``walls``: rigid walls
    (:class:`~refsph.boundaries.RigidWall`); ``snapshot_times``: extra output times [s] besides the
    ``n_snapshots`` evenly spaced ones; ``rigid``: tools (:class:`~refsph.boundaries.RigidBody`, their
    particles the last rows of ``state``); ``clamps``: held particles (:class:`~refsph.boundaries.Clamp`);
    ``friction``: a :class:`~refsph.contact.CoulombFriction` for the TLSPH pinball contact (None: frictionless,
    as in the paper)."""

    state: State
    material: ElasticMaterial
    dp: float
    numerics: Numerics
    t_end: float
    n_snapshots: int
    info: dict = field(default_factory=dict)
    plasticity: JohnsonCook | None = None
    mirror: MirrorPlanes | None = None
    walls: tuple = ()
    snapshot_times: tuple = ()
    rigid: tuple = ()
    clamps: tuple = ()
    friction: object = None

    @property
    def h(self) -> float:
        return self.numerics.h_over_dp * self.dp


@dataclass(frozen=True)
class Scene:
    """A scene as data. ``build(dim, dp, quick, **options)``; ``options``: the scene's own settings,
    {name: (default, help)}; ``default_dim``: the dimension a plain ``refsph run SCENE`` uses;
    ``methods``: what a plain ``refsph run SCENE`` runs."""

    name: str
    description: str
    default_dp: Callable[[int, bool], float]
    build: Callable[..., Setup]
    record: Callable[[State, Setup], dict]
    metrics: Callable[[dict, State, Setup], dict]
    options: dict = field(default_factory=dict)
    default_dim: int = 2
    methods: tuple = ("tlsph",)
    report: Callable[[list], str] | None = None


_TRUE, _FALSE = ("true", "1", "yes"), ("false", "0", "no")


def parse_bool(value, what: str) -> bool:
    """A boolean, or its spelling true/false/1/0/yes/no (any case); ``what`` names it in the error."""
    if isinstance(value, str) and value.lower() in _TRUE + _FALSE:
        return value.lower() in _TRUE
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise ValueError(f"{what} must be true or false, got {value!r}")


def convert_options(scene: Scene, options: dict) -> dict:
    """Check a scene's options and convert each value like its default (strings from the command line
    included): booleans from true/false/1/0/yes/no, numbers with float(). Unknown names are refused."""
    out = {}
    for name, value in options.items():
        if name not in scene.options:
            known = ", ".join(sorted(scene.options)) or "none"
            raise ValueError(f"unknown option {name!r} for scene {scene.name!r} (known: {known})")
        default = scene.options[name][0]
        if isinstance(default, bool):
            out[name] = parse_bool(value, f"option {name}")
        elif isinstance(default, (int, float)):
            try:
                out[name] = float(value)
            except (TypeError, ValueError):
                raise ValueError(f"option {name} must be a number, got {value!r}") from None
        else:
            out[name] = value
    return out


def lattice(lengths, dp: float) -> np.ndarray:
    """Particle centres of a box [0, L_0] x ... on a square/cubic lattice of spacing dp (cell centres)."""
    axes = []
    for L in lengths:
        n = int(round(L / dp))
        if n < 1:
            raise ValueError(f"spacing dp={dp!r} is larger than the body ({L!r} m)")
        axes.append((np.arange(n) + 0.5) * dp)
    grids = np.meshgrid(*axes, indexing="ij")
    return np.stack([g.ravel() for g in grids], axis=1)


# ----------------------------------------------------------------------------- diagnostics
def kinetic_energy(state: State) -> float:
    return float(0.5 * np.sum(state.m * np.einsum("ik,ik->i", state.v, state.v)))


def elastic_energy(state: State, mat: ElasticMaterial) -> float:
    """sum_i V_i (p_i^2 / (2K) + s_i:s_i / (4G)), V = m / rho; small-strain energy of the stress state."""
    p = eos_pressure(state.rho, mat.rho0, mat.K)
    ss = np.einsum("nab,nab->n", state.S, state.S)
    if state.dim == 2:
        ss = ss + state.S_zz**2
    V = state.m / state.rho
    return float(np.sum(V * (p * p / (2.0 * mat.K) + ss / (4.0 * mat.G))))


def linear_momentum(state: State) -> np.ndarray:
    return np.sum(state.m[:, None] * state.v, axis=0)


def min_pair_distance(x: np.ndarray, radius: float) -> float:
    I, J = find_pairs(x, radius)
    if len(I) == 0:
        return float("inf")
    d = x[I] - x[J]
    return float(np.sqrt(np.min(np.einsum("pk,pk->p", d, d))))


def _zero_crossings(t: np.ndarray, a: np.ndarray) -> np.ndarray:
    s = np.sign(a)
    k = np.flatnonzero((s[1:] != s[:-1]) & (s[1:] != 0))
    return t[k] - a[k] * (t[k + 1] - t[k]) / (a[k + 1] - a[k])


# ----------------------------------------------------------------------------- bar
def _bar_geometry(dim):
    L, W = 20e-3, 2e-3
    return L, W, ([L, W] if dim == 2 else [L, W, W])


def _bar_default_dp(dim, quick):
    _, W, _ = _bar_geometry(dim)
    if dim == 2:
        return W / (8 if quick else 16)
    return W / (4 if quick else 8)


def _bar_build(dim, dp, quick):
    """Free-free elastic bar, first axial mode: v_x(X, 0) = v0 cos(pi X / L). Period T = 2 L / c_bar."""
    L, W, lengths = _bar_geometry(dim)
    mat = ElasticMaterial(**AISI4340_ELASTIC)
    x = lattice(lengths, dp)
    v0 = 1.0
    v = np.zeros_like(x)
    v[:, 0] = v0 * np.cos(np.pi * x[:, 0] / L)
    state = make_state(x, v, mat.rho0, dp**dim)
    period = 2.0 * L / mat.c_bar(dim)
    return Setup(state=state, material=mat, dp=dp, numerics=Numerics(), t_end=2.0 * period, n_snapshots=10,
                 info=dict(L=L, W=W, v0=v0, period_theory=period))


def _bar_record(state, setup):
    L = setup.info["L"]
    phi = np.cos(np.pi * state.X[:, 0] / L)
    amp = float(np.sum(state.m * state.v[:, 0] * phi) / np.sum(state.m * phi * phi))
    P = linear_momentum(state)
    return dict(t=state.t, amplitude=amp, E_kin=kinetic_energy(state),
                E_el=elastic_energy(state, setup.material), Px=float(P[0]), Py=float(P[1]))


def _bar_metrics(hist, state, setup):
    t, a = np.asarray(hist["t"]), np.asarray(hist["amplitude"])
    tz = _zero_crossings(t, a)
    L = setup.info["L"]
    c_th = setup.material.c_bar(state.dim)
    if len(tz) >= 2:
        period = 2.0 * float(np.mean(np.diff(tz)))
        c = 2.0 * L / period
    else:
        period, c = float("nan"), float("nan")
    E = np.asarray(hist["E_kin"]) + np.asarray(hist["E_el"])
    P = np.stack([hist["Px"], hist["Py"]], axis=1)
    p_scale = float(np.sum(state.m)) * setup.info["v0"]
    return dict(
        period_s=period,
        wave_speed_m_s=c,
        wave_speed_theory_m_s=c_th,
        wave_speed_rel_error=(c - c_th) / c_th,
        energy_history=np.stack([t, hist["E_kin"], hist["E_el"]], axis=1),
        energy_final_over_initial=float(E[-1] / E[0]),
        momentum_drift_rel=float(np.max(np.abs(P - P[0])) / p_scale),
    )


# ----------------------------------------------------------------------------- tension
def _tension_default_dp(dim, quick):
    return (0.5e-3 if quick else 0.25e-3) if dim == 2 else 1.0e-3


def _tension_build(dim, dp, quick):
    """Square (cubic) block in free flight with a uniform expansion v = rate (x - x_c) (edge speed 300 m/s)
    that puts it in tension (down to about -15 GPa in the first breathing cycle); a 1 % random lattice perturbation (fixed seed) seeds the
    tensile instability. Artificial viscosity beta1 = beta2 = 0.5 (the paper's Tables 4-5): with 1.5 the
    breathing is damped out before clumping can grow. t_end = 24 side / c_L (about 40 us)."""
    side = 10e-3
    mat = ElasticMaterial(**AISI4340_ELASTIC)
    x = lattice([side] * dim, dp)
    rng = np.random.default_rng(12345)
    x = x + 0.01 * dp * rng.uniform(-1.0, 1.0, size=x.shape)
    v_edge = 300.0
    rate = v_edge / (0.5 * side)
    v = rate * (x - 0.5 * side)
    state = make_state(x, v, mat.rho0, dp**dim)
    t_end = 24.0 * side / mat.c_longitudinal
    return Setup(state=state, material=mat, dp=dp, numerics=Numerics(beta1=0.5, beta2=0.5), t_end=t_end,
                 n_snapshots=10,
                 info=dict(side=side, v_edge=v_edge))


def _tension_record(state, setup):
    p = eos_pressure(state.rho, setup.material.rho0, setup.material.K)
    return dict(t=state.t, min_pair_distance_over_dp=min_pair_distance(state.x, 1.5 * setup.dp) / setup.dp,
                min_pressure_Pa=float(np.min(p)))


def _tension_metrics(hist, state, setup):
    r = np.asarray(hist["min_pair_distance_over_dp"])
    return dict(
        min_pair_distance_over_dp=float(np.min(r)),
        final_min_pair_distance_over_dp=float(r[-1]),
        min_pair_distance_history=np.stack([hist["t"], r], axis=1),
        min_pressure_Pa=float(np.min(hist["min_pressure_Pa"])),
    )


SCENES: dict[str, Scene] = {
    "bar": Scene(
        "bar",
        "free-free elastic AISI 4340 bar 20 x 2 mm in its first axial mode: wave speed, energy, momentum",
        _bar_default_dp, _bar_build, _bar_record, _bar_metrics),
    "tension": Scene(
        "tension",
        "elastic AISI 4340 block 10 x 10 mm expanding in free flight: tensile instability (min pair distance)",
        _tension_default_dp, _tension_build, _tension_record, _tension_metrics),
}


from .taylor import make_scene as _make_taylor  # noqa: E402  (the Taylor scene uses the classes above)

SCENES["taylor"] = _make_taylor()

from .pressing import make_scene as _make_pressing  # noqa: E402

SCENES["pressing"] = _make_pressing()

from .cutting import make_scene as _make_cutting  # noqa: E402

SCENES["cutting"] = _make_cutting()


def get_scene(name: str) -> Scene:
    try:
        return SCENES[name]
    except KeyError:
        raise ValueError(f"unknown scene {name!r}; available: {', '.join(sorted(SCENES))}") from None
