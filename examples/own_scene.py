"""A scene refsph does not ship, from the public API: a rigid roller rolls (turns and translates) across an AISI 4340
plate and ploughs a groove into it. TLSPH, Johnson-Cook (Table 3), Coulomb friction, no heating."""
import numpy as np

from refsph.boundaries import Clamp, RigidBody
from refsph.contact import CoulombFriction
from refsph.scenes import Numerics, Setup, aisi4340_johnson_cook, aisi4340_material, lattice
from refsph.simulate import simulate
from refsph.state import concatenate_states, make_state

dp, R, V = 25e-6, 0.2e-3, 50.0                       # spacing, roller radius [m], rolling speed [m/s]
mat, jc = aisi4340_material(), aisi4340_johnson_cook(eps_dot_0=1.0, heating=False)
plate = make_state(lattice([1.5e-3, 0.3e-3], dp), [0.0, 0.0], mat.rho0, dp * dp, T0=jc.T_room)
centre = np.array([0.3e-3, 0.3e-3 + R + 0.5 * dp])    # the roller starts half a spacing above the plate
phi = np.linspace(0.0, 2 * np.pi, round(2 * np.pi * R / dp), endpoint=False)
ring = centre + (R - 0.5 * dp) * np.stack([np.cos(phi), np.sin(phi)], axis=1)
roller = RigidBody("roller", 1, velocity=(V, -0.05 * V), angular_velocity=-V / R, centre=tuple(centre))
tool = make_state(ring, roller.velocity_at(ring), mat.rho0, dp * dp, T0=jc.T_room, body=np.ones(len(ring)))
setup = Setup(state=concatenate_states(plate, tool), material=mat, dp=dp, t_end=16e-6, n_snapshots=4,
              numerics=Numerics(beta1=0.5, beta2=0.5), strength=jc, rigid=(roller,),
              clamps=(Clamp("base", np.flatnonzero(plate.x[:, 1] < dp)),),
              friction=CoulombFriction(mu0=0.3, q=1.0, T_room=jc.T_room, T_melt=jc.T_melt))
n = plate.n


def record(state, setup):                             # called every few steps: scalars into the history
    return dict(t=state.t, surface_mm=1e3 * state.x[:n, 1].max(), eps_p=float(state.eps_p[:n].max()))


def metrics(history, state, setup):                   # once at the end: summary.json's "metrics"
    F = history["reaction"]["roller"]                 # force of the plate on the roller [N/m], every step
    top = np.abs(state.x[:n, 0] - 0.8e-3) < dp           # the column at x = 0.8 mm; its top started at 0.3 mm - dp/2
    groove = 0.3e-3 - 0.5 * dp - state.x[:n][top, 1].max()
    return dict(groove_depth_um=float(1e6 * groove), max_plastic_strain=max(history["eps_p"]),
                mean_force_N_per_m=np.mean(F, axis=0).tolist(), max_T_K=float(state.T[:n].max()))


res = simulate(setup, "tlsph", record=record, metrics=metrics, out="runs/own-scene", progress=False)
print(res.summary["status"], res.summary["n_steps"], "steps:", res.summary["metrics"])
