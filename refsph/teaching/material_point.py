"""A material-point driver: one particle, a prescribed velocity gradient, the package's own constitutive path.

The same functions as in a particle run are used, in the same order: the Jaumann stress rate (Eq. (20)), the
density from continuity (rho_dot = -rho tr l, integrated exactly over the step, rho exp(-dt tr l), as l is
constant in a step; p follows Eq. (24)), the predictor-corrector step and the
Wilkins return map with Johnson-Cook hardening, rate and temperature (Eqs. (25)-(31)), so curves from here test
what the SPH solvers do to each particle.

Two loadings are provided:

* a velocity gradient ``l`` given directly (constant (3, 3) array, or a function of time), e.g. simple shear
  l = [[0, gamma_dot, 0], [0, 0, 0], [0, 0, 0]];
* uniaxial stress along x (``lateral_stress_free=True``): l = diag(eps_dot, lam, lam) with lam found in every
  step (secant iteration) so that sigma_yy = sigma_zz = 0 at the end of the step.

Three dimensions throughout (a single particle has no plane-strain constraint to model).
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from ..material import ElasticMaterial, eos_pressure, jaumann_deviatoric_rate
from ..plasticity import J2Plasticity, equivalent_strain_rate
from ..strength import plastic_update

__all__ = ["material_point"]


def _step(S, rho, eps_p, T, l, dt, mat: ElasticMaterial, jc: J2Plasticity | None, heating: bool):
    """One predictor-corrector step of a single particle with constant l over the step."""
    L = l[None]
    Szz = np.zeros(1)
    eps_dot = equivalent_strain_rate(L)
    tr = float(np.trace(l))

    def rates(S_):
        dS, _ = jaumann_deviatoric_rate(S_, Szz, L, mat.G)
        return np.array(dS)

    def ret(S_trial, rho_):
        if jc is None:
            return S_trial, 0.0, 0.0, 0.0
        S_n, _, deps, dw, dT = plastic_update(S_trial, Szz, eps_p, T, np.array([rho_]), eps_dot, jc, mat.G)
        return S_n, float(deps[0]), float(dw[0]), float(dT[0]) if heating else 0.0

    rho_half = rho * np.exp(-0.5 * dt * tr)
    S_half, _, _, _ = ret(S + 0.5 * dt * rates(S), rho_half)
    rho_new = rho * np.exp(-dt * tr)
    S_new, deps, dw, dT = ret(S + dt * rates(S_half), rho_new)
    return S_new, rho_new, deps, dw, dT, float(eps_dot[0])


def _uniaxial_step(trial, eps_dot_xx: float, lam: float, mat: ElasticMaterial):
    """The step under uniaxial stress: l = diag(eps_dot_xx, lam, lam) with lam found by a secant iteration (from the
    previous step's lam) so that sigma_yy = sigma_zz = 0 at its end. Returns (lam, l, the step's result)."""
    def with_lam(x):
        ll = np.zeros((3, 3))
        ll[0, 0] = eps_dot_xx
        ll[1, 1] = ll[2, 2] = x
        return ll

    def lateral_stress(res):
        S_new, rho_new = res[0], res[1]
        return float(S_new[0, 1, 1] - eos_pressure(rho_new, mat.rho0, mat.K))

    a, fa = lam, lateral_stress(trial(with_lam(lam)))
    b = lam + 1e-3 * abs(eps_dot_xx) + 1e-12
    res = trial(with_lam(b))
    fb = lateral_stress(res)
    for _ in range(30):                                     # secant on sigma_yy(lam) = 0
        if fb == fa:
            break
        a, fa, b = b, fb, b - fb * (b - a) / (fb - fa)
        res = trial(with_lam(b))
        fb = lateral_stress(res)
        if abs(fb) < 1e-9 * max(mat.G * 1e-6, 1.0):
            break
    return b, with_lam(b), res                              # res is the step with this l


def material_point(mat: ElasticMaterial, jc: J2Plasticity | None, l, dt: float, n_steps: int, T0: float, *,
                   heating: bool = True, lateral_stress_free: bool = False) -> dict:
    """Drive one particle; returns arrays over n_steps + 1 instants (index 0 = the stress-free start):

    t [s], strain (3, 3) [-] (integral of the symmetric part of l: the logarithmic strain for coaxial
    loading), sigma (3, 3) [Pa] Cauchy stress, S deviatoric stress, p [Pa], sigma_vm [Pa], sigma_y [Pa]
    (Eq. (25) with the step's rate and the *start-of-step* eps_p and T: the yield stress the step returned to,
    so sigma_vm == sigma_y in every plastic step; index 0: the initial yield stress), eps_p [-],
    eps_dot [1/s], W_p [J/m^3], T [K], l (3, 3).

    ``l``: (3, 3) array or callable t -> (3, 3). ``lateral_stress_free``: uniaxial stress along x, l[0, 0]
    prescribed, l[1, 1] = l[2, 2] solved each step so that sigma_yy = sigma_zz = 0; other entries of l must be 0.
    ``heating``: False keeps T = T0 (isothermal curves; the plastic work is still accumulated).
    """
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"time step dt must be positive, got {dt!r}")
    if int(n_steps) != n_steps or n_steps < 1:
        raise ValueError(f"n_steps must be a positive integer, got {n_steps!r}")
    if not (np.isfinite(T0) and T0 > 0):
        raise ValueError(f"T0 must be positive (kelvin), got {T0!r}")
    l_of_t: Callable = l if callable(l) else (lambda t, _l=np.asarray(l, dtype=float): _l)
    l0 = np.asarray(l_of_t(0.0), dtype=float)
    if l0.shape != (3, 3):
        raise ValueError(f"the velocity gradient must be a (3, 3) array, got shape {l0.shape}")
    if lateral_stress_free:
        off = l0.copy()
        off[0, 0] = 0.0
        if np.any(off != 0):
            raise ValueError("lateral_stress_free: only l[0, 0] may be prescribed (uniaxial stress along x)")

    n = int(n_steps)
    out = {k: np.zeros(n + 1) for k in ("t", "p", "sigma_vm", "sigma_y", "eps_p", "eps_dot", "W_p", "T")}
    for k in ("strain", "sigma", "S", "l"):
        out[k] = np.zeros((n + 1, 3, 3))
    S = np.zeros((1, 3, 3))
    rho = mat.rho0
    eps_p, W_p, T = np.zeros(1), 0.0, np.array([float(T0)])
    strain = np.zeros((3, 3))
    out["T"][0] = T0
    if jc is not None:
        out["sigma_y"][0] = float(jc.flow_stress(0.0, 0.0, T0))
    lam = -mat.nu * l0[0, 0]                                # elastic guess for the lateral rate
    t = 0.0

    def trial(l_step):
        return _step(S, rho, eps_p, T, l_step, dt, mat, jc, heating)

    for k in range(1, n + 1):
        l_step = np.array(l_of_t(t + 0.5 * dt), dtype=float)
        if lateral_stress_free:
            lam, l_step, res = _uniaxial_step(trial, l_step[0, 0], lam, mat)
        else:
            res = trial(l_step)
        S, rho, deps, dw, dT, edot = res
        if jc is not None:                                  # the yield stress this step returned to
            out["sigma_y"][k] = float(jc.flow_stress(eps_p[0], edot, T[0]))
        eps_p = eps_p + deps
        W_p += dw
        T = T + dT
        t += dt
        strain = strain + dt * 0.5 * (l_step + l_step.T)
        p = float(eos_pressure(rho, mat.rho0, mat.K))
        out["t"][k] = t
        out["l"][k] = l_step
        out["strain"][k] = strain
        out["S"][k] = S[0]
        out["sigma"][k] = S[0] - p * np.eye(3)
        out["p"][k] = p
        out["sigma_vm"][k] = float(np.sqrt(1.5 * np.sum(S[0] * S[0])))
        out["eps_p"][k] = eps_p[0]
        out["eps_dot"][k] = edot
        out["W_p"][k] = W_p
        out["T"][k] = T[0]
    return out
