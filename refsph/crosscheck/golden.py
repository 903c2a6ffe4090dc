"""Golden cases: small, versioned inputs with refsph's outputs, for checking another backend (``refsph oracle DIR``).

Each case is a folder ``DIR/<case>/`` with

* ``input.npz``  -- what a backend needs to compute the case (arrays, SI units);
* ``output.npz`` -- refsph's result;
* ``case.json``  -- what the case is, the equations it exercises, every array (shape, unit, meaning), the scene or
  parameters, and ``tolerance``: {array: relative tolerance} with ``why`` (errors are measured as
  max |test - ref| / max |ref| per array unless ``measure`` names another error for an array, see
  :mod:`refsph.crosscheck.compare`).

``DIR/index.json`` lists the cases with the refsph version, the format version and the software that wrote them
(``generated_with``). The cases:

| case | what | equations |
|---|---|---|
| kernel_{cubic,wendland}_{2d,3d} | W, dW/dr and grad W at given r and x_ij | Eq. (9), Wendland C2 |
| esph_rates | ESPH rates of a perturbed 2D block with free surfaces, given half pairs | Eqs. (10)-(14), (20)-(24) |
| tlsph_{affine,rotation,random}_{corrected,uncorrected} | F, J, P, l, rates of a 2D block | Eqs. (2), (16)-(24) |
| return_map_{johnson_cook,modified} | return map of trial stresses (elastic, yielding, fast, hot) | Eqs. (25)-(31) |
| pinball | contact forces against a rigid and a deformable partner | Eqs. (32)-(36) |
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
from dataclasses import replace
from pathlib import Path

import numpy as np
import scipy

from .. import __version__
from ..contact import CoulombFriction, PinballContact, pinball_contact
from ..esph import ESPHParams, esph_rates
from ..integrate import cfl_time_step
from ..io import json_ready
from ..kernels import get_kernel
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
from .compare import Row, compare_case

__all__ = ["write_golden_cases", "case_names", "pinned_environment", "generated_with", "metric_rows", "METRIC_RUNS",
           "FORMAT_VERSION"]

FORMAT_VERSION = 1
ROUND_OFF = ("summed over pairs in another order, a sum of O(10) terms of mixed sign loses a few digits; 1e-10 "
             "of the largest value leaves room for that and catches any real difference")
MAT = aisi4340_material()


def savez_fixed(path: Path, **arrays) -> None:
    """np.savez with fixed zip timestamps, so that the same arrays always give the same bytes."""
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_STORED) as z:
        for name, a in arrays.items():
            info = zipfile.ZipInfo(name + ".npy", date_time=(1980, 1, 1, 0, 0, 0))
            with z.open(info, "w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asanyarray(a), allow_pickle=False)


def _write(root: Path, name: str, what: str, equations: str, inputs: dict, outputs: dict, units: dict,
           tolerance: dict, why: str, **extra) -> str:
    missing = sorted(set(outputs) - set(tolerance))
    if missing:
        raise ValueError(f"golden case {name}: no tolerance stated for {', '.join(missing)}")
    folder = root / name
    folder.mkdir(parents=True, exist_ok=True)
    savez_fixed(folder / "input.npz", **inputs)
    savez_fixed(folder / "output.npz", **outputs)
    arrays = {f"{side}/{k}": dict(shape=list(np.shape(v)), unit=units.get(k, "-"))
              for side, d in (("input", inputs), ("output", outputs)) for k, v in d.items()}
    case = dict(name=name, what=what, equations=equations, arrays=arrays, tolerance=tolerance, why=why, **extra)
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
                dict(W=1e-12, dW_dr=1e-12, grad_W=1e-12), "closed forms: only the last digits may differ"))
    return names


def _block(nx=12, ny=10, dp=1e-4, seed=7):
    rng = np.random.default_rng(seed)
    X = lattice([nx * dp, ny * dp], dp)
    return X, rng


def _esph_case(root):
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
    r = esph_rates(st, MAT, prm, I, J)
    return _write(root, "esph_rates", "ESPH rates of a perturbed 2D block (free surfaces all round), plane strain",
                  "Eqs. (10)-(14), (20)-(24)",
                  dict(x=st.x, v=st.v, m=st.m, rho=st.rho, S=st.S, S_zz=st.S_zz, I=I, J=J),
                  dict(rho_dot=r.rho, v_dot=r.v, S_dot=np.array(r.S), S_zz_dot=r.S_zz, l=np.array(r.l)),
                  dict(x="m", v="m/s", m="kg/m", rho="kg/m^3", S="Pa", S_zz="Pa", rho_dot="kg/m^3/s", v_dot="m/s^2",
                       S_dot="Pa/s", S_zz_dot="Pa/s", l="1/s", I="index", J="index"),
                  {k: 1e-10 for k in ("rho_dot", "v_dot", "S_dot", "S_zz_dot", "l")}, ROUND_OFF,
                  material=dict(rho0=MAT.rho0, E=MAT.E, nu=MAT.nu),
                  params=dict(h=prm.h, dp=dp, beta1=1.5, beta2=1.5, gamma=0.3, n_ap=4.0, eps=0.01, kernel="cubic"),
                  pairs="half pairs I < J within 2h, as find_pairs gives them")


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
                dict(X=X, V0=V, x=x, v=v, m=st.m, S=S, S_zz=S_zz, I=op.I, J=op.J),
                dict(F=np.array(out["F"]), J_det=out["J"], P=np.array(out["P"]), l=np.array(out["l"]), v_dot=r.v,
                     S_dot=np.array(r.S), S_zz_dot=r.S_zz),
                dict(X="m", V0="m^2", x="m", v="m/s", m="kg/m", S="Pa", S_zz="Pa", F="1", J_det="1", P="Pa",
                     l="1/s", v_dot="m/s^2", S_dot="Pa/s", S_zz_dot="Pa/s", I="index", J="index"),
                {k: 1e-10 for k in ("F", "J_det", "P", "l", "v_dot", "S_dot", "S_zz_dot")}, ROUND_OFF,
                material=dict(rho0=MAT.rho0, E=MAT.E, nu=MAT.nu),
                params=dict(h=prm.h, beta1=1.5, beta2=1.5, eps=0.01, kernel="cubic", corrected=corrected),
                pairs="half pairs I < J of the reference configuration X within 2h"))
    return names


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
            dict(S_trial=S, eps_p=eps_p, eps_dot=eps_dot, T=T, rho=rho, G=np.float64(MAT.G)),
            dict(S=S_n, d_eps_p=deps, d_w_p=dw, d_T=dT),
            dict(S_trial="Pa", S="Pa", eps_p="1", eps_dot="1/s", T="K", rho="kg/m^3", G="Pa", d_eps_p="1",
                 d_w_p="J/m^3", d_T="K"),
            dict(S=1e-12, d_eps_p=1e-12, d_w_p=1e-12, d_T=1e-12), "closed forms per particle: round-off only",
            law=dict(model=type(law).__name__, **consts),
            conventions="ln(max(eps_dot/eps_dot_0, 1)); T* clipped to [0, 1]; flow stress with the start values"))
    return names


def _pinball_case(root):
    dp = 1e-4
    h = 1.5 * dp
    rng = np.random.default_rng(5)
    xa = lattice([6 * dp, 4 * dp], dp) + 0.02 * dp * rng.normal(size=(24, 2))
    xb = np.stack([np.arange(-1, 7) * dp + 0.5 * dp, np.full(8, -0.5 * dp + 0.1 * dp)], axis=1)
    va = rng.normal(0, 1, xa.shape) - [0.0, 5.0]
    vb = np.zeros_like(xb)
    ma = np.full(len(xa), MAT.rho0 * dp * dp)
    c = PinballContact(k=dp / (2 * h), K_p=50.0)
    R = c.k * h
    dt = 1e-8
    rigid = pinball_contact(xa, va, ma, xb, vb, np.inf, R, MAT.G, np.inf, dt, c, thickness=dp)
    mb = np.full(len(xb), MAT.rho0 * dp * dp)
    soft = pinball_contact(xa, va, ma, xb, vb, mb, R, MAT.G, MAT.G, dt, c, thickness=dp)
    return _write(root, "pinball", "pinball contact of a 2D block against a row of particles below it: rigid (m_b, "
                  "mu_b infinite) and deformable partners", "Eqs. (32)-(36)",
                  dict(x_a=xa, v_a=va, m_a=ma, x_b=xb, v_b=vb, m_b=mb, R=np.float64(R), G=np.float64(MAT.G),
                       dt=np.float64(dt), K_p=np.float64(50.0), thickness=np.float64(dp)),
                  dict(a_rigid=rigid.a, force_on_b_rigid=rigid.force_on_b, a_deformable=soft.a,
                       force_on_b_deformable=soft.force_on_b),
                  dict(x_a="m", v_a="m/s", m_a="kg/m", x_b="m", v_b="m/s", m_b="kg/m", R="m", G="Pa", dt="s",
                       thickness="m", a_rigid="m/s^2", force_on_b_rigid="N/m", a_deformable="m/s^2",
                       force_on_b_deformable="N/m"),
                  dict(a_rigid=1e-12, force_on_b_rigid=1e-12, a_deformable=1e-12, force_on_b_deformable=1e-12),
                  "closed forms per pair, summed per particle: round-off only",
                  conventions="penetration rate -(v_i - v_j).e_ij; reduced mass m_i m_j/(m_i + m_j) (m_i against a "
                              "rigid partner); 2D Hertz force divided by the thickness dp; see refsph/contact.py")


STATE_KEYS = ("x", "v", "rho", "S", "S_zz", "eps_p", "T")
SCENES = dict(taylor=dict(dim=2, quick=True), pressing=dict(quick=True), cutting=dict(quick=True))


def _state_arrays(s) -> dict:
    return {k: np.asarray(getattr(s, k)) for k in STATE_KEYS if getattr(s, k) is not None}


def _step_and_run_cases(root):
    names = []
    units = dict(x="m", v="m/s", rho="kg/m^3", S="Pa", S_zz="Pa", eps_p="1", T="K", t="s")
    for scene, args in (("taylor", SCENES["taylor"]), ("pressing", SCENES["pressing"])):
        setup = get_scene(scene).setup(**args)
        for method in ("esph", "tlsph"):
            dt0 = cfl_time_step(setup.state, setup.material, setup.h, setup.numerics.courant)
            res = run(scene, method, progress=False, numerics=dict(threads=1), t_end=dt0, **args)
            names.append(_write(
                root, f"step_{method}_{scene}", f"one CFL step's time of the whole {scene} scene ({method.upper()}, "
                "quick), in the run loop's steps: " + ("symmetry plane and rigid wall" if scene == "taylor"
                                                       else "clamped column and rigid tool"),
                "all of the method's equations, the boundaries, the return map",
                _state_arrays(setup.state), dict(_state_arrays(res.state), t=np.float64(res.state.t)), units,
                {k: 1e-10 for k in STATE_KEYS + ("t",)}, ROUND_OFF,
                scene=scene, scene_args=args, method=method, dt=dt0, n_steps=res.summary["n_steps"],
                step="the run loop with t_end = dt (the CFL step) and the scene's output intervals: the loop "
                     "shortens each step to land on the next output time, so it takes n_steps predictor-corrector "
                     "steps of dt / n_steps (the step_*_leapfrog cases take one whole step)"))
    for scene, args in SCENES.items():
        for method in ("esph", "tlsph"):
            setup = get_scene(scene).setup(**args)
            t_end = 40 * 0.3 * setup.h / (setup.material.c_longitudinal + 200.0)    # about 40 steps
            res = run(scene, method, progress=False, numerics=dict(threads=1), t_end=t_end, **args)
            names.append(_write(
                root, f"run_{scene}_{method}", f"a short run of the {scene} scene at quick resolution ({method.upper()}"
                ", about 40 CFL steps): the final state and the metrics", "all",
                _state_arrays(setup.state), dict(_state_arrays(res.state), t=np.float64(res.state.t)), units,
                {k: 1e-6 for k in STATE_KEYS + ("t",)},
                "40 steps amplify round-off (the pinball switch of Eq. (34) most): 1e-6 of the largest value",
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
                  dict(x="m", V="m^2", T="K", a="m^2/s", source="K/s", h="m", lap_T="K/m^2", T_dot="K/s", I="index",
                       J="index"),
                  dict(lap_T=1e-10, T_dot=1e-10), ROUND_OFF, kernel="wendland (support 2h)",
                  pairs="half pairs I < J within 2h, as find_pairs gives them",
                  conventions="lap T_i = sum_j 2 (T_i - T_j) (dW/dr)(r_ij) / r_ij V_j over the pairs (each pair adds "
                              "to i and, with the opposite sign and V_i, to j); T_dot = a lap T + source; no "
                              "boundary term (free edges carry no flux)")


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
                  dict(x="m", V="m^2", h="m", dp="m", threshold="1", alpha="1", lambda_min="1", surface_sph="bool",
                       surface_alpha="bool"),
                  dict(lambda_min=1e-10, surface_sph=0.0, surface_alpha=0.0),
                  "lambda_min: a pair sum and a closed-form eigenvalue, round-off only; the masks (1 on the surface) "
                  "must agree exactly: no particle lies near a threshold (margins below)",
                  kernel="wendland (support 2h)",
                  conventions="M_i = - sum_j V_j x_ij (x) grad_i W_ij (symmetrised), lambda_min <= threshold marks the "
                              "SPH surface; Delaunay triangles with circumradius <= alpha dp are kept and the vertices "
                              "of the edges that only one kept triangle has are the alpha-shape surface",
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
                  margins=dict(trial_friction_over_mu_f_normal_to_1=margin),
                  conventions="core vertices relative to shift (the tool particles' centroid), counter-clockwise; "
                              "gap = offset + radius - (signed distance to the core); the history xi_in is projected "
                              "on the tangent plane before v_t dt is added; see refsph/penalty.py")


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
                  conventions="as pinball; tangential velocity v_t = dv - (dv . e) e, friction force "
                              "min(mu(T_a) F_n, m_ij |v_t| / dt) against v_t (the cap: no more than stops the "
                              "sliding in one step); T* = (T - T_room)/(T_melt - T_room) clipped to [0, 1]; friction "
                              "power |f_t| |v_t| per pair, summed on each side (W per metre of width)")


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
    units = dict(x="m", v="m/s", rho="kg/m^3", S="Pa", S_zz="Pa", eps_p="1", T="K", t="s")
    numerics = dict(integrator="leapfrog", threads=1)
    for scene, args in LEAPFROG.items():
        options = args.get("options", {})
        setup = get_scene(scene).setup(**{k: v for k, v in args.items() if k != "options"}, **options)
        tag = "_leapfrog" if scene == "taylor" else ""
        for method in ("esph", "tlsph") if scene == "taylor" else ("tlsph",):
            res, dt0 = _one_step(scene, method, args, numerics)
            names.append(_write(
                root, f"step_{method}_{scene}{tag}", f"one leapfrog step of the whole {scene} scene "
                f"({method.upper()}, quick)", "all of the method's equations, the boundaries, the return map"
                + (", conduction, friction heat, surface losses" if scene == "thermal_cutting" else ""),
                _state_arrays(setup.state), dict(_state_arrays(res.state), t=np.float64(res.state.t)), units,
                {k: 1e-10 for k in STATE_KEYS + ("t",)}, ROUND_OFF, scene=scene, scene_args=args, method=method,
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
            names.append(_write(
                root, f"run_{scene}_{method}{tag}", f"a short leapfrog run of the {scene} scene at quick resolution "
                f"({method.upper()}, {what}): the final state and the metrics", "all",
                _state_arrays(setup.state), dict(_state_arrays(res.state), t=np.float64(res.state.t)), units,
                {k: tol for k in STATE_KEYS + ("t",)}, why, scene=scene, scene_args=args, method=method,
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
    return _write(root, f"metrics_{key}_{method}", f"{spec['what']} ({method.upper()}): its metrics", "all",
                  _state_arrays(setup.state), out, spec["units"], tol, spec["why"],
                  measure=spec.get("measure", {}).get(method, {}), scene=spec["scene"], scene_args=spec["args"],
                  method=method, n_steps=res.summary["n_steps"],
                  regression="compared with the scene test's own run: tests/test_" + spec["scene"] + ".py")


def metric_rows(case_dir, metrics: dict) -> list[Row]:
    """A run's summary ``metrics`` against the ``metrics_*`` golden case in ``case_dir``, each within its tolerance
    (the regression check of the scene tests)."""
    case_dir = Path(case_dir)
    key = next(k for k in METRIC_RUNS if case_dir.name.startswith(f"metrics_{k}_"))
    return compare_case(case_dir, _metric_arrays(METRIC_RUNS[key], metrics))


def _registry() -> list[tuple[tuple[str, ...], object]]:
    """(the case names, the function that writes them), in the order of index.json."""
    kernels = tuple(f"kernel_{k}_{d}d" for k in ("cubic", "wendland") for d in (2, 3))
    tlsph = tuple(f"tlsph_{m}_{c}" for m in ("affine", "rotation", "random") for c in ("corrected", "uncorrected"))
    steps = tuple(f"step_{m}_{s}" for s in ("taylor", "pressing") for m in ("esph", "tlsph"))
    runs = tuple(f"run_{s}_{m}" for s in SCENES for m in ("esph", "tlsph"))
    leapfrog = ("step_esph_taylor_leapfrog", "run_taylor_esph_leapfrog", "step_tlsph_taylor_leapfrog",
                "run_taylor_tlsph_leapfrog", "step_tlsph_thermal_cutting", "run_thermal_cutting_tlsph")
    groups = [(kernels, _kernel_cases), (("esph_rates",), _esph_case), (tlsph, _tlsph_cases),
              (("return_map_johnson_cook", "return_map_modified"), _return_map_cases), (("pinball",), _pinball_case),
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


def _write_cases(root: Path, only=None) -> list[str]:
    _check_pinned()
    chosen = _check_target(root, only)
    if only is None and root.exists():
        shutil.rmtree(root)
    for name in chosen:
        shutil.rmtree(root / name, ignore_errors=True)
    root.mkdir(parents=True, exist_ok=True)
    for group, write in _registry():
        if chosen & set(group):
            written = write(root)
            written = [written] if isinstance(written, str) else written
            assert list(written) == list(group), (written, group)
    index = dict(format_version=FORMAT_VERSION, refsph_version=__version__, cases=case_names(),
                 generated_with=generated_with(),
                 compare="refsph compare DIR YOUR_DIR: every output array within its case's tolerance, relative to "
                         "the largest value of the reference array")
    (root / "index.json").write_text(json.dumps(index, indent=1) + "\n")
    return case_names(only)


def write_golden_cases(directory, only=None) -> list[str]:
    """Write the golden cases into ``directory`` and an ``index.json`` (of every case); returns the names written.
    Without ``only`` the directory is emptied first and every case written (the ``metrics_*`` cases run whole
    scenes: minutes); ``only``: the cases matching these patterns, the others kept. The cases are computed in a
    child process with :func:`pinned_environment` (module text: the bytes do not depend on the CPU)."""
    if os.environ.get(CHILD) == "1":
        return _write_cases(Path(directory), only)
    _check_target(Path(directory), only)                   # bad input is said here, not in the child's traceback
    cmd = [sys.executable, "-m", "refsph.crosscheck.golden", str(directory)] + (["--only", *only] if only else [])
    subprocess.run(cmd, env=pinned_environment(), check=True)
    return case_names(only)


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
