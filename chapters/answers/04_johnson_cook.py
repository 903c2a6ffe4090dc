"""Answer key of chapter 4 (Johnson-Cook), run by tests/test_exercises.py in quick mode.

* answer_1: above the reference rate the uniaxial flow stress is lifted by 1 + C ln(rate / eps_dot_0) (4340 at
  1e5 /s: about 16 %); below it (1e-2 /s) the clamp of refsph leaves it at the 1 /s value.
* answer_2: in adiabatic shear a smaller Taylor-Quinney coefficient chi (less of the plastic work becomes heat)
  moves the stress peak to a larger strain, keeps the particle cooler and stronger; chi = 0 keeps it at room
  temperature and the curve hardens to the end (no peak).
* answer_3: with T_m = 1793 K instead of 1293 K the adiabatic particle is stronger at the end, peaks later, and is
  hotter (more plastic work per unit strain).
"""
import math
from dataclasses import replace

import numpy as np

from refsph.teaching.material_point import material_point
from refsph.plasticity import yield_stress
from refsph.scenes.taylor import taylor_johnson_cook, taylor_material

MAT = taylor_material()
JC = taylor_johnson_cook(1293.0, 1.0)
T0 = JC.T_room


def flow_stress_ratio(rate):
    """Exercise 1: uniaxial flow stress at eps_p = 0.2 over Eq. (25) at the reference rate."""
    o = material_point(MAT, JC, np.diag([rate, 0.0, 0.0]), 0.3 / (rate * 300), 300, T0, heating=False,
                       lateral_stress_free=True)
    return np.interp(0.2, o["eps_p"], o["sigma"][:, 0, 0]) / yield_stress(JC, 0.2, JC.eps_dot_0, T0)


def adiabatic_shear(jc):
    """Exercises 2 and 3: simple shear at 1e4 /s to an equivalent strain of 2, heating on."""
    rate = 1e4
    gdot = math.sqrt(3.0) * rate
    o = material_point(MAT, jc, [[0, gdot, 0], [0, 0, 0], [0, 0, 0]], 2.0 / (rate * 500), 500, T0, heating=True)
    k = int(np.argmax(o["sigma_vm"]))
    return dict(eps_peak=o["eps_p"][k], k_peak=k, n=len(o["eps_p"]) - 1, s_end=o["sigma_vm"][-1], T_end=o["T"][-1],
                T_max=o["T"].max())


def answer_1():
    fast, base, slow = flow_stress_ratio(1e5), flow_stress_ratio(1e3), flow_stress_ratio(1e-2)
    assert fast > base > slow
    assert abs(fast / (1 + JC.C * math.log(1e5 / JC.eps_dot_0)) - 1) < 0.01
    assert abs(slow - 1) < 0.01                    # clamped: no rate effect below eps_dot_0


def answer_2():
    full, half, none = (adiabatic_shear(replace(JC, chi=c)) for c in (0.9, 0.45, 0.0))
    assert half["eps_peak"] > full["eps_peak"] and half["T_end"] < full["T_end"] and half["s_end"] > full["s_end"]
    assert none["T_max"] == T0 and none["k_peak"] == none["n"]      # no heating: hardens to the end


def answer_3():
    low, high = (adiabatic_shear(replace(JC, T_melt=Tm)) for Tm in (1293.0, 1793.0))
    assert high["s_end"] > 1.1 * low["s_end"]
    assert high["eps_peak"] > low["eps_peak"]
    assert high["T_end"] > low["T_end"]
