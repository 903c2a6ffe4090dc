"""The public path for a scene of one's own: the README's script, a solver of one's own, a per-step hook, rigid
bodies that turn, an initial stress, the heating switch, clean summaries."""
import json
import re
import runpy
from pathlib import Path

import numpy as np
import pytest

from refsph.boundaries import RigidBody
from refsph.integrate import Solver
from refsph.scenes import Numerics, Setup, aisi4340_material, lattice
from refsph.simulate import build, make_solver, run, simulate
from refsph.state import concatenate_states, make_state

ROOT = Path(__file__).resolve().parent.parent
MAT = aisi4340_material()
DP = 0.1e-3


def test_readme_own_scene_is_the_example_and_runs(tmp_path, monkeypatch, capsys):
    """The README's "Your own scene" script is examples/own_scene.py, at most 40 lines, public API only; it runs
    and the roller ploughs a groove."""
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Your own scene", 1)[1]
    block = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    script = (ROOT / "examples" / "own_scene.py").read_text()
    assert block == script
    assert len(script.splitlines()) <= 40
    assert not re.search(r"\bimport _|\._[a-z]", script)            # no private names
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(ROOT / "examples" / "own_scene.py"), run_name="__main__")
    text = capsys.readouterr().out
    assert text.startswith("ok ")
    m = eval(text.split("steps:", 1)[1])                            # the metrics dict it printed
    assert 1 < m["groove_depth_um"] < 40 and m["max_plastic_strain"] > 0.1        # an untouched plate gives 0
    assert m["max_T_K"] == 298.0                                    # heating off
    assert (tmp_path / "runs" / "own-scene" / "summary.json").exists()


def test_readme_pfem_script_is_the_example_and_runs(tmp_path, monkeypatch, capsys):
    """The README's "The PFEM from a script" is examples/pfem_script.py, public API only; it steps the cut to its
    end, prints the tool force as it goes and the measures, and the heat ledger closes."""
    section = (ROOT / "README.md").read_text().split("### The PFEM from a script", 1)[1]
    block = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    script = (ROOT / "examples" / "pfem_script.py").read_text()
    assert block == script and len(script.splitlines()) <= 25
    assert not re.search(r"\bimport _|\._[a-z]", script)
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(ROOT / "examples" / "pfem_script.py"), run_name="__main__")
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("step  10") and "Fc = " in lines[0]
    m = re.search(r"(\d+) steps, (\d+) nodes: Fc ([\d.]+) N/mm, Fp/Fc ([\d.]+), T_RF (\d+) K", lines[-2])
    assert m and int(m.group(1)) >= 40 and 100 < float(m.group(3)) < 500 and 300 < int(m.group(5)) < 900
    ledger = eval(lines[-1].split(":", 1)[1])
    assert ledger["plastic_J"] > 0 and abs(ledger["residual_rel"]) < 1e-9


def _block(n_side=6, v=(0.0, 0.0)):
    return make_state(lattice([n_side * DP] * 2, DP), v, MAT.rho0, DP * DP)


def _ring(centre, r, n):
    phi = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.asarray(centre) + r * np.stack([np.cos(phi), np.sin(phi)], axis=1)


@pytest.mark.parametrize("method", ["esph", "tlsph"])
def test_turning_rigid_body_follows_its_closed_form(method):
    block = _block()
    c0 = np.array([3e-3, 1e-3])
    x0 = _ring(c0, 0.5e-3, 24)
    body = RigidBody("wheel", 1, velocity=(-20.0, 5.0), angular_velocity=4e4, centre=tuple(c0))
    wheel = make_state(x0, body.velocity_at(x0), MAT.rho0, DP * DP, body=np.ones(len(x0)))
    setup = Setup(state=concatenate_states(block, wheel), material=MAT, dp=DP, numerics=Numerics(), t_end=2e-6,
                  n_snapshots=1, rigid=(body,))
    res = simulate(setup, method, progress=False)
    s, n, t = res.state, block.n, res.state.t
    a = 4e4 * t
    R = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    c = c0 + np.array([-20.0, 5.0]) * t
    assert np.allclose(s.x[n:], c + (x0 - c0) @ R.T, rtol=0, atol=1e-15)
    assert np.allclose(s.v[n:], body.velocity_at(s.x[n:], c), rtol=1e-12)
    assert np.allclose(s.x[:n], block.x, rtol=0, atol=1e-9 * DP)   # far from the block: nothing touched it


def test_turning_rigid_body_3d_and_bad_input():
    b = RigidBody("w", 1, velocity=(0.0, 0.0, 1.0), angular_velocity=(0.0, 0.0, 2.0), centre=(0.0, 0.0, 0.0))
    x = np.array([[1.0, 0.0, 0.0]])
    assert np.allclose(b.velocity_at(x), [[0.0, 2.0, 1.0]])
    assert np.allclose(b.rotation(np.pi / 4, 3) @ x[0], [0.0, 1.0, 0.0])
    with pytest.raises(ValueError, match="angular velocity"):
        RigidBody("w", 1, velocity=(0.0, 0.0), angular_velocity=(1.0, 2.0)).check(2)
    block = _block()
    x0 = _ring((3e-3, 1e-3), 0.5e-3, 12)
    wheel = make_state(x0, [0.0, 0.0], MAT.rho0, DP * DP, body=np.ones(len(x0)))   # not turning: refused
    setup = Setup(state=concatenate_states(block, wheel), material=MAT, dp=DP, numerics=Numerics(), t_end=1e-7,
                  n_snapshots=1, rigid=(RigidBody("wheel", 1, (0.0, 0.0), angular_velocity=1e3),))
    with pytest.raises(ValueError, match="velocity_at"):
        simulate(setup, "esph", progress=False)


def test_initial_stress_what_each_method_reads():
    """ESPH reads S and rho (the pressure); TLSPH reads S and refuses a rho it would ignore."""
    S = np.array([[1e8, 0.0], [0.0, -1e8]])
    rho = MAT.rho0 * (1 + 1e8 / MAT.K)                            # p = 100 MPa
    ok = make_state(lattice([8 * DP] * 2, DP), [0.0, 0.0], MAT.rho0, DP * DP, S=S)
    pre = make_state(lattice([8 * DP] * 2, DP), [0.0, 0.0], MAT.rho0, DP * DP, S=S, rho=rho)
    assert np.allclose(pre.rho, rho) and np.allclose(pre.m, MAT.rho0 * DP * DP)
    for method, state in (("esph", pre), ("tlsph", ok)):
        setup = Setup(state=state, material=MAT, dp=DP, numerics=Numerics(), t_end=1e-8, n_snapshots=1)
        solver = make_solver(method, setup)
        solver.check_state(state)
        a = solver.rates(state, 1e-9).v
        left = state.x[:, 0] < DP                                  # the left free face
        assert np.abs(a[left, 0]).min() > 0                        # the stress is felt at the free surface
    setup = Setup(state=pre, material=MAT, dp=DP, numerics=Numerics(), t_end=1e-8, n_snapshots=1)
    with pytest.raises(ValueError, match="does not read State.rho"):
        simulate(setup, "tlsph", progress=False)
    with pytest.raises(ValueError, match="traceless"):
        make_state(lattice([2 * DP] * 2, DP), [0.0, 0.0], MAT.rho0, DP * DP, S=np.eye(2) * 1e8)


@pytest.mark.parametrize("integrator", ["predictor_corrector", "leapfrog"])
def test_own_solver_and_hook(integrator):
    """A solver of one's own (gravity on top of TLSPH) and a hook that counts steps, with every stepper: the free
    block falls with momentum m g t; the summary, snapshots and NaN handling stay those of simulate. What passes
    isinstance(..., Solver) runs: the protocol declares the ``part`` the steppers pass."""

    class WithGravity:
        def __init__(self, inner, g):
            self.inner, self.g = inner, np.asarray(g)

        def rates(self, state, dt, part="all"):
            r = self.inner.rates(state, dt, part=part)
            if part != "deformation":                              # the leapfrog's stress half has no forces
                r.v = r.v + self.g
            return r

        def __getattr__(self, name):                               # everything else: the wrapped solver's
            return getattr(self.inner, name)

    block = _block(v=(0.0, 0.0))
    setup = Setup(state=block, material=MAT, dp=DP, numerics=Numerics(integrator=integrator), t_end=1e-6,
                  n_snapshots=2)
    solver = WithGravity(make_solver("tlsph", setup), (0.0, -1e6))
    assert isinstance(solver, Solver)
    calls = []
    res = simulate(setup, solver=solver, hook=lambda s, sv: calls.append(s.t), progress=False)
    P = np.sum(res.state.m[:, None] * res.state.v, axis=0)
    assert P[1] == pytest.approx(-1e6 * res.state.t * res.state.m.sum(), rel=1e-9)
    assert len(calls) == res.summary["n_steps"] and res.summary["method"] == "tlsph"


def test_build_is_what_run_simulates(tmp_path):
    """build: a registered scene's setup with run's numerics and options applied and checked, not run; simulated
    with its scene and metrics (and a hook of one's own) it gives run's numbers, bit for bit. Unknown numerics and
    options are refused as run refuses them."""
    kw = dict(quick=True, t_end=2e-6, numerics=dict(courant=0.2), options=dict(symmetry=False))
    b = build("taylor", "tlsph", **kw)
    assert b.setup.numerics.courant == 0.2 and b.setup.t_end == 2e-6 and b.scene.name == "taylor"
    steps = []
    mine = simulate(b.setup, "tlsph", scene=b.scene, metrics=b.metrics, hook=lambda s, sv: steps.append(s.t),
                    out=tmp_path / "mine", progress=False)
    ref = run("taylor", "tlsph", out=tmp_path / "run", progress=False, **kw)
    assert np.array_equal(mine.state.x, ref.state.x)
    assert (json.loads((tmp_path / "mine" / "summary.json").read_text())["metrics"]
            == json.loads((tmp_path / "run" / "summary.json").read_text())["metrics"])
    assert len(steps) == ref.summary["n_steps"] > 0
    with pytest.raises(ValueError, match="unknown numerical parameter"):
        build("taylor", "tlsph", quick=True, numerics=dict(courrant=0.2))
    with pytest.raises((ValueError, TypeError), match="symetry"):
        build("taylor", "tlsph", quick=True, options=dict(symetry=False))


def test_a_wrapper_without_part_is_refused_before_the_first_step():
    """A wrapper whose rates take (state, dt) only passes isinstance (a Protocol does not read signatures), so
    simulate reads the signature and refuses it with a message naming part= (not a TypeError deep in a step)."""

    class Old:
        def __init__(self, inner):
            self.inner = inner

        def rates(self, state, dt):
            return self.inner.rates(state, dt)

        def __getattr__(self, name):
            return getattr(self.inner, name)

    setup = Setup(state=_block(v=(0.0, 0.0)), material=MAT, dp=DP, numerics=Numerics(), t_end=1e-7, n_snapshots=1)
    with pytest.raises(TypeError, match="part"):
        simulate(setup, solver=Old(make_solver("tlsph", setup)), progress=False)


def test_a_method_that_advances_itself_runs_in_the_same_loop(tmp_path):
    """An implicit method (SelfAdvancing: it gives advance(state, dt), not rates): backward Euler for particles
    under linear drag dv/dt = -c v, v_{n+1} = v_n / (1 + c dt), x_{n+1} = x_n + dt v_{n+1}. The run loop steps it
    with its own stepper, writes the summary and snapshots, and a restart continues it bit for bit."""
    from dataclasses import replace

    from refsph.integrate import SelfAdvancing

    class ImplicitDrag:
        method, threads = "implicit_drag", 1

        def __init__(self, c, h):
            self.c, self.h, self.n_solves = c, h, 0

        def check_state(self, state):
            return None

        def advance(self, state, dt):
            self.n_solves += 1
            v = state.v / (1.0 + self.c * dt)
            return replace(state, x=state.x + dt * v, v=v, t=state.t + dt)

        def checkpoint(self):
            return dict(n_solves=np.int64(self.n_solves))

        def restore(self, arrays, state):
            self.n_solves = int(arrays["n_solves"])

        def deformation_gradient(self, state):
            return None

        def reaction_history(self):
            return {}

        def diagnostics(self):
            return dict(solves=self.n_solves)

    c, dt = 2e5, 1e-7
    setup = Setup(state=_block(v=(10.0, 0.0)), material=MAT, dp=DP, numerics=Numerics(), t_end=20 * dt,
                  n_snapshots=2)
    method = ImplicitDrag(c, setup.h)
    assert isinstance(method, SelfAdvancing)
    res = simulate(setup, solver=method, dt=dt, progress=False, out=tmp_path / "a")
    assert res.summary["n_steps"] == 20 and res.summary["diagnostics"]["solves"] == 20
    assert res.state.v[0, 0] == pytest.approx(10.0 / (1 + c * dt) ** 20, rel=1e-12)

    def stop(state, solver):                                       # the run is killed after step 15
        if state.t > 15.5 * dt:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        simulate(setup, solver=ImplicitDrag(c, setup.h), dt=dt, progress=False, out=tmp_path / "b", hook=stop)
    again = simulate(setup, solver=ImplicitDrag(c, setup.h), dt=dt, progress=False, out=tmp_path / "b",
                     restart=True)
    assert np.array_equal(again.state.x, res.state.x) and again.summary["restarts"] == 1
    assert again.summary["diagnostics"]["solves"] == 20


def test_info_stays_clean_and_cache_hits(tmp_path):
    with pytest.raises(ValueError, match="Setup.arrays"):
        Setup(state=_block(), material=MAT, dp=DP, numerics=Numerics(), t_end=1e-7, n_snapshots=1,
              info=dict(rows=np.arange(3)))
    res = run("pressing", "tlsph", quick=True, t_end=0.05e-6, progress=False, out=tmp_path)
    cache = res.summary["diagnostics"]["momentum_sum_cache"]
    assert cache["misses"] == 1 + res.summary["diagnostics"]["reference_updates"]
    assert cache["hits"] == 2 * res.summary["n_steps"] - cache["misses"]
    import json
    info = json.loads((tmp_path / "summary.json").read_text())["scene_info"]
    assert all(not isinstance(v, list) or len(v) < 10 for v in info.values())


def test_make_state_refuses_bad_stress_and_density():
    x = lattice([2 * DP] * 2, DP)
    with pytest.raises(ValueError, match="symmetric"):
        make_state(x, [0.0, 0.0], MAT.rho0, DP * DP, S=np.array([[0.0, 1e8], [-3e8, 0.0]]))
    with pytest.raises(ValueError, match="rho"):
        make_state(x, [0.0, 0.0], MAT.rho0, DP * DP, rho=np.nan)
    st = make_state(x, [0.0, 0.0], MAT.rho0, DP * DP)
    st.v[0, 0] = np.inf
    with pytest.raises(ValueError, match="finite"):
        st.check()


def test_tlsph_deformed_start_with_its_density_is_accepted():
    """A TLSPH state that starts deformed (x != X) with rho = m / (J V0) runs; the same with rho0 is refused."""
    X = lattice([8 * DP] * 2, DP)
    x = X @ np.array([[1.01, 0.0], [0.0, 0.99]]).T
    st = make_state(x, [0.0, 0.0], MAT.rho0, DP * DP, X=X)
    setup = Setup(state=st, material=MAT, dp=DP, numerics=Numerics(), t_end=1e-8, n_snapshots=1)
    solver = make_solver("tlsph", setup)
    with pytest.raises(ValueError, match="does not read State.rho"):
        solver.check_state(st)
    J = np.linalg.det(solver.deformation_gradient(st))
    st.rho = st.m / (J * st.V0)
    assert simulate(setup, "tlsph", progress=False).summary["status"] == "ok"


def test_a_law_without_plastic_fields_is_still_called():
    """A strength model with state_fields = () (e.g. a cap on the deviatoric stress) runs its return map on an
    elastic state: nothing special-cases it as elastic."""
    class Cap:
        state_fields = ()
        calls = 0

        def return_map(self, S, S_zz, eps_p, eps_dot, T, G):
            Cap.calls += 1
            return 0.5 * S, 0.5 * S_zz, np.zeros(len(S)), np.zeros(len(S))

        def heat(self, d_w_p, rho):
            return np.zeros_like(d_w_p)

    st = _block(v=(1.0, 0.0))
    st.S[:, 0, 1] = st.S[:, 1, 0] = 1e6
    setup = Setup(state=st, material=MAT, dp=DP, numerics=Numerics(), t_end=1e-8, n_snapshots=1, strength=Cap())
    res = simulate(setup, "esph", progress=False)
    assert Cap.calls == 2 * res.summary["n_steps"] and np.abs(res.state.S[:, 0, 1]).max() < 0.6e6


def test_method_and_solver_must_agree():
    setup = Setup(state=_block(), material=MAT, dp=DP, numerics=Numerics(), t_end=1e-8, n_snapshots=1)
    with pytest.raises(ValueError, match="does not match"):
        simulate(setup, "esph", solver=make_solver("tlsph", setup), progress=False)
