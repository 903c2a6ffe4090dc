"""The second paper's 18 measured orthogonal cuts (Rodriguez Prieto, Larsson & Afrasiabi 2023, Appendix B) with
refsph's thermomechanical cutting scene, next to the measurements and the paper's own SPH and PFEM; and the studies
that say which digits of them mean something (issue 22).

    python benchmarks/thermal_cutting.py                     # every run not yet recorded, in jobs() order, 2 processes
    python benchmarks/thermal_cutting.py --jobs 1 --study tool scatter   # only these studies, one process
    python benchmarks/thermal_cutting.py --study cases --only 1 4 7      # some of the 18 cases
    python benchmarks/thermal_cutting.py --study pfem --only 1 10        # the PFEM's cuts of cases 1 and 10
    python benchmarks/thermal_cutting.py --scheduler tcp://HOST:8786     # the same on a dask.distributed cluster
    python benchmarks/thermal_cutting.py --redo "case 3"     # run one again (a failed record is kept until then)
    python benchmarks/thermal_cutting.py --report            # page and figures from the committed JSON only
    python benchmarks/thermal_cutting.py --status --study cases   # what is recorded, how far each run has got
    python benchmarks/thermal_cutting.py --keys "case 1 s/2" "case 11"   # these runs, in this order
    python benchmarks/thermal_cutting.py --quick --json /tmp/q.json --only 1 2   # a try-out (quick cuts)

Each run is ``refsph run thermal_cutting --case N`` with the sweep's numerics (:func:`converged`: dx = t_u / 10, 16
t_u of cut on a workpiece 28 t_u long, a tool 10 t_u x 6 t_u, the mass-scaling rule s rho vc^2 = 0.01 A, the penalty
contact, the numerical dissipation turned into heat; means over the last quarter of the cut; Ti6Al4V with the step
at courant 0.15 instead of the scene's 0.3, :func:`sweep_numerics`: at 0.3 case 10 breaks down at 1.1 ms, a particle
under the edge inverting) in ``runs/thermal_cutting/<key>/`` on one core (40-50 minutes a case beside another run).
The studies (``--study``): ``coarse`` (all 18 cases at t_u/5, keys 'case N n_tu 5': the complete table while the
t_u/10 sweep runs), ``scaling`` (s halved: cases 1 and 10), ``scatter`` (case 1 with its particles jittered by 0.01
dx, three seeds; first at t_u/5), ``resolution`` (t_u/5 and t_u/15 for cases 1 and 10), ``timestep`` (case 10 at the
scene's step, which fails, case 1 at Ti6Al4V's, and case 10 at t_u/5 at both), ``tool`` (the first sweep's tool 5
t_u x 3 t_u and 4 t_u left uncut, one change at a time, at t_u/5 and t_u/10), ``contact`` (the pinball; all the
frictional heat to the chip), ``refupdate`` (how often TLSPH's reference configuration is updated,
:func:`reference_update_jobs`). Resumable twice over: a finished run is a record in
``benchmarks/thermal_cutting.json`` and is skipped; a run that was killed continues from its last checkpoint
(``refsph run --restart``; one at every snapshot and every 10 minutes of wall time between them), and ``--park``
keeps those checkpoints in git (``benchmarks/parked/thermal_cutting/``) for a new checkout to continue from (a run
longer than a working session; ``runs/`` is not in git). A run that fails
(non-finite state, lost chip) is a record with its status and error; it stays in the table until ``--redo`` runs it
again, and a failed rerun never replaces a good record. A failed case of the t_u/10 tables is taken again by its
retry (``retry_jobs``: SPH at half the step, PFEM with the Bossak rule) in the same call and in every later one. A
rerun with nothing to do writes nothing.

The experimental values are not printed in the paper: ``refsph.paper_data.RLA_CUTTING_CASES`` recovers them from
each printed prediction and its printed percent error. The paper does not state the width of cut, so forces are
per mm of width; the table compares Fp/Fc and gives the width at which refsph's Fc equals the measured one.
Issue 19's sweep (pinball, t_u/5, 8 t_u) is kept in ``benchmarks/thermal_cutting_pinball_tu5.json`` for the page's
'before' column.

Writes benchmarks/thermal_cutting.json, benchmarks/thermal_cutting_report.md and figures/11_thermal_cutting_*.png.
The dask path needs ``pip install -e '.[dask]'`` on the client and every worker (refsph importable there).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # benchmarks/study.py, however this file is loaded
import study  # noqa: E402

study.pin_threads()

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
OUT_JSON = ROOT / "benchmarks" / "thermal_cutting.json"
BEFORE_JSON = ROOT / "benchmarks" / "thermal_cutting_pinball_tu5.json"   # issue 19's sweep: pinball, t_u/5, 8 t_u
REPORT = ROOT / "benchmarks" / "thermal_cutting_report.md"
RUNS = ROOT / "runs" / "thermal_cutting"
PARKED = ROOT / "benchmarks" / "parked" / "thermal_cutting"   # killed runs' checkpoints, in git (--park)
FIG = ROOT / "figures"
N_TU, TRAVEL = 10.0, 16.0                  # the sweep: dx = t_u / 10, 16 t_u of cut (means over the last quarter)
UNCUT = 12.0                               # t_u of workpiece left uncut at the end (4 t_u: the Fc drift was 21 %)
TOOL = dict(tool_length=10.0, tool_depth=6.0)   # t_u; 5 x 3 t_u: the contact (4 t_u) reached the held back face
SMALL = dict(tool_length=5.0, tool_depth=3.0)   # the first sweep's tool (the scene's default)
INERTIA = 0.01                             # the mass-scaling rule: s rho vc^2 = 0.01 A (module text)
KEEP = ("cutting_force_N_per_m", "passive_force_N_per_m", "force_ratio", "rake_face_temperature_K",
        "rake_face_temperature_max_K", "free_chip_surface_temperature_K", "chip_thickness_mm", "contact_length_mm",
        "max_temperature_K", "max_plastic_strain", "tool_work_J_per_m", "cut_length_mm", "mass_scale",
        "inertia_ratio", "width_matching_Fc_mm", "drift_last_quarter", "measured", "blow_up")


def converged(case: int, **more) -> dict:
    """The sweep's options for a case: dx = t_u / N_TU, TRAVEL t_u of cut on a workpiece (TRAVEL + UNCUT) t_u long,
    the tool TOOL; ``uncut``: other t_u left uncut."""
    from refsph.paper_data import rla_cutting_case
    tu = rla_cutting_case(case)["tu_mm"] * 1e-3
    uncut = more.pop("uncut", UNCUT)
    return dict(dict(case=case, n_tu=N_TU, travel=TRAVEL, length=(TRAVEL + uncut) * tu, **TOOL), **more)


def _s(case: int) -> float:
    from refsph.scenes.thermal_cutting import MATERIALS, mass_scale_for
    from refsph.paper_data import rla_cutting_case
    row = rla_cutting_case(case)
    return mass_scale_for(MATERIALS[row["material"]], row["vc_m_per_min"] / 60.0, INERTIA)


STUDY_NAMES = ("cases", "coarse", "pfem", "detector", "scaling", "scatter", "resolution", "timestep", "tool",
               "contact", "refupdate", "selfcontact", "gain", "frequency", "refined", "gap", "conductivity")
COURANT = 0.15                             # every run at dx <= t_u / 10: half the scene's step (module text)
COARSE = " n_tu 5"                         # the key suffix of the 'coarse' study: all 18 cases at dx = t_u / 5
PFEM = " pfem n_tu 5"                      # the key suffix of the 'pfem' study: the 18 cases with the PFEM at t_u / 5
PFEM10 = " pfem"                           # ... and at t_u / 10 (the paper's resolution for t_u = 0.1 mm)
RETRY_COURANT = 0.075                      # a case of the t_u / 10 table that failed at COURANT, again at half of it,
RETRY = f" courant {RETRY_COURANT:g}"        # under the key 'case N' + RETRY
REF_KEY = " ref update "                   # the 'refupdate' study's key part: TLSPH's ref_update_strain (the scene's
REF_UPDATES = (1.5, 0.2, 0.1, 0.05, 0.02)  # 0.5) at these values at t_u/5 (reference_update_jobs) ...
REF_UPDATE = 0.1                           # ... and at this one at t_u/10 and for the scatter
SCENE_REF_UPDATE = 0.5                     # the scene's (refsph.scenes.thermal_cutting; a test holds them equal)
REF_FAILED = ((10, 0.2), (1, 0.02))        # (case, reference update) of the two t_u/5 runs that failed at courant 0.3
HALF_STEP = f"{REF_KEY}{REF_UPDATE:g} courant {COURANT:g}"   # the 18 cuts at t_u/5 at REF_UPDATE and half the step
SELF_KEY = " self contact"                 # the 'selfcontact' study's key part: Numerics.self_contact at SELF_CONTACT
SELF_CONTACT = 0.5                         # (refsph.self_contact: LAMMPS SMD's r_c = dp/2), self_contact_jobs
SELF_REF_UPDATES = (0.2, 0.1, 0.02)        # ... with these reference updates too (the refupdate study's failures)
RERUN = " rerun"                           # a run again with today's code, beside its record (its crowding)
GAIN_KEY = " gain step"                    # the 'gain' study's key part: Numerics.gain_step (the CFL step over the
                                           # corrected gradient's largest gain, refsph.tlsph.gradient_gain)
FREQUENCY_STEP = 0.5                       # the 'frequency' study: Numerics.frequency_step (the step under this
FREQ_KEY = f" frequency step {FREQUENCY_STEP:g}"   # fraction of 2 / w_max, refsph.tlsph.largest_frequency)
REFINED = f"{REF_KEY}{REF_UPDATE:g}{FREQ_KEY}"   # the 'refined' study: the 18 cuts at t_u/10 at REF_UPDATE (the
                                           # t_u/5 study: 0.5 is not converged, 0.1 is within the scatter of 0.05) at
                                           # the scene's courant 0.3 under FREQUENCY_STEP (case 1: the 'frequency' run)
DAMPED_GAMMA = 0.6                         # a PFEM case of the t_u / 10 table that failed with the trapezoidal rule,
DAMPED = f" n_tu 10 gamma {DAMPED_GAMMA:g}"  # again with Newmark's damped rule, under 'case N pfem' + DAMPED
BOSSAK_ALPHA = -0.1                        # the Bossak-Newmark rule (second order, damped) beside the damped rule:
BOSSAK = f" bossak {BOSSAK_ALPHA:g}"         # its key suffix (gamma 0.6 too, beta 0.3025; inertia 1.1 a_n+1 - 0.1 a_n)
# the tables that take such a run for a failed case's row, the first recorded 'ok' of each tuple: for the PFEM the
# Bossak-Newmark run before the damped one, for its order (second; on the whole cuts of cases 1 and 8 at t_u/5 the
# two damped rules move Fp by 5-30 % from the trapezoidal rule's, each the more on one case: the time-rule table)
GAP_CHANGES = ((" frictionless", dict(friction=False)),           # the 'gap' study: key suffix, scene option
               (" no dissipation heat", dict(dissipation_heat=False)),
               (" friction without heat", dict(eta=0.0)))        # friction's mechanics without its heat
WITHOUT_HEAT = GAP_CHANGES[2][0]                               # ... its key suffix, also run at t_u/10
COND_KEY = " conductivity x"               # the 'conductivity' study (a sensitivity, not the paper's model): the
CONDUCTIVITY = ((10, 2.0), (1, 0.6))       # workpiece's k of Table A1 times a factor ((case, factor): Ti6Al4V's k
#                                            about doubles from room temperature to 1000 K, a carbon steel's falls by
#                                            about 40 %; the paper holds the room-temperature value), at t_u/10 REFINED
REFINED_NUMERICS = dict(ref_update_strain=REF_UPDATE, frequency_step=FREQUENCY_STEP)   # what 'refined' sets
REFINED_RETRY = f" courant {COURANT:g}"      # a 'refined' case that failed: again at half the CFL part of its step
RETRIES = {"": (RETRY,), PFEM10: (f" n_tu 10{BOSSAK}", DAMPED), REFINED: (REFINED_RETRY,)}
REDONE = {PFEM10: (RERUN,), PFEM: (RERUN,)}   # a table's case made again by today's solver (RERUN): taken before its
#                                            record (refsph.teaching.plots.cut_record; PFEM*_RERUN_CASES)
PFEM_OPTIONS = ("case", "n_tu", "travel", "length", "gamma", "remesh_when_needed", "bossak", "eta", "jitter",
                "seed", "conductivity_factor")   # the PFEM cut's options a key may set (the rest: the SPH scene's)
REMESH = " remesh when needed"              # the key suffix of a PFEM cut that remeshes only where the quality asks
PAPER_CUT = (1.5e-3, 2.0e-3)   # m of tool travel: the last quarter of the paper's PFEM cut, 2/3 of its 3 mm workpiece
TO_CHIP = " all friction heat to the chip"   # key suffix: chip_fraction 1 (the paper's SPH code's choice; scene 0.5)
TO_2MM = " 2 mm"               # key suffix: a t_u = 0.1 mm case cut to 2 mm (20 t_u) on the paper's 3 mm workpiece
TU_01 = (1, 4, 7, 10, 13, 16)   # the cases at t_u = 0.1 mm
MATERIAL_NAMES = ("AISI1045", "Ti6Al4V")   # the tables' materials, in their order
PFEM_FINE = ((1, 15.0), (2, 15.0), (3, 20.0), (5, 15.0), (8, 15.0), (6, 20.0), (9, 20.0))   # (case, nodes across
                                           # t_u) of the PFEM finer than t_u/10: the paper's 10 um near the tool
PFEM_FINE_BOSSAK = (8, 9)                  # ... with the Bossak rule, as at t_u/10 (the trapezoidal rule stalled)
PFEM_RERUN_CASES = (2, 5, 3, 6, 1)         # cases whose t_u/5 and t_u/10 PFEM records an earlier solver made: again
#                                            with today's (key suffix RERUN) for the spacing study (pfem_spacing_keys)
PFEM10_RERUN_CASES = PFEM_RERUN_CASES + (4, 7)   # ... at t_u/10 also for the 18-case table (REDONE): AISI 1045's
#                                            cases 1-7 were cut before the contact's changes of b294aaf and 248e7e0
PFEM5_RERUN_CASES = PFEM10_RERUN_CASES + tuple(range(8, 19))   # ... at t_u/5 all 18 (REDONE): that table was cut
#                                            on 2026-11-25, before those changes and the Newton's of later days
REMESH_RUNS = ((1, PFEM, 5.0), (5, PFEM, 5.0), (10, PFEM, 5.0), (1, PFEM10, 10.0))   # (case, suffix, n_tu) of those


def sweep_numerics(n_tu: float = N_TU, **more) -> dict:
    """The Numerics overrides of an SPH run of the sweep: at dx <= t_u / 10 the step at courant COURANT (at the
    scene's 0.3 case 10 breaks down at 1.1 ms and case 2 blows up at 2.25 ms, module text); at t_u / 5 the
    scene's."""
    return dict(dict(courant=COURANT) if n_tu >= N_TU else {}, **more)


def jobs(studies=STUDY_NAMES, only=None) -> dict:
    """{key: (scene options, Numerics overrides)} of the runs asked for, in the order they run (a sweep that spans
    sessions does the informative ones first: case 1 and what tests its numerics, then the 18 cases, then the
    long resolution checks). ``only``: case numbers (of the 'cases', 'coarse' and 'pfem' studies)."""
    todo = {}

    def add(study_name, key, options, numerics=None):
        if study_name in studies and (study_name not in ("cases", "coarse", "pfem") or only is None
                                      or options["case"] in only):
            todo[key] = (options, dict(numerics or {}))
    add("cases", "case 1", converged(1), sweep_numerics())
    # the heat step once every 8 mechanical steps (Numerics.heat_every; its stable step is 30-60 of the mechanical
    # one at t_u/10): the cost of a converged case (issue 22: under 40 min on one core), beside 'case 1'
    add("timestep", "case 1 heat every 8", converged(1), sweep_numerics(heat_every=8))
    # the scatter: first at t_u/5 (an eighth of the cost); Ti6Al4V's too (its time-step runs differ by more)
    for n, seed in [(c, k) for c in (1, 10) for k in (1, 2, 3)]:
        add("scatter", f"case {n} n_tu 5 jitter {seed}", converged(n, n_tu=5.0, jitter=0.01, seed=seed))
    for n in range(1, 19):                                   # all 18 at t_u/5 (Ti6Al4V's case 10 fails at t_u/10)
        if n == 1 or n == 10:
            add("resolution", f"case {n}{COARSE}", converged(n, n_tu=5.0))
        add("coarse", f"case {n}{COARSE}", converged(n, n_tu=5.0))
    for n in (1, 10):                                        # the paper's future work: alpha-shape vs SPH detector
        add("detector", f"case {n}{COARSE} alpha detector", converged(n, n_tu=5.0, detector="alpha"))
    # case 10's alpha-shape run inverted a particle at 3.9 ms at the scene's step: again at courant 0.15, beside
    # 'case 10 n_tu 5 courant 0.15' (the 'timestep' study)
    add("detector", f"case 10{COARSE} alpha detector courant 0.15", converged(10, n_tu=5.0, detector="alpha"),
        dict(courant=0.15))
    for n in [1, 10] + [k for k in range(2, 19) if k != 10]:   # the PFEM: cases 1 and 10 first
        add("pfem", f"case {n}{PFEM}", converged(n, n_tu=5.0), dict(method="pfem"))
        if n == 10:                                          # the PFEM's resolution, on the short cut of --quick,
            for k in (5, 10):                                # then case 1 at the paper's resolution (the long one)
                add("pfem", f"case 1 pfem short n_tu {k}", converged(1, n_tu=float(k), travel=4.0, length=1.2e-3),
                    dict(method="pfem"))
            add("pfem", "case 1 pfem", converged(1, n_tu=10.0), dict(method="pfem"))
    add("pfem", "case 16 pfem gamma 0.6", dict(converged(16, n_tu=5.0), gamma=0.6), dict(method="pfem"))  # damped
    add("scaling", "case 1 s/2", converged(1, mass_scale=_s(1) / 2), sweep_numerics())
    add("scaling", f"case 1{COARSE} s/2", converged(1, n_tu=5.0, mass_scale=_s(1) / 2))   # beside the t_u/5 scatter
    add("scaling", f"case 10{COARSE} s/2", converged(10, n_tu=5.0, mass_scale=_s(10) / 2))
    # at t_u/5 s/2 moved case 1's temperatures by 3-7 of the scatter's standard deviations: the scatter at s/2
    # (the same three seeds), then s/4, so that the temperatures' dependence on s is measured, not one run's
    for seed in (1, 2, 3):
        add("scaling", f"case 1{COARSE} s/2 jitter {seed}",
            converged(1, n_tu=5.0, mass_scale=_s(1) / 2, jitter=0.01, seed=seed))
    add("scaling", f"case 1{COARSE} s/4", converged(1, n_tu=5.0, mass_scale=_s(1) / 4))
    # at the scene's step s/4 inverts a particle at 0.93 ms of 1.6: again at half the step
    add("scaling", f"case 1{COARSE} s/4 courant 0.15", converged(1, n_tu=5.0, mass_scale=_s(1) / 4),
        dict(courant=0.15))
    add("timestep", "case 10 courant 0.3", converged(10))        # the scene's step: breaks down at 1.1 ms
    add("cases", "case 10", converged(10), sweep_numerics())
    add("scaling", "case 10 s/2", converged(10, mass_scale=_s(10) / 2), sweep_numerics())
    for seed in (1, 2, 3):
        add("scatter", f"case 1 jitter {seed}", converged(1, jitter=0.01, seed=seed), sweep_numerics())
    # case 10 at s/2 moved Fc by -21 % at t_u/10 (one run each): Ti6Al4V's scatter at t_u/10, to read it by
    for seed in (1, 2):
        add("scatter", f"case 10 jitter {seed}", converged(10, jitter=0.01, seed=seed), sweep_numerics())
    for n in list(range(2, 10)) + list(range(11, 19)):
        add("cases", f"case {n}", converged(n), sweep_numerics())
    for n in (1, 2):                                          # the scene's step at t_u/10 (the first runs)
        add("timestep", f"case {n} courant 0.3", converged(n))
    for n, c in ((10, COURANT), (1, 0.15), (2, 0.15), (10, 0.075), (1, 0.075)):   # the step at t_u/5
        add("timestep", f"case {n}{COARSE} courant {c:g}", converged(n, n_tu=5.0), dict(courant=c))
    # the tool and workpiece checks (the first sweep's tool 5 x 3 t_u and 4 t_u uncut, one change at a time)
    add("tool", "case 1 n_tu 5 tool 5x3, 4 t_u uncut", converged(1, n_tu=5.0, uncut=4.0, **SMALL))
    add("tool", "case 1 n_tu 5 tool 5x3, 8 t_u uncut", converged(1, n_tu=5.0, uncut=8.0, **SMALL))
    add("tool", "case 1 n_tu 5 4 t_u uncut", converged(1, n_tu=5.0, uncut=4.0))
    add("tool", "case 1 tool 5x3, 4 t_u uncut", converged(1, uncut=4.0, **SMALL))      # (at the scene's step)
    add("contact", "case 1 pinball", converged(1), sweep_numerics(contact="pinball"))
    add("contact", f"case 1{TO_CHIP}", converged(1, chip_fraction=1.0), sweep_numerics())
    # case 9 blew up at 0.73 ms of 1.07 at courant 0.15 (22 chip particles past 1500 K, 0.4 mm up the rake face, then
    # two inverted particles; from its 0.67 ms checkpoint the same at 0.15, none at 0.075): again at half that step;
    # the report takes it for case 9's row (RETRY)
    add("timestep", f"case 9{RETRY}", converged(9), sweep_numerics(courant=RETRY_COURANT))
    add("resolution", "case 1 n_tu 15", converged(1, n_tu=15.0), sweep_numerics(15.0))
    add("resolution", "case 10 n_tu 15", converged(10, n_tu=15.0), sweep_numerics(15.0))
    for n in range(2, 19):                                   # the PFEM's 18 cases at t_u/10 ('case 1 pfem' above)
        add("pfem", f"case {n}{PFEM10}", converged(n, n_tu=10.0), dict(method="pfem"))
    for study_name, key, options, numerics in more_jobs():   # time rules, remeshing, finer nodes, the paper's cut
        add(study_name, key, options, numerics)
    return todo


def more_jobs() -> list[tuple[str, str, dict, dict]]:
    """(study, key, options, numerics) of the sweep's later runs: the PFEM's damped time rules (time_rule_jobs),
    its remeshing only where needed (remesh_jobs) and finer nodes (pfem_resolution_jobs), then the t_u = 0.1 mm
    cases cut to the paper's 2 mm (20 t_u; the sweep's 16 t_u is 1.6 mm) on its 3 mm workpiece (TO_2MM), the
    PFEM's first."""
    pfem = dict(method="pfem")
    out = [("selfcontact", key, options, numerics) for key, (options, numerics) in self_contact_jobs().items()]
    out += [("refupdate", key, options, numerics) for key, (options, numerics) in reference_update_jobs().items()]
    out += [("gain", key, options, numerics) for key, (options, numerics) in gain_step_jobs().items()]
    out += [("frequency", key.replace(GAIN_KEY, FREQ_KEY), options,
             dict({k: v for k, v in numerics.items() if k != "gain_step"}, frequency_step=FREQUENCY_STEP))
            for key, (options, numerics) in gain_step_jobs().items()]
    out += [("refined", f"case {n}{REFINED}", converged(n), dict(REFINED_NUMERICS)) for n in range(1, 19)]
    # the resolution check at REF_UPDATE (the 'resolution' study's runs are at the scene's 0.5): t_u/15 of cases 1, 10
    # at REF_UPDATE the frictional heat is 9-19 % of the tool's work (1-10 % at the scene's 0.5), so where it is put
    # matters more: cases 1 and 10 with all of it in the chip (the paper's SPH code's choice), before the t_u/15 runs
    out += [("contact", f"case {n}{REFINED}{TO_CHIP}", converged(n, chip_fraction=1.0), dict(REFINED_NUMERICS))
            for n in (10, 1)]
    out += [("refined", f"case {n} n_tu 15{REFINED}", converged(n, n_tu=15.0), dict(REFINED_NUMERICS))
            for n in (1, 10)]
    # the scatter and the mass scale at REF_UPDATE (SCATTER_TI10, SCATTER_KEYS and SCATTER_TI10_S2 are at the scene's
    # 0.5): cases 10 and 1 with the seeds of their scatter at 0.5, then case 10 at s/2 with the same seeds, so that
    # the t_u/15 checks, the heat split and halving s at the converged update are read against a scatter measured there
    out += [("scatter", f"case {n}{REFINED} jitter {seed}", converged(n, jitter=0.01, seed=seed),
             dict(REFINED_NUMERICS)) for n in (10, 1) for seed in (1, 2)]
    out += [("scaling", f"case 10 s/2{REFINED}" + (f" jitter {seed}" if seed else ""),
             converged(10, mass_scale=_s(10) / 2, **(dict(jitter=0.01, seed=seed) if seed else {})),
             dict(REFINED_NUMERICS)) for seed in (0, 1, 2)]
    # ... and steel's at REF_UPDATE: case 1 at s/2 (one run), read against case 1's scatter there (SINGLES)
    out += [("scaling", f"case 1 s/2{REFINED}", converged(1, mass_scale=_s(1) / 2), dict(REFINED_NUMERICS))]
    # case 10 at s/2 moved Fc by -21 %, T_RF by -12 %, one run against case 10's scatter of three: its scatter at s/2
    # too (the same two seeds), so that the forces' dependence on s is read between two groups of three
    out += [("scaling", f"case 10 s/2 jitter {seed}", converged(10, mass_scale=_s(10) / 2, jitter=0.01, seed=seed),
             sweep_numerics()) for seed in (1, 2)]
    # what makes the rake face stand far above the free chip surface at REF_UPDATE (T_RF - T_FCS twice the measured
    # for steel, three times for Ti6Al4V; already at t_u/5, where a run costs 3-6 min): cases 10 and 1 at t_u/5 as
    # the 'refupdate' study's runs, with friction off and with the numerical dissipation's heat left out
    out += [("gap", f"case {n}{COARSE}{REF_KEY}{REF_UPDATE:g}{sfx}", converged(n, n_tu=5.0, **change),
             dict(ref_update_strain=REF_UPDATE)) for n in (10, 1) for sfx, change in GAP_CHANGES]
    # at t_u/5 case 10's gap scatters by +-92 K, at t_u/10 by +-11 K: friction without its heat there too, read against
    # SCATTER_TI10_REF (SINGLES); then case 1's, read against SCATTER_REF
    out += [("gap", f"case {n}{REFINED}{WITHOUT_HEAT}", converged(n, **dict(GAP_CHANGES)[WITHOUT_HEAT]),
             dict(REFINED_NUMERICS)) for n in (10, 1)]
    # the PFEM's rake face stands 217 K (case 1) and 35 K (case 10) above its free chip surface with 6 and 13 % of
    # the work made frictional heat: the same split there, case 1 and case 10 at t_u/10 (PFEM_GAP_RUNS)
    out += [("gap", f"case {n}{PFEM10}{WITHOUT_HEAT}", dict(converged(n, n_tu=10.0), **dict(GAP_CHANGES)[WITHOUT_HEAT]),
             pfem) for n in (1, 10)]
    # case 10's scatter at t_u/5 and REF_UPDATE (the seeds of case 1's, REF_SCATTER), for the gap study's case 10
    # and the resolution check at REF_UPDATE (REFINED_NOISE), which took it from the scene's 0.5 before
    out += [("gap", f"case 10{COARSE}{REF_KEY}{REF_UPDATE:g} jitter {seed}",
             converged(10, n_tu=5.0, jitter=0.01, seed=seed), dict(ref_update_strain=REF_UPDATE)) for seed in (1, 2)]
    out += [("conductivity", key, options, numerics) for key, (options, numerics) in conductivity_jobs().items()]
    out += [("pfem", key, options, pfem) for key, options in time_rule_jobs() + remesh_jobs() + pfem_resolution_jobs()]
    # the PFEM's run-to-run scatter (case 2 at t_u/5, today's solver, unperturbed and with its nodes jittered by 0.01
    # of their spacing, three seeds), for the changes of the spacing study (pfem_spacing_convergence) to be read by
    out += [("pfem", key, dict(converged(2, n_tu=5.0), **({} if seed == 0 else dict(jitter=0.01, seed=seed))), pfem)
            for seed, key in enumerate(PFEM_SCATTER)]
    # ... and at t_u/10, the resolution of the 18-case table (case 2's rerun is the unperturbed run), so that the
    # t_u/10 changes are read against the scatter at their own resolution instead of the one at t_u/5
    out += [("pfem", key, dict(converged(PFEM_SCATTER_CASE, n_tu=10.0), jitter=0.01, seed=seed), pfem)
            for seed, key in enumerate(PFEM_SCATTER10) if seed]
    # ... and of a Ti6Al4V case at t_u/10 (case 10: its record postdates the contact's changes), four runs
    out += [("pfem", key, dict(converged(10, n_tu=10.0), jitter=0.01, seed=seed), pfem)
            for seed, key in enumerate(PFEM_SCATTER10_TI) if seed]
    # the coarse cuts of the spacing study whose records an earlier solver made (before the contact's changes of
    # b294aaf and 248e7e0; the fine runs came after them), again with today's: t_u/5 (minutes), then t_u/10
    out += [("pfem", f"case {n}{PFEM}{RERUN}", converged(n, n_tu=5.0), pfem) for n in PFEM5_RERUN_CASES]
    out += [("pfem", f"case {n}{PFEM10}{RERUN}", converged(n, n_tu=10.0), pfem) for n in PFEM10_RERUN_CASES]
    out += [("pfem", f"case {n}{PFEM10}{TO_2MM}", to_2mm(n, n_tu=10.0), pfem) for n in TU_01]
    return out + [("cases", f"case {n}{TO_2MM}", to_2mm(n), sweep_numerics()) for n in TU_01]


def conductivity_jobs() -> dict:
    """{key: (options, numerics)} of the 'conductivity' study: the rake face's sensitivity to the workpiece's
    conductivity (held at its room-temperature value by the paper): Ti6Al4V's k doubled, AISI 1045's at 0.6, each at
    the 'refined' numerics, read against its case's scatter there; the same in the PFEM at t_u/10; and, as case 1's
    x0.6 stalled at 1.56 of 1.6 ms with the trapezoidal rule (the late ringing of cases 8, 9, 12, 14, 16), the PFEM's
    pair again with the Bossak rule, so that the change is read between two runs of one time rule."""
    out = {f"case {n}{REFINED}{COND_KEY}{f:g}": (converged(n, conductivity_factor=f), dict(REFINED_NUMERICS))
           for n, f in CONDUCTIVITY}
    out.update({f"case {n}{PFEM10}{COND_KEY}{f:g}": (converged(n, n_tu=10.0, conductivity_factor=f),
                                                     dict(method="pfem")) for n, f in CONDUCTIVITY})
    for sfx, more in ((" n_tu 10", {}), (f"{COND_KEY}0.6", dict(conductivity_factor=0.6))):
        out[f"case 1{PFEM10}{sfx}{BOSSAK}"] = (dict(converged(1, n_tu=10.0, **more), bossak=BOSSAK_ALPHA),
                                               dict(method="pfem"))
    return out


def reference_update_jobs() -> dict:
    """{key: (options, numerics)} of the 'refupdate' study: how often TLSPH's reference configuration is updated
    (Numerics.ref_update_strain, the largest Green-Lagrange strain |E| it lets grow; the scene's 0.5; the first paper
    says only 'when the deviation is considerable'), at t_u/5 for cases 1 and 10 at REF_UPDATES, the run-to-run
    scatter at REF_UPDATE (case 1, two more seeds), and cases 1 and 10 at t_u/10 at REF_UPDATE: at the scene's 0.5
    the chip carries about half the plastic strain its thickness implies (benchmarks/chip_strain.py)."""
    out = {}
    for n in (1, 10):
        for r in REF_UPDATES:
            out[f"case {n}{COARSE}{REF_KEY}{r:g}"] = (converged(n, n_tu=5.0), dict(ref_update_strain=r))
    for seed in (1, 2):
        out[f"case 1{COARSE}{REF_KEY}{REF_UPDATE:g} jitter {seed}"] = (
            converged(1, n_tu=5.0, jitter=0.01, seed=seed), dict(ref_update_strain=REF_UPDATE))
    for n in range(1, 19):                                   # the 18 cuts at t_u/5 at REF_UPDATE and half the step
        out[f"case {n}{COARSE}{HALF_STEP}"] = (converged(n, n_tu=5.0),
                                               dict(ref_update_strain=REF_UPDATE, courant=COURANT))
    for n, r in REF_FAILED:                                  # the two that failed at t_u/5, at half the step
        out[f"case {n}{COARSE}{REF_KEY}{r:g} courant {COURANT:g}"] = (converged(n, n_tu=5.0),
                                                                      dict(ref_update_strain=r, courant=COURANT))
    for n in (1, 10):
        out[f"case {n}{REF_KEY}{REF_UPDATE:g}"] = (converged(n), sweep_numerics(ref_update_strain=REF_UPDATE))
    # case 1's failed at 0.93 of 1.6 ms; replayed, its trouble starts at 0.81 ms, where two chip-surface particles
    # crowded to 0.33 dx are taken into a fresh reference (history): again at half the step (as 'case 9' + RETRY)
    out[f"case 1{REF_KEY}{REF_UPDATE:g}{RETRY}"] = (converged(1), sweep_numerics(ref_update_strain=REF_UPDATE,
                                                                                 courant=RETRY_COURANT))
    return out


def self_contact_jobs() -> dict:
    """{key: (options, numerics)} of the 'selfcontact' study: TLSPH's particles of one body repel below
    SELF_CONTACT dp (refsph.self_contact; without it the chip's particles pair up, and with frequent reference
    updates such pairs blew up three of the refupdate study's runs). Case 1 at t_u/10 at REF_UPDATE first (it
    failed at 0.93 ms without), then cases 1 and 10 at t_u/5 without self-contact again (RERUN: the record then
    says how crowded the particles are, ``crowding``), with it at the scene's reference update and at
    SELF_REF_UPDATES (0.2 failed for case 10, 0.02 for case 1), case 1's scatter (two more seeds), and case 1 at
    t_u/10 at the scene's reference update."""
    sc = dict(self_contact=SELF_CONTACT)
    out = {f"case 1{REF_KEY}{REF_UPDATE:g}{SELF_KEY}": (converged(1), sweep_numerics(ref_update_strain=REF_UPDATE,
                                                                                      **sc))}
    for n in (10, 1):
        out[f"case {n}{COARSE}{RERUN}"] = (converged(n, n_tu=5.0), {})     # the record with its crowding
        out[f"case {n}{COARSE}{SELF_KEY}"] = (converged(n, n_tu=5.0), dict(sc))
        for r in SELF_REF_UPDATES:
            out[f"case {n}{COARSE}{REF_KEY}{r:g}{SELF_KEY}"] = (converged(n, n_tu=5.0), dict(ref_update_strain=r, **sc))
    for seed in (1, 2):
        out[f"case 1{COARSE}{SELF_KEY} jitter {seed}"] = (converged(1, n_tu=5.0, jitter=0.01, seed=seed), dict(sc))
    out[f"case 1{SELF_KEY}"] = (converged(1), sweep_numerics(**sc))
    # case 10's at the scene's step blew up at 1.22 ms (a hot particle with 4 reference neighbours after an
    # update, thrown to 28 m/s in 5 steps): again at half the step, the sweep's at t_u/10
    out[f"case 10{COARSE}{SELF_KEY} courant {COURANT:g}"] = (converged(10, n_tu=5.0), dict(sc, courant=COURANT))
    # case 1's rerun at the scene's step blew up at 0.77 ms; its record at half the step, again with today's code
    out[f"case 1{COARSE} courant {COURANT:g}{RERUN}"] = (converged(1, n_tu=5.0), dict(courant=COURANT))
    return out


def gain_step_jobs() -> dict:
    """{key: (options, numerics)} of the 'gain' study: the runs that broke down at the scene's courant 0.3 (a
    reference update left a hot chip-tip particle with few neighbours on one side, its correction amplified: the
    history), again at 0.3 with the step divided by the corrected gradient's largest gain (``Numerics.gain_step``):
    case 1 at t_u/5 (its rerun blew up), case 10 at reference update 0.2, case 1 at 0.02, case 10 with
    self-contact, case 1 at s/4 and case 10 with the alpha-shape detector; then case 10 at t_u/10 (the sweep's
    reason for half the step there) and case 1 at t_u/10 at reference update 0.1 (failed at half the step)."""
    g = dict(gain_step=True)
    out = {f"case 1{COARSE}{GAIN_KEY}": (converged(1, n_tu=5.0), dict(g))}
    out.update({f"case {n}{COARSE}{REF_KEY}{r:g}{GAIN_KEY}": (converged(n, n_tu=5.0), dict(g, ref_update_strain=r))
                for n, r in REF_FAILED})
    out.update({f"case 10{COARSE}{SELF_KEY}{GAIN_KEY}": (converged(10, n_tu=5.0), dict(g, self_contact=SELF_CONTACT)),
           f"case 1{COARSE} s/4{GAIN_KEY}": (converged(1, n_tu=5.0, mass_scale=_s(1) / 4), dict(g)),
           f"case 10{COARSE} alpha detector{GAIN_KEY}": (converged(10, n_tu=5.0, detector="alpha"), dict(g)),
           f"case 10{GAIN_KEY}": (converged(10), dict(g))})
    out[f"case 1{REF_KEY}{REF_UPDATE:g}{GAIN_KEY}"] = (converged(1), dict(g, ref_update_strain=REF_UPDATE))
    return out


def to_2mm(n: int, **more) -> dict:
    """The options of case ``n`` cut to the paper's 2 mm (20 t_u for t_u = 0.1 mm) on its 3 mm workpiece."""
    return converged(n, travel=20.0, length=3e-3, **more)


def bossak_cut(n: int, n_tu: float) -> dict:
    """The options of case ``n``'s PFEM cut at t_u / ``n_tu`` with the Bossak-Newmark rule (BOSSAK_ALPHA)."""
    return dict(converged(n, n_tu=n_tu), bossak=BOSSAK_ALPHA)


def retry_jobs(records: dict, studies=STUDY_NAMES) -> dict:
    """The retries (RETRIES) of the t_u/10 tables' cases whose record failed and whose retry is not in jobs(): an
    SPH case 'case N' again at RETRY_COURANT, a PFEM case 'case N pfem' with the Bossak-Newmark rule (key + the
    first of RETRIES[PFEM10]; also where its rerun by today's solver failed), a PFEM cut to 2 mm 'case N pfem 2 mm'
    with it too (key + BOSSAK), a 'refined' case at courant COURANT under the same frequency step (key +
    REFINED_RETRY); the sweep adds them, so that a failed case is taken again without a new line in jobs()."""
    out = {}
    for n in TU_01:
        key = f"case {n}{PFEM10}{TO_2MM}"
        if "pfem" in studies and records.get(key, {}).get("status", "ok") != "ok":
            out[key + BOSSAK] = (dict(to_2mm(n, n_tu=10.0), bossak=BOSSAK_ALPHA), dict(method="pfem"))
    for n in range(1, 19):
        sph, pfem = f"case {n}", f"case {n}{PFEM10}"
        if "cases" in studies and records.get(sph, {}).get("status", "ok") != "ok":
            out[sph + RETRY] = (converged(n), sweep_numerics(courant=RETRY_COURANT))
        if "pfem" in studies and any(records.get(k, {}).get("status", "ok") != "ok" for k in (pfem, pfem + RERUN)):
            out[pfem + RETRIES[PFEM10][0]] = (bossak_cut(n, 10.0), dict(method="pfem"))   # failed, or its rerun
        if "refined" in studies and records.get(f"case {n}{REFINED}", {}).get("status", "ok") != "ok":
            out[f"case {n}{REFINED}{REFINED_RETRY}"] = (converged(n), dict(REFINED_NUMERICS, courant=COURANT))
    return out


def time_rule_jobs() -> list[tuple[str, dict]]:
    """(key, options) of the PFEM cuts with a damped time rule: the damped Newmark rule (DAMPED) for the cases where
    the trapezoidal rule rang and Newton stalled (16, 8, 9 at t_u/10); the damped rule is first-order accurate and
    Bossak-Newmark second, so both on the whole cuts of cases 1 and 8 at t_u/5 (beside their trapezoidal records),
    Bossak on case 16 at t_u/5 (beside its damped run: the trapezoidal rule failed) and on case 8 at t_u/10 (beside
    its damped run)."""
    out = [(f"case {n}{PFEM10}{DAMPED}", dict(converged(n, n_tu=10.0), gamma=DAMPED_GAMMA)) for n in (16, 8, 9)]
    out += [(f"case {n}{PFEM}{suffix}", dict(converged(n, n_tu=5.0), **opts)) for n in (1, 8) for suffix, opts in
            ((f" gamma {DAMPED_GAMMA:g}", dict(gamma=DAMPED_GAMMA)), (BOSSAK, dict(bossak=BOSSAK_ALPHA)))]
    out += [(f"case 16{PFEM}{BOSSAK}", bossak_cut(16, 5.0))]   # beside its gamma 0.6
    return out + [(f"case 8{PFEM10} n_tu 10{BOSSAK}", bossak_cut(8, 10.0))]


def remesh_jobs() -> list[tuple[str, dict]]:
    """(key, options) of the PFEM cuts that remesh only where a triangle's quality falls below 0.3
    (``remesh_when_needed``), beside the sweep's 'case N' + suffix (a remeshing after every step): REMESH_RUNS."""
    return [(f"case {n}{suffix}{REMESH}", dict(converged(n, n_tu=n_tu), remesh_when_needed=True))
            for n, suffix, n_tu in REMESH_RUNS]


def pfem_resolution_jobs() -> list[tuple[str, dict]]:
    """(key, options) of the PFEM cuts finer than the sweep's t_u/10 (PFEM_FINE): case 1 at t_u/15 (from t_u/5 to
    t_u/10 its Fp/Fc rose from 0.33 to 0.40: whether it converges, and to what), and cases 2 and 3 at the paper's
    node spacing, 10 um near the tool (15 and 20 nodes across t_u = 0.15 and 0.20 mm, where t_u/10 is 15 and
    20 um); then AISI 1045's other cases at t_u = 0.15 and 0.20 mm at that spacing (at t_u/10 their rake faces are
    44-118 K hotter than the paper's PFEM, where cases 1, 4 and 7, at 10 um, are within 41 K of it), cases 8 and 9
    with the Bossak rule (PFEM_FINE_BOSSAK), and so at t_u/5 too (:func:`pfem_spacing_keys`: the three spacings of
    one case on one rule; case 8's is the time rule's study's)."""
    fine = [(pfem_fine_key(n, n_tu), bossak_cut(n, n_tu) if n in PFEM_FINE_BOSSAK else converged(n, n_tu=n_tu))
            for n, n_tu in PFEM_FINE]
    taken = {k for k, _ in time_rule_jobs()}
    return fine + [(pfem_spacing_keys(n)[0], bossak_cut(n, 5.0)) for n in PFEM_FINE_BOSSAK
                   if pfem_spacing_keys(n)[0] not in taken]


def pfem_fine_key(n: int, n_tu: float) -> str:
    """The key of case ``n``'s PFEM cut at ``n_tu`` nodes across t_u (PFEM_FINE; BOSSAK for PFEM_FINE_BOSSAK)."""
    return f"case {n}{PFEM10} n_tu {n_tu:g}" + (BOSSAK if n in PFEM_FINE_BOSSAK else "")


QUICK = dict(length=1.2e-3, travel=4.0, n_tu=5.0)   # --quick: chapter 11's short cut at the quick resolution


def run_case(key: str, options: dict, numerics: dict, quick: bool = False) -> dict:
    """One run (continued from its checkpoint if an earlier attempt was killed); its record. ``numerics`` with
    method 'pfem': the PFEM cut (:mod:`refsph.pfem_run`) with the options it takes (PFEM_OPTIONS; its tool is the
    sweep's, TOOL)."""
    from refsph.simulate import SimulationError, run, run_commits
    out = run_folder(key, quick)
    if not quick and study.unpark(PARKED / out.name, out, (options, numerics)):   # parked by an earlier session
        print(f"{key}: continues from its parked checkpoint ({PARKED.relative_to(ROOT) / out.name})", flush=True)
    elif not quick and study.parked_job_differs(PARKED / out.name, (options, numerics)):
        print(f"{key}: its parked checkpoint was made with other options or numerics: not continued", flush=True)
    restart = (out / "snapshots" / "restart.npz").exists()
    t0 = time.perf_counter()
    rec = dict(key=key, options=options, numerics=numerics, quick=quick)
    res = None
    try:
        if numerics.get("method") == "pfem":
            from refsph.pfem_run import run_pfem
            if any(options.get(k, v) != v for k, v in TOOL.items()):
                raise ValueError(f"the PFEM cut's tool is {TOOL}, asked {options}")
            res = run_pfem("thermal_cutting", out=out, progress=False, restart=restart, quick=quick,
                           options={k: options[k] for k in PFEM_OPTIONS if k in options and (k == "case" or not quick)})
        else:
            res = run("thermal_cutting", "tlsph", out=out, progress=False, restart=restart, quick=quick,
                      options=dict(options, **(QUICK if quick else {})), numerics=dict(numerics, threads=1))
        s = res.summary
    except SimulationError as e:
        s = json.loads((out / "summary.json").read_text())
        s.setdefault("error", str(e))
    m = s.get("metrics") or {}
    if s.get("status") == "ok" and m.get("blow_up"):                # ran to the end, but not sane (the metrics)
        s.update(status="blow-up", error=m["blow_up"])
    rec.update(status=s.get("status"), error=s.get("error", "")[:300], n_particles=s.get("n_particles"),
               n_steps=s.get("n_steps"), wall_time_s=s.get("wall_time_s"), cpu_time_s=s.get("cpu_time_s"),
               dp=s.get("dp"),
               scene_info={k: v for k, v in s.get("scene_info", {}).items() if k != "measured"},
               heat_balance=s.get("heat_balance"), restarted=restart,
               metrics={k: m[k] for k in KEEP if k in m},
               histories={k: _thin(m[k]) for k in ("cutting_force_history", "passive_force_history",
                                                     "temperature_history") if k in m})
    if numerics.get("method") != "pfem":                            # how the SPH particles ended, where they broke
        last_good = out / "snapshots" / "last_good.npz"
        if getattr(res, "state", None) is not None:
            rec["crowding"] = crowding(res.state, s.get("dp"))
        if s.get("status") != "ok" and last_good.exists():
            from refsph.kernels import get_kernel
            rec["failure_site"] = failure_site(last_good, s["dp"], get_kernel(s["numerics"]["kernel"]).support * s["h"])
    rec["commits"] = run_commits(s.get("provenance") or {})       # the code that ran it (a restart: each part's)
    if s.get("heat_dissipation"):                                    # the ledger's dissipation split (newer runs)
        rec["heat_dissipation"] = s["heat_dissipation"]
    rec["script_wall_s"] = time.perf_counter() - t0
    return rec


def crowding(state, dp: float) -> dict:
    """How the workpiece's particles have paired up by the end of the cut: the fraction of them with a neighbour
    closer than dp/2, and the closest pair's distance in dp (a lattice at rest: none, 1)."""
    from scipy.spatial import cKDTree
    from refsph.scenes.measure import TOOL_BODY
    x = state.x[state.body != TOOL_BODY]
    d = cKDTree(x).query(x, k=2)[0][:, 1] / dp
    return dict(fraction_below_half_dp=float(np.mean(d < 0.5)), min_distance_dp=float(d.min()))


def failure_site(path: Path, dp: float, support: float) -> dict:
    """Where a failed SPH run broke, from its last good state: the hottest workpiece particle, its temperature, how
    many particles lie within the kernel's support of it in the reference configuration (X: its reference
    neighbours; about 20 inside the body at h = 1.3 dp) and now (x), and its nearest neighbour [dp]."""
    from scipy.spatial import cKDTree
    from refsph.scenes.measure import TOOL_BODY
    with np.load(path) as z:
        work = z["body"] != TOOL_BODY
        x, X, T, v = z["x"][work], z["X"][work], z["T"][work], z["v"][work]
    k, now = int(np.argmax(T)), cKDTree(x)
    return dict(particle=k, T_K=float(T[k]), speed_m_s=float(np.linalg.norm(v[k])),
                reference_neighbours=len(cKDTree(X).query_ball_point(X[k], support)) - 1,
                current_neighbours=len(now.query_ball_point(x[k], support)) - 1,
                nearest_dp=float(now.query(x[k], k=2)[0][1] / dp))


def _thin(a, n: int = 100) -> list:
    a = np.asarray(a, dtype=float)
    idx = np.unique(np.linspace(0, len(a) - 1, min(n, len(a))).astype(int))
    return [[float(v) if np.isfinite(v) else None for v in row] for row in a[idx]]


def store(path: Path = OUT_JSON) -> study.RunStore:
    """The records (``{"runs": {key: record}}``): locked, atomic, shared by sweeps on the same file."""
    return study.RunStore(path)


def load(path: Path = OUT_JSON) -> dict:
    return store(path).load()


# ----------------------------------------------------------------------------- the comparison
def _err(sim, exp) -> float:
    """Percent error as the paper gives it: 100 |sim - exp| / exp."""
    return 100.0 * abs(sim - exp) / exp if sim is not None and np.isfinite(sim) else float("nan")


def comparison(res: dict, suffix: str = "", keys: dict | None = None) -> list[dict]:
    """Per case: refsph, the measurement and the paper's SPH and PFEM, with the percent errors (``suffix``: the
    records 'case N' + suffix, e.g. COARSE; ``keys``: case -> the key to take instead, without retries)."""
    from refsph.paper_data import rla_cutting_case
    from refsph.teaching.plots import cut_record
    rows = []
    for n in range(1, 19):
        c = rla_cutting_case(n)
        # a failed case: its retry at a smaller step, or damped (RETRIES), where one is recorded ok; a case made again
        # by today's solver (REDONE): that run
        key, r = (cut_record(res["runs"], f"case {n}{suffix}", RETRIES.get(suffix, ()), REDONE.get(suffix, ()))
                  if n not in (keys or {})
                  else (keys[n], res["runs"].get(keys[n])))
        status = "to run" if r is None else r["status"]
        m = (r or {}).get("metrics", {})
        ok = r is not None and r["status"] == "ok"
        row = dict(case=n, key=key, material=c["material"], vc=c["vc_m_per_min"], tu=c["tu_mm"], status=status,
                   wall_s=None if r is None else r.get("wall_time_s"),
                   ratio_exp=c["Fp_exp_N"] / c["Fc_exp_N"], ratio_sph=c["Fp_sph_N"] / c["Fc_sph_N"],
                   ratio_pfem=c["Fp_pfem_N"] / c["Fc_pfem_N"])
        for q, key in (("TRF", "rake_face_temperature_K"), ("TFCS", "free_chip_surface_temperature_K")):
            row[f"{q}_exp"], row[f"{q}_sph"], row[f"{q}_pfem"] = c[f"{q}_exp_K"], c[f"{q}_sph_K"], c[f"{q}_pfem_K"]
            row[f"{q}"] = m.get(key) if ok else None
            for src in ("", "_sph", "_pfem"):
                row[f"{q}{src}_err"] = _err(row[f"{q}{src}"], row[f"{q}_exp"])
        row["TRFmax"] = m.get("rake_face_temperature_max_K") if ok else None
        row["TRFmax_err"] = _err(row["TRFmax"], row["TRF_exp"])
        row["ratio"] = m.get("force_ratio") if ok else None
        for src in ("", "_sph", "_pfem"):
            row[f"ratio{src}_err"] = _err(row[f"ratio{src}"], row["ratio_exp"])
        row["Fc_N_per_mm"] = 1e-3 * m["cutting_force_N_per_m"] if ok else None
        row["Fp_N_per_mm"] = 1e-3 * m["passive_force_N_per_m"] if ok else None
        for src in ("exp", "sph", "pfem"):                     # the paper's forces, in N as printed
            row[f"Fc_{src}"], row[f"Fp_{src}"] = c[f"Fc_{src}_N"], c[f"Fp_{src}_N"]
        row["width_mm"] = m.get("width_matching_Fc_mm") if ok else None
        row["chip_mm"], row["contact_mm"] = (m.get("chip_thickness_mm"), m.get("contact_length_mm")) if ok else (None,
                                                                                                            None)
        hb = (r or {}).get("heat_balance") or {}
        row["heat_residual"] = hb.get("residual_rel") if ok else None
        rows.append(row)
    return rows


def _mean(rows, key) -> float:
    v = [r[key] for r in rows if r[key] is not None and np.isfinite(r[key])]
    return float(np.mean(v)) if v else float("nan")


def _rising(values) -> bool | None:
    """True if the values rise strictly, None if one is missing."""
    if any(v is None or not np.isfinite(v) for v in values):
        return None
    return all(b > a for a, b in zip(values, values[1:]))


TREND_NAMES = ("Fc_rises_with_tu", "Fp_rises_with_tu", "TRF_rises_with_vc", "Fc_falls_with_vc")


def _exp_name(name: str) -> str:
    """The measured counterpart of a trend's name: 'Fc_rises_with_tu' -> 'Fc_exp_rises_with_tu'."""
    q, rest = name.split("_", 1)
    return f"{q}_exp_{rest}"


def trends(rows) -> dict:
    """Per material: does Fc (Fp) rise with t_u at every v_c, T_RF rise and Fc fall with v_c at every t_u (refsph
    and measured; TREND_NAMES)? The verdict is None where a case is missing; '<key>_lines' counts (lines that go
    that way, lines with every case recorded, lines), so that a partial sweep still shows the lines it has. The
    measured verdict and counts are taken over the lines refsph has recorded (over every line where it has none)."""
    out = {}
    columns = dict(Fc=("Fc_N_per_mm", "Fc_exp"), Fp=("Fp_N_per_mm", "Fp_exp"), TRF=("TRF", "TRF_exp"))
    for mat in MATERIAL_NAMES:
        get = {(r["vc"], r["tu"]): r for r in rows if r["material"] == mat}
        vcs, tus = sorted({k[0] for k in get}), sorted({k[1] for k in get})
        t = out[mat] = {}
        for name in TREND_NAMES:
            q, along_tu, sign = name.split("_")[0], name.endswith("_tu"), -1.0 if "_falls_" in name else 1.0
            verdicts = {}
            for label, k in zip((name, _exp_name(name)), columns[q]):
                lines = [[get[(v, u)][k] for u in tus] for v in vcs] if along_tu else \
                    [[get[(v, u)][k] for v in vcs] for u in tus]
                verdicts[label] = [_rising([None if x is None else sign * x for x in vals]) for vals in lines]
            have = [v is not None for v in verdicts[name]]      # the measured over refsph's recorded lines only
            for label, vs in verdicts.items():
                known = [v for v, h in zip(vs, have if any(have) else [True] * len(vs)) if h and v is not None]
                t[label] = None if None in vs or not vs else all(known)
                t[label + "_lines"] = (sum(known), len(known), len(vs))
    return out


TREND_STEPS = (("Fc with t_u", "Fc_N_per_mm", "Fc_exp", "tu", "Fc"),
               ("Fp with t_u", "Fp_N_per_mm", "Fp_exp", "tu", "Fp"),
               ("T_RF with v_c", "TRF", "TRF_exp", "vc", "rake_face_temperature_K"),
               ("Fc with v_c", "Fc_N_per_mm", "Fc_exp", "vc", "Fc"))   # (name, column, measured, along, scatter's)


def trend_steps(rows) -> dict:
    """Per material and TREND_STEPS entry, each step along a line (t_u or v_c one value up, the other fixed: two
    steps on each of three lines) as the relative change of refsph and of the measurement: {material: {name:
    (steps with both recorded, of them the same sign, [(fixed value, refsph %, measured %) of those of opposite
    sign])}}."""
    out = {}
    for mat in MATERIAL_NAMES:
        get = {(r["vc"], r["tu"]): r for r in rows if r["material"] == mat}
        vcs, tus = sorted({k[0] for k in get}), sorted({k[1] for k in get})
        out[mat] = {}
        for name, col, exp, along, _ in TREND_STEPS:
            lines = [(v, [get[(v, u)] for u in tus]) for v in vcs] if along == "tu" else \
                [(u, [get[(v, u)] for v in vcs]) for u in tus]
            n, same, other = 0, 0, []
            for fixed, line in lines:
                for a, b in zip(line, line[1:]):
                    if a[col] is None or b[col] is None:
                        continue
                    d, de = 100.0 * (b[col] / a[col] - 1.0), 100.0 * (b[exp] / a[exp] - 1.0)
                    agree = np.sign(d) == np.sign(de)
                    n, same = n + 1, same + agree
                    if not agree:
                        other.append((fixed, d, de))
            out[mat][name] = (n, same, other)
    return out


def _trend_step_lines(sets: dict, noise: dict) -> list[str]:
    """The step-by-step trends table: per refsph set ({label: comparison rows}) and material, each TREND_STEPS
    entry's 'same of steps', and the steps of opposite sign as 'refsph / measured %' at the line's fixed value, with
    the run-to-run scatter of that quantity ({material: scatter()} where measured; sd in percent) and each such
    step's z (:func:`change_z`, two single runs): how far its sign is told from the scatter."""
    lines = []
    for label, rows in sets.items():
        for mat, t in trend_steps(rows).items():
            cells = []
            for name, _, _, along, sd_key in TREND_STEPS:
                n, same, other = t[name]
                unit = "mm" if along == "vc" else "m/min"
                sd = noise.get((label, mat), {}).get(sd_key)
                off = "; ".join(f"{d:+.1f} / {de:+.1f} at {x:g} {unit}"
                                + (f" (z {change_z(d, sd['std_pct']):+.1f})" if sd else "")
                                for x, d, de in other)
                cells.append(f"{same} of {n}" + (f" ({off})" if off else "")
                             + (f", sd {sd['std_pct']:.1f} %" if off and sd else ""))
            lines.append(f"| {label} | {mat} | " + " | ".join(cells) + " |")
    return lines


def _trend_cell(t: dict, name: str) -> str:
    """'yes' / 'no (k of n rise)' (or 'fall') for refsph, with 'k of n lines recorded' where cases are missing; then
    the measured."""
    rising, known, total = t[name + "_lines"]
    verb = "fall" if "_falls_" in name else "rise"
    went, n_exp, _ = t[_exp_name(name) + "_lines"]
    exp = {True: "yes", False: f"no ({went} of {n_exp} {verb})", None: "-"}[t[_exp_name(name)]]
    if not known:
        return f"- / {exp}"
    cell = "yes" if rising == known else f"no ({rising} of {known} {verb})"
    return f"{cell}{'' if known == total else f', {known} of {total} lines recorded'} / {exp}"


TRF_TARGET = 0.15   # issues 22 and 24: mean T_RF error <= 15 % (the rake-face ceiling's cooler face, below)


def _ceiling_law(mat: str):
    """(mu0, Merchant's tan(atan(mu0) - gamma), T -> tan(atan(mu(T)) - gamma)) of ``mat`` under the paper's friction
    law (Eq. (11))."""
    from pfem_rake_friction import rake_friction_bound
    from refsph.contact import CoulombFriction
    from refsph.paper_data import CONTACT_RLA
    from refsph.scenes.thermal_cutting import MATERIALS, RAKE_DEG
    d = MATERIALS[mat]
    law = CoulombFriction(mu0=d["mu0"], q=d["q_friction"], T_room=CONTACT_RLA["T_ref_K"], T_melt=d["T_melt_K"])
    return (d["mu0"], rake_friction_bound(d["mu0"], RAKE_DEG),
            lambda T: rake_friction_bound(float(law.mu(np.array(T))), RAKE_DEG))


def rake_face_ceiling(rows: list) -> list[dict]:
    """Per material: the largest Fp/Fc that friction on the rake face alone can give, Merchant's tan(atan(mu) -
    gamma) for a chip slipping everywhere at mu (no force on the edge or the flank), at the law's mu0 and at mu(T)
    of the measured T_RF (Eq. (11)), with its mean error against the measured Fp/Fc: the smallest mean error a model
    whose thrust comes from the rake face's Coulomb friction can reach ('ceiling'; cases whose measured ratio lies
    above it); also at mu(T) of a rake face TRF_TARGET (15 %) cooler than measured in every case, the coolest the
    issues' T_RF target allows case by case ('error_T_cooler'). ``rows``: :func:`comparison`'s (their measured
    columns only)."""
    out = []
    for mat in MATERIAL_NAMES:
        sel, (mu0, at_mu0, ceiling) = [r for r in rows if r["material"] == mat], _ceiling_law(mat)
        at_T = [ceiling(r["TRF_exp"]) for r in sel]
        at_cooler = [ceiling((1.0 - TRF_TARGET) * r["TRF_exp"]) for r in sel]
        exp = [r["ratio_exp"] for r in sel]
        out.append(dict(material=mat, mu0=mu0, ceiling_mu0=at_mu0,
                        error_mu0=float(np.mean([_err(at_mu0, e) for e in exp])),
                        ceiling_T=(min(at_T), max(at_T)),
                        error_T=float(np.mean([_err(c, e) for c, e in zip(at_T, exp)])),
                        error_T_cooler=float(np.mean([_err(c, e) for c, e in zip(at_cooler, exp)])),
                        cases=len(sel), measured=(min(exp), max(exp)),
                        above={src: sum(r[f"ratio{src}"] > at_mu0 for r in sel if r[f"ratio{src}"] is not None)
                               for src in ("_exp", "_sph", "_pfem", "")},
                        recorded=sum(r["ratio"] is not None for r in sel)))
    return out


def own_ceilings(sets: dict) -> dict:
    """Per material and prediction: how many of its cases' Fp/Fc lie above the rake-face ceiling at mu(T) of its
    own T_RF (:func:`rake_face_ceiling`'s ceiling at the temperature that prediction puts on the rake face), and
    its mean of Fp/Fc over that ceiling. ``sets``: {label: (rows, ratio key, T_RF key)} of :func:`comparison`'s
    rows. Above it, a prediction's thrust does not come from the friction law on the rake face alone."""
    out = {}
    for mat in MATERIAL_NAMES:
        _, _, ceiling = _ceiling_law(mat)
        for label, (rows, rk, tk) in sets.items():
            c = [(r[rk], ceiling(r[tk])) for r in rows
                 if r["material"] == mat and r[rk] is not None and r[tk] is not None]
            x = [v / b if b > 0 else float("inf") for v, b in c]      # (mu(T) <= tan(gamma): no thrust from it)
            out[(mat, label)] = (sum(v > 1.0 for v in x), len(x), float(np.mean(x)) if x else float("nan"))
    return out


def _own_ceiling_lines(rows: list, pfem10: list) -> list[str]:
    sets = {"paper SPH": (rows, "ratio_sph", "TRF_sph"), "paper PFEM": (rows, "ratio_pfem", "TRF_pfem"),
            "refsph SPH": (rows, "ratio", "TRF"), "refsph PFEM": (pfem10, "ratio", "TRF")}
    got = own_ceilings(sets)
    return [f"| {mat} | " + " | ".join(f"{got[(mat, k)][0]} of {got[(mat, k)][1]} ({got[(mat, k)][2]:.2f})"
                                       for k in sets) + " |" for mat in MATERIAL_NAMES]


def force_slopes(sets: dict, noise: dict | None = None) -> list[dict]:
    """Albrecht's separation of each speed line's forces (P. Albrecht, J. Eng. Ind. 82 (1960) 348-357): through the
    line's three cuts (t_u = 0.10, 0.15, 0.20 mm at one v_c) the least-squares lines Fc = Fc0 + c t_u and Fp = Fp0 + p
    t_u. The slope ratio p / c is the Fp/Fc of the force that grows with the chip (the rake face's, if the chip's forces
    are proportional to t_u); the thinnest cut's Fp/Fc splits into Fp0 / Fc, the thrust that does not grow with t_u
    (Albrecht's edge, or ploughing, force, extrapolated to t_u = 0), and (Fp - Fp0) / Fc, the thrust that does. All are
    ratios of forces at one width of cut, so the paper's forces in N and refsph's in N/mm compare directly. ``sets``:
    {label: (rows, Fc key, Fp key)} of :func:`comparison`'s rows; ``noise``: {(label, material): (sd of Fc, sd of Fp)}
    in percent of one run (:func:`scatter`), which gives the slope ratio's standard deviation by propagation (Fc and Fp
    of each cut taken as independent of each other: where they scatter together, this overstates it). Per material and
    speed: Merchant's ceiling at mu0 and at mu(T) of the line's mean measured T_RF (:func:`rake_face_ceiling`), and per
    label (slope ratio, its sd or None, Fp0 / Fc, (Fp - Fp0) / Fc at the thinnest cut), or None where the line lacks a
    cut."""
    out = []
    for mat in MATERIAL_NAMES:
        _, at_mu0, ceiling = _ceiling_law(mat)
        for vc in sorted({r["vc"] for rows, _, _ in sets.values() for r in rows if r["material"] == mat}):
            first = [r for r in next(iter(sets.values()))[0] if r["material"] == mat and r["vc"] == vc]
            fits = {label: _slope_fit([r for r in rows if r["material"] == mat and r["vc"] == vc], fc, fp,
                                      (noise or {}).get((label, mat)))
                    for label, (rows, fc, fp) in sets.items()}
            out.append(dict(material=mat, vc=vc, ceiling_mu0=at_mu0,
                            ceiling_T=ceiling(float(np.mean([r["TRF_exp"] for r in first]))), fits=fits))
    return out


def _complete_line(line, fc: str, fp: str) -> list | None:
    """The rows of one speed line sorted by t_u, or None unless all three cuts have both forces."""
    line = sorted(line, key=lambda r: r["tu"])
    return None if len(line) < 3 or any(r[fc] is None or r[fp] is None for r in line) else line


def _slope_fit(line: list, fc: str, fp: str, sd_pct) -> tuple | None:
    """(p / c, its sd or None, Fp0 / Fc and (Fp - Fp0) / Fc at the thinnest cut) of one line (:func:`force_slopes`)."""
    line = _complete_line(line, fc, fp)
    if line is None:
        return None
    tu = np.array([r["tu"] for r in line])
    Fc, Fp = (np.array([r[k] for r in line], dtype=float) for k in (fc, fp))
    (c, _), (p, p0) = np.polyfit(tu, Fc, 1), np.polyfit(tu, Fp, 1)
    sd = None
    if sd_pct is not None:
        w = (tu - tu.mean()) / np.sum((tu - tu.mean()) ** 2)                     # slope = sum(w_i F_i)
        s_c, s_p = (float(np.sqrt(np.sum((w * F * pct / 100.0) ** 2))) for F, pct in zip((Fc, Fp), sd_pct))
        sd = float(np.hypot(s_p / c, p * s_c / c ** 2))
    return float(p / c), sd, float(p0 / Fc[0]), float((Fp[0] - p0) / Fc[0])      # the parts add up to Fp/Fc


def ratio_parts(rows: list, fc: str, fp: str) -> dict:
    """{case: (Fp0 / Fc, Fp / Fc - Fp0 / Fc, Fp / Fc)} of every case on a speed line with all three cuts: its Fp/Fc
    split into the thrust that does not grow with t_u (the line's intercept Fp0 of :func:`force_slopes`) and the
    rest, what grows with it (and what the line's straight fit leaves over)."""
    out = {}
    for mat, vc in {(r["material"], r["vc"]) for r in rows}:
        line = _complete_line((r for r in rows if r["material"] == mat and r["vc"] == vc), fc, fp)
        if line is None:
            continue
        _, p0 = np.polyfit([r["tu"] for r in line], [r[fp] for r in line], 1)
        out.update({r["case"]: (p0 / r[fc], (r[fp] - p0) / r[fc], r[fp] / r[fc]) for r in line})
    return out


def ratio_part_errors(sets: dict, measured: str = "measured") -> dict:
    """Per (material, label) of ``sets`` (:func:`force_slopes`'): the mean error of Fp/Fc against ``measured``'s over
    the cases both have, and what it would be with the measured intercept's part (the error left is the growing
    part's, |grow - grow_measured| / ratio_measured) or with the measured growing part (the intercept's), so that a
    reader sees which part of the thrust a prediction misses. Returns {(material, label): (n, error, with the
    measured intercept, with the measured growing part)} in percent."""
    parts = {k: ratio_parts(*v) for k, v in sets.items()}
    mat = {r["case"]: r["material"] for r in sets[measured][0]}
    out = {}
    for m in MATERIAL_NAMES:
        for label, got in parts.items():
            both = [(got[c], parts[measured][c]) for c in got if c in parts[measured] and mat[c] == m]
            if label != measured and both:
                out[(m, label)] = (len(both),) + tuple(                       # Fp/Fc, growing part, intercept
                    100 * float(np.mean([abs(a[i] - e[i]) / e[2] for a, e in both])) for i in (2, 1, 0))
    return out


def _sum_text(a: float, b: float) -> str:
    """'a + b' or 'a - b' to two decimals (a minus sign, not '+ -')."""
    return f"{round(a, 2) + 0.0:.2f} {'+' if b >= 0 else '-'} {abs(b):.2f}"


def _slope_lines(slopes: list[dict]) -> list[str]:
    """The table of :func:`force_slopes`, then per material and label the mean slope ratio, the mean of the thinnest
    cut's Fp/Fc split into its two parts, and the speed lines whose slope ratio lies above the ceiling at mu0."""
    labels = list(slopes[0]["fits"])
    cell = lambda f: "-" if f is None else (f"{f[0]:.2f}" + ("" if f[1] is None else f" ± {f[1]:.2f}")  # noqa: E731
                                            + f" ({_sum_text(f[2], f[3])})")
    lines = ["| material | v_c [m/min] | ceiling at mu0 / at mu(the line's mean measured T_RF) | "
             + " | ".join(labels) + " |",
             "|---" * (len(labels) + 3) + "|"]
    lines += [f"| {s['material']} | {s['vc']:.0f} | {s['ceiling_mu0']:.2f} / {s['ceiling_T']:.2f} | "
              + " | ".join(cell(s["fits"][k]) for k in labels) + " |" for s in slopes]
    for mat in MATERIAL_NAMES:
        sel = [s for s in slopes if s["material"] == mat]
        parts = []
        for k in labels:
            got = [(s["fits"][k], s["ceiling_mu0"]) for s in sel if s["fits"][k] is not None]
            if got:
                m = [np.mean([f[i] for f, _ in got]) for i in (0, 2, 3)]
                parts.append(f"{k} {m[0]:.2f} ({_sum_text(m[1], m[2])}), "
                             f"{sum(f[0] > c for f, c in got)} of {len(got)}")
        lines.append(f"\n{mat}, the mean slope ratio (the thinnest cut's Fp/Fc as the mean thrust that does not grow "
                     "with t_u + the mean that does) and the speed lines whose slope ratio lies above the ceiling at "
                     "mu0: " + "; ".join(parts) + ".")
    return lines


def rake_gaps(rows: list, groups: dict) -> list[dict]:
    """Per case, how much hotter the rake face is than the free chip surface, T_RF - T_FCS [K]: measured, the
    paper's SPH and PFEM (``rows``: :func:`comparison`'s) and refsph's ``groups`` ({label: comparison rows}; None
    where a case is not recorded ok)."""
    out = []
    for i, r in enumerate(rows):
        gap = {"measured": r["TRF_exp"] - r["TFCS_exp"], "paper SPH": r["TRF_sph"] - r["TFCS_sph"],
               "paper PFEM": r["TRF_pfem"] - r["TFCS_pfem"]}
        for label, sel in groups.items():
            g = sel[i]
            ok = all(g[q] is not None and math.isfinite(g[q]) for q in ("TRF", "TFCS"))
            gap[label] = g["TRF"] - g["TFCS"] if ok else None
        out.append(dict(case=r["case"], material=r["material"], gap=gap))
    return out


def _rake_gap_lines(gaps: list) -> list[str]:
    """The table of :func:`rake_gaps`, then each material's mean over the cases with every column recorded."""
    labels = list(gaps[0]["gap"])
    lines = ["| case | material | " + " | ".join(labels) + " |", "|---" * (len(labels) + 2) + "|"]
    lines += [f"| {g['case']} | {g['material']} | " + " | ".join(_f(g["gap"][k], ".0f") for k in labels) + " |"
              for g in gaps]
    for mat in MATERIAL_NAMES:
        full = [g for g in gaps if g["material"] == mat and all(v is not None for v in g["gap"].values())]
        if full:
            lines.append(f"| mean ({len(full)} cases) | {mat} | "
                         + " | ".join(f"{np.mean([g['gap'][k] for g in full]):.0f}" for k in labels) + " |")
    return lines


def _ceiling_lines(rows: list) -> list[str]:
    return [f"| {c['material']} | {c['mu0']:.2f} | {c['measured'][0]:.2f}-{c['measured'][1]:.2f} | "
            f"{c['ceiling_mu0']:.3f} | {c['error_mu0']:.1f} | {c['ceiling_T'][0]:.3f}-{c['ceiling_T'][1]:.3f} | "
            f"{c['error_T']:.1f} | {c['error_T_cooler']:.1f} | "
            + " / ".join(str(c["above"][k]) for k in ("_exp", "_sph", "_pfem"))
            + f" / {c['above']['']} of {c['recorded']} |"
            for c in rake_face_ceiling(rows)]


def _force_sd(sc: dict):
    """(sd of Fc, sd of Fp) in percent from :func:`scatter`'s output, or None without both."""
    return (sc["Fc"]["std_pct"], sc["Fp"]["std_pct"]) if "Fc" in sc and "Fp" in sc else None


def _f(v, fmt: str) -> str:
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, fmt)


def report(res: dict, before: dict | None = None) -> str:
    """The page, from the records alone (``before``: issue 19's pinball sweep, ``BEFORE_JSON``, for its mean errors);
    its prose is benchmarks/templates/thermal_cutting_report.md."""
    if before is None and BEFORE_JSON.exists():
        before = json.loads(BEFORE_JSON.read_text())
    P, rows = study.Page("thermal_cutting_report"), comparison(res)
    old = comparison(before) if before else None
    done = [r for r in rows if r["status"] == "ok"]
    lines = [P("head", n_tu=f"{N_TU:g}", travel=f"{TRAVEL:g}", inertia=f"{100 * INERTIA:g}", done=len(done))]
    lines += [_case_line(r) for r in rows] + ["", P("mean_errors")] + _mean_error_lines(rows, old)
    refined = comparison(res, REFINED)
    lines += ["", P("refined_errors")] + _mean_error_lines(refined, old)
    coarse = comparison(res, COARSE)
    lines += ["", P("coarse", done=sum(r["status"] == "ok" for r in coarse))] + [_case_line(r) for r in coarse]
    lines += ["", P("coarse_errors")] + _mean_error_lines(coarse, old)
    pfem = comparison(res, PFEM)
    lines += ["", P("pfem", done=sum(r["status"] == "ok" for r in pfem))] + [_case_line(r) for r in pfem]
    lines += ["", P("pfem_errors")] + _mean_error_lines(pfem, old)
    pfem10 = comparison(res, PFEM10)
    lines += ["", P("pfem10", done=sum(r["status"] == "ok" for r in pfem10))] + [_case_line(r) for r in pfem10]
    lines += ["", P("pfem10_errors")] + _mean_error_lines(pfem10, old)
    lines += ["", P("pfem10_same")] + _same_cases_lines(pfem10)
    lines += ["", P("method_gap")] + _gap_lines(method_gaps(res))
    at2 = {m: paper_length_rows(res, sfx) for m, sfx in (("PFEM", PFEM10), ("SPH", ""))}
    lines += ["", P("paper_length")] + [x for m, rows_ in at2.items() for x in _paper_length_lines(rows_, m)]
    lines += ["", P("paper_length_errors")] + [x for m, rows_ in at2.items() for x in _paper_length_errors(rows_, m)]
    spacing = paper_spacing_rows(res)
    lines += ["", P("paper_spacing", done=sum(r["status"] == "ok" for r in spacing))] + _paper_length_lines(
        spacing, "PFEM")
    lines += ["", P("paper_spacing_errors")] + _same_cases_lines(spacing, ("AISI1045",))
    lines += ["", P("paper_spacing_2mm")] + _paper_length_errors(spacing, "PFEM", ("AISI1045",))
    lines += ["", P("pfem_spacing_orders")] + _pfem_spacing_lines(pfem_spacing_convergence(res))
    lines += ["", pfem_scatter_line(res)]
    lines += ["", P("pfem_forces")] + [_pfem_force_line(r, res) for r in pfem]
    dof = dof_rows(res)
    lines += ["", P("dof", **dof_changes(dof))] + _dof_lines(dof)
    lines += ["", P("forces")]
    for r in rows:
        lines.append(f"| {r['case']} | {_f(r['Fc_N_per_mm'], '.1f')} | {_f(r['Fp_N_per_mm'], '.1f')} | "
                     f"{r['Fc_exp']:.0f}, {r['Fp_exp']:.0f} | {_f(r['width_mm'], '.2f')} | {_f(r['chip_mm'], '.3f')} | "
                     f"{_f(r['contact_mm'], '.3f')} | {_f(r['wall_s'], '.0f')} |")
    lines += ["", P("steady")]
    for r in rows:
        v = _values(res["runs"][r["key"]]) if r["status"] == "ok" else {}
        lines.append(_row([(r["case"], "d")] + [(v.get(key), fmt) for _, key, fmt in STEADY_COLUMNS]))
    lines += ["", P("trends")]
    for label, sel in (("SPH, t_u/10", rows), (f"SPH, t_u/10, ref update {REF_UPDATE:g}", refined),
                       ("SPH, t_u/5", coarse), ("PFEM, t_u/5", pfem), ("PFEM, t_u/10", pfem10)):
        for mat, t in trends(sel).items():
            lines.append(f"| {mat} | {label} | " + " | ".join(_trend_cell(t, n) for n in TREND_NAMES) + " |")
    noise = {(f"SPH, t_u/10, ref update {REF_UPDATE:g}", m): scatter(res, keys) for m, keys in
             (("AISI1045", SCATTER_REF), ("Ti6Al4V", SCATTER_TI10_REF))}
    noise.update({("SPH, t_u/10", m): scatter(res, keys) for m, keys in (("AISI1045", SCATTER_KEYS),
                                                                          ("Ti6Al4V", SCATTER_TI10))})
    noise.update({("PFEM, t_u/10", m): scatter(res, keys) for m, keys in (("AISI1045", PFEM_SCATTER10),   # case 2's
                                                                          ("Ti6Al4V", PFEM_SCATTER10_TI))})  # 10's
    lines += ["", P("trend_steps")] + _trend_step_lines(
        {"SPH, t_u/10": rows, f"SPH, t_u/10, ref update {REF_UPDATE:g}": refined, "PFEM, t_u/10": pfem10}, noise)
    lines += ["", P("rake_ceiling")] + _ceiling_lines(rows)
    lines += ["", P("own_ceiling")] + _own_ceiling_lines(rows, pfem10)
    lines += _thrust_part_lines(res, P, rows, refined, pfem10)
    gaps = rake_gaps(rows, {"refsph SPH": rows, f"refsph SPH, ref update {REF_UPDATE:g}": refined,
                            "refsph PFEM": pfem10})
    lines += ["", P("rake_gap"), ""] + _rake_gap_lines(gaps)
    lines += _study_lines(res)
    todo = [k for k in dict(jobs(), **retry_jobs(res["runs"])) if k not in res["runs"]]
    recorded = [r for r in res["runs"].values() if r.get("wall_time_s")]
    lines += ["", P("total", n=len(recorded), minutes=f"{sum(r['wall_time_s'] for r in recorded) / 60:.1f}",
                    todo=len(todo), keys=", ".join(f"'{k}'" for k in todo) or "none"), ""]
    return "\n".join(lines)


def _thrust_part_lines(res: dict, P, rows: list, refined: list, pfem10: list) -> list[str]:
    """The page's sections on the thrust that grows with t_u and the thrust that does not (:func:`force_slopes`,
    :func:`ratio_part_errors`): measured, the paper's two methods, refsph's SPH at both reference updates and its
    PFEM, each refsph set with its method's run-to-run scatter of the forces."""
    sets = {"measured": (rows, "Fc_exp", "Fp_exp"), "paper SPH": (rows, "Fc_sph", "Fp_sph"),
            "paper PFEM": (rows, "Fc_pfem", "Fp_pfem"), "refsph SPH": (rows, "Fc_N_per_mm", "Fp_N_per_mm"),
            f"refsph SPH, ref update {REF_UPDATE:g}": (refined, "Fc_N_per_mm", "Fp_N_per_mm"),
            "refsph PFEM": (pfem10, "Fc_N_per_mm", "Fp_N_per_mm")}
    noise = {(label, m): _force_sd(scatter(res, keys)) for label, m, keys in
             (("refsph SPH", "AISI1045", SCATTER_KEYS), ("refsph SPH", "Ti6Al4V", SCATTER_TI10),
              (f"refsph SPH, ref update {REF_UPDATE:g}", "AISI1045", SCATTER_REF),
              (f"refsph SPH, ref update {REF_UPDATE:g}", "Ti6Al4V", SCATTER_TI10_REF),
              ("refsph PFEM", "AISI1045", PFEM_SCATTER10), ("refsph PFEM", "Ti6Al4V", PFEM_SCATTER10_TI))}
    lines = ["", P("force_slopes"), ""] + _slope_lines(force_slopes(sets, noise))
    lines += ["", P("ratio_parts"), "", "| material | prediction | cases | Fp/Fc error [%] | with the measured "
              "intercept | with the measured growing part |", "|---|---|---|---|---|---|"]
    return lines + [f"| {m} | {label} | {v[0]} | {v[1]:.1f} | {v[2]:.1f} | {v[3]:.1f} |"
                    for (m, label), v in ratio_part_errors(sets).items()]


def _pfem_force_line(r: dict, res: dict) -> str:
    """A PFEM case's forces next to refsph's SPH at the same spacing, with the cost of each."""
    sph = res["runs"].get(f"case {r['case']}{COARSE}") or {}
    pf = res["runs"].get(f"case {r['case']}{PFEM}") or {}
    m = sph.get("metrics", {}) if sph.get("status") == "ok" else {}
    fc = 1e-3 * m["cutting_force_N_per_m"] if "cutting_force_N_per_m" in m else None
    return (f"| {r['case']} | {_f(r['Fc_N_per_mm'], '.1f')} | {_f(fc, '.1f')} | {_f(r['Fp_N_per_mm'], '.1f')} | "
            f"{_f(r['chip_mm'], '.3f')} | {_f(m.get('chip_thickness_mm'), '.3f')} | {_f(r['contact_mm'], '.3f')} | "
            f"{_f(pf.get('n_particles'), 'd')} | {_f(sph.get('n_particles'), 'd')} | "
            f"{_f(pf.get('wall_time_s'), '.0f')} | {_f(sph.get('wall_time_s'), '.0f')} |")


DOF_QUANTITIES = (("TRF", "T_RF"), ("TFCS", "T_FCS"), ("ratio", "Fp/Fc"))   # the DOF table's errors, in order


def both_ok(rows_a: list, rows_b: list, material: str) -> tuple[list, list]:
    """The rows of two comparison() tables (the same cases, in order) of ``material`` where both runs are 'ok'."""
    pairs = [(a, b) for a, b in zip(rows_a, rows_b) if a["material"] == material and a["status"] == b["status"] == "ok"]
    return [a for a, _ in pairs], [b for _, b in pairs]


def dof_rows(res: dict) -> list[dict]:
    """Degrees of freedom against accuracy, per resolution and material, over the cases both methods ran (t_u / 5:
    the 'pfem' and 'coarse' studies; t_u / 10: the PFEM's and the sweep's tables): the mean node and particle
    counts, DOF (PFEM: u_x, u_y, p per node; SPH: x, y per particle), each method's mean errors (DOF_QUANTITIES)
    and mean wall time, and the paper's SPH and PFEM mean errors on the same cases."""
    out = []
    for label, sfx_pf, sfx_sph in (("t_u/5", PFEM, COARSE), ("t_u/10", PFEM10, "")):
        pf_rows, sph_rows = comparison(res, sfx_pf), comparison(res, sfx_sph)
        for mat in MATERIAL_NAMES:
            pf, sph = both_ok(pf_rows, sph_rows, mat)
            if not pf:
                continue
            n = [round(float(np.mean([res["runs"][r["key"]]["n_particles"] for r in rows]))) for rows in (pf, sph)]
            row = dict(dx=label, material=mat, cases=len(pf), nodes=n[0], dof_pfem=3 * n[0], particles=n[1],
                       dof_sph=2 * n[1], wall_min_pfem=_mean(pf, "wall_s") / 60, wall_min_sph=_mean(sph, "wall_s") / 60)
            for q, _ in DOF_QUANTITIES:
                row.update({f"{q}_pfem": _mean(pf, f"{q}_err"), f"{q}_sph": _mean(sph, f"{q}_err"),
                            f"{q}_paper_pfem": _mean(pf, f"{q}_pfem_err"), f"{q}_paper_sph": _mean(pf, f"{q}_sph_err")})
            out.append(row)
    return out


def dof_changes(rows: list[dict]) -> dict:
    """How the DOF table's mean errors move from t_u / 5 to t_u / 10 (both methods, both materials, DOF_QUANTITIES):
    how many fall and rise (of n), and the smallest and largest change in percentage points."""
    d = [b[f"{q}_{m}"] - a[f"{q}_{m}"] for a in rows for b in rows if a["dx"] == "t_u/5" and b["dx"] == "t_u/10"
         and a["material"] == b["material"] for q, _ in DOF_QUANTITIES for m in ("pfem", "sph")]
    d = [v for v in d if np.isfinite(v)]
    return dict(n=len(d), fall=sum(v < 0 for v in d), rise=sum(v > 0 for v in d),
                lo=f"{min(d, default=math.nan):+.1f}", hi=f"{max(d, default=math.nan):+.1f}")


def _dof_lines(rows: list[dict]) -> list[str]:
    """The DOF table's rows (dof_rows); wall time at t_u / 5 only (t_u / 10: runs three and four at a time, page)."""
    lines = []
    for r in rows:
        cells = [r["dx"], r["material"], str(r["cases"]), f"{r['nodes']} / {r['dof_pfem']}",
                 f"{r['particles']} / {r['dof_sph']}"]
        cells += [f"{r[f'{q}_pfem']:.1f} / {r[f'{q}_sph']:.1f}" for q, _ in DOF_QUANTITIES]
        cells.append(f"{r['wall_min_pfem']:.1f} / {r['wall_min_sph']:.1f}" if r["dx"] == "t_u/5" else "-")
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def _mean_error_lines(rows: list, old: list | None) -> list[str]:
    """The mean-error table's rows: per material and quantity, refsph's, issue 19's ('before'), the paper's."""
    lines = []
    for mat in MATERIAL_NAMES:
        sel = [r for r in rows if r["material"] == mat]
        was = [r for r in old if r["material"] == mat] if old else None
        ran = [r for r in sel if r["status"] == "ok"]
        for q, name in (("TRF", "T_RF, contact mean"), ("TRFmax", "T_RF, hottest contact particle"),
                        ("TFCS", "T_FCS"), ("ratio", "Fp/Fc")):
            paper = ("", "") if q == "TRFmax" else (f"{_mean(sel, f'{q}_sph_err'):.1f}",
                                                   f"{_mean(sel, f'{q}_pfem_err'):.1f}")
            lines.append(f"| {mat} | {name} | {_f(_mean(sel, f'{q}_err'), '.1f')} | "
                         f"{_f(_mean(was, f'{q}_err'), '.1f') if was else '-'} | {paper[0]} | {paper[1]} | "
                         f"{len(ran)} of {len(sel)} |")
    return lines


def _same_cases_lines(rows: list, materials=MATERIAL_NAMES) -> list[str]:
    """refsph's PFEM against the paper's on the cases refsph recorded: each one's mean error there (against the
    measurement), and refsph's mean and range of signed differences from the paper's PFEM prediction (percent); a
    row per quantity of each of ``materials``."""
    lines = []
    for mat in materials:
        ran = [r for r in rows if r["material"] == mat and r["status"] == "ok"]
        for q, name in (("TRF", "T_RF, contact mean"), ("TFCS", "T_FCS"), ("ratio", "Fp/Fc")):
            d = [100.0 * (r[q] / r[f"{q}_pfem"] - 1.0) for r in ran]
            diff = f"{np.mean(d):+.1f} ({min(d):+.0f} to {max(d):+.0f})" if d else "-"
            lines.append(f"| {mat} | {name} | {len(ran)} | {_f(_mean(ran, f'{q}_err'), '.1f')} | "
                         f"{_f(_mean(ran, f'{q}_pfem_err'), '.1f')} | {diff} |")
    return lines


GAP_QUANTITIES = (("TRF", "T_RF [K]", "K"), ("TFCS", "T_FCS [K]", "K"), ("Fc", "Fc [%]", "%"),
                  ("ratio", "Fp/Fc [%]", "%"))   # the PFEM-SPH gap: in kelvin for temperatures, relative for forces


def method_gaps(res: dict) -> list[dict]:
    """Per case with both of refsph's methods recorded at t_u/10: the PFEM's value minus the SPH's (temperatures in
    K; Fc and Fp/Fc as PFEM/SPH - 1 in percent), refsph's and the paper's (its Appendix B predictions): whether
    refsph's two methods differ as the paper's do."""
    from refsph.paper_data import rla_cutting_case
    sph, pfem = comparison(res), comparison(res, PFEM10)
    out = []
    need = ("TRF", "TFCS", "Fc_N_per_mm", "ratio")
    for a, b in zip(sph, pfem):
        if a["status"] != "ok" or b["status"] != "ok" or any(r[k] is None for r in (a, b) for k in need):
            continue
        c = rla_cutting_case(a["case"])
        ours = dict(TRF=b["TRF"] - a["TRF"], TFCS=b["TFCS"] - a["TFCS"],
                    Fc=100.0 * (b["Fc_N_per_mm"] / a["Fc_N_per_mm"] - 1.0),
                    ratio=100.0 * (b["ratio"] / a["ratio"] - 1.0))
        paper = dict(TRF=c["TRF_pfem_K"] - c["TRF_sph_K"], TFCS=c["TFCS_pfem_K"] - c["TFCS_sph_K"],
                     Fc=100.0 * (c["Fc_pfem_N"] / c["Fc_sph_N"] - 1.0),
                     ratio=100.0 * (a["ratio_pfem"] / a["ratio_sph"] - 1.0))
        out.append(dict(case=a["case"], material=a["material"], ours=ours, paper=paper,
                        retried=a["key"] != f"case {a['case']}"
                        or b["key"] not in (f"case {a['case']}{PFEM10}", f"case {a['case']}{PFEM10}{RERUN}")))
    return out


def _gap_lines(gaps: list) -> list[str]:
    """The gap table's rows, then per material the means and on how many cases refsph's gap has the paper's sign."""
    lines = [f"| {g['case']}{' †' if g['retried'] else ''} | {g['material']} | "
             + " | ".join(f"{g['ours'][q]:+.0f} | {g['paper'][q]:+.0f}" for q, _, _ in GAP_QUANTITIES) + " |"
             for g in gaps]
    for mat in MATERIAL_NAMES:
        sel = [g for g in gaps if g["material"] == mat]
        if not sel:
            continue
        cells = []
        for q, _, _ in GAP_QUANTITIES:
            same = sum(np.sign(g["ours"][q]) == np.sign(g["paper"][q]) for g in sel)
            cells.append(f"{np.mean([g['ours'][q] for g in sel]):+.0f} | {np.mean([g['paper'][q] for g in sel]):+.0f}"
                         f" (same sign: {same} of {len(sel)})")
        lines.append(f"| mean | {mat} | " + " | ".join(cells) + " |")
    return lines


def window_means(rec: dict | None, vc: float, a: float, b: float) -> dict | None:
    """Means over the tool's travel a..b [m] (v_c t) of a record's histories (about 100 points over its cut): T_RF,
    T_FCS [K] and Fp/Fc (the ratio of the mean forces, as the metrics); None where the run is not 'ok' or did not
    reach b."""
    h = rec.get("histories") if rec and rec.get("status") == "ok" else None
    if not h:
        return None
    T = np.array(h["temperature_history"], dtype=float)          # rows (t, T_RF, T_FCS); None -> nan
    Fc, Fp = (np.array(h[k], dtype=float) for k in ("cutting_force_history", "passive_force_history"))
    if vc * T[-1, 0] < b * (1.0 - 1e-6):
        return None

    def mean(rows, col):
        s = vc * rows[:, 0]
        v = rows[(s >= a) & (s <= b * (1.0 + 1e-9)), col]
        return float(v[np.isfinite(v)].mean()) if np.isfinite(v).any() else float("nan")
    return dict(TRF=mean(T, 1), TFCS=mean(T, 2), ratio=mean(Fp, 1) / mean(Fc, 1))


def paper_length_rows(res: dict, suffix: str, keys: dict | None = None) -> list[dict]:
    """The comparison rows (``suffix``: "" the SPH, PFEM10 the PFEM, both at t_u / 10; ``keys`` as comparison's)
    with each quantity also at the paper's length of cut: means over PAPER_CUT of the tool's travel, from the case's
    own run where its cut is longer (t_u = 0.15, 0.20 mm), else from its run cut to 2 mm ('case N' + suffix +
    TO_2MM); '2mm' the values (None where neither has run), 'key2' the run they come from."""
    rows = comparison(res, suffix, keys)
    for r in rows:
        longer = f"case {r['case']}{suffix}{TO_2MM}"                # or, where it failed, its Bossak retry
        key2 = next((k for k in (longer, longer + BOSSAK) if res["runs"].get(k, {}).get("status") == "ok"), r["key"])
        w = window_means(res["runs"].get(key2), r["vc"] / 60.0, *PAPER_CUT)
        r["key2"] = key2 if w else None
        r["2mm"] = {q: (v, _err(v, r[f"{q}_exp"])) for q, v in w.items()} if w else None
    return rows


def paper_spacing_rows(res: dict) -> list[dict]:
    """AISI 1045's nine PFEM cuts at the paper's node spacing, 10 um near the tool (its Figure 5): the t_u = 0.1 mm
    cases' t_u/10 runs (PFEM10, with their retries), the others' PFEM_FINE runs (pfem_fine_key), as
    :func:`paper_length_rows`."""
    keys = {n: pfem_fine_key(n, n_tu) for n, n_tu in PFEM_FINE if n not in TU_01}
    return [r for r in paper_length_rows(res, PFEM10, keys) if r["material"] == "AISI1045"]


def pfem_spacing_keys(n: int) -> tuple:
    """Case ``n``'s PFEM cuts at three node spacings near the tool, coarsest first: t_u/5 (PFEM), t_u/10 (PFEM10)
    and PFEM_FINE's (pfem_fine_key: 10 um, t_u/15 for case 1); a PFEM_FINE_BOSSAK case on the Bossak rule at
    every spacing, so that only the spacing changes; a PFEM_RERUN_CASES case's coarse cuts made again with today's
    solver (key suffix RERUN), so that only the spacing changes, not the solver."""
    rule = BOSSAK if n in PFEM_FINE_BOSSAK else ""
    fine = dict(PFEM_FINE)[n]
    again = RERUN if n in PFEM_RERUN_CASES else ""             # the coarse runs again with the fine runs' solver
    return (f"case {n}{PFEM}{rule}{again}", f"case {n}{PFEM10}" + (f" n_tu 10{rule}" if rule else "") + again,
            pfem_fine_key(n, fine))


PFEM_ORDER_MIN = 0.5    # below this observed order the extrapolation of pfem_spacing_convergence is not made: its
#                         correction would be many times the last change (case 8's T_FCS at p = 0.2: +356 K on +28 K)
PFEM_ORDER_QUANTITIES = (("T_RF [K]", "rake_face_temperature_K", ".0f", "TRF"),
                         ("T_FCS [K]", "free_chip_surface_temperature_K", ".0f", "TFCS"),
                         ("Fc [N/mm]", "Fc", ".1f", None), ("Fp [N/mm]", "Fp", ".1f", None),
                         ("Fp/Fc", "force_ratio", ".3f", "ratio"))


def pfem_spacing_convergence(res: dict) -> list[dict]:
    """Per case of PFEM_FINE with its three spacings recorded (:func:`pfem_spacing_keys`) and per quantity: the
    values f at dx = t_u/5, t_u/10 and the fine spacing, the changes in percent, the observed order p of
    f = f0 + C dx^p (``study.observed_order``; None where the changes differ in sign or grow) and the extrapolated
    f0 (``study.richardson``; None below PFEM_ORDER_MIN), beside the measured value and the paper's PFEM
    (``comparison``); z1, z2: each change over its standard deviation, from the relative spread at each spacing
    (:func:`pfem_scatter_of`: measured on case 2, taken for the other cases; NaN where not recorded)."""
    paper_rows, out = {r["case"]: r for r in comparison(res, PFEM10)}, []   # its measured and paper columns only
    for n in sorted(dict(PFEM_FINE)):
        keys = pfem_spacing_keys(n)
        runs = [res["runs"].get(k) for k in keys]
        missing = [f"'{k}'" + ("" if r is None else f" ({r.get('status')})") for k, r in zip(keys, runs)
                   if r is None or r.get("status") != "ok"]
        if missing:
            out.append(dict(case=n, keys=missing, name=None))
            continue
        vals, c = [_values(r) for r in runs], paper_rows[n]
        h = [v["dx_um"] for v in vals]
        spreads = [pfem_scatter_of(res, k) for k in keys]    # case 2's (or case 10's) for every case: an assumption
        for name, q, spec, paper in PFEM_ORDER_QUANTITIES:
            f = [float(v[q]) for v in vals]
            p = study.observed_order(h, f)
            f0 = study.richardson(h, f, p) if p is not None and PFEM_ORDER_MIN <= p < math.inf else None
            exp, pfem = (c[f"{paper}_exp"], c[f"{paper}_pfem"]) if paper else (None, None)
            s = [sp[q]["std_pct"] / 100 if q in sp else math.nan for sp in spreads]   # relative, per spacing
            z1, z2 = (_z(f[i + 1] - f[i], math.hypot(s[i] * f[i], s[i + 1] * f[i + 1])) for i in (0, 1))
            out.append(dict(case=n, keys=keys, name=name, spec=spec, h=h, f=f, p=p, f0=f0, exp=exp, pfem=pfem,
                            d1=_rel(f[1], f[0]), d2=_rel(f[2], f[1]), z1=z1, z2=z2))
    return out


def solver_changes(res: dict) -> dict:
    """Per quantity of PFEM_ORDER_QUANTITIES, over the (record, rerun) pairs of SOLVER_CHANGES both recorded ok: the
    changes 100 (rerun - record) / record, and each change's z against the PFEM's run-to-run scatter at the pair's
    spacing (:func:`pfem_scatter_of`), the change over its standard deviation as a change between two single runs
    (:func:`change_z`). {name: [(key, change, z)]}; z NaN where the scatter is not recorded."""
    pairs = [(new, _values(res["runs"][old]), _values(res["runs"][new]), pfem_scatter_of(res, new))
             for old, new in zip(SOLVER_CHANGES[::2], SOLVER_CHANGES[1::2])
             if all(res["runs"].get(k, {}).get("status") == "ok" for k in (old, new))]   # each pair's scatter once
    out = {}
    for name, q, _, _ in PFEM_ORDER_QUANTITIES:
        out[name] = []
        for new, va, vb, sc in pairs:
            d = _rel(vb[q], va[q])
            out[name].append((new, d, change_z(d, sc[q]["std_pct"] if q in sc else math.nan)))
    return out


def solver_changes_line(res: dict) -> str:
    """What :func:`solver_changes` says: per quantity, the pairs recorded, the mean and the largest |change|, and how
    many changes lie beyond twice their standard deviation from the PFEM's run-to-run scatter."""
    ch = solver_changes(res)
    parts = []
    for name, rows in ch.items():
        if not rows:
            continue
        d = np.array([r[1] for r in rows])
        z = np.array([r[2] for r in rows])
        big = max(rows, key=lambda r: abs(r[1]))
        known = np.isfinite(z)
        beyond = "" if not known.any() else (f", {int(np.sum(np.abs(z[known]) > 2))} of {int(known.sum())} beyond 2 "
                                             "sd" + (f" ({int((~known).sum())} without a scatter yet)"
                                                     if not known.all() else ""))
        parts.append(f"{name.split(' [')[0]} mean |change| {np.mean(np.abs(d)):.1f} %, largest {big[1]:+.1f} % "
                     f"('{big[0]}'){beyond}")
    n = max((len(r) for r in ch.values()), default=0)
    if n == 0:
        return "No record and its rerun both recorded yet."
    return (f"Over the {n} pairs recorded, rerun against record: " + "; ".join(parts) + ". The standard deviation of "
            "a change between two single runs is the hypot of the two runs' own, each the PFEM's run-to-run scatter "
            "at the pair's spacing (case 2's at t_u/5 or at t_u/10, taken at every case of its material: an "
            "assumption); with the spread from 3-4 runs, a change within about 2 sd is not told from the scatter.")


def pfem_scatter_of(res: dict, key: str) -> dict:
    """The PFEM's run-to-run scatter (:func:`scatter`) at the node spacing and of the material of the PFEM run
    ``key`` (its record's n_tu, or t_u / dx, and case; a run not recorded: from its key, suffix PFEM at t_u/5, else
    t_u/10): PFEM_SCATTER's (case 2 at t_u/5) for a run at t_u/5 or coarser, of either material; for a finer one
    PFEM_SCATTER10's (case 2 at t_u/10) for AISI 1045 and PFEM_SCATTER10_TI's (case 10 at t_u/10) for Ti6Al4V. An
    assumption wherever it is not the measured case and spacing."""
    from refsph.paper_data import rla_cutting_case
    if " pfem" not in key:
        raise ValueError(f"not a PFEM run: {key!r}")
    r = res["runs"].get(key) or {}
    opts = r.get("options") or {}
    if "n_tu" in opts:
        n_tu = float(opts["n_tu"])
    elif r.get("dp") and r.get("scene_info", {}).get("tu_m"):
        n_tu = r["scene_info"]["tu_m"] / r["dp"]
    else:
        n_tu = 5.0 if PFEM in key else 10.0
    if n_tu < 7.5:
        return scatter(res, PFEM_SCATTER)
    ti = rla_cutting_case(int(opts.get("case", key.split()[1])))["material"] == "Ti6Al4V"
    return scatter(res, PFEM_SCATTER10_TI if ti else PFEM_SCATTER10)


def _pfem_scatter_sentence(res: dict, keys: tuple, where: str, old_key: str) -> str:
    """One scatter group of the PFEM (``keys``, named by ``where``, the sentence's opening): each quantity's sample
    standard deviation in percent of the mean, and how far ``old_key`` (where given), the same cut by an earlier
    solver, lies from that mean, in percent and (in brackets) in standard deviations of one run."""
    sc = scatter(res, keys)
    n = min((v["n"] for v in sc.values()), default=0)
    if n < 2:
        n = len([k for k in keys if res["runs"].get(k, {}).get("status") == "ok"])
        return f"{where}: {n} of {len(keys)} runs recorded, too few for a spread."
    old = res["runs"].get(old_key)
    v_old = _values(old) if old is not None and old.get("status") == "ok" else {}
    parts, away = [], []
    for name, q, _, _ in PFEM_ORDER_QUANTITIES:
        if q not in sc:
            continue
        short, mean, sd = name.split(" [")[0], sc[q]["mean"], sc[q]["std_pct"] / 100 * abs(sc[q]["mean"])
        parts.append(f"{short} {sc[q]['std_pct']:.1f} %")
        if q in v_old:
            away.append(f"{short} {_change_cell(_rel(v_old[q], mean), _z(v_old[q] - mean, sd))}")
    if not old_key:
        return f"{where}, {n} runs: " + ", ".join(parts) + "."
    return (f"{where}, {n} runs: " + ", ".join(parts) + f"; the sweep's first record of the same cut ('{old_key}', "
            "made by an earlier solver; the tables take its rerun, the first of these runs) lies from their mean by "
            + (", ".join(away) or "-") + ".")


def pfem_scatter_line(res: dict) -> str:
    """The PFEM's run-to-run scatter, today's solver, unperturbed and jittered: case 2 at t_u/5 (PFEM_SCATTER) and
    at t_u/10 (PFEM_SCATTER10), case 10 at t_u/10 (PFEM_SCATTER10_TI). Each quantity's sample standard deviation in
    percent of the mean, and how far the sweep's first record of case 2's cut, made by an earlier solver, lies from
    the mean in those units."""
    return ("The PFEM's run-to-run scatter (today's solver, unperturbed and with each coordinate of the workpiece's "
            "nodes moved at random by up to 0.01 of their spacing; the tables 'The PFEM's run-to-run scatter' "
            "below), sample standard deviation in percent of the mean (in brackets after a change: the change in "
            "standard deviations of one run). "
            + _pfem_scatter_sentence(res, PFEM_SCATTER, f"Case {PFEM_SCATTER_CASE} at t_u/5",
                                     f"case {PFEM_SCATTER_CASE}{PFEM}")
            + " " + _pfem_scatter_sentence(res, PFEM_SCATTER10, "At t_u/10", f"case {PFEM_SCATTER_CASE}{PFEM10}")
            + " " + _pfem_scatter_sentence(res, PFEM_SCATTER10_TI, "Case 10 (Ti6Al4V) at t_u/10", "")
            + " The spacing changes above carry their z in brackets: the change over its standard deviation, "
            "sqrt((s_a f_a)^2 + (s_b f_b)^2) with s each spacing's relative spread (case 2's, taken for every case, "
            "and t_u/10's taken at the finer spacing: assumptions, the scatter being measured on case 2 at t_u/5 and "
            "t_u/10 only).")


def _pfem_spacing_lines(rows: list) -> list[str]:
    """The table of :func:`pfem_spacing_convergence`; a case still to run as one line naming its missing keys (a
    failed record with its status)."""
    lines = ["", "| case | quantity | dx [um] | t_u/5 | t_u/10 | fine | t_u/5 -> 10 | t_u/10 -> fine | observed order "
             "| extrapolated | measured | paper PFEM |", "|---" * 12 + "|"]
    for r in rows:
        if r["name"] is None:
            lines.append(f"| {r['case']} | to run: " + ", ".join(r["keys"]) + " |" + " |" * 10)
            continue
        spec = r["spec"]
        order = ("changes differ in sign or grow" if r["p"] is None else
                 "above 20" if not math.isfinite(r["p"]) else f"{r['p']:.1f}")
        cells = [r["case"], r["name"], " / ".join(f"{x:.0f}" for x in r["h"])] + [_f(x, spec) for x in r["f"]] + [
            _change_cell(r["d1"], r["z1"]), _change_cell(r["d2"], r["z2"]), order, _f(r["f0"], spec),
            _f(r["exp"], spec), _f(r["pfem"], spec)]
        lines.append("| " + " | ".join(str(x) for x in cells) + " |")
    return lines


def _paper_length_lines(rows: list, method: str) -> list[str]:
    """The table of :func:`paper_length_rows` (``method``: 'SPH' or 'PFEM', whose paper column it shows)."""
    src, lines = f"_{method.lower()}", []
    for r in rows:
        w = r["2mm"] or {}
        cells = [f"{r['case']}", r["material"], f"{r['tu']:.2f}", f"'{r['key2']}'" if r["key2"] else "-"]
        for q, fmt in (("TRF", ".0f"), ("TFCS", ".0f"), ("ratio", ".2f")):
            v, e = w.get(q, (None, float("nan")))
            cells += [f"{_f(v, fmt)} ({_f(e, '.0f')} %)", f"{_f(r[q], fmt)} ({_f(r[f'{q}_err'], '.0f')} %)",
                      format(r[f"{q}_exp"], fmt), f"{format(r[q + src], fmt)} ({r[q + src + '_err']:.0f} %)"]
        lines.append(f"| {method} | " + " | ".join(cells) + " |")
    return lines


def _paper_length_errors(rows: list, method: str, materials=MATERIAL_NAMES) -> list[str]:
    """Mean errors per material (of ``materials``) over the cases with a value at 2 mm: at 2 mm, at 16 t_u, the
    paper's method."""
    lines, src = [], f"_{method.lower()}"
    for mat in materials:
        got = [r for r in rows if r["material"] == mat and r["2mm"] and r["status"] == "ok"]
        for q, name in (("TRF", "T_RF, contact mean"), ("TFCS", "T_FCS"), ("ratio", "Fp/Fc")):
            at2 = float(np.mean([r["2mm"][q][1] for r in got])) if got else float("nan")
            lines.append(f"| {method} | {mat} | {name} | {len(got)} of 9 | {_f(at2, '.1f')} | "
                         f"{_f(_mean(got, f'{q}_err'), '.1f')} | {_f(_mean(got, f'{q}{src}_err'), '.1f')} |")
    return lines


def _case_line(r: dict) -> str:
    """A case's row of the temperatures and force ratio."""
    status = r["status"] + (f" (courant {RETRY_COURANT:g})" if r["key"].endswith(RETRY) else
                            f" (gamma {DAMPED_GAMMA:g})" if r["key"].endswith(DAMPED) else
                            f" (Bossak {BOSSAK_ALPHA:g})" if r["key"].endswith(BOSSAK) else
                            " (rerun)" if r["key"].endswith(RERUN) else "")
    return (f"| {r['case']} | {r['material']} | {r['vc']:.0f} | {r['tu']:.2f} | {status} | "
            f"{_f(r['TRF'], '.0f')} ({_f(r['TRF_err'], '.0f')} %) | {_f(r['TRFmax'], '.0f')} | {r['TRF_exp']:.0f} | "
            f"{r['TRF_sph']:.0f} ({r['TRF_sph_err']:.0f} %) | {r['TRF_pfem']:.0f} ({r['TRF_pfem_err']:.0f} %) | "
            f"{_f(r['TFCS'], '.0f')} ({_f(r['TFCS_err'], '.0f')} %) | {r['TFCS_exp']:.0f} | "
            f"{r['TFCS_sph']:.0f} ({r['TFCS_sph_err']:.0f} %) | {r['TFCS_pfem']:.0f} ({r['TFCS_pfem_err']:.0f} %) | "
            f"{_f(r['ratio'], '.2f')} ({_f(r['ratio_err'], '.0f')} %) | {r['ratio_exp']:.2f} | "
            f"{r['ratio_sph']:.2f} ({r['ratio_sph_err']:.0f} %) | "
            f"{r['ratio_pfem']:.2f} ({r['ratio_pfem_err']:.0f} %) |")


def _row(cells) -> str:
    """A Markdown table row from (value, format) pairs ('-' for a missing value)."""
    return "| " + " | ".join(_f(v, fmt) for v, fmt in cells) + " |"


def _values(r: dict) -> dict:
    """A run's metrics with the derived columns of the study tables: forces per mm, resolution, the drifts over the
    last quarter, and where the tool's work went (heat ledger over the tool's work)."""
    m, hb = r.get("metrics") or {}, r.get("heat_balance") or {}
    drift = m.get("drift_last_quarter") or {}
    work = m.get("tool_work_J_per_m", math.nan)
    out = dict(m, Fc=1e-3 * m.get("cutting_force_N_per_m", math.nan),
               Fp=1e-3 * m.get("passive_force_N_per_m", math.nan), dx_um=1e6 * r["dp"],
               across=r["scene_info"]["tu_m"] / r["dp"], n_particles=r.get("n_particles"), n_steps=r.get("n_steps"),
               wall=r.get("wall_time_s"), lost=hb.get("lost_J"),
               cpu_min=(r.get("cpu_time_s") or math.nan) / 60.0,
               made=sum(hb.get(k, math.nan) for k in ("plastic_J", "friction_J", "dissipation_J")),
               residual=hb.get("residual_rel"),
               ref_update=(r.get("numerics") or {}).get("ref_update_strain", SCENE_REF_UPDATE),
               self_contact=(r.get("numerics") or {}).get("self_contact"),
               crowded_pct=100.0 * (r.get("crowding") or {}).get("fraction_below_half_dp", math.nan),
               closest_dp=(r.get("crowding") or {}).get("min_distance_dp", math.nan))
    for key, name in (("cutting_force_N_per_m", "Fc"), ("passive_force_N_per_m", "Fp")):
        out[f"{name}_drift_pct"] = 100.0 * drift.get(key, math.nan) / m.get(key, math.nan)
    for key, name in (("rake_face_temperature_K", "TRF"), ("free_chip_surface_temperature_K", "TFCS")):
        out[f"{name}_drift"] = drift.get(key, math.nan)
    for key in ("plastic_J", "friction_J", "dissipation_J", "removed_J", "lost_J"):
        out[f"{key[:-2]}_of_work"] = 100.0 * hb.get(key, math.nan) / work
    out["made_of_work"] = 100.0 * out["made"] / work
    out["gap"] = (m.get("rake_face_temperature_K") or math.nan) - (m.get("free_chip_surface_temperature_K") or math.nan)
    damping = (r.get("heat_dissipation") or {}).get("contact_damping_J")
    out["damping_of_work"] = math.nan if damping is None else 100.0 * damping / work
    return out


STEADY_COLUMNS = (("Fc drift [%]", "Fc_drift_pct", ".1f"), ("Fp drift [%]", "Fp_drift_pct", ".1f"),
                  ("T_RF drift [K]", "TRF_drift", ".0f"), ("T_FCS drift [K]", "TFCS_drift", ".0f"),
                  ("plastic heat [% of work]", "plastic_of_work", ".1f"),
                  ("friction heat [%]", "friction_of_work", ".1f"),
                  ("viscosity + contact damping heat [%]", "dissipation_of_work", ".1f"),
                  ("all heat made [%]", "made_of_work", ".1f"), ("removed at held faces [%]", "removed_of_work", ".1f"),
                  ("ledger residual", "residual", ".0e"))
BASIC = (("Fc [N/mm]", "Fc", ".1f"), ("Fp [N/mm]", "Fp", ".1f"), ("Fp/Fc", "force_ratio", ".3f"),
         ("T_RF [K]", "rake_face_temperature_K", ".0f"), ("T_RF max [K]", "rake_face_temperature_max_K", ".0f"),
         ("T_FCS [K]", "free_chip_surface_temperature_K", ".0f"), ("chip [mm]", "chip_thickness_mm", ".3f"),
         ("contact [mm]", "contact_length_mm", ".3f"))
SCATTER_KEYS = ("case 1", "case 1 jitter 1", "case 1 jitter 2", "case 1 jitter 3")   # the scatter at t_u/10
PFEM_SCATTER_CASE = 2
PFEM_SCATTER = (f"case {PFEM_SCATTER_CASE}{PFEM}{RERUN}",) + tuple(f"case {PFEM_SCATTER_CASE}{PFEM} jitter {seed}"
                                                      for seed in (1, 2, 3))   # the PFEM's scatter (more_jobs)
PFEM_SCATTER10 = (f"case {PFEM_SCATTER_CASE}{PFEM10}{RERUN}",) + tuple(
    f"case {PFEM_SCATTER_CASE}{PFEM10} jitter {seed}" for seed in (1, 2, 3))   # ... at t_u/10 (more_jobs)
PFEM_SCATTER10_TI = (f"case 10{PFEM10}",) + tuple(f"case 10{PFEM10} jitter {seed}" for seed in (1, 2, 3))  # Ti6Al4V
SCATTER_T5 = tuple(k.replace("case 1", "case 1 n_tu 5") for k in SCATTER_KEYS)         # at t_u/5
SCATTER_S2 = tuple(k.replace("n_tu 5", "n_tu 5 s/2") for k in SCATTER_T5)               # at t_u/5 and s/2
SCATTER_TI10 = ("case 10", "case 10 jitter 1", "case 10 jitter 2")                     # Ti6Al4V at t_u/10
SCATTER_TI10_S2 = tuple(k.replace("case 10", "case 10 s/2") for k in SCATTER_TI10)        # ... and at s/2
SCATTER_TI10_REF = tuple(f"case 10{REFINED}" + k[len("case 10"):] for k in SCATTER_TI10)  # ... at REF_UPDATE
SCATTER_TI10_REF_S2 = tuple(k.replace("case 10", "case 10 s/2", 1) for k in SCATTER_TI10_REF)   # ... and at s/2
SCATTER_REF = tuple(f"case 1{REFINED}" + k[len("case 1"):] for k in SCATTER_KEYS[:3])   # case 1's at REF_UPDATE
# the 'refupdate' study: case 1's scatter at REF_UPDATE (t_u/5, the seeds of SCATTER_T5) and the study's table (each
# case at t_u/5 from the loosest threshold to the tightest, the scene's among them, then t_u/10)
REF_SCATTER = tuple(f"case 1{COARSE}{REF_KEY}{REF_UPDATE:g}" + k[len("case 1 n_tu 5"):] for k in SCATTER_T5[:3])
REF_SCATTER_TI = tuple(k.replace("case 1 ", "case 10 ", 1) for k in REF_SCATTER)            # case 10's, the same seeds
REF_RUNS = tuple(f"case {n}{COARSE}{REF_KEY}{r:g}" if r != SCENE_REF_UPDATE else f"case {n}{COARSE}"
                 for n in (1, 10) for r in sorted(REF_UPDATES + (SCENE_REF_UPDATE,), reverse=True)) + tuple(
    k for n in (1, 10) for k in (f"case {n}", f"case {n}{REF_KEY}{REF_UPDATE:g}")) + (
    f"case 1{REF_KEY}{REF_UPDATE:g}{RETRY}",) + tuple(
    f"case {n}{COARSE}{REF_KEY}{r:g} courant {COURANT:g}" for n, r in REF_FAILED)
HALF_STEP_RUNS = tuple(f"case {n}{COARSE}{HALF_STEP}" for n in range(1, 19))
REFINED_RUNS = tuple(f"case {n}{REFINED}" for n in range(1, 19))
# the 'gap' study: each case's changed runs against its scatter at t_u/5 and REF_UPDATE, whose first run is the
# unchanged one; the study's table, each case's unchanged run before its changed ones
GAP_SINGLES = tuple((group, tuple(group[0] + sfx for sfx, _ in GAP_CHANGES))
                    for group in (REF_SCATTER_TI, REF_SCATTER))
GAP_RUNS = tuple(k for group, singles in GAP_SINGLES for k in (group[0], *singles))
SOLVER_CHANGES = tuple(k for n in PFEM5_RERUN_CASES for sfx, cases in ((PFEM, PFEM5_RERUN_CASES),
                                                                        (PFEM10, PFEM10_RERUN_CASES))
                       if n in cases for k in (f"case {n}{sfx}", f"case {n}{sfx}{RERUN}"))   # (record, rerun) pairs


def pfem10_base(n: int) -> str:
    """The key of case n's run in the PFEM's 18-case table at t_u/10: today's solver's ('rerun') where an earlier
    solver made the record (PFEM10_RERUN_CASES), so that a change is read against a run of the same solver."""
    return f"case {n}{PFEM10}{RERUN}" if n in PFEM10_RERUN_CASES else f"case {n}{PFEM10}"


CONDUCTIVITY_RUNS = tuple(k for n, f in CONDUCTIVITY
                          for k in (f"case {n}{REFINED}", f"case {n}{REFINED}{COND_KEY}{f:g}"))
CONDUCTIVITY_RUNS += tuple(k for n, f in CONDUCTIVITY for k in (pfem10_base(n), f"case {n}{PFEM10}{COND_KEY}{f:g}"))
CONDUCTIVITY_RUNS += (f"case 1{PFEM10} n_tu 10{BOSSAK}", f"case 1{PFEM10}{COND_KEY}0.6{BOSSAK}")   # its retry pair
PFEM_GAP_RUNS = tuple(k for n in (1, 10) for k in (pfem10_base(n), f"case {n}{PFEM10}{WITHOUT_HEAT}"))   # the PFEM's
REFINED_SERIES = (("refsph SPH, t_u/10,\nref update 0.5,\ncourant 0.15", "", "D", "C1"),   # the figure's series
                  (f"refsph SPH, t_u/10,\nref update {REF_UPDATE:g},\nfrequency step", REFINED, "o", "C3"))
# the resolution check at REF_UPDATE: each case at t_u/5 (the 'refupdate' study's run, courant 0.3), t_u/10 and t_u/15
REFINED_RESOLUTION_KEYS = {n: (f"case {n}{COARSE}{REF_KEY}{REF_UPDATE:g}", f"case {n}{REFINED}",
                               f"case {n} n_tu 15{REFINED}") for n in (1, 10)}
REFINED_RESOLUTION = tuple(k for keys in REFINED_RESOLUTION_KEYS.values() for k in keys)
# the 'gain' study's table: each run with the step over the gradient's gain beside the same run at the scene's step
# (courant 0.3) and at half of it
GAIN_T5 = (*(f"case {n}{COARSE}{REF_KEY}{r:g}" for n, r in REF_FAILED), f"case 10{COARSE}{SELF_KEY}",
           f"case 1{COARSE} s/4", f"case 10{COARSE} alpha detector")   # failed at 0.3 (case 1's: its rerun)
GAIN_RUNS = ((f"case 1{COARSE} rerun", f"case 1{COARSE} courant {COURANT:g} rerun", f"case 1{COARSE}{GAIN_KEY}",
              f"case 1{COARSE}{FREQ_KEY}")
             + tuple(base + sfx for base in GAIN_T5 for sfx in ("", f" courant {COURANT:g}", GAIN_KEY, FREQ_KEY))
             + ("case 10 courant 0.3", "case 10", f"case 10{GAIN_KEY}", f"case 10{FREQ_KEY}",
                f"case 1{REF_KEY}{REF_UPDATE:g}", f"case 1{REF_KEY}{REF_UPDATE:g}{RETRY}",
                f"case 1{REF_KEY}{REF_UPDATE:g}{GAIN_KEY}", f"case 1{REF_KEY}{REF_UPDATE:g}{FREQ_KEY}"))
# the 'selfcontact' study: case 1's scatter with self-contact (t_u/5, the seeds of SCATTER_T5) and the study's table
SELF_SCATTER = tuple(f"case 1{COARSE}{SELF_KEY}" + k[len("case 1 n_tu 5"):] for k in SCATTER_T5[:3])
SELF_RUNS = tuple(k for n in (1, 10) for k in (
    f"case {n}{COARSE}", f"case {n}{COARSE}{RERUN}", f"case {n}{COARSE}{SELF_KEY}",
    *((f"case {n}{COARSE} courant {COURANT:g}", f"case {n}{COARSE}{SELF_KEY} courant {COURANT:g}") if n == 10 else
      (f"case {n}{COARSE} courant {COURANT:g}", f"case {n}{COARSE} courant {COURANT:g}{RERUN}")),
    *(k2 for r in SELF_REF_UPDATES for k2 in (f"case {n}{COARSE}{REF_KEY}{r:g}",
                                              f"case {n}{COARSE}{REF_KEY}{r:g}{SELF_KEY}")))) + (
    "case 1", f"case 1{SELF_KEY}", f"case 1{REF_KEY}{REF_UPDATE:g}", f"case 1{REF_KEY}{REF_UPDATE:g}{SELF_KEY}")
# the resolution study: case -> its runs at 5, 10 and 15 particles across t_u (at courant 0.15), and the scatter
# groups that measure its run-to-run spread at t_u/5 and t_u/10 (the t_u/5 groups at the scene's courant 0.3)
RESOLUTION_N = (5.0, 10.0, 15.0)
RESOLUTION_KEYS = {1: ("case 1 n_tu 5 courant 0.15", "case 1", "case 1 n_tu 15"),
                   10: ("case 10 n_tu 5 courant 0.15", "case 10", "case 10 n_tu 15")}
RESOLUTION_RUNS = tuple(k for keys in RESOLUTION_KEYS.values() for k in keys)     # the study's table, in order
RESOLUTION_NOISE = {1: (SCATTER_T5, SCATTER_KEYS),
                    10: (("case 10 n_tu 5", "case 10 n_tu 5 jitter 1", "case 10 n_tu 5 jitter 2",
                          "case 10 n_tu 5 jitter 3"), SCATTER_TI10)}
# ... and at REF_UPDATE (the 'refined' resolution check): measured there, but for case 10's at t_u/5, taken from the
# scene's 0.5
REFINED_NOISE = {1: (REF_SCATTER, SCATTER_REF), 10: (REF_SCATTER_TI, SCATTER_TI10_REF)}
STUDIES = (
    ("Mass scaling: s halved (the rule's factor 0.01 A in s rho vc^2 = 0.01 A halved to 0.005 A)",
     ("case 1", "case 1 s/2", "case 10", "case 10 s/2", "case 1 n_tu 5", "case 1 n_tu 5 s/2", "case 10 n_tu 5",
      "case 10 n_tu 5 s/2"),
     (("s", "mass_scale", ".0f"), ("s rho vc^2 / A", "inertia_ratio", ".4f")) + BASIC
     + (("viscosity + damping heat [% of work]", "dissipation_of_work", ".1f"), ("steps", "n_steps", "d"),
        ("wall [s]", "wall", ".0f"))),
    ("Run-to-run scatter at s/2 (t_u/5; the same three seeds): whether the mass scale moves the results by more "
     "than the scatter, two groups of four runs",
     SCATTER_S2, BASIC),
    ("The mass scale at t_u/5: s, s/2 and s/4 (case 1, one run each; read with the two scatter tables; s/4 at the "
     "scene's step inverted a particle, so it runs at courant 0.15 beside s at 0.15)",
     ("case 1 n_tu 5", "case 1 n_tu 5 s/2", "case 1 n_tu 5 s/4", "case 1 n_tu 5 courant 0.15",
      "case 1 n_tu 5 s/4 courant 0.15"),
     (("s", "mass_scale", ".0f"),) + BASIC + (("friction heat [% of work]", "friction_of_work", ".1f"),
                                             ("viscosity + damping heat [% of work]", "dissipation_of_work", ".1f"),
                                             ("of which contact damping [% of work]", "damping_of_work", ".1f"),
                                             ("steps", "n_steps", "d"), ("wall [s]", "wall", ".0f"))),
    ("Run-to-run scatter: case 1 and three runs with the workpiece's particles moved at random by up to 0.01 dx",
     SCATTER_KEYS, BASIC),
    ("Run-to-run scatter at t_u/5 (the same, where a run costs an eighth)", SCATTER_T5, BASIC),
    ("Run-to-run scatter of Ti6Al4V at t_u/10 (case 10 and two runs with the same perturbation): whether case 10 "
     "at s/2 (one run) moves by more than the scatter", SCATTER_TI10, BASIC),
    ("Run-to-run scatter of Ti6Al4V at t_u/10 and s/2 (case 10 at s/2 and two runs with the same perturbations): "
     "whether halving s moves case 10 by more than the scatter, two groups of three runs", SCATTER_TI10_S2, BASIC),
    ("Run-to-run scatter of Ti6Al4V at t_u/10 at reference update 0.1 (the 'refined' study's case 10 and two runs "
     "with the same perturbations): whether the converged update, t_u/15 and the heat split move case 10 by more "
     "than the scatter measured at that update", SCATTER_TI10_REF, BASIC),
    ("Run-to-run scatter of Ti6Al4V at t_u/10, reference update 0.1 and s/2 (the same three runs at s/2): whether "
     "halving s moves case 10 by more than the scatter at the converged update, two groups of three runs",
     SCATTER_TI10_REF_S2, BASIC),
    ("What makes the rake face hotter than the free chip surface (T_RF - T_FCS; t_u/5 at ref update 0.1, courant "
     "0.3): cases 10 and 1 as the 'refupdate' study's runs, with friction off (no frictional heat, and a chip that "
     "slides freely), with the artificial viscosity's and contact damping's work left out of the heat, and with "
     "friction acting but making no heat (eta = 0: its mechanics without its heat); read "
     "with each case's scatter at ref update 0.1 and t_u/5 (case 10's below, case 1's further down)", GAP_RUNS,
     BASIC + (("T_RF - T_FCS [K]", "gap", ".0f"), ("friction heat [% of work]", "friction_of_work", ".1f"),
              ("viscosity + damping heat [% of work]", "dissipation_of_work", ".1f"), ("CPU [min]", "cpu_min", ".1f"))),
    ("The workpiece's conductivity (a sensitivity study, not the paper's model, which holds Table A1's "
     "room-temperature k): case 10 with Ti6Al4V's k doubled (it about doubles by 1000 K) and case 1 with AISI 1045's "
     "at 0.6 (a carbon steel's falls by about 40 %), each below its 'refined' run (t_u/10, ref update 0.1) and read "
     "against its scatter there (the tables of the scatter at reference update 0.1); then the same in the PFEM at "
     "t_u/10, each below the 18-case table's run (case 1's: its 'rerun' by today's solver; case 10 against its "
     "scatter there, case 1 by its change in units of case 2's spread at t_u/10)", CONDUCTIVITY_RUNS,
     BASIC + (("T_RF - T_FCS [K]", "gap", ".0f"), ("friction heat [% of work]", "friction_of_work", ".1f"),
              ("CPU [min]", "cpu_min", ".1f"))),
    ("The PFEM's run-to-run scatter (case 2 at t_u/5 with today's solver: unperturbed, and with the workpiece's "
     "nodes moved at random by up to 0.01 of their spacing, three seeds; the sweep's record 'case 2 pfem n_tu 5', "
     "made by an earlier solver, against their spread below them): what the t_u/5 changes (the solver's t_u/5 "
     "pairs, the spacing study's first step at its t_u/5 end) are read against",
     PFEM_SCATTER, BASIC),
    ("The PFEM's run-to-run scatter at t_u/10 (case 2 as above at the 18-case table's resolution: its rerun and three "
     "jittered runs; the sweep's record 'case 2 pfem', made by an earlier solver, against their spread below them, "
     "and their mean against the t_u/5 runs'): what AISI 1045's t_u/10 changes (the solver's t_u/10 pairs, "
     "the trends' steps, both steps of the spacing study at their t_u/10 and finer ends) are read against",
     PFEM_SCATTER10, BASIC),
    ("The PFEM's run-to-run scatter of Ti6Al4V at t_u/10 (case 10: its record and three jittered runs): what "
     "Ti6Al4V's t_u/10 changes (the trends' steps) are read against",
     PFEM_SCATTER10_TI, BASIC),
    ("What the PFEM's solver changes moved (each record made by an earlier solver, before the contact's changes of "
     "b294aaf and 248e7e0, above the same cut with today's, key suffix 'rerun', which the t_u/5 and t_u/10 tables "
     "and the spacing table take; at t_u/5 all 18, at t_u/10 AISI 1045's cases 1-7)",
     SOLVER_CHANGES, BASIC + (("steps", "n_steps", "d"), ("CPU [min]", "cpu_min", ".1f"))),
    ("The same in the PFEM (t_u/10, the sweep's runs): friction acting but making no heat (eta = 0); one run each, "
     "to be read against the PFEM's scatter at t_u/10 (case 2's and case 10's tables above)", PFEM_GAP_RUNS,
     BASIC + (("T_RF - T_FCS [K]", "gap", ".0f"), ("friction heat [% of work]", "friction_of_work", ".1f"),
              ("CPU [min]", "cpu_min", ".1f"))),
    ("Run-to-run scatter of Ti6Al4V at t_u/5 at reference update 0.1 (case 10 and two runs with the perturbations "
     "of case 1's scatter there)", REF_SCATTER_TI, BASIC + (("T_RF - T_FCS [K]", "gap", ".0f"),)),
    ("Run-to-run scatter of AISI 1045 at t_u/10 at reference update 0.1 (the 'refined' study's case 1 and two runs "
     "with the perturbations of case 1's scatter at 0.5): whether the converged update, t_u/15, the heat split, "
     "friction without its heat and half the mass scale move case 1 by more than the scatter measured at that update",
     SCATTER_REF, BASIC),
    ("Run-to-run scatter of Ti6Al4V at t_u/5 (case 10, the same perturbation)",
     ("case 10 n_tu 5", "case 10 n_tu 5 jitter 1", "case 10 n_tu 5 jitter 2", "case 10 n_tu 5 jitter 3"), BASIC),
    ("Resolution (particles across t_u; at courant 0.15)", RESOLUTION_RUNS,
     (("across t_u", "across", ".0f"), ("dx [um]", "dx_um", ".1f"), ("particles", "n_particles", "d")) + BASIC
     + (("steps", "n_steps", "d"), ("wall [s]", "wall", ".0f"))),
    ("Tool and workpiece size (the sweep: the tool 10 t_u x 6 t_u, 12 t_u left uncut at the end of the cut; the "
     "first sweep's tool 5 t_u x 3 t_u, whose back face the chip's contact (4 t_u) nearly reached, and 4 t_u "
     "uncut, one change at a time; at t_u/5, where a run costs an eighth, and at t_u/10)",
     ("case 1 n_tu 5 tool 5x3, 4 t_u uncut", "case 1 n_tu 5 tool 5x3, 8 t_u uncut", "case 1 n_tu 5 4 t_u uncut",
      "case 1 n_tu 5", "case 1 tool 5x3, 4 t_u uncut", "case 1 courant 0.3"),
     BASIC + (("removed at held faces [% of work]", "removed_of_work", ".1f"), ("Fc drift [%]", "Fc_drift_pct", ".1f"),
              ("T_RF drift [K]", "TRF_drift", ".0f"))),
    ("Free-surface detector of the heat losses (the paper's future work: the alpha-shape instead of the SPH "
     "detector; t_u/5; case 10's alpha-shape run at the scene's courant 0.3 inverted a particle, so the pair is "
     "also run at 0.15)",
     ("case 1 n_tu 5", "case 1 n_tu 5 alpha detector", "case 10 n_tu 5", "case 10 n_tu 5 alpha detector",
      "case 10 n_tu 5 courant 0.15", "case 10 n_tu 5 alpha detector courant 0.15"),
     BASIC + (("lost at the surface [% of work]", "lost_of_work", ".3f"),)),
    ("The heat step once every 8 mechanical steps (Numerics.heat_every = 8; the heat step's stable step, the "
     "tool's with its reduced c_p, is 30-60 mechanical steps of AISI 1045 at t_u/10, 5 of Ti6Al4V): the cost of a "
     "converged case (issue 22's target: under 40 min of CPU on one core) beside case 1 at every step and its "
     "run-to-run scatter (CPU: of the run's own process, beside other runs; '-' where the record predates it)",
     ("case 1 heat every 8",) + SCATTER_KEYS,
     BASIC + (("steps", "n_steps", "d"), ("CPU [min]", "cpu_min", ".1f"), ("wall [s]", "wall", ".0f"))),
    ("The PFEM's resolution (case 1: the short cut of --quick, 4 t_u on a workpiece 1.2 mm long, and the full cut "
     "of 16 t_u; cases 2 and 3 at t_u/5, t_u/10 and the paper's 10 um near the tool, 15 and 20 nodes across t_u)",
     ("case 1 pfem short n_tu 5", "case 1 pfem short n_tu 10", "case 1 pfem n_tu 5", "case 1 pfem",
      "case 1 pfem n_tu 15", "case 2 pfem n_tu 5", "case 2 pfem", "case 2 pfem n_tu 15", "case 3 pfem n_tu 5",
      "case 3 pfem", "case 3 pfem n_tu 20"),
     (("across t_u", "across", ".0f"), ("dx [um]", "dx_um", ".1f"), ("nodes", "n_particles", "d")) + BASIC
     + (("steps", "n_steps", "d"), ("wall [s]", "wall", ".0f"))),
    ("The time step (the sweep at t_u/10 runs at courant 0.15: at the scene's 0.3 a particle on the torn surface "
     "under case 10's edge inverts at 1.1 ms, and in case 2 two particles of the chip's free surface oscillate "
     "against each other from 2.25 ms, heating 54 particles past 1500 K; at t_u/5 the scene's 0.3, whose results "
     "move with the step by no more than the run-to-run scatter)",
     ("case 10 n_tu 5", "case 10 n_tu 5 courant 0.15", "case 10 n_tu 5 courant 0.075", "case 10 courant 0.3",
      "case 10", "case 1 n_tu 5", "case 1 n_tu 5 courant 0.15", "case 1 n_tu 5 courant 0.075", "case 1 courant 0.3",
      "case 1", "case 2 n_tu 5", "case 2 n_tu 5 courant 0.15", "case 2 courant 0.3", "case 2"),
     BASIC + (("max T [K]", "max_temperature_K", ".0f"), ("steps", "n_steps", "d"), ("wall [s]", "wall", ".0f"))),
    ("The PFEM's time rule (case 16, Ti6Al4V, 60 m/min, 0.10 mm, t_u/5 and t_u/10; cases 8 and 9, AISI 1045, 180 "
     "m/min, 0.15 and 0.20 mm, t_u/10; cases 1 and 8 at t_u/5, where every rule runs): the paper's trapezoidal "
     "rule rings in the chip and Newton stalls (case 16 at 0.85 ms at t_u/5, case 8 at 0.568 of 0.8 ms, case 9 at "
     "0.758 of 1.067 ms); the damped Newmark rule gamma = 0.6 (first order) and the Bossak-Newmark rule alpha_B = "
     "-0.1 (second order, the same gamma), both departures from the paper",
     ("case 1 pfem n_tu 5", "case 1 pfem n_tu 5 gamma 0.6", "case 1 pfem n_tu 5 bossak -0.1", "case 8 pfem n_tu 5",
      "case 8 pfem n_tu 5 gamma 0.6", "case 8 pfem n_tu 5 bossak -0.1", "case 16 pfem n_tu 5", "case 16 pfem gamma 0.6",
      "case 16 pfem n_tu 5 bossak -0.1", "case 16 pfem", "case 16 pfem n_tu 10 gamma 0.6", "case 8 pfem",
      "case 8 pfem n_tu 10 gamma 0.6", "case 8 pfem n_tu 10 bossak -0.1", "case 9 pfem",
      "case 9 pfem n_tu 10 gamma 0.6"),
     BASIC + (("steps", "n_steps", "d"), ("wall [s]", "wall", ".0f"))),
    ("The PFEM's remeshing: after every step (the sweep's) or only where a triangle's quality falls below 0.3 "
     "(Algorithm 1's 'if remeshing is needed' read literally; key suffix 'remesh when needed'); the 'every step' rows "
     "are the sweep's records, made by earlier versions of the solver (the PFEM's path moves its forces by up to 12 %)",
     tuple(k for n, suffix, _ in REMESH_RUNS for k in (f"case {n}{suffix}", f"case {n}{suffix}{REMESH}")),
     BASIC + (("steps", "n_steps", "d"), ("wall [s]", "wall", ".0f"))),
    ("How often TLSPH's reference configuration is updated (Numerics.ref_update_strain: the largest Green-Lagrange "
     "strain |E| a particle may reach before X <- x; the scene's 0.5; the first paper: 'when the deviation is "
     "considerable'): t_u/5 for cases 1 and 10, then t_u/10 at 0.1; read with the scatter tables at t_u/5 and t_u/10 "
     "and the chip's plastic strain in benchmarks/chip_strain_report.md",
     REF_RUNS, (("ref update", "ref_update", ".2f"),) + BASIC
     + (("plastic heat [% of work]", "plastic_of_work", ".1f"),
        ("viscosity + damping heat [% of work]", "dissipation_of_work", ".1f"), ("wall [s]", "wall", ".0f"))),
    (f"The 18 cuts at t_u/5 at ref update {REF_UPDATE:g} and half the step (Courant 0.15; the 'coarse' table's at the "
     "scene's 0.5 and 0.3): at 0.3 the SPH cuts' blow-ups come by chance at every threshold, at 0.15 none of the "
     "four tried failed (the self-contact tables below)",
     HALF_STEP_RUNS, BASIC + (("max T [K]", "max_temperature_K", ".0f"), ("wall [s]", "wall", ".0f"))),
    (f"The 18 cuts at t_u/10 at ref update {REF_UPDATE:g} (the t_u/10 table's: the scene's 0.5, which the t_u/5 study "
     f"finds unconverged) at the scene's courant 0.3 with the step under {FREQUENCY_STEP:g} of 2 / w_max "
     f"(Numerics.frequency_step; case 1 at {REF_UPDATE:g} went NaN at courant 0.15 without it)",
     REFINED_RUNS, BASIC + (("max T [K]", "max_temperature_K", ".0f"), ("steps", "n_steps", "d"),
                            ("CPU [min]", "cpu_min", ".1f"))),
    (f"Resolution at ref update {REF_UPDATE:g} (the 'resolution' study's runs are at the scene's 0.5): cases 1 and 10 "
     f"at t_u/5 (courant 0.3), t_u/10 and t_u/15 (courant 0.3 under {FREQUENCY_STEP:g} of 2 / w_max); read with "
     "the scatter at ref update 0.1 below (t_u/5) and the scatter tables at 0.5",
     REFINED_RESOLUTION, (("across t_u", "across", ".0f"), ("particles", "n_particles", "d")) + BASIC
     + (("steps", "n_steps", "d"), ("CPU [min]", "cpu_min", ".1f"))),
    (f"Run-to-run scatter at ref update {REF_UPDATE:g} (t_u/5, case 1, the same perturbation as at the scene's 0.5)",
     REF_SCATTER, BASIC),
    ("Self-contact (Numerics.self_contact = 0.5: particles of the workpiece closer than dx/2 repel, "
     "refsph.self_contact; off in the scene, as in the paper): each run without it (the record, and the record "
     "made again with today's code, 'rerun') beside the same run with it; 'crowded': the workpiece's particles "
     "with a neighbour closer than dx/2 at the end of the cut ('-' where the record predates the measure)",
     SELF_RUNS, (("self contact", "self_contact", ".1f"), ("ref update", "ref_update", ".2f"),
                 ("crowded [%]", "crowded_pct", ".1f"), ("closest pair [dx]", "closest_dp", ".2f")) + BASIC
     + (("max T [K]", "max_temperature_K", ".0f"), ("wall [s]", "wall", ".0f"))),
    ("Run-to-run scatter with self-contact (t_u/5, case 1, the same perturbation as without)", SELF_SCATTER, BASIC),
    ("The step over the corrected gradient's gain (Numerics.gain_step, refsph.tlsph.gradient_gain) and under half "
     "the critical step (Numerics.frequency_step 0.5, refsph.tlsph.largest_frequency; both off in the scene): each "
     "run that broke down at the scene's courant 0.3, the same at half the step, and at 0.3 with the step divided "
     "by the largest gain, or held under half of 2 / w_max (t_u/10: case 10 at 0.3, the sweep's case 10 at 0.15; "
     "case 1 at reference update 0.1 at 0.15, at 0.075, and at 0.3 with either); a failed run shows its status",
     GAIN_RUNS, BASIC + (("steps", "n_steps", "d"), ("CPU [min]", "cpu_min", ".1f"), ("wall [s]", "wall", ".0f"))),
    ("Contact and heat split (case 1: penalty contact, half the frictional heat into the chip; then cases 1 and 10 at "
     f"ref update {REF_UPDATE:g}, where the frictional heat is a larger part of the tool's work, with all of it in "
     "the chip, the paper's SPH code's choice)",
     ("case 1", "case 1 pinball", f"case 1{TO_CHIP}") + tuple(k for n in (1, 10) for k in (
         f"case {n}{REFINED}", f"case {n}{REFINED}{TO_CHIP}")),
     BASIC + (("friction heat [% of work]", "friction_of_work", ".1f"),
              ("viscosity + damping heat [% of work]", "dissipation_of_work", ".1f"))),
)


def scatter(res: dict, keys=None) -> dict:
    """Mean and sample standard deviation (percent of the mean) of each basic quantity over case 1 and its jittered
    runs (``keys``: the runs of a scatter study; default the first), those recorded ok."""
    out = {}
    for key, v in _groups(res, SCATTER_KEYS if keys is None else keys).items():
        if len(v) >= 2:
            out[key] = dict(n=len(v), mean=float(v.mean()), std_pct=float(100 * v.std(ddof=1) / abs(v.mean())))
    return out


def _study_lines(res: dict) -> list[str]:
    """The studies: a row per recorded run (or 'to run'), and the scatter's spread."""
    runs, lines = res["runs"], []
    for title, keys, columns in STUDIES:
        lines += ["", f"## {title}", "", "| run | " + " | ".join(c[0] for c in columns) + " |",
                  "|---" * (len(columns) + 1) + "|"]
        shown = keys if keys != REFINED_RUNS else tuple(      # a failed refined case: its retry below it, if recorded
            x for k in keys for x in (k, k + REFINED_RETRY) if x == k or x in runs)
        for k in shown:
            r = runs.get(k)
            if r is None or r.get("status") != "ok":
                lines.append(f"| {k} | " + " | ".join(["-"] * (len(columns) - 1)
                                                      + ["to run" if r is None else r["status"][:40]]) + " |")
                continue
            v = _values(r)
            lines.append(f"| {k} " + _row((v.get(key), fmt) for _, key, fmt in columns))
        if "jitter" in " ".join(keys):
            sc = scatter(res, keys)
            if sc:
                lines += ["", "Spread (sample standard deviation over the runs, percent of their mean): " + ", ".join(
                    f"{name} {sc[key]['std_pct']:.1f} %" for name, key, _ in BASIC if key in sc)
                    + f" ({next(iter(sc.values()))['n']} runs)."]
            other = COMPARED.get(keys)
            if other is not None:
                lines += ["", _difference_line(res, keys, other)]
            lines += [_single_run_line(res, k, keys) for k in SINGLES.get(keys, ())]
        if keys == SOLVER_CHANGES:
            lines += ["", solver_changes_line(res)]
        if keys == RESOLUTION_RUNS:
            lines += _resolution_lines(res)
        if keys == REFINED_RESOLUTION:
            lines += _resolution_lines(res, REFINED_RESOLUTION_KEYS, REFINED_NOISE, "refined_orders")
        lines += [_single_run_line(res, k, group) for group, singles in TABLE_SINGLES.get(keys, ()) for k in singles]
        lines += [_pair_change_line(res, key, base, group) for key, base, group in TABLE_PAIRS.get(keys, ())]
        if keys == HALF_STEP_RUNS:
            lines += ["", _group_errors(res)]
        if keys == REFINED_RUNS:
            lines += ["", _group_errors(res, REFINED, "", "the t_u/10"), "", _ledger_line(res, REFINED, ""), "",
                      "![The cuts at reference update 0.1 beside the t_u/10 table's, case by case, against the "
                      "measurements and the paper's SPH and PFEM](../figures/11_thermal_cutting_refined.png)"]
    return lines


LEDGER_SHARES = (("plastic", "plastic_of_work"), ("friction", "friction_of_work"),
                 ("viscosity + contact damping", "dissipation_of_work"))


def _ledger_line(res: dict, suffix: str, base: str, name: str = "the t_u/10 table") -> str:
    """Where the tool's work goes in the group of key suffix ``suffix`` beside the group ``base`` (its ``name`` in
    the line), per material over the cases both have recorded 'ok' (the mean over those cases of each heat source
    in percent of the tool's work, :func:`_values`), and the tool's work of the group over the base's (the mean of
    the per-case ratios)."""
    parts = []
    for material in MATERIAL_NAMES:
        here, other = both_ok(comparison(res, suffix), comparison(res, base), material)
        if not here:
            continue
        a = [_values(res["runs"][r["key"]]) for r in here]
        b = [_values(res["runs"][r["key"]]) for r in other]
        shares = ", ".join(f"{label} {np.mean([v[k] for v in a]):.1f} % ({np.mean([v[k] for v in b]):.1f} %)"
                           for label, k in LEDGER_SHARES)
        work = np.mean([x["tool_work_J_per_m"] / y["tool_work_J_per_m"] for x, y in zip(a, b)])
        parts.append(f"{material} ({len(here)} cases): {shares}; the tool's work {work:.2f} of {name}'s")
    return ("Where the tool's work goes (the heat made, percent of the tool's work, mean over the cases recorded "
            f"both here and in {name}, its means in brackets): "
            + ("; ".join(parts) if parts else "none recorded yet") + ".")


def _group_errors(res: dict, suffix: str = COARSE + HALF_STEP, base: str = COARSE,
                      name: str = "the 'coarse'") -> str:
    """Mean |error| against the measurements of T_RF, T_FCS and Fp/Fc per material over the cases the group of key
    suffix ``suffix`` (default: the half-step group) has recorded 'ok', beside the group ``base``'s (default the
    'coarse' table's: 0.5, Courant 0.3; its ``name`` in the line) over the same cases (both from
    :func:`comparison`)."""
    here, coarse = comparison(res, suffix), comparison(res, base)
    parts = []
    for material in MATERIAL_NAMES:
        h, c = both_ok(here, coarse, material)
        if h:
            errs = [f"{qn} {_mean(h, q):.1f} % ({'before ' if q == 'TRF_err' else ''}{_mean(c, q):.1f} %)"
                    for qn, q in (("T_RF", "TRF_err"), ("T_FCS", "TFCS_err"), ("Fp/Fc", "ratio_err"))]
            parts.append(f"{material} ({len(h)} cases): " + ", ".join(errs))
    return ("Mean |error| against the measurements over the cases recorded here, beside " + name + " table's on the "
            "same cases ('before'): " + ("; ".join(parts) if parts else "none recorded yet") + ".")


def resolution_convergence(res: dict, resolution_keys=None, noise=None) -> list[dict]:
    """Per case of a resolution study (``resolution_keys``: case -> its keys at t_u/5, /10, /15, default
    RESOLUTION_KEYS; ``noise``: case -> its scatter groups at t_u/5 and t_u/10, default RESOLUTION_NOISE) and basic
    quantity: its values f at 5, 10 and 15 particles across t_u, the
    changes between successive resolutions with their z (the change over its standard deviation from the scatter
    groups: sqrt(s5^2 + s10^2) for t_u/5 -> t_u/10, sqrt(2) s10 for t_u/10 -> t_u/15, t_u/15's spread taken as
    t_u/10's), the verdict (``_verdict``), and where both changes exceed twice their standard deviation with the
    same sign, the observed order p of f = f0 + C dx^p with its range (``_order_range``) and the extrapolated f0
    (``study.observed_order``, ``study.richardson``)."""
    h, out = [1.0 / n for n in RESOLUTION_N], []
    resolution_keys, noise = resolution_keys or RESOLUTION_KEYS, noise or RESOLUTION_NOISE
    for case, keys in resolution_keys.items():
        runs = [res["runs"].get(k) for k in keys]
        vals = [_values(r) if r is not None and r.get("status") == "ok" else {} for r in runs]
        g5, g10 = (_groups(res, grp) for grp in noise[case])
        for name, q, spec in BASIC:
            f = [float(v.get(q, math.nan)) for v in vals]
            sd5, sd10 = (float(g[q].std(ddof=1)) if len(g[q]) >= 2 else math.nan for g in (g5, g10))
            s1, s2 = math.hypot(sd5, sd10), math.sqrt(2.0) * sd10
            z1, z2 = _z(f[1] - f[0], s1), _z(f[2] - f[1], s2)
            verdict, p, f0, p_range = _verdict(f, sd5, sd10, z1, z2), None, None, None
            if verdict == "order":
                p = study.observed_order(h, f)
                if p is None:
                    verdict = "no convergence seen"
                else:
                    f0 = study.richardson(h, f, p) if math.isfinite(p) else None
                    p_range = _order_range(h, f, s1, s2)
            out.append(dict(case=case, name=name, spec=spec, f=f, z1=z1, z2=z2, p=p, f0=f0, sd=[sd5, sd10],
                            d1=_rel(f[1], f[0]), d2=_rel(f[2], f[1]), verdict=verdict, p_range=p_range))
    return out


def _verdict(f: list, sd5: float, sd10: float, z1: float, z2: float) -> str:
    """What three resolutions can say: 'order' only where all three runs and both scatters are there and both
    changes exceed twice their standard deviation with the same sign; else which change does ('only ...'), or
    neither."""
    if math.isnan(f[0]) or math.isnan(f[1]):
        return "t_u/5 or t_u/10 not recorded"
    if math.isnan(f[2]):
        return "t_u/15 to run"
    if math.isnan(sd5) or math.isnan(sd10):
        return "scatter not measured"
    if math.isnan(z1) or math.isnan(z2):
        return "a change inside the scatter"
    if max(abs(z1), abs(z2)) <= 2.0:
        return "both changes inside the scatter"
    if min(abs(z1), abs(z2)) <= 2.0:                      # one beyond twice its deviation, the other not: no order
        return "only t_u/10 -> 15 beyond the scatter" if abs(z2) > 2.0 else "only t_u/5 -> 10 beyond the scatter"
    return "order" if z1 * z2 > 0 else "not monotone"


def _order_range(h: list, f: list, s1: float, s2: float) -> tuple:
    """The observed order with each change moved by one standard deviation either way (f at t_u/5 by s1, at t_u/15
    by s2): (lowest, highest); 0 where a moved pair shows no convergence, inf above 20."""
    ps = [study.observed_order(h, [f[0] + a, f[1], f[2] + b]) for a in (-s1, s1) for b in (-s2, s2)]
    ps = [0.0 if x is None else x for x in ps]
    return min(ps), max(ps)


def change_z(d: float, sd_pct: float) -> float:
    """The z of a relative change d = 100 (f_b - f_a) / f_a [%] between two single runs, each with a relative
    standard deviation of sd_pct [%]: d over its standard deviation sd_pct sqrt(1 + (f_b / f_a)^2) (the hypot of the
    two runs' deviations, in percent of f_a; sqrt(2) sd_pct for a small change). NaN without a spread."""
    return _z(d, sd_pct * math.hypot(1.0, 1.0 + d / 100.0))


def _z(d: float, sd: float) -> float:
    """A change over its standard deviation: +-inf for a change where the runs have no spread, NaN for none."""
    if math.isnan(d) or math.isnan(sd):
        return math.nan
    if sd > 0:
        return d / sd
    return math.copysign(math.inf, d) if d != 0 else math.nan


def _rel(a: float, b: float) -> float:
    """100 (a - b) / |b|: a change in percent (NaN where either is missing)."""
    return 100.0 * (a - b) / abs(b) if math.isfinite(a) and math.isfinite(b) and b != 0 else math.nan


def _order_cell(r: dict) -> str:
    """The observed order with its range ('1.8 (0.9-3.5)'), or the verdict where there is none."""
    if r["p"] is None:
        return r["verdict"]
    fmt = lambda x: "above 20" if not math.isfinite(x) else f"{x:.1f}"  # noqa: E731
    return f"{fmt(r['p'])} ({fmt(r['p_range'][0])}-{fmt(r['p_range'][1])})"


def _resolution_lines(res: dict, resolution_keys=None, noise=None, section="resolution_orders") -> list[str]:
    """A resolution study's convergence table (``resolution_convergence``) with its prose (the page's
    ``section``)."""
    lines = ["", study.Page("thermal_cutting_report")(section), "",
             "| case | quantity | t_u/5 | t_u/10 | t_u/15 | t_u/5 -> 10 (z) | t_u/10 -> 15 (z) | observed order "
             "| extrapolated | t_u/10 from it |", "|---" * 10 + "|"]
    for r in resolution_convergence(res, resolution_keys, noise):
        f, spec = r["f"], r["spec"]
        off = _rel(f[1], r["f0"]) if r["f0"] is not None else math.nan
        cells = [r["case"], r["name"]] + [_f(x, spec) for x in f] + [_change_cell(r["d1"], r["z1"]),
                                                                      _change_cell(r["d2"], r["z2"]), _order_cell(r),
                                                                      _f(r["f0"], spec), _change_cell(off)]
        lines.append("| " + " | ".join(str(c) for c in cells) + " |")
    return lines


def _change_cell(d: float, z: float = math.nan) -> str:
    """'+5.1 % (+2.3)': a change in percent and its z; '-' where the change is missing."""
    if not math.isfinite(d):
        return "-"
    return f"{d:+.1f} %" + (f" ({z:+.1f})" if math.isfinite(z) else "")


# a scatter group -> the group it is compared with (_difference_line)
COMPARED = {SCATTER_S2: SCATTER_T5, REF_SCATTER: SCATTER_T5, SELF_SCATTER: SCATTER_T5, SCATTER_TI10_S2: SCATTER_TI10,
            SCATTER_TI10_REF: SCATTER_TI10, SCATTER_TI10_REF_S2: SCATTER_TI10_REF, SCATTER_REF: SCATTER_KEYS,
            PFEM_SCATTER10: PFEM_SCATTER}
SINGLES = {SCATTER_KEYS: ("case 1 s/2", "case 1 heat every 8"), SCATTER_TI10: ("case 10 s/2",),   # one run each
           PFEM_SCATTER: (f"case {PFEM_SCATTER_CASE}{PFEM}",),
           PFEM_SCATTER10: (f"case {PFEM_SCATTER_CASE}{PFEM10}",),
           PFEM_SCATTER10_TI: (f"case 10{PFEM10}{COND_KEY}2",),
           SCATTER_TI10_REF: (f"case 10 n_tu 15{REFINED}", f"case 10{REFINED}{TO_CHIP}",
                              f"case 10{REFINED}{WITHOUT_HEAT}", f"case 10{REFINED}{COND_KEY}2"),
           SCATTER_REF: (f"case 1 n_tu 15{REFINED}", f"case 1{REFINED}{TO_CHIP}", f"case 1{REFINED}{WITHOUT_HEAT}",
                         f"case 1 s/2{REFINED}", f"case 1{REFINED}{COND_KEY}0.6")}
# the 'refupdate' study's single runs, each against the scatter group of its resolution and material (at the
# scene's reference update, or at REF_UPDATE for case 1 at t_u/5): which changes the scatter does not explain
REF_SINGLES = ((SCATTER_T5, tuple(f"case 1{COARSE}{REF_KEY}{r:g}" for r in REF_UPDATES if r > SCENE_REF_UPDATE)
                + REF_SCATTER[:1]),
               (REF_SCATTER, tuple(f"case 1{COARSE}{REF_KEY}{r:g}" for r in REF_UPDATES
                                   if r < SCENE_REF_UPDATE and r != REF_UPDATE)),
               (RESOLUTION_NOISE[10][0], tuple(f"case 10{COARSE}{REF_KEY}{r:g}" for r in REF_UPDATES)),
               (REF_SCATTER_TI, tuple(f"case 10{COARSE}{REF_KEY}{r:g}" for r in REF_UPDATES
                                      if r < SCENE_REF_UPDATE and r != REF_UPDATE)),   # ... and at REF_UPDATE's
               (SCATTER_KEYS, (f"case 1{REF_KEY}{REF_UPDATE:g}",)),
               (SCATTER_TI10, (f"case 10{REF_KEY}{REF_UPDATE:g}",)))
TABLE_SINGLES = {REF_RUNS: REF_SINGLES, GAP_RUNS: GAP_SINGLES,   # a table -> (group, its single runs) read under it
                 # the refined numerics' step checked: case 1 at 0.1, fixed courant 0.075, against its scatter there
                 GAIN_RUNS: ((SCATTER_REF, (f"case 1{REF_KEY}{REF_UPDATE:g}{RETRY}",)),)}
# a table -> (run, the run it is read against, the scatter group whose relative spread measures the change) under it:
# the PFEM's conductivity pair on the Bossak rule, in case 2's spread at t_u/10 (case 1 has no jittered PFEM runs)
TABLE_PAIRS = {CONDUCTIVITY_RUNS: ((CONDUCTIVITY_RUNS[-1], CONDUCTIVITY_RUNS[-2], PFEM_SCATTER10),)}


def _single_run_line(res: dict, key: str, group) -> str:
    """One run against the mean of a scatter group: the difference in percent of the mean and in the group's
    standard deviations (z); |z| above about 2 is a difference the scatter does not explain."""
    r, g = res["runs"].get(key), _groups(res, group)
    if r is None or r.get("status") != "ok" or len(g["Fc"]) < 2:
        return f"\n'{key}' against these runs: not recorded yet, or fewer than two runs above."
    v, parts = _values(r), []
    for name, q, _ in BASIC:
        y = g[q]
        if v.get(q) is None or not np.isfinite(v[q]):
            continue
        d = v[q] - y.mean()
        sd = y.std(ddof=1)
        parts.append(f"{name} {100 * d / abs(y.mean()):+.1f} %" + (f" (z = {d / sd:+.1f})" if sd > 0 else ""))
    return (f"\n'{key}' less the mean of these {len(g['Fc'])} runs, percent of it (z: in their standard "
            "deviations): " + ", ".join(parts) + ".")


def _pair_change_line(res: dict, key: str, base: str, group) -> str:
    """One run less another (``base``), in percent of the latter and in units of a scatter group's relative standard
    deviation (z: the percent change over the group's standard deviation in percent of its mean), for two single
    runs whose own scatter is not measured but a like case's is."""
    r, b, g = res["runs"].get(key), res["runs"].get(base), _groups(res, group)
    if any(x is None or x.get("status") != "ok" for x in (r, b)) or len(g["Fc"]) < 2:
        return f"\n'{key}' against '{base}': not recorded yet, or fewer than two runs in its scatter group."
    v, w, parts = _values(r), _values(b), []
    for name, q, _ in BASIC:
        if v.get(q) is None or w.get(q) is None or not (np.isfinite(v[q]) and np.isfinite(w[q])):
            continue
        d = 100 * (v[q] - w[q]) / abs(w[q])
        sd = 100 * g[q].std(ddof=1) / abs(g[q].mean())
        parts.append(f"{name} {d:+.1f} %" + (f" (z = {d / sd:+.1f})" if sd > 0 else ""))
    return (f"\n'{key}' less '{base}', percent of the latter (z: in the relative standard deviation of "
            f"'{group[0]}' and its {len(g['Fc']) - 1} jittered runs): " + ", ".join(parts) + ".")


def _groups(res: dict, keys) -> dict:
    """{basic quantity: its values over the runs ``keys`` recorded ok}."""
    runs = [res["runs"][k] for k in keys if k in res["runs"] and res["runs"][k]["status"] == "ok"]
    return {key: np.array([_values(r)[key] for r in runs], dtype=float) for _, key, _ in BASIC}


def _difference_line(res: dict, keys, other) -> str:
    """The mean of each basic quantity over ``keys`` less its mean over ``other``, in percent of the latter, and
    that difference in units of its standard error (Welch's t: the difference of the means over sqrt(s1^2 / n1 +
    s2^2 / n2)); |t| above about 3 with four runs a side is a difference the scatter does not explain."""
    a, b = _groups(res, keys), _groups(res, other)
    parts = []
    for name, key, _ in BASIC:
        x, y = a[key], b[key]
        if len(x) < 2 or len(y) < 2:
            continue
        se = np.sqrt(x.var(ddof=1) / len(x) + y.var(ddof=1) / len(y))
        d = x.mean() - y.mean()
        parts.append(f"{name} {100 * d / abs(y.mean()):+.1f} % (t = {d / se:+.1f})" if se > 0 else
                     f"{name} {100 * d / abs(y.mean()):+.1f} %")
    if not parts:
        return f"Against {other[0]!r} and its jittered runs: not enough runs recorded yet."
    return (f"Mean of these runs less the mean of {other[0]!r} and its jittered runs, percent of the latter (t: "
            "the difference over its standard error): " + ", ".join(parts) + ".")


def figures(res: dict) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from refsph.teaching.plots import CUT_SERIES, measured_cuts, slide_style
    rows = comparison(res)
    # the figure chapter 11 shows (drawn by the same code), then the 'refined' study beside the t_u/10 table
    for series, name in ((CUT_SERIES, "vs_measured"), (REFINED_SERIES, "refined")):
        with plt.rc_context(slide_style()):
            fig, axes = plt.subplots(3, 1, figsize=(10, 6.5), sharex=True, constrained_layout=True)
            measured_cuts(axes, res["runs"], series, RETRIES)
            fig.legend(loc="outside right upper")
            study.save_figure(fig, FIG / f"11_thermal_cutting_{name}.png", dpi=100)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for ax, mat in zip(axes, MATERIAL_NAMES):
        for k, vc in enumerate(sorted({r["vc"] for r in rows if r["material"] == mat})):
            sel = sorted((r for r in rows if r["material"] == mat and r["vc"] == vc), key=lambda r: r["tu"])
            ax.plot([r["tu"] for r in sel], [r["Fc_exp"] for r in sel], "s--", color=f"C{k}",
                    label=f"measured [N], {vc:.0f} m/min")
            pts = [(r["tu"], r["Fc_N_per_mm"]) for r in sel if r["Fc_N_per_mm"] is not None]
            if pts:
                p = np.array(pts)
                ax.plot(p[:, 0], p[:, 1], "o-", color=f"C{k}", label=f"refsph [N/mm], {vc:.0f} m/min")
        ax.set_xlabel("uncut chip thickness t_u [mm]")
        ax.set_ylabel("cutting force Fc")
        ax.set_title(mat)
        ax.legend(fontsize=7)
    fig.savefig(FIG / "11_thermal_cutting_trends.png", dpi=100)
    plt.close(fig)
    resolution_figure(res, plt)
    dof_figure(dof_rows(res), plt)
    ceiling_figure(ceiling_series(res), plt)


def ceiling_series(res: dict) -> dict:
    """{label: (comparison rows, marker, colour)} that :func:`ceiling_figure` draws: refsph's SPH at reference update
    0.1 (the 'refined' study) and its PFEM at t_u/10."""
    return {"refsph SPH, ref update 0.1": (comparison(res, REFINED), "o", "C3"),
            "refsph PFEM": (comparison(res, PFEM10), "D", "C0")}


def ceiling_figure(predicted: dict, plt) -> None:
    """Fp/Fc against the rake-face temperature, per material: Merchant's ceiling of the rake face's Coulomb friction
    under the paper's law, tan(atan(mu(T)) - gamma) (:func:`rake_face_ceiling`), as a curve; the measured cuts, the
    paper's SPH and PFEM, and ``predicted`` ({label: (comparison rows, marker, colour)}) as points at their own T_RF.
    A point above the curve has more thrust than friction on the rake face gives at that temperature; the band is
    the T_RF target's 15 % below each measured point."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for ax, mat in zip(axes, MATERIAL_NAMES):
        _, _, ceiling = _ceiling_law(mat)
        T = np.linspace(293.0, 1600.0, 200)
        ax.plot(T, [ceiling(t) for t in T], "k-", lw=1.5, label="ceiling: rake-face friction, tan(atan mu(T) - 10 deg)")
        rows = [r for r in predicted[next(iter(predicted))][0] if r["material"] == mat]
        for r in rows:
            ax.plot([(1.0 - TRF_TARGET) * r["TRF_exp"], r["TRF_exp"]], [r["ratio_exp"]] * 2, "-", color="0.8", lw=4)
        for src, marker, label in (("_exp", "s", "measured"), ("_sph", "s", "paper SPH"), ("_pfem", "^", "paper PFEM")):
            pts = np.array([(r[f"TRF{src}"], r[f"ratio{src}"]) for r in rows])
            ax.plot(pts[:, 0], pts[:, 1], marker, mfc="none" if src != "_exp" else "k",
                    color="k" if src == "_exp" else "0.5", label=label)
        for label, (pred, marker, colour) in predicted.items():
            pts = np.array([(r["TRF"], r["ratio"]) for r in pred
                            if r["material"] == mat and r["TRF"] is not None and r["ratio"] is not None])
            if len(pts):
                ax.plot(pts[:, 0], pts[:, 1], marker, color=colour, label=label)
        ax.set_xlabel("rake-face temperature T_RF [K]")
        ax.set_ylabel("Fp / Fc")
        ax.set_title(f"{mat} (grey bars: 15 % below each measured T_RF)")
        ax.set_ylim(0.0, 1.0)
        ax.legend(fontsize=7)
    study.save_figure(fig, FIG / "11_thermal_cutting_ceiling.png", dpi=100)


def dof_figure(rows: list[dict], plt) -> None:
    """figures/11_thermal_cutting_dof.png: the DOF table (dof_rows) drawn: each method's mean error against the
    measurements over its degrees of freedom, t_u/5 then t_u/10, the paper's SPH and PFEM means on the same cases as
    lines (over the cases of the table's last row of that material)."""
    fig, axes = plt.subplots(2, len(DOF_QUANTITIES), figsize=(12, 6.2), constrained_layout=True, squeeze=False)
    for i, mat in enumerate(MATERIAL_NAMES):
        sel = [r for r in rows if r["material"] == mat]
        for j, (q, name) in enumerate(DOF_QUANTITIES):
            ax = axes[i][j]
            for k, (m, label, mark) in enumerate((("pfem", "refsph PFEM", "^"), ("sph", "refsph SPH", "o"))):
                ax.plot([r[f"dof_{m}"] for r in sel], [r[f"{q}_{m}"] for r in sel], mark + "-", color=f"C{k}",
                        label=label)
                for r in sel:
                    ax.annotate(r["dx"], (r[f"dof_{m}"], r[f"{q}_{m}"]), fontsize=7, xytext=(3, 3),
                                textcoords="offset points")
                if sel:
                    ax.axhline(sel[-1][f"{q}_paper_{m}"], ls="--", color=f"C{k}", lw=1,
                               label=f"the paper's {m.upper()}")
            ax.set_xscale("log")
            ax.set_ylim(bottom=0.0)
            ax.set_title(f"{mat}: {name}", fontsize=10)
            ax.grid(alpha=0.3)
            if i == 1:
                ax.set_xlabel("degrees of freedom")
            if j == 0:
                ax.set_ylabel("mean error [%]")
    axes[0][0].legend(fontsize=7)
    fig.suptitle("Degrees of freedom against the mean error against the measurements: the cases both methods ran "
                 "(the page's DOF table)",
                 fontsize=10)
    study.save_figure(fig, FIG / "11_thermal_cutting_dof.png", dpi=100)


RESOLUTION_SHOWN = ("Fc [N/mm]", "Fp/Fc", "T_RF [K]", "T_FCS [K]")


def resolution_figure(res: dict, plt) -> None:
    """figures/11_thermal_cutting_resolution.png: the resolution study's quantities against dx / t_u, each run with
    its scatter group's standard deviation as an error bar (t_u/15's taken as t_u/10's), the Richardson limit at 0
    where the three runs show an order (``resolution_convergence``)."""
    rows = resolution_convergence(res)
    fig, axes = plt.subplots(1, len(RESOLUTION_SHOWN), figsize=(13, 3.4), constrained_layout=True)
    x = [1.0 / n for n in RESOLUTION_N]
    for ax, name in zip(axes, RESOLUTION_SHOWN):
        for k, case in enumerate(RESOLUTION_KEYS):
            r = next(r for r in rows if r["case"] == case and r["name"] == name)
            sd = r["sd"] + [r["sd"][1]]
            ax.errorbar(x, r["f"], yerr=sd, fmt="o-", color=f"C{k}", capsize=3, label=f"case {case}")
            if r["f0"] is not None:
                ax.plot([0.0, x[2]], [r["f0"], r["f"][2]], ":", color=f"C{k}")
                ax.plot([0.0], [r["f0"]], "*", color=f"C{k}", ms=9)
        ax.set_xlim(left=0.0)
        ax.set_xlabel("dx / t_u")
        ax.set_title(name, fontsize=10)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Resolution: t_u/5, t_u/10, t_u/15 (courant 0.15), bars: run-to-run standard deviation; "
                 "star: Richardson limit where an order is seen", fontsize=9)
    study.save_figure(fig, FIG / "11_thermal_cutting_resolution.png", dpi=100)


def folder_rows(row, folders, rows: dict, wanted) -> dict:
    """``rows`` updated with ``row(folder)`` of each job (``jobs()`` and the retries) for which ``wanted(options,
    numerics)`` holds and whose run folder, looked for in ``folders`` in order, gives a row (not None). A key whose
    folder is gone keeps its earlier row."""
    for key, (options, numerics) in dict(jobs(), **retry_jobs(load()["runs"])).items():
        if wanted(options, numerics):
            r = next((r for r in (row(d / run_folder(key).name) for d in folders) if r is not None), None)
            if r is not None:
                rows[key] = r
    return rows


def folder_study(argv, doc: str, row, wanted, out_json: Path, out_md: Path, page, sort_key=None) -> int:
    """The command of a study that reads the sweep's run folders (pfem_ringing.py, chip_strain.py): ``--runs DIR
    ...`` (default runs/thermal_cutting), its rows (:func:`folder_rows`) merged into ``out_json``, optionally sorted,
    and ``page(rows)`` written to ``out_md`` and printed."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--runs", type=Path, nargs="+", default=[RUNS],
                    help="folders of the sweep's run folders, looked in in order (default runs/thermal_cutting)")
    args = ap.parse_args(argv)
    rows = folder_rows(row, args.runs, json.loads(out_json.read_text()) if out_json.exists() else {}, wanted)
    if sort_key is not None:
        rows = dict(sorted(rows.items(), key=sort_key))
    out_json.write_text(json.dumps(rows, indent=1) + "\n")
    out_md.write_text(page(rows))
    print(page(rows))
    return 0


def run_folder(key: str, quick: bool = False) -> Path:
    """The run folder of a job (``runs/thermal_cutting/<key>``)."""
    return RUNS / (key.replace(" ", "_").replace("/", "") + ("_quick" if quick else ""))


def status_lines(records: dict, todo: dict, quick: bool = False) -> list[str]:
    """One line per job of ``todo``: its record's status, or how far its run folder has got (the simulated time
    of its last snapshot's summary against the run's end, steps, wall time so far: a run in progress, or one that
    was killed and continues from there), or 'to run'."""
    lines = []
    for key in todo:
        rec = records.get(key)
        if rec is not None:
            wall = rec.get("wall_time_s")
            lines.append(f"{key:40s} recorded: {rec.get('status')}"
                         + ("" if wall is None else f" ({wall / 60:.0f} min)"))
            continue
        path = run_folder(key, quick) / "summary.json"
        try:
            s = json.loads(path.read_text())
        except (OSError, ValueError):                        # before its first snapshot: its heartbeat, if any
            beat = _heartbeat(path.parent, 0.0)
            t = None if quick else _checkpoint_time(PARKED / path.parent.name / "restart.npz")
            parked = None if t is None else f"parked at t = {t * 1e3:.3f} ms (a rerun continues from there)"
            lines.append(f"{key:40s} {beat or parked or 'to run'}")
            continue
        beat = _heartbeat(path.parent, path.stat().st_mtime) if s.get("status") == "running" else None
        if beat is not None:
            lines.append(f"{key:40s} {beat}")
            continue
        t, t_end, wall = s.get("t_final") or 0.0, s.get("t_end") or float("nan"), s.get("wall_time_s") or 0.0
        left = wall * (t_end / t - 1.0) if t > 0 else float("nan")
        age = (time.time() - path.stat().st_mtime) / 60
        lines.append(f"{key:40s} {s.get('status')}: t = {t * 1e3:.3f} of {t_end * 1e3:.3f} ms "
                     f"({100 * t / t_end:.0f} %), {s.get('n_steps')} steps, {wall / 60:.0f} min so far, "
                     f"about {left / 60:.0f} min to go; summary written {age:.0f} min ago")
    return lines


def park(records: dict, todo: dict) -> list[str]:
    """``--park``: the checkpoint of each job of ``todo`` that is not recorded, from its run folder, into PARKED
    (:func:`study.park`, with the job's options and numerics); then the parked checkpoints of recorded jobs, of no
    job at all, or of a job whose options or numerics have changed since, dropped (their run folders are not
    touched). One line per change."""
    lines = []
    for key in todo:
        if key not in records and study.park(run_folder(key), PARKED / run_folder(key).name, todo[key]):
            t = _checkpoint_time(PARKED / run_folder(key).name / "restart.npz")
            lines.append(f"parked {key}" + ("" if t is None else f" at t = {t * 1e3:.3f} ms"))
    every = {**jobs(), **retry_jobs(records), **todo}
    wanted = {run_folder(k).name: job for k, job in every.items() if k not in records}
    lines += [f"dropped {name}" for name in study.prune_parked(
        PARKED, lambda name: name in wanted and not study.parked_job_differs(PARKED / name, wanted[name]))]
    return lines or ["nothing to park"]


def _heartbeat(folder: Path, summary_written: float) -> str | None:
    """The run's state from its heartbeat (:func:`refsph.io.write_progress`, every 30 s) where that is newer than
    its summary: 'running: ' t, steps, this process's rate and the time to go; or 'stopped: ' where the process that
    wrote it is gone (:func:`refsph.io.writer_alive`: a killed run, or a machine restarted); None without one."""
    try:
        b = json.loads((folder / "progress.json").read_text())
    except (OSError, ValueError):
        return None
    from refsph.io import writer_alive
    gone = writer_alive(b) is False                          # also where the summary is newer (killed after it)
    if b.get("written", 0.0) <= summary_written and not gone:
        return None
    t, t_end, t0, wall = b["t"], b["t_end"], b.get("t_begin", 0.0), b["wall_s"]
    age = (time.time() - b["written"]) / 60
    if gone:
        ck = _checkpoint_time(folder / "snapshots" / "restart.npz")
        return (f"stopped: its process ({b['pid']}) is gone, last heard of {age:.0f} min ago at t = {t * 1e3:.3f} of "
                f"{t_end * 1e3:.3f} ms ({100 * t / t_end:.0f} %); a rerun of the key continues from its last "
                "checkpoint" + ("" if ck is None else f", at t = {ck * 1e3:.3f} ms"))
    left = wall * (t_end - t) / (t - t0) if t > t0 else float("nan")
    return (f"running: t = {t * 1e3:.3f} of {t_end * 1e3:.3f} ms ({100 * t / t_end:.0f} %), {b['steps']} steps, "
            f"this process {wall / 60:.0f} min, about {left / 60:.0f} min to go; heartbeat {age:.0f} min ago")


def _checkpoint_time(path: Path) -> float | None:
    """The simulated time of a checkpoint ``path`` (a run folder's ``snapshots/restart.npz``, or a parked one): an
    SPH run's names it in its run record, a PFEM run's is its nodes' time; None where there is none or it does not
    say (an older one's)."""
    try:
        with np.load(path) as z:
            t = float(z["nodes/t"]) if "nodes/t" in z.files else json.loads(str(z["run"])).get("t")
    except (OSError, ValueError, KeyError):
        return None
    return float(t) if isinstance(t, (int, float)) else None


def backfill_cpu(st) -> list[str]:
    """Records made before the sweep kept the CPU seconds get them from their run folder's summary.json, where that
    is the same run (ok, the same number of steps); the keys filled."""
    filled = []

    def change(doc):
        for key, rec in doc.get("runs", {}).items():
            path = run_folder(key, rec.get("quick", False)) / "summary.json"
            if rec.get("cpu_time_s") is not None or rec.get("status") != "ok" or not path.exists():
                continue
            s = json.loads(path.read_text())
            if s.get("status") == "ok" and s.get("n_steps") == rec.get("n_steps") and s.get("cpu_time_s"):
                rec["cpu_time_s"] = s["cpu_time_s"]
                filled.append(key)
    st.update(change)
    return filled


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    if args.quick and args.json == OUT_JSON:
        _parser().error("--quick writes try-out records: give them their own --json file")
    todo = jobs(args.study or STUDY_NAMES, args.only)
    todo.update({k: v for k, v in retry_jobs(store(args.json).records(), args.study or STUDY_NAMES).items()
                 if k not in todo and (args.only is None or v[0]["case"] in args.only)})
    if args.keys is not None:
        unknown = [k for k in args.keys if k not in todo]
        if unknown:
            _parser().error(f"--keys: no such run in the studies asked for: {unknown}")
        todo = {k: todo[k] for k in args.keys}
    if args.status:
        print("\n".join(status_lines(store(args.json).records(), todo, args.quick)))
        return 0
    if args.park:
        print("\n".join(park(store(args.json).records(), todo)))
        return 0
    if args.merge is not None:
        try:
            merged = store(args.json).merge(args.merge)
        except ValueError as e:
            _parser().error(f"--merge: {e}")
        print("\n".join(f"{what}: {', '.join(keys) or 'none'}" for what, keys in merged.items()))
        args.report = True                                  # then the page, not a sweep
    if args.backfill_cpu:
        print(f"CPU seconds from the run folders: {', '.join(backfill_cpu(store(args.json))) or 'none'}")
        args.report = True                                  # then the page, not a sweep
    if not args.report:
        if not sweep(store(args.json), todo, args):
            print("nothing ran: every run asked for is recorded; the JSON, the page and the figures are unchanged "
                  "(--redo KEY runs one again, --report rewrites the page)")
            return 0
    res = load(args.json)                                 # with what another sweep on the same file added
    if args.json != OUT_JSON:
        print(report(res))
        print(f"wrote {args.json}")
        return 0
    REPORT.write_text(report(res))
    figures(res)
    print(f"wrote {OUT_JSON}, {REPORT}, figures/11_thermal_cutting_*.png")
    return 0


def _parser():
    ap = study.parser(__doc__, "jobs", "scheduler", "only", jobs=dict(default=2, help="local processes (default 2)"),
                      only=dict(type=int, nargs="*", help="case numbers to run (default: all 18)"))
    ap.add_argument("--study", nargs="*", choices=STUDY_NAMES, default=None,
                    help="which runs: the 18 cases, the mass-scaling, scatter, resolution, tool-size and contact "
                         "checks (default: all, in the order jobs() gives)")
    ap.add_argument("--redo", nargs="*", default=(), help="keys to run again (e.g. 'case 3')")
    ap.add_argument("--keys", nargs="*", default=None,
                    help="only these runs, by key, in this order (e.g. 'case 1 s/2' 'case 11'; keys of --study)")
    study.add_flags(ap, "report", "quick", report=dict(help="table and figures from the committed JSON only"),
                    quick=dict(help="quick short cuts (a try-out; give --json elsewhere)"))
    ap.add_argument("--json", type=Path, default=OUT_JSON, help="the records (default: the committed JSON)")
    ap.add_argument("--backfill-cpu", action="store_true",
                    help="records without CPU seconds get them from their run folder's summary (then the report)")
    ap.add_argument("--merge", type=Path, default=None, metavar="JSON",
                    help="take the records of another sweep's JSON (another worktree or machine) that are missing "
                         "here, or good there and failed here (never the other way), then write the page")
    ap.add_argument("--status", action="store_true",
                    help="no runs: each job's record, or how far its run folder has got, or 'to run'")
    ap.add_argument("--park", action="store_true",
                    help="no runs: keep the last checkpoint of every unrecorded job's run folder in "
                         "benchmarks/parked/thermal_cutting/ (to commit: a run longer than a session continues "
                         "from there in a new checkout), and drop the parked ones whose job is recorded")
    return ap


def _same_options(recorded: dict, asked: dict) -> bool:
    """Whether a record's scene options are the job's (the scene's defaults filled in, lengths to 1e-12 m)."""
    from refsph.scenes.thermal_cutting import OPTIONS
    defaults = {k: v for k, (v, _) in OPTIONS.items()}
    a, b = dict(defaults, **recorded), dict(defaults, **asked)
    return a.keys() == b.keys() and all(
        a[k] == b[k] or (isinstance(a[k], float) and isinstance(b[k], float) and abs(a[k] - b[k]) < 1e-12) for k in a)


def sweep(runs: study.RunStore, todo: dict, args) -> list:
    """Run the keys of ``todo`` not yet recorded (or in ``--redo``), each record stored as it comes (a failed run
    never replaces a good record: study.RunStore), then the retries (``retry_jobs``) that this sweep's own failures
    call for (not those another sweep on the same file records meanwhile), in the same call, so that an unattended
    sweep takes a failed case again; the keys that ran."""
    ran = _sweep_round(runs, todo, args)
    recs = runs.records()
    retries = {k: v for k, v in retry_jobs({k: recs[k] for k in ran if k in recs}, args.study or STUDY_NAMES).items()
               if k not in ran}
    if retries:
        print(f"retrying what failed: {', '.join(retries)}", flush=True)
        ran += _sweep_round(runs, retries, args)
    return ran


def _sweep_round(runs: study.RunStore, todo: dict, args) -> list:
    """One pass of ``sweep`` over ``todo``: the keys that ran."""
    stale = [k for k, r in runs.records().items() if k in todo and k not in args.redo
             and (not _same_options(r.get("options", {}), todo[k][0]) or r.get("numerics", {}) != todo[k][1])]
    if stale:
        raise SystemExit(f"error: the records of {stale} were made with other scene options or numerics than "
                         "jobs() gives now; --redo them (their old runs are kept until a good one replaces them)")
    todo = {k: todo[k] for k in runs.pending(todo, redo=args.redo)}
    print(f"{len(todo)} runs to do ({len(runs.records())} recorded)", flush=True)
    t0 = time.perf_counter()
    tasks = {k: (k, o, nm, args.quick) for k, (o, nm) in todo.items()}
    ran = []
    for k, (key, rec) in enumerate(study.execute(run_case, tasks, args.jobs, args.scheduler)):
        runs.commit(key, rec)
        ran.append(key)
        m = rec.get("metrics", {})
        print(f"[{k + 1}/{len(todo)}] {key:24s} {rec['status']:6s} Fp/Fc {_f(m.get('force_ratio'), '.2f')} "
              f"T_RF {_f(m.get('rake_face_temperature_K'), '.0f')} K, {_f(rec.get('wall_time_s'), '.0f')} s "
              f"({(time.perf_counter() - t0) / 60:.1f} min elapsed)", flush=True)
    return ran


if __name__ == "__main__":
    sys.exit(main())
