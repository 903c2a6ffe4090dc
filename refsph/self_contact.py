"""Self-contact of a TLSPH body: a short-range repulsion between particles of the same body that come closer than
r_c (not in the paper; an option, off by default).

Why. TLSPH's forces come from the deformation gradient F of Eq. (18), a kernel-weighted average over each
particle's reference neighbours. Two neighbours can approach each other without changing any particle's F much
(a zero-energy mode of the particle sum, as hourglassing is), and after a reference update (X <- x) the crowded
pair is the new reference and nothing pushes it apart. In the cutting scenes the chip's particles pair up: at the
scene's ``ref_update_strain`` 0.5, 29-31 % of the workpiece's particles of ``thermal_cutting`` cases 1 and 10 at
dx = t_u/5 end the cut with a neighbour closer than dx/2, the closest pair at 0.01-0.015 dx (the sweep's
'selfcontact' study, ``benchmarks/thermal_cutting_report.md``). Self-contact holds every pair at 0.45 dx or more
(and case 1's chip 29 % thicker), but it does not make the cuts safer: their blow-ups look mainly like a time-step
instability; half the step ran each of the four failed cuts tried to the end (chapter 10, section 6).

What. LAMMPS's SMD package (Ganzenmueller's Smooth Mach Dynamics, ``pair_style smd/hertz``) gives particles of
one body that are SPH neighbours a Hertzian contact at half the contact diameter; refsph does the same with the
contact distance r_c (``Numerics.self_contact`` dp; LAMMPS: contact radius dp/2, halved, so r_c = dp/2). For a pair
of the same deformable body at distance r < r_c, overlap delta = r_c - r, along e_ij = (x_i - x_j) / r:

    3D (two spheres of radius r_c/2, Hertz):   f_ij = (4/3) E* sqrt(r_c/4) delta^(3/2) e_ij
    2D (per unit thickness, a linear spring):  f_ij = E* delta e_ij
    E* = E / (2 (1 - nu^2))                    (the reduced modulus of two bodies of one material)

Pairs across symmetry planes are not included. f_ji = -f_ij, so momentum is conserved; the force has a potential, so
it makes no heat. The 2D law is a penalty with the reduced modulus as its stiffness (Hertz's line contact has no
closed force-overlap law without a length scale); its spring, with the particle's mass m = rho dp^2, has omega dt =
sqrt(2 E* / (rho dp^2)) dt, about 0.35 at the scenes' CFL steps, well inside the leapfrog's limit of 2.

Cost. A cKDTree over the body's current positions at every force evaluation: on ``thermal_cutting`` case 1 at
t_u/5 (2,584 particles, ``python benchmarks/profile_cutting.py --set self_contact=0.5``) 11 % of the step, 2.08
against 1.82 us per particle-step without it (+14 %; one profile each, beside two other runs on 2 cores). Off, it
costs nothing.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["reduced_modulus", "self_contact_forces", "self_contact_acceleration", "contact_distance"]


def reduced_modulus(E: float, nu: float) -> float:
    """E* = E / (2 (1 - nu^2)): the contact modulus of two bodies of one material (Hertz; K. L. Johnson, Contact
    Mechanics, 1985, ch. 4)."""
    return E / (2.0 * (1.0 - nu * nu))


def self_contact_forces(x: np.ndarray, body: np.ndarray | None, r_c: float, E_star: float) -> np.ndarray:
    """The self-contact force on every particle (module text): (N, d), N per unit thickness in 2D, N in 3D.
    ``x``: positions of the deformable particles (N, d); ``body``: their body ids (None: one body), pairs of two
    bodies are left out (they meet through the contact model); ``r_c``: the contact distance [m]."""
    n, dim = x.shape
    pairs = cKDTree(x).query_pairs(r_c, output_type="ndarray")
    f = np.zeros((n, dim))
    if body is not None and len(pairs):
        pairs = pairs[body[pairs[:, 0]] == body[pairs[:, 1]]]
    if not len(pairs):
        return f
    i, j = pairs[:, 0], pairs[:, 1]
    d = x[i] - x[j]
    r = np.sqrt(np.einsum("pd,pd->p", d, d))
    delta = r_c - r
    size = E_star * delta if dim == 2 else (4.0 / 3.0) * E_star * np.sqrt(0.25 * r_c) * delta ** 1.5
    f_ij = np.where(r > 0.0, size / np.where(r > 0.0, r, 1.0), 0.0)[:, None] * d   # coincident pair: no direction
    for k in range(dim):
        f[:, k] = np.bincount(i, f_ij[:, k], n) - np.bincount(j, f_ij[:, k], n)
    return f


def self_contact_acceleration(body, r_c: float, material, several_bodies: bool) -> np.ndarray:
    """dv/dt of the self-contact on the deformable rows ``body`` (a State): :func:`self_contact_forces` / m, with
    the reduced modulus of ``material`` (E, nu); ``several_bodies``: pairs only within each body's own ids."""
    f = self_contact_forces(body.x, body.body if several_bodies else None, r_c,
                            reduced_modulus(material.E, material.nu))
    return f / body.m[:, None]


def contact_distance(r_c: float | None) -> float | None:
    """The self-contact distance r_c [m] checked: a finite number > 0, or None (off); ValueError otherwise."""
    if r_c is not None and not (np.isfinite(r_c) and r_c > 0.0):
        raise ValueError(f"self_contact is the self-contact distance r_c [m] (> 0, or None), got {r_c!r}")
    return r_c
