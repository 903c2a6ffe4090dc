"""Answer key of chapter 11 (thermomechanical cutting), run by tests/test_exercises.py in quick mode. Each answer
runs a very short quick cut (case 1, a 0.5 mm workpiece, one t_u of cut: a few seconds; the chip has only begun)
and compares with the same cut with everything on. Measured (this key's runs):

* answer_1: without conduction the rake face's *mean* temperature hardly moves (405 against 404 K): the scene's
  ``conduction=false`` is the first paper's adiabatic model, so it switches the frictional heat and the heat of the
  numerical dissipation off too (``Setup.friction_heat``, ``Setup.dissipation_heat``), but with the penalty
  contact the chip's contact particles mostly stick at this early stage and friction makes little heat (0.12 of
  17 J/m). The hottest particle is much hotter (568 against 490 K): without conduction the heat of the shear zone
  stays where it is made.
* answer_2: the split of the frictional heat hardly matters: all of it into the chip raises T_RF by ~1 K over all
  of it into the tool (there is little of it, and conduction across the interface, harmonic-mean k, moves it on
  within a few steps); the tool stores more heat when it gets the whole share (0.33 against 0.32 J/m).
* answer_3: frictionless, Fp/Fc falls from 0.44 to about 0 (the thrust at this early stage is friction) and the
  frictional heat is zero; the rake face's mean temperature moves by about 1 K, the plastic heat falls by a
  quarter (11.6 against 15.9 J/m: the sticking chip is sheared less).
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
    assert abs(off[0]["rake_face_temperature_K"] - on["rake_face_temperature_K"]) < 0.02 * on[
        "rake_face_temperature_K"]
    assert off[0]["max_temperature_K"] > on["max_temperature_K"] + 20.0


def answer_2():
    to_tool, to_chip = _cut(chip_fraction=0.0), _cut(chip_fraction=1.0)
    dT = to_chip[0]["rake_face_temperature_K"] - to_tool[0]["rake_face_temperature_K"]
    assert 0.0 < dT < 0.05 * to_tool[0]["rake_face_temperature_K"]
    assert to_tool[2] > to_chip[2] > 0.0


def answer_3():
    (on, heat_on, _), (off, heat, _) = _cut(), _cut(friction=False)
    assert off["force_ratio"] < 0.2 * on["force_ratio"]
    assert heat["friction_J"] == 0.0
    assert abs(off["rake_face_temperature_K"] - on["rake_face_temperature_K"]) < 0.02 * on["rake_face_temperature_K"]
    assert heat["plastic_J"] < 0.9 * heat_on["plastic_J"]
