"""The golden cases as a format any language can read (golden/FORMAT.md, version 2, issue 23): plain uncompressed
npz of float64/int64 arrays in C order, case.json describing every array and every convention as data, the
per-term cases; and the proof: an independent C checker (checkers/c/) with its own zip/NPY reader that computes
the cubic kernel and the ESPH cases from the spec alone and matches them to round-off, and `refsph compare` naming
a bug planted in it down to the term (the case) and the particle or pair; and plain Python loops written from
FORMAT.md's sections alone that reproduce the penalty, conduction and surface cases."""
import json
import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

from refsph.crosscheck.compare import compare, format_table
from refsph.crosscheck.golden import COMMON_CONVENTIONS, ESPH_RATE_CASES, FORMAT_VERSION, case_names

ROOT = Path(__file__).resolve().parent.parent
GOLDEN = ROOT / "golden"
KINDS = ("kernel", "esph_rates", "esph_pair_terms", "tlsph_rates", "return_map", "pinball", "pinball_pairs",
         "pinball_friction", "penalty", "conduction", "surface", "step", "run", "metrics")
C_CASES = ["kernel_cubic_2d", "kernel_cubic_3d", *ESPH_RATE_CASES, "esph_pair_terms"]


def _npy_headers(path: Path) -> dict:
    """{array: (NPY version, header dict)} of an npz file, read the way a C reader does; every entry stored."""
    out = {}
    with zipfile.ZipFile(path) as z:
        for info in z.infolist():
            assert info.compress_type == zipfile.ZIP_STORED, (path, info.filename)
            assert info.filename.endswith(".npy") and info.flag_bits & 8 == 0, (path, info.filename)
            with z.open(info) as f:
                version = np.lib.format.read_magic(f)
                header = np.lib.format.read_array_header_1_0(f) if version == (1, 0) else None
            out[info.filename[:-4]] = (version, header)
    return out


def test_every_golden_file_is_plain_and_described():
    """Every array of every case: NPY 1.0, '<f8' or '<i8', C order, uncompressed; case.json lists exactly these
    arrays with shape, dtype, descr, unit, meaning and (but for numbers) what their rows are; every case says its
    format version, kind, conventions (the common ones among them) and a tolerance per output."""
    index = json.loads((GOLDEN / "index.json").read_text())
    assert index["format_version"] == FORMAT_VERSION == 2 and index["cases"] == case_names()
    for name in index["cases"]:
        case = json.loads((GOLDEN / name / "case.json").read_text())
        assert case["format_version"] == 2 and case["name"] == name and case["kind"] in KINDS, name
        assert set(COMMON_CONVENTIONS) <= set(case["conventions"]), name
        listed = set()
        for side in ("input", "output"):
            for k, (version, (shape, fortran, dtype)) in _npy_headers(GOLDEN / name / f"{side}.npz").items():
                entry = case["arrays"][f"{side}/{k}"]
                listed.add(f"{side}/{k}")
                assert version == (1, 0) and not fortran and dtype.str in ("<f8", "<i8"), (name, side, k)
                assert entry["shape"] == list(shape) and entry["descr"] == dtype.str, (name, side, k)
                assert entry["dtype"] == dtype.name and entry["unit"] and entry["meaning"], (name, side, k)
                assert ("rows" in entry) == (len(shape) > 0), (name, side, k)
                if side == "output":
                    assert k in case["tolerance"], (name, k)
        assert listed == set(case["arrays"]), name


def test_format_md_is_the_spec():
    """golden/FORMAT.md exists in the repository, is this version, and documents every kind and every change."""
    text = (GOLDEN / "FORMAT.md").read_text()
    assert f"version {FORMAT_VERSION}" in text and "## Versions" in text
    for kind in KINDS:
        assert kind in text, kind
    for rule in ("c0 = √(E/ρ0)", "I[k] < J[k]", "unless p_i > 0 and p_j > 0", "ω S − S ω", "uncompressed", "'<f8'",
                 "C order", "0-d array"):
        assert rule in text, rule


def test_esph_cases_carry_their_numbers_and_conventions():
    """A reader needs no JSON for numbers (they are 0-d inputs, equal to case.json's params and material), and every
    ESPH convention that a backend could get wrong is stated as data."""
    for name in ("esph_rates", "esph_pair_terms", *ESPH_RATE_CASES):
        case = json.loads((GOLDEN / name / "case.json").read_text())
        with np.load(GOLDEN / name / "input.npz") as z:
            numbers = {k for k, v in case["params"].items() if not isinstance(v, str)}
            assert numbers - set(z.files) <= {"W_dp", "dim"}, (name, numbers - set(z.files))   # derived / the shape
            for k in numbers & set(z.files):
                assert float(z[k]) == case["params"][k], (name, k)
            for k in ("rho0", "E", "nu"):
                assert float(z[k]) == case["material"][k]
            I, J = z["I"], z["J"]
        assert np.all(I < J) and len(np.unique(I * 10**6 + J)) == len(I)
        c = case["conventions"]
        assert "c0 = sqrt(E / rho0)" in c["viscosity_sound_speed"] and "v_ij . x_ij > 0" in c["viscosity"]
        assert "except p^a_ij = 0 where p_i > 0 and p_j > 0" in c["artificial_pressure"]
        assert "omega S - S omega" in c["jaumann"] and "I[k] < J[k]" in c["pairs"]


def _golden(name: str, which: str) -> dict:
    """A golden case's input or output arrays."""
    with np.load(GOLDEN / name / f"{which}.npz") as z:
        return {k: z[k] for k in z.files}


def _pair_sum(f: np.ndarray, I, J, m, n: int) -> np.ndarray:
    """Eq. (11)'s sum over the half pairs of a per-pair force f (P, 2): +m_j f on I, -m_i f on J."""
    a = np.zeros((n, f.shape[1]))
    np.add.at(a, I, m[J, None] * f)
    np.add.at(a, J, -m[I, None] * f)
    return a


def test_switched_off_terms_change_only_the_acceleration():
    """The rate cases with viscosity / artificial pressure off share esph_rates' state and differ from it in v_dot
    alone, and by that term: what fails in which case names the term."""
    full = _golden("esph_rates", "output")
    for name in ESPH_RATE_CASES:
        other = _golden(name, "output")
        for k in ("rho_dot", "S_dot", "S_zz_dot", "l"):
            np.testing.assert_array_equal(other[k], full[k])
        assert (name == "esph_rates") == np.array_equal(other["v_dot"], full["v_dot"])
    # ... by that term: the pair case's pi and p^a summed as Eq. (11) sums them
    inp, terms = _golden("esph_pair_terms", "input"), _golden("esph_pair_terms", "output")
    n = len(full["v_dot"])

    def acceleration(per_pair):
        return _pair_sum(-per_pair[:, None] * terms["grad_W"], inp["I"], inp["J"], inp["m"], n)
    for name, term in (("esph_rates_no_viscosity", terms["pi"]), ("esph_rates_no_artificial_pressure", terms["p_a"]),
                       ("esph_rates_stress_only", terms["pi"] + terms["p_a"])):
        assert name in ESPH_RATE_CASES
        off = full["v_dot"] - _golden(name, "output")["v_dot"]
        assert np.max(np.abs(off - acceleration(term))) <= 1e-12 * np.max(np.abs(full["v_dot"])), name
        assert np.max(np.abs(off)) > 1e-6 * np.max(np.abs(full["v_dot"])), name          # the term is not nil


def test_pair_terms_add_up_to_the_rates():
    """The per-pair terms of esph_pair_terms, summed over the half pairs as FORMAT.md says (Eq. (11)), give
    esph_rates' acceleration: the pair case and the rate case tell one story."""
    inp, terms = _golden("esph_pair_terms", "input"), _golden("esph_pair_terms", "output")
    v_dot = _golden("esph_rates", "output")["v_dot"]
    I, J, m, rho, p, g = inp["I"], inp["J"], inp["m"], inp["rho"], terms["p"], terms["grad_W"]
    s = (inp["S"] - p[:, None, None] * np.eye(2)) / (rho**2)[:, None, None]
    bracket = s[I] + s[J] - (terms["pi"] + terms["p_a"])[:, None, None] * np.eye(2)
    a = _pair_sum(np.einsum("pab,pb->pa", bracket, g), I, J, m, len(v_dot))
    assert np.max(np.abs(a - v_dot)) <= 1e-12 * np.max(np.abs(v_dot))


def _compiler():
    return shutil.which("cc") or shutil.which("gcc")


@pytest.fixture(scope="module")
def checker(tmp_path_factory):
    """The C checker, compiled from checkers/c/ (C99; it builds without a warning under -Wall -Wextra -pedantic)."""
    cc = _compiler()
    if cc is None:
        pytest.skip("no C compiler (cc or gcc) on the PATH: the C checker of the golden format is not compiled")
    exe = tmp_path_factory.mktemp("c") / "golden_check"
    src = ROOT / "checkers" / "c"
    subprocess.run([cc, "-std=c99", "-O2", "-Wall", "-o", str(exe),
                    str(src / "golden_check.c"), str(src / "npz.c"), "-lm"], check=True, capture_output=True)
    return exe


def _run_checker(exe, out: Path, *plant) -> None:
    subprocess.run([str(exe), *plant, str(GOLDEN), str(out), *C_CASES], check=True, capture_output=True, text=True)


def test_c_checker_matches_to_round_off(checker, tmp_path):
    """The C program, from FORMAT.md and the paper alone, reproduces the cubic kernel (2D, 3D), the ESPH rates
    (all terms, each term off) and the ESPH pair terms to round-off: a few 1e-16 of the largest value (the cases'
    tolerances are 1e-12 and 1e-10)."""
    _run_checker(checker, tmp_path)
    rows = compare(GOLDEN, tmp_path, only=C_CASES)
    assert len(rows) == 6 + 5 * len(ESPH_RATE_CASES) + 7
    assert all(r.passed for r in rows), format_table(rows)
    assert max(r.error for r in rows) < 1e-14, format_table(rows)
    with np.load(tmp_path / "esph_rates" / "output.npz") as z:        # what C wrote reads as plain arrays
        assert z["v_dot"].dtype == np.float64 and z["S_dot"].shape == (120, 2, 2)


def _separating(case="esph_pair_terms"):
    with np.load(GOLDEN / case / "input.npz") as z:
        x, v, I, J = z["x"], z["v"], z["I"], z["J"]
    return np.einsum("pk,pk->p", v[I] - v[J], x[I] - x[J]) > 0, I, J


def test_planted_viscosity_bug_is_named(checker, tmp_path):
    """Viscosity also on separating pairs (against Eq. (12)): compare fails exactly the cases that have the
    viscosity and only their accelerations (not the no-viscosity case), names pi_ij as the term and the worst pair,
    a separating one with its particles, and the worst particle of v_dot with both values."""
    _run_checker(checker, tmp_path, "--plant", "separating-viscosity")
    rows = compare(GOLDEN, tmp_path, only=C_CASES)
    failed = {r.quantity: r for r in rows if not r.passed}
    assert set(failed) == {"esph_rates/v_dot", "esph_rates_no_artificial_pressure/v_dot", "esph_pair_terms/pi"}
    separating, I, J = _separating()
    pi = failed["esph_pair_terms/pi"]
    k = int(pi.where.split()[1])
    assert separating[k] and pi.where == f"pair {k} (I {I[k]}, J {J[k]})" and pi.ref_value == 0 != pi.test_value
    with np.load(GOLDEN / "esph_rates" / "output.npz") as a, np.load(tmp_path / "esph_rates" / "output.npz") as b:
        worst = np.unravel_index(np.argmax(np.abs(a["v_dot"] - b["v_dot"])), a["v_dot"].shape)
        ref, test = a["v_dot"][worst], b["v_dot"][worst]
    row = failed["esph_rates/v_dot"]
    assert row.where == f"particle {worst[0]} component [{worst[1]}]"
    assert (row.ref_value, row.test_value) == (ref, test)
    table = format_table(rows)
    assert f"worst at pair {k} (I {I[k]}, J {J[k]}): REF 0, TEST " in table
    assert f"worst at particle {worst[0]} component [{worst[1]}]: REF {ref:.10g}, TEST {test:.10g}" in table


def test_planted_support_bug_is_named(checker, tmp_path):
    """The kernel cut off at h instead of 2h (against Eq. (9)): the kernel cases fail at a distance between h and 2h,
    and of the pair terms exactly the kernel's (W, dW/dr, grad W) and the artificial pressure, which uses W; pi_ij
    and r pass, so the term is the kernel."""
    _run_checker(checker, tmp_path, "--plant", "support-h")
    rows = compare(GOLDEN, tmp_path, only=C_CASES)
    failed = {r.quantity: r for r in rows if not r.passed}
    assert {q for q in failed if q.startswith("esph_pair_terms/")} == {
        "esph_pair_terms/W", "esph_pair_terms/dW_dr", "esph_pair_terms/grad_W", "esph_pair_terms/p_a"}
    assert all(f"kernel_cubic_{d}d/{k}" in failed for d in (2, 3) for k in ("W", "dW_dr", "grad_W"))
    pairs = GOLDEN / "esph_pair_terms"
    with np.load(pairs / "output.npz") as z, np.load(pairs / "input.npz") as i:
        r, h = z["r"], float(i["h"])
    k = int(failed["esph_pair_terms/W"].where.split()[1])
    assert h < r[k] < 2 * h and failed["esph_pair_terms/W"].test_value == 0
    with np.load(GOLDEN / "kernel_cubic_2d" / "input.npz") as z:
        r, h = z["r"], float(z["h"])
    k = int(failed["kernel_cubic_2d/W"].where.split()[1])
    assert failed["kernel_cubic_2d/W"].where == f"sample {k}" and h * (1 - 1e-12) <= r[k] <= 2 * h


def _wendland_dw_dr(r: float, h: float) -> float:
    """dW/dr of the 2D Wendland C2 kernel, W = 7/(4 pi h^2) (1 - q/2)^4 (2q + 1), q = r/h (its case.json 'kernel')."""
    q = r / h
    if q >= 2.0:
        return 0.0
    return 7.0 / (4.0 * np.pi * h * h) * (-5.0 * q * (1.0 - 0.5 * q) ** 3) / h


def test_penalty_case_follows_format_md_alone():
    """penalty_friction recomputed particle by particle from FORMAT.md's 'penalty' section alone (gap to the rounded
    polygon, spring-damper normal force, return-mapped friction, power, reaction), not from refsph/penalty.py."""
    i, o = _golden("penalty_friction", "input"), _golden("penalty_friction", "output")
    P = i["core"] + i["shift"]
    tau, alpha, dt = float(i["time_scale"]), float(i["alpha"]), float(i["dt"])
    beta = 2.0 * float(i["damping"]) * np.sqrt(alpha)
    total, in_contact, slipping = np.zeros(2), 0, 0
    for p in range(len(i["x"])):
        x, m = i["x"][p], float(i["m"][p])
        best, inside, lines = None, True, []
        for k in range(len(P)):
            a, b = P[k], P[(k + 1) % len(P)]
            e = b - a
            nrm = np.array([e[1], -e[0]]) / np.hypot(*e)
            s = min(max(np.dot(x - a, e) / np.dot(e, e), 0.0), 1.0)
            q = a + s * e
            if best is None or np.hypot(*(x - q)) < best[0]:
                best = (np.hypot(*(x - q)), q)
            side = np.dot(x - a, nrm)
            inside &= side <= 0.0
            lines.append((side, nrm))
        if inside:
            side, n = max(lines, key=lambda t: t[0])
            d = side - float(i["radius"])
        else:
            d, n = best[0] - float(i["radius"]), (x - best[1]) / best[0]
        g = float(i["offset"]) - d
        assert o["gap"][p] == pytest.approx(g, abs=1e-18)
        f_t, xi, power, fN = np.zeros(2), np.zeros(2), 0.0, 0.0
        if g > 0:
            in_contact += 1
            k_s = alpha * m / tau**2
            vr = i["v"][p] - i["V"]
            vn = np.dot(vr, n)
            fN = max(k_s * g - beta * m * vn / tau, 0.0)
            xi_p = i["xi_in"][p] - np.dot(i["xi_in"][p], n) * n
            xi_star = xi_p + (vr - vn * n) * dt
            f_star = -k_s * xi_star
            Ts = min(max((i["T"][p] - i["T_room"]) / (i["T_melt"] - i["T_room"]), 0.0), 1.0)
            limit = float(i["mu0"]) * (1.0 - Ts ** float(i["q"])) * fN
            if np.hypot(*f_star) <= limit:
                f_t, xi = f_star, xi_star
            else:
                slipping += 1
                f_t = limit * f_star / np.hypot(*f_star)
                xi = -f_t / k_s
            power = np.hypot(*f_t) * max(np.hypot(*xi_star) - np.hypot(*xi), 0.0) / dt
        f = fN * n + f_t if g > 0 else np.zeros(2)
        total -= f
        scale = max(abs(fN), 1e-30)
        assert o["f_normal"][p] == pytest.approx(fN, rel=1e-12, abs=1e-12 * scale)
        np.testing.assert_allclose(o["f_tangent"][p], f_t, rtol=1e-12, atol=1e-12 * scale)
        np.testing.assert_allclose(o["xi"][p], xi, rtol=1e-12, atol=1e-22)
        np.testing.assert_allclose(o["a"][p], f / m, rtol=1e-12, atol=1e-12 * scale / m)
        assert o["friction_power"][p] == pytest.approx(power, rel=1e-12, abs=1e-12 * scale)
    np.testing.assert_allclose(o["force_on_tool"], total, rtol=1e-12)
    assert in_contact >= 5 and 0 < slipping < in_contact                 # the case exercises stick and slip


def test_conduction_case_follows_format_md_alone():
    """conduction recomputed pair by pair from FORMAT.md (Brookshaw's Laplacian with the Wendland C2 kernel)."""
    i, o = _golden("conduction", "input"), _golden("conduction", "output")
    h, lap = float(i["h"]), np.zeros(len(i["x"]))
    for a, b in zip(i["I"], i["J"]):
        r = np.hypot(*(i["x"][a] - i["x"][b]))
        w = 2.0 * _wendland_dw_dr(r, h) / r
        lap[a] += w * (i["T"][a] - i["T"][b]) * i["V"][b]
        lap[b] += w * (i["T"][b] - i["T"][a]) * i["V"][a]
    np.testing.assert_allclose(o["lap_T"], lap, rtol=1e-10, atol=1e-10 * np.abs(lap).max())
    np.testing.assert_allclose(o["T_dot"], i["a"] * lap + i["source"], rtol=1e-10,
                               atol=1e-10 * np.abs(o["T_dot"]).max())


def test_surface_case_follows_format_md_alone():
    """surface_notch recomputed from FORMAT.md: the moment matrix's smaller eigenvalue by a double loop and the
    alpha-shape from scipy's Delaunay with circumradii from the triangles' sides (R = abc / (4 area))."""
    from scipy.spatial import Delaunay
    i, o = _golden("surface_notch", "input"), _golden("surface_notch", "output")
    x, V, h, n = i["x"], i["V"], float(i["h"]), len(i["x"])
    lam = np.zeros(n)
    for a in range(n):
        M = np.zeros((2, 2))
        for b in range(n):
            r = np.hypot(*(x[a] - x[b]))
            if b != a and r < 2 * h:
                xab = x[a] - x[b]
                M -= V[b] * np.outer(xab, _wendland_dw_dr(r, h) / r * xab)
        lam[a] = np.linalg.eigvalsh(0.5 * (M + M.T))[0]
    np.testing.assert_allclose(o["lambda_min"], lam, rtol=1e-10, atol=1e-12)
    np.testing.assert_array_equal(o["surface_sph"], (lam <= float(i["threshold"])).astype(np.int64))
    edges: dict = {}
    for t in Delaunay(x).simplices:
        A, B, C = x[t]
        sides = [np.hypot(*(B - C)), np.hypot(*(A - C)), np.hypot(*(A - B))]
        area = 0.5 * abs((B - A)[0] * (C - A)[1] - (B - A)[1] * (C - A)[0])
        if area == 0 or np.prod(sides) / (4 * area) > float(i["alpha"]) * float(i["dp"]):
            continue
        for e in ((t[0], t[1]), (t[1], t[2]), (t[0], t[2])):
            edges[tuple(sorted(e))] = edges.get(tuple(sorted(e)), 0) + 1
    mask = np.zeros(n, dtype=np.int64)
    for e, c in edges.items():
        if c == 1:
            mask[list(e)] = 1
    np.testing.assert_array_equal(o["surface_alpha"], mask)
    assert 0 < mask.sum() < n and 0 < o["surface_sph"].sum() < n
