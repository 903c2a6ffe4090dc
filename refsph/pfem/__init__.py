"""The Particle Finite Element Method of Rodriguez Prieto, Larsson & Afrasiabi (2023, Section 2.3): the second
paper's other method, beside refsph's SPH (issue 24). Particles are the nodes of a mesh made anew from them
(Delaunay and the alpha-shape, :mod:`.mesh`); the solid is an updated-Lagrangian mixed displacement-pressure
linear triangle with the polynomial-pressure-projection stabilisation (:mod:`.element`), implicit in time and
solved by Newton-Raphson (:mod:`.solid`); the heat step is a backward-Euler finite element step on the same mesh
(:mod:`.thermal`). The strength laws are the SPH solvers' (:mod:`refsph.strength`).

Status: the mechanics, the heat step and the tool contact with their checks (``tests/test_pfem.py``,
``tests/test_pfem_thermal.py``); the cutting scene (:mod:`.cutting`) with the heat step and a meshed tool runs to
the end (the quick cut, case 1 at t_u / 5 over 4 t_u: about 2 minutes on one core); ``refsph run thermal_cutting
--method pfem`` writes it as a run folder (:mod:`refsph.pfem_run`, ``tests/test_pfem_run.py``). The 18 PFEM cuts
are a study of ``benchmarks/thermal_cutting.py`` ('pfem'). Node removal and insertion at each remeshing
(:mod:`.refine`) keep the chip's nodes from piling up against the rake face: the full-length cut of case 1 at
t_u / 5 runs to the end (34 minutes on one core; without them it failed at 5.1 t_u of 16, Newton on sliver
triangles there).
"""
