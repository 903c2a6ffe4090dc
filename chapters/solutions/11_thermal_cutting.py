# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Chapter 11 — worked solutions (lecturer's copy)
#
# Each solution runs in the namespace of `chapters/11_thermal_cutting.py`, on the chapter's own cut (`res`: case 1,
# AISI 1045 at 60 m/min, $t_u$ = 0.1 mm; in quick mode a 0.9 mm workpiece and 3 $t_u$ of cut) and the records its
# figure reads: `refsph handout DIR --instructor` inserts it right after its exercise, and `tests/test_exercises.py`
# executes that copy in quick mode, so every number quoted here is asserted (quick mode; at full resolution they
# differ). This file does not run on its own.

# %% [markdown]
# ### Solution 1 — Switch the heat flow off
#
# Adiabatic, the rake face's mean temperature rises from 531 to 573 K, but its hottest contact particle from 621 to
# 993 K and the hottest particle of the cut from 648 to 1069 K. The heat is made in thin shear zones, the
# secondary one just above the rake face; conduction spreads it, within the cut's 0.3 ms, over a few spacings
# ($\sqrt{k t/\rho c_p}$ is about 60 µm in steel), into the chip and into the tool (2 % of the heat made leaves
# through the held faces). Without it every joule stays in the particle that made it, and the hottest
# particles are those that sheared most. The free chip surface is 27 K colder (no heat reaches it from the
# interface), and the forces hardly move: at these temperatures the yield stress is only a little lower.
#
# `conduction=False` switches the frictional and dissipation heat off too; they are 0.6 % and 12 % of the heat
# made with conduction on, so most of the difference is conduction's.

# %%
from refsph.paper_data import AISI1045_RLA as steel

adiabatic = run("thermal_cutting", "tlsph", quick=ch.quick, progress=False, options=dict(opts, conduction=False),
                numerics=dict(threads=1))
on, off = res.summary["metrics"], adiabatic.summary["metrics"]
for key in ("rake_face_temperature_K", "rake_face_temperature_max_K", "max_temperature_K",
            "free_chip_surface_temperature_K", "force_ratio", "cutting_force_N_per_m"):
    print(f"{key:33s} with heat flow {on[key]:10.2f}, adiabatic {off[key]:10.2f}")
assert adiabatic.summary.get("heat_balance") is None                    # no heat flow, no ledger
# the numbers of the text to 2 K: the contact's stick/slip switches carry round-off from one NumPy or SciPy release
# to the next into the hottest particles (the adiabatic T_RF max: 992.5 K with one, 992.49 K with the next)
keys = ("rake_face_temperature_K", "rake_face_temperature_max_K", "max_temperature_K")
assert np.allclose([on[k] for k in keys], [531, 621, 648], rtol=0, atol=2)
assert np.allclose([off[k] for k in keys], [573, 993, 1069], rtol=0, atol=2)
assert abs(on["free_chip_surface_temperature_K"] - off["free_chip_surface_temperature_K"] - 27) < 2
assert abs(off["force_ratio"] / on["force_ratio"] - 1) < 0.1 and abs(
    off["cutting_force_N_per_m"] / on["cutting_force_N_per_m"] - 1) < 0.05
assert 55e-6 < np.sqrt(steel["k_W_mK"] * res.setup.t_end / (steel["rho"] * steel["cp_J_kgK"])) < 65e-6
made = hb["plastic_J"] + hb["friction_J"] + hb["dissipation_J"]
assert round(100 * hb["removed_J"] / made) == 2
assert round(100 * hb["friction_J"] / made, 1) == 0.6 and round(100 * hb["dissipation_J"] / made) == 12

# %% [markdown]
# ### Solution 2 — The tool's heat capacity
#
# The diffusion time across a depth $d$ is about $\rho c_p d^2/k$. For the 0.3 mm deep tool of the quick cut: 0.36
# ms with 15 J/(kg K), about the cut's 0.30 ms, so the tool's temperature field can settle within the cut; with 200,
# 4.8 ms, 16 cuts long: the simulated tool would stay nearly cold and draw more heat from the rake face than the
# real one does once it has warmed up over seconds of cutting. That is Childs' argument for the reduced $c_p$: it
# fast-forwards the tool, not the chip.
#
# The explicit conduction step is 1.3 µs in the tool (17 µs with 200; 24 µs in the chip) against the mechanical
# step of 0.063 µs: conduction never limits this run. That step is already 38 times longer than without mass
# scaling ($s$ = 1464, the step grows as $\sqrt s$); the heat step would bind only in a much smaller, much more
# conductive body.

# %%
tau_of = {cp: carbide["rho"] * cp * depth**2 / carbide["k_W_mK"] for cp in (15.0, 200.0)}
dt_of = {cp: thermal_time_step(carbide["rho"], cp, carbide["k_W_mK"], res.setup.h, 0.3) for cp in (15.0, 200.0)}
dt_chip = thermal_time_step(steel["rho"], steel["cp_J_kgK"], steel["k_W_mK"], res.setup.h, 0.3)
print(f"tau: {tau_of[15.0] * 1e3:.2f} / {tau_of[200.0] * 1e3:.2f} ms (cut {t_cut * 1e3:.2f} ms); conduction step "
      f"tool {dt_of[15.0]:.2e} / {dt_of[200.0]:.2e} s, chip {dt_chip:.2e} s; mechanical {dt_wave:.2e} s; "
      f"sqrt(s) = {np.sqrt(info['mass_scale']):.1f}")
assert round(depth * 1e3, 2) == 0.3 and round(t_cut * 1e3, 2) == 0.3 and res.setup.thermal.courant == 0.3
assert round(tau_of[15.0] * 1e3, 2) == 0.36 and round(tau_of[200.0] * 1e3, 1) == 4.8
assert round(dt_of[15.0] * 1e6, 1) == 1.3 and round(dt_of[200.0] * 1e6) == 17 and round(dt_chip * 1e6) == 24
assert round(dt_wave * 1e6, 3) == 0.063 and round(np.sqrt(info["mass_scale"])) == 38

# %% [markdown]
# ### Solution 3 — Systematic or random?
#
# Systematic: in all nine steel cases of the $t_u/10$ table refsph is below the measurement on all three
# quantities. The force ratio is 39–51 % low, the free chip surface 15–24 % cold, the rake face 7–26 % cold (14 %
# in case 1), on average colder at 120 and 180 m/min (21 and 24 %) than at 60 (13 %), because the measured
# rake-face temperature rises with the speed faster than refsph's. Nine cases with one sign are not noise (section 6's scatter:
# 2–5 % in T, 12 % in Fp/Fc): the model lacks something, such as thrust from the edge and the flank, friction above the law's
# $\mu$ (Merchant, "Where it fails") or heat at the rake face. Titanium goes the other way: rake face 19–38 %, free
# surface 12–30 % too hot. The rake face's sign is the numerics' as much as the model's: at the
# converged reference update 0.1 seven of the nine steel rake faces are 6–27 % too hot (cases 8 and 9 at the
# measurement, +0.1 and +1.7 %), while the force ratio stays 46–57 % low.

# %%
err_all = {}
for q, mq in MEASURED.items():
    err_all[q] = {}
    for n in range(1, 10):
        m = cut_record(records, f"case {n}", CUT_RETRIES[""])[1]["metrics"]
        err_all[q][n] = m[q] / m["measured"][mq] - 1
    e = np.array(list(err_all[q].values()))
    print(f"{q:33s} steel: {100 * e.min():+.1f} % to {100 * e.max():+.1f} %")
assert all(e < 0 for q in err_all for e in err_all[q].values())
ratio, rake, free = (np.array(list(err_all[q].values())) for q in MEASURED)
assert (round(-100 * ratio.max()), round(-100 * ratio.min())) == (39, 51)
assert (round(-100 * free.max()), round(-100 * free.min())) == (15, 24)
assert (round(-100 * rake.max()), round(-100 * rake.min())) == (7, 26)
assert round(100 * err_all["rake_face_temperature_K"][1]) == -14
ti = records["case 10"]["metrics"]
assert round(100 * (ti["rake_face_temperature_K"] / ti["measured"]["T_RF_K"] - 1)) == 19
assert round(100 * (ti["free_chip_surface_temperature_K"] / ti["measured"]["T_FCS_K"] - 1)) == 12
refined = [records[f"case {n} ref update 0.1 frequency step 0.5"]["metrics"] for n in range(1, 10)]
hot = np.array([m["rake_face_temperature_K"] / m["measured"]["T_RF_K"] - 1 for m in refined])
low = np.array([m["force_ratio"] / m["measured"]["force_ratio"] - 1 for m in refined])
assert (round(100 * hot.min()), round(100 * hot.max())) == (0, 27) and (round(-100 * low.max()), round(-100 * low.min())) == (46, 57)
assert sum(hot > 0.05) == 7 and round(100 * np.sort(hot)[2]) == 6
speed = [100 * np.mean(rake[i:i + 3]) for i in (0, 3, 6)]          # cases 1-3, 4-6, 7-9: 60, 120, 180 m/min
assert [round(-x) for x in speed] == [13, 21, 24]

# %% [markdown]
# ### Solution 4 — Write the heat flow between two materials yourself
#
# The handed-out stub failed as it should (asserted first). A worked answer: section 1's pair loop, vectorised over
# the half pairs, with the harmonic-mean conductivity in the flux (`np.divide` with `where=` gives 0 where both
# conductivities are 0), the flux added to $i$ with $V_j$ and taken from $j$ with $V_i$, and $1/(\rho_i c_i)$ at
# the end. Each pair term moves heat and makes none: $\sum_i \rho_i c_i V_i\,dT_i/dt = 0$, checked below.
#
# Then the two mistakes the exercise asks about: the arithmetic mean fails the steel beside carbide; no guard gives
# NaN at the insulator's own pairs. The harmonic mean is the series conductance of two half-spacings of the two
# materials: an insulator on either side stops the flux, as it must.

# %%
assert not report, "the stub as handed out must fail the grader"
from refsph.neighbours import find_pairs


def my_heat_rate(T, x, V, rho, c, k, h, kernel, mean="harmonic"):
    """dT/dt [K/s] of every particle by conduction, with the harmonic-mean pair conductivity."""
    I, J = find_pairs(x, kernel.support * h)
    r = np.linalg.norm(x[I] - x[J], axis=1)
    dWdr = kernel.dw_dr_over_r(r, h, x.shape[1]) * r
    if mean == "harmonic":
        k_ij = np.divide(2 * k[I] * k[J], k[I] + k[J], out=np.zeros(len(I)), where=k[I] + k[J] > 0)
    elif mean == "unguarded":
        k_ij = 2 * k[I] * k[J] / (k[I] + k[J])
    else:
        k_ij = 0.5 * (k[I] + k[J])
    flux = 2 * k_ij * (T[I] - T[J]) / r * dWdr
    heat = np.bincount(I, flux * V[J], minlength=len(x)) - np.bincount(J, flux * V[I], minlength=len(x))
    return heat / (rho * c)


assert check(my_heat_rate, pkg_heat_rate, cases_ex4)
arith = check(lambda *a: my_heat_rate(*a, mean="arithmetic"), pkg_heat_rate, cases_ex4, name="arithmetic mean")
assert not arith and arith.n_passed == 1
unguarded = check(lambda *a: my_heat_rate(*a, mean="unguarded"), pkg_heat_rate, cases_ex4, name="no guard")
assert not unguarded and unguarded.n_passed == 2 and "nan" in unguarded.message
for cs in cases_ex4:
    T_c, x_c, V_c, rho_c, c_c, k_c = cs.args[:6]
    assert abs(np.sum(rho_c * c_c * V_c * my_heat_rate(*cs.args))) < 1e-9 * np.sum(
        np.abs(rho_c * c_c * V_c * my_heat_rate(*cs.args)))
