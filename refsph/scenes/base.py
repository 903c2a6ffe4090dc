"""What a scene is made of: the numerical parameters (:class:`Numerics`), everything a run needs
(:class:`Setup`), a scene as data (:class:`Scene`) and the parsing of its options.

A :class:`Setup` is all :func:`refsph.simulate.simulate` needs; a :class:`Scene` adds what the command line needs
to make one (``build``, ``default_dp``, ``options``) and what to measure (``record``, ``metrics``, ``report``).
A script that builds its own case makes a Setup and calls ``simulate`` (README, "Your own scene").
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Callable

import numpy as np

from ..boundaries import MirrorPlanes
from ..kernels import KERNELS
from ..material import ElasticMaterial
from ..state import State
from ..strength import Elastic, StrengthModel

__all__ = ["Numerics", "Setup", "Scene", "parse_bool", "convert_options", "numerics_field_optional"]


@dataclass(frozen=True)
class Numerics:
    """Numerical parameters of a run (not material constants, so defaults are allowed here).

    h_over_dp: smoothing length / spacing; beta1, beta2: artificial viscosity (Eq. (12)); gamma: ESPH
    artificial pressure (Eq. (14); 0 = off); n_ap: its exponent; eps: Eq. (13); kernel: 'cubic' | 'wendland';
    courant: CFL number; corrected: TLSPH kernel-gradient correction; ref_update_strain: TLSPH reference
    update trigger on max |E| (None = never); skin_factor: ESPH Verlet skin in units of h; contact_k: TLSPH
    pinball radius R = contact_k h (Eq. (32); None = dp / (2h), pinballs of neighbouring bodies touch at one
    spacing); contact_Kp: the pinball scaling factor K_p (Eq. (33)); threads: threads that share the pair sums
    (0 = one per available core); integrator: the time stepper (:data:`refsph.integrate.STEPPERS`); esph_correction:
    ESPH's normalised velocity gradient (:mod:`refsph.esph`; off: Eq. (23) as printed); hourglass: TLSPH hourglass
    control coefficient (Ganzenmueller 2015, :mod:`refsph.tlsph`; 0 = off, as in the paper); contact: the
    contact with rigid tools, 'pinball' (TLSPH: Eqs. (32)-(36), the paper's; ESPH: the tools in the SPH sums, the
    paper's) or 'penalty' (either method: :mod:`refsph.penalty`, on the tools' exact geometry,
    ``RigidBody.shape``); penalty_alpha: the penalty stiffness alpha m / dt^2 (the fraction of the penetration
    removed per step); penalty_damping: the damping ratio of the penalty's normal spring;
    max_condition: TLSPH's kernel-gradient correction inverts a moment matrix whose condition number exceeds it
    only up to it (:func:`refsph.kernels.correction_matrix`; None = no limit, as in the paper); heat_every: the
    heat step (conduction, frictional heat, losses, :class:`refsph.thermal.HeatFlow`) runs once every this many
    mechanical steps, over their summed step with the heat they made (1 = every step; the plastic heat of the return
    map still raises T every step); self_contact: TLSPH particles of one body closer than self_contact dp repel
    (:mod:`refsph.self_contact`, LAMMPS SMD's self-contact at 0.5; None = off, as in the paper); gain_step: TLSPH's
    CFL step divided by the corrected gradient's largest gain, max(1, max_i a_i) (:func:`refsph.tlsph.gradient_gain`:
    0.90 inside a body at h = 1.3 dp (Wendland), 2.8 at a torn chip tip after a reference update in case 1's blow-up;
    off = the plain CFL step, as in the paper); frequency_step: TLSPH's step no longer than this fraction of the
    critical step 2 / w_max of each reference configuration (:meth:`refsph.tlsph.ReferenceOperator.critical_step`;
    0 = off, as in the paper; the leapfrog fails above 1). The numbers of a run do not depend on ``threads``, only
    its speed does.
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
    integrator: str = "predictor_corrector"
    esph_correction: bool = False
    hourglass: float = 0.0
    contact: str = "pinball"
    penalty_alpha: float = 0.1
    penalty_damping: float = 0.5
    max_condition: float | None = None
    heat_every: int = 1
    self_contact: float | None = None
    gain_step: bool = False
    frequency_step: float = 0.0

    def __post_init__(self):
        """Every parameter checked when the Numerics is made (a scene's, or ``--set``'s replacement of it), so that
        a bad value is refused by name before anything runs, not at step N."""
        def real(name, lo=None, hi=None, lo_open=False, optional=False):
            v = getattr(self, name)
            if v is None and optional:
                return
            ok = isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v)
            ok = ok and (lo is None or (v > lo if lo_open else v >= lo)) and (hi is None or v <= hi)
            if not ok:
                span = ("" if lo is None else f"{'>' if lo_open else '>='} {lo!r}") + \
                       ("" if hi is None else f"{' and ' if lo is not None else ''}<= {hi!r}")
                raise ValueError(f"numerical parameter {name} must be a finite number {span}"
                                 f"{' (or none)' if optional else ''}, got {v!r}")
        real("h_over_dp", 1.0, 4.0)
        for name in ("beta1", "beta2", "gamma", "skin_factor", "hourglass", "penalty_damping"):
            real(name, 0.0)
        for name in ("n_ap", "eps", "contact_Kp"):
            real(name, 0.0, lo_open=True)
        real("courant", 0.0, 1.0, lo_open=True)
        real("ref_update_strain", 0.0, lo_open=True, optional=True)
        real("contact_k", 0.0, lo_open=True, optional=True)
        real("penalty_alpha", 0.0, 4.0, lo_open=True)
        real("max_condition", 1.0, lo_open=True, optional=True)
        real("self_contact", 0.0, 1.0, lo_open=True, optional=True)
        real("frequency_step", 0.0, 1.0)
        if not (isinstance(self.threads, int) and not isinstance(self.threads, bool) and self.threads >= 0):
            raise ValueError(f"numerical parameter threads must be a whole number >= 0, got {self.threads!r}")
        if not (isinstance(self.heat_every, int) and not isinstance(self.heat_every, bool) and self.heat_every >= 1):
            raise ValueError(f"numerical parameter heat_every must be a whole number >= 1, got {self.heat_every!r}")
        for name, choices in (("kernel", tuple(KERNELS)), ("contact", ("pinball", "penalty"))):
            if getattr(self, name) not in choices:
                raise ValueError(f"numerical parameter {name} must be one of {', '.join(choices)}, got "
                                 f"{getattr(self, name)!r}")
        for name in ("corrected", "esph_correction", "gain_step"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise ValueError(f"numerical parameter {name} must be true or false, got {getattr(self, name)!r}")


def numerics_field_optional(name: str) -> bool:
    """True if the Numerics field accepts None (read from its annotation)."""
    return any(f.name == name and "None" in str(f.type) for f in fields(Numerics))


@dataclass
class Setup:
    """Everything a run needs.

    ``state``: the particles (:func:`refsph.state.make_state`); ``material``: elastic constants; ``dp``: spacing;
    ``numerics``; ``t_end`` [s]; ``n_snapshots``: evenly spaced output times (plus ``snapshot_times`` [s]);
    ``strength``: the strength model (:mod:`refsph.strength`; None: elastic; whether plastic work heats, Eq. (28),
    is its own ``heating`` switch, and its ``cp`` is the body's heat capacity); ``mirror``: symmetry planes
    (:class:`~refsph.boundaries.MirrorPlanes`);
    ``walls``: rigid walls (:class:`~refsph.boundaries.RigidWall`); ``rigid``: tools
    (:class:`~refsph.boundaries.RigidBody`, their particles the last rows of ``state``); ``clamps``: held
    particles (:class:`~refsph.boundaries.Clamp`); ``friction``: a :class:`~refsph.contact.CoulombFriction` for
    the tool contact (TLSPH's pinball, or either method's penalty; None: frictionless, as in the paper);
    ``info``: numbers that describe the scene (written to ``summary.json`` as ``scene_info``: JSON scalars, strings
    and short lists only); ``arrays``:
    per-particle arrays the scene's measurements need (index sets; not written to the summary); ``thermal``: heat
    conduction during the run (a :class:`refsph.thermal.Conduction`; None: none, the paper's adiabatic model);
    ``friction_heat``: the frictional heat of the contact (a :class:`refsph.thermal.FrictionHeat`; None: friction
    makes no heat). Either switches the run's heat flow on (:class:`refsph.thermal.HeatFlow`).
    ``dissipation_heat``: the numerical dissipation (TLSPH's artificial viscosity, the penalty contact's normal
    damping; ``Rates.heat_power``) becomes heat in the particle where it is taken from the motion, so that the
    tool's work ends up as heat (with a heat flow only; False: it leaves the energy balance, the paper's model).
    ``T_limit`` [K]: the run stops (status 'blow-up', the last good state kept) when a particle gets hotter than
    this, a temperature no material model of the scene means anything at (a local numerical blow-up); None: no limit.
    """

    state: State
    material: ElasticMaterial
    dp: float
    numerics: Numerics
    t_end: float
    n_snapshots: int
    info: dict = field(default_factory=dict)
    strength: StrengthModel | None = None
    mirror: MirrorPlanes | None = None
    walls: tuple = ()
    snapshot_times: tuple = ()
    rigid: tuple = ()
    clamps: tuple = ()
    friction: object = None
    arrays: dict = field(default_factory=dict)
    thermal: object = None
    friction_heat: object = None
    dissipation_heat: bool = False
    T_limit: float | None = None

    def __post_init__(self):
        if self.strength is None:
            self.strength = Elastic()
        if self.dissipation_heat and self.thermal is None and self.friction_heat is None:
            raise ValueError("Setup.dissipation_heat turns numerical dissipation into heat and needs a heat flow "
                             "(Setup.thermal or Setup.friction_heat)")
        bad = [k for k, v in self.info.items() if isinstance(v, np.ndarray)]
        if bad:
            raise ValueError(f"Setup.info goes into summary.json: put the arrays {', '.join(bad)} into Setup.arrays")

    @property
    def h(self) -> float:
        return self.numerics.h_over_dp * self.dp


@dataclass(frozen=True)
class Scene:
    """A scene as data. ``build(dim, dp, quick, **options) -> Setup`` (every option given; :meth:`setup` fills in
    the defaults); ``default_dp(dim, quick)`` (None: ``build`` derives the spacing from its options);
    ``record(state, setup) -> dict`` of scalars stored in the history every few steps;
    ``metrics(history, state, setup) -> dict``, the ``metrics`` of ``summary.json``; ``options``: the scene's own
    settings, {name: (default, help)}; ``default_dim``, ``methods``: what a plain ``refsph run SCENE`` runs;
    ``report(summaries) -> str``: a table of runs."""

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

    def setup(self, dim: int | None = None, dp: float | None = None, quick: bool = False, **options) -> Setup:
        """The scene's Setup: ``dim`` and ``dp`` default to the scene's, options to their defaults (strings
        converted like the default, as from the command line)."""
        dim = self.default_dim if dim is None else dim
        dp = self.default_dp(dim, quick) if dp is None else dp
        return self.build(dim, dp, quick, **convert_options(self, options))


_TRUE, _FALSE = ("true", "1", "yes"), ("false", "0", "no")


def parse_bool(value, what: str) -> bool:
    """A boolean, or its spelling true/false/1/0/yes/no (any case); ``what`` names it in the error."""
    if isinstance(value, str) and value.lower() in _TRUE + _FALSE:
        return value.lower() in _TRUE
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise ValueError(f"{what} must be true or false, got {value!r}")


def convert_options(scene: Scene, options: dict) -> dict:
    """Every option of the scene: the given ones checked and converted like their default (strings from the
    command line included: booleans from true/false/1/0/yes/no, numbers with float()), the others at their
    default. Unknown names are refused."""
    out = {name: default for name, (default, _) in scene.options.items()}
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
