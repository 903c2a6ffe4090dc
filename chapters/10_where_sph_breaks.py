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
# # Chapter 10 — Where SPH breaks, and what each remedy costs
#
# The benchmarks of chapters 6–8 run. That does not mean the method is safe: a code must also *fail loudly or
# survive* on the cases that break it. Five mechanisms break SPH solids, each with a standard remedy:
#
# | failure | where | remedy (`--set ...`) |
# |---|---|---|
# | tensile instability: particles clump in tension | ESPH | artificial pressure `gamma` (Eq. (14)) |
# | non-objectivity at free surfaces: a rotation reads as strain | ESPH | `esph_correction=true` |
# | zero-energy (hourglass) modes: zig-zags F cannot see | TLSPH | `hourglass=1` (Ganzenmüller 2015) |
# | interpenetration: bodies do not know each other | TLSPH | the pinball contact between bodies |
# | growth of undamped modes in the time stepper | both | `integrator=leapfrog`, or artificial viscosity |
#
# We show each on a hard case at quick resolution, with the remedy off and on, and time both: a remedy is only
# worth what it costs.

# %%
import json
import matplotlib.pyplot as plt
import numpy as np
from refsph.teaching.notebook import chapter, repository_root
from refsph.teaching.plots import particle_field
from refsph.simulate import SimulationError, run
ch = chapter("10_where_sph_breaks")

# %% [markdown]
# ## 1. The tensile instability (ESPH)
#
# A block in free flight expands and goes into tension (`refsph run tension`). In tension the SPH pressure force
# between two particles turns attractive, and a small perturbation pulls neighbours into pairs (chapter 2). The
# smallest pair distance says it: about 1 spacing in a healthy lattice, much less when particles clump.

# %%
def quick(scene, method, numerics=None, **kw):
    res = run(scene, method, quick=True, progress=False, numerics=dict(numerics or {}, threads=1), **kw)
    return res.summary["metrics"], res.summary["wall_time_s"], res


for gamma in (0.0, 0.3):
    m, wall, _ = quick("tension", "esph", dict(gamma=gamma))
    print(f"ESPH gamma = {gamma}: smallest pair distance {m['min_pair_distance_over_dp']:.2f} dp  ({wall:.1f} s)")

# %% [markdown]
# ## 2. Non-objectivity at free surfaces (ESPH)
#
# A free disc set spinning as a rigid body should spin on, unstressed but for the small centrifugal stress
# (`refsph run spinning_disc`). Eq. (23) at a free surface turns the rotation into a spurious strain rate
# (chapter 2, the patch test), so uncorrected ESPH builds stress and brakes the disc. Here a tenth of a turn at a
# rim speed of 1 % of $c_L$:

# %%
for method, numerics in (("esph", {}), ("esph", dict(esph_correction=True))):
    m, wall, _ = quick("spinning_disc", method, numerics, options=dict(speed=0.01, turns=0.1))
    print(f"{method} {str(numerics or ''):28s} L/L0 = {m['angular_momentum_ratio']:.5f}, stress "
          f"{m['max_stress_over_1pct']:.1e} x E 1 % (centrifugal {m['centrifugal_stress_over_1pct']:.1e})"
          f"  ({wall:.1f} s)")

# %% [markdown]
# The corrected gradient costs one more $d \times d$ pair sum (the moment matrix) and a small inverse per particle.
#
# ## 3. Two rings: the zero-energy mode, and bodies that must not merge
#
# Two elastic rings thrown at each other (Gray, Monaghan & Swift 2001; `refsph run rings`) should bounce off and
# fly apart whole. In TLSPH each ring is a body: its neighbours are its own, and the rings meet through the pinball
# contact (chapter 5, now between two deformable bodies). ESPH has no contact law: within $2h$ the rings are one
# continuum to the SPH sums. We run each method with its remedy off and on (45 µs: the impact and the rebound):

# %%
ring_runs = {"TLSPH, no hourglass control": ("tlsph", dict(hourglass=0.0)),
             "TLSPH, hourglass = 1": ("tlsph", dict(hourglass=1.0)),
             "ESPH, gamma = 0": ("esph", dict(gamma=0.0)),
             "ESPH, gamma = 0.3": ("esph", dict(gamma=0.3))}
fig, axes = plt.subplots(1, 4, figsize=(15, 3.6), constrained_layout=True)
for ax, (name, (method, numerics)) in zip(axes, ring_runs.items()):
    m, wall, res = quick("rings", method, numerics, t_end=45e-6)
    print(f"{name:28s}: {m['n_fragments']} pieces, restitution {m['restitution']:.2f}, closest pair "
          f"{m['min_pair_distance_over_dp']:.3f} dp, closest rings {m['min_interbody_distance_over_dp']:.2f} dp"
          f"  ({wall:.1f} s)")
    particle_field(ax, res.state.x, res.state.body.astype(float), res.setup.dp, vmin=0, vmax=1)
    ax.set(title=name, xlabel="x [mm]", ylabel="y [mm]", aspect="equal")
ch.show(fig, "10_rings.png", caption="Two elastic rings after their impact and rebound (45 µs), one colour per ring: "
                                     "TLSPH without and with hourglass control, ESPH with γ = 0 and with γ = 0.3.")

# %% [markdown]
# Without hourglass control, TLSPH's rings bounce but some particles of a ring collapse onto each other (the
# closest pair falls to a few thousandths of a spacing): a zero-energy mode grew where the impact shook the ring.
# With $\alpha = 1$ the lattice stays whole. ESPH (the warning says so) has no contact: the rings push each other
# off through the pressure but cling in tension, so they part slowly (a low restitution); without artificial
# pressure the rebound is weaker still, and over the whole run (`refsph run rings`, the map below) the rings tear.
#
# ## 4. The time stepper
#
# The paper's predictor-corrector is second order, but for an undamped oscillation of frequency $\omega$ its
# amplification is $\sqrt{1 + (\omega\,\Delta t)^4/4} > 1$: without artificial viscosity the particle-scale modes
# grow every step. The leapfrog (`integrator=leapfrog`, the second paper's scheme; `refsph.integrate`) is
# symplectic: the energy oscillates by $(\omega\,\Delta t)^2/8$ and does not drift. The undamped elastic bar, 10
# periods at Courant 0.3:

# %%
fig, ax = plt.subplots(figsize=(7, 3.6))
period = 2 * 20e-3 / 5382.7
for integrator in ("predictor_corrector", "leapfrog"):
    try:
        m, wall, res = quick("bar", "tlsph", dict(beta1=0.0, beta2=0.0, integrator=integrator), t_end=10 * period)
        e = np.asarray(m["energy_history"])
        ax.plot(e[:, 0] / period, (e[:, 1] + e[:, 2]) / (e[0, 1] + e[0, 2]), label=integrator)
        print(f"{integrator:19s}: energy end / start {m['energy_final_over_initial']:.6f}  ({wall:.1f} s, "
              f"{res.summary['n_steps']} steps)")
    except SimulationError as err:
        print(f"{integrator:19s}: {err}")
ax.set(xlabel="t / period", ylabel="energy / initial", ylim=(0.99, 1.01))
ax.legend()
ch.show(fig, "10_integrators.png", caption="Total energy of the undamped elastic bar over 10 periods at Courant 0.3: "
                                           "the predictor-corrector's grows (where its run has not failed), the "
                                           "leapfrog's oscillates without drift.")

# %% [markdown]
# ## 5. The stability map
#
# `python benchmarks/stability_map.py` runs every hard case (the bar, the disc, the rings, a Taylor bar at twice
# the speed, the pressing block for ten times its end time) with each method at the paper's settings and one change
# at a time. The committed map ([`benchmarks/stability_map_report.md`](../benchmarks/stability_map_report.md)):

# %%
runs = json.loads((repository_root() / "benchmarks" / "stability_map.json").read_text())["runs"]
cases = ("bar", "spinning", "rings", "taylor2x", "pressing10x")
for method in ("esph", "tlsph"):
    variants = sorted({r["variant"] for r in runs.values() if r["method"] == method})
    print(f"\n{method.upper():24s}" + "".join(f"{c:>12s}" for c in cases))
    for v in variants:
        cells = [runs.get(f"{c}|{method}|{v}") for c in cases]
        print(f"{v:24s}" + "".join(f"{'-' if r is None else ('ok' if r['survived'] else 'FAILS'):>12s}" for r in cells))

# %% [markdown]
# A run whose settings the map shows failing warns when it starts (`refsph.stability`): the warning names the case
# that failed and the remedy.
#
# ## Where it fails
#
# * Every remedy is a numerical device with a free constant ($\gamma$, $\alpha$, $\beta$); none is derived from
#   the physics, and each damps or stiffens something real. Report results with and without.
# * The ESPH correction restores objectivity, not conservation: the momentum equation keeps its uncorrected,
#   conservative gradient.
# * TLSPH's contact is between bodies. A body folding onto itself (a chip curling back onto the workpiece) needs
#   self-contact, which `refsph` does not have.
#
# ## Your turn
#
# ### Exercise 1 — How small can the artificial viscosity be?
#
# Predict, then run the undamped bar of section 4 with the predictor-corrector and `beta1 = beta2 = 0.1`. Does it
# survive 10 periods? What happens to its energy?
#
# ### Exercise 2 — The hourglass coefficient
#
# Run the TLSPH rings of section 3 with `hourglass` = 0.1 and 10. Which closest pair distance and restitution do
# you get? What does a large $\alpha$ cost in time steps?
#
# ### Exercise 3 — Spin faster
#
# Run the corrected ESPH disc at a rim speed of 5 % of $c_L$. Its stress now exceeds 1e-3 of E × 1 %. Is that a
# failure of the method? Compare with the centrifugal stress the metrics report.
