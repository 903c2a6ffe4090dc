"""Answer key of chapter 11 (thermomechanical cutting), run by tests/test_exercises.py in quick mode. Each answer
runs a very short quick cut (case 1, a 0.5 mm workpiece, one t_u of cut: a few seconds; the chip has only begun)
and compares with the same cut with everything on. Measured (this key's runs):

* answer_1: without conduction the rake face's *mean* temperature is lower (363 against 429 K): the scene's
  ``conduction=false`` is the first paper's adiabatic model, so it switches the frictional heat off too
  (``Setup.friction_heat``, its own switch in a Setup of one's own), and that heat is made right at the rake face.
  But the hottest particle is hotter (564 against 507 K): the heat of the shear zone stays where it is made.
* answer_2: the split of the frictional heat hardly matters: all of it into the chip raises T_RF by ~8 K over
  all of it into the tool, because conduction across the interface (harmonic-mean k) moves it on within a few
  steps; the tool stores more heat when it gets the whole share (0.70 against 0.52 J/m).
* answer_3: frictionless, Fp/Fc falls from 0.34 to about 0.02 (the thrust at this early stage is nearly all
  friction) and the frictional heat is zero; the rake face is ~45 K colder.
"""
from functools import lru_cache

from refsph.simulate import run


@lru_cache(maxsize=None)
def _cut(**changes):
    options = dict(case=1, length=0.5e-3, travel=1.0, **changes)
    res = run("thermal_cutting", "tlsph", quick=True, progress=False, options=options, numerics=dict(threads=1))
    n = res.setup.info["n_work"]
    tool_heat = float(((res.state.T[n:] - 293.0) * res.state.m[n:] * res.setup.thermal.tools[1][1]).sum()) \
        if res.setup.thermal is not None else 0.0
    return res.summary["metrics"], res.summary.get("heat_balance"), tool_heat


def answer_1():
    on, off = _cut()[0], _cut(conduction=False)
    assert off[1] is None                                   # no heat flow: no ledger, no frictional heat
    assert off[0]["rake_face_temperature_K"] < on["rake_face_temperature_K"]
    assert off[0]["max_temperature_K"] > on["max_temperature_K"] + 20.0


def answer_2():
    to_tool, to_chip = _cut(chip_fraction=0.0), _cut(chip_fraction=1.0)
    dT = to_chip[0]["rake_face_temperature_K"] - to_tool[0]["rake_face_temperature_K"]
    assert 0.0 < dT < 0.05 * to_tool[0]["rake_face_temperature_K"]
    assert to_tool[2] > to_chip[2] > 0.0


def answer_3():
    on, (off, heat, _) = _cut()[0], _cut(friction=False)
    assert off["force_ratio"] < 0.6 * on["force_ratio"]
    assert heat["friction_J"] == 0.0
    assert off["rake_face_temperature_K"] < on["rake_face_temperature_K"]
