"""Golden cases: small, versioned inputs with refsph's outputs, for checking another backend (``refsph oracle DIR``).

Each case is a folder ``DIR/<case>/`` with

* ``input.npz``  -- what a backend needs to compute the case (arrays, SI units);
* ``output.npz`` -- refsph's result;
* ``case.json``  -- what the case is, the equations it exercises, every array (shape, unit, meaning), the scene or
  parameters, and ``tolerance``: {array: relative tolerance} with ``why`` (errors are measured as
  max |test - ref| / max |ref| per array, see :mod:`refsph.compare`).

``DIR/index.json`` lists the cases with the refsph version and the format version. Everything is deterministic:
regenerating gives the same bytes (``tests/test_golden.py`` checks the committed copy in ``golden/``). The cases:

| case | what | equations |
|---|---|---|
| kernel_{cubic,wendland}_{2d,3d} | W, dW/dr and grad W at given r and x_ij | Eq. (9), Wendland C2 |
| esph_rates | ESPH rates of a perturbed 2D block with free surfaces, given half pairs | Eqs. (10)-(14), (20)-(24) |
| tlsph_{affine,rotation,random}_{corrected,uncorrected} | F, J, P, l, rates of a 2D block | Eqs. (2), (16)-(24) |
| return_map_{johnson_cook,modified} | return map of trial stresses (elastic, yielding, fast, hot) | Eqs. (25)-(31) |
| pinball | contact forces against a rigid and a deformable partner | Eqs. (32)-(36) |
| step_{esph,tlsph}_{taylor,pressing} | one step of a scene: wall + symmetry (Taylor 2D), clamp + tool | all |
| run_{taylor,pressing,cutting}_{esph,tlsph} | a short quick-resolution run: final state, metrics | all |
"""
from __future__ import annotations

import json
import shutil
import zipfile
from pathlib import Path

import numpy as np

from . import __version__
from .contact import PinballContact, pinball_contact
from .esph import ESPHParams, esph_rates
from .integrate import cfl_time_step
from .io import json_ready
from .kernels import get_kernel
from .neighbours import find_pairs
from .paper_data import AISI1045_RLA
from .plasticity import ModifiedJohnsonCook
from .scenes import aisi4340_johnson_cook, aisi4340_material, get_scene, lattice
from .simulate import run
from .state import make_state
from .strength import plastic_update
from .tlsph import ReferenceOperator, TLSPHParams, tlsph_rates

__all__ = ["write_golden_cases", "FORMAT_VERSION"]

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
        consts = {k: getattr(law, k) for k in law.__dataclass_fields__}
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
                root, f"step_{method}_{scene}", f"one CFL step of the whole {scene} scene ({method.upper()}, quick): "
                + ("symmetry plane and rigid wall" if scene == "taylor" else "clamped column and rigid tool"),
                "all of the method's equations, the boundaries, the return map",
                _state_arrays(setup.state), dict(_state_arrays(res.state), t=np.float64(res.state.t)), units,
                {k: 1e-10 for k in STATE_KEYS + ("t",)}, ROUND_OFF,
                scene=scene, scene_args=args, method=method, dt=dt0,
                step="one predictor-corrector step of the CFL size dt (t_end = dt)"))
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


def write_golden_cases(directory) -> list[str]:
    """Write every golden case into ``directory`` (emptied first) and an ``index.json``; returns the case names."""
    root = Path(directory)
    if root.exists():
        shutil.rmtree(root)
    root.mkdir(parents=True)
    names = (_kernel_cases(root) + [_esph_case(root)] + _tlsph_cases(root) + _return_map_cases(root)
             + [_pinball_case(root)] + _step_and_run_cases(root))
    index = dict(format_version=FORMAT_VERSION, refsph_version=__version__, cases=names,
                 compare="refsph compare DIR YOUR_DIR: every output array within its case's tolerance, relative to "
                         "the largest value of the reference array")
    (root / "index.json").write_text(json.dumps(index, indent=1) + "\n")
    return names

