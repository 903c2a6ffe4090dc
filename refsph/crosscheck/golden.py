"""Golden cases: small, versioned inputs with refsph's outputs, for checking another backend (``refsph oracle DIR``).

Each case is a folder ``DIR/<case>/`` with

* ``input.npz``  -- everything a backend needs to compute the case: particles, masses, reference positions, pair
  lists, and every number (h, the kernel's dp, the numerics, the material constants) as a 0-d array, SI units;
* ``output.npz`` -- refsph's result;
* ``case.json``  -- what the case is (``kind``), the equations it exercises, every array (shape, dtype, unit, what
  its rows are, meaning), every convention as data (``conventions``), the parameters, material, or the whole
  scene set-up (tools and their motion, clamps, walls, symmetry planes, numerics), and ``tolerance``: {array:
  relative tolerance} with ``why`` (errors are measured as max |test - ref| / max |ref| per array unless
  ``measure`` names another error for an array, see :mod:`refsph.crosscheck.compare`);
* ``scatter.json`` -- only beside ``metrics_cutting_coarse_*``, and not written here: the measured run-to-run
  scatter of the metrics that depend chaotically on details and their tolerances (benchmarks/metric_scatter.py,
  :func:`scatter_document`, ``SCATTER_RULE``); writing a case again keeps it (:func:`_clear_case`).

The format (version 2) is written down for readers in any language in ``golden/FORMAT.md``: the npz files are
uncompressed zip archives of NPY 1.0 arrays of float64 or int64, little-endian, C order (:func:`plain_array`;
format 1 let NumPy store some arrays in Fortran order, which a reader that ignores ``fortran_order`` reads
transposed), 0-d arrays for numbers; no text, no booleans, no objects. ``checkers/c/`` reads the kernel and ESPH
cases with ~100 lines of its own zip/NPY reading and matches them to round-off (``tests/test_golden_format.py``).

``DIR/index.json`` lists the cases with the refsph version, the format version and the software that wrote them
(``generated_with``). The cases:

| case | what | equations |
|---|---|---|
| kernel_{cubic,wendland}_{2d,3d} | W, dW/dr and grad W at given r and x_ij | Eq. (9), Wendland C2 |
| esph_rates | ESPH rates of a perturbed 2D block with free surfaces, given half pairs | Eqs. (10)-(14), (20)-(24) |
| esph_rates_{no_viscosity,no_artificial_pressure,stress_only} | the same with pi_ij, p^a_ij or both off | the same |
| esph_pair_terms | per half pair: r, W, dW/dr, grad W, pi_ij, p^a_ij (and p per particle) | Eqs. (9), (12)-(14), (24) |
| tlsph_{affine,rotation,random}_{corrected,uncorrected} | F, J, P, l, rates of a 2D block | Eqs. (2), (16)-(24) |
| return_map_{johnson_cook,modified} | return map of trial stresses (elastic, yielding, fast, hot) | Eqs. (25)-(31) |
| pinball | contact forces against a rigid and a deformable partner | Eqs. (32)-(36) |
| pinball_pairs | the pinball per pair: p_d, its rate, F1, F2, F and the force vector | Eqs. (32)-(36) |
| step_{esph,tlsph}_{taylor,pressing} | one step of a scene: wall + symmetry (Taylor 2D), clamp + tool | all |
| run_{taylor,pressing,cutting}_{esph,tlsph} | a short quick-resolution run: final state, metrics | all |
| conduction | Brookshaw's Laplacian and the conduction rate on a perturbed 2D lattice | Eqs. (26), (29) |
| surface_notch | the two free-surface detectors on a 2D body with a V-notch | Marrone et al. 2010; alpha-shape |
| pinball_friction | contact with Coulomb friction mu(T): forces, friction power | Eqs. (32)-(36), mu(T) |
| step_{esph,tlsph}_taylor_leapfrog, run_taylor_{esph,tlsph}_leapfrog | the leapfrog: one step, ~40 steps | all |
| step_tlsph_thermal_cutting, run_thermal_cutting_tlsph | the thermomechanical cut: one step, a quick cut | all |
| metrics_{taylor_3d_1mm,pressing_quick,cutting_coarse}_{esph,tlsph} | whole runs: their metrics | all |

The ``metrics_*`` cases are the regression values of tests/test_taylor.py, test_pressing.py and test_cutting.py.

**Byte for byte, on any CPU.** Regenerating gives the same bytes (``tests/test_golden.py`` checks the committed copy
in ``golden/``) on any machine with the same software (``generated_with``: the machine architecture, NumPy, SciPy
and the C library). Not by itself: NumPy picks at run time, per CPU, among SIMD versions of its loops (AVX2,
AVX-512, ...; its "CPU dispatch"), and these round differently in the last bit (``10.0 ** x`` differs by one ulp
between the AVX-512 and the AVX2 loops; 40 steps of a run turn that into 1e-12 relative); OpenBLAS picks its
kernels per CPU (``np.linalg`` of the surface detector, of the cutting scene's measurement); glibc picks FMA
versions of exp, log, pow, sin, ... where the CPU has FMA, which round differently from its plain ones. So
:func:`write_golden_cases` always computes in a child process whose environment fixes all three to what every
CPU of the architecture has (:func:`pinned_environment`):

* ``NPY_DISABLE_CPU_FEATURES`` = every feature NumPy may dispatch to (``numpy._core._multiarray_umath.
  __cpu_dispatch__``: on NumPy 2.4 for x86-64 X86_V3 X86_V4 AVX512_ICL AVX512_SPR), leaving NumPy's baseline loops
  (X86_V2 there). NumPy accepts the features a CPU lacks in that list silently; it refuses only baseline ones;
* ``OPENBLAS_CORETYPE`` = Nehalem on x86-64 (ARMV8 on aarch64), one thread (``OPENBLAS_NUM_THREADS``,
  ``OMP_NUM_THREADS``; ``MKL_CBWR=COMPATIBLE`` for an MKL NumPy);
* ``GLIBC_TUNABLES`` glibc.cpu.hwcaps=-AVX2,-FMA,-FMA4,-AVX512F (the glibc manual's tunables): glibc's plain
  libm functions.

The child checks that NumPy dispatches to nothing beyond its baseline before it writes a byte. The numbers of the
committed cases hence come from these plain loops; a run with the machine's fast loops differs in the last digits
(within every tolerance). ``python -m refsph.crosscheck.golden DIR`` and ``refsph oracle DIR`` both go this way.

The ``metrics_*`` cases run whole scenes (minutes): ``--only`` writes some cases and keeps the others (``refsph
oracle golden/ --only 'metrics_pressing*'``); the default test run regenerates every other case
(``tests/test_golden.py``), and the scene tests compare their own runs with the ``metrics_*`` cases through
:func:`metric_rows`.
"""
from __future__ import annotations

import argparse
import fnmatch
import json
import os
import platform
import shutil
import subprocess
import sys
import zipfile
import dataclasses
from dataclasses import replace
from pathlib import Path

import numpy as np
import scipy

from .. import __version__
from ..contact import (CoulombFriction, PinballContact, hertz_force, penetration, penetration_rate, pinball_contact,
                       pinball_force, rate_force, reduced)
from ..esph import ESPHParams, artificial_pressure, artificial_viscosity, esph_rates
from ..integrate import cfl_time_step
from ..io import json_ready, read_npz
from ..kernels import get_kernel
from ..material import eos_pressure
from ..neighbours import find_pairs
from ..paper_data import AISI1045_RLA
from ..penalty import PenaltyContact, RoundedPolygon, penalty_contact
from ..plasticity import ModifiedJohnsonCook
from ..scenes import aisi4340_johnson_cook, aisi4340_material, get_scene, lattice
from ..simulate import run, simulate
from ..state import make_state
from ..strength import plastic_update
from ..surface import moment_min_eigenvalue, surface_alpha_shape, surface_sph
from ..thermal import conduction_rate, laplacian
from ..tlsph import ReferenceOperator, TLSPHParams, tlsph_rates
from .compare import SCATTER_FILE, Row, compare_case

__all__ = ["write_golden_cases", "case_names", "written_names", "pinned_environment", "generated_with", "metric_rows",
           "METRIC_RUNS", "FORMAT_VERSION", "FORMAT_CHANGES", "COMMON_CONVENTIONS", "ESPH_CONVENTIONS", "plain_array",
           "savez_fixed"]

FORMAT_VERSION = 2
FORMAT_CHANGES = {
    "2": "every array float64 or int64, little-endian, C order (version 1 stored some outputs, e.g. esph_rates/v_dot "
         "and tlsph_*/F, in Fortran order); case.json: format_version, kind, per array its dtype, rows (what axis 0 "
         "counts) and meaning, every convention as data (conventions: a dict), and every number a case needs also "
         "as a 0-d input array (h, dp, beta1, ... of esph_rates; the material constants) so that a reader needs "
         "no JSON for numbers; scene cases carry their whole set-up (masses, reference positions, body ids, clamp "
         "rows as input arrays; material, strength, numerics, tools and their motion, walls, symmetry planes in "
         "case.json's setup); new cases esph_rates_{no_viscosity,no_artificial_pressure,stress_only}, "
         "esph_pair_terms, pinball_pairs. The output numbers of every version-1 case are unchanged.",
    "1": "the first version: input.npz, output.npz, case.json with shape and unit per array",
}
ROUND_OFF = ("summed over pairs in another order, a sum of O(10) terms of mixed sign loses a few digits; 1e-10 "
             "of the largest value leaves room for that and catches any real difference")
MAT = aisi4340_material()

# Conventions every case shares (in every case.json under "conventions", and in golden/FORMAT.md).
COMMON_CONVENTIONS = dict(
    format="golden/FORMAT.md, version 2: input.npz and output.npz are uncompressed zip archives (np.savez, not "
           "savez_compressed) of NPY 1.0 arrays <name>.npy, float64 ('<f8') or int64 ('<i8'), little-endian, C "
           "order (fortran_order False); a number is a 0-d array; a mask is int64 0/1",
    units="SI (m, s, kg, Pa, K, J, W); each array's unit is in arrays[...].unit. 2D is plane strain per metre of "
          "thickness: mass kg/m, volume m^2, force N/m, power W/m",
    indices="0-based int64 row indices into the arrays of the same case",
    tensors="an (N, d, d) array T holds T[n, a, b] = row a, column b of particle n's tensor; the velocity gradient "
            "l[n, a, b] = dv_a/dx_b; 2D stresses are the in-plane block, S_zz the out-of-plane deviatoric normal "
            "stress (plane strain)",
    rows="arrays[...].rows says what axis 0 of an array counts: particle, pair (a row of the pair list I, J), "
         "sample, point, vertex; absent for a 0-d number",
)
# The ESPH equations as a backend has to implement them (Eqs. (9)-(14), (20)-(24); refsph/esph.py).
ESPH_CONVENTIONS = dict(
    pairs="half pairs: each interacting pair once, I[k] < J[k], no self-pairs, no duplicates; a pair term is "
          "computed once and added to particle i = I[k] and, with the sign its symmetry gives, to j = J[k]",
    separation="x_ij = x_i - x_j, v_ij = v_i - v_j, r_ij = |x_ij| (i = I[k], j = J[k])",
    kernel="cubic B-spline, Eq. (9): W = alpha_d f(q), q = r/h, f = 1 - 3/2 q^2 + 3/4 q^3 (q <= 1), 1/4 (2 - q)^3 "
           "(1 < q <= 2), 0 beyond: support 2h; alpha_2 = 10/(7 pi h^2), alpha_3 = 1/(pi h^3)",
    kernel_gradient="grad_i W_ij = (dW/dr)(r_ij) x_ij / r_ij (points from i towards j: dW/dr < 0); "
                    "grad_j W_ji = -grad_i W_ij",
    equation_of_state="p = K (rho / rho0 - 1), K = E / (3 (1 - 2 nu)) (Eq. (24)); p > 0 in compression",
    stress="sigma = S - p I (the in-plane block in 2D)",
    continuity="rho_dot_i = sum_j m_j v_ij . grad_i W_ij (Eq. (10)); the pair adds m_j v_ij . grad_i W_ij to i "
               "and m_i v_ij . grad_i W_ij to j",
    momentum="v_dot_i = sum_j m_j (sigma_i / rho_i^2 + sigma_j / rho_j^2 - (pi_ij + p^a_ij) I) grad_i W_ij "
             "(Eq. (11)); the pair adds to j the same bracket times m_i and -grad_i W_ij",
    viscosity="pi_ij = (-beta1 c0 mu_ij + beta2 mu_ij^2) / rho_bar_ij where v_ij . x_ij <= 0 (approaching), "
              "pi_ij = 0 where v_ij . x_ij > 0 (separating) (Eq. (12)); mu_ij = h v_ij . x_ij / (r_ij^2 + eps h^2) "
              "(Eq. (13)); rho_bar_ij = (rho_i + rho_j) / 2",
    viscosity_sound_speed="c0 = sqrt(E / rho0): the paper's C = sqrt(E / rho) with the reference density, one "
                          "number for every pair (not the dilatational speed of the time step, not the pair's "
                          "densities)",
    artificial_pressure="p^a_ij = gamma (|p_i| / rho_i^2 + |p_j| / rho_j^2) (W(r_ij) / W(dp))^n_ap (Eq. (14)) on "
                        "every pair, except p^a_ij = 0 where p_i > 0 and p_j > 0 (both compressed); W(dp): the "
                        "kernel at the distance dp",
    velocity_gradient="l_i = -sum_j (m_j / rho_j) v_ij (x) grad_i W_ij, l_ab = dv_a/dx_b (Eq. (23)); the pair adds "
                      "-(m_j / rho_j) (v_ij)_a (grad_i W_ij)_b to i and -(m_i / rho_i) (v_ij)_a (grad_i W_ij)_b "
                      "to j (v and grad W both change sign)",
    jaumann="S_dot = 2 G (eps_dot - tr(eps_dot) / 3 I) + omega S - S omega, eps_dot = (l + l^T) / 2, omega = "
            "(l - l^T) / 2, G = E / (2 (1 + nu)) (Eqs. (20)-(22); the paper prints s omega - omega s, which is "
            "the same for the transposed gradient l_ab = dv_b/dx_a)",
    plane_strain="2D: eps_dot_zz = 0, tr(eps_dot) = l_xx + l_yy, S_zz_dot = -(2 G / 3) tr(eps_dot); S_zz enters "
                 "no rate of this case",
)
# What each array name means (case.json arrays[...].meaning); a case may override one (_write's meaning=).
MEANING = dict(
    x="position", v="velocity", m="mass", rho="density", S="deviatoric Cauchy stress (in-plane block in 2D)",
    S_zz="out-of-plane deviatoric normal stress (2D plane strain)", X="reference position (TLSPH; ESPH: the "
    "initial one)", V0="reference volume", V="volume", eps_p="accumulated effective plastic strain",
    eps_dot_p="effective plastic strain rate of the last step", W_p="accumulated plastic work density",
    T="temperature", t="time at the end", body="body id (0: the deformable workpiece; a tool: its RigidBody.body)",
    I="first particle of each half pair (I < J)", J="second particle of each half pair",
    h="smoothing length", dp="initial particle spacing (W(dp) of Eq. (14))", beta1="linear viscosity coefficient "
    "(Eq. (12))", beta2="quadratic viscosity coefficient (Eq. (12))", gamma="artificial pressure coefficient "
    "(Eq. (14))", n_ap="artificial pressure exponent n (Eq. (14))", eps="regulariser of Eq. (13)",
    rho0="reference density", E="Young's modulus", nu="Poisson's ratio", G="shear modulus",
    r="distance", x_ij="separation x_i - x_j", W="kernel value W(r, h)", dW_dr="kernel derivative dW/dr",
    grad_W="kernel gradient grad_i W(x_ij) = dW/dr x_ij / r", rho_dot="density rate (Eq. (10))",
    v_dot="acceleration", S_dot="deviatoric stress rate (Jaumann, Eq. (20))", S_zz_dot="out-of-plane deviatoric "
    "stress rate", l="velocity gradient l_ab = dv_a/dx_b", F="deformation gradient", J_det="det F",
    P="first Piola-Kirchhoff stress P = J sigma F^-T", pi="artificial viscosity pi_ij (Eq. (12))",
    p_a="artificial pressure p^a_ij (Eq. (14))", p="pressure K (rho / rho0 - 1) (Eq. (24))",
    S_trial="trial deviatoric stress (3D)", eps_dot="equivalent strain rate of the step",
    d_eps_p="plastic strain increment", d_w_p="plastic work density increment", d_T="temperature increment",
    x_a="positions of body a (deformable)", v_a="velocities of body a", m_a="masses of body a", T_a="temperatures "
    "of body a", x_b="positions of body b (the partner)", v_b="velocities of body b", m_b="masses of body b "
    "(the deformable partner)", R="pinball radius", dt="time step", K_p="pinball scaling factor K_p (Eq. (33))",
    thickness="thickness a 2D particle stands for (dp): F2 is divided by it", mu0="friction coefficient at room "
    "temperature", q="friction exponent", T_room="room temperature", T_melt="melting temperature",
    a_rigid="acceleration of body a against the rigid partner", a_deformable="acceleration of body a against the "
    "deformable partner", force_on_b_rigid="force on each particle of the rigid partner", force_on_b_deformable=
    "force on each particle of the deformable partner", source="heat source (a temperature rate)", a="thermal "
    "diffusivity", lap_T="SPH Laplacian of T (Brookshaw)", T_dot="temperature rate", threshold="surface threshold "
    "on lambda_min", alpha="alpha of the alpha-shape (in units of dp)", lambda_min="smallest eigenvalue of the "
    "moment matrix", surface_sph="1 where lambda_min <= threshold", surface_alpha="1 on the alpha-shape's "
    "boundary", xi_in="committed tangential spring history", core="tool core vertices (relative to shift)",
    radius="tool edge radius", shift="position of the tool's particle centroid", damping="normal damping ratio",
    offset="contact offset", time_scale="time scale of the penalty stiffness", gap="gap (> 0: in contact)",
    force_on_tool="force on the tool", friction_power="friction power per particle",
    xi="tangential spring history after the step", f_normal="normal contact force", f_tangent="tangential contact "
    "force", p_d="penetration (R_i + R_j) - r (Eq. (32))", pdot_d="penetration rate -(v_i - v_j) . e_ij",
)


def plain_array(name: str, a) -> np.ndarray:
    """``a`` as golden/FORMAT.md stores it: float64 or int64 (booleans as int64 0/1), little-endian, C order; a
    ValueError naming ``name`` for anything else (text, objects)."""
    a = np.asarray(a)
    if a.dtype.kind == "f":
        a = a.astype("<f8", copy=False)
    elif a.dtype.kind in "iub":
        a = a.astype("<i8", copy=False)
    else:
        raise ValueError(f"array {name}: dtype {a.dtype} is not a plain number (golden/FORMAT.md: float64 or int64)")
    return a if a.flags.c_contiguous else a.copy(order="C")


def savez_fixed(path: Path, **arrays) -> None:
    """np.savez with fixed zip timestamps, so that the same arrays always give the same bytes: uncompressed
    (ZIP_STORED) NPY entries with a zip64 extra field, as np.savez writes them (golden/FORMAT.md)."""
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_STORED) as z:
        for name, a in arrays.items():
            info = zipfile.ZipInfo(name + ".npy", date_time=(1980, 1, 1, 0, 0, 0))
            with z.open(info, "w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asanyarray(a), allow_pickle=False)


def _axis0(name: str, a: np.ndarray, inputs: dict, rows: dict) -> str | None:
    """What axis 0 of array ``name`` counts (case.json arrays[...].rows): ``rows`` names it, else a particle (as
    many rows as the input positions x) or a pair (as many as the pair list I); None for a 0-d number."""
    if name in rows:
        return rows[name]
    if a.ndim == 0:
        return None
    n_pairs = len(inputs["I"]) if "I" in inputs else None
    n = len(inputs["x"]) if "x" in inputs else None
    if a.shape[0] == n_pairs and a.shape[0] != n:
        return "pair"
    if a.shape[0] == n and a.shape[0] != n_pairs:
        return "particle"
    raise ValueError(f"array {name}: say what its rows are (rows=)")


def _write(root: Path, name: str, what: str, equations: str, inputs: dict, outputs: dict, units: dict,
           tolerance: dict, why: str, *, kind: str, conventions: dict | None = None, rows: dict | None = None,
           meaning: dict | None = None, **extra) -> str:
    """Write one case (module text; golden/FORMAT.md): the arrays in their plain form, case.json with every array's
    shape, dtype, unit, rows and meaning, the common conventions and the case's own."""
    missing = sorted(set(outputs) - set(tolerance))
    if missing:
        raise ValueError(f"golden case {name}: no tolerance stated for {', '.join(missing)}")
    inputs = {k: plain_array(f"{name}/input/{k}", v) for k, v in inputs.items()}
    outputs = {k: plain_array(f"{name}/output/{k}", v) for k, v in outputs.items()}
    folder = root / name
    folder.mkdir(parents=True, exist_ok=True)
    savez_fixed(folder / "input.npz", **inputs)
    savez_fixed(folder / "output.npz", **outputs)
    rows, meaning = rows or {}, dict(MEANING, **(meaning or {}))
    arrays = {}
    for side, d in (("input", inputs), ("output", outputs)):
        for k, v in d.items():
            if k not in units or k not in meaning:
                raise ValueError(f"golden case {name}: no {'unit' if k not in units else 'meaning'} for {side}/{k}")
            arrays[f"{side}/{k}"] = dict(shape=list(v.shape), dtype=v.dtype.name, descr=v.dtype.str, unit=units[k],
                                         meaning=meaning[k])
            axis0 = _axis0(k, v, inputs, rows)
            if axis0 is not None:
                arrays[f"{side}/{k}"]["rows"] = axis0
    case = dict(name=name, format_version=FORMAT_VERSION, kind=kind, what=what, equations=equations, arrays=arrays,
                tolerance=tolerance, why=why, conventions=dict(COMMON_CONVENTIONS, **(conventions or {})), **extra)
    (folder / "case.json").write_text(json.dumps(json_ready(case), indent=1, sort_keys=True) + "\n")
    return name


def _kernel_cases(root):
    names = []
    for kname in ("cubic", "wendland"):
        K = get_kernel(kname)
        for dim in (2, 3):
            h = 1.5e-4
            r = np.linspace(0.0, 2.2 * h, 111)
            xij = np.random.default_rng(dim).uniform(-2.1 * h, 2.1 * h, size=(50, dim))
            names.append(_write(
                root, f"kernel_{kname}_{dim}d", f"the {kname} kernel in {dim}D: W(r), dW/dr and grad_i W(x_ij)",
                "Eq. (9)" if kname == "cubic" else "Wendland C2 (Dehnen & Aly 2012 normalisation, support 2h)",
                dict(r=r, h=np.float64(h), x_ij=xij),
                dict(W=K.w(r, h, dim), dW_dr=K.dw_dr(r, h, dim),
                     grad_W=K.dw_dr_over_r(np.linalg.norm(xij, axis=1), h, dim)[:, None] * xij),
                dict(r="m", h="m", x_ij="m", W="1/m^d", dW_dr="1/m^(d+1)", grad_W="1/m^(d+1)"),
                dict(W=1e-12, dW_dr=1e-12, grad_W=1e-12), "closed forms: only the last digits may differ",
                kind="kernel", rows=dict(r="sample", x_ij="sample", W="sample", dW_dr="sample", grad_W="sample"),
                meaning=dict(W="W(r[k], h)", dW_dr="dW/dr at r[k]", grad_W="grad_i W(x_ij[k]) = dW/dr x_ij / r"),
                conventions=dict(kernel=KERNEL_TEXT[kname], dimension=f"d = {dim}: the number of columns of x_ij",
                                 kernel_gradient="grad_i W(x_ij) = (dW/dr)(|x_ij|) x_ij / |x_ij|"),
                kernel=kname, dim=dim))
    return names


KERNEL_TEXT = dict(
    cubic="cubic B-spline, Eq. (9): W = alpha_d f(q), q = r/h, f = 1 - 3/2 q^2 + 3/4 q^3 (0 <= q <= 1), "
          "1/4 (2 - q)^3 (1 < q <= 2), 0 (q > 2): support 2h; alpha_2 = 10/(7 pi h^2), alpha_3 = 1/(pi h^3)",
    wendland="Wendland C2: W = alpha_d (1 - q/2)^4 (2 q + 1) for q = r/h <= 2, 0 beyond: support 2h; alpha_2 = "
             "7/(4 pi h^2), alpha_3 = 21/(16 pi h^3) (Dehnen & Aly 2012)")


def _block(nx=12, ny=10, dp=1e-4, seed=7):
    rng = np.random.default_rng(seed)
    X = lattice([nx * dp, ny * dp], dp)
    return X, rng


def _esph_block():
    """The state of the ESPH cases: a perturbed 2D block (12 x 10), random velocities, densities (so pressures of
    both signs) and deviatoric stresses; the paper's numerics (gamma = 0.3); the half pairs within 2h."""
    dp = 1e-4
    X, rng = _block(dp=dp)
    x = X + 0.05 * dp * rng.uniform(-1, 1, X.shape)
    st = make_state(x, rng.normal(0, 5.0, X.shape), MAT.rho0, dp * dp,
                    rho=MAT.rho0 * (1 + 2e-3 * rng.normal(size=len(X))))
    S = rng.normal(0, 5e7, (len(X), 2, 2))
    S = 0.5 * (S + S.transpose(0, 2, 1))
    st.S_zz = -(S[:, 0, 0] + S[:, 1, 1])
    st.S = S
    prm = ESPHParams(h=1.5 * dp, dp=dp, beta1=1.5, beta2=1.5, gamma=0.3, n_ap=4.0, eps=0.01,
                     kernel=get_kernel("cubic"))
    I, J = find_pairs(st.x, 2 * prm.h)
    return st, prm, I, J


ESPH_UNITS = dict(x="m", v="m/s", m="kg/m", rho="kg/m^3", S="Pa", S_zz="Pa", rho_dot="kg/m^3/s", v_dot="m/s^2",
                  S_dot="Pa/s", S_zz_dot="Pa/s", l="1/s", I="1 (index)", J="1 (index)", h="m", dp="m", beta1="1",
                  beta2="1", gamma="1", n_ap="1", eps="1", rho0="kg/m^3", E="Pa", nu="1", r="m", W="1/m^2",
                  dW_dr="1/m^3", grad_W="1/m^3", pi="m^2/s^2 / (kg/m^3)", p_a="Pa / (kg/m^3)^2", p="Pa")
ESPH_RATE_CASES = dict(esph_rates=dict(), esph_rates_no_viscosity=dict(beta1=0.0, beta2=0.0),
                       esph_rates_no_artificial_pressure=dict(gamma=0.0),
                       esph_rates_stress_only=dict(beta1=0.0, beta2=0.0, gamma=0.0))


def _esph_inputs(st, prm, I, J) -> dict:
    """Every input of an ESPH case, numbers as 0-d arrays (golden/FORMAT.md: no JSON needed for numbers)."""
    numbers = dict(h=prm.h, dp=prm.dp, beta1=prm.beta1, beta2=prm.beta2, gamma=prm.gamma, n_ap=prm.n_ap, eps=prm.eps,
                   rho0=MAT.rho0, E=MAT.E, nu=MAT.nu)
    return dict(x=st.x, v=st.v, m=st.m, rho=st.rho, S=st.S, S_zz=st.S_zz, I=I, J=J,
                **{k: np.float64(v) for k, v in numbers.items()})


def _esph_json(prm) -> dict:
    """case.json's material and params of an ESPH case (the derived constants with their formulas)."""
    return dict(material=dict(rho0=MAT.rho0, E=MAT.E, nu=MAT.nu, derived=dict(
                    K=MAT.K, G=MAT.G, c0=MAT.c0, formulas="K = E / (3 (1 - 2 nu)), G = E / (2 (1 + nu)), "
                                                          "c0 = sqrt(E / rho0)")),
                params=dict(h=prm.h, dp=prm.dp, beta1=prm.beta1, beta2=prm.beta2, gamma=prm.gamma, n_ap=prm.n_ap,
                            eps=prm.eps, kernel="cubic", W_dp=float(prm.kernel.w(prm.dp, prm.h, 2)), dim=2),
                pairs="half pairs I < J within 2h, as find_pairs gives them")


def _esph_cases(root):
    """ESPH rates of one state (Eqs. (10)-(14), (20)-(24)) with all terms, with the artificial viscosity off, with
    the artificial pressure off, with both off (so that a failing term is named by the case it fails in), and the
    pair terms of Eqs. (9), (12)-(14) one by one (:func:`_esph_pair_terms`)."""
    st, prm0, I, J = _esph_block()
    names = []
    for name, off in ESPH_RATE_CASES.items():
        prm = replace(prm0, **off)
        r = esph_rates(st, MAT, prm, I, J)
        what = "ESPH rates of a perturbed 2D block (free surfaces all round), plane strain" + (
            {"esph_rates_no_viscosity": ", artificial viscosity off (beta1 = beta2 = 0)",
             "esph_rates_no_artificial_pressure": ", artificial pressure off (gamma = 0)",
             "esph_rates_stress_only": ", artificial viscosity and pressure off: the stress terms alone"}.get(name, ""))
        names.append(_write(root, name, what, "Eqs. (9)-(14), (20)-(24)", _esph_inputs(st, prm, I, J),
                            dict(rho_dot=r.rho, v_dot=r.v, S_dot=np.array(r.S), S_zz_dot=r.S_zz, l=np.array(r.l)),
                            ESPH_UNITS, {k: 1e-10 for k in ("rho_dot", "v_dot", "S_dot", "S_zz_dot", "l")}, ROUND_OFF,
                            kind="esph_rates", conventions=ESPH_CONVENTIONS, switched_off=sorted(off),
                            **_esph_json(prm)))
    names.append(_esph_pair_terms(root, st, prm0, I, J))
    return names


def _esph_pair_terms(root, st, prm, I, J) -> str:
    """The terms of Eq. (11) per half pair, with the functions esph_rates uses: r, W and dW/dr (Eq. (9)), grad W,
    pi_ij (Eqs. (12)-(13)), p^a_ij (Eq. (14)), and the pressure of each particle (Eq. (24))."""
    x, v, rho = st.x, st.v, st.rho
    dx, dv = x[I] - x[J], v[I] - v[J]
    r2 = np.einsum("pk,pk->p", dx, dx)
    r = np.sqrt(r2)
    K = prm.kernel
    W, fr = K.w_and_dw_dr_over_r(r, prm.h, 2)
    p = eos_pressure(rho, MAT.rho0, MAT.K)
    vr = np.einsum("pk,pk->p", dv, dx)
    pi = artificial_viscosity(vr, r2, 0.5 * (rho[I] + rho[J]), MAT.c0, prm.h, prm.beta1, prm.beta2, prm.eps)
    p_a = artificial_pressure(p[I], p[J], rho[I], rho[J], W / K.w(prm.dp, prm.h, 2), prm.gamma, prm.n_ap)
    out = dict(r=r, W=W, dW_dr=K.dw_dr(r, prm.h, 2), grad_W=fr[:, None] * dx, pi=pi, p_a=p_a, p=p)
    return _write(root, "esph_pair_terms", "the terms of ESPH's momentum equation per half pair (the state of "
                  "esph_rates): distance, kernel value and gradient, artificial viscosity, artificial pressure; and "
                  "each particle's pressure", "Eqs. (9), (12)-(14), (24)", _esph_inputs(st, prm, I, J), out,
                  ESPH_UNITS, {k: 1e-12 for k in out}, "closed forms per pair: round-off only",
                  kind="esph_pair_terms", conventions=ESPH_CONVENTIONS,
                  meaning=dict(r="r_ij = |x_i - x_j| of pair k", W="W(r_ij, h) of pair k", dW_dr="dW/dr at r_ij",
                               grad_W="grad_i W_ij of pair k", pi="pi_ij of pair k (0 where separating)",
                               p_a="p^a_ij of pair k (0 where both pressures are positive)"),
                  counts=dict(pairs=len(I), separating=int(np.count_nonzero(vr > 0)),
                              both_compressed=int(np.count_nonzero((p[I] > 0) & (p[J] > 0)))),
                  **_esph_json(prm))


def _tlsph_cases(root):
    dp = 1e-4
    X, rng = _block(dp=dp, seed=11)
    V = np.full(len(X), dp * dp)
    a = 0.4
    Rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    maps = dict(affine=lambda X: X @ np.array([[1.02, 0.03], [-0.01, 0.97]]).T,
                rotation=lambda X: X @ Rot.T,
                random=lambda X: X + 0.03 * dp * rng.normal(size=X.shape))
    names = []
    for mname, f in maps.items():
        x = f(X)
        v = rng.normal(0, 2.0, X.shape)
        S = rng.normal(0, 3e7, (len(X), 2, 2))
        S = 0.5 * (S + S.transpose(0, 2, 1))
        S_zz = -(S[:, 0, 0] + S[:, 1, 1])
        for corrected in (True, False):
            prm = TLSPHParams(h=1.5 * dp, beta1=1.5, beta2=1.5, eps=0.01, kernel=get_kernel("cubic"),
                              corrected=corrected, ref_update_strain=None)
            st = make_state(X, v, MAT.rho0, V, S=S, S_zz=S_zz)
            st.x = x
            op = ReferenceOperator(X, V, prm.h, prm.kernel, corrected)
            out: dict = {}
            r = tlsph_rates(st, MAT, prm, op, out=out)
            tag = "corrected" if corrected else "uncorrected"
            names.append(_write(
                root, f"tlsph_{mname}_{tag}", f"TLSPH of a 2D block mapped by a {mname} map, kernel gradient {tag}",
                "Eqs. (2), (16)-(24); correction L = M^-T (Bonet & Lok 1999)",
                dict(X=X, V0=V, x=x, v=v, m=st.m, S=S, S_zz=S_zz, I=op.I, J=op.J, h=np.float64(prm.h),
                     beta1=np.float64(1.5), beta2=np.float64(1.5), eps=np.float64(0.01), rho0=np.float64(MAT.rho0),
                     E=np.float64(MAT.E), nu=np.float64(MAT.nu), corrected=np.int64(corrected)),
                dict(F=np.array(out["F"]), J_det=out["J"], P=np.array(out["P"]), l=np.array(out["l"]), v_dot=r.v,
                     S_dot=np.array(r.S), S_zz_dot=r.S_zz),
                dict(X="m", V0="m^2", x="m", v="m/s", m="kg/m", S="Pa", S_zz="Pa", F="1", J_det="1", P="Pa",
                     l="1/s", v_dot="m/s^2", S_dot="Pa/s", S_zz_dot="Pa/s", I="1 (index)", J="1 (index)", h="m",
                     beta1="1", beta2="1", eps="1", rho0="kg/m^3", E="Pa", nu="1", corrected="1 (0/1)"),
                {k: 1e-10 for k in ("F", "J_det", "P", "l", "v_dot", "S_dot", "S_zz_dot")}, ROUND_OFF,
                kind="tlsph_rates", conventions=TLSPH_CONVENTIONS,
                meaning=dict(corrected="1: the corrected kernel gradient L_i grad_i W (L = M^-T); 0: Eq. (18) "
                                       "as printed", I="first particle of each half pair of the reference "
                                       "configuration (I < J)"),
                material=dict(rho0=MAT.rho0, E=MAT.E, nu=MAT.nu, derived=dict(K=MAT.K, G=MAT.G, c0=MAT.c0)),
                params=dict(h=prm.h, beta1=1.5, beta2=1.5, eps=0.01, kernel="cubic", corrected=corrected),
                pairs="half pairs I < J of the reference configuration X within 2h"))
    return names


TLSPH_CONVENTIONS = dict(
    pairs="half pairs of the reference configuration: I[k] < J[k] with |X_I - X_J| <= 2h; each pair term is "
          "added to i = I[k] and, with its symmetry's sign, to j = J[k]",
    kernel=ESPH_CONVENTIONS["kernel"] + "; evaluated at X_ij = X_i - X_j (the reference configuration)",
    volumes="V_j = V0_j (reference volumes); rho0_j = m_j / V0_j",
    correction="corrected = 1: grad~_i W_ij = L_i grad_i W(X_ij), L_i = M_i^-T, M_i = sum_j V_j (X_j - X_i) (x) "
               "grad_i W(X_ij) (Bonet & Lok 1999; pseudo-inverse where M_i is singular); corrected = 0: "
               "grad_i W(X_ij) as printed",
    deformation_gradient="F_i = -sum_j V_j (x_i - x_j) (x) grad~_i W_ij (Eq. (18)); Fdot_i likewise with v "
                         "(Eq. (19)); l_i = Fdot_i F_i^-1; J = det F; rho = rho0 / J (Eq. (2))",
    stress="sigma = S - p I, p = K (rho / rho0 - 1) (Eq. (24)); P = J sigma F^-T (the paper prints J F^-1 sigma, "
           "the nominal stress; README 'Where refsph departs from the paper')",
    momentum="v_dot_i = sum_j m_j (P_i / rho0_i^2 + P_j / rho0_j^2 - Pi_ij) grad~ W, Eq. (17): with the corrected "
             "gradient each side uses its own, (P_i / rho0_i^2) grad~_i W_ij - (P_j / rho0_j^2) grad~_j W_ji",
    viscosity="v_dot_i -= sum_j m_j pi_ij (B_i + B_j) / 2 grad_i W(X_ij), B = J F^-T, with the uncorrected "
              "gradient; pi_ij of Eqs. (12)-(13) with the current x_ij, v_ij (0 where v_ij . x_ij > 0), c0 = "
              "sqrt(E / rho0) and rho_bar = (rho_i + rho_j) / 2, rho = rho0_i / J",
    jaumann=ESPH_CONVENTIONS["jaumann"],
    plane_strain=ESPH_CONVENTIONS["plane_strain"],
)


def _return_map_cases(root):
    rng = np.random.default_rng(3)
    n = 200
    S = rng.normal(0, 1, (n, 3, 3))
    S = 0.5 * (S + S.transpose(0, 2, 1))
    tr = np.trace(S, axis1=1, axis2=2) / 3
    S = S - tr[:, None, None] * np.eye(3)
    S *= rng.uniform(0.1, 3.0, n)[:, None, None] * 1e9 / np.sqrt(1.5 * np.einsum("nab,nab->n", S, S))[:, None, None]
    eps_p = rng.uniform(0, 3.0, n)
    eps_dot = 10.0 ** rng.uniform(-3, 6, n)
    T = rng.uniform(250, 1700, n)
    rho = np.full(n, 7830.0)
    jc = aisi4340_johnson_cook(eps_dot_0=1.0)
    t = AISI1045_RLA
    mod = ModifiedJohnsonCook(A=t["A_Pa"], B=t["B_Pa"], n=t["n"], C=t["C"], m=t["m"], eps_dot_0=t["eps_dot_0"],
                              T_room=t["T_room_K"], T_melt=t["T_melt_K"], cp=t["cp_J_kgK"], chi=t["taylor_quinney"],
                              hardening_saturation_strain=t["hardening_saturation_strain"])
    names = []
    for name, law in (("johnson_cook", jc), ("modified", mod)):
        S_n, _, deps, dw, dT = plastic_update(S, np.zeros(n), eps_p, T, rho, eps_dot, law, MAT.G)
        consts = {k: getattr(law, k) for k in law.constants()}
        names.append(_write(
            root, f"return_map_{name}", f"the return map of {n} trial stresses (3D): elastic, yielding, fast, hot and "
            f"above T_melt, {type(law).__name__}", "Eqs. (25)-(31)" + (", modified law (second paper, Eq. (9))"
                                                                       if law is mod else ""),
            dict(S_trial=S, eps_p=eps_p, eps_dot=eps_dot, T=T, rho=rho, G=np.float64(MAT.G),
                 **{f"law_{k}": np.float64(v) for k, v in consts.items()}),
            dict(S=S_n, d_eps_p=deps, d_w_p=dw, d_T=dT),
            dict(S_trial="Pa", S="Pa", eps_p="1", eps_dot="1/s", T="K", rho="kg/m^3", G="Pa", d_eps_p="1",
                 d_w_p="J/m^3", d_T="K", **{f"law_{k}": LAW_UNITS[k] for k in consts}),
            dict(S=1e-12, d_eps_p=1e-12, d_w_p=1e-12, d_T=1e-12), "closed forms per particle: round-off only",
            kind="return_map", rows={"S_trial": "particle", "eps_p": "particle", "eps_dot": "particle",
                                     "T": "particle", "rho": "particle", "S": "particle", "d_eps_p": "particle",
                                     "d_w_p": "particle", "d_T": "particle"},
            meaning=dict(S="deviatoric stress after the return map (3D)", eps_p="plastic strain at the start",
                         T="temperature at the start", **{f"law_{k}": f"the law's constant {k} (case.json law)"
                                                          for k in consts}),
            law=dict(model=type(law).__name__, **consts),
            conventions=dict(
                rate="ln(max(eps_dot / eps_dot_0, 1)) in Eq. (25): rates below eps_dot_0 have no rate effect",
                homologous_temperature="T* = (T - T_room) / (T_melt - T_room) clipped to [0, 1]",
                explicit="the flow stress uses the start values eps_p and T (Eq. (25)); radial return of S_trial "
                         "to the von Mises surface sqrt(3/2 S:S) = sigma_y (Eqs. (29)-(30)), d_eps_p = "
                         "(sigma_vm - sigma_y) / (3 G), d_w_p = sigma_y d_eps_p (Eq. (31))",
                heating="d_T = chi d_w_p / (rho cp) (Eq. (28) in increment form)"
                        + ("; hardening with min(eps_p, hardening_saturation_strain)" if law is mod else ""))))
    return names


LAW_UNITS = dict(A="Pa", B="Pa", n="1", C="1", m="1", eps_dot_0="1/s", T_room="K", T_melt="K", cp="J/(kg K)",
                 chi="1", hardening_saturation_strain="1")


def _pinball_setup():
    """The pinball cases' particles: a perturbed 2D block (6 x 4) falling at ~5 m/s onto a row of 8 particles
    below it that overlaps its bottom row by 0.1 dp; R = dp / 2 (k = dp / (2h)), K_p = 50, dt = 10 ns."""
    dp = 1e-4
    h = 1.5 * dp
    rng = np.random.default_rng(5)
    xa = lattice([6 * dp, 4 * dp], dp) + 0.02 * dp * rng.normal(size=(24, 2))
    xb = np.stack([np.arange(-1, 7) * dp + 0.5 * dp, np.full(8, -0.5 * dp + 0.1 * dp)], axis=1)
    va = rng.normal(0, 1, xa.shape) - [0.0, 5.0]
    vb = np.zeros_like(xb)
    ma = np.full(len(xa), MAT.rho0 * dp * dp)
    mb = np.full(len(xb), MAT.rho0 * dp * dp)
    c = PinballContact(k=dp / (2 * h), K_p=50.0)
    return dict(x_a=xa, v_a=va, m_a=ma, x_b=xb, v_b=vb, m_b=mb, R=np.float64(c.k * h), G=np.float64(MAT.G),
                dt=np.float64(1e-8), K_p=np.float64(c.K_p), thickness=np.float64(dp)), c


PINBALL_UNITS = dict(x_a="m", v_a="m/s", m_a="kg/m", x_b="m", v_b="m/s", m_b="kg/m", R="m", G="Pa", dt="s", K_p="1",
                     thickness="m", a_rigid="m/s^2", force_on_b_rigid="N/m", a_deformable="m/s^2",
                     force_on_b_deformable="N/m", I="1 (index into x_a)", J="1 (index into x_b)", p_d="m",
                     pdot_d="m/s", m_ij="kg/m", F1_rigid="N/m", F2_rigid="N/m", F_rigid="N/m", f_rigid="N/m",
                     F1_deformable="N/m", F2_deformable="N/m", F_deformable="N/m", f_deformable="N/m")
PINBALL_ROWS = dict(x_a="particle of a", v_a="particle of a", m_a="particle of a", a_rigid="particle of a",
                    a_deformable="particle of a", x_b="particle of b", v_b="particle of b", m_b="particle of b",
                    force_on_b_rigid="particle of b", force_on_b_deformable="particle of b")
PINBALL_CONVENTIONS = dict(
    pairs="every particle i of body a with every particle j of body b at 0 < r_ij < 2R (I indexes x_a, J indexes "
          "x_b: two bodies, no I < J rule); x_ij = x_a[i] - x_b[j], e_ij = x_ij / r_ij",
    penetration="p_d = 2R - r_ij (Eq. (32), R_i = R_j = R); a pair is in contact where p_d > 0",
    penetration_rate="pdot_d = -(v_i - v_j) . e_ij, positive while approaching (the paper prints |vdot_i - vdot_j|)",
    reduced_mass="m_ij = m_i m_j / (m_i + m_j); = m_i against the rigid partner (m_j infinite)",
    rate_force="F1 = m_ij pdot_d / dt where pdot_d > 0, else 0 (Eq. (34), m_ij in place of rho R^3)",
    hertz_force="F2 = mu_ij sqrt(R_i R_j / (R_i + R_j)) max(p_d, 0)^1.5 / thickness (Eq. (35)); mu = G, mu_ij = "
                "G/2 between two deformable particles of the same G, = G against the rigid partner (mu_j infinite)",
    force="F = K_p min(F1, F2) where p_d > 0, else 0 (Eq. (33)); the force on i is f_ij = F e_ij, on j -f_ij; "
          "a_i = sum_j f_ij / m_i (Eq. (36))",
    partners="rigid: m_b and mu_b infinite (the masses m_b of the input are not used); deformable: m_b, mu_b = G",
)


def _pinball_case(root):
    inputs, c = _pinball_setup()
    xa, va, ma, xb, vb, mb = (inputs[k] for k in ("x_a", "v_a", "m_a", "x_b", "v_b", "m_b"))
    R, dt, dp = float(inputs["R"]), float(inputs["dt"]), float(inputs["thickness"])
    rigid = pinball_contact(xa, va, ma, xb, vb, np.inf, R, MAT.G, np.inf, dt, c, thickness=dp)
    soft = pinball_contact(xa, va, ma, xb, vb, mb, R, MAT.G, MAT.G, dt, c, thickness=dp)
    return _write(root, "pinball", "pinball contact of a 2D block against a row of particles below it: rigid (m_b, "
                  "mu_b infinite) and deformable partners", "Eqs. (32)-(36)", inputs,
                  dict(a_rigid=rigid.a, force_on_b_rigid=rigid.force_on_b, a_deformable=soft.a,
                       force_on_b_deformable=soft.force_on_b), PINBALL_UNITS,
                  dict(a_rigid=1e-12, force_on_b_rigid=1e-12, a_deformable=1e-12, force_on_b_deformable=1e-12),
                  "closed forms per pair, summed per particle: round-off only", kind="pinball", rows=PINBALL_ROWS,
                  conventions=PINBALL_CONVENTIONS, meaning=dict(G="shear modulus mu of both bodies (Eq. (35))"))


def _pinball_pairs_case(root):
    """The pinball contact pair by pair (Eqs. (32)-(35)): a perturbed block overlapping a row of partner particles
    by 0.3 dp, R = 0.75 dp (so diagonal pairs touch too), speeds from 10 cm/s to 300 m/s in random directions: pairs
    that approach and pairs that separate (F1 = 0), pairs where the rate force F1 is the smaller and pairs where
    the Hertz force F2 is; their penetration and its rate, F1, F2 (before K_p), F and the force vector on a,
    against a rigid and a deformable (1.5 times heavier) partner."""
    dp = 1e-4
    rng = np.random.default_rng(56)
    xa = lattice([6 * dp, 4 * dp], dp) + 0.05 * dp * rng.normal(size=(24, 2))
    xb = np.stack([np.arange(-1, 7) * dp + 0.5 * dp, np.full(8, -0.5 * dp + 0.3 * dp)], axis=1)
    va = rng.normal(0, 1, xa.shape) * 10.0 ** rng.uniform(-1, 2.5, (24, 1))
    vb = rng.normal(0, 0.5, xb.shape)
    ma, mb = np.full(24, MAT.rho0 * dp * dp), np.full(8, 1.5 * MAT.rho0 * dp * dp)
    R, dt, G, K_p = 0.75 * dp, 1e-8, MAT.G, 50.0
    dx = xa[:, None, :] - xb[None, :, :]
    r = np.sqrt(np.einsum("abk,abk->ab", dx, dx))
    I, J = np.nonzero((r > 0) & (r < 2 * R))                   # row-major: sorted by I, then J
    dx, r = dx[I, J], r[I, J]
    p_d = penetration(R, R, r)
    pdot = penetration_rate(dx, va[I] - vb[J], r)
    out = dict(p_d=p_d, pdot_d=pdot)
    switch = []
    for tag, m_b, mu_b in (("rigid", np.inf, np.inf), ("deformable", mb[J], G)):
        m_ij, mu_ij = reduced(ma[I], m_b), reduced(G, mu_b)
        F1, F2 = rate_force(m_ij, pdot, dt), hertz_force(mu_ij, R, R, p_d, dp)
        F = pinball_force(p_d, pdot, m_ij, mu_ij, R, R, dt, K_p, dp)
        out.update({f"F1_{tag}": F1, f"F2_{tag}": F2, f"F_{tag}": F, f"f_{tag}": dx / r[:, None] * F[:, None]})
        switch.append(dict(partner=tag, hertz_smaller=int(np.count_nonzero((pdot > 0) & (F2 < F1))),
                           margin_F1_over_F2_to_1=float(np.min(np.abs(F1[pdot > 0] / F2[pdot > 0] - 1)))))
    inputs = dict(x_a=xa, v_a=va, m_a=ma, x_b=xb, v_b=vb, m_b=mb, R=np.float64(R), G=np.float64(G),
                  dt=np.float64(dt), K_p=np.float64(K_p), thickness=np.float64(dp), I=I, J=J)
    return _write(root, "pinball_pairs", "pinball contact pair by pair: penetration, its rate, the rate force F1, "
                  "the Hertz force F2 (before K_p), the force F and its vector on a, against a rigid and a "
                  "deformable partner; pairs approaching and separating, either force the smaller",
                  "Eqs. (32)-(36)", inputs, out, PINBALL_UNITS, {k: 1e-12 for k in out},
                  "closed forms per pair: round-off only (no approaching pair within 5 % of the F1 = F2 switch)",
                  kind="pinball_pairs", rows=PINBALL_ROWS, conventions=PINBALL_CONVENTIONS,
                  meaning=dict(G="shear modulus mu of both bodies (Eq. (35))", I="particle of body a of each pair",
                               J="particle of body b of each pair", F1_rigid="Eq. (34) against the rigid partner",
                               F2_rigid="Eq. (35) against the rigid partner", F_rigid="Eq. (33) against the rigid "
                               "partner", f_rigid="force on a of each pair, F e_ij (rigid partner)",
                               F1_deformable="Eq. (34) against the deformable partner", F2_deformable="Eq. (35) "
                               "against the deformable partner", F_deformable="Eq. (33) against the deformable "
                               "partner", f_deformable="force on a of each pair, F e_ij (deformable partner)"),
                  counts=dict(pairs=len(I), approaching=int(np.count_nonzero(pdot > 0))), switch=switch)


STATE_KEYS = ("x", "v", "rho", "S", "S_zz", "eps_p", "T")
SCENES = dict(taylor=dict(dim=2, quick=True), pressing=dict(quick=True), cutting=dict(quick=True))


def _state_arrays(s) -> dict:
    return {k: np.asarray(getattr(s, k)) for k in STATE_KEYS if getattr(s, k) is not None}


SCENE_CONVENTIONS = dict(
    state="input.npz holds the initial state of every particle (the deformable rows first, the tools' rows last: "
          "body > 0) with its masses, reference positions and volumes; output.npz the state at the end, t",
    method="esph: ESPH (Eqs. (9)-(14), (20)-(24), the conventions of the esph_rates case), the tools' particles "
           "as SPH neighbours; tlsph: TLSPH (Eqs. (2), (16)-(24), the tlsph_* cases) with the contact of "
           "setup.numerics.contact between workpiece and tools: pinball (Eqs. (32)-(36), R = contact_k h, "
           "contact_k null meaning R = dp / 2) or penalty (the formulas of the penalty_friction case, golden/FORMAT.md "
           "'penalty', against each tool's setup.rigid_bodies[].shape with shift = the centroid of its particles: "
           "alpha = numerics.penalty_alpha, damping = numerics.penalty_damping, offset = dp / 2, time_scale = "
           "courant h / c_L, mu(T) of setup.friction (null: frictionless); every contact evaluation of a step takes "
           "the whole step's dt in xi* = xi + v_t dt and starts from the same committed xi, which starts at 0 and is "
           "committed at the end of each step from the step's last evaluation (the leapfrog's, at the step's end "
           "with the half-step velocity); the friction power heats the sliding particle and the tool row nearest it, "
           "and with dissipation_heat the damping power heats the particle)",
    time_step="dt = courant h / (c_L + max_i |v_i|), c_L = sqrt((K + 4 G / 3) / rho0) (the CFL step, evaluated at "
              "the start of every step; a step is shortened to land on the next output time)",
    integrator="setup.numerics.integrator: predictor_corrector (y_1/2 = y + dt/2 f(y), y_1 = y + dt f(y_1/2)) or "
               "leapfrog (kick-drift-kick), refsph/integrate.py",
    output_times="t_end k / n_snapshots for k = 1 .. n_snapshots, and snapshot_times",
    boundaries="symmetry planes x_a = 0 by mirror ghosts (setup.symmetry_axes); rigid walls x_axis >= position, "
               "unilateral and frictionless (setup.walls); rigid bodies move as setup.rigid_bodies say, c(t) = c0 + "
               "V t, their rows carry v = V and no stress rate; clamped rows (input clamp_<name>) keep x, and v = 0",
    return_map="setup.strength's return map (Eqs. (25)-(31)) on every stage's state, with the start-of-step "
               "eps_p and T; heating adds d_T = chi d_w_p / (rho cp)",
    objects="setup: every refsph object as data, its class in 'type' and its fields (null: none or infinite)",
)


def _data(o):
    """A scene's object as JSON data: a dataclass as {"type": its class, field: value, ...}, recursively."""
    if dataclasses.is_dataclass(o) and not isinstance(o, type):
        return dict(type=type(o).__name__, **{f.name: _data(getattr(o, f.name)) for f in dataclasses.fields(o)})
    if isinstance(o, dict):
        return {str(k): _data(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_data(v) for v in o]
    return o


def _scene_case(setup, numerics: dict, t_end: float, n_snapshots: int | None = None) -> tuple[dict, dict]:
    """(the input arrays, case.json's scene entries) of a whole-scene case: the state, masses, reference positions
    and volumes, body ids, plastic fields and clamp rows as arrays; material, strength, numerics (with the case's
    ``numerics``), tools and their motion, walls, symmetry planes, heat flow in ``setup`` (Section 2 of the
    paper; the README's departures)."""
    s, mat = setup.state, setup.material
    arrays = dict(_state_arrays(s), m=s.m, X=s.X, V0=s.V0,
                  body=s.body if s.body is not None else np.zeros(s.n, dtype=np.int64))
    if s.plastic:
        arrays.update(eps_dot_p=s.eps_dot_p, W_p=s.W_p)
    arrays.update({f"clamp_{c.name}": c.index for c in setup.clamps})
    arrays.update({f"scene_{k}": a for k, a in setup.arrays.items()})
    d = s.dim
    units = dict(x="m", v="m/s", rho="kg/m^3", S="Pa", S_zz="Pa", eps_p="1", T="K", t="s", X="m",
                 m="kg/m" if d == 2 else "kg", V0="m^2" if d == 2 else "m^3", body="1 (id)", eps_dot_p="1/s",
                 W_p="J/m^3", **{k: "1 (index)" for k in arrays if k.startswith(("clamp_", "scene_"))})
    meaning = {k: f"rows of clamp {k[6:]} (held: x fixed, v = 0)" for k in arrays if k.startswith("clamp_")}
    meaning.update({k: f"the scene's index set {k[6:]} (its measurements)" for k in arrays if k.startswith("scene_")})
    rows = {k: "index" for k in arrays if k.startswith(("clamp_", "scene_"))}
    numerics = replace(setup.numerics, **numerics)
    data = dict(
        dim=d, dp=setup.dp, h=numerics.h_over_dp * setup.dp, n_particles=s.n, t_end=t_end,
        n_snapshots=setup.n_snapshots if n_snapshots is None else n_snapshots,
        snapshot_times=[float(t) for t in setup.snapshot_times] if n_snapshots is None else [],
        material=dict(rho0=mat.rho0, E=mat.E, nu=mat.nu, G=mat.G, K=mat.K, c0=mat.c0,
                      c_longitudinal=mat.c_longitudinal),
        strength=_data(setup.strength), numerics=_data(numerics),
        symmetry_axes=list(setup.mirror.axes) if setup.mirror is not None else [],
        walls=_data(setup.walls), rigid_bodies=_data(setup.rigid),
        clamps=[dict(name=c.name, rows=f"input/clamp_{c.name}") for c in setup.clamps],
        friction=_data(setup.friction), thermal=_data(setup.thermal), friction_heat=_data(setup.friction_heat),
        dissipation_heat=setup.dissipation_heat, info=setup.info)
    return arrays, dict(setup=data, units=units, meaning=meaning, rows=rows, conventions=SCENE_CONVENTIONS)


def _write_scene(root, name, what, equations, scene_case, outputs, tolerance, why, kind, **extra) -> str:
    """_write for a whole-scene case (:func:`_scene_case`'s arrays and entries)."""
    inputs, entries = scene_case
    return _write(root, name, what, equations, inputs, outputs, entries["units"], tolerance, why, kind=kind,
                  conventions=entries["conventions"], rows=entries["rows"], meaning=entries["meaning"],
                  setup=entries["setup"], **extra)


def _step_and_run_cases(root):
    names = []
    for scene, args in (("taylor", SCENES["taylor"]), ("pressing", SCENES["pressing"])):
        setup = get_scene(scene).setup(**args)
        for method in ("esph", "tlsph"):
            dt0 = cfl_time_step(setup.state, setup.material, setup.h, setup.numerics.courant)
            res = run(scene, method, progress=False, numerics=dict(threads=1), t_end=dt0, **args)
            names.append(_write_scene(
                root, f"step_{method}_{scene}", f"one CFL step's time of the whole {scene} scene ({method.upper()}, "
                "quick), in the run loop's steps: " + ("symmetry plane and rigid wall" if scene == "taylor"
                                                       else "clamped column and rigid tool"),
                "all of the method's equations, the boundaries, the return map",
                _scene_case(setup, dict(threads=1), dt0), dict(_state_arrays(res.state), t=np.float64(res.state.t)),
                {k: 1e-10 for k in STATE_KEYS + ("t",)}, ROUND_OFF, "step",
                scene=scene, scene_args=args, method=method, dt=dt0, n_steps=res.summary["n_steps"],
                step="the run loop with t_end = dt (the CFL step) and the scene's output intervals: the loop "
                     "shortens each step to land on the next output time, so it takes n_steps predictor-corrector "
                     "steps of dt / n_steps (the step_*_leapfrog cases take one whole step)"))
    for scene, args in SCENES.items():
        for method in ("esph", "tlsph"):
            setup = get_scene(scene).setup(**args)
            t_end = 40 * 0.3 * setup.h / (setup.material.c_longitudinal + 200.0)    # about 40 steps
            res = run(scene, method, progress=False, numerics=dict(threads=1), t_end=t_end, **args)
            names.append(_write_scene(
                root, f"run_{scene}_{method}", f"a short run of the {scene} scene at quick resolution ({method.upper()}"
                ", about 40 CFL steps): the final state and the metrics", "all",
                _scene_case(setup, dict(threads=1), t_end), dict(_state_arrays(res.state), t=np.float64(res.state.t)),
                {k: 1e-6 for k in STATE_KEYS + ("t",)},
                "40 steps amplify round-off (the pinball switch of Eq. (34) most): 1e-6 of the largest value", "run",
                scene=scene, scene_args=args, method=method, t_end=t_end, n_steps=res.summary["n_steps"],
                metrics={k: v for k, v in res.summary["metrics"].items() if np.ndim(v) == 0}))
    return names


def _conduction_case(root):
    dp = 1e-4
    h = 1.3 * dp
    X, rng = _block(nx=14, ny=12, dp=dp, seed=13)
    x = X + 0.1 * dp * rng.uniform(-1, 1, X.shape)
    V = dp * dp * (1 + 0.1 * rng.uniform(-1, 1, len(X)))
    centre = np.array([5.0, 6.0]) * dp
    T = (293.0 + 600.0 * np.exp(-np.sum((x - centre) ** 2, axis=1) / (3 * dp) ** 2) + 2e5 * x[:, 0]
         + 3.0 * rng.normal(size=len(X)))
    t = AISI1045_RLA
    a = t["k_W_mK"] / (t["rho"] * t["cp_J_kgK"]) * (1 + 0.3 * rng.uniform(-1, 1, len(X)))
    source = rng.uniform(0, 1e5, len(X))
    K = get_kernel("wendland")
    I, J = find_pairs(x, K.support * h)
    lap = laplacian(T, x, V, h, K, pairs=(I, J))
    rate = conduction_rate(T, x, V, a, h, K, pairs=(I, J), source=source)
    return _write(root, "conduction", "Brookshaw's SPH Laplacian of a temperature field (a hot spot on a gradient, "
                  "with noise) on a perturbed 2D lattice with free edges, and the conduction rate with a diffusivity "
                  "and a heat source per particle", "Eqs. (26), (29) (second paper; Brookshaw 1985)",
                  dict(x=x, V=V, T=T, a=a, source=source, h=np.float64(h), I=I, J=J),
                  dict(lap_T=lap, T_dot=rate),
                  dict(x="m", V="m^2", T="K", a="m^2/s", source="K/s", h="m", lap_T="K/m^2", T_dot="K/s",
                       I="1 (index)", J="1 (index)"),
                  dict(lap_T=1e-10, T_dot=1e-10), ROUND_OFF, kind="conduction", kernel="wendland (support 2h)",
                  pairs="half pairs I < J within 2h, as find_pairs gives them",
                  conventions=dict(pairs=ESPH_CONVENTIONS["pairs"], kernel=KERNEL_TEXT["wendland"],
                                   laplacian="lap T_i = sum_j 2 (T_i - T_j) (dW/dr)(r_ij) / r_ij V_j over the pairs "
                                             "(each pair adds to i and, with the opposite sign and V_i, to j)",
                                   rate="T_dot = a lap T + source (a per particle); no boundary term (free edges "
                                        "carry no flux)"))


def _triangle_circumradius(P: np.ndarray) -> np.ndarray:
    """R = abc / (4 area) of triangles P (m, 3, 2)."""
    a, b, c = (np.linalg.norm(P[:, k] - P[:, (k + 1) % 3], axis=1) for k in range(3))
    e1, e2 = P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    with np.errstate(divide="ignore"):
        return a * b * c / (4 * area)


def _surface_case(root):
    from scipy.spatial import Delaunay

    dp = 1e-4
    h = 1.3 * dp
    X, rng = _block(nx=16, ny=10, dp=dp, seed=17)
    Ly, xc, half, depth = 10 * dp, 8 * dp, 4 * dp, 5 * dp      # a V-notch from the top face, 8 dp wide, 5 dp deep
    notch = (np.abs(X[:, 0] - xc) < half) & (X[:, 1] > Ly - depth * (1 - np.abs(X[:, 0] - xc) / half))
    x = X[~notch] + 0.05 * dp * rng.uniform(-1, 1, (np.count_nonzero(~notch), 2))
    V = np.full(len(x), dp * dp)
    K = get_kernel("wendland")
    threshold, alpha = 0.75, 1.3
    lam = moment_min_eigenvalue(x, V, h, K)
    sph = surface_sph(x, V, h, K, threshold)
    alpha_shape = surface_alpha_shape(x, dp, alpha)
    R = _triangle_circumradius(x[Delaunay(x).simplices]) / (alpha * dp)
    return _write(root, "surface_notch", "the two free-surface detectors on a 2D block with a V-notch in its top "
                  "face (positions perturbed by 5 % of dp, so that the Delaunay triangulation is unique)",
                  "Marrone et al. 2010 (lambda_min of the moment matrix, threshold 0.75); the alpha-shape "
                  "(Edelsbrunner & Muecke 1994), alpha = 1.3",
                  dict(x=x, V=V, h=np.float64(h), dp=np.float64(dp), threshold=np.float64(threshold),
                       alpha=np.float64(alpha)),
                  dict(lambda_min=lam, surface_sph=sph.astype(np.int64), surface_alpha=alpha_shape.astype(np.int64)),
                  dict(x="m", V="m^2", h="m", dp="m", threshold="1", alpha="1", lambda_min="1",
                       surface_sph="1 (mask 0/1)", surface_alpha="1 (mask 0/1)"),
                  dict(lambda_min=1e-10, surface_sph=0.0, surface_alpha=0.0),
                  "lambda_min: a pair sum and a closed-form eigenvalue, round-off only; the masks (1 on the surface) "
                  "must agree exactly: no particle lies near a threshold (margins below)",
                  kind="surface", kernel="wendland (support 2h)",
                  meaning=dict(dp="initial particle spacing (the alpha-shape's length unit)"),
                  conventions=dict(kernel=KERNEL_TEXT["wendland"],
                                   moment_matrix="M_i = - sum_j V_j x_ij (x) grad_i W_ij over the neighbours within "
                                                 "2h (symmetrised); lambda_min its smallest eigenvalue; "
                                                 "lambda_min <= threshold marks the SPH surface",
                                   alpha_shape="Delaunay triangles with circumradius <= alpha dp are kept and the "
                                               "vertices of the edges that only one kept triangle has are the "
                                               "alpha-shape surface"),
                  margins=dict(lambda_min_to_threshold=float(np.min(np.abs(lam - threshold))),
                               circumradius_over_alpha_dp_to_1=float(np.min(np.abs(R - 1.0)))),
                  counts=dict(particles=len(x), surface_sph=int(sph.sum()), surface_alpha=int(alpha_shape.sum())))


def _penalty_friction_case(root):
    """The penalty contact (refsph.penalty, issue 22) of particles around a cutting edge: a wedge rounded by 20 um,
    particles inside and outside the core and the fillet, sliding and sticking, hot and cold, with a random
    committed tangential history."""
    rng = np.random.default_rng(22)
    wedge = [[0.0, 0.0], [1e-3, 0.0], [1e-3, 0.6e-3], [0.25e-3, 0.6e-3]]
    tool = RoundedPolygon.from_polygon(wedge, 20e-6, [0.5e-3, 0.3e-3])
    n = 40
    x = np.stack([rng.uniform(-40e-6, 60e-6, n), rng.uniform(-40e-6, 60e-6, n)], axis=1)
    v = rng.normal(0.0, 2.0, (n, 2))
    m = np.full(n, 7850.0 * 1e-10)
    T = rng.uniform(293.0, 1900.0, n)
    xi = rng.normal(0.0, 8e-6, (n, 2))                          # some within the cone, some beyond it
    t = AISI1045_RLA
    law = CoulombFriction(mu0=t["mu0"], q=t["q_friction"], T_room=t["T_room_K"], T_melt=t["T_melt_K"])
    contact = PenaltyContact(alpha=0.1, damping=0.5, offset=5e-6, time_scale=2e-9, friction=law)
    shift, V, dt = np.array([0.5e-3, 0.3e-3]), np.array([-1.0, 0.0]), 1.5e-9
    c = penalty_contact(x, v, m, T, tool, shift, V, dt, contact, xi)
    out = dict(gap=c.gap, a=c.a, force_on_tool=c.force_on_tool, friction_power=c.friction_power, xi=c.xi,
               f_normal=c.f_normal, f_tangent=c.f_tangent)
    units = dict(x="m", v="m/s", m="kg/m", T="K", xi_in="m", core="m", radius="m", shift="m", V="m/s", dt="s",
                 alpha="1", damping="1", offset="m", time_scale="s", mu0="1", q="1", T_room="K", T_melt="K",
                 gap="m", a="m/s^2", force_on_tool="N/m", friction_power="W/m", xi="m", f_normal="N/m",
                 f_tangent="N/m")
    on = c.gap > 0
    f_trial = np.linalg.norm(c.f_trial, axis=1)             # the stick/slip switch: |f*| against mu f_N
    limit = law.mu(T) * c.f_normal
    rubbing = on & (limit > 0)
    margin = float(np.min(np.abs(f_trial[rubbing] / limit[rubbing] - 1.0))) if rubbing.any() else None
    return _write(root, "penalty_friction", "penalty contact on a rounded wedge (exact geometry) with Coulomb "
                  "friction mu(T) as a return map on a tangential spring: particles in the core, on the faces and "
                  "around the fillet, sticking and sliding", "refsph/penalty.py (issue 22); mu(T) of the second "
                  "paper's Eqs. (10)-(11)",
                  dict(x=x, v=v, m=m, T=T, xi_in=xi, core=np.asarray(tool.core), radius=np.float64(tool.radius),
                       shift=shift, V=V, dt=np.float64(dt), alpha=np.float64(contact.alpha),
                       damping=np.float64(contact.damping), offset=np.float64(contact.offset),
                       time_scale=np.float64(contact.time_scale), mu0=np.float64(law.mu0), q=np.float64(law.q),
                       T_room=np.float64(law.T_room), T_melt=np.float64(law.T_melt)),
                  out, units, {k: 1e-12 for k in out}, "closed forms per particle: round-off only",
                  counts=dict(particles=n, in_contact=int(on.sum()),
                              sliding=int(np.count_nonzero(c.friction_power > 0))),
                  margins=dict(trial_friction_over_mu_f_normal_to_1=margin), kind="penalty",
                  rows=dict(core="vertex", shift="component", V="component", force_on_tool="component"),
                  meaning=dict(V="tool velocity", m="particle mass", T="particle temperature",
                               a="acceleration of each particle from the contact",
                               force_on_tool="total force on the tool (the reaction)",
                               alpha="fraction of the penetration the spring removes per time_scale"),
                  conventions=dict(
                      geometry="core vertices relative to shift (the tool particles' centroid), counter-clockwise; "
                               "the tool is the core grown by radius",
                      gap="gap = offset - d, d = dist(x, core + shift) - radius outside the core, -min_k (distance "
                          "to edge line k) - radius inside; n the outward unit normal at the nearest surface point",
                      normal_force="f_N = m (alpha gap / tau^2 - beta v_n / tau) clipped at 0, tau = time_scale, "
                                   "beta = 2 damping sqrt(alpha), v_n = (v - V) . n",
                      friction="xi* = P(xi_in) + v_t dt (P: projection on the tangent plane), f* = -k xi*, k = "
                               "alpha m / tau^2; stick where |f*| <= mu(T) f_N (f_t = f*, xi = xi*), else slip "
                               "(f_t = mu f_N f* / |f*|, xi = -f_t / k); mu(T) = mu0 (1 - T*^q), T* clipped to "
                               "[0, 1]; friction_power = |f_t| (|xi*| - |xi|) / dt",
                      force="a = (f_N n + f_t) / m per particle, force_on_tool = -sum over the particles of (f_N n + "
                            "f_t); see refsph/penalty.py"))


def _pinball_friction_case(root):
    dp = 1e-4
    h = 1.5 * dp
    rng = np.random.default_rng(20)
    xa = lattice([10 * dp, 3 * dp], dp) + 0.02 * dp * rng.normal(size=(30, 2))
    xb = np.stack([np.arange(-1, 11) * dp + 0.5 * dp, np.full(12, -0.48 * dp)], axis=1)   # below the bottom row
    slide = 10.0 ** rng.uniform(-2, 1.3, len(xa))          # 1 cm/s to 20 m/s: pairs that stick, pairs that slide
    va = np.stack([slide, -0.05 + rng.normal(0, 0.02, len(xa))], axis=1)  # approaching at ~5 cm/s: sliding needs
    vb = np.stack([np.zeros(12), rng.normal(0, 0.01, 12)], axis=1)        # |v_t| > mu K_p pdot_d (Eqs. (33)-(34))
    T_a = rng.uniform(293.0, 1900.0, len(xa))                   # room temperature to above T_melt (mu = 0 there)
    ma = np.full(len(xa), MAT.rho0 * dp * dp)
    mb = np.full(len(xb), MAT.rho0 * dp * dp)
    t = AISI1045_RLA
    law = CoulombFriction(mu0=t["mu0"], q=t["q_friction"], T_room=t["T_room_K"], T_melt=t["T_melt_K"])
    c = PinballContact(k=dp / (2 * h), K_p=50.0, friction=law)
    R = c.k * h
    dt = 1e-8
    out = {}
    for tag, m_b, mu_b in (("rigid", np.inf, np.inf), ("deformable", mb, MAT.G)):
        r = pinball_contact(xa, va, ma, xb, vb, m_b, R, MAT.G, mu_b, dt, c, thickness=dp, T_a=T_a)
        out.update({f"a_{tag}": r.a, f"force_on_b_{tag}": r.force_on_b, f"friction_power_a_{tag}": r.friction_power_a,
                    f"friction_power_b_{tag}": r.friction_power_b})
    units = dict(x_a="m", v_a="m/s", m_a="kg/m", x_b="m", v_b="m/s", m_b="kg/m", T_a="K", R="m", G="Pa", dt="s",
                 K_p="1", thickness="m", mu0="1", q="1", T_room="K", T_melt="K")
    units.update({k: ("m/s^2" if k.startswith("a_") else "N/m" if k.startswith("force") else "W/m") for k in out})
    return _write(root, "pinball_friction", "pinball contact with Coulomb friction mu(T) of a 2D block sliding over "
                  "a row of particles below it (tangential speeds from 1 cm/s, where friction sticks, to 20 m/s; "
                  "temperatures up to above T_melt): rigid and deformable partners",
                  "Eqs. (32)-(36); friction mu(T) = mu0 (1 - T*^q), the second paper's Eqs. (10)-(11)",
                  dict(x_a=xa, v_a=va, m_a=ma, x_b=xb, v_b=vb, m_b=mb, T_a=T_a, R=np.float64(R), G=np.float64(MAT.G),
                       dt=np.float64(dt), K_p=np.float64(50.0), thickness=np.float64(dp), mu0=np.float64(law.mu0),
                       q=np.float64(law.q), T_room=np.float64(law.T_room), T_melt=np.float64(law.T_melt)),
                  out, units, {k: 1e-12 for k in out}, "closed forms per pair, summed per particle: round-off only "
                  "(against the rigid partner no pair lies within 8 % of the stick/slip switch)",
                  pairs="9 pairs in contact: 5 stick (the friction force is the cap), 4 slide (one of them above "
                        "T_melt, mu = 0)",
                  kind="pinball_friction", rows=dict(PINBALL_ROWS, T_a="particle of a",
                                                     **{k: f"particle of {k.split('_')[-2]}" for k in out
                                                        if k.startswith("friction_power")}),
                  meaning=dict(G="shear modulus mu of both bodies (Eq. (35))", **{
                      f"friction_power_{side}_{tag}": f"friction power |f_t| |v_t| of the pairs of each particle of "
                      f"{side} ({tag} partner)" for side in "ab" for tag in ("rigid", "deformable")}),
                  conventions=dict(PINBALL_CONVENTIONS, friction="tangential velocity v_t = v_ij - (v_ij . e) e, "
                                   "friction force min(mu(T_a) F, m_ij |v_t| / dt) against v_t, added to the normal "
                                   "force of the pair (the cap: no more than stops the sliding in one step); mu(T) = "
                                   "mu0 (1 - T*^q), T* = (T - T_room) / (T_melt - T_room) clipped to [0, 1]",
                                   friction_power="|f_t| |v_t| per pair, summed on each side (W per metre of width)"))


def _one_step(scene: str, method: str, args: dict, numerics: dict):
    """One step of the run loop of the CFL size dt (one output interval: the loop shortens a step to land on each
    output time). Returns (the run's result, dt)."""
    setup = get_scene(scene).setup(**{k: v for k, v in args.items() if k != "options"}, **args.get("options", {}))
    setup.numerics = replace(setup.numerics, **numerics)
    dt0 = cfl_time_step(setup.state, setup.material, setup.h, setup.numerics.courant)
    setup.t_end, setup.n_snapshots = dt0, 1
    res = simulate(setup, method, scene=get_scene(scene), progress=False)
    if res.summary["n_steps"] != 1:
        raise RuntimeError(f"{scene}: a step of the CFL size took {res.summary['n_steps']} steps (a smaller limit)")
    return res, dt0


LEAPFROG = dict(taylor=dict(dim=2, quick=True),
                thermal_cutting=dict(quick=True, options=dict(case=1, length=0.5e-3, travel=0.2)))


def _leapfrog_cases(root):
    """The leapfrog (kick-drift-kick, :class:`refsph.integrate.Leapfrog`): one step and a short run of the Taylor
    bar (both methods), and of the thermomechanical cut (TLSPH; its own integrator): contact, friction, heat."""
    names = []
    numerics = dict(integrator="leapfrog", threads=1)
    for scene, args in LEAPFROG.items():
        options = args.get("options", {})
        setup = get_scene(scene).setup(**{k: v for k, v in args.items() if k != "options"}, **options)
        tag = "_leapfrog" if scene == "taylor" else ""
        for method in ("esph", "tlsph") if scene == "taylor" else ("tlsph",):
            res, dt0 = _one_step(scene, method, args, numerics)
            names.append(_write_scene(
                root, f"step_{method}_{scene}{tag}", f"one leapfrog step of the whole {scene} scene "
                f"({method.upper()}, quick)", "all of the method's equations, the boundaries, the return map"
                + (", conduction, friction heat, surface losses" if scene == "thermal_cutting" else ""),
                _scene_case(setup, numerics, dt0, n_snapshots=1),
                dict(_state_arrays(res.state), t=np.float64(res.state.t)),
                {k: 1e-10 for k in STATE_KEYS + ("t",)}, ROUND_OFF, "step", scene=scene, scene_args=args, method=method,
                numerics=numerics, dt=dt0, n_steps=res.summary["n_steps"],
                step="kick (dt/2) - drift - kick (dt/2), one step of the CFL size dt: the run loop with t_end = dt "
                     "and one output interval (its default of 10 would cut the step into 10)"))
            if scene == "taylor":
                t_end = 40 * 0.3 * setup.h / (setup.material.c_longitudinal + 200.0)    # about 40 steps
                what, tol, why = "about 40 CFL steps", 1e-6, ("40 steps amplify round-off (the pinball switch of "
                                                              "Eq. (34) most): 1e-6 of the largest value")
            else:
                t_end = setup.t_end
                what, tol, why = ("the whole quick cut, 0.2 t_u of travel: about 320 steps (40 would end "
                                  "before the chip meets the rake face)", 1e-6,
                                  "320 steps of contact with friction amplify round-off (the pinball switch of "
                                  "Eq. (34), the stick/slip switch of friction): 1e-6 of the largest value")
            res = run(scene, method, progress=False, numerics=numerics, t_end=t_end, **args)
            extra = {"heat_balance": res.summary["heat_balance"]} if "heat_balance" in res.summary else {}
            names.append(_write_scene(
                root, f"run_{scene}_{method}{tag}", f"a short leapfrog run of the {scene} scene at quick resolution "
                f"({method.upper()}, {what}): the final state and the metrics", "all",
                _scene_case(setup, numerics, t_end), dict(_state_arrays(res.state), t=np.float64(res.state.t)),
                {k: tol for k in STATE_KEYS + ("t",)}, why, "run", scene=scene, scene_args=args, method=method,
                numerics=numerics, t_end=t_end, n_steps=res.summary["n_steps"],
                metrics={k: v for k, v in res.summary["metrics"].items() if np.ndim(v) == 0}, **extra))
    return names


# The whole runs whose metrics tests/test_taylor.py, test_pressing.py and test_cutting.py compare with (their
# regression values): the scene, its arguments, the metrics and each one's tolerance per method, and why.
_PINBALL_WHY = ("TLSPH is not reproducible to 1e-4 across machines: with K_p = 50 the on/off switch of the pinball "
                "force (Eq. (34)) amplifies round-off (a 1e-13 dp shift of the particles moves the pressing's max "
                "plastic strain by 2.5 %, its strain line by 1 %, its mean force by 0.2 %; chapter 07; summing the "
                "artificial viscosity in another order moved the mean tool force by 1.0 % and the max plastic strain "
                "by 1.9 %): integral quantities (force means) at 2 %, local ones (maxima, peaks, the strain line as "
                "a relative L2 difference) at 5 %. ESPH at 1e-4 (the strain line: |d| <= 1e-4 |ref| + 1e-6 per "
                "point)")
METRIC_RUNS = {
    "taylor_3d_1mm": dict(
        scene="taylor", args=dict(dim=3, dp=1.0e-3), what="the 3D Taylor bar at dp = 1 mm (4 particles across the "
        "radius), the whole impact (80 us)", units=dict(final_length_mm="mm", final_diameter_mm="mm",
                                                        max_plastic_strain="1", max_temperature_K="K"),
        tolerance=dict(esph=1e-4, tlsph=1e-4), why="a whole run of a bar that comes to rest: 1e-4 (both methods)"),
    "pressing_quick": dict(
        scene="pressing", args=dict(quick=True), what="the quick pressing run (dp = 1/60 mm, 0.2 mm of tool travel)",
        units=dict(tool_force_peak_N_per_m="N/m", tool_force_mean_N_per_m="N/m", clamp_force_mean_N_per_m="N/m",
                   max_plastic_strain="1", max_temperature_K="K", plastic_strain_line_eps_p="1"),
        tolerance=dict(esph=1e-4, tlsph=dict(tool_force_mean_N_per_m=0.02, clamp_force_mean_N_per_m=0.02,
                                             tool_force_peak_N_per_m=0.05, max_plastic_strain=0.05,
                                             max_temperature_K=0.05, plastic_strain_line_eps_p=0.05)),
        measure=dict(esph=dict(plastic_strain_line_eps_p=dict(kind="pointwise", floor=1e-2)),
                     tlsph=dict(plastic_strain_line_eps_p=dict(kind="l2"))), why=_PINBALL_WHY),
    "cutting_coarse": dict(
        scene="cutting", args=dict(dp=0.05e-3, options=dict(travel=0.2e-3)), what="the cutting run at dp = 0.05 mm, "
        "0.2 mm of cut", units=dict(cutting_force_mean_N_per_m="N/m", thrust_force_mean_N_per_m="N/m",
                                   max_temperature_K="K", max_plastic_strain="1"),
        tolerance=dict(esph=1e-4, tlsph=dict(cutting_force_mean_N_per_m=0.02, thrust_force_mean_N_per_m=0.02,
                                             max_temperature_K=0.05, max_plastic_strain=0.05)), why=_PINBALL_WHY),
}


# The metrics' definitions (refsph/scenes/<scene>.py, _metrics / cutting_metrics); "time mean over the second half":
# sum(f dt) / sum(dt) over the steps of the reaction history with t > t_end / 2 (refsph.scenes.measure.time_mean)
METRIC_MEANING = dict(
    final_length_mm="final length of the bar, max z - min z of the particle centres plus one spacing dz, in mm: the "
    "mean over the last 30 us once the bar is at rest (its plastic work at 99.5 % of the final), else at the end",
    final_diameter_mm="final diameter of the impact face, 2 (max r + dr/2) over all particles (r = sqrt(x^2 + y^2)), "
    "in mm, over the same window as the length",
    max_plastic_strain="largest plastic strain of any particle at the end", max_temperature_K="highest temperature "
    "of any particle at the end",
    tool_force_peak_N_per_m="peak of the tool force (block on tool, +x) binned into 400 equal time means",
    tool_force_mean_N_per_m="time mean over the second half of the run of the tool force (block on tool, +x)",
    clamp_force_mean_N_per_m="time mean over the second half of the run of the force of the block on its clamped "
    "column (+x)", plastic_strain_line_eps_p="plastic strain along the scene's line (input scene_line_index), "
    "point by point", cutting_force_mean_N_per_m="time mean over the second half of the run of the force of the "
    "workpiece on the tool along +x (against the cut)", thrust_force_mean_N_per_m="time mean over the second half "
    "of the run of the force of the workpiece on the tool along +y (pushing it away from the workpiece)")


def _metric_arrays(spec: dict, metrics: dict) -> dict:
    """The metrics of a METRIC_RUNS entry as arrays (the pressing's strain line: its eps_p column)."""
    return {k: (np.asarray(metrics["plastic_strain_line"], dtype=float)[:, 1] if k == "plastic_strain_line_eps_p"
                else np.float64(metrics[k])) for k in spec["units"]}


def _metric_case(root, key: str, method: str) -> str:
    spec = METRIC_RUNS[key]
    setup = get_scene(spec["scene"]).setup(**{k: v for k, v in spec["args"].items() if k != "options"},
                                           **spec["args"].get("options", {}))
    res = run(spec["scene"], method, progress=False, numerics=dict(threads=1), **spec["args"])
    out = _metric_arrays(spec, res.summary["metrics"])
    tol = spec["tolerance"][method]
    tol = {k: tol for k in out} if np.isscalar(tol) else tol
    scene = _scene_case(setup, dict(threads=1), setup.t_end)
    scene[1]["units"].update(spec["units"])
    scene[1]["meaning"].update({k: METRIC_MEANING[k] for k in out})
    scene[1]["rows"].update(plastic_strain_line_eps_p="point")
    return _write_scene(root, f"metrics_{key}_{method}", f"{spec['what']} ({method.upper()}): its metrics", "all",
                        scene, out, tol, spec["why"], "metrics", measure=spec.get("measure", {}).get(method, {}),
                        scene=spec["scene"], scene_args=spec["args"], method=method, n_steps=res.summary["n_steps"],
                        regression="compared with the scene test's own run: tests/test_" + spec["scene"] + ".py")


def metric_rows(case_dir, metrics: dict) -> list[Row]:
    """A run's summary ``metrics`` against the ``metrics_*`` golden case in ``case_dir``, each within its tolerance
    (the regression check of the scene tests)."""
    case_dir = Path(case_dir)
    key = next(k for k in METRIC_RUNS if case_dir.name.startswith(f"metrics_{k}_"))
    return compare_case(case_dir, _metric_arrays(METRIC_RUNS[key], metrics))


# The metrics of the cutting scene that depend chaotically on details (the pinball's on/off switch, which particle
# reaches the edge first): their run-to-run scatter, measured by benchmarks/metric_scatter.py on runs whose
# workpiece particles are moved at random by SCATTER_JITTER dx, is kept beside the golden case in scatter.json
# (golden/FORMAT.md) and refsph compare takes the tolerance of such a metric from there
# (refsph.crosscheck.compare.scatter_tolerances). The rule:
SCATTER_K = 2.0
SCATTER_JITTER = 0.01
SCATTER_METRICS = ("cutting_force_mean_N_per_m", "thrust_force_mean_N_per_m", "chip_thickness_mm", "n_shear_bands")
SCATTER_RULE = (f"tolerance = k x the largest relative deviation of a perturbed run from the reference value "
                f"(|v_i - v_ref| / |v_ref|), k = {SCATTER_K:g}; refsph compare uses the larger of it and case.json's "
                "own tolerance")


def spread(values, reference=None) -> dict:
    """The spread of one metric over perturbed runs: ``n`` (runs that measured it: None and nan are runs that
    could not), ``mean``, sample ``std``, ``max_deviation`` (max |v - mean|); with a finite ``reference`` also
    ``max_deviation_from_reference`` (max |v - reference|), it relative to |reference|, and the ``tolerance`` of
    :data:`SCATTER_RULE` (None where the reference is 0 or not finite, or fewer than two runs measured it)."""
    v = np.array([np.nan if x is None else x for x in values], dtype=float)
    v = v[np.isfinite(v)]
    out = dict(values=[float(x) for x in v], n=int(len(v)), runs=len(values), mean=None, std=None,
               max_deviation=None, reference=None if reference is None else float(reference),
               max_deviation_from_reference=None, relative_max_deviation=None, tolerance=None)
    if len(v) >= 2:
        out.update(mean=float(v.mean()), std=float(v.std(ddof=1)), max_deviation=float(np.max(np.abs(v - v.mean()))))
    ref = np.nan if reference is None else float(reference)
    if len(v) >= 2 and np.isfinite(ref):
        dev = float(np.max(np.abs(v - ref)))
        out.update(max_deviation_from_reference=dev)
        if ref != 0:
            out.update(relative_max_deviation=dev / abs(ref), tolerance=SCATTER_K * dev / abs(ref))
    return out


def scatter_document(case_dir, unperturbed: dict, perturbed: dict, **about) -> dict:
    """The content of ``<case>/scatter.json`` for a ``metrics_*`` golden case: the spread (:func:`spread`) of the
    sensitive metrics (:data:`SCATTER_METRICS`) and the case's own over the perturbed runs (``perturbed``: {seed:
    the run's summary metrics}) around the reference (the case's output where it holds the metric, else the
    unperturbed run's value, ``unperturbed``), and ``tolerance`` for the sensitive ones where the rule gives one;
    ``about``: what else to say (jitter, dp, length of cut, ...)."""
    case_dir = Path(case_dir)
    out_ref = read_npz(case_dir / "output.npz", "golden-case output")
    names = [k for k in dict.fromkeys(SCATTER_METRICS + tuple(out_ref)) if k in unperturbed]
    metrics = {k: spread([m.get(k) for m in perturbed.values()],
                         out_ref[k] if k in out_ref and np.ndim(out_ref[k]) == 0 else unperturbed[k]) for k in names}
    tolerance = {k: metrics[k]["tolerance"] for k in SCATTER_METRICS if k in metrics}
    return dict(case=case_dir.name, what="the run-to-run scatter of the case's metrics: the same run with the "
                "workpiece's particles moved at random by up to jitter x dx (one run per seed), against the "
                "reference (the case's output, or the unperturbed run for a metric the case does not hold)",
                written_by="benchmarks/metric_scatter.py", rule=SCATTER_RULE, k=SCATTER_K, **about,
                seeds=[int(s) for s in perturbed], metrics=metrics, tolerance=tolerance)


def _registry() -> list[tuple[tuple[str, ...], object]]:
    """(the case names, the function that writes them), in the order of index.json."""
    kernels = tuple(f"kernel_{k}_{d}d" for k in ("cubic", "wendland") for d in (2, 3))
    tlsph = tuple(f"tlsph_{m}_{c}" for m in ("affine", "rotation", "random") for c in ("corrected", "uncorrected"))
    steps = tuple(f"step_{m}_{s}" for s in ("taylor", "pressing") for m in ("esph", "tlsph"))
    runs = tuple(f"run_{s}_{m}" for s in SCENES for m in ("esph", "tlsph"))
    leapfrog = ("step_esph_taylor_leapfrog", "run_taylor_esph_leapfrog", "step_tlsph_taylor_leapfrog",
                "run_taylor_tlsph_leapfrog", "step_tlsph_thermal_cutting", "run_thermal_cutting_tlsph")
    groups = [(kernels, _kernel_cases), (tuple(ESPH_RATE_CASES) + ("esph_pair_terms",), _esph_cases),
              (tlsph, _tlsph_cases), (("return_map_johnson_cook", "return_map_modified"), _return_map_cases),
              (("pinball",), _pinball_case), (("pinball_pairs",), _pinball_pairs_case),
              (steps + runs, _step_and_run_cases), (("conduction",), _conduction_case),
              (("surface_notch",), _surface_case), (("pinball_friction",), _pinball_friction_case),
              (leapfrog, _leapfrog_cases), (("penalty_friction",), _penalty_friction_case)]
    for key in METRIC_RUNS:
        for method in ("esph", "tlsph"):
            groups.append(((f"metrics_{key}_{method}",), lambda root, k=key, m=method: _metric_case(root, k, m)))
    return groups


def case_names(only=None) -> list[str]:
    """Every golden case's name in order, or those matching one of the patterns ``only`` (as in 'metrics_*')."""
    names = [n for group, _ in _registry() for n in group]
    return names if not only else [n for n in names if any(fnmatch.fnmatchcase(n, p) for p in only)]


def generated_with() -> dict:
    """What decides the bytes beyond refsph (module text): the architecture, NumPy, SciPy, the C library."""
    libc = " ".join(platform.libc_ver()).strip()
    return dict(machine=platform.machine(), numpy=np.__version__, scipy=scipy.__version__, libc=libc or "unknown")


CHILD = "REFSPH_GOLDEN_PINNED"                  # set in the child process that computes the cases


def _dispatched_features() -> tuple[list, dict]:
    try:
        from numpy._core import _multiarray_umath as mu            # NumPy 2
    except ImportError:                                             # pragma: no cover - NumPy 1
        from numpy.core import _multiarray_umath as mu
    return list(mu.__cpu_dispatch__), dict(mu.__cpu_features__)


def pinned_environment(base: dict | None = None) -> dict:
    """``base`` (default os.environ) with NumPy's CPU dispatch, OpenBLAS's kernels and glibc's libm variants fixed to
    what every CPU of this architecture has (module text)."""
    env = dict(os.environ if base is None else base)
    env["NPY_DISABLE_CPU_FEATURES"] = " ".join(_dispatched_features()[0])
    core = {"x86_64": "Nehalem", "amd64": "Nehalem", "aarch64": "ARMV8", "arm64": "ARMV8"}.get(
        platform.machine().lower())
    if core:
        env["OPENBLAS_CORETYPE"] = core
    env.update(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1", MKL_CBWR="COMPATIBLE")
    others = [t for t in env.get("GLIBC_TUNABLES", "").split(":") if t and not t.startswith("glibc.cpu.hwcaps=")]
    env["GLIBC_TUNABLES"] = ":".join(["glibc.cpu.hwcaps=-AVX2,-FMA,-FMA4,-AVX512F"] + others)
    env[CHILD] = "1"
    return env


def _check_pinned() -> None:
    dispatch, features = _dispatched_features()
    on = [f for f in dispatch if features.get(f)]
    if on:
        raise RuntimeError(f"NumPy still dispatches to {', '.join(on)} (NPY_DISABLE_CPU_FEATURES ignored?): the golden "
                           "cases would depend on this CPU")


def _check_target(root: Path, only=None) -> set:
    """The cases to write (ValueError naming the patterns if none match), after refusing a directory that holds
    anything but golden cases: writing empties it (or the chosen cases' folders), and refsph deletes only what it
    wrote (a golden directory has its index.json)."""
    chosen = set(case_names(only))
    if not chosen:
        raise ValueError(f"no golden case matches {' '.join(only)} (the cases: {', '.join(case_names())})")
    if root.exists() and (not root.is_dir() or (any(root.iterdir()) and not (root / "index.json").is_file())):
        raise ValueError(f"{root} exists and is not a golden-case directory (no index.json): refsph oracle writes "
                         "into a new or empty directory, or one it wrote before")
    return chosen


def _clear_case(folder: Path) -> None:
    """Remove what the generator writes in a case's folder; a stored scatter (``scatter.json``: measured by
    benchmarks/metric_scatter.py, minutes of runs, not by the generator) stays, and says itself when it is stale."""
    if not folder.is_dir():
        return
    for p in folder.iterdir():
        if p.name != SCATTER_FILE:
            shutil.rmtree(p) if p.is_dir() else p.unlink()


def _write_cases(root: Path, only=None) -> list[str]:
    _check_pinned()
    chosen = _check_target(root, only)
    if only is None and root.exists():                     # what refsph wrote: the cases and index.json; the
        for case in root.iterdir():                         # rest (golden/FORMAT.md, the spec) stays
            if case.is_dir() and (case / "case.json").is_file():
                _clear_case(case)
        (root / "index.json").unlink(missing_ok=True)
    for name in chosen:
        _clear_case(root / name)
    root.mkdir(parents=True, exist_ok=True)
    for group, write in _registry():
        if chosen & set(group):                             # a group's cases are computed together, all written
            written = write(root)
            written = [written] if isinstance(written, str) else written
            assert list(written) == list(group), (written, group)
    index = dict(format_version=FORMAT_VERSION, format="golden/FORMAT.md", format_changes=FORMAT_CHANGES,
                 refsph_version=__version__, cases=case_names(), generated_with=generated_with(),
                 conventions=COMMON_CONVENTIONS,
                 compare="refsph compare DIR YOUR_DIR: every output array within its case's tolerance, relative to "
                         "the largest value of the reference array")
    (root / "index.json").write_text(json.dumps(index, indent=1) + "\n")
    return written_names(only)


def written_names(only=None) -> list[str]:
    """The cases that writing ``only`` writes: those chosen and their group-mates (computed together), in order."""
    chosen = set(case_names(only))
    done = {n for group, _ in _registry() if chosen & set(group) for n in group}
    return [n for n in case_names() if n in done]


def write_golden_cases(directory, only=None) -> list[str]:
    """Write the golden cases into ``directory`` and an ``index.json`` (of every case); returns the names written
    (with ``only``, a chosen case's group-mates too: cases computed together are written together).
    Without ``only`` the cases there are deleted first (a FORMAT.md or other notes stay) and every case written
    (the ``metrics_*`` cases run whole scenes: minutes); ``only``: the cases matching these patterns, the others
    kept. The cases are computed in a child process with :func:`pinned_environment` (module text: the bytes do
    not depend on the CPU)."""
    if os.environ.get(CHILD) == "1":
        return _write_cases(Path(directory), only)
    _check_target(Path(directory), only)                   # bad input is said here, not in the child's traceback
    Path(directory).mkdir(parents=True, exist_ok=True)     # (an unwritable place: OSError naming it, here)
    cmd = [sys.executable, "-m", "refsph.crosscheck.golden", str(directory)] + (["--only", *only] if only else [])
    child = subprocess.run(cmd, env=pinned_environment(), capture_output=True, text=True)
    if child.returncode != 0:
        last = (child.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise RuntimeError(f"writing the golden cases into {directory} failed in the pinned child process: {last}")
    return written_names(only)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m refsph.crosscheck.golden", description="write the golden cases "
                                 "(as refsph oracle DIR)")
    ap.add_argument("dir")
    ap.add_argument("--only", nargs="+", default=None, metavar="CASE", help="cases to write (names or patterns)")
    args = ap.parse_args(argv)
    names = write_golden_cases(args.dir, args.only)
    if os.environ.get(CHILD) != "1":
        print(f"{len(names)} golden cases in {args.dir}: {', '.join(names)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
