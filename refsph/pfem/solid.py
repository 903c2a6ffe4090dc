"""The PFEM's mechanical step (Rodriguez Prieto, Larsson & Afrasiabi 2023, Sections 2.3.1-2.3.3): an updated
Lagrangian mixed displacement-pressure solid on linear triangles, implicit in time, solved by Newton-Raphson.

    Eq. (12)  rho d2u/dt2 = div sigma + b
    Eq. (13)  p = K ln(J) / J - 3 K alpha (1 - ln J) / J (T - T0)          (as printed; p the mean stress)
    Eq. (15)  sigma = p I + s
    Eq. (19)  M a_{n+1} + F_int(u_{n+1}, p_{n+1}) = F_ext
    Eq. (20)  M_p p_{n+1} - F_vol(u_{n+1}) + F_stab p_{n+1} = 0
    Eq. (21)  v_{n+1} = -v_n + 2 / dt (u_{n+1} - u_n),
              a_{n+1} = -a_n - 4 / dt v_n + 4 / dt^2 (u_{n+1} - u_n)          (trapezoidal rule, Newmark 1/4, 1/2)

(the minus signs of Eq. (21) are lost in the paper's typesetting; these are the trapezoidal rule's). On each
triangle e, with the mesh at t_n (x_n), the displacement increment du of the step and the nodal pressures p:

* **kinematics** (Hughes & Winget 1980, incrementally objective): L = grad_{n+1/2} du, the gradient on the
  midpoint configuration x_n + du/2; d = sym L, w = skew L; the rotation Q = (I - w/2)^{-1} (I + w/2);
  J_{n+1} = J_n det f, det f = A_{n+1} / A_n = 1 + tr H + det H with H = grad_n du (written so, not as the area
  ratio, ln J keeps its digits at small strains);
* **deviatoric stress**: the trial s* = Q s_n Q^T + 2 G dev(d) (plane strain: d_zz = 0, s_zz carried), returned by
  the strength model of :mod:`refsph.strength` (the same seam as the SPH solvers: Johnson-Cook, the modified
  Johnson-Cook of the paper, elastic) with the step's equivalent strain rate sqrt(2/3 dev d : dev d) / dt;
* **pressure**: Eq. (13) at the element, p_hat(J_{n+1}, T);
* **residuals** (forces per metre of width):

      r_u,a = A_{n+1} (s + pbar I) grad_{n+1} N_a                     pbar = the element mean of the nodal p
      r_p   = (M_e p - A_{n+1} / 3 p_hat) / K + S_e p / G               (M_e, S_e of :mod:`refsph.pfem.element`)

  so that Eq. (20) reads M_p p - F_vol + F_stab p = 0 with M_p = int N N / K, F_vol = int N p_hat / K.

**Mass.** Each node is a particle with a fixed mass m_i (the lumped mass matrix, M = diag(m_i)); the paper's
M_{n+1} is the consistent one of the current mesh. With fixed nodal masses a remeshing neither creates nor loses
mass (the standard PFEM mass error is the change of the meshed area; here that change is a density change instead).

**Tangent.** The Newton-Raphson matrix is the exact derivative of the discrete residual. The pressure columns are
linear and written out. The displacement columns are differentiated by hand (:func:`_element_tangent_exact`) for the
laws whose return map is the von Mises radial return (Johnson-Cook, the modified Johnson-Cook, any
:class:`refsph.plasticity.J2Plasticity` with its own flow stress) and for the elastic solid: the midpoint and end
gradients moving with du, the Hughes-Winget rotation, the radial return's factor c_f = sigma_y / sigma_vm (with d
sigma_y / d eps_dot where the rate is the step's own, by central differences in that scalar) and Eq. (13) through
det f. It agrees with central differences of the element residual to their own error, 2e-10 with the rate lagged and
5e-9 with the step's own (``tests/test_pfem.py``, the force and the pressure rows each against its own size). For
any other strength model the columns are the element residual's forward differences from the residual already
computed at du (:func:`_element_tangent_fd`: 6 evaluations of all the elements at once, step 1e-8 of the element
size; error ~1e-8 relative). On the short cut's first 30 steps at t_u/10 the two give the same 362 Newton iterations
and the same tool force to 1e-11; the exact one takes 22.8 s of CPU against 29.3 s (the tangent 10 % of the time
against 27 %; ``benchmarks/pfem_step_cost.py``). Newton converges quadratically down to the tolerance
(``tests/test_pfem.py`` prints the residual norms). The line search's accepted point is not evaluated again (its
residual and element response are kept), and the tangent is computed only where a correction follows: a solve's
converged point (one a step, often its last solve's only point) needs none.

**Linear solve.** Each Newton correction solves K delta = -R with SuperLU (:func:`solve_linear`): a symmetric
fill-reducing ordering (minimum degree on K^T + K) and the diagonal as pivots, since K's diagonal never vanishes
(mass / (beta dt^2) plus stiffness in the displacement rows, M_p / K + S / G in the pressure rows). That fills a
third less than SciPy's default (column ordering with partial pivoting) and halves the time of a solve (8538
unknowns: 0.057 against 0.113 s on one core); the result is checked (relative residual below 1e-8) and solved the
default way where the check fails. The matrix is summed into a sparsity pattern found once per mesh
(:class:`FreeMatrix`: the held dofs' rows and columns already the identity), not built, masked and converted at
every iteration. With the forward-difference tangent: the quick cut's first 40 steps take 20-23 s of CPU against
38 s before both changes (timed back to back on a loaded machine), the forces the same to 1e-12. The first
factorisation on a pattern keeps its minimum-degree ordering, and the pattern is then relabelled into that order
once (:meth:`FreeMatrix.permute`), so later factorisations get the matrix already permuted instead of slicing it
(the short cut's first 30 steps at t_u/10 under cProfile: 22.8 against 24.8 s in :func:`solve_linear`, the same
bits). Modified Newton was tried and left: the factors reused for one or two corrections after each new one took
829 instead of 362 iterations and 36 against 24 s.
Tried on a Newton matrix of the t_u/10 short cut (8538 unknowns, 171,200 entries; one core) and left: the other
orderings SuperLU offers (COLAMD 41 ms, minimum degree on K^T K 39 ms, against 28 ms, and a third to a half more
fill), a nested dissection by breadth-first level sets (27-44 ms with the factor's 1.2-1.7 million entries against
the minimum degree's 0.97 million and 17-20 ms with the ordering reused), SuperLU's panel size and relaxation (within
10 %), and GMRES preconditioned by the last factorisation instead of a new one (the next Newton iteration's matrix,
2 % away from the factored one: 29 GMRES iterations, 103 ms against a factorisation's 26 ms; a matrix 100 iterations
later does not converge). The factorisation (about 40 % of a step) stays.

**History.** Between remeshings each triangle keeps its own history (s, s_zz, eps_p, W_p, J); at a remeshing
(Algorithm 1) a triangle that the new mesh keeps (the same three nodes) keeps its history, and a new triangle
starts from the mean of its nodes' (the history projected to the nodes by area-weighted means,
:func:`project_to_nodes`; :func:`transfer_history`). That averaging is the PFEM's only smoothing, and it relaxes
the stress where it acts (chapter 12 measures it); a run that never remeshes is a plain updated-Lagrangian finite
element run.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu, spsolve

from .element import ppp_stabilisation, pressure_mass, shape_gradients
from .mesh import Mesh, signed_areas

__all__ = ["SolidLaw", "Nodes", "History", "Loads", "StepResult", "element_response", "element_residual",
           "volumetric_pressure", "assemble", "newton_step", "commit", "project_to_nodes", "history_from_nodes",
           "make_nodes", "NewtonFailed", "transfer_history", "settle_nodes", "Newmark", "TRAPEZOIDAL",
           "newmark_of", "solve_linear", "TangentParts", "FreeMatrix"]


class NewtonFailed(RuntimeError):
    """Newton-Raphson did not converge in the allowed iterations (the step should be cut). ``args``: the message,
    then (where given) the residual norms per iteration and the last iterate (du, p); str() is the message alone,
    so that a run's error (summary.json, the terminal) does not print the arrays."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


@dataclass(frozen=True)
class SolidLaw:
    """The workpiece's constitutive data, SI units, no defaults: ``rho0`` [kg/m^3], shear modulus ``G`` and bulk
    modulus ``K`` [Pa], thermal expansion ``alpha_T`` [1/K] and its reference temperature ``T_ref`` [K] (Eq. (13)),
    and the deviatoric ``strength`` law (a :mod:`refsph.strength` model)."""

    rho0: float
    G: float
    K: float
    alpha_T: float
    T_ref: float
    strength: object

    def __post_init__(self):
        for name in ("rho0", "G", "K", "alpha_T", "T_ref"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
                raise ValueError(f"SolidLaw.{name} must be a finite number, got {v!r}")
        for name in ("rho0", "G", "K", "T_ref"):
            if not getattr(self, name) > 0:
                raise ValueError(f"SolidLaw.{name} must be positive, got {getattr(self, name)!r}")
        if self.alpha_T < 0:
            raise ValueError(f"SolidLaw.alpha_T must not be negative, got {self.alpha_T!r}")
        if not hasattr(self.strength, "return_map"):
            raise ValueError("SolidLaw.strength must be a strength model (refsph.strength: return_map, heat)")

    @classmethod
    def from_elastic(cls, material, strength, alpha_T: float, T_ref: float) -> "SolidLaw":
        """From an :class:`refsph.material.ElasticMaterial` (rho0, E, nu)."""
        return cls(rho0=material.rho0, G=material.G, K=material.K, alpha_T=alpha_T, T_ref=T_ref, strength=strength)


@dataclass
class Nodes:
    """The particles, which are the nodes: x, v, a (N, 2) [m, m/s, m/s^2], m (N,) [kg/m], p (N,) [Pa] (mean
    stress), T (N,) [K], and the history projected to them at the last remeshing: S (N, 2, 2), S_zz (N,) [Pa],
    eps_p (N,), W_p (N,) [J/m^3], J (N,) (the volume ratio), eps_dot (N,) [1/s] (the last step's equivalent strain
    rate); t [s]."""

    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    m: np.ndarray
    p: np.ndarray
    T: np.ndarray
    S: np.ndarray
    S_zz: np.ndarray
    eps_p: np.ndarray
    W_p: np.ndarray
    J: np.ndarray
    eps_dot: np.ndarray
    t: float = 0.0

    @property
    def n(self) -> int:
        return len(self.x)


@dataclass
class History:
    """Per triangle, at the start of the step: S (M, 2, 2), S_zz, eps_p, W_p, J (M,); ``eps_dot`` (M,) [1/s] the
    equivalent strain rate of the previous step, or None. Given, the return map takes the yield stress at that
    rate (lagged one step) instead of at the step's own: sigma_y(eps_dot) with eps_dot = |dev d| / dt has a cone
    point at d = 0 (its derivative ~ C sigma_y / |d|), on which Newton-Raphson stalls wherever a flowing element
    unloads; lagged, the step is smooth (the staggered treatment of the rate, stated in chapter 12)."""

    S: np.ndarray
    S_zz: np.ndarray
    eps_p: np.ndarray
    W_p: np.ndarray
    J: np.ndarray
    eps_dot: np.ndarray | None = None


@dataclass
class Loads:
    """What acts on the nodes in a step: ``fixed`` (N, 2) bool, the prescribed displacement components, and
    ``du_fixed`` (N, 2) [m] their increments in the step; ``f_ext`` (N, 2) [N/m] nodal forces (None: none);
    ``contact``: None, or a function x_{n+1} (N, 2) -> (f (N, 2) [N/m], k (N, 2, 2) [N/m^2]) giving the contact
    force on each node and its derivative df/dx (the Newton matrix adds -k); called with ``stiffness=False`` where
    only f is needed (k may then be zeros)."""

    fixed: np.ndarray
    du_fixed: np.ndarray
    f_ext: np.ndarray | None = None
    contact: object = None


@dataclass
class StepResult:
    """A step's solution: du (N, 2), p (N,), the triangles' new history and heat, the Newton record; ``converged``
    False where :func:`newton_step` came back early (``settle``) at a point short of the tolerance; ``evaluation``
    the residual's evaluation there (:func:`newton_step`'s ``start`` for a solve that goes on from it)."""

    du: np.ndarray
    p: np.ndarray
    history: History
    d_eps_p: np.ndarray
    d_w_p: np.ndarray
    area: np.ndarray
    residuals: list = field(default_factory=list)
    contact_force: np.ndarray | None = None
    solves_iterations: int | None = None
    converged: bool = True
    evaluation: tuple | None = None

    @property
    def iterations(self) -> int:
        """The Newton iterations of the step: of every solve it took (the active-set strategy's several) where
        ``solves_iterations`` is set, else of this solve."""
        return len(self.residuals) - 1 if self.solves_iterations is None else self.solves_iterations


@dataclass(frozen=True)
class Newmark:
    """Newmark's rule (beta, gamma): a_{n+1} = (du - dt v_n - dt^2 (1/2 - beta) a_n) / (beta dt^2),
    v_{n+1} = v_n + dt ((1 - gamma) a_n + gamma a_{n+1}). beta = 1/4, gamma = 1/2 is the paper's trapezoidal rule
    (Eq. (21): it damps nothing); gamma > 1/2 with beta = (gamma + 1/2)^2 / 4 damps the high frequencies (an
    impact's ringing) at first-order accuracy. ``dynamic=True`` in the functions below is the trapezoidal rule.

    ``alpha_B`` (-1/3..0; 0: Newmark's rule itself) is Wood, Bossak & Zienkiewicz's (1980) alpha: the inertia
    M ((1 - alpha_B) a_{n+1} + alpha_B a_n) in the equation of motion, with gamma = 1/2 - alpha_B and beta =
    (1 - alpha_B)^2 / 4 (:meth:`bossak`), damps the high frequencies at second-order accuracy (the Bossak-Newmark
    rule of implicit codes, e.g. Kratos' structural solvers; the paper names none)."""

    beta: float
    gamma: float
    alpha_B: float = 0.0

    def __post_init__(self):
        if not -1.0 / 3.0 <= self.alpha_B <= 0.0:
            raise ValueError(f"Bossak's alpha_B must lie in [-1/3, 0], got {self.alpha_B!r}")
        if not (0.0 < self.beta <= 0.5 and 0.5 <= self.gamma <= 1.0 and self.beta >= 0.25 * (self.gamma + 0.5) ** 2
                - 1e-12):
            raise ValueError(f"Newmark(beta, gamma) must be unconditionally stable: 1/2 <= gamma <= 1, "
                             f"(gamma + 1/2)^2 / 4 <= beta <= 1/2; got {self.beta!r}, {self.gamma!r}")

    @classmethod
    def bossak(cls, alpha_B: float) -> "Newmark":
        """The Bossak-Newmark rule: gamma = 1/2 - alpha_B, beta = (1 - alpha_B)^2 / 4 (second order, damped)."""
        return cls((1.0 - alpha_B) ** 2 / 4.0, 0.5 - alpha_B, alpha_B)

    def acceleration(self, du, v, a, dt):
        return (du - dt * v - dt * dt * (0.5 - self.beta) * a) / (self.beta * dt * dt)

    def inertia(self, a_new, a):
        """The acceleration the inertia of the equation of motion takes: (1 - alpha_B) a_{n+1} + alpha_B a_n."""
        return a_new if self.alpha_B == 0.0 else (1.0 - self.alpha_B) * a_new + self.alpha_B * a


TRAPEZOIDAL = Newmark(0.25, 0.5)


def newmark_of(dynamic) -> Newmark:
    """The rule a ``dynamic`` argument names: True -> the trapezoidal rule, a :class:`Newmark` -> itself."""
    return dynamic if isinstance(dynamic, Newmark) else TRAPEZOIDAL


def make_nodes(x: np.ndarray, m: np.ndarray, T: np.ndarray | float) -> Nodes:
    """Nodes at rest and stress free at positions x (N, 2) with masses m (N,) and temperature T."""
    x = np.asarray(x, dtype=float)
    n = len(x)
    z = np.zeros(n)
    return Nodes(x=x.copy(), v=np.zeros((n, 2)), a=np.zeros((n, 2)), m=np.asarray(m, dtype=float).copy(),
                 p=z.copy(), T=np.broadcast_to(np.asarray(T, dtype=float), (n,)).copy(), S=np.zeros((n, 2, 2)),
                 S_zz=z.copy(), eps_p=z.copy(), W_p=z.copy(), J=np.ones(n), eps_dot=z.copy())


def volumetric_pressure(J: np.ndarray, T: np.ndarray, law: SolidLaw, lnJ: np.ndarray | None = None) -> np.ndarray:
    """Eq. (13) as printed: p_hat = K ln J / J - 3 K alpha (1 - ln J) / J (T - T0) (``lnJ``: ln J if known more
    accurately than np.log(J))."""
    lnJ = np.log(J) if lnJ is None else lnJ
    return law.K * lnJ / J - 3.0 * law.K * law.alpha_T * (1.0 - lnJ) / J * (T - law.T_ref)


def _rotated(S: np.ndarray, c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Q S Q^T for the rotations Q = [[c, s], [-s, c]] and symmetric S (M, 2, 2), written out."""
    a, b, d = S[:, 0, 0], S[:, 0, 1], S[:, 1, 1]
    cc, ss, cs = c * c, s * s, c * s
    out = np.empty_like(S)
    out[:, 0, 0] = cc * a + 2.0 * cs * b + ss * d
    out[:, 1, 1] = ss * a - 2.0 * cs * b + cc * d
    out[:, 0, 1] = out[:, 1, 0] = (cc - ss) * b + cs * (d - a)
    return out


def element_response(xe: np.ndarray, due: np.ndarray, hist: History, Te: np.ndarray, dt: float,
                     law: SolidLaw) -> dict:
    """The triangles' state at t_{n+1} for the increment du (module text): S, S_zz, d_eps_p, d_w_p, J, p_hat, the
    gradients and areas at n+1. xe, due (M, 3, 2); Te (M,) [K]."""
    g_half, _ = shape_gradients(xe + 0.5 * due)
    g_end, A_end = shape_gradients(xe + due)
    g_n, A_n = shape_gradients(xe)
    dueT = np.swapaxes(due, 1, 2)
    H = dueT @ g_n                                                 # grad_n du: det f - 1 = tr H + det H, exactly
    dJ = H[:, 0, 0] + H[:, 1, 1] + H[:, 0, 0] * H[:, 1, 1] - H[:, 0, 1] * H[:, 1, 0]
    L = dueT @ g_half                                              # L_ij = sum_a du_a,i dN_a/dx_j
    d = 0.5 * (L + np.swapaxes(L, 1, 2))
    w = 0.5 * (L[:, 0, 1] - L[:, 1, 0])
    q = 1.0 / (1.0 + 0.25 * w * w)                                 # Q = (I - W/2)^-1 (I + W/2), W = [[0, w], [-w, 0]]
    c, s = (1.0 - 0.25 * w * w) * q, w * q                         # Q = [[c, s], [-s, c]]
    tr = d[:, 0, 0] + d[:, 1, 1]
    dev = d - (tr / 3.0)[:, None, None] * np.eye(2)
    dev_zz = -tr / 3.0
    S_trial = _rotated(hist.S, c, s) + 2.0 * law.G * dev           # Q S_n Q^T + 2 G dev d
    S_zz_trial = hist.S_zz + 2.0 * law.G * dev_zz
    eps_dot = np.sqrt(np.maximum(2.0 / 3.0 * (np.einsum("mij,mij->m", dev, dev) + dev_zz * dev_zz), 0.0)) / dt
    rate = eps_dot if hist.eps_dot is None else hist.eps_dot
    S_new, S_zz_new, d_eps_p, d_w_p = law.strength.return_map(S_trial, S_zz_trial, hist.eps_p, rate, Te, law.G)
    J = hist.J * (1.0 + dJ)
    lnJ = np.log(hist.J) + np.log1p(dJ)                          # no cancellation at small strains
    return dict(S=S_new, S_zz=S_zz_new, d_eps_p=d_eps_p, d_w_p=d_w_p, J=J, eps_dot=eps_dot,
                p_hat=volumetric_pressure(J, Te, law, lnJ), grad=g_end, area=A_end, area_n=A_n,
                grad_half=g_half, grad_n=g_n, L=L, H=H, w=w, S_trial=S_trial, S_zz_trial=S_zz_trial, rate=rate,
                lnJ=lnJ)


def element_residual(xe, due, pe, hist, Te, dt, law) -> tuple[np.ndarray, np.ndarray, dict]:
    """(r_u (M, 3, 2), r_p (M, 3), the response): the element residuals of Eqs. (19)-(20) without inertia."""
    r = element_response(xe, due, hist, Te, dt, law)
    A = r["area"]
    sigma = r["S"] + pe.mean(axis=1)[:, None, None] * np.eye(2)
    r_u = A[:, None, None] * (r["grad"] @ np.swapaxes(sigma, 1, 2))       # sum_j sigma_ij dN_a/dx_j
    r_p = (np.einsum("mab,mb->ma", pressure_mass(A), pe) - (A / 3.0 * r["p_hat"])[:, None]) / law.K \
        + np.einsum("mab,mb->ma", ppp_stabilisation(A), pe) / law.G
    return r_u, r_p, r


def _element_dofs(tri: np.ndarray, n: int) -> np.ndarray:
    """(M, 9): u_x, u_y of the three nodes, then their three pressures (global numbering: u 2i + k, p 2N + i)."""
    u = np.stack([2 * tri, 2 * tri + 1], axis=-1).reshape(len(tri), 6)
    return np.concatenate([u, 2 * n + tri], axis=1)


def _element_tangent(xe, due, pe, hist, Te, dt, law, r, r_u, r_p) -> np.ndarray:
    """(M, 9, 9) d(r_u, r_p)/d(du, p) (module text, "Tangent"): exact (:func:`_element_tangent_exact`) for the laws
    whose return map it knows (von Mises radial return, :class:`refsph.plasticity.J2Plasticity`, and the elastic
    solid), forward differences (:func:`_element_tangent_fd`) for any other strength model."""
    if _exact_tangent_known(law.strength):
        return _element_tangent_exact(pe, hist, Te, dt, law, r)
    return _element_tangent_fd(xe, due, pe, hist, Te, dt, law, r, r_u, r_p)


def _exact_tangent_known(strength) -> bool:
    """Whether :func:`_element_tangent_exact` knows the law's return map: the radial return of
    :class:`J2Plasticity` with its ``flow_stress`` (not a subclass's own return map), or the elastic solid."""
    from ..plasticity import J2Plasticity
    from ..strength import Elastic
    own = getattr(strength.return_map, "__func__", None)            # the bound method's function (an instance's
    return own is J2Plasticity.return_map or own is Elastic.return_map   # own return map is not the class's)


def _return_factor(hist, Te, dt, law, r):
    """The radial return at the trial stress of ``r``: (c_f, sigma_vm trial, sigma_y, d sigma_y / d eps_dot where
    the rate is the step's own (zeros where it is lagged, :class:`History`), plastic mask); c_f = 1 for the
    elastic solid."""
    S_tr, Szz_tr = r["S_trial"], r["S_zz_trial"]
    svm = np.sqrt(1.5 * (np.einsum("mij,mij->m", S_tr, S_tr) + Szz_tr * Szz_tr))
    zero = np.zeros_like(svm)
    if not hasattr(law.strength, "flow_stress"):                    # the elastic solid
        return np.ones_like(svm), svm, zero, zero, np.zeros(len(svm), dtype=bool)
    rate = r["rate"]
    sy = law.strength.flow_stress(hist.eps_p, rate, Te)
    dsy = zero
    if hist.eps_dot is None:                                      # sigma_y(eps_dot(du)): central differences in the
        h = 1e-6 * np.maximum(rate, 1e-300)                       # scalar rate (the law is smooth but for its kink)
        dsy = (law.strength.flow_stress(hist.eps_p, rate + h, Te)
               - law.strength.flow_stress(hist.eps_p, np.maximum(rate - h, 0.0), Te)) / (rate + h - np.maximum(
                   rate - h, 0.0))
    plastic = svm > sy
    cf = np.where(plastic, sy / np.where(svm > 0, svm, 1.0), 1.0)
    return cf, svm, sy, dsy, plastic


def _element_tangent_exact(pe, hist, Te, dt, law, r) -> np.ndarray:
    """(M, 9, 9) d(r_u, r_p)/d(du, p), differentiated by hand (module text). For a column du_b,i (node b,
    direction i) and G_b,i = e_i (x) grad N_b on a configuration:

        dL = (I - L/2) (e_i (x) grad_{n+1/2} N_b)                 (the midpoint gradient moves with du/2)
        d grad_{n+1} N_a = -(grad_{n+1} N_a)_i grad_{n+1} N_b,   dA_{n+1} = A_{n+1} (grad_{n+1} N_b)_i
        dQ from dw (Q's entries c, s of w: dc/dw = -w q^2, ds/dw = q^2 (1 - w^2/4), q = 1 / (1 + w^2/4))
        ds* = dQ s_n Q^T + Q s_n dQ^T + 2 G dev(dd),  dc_f = d sigma_y / sigma_vm - sigma_y d sigma_vm / sigma_vm^2
        d(det f) = (cofactor of f = I + H) : (e_i (x) grad_n N_b),  d p_hat / dJ = K (1 - ln J) / J^2
                   - 3 K alpha (ln J - 2) / J^2 (T - T0)

    and the pressure columns as in the forward-difference tangent. Checked against central differences in
    ``tests/test_pfem.py``."""
    m, G = len(pe), law.G
    T = _components_first                                           # arrays (..., M): each operation one long loop
    A, g, gh, gn = r["area"], T(r["grad"]), T(r["grad_half"]), T(r["grad_n"])
    L, H, w, S_tr, Szz_tr = T(r["L"]), T(r["H"]), r["w"], T(r["S_trial"]), r["S_zz_trial"]
    cf, svm, sy, dsy, plastic = _return_factor(hist, Te, dt, law, r)
    eye = np.eye(2)[:, :, None]
    sigma = T(r["S"]) + pe.mean(axis=1) * eye
    q = 1.0 / (1.0 + 0.25 * w * w)
    dc, ds = -w * q * q, q * q * (1.0 - 0.25 * w * w)
    c, s = (1.0 - 0.25 * w * w) * q, w * q
    a0, b0, d0 = hist.S[:, 0, 0], hist.S[:, 0, 1], hist.S[:, 1, 1]
    dR = np.empty((2, 2, m))                                       # d(Q s_n Q^T)/dw (the entries of _rotated)
    dR[0, 0] = (2 * c * a0 + 2 * s * b0) * dc + (2 * c * b0 + 2 * s * d0) * ds
    dR[1, 1] = (-2 * s * b0 + 2 * c * d0) * dc + (2 * s * a0 - 2 * c * b0) * ds
    dR[0, 1] = dR[1, 0] = (2 * c * b0 + s * (d0 - a0)) * dc + (-2 * s * b0 + c * (d0 - a0)) * ds
    lnJ = r["lnJ"]
    dphat = (law.K * (1.0 - lnJ) - 3.0 * law.K * law.alpha_T * (lnJ - 2.0) * (Te - law.T_ref)) / r["J"] ** 2
    gsig = g[:, None, 0] * sigma[None, :, 0] + g[:, None, 1] * sigma[None, :, 1]   # [a, i'] grad N_a . sigma_i'
    unit = np.ones(1)                                               # M_e / A and S_e / A (:mod:`.element`)
    pm_pe = (pressure_mass(unit)[0] / law.K + ppp_stabilisation(unit)[0] / G) @ pe.T   # the r_p terms, per A
    # every column (b, i) at once: arrays [b, i, ..., M]
    I_L = eye - 0.5 * L
    dL = np.swapaxes(I_L, 0, 1)[None, :, :, None] * gh[:, None, None, :]          # [b, i, j, l]
    dd = 0.5 * (dL + np.swapaxes(dL, 2, 3))
    dtr = dd[:, :, 0, 0] + dd[:, :, 1, 1]
    dw = 0.5 * (dL[:, :, 0, 1] - dL[:, :, 1, 0])
    dS_tr = dR * dw[:, :, None, None] + 2.0 * G * (dd - dtr[:, :, None, None] / 3.0 * eye)
    inv_svm = 1.0 / np.where(svm > 0, svm, 1.0)
    dsvm = 1.5 * (np.einsum("jlm,bijlm->bim", S_tr, dS_tr) - Szz_tr * 2.0 * G * dtr / 3.0) * inv_svm
    dsy_k = dsy * _rate_derivative(L, r["eps_dot"], dd, dtr, dt) if hist.eps_dot is None else 0.0
    dcf = np.where(plastic, (dsy_k - sy * dsvm * inv_svm) * inv_svm, 0.0)
    dS = cf * dS_tr + dcf[:, :, None, None] * S_tr
    dr_u = g[:, None, 0] * dS[:, :, None, :, 0]     # [b, i, a, i']: A (grad N_a . dS_i' + dA / A grad N_a . sigma_i'
    dr_u += g[:, None, 1] * dS[:, :, None, :, 1]    # + dgrad N_a . sigma_i')
    dr_u -= np.swapaxes(g, 0, 1)[None, :, :, None] * gsig[:, None, None]
    dr_u += g[:, :, None, None] * gsig
    dr_u *= A
    dA = A * g                                                      # [b, i]
    cof = np.array([[1.0 + H[1, 1], -H[1, 0]], [-H[0, 1], 1.0 + H[0, 0]]])
    dJ = hist.J * (cof[None, :, 0] * gn[:, None, 0] + cof[None, :, 1] * gn[:, None, 1])
    dr_p = dA[:, :, None] * pm_pe - ((dA * r["p_hat"] + A * dphat * dJ) / (3.0 * law.K))[:, :, None]
    K = np.empty((9, 9, m))
    K[:6, :6] = np.swapaxes(dr_u.reshape(6, 6, m), 0, 1)
    K[6:, :6] = np.swapaxes(dr_p.reshape(6, 3, m), 0, 1)
    K[:6, 6:] = (A * g / 3.0).reshape(6, 1, m)
    K = np.ascontiguousarray(np.moveaxis(K, 2, 0))
    K[:, 6:, 6:] = pressure_mass(A) / law.K + ppp_stabilisation(A) / law.G
    return K


def _components_first(a: np.ndarray) -> np.ndarray:
    """(M, ...) -> (..., M), contiguous."""
    return np.ascontiguousarray(np.moveaxis(a, 0, -1))


def _rate_derivative(L, eps_dot, dd, dtr, dt):
    """d eps_dot [b, i, M] for the strain-rate changes dd [b, i, j, l, M] of the columns (eps_dot = sqrt(2/3
    (dev d : dev d + dev_zz^2)) / dt); L [j, l, M]."""
    d = 0.5 * (L + np.swapaxes(L, 0, 1))
    tr = d[0, 0] + d[1, 1]
    eye = np.eye(2)[:, :, None]
    dev, dev_zz = d - tr / 3.0 * eye, -tr / 3.0
    ddev, ddev_zz = dd - dtr[:, :, None, None] / 3.0 * eye, -dtr / 3.0
    num = 2.0 / 3.0 * (np.einsum("jlm,bijlm->bim", dev, ddev) + dev_zz * ddev_zz) / (dt * dt)
    return np.where(eps_dot > 0, num / np.where(eps_dot > 0, eps_dot, 1.0), 0.0)


def _element_tangent_fd(xe, due, pe, hist, Te, dt, law, r, r_u, r_p) -> np.ndarray:
    """(M, 9, 9) d(r_u, r_p)/d(du, p): forward differences in du from the residual (r_u, r_p) at du (module text),
    the pressure columns exactly."""
    m = len(xe)
    eps = 1e-8 * np.sqrt(np.abs(r["area_n"]))
    K = np.empty((m, 9, 9))
    base = np.concatenate([r_u.reshape(m, 6), r_p], axis=1)
    for k in range(6):
        a, i = divmod(k, 2)
        d = np.zeros_like(due)
        d[:, a, i] = eps
        up, pp, _ = element_residual(xe, due + d, pe, hist, Te, dt, law)
        K[:, :, k] = (np.concatenate([up.reshape(m, 6), pp], axis=1) - base) / eps[:, None]
    A, g = r["area"], r["grad"]
    K[:, :6, 6:] = np.repeat((A[:, None, None] * g / 3.0).reshape(m, 6, 1), 3, axis=2)
    K[:, 6:, 6:] = pressure_mass(A) / law.K + ppp_stabilisation(A) / law.G
    return K


@dataclass
class TangentParts:
    """The Newton-Raphson matrix in pieces: the element blocks ``Ke`` (M, 9, 9) on the element dofs ``dofs`` (M, 9)
    (:func:`_element_dofs`), a diagonal ``diag`` (3N,) (the mass term M / (beta dt^2), or None) and each node's
    2 x 2 contact block ``kc`` (N, 2, 2, subtracted; or None)."""

    Ke: np.ndarray
    dofs: np.ndarray
    n: int
    diag: np.ndarray | None = None
    kc: np.ndarray | None = None

    def entries(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(rows, cols, values): the element entries, the contact blocks' and the diagonal's, in that order."""
        n, dofs = self.n, self.dofs
        i = np.arange(2 * n).reshape(n, 2)
        rows = np.concatenate([np.repeat(dofs, 9, axis=1).ravel(), np.repeat(i, 2, axis=1).ravel(), np.arange(3 * n)])
        cols = np.concatenate([np.tile(dofs, (1, 9)).ravel(), np.tile(i, (1, 2)).ravel(), np.arange(3 * n)])
        return rows, cols, self.values()

    def values(self) -> np.ndarray:
        """The values of :meth:`entries` alone (its rows and columns depend on the mesh only)."""
        n = self.n
        return np.concatenate([self.Ke.ravel(), np.zeros(4 * n) if self.kc is None else -self.kc.ravel(),
                               np.zeros(3 * n) if self.diag is None else self.diag])

    def sparse(self):
        """The matrix, sparse (3N, 3N) CSR."""
        rows, cols, vals = self.entries()
        return sp.coo_matrix((vals, (rows, cols)), shape=(3 * self.n, 3 * self.n)).tocsr()


class FreeMatrix:
    """The matrix of a Newton correction: the tangent with the held dofs' rows and columns replaced by the identity,
    as CSC on a sparsity pattern found once per mesh and set of held dofs (:func:`_shared_pattern`), so each
    iteration only sums its entries into place (np.bincount) instead of building and masking a sparse matrix."""

    def __init__(self, dofs: np.ndarray, n: int, fix: np.ndarray):
        rows, cols, _ = TangentParts(np.zeros((len(dofs), 9, 9)), dofs, n).entries()
        self.valid = ~(fix[rows] | fix[cols])
        self.valid[-3 * n:] = True                                # the diagonal entries come last
        self._uniq, self.where = np.unique(cols[self.valid] * (3 * n) + rows[self.valid], return_inverse=True)
        self._where0, uniq = self.where, self._uniq
        self.indices, self.n3 = uniq % (3 * n), 3 * n
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(uniq // (3 * n), minlength=3 * n))])
        self.fix_diag = np.flatnonzero(fix)

    def permute(self, inverse: np.ndarray) -> None:
        """From now on give the matrix permuted, A[inverse][:, inverse] (:func:`solve_linear`'s stored ordering):
        its pattern relabelled once, instead of the matrix sliced at every factorisation."""
        pos = np.argsort(inverse)                                  # entry (r, c) goes to (pos[r], pos[c])
        n3 = self.n3
        rows, cols = pos[self._uniq % n3], pos[self._uniq // n3]
        order = np.argsort(cols * n3 + rows)
        new_pos = np.empty_like(order)
        new_pos[order] = np.arange(len(order))
        self.where = new_pos[self._where0]
        self.indices = rows[order]
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(cols, minlength=n3))])

    def solve(self, parts: TangentParts, b: np.ndarray, ordering: dict) -> np.ndarray:
        """:func:`solve_linear` on this matrix with the ordering dict of its pattern; once that holds an ordering,
        the pattern is relabelled into it (:meth:`permute`) and the matrix given permuted."""
        if "inverse" in ordering and not ordering.get("permuted"):
            self.permute(ordering["inverse"])
            ordering["permuted"] = True
        return solve_linear(self(parts), b, ordering)

    def __call__(self, parts: TangentParts):
        vals = parts.values()
        vals[len(vals) - self.n3 + self.fix_diag] = 1.0
        data = np.bincount(self.where, vals[self.valid], minlength=len(self.indices))
        return sp.csc_matrix((data, self.indices, self.indptr), shape=(self.n3, self.n3))


def _assemble(nodes, mesh, hist, law, du, p, dt, dynamic, tangent=True, known=None):
    """:func:`assemble` with the matrix as :class:`TangentParts` (or None)."""
    n, tri = nodes.n, mesh.tri
    xe, due, pe, Te = nodes.x[tri], du[tri], p[tri], nodes.T[tri].mean(axis=1)
    if known is None:
        r_u, r_p, resp = element_residual(xe, due, pe, hist, Te, dt, law)
        resp.update(r_u=r_u, r_p=r_p)
    else:
        resp = known
        r_u, r_p = resp["r_u"], resp["r_p"]
    dofs = _element_dofs(tri, n)
    loc = np.concatenate([r_u.reshape(len(tri), 6), r_p], axis=1)
    R = np.bincount(dofs.ravel(), loc.ravel(), minlength=3 * n)
    scale = np.bincount(dofs[:, :6].ravel(), np.abs(loc[:, :6]).ravel(), minlength=3 * n)[:2 * n]
    area = np.abs(resp["area"])[:, None] / 3.0 * np.ones(3)              # the pressure rows' scale: int N |p| / K
    scale_p = np.linalg.norm(np.bincount(tri.ravel(), (area * (np.abs(resp["p_hat"])[:, None] + np.abs(pe)
                                                                 + 1e-12 * law.G)).ravel() / law.K, minlength=n))
    if dynamic:
        nm = newmark_of(dynamic)
        a_new = nm.acceleration(du, nodes.v, nodes.a, dt)                  # Eq. (21)
        inertia = nodes.m[:, None] * nm.inertia(a_new, nodes.a)
        R[:2 * n] += inertia.ravel()
        scale = scale + np.abs(inertia).ravel()
    parts = None
    if tangent:
        parts = TangentParts(_element_tangent(xe, due, pe, hist, Te, dt, law, resp, r_u, r_p), dofs, n)
        if dynamic:
            parts.diag = np.concatenate([np.repeat(nodes.m * (1.0 - nm.alpha_B) / (nm.beta * dt**2), 2), np.zeros(n)])
    return R, parts, resp, (float(np.linalg.norm(scale)), float(scale_p))


def assemble(nodes: Nodes, mesh: Mesh, hist: History, law: SolidLaw, du: np.ndarray, p: np.ndarray, dt: float,
             dynamic: bool, tangent: bool = True, known: dict | None = None):
    """The global residual R (3N,) = (F_int - F_ext + M a_{n+1}, Eq. (19); Eq. (20)) without loads, its matrix
    (sparse (3N, 3N), or None), the element response (with the element residuals "r_u", "r_p"), and the scales of
    the displacement and pressure rows (the norms of the sums of the magnitudes of their terms: the tolerance is
    relative to them). ``known``: the element response this function returned for the same du and p (a line
    search's accepted point), which is then not computed again."""
    R, parts, resp, scale = _assemble(nodes, mesh, hist, law, du, p, dt, dynamic, tangent, known)
    return R, None if parts is None else parts.sparse(), resp, scale


def _node_sizes(nodes: Nodes, mesh: Mesh) -> np.ndarray:
    """Each node's local size sqrt(mean area of its triangles) (inf for a node without one)."""
    a = np.repeat(np.abs(signed_areas(nodes.x, mesh.tri)), 3)
    cnt = np.bincount(mesh.tri.ravel(), minlength=nodes.n)
    size = np.sqrt(np.bincount(mesh.tri.ravel(), a, minlength=nodes.n) / np.maximum(cnt, 1))
    size[cnt == 0] = np.inf
    return size


def _shared_pattern(pattern: dict | None, mesh: Mesh, n: int, fix: np.ndarray):
    """(:class:`FreeMatrix`, the ordering dict of :func:`solve_linear`) for this mesh and these held dofs: those
    kept in ``pattern`` where they match, else found and kept there."""
    if pattern is None or not np.array_equal(pattern.get("fix", ()), fix) or pattern.get("tri") is not mesh.tri:
        pattern = {} if pattern is None else pattern
        pattern.clear()
        pattern.update(fix=fix, tri=mesh.tri, free=FreeMatrix(_element_dofs(mesh.tri, n), n, fix), ordering={})
    return pattern["free"], pattern["ordering"]


def newton_step(nodes: Nodes, mesh: Mesh, hist: History, law: SolidLaw, dt: float, loads: Loads,
                dynamic: bool = True, tol: float = 1e-10, max_iter: int = 25, predictor: bool = True,
                max_move: float | None = None, du0: np.ndarray | None = None, p0: np.ndarray | None = None,
                pattern: dict | None = None, settle: int | None = None, start: tuple | None = None) -> StepResult:
    """Solve Eqs. (19)-(20) for the step's du and p by Newton-Raphson. Converged when the residual of the free
    displacement rows and that of the pressure rows are below ``tol`` times their scales (:func:`assemble`), or
    below 100 tol and no longer falling (the round-off floor of a large system: the sums of many forces).
    Nodes without a triangle keep p = 0 (and, quasi-static, du = 0). ``max_move``: no Newton correction moves a
    node by more than this fraction of its local size sqrt(mean area of its triangles) (the whole correction scaled
    down, before the line search; None: no limit; where elements flow the tangent is soft and a node on the tool can
    get a correction of ten spacings, on which the line search alone crawls: chapter 12). ``du0``: the first guess
    of du where the predictor is off (default zeros); ``p0``: that of p (default p at t_n). ``pattern``: a dict
    kept between the solves of one mesh and one set of held dofs (the Newton matrix's sparsity pattern and ordering,
    :class:`FreeMatrix`; found again where they differ). ``settle``: return after this many
    corrections, at a finite residual with no prescribed correction pending, even if not converged (``converged``
    False; :func:`refsph.pfem.contact.solve_with_active_set` looks at its sets there; None: to the tolerance).
    ``start``: the residual's evaluation at (du0, p0) under these loads (a settled result's ``evaluation``), not
    computed again (taken only with the predictor off and du0 given). Raises :class:`NewtonFailed`."""
    n = nodes.n
    size = None if max_move is None else _node_sizes(nodes, mesh)
    fixed = np.asarray(loads.fixed, dtype=bool).copy()
    meshed = mesh.meshed
    if not dynamic:
        fixed[~meshed] = True
    du = dt * nodes.v + 0.5 * dt * dt * nodes.a if dynamic and predictor else np.zeros((n, 2))
    if du0 is not None and not predictor:
        du = np.asarray(du0, dtype=float).copy()
    target = np.where(fixed, np.where(meshed[:, None] | bool(dynamic), loads.du_fixed, 0.0), du).ravel()
    p = (nodes.p if p0 is None else np.asarray(p0, dtype=float)).copy()
    p[~meshed] = 0.0
    fix = np.concatenate([fixed.ravel(), ~meshed])
    f_ext = np.zeros(2 * n) if loads.f_ext is None else np.asarray(loads.f_ext, dtype=float).ravel()
    history = []
    free, ordering = _shared_pattern(pattern, mesh, n, fix)

    def evaluate(du, p, tangent, known=None):
        return _residual(nodes, mesh, hist, law, du, p, dt, dynamic, f_ext, loads.contact, tangent, known)

    def norms(R, scale):
        R_free = np.where(fix, 0.0, R)
        return R_free, (float(np.linalg.norm(R_free[:2 * n])) / scale[0], float(np.linalg.norm(R_free[2 * n:]))
                        / scale[1])

    R, Kg, resp, scale, fc = ev = (start if not predictor and du0 is not None else None) or evaluate(du, p, False)
    for _ in range(max_iter + 1):
        lift = np.zeros(3 * n)
        lift[:2 * n] = target - du.ravel()                        # the prescribed part of the correction
        lift[~fix] = 0.0
        R_free, (res_u, res_p) = norms(R, scale)
        history.append((res_u, res_p))
        floor = (len(history) > 2 and max(res_u, res_p) < 100.0 * tol
                 and max(res_u, res_p) > 0.5 * max(history[-2]))      # stagnating at round-off, just above tol
        done = ((res_u < tol and res_p < tol) or floor) and not np.any(lift)
        if done or (settle is not None and len(history) > settle and not np.any(lift) and np.all(np.isfinite(R))):
            return _step_result(du, p, hist, history, ev, bool(done))
        if not np.all(np.isfinite(R)):
            break
        Kg = evaluate(du, p, True, resp)[1]                       # the tangent at this point (its residual known)
        rhs = -R_free - (np.where(fix, 0.0, Kg.sparse() @ lift) if np.any(lift) else 0.0)
        step = free.solve(Kg, rhs, ordering) + lift
        if not np.all(np.isfinite(step)):
            break
        s = 1.0 if max_move is None else min(1.0, max_move / max(float(np.max(
            np.hypot(step[0:2 * n:2], step[1:2 * n:2]) / size)), 1e-300))      # the step limit (docstring)
        for _ls in range(12):                                     # backtracking on the scaled residual (a contact
            #                                                       that switches on and off, an inverted triangle)
            trial = evaluate(du + s * step[:2 * n].reshape(n, 2), p + s * step[2 * n:], False)
            common = (max(scale[0], trial[3][0]), max(scale[1], trial[3][1]))   # both points on one scale (a
            m0, mt = norms(R, common)[1], norms(trial[0], common)[1]            # stress-free start has a tiny one)
            if np.all(np.isfinite(trial[0])) and (np.any(lift) or mt[0]**2 + mt[1]**2
                                                  <= (1.0 - 1e-4 * s) * (m0[0]**2 + m0[1]**2)):
                break
            s *= 0.5
        else:
            trial = None                                          # no trial taken: the point is new
        du, p = du + s * step[:2 * n].reshape(n, 2), p + s * step[2 * n:]
        R, Kg, resp, scale, fc = ev = trial if trial is not None else evaluate(du, p, False)   # the accepted trial
    raise NewtonFailed(f"Newton-Raphson did not converge in {max_iter} iterations (residuals {history[-3:]})",
                       history, (du, p))


def _step_result(du, p, hist, history, ev, converged) -> StepResult:
    """newton_step's result at (du, p): the element response there (of the evaluation ``ev``, :func:`_residual`'s
    tuple) as the triangles' new history."""
    resp, fc = ev[2], ev[4]
    return StepResult(du=du, p=p, history=History(resp["S"], resp["S_zz"], hist.eps_p + resp["d_eps_p"],
                                                   hist.W_p + resp["d_w_p"], resp["J"],
                                                   None if hist.eps_dot is None else resp["eps_dot"]),
                      d_eps_p=resp["d_eps_p"], d_w_p=resp["d_w_p"], area=resp["area"], residuals=history,
                      contact_force=fc, converged=converged, evaluation=ev)


def solve_linear(A, b: np.ndarray, ordering: dict | None = None) -> np.ndarray:
    """x with A x = b (module text, "Linear solve"): SuperLU with the minimum-degree ordering of A^T + A and
    diagonal pivots; where that fails or leaves a relative residual above 1e-8, scipy's spsolve (partial
    pivoting). ``ordering``: a dict kept between solves on one sparsity pattern; the first solve stores its
    ordering there ("inverse"), and later ones permute A by it and factor in that order (the same factors, without
    computing the ordering again); with "permuted" True there, A is given already permuted (A[inv][:, inv], as
    :meth:`FreeMatrix.permute` makes it) and x is still returned in the original order."""
    A = sp.csc_matrix(A)
    opts = dict(diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
    inv = None if ordering is None else ordering.get("inverse")
    given = inv is not None and ordering.get("permuted", False)
    M, rhs = (A, b) if inv is None else (A if given else A[inv][:, inv].tocsc(), b[inv])
    try:
        lu = splu(M, permc_spec="MMD_AT_PLUS_A" if inv is None else "NATURAL", **opts)
        y = lu.solve(rhs)
        if ordering is not None and inv is None:
            ordering["inverse"] = np.argsort(lu.perm_c)
        if np.all(np.isfinite(y)) and np.linalg.norm(M @ y - rhs) <= 1e-8 * np.linalg.norm(rhs):
            return _unpermuted(y, inv)
    except RuntimeError:                                           # an exactly zero pivot
        pass
    return _unpermuted(spsolve(M, rhs), inv)


def _unpermuted(y: np.ndarray, inv: np.ndarray | None) -> np.ndarray:
    """x with x[inv] = y (y itself where inv is None)."""
    if inv is None:
        return y
    x = np.empty_like(y)
    x[inv] = y
    return x


def _residual(nodes, mesh, hist, law, du, p, dt, dynamic, f_ext, contact, tangent=True, known=None):
    """assemble() with the nodal forces and the contact (its force and stiffness) added."""
    n = nodes.n
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        R, Kg, resp, scale = _assemble(nodes, mesh, hist, law, du, p, dt, dynamic, tangent, known)
    R[:2 * n] -= f_ext
    floor = 1e-8 * law.G * float(np.sqrt(np.sum(np.abs(resp["area"]))))   # a stress of 1e-8 G over the body
    scale = (float(np.sqrt(scale[0] ** 2 + np.sum(f_ext**2) + floor**2)), scale[1])
    fc = None
    if contact is not None:
        fc, kc = contact(nodes.x + du, stiffness=tangent)
        R[:2 * n] -= fc.ravel()
        scale = (float(np.hypot(scale[0], np.linalg.norm(fc))), scale[1])
        if Kg is not None:                                # each node's 2 x 2 block df_i/dx_i on the diagonal
            Kg.kc = kc
    return R, Kg, resp, scale, fc


def commit(nodes: Nodes, step: StepResult, dt: float, dynamic: bool = True) -> Nodes:
    """The nodes at t_{n+1}: x += du, v and a by Eq. (21) (quasi-static: v = du / dt, a = 0), p."""
    if dynamic:
        nm = newmark_of(dynamic)
        a = nm.acceleration(step.du, nodes.v, nodes.a, dt)
        v = nodes.v + dt * ((1.0 - nm.gamma) * nodes.a + nm.gamma * a)
    else:
        v, a = step.du / dt, np.zeros_like(step.du)
    return replace(nodes, x=nodes.x + step.du, v=v, a=a, p=step.p.copy(), t=nodes.t + dt)


def project_to_nodes(mesh: Mesh, area: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """Area-weighted nodal means of per-triangle values (M, ...): v_i = sum_e A_e v_e / sum_e A_e over the triangles
    of node i (0 for a node without one)."""
    w = np.repeat(np.abs(area), 3)
    idx = mesh.tri.ravel()
    den = np.bincount(idx, w, minlength=n)
    flat = np.repeat(values.reshape(len(area), -1), 3, axis=0)
    num = np.stack([np.bincount(idx, w * flat[:, k], minlength=n) for k in range(flat.shape[1])], axis=1)
    out = np.where(den[:, None] > 0, num / np.where(den > 0, den, 1.0)[:, None], 0.0)
    return out.reshape((n,) + values.shape[1:])


def transfer_history(old: Mesh, hist: History, new: Mesh, nodes: Nodes) -> History:
    """The history on a new mesh: a triangle the remeshing kept (the same three nodes) keeps its own history
    exactly; a new one starts from the mean of its nodes' (:func:`history_from_nodes`). Between two Delaunay
    meshes of nodes that moved a little most triangles are the same, so the averaging (which relaxes the stress a
    little at each remeshing, chapter 12) touches only the triangles that changed."""
    out = history_from_nodes(nodes, new)
    key_old = np.sort(old.tri, axis=1)
    key_new = np.sort(new.tri, axis=1)
    n = int(max(key_old.max(), key_new.max())) + 1
    code_old = (key_old[:, 0] * n + key_old[:, 1]) * n + key_old[:, 2]
    code_new = (key_new[:, 0] * n + key_new[:, 1]) * n + key_new[:, 2]
    order = np.argsort(code_old)
    pos = np.searchsorted(code_old[order], code_new)
    pos = np.minimum(pos, len(order) - 1)
    same = code_old[order][pos] == code_new
    src = order[pos[same]]
    for name in ("S", "S_zz", "eps_p", "W_p", "J", "eps_dot"):
        a, b = getattr(out, name), getattr(hist, name)
        if a is not None and b is not None:
            a[same] = b[src]
    return out


def plastic_heat(mesh: Mesh, step: StepResult, strength, n: int) -> np.ndarray:
    """The plastic heat of a step per node [J/m]: chi dW_p A of each triangle (Eq. (5) over the step), a third to
    each of its nodes; zeros for a law that does not heat."""
    if not getattr(strength, "heating", False):
        return np.zeros(n)
    q = strength.chi * step.d_w_p * np.abs(step.area)
    return np.bincount(mesh.tri.ravel(), np.repeat(q / 3.0, 3), minlength=n)


def settle_nodes(nodes: Nodes, mesh: Mesh, step: StepResult, strength, heat: bool = True) -> None:
    """After a converged step (in place): the plastic heat chi dW_p A of each triangle, a third to each of its
    nodes, over m_i c_p (adiabatic; none for a law that does not heat; ``heat=False``: none, for a run whose heat
    step takes it as a source), and the triangles' new history projected to the nodes (:func:`project_to_nodes`),
    ready for a remeshing."""
    if heat and getattr(strength, "heating", False):
        nodes.T = nodes.T + plastic_heat(mesh, step, strength, nodes.n) / (nodes.m * strength.cp)
    for name in ("S", "S_zz", "eps_p", "W_p", "J", "eps_dot"):
        value = getattr(step.history, name)
        if value is not None:
            setattr(nodes, name, project_to_nodes(mesh, step.area, value, nodes.n))


def history_from_nodes(nodes: Nodes, mesh: Mesh) -> History:
    """Each triangle's history as the mean of its three nodes' (after a remeshing)."""
    t = mesh.tri
    return History(S=nodes.S[t].mean(axis=1), S_zz=nodes.S_zz[t].mean(axis=1), eps_p=nodes.eps_p[t].mean(axis=1),
                   W_p=nodes.W_p[t].mean(axis=1), J=nodes.J[t].mean(axis=1), eps_dot=nodes.eps_dot[t].mean(axis=1))
